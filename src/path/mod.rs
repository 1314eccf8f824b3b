//! The position-free path model of Wang, Jin, Fan, Yang, Holzschuch and Yan 2022
//! (“Position-free Multiple-bounce Computations for Smith Microfacet BSDFs”, §3): a light path
//! inside the microsurface is a sequence of directions, every vertex has the same statistics,
//! and the path contribution is a product of vertex terms (the local BSDF of one bounce
//! without shadowing, [`Material::vertex`]) and shadowing factors ([`Shadowing`]).
//!
//! This layer holds the vertex machinery and the one-vertex path, which is the
//! single-scattering BSDF with full-spherical masking (`single_scattering` is built on
//! it); the multiple-bounce estimators (PT, BDPT) are the `position_free` module's.

mod shadowing;

pub use shadowing::Shadowing;
pub(crate) use shadowing::{LAMBDA_SATURATION, VertexRole, VertexShadowing, inv_g1};

use crate::material::{Event, Interaction, Material, Side};
use crate::slope::MicrosurfaceSlope;
use core::f32::consts::FRAC_1_PI;
use glam::{DVec3, Vec3};
use rand::Rng;

/// Below this incident 1 + L̃ (a backfacing Λ(−ωin) near f64 underflow) the masking ratio
/// Λo/k_in of a correlated reflection is formed from logarithms.
pub(crate) const LAMBDA_RATIO_LOG_BELOW: f64 = 1e-290;
/// Share of the cosine lobe in the approximate MIS density [`PathModel::mis_pdf`].
pub(crate) const PDF_COSINE_SHARE: f32 = 0.2;

/// The position-free model of a slope distribution `S`, a material `M` and a [`Shadowing`]
/// model: the vertex terms and shadowing factors every position-free path is built from. No
/// argument checks: the public types built on it (`SingleScattering`, `PositionFree`) check at
/// their entry points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PathModel<S, M> {
    pub(crate) slope: S,
    pub(crate) material: M,
    pub(crate) shadowing: Shadowing,
}

/// An outgoing direction of a vertex with what its shadowing factors need.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Exit {
    /// The direction.
    pub(crate) w: Vec3,
    /// Its side of the interface.
    pub(crate) side: Side,
    /// Λ in its side frame where it can leave the surface (points up there); `None` where it
    /// cannot.
    pub(crate) lambda: Option<f64>,
}

/// The incident state at a vertex: the direction towards the previous vertex and its side.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Incident {
    pub(crate) w: Vec3,
    pub(crate) side: Side,
}

impl Incident {
    /// The incident direction in the frame of its side.
    #[inline(always)]
    pub(crate) fn in_frame(self) -> Vec3 {
        self.side.frame(self.w)
    }

    /// The event from this incident direction to `w` on `side`.
    #[inline(always)]
    pub(crate) fn to(self, w: Vec3, side: Side) -> Interaction {
        Interaction::new(self.w, w, self.side, side)
    }

    /// The event from this incident direction to the outgoing one.
    #[inline(always)]
    pub(crate) fn towards(self, out: Exit) -> Interaction {
        self.to(out.w, out.side)
    }
}

impl<S: MicrosurfaceSlope, M: Material> PathModel<S, M> {
    /// The model of the given slope distribution, material and shadowing.
    #[inline]
    pub(crate) fn new(slope: S, material: M, shadowing: Shadowing) -> Self {
        Self { slope, material, shadowing }
    }

    /// The single-bounce term v(ωi, ωo)·S_last (the path of one vertex) for unit directions:
    /// the microfacet BSDF times |cos θo| with this model's masking-shadowing — G1(ωi)G1(ωo)
    /// uncorrelated, 1/(1 + Λ(ωi) + Λ(ωo)) or B(1 + Λ(ωi), 1 + Λ(−ωo)) correlated. Exact,
    /// except for diffuse facets (unbiased estimate).
    #[inline]
    pub(crate) fn eval_single_scattering(&self, wi: Vec3, wo: Vec3, rng: &mut impl Rng) -> Vec3 {
        let (Some(start), Some(wo_side)) = (Self::incident(wi), Self::exit_side(wo)) else {
            return Vec3::ZERO;
        };
        self.connect(start, wo, wo_side, VertexRole::Last, rng).as_vec3()
    }

    /// The approximate density of a multiple-bounce sample, for multiple importance sampling
    /// in a renderer: 0.8 × the single-bounce sampling density of ωo plus 0.2 × a cosine lobe
    /// on ωo's side (divided between both sides for a dielectric), for unit directions. Like
    /// the papers' `pdf()`, it is **not** the density of what the walks draw (which has no
    /// closed form); their weights never use it.
    #[inline]
    pub(crate) fn mis_pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        let (Some(start), Some(wo_side)) = (Self::incident(wi), Self::exit_side(wo)) else {
            return 0.0;
        };
        let single = self.material.pdf_phase_unchecked(&self.slope, &start.to(wo, wo_side));
        let sides = if M::TRANSMITS { 2.0 } else { 1.0 };
        (1.0 - PDF_COSINE_SHARE) * single + PDF_COSINE_SHARE * FRAC_1_PI * wo.z.abs() / sides
    }

    /// The incident state for the macro direction ωi, or `None` on the horizon.
    ///
    /// A dielectric lit from below is lit from inside. An opaque material lit from below the
    /// macrosurface (a backfacing view under a normal map: Tokuyoshi; Wang et al. 2022 §3.5)
    /// keeps the outside state: its first vertex is then exactly a vertex reached from below,
    /// which the path integral already contains after any upward bounce (Wang et al. 2022,
    /// Fig. 5): incident masking G1(ωi) = 1/|1 + Λ(ωi)| = 1/Λ(−ωi) (eq. 10), the VNDF D_ωi on
    /// the whole sphere, and the shadowing factors of eqs. 17–18 with 1 + L̃ = Λ(−ωi). Every
    /// exit of an opaque path is upwards. See DESIGN.md, “Paths from below”.
    #[inline(always)]
    pub(crate) fn incident(wi: Vec3) -> Option<Incident> {
        let side = Side::of(wi.z)?;
        Some(Incident { w: wi, side: if M::TRANSMITS { side } else { Side::Outside } })
    }

    /// The side of the macro direction ωo, or `None` if light cannot leave there.
    #[inline(always)]
    pub(crate) fn exit_side(wo: Vec3) -> Option<Side> {
        Side::of(wo.z).filter(|&side| M::TRANSMITS || side == Side::Outside)
    }

    /// 1 + L̃ of the incident state `at` (the inverse full-spherical masking, `inv_g1`, in its
    /// side frame).
    #[inline(always)]
    pub(crate) fn incident_k(&self, at: Incident) -> f64 {
        inv_g1(&self.slope, at.in_frame())
    }

    /// The forward contribution of one vertex in the given role, v(ωin, ωout)·S (S the
    /// last-vertex or the continuing factor).
    #[inline]
    pub(crate) fn connect(
        &self,
        at: Incident,
        wo: Vec3,
        wo_side: Side,
        role: VertexRole,
        rng: &mut impl Rng,
    ) -> DVec3 {
        let k_in = inv_g1(&self.slope, at.in_frame());
        self.connect_known(at, k_in, self.exit(wo, wo_side), role, rng)
    }

    /// [`Self::connect`] with the incident 1 + L̃ = `k_in` and the outgoing direction's exit
    /// data already known.
    #[inline(always)]
    pub(crate) fn connect_known(
        &self,
        at: Incident,
        k_in: f64,
        out: Exit,
        role: VertexRole,
        rng: &mut impl Rng,
    ) -> DVec3 {
        if k_in < 1.0 {
            // a backfacing incident direction (below the horizon in its side frame): v·S =
            // p·(k_in S), with the phase function p and the relative factor both free of the
            // tiny k_in = Λ(−ωin), which v = p·k_in and S ∝ 1/k_in would underflow and overflow
            let factor = self.relative_shadowing(at, k_in, out).factor(role);
            if factor == 0.0 {
                return DVec3::ZERO;
            }
            let phase = self.material.eval_phase_unchecked(&self.slope, &at.towards(out), rng);
            return phase.as_dvec3() * factor;
        }
        let factor = self.shadowing_factor(at, k_in, out, role);
        if factor == 0.0 {
            return DVec3::ZERO;
        }
        self.material.vertex_unchecked(&self.slope, &at.towards(out), rng).as_dvec3() * factor
    }

    /// The shadowing factors of a vertex relative to its incident masking, k_in·S
    /// ([`Shadowing::relative`]), with the ratio Λo/k_in of a correlated reflection formed as
    /// exp(ln Λo − ln k_in) ([`MicrosurfaceSlope::ln_lambda`]) where k_in is below
    /// `LAMBDA_RATIO_LOG_BELOW` (only backfacing incident directions of low-roughness
    /// Beckmann surfaces): exact to a few f64 ulps down to the smallest α.
    #[inline(always)]
    pub(crate) fn relative_shadowing(&self, at: Incident, k_in: f64, out: Exit) -> VertexShadowing {
        let event = if at.side == out.side { Event::Reflection } else { Event::Transmission };
        let ratio = match out.lambda {
            Some(lambda) if event == Event::Reflection && self.shadowing == Shadowing::Correlated => {
                if k_in >= LAMBDA_RATIO_LOG_BELOW {
                    lambda / k_in
                } else {
                    // k_in = Λ(−ωin) of a backfacing incident direction, in its side frame
                    let ln_k = self.slope.ln_lambda(-at.in_frame());
                    if ln_k == f64::NEG_INFINITY {
                        f64::INFINITY
                    } else {
                        (self.slope.ln_lambda(out.side.frame(out.w)) - ln_k).exp()
                    }
                }
            }
            _ => 0.0,
        };
        self.shadowing.relative(k_in, out.lambda, ratio, event)
    }

    /// The exit data of an outgoing direction: whether it points up in its side frame (can
    /// leave the surface) and then its Λ there (0 otherwise).
    #[inline]
    pub(crate) fn exit(&self, w: Vec3, side: Side) -> Exit {
        let frame = side.frame(w);
        let lambda = (frame.z > 0.0).then(|| self.slope.lambda64(frame).min(LAMBDA_SATURATION));
        Exit { w, side, lambda }
    }

    /// The shadowing factor of a vertex in the given role with incident state `at`
    /// (1 + L̃ = `k_in`) and outgoing direction `out`; 0 where `at` sees no microsurface and
    /// where k_in < `LAMBDA_RATIO_LOG_BELOW` (S would overflow: use [`Self::relative_shadowing`]).
    #[inline(always)]
    pub(crate) fn shadowing_factor(&self, at: Incident, k_in: f64, out: Exit, role: VertexRole) -> f64 {
        // S ∝ G1in = 1/k_in overflows for a subnormal f64 k_in; its product with a vertex term
        // (∝ k_in) is formed by `relative_shadowing` instead, where callers need it
        if k_in < LAMBDA_RATIO_LOG_BELOW {
            return 0.0;
        }
        let event = if at.side == out.side { Event::Reflection } else { Event::Transmission };
        self.shadowing.vertex(k_in, out.lambda, event).factor(role)
    }
}
