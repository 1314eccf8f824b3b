//! The stretch–rotate–unstretch step of the Smith samplers (Heitz et al. 2016, supplement
//! §2.1; Heitz 2018, §3): an anisotropic distribution of roughness (αx, αy) seen from ωi is
//! the α = 1 distribution seen from the stretched ωs = (αx ωi.x, αy ωi.y, ωi.z); slopes sampled
//! in the azimuth frame of ωs are rotated back and scaled by (αx, αy). Written once, for f32
//! and f64 callers alike, with the same operations in either precision.

use super::MicrosurfaceSlope;
use crate::vector::normal_from_slopes;
use core::ops::{Add, Div, Mul, Sub};
use glam::{DVec3, Vec2, Vec3};

/// The real types the step runs in (f32 or f64).
pub(crate) trait Real:
    Copy + PartialOrd + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// The square root.
    fn sqrt(self) -> Self;
    /// Rounded to f32.
    fn to_f32(self) -> f32;
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn to_f32(self) -> f32 {
        self
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn to_f32(self) -> f32 {
        self as f32
    }
}

/// The azimuth of a (stretched) direction: (cos φ, sin φ) of its horizontal part (x, y) and
/// the length √(x² + y²) of that part; φ = 0 for a vertical direction (any azimuth is valid
/// there: the distribution seen from it is symmetric about z).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Azimuth<T> {
    /// cos φ.
    pub(crate) cos_phi: T,
    /// sin φ.
    pub(crate) sin_phi: T,
    /// √(x² + y²) ≥ 0 (sin θ for a unit direction).
    pub(crate) len_xy: T,
}

impl<T: Real> Azimuth<T> {
    /// The azimuth of the horizontal part (x, y).
    #[must_use]
    #[inline(always)]
    pub(crate) fn of(x: T, y: T) -> Self {
        let len_xy = (x * x + y * y).sqrt();
        let (cos_phi, sin_phi) = if len_xy > T::ZERO { (x / len_xy, y / len_xy) } else { (T::ONE, T::ZERO) };
        Self { cos_phi, sin_phi, len_xy }
    }

    /// The slopes (x̃, ỹ) of the α = 1 configuration, given in this azimuth's frame (x̃ along
    /// φ), rotated to the surface frame and unstretched by (αx, αy):
    /// (αx (cos φ x̃ − sin φ ỹ), αy (sin φ x̃ + cos φ ỹ)), in the precision T, rounded to f32.
    #[must_use]
    #[inline(always)]
    pub(crate) fn unstretch(&self, alpha_x: T, alpha_y: T, x: T, y: T) -> Vec2 {
        let slope_x = alpha_x * (self.cos_phi * x - self.sin_phi * y);
        let slope_y = alpha_y * (self.sin_phi * x + self.cos_phi * y);
        Vec2::new(slope_x.to_f32(), slope_y.to_f32())
    }

    /// [`Self::unstretch`] turned into the unit normal of the slopes (without overflow).
    #[must_use]
    #[inline(always)]
    pub(crate) fn unstretched_normal(&self, alpha_x: T, alpha_y: T, x: T, y: T) -> Vec3 {
        let s = self.unstretch(alpha_x, alpha_y, x, y);
        normal_from_slopes(s.x, s.y)
    }
}

/// Stretches a direction by the roughness: (αx x, αy y, z).
#[must_use]
#[inline(always)]
pub(crate) fn stretch<S: MicrosurfaceSlope>(slope: &S, w: Vec3) -> Vec3 {
    Vec3::new(slope.alpha_x() * w.x, slope.alpha_y() * w.y, w.z)
}

/// Stretches a direction by the roughness in double precision: Beckmann terms depend on
/// exp(−z²/q), which amplifies an f32 rounding of q by 2w² (w = |z|/√q reaches hundreds near
/// the nadir).
#[must_use]
#[inline(always)]
pub(crate) fn stretch64<S: MicrosurfaceSlope>(slope: &S, w: Vec3) -> DVec3 {
    DVec3::new(
        f64::from(slope.alpha_x()) * f64::from(w.x),
        f64::from(slope.alpha_y()) * f64::from(w.y),
        f64::from(w.z),
    )
}

/// The frame (T1, T2) of the disk orthogonal to the unit stretched direction v (Heitz 2018,
/// listing 1): T1 horizontal, T2 = v × T1 in the plane of v and z, so that (T1, T2, v) is a
/// right-handed orthonormal basis (T1 × T2 = v) and T2 points up (T2.z ≥ 0). For a vertical v
/// (±z), T1 = +y and T2 = v × T1 = ∓x, the limit of the general form along φ = 0.
#[must_use]
#[inline(always)]
pub(crate) fn disk_frame(v: Vec3) -> (Vec3, Vec3) {
    let len_xy = (v.x * v.x + v.y * v.y).sqrt();
    if len_xy > 0.0 {
        let t1 = Vec3::new(-v.y / len_xy, v.x / len_xy, 0.0);
        (t1, v.cross(t1))
    } else {
        // v × y for v = (0, 0, v.z)
        (Vec3::Y, Vec3::new(-v.z, 0.0, v.x))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The disk frame is a right-handed orthonormal basis with v for every v, including the
    /// vertical ones (where the two former copies of this code chose T2 = +x or +x·sign(v.z),
    /// left-handed for v = +z), and T2 points up.
    #[test]
    fn disk_frame_is_right_handed_and_orthonormal() {
        let mut worst = 0.0f32;
        let mut directions = vec![Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.0, -1.0, 0.0)];
        for i in 0..64 {
            for j in 0..=32 {
                let (phi, theta) =
                    (i as f32 / 64.0 * core::f32::consts::TAU, j as f32 / 32.0 * core::f32::consts::PI);
                directions.push(Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()));
            }
        }
        for v in directions {
            let (t1, t2) = disk_frame(v);
            assert!(t1.z == 0.0, "T1 = {t1} is not horizontal for v = {v}");
            assert!(t2.z >= 0.0, "T2 = {t2} points down for v = {v}");
            for e in [
                (t1.length() - 1.0).abs(),
                (t2.length() - 1.0).abs(),
                t1.dot(t2).abs(),
                t1.dot(v).abs(),
                t2.dot(v).abs(),
                (t1.cross(t2) - v).length(),
            ] {
                worst = worst.max(e);
            }
        }
        eprintln!("disk frame: worst orthonormality / handedness error {worst:e}");
        assert!(worst <= 4.0 * f32::EPSILON, "worst error {worst:e} > 4ε");
    }

    /// The rotation is orthogonal and the unstretch scales by α: the step in f32 and in f64
    /// agree to the f32 rounding, slopes along φ come out along φ, and the slopes' length is
    /// kept at α = 1.
    #[test]
    fn unstretch_rotates_and_scales() {
        let mut worst_f32_vs_f64 = 0.0f64;
        for i in 0..100 {
            let phi = i as f64 / 100.0 * core::f64::consts::TAU;
            let (x, y) = (3.0 * phi.cos(), 2.0 * phi.sin());
            let a64 = Azimuth::of(x, y);
            let a32 = Azimuth::of(x as f32, y as f32);
            // along φ: (r, 0) in the frame is r (cos φ, sin φ) in the surface frame
            let s = a64.unstretch(1.0, 1.0, 1.5, 0.0);
            assert!(
                (f64::from(s.x) - 1.5 * a64.cos_phi).abs() <= 1e-6
                    && (f64::from(s.y) - 1.5 * a64.sin_phi).abs() <= 1e-6
            );
            // an orthogonal rotation at α = 1
            let s = a64.unstretch(1.0, 1.0, 0.6, -0.8);
            assert!((f64::from(s.length()) - 1.0).abs() <= 1e-6, "|s| = {} at φ = {phi}", s.length());
            // the unstretch scales each axis
            let (s1, s2) = (a64.unstretch(1.0, 1.0, 0.6, -0.8), a64.unstretch(0.25, 4.0, 0.6, -0.8));
            assert!((f64::from(s2.x) - 0.25 * f64::from(s1.x)).abs() <= 1e-6);
            assert!((f64::from(s2.y) - 4.0 * f64::from(s1.y)).abs() <= 1e-5);
            let (p, q) = (a32.unstretch(0.25, 4.0, 0.6, -0.8), s2);
            worst_f32_vs_f64 = worst_f32_vs_f64.max(f64::from((p - q).length()) / f64::from(q.length()));
        }
        assert!(worst_f32_vs_f64 <= 1e-6, "f32 and f64 steps differ by {worst_f32_vs_f64:e}");
        // a vertical direction has φ = 0
        let a = Azimuth::of(0.0f32, -0.0);
        assert_eq!((a.cos_phi, a.sin_phi, a.len_xy), (1.0, 0.0, 0.0));
        // the normal of the slopes
        let n = Azimuth::of(1.0f32, 0.0).unstretched_normal(1.0, 1.0, 1.0, 0.0);
        assert!((n - Vec3::new(-1.0, 0.0, 1.0).normalize()).length() <= 1e-6);
    }
}
