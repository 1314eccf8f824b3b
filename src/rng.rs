//! Uniform random numbers drawn from any `rand` generator.

use rand::Rng;

/// 2⁻²⁴: the spacing of the uniforms returned by [`uniform`].
const INV_2_POW_24: f32 = 1.0 / 16_777_216.0;

/// A uniform number in [0, 1) with 24 random bits (every value exactly representable in f32).
#[inline(always)]
pub(crate) fn uniform(rng: &mut impl Rng) -> f32 {
    (rng.next_u32() >> 8) as f32 * INV_2_POW_24
}
