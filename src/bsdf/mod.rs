//! The renderer-facing interface: one small trait, [`Bsdf`], implemented by every model of the
//! crate, and the shading frame a renderer needs to use it.
//!
//! Renderer conventions (pbrt's): `wo` points towards the viewer (the previous path vertex),
//! `wi` towards the light (the direction to sample); both point away from the surface, in the
//! local shading frame (z = shading normal). `eval` returns the BSDF f (not multiplied by a
//! cosine); a sample's `weight` is f·|cos θi|/pdf.

mod classic;
mod frame;
mod microfacet;

pub use classic::{ClassicBrdf, ClassicMasking, ClassicNdf};
pub use frame::ShadingFrame;
pub use microfacet::{EnergyByOrder, MicrofacetBsdf, Technique};

use glam::Vec3;
use rand::Rng;

/// Which quantity a path carries across a dielectric interface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Transport {
    /// Paths from the camera carrying radiance: transmission scales by (η_wo/η_wi)².
    #[default]
    Radiance,
    /// Paths from the lights carrying importance (the adjoint BSDF, no η² factor).
    Importance,
}

/// What kind of scattering a sample represents.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SampleFlags {
    /// `wi` is on the same side of the surface as `wo`.
    pub reflection: bool,
    /// `wi` crossed the surface.
    pub transmission: bool,
    /// The sample comes from a Dirac lobe (never, for the rough models of this crate).
    pub specular: bool,
    /// `pdf` is the exact density of the sampling procedure. When false it is the documented
    /// approximation of the stochastic models: use it only for MIS weights, and use `weight`
    /// (computed from the walk) for the throughput.
    pub exact_pdf: bool,
}

/// A direction sampled by [`Bsdf::sample`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// The sampled direction towards the light (unit, shading frame).
    pub wi: Vec3,
    /// f·|cos θi|/pdf per channel: what the path throughput is multiplied by.
    pub weight: Vec3,
    /// The density of `wi` (exact or approximate, see `flags.exact_pdf`), > 0.
    pub pdf: f32,
    /// The kind of event.
    pub flags: SampleFlags,
}

/// A BSDF value from [`Bsdf::eval`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfValue {
    /// f(wi → wo) per channel (not multiplied by a cosine).
    pub f: Vec3,
    /// Whether `f` is exact; false for stochastic (unbiased) estimates of random-walk and
    /// position-free models.
    pub exact: bool,
}

/// The interface a renderer integrates against (the CS500 project's SampleBrdf / PdfBrdf /
/// EvalScattering).
///
/// Every method returns finite values; invalid or degenerate directions (zero, NaN, on the
/// horizon, or below it for reflection-only models) give a zero value, a zero pdf or `None`.
pub trait Bsdf {
    /// The BSDF f for light arriving from `wi` and leaving towards `wo`.
    fn eval(&self, wo: Vec3, wi: Vec3, rng: &mut impl Rng) -> BsdfValue;

    /// Samples a direction `wi` for the view direction `wo`.
    fn sample(&self, wo: Vec3, rng: &mut impl Rng) -> Option<BsdfSample>;

    /// The density with which `sample` would return `wi` (exact or approximate, as the
    /// samples' `exact_pdf` flag says).
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;
}

/// Whether a direction is usable: finite and of (nearly) unit length.
#[inline(always)]
pub(crate) fn is_direction(w: Vec3) -> bool {
    w.is_finite() && (w.length_squared() - 1.0).abs() < 1e-3
}
