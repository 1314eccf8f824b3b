//! Uniform sampling of a band of the unit disk, the building block of the disk-projection
//! visible-normal samplers (Heitz 2018; Tokuyoshi, listings 2–3).

use core::f32::consts::TAU;

/// A point (t1, t2) uniform in the band {t2 ∈ [lo ρ, hi ρ]} of the unit disk, ρ = √(1 − t1²),
/// −1 ≤ lo ≤ hi ≤ 1, from two uniforms.
///
/// A uniform disk point has t1 with density ∝ ρ(t1); mapping its t2 ∈ [−ρ, ρ] affinely onto
/// [lo ρ, hi ρ] keeps the conditional uniform and scales every chord by the same factor, so
/// the result is uniform on the band. This is Heitz's (2018) warp of the half disk, with both
/// ends of the chord free.
#[inline(always)]
pub(crate) fn sample_band(u1: f32, u2: f32, lo: f32, hi: f32) -> (f32, f32) {
    let r = u1.sqrt();
    let (sin_phi, cos_phi) = (TAU * u2).sin_cos();
    let (t1, t) = (r * cos_phi, r * sin_phi);
    let rho = (1.0 - t1 * t1).max(0.0).sqrt();
    // t ∈ [−ρ, ρ] ↦ [lo ρ, hi ρ]
    let t2 = 0.5 * ((hi - lo) * t + (hi + lo) * rho);
    (t1, t2)
}

/// The band [lo, hi] (in units of ρ) of the upper semicircle t3 ≥ 0 of the disk coordinates
/// (t2, t3) where a·t2 + b·t3 has the sign `keep_positive` asks for.
///
/// The line a t2 + b t3 = 0 meets the semicircle of radius ρ at t2 = cρ with c = b if a ≤ 0,
/// −b otherwise (for a unit (a, b)); the kept side contains t2 = ρ iff the sign of a agrees.
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
