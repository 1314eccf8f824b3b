//! The path-tracing estimator (Wang et al. 2022, §4.1, eqs. 24–26).

use super::{PositionFree, ROULETTE_FROM_BOUNCE, Roulette};
use crate::contract::is_direction;
use crate::material::Material;
use crate::microsurface::ScatteringOrder;
use crate::path::{Incident, PathModel};
use crate::path::{VertexRole, inv_g1};
use crate::rng::uniform;
use crate::slope::MicrosurfaceSlope;
use glam::{DVec3, Vec3};
use rand::Rng;

impl<S: MicrosurfaceSlope, M: Material> PositionFree<S, M> {
    /// Evaluates f·|cos θo| by path tracing with next-event estimation towards ωo at every
    /// vertex (Wang et al. 2022, eqs. 24–26). Unbiased and stochastic.
    ///
    /// A path is extended by sampling the phase function (exact full-spherical VNDF
    /// sampling): the vertex term and the sampling density cancel up to w/G1(ωin), so the
    /// throughput of a bounce is w·S_middle/G1(ωin) (w: the sample weight). Russian roulette
    /// from the fourth vertex on, with survival probability min(1, T·max(1, Φ)), T the
    /// throughput and Φ the next vertex's masking G1 capped at a multiple of its phase
    /// function's peak relative to this path's single-scattering term, keeps it unbiased and
    /// of finite variance and ends the paths lit from below a smooth surface (see
    /// `Roulette::survival`); the throughput is carried in f64. `order` selects all orders (no
    /// truncation; [`crate::research::MAX_BOUNCES`] is only a guard), exactly the n-th, or the first n.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    pub fn eval_pt(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut impl Rng) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        self.eval_pt_counted(wi, wo, order, rng).0
    }

    /// [`Self::eval_pt`] for validated directions, with the number of path extensions (sampled
    /// directions) it made.
    #[inline(always)]
    pub(crate) fn eval_pt_counted(
        &self,
        wi: Vec3,
        wo: Vec3,
        order: ScatteringOrder,
        rng: &mut impl Rng,
    ) -> (Vec3, u32) {
        let (Some(mut at), Some(wo_side)) =
            (PathModel::<S, M>::incident(wi), PathModel::<S, M>::exit_side(wo))
        else {
            return (Vec3::ZERO, 0);
        };
        let mut extensions = 0;
        let last = order.last();
        // the exit data of ωo (constant) and 1 + L̃ of the current incident direction: one Λ
        // per bounce
        let to_wo = self.model.exit(wo, wo_side);
        let mut k_in = inv_g1(&self.model.slope, at.in_frame());
        let mut throughput = DVec3::ONE;
        let mut sum = DVec3::ZERO;
        // the reference is the single-scattering term, set at the first vertex where it is evaluated
        let mut roulette =
            if order.includes(1) { Roulette::UNSET } else { Roulette::new(self, at, k_in, None) };
        for bounce in 1..=last {
            if order.includes(bounce) {
                let contribution = self.model.connect_known(at, k_in, to_wo, VertexRole::Last, rng);
                if bounce == 1 {
                    // the single-scattering term is the roulette's reference
                    roulette.set_reference(self, at, k_in, contribution);
                }
                sum += throughput * contribution;
            }
            if bounce == last {
                break;
            }
            match self.extend_known(at, k_in, rng) {
                Some((next, k_next, ratio)) => {
                    extensions += 1;
                    throughput *= ratio;
                    (at, k_in) = (next, k_next);
                }
                None => break,
            }
            if throughput == DVec3::ZERO {
                break;
            }
            if bounce >= ROULETTE_FROM_BOUNCE {
                let q = roulette.survival(self, throughput, at, k_in);
                if f64::from(uniform(rng)) >= q {
                    break;
                }
                throughput /= q;
            }
        }
        (sum.as_vec3(), extensions)
    }

    /// Samples the next direction from the incident state `at` (with 1 + L̃ = `k_in`) and
    /// returns the next incident state, its 1 + L̃ and the throughput ratio
    /// w·S_middle/G1(ωin) = w·k_in·S_middle. Λ of the sampled direction serves both this
    /// vertex's continuing factor and the next incident masking (Λ(−ω) = −1 − Λ(ω)), so a
    /// bounce evaluates Λ once.
    #[inline]
    pub(crate) fn extend_known(
        &self,
        at: Incident,
        k_in: f64,
        rng: &mut impl Rng,
    ) -> Option<(Incident, f64, DVec3)> {
        if !k_in.is_finite() || self.model.sees_nothing(at, k_in) {
            return None;
        }
        let s = self.model.material.sample_phase_unchecked(&self.model.slope, at.w, at.side, rng);
        let out = self.model.exit(s.wo, s.side);
        // k_in·S_middle, exact also where k_in underflows (a backfacing low-roughness vertex)
        let middle = self.model.relative_shadowing(at, k_in, out).middle;
        // the next incident direction −ω: below the horizon in its frame where ω can exit, and
        // then 1 + L̃ = Λ(ω)
        let k_next = match out.lambda {
            Some(lambda) => lambda,
            None => inv_g1(&self.model.slope, -s.side.frame(s.wo)),
        };
        let next = Incident { w: -s.wo, side: s.side };
        Some((next, k_next, s.weight.as_dvec3() * middle))
    }
}
