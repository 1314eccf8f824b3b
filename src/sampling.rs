//! Warps of the unit square onto the disk and the hemisphere: the concentric disk and
//! cosine-weighted directions.

use crate::contract::is_uniform;
use crate::rng::cut_tails;
use crate::special::sin_cos_turns;
use crate::vector::normalize_fast;
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

/// A cosine-distributed direction about the unit vector `n` (density max(0, ω·n)/π), from two
/// uniforms in [0, 1): ω = (n + s)/|n + s| with s uniform on the unit sphere. The map
/// s = 2(ω·n)ω − n (the reflection of n about ω) has the Jacobian 4 ω·n, so the uniform
/// density 1/(4π) of s becomes (ω·n)/π (the construction of Dupuy and Benyoub 2023's
/// spherical caps, used whole). No frame about n is built.
///
/// s.z = 1 − 2u₁ with u₁ cut to [2⁻²⁴, 1 − 2⁻²⁴] (the crate's tail policy; s is never a pole),
/// its radius 2√(u₁(1 − u₁)) without cancellation, its azimuth 2πu₂ ([`sin_cos_turns`],
/// absolute error 1.2e-7). The direction of n + s carries the f32 error ε/|n + s| of the sum,
/// i.e. about 1e-7/(2 cos θ) rad for ω at cos θ = ω·n: only directions within 1e-3 of the
/// horizon of n (a share 1e-6 of the samples) are off by more than 1e-4 rad, and none lies
/// beyond rounding below that horizon; n + s = 0, which needs s = −n to the last bit, gives n.
/// Unit up to rounding.
#[must_use]
#[inline(always)]
pub(crate) fn cosine_about(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let u1 = cut_tails(u1);
    let radius = 2.0 * (u1 * (1.0 - u1)).sqrt();
    let (sin_phi, cos_phi) = sin_cos_turns(u2);
    let s = Vec3::new(radius * cos_phi, radius * sin_phi, 1.0 - 2.0 * u1);
    normalize_fast(n + s, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use validation::chi2::{Chi2Grid, chi2_test};

    /// `cosine_about` draws the density max(0, ω·n)/π: χ² on 16 × 32 equal-area cells of the
    /// sphere around n for normals at the pole, on the equator and in between (Šidák over the
    /// 5 normals at a family-wise level of 1e-3), and every sample is unit and at most a
    /// rounding below the horizon of n.
    #[test]
    fn cosine_about_draws_the_cosine_density() {
        const N: usize = 400_000;
        let alpha = 1.0 - (1.0 - 1e-3f64).powf(1.0 / 5.0);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / 16_777_216.0
        };
        for n in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.48, -0.6, 0.64), Vec3::new(-0.0, 0.6, -0.8)] {
            let n = n.normalize();
            let mut worst = (0.0f32, 0.0f32);
            chi2_test(
                &format!("cosine about {n}"),
                Chi2Grid::cap(n, core::f64::consts::PI, 16, 32),
                |w| (f64::from(w.dot(n)).max(0.0)) / core::f64::consts::PI,
                || {
                    let w = cosine_about(n, next(), next());
                    worst.0 = worst.0.max((w.length_squared() - 1.0).abs());
                    worst.1 = worst.1.min(w.dot(n));
                    Some(w)
                },
                N,
                alpha,
                1.0,
            );
            assert!(worst.0 <= 4.0 * f32::EPSILON && worst.1 >= -1e-6, "n = {n}: {worst:?}");
        }
        // the extreme uniforms: every direction strictly above the horizon of +z
        for (u1, u2) in [(0.0f32, 0.0f32), (1.0, 0.5), (1.0 - 1.0 / 16_777_216.0, 0.999_999_94)] {
            let w = cosine_about(Vec3::Z, u1, u2);
            assert!(w.z > 0.0 && w.is_normalized(), "u = ({u1}, {u2}): {w}");
        }
    }
}
