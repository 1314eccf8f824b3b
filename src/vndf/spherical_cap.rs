//! GGX visible normals by the spherical-cap method (Dupuy and Benyoub 2023, “Sampling
//! Visible GGX Normals with Spherical Caps”), exact on the whole sphere of incident directions.

use super::VisibleNormalSampler;
use crate::contract::{are_uniform, is_direction};
use crate::slope::{Ggx, MicrosurfaceSlope};
use glam::Vec3;

/// GGX visible normals by the spherical-cap method (Dupuy and Benyoub 2023): ωm is the
/// normalized sum of the stretched ωi and a point uniform on the cap z > −ωi.z. Exact on the
/// whole sphere; the same routine as [`SmithVndf`](super::SmithVndf)`<Ggx>`, named for
/// comparisons.
///
/// # Examples
/// ```
/// use microsurface::Ggx;
/// use microsurface::vndf::{GgxSphericalCap, VisibleNormalSampler};
/// use microsurface::glam::Vec3;
/// let sampler = GgxSphericalCap(Ggx::isotropic(0.3)?);
/// let wi = Vec3::new(0.6, 0.0, 0.8);
/// let wm = sampler.sample(wi, [0.3, 0.7, 0.0]);
/// assert!(wm.z >= 0.0 && wi.dot(wm) > 0.0 && sampler.pdf(wi, wm) > 0.0);
/// # Ok::<(), microsurface::Error>(())
/// ```
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
