//! Transport modes and generalized reciprocity.

use super::fixtures::*;
use super::weights::{Visit, view_in, view_out};

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
