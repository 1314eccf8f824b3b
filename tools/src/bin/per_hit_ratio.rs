//! The per-hit construction's cost on a shared machine: the `per_hit` criterion group's four
//! variants (the two calls `sample` + `eval_with_pdf` on prebuilt BSDFs, and construction +
//! the two calls, static and `dyn`; the same hit parameters and inputs as `benches/bsdf.rs`)
//! run interleaved in chunks of 1024 hits, `rounds` times, and the fastest chunk of each variant
//! kept. Other work on the machine only ever slows a chunk down, so the minima and their ratios
//! are stable where criterion's medians of variants measured seconds apart are not.
//!
//! Usage: `per_hit_ratio [rounds]` (default 400); prints one row per type: single scattering
//! and every compensated scheme.

use microsurface::glam::Vec3;
use microsurface::{
    Bsdf, Compensated, Compensation, ComplexIor, Conductor, Dielectric, Ggx, MicrofacetBsdf, Technique,
};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;
use std::time::Instant;
use validation::inputs::{Inputs, inputs};

/// Hits per chunk (the inputs' count).
const N: usize = 1024;

/// The two calls of a hit, as `benches/bsdf.rs` makes them.
#[inline(always)]
fn calls<B: Bsdf + ?Sized>(b: &B, x: &Inputs, k: usize) -> f32 {
    let wo = black_box(x.wo[k]);
    let s = b.sample(wo, black_box(x.uc[k]), black_box(x.u[k]));
    let wi = s.map_or(x.wi[k], |s| s.wi);
    let (f, pdf) = b.eval_with_pdf_keyed(wo, wi, k as u64);
    f.f.x + pdf + s.map_or(0.0, |s| s.pdf)
}

/// The fastest chunk of each variant (ns per hit): prebuilt static, per-hit static, prebuilt
/// dyn, per-hit dyn.
fn measure<B: Bsdf + 'static>(build: impl Fn(usize) -> B, x: &Inputs, rounds: usize) -> [f64; 4] {
    let prebuilt: Vec<B> = (0..N).map(&build).collect();
    let mut best = [f64::MAX; 4];
    let mut time = |v: usize, chunk: &mut dyn FnMut() -> f32| {
        let t = Instant::now();
        black_box(chunk());
        best[v] = best[v].min(t.elapsed().as_secs_f64() * 1e9 / N as f64);
    };
    for _ in 0..rounds {
        time(0, &mut || (0..N).map(|k| calls(black_box(&prebuilt[k]), x, k)).sum());
        time(1, &mut || (0..N).map(|k| calls(&build(k), x, k)).sum());
        time(2, &mut || (0..N).map(|k| calls(black_box(&prebuilt[k] as &dyn Bsdf), x, k)).sum());
        time(3, &mut || {
            (0..N)
                .map(|k| {
                    let b = build(k);
                    calls(black_box(&b as &dyn Bsdf), x, k)
                })
                .sum()
        });
    }
    best
}

fn main() {
    let rounds = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(400);
    // the hit parameters of `benches/bsdf.rs`'s `per_hit` group: GGX α ∈ [0.05, 1], gold to
    // copper, glass η ∈ [1.2, 2.2]
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(400);
    let (gold, copper) = (ComplexIor::GOLD, ComplexIor::COPPER);
    let mut hits = Vec::with_capacity(N);
    for _ in 0..N {
        let alpha = 0.05 + 0.95 * rng.random::<f32>();
        let t = rng.random::<f32>();
        let ior = (gold.eta().lerp(copper.eta(), t), gold.k().lerp(copper.k(), t));
        hits.push((alpha, ior, 1.2 + rng.random::<f32>()));
    }
    // the hit's parameters read at a black-boxed index, as `benches/bsdf.rs` reads them
    let slope = |k: usize| Ggx::isotropic(hits[black_box(k)].0).expect("α in (0, 1]");
    let conductor = |k: usize| {
        let (eta, kappa): (Vec3, Vec3) = hits[black_box(k)].1;
        Conductor::new(ComplexIor::new(eta, kappa).expect("a metal's index"))
    };
    let glass = |k: usize| Dielectric::new(hits[black_box(k)].2).expect("η > 0");
    let (xg, xd) = (inputs(false, 410), inputs(true, 420));
    println!("| type | prebuilt ns | per-hit ns | ratio static | ratio dyn |");
    println!("|---|---|---|---|---|");
    let row = |name: &str, b: [f64; 4]| {
        println!("| {name} | {:.1} | {:.1} | {:.2} | {:.2} |", b[0], b[1], b[1] / b[0], b[3] / b[2]);
    };
    let gold_single = |k: usize| {
        MicrofacetBsdf::new(slope(k), conductor(k))
            .expect("α ≤ 10")
            .with_technique(Technique::SingleScattering)
    };
    row("gold single scattering", measure(gold_single, &xg, rounds));
    let glass_single = |k: usize| {
        MicrofacetBsdf::new(slope(k), glass(k)).expect("α ≤ 10").with_technique(Technique::SingleScattering)
    };
    row("glass single scattering", measure(glass_single, &xd, rounds));
    for (name, scheme) in [
        ("walk", Compensation::Walk),
        ("kulla-conty", Compensation::KullaConty),
        ("turquin", Compensation::Turquin),
    ] {
        let build = |k: usize| Compensated::with_scheme(slope(k), conductor(k), scheme).expect("α ≤ 1");
        row(&format!("gold compensated {name}"), measure(build, &xg, rounds));
    }
    for (name, scheme) in [("walk", Compensation::Walk), ("turquin", Compensation::Turquin)] {
        let build =
            |k: usize| Compensated::with_scheme(slope(k), glass(k), scheme).expect("in the tables' range");
        row(&format!("glass compensated {name}"), measure(build, &xd, rounds));
    }
}
