//! Measures what the technique chooser (`microsurface::techniques`) ships: the hemispherical
//! albedo error against the exact random walk of single scattering and of the compensated
//! lobes, ε = |Ā − Ā_walk| with Ā = 2∫₀¹ A(μ) μ dμ (largest RGB channel; dielectrics R + T as
//! flux, each side of the interface), over GGX and Beckmann, α ∈ {0.05, …, 1}, F = 1, gold,
//! copper, aluminium and glass of η ∈ {1.33, 1.5, 2}; and the time per sample of each technique
//! relative to single scattering.
//!
//! Ā is estimated by sampling: μo = √u (cosine-weighted views), one BSDF sample per view, the
//! mean of the sample weights (unbiased for every technique), with its standard error.
//!
//! Prints the table, the compensated lobes' bounds the measurements support (per slope family
//! and material class, the largest error plus three standard errors, for
//! `src/techniques/error_model.rs`) and checks the shipped
//! bounds and the chooser's single-scattering errors against the measurements (exit status 1 if
//! a measurement exceeds a shipped bound by more than z standard errors, z one-sided Šidák
//! over every cell and technique at a family-wise level of 10⁻³). The full run writes the table
//! of the techniques page, `docs/techniques.md`.
//!
//! ```sh
//! cargo run --release -p lab --bin techniques            # the published numbers, docs/techniques.md
//! cargo run --release -p lab --bin techniques -- --quick # a smaller run (CI): the check only
//! ```

use microsurface::compensation::AlbedoTabulated;
use microsurface::glam::{Vec2, Vec3};
use microsurface::rand::{RngExt, SeedableRng};
use microsurface::techniques::{Budgeted, Candidates, Choice, ChosenTechnique};
use microsurface::{
    Beckmann, Bsdf, ComplexIor, Conductor, Dielectric, Ggx, MicrofacetBsdf, Technique, Transport,
};
use std::fmt::Write as _;
use std::time::Instant;

type Pcg = rand_pcg::Pcg64Mcg;

const ALPHAS: [f32; 7] = [0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0];
const BUDGETS: [f32; 3] = [0.005, 0.01, 0.03];
/// z of the suggested bounds.
const Z_SUGGEST: f64 = 3.0;
/// The family-wise significance of the checks (one-sided, Šidák over every cell and technique).
const CHECK_LEVEL: f64 = 1e-3;

#[derive(Clone, Copy)]
enum Mat {
    Conductor(&'static str, Conductor),
    Glass(&'static str, f32),
}

impl Mat {
    fn name(&self) -> String {
        match self {
            Mat::Conductor(n, _) => (*n).to_string(),
            Mat::Glass(n, _) => (*n).to_string(),
        }
    }
}

fn materials() -> Vec<Mat> {
    vec![
        Mat::Conductor("F = 1", Conductor::perfect()),
        Mat::Conductor("gold", Conductor::new(ComplexIor::GOLD)),
        Mat::Conductor("copper", Conductor::new(ComplexIor::COPPER)),
        Mat::Conductor("aluminium", Conductor::new(ComplexIor::ALUMINIUM)),
        Mat::Glass("glass 1.33", 1.33),
        Mat::Glass("glass 1.5", 1.5),
        Mat::Glass("glass 2", 2.0),
    ]
}

/// Ā per channel with its standard error.
#[derive(Clone, Copy, Default)]
struct Mean {
    mean: [f64; 3],
    se: [f64; 3],
}

/// Ā of a BSDF seen from above (`below` false) or below: μo = √u, one sample each.
fn hemispherical(bsdf: &dyn Bsdf, below: bool, n: usize, seed: u64) -> Mean {
    let mut rng = Pcg::seed_from_u64(seed);
    let (mut s, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
    for _ in 0..n {
        let mu = rng.random::<f32>().sqrt().max(1e-4);
        let phi = std::f32::consts::TAU * rng.random::<f32>();
        let sin = (1.0 - mu * mu).max(0.0).sqrt();
        let wo = Vec3::new(sin * phi.cos(), sin * phi.sin(), if below { -mu } else { mu });
        let (uc, u) = (rng.random::<f32>(), Vec2::new(rng.random::<f32>(), rng.random::<f32>()));
        if let Some(smp) = bsdf.sample(wo, uc, u) {
            for c in 0..3 {
                let x = f64::from(smp.weight[c]);
                s[c] += x;
                s2[c] += x * x;
            }
        }
    }
    let nf = n as f64;
    let mean = s.map(|v| v / nf);
    let se = std::array::from_fn(|c| ((s2[c] / nf - mean[c] * mean[c]).max(0.0) / (nf - 1.0)).sqrt());
    Mean { mean, se }
}

/// The largest channel's |a − b| and its standard error.
fn error(a: Mean, b: Mean) -> (f64, f64) {
    (0..3)
        .map(|c| ((a.mean[c] - b.mean[c]).abs(), a.se[c].hypot(b.se[c])))
        .fold((0.0, 0.0), |acc, x| if x.0 > acc.0 { x } else { acc })
}

/// The three BSDFs (single scattering, compensated, walk) of a material, as flux.
fn bsdfs<S: AlbedoTabulated + 'static>(slope: S, mat: Mat) -> [Box<dyn Bsdf>; 3] {
    match mat {
        Mat::Conductor(_, c) => [
            Box::new(MicrofacetBsdf::new(slope, c).unwrap().with_technique(Technique::SingleScattering)),
            Box::new(microsurface::Compensated::new(slope, c).unwrap()),
            Box::new(MicrofacetBsdf::new(slope, c).unwrap()),
        ],
        Mat::Glass(_, eta) => {
            let d = Dielectric::new(eta).unwrap();
            let t = Transport::Importance;
            [
                Box::new(
                    MicrofacetBsdf::new(slope, d)
                        .unwrap()
                        .with_technique(Technique::SingleScattering)
                        .with_transport(t),
                ),
                Box::new(microsurface::Compensated::new(slope, d).unwrap().with_transport(t)),
                Box::new(MicrofacetBsdf::new(slope, d).unwrap().with_transport(t)),
            ]
        }
    }
}

fn candidates<S: AlbedoTabulated>(slope: &S, mat: Mat) -> Candidates {
    match mat {
        Mat::Conductor(_, c) => Candidates::new(slope, &c).unwrap(),
        Mat::Glass(_, eta) => Candidates::new(slope, &Dielectric::new(eta).unwrap()).unwrap(),
    }
}

fn choice<S: AlbedoTabulated, M: Budgeted>(slope: &S, m: &M, budget: f32) -> Choice {
    Choice::new(slope, m, budget).unwrap()
}

fn choices<S: AlbedoTabulated>(slope: &S, mat: Mat) -> Vec<ChosenTechnique> {
    BUDGETS
        .iter()
        .map(|&b| match mat {
            Mat::Conductor(_, c) => choice(slope, &c, b).technique,
            Mat::Glass(_, eta) => choice(slope, &Dielectric::new(eta).unwrap(), b).technique,
        })
        .collect()
}

/// One measured cell.
struct Cell {
    family: &'static str,
    material: String,
    alpha: f32,
    /// ε_ss and ε_comp measured (worse side), with standard errors.
    single: (f64, f64),
    compensated: (f64, f64),
    /// The chooser's ε_ss and bound of ε_comp.
    shipped: Candidates,
    chosen: Vec<ChosenTechnique>,
}

fn measure<S: AlbedoTabulated + 'static>(
    family: &'static str,
    slope: S,
    mat: Mat,
    n: usize,
    seed: u64,
) -> Cell {
    let [single, comp, walk] = bsdfs(slope, mat);
    let sides: &[bool] = if matches!(mat, Mat::Glass(..)) { &[false, true] } else { &[false] };
    let (mut e_single, mut e_comp) = ((0.0, 0.0), (0.0, 0.0));
    for (k, &below) in sides.iter().enumerate() {
        let seed = seed * 4 + k as u64;
        let w = hemispherical(walk.as_ref(), below, n, seed * 3);
        let s = error(hemispherical(single.as_ref(), below, n, seed * 3 + 1), w);
        let c = error(hemispherical(comp.as_ref(), below, n, seed * 3 + 2), w);
        if s.0 > e_single.0 {
            e_single = s;
        }
        if c.0 > e_comp.0 {
            e_comp = c;
        }
    }
    Cell {
        family,
        material: mat.name(),
        alpha: slope.alpha_x(),
        single: e_single,
        compensated: e_comp,
        shipped: candidates(&slope, mat),
        chosen: choices(&slope, mat),
    }
}

/// Median nanoseconds per bounce of a path tracer with next-event estimation (one `sample` and
/// one `eval_with_pdf` towards a light) of a BSDF over chunks.
fn time_per_bounce(bsdf: &dyn Bsdf, chunks: usize, per_chunk: usize) -> f64 {
    let mut rng = Pcg::seed_from_u64(99);
    let cosine = |rng: &mut Pcg| {
        let mu = rng.random::<f32>().sqrt().max(1e-3);
        let phi = std::f32::consts::TAU * rng.random::<f32>();
        let sin = (1.0 - mu * mu).sqrt();
        Vec3::new(sin * phi.cos(), sin * phi.sin(), mu)
    };
    let mut times: Vec<f64> = (0..chunks)
        .map(|_| {
            let inputs: Vec<(Vec3, f32, Vec2, Vec3)> = (0..per_chunk)
                .map(|_| {
                    let wo = cosine(&mut rng);
                    let (uc, u) = (rng.random::<f32>(), Vec2::new(rng.random::<f32>(), rng.random::<f32>()));
                    (wo, uc, u, cosine(&mut rng))
                })
                .collect();
            let start = Instant::now();
            let mut acc = 0.0f32;
            for &(wo, uc, u, light) in &inputs {
                if let Some(s) = bsdf.sample(wo, uc, u) {
                    acc += s.weight.x;
                }
                let (f, pdf) = bsdf.eval_with_pdf(wo, light);
                acc += f.f.x + pdf;
            }
            std::hint::black_box(acc);
            start.elapsed().as_secs_f64() * 1e9 / per_chunk as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[chunks / 2]
}

fn short(t: ChosenTechnique) -> &'static str {
    match t {
        ChosenTechnique::SingleScattering => "single",
        ChosenTechnique::Compensated => "compensated",
        ChosenTechnique::RandomWalk => "walk",
    }
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let n = if quick { 1 << 15 } else { 1 << 18 };
    let start = Instant::now();
    let mats = materials();
    let mut jobs: Vec<(&'static str, usize, f32)> = Vec::new();
    for family in ["ggx", "beckmann"] {
        for m in 0..mats.len() {
            for &alpha in &ALPHAS {
                jobs.push((family, m, alpha));
            }
        }
    }
    let threads = std::thread::available_parallelism().map_or(2, |t| t.get()).min(2);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut cells: Vec<(usize, Cell)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut out = Vec::new();
                    loop {
                        let j = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(&(family, m, alpha)) = jobs.get(j) else { break };
                        let seed = 1000 + j as u64;
                        let cell = if family == "ggx" {
                            measure(family, Ggx::isotropic(alpha).unwrap(), mats[m], n, seed)
                        } else {
                            measure(family, Beckmann::isotropic(alpha).unwrap(), mats[m], n, seed)
                        };
                        out.push((j, cell));
                    }
                    out
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().unwrap()).collect()
    });
    cells.sort_by_key(|c| c.0);
    let cells: Vec<Cell> = cells.into_iter().map(|c| c.1).collect();

    let mut failures = 0;
    // one-sided: the two-sided z at twice the level
    let z_check = validation::family_z(2.0 * CHECK_LEVEL, 2 * cells.len());
    // what the measurements support, per slope family and material class
    let up = |v: f64| (v * 1e3).ceil() / 1e3;
    for family in ["ggx", "beckmann"] {
        for (class, glass) in [("conductor", false), ("dielectric", true)] {
            let ours: Vec<&Cell> = cells
                .iter()
                .filter(|c| c.family == family && c.material.starts_with("glass") == glass)
                .collect();
            let bound =
                ours.iter().map(|c| c.compensated.0 + Z_SUGGEST * c.compensated.1).fold(0.0f64, f64::max);
            let shipped = ours[0].shipped.compensated.unwrap_or(f32::NAN);
            let z = ours
                .iter()
                .map(|c| (c.single.0 - f64::from(c.shipped.single.unwrap_or(0.0))) / c.single.1)
                .fold(f64::NEG_INFINITY, f64::max);
            println!(
                "{family} {class}: compensated bound supported {:.3} (shipped {shipped}); single scattering: \
                 largest z of the measured error over the chooser's {z:+.2} (the check fails above {z_check:.2})",
                up(bound)
            );
        }
    }
    for c in &cells {
        let (Some(ss), Some(cb)) = (c.shipped.single, c.shipped.compensated) else { continue };
        for (what, (e, se), bound) in [("single", c.single, ss), ("compensated", c.compensated, cb)] {
            if e - z_check * se > f64::from(bound) {
                failures += 1;
                println!(
                    "EXCEEDED {} {} α = {}: {what} measured {e:.5} ± {se:.5} > shipped {bound:.5}",
                    c.family, c.material, c.alpha
                );
            }
        }
    }

    // relative costs at GGX α = 0.5
    let (chunks, per_chunk) = if quick { (5, 500) } else { (31, 4000) };
    let slope = Ggx::isotropic(0.5).unwrap();
    let mut costs = String::new();
    for mat in [mats[1], mats[5]] {
        let b = bsdfs(slope, mat);
        let t: Vec<f64> = b.iter().map(|b| time_per_bounce(b.as_ref(), chunks, per_chunk)).collect();
        let _ =
            writeln!(costs, "| {} | {:.0} ns | {:.2} | {:.2} |", mat.name(), t[0], t[1] / t[0], t[2] / t[0]);
    }

    let mut md = String::new();
    let _ = writeln!(
        md,
        "Time per bounce of a path tracer with next-event estimation (one `sample` and one \
         `eval_with_pdf` towards a light, through `dyn Bsdf`; cosine-weighted views and lights, GGX α = 0.5, \
         the median of {chunks} chunks of {per_chunk} bounces, one thread) relative to single scattering: the chooser's `cost`.\n"
    );
    md.push_str("| material | single scattering | compensated | walk |\n|---|---|---|---|\n");
    md.push_str(&costs);
    let _ = writeln!(
        md,
        "\nHemispherical albedo error against the walk ({n} cosine-weighted views per technique and \
         side; ± one standard error) beside the chooser's single-scattering error and compensated bound, \
         and the chooser's pick for budgets {BUDGETS:?}:\n"
    );
    md.push_str(
        "| slopes | material | α | ε single (measured) | ε single (chooser) | ε compensated (measured) | bound (chooser) | choice |\n|---|---|---|---|---|---|---|---|\n",
    );
    for c in &cells {
        let opt = |v: Option<f32>| v.map_or("—".to_string(), |v| format!("{v:.4}"));
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.4} ± {:.4} | {} | {:.4} ± {:.4} | {} | {} |",
            c.family,
            c.material,
            c.alpha,
            c.single.0,
            c.single.1,
            opt(c.shipped.single),
            c.compensated.0,
            c.compensated.1,
            opt(c.shipped.compensated),
            c.chosen.iter().map(|&t| short(t)).collect::<Vec<_>>().join(" / ")
        );
    }
    println!("{md}");
    if !quick {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/techniques.md");
        std::fs::write(&path, &md).expect("write docs/techniques.md");
        println!("wrote {}", path.display());
    }
    println!(
        "{} cells in {:.1} s; {failures} exceed their shipped bound",
        cells.len(),
        start.elapsed().as_secs_f64()
    );
    if failures > 0 {
        std::process::exit(1);
    }
}
