//! A profiling driver for the position-free estimators (PT and BDPT, correlated shadowing) in
//! the report's configurations and in views from below the macrosurface: runs `calls`
//! evaluations of one configuration, for instruction counts under
//! `valgrind --tool=callgrind` (run it with two call counts and take the difference per call,
//! which removes the start-up cost).
//!
//! Configurations:
//! - the report's five (`conductor-ggx-a1.0`, `conductor-ggx-a0.1`, `dielectric-ggx-a1.0`,
//!   `diffuse-ggx-a1.0`, `conductor-beckmann-a0.5`): the calls cycle through its nine
//!   (θi, ωo) of the error study (θi ∈ {0, 1, 1.5}; ωo the mirror direction, the normal, and
//!   θo = 1.2 at azimuth π/2 or, for the dielectric, the transmitted θo = π − 0.6 max(θi, 0.3)),
//!   so the count is their average;
//! - views from below (`below-{conductor|diffuse}-{beckmann|ggx}-a<α>-t<θi in degrees>`, e.g.
//!   `below-conductor-beckmann-a0.02-t120`, a = |cot θi|/α = 28.9): ωi at θi > 90°, the calls
//!   cycle through 1024 ωo drawn from the mixture of `PositionFree::pdf` (0.8 phase sampling,
//!   0.2 cosine), as the albedo tests draw them.
//!
//! Usage: `profile_position_free <configuration> {pt|bdpt} calls`

use microsurface::glam::Vec3;
use microsurface::rand::SeedableRng;
use microsurface::research::{
    Material, PositionFree, ScatteringOrder, Shadowing, Side, sample_cosine_hemisphere,
};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Conductor, Dielectric, Diffuse, Ggx};
use rand_pcg::Pcg64Mcg;
use std::f64::consts::{FRAC_PI_2, PI};
use std::hint::black_box;

/// The unit direction with polar angle `theta` and azimuth `phi`.
fn dir(theta: f64, phi: f64) -> Vec3 {
    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32)
}

/// The nine (ωi, ωo) of the report's error study (`validation::report::configure`).
fn report_cases(transmits: bool) -> Vec<(Vec3, Vec3)> {
    let mut cases = Vec::new();
    for theta_i in [0.0, 1.0, 1.5f64] {
        let mirror = dir(theta_i.max(0.15), PI);
        let normal = if theta_i == 0.0 { dir(0.6, 0.0) } else { Vec3::Z };
        let third = if transmits { dir(PI - 0.6 * theta_i.max(0.3), PI) } else { dir(1.2, FRAC_PI_2) };
        for wo in [mirror, normal, third] {
            cases.push((dir(theta_i, 0.0), wo));
        }
    }
    cases
}

/// 1024 pairs (ωi, ωo) with ωo from the mixture 0.8 phase sampling + 0.2 cosine.
fn mixture_cases<S: MicrosurfaceSlope, M: Material>(pf: &PositionFree<S, M>, wi: Vec3) -> Vec<(Vec3, Vec3)> {
    use microsurface::rand::RngExt;
    let mut rng = Pcg64Mcg::seed_from_u64(7);
    let mut cases = Vec::with_capacity(1024);
    while cases.len() < 1024 {
        let wo = if rng.random::<f32>() < 0.8 {
            pf.material().sample_phase(pf.slope(), wi, Side::Outside, &mut rng).wo
        } else {
            sample_cosine_hemisphere(rng.random::<f32>(), rng.random::<f32>())
        };
        if pf.pdf(wi, wo) > 0.0 {
            cases.push((wi, wo));
        }
    }
    cases
}

fn run<S: MicrosurfaceSlope, M: Material>(
    pf: PositionFree<S, M>,
    cases: &[(Vec3, Vec3)],
    what: &str,
    calls: u64,
) -> f64 {
    let mut rng = Pcg64Mcg::seed_from_u64(6000);
    let mut sum = 0.0f64;
    for k in 0..calls as usize {
        let (wi, wo) = cases[k % cases.len()];
        sum += f64::from(match what {
            "pt" => black_box(&pf).eval_pt(black_box(wi), black_box(wo), ScatteringOrder::All, &mut rng).x,
            "bdpt" => {
                black_box(&pf).eval_bdpt(black_box(wi), black_box(wo), ScatteringOrder::All, &mut rng).x
            }
            _ => panic!("pt or bdpt, not {what}"),
        });
    }
    sum / calls as f64
}

fn run_config<S: MicrosurfaceSlope, M: Material>(
    slope: S,
    material: M,
    below_deg: Option<f64>,
    what: &str,
    calls: u64,
) -> f64 {
    let pf = PositionFree::new(slope, material, Shadowing::Correlated);
    let cases = match below_deg {
        None => report_cases(M::TRANSMITS),
        Some(deg) => mixture_cases(&pf, dir(deg.to_radians(), 0.0)),
    };
    run(pf, &cases, what, calls)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, config, what, calls] = &args[..] else {
        panic!("usage: profile_position_free <configuration> {{pt|bdpt}} calls")
    };
    let calls: u64 = calls.parse().expect("a call count");
    let parts: Vec<&str> = config.split('-').collect();
    let (below, material, slope, alpha, deg) = match &parts[..] {
        ["below", m, s, a, t] => (true, *m, *s, &a[1..], Some(t[1..].parse::<f64>().expect("θi in degrees"))),
        [m, s, a] => (false, *m, *s, &a[1..], None),
        _ => panic!("unknown configuration {config}"),
    };
    assert!(below == deg.is_some());
    let alpha: f32 = alpha.parse().expect("a roughness");
    let ggx = Ggx::isotropic(alpha).expect("valid roughness");
    let beckmann = Beckmann::isotropic(alpha).expect("valid roughness");
    let dielectric = Dielectric::new(1.5).expect("valid index");
    let mean = match (material, slope) {
        ("conductor", "ggx") => run_config(ggx, Conductor::perfect(), deg, what, calls),
        ("diffuse", "ggx") => run_config(ggx, Diffuse::white(), deg, what, calls),
        ("dielectric", "ggx") => run_config(ggx, dielectric, deg, what, calls),
        ("conductor", "beckmann") => run_config(beckmann, Conductor::perfect(), deg, what, calls),
        ("diffuse", "beckmann") => run_config(beckmann, Diffuse::white(), deg, what, calls),
        ("dielectric", "beckmann") => run_config(beckmann, dielectric, deg, what, calls),
        _ => panic!("unknown configuration {config}"),
    };
    println!("{config}/{what}: {calls} calls, mean {mean}");
}
