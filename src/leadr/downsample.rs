//! Dupuy's downsampling operator (thesis §5.1): the slope distribution of a displacement over a
//! base microsurface as the convolution of their slope distributions, tabulated.

use super::fft::{Grid2, convolve};
use super::{SlopeHistogram, SlopeMoments};
use crate::error::Error;
use crate::noncentral::{Noncentral, NoncentralBsdf, NoncentralMaterial};
use crate::slope::MicrosurfaceSlope;
use crate::tabulated::GridSlope;
use glam::{DVec2, DVec3, Vec2};

/// Uniform nodes of the numerical convolution per √2 × the smallest standard deviation of the
/// result (its smallest Beckmann-equivalent roughness).
const NODES_PER_ALPHA: f64 = 16.0;
/// Half-width of the Gaussian displacement's box, in standard deviations (mass outside
/// < 1e-9).
const GAUSSIAN_BOX: f64 = 6.5;
/// Half-width of the base's core box, in its roughness (GGX's density there is 2.4e-4 of its
/// peak, Beckmann's e⁻⁶⁴), at least `BASE_BOX_IN_SIGMAS` standard deviations of the
/// displacement (so that the coarse rule of the tail term resolves it).
const BASE_BOX: f64 = 8.0;
const BASE_BOX_IN_SIGMAS: f64 = 4.0;
/// The base is sampled at the uniform nodes when its smallest roughness spans this many
/// spacings (the trapezoidal rule on GGX's peak then errs by ~e^{−2π·3}), and its mass is
/// spread onto them from a finer quadrature otherwise.
const BASE_NODES_PER_ALPHA: f64 = 3.0;
/// The largest transform per axis (a 1024 × 1024 complex array is 16 MB).
const MAX_TRANSFORM: usize = 1024;
/// Gauss–Hermite rule of 5 points for the standard normal (probabilists'): nodes and weights.
const HERMITE5: [(f64, f64); 5] = [
    (-2.856_970_013_872_805_6, 0.011_257_411_327_720_69),
    (-1.355_626_179_974_265_9, 0.222_075_922_005_612_6),
    (0.0, 0.533_333_333_333_333_3),
    (1.355_626_179_974_265_9, 0.222_075_922_005_612_6),
    (2.856_970_013_872_805_6, 0.011_257_411_327_720_69),
];

/// The slope distribution of a displacement, the input P_X of [`DownsampledSlope`].
///
/// # Examples
/// ```
/// use microsurface::glam::Vec2;
/// use microsurface::leadr::{Displacement, SlopeHistogram, SlopeMoments};
///
/// // a Gaussian of mean slope (0.1, 0) and variance 0.01 per axis, or the slopes themselves
/// let moments = SlopeMoments::new(0.1, 0.0, 0.01 + 0.01, 0.01, 0.0)?;
/// let gaussian = Displacement::Moments(&moments);
/// let slopes = [Vec2::new(0.0, -0.1), Vec2::new(0.2, 0.1)];
/// let histogram = SlopeHistogram::from_slopes(&slopes, 8)?;
/// let tabulated = Displacement::Histogram(&histogram);
/// assert!(matches!((gaussian, tabulated), (Displacement::Moments(_), Displacement::Histogram(_))));
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub enum Displacement<'a> {
    /// The displacement's LEADR moments, a Gaussian of their mean and covariance (eqs.
    /// 3.5–3.9): the moments of the displacement alone, without a base roughness (a texel of a
    /// [`LeadrMap`](crate::leadr::LeadrMap) built on a base: [`SlopeMoments::without_base`]).
    /// A covariance that rounding made slightly indefinite has its negative eigenvalues taken
    /// as 0 (a displacement flat along that axis).
    Moments(&'a SlopeMoments),
    /// A histogram of the displacement's slopes: the mixture of its bins.
    Histogram(&'a SlopeHistogram),
}

/// The slope distribution of a displaced surface whose base material is itself a
/// microsurface: P_Z = P_X ∗ P_Y, the convolution of the displacement's slope distribution P_X
/// and the base's P_Y (Dupuy 2015, §5.1, eqs. 5.1–5.4: the slopes of independent processes add),
/// tabulated as a [`GridSlope`] and sheared to the displacement's mean slope
/// ([`Noncentral`], as LEADR does), so that any base, analytic ([`Ggx`](crate::Ggx),
/// [`Beckmann`](crate::Beckmann), [`Elliptical`](crate::Elliptical)) or data-driven
/// ([`GridSlope`], [`TabulatedSlope`](crate::tabulated::TabulatedSlope), an extracted or
/// measured one), filters a displacement map: the generalization the thesis proposes of LEADR,
/// whose closed form needs Beckmann on both sides.
///
/// * [`Self::grid`] is the centred convolution (the displacement's slopes less their mean,
///   convolved with the base): a [`GridSlope`], usable by every model of the crate (single
///   scattering, the random walks, the position-free estimators, [`MicrofacetBsdf`](crate::MicrofacetBsdf))
///   as a centred table is. [`Self::slope`] shears it to the mean slope for the noncentral
///   single scattering and [`Self::bsdf`] ([`NoncentralBsdf`], any [`NoncentralMaterial`]).
/// * **Histogram** ([`Displacement::Histogram`]): P_Z(h̃) = Σ_b m_b P_Y(h̃ − x̃_b), exact (the
///   mixture of the base shifted to every bin), evaluated where the table needs it.
/// * **Moments** ([`Displacement::Moments`]): P_Z = N(0, Σ) ∗ P_Y computed numerically: the
///   Gaussian and the base's core (|ỹ| ≤ max(8α_Y, 4σ_X) per axis) on a uniform grid of spacing
///   δ = min_axis(α_Z)/16, α_Z² = α_Y² + 2σ_X² (the Beckmann-equivalent roughness of the sum),
///   convolved by the FFT and read bilinearly; the base's tail beyond its core convolved with a
///   5 × 5 Gauss–Hermite rule of the Gaussian (the tail varies on a scale ≥ 4σ_X there).
///   Node-sampled densities integrate spectrally accurately; a base narrower than 3δ, or a
///   Gaussian narrower than δ along an axis, has its mass spread onto the nodes instead
///   (bilinearly, from a finer quadrature), which widens it by at most δ²/6 in variance. The
///   bilinear read widens the result by at most δ²/6 in variance per axis, 1/512 of the
///   smallest variance α_Z²/2: a relative error in the roughness below 1e-3. The transform is
///   at most 1024 × 1024 (δ grows if a very elongated result needs more).
/// * The table: [`GridSlope::from_fn`] with `half_cells` per half axis and the scales
///   (α_Z,x, α_Z,y), normalized (the mass beyond the table, GGX's far tail, is dropped), piecewise
///   constant on its cells: its resolution, not the convolution's, bounds the accuracy (cells of
///   ≈ π α_Z/(N + 1) at the centre).
///
/// Validated (`tests/downsample.rs`) against the closed form, with the convention that a
/// Beckmann density exp(−x̃²/α²)/(πα²) has slope variance α²/2 per axis, so that
/// Beckmann(α) ∗ N(0, σ²I) = Beckmann(√(α² + 2σ²)) (with a covariance, the elliptical Beckmann
/// of Σ_Y + Σ_X, LEADR's lobe): within L1 1e-3 of the closed form tabulated the same way, G1
/// within 1e-3; the table itself is at L1 4e-2 of the continuous density at 48 cells per half
/// axis (∝ 1/N). Against the supersampled BRDF of a displaced rough surface (the LEADR
/// validation metric, 128 cells): relative L1 0.016–0.019 over Beckmann and GGX bases.
///
/// Requires the features `leadr` and `data-driven`.
///
/// # Examples
/// ```
/// use microsurface::glam::Vec2;
/// use microsurface::leadr::{Displacement, DownsampledSlope, SlopeMoments};
/// use microsurface::slope::MicrosurfaceSlope;
/// use microsurface::Ggx;
///
/// // a displacement of mean slope (0.2, 0) and slope variance 0.02 per axis over GGX α = 0.2
/// let (mx, var) = (0.2f32, 0.02f32);
/// let moments = SlopeMoments::new(mx, 0.0, var + mx * mx, var, 0.0)?;
/// let z = DownsampledSlope::new(Displacement::Moments(&moments), Ggx::isotropic(0.2)?, 24)?;
/// assert_eq!(z.mean_slope(), Vec2::new(0.2, 0.0));
/// // the centred table is rougher than the base: more masking at a grazing view
/// let w = microsurface::glam::Vec3::new(0.8, 0.0, 0.6);
/// assert!(z.grid().lambda(w) > Ggx::isotropic(0.2)?.lambda(w));
/// assert!(z.slope().g1(microsurface::glam::Vec3::Z) > 0.9);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug)]
pub struct DownsampledSlope {
    grid: GridSlope,
    mean_slope: Vec2,
}

impl DownsampledSlope {
    /// P_X ∗ P_Y for the displacement `displacement` over the base `base` (assumed centred, as
    /// the crate's slopes are), tabulated with `half_cells` cells per half axis (see the type).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`]: `"mean_slope"` if the displacement's mean slope is not
    /// finite in f32 or its squared norm overflows (as [`NoncentralBsdf::new`]), `"covariance"`
    /// if its covariance is not finite, `"base roughness"` if the base's αx or αy is not finite
    /// and > 0; those of [`GridSlope::from_fn`] (`half_cells` 0 or above 512; a result without
    /// mass).
    pub fn new<S: MicrosurfaceSlope>(
        displacement: Displacement<'_>,
        base: S,
        half_cells: usize,
    ) -> Result<Self, Error> {
        let (mean, covariance) = match displacement {
            Displacement::Moments(m) => (m.mean().as_dvec2(), m.covariance64()),
            Displacement::Histogram(h) => (h.mean64(), h.covariance64()),
        };
        let mean_slope = mean.as_vec2();
        if !(mean_slope.is_finite() && mean_slope.length_squared().is_finite()) {
            let value = mean_slope.length_squared();
            return Err(Error::InvalidParameter {
                name: "mean_slope",
                value,
                expected: "finite, x̃n² + ỹn² finite",
            });
        }
        if let Some(&c) = covariance.iter().find(|c| !c.is_finite()) {
            return Err(Error::InvalidParameter { name: "covariance", value: c as f32, expected: "finite" });
        }
        let alpha_y = DVec2::new(f64::from(base.alpha_x()), f64::from(base.alpha_y()));
        if !(alpha_y.is_finite() && alpha_y.min_element() > 0.0) {
            return Err(Error::InvalidParameter {
                name: "base roughness",
                value: alpha_y.min_element() as f32,
                expected: "finite and > 0",
            });
        }
        let gaussian = Gaussian::new(covariance);
        let variance = DVec2::new(gaussian.cov[0], gaussian.cov[1]);
        // the Beckmann-equivalent roughness of the sum, per axis: the table's scales
        let scale = (alpha_y * alpha_y + 2.0 * variance).map(f64::sqrt);
        let density = |h: DVec2| base_density(&base, h);
        let grid = match displacement {
            Displacement::Histogram(hist) => {
                let bins: Vec<(DVec2, f64)> = hist.bins().iter().map(|&(c, m)| (c - mean, m)).collect();
                let mixture = |x: f64, y: f64| {
                    let h = DVec2::new(x, y);
                    bins.iter().map(|&(c, m)| m * density(h - c)).sum::<f64>()
                };
                GridSlope::from_fn(scale.x as f32, scale.y as f32, half_cells, mixture)?
            }
            Displacement::Moments(_) => {
                let conv = GaussianConvolution::new(&gaussian, alpha_y, &density);
                GridSlope::from_fn(scale.x as f32, scale.y as f32, half_cells, |x, y| {
                    conv.p22(DVec2::new(x, y), &density)
                })?
            }
        };
        Ok(Self { grid, mean_slope })
    }

    /// The centred convolution (the displacement less its mean slope, convolved with the
    /// base) as a data-driven slope: `&GridSlope` implements
    /// [`MicrosurfaceSlope`] for every model of the crate.
    #[must_use]
    pub fn grid(&self) -> &GridSlope {
        &self.grid
    }

    /// The displacement's mean slope (x̃n, ỹn).
    #[must_use]
    pub fn mean_slope(&self) -> Vec2 {
        self.mean_slope
    }

    /// The convolution sheared to the mean slope: the noncentral slope distribution of the
    /// displaced surface (Dupuy 2015, eq. 3.2 with P_std = P_Z).
    #[must_use]
    pub fn slope(&self) -> Noncentral<&GridSlope> {
        Noncentral::new(&self.grid, self.mean_slope)
            .expect("a finite mean slope (checked by the constructor)")
    }

    /// The single-scattering BSDF of [`Self::slope`] with `material`, for renderers.
    ///
    /// # Errors
    /// Never for a constructed value (the mean slope was checked); the `Result` is
    /// [`NoncentralBsdf::new`]'s.
    pub fn bsdf<M: NoncentralMaterial>(&self, material: M) -> Result<NoncentralBsdf<&GridSlope, M>, Error> {
        NoncentralBsdf::new(self.slope(), material)
    }
}

/// The base's slope density P_Y(x̃, ỹ) = D(m)·cos⁴θm, m = (−x̃, −ỹ, 1)/‖·‖, in f64.
#[inline]
fn base_density<S: MicrosurfaceSlope>(base: &S, h: DVec2) -> f64 {
    let v = DVec3::new(-h.x, -h.y, 1.0);
    let len_sq = v.length_squared();
    if !len_sq.is_finite() {
        return 0.0;
    }
    base.d64_unchecked(v / len_sq.sqrt()) / (len_sq * len_sq)
}

/// A centred Gaussian N(0, Σ) by its principal axes (negative eigenvalues of a rounded
/// covariance taken as 0).
struct Gaussian {
    /// [Σxx, Σyy, Σxy] after the eigenvalues' clamp.
    cov: [f64; 3],
    /// Standard deviations along the principal axes e₁, e₂.
    sigma: DVec2,
    /// The unit principal axes.
    axes: [DVec2; 2],
}

impl Gaussian {
    fn new([xx, yy, xy]: [f64; 3]) -> Self {
        let (half_sum, half_diff) = (0.5 * (xx + yy), 0.5 * (xx - yy));
        let radius = half_diff.hypot(xy);
        let (l1, l2) = ((half_sum + radius).max(0.0), (half_sum - radius).max(0.0));
        let phi = 0.5 * xy.atan2(half_diff);
        let e1 = DVec2::new(phi.cos(), phi.sin());
        let e2 = e1.perp();
        let cov = [
            l1 * e1.x * e1.x + l2 * e2.x * e2.x,
            l1 * e1.y * e1.y + l2 * e2.y * e2.y,
            l1 * e1.x * e1.y + l2 * e2.x * e2.y,
        ];
        Self { cov, sigma: DVec2::new(l1.sqrt(), l2.sqrt()), axes: [e1, e2] }
    }

    /// The density at x (both standard deviations > 0).
    fn density(&self, x: DVec2) -> f64 {
        let (u, v) = (x.dot(self.axes[0]) / self.sigma.x, x.dot(self.axes[1]) / self.sigma.y);
        (-0.5 * (u * u + v * v)).exp() / (core::f64::consts::TAU * self.sigma.x * self.sigma.y)
    }

    /// A product rule of the Gaussian along its axes: along an axis whose deviation is at least
    /// `spacing`, the midpoint rule of step `spacing`/2 over ±`GAUSSIAN_BOX` deviations
    /// (weights normalized), along a narrower one 3-point Gauss–Hermite (exact to degree 5);
    /// `hermite5` for the 5-point rule on both axes.
    fn rule(&self, spacing: f64, hermite5: bool) -> Vec<(DVec2, f64)> {
        let axis = |sigma: f64| -> Vec<(f64, f64)> {
            if hermite5 {
                return HERMITE5.iter().map(|&(t, w)| (t * sigma, w)).collect();
            }
            if sigma < spacing {
                let t = 3f64.sqrt() * sigma;
                return vec![(-t, 1.0 / 6.0), (0.0, 2.0 / 3.0), (t, 1.0 / 6.0)];
            }
            let step = 0.5 * spacing;
            let k = (GAUSSIAN_BOX * sigma / step).ceil() as i64;
            let mut nodes: Vec<(f64, f64)> = (-k..=k)
                .map(|i| {
                    let t = i as f64 * step;
                    (t, (-0.5 * (t / sigma) * (t / sigma)).exp())
                })
                .collect();
            let total: f64 = nodes.iter().map(|n| n.1).sum();
            nodes.iter_mut().for_each(|n| n.1 /= total);
            nodes
        };
        let (a, b) = (axis(self.sigma.x), axis(self.sigma.y));
        let mut points = Vec::with_capacity(a.len() * b.len());
        for &(s, ws) in &a {
            for &(t, wt) in &b {
                points.push((s * self.axes[0] + t * self.axes[1], ws * wt));
            }
        }
        points
    }
}

/// The numerical convolution N(0, Σ) ∗ P_Y of [`DownsampledSlope`]: the core on a uniform grid
/// by the FFT, the base's tail by a Gauss–Hermite rule of the Gaussian.
struct GaussianConvolution {
    /// The spacing δ.
    spacing: f64,
    /// The result's nodes k ∈ [−k_max, k_max] per axis (density values, row-major).
    k_max: [usize; 2],
    core: Vec<f64>,
    /// The half-widths of the base's core, beyond which its density is the tail's.
    core_half: DVec2,
    /// The Gaussian's 5 × 5 Gauss–Hermite points (offset, weight).
    tail_rule: Vec<(DVec2, f64)>,
}

impl GaussianConvolution {
    fn new(gaussian: &Gaussian, alpha_y: DVec2, density: &impl Fn(DVec2) -> f64) -> Self {
        let sigma_x = DVec2::new(gaussian.cov[0].sqrt(), gaussian.cov[1].sqrt());
        // the smallest Beckmann-equivalent roughness of the result, over all directions
        let alpha_min = (alpha_y.min_element().powi(2) + 2.0 * gaussian.sigma.y * gaussian.sigma.y).sqrt();
        let x_half = GAUSSIAN_BOX * sigma_x;
        let y_half = (BASE_BOX * alpha_y).max(BASE_BOX_IN_SIGMAS * sigma_x);
        let mut spacing = alpha_min / NODES_PER_ALPHA;
        // the transform holds 2(kx + ky) + 1 nodes per axis
        let needed = |spacing: f64| {
            let n = 2.0 * ((x_half + y_half) / spacing).ceil() + 3.0;
            n.max_element()
        };
        let too_many = needed(spacing) / MAX_TRANSFORM as f64;
        if too_many > 1.0 {
            spacing *= too_many * 1.01;
        }
        // at least one node on either side of 0 (a flat displacement is a Dirac at 0)
        let count = |half: f64| ((half / spacing).ceil() as usize).max(1);
        let (kx, ky) = ([count(x_half.x), count(x_half.y)], [count(y_half.x), count(y_half.y)]);

        // the Gaussian's masses on its nodes
        let mut x_grid = Grid2 { nx: 2 * kx[0] + 1, ny: 2 * kx[1] + 1, values: vec![] };
        if gaussian.sigma.y >= spacing {
            x_grid.values = nodes(kx, spacing, |p| gaussian.density(p) * spacing * spacing);
            let total: f64 = x_grid.values.iter().sum();
            x_grid.values.iter_mut().for_each(|v| *v /= total);
        } else {
            x_grid.values = vec![0.0; x_grid.nx * x_grid.ny];
            splat(&mut x_grid, kx, spacing, gaussian.rule(spacing, false));
        }

        // the base's core masses on its nodes
        let mut y_grid = Grid2 { nx: 2 * ky[0] + 1, ny: 2 * ky[1] + 1, values: vec![] };
        let core_half;
        if alpha_y.min_element() >= BASE_NODES_PER_ALPHA * spacing {
            y_grid.values = nodes(ky, spacing, |p| density(p) * spacing * spacing);
            core_half = (DVec2::new(ky[0] as f64, ky[1] as f64) + 0.5) * spacing;
        } else {
            y_grid.values = vec![0.0; y_grid.nx * y_grid.ny];
            core_half = DVec2::new(ky[0] as f64, ky[1] as f64) * spacing;
            splat(&mut y_grid, ky, spacing, base_rule(alpha_y, core_half, density));
        }

        let z = convolve(&x_grid, &y_grid);
        let inv_area = 1.0 / (spacing * spacing);
        let core = z.values.iter().map(|v| (v * inv_area).max(0.0)).collect();
        Self {
            spacing,
            k_max: [kx[0] + ky[0], kx[1] + ky[1]],
            core,
            core_half,
            tail_rule: gaussian.rule(spacing, true),
        }
    }

    /// P_Z at h: the core read bilinearly plus the tail's convolution.
    fn p22(&self, h: DVec2, density: &impl Fn(DVec2) -> f64) -> f64 {
        let tail: f64 = self
            .tail_rule
            .iter()
            .map(|&(x, w)| {
                let y = h - x;
                if y.x.abs() <= self.core_half.x && y.y.abs() <= self.core_half.y {
                    0.0
                } else {
                    w * density(y)
                }
            })
            .sum();
        self.core_at(h) + tail
    }

    /// The core density at h, bilinear between the nodes, 0 beyond them.
    fn core_at(&self, h: DVec2) -> f64 {
        let (nx, ny) = (2 * self.k_max[0] + 1, 2 * self.k_max[1] + 1);
        let p = h / self.spacing + DVec2::new(self.k_max[0] as f64, self.k_max[1] as f64);
        if !(p.x >= 0.0 && p.y >= 0.0 && p.x < (nx - 1) as f64 && p.y < (ny - 1) as f64) {
            return 0.0;
        }
        let (i, j) = (p.x as usize, p.y as usize);
        let (fx, fy) = (p.x - i as f64, p.y - j as f64);
        let at = |i: usize, j: usize| self.core[j * nx + i];
        (1.0 - fy) * ((1.0 - fx) * at(i, j) + fx * at(i + 1, j))
            + fy * ((1.0 - fx) * at(i, j + 1) + fx * at(i + 1, j + 1))
    }
}

/// `f` at the nodes (i, j)·δ, i ∈ [−k₀, k₀], j ∈ [−k₁, k₁], row-major.
fn nodes(k: [usize; 2], spacing: f64, f: impl Fn(DVec2) -> f64) -> Vec<f64> {
    let mut values = Vec::with_capacity((2 * k[0] + 1) * (2 * k[1] + 1));
    for j in -(k[1] as i64)..=k[1] as i64 {
        for i in -(k[0] as i64)..=k[0] as i64 {
            values.push(f(DVec2::new(i as f64, j as f64) * spacing));
        }
    }
    values
}

/// Adds the weighted points to the grid of nodes (i, j)·δ (|i| ≤ k₀, |j| ≤ k₁), each spread
/// bilinearly onto the four nodes around it (mass and mean kept); points beyond the last nodes
/// are dropped (the callers keep them inside).
fn splat(grid: &mut Grid2, k: [usize; 2], spacing: f64, points: Vec<(DVec2, f64)>) {
    let offset = DVec2::new(k[0] as f64, k[1] as f64);
    for (x, w) in points {
        let p = x / spacing + offset;
        if !(p.x >= 0.0 && p.y >= 0.0 && p.x <= (grid.nx - 1) as f64 && p.y <= (grid.ny - 1) as f64) {
            continue;
        }
        let (i, j) = ((p.x as usize).min(grid.nx - 2), (p.y as usize).min(grid.ny - 2));
        let (fx, fy) = (p.x - i as f64, p.y - j as f64);
        let nx = grid.nx;
        grid.values[j * nx + i] += w * (1.0 - fx) * (1.0 - fy);
        grid.values[j * nx + i + 1] += w * fx * (1.0 - fy);
        grid.values[(j + 1) * nx + i] += w * (1.0 - fx) * fy;
        grid.values[(j + 1) * nx + i + 1] += w * fx * fy;
    }
}

/// A quadrature of the base's density over its core |ỹ| ≤ `half` (per axis): 2 × 2
/// Gauss–Legendre points on the cells of boundaries ±α tan θ′ₖ, θ′ₖ = (π/2)(1 − (1 − k/33)²)
/// (the stretched grid of [`GridSlope`], 32 cells per half axis), clipped to the core.
fn base_rule(alpha: DVec2, half: DVec2, density: &impl Fn(DVec2) -> f64) -> Vec<(DVec2, f64)> {
    const HALF_CELLS: usize = 32;
    const GL2: [f64; 2] = [-0.577_350_269_189_625_8, 0.577_350_269_189_625_8];
    let edges = |s: f64, limit: f64| -> Vec<f64> {
        let half: Vec<f64> = (0..=HALF_CELLS)
            .map(|k| {
                let t = 1.0 - k as f64 / (HALF_CELLS + 1) as f64;
                (s * (core::f64::consts::FRAC_PI_2 * (1.0 - t * t)).tan()).min(limit)
            })
            .collect();
        let mut all: Vec<f64> = half.iter().rev().map(|v| -v).collect();
        all.extend(&half[1..]);
        all.dedup();
        all
    };
    let (xs, ys) = (edges(alpha.x, half.x), edges(alpha.y, half.y));
    let mut points = Vec::with_capacity(4 * xs.len() * ys.len());
    for wy in ys.windows(2) {
        for wx in xs.windows(2) {
            let (cx, hx, cy, hy) =
                (0.5 * (wx[0] + wx[1]), 0.5 * (wx[1] - wx[0]), 0.5 * (wy[0] + wy[1]), 0.5 * (wy[1] - wy[0]));
            for gy in GL2 {
                for gx in GL2 {
                    let p = DVec2::new(cx + gx * hx, cy + gy * hy);
                    points.push((p, density(p) * hx * hy));
                }
            }
        }
    }
    points
}
