//! Orthonormal bases completing a unit normal (the local frames of the BSDFs and materials).

use crate::contract::is_direction;
use glam::Vec3;

/// Two unit vectors (t, b) completing the unit vector `n` to a right-handed orthonormal basis
/// (t, b, n), branch-free except for the sign of n.z (Duff et al. 2017, “Building an
/// Orthonormal Basis, Revisited”, JCGT 6(1)). n.z = −0 is treated like +0 (the upper
/// hemisphere's basis; Duff et al.'s copysign would pick the lower one's).
///
/// Invalid input ([policy](crate#invalid-input)): an `n` that is not a unit direction
/// (zero, NaN or ±∞ components, |‖n‖² − 1| > [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE)) gives
/// (`Vec3::NAN`, `Vec3::NAN`) (a debug assertion in debug builds).
#[must_use]
#[inline]
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    require!(is_direction(n), (Vec3::NAN, Vec3::NAN); n);
    basis(n)
}

/// [`orthonormal_basis`] without the argument check, for the crate's own unit normals.
#[must_use]
#[inline(always)]
pub(crate) fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = if n.z >= 0.0 { 1.0f32 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}
