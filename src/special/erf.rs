//! The error function and its complements.

/// 1/√π.
const INV_SQRT_PI: f64 = 0.564_189_583_547_756_3;
/// Above this argument `exp(u²)` times `erfc(u)` is replaced by the asymptotic series
/// (`erfc` itself is still far from underflow at 25: about 1e-274).
const ERFCX_ASYMPTOTIC_FROM: f64 = 25.0;

/// The error function erf(x) = 2/√π ∫₀ˣ exp(−t²) dt.
///
/// Defined for every finite x, and erf(±∞) = ±1. Evaluated in double precision and rounded
/// once, so the result is within 1 ulp of the exact value (measured maximum: see
/// `tests/special_functions.rs`, 1 ulp).
#[inline]
pub fn erf(x: f32) -> f32 {
    libm::erf(f64::from(x)) as f32
}

/// The complementary error function erfc(x) = 1 − erf(x), accurate in its tails.
///
/// Relative error within 1 ulp where the result is a normal f32 (measured in
/// `tests/special_functions.rs`); underflows to 0 for x > 10.05.
#[inline]
pub fn erfc(x: f32) -> f32 {
    libm::erfc(f64::from(x)) as f32
}

/// erf in double precision (musl's algorithm via `libm`, < 1 ulp).
#[inline(always)]
pub(crate) fn erf64(x: f64) -> f64 {
    libm::erf(x)
}

/// erfc in double precision (musl's algorithm via `libm`, < 1 ulp, relative).
#[inline(always)]
pub(crate) fn erfc64(x: f64) -> f64 {
    libm::erfc(x)
}

/// The scaled complementary error function erfcx(u) = exp(u²) erfc(u), for u ≥ 0.
///
/// Below 25 it is the product of the two factors (relative error about u²·2⁻⁵³ ≤ 7e-14);
/// from 25 on, the asymptotic series 1/(u√π) Σ (−1)ⁿ (2n−1)!!/(2u²)ⁿ, whose terms fall
/// below 1e-17 after six of them.
#[inline]
pub(crate) fn erfcx64(u: f64) -> f64 {
    debug_assert!(u >= 0.0);
    if u < ERFCX_ASYMPTOTIC_FROM {
        return (u * u).exp() * erfc64(u);
    }
    let r = 1.0 / (2.0 * u * u);
    // 1 − r + 3r² − 15r³ + 105r⁴ − 945r⁵ + 10395r⁶
    let series = 1.0 - r * (1.0 - r * (3.0 - r * (15.0 - r * (105.0 - r * (945.0 - r * 10395.0)))));
    INV_SQRT_PI / u * series
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erfcx_is_continuous_at_the_switch() {
        let below = (ERFCX_ASYMPTOTIC_FROM * ERFCX_ASYMPTOTIC_FROM).exp() * erfc64(ERFCX_ASYMPTOTIC_FROM);
        let above = erfcx64(ERFCX_ASYMPTOTIC_FROM);
        assert!(((below - above) / above).abs() < 1e-13, "{below} vs {above}");
    }
}
