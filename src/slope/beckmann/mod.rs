//! The Beckmann slope distribution.

use super::{MicrosurfaceSlope, check_roughness, is_direction, is_uniform};
use crate::constants::INV_SQRT_PI;
use crate::error::Error;
use crate::special::{
    EXP_NONPOSITIVE_FROM, PSI_SERIES_FROM, exp_nonpositive, one_minus_scaled_erfcx, tail_ratio,
};
mod inversion;

use crate::albedo::AlbedoTable;
use glam::{DVec3, Vec2, Vec3};
pub(crate) use inversion::{gaussian_slope, sample_visible_normal, visible_slope_x_above, visible_slopes};

/// 1/π.
const INV_PI: f64 = core::f64::consts::FRAC_1_PI;
/// Below this cos θm, D is 0 in double precision for every roughness an f32 holds.
const D_VANISHES_BELOW_COS: f64 = 1e-100;
/// Below this projected area (a ≈ 26 from below) D_ωi is evaluated in log space.
const AREA_LOG_SPACE_BELOW: f64 = 1e-280;
/// From this a = cot θ/αᵢ on, Λ above the horizon (below 5.2e-48) rounds to 0 in f32: half the
/// smallest subnormal is 7.0e-46.
const LAMBDA32_VANISHES_FROM: f64 = 10.0;

/// The anisotropic Beckmann slope distribution (Heitz et al. 2016, supplement §2.2):
///
/// P²²(x̃, ỹ) = exp(−x̃²/αx² − ỹ²/αy²) / (π αx αy),
/// Λ(ω) = (erf(a) − 1)/2 + exp(−a²)/(2a√π) with a = 1/(αᵢ tan θ).
///
/// D, D_ωi and the projected area are evaluated in double precision with forms that avoid the
/// cancellation of erf(a) − 1 (they use erfc); so is Λ in `lambda64` (relative error 4e-13),
/// while the f32 [`MicrosurfaceSlope::lambda`] of the walks is formed from a fit of the tail
/// ratio and a table exponential, within 0.51 f32 ulp. Visible normals are sampled
/// exactly by inverting the visible-slope CDF (Jakob 2014, extended to θ ∈ [0, π]) from a
/// tabulated guess with Halley steps on fitted forms of the CDF (a safeguarded Halley
/// iteration on the log-CDF where their error estimate fails), without the supplement's
/// truncation of the tail (`erf_min = −0.9999`).
///
/// # Examples
/// ```
/// use microsurface::Beckmann;
/// use microsurface::slope::MicrosurfaceSlope;
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

    /// D(ωm) in double precision (0 for ωm.z ≤ 0), the exponential from the table of
    /// [`exp_nonpositive`] (relative error 4e-15; the library's below −708, where the result
    /// is subnormal): relative error below 5e-15 beyond that of the exponent's rounding,
    /// E·2⁻⁵² for the exponent E (measured by the unit test).
    #[inline]
    fn d_double(&self, wm: DVec3) -> f64 {
        // also 0 where 0 < m.z < 1e-100: there the exponent exceeds 1e120 for every f32 α
        if wm.z.is_nan() || wm.z < D_VANISHES_BELOW_COS {
            return 0.0;
        }
        // one division; multiplied left to right, so that a vanishing exponential gives 0
        let (x, y) = (wm.x * self.inv_alpha_x, wm.y * self.inv_alpha_y);
        let inv_z2 = 1.0 / (wm.z * wm.z);
        let exponent = -(x * x + y * y) * inv_z2;
        let gauss = if exponent >= EXP_NONPOSITIVE_FROM { exp_nonpositive(exponent) } else { exponent.exp() };
        gauss * inv_z2 * inv_z2 * self.d_scale
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

/// Λ on the whole sphere for the f32 [`MicrosurfaceSlope::lambda`], in double precision from
/// the fits: above the horizon Λ = e^{−a²} r(a)/(2√π a) with a = cot θ/αᵢ, e^{−a²} from
/// [`exp_nonpositive`] (relative error 4e-15, a² formed in f64: its rounding error is
/// amplified by a² ≤ 100) and r(a) = 1 − √π a erfcx(a) from [`tail_ratio`] (1e-10); 0 from
/// a = 10 on (where Λ < 5.2e-48 rounds to 0 in f32); below, −1 − Λ(−ω). Relative error below
/// 2e-10 (measured against [`MicrosurfaceSlope::lambda64`] by the unit test), so that the f32
/// rounding of it is within 0.51 ulp of Λ. +∞ at the horizon (a = 0).
#[inline(always)]
fn lambda_from_fits(alpha_x: f32, alpha_y: f32, w: Vec3) -> f64 {
    let q = projected_roughness_sq64(alpha_x, alpha_y, w);
    let z = f64::from(w.z).abs();
    let root_q = q.sqrt();
    let a = z / root_q;
    let up = if a >= LAMBDA32_VANISHES_FROM {
        0.0
    } else {
        let inv_a = root_q / z;
        exp_nonpositive(-a * a) * tail_ratio(a, inv_a) * inv_a * (0.5 * INV_SQRT_PI)
    };
    if w.z >= 0.0 { up } else { -1.0 - up }
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
    /// |F(x̃) − u| ≤ 1e-7·u + 1e-10 seen from above the horizon and from below it for
    /// |cot θ| ≤ 64, ≤ 1e-5 beyond; ỹ is Gaussian and independent of x̃. Seen from straight
    /// below (sin θ = 0, cos θ < 0), where nothing is visible, returns the zero slope.
    #[inline]
    #[must_use]
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
    fn conductor_albedo(&self) -> Option<(AlbedoTable, f32)> {
        Some((AlbedoTable::BECKMANN, (self.alpha_x() * self.alpha_y()).sqrt()))
    }

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

    /// exp(−(m.x²/αx² + m.y²/αy²)/m.z²) / (π αx αy m.z⁴), in double precision (relative error
    /// below 5e-15 besides the exponent's rounding): the error of an f32 exponent E grows as
    /// E·2⁻²⁴, and m.z⁴ would underflow before the exponential.
    #[inline]
    fn d(&self, wm: Vec3) -> f32 {
        require!(is_direction(wm), 0.0; wm);
        self.d_double(wm.as_dvec3()) as f32
    }

    #[inline]
    fn d64_unchecked(&self, wm: DVec3) -> f64 {
        self.d_double(wm)
    }

    /// D(ωh)/(|h|⁴ A): `d_double` of h itself, whose form exp(−(h.x²/αx² + h.y²/αy²)/h.z²)/
    /// (π αx αy h.z⁴) is D(ωh)/|h|⁴ for an unnormalized h (its exponent is of degree 0 in h,
    /// h.z⁴ = ωh.z⁴ |h|⁴), divided by A: two divisions, no square root. Its cut at
    /// h.z < 1e-100 returns 0 only where D(ωh) vanishes (for |h| ≥ 1e-6, the walk's
    /// refraction half vectors, the exponent exceeds 1e100 there).
    #[inline]
    fn d64_over_len4_area_unchecked(&self, h: DVec3, area: f32) -> f64 {
        self.d_double(h) / f64::from(area)
    }

    /// Formed from the fits of [`lambda_from_fits`] (within 0.51 f32 ulp of Λ, saturating at
    /// ±`f32::MAX`); [`MicrosurfaceSlope::lambda64`] keeps the double-precision forms.
    #[inline]
    fn lambda_unchecked(&self, w: Vec3) -> f32 {
        (lambda_from_fits(self.alpha_x, self.alpha_y, w) as f32).clamp(-f32::MAX, f32::MAX)
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
    fn sample_d_wi_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        sample_visible_normal(self, wi, u1, u2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// D in double precision against the same formula with the library's exponential, on
    /// normals from the zenith to 1e-6 from the horizon for several roughnesses: relative
    /// error below 5e-15, and the same 0s.
    #[test]
    fn d_double_meets_its_error_bound() {
        let mut worst = 0.0f64;
        for alpha in [0.01f32, 0.05, 0.3, 0.5, 1.0, 2.5, 40.0] {
            let slope = Beckmann::new(alpha, 0.6 * alpha).expect("valid roughness");
            for i in 0..=4000 {
                let cos = 1.0 - f64::from(i) / 4000.0 * (1.0 - 1e-6);
                for phi in [0.0f64, 0.7, 1.6] {
                    let sin = (1.0 - cos * cos).sqrt();
                    let wm = DVec3::new(sin * phi.cos(), sin * phi.sin(), cos);
                    let (x, y) = (wm.x * slope.inv_alpha_x, wm.y * slope.inv_alpha_y);
                    let inv_z2 = 1.0 / (wm.z * wm.z);
                    let exact = (-(x * x + y * y) * inv_z2).exp() * inv_z2 * inv_z2 * slope.d_scale;
                    let got = slope.d_double(wm);
                    if exact == 0.0 || exact < f64::MIN_POSITIVE {
                        assert!((got - exact).abs() <= f64::MIN_POSITIVE, "D({wm}) = {got:e}, {exact:e}");
                        continue;
                    }
                    worst = worst.max((got / exact - 1.0).abs());
                }
            }
        }
        eprintln!("Beckmann D: worst relative error against the library's exp {worst:.3e}");
        assert!(worst <= 5e-15, "relative error {worst:e}");
    }

    /// The documented relative error of [`lambda_from_fits`] and the f32 bound that follows.
    const FITS_MAX_RELATIVE_ERROR: f64 = 2e-10;
    const LAMBDA32_MAX_ULPS: f64 = 0.51;

    /// Directions at cot θ/αᵢ = a for a geometric sweep of a ∈ [1e-6, 12] and a linear one of
    /// [0, 10.5], on both hemispheres and three azimuths, for several (anisotropic) roughnesses.
    fn cases() -> impl Iterator<Item = (Beckmann, Vec3)> {
        let alphas = [0.01f32, 0.05, 0.3, 0.5, 1.0, 2.5];
        let geometric = (0..=2000).map(|i| 1e-6 * (12e6f64).powf(f64::from(i) / 2000.0));
        let linear = (0..=2100).map(|i| f64::from(i) / 200.0);
        let a_values: Vec<f64> = geometric.chain(linear).collect();
        alphas.into_iter().flat_map(move |alpha| {
            let slope = Beckmann::new(alpha, 0.6 * alpha).expect("valid roughness");
            let a_values = a_values.clone();
            [0.0f64, 0.7, 1.6].into_iter().flat_map(move |phi| {
                // αᵢ along φ, then the polar angle with cot θ = a·αᵢ
                let (ax, ay) = (f64::from(alpha), 0.6 * f64::from(alpha));
                let alpha_i = (ax * ax * phi.cos().powi(2) + ay * ay * phi.sin().powi(2)).sqrt();
                let a_values = a_values.clone();
                a_values.into_iter().flat_map(move |a| {
                    let theta = (a * alpha_i).recip().atan();
                    let (s, c) = theta.sin_cos();
                    let w = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32).normalize();
                    [(slope, w), (slope, -w)]
                })
            })
        })
    }

    /// Λ from the fits against the double-precision Λ (relative error 4e-13) over the sweep of
    /// `cases`: relative error below 2e-10 in f64, and the f32 Λ within 0.51 ulp where Λ is
    /// a normal f32 (within one subnormal step below); the identity Λ(−ω) = −1 − Λ(ω) holds to
    /// an f32 rounding.
    #[test]
    fn lambda_from_fits_meets_its_error_bound() {
        let (mut worst, mut worst_ulps, mut checked) = (0.0f64, 0.0f64, 0usize);
        for (slope, w) in cases() {
            let exact = slope.lambda64(w);
            let fit = lambda_from_fits(slope.alpha_x, slope.alpha_y, w);
            let lambda = slope.lambda(w);
            if exact.is_infinite() {
                assert_eq!(lambda, f32::MAX.copysign(w.z), "at the horizon: {w}");
                continue;
            }
            checked += 1;
            if fit == 0.0 {
                // from a = 10 on: Λ rounds to 0 in f32
                assert!(exact < 0.5 * f64::from(f32::from_bits(1)), "Λ({w}) = {exact:e}, fit 0");
            } else {
                worst = worst.max((fit / exact - 1.0).abs());
            }
            let ulp = f64::from(f32::EPSILON) * exact.abs();
            if exact.abs() >= f64::from(f32::MIN_POSITIVE) && exact.abs() <= f64::from(f32::MAX) {
                worst_ulps = worst_ulps.max((f64::from(lambda) - exact).abs() / ulp);
            } else if exact.abs() < f64::from(f32::MIN_POSITIVE) {
                let step = f64::from(f32::from_bits(1));
                assert!((f64::from(lambda) - exact).abs() <= step, "Λ({w}) = {exact:e}: {lambda:e}");
            }
            let identity = slope.lambda(-w) + 1.0 + lambda;
            assert!(
                identity.abs() <= 2.0 * f32::EPSILON * (1.0 + lambda.abs()),
                "Λ(−ω) + 1 + Λ(ω) = {identity:e} at {w}"
            );
        }
        eprintln!(
            "Beckmann Λ from fits: {checked} directions, worst relative error {worst:.3e}, worst f32 error {worst_ulps:.3} ulp"
        );
        assert!(worst <= FITS_MAX_RELATIVE_ERROR, "relative error {worst:e} > {FITS_MAX_RELATIVE_ERROR:e}");
        assert!(worst_ulps <= LAMBDA32_MAX_ULPS, "f32 error {worst_ulps} ulp > {LAMBDA32_MAX_ULPS}");
        // where the fits stop, Λ is below half the smallest f32 subnormal
        let alpha_i = 1.0f64;
        let theta = (LAMBDA32_VANISHES_FROM * alpha_i).recip().atan();
        let w = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
        let slope = Beckmann::isotropic(1.0).expect("valid roughness");
        assert!(
            slope.lambda64(w) < 0.5 * f64::from(f32::from_bits(1)),
            "Λ = {:e} at a = 10",
            slope.lambda64(w)
        );
    }
}
