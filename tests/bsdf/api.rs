//! Integration tests of the renderer-facing BSDF API (`Bsdf`, `ShadingFrame`, `Transport`,
//! `MicrofacetBsdf` with every technique, `ClassicBrdf`, `EnergyByOrder`).
//!
//! The matrix: `ClassicBrdf` with Phong, Beckmann and GGX normals and both maskings;
//! `MicrofacetBsdf` with a perfect conductor (F = 1), gold, a dielectric η = 1.5 in radiance
//! and importance transport and coloured diffuse facets, over GGX and Beckmann slopes, with
//! single scattering, the random walk and the four position-free variants.
//!
//! * Exact densities (`ClassicBrdf`; single scattering on conductors and dielectrics): the
//!   samples pass a chi-square test against `pdf` (the samples that `sample` refuses, `None`,
//!   account for the mass ∫pdf leaves out, checked by a binomial test), every sample's weight
//!   is eval·|cos θi|/pdf (relative 1e-4) and ∫pdf ≤ 1 by quadrature.
//! * Stochastic models: E[weight] equals the albedo ∫ f·|cos θi| dωi, estimated independently
//!   by importance sampling `eval` with a proposal of exactly known density; every sample
//!   lands where `pdf` > 0 and carries consistent flags.
//!
//! Statistics: every Monte Carlo assertion is |m1 − m2| ≤ z·√(SE1² + SE2²) with
//! z = `family_z(0.01, m)` for the m assertions of its test function, and bounds the combined
//! SE so that the test can fail; chi-square tests run at the Šidák-corrected level
//! `sidak(0.01, CHI2_FAMILY)` over all chi-square tests of this file. Every generator is a
//! fixed-seed PCG.

use glam::{Vec2, Vec3};
use microsurface::{
    Beckmann, Bsdf, BsdfFlags, BsdfSample, BsdfValue, ClassicBrdf, ClassicMasking, ClassicNdf, ComplexIor,
    Conductor, Dielectric, Diffuse, Estimator, Ggx, Material, MicrofacetBsdf, MicrosurfaceSlope,
    ScatteringOrder, ShadingFrame, Shadowing, SpecularLimit, Technique, Transport, sample_cosine_hemisphere,
};
use std::f64::consts::PI;
use validation::chi2::{Chi2Grid, chi2_test};
use validation::quadrature::integrate_sphere;
use validation::{
    Stats, TestRng, assert_two_sample, dir, family_z, par_map, sidak, uniform_sphere, uniform32, uniform64,
};

const ETA: f32 = 1.5;
/// Roughness of the multiple-scattering tests (enough for a visible second order).
const ALPHA_MS: f32 = 0.6;
/// The number of chi-square tests of this file that must pass (the Šidák family).
const CHI2_FAMILY: usize = 29;
/// Share of the single-bounce phase function in the proposal of the albedo estimates.
const PHASE_SHARE: f64 = 0.7;

type Mf<S, M> = MicrofacetBsdf<S, M>;

/// A microfacet BSDF of the default technique (the roughnesses of this file are valid).
fn mf<S: MicrosurfaceSlope, M: Material + SpecularLimit>(slope: S, material: M) -> Mf<S, M> {
    MicrofacetBsdf::new(slope, material).expect("α ≤ MAX_WALK_ALPHA")
}

/// The trait's calls with the random numbers drawn from a test generator: `eval_rng` passes
/// a fresh key (independent estimates from call to call), `sample_rng` three fresh uniforms.
trait WithRng {
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

fn chi2_alpha() -> f64 {
    sidak(0.01, CHI2_FAMILY)
}

fn gold() -> Conductor {
    Conductor::new(ComplexIor::GOLD)
}

fn dielectric() -> Dielectric {
    Dielectric::new(ETA).unwrap()
}

fn diffuse() -> Diffuse {
    Diffuse::new(Vec3::new(0.9, 0.6, 0.3)).unwrap()
}

fn ggx(ax: f32, ay: f32) -> Ggx {
    Ggx::new(ax, ay).unwrap()
}

fn beckmann(ax: f32, ay: f32) -> Beckmann {
    Beckmann::new(ax, ay).unwrap()
}

const PT_CORRELATED: Technique =
    Technique::PositionFree { estimator: Estimator::Pt, shadowing: Shadowing::Correlated };
const PT_UNCORRELATED: Technique =
    Technique::PositionFree { estimator: Estimator::Pt, shadowing: Shadowing::Uncorrelated };
const BDPT_CORRELATED: Technique =
    Technique::PositionFree { estimator: Estimator::Bdpt, shadowing: Shadowing::Correlated };
const BDPT_UNCORRELATED: Technique =
    Technique::PositionFree { estimator: Estimator::Bdpt, shadowing: Shadowing::Uncorrelated };

const ALL_TECHNIQUES: [(&str, Technique); 6] = [
    ("single", Technique::SingleScattering),
    ("walk", Technique::RandomWalk),
    ("pf-pt-corr", PT_CORRELATED),
    ("pf-pt-uncorr", PT_UNCORRELATED),
    ("pf-bdpt-corr", BDPT_CORRELATED),
    ("pf-bdpt-uncorr", BDPT_UNCORRELATED),
];

/// The relative index η_wo/η_wi squared of a pair of directions across the dielectric
/// (outside index 1, inside η).
fn eta_ratio_sq(wo: Vec3, wi: Vec3) -> f32 {
    let eta = |w: Vec3| if w.z > 0.0 { 1.0 } else { ETA };
    (eta(wo) / eta(wi)).powi(2)
}

fn rel_close(a: Vec3, b: Vec3, rel: f32) -> bool {
    let scale = a.abs().max(b.abs()).max_element();
    (a - b).abs().max_element() <= rel * scale
}

// ---------------------------------------------------------------------------------------------
// Importance sampling of the albedo ∫ f·|cos θi| dωi, independent of `Bsdf::sample`
// ---------------------------------------------------------------------------------------------

/// The proposal of the albedo estimates: with probability `PHASE_SHARE` the single-bounce
/// phase function of the material seen from `wo` (conductors and dielectrics, whose phase
/// density is exact), otherwise a cosine lobe above (opaque) or on a random side
/// (dielectric). Diffuse facets use the cosine lobe only.
fn proposal_sample<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
    b: &Mf<S, M>,
    wo: Vec3,
    rng: &mut TestRng,
) -> Vec3 {
    let (s, m) = (b.surface().slope(), b.surface().material());
    if M::EXACT_PHASE_PDF && uniform64(rng) < PHASE_SHARE {
        // wo.z < 0 for an opaque material is a backfacing view (normal mapping): its phase
        // function is still the reflection about a visible normal
        let outside = wo.z > 0.0 || !M::TRANSMITS;
        return m.sample_phase(s, wo, outside, rng).wo;
    }
    let w = sample_cosine_hemisphere(uniform32(rng), uniform32(rng));
    if M::TRANSMITS && uniform64(rng) < 0.5 { -w } else { w }
}

/// The exact density of `proposal_sample` (both phase mechanisms of a dielectric summed).
fn proposal_pdf<S: MicrosurfaceSlope, M: Material + SpecularLimit>(b: &Mf<S, M>, wo: Vec3, w: Vec3) -> f64 {
    let (s, m) = (b.surface().slope(), b.surface().material());
    let cosine = if M::TRANSMITS { f64::from(w.z).abs() / (2.0 * PI) } else { f64::from(w.z).max(0.0) / PI };
    if !M::EXACT_PHASE_PDF {
        return cosine;
    }
    let out = wo.z > 0.0 || !M::TRANSMITS;
    let mut phase = f64::from(m.pdf_phase(s, wo, w, out, out));
    if M::TRANSMITS {
        phase += f64::from(m.pdf_phase(s, wo, w, out, !out));
    }
    PHASE_SHARE * phase + (1.0 - PHASE_SHARE) * cosine
}

/// Per-channel statistics of the albedo ∫ eval·|cos θi| dωi from `n` proposal samples.
fn albedo_stats<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
    label: &str,
    b: &Mf<S, M>,
    wo: Vec3,
    exact: bool,
    n: usize,
    rng: &mut TestRng,
) -> [Stats; 3] {
    let mut st = [Stats::default(); 3];
    for _ in 0..n {
        let w = proposal_sample(b, wo, rng);
        let p = proposal_pdf(b, wo, w);
        let v = b.eval_rng(wo, w, rng);
        assert!(v.f.is_finite() && v.f.min_element() >= 0.0, "{label}: eval({wo}, {w}) = {:?}", v.f);
        assert_eq!(v.exact, exact, "{label}: BsdfValue::exact");
        let x = if p > 0.0 { v.f.as_dvec3() * f64::from(w.z.abs()) / p } else { glam::DVec3::ZERO };
        assert!(p > 0.0 || v.f == Vec3::ZERO, "{label}: proposal density 0 where f = {:?}", v.f);
        for c in 0..3 {
            st[c].push(x[c]);
        }
    }
    st
}

/// Per-channel statistics of the weights of `n` calls of `sample` (0 for `None`), checking
/// every sample: unit direction, finite non-negative weight, pdf > 0 and equal to `pdf`,
/// consistent flags.
fn weight_stats<B: Bsdf>(
    label: &str,
    b: &B,
    wo: Vec3,
    exact_pdf: bool,
    n: usize,
    rng: &mut TestRng,
) -> [Stats; 3] {
    let mut st = [Stats::default(); 3];
    for _ in 0..n {
        let w = match b.sample_rng(wo, rng) {
            None => Vec3::ZERO,
            Some(s) => {
                assert!((s.wi.length() - 1.0).abs() < 1e-4, "{label}: wi = {} is not unit", s.wi);
                assert!(
                    s.weight.is_finite() && s.weight.min_element() >= 0.0,
                    "{label}: weight {}",
                    s.weight
                );
                let p = b.pdf(wo, s.wi);
                assert!(
                    s.pdf > 0.0 && s.pdf.is_finite() && p > 0.0,
                    "{label}: pdf {} / {p} at {}",
                    s.pdf,
                    s.wi
                );
                assert!((s.pdf - p).abs() <= 1e-5 * p, "{label}: sample pdf {} ≠ pdf() {p}", s.pdf);
                // an opaque BSDF reflects even where a normal map puts wi and wo on opposite
                // sides of the shading plane
                let reflection = !b.flags().transmission || (s.wi.z > 0.0) == (wo.z > 0.0);
                assert_eq!(
                    s.flags.reflection, reflection,
                    "{label}: flags {:?} for wo {wo} wi {}",
                    s.flags, s.wi
                );
                assert_eq!(s.flags.transmission, !reflection, "{label}: flags {:?}", s.flags);
                assert!(!s.flags.specular, "{label}: rough models have no Dirac lobe");
                assert_eq!(s.flags.exact_pdf, exact_pdf, "{label}: flags {:?}", s.flags);
                s.weight
            }
        };
        for c in 0..3 {
            st[c].push(f64::from(w[c]));
        }
    }
    st
}

/// Compares E[weight] with the albedo: per channel for a chromatic material, the channel
/// mean otherwise (whose channels are equal sample by sample).
fn compare_channels(label: &str, a: &[Stats; 3], b: &[Stats; 3], chromatic: bool, z: f64) {
    let max_se = |c: usize| MAX_REL_SE * b[c].mean().max(0.25);
    println!(
        "{label}: E[weight] = {:.5} ± {:.5}, albedo = {:.5} ± {:.5}",
        (a[0].mean() + a[1].mean() + a[2].mean()) / 3.0,
        a[0].se(),
        (b[0].mean() + b[1].mean() + b[2].mean()) / 3.0,
        b[0].se()
    );
    if chromatic {
        for c in 0..3 {
            assert_two_sample(&format!("{label} [channel {c}]"), &a[c], &b[c], z, max_se(c));
        }
    } else {
        // achromatic: the channels are equal sample by sample
        assert_two_sample(label, &a[0], &b[0], z, max_se(0));
    }
}

/// Whether `eval` and `pdf` of this BSDF are exact (single scattering on conductors and
/// dielectrics).
fn is_exact<S: MicrosurfaceSlope, M: Material + SpecularLimit>(b: &Mf<S, M>) -> bool {
    b.technique() == Technique::SingleScattering && M::EXACT_PHASE_PDF
}

/// Largest combined SE allowed, relative to the albedo of the channel (floored at 0.25): a
/// bias of about 3.5 % of the albedo is detected. The stochastic `eval` estimators are heavy
/// tailed near ωi = +z (single evaluations up to ~500× the mean were seen, where
/// Λ(ωi) → 0), which sets this bound and the sample counts.
const MAX_REL_SE: f64 = 0.01;

/// E[weight] of `n_sample` samples against the albedo from `n_eval` evaluations.
#[allow(clippy::too_many_arguments)]
fn check_weight_vs_albedo<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
    label: &str,
    b: &Mf<S, M>,
    wo: Vec3,
    chromatic: bool,
    n_sample: usize,
    n_eval: usize,
    seed: u64,
    z: f64,
) {
    let label = format!("{label} wo = {wo}");
    let exact = is_exact(b);
    let w = weight_stats(&label, b, wo, exact, n_sample, &mut validation::rng(seed));
    let mut rng = validation::rng(seed + 1_000_000);
    let a = albedo_stats(&label, b, wo, exact, n_eval, &mut rng);
    compare_channels(&label, &w, &a, chromatic, z);
}

// ---------------------------------------------------------------------------------------------
// The matrix of microfacet BSDFs
// ---------------------------------------------------------------------------------------------

/// A view from outside, and one from inside the dielectric.
fn view_out() -> Vec3 {
    dir(0.7, 0.4)
}

fn view_in() -> Vec3 {
    -dir(0.6, 2.0)
}

/// What a test does with each microfacet BSDF of the matrix.
trait Visit {
    fn visit<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
        &mut self,
        label: &str,
        b: &Mf<S, M>,
        chromatic: bool,
        views: &[Vec3],
    );
}

/// Visits the five materials (perfect conductor, gold, dielectric in radiance and importance
/// transport, coloured diffuse) over `slope` with technique `t`. The views: outside, plus
/// inside for the dielectric in radiance transport (importance transport differs from it only
/// by the exact factor checked by `transport_modes_differ_by_the_eta_ratio`).
fn visit_materials<S: MicrosurfaceSlope>(
    v: &mut impl Visit,
    slope: S,
    sname: &str,
    t: Technique,
    tname: &str,
) {
    let label = |m: &str| format!("{tname} {sname} {m}");
    let out = [view_out()];
    let both = [view_out(), view_in()];
    let b = mf(slope, Conductor::perfect()).with_technique(t);
    v.visit(&label("conductor F=1"), &b, false, &out);
    v.visit(&label("gold"), &mf(slope, gold()).with_technique(t), true, &out);
    let d = mf(slope, dielectric()).with_technique(t);
    v.visit(&label("dielectric radiance"), &d.with_transport(Transport::Radiance), false, &both);
    v.visit(&label("dielectric importance"), &d.with_transport(Transport::Importance), false, &out);
    v.visit(&label("diffuse"), &mf(slope, diffuse()).with_technique(t), true, &out);
}

fn visit_all_slopes(v: &mut impl Visit, techniques: &[(&str, Technique)]) {
    for &(tname, t) in techniques {
        visit_materials(v, ggx(ALPHA_MS, ALPHA_MS), "GGX", t, tname);
        visit_materials(v, beckmann(ALPHA_MS, ALPHA_MS), "Beckmann", t, tname);
    }
}

/// Counts the comparisons of the E[weight] tests of a matrix (for the Šidák z).
struct Count(usize);

impl Visit for Count {
    fn visit<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
        &mut self,
        _: &str,
        _: &Mf<S, M>,
        chromatic: bool,
        views: &[Vec3],
    ) {
        self.0 += views.len() * if chromatic { 3 } else { 1 };
    }
}

/// E[weight] = albedo for every visited BSDF and view.
struct WeightVsAlbedo {
    z: f64,
    n_sample: usize,
    n_eval: usize,
    seed: u64,
}

impl Visit for WeightVsAlbedo {
    fn visit<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
        &mut self,
        label: &str,
        b: &Mf<S, M>,
        chromatic: bool,
        views: &[Vec3],
    ) {
        for &wo in views {
            self.seed += 2;
            check_weight_vs_albedo(label, b, wo, chromatic, self.n_sample, self.n_eval, self.seed, self.z);
        }
    }
}

/// Runs the E[weight] = albedo test over both slopes and all materials for the techniques.
fn weight_matches_albedo(techniques: &[(&str, Technique)], n_sample: usize, n_eval: usize, seed: u64) {
    let mut count = Count(0);
    visit_all_slopes(&mut count, techniques);
    let mut check = WeightVsAlbedo { z: family_z(0.01, count.0), n_sample, n_eval, seed };
    visit_all_slopes(&mut check, techniques);
}

#[test]
fn single_scattering_weight_matches_albedo() {
    weight_matches_albedo(&[("single", Technique::SingleScattering)], 60_000, 60_000, 100);
}

#[test]
fn random_walk_weight_matches_albedo() {
    weight_matches_albedo(&[("walk", Technique::RandomWalk)], 60_000, 60_000, 200);
}

#[test]
fn position_free_pt_weight_matches_albedo() {
    weight_matches_albedo(
        &[("pf-pt-corr", PT_CORRELATED), ("pf-pt-uncorr", PT_UNCORRELATED)],
        60_000,
        100_000,
        300,
    );
}

#[test]
fn position_free_bdpt_correlated_weight_matches_albedo() {
    weight_matches_albedo(&[("pf-bdpt-corr", BDPT_CORRELATED)], 60_000, 30_000, 400);
}

#[test]
fn position_free_bdpt_uncorrelated_weight_matches_albedo() {
    weight_matches_albedo(&[("pf-bdpt-uncorr", BDPT_UNCORRELATED)], 60_000, 30_000, 500);
}

/// `with_order` truncates the BSDF: `sample` must then return the truncated BSDF's weights
/// too (E[weight] = the truncated albedo), or a renderer mixing `eval` (NEE) and `sample`
/// (BSDF sampling) integrates two different BSDFs.
#[test]
fn truncated_orders_weight_matches_albedo() {
    let up_to = |n| ScatteringOrder::up_to(n).unwrap();
    let only = |n| ScatteringOrder::only(n).unwrap();
    let z = family_z(0.01, 1 + 3 + 3 + 1);
    let g = ggx(ALPHA_MS, ALPHA_MS);
    let bk = beckmann(ALPHA_MS, ALPHA_MS);
    let wo = view_out();
    let conductor = mf(g, Conductor::perfect());
    let b = conductor.with_technique(Technique::RandomWalk).with_order(up_to(2));
    check_weight_vs_albedo("walk GGX conductor F=1 up to 2", &b, wo, false, 60_000, 60_000, 600, z);
    let b = mf(bk, diffuse()).with_technique(Technique::RandomWalk).with_order(only(2));
    check_weight_vs_albedo("walk Beckmann diffuse only 2", &b, wo, true, 60_000, 60_000, 602, z);
    let b = mf(bk, gold()).with_technique(PT_CORRELATED).with_order(up_to(1));
    check_weight_vs_albedo("pf-pt-corr Beckmann gold up to 1", &b, wo, true, 60_000, 50_000, 604, z);
    let b = mf(g, dielectric()).with_technique(BDPT_UNCORRELATED).with_order(up_to(2));
    check_weight_vs_albedo("pf-bdpt-uncorr GGX dielectric up to 2", &b, wo, false, 60_000, 30_000, 606, z);
}

// ---------------------------------------------------------------------------------------------
// Exact densities: chi-square, weights, ∫pdf ≤ 1
// ---------------------------------------------------------------------------------------------

/// Samples per chi-square test.
const CHI2_N: usize = 200_000;

/// 20 × 40 equal-area cells of the sphere. Expected counts are ~N/800 = 250: a quadrature
/// error of 1e-5 over the sphere (1.25e-8 per cell) is far below their Poisson noise.
fn chi2_grid() -> Chi2Grid {
    Chi2Grid { quad_tol: 1e-5, max_depth: 7, ..Chi2Grid::sphere(20, 40) }
}

/// ∫ pdf(wo, ·) over the sphere by adaptive quadrature.
fn pdf_mass<B: Bsdf>(b: &B, wo: Vec3) -> f64 {
    integrate_sphere(&mut |w| f64::from(b.pdf(wo, w)), 16, 32, false, 1e-5, 7)
}

/// For a BSDF with an exact density: ∫pdf ≤ 1; `sample` passes the chi-square test against
/// `pdf` (scaled by `pdf_scale`, 1 except in the negative controls), its refusals (`None`)
/// match the mass ∫pdf leaves out (binomial, z·SE + the quadrature's 1e-3), and every
/// sample's weight is eval·|cos θi|/pdf (relative 1e-4). Returns (p-value, ∫pdf).
fn chi2_exact<B: Bsdf>(label: &str, b: &B, wo: Vec3, seed: u64, z: f64, pdf_scale: f64) -> (f64, f64) {
    let mass = pdf_mass(b, wo);
    assert!(mass <= 1.0 + 1e-3, "{label}: ∫pdf = {mass} > 1");
    let mut rng = validation::rng(seed);
    let mut eval_rng = validation::rng(seed + 7);
    let out = chi2_test(
        label,
        chi2_grid(),
        |w| pdf_scale * f64::from(b.pdf(wo, w)),
        || {
            let s = b.sample_rng(wo, &mut rng)?;
            assert!(s.flags.exact_pdf, "{label}: exact_pdf flag not set");
            let v = b.eval_rng(wo, s.wi, &mut eval_rng);
            assert!(v.exact, "{label}: eval not flagged exact");
            let expected = v.f * (s.wi.z.abs() / s.pdf);
            assert!(
                rel_close(s.weight, expected, 1e-4),
                "{label}: weight {} ≠ eval·|cos θi|/pdf = {expected} at wi = {}",
                s.weight,
                s.wi
            );
            Some(s.wi)
        },
        CHI2_N,
        chi2_alpha(),
        pdf_scale * mass,
    );
    let p_none = (1.0 - mass).clamp(0.0, 1.0);
    let se = (p_none * (1.0 - p_none) / CHI2_N as f64).sqrt();
    let frac = out.failures as f64 / CHI2_N as f64;
    assert!(
        (frac - p_none).abs() <= z * se + 1e-3,
        "{label}: sample refused {frac:.5} of the time, 1 − ∫pdf = {p_none:.5} (N = {CHI2_N}, SE = {se:.2e}, z = {z:.2})"
    );
    println!(
        "{label}: χ² = {:.1}, dof = {}, p = {:.4}, ∫pdf = {mass:.5}",
        out.statistic, out.dof, out.p_value
    );
    (out.p_value, mass)
}

/// The classic BRDFs of one NDF: both maskings at θo = 0.8, and the exact masking near
/// grazing (θo = 1.35, where most specular samples leave below the horizon).
fn classic_models(ndf: ClassicNdf) -> Vec<(String, ClassicBrdf, Vec3)> {
    let (kd, ks) = (Vec3::new(0.3, 0.4, 0.5), Vec3::new(0.6, 0.5, 0.4));
    let mut v = vec![];
    for masking in [ClassicMasking::Exact, ClassicMasking::Rational] {
        let b = ClassicBrdf::new(kd, ks, ndf, masking).unwrap();
        v.push((format!("classic {ndf:?} {masking:?}"), b, dir(0.8, 0.3)));
    }
    let b = ClassicBrdf::new(kd, ks, ndf, ClassicMasking::Exact).unwrap();
    v.push((format!("classic {ndf:?} grazing"), b, dir(1.35, 2.0)));
    v
}

fn classic_sampling_matches_pdf(ndf: ClassicNdf, seed: u64) {
    let models = classic_models(ndf);
    let z = family_z(0.01, models.len());
    for (i, (label, b, wo)) in models.iter().enumerate() {
        let (_, mass) = chi2_exact(label, b, *wo, seed + i as u64, z, 1.0);
        assert!(mass > 0.5, "{label}: ∫pdf = {mass}");
    }
}

#[test]
fn classic_phong_sampling_matches_pdf() {
    classic_sampling_matches_pdf(ClassicNdf::Phong(30.0), 1000);
}

#[test]
fn classic_beckmann_sampling_matches_pdf() {
    classic_sampling_matches_pdf(ClassicNdf::Beckmann(0.3), 1010);
}

#[test]
fn classic_ggx_sampling_matches_pdf() {
    classic_sampling_matches_pdf(ClassicNdf::Ggx(0.3), 1020);
}

/// Single scattering on conductors and dielectrics: anisotropic roughness, views from
/// outside at two angles and from inside the dielectric.
#[test]
fn single_scattering_sampling_matches_pdf() {
    let ss = Technique::SingleScattering;
    let g = ggx(0.25, 0.45);
    let bk = beckmann(0.45, 0.25);
    let z = family_z(0.01, 16);
    let mut p = vec![];
    let mut seed = 2000;
    let mut run = |pv: (f64, f64)| p.push(pv.0);
    for (sname, theta) in [("GGX", 0.5), ("GGX", 1.3), ("Beckmann", 0.5), ("Beckmann", 1.3)] {
        let wo = dir(theta, 0.6);
        seed += 10;
        if sname == "GGX" {
            let b = mf(g, Conductor::perfect()).with_technique(ss);
            run(chi2_exact(&format!("single {sname} F=1 θo={theta}"), &b, wo, seed, z, 1.0));
            let b = mf(ggx(0.5, 0.5), gold()).with_technique(ss);
            run(chi2_exact(&format!("single {sname} gold θo={theta}"), &b, wo, seed + 1, z, 1.0));
        } else {
            let b = mf(bk, Conductor::perfect()).with_technique(ss);
            run(chi2_exact(&format!("single {sname} F=1 θo={theta}"), &b, wo, seed, z, 1.0));
            let b = mf(beckmann(0.5, 0.5), gold()).with_technique(ss);
            run(chi2_exact(&format!("single {sname} gold θo={theta}"), &b, wo, seed + 1, z, 1.0));
        }
    }
    for (sname, wo_r, wo_i) in
        [("GGX", dir(0.5, 0.6), dir(1.2, 2.0)), ("Beckmann", dir(0.5, 0.6), dir(1.2, 2.0))]
    {
        for (transport, wo_out, wo_in) in
            [(Transport::Radiance, wo_r, -dir(0.9, 1.0)), (Transport::Importance, wo_i, -dir(0.5, 1.0))]
        {
            for wo in [wo_out, wo_in] {
                seed += 10;
                let label = format!("single {sname} dielectric {transport:?} wo = {wo}");
                let pv = if sname == "GGX" {
                    let b = mf(g, dielectric()).with_technique(ss);
                    chi2_exact(&label, &b.with_transport(transport), wo, seed, z, 1.0)
                } else {
                    let b = mf(bk, dielectric()).with_technique(ss);
                    chi2_exact(&label, &b.with_transport(transport), wo, seed, z, 1.0)
                };
                run(pv);
            }
        }
    }
    assert_eq!(p.len(), 16);
    println!("single scattering: worst p = {:.4}", p.iter().cloned().fold(1.0, f64::min));
}

// ---------------------------------------------------------------------------------------------
// Normal mapping: backfacing views in the shading frame (Tokuyoshi)
// ---------------------------------------------------------------------------------------------

/// The backfacing configurations: slope, polar angle of wo (> π/2).
fn backfacing_views() -> [(&'static str, f64); 4] {
    [("GGX", 1.8), ("GGX", 2.2), ("Beckmann", 1.8), ("Beckmann", 2.2)]
}

/// The backfacing BSDF over GGX or Beckmann (one of the two is `Some`).
type EitherSlope<M> = (Option<Mf<Ggx, M>>, Option<Mf<Beckmann, M>>);

fn backfacing_bsdf<M: Material + SpecularLimit>(sname: &str, m: M) -> EitherSlope<M> {
    let ss = Technique::SingleScattering;
    if sname == "GGX" {
        (Some(mf(ggx(0.5, 0.5), m).with_technique(ss)), None)
    } else {
        (None, Some(mf(beckmann(0.5, 0.5), m).with_technique(ss)))
    }
}

/// A visible normal m (m.z > 0, wo·m > 0) seen from below the horizon reflects wo to
/// 2(wo·m)m − wo, whose z = 2(wo·m)m.z − wo.z > 0: every sample leaves upwards, so the
/// density of a backfacing view integrates to one (and a model that returns zero light for
/// backfacing views fails here rather than passing the unbiasedness test vacuously).
#[test]
fn normal_mapping_pdf_integrates_to_one() {
    for (sname, theta) in backfacing_views() {
        let wo = dir(theta, 0.3);
        let mass = match backfacing_bsdf(sname, Conductor::perfect()) {
            (Some(b), _) => pdf_mass(&b, wo),
            (_, Some(b)) => pdf_mass(&b, wo),
            _ => unreachable!(),
        };
        assert!(
            (mass - 1.0).abs() <= 1e-3,
            "single {sname} conductor, backfacing θo = {theta}: ∫pdf = {mass}"
        );
    }
}

#[test]
fn normal_mapping_sampling_matches_pdf() {
    let z = family_z(0.01, 4);
    for (i, (sname, theta)) in backfacing_views().into_iter().enumerate() {
        let wo = dir(theta, 0.3);
        let label = format!("single {sname} conductor F=1, backfacing θo = {theta}");
        let (_, mass) = match backfacing_bsdf(sname, Conductor::perfect()) {
            (Some(b), _) => chi2_exact(&label, &b, wo, 3000 + i as u64, z, 1.0),
            (_, Some(b)) => chi2_exact(&label, &b, wo, 3000 + i as u64, z, 1.0),
            _ => unreachable!(),
        };
        assert!(mass > 0.5, "{label}: ∫pdf = {mass}: the chi-square test would pass vacuously");
    }
}

#[test]
fn normal_mapping_weight_is_unbiased() {
    let z = family_z(0.01, 4 * 3);
    for (i, (sname, theta)) in backfacing_views().into_iter().enumerate() {
        let wo = dir(theta, 0.3);
        let label = format!("single {sname} gold, backfacing θo = {theta}");
        let seed = 3100 + 2 * i as u64;
        let albedo = match backfacing_bsdf(sname, gold()) {
            (Some(b), _) => {
                check_weight_vs_albedo(&label, &b, wo, true, 60_000, 60_000, seed, z);
                albedo_stats(&label, &b, wo, true, 2_000, &mut validation::rng(seed + 5))
            }
            (_, Some(b)) => {
                check_weight_vs_albedo(&label, &b, wo, true, 60_000, 60_000, seed, z);
                albedo_stats(&label, &b, wo, true, 2_000, &mut validation::rng(seed + 5))
            }
            _ => unreachable!(),
        };
        let mean = albedo.iter().map(Stats::mean).sum::<f64>() / 3.0;
        assert!(
            mean > 0.05,
            "{label}: albedo {mean}: a backfacing view reflects nothing, the test is vacuous"
        );
    }
}

/// The chi-square test has power: a density scaled by 0.9 (with the matching expected mass)
/// is rejected, for a front-facing and a backfacing view.
#[test]
fn chi2_negative_control() {
    let rejects = |f: &mut dyn FnMut()| {
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
        match r {
            Ok(()) => false,
            Err(e) => {
                let msg = e
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                assert!(msg.contains("chi-square rejects"), "unexpected failure: {msg}");
                true
            }
        }
    };
    let z = family_z(0.01, 1);
    let b = mf(ggx(0.5, 0.5), Conductor::perfect()).with_technique(Technique::SingleScattering);
    for (wo, what) in [(dir(0.5, 0.3), "front-facing"), (dir(1.8, 0.3), "backfacing")] {
        let rejected = rejects(&mut || {
            chi2_exact(&format!("negative control {what}"), &b, wo, 3900, z, 0.9);
        });
        assert!(rejected, "{what}: a density scaled by 0.9 passed the chi-square test");
    }
}

// ---------------------------------------------------------------------------------------------
// Transport modes and generalized reciprocity
// ---------------------------------------------------------------------------------------------

/// The direction pairs (wo, wi) of the transport tests: reflection outside, transmission in
/// both directions, internal reflection.
/// The transmissions are near the macro refraction (θt = asin(sin θ/η) on the inside,
/// θ = asin(η sin θ) from inside) so that f is large.
fn transport_pairs() -> [(Vec3, Vec3); 4] {
    let refract_in = (0.5f64.sin() / f64::from(ETA)).asin() + 0.1;
    let refract_out = (0.4f64.sin() * f64::from(ETA)).asin() - 0.1;
    [
        (dir(0.5, 0.2), dir(0.9, 2.5)),
        (dir(0.5, 0.2), -dir(refract_in, 0.3)),
        (-dir(0.4, 1.0), dir(refract_out, 1.1)),
        (-dir(0.4, 1.0), -dir(0.9, 3.0)),
    ]
}

struct TransportCheck;

impl Visit for TransportCheck {
    fn visit<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
        &mut self,
        label: &str,
        b: &Mf<S, M>,
        _: bool,
        _: &[Vec3],
    ) {
        let (r, i) = (b.with_transport(Transport::Radiance), b.with_transport(Transport::Importance));
        for (k, (wo, wi)) in transport_pairs().into_iter().enumerate() {
            let ratio = eta_ratio_sq(wo, wi);
            let mut nonzero = 0;
            for seed in 0..40 {
                let fr = r.eval_rng(wo, wi, &mut validation::rng(seed));
                let fi = i.eval_rng(wo, wi, &mut validation::rng(seed));
                assert_eq!(fr.exact, fi.exact, "{label}");
                assert!(
                    rel_close(fr.f, fi.f * ratio, 1e-5),
                    "{label}: radiance f {} ≠ importance f {} × (η_wo/η_wi)² = {ratio} (wo {wo}, wi {wi})",
                    fr.f,
                    fi.f
                );
                nonzero += usize::from(fr.f != Vec3::ZERO);
            }
            assert!(nonzero > 0, "{label}: f = 0 for every seed at pair {k}: the check is vacuous");
        }
        for wo in [view_out(), view_in()] {
            let mut crossed = 0;
            for seed in 0..400 {
                let sr = r.sample_rng(wo, &mut validation::rng(seed));
                let si = i.sample_rng(wo, &mut validation::rng(seed));
                match (sr, si) {
                    (None, None) => {}
                    (Some(sr), Some(si)) => {
                        assert_eq!((sr.wi, sr.pdf, sr.flags), (si.wi, si.pdf, si.flags), "{label}");
                        let ratio = eta_ratio_sq(wo, sr.wi);
                        assert!(
                            rel_close(sr.weight, si.weight * ratio, 1e-5),
                            "{label}: weights {sr:?} {si:?}"
                        );
                        crossed += usize::from(sr.flags.transmission);
                    }
                    _ => panic!("{label}: the transports disagree on whether a sample exists"),
                }
            }
            assert!(crossed > 0, "{label}: no transmission sampled from {wo}");
        }
    }
}

/// Same seed, same random numbers: radiance and importance transport differ exactly by
/// (η_wo/η_wi)², in `eval` and in `sample`'s weights, for every technique.
#[test]
fn transport_modes_differ_by_the_eta_ratio() {
    for (tname, t) in ALL_TECHNIQUES {
        let d = mf(ggx(ALPHA_MS, ALPHA_MS), dielectric()).with_technique(t);
        TransportCheck.visit(&format!("{tname} GGX dielectric"), &d, false, &[]);
        let d = mf(beckmann(0.3, 0.7), dielectric()).with_technique(t);
        TransportCheck.visit(&format!("{tname} Beckmann(0.3, 0.7) dielectric"), &d, false, &[]);
    }
}

/// Generalized reciprocity of the radiance BSDF, f(wo, wi)/η_wo² = f(wi, wo)/η_wi², exact for
/// single scattering (to f32 rounding, 5e-4 of f + 1e-5, over random pairs of directions; a
/// missing or misplaced η² changes f by a factor 2.25).
#[test]
fn single_scattering_is_reciprocal() {
    let mut rng = validation::rng(4000);
    let ss = Technique::SingleScattering;
    let d = mf(ggx(0.4, 0.7), dielectric()).with_technique(ss);
    let c = mf(beckmann(0.6, 0.3), gold()).with_technique(ss);
    let eta2 = |w: Vec3| if w.z > 0.0 { 1.0 } else { ETA * ETA };
    let (mut checked_d, mut checked_c) = (0, 0);
    for _ in 0..20_000 {
        let (wo, wi) = (uniform_sphere(&mut rng), uniform_sphere(&mut rng));
        let a = d.eval_rng(wo, wi, &mut rng).f / eta2(wo);
        let b = d.eval_rng(wi, wo, &mut rng).f / eta2(wi);
        // f32 rounding through the flipped (inside) evaluation reaches ~1.4e-4 of f in the
        // lobe, and the support's edge (ωo·ωh → 0) differs by rounding where f → 0
        let m = a.max(b).max_element();
        checked_d += usize::from(m > 1e-2);
        if m > 0.0 {
            assert!(
                (a - b).abs().max_element() <= 5e-4 * m + 1e-5,
                "dielectric: f(wo, wi)/η_wo² = {a} ≠ f(wi, wo)/η_wi² = {b} (wo {wo}, wi {wi})"
            );
        }
        if wo.z > 0.0 && wi.z > 0.0 {
            let (a, b) = (c.eval_rng(wo, wi, &mut rng).f, c.eval_rng(wi, wo, &mut rng).f);
            assert!(
                (a - b).abs().max_element() <= 5e-4 * a.max(b).max_element() + 1e-5,
                "gold: f(wo, wi) = {a} ≠ f(wi, wo) = {b} (wo {wo}, wi {wi})"
            );
            checked_c += usize::from(a.max_element() > 1e-3);
        }
    }
    assert!(checked_d > 2_000 && checked_c > 2_000, "{checked_d} {checked_c}");
}

/// Generalized reciprocity of the stochastic radiance BSDFs (random walk and the reciprocal,
/// height-uncorrelated position-free model; the correlated one is documented as not
/// reciprocal), in expectation: two-sample tests at four pairs of directions.
#[test]
fn stochastic_models_are_reciprocal() {
    let techniques = [
        ("walk", Technique::RandomWalk),
        ("pf-pt-uncorr", PT_UNCORRELATED),
        ("pf-bdpt-uncorr", BDPT_UNCORRELATED),
    ];
    let z = family_z(0.01, techniques.len() * (4 + 2));
    let eta2 = |w: Vec3| f64::from(if w.z > 0.0 { 1.0 } else { ETA * ETA });
    let mut seed = 4100;
    let mut stats = |label: &str, f: &mut dyn FnMut(&mut TestRng) -> f64, n: usize| {
        seed += 1;
        let mut rng = validation::rng(seed);
        let mut s = Stats::default();
        for _ in 0..n {
            s.push(f(&mut rng));
        }
        let _ = label;
        s
    };
    for (tname, t) in techniques {
        let n = if t == BDPT_UNCORRELATED { 150_000 } else { 50_000 };
        let d = mf(ggx(ALPHA_MS, ALPHA_MS), dielectric()).with_technique(t);
        for (wo, wi) in transport_pairs() {
            let label = format!("{tname} dielectric wo {wo} wi {wi}");
            let a = stats(&label, &mut |r| f64::from(d.eval_rng(wo, wi, r).f.x) / eta2(wo), n);
            let b = stats(&label, &mut |r| f64::from(d.eval_rng(wi, wo, r).f.x) / eta2(wi), n);
            println!("{label}: {:.5} ± {:.5} vs {:.5} ± {:.5}", a.mean(), a.se(), b.mean(), b.se());
            assert_two_sample(&label, &a, &b, z, 0.03 * a.mean().max(b.mean()));
        }
        let (wo, wi) = (dir(0.5, 0.2), dir(1.0, 2.5));
        let c = mf(beckmann(ALPHA_MS, ALPHA_MS), gold()).with_technique(t);
        let f = mf(ggx(ALPHA_MS, ALPHA_MS), diffuse()).with_technique(t);
        let label = format!("{tname} gold wo {wo} wi {wi}");
        let a = stats(&label, &mut |r| f64::from(c.eval_rng(wo, wi, r).f.element_sum()), n);
        let b = stats(&label, &mut |r| f64::from(c.eval_rng(wi, wo, r).f.element_sum()), n);
        assert_two_sample(&label, &a, &b, z, 0.03 * a.mean().max(b.mean()));
        let label = format!("{tname} diffuse wo {wo} wi {wi}");
        let a = stats(&label, &mut |r| f64::from(f.eval_rng(wo, wi, r).f.element_sum()), n);
        let b = stats(&label, &mut |r| f64::from(f.eval_rng(wi, wo, r).f.element_sum()), n);
        assert_two_sample(&label, &a, &b, z, 0.03 * a.mean().max(b.mean()));
    }
}

// ---------------------------------------------------------------------------------------------
// ShadingFrame
// ---------------------------------------------------------------------------------------------

#[test]
fn shading_frame_is_orthonormal_and_round_trips() {
    let mut rng = validation::rng(5000);
    let mut normals = vec![
        Vec3::Z,
        -Vec3::Z,
        Vec3::X,
        -Vec3::Y,
        Vec3::new(1e-8, 0.0, -1.0),
        Vec3::new(0.0, 1e-4, -1.0),
        Vec3::new(-1e-3, 1e-3, -1.0),
        Vec3::new(3e-4, -2e-4, -1.0),
        Vec3::new(1e-7, 1e-7, 1.0),
        Vec3::new(0.0, 0.0, -3.5),
        Vec3::new(2.0, -1.0, 0.0),
    ];
    for _ in 0..2000 {
        // random directions, random lengths
        normals.push(uniform_sphere(&mut rng) * (0.1 + 5.0 * uniform32(&mut rng)));
    }
    for n in normals {
        let f = ShadingFrame::from_normal(n).unwrap_or_else(|| panic!("no frame for {n}"));
        let nn = n.normalize();
        let (t, b, z) = (f.to_world(Vec3::X), f.to_world(Vec3::Y), f.to_world(Vec3::Z));
        assert!((f.normal() - nn).length() <= 1e-6, "{n}: normal {}", f.normal());
        assert!((z - nn).length() <= 1e-6, "{n}: to_world(z) = {z}");
        for (name, v) in [("t", t), ("b", b), ("n", z)] {
            assert!((v.length() - 1.0).abs() <= 1e-6, "{n}: |{name}| = {}", v.length());
        }
        assert!(
            t.dot(b).abs() <= 1e-6 && t.dot(z).abs() <= 1e-6 && b.dot(z).abs() <= 1e-6,
            "{n}: {t} {b} {z}"
        );
        assert!((t.cross(b) - z).length() <= 1e-5, "{n}: (t, b, n) is not right-handed");
        assert!((f.to_local(nn) - Vec3::Z).length() <= 1e-6, "{n}: to_local(n) = {}", f.to_local(nn));
        for _ in 0..4 {
            let w = uniform_sphere(&mut rng);
            assert!((f.to_world(f.to_local(w)) - w).length() <= 1e-6, "{n}: round trip of {w}");
            assert!((f.to_local(f.to_world(w)) - w).length() <= 1e-6, "{n}: round trip of {w}");
            assert!((f.to_local(w).length() - 1.0).abs() <= 1e-6);
        }
    }
}

#[test]
fn shading_frame_rejects_degenerate_normals() {
    for n in [
        Vec3::ZERO,
        Vec3::splat(f32::NAN),
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, f32::INFINITY, 1.0),
        Vec3::new(f32::NEG_INFINITY, 0.0, 0.0),
    ] {
        assert!(ShadingFrame::from_normal(n).is_none(), "a frame for {n}");
    }
}

// ---------------------------------------------------------------------------------------------
// EnergyByOrder
// ---------------------------------------------------------------------------------------------

/// Batches of `energy_by_order`: the table of all walks, and per-batch statistics of the
/// total and of the first order (for their standard errors).
fn energy_batches<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
    b: &Mf<S, M>,
    wo: Vec3,
    batches: usize,
    walks: usize,
    seed: u64,
) -> (Stats, Stats) {
    let mut rng = validation::rng(seed);
    let (mut total, mut first) = (Stats::default(), Stats::default());
    for _ in 0..batches {
        let t = b.energy_by_order(wo, walks, &mut rng);
        assert_eq!(t.walks, walks);
        assert!(t.per_order.iter().all(|&e| e >= 0.0 && e.is_finite()) && t.beyond >= 0.0, "{t:?}");
        assert_eq!(t.left_out(0), t.total());
        let mut previous = t.left_out(0);
        for n in 1..=12 {
            let l = t.left_out(n);
            assert!(l <= previous + 1e-12 && l >= -1e-12, "left_out({n}) = {l} after {previous}: {t:?}");
            previous = l;
        }
        assert!((t.left_out(8) - t.beyond).abs() <= 1e-12 && (t.left_out(20) - t.beyond).abs() <= 1e-12);
        assert!((t.left_out(1) - (t.total() - t.per_order[0])).abs() <= 1e-12);
        total.push(t.total());
        first.push(t.per_order[0]);
    }
    (total, first)
}

/// Statistics of the channel-averaged albedo ∫ eval·|cos θi| dωi.
fn albedo_mean_stats<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
    b: &Mf<S, M>,
    wo: Vec3,
    n: usize,
    seed: u64,
) -> Stats {
    let mut rng = validation::rng(seed);
    let mut st = Stats::default();
    for _ in 0..n {
        let w = proposal_sample(b, wo, &mut rng);
        let p = proposal_pdf(b, wo, w);
        let f = b.eval_rng(wo, w, &mut rng).f;
        st.push(if p > 0.0 { f64::from(f.element_sum()) / 3.0 * f64::from(w.z.abs()) / p } else { 0.0 });
    }
    st
}

/// The table's total equals the albedo of the technique (the random walk's for single
/// scattering, as documented), its first order equals the single-scattering albedo, and
/// left_out is a non-increasing tail sum with left_out(0) = total.
#[test]
fn energy_by_order_matches_the_albedo() {
    let z = family_z(0.01, 6);
    let wo = view_out();
    let g = ggx(ALPHA_MS, ALPHA_MS);
    let bk = beckmann(ALPHA_MS, ALPHA_MS);
    let walk = Technique::RandomWalk;
    let ss = Technique::SingleScattering;
    let check = |label: &str, e: &Stats, a: &Stats| {
        println!("{label}: table {:.5} ± {:.5}, albedo {:.5} ± {:.5}", e.mean(), e.se(), a.mean(), a.se());
        assert_two_sample(label, e, a, z, MAX_REL_SE * a.mean().max(0.25));
    };

    let b = mf(g, gold());
    let (total, first) = energy_batches(&b.with_technique(walk), wo, 20, 3000, 5100);
    check("walk GGX gold: total", &total, &albedo_mean_stats(&b.with_technique(walk), wo, 60_000, 5101));
    check("walk GGX gold: order 1", &first, &albedo_mean_stats(&b.with_technique(ss), wo, 60_000, 5102));
    // single scattering tabulates the random walk
    let (total_ss, _) = energy_batches(&b.with_technique(ss), wo, 20, 3000, 5103);
    assert_two_sample("single GGX gold: table of the walk", &total_ss, &total, z, 0.01);

    let b = mf(bk, diffuse()).with_technique(walk);
    let (total, _) = energy_batches(&b, wo, 20, 3000, 5110);
    check("walk Beckmann diffuse: total", &total, &albedo_mean_stats(&b, wo, 60_000, 5111));

    // the table ignores the transport factor: compare with importance transport
    let b = mf(g, dielectric()).with_technique(walk).with_transport(Transport::Importance);
    let (total, _) = energy_batches(&b, wo, 20, 3000, 5120);
    check("walk GGX dielectric: total", &total, &albedo_mean_stats(&b, wo, 60_000, 5121));

    let b = mf(bk, gold()).with_technique(BDPT_UNCORRELATED);
    let (total, _) = energy_batches(&b, wo, 20, 3000, 5130);
    check("pf-bdpt-uncorr Beckmann gold: total", &total, &albedo_mean_stats(&b, wo, 30_000, 5131));
}

// ---------------------------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------------------------

/// Invalid directions: zero, NaN, infinite, non-unit.
fn bad_directions() -> Vec<Vec3> {
    let w = dir(0.6, 0.3);
    vec![
        Vec3::ZERO,
        Vec3::splat(f32::NAN),
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, 0.0, f32::INFINITY),
        2.0 * w,
        0.5 * w,
        -3.0 * w,
    ]
}

/// Valid directions on the horizon: zero, without a debug assertion.
fn horizon_directions() -> [Vec3; 2] {
    [Vec3::X, Vec3::new(0.6, -0.8, 0.0)]
}

/// In debug builds `call` must trip the trait's debug assertion; in release builds it must
/// return "nothing" (`is_nothing`).
fn nothing_or_debug_panic<T>(label: &str, call: impl FnOnce() -> T, is_nothing: impl Fn(&T) -> bool) {
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(call));
    if cfg!(debug_assertions) {
        assert!(r.is_err(), "{label}: no debug assertion for an invalid argument");
    } else {
        let v = r.unwrap_or_else(|_| panic!("{label}: panicked in a release build"));
        assert!(is_nothing(&v), "{label}: returned something for an invalid argument");
    }
}

/// Zero f, zero pdf and no sample (release) or a debug assertion (debug) for invalid
/// directions and uniforms; zero without an assertion on the horizon; zero below the surface
/// for reflection-only models (`backfacing_view_valid`: the microfacet BSDFs accept
/// backfacing views, see the normal-mapping tests); finite, non-negative values for random
/// and grazing directions.
fn check_bad_input<B: Bsdf>(
    label: &str,
    b: &B,
    reflection_only: bool,
    backfacing_view_valid: bool,
    seed: u64,
) {
    let mut rng = validation::rng(seed);
    let (good_o, good_i) = (dir(0.6, 0.3), dir(0.8, 2.0));
    let zero_f = |v: &BsdfValue| v.f == Vec3::ZERO;
    let zero_pdf = |p: &f32| *p == 0.0;
    for bad in bad_directions() {
        let key = rand::Rng::next_u64(&mut rng);
        nothing_or_debug_panic(
            &format!("{label}: eval(wo = {bad})"),
            || b.eval_keyed(bad, good_i, key),
            zero_f,
        );
        nothing_or_debug_panic(
            &format!("{label}: eval(wi = {bad})"),
            || b.eval_keyed(good_o, bad, key),
            zero_f,
        );
        let s = &format!("{label}: sample(wo = {bad})");
        nothing_or_debug_panic(s, || b.sample(bad, 0.3, Vec2::new(0.6, 0.2)), Option::is_none);
        nothing_or_debug_panic(&format!("{label}: pdf(wo = {bad})"), || b.pdf(bad, good_i), zero_pdf);
        nothing_or_debug_panic(&format!("{label}: pdf(wi = {bad})"), || b.pdf(good_o, bad), zero_pdf);
        let both = &format!("{label}: eval_with_pdf(wi = {bad})");
        nothing_or_debug_panic(both, || b.eval_with_pdf(good_o, bad), |(v, p)| zero_f(v) && *p == 0.0);
    }
    for (uc, u) in [
        (1.0, Vec2::new(0.5, 0.5)),
        (-0.1, Vec2::new(0.5, 0.5)),
        (0.5, Vec2::new(f32::NAN, 0.5)),
        (0.5, Vec2::new(0.5, 1.0)),
        (f32::INFINITY, Vec2::ZERO),
    ] {
        let s = &format!("{label}: sample(uc = {uc}, u = {u})");
        nothing_or_debug_panic(s, || b.sample(good_o, uc, u), Option::is_none);
    }
    for h in horizon_directions() {
        assert_eq!(b.eval_rng(good_o, h, &mut rng).f, Vec3::ZERO, "{label}: eval(wi = {h})");
        assert!(b.sample_rng(h, &mut rng).is_none(), "{label}: sample(wo = {h})");
        assert_eq!(b.pdf(h, good_i), 0.0, "{label}: pdf(wo = {h})");
        assert_eq!(b.pdf(good_o, h), 0.0, "{label}: pdf(wi = {h})");
    }
    if reflection_only {
        for _ in 0..50 {
            let (below, above) =
                (-dir(0.3 + 1.2 * uniform64(&mut rng), 6.0 * uniform64(&mut rng)), dir(0.7, 1.0));
            assert_eq!(b.eval_rng(above, below, &mut rng).f, Vec3::ZERO, "{label}: wi below {below}");
            assert_eq!(b.pdf(above, below), 0.0, "{label}: pdf at wi below {below}");
            if !backfacing_view_valid {
                assert_eq!(b.eval_rng(below, above, &mut rng).f, Vec3::ZERO, "{label}: wo below {below}");
                assert_eq!(b.pdf(below, above), 0.0, "{label}: pdf for wo below {below}");
                assert!(b.sample_rng(below, &mut rng).is_none(), "{label}: sample for wo below {below}");
            }
        }
    }
    // random and nearly grazing directions: everything finite
    let grazing = [1e-7f32, -1e-7, 1e-4, -1e-4, 0.9999, -0.9999];
    for k in 0..200 {
        let mut wo = uniform_sphere(&mut rng);
        let mut wi = uniform_sphere(&mut rng);
        if k < 36 {
            let (zo, zi) = (grazing[k % 6], grazing[k / 6]);
            wo = Vec3::new((1.0 - zo * zo).sqrt(), 0.0, zo);
            wi = Vec3::new(-(1.0 - zi * zi).sqrt() * 0.6, (1.0 - zi * zi).sqrt() * 0.8, zi);
        }
        let f = b.eval_rng(wo, wi, &mut rng).f;
        assert!(f.is_finite() && f.min_element() >= 0.0, "{label}: eval({wo}, {wi}) = {f}");
        let p = b.pdf(wo, wi);
        assert!(p.is_finite() && p >= 0.0, "{label}: pdf({wo}, {wi}) = {p}");
        if let Some(s) = b.sample_rng(wo, &mut rng) {
            assert!(s.weight.is_finite() && s.weight.min_element() >= 0.0, "{label}: {s:?} for {wo}");
            assert!(s.pdf.is_finite() && s.pdf > 0.0 && s.wi.is_finite(), "{label}: {s:?} for {wo}");
        }
    }
}

struct BadInput(u64);

impl Visit for BadInput {
    fn visit<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
        &mut self,
        label: &str,
        b: &Mf<S, M>,
        _: bool,
        _: &[Vec3],
    ) {
        self.0 += 1;
        // every technique accepts backfacing views of opaque materials (tests/walk/backfacing_views.rs)
        check_bad_input(label, b, !M::TRANSMITS, true, self.0);
    }
}

#[test]
fn invalid_directions_give_zero() {
    let mut v = BadInput(6000);
    visit_all_slopes(&mut v, &ALL_TECHNIQUES);
    for ndf in [ClassicNdf::Phong(30.0), ClassicNdf::Beckmann(0.3), ClassicNdf::Ggx(0.3)] {
        for (label, b, _) in classic_models(ndf) {
            v.0 += 1;
            check_bad_input(&label, &b, true, false, v.0);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// ClassicBrdf specifics
// ---------------------------------------------------------------------------------------------

/// The documented accuracy of the rational masking: relative error below 0.5 % against the
/// exact Smith G1, for Beckmann and Phong.
#[test]
fn classic_rational_masking_is_within_half_a_percent() {
    let (kd, ks) = (Vec3::splat(0.2), Vec3::splat(0.5));
    let mut worst = 0.0f32;
    for ndf in [
        ClassicNdf::Beckmann(0.1),
        ClassicNdf::Beckmann(0.5),
        ClassicNdf::Beckmann(1.2),
        ClassicNdf::Phong(5.0),
        ClassicNdf::Phong(80.0),
    ] {
        let exact = ClassicBrdf::new(kd, ks, ndf, ClassicMasking::Exact).unwrap();
        let rational = ClassicBrdf::new(kd, ks, ndf, ClassicMasking::Rational).unwrap();
        for i in 1..2000 {
            let v = dir(f64::from(i) / 2000.0 * std::f64::consts::FRAC_PI_2, 0.4);
            let (e, r) = (exact.g1(v), rational.g1(v));
            assert!(e > 0.0 && e <= 1.0, "{ndf:?}: G1({v}) = {e}");
            worst = worst.max((r / e - 1.0).abs());
            assert!((r / e - 1.0).abs() <= 5e-3, "{ndf:?}: rational G1 {r} vs exact {e} at {v}");
        }
    }
    println!("rational masking: worst relative error {worst:.4}");
}

#[test]
fn classic_rejects_invalid_parameters() {
    let ok = (Vec3::splat(0.5), Vec3::splat(0.5));
    let m = ClassicMasking::Exact;
    assert!(ClassicBrdf::new(ok.0, ok.1, ClassicNdf::Ggx(0.3), m).is_ok());
    assert!(ClassicBrdf::new(Vec3::new(1.1, 0.0, 0.0), ok.1, ClassicNdf::Ggx(0.3), m).is_err());
    assert!(ClassicBrdf::new(ok.0, Vec3::new(0.0, f32::NAN, 0.0), ClassicNdf::Ggx(0.3), m).is_err());
    assert!(ClassicBrdf::new(ok.0, Vec3::new(0.0, -0.1, 0.0), ClassicNdf::Ggx(0.3), m).is_err());
    assert!(ClassicBrdf::new(Vec3::ZERO, Vec3::ZERO, ClassicNdf::Ggx(0.3), m).is_err());
    assert!(ClassicBrdf::new(ok.0, ok.1, ClassicNdf::Phong(-1.0), m).is_err());
    assert!(ClassicBrdf::new(ok.0, ok.1, ClassicNdf::Phong(f32::INFINITY), m).is_err());
    assert!(ClassicBrdf::new(ok.0, ok.1, ClassicNdf::Beckmann(0.0), m).is_err());
    assert!(ClassicBrdf::new(ok.0, ok.1, ClassicNdf::Ggx(f32::NAN), m).is_err());
}

#[test]
fn classic_is_reciprocal() {
    let mut rng = validation::rng(7000);
    for ndf in [ClassicNdf::Phong(30.0), ClassicNdf::Beckmann(0.3), ClassicNdf::Ggx(0.3)] {
        let b = ClassicBrdf::new(
            Vec3::new(0.3, 0.4, 0.5),
            Vec3::new(0.6, 0.5, 0.4),
            ndf,
            ClassicMasking::Rational,
        )
        .unwrap();
        for _ in 0..5000 {
            let (wo, wi) = (uniform_sphere(&mut rng), uniform_sphere(&mut rng));
            let (a, c) = (b.eval_rng(wo, wi, &mut rng).f, b.eval_rng(wi, wo, &mut rng).f);
            assert!(rel_close(a, c, 1e-5), "{ndf:?}: f({wo}, {wi}) = {a} ≠ {c}");
            assert!(a.is_finite() && a.min_element() >= 0.0);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The renderer API: object safety, determinism, decorrelation, stratified sampling
// ---------------------------------------------------------------------------------------------

/// Every BSDF of the crate, behind the object-safe trait.
fn dyn_scene() -> Vec<(String, Box<dyn Bsdf>)> {
    let mut v: Vec<(String, Box<dyn Bsdf>)> = vec![];
    for (tname, t) in ALL_TECHNIQUES {
        v.push((format!("{tname} gold"), Box::new(mf(ggx(ALPHA_MS, ALPHA_MS), gold()).with_technique(t))));
        v.push((format!("{tname} glass"), Box::new(mf(beckmann(0.4, 0.7), dielectric()).with_technique(t))));
        v.push((format!("{tname} diffuse"), Box::new(mf(ggx(ALPHA_MS, 0.3), diffuse()).with_technique(t))));
    }
    let classic =
        ClassicBrdf::new(Vec3::splat(0.3), Vec3::splat(0.5), ClassicNdf::Ggx(0.3), ClassicMasking::Exact);
    v.push(("classic".into(), Box::new(classic.unwrap())));
    v
}

/// (i) Pure functions: the same arguments give the same bits, in any order and on any
/// thread; a different key, seed or uniform gives a different stochastic estimate.
#[test]
fn identical_inputs_give_identical_bits() {
    let scene = dyn_scene();
    let mut rng = validation::rng(8000);
    let calls: Vec<(Vec3, Vec3, f32, Vec2, u64)> = (0..64)
        .map(|_| {
            let wo = uniform_sphere(&mut rng);
            let wi = uniform_sphere(&mut rng);
            let (uc, u) = (uniform32(&mut rng), Vec2::new(uniform32(&mut rng), uniform32(&mut rng)));
            (wo, wi, uc, u, rand::Rng::next_u64(&mut rng))
        })
        .collect();
    type Out = Vec<(BsdfValue, f32, Option<BsdfSample>, (BsdfValue, f32))>;
    let run = |b: &dyn Bsdf, order: &mut dyn Iterator<Item = usize>| -> Out {
        let mut out: Vec<_> = order
            .map(|k| {
                let (wo, wi, uc, u, key) = calls[k];
                (
                    k,
                    (
                        b.eval_keyed(wo, wi, key),
                        b.pdf(wo, wi),
                        b.sample_keyed(wo, uc, u, key),
                        b.eval_with_pdf_keyed(wo, wi, key),
                    ),
                )
            })
            .collect();
        out.sort_by_key(|(k, _)| *k);
        out.into_iter().map(|(_, x)| x).collect()
    };
    let sequential: Vec<Out> = scene.iter().map(|(_, b)| run(b.as_ref(), &mut (0..calls.len()))).collect();
    // the same calls in reverse order, spread over threads
    let parallel = par_map(&scene, |_, (_, b)| run(b.as_ref(), &mut (0..calls.len()).rev()));
    for ((label, b), (s, p)) in scene.iter().zip(sequential.iter().zip(&parallel)) {
        assert!(format!("{s:?}") == format!("{p:?}"), "{label}: results depend on order or thread");
        let stochastic = !b.eval(dir(0.5, 0.1), dir(0.7, 2.0)).exact;
        for (k, (v, pdf, smp, (v2, pdf2))) in s.iter().enumerate() {
            // eval_with_pdf is eval and pdf
            assert_eq!(v.f.to_array().map(f32::to_bits), v2.f.to_array().map(f32::to_bits), "{label}");
            assert_eq!(pdf.to_bits(), pdf2.to_bits(), "{label}: call {k}");
            if let Some(smp) = smp {
                assert!(smp.weight.is_finite() && smp.pdf > 0.0, "{label}: {smp:?}");
            }
        }
        if stochastic {
            // another key gives another estimate (somewhere among the calls)
            let differs = calls.iter().any(|&(wo, wi, _, _, key)| {
                let a = b.eval_keyed(wo, wi, key);
                a.f != Vec3::ZERO && a != b.eval_keyed(wo, wi, key ^ 1)
            });
            assert!(differs, "{label}: the key does not reach the estimator");
        }
    }
    // with_seed reaches the estimator, and the sample's later bounces
    let walk = mf(ggx(ALPHA_MS, ALPHA_MS), Conductor::perfect());
    let (wo, wi) = (dir(0.7, 0.4), dir(0.9, 2.5));
    assert_ne!(walk.eval(wo, wi), walk.with_seed(1).eval(wo, wi));
    let samples = |b: &Mf<Ggx, Conductor>| -> Vec<Option<BsdfSample>> {
        (0..32).map(|k| b.sample(wo, 0.5, Vec2::new(k as f32 / 32.0, 0.3))).collect()
    };
    assert_ne!(samples(&walk), samples(&walk.with_seed(1)), "the seed does not reach the walk");
}

/// Uniforms of a stratified design of `n` = `side`² points: u on a jittered `side` × `side`
/// grid, uc a jittered Latin-hypercube coordinate (a random permutation of the n strata).
fn stratified_uniforms(side: usize, rng: &mut TestRng) -> Vec<(f32, Vec2)> {
    let n = side * side;
    let mut perm: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        let j = (rand::Rng::next_u64(rng) % (i as u64 + 1)) as usize;
        perm.swap(i, j);
    }
    let cell = |k: usize, m: usize, rng: &mut TestRng| {
        ((k as f64 + uniform64(rng)) / m as f64).min(1.0 - 1e-7) as f32
    };
    (0..n)
        .map(|i| {
            let u = Vec2::new(cell(i % side, side, rng), cell(i / side, side, rng));
            (cell(perm[i], n, rng), u)
        })
        .collect()
}

/// (ii) Unbiased with hashed seeds: over many (wo, wi) pairs, the albedo ∫ eval·|cos θi| dωi
/// estimated by importance sampling (the proposal of `proposal_sample`, independent of
/// `Bsdf::sample`) equals the research layer's albedo E[weight] of its own walks with an
/// ordinary generator (importance transport: no η² factor). Every call of `eval` has a
/// distinct (wo, wi) and key 0: the estimates are decorrelated by the hash of the directions
/// alone.
#[test]
fn hashed_eval_is_unbiased_over_many_pairs() {
    const N: usize = 80_000;
    let views = [dir(0.2, 0.3), dir(0.8, 1.0), dir(1.3, 4.0)];
    let techniques = [
        ("walk", Technique::RandomWalk),
        ("pf-pt-corr", PT_CORRELATED),
        ("pf-bdpt-uncorr", BDPT_UNCORRELATED),
    ];
    let z = family_z(0.01, views.len() * techniques.len() * 2);
    let cases: Vec<(usize, usize, bool)> = (0..views.len())
        .flat_map(|v| (0..techniques.len()).flat_map(move |t| [(v, t, false), (v, t, true)]))
        .collect();
    par_map(&cases, |i, &(v, t, glass)| {
        let wo = views[v];
        let (tname, technique) = techniques[t];
        let mut rng = validation::rng(8100 + i as u64);
        let (albedo, reference) = if glass {
            let b = mf(ggx(ALPHA_MS, ALPHA_MS), dielectric())
                .with_technique(technique)
                .with_transport(Transport::Importance);
            (key0_albedo(&b, wo, N, &mut rng), research_albedo(&b, wo, N, &mut rng))
        } else {
            let b = mf(ggx(ALPHA_MS, ALPHA_MS), gold()).with_technique(technique);
            (key0_albedo(&b, wo, N, &mut rng), research_albedo(&b, wo, N, &mut rng))
        };
        let label = format!("{tname} {} wo = {wo}", if glass { "glass" } else { "gold" });
        println!(
            "{label}: hashed eval {:.5} ± {:.5}, research walks {:.5} ± {:.5}",
            albedo.mean(),
            albedo.se(),
            reference.mean(),
            reference.se()
        );
        assert_two_sample(&label, &albedo, &reference, z, MAX_REL_SE * reference.mean().max(0.25));
    });
}

/// ∫ eval·|cos θi| dωi (channel mean) from `n` proposal directions, every eval with key 0.
fn key0_albedo<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
    b: &Mf<S, M>,
    wo: Vec3,
    n: usize,
    rng: &mut TestRng,
) -> Stats {
    let mut st = Stats::default();
    for _ in 0..n {
        let w = proposal_sample(b, wo, rng);
        let p = proposal_pdf(b, wo, w);
        let f = b.eval(wo, w).f;
        st.push(if p > 0.0 { f64::from(f.element_sum()) / 3.0 * f64::from(w.z.abs()) / p } else { 0.0 });
    }
    st
}

/// The research layer's albedo: the channel-mean weight of its own samples (the walk's for
/// the random walk, the position-free walk's otherwise) with an ordinary generator.
fn research_albedo<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
    b: &Mf<S, M>,
    wo: Vec3,
    n: usize,
    rng: &mut TestRng,
) -> Stats {
    let pf = |sh| microsurface::PositionFree::new(*b.surface().slope(), *b.surface().material(), sh);
    let mut st = Stats::default();
    for _ in 0..n {
        let s = match b.technique() {
            Technique::PositionFree { shadowing, .. } => pf(shadowing).sample(wo, rng),
            _ => b.surface().sample(wo, rng),
        };
        st.push(s.map_or(0.0, |s| f64::from(s.weight.element_sum()) / 3.0));
    }
    st
}

/// (iii) The stochastic techniques' `sample`, driven by stratified uniforms (the caller's
/// sampler) and the hashed generator after the first bounce, follows the density
/// E[eval]·|cos θi| (non-absorptive materials in importance transport: weights 1).
#[test]
fn stochastic_sample_with_stratified_uniforms_passes_chi_square() {
    use validation::stochastic::stochastic_chi2;
    const SIDE: usize = 224; // 50 176 samples
    let cases = [
        ("walk conductor", false, Technique::RandomWalk),
        ("pf-pt-corr glass", true, PT_CORRELATED),
        ("walk glass", true, Technique::RandomWalk),
    ];
    let alpha_test = sidak(0.01, cases.len());
    let p = par_map(&cases, |i, &(label, glass, t)| {
        let wo = dir(0.6, 0.8);
        let mut rng = validation::rng(8200 + i as u64);
        let uniforms = stratified_uniforms(SIDE, &mut rng);
        let run = |b: &dyn Bsdf, z_lo: f64, nz: usize| {
            let mut key = 0u64;
            let mut it = uniforms.iter();
            stochastic_chi2(
                label,
                z_lo,
                nz,
                16,
                &mut |wi: Vec3| {
                    key += 1;
                    f64::from(b.eval_keyed(wo, wi, key).f.x) * f64::from(wi.z.abs())
                },
                &mut || {
                    let &(uc, u) = it.next().expect("one design point per sample");
                    let s = b.sample(wo, uc, u)?;
                    assert_eq!(s.weight, Vec3::ONE, "{label}: non-absorptive weights are 1");
                    Some(s.wi)
                },
                uniforms.len(),
                alpha_test,
            )
            .p_value
        };
        if glass {
            let b = mf(ggx(0.5, 0.5), dielectric()).with_technique(t).with_transport(Transport::Importance);
            run(&b, -1.0, 16)
        } else {
            run(&mf(ggx(0.5, 0.5), Conductor::perfect()).with_technique(t), 0.0, 8)
        }
    });
    println!("stratified stochastic sampling: p-values {p:.4?} (per-test α = {alpha_test:.2e})");
}

/// (iv) An orthographic view of a plane under a directional light: every pixel evaluates the
/// same (wo, wi). With key 0 every pixel gets the same estimate (bit for bit): the image mean
/// carries the error of one estimate. With the pixel index as key the pixels are independent:
/// over R images (BSDF seeds 0..R) the variance of the image mean is σ²/P, which the
/// statistic T = P·Var(image means)/mean(within-image variance) ≈ 1 checks (T(R − 1) is
/// approximately χ²(R − 1)); the same statistic for key 0 is ≈ P and rejects.
#[test]
fn pixel_keys_decorrelate_repeated_directions() {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    const PIXELS: usize = 64;
    const IMAGES: usize = 120;
    let b = mf(ggx(ALPHA_MS, ALPHA_MS), gold());
    let (wo, wi) = (dir(0.7, 0.4), dir(0.9, 2.5));
    let estimate =
        |b: &Mf<Ggx, Conductor>, key: u64| f64::from(b.eval_keyed(wo, wi, key).f.element_sum()) / 3.0;
    let (mut keyed_means, mut unkeyed_means, mut within) =
        (Stats::default(), Stats::default(), Stats::default());
    for r in 0..IMAGES {
        let b = b.with_seed(r as u64);
        let keyed: Vec<f64> = (0..PIXELS).map(|p| estimate(&b, p as u64)).collect();
        let unkeyed: Vec<f64> = (0..PIXELS).map(|_| estimate(&b, 0)).collect();
        assert!(unkeyed.iter().all(|&x| x.to_bits() == unkeyed[0].to_bits()), "key 0: pixels differ");
        let mut st = Stats::default();
        keyed.iter().for_each(|&x| st.push(x));
        keyed_means.push(st.mean());
        within.push(st.std().powi(2));
        unkeyed_means.push(unkeyed[0]);
    }
    let sigma2 = within.mean();
    assert!(sigma2 > 0.0, "keyed pixels are all equal");
    let t = |means: &Stats| PIXELS as f64 * means.std().powi(2) / sigma2;
    let (t_keyed, t_unkeyed) = (t(&keyed_means), t(&unkeyed_means));
    let dof = (IMAGES - 1) as f64;
    let critical = ChiSquared::new(dof).unwrap().inverse_cdf(1.0 - sidak(0.01, 2)) / dof;
    println!(
        "T keyed = {t_keyed:.3}, T key 0 = {t_unkeyed:.3} (critical {critical:.3}, σ² = {sigma2:.4e}, P = {PIXELS}, R = {IMAGES})"
    );
    assert!(
        t_keyed <= critical,
        "pixel keys: image means vary {t_keyed:.2}× more than independent pixels would"
    );
    assert!(
        t_unkeyed > critical,
        "key 0: T = {t_unkeyed:.2} does not show the correlation (test without power)"
    );
    // and the keyed image is an unbiased estimate: its mean against the research walk's
    let mut reference = Stats::default();
    let mut rng = validation::rng(8300);
    for _ in 0..200_000 {
        let f = b.surface().eval(wo, wi, ScatteringOrder::All, &mut rng);
        reference.push(f64::from(f.element_sum()) / 3.0 / f64::from(wi.z));
    }
    let mut all = Stats::default();
    for r in 0..IMAGES {
        let b = b.with_seed(r as u64);
        (0..PIXELS).for_each(|p| all.push(estimate(&b, p as u64)));
    }
    assert_two_sample(
        "orthographic plane, keyed pixels",
        &all,
        &reference,
        family_z(0.01, 1),
        0.02 * reference.mean(),
    );
}

// ---------------------------------------------------------------------------------------------
// What an integrator needs: flags, η, the specular limit, the roughness range
// ---------------------------------------------------------------------------------------------

#[test]
fn flags_describe_the_lobes() {
    let rough = |f: BsdfFlags| f.glossy && !f.specular && f.has_non_specular();
    for (_, t) in ALL_TECHNIQUES {
        let f = mf(ggx(0.3, 0.3), gold()).with_technique(t).flags();
        assert!(f.reflection && !f.transmission && rough(f) && !f.diffuse, "gold {t:?}: {f:?}");
        let f = mf(ggx(0.3, 0.3), dielectric()).with_technique(t).flags();
        assert!(f.reflection && f.transmission && rough(f), "glass {t:?}: {f:?}");
        let f = mf(ggx(0.3, 0.3), diffuse()).with_technique(t).flags();
        assert!(
            f.reflection && !f.transmission && f.diffuse && !f.glossy && !f.specular,
            "diffuse {t:?}: {f:?}"
        );
        // diffuse facets have no specular limit
        let f = mf(ggx(1e-4, 1e-4), diffuse()).with_technique(t).flags();
        assert!(f.diffuse && !f.specular, "smooth diffuse {t:?}: {f:?}");
    }
    let c = ClassicBrdf::new(Vec3::splat(0.3), Vec3::splat(0.5), ClassicNdf::Ggx(0.3), ClassicMasking::Exact)
        .unwrap();
    let f = c.flags();
    assert!(f.reflection && !f.transmission && f.diffuse && f.glossy && !f.specular, "{f:?}");
    let c =
        ClassicBrdf::new(Vec3::splat(0.3), Vec3::ZERO, ClassicNdf::Ggx(0.3), ClassicMasking::Exact).unwrap();
    assert!(c.flags().diffuse && !c.flags().glossy);
}

/// The relative index of a sample: η entering the dielectric, 1/η leaving it, 1 for a
/// reflection, and consistent with the side of wi.
#[test]
fn samples_carry_the_relative_index() {
    let mut rng = validation::rng(8400);
    let (mut entering, mut leaving, mut reflected) = (0, 0, 0);
    for (_, t) in ALL_TECHNIQUES {
        let b = mf(ggx(ALPHA_MS, ALPHA_MS), dielectric()).with_technique(t);
        for wo in [view_out(), view_in()] {
            for _ in 0..400 {
                let Some(s) = b.sample_rng(wo, &mut rng) else { continue };
                let expected = match (wo.z > 0.0, s.wi.z > 0.0) {
                    (true, false) => {
                        entering += 1;
                        ETA
                    }
                    (false, true) => {
                        leaving += 1;
                        1.0 / ETA
                    }
                    _ => {
                        reflected += 1;
                        1.0
                    }
                };
                assert!(
                    (s.eta - expected).abs() <= 1e-6 * expected,
                    "{t:?} wo {wo}: η = {} for wi {}",
                    s.eta,
                    s.wi
                );
            }
        }
        let g = mf(ggx(ALPHA_MS, ALPHA_MS), gold()).with_technique(t);
        let s = g.sample(view_out(), 0.5, Vec2::new(0.3, 0.6)).unwrap();
        assert_eq!(s.eta, 1.0);
    }
    assert!(entering > 100 && leaving > 100 && reflected > 100, "{entering} {leaving} {reflected}");
}

/// An opaque BSDF seen from below its shading hemisphere keeps its rough lobe across
/// `SMOOTH_ALPHA`: the albedo of GGX gold at θo = 100° just below the threshold equals the one
/// just above it (both ≈ 0.94; the Dirac limit made it 0), for the walk and single scattering.
#[test]
fn backfacing_views_keep_their_lobe_across_smooth_alpha() {
    use microsurface::SMOOTH_ALPHA;
    const N: usize = 6_000;
    let wo = dir(100f64.to_radians(), 0.3);
    let cases = [("walk", Technique::RandomWalk), ("single", Technique::SingleScattering)];
    let z = family_z(1e-3, cases.len());
    for (k, (tname, t)) in cases.into_iter().enumerate() {
        let stats = [0.99, 1.01].map(|f| {
            let b = mf(ggx(f * SMOOTH_ALPHA, f * SMOOTH_ALPHA), gold()).with_technique(t);
            let mut rng = validation::rng(8600 + k as u64);
            let mut st = Stats::default();
            for _ in 0..N {
                st.push(b.sample_rng(wo, &mut rng).map_or(0.0, |s| f64::from(s.weight.x)));
            }
            st
        });
        assert!(stats[1].mean() > 0.5, "{tname}: albedo above the threshold {}", stats[1].mean());
        assert_two_sample(&format!("{tname}: albedo across SMOOTH_ALPHA"), &stats[0], &stats[1], z, 0.01);
    }
}

/// Both sides of `SMOOTH_ALPHA`: just below, a conductor and a dielectric are Dirac lobes for
/// every technique (eval and pdf 0, the mirror and refraction directions with Fresnel
/// weights, `specular` flags, the event probabilities as pdf); just above, they are glossy
/// and sample near those directions with a density.
#[test]
fn the_specular_limit_below_smooth_alpha() {
    use microsurface::{SMOOTH_ALPHA, fresnel_dielectric};
    let below = SMOOTH_ALPHA * 0.9;
    let above = SMOOTH_ALPHA * 1.1;
    let wo = dir(0.6, 0.4);
    let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
    let f_glass = fresnel_dielectric(wo.z, ETA);
    let mut rng = validation::rng(8500);
    for (tname, t) in ALL_TECHNIQUES {
        // conductor
        let b = mf(ggx(below, 0.5 * below), gold()).with_technique(t);
        assert!(b.flags().specular && !b.flags().glossy && !b.flags().has_non_specular(), "{tname}");
        let s = b.sample_rng(wo, &mut rng).expect("a mirror reflects");
        assert_eq!(s.wi, mirror, "{tname}");
        assert!(rel_close(s.weight, gold().fresnel(wo.z), 1e-6), "{tname}: weight {}", s.weight);
        assert!(s.flags.specular && s.flags.reflection && s.pdf == 1.0 && s.eta == 1.0, "{tname}: {s:?}");
        assert_eq!(b.eval(wo, mirror).f, Vec3::ZERO);
        assert_eq!(b.pdf(wo, mirror), 0.0);
        // seen from below the shading hemisphere (a normal map) the rough lobe answers: its
        // visible facets are the distribution's tails, which do not shrink as α → 0
        let from_below = b.sample(-wo, 0.5, Vec2::splat(0.5));
        assert!(from_below.is_none_or(|s| !s.flags.specular), "{tname}: {from_below:?}");
        // dielectric: reflection with probability F, refraction (Snell) otherwise
        let d = mf(ggx(below, below), dielectric()).with_technique(t);
        assert!(d.flags().specular && d.flags().transmission && d.flags().reflection, "{tname}");
        let n = 4000;
        let mut refracted = 0;
        for k in 0..n {
            let uc = (k as f32 + 0.5) / n as f32;
            let s = d.sample(wo, uc, Vec2::new(0.3, 0.7)).expect("a smooth interface scatters");
            assert!(s.flags.specular && s.flags.exact_pdf, "{tname}: {s:?}");
            if s.flags.reflection {
                assert_eq!(s.wi, mirror);
                assert!((s.pdf - f_glass).abs() <= 1e-6 && s.weight == Vec3::ONE && s.eta == 1.0, "{s:?}");
            } else {
                refracted += 1;
                // tangential components −wo/η, radiance scaled by 1/η²
                let t_expected = -Vec2::new(wo.x, wo.y) / ETA;
                assert!((Vec2::new(s.wi.x, s.wi.y) - t_expected).length() <= 1e-6 && s.wi.z < 0.0, "{s:?}");
                assert!((s.wi.length() - 1.0).abs() <= 1e-6);
                assert!((s.pdf - (1.0 - f_glass)).abs() <= 1e-6 && s.eta == ETA, "{s:?}");
                assert!(rel_close(s.weight, Vec3::splat(1.0 / (ETA * ETA)), 1e-6), "{s:?}");
            }
            assert_eq!(d.pdf(wo, s.wi), 0.0);
            assert_eq!(d.eval(wo, s.wi).f, Vec3::ZERO);
        }
        // stratified uc: the refracted share is 1 − F up to the grid's resolution
        let share = refracted as f32 / n as f32;
        assert!(
            (share - (1.0 - f_glass)).abs() <= 1.0 / n as f32,
            "{tname}: refracted {share}, 1 − F = {}",
            1.0 - f_glass
        );
        // just above the threshold: glossy, near the specular directions, with a density
        for (label, rough) in [
            ("gold", &mf(ggx(above, above), gold()) as &dyn Bsdf),
            ("glass", &mf(ggx(above, above), dielectric())),
        ] {
            let _ = label;
            assert!(!rough.flags().specular && rough.flags().glossy, "{tname} {label}");
        }
        let rough = mf(ggx(above, above), gold()).with_technique(t);
        let s = rough.sample_rng(wo, &mut rng).expect("gold reflects");
        assert!(!s.flags.specular && s.pdf > 0.0, "{tname}: {s:?}");
        assert!(s.wi.dot(mirror) > 0.999, "{tname}: {} far from the mirror direction", s.wi);
        assert!(rough.eval(wo, s.wi).f.max_element() > 0.0 || t != Technique::SingleScattering, "{tname}");
        assert!(rough.pdf(wo, s.wi) > 0.0, "{tname}");
    }
}

/// An index-matched dielectric (η = 1) is a Dirac transmission at every roughness: light
/// passes straight through with weight 1, and eval and pdf are 0.
#[test]
fn index_matched_dielectric_is_a_specular_transmission() {
    let mut rng = validation::rng(8600);
    for (tname, t) in ALL_TECHNIQUES {
        let b = mf(ggx(0.5, 0.5), Dielectric::new(1.0).unwrap()).with_technique(t);
        let f = b.flags();
        assert!(f.specular && f.transmission && !f.reflection && !f.has_non_specular(), "{tname}: {f:?}");
        for wo in [view_out(), view_in()] {
            let s = b.sample_rng(wo, &mut rng).expect("light passes through");
            assert!((s.wi + wo).length() <= 1e-6, "{tname}: wi = {} for wo = {wo}", s.wi);
            assert!(s.weight == Vec3::ONE && s.pdf == 1.0 && s.eta == 1.0, "{tname}: {s:?}");
            assert!(s.flags.specular && s.flags.transmission && !s.flags.reflection, "{tname}: {s:?}");
            for _ in 0..20 {
                let w = uniform_sphere(&mut rng);
                assert_eq!(b.eval(wo, w).f, Vec3::ZERO);
                assert_eq!(b.pdf(wo, w), 0.0);
            }
            assert_eq!(b.pdf(wo, s.wi), 0.0);
        }
    }
}

/// α above `MAX_WALK_ALPHA` is rejected (walks grow linearly with α); up to it accepted.
#[test]
fn roughness_above_the_walk_range_is_rejected() {
    use microsurface::{Error, MAX_WALK_ALPHA};
    assert!(MicrofacetBsdf::new(ggx(MAX_WALK_ALPHA, 0.1), gold()).is_ok());
    for a in [MAX_WALK_ALPHA * 1.01, 1e6] {
        for r in [
            MicrofacetBsdf::new(ggx(a, 0.5), gold()).err(),
            MicrofacetBsdf::new(beckmann(0.5, a), diffuse()).err(),
        ] {
            match r {
                Some(Error::InvalidParameter { name: "alpha", value, .. }) => assert_eq!(value, a),
                other => panic!("α = {a}: {other:?}"),
            }
        }
    }
}

/// Single scattering uses the caller's uniforms directly: `u` is the visible-normal sample
/// (`sample_d_wi(wo, u.x, u.y)`, the reflection about it) and `uc` the Fresnel event of a
/// dielectric (reflection iff uc < F(wo·m)). Uniforms on the 2⁻²⁴ grid the crate draws on
/// are passed through exactly.
#[test]
fn single_scattering_sample_is_driven_by_the_callers_uniforms() {
    use microsurface::fresnel_dielectric;
    let grid = |x: f32| (x * 16_777_216.0).floor() / 16_777_216.0;
    let slope = ggx(0.4, 0.25);
    let gold_b = mf(slope, gold()).with_technique(Technique::SingleScattering);
    let glass_b = mf(slope, dielectric()).with_technique(Technique::SingleScattering);
    let mut rng = validation::rng(8700);
    let (mut reflections, mut refractions) = (0, 0);
    for _ in 0..2000 {
        let wo = dir(1.4 * uniform64(&mut rng), 2.0 * PI * uniform64(&mut rng));
        let u = Vec2::new(grid(uniform32(&mut rng)), grid(uniform32(&mut rng)));
        let uc = grid(uniform32(&mut rng));
        let m = slope.sample_d_wi(wo, u.x, u.y);
        let mirror = 2.0 * wo.dot(m) * m - wo;
        if let Some(s) = gold_b.sample(wo, uc, u) {
            assert!((s.wi - mirror).length() <= 1e-5, "wo {wo}, u {u}: wi {} ≠ reflection {mirror}", s.wi);
        }
        let f = fresnel_dielectric(wo.dot(m), ETA);
        if let Some(s) = glass_b.sample(wo, uc, u) {
            let reflected = s.wi.z > 0.0;
            // a reflection at the facet m is the mirror direction; near F the rounding of the
            // threshold may differ
            if (uc - f).abs() > 1e-5 {
                assert_eq!(reflected, uc < f, "wo {wo}, uc {uc}, F {f}: event");
            }
            if reflected {
                reflections += 1;
                assert!((s.wi - mirror).length() <= 1e-5, "{} ≠ {mirror}", s.wi);
            } else {
                refractions += 1;
            }
        }
    }
    assert!(reflections > 50 && refractions > 500, "{reflections} reflections, {refractions} refractions");
}
