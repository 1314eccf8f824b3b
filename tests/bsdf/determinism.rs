//! The renderer API: object safety, determinism, decorrelation, stratified sampling.

use super::fixtures::*;
use super::weights::{MAX_REL_SE, proposal_pdf, proposal_sample};

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
    let wo = dir(0.7, 0.4);
    // the walk's first order is exact (its next-event masking in closed form), so one call
    // gives the same value for both seeds wherever both walks end after one bounce (about half
    // the time): the seed must change the estimate of some of 16 calls
    let differs = (0..16).any(|k| {
        let wi = dir(0.9, 2.5 + 0.1 * k as f64);
        walk.eval(wo, wi) != walk.with_seed(1).eval(wo, wi)
    });
    assert!(differs, "the seed does not reach the walk's estimate");
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
    // N = 320 000 (SE about 6.5e-4 at 0.63): at 80 000 uncorrelated BDPT gold at the first view
    // once read 3.45 SE high; 24 independent seeds at 80 000 (SD of the means 0.00144) and
    // 3 × 10⁶ samples (0.6296 ± 0.0002 against 0.6299) found no bias, so the test is the
    // stronger one (SE halved), not a looser bound (DESIGN.md, “Determinism and the seed hash”)
    const N: usize = 320_000;
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
    let pf =
        |sh| microsurface::research::PositionFree::new(*b.surface().slope(), *b.surface().material(), sh);
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
