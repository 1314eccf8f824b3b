//! Beckmann visible normals by exact inversion of the visible-slope CDF (Jakob 2014,
//! “An Improved Visible Normal Sampling Routine for the Beckmann Distribution”, extended to
//! θ ∈ [0, π]): a tabulated initial guess, Halley steps on the CDF (above the horizon from a
//! piecewise fit of the Gaussian and its integral, below it from a fit of the tail ratio and a
//! table exponential) and, where their error estimate fails, a
//! safeguarded Halley iteration on the log-CDF, without the supplement's truncation of the tail
//! (`erf_min = −0.9999`). It is
//! [`Beckmann`]'s `sample_d_wi` (and so [`SmithVndf`](super::SmithVndf)`<Beckmann>`).

use super::Beckmann;
use crate::constants::SQRT_PI;
use crate::rng::cut_tails64;
use crate::slope::MicrosurfaceSlope;
use crate::slope::stretch::{Azimuth, stretch64};
use crate::special::{
    NO_LOG_BELOW, PSI_SERIES_FROM, ROUNDING_MAGIC, erfc_inv_f32, erfcx64, erfinv_central, exp_nonpositive,
    gaussian_integral_and_half, one_minus_scaled_erfcx, tail_ratio,
};
use crate::vector::ensure_visible;
use glam::Vec3;

/// The Halley–bisection iteration stops once its step is below this fraction of 1 + |x̃| (about
/// the f32 resolution of x̃). The error after that step is of order C·step² or less, where C, the
/// inverse of the lobe's width, reaches |cot θ| far below the horizon (see DESIGN.md, “Halley steps”, for why not
/// looser).
const HALLEY_TOLERANCE: f64 = 1e-7;
/// Halley's step n/(1 − c) is taken only for |c| up to this (else Newton's step n): it then
/// differs from Newton's by a factor in [2/3, 2].
const HALLEY_MAX_CORRECTION: f64 = 0.5;
/// The factor by which the iteration overestimates the error left after its last step,
/// |g″/(2g′)|·step² (the asymptotic error of a Newton step, which bounds Halley's).
const ERROR_ESTIMATE_SAFETY: f64 = 10.0;
/// The fast sampler accepts its Halley step when the estimated error of ln F (F the sampled
/// CDF) is below this: then |F(x̃) − u| is below it too.
const FAST_LN_CDF_TOLERANCE: f64 = 1e-7;
/// Halley steps of the fast sampler before it hands over to the safeguarded iteration.
const FAST_STEPS: usize = 4;
/// A hard cap on Halley–bisection iterations (never reached in the tests: typically 3–4).
const MAX_ITERATIONS: usize = 64;

/// A Beckmann visible normal for a unit ωi, exact for every ωi: the stretch–rotate–unstretch
/// step around [`visible_slope_x`] and [`gaussian_slope`], with the stretched cot θ formed in
/// double precision (far below the horizon the visible slopes lie within about 1/|cot θ| of
/// it, so an f32 rounding of cot θ, relative 6e-8, would shift them by a visible fraction of
/// their spread: 5 % at |cot θ| = 480). +z for ωi = −z, which sees no microsurface. No argument
/// check (the callers have done it).
#[must_use]
#[inline]
pub(crate) fn sample_visible_normal(beckmann: &Beckmann, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
    let (ax, ay) = (f64::from(beckmann.alpha_x()), f64::from(beckmann.alpha_y()));
    let v = stretch64(beckmann, wi);
    let len_xy = (v.x * v.x + v.y * v.y).sqrt();
    if len_xy.is_nan() || len_xy <= 0.0 {
        // vertical: any azimuth (φ = 0)
        let Some((x, y)) = visible_slopes(v.z, 0.0, u1, u2) else {
            return Vec3::Z;
        };
        return ensure_visible(wi, Azimuth::of(0.0, 0.0).unstretched_normal(ax, ay, x, y));
    }
    // one division for cot θ and the azimuth, and |cot θ|/(1 + |cot θ|) (the guess table's
    // coordinate) from its own, in parallel
    let inv_len = 1.0 / len_xy;
    let azimuth = Azimuth { cos_phi: v.x * inv_len, sin_phi: v.y * inv_len, len_xy };
    let y = gaussian_slope(f64::from(u2));
    let x = visible_slope_x(v.z * inv_len, v.z.abs() / (v.z.abs() + len_xy), f64::from(u1));
    ensure_visible(wi, azimuth.unstretched_normal(ax, ay, x, y))
}

/// The visible slopes (x̃, ỹ) of the α = 1 distribution seen from a direction of height `z`
/// and horizontal length `len_xy` ≥ 0 (not necessarily unit; cot θ = z/len_xy), in its
/// azimuth frame: x̃ from the exact inversion [`visible_slope_x`], ỹ Gaussian and independent
/// of x̃ ([`gaussian_slope`]). `None` seen from straight below (len_xy = 0, z ≤ 0), where
/// nothing is visible. Tails cut at 2⁻²⁴ (the crate's tail policy).
#[must_use]
#[inline]
pub(crate) fn visible_slopes(z: f64, len_xy: f64, u1: f32, u2: f32) -> Option<(f64, f64)> {
    let x = if len_xy > 0.0 {
        visible_slope_x(z / len_xy, z.abs() / (z.abs() + len_xy), f64::from(u1))
    } else if z > 0.0 {
        gaussian_slope(f64::from(u1))
    } else {
        return None;
    };
    Some((x, gaussian_slope(f64::from(u2))))
}

/// The quantile of the slope density exp(−x²)/√π: erf⁻¹(2u − 1), in single precision
/// (relative error below 4e-7, see `erfc_inv_f32`): for |2u − 1| ≤ 0.8 from the central
/// polynomial (`erfinv_central`, no logarithm, 80 % of the uniforms), else from the nearer end
/// of [0, 1]. Both tails are cut at probability 2⁻²⁴ (the crate's tail policy, `rng`): u = 0
/// gives x̃ = −3.744, with 2⁻²⁴ of the density below it, and u = 1 − 2⁻²⁴ gives +3.744.
#[must_use]
#[inline(always)]
pub(crate) fn gaussian_slope(u: f64) -> f64 {
    // in single precision: u is an f32 uniform or an f64 one that `erfc_inv_f32` reads in
    // single precision anyway
    let u = crate::rng::cut_tails(u as f32);
    // exact for u ≥ ¼; below, the rounding of 1 − 2u that the tail form makes too
    let y = 2.0 * u - 1.0;
    if y.abs() <= NO_LOG_BELOW {
        return f64::from(erfinv_central(y));
    }
    let tail = if u < 0.5 { u } else { 1.0 - u };
    // the sign without a branch (a coin flip)
    f64::from(erfc_inv_f32(tail).copysign(y))
}

/// ln S(x), its derivative g′ = (κ − x)e^{−x²}/S and g′/(κ − x) = e^{−x²}/S, where
/// S(x) = ∫₋∞ˣ (κ − t) e^{−t²} dt is (up to a constant factor) the unnormalized CDF of the
/// visible slopes, x < κ. One division (1/S or 1/ψ).
///
/// S(x) = κ(√π/2) erfc(−x) + e^{−x²}/2. For x < 0 it is written e^{−u²} ψ(u)/2 with u = −x
/// and ψ(u) = 1 + κ√π erfcx(u), so that the Gaussian factor is carried as a logarithm and
/// never underflows. For κ < 0 (ωi below the horizon) ψ is a small difference; beyond
/// `PSI_SERIES_FROM` it is evaluated as ((u + κ) + (−κ) r(u))/u with
/// r(u) = 1 − √π u erfcx(u) from its asymptotic series, free of cancellation.
#[inline]
fn ln_s(kappa: f64, x: f64) -> (f64, f64, f64) {
    if x >= 0.0 {
        // erfc(x) = e^{−x²} erfcx(x): one exponential
        let gauss = (-x * x).exp();
        let s = kappa * 0.5 * SQRT_PI * (2.0 - gauss * erfcx64(x)) + 0.5 * gauss;
        let over_gap = gauss / s;
        return (s.ln(), (kappa - x) * over_gap, over_gap);
    }
    let u = -x;
    let psi = if kappa >= 0.0 || u < PSI_SERIES_FROM {
        1.0 + kappa * SQRT_PI * erfcx64(u)
    } else {
        // 1 + κ√π erfcx(u) = (u + κ − κ r(u))/u, with u + κ = κ − x
        ((kappa - x) - kappa * one_minus_scaled_erfcx(u)) / u
    };
    let over_gap = 2.0 / psi;
    (-u * u + (0.5 * psi).ln(), (kappa - x) * over_gap, over_gap)
}

/// Samples x̃ < κ from the density ∝ (κ − x̃) e^{−x̃²}: the visible slopes at α = 1 seen from
/// cot θ = κ (any sign), by solving F(x̃) = S(x̃)/S(κ) = u. `s` = |κ|/(1 + |κ|), the guess
/// table's coordinate (formed by the caller in parallel with κ).
///
/// A tabulated initial guess ([`GuessTable`], bilinear in (s, u)) followed by up to
/// `FAST_STEPS` Halley steps on the residual g = F(x̃)/u − 1 of [`Residual`], in linear space on
/// both sides of the horizon and without a logarithm, an erfcx or a library exponential:
/// above the horizon (κ ≥ 0) from the piecewise fit of the Gaussian and its integral
/// (`gaussian_integral_and_half`, no branch on the sign of x̃), below it from the fit of the
/// tail ratio r (`tail_ratio`) and one `exp_nonpositive`. g′ and g″ need no division. A step
/// is accepted when its a-posteriori error estimate, `ERROR_ESTIMATE_SAFETY`·(g″/g′)²·|step|³
/// plus `ERROR_ESTIMATE_SAFETY`·|g‴/g′|·|step|³/6 for Halley's step (its error is
/// (c₂² − c₃)·e³ with c_k = g⁽ᵏ⁾/(k! g′): the c₃ term dominates far below the horizon, where
/// F ∝ e^{−2|κ|t}) or ½·`ERROR_ESTIMATE_SAFETY`·|g″/g′|·step² for Newton's, times g′ (the
/// relative error of F) is below `FAST_LN_CDF_TOLERANCE`;
/// otherwise, after `FAST_STEPS` steps (or when a step leaves the bracket its evaluations
/// established), the safeguarded f64 iteration of [`visible_slope_x_above`] continues within
/// that bracket.
///
/// Error bound of the sampled CDF F: |F(x̃) − u| ≤ 1e-7·u + 1e-10 above the horizon (the step's
/// acceptance plus the fit's absolute error, below 5e-12 for A and 9e-12 for B, against
/// S(κ) ≥ ½) and below it for |κ| ≤ 64 where the fast steps decide (the step's acceptance plus
/// the relative errors of r, 1e-10, and of the exponential, 4e-15) — measured on a grid with the
/// extreme uniforms, which none of them leaves to the fallback; in every case (the fallback
/// included, whose f32 resolution of x̃ then dominates) below 2e-7 for |κ| ≤ 64 and below 1e-5
/// for |κ| ≤ 400 (`fast_visible_slope_meets_its_cdf_bound*`). The tails are cut as in
/// [`visible_slope_x_above`].
#[inline]
fn visible_slope_x(kappa: f64, s: f64, u: f64) -> f64 {
    let u = cut_tails64(u);
    let x = GuessTable::get().guess(kappa, s, u);
    if x.is_nan() || x >= kappa {
        #[cfg(test)]
        tests::FALLBACKS.with(|n| n.set(n.get() + 1));
        return visible_slope_x_above(kappa, f64::NEG_INFINITY, u);
    }
    let residual = Residual::new(kappa, u);
    // the first step straight-line (it is almost always accepted: its values stay in
    // registers), the others in a loop
    let (mut x, mut lo, mut hi) = match fast_step(residual, x, f64::NEG_INFINITY, kappa) {
        Step::Accepted(x) => return x,
        Step::Continue(x, lo, hi) => (x, lo, hi),
        Step::Fallback(x, lo, hi) => return fallback(kappa, u, x, lo, hi),
    };
    for _ in 1..FAST_STEPS {
        (x, lo, hi) = match fast_step(residual, x, lo, hi) {
            Step::Accepted(x) => return x,
            Step::Continue(x, lo, hi) => (x, lo, hi),
            Step::Fallback(x, lo, hi) => return fallback(kappa, u, x, lo, hi),
        };
    }
    fallback(kappa, u, x, lo, hi)
}

/// The outcome of one fast step of [`visible_slope_x`].
#[derive(Debug, Clone, Copy)]
enum Step {
    /// The new x̃, within the tolerance (inside the bracket, so below κ).
    Accepted(f64),
    /// The new x̃ and the bracket (lo, hi) of the root, for another step.
    Continue(f64, f64, f64),
    /// The step left the bracket or the residual could not be evaluated: x̃ and the bracket
    /// for the fallback iteration.
    Fallback(f64, f64, f64),
}

/// One Halley (or Newton) step of [`visible_slope_x`] on `residual` from x̃ = `x` inside the
/// bracket (`lo`, `hi`), with its a-posteriori acceptance test.
#[inline(always)]
fn fast_step(residual: Residual, x: f64, mut lo: f64, mut hi: f64) -> Step {
    let Some((g, derivative, second, third)) = residual.at(x) else {
        return Step::Fallback(x, lo, hi);
    };
    if g > 0.0 {
        hi = x;
    } else {
        lo = x;
    }
    // the step of `refine`: Halley's where its correction is small, else Newton's
    let d2 = derivative * derivative;
    let halley = (g * second).abs() <= 2.0 * HALLEY_MAX_CORRECTION * d2;
    let next = if halley { x - g * derivative / (d2 - 0.5 * g * second) } else { x - g / derivative };
    if !(next > lo && next < hi) {
        return Step::Fallback(x, lo, hi);
    }
    let step = (next - x).abs();
    // the error estimate of x̃ times g′/(u S(κ)) (g′ > 0 here: the step stayed finite), the
    // relative error of F, without dividing by g′ or u S(κ):
    // ERROR_ESTIMATE_SAFETY·((g″/g′)² + |g‴/g′|/6)·|step|³·g′ for Halley's step,
    // ½·ERROR_ESTIMATE_SAFETY·|g″/g′|·step²·g′ for Newton's
    let tolerance = FAST_LN_CDF_TOLERANCE * residual.norm();
    let accepted = if halley {
        ERROR_ESTIMATE_SAFETY
            * (second * second + third.abs() * derivative * (1.0 / 6.0))
            * step
            * step
            * step
            <= tolerance * derivative
    } else {
        ERROR_ESTIMATE_SAFETY * 0.5 * second.abs() * step * step <= tolerance
    };
    if accepted { Step::Accepted(next) } else { Step::Continue(next, lo, hi) }
}

/// The fallback of [`visible_slope_x`]: the safeguarded f64 iteration of
/// [`visible_slope_x_above`] from x̃ = `x` within the bracket (`lo`, `hi`).
#[cold]
#[inline(never)]
fn fallback(kappa: f64, u: f64, x: f64, lo: f64, hi: f64) -> f64 {
    #[cfg(test)]
    tests::FALLBACKS.with(|n| n.set(n.get() + 1));
    let target = ln_s(kappa, kappa).0 + u.ln();
    refine(kappa, target, x, lo, hi).min(kappa)
}

/// The residual of the fast steps of [`visible_slope_x`] and its first three derivatives, on
/// either side of the horizon: g = (F(x̃) − u)·S(κ)·c for the visible-slope CDF
/// F = S(x̃)/S(κ) and a positive constant c (g/(u S(κ) c) = F/u − 1 is the relative error of
/// F, [`Residual::norm`] = u S(κ) c; no division by it).
#[derive(Debug, Clone, Copy)]
enum Residual {
    /// κ ≥ 0: g = S(x̃) − u S(κ) with S = κA + B from the fit of the Gaussian and its integral
    /// (c = 1); `norm` = u S(κ).
    Above { kappa: f64, norm: f64 },
    /// κ = −m < 0: with v = −x̃ and t = κ − x̃ = v − m > 0, S(x̃) = e^{−v²} ψ(v)/2 with
    /// ψ(v) = 1 − m√π erfcx(v) = (t + m r(v))/v (both terms positive: no cancellation) and
    /// S(κ) = e^{−m²} r(m)/2, so F = e^{−t(m + v)} ψ(v)/r(m); g = e^{−t(m + v)} ψ(v) − u r(m)
    /// (c = 2e^{m²}), g′ = 2t e^{−t(m + v)}; `norm` = u r(m).
    Below { m: f64, norm: f64 },
}

impl Residual {
    #[inline(always)]
    fn new(kappa: f64, u: f64) -> Self {
        if kappa < 0.0 {
            let m = -kappa;
            return Self::Below { m, norm: u * tail_ratio(m, 1.0 / m) };
        }
        // S(κ) = κA(κ) + B(κ), κ√π to double precision from `GAUSS_NEGLIGIBLE_FROM` on (inside
        // the fit: the f64 form is the never-taken alternative)
        let s_kappa = if kappa < GAUSS_NEGLIGIBLE_FROM {
            gaussian_integral_and_half(kappa)
                .map_or_else(|| s_nonnegative(kappa, kappa), |(a, b)| kappa * a + b)
        } else {
            kappa * SQRT_PI
        };
        Self::Above { kappa, norm: u * s_kappa }
    }

    /// u S(κ) c: the residual's scale (g/norm = F/u − 1).
    #[inline(always)]
    fn norm(self) -> f64 {
        match self {
            Self::Above { norm, .. } | Self::Below { norm, .. } => norm,
        }
    }

    /// (g, g′, g″, g‴) at x̃ < κ; `None` below the fit (x̃ < −4.5 above the horizon,
    /// beyond the lowest sample: the fallback takes over). Below the horizon a hopeless x̃
    /// (F underflowing, far beyond the lowest sample) gives g′ = 0, and the step leaves the
    /// bracket.
    #[inline(always)]
    fn at(self, x: f64) -> Option<(f64, f64, f64, f64)> {
        match self {
            Self::Above { kappa, norm } => {
                let (a, b) = gaussian_integral_and_half(x)?;
                let derivative = 2.0 * (kappa - x) * b;
                // B′ = −2x̃B
                let second = -2.0 * b - 2.0 * x * derivative;
                let third = 4.0 * x * b - 2.0 * derivative - 2.0 * x * second;
                Some(((kappa * a + b) - norm, derivative, second, third))
            }
            Self::Below { m, norm } => {
                let v = -x;
                let t = v - m;
                let inv_v = 1.0 / v;
                let psi = (t + m * tail_ratio(v, inv_v)) * inv_v;
                let gauss = exp_nonpositive(-t * (m + v));
                let derivative = 2.0 * t * gauss;
                // d/dx̃ e^{−t(m + v)} = 2v e^{−t(m + v)}, dt/dx̃ = dv/dx̃ = −1
                let second = 2.0 * gauss * (2.0 * t * v - 1.0);
                let third = 2.0 * gauss * (2.0 * v * (2.0 * t * v - 1.0) - 2.0 * (t + v));
                Some((gauss * psi - norm, derivative, second, third))
            }
        }
    }
}

/// S(x̃) = κ(√π/2) erfc(−x̃) + e^{−x̃²}/2 for x̃ ≥ 0 (then κ ≥ x̃ ≥ 0 and S ≥ 1/2·e^{−x̃²}).
#[inline(always)]
fn s_nonnegative(kappa: f64, x: f64) -> f64 {
    let gauss = (-x * x).exp();
    kappa * 0.5 * SQRT_PI * (2.0 - gauss * erfcx64(x)) + 0.5 * gauss
}

/// From this κ on, S(κ) = κ√π − κ(√π/2)erfc(κ) + e^{−κ²}/2 is κ√π to double precision (the other
/// terms are below 2.4e-16 of it).
const GAUSS_NEGLIGIBLE_FROM: f64 = 6.0;

/// Cells of the initial-guess table along s = |κ|/(1 + |κ|) ∈ [0, 1].
const GUESS_KAPPA_CELLS: usize = 32;
/// Cells of the initial-guess table along u ∈ [0, 1].
const GUESS_U_CELLS: usize = 128;
/// |κ| at which the nodes at s = 1 are solved: beyond it the quantiles normalized by
/// m + √(m² + 1) change by less than 1e-8.
const GUESS_KAPPA_LIMIT: f64 = 1e4;

/// √(−ln u) at the nodes of the guess table's first cell in u, 2⁻²⁴ (the cut tail) and 1/128,
/// and √(−ln(1 − u)) at those of its last cell, 1 − 2⁻²⁴ and 127/128.
const TAIL_CELL_W: (f64, f64) = (4.078_667_960_675_236, 2.202_732_454_003_349_3);

/// The initial guess of [`visible_slope_x`]: the exact quantile (from [`visible_slope_x_above`])
/// at the nodes of a grid in s = |κ|/(1 + |κ|) and u, interpolated bilinearly. Above the horizon
/// (κ ≥ 0) it holds x̃ itself (which tends to the Gaussian quantile as κ → ∞); below, the
/// normalized distance τ = (κ − x̃)(1 + m), m = −κ, which tends to half the quantile of the
/// Gamma(2) survival (1 + τ)e^{−τ} = u as κ → −∞ (the lobe's width is 1/(2m) there), so that
/// the guess keeps its relative accuracy in the thin lobes far below the horizon; 1/(1 + m) is
/// 1 − s, no division. The nodes at s = 1 hold that limit (solved at m = 10⁴, normalized by
/// (m + √(m² + 1))/2, which converges faster). Built on first use (33 × 129 × 2 solves, about
/// 2 ms), 34 KB.
struct GuessTable {
    above: [[f32; GUESS_U_CELLS + 1]; GUESS_KAPPA_CELLS + 1],
    below: [[f32; GUESS_U_CELLS + 1]; GUESS_KAPPA_CELLS + 1],
}

impl GuessTable {
    /// The table, built on first use.
    #[inline(always)]
    fn get() -> &'static Self {
        static TABLE: std::sync::OnceLock<GuessTable> = std::sync::OnceLock::new();
        TABLE.get_or_init(Self::build)
    }

    fn build() -> Self {
        let mut table = Self {
            above: [[0.0; GUESS_U_CELLS + 1]; GUESS_KAPPA_CELLS + 1],
            below: [[0.0; GUESS_U_CELLS + 1]; GUESS_KAPPA_CELLS + 1],
        };
        for i in 0..=GUESS_KAPPA_CELLS {
            let s = i as f64 / GUESS_KAPPA_CELLS as f64;
            let (m, normalizer) = if i == GUESS_KAPPA_CELLS {
                let m = GUESS_KAPPA_LIMIT;
                (m, 0.5 * (m + (m * m + 1.0).sqrt()))
            } else {
                let m = s / (1.0 - s);
                (m, 1.0 + m)
            };
            for j in 0..=GUESS_U_CELLS {
                let u = j as f64 / GUESS_U_CELLS as f64;
                table.above[i][j] = visible_slope_x_above(m, f64::NEG_INFINITY, u) as f32;
                let x = visible_slope_x_above(-m, f64::NEG_INFINITY, u);
                table.below[i][j] = ((-m - x) * normalizer) as f32;
            }
        }
        table
    }

    /// The interpolated guess of x̃ for u ∈ [0, 1], given s = |κ|/(1 + |κ|) (may equal or
    /// exceed κ where the table is coarse, next to u = 1). Bilinear, but in the first cell in
    /// u (u < 1/128, whose node at u = 0 holds the quantile at 2⁻²⁴, where the tails are cut)
    /// linear in w = √(−ln u) instead (`first_cell_guess`), and above the horizon in the last
    /// one (u > 127/128, its node at u = 1 holding the quantile at 1 − 2⁻²⁴) linear in
    /// √(−ln(1 − u)) (`last_cell_guess`): the quantile is singular in u there and about linear
    /// in these (exactly −√(−ln u) at κ = 0; the Gaussian quantile's tails for large κ).
    /// Bilinear guesses sent most of these uniforms to the fallback.
    #[inline(always)]
    fn guess(&self, kappa: f64, s: f64, u: f64) -> f64 {
        if u < 1.0 / GUESS_U_CELLS as f64 {
            return self.first_cell_guess(kappa, s, u);
        }
        if u > 1.0 - 1.0 / GUESS_U_CELLS as f64 && kappa >= 0.0 {
            return self.last_cell_guess(kappa, s, u);
        }
        self.interpolate(kappa, s, u, None)
    }

    /// [`GuessTable::guess`] in the first cell in u (out of line: 1/128 of the uniforms).
    #[cold]
    #[inline(never)]
    fn first_cell_guess(&self, kappa: f64, s: f64, u: f64) -> f64 {
        let w = (-u.ln()).sqrt();
        let weight = ((TAIL_CELL_W.0 - w) / (TAIL_CELL_W.0 - TAIL_CELL_W.1)) as f32;
        self.interpolate(kappa, s, u, Some(weight))
    }

    /// [`GuessTable::guess`] in the last cell in u above the horizon, linear in
    /// w = √(−ln(1 − u)) (out of line: 1/128 of the uniforms).
    #[cold]
    #[inline(never)]
    fn last_cell_guess(&self, kappa: f64, s: f64, u: f64) -> f64 {
        let w = (-(1.0 - u).ln()).sqrt();
        let weight = ((w - TAIL_CELL_W.1) / (TAIL_CELL_W.0 - TAIL_CELL_W.1)) as f32;
        self.interpolate(kappa, s, u, Some(weight))
    }

    /// The table interpolated at (s, u), bilinearly or with the given weight in u.
    #[inline(always)]
    fn interpolate(&self, kappa: f64, s: f64, u: f64, u_weight: Option<f32>) -> f64 {
        // s ∈ [0, 1] and u ∈ [0, 1]: the cells are the nearest integers of CELLS·s − ½ and
        // CELLS·u − ½ (the floor but at a tie, where either cell interpolates the node), in
        // [0, CELLS − 1], formed by rounding with `ROUNDING_MAGIC` (cheaper than an f64 → u32
        // conversion's saturation); the weights are in [0, 1]
        let fs = s * GUESS_KAPPA_CELLS as f64;
        let i = ((fs - 0.5 + ROUNDING_MAGIC).to_bits() as u32).min(GUESS_KAPPA_CELLS as u32 - 1);
        let a = (fs - f64::from(i)) as f32;
        let fu = u * GUESS_U_CELLS as f64;
        let j = ((fu - 0.5 + ROUNDING_MAGIC).to_bits() as u32).min(GUESS_U_CELLS as u32 - 1);
        let b = u_weight.unwrap_or((fu - f64::from(j)) as f32);
        let (i, j) = (i as usize, j as usize);
        let rows = if kappa < 0.0 { &self.below } else { &self.above };
        let (r0, r1) = (&rows[i], &rows[i + 1]);
        let v0 = r0[j] + b * (r0[j + 1] - r0[j]);
        let v1 = r1[j] + b * (r1[j + 1] - r1[j]);
        let v = f64::from(v0 + a * (v1 - v0));
        // below the horizon x̃ = κ − τ/(1 + m) = κ − τ(1 − s)
        if kappa < 0.0 { kappa - v * (1.0 - s) } else { v }
    }
}

/// Like [`visible_slope_x`], restricted to x̃ ∈ [`lower`, κ) (`lower` may be −∞): solves
/// S(x̃) = S(lower) + u (S(κ) − S(lower)) in log space. Used by the V-cavity sampler, whose
/// unmasked part is the Smith VNDF limited to slopes above 3 cot θ (Tokuyoshi, listing 5).
///
/// u is cut to [2⁻²⁴, 1 − 2⁻²⁴] (the crate's tail policy, `rng`): the lowest sample has 2⁻²⁴ of
/// the visible slopes below it, the highest 2⁻²⁴ between it and κ (where the density vanishes).
#[must_use]
#[inline]
pub(crate) fn visible_slope_x_above(kappa: f64, lower: f64, u: f64) -> f64 {
    let u = cut_tails64(u);
    let ln_u = u.ln();
    let ln_s_kappa = ln_s(kappa, kappa).0;
    let (target, lo) = if lower > f64::NEG_INFINITY && lower < kappa {
        let r = (ln_s(kappa, lower).0 - ln_s_kappa).exp();
        (ln_s_kappa + (r + u * (1.0 - r)).ln(), lower)
    } else {
        (ln_s_kappa + ln_u, f64::NEG_INFINITY)
    };
    // initial guess from the model survival e^{−(2m t + t²)} with t = κ − x̃ and m = max(−κ, 0),
    // corrected for the linear factor t; exact at κ = 0
    let big_l = -ln_u + (-ln_u).ln_1p();
    let m = (-kappa).max(0.0);
    let t0 = if kappa >= 0.0 {
        // above the horizon the Gaussian quantile is an upper bound of the root
        let x_gauss = gaussian_slope(u);
        (kappa - x_gauss).max(big_l / (m + (m * m + big_l).sqrt()))
    } else {
        big_l / (m + (m * m + big_l).sqrt())
    };
    let mut x = kappa - t0.max(f64::MIN_POSITIVE);
    if x <= lo {
        x = 0.5 * (lo + kappa);
    }
    refine(kappa, target, x, lo, kappa)
}

/// The safeguarded Halley–Newton–bisection iteration of [`visible_slope_x_above`] for
/// ln S(x̃) = `target`, from `x` inside the bracket (`lo`, `hi`) (`lo` may be −∞).
#[inline]
fn refine(kappa: f64, target: f64, mut x: f64, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..MAX_ITERATIONS {
        let (value, derivative, over_gap) = ln_s(kappa, x);
        let g = value - target;
        if g > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        // Halley's step g g′/(g′² − g g″/2) with g″ = −g′/(κ − x̃) − g′(2x̃ + g′) (from
        // S′ = (κ − x̃)e^{−x̃²}) costs no further evaluation and converges cubically. Where its
        // correction c = g g″/(2g′²) exceeds ½ in magnitude (near κ the curvature diverges,
        // and Halley's step would vanish far from the root) Newton's step g/g′ is taken
        let second = -over_gap - derivative * (2.0 * x + derivative);
        let d2 = derivative * derivative;
        let halley = (g * second).abs() <= 2.0 * HALLEY_MAX_CORRECTION * d2;
        let mut next = if halley { x - g * derivative / (d2 - 0.5 * g * second) } else { x - g / derivative };
        let bracketed = next > lo && next < hi;
        if !bracketed {
            next = if lo.is_finite() { 0.5 * (lo + hi) } else { x - 2.0 * (hi - x) - 1.0 };
        }
        let step = next - x;
        x = next;
        let tolerance = HALLEY_TOLERANCE * (1.0 + x.abs());
        // a Newton or Halley step from error e leaves about |g″/(2g′)| e² or less: stop when
        // that estimate (with a safety factor) is below the tolerance, one evaluation early
        if step.abs() <= tolerance
            || (bracketed
                && ERROR_ESTIMATE_SAFETY * 0.5 * second.abs() * step * step <= tolerance * derivative)
        {
            break;
        }
    }
    x.min(kappa)
}

#[cfg(test)]
mod tests {
    use super::*;

    // How often the fast sampler took its fallback iteration (on this thread).
    thread_local! {
        pub(super) static FALLBACKS: core::cell::Cell<usize> = const { core::cell::Cell::new(0) };
    }

    /// [`visible_slope_x`] with its table coordinate formed from κ.
    fn fast(kappa: f64, u: f64) -> f64 {
        visible_slope_x(kappa, kappa.abs() / (1.0 + kappa.abs()), u)
    }

    /// The sampled CDF at the fast sampler's x̃ against the exact (f64) CDF, over a grid of
    /// κ = ±s/(1 − s) and u; returns the worst |F(x̃) − u| for |κ| ≤ `kappa_max`, its κ and u,
    /// and the fraction of samples that take the fallback iteration.
    fn worst_cdf_error(kappa_max: f64, sampler: fn(f64, f64) -> f64) -> (f64, f64, f64) {
        let (mut worst, mut at_k, mut at_u) = (0.0f64, 0.0, 0.0);
        for i in 0..=400 {
            let s = i as f64 / 401.0;
            let m = s / (1.0 - s);
            if m > kappa_max {
                break;
            }
            for kappa in [m, -m] {
                let ln_s_kappa = ln_s(kappa, kappa).0;
                for j in 0..=250 {
                    let u = cut_tails64((j as f64 + 0.37) / 251.0);
                    let x = sampler(kappa, u);
                    let cdf = (ln_s(kappa, x).0 - ln_s_kappa).exp();
                    let err = (cdf - u).abs();
                    if err > worst {
                        (worst, at_k, at_u) = (err, kappa, u);
                    }
                }
            }
        }
        (worst, at_k, at_u)
    }

    /// The documented bound of the fast sampler's CDF error for |κ| ≤ 64.
    const FAST_CDF_MAX_ERROR: f64 = 2e-7;
    /// Its bound for |κ| ≤ 400, where the f32 rounding of x̃ (tolerance of the fallback
    /// iteration, `HALLEY_TOLERANCE`·(1 + |x̃|)) dominates: below that of the iteration alone.
    const FAST_CDF_MAX_ERROR_FAR: f64 = 1e-5;
    /// The largest fraction of the grid's samples allowed to take the fallback iteration.
    const FAST_MAX_FALLBACK_FRACTION: f64 = 0.005;

    /// The documented bound above the horizon (and below it for |κ| ≤ 64):
    /// |F(x̃) − u| ≤ `ABOVE_RELATIVE`·u + `ABOVE_ABSOLUTE`.
    const ABOVE_RELATIVE: f64 = 1e-7;
    const ABOVE_ABSOLUTE: f64 = 1e-10;

    /// The largest |F(x̃) − u| − 1e-7·u of the fast sampler on one side of the horizon (`sign`
    /// of κ), over the κ of `worst_cdf_error` up to |κ| ≤ `kappa_max` and its uniforms plus
    /// the extreme ones; with its κ and u, the number of samples and the largest |F − u|.
    fn worst_relative_excess(sign: f64, kappa_max: f64) -> (f64, f64, f64, usize, f64) {
        let tails = [0.0, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1.0 - 1e-5, 1.0 - 1e-6, 1.0];
        let (mut worst, mut at_k, mut at_u) = (f64::NEG_INFINITY, 0.0, 0.0);
        let (mut checked, mut largest) = (0usize, 0.0f64);
        for i in 0..=400 {
            let s = i as f64 / 401.0;
            let kappa = sign * s / (1.0 - s);
            if kappa.abs() > kappa_max {
                break;
            }
            let ln_s_kappa = ln_s(kappa, kappa).0;
            let grid = (0..=250).map(|j| (j as f64 + 0.37) / 251.0);
            for u in grid.chain(tails) {
                let u = cut_tails64(u);
                let x = fast(kappa, u);
                let cdf = (ln_s(kappa, x).0 - ln_s_kappa).exp();
                let excess = (cdf - u).abs() - ABOVE_RELATIVE * u;
                largest = largest.max((cdf - u).abs());
                checked += 1;
                if excess > worst {
                    (worst, at_k, at_u) = (excess, kappa, u);
                }
            }
        }
        (worst, at_k, at_u, checked, largest)
    }

    /// Above the horizon, on the grid of `worst_cdf_error` plus the extreme uniforms, the
    /// error of the sampled CDF is within 1e-7·u + 1e-10 (the step's acceptance plus the
    /// Gaussian fit's absolute error).
    #[test]
    fn fast_visible_slope_meets_its_cdf_bound_above_the_horizon() {
        let (worst, at_k, at_u, checked, largest) = worst_relative_excess(1.0, f64::INFINITY);
        eprintln!(
            "fast sampler above the horizon: {checked} samples, worst |F − u| − {ABOVE_RELATIVE:e}·u = {worst:.3e} at κ = {at_k}, u = {at_u}; largest |F − u| {largest:.3e}"
        );
        assert!(
            worst <= ABOVE_ABSOLUTE,
            "|F − u| exceeds {ABOVE_RELATIVE:e}·u by {worst:e} > {ABOVE_ABSOLUTE:e} at κ = {at_k}, u = {at_u}"
        );
    }

    /// Below the horizon, for |κ| ≤ 64, the same bound 1e-7·u + 1e-10 on the grid plus the
    /// extreme uniforms (the step's acceptance plus the relative errors of the tail-ratio fit
    /// and the exponential, 1e-10 and 4e-15).
    #[test]
    fn fast_visible_slope_meets_its_cdf_bound_below_the_horizon() {
        let (worst, at_k, at_u, checked, largest) = worst_relative_excess(-1.0, 64.0);
        eprintln!(
            "fast sampler below the horizon, |κ| ≤ 64: {checked} samples, worst |F − u| − {ABOVE_RELATIVE:e}·u = {worst:.3e} at κ = {at_k}, u = {at_u}; largest |F − u| {largest:.3e}"
        );
        assert!(
            worst <= ABOVE_ABSOLUTE,
            "|F − u| exceeds {ABOVE_RELATIVE:e}·u by {worst:e} > {ABOVE_ABSOLUTE:e} at κ = {at_k}, u = {at_u}"
        );
    }

    /// The tabulated constants of the first cell in u.
    #[test]
    fn tail_cell_constants() {
        let ln2 = core::f64::consts::LN_2;
        assert!((TAIL_CELL_W.0 - (24.0 * ln2).sqrt()).abs() <= 4.0 * f64::EPSILON);
        assert!((TAIL_CELL_W.1 - (7.0 * ln2).sqrt()).abs() <= 4.0 * f64::EPSILON);
        assert_eq!(cut_tails64(0.0), 2f64.powi(-24));
        assert_eq!(cut_tails64(1.0), 1.0 - 2f64.powi(-24));
    }

    #[test]
    fn fast_visible_slope_meets_its_cdf_bound() {
        let (near, k, u) = worst_cdf_error(64.0, fast);
        eprintln!("fast sampler, |κ| ≤ 64: worst |F − u| {near:.3e} at κ = {k}, u = {u}");
        FALLBACKS.with(|n| n.set(0));
        let (far, k, u) = worst_cdf_error(400.0, fast);
        let fallbacks = FALLBACKS.with(|n| n.get());
        eprintln!("fast sampler, |κ| ≤ 400: worst |F − u| {far:.3e} at κ = {k}, u = {u}");
        let (old, k, u) = worst_cdf_error(400.0, |k, u| visible_slope_x_above(k, f64::NEG_INFINITY, u));
        eprintln!("iteration alone, |κ| ≤ 400: worst |F − u| {old:.3e} at κ = {k}, u = {u}");
        // the fallback from the table's guess (which the fast steps now rarely hand over to)
        let (from_guess, k, u) = worst_cdf_error(400.0, |k, u| {
            let x = GuessTable::get().guess(k, k.abs() / (1.0 + k.abs()), u);
            fallback(k, u, x.min(k), f64::NEG_INFINITY, k)
        });
        eprintln!("fallback from the guess, |κ| ≤ 400: worst |F − u| {from_guess:.3e} at κ = {k}, u = {u}");
        assert!(
            from_guess <= FAST_CDF_MAX_ERROR_FAR,
            "fallback: |F − u| = {from_guess:e} > {FAST_CDF_MAX_ERROR_FAR:e} for |κ| ≤ 400"
        );
        // the grid of `worst_cdf_error(400.0, ..)`: 2 · 400 κ (s < 400/401) by 251 u
        let fraction = fallbacks as f64 / (2.0 * 400.0 * 251.0);
        eprintln!("fallback fraction {fraction:.4} ({fallbacks} calls)");
        assert!(near <= FAST_CDF_MAX_ERROR, "|F − u| = {near:e} > {FAST_CDF_MAX_ERROR:e} for |κ| ≤ 64");
        assert!(
            far <= FAST_CDF_MAX_ERROR_FAR,
            "|F − u| = {far:e} > {FAST_CDF_MAX_ERROR_FAR:e} for |κ| ≤ 400"
        );
        assert!(
            fraction <= FAST_MAX_FALLBACK_FRACTION,
            "fallback fraction {fraction} > {FAST_MAX_FALLBACK_FRACTION}"
        );
    }
}
