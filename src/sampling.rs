//! Warps of the unit square onto the disk and the hemisphere: the concentric disk and
//! cosine-weighted directions.

use crate::contract::is_uniform;
use crate::rng::cut_tails;
use core::f32::consts::FRAC_PI_4;
use glam::{Vec2, Vec3};

/// Maps two uniforms in [0, 1) to the unit disk, preserving relative areas (Shirley and
/// Chiu 1997, concentric map).
///
/// The square's boundary goes to the rim: the uniforms are cut to [2⁻²⁴, 1 − 2⁻²⁴] first (the
/// crate's tail policy), so that every point has at least 2⁻²³ of the disk's area outside its
/// radius (u = 0 would put 2⁻²⁴ of the samples on the rim itself).
///
/// Invalid input ([policy](crate#invalid-input)): a uniform that is NaN or outside
/// [0, 1] gives `Vec2::NAN` (a debug assertion in debug builds).
#[must_use]
#[inline]
pub fn concentric_disk(u1: f32, u2: f32) -> Vec2 {
    require!(is_uniform(u1) && is_uniform(u2), Vec2::NAN; u1, u2);
    disk(u1, u2)
}

/// [`concentric_disk`] without the argument check, for the crate's own uniforms.
#[must_use]
#[inline(always)]
pub(crate) fn disk(u1: f32, u2: f32) -> Vec2 {
    let (r, cos_phi, sin_phi) = concentric_polar(u1, u2);
    Vec2::new(r * cos_phi, r * sin_phi)
}

/// The concentric map in polar form: (r, cos φ, sin φ) with r signed (the point is
/// r (cos φ, sin φ)) and |r| = max(|2u1 − 1|, |2u2 − 1|) exact, so that 1 − r² can be formed
/// as (1 − |r|)(1 + |r|) without cancellation. Uniforms are cut as in [`concentric_disk`].
#[inline(always)]
fn concentric_polar(u1: f32, u2: f32) -> (f32, f32, f32) {
    let (a, b) = (2.0 * cut_tails(u1) - 1.0, 2.0 * cut_tails(u2) - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 1.0, 0.0);
    }
    let (r, phi) =
        if a * a > b * b { (a, FRAC_PI_4 * (b / a)) } else { (b, 2.0 * FRAC_PI_4 - FRAC_PI_4 * (a / b)) };
    let (s, c) = phi.sin_cos();
    (r, c, s)
}

/// A cosine-distributed direction about +z (density cos θ/π), from two uniforms in [0, 1)
/// (the concentric disk lifted to the hemisphere).
///
/// cos θ = √((1 − r)(1 + r)) from the disk radius r exactly, not from the rounded disk point:
/// with the uniforms cut at 2⁻²⁴ (the crate's tail policy) the lowest direction has
/// cos²θ ≥ 2⁻²², i.e. at least that share of the density below it, and never lies on the
/// horizon, where the density is 0. Unit up to rounding (|‖ω‖² − 1| ≤ 4 ulp).
///
/// Invalid input ([policy](crate#invalid-input)): a uniform that is NaN or outside
/// [0, 1] gives `Vec3::NAN` (a debug assertion in debug builds).
#[must_use]
#[inline]
pub fn sample_cosine_hemisphere(u1: f32, u2: f32) -> Vec3 {
    require!(is_uniform(u1) && is_uniform(u2), Vec3::NAN; u1, u2);
    cosine_hemisphere(u1, u2)
}

/// [`sample_cosine_hemisphere`] without the argument check, for the crate's own uniforms.
#[must_use]
#[inline(always)]
pub(crate) fn cosine_hemisphere(u1: f32, u2: f32) -> Vec3 {
    let (r, cos_phi, sin_phi) = concentric_polar(u1, u2);
    let radius = r.abs();
    Vec3::new(r * cos_phi, r * sin_phi, ((1.0 - radius) * (1.0 + radius)).sqrt())
}
