//! Sampling the exit direction with the depths integrated out.

use super::Invariance;
use super::depth_law::DepthLaw;
use crate::contract::is_direction;
use crate::material::{Material, Side};
use crate::microsurface::{MAX_BOUNCES, WalkSample};
use crate::rng::uniform;
use crate::slope::MicrosurfaceSlope;
use glam::Vec3;
use rand::Rng;

impl<S: MicrosurfaceSlope, M: Material> Invariance<S, M> {
    /// Samples an exit direction of the walk's BRDF (the derivation on [`Invariance`]):
    /// directions from the phase function, and at every upward segment of rate b = Λ(d) an
    /// exit with the exact probability Ψ(b) that the walk's ray escapes given the directions
    /// so far (no height is drawn). The returned direction has the walk's exit density, and
    /// the weight is f·|cos θo|/pdf exactly: the product of the phase samples' weights (the
    /// Fresnel terms; 1 for F = 1).
    ///
    /// `None` if ωi lies on the horizon, if the path was absorbed (a zero weight) or if it
    /// reached [`MAX_BOUNCES`]. ωi below the horizon (a backfacing view) enters with
    /// σ₀ = Λ(−ωi); where that is below [`MIN_FIRST_RATE`](crate::research::MIN_FIRST_RATE) the walk from below answers
    /// ([`crate::research::Microsurface::sample_from_below`]).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` that is not a unit direction gives
    /// `None` (a debug assertion in debug builds).
    pub fn sample(&self, wi: Vec3, rng: &mut impl Rng) -> Option<WalkSample> {
        require!(is_direction(wi), None; wi);
        if wi.z == 0.0 {
            return None;
        }
        let slope = &self.slope;
        let Some((first_rate, _)) = self.entry(wi) else {
            return self.walk().sample_from_below(wi, rng);
        };
        let mut law = DepthLaw::new(first_rate, 0.0);
        let mut weight = Vec3::ONE;
        let mut incident = wi;
        for bounces in 1..=MAX_BOUNCES {
            let s = self.material.sample_phase_walk_unchecked(slope, incident, Side::Outside, rng);
            weight *= s.weight;
            if weight == Vec3::ZERO {
                return None;
            }
            let d = s.wo;
            if d.z < 0.0 {
                law.down(-f64::from(slope.lambda_unchecked(d)));
            } else if d.z > 0.0 {
                let hit = law.up(f64::from(slope.lambda_unchecked(d)));
                if f64::from(uniform(rng)) >= hit {
                    return Some(WalkSample { wo: d, weight, bounces });
                }
            }
            incident = -d;
        }
        None
    }
}
