//! Micro-benchmarks of the geometric primitives: the slope distributions (D, Λ, projected
//! area, D_ωi, visible-normal sampling) and the height sampling of the random walk.
//!
//! Every benchmark measures one call per iteration. Its inputs are pre-generated from a fixed
//! seed (`N` of them) and rotated through with a wrapping counter, behind
//! `std::hint::black_box`, so that nothing is hoisted out of the timed loop and the branch
//! predictor sees realistic variation. The counter and the load of the input add about 1 ns.
//! Successive calls are independent, so the figure is the throughput cost of a call.
//!
//! Benchmark ids: `{slope}/{function}/a{α}/t{θ}` (θ in radians: the incident direction, or
//! for `d` the direction the normals are visible from),
//! `{height}/sample_height/{slope}_a0.5/{case}` for the height sampling, and
//! `data_driven/{function}/{slope}/t{θ}`: D and `sample_d_wi` of the tabulated slopes against
//! the analytic GGX they tabulate (α = 0.5) in one group, so that their ratios come from one run.

use core::f32::consts::TAU;
use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use microsurface::research::{GaussianHeight, MicrosurfaceGeometry, MicrosurfaceHeight, UniformHeight};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::tabulated::{GridSlope, TabulatedSlope};
use microsurface::{Beckmann, Ggx};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;

use validation::clock::{Clock, config};

/// The number of pre-generated inputs per benchmark (a power of two).
const N: usize = 1024;
/// Roughnesses of the slope benchmarks.
const ALPHAS: [f32; 3] = [0.05, 0.5, 1.0];
/// Incident polar angles in radians (2.2 is below the horizon).
const THETAS: [f32; 3] = [0.3, 1.4, 2.2];

/// The next index of the rotation through the `N` inputs.
#[inline(always)]
fn next(i: &mut usize) -> usize {
    let k = *i & (N - 1);
    *i = i.wrapping_add(1);
    k
}

/// The unit direction with polar angle `theta` and azimuth `phi`.
fn direction(theta: f32, phi: f32) -> Vec3 {
    let (s, c) = theta.sin_cos();
    Vec3::new(s * phi.cos(), s * phi.sin(), c)
}

/// The pre-generated inputs of one (α, θ) configuration.
struct Inputs {
    /// Directions at polar angle θ with uniform random azimuths.
    w: Vec<Vec3>,
    /// Pairs of uniforms in [0, 1).
    u: Vec<(f32, f32)>,
    /// Normals sampled from D_ω for the ω of the same index (what `d` and `d_wi` see in a walk).
    wm: Vec<Vec3>,
}

impl Inputs {
    fn new<S: MicrosurfaceSlope>(slope: &S, theta: f32, seed: u64) -> Self {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let w: Vec<Vec3> = (0..N).map(|_| direction(theta, TAU * rng.random::<f32>())).collect();
        let u: Vec<(f32, f32)> = (0..N).map(|_| (rng.random::<f32>(), rng.random::<f32>())).collect();
        let wm = w.iter().map(|&w| slope.sample_d_wi(w, rng.random::<f32>(), rng.random::<f32>())).collect();
        Self { w, u, wm }
    }
}

fn bench_slope<S: MicrosurfaceSlope>(c: &mut Criterion<Clock>, name: &str, make: impl Fn(f32) -> S) {
    let configs: Vec<(f32, f32, S, Inputs)> = ALPHAS
        .iter()
        .flat_map(|&a| THETAS.iter().map(move |&t| (a, t)))
        .enumerate()
        .map(|(k, (a, t))| {
            let slope = make(a);
            (a, t, slope, Inputs::new(&slope, t, 1000 + k as u64))
        })
        .collect();

    let mut group = c.benchmark_group(format!("{name}/d"));
    for (a, t, slope, inputs) in &configs {
        group.bench_function(format!("a{a:?}/t{t:?}"), |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(slope).d(black_box(inputs.wm[k]))
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group(format!("{name}/lambda"));
    for (a, t, slope, inputs) in &configs {
        group.bench_function(format!("a{a:?}/t{t:?}"), |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(slope).lambda(black_box(inputs.w[k]))
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group(format!("{name}/projected_area"));
    for (a, t, slope, inputs) in &configs {
        group.bench_function(format!("a{a:?}/t{t:?}"), |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(slope).projected_area(black_box(inputs.w[k]))
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group(format!("{name}/d_wi"));
    for (a, t, slope, inputs) in &configs {
        group.bench_function(format!("a{a:?}/t{t:?}"), |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(slope).d_wi(black_box(inputs.w[k]), black_box(inputs.wm[k]))
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group(format!("{name}/sample_d_wi"));
    for (a, t, slope, inputs) in &configs {
        group.bench_function(format!("a{a:?}/t{t:?}"), |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                let (u1, u2) = black_box(inputs.u[k]);
                black_box(slope).sample_d_wi(black_box(inputs.w[k]), u1, u2)
            })
        });
    }
    group.finish();
}

fn slopes(c: &mut Criterion<Clock>) {
    bench_slope(c, "ggx", |a| Ggx::isotropic(a).expect("valid roughness"));
    bench_slope(c, "beckmann", |a| Beckmann::isotropic(a).expect("valid roughness"));
    // GGX tabulated on 256 rings at s = α (the table size of tests/tabulated/tabulated.rs); the
    // tables are leaked: the trait is implemented for `&TabulatedSlope`
    bench_slope(c, "tabulated_ggx256", |a| {
        let ggx = Ggx::isotropic(a).expect("valid roughness");
        &*Box::leak(Box::new(TabulatedSlope::from_slope(&ggx, a, 256).expect("valid table")))
    });
    // GGX on a 2D grid of 2 × 32 cells per axis
    bench_slope(c, "grid_ggx32", |a| {
        let a64 = f64::from(a);
        let ggx = move |x: f64, y: f64| {
            let t = 1.0 + (x * x + y * y) / (a64 * a64);
            1.0 / (core::f64::consts::PI * a64 * a64 * t * t)
        };
        &*Box::leak(Box::new(GridSlope::from_fn(a, a, 32, ggx).expect("valid table")))
    });
}

/// The data-driven slopes against the GGX they tabulate (α = 0.5): `d` and `sample_d_wi` in one
/// group, slope by slope for each θ, on the same inputs (normals sampled from GGX's D_ω).
fn data_driven(c: &mut Criterion<Clock>) {
    let a = 0.5f32;
    let ggx = Ggx::isotropic(a).expect("valid roughness");
    let table = TabulatedSlope::from_slope(&ggx, a, 256).expect("valid table");
    let stretched = table.stretched(0.6, 1.4).expect("valid stretch");
    let a64 = f64::from(a);
    let grid = GridSlope::from_fn(a, a, 32, move |x: f64, y: f64| {
        let t = 1.0 + (x * x + y * y) / (a64 * a64);
        1.0 / (core::f64::consts::PI * a64 * a64 * t * t)
    })
    .expect("valid table");
    let inputs: Vec<(f32, Inputs)> =
        THETAS.iter().enumerate().map(|(k, &t)| (t, Inputs::new(&ggx, t, 3000 + k as u64))).collect();
    let mut group = c.benchmark_group("data_driven");
    fn both<S: MicrosurfaceSlope>(
        group: &mut criterion::BenchmarkGroup<'_, Clock>,
        name: &str,
        slope: S,
        inputs: &[(f32, Inputs)],
    ) {
        for (t, inputs) in inputs {
            group.bench_function(format!("d/{name}/t{t:?}"), |b| {
                let mut i = 0;
                b.iter(|| {
                    let k = next(&mut i);
                    black_box(slope).d(black_box(inputs.wm[k]))
                })
            });
            group.bench_function(format!("sample_d_wi/{name}/t{t:?}"), |b| {
                let mut i = 0;
                b.iter(|| {
                    let k = next(&mut i);
                    let (u1, u2) = black_box(inputs.u[k]);
                    black_box(slope).sample_d_wi(black_box(inputs.w[k]), u1, u2)
                })
            });
        }
    }
    both(&mut group, "ggx", ggx, &inputs);
    both(&mut group, "tabulated_ggx256", &table, &inputs);
    both(&mut group, "stretched_ggx256", stretched, &inputs);
    both(&mut group, "grid_ggx32", &grid, &inputs);
    group.finish();
}

/// `sample_height` at α = 0.5: a ray arriving from above the surface (h0 = +∞, θ = 2.2 below
/// the horizon, the first bounce of every walk), and rays leaving the surface from heights
/// drawn from the height distribution at θ ∈ {0.3, 1.4, 2.2}.
fn bench_heights<H: MicrosurfaceHeight, S: MicrosurfaceSlope>(
    c: &mut Criterion<Clock>,
    height_name: &str,
    height: H,
    slope_name: &str,
    slope: S,
) {
    let geometry = MicrosurfaceGeometry::new(height, slope);
    let mut group = c.benchmark_group(format!("{height_name}/sample_height"));
    let cases =
        [("from_above_t2.2", 2.2, true), ("t0.3", 0.3, false), ("t1.4", 1.4, false), ("t2.2", 2.2, false)];
    for (k, (case, theta, from_above)) in cases.into_iter().enumerate() {
        let mut rng = Pcg64Mcg::seed_from_u64(2000 + k as u64);
        let w: Vec<Vec3> = (0..N).map(|_| direction(theta, TAU * rng.random::<f32>())).collect();
        let h0: Vec<f32> = (0..N)
            .map(|_| if from_above { f32::INFINITY } else { height.inv_c1(rng.random::<f32>()) })
            .collect();
        let u: Vec<f32> = (0..N).map(|_| rng.random::<f32>()).collect();
        group.bench_function(format!("{slope_name}_a0.5/{case}"), |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(&geometry).sample_height(black_box(w[k]), black_box(h0[k]), black_box(u[k]))
            })
        });
    }
    group.finish();
}

fn heights(c: &mut Criterion<Clock>) {
    let ggx = Ggx::isotropic(0.5).expect("valid roughness");
    let beckmann = Beckmann::isotropic(0.5).expect("valid roughness");
    bench_heights(c, "uniform_height", UniformHeight, "ggx", ggx);
    bench_heights(c, "uniform_height", UniformHeight, "beckmann", beckmann);
    bench_heights(c, "gaussian_height", GaussianHeight, "ggx", ggx);
    bench_heights(c, "gaussian_height", GaussianHeight, "beckmann", beckmann);
}

criterion_group! {
    name = benches;
    config = config();
    targets = slopes, heights, data_driven
}
criterion_main!(benches);
