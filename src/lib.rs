//! # microsurface
//!
//! Physically based microfacet BSDFs on Smith microsurfaces, **with multiple scattering**: the
//! random walks of Heitz, Hanika, d'Eon and Dachsbacher 2016, the position-free estimators of
//! Wang et al. 2022 and the invariance-principle estimator of Cui et al. 2023 on conductor,
//! diffuse and dielectric microfacets, energy-compensated lobes built from tables of the exact
//! model, and exact visible-normal sampling on the whole sphere — behind one renderer-facing
//! trait.
//!
//! The documentation is grouped by use:
//!
//! | you want | start at |
//! |---|---|
//! | a BSDF in a renderer | [`Bsdf`], [`MicrofacetBsdf`], [`ShadingFrame`] (this page) |
//! | which technique, at what cost and error; a chooser within a budget | [`techniques`] |
//! | energy-conserving lobes at single-scattering cost | [`Compensated`], [`Compensation`], [`compensation`] |
//! | the papers' models for references and experiments | [`research`] |
//! | slope distributions and visible normals | [`slope`], [`vndf`] |
//! | measured materials, data-driven slopes | [`tabulated`] (feature `data-driven`) |
//! | filtered displacement and normal maps | [`leadr`] (feature `leadr`) |
//! | Fresnel terms, special functions | [`fresnel`], [`special`] |
//!
//! ## A BSDF in a renderer
//!
//! Build a material (cheap: per hit from textured parameters, or once), then evaluate, sample
//! and query the density in the local shading frame of each hit ([`ShadingFrame`]). `sample`
//! takes the renderer's own uniforms (a 1D and a 2D sample, like pbrt's `Sample_f(wo, uc, u)`);
//! every call is a pure function of its arguments, so renders are reproducible for any thread
//! count, and `Vec<Box<dyn Bsdf>>` holds mixed materials.
//!
//! ```
//! use microsurface::glam::{Vec2, Vec3};
//! use microsurface::{Bsdf, ComplexIor, Conductor, Dielectric, Ggx, MicrofacetBsdf, ShadingFrame};
//!
//! // gold and glass with multiple scattering (the random walk of Heitz et al., all orders)
//! let gold = MicrofacetBsdf::new(Ggx::isotropic(0.4)?, Conductor::new(ComplexIor::GOLD))?;
//! let glass = MicrofacetBsdf::new(Ggx::new(0.3, 0.15)?, Dielectric::new(1.5)?)?;
//! let materials: Vec<Box<dyn Bsdf>> = vec![Box::new(gold), Box::new(glass)];
//!
//! // at a hit: the shading frame of the normal, the view direction in it
//! let frame = ShadingFrame::from_normal(Vec3::new(0.0, 1.0, 0.2)).expect("a non-zero normal");
//! let ray_dir = Vec3::new(0.3, -0.9, 0.1).normalize();
//! let wo = frame.to_local(-ray_dir);
//! for bsdf in &materials {
//!     // BSDF sampling with the renderer's uniforms: weight = f·|cos θi|/pdf
//!     if let Some(s) = bsdf.sample(wo, 0.42, Vec2::new(0.17, 0.83)) {
//!         let next_ray_dir = frame.to_world(s.wi);
//!         assert!(s.weight.is_finite() && s.pdf > 0.0 && next_ray_dir.is_normalized());
//!         // transmissions carry the relative index (for Russian roulette): η or 1/η
//!         assert!(s.flags.reflection || s.eta != 1.0);
//!     }
//!     // light sampling: f (no cosine) and the BSDF's density for the MIS weight
//!     let wi = frame.to_local(Vec3::new(0.2, 1.0, 0.3).normalize());
//!     let (f, pdf) = bsdf.eval_with_pdf(wo, wi);
//!     assert!(f.f.is_finite() && pdf >= 0.0 && pdf == bsdf.pdf(wo, wi));
//! }
//! # Ok::<(), microsurface::Error>(())
//! ```
//!
//! [`Technique`] chooses single scattering (exact on conductors and dielectrics, stochastic on
//! diffuse facets; the cheapest; it loses the energy of the higher orders), the random walk (the
//! exact model, stochastic), the invariance-principle estimator of the same model, or the
//! position-free PT and BDPT estimators; the compensated lobes restore the lost energy
//! deterministically from tables. [`ClassicBrdf`] is the classic Lambert plus
//! Cook–Torrance BRDF. Surfaces smoother than [`SMOOTH_ALPHA`] are Dirac lobes
//! (`flags().specular`).
//!
//! ## Conventions: one per layer
//!
//! Directions are unit `glam::Vec3` in a local frame whose z axis is the (shading) normal, and
//! every direction points away from the surface. The two layers name and orient them
//! differently:
//!
//! * **Renderer layer** ([`Bsdf`], pbrt's convention): `eval(wo, wi)` with `wo` towards the
//!   viewer and `wi` towards the light returns **f** (no cosine); a sample's weight is
//!   f·|cos θi|/pdf.
//! * **Research layer** ([`research`], the papers' convention): `eval(wi, wo)` with `wi` the
//!   direction light arrives from and `wo` the one it leaves along returns **f·|cos θo|**,
//!   stochastic evaluations take `&mut impl Rng`, and a walk sample's weight is f·|cos θo|/pdf.
//!
//! The renderer layer accepts what a real pipeline sends: directions within
//! [`BSDF_DIRECTION_TOLERANCE`] (10⁻²) of unit length are renormalized, and a uniform of exactly
//! 1 is taken as 1 − 2⁻²⁴ (see [`Bsdf`], “Inputs”); the research layer keeps the strict
//! [`DIRECTION_TOLERANCE`]. With the `mint` feature, `MintBsdf` takes and returns the
//! `mint` interop vectors (which glam, nalgebra and cgmath convert to and from), for a
//! renderer on another vector library or another glam version.
//!
//! A zero component of a direction may have either sign: −0 is treated exactly like +0
//! (ω.z = −0 is the horizon seen from above). Samplers take uniforms in [0, 1) and cut the
//! tails of every quantile they invert at 2⁻²⁴, the spacing of 24-bit uniforms (u is used as
//! clamp(u, 2⁻²⁴, 1 − 2⁻²⁴)): no sample lies beyond the last 2⁻²⁴ of its distribution, so the
//! extreme uniforms never put a point mass where the model has almost nothing.
//!
//! # Invalid input
//!
//! One policy for every public entry point: an argument outside its function's domain (a
//! direction that is zero, has a NaN or ±∞ component, or is not unit within
//! [`DIRECTION_TOLERANCE`] — within [`BSDF_DIRECTION_TOLERANCE`] of unit length for the
//! renderer layer, which renormalizes; a NaN scalar; a uniform outside [0, 1], a cosine beyond
//! ±(1 + [`DIRECTION_TOLERANCE`]), an η that is not finite and > 0) is a contract violation. It
//! panics in debug builds (a debug assertion whose message starts with `invalid input`), and
//! release builds return the function's documented *nothing*, never a plausible value: 0 for
//! BSDF values, phase functions and densities; `None` from samplers that return an `Option`
//! and a NaN direction (with a zero weight) from those that do not; NaN for quantities
//! without a neutral value (Λ, G1, projected areas, Fresnel terms, heights). Grazing, exactly
//! horizontal and below-horizon unit directions are valid input.
//!
//! # Features
//!
//! All on by default: `position-free` ([`research::PositionFree`], `Technique::PositionFree`),
//! `invariance` ([`research::Invariance`], `Technique::Invariance`), `leadr` ([`leadr`]) and
//! `data-driven` ([`tabulated`]). A renderer that needs only this page's types, the compensated
//! lobes and the walk builds with `default-features = false`.

// No unsafe code, except the runtime dispatch of the batch loops to their AVX-512 and AVX2 builds
// (`lanes::dispatch`: a call of a `#[target_feature]` function after the CPU check).
#![deny(unsafe_code)]
#![deny(missing_docs)]
// One allowance for the fitted coefficient tables of src/special (the erfcx pieces, the
// Gaussian-quantile fits, the azimuth polynomials) and their reference values: they are written
// as their generators in scripts/ print them (the f32 fits with ten significant digits), so
// that a diff against a generator's output checks them; excessive_precision would have the
// f32 literals cut to the digits an f32 holds.
#![allow(clippy::excessive_precision)]

#[macro_use]
mod contract;
mod albedo;
mod basis;
mod bsdf;
mod constants;
mod error;
mod height;
#[cfg(feature = "invariance")]
mod invariance;
mod lanes;
mod material;
mod microsurface;
#[cfg(feature = "leadr")]
mod noncentral;
mod path;
#[cfg(feature = "position-free")]
mod position_free;
mod rng;
mod sampling;
mod sealed;
mod single_scattering;
mod soa;
mod vector;

pub mod compensation;
pub mod fresnel;
#[cfg(feature = "leadr")]
pub mod leadr;
pub mod slope;
pub mod special;
#[cfg(feature = "data-driven")]
pub mod tabulated;
pub mod techniques;
pub mod vndf;

// The renderer layer: what a renderer reaches first.
pub use bsdf::{
    BSDF_DIRECTION_TOLERANCE, BatchBsdf, Bsdf, BsdfFlags, BsdfSample, BsdfValue, ClassicBrdf, ClassicMasking,
    ClassicNdf, MAX_WALK_ALPHA, MicrofacetBsdf, SMOOTH_ALPHA, SampleFlags, SampleOutputs, ShadingFrame,
    Sidedness, Technique, Transport,
};
#[cfg(feature = "mint")]
pub use bsdf::{MintBsdf, MintSample};
pub use compensation::{Compensated, Compensation};
pub use contract::DIRECTION_TOLERANCE;
pub use error::Error;
pub use fresnel::ComplexIor;
pub use material::{Conductor, Dielectric, Diffuse};
pub use slope::{Beckmann, Elliptical, Ggx};
pub use soa::{Channels, Directions};

/// The vector library of the public API, re-exported so that users on another `glam` version
/// can name the crate's types.
pub use glam;
/// The random-number traits the research layer's walks take, re-exported for the same reason.
pub use rand;

/// The research layer: the papers' models with the papers' interfaces.
///
/// The random walks of Heitz, Hanika, d'Eon and Dachsbacher 2016 ([`Microsurface`](crate::research::Microsurface): heights,
/// slopes and a material, evaluated and sampled by tracing a ray through the microsurface),
/// the exact single-scattering BSDF with full-spherical masking ([`SingleScattering`](crate::research::SingleScattering)), the
/// position-free estimators of Wang et al. 2022 ([`PositionFree`](crate::research::PositionFree), feature `position-free`),
/// the height distributions, the materials' phase functions ([`Material`](crate::research::Material)) and the geometry
/// queries of the microsurface ([`MicrosurfaceGeometry`](crate::research::MicrosurfaceGeometry)).
///
/// Conventions (the papers'): `eval(wi, wo)` with `wi` towards the light and `wo` towards the
/// viewer returns f·|cos θo| per RGB channel; stochastic evaluations take `&mut impl Rng` and
/// are unbiased estimates; a walk sample's weight is f·|cos θo|/pdf. The renderer layer
/// ([`Bsdf`]) is built on these types.
///
/// # Examples
///
/// ```
/// use microsurface::glam::Vec3;
/// use microsurface::research::{Microsurface, ScatteringOrder, UniformHeight};
/// use microsurface::{Conductor, Ggx};
/// use rand::SeedableRng;
///
/// let surface = Microsurface::new(UniformHeight, Ggx::isotropic(0.5)?, Conductor::perfect());
/// let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(7);
/// let (wi, wo) = (Vec3::new(0.3, 0.0, 0.954).normalize(), Vec3::Z);
/// let n = 10_000;
/// // f·|cos θo|, averaged over independent walks
/// let f_cos: f32 = (0..n).map(|_| surface.eval(wi, wo, ScatteringOrder::All, &mut rng).x).sum::<f32>() / n as f32;
/// let single = surface.eval_single_scattering(wi, wo, &mut rng).x;
/// assert!(f_cos > single); // multiple scattering adds energy
/// # Ok::<(), microsurface::Error>(())
/// ```
pub mod research {
    pub use crate::basis::orthonormal_basis;
    pub use crate::bsdf::{EnergyByOrder, SpecularEvent, SpecularLimit};
    pub use crate::height::{GaussianHeight, MicrosurfaceHeight, UniformHeight};
    #[cfg(feature = "invariance")]
    pub use crate::invariance::{Invariance, MIN_FIRST_RATE};
    pub use crate::material::{Event, Interaction, Material, PhaseSample, Side};
    pub use crate::microsurface::{
        HeightSample, MAX_BOUNCES, Microsurface, MicrosurfaceGeometry, ScatteringOrder, WalkOutputs,
        WalkSample,
    };
    pub use crate::path::Shadowing;
    #[cfg(feature = "position-free")]
    pub use crate::position_free::{Estimator, PositionFree};
    pub use crate::sampling::{concentric_disk, sample_cosine_hemisphere};
    pub use crate::single_scattering::{SingleSample, SingleScattering};
}

/// The README's code blocks, compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
