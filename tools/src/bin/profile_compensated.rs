//! A profiling driver for the energy-compensated lobes against the single-scattering lobe they
//! are built on (`benches/bsdf.rs`'s `gold/compensated/` and `glass/compensated/` groups: GGX
//! α = 0.5, gold or glass η = 1.5, the bench's 1024 pre-generated inputs from the same seeds):
//! runs `calls` calls of one method of one model, static dispatch, for instruction counts under
//! `valgrind --tool=callgrind`. Run it with two call counts (multiples of 1024) and take the
//! difference per call, which removes the start-up cost; the technique `none` runs the same
//! loop around a trivial call, whose count per call is the loop's own, to subtract.
//!
//! `sample-first` and `sample-last` run the sampler with the lobe-choice uniform fixed at 0 or
//! 1⁻ (a mixture's single-scattering lobe, or its added lobe), to time the branches apart.
//!
//! Usage: `profile_compensated {gold|glass} {none|single|kulla-conty|turquin|per-order}
//! {eval|pdf|sample|eval_with_pdf|sample-first|sample-last} calls`

use microsurface::glam::{Vec2, Vec3};
use microsurface::{
    Bsdf, BsdfFlags, BsdfSample, BsdfValue, Compensated, Compensation, ComplexIor, Conductor, Dielectric,
    Ggx, MicrofacetBsdf, Technique,
};
use std::hint::black_box;
use validation::inputs::{Inputs, N, inputs};

/// The roughness of every configuration (the bench's).
const ALPHA: f32 = 0.5;

/// A model whose every call is trivial: the driver loop's own cost.
struct Nothing;

impl Bsdf for Nothing {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags { reflection: true, transmission: false, glossy: true, diffuse: false, specular: false }
    }
    #[inline(always)]
    fn eval_keyed(&self, wo: Vec3, _wi: Vec3, _key: u64) -> BsdfValue {
        BsdfValue { f: black_box(wo), exact: true }
    }
    #[inline(always)]
    fn sample_keyed(&self, _wo: Vec3, _uc: f32, _u: Vec2, _key: u64) -> Option<BsdfSample> {
        black_box(None)
    }
    #[inline(always)]
    fn pdf(&self, wo: Vec3, _wi: Vec3) -> f32 {
        black_box(wo.x)
    }
    #[inline(always)]
    fn eval_with_pdf_keyed(&self, wo: Vec3, _wi: Vec3, _key: u64) -> (BsdfValue, f32) {
        (BsdfValue { f: black_box(wo), exact: true }, black_box(wo.x))
    }
}

/// `calls` calls of `what` on `b`, rotating through the inputs; returns a checksum. Each method
/// has its own loop, not inlined, so that the code around a call does not depend on the others.
fn run<B: Bsdf>(b: &B, x: &Inputs, what: &str, calls: usize) -> f64 {
    match what {
        "eval" => run_eval(b, x, calls),
        "pdf" => run_pdf(b, x, calls),
        "eval_with_pdf" => run_eval_with_pdf(b, x, calls),
        "sample" => run_sample(b, x, calls, None),
        // the sampler with the lobe-choice uniform fixed at 0 (the single-scattering lobe of a
        // mixture) or at 1⁻ (its added lobe)
        "sample-first" => run_sample(b, x, calls, Some(0.0)),
        "sample-last" => run_sample(b, x, calls, Some(1.0 - f32::EPSILON / 2.0)),
        _ => panic!("eval, pdf, eval_with_pdf, sample, sample-first or sample-last, not {what}"),
    }
}

#[inline(never)]
fn run_eval<B: Bsdf>(b: &B, x: &Inputs, calls: usize) -> f64 {
    let mut sum = 0.0f64;
    for k in 0..calls {
        let k = k & (N - 1);
        sum += f64::from(black_box(b).eval(black_box(x.wo[k]), black_box(x.wi[k])).f.x);
    }
    sum
}

#[inline(never)]
fn run_pdf<B: Bsdf>(b: &B, x: &Inputs, calls: usize) -> f64 {
    let mut sum = 0.0f64;
    for k in 0..calls {
        let k = k & (N - 1);
        sum += f64::from(black_box(b).pdf(black_box(x.wo[k]), black_box(x.wi[k])));
    }
    sum
}

#[inline(never)]
fn run_eval_with_pdf<B: Bsdf>(b: &B, x: &Inputs, calls: usize) -> f64 {
    let mut sum = 0.0f64;
    for k in 0..calls {
        let k = k & (N - 1);
        sum += f64::from(black_box(b).eval_with_pdf(black_box(x.wo[k]), black_box(x.wi[k])).1);
    }
    sum
}

#[inline(never)]
fn run_sample<B: Bsdf>(b: &B, x: &Inputs, calls: usize, uc: Option<f32>) -> f64 {
    let mut sum = 0.0f64;
    for k in 0..calls {
        let k = k & (N - 1);
        let uc = uc.unwrap_or(x.uc[k]);
        let s = black_box(b).sample(black_box(x.wo[k]), black_box(uc), black_box(x.u[k]));
        sum += s.map_or(0.0, |s| f64::from(s.pdf));
    }
    sum
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, material, technique, what, calls] = &args[..] else {
        panic!(
            "usage: profile_compensated {{gold|glass}} {{none|single|kulla-conty|turquin|per-order}} {{eval|pdf|sample|eval_with_pdf|sample-first|sample-last}} calls"
        )
    };
    let calls: usize = calls.parse().expect("a call count");
    let slope = Ggx::isotropic(ALPHA).expect("valid roughness");
    let sum = match material.as_str() {
        "gold" => {
            let gold = Conductor::new(ComplexIor::GOLD);
            let x = inputs(false, 300);
            let scheme = match technique.as_str() {
                "kulla-conty" => Some(Compensation::KullaConty),
                "turquin" => Some(Compensation::Turquin),
                "walk" | "per-order" => Some(Compensation::Walk),
                _ => None,
            };
            match (technique.as_str(), scheme) {
                ("none", _) => run(&Nothing, &x, what, calls),
                ("single", _) => {
                    let b = MicrofacetBsdf::new(slope, gold)
                        .expect("valid material")
                        .with_technique(Technique::SingleScattering);
                    run(&b, &x, what, calls)
                }
                (_, Some(scheme)) => {
                    run(&Compensated::with_scheme(slope, gold, scheme).expect("α ≤ 1"), &x, what, calls)
                }
                _ => panic!("unknown technique {technique}"),
            }
        }
        "glass" => {
            let glass = Dielectric::new(1.5).expect("valid index");
            let x = inputs(true, 310);
            match technique.as_str() {
                "none" => run(&Nothing, &x, what, calls),
                "single" => {
                    let b = MicrofacetBsdf::new(slope, glass)
                        .expect("valid material")
                        .with_technique(Technique::SingleScattering);
                    run(&b, &x, what, calls)
                }
                "walk" | "kulla-conty" => {
                    run(&Compensated::new(slope, glass).expect("in range"), &x, what, calls)
                }
                "turquin" => run(
                    &Compensated::with_scheme(slope, glass, Compensation::Turquin).expect("in range"),
                    &x,
                    what,
                    calls,
                ),
                _ => panic!("unknown technique {technique}"),
            }
        }
        _ => panic!("gold or glass, not {material}"),
    };
    println!("{material}/{technique}/{what}: {calls} calls, checksum {sum}");
}
