//! A tabulated isotropic slope distribution (Dupuy 2015, thesis §4.2: data-driven
//! microsurfaces): a GGX lobe modulated ring by ring, with an optional r⁻⁴ tail, exact
//! visible-normal sampling on the whole sphere, and D, Λ and the sampler driven by tables
//! built at construction.

use super::rings::{RingGrid, RingLookup, back_area};
use super::vndf::{Visible, VisibleSampler};
use crate::error::Error;
use crate::slope::{Ggx, MicrosurfaceSlope, sample_spherical_cap, sample_visible_hemisphere};
use crate::vector::ensure_visible;
use core::f64::consts::{FRAC_PI_2, PI};
use glam::{DVec3, Vec2, Vec3};

/// Largest number of rings a table may have.
pub const MAX_RINGS: usize = 4096;

/// Gauss–Legendre nodes and weights on [−1, 1], 8 points (exact for polynomials of degree 15),
/// used for the ring masses of [`TabulatedSlope::from_radial_fn`].
const GL8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
];

/// Nodes of the back-face factor in all (at least two per group of rings; linear in c between
/// them).
const BACKFACE_NODES: usize = 2048;
/// Groups of rings of the back-face factor at most (larger tables group several rings).
const MAX_GROUPS: usize = 256;
/// The outermost rings whose back-face area is summed exactly rather than interpolated: 16, or
/// a quarter of the rings if fewer (a coarse table interpolates its inner rings too).
const EXACT_OUTER_RINGS: usize = 16;

/// The model of a [`TabulatedSlope`] beyond its last ring, R > R_N.
///
/// # Examples
/// ```
/// use microsurface::Ggx;
/// use microsurface::slope::MicrosurfaceSlope;
/// use microsurface::tabulated::{TabulatedSlope, Tail};
/// use microsurface::glam::Vec3;
/// let ggx = Ggx::isotropic(0.5)?;
/// let table = TabulatedSlope::from_slope(&ggx, 0.5, 256)?.with_tail(Tail::Continued);
/// let w = Vec3::new(0.6, 0.0, 0.8);
/// assert!(((&table).lambda(w) / ggx.lambda(w) - 1.0).abs() < 1e-4);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tail {
    /// No slopes beyond R_N: all the mass is in the rings (the constructors' default).
    #[default]
    Truncated,
    /// The last ring's factor continued to every slope: P²² = f_{N−1}·P_GGX(s)(r) for
    /// r ≥ R_N, an r⁻⁴ tail of mass f_{N−1} cos²θ′_N (θ′_N the last ring's stretched angle),
    /// the rings rescaled so that the whole integrates to 1. Exact for GGX of roughness s; for
    /// other data it assumes that beyond the table the density keeps the ratio to GGX(s) it
    /// has in the last ring: a lighter tail (Beckmann) has a last factor of about 0 and gets
    /// about no tail, a heavier one is cut to r⁻⁴.
    Continued,
}

/// An isotropic slope distribution given by a radial table: a GGX lobe of roughness s (the
/// table's scale) multiplied by a factor fₖ ≥ 0 constant on each ring of slope radius,
/// P²²(r) = fₖ·s²/(π(s² + r²)²) for r in the ring [Rₖ, Rₖ₊₁), k = 0 … N − 1, and beyond R_N as
/// the [`Tail`] says.
///
/// # The table
/// The ring boundaries are Rₖ = s·tan θ′ₖ at the "stretched" normal angles
/// θ′ₖ = (π/2)(1 − (1 − k/(N+1))²): steps of the angle atan(r/s) that are π/(N+1) at the centre
/// and shrink towards the horizon, up to R_N ≈ 0.64 (N+1)² s. Stretched by 1/s, GGX(s) becomes
/// the unit GGX lobe, whose density of normals is constant, D′ = 1/π: the table is the
/// piecewise-constant density of normals D′ = fₖ/π on the zones θ′ₖ ≤ θ′ < θ′ₖ₊₁ of the
/// stretched hemisphere, and D(ωm) = fₖ·D_GGX(s)(ωm). The factors are normalized so that
/// Σₖ fₖ (cos²θ′ₖ − cos²θ′ₖ₊₁) = 1 (the zones' masses under GGX(s)), i.e. ∫D cos θm dωm = 1.
/// A GGX of roughness s is reproduced exactly (every fₖ = 1, with [`Tail::Continued`]); any
/// other profile is approximated ring by ring with its ring masses kept: within a ring the
/// density follows the r⁻⁴ decay of GGX rather than a constant, which in the wide outer rings
/// (radius ratios up to 4) is what keeps the first moment of a heavy tail, hence Λ, right.
/// The relative error of D for a smooth profile is of the order of ½ δθ′·|d ln(P/P_GGX(s))/dθ′|
/// at the ring edges (δθ′ ≤ π/(N+1) the ring's angular width).
///
/// # Λ and the projected area
/// The back-face area B(ω) = ∫⟨ω, ωm⟩₋ D dωm of a zone has a closed form (the rings'
/// module: with c = cot θ′ of the stretched direction, the unit lobe's
/// S(R′, c) = k·atan(V/k) − c·atan(V/c) − (V − c·atan(V/c))/(1 + R′²), V = √(R′² − c²),
/// k = √(1 + c²), rearranged or summed as a series where that cancels), so the projected area
/// is an exact O(N) sum ([`TabulatedSlope::projected_area_exact`]). The trait's `lambda` and
/// `projected_area` multiply the closed-form back-face area of GGX(s),
/// s²h²/(2(√(z² + s²h²) + |z|)) (h = |ω_xy|, z = ω.z), by a factor ρ = B/B_GGX(s) tabulated at
/// construction (2048 nodes, at least two per group of rings, linear in c = |z|/h between them,
/// found by the constant-time ring lookup), except when the visibility line cuts only the 16
/// outermost rings (a quarter of the rings if fewer; near the poles), where the sum is exact.
/// ρ is a weighted mean of the factors fₖ of the rings beyond the visibility line: exactly 1
/// for GGX(s), smooth otherwise (interpolation error 1.6e-7 relative for a mixture of two GGX
/// lobes on 64 or 256 rings). Λ = B/cos θ above the horizon and −1 − B/|cos θ| below, so
/// Λ(−ω) = −1 − Λ(ω) holds exactly. A GGX of roughness α tabulated on 256 rings at s = α with
/// [`Tail::Continued`] has Λ within 2.3e-8 (relative) of the analytic one over the whole sphere,
/// 1.2e-5 at s = 0.7 α; without the tail its Λ misses the tail's first moment, 4e-4 at θ = 0.3
/// and more towards the poles (`tests/tabulated/tail.rs`).
///
/// # Sampling
/// Visible normals are sampled **exactly** in the stretched hemisphere by a proposal tabulated
/// at construction and corrected by rejection with the exact density ratio (the
/// `vndf` module): majorants of ⟨ω, ωm⟩ per cell (zone × azimuth bin) tabulated at
/// about 60 incident directions, interpolated between the two that bracket ω by the convexity
/// of ⟨·, ωm⟩₊, picked in constant time (guide tables); from below, the cells above the
/// visible region excluded and its top cell given its own proposal. 0.78 to 0.98 of the
/// proposals are accepted for a tabulated GGX; the first proposal inverts the two uniforms, the
/// acceptance test and any further proposal use uniforms hashed from their bits. Directions
/// that see only the tail (within (π/2)/(N+1)² of the nadir, stretched) are sampled by GGX(s)'s
/// spherical cap, exactly.
///
/// # Cost
/// Construction is O(N²): the back-face factor's 2048 nodes, each an exact sum over the rings
/// beyond it, and the sampler's tables (about 60 directions × the cells they see × 16 bins);
/// 45 ms at N = 256, 0.7 s at N = 4096 (measured on one shared core). [`TabulatedSlope::heap_bytes`]
/// reports the memory: 148 KB at N = 256 (176 KB with the tail), 1.9 MB at N = 4096; the struct
/// itself is 536 bytes.
/// `d` is a ring lookup (float bits of r² index a table of ring starts, then one or two exact
/// boundary comparisons) and a few multiplications; `lambda` adds the closed form of GGX(s)
/// and a linear interpolation; `sample_d_wi` is one proposal in general (a node pair, a guide
/// table, 16 bin majorants, a square root and a hash).
///
/// The crate's [`MicrosurfaceSlope`] trait requires `Copy`; it is implemented for
/// `&TabulatedSlope`, so that the tables live once and the walks, estimators and BSDFs share
/// them by reference.
///
/// Reference: Dupuy 2015, *Photorealistic Surface Rendering with Microfacet Theory*, §4.2–4.3
/// (the tabulated slope distribution and its Smith Λ by quadrature).
///
/// # Examples
/// ```
/// use microsurface::Ggx;
/// use microsurface::slope::MicrosurfaceSlope;
/// use microsurface::tabulated::TabulatedSlope;
/// use microsurface::glam::Vec3;
/// // a mixture of two GGX lobes, tabulated on 128 rings at scale 0.3
/// let p = |a: f64, r: f64| a * a / (std::f64::consts::PI * (a * a + r * r).powi(2));
/// let table = TabulatedSlope::from_radial_fn(0.3, 128, |r| 0.5 * p(0.15, r) + 0.5 * p(0.7, r))?;
/// let wi = Vec3::new(0.6, 0.0, 0.8);
/// let wm = (&table).sample_d_wi(wi, 0.3, 0.7);
/// assert!(wm.z > 0.0 && wi.dot(wm) > 0.0 && (&table).d_wi(wi, wm) > 0.0);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Clone)]
pub struct TabulatedSlope {
    /// The ring grid.
    grid: RingGrid,
    /// The normalized ring factors fₖ, k = 0 … N (the last one the tail's, 0 if truncated).
    factors: Vec<f64>,
    /// fₖ s²/π, k = 0 … N: D = that·(|m|²/(s²z² + h²))².
    d_coef: Vec<f64>,
    /// The ring averages of P²² (N of them).
    ring_values: Vec<f64>,
    /// The ring of a squared slope radius.
    lookup: RingLookup,
    /// The back-face factor ρ = B/B_GGX(s).
    backface: BackfaceTable,
    /// The visible-normal sampler's tables.
    sampler: VisibleSampler,
    /// The GGX-equivalent roughness 2 B(horizon).
    alpha: f32,
    /// The mass of the input before normalization (≠ 1 when the input was truncated at R_N).
    input_mass: f64,
    /// The model beyond R_N.
    tail: Tail,
    /// GGX of roughness s (whose visible normals the directions that see only the tail see).
    lobe: Ggx,
}

impl core::fmt::Debug for TabulatedSlope {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("TabulatedSlope")
            .field("rings", &self.grid.rings)
            .field("scale", &self.grid.scale)
            .field("alpha", &self.alpha)
            .field("tail", &self.tail)
            .field("input_mass", &self.input_mass)
            .finish_non_exhaustive()
    }
}

/// The back-face factor ρ = B/B_GGX(s) at nodes of c² (see [`TabulatedSlope`]).
#[derive(Debug, Clone)]
struct BackfaceTable {
    /// Rings per group, and nodes per group.
    step: usize,
    sub: usize,
    /// The first ring summed exactly (a multiple of `step`; the groups cover the rings below).
    exact_from: usize,
    /// ρ at c = R_{g·step} + (i/sub)(R_{(g+1)step} − R_{g·step}), and at R_{exact_from}.
    nodes: Vec<f64>,
}

impl TabulatedSlope {
    /// A table from ring values of P²²: `values[k]` is the mean of P²² over the ring
    /// [Rₖ, Rₖ₊₁) of the grid of N = `values.len()` rings at scale `scale` (see the type's
    /// documentation); the table keeps each ring's mass π(Rₖ₊₁² − Rₖ²)·`values[k]`, normalized
    /// to unit total, and its factor fₖ is that mass over the ring's mass under GGX(`scale`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `scale` is not finite and > 0, if `values` is empty or
    /// longer than [`MAX_RINGS`] (`name = "values.len()"`), if a value is NaN, infinite or
    /// negative (`name = "values[k]"`, the offending value), or if the total mass is zero or not
    /// finite (`name = "total mass"`).
    pub fn from_p22(scale: f32, values: &[f32]) -> Result<Self, Error> {
        let s = f64::from(Error::check_positive("scale", scale)?);
        check_ring_count(values.len())?;
        check_values(values.iter().map(|&v| f64::from(v)))?;
        let grid = RingGrid::new(s, values.len());
        let masses = values
            .iter()
            .enumerate()
            .map(|(k, &v)| f64::from(v) * PI * (grid.radii_sq[k + 1] - grid.radii_sq[k]))
            .collect();
        Self::from_masses(grid, masses, None)
    }

    /// A table from samples of D: `values[k]` is D at the normal angle of the centre of ring k,
    /// θₖ = atan(`scale`·tan θ′ₖ₊½) ([`Self::ring_centre_angle`]); ring k's factor is
    /// `values[k]`/D_GGX(s)(θₖ), so that the table passes through the samples, then the factors
    /// are normalized.
    ///
    /// # Errors
    /// As [`Self::from_p22`].
    pub fn from_d(scale: f32, values: &[f32]) -> Result<Self, Error> {
        let s = f64::from(Error::check_positive("scale", scale)?);
        check_ring_count(values.len())?;
        check_values(values.iter().map(|&v| f64::from(v)))?;
        let n = values.len();
        let grid = RingGrid::new(s, n);
        let masses = values
            .iter()
            .enumerate()
            .map(|(k, &d)| {
                // D_GGX(s)(θₖ) = cos⁴θ′/(π s² cos⁴θₖ) with tan θₖ = s tan θ′
                let t = grid_angle(k as f64 + 0.5, n).tan();
                let (cos2_prime, cos2) = (1.0 / (1.0 + t * t), 1.0 / (1.0 + s * s * t * t));
                let factor = f64::from(d) * PI * s * s * cos2 * cos2 / (cos2_prime * cos2_prime);
                factor * grid.ggx_mass[k]
            })
            .collect();
        Self::from_masses(grid, masses, None)
    }

    /// A table of `rings` rings of the radial slope density `p22(r)` (r ≥ 0 the slope radius),
    /// by its exact ring masses ∫_{Rₖ}^{Rₖ₊₁} p22(r) 2πr dr (8-point Gauss–Legendre in the
    /// stretched angle per ring), normalized. The mass beyond R_N is dropped
    /// ([`Tail::Truncated`]); [`Self::input_mass`] reports the mass that was tabulated.
    ///
    /// # Errors
    /// As [`Self::from_p22`] (`rings` is `values.len()`); a NaN, infinite or negative value
    /// of `p22` at a quadrature node is reported as `values[k]`.
    pub fn from_radial_fn(scale: f32, rings: usize, p22: impl Fn(f64) -> f64) -> Result<Self, Error> {
        let s = f64::from(Error::check_positive("scale", scale)?);
        check_ring_count(rings)?;
        let mut masses = Vec::with_capacity(rings);
        let mut input_mass = 0.0;
        for k in 0..rings {
            let (t0, t1) = (grid_angle(k as f64, rings), grid_angle((k + 1) as f64, rings));
            let (mid, half) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
            let mut mass = 0.0;
            for (x, w) in GL8 {
                let t = mid + half * x;
                let r = s * t.tan();
                let v = p22(r);
                if !(v.is_finite() && v >= 0.0) {
                    return Err(Error::InvalidParameter {
                        name: "values[k]",
                        value: v as f32,
                        expected: "finite and >= 0",
                    });
                }
                // dr = s sec²t dt
                let sec2 = 1.0 + t.tan() * t.tan();
                mass += w * half * v * 2.0 * PI * r * s * sec2;
            }
            input_mass += mass;
            masses.push(mass);
        }
        Self::from_masses(RingGrid::new(s, rings), masses, Some(input_mass))
    }

    /// A table of an isotropic analytic slope distribution ([`crate::Ggx`], [`crate::Beckmann`],
    /// …) by [`Self::from_radial_fn`] of its `p22(r, 0)`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `slope` is anisotropic (`name = "alpha_y"`: αx ≠ αy, or a
    /// projected roughness on the diagonal that differs from αx, as for a correlated slope), else as
    /// [`Self::from_radial_fn`].
    pub fn from_slope<S: MicrosurfaceSlope>(slope: &S, scale: f32, rings: usize) -> Result<Self, Error> {
        if !is_isotropic(slope) {
            return Err(Error::InvalidParameter {
                name: "alpha_y",
                value: slope.alpha_y(),
                expected: "equal to alpha_x (the table is isotropic)",
            });
        }
        Self::from_radial_fn(scale, rings, |r| f64::from(slope.p22(r as f32, 0.0)))
    }

    /// A table of ring factors fₖ (the extraction's eigenvector), normalized.
    pub(super) fn from_factors(scale: f32, factors: Vec<f64>) -> Result<Self, Error> {
        let s = f64::from(Error::check_positive("scale", scale)?);
        check_ring_count(factors.len())?;
        check_values(factors.iter().copied())?;
        let grid = RingGrid::new(s, factors.len());
        let masses = factors.iter().zip(&grid.ggx_mass).map(|(f, m)| f * m).collect();
        Self::from_masses(grid, masses, None)
    }

    /// The table of the ring masses `masses` (validated ≥ 0), normalized, truncated.
    fn from_masses(grid: RingGrid, masses: Vec<f64>, input_mass: Option<f64>) -> Result<Self, Error> {
        let total: f64 = masses.iter().sum();
        if !(total.is_finite() && total > 0.0) {
            return Err(Error::InvalidParameter {
                name: "total mass",
                value: total as f32,
                expected: "finite and > 0 (a table with some mass)",
            });
        }
        let lobe = Ggx::isotropic(grid.scale as f32)?;
        let mut factors: Vec<f64> = masses.iter().zip(&grid.ggx_mass).map(|(m, g)| m / total / g).collect();
        factors.push(0.0);
        Ok(Self::build(grid, factors, Tail::Truncated, input_mass.unwrap_or(total), lobe))
    }

    /// The same rings with the model `tail` beyond R_N (the factors rescaled so that the whole
    /// integrates to 1); the derived tables are rebuilt (the cost of a construction).
    #[must_use]
    pub fn with_tail(self, tail: Tail) -> Self {
        let n = self.grid.rings;
        let mut factors = self.factors;
        factors[n] = match tail {
            Tail::Truncated => 0.0,
            Tail::Continued => factors[n - 1],
        };
        let total: f64 = factors.iter().zip(&self.grid.ggx_mass).map(|(f, m)| f * m).sum();
        for f in &mut factors {
            *f /= total;
        }
        Self::build(self.grid, factors, tail, self.input_mass, self.lobe)
    }

    /// The derived tables of normalized factors.
    fn build(grid: RingGrid, factors: Vec<f64>, tail: Tail, input_mass: f64, lobe: Ggx) -> Self {
        let n = grid.rings;
        let s = grid.scale;
        let d_coef = factors.iter().map(|f| f * s * s / PI).collect();
        let ring_values = (0..n)
            .map(|k| factors[k] * grid.ggx_mass[k] / (PI * (grid.radii_sq[k + 1] - grid.radii_sq[k])))
            .collect();
        let lookup = RingLookup::new(&grid.radii_sq);
        let sampler = VisibleSampler::new(&grid, &factors);
        let step = n.div_ceil(MAX_GROUPS).max(1);
        let exact_from = n.saturating_sub(EXACT_OUTER_RINGS.min(n.div_ceil(4))) / step * step;
        let sub = (BACKFACE_NODES / (exact_from / step).max(1)).max(2);
        let mut table = Self {
            grid,
            factors,
            d_coef,
            ring_values,
            lookup,
            backface: BackfaceTable { step, sub, exact_from, nodes: Vec::new() },
            sampler,
            alpha: 0.0,
            input_mass,
            tail,
            lobe,
        };
        let mut nodes = Vec::with_capacity(exact_from / step * sub + 1);
        for g in 0..exact_from / step {
            let (lo, hi) = (table.grid.radii[g * step], table.grid.radii[(g + 1) * step]);
            for i in 0..sub {
                nodes.push(table.back_factor_exact(lo + (hi - lo) * i as f64 / sub as f64));
            }
        }
        if exact_from > 0 {
            nodes.push(table.back_factor_exact(table.grid.radii[exact_from]));
        }
        table.backface.nodes = nodes;
        table.alpha = (2.0 * table.backface_area(1.0, 0.0)) as f32;
        table
    }

    /// The number of rings N.
    #[must_use]
    pub fn rings(&self) -> usize {
        self.grid.rings
    }

    /// The slope scale s of the ring grid (the roughness of the GGX lobe the rings modulate).
    #[must_use]
    pub fn scale(&self) -> f32 {
        self.grid.scale as f32
    }

    /// The ring boundaries R₀ = 0 < … < R_N.
    #[must_use]
    pub fn radii(&self) -> &[f64] {
        &self.grid.radii
    }

    /// The normalized ring averages of P²², (mass of ring k)/(π(Rₖ₊₁² − Rₖ²)).
    #[must_use]
    pub fn ring_values(&self) -> &[f64] {
        &self.ring_values
    }

    /// The normalized ring factors fₖ (P²² = fₖ·P_GGX(s) on ring k), k = 0 … N − 1, then the
    /// tail's (0 for [`Tail::Truncated`]).
    #[must_use]
    pub fn ring_factors(&self) -> &[f64] {
        &self.factors
    }

    /// The model beyond the last ring.
    #[must_use]
    pub fn tail(&self) -> Tail {
        self.tail
    }

    /// The mass ∫P²² of the input before normalization (for [`Self::from_radial_fn`], the mass
    /// inside R_N: 1 minus the truncated tail for a normalized input).
    #[must_use]
    pub fn input_mass(&self) -> f64 {
        self.input_mass
    }

    /// The heap memory of the table's arrays, in bytes (the struct itself is
    /// `size_of::<TabulatedSlope>()`).
    #[must_use]
    pub fn heap_bytes(&self) -> usize {
        let n = self.grid.rings;
        // grid: radii, radii², stretched (N + 1 each), cos, sin (N + 2), masses (N + 1)
        let grid = (6 * n + 8) * 8;
        grid + (self.factors.len() + self.d_coef.len() + self.ring_values.len() + self.backface.nodes.len())
            * 8
            + self.lookup.heap_bytes()
            + self.sampler.heap_bytes()
    }

    /// The GGX-equivalent roughness α = 2·projected_area(horizon) = E|x̃|: the GGX α with the
    /// same projected area at grazing incidence. Reported by `alpha_x`/`alpha_y`.
    #[must_use]
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// The Beckmann roughness with the same second moment, α = √E[x̃² + ỹ²] (E\[r²\] = α² for
    /// Beckmann), computed exactly from the rings: ring k holds
    /// fₖ s²(2 ln(cos θ′ₖ/cos θ′ₖ₊₁) − (cos²θ′ₖ − cos²θ′ₖ₊₁)) of E\[r²\] (Dupuy 2015,
    /// Listing 4.4, which converts a radial table to Beckmann roughness by its second moment).
    /// Infinite with a [`Tail::Continued`] (the second moment of an r⁻⁴ tail diverges).
    #[must_use]
    pub fn beckmann_alpha(&self) -> f32 {
        let (g, n) = (&self.grid, self.grid.rings);
        if self.factors[n] > 0.0 {
            return f32::INFINITY;
        }
        let m2: f64 = (0..n)
            .map(|k| {
                self.factors[k] * g.scale * g.scale * (2.0 * (g.cos[k] / g.cos[k + 1]).ln() - g.ggx_mass[k])
            })
            .sum();
        m2.sqrt() as f32
    }

    /// The normal angle θₖ = atan(s·tan θ′) of the centre of ring k (θ′ the stretched angle at
    /// k + ½): where [`crate::tabulated::extract_isotropic`] collocates the backscattering samples.
    #[must_use]
    pub fn ring_centre_angle(scale: f32, rings: usize, k: usize) -> f64 {
        (f64::from(scale) * grid_angle(k as f64 + 0.5, rings).tan()).atan()
    }

    /// The radial density P²² at slope radius `r` ≥ 0 (f64; 0 for a NaN or negative r).
    #[must_use]
    pub fn p22_radial(&self, r: f64) -> f64 {
        if r.is_nan() || r < 0.0 {
            return 0.0;
        }
        let r2 = r * r;
        let k = self.lookup.ring(r2, &self.grid.radii_sq);
        let s2 = self.grid.scale * self.grid.scale;
        self.d_coef[k] / ((s2 + r2) * (s2 + r2))
    }

    /// The exact projected area ∫⟨ω, ωm⟩₊ D(ωm) dωm of the table (O(N) closed-form sum, f64):
    /// the reference of the interpolated [`MicrosurfaceSlope::projected_area`].
    #[must_use]
    pub fn projected_area_exact(&self, w: Vec3) -> f64 {
        let w = w.as_dvec3();
        let h = (w.x * w.x + w.y * w.y).sqrt();
        let len = (h * h + w.z * w.z).sqrt();
        if len.is_nan() || len <= 0.0 {
            return 0.0;
        }
        let (h, z) = (h / len, w.z / len);
        let b = if h > 0.0 {
            let c = z.abs() / (self.grid.scale * h);
            self.grid.scale * h * self.back_sum(c) / PI
        } else {
            0.0
        };
        z.max(0.0) + b
    }

    /// Σₖ fₖ ΔSₖ(c′) over the rings beyond the visibility line c′ (stretched): π B/(s h).
    fn back_sum(&self, c: f64) -> f64 {
        let first = self.lookup.ring((self.grid.scale * c).powi(2), &self.grid.radii_sq);
        self.grid.back_sum(&self.factors, c, first)
    }

    /// The back-face factor ρ = B/B_GGX(s) at the (unstretched) visibility line c = |z|/h,
    /// summed exactly.
    fn back_factor_exact(&self, c: f64) -> f64 {
        let c = c / self.grid.scale;
        self.back_sum(c) / back_area(f64::INFINITY, c)
    }

    /// The back-face area B for a direction of horizontal length `h` ≥ 0 and height ±`z`
    /// (|z| is used): B_GGX(s) times the interpolated factor ρ (exact near the poles).
    #[inline]
    fn backface_area(&self, h: f64, z: f64) -> f64 {
        let z = z.abs();
        let sh = self.grid.scale * h;
        let ggx = sh * sh / (2.0 * ((sh * sh + z * z).sqrt() + z));
        if ggx.is_nan() || ggx <= 0.0 {
            return 0.0;
        }
        let c = z / h;
        let k = self.lookup.ring(c * c, &self.grid.radii_sq);
        let t = &self.backface;
        let rho = if k < t.exact_from {
            let g = k / t.step;
            let (lo, hi) = (self.grid.radii[g * t.step], self.grid.radii[(g + 1) * t.step]);
            let pos = ((c - lo) / (hi - lo)).clamp(0.0, 1.0) * t.sub as f64;
            let i = (pos as usize).min(t.sub - 1);
            let (a, b) = (t.nodes[g * t.sub + i], t.nodes[g * t.sub + i + 1]);
            a + (pos - i as f64) * (b - a)
        } else {
            let c = z / sh;
            self.grid.back_sum(&self.factors, c, k) / back_area(f64::INFINITY, c)
        };
        ggx * rho
    }

    /// D in f64 for a normal with squared horizontal length `h2`, height `z` and squared
    /// length `len2`: fₖ s²/π·(len2/(s²z² + h2))² (0 for z ≤ 0).
    #[inline(always)]
    fn d_of(&self, h2: f64, z: f64, len2: f64) -> f64 {
        if !(z > 0.0 && h2.is_finite()) {
            return 0.0;
        }
        let z2 = z * z;
        let k = self.lookup.ring(h2 / z2, &self.grid.radii_sq);
        let s = self.grid.scale;
        let q = len2 / (s * s * z2 + h2);
        self.d_coef[k] * q * q
    }

    /// The ring holding the visibility line c = |z|/h of a direction of horizontal length `h`
    /// and height `z` (N beyond the last ring, and for h = 0).
    #[inline(always)]
    fn visibility_ring(&self, h: f64, z: f64) -> usize {
        let c = z / h;
        self.lookup.ring(c * c, &self.grid.radii_sq)
    }

    /// An exactly sampled visible normal for a unit `wi` (f64 inside); +z if ωi sees nothing.
    fn sample_normal(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        let (x, y, z) = (f64::from(wi.x), f64::from(wi.y), f64::from(wi.z));
        let h = (x * x + y * y).sqrt();
        let s = self.grid.scale;
        // the ring of the visibility line matters from below only
        let ring = if z < 0.0 { self.visibility_ring(h, z) } else { 0 };
        let m = match self.sampler.sample(s * h, z, ring, u1, u2) {
            Visible::Normal(m) => m,
            // the directions that see only the tail see GGX(s): its exact sampler
            Visible::TailOnly => return sample_spherical_cap(&self.lobe, wi, u1, u2),
            Visible::Nothing => return Vec3::Z,
        };
        // unstretch (the slopes scale by s) and rotate to the azimuth (x, y)/h of ωi, all
        // times h (no division): h·(s R m_xy, m.z), R the rotation
        let n = if h > 0.0 {
            DVec3::new(s * (x * m.x - y * m.y), s * (y * m.x + x * m.y), h * m.z)
        } else {
            DVec3::new(s * m.x, s * m.y, m.z)
        };
        ensure_visible(wi, (n * n.length().recip()).as_vec3())
    }

    /// The fraction of visible-normal proposals accepted from the unit direction `w` (the
    /// exact visible mass over the proposal's): a measurement of the sampler's efficiency
    /// (1 where no rejection is used, near the nadir).
    #[doc(hidden)]
    #[must_use]
    pub fn sampler_acceptance(&self, w: Vec3) -> f64 {
        let w = w.as_dvec3();
        let h = (w.x * w.x + w.y * w.y).sqrt();
        match self.sampler.proposal_mass(self.grid.scale * h, w.z, self.visibility_ring(h, w.z)) {
            Some(q) if q > 0.0 => self.projected_area_exact(w.as_vec3()) / (2.0 * q),
            _ => 1.0,
        }
    }
}

/// Whether `slope` is isotropic to within 1e-6: αx = αy, and the same projected roughness on
/// the diagonal (αx = αy is not enough: a correlated, rotated elliptical slope has equal
/// marginals and a different αᵢ on the diagonals).
pub(super) fn is_isotropic<S: MicrosurfaceSlope>(slope: &S) -> bool {
    let diagonal = Vec3::new(core::f32::consts::FRAC_1_SQRT_2, core::f32::consts::FRAC_1_SQRT_2, 0.0);
    slope.alpha_x() == slope.alpha_y()
        && (slope.alpha_i(diagonal) - slope.alpha_x()).abs() <= 1e-6 * slope.alpha_x()
}

/// Checks that every value is finite and ≥ 0 (`values[k]`).
fn check_values(values: impl Iterator<Item = f64>) -> Result<(), Error> {
    for v in values {
        if !(v.is_finite() && v >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "values[k]",
                value: v as f32,
                expected: "finite and >= 0",
            });
        }
    }
    Ok(())
}

/// The stretched angle θ′ = (π/2)(1 − (1 − k/(N+1))²) of the (fractional) ring boundary `k` of
/// a grid of N = `rings` rings.
pub(super) fn grid_angle(k: f64, rings: usize) -> f64 {
    let v = 1.0 - k / (rings as f64 + 1.0);
    FRAC_PI_2 * (1.0 - v * v)
}

pub(super) fn check_ring_count(rings: usize) -> Result<(), Error> {
    if rings == 0 || rings > MAX_RINGS {
        return Err(Error::InvalidParameter {
            name: "values.len()",
            value: rings as f32,
            expected: "between 1 and MAX_RINGS = 4096 rings",
        });
    }
    Ok(())
}

impl TabulatedSlope {
    /// Visible slopes of the table stretched by 1/α (α = [`TabulatedSlope::alpha`]), seen from
    /// the stretched direction (sin θ, 0, cos θ): the table's exact sampler from the
    /// unstretched direction (sin θ/α, 0, cos θ), its slopes divided by α. The trait's default
    /// `sample_d_wi` composed with this is exact; the override below skips the stretching.
    #[must_use]
    pub fn sample_p22_11(&self, cos_theta: f32, sin_theta: f32, u1: f32, u2: f32) -> Vec2 {
        let (a, s) = (f64::from(self.alpha), self.grid.scale);
        let (h, z) = (f64::from(sin_theta) / a, f64::from(cos_theta));
        // the ring of the visibility line matters from below only
        let ring = if z < 0.0 { self.visibility_ring(h, z) } else { 0 };
        let m = match self.sampler.sample(s * h, z, ring, u1, u2) {
            Visible::Normal(m) => m,
            Visible::TailOnly => {
                // the unit GGX lobe's visible normals from the stretched direction (s h, 0, z)
                let len = (s * h).hypot(z);
                let v = Vec3::new((s * h / len) as f32, 0.0, (z / len) as f32);
                sample_visible_hemisphere(v, 1.0, u1, u2).as_dvec3()
            }
            Visible::Nothing => return Vec2::ZERO,
        };
        if m.z <= 0.0 {
            return Vec2::ZERO;
        }
        // slopes −s m.x/m.z, −s m.y/m.z, finite (a horizontal normal has the largest f32 slope)
        let slope = |v: f64| (-s * v / (m.z * a)).clamp(-f64::from(f32::MAX), f64::from(f32::MAX)) as f32;
        Vec2::new(slope(m.x), slope(m.y))
    }
}

impl crate::sealed::Sealed for &TabulatedSlope {}

impl MicrosurfaceSlope for &TabulatedSlope {
    #[inline]
    fn alpha_x(&self) -> f32 {
        self.alpha
    }

    #[inline]
    fn alpha_y(&self) -> f32 {
        self.alpha
    }

    /// fₖ s²/(π(s² + r²)²) at the slope radius r (0 beyond R_N when truncated, and for NaN
    /// slopes).
    #[inline]
    fn p22(&self, slope_x: f32, slope_y: f32) -> f32 {
        let (x, y) = (f64::from(slope_x), f64::from(slope_y));
        self.p22_radial((x * x + y * y).sqrt()) as f32
    }

    /// fₖ D_GGX(s)(ωm) in f64, rounded (0 for ωm.z ≤ 0 and beyond R_N when truncated).
    #[inline]
    fn d(&self, wm: Vec3) -> f32 {
        self.d64_unchecked(wm.as_dvec3()) as f32
    }

    /// As `d`; 0 for a non-finite normal (a debug assertion in debug builds).
    #[inline]
    fn d64_unchecked(&self, wm: DVec3) -> f64 {
        debug_assert!(wm.is_finite(), "d64: non-finite normal {wm}");
        if !wm.is_finite() {
            return 0.0;
        }
        let h2 = wm.x * wm.x + wm.y * wm.y;
        self.d_of(h2, wm.z, h2 + wm.z * wm.z)
    }

    /// B/cos θ above the horizon and −1 − B/|cos θ| below, B interpolated (see the type's
    /// documentation); saturates to ±`f32::MAX` at ±0. Invalid input
    /// ([policy](crate#invalid-input)): a `w` that is not a unit direction gives NaN.
    #[inline]
    fn lambda_unchecked(&self, w: Vec3) -> f32 {
        let (x, y, z) = (f64::from(w.x), f64::from(w.y), f64::from(w.z));
        let b = self.backface_area((x * x + y * y).sqrt(), z);
        let lambda = (b / z.abs()).min(f64::from(f32::MAX)) as f32;
        if w.z >= 0.0 { lambda } else { -1.0 - lambda }
    }

    /// Λ in f64, unsaturated (±∞ at ±0).
    #[inline]
    fn lambda64(&self, w: Vec3) -> f64 {
        let (x, y, z) = (f64::from(w.x), f64::from(w.y), f64::from(w.z));
        let b = self.backface_area((x * x + y * y).sqrt(), z);
        let l = b / z.abs();
        if w.z >= 0.0 { l } else { -1.0 - l }
    }

    /// cos θ + B above the horizon, B below (B interpolated). Invalid input
    /// ([policy](crate#invalid-input)): a `w` that is not a unit direction gives NaN.
    #[inline]
    fn projected_area_unchecked(&self, w: Vec3) -> f32 {
        self.projected_area64(w) as f32
    }

    /// The projected area in f64.
    #[inline]
    fn projected_area64(&self, w: Vec3) -> f64 {
        let (x, y, z) = (f64::from(w.x), f64::from(w.y), f64::from(w.z));
        let b = self.backface_area((x * x + y * y).sqrt(), z);
        if z >= 0.0 { z + b } else { b }
    }

    /// Exact for every ωi (see the type's documentation); +z for ωi = −z. Invalid
    /// input ([policy](crate#invalid-input)): a non-unit ωi or a uniform outside [0, 1] gives NaN.
    #[inline]
    fn sample_d_wi_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        self.sample_normal(wi, u1, u2)
    }
}

/// An anisotropic slope distribution made by stretching a [`TabulatedSlope`] by (sx, sy):
/// P²²(x̃, ỹ) = P²²_table(√((x̃/sx)² + (ỹ/sy)²))/(sx sy), i.e. a tabulated profile with
/// elliptic level sets (the way the analytic GGX and Beckmann become anisotropic; not a general
/// 2D table).
///
/// Everything follows from the table by the stretch (Heitz et al. 2016, supplement §2.1):
/// with ω_s = (sx ω.x, sy ω.y, ω.z), Λ(ω) = Λ_table(ω_s/‖ω_s‖) and the projected area is
/// ‖ω_s‖·area_table(ω_s/‖ω_s‖); visible normals are sampled exactly by sampling the table's
/// visible slopes from ω_s/‖ω_s‖ and scaling them by (sx, sy), since
/// (ω.z − x̃ω.x − ỹω.y)₊ dx̃ dỹ becomes ‖ω_s‖(ŝ.z − uŝ.x − vŝ.y)₊ du dv. `alpha_x` and
/// `alpha_y` report sx·α and sy·α (α = [`TabulatedSlope::alpha`]).
#[derive(Debug, Clone, Copy)]
pub struct StretchedTabulated<'a> {
    table: &'a TabulatedSlope,
    sx: f32,
    sy: f32,
}

impl TabulatedSlope {
    /// The table stretched by (`sx`, `sy`) into an anisotropic distribution.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `sx` or `sy` is not finite and > 0.
    pub fn stretched(&self, sx: f32, sy: f32) -> Result<StretchedTabulated<'_>, Error> {
        Ok(StretchedTabulated {
            table: self,
            sx: Error::check_positive("sx", sx)?,
            sy: Error::check_positive("sy", sy)?,
        })
    }
}

impl StretchedTabulated<'_> {
    /// ω_s/‖ω_s‖ and ‖ω_s‖ for ω_s = (sx ω.x, sy ω.y, ω.z), in f64.
    #[inline]
    fn stretch(&self, w: Vec3) -> (Vec3, f64) {
        let s = DVec3::new(
            f64::from(self.sx) * f64::from(w.x),
            f64::from(self.sy) * f64::from(w.y),
            f64::from(w.z),
        );
        let len = s.length();
        if len.is_nan() || len <= 0.0 {
            return (Vec3::Z, 0.0);
        }
        ((s / len).as_vec3(), len)
    }
}

impl StretchedTabulated<'_> {
    /// The table's back-face area at the stretched direction (sx ω.x, sy ω.y, ω.z).
    #[inline]
    fn backface_area(&self, w: Vec3) -> f64 {
        let (x, y) = (f64::from(self.sx) * f64::from(w.x), f64::from(self.sy) * f64::from(w.y));
        self.table.backface_area((x * x + y * y).sqrt(), f64::from(w.z))
    }
}

impl crate::sealed::Sealed for StretchedTabulated<'_> {}

impl MicrosurfaceSlope for StretchedTabulated<'_> {
    #[inline]
    fn alpha_x(&self) -> f32 {
        self.sx * self.table.alpha
    }

    #[inline]
    fn alpha_y(&self) -> f32 {
        self.sy * self.table.alpha
    }

    #[inline]
    fn p22(&self, slope_x: f32, slope_y: f32) -> f32 {
        let (x, y) = (f64::from(slope_x) / f64::from(self.sx), f64::from(slope_y) / f64::from(self.sy));
        (self.table.p22_radial((x * x + y * y).sqrt()) / (f64::from(self.sx) * f64::from(self.sy))) as f32
    }

    #[inline]
    fn d(&self, wm: Vec3) -> f32 {
        self.d64_unchecked(wm.as_dvec3()) as f32
    }

    /// P²²(x̃, ỹ)/cos⁴θm in f64; 0 for ωm.z ≤ 0, beyond the table and for a non-finite normal
    /// (a debug assertion).
    #[inline]
    fn d64_unchecked(&self, wm: DVec3) -> f64 {
        debug_assert!(wm.is_finite(), "d64: non-finite normal {wm}");
        if !wm.is_finite() || wm.z <= 0.0 {
            return 0.0;
        }
        let (sx, sy) = (f64::from(self.sx), f64::from(self.sy));
        // the stretched normal m′ = (m.x/sx, m.y/sy, m.z) has the stretched slopes, and D
        // transforms with cos⁴: D(m) = D_table(m′)(cos θm′/cos θm)⁴/(sx sy) =
        // fₖ s²/π·(|m|²/(s² m.z² + |m′_xy|²))²/(sx sy), the table's form with |m|² for |m′|²
        let (x, y) = (wm.x / sx, wm.y / sy);
        self.table.d_of(x * x + y * y, wm.z, wm.length_squared()) / (sx * sy)
    }

    /// The table's Λ at the stretched direction (the table's back-face area is homogeneous of
    /// degree 1, so it is evaluated at (sx ω.x, sy ω.y, ω.z) directly, in f64); saturates to
    /// ±`f32::MAX` at ±0. Invalid input ([policy](crate#invalid-input)): NaN.
    #[inline]
    fn lambda_unchecked(&self, w: Vec3) -> f32 {
        let lambda = (self.backface_area(w) / f64::from(w.z).abs()).min(f64::from(f32::MAX)) as f32;
        if w.z >= 0.0 { lambda } else { -1.0 - lambda }
    }

    /// Λ in f64, unsaturated.
    #[inline]
    fn lambda64(&self, w: Vec3) -> f64 {
        let l = self.backface_area(w) / f64::from(w.z).abs();
        if w.z >= 0.0 { l } else { -1.0 - l }
    }

    /// cos θ + B above the horizon, B below, B the table's back-face area at the stretched
    /// direction. Invalid input ([policy](crate#invalid-input)): NaN.
    #[inline]
    fn projected_area_unchecked(&self, w: Vec3) -> f32 {
        self.projected_area64(w) as f32
    }

    /// The projected area in f64.
    #[inline]
    fn projected_area64(&self, w: Vec3) -> f64 {
        f64::from(w.z).max(0.0) + self.backface_area(w)
    }

    /// Exact for every ωi: the table's visible slopes from ω_s/‖ω_s‖, scaled by (sx, sy); +z
    /// for ωi = −z. Invalid input ([policy](crate#invalid-input)): a non-unit ωi or a uniform
    /// outside [0, 1] gives NaN.
    #[inline]
    fn sample_d_wi_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        let (s, len) = self.stretch(wi);
        if len <= 0.0 {
            return Vec3::Z;
        }
        let m = (&self.table).sample_d_wi(s, u1, u2);
        if m == Vec3::Z && wi.z <= 0.0 {
            // the table sees nothing from the stretched ωi (as +z is not visible from ωi)
            return Vec3::Z;
        }
        // the table's normal m ∝ (−u, −v, 1): the slopes scale by (sx, sy)
        let stretched = Vec3::new(m.x * self.sx, m.y * self.sy, m.z);
        ensure_visible(wi, crate::vector::normalize_scaled(stretched, Vec3::Z))
    }
}
