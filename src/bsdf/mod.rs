//! The renderer-facing interface: one object-safe trait, [`Bsdf`], implemented by every model
//! of the crate, and the shading frame a renderer needs to use it.
//!
//! # Conventions of this layer (pbrt's)
//!
//! * `wo` points towards the viewer (the previous path vertex), `wi` towards the light (the
//!   direction to sample); both point away from the surface, in the local shading frame
//!   (z = shading normal), unit length.
//! * [`Bsdf::eval`] returns the BSDF **f itself** (not multiplied by a cosine); a sample's
//!   `weight` is f·|cos θi|/pdf; [`Bsdf::pdf`] is a solid-angle density of `wi`.
//! * Every method is a **pure function of its arguments**: the stochastic techniques draw
//!   their random numbers from a private generator seeded by a hash of the arguments, the
//!   BSDF's seed ([`MicrofacetBsdf::with_seed`]) and the caller's key (the `_keyed`
//!   methods), so identical calls give identical bits on any thread.
//!
//! (The research layer, [`crate::research::Microsurface`] and [`crate::research::PositionFree`], keeps the papers'
//! convention instead: `eval(wi, wo)` with `wi` the direction light arrives from, returning
//! f·|cos θo|, and `&mut impl Rng` arguments.)

mod classic;
mod frame;
mod microfacet;
mod seed;
mod specular;

pub use classic::{ClassicBrdf, ClassicMasking, ClassicNdf};
pub use frame::ShadingFrame;
pub use microfacet::{EnergyByOrder, MAX_WALK_ALPHA, MicrofacetBsdf, SMOOTH_ALPHA, Technique};
pub use specular::{SpecularEvent, SpecularLimit};

/// The deterministic randomness of the stochastic evaluations, for the renderer BSDFs of the
/// layers above (the noncentral lobes).
#[cfg(feature = "leadr")]
pub(crate) use seed::{Hasher, PrimedRng};

use glam::{Vec2, Vec3};

/// Which quantity a path carries across a dielectric interface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Transport {
    /// Paths from the camera carrying radiance: transmission scales by (η_wo/η_wi)².
    #[default]
    Radiance,
    /// Paths from the lights carrying importance (the adjoint BSDF, no η² factor).
    Importance,
}

/// The lobes a BSDF has, as [`Bsdf::flags`] reports them (pbrt's `BxDFFlags`): what an
/// integrator asks before deciding on next-event estimation (useless on a purely specular
/// BSDF) or on two-sided handling (transmission).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BsdfFlags {
    /// Some light leaves on the side it arrived from.
    pub reflection: bool,
    /// Some light crosses the surface.
    pub transmission: bool,
    /// A lobe with a density (eval and pdf are non-zero somewhere) that is not Lambertian.
    pub glossy: bool,
    /// A Lambertian-like lobe (diffuse facets, the classic BRDF's diffuse term).
    pub diffuse: bool,
    /// A Dirac lobe: `eval` and `pdf` are 0 everywhere and only `sample` finds the light.
    pub specular: bool,
}

impl BsdfFlags {
    /// Whether the BSDF has a lobe with a density, where light sampling (NEE) can help.
    #[inline]
    #[must_use]
    pub fn has_non_specular(&self) -> bool {
        self.glossy || self.diffuse
    }
}

/// What kind of scattering a sample represents.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SampleFlags {
    /// The light did not cross the surface: `wi` is on the same side of the shading plane as
    /// `wo`, or the material is opaque (under a normal map a reflection off an opaque surface
    /// can leave `wi` and `wo` on opposite sides of the shading plane).
    pub reflection: bool,
    /// `wi` crossed the surface of a transmissive material.
    pub transmission: bool,
    /// The sample comes from a Dirac lobe: `pdf` is the discrete probability of the event
    /// (not a density), and `eval`/`pdf` at `wi` are 0. Skip MIS for such a bounce.
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
    /// f·|cos θi|/pdf per channel: what the path throughput is multiplied by (for a specular
    /// sample, the Dirac lobe's weight divided by the event's probability).
    pub weight: Vec3,
    /// The density of `wi` (exact or approximate, see `flags.exact_pdf`), > 0; for a
    /// specular sample the probability of the chosen event.
    pub pdf: f32,
    /// The relative index of refraction η_wi/η_wo of a transmission (pbrt's `etap`: η when
    /// entering a dielectric of index η, 1/η when leaving it), 1 for a reflection. Russian
    /// roulette on radiance should divide the throughput by η² to track the energy.
    pub eta: f32,
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

impl BsdfValue {
    /// The zero value of an exact model.
    pub const ZERO: Self = Self { f: Vec3::ZERO, exact: true };
}

/// The interface a renderer integrates against: pbrt-v4's `BxDF` (`f`, `Sample_f`, `PDF`,
/// `Flags`) for one shading point, in the local shading frame.
///
/// Object safe: scenes can hold `Vec<Box<dyn Bsdf>>` (or `&dyn Bsdf`), and the trait has
/// `Send + Sync` as supertraits so such a scene can be shared by render threads.
///
/// Every method returns finite values. Invalid arguments (a direction that is zero, NaN,
/// infinite or not of unit length; a uniform outside [0, 1)) trip a `debug_assert!` in debug
/// builds and give a zero value, a zero pdf or `None` in release builds. Valid but degenerate
/// directions (on the horizon, or below it for reflection-only models) give zero or `None`
/// without asserting.
///
/// # Determinism and decorrelation
///
/// All methods are pure functions of their arguments (see the module conventions). The
/// `_keyed` variants mix a 64-bit value of the caller's into the hash that seeds the
/// stochastic techniques; the plain methods use key 0. Pass a pixel or sample index where the
/// same directions recur across pixels (an orthographic view of a plane under a directional
/// light): with key 0 every pixel would then receive the same stochastic estimate and its
/// error would be correlated across the image. Deterministic models ignore the key.
///
/// ```
/// use microsurface::glam::{Vec2, Vec3};
/// use microsurface::{Bsdf, ComplexIor, Conductor, Dielectric, Ggx, MicrofacetBsdf, Technique};
///
/// let gold = MicrofacetBsdf::new(Ggx::isotropic(0.3)?, Conductor::new(ComplexIor::GOLD))?;
/// let glass = MicrofacetBsdf::new(Ggx::isotropic(0.2)?, Dielectric::new(1.5)?)?
///     .with_technique(Technique::SingleScattering);
/// let scene: Vec<Box<dyn Bsdf>> = vec![Box::new(gold), Box::new(glass)];
/// let wo = Vec3::new(0.3, 0.0, 0.954).normalize();
/// for bsdf in &scene {
///     if let Some(s) = bsdf.sample(wo, 0.5, Vec2::new(0.25, 0.75)) {
///         assert!(s.weight.is_finite() && s.pdf > 0.0);
///         // the same call, the same bits
///         assert_eq!(bsdf.sample(wo, 0.5, Vec2::new(0.25, 0.75)), Some(s));
///     }
/// }
/// # Ok::<(), microsurface::Error>(())
/// ```
pub trait Bsdf: Send + Sync {
    /// The lobes of this BSDF.
    #[must_use]
    fn flags(&self) -> BsdfFlags;

    /// The BSDF f for light arriving from `wi` and leaving towards `wo`, with the caller's
    /// `key` mixed into the seed of a stochastic estimate.
    #[must_use]
    fn eval_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> BsdfValue;

    /// Samples a direction `wi` for the view direction `wo` from the caller's uniforms `uc`
    /// (the 1D sample: lobe or event choice) and `u` (the 2D sample: the direction), all in
    /// [0, 1), with the caller's `key` mixed into the seed of the random numbers a
    /// stochastic technique draws after its first bounce. `None` if nothing is sampled
    /// (absorption, a direction that cannot leave the surface).
    #[must_use]
    fn sample_keyed(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample>;

    /// The density with which `sample` would return `wi` (exact or approximate, as the
    /// samples' `exact_pdf` flag says); 0 for a specular BSDF. Deterministic.
    #[must_use]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;

    /// [`Bsdf::eval_keyed`] and [`Bsdf::pdf`] in one call, for models where they share
    /// work (the exact single-scattering models evaluate one half vector and one D for both).
    #[inline]
    #[must_use]
    fn eval_with_pdf_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> (BsdfValue, f32) {
        (self.eval_keyed(wo, wi, key), self.pdf(wo, wi))
    }

    /// [`Bsdf::eval_keyed`] with key 0.
    #[inline]
    #[must_use]
    fn eval(&self, wo: Vec3, wi: Vec3) -> BsdfValue {
        self.eval_keyed(wo, wi, 0)
    }

    /// [`Bsdf::sample_keyed`] with key 0.
    #[inline]
    #[must_use]
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        self.sample_keyed(wo, uc, u, 0)
    }

    /// [`Bsdf::eval_with_pdf_keyed`] with key 0.
    #[inline]
    #[must_use]
    fn eval_with_pdf(&self, wo: Vec3, wi: Vec3) -> (BsdfValue, f32) {
        self.eval_with_pdf_keyed(wo, wi, 0)
    }
}

/// Whether a direction is usable: the crate's one definition of a unit direction
/// ([`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE)), shared with the research layer.
pub(crate) use crate::contract::is_direction;

/// [`is_direction`], asserted in debug builds: the trait's entry-point check of a direction.
#[inline(always)]
pub(crate) fn valid_direction(w: Vec3) -> bool {
    let ok = is_direction(w);
    debug_assert!(ok, "Bsdf: invalid direction {w} (expected finite and of unit length)");
    ok
}

/// Whether the caller's uniforms lie in [0, 1), asserted in debug builds.
#[inline(always)]
pub(crate) fn valid_uniforms(uc: f32, u: Vec2) -> bool {
    let ok = (0.0..1.0).contains(&uc) && (0.0..1.0).contains(&u.x) && (0.0..1.0).contains(&u.y);
    debug_assert!(ok, "Bsdf::sample: uniforms ({uc}, {u}) outside [0, 1)");
    ok
}
