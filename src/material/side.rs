//! The two sides of the microsurface interface.

use glam::Vec3;

/// A side of the microsurface interface: the outside medium (above the macrosurface, z > 0)
/// or the inside of a dielectric (Heitz et al. 2016, supplement §3.4).
///
/// Opaque materials are only ever reached from [`Side::Outside`]. Inside a dielectric every
/// configuration is the vertically flipped one (ω ↦ −ω, η ↦ 1/η), so a direction is often
/// needed in the frame of its side ([`Side::frame`]).
///
/// # Examples
/// ```
/// use microsurface::research::Side;
/// use microsurface::glam::Vec3;
///
/// assert_eq!(Side::of(-0.5), Some(Side::Inside));
/// assert_eq!(Side::Inside.frame(Vec3::new(0.0, 0.6, -0.8)), Vec3::new(0.0, -0.6, 0.8));
/// assert_eq!(Side::Outside.flipped(), Side::Inside);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Side {
    /// The medium above the interface, where the light arrives from and leaves to.
    Outside,
    /// The medium below a dielectric interface.
    Inside,
}

impl Side {
    /// The side a macro direction with z-component `z` lies on; `None` on the horizon
    /// (z = ±0) and for NaN.
    #[inline]
    #[must_use]
    pub fn of(z: f32) -> Option<Self> {
        if z > 0.0 {
            Some(Self::Outside)
        } else if z < 0.0 {
            Some(Self::Inside)
        } else {
            None
        }
    }

    /// [`Side::Outside`] for z > 0, [`Side::Inside`] otherwise (the horizon and NaN
    /// included): for callers that have excluded those or treat them as inside.
    #[inline(always)]
    pub(crate) fn above_or_inside(z: f32) -> Self {
        if z > 0.0 { Self::Outside } else { Self::Inside }
    }

    /// The other side.
    #[inline]
    #[must_use]
    pub const fn flipped(self) -> Self {
        match self {
            Self::Outside => Self::Inside,
            Self::Inside => Self::Outside,
        }
    }

    /// `w` in the frame of this side: unchanged outside, mirrored (ω ↦ −ω) inside (Heitz
    /// et al. 2016, supplement §3.4).
    #[inline(always)]
    #[must_use]
    pub fn frame(self, w: Vec3) -> Vec3 {
        match self {
            Self::Outside => w,
            Self::Inside => -w,
        }
    }

    /// Whether this is [`Side::Outside`].
    #[inline(always)]
    #[must_use]
    pub const fn is_outside(self) -> bool {
        matches!(self, Self::Outside)
    }
}
