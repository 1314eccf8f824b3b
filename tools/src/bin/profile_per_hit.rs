//! A profiling driver of the per-hit construction of the energy-compensated lobes
//! (`benches/bsdf.rs`'s `per_hit` group): builds `builds` BSDFs from per-hit parameters (GGX
//! α ∈ [0.05, 1], gold-to-copper indices or glass η ∈ [1.2, 2.2], 1024 pre-generated hits),
//! for instruction counts under `valgrind --tool=callgrind`. Run it with two counts (multiples
//! of 1024) and take the difference per build, which removes the start-up cost (the tables are
//! built on the first use); `none` runs the same loop around the parameters alone.
//!
//! Usage: `profile_per_hit {gold|glass} {none|single|walk|kulla-conty|turquin} builds`

use microsurface::glam::Vec3;
use microsurface::{
    Compensated, Compensation, ComplexIor, Conductor, Dielectric, Ggx, MicrofacetBsdf, Technique,
};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;

/// Hits of the driver.
const HITS: usize = 1024;

/// Keeps a built BSDF alive, for the size of its type.
#[inline(never)]
fn keep<T>(b: T) -> f32 {
    let b = black_box(b);
    core::mem::size_of_val(&b) as f32
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, material, technique, builds] = &args[..] else {
        panic!("usage: profile_per_hit {{gold|glass}} {{none|single|walk|kulla-conty|turquin}} builds")
    };
    let builds: usize = builds.parse().expect("a build count");
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(400);
    let (gold, copper) = (ComplexIor::GOLD, ComplexIor::COPPER);
    let hits: Vec<(f32, Vec3, Vec3, f32)> = (0..HITS)
        .map(|_| {
            let alpha = 0.05 + 0.95 * rng.random::<f32>();
            let t: f32 = rng.random();
            (alpha, gold.eta().lerp(copper.eta(), t), gold.k().lerp(copper.k(), t), 1.2 + rng.random::<f32>())
        })
        .collect();
    let scheme = match technique.as_str() {
        "walk" => Some(Compensation::Walk),
        "kulla-conty" => Some(Compensation::KullaConty),
        "turquin" => Some(Compensation::Turquin),
        "none" | "single" => None,
        _ => panic!("unknown technique {technique}"),
    };
    let mut sum = 0.0f32;
    for n in 0..builds {
        let (alpha, eta, k, glass_eta) = black_box(hits[n & (HITS - 1)]);
        let slope = Ggx::isotropic(alpha).expect("α in (0, 1]");
        sum += match (material.as_str(), technique.as_str(), scheme) {
            (_, "none", _) => keep(alpha + eta.x + k.x + glass_eta),
            ("gold", "single", _) => keep(
                MicrofacetBsdf::new(slope, Conductor::new(ComplexIor::new(eta, k).expect("an index")))
                    .expect("α ≤ 10")
                    .with_technique(Technique::SingleScattering),
            ),
            ("glass", "single", _) => keep(
                MicrofacetBsdf::new(slope, Dielectric::new(glass_eta).expect("η > 0"))
                    .expect("α ≤ 10")
                    .with_technique(Technique::SingleScattering),
            ),
            ("gold", _, Some(scheme)) => keep(
                Compensated::with_scheme(
                    slope,
                    Conductor::new(ComplexIor::new(eta, k).expect("an index")),
                    scheme,
                )
                .expect("α ≤ 1"),
            ),
            ("glass", _, Some(scheme)) => keep(
                Compensated::with_scheme(slope, Dielectric::new(glass_eta).expect("η > 0"), scheme)
                    .expect("in the tables' range"),
            ),
            _ => panic!("gold or glass, not {material}"),
        };
    }
    println!("{material}/{technique}: {builds} builds, checksum {sum}");
}
