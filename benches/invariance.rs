//! Benchmarks of the invariance-principle estimator (`Invariance`, Cui et al. 2023) beside the
//! estimators of the same and the neighbouring models at the same configurations: its `eval`
//! (all orders) and `sample`, the Heitz walk's (`Microsurface`, the model it estimates), and
//! the position-free PT and BDPT evaluations (Wang et al. 2022, height-correlated).
//!
//! One call per iteration. ωi is fixed per configuration (azimuth 0); the ωo of `eval` are
//! pre-generated from a fixed seed, uniform on the upper hemisphere, and rotated through with
//! a wrapping counter behind `std::hint::black_box`. The estimators' random numbers come from a
//! seeded `Pcg64Mcg` that runs on across iterations.
//!
//! Configurations: perfect conductors (F = 1), GGX and Beckmann, (α, θi) ∈ {(0.1, 0),
//! (0.5, 0.5), (1, 1), (0.5, 1.5)}, and the configuration of the paper's released test scene
//! (copper, GGX α = 0.5; here at θi = 0.5).
//!
//! Benchmark ids: `invariance/{material}/{slope}/{estimator}/{eval|sample}/a{α}/t{θi}` with
//! estimator ∈ {invariance, walk, pt-corr, bdpt-corr} (`sample` for invariance and walk).

use core::f32::consts::TAU;
use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use microsurface::research::{
    Estimator, Invariance, Microsurface, PositionFree, ScatteringOrder, Shadowing, UniformHeight,
};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, ComplexIor, Conductor, Ggx};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;

use validation::clock::{Clock, config};

/// The number of pre-generated outgoing directions per benchmark (a power of two).
const N: usize = 1024;
/// (α, θi) of the perfect conductors.
const CONFIGS: [(f32, f32); 4] = [(0.1, 0.0), (0.5, 0.5), (1.0, 1.0), (0.5, 1.5)];

/// The next index of the rotation through the `N` inputs.
#[inline(always)]
fn next(i: &mut usize) -> usize {
    let k = *i & (N - 1);
    *i = i.wrapping_add(1);
    k
}

/// `N` outgoing directions uniform on the upper hemisphere (z in (0, 1]).
fn outgoing_directions(seed: u64) -> Vec<Vec3> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..N)
        .map(|_| {
            let z = 1.0 - rng.random::<f32>();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = TAU * rng.random::<f32>();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

fn bench_config<S: MicrosurfaceSlope>(
    c: &mut Criterion<Clock>,
    prefix: &str,
    material: Conductor,
    slope: S,
    (alpha, theta): (f32, f32),
    seed: u64,
) {
    let invariance = Invariance::new(slope, material).expect("a conductor");
    let walk = Microsurface::new(UniformHeight, slope, material);
    let pf = PositionFree::new(slope, material, Shadowing::Correlated);
    let wi = Vec3::new(theta.sin(), 0.0, theta.cos());
    let wo = outgoing_directions(seed);
    let id = format!("a{alpha:?}/t{theta:?}");
    let all = ScatteringOrder::All;
    let mut rng = Pcg64Mcg::seed_from_u64(seed + 1);
    let mut eval = |name: &str, f: &mut dyn FnMut(Vec3, &mut Pcg64Mcg) -> Vec3| {
        c.benchmark_group(format!("{prefix}/{name}/eval")).bench_function(&id, |b| {
            let mut i = 0;
            b.iter(|| f(black_box(wo[next(&mut i)]), &mut rng))
        });
    };
    eval("invariance", &mut |wo, rng| black_box(&invariance).eval(black_box(wi), wo, all, rng));
    eval("walk", &mut |wo, rng| black_box(&walk).eval(black_box(wi), wo, all, rng));
    eval("pt-corr", &mut |wo, rng| black_box(&pf).eval(black_box(wi), wo, Estimator::Pt, all, rng));
    eval("bdpt-corr", &mut |wo, rng| black_box(&pf).eval(black_box(wi), wo, Estimator::Bdpt, all, rng));
    let mut rng = Pcg64Mcg::seed_from_u64(seed + 2);
    c.benchmark_group(format!("{prefix}/invariance/sample"))
        .bench_function(&id, |b| b.iter(|| black_box(&invariance).sample(black_box(wi), &mut rng)));
    c.benchmark_group(format!("{prefix}/walk/sample"))
        .bench_function(&id, |b| b.iter(|| black_box(&walk).sample(black_box(wi), &mut rng)));
}

fn estimators(c: &mut Criterion<Clock>) {
    for (k, &config) in CONFIGS.iter().enumerate() {
        let ggx = Ggx::isotropic(config.0).expect("valid roughness");
        let beckmann = Beckmann::isotropic(config.0).expect("valid roughness");
        let seed = 7000 + 10 * k as u64;
        bench_config(c, "invariance/conductor/ggx", Conductor::perfect(), ggx, config, seed);
        bench_config(c, "invariance/conductor/beckmann", Conductor::perfect(), beckmann, config, seed + 5);
    }
    let copper = Conductor::new(ComplexIor::COPPER);
    let ggx = Ggx::isotropic(0.5).expect("valid roughness");
    bench_config(c, "invariance/copper/ggx", copper, ggx, (0.5, 0.5), 7100);
}

criterion_group! {
    name = benches;
    config = config();
    targets = estimators
}
criterion_main!(benches);
