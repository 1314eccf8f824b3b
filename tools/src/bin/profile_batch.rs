//! A profiling driver for the batch calls (`BatchBsdf`) of the single-scattering lobe and of the
//! compensated lobes built on it (`benches/batch.rs`'s groups: GGX α = 0.5, gold or glass
//! η = 1.5, the bench's 1024 pre-generated inputs from the same seeds): runs `batches` batch
//! calls of one method of one model over the 1024 queries, for instruction counts under
//! `valgrind --tool=callgrind`. Run it with two batch counts and take the difference per query
//! (the difference of the counts over 1024 × the difference of the batch counts), which removes
//! the start-up cost.
//!
//! Usage: `profile_batch {gold|glass} {single|walk|kulla-conty|turquin}
//! {eval|pdf|eval_with_pdf|sample} batches`

use microsurface::{
    BatchBsdf, Channels, Compensated, Compensation, ComplexIor, Conductor, Dielectric, Directions, Ggx,
    MicrofacetBsdf, SampleOutputs, Technique,
};
use std::hint::black_box;
use validation::inputs::{Inputs, N};

/// The roughness of every configuration (the bench's).
const ALPHA: f32 = 0.5;

/// Three coordinate slices.
struct Soa {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
}

impl Soa {
    fn of(v: &[microsurface::glam::Vec3]) -> Self {
        Self {
            x: v.iter().map(|w| w.x).collect(),
            y: v.iter().map(|w| w.y).collect(),
            z: v.iter().map(|w| w.z).collect(),
        }
    }
    fn zeros() -> Self {
        Self { x: vec![0.0; N], y: vec![0.0; N], z: vec![0.0; N] }
    }
    fn dirs(&self) -> Directions<'_> {
        Directions::new(&self.x, &self.y, &self.z).expect("equal lengths")
    }
    fn channels(&mut self) -> Channels<'_> {
        Channels::new(&mut self.x, &mut self.y, &mut self.z)
    }
}

/// `batches` calls of `what` on `b` over the inputs; returns a checksum.
#[inline(never)]
fn run<B: BatchBsdf>(b: &B, x: &Inputs, what: &str, batches: usize) -> f64 {
    let (wo, wi) = (Soa::of(&x.wo), Soa::of(&x.wi));
    let u1: Vec<f32> = x.u.iter().map(|u| u.x).collect();
    let u2: Vec<f32> = x.u.iter().map(|u| u.y).collect();
    let (mut f, mut pdf) = (Soa::zeros(), vec![0.0f32; N]);
    let (mut sw, mut weight, mut eta) = (Soa::zeros(), Soa::zeros(), vec![0.0f32; N]);
    for _ in 0..batches {
        let b = black_box(b);
        match what {
            "eval" => b.eval_batch(&wo.dirs(), &wi.dirs(), &mut f.channels()),
            "pdf" => b.pdf_batch(&wo.dirs(), &wi.dirs(), &mut pdf),
            "eval_with_pdf" => b.eval_with_pdf_batch(&wo.dirs(), &wi.dirs(), &mut f.channels(), &mut pdf),
            "sample" => {
                let mut out = SampleOutputs {
                    wi: sw.channels(),
                    weight: weight.channels(),
                    pdf: &mut pdf,
                    eta: &mut eta,
                };
                b.sample_batch(&wo.dirs(), &x.uc, &u1, &u2, &mut out)
            }
            _ => panic!("eval, pdf, eval_with_pdf or sample, not {what}"),
        }
        .expect("equal lengths");
    }
    f.x.iter().chain(&pdf).map(|&v| f64::from(v)).sum()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, material, technique, what, batches] = &args[..] else {
        panic!(
            "usage: profile_batch {{gold|glass}} {{single|walk|kulla-conty|turquin}} {{eval|pdf|eval_with_pdf|sample}} batches"
        )
    };
    let batches: usize = batches.parse().expect("a batch count");
    let slope = Ggx::isotropic(ALPHA).expect("valid roughness");
    let scheme = match technique.as_str() {
        "single" => None,
        "walk" => Some(Compensation::Walk),
        "kulla-conty" => Some(Compensation::KullaConty),
        "turquin" => Some(Compensation::Turquin),
        _ => panic!("single, walk, kulla-conty or turquin, not {technique}"),
    };
    // the inputs of `benches/batch.rs`
    let sum = match material.as_str() {
        "gold" => {
            let (gold, x) = (Conductor::new(ComplexIor::GOLD), validation::inputs::inputs(false, 3));
            match scheme {
                None => {
                    let b = MicrofacetBsdf::new(slope, gold)
                        .expect("valid")
                        .with_technique(Technique::SingleScattering);
                    run(&b, &x, what, batches)
                }
                Some(scheme) => {
                    run(&Compensated::with_scheme(slope, gold, scheme).expect("α ≤ 1"), &x, what, batches)
                }
            }
        }
        "glass" => {
            let glass = Dielectric::new(1.5).expect("valid index");
            let x = validation::inputs::inputs(true, 4);
            match scheme {
                None => {
                    let b = MicrofacetBsdf::new(slope, glass)
                        .expect("valid")
                        .with_technique(Technique::SingleScattering);
                    run(&b, &x, what, batches)
                }
                Some(scheme) => {
                    run(&Compensated::with_scheme(slope, glass, scheme).expect("in range"), &x, what, batches)
                }
            }
        }
        _ => panic!("gold or glass, not {material}"),
    };
    println!("{material}/{technique}/{what}: {batches} batches of {N}, checksum {sum}");
}
