//! The computations of the report: error against run time, lobes per scattering order,
//! energy per order and cost. Shared by `main.rs` and `tests/report.rs`.

use super::plot::{Canvas, PALETTE, Series, loglog_chart, polar_chart};
use glam::Vec3;
use microsurface::{
    Beckmann, Conductor, Dielectric, Diffuse, Ggx, MAX_BOUNCES, Material, Microsurface, MicrosurfaceSlope,
    PositionFree, ScatteringOrder, Shadowing, UniformHeight,
};
use rand::SeedableRng;
use std::fmt::Write as _;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

type Rng = rand_pcg::Pcg64Mcg;

/// What to compute and where to write it.
#[derive(Debug, Clone)]
pub struct Options {
    /// A small run for CI (seconds instead of a minute).
    pub quick: bool,
    /// Output directory.
    pub out_dir: PathBuf,
    /// Worker threads.
    pub threads: usize,
    /// Print a progress bar on stderr (`main` sets it only when stderr is a terminal).
    pub progress: bool,
}

/// Sample counts of one run.
#[derive(Debug, Clone, Copy)]
struct Budget {
    /// Evaluations per estimator and configuration.
    samples: usize,
    /// Evaluations of the converged reference, as a multiple of `samples`.
    reference_factor: usize,
    lobe_angles: usize,
    lobe_samples: usize,
    energy_walks: usize,
    furnace_samples: usize,
    cost_calls: usize,
}

impl Budget {
    fn new(quick: bool) -> Self {
        if quick {
            Self {
                samples: 1 << 10,
                reference_factor: 4,
                lobe_angles: 13,
                lobe_samples: 96,
                energy_walks: 1 << 10,
                furnace_samples: 1 << 10,
                cost_calls: 2_000,
            }
        } else {
            Self {
                samples: 1 << 15,
                reference_factor: 4,
                lobe_angles: 61,
                lobe_samples: 2048,
                energy_walks: 1 << 15,
                furnace_samples: 1 << 15,
                cost_calls: 100_000,
            }
        }
    }
}

/// The estimators compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Est {
    Single,
    Walk,
    PtUncorrelated,
    PtCorrelated,
    BdptUncorrelated,
    BdptCorrelated,
}

impl Est {
    pub const ALL: [Est; 6] = [
        Est::Single,
        Est::Walk,
        Est::PtUncorrelated,
        Est::PtCorrelated,
        Est::BdptUncorrelated,
        Est::BdptCorrelated,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Est::Single => "single",
            Est::Walk => "heitz-walk",
            Est::PtUncorrelated => "pt-uncorr",
            Est::PtCorrelated => "pt-corr",
            Est::BdptUncorrelated => "bdpt-uncorr",
            Est::BdptCorrelated => "bdpt-corr",
        }
    }

    /// The estimator that computes the converged reference of this estimator's model.
    fn reference(self) -> Est {
        match self {
            Est::PtUncorrelated => Est::BdptUncorrelated,
            Est::PtCorrelated => Est::BdptCorrelated,
            other => other,
        }
    }
}

/// The configurations of the error study.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Config {
    ConductorGgx1,
    ConductorGgx01,
    DielectricGgx1,
    DiffuseGgx1,
    ConductorBeckmann05,
}

impl Config {
    pub const ALL: [Config; 5] = [
        Config::ConductorGgx1,
        Config::ConductorGgx01,
        Config::DielectricGgx1,
        Config::DiffuseGgx1,
        Config::ConductorBeckmann05,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Config::ConductorGgx1 => "conductor-ggx-a1.0",
            Config::ConductorGgx01 => "conductor-ggx-a0.1",
            Config::DielectricGgx1 => "dielectric-ggx-a1.0",
            Config::DiffuseGgx1 => "diffuse-ggx-a1.0",
            Config::ConductorBeckmann05 => "conductor-beckmann-a0.5",
        }
    }
}

/// The three models behind the estimators, over one slope and material.
struct Models<S, M> {
    walk: Microsurface<UniformHeight, S, M>,
    uncorrelated: PositionFree<S, M>,
    correlated: PositionFree<S, M>,
}

impl<S: MicrosurfaceSlope, M: Material> Models<S, M> {
    fn new(slope: S, material: M) -> Self {
        Self {
            walk: Microsurface::new(UniformHeight, slope, material),
            uncorrelated: PositionFree::new(slope, material, Shadowing::Uncorrelated),
            correlated: PositionFree::new(slope, material, Shadowing::Correlated),
        }
    }

    /// One estimate of f·|cos θo| (mean over RGB).
    #[inline]
    fn eval(&self, est: Est, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut Rng) -> f64 {
        let v = match est {
            Est::Single => self.walk.eval_single_scattering(wi, wo, rng),
            Est::Walk => self.walk.eval(wi, wo, order, rng),
            Est::PtUncorrelated => self.uncorrelated.eval_pt(wi, wo, order, rng),
            Est::PtCorrelated => self.correlated.eval_pt(wi, wo, order, rng),
            Est::BdptUncorrelated => self.uncorrelated.eval_bdpt(wi, wo, order, rng),
            Est::BdptCorrelated => self.correlated.eval_bdpt(wi, wo, order, rng),
        };
        f64::from(v.element_sum()) / 3.0
    }
}

fn dir(theta: f64, phi: f64) -> Vec3 {
    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32)
}

/// The incident angles of the error study and energy table.
pub const THETAS: [f64; 3] = [0.0, 1.0, 1.5];

/// The outgoing directions of the error study for θi: the mirror direction, the normal
/// (or a 0.6 rad tilt at normal incidence) and, for the dielectric, the transmission through
/// the macrosurface; otherwise a side-scattering direction.
fn outgoing(config: Config, theta_i: f64) -> [(&'static str, Vec3); 3] {
    let third = if config == Config::DielectricGgx1 {
        ("transmission", dir(std::f64::consts::PI - 0.6 * theta_i.max(0.3), std::f64::consts::PI))
    } else {
        ("side", dir(1.2, std::f64::consts::FRAC_PI_2))
    };
    [
        ("mirror", dir(theta_i.max(0.15), std::f64::consts::PI)),
        ("normal", if theta_i == 0.0 { dir(0.6, 0.0) } else { Vec3::Z }),
        third,
    ]
}

/// Per-sample values of one estimator in one configuration, with its timing.
struct Run {
    config: Config,
    theta_i: f64,
    wo_label: &'static str,
    est: Est,
    values: Vec<f32>,
    timing: Timing,
}

/// The measured cost of one estimator run: the mean time per sample and its standard error
/// from `TIMING_CHUNKS` separately timed chunks of the run.
#[derive(Debug, Clone, Copy)]
struct Timing {
    ns_per_sample: f64,
    ns_se: f64,
}

/// The number of separately timed chunks of an estimator run (for the SE of its cost).
const TIMING_CHUNKS: usize = 16;

/// Runs `n` evaluations single-threaded and times them in `TIMING_CHUNKS` chunks. The model
/// and both directions pass through `black_box` on every call, so that nothing that depends
/// on them is hoisted out of the timed loop (the error study estimates one value, so its
/// inputs cannot rotate; `cost` rotates pre-generated directions).
fn run_estimator(config: Config, est: Est, wi: Vec3, wo: Vec3, n: usize, seed: u64) -> (Vec<f32>, Timing) {
    fn go<S: MicrosurfaceSlope, M: Material>(
        m: Models<S, M>,
        est: Est,
        wi: Vec3,
        wo: Vec3,
        n: usize,
        seed: u64,
    ) -> (Vec<f32>, Timing) {
        let mut rng = Rng::seed_from_u64(seed);
        let mut values = Vec::with_capacity(n);
        let chunk = n.div_ceil(TIMING_CHUNKS).max(1);
        let (mut total_ns, mut per_chunk) = (0.0, Vec::with_capacity(TIMING_CHUNKS));
        while values.len() < n {
            let len = chunk.min(n - values.len());
            let start = Instant::now();
            for _ in 0..len {
                let v = black_box(&m).eval(est, black_box(wi), black_box(wo), ScatteringOrder::All, &mut rng);
                values.push(v as f32);
            }
            let ns = start.elapsed().as_secs_f64() * 1e9;
            total_ns += ns;
            per_chunk.push(ns / len as f64);
        }
        let k = per_chunk.len() as f64;
        let mean_chunk = per_chunk.iter().sum::<f64>() / k;
        let var_chunk = per_chunk.iter().map(|t| (t - mean_chunk).powi(2)).sum::<f64>() / (k - 1.0).max(1.0);
        (values, Timing { ns_per_sample: total_ns / n as f64, ns_se: (var_chunk / k).sqrt() })
    }
    let ggx = |a| Ggx::isotropic(a).expect("valid α");
    match config {
        Config::ConductorGgx1 => go(Models::new(ggx(1.0), Conductor::perfect()), est, wi, wo, n, seed),
        Config::ConductorGgx01 => go(Models::new(ggx(0.1), Conductor::perfect()), est, wi, wo, n, seed),
        Config::DielectricGgx1 => {
            go(Models::new(ggx(1.0), Dielectric::new(1.5).expect("valid η")), est, wi, wo, n, seed)
        }
        Config::DiffuseGgx1 => go(Models::new(ggx(1.0), Diffuse::white()), est, wi, wo, n, seed),
        Config::ConductorBeckmann05 => go(
            Models::new(Beckmann::isotropic(0.5).expect("valid α"), Conductor::perfect()),
            est,
            wi,
            wo,
            n,
            seed,
        ),
    }
}

/// Runs `jobs` on `threads` workers, reporting progress on stderr.
fn parallel<T: Send, R: Send>(
    label: &str,
    jobs: Vec<T>,
    opts: &Options,
    work: impl Fn(T) -> R + Sync,
) -> Vec<R> {
    let total = jobs.len();
    let queue = Mutex::new(jobs.into_iter().enumerate().collect::<Vec<_>>());
    let done = AtomicUsize::new(0);
    let results = Mutex::new(Vec::with_capacity(total));
    std::thread::scope(|s| {
        for _ in 0..opts.threads.max(1) {
            s.spawn(|| {
                loop {
                    let Some((i, job)) = queue.lock().expect("queue").pop() else { break };
                    let r = work(job);
                    results.lock().expect("results").push((i, r));
                    let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                    if opts.progress {
                        let bar = 30 * d / total.max(1);
                        eprint!("\r{label:<22} [{}{}] {d}/{total}", "=".repeat(bar), " ".repeat(30 - bar));
                    }
                }
            });
        }
    });
    if opts.progress {
        eprintln!();
    }
    let mut results = results.into_inner().expect("results");
    results.sort_by_key(|(i, _)| *i);
    results.into_iter().map(|(_, r)| r).collect()
}

fn mean_and_variance(values: &[f32]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let var = values.iter().map(|&v| (f64::from(v) - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, var)
}

/// The standard error of the sample variance: the standard deviation of the squared
/// deviations (x − mean)² over √n (delta method; it needs a finite fourth moment, so for
/// heavy-tailed estimators it is itself uncertain).
fn variance_se(values: &[f32], mean: f64) -> f64 {
    let n = values.len() as f64;
    let sq: Vec<f64> = values.iter().map(|&v| (f64::from(v) - mean).powi(2)).collect();
    let m = sq.iter().sum::<f64>() / n;
    let v = sq.iter().map(|q| (q - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (v / n).sqrt()
}

/// One row of the efficiency table (all fields are read by `tests/report.rs`).
#[allow(dead_code)]
#[derive(Debug, Clone)]
pub struct EfficiencyRow {
    pub config: Config,
    pub theta_i: f64,
    pub wo: &'static str,
    pub est: Est,
    pub mean: f64,
    pub std: f64,
    /// Standard error of the sample variance σ̂² (`variance_se`).
    pub variance_se: f64,
    pub ns_per_sample: f64,
    /// Standard error of `ns_per_sample` over the timed chunks of the run.
    pub ns_se: f64,
    pub reference: f64,
    pub reference_se: f64,
    /// 1/(relative variance × seconds per sample).
    pub efficiency: f64,
    /// (samples, seconds, relative RMSE) measured on batches.
    pub curve: Vec<(usize, f64, f64)>,
}

/// One row of the energy table: (label, θi, R, T, per order [1, 2, 3, 4+], mean bounces,
/// furnace ∫eval, its SE).
pub type EnergyRow = (String, f64, f64, f64, [f64; 4], f64, f64, f64);

/// A ratio of efficiencies, geometric mean over θi and ωo, with its 95 % confidence interval.
///
/// Per (θi, ωo) the log ratio is ln e_a − ln e_b with e = reference²/(σ̂² t); its variance is
/// propagated by the delta method from the standard errors of both sample variances
/// (`variance_se`), of both times per sample (over the timed chunks) and, where the two
/// estimators have different references, of both references. The geometric mean's log is the
/// mean of the J log ratios with SE √(Σ var)/J; the interval is exp(mean ± 1.96 SE). It covers
/// the sampling noise of one run (not a change of machine load between runs, nor the
/// unreliability of σ̂² for heavy-tailed estimators).
#[allow(dead_code)] // the components are read by tests/report.rs
#[derive(Debug, Clone, Copy)]
pub struct Ratio {
    pub estimate: f64,
    pub lo: f64,
    pub hi: f64,
    /// Geometric mean of σ̂²_b/σ̂²_a (relative variances): how much lower a's variance is.
    pub variance_ratio: f64,
    /// Geometric mean of t_a/t_b: how much more a costs per sample.
    pub cost_ratio: f64,
    /// The number of (θi, ωo) pairs in the mean.
    pub pairs: usize,
}

/// What the report found, for the summary and the tests.
#[derive(Debug, Clone, Default)]
pub struct Summary {
    pub efficiency: Vec<EfficiencyRow>,
    /// (config, ratio of PT-corr to walk efficiency, ratio of BDPT-corr to PT-corr).
    pub ratios: Vec<(Config, Ratio, Ratio)>,
    /// (label, θi, R, T, per order [1, 2, 3, 4+], mean bounces, furnace ∫eval, its SE).
    pub energy: Vec<EnergyRow>,
    /// (model, ns per eval, ns per sample, mean bounces).
    pub cost: Vec<(String, f64, f64, f64)>,
    pub files: Vec<PathBuf>,
    pub markdown: String,
}

fn error_study(opts: &Options, budget: Budget, summary: &mut Summary) -> std::io::Result<()> {
    let mut jobs = Vec::new();
    for config in Config::ALL {
        for theta_i in THETAS {
            for (label, wo) in outgoing(config, theta_i) {
                for est in Est::ALL {
                    jobs.push((config, theta_i, label, wo, est, budget.samples, false));
                }
                for est in [Est::Walk, Est::BdptUncorrelated, Est::BdptCorrelated] {
                    jobs.push((
                        config,
                        theta_i,
                        label,
                        wo,
                        est,
                        budget.samples * budget.reference_factor,
                        true,
                    ));
                }
            }
        }
    }
    let seed_of = |i: usize| 0x5EED_0000 + i as u64;
    let jobs: Vec<_> = jobs.into_iter().enumerate().collect();
    let runs = parallel("error vs time", jobs, opts, |(i, (config, theta_i, label, wo, est, n, is_ref))| {
        let wi = dir(theta_i, 0.0);
        let (values, timing) = run_estimator(config, est, wi, wo, n, seed_of(i));
        (is_ref, Run { config, theta_i, wo_label: label, est, values, timing })
    });
    let (refs, runs): (Vec<_>, Vec<_>) = runs.into_iter().partition(|(is_ref, _)| *is_ref);
    let mut csv = String::from("config,theta_i,wo,estimator,samples,time_s,rmse,rel_rmse\n");
    let mut eff_csv = String::from(
        "config,theta_i,wo,estimator,mean,std,variance_se,ns_per_sample,ns_se,reference,reference_se,efficiency_per_s\n",
    );
    for (_, run) in &runs {
        let (mean, var) = mean_and_variance(&run.values);
        let (reference, reference_se) = if run.est == Est::Single && run.config != Config::DiffuseGgx1 {
            (mean, 0.0)
        } else {
            let r = refs
                .iter()
                .map(|(_, r)| r)
                .find(|r| {
                    r.config == run.config
                        && r.theta_i == run.theta_i
                        && r.wo_label == run.wo_label
                        && r.est == run.est.reference()
                })
                .map(|r| {
                    let (m, v) = mean_and_variance(&r.values);
                    (m, (v / r.values.len() as f64).sqrt())
                });
            r.unwrap_or((mean, (var / run.values.len() as f64).sqrt()))
        };
        let scale = if reference.abs() > 0.0 { reference.abs() } else { 1.0 };
        let mut curve = Vec::new();
        let mut batch = 1;
        while batch * 16 <= run.values.len() {
            let batches = run.values.len() / batch;
            let mse = run
                .values
                .chunks_exact(batch)
                .map(|c| (c.iter().map(|&v| f64::from(v)).sum::<f64>() / batch as f64 - reference).powi(2))
                .sum::<f64>()
                / batches as f64;
            let seconds = batch as f64 * run.timing.ns_per_sample * 1e-9;
            curve.push((batch, seconds, mse.sqrt() / scale));
            let _ = writeln!(
                csv,
                "{},{},{},{},{batch},{seconds:.3e},{:.4e},{:.4e}",
                run.config.name(),
                run.theta_i,
                run.wo_label,
                run.est.name(),
                mse.sqrt(),
                mse.sqrt() / scale
            );
            batch *= 2;
        }
        let rel_var = var / (scale * scale);
        let efficiency =
            if rel_var > 0.0 { 1.0 / (rel_var * run.timing.ns_per_sample * 1e-9) } else { f64::INFINITY };
        let var_se = variance_se(&run.values, mean);
        let _ = writeln!(
            eff_csv,
            "{},{},{},{},{mean:.6e},{:.4e},{var_se:.4e},{:.1},{:.2},{reference:.6e},{reference_se:.2e},{efficiency:.4e}",
            run.config.name(),
            run.theta_i,
            run.wo_label,
            run.est.name(),
            var.sqrt(),
            run.timing.ns_per_sample,
            run.timing.ns_se
        );
        summary.efficiency.push(EfficiencyRow {
            config: run.config,
            theta_i: run.theta_i,
            wo: run.wo_label,
            est: run.est,
            mean,
            std: var.sqrt(),
            variance_se: var_se,
            ns_per_sample: run.timing.ns_per_sample,
            ns_se: run.timing.ns_se,
            reference,
            reference_se,
            efficiency,
            curve,
        });
    }
    write(opts, "errors.csv", &csv, summary)?;
    write(opts, "efficiency.csv", &eff_csv, summary)?;

    // efficiency ratios (geometric means over θi and ωo where both are finite), with
    // delta-method confidence intervals (see `Ratio`)
    let mut ratio_csv =
        String::from("config,ratio,estimate,ci95_lo,ci95_hi,variance_ratio,cost_ratio,pairs\n");
    for config in Config::ALL {
        let ratio = |a: Est, b: Est| {
            let rel2 = |x: f64, se: f64| if x != 0.0 { (se / x).powi(2) } else { 0.0 };
            let terms: Vec<(f64, f64, f64, f64)> = summary
                .efficiency
                .iter()
                .filter(|r| r.config == config && r.est == a)
                .filter_map(|ra| {
                    let rb = summary.efficiency.iter().find(|r| {
                        r.config == config && r.est == b && r.theta_i == ra.theta_i && r.wo == ra.wo
                    })?;
                    let q = ra.efficiency / rb.efficiency;
                    if !(q.is_finite() && q > 0.0) {
                        return None;
                    }
                    let (va, vb) = (ra.std * ra.std, rb.std * rb.std);
                    let mut var_ln = rel2(va, ra.variance_se)
                        + rel2(vb, rb.variance_se)
                        + rel2(ra.ns_per_sample, ra.ns_se)
                        + rel2(rb.ns_per_sample, rb.ns_se);
                    if a.reference() != b.reference() {
                        var_ln +=
                            4.0 * (rel2(ra.reference, ra.reference_se) + rel2(rb.reference, rb.reference_se));
                    }
                    let rel_var = |r: &EfficiencyRow| r.std * r.std / (r.reference * r.reference);
                    Some((
                        q.ln(),
                        var_ln,
                        (rel_var(rb) / rel_var(ra)).ln(),
                        (ra.ns_per_sample / rb.ns_per_sample).ln(),
                    ))
                })
                .collect();
            let j = terms.len() as f64;
            let mean = |f: fn(&(f64, f64, f64, f64)) -> f64| terms.iter().map(f).sum::<f64>() / j;
            let (ln_q, se) = (mean(|t| t.0), terms.iter().map(|t| t.1).sum::<f64>().sqrt() / j);
            Ratio {
                estimate: ln_q.exp(),
                lo: (ln_q - 1.96 * se).exp(),
                hi: (ln_q + 1.96 * se).exp(),
                variance_ratio: mean(|t| t.2).exp(),
                cost_ratio: mean(|t| t.3).exp(),
                pairs: terms.len(),
            }
        };
        let (walk, bdpt) =
            (ratio(Est::PtCorrelated, Est::Walk), ratio(Est::BdptCorrelated, Est::PtCorrelated));
        for (name, r) in [("pt-corr/heitz-walk", walk), ("bdpt-corr/pt-corr", bdpt)] {
            let _ = writeln!(
                ratio_csv,
                "{},{name},{:.4},{:.4},{:.4},{:.4},{:.4},{}",
                config.name(),
                r.estimate,
                r.lo,
                r.hi,
                r.variance_ratio,
                r.cost_ratio,
                r.pairs
            );
        }
        summary.ratios.push((config, walk, bdpt));
    }
    write(opts, "ratios.csv", &ratio_csv, summary)?;

    // plots: θi = 1.0, mirror direction
    for config in Config::ALL {
        let series: Vec<Series> = Est::ALL
            .iter()
            .enumerate()
            .filter_map(|(k, &est)| {
                let row = summary
                    .efficiency
                    .iter()
                    .find(|r| r.config == config && r.est == est && r.theta_i == 1.0 && r.wo == "mirror")?;
                let points: Vec<(f64, f64)> = row.curve.iter().map(|&(_, t, e)| (t, e)).collect();
                (!points.is_empty() && points.iter().any(|p| p.1 > 0.0)).then(|| Series {
                    label: est.name().into(),
                    points,
                    color: PALETTE[k],
                })
            })
            .collect();
        let mut canvas = Canvas::new(520, 340);
        loglog_chart(
            &mut canvas,
            &format!("{}, theta_i=1, mirror", config.name()),
            "seconds",
            "rel. RMSE",
            &series,
        );
        save(opts, &format!("error_vs_time_{}.png", config.name()), &canvas, summary)?;
    }
    Ok(())
}

fn write(opts: &Options, name: &str, content: &str, summary: &mut Summary) -> std::io::Result<()> {
    let path = opts.out_dir.join(name);
    std::fs::write(&path, content)?;
    summary.files.push(path);
    Ok(())
}

fn save(opts: &Options, name: &str, canvas: &Canvas, summary: &mut Summary) -> std::io::Result<()> {
    let path = opts.out_dir.join(name);
    canvas.save(&path)?;
    summary.files.push(path);
    Ok(())
}

/// The continuation probability q of the random order of `orders_from_3`.
const ORDER3_CONTINUE: f64 = 0.75;

/// An unbiased estimate of the orders 3 and up of f·|cos θo| from one term: the order
/// k = 3 + G, G geometric (P(G = g) = (1 − q) q^g, q = `ORDER3_CONTINUE`), capped at
/// `MAX_BOUNCES` (which then takes the remaining mass q^{cap − 3}), evaluated with
/// `ScatteringOrder::only(k)` and divided by P(k). Every term is ≥ 0 for non-negative
/// models, unlike the difference total − order 1 − order 2. Its variance is finite when the
/// order-k contributions fall faster than √q^k; it costs a walk of 3 + q/(1 − q) = 6 bounces
/// on average.
fn orders_from_3(eval: &impl Fn(ScatteringOrder, &mut Rng) -> f64, rng: &mut Rng) -> f64 {
    let (mut k, mut p) = (3u32, 1.0 - ORDER3_CONTINUE);
    while k < MAX_BOUNCES {
        if rand::RngExt::random::<f64>(rng) >= ORDER3_CONTINUE {
            break;
        }
        k += 1;
        p *= ORDER3_CONTINUE;
    }
    if k == MAX_BOUNCES {
        p *= 1.0 / (1.0 - ORDER3_CONTINUE);
    }
    eval(ScatteringOrder::only(k).expect("k ≥ 3"), rng) / p
}

/// The lobe materials: conductor, dielectric and diffuse on GGX α = 1.
fn lobes(opts: &Options, budget: Budget, summary: &mut Summary) -> std::io::Result<()> {
    let materials = ["conductor", "dielectric", "diffuse"];
    let n = budget.lobe_angles;
    let mut jobs = Vec::new();
    for (m, &name) in materials.iter().enumerate() {
        let angles: Vec<f64> = if name == "dielectric" {
            (0..2 * n)
                .map(|k| -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * k as f64 / (n - 1) as f64)
                .collect()
        } else {
            (0..n)
                .map(|k| -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * k as f64 / (n - 1) as f64)
                .collect()
        };
        for theta_i in THETAS {
            for &t in &angles {
                jobs.push((m, theta_i, t));
            }
        }
    }
    let samples = budget.lobe_samples;
    let ggx = Ggx::isotropic(1.0).expect("valid α");
    let values = parallel("lobes per order", jobs.clone(), opts, |(m, theta_i, t)| {
        let wi = dir(theta_i, 0.0);
        // θo measured from the normal towards −x (the mirror side); beyond π/2 below
        let wo = Vec3::new(-(t.sin()) as f32, 0.0, t.cos() as f32);
        let mut rng = Rng::seed_from_u64(((m as u64) << 32) ^ (theta_i * 1e3) as u64 ^ (t * 1e6) as u64);
        let eval = |order: ScatteringOrder, rng: &mut Rng| -> f64 {
            let v = match m {
                0 => Microsurface::new(UniformHeight, ggx, Conductor::perfect()).eval(wi, wo, order, rng),
                1 => Microsurface::new(UniformHeight, ggx, Dielectric::new(1.5).expect("valid η"))
                    .eval(wi, wo, order, rng),
                _ => Microsurface::new(UniformHeight, ggx, Diffuse::white()).eval(wi, wo, order, rng),
            };
            f64::from(v.x)
        };
        let mut go = |order: ScatteringOrder| -> f64 {
            (0..samples).map(|_| eval(order, &mut rng)).sum::<f64>() / samples as f64
        };
        let o1 = go(ScatteringOrder::only(1).expect("n > 0"));
        let o2 = go(ScatteringOrder::only(2).expect("n > 0"));
        let all = go(ScatteringOrder::All);
        let o3plus = (0..samples).map(|_| orders_from_3(&eval, &mut rng)).sum::<f64>() / samples as f64;
        (o1, o2, o3plus, all)
    });
    let mut csv = String::from("material,theta_i,theta_o,order1,order2,order3plus,total\n");
    for (&(m, theta_i, t), &(o1, o2, o3plus, all)) in jobs.iter().zip(&values) {
        let _ = writeln!(csv, "{},{theta_i},{t:.4},{o1:.5e},{o2:.5e},{o3plus:.5e},{all:.5e}", materials[m]);
    }
    write(opts, "lobes.csv", &csv, summary)?;
    for (m, &name) in materials.iter().enumerate() {
        let (pw, ph) = (300u32, if name == "dielectric" { 300 } else { 220 });
        let mut canvas = Canvas::new(3 * pw, ph);
        for (k, theta_i) in THETAS.into_iter().enumerate() {
            let rows: Vec<(f64, f64, f64, f64, f64)> = jobs
                .iter()
                .zip(&values)
                .filter(|((mm, ti, _), _)| *mm == m && *ti == theta_i)
                .map(|(&(_, _, t), &(o1, o2, o3plus, all))| (t, o1, o2, o3plus, all))
                .collect();
            let pick = |f: fn(&(f64, f64, f64, f64, f64)) -> f64| {
                rows.iter().map(|r| (r.0, f(r))).collect::<Vec<_>>()
            };
            let series = vec![
                Series { label: "order 1".into(), points: pick(|r| r.1), color: PALETTE[0] },
                Series { label: "order 2".into(), points: pick(|r| r.2), color: PALETTE[1] },
                Series { label: "order 3+".into(), points: pick(|r| r.3), color: PALETTE[2] },
                Series { label: "total".into(), points: pick(|r| r.4), color: PALETTE[3] },
            ];
            let energy = summary
                .energy
                .iter()
                .find(|e| e.0 == format!("{name} ggx a1.0") && e.1 == theta_i)
                .map(|e| format!("E 1/2/3+: {:.3}/{:.3}/{:.3}", e.4[0], e.4[1], e.4[2] + e.4[3]))
                .unwrap_or_default();
            let mut panel = Canvas::new(pw, ph);
            polar_chart(&mut panel, &format!("{name}, theta_i = {theta_i}"), &[energy], &series, -theta_i);
            canvas.blit(&panel, (k as u32 * pw) as i32, 0);
        }
        save(opts, &format!("lobes_{name}.png"), &canvas, summary)?;
    }
    Ok(())
}

/// Albedo per order from sampled walks, and the white furnace ∫eval dωo by uniform-sphere MC.
fn energy(opts: &Options, budget: Budget, summary: &mut Summary) -> std::io::Result<()> {
    let mut jobs = Vec::new();
    for material in ["conductor", "dielectric", "diffuse"] {
        for slope in ["ggx", "beckmann"] {
            for alpha in [0.1f32, 0.5, 1.0] {
                for theta_i in THETAS {
                    jobs.push((material, slope, alpha, theta_i));
                }
            }
        }
    }
    fn go<S: MicrosurfaceSlope, M: Material>(
        walk: Microsurface<UniformHeight, S, M>,
        theta_i: f64,
        walks: usize,
        furnace: usize,
        seed: u64,
    ) -> (f64, f64, [f64; 4], f64, f64, f64) {
        let mut rng = Rng::seed_from_u64(seed);
        let wi = dir(theta_i, 0.0);
        let (mut r, mut t, mut orders, mut bounces) = (0.0, 0.0, [0.0; 4], 0.0);
        for _ in 0..walks {
            if let Some(s) = walk.sample(wi, &mut rng) {
                let w = f64::from(s.weight.x) / walks as f64;
                if s.wo.z > 0.0 {
                    r += w
                } else {
                    t += w
                }
                orders[(s.bounces as usize - 1).min(3)] += w;
                bounces += f64::from(s.bounces) / walks as f64;
            }
        }
        // ωo from a mixture of the uniform sphere and (when its density is exact) the
        // first-bounce phase function, so that sharp lobes (α = 0.1) are found
        let phase_share = if M::EXACT_PHASE_PDF { 0.5 } else { 0.0 };
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..furnace {
            let u0: f64 = rand::RngExt::random(&mut rng);
            let wo = if u0 < phase_share {
                walk.sample_phase(wi, &mut rng).wo
            } else {
                let u1: f64 = rand::RngExt::random(&mut rng);
                let u2: f64 = rand::RngExt::random(&mut rng);
                dir((1.0 - 2.0 * u1).acos(), std::f64::consts::TAU * u2)
            };
            let phase = if phase_share > 0.0 { f64::from(walk.eval_phase(wi, wo, &mut rng).x) } else { 0.0 };
            let density = (1.0 - phase_share) / (4.0 * std::f64::consts::PI) + phase_share * phase;
            let v = f64::from(walk.eval(wi, wo, ScatteringOrder::All, &mut rng).x) / density;
            sum += v;
            sum2 += v * v;
        }
        let mean = sum / furnace as f64;
        let se = ((sum2 / furnace as f64 - mean * mean).max(0.0) / furnace as f64).sqrt();
        (r, t, orders, bounces, mean, se)
    }
    let results = parallel("energy per order", jobs.clone(), opts, |(material, slope, alpha, theta_i)| {
        let seed = (alpha * 1e3) as u64
            ^ ((theta_i * 1e3) as u64) << 16
            ^ (material.len() as u64) << 32
            ^ (slope.len() as u64) << 40;
        let (w, f) = (budget.energy_walks, budget.furnace_samples);
        macro_rules! with_slope {
            ($m:expr) => {
                if slope == "ggx" {
                    go(
                        Microsurface::new(UniformHeight, Ggx::isotropic(alpha).expect("valid α"), $m),
                        theta_i,
                        w,
                        f,
                        seed,
                    )
                } else {
                    go(
                        Microsurface::new(UniformHeight, Beckmann::isotropic(alpha).expect("valid α"), $m),
                        theta_i,
                        w,
                        f,
                        seed,
                    )
                }
            };
        }
        match material {
            "conductor" => with_slope!(Conductor::perfect()),
            "dielectric" => with_slope!(Dielectric::new(1.5).expect("valid η")),
            _ => with_slope!(Diffuse::white()),
        }
    });
    let mut csv = String::from(
        "material,slope,alpha,theta_i,reflected,transmitted,order1,order2,order3,order4plus,mean_bounces,furnace,furnace_se\n",
    );
    for (&(material, slope, alpha, theta_i), &(r, t, o, b, f, fse)) in jobs.iter().zip(&results) {
        let _ = writeln!(
            csv,
            "{material},{slope},{alpha},{theta_i},{r:.5},{t:.5},{:.5},{:.5},{:.5},{:.5},{b:.3},{f:.5},{fse:.5}",
            o[0], o[1], o[2], o[3]
        );
        summary.energy.push((format!("{material} {slope} a{alpha:.1}"), theta_i, r, t, o, b, f, fse));
    }
    write(opts, "energy.csv", &csv, summary)
}

/// The number of pre-generated outgoing directions the cost loops rotate through (a power of
/// two).
const COST_DIRECTIONS: usize = 1024;

/// `COST_DIRECTIONS` outgoing directions from a fixed seed, uniform on the upper hemisphere
/// (on the whole sphere when `transmits`), never horizontal.
fn cost_directions(transmits: bool) -> Vec<Vec3> {
    let mut rng = Rng::seed_from_u64(0xC057);
    (0..COST_DIRECTIONS)
        .map(|_| {
            loop {
                let u: f64 = rand::RngExt::random(&mut rng);
                let v: f64 = rand::RngExt::random(&mut rng);
                let z = if transmits { 1.0 - 2.0 * u } else { 1.0 - u };
                if z != 0.0 {
                    break dir(z.acos(), std::f64::consts::TAU * v);
                }
            }
        })
        .collect()
}

/// Single-threaded cost per call, like the criterion benches: ωi fixed (θi = 0.5), the ωo of
/// `eval` rotated through `COST_DIRECTIONS` pre-generated directions, the model and every
/// input behind `black_box` so that no work is hoisted out of the loop.
fn cost(opts: &Options, budget: Budget, summary: &mut Summary) -> std::io::Result<()> {
    let wi = dir(0.5, 0.0);
    let n = budget.cost_calls;
    fn time<S: MicrosurfaceSlope, M: Material>(
        name: &str,
        m: Models<S, M>,
        wi: Vec3,
        n: usize,
        out: &mut Vec<(String, f64, f64, f64)>,
    ) {
        let wos = cost_directions(M::TRANSMITS);
        let mut rng = Rng::seed_from_u64(99);
        for est in Est::ALL {
            let start = Instant::now();
            let mut acc = 0.0;
            for i in 0..n {
                let wo = wos[i & (COST_DIRECTIONS - 1)];
                acc += black_box(&m).eval(est, black_box(wi), black_box(wo), ScatteringOrder::All, &mut rng);
            }
            let eval_ns = start.elapsed().as_secs_f64() * 1e9 / n as f64;
            black_box(acc);
            let start = Instant::now();
            let mut bounces = 0.0;
            for _ in 0..n {
                let m = black_box(&m);
                let s = match est {
                    Est::Single => None,
                    Est::Walk => m.walk.sample(black_box(wi), &mut rng),
                    Est::PtUncorrelated | Est::BdptUncorrelated => {
                        m.uncorrelated.sample(black_box(wi), &mut rng)
                    }
                    Est::PtCorrelated | Est::BdptCorrelated => m.correlated.sample(black_box(wi), &mut rng),
                };
                bounces += s.map_or(0.0, |s| f64::from(s.bounces));
            }
            black_box(bounces);
            let sample_ns =
                if est == Est::Single { f64::NAN } else { start.elapsed().as_secs_f64() * 1e9 / n as f64 };
            out.push((format!("{name} {}", est.name()), eval_ns, sample_ns, bounces / n as f64));
        }
    }
    let ggx = Ggx::isotropic(0.5).expect("valid α");
    let beckmann = Beckmann::isotropic(0.5).expect("valid α");
    let mut rows = Vec::new();
    time("conductor ggx a0.5", Models::new(ggx, Conductor::perfect()), wi, n, &mut rows);
    time("conductor beckmann a0.5", Models::new(beckmann, Conductor::perfect()), wi, n, &mut rows);
    time("dielectric ggx a0.5", Models::new(ggx, Dielectric::new(1.5).expect("valid η")), wi, n, &mut rows);
    time("diffuse ggx a0.5", Models::new(ggx, Diffuse::white()), wi, n, &mut rows);
    let mut csv = String::from("model,ns_per_eval,ns_per_sample,mean_bounces_of_sample\n");
    for (name, e, s, b) in &rows {
        let _ = writeln!(csv, "{name},{e:.1},{s:.1},{b:.3}");
    }
    summary.cost = rows;
    write(opts, "cost.csv", &csv, summary)
}

fn markdown(summary: &Summary) -> String {
    let mut md = String::from(
        "# microsurface report\n\n## Efficiency ratios (geometric means over θi ∈ {0, 1, 1.5} and three ωo)\n\n",
    );
    md.push_str(
        "| configuration | PT-corr / Heitz walk [95 % CI] | variance ÷, cost × | BDPT-corr / PT-corr [95 % CI] | variance ÷, cost × |\n|---|---|---|---|---|\n",
    );
    for (c, a, b) in &summary.ratios {
        let _ = writeln!(
            md,
            "| {} | {:.2} [{:.2}, {:.2}] | {:.2}, {:.2} | {:.2} [{:.2}, {:.2}] | {:.2}, {:.2} |",
            c.name(),
            a.estimate,
            a.lo,
            a.hi,
            a.variance_ratio,
            a.cost_ratio,
            b.estimate,
            b.lo,
            b.hi,
            b.variance_ratio,
            b.cost_ratio
        );
    }
    md.push_str(
        "\nEfficiency = 1 / (relative variance × seconds per sample); a ratio above 1 means the first estimator reaches a given error sooner. \
         The interval propagates (delta method) the standard errors of the sample variances (from the variance of the squared deviations), \
         of the times per sample (16 timed chunks per run) and of the references; it covers one run's sampling noise, not changes of machine load \
         between runs. \"variance ÷\": how many times lower the first estimator's relative variance is; \"cost ×\": how many times more it costs per sample \
         (geometric means).\n",
    );
    md.push_str("\n## Efficiency per estimator at θi = 1.0, mirror direction (1/s)\n\n| configuration |");
    for est in Est::ALL {
        let _ = write!(md, " {} |", est.name());
    }
    md.push_str("\n|---|---|---|---|---|---|---|\n");
    for config in Config::ALL {
        let _ = write!(md, "| {} |", config.name());
        for est in Est::ALL {
            let e = summary
                .efficiency
                .iter()
                .find(|r| r.config == config && r.est == est && r.theta_i == 1.0 && r.wo == "mirror")
                .map_or(f64::NAN, |r| r.efficiency);
            let _ = write!(md, " {e:.2e} |");
        }
        md.push('\n');
    }
    md.push_str("\n## Energy per scattering order (Heitz walk; white furnace ∫f cos dωo ± SE)\n\n");
    md.push_str("| model | θi | R | T | order 1 | order 2 | order 3 | order 4+ | bounces | furnace |\n|---|---|---|---|---|---|---|---|---|---|\n");
    for (label, t, r, tr, o, b, f, fse) in &summary.energy {
        let _ = writeln!(
            md,
            "| {label} | {t} | {r:.4} | {tr:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {b:.2} | {f:.3} ± {fse:.3} |",
            o[0], o[1], o[2], o[3]
        );
    }
    md.push_str("\n## Cost (single thread, θi = 0.5, α = 0.5; eval rotates 1024 pre-generated ωo, uniform on the hemisphere or, for the dielectric, the sphere; inputs behind black_box)\n\n| model | ns / eval | ns / sample | mean bounces |\n|---|---|---|---|\n");
    for (name, e, s, b) in &summary.cost {
        let _ = writeln!(md, "| {name} | {e:.0} | {s:.0} | {b:.2} |");
    }
    md
}

/// Runs the whole report and writes its files into `opts.out_dir`.
pub fn run(opts: &Options) -> std::io::Result<Summary> {
    std::fs::create_dir_all(&opts.out_dir)?;
    let budget = Budget::new(opts.quick);
    let mut summary = Summary::default();
    error_study(opts, budget, &mut summary)?;
    energy(opts, budget, &mut summary)?;
    lobes(opts, budget, &mut summary)?;
    cost(opts, budget, &mut summary)?;
    summary.markdown = markdown(&summary);
    let md = summary.markdown.clone();
    write(opts, "summary.md", &md, &mut summary)?;
    Ok(summary)
}

/// The default output directory.
#[allow(dead_code)] // used by main.rs, not by tests/report.rs
pub fn default_out_dir() -> PathBuf {
    Path::new("target").join("report")
}
