//! The inverse error function.

use super::erf::{erf64, erfc64};

/// 2/√π: erf'(0).
const TWO_OVER_SQRT_PI: f64 = core::f64::consts::FRAC_2_SQRT_PI;
/// Winitzki's constant `a` of the closed-form initial guess (relative error < 2e-3).
const WINITZKI_A: f64 = 0.147;
/// Above this |y| the residual is formed from erfc, which keeps the tail's relative accuracy.
const TAIL_FROM: f64 = 0.5;
/// Halley steps after the initial guess: the error goes 2e-3 → 1e-8 → below 1e-16.
const HALLEY_STEPS: usize = 2;

/// The inverse error function: erfinv(y) = x such that erf(x) = y, for y ∈ [−1, 1].
///
/// Special cases: erfinv(0) = 0 and erfinv(±1) = ±`f32::MAX` (the exact value is ±∞: the
/// result saturates instead of leaving the finite numbers). NaN input gives NaN.
///
/// Accuracy: computed in double precision (Winitzki's closed form refined by two Halley
/// steps on erf, on erfc in the tails) and rounded once. Measured over the whole of (−1, 1),
/// including the 2¹⁶ f32 neighbours of ±1, in `tests/special/functions.rs` against `statrs`'
/// `erf_inv` refined by one Newton step: within 1 ulp (0.501 ulp against the f64 value).
#[must_use]
#[inline]
pub fn erfinv(y: f32) -> f32 {
    if y.abs() >= 1.0 {
        return f32::MAX.copysign(y);
    }
    erfinv64(f64::from(y)) as f32
}

/// erfinv in double precision for |y| < 1 (relative error about 1e-15; ±`f64::MAX` at ±1).
#[must_use]
#[inline]
pub(crate) fn erfinv64(y: f64) -> f64 {
    let a = y.abs();
    if a >= 1.0 {
        return f64::MAX.copysign(y);
    }
    // 1 − |y| is exact for the f32 and f64 inputs near 1 (Sterbenz)
    erfinv_from_both_ends(a, 1.0 - a).copysign(y)
}

/// x ≥ 0 with erf(x) = a, given both a ∈ [0, 1) and its complement `one_minus_a` = 1 − a.
///
/// Taking the complement separately lets callers that know it exactly (the Gaussian height
/// quantile, 1 − a = 2u for tiny u) keep full relative accuracy deep in the tail, where
/// forming 1 − a from a would round to 0.
#[must_use]
#[inline]
pub(crate) fn erfinv_from_both_ends(a: f64, one_minus_a: f64) -> f64 {
    erfinv_refined(a, one_minus_a)
}

#[inline(always)]
fn erfinv_refined(a: f64, one_minus_a: f64) -> f64 {
    if a == 0.0 {
        return 0.0;
    }
    if one_minus_a <= 0.0 {
        return f64::MAX;
    }
    // ln(1 − a²) without cancellation near a = 1
    let ln_1ma2 = one_minus_a.ln() + a.ln_1p();
    let t = 2.0 / (core::f64::consts::PI * WINITZKI_A) + 0.5 * ln_1ma2;
    let mut x = ((t * t - ln_1ma2 / WINITZKI_A).sqrt() - t).sqrt();
    for _ in 0..HALLEY_STEPS {
        let residual = if a <= TAIL_FROM { erf64(x) - a } else { one_minus_a - erfc64(x) };
        let derivative = TWO_OVER_SQRT_PI * (-x * x).exp();
        let newton = residual / derivative;
        x -= newton / (1.0 + x * newton);
    }
    x
}

/// w = −ln(4t(1 − t)) below which [`erfc_inv_f32`] uses its central polynomial.
const CENTRAL_BELOW: f32 = 6.25;
/// w below which it uses the tail polynomial (above: the far tail).
const TAIL_BELOW: f32 = 25.0;
/// The largest w the far-tail polynomial was fitted to (t = 1e-30).
const FAR_TAIL_UNTIL: f32 = 72.0;

/// From this tail probability on (|y| ≤ 0.8, 80 % of uniform tails), [`erfc_inv_f32`] needs
/// no logarithm: it evaluates [`NO_LOG`].
const NO_LOG_FROM: f32 = 0.1;
/// erfinv(y)/y as a polynomial in v = y², for v ∈ [0, 0.64] (relative least-squares fit,
/// `scripts/erfinv_central.py`; relative error 1.5e-7 in f32 evaluation).
const NO_LOG: [f32; 10] = [
    8.862268925e-01,
    2.320237309e-01,
    1.270521581e-01,
    9.622960538e-02,
    -2.801984921e-02,
    5.546818972e-01,
    -1.565399885e+00,
    3.069943428e+00,
    -3.123091698e+00,
    1.463224292e+00,
];

/// erfinv(y)/y as a polynomial in w − 3.125, for w = −ln(1 − y²) ∈ [0, 6.25].
const CENTRAL: [f32; 10] = [
    1.653654646e+00,
    2.401580613e-01,
    -6.034154332e-03,
    -7.405188886e-04,
    1.871795343e-04,
    -1.395875323e-05,
    -1.509433810e-06,
    4.361498711e-07,
    -9.522621044e-09,
    -5.114583298e-09,
];
/// erfinv(y)/y as a polynomial in √w − 3.75, for w ∈ [6.25, 25].
const TAIL: [f32; 9] = [
    3.587504144e+00,
    1.008678372e+00,
    2.056057066e-03,
    -1.294739095e-03,
    5.358158224e-04,
    -2.407513780e-04,
    1.747087012e-04,
    -1.266308138e-04,
    3.940828422e-05,
];
/// erfinv(y)/y as a polynomial in √w − 6.6, for w ∈ [25, 72].
const FAR_TAIL: [f32; 9] = [
    6.465499149e+00,
    1.009006988e+00,
    -5.132083073e-04,
    -6.474486027e-06,
    1.017458217e-05,
    -2.558078011e-06,
    5.179500054e-07,
    -1.068874446e-07,
    1.539970262e-08,
];

/// Evaluates a polynomial (lowest degree first, at least one coefficient) at `x` by Horner's
/// rule, from the leading coefficient.
#[inline(always)]
fn horner(coefficients: &[f32], x: f32) -> f32 {
    let (&leading, rest) = coefficients.split_last().expect("a polynomial has a coefficient");
    rest.iter().rev().fold(leading, |acc, &c| c + acc * x)
}

/// erfinv(y) for |y| ≤ [`NO_LOG_BELOW`] as y·[`NO_LOG`](y²): the central part of
/// [`erfc_inv_f32`] (which takes y = 1 − 2t ∈ [0, 0.8]), odd in y. Relative error below 4e-7
/// (that of `erfc_inv_f32`, whose unit test covers these y; 1.5e-7 for the fit).
#[must_use]
#[inline(always)]
pub(crate) fn erfinv_central(y: f32) -> f32 {
    y * horner(&NO_LOG, y * y)
}

/// The largest |y| of [`erfinv_central`]: 1 − 2·`NO_LOG_FROM`.
pub(crate) const NO_LOG_BELOW: f32 = 0.8;

/// erfc⁻¹(2t) = erfinv(1 − 2t) ≥ 0 for a tail probability t ∈ [1e-30, ½], in single precision:
/// the Gaussian quantile without a library call other than one logarithm (and a square root in
/// the tails), and without the logarithm for t ≥ 0.1 (a polynomial in y², [`NO_LOG`]).
///
/// In the manner of Giles 2010 (“Approximating the erfinv function”), erfinv(y)/y is a
/// polynomial in w = −ln(1 − y²) = −ln(4t(1 − t)) (formed from t, so the tail keeps its
/// relative accuracy), on three ranges of w with our own least-squares fits (degrees 9, 8, 8;
/// relative fit error 2.4e-7 in f32 evaluation). Relative error below 4e-7 over the whole
/// domain (measured 2.9e-7), against the f64 [`erfinv_from_both_ends`] by the unit test. t is clamped
/// to [1e-30, ½].
#[must_use]
#[inline(always)]
pub(crate) fn erfc_inv_f32(tail: f32) -> f32 {
    let t = tail.clamp(1e-30, 0.5);
    let y = 1.0 - 2.0 * t;
    if t >= NO_LOG_FROM {
        return erfinv_central(y);
    }
    let w = -(4.0 * t * (1.0 - t)).ln();
    let ratio = if w < CENTRAL_BELOW {
        horner(&CENTRAL, w - 3.125)
    } else if w < TAIL_BELOW {
        horner(&TAIL, w.sqrt() - 3.75)
    } else {
        debug_assert!(w <= FAR_TAIL_UNTIL);
        horner(&FAR_TAIL, w.sqrt() - 6.6)
    };
    y * ratio
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The documented bound of [`erfc_inv_f32`].
    const ERFC_INV_F32_MAX_ERROR: f64 = 4e-7;

    #[test]
    fn erfc_inv_f32_is_within_its_bound() {
        let mut tails: Vec<f32> =
            (0..=3000).map(|k| 10f32.powf(-30.0 + 29.69 * k as f32 / 3000.0).max(1e-30)).collect();
        tails.extend((1..=20000).map(|k| k as f32 / 40000.0));
        let (mut worst, mut at) = (0.0f64, 0.0f32);
        for t in tails {
            let t64 = f64::from(t);
            let reference = erfinv_from_both_ends(1.0 - 2.0 * t64, 2.0 * t64);
            let got = f64::from(erfc_inv_f32(t));
            let rel = if reference == 0.0 { got.abs() } else { (got / reference - 1.0).abs() };
            if rel > worst {
                (worst, at) = (rel, t);
            }
        }
        eprintln!("erfc_inv_f32: worst relative error {worst:.3e} at t = {at:e}");
        assert!(worst <= ERFC_INV_F32_MAX_ERROR, "erfc_inv_f32 errs by {worst:e} (relative) at t = {at:e}");
    }
}
