//! A profiling driver for `benches/bsdf.rs`: runs `calls` calls of one of its configurations
//! (the same materials, roughness, pre-generated inputs, seeds and call forms: the research
//! calls through the bench's `Research` dispatch, the trait's through `black_box(&bsdf)` or
//! `&dyn Bsdf`), for instruction counts under `valgrind --tool=callgrind`. Run it with two call
//! counts that differ by a multiple of 1024 (a whole number of passes through the inputs) and
//! take the difference per call, which removes the start-up cost; then subtract the same
//! difference for the `loop` variant of the call (the rotation through the same inputs,
//! behind the same `black_box`es, without the call).
//!
//! Usage: `profile_bsdf {gold|glass} {single|walk|pt|bdpt} {eval|pdf|eval_with_pdf|sample}
//! {research|research+pdf|static|dyn|loop|loop-research} calls`, and
//! `profile_bsdf gold single sample {vndf|vndf-static|vndf-loop} calls` for the
//! `gold/single/sample-vs-vndf` group (its own inputs). `loop` is the baseline of the trait's
//! calls and of the research `eval`, `pdf` and `eval_with_pdf` (the same inputs read);
//! `loop-research` that of the research `sample` (which reads only wo).

use microsurface::glam::Vec3;
use microsurface::rand::SeedableRng;
use microsurface::research::{Estimator, Material, Microsurface, Shadowing, SpecularLimit, UniformHeight};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Bsdf, ComplexIor, Conductor, Dielectric, Ggx, MicrofacetBsdf, Technique};
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;
use validation::inputs::{N, inputs};
use validation::research::Research;

/// The roughness of every configuration.
const ALPHA: f32 = 0.5;

/// The calls, one loop per closure (monomorphized: no dispatch in the loop).
#[inline(never)]
fn drive(calls: usize, mut f: impl FnMut(usize, u64) -> f32) -> f32 {
    let mut sum = 0.0;
    for i in 0..calls {
        sum += f(i & (N - 1), i as u64);
    }
    sum
}

/// A value to sum, so that no part of a sample can be dropped.
fn first(x: Option<(Vec3, Vec3, f32)>) -> f32 {
    x.map_or(0.0, |(w, f, p)| w.x + f.x + p)
}

fn run<M: Material + SpecularLimit>(
    material: M,
    seed: u64,
    technique: Technique,
    call: &str,
    variant: &str,
    calls: usize,
) -> f32 {
    let slope = Ggx::isotropic(ALPHA).expect("valid roughness");
    let x = inputs(M::TRANSMITS, seed);
    let bsdf = MicrofacetBsdf::new(slope, material).expect("α ≤ MAX_WALK_ALPHA").with_technique(technique);
    let dynamic: &dyn Bsdf = &bsdf;
    let research = Research { surface: Microsurface::new(UniformHeight, slope, material), technique };
    let single = research.single();
    let mut rng = Pcg64Mcg::seed_from_u64(seed + 1);
    let (wo, wi, uc, u) = (&x.wo, &x.wi, &x.uc, &x.u);
    match (call, variant) {
        ("eval" | "eval_with_pdf", "loop") => {
            drive(calls, |k, key| black_box(wo[k]).x + black_box(wi[k]).x + key as f32)
        }
        ("pdf", "loop") => drive(calls, |k, _| black_box(wo[k]).x + black_box(wi[k]).x),
        ("sample", "loop") => drive(calls, |k, _| black_box(wo[k]).x + black_box(uc[k]) + black_box(u[k]).x),
        (_, "loop-research") => drive(calls, |k, _| black_box(wo[k]).x),
        ("eval", "research") => {
            drive(calls, |k, _| black_box(&research).eval(black_box(wo[k]), black_box(wi[k]), &mut rng).x)
        }
        ("eval", "static") => {
            drive(calls, |k, key| black_box(&bsdf).eval_keyed(black_box(wo[k]), black_box(wi[k]), key).f.x)
        }
        ("eval", "dyn") => {
            drive(calls, |k, key| black_box(dynamic).eval_keyed(black_box(wo[k]), black_box(wi[k]), key).f.x)
        }
        ("pdf", "research") => {
            drive(calls, |k, _| black_box(&research).pdf(black_box(wo[k]), black_box(wi[k])))
        }
        ("pdf", "static") => drive(calls, |k, _| black_box(&bsdf).pdf(black_box(wo[k]), black_box(wi[k]))),
        ("pdf", "dyn") => drive(calls, |k, _| black_box(dynamic).pdf(black_box(wo[k]), black_box(wi[k]))),
        ("eval_with_pdf", "research") => drive(calls, |k, _| {
            let (f, p) = black_box(&single).eval_with_pdf(black_box(wo[k]), black_box(wi[k]), &mut rng);
            f.x + p
        }),
        ("eval_with_pdf", "static") => drive(calls, |k, key| {
            let (f, p) = black_box(&bsdf).eval_with_pdf_keyed(black_box(wo[k]), black_box(wi[k]), key);
            f.f.x + p
        }),
        ("eval_with_pdf", "dyn") => drive(calls, |k, key| {
            let (f, p) = black_box(dynamic).eval_with_pdf_keyed(black_box(wo[k]), black_box(wi[k]), key);
            f.f.x + p
        }),
        ("sample", "research") => {
            drive(calls, |k, _| first(black_box(&research).sample(black_box(wo[k]), &mut rng)))
        }
        ("sample", "research+pdf") => {
            drive(calls, |k, _| first(black_box(&research).sample_with_pdf(black_box(wo[k]), &mut rng)))
        }
        ("sample", "static") => drive(calls, |k, _| {
            first(
                black_box(&bsdf)
                    .sample(black_box(wo[k]), black_box(uc[k]), black_box(u[k]))
                    .map(|s| (s.wi, s.weight, s.pdf)),
            )
        }),
        ("sample", "dyn") => drive(calls, |k, _| {
            first(
                black_box(dynamic)
                    .sample(black_box(wo[k]), black_box(uc[k]), black_box(u[k]))
                    .map(|s| (s.wi, s.weight, s.pdf)),
            )
        }),
        ("sample", "vndf") => drive(calls, |k, _| {
            black_box(&slope).sample_d_wi(black_box(wo[k]), black_box(u[k].x), black_box(u[k].y)).x
        }),
        ("sample", "vndf-loop") => {
            drive(calls, |k, _| black_box(wo[k]).x + black_box(u[k].x) + black_box(u[k].y))
        }
        _ => panic!("unknown call {call} {variant}"),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, material, technique, call, variant, calls] = &args[..] else {
        panic!("usage: profile_bsdf {{gold|glass}} {{single|walk|pt|bdpt}} call variant calls");
    };
    let calls: usize = calls.parse().expect("a call count");
    let technique = match technique.as_str() {
        "single" => Technique::SingleScattering,
        "walk" => Technique::RandomWalk,
        "pt" => Technique::PositionFree { estimator: Estimator::Pt, shadowing: Shadowing::Correlated },
        "bdpt" => Technique::PositionFree { estimator: Estimator::Bdpt, shadowing: Shadowing::Correlated },
        t => panic!("unknown technique {t}"),
    };
    // the sample-vs-vndf group has its own inputs (seed 77)
    let (seed_gold, variant) = match variant.as_str() {
        "vndf-static" => (77, "static"),
        v @ ("vndf" | "vndf-loop") => (77, v),
        v => (100, v),
    };
    let sum = match material.as_str() {
        "gold" => run(Conductor::new(ComplexIor::GOLD), seed_gold, technique, call, variant, calls),
        "glass" => run(Dielectric::new(1.5).expect("valid index"), 200, technique, call, variant, calls),
        m => panic!("unknown material {m}"),
    };
    println!("{sum}");
}
