//! The hard cap `MAX_BOUNCES` of the random walk removes less than 1e-4 of the albedo for
//! α ≤ 2 (the claim of its documentation).
//!
//! For non-absorptive materials (perfect conductor, white diffuse, dielectric lit from
//! outside and from inside) every walk carries weight 1, and `sample` returns `None` only
//! when a walk reaches the cap, so the fraction of the albedo the cap removes is the
//! probability of `None`. With k capped walks out of N, its one-sided Clopper–Pearson upper
//! confidence bound at level 1 − α (Šidák-corrected over the configurations) must be below
//! 1e-4. The test reports the mean number of bounces and the fraction of walks longer than
//! 64 bounces (the truncation of `tests/walk.rs`'s order sum).
mod common;

use common::{Stats, TestRng};
use glam::Vec3;
use microsurface::{
    Beckmann, Conductor, Dielectric, Diffuse, GaussianHeight, Ggx, MAX_BOUNCES, Material, Microsurface,
    MicrosurfaceHeight, MicrosurfaceSlope, UniformHeight, WalkSample,
};
use statrs::distribution::{Beta, ContinuousCDF};

const ALPHA: f32 = 2.0;
const N: usize = 100_000;
const BOUND: f64 = 1e-4;

fn walks<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
    surface: Microsurface<H, S, M>,
    wi: Vec3,
    rng: &mut TestRng,
) -> (usize, Stats, usize) {
    let (mut capped, mut bounces, mut long) = (0, Stats::default(), 0);
    for _ in 0..N {
        match surface.sample(wi, rng) {
            None => capped += 1,
            Some(WalkSample { weight, bounces: b, .. }) => {
                assert_eq!(weight, Vec3::ONE, "non-absorptive weight");
                assert!((1..=MAX_BOUNCES).contains(&b));
                bounces.push(f64::from(b));
                long += usize::from(b > 64);
            }
        }
    }
    (capped, bounces, long)
}

/// One-sided Clopper–Pearson upper bound of a binomial proportion (k successes of n).
fn upper_bound(k: usize, n: usize, alpha: f64) -> f64 {
    if k == n {
        return 1.0;
    }
    if k == 0 {
        return 1.0 - alpha.powf(1.0 / n as f64);
    }
    Beta::new(k as f64 + 1.0, (n - k) as f64).unwrap().inverse_cdf(1.0 - alpha)
}

#[derive(Clone, Copy, Debug)]
enum Mat {
    Conductor,
    Diffuse,
    Dielectric,
    DielectricInside,
}

fn run_one<H: MicrosurfaceHeight, S: MicrosurfaceSlope>(
    h: H,
    s: S,
    m: Mat,
    theta: f64,
    seed: u64,
) -> (usize, Stats, usize) {
    let mut rng = common::rng(seed);
    let wi = common::dir(theta, 0.7);
    match m {
        Mat::Conductor => walks(Microsurface::new(h, s, Conductor::perfect()), wi, &mut rng),
        Mat::Diffuse => walks(Microsurface::new(h, s, Diffuse::white()), wi, &mut rng),
        Mat::Dielectric => walks(Microsurface::new(h, s, Dielectric::new(1.5).unwrap()), wi, &mut rng),
        Mat::DielectricInside => walks(Microsurface::new(h, s, Dielectric::new(1.5).unwrap()), -wi, &mut rng),
    }
}

#[test]
fn cap_removes_less_than_1e4_of_the_albedo() {
    // (material, Gaussian heights?, Beckmann?, θi): every material with both heights and both
    // slopes, at normal and grazing incidence
    let mut cases = Vec::new();
    for (k, m) in
        [Mat::Conductor, Mat::Diffuse, Mat::Dielectric, Mat::DielectricInside].into_iter().enumerate()
    {
        for gaussian in [false, true] {
            for beckmann in [false, true] {
                let theta =
                    if (k + usize::from(gaussian) + usize::from(beckmann)) % 2 == 0 { 0.0 } else { 1.5 };
                cases.push((m, gaussian, beckmann, theta));
            }
        }
    }
    let alpha = common::sidak(0.01, cases.len());
    let results: Vec<_> = std::thread::scope(|scope| {
        let handles: Vec<_> = cases
            .chunks(cases.len().div_ceil(2))
            .enumerate()
            .map(|(t, chunk)| {
                scope.spawn(move || {
                    chunk
                        .iter()
                        .enumerate()
                        .map(|(j, &(m, gaussian, beckmann, theta))| {
                            let seed = 7000 + (t * 100 + j) as u64;
                            let ggx = Ggx::isotropic(ALPHA).unwrap();
                            let beck = Beckmann::isotropic(ALPHA).unwrap();
                            match (gaussian, beckmann) {
                                (false, false) => run_one(UniformHeight, ggx, m, theta, seed),
                                (false, true) => run_one(UniformHeight, beck, m, theta, seed),
                                (true, false) => run_one(GaussianHeight, ggx, m, theta, seed),
                                (true, true) => run_one(GaussianHeight, beck, m, theta, seed),
                            }
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().unwrap()).collect()
    });
    let mut worst: f64 = 0.0;
    let mut total_capped = 0;
    for (&(m, gaussian, beckmann, theta), (capped, bounces, long)) in cases.iter().zip(&results) {
        let bound = upper_bound(*capped, N, alpha);
        worst = worst.max(bound);
        total_capped += capped;
        let label = format!(
            "{m:?}, {} heights, {}, α = {ALPHA}, θi = {theta}{}",
            if gaussian { "Gaussian" } else { "uniform" },
            if beckmann { "Beckmann" } else { "GGX" },
            if matches!(m, Mat::DielectricInside) { " (from inside)" } else { "" }
        );
        println!(
            "{label}: {capped} capped of {N} (upper bound {bound:.2e}), mean bounces {:.3} (σ̂ = {:.2}), longer than 64: {long}",
            bounces.mean(),
            bounces.std()
        );
        assert!(
            bound < BOUND,
            "{label}: the cap removes up to {bound:.2e} of the albedo (k = {capped}, N = {N}, level {alpha:.2e})"
        );
        assert!(bounces.mean() >= 1.0 && bounces.mean().is_finite());
    }
    // the bound is attainable with the sample size: it is not vacuous
    assert!(upper_bound(0, N, alpha) < BOUND);
    println!(
        "cap: {} configurations × {N} walks, {total_capped} capped, worst upper bound {worst:.2e}",
        cases.len()
    );
}
