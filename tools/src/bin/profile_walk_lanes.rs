//! A profiling driver of the random walk in lanes (`Microsurface::sample_batch`) against the
//! scalar walk (`Microsurface::sample`), GGX α = 0.5, views uniform on the upper hemisphere (the
//! throughput example's walk rows): runs `queries` walks, for instruction counts under
//! `valgrind --tool=callgrind`. Run it with two query counts (multiples of 4096) and take the
//! difference per query, which removes the start-up cost.
//!
//! Usage: `profile_walk_lanes {lanes|scalar} {gold|mirror} queries`

use microsurface::glam::Vec3;
use microsurface::research::{Material, Microsurface, UniformHeight, WalkOutputs};
use microsurface::{ComplexIor, Conductor, Directions, Ggx};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;

/// Queries per batch call.
const BATCH: usize = 4096;

fn run<M: Material>(material: M, lanes: bool, queries: usize) -> u64 {
    let surface = Microsurface::new(UniformHeight, Ggx::isotropic(0.5).expect("valid"), material);
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(7);
    let wi: Vec<Vec3> = (0..BATCH)
        .map(|_| {
            let z: f32 = rng.random::<f32>().max(1e-3);
            let phi = core::f32::consts::TAU * rng.random::<f32>();
            let s = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(s * phi.cos(), s * phi.sin(), z)
        })
        .collect();
    let (x, y, z): (Vec<f32>, Vec<f32>, Vec<f32>) = (
        wi.iter().map(|w| w.x).collect(),
        wi.iter().map(|w| w.y).collect(),
        wi.iter().map(|w| w.z).collect(),
    );
    let dirs = Directions::new(&x, &y, &z).expect("equal lengths");
    let mut out = vec![0.0f32; 6 * BATCH];
    let mut bounces = vec![0u32; BATCH];
    let mut total = 0u64;
    for b in 0..queries / BATCH {
        if lanes {
            let (wo, weight) = out.split_at_mut(3 * BATCH);
            let (a, rest) = wo.split_at_mut(BATCH);
            let (bb, c) = rest.split_at_mut(BATCH);
            let (d, rest) = weight.split_at_mut(BATCH);
            let (e, f) = rest.split_at_mut(BATCH);
            let mut o = WalkOutputs {
                wo: microsurface::Channels::new(a, bb, c),
                weight: microsurface::Channels::new(d, e, f),
                bounces: &mut bounces,
            };
            surface.sample_batch(&dirs, b as u64, &mut o).expect("lengths");
            total += bounces.iter().map(|&n| u64::from(n)).sum::<u64>();
        } else {
            for w in &wi {
                total += black_box(&surface).sample(*w, &mut rng).map_or(0, |s| u64::from(s.bounces));
            }
        }
    }
    total
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, mode, material, queries] = &args[..] else {
        panic!("usage: profile_walk_lanes {{lanes|scalar}} {{gold|mirror}} queries")
    };
    let queries: usize = queries.parse().expect("a query count");
    let lanes = mode == "lanes";
    let bounces = match material.as_str() {
        "gold" => run(Conductor::new(ComplexIor::GOLD), lanes, queries),
        "mirror" => run(Conductor::perfect(), lanes, queries),
        _ => panic!("gold or mirror, not {material}"),
    };
    println!("{mode} {material}: {queries} walks, {bounces} bounces");
}
