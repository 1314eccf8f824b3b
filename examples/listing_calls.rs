//! A profiling driver for the random walks in the configurations of the supplement's listing
//! timing (`benches/walk.rs`'s `listing/` group: uniform heights, α = 0.5, ωi at θ = 0.5,
//! ωo at θ = 0.8, φ = 3.5, fixed): runs `calls` evaluations or samples of one configuration,
//! for instruction counts under `valgrind --tool=callgrind` (run it with two call counts and
//! take the difference per call, which removes the start-up cost).
//!
//! Usage: `listing_calls {conductor|diffuse|dielectric} {ggx|beckmann} {eval|sample} calls`

use microsurface::glam::Vec3;
use microsurface::rand::SeedableRng;
use microsurface::{
    Beckmann, Conductor, Dielectric, Diffuse, Ggx, Material, Microsurface, MicrosurfaceSlope,
    ScatteringOrder, UniformHeight,
};
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;

/// The unit direction with polar angle `theta` and azimuth `phi` (rounded from f64, as the
/// listing's driver does).
fn spherical(theta: f64, phi: f64) -> Vec3 {
    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32)
}

fn run<S: MicrosurfaceSlope, M: Material>(slope: S, material: M, what: &str, calls: u64) -> f64 {
    let surface = Microsurface::new(UniformHeight, slope, material);
    let (wi, wo) = (spherical(0.5, 0.0), spherical(0.8, 3.5));
    let mut rng = Pcg64Mcg::seed_from_u64(6000);
    let mut sum = 0.0f64;
    for _ in 0..calls {
        sum += f64::from(match what {
            "eval" => {
                black_box(&surface).eval(black_box(wi), black_box(wo), ScatteringOrder::All, &mut rng).x
            }
            "sample" => black_box(&surface).sample(black_box(wi), &mut rng).map_or(0.0, |s| s.weight.x),
            _ => panic!("eval or sample, not {what}"),
        });
    }
    sum / calls as f64
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, material, slope, what, calls] = &args[..] else {
        panic!("usage: listing_calls {{conductor|diffuse|dielectric}} {{ggx|beckmann}} {{eval|sample}} calls")
    };
    let calls: u64 = calls.parse().expect("a call count");
    let ggx = Ggx::isotropic(0.5).expect("valid roughness");
    let beckmann = Beckmann::isotropic(0.5).expect("valid roughness");
    let dielectric = Dielectric::new(1.5).expect("valid index");
    let mean = match (material.as_str(), slope.as_str()) {
        ("conductor", "ggx") => run(ggx, Conductor::perfect(), what, calls),
        ("diffuse", "ggx") => run(ggx, Diffuse::white(), what, calls),
        ("dielectric", "ggx") => run(ggx, dielectric, what, calls),
        ("conductor", "beckmann") => run(beckmann, Conductor::perfect(), what, calls),
        ("diffuse", "beckmann") => run(beckmann, Diffuse::white(), what, calls),
        ("dielectric", "beckmann") => run(beckmann, dielectric, what, calls),
        _ => panic!("unknown configuration {material} {slope}"),
    };
    println!("{material}/{slope}/{what}: {calls} calls, mean {mean}");
}
