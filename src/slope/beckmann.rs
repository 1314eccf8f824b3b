//! The Beckmann slope distribution.

use super::{MicrosurfaceSlope, check_roughness, is_direction, is_direction64, is_uniform};
use crate::constants::INV_SQRT_PI;
use crate::error::Error;
use crate::special::{PSI_SERIES_FROM, one_minus_scaled_erfcx};
use crate::vndf::{sample_visible_normal, visible_slopes};
use glam::{DVec3, Vec2, Vec3};

/// 1/π.
const INV_PI: f64 = core::f64::consts::FRAC_1_PI;
/// Below this cos θm, D is 0 in double precision for every roughness an f32 holds.
const D_VANISHES_BELOW_COS: f64 = 1e-100;
/// Below this projected area (a ≈ 26 from below) D_ωi is evaluated in log space.
const AREA_LOG_SPACE_BELOW: f64 = 1e-280;

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
///
/// # Examples
/// ```
/// use microsurface::{Beckmann, MicrosurfaceSlope};
/// use microsurface::glam::Vec3;
///
/// let beckmann = Beckmann::isotropic(0.5)?;
/// // Λ(−ω) = −1 − Λ(ω) on the whole sphere, also for a view below the horizon
/// let w = Vec3::new(0.8, 0.0, -0.6);
/// assert!((beckmann.lambda(-w) + 1.0 + beckmann.lambda(w)).abs() < 1e-6);
/// let wm = beckmann.sample_d_wi(w, 0.5, 0.5);
/// assert!(wm.dot(w) > 0.0);
/// # Ok::<(), microsurface::Error>(())
/// ```
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
/// ([`one_minus_scaled_erfcx`]): relative error below 4e-13 (that of r, which loses a factor
/// 1 + 2a² of erfcx's accuracy to cancellation just below a = 8, its series' start; 1e-15
/// beyond). +∞ at a = 0.
#[inline(always)]
fn lambda_up64(a: f64) -> f64 {
    0.5 * INV_SQRT_PI * (-a * a).exp() * one_minus_scaled_erfcx(a) / a
}

impl Beckmann {
    /// The stretched-space primitive of [`MicrosurfaceSlope::sample_d_wi`] (supplement §2.1,
    /// `sampleP22_11`): visible slopes of the distribution stretched to α = 1, seen from
    /// (sin θ, 0, cos θ), θ ∈ [0, π]; rotating them into the azimuth of the stretched ωi and
    /// unstretching by (αx, αy) samples D_ωi. Takes cos θ and sin θ ≥ 0 (either may be ±0)
    /// and two uniforms in [0, 1], used as clamp(u, 2⁻²⁴, 1 − 2⁻²⁴).
    ///
    /// Exact inversion of the visible-slope CDF F (a tabulated guess, Halley steps and, where
    /// their error estimate fails, a safeguarded Halley iteration on its logarithm):
    /// |F(x̃) − u| ≤ 1e-7·u + 1e-10 seen from above the horizon, ≤ 2e-7 for
    /// |cot θ| ≤ 64 on either side; ỹ is Gaussian and independent of x̃. Seen from straight below (sin θ = 0, cos θ < 0), where nothing is
    /// visible, returns the zero slope.
    #[inline]
    pub fn sample_p22_11(&self, cos_theta: f32, sin_theta: f32, u1: f32, u2: f32) -> Vec2 {
        require!(
            is_direction(Vec3::new(sin_theta, 0.0, cos_theta)) && sin_theta >= 0.0 && is_uniform(u1) && is_uniform(u2),
            Vec2::NAN;
            cos_theta, sin_theta, u1, u2
        );
        match visible_slopes(f64::from(cos_theta), f64::from(sin_theta), u1, u2) {
            Some((x, y)) => Vec2::new(x as f32, y as f32),
            None => Vec2::ZERO,
        }
    }
}

impl crate::sealed::Sealed for Beckmann {}

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
        sample_visible_normal(self, wi, u1, u2)
    }
}
