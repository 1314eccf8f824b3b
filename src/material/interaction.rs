//! One scattering event at a microfacet: the direction pair, their sides and what is known
//! about them.

use super::Side;
use crate::contract::is_direction;
use glam::Vec3;

/// Whether an event keeps the side of the interface (a reflection) or crosses it (a
/// transmission through a dielectric).
///
/// # Examples
/// ```
/// use microsurface::research::{Event, Interaction, Side};
/// use microsurface::glam::Vec3;
///
/// let (wi, wo) = (Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.6, 0.0, -0.8));
/// assert_eq!(Interaction::new(wi, wo, Side::Outside, Side::Inside).event(), Event::Transmission);
/// assert_eq!(Interaction::new(wi, -wo, Side::Outside, Side::Outside).event(), Event::Reflection);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Event {
    /// ωi and ωo lie on the same side.
    Reflection,
    /// ωi and ωo lie on opposite sides.
    Transmission,
}

/// The arguments of a [`Material`](crate::research::Material) evaluation: the incident direction ωi,
/// the outgoing direction ωo (both pointing away from the scattering point, ωi towards where
/// light comes from) and the side of the interface each lies on.
///
/// Inside a dielectric the configuration is evaluated flipped (supplement §3.4). The crate's
/// random walk also stores the projected area A(ωi) it already knows from the height step
/// (Λ(−ωi) of the arriving ray gives A(ωi) = Λ(−ωi)·(−cos θi), Heitz et al. 2016, supplement
/// §2.2, for a backfacing ωi too), so that a phase-function evaluation does not compute it
/// again; an interaction built with [`Interaction::new`] carries none and the material
/// computes it.
///
/// # Examples
/// ```
/// use microsurface::{Conductor, Ggx};
/// use microsurface::research::{Interaction, Material, Side};
/// use microsurface::glam::Vec3;
/// use microsurface::rand::SeedableRng;
///
/// let slope = Ggx::isotropic(0.5).unwrap();
/// let (wi, wo) = (Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.6, 0.0, 0.8));
/// let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
/// let reflection = Interaction::reflection(wi, wo);
/// assert_eq!(reflection, Interaction::new(wi, wo, Side::Outside, Side::Outside));
/// let p = Conductor::perfect().eval_phase(&slope, &reflection, &mut rng);
/// assert!(p.x > 0.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interaction {
    wi: Vec3,
    wo: Vec3,
    wi_side: Side,
    wo_side: Side,
    /// A(ωi) in the frame of ωi's side, where the caller knows it (a normal f32, to a few ulps).
    incident_area: Option<f32>,
}

impl Interaction {
    /// The event ωi → ωo with ωi on `wi_side` and ωo on `wo_side`. The directions are
    /// checked by the [`Material`](crate::research::Material) methods, not here.
    #[inline]
    #[must_use]
    pub fn new(wi: Vec3, wo: Vec3, wi_side: Side, wo_side: Side) -> Self {
        Self { wi, wo, wi_side, wo_side, incident_area: None }
    }

    /// A reflection on the outside: [`Interaction::new`] with both sides [`Side::Outside`]
    /// (every event of an opaque material).
    #[inline]
    #[must_use]
    pub fn reflection(wi: Vec3, wo: Vec3) -> Self {
        Self::new(wi, wo, Side::Outside, Side::Outside)
    }

    /// The incident direction ωi.
    #[inline]
    #[must_use]
    pub fn wi(&self) -> Vec3 {
        self.wi
    }

    /// The outgoing direction ωo.
    #[inline]
    #[must_use]
    pub fn wo(&self) -> Vec3 {
        self.wo
    }

    /// The side of ωi.
    #[inline]
    #[must_use]
    pub fn wi_side(&self) -> Side {
        self.wi_side
    }

    /// The side of ωo.
    #[inline]
    #[must_use]
    pub fn wo_side(&self) -> Side {
        self.wo_side
    }

    /// Whether the event keeps or crosses the side.
    #[inline]
    #[must_use]
    pub fn event(&self) -> Event {
        if self.wi_side == self.wo_side { Event::Reflection } else { Event::Transmission }
    }

    /// Whether both directions are outside: the only interaction of an opaque material.
    #[inline(always)]
    pub(crate) fn is_outside_reflection(&self) -> bool {
        self.wi_side == Side::Outside && self.wo_side == Side::Outside
    }

    /// The reverse event ωo → ωi (as the bidirectional estimator needs for its reverse
    /// densities).
    #[inline]
    #[must_use]
    pub fn reversed(&self) -> Self {
        Self::new(self.wo, self.wi, self.wo_side, self.wi_side)
    }

    /// The same event with the projected area A(ωi) in the frame of ωi's side known to be
    /// `area` (a normal f32, on either side of that frame's horizon). Set by the crate's walk
    /// only.
    #[inline(always)]
    pub(crate) fn with_incident_area(mut self, area: Option<f32>) -> Self {
        self.incident_area = area;
        self
    }

    /// The known projected area A(ωi) in the frame of ωi's side, if any.
    #[inline(always)]
    pub(crate) fn incident_area(&self) -> Option<f32> {
        self.incident_area
    }

    /// The event seen from ωi's side: unchanged from outside; from inside flipped vertically
    /// (ω ↦ −ω, both sides swapped), so that ωi lies outside. A(ωi) in its side frame is the
    /// same in both views.
    #[inline(always)]
    pub(crate) fn seen_from_outside(&self) -> Self {
        match self.wi_side {
            Side::Outside => *self,
            Side::Inside => Self {
                wi: -self.wi,
                wo: -self.wo,
                wi_side: Side::Outside,
                wo_side: self.wo_side.flipped(),
                incident_area: self.incident_area,
            },
        }
    }

    /// Whether both directions are unit ([`crate::DIRECTION_TOLERANCE`]).
    #[inline(always)]
    pub(crate) fn has_unit_directions(&self) -> bool {
        is_direction(self.wi) && is_direction(self.wo)
    }
}
