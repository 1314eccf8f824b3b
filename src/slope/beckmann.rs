//! The Beckmann slope distribution.

use super::{
    MicrosurfaceSlope, check_roughness, ensure_visible, is_direction, is_direction64, is_uniform,
    normal_from_slopes,
};
use crate::error::Error;
use crate::rng::cut_tails64;
use crate::special::{erfc_inv_f32, erfcx64};
use glam::{DVec3, Vec2, Vec3};

/// √π.
const SQRT_PI: f64 = 1.772_453_850_905_516;
/// 1/√π.
const INV_SQRT_PI: f64 = 0.564_189_583_547_756_3;
/// 1/π.
const INV_PI: f64 = core::f64::consts::FRAC_1_PI;
/// From this u = −x̃ on, 1 − m√π erfcx(u) is evaluated by its asymptotic series (which is free
/// of the cancellation the direct form suffers for large u).
const PSI_SERIES_FROM: f64 = 8.0;
/// The iteration stops once its step is below this fraction of 1 + |x̃| (about the f32 resolution
/// of x̃). The error after that step is of order C·step² or less, where C, the inverse of the
/// lobe's width, reaches |cot θ| far below the horizon: a looser stop (3e-5 was tried with
/// Newton steps) biases those thin lobes measurably.
const NEWTON_TOLERANCE: f64 = 1e-7;
/// Below this cos θm, D is 0 in double precision for every roughness an f32 holds.
const D_VANISHES_BELOW_COS: f64 = 1e-100;
/// Below this projected area (a ≈ 26 from below) D_ωi is evaluated in log space.
const AREA_LOG_SPACE_BELOW: f64 = 1e-280;
/// Halley's step n/(1 − c) is taken only for |c| up to this (else Newton's step n): it then
/// differs from Newton's by a factor in [2/3, 2].
const HALLEY_MAX_CORRECTION: f64 = 0.5;
/// The factor by which the iteration overestimates the error left after its last step,
/// |g″/(2g′)|·step² (the asymptotic error of a Newton step, which bounds Halley's).
const ERROR_ESTIMATE_SAFETY: f64 = 10.0;
/// A hard cap on Halley–bisection iterations (never reached in the tests: typically 3–4).
const MAX_ITERATIONS: usize = 64;

/// The anisotropic Beckmann slope distribution (Heitz et al. 2016, supplement §2.2):
///
/// P²²(x̃, ỹ) = exp(−x̃²/αx² − ỹ²/αy²) / (π αx αy),
/// Λ(ω) = (erf(a) − 1)/2 + exp(−a²)/(2a√π) with a = 1/(αᵢ tan θ).
///
/// Λ, D, D_ωi and the projected area are evaluated in double precision with forms that
/// avoid the cancellation of erf(a) − 1 (they use erfc). Visible normals are sampled
/// exactly by inverting the visible-slope CDF (Jakob 2014, extended to θ ∈ [0, π]) with a
/// safeguarded Halley iteration on the log-CDF, without the supplement's truncation of the
/// tail (`erf_min = −0.9999`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Beckmann {
    alpha_x: f32,
    alpha_y: f32,
    /// 1/αx, 1/αy and 1/(π αx αy) in double precision (D needs no division by them).
    inv_alpha_x: f64,
    inv_alpha_y: f64,
    d_scale: f64,
}

impl Beckmann {
    /// An anisotropic Beckmann distribution.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `alpha_x` or `alpha_y` is NaN, infinite or ≤ 0.
    pub fn new(alpha_x: f32, alpha_y: f32) -> Result<Self, Error> {
        let (alpha_x, alpha_y) = check_roughness(alpha_x, alpha_y)?;
        let (ax, ay) = (f64::from(alpha_x), f64::from(alpha_y));
        Ok(Self {
            alpha_x,
            alpha_y,
            inv_alpha_x: 1.0 / ax,
            inv_alpha_y: 1.0 / ay,
            d_scale: INV_PI / (ax * ay),
        })
    }

    /// An isotropic Beckmann distribution, α = αx = αy.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `alpha` is NaN, infinite or ≤ 0.
    pub fn isotropic(alpha: f32) -> Result<Self, Error> {
        Self::new(alpha, alpha)
    }

    /// D(ωm) in double precision (0 for ωm.z ≤ 0).
    #[inline]
    fn d_double(&self, wm: DVec3) -> f64 {
        // also 0 where 0 < m.z < 1e-100: there the exponent exceeds 1e120 for every f32 α
        if wm.z.is_nan() || wm.z < D_VANISHES_BELOW_COS {
            return 0.0;
        }
        // one division; multiplied left to right, so that a vanishing exponential gives 0
        let (x, y) = (wm.x * self.inv_alpha_x, wm.y * self.inv_alpha_y);
        let inv_z2 = 1.0 / (wm.z * wm.z);
        (-(x * x + y * y) * inv_z2).exp() * inv_z2 * inv_z2 * self.d_scale
    }

    /// The projected area in double precision.
    #[inline]
    fn projected_area_double(&self, w: Vec3) -> f64 {
        let q = projected_roughness_sq64(self.alpha_x, self.alpha_y, w);
        let root_q = q.sqrt();
        let z = f64::from(w.z);
        // above: ((1 + erf a)/2) cos θ + αᵢ sin θ e^{−a²}/(2√π) = cos θ (1 + Λ(ω)); below:
        // Λ(−ω)|cos θ|; both with a = |cot θ|/αᵢ, through Λ = e^{−a²} r(a)/(2a√π)
        let a = z.abs() / root_q;
        let tail = 0.5 * INV_SQRT_PI * root_q * (-a * a).exp() * one_minus_scaled_erfcx(a);
        if z >= 0.0 { z + tail } else { tail }
    }
}

/// q = αx² ω.x² + αy² ω.y² in double precision: Λ and the projected area depend on it through
/// exp(−z²/q), which amplifies an f32 rounding of q by 2a².
#[inline(always)]
fn projected_roughness_sq64(alpha_x: f32, alpha_y: f32, w: Vec3) -> f64 {
    let (x, y) = (f64::from(alpha_x) * f64::from(w.x), f64::from(alpha_y) * f64::from(w.y));
    x * x + y * y
}

/// Λ for the upper hemisphere in double precision, a = cot θ / αᵢ ≥ 0:
/// exp(−a²)/(2a√π) − erfc(a)/2 = exp(−a²) r(a)/(2a√π) with r(a) = 1 − √π a erfcx(a)
/// ([`one_minus_scaled_erfcx`]), which has no cancellation beyond a = 8 and at most
/// 2a² ≤ 128 ulps below: relative error below 3e-14. +∞ at a = 0.
#[inline(always)]
fn lambda_up64(a: f64) -> f64 {
    0.5 * INV_SQRT_PI * (-a * a).exp() * one_minus_scaled_erfcx(a) / a
}

impl MicrosurfaceSlope for Beckmann {
    #[inline]
    fn alpha_x(&self) -> f32 {
        self.alpha_x
    }

    #[inline]
    fn alpha_y(&self) -> f32 {
        self.alpha_y
    }

    #[inline]
    fn p22(&self, slope_x: f32, slope_y: f32) -> f32 {
        require!(!slope_x.is_nan() && !slope_y.is_nan(), 0.0; slope_x, slope_y);
        let (ax, ay) = (f64::from(self.alpha_x), f64::from(self.alpha_y));
        let (x, y) = (f64::from(slope_x) / ax, f64::from(slope_y) / ay);
        ((-(x * x) - y * y).exp() * INV_PI / (ax * ay)) as f32
    }

    /// exp(−(m.x²/αx² + m.y²/αy²)/m.z²) / (π αx αy m.z⁴), in double precision: the error of
    /// an f32 exponent E grows as E·2⁻²⁴, and m.z⁴ would underflow before the exponential.
    #[inline]
    fn d(&self, wm: Vec3) -> f32 {
        require!(is_direction(wm), 0.0; wm);
        self.d_double(wm.as_dvec3()) as f32
    }

    #[inline]
    fn d64(&self, wm: DVec3) -> f64 {
        require!(is_direction64(wm), 0.0; wm);
        self.d64_unchecked(wm)
    }

    #[inline]
    fn d64_unchecked(&self, wm: DVec3) -> f64 {
        self.d_double(wm)
    }

    #[inline]
    fn lambda(&self, w: Vec3) -> f32 {
        require!(is_direction(w), f32::NAN; w);
        self.lambda_unchecked(w)
    }

    #[inline]
    fn lambda_unchecked(&self, w: Vec3) -> f32 {
        (self.lambda64(w) as f32).clamp(-f32::MAX, f32::MAX)
    }

    #[inline]
    fn lambda64(&self, w: Vec3) -> f64 {
        let q = projected_roughness_sq64(self.alpha_x, self.alpha_y, w);
        let a = f64::from(w.z.abs()) / q.sqrt();
        let up = lambda_up64(a);
        if w.z >= 0.0 { up } else { -1.0 - up }
    }

    /// ln Λ = −a² + ln r(a) − ln(2a√π) with a = cot θ/αᵢ and r = 1 − √π a erfcx(a)
    /// (`one_minus_scaled_erfcx`): no exponential, so it stays finite (and relative error
    /// below 3e-14 of ln Λ's magnitude or 1e-13 absolute) where Λ underflows f64 (a > 26.6).
    #[inline]
    fn ln_lambda(&self, w: Vec3) -> f64 {
        if w.z < 0.0 {
            return f64::NAN;
        }
        let q = projected_roughness_sq64(self.alpha_x, self.alpha_y, w);
        let a = f64::from(w.z) / q.sqrt();
        if a == 0.0 {
            return f64::INFINITY;
        }
        if a.is_infinite() {
            return f64::NEG_INFINITY;
        }
        -a * a + (one_minus_scaled_erfcx(a) * (0.5 * INV_SQRT_PI) / a).ln()
    }

    #[inline]
    fn projected_area(&self, w: Vec3) -> f32 {
        require!(is_direction(w), f32::NAN; w);
        self.projected_area_unchecked(w)
    }

    #[inline]
    fn projected_area_unchecked(&self, w: Vec3) -> f32 {
        self.projected_area_double(w) as f32
    }

    #[inline]
    fn projected_area64(&self, w: Vec3) -> f64 {
        self.projected_area_double(w)
    }

    /// Evaluated in double precision; when ωi is so far below the horizon that the
    /// projected area underflows even there (a = |cot θ|/αᵢ beyond about 26), as the ratio of
    /// logarithms ln D − ln A, with ln A = −a² + ln(αᵢ sin θ/(2√π)) + ln(1 − √π a erfcx(a)).
    #[inline]
    fn d_wi(&self, wi: Vec3, wm: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wm), 0.0; wi, wm);
        self.d_wi64_unchecked(wi, wm.as_dvec3()) as f32
    }

    #[inline]
    fn d_wi64(&self, wi: Vec3, wm: DVec3) -> f64 {
        require!(is_direction(wi) && is_direction64(wm), 0.0; wi, wm);
        self.d_wi64_unchecked(wi, wm)
    }

    #[inline]
    fn d_wi64_unchecked(&self, wi: Vec3, wm: DVec3) -> f64 {
        let cos_im = wi.as_dvec3().dot(wm);
        if cos_im <= 0.0 || wm.z <= 0.0 {
            return 0.0;
        }
        let area = self.projected_area_double(wi);
        if area > AREA_LOG_SPACE_BELOW {
            return cos_im * self.d_double(wm) / area;
        }
        let q = projected_roughness_sq64(self.alpha_x, self.alpha_y, wi);
        let a = -f64::from(wi.z) / q.sqrt();
        if !(q > 0.0 && a >= PSI_SERIES_FROM) {
            return 0.0;
        }
        let ln_area = -a * a + (0.5 * INV_SQRT_PI * q.sqrt()).ln() + one_minus_scaled_erfcx(a).ln();
        let (ax, ay) = (f64::from(self.alpha_x), f64::from(self.alpha_y));
        let (x, y, z) = (wm.x / ax, wm.y / ay, wm.z);
        let ln_d = -(x * x + y * y) / (z * z) - (core::f64::consts::PI * ax * ay * z * z * z * z).ln();
        cos_im * (ln_d - ln_area).exp()
    }

    /// The trait's stretch–sample–unstretch with the stretched cot θ formed in double
    /// precision: far below the horizon the visible slopes lie within about 1/|cot θ| of it, so
    /// an f32 rounding of cot θ (relative 6e-8) would shift them by a visible fraction of
    /// their spread (5 % at |cot θ| = 480).
    #[inline]
    fn sample_d_wi(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        require!(is_direction(wi) && is_uniform(u1) && is_uniform(u2), Vec3::NAN; wi, u1, u2);
        self.sample_d_wi_unchecked(wi, u1, u2)
    }

    #[inline]
    fn sample_d_wi_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        let (ax, ay) = (f64::from(self.alpha_x), f64::from(self.alpha_y));
        let (sx, sy, z) = (ax * f64::from(wi.x), ay * f64::from(wi.y), f64::from(wi.z));
        let len_xy = (sx * sx + sy * sy).sqrt();
        let (cos_phi, sin_phi) = if len_xy > 0.0 { (sx / len_xy, sy / len_xy) } else { (1.0, 0.0) };
        let x = if len_xy > 0.0 {
            visible_slope_x(z / len_xy, f64::from(u1))
        } else if z > 0.0 {
            gaussian_slope(f64::from(u1))
        } else {
            return Vec3::Z;
        };
        let y = gaussian_slope(f64::from(u2));
        let slope_x = (ax * (cos_phi * x - sin_phi * y)) as f32;
        let slope_y = (ay * (sin_phi * x + cos_phi * y)) as f32;
        ensure_visible(wi, normal_from_slopes(slope_x, slope_y))
    }

    /// Exact inversion of the visible-slope CDF (a safeguarded Halley iteration on its logarithm); ỹ is Gaussian and
    /// independent of x̃. Seen from straight below (sin θ = 0, cos θ < 0), where nothing is
    /// visible, returns the zero slope.
    #[inline]
    fn sample_p22_11(&self, cos_theta: f32, sin_theta: f32, u1: f32, u2: f32) -> Vec2 {
        require!(
            is_direction(Vec3::new(sin_theta, 0.0, cos_theta)) && sin_theta >= 0.0 && is_uniform(u1) && is_uniform(u2),
            Vec2::NAN;
            cos_theta, sin_theta, u1, u2
        );
        let (c, s) = (f64::from(cos_theta), f64::from(sin_theta));
        let slope_x = if s > 0.0 {
            visible_slope_x(c / s, f64::from(u1))
        } else if c > 0.0 {
            gaussian_slope(f64::from(u1))
        } else {
            return Vec2::ZERO;
        };
        Vec2::new(slope_x as f32, gaussian_slope(f64::from(u2)) as f32)
    }
}

/// The quantile of the slope density exp(−x²)/√π: erf⁻¹(2u − 1), evaluated from the nearer
/// end of [0, 1] in single precision (relative error below 4e-7, see `erfc_inv_f32`). Both
/// tails are cut at probability 2⁻²⁴ (the crate's tail policy, `rng`): u = 0 gives
/// x̃ = −3.744, with 2⁻²⁴ of the density below it, and u = 1 − 2⁻²⁴ gives +3.744.
#[inline]
pub(crate) fn gaussian_slope(u: f64) -> f64 {
    let u = cut_tails64(u);
    let tail = u.min(1.0 - u);
    let x = f64::from(erfc_inv_f32(tail as f32));
    if u < 0.5 { -x } else { x }
}

/// r(u) = 1 − √π u erfcx(u) for u ≥ 0 (the ratio of the Gaussian tail's two terms; r(0) = 1,
/// r(u) ≈ 1/(2u²) for large u). From `PSI_SERIES_FROM` on, by its asymptotic series
/// r = r2 − 3r2² + 15r2³ − 105r2⁴ + 945r2⁵ − 10395r2⁶ with r2 = 1/(2u²) (the next term is
/// below 1e-16 relative for u ≥ 8), free of the cancellation of the direct form, which below
/// 8 loses at most a factor 2u² ≤ 128 of erfcx's relative accuracy.
#[inline(always)]
pub(crate) fn one_minus_scaled_erfcx(u: f64) -> f64 {
    if u < PSI_SERIES_FROM {
        return 1.0 - SQRT_PI * u * erfcx64(u);
    }
    let r2 = 1.0 / (2.0 * u * u);
    r2 * (1.0 - r2 * (3.0 - r2 * (15.0 - r2 * (105.0 - r2 * (945.0 - r2 * 10395.0)))))
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
/// cot θ = κ (any sign), by solving ln S(x̃) − ln S(κ) = ln u.
///
/// ln S is concave (S is the integral of a log-concave density), so Newton's method from the
/// left of the root climbs to it monotonically. The iteration takes Halley steps (Newton's
/// with the curvature of ln S, which is known in closed form: cubic convergence), falls back
/// to Newton's step where Halley's correction is not small, and replaces steps that leave the
/// current bracket by bisection, or by a doubling step to the left while no lower bound is
/// known. It stops when the step, or ten times the error a Newton step of that size would
/// leave, |g″/(2g′)|·step², is below the tolerance: 2–3.3 evaluations of ln S per sample at
/// α = 1 (4–5 with plain Newton steps and the step test alone).
#[inline]
fn visible_slope_x(kappa: f64, u: f64) -> f64 {
    visible_slope_x_above(kappa, f64::NEG_INFINITY, u)
}

/// Like [`visible_slope_x`], restricted to x̃ ∈ [`lower`, κ) (`lower` may be −∞): solves
/// S(x̃) = S(lower) + u (S(κ) − S(lower)) in log space. Used by the V-cavity sampler, whose
/// unmasked part is the Smith VNDF limited to slopes above 3 cot θ (Tokuyoshi, listing 5).
///
/// u is cut to [2⁻²⁴, 1 − 2⁻²⁴] (the crate's tail policy, `rng`): the lowest sample has 2⁻²⁴ of
/// the visible slopes below it, the highest 2⁻²⁴ between it and κ (where the density vanishes).
#[inline]
pub(crate) fn visible_slope_x_above(kappa: f64, lower: f64, u: f64) -> f64 {
    let u = cut_tails64(u);
    let ln_u = u.ln();
    let ln_s_kappa = ln_s(kappa, kappa).0;
    let (target, mut lo) = if lower > f64::NEG_INFINITY && lower < kappa {
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
    let mut hi = kappa;
    let mut x = kappa - t0.max(f64::MIN_POSITIVE);
    if x <= lo {
        x = 0.5 * (lo + hi);
    }
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
        let tolerance = NEWTON_TOLERANCE * (1.0 + x.abs());
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
