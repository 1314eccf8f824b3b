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

#[cfg(test)]
mod tests {
    use super::*;

    /// (t, b, n) is a right-handed orthonormal basis for unit normals all over the sphere,
    /// including the poles and the branch switch at n.z = 0, and n.z = −0 gets the basis of +0.
    #[test]
    fn basis_is_right_handed_and_orthonormal() {
        let mut normals =
            vec![Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.6, 0.8, 0.0), Vec3::new(0.6, 0.8, -0.0)];
        for i in 0..48 {
            for j in 0..=48 {
                let (phi, theta) =
                    (i as f32 / 48.0 * core::f32::consts::TAU, j as f32 / 48.0 * core::f32::consts::PI);
                normals.push(
                    Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()).normalize(),
                );
            }
        }
        let mut worst = 0.0f32;
        for n in normals {
            let (t, b) = basis(n);
            for e in [
                (t.length() - 1.0).abs(),
                (b.length() - 1.0).abs(),
                t.dot(b).abs(),
                t.dot(n).abs(),
                b.dot(n).abs(),
                (t.cross(b) - n).length(),
            ] {
                worst = worst.max(e);
            }
        }
        eprintln!("basis: worst orthonormality / handedness error {worst:e}");
        assert!(worst <= 8.0 * f32::EPSILON, "worst error {worst:e} > 8ε");
        assert_eq!(basis(Vec3::new(0.6, 0.8, -0.0)), basis(Vec3::new(0.6, 0.8, 0.0)));
    }
}
