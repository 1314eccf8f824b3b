//! The research-layer calls that the renderer trait's techniques wrap, in the trait's
//! orientation, as the BSDF benches (`benches/bsdf.rs`) and their instruction-count driver
//! (`tools/src/bin/profile_bsdf.rs`) call them.

use glam::Vec3;
use microsurface::Technique;
use microsurface::research::{
    Invariance, Material, Microsurface, PositionFree, ScatteringOrder, Shadowing, SingleScattering,
    UniformHeight,
};
use microsurface::slope::MicrosurfaceSlope;
use rand_pcg::Pcg64Mcg;

/// The research-layer calls a technique wraps, in the adjoint orientation of the trait (the
/// walk enters along the renderer's wo).
pub struct Research<S, M> {
    /// The microsurface (its slope and material serve every technique).
    pub surface: Microsurface<UniformHeight, S, M>,
    /// The technique whose research call is made.
    pub technique: Technique,
}

impl<S: MicrosurfaceSlope, M: Material> Research<S, M> {
    /// The position-free model of the same slope and material.
    pub fn pf(&self, shadowing: Shadowing) -> PositionFree<S, M> {
        PositionFree::new(*self.surface.slope(), *self.surface.material(), shadowing)
    }

    /// The single-scattering model of the same slope and material.
    pub fn single(&self) -> SingleScattering<S, M> {
        SingleScattering::new(*self.surface.slope(), *self.surface.material())
    }

    /// The technique's research `eval` of (wi, wo) = (walk_in, walk_out).
    #[inline(always)]
    pub fn eval(&self, walk_in: Vec3, walk_out: Vec3, rng: &mut Pcg64Mcg) -> Vec3 {
        match self.technique {
            Technique::SingleScattering => self.single().eval(walk_in, walk_out, rng),
            Technique::RandomWalk => self.surface.eval(walk_in, walk_out, ScatteringOrder::All, rng),
            Technique::PositionFree { estimator, shadowing } => {
                self.pf(shadowing).eval(walk_in, walk_out, estimator, ScatteringOrder::All, rng)
            }
            Technique::Invariance => match Invariance::new(*self.surface.slope(), *self.surface.material()) {
                Ok(invariance) => invariance.eval(walk_in, walk_out, ScatteringOrder::All, rng),
                Err(_) => self.surface.eval(walk_in, walk_out, ScatteringOrder::All, rng),
            },
        }
    }

    /// Single scattering's density, or the position-free model's (correlated) for the
    /// stochastic techniques (what the trait's `pdf` returns).
    #[inline(always)]
    pub fn pdf(&self, walk_in: Vec3, walk_out: Vec3) -> f32 {
        match self.technique {
            Technique::SingleScattering => self.single().pdf(walk_in, walk_out),
            _ => self.pf(Shadowing::Correlated).pdf(walk_in, walk_out),
        }
    }

    /// The sampled direction and weight, and for single scattering its density (what the
    /// trait's sample returns): all of it is returned, so that the optimizer cannot drop the
    /// density (mapping to the direction alone let it: 411 instead of 530 instructions).
    #[inline(always)]
    pub fn sample(&self, walk_in: Vec3, rng: &mut Pcg64Mcg) -> Option<(Vec3, Vec3, f32)> {
        match self.technique {
            Technique::SingleScattering => {
                self.single().sample(walk_in, rng).map(|s| (s.wo, s.weight, s.pdf))
            }
            Technique::RandomWalk => self.surface.sample(walk_in, rng).map(|s| (s.wo, s.weight, 0.0)),
            Technique::PositionFree { shadowing, .. } => {
                self.pf(shadowing).sample(walk_in, rng).map(|s| (s.wo, s.weight, 0.0))
            }
            Technique::Invariance => match Invariance::new(*self.surface.slope(), *self.surface.material()) {
                Ok(invariance) => invariance.sample(walk_in, rng).map(|s| (s.wo, s.weight, 0.0)),
                Err(_) => self.surface.sample(walk_in, rng).map(|s| (s.wo, s.weight, 0.0)),
            },
        }
    }

    /// The research sample followed by the density of its direction: what the trait's sample
    /// of a stochastic technique computes.
    #[inline(always)]
    pub fn sample_with_pdf(&self, walk_in: Vec3, rng: &mut Pcg64Mcg) -> Option<(Vec3, Vec3, f32)> {
        let (wo, weight, pdf) = self.sample(walk_in, rng)?;
        let pdf = if self.technique == Technique::SingleScattering { pdf } else { self.pdf(walk_in, wo) };
        Some((wo, weight, pdf))
    }
}
