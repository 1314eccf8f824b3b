//! The generic exact sampler of the Smith distribution of visible normals D_ωi.

use super::VisibleNormalSampler;
use crate::contract::{are_uniform, is_direction};
use crate::slope::MicrosurfaceSlope;
use glam::Vec3;

/// The crate's default exact sampler of D_ωi for any slope distribution: the slope's own
/// [`MicrosurfaceSlope::sample_d_wi`] (spherical caps for GGX, the safeguarded Halley inversion of the log-CDF
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
