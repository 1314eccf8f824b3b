//! The relative L1 error of a filtered lobe against the average of the fine texels' BRDFs
//! (the supersampled ground truth), measured on the crate's own lobes: every BRDF value is
//! [`Noncentral::eval_single_scattering`] of the lobe's noncentral slope distribution
//! ([`LeadrLobe::slope`], or any [`SlopeLobe`]: the downsampling operator's tables, GGX texels)
//! with a perfect mirror ([`Conductor::perfect`]), f = D(ωh) G1(ωi) G1(ωo)/(4 cos θi cos θo)
//! (Dupuy 2015, eqs. 3.2–3.3, the separable Torrance–Sparrow form of §2.1).

use glam::{DVec2, DVec3, Vec3};
use microsurface::leadr::{LeadrLobe, Noncentral, SlopeMoments};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Conductor};

/// A lobe of the filtering validation: a noncentral slope distribution shaded as a perfect
/// mirror, with the box of the half-vector slope plane that holds it.
pub trait Lobe {
    /// f·cos θo of the mirror microsurface (F = 1) for light from `wi` leaving along `wo`
    /// ([`Noncentral::eval_single_scattering`]), in f64.
    fn f_cos(&self, wi: Vec3, wo: Vec3) -> f64;
    /// The box (min, max corners) of the slope plane the quadrature covers for this lobe, and
    /// the smallest scale (a standard deviation) the lobe varies on.
    fn support(&self) -> (DVec2, DVec2, f64);
}

impl Lobe for LeadrLobe {
    fn f_cos(&self, wi: Vec3, wo: Vec3) -> f64 {
        mirror_f_cos(&self.slope(), wi, wo)
    }

    fn support(&self) -> (DVec2, DVec2, f64) {
        let (lo, hi) = slope_box(self);
        (lo, hi, min_sigma(self))
    }
}

impl<T: Lobe + ?Sized> Lobe for &T {
    fn f_cos(&self, wi: Vec3, wo: Vec3) -> f64 {
        (**self).f_cos(wi, wo)
    }

    fn support(&self) -> (DVec2, DVec2, f64) {
        (**self).support()
    }
}

/// Any noncentral slope distribution as a [`Lobe`]: the box is the mean slope ± `half_width`,
/// its scale `scale` (for a heavy-tailed GGX lobe, a box of ±15 α holds all but 0.3 % of its
/// slopes along each axis, and the scale is α/√2).
#[derive(Debug, Clone, Copy)]
pub struct SlopeLobe<S> {
    pub surface: Noncentral<S>,
    pub half_width: DVec2,
    pub scale: f64,
}

impl<S: MicrosurfaceSlope> Lobe for SlopeLobe<S> {
    fn f_cos(&self, wi: Vec3, wo: Vec3) -> f64 {
        mirror_f_cos(&self.surface, wi, wo)
    }

    fn support(&self) -> (DVec2, DVec2, f64) {
        let mean = self.surface.mean_slope().as_dvec2();
        (mean - self.half_width, mean + self.half_width, self.scale)
    }
}

/// f·cos θo of a mirror noncentral microsurface ([`Noncentral::eval_single_scattering`] with
/// F = 1, which draws no random number).
fn mirror_f_cos<S: MicrosurfaceSlope>(surface: &Noncentral<S>, wi: Vec3, wo: Vec3) -> f64 {
    let mut unused = rand_pcg::Pcg64Mcg::new(1);
    f64::from(surface.eval_single_scattering(&Conductor::perfect(), wi, wo, &mut unused).x)
}

/// Half-width of the slope-space quadrature box, in standard deviations of each lobe.
const BOX_SIGMAS: f64 = 6.0;
/// Quadrature nodes per standard deviation of the narrowest lobe (midpoint rule; for Gaussian
/// integrands its error is of order exp(−2π² · 2.5²) ≈ 1e-53 relative, the kinks of |g_a − g_r|
/// aside, which converge as h²).
pub const NODES_PER_SIGMA: f64 = 2.5;
/// A cap on the nodes per axis.
const MAX_NODES: usize = 700;

/// The lobe of a texel of mesosurface slope `mean` on an isotropic Beckmann base of roughness
/// `alpha` (the naive filter's lobe): the LEADR lobe of that texel's moments.
pub fn texel_lobe(mean: DVec2, alpha: f32) -> LeadrLobe {
    let base = Beckmann::isotropic(alpha).expect("a valid base roughness");
    LeadrLobe::from_moments(&SlopeMoments::from_slope(mean.as_vec2(), base).expect("a finite slope"))
}

/// f·cos θo of the mirror microsurface of `lobe` for light from `wi` leaving along `wo`
/// ([`Noncentral::eval_single_scattering`] with F = 1), in f64.
pub fn f_cos(lobe: &LeadrLobe, wi: DVec3, wo: DVec3) -> f64 {
    lobe.f_cos(wi.as_vec3(), wo.as_vec3())
}

/// The box (min, max corners) holding `BOX_SIGMAS` standard deviations of the slopes.
fn slope_box(lobe: &LeadrLobe) -> (DVec2, DVec2) {
    let [xx, yy, _] = lobe.covariance().map(f64::from);
    let half = DVec2::new(xx.sqrt(), yy.sqrt()) * BOX_SIGMAS;
    let mean = lobe.mean_slope().as_dvec2();
    (mean - half, mean + half)
}

/// The smallest standard deviation of the slopes along any direction.
fn min_sigma(lobe: &LeadrLobe) -> f64 {
    let [xx, yy, xy] = lobe.covariance().map(f64::from);
    let (m, r) = (0.5 * (xx + yy), (0.5 * (xx - yy)).hypot(xy));
    (m - r).max(0.0).sqrt()
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
pub fn filter_error<R: Lobe, C: Lobe>(wi: DVec3, reference: &[R], filtered: &C, refine: f64) -> FilterError {
    filter_errors(wi, reference, &[filtered], refine)[0]
}

/// The relative L1 errors over outgoing directions of each candidate lobe against the average
/// of the `reference` lobes' BRDFs, for light from `wi`, by the midpoint rule in the half-vector
/// slope plane (ωo = mirror of ωi about ωh(h̃); the map is one to one onto the ωo with
/// (ωi + ωo).z > 0, which holds for every ωo above the horizon), over a box holding
/// `BOX_SIGMAS` standard deviations of every lobe. `refine` multiplies the node density (1 for
/// the stated default, 2 to check convergence).
pub fn filter_errors<R: Lobe, C: Lobe>(
    wi: DVec3,
    reference: &[R],
    candidates: &[C],
    refine: f64,
) -> Vec<FilterError> {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    let mut sigma = f64::INFINITY;
    let supports = reference.iter().map(Lobe::support).chain(candidates.iter().map(Lobe::support));
    for (a, b, scale) in supports {
        lo = lo.min(a);
        hi = hi.max(b);
        sigma = sigma.min(scale);
    }
    let step_wanted = sigma / (NODES_PER_SIGMA * refine);
    let extent = hi - lo;
    let nodes = ((extent.max_element() / step_wanted).ceil() as usize).clamp(16, MAX_NODES);
    let step = extent / nodes as f64;
    let wi32 = wi.as_vec3();
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
            // f·cos θo times the Jacobian |dωo/dh̃| = 4 (ωi·ωh) cos³θh of the mirror map h̃ ↦ ωo
            let jacobian = 4.0 * cos_ih * h.z * h.z * h.z;
            let wo32 = wo.as_vec3();
            let reference_value = reference.iter().map(|l| l.f_cos(wi32, wo32)).sum::<f64>() * jacobian
                / reference.len() as f64;
            for (d, c) in diff.iter_mut().zip(candidates) {
                *d += (c.f_cos(wi32, wo32) * jacobian - reference_value).abs();
            }
            total += reference_value;
        }
    }
    let cell = step.x * step.y;
    diff.iter().map(|d| FilterError { relative_l1: d / total, albedo: total * cell, nodes }).collect()
}
