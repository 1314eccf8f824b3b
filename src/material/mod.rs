//! Materials of the microfacets: their phase functions and single-scattering BSDFs
//! (Heitz et al. 2016, supplement §3.2–3.4).

mod conductor;
mod dielectric;
mod diffuse;

pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;

use crate::contract::is_direction;
use crate::slope::MicrosurfaceSlope;
use glam::{DVec3, Vec3};
use rand::Rng;

/// An outgoing direction sampled from a phase function.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseSample {
    /// The outgoing direction ωo (unit).
    pub wo: Vec3,
    /// The sample weight p/pdf per RGB channel: the Fresnel term of a conductor, the albedo of
    /// a diffuse facet, 1 for a dielectric (whose Fresnel term chooses the event instead).
    pub weight: Vec3,
    /// Whether ωo leaves on the outside of the interface (always true for opaque materials;
    /// false after a refraction).
    pub outside: bool,
}

/// The material of the microfacets: a phase function and the single-scattering BSDF.
///
/// Directions follow the supplement's convention: `wi` points away from the scattering point
/// towards where light comes from, `wo` towards where it goes. `wi_outside` and `wo_outside`
/// tell on which side of the interface each direction lies; a material that does not
/// transmit is only evaluated with both true. Phase functions are flipped vertically inside a
/// dielectric (supplement §3.4), so every method is written for `wi_outside = true` and
/// inside configurations are mapped to it.
///
/// Invalid input ([policy](crate#invalid-input)), the same for every method and every
/// material of the crate: a `wi` or `wo` that is zero, has a NaN or ±∞ component, or is not
/// unit within [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE) trips a debug assertion in
/// debug builds; release builds return 0 from the evaluations and densities (`eval_phase`,
/// `pdf_phase`, `vertex`, `connection`, `eval_single_scattering`) and, from `sample_phase`, a
/// [`PhaseSample`] with a NaN `wo` and a zero weight. Grazing and below-horizon unit
/// directions are valid.
pub trait Material: Copy + core::fmt::Debug + Send + Sync {
    /// Whether light can cross the interface (dielectrics).
    const TRANSMITS: bool;

    /// The phase function p(ωi, ωo) times the per-channel weight (Fresnel, albedo), for the
    /// given sides. Stochastic (unbiased) for the diffuse material, exact otherwise.
    fn eval_phase<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
        rng: &mut impl Rng,
    ) -> Vec3;

    /// Samples ωo from the phase function p(ωi, ·) for a ray arriving on side `wi_outside`.
    fn sample_phase<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wi_outside: bool,
        rng: &mut impl Rng,
    ) -> PhaseSample;

    /// Whether [`Material::pdf_phase`] is the exact density of [`Material::sample_phase`].
    const EXACT_PHASE_PDF: bool;

    /// Whether the interface does not interact with light at all: every facet event keeps the
    /// direction and the weight (a dielectric with η = 1 exactly: F = 0, refraction is the
    /// identity). The random walks then return ωo = −ωi with weight 1 as one event instead of
    /// walking the interface's crossings, whose number grows without bound at grazing
    /// incidence, and their evaluations are 0 (the BSDF is a Dirac). False by default.
    #[inline]
    fn is_transparent(&self) -> bool {
        false
    }

    /// The solid-angle density with which [`Material::sample_phase`] draws ωo on side
    /// `wo_outside` from ωi on side `wi_outside`: the phase function without the per-channel
    /// weight. Exact for conductors and dielectrics; for diffuse facets, whose density has no
    /// closed form, a documented deterministic approximation (used only for MIS weights,
    /// never to divide a contribution).
    fn pdf_phase<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
    ) -> f32;

    /// The vertex term of the position-free path integral (Wang et al. 2022, eqs. 2–3): the
    /// local BSDF of one bounce without any shadowing, F D(ωh)/(4|cos θi|) for a reflection
    /// and Walter's BTDF without G for a transmission. It equals the phase function divided
    /// by the full-spherical masking G1(ωi) = |cos θi|/A(ωi) of the incident direction (A is
    /// the projected area). Per channel; stochastic (unbiased) for diffuse facets.
    fn vertex<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
        rng: &mut impl Rng,
    ) -> Vec3;

    /// The vertex term and the phase-function densities of ωo given ωi and of ωi given ωo
    /// ([`Material::vertex`] and [`Material::pdf_phase`] both ways) of one connection, which an
    /// implementation may compute together: a conductor evaluates one half vector and one D
    /// for the three. The bidirectional position-free estimator needs all three for every
    /// connection. Returns (vertex, pdf ωi → ωo, pdf ωo → ωi).
    #[inline]
    fn connection<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
        rng: &mut impl Rng,
    ) -> (Vec3, f32, f32) {
        require!(is_direction(wi) && is_direction(wo), (Vec3::ZERO, 0.0, 0.0); wi, wo);
        self.connection_unchecked(slope, wi, wo, wi_outside, wo_outside, rng)
    }

    // The methods without the argument check, for the crate's walks, which call them once or
    // more per bounce with directions they produced themselves (unit up to rounding). The
    // required ones default to the checked methods, so that a material outside the crate
    // keeps its own behaviour; the crate's materials override them with the unchecked bodies.

    /// [`Material::eval_phase`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn eval_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
        rng: &mut impl Rng,
    ) -> Vec3 {
        self.eval_phase(slope, wi, wo, wi_outside, wo_outside, rng)
    }

    /// [`Material::sample_phase`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn sample_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wi_outside: bool,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        self.sample_phase(slope, wi, wi_outside, rng)
    }

    /// [`Material::pdf_phase`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn pdf_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
    ) -> f32 {
        self.pdf_phase(slope, wi, wo, wi_outside, wo_outside)
    }

    /// [`Material::vertex`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn vertex_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
        rng: &mut impl Rng,
    ) -> Vec3 {
        self.vertex(slope, wi, wo, wi_outside, wo_outside, rng)
    }

    /// [`Material::connection`] without the argument check (crate-internal hot path): by
    /// default the three separate unchecked calls.
    #[doc(hidden)]
    #[inline]
    fn connection_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
        rng: &mut impl Rng,
    ) -> (Vec3, f32, f32) {
        (
            self.vertex_unchecked(slope, wi, wo, wi_outside, wo_outside, rng),
            self.pdf_phase_unchecked(slope, wi, wo, wi_outside, wo_outside),
            self.pdf_phase_unchecked(slope, wo, wi, wo_outside, wi_outside),
        )
    }

    /// (ηo/ηi)², the squared ratio of the indices on the two sides of an event from side
    /// `wi_outside` to side `wo_outside`: η² for a transmission into a dielectric, 1/η² out of
    /// it, 1 otherwise. It is the factor by which radiance transport differs from importance
    /// transport across the interface.
    #[inline]
    fn relative_eta_sq(&self, wi_outside: bool, wo_outside: bool) -> f32 {
        let _ = (wi_outside, wo_outside);
        1.0
    }

    /// The single-scattering BSDF times |cos θo|, for ωi above the surface. Stochastic
    /// (unbiased) for the diffuse material, exact otherwise.
    fn eval_single_scattering<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        rng: &mut impl Rng,
    ) -> Vec3;
}

/// The normalized half vector of a reflection ωi → ωo, if it is a valid microfacet normal
/// for the pair (ωh.z > 0 and ωi·ωh > 0).
#[inline(always)]
pub(crate) fn reflection_half_vector(wi: Vec3, wo: Vec3) -> Option<DVec3> {
    // kept in f64: D in its tails and at small α amplifies the half vector's rounding
    let wh = (wi.as_dvec3() + wo.as_dvec3()).normalize_or_zero();
    (wh.z > 0.0 && wi.as_dvec3().dot(wh) > 0.0).then_some(wh)
}

/// The reflection of `wi` about the unit normal `wm`: 2(ωi·ωm)ωm − ωi.
#[inline(always)]
pub(crate) fn reflect(wi: Vec3, wm: Vec3) -> Vec3 {
    2.0 * wi.dot(wm) * wm - wi
}

/// The Smith masking-shadowing G2 = 1/(1 + Λ(ωi) + Λ(ωo)) for ωi and ωo above the surface
/// (supplement §3.2), 0 if either is at or below the horizon.
#[inline(always)]
pub(crate) fn g2_reflection<S: MicrosurfaceSlope>(slope: &S, wi: Vec3, wo: Vec3) -> f32 {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    // in f64: the f32 Λ saturates at f32::MAX near grazing, where 1 + Λi + Λo would overflow
    (1.0 / (1.0 + slope.lambda64(wi) + slope.lambda64(wo))) as f32
}

/// D_ωi(ωh)/(4 ωi·ωh) = D(ωh)/(4 A(ωi)) for a valid reflection half vector ωh (ωh.z > 0,
/// ωi·ωh > 0); 0 where ωi sees no microsurface.
///
/// Formed from [`MicrosurfaceSlope::d_wi64`], the visible-normal density itself: for a
/// backfacing ωi both D(ωh) and A(ωi) are of order e^{−a²} (Beckmann, a = |cot θi|/αᵢ) and
/// underflow f64 from a ≈ 26.6 on, where D_ωi is still evaluated (in log space). Relative
/// error: that of D_ωi (a few f64 ulps times the condition numbers of D, see
/// [`MicrosurfaceSlope::d64`]) plus the final rounding to f32.
#[inline(always)]
pub(crate) fn phase_reflection<S: MicrosurfaceSlope>(slope: &S, wi: Vec3, wh: DVec3) -> f32 {
    if wi.z > 0.0 {
        // front-facing: A ≥ cos θi, nothing underflows (the walks' hot path)
        return reflection_density(slope, wi, slope.d64_unchecked(wh));
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
    let area =
        if w.z > 0.0 { f64::from(slope.projected_area_unchecked(w)) } else { slope.projected_area64(w) };
    if area <= 0.0 { 0.0 } else { (0.25 * d / area) as f32 }
}
