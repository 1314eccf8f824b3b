//! # microsurface
//!
//! Physically based microfacet BSDFs on Smith microsurfaces, with multiple scattering:
//! the random-walk BSDFs of Heitz, Hanika, d'Eon and Dachsbacher 2016 (“Multiple-Scattering
//! Microfacet BSDFs with the Smith Model”) on conductor, diffuse and dielectric microfacets,
//! built on height distributions, slope distributions and exact visible-normal sampling.
//!
//! Conventions: directions are unit `glam::Vec3` in a local frame whose z axis is the
//! macrosurface normal; every direction points away from the surface. Evaluations of BSDFs
//! return f·|cos θo|. A zero component of a direction may have either sign: −0 is treated
//! exactly like +0 (ω.z = −0 is the horizon seen from above). Samplers take uniforms in [0, 1)
//! and cut the tails of every quantile they invert at 2⁻²⁴, the spacing of 24-bit uniforms
//! (u is used as clamp(u, 2⁻²⁴, 1 − 2⁻²⁴)): no sample lies beyond the last 2⁻²⁴ of its
//! distribution, so the extreme uniforms never put a point mass where the model has almost
//! nothing. See the README for the model table and the validation suite.
//!
//! ```
//! use microsurface::{Conductor, Ggx, Microsurface, ScatteringOrder, UniformHeight};
//! use glam::Vec3;
//! use rand::SeedableRng;
//!
//! let surface = Microsurface::new(UniformHeight, Ggx::isotropic(0.5)?, Conductor::perfect());
//! let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(7);
//! let (wi, wo) = (Vec3::new(0.3, 0.0, 0.954).normalize(), Vec3::Z);
//! let n = 10_000;
//! let f_cos: f32 = (0..n).map(|_| surface.eval(wi, wo, ScatteringOrder::All, &mut rng).x).sum::<f32>() / n as f32;
//! let single = surface.eval_single_scattering(wi, wo, &mut rng).x;
//! assert!(f_cos > single); // multiple scattering adds energy
//! let s = surface.sample(wi, &mut rng).expect("a walk from above always exits");
//! assert!(s.bounces >= 1 && s.weight == Vec3::ONE);
//! # Ok::<(), microsurface::Error>(())
//! ```
//!
//! # Invalid input
//!
//! One policy for every public entry point: an argument outside its function's domain (a
//! direction that is zero, has a NaN or ±∞ component, or is not unit within
//! [`DIRECTION_TOLERANCE`]; a NaN scalar; a uniform outside [0, 1], a cosine beyond
//! ±(1 + [`DIRECTION_TOLERANCE`]), an η that is not finite and > 0) is a contract violation. It
//! panics in debug builds (a debug assertion whose message starts with `invalid input`), and
//! release builds return the function's documented *nothing*, never a plausible value: 0 for
//! BSDF values, phase functions and densities; `None` from samplers that return an `Option`
//! and a NaN direction (with a zero weight) from those that do not; NaN for quantities
//! without a neutral value (Λ, G1, projected areas, Fresnel terms, heights). Grazing, exactly
//! horizontal and below-horizon unit directions are valid input.

#![warn(missing_docs)]

#[macro_use]
mod contract;
mod bsdf;
mod error;
mod frame;
mod fresnel;
mod height;
mod material;
mod microsurface;
mod position_free;
mod rng;
mod slope;
mod special;
mod vndf;

pub use bsdf::{
    Bsdf, BsdfSample, BsdfValue, ClassicBrdf, ClassicMasking, ClassicNdf, EnergyByOrder, MicrofacetBsdf,
    SampleFlags, ShadingFrame, Technique, Transport,
};
pub use contract::DIRECTION_TOLERANCE;
pub use error::Error;
pub use frame::{concentric_disk, orthonormal_basis, sample_cosine_hemisphere};
pub use fresnel::{ComplexIor, fresnel_conductor, fresnel_dielectric, fresnel_schlick};
/// The vector library of the public API, re-exported so that users on another `glam` version
/// can name the crate's types.
pub use glam;
pub use height::{GaussianHeight, MicrosurfaceHeight, UniformHeight};
pub use material::{Conductor, Dielectric, Diffuse, Material, PhaseSample};
pub use microsurface::{
    HeightSample, MAX_BOUNCES, Microsurface, MicrosurfaceGeometry, ScatteringOrder, WalkSample,
};
pub use position_free::{Estimator, PositionFree, Shadowing};
/// The random-number traits the research layer's walks take, re-exported for the same reason.
pub use rand;
pub use slope::{Beckmann, Ggx, MicrosurfaceSlope};
pub use special::{beta, erf, erfc, erfinv, ln_beta, ln_gamma, sin_cos_turns};
pub use vndf::{
    BeckmannNewton, GgxDisk, GgxSphericalCap, SmithVndf, VCavity, VCavitySlope, VisibleNormalSampler,
    smith_normalization,
};

/// The README's code blocks, compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
