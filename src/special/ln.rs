//! The logarithms of the random walks' height steps (Heitz et al. 2016, supplement §3.1,
//! Algorithm 1 in ln C¹ space), inline and in double precision, and the f32 exponential of their
//! masking terms.
//!
//! Every bounce of a walk takes a logarithm (the exponential variate −ln(1 − u) of its height
//! step) and, in `eval`, an exponential (the masking C¹^Λ(ωo) of its next-event estimate); a
//! dielectric walk also flips ln C¹ to ln(1 − C¹) at each crossing. The f32 library functions
//! cost a call each (and the spills of the walk's registers around it) and test for arguments
//! the walks never pass. These kernels take the walks' arguments only, work in f64 and round
//! once to f32, so their f32 results are the correctly rounded ones except within 0.002 ulp of
//! a rounding midpoint (relative errors before that rounding: below 1e-10 for the logarithms,
//! 4e-15 for the exponential, [`exp_nonpositive`]; asserted against the f64 library below).

use super::exp_nonpositive;
use core::f64::consts::LN_2;

/// The bits of √½: a positive f64 whose bits minus these have the exponent field k with
/// x/2ᵏ ∈ [√½, √2).
const SQRT_HALF_BITS: u64 = 0x3fe6_a09e_667f_3bcd;

/// ln(1 + f) for f ∈ [√½ − 1, √2 − 1] (in f64): 2 atanh(s) with s = f/(2 + f), |s| ≤ 0.1716,
/// by its series to s¹¹. Relative truncation error s¹²/13 ≤ 5.6e-11; the division and the
/// series add a few f64 ulps.
#[inline(always)]
fn ln_1p_reduced(f: f64) -> f64 {
    let s = f / (2.0 + f);
    let s2 = s * s;
    let series = 2.0 / 3.0 + s2 * (2.0 / 5.0 + s2 * (2.0 / 7.0 + s2 * (2.0 / 9.0 + s2 * (2.0 / 11.0))));
    s * (2.0 + s2 * series)
}

/// ln x for a positive normal f64 x: x = 2ᵏ m with m ∈ [√½, √2), ln x = k ln 2 + ln m
/// (no cancellation between the two: |ln m| ≤ ln 2/2). Relative error below 1e-10.
#[inline(always)]
pub(crate) fn ln(x: f64) -> f64 {
    let bits = x.to_bits();
    let k = (bits.wrapping_sub(SQRT_HALF_BITS) as i64) >> 52;
    let m = f64::from_bits(bits.wrapping_sub((k as u64) << 52));
    k as f64 * LN_2 + ln_1p_reduced(m - 1.0)
}

/// ln x of a positive normal f32, rounded once to f32 (see the module: the correctly rounded
/// value except within 0.002 ulp of a midpoint).
#[inline(always)]
pub(crate) fn ln_f32(x: f32) -> f32 {
    ln(f64::from(x)) as f32
}

/// ln(1 + y) for y ∈ (−1, 1]: ln_1p_reduced of y itself where 1 + y ∈ [√½, √2) (so that a
/// small y keeps its relative accuracy), [`ln`] of 1 + y elsewhere (where ln(1 + y) is of
/// order one). Relative error below 1e-10.
#[inline(always)]
pub(crate) fn ln_1p(y: f64) -> f64 {
    if y > core::f64::consts::FRAC_1_SQRT_2 - 1.0 && y < core::f64::consts::SQRT_2 - 1.0 {
        ln_1p_reduced(y)
    } else {
        ln(1.0 + y)
    }
}

/// eˣ of an f32 x ≤ 0 through [`exp_nonpositive`], rounded once to f32 (0 below −103.98,
/// where eˣ is below half the smallest f32 subnormal; NaN for NaN).
#[inline(always)]
pub(crate) fn exp_f32(x: f32) -> f32 {
    exp_nonpositive(f64::from(x)) as f32
}

/// ln(1 − eˣ) for x < 0, without cancellation on either side of −ln 2 (Mächler 2012,
/// “Accurately computing log(1 − exp(−|a|))”), in f64 and rounded once to f32:
/// - x ≥ −ln 2: ln(−x) + ln((1 − eˣ)/(−x)), the second term by its series
///   x/2 + Σ B₂ₙ x²ⁿ/(2n (2n)!) = x/2 + x²/24 − x⁴/2880 + x⁶/181440 − x⁸/9676800 (truncation
///   ≤ 5.4e-11 absolute, against a result of magnitude ≥ ln 2);
/// - x < −ln 2: ln(1 + y) with y = −eˣ ∈ [−½, 0) ([`ln_1p`], relative to its small result).
///
/// −0 where eˣ is below f32's smallest subnormal.
#[inline(always)]
pub(crate) fn ln_1m_exp_f32(x: f32) -> f32 {
    let x = f64::from(x);
    if x >= -LN_2 {
        let x2 = x * x;
        let series =
            x * (0.5 + x * (1.0 / 24.0 + x2 * (-1.0 / 2880.0 + x2 * (1.0 / 181_440.0 - x2 / 9_676_800.0))));
        (ln(-x) + series) as f32
    } else {
        ln_1p(-exp_nonpositive(x)) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator of uniforms in [0, 1) (xorshift64).
    fn uniforms(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn rel(a: f64, b: f64) -> f64 {
        if a == b { 0.0 } else { (a - b).abs() / b.abs() }
    }

    /// The f32 ulps between `a` and the exact `b` (in units of the ulp of b's binade).
    fn ulps(a: f32, b: f64) -> f64 {
        let scale = (b.abs() as f32).max(f32::MIN_POSITIVE);
        let ulp = f64::from(f32::from_bits(scale.to_bits() + 1) - scale);
        (f64::from(a) - b).abs() / ulp
    }

    /// ln against the f64 library on every binade of f32's positive normals and beyond (and
    /// at the walk's arguments 1 − k·2⁻²⁴): relative error below 1e-10, and its f32 rounding
    /// within 0.51 ulp of the exact value.
    #[test]
    fn ln_is_accurate() {
        let mut next = uniforms(0x9e37_79b9_7f4a_7c15);
        let (mut worst, mut worst_f32) = (0.0f64, 0.0f64);
        for _ in 0..400_000 {
            let x = (2.0f64).powf(-140.0 + 280.0 * next()) * (1.0 + next());
            worst = worst.max(rel(ln(x), x.ln()));
        }
        for k in (1..(1u32 << 24)).step_by(97).chain([1, 2, 3, (1 << 23) - 1, 1 << 23, (1 << 24) - 1]) {
            let x = 1.0 - k as f32 / 16_777_216.0;
            let exact = f64::from(x).ln();
            worst = worst.max(rel(ln(f64::from(x)), exact));
            worst_f32 = worst_f32.max(ulps(ln_f32(x), exact));
        }
        for x in [1.0f64, 0.5, core::f64::consts::FRAC_1_SQRT_2, 2.0, f64::MIN_POSITIVE, f64::MAX] {
            worst = worst.max(rel(ln(x), x.ln()));
        }
        assert_eq!(ln(1.0), 0.0);
        eprintln!("ln: relative {worst:.2e}, f32 {worst_f32:.3} ulp");
        assert!(worst < 1e-10, "relative error {worst:e}");
        assert!(worst_f32 < 0.51, "{worst_f32} ulp");
    }

    /// ln(1 + y) against the f64 library on (−1, 1], relative to its (small) result.
    #[test]
    fn ln_1p_is_accurate() {
        let mut next = uniforms(0x2545_f491_4f6c_dd1d);
        let mut worst = 0.0f64;
        for _ in 0..400_000 {
            let magnitude = (10.0f64).powf(-40.0 * next());
            let y = if next() < 0.5 { -magnitude * 0.999_999 } else { magnitude };
            worst = worst.max(rel(ln_1p(y), y.ln_1p()));
        }
        eprintln!("ln_1p: relative {worst:.2e}");
        assert!(worst < 1e-10, "relative error {worst:e}");
    }

    /// eˣ in f32 ([`exp_f32`]) within 0.51 ulp of the exact value for normal results, from
    /// −87 to 0; 0 below the f32 range (−∞ included); e⁰ = 1.
    #[test]
    fn exp_f32_is_accurate() {
        let mut next = uniforms(0x1234_5678_9abc_def1);
        let mut worst_f32 = 0.0f64;
        for _ in 0..400_000 {
            let x = (-87.0 * next() * next()) as f32;
            worst_f32 = worst_f32.max(ulps(exp_f32(x), f64::from(x).exp()));
        }
        assert_eq!(exp_f32(-0.0), 1.0);
        assert_eq!(exp_f32(-200.5), 0.0);
        assert_eq!(exp_f32(f32::NEG_INFINITY), 0.0);
        assert_eq!(exp_f32(f32::MIN), 0.0);
        eprintln!("exp_f32: {worst_f32:.3} ulp");
        assert!(worst_f32 < 0.51, "{worst_f32} ulp");
    }

    /// ln(1 − eˣ) against the f64 reference (Mächler's two forms in the f64 library) on
    /// x ∈ [−104, −f32::MIN_POSITIVE], within 0.51 ulp of the exact value, on both sides of
    /// −ln 2 and at the extremes; −0 where eˣ underflows.
    #[test]
    fn ln_1m_exp_is_accurate() {
        let reference =
            |x: f64| if x > -core::f64::consts::LN_2 { (-x.exp_m1()).ln() } else { (-x.exp()).ln_1p() };
        let mut next = uniforms(0x0bad_5eed_dead_beef);
        let mut worst = (0.0f64, 0.0f32);
        for _ in 0..400_000 {
            let x = -(10.0f64).powf(-38.0 + 40.0 * next()) as f32;
            if !(-100.0..0.0).contains(&x) {
                continue;
            }
            let e = ulps(ln_1m_exp_f32(x), reference(f64::from(x)));
            if e > worst.0 {
                worst = (e, x);
            }
        }
        for x in [
            -f32::MIN_POSITIVE,
            -1e-30,
            f32::from_bits((-core::f32::consts::LN_2).to_bits() + 1),
            f32::from_bits((-core::f32::consts::LN_2).to_bits() - 1),
            -core::f32::consts::LN_2,
            -1.0,
            -87.0,
        ] {
            let e = ulps(ln_1m_exp_f32(x), reference(f64::from(x)));
            if e > worst.0 {
                worst = (e, x);
            }
        }
        assert_eq!(ln_1m_exp_f32(-120.0), -0.0);
        assert_eq!(ln_1m_exp_f32(f32::MIN), -0.0);
        eprintln!("ln(1 − eˣ): {:.3} ulp at x = {:e}", worst.0, worst.1);
        assert!(worst.0 < 0.51, "{} ulp at x = {:e}", worst.0, worst.1);
    }
}
