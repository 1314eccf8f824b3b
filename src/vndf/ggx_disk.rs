//! GGX visible normals by Heitz's (2018) disk method (“Sampling the GGX Distribution of
//! Visible Normals”, JCGT 7(4)), exact on the whole sphere of incident directions.

use super::VisibleNormalSampler;
use super::disk_band::{half_space_band, sample_band};
use crate::contract::{are_uniform, is_direction};
use crate::slope::{Ggx, MicrosurfaceSlope, disk_frame};
use crate::vector::ensure_visible;
use glam::Vec3;

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
        // T2 in the plane of v and z, orthogonal to v, pointing up; T1 horizontal
        let (t1_axis, t2_axis) = disk_frame(v);
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
