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
mod common;

use common::chi2::{Chi2Grid, chi2_test};
use common::quadrature::integrate_sphere;
use common::{Stats, TestRng, assert_two_sample, dir, family_z, sidak, uniform32, uniform64};
use glam::Vec3;
use microsurface::{
    Beckmann, Bsdf, ClassicBrdf, ClassicMasking, ClassicNdf, ComplexIor, Conductor, Dielectric, Diffuse,
    Estimator, Ggx, Material, MicrofacetBsdf, MicrosurfaceSlope, ScatteringOrder, ShadingFrame, Shadowing,
    Technique, Transport, UniformHeight, sample_cosine_hemisphere,
};
use std::f64::consts::PI;

const ETA: f32 = 1.5;
/// Roughness of the multiple-scattering tests (enough for a visible second order).
const ALPHA_MS: f32 = 0.6;
/// The number of chi-square tests of this file that must pass (the Šidák family).
const CHI2_FAMILY: usize = 29;
/// Share of the single-bounce phase function in the proposal of the albedo estimates.
const PHASE_SHARE: f64 = 0.7;

type Mf<S, M> = MicrofacetBsdf<UniformHeight, S, M>;

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

/// A uniform direction on the sphere.
fn uniform_sphere(rng: &mut TestRng) -> Vec3 {
    let z = 2.0 * uniform64(rng) - 1.0;
    let phi = 2.0 * PI * uniform64(rng);
    let s = (1.0 - z * z).max(0.0).sqrt();
    glam::DVec3::new(s * phi.cos(), s * phi.sin(), z).as_vec3()
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
fn proposal_sample<S: MicrosurfaceSlope, M: Material>(b: &Mf<S, M>, wo: Vec3, rng: &mut TestRng) -> Vec3 {
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
fn proposal_pdf<S: MicrosurfaceSlope, M: Material>(b: &Mf<S, M>, wo: Vec3, w: Vec3) -> f64 {
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
fn albedo_stats<S: MicrosurfaceSlope, M: Material>(
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
        let v = b.eval(wo, w, rng);
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
        let w = match b.sample(wo, rng) {
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
                let reflection = (s.wi.z > 0.0) == (wo.z > 0.0);
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
fn is_exact<S: MicrosurfaceSlope, M: Material>(b: &Mf<S, M>) -> bool {
    b.technique() == Technique::SingleScattering && M::EXACT_PHASE_PDF
}

/// Largest combined SE allowed, relative to the albedo of the channel (floored at 0.25): a
/// bias of about 3.5 % of the albedo is detected. The stochastic `eval` estimators are heavy
/// tailed near ωi = +z (single evaluations up to ~500× the mean were seen, where
/// Λ(ωi) → 0), which sets this bound and the sample counts.
const MAX_REL_SE: f64 = 0.01;

/// E[weight] of `n_sample` samples against the albedo from `n_eval` evaluations.
#[allow(clippy::too_many_arguments)]
fn check_weight_vs_albedo<S: MicrosurfaceSlope, M: Material>(
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
    let w = weight_stats(&label, b, wo, exact, n_sample, &mut common::rng(seed));
    let mut rng = common::rng(seed + 1_000_000);
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
    fn visit<S: MicrosurfaceSlope, M: Material>(
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
    let b = MicrofacetBsdf::new(UniformHeight, slope, Conductor::perfect()).with_technique(t);
    v.visit(&label("conductor F=1"), &b, false, &out);
    v.visit(&label("gold"), &MicrofacetBsdf::new(UniformHeight, slope, gold()).with_technique(t), true, &out);
    let d = MicrofacetBsdf::new(UniformHeight, slope, dielectric()).with_technique(t);
    v.visit(&label("dielectric radiance"), &d.with_transport(Transport::Radiance), false, &both);
    v.visit(&label("dielectric importance"), &d.with_transport(Transport::Importance), false, &out);
    v.visit(
        &label("diffuse"),
        &MicrofacetBsdf::new(UniformHeight, slope, diffuse()).with_technique(t),
        true,
        &out,
    );
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
    fn visit<S: MicrosurfaceSlope, M: Material>(
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
    fn visit<S: MicrosurfaceSlope, M: Material>(
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
    let conductor = MicrofacetBsdf::new(UniformHeight, g, Conductor::perfect());
    let b = conductor.with_technique(Technique::RandomWalk).with_order(up_to(2));
    check_weight_vs_albedo("walk GGX conductor F=1 up to 2", &b, wo, false, 60_000, 60_000, 600, z);
    let b = MicrofacetBsdf::new(UniformHeight, bk, diffuse())
        .with_technique(Technique::RandomWalk)
        .with_order(only(2));
    check_weight_vs_albedo("walk Beckmann diffuse only 2", &b, wo, true, 60_000, 60_000, 602, z);
    let b = MicrofacetBsdf::new(UniformHeight, bk, gold()).with_technique(PT_CORRELATED).with_order(up_to(1));
    check_weight_vs_albedo("pf-pt-corr Beckmann gold up to 1", &b, wo, true, 60_000, 50_000, 604, z);
    let b = MicrofacetBsdf::new(UniformHeight, g, dielectric())
        .with_technique(BDPT_UNCORRELATED)
        .with_order(up_to(2));
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
    let mut rng = common::rng(seed);
    let mut eval_rng = common::rng(seed + 7);
    let out = chi2_test(
        label,
        chi2_grid(),
        |w| pdf_scale * f64::from(b.pdf(wo, w)),
        || {
            let s = b.sample(wo, &mut rng)?;
            assert!(s.flags.exact_pdf, "{label}: exact_pdf flag not set");
            let v = b.eval(wo, s.wi, &mut eval_rng);
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
            let b = MicrofacetBsdf::new(UniformHeight, g, Conductor::perfect()).with_technique(ss);
            run(chi2_exact(&format!("single {sname} F=1 θo={theta}"), &b, wo, seed, z, 1.0));
            let b = MicrofacetBsdf::new(UniformHeight, ggx(0.5, 0.5), gold()).with_technique(ss);
            run(chi2_exact(&format!("single {sname} gold θo={theta}"), &b, wo, seed + 1, z, 1.0));
        } else {
            let b = MicrofacetBsdf::new(UniformHeight, bk, Conductor::perfect()).with_technique(ss);
            run(chi2_exact(&format!("single {sname} F=1 θo={theta}"), &b, wo, seed, z, 1.0));
            let b = MicrofacetBsdf::new(UniformHeight, beckmann(0.5, 0.5), gold()).with_technique(ss);
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
                    let b = MicrofacetBsdf::new(UniformHeight, g, dielectric()).with_technique(ss);
                    chi2_exact(&label, &b.with_transport(transport), wo, seed, z, 1.0)
                } else {
                    let b = MicrofacetBsdf::new(UniformHeight, bk, dielectric()).with_technique(ss);
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

fn backfacing_bsdf<M: Material>(sname: &str, m: M) -> EitherSlope<M> {
    let ss = Technique::SingleScattering;
    if sname == "GGX" {
        (Some(MicrofacetBsdf::new(UniformHeight, ggx(0.5, 0.5), m).with_technique(ss)), None)
    } else {
        (None, Some(MicrofacetBsdf::new(UniformHeight, beckmann(0.5, 0.5), m).with_technique(ss)))
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
                albedo_stats(&label, &b, wo, true, 2_000, &mut common::rng(seed + 5))
            }
            (_, Some(b)) => {
                check_weight_vs_albedo(&label, &b, wo, true, 60_000, 60_000, seed, z);
                albedo_stats(&label, &b, wo, true, 2_000, &mut common::rng(seed + 5))
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
    let b = MicrofacetBsdf::new(UniformHeight, ggx(0.5, 0.5), Conductor::perfect())
        .with_technique(Technique::SingleScattering);
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
    fn visit<S: MicrosurfaceSlope, M: Material>(&mut self, label: &str, b: &Mf<S, M>, _: bool, _: &[Vec3]) {
        let (r, i) = (b.with_transport(Transport::Radiance), b.with_transport(Transport::Importance));
        for (k, (wo, wi)) in transport_pairs().into_iter().enumerate() {
            let ratio = eta_ratio_sq(wo, wi);
            let mut nonzero = 0;
            for seed in 0..40 {
                let fr = r.eval(wo, wi, &mut common::rng(seed));
                let fi = i.eval(wo, wi, &mut common::rng(seed));
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
                let sr = r.sample(wo, &mut common::rng(seed));
                let si = i.sample(wo, &mut common::rng(seed));
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
        let d = MicrofacetBsdf::new(UniformHeight, ggx(ALPHA_MS, ALPHA_MS), dielectric()).with_technique(t);
        TransportCheck.visit(&format!("{tname} GGX dielectric"), &d, false, &[]);
        let d = MicrofacetBsdf::new(UniformHeight, beckmann(0.3, 0.7), dielectric()).with_technique(t);
        TransportCheck.visit(&format!("{tname} Beckmann(0.3, 0.7) dielectric"), &d, false, &[]);
    }
}

/// Generalized reciprocity of the radiance BSDF, f(wo, wi)/η_wo² = f(wi, wo)/η_wi², exact for
/// single scattering (to f32 rounding, 5e-4 of f + 1e-5, over random pairs of directions; a
/// missing or misplaced η² changes f by a factor 2.25).
#[test]
fn single_scattering_is_reciprocal() {
    let mut rng = common::rng(4000);
    let ss = Technique::SingleScattering;
    let d = MicrofacetBsdf::new(UniformHeight, ggx(0.4, 0.7), dielectric()).with_technique(ss);
    let c = MicrofacetBsdf::new(UniformHeight, beckmann(0.6, 0.3), gold()).with_technique(ss);
    let eta2 = |w: Vec3| if w.z > 0.0 { 1.0 } else { ETA * ETA };
    let (mut checked_d, mut checked_c) = (0, 0);
    for _ in 0..20_000 {
        let (wo, wi) = (uniform_sphere(&mut rng), uniform_sphere(&mut rng));
        let a = d.eval(wo, wi, &mut rng).f / eta2(wo);
        let b = d.eval(wi, wo, &mut rng).f / eta2(wi);
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
            let (a, b) = (c.eval(wo, wi, &mut rng).f, c.eval(wi, wo, &mut rng).f);
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
        let mut rng = common::rng(seed);
        let mut s = Stats::default();
        for _ in 0..n {
            s.push(f(&mut rng));
        }
        let _ = label;
        s
    };
    for (tname, t) in techniques {
        let n = if t == BDPT_UNCORRELATED { 20_000 } else { 50_000 };
        let d = MicrofacetBsdf::new(UniformHeight, ggx(ALPHA_MS, ALPHA_MS), dielectric()).with_technique(t);
        for (wo, wi) in transport_pairs() {
            let label = format!("{tname} dielectric wo {wo} wi {wi}");
            let a = stats(&label, &mut |r| f64::from(d.eval(wo, wi, r).f.x) / eta2(wo), n);
            let b = stats(&label, &mut |r| f64::from(d.eval(wi, wo, r).f.x) / eta2(wi), n);
            println!("{label}: {:.5} ± {:.5} vs {:.5} ± {:.5}", a.mean(), a.se(), b.mean(), b.se());
            assert_two_sample(&label, &a, &b, z, 0.03 * a.mean().max(b.mean()));
        }
        let (wo, wi) = (dir(0.5, 0.2), dir(1.0, 2.5));
        let c = MicrofacetBsdf::new(UniformHeight, beckmann(ALPHA_MS, ALPHA_MS), gold()).with_technique(t);
        let f = MicrofacetBsdf::new(UniformHeight, ggx(ALPHA_MS, ALPHA_MS), diffuse()).with_technique(t);
        let label = format!("{tname} gold wo {wo} wi {wi}");
        let a = stats(&label, &mut |r| f64::from(c.eval(wo, wi, r).f.element_sum()), n);
        let b = stats(&label, &mut |r| f64::from(c.eval(wi, wo, r).f.element_sum()), n);
        assert_two_sample(&label, &a, &b, z, 0.03 * a.mean().max(b.mean()));
        let label = format!("{tname} diffuse wo {wo} wi {wi}");
        let a = stats(&label, &mut |r| f64::from(f.eval(wo, wi, r).f.element_sum()), n);
        let b = stats(&label, &mut |r| f64::from(f.eval(wi, wo, r).f.element_sum()), n);
        assert_two_sample(&label, &a, &b, z, 0.03 * a.mean().max(b.mean()));
    }
}

// ---------------------------------------------------------------------------------------------
// ShadingFrame
// ---------------------------------------------------------------------------------------------

#[test]
fn shading_frame_is_orthonormal_and_round_trips() {
    let mut rng = common::rng(5000);
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
fn energy_batches<S: MicrosurfaceSlope, M: Material>(
    b: &Mf<S, M>,
    wo: Vec3,
    batches: usize,
    walks: usize,
    seed: u64,
) -> (Stats, Stats) {
    let mut rng = common::rng(seed);
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
fn albedo_mean_stats<S: MicrosurfaceSlope, M: Material>(
    b: &Mf<S, M>,
    wo: Vec3,
    n: usize,
    seed: u64,
) -> Stats {
    let mut rng = common::rng(seed);
    let mut st = Stats::default();
    for _ in 0..n {
        let w = proposal_sample(b, wo, &mut rng);
        let p = proposal_pdf(b, wo, w);
        let f = b.eval(wo, w, &mut rng).f;
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

    let b = MicrofacetBsdf::new(UniformHeight, g, gold());
    let (total, first) = energy_batches(&b.with_technique(walk), wo, 20, 3000, 5100);
    check("walk GGX gold: total", &total, &albedo_mean_stats(&b.with_technique(walk), wo, 60_000, 5101));
    check("walk GGX gold: order 1", &first, &albedo_mean_stats(&b.with_technique(ss), wo, 60_000, 5102));
    // single scattering tabulates the random walk
    let (total_ss, _) = energy_batches(&b.with_technique(ss), wo, 20, 3000, 5103);
    assert_two_sample("single GGX gold: table of the walk", &total_ss, &total, z, 0.01);

    let b = MicrofacetBsdf::new(UniformHeight, bk, diffuse()).with_technique(walk);
    let (total, _) = energy_batches(&b, wo, 20, 3000, 5110);
    check("walk Beckmann diffuse: total", &total, &albedo_mean_stats(&b, wo, 60_000, 5111));

    // the table ignores the transport factor: compare with importance transport
    let b = MicrofacetBsdf::new(UniformHeight, g, dielectric())
        .with_technique(walk)
        .with_transport(Transport::Importance);
    let (total, _) = energy_batches(&b, wo, 20, 3000, 5120);
    check("walk GGX dielectric: total", &total, &albedo_mean_stats(&b, wo, 60_000, 5121));

    let b = MicrofacetBsdf::new(UniformHeight, bk, gold()).with_technique(BDPT_UNCORRELATED);
    let (total, _) = energy_batches(&b, wo, 20, 3000, 5130);
    check("pf-bdpt-uncorr Beckmann gold: total", &total, &albedo_mean_stats(&b, wo, 30_000, 5131));
}

// ---------------------------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------------------------

/// Invalid directions: zero, NaN, infinite, non-unit, on the horizon.
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
        Vec3::X,
        Vec3::new(0.6, -0.8, 0.0),
    ]
}

/// Zero f, zero pdf and no sample for invalid directions; zero below the surface for
/// reflection-only models (`backfacing_view_valid`: single scattering accepts backfacing
/// views, see the normal-mapping tests); finite, non-negative values for random and grazing
/// directions.
fn check_bad_input<B: Bsdf>(
    label: &str,
    b: &B,
    reflection_only: bool,
    backfacing_view_valid: bool,
    seed: u64,
) {
    let mut rng = common::rng(seed);
    let (good_o, good_i) = (dir(0.6, 0.3), dir(0.8, 2.0));
    for bad in bad_directions() {
        for _ in 0..3 {
            assert_eq!(b.eval(bad, good_i, &mut rng).f, Vec3::ZERO, "{label}: eval(wo = {bad})");
            assert_eq!(b.eval(good_o, bad, &mut rng).f, Vec3::ZERO, "{label}: eval(wi = {bad})");
            assert!(b.sample(bad, &mut rng).is_none(), "{label}: sample(wo = {bad})");
        }
        assert_eq!(b.pdf(bad, good_i), 0.0, "{label}: pdf(wo = {bad})");
        assert_eq!(b.pdf(good_o, bad), 0.0, "{label}: pdf(wi = {bad})");
    }
    if reflection_only {
        for _ in 0..50 {
            let (below, above) =
                (-dir(0.3 + 1.2 * uniform64(&mut rng), 6.0 * uniform64(&mut rng)), dir(0.7, 1.0));
            assert_eq!(b.eval(above, below, &mut rng).f, Vec3::ZERO, "{label}: wi below {below}");
            assert_eq!(b.pdf(above, below), 0.0, "{label}: pdf at wi below {below}");
            if !backfacing_view_valid {
                assert_eq!(b.eval(below, above, &mut rng).f, Vec3::ZERO, "{label}: wo below {below}");
                assert_eq!(b.pdf(below, above), 0.0, "{label}: pdf for wo below {below}");
                assert!(b.sample(below, &mut rng).is_none(), "{label}: sample for wo below {below}");
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
        let f = b.eval(wo, wi, &mut rng).f;
        assert!(f.is_finite() && f.min_element() >= 0.0, "{label}: eval({wo}, {wi}) = {f}");
        let p = b.pdf(wo, wi);
        assert!(p.is_finite() && p >= 0.0, "{label}: pdf({wo}, {wi}) = {p}");
        if let Some(s) = b.sample(wo, &mut rng) {
            assert!(s.weight.is_finite() && s.weight.min_element() >= 0.0, "{label}: {s:?} for {wo}");
            assert!(s.pdf.is_finite() && s.pdf > 0.0 && s.wi.is_finite(), "{label}: {s:?} for {wo}");
        }
    }
}

struct BadInput(u64);

impl Visit for BadInput {
    fn visit<S: MicrosurfaceSlope, M: Material>(&mut self, label: &str, b: &Mf<S, M>, _: bool, _: &[Vec3]) {
        self.0 += 1;
        // every technique accepts backfacing views of opaque materials (tests/backfacing_views.rs)
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
    let mut rng = common::rng(7000);
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
            let (a, c) = (b.eval(wo, wi, &mut rng).f, b.eval(wi, wo, &mut rng).f);
            assert!(rel_close(a, c, 1e-5), "{ndf:?}: f({wo}, {wi}) = {a} ≠ {c}");
            assert!(a.is_finite() && a.min_element() >= 0.0);
        }
    }
}
