//! Measures the error of the energy-compensated conductors (`Compensated`: Kulla–Conty, Turquin
//! and the walk's per-order lobe) and of plain single scattering against the exact multiple-scattering
//! model (the random walk of Heitz et al. 2016), GGX:
//!
//! * directional albedo error A_technique(μ) − A_walk(μ) per RGB channel, max and RMS over a
//!   grid of μ and α, for F = 1, gold, copper and aluminium;
//! * lobe-shape error: relative L1 distance of the binned f·cos θi over the hemisphere,
//!   Σ|h − h_walk| / Σ h_walk (F = 1), per α ∈ {0.1, 0.3, 0.6, 1} and θo ∈ {0, 1, 1.4}, with
//!   the noise floor of the estimate (the same distance between two independent walk runs);
//! * the albedo error of anisotropic GGX (F = 1) compensated at α = √(αx αy);
//! * glass (`Compensated` with Turquin's scaling, and with the walk's
//!   higher orders as separable reflection and transmission lobes; and single scattering): the
//!   reflected, transmitted and total albedo against the walk's (importance transport: flux),
//!   max and RMS over μ, α and η ∈ {1.33, 1.5, 2} seen from outside and from inside (1/η), and
//!   the lobe-shape error over the whole sphere (η = 1.5, both sides);
//! * the technique-choice table: per material and α, the albedo error (max over μo and RGB) and
//!   the time per sample of single scattering, the compensated lobes, the walk and the
//!   position-free PT and BDPT estimators (timed one technique at a time after the error runs,
//!   the median over short chunks of samples, which filters out preemption on a shared machine).
//!
//! Every estimate is the mean of sample weights (unbiased for each technique), with its
//! standard error. Writes `target/compensation/albedo.csv`, `lobes.csv` and `table.md`.
//!
//! ```sh
//! cargo run --release -p lab --bin compensation            # the published numbers
//! cargo run --release -p lab --bin compensation -- --quick # a smaller run (CI)
//! ```

use microsurface::glam::{Vec2, Vec3};
use microsurface::rand::{RngExt, SeedableRng};
use microsurface::research::{Estimator, Microsurface, Shadowing, UniformHeight};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{
    Bsdf, Compensated, Compensation, ComplexIor, Conductor, Dielectric, Ggx, MicrofacetBsdf, Technique,
    Transport,
};
use std::fmt::Write as _;
use std::time::Instant;

type Pcg = rand_pcg::Pcg64Mcg;

/// The techniques compared with the walk.
const TECHNIQUES: [&str; 4] = ["single", "kulla-conty", "turquin", "per-order"];
/// Their names in the tables' headers.
const TECHNIQUE_TITLES: [&str; 4] = ["single", "Kulla–Conty", "Turquin", "per-order"];
/// The stochastic estimators of the position-free model, in the technique-choice table.
const ESTIMATORS: [(&str, Estimator); 2] = [("pt", Estimator::Pt), ("bdpt", Estimator::Bdpt)];
/// The glass indices of the dielectric comparison (seen from outside; from inside 1/η).
const GLASS_ETAS: [f32; 3] = [1.33, 1.5, 2.0];

/// Lobe bins: equal-area cells in (cos θ, φ) over the upper hemisphere.
const LOBE_NZ: usize = 16;
const LOBE_NPHI: usize = 32;

struct Settings {
    alphas: Vec<f32>,
    mus: Vec<f32>,
    albedo_samples: usize,
    lobe_samples: usize,
}

fn materials() -> Vec<(&'static str, Conductor)> {
    vec![
        ("F = 1", Conductor::perfect()),
        ("gold", Conductor::new(ComplexIor::GOLD)),
        ("copper", Conductor::new(ComplexIor::COPPER)),
        ("aluminium", Conductor::new(ComplexIor::ALUMINIUM)),
    ]
}

/// The renderer-layer BSDF of a technique.
fn technique(name: &str, slope: Ggx, c: Conductor) -> Box<dyn Bsdf> {
    match name {
        "single" => {
            Box::new(MicrofacetBsdf::new(slope, c).unwrap().with_technique(Technique::SingleScattering))
        }
        "kulla-conty" => Box::new(Compensated::with_scheme(slope, c, Compensation::KullaConty).unwrap()),
        "turquin" => Box::new(Compensated::with_scheme(slope, c, Compensation::Turquin).unwrap()),
        "per-order" => Box::new(Compensated::with_scheme(slope, c, Compensation::Walk).unwrap()),
        _ => unreachable!(),
    }
}

/// Mean and standard error per channel of `n` weights.
struct Estimate {
    mean: [f64; 3],
    se: [f64; 3],
}

fn estimate(n: usize, mut draw: impl FnMut() -> Option<Vec3>) -> Estimate {
    let (mut s, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
    for _ in 0..n {
        if let Some(w) = draw() {
            for c in 0..3 {
                let x = f64::from(w[c]);
                s[c] += x;
                s2[c] += x * x;
            }
        }
    }
    let nf = n as f64;
    let mean = s.map(|v| v / nf);
    let se = core::array::from_fn(|c| ((s2[c] / nf - mean[c] * mean[c]).max(0.0) / (nf - 1.0)).sqrt());
    Estimate { mean, se }
}

fn uniforms(rng: &mut Pcg) -> (f32, Vec2) {
    (rng.random::<f32>(), Vec2::new(rng.random::<f32>(), rng.random::<f32>()))
}

/// One albedo cell: the walk and each technique at (material, α, μ).
struct AlbedoCell {
    material: &'static str,
    alpha: f32,
    mu: f32,
    walk: Estimate,
    techniques: Vec<Estimate>,
    /// PT and BDPT of the position-free model (empty in the anisotropic cells).
    estimators: Vec<Estimate>,
}

fn albedo_cell(material: &'static str, c: Conductor, alpha: f32, mu: f32, n: usize, seed: u64) -> AlbedoCell {
    let slope = Ggx::isotropic(alpha).unwrap();
    let mut cell = albedo_cell_of(material, c, slope, mu, 0.0, n, seed);
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    cell.estimators = ESTIMATORS
        .iter()
        .enumerate()
        .map(|(k, &(_, estimator))| {
            let b = MicrofacetBsdf::new(slope, c)
                .unwrap()
                .with_technique(Technique::PositionFree { estimator, shadowing: Shadowing::Correlated });
            let mut rng = Pcg::seed_from_u64(seed + 5 + k as u64);
            estimate(n, || {
                let (uc, u) = uniforms(&mut rng);
                b.sample(wo, uc, u).map(|s| s.weight)
            })
        })
        .collect();
    cell
}

/// One glass cell: reflected, transmitted and total albedo (importance transport) of the walk,
/// single scattering and Turquin's compensated dielectric at (η seen from the view's side, α, μ).
struct GlassCell {
    eta: f32,
    inside: bool,
    alpha: f32,
    mu: f32,
    /// [walk, single, turquin, kulla-conty], channels [R, T, R + T].
    albedo: [Estimate; 4],
}

/// The glass models: [walk, single, Turquin, Kulla–Conty with the walk's split], importance
/// transport.
fn glass_models(slope: Ggx, material: Dielectric) -> [Box<dyn Bsdf>; 4] {
    let mf = MicrofacetBsdf::new(slope, material).unwrap().with_transport(Transport::Importance);
    [
        Box::new(mf.with_technique(Technique::RandomWalk)),
        Box::new(mf.with_technique(Technique::SingleScattering)),
        Box::new(
            Compensated::with_scheme(slope, material, Compensation::Turquin)
                .unwrap()
                .with_transport(Transport::Importance),
        ),
        Box::new(Compensated::new(slope, material).unwrap().with_transport(Transport::Importance)),
    ]
}

/// The binned f·|cos θi| of glass over the whole sphere (2·LOBE_NZ × LOBE_NPHI equal-area
/// cells, z ∈ [−1, 1]) of `n` samples, normalized by n.
fn sphere_lobe(n: usize, mut draw: impl FnMut() -> Option<(Vec3, f32)>) -> Vec<f64> {
    let nz = 2 * LOBE_NZ;
    let mut h = vec![0.0; nz * LOBE_NPHI];
    for _ in 0..n {
        if let Some((w, weight)) = draw() {
            let iz = (((w.z + 1.0) * 0.5 * nz as f32) as usize).min(nz - 1);
            let phi = w.y.atan2(w.x).rem_euclid(core::f32::consts::TAU);
            let ip = ((phi / core::f32::consts::TAU * LOBE_NPHI as f32) as usize).min(LOBE_NPHI - 1);
            h[iz * LOBE_NPHI + ip] += f64::from(weight) / n as f64;
        }
    }
    h
}

/// One glass lobe case (η = 1.5): L1 of [single, Turquin, Kulla–Conty] against the walk, and
/// the walk-vs-walk floor.
struct GlassLobeCell {
    inside: bool,
    alpha: f32,
    theta: f32,
    floor: f64,
    errors: [f64; 3],
}

fn glass_lobe_cell(inside: bool, alpha: f32, theta: f32, n: usize, seed: u64) -> GlassLobeCell {
    let models = glass_models(Ggx::isotropic(alpha).unwrap(), Dielectric::new(1.5).unwrap());
    let wo = Vec3::new(theta.sin(), 0.0, if inside { -theta.cos() } else { theta.cos() });
    let run = |m: usize, seed: u64| {
        let mut rng = Pcg::seed_from_u64(seed);
        sphere_lobe(n, || {
            let (uc, u) = uniforms(&mut rng);
            models[m].sample(wo, uc, u).map(|s| (s.wi, s.weight.x))
        })
    };
    let (walk, walk_b) = (run(0, seed), run(0, seed + 1));
    let errors = core::array::from_fn(|k| l1(&run(k + 1, seed + 2 + k as u64), &walk));
    GlassLobeCell { inside, alpha, theta, floor: l1(&walk_b, &walk), errors }
}

fn glass_cell(eta: f32, inside: bool, alpha: f32, mu: f32, n: usize, seed: u64) -> GlassCell {
    let slope = Ggx::isotropic(alpha).unwrap();
    let material = Dielectric::new(eta).unwrap();
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    let wo = Vec3::new(s, 0.0, if inside { -mu } else { mu });
    let models = glass_models(slope, material);
    // one sample stream per model: channel 0 the reflected weight, 1 the transmitted, 2 both
    let albedo = core::array::from_fn(|m| {
        let mut rng = Pcg::seed_from_u64(seed + m as u64);
        estimate(n, || {
            let (uc, u) = uniforms(&mut rng);
            let smp = models[m].sample(wo, uc, u)?;
            let w = smp.weight.x;
            Some(if smp.flags.transmission { Vec3::new(0.0, w, w) } else { Vec3::new(w, 0.0, w) })
        })
    });
    GlassCell { eta, inside, alpha, mu, albedo }
}

/// [`albedo_cell`] for any GGX slopes and view azimuth φo.
fn albedo_cell_of(
    material: &'static str,
    c: Conductor,
    slope: Ggx,
    mu: f32,
    phi: f32,
    n: usize,
    seed: u64,
) -> AlbedoCell {
    let alpha = slope.alpha_x();
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    let wo = Vec3::new(s * phi.cos(), s * phi.sin(), mu);
    let surface = Microsurface::new(UniformHeight, slope, c);
    let mut rng = Pcg::seed_from_u64(seed);
    let walk = estimate(n, || surface.sample(wo, &mut rng).map(|s| s.weight));
    let techniques = TECHNIQUES
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let b = technique(name, slope, c);
            let mut rng = Pcg::seed_from_u64(seed + 1 + k as u64);
            estimate(n, || {
                let (uc, u) = uniforms(&mut rng);
                b.sample(wo, uc, u).map(|s| s.weight)
            })
        })
        .collect();
    AlbedoCell { material, alpha, mu, walk, techniques, estimators: vec![] }
}

/// The binned f·cos θi (F = 1, channel 0) of `n` samples, normalized by n: an estimate of
/// ∫_bin f cos dω per bin.
fn lobe(n: usize, mut draw: impl FnMut() -> Option<(Vec3, f32)>) -> Vec<f64> {
    let mut h = vec![0.0; LOBE_NZ * LOBE_NPHI];
    for _ in 0..n {
        if let Some((w, weight)) = draw() {
            if w.z <= 0.0 {
                continue;
            }
            let iz = ((w.z * LOBE_NZ as f32) as usize).min(LOBE_NZ - 1);
            let phi = w.y.atan2(w.x).rem_euclid(core::f32::consts::TAU);
            let ip = ((phi / core::f32::consts::TAU * LOBE_NPHI as f32) as usize).min(LOBE_NPHI - 1);
            h[iz * LOBE_NPHI + ip] += f64::from(weight) / n as f64;
        }
    }
    h
}

fn l1(a: &[f64], reference: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(reference).map(|(x, y)| (x - y).abs()).sum();
    d / reference.iter().sum::<f64>()
}

/// One lobe case: L1 of each technique against the walk, and the walk-vs-walk noise floor.
struct LobeCell {
    alpha: f32,
    theta: f32,
    floor: f64,
    errors: Vec<f64>,
}

fn lobe_cell(alpha: f32, theta: f32, n: usize, seed: u64) -> LobeCell {
    let slope = Ggx::isotropic(alpha).unwrap();
    let c = Conductor::perfect();
    let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
    let surface = Microsurface::new(UniformHeight, slope, c);
    let walk_lobe = |seed: u64| {
        let mut rng = Pcg::seed_from_u64(seed);
        lobe(n, || surface.sample(wo, &mut rng).map(|s| (s.wo, s.weight.x)))
    };
    let (walk, walk_b) = (walk_lobe(seed), walk_lobe(seed + 1));
    let errors = TECHNIQUES
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let b = technique(name, slope, c);
            let mut rng = Pcg::seed_from_u64(seed + 2 + k as u64);
            let h = lobe(n, || {
                let (uc, u) = uniforms(&mut rng);
                b.sample(wo, uc, u).map(|s| (s.wi, s.weight.x))
            });
            l1(&h, &walk)
        })
        .collect();
    LobeCell { alpha, theta, floor: l1(&walk_b, &walk), errors }
}

/// Runs `f` over `0..n` on all cores, results in order.
fn par_map<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let next = AtomicUsize::new(0);
    let out: Mutex<Vec<Option<T>>> = Mutex::new((0..n).map(|_| None).collect());
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= n {
                        break;
                    }
                    let r = f(i);
                    out.lock().unwrap()[i] = Some(r);
                }
            });
        }
    });
    out.into_inner().unwrap().into_iter().map(Option::unwrap).collect()
}

/// Samples per timed chunk: short enough that most chunks run without being preempted on a
/// shared machine, so that the median chunk is the unloaded cost.
const COST_CHUNK: usize = 512;

/// ns per `sample` of `b`, cycling over the views `wos`: the median over chunks of
/// [`COST_CHUNK`] samples of `n` samples in all.
fn time_samples(b: &dyn Bsdf, wos: &[Vec3], n: usize, seed: u64) -> f64 {
    let mut rng = Pcg::seed_from_u64(seed);
    let draws: Vec<(f32, Vec2)> = (0..COST_CHUNK).map(|_| uniforms(&mut rng)).collect();
    let mut times: Vec<f64> = (0..n.div_ceil(COST_CHUNK))
        .map(|chunk| {
            let t = Instant::now();
            let mut acc = Vec3::ZERO;
            for (k, &(uc, u)) in draws.iter().enumerate() {
                let wo = std::hint::black_box(wos[(k + chunk) % wos.len()]);
                if let Some(smp) = b.sample(wo, uc, u) {
                    acc += smp.weight;
                }
            }
            std::hint::black_box(acc);
            t.elapsed().as_secs_f64() * 1e9 / COST_CHUNK as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// The views of the cost runs (azimuth 0).
fn views(mus: &[f32], below: bool) -> Vec<Vec3> {
    mus.iter()
        .map(|&mu| Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, if below { -mu } else { mu }))
        .collect()
}

/// ns per sample of [single, Kulla–Conty, Turquin, per-order, walk, PT, BDPT] for a conductor.
fn conductor_cost(c: Conductor, alpha: f32, mus: &[f32], n: usize) -> [f64; 7] {
    let slope = Ggx::isotropic(alpha).unwrap();
    let wos = views(mus, false);
    let mf = MicrofacetBsdf::new(slope, c).unwrap();
    let stochastic: [Box<dyn Bsdf>; 3] = [
        Box::new(mf.with_technique(Technique::RandomWalk)),
        Box::new(mf.with_technique(Technique::PositionFree {
            estimator: Estimator::Pt,
            shadowing: Shadowing::Correlated,
        })),
        Box::new(mf.with_technique(Technique::PositionFree {
            estimator: Estimator::Bdpt,
            shadowing: Shadowing::Correlated,
        })),
    ];
    let mut out = [0.0; 7];
    for (k, name) in TECHNIQUES.iter().enumerate() {
        out[k] = time_samples(technique(name, slope, c).as_ref(), &wos, n, 30_000 + k as u64);
    }
    for (k, b) in stochastic.iter().enumerate() {
        out[4 + k] = time_samples(b.as_ref(), &wos, n / 10, 30_010 + k as u64);
    }
    out
}

/// ns per sample of [single, Turquin, walk] for glass η = 1.5 seen from outside.
fn glass_cost(alpha: f32, mus: &[f32], n: usize) -> [f64; 4] {
    let slope = Ggx::isotropic(alpha).unwrap();
    let material = Dielectric::new(1.5).unwrap();
    let wos = views(mus, false);
    let mf = MicrofacetBsdf::new(slope, material).unwrap().with_transport(Transport::Importance);
    [
        time_samples(&mf.with_technique(Technique::SingleScattering), &wos, n, 30_020),
        time_samples(
            &Compensated::with_scheme(slope, material, Compensation::Turquin)
                .unwrap()
                .with_transport(Transport::Importance),
            &wos,
            n,
            30_021,
        ),
        time_samples(&mf.with_technique(Technique::RandomWalk), &wos, n / 10, 30_022),
        time_samples(
            &Compensated::new(slope, material).unwrap().with_transport(Transport::Importance),
            &wos,
            n,
            30_023,
        ),
    ]
}

fn main() -> std::io::Result<()> {
    let quick = std::env::args().any(|a| a == "--quick");
    let s = if quick {
        Settings {
            alphas: vec![0.1, 0.5, 1.0],
            mus: vec![0.1, 0.5, 1.0],
            albedo_samples: 20_000,
            lobe_samples: 100_000,
        }
    } else {
        Settings {
            alphas: vec![0.05, 0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0],
            mus: vec![0.05, 0.15, 0.3, 0.45, 0.6, 0.75, 0.9, 1.0],
            albedo_samples: 100_000,
            lobe_samples: 1_000_000,
        }
    };
    let start = Instant::now();
    let mats = materials();
    let mut jobs: Vec<(usize, f32, f32)> = vec![];
    for m in 0..mats.len() {
        for &a in &s.alphas {
            for &mu in &s.mus {
                jobs.push((m, a, mu));
            }
        }
    }
    eprintln!("albedo: {} cells × {} samples × 4 models", jobs.len(), s.albedo_samples);
    let cells = par_map(jobs.len(), |i| {
        let (m, a, mu) = jobs[i];
        albedo_cell(mats[m].0, mats[m].1, a, mu, s.albedo_samples, 16_000 + 8 * i as u64)
    });
    // anisotropic slopes, compensated at α = √(αx αy): F = 1, φo ∈ {0, π/4, π/2}
    let anisotropic = [(0.1f32, 0.4f32), (0.2, 0.8), (0.5, 1.0)];
    let mut aniso_jobs = vec![];
    for (k, &(ax, ay)) in anisotropic.iter().enumerate() {
        for phi in [0.0f32, core::f32::consts::FRAC_PI_4, core::f32::consts::FRAC_PI_2] {
            for &mu in &s.mus {
                aniso_jobs.push((k, ax, ay, phi, mu));
            }
        }
    }
    eprintln!("anisotropic albedo: {} cells × {} samples × 4 models", aniso_jobs.len(), s.albedo_samples);
    let aniso_cells = par_map(aniso_jobs.len(), |i| {
        let (_, ax, ay, phi, mu) = aniso_jobs[i];
        let slope = Ggx::new(ax, ay).unwrap();
        albedo_cell_of("F = 1", Conductor::perfect(), slope, mu, phi, s.albedo_samples, 18_000 + 8 * i as u64)
    });
    let lobe_jobs: Vec<(f32, f32)> =
        [0.1f32, 0.3, 0.6, 1.0].iter().flat_map(|&a| [0.0f32, 1.0, 1.4].map(|t| (a, t))).collect();
    eprintln!("lobes: {} cases × {} samples × 5 runs", lobe_jobs.len(), s.lobe_samples);
    let lobes = par_map(lobe_jobs.len(), |i| {
        lobe_cell(lobe_jobs[i].0, lobe_jobs[i].1, s.lobe_samples, 17_000 + 8 * i as u64)
    });

    let mut glass_jobs = vec![];
    for &eta in &GLASS_ETAS {
        for inside in [false, true] {
            for &a in &s.alphas {
                for &mu in &s.mus {
                    glass_jobs.push((eta, inside, a, mu));
                }
            }
        }
    }
    eprintln!("glass albedo: {} cells × {} samples × 4 models", glass_jobs.len(), s.albedo_samples);
    let glass = par_map(glass_jobs.len(), |i| {
        let (eta, inside, a, mu) = glass_jobs[i];
        glass_cell(eta, inside, a, mu, s.albedo_samples, 19_000 + 8 * i as u64)
    });

    let glass_lobe_jobs: Vec<(bool, f32, f32)> = [false, true]
        .iter()
        .flat_map(|&inside| {
            [0.1f32, 0.3, 0.6, 1.0].iter().flat_map(move |&a| [0.0f32, 1.0, 1.4].map(|t| (inside, a, t)))
        })
        .collect();
    eprintln!("glass lobes: {} cases × {} samples × 5 runs", glass_lobe_jobs.len(), s.lobe_samples);
    let glass_lobes = par_map(glass_lobe_jobs.len(), |i| {
        let (inside, a, t) = glass_lobe_jobs[i];
        glass_lobe_cell(inside, a, t, s.lobe_samples, 21_000 + 8 * i as u64)
    });

    let dir = std::path::Path::new("target/compensation");
    std::fs::create_dir_all(dir)?;
    let mut csv = String::from("material,alpha,mu,channel,walk,walk_se");
    for t in TECHNIQUES {
        write!(csv, ",{t},{t}_se").unwrap();
    }
    csv.push('\n');
    for cell in &cells {
        for c in 0..3 {
            write!(
                csv,
                "{},{},{},{c},{:.6},{:.2e}",
                cell.material, cell.alpha, cell.mu, cell.walk.mean[c], cell.walk.se[c]
            )
            .unwrap();
            for e in &cell.techniques {
                write!(csv, ",{:.6},{:.2e}", e.mean[c], e.se[c]).unwrap();
            }
            csv.push('\n');
        }
    }
    std::fs::write(dir.join("albedo.csv"), csv)?;
    let mut csv = String::from("alpha,theta_o,walk_noise_floor");
    for t in TECHNIQUES {
        write!(csv, ",{t}").unwrap();
    }
    csv.push('\n');
    for l in &lobes {
        write!(csv, "{},{},{:.4}", l.alpha, l.theta, l.floor).unwrap();
        for e in &l.errors {
            write!(csv, ",{e:.4}").unwrap();
        }
        csv.push('\n');
    }
    std::fs::write(dir.join("lobes.csv"), csv)?;

    // the markdown tables
    let mut md = String::new();
    writeln!(
        md,
        "Directional albedo error against the walk (GGX, α ∈ {:?}, μo ∈ {:?}, {} samples per model and cell; \
         max |A − A_walk| and RMS over cells and RGB channels; largest standard error of a difference {:.1e}):\n",
        s.alphas,
        s.mus,
        s.albedo_samples,
        cells
            .iter()
            .flat_map(|c| c.techniques.iter().flat_map(|e| (0..3).map(|ch| e.se[ch].hypot(c.walk.se[ch]))))
            .fold(0.0, f64::max)
    )
    .unwrap();
    writeln!(md, "| material |{}", TECHNIQUE_TITLES.map(|t| format!(" {t}: max | RMS |")).concat()).unwrap();
    writeln!(md, "|---|{}", "---|---|".repeat(TECHNIQUES.len())).unwrap();
    for (name, _) in &mats {
        write!(md, "| {name} |").unwrap();
        for k in 0..TECHNIQUES.len() {
            let errs: Vec<f64> = cells
                .iter()
                .filter(|c| c.material == *name)
                .flat_map(|c| (0..3).map(move |ch| c.techniques[k].mean[ch] - c.walk.mean[ch]))
                .collect();
            let max = errs.iter().fold(0.0f64, |m, e| m.max(e.abs()));
            let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
            write!(md, " {max:.4} | {rms:.4} |").unwrap();
        }
        md.push('\n');
    }
    writeln!(
        md,
        "\nSampling quality: the standard deviation σ of one sample's weight (the one-sample albedo estimate; \
         the lower, the better the pdf follows f·cos), mean and max over the cells and RGB channels above:\n"
    )
    .unwrap();
    writeln!(md, "| material |{}", TECHNIQUE_TITLES.map(|t| format!(" {t}: mean σ | max σ |")).concat())
        .unwrap();
    writeln!(md, "|---|{}", "---|---|".repeat(TECHNIQUES.len())).unwrap();
    let n_albedo = (s.albedo_samples as f64).sqrt();
    for (name, _) in &mats {
        write!(md, "| {name} |").unwrap();
        for k in 0..TECHNIQUES.len() {
            let sigmas: Vec<f64> = cells
                .iter()
                .filter(|c| c.material == *name)
                .flat_map(|c| (0..3).map(move |ch| c.techniques[k].se[ch] * n_albedo))
                .collect();
            let max = sigmas.iter().fold(0.0f64, |m, &e| m.max(e));
            let mean = sigmas.iter().sum::<f64>() / sigmas.len() as f64;
            write!(md, " {mean:.4} | {max:.4} |").unwrap();
        }
        md.push('\n');
    }
    writeln!(
        md,
        "\nAnisotropic GGX, F = 1, compensated at α = √(αx αy): albedo error over μo (as above) and \
         φo ∈ {{0, π/4, π/2}}:\n"
    )
    .unwrap();
    writeln!(md, "| αx, αy |{}", TECHNIQUE_TITLES.map(|t| format!(" {t}: max | RMS |")).concat()).unwrap();
    writeln!(md, "|---|{}", "---|---|".repeat(TECHNIQUES.len())).unwrap();
    for (k, (ax, ay)) in anisotropic.iter().enumerate() {
        write!(md, "| {ax}, {ay} |").unwrap();
        for t in 0..TECHNIQUES.len() {
            let errs: Vec<f64> = aniso_jobs
                .iter()
                .zip(&aniso_cells)
                .filter(|(j, _)| j.0 == k)
                .map(|(_, c)| c.techniques[t].mean[0] - c.walk.mean[0])
                .collect();
            let max = errs.iter().fold(0.0f64, |m, e| m.max(e.abs()));
            let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
            write!(md, " {max:.4} | {rms:.4} |").unwrap();
        }
        md.push('\n');
    }
    writeln!(
        md,
        "\nLobe-shape error against the walk (F = 1, relative L1 of f·cos θi binned in {LOBE_NZ} × {LOBE_NPHI} \
         equal-area cells of the hemisphere, {} samples per run; the floor is the L1 distance between two \
         independent walk runs, the noise in every entry):\n",
        s.lobe_samples
    )
    .unwrap();
    writeln!(md, "| α | θo | floor |{}", TECHNIQUE_TITLES.map(|t| format!(" {t} |")).concat()).unwrap();
    writeln!(md, "|---|---|---|{}", "---|".repeat(TECHNIQUES.len())).unwrap();
    for l in &lobes {
        write!(md, "| {} | {} | {:.3} |", l.alpha, l.theta, l.floor).unwrap();
        for e in &l.errors {
            write!(md, " {e:.3} |").unwrap();
        }
        md.push('\n');
    }
    writeln!(
        md,
        "\nGlass (GGX, η ∈ {GLASS_ETAS:?} seen from outside and 1/η from inside, α and μo as above, importance \
         transport): albedo error against the walk, max |A − A_walk| and RMS over cells, of the reflected (R), \
         transmitted (T) and total (R + T = 1 for the walk) albedo:\n"
    )
    .unwrap();
    writeln!(md, "| technique | side | R: max | RMS | T: max | RMS | R + T: max | RMS |").unwrap();
    writeln!(md, "|---|---|---|---|---|---|---|---|").unwrap();
    for (m, name) in [(1usize, "single"), (2, "Turquin"), (3, "Kulla–Conty (walk split)")] {
        for inside in [false, true] {
            write!(md, "| {name} | {} |", if inside { "inside" } else { "outside" }).unwrap();
            for part in 0..3 {
                let errs: Vec<f64> = glass
                    .iter()
                    .filter(|c| c.inside == inside)
                    .map(|c| c.albedo[m].mean[part] - c.albedo[0].mean[part])
                    .collect();
                let max = errs.iter().fold(0.0f64, |x, e| x.max(e.abs()));
                let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
                write!(md, " {max:.4} | {rms:.4} |").unwrap();
            }
            md.push('\n');
        }
    }
    writeln!(
        md,
        "\nGlass sampling quality: σ of one sample's total (R + T) weight, mean and max over the cells above:\n"
    )
    .unwrap();
    writeln!(md, "| technique | side | mean σ | max σ |").unwrap();
    writeln!(md, "|---|---|---|---|").unwrap();
    for (m, name) in [(1usize, "single"), (2, "Turquin"), (3, "Kulla–Conty (walk split)")] {
        for inside in [false, true] {
            let sigmas: Vec<f64> =
                glass.iter().filter(|c| c.inside == inside).map(|c| c.albedo[m].se[2] * n_albedo).collect();
            let max = sigmas.iter().fold(0.0f64, |x, &e| x.max(e));
            let mean = sigmas.iter().sum::<f64>() / sigmas.len() as f64;
            writeln!(md, "| {name} | {} | {mean:.4} | {max:.4} |", if inside { "inside" } else { "outside" })
                .unwrap();
        }
    }
    writeln!(
        md,
        "\nGlass lobe shape against the walk (GGX, η = 1.5, importance transport; relative L1 of f·|cos θi| \
         binned in {} × {LOBE_NPHI} equal-area cells of the sphere, {} samples per run; floor: two walk runs):\n",
        2 * LOBE_NZ,
        s.lobe_samples
    )
    .unwrap();
    writeln!(md, "| side | α | θo | floor | single | Turquin | Kulla–Conty (walk split) |").unwrap();
    writeln!(md, "|---|---|---|---|---|---|---|").unwrap();
    for l in &glass_lobes {
        writeln!(
            md,
            "| {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} |",
            if l.inside { "inside" } else { "outside" },
            l.alpha,
            l.theta,
            l.floor,
            l.errors[0],
            l.errors[1],
            l.errors[2]
        )
        .unwrap();
    }
    let mut csv = String::from(
        "eta,side,alpha,mu,part,walk,walk_se,single,single_se,turquin,turquin_se,kulla_conty,kulla_conty_se\n",
    );
    for c in &glass {
        for (part, pname) in ["R", "T", "total"].iter().enumerate() {
            write!(
                csv,
                "{},{},{},{},{pname}",
                c.eta,
                if c.inside { "inside" } else { "outside" },
                c.alpha,
                c.mu
            )
            .unwrap();
            for m in 0..4 {
                write!(csv, ",{:.6},{:.2e}", c.albedo[m].mean[part], c.albedo[m].se[part]).unwrap();
            }
            csv.push('\n');
        }
    }
    std::fs::write(dir.join("glass.csv"), csv)?;

    // the cost of each technique, timed serially (one thread busy) after the error runs
    eprintln!(
        "cost: {} rows × 7 techniques, timed one after the other",
        mats.len() * s.alphas.len() + s.alphas.len()
    );
    let cost_samples = if quick { 40_000 } else { 200_000 };
    let costs: Vec<[f64; 7]> = mats
        .iter()
        .flat_map(|&(_, c)| s.alphas.iter().map(move |&a| (c, a)))
        .map(|(c, a)| conductor_cost(c, a, &s.mus, cost_samples))
        .collect();
    let glass_costs: Vec<[f64; 4]> = s.alphas.iter().map(|&a| glass_cost(a, &s.mus, cost_samples)).collect();
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();

    // the technique-choice table: per material and α, max over μo (and RGB) of |A − A_walk|,
    // and the time per sample
    writeln!(
        md,
        "\nTechnique choice (GGX): albedo error against the walk, max over μo ∈ {:?} and RGB, and time per \
         sample (ns per `Bsdf::sample` through `Box<dyn Bsdf>`, median over chunks of {COST_CHUNK} samples of {cost_samples} \
         (a tenth for walk, PT and BDPT) cycling over the μo, each technique timed alone after the error \
         runs; load average {}). The walk is the reference (error 0, its standard error is in the headers above); \
         PT and BDPT are the position-free model's estimators (Wang et al. 2022), a different model whose albedo \
         differs from the walk's by the entry. Glass: total albedo, importance transport, η = 1.5 from outside \
         (Kulla–Conty: the walk split); then the larger error of R and T, views from both sides.\n",
        s.mus,
        load.split_whitespace().take(3).collect::<Vec<_>>().join(" ")
    )
    .unwrap();
    writeln!(
        md,
        "| material | α |{} PT | BDPT | ns: single | Kulla–Conty | Turquin | per-order | walk | PT | BDPT |",
        TECHNIQUE_TITLES.map(|t| format!(" {t} |")).concat()
    )
    .unwrap();
    writeln!(md, "|---|---|{}", "---|".repeat(TECHNIQUES.len() + 2 + 7)).unwrap();
    let mut row_index = 0;
    for (name, _) in &mats {
        for &a in &s.alphas {
            let row: Vec<&AlbedoCell> =
                cells.iter().filter(|c| c.material == *name && c.alpha == a).collect();
            let err = |f: &dyn Fn(&AlbedoCell) -> &Estimate| {
                row.iter()
                    .flat_map(|c| (0..3).map(|ch| (f(c).mean[ch] - c.walk.mean[ch]).abs()))
                    .fold(0.0f64, f64::max)
            };
            write!(md, "| {name} | {a} |").unwrap();
            for k in 0..TECHNIQUES.len() {
                write!(md, " {:.4} |", err(&|c| &c.techniques[k])).unwrap();
            }
            for k in 0..2 {
                write!(md, " {:.4} |", err(&|c| &c.estimators[k])).unwrap();
            }
            for ns in costs[row_index] {
                write!(md, " {ns:.0} |").unwrap();
            }
            row_index += 1;
            md.push('\n');
        }
    }
    for (&a, ns) in s.alphas.iter().zip(&glass_costs) {
        let row: Vec<&GlassCell> =
            glass.iter().filter(|c| c.eta == 1.5 && !c.inside && c.alpha == a).collect();
        let err = |m: usize| {
            row.iter().map(|c| (c.albedo[m].mean[2] - c.albedo[0].mean[2]).abs()).fold(0.0f64, f64::max)
        };
        writeln!(
            md,
            "| glass 1.5 | {a} | {:.4} | {:.4} | {:.4} | — | — | — | {:.0} | {:.0} | {:.0} | — | {:.0} | — | — |",
            err(1),
            err(3),
            err(2),
            ns[0],
            ns[3],
            ns[1],
            ns[2]
        )
        .unwrap();
    }
    // where the energy goes: the larger of the R and T errors, views from both sides
    for &a in &s.alphas {
        let row: Vec<&GlassCell> = glass.iter().filter(|c| c.eta == 1.5 && c.alpha == a).collect();
        let err = |m: usize| {
            row.iter()
                .flat_map(|c| (0..2).map(move |p| (c.albedo[m].mean[p] - c.albedo[0].mean[p]).abs()))
                .fold(0.0f64, f64::max)
        };
        writeln!(
            md,
            "| glass 1.5, R and T, both sides | {a} | {:.4} | {:.4} | {:.4} | — | — | — | | | | | | | |",
            err(1),
            err(3),
            err(2)
        )
        .unwrap();
    }
    std::fs::write(dir.join("table.md"), &md)?;
    println!("{md}");
    eprintln!("wrote {} in {:.1} s", dir.display(), start.elapsed().as_secs_f64());
    Ok(())
}
