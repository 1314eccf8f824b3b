//! The local shading frame.

use crate::frame::orthonormal_basis;
use glam::Vec3;

/// An orthonormal frame (t, b, n) built from a shading normal n, to move directions between
/// world space and the local frame the BSDFs work in (z = n).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingFrame {
    t: Vec3,
    b: Vec3,
    n: Vec3,
}

impl ShadingFrame {
    /// The frame of the normal `n` (normalized here), built branch-free (Duff et al. 2017).
    /// `None` if `n` is zero, NaN or infinite.
    pub fn from_normal(n: Vec3) -> Option<Self> {
        let n = n.try_normalize()?;
        let (t, b) = orthonormal_basis(n);
        Some(Self { t, b, n })
    }

    /// The normal.
    #[inline]
    pub fn normal(&self) -> Vec3 {
        self.n
    }

    /// A world-space vector in local coordinates.
    #[inline]
    pub fn to_local(&self, w: Vec3) -> Vec3 {
        Vec3::new(w.dot(self.t), w.dot(self.b), w.dot(self.n))
    }

    /// A local vector in world space.
    #[inline]
    pub fn to_world(&self, w: Vec3) -> Vec3 {
        w.x * self.t + w.y * self.b + w.z * self.n
    }
}
