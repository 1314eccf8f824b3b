//! Local frames and hemisphere sampling.

use crate::contract::{is_direction, is_uniform};
use core::f32::consts::FRAC_PI_4;
use glam::{Vec2, Vec3};

/// Two unit vectors (t, b) completing the unit vector `n` to a right-handed orthonormal basis
/// (t, b, n), branch-free except for the sign of n.z (Duff et al. 2017, “Building an
/// Orthonormal Basis, Revisited”, JCGT 6(1)).
///
/// Invalid input ([policy](crate#invalid-input)): an `n` that is not a unit direction
/// (zero, NaN or ±∞ components, |‖n‖² − 1| > [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE)) gives
/// (`Vec3::NAN`, `Vec3::NAN`) (a debug assertion in debug builds).
#[inline]
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    require!(is_direction(n), (Vec3::NAN, Vec3::NAN); n);
    basis(n)
}

/// [`orthonormal_basis`] without the argument check, for the crate's own unit normals.
#[inline(always)]
pub(crate) fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

/// Maps two uniforms in [0, 1) to the unit disk, preserving relative areas (Shirley and
/// Chiu 1997, concentric map).
///
/// Invalid input ([policy](crate#invalid-input)): a uniform that is NaN or outside
/// [0, 1] gives `Vec2::NAN` (a debug assertion in debug builds).
#[inline]
pub fn concentric_disk(u1: f32, u2: f32) -> Vec2 {
    require!(is_uniform(u1) && is_uniform(u2), Vec2::NAN; u1, u2);
    disk(u1, u2)
}

/// [`concentric_disk`] without the argument check, for the crate's own uniforms.
#[inline(always)]
pub(crate) fn disk(u1: f32, u2: f32) -> Vec2 {
    let (a, b) = (2.0 * u1 - 1.0, 2.0 * u2 - 1.0);
    if a == 0.0 && b == 0.0 {
        return Vec2::ZERO;
    }
    let (r, phi) =
        if a * a > b * b { (a, FRAC_PI_4 * (b / a)) } else { (b, 2.0 * FRAC_PI_4 - FRAC_PI_4 * (a / b)) };
    let (s, c) = phi.sin_cos();
    Vec2::new(r * c, r * s)
}

/// A cosine-distributed direction about +z (density cos θ/π), from two uniforms in [0, 1].
///
/// Invalid input ([policy](crate#invalid-input)): a uniform that is NaN or outside
/// [0, 1] gives `Vec3::NAN` (a debug assertion in debug builds).
#[inline]
pub fn sample_cosine_hemisphere(u1: f32, u2: f32) -> Vec3 {
    require!(is_uniform(u1) && is_uniform(u2), Vec3::NAN; u1, u2);
    cosine_hemisphere(u1, u2)
}

/// [`sample_cosine_hemisphere`] without the argument check, for the crate's own uniforms.
#[inline(always)]
pub(crate) fn cosine_hemisphere(u1: f32, u2: f32) -> Vec3 {
    let d = disk(u1, u2);
    Vec3::new(d.x, d.y, (1.0 - d.length_squared()).max(0.0).sqrt())
}
