//! A short tour of what `microsurface` computes: masking, visible normals, and the
//! multiple-scattering random walks of Heitz et al. 2016, with their energy per bounce.
//!
//! Run with `cargo run --release --example tour`.

use glam::Vec3;
use microsurface::research::{Material, Microsurface, MicrosurfaceHeight, ScatteringOrder, UniformHeight};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, ComplexIor, Conductor, Dielectric, Diffuse, Ggx};
use rand::SeedableRng;

type Rng = rand_pcg::Pcg64Mcg;

/// Albedo (reflected, transmitted) and the share of orders 1, 2, 3+, estimated from `n` walks.
fn albedo_by_order<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
    surface: &Microsurface<H, S, M>,
    wi: Vec3,
    n: usize,
    rng: &mut Rng,
) -> ([f64; 2], [f64; 3], f64) {
    let (mut sides, mut orders, mut bounces) = ([0.0; 2], [0.0; 3], 0.0);
    for _ in 0..n {
        if let Some(s) = surface.sample(wi, rng) {
            let w = f64::from(s.weight.x) / n as f64;
            sides[usize::from(s.wo.z < 0.0)] += w;
            orders[(s.bounces as usize - 1).min(2)] += w;
            bounces += f64::from(s.bounces) / n as f64;
        }
    }
    (sides, orders, bounces)
}

fn row<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
    name: &str,
    surface: &Microsurface<H, S, M>,
    rng: &mut Rng,
) {
    for theta in [0.0f32, 1.0, 1.5] {
        let wi = Vec3::new(theta.sin(), 0.0, theta.cos());
        let (sides, orders, bounces) = albedo_by_order(surface, wi, 200_000, rng);
        println!(
            "  {name:<34} θi = {theta:.1}  R = {:.4}  T = {:.4}  orders 1/2/3+ = {:.4}/{:.4}/{:.4}  bounces = {bounces:.2}",
            sides[0], sides[1], orders[0], orders[1], orders[2]
        );
    }
}

const USAGE: &str = "usage: cargo run --release --example tour

Prints a short tour of what the crate computes (masking, visible normals, the random walks and
their energy per bounce). Takes no arguments other than --help.";

fn main() -> Result<(), microsurface::Error> {
    if let Some(arg) = std::env::args().nth(1) {
        if arg == "-h" || arg == "--help" {
            println!("{USAGE}");
            return Ok(());
        }
        eprintln!("unknown argument {arg}\n\n{USAGE}");
        std::process::exit(2);
    }
    let mut rng = Rng::seed_from_u64(2016);

    println!("microsurface — a tour\n");
    println!("1. Smith masking on the whole sphere (α = 0.5): Λ(ω), G1(ω) = 1/(1+Λ), projected area");
    let (ggx, beckmann) = (Ggx::isotropic(0.5)?, Beckmann::isotropic(0.5)?);
    for theta in [0.0f32, 0.8, 1.4, 1.57, 2.0, 3.0] {
        let w = Vec3::new(theta.sin(), 0.0, theta.cos());
        println!(
            "  θ = {theta:4.2}  GGX Λ = {:>10.5}  A = {:.5}   Beckmann Λ = {:>10.5}  A = {:.3e}",
            ggx.lambda(w),
            ggx.projected_area(w),
            beckmann.lambda(w),
            beckmann.projected_area(w)
        );
    }

    println!("\n2. Exact visible-normal sampling: mean sampled normal vs θi (α = 1, 100k samples)");
    for theta in [0.5f32, 1.55, 2.8] {
        let wi = Vec3::new(theta.sin(), 0.0, theta.cos());
        let (mut g, mut b) = (Vec3::ZERO, Vec3::ZERO);
        let n = 100_000;
        for k in 0..n {
            let (u1, u2) = ((k as f32 + 0.5) / n as f32, rand::RngExt::random::<f32>(&mut rng));
            g += Ggx::isotropic(1.0)?.sample_d_wi(wi, u1, u2) / n as f32;
            b += Beckmann::isotropic(1.0)?.sample_d_wi(wi, u1, u2) / n as f32;
        }
        println!("  θi = {theta:4.2}  GGX E[ωm] = {g:.4}   Beckmann E[ωm] = {b:.4}");
    }

    println!(
        "\n3. Random walks: albedo and its split by scattering order (200k walks each, uniform heights)"
    );
    let gold = ComplexIor::new(Vec3::new(0.143, 0.374, 1.442), Vec3::new(3.983, 2.385, 1.603))?;
    row(
        "conductor F=1, GGX α=1",
        &Microsurface::new(UniformHeight, Ggx::isotropic(1.0)?, Conductor::perfect()),
        &mut rng,
    );
    row(
        "conductor gold (red), GGX α=1",
        &Microsurface::new(UniformHeight, Ggx::isotropic(1.0)?, Conductor::new(gold)),
        &mut rng,
    );
    row(
        "diffuse a=1, Beckmann α=1",
        &Microsurface::new(UniformHeight, Beckmann::isotropic(1.0)?, Diffuse::white()),
        &mut rng,
    );
    row(
        "dielectric η=1.5, GGX α=1",
        &Microsurface::new(UniformHeight, Ggx::isotropic(1.0)?, Dielectric::new(1.5)?),
        &mut rng,
    );
    row(
        "dielectric η=1.5, GGX (1, 0.1)",
        &Microsurface::new(UniformHeight, Ggx::new(1.0, 0.1)?, Dielectric::new(1.5)?),
        &mut rng,
    );

    println!("\n4. Single scattering vs the walk cut after one bounce (conductor GGX α=0.5, θi = θo = 0.5)");
    let surface = Microsurface::new(UniformHeight, Ggx::isotropic(0.5)?, Conductor::perfect());
    let (wi, wo) =
        (Vec3::new(0.5f32.sin(), 0.0, 0.5f32.cos()), Vec3::new(-(0.5f32.sin()), 0.0, 0.5f32.cos()));
    let n = 200_000;
    let (mut first, mut all) = (0.0f64, 0.0f64);
    for _ in 0..n {
        first +=
            f64::from(surface.eval(wi, wo, ScatteringOrder::only(1).expect("1 > 0"), &mut rng).x) / n as f64;
        all += f64::from(surface.eval(wi, wo, ScatteringOrder::All, &mut rng).x) / n as f64;
    }
    println!(
        "  analytic single scattering f·cos = {:.5}   walk, order 1 = {first:.5}   walk, all orders = {all:.5}",
        surface.eval_single_scattering(wi, wo, &mut rng).x
    );
    Ok(())
}
