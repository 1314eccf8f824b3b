//! Uniform sampling of a band of the unit disk, the building block of the disk-projection
//! visible-normal samplers (Heitz 2018; Tokuyoshi, listings 2–3).

use crate::rng::cut_tails;
use core::f32::consts::TAU;

/// A point (t1, t2) uniform in the band {t2 ∈ [lo ρ, hi ρ]} of the unit disk, ρ = √(1 − t1²),
/// −1 ≤ lo ≤ hi ≤ 1, from two uniforms, and its lift t3 = √(1 − t1² − t2²) ≥ 0 onto the
/// hemisphere.
///
/// A uniform disk point has t1 with density ∝ ρ(t1); mapping its t2 ∈ [−ρ, ρ] affinely onto
/// [lo ρ, hi ρ] keeps the conditional uniform and scales every chord by the same factor, so
/// the result is uniform on the band. This is Heitz's (2018) warp of the half disk, with both
/// ends of the chord free.
///
/// The radial uniform u1 (P(r′ < r) = r² = u1) is cut to [2⁻²⁴, 1 − 2⁻²⁴] (the crate's tail
/// policy, `rng`): u1 = 0 gives r = 2⁻¹² rather than the centre; u2 is an azimuth, not cut.
/// t3 is formed without cancellation, as √((ρ − t2)(ρ + t2)) with
/// ρ ∓ t2 = ((1 ∓ hi)(ρ + t) + (1 ∓ lo)(ρ − t))/2 and (ρ + t)(ρ − t) = 1 − r² = 1 − u1 (t the
/// unwarped coordinate): near the rim (u1 = 1 − 2⁻²⁴) the direct 1 − t1² − t2² is all
/// rounding and rounds to 0, a normal perpendicular to ωi (density 0).
#[must_use]
#[inline(always)]
pub(crate) fn sample_band(u1: f32, u2: f32, lo: f32, hi: f32) -> BandPoint {
    let u1 = cut_tails(u1);
    let r = u1.sqrt();
    let (sin_phi, cos_phi) = (TAU * u2).sin_cos();
    let (t1, t) = (r * cos_phi, r * sin_phi);
    let rho = (1.0 - t1 * t1).max(0.0).sqrt();
    // t ∈ [−ρ, ρ] ↦ [lo ρ, hi ρ]
    let t2 = 0.5 * ((hi - lo) * t + (hi + lo) * rho);
    // ρ ± t, the smaller one from their product 1 − r² (both positive: ρ ≥ √(1 − r²) > 0)
    let one_minus_r2 = 1.0 - u1;
    let (plus, minus) = if t >= 0.0 {
        let plus = rho + t;
        (plus, one_minus_r2 / plus)
    } else {
        let minus = rho - t;
        (one_minus_r2 / minus, minus)
    };
    let below = 0.5 * ((1.0 - hi) * plus + (1.0 - lo) * minus);
    let above = 0.5 * ((1.0 + hi) * plus + (1.0 + lo) * minus);
    BandPoint { t1, t2, t3: (below * above).max(0.0).sqrt(), rho, above_lo: 0.5 * (hi - lo) * plus }
}

/// A point of [`sample_band`] with what its callers need to lift it without cancellation.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BandPoint {
    /// The coordinate across the band.
    pub(crate) t1: f32,
    /// The coordinate along the band, in [lo ρ, hi ρ].
    pub(crate) t2: f32,
    /// √(1 − t1² − t2²) ≥ 0, formed without cancellation.
    pub(crate) t3: f32,
    /// ρ = √(1 − t1²), the half chord.
    pub(crate) rho: f32,
    /// t2 − lo ρ = (hi − lo)(ρ + t)/2 ≥ 0, the distance from the band's lower edge, formed
    /// without cancellation.
    pub(crate) above_lo: f32,
}

/// The band [lo, hi] (in units of ρ) of the upper semicircle t3 ≥ 0 of the disk coordinates
/// (t2, t3) where a·t2 + b·t3 has the sign `keep_positive` asks for.
///
/// The line a t2 + b t3 = 0 meets the semicircle of radius ρ at t2 = cρ with c = b if a ≤ 0,
/// −b otherwise (for a unit (a, b)); the kept side contains t2 = ρ iff the sign of a agrees.
#[must_use]
#[inline(always)]
pub(crate) fn half_space_band(a: f32, b: f32, keep_positive: bool) -> (f32, f32) {
    let norm = (a * a + b * b).sqrt();
    if norm == 0.0 {
        return (-1.0, 1.0);
    }
    let (a, b) = (a / norm, b / norm);
    let c = if a <= 0.0 { b } else { -b };
    let end_kept = if keep_positive { a > 0.0 } else { a < 0.0 };
    if end_kept { (c.clamp(-1.0, 1.0), 1.0) } else { (-1.0, c.clamp(-1.0, 1.0)) }
}
