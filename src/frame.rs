//! Local frames and hemisphere sampling.

use core::f32::consts::FRAC_PI_4;
use glam::{Vec2, Vec3};

/// Two unit vectors (t, b) completing the unit vector `n` to a right-handed orthonormal basis
/// (t, b, n), branch-free except for the sign of n.z (Duff et al. 2017, “Building an
/// Orthonormal Basis, Revisited”, JCGT 6(1)).
#[inline]
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

/// Maps two uniforms in [0, 1) to the unit disk, preserving relative areas (Shirley and
/// Chiu 1997, concentric map).
#[inline]
pub fn concentric_disk(u1: f32, u2: f32) -> Vec2 {
    let (a, b) = (2.0 * u1 - 1.0, 2.0 * u2 - 1.0);
    if a == 0.0 && b == 0.0 {
        return Vec2::ZERO;
    }
    let (r, phi) =
        if a * a > b * b { (a, FRAC_PI_4 * (b / a)) } else { (b, 2.0 * FRAC_PI_4 - FRAC_PI_4 * (a / b)) };
    let (s, c) = phi.sin_cos();
    Vec2::new(r * c, r * s)
}

/// A cosine-distributed direction about +z (density cos θ/π), from two uniforms.
#[inline]
pub fn sample_cosine_hemisphere(u1: f32, u2: f32) -> Vec3 {
    let d = concentric_disk(u1, u2);
    Vec3::new(d.x, d.y, (1.0 - d.length_squared()).max(0.0).sqrt())
}
