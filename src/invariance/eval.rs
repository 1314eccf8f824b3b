//! The path-tracing estimator of f·|cos θo| with next-event estimation at every vertex.

use super::depth_law::DepthLaw;
use super::{Invariance, MIN_FIRST_RATE};
use crate::contract::is_direction;
use crate::material::{Interaction, Material, Side};
use crate::microsurface::{ScatteringOrder, incident_area};
use crate::rng::uniform;
use crate::slope::MicrosurfaceSlope;
use glam::{DVec3, Vec3};
use rand::Rng;

/// The hit probability L of an upward segment is carried as a weight to the next-event term
/// of the vertex it reaches; the path then continues past that vertex with probability L
/// (Russian roulette with the walk's own law, the weight divided by L) — except past the
/// first `FORCED_BOUNCES` vertices, where it always continues with L kept in the weight.
pub const FORCED_BOUNCES: u32 = 2;

impl<S: MicrosurfaceSlope, M: Material> Invariance<S, M> {
    /// Estimates f(ωi, ωo)·|cos θo| of the orders `order` (Cui et al. 2023; the estimator of
    /// the [module documentation](super)): unbiased, stochastic, per RGB channel.
    ///
    /// A path draws its directions from the phase function (exact visible-normal sampling)
    /// and adds at every vertex j the next-event term (Π w)·L·p(d_{j−1} → ωo)·Ψ_j(Λ(ωo)),
    /// Ψ_j(Λ(ωo)) the exact probability that ωo leaves vertex j unmasked given the directions
    /// (order 1: the height-correlated single scattering, exactly). Paths end by Russian
    /// roulette with the exact hit probability of their upward segments after
    /// [`FORCED_BOUNCES`]; `order` truncates them (all orders: [`crate::MAX_BOUNCES`] is only
    /// a guard). Precision: the depth law is in f64 with positive terms only (relative error
    /// a few f64 ulps per bounce); Λ in f64.
    ///
    /// 0 for ωi or ωo on the horizon and for ωo below it. ωi below the horizon (a backfacing
    /// view) enters with σ₀ = Λ(−ωi); where that is below [`MIN_FIRST_RATE`] the walk from
    /// below answers ([`crate::Microsurface::eval_from_below`], the same model).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    pub fn eval(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut impl Rng) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        if !(wo.z > 0.0) || wi.z == 0.0 {
            return Vec3::ZERO;
        }
        let slope = &self.slope;
        // σ₀ = |Λ(−ωi)|: 1 + Λ(ωi) from above, Λ(−ωi) from below
        let first_rate = slope.lambda64(-wi).abs();
        if !(first_rate >= MIN_FIRST_RATE) {
            return self.walk().eval_from_below(wi, wo, order, rng);
        }
        let mut law = DepthLaw::new(first_rate, slope.lambda64(wo));
        let last = order.last();
        // the throughput: the phase samples' weights times the hit probability of the
        // segment that reached the current vertex (and of earlier ones, while forced)
        let mut weight = DVec3::ONE;
        // the hit probability carried in `weight` that the roulette has not yet resolved
        let mut pending = 1.0;
        let mut sum = DVec3::ZERO;
        // the incident direction at the current vertex (−d of the segment that reached it)
        // and its projected area where known
        let (mut incident, mut area) = (wi, None);
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
            if pending < 1.0 && bounce > FORCED_BOUNCES {
                // the roulette of the segment that reached this vertex, after its next-event
                // term (which kept the hit probability as a weight: with p ∝ 1/A(−d) it stays
                // bounded, where a sampled hit would give p alone, of unbounded variance)
                if !(f64::from(uniform(rng)) < pending) {
                    break;
                }
                weight /= pending;
            }
            let s = self.material.sample_phase_walk_unchecked(slope, incident, Side::Outside, rng);
            weight *= s.weight.as_dvec3();
            let d = s.wo;
            let lambda = slope.lambda64(d);
            pending = 1.0;
            if d.z < 0.0 {
                law.down(-lambda);
            } else if d.z > 0.0 {
                pending = law.up(lambda);
                weight *= pending;
            }
            // (a horizontal d meets the surface at once, at the same depth: the law is unchanged)
            if weight == DVec3::ZERO {
                break;
            }
            area = incident_area(d.z, lambda as f32);
            incident = -d;
        }
        sum.as_vec3()
    }
}
