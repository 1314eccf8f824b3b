//! The uniform height distribution on [−1, 1].

use super::MicrosurfaceHeight;
use crate::contract::is_uniform;

/// Heights uniform on [−1, 1] (Heitz et al. 2016, supplement §1.2).
///
/// P¹(h) = ½ on [−1, 1] and 0 elsewhere; C¹(h) = (h + 1)/2 clamped to [0, 1];
/// C⁻¹(u) = 2u − 1, so `inv_c1(0) = -1` and `inv_c1(1) = 1`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct UniformHeight;

impl crate::sealed::Sealed for UniformHeight {}

impl MicrosurfaceHeight for UniformHeight {
    #[inline]
    fn p1(&self, h: f32) -> f32 {
        require!(!h.is_nan(), 0.0; h);
        if (-1.0..=1.0).contains(&h) { 0.5 } else { 0.0 }
    }

    #[inline]
    fn c1(&self, h: f32) -> f32 {
        require!(!h.is_nan(), f32::NAN; h);
        (0.5 * (h + 1.0)).clamp(0.0, 1.0)
    }

    /// 2u − 1; u outside [0, 1] (or NaN) is a contract violation: a debug assertion in debug
    /// builds, NaN in release builds.
    #[inline]
    fn inv_c1(&self, u: f32) -> f32 {
        require!(is_uniform(u), f32::NAN; u);
        (2.0 * u - 1.0).clamp(-1.0, 1.0)
    }
}
