//! Chi-square goodness-of-fit tests of samplers against exact densities, in two domains: the
//! sphere of directions ([`chi2_test`]) and the stretched slope plane of the normals visible
//! from a direction ([`slope_chi2`]); and the pooling of low-expectation cells ([`pool`])
//! that every chi-square test of the crate uses (also `crate::stochastic`).
//!
//! Sphere: bins are equal-area cells of a grid in (cos θ', φ') over a spherical cap around a chosen
//! pole (the whole sphere when `cap_cos = -1`), plus one cell for the rest of the sphere.
//! Expected counts come from adaptive Gauss–Legendre quadrature of the density per cell, so
//! that sharp lobes (low α, grazing) are integrated accurately. Cells with an expected count
//! below 5 are pooled into one cell. The statistic is compared with the chi-square
//! distribution at a Šidák-corrected significance chosen by the caller.

use crate::check::rel_close;
use crate::quadrature::{
    CrossMap, Domain, integrate, integrate_refined, integrate_sphere, uv_of, visible_frame,
};
use glam::Vec3;
use microsurface::{Bsdf, BsdfSample, BsdfValue};
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
    /// Splits of every cell before the adaptive test (see
    /// [`crate::quadrature::integrate_refined`]): 0 except for densities
    /// with a jump along a curve that the cells do not follow.
    pub min_depth: u32,
}

impl Chi2Grid {
    /// The whole sphere, `nz` × `nphi` equal-area cells.
    pub fn sphere(nz: usize, nphi: usize) -> Self {
        Self { pole: Vec3::Z, cap_cos: -1.0, nz, nphi, quad_tol: 1e-7, max_depth: 10, min_depth: 0 }
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
            min_depth: 0,
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
            expected[iz * grid.nphi + ip] = integrate_refined(
                &mut g,
                z0,
                z1,
                p0,
                p1,
                grid.quad_tol / cells as f64,
                grid.min_depth,
                grid.max_depth,
            );
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
                outside += integrate_refined(
                    &mut g,
                    z0,
                    z1,
                    p0,
                    p1,
                    grid.quad_tol / 64.0,
                    grid.min_depth,
                    grid.max_depth,
                );
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
    let pooled = pool(
        n,
        expected.iter().zip(&observed).map(|(&m, &o)| Cell { mass: m, variance: 0.0, observed: o as f64 }),
    );
    if pooled.statistic.is_infinite() {
        panic!("{label}: {} samples fell where the density is zero", pooled.zero_mass_observed);
    }
    let (stat, dof) = (pooled.statistic, pooled.dof());
    let p_value = 1.0 - ChiSquared::new(dof as f64).unwrap().cdf(stat);
    let outcome = Chi2Outcome { statistic: stat, dof, p_value, integral, samples: n, failures };
    assert!(
        p_value >= alpha,
        "{label}: chi-square rejects the sampler: χ² = {stat:.2}, dof = {dof}, p = {p_value:.3e} < α = {alpha:.3e} \
         (N = {n}, ∫pdf = {integral:.6}, failures = {failures})"
    );
    outcome
}

/// Pooling: cells whose expected count is below this are pooled into one cell.
pub const MIN_EXPECTED: f64 = 5.0;

/// One cell of a chi-square test: its expected probability m̂, the variance of m̂ (0 for an
/// exact density) and the observed count.
#[derive(Debug, Clone, Copy)]
pub struct Cell {
    pub mass: f64,
    pub variance: f64,
    pub observed: f64,
}

/// The pooled chi-square statistic of [`pool`].
#[derive(Debug, Clone, Copy)]
pub struct Pooled {
    /// Σ (O − N m̂)² / (N m̂ + N² Var m̂) over the cells used; +∞ if samples fell where the
    /// expected mass is exactly zero.
    pub statistic: f64,
    /// Cells used (the pool counts as one).
    pub cells: usize,
    /// The mean of the statistic, Σ (1 − m̂/(1 + N Var m̂/m̂)) over the cells used: the
    /// (fractional) degrees of freedom of a stochastic expectation.
    pub stochastic_dof: f64,
    /// The largest noise ratio N Var m̂/m̂ of a cell used (0 for exact densities).
    pub max_ratio: f64,
    /// The samples in cells of zero expected mass (non-zero only if `statistic` is +∞).
    pub zero_mass_observed: f64,
}

impl Pooled {
    /// The degrees of freedom of an exact expectation: cells − 1 (at least 1).
    pub fn dof(&self) -> usize {
        self.cells.saturating_sub(1).max(1)
    }
}

/// The chi-square statistic of `n` samples over `cells`, with every cell of expected count
/// N m̂ < [`MIN_EXPECTED`] pooled into one. A sample in a cell of exactly zero total expected
/// mass makes the statistic +∞.
pub fn pool(n: usize, cells: impl IntoIterator<Item = Cell>) -> Pooled {
    let nf = n as f64;
    let mut out =
        Pooled { statistic: 0.0, cells: 0, stochastic_dof: 0.0, max_ratio: 0.0, zero_mass_observed: 0.0 };
    let add = |out: &mut Pooled, m: f64, v: f64, o: f64| {
        let ratio = nf * v / m;
        out.statistic += (o - nf * m) * (o - nf * m) / (nf * m * (1.0 + ratio));
        out.stochastic_dof += 1.0 - m / (1.0 + ratio);
        out.max_ratio = out.max_ratio.max(ratio);
        out.cells += 1;
    };
    let (mut pool_m, mut pool_v, mut pool_o) = (0.0, 0.0, 0.0);
    for c in cells {
        if nf * c.mass < MIN_EXPECTED {
            pool_m += c.mass;
            pool_v += c.variance;
            pool_o += c.observed;
        } else {
            add(&mut out, c.mass, c.variance, c.observed);
        }
    }
    if pool_m > 0.0 {
        add(&mut out, pool_m, pool_v, pool_o);
    } else if pool_o > 0.0 {
        out.statistic = f64::INFINITY;
        out.zero_mass_observed = pool_o;
    }
    out
}

/// The outcome of [`slope_chi2`].
#[derive(Debug, Clone, Copy)]
pub struct SlopeChi2Outcome {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    /// ∫ D_ωi over the visible half-plane by the quadrature.
    pub integral: f64,
}

/// The settings of [`slope_chi2`]: `nu` u-bins of equal probability (edges from `strips`
/// quadrature strips), each split into `nv` equal v-bins.
#[derive(Debug, Clone, Copy)]
pub struct SlopeGrid {
    pub nu: usize,
    pub nv: usize,
    pub strips: usize,
    /// Relative adaptive tolerance of the quadrature per cell.
    pub rel_tol: f64,
    /// Maximum depth of the quadrature of a bin.
    pub max_depth: u32,
}

/// A chi-square test of a visible-normal sampler in the slope plane (Heitz et al. 2016,
/// supplement §4.2.2), with bins in the coordinates (u, v) of
/// [`crate::quadrature::integrate_visible`]: the lobe of D_ωi is resolved in these
/// coordinates whatever α and θi (including the thin crescents of Beckmann below the horizon,
/// which equal-area bins on the sphere do not resolve). Expected probabilities by adaptive
/// quadrature of `d_wi64` (the density at an f64 normal: rounding the normal to f32 flips the
/// visibility of normals near the boundary of thin lobes); the last cell is "not visible";
/// cells with expectation < 5 pooled ([`pool`]). Returns the outcome, or the failure message
/// (nothing visible, D_ωi not integrating to 1 within 1e-3, samples where D_ωi is 0, or p <
/// `alpha`).
#[allow(clippy::too_many_arguments)]
pub fn slope_chi2(
    label: &str,
    a: (f32, f32),
    map: CrossMap,
    wi: Vec3,
    grid: SlopeGrid,
    d_wi64: impl Fn(glam::DVec3) -> f64,
    mut sample: impl FnMut() -> Vec3,
    n: usize,
    alpha: f64,
) -> Result<SlopeChi2Outcome, String> {
    use crate::quadrature::cross_y;
    use std::f64::consts::FRAC_PI_2;
    let SlopeGrid { nu, nv, strips: n_strips, rel_tol, max_depth } = grid;
    let Some(frame) = visible_frame(a, wi) else { return Err(format!("{label}: nothing visible")) };
    let (cos_phi, sin_phi, u_hi) = frame;
    let (ax, ay) = (f64::from(a.0), f64::from(a.1));
    let mut f = |u: f64, v: f64| {
        let (x, dx) = (u.tan(), 1.0 / (u.cos() * u.cos()));
        let (y, dy) = cross_y(x, v, map);
        if !y.is_finite() {
            return 0.0;
        }
        let sx = ax * (cos_phi * x - sin_phi * y);
        let sy = ay * (sin_phi * x + cos_phi * y);
        let norm = (1.0 + sx * sx + sy * sy).sqrt();
        // the normal stays in f64: rounding it to f32 flips the visibility of normals near the
        // boundary of thin lobes (Beckmann far below the horizon)
        let m = glam::DVec3::new(-sx / norm, -sy / norm, 1.0 / norm);
        let value = d_wi64(m);
        if value == 0.0 { 0.0 } else { value * ax * ay * dx * dy / (norm * norm * norm) }
    };
    let (vlo, vhi) = (-FRAC_PI_2, FRAC_PI_2);
    // marginal in u by strips
    let strips = |lo: f64, f: &mut dyn FnMut(f64, f64) -> f64| {
        let mut cum = vec![0.0; n_strips + 1];
        for k in 0..n_strips {
            let u0 = lo + (u_hi - lo) * k as f64 / n_strips as f64;
            let u1 = lo + (u_hi - lo) * (k + 1) as f64 / n_strips as f64;
            let mut strip = 0.0;
            for j in 0..8 {
                let v0 = vlo + (vhi - vlo) * j as f64 / 8.0;
                let v1 = vlo + (vhi - vlo) * (j + 1) as f64 / 8.0;
                let mut g = |u: f64, v: f64| f(u, v);
                let rough = integrate(&mut g, u0, u1, v0, v1, 0.0, 0).abs();
                strip += integrate(&mut g, u0, u1, v0, v1, (1e-9f64).max(rel_tol * rough), 5);
            }
            cum[k + 1] = cum[k] + strip;
        }
        cum
    };
    // a second pass zooms onto the support when the lobe spans only a few strips (the thin
    // crescents of Beckmann far below the horizon): the mass left below `lo` is < 1e-12
    let mut lo = -FRAC_PI_2;
    let mut cum = strips(lo, &mut f);
    let first = cum.iter().position(|&c| c > 1e-12 * cum[n_strips]).unwrap_or(1).saturating_sub(1);
    if first > 0 {
        lo += (u_hi - lo) * first as f64 / n_strips as f64;
        cum = strips(lo, &mut f);
    }
    let total = cum[n_strips];
    if (total - 1.0).abs() > 1e-3 {
        return Err(format!("{label}: D_ωi integrates to {total:.6} by quadrature, expected 1"));
    }
    // equal-probability u edges (linear interpolation in the cumulative)
    let mut edges = vec![lo];
    let mut k = 0;
    for b in 1..nu {
        let target = total * b as f64 / nu as f64;
        while cum[k + 1] < target {
            k += 1;
        }
        let t = (target - cum[k]) / (cum[k + 1] - cum[k]).max(1e-300);
        edges.push(lo + (u_hi - lo) * (k as f64 + t) / n_strips as f64);
    }
    edges.push(u_hi);
    // expected probabilities per cell; the last cell (index nu·nv) is "not visible"
    let mut expected = vec![0.0; nu * nv + 1];
    for i in 0..nu {
        for j in 0..nv {
            let v0 = vlo + (vhi - vlo) * j as f64 / nv as f64;
            let v1 = vlo + (vhi - vlo) * (j + 1) as f64 / nv as f64;
            let rough = integrate(&mut f, edges[i], edges[i + 1], v0, v1, 0.0, 0).abs();
            expected[i * nv + j] =
                integrate(&mut f, edges[i], edges[i + 1], v0, v1, (1e-9f64).max(rel_tol * rough), max_depth);
        }
    }
    let mut observed = vec![0u64; nu * nv + 1];
    for _ in 0..n {
        let m = sample();
        let (u, v) = uv_of(a, frame, m, map);
        let cell = if !(u.is_finite() && v.is_finite()) || u > u_hi {
            nu * nv
        } else {
            let i = edges.partition_point(|&e| e <= u).clamp(1, nu) - 1;
            let j = (((v - vlo) / (vhi - vlo) * nv as f64) as usize).min(nv - 1);
            i * nv + j
        };
        observed[cell] += 1;
    }
    let pooled = pool(
        n,
        expected.iter().zip(&observed).map(|(&m, &o)| Cell { mass: m, variance: 0.0, observed: o as f64 }),
    );
    if pooled.statistic.is_infinite() {
        return Err(format!("{label}: {} samples where D_ωi is 0 (N = {n})", pooled.zero_mass_observed));
    }
    let (stat, dof) = (pooled.statistic, pooled.dof());
    let p = 1.0 - ChiSquared::new(dof as f64).unwrap().cdf(stat);
    if p < alpha {
        return Err(format!(
            "{label}: slope-space chi-square rejects the sampler: χ² = {stat:.2}, dof = {dof}, p = {p:.3e} < α = {alpha:.3e} \
             (N = {n}, ∫D_ωi = {total:.6}, {nu} × {nv} bins)"
        ));
    }
    Ok(SlopeChi2Outcome { statistic: stat, dof, p_value: p, integral: total })
}

/// The margin of the ∫pdf checks of [`bsdf_chi2`] (∫pdf ≤ 1, the refusal rate): a deterministic
/// allowance for the adaptive quadrature's error over the absolute tolerance it is asked for
/// (1e-5 or 1e-4), whose error estimate is not a rigorous bound where a density has a kink (its
/// horizon cut-off); not a statistical allowance.
pub const MASS_TOLERANCE: f64 = 1e-3;

/// The settings of [`bsdf_chi2`].
#[derive(Debug, Clone, Copy)]
pub struct BsdfChi2 {
    /// The chi-square test's cells and quadrature.
    pub grid: Chi2Grid,
    /// The quadrature of ∫pdf over the sphere: initial panels in cos θ and φ, absolute
    /// tolerance, maximum depth.
    pub mass: (usize, usize, f64, u32),
    /// Samples.
    pub n: usize,
    /// The density the samples are tested against is `pdf_scale` × pdf (1, or a negative
    /// control's wrong scale).
    pub pdf_scale: f64,
    /// If set, each sample's density is also checked against the BSDF's own: `eval_with_pdf`
    /// at its direction gives the density of `pdf` (the same bits) within this relative
    /// tolerance of the sample's, and the value of `eval` (the same bits).
    pub pdf_consistency: Option<f32>,
}

impl BsdfChi2 {
    /// `n` samples in 20 × 40 equal-area cells of the sphere, the cells' densities and ∫pdf
    /// (from 8 × 16 panels) integrated to the absolute tolerance `tol` at depth `depth`, each
    /// sample's density equal to `pdf`'s within `pdf_rel` (see [`Self::pdf_consistency`]).
    pub fn sphere(n: usize, tol: f64, depth: u32, pdf_rel: f32) -> Self {
        Self {
            grid: Chi2Grid { quad_tol: tol, max_depth: depth, ..Chi2Grid::sphere(20, 40) },
            mass: (8, 16, tol, depth),
            n,
            pdf_scale: 1.0,
            pdf_consistency: Some(pdf_rel),
        }
    }
}

/// [`bsdf_chi2`] of `b.sample` from fresh uniforms of `rng` ([`crate::check::draw`]: uc, then
/// u) against `b.eval`.
#[allow(clippy::too_many_arguments)]
pub fn sampler_chi2(
    label: &str,
    b: &dyn Bsdf,
    wo: Vec3,
    settings: BsdfChi2,
    rng: &mut crate::TestRng,
    each: impl FnMut(&BsdfSample),
    alpha: f64,
    z: f64,
) -> BsdfChi2Outcome {
    bsdf_chi2(label, b, wo, settings, || crate::check::draw(b, wo, rng), |wi| b.eval(wo, wi), each, alpha, z)
}

/// The outcome of [`bsdf_chi2`]: the chi-square test's and ∫pdf.
#[derive(Debug, Clone)]
pub struct BsdfChi2Outcome {
    pub chi2: Chi2Outcome,
    pub mass: f64,
}

/// The test of a BSDF sampler with an exact density, for the view `wo`: ∫pdf ≤ 1 (within
/// [`MASS_TOLERANCE`]); `sample` (each call one sample, `None` a refusal) passes the
/// chi-square test against `pdf` at significance `alpha`; it refuses exactly the mass 1 − ∫pdf
/// ([`crate::assert_refusal_rate`], z·SE + [`MASS_TOLERANCE`]); and each sample carries the
/// `exact_pdf` flag and a weight equal to f·|cos θi|/pdf (relative 1e-4, [`crate::check::rel_close`])
/// with f = `eval(wi)`, flagged exact, and the density checks of
/// [`BsdfChi2::pdf_consistency`]. `each` makes the caller's own checks of a sample (flags,
/// counts). Prints and returns χ², the degrees of freedom, p and ∫pdf.
#[allow(clippy::too_many_arguments)]
pub fn bsdf_chi2(
    label: &str,
    b: &dyn Bsdf,
    wo: Vec3,
    settings: BsdfChi2,
    mut sample: impl FnMut() -> Option<BsdfSample>,
    mut eval: impl FnMut(Vec3) -> BsdfValue,
    mut each: impl FnMut(&BsdfSample),
    alpha: f64,
    z: f64,
) -> BsdfChi2Outcome {
    let (nz, nphi, tol, depth) = settings.mass;
    let mass = integrate_sphere(&mut |w| f64::from(b.pdf(wo, w)), nz, nphi, Domain::Sphere, tol, depth);
    assert!(mass <= 1.0 + MASS_TOLERANCE, "{label}: ∫pdf = {mass} > 1");
    let scale = settings.pdf_scale;
    let chi2 = chi2_test(
        label,
        settings.grid,
        |w| scale * f64::from(b.pdf(wo, w)),
        || {
            let s = sample()?;
            assert!(s.flags.exact_pdf, "{label}: exact_pdf flag not set ({:?})", s.flags);
            each(&s);
            let v = eval(s.wi);
            assert!(v.exact, "{label}: eval not flagged exact");
            if let Some(tol) = settings.pdf_consistency {
                let (value, pdf) = b.eval_with_pdf(wo, s.wi);
                assert!((pdf - s.pdf).abs() <= tol * pdf, "{label}: pdf {pdf} ≠ sample's {}", s.pdf);
                assert_eq!(pdf, b.pdf(wo, s.wi), "{label}: eval_with_pdf and pdf disagree");
                assert_eq!(value, v, "{label}: eval_with_pdf and eval disagree");
            }
            let expected = v.f * (s.wi.z.abs() / s.pdf);
            assert!(
                rel_close(s.weight, expected, 1e-4),
                "{label}: weight {} ≠ eval·|cos θi|/pdf = {expected} at wi = {}",
                s.weight,
                s.wi
            );
            Some(s.wi)
        },
        settings.n,
        alpha,
        scale * mass,
    );
    crate::assert_refusal_rate(label, chi2.failures, settings.n, mass, MASS_TOLERANCE, z);
    println!(
        "{label}: χ² = {:.1}, dof = {}, p = {:.4}, ∫pdf = {mass:.5}",
        chi2.statistic, chi2.dof, chi2.p_value
    );
    BsdfChi2Outcome { chi2, mass }
}
