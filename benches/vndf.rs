//! All visible-normal samplers side by side on the same inputs (Tokuyoshi's comparison):
//! GGX by spherical caps (the crate's default), the bounded caps of Eto and Tokuyoshi 2023
//! (reflections; target at most 1.15× the spherical cap), Heitz's 2018 disk and the V-cavity model;
//! Beckmann by the safeguarded log-space inversion (default), the erf-domain Newton method and
//! the V-cavity model. One call per iteration on 1024 pre-generated (direction, uniforms)
//! pairs from a fixed seed, rotated behind `black_box`. `MICROSURFACE_BENCH_CLOCK=cpu` times
//! the thread's CPU time (`validation::clock`), which leaves out preemption on a loaded machine.
//!
//! Benchmark ids: `vndf/{sampler}/a{α}/t{θi}`; the cost of elliptical anisotropy (a rotated
//! ellipse against the axis-aligned one of the same radii, 0.5 × 0.1, θi = 0.9):
//! `elliptical/{d,lambda,sample_d_wi}/{ggx,beckmann}/{aligned,rotated}`.

use core::f32::consts::TAU;
use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use microsurface::slope::{AxisAlignedSlope, MicrosurfaceSlope};
use microsurface::vndf::{
    BeckmannNewton, GgxBoundedCap, GgxDisk, GgxSphericalCap, SmithVndf, VCavity, VisibleNormalSampler,
};
use microsurface::{Beckmann, Elliptical, Ggx};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;
use validation::clock::{Clock, config};

/// Pre-generated inputs per configuration (a power of two).
const N: usize = 1024;
/// Roughnesses compared.
const ALPHAS: [f32; 2] = [0.05, 0.5];
/// Incident polar angles compared (radians).
const THETAS: [f32; 2] = [0.3, 1.4];

fn inputs(theta: f32, seed: u64) -> Vec<(Vec3, [f32; 3])> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..N)
        .map(|_| {
            let phi = TAU * rng.random::<f32>();
            let (s, c) = theta.sin_cos();
            (Vec3::new(s * phi.cos(), s * phi.sin(), c), [rng.random(), rng.random(), rng.random()])
        })
        .collect()
}

fn bench_sampler<V: VisibleNormalSampler>(c: &mut Criterion<Clock>, name: &str, make: impl Fn(f32) -> V) {
    let mut group = c.benchmark_group("vndf");
    for (k, &a) in ALPHAS.iter().enumerate() {
        for (j, &t) in THETAS.iter().enumerate() {
            let sampler = make(a);
            let data = inputs(t, 7_000 + 10 * k as u64 + j as u64);
            let mut i = 0usize;
            group.bench_function(format!("{name}/a{a}/t{t}"), |b| {
                b.iter(|| {
                    let (wi, u) = data[i & (N - 1)];
                    i = i.wrapping_add(1);
                    black_box(sampler.sample(black_box(wi), black_box(u)))
                })
            });
        }
    }
    group.finish();
}

fn samplers(c: &mut Criterion<Clock>) {
    let ggx = |a: f32| Ggx::isotropic(a).expect("valid α");
    let beckmann = |a: f32| Beckmann::isotropic(a).expect("valid α");
    bench_sampler(c, "ggx_spherical_cap", |a| GgxSphericalCap(ggx(a)));
    bench_sampler(c, "ggx_bounded_cap", |a| GgxBoundedCap(ggx(a)));
    bench_sampler(c, "ggx_disk", |a| GgxDisk(ggx(a)));
    bench_sampler(c, "ggx_vcavity", |a| VCavity(ggx(a)));
    bench_sampler(c, "beckmann_safeguarded", |a| SmithVndf(beckmann(a)));
    bench_sampler(c, "beckmann_newton", |a| BeckmannNewton(beckmann(a)));
    bench_sampler(c, "beckmann_vcavity", |a| VCavity(beckmann(a)));
}

/// D, Λ and `sample_d_wi` of one slope on the pre-generated inputs.
fn bench_slope<S: MicrosurfaceSlope>(c: &mut Criterion<Clock>, name: &str, slope: S) {
    let mut group = c.benchmark_group("elliptical");
    let data = inputs(0.9, 7_100);
    let mut i = 0usize;
    group.bench_function(format!("d/{name}"), |b| {
        b.iter(|| {
            // a direction of the upper hemisphere as the normal
            let wm = data[i & (N - 1)].0;
            i = i.wrapping_add(1);
            black_box(slope.d(black_box(wm)))
        })
    });
    group.bench_function(format!("lambda/{name}"), |b| {
        b.iter(|| {
            let w = data[i & (N - 1)].0;
            i = i.wrapping_add(1);
            black_box(slope.lambda(black_box(w)))
        })
    });
    group.bench_function(format!("sample_d_wi/{name}"), |b| {
        b.iter(|| {
            let (wi, u) = data[i & (N - 1)];
            i = i.wrapping_add(1);
            black_box(slope.sample_d_wi(black_box(wi), black_box(u[0]), black_box(u[1])))
        })
    });
    group.finish();
}

fn elliptical_pair<S: AxisAlignedSlope>(c: &mut Criterion<Clock>, family: &str) {
    let (a1, a2, phi) = (0.5, 0.1, 0.6);
    bench_slope(c, &format!("{family}/aligned"), S::axis_aligned(a1, a2).expect("valid radii"));
    bench_slope(
        c,
        &format!("{family}/rotated"),
        Elliptical::<S>::from_ellipse(a1, a2, phi).expect("valid ellipse"),
    );
}

fn elliptical(c: &mut Criterion<Clock>) {
    elliptical_pair::<Ggx>(c, "ggx");
    elliptical_pair::<Beckmann>(c, "beckmann");
}

criterion_group! {
    name = benches;
    config = config();
    targets = samplers, elliptical
}
criterion_main!(benches);
