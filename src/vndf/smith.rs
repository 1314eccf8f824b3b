//! Samplers of the Smith distribution of visible normals D_ωi.

use super::VisibleNormalSampler;
use super::disk::{half_space_band, sample_band};
use crate::contract::{are_uniform, is_direction};
use crate::rng::cut_tails64;
use crate::slope::{Beckmann, Ggx, MicrosurfaceSlope, ensure_visible, gaussian_slope, normal_from_slopes};
use crate::special::{erf64, erfinv64};
use glam::Vec3;

/// 1/√π.
const INV_SQRT_PI: f64 = 0.564_189_583_547_756_3;
/// Newton steps of [`BeckmannNewton`] stop once a step is below this (in the erf domain).
const ERF_NEWTON_TOLERANCE: f64 = 1e-7;
/// At most this many Newton steps in [`BeckmannNewton`].
const ERF_NEWTON_MAX_STEPS: usize = 8;

/// The crate's default exact sampler of D_ωi for any slope distribution: the slope's own
/// [`MicrosurfaceSlope::sample_d_wi`] (spherical caps for GGX, safeguarded log-space Newton
/// for Beckmann), with density [`MicrosurfaceSlope::d_wi`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmithVndf<S>(pub S);

impl<S: MicrosurfaceSlope> VisibleNormalSampler for SmithVndf<S> {
    #[inline]
    fn sample(&self, wi: Vec3, u: [f32; 3]) -> Vec3 {
        require!(is_direction(wi) && are_uniform(&u), Vec3::NAN; wi, u);
        self.0.sample_d_wi(wi, u[0], u[1])
    }

    #[inline]
    fn pdf(&self, wi: Vec3, wm: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wm), 0.0; wi, wm);
        self.0.d_wi(wi, wm)
    }
}

/// GGX visible normals by the spherical-cap method (Dupuy and Benyoub 2023): ωm is the
/// normalized sum of the stretched ωi and a point uniform on the cap z > −ωi.z. Exact on the
/// whole sphere; the same routine as [`SmithVndf`]`<Ggx>`, named for comparisons.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GgxSphericalCap(pub Ggx);

impl VisibleNormalSampler for GgxSphericalCap {
    #[inline]
    fn sample(&self, wi: Vec3, u: [f32; 3]) -> Vec3 {
        require!(is_direction(wi) && are_uniform(&u), Vec3::NAN; wi, u);
        self.0.sample_d_wi(wi, u[0], u[1])
    }

    #[inline]
    fn pdf(&self, wi: Vec3, wm: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wm), 0.0; wi, wm);
        self.0.d_wi(wi, wm)
    }
}

/// GGX visible normals by Heitz's (2018) disk method (“Sampling the GGX Distribution of
/// Visible Normals”, JCGT 7(4)): a uniform point of the disk orthogonal to the stretched ωi,
/// warped onto the projection of the visible hemisphere and lifted onto it.
///
/// The visible part of the hemisphere m.z ≥ 0 is the band t2 ≥ −v.z ρ of the disk (v the
/// stretched ωi), which also holds for v.z < 0: the method is exact on the whole sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GgxDisk(pub Ggx);

impl VisibleNormalSampler for GgxDisk {
    #[inline]
    fn sample(&self, wi: Vec3, u: [f32; 3]) -> Vec3 {
        require!(is_direction(wi) && are_uniform(&u), Vec3::NAN; wi, u);
        let (ax, ay) = (self.0.alpha_x(), self.0.alpha_y());
        let v = Vec3::new(ax * wi.x, ay * wi.y, wi.z).normalize_or(Vec3::Z);
        let len_xy = (v.x * v.x + v.y * v.y).sqrt();
        // T2 in the plane of v and z, orthogonal to v, pointing up; T1 horizontal
        let (t1_axis, t2_axis) = if len_xy > 0.0 {
            let t1 = Vec3::new(-v.y / len_xy, v.x / len_xy, 0.0);
            (t1, v.cross(t1))
        } else {
            (Vec3::Y, Vec3::X * v.z.signum())
        };
        let (lo, hi) = half_space_band(t2_axis.z, v.z, true);
        let p = sample_band(u[0], u[1], lo, hi);
        let mut h = p.t1 * t1_axis + p.t2 * t2_axis + p.t3 * v;
        // h.z = T2.z t2 + v.z t3 vanishes on the band's lower edge (lo = −v.z, T2.z² + v.z² = 1),
        // where its two terms cancel: near the rim (u[0] = 1 − 2⁻²⁴) rounding would put the
        // normal on the horizon (density 0). Exactly, h.z = (t2 − lo ρ)(T2.z t3 − v.z t2 + ρ) /
        // (t3 + ρ T2.z), a product of non-negative factors
        let denom = p.t3 + p.rho * t2_axis.z;
        if denom > 0.0 {
            h.z = p.above_lo * (t2_axis.z * p.t3 - v.z * p.t2 + p.rho) / denom;
        }
        ensure_visible(wi, Vec3::new(ax * h.x, ay * h.y, h.z.max(0.0)).normalize_or(Vec3::Z))
    }

    #[inline]
    fn pdf(&self, wi: Vec3, wm: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wm), 0.0; wi, wm);
        self.0.d_wi(wi, wm)
    }
}

/// Beckmann visible normals by Newton's method on the visible-slope CDF in the erf domain,
/// without a bisection safeguard (Jakob 2014, as simplified in Mitsuba 2 and Tokuyoshi's
/// listing 6), started from Mitsuba 2's initial guess and iterated to convergence (at most
/// eight steps) rather than a fixed three.
///
/// For incident directions above the horizon only: the erf domain loses the tail's precision
/// below it, where this sampler defers to the exact safeguarded one ([`SmithVndf`]). Its
/// accuracy above the horizon is measured by the chi-square tests in `tests/vndf_samplers.rs`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeckmannNewton(pub Beckmann);

impl VisibleNormalSampler for BeckmannNewton {
    fn sample(&self, wi: Vec3, u: [f32; 3]) -> Vec3 {
        require!(is_direction(wi) && are_uniform(&u), Vec3::NAN; wi, u);
        let (ax, ay) = (self.0.alpha_x(), self.0.alpha_y());
        let v = Vec3::new(ax * wi.x, ay * wi.y, wi.z).normalize_or(Vec3::Z);
        if v.z <= 0.0 {
            return self.0.sample_d_wi(wi, u[0], u[1]);
        }
        let sin_theta = (v.x * v.x + v.y * v.y).sqrt();
        let (cos_phi, sin_phi) =
            if sin_theta > 0.0 { (v.x / sin_theta, v.y / sin_theta) } else { (1.0, 0.0) };
        let x = erf_domain_slope(f64::from(sin_theta) / f64::from(v.z), f64::from(u[0])) as f32;
        let y = gaussian_slope(f64::from(u[1])) as f32;
        normal_from_slopes(ax * (cos_phi * x - sin_phi * y), ay * (sin_phi * x + cos_phi * y))
    }

    #[inline]
    fn pdf(&self, wi: Vec3, wm: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wm), 0.0; wi, wm);
        self.0.d_wi(wi, wm)
    }
}

/// The visible slope x̃ < cot θ at α = 1 for tan θ ≥ 0: Newton on
/// C(e) = e + tan θ exp(−x̃²)/√π (e = erf x̃), whose value runs from −1 to C(erf(cot θ)); u is
/// cut to [2⁻²⁴, 1 − 2⁻²⁴] (the crate's tail policy).
fn erf_domain_slope(tan_theta: f64, u: f64) -> f64 {
    if tan_theta == 0.0 {
        return gaussian_slope(u);
    }
    let slope_max = 1.0 / tan_theta;
    let e_max = erf64(slope_max);
    let c_max = e_max + INV_SQRT_PI * tan_theta * (-slope_max * slope_max).exp();
    // u = 0 would put e on −1 (slope −∞): both tails are cut at 2⁻²⁴ (the crate's tail policy)
    let u = cut_tails64(u);
    let target = u * (c_max + 1.0) - 1.0;
    let mut e = e_max - (1.0 + e_max) * erf64((-u.ln()).sqrt());
    for _ in 0..ERF_NEWTON_MAX_STEPS {
        let x = erfinv64(e);
        let value = e + INV_SQRT_PI * tan_theta * (-x * x).exp() - target;
        let derivative = 1.0 - tan_theta * x;
        let step = value / derivative;
        e = (e - step).clamp(-1.0, e_max);
        if step.abs() < ERF_NEWTON_TOLERANCE {
            break;
        }
    }
    erfinv64(e.max(-1.0 + f64::EPSILON)).min(slope_max)
}
