//! The noncentral anisotropic Beckmann lobe of a LEAN/LEADR texel.

use super::SlopeMoments;
use crate::error::Error;
use crate::noncentral::{Noncentral, NoncentralBsdf, NoncentralMaterial};
use crate::slope::{Beckmann, Elliptical};
use glam::Vec2;

/// The smallest roughness a LEADR lobe is given along any direction: the covariance's
/// eigenvalues are floored at `MIN_LEADR_ALPHA²/2` (the listing of the thesis floors
/// αx, αy at 1e-5). Below it a Beckmann lobe is far narrower than a renderer resolves
/// (`SMOOTH_ALPHA` = 1e-3 already makes a Dirac lobe).
pub const MIN_LEADR_ALPHA: f32 = 1e-4;

/// The smallest ratio of the covariance's eigenvalues λ₂/λ₁ a LEADR lobe keeps: the smaller
/// eigenvalue is floored at this fraction of the larger. It keeps the correlation
/// |ρ| ≤ 1 − 5e-7, which f32 distinguishes from 1 (its spacing below 1 is 6e-8), for
/// every covariance.
pub const MIN_EIGENVALUE_RATIO: f32 = 1e-6;

/// Whether [`LeadrLobe::from_moments`] had to change the covariance of its moments.
///
/// # Examples
/// ```
/// use microsurface::Beckmann;
/// use microsurface::leadr::{CovarianceTreatment, LeadrLobe, SlopeMoments};
/// use microsurface::glam::Vec2;
///
/// let base = Beckmann::isotropic(0.2)?;
/// let moments = SlopeMoments::from_slope(Vec2::new(0.1, 0.0), base)?;
/// assert_eq!(LeadrLobe::from_moments(&moments).treatment(), CovarianceTreatment::AsGiven);
/// // E[x̃²] = E[x̃]² and E[ỹ²] = E[ỹ]²: no variance at all, which no lobe has
/// let degenerate = SlopeMoments::new(0.1, 0.0, 0.01, 0.0, 0.0)?;
/// assert_eq!(LeadrLobe::from_moments(&degenerate).treatment(), CovarianceTreatment::EigenvalueFloored);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CovarianceTreatment {
    /// The covariance was positive definite with eigenvalues above the floor, used as is.
    AsGiven,
    /// An eigenvalue was below the floor (the moments were not a valid covariance, e.g.
    /// after rounding, or were narrower than [`MIN_LEADR_ALPHA`]) and was raised to it.
    EigenvalueFloored,
}

/// A noncentral, anisotropic, correlated Beckmann slope distribution: mean slope (x̃n, ỹn)
/// and bivariate roughness (αx, αy, ρ) (Dupuy 2015, eq. 3.2):
///
/// P²²(x̃, ỹ) = exp(−½ dᵀΣ⁻¹d) / (2π √det Σ), d = (x̃ − x̃n, ỹ − ỹn),
/// Σ = ½ [[αx², ρ αx αy], [ρ αx αy, αy²]],
///
/// the lobe LEADR mapping assigns to a texel from its moments (eqs. 3.5–3.9 inverted):
/// x̃n = E₁, ỹn = E₂, αx = √(2(E₃ − E₁²)), αy = √(2(E₄ − E₂²)), ρ = 2(E₅ − E₁E₂)/(αx αy).
///
/// **Beckmann only.** The moment matching needs the second slope moments of the base
/// distribution; GGX's (and every Student-t-like distribution's with ν ≤ 2) diverge, so a GGX
/// texel has no finite E₃ and the linear representation does not exist (thesis §3.3).
///
/// # Examples
///
/// ```
/// use microsurface::glam::Vec2;
/// use microsurface::Beckmann;
/// use microsurface::leadr::{CovarianceTreatment, LeadrLobe, SlopeMoments};
///
/// let m = SlopeMoments::from_slope(Vec2::new(0.1, -0.2), Beckmann::new(0.3, 0.1)?)?;
/// let lobe = LeadrLobe::from_moments(&m);
/// assert_eq!(lobe.treatment(), CovarianceTreatment::AsGiven);
/// assert!((lobe.alpha_x() - 0.3).abs() < 1e-6 && (lobe.alpha_y() - 0.1).abs() < 1e-6);
/// assert!(lobe.rho().abs() < 1e-5 && lobe.mean_slope() == Vec2::new(0.1, -0.2));
/// // the crate's noncentral slope distribution, for D, G1 and visible-normal sampling
/// let slope = lobe.slope();
/// let wi = microsurface::glam::Vec3::new(0.5, 0.0, 0.866);
/// assert!(slope.g1(wi) > 0.0 && slope.d(slope.mean_normal()) > 0.0);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeadrLobe {
    mean_slope: Vec2,
    alpha_x: f32,
    alpha_y: f32,
    rho: f32,
    treatment: CovarianceTreatment,
    slope: Noncentral<Elliptical<Beckmann>>,
}

impl LeadrLobe {
    /// The lobe of a texel's moments (eqs. 3.5–3.9 inverted; see [`LeadrLobe`]).
    ///
    /// Moments whose covariance Σ = [[E₃ − E₁², E₅ − E₁E₂], [·, E₄ − E₂²]] (formed in f64) is
    /// not positive definite, or has an eigenvalue below the floor
    /// λ_min = max(`MIN_LEADR_ALPHA`²/2, `MIN_EIGENVALUE_RATIO` · λ₁), λ₁ the larger
    /// eigenvalue, get the covariance nearest to Σ in the Frobenius norm among those whose
    /// eigenvalues are all ≥ λ_min: Σ's eigenvectors with its eigenvalues raised to λ_min
    /// (the projection onto that set; [`CovarianceTreatment::EigenvalueFloored`]). The mean
    /// slope is kept. Linear filtering of valid moments gives a valid covariance in exact
    /// arithmetic (a mixture's covariance is the mean of the covariances plus that of the
    /// means), so the floor only catches rounding, moments given by hand, and base
    /// roughness below [`MIN_LEADR_ALPHA`]. The result is always finite.
    #[must_use]
    pub fn from_moments(moments: &SlopeMoments) -> Self {
        let [xx, yy, xy] = moments.covariance64();
        let (half_sum, half_diff) = (0.5 * (xx + yy), 0.5 * (xx - yy));
        let radius = half_diff.hypot(xy);
        let (l1, l2) = (half_sum + radius, half_sum - radius);
        let min_variance = 0.5 * f64::from(MIN_LEADR_ALPHA) * f64::from(MIN_LEADR_ALPHA);
        let floor = min_variance.max(f64::from(MIN_EIGENVALUE_RATIO) * l1);
        let (cov, treatment) = if l2 >= floor {
            ([xx, yy, xy], CovarianceTreatment::AsGiven)
        } else {
            let (l1, l2) = (l1.max(floor), floor);
            let (mid, half_gap) = (0.5 * (l1 + l2), 0.5 * (l1 - l2));
            // Σ' = mid·I + half_gap·[[cos 2φ, sin 2φ], [sin 2φ, −cos 2φ]] (φ the major axis)
            let (c2, s2) = if radius > 0.0 { (half_diff / radius, xy / radius) } else { (1.0, 0.0) };
            (
                [mid + half_gap * c2, mid - half_gap * c2, half_gap * s2],
                CovarianceTreatment::EigenvalueFloored,
            )
        };
        let [xx, yy, xy] = cov;
        let rho = (xy / (xx * yy).sqrt()).clamp(-1.0, 1.0) as f32;
        let (alpha_x, alpha_y) = ((2.0 * xx).sqrt() as f32, (2.0 * yy).sqrt() as f32);
        let mean_slope = moments.mean();
        // roughness ≥ MIN_LEADR_ALPHA and finite, |ρ| < 1 (the eigenvalue ratio floor), a
        // finite mean: both constructors' domains
        let slope = Elliptical::<Beckmann>::from_bivariate(alpha_x, alpha_y, rho)
            .and_then(|central| Noncentral::new(central, mean_slope))
            .expect("a floored covariance and finite moments are a valid lobe");
        Self { mean_slope, alpha_x, alpha_y, rho, treatment, slope }
    }

    /// The mean slope (x̃n, ỹn) of the mesosurface.
    #[must_use]
    pub fn mean_slope(&self) -> Vec2 {
        self.mean_slope
    }

    /// Roughness along x, ≥ [`MIN_LEADR_ALPHA`].
    #[must_use]
    pub fn alpha_x(&self) -> f32 {
        self.alpha_x
    }

    /// Roughness along y, ≥ [`MIN_LEADR_ALPHA`].
    #[must_use]
    pub fn alpha_y(&self) -> f32 {
        self.alpha_y
    }

    /// The correlation of the slopes, |ρ| ≤ 1 − [`MIN_EIGENVALUE_RATIO`]/2.
    #[must_use]
    pub fn rho(&self) -> f32 {
        self.rho
    }

    /// Whether the covariance of the moments was used as is.
    #[must_use]
    pub fn treatment(&self) -> CovarianceTreatment {
        self.treatment
    }

    /// The lobe as the crate's slope distribution: the correlated Beckmann distribution
    /// [`Elliptical::<Beckmann>::from_bivariate`] of (αx, αy, ρ), sheared to the mean slope by
    /// [`Noncentral::new`], whose D (eq. 3.2), projected area and G1 (eq. 3.3) and visible
    /// normals (eq. 3.4) are those of the lobe.
    ///
    /// Built once by [`Self::from_moments`], whose lobes are always in the constructors'
    /// domains (roughness ≥ [`MIN_LEADR_ALPHA`] and finite, |ρ| < 1, a finite mean).
    #[must_use]
    pub fn slope(&self) -> Noncentral<Elliptical<Beckmann>> {
        self.slope
    }

    /// The lobe's single-scattering BSDF with `material` (a [`Conductor`](crate::Conductor),
    /// a [`Dielectric`](crate::Dielectric) for filtered glass, or [`Diffuse`](crate::Diffuse)
    /// facets), for renderers: the [`NoncentralBsdf`] of [`Self::slope`] (Dupuy 2015, §3.4: the
    /// filtered texel shaded with the noncentral microfacet BSDF; the models are on
    /// [`NoncentralMaterial`]).
    ///
    /// # Errors
    /// Those of [`NoncentralBsdf::new`] (a mean slope whose squared length overflows f32).
    pub fn bsdf<M: NoncentralMaterial>(
        &self,
        material: M,
    ) -> Result<NoncentralBsdf<Elliptical<Beckmann>, M>, Error> {
        NoncentralBsdf::new(self.slope(), material)
    }

    /// The slope covariance Σ = ½ [[αx², ρ αx αy], [ρ αx αy, αy²]] as [Σxx, Σyy, Σxy].
    #[must_use]
    pub fn covariance(&self) -> [f32; 3] {
        let (ax, ay, rho) = (f64::from(self.alpha_x), f64::from(self.alpha_y), f64::from(self.rho));
        [0.5 * ax * ax, 0.5 * ay * ay, 0.5 * rho * ax * ay].map(|c| c as f32)
    }

    /// The moments of this lobe (eqs. 3.5–3.9): its inverse up to rounding.
    pub fn moments(&self) -> SlopeMoments {
        let m = self.mean_slope.as_dvec2();
        let [xx, yy, xy] = self.covariance().map(f64::from);
        SlopeMoments::from_array64([m.x, m.y, xx + m.x * m.x, yy + m.y * m.y, xy + m.x * m.y])
    }
}
