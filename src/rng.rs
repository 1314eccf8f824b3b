//! Uniform random numbers drawn from any `rand` generator, and the crate's policy for the
//! tails of its samplers.
//!
//! # Tail policy
//! [`uniform`] returns the 2²⁴ multiples of 2⁻²⁴ in [0, 1 − 2⁻²⁴], each with probability 2⁻²⁴;
//! a renderer's f32 uniform in [0, 1) is at most 1 − 2⁻²⁴ too. Mapped through a quantile Q,
//! the value u stands for the bucket [u, u + 2⁻²⁴): at the top, Q(1 − 2⁻²⁴) has exactly the
//! bucket's probability 2⁻²⁴ beyond it, but at the bottom Q(0) is the end of the support (or of
//! a truncated tail) and would put the first bucket's 2⁻²⁴ on a point the model gives nothing
//! (a Beckmann slope of −8 with a tail of 1e-30, a cosine direction on the horizon).
//!
//! Every sampler therefore cuts both tails of every quantile it inverts at [`TAIL_CUT`] = 2⁻²⁴,
//! by evaluating it at [`cut_tails`]`(u)` = clamp(u, 2⁻²⁴, 1 − 2⁻²⁴): u = 0 is sampled as
//! u = 2⁻²⁴, so the extreme values at both ends have exactly 2⁻²⁴ of the model beyond them, and
//! every other uniform of the crate is unchanged. Samplers accept any u in [0, 1) (and u = 1,
//! treated as 1 − 2⁻²⁴); a NaN stays NaN. Azimuths (periodic, no tail) and discrete choices
//! are not cut. A renderer with finer uniforms loses at most 2⁻²⁴ of each tail, moved onto
//! the cut.

use rand::Rng;

/// 2⁻²⁴: the spacing of the uniforms returned by [`uniform`].
const INV_2_POW_24: f32 = 1.0 / 16_777_216.0;

/// 2⁻²⁴: the probability at which every sampler cuts the tails of its quantiles (see the
/// module's tail policy).
pub(crate) const TAIL_CUT: f32 = INV_2_POW_24;

/// A uniform number in [0, 1) with 24 random bits (every value exactly representable in f32).
/// Samplers cut its extreme values by [`cut_tails`].
#[inline(always)]
pub(crate) fn uniform(rng: &mut impl Rng) -> f32 {
    (rng.next_u32() >> 8) as f32 * INV_2_POW_24
}

/// Two uniforms as [`uniform`] returns them, from one 64-bit draw: the first from the low 32
/// bits (the value `uniform` would return from the same generator state, since `next_u32` is
/// the low half of `next_u64` for the crate's generators), the second from the top 24 bits.
/// Half the generator steps of two [`uniform`] calls, for the samplers that take their
/// uniforms in pairs (a visible normal, a cosine lobe).
#[inline(always)]
pub(crate) fn uniform_pair(rng: &mut impl Rng) -> (f32, f32) {
    let bits = rng.next_u64();
    ((bits as u32 >> 8) as f32 * INV_2_POW_24, (bits >> 40) as f32 * INV_2_POW_24)
}

/// clamp(u, 2⁻²⁴, 1 − 2⁻²⁴): a uniform with both tails cut at [`TAIL_CUT`] (module doc),
/// applied by every sampler to each uniform it maps through a quantile. NaN stays NaN.
#[inline(always)]
pub(crate) fn cut_tails(u: f32) -> f32 {
    u.clamp(TAIL_CUT, 1.0 - TAIL_CUT)
}

/// [`cut_tails`] in double precision, for the samplers that invert their quantiles in f64
/// (the same cut at 2⁻²⁴ on both sides).
#[inline(always)]
pub(crate) fn cut_tails64(u: f64) -> f64 {
    u.clamp(f64::from(TAIL_CUT), 1.0 - f64::from(TAIL_CUT))
}
