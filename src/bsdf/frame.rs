//! The local shading frame.

use crate::basis::orthonormal_basis;
use glam::Vec3;

/// An orthonormal frame (t, b, n) built from a shading normal n, to move directions between
/// world space and the local frame the BSDFs work in (z = n).
///
/// # Examples
///
/// ```
/// use microsurface::ShadingFrame;
/// use microsurface::glam::Vec3;
///
/// let frame = ShadingFrame::from_normal(Vec3::new(0.0, 2.0, 0.0)).expect("a non-zero normal");
/// let to_viewer = Vec3::new(0.6, 0.8, 0.0);
/// let wo = frame.to_local(to_viewer);
/// assert!((wo.z - 0.8).abs() < 1e-6); // z is the cosine with the normal
/// assert!((frame.to_world(wo) - to_viewer).length() < 1e-6);
/// assert!(ShadingFrame::from_normal(Vec3::ZERO).is_none());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingFrame {
    t: Vec3,
    b: Vec3,
    n: Vec3,
}

impl ShadingFrame {
    /// The frame of the normal `n` (normalized here), built branch-free (Duff et al. 2017).
    /// `None` if `n` is zero, NaN or infinite.
    #[must_use]
    pub fn from_normal(n: Vec3) -> Option<Self> {
        let n = n.try_normalize()?;
        let (t, b) = orthonormal_basis(n);
        Some(Self { t, b, n })
    }

    /// The normal.
    #[inline]
    #[must_use]
    pub fn normal(&self) -> Vec3 {
        self.n
    }

    /// A world-space vector in local coordinates.
    #[inline]
    #[must_use]
    pub fn to_local(&self, w: Vec3) -> Vec3 {
        Vec3::new(w.dot(self.t), w.dot(self.b), w.dot(self.n))
    }

    /// A local vector in world space.
    #[inline]
    #[must_use]
    pub fn to_world(&self, w: Vec3) -> Vec3 {
        w.x * self.t + w.y * self.b + w.z * self.n
    }
}
