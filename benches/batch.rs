//! Benchmarks of the batch calls (`BatchBsdf`) on the rows of `examples/throughput` (gold and
//! glass, GGX α = 0.5, single scattering and the compensated lobes built on it: eval, pdf,
//! eval_with_pdf, sample), each iteration one batch of the `N` pre-generated inputs of
//! `validation::inputs` (criterion reports the time per batch and, with the throughput set,
//! per query); and the random walk in lanes (`Microsurface::sample_batch`) against the scalar
//! walk for the same queries.
//!
//! Benchmark ids: `{gold|glass}/batch/{eval|pdf|eval_with_pdf|sample}`,
//! `gold/compensated/{walk|kulla-conty|turquin}/batch/{…}`,
//! `glass/compensated/{walk|turquin}/batch/{…}`, `walk/{gold|mirror}/{lanes|scalar}`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use microsurface::glam::Vec3;
use microsurface::research::{Material, Microsurface, SpecularLimit, UniformHeight, WalkOutputs};
use microsurface::{
    BatchBsdf, Channels, Compensated, Compensation, ComplexIor, Conductor, Dielectric, Directions, Ggx,
    MicrofacetBsdf, SampleOutputs, Technique,
};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;
use validation::clock::{Clock, config};
use validation::inputs::{N, inputs};

struct Soa {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
}

impl Soa {
    fn of(v: &[Vec3]) -> Self {
        Self {
            x: v.iter().map(|w| w.x).collect(),
            y: v.iter().map(|w| w.y).collect(),
            z: v.iter().map(|w| w.z).collect(),
        }
    }
    fn zeros(n: usize) -> Self {
        Self { x: vec![0.0; n], y: vec![0.0; n], z: vec![0.0; n] }
    }
    fn dirs(&self) -> Directions<'_> {
        Directions::new(&self.x, &self.y, &self.z).expect("equal lengths")
    }
    fn channels(&mut self) -> Channels<'_> {
        Channels::new(&mut self.x, &mut self.y, &mut self.z)
    }
}

fn bench_material<M: Material + SpecularLimit>(c: &mut Criterion<Clock>, name: &str, material: M, seed: u64) {
    let slope = Ggx::isotropic(0.5).expect("valid roughness");
    let bsdf =
        MicrofacetBsdf::new(slope, material).expect("valid").with_technique(Technique::SingleScattering);
    bench_batch(c, &format!("{name}/batch"), &bsdf, M::TRANSMITS, seed);
}

/// The compensated lobes on the inputs of the single-scattering rows.
fn bench_compensated(c: &mut Criterion<Clock>) {
    let slope = Ggx::isotropic(0.5).expect("valid roughness");
    let schemes = [
        ("walk", Compensation::Walk),
        ("kulla-conty", Compensation::KullaConty),
        ("turquin", Compensation::Turquin),
    ];
    for (name, scheme) in schemes {
        let gold = Compensated::with_scheme(slope, Conductor::new(ComplexIor::GOLD), scheme).expect("α ≤ 1");
        bench_batch(c, &format!("gold/compensated/{name}/batch"), &gold, false, 3);
    }
    // (Kulla–Conty's glass lobes are the walk's)
    for (name, scheme) in [schemes[0], schemes[2]] {
        let glass = Dielectric::new(1.5).expect("valid index");
        let glass = Compensated::with_scheme(slope, glass, scheme).expect("in range");
        bench_batch(c, &format!("glass/compensated/{name}/batch"), &glass, true, 4);
    }
}

/// eval, pdf, eval_with_pdf and sample of `bsdf` in group `group`, on the inputs of `seed`.
fn bench_batch<B: BatchBsdf>(c: &mut Criterion<Clock>, group: &str, bsdf: &B, transmits: bool, seed: u64) {
    let x = inputs(transmits, seed);
    let (wo, wi) = (Soa::of(&x.wo), Soa::of(&x.wi));
    let u1: Vec<f32> = x.u.iter().map(|u| u.x).collect();
    let u2: Vec<f32> = x.u.iter().map(|u| u.y).collect();
    let (mut f, mut pdf) = (Soa::zeros(N), vec![0.0f32; N]);
    let (mut sw, mut weight, mut spdf, mut eta) =
        (Soa::zeros(N), Soa::zeros(N), vec![0.0f32; N], vec![0.0f32; N]);
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("eval", |b| {
        b.iter(|| black_box(bsdf).eval_batch(&wo.dirs(), &wi.dirs(), &mut f.channels()).expect("lengths"))
    });
    g.bench_function("pdf", |b| {
        b.iter(|| black_box(bsdf).pdf_batch(&wo.dirs(), &wi.dirs(), &mut pdf).expect("lengths"))
    });
    g.bench_function("eval_with_pdf", |b| {
        b.iter(|| {
            black_box(bsdf)
                .eval_with_pdf_batch(&wo.dirs(), &wi.dirs(), &mut f.channels(), &mut pdf)
                .expect("lengths")
        })
    });
    g.bench_function("sample", |b| {
        b.iter(|| {
            let mut out =
                SampleOutputs { wi: sw.channels(), weight: weight.channels(), pdf: &mut spdf, eta: &mut eta };
            black_box(bsdf).sample_batch(&wo.dirs(), &x.uc, &u1, &u2, &mut out).expect("lengths")
        })
    });
    g.finish();
}

fn walks(c: &mut Criterion<Clock>) {
    let x = inputs(false, 9);
    let wi = Soa::of(&x.wo);
    let slope = Ggx::isotropic(0.5).expect("valid roughness");
    for (name, material) in [("gold", Conductor::new(ComplexIor::GOLD)), ("mirror", Conductor::perfect())] {
        let surface = Microsurface::new(UniformHeight, slope, material);
        let mut g = c.benchmark_group(format!("walk/{name}"));
        g.throughput(Throughput::Elements(N as u64));
        let (mut wo, mut weight, mut bounces) = (Soa::zeros(N), Soa::zeros(N), vec![0u32; N]);
        let mut seed = 0u64;
        g.bench_function("lanes", |b| {
            b.iter(|| {
                seed += 1;
                let mut out =
                    WalkOutputs { wo: wo.channels(), weight: weight.channels(), bounces: &mut bounces };
                black_box(&surface).sample_batch(&wi.dirs(), seed, &mut out).expect("lengths")
            })
        });
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        g.bench_function("scalar", |b| {
            b.iter(|| {
                for w in &x.wo {
                    black_box(black_box(&surface).sample(*w, &mut rng));
                }
            })
        });
        g.finish();
    }
}

fn benches(c: &mut Criterion<Clock>) {
    bench_material(c, "gold", Conductor::new(ComplexIor::GOLD), 3);
    bench_material(c, "glass", Dielectric::new(1.5).expect("valid index"), 4);
    bench_compensated(c);
    walks(c);
}

criterion_group! {
    name = batch;
    config = config();
    targets = benches
}
criterion_main!(batch);
