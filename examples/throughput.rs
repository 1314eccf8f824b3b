//! Throughput of the batch calls (`BatchBsdf`) against the scalar calls, on the rows of
//! `../shared/bench/mitsuba3/run.sh` (Mitsuba 3's `roughconductor` / `roughdielectric`): gold and
//! glass, GGX α = 0.5, single scattering; eval, pdf, eval_with_pdf and sample over 2²⁰ random
//! queries (views uniform on the upper hemisphere; lights on the upper hemisphere for gold and
//! on the whole sphere for glass), one thread, the thread's CPU time per query, the median of
//! calls 2 to 7 (the first call warms the caches and is left out, as the script leaves out
//! Mitsuba's JIT compilation). The compensated lobes (`Compensated`, every scheme; no Mitsuba
//! counterpart) follow on the same queries.
//!
//! ```sh
//! cargo run --release --example throughput
//! ```

use microsurface::glam::{Vec2, Vec3};
use microsurface::{
    BatchBsdf, Channels, Compensated, Compensation, ComplexIor, Conductor, Dielectric, Directions, Ggx,
    MicrofacetBsdf, SampleOutputs, Technique,
};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;
use std::time::Duration;

/// log₂ of the number of queries (as the Mitsuba script).
const LOG2_N: u32 = 20;
/// Calls per measurement; the first is left out.
const REPS: usize = 7;

/// The CPU time of this thread.
fn thread_time() -> Duration {
    // the validation crate's clock, without criterion
    #[cfg(target_os = "linux")]
    {
        #[repr(C)]
        struct Timespec {
            tv_sec: isize,
            tv_nsec: isize,
        }
        unsafe extern "C" {
            fn clock_gettime(clock_id: i32, tp: *mut Timespec) -> i32;
        }
        let mut t = Timespec { tv_sec: 0, tv_nsec: 0 };
        // SAFETY: `t` is a valid `struct timespec`; CLOCK_THREAD_CPUTIME_ID (3) is supported
        // by every Linux since 2.6.12.
        let rc = unsafe { clock_gettime(3, &mut t) };
        assert_eq!(rc, 0);
        Duration::new(t.tv_sec as u64, t.tv_nsec as u32)
    }
    #[cfg(not(target_os = "linux"))]
    {
        use std::sync::OnceLock;
        static ORIGIN: OnceLock<std::time::Instant> = OnceLock::new();
        ORIGIN.get_or_init(std::time::Instant::now).elapsed()
    }
}

/// The median over calls 2..=REPS of `f`'s CPU time, in ns per query.
fn ns_per_query(n: usize, mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..REPS)
        .map(|_| {
            let t0 = thread_time();
            f();
            (thread_time() - t0).as_secs_f64()
        })
        .skip(1)
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2] / n as f64 * 1e9
}

/// A direction uniform on the upper hemisphere or the whole sphere.
fn direction(rng: &mut Pcg64Mcg, sphere: bool) -> Vec3 {
    let u = 1.0 - rng.random::<f32>();
    let z = if sphere && rng.random::<bool>() { -u } else { u };
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = core::f32::consts::TAU * rng.random::<f32>();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

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

fn rows<B: BatchBsdf>(material: &str, bsdf: &B, sphere: bool, seed: u64) {
    let n = 1usize << LOG2_N;
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let wo: Vec<Vec3> = (0..n).map(|_| direction(&mut rng, false)).collect();
    let wi: Vec<Vec3> = (0..n).map(|_| direction(&mut rng, sphere)).collect();
    let uc: Vec<f32> = (0..n).map(|_| rng.random()).collect();
    let u1: Vec<f32> = (0..n).map(|_| rng.random()).collect();
    let u2: Vec<f32> = (0..n).map(|_| rng.random()).collect();
    let (so, si) = (Soa::of(&wo), Soa::of(&wi));
    let (mut f, mut pdf) = (Soa::zeros(n), vec![0.0f32; n]);
    let (mut sw, mut weight, mut spdf, mut eta) =
        (Soa::zeros(n), Soa::zeros(n), vec![0.0f32; n], vec![0.0f32; n]);

    let batch = [
        (
            "eval",
            ns_per_query(n, || bsdf.eval_batch(&so.dirs(), &si.dirs(), &mut f.channels()).expect("lengths")),
        ),
        ("pdf", ns_per_query(n, || bsdf.pdf_batch(&so.dirs(), &si.dirs(), &mut pdf).expect("lengths"))),
        (
            "eval_pdf",
            ns_per_query(n, || {
                bsdf.eval_with_pdf_batch(&so.dirs(), &si.dirs(), &mut f.channels(), &mut pdf)
                    .expect("lengths")
            }),
        ),
        (
            "sample",
            ns_per_query(n, || {
                let mut out = SampleOutputs {
                    wi: sw.channels(),
                    weight: weight.channels(),
                    pdf: &mut spdf,
                    eta: &mut eta,
                };
                bsdf.sample_batch(&so.dirs(), &uc, &u1, &u2, &mut out).expect("lengths")
            }),
        ),
    ];
    let mut acc = 0.0f32;
    let scalar = [
        ns_per_query(n, || {
            for k in 0..n {
                acc += black_box(bsdf).eval(wo[k], wi[k]).f.x;
            }
        }),
        ns_per_query(n, || {
            for k in 0..n {
                acc += black_box(bsdf).pdf(wo[k], wi[k]);
            }
        }),
        ns_per_query(n, || {
            for k in 0..n {
                acc += black_box(bsdf).eval_with_pdf(wo[k], wi[k]).1;
            }
        }),
        ns_per_query(n, || {
            for k in 0..n {
                acc += black_box(bsdf).sample(wo[k], uc[k], Vec2::new(u1[k], u2[k])).map_or(0.0, |s| s.pdf);
            }
        }),
    ];
    black_box(acc);
    for ((call, b), s) in batch.iter().zip(scalar) {
        println!("| {material} | {call} | {b:.2} | {s:.1} | {:.1} |", s / b);
    }
}

/// The random walk (GGX α = 0.5, views uniform on the upper hemisphere): the walks in lanes
/// (`Microsurface::sample_batch`) against the scalar walk, per query.
fn walk_rows<M: microsurface::research::Material>(name: &str, material: M, seed: u64) {
    use microsurface::research::{Microsurface, UniformHeight, WalkOutputs};
    let n = 1usize << (LOG2_N - 2);
    let surface = Microsurface::new(UniformHeight, Ggx::isotropic(0.5).expect("valid"), material);
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let wi: Vec<Vec3> = (0..n).map(|_| direction(&mut rng, false)).collect();
    let si = Soa::of(&wi);
    let (mut wo, mut weight, mut bounces) = (Soa::zeros(n), Soa::zeros(n), vec![0u32; n]);
    let mut batch_seed = 0;
    let lanes = ns_per_query(n, || {
        batch_seed += 1;
        let mut out = WalkOutputs { wo: wo.channels(), weight: weight.channels(), bounces: &mut bounces };
        surface.sample_batch(&si.dirs(), batch_seed, &mut out).expect("lengths");
    });
    let mut acc = 0u32;
    let scalar = ns_per_query(n, || {
        for w in &wi {
            acc += black_box(&surface).sample(*w, &mut rng).map_or(0, |s| s.bounces);
        }
    });
    black_box(acc);
    println!("| {name} | walk sample | {lanes:.2} | {scalar:.1} | {:.1} |", scalar / lanes);
}

fn load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(", "))
        .unwrap_or_else(|_| "unknown".into())
}

fn main() -> Result<(), microsurface::Error> {
    #[cfg(target_arch = "x86_64")]
    let avx2 = std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma");
    #[cfg(target_arch = "x86_64")]
    let isa = if avx2
        && std::is_x86_feature_detected!("avx512f")
        && std::is_x86_feature_detected!("avx512vl")
        && std::is_x86_feature_detected!("avx512dq")
        && std::is_x86_feature_detected!("avx512bw")
    {
        "AVX-512 (16 f32 lanes)"
    } else if avx2 {
        "AVX2 + FMA (8 f32 lanes)"
    } else {
        "SSE2 (4 f32 lanes)"
    };
    #[cfg(not(target_arch = "x86_64"))]
    let isa = "the build's baseline";
    println!("microsurface batch calls, one thread, {isa}; load average {}", load());
    println!("| material | call | ns per lane | scalar ns per call | scalar ÷ batch |");
    println!("|---|---|---|---|---|");
    let slope = Ggx::isotropic(0.5)?;
    let gold = MicrofacetBsdf::new(slope, Conductor::new(ComplexIor::GOLD))?
        .with_technique(Technique::SingleScattering);
    let glass =
        MicrofacetBsdf::new(slope, Dielectric::new(1.5)?)?.with_technique(Technique::SingleScattering);
    rows("gold", &gold, false, 3);
    rows("glass", &glass, true, 4);
    let schemes = [
        ("walk", Compensation::Walk),
        ("kulla-conty", Compensation::KullaConty),
        ("turquin", Compensation::Turquin),
    ];
    for (name, scheme) in schemes {
        let gold = Compensated::with_scheme(slope, Conductor::new(ComplexIor::GOLD), scheme)?;
        rows(&format!("gold compensated ({name})"), &gold, false, 3);
    }
    // (Kulla–Conty's glass lobes are the walk's)
    for (name, scheme) in [schemes[0], schemes[2]] {
        let glass = Compensated::with_scheme(slope, Dielectric::new(1.5)?, scheme)?;
        rows(&format!("glass compensated ({name})"), &glass, true, 4);
    }
    walk_rows("gold", Conductor::new(ComplexIor::GOLD), 5);
    walk_rows("mirror", Conductor::perfect(), 6);
    println!("load average after: {}", load());
    Ok(())
}
