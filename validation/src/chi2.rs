//! Chi-square goodness-of-fit tests of direction samplers against their densities.
//!
//! Bins are equal-area cells of a grid in (cos θ', φ') over a spherical cap around a chosen
//! pole (the whole sphere when `cap_cos = -1`), plus one cell for the rest of the sphere.
//! Expected counts come from adaptive Gauss–Legendre quadrature of the density per cell, so
//! that sharp lobes (low α, grazing) are integrated accurately. Cells with an expected count
//! below 5 are pooled into one cell. The statistic is compared with the chi-square
//! distribution at a Šidák-corrected significance chosen by the caller.

use super::quadrature::integrate;
use glam::Vec3;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Binning and quadrature settings.
#[derive(Debug, Clone, Copy)]
pub struct Chi2Grid {
    /// The pole of the binning frame (unit): put it at the lobe's centre for sharp lobes.
    pub pole: Vec3,
    /// Cells cover cos θ' ∈ [cap_cos, 1] around the pole; −1 covers the whole sphere.
    pub cap_cos: f64,
    /// Cells along cos θ'.
    pub nz: usize,
    /// Cells along φ'.
    pub nphi: usize,
    /// Absolute tolerance of the integral of the density per cell (relative to 1).
    pub quad_tol: f64,
    /// Maximum depth of the adaptive quadrature per cell.
    pub max_depth: u32,
}

impl Chi2Grid {
    /// The whole sphere, `nz` × `nphi` equal-area cells.
    pub fn sphere(nz: usize, nphi: usize) -> Self {
        Self { pole: Vec3::Z, cap_cos: -1.0, nz, nphi, quad_tol: 1e-7, max_depth: 10 }
    }

    /// A cap of angular radius `radius` (radians) around `pole`, plus the rest of the sphere.
    pub fn cap(pole: Vec3, radius: f64, nz: usize, nphi: usize) -> Self {
        Self {
            pole: pole.normalize(),
            cap_cos: radius.cos().max(-1.0),
            nz,
            nphi,
            quad_tol: 1e-7,
            max_depth: 10,
        }
    }
}

/// The outcome of one chi-square test.
#[derive(Debug, Clone)]
pub struct Chi2Outcome {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    /// ∫ pdf over the sphere by the quadrature (should be 1 for a normalized density).
    pub integral: f64,
    pub samples: usize,
    /// Samples the sampler did not produce (`None`).
    pub failures: usize,
}

/// Orthonormal frame (t, b, n) with n = pole.
fn frame(pole: Vec3) -> (glam::DVec3, glam::DVec3, glam::DVec3) {
    let n = pole.as_dvec3().normalize();
    let helper = if n.x.abs() < 0.9 { glam::DVec3::X } else { glam::DVec3::Y };
    let t = helper.cross(n).normalize();
    let b = n.cross(t);
    (t, b, n)
}

/// Runs the test: `n` samples from `sample` (which may fail with `None`) binned against
/// `pdf` (solid-angle density). Panics with a full report if p < `alpha`, if the sampler
/// failed more often than the density's missing mass allows, or if the density does not
/// integrate to `expected_mass` within 1e-3.
pub fn chi2_test(
    label: &str,
    grid: Chi2Grid,
    mut pdf: impl FnMut(Vec3) -> f64,
    mut sample: impl FnMut() -> Option<Vec3>,
    n: usize,
    alpha: f64,
    expected_mass: f64,
) -> Chi2Outcome {
    let (t, b, p) = frame(grid.pole);
    let to_world = |z: f64, phi: f64| {
        let s = (1.0 - z * z).max(0.0).sqrt();
        (t * (s * phi.cos()) + b * (s * phi.sin()) + p * z).as_vec3()
    };
    let cells = grid.nz * grid.nphi;
    let cell_of = |w: Vec3| -> usize {
        let w = w.as_dvec3().normalize();
        let z = w.dot(p).clamp(-1.0, 1.0);
        if z < grid.cap_cos {
            return cells;
        }
        let iz = (((z - grid.cap_cos) / (1.0 - grid.cap_cos) * grid.nz as f64) as usize).min(grid.nz - 1);
        let phi = w.dot(b).atan2(w.dot(t)).rem_euclid(std::f64::consts::TAU);
        let ip = ((phi / std::f64::consts::TAU * grid.nphi as f64) as usize).min(grid.nphi - 1);
        iz * grid.nphi + ip
    };

    // expected probabilities
    let mut g = |z: f64, phi: f64| pdf(to_world(z, phi));
    let mut expected = vec![0.0; cells + 1];
    for iz in 0..grid.nz {
        let z0 = grid.cap_cos + (1.0 - grid.cap_cos) * iz as f64 / grid.nz as f64;
        let z1 = grid.cap_cos + (1.0 - grid.cap_cos) * (iz + 1) as f64 / grid.nz as f64;
        for ip in 0..grid.nphi {
            let p0 = std::f64::consts::TAU * ip as f64 / grid.nphi as f64;
            let p1 = std::f64::consts::TAU * (ip + 1) as f64 / grid.nphi as f64;
            expected[iz * grid.nphi + ip] =
                integrate(&mut g, z0, z1, p0, p1, grid.quad_tol / cells as f64, grid.max_depth);
        }
    }
    if grid.cap_cos > -1.0 {
        let mut outside = 0.0;
        let strips = 16;
        for k in 0..strips {
            let z0 = -1.0 + (grid.cap_cos + 1.0) * k as f64 / strips as f64;
            let z1 = -1.0 + (grid.cap_cos + 1.0) * (k + 1) as f64 / strips as f64;
            for q in 0..4 {
                let p0 = std::f64::consts::TAU * q as f64 / 4.0;
                let p1 = std::f64::consts::TAU * (q + 1) as f64 / 4.0;
                outside += integrate(&mut g, z0, z1, p0, p1, grid.quad_tol / 64.0, grid.max_depth);
            }
        }
        expected[cells] = outside;
    }
    let integral: f64 = expected.iter().sum();
    assert!(
        (integral - expected_mass).abs() < 1e-3,
        "{label}: the density integrates to {integral:.6} by quadrature, expected {expected_mass}"
    );

    // observed counts
    let mut observed = vec![0u64; cells + 1];
    let mut failures = 0;
    for _ in 0..n {
        match sample() {
            Some(w) if w.is_finite() => observed[cell_of(w)] += 1,
            _ => failures += 1,
        }
    }
    // failures are legitimate only for the mass the density leaves out (e.g. absorbed walks)
    let missing = (1.0 - integral).max(0.0) * n as f64;
    assert!(
        failures as f64 <= missing + 5.0 * (missing.max(1.0)).sqrt() + 1.0,
        "{label}: {failures} failed samples out of {n}, expected about {missing:.1}"
    );

    // pool low-expectation cells
    let (mut stat, mut used) = (0.0, 0usize);
    let (mut pool_e, mut pool_o) = (0.0, 0.0);
    for (e, o) in expected.iter().zip(&observed) {
        let e = e * n as f64;
        let o = *o as f64;
        if e < 5.0 {
            pool_e += e;
            pool_o += o;
        } else {
            stat += (o - e) * (o - e) / e;
            used += 1;
        }
    }
    if pool_e > 0.0 {
        stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        used += 1;
    } else if pool_o > 0.0 {
        panic!("{label}: {pool_o} samples fell where the density is zero");
    }
    let dof = used.saturating_sub(1).max(1);
    let p_value = 1.0 - ChiSquared::new(dof as f64).unwrap().cdf(stat);
    let outcome = Chi2Outcome { statistic: stat, dof, p_value, integral, samples: n, failures };
    assert!(
        p_value >= alpha,
        "{label}: chi-square rejects the sampler: χ² = {stat:.2}, dof = {dof}, p = {p_value:.3e} < α = {alpha:.3e} \
         (N = {n}, ∫pdf = {integral:.6}, failures = {failures})"
    );
    outcome
}
