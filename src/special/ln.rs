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
use crate::lanes::Lanes;
use core::f64::consts::LN_2;

/// The bits of √½: a positive f64 whose bits minus these have the exponent field k with
/// x/2ᵏ ∈ [√½, √2).
const SQRT_HALF_BITS: u64 = 0x3fe6_a09e_667f_3bcd;

/// ln(1 + f) for f ∈ [√½ − 1, √2 − 1] (in f64): 2 atanh(s) with s = f/(2 + f), |s| ≤ 0.1716,
/// by its series to s¹¹. Relative truncation error s¹²/13 ≤ 5.6e-11; the division and the
/// series add a few f64 ulps. The series in s² by Estrin's scheme (three multiplications
/// deep after s², where Horner's is five: the logarithm of a dielectric walk's crossing lies
/// on its chain of heights).
#[inline(always)]
fn ln_1p_reduced(f: f64) -> f64 {
    let s = f / (2.0 + f);
    let s2 = s * s;
    let s4 = s2 * s2;
    let series = (2.0 / 3.0 + s2 * (2.0 / 5.0)) + s4 * ((2.0 / 7.0 + s2 * (2.0 / 9.0)) + s4 * (2.0 / 11.0));
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
/// - x < −ln 2: with y = eˣ < ½ and w = 1 − y rounded (w ∈ (½, 1]), ln w plus w's rounding
///   error δ = (1 − w) − y (both subtractions exact), since ln(1 − y) = ln w + ln(1 + δ/w): δ
///   stands for ln(1 + δ/w) within 2|δ|y + 2δ², below 2.3e-16 of |ln(1 − y)| ≥ y. One [`ln`]
///   and no branch on y (a walk's depths fall on both sides of any split of y).
///
/// −0 where eˣ is below f32's smallest subnormal.
#[inline(always)]
pub(crate) fn ln_1m_exp_f32(x: f32) -> f32 {
    let x = f64::from(x);
    if x >= -LN_2 {
        let x2 = x * x;
        let series = x
            * (0.5
                + x * (1.0 / 24.0
                    + x2 * (-1.0 / 2880.0 + x2 * (1.0 / 181_440.0 - x2 * (1.0 / 9_676_800.0)))));
        (ln(-x) + series) as f32
    } else {
        // 1 − y rounded to w ∈ (½, 1] and its rounding error (1 − w) − y (both subtractions
        // exact); in this order −0 where y = 0
        let y = exp_nonpositive(x);
        let w = 1.0 - y;
        (-((y - (1.0 - w)) - ln(w))) as f32
    }
}

/// ln 2 = `LN2_HI` + `LN2_LO`: the high part has 9 significant bits, so that k·`LN2_HI` is exact
/// in f32 for every integer |k| ≤ 2¹⁵.
const LN2_HI: f32 = 0.693_359_375;
/// ln 2 − `LN2_HI`, rounded to f32.
const LN2_LO: f32 = -2.121_944_4e-4;

/// ln x of a positive normal x, for every lane type (Cody and Waite's reduction): x = 2ᵏ m with
/// m ∈ [√½, √2) ([`Lanes::exponent_and_mantissa`]), ln m = 2 atanh(s) with s = (m − 1)/(m + 1)
/// = f/(2 + f), |s| ≤ 0.1716, by its series to s⁹ (relative truncation s¹⁰/11 ≤ 2e-9), and
/// k ln 2 in two parts. Relative error in f32 lanes below 4 ulps (2.4e-7; `lanes_ln_exp`
/// below measures it).
#[inline(always)]
pub(crate) fn ln_of<L: Lanes>(x: L) -> L {
    let (k, m) = x.exponent_and_mantissa();
    let f = m - L::lit(1.0);
    let s = f / (L::lit(2.0) + f);
    let s2 = s * s;
    let series = L::lit(1.0 / 3.0) + s2 * (L::lit(0.2) + s2 * (L::lit(1.0 / 7.0) + s2 * L::lit(1.0 / 9.0)));
    let two_s = L::lit(2.0) * s;
    k * L::lit(LN2_HI) + (k * L::lit(LN2_LO) + (two_s + two_s * (s2 * series)))
}

/// ln(1 + t) for t ≥ 0, for every lane type, without losing small t: u = 1 + t rounded,
/// ln u + (t − (u − 1))/u (the rounding of u corrected to first order). Relative error in f32
/// lanes below 4 ulps (measured below).
#[inline(always)]
pub(crate) fn ln_1p_of<L: Lanes>(t: L) -> L {
    let u = L::lit(1.0) + t;
    ln_of(u) + (t - (u - L::lit(1.0))) / u
}

/// eˣ for x ∈ [−87, 88], for every lane type (normal f32 results): k = nearest(x/ln 2),
/// r = x − k ln 2 (ln 2 in two parts, |r| ≤ 0.347), eʳ by its Taylor polynomial of degree 7
/// (relative truncation r⁸/8! ≤ 5.2e-9) and 2ᵏ from the exponent field
/// ([`Lanes::exp2_int`]). Relative error in f32 lanes below 3 ulps (measured below).
#[inline(always)]
pub(crate) fn exp_of<L: Lanes>(x: L) -> L {
    let k = (x * L::lit(core::f32::consts::LOG2_E)).nearest_int();
    let r = (x - k * L::lit(LN2_HI)) - k * L::lit(LN2_LO);
    let c = |v: f64| L::lit(v as f32);
    let poly = L::lit(1.0)
        + r * (L::lit(1.0)
            + r * (c(1.0 / 2.0)
                + r * (c(1.0 / 6.0)
                    + r * (c(1.0 / 24.0)
                        + r * (c(1.0 / 120.0) + r * (c(1.0 / 720.0) + r * c(1.0 / 5040.0)))))));
    poly * k.exp2_int()
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

    /// The f32 lane forms of ln, ln(1 + t) and eˣ within their stated ulps of the f64 library
    /// over 10⁶ points each: ln over the whole normal range, ln(1 + t) for t from 1e-30 to 1e30,
    /// eˣ over [−87, 88].
    #[test]
    fn lanes_ln_exp() {
        let mut u = uniforms(17);
        let (mut ln_worst, mut ln1p_worst, mut exp_worst) = (0.0f64, 0.0f64, 0.0f64);
        for _ in 0..1_000_000 {
            let x = (f64::from(f32::MIN_POSITIVE).ln() + u() * 175.0).exp() as f32;
            if x.is_normal() {
                ln_worst = ln_worst.max(ulps(ln_of(x), f64::from(x).ln()));
            }
            let t = (u() * 138.0 - 69.0).exp() as f32;
            ln1p_worst = ln1p_worst.max(ulps(ln_1p_of(t), f64::from(t).ln_1p()));
            let e = (u() * 175.0 - 87.0) as f32;
            exp_worst = exp_worst.max(ulps(exp_of(e), f64::from(e).exp()));
        }
        for x in [f32::MIN_POSITIVE, 0.5, 1.0, 1.0 + f32::EPSILON, 2.0, f32::MAX] {
            ln_worst = ln_worst.max(ulps(ln_of(x), f64::from(x).ln()));
        }
        eprintln!("lane ln {ln_worst:.2} ulps, ln_1p {ln1p_worst:.2}, exp {exp_worst:.2}");
        assert!(ln_worst <= 4.0 && ln1p_worst <= 4.0 && exp_worst <= 3.0);
        assert_eq!(ln_of(1.0f32), 0.0);
        assert_eq!(ln_1p_of(0.0f32), 0.0);
        assert_eq!(exp_of(0.0f32), 1.0);
    }
}
