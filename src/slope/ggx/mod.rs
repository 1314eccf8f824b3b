//! The GGX (Trowbridge–Reitz) slope distribution.

use super::{
    MicrosurfaceSlope, check_roughness, d64_over_len4_area, is_direction, is_uniform, projected_roughness_sq,
    projected_roughness_sq_of, reflection_density64_over, smith_d_wi64,
};
use crate::error::Error;
use crate::lanes::{Lanes, V3};
mod visible;

pub(crate) use visible::{bounded_area_of, kappa_of, sample_cap_of, sample_cap_scaled_of};

use crate::albedo::AlbedoTable;
use core::f32::consts::FRAC_1_PI;
use glam::{DVec3, Vec2, Vec3};
use visible::bounded_area;
use visible::sample_spherical_cap_scaled;
pub(crate) use visible::{cap_bound, sample_bounded_cap, sample_spherical_cap, sample_visible_hemisphere};

/// 1/(4π), the constant of the reflection density D(ωh)/(4 A(ωi)).
const FRAC_1_4PI: f32 = 0.25 * FRAC_1_PI;

/// The smallest |ωi + ωo|² and stretched t for which the f32 reflection density is used: above
/// it no term of either sum is subnormal enough to matter (absolute error 2⁻¹⁴⁹ against 2⁻¹⁰⁰).
pub(crate) const F32_DENSITY_MIN_SUM: f32 = 7.888_609_e-31; // 2⁻¹⁰⁰

/// Smallest cos θm kept when a sampled normal is turned into slopes (only
/// [`Ggx::sample_p22_11`]; the sampled normals themselves are exact).
const MIN_SLOPE_COS: f32 = f32::MIN_POSITIVE;

/// The anisotropic GGX slope distribution (Heitz et al. 2016, supplement §2.3):
///
/// P²²(x̃, ỹ) = 1 / (π αx αy (1 + x̃²/αx² + ỹ²/αy²)²),
/// Λ(ω) = (−1 + sign(a) √(1 + 1/a²))/2 with a = 1/(αᵢ tan θ).
///
/// Visible normals are sampled exactly on the whole sphere with the spherical-cap method of
/// Dupuy and Benyoub 2023 (“Sampling Visible GGX Normals with Spherical Caps”), which also
/// holds for incident directions below the horizon.
///
/// # Examples
/// ```
/// use microsurface::Ggx;
/// use microsurface::slope::MicrosurfaceSlope;
/// use microsurface::glam::Vec3;
///
/// let ggx = Ggx::new(0.3, 0.1)?;
/// let wi = Vec3::new(0.6, 0.0, 0.8);
/// // the projected area of the microsurface is (1 + Λ) cos θ, and a sampled visible normal
/// // faces the incident direction
/// assert!((ggx.projected_area(wi) - (1.0 + ggx.lambda(wi)) * wi.z).abs() < 1e-6);
/// let wm = ggx.sample_d_wi(wi, 0.3, 0.6);
/// assert!(wm.dot(wi) > 0.0 && ggx.d_wi(wi, wm) > 0.0);
/// assert!(Ggx::isotropic(-1.0).is_err());
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ggx {
    alpha_x: f32,
    alpha_y: f32,
}

impl Ggx {
    /// An anisotropic GGX distribution.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `alpha_x` or `alpha_y` is NaN, infinite or ≤ 0.
    pub fn new(alpha_x: f32, alpha_y: f32) -> Result<Self, Error> {
        let (alpha_x, alpha_y) = check_roughness(alpha_x, alpha_y)?;
        Ok(Self { alpha_x, alpha_y })
    }

    /// An isotropic GGX distribution, α = αx = αy.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `alpha` is NaN, infinite or ≤ 0.
    pub fn isotropic(alpha: f32) -> Result<Self, Error> {
        Self::new(alpha, alpha)
    }
}

/// Λ for the upper hemisphere from q = (αᵢ sin θ)² and z = cos θ ≥ 0 (+0 at the horizon: the
/// caller passes |cos θ|), in the cancellation-free form q / (2z(z + √(z² + q))); saturates to
/// `f32::MAX` at z = +0. One formula for every lane type (f32, f64, [`F32x8`](crate::lanes::F32x8)).
#[inline(always)]
pub(crate) fn lambda_up<L: Lanes>(q: L, z: L) -> L {
    lambda_up_unsaturated(q, z).min(L::lit(f32::MAX))
}

/// [`lambda_up`] without the saturation: +∞ at z = +0 (the f64 Λ of the walks' shadowing).
#[inline(always)]
pub(crate) fn lambda_up_unsaturated<L: Lanes>(q: L, z: L) -> L {
    q / (L::lit(2.0) * z * (z + (z * z + q).sqrt()))
}

/// The signed Λ on the whole sphere from q = (αᵢ sin θ)² and z = cos θ, given the upper
/// hemisphere's Λ at |z| (`up`): `up` above the horizon, −1 − `up` below it (z = −0 is the
/// horizon seen from above, like +0).
#[inline(always)]
pub(crate) fn lambda_signed<L: Lanes>(up: L, z: L) -> L {
    L::select(z.ge(L::lit(0.0)), up, -L::lit(1.0) - up)
}

/// The projected area (1 + Λ) cos θ from q = (αᵢ sin θ)² and z = cos θ: ½(z + √(z² + q)) above
/// the horizon (supplement §2.3) and the equivalent q / (2(√(z² + q) − z)) below it, which has
/// no cancellation there.
#[inline(always)]
pub(crate) fn projected_area_of<L: Lanes>(q: L, z: L) -> L {
    let root = (z * z + q).sqrt();
    L::choose(z.ge(L::lit(0.0)), || L::lit(0.5) * (z + root), || q / (L::lit(2.0) * (root - z)))
}

/// D(ωm) = 1/(π αx αy t²), t = m.x²/αx² + m.y²/αy² + m.z², for m.z > 0 (the caller tests it):
/// the slope form multiplied through by cos⁴θm, finite down to m.z = 0.
#[inline(always)]
pub(crate) fn d_of<L: Lanes>(ax: L, ay: L, m: V3<L>, frac_1_pi: L) -> L {
    let (x, y) = (m.x / ax, m.y / ay);
    let t = x * x + y * y + m.z * m.z;
    frac_1_pi / (ax * ay * t * t)
}

/// |h|²/t with t = h.x²/αx² + h.y²/αy² + h.z², and |h|² and t themselves: D of the direction of
/// an unnormalized h is (|h|²/t)²/(π αx αy) (D is homogeneous of degree 0). Sums of squares
/// only: a few ulps of the lane type for every h. The coordinates are scaled by 1/αx and 1/αy,
/// which a loop over queries of one roughness forms once (one division per query, not three).
#[inline(always)]
pub(crate) fn sum_ratio<L: Lanes>(ax: L, ay: L, h: V3<L>) -> (L, L, L) {
    let one = L::lit(1.0);
    let (x, y) = (h.x * (one / ax), h.y * (one / ay));
    let t = x * x + y * y + h.z * h.z;
    let len_sq = h.length_squared();
    (len_sq / t, len_sq, t)
}

/// D(ωh) of the direction of an unnormalized h: (|h|²/t)²/(π αx αy) ([`sum_ratio`]).
#[inline(always)]
pub(crate) fn d_of_sum<L: Lanes>(ax: L, ay: L, h: V3<L>, frac_1_pi: L) -> L {
    let (ratio, _, _) = sum_ratio(ax, ay, h);
    // (1/(π αx αy) formed once per roughness in a loop over queries)
    (ratio * ratio) * (frac_1_pi / (ax * ay))
}

/// Λ(ω) on the whole sphere (saturated at ±`f32::MAX` in f32 lanes) and the projected area
/// A(ω) of a direction, for every lane type.
#[inline(always)]
pub(crate) fn lambda_and_area_of<L: Lanes>(ax: L, ay: L, w: V3<L>) -> (L, L) {
    let q = projected_roughness_sq_of(ax, ay, w.x, w.y);
    (lambda_signed(lambda_up(q, w.z.abs()), w.z), projected_area_of(q, w.z))
}

/// The reflection density D(ωh)/(4 A(ωi)) = (|h|²/t)²/(4π αx αy A) of the unnormalized
/// h = ωi + ωo with A = `area`, with |h|² and t (the caller checks their range): see
/// [`Ggx`]'s `reflection_density_unchecked` for the bound.
#[inline(always)]
pub(crate) fn reflection_density_of<L: Lanes>(ax: L, ay: L, h: V3<L>, area: L) -> (L, L, L) {
    let (ratio, len_sq, t) = sum_ratio(ax, ay, h);
    (L::lit(FRAC_1_4PI) * (ratio * ratio) / (ax * ay * area), len_sq, t)
}

impl Ggx {
    /// t′ = h.x²αy² + h.y²αx² + h.z²αx²αy² (t αx²αy² with t = h.x²/αx² + h.y²/αy² + h.z² of
    /// an unnormalized h) in f64 and αx αy, for the densities' forms with one division; `None`
    /// where αx αy is outside [1e-60, 1e60] (t′² could leave f64's normal range there).
    #[inline(always)]
    fn scaled_t(&self, h: DVec3) -> Option<(f64, f64)> {
        let (ax, ay) = (f64::from(self.alpha_x), f64::from(self.alpha_y));
        let axy = ax * ay;
        (1e-60..=1e60)
            .contains(&axy)
            .then_some((h.x * h.x * (ay * ay) + h.y * h.y * (ax * ax) + h.z * h.z * (axy * axy), axy))
    }

    /// The stretched-space primitive of [`MicrosurfaceSlope::sample_d_wi`] (supplement §2.1,
    /// `sampleP22_11`): visible slopes of the distribution stretched to α = 1, seen from
    /// (sin θ, 0, cos θ), θ ∈ [0, π]; rotating them into the azimuth of the stretched ωi and
    /// unstretching by (αx, αy) samples D_ωi. Takes cos θ and sin θ ≥ 0 (either may be ±0)
    /// and two uniforms in [0, 1], used as clamp(u, 2⁻²⁴, 1 − 2⁻²⁴).
    ///
    /// Visible slopes at α = 1 from the spherical-cap sampler. Slopes of normals that round
    /// to cos θm = 0 are computed with cos θm = `f32::MIN_POSITIVE` (finite, probability 0).
    /// Seen from straight below (θ = π), where nothing is visible (the cap is empty), returns
    /// the zero slope, like [`Beckmann`](super::Beckmann).
    #[inline]
    #[must_use]
    pub fn sample_p22_11(&self, cos_theta: f32, sin_theta: f32, u1: f32, u2: f32) -> Vec2 {
        require!(
            is_direction(Vec3::new(sin_theta, 0.0, cos_theta)) && sin_theta >= 0.0 && is_uniform(u1) && is_uniform(u2),
            Vec2::NAN;
            cos_theta, sin_theta, u1, u2
        );
        // slopes are invariant under scaling, so the unnormalized normal serves
        let m = sample_visible_hemisphere(Vec3::new(sin_theta, 0.0, cos_theta), 1.0, u1, u2);
        if m == Vec3::ZERO {
            return Vec2::ZERO;
        }
        let z = m.z.max(MIN_SLOPE_COS * m.length());
        Vec2::new(-m.x / z, -m.y / z)
    }
}

impl crate::sealed::Sealed for Ggx {}

impl MicrosurfaceSlope for Ggx {
    #[inline]
    fn conductor_albedo(&self) -> Option<(AlbedoTable, f32)> {
        Some((AlbedoTable::GGX, (self.alpha_x() * self.alpha_y()).sqrt()))
    }

    #[inline]
    fn ggx_roughness(&self) -> Option<(f32, f32)> {
        Some((self.alpha_x, self.alpha_y))
    }

    #[inline]
    fn d_wi64_unchecked(&self, wi: Vec3, wm: DVec3) -> f64 {
        smith_d_wi64(self, wi, wm)
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
        let (x, y) = (slope_x / self.alpha_x, slope_y / self.alpha_y);
        let t = 1.0 + x * x + y * y;
        FRAC_1_PI / (self.alpha_x * self.alpha_y * t * t)
    }

    /// D(ωm) = 1 / (π αx αy (m.x²/αx² + m.y²/αy² + m.z²)²) for m.z > 0: the slope form
    /// multiplied through by cos⁴θm, finite down to m.z = 0.
    #[inline]
    fn d(&self, wm: Vec3) -> f32 {
        require!(is_direction(wm), 0.0; wm);
        if wm.z <= 0.0 {
            return 0.0;
        }
        d_of(self.alpha_x, self.alpha_y, V3::of(wm), FRAC_1_PI)
    }

    #[inline]
    fn d64_unchecked(&self, wm: DVec3) -> f64 {
        if wm.z <= 0.0 {
            return 0.0;
        }
        let (ax, ay) = (f64::from(self.alpha_x), f64::from(self.alpha_y));
        d_of(ax, ay, V3::new(wm.x, wm.y, wm.z), core::f64::consts::FRAC_1_PI)
    }

    /// (|h|²/t)²/(π αx αy) with t = h.x²/αx² + h.y²/αy² + h.z²: [`Self::d64_unchecked`]'s
    /// form multiplied through by |h|⁴ (D is homogeneous of degree 0 in its argument). Sums of
    /// squares only: a few f64 ulps for every h, as for a unit argument.
    #[inline]
    fn d64_of_sum_unchecked(&self, h: DVec3) -> f64 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let (ax, ay) = (f64::from(self.alpha_x), f64::from(self.alpha_y));
        d_of_sum(ax, ay, V3::new(h.x, h.y, h.z), core::f64::consts::FRAC_1_PI)
    }

    /// D(ĥ)/(4A) = (|h|²/t)²/(4π αx αy A) written with t′ = t αx²αy² = h.x²αy² + h.y²αx² +
    /// h.z²αx²αy² as |h|⁴ (αx αy)³/(4π t′² A) ([`Ggx::scaled_t`]): one division instead of
    /// five, the same sums of squares (a few f64 ulps). For αx αy outside [1e-60, 1e60], where
    /// t′² could leave f64's normal range, the default form.
    #[inline]
    fn reflection_density_of_sum_unchecked(&self, h: DVec3, area: f32) -> f32 {
        let Some((t, axy)) = self.scaled_t(h) else {
            return (0.25 * self.d64_of_sum_unchecked(h) / f64::from(area)) as f32;
        };
        if h.z <= 0.0 {
            return 0.0;
        }
        let len_sq = h.length_squared();
        let numerator = (len_sq * len_sq) * (axy * axy * axy);
        (numerator / (4.0 * core::f64::consts::PI * (t * t) * f64::from(area))) as f32
    }

    /// D(ĥ)/(|h|⁴A) = 1/(π αx αy t² A) (t of [`Self::d64_of_sum_unchecked`]), written as
    /// (αx αy)³/(π t′² A) with t′ = t αx²αy² ([`Ggx::scaled_t`]): one division, no |h|², a
    /// few f64 ulps. The default form where αx αy is outside [1e-60, 1e60] or the quotient is
    /// not a normal f64 (t′ ≈ |h|² max(αx, αy, αx αy)² squared overflows f64 only for |h|, an
    /// index η, beyond ~1e70 at moderate α).
    #[inline]
    fn d64_over_len4_area_unchecked(&self, h: DVec3, area: f32) -> f64 {
        if h.z <= 0.0 {
            return 0.0;
        }
        if let Some((t, axy)) = self.scaled_t(h) {
            let d = (axy * axy * axy) / (core::f64::consts::PI * (t * t) * f64::from(area));
            if d.is_normal() {
                return d;
            }
        }
        d64_over_len4_area(self, h, area)
    }

    /// The f32 form's cancellation-free q / (2z(z + √(z² + q))) in f64.
    #[inline]
    fn lambda64(&self, w: Vec3) -> f64 {
        let (x, y) = (f64::from(self.alpha_x) * f64::from(w.x), f64::from(self.alpha_y) * f64::from(w.y));
        let (q, z) = (x * x + y * y, f64::from(w.z));
        // unsaturated: ±∞ at exactly grazing directions
        lambda_signed(lambda_up_unsaturated(q, z.abs()), z)
    }

    /// The f32 forms of [`Self::projected_area`] in f64.
    #[inline]
    fn projected_area64(&self, w: Vec3) -> f64 {
        let (x, y) = (f64::from(self.alpha_x) * f64::from(w.x), f64::from(self.alpha_y) * f64::from(w.y));
        projected_area_of(x * x + y * y, f64::from(w.z))
    }

    #[inline]
    fn lambda_unchecked(&self, w: Vec3) -> f32 {
        let q = projected_roughness_sq(self.alpha_x, self.alpha_y, w);
        // Λ of the upper hemisphere at |cos θ|: z = −0 is the horizon seen from above, like +0
        // (passing w.z itself gave lambda_up(q, −0) = q/(−0) = −∞)
        lambda_signed(lambda_up(q, w.z.abs()), w.z)
    }

    /// ½(cos θ + √(cos²θ + αᵢ² sin²θ)) above the horizon (supplement §2.3) and the
    /// equivalent αᵢ² sin²θ / (2(√(cos²θ + αᵢ² sin²θ) − cos θ)) below it, which has no
    /// cancellation there.
    #[inline]
    fn projected_area_unchecked(&self, w: Vec3) -> f32 {
        projected_area_of(projected_roughness_sq(self.alpha_x, self.alpha_y, w), w.z)
    }

    /// Exact for every ωi: stretch ωi to α = 1, sample the visible hemisphere with the
    /// spherical cap, unstretch (Dupuy and Benyoub 2023, with the cap z > −ωi.z, which is
    /// also valid for ωi.z < 0). The stretched ωi is not normalized: the cap is sampled at its
    /// scale (a square root, no division).
    #[inline(always)]
    fn sample_d_wi_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        sample_spherical_cap(self, wi, u1, u2)
    }

    #[inline(always)]
    fn sample_d_wi_scaled_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> (Vec3, f32) {
        sample_spherical_cap_scaled(self, wi, u1, u2)
    }

    /// D(ωh)/(4 A(ωi)) in f32 from the unnormalized sum h = ωi + ωo: D is homogeneous of
    /// degree 0 in its argument, D(ĥ) = (|h|²/t)²/(π αx αy) with t = h.x²/αx² + h.y²/αy² + h.z²,
    /// so no normalization is needed. Every term of |h|² and t is a square (no cancellation)
    /// and each component of h carries only the rounding of one addition, so the relative
    /// error is bounded independently of α and of the angle between the directions: at most
    /// about 34 half-ulps (2u, u = 2⁻²⁴: h, the stretch and the squares 4u per term, |h|²/t
    /// 12u, squared 25u, A(ωi) 4u, the product and the division 5u), i.e. below 4e-6, tested
    /// against an f64 reference in `tests/single_scattering.rs`. Where |h|² or t is below
    /// 2⁻¹⁰⁰ (subnormal terms) or the result is not a normal f32, the f64 form serves.
    #[inline(always)]
    fn reflection_density_unchecked(&self, wi: Vec3, wo: Vec3) -> f32 {
        self.reflection_density_over(wi, wo, self.projected_area_unchecked(wi))
    }

    /// [`Self::reflection_density_unchecked`]'s f32 form with the given area.
    #[inline(always)]
    fn reflection_density_over_unchecked(&self, wi: Vec3, wo: Vec3, area: f32) -> f32 {
        self.reflection_density_over(wi, wo, area)
    }

    /// The bounded cap of Eto and Tokuyoshi 2023 ([`GgxBoundedCap`](crate::GgxBoundedCap)),
    /// with its bounded projected area A_b = (L + k ωi.z)/2 (eq. 8).
    #[inline(always)]
    fn sample_mirror_normal_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> (Vec3, f32) {
        (sample_bounded_cap(self, wi, u1, u2), bounded_area(self, wi))
    }

    #[inline(always)]
    fn mirror_sampling_area_unchecked(&self, wi: Vec3) -> f32 {
        bounded_area(self, wi)
    }
}

impl Ggx {
    /// D(ωh)/(4 `area`) in f32 from the unnormalized sum h = ωi + ωo (see
    /// [`MicrosurfaceSlope::reflection_density_unchecked`], which passes A(ωi); the bounded cap
    /// passes its A_b), with the f64 form where a term is subnormal or the result is not a
    /// normal f32.
    #[inline(always)]
    pub(crate) fn reflection_density_over(&self, wi: Vec3, wo: Vec3, area: f32) -> f32 {
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let h = V3::of(wi + wo);
        let (density, len_sq, t) = reflection_density_of(ax, ay, h, area);
        if len_sq >= F32_DENSITY_MIN_SUM && t >= F32_DENSITY_MIN_SUM && density.is_normal() {
            density
        } else {
            reflection_density64_over(self, wi, wo, area)
        }
    }
}
