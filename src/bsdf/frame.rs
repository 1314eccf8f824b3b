//! The local shading frame.

use crate::basis::orthonormal_basis;
use glam::Vec3;

/// An orthonormal, right-handed frame (t, b, n) built from a shading normal n (and, for
/// anisotropic materials, a tangent t), to move directions between world space and the local
/// frame the BSDFs work in: x along t, y along b = n × t, z along n. An anisotropic slope's
/// αx is its roughness along t, αy along b.
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
///
/// // brushed metal: the tangent of the mesh orients αx (Gram–Schmidt against the normal)
/// let n = Vec3::new(0.0, 0.0, 1.0);
/// let frame = ShadingFrame::from_normal_tangent(n, Vec3::new(1.0, 1.0, 0.5)).expect("a frame");
/// assert!((frame.tangent() - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-6);
/// assert!((frame.to_local(Vec3::new(1.0, 1.0, 0.0).normalize()) - Vec3::X).length() < 1e-6);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingFrame {
    t: Vec3,
    b: Vec3,
    n: Vec3,
}

/// Below this ‖t − (t·n) n‖² relative to ‖t‖² a tangent is taken as parallel to the normal
/// (an angle below 1e-3 rad, where its direction in the plane is lost to f32 rounding).
const PARALLEL_TANGENT_SQ: f32 = 1e-6;

impl ShadingFrame {
    /// The frame of the normal `n` (normalized here), with a tangent chosen branch-free
    /// (Duff et al. 2017): for isotropic materials, whose BSDF does not depend on it.
    /// `None` if `n` is zero, NaN or infinite.
    #[must_use]
    pub fn from_normal(n: Vec3) -> Option<Self> {
        let n = n.try_normalize()?;
        let (t, b) = orthonormal_basis(n);
        Some(Self { t, b, n })
    }

    /// The frame of the normal `n` and the tangent `t` (neither need be unit): n normalized,
    /// t made orthogonal to it (Gram–Schmidt, t − (t·n) n, normalized) and b = n × t. For
    /// anisotropic materials, whose αx lies along t. A tangent that is zero, not finite or
    /// within 1e-3 rad of the normal's direction cannot orient the frame: the frame of
    /// [`ShadingFrame::from_normal`] is used then (an arbitrary orientation, as without a
    /// tangent). `None` if `n` is zero, NaN or infinite.
    #[must_use]
    pub fn from_normal_tangent(n: Vec3, t: Vec3) -> Option<Self> {
        let n = n.try_normalize()?;
        let along = t - t.dot(n) * n;
        let len_sq = along.length_squared();
        if !(len_sq.is_finite() && len_sq > PARALLEL_TANGENT_SQ * t.length_squared() && len_sq > 0.0) {
            let (t, b) = orthonormal_basis(n);
            return Some(Self { t, b, n });
        }
        // one Gram–Schmidt step leaves |t·n| at a few ulps of |t| relative to the remaining
        // length: a second step makes it f32-orthogonal
        let t = along / len_sq.sqrt();
        let t = (t - t.dot(n) * n).normalize();
        Some(Self { t, b: n.cross(t), n })
    }

    /// The normal.
    #[inline]
    #[must_use]
    pub fn normal(&self) -> Vec3 {
        self.n
    }

    /// The tangent (the local x axis).
    #[inline]
    #[must_use]
    pub fn tangent(&self) -> Vec3 {
        self.t
    }

    /// The bitangent n × t (the local y axis).
    #[inline]
    #[must_use]
    pub fn bitangent(&self) -> Vec3 {
        self.b
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
