//! Stochastic models: E[weight] equals the albedo ∫ f·|cos θi| dωi, estimated independently by
//! importance sampling `eval` with a proposal of exactly known density, over the matrix of
//! microfacet BSDFs.

use super::fixtures::*;
use microsurface::research::{Interaction, Side};

/// The proposal of the albedo estimates: with probability `PHASE_SHARE` the single-bounce
/// phase function of the material seen from `wo` (conductors and dielectrics, whose phase
/// density is exact), otherwise a cosine lobe above (opaque) or on a random side
/// (dielectric). Diffuse facets use the cosine lobe only.
pub(crate) fn proposal_sample<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
    b: &Mf<S, M>,
    wo: Vec3,
    rng: &mut TestRng,
) -> Vec3 {
    let (s, m) = (b.surface().slope(), b.surface().material());
    if M::EXACT_PHASE_PDF && uniform64(rng) < PHASE_SHARE {
        // wo.z < 0 for an opaque material is a backfacing view (normal mapping): its phase
        // function is still the reflection about a visible normal
        let outside = wo.z > 0.0 || !M::TRANSMITS;
        return m.sample_phase(s, wo, side(outside), rng).wo;
    }
    let w = sample_cosine_hemisphere(uniform32(rng), uniform32(rng));
    if M::TRANSMITS && uniform64(rng) < 0.5 { -w } else { w }
}

/// The exact density of `proposal_sample` (both phase mechanisms of a dielectric summed).
pub(crate) fn proposal_pdf<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
    b: &Mf<S, M>,
    wo: Vec3,
    w: Vec3,
) -> f64 {
    let (s, m) = (b.surface().slope(), b.surface().material());
    let cosine = if M::TRANSMITS { f64::from(w.z).abs() / (2.0 * PI) } else { f64::from(w.z).max(0.0) / PI };
    if !M::EXACT_PHASE_PDF {
        return cosine;
    }
    let out = wo.z > 0.0 || !M::TRANSMITS;
    let mut phase = f64::from(m.pdf_phase(s, &Interaction::new(wo, w, side(out), side(out))));
    if M::TRANSMITS {
        phase += f64::from(m.pdf_phase(s, &Interaction::new(wo, w, side(out), side(!out))));
    }
    PHASE_SHARE * phase + (1.0 - PHASE_SHARE) * cosine
}

/// Per-channel statistics of the albedo ∫ eval·|cos θi| dωi from `n` proposal samples.
pub(crate) fn albedo_stats<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
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
pub(crate) const MAX_REL_SE: f64 = 0.01;

/// E[weight] of `n_sample` samples against the albedo from `n_eval` evaluations.
#[allow(clippy::too_many_arguments)]
pub(crate) fn check_weight_vs_albedo<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
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
pub(crate) fn view_out() -> Vec3 {
    dir(0.7, 0.4)
}

pub(crate) fn view_in() -> Vec3 {
    -dir(0.6, 2.0)
}

/// What a test does with each microfacet BSDF of the matrix.
pub(crate) trait Visit {
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

pub(crate) fn visit_all_slopes(v: &mut impl Visit, techniques: &[(&str, Technique)]) {
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

/// The side of the interface for the test tables' `outside` flags.
fn side(outside: bool) -> Side {
    if outside { Side::Outside } else { Side::Inside }
}
