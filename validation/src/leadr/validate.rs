//! The single-scattering BRDF of a noncentral correlated Beckmann lobe in closed form, and the
//! relative L1 error of a filtered lobe against the average of the fine texels' BRDFs (the
//! supersampled ground truth). Shared by `examples/leadr` and `tests/leadr.rs`.

use glam::{DVec2, DVec3};
use microsurface::LeadrLobe;
use std::f64::consts::{FRAC_1_SQRT_2, PI};

/// 1/√(2π).
const INV_SQRT_TAU: f64 = 0.398_942_280_401_432_7;
/// Half-width of the slope-space quadrature box, in standard deviations of each lobe.
const BOX_SIGMAS: f64 = 6.0;
/// Quadrature nodes per standard deviation of the narrowest lobe (midpoint rule; for Gaussian
/// integrands its error is of order exp(−2π² · 2.5²) ≈ 1e-53 relative, the kinks of |g_a − g_r|
/// aside, which converge as h²).
pub const NODES_PER_SIGMA: f64 = 2.5;
/// A cap on the nodes per axis.
const MAX_NODES: usize = 700;

/// A noncentral, anisotropic, correlated Beckmann slope distribution N(mean, Σ) (Dupuy 2015,
/// eq. 3.2) with Smith masking (eq. 3.3) and the single-scattering BRDF of a perfect mirror
/// microsurface (F = 1): f = D(ωh) G1(ωi) G1(ωo) / (4 cos θi cos θo), the separable
/// Torrance–Sparrow form the thesis uses (§2.1, listing 3.2 per direction).
#[derive(Debug, Clone, Copy)]
pub struct Lobe {
    mean: DVec2,
    cov: [f64; 3],
    inv: [f64; 3],
    norm: f64,
}

impl Lobe {
    /// The lobe of slope mean `mean` and covariance [Σxx, Σyy, Σxy] (positive definite).
    pub fn new(mean: DVec2, cov: [f64; 3]) -> Self {
        let [xx, yy, xy] = cov;
        let det = xx * yy - xy * xy;
        assert!(det > 0.0 && xx > 0.0, "a positive-definite covariance: {cov:?}");
        Self { mean, cov, inv: [yy / det, xx / det, -xy / det], norm: 1.0 / (2.0 * PI * det.sqrt()) }
    }

    /// The lobe LEADR gives a texel.
    pub fn leadr(lobe: &LeadrLobe) -> Self {
        Self::new(lobe.mean_slope().as_dvec2(), lobe.covariance().map(f64::from))
    }

    /// A texel of mesosurface slope `mean` on an isotropic Beckmann base of roughness `alpha`
    /// (the fine texels of the reference, and the naive filter's lobe).
    pub fn texel(mean: DVec2, alpha: f64) -> Self {
        let v = 0.5 * alpha * alpha;
        Self::new(mean, [v, v, 0.0])
    }

    /// The slope density.
    pub fn p22(&self, s: DVec2) -> f64 {
        let d = s - self.mean;
        let [a, b, c] = self.inv;
        self.norm * (-0.5 * (a * d.x * d.x + b * d.y * d.y + 2.0 * c * d.x * d.y)).exp()
    }

    /// The projected area A(k) = ∫ P²²(h̃) (k.z − k.x h̃x − k.y h̃y)⁺ dh̃ = E[u⁺] for the Gaussian
    /// u of mean c = k.z − k.xy·mean and variance s² = k.xyᵀ Σ k.xy: s φ(t) + c Φ(t), t = c/s.
    pub fn area(&self, k: DVec3) -> f64 {
        let c = k.z - k.x * self.mean.x - k.y * self.mean.y;
        let [xx, yy, xy] = self.cov;
        let s2 = k.x * k.x * xx + k.y * k.y * yy + 2.0 * k.x * k.y * xy;
        if s2 <= 0.0 {
            return c.max(0.0);
        }
        let s = s2.sqrt();
        let t = c / s;
        s * INV_SQRT_TAU * (-0.5 * t * t).exp() + c * 0.5 * libm::erfc(-t * FRAC_1_SQRT_2)
    }

    /// G1(k) = cos θk / A(k) (eq. 3.3), 0 below the base plane.
    pub fn g1(&self, k: DVec3) -> f64 {
        if k.z <= 0.0 { 0.0 } else { k.z / self.area(k) }
    }

    /// f·cos θo of the mirror microsurface for light from `wi` leaving along `wo`.
    pub fn f_cos(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let h = (wi + wo).normalize();
        let d = self.p22(DVec2::new(-h.x / h.z, -h.y / h.z)) / (h.z * h.z * h.z * h.z);
        d * self.g1(wi) * self.g1(wo) / (4.0 * wi.z)
    }

    /// The slope-space integrand of the directional albedo for light from `wi`: f·cos θo times
    /// the Jacobian |dωo/dh̃| = 4 (ωi·ωh) cos³θh of the mirror map h̃ ↦ ωo, i.e.
    /// P²²(h̃) G1(ωi) G1(ωo) (ωi·ωh)/(cos θi cos θh), for the given G1(ωi).
    fn albedo_density(&self, g1_wi: f64, wi: DVec3, slope: DVec2, h: DVec3, wo: DVec3, cos_ih: f64) -> f64 {
        self.p22(slope) * g1_wi * self.g1(wo) * cos_ih / (wi.z * h.z)
    }

    /// The box (min, max corners) holding `BOX_SIGMAS` standard deviations of the slopes.
    fn slope_box(&self) -> (DVec2, DVec2) {
        let half = DVec2::new(self.cov[0].sqrt(), self.cov[1].sqrt()) * BOX_SIGMAS;
        (self.mean - half, self.mean + half)
    }

    /// The smallest standard deviation of the slopes along any direction.
    fn min_sigma(&self) -> f64 {
        let [xx, yy, xy] = self.cov;
        let (m, r) = (0.5 * (xx + yy), (0.5 * (xx - yy)).hypot(xy));
        (m - r).max(0.0).sqrt()
    }
}

/// The error of a filtered lobe against the supersampled ground truth for light from `wi`.
#[derive(Debug, Clone, Copy)]
pub struct FilterError {
    /// ∫ |f_filtered − f_reference| cos θo dωo / ∫ f_reference cos θo dωo.
    pub relative_l1: f64,
    /// ∫ f_reference cos θo dωo, the reference's directional albedo.
    pub albedo: f64,
    /// Quadrature nodes per axis.
    pub nodes: usize,
}

/// The relative L1 error over outgoing directions of `filtered` against the average of the
/// `reference` lobes' BRDFs, for light from `wi` ([`filter_errors`] for one candidate).
pub fn filter_error(wi: DVec3, reference: &[Lobe], filtered: &Lobe, refine: f64) -> FilterError {
    filter_errors(wi, reference, &[*filtered], refine)[0]
}

/// The relative L1 errors over outgoing directions of each candidate lobe against the average
/// of the `reference` lobes' BRDFs, for light from `wi`, by the midpoint rule in the half-vector
/// slope plane (ωo = mirror of ωi about ωh(h̃); the map is one to one onto the ωo with
/// (ωi + ωo).z > 0, which holds for every ωo above the horizon), over a box holding
/// `BOX_SIGMAS` standard deviations of every lobe. `refine` multiplies the node density (1 for
/// the stated default, 2 to check convergence).
pub fn filter_errors(wi: DVec3, reference: &[Lobe], candidates: &[Lobe], refine: f64) -> Vec<FilterError> {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    let mut sigma = f64::INFINITY;
    for l in reference.iter().chain(candidates) {
        let (a, b) = l.slope_box();
        lo = lo.min(a);
        hi = hi.max(b);
        sigma = sigma.min(l.min_sigma());
    }
    let step_wanted = sigma / (NODES_PER_SIGMA * refine);
    let extent = hi - lo;
    let nodes = ((extent.max_element() / step_wanted).ceil() as usize).clamp(16, MAX_NODES);
    let step = extent / nodes as f64;
    let g1_ref: Vec<f64> = reference.iter().map(|l| l.g1(wi)).collect();
    let g1_candidates: Vec<f64> = candidates.iter().map(|l| l.g1(wi)).collect();
    let mut diff = vec![0.0; candidates.len()];
    let mut total = 0.0;
    for j in 0..nodes {
        for i in 0..nodes {
            let slope = lo + (DVec2::new(i as f64, j as f64) + 0.5) * step;
            let h = DVec3::new(-slope.x, -slope.y, 1.0).normalize();
            let cos_ih = wi.dot(h);
            if cos_ih <= 0.0 {
                continue;
            }
            let wo = 2.0 * cos_ih * h - wi;
            if wo.z <= 0.0 {
                continue;
            }
            let reference_value = reference
                .iter()
                .zip(&g1_ref)
                .map(|(l, &g)| l.albedo_density(g, wi, slope, h, wo, cos_ih))
                .sum::<f64>()
                / reference.len() as f64;
            for ((d, c), &g) in diff.iter_mut().zip(candidates).zip(&g1_candidates) {
                *d += (c.albedo_density(g, wi, slope, h, wo, cos_ih) - reference_value).abs();
            }
            total += reference_value;
        }
    }
    let cell = step.x * step.y;
    diff.iter().map(|d| FilterError { relative_l1: d / total, albedo: total * cell, nodes }).collect()
}
