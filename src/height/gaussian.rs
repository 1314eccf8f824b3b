//! The standard Gaussian height distribution.

use super::MicrosurfaceHeight;
use crate::contract::is_uniform;
use crate::special::{erfc64, erfinv_from_both_ends};

/// 1/√(2π).
const INV_SQRT_2PI: f32 = 0.398_942_3;
/// √2.
const SQRT_2: f64 = core::f64::consts::SQRT_2;

/// Heights distributed as N(0, 1) (Heitz et al. 2016, supplement §1.3).
///
/// P¹(h) = exp(−h²/2)/√(2π), C¹(h) = ½ erfc(−h/√2) (accurate in both tails),
/// C⁻¹(u) = √2 erf⁻¹(2u − 1), evaluated from whichever end of [0, 1] u is nearer so that the
/// lower tail keeps full relative accuracy down to the smallest positive f32.
///
/// End values: the exact C⁻¹(0) and C⁻¹(1) are ∓∞; `inv_c1` returns
/// ∓[`GaussianHeight::H_MAX`] instead, a height beyond which C¹ rounds to exactly 0 or 1 in f32,
/// so that `c1(inv_c1(u)) == u` still holds at both ends.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GaussianHeight;

impl GaussianHeight {
    /// The height returned for u = 1 (and its negative for u = 0): C¹(16) = 1 and C¹(−16) = 0
    /// in f32, while every u strictly inside (0, 1) maps to |h| < 14.13
    /// (inv_c1(2⁻¹⁴⁹) = −14.1214).
    pub const H_MAX: f32 = 16.0;
}

impl crate::sealed::Sealed for GaussianHeight {}

impl MicrosurfaceHeight for GaussianHeight {
    #[inline]
    fn p1(&self, h: f32) -> f32 {
        require!(!h.is_nan(), 0.0; h);
        INV_SQRT_2PI * (-0.5 * h * h).exp()
    }

    #[inline]
    fn c1(&self, h: f32) -> f32 {
        require!(!h.is_nan(), f32::NAN; h);
        (0.5 * erfc64(-f64::from(h) / SQRT_2)) as f32
    }

    /// u outside [0, 1] (or NaN) is a contract violation: a debug assertion in debug builds,
    /// NaN in release builds.
    #[inline]
    fn inv_c1(&self, u: f32) -> f32 {
        require!(is_uniform(u), f32::NAN; u);
        let u = f64::from(u);
        if u <= 0.0 {
            return -Self::H_MAX;
        }
        if u >= 1.0 {
            return Self::H_MAX;
        }
        // erf(|h|/√2) = |2u − 1|, and its complement 2·min(u, 1 − u) is exact in f64
        let (a, one_minus_a, sign) =
            if u < 0.5 { (1.0 - 2.0 * u, 2.0 * u, -1.0) } else { (2.0 * u - 1.0, 2.0 * (1.0 - u), 1.0) };
        let h = sign * SQRT_2 * erfinv_from_both_ends(a, one_minus_a);
        (h as f32).clamp(-Self::H_MAX, Self::H_MAX)
    }
}
