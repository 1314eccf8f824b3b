//! The renderer-facing interface: one object-safe trait, [`Bsdf`], implemented by every model
//! of the crate, and the shading frame a renderer needs to use it.
//!
//! # Conventions of this layer (pbrt's)
//!
//! * `wo` points towards the viewer (the previous path vertex), `wi` towards the light (the
//!   direction to sample); both point away from the surface, in the local shading frame
//!   (z = shading normal), unit length within [`BSDF_DIRECTION_TOLERANCE`] (renormalized on
//!   entry: see [Inputs](Bsdf#inputs)).
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

mod batch;
mod classic;
mod frame;
mod microfacet;
#[cfg(feature = "mint")]
mod mint;
mod seed;
mod sidedness;
mod specular;
mod walk_density;

pub(crate) use batch::sample_each;
pub use batch::{BatchBsdf, SampleOutputs};
pub use classic::{ClassicBrdf, ClassicMasking, ClassicNdf};
pub use frame::ShadingFrame;
pub use microfacet::{EnergyByOrder, MAX_WALK_ALPHA, MicrofacetBsdf, SMOOTH_ALPHA, Technique};
#[cfg(feature = "mint")]
pub use mint::{MintBsdf, MintSample};
pub use sidedness::Sidedness;
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
    /// entering a dielectric of index η, 1/η when leaving it), 1 for a reflection.
    ///
    /// Russian roulette on radiance should **multiply** the throughput by η² to track the
    /// energy: radiance transport scales a transmission's weight by (η_wo/η_wi)² = 1/η²
    /// (entering glass of η = 1.5 the weight is T/2.25, ≈ 0.43 at normal incidence), so
    /// the throughput drops inside the denser medium while the energy it carries does not.
    /// Keep the product of η² over the path's transmissions (pbrt-v4's `etaScale`) and decide
    /// the roulette on throughput × that product; it returns to 1 when the path leaves the
    /// medium again (η·(1/η)). Dividing instead would make the survival probability 1/η⁴ of
    /// the energy inside glass (0.2 for η = 1.5) and kill those paths about 5× too often.
    /// With [`Transport::Importance`] the weights carry no η² and the product is not needed.
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
/// Every method returns finite values.
///
/// # Inputs
///
/// What a real pipeline sends is answered:
///
/// * a direction whose length is within [`BSDF_DIRECTION_TOLERANCE`] of 1 (|‖ω‖ − 1| ≤ 10⁻²:
///   the drift of an f32 instance transform or of a few frame changes) is renormalized on
///   entry and answered as its unit direction; a direction that is unit to
///   [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE) (|‖ω‖² − 1| ≤ 10⁻³, what f32
///   normalization gives) is used as it is, with no extra work;
/// * a uniform equal to 1 (an f64 → f32 rounding) is taken as 1 − 2⁻²⁴, the largest f32
///   below 1, as pbrt's samplers clamp theirs.
///
/// Only garbage gets the documented *nothing*: a direction that is zero, NaN, infinite or
/// further from unit length, or a uniform that is NaN, negative or above 1, trips a debug
/// assertion naming the argument and its value (`invalid input: `wo` = Vec3(…) is not a unit
/// direction (|wo| = …)`) and gives a zero value, a zero pdf or `None` in release builds.
/// Valid but degenerate directions (on the horizon, or below it for reflection-only models)
/// give zero or `None` without asserting.
///
/// # Flags
///
/// [`Bsdf::flags`] holds over the whole domain (both sides of the shading plane, every
/// roughness, every index): a BSDF whose flags have no non-specular lobe has `eval` and `pdf`
/// 0 everywhere and returns only specular samples, so an integrator may skip light sampling
/// on it; a sample flagged specular has `eval` and `pdf` 0 at its direction, and one that is
/// not has a positive `pdf` there.
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

/// The largest |‖ω‖ − 1| of a direction given to a [`Bsdf`] method: 10⁻². Such a direction is
/// renormalized on entry (one comparison when it is already unit to
/// [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE), the research layer's bound, which
/// stays strict); beyond it the direction is invalid input (see [Inputs](Bsdf#inputs)).
pub const BSDF_DIRECTION_TOLERANCE: f32 = 1e-2;

/// (1 − [`BSDF_DIRECTION_TOLERANCE`])² and (1 + [`BSDF_DIRECTION_TOLERANCE`])²: the range of
/// ‖ω‖² the renderer layer renormalizes.
const LENGTH_SQ_RANGE: core::ops::RangeInclusive<f32> = {
    let (lo, hi) = (1.0 - BSDF_DIRECTION_TOLERANCE, 1.0 + BSDF_DIRECTION_TOLERANCE);
    (lo * lo)..=(hi * hi)
};

/// 1 − 2⁻²⁴, the largest f32 below 1: what a uniform of exactly 1 is taken as.
pub(crate) const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Whether `w` is unit by the research layer's bound: the fast path of the entry checks.
pub(crate) use crate::contract::is_direction;

/// `unit_directions!(wo, wi, nothing, retry)`, at the top of a [`Bsdf`] method: if `wo` or
/// `wi` is not unit to [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE) (one comparison
/// each, the whole cost for unit input), returns `retry` evaluated with both renormalized
/// (rebound under their names) if they lie within [`BSDF_DIRECTION_TOLERANCE`], and
/// `nothing` otherwise, after a debug assertion naming the argument and its value.
macro_rules! unit_directions {
    ($wo:ident, $wi:ident, $nothing:expr, $retry:expr) => {
        if !$crate::bsdf::is_direction($wo) || !$crate::bsdf::is_direction($wi) {
            return match $crate::bsdf::renormalize_pair($wo, $wi) {
                Some(($wo, $wi)) => $retry,
                None => $nothing,
            };
        }
    };
}
pub(crate) use unit_directions;

/// `unit_view!(wo, uc, u, nothing, retry)`, at the top of a `sample` method: as
/// [`unit_directions!`] for the view `wo`, and uniforms of exactly 1 taken as 1 − 2⁻²⁴
/// (`nothing` for a NaN, negative or above 1).
macro_rules! unit_view {
    ($wo:ident, $uc:ident, $u:ident, $nothing:expr, $retry:expr) => {
        if !$crate::bsdf::is_direction($wo) || !$crate::bsdf::are_unit_uniforms($uc, $u) {
            return match $crate::bsdf::renormalize_view($wo, $uc, $u) {
                Some(($wo, $uc, $u)) => $retry,
                None => $nothing,
            };
        }
    };
}
pub(crate) use unit_view;

/// The slow path of [`unit_directions!`]: both directions renormalized, or `None` (with the
/// debug assertion) if one is beyond [`BSDF_DIRECTION_TOLERANCE`].
#[cold]
#[inline(never)]
#[track_caller]
pub(crate) fn renormalize_pair(wo: Vec3, wi: Vec3) -> Option<(Vec3, Vec3)> {
    Some((unit_or_report("wo", wo)?, unit_or_report("wi", wi)?))
}

/// The slow path of [`unit_view!`].
#[cold]
#[inline(never)]
#[track_caller]
pub(crate) fn renormalize_view(wo: Vec3, uc: f32, u: Vec2) -> Option<(Vec3, f32, Vec2)> {
    let wo = unit_or_report("wo", wo)?;
    let r = clamp_ones(uc, u);
    if r.is_none() {
        report_uniforms(uc, u);
    }
    let (uc, u) = r?;
    Some((wo, uc, u))
}

/// The unit direction of the argument `name`: `w` if unit, renormalized within
/// [`BSDF_DIRECTION_TOLERANCE`], otherwise `None` after the debug assertion.
#[inline(always)]
#[track_caller]
fn unit_or_report(name: &str, w: Vec3) -> Option<Vec3> {
    if is_direction(w) {
        return Some(w);
    }
    let r = renormalize_drifted(w);
    if r.is_none() {
        report_direction(name, w);
    }
    r
}

/// The debug assertion of an invalid direction argument.
#[cold]
#[inline(never)]
#[track_caller]
fn report_direction(name: &str, w: Vec3) {
    crate::contract::violated_argument(format_args!(
        "`{name}` = {w:?} is not a unit direction (|{name}| = {})",
        w.length()
    ));
}

/// `w/‖w‖` for a length within [`BSDF_DIRECTION_TOLERANCE`] of 1, `None` beyond (NaN, ±∞
/// and zero included).
#[cold]
#[inline(never)]
fn renormalize_drifted(w: Vec3) -> Option<Vec3> {
    let len_sq = w.length_squared();
    LENGTH_SQ_RANGE.contains(&len_sq).then(|| w / len_sq.sqrt())
}

/// A direction already accepted by the entry checks (`unit_directions!`), renormalized if it
/// drifted (for the wrappers that validate once and call the inner lobe's `*_valid` methods).
#[inline(always)]
pub(crate) fn renormalized(w: Vec3) -> Vec3 {
    if is_direction(w) { w } else { renormalize_drifted(w).unwrap_or(w) }
}

/// Whether the caller's uniforms all lie in [0, 1) (NaN fails): the fast path of
/// [`unit_view!`].
#[inline(always)]
pub(crate) fn are_unit_uniforms(uc: f32, u: Vec2) -> bool {
    in_unit_interval(uc) & in_unit_interval(u.x) & in_unit_interval(u.y)
}

/// The debug assertion of invalid uniforms, naming the first bad argument.
#[cold]
#[inline(never)]
#[track_caller]
fn report_uniforms(uc: f32, u: Vec2) {
    if (0.0..=1.0).contains(&uc) {
        crate::contract::violated_argument(format_args!("`u` = {u:?} is not a pair of uniforms in [0, 1]"));
    } else {
        crate::contract::violated_argument(format_args!("`uc` = {uc:?} is not a uniform in [0, 1]"));
    }
}

/// Whether `x` ∈ [0, 1) (NaN fails).
#[inline(always)]
fn in_unit_interval(x: f32) -> bool {
    (0.0..1.0).contains(&x)
}

/// The uniforms with every 1 replaced by 1 − 2⁻²⁴ if all lie in [0, 1], `None` otherwise.
#[inline(always)]
fn clamp_ones(uc: f32, u: Vec2) -> Option<(f32, Vec2)> {
    let all = [uc, u.x, u.y];
    all.iter().all(|x| (0.0..=1.0).contains(x)).then(|| {
        let [uc, x, y] = all.map(|x| x.min(ONE_MINUS_EPSILON));
        (uc, Vec2::new(x, y))
    })
}
