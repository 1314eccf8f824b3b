//! `NoncentralBsdf`: the renderer-facing single-scattering BSDF of a sheared microsurface
//! (Dupuy 2015, eqs. 3.2–3.4) with a conductor, and `LeadrLobe::bsdf`.
//!
//! * χ² of `sample` against `pdf` (with the weight = eval·cos θi/pdf check of every sample,
//!   ∫pdf ≤ 1 and the refusals matching 1 − ∫pdf: `densities::chi2_exact`) over mean slopes up
//!   to θn = 72°, roughness 0.15–0.5, ρ up to 0.9, views from normal to grazing, including a
//!   view behind the tilted mean plane.
//! * `eval` is `Noncentral::eval_single_scattering(wo, wi) / cos θi` bit for bit, `pdf` is
//!   `Noncentral::pdf_single_scattering(wo, wi)` bit for bit, and both agree with the formula
//!   F D G1 G1/(4 cos θo cos θi) assembled from the public D, G1 and Fresnel (relative 1e-5).
//! * Determinism, flags, reciprocity, invalid input (`invalid_directions::check_bad_input`)
//!   and the constructor's rejection of an unrepresentable mean slope.

use super::densities::chi2_exact;
use super::fixtures::*;
use super::invalid_directions::check_bad_input;
use microsurface::Elliptical;
use microsurface::leadr::{LeadrLobe, Noncentral, NoncentralBsdf, NoncentralMasking, SlopeMoments};

/// The number of chi-square tests of `noncentral_sampling_matches_pdf` (part of
/// `CHI2_FAMILY`).
pub(crate) const NONCENTRAL_CHI2_TESTS: usize = 7;

type Ell<S> = Elliptical<S>;

fn bsdf<S: MicrosurfaceSlope>(slope: S, mean: Vec2, conductor: Conductor) -> NoncentralBsdf<S> {
    NoncentralBsdf::new(Noncentral::new(slope, mean).unwrap(), conductor).unwrap()
}

fn ell_beckmann(ax: f32, ay: f32, rho: f32) -> Ell<Beckmann> {
    Ell::<Beckmann>::from_bivariate(ax, ay, rho).unwrap()
}

fn ell_ggx(ax: f32, ay: f32, rho: f32) -> Ell<Ggx> {
    Ell::<Ggx>::from_bivariate(ax, ay, rho).unwrap()
}

/// A LEADR lobe: mean slope (0.3, 0.2), Σ = [[0.02, 0.01], [0.01, 0.045]] (αx = 0.2,
/// αy = 0.3, ρ = 1/3).
fn leadr_lobe() -> LeadrLobe {
    let (mx, my) = (0.3f32, 0.2f32);
    let m = SlopeMoments::new(mx, my, 0.02 + mx * mx, 0.045 + my * my, 0.01 + mx * my).unwrap();
    LeadrLobe::from_moments(&m)
}

#[test]
fn noncentral_sampling_matches_pdf() {
    let z = family_z(0.01, NONCENTRAL_CHI2_TESTS);
    let mut masses = vec![];
    fn one<B: Bsdf>(masses: &mut Vec<f64>, z: f64, label: &str, b: &B, wo: Vec3, seed: u64) {
        let (_, mass) = chi2_exact(label, b, wo, seed, z, 1.0);
        // behind the mean plane most reflections leave below the base plane (∫pdf = 0.044):
        // ~9000 of the 200 000 samples still land, and the refusals are tested
        let min_mass = if label.contains("behind") { 0.02 } else { 0.3 };
        assert!(mass > min_mass, "{label}: ∫pdf = {mass}: the chi-square test would be nearly vacuous");
        masses.push(mass);
    }
    let b = bsdf(ell_beckmann(0.3, 0.2, 0.5), Vec2::new(0.4, -0.1), Conductor::perfect());
    one(
        &mut masses,
        z,
        "noncentral Beckmann (0.3, 0.2, ρ 0.5), x̃n (0.4, −0.1), θo 0.5",
        &b,
        dir(0.5, 0.6),
        7000,
    );
    let b = bsdf(ggx(0.4, 0.4), Vec2::new(1.5, 0.5), gold());
    one(&mut masses, z, "noncentral GGX 0.4, x̃n (1.5, 0.5), θo 0.8", &b, dir(0.8, 2.5), 7010);
    let b = bsdf(ell_beckmann(0.15, 0.4, -0.7), Vec2::new(-2.0, 1.0), Conductor::perfect());
    one(
        &mut masses,
        z,
        "noncentral Beckmann (0.15, 0.4, ρ −0.7), x̃n (−2, 1), θo 1.2",
        &b,
        dir(1.2, -0.4),
        7020,
    );
    let b = bsdf(ell_ggx(0.5, 0.25, 0.9), Vec2::new(3.0, 0.0), gold());
    one(&mut masses, z, "noncentral GGX (0.5, 0.25, ρ 0.9), x̃n (3, 0), θo 1.4", &b, dir(1.4, 3.0), 7030);
    // c = cos θo − sin θo x̃n < 0: the view lies behind the tilted mean plane
    let b = bsdf(ell_beckmann(0.4, 0.3, 0.2), Vec2::new(2.0, 0.0), Conductor::perfect());
    let wo = dir(1.2, 0.0);
    assert!(wo.z - 2.0 * wo.x < 0.0);
    one(
        &mut masses,
        z,
        "noncentral Beckmann (0.4, 0.3, ρ 0.2), x̃n (2, 0), behind the mean plane",
        &b,
        wo,
        7040,
    );
    let b = bsdf(ggx(0.3, 0.3), Vec2::new(0.5, 0.5), gold());
    one(&mut masses, z, "noncentral GGX 0.3, x̃n (0.5, 0.5), grazing θo 1.45", &b, dir(1.45, 4.0), 7050);
    let b = leadr_lobe().bsdf(gold()).unwrap();
    one(&mut masses, z, "LeadrLobe::bsdf, θo 0.9", &b, dir(0.9, 1.0), 7060);
    assert_eq!(masses.len(), NONCENTRAL_CHI2_TESTS);
}

/// The models of the value tests.
/// A model of the value tests: its label and its `checked` at (wo, wi).
type ValueModel = (&'static str, Box<dyn Fn(Vec3, Vec3) -> Checked>);

fn value_models() -> Vec<ValueModel> {
    let a = bsdf(ell_beckmann(0.3, 0.2, 0.5), Vec2::new(0.4, -0.1), gold());
    let b = bsdf(ell_ggx(0.5, 0.25, 0.9), Vec2::new(3.0, 0.0), gold());
    let c = bsdf(ggx(0.2, 0.2), Vec2::new(-1.0, 2.0), gold());
    vec![
        ("Beckmann x̃n (0.4, −0.1)", Box::new(move |wo, wi| checked(&a, wo, wi))),
        ("GGX ρ 0.9 x̃n (3, 0)", Box::new(move |wo, wi| checked(&b, wo, wi))),
        ("GGX 0.2 x̃n (−1, 2)", Box::new(move |wo, wi| checked(&c, wo, wi))),
    ]
}

/// What `checked` compares: (eval, pdf) of the BSDF, of the research layer, of the formula.
struct Checked {
    f: Vec3,
    pdf: f32,
    f_research: Vec3,
    pdf_research: f32,
    f_formula: [f64; 3],
    f_swapped: Vec3,
    both: (BsdfValue, f32),
}

fn checked<S: MicrosurfaceSlope>(b: &NoncentralBsdf<S>, wo: Vec3, wi: Vec3) -> Checked {
    let s = b.surface();
    let c = b.material();
    let v = b.eval(wo, wi);
    assert!(v.exact);
    let f_research = s.eval_single_scattering(c, wo, wi, &mut validation::rng(0)) / wi.z;
    // the model takes unit directions: the f32 ones renormalized in f64
    let (o, i) = (wo.as_dvec3().normalize(), wi.as_dvec3().normalize());
    let wh = (o + i).normalize();
    let fresnel = c.fresnel(i.dot(wh) as f32);
    let scalar = s.d64(wh) * f64::from(s.g1(wo)) * f64::from(s.g1(wi)) / (4.0 * f64::from(wo.z * wi.z));
    Checked {
        f: v.f,
        pdf: b.pdf(wo, wi),
        f_research,
        pdf_research: s.pdf_single_scattering(c, wo, wi),
        f_formula: fresnel.to_array().map(|x| f64::from(x) * scalar),
        f_swapped: b.eval(wi, wo).f,
        both: b.eval_with_pdf(wo, wi),
    }
}

/// eval and pdf are the research layer's, bit for bit; f matches the formula and is
/// reciprocal to 1e-5; eval_with_pdf is (eval, pdf); below the base plane everything is 0.
#[test]
fn noncentral_eval_and_pdf_match_the_research_layer() {
    let mut rng = validation::rng(7100);
    for (label, model) in value_models() {
        let mut compared = 0;
        for _ in 0..2000 {
            let (wo, wi) = (uniform_sphere(&mut rng), uniform_sphere(&mut rng));
            let r = model(wo, wi);
            assert_eq!(r.both, (BsdfValue { f: r.f, exact: true }, r.pdf), "{label}: eval_with_pdf");
            if wo.z <= 0.0 || wi.z <= 0.0 {
                assert_eq!((r.f, r.pdf), (Vec3::ZERO, 0.0), "{label}: below the base plane {wo}, {wi}");
                continue;
            }
            assert_eq!(
                r.f.to_array().map(f32::to_bits),
                r.f_research.to_array().map(f32::to_bits),
                "{label}"
            );
            assert_eq!(r.pdf.to_bits(), r.pdf_research.to_bits(), "{label}: pdf at {wo}, {wi}");
            let scale = r.f.max_element();
            if !(1e-30..=1e30).contains(&scale) {
                continue;
            }
            compared += 1;
            for (k, (&got, &want)) in r.f.to_array().iter().zip(&r.f_formula).enumerate() {
                let rel = (f64::from(got) - want).abs() / want.max(1e-300);
                assert!(rel <= 1e-5, "{label}: f[{k}] = {got}, formula {want} (rel {rel:.2e}) at {wo}, {wi}");
            }
            assert!(
                rel_close(r.f, r.f_swapped, 1e-5),
                "{label}: f(wo, wi) = {} ≠ f(wi, wo) = {}",
                r.f,
                r.f_swapped
            );
        }
        assert!(compared > 300, "{label}: only {compared} pairs compared");
    }
}

#[test]
fn noncentral_is_deterministic_and_flagged() {
    let b = bsdf(ell_beckmann(0.3, 0.2, 0.5), Vec2::new(0.4, -0.1), gold());
    let flags = b.flags();
    assert!(flags.reflection && flags.glossy && !flags.transmission && !flags.specular && !flags.diffuse);
    let mut rng = validation::rng(7200);
    let mut sampled = 0;
    for _ in 0..500 {
        let wo = uniform_sphere(&mut rng);
        let (uc, u) = (uniform32(&mut rng), Vec2::new(uniform32(&mut rng), uniform32(&mut rng)));
        let s = b.sample(wo, uc, u);
        assert_eq!(s, b.sample(wo, uc, u), "same call, same bits");
        assert_eq!(s, b.sample_keyed(wo, 1.0 - uc.max(1e-7), u, 77), "uc and the key are unused");
        let wi = uniform_sphere(&mut rng);
        assert_eq!(b.eval(wo, wi), b.eval_keyed(wo, wi, 12345));
        if let Some(s) = s {
            sampled += 1;
            assert!(wo.z > 0.0 && s.wi.z > 0.0, "{s:?} for {wo}");
            assert!(s.flags.reflection && !s.flags.transmission && !s.flags.specular && s.flags.exact_pdf);
            assert_eq!(s.eta, 1.0);
        } else if wo.z > 0.0 {
            // a refusal: the reflection about the sampled normal leaves below the base plane
            let wh = b.surface().sample_d_wi(wo, u.x, u.y);
            assert!((2.0 * wo.dot(wh) * wh - wo).z <= 1e-6, "refused a reflection above the plane at {wo}");
        }
    }
    assert!(sampled > 150, "only {sampled} samples");
}

#[test]
fn noncentral_invalid_input() {
    let models = [
        bsdf(ell_beckmann(0.3, 0.2, 0.5), Vec2::new(0.4, -0.1), gold()),
        bsdf(ell_beckmann(0.05, 0.5, -0.95), Vec2::new(-40.0, 25.0), gold()),
        bsdf(ell_beckmann(1e-3, 1e-3, 0.0), Vec2::new(1e6, -1e6), Conductor::perfect()),
    ];
    for (i, b) in models.iter().enumerate() {
        check_bad_input(&format!("noncentral #{i}"), b, true, false, 7300 + i as u64);
        let clamped = b.with_masking(NoncentralMasking::Clamped);
        check_bad_input(&format!("noncentral clamped #{i}"), &clamped, true, false, 7320 + i as u64);
    }
    let ggx_models = [bsdf(ell_ggx(0.3, 0.2, 0.5), Vec2::new(5.0, 5.0), gold())];
    check_bad_input("noncentral GGX", &ggx_models[0], true, false, 7310);
    // the squared norm of the mean slope overflows f32: rejected
    for mean in [Vec2::new(2e19, 0.0), Vec2::new(-1.5e19, 1.5e19), Vec2::new(0.0, f32::MAX)] {
        let surface = Noncentral::new(ggx(0.3, 0.3), mean).unwrap();
        let r = NoncentralBsdf::new(surface, gold());
        assert!(r.is_err(), "mean slope {mean} accepted");
    }
    let surface = Noncentral::new(ggx(0.3, 0.3), Vec2::new(1e19, 0.0)).unwrap();
    assert!(NoncentralBsdf::new(surface, gold()).is_ok(), "x̃n = 1e19 is representable");
}

/// weight = f·cos θi/pdf at the returned direction to relative 1e-5 (the documented bound;
/// the chi-square test checks 1e-4), including a view behind the mean plane and a smooth lobe,
/// for both maskings.
#[test]
fn noncentral_weight_is_f_cos_over_pdf() {
    let cases = [
        (bsdf(ell_beckmann(0.3, 0.2, 0.5), Vec2::new(0.4, -0.1), gold()), dir(0.5, 0.6)),
        (bsdf(ell_beckmann(0.15, 0.4, -0.7), Vec2::new(-2.0, 1.0), gold()), dir(1.2, -0.4)),
        (bsdf(ell_beckmann(0.4, 0.3, 0.2), Vec2::new(2.0, 0.0), gold()), dir(1.2, 0.0)),
        (bsdf(ell_beckmann(0.01, 0.01, 0.2), Vec2::new(2.0, 0.0), gold()), dir(1.4, 3.0)),
    ];
    let mut rng = validation::rng(7400);
    let both = [NoncentralMasking::BasePlane, NoncentralMasking::Clamped];
    let cases: Vec<_> =
        both.iter().flat_map(|&m| cases.iter().map(move |(b, wo)| (b.with_masking(m), *wo))).collect();
    for (i, (b, wo)) in cases.iter().enumerate() {
        let (mut worst, mut n) = (0.0f64, 0);
        for _ in 0..50_000 {
            if let Some(s) = b.sample_rng(*wo, &mut rng) {
                n += 1;
                let (v, pdf) = b.eval_with_pdf(*wo, s.wi);
                assert_eq!(pdf, s.pdf, "case {i}: the sample's pdf is pdf(wo, wi)");
                let expected = v.f * (s.wi.z / pdf);
                for k in 0..3 {
                    worst = worst.max((f64::from(expected[k]) / f64::from(s.weight[k]) - 1.0).abs());
                }
            }
        }
        println!("case {i}: {n} samples, worst |f·cos/pdf / weight − 1| = {worst:.2e}");
        assert!(n > 1000, "case {i}: only {n} samples");
        assert!(worst <= 1e-5, "case {i}: weight ≠ f·cos/pdf, worst relative error {worst:.2e}");
    }
}

/// The energy of the two maskings for a perfect conductor seen from behind the tilted mean
/// plane (α = 0.1, x̃n = (1, 0), θo = 1.2, φo = 0), at normal incidence and at θo = 0.6 towards n: the base-plane G1
/// of the thesis reflects more than it receives there (measured 5.8), the clamped masking
/// never does (every weight ≤ 1), and its f is F D min(1, G1(wo)) min(1, G1(wi))/(4 cos θo cos θi).
#[test]
fn noncentral_clamped_masking_conserves_energy() {
    const N: usize = 40_000;
    let views = [dir(1.2, 0.0), dir(0.0, 0.0), dir(0.6, PI)];
    let z = family_z(0.01, views.len() + 1);
    let base = bsdf(ggx(0.1, 0.1), Vec2::new(1.0, 0.0), Conductor::perfect());
    let clamped = base.with_masking(NoncentralMasking::Clamped);
    assert_eq!(clamped.masking(), NoncentralMasking::Clamped);
    let s = clamped.surface();
    let mut rng = validation::rng(7500);
    for (i, wo) in views.iter().enumerate() {
        let (mut e_base, mut e_clamped) = (Stats::default(), Stats::default());
        for _ in 0..N {
            let (uc, u) = (uniform32(&mut rng), Vec2::new(uniform32(&mut rng), uniform32(&mut rng)));
            e_base.push(base.sample(*wo, uc, u).map_or(0.0, |s| f64::from(s.weight.x)));
            let Some(smp) = clamped.sample(*wo, uc, u) else {
                e_clamped.push(0.0);
                continue;
            };
            let w = f64::from(smp.weight.x);
            assert!(w <= 1.0 + 1e-6, "view {i}: clamped weight {w} > 1 at wi = {}", smp.wi);
            e_clamped.push(w);
            let wi = smp.wi;
            let wh = (wo.as_dvec3() + wi.as_dvec3()).normalize();
            let g = |w: Vec3| f64::from(s.g1(w).min(1.0));
            let want = s.d64(wh) * g(*wo) * g(wi) / (4.0 * f64::from(wo.z * wi.z));
            let got = f64::from(clamped.eval(*wo, wi).f.x);
            assert!(
                (got / want - 1.0).abs() <= 1e-5,
                "view {i}: clamped f = {got}, formula {want} at wi = {wi}"
            );
        }
        println!(
            "view {i}: albedo base plane {:.4} ± {:.4}, clamped {:.4} ± {:.4} (N = {N}, z = {z:.2})",
            e_base.mean(),
            e_base.se(),
            e_clamped.mean(),
            e_clamped.se()
        );
        // behind the mean plane the clamped lobe keeps 0.0039 (the texel hides most of itself)
        assert!(e_clamped.mean() > 1e-3, "view {i}: the clamped lobe reflects nothing");
        if i == 0 {
            assert!(e_base.se() < 0.2, "view {i}: SE {} too large to tell 5.8 from 1", e_base.se());
            assert!(
                e_base.mean() - z * e_base.se() > 1.0,
                "view {i}: the base-plane albedo {} ± {} no longer exceeds 1: update the documentation",
                e_base.mean(),
                e_base.se()
            );
        }
    }
}
