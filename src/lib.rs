//! # microsurface
//!
//! Physically based microfacet BSDFs on Smith microsurfaces, with multiple scattering:
//! the random-walk BSDFs of Heitz, Hanika, d'Eon and Dachsbacher 2016 (“Multiple-Scattering
//! Microfacet BSDFs with the Smith Model”) on conductor, diffuse and dielectric microfacets,
//! built on height distributions, slope distributions and exact visible-normal sampling.
//!
//! Conventions: directions are unit `glam::Vec3` in a local frame whose z axis is the
//! macrosurface normal; every direction points away from the surface. Evaluations of BSDFs
//! return f·|cos θo|. See the README for the model table and the validation suite.
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

#![warn(missing_docs)]

mod bsdf;
mod error;
mod frame;
mod fresnel;
mod height;
mod material;
mod merl;
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
pub use error::Error;
pub use frame::{concentric_disk, orthonormal_basis, sample_cosine_hemisphere};
pub use fresnel::{ComplexIor, fresnel_conductor, fresnel_dielectric, fresnel_schlick};
/// The vector library of the public API, re-exported so that users on another `glam` version
/// can name the crate's types.
pub use glam;
pub use height::{GaussianHeight, MicrosurfaceHeight, UniformHeight};
pub use material::{Conductor, Dielectric, Diffuse, Material, PhaseSample};
pub use merl::{MERL_PHI_D, MERL_THETA_D, MERL_THETA_H, MerlBrdf, MerlError, half_diff_angles};
pub use microsurface::{
    HeightSample, MAX_BOUNCES, Microsurface, MicrosurfaceGeometry, ScatteringOrder, WalkSample,
};
pub use position_free::{Estimator, PositionFree, Shadowing};
/// The random-number traits the research layer's walks take, re-exported for the same reason.
pub use rand;
pub use slope::{
    BackscatterShadowing, Beckmann, Extraction, Ggx, GridExtraction, GridSlope, MAX_RINGS, MicrosurfaceSlope,
    StretchedTabulated, TabulatedSlope, extract_anisotropic, extract_anisotropic_fn, extract_fresnel,
    extract_isotropic, extract_isotropic_fn,
};
pub use special::{beta, erf, erfc, erfinv, ln_beta, ln_gamma, sin_cos_turns};
pub use vndf::{
    BeckmannNewton, GgxDisk, GgxSphericalCap, SmithVndf, VCavity, VCavitySlope, VisibleNormalSampler,
    smith_normalization,
};

/// The README's code blocks, compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
