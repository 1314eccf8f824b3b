//! Elliptical anisotropy with correlation: an axis-aligned slope distribution rotated in the
//! tangent plane (Dupuy 2015, thesis §2.3).

use super::{Beckmann, Ggx, MicrosurfaceSlope, is_direction};
use crate::error::Error;
use crate::vector::ensure_visible;
use glam::{DVec3, Vec3};

/// A slope distribution with independent roughnesses along x and y, from which
/// [`Elliptical`] builds the rotated (correlated) one: [`Ggx`] and [`Beckmann`].
///
/// Its distribution at α = 1 must be rotation invariant (isotropic), which is what makes the
/// rotated distribution depend on the ellipse alone (Dupuy 2015, eq. 2.27).
pub trait AxisAlignedSlope: MicrosurfaceSlope {
    /// The distribution with roughness `alpha_x` along x and `alpha_y` along y.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if a roughness is NaN, infinite or ≤ 0.
    fn axis_aligned(alpha_x: f32, alpha_y: f32) -> Result<Self, Error>;
}

impl AxisAlignedSlope for Ggx {
    #[inline]
    fn axis_aligned(alpha_x: f32, alpha_y: f32) -> Result<Self, Error> {
        Ggx::new(alpha_x, alpha_y)
    }
}

impl AxisAlignedSlope for Beckmann {
    #[inline]
    fn axis_aligned(alpha_x: f32, alpha_y: f32) -> Result<Self, Error> {
        Beckmann::new(alpha_x, alpha_y)
    }
}

/// An elliptically anisotropic slope distribution with correlation (Dupuy 2015, thesis §2.3):
/// the axis-aligned distribution `S` with radii (α₁, α₂) rotated by φα in the tangent plane.
///
/// Two equivalent parameterizations:
/// * the **ellipse** (α₁, α₂, φα): the slopes' scale matrix is Σ = R(φα) diag(α₁², α₂²) R(φα)ᵀ,
///   with α₁ along the unit vector (cos φα, sin φα);
/// * the **bivariate** parameters (αx, αy, ρ): Σ = [[αx², ρ αx αy], [ρ αx αy, αy²]], i.e. the
///   marginal roughnesses and the correlation of the two slopes.
///
/// They are related by eqs. 2.29–2.31 (αx² = α₁² cos²φα + α₂² sin²φα,
/// αy² = α₁² sin²φα + α₂² cos²φα, ρ αx αy = (α₁² − α₂²) cos φα sin φα) and, the other way, by
/// eqs. 2.32–2.33 (the eigenvalues of Σ) with tan 2φα = 2ρ αx αy/(αx² − αy²). (Eq. 2.34 as
/// printed returns −φα, and eq. 2.25 rotates by +φα, i.e. puts α₁ at −φα; the bivariate form
/// eq. 2.26, which this type implements, fixes the sign convention used here.)
///
/// D is eq. 2.26, D(ωm) = P_std(x̃/αx, (αx ỹ − ρ αy x̃)/(αx αy √(1−ρ²))) sec⁴θm/(αx αy √(1−ρ²)),
/// which equals the axis-aligned D of (α₁, α₂) at ωm rotated by −φα; Λ follows by roughness
/// invariance (thesis §2.3: Λ of the stretched direction a = αx x + ρ αy y, b = αy y √(1−ρ²),
/// equivalently the axis-aligned Λ of the rotated direction), and visible normals are sampled
/// exactly by eq. 2.35 in its rotated form (any square root L of Σ maps the isotropic standard
/// distribution onto the same one; this type uses L = R(φα) diag(α₁, α₂) and the axis-aligned
/// sampler of `S`). Every query is therefore `S`'s on a direction rotated by −φα about z, which
/// is exact except for one rounding of the rotated direction to f32 (the same as the rounding of
/// the input itself): the accuracy of each method is `S`'s for an input perturbed by half an
/// ulp per component. Normals given in f64 (`d64`, `d_wi64`) are rotated in f64. The z
/// component is never changed, so above / below the horizon is decided exactly.
///
/// [`MicrosurfaceSlope::alpha_x`] and [`MicrosurfaceSlope::alpha_y`] are the marginals αx and
/// αy; [`MicrosurfaceSlope::alpha_i`] includes the correlation,
/// αᵢ² = αx² cos²φ + 2ρ αx αy cos φ sin φ + αy² sin²φ. The walks, the position-free estimators,
/// single scattering and [`MicrofacetBsdf`](crate::MicrofacetBsdf) accept it as any other slope
/// (they reflect in real microfacet space), and [`Compensated`](crate::Compensated)
/// reads its albedo tables at √(α₁ α₂) (the rotation-invariant geometric mean, what √(αx αy) is
/// for an axis-aligned slope); `MicrofacetBsdf`'s smooth and walk-length limits compare
/// [`MicrosurfaceSlope::alpha_max`] = max(α₁, α₂), the same for every φα, against their
/// thresholds.
/// It does not implement [`VCavitySlope`](crate::vndf::VCavitySlope), whose closed forms are written
/// in the stretched frame of an axis-aligned distribution.
///
/// # Examples
/// ```
/// use microsurface::{Beckmann, Elliptical};
/// use microsurface::slope::MicrosurfaceSlope;
/// use microsurface::glam::Vec3;
///
/// let slope = Elliptical::<Beckmann>::from_ellipse(0.5, 0.1, 0.3)?;
/// let (alpha_x, alpha_y, rho) = slope.bivariate();
/// let same = Elliptical::<Beckmann>::from_bivariate(alpha_x, alpha_y, rho)?;
/// let wm = Vec3::new(0.1, 0.2, 0.9).normalize();
/// assert!((slope.d(wm) - same.d(wm)).abs() <= 1e-4 * slope.d(wm));
/// assert!(Elliptical::<Beckmann>::from_bivariate(0.5, 0.5, 1.0).is_err());
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elliptical<S> {
    /// The axis-aligned distribution of radii (α₁, α₂).
    axis_aligned: S,
    /// The ellipse (α₁, α₂, φα) as given or derived.
    ellipse: (f32, f32, f32),
    /// The bivariate parameters (αx, αy, ρ) as given or derived.
    bivariate: (f32, f32, f32),
    /// cos φα and sin φα.
    cos_phi: f64,
    sin_phi: f64,
    /// The scale matrix Σ: αx², ρ αx αy, αy².
    sigma_xx: f64,
    sigma_xy: f64,
    sigma_yy: f64,
}

/// The largest |ρ| that [`Elliptical::from_ellipse`] derives: 1 − 2⁻²⁴, the largest f32 below 1.
const MAX_RHO: f32 = 1.0 - f32::EPSILON / 2.0;

impl<S: AxisAlignedSlope> Elliptical<S> {
    /// The distribution of the ellipse with radii `alpha_1` (along (cos φα, sin φα)) and
    /// `alpha_2`, at angle `phi` = φα (radians, any finite value).
    ///
    /// The derived correlation ρ (eq. 2.31) is rounded to f32 and kept in
    /// [−(1 − 2⁻²⁴), 1 − 2⁻²⁴], so that [`Elliptical::bivariate`] is always accepted by
    /// [`Elliptical::from_bivariate`]. The round trip reproduces the ellipse to f32 rounding of
    /// (αx, αy, ρ); for ellipses so thin that 1 − |ρ| < 2⁻²⁴ (α₂/α₁ ≲ 2⁻¹² at φα = π/4) the
    /// bivariate form cannot represent them in f32 and describes a slightly wider one.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `alpha_1` or `alpha_2` is NaN, infinite or ≤ 0 (`"alpha_1"`,
    /// `"alpha_2"`), or `phi` is not finite; `"alpha_x"`/`"alpha_y"` if a marginal overflows f32.
    pub fn from_ellipse(alpha_1: f32, alpha_2: f32, phi: f32) -> Result<Self, Error> {
        let alpha_1 = Error::check_positive("alpha_1", alpha_1)?;
        let alpha_2 = Error::check_positive("alpha_2", alpha_2)?;
        if !phi.is_finite() {
            return Err(Error::InvalidParameter { name: "phi", value: phi, expected: "finite" });
        }
        let (sin_phi, cos_phi) = f64::from(phi).sin_cos();
        let (a1, a2) = (f64::from(alpha_1), f64::from(alpha_2));
        let (s1, s2) = (a1 * a1, a2 * a2);
        // eqs. 2.29–2.31
        let sigma_xx = s1 * cos_phi * cos_phi + s2 * sin_phi * sin_phi;
        let sigma_yy = s1 * sin_phi * sin_phi + s2 * cos_phi * cos_phi;
        let sigma_xy = (s1 - s2) * cos_phi * sin_phi;
        let alpha_x = Error::check_positive("alpha_x", sigma_xx.sqrt() as f32)?;
        let alpha_y = Error::check_positive("alpha_y", sigma_yy.sqrt() as f32)?;
        // |ρ| ≤ 1 in f64 (Cauchy–Schwarz) but rounds to ±1 in f32 for very thin ellipses
        let rho = ((sigma_xy / (sigma_xx * sigma_yy).sqrt()) as f32).clamp(-MAX_RHO, MAX_RHO);
        Ok(Self {
            axis_aligned: S::axis_aligned(alpha_1, alpha_2)?,
            ellipse: (alpha_1, alpha_2, phi),
            bivariate: (alpha_x, alpha_y, rho),
            cos_phi,
            sin_phi,
            sigma_xx,
            sigma_xy,
            sigma_yy,
        })
    }

    /// The distribution of marginal roughnesses `alpha_x`, `alpha_y` and slope correlation `rho`.
    ///
    /// The ellipse is α₁ ≥ α₂ (eqs. 2.32–2.33, α₂² formed as det Σ/α₁², free of cancellation)
    /// and φα = ½ atan2(2ρ αx αy, αx² − αy²) ∈ [−π/2, π/2] (0 for an isotropic Σ).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `alpha_x` or `alpha_y` is NaN, infinite or ≤ 0, or `rho` is
    /// not in (−1, 1) (`"rho"`, NaN included).
    pub fn from_bivariate(alpha_x: f32, alpha_y: f32, rho: f32) -> Result<Self, Error> {
        let alpha_x = Error::check_positive("alpha_x", alpha_x)?;
        let alpha_y = Error::check_positive("alpha_y", alpha_y)?;
        if rho.is_nan() || rho.abs() >= 1.0 {
            return Err(Error::InvalidParameter { name: "rho", value: rho, expected: "in (-1, 1)" });
        }
        let (ax, ay, r) = (f64::from(alpha_x), f64::from(alpha_y), f64::from(rho));
        let (sigma_xx, sigma_yy, sigma_xy) = (ax * ax, ay * ay, r * ax * ay);
        let half_gap = 0.5 * (sigma_xx - sigma_yy);
        let radius = half_gap.hypot(sigma_xy);
        let s1 = 0.5 * (sigma_xx + sigma_yy) + radius;
        // det Σ = αx² αy² (1 − ρ²), with 1 − ρ² = (1 − ρ)(1 + ρ) exact for f32 ρ
        let s2 = sigma_xx * sigma_yy * ((1.0 - r) * (1.0 + r)) / s1;
        let phi = 0.5 * sigma_xy.atan2(half_gap);
        let (sin_phi, cos_phi) = phi.sin_cos();
        let alpha_1 = Error::check_positive("alpha_1", s1.sqrt() as f32)?;
        let alpha_2 = Error::check_positive("alpha_2", s2.sqrt() as f32)?;
        Ok(Self {
            axis_aligned: S::axis_aligned(alpha_1, alpha_2)?,
            ellipse: (alpha_1, alpha_2, phi as f32),
            bivariate: (alpha_x, alpha_y, rho),
            cos_phi,
            sin_phi,
            sigma_xx,
            sigma_xy,
            sigma_yy,
        })
    }
}

impl<S> Elliptical<S> {
    /// The ellipse (α₁, α₂, φα): as given to [`Elliptical::from_ellipse`], or derived by
    /// [`Elliptical::from_bivariate`].
    #[inline]
    pub fn ellipse(&self) -> (f32, f32, f32) {
        self.ellipse
    }

    /// The bivariate parameters (αx, αy, ρ): as given to [`Elliptical::from_bivariate`], or
    /// derived by [`Elliptical::from_ellipse`] (eqs. 2.29–2.31).
    #[inline]
    pub fn bivariate(&self) -> (f32, f32, f32) {
        self.bivariate
    }

    /// The axis-aligned distribution of radii (α₁, α₂) that this one rotates by φα.
    #[inline]
    pub fn axis_aligned(&self) -> &S {
        &self.axis_aligned
    }

    /// A direction in the ellipse's frame (rotated by −φα about z), computed in f64.
    #[inline(always)]
    fn to_ellipse64(&self, w: DVec3) -> DVec3 {
        DVec3::new(self.cos_phi * w.x + self.sin_phi * w.y, self.cos_phi * w.y - self.sin_phi * w.x, w.z)
    }

    /// [`Self::to_ellipse64`] of an f32 direction, rounded once to f32 (z unchanged).
    #[inline(always)]
    fn to_ellipse(&self, w: Vec3) -> Vec3 {
        let r = self.to_ellipse64(w.as_dvec3());
        Vec3::new(r.x as f32, r.y as f32, w.z)
    }

    /// A direction of the ellipse's frame back in the tangent frame (rotated by +φα), rounded
    /// once to f32 (z unchanged).
    #[inline(always)]
    fn to_tangent(&self, m: Vec3) -> Vec3 {
        let (x, y) = (f64::from(m.x), f64::from(m.y));
        Vec3::new(
            (self.cos_phi * x - self.sin_phi * y) as f32,
            (self.sin_phi * x + self.cos_phi * y) as f32,
            m.z,
        )
    }
}

impl<S: AxisAlignedSlope> crate::sealed::Sealed for Elliptical<S> {}

impl<S: AxisAlignedSlope> MicrosurfaceSlope for Elliptical<S> {
    /// The axis-aligned slope's: √(α₁ α₂) is invariant under the rotation.
    #[inline]
    fn conductor_albedo(&self) -> Option<(crate::albedo::AlbedoTable, f32)> {
        self.axis_aligned().conductor_albedo()
    }

    /// The marginal roughness αx (eq. 2.29).
    #[inline]
    fn alpha_x(&self) -> f32 {
        self.bivariate.0
    }

    /// The marginal roughness αy (eq. 2.30).
    #[inline]
    fn alpha_y(&self) -> f32 {
        self.bivariate.1
    }

    /// max(α₁, α₂), the ellipse's largest radius (eqs. 2.32–2.33), whatever φα.
    #[inline]
    fn alpha_max(&self) -> f32 {
        self.ellipse.0.max(self.ellipse.1)
    }

    /// Eq. 2.27: the axis-aligned density of the slopes rotated by −φα.
    #[inline]
    fn p22(&self, slope_x: f32, slope_y: f32) -> f32 {
        require!(!slope_x.is_nan() && !slope_y.is_nan(), 0.0; slope_x, slope_y);
        let r = self.to_ellipse64(DVec3::new(f64::from(slope_x), f64::from(slope_y), 0.0));
        self.axis_aligned.p22(r.x as f32, r.y as f32)
    }

    /// Eq. 2.26, evaluated as the axis-aligned D of ωm rotated in f64.
    #[inline]
    fn d(&self, wm: Vec3) -> f32 {
        require!(is_direction(wm), 0.0; wm);
        self.d64_unchecked(wm.as_dvec3()) as f32
    }

    #[inline]
    fn d64_unchecked(&self, wm: DVec3) -> f64 {
        self.axis_aligned.d64_unchecked(self.to_ellipse64(wm))
    }

    #[inline]
    fn lambda_unchecked(&self, w: Vec3) -> f32 {
        self.axis_aligned.lambda_unchecked(self.to_ellipse(w))
    }

    #[inline]
    fn lambda64(&self, w: Vec3) -> f64 {
        self.axis_aligned.lambda64(self.to_ellipse(w))
    }

    #[inline]
    fn ln_lambda(&self, w: Vec3) -> f64 {
        self.axis_aligned.ln_lambda(self.to_ellipse(w))
    }

    #[inline]
    fn projected_area_unchecked(&self, w: Vec3) -> f32 {
        self.axis_aligned.projected_area_unchecked(self.to_ellipse(w))
    }

    #[inline]
    fn projected_area64(&self, w: Vec3) -> f64 {
        self.axis_aligned.projected_area64(self.to_ellipse(w))
    }

    /// αᵢ² = (Σxx x² + 2Σxy x y + Σyy y²)/(x² + y²), the correlated form; αx at ω = ±z.
    #[inline]
    fn alpha_i(&self, w: Vec3) -> f32 {
        require!(is_direction(w), f32::NAN; w);
        let scale = w.x.abs().max(w.y.abs());
        if scale == 0.0 {
            return self.alpha_x();
        }
        let (x, y) = (f64::from(w.x / scale), f64::from(w.y / scale));
        let q = self.sigma_xx * x * x + 2.0 * self.sigma_xy * x * y + self.sigma_yy * y * y;
        (q / (x * x + y * y)).sqrt() as f32
    }

    #[inline]
    fn d_wi(&self, wi: Vec3, wm: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wm), 0.0; wi, wm);
        self.d_wi64_unchecked(wi, wm.as_dvec3()) as f32
    }

    /// The axis-aligned D_ωi of the rotated pair, with the visibility ⟨ωi, ωm⟩ > 0 decided on the
    /// given (unrotated) vectors, as the samplers guarantee it.
    #[inline]
    fn d_wi64_unchecked(&self, wi: Vec3, wm: DVec3) -> f64 {
        let cos_im = wi.as_dvec3().dot(wm);
        if cos_im <= 0.0 || wm.z <= 0.0 {
            return 0.0;
        }
        let (wi_e, wm_e) = (self.to_ellipse(wi), self.to_ellipse64(wm));
        let cos_e = wi_e.as_dvec3().dot(wm_e);
        if cos_e > 0.0 {
            // the rotated pair's cosine differs from cos_im only by the rounding of wi_e
            return self.axis_aligned.d_wi64_unchecked(wi_e, wm_e) * (cos_im / cos_e);
        }
        let area = self.axis_aligned.projected_area64(wi_e);
        if area > 0.0 { cos_im * self.axis_aligned.d64_unchecked(wm_e) / area } else { 0.0 }
    }

    /// Eq. 2.35 in its rotated form: `S`'s exact sampler from ωi rotated by −φα, its normal
    /// rotated back by +φα (and made visible from ωi against the rounding of the rotations).
    #[inline]
    fn sample_d_wi_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        let wm = self.axis_aligned.sample_d_wi_unchecked(self.to_ellipse(wi), u1, u2);
        ensure_visible(wi, self.to_tangent(wm))
    }

    /// `S`'s reflection sampler in the ellipse's frame (for GGX the bounded cap, whose bound
    /// depends on min(α₁, α₂) and on θi only, both rotation invariant), rotated back.
    #[inline]
    fn sample_mirror_normal_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> (Vec3, f32) {
        let (wm, area) = self.axis_aligned.sample_mirror_normal_unchecked(self.to_ellipse(wi), u1, u2);
        (ensure_visible(wi, self.to_tangent(wm)), area)
    }

    #[inline]
    fn mirror_sampling_area_unchecked(&self, wi: Vec3) -> f32 {
        self.axis_aligned.mirror_sampling_area_unchecked(self.to_ellipse(wi))
    }
}
