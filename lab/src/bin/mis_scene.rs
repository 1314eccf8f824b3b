//! The noise of the stochastic techniques' MIS in a small scene: four rough gold spheres
//! (random walk at α = 0.3 and 1, position-free PT and BDPT at α = 0.6) on a diffuse ground,
//! lit by a spherical light of constant power (radius 0.25 by default; next-event estimation
//! with MIS, power heuristic) and a sky (BSDF sampling only), rendered by the crate's path tracer (`lab::tracer`). The sample
//! weights come from the walks; `Bsdf::pdf` enters only the MIS weights, so two builds that
//! differ only in that density render the same image (unbiased) with different noise.
//!
//! Printed per sphere (the pixels whose centre sees it): the mean radiance and the mean
//! per-pixel variance of one sample (spp × the squared standard error of the pixel mean),
//! and the render time.
//!
//! `--single` renders the four spheres with single scattering instead (gold at α = 0.1, 0.3,
//! 0.6 and 1), whose conductor sampler is the bounded visible-normal cap (Eto and Tokuyoshi
//! 2023): the scene for the noise of that sampler at equal time against a build whose cap is
//! the whole spherical one.
//!
//! `cargo run --release -p lab --bin mis_scene -- [--spp N] [--light-radius R] [--single]` (default 64 spp,
//! R = 0.25; at that size light sampling dominates the MIS weights whatever the BSDF density:
//! the density matters for lights whose solid angle is not small, R ≈ 1 to 3 here).

use glam::Vec3;
use lab::tracer::{BDPT, Camera, Environment, Hit, Light, Material, PT, RenderStats, Scene, Sphere, render};
use microsurface::{
    ClassicBrdf, ClassicMasking, ClassicNdf, ComplexIor, Conductor, Ggx, MicrofacetBsdf, Technique,
};
use std::time::Instant;

fn gold(alpha: f32, technique: Technique) -> Material {
    let slope = Ggx::isotropic(alpha).expect("valid α");
    Box::new(
        MicrofacetBsdf::new(slope, Conductor::new(ComplexIor::GOLD))
            .expect("α ≤ MAX_WALK_ALPHA")
            .with_technique(technique),
    )
}

fn main() {
    let mut args = std::env::args().skip(1);
    let (mut spp, mut light_radius, mut single) = (64u32, 0.25f32, false);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--spp" => spp = args.next().and_then(|v| v.parse().ok()).expect("--spp N"),
            "--light-radius" => {
                light_radius = args.next().and_then(|v| v.parse().ok()).expect("--light-radius R")
            }
            "--single" => single = true,
            other => {
                panic!("unknown argument {other}; usage: mis_scene [--spp N] [--light-radius R] [--single]")
            }
        }
    }
    let (labels, mut materials) = if single {
        let alphas = [0.1, 0.3, 0.6, 1.0];
        let materials: Vec<Material> = alphas.iter().map(|&a| gold(a, Technique::SingleScattering)).collect();
        (["single α = 0.1", "single α = 0.3", "single α = 0.6", "single α = 1"], materials)
    } else {
        let materials = vec![
            gold(0.3, Technique::RandomWalk),
            gold(1.0, Technique::RandomWalk),
            gold(0.6, PT),
            gold(0.6, BDPT),
        ];
        (["walk α = 0.3", "walk α = 1", "PT α = 0.6", "BDPT α = 0.6"], materials)
    };
    let mut spheres: Vec<Sphere> = (0..4)
        .map(|i| Sphere { center: Vec3::new(-1.65 + 1.1 * i as f32, 0.5, 0.0), radius: 0.5, material: i })
        .collect();
    materials.push(Box::new(
        ClassicBrdf::new(Vec3::splat(0.5), Vec3::ZERO, ClassicNdf::Ggx(1.0), ClassicMasking::Exact)
            .expect("valid"),
    ));
    spheres.push(Sphere { center: Vec3::new(0.0, -1000.0, 0.0), radius: 1000.0, material: 4 });
    let scene = Scene {
        spheres,
        materials,
        // the same power for every radius (12 × 1² at radius 1)
        light: Some(Light {
            center: Vec3::new(-2.0, 6.0, 4.0),
            radius: light_radius,
            radiance: Vec3::splat(12.0 / (light_radius * light_radius)),
        }),
        environment: Environment::Sky {
            zenith: Vec3::new(0.25, 0.35, 0.6),
            horizon: Vec3::new(0.7, 0.75, 0.8),
            ground: Vec3::splat(0.2),
        },
    };
    let camera = Camera::look_at(Vec3::new(0.0, 1.6, 6.0), Vec3::new(0.0, 0.5, 0.0), 40.0);
    let (width, height) = (320u32, 120u32);
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let stats = RenderStats::default();
    let start = Instant::now();
    let (image, errors) = render(&scene, &camera, (width, height), spp, 7, threads, &stats);
    let seconds = start.elapsed().as_secs_f64();
    let mut sums = [(0usize, 0.0f64, 0.0f64); 4];
    for y in 0..height {
        for x in 0..width {
            let d = camera.ray(x as f32 + 0.5, y as f32 + 0.5, width, height);
            if let Some(Hit::Surface { material, .. }) = scene.intersect(camera.origin, d)
                && material < 4
            {
                let k = (y * width + x) as usize;
                let s = &mut sums[material];
                s.0 += 1;
                s.1 += f64::from(image[k].iter().sum::<f32>() / 3.0);
                s.2 += f64::from(errors[k]).powi(2) * f64::from(spp);
            }
        }
    }
    println!(
        "{width}x{height} at {spp} spp, light radius {light_radius}, on {threads} threads in {seconds:.1} s"
    );
    println!("| sphere | pixels | mean radiance | mean per-sample variance |");
    println!("|---|---|---|---|");
    for (label, (n, sum, var)) in labels.iter().zip(sums) {
        println!("| {label} | {n} | {:.4} | {:.4e} |", sum / n as f64, var / n as f64);
    }
}
