//! The path-tracing estimator of f·|cos θo| with next-event estimation at every vertex.

use super::Invariance;
use super::depth_law::DepthLaw;
use crate::contract::is_direction;
use crate::material::{Interaction, Material, Side};
use crate::microsurface::{ScatteringOrder, incident_area};
use crate::rng::uniform;
use crate::slope::MicrosurfaceSlope;
use glam::{DVec3, Vec3};
use rand::Rng;

impl<S: MicrosurfaceSlope, M: Material> Invariance<S, M> {
    /// Estimates f(ωi, ωo)·|cos θo| of the orders `order` (Cui et al. 2023; the estimator of
    /// the derivation on [`Invariance`]): unbiased, stochastic, per RGB channel.
    ///
    /// A path draws its directions from the phase function (exact visible-normal sampling)
    /// and adds at every vertex j the next-event term (Π w)·P·p(d_{j−1} → ωo)·Ψ_j(Λ(ωo)):
    /// w the phase samples' weights (Fresnel), Ψ_j(Λ(ωo)) the exact probability that ωo
    /// leaves vertex j unmasked given the directions (order 1: the height-correlated single
    /// scattering, exactly), and P the exact probability that the segment d_{j−1} hits (1
    /// going down). The path then goes on past vertex j with probability P (Russian roulette
    /// with the walk's own law, the weight divided by P), so that its length is the walk's,
    /// while the next-event term keeps P as a weight: where an upward d_{j−1} barely hits
    /// (Λ → 0) the phase function p ∝ 1/A(−d_{j−1}) = 1/(Λ|cos|) is unbounded but P·p is not,
    /// whereas the walk's next-event term after a sampled hit has unbounded variance there.
    /// `order` truncates the paths (all orders: [`crate::research::MAX_BOUNCES`] is only a guard). Precision: the depth law is in f64 with positive terms only (relative error
    /// a few f64 ulps per bounce); Λ in f64.
    ///
    /// 0 for ωi or ωo on the horizon and for ωo below it. ωi below the horizon (a backfacing
    /// view) enters with σ₀ = Λ(−ωi); where that is below [`MIN_FIRST_RATE`](crate::research::MIN_FIRST_RATE) the walk from
    /// below answers ([`crate::research::Microsurface::eval_from_below`], the same model).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    pub fn eval(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut impl Rng) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        if wo.z <= 0.0 || wi.z == 0.0 {
            return Vec3::ZERO;
        }
        let slope = &self.slope;
        let Some((first_rate, first_area)) = self.entry(wi) else {
            return self.walk().eval_from_below(wi, wo, order, rng);
        };
        let mut law = DepthLaw::new(first_rate, f64::from(slope.lambda_unchecked(wo)));
        let last = order.last();
        // the throughput: the phase samples' weights times the hit probability of the
        // segment that reached the current vertex
        let mut weight = DVec3::ONE;
        // the hit probability carried in `weight` that the roulette has not yet resolved
        let mut pending = 1.0;
        let mut sum = DVec3::ZERO;
        // the incident direction at the current vertex (−d of the segment that reached it)
        // and its projected area where known
        let (mut incident, mut area) = (wi, first_area);
        for bounce in 1..=last {
            if order.includes(bounce) {
                let it = Interaction::reflection(incident, wo).with_incident_area(area);
                let phase = self.material.eval_phase_unchecked(slope, &it, rng);
                if phase != Vec3::ZERO {
                    sum += weight * phase.as_dvec3() * law.escape_at_exit();
                }
            }
            if bounce == last {
                break;
            }
            if pending < 1.0 {
                // the roulette of the segment that reached this vertex, after its next-event
                // term (which kept the hit probability as a weight: with p ∝ 1/A(−d) it stays
                // bounded, where a sampled hit would give p alone, of unbounded variance)
                if f64::from(uniform(rng)) >= pending {
                    break;
                }
                weight /= pending;
            }
            let s = self.material.sample_phase_walk_unchecked(slope, incident, Side::Outside, rng);
            weight *= s.weight.as_dvec3();
            let d = s.wo;
            // Λ in f32 as the walk takes it (relative error a few ulps; a Λ below f32's range
            // ends an upward segment's path, whose hit probability it is)
            let lambda = slope.lambda_unchecked(d);
            pending = 1.0;
            if d.z < 0.0 {
                law.down(-f64::from(lambda));
            } else if d.z > 0.0 {
                pending = law.up(f64::from(lambda));
                weight *= pending;
            }
            // (a horizontal d meets the surface at once, at the same depth: the law is unchanged)
            if weight == DVec3::ZERO {
                break;
            }
            area = incident_area(d.z, lambda);
            incident = -d;
        }
        sum.as_vec3()
    }
}
