//! Chi-square tests of samplers against densities known only through unbiased stochastic
//! estimators (the random walks, the position-free estimators, diffuse phase functions).

use super::{Stats, rng, uniform64};
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

/// Chi-square test of `sample` against a density known only through an unbiased stochastic
/// estimator `density`, over an equal-area `nz` × `nphi` grid of (cos θ, φ) on cos θ ≥ z_lo.
///
/// The expected probability m̂ of a cell is its area times the mean of `density` at uniform
/// points of the cell, one independent evaluation each, doubled until N·Var(m̂)/m ≤
/// `NOISE_RATIO` (or `CELL_MAX` points). Cells with N m̂ < 5 are pooled. The statistic
/// Σ (O − N m̂)²/(N m̂ + N² Var m̂) has mean k − Σ m/(1 + N Var m̂/m) over the k cells used, and
/// is compared with the chi-square distribution with that (fractional) number of degrees of
/// freedom. Samples outside cos θ ≥ z_lo, or where every estimate is 0, fail the test.
/// Failed samples (`None`) are allowed only for the mass the density leaves out.
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
    let mut point_rng = rng(0x5eed);
    let nf = n as f64;
    let cells = nz * nphi;
    let (dz, dp) = ((1.0 - z_lo) / nz as f64, TAU / nphi as f64);
    let (mut mass, mut var) = (vec![0.0; cells], vec![0.0; cells]);
    for iz in 0..nz {
        for ip in 0..nphi {
            let (z0, p0) = (z_lo + dz * iz as f64, dp * ip as f64);
            let mut stats = Stats::default();
            let mut target = CELL_START;
            loop {
                while (stats.n as usize) < target {
                    let z = z0 + dz * uniform64(&mut point_rng);
                    let phi = p0 + dp * uniform64(&mut point_rng);
                    let s = (1.0 - z * z).max(0.0).sqrt();
                    stats.push(density(DVec3::new(s * phi.cos(), s * phi.sin(), z).as_vec3()));
                }
                let (m, v) = (dz * dp * stats.mean(), (dz * dp * stats.se()).powi(2));
                if m == 0.0 || nf * v / m <= NOISE_RATIO || target >= CELL_MAX {
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
    let (mut stat, mut dof, mut max_ratio) = (0.0, 0.0, 0.0f64);
    let mut add = |m: f64, v: f64, o: f64| {
        let ratio = nf * v / m;
        stat += (o - nf * m).powi(2) / (nf * m * (1.0 + ratio));
        dof += 1.0 - m / (1.0 + ratio);
        max_ratio = max_ratio.max(ratio);
    };
    let (mut pool_m, mut pool_v, mut pool_o) = (0.0, 0.0, 0.0);
    for c in 0..cells {
        if nf * mass[c] < 5.0 {
            pool_m += mass[c];
            pool_v += var[c];
            pool_o += observed[c] as f64;
        } else {
            add(mass[c], var[c], observed[c] as f64);
        }
    }
    if pool_m > 0.0 {
        add(pool_m, pool_v, pool_o);
    } else {
        assert!(pool_o == 0.0, "{label}: {pool_o} samples fell where the density is zero");
    }
    let p_value = 1.0 - ChiSquared::new(dof).unwrap().cdf(stat);
    assert!(
        max_ratio <= 4.0 * NOISE_RATIO,
        "{label}: the expectation stayed too noisy (N·Var(m̂)/m = {max_ratio:.3}): the test would lose its power"
    );
    assert!(
        p_value >= alpha,
        "{label}: chi-square rejects the sampler: χ² = {stat:.2}, dof = {dof:.2}, p = {p_value:.3e} < α = {alpha:.3e} \
         (N = {n}, Σm̂ = {total:.5}, failures = {failures}, largest N·Var(m̂)/m = {max_ratio:.3})"
    );
    Chi2Result { p_value, dof, mass: total, max_ratio }
}
