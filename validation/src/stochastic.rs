//! Chi-square tests of samplers against densities known only through unbiased stochastic
//! estimators (the random walks, the position-free estimators, diffuse phase functions).

use crate::chi2::{Cell, pool};
use crate::{Stats, rng, uniform64};
use glam::{DVec3, Vec3};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::TAU;

/// The outcome of [`stochastic_chi2`].
pub struct Chi2Result {
    pub p_value: f64,
    pub dof: f64,
    pub mass: f64,
    pub max_ratio: f64,
}

/// Target of the adaptive refinement: N·Var(m̂)/m ≤ this in every cell.
pub const NOISE_RATIO: f64 = 0.1;
/// Evaluations per cell before refinement, and the cap.
pub const CELL_START: usize = 1_000;
pub const CELL_MAX: usize = 64_000;

/// The binning and the expectation budget of [`stochastic_chi2_with`]: an equal-area `nz` ×
/// `nphi` grid of (cos θ, φ) on cos θ ≥ `z_lo`; per cell, `cell_start` evaluations doubled
/// until N·Var(m̂)/m ≤ `noise_ratio` or `cell_max` (equal: a fixed budget); the test fails
/// if a cell used keeps N·Var(m̂)/m > `max_noise_ratio` (it would lose its power).
#[derive(Debug, Clone, Copy)]
pub struct StochasticGrid {
    pub z_lo: f64,
    pub nz: usize,
    pub nphi: usize,
    pub cell_start: usize,
    pub cell_max: usize,
    pub noise_ratio: f64,
    pub max_noise_ratio: f64,
}

impl StochasticGrid {
    /// The default budget ([`CELL_START`] doubled up to [`CELL_MAX`], [`NOISE_RATIO`], at most
    /// 4 × [`NOISE_RATIO`]) on cos θ ≥ `z_lo`.
    pub fn adaptive(z_lo: f64, nz: usize, nphi: usize) -> Self {
        Self {
            z_lo,
            nz,
            nphi,
            cell_start: CELL_START,
            cell_max: CELL_MAX,
            noise_ratio: NOISE_RATIO,
            max_noise_ratio: 4.0 * NOISE_RATIO,
        }
    }
}

/// Chi-square test of `sample` against a density known only through an unbiased stochastic
/// estimator `density`, over an equal-area `nz` × `nphi` grid of (cos θ, φ) on cos θ ≥ z_lo,
/// with the default budget ([`StochasticGrid::adaptive`]; see [`stochastic_chi2_with`]).
#[allow(clippy::too_many_arguments)]
pub fn stochastic_chi2(
    label: &str,
    z_lo: f64,
    nz: usize,
    nphi: usize,
    density: &mut dyn FnMut(Vec3) -> f64,
    sample: &mut dyn FnMut() -> Option<Vec3>,
    n: usize,
    alpha: f64,
) -> Chi2Result {
    stochastic_chi2_with(label, StochasticGrid::adaptive(z_lo, nz, nphi), density, sample, n, alpha)
}

/// Chi-square test of `sample` against a density known only through an unbiased stochastic
/// estimator `density`, over the grid `grid` (Mitsuba's `ChiSquareTest` with a stochastic
/// expectation).
///
/// The expected probability m̂ of a cell is its area times the mean of `density` at uniform
/// points of the cell, one independent evaluation each, doubled until N·Var(m̂)/m ≤
/// `noise_ratio` (or `cell_max` points). Cells with N m̂ < 5 are pooled ([`crate::chi2::pool`]).
/// The statistic Σ (O − N m̂)²/(N m̂ + N² Var m̂) has mean k − Σ m/(1 + N Var m̂/m) over the k
/// cells used, and is compared with the chi-square distribution with that (fractional) number
/// of degrees of freedom. Samples outside cos θ ≥ z_lo, or where every estimate is 0, fail the
/// test. Failed samples (`None`) are allowed only for the mass the density leaves out.
pub fn stochastic_chi2_with(
    label: &str,
    grid: StochasticGrid,
    density: &mut dyn FnMut(Vec3) -> f64,
    sample: &mut dyn FnMut() -> Option<Vec3>,
    n: usize,
    alpha: f64,
) -> Chi2Result {
    let StochasticGrid { z_lo, nz, nphi, cell_start, cell_max, noise_ratio, max_noise_ratio } = grid;
    let mut point_rng = rng(0x5eed);
    let nf = n as f64;
    let cells = nz * nphi;
    let (dz, dp) = ((1.0 - z_lo) / nz as f64, TAU / nphi as f64);
    let (mut mass, mut var) = (vec![0.0; cells], vec![0.0; cells]);
    for iz in 0..nz {
        for ip in 0..nphi {
            let (z0, p0) = (z_lo + dz * iz as f64, dp * ip as f64);
            let mut stats = Stats::default();
            let mut target = cell_start;
            loop {
                while (stats.n as usize) < target {
                    let z = z0 + dz * uniform64(&mut point_rng);
                    let phi = p0 + dp * uniform64(&mut point_rng);
                    let s = (1.0 - z * z).max(0.0).sqrt();
                    stats.push(density(DVec3::new(s * phi.cos(), s * phi.sin(), z).as_vec3()));
                }
                let (m, v) = (dz * dp * stats.mean(), (dz * dp * stats.se()).powi(2));
                if m == 0.0 || nf * v / m <= noise_ratio || target >= cell_max {
                    break;
                }
                target *= 2;
            }
            mass[iz * nphi + ip] = dz * dp * stats.mean();
            var[iz * nphi + ip] = (dz * dp * stats.se()).powi(2);
        }
    }
    let mut observed = vec![0u64; cells];
    let mut failures = 0usize;
    for _ in 0..n {
        let Some(w) = sample() else {
            failures += 1;
            continue;
        };
        assert!(w.is_finite() && w.is_normalized(), "{label}: sampled ωo = {w} is not a unit vector");
        let w = w.as_dvec3();
        assert!(w.z >= z_lo, "{label}: sampled ωo = {w} outside the support cos θ ≥ {z_lo}");
        let iz = (((w.z - z_lo) / dz) as usize).min(nz - 1);
        let ip = ((w.y.atan2(w.x).rem_euclid(TAU) / dp) as usize).min(nphi - 1);
        observed[iz * nphi + ip] += 1;
    }
    let total: f64 = mass.iter().sum();
    let missing = (1.0 - total).max(0.0) * nf;
    assert!(
        failures as f64 <= missing + 5.0 * missing.max(1.0).sqrt() + 1.0,
        "{label}: {failures} failed samples out of {n}, expected about {missing:.1}"
    );
    let pooled =
        pool(n, (0..cells).map(|c| Cell { mass: mass[c], variance: var[c], observed: observed[c] as f64 }));
    assert!(
        pooled.statistic.is_finite(),
        "{label}: {} samples fell where the density is zero",
        pooled.zero_mass_observed
    );
    let (stat, dof, max_ratio) = (pooled.statistic, pooled.stochastic_dof, pooled.max_ratio);
    let p_value = 1.0 - ChiSquared::new(dof).unwrap().cdf(stat);
    assert!(
        max_ratio <= max_noise_ratio,
        "{label}: the expectation stayed too noisy (N·Var(m̂)/m = {max_ratio:.3}): the test would lose its power"
    );
    assert!(
        p_value >= alpha,
        "{label}: chi-square rejects the sampler: χ² = {stat:.2}, dof = {dof:.2}, p = {p_value:.3e} < α = {alpha:.3e} \
         (N = {n}, Σm̂ = {total:.5}, failures = {failures}, largest N·Var(m̂)/m = {max_ratio:.3})"
    );
    Chi2Result { p_value, dof, mass: total, max_ratio }
}
