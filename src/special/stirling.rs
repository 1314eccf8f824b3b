//! The beta function B(1 + a, 1 + b), a, b ≥ 0, for every lane type: the height-correlated
//! masking-shadowing of a transmission (Heitz 2014, “Understanding the masking-shadowing
//! function in microfacet-based BRDFs”, eq. 99; Heitz et al. 2016, supplement §3.4), in f32
//! lanes without the f64 log-gamma.

use super::ln::{exp_of, ln_1p_of, ln_of};
use crate::lanes::Lanes;

/// x μ(x) for x ≥ 1 as a polynomial in t = 1/x ∈ (0, 1], highest degree first, with μ the
/// remainder of Stirling's series, ln Γ(x) = (x − ½) ln x − x + ½ ln 2π + μ(x): the degree-7
/// Chebyshev interpolant on [0, 1] (`scripts/stirling_remainder.py`), absolute error of
/// t·P(t) against μ below 1.6e-9 with the coefficients in f32.
const STIRLING: [f32; 8] = [
    -1.831_591_9e-5,
    0.000_202_577_01,
    -0.000_722_282_3,
    0.001_110_248_5,
    -7.473_104e-5,
    -0.002_768_958_7,
    -4.062_899_8e-7,
    0.083_333_336,
];

/// ½ ln 2π.
const HALF_LN_2PI: f32 = 0.918_938_5;

/// μ(x) = ln Γ(x) − (x − ½) ln x + x − ½ ln 2π for x ≥ 1 (at most μ(1) = 0.0811), as t·P(t),
/// t = 1/x ([`STIRLING`]).
#[inline(always)]
fn stirling_remainder_of<L: Lanes>(x: L) -> L {
    let t = L::lit(1.0) / x;
    let p = STIRLING[1..].iter().fold(L::lit(STIRLING[0]), |p, &c| p * t + L::lit(c));
    t * p
}

/// ln B(1 + a, 1 + b) for a, b ≥ 0, for every lane type: with x = 1 + a, y = 1 + b, s = x + y,
/// Stirling's formula for the three log-gammas rearranged as
///
/// ln B(x, y) = ½ ln 2π + μ(x) + μ(y) − μ(s) − [(x − ½) ln(1 + y/x) + (y − ½) ln(1 + x/y) + ½ ln s],
///
/// (x − ½) ln(x/s) + (y − ½) ln(y/s) − ½ ln s being the three (x − ½) ln x terms of Stirling's
/// formula regrouped. The bracket's three terms are positive, each computed to a few ulps
/// (ln(1 + y/x) by [`ln_1p_of`], accurate where y ≪ x), so their sum has no cancellation,
/// and the bracket is at most |ln B| + 1.08: the absolute error of ln B, hence the relative
/// error of B, grows as ε (1 + |ln B|) and not with a or b. μ from [`STIRLING`] (error
/// 1.6e-9). Domain: a, b ≥ 0 with 2 + a + b finite; B(1 + a, 1 + b) ≤ 1, so the result is
/// ≤ 0 up to rounding.
///
/// Error in f32 lanes against the f64 [`super::ln_beta`] (`tests` below, a dense grid of a, b
/// from 0 to 10⁸ and a = 0 or b = 0): absolute error below 4e-7·(1 + |ln B|) (measured:
/// 3.1e-7·(1 + |ln B|), at ln B ≈ 0, where the bracket and ½ ln 2π cancel: 4 ulps of 1, part
/// of them the rounding of x = 1 + a).
#[inline(always)]
pub(crate) fn ln_beta_1p_of<L: Lanes>(a: L, b: L) -> L {
    let (one, half) = (L::lit(1.0), L::lit(0.5));
    let (x, y) = (one + a, one + b);
    let s = x + y;
    let bracket = (x - half) * ln_1p_of(y / x) + (y - half) * ln_1p_of(x / y) + half * ln_of(s);
    let remainders = stirling_remainder_of(x) + stirling_remainder_of(y) - stirling_remainder_of(s);
    (L::lit(HALF_LN_2PI) + remainders) - bracket
}

/// B(1 + a, 1 + b) for a, b ≥ 0 where ln B ≥ −87 (a normal f32), for every lane type: the
/// exponential ([`exp_of`]) of [`ln_beta_1p_of`] (clamped to [−87, 0]; the caller tests the
/// range). Relative error in f32 lanes below 4e-7·(1 + |ln B|) + 3 ulps, at most 3.6e-5 at
/// ln B = −87 (the test below measures it).
#[inline(always)]
pub(crate) fn beta_1p_of<L: Lanes>(ln_beta: L) -> L {
    exp_of(ln_beta.clamp(L::lit(-87.0), L::lit(0.0)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::special::ln_beta;

    /// The stated bounds over a dense grid: a and b each from 0 and 10⁻⁷ to 10⁸ (80 points per
    /// decade) and 0, against ln Γ in f64 (`ln_beta`, error below 1e-10 there).
    #[test]
    fn lane_beta_meets_its_bound() {
        let mut args = vec![0.0f32];
        for k in 0..=1200 {
            args.push(10f32.powf(-7.0 + k as f32 / 80.0));
        }
        let (mut worst_ln, mut worst_b, mut compared) = (0.0f64, 0.0f64, 0);
        for &a in &args {
            for &b in &args {
                let reference = ln_beta(1.0 + f64::from(a), 1.0 + f64::from(b));
                let lanes = ln_beta_1p_of(a, b);
                let e = (f64::from(lanes) - reference).abs() / (1.0 + reference.abs());
                assert!(e <= 4e-7, "ln B(1 + {a}, 1 + {b}) = {lanes}, reference {reference}");
                worst_ln = worst_ln.max(e);
                if reference >= -87.0 {
                    let b_ref = reference.exp();
                    let rel = (f64::from(beta_1p_of(lanes)) - b_ref).abs() / b_ref;
                    let bound = 4e-7 * (1.0 + reference.abs()) + 3.0 * f64::from(f32::EPSILON);
                    assert!(rel <= bound, "B(1 + {a}, 1 + {b}): relative error {rel:e}");
                    worst_b = worst_b.max(rel / bound);
                    compared += 1;
                }
            }
        }
        eprintln!(
            "ln B: error ≤ {worst_ln:.2e}·(1 + |ln B|); B: ≤ {worst_b:.2} of its bound ({compared} values)"
        );
        assert!(compared > 500_000);
    }
}
