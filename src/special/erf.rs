//! The error function and its complements.

/// The error function erf(x) = 2/√π ∫₀ˣ exp(−t²) dt.
///
/// Defined for every finite x, and erf(±∞) = ±1. Evaluated in double precision and rounded
/// once, so the result is within 1 ulp of the exact value (measured maximum: see
/// `tests/special/functions.rs`, 1 ulp).
#[must_use]
#[inline]
pub fn erf(x: f32) -> f32 {
    libm::erf(f64::from(x)) as f32
}

/// The complementary error function erfc(x) = 1 − erf(x), accurate in its tails.
///
/// Relative error within 1 ulp where the result is a normal f32 (measured in
/// `tests/special/functions.rs`); underflows to 0 for x > 10.05.
#[must_use]
#[inline]
pub fn erfc(x: f32) -> f32 {
    libm::erfc(f64::from(x)) as f32
}

/// erf in double precision (musl's algorithm via `libm`, < 1 ulp).
#[must_use]
#[inline(always)]
pub(crate) fn erf64(x: f64) -> f64 {
    libm::erf(x)
}

/// erfc in double precision (musl's algorithm via `libm`, < 1 ulp, relative).
#[must_use]
#[inline(always)]
pub(crate) fn erfc64(x: f64) -> f64 {
    libm::erfc(x)
}
