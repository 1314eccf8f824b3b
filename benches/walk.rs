//! Benchmarks of the random walks: the stochastic evaluation (`eval`, all orders) and the
//! sampling (`sample`) of the multiple-scattering BSDF per material, slope, roughness and
//! incident angle, on uniform heights, and the closed-form single scattering of the conductor.
//!
//! One call per iteration. ωi is fixed per configuration (azimuth 0, the slopes are
//! isotropic); the ωo of `eval` are pre-generated from a fixed seed, uniform on the upper
//! hemisphere for the opaque materials and on the whole sphere for the dielectric, and rotated
//! through with a wrapping counter behind `std::hint::black_box`. The walk's own random
//! numbers come from a seeded `Pcg64Mcg` that runs on across iterations.
//!
//! Before each configuration's benchmarks the mean number of bounces of `sample` over
//! `BOUNCE_WALKS` walks is printed to stderr (outside the timed loops): the walk's cost is
//! about that many times the cost of one bounce.
//!
//! Benchmark ids: `{material}/{slope}/{eval|sample|single}/a{α}/t{θi}` (θi in radians), and
//! `listing/{material}/{slope}/{eval|sample|eval_inside}` for the fixed directions of the
//! supplement's listing timing (`../shared/bench/heitz2016-listing`; `benches/compare-listing.sh`).

use core::f32::consts::TAU;
use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use microsurface::research::{Material, Microsurface, ScatteringOrder, UniformHeight};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Conductor, Dielectric, Diffuse, Ggx};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;

use validation::clock::{Clock, config};

/// The number of pre-generated outgoing directions per benchmark (a power of two).
const N: usize = 1024;
/// The number of walks the mean bounce count is estimated from.
const BOUNCE_WALKS: usize = 100_000;
/// (α, θi) configurations: the 3 × 3 matrix, plus the reference configuration α = 0.5,
/// θi = 0.5 rad.
const CONFIGS: [(f32, f32); 10] = [
    (0.1, 0.0),
    (0.1, 1.0),
    (0.1, 1.5),
    (0.5, 0.0),
    (0.5, 0.5),
    (0.5, 1.0),
    (0.5, 1.5),
    (1.0, 0.0),
    (1.0, 1.0),
    (1.0, 1.5),
];

/// The next index of the rotation through the `N` inputs.
#[inline(always)]
fn next(i: &mut usize) -> usize {
    let k = *i & (N - 1);
    *i = i.wrapping_add(1);
    k
}

/// `N` outgoing directions, uniform on the upper hemisphere (or the whole sphere when
/// `transmits`), never exactly horizontal.
fn outgoing_directions(transmits: bool, seed: u64) -> Vec<Vec3> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..N)
        .map(|_| {
            // z in (0, 1], or (−1, 1] \ {0}
            let u = 1.0 - rng.random::<f32>();
            let z = if transmits {
                if u > 0.5 { 2.0 * u - 1.0 } else { 2.0 * u - 1.0 - f32::EPSILON }
            } else {
                u
            };
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = TAU * rng.random::<f32>();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

fn bench_material<S: MicrosurfaceSlope, M: Material>(
    c: &mut Criterion<Clock>,
    material_name: &str,
    material: M,
    slope_name: &str,
    make_slope: impl Fn(f32) -> S,
    single_scattering: bool,
) {
    for (k, &(alpha, theta)) in CONFIGS.iter().enumerate() {
        let surface = Microsurface::new(UniformHeight, make_slope(alpha), material);
        let wi = Vec3::new(theta.sin(), 0.0, theta.cos());
        let wo = outgoing_directions(M::TRANSMITS, 3000 + k as u64);
        let id = format!("a{alpha:?}/t{theta:?}");

        let mut rng = Pcg64Mcg::seed_from_u64(4000 + k as u64);
        let (mut bounces, mut exits) = (0u64, 0u64);
        for _ in 0..BOUNCE_WALKS {
            if let Some(s) = surface.sample(wi, &mut rng) {
                bounces += u64::from(s.bounces);
                exits += 1;
            }
        }
        eprintln!(
            "{material_name}/{slope_name}/{id}: mean bounces of sample = {:.4} ({exits}/{BOUNCE_WALKS} walks exited)",
            bounces as f64 / exits.max(1) as f64
        );

        let mut rng = Pcg64Mcg::seed_from_u64(5000 + k as u64);
        c.benchmark_group(format!("{material_name}/{slope_name}/eval")).bench_function(&id, |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(&surface).eval(black_box(wi), black_box(wo[k]), ScatteringOrder::All, &mut rng)
            })
        });
        c.benchmark_group(format!("{material_name}/{slope_name}/sample"))
            .bench_function(&id, |b| b.iter(|| black_box(&surface).sample(black_box(wi), &mut rng)));
        if single_scattering {
            c.benchmark_group(format!("{material_name}/{slope_name}/single")).bench_function(&id, |b| {
                let mut i = 0;
                b.iter(|| {
                    let k = next(&mut i);
                    black_box(&surface).eval_single_scattering(black_box(wi), black_box(wo[k]), &mut rng)
                })
            });
        }
    }
}

/// The unit direction with polar angle `theta` and azimuth `phi` (computed in double precision and
/// rounded, as the listing's timing driver does).
fn spherical(theta: f64, phi: f64) -> Vec3 {
    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32)
}

/// ωo of the listing's timing: θ = 0.8, φ = 3.5 (a reflection).
const LISTING_WO: (f64, f64) = (0.8, 3.5);
/// ωo of the listing's dielectric transmission timing: θ = π − 0.6, φ = 3.5 (seen from inside).
const LISTING_WO_INSIDE: (f64, f64) = (2.541_592_653_589_793, 3.5);

/// The configuration of `../shared/bench/heitz2016-listing` exactly: uniform heights, α = 0.5,
/// ωi at θ = 0.5 (φ = 0), ωo at `wo` (θ, φ), both fixed; one call per iteration. `sample`
/// does not depend on ωo and is benchmarked when `with_sample`.
fn bench_listing<S: MicrosurfaceSlope, M: Material>(
    c: &mut Criterion<Clock>,
    id: (&str, &str),
    material: M,
    slope: S,
    (eval_name, wo): (&str, (f64, f64)),
    with_sample: bool,
) {
    let surface = Microsurface::new(UniformHeight, slope, material);
    let (wi, wo) = (spherical(0.5, 0.0), spherical(wo.0, wo.1));
    let mut rng = Pcg64Mcg::seed_from_u64(6000);
    let mut group = c.benchmark_group(format!("listing/{}/{}", id.0, id.1));
    group.bench_function(eval_name, |b| {
        b.iter(|| black_box(&surface).eval(black_box(wi), black_box(wo), ScatteringOrder::All, &mut rng))
    });
    if with_sample {
        group.bench_function("sample", |b| b.iter(|| black_box(&surface).sample(black_box(wi), &mut rng)));
    }
    group.finish();
}

/// The listing's configurations (`benches/compare-listing.sh` prints the ratios): the six
/// materials and slopes with ωo above, and the GGX dielectric's `eval` with ωo inside
/// (`eval_inside`).
fn listing(c: &mut Criterion<Clock>) {
    let ggx = Ggx::isotropic(0.5).expect("valid roughness");
    let beckmann = Beckmann::isotropic(0.5).expect("valid roughness");
    let dielectric = Dielectric::new(1.5).expect("valid index");
    let above = ("eval", LISTING_WO);
    bench_listing(c, ("conductor", "ggx"), Conductor::perfect(), ggx, above, true);
    bench_listing(c, ("diffuse", "ggx"), Diffuse::white(), ggx, above, true);
    bench_listing(c, ("dielectric", "ggx"), dielectric, ggx, above, true);
    bench_listing(c, ("dielectric", "ggx"), dielectric, ggx, ("eval_inside", LISTING_WO_INSIDE), false);
    bench_listing(c, ("conductor", "beckmann"), Conductor::perfect(), beckmann, above, true);
    bench_listing(c, ("diffuse", "beckmann"), Diffuse::white(), beckmann, above, true);
    bench_listing(c, ("dielectric", "beckmann"), dielectric, beckmann, above, true);
}

fn walks(c: &mut Criterion<Clock>) {
    let ggx = |a| Ggx::isotropic(a).expect("valid roughness");
    let beckmann = |a| Beckmann::isotropic(a).expect("valid roughness");
    let dielectric = Dielectric::new(1.5).expect("valid index");
    bench_material(c, "conductor", Conductor::perfect(), "ggx", ggx, true);
    bench_material(c, "conductor", Conductor::perfect(), "beckmann", beckmann, true);
    bench_material(c, "dielectric", dielectric, "ggx", ggx, false);
    bench_material(c, "dielectric", dielectric, "beckmann", beckmann, false);
    bench_material(c, "diffuse", Diffuse::white(), "ggx", ggx, false);
    bench_material(c, "diffuse", Diffuse::white(), "beckmann", beckmann, false);
}

criterion_group! {
    name = benches;
    config = config();
    targets = listing, walks
}
criterion_main!(benches);
