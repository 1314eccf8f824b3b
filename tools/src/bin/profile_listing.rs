//! A profiling driver for the random walks in the configurations of the supplement's listing
//! timing (`benches/walk.rs`'s `listing/` group: uniform heights, α = 0.5, ωi at θ = 0.5,
//! ωo at θ = 0.8, φ = 3.5, fixed): runs `calls` evaluations or samples of one configuration,
//! for instruction counts under `valgrind --tool=callgrind` (run it with two call counts and
//! take the difference per call, which removes the start-up cost).
//!
//! `eval_inside` evaluates with ωo at θ = π − 0.6, φ = 3.5 instead (the listing's dielectric
//! transmission, `eval_inside` in the bench group). `pt` and `bdpt` run the position-free
//! estimators (correlated shadowing) on the same configuration instead; an optional last
//! argument replaces α = 0.5.
//!
//! Usage: `profile_listing {conductor|diffuse|dielectric} {ggx|beckmann} {eval|eval_inside|sample|pt|bdpt} calls [α]`

use microsurface::glam::Vec3;
use microsurface::rand::SeedableRng;
use microsurface::research::{
    Material, Microsurface, PositionFree, ScatteringOrder, Shadowing, UniformHeight,
};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Conductor, Dielectric, Diffuse, Ggx};
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;

/// The unit direction with polar angle `theta` and azimuth `phi` (rounded from f64, as the
/// listing's driver does).
fn spherical(theta: f64, phi: f64) -> Vec3 {
    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32)
}

fn run<S: MicrosurfaceSlope, M: Material>(slope: S, material: M, what: &str, calls: u64) -> f64 {
    let surface = Microsurface::new(UniformHeight, slope, material);
    let position_free = PositionFree::new(slope, material, Shadowing::Correlated);
    let (wi, wo) = (spherical(0.5, 0.0), spherical(0.8, 3.5));
    let wo_inside = spherical(2.541_592_653_589_793, 3.5);
    let mut rng = Pcg64Mcg::seed_from_u64(6000);
    let mut sum = 0.0f64;
    for _ in 0..calls {
        sum += f64::from(match what {
            "eval" => {
                black_box(&surface).eval(black_box(wi), black_box(wo), ScatteringOrder::All, &mut rng).x
            }
            "eval_inside" => {
                black_box(&surface)
                    .eval(black_box(wi), black_box(wo_inside), ScatteringOrder::All, &mut rng)
                    .x
            }
            "sample" => black_box(&surface).sample(black_box(wi), &mut rng).map_or(0.0, |s| s.weight.x),
            "pt" => {
                black_box(&position_free)
                    .eval_pt(black_box(wi), black_box(wo), ScatteringOrder::All, &mut rng)
                    .x
            }
            "bdpt" => {
                black_box(&position_free)
                    .eval_bdpt(black_box(wi), black_box(wo), ScatteringOrder::All, &mut rng)
                    .x
            }
            _ => panic!("eval or sample, not {what}"),
        });
    }
    sum / calls as f64
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (material, slope, what, calls, alpha) = match &args[..] {
        [_, m, s, w, c] => (m, s, w, c, 0.5),
        [_, m, s, w, c, a] => (m, s, w, c, a.parse().expect("a roughness")),
        _ => panic!(
            "usage: profile_listing {{conductor|diffuse|dielectric}} {{ggx|beckmann}} {{eval|eval_inside|sample|pt|bdpt}} calls [α]"
        ),
    };
    let calls: u64 = calls.parse().expect("a call count");
    let ggx = Ggx::isotropic(alpha).expect("valid roughness");
    let beckmann = Beckmann::isotropic(alpha).expect("valid roughness");
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
