//! The fixtures shared by the BSDF tests: the materials, slopes and techniques of the matrix,
//! the Šidák family of the chi-square tests, the trait's calls with a test generator, and the
//! imports every file of the binary uses.

pub(crate) use glam::{Vec2, Vec3};
pub(crate) use microsurface::research::{
    Estimator, Material, ScatteringOrder, Shadowing, SpecularLimit, sample_cosine_hemisphere,
};
pub(crate) use microsurface::slope::MicrosurfaceSlope;
pub(crate) use microsurface::{
    Beckmann, Bsdf, BsdfFlags, BsdfSample, BsdfValue, ClassicBrdf, ClassicMasking, ClassicNdf, ComplexIor,
    Conductor, Dielectric, Diffuse, Ggx, MicrofacetBsdf, ShadingFrame, Technique, Transport,
};
pub(crate) use std::f64::consts::PI;
pub(crate) use validation::check::rel_close;
pub(crate) use validation::chi2::{BsdfChi2, Chi2Grid, bsdf_chi2};
pub(crate) use validation::quadrature::{Domain, integrate_sphere};
pub(crate) use validation::{
    Stats, TestRng, assert_two_sample, dir, family_z, par_map, sidak, uniform_sphere, uniform32, uniform64,
};

pub(crate) const ETA: f32 = 1.5;
/// Roughness of the multiple-scattering tests (enough for a visible second order).
pub(crate) const ALPHA_MS: f32 = 0.6;
/// The number of chi-square tests of this binary that must pass (the Šidák family): 33 of
/// the microfacet (incl. elliptical) and classic models and those of `noncentral` and
/// `noncentral_materials`.
pub(crate) const CHI2_FAMILY: usize = 33
    + super::noncentral::NONCENTRAL_CHI2_TESTS
    + super::noncentral_materials::NONCENTRAL_MATERIAL_CHI2_TESTS;
/// Share of the single-bounce phase function in the proposal of the albedo estimates.
pub(crate) const PHASE_SHARE: f64 = 0.7;

pub(crate) type Mf<S, M> = MicrofacetBsdf<S, M>;

/// A microfacet BSDF of the default technique (the roughnesses of this file are valid).
pub(crate) fn mf<S: MicrosurfaceSlope, M: Material + SpecularLimit>(slope: S, material: M) -> Mf<S, M> {
    MicrofacetBsdf::new(slope, material).expect("α ≤ MAX_WALK_ALPHA")
}

/// The trait's calls with the random numbers drawn from a test generator: `eval_rng` passes
/// a fresh key (independent estimates from call to call), `sample_rng` three fresh uniforms.
pub(crate) trait WithRng {
    fn eval_rng(&self, wo: Vec3, wi: Vec3, rng: &mut TestRng) -> BsdfValue;
    fn sample_rng(&self, wo: Vec3, rng: &mut TestRng) -> Option<BsdfSample>;
}

impl<B: Bsdf + ?Sized> WithRng for B {
    fn eval_rng(&self, wo: Vec3, wi: Vec3, rng: &mut TestRng) -> BsdfValue {
        self.eval_keyed(wo, wi, rand::Rng::next_u64(rng))
    }

    fn sample_rng(&self, wo: Vec3, rng: &mut TestRng) -> Option<BsdfSample> {
        let uc = uniform32(rng);
        let u = Vec2::new(uniform32(rng), uniform32(rng));
        self.sample(wo, uc, u)
    }
}

pub(crate) fn chi2_alpha() -> f64 {
    sidak(0.01, CHI2_FAMILY)
}

pub(crate) fn gold() -> Conductor {
    Conductor::new(ComplexIor::GOLD)
}

pub(crate) fn dielectric() -> Dielectric {
    Dielectric::new(ETA).unwrap()
}

pub(crate) fn diffuse() -> Diffuse {
    Diffuse::new(Vec3::new(0.9, 0.6, 0.3)).unwrap()
}

pub(crate) fn ggx(ax: f32, ay: f32) -> Ggx {
    Ggx::new(ax, ay).unwrap()
}

pub(crate) fn beckmann(ax: f32, ay: f32) -> Beckmann {
    Beckmann::new(ax, ay).unwrap()
}

pub(crate) const PT_CORRELATED: Technique =
    Technique::PositionFree { estimator: Estimator::Pt, shadowing: Shadowing::Correlated };
pub(crate) const PT_UNCORRELATED: Technique =
    Technique::PositionFree { estimator: Estimator::Pt, shadowing: Shadowing::Uncorrelated };
pub(crate) const BDPT_CORRELATED: Technique =
    Technique::PositionFree { estimator: Estimator::Bdpt, shadowing: Shadowing::Correlated };
pub(crate) const BDPT_UNCORRELATED: Technique =
    Technique::PositionFree { estimator: Estimator::Bdpt, shadowing: Shadowing::Uncorrelated };

pub(crate) const ALL_TECHNIQUES: [(&str, Technique); 6] = [
    ("single", Technique::SingleScattering),
    ("walk", Technique::RandomWalk),
    ("pf-pt-corr", PT_CORRELATED),
    ("pf-pt-uncorr", PT_UNCORRELATED),
    ("pf-bdpt-corr", BDPT_CORRELATED),
    ("pf-bdpt-uncorr", BDPT_UNCORRELATED),
];

/// The relative index η_wo/η_wi squared of a pair of directions across the dielectric
/// (outside index 1, inside η).
pub(crate) fn eta_ratio_sq(wo: Vec3, wi: Vec3) -> f32 {
    let eta = |w: Vec3| if w.z > 0.0 { 1.0 } else { ETA };
    (eta(wo) / eta(wi)).powi(2)
}
