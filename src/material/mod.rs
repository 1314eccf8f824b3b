//! Materials of the microfacets: their phase functions and single-scattering BSDFs
//! (Heitz et al. 2016, supplement §3.2–3.4).

mod conductor;
mod dielectric;
mod diffuse;
mod interaction;
mod side;

pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub(crate) use dielectric::{reflectance_scaled_of, refraction_scale};
pub use diffuse::Diffuse;
pub use interaction::{Event, Interaction};
pub use side::Side;

use crate::contract::is_direction;
use crate::lanes::Lanes;
use crate::slope::MicrosurfaceSlope;
use glam::{DVec3, Vec3, Vec3A};
use rand::Rng;

/// A material as the batch calls' lane kernels see it (crate-internal).
#[doc(hidden)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LaneMaterial {
    /// Conductor facets: the per-channel constants (η² − k² − 1, 4η²k²) of their Fresnel
    /// term, `None` for a perfect mirror.
    Conductor(Option<(Vec3A, Vec3A)>),
    /// Dielectric facets of relative index η, with 1/η as the material keeps it (the
    /// refraction's factor: `Dielectric::flipped` swaps the two, so 1/η is not always 1.0/η
    /// rounded).
    Dielectric(f32, f32),
    /// No lane kernels.
    Other,
}

/// An outgoing direction sampled from a phase function.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseSample {
    /// The outgoing direction ωo (unit).
    pub wo: Vec3,
    /// The sample weight p/pdf per RGB channel: the Fresnel term of a conductor, the albedo of
    /// a diffuse facet, 1 for a dielectric (whose Fresnel term chooses the event instead).
    pub weight: Vec3,
    /// The side ωo leaves on (always [`Side::Outside`] for opaque materials; the other side
    /// after a refraction).
    pub side: Side,
}

impl crate::sealed::Sealed for Conductor {}
impl crate::sealed::Sealed for Dielectric {}
impl crate::sealed::Sealed for Diffuse {}

/// The material of the microfacets: a phase function, the position-free vertex term and the
/// single-scattering BSDF.
///
/// Sealed: implemented by [`Conductor`], [`Dielectric`] and [`Diffuse`] only. The walks rely
/// on properties no trait bound can state (the phase function integrates to the albedo, the
/// sampler's density is `pdf_phase` where [`Material::EXACT_PHASE_PDF`] says so, the vertex
/// term is the phase function divided by G1(ωi)), which `tests/` verifies for these three.
///
/// Directions follow the supplement's convention: ωi points away from the scattering point
/// towards where light comes from, ωo towards where it goes; an [`Interaction`] bundles them
/// with their [`Side`]s. A material that does not transmit gives 0 for every interaction
/// that is not an outside reflection. Phase functions are flipped vertically inside a
/// dielectric (supplement §3.4), so every method is written for ωi outside and inside
/// configurations are mapped to it.
///
/// The vertex terms of the position-free model ([`Material::vertex`], [`Material::connection`])
/// are here rather than in [`PositionFree`](crate::research::PositionFree): they are the material's
/// local BSDF without shadowing (Wang et al. 2022, eqs. 2–3), built from the same half
/// vector, refraction geometry and Fresnel term as the phase function, which equals the
/// vertex term times 1/G1(ωi); keeping both in one place keeps them consistent.
///
/// Invalid input ([policy](crate#invalid-input)), the same for every method and every
/// material of the crate: a ωi or ωo that is zero, has a NaN or ±∞ component, or is not
/// unit within [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE) trips a debug assertion in
/// debug builds; release builds return 0 from the evaluations and densities (`eval_phase`,
/// `pdf_phase`, `vertex`, `connection`, `eval_single_scattering`) and, from `sample_phase`, a
/// [`PhaseSample`] with a NaN `wo` and a zero weight. Grazing and below-horizon unit
/// directions are valid. Each checked method validates once and calls its unchecked body,
/// which the crate's walks call directly with the directions they produced themselves.
pub trait Material: crate::sealed::Sealed + Copy + core::fmt::Debug + Send + Sync {
    /// Whether light can cross the interface (dielectrics).
    const TRANSMITS: bool;

    /// Whether [`Material::pdf_phase`] is the exact density of [`Material::sample_phase`].
    const EXACT_PHASE_PDF: bool;

    /// Whether the facets are mirrors with a per-channel weight w(ωi·ωh) (conductors): the
    /// phase function of an outside reflection is w·D(ωh)/(4 A(ωi)), the sampler reflects ωi
    /// about ωm ~ D_ωi with weight w, and nothing crosses the surface. Single scattering then
    /// forms its density and masking ratio from the slope directly (`SingleScattering`).
    #[doc(hidden)]
    const MIRROR_FACETS: bool = false;

    /// Whether the vertex term carries the incident projected area A(ωi)/|cos θi| as a factor
    /// (diffuse facets: their phase function is estimated from D_ωi). For a backfacing ωi that
    /// factor is Λ(−ωi), below f32's range once Λ(−ωi) < 1e-38 (Beckmann, a = |cot θi|/αᵢ > 9.4),
    /// so the position-free estimators form such a vertex as phase function × the relative
    /// shadowing factor instead.
    #[doc(hidden)]
    const VERTEX_HAS_INCIDENT_AREA: bool = false;

    /// The phase function p(ωi, ωo) times the per-channel weight (Fresnel, albedo), for the
    /// interaction's sides. Stochastic (unbiased) for the diffuse material, exact otherwise
    /// (the formulas are on each material's type).
    #[inline]
    #[must_use]
    fn eval_phase<S: MicrosurfaceSlope>(&self, slope: &S, it: &Interaction, rng: &mut impl Rng) -> Vec3 {
        require!(it.has_unit_directions(), Vec3::ZERO; it);
        self.eval_phase_unchecked(slope, it, rng)
    }

    /// Samples ωo from the phase function p(ωi, ·) for a ray arriving on `side`.
    #[inline]
    #[must_use]
    fn sample_phase<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        side: Side,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        let nothing_side = if Self::TRANSMITS { side } else { Side::Outside };
        require!(is_direction(wi), PhaseSample { wo: Vec3::NAN, weight: Vec3::ZERO, side: nothing_side }; wi);
        self.sample_phase_unchecked(slope, wi, side, rng)
    }

    /// The solid-angle density with which [`Material::sample_phase`] draws ωo from ωi: the
    /// phase function without the per-channel weight. Exact for conductors and dielectrics;
    /// for diffuse facets, whose density has no closed form, a documented deterministic
    /// approximation (used only for MIS weights, never to divide a contribution).
    #[inline]
    #[must_use]
    fn pdf_phase<S: MicrosurfaceSlope>(&self, slope: &S, it: &Interaction) -> f32 {
        require!(it.has_unit_directions(), 0.0; it);
        self.pdf_phase_unchecked(slope, it)
    }

    /// The vertex term of the position-free path integral (Wang et al. 2022, eqs. 2–3): the
    /// local BSDF of one bounce without any shadowing, F D(ωh)/(4|cos θi|) for a reflection
    /// and Walter's BTDF without G for a transmission. It equals the phase function divided
    /// by the full-spherical masking G1(ωi) = |cos θi|/A(ωi) of the incident direction (A is
    /// the projected area). Per channel; stochastic (unbiased) for diffuse facets.
    #[inline]
    #[must_use]
    fn vertex<S: MicrosurfaceSlope>(&self, slope: &S, it: &Interaction, rng: &mut impl Rng) -> Vec3 {
        require!(it.has_unit_directions(), Vec3::ZERO; it);
        self.vertex_unchecked(slope, it, rng)
    }

    /// The vertex term and the phase-function densities of ωo given ωi and of ωi given ωo
    /// ([`Material::vertex`] and [`Material::pdf_phase`] both ways) of one connection, which an
    /// implementation may compute together: a conductor evaluates one half vector and one D
    /// for the three. The bidirectional position-free estimator needs all three for every
    /// connection. Returns (vertex, pdf ωi → ωo, pdf ωo → ωi).
    #[inline]
    #[must_use]
    fn connection<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        rng: &mut impl Rng,
    ) -> (Vec3, f32, f32) {
        require!(it.has_unit_directions(), (Vec3::ZERO, 0.0, 0.0); it);
        self.connection_unchecked(slope, it, rng)
    }

    /// Whether the interface does not interact with light at all: every facet event keeps the
    /// direction and the weight (a dielectric with η = 1 exactly: F = 0, refraction is the
    /// identity). The random walks then return ωo = −ωi with weight 1 as one event instead of
    /// walking the interface's crossings, whose number grows without bound at grazing
    /// incidence, and their evaluations are 0 (the BSDF is a Dirac). False by default.
    #[inline]
    #[must_use]
    fn is_transparent(&self) -> bool {
        false
    }

    /// (ηo/ηi)², the squared ratio of the indices on the two sides of an event from side
    /// `from` to side `to`: η² for a transmission into a dielectric, 1/η² out of it, 1
    /// otherwise. It is the factor by which radiance transport differs from importance
    /// transport across the interface.
    #[inline]
    #[must_use]
    fn relative_eta_sq(&self, from: Side, to: Side) -> f32 {
        let _ = (from, to);
        1.0
    }

    /// The single-scattering BSDF times |cos θo|, for ωi above the surface. Stochastic
    /// (unbiased) for the diffuse material, exact otherwise.
    #[must_use]
    fn eval_single_scattering<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        rng: &mut impl Rng,
    ) -> Vec3;

    // The bodies without the argument check: the required methods of the sealed trait, which
    // the crate's walks call once or more per bounce with directions they produced
    // themselves (unit up to rounding).

    /// What the batch calls' lane kernels need of the material ([`LaneMaterial`]); `Other`
    /// for materials without lane kernels (their batch calls run the scalar ones lane by lane).
    #[doc(hidden)]
    #[inline]
    fn lane_material(&self) -> LaneMaterial {
        LaneMaterial::Other
    }

    /// [`Material::eval_phase`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[must_use]
    fn eval_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        rng: &mut impl Rng,
    ) -> Vec3;

    /// [`Material::sample_phase`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[must_use]
    fn sample_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        side: Side,
        rng: &mut impl Rng,
    ) -> PhaseSample;

    /// The reflection of ωi off the mirror facet ωm (visible from ωi) with its weight, for
    /// mirror facets ([`Material::MIRROR_FACETS`]), without the argument check: the phase
    /// sample for a normal the caller drew (`sample_phase` draws it from D_ωi; the renderer
    /// layer's single scattering from [`MicrosurfaceSlope::sample_mirror_normal_unchecked`]).
    /// Other materials never have it called and return a NaN direction with a zero weight.
    #[doc(hidden)]
    #[inline]
    #[must_use]
    fn mirror_reflection_unchecked(&self, wi: Vec3, wm: Vec3) -> PhaseSample {
        let _ = (wi, wm);
        PhaseSample { wo: Vec3::NAN, weight: Vec3::ZERO, side: Side::Outside }
    }

    /// [`Material::sample_phase`] as the crate's random walks draw it (crate-internal hot
    /// path): the same distribution, with each pair of uniforms the sampler maps together (the
    /// visible normal's, a diffuse lobe's) taken from one 64-bit draw (`rng::uniform_pair`) —
    /// the walks' own random stream; a diffuse lobe is built without a frame about ωm
    /// (`sampling::cosine_about`). By default the plain unchecked sampler. The other callers
    /// (single scattering, the position-free estimators) keep the plain sampler's stream.
    #[doc(hidden)]
    #[inline(always)]
    #[must_use]
    fn sample_phase_walk_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        side: Side,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        self.sample_phase_unchecked(slope, wi, side, rng)
    }

    /// [`Material::pdf_phase`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[must_use]
    fn pdf_phase_unchecked<S: MicrosurfaceSlope>(&self, slope: &S, it: &Interaction) -> f32;

    /// [`Material::vertex`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[must_use]
    fn vertex_unchecked<S: MicrosurfaceSlope>(&self, slope: &S, it: &Interaction, rng: &mut impl Rng)
    -> Vec3;

    /// The phase function at the interaction `it` (as [`Material::eval_phase`]) and a sample
    /// of p(ωi, ·) from the same incident direction and side (as [`Material::sample_phase`]):
    /// the two calls of a bounce of the walk's next-event estimation (supplement §3.1,
    /// Algorithm 2). By default the two separate unchecked calls, in that order, the sample as
    /// the walks draw it ([`Material::sample_phase_walk_unchecked`]). A material whose
    /// evaluation is itself stochastic may share its random facet between the two: the
    /// evaluation's expectation given everything before it is unchanged, so the walk's
    /// estimate stays unbiased (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    #[must_use]
    fn eval_and_sample_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        rng: &mut impl Rng,
    ) -> (Vec3, PhaseSample) {
        let sample = self.sample_phase_walk_unchecked(slope, it.wi(), it.wi_side(), rng);
        (self.eval_phase_unchecked(slope, it, rng), sample)
    }

    /// [`Material::connection`] without the argument check (crate-internal hot path): by
    /// default the three separate unchecked calls.
    #[doc(hidden)]
    #[inline]
    #[must_use]
    fn connection_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        rng: &mut impl Rng,
    ) -> (Vec3, f32, f32) {
        (
            self.vertex_unchecked(slope, it, rng),
            self.pdf_phase_unchecked(slope, it),
            self.pdf_phase_unchecked(slope, &it.reversed()),
        )
    }
}

/// The normalized half vector of a reflection ωi → ωo, if it is a valid microfacet normal
/// for the pair (ωh.z > 0 and ωi·ωh > 0).
///
/// The f32 vectors' lengths differ from 1 by Δ (an f32 ulp, 6e-8, for directions the crate
/// produced; up to [`crate::DIRECTION_TOLERANCE`] for callers'). In the half vector of their
/// plain sum ωi + ωo, Δ = |ωi| − |ωo| turns ωh towards the longer one by Δ√(1 − c²)/(2c) rad,
/// c = ω̂i·ωh, which changes c itself by about Δ/(2c): relative to c, Δ/(2c²), 1/c times the
/// change of c that a rounding of either direction by Δ causes. For near-forward reflections
/// (ωo close to −ωi, c small) this dominates: from below a smooth surface (Beckmann α = 0.02
/// at θi = 120°, c ≈ 1e-4) the plain sum lost the sign of ωi·ωh for about 1 % of the sampled
/// directions (eval and pdf 0 where the sampler put mass) and was off by a median 5 %
/// elsewhere (DESIGN.md, “Paths from below”).
///
/// So where either direction is below the horizon, ωh is that of the directions the vectors
/// represent, ωh ∝ ω̂i + ω̂o ∝ ωi + (|ωi|/|ωo|)ωo in f64: its direction is exact to 1e-16/c rad
/// whatever the lengths (only ωo = −ωi has none). Where both are above, ωh is that of the
/// plain sum, the convention of the slopes' reflection densities in the renderer's
/// front-facing single scattering ([`MicrosurfaceSlope::reflection_density_unchecked`]), so
/// that eval, pdf and sample weights agree bit for bit there; a near-forward pair above the
/// horizon needs both directions grazing (at α = 1e-4 and cos θ = 1e-2 the two forms' D differ
/// by 1 %). The rule is symmetric in ωi and ωo, so that the forward and reverse densities of a
/// pair agree. The f64 reference of `validation::reference::phase_reflection_ref` follows it.
#[inline(always)]
pub(crate) fn reflection_half_vector(wi: Vec3, wo: Vec3) -> Option<DVec3> {
    // in f64: D in its tails and at small α amplifies the half vector's rounding
    let (wi, wo) = (wi.as_dvec3(), wo.as_dvec3());
    let sum = if wi.z < 0.0 || wo.z < 0.0 {
        // ω̂i + ω̂o ∝ ωi + (|ωi|/|ωo|) ωo: one square root and one division
        wi + wo * (wi.length_squared() / wo.length_squared()).sqrt()
    } else {
        wi + wo
    };
    let len_sq = sum.length_squared();
    // as `normalize_or_zero` rounds it; a zero sum (ωo = −ωi) gives NaN components, which
    // fail both tests
    let wh = sum * (1.0 / len_sq.sqrt());
    (wh.z > 0.0 && wi.dot(wh) > 0.0).then_some(wh)
}

/// The half vector of a reflection ωi → ωo unnormalized, h = ωi + ωo in f64 (exact: a sum
/// of two f32), with ωi·h: what the walk's next-event estimation needs of it (D is a
/// function of the direction of h only, [`MicrosurfaceSlope::d64_of_sum_unchecked`]; the
/// cosine ωi·ωh only for a Fresnel term).
#[derive(Debug, Clone, Copy)]
pub(crate) struct HalfSum {
    h: DVec3,
    wi_dot_h: f64,
}

impl HalfSum {
    /// The sum of a reflection ωi → ωo if its direction is a valid microfacet normal for the
    /// pair (h.z > 0 and ωi·h > 0: the tests of [`reflection_half_vector`], whose normalized
    /// vector has the same signs).
    #[inline(always)]
    pub(crate) fn visible(wi: Vec3, wo: Vec3) -> Option<Self> {
        let i = wi.as_dvec3();
        let h = i + wo.as_dvec3();
        let wi_dot_h = i.dot(h);
        (h.z > 0.0 && wi_dot_h > 0.0).then_some(Self { h, wi_dot_h })
    }

    /// ωi·ωh with ωh = h/|h| (in f64, rounded once to f32).
    #[inline(always)]
    pub(crate) fn cos_ih(&self) -> f32 {
        (self.wi_dot_h / self.h.length()) as f32
    }

    /// ωi·h, unnormalized (> 0).
    #[inline(always)]
    pub(crate) fn wi_dot_h(&self) -> f64 {
        self.wi_dot_h
    }

    /// |h|².
    #[inline(always)]
    pub(crate) fn length_sq(&self) -> f64 {
        self.h.length_squared()
    }

    /// The reflection density D(ωh)/(4 A(ωi)) for A(ωi) = `area` > 0 known (the walk's, see
    /// [`Interaction`]): [`phase_reflection`] without normalizing the half vector, in f64
    /// ([`MicrosurfaceSlope::reflection_density_of_sum_unchecked`]), rounded once.
    #[inline(always)]
    pub(crate) fn density<S: MicrosurfaceSlope>(&self, slope: &S, area: f32) -> f32 {
        slope.reflection_density_of_sum_unchecked(self.h, area)
    }
}

/// The reflection of `wi` about the unit normal `wm`: 2(ωi·ωm)ωm − ωi.
#[inline(always)]
pub(crate) fn reflect(wi: Vec3, wm: Vec3) -> Vec3 {
    reflect_scaled(wi, wm, 1.0)
}

/// The reflection of `wi` about the normal `m` of any length, given 1/|m|² = `inv_len_sq`:
/// 2(ωi·m)/|m|² m − ωi (the multiplication by 1 of a unit normal is exact: [`reflect`]).
#[inline(always)]
pub(crate) fn reflect_scaled(wi: Vec3, m: Vec3, inv_len_sq: f32) -> Vec3 {
    2.0 * wi.dot(m) * inv_len_sq * m - wi
}

/// The Smith masking-shadowing G2 = 1/(1 + Λ(ωi) + Λ(ωo)) for ωi and ωo above the surface
/// (supplement §3.2), 0 if either is at or below the horizon.
#[inline(always)]
pub(crate) fn g2_reflection<S: MicrosurfaceSlope>(slope: &S, wi: Vec3, wo: Vec3) -> f32 {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    // in f64: the f32 Λ saturates at f32::MAX near grazing, where 1 + Λi + Λo would overflow
    g2_reflection_of(slope.lambda64(wi), slope.lambda64(wo)) as f32
}

/// The height-correlated G2 = 1/(1 + Λ(ωi) + Λ(ωo)) of a reflection from Λ(ωi) and Λ(ωo) ≥ 0,
/// for every lane type (in f32 lanes a saturated Λ gives 1/∞ = 0, the limit).
#[inline(always)]
pub(crate) fn g2_reflection_of<L: Lanes>(lambda_i: L, lambda_o: L) -> L {
    L::lit(1.0) / (L::lit(1.0) + lambda_i + lambda_o)
}

/// G2/G1(ωi) = (1 + Λi)/(1 + Λi + Λo) of a reflection between directions above the horizon,
/// from their projected areas A = (1 + Λ) cos θ and cosines z, for every lane type:
/// Ai zo/(Ai zo + zi (Ao − zo)), one division. The rounding of Ao − zo = Λo zo, which cancels
/// where Λo is small, is at most ε Ao, and relative to the denominator (at least
/// zi zo max(1, Λo)) that is at most 3ε: the ratio keeps a few ulps.
#[inline(always)]
pub(crate) fn g2_over_g1_of<L: Lanes>(area_i: L, area_o: L, z_i: L, z_o: L) -> L {
    let front = area_i * z_o;
    front / (front + z_i * (area_o - z_o))
}

/// D_ωi(ωh)/(4 ωi·ωh) = D(ωh)/(4 A(ωi)) for a valid reflection half vector ωh (ωh.z > 0,
/// ωi·ωh > 0); 0 where ωi sees no microsurface.
///
/// Formed from [`MicrosurfaceSlope::d_wi64`], the visible-normal density itself: for a
/// backfacing ωi both D(ωh) and A(ωi) are of order e^{−a²} (Beckmann, a = |cot θi|/αᵢ) and
/// underflow f64 from a ≈ 26.6 on, where D_ωi is still evaluated (in log space). Relative
/// error: that of D_ωi (a few f64 ulps times the condition numbers of D, see
/// [`MicrosurfaceSlope::d64`]) plus the final rounding to f32.
///
/// `area` is A(ωi) where the caller knows it ([`Interaction`]'s cache), used where ωi faces up.
#[inline(always)]
pub(crate) fn phase_reflection<S: MicrosurfaceSlope>(
    slope: &S,
    wi: Vec3,
    wh: DVec3,
    area: Option<f32>,
) -> f32 {
    if wi.z > 0.0 {
        // front-facing: A ≥ cos θi, nothing underflows (the walks' hot path)
        let d = slope.d64_unchecked(wh);
        return match area {
            Some(area) => front_density(d, area),
            None => reflection_density(slope, wi, d),
        };
    }
    let cos_ih = wi.as_dvec3().dot(wh);
    if cos_ih <= 0.0 {
        return 0.0;
    }
    (0.25 * slope.d_wi64_unchecked(wi, wh) / cos_ih) as f32
}

/// D(ωh)/(4 A(ω)) for D(ωh) = `d`: the reflection density of [`phase_reflection`] with D known
/// (A in f64 below the horizon, where it underflows f32 long before f64; above it A ≥ cos θ
/// and the f32 area serves).
#[inline(always)]
pub(crate) fn reflection_density<S: MicrosurfaceSlope>(slope: &S, w: Vec3, d: f64) -> f32 {
    if w.z > 0.0 {
        return front_density(d, slope.projected_area_unchecked(w));
    }
    let area = slope.projected_area64(w);
    if area <= 0.0 { 0.0 } else { (0.25 * d / area) as f32 }
}

/// D(ωh)/(4 A(ω)) for D(ωh) = `d` and a front-facing ω with the f32 projected area `area`
/// (≥ cos θ > 0).
#[inline(always)]
fn front_density(d: f64, area: f32) -> f32 {
    let area = f64::from(area);
    if area <= 0.0 { 0.0 } else { (0.25 * d / area) as f32 }
}
