//! The efficiency table of the invariance-principle estimator (`Invariance`, Cui et al.
//! 2023): 1/(relative variance × seconds per evaluation) with 95 % confidence intervals for it,
//! the Heitz walk (the model it estimates), and the position-free PT and BDPT (Wang et al.
//! 2022, height-correlated: a neighbouring model), on the report's opaque configurations and
//! on the paper's.
//!
//! The paper claims less noise than Heitz et al. 2016 (and Bitterli and d'Eon 2022, which the
//! crate does not implement) at equal time. Its text was not available here; the configuration
//! it is checked on is that of the authors' released test scene
//! (`scene_test_conductor_new_release.xml`: copper, GGX α = 0.5, isotropic, up to 10 orders;
//! here all orders), and the same surface with Beckmann slopes, at the report's θi and ωo.
//!
//! Measurement, as the error study's (`measure`): per (configuration, θi, ωo) every estimator
//! evaluates `n` times, timed in [`TIMING_CHUNKS`] chunks; here the four estimators' chunks are
//! interleaved (so a change of machine load falls on all of them alike) and timed with the
//! thread's CPU clock ([`validation::clock::thread_time`]), which leaves out preemption on a shared
//! machine. Reduction, as the error study's ratios (`reduce`): per case ln e = 2 ln m − ln σ̂²
//! − ln t with its delta-method variance from the standard errors of σ̂² (`variance_se`), of t
//! (over the chunks) and of the mean m; per configuration the geometric mean over the cases
//! with exp(mean ± 1.96 SE); a ratio is the same for ln e_a − ln e_b (independent runs).

use super::configure::{Budget, Case, Config, Options, Outgoing, Rng, SlopeKind, THETAS};
use super::measure::{Estimate, TIMING_CHUNKS, Timing};
use super::reduce::{mean_and_variance, rel2, variance_se};
use glam::Vec3;
use microsurface::research::{
    Estimator, Invariance, Material, Microsurface, PositionFree, ScatteringOrder, Shadowing, UniformHeight,
};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, ComplexIor, Conductor, Diffuse, Ggx};
use rand::SeedableRng;
use std::fmt::Write as _;
use std::hint::black_box;
use validation::clock::thread_time;

/// The estimators of the table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableEst {
    Invariance,
    Walk,
    PtCorrelated,
    BdptCorrelated,
}

impl TableEst {
    pub const ALL: [TableEst; 4] =
        [TableEst::Invariance, TableEst::Walk, TableEst::PtCorrelated, TableEst::BdptCorrelated];

    pub fn name(self) -> &'static str {
        match self {
            TableEst::Invariance => "invariance",
            TableEst::Walk => "heitz-walk",
            TableEst::PtCorrelated => "pt-corr",
            TableEst::BdptCorrelated => "bdpt-corr",
        }
    }
}

/// The microfacet material of a configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableMaterial {
    /// F = 1.
    Perfect,
    /// Copper (`ComplexIor::COPPER`, RGB).
    Copper,
    /// White diffuse facets.
    Diffuse,
}

/// Where a configuration comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// The report's error study (its opaque configurations).
    Report,
    /// The paper's released test scene.
    Paper,
}

/// A configuration of the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableConfig {
    pub name: &'static str,
    pub label: &'static str,
    pub source: Source,
    pub material: TableMaterial,
    pub slope: SlopeKind,
    pub alpha: f32,
}

/// The configurations: the report's opaque ones (their labels as the error study's) and the
/// paper's.
pub const CONFIGS: [TableConfig; 6] = [
    TableConfig {
        name: "conductor-ggx-a1.0",
        label: "conductor (F = 1), GGX α = 1",
        source: Source::Report,
        material: TableMaterial::Perfect,
        slope: SlopeKind::Ggx,
        alpha: 1.0,
    },
    TableConfig {
        name: "conductor-ggx-a0.1",
        label: "conductor (F = 1), GGX α = 0.1",
        source: Source::Report,
        material: TableMaterial::Perfect,
        slope: SlopeKind::Ggx,
        alpha: 0.1,
    },
    TableConfig {
        name: "conductor-beckmann-a0.5",
        label: "conductor (F = 1), Beckmann α = 0.5",
        source: Source::Report,
        material: TableMaterial::Perfect,
        slope: SlopeKind::Beckmann,
        alpha: 0.5,
    },
    TableConfig {
        name: "diffuse-ggx-a1.0",
        label: "diffuse (white), GGX α = 1",
        source: Source::Report,
        material: TableMaterial::Diffuse,
        slope: SlopeKind::Ggx,
        alpha: 1.0,
    },
    TableConfig {
        name: "paper-copper-ggx-a0.5",
        label: "paper's scene: copper, GGX α = 0.5",
        source: Source::Paper,
        material: TableMaterial::Copper,
        slope: SlopeKind::Ggx,
        alpha: 0.5,
    },
    TableConfig {
        name: "paper-copper-beckmann-a0.5",
        label: "paper's scene with Beckmann: copper, α = 0.5",
        source: Source::Paper,
        material: TableMaterial::Copper,
        slope: SlopeKind::Beckmann,
        alpha: 0.5,
    },
];

/// The (θi, ωo) of a configuration: the error study's (θi ∈ `THETAS`, ωo mirror, normal, side).
fn cases() -> Vec<(f64, Outgoing)> {
    // the error study's cases of a reflecting configuration
    Case::all(Config::ConductorGgx1).into_iter().map(|c| (c.theta_i(), c.wo)).collect()
}

/// One estimator's run in one case.
#[derive(Debug, Clone)]
pub struct CaseRun {
    pub config: usize,
    pub theta_i: f64,
    pub wo: Outgoing,
    pub est: TableEst,
    pub mean: Estimate,
    pub variance: f64,
    pub variance_se: f64,
    /// The share of Σ (x − mean)² that the `TAIL_VALUES` largest terms carry.
    pub tail_share: f64,
    pub timing: Timing,
}

/// The number of largest squared deviations whose share of the sum [`CaseRun::tail_share`]
/// measures.
pub const TAIL_VALUES: usize = 10;

/// Above this [`CaseRun::tail_share`], a run's σ̂² rests on a handful of rare paths: its
/// variance, and the delta-method interval built on it, are unreliable (the case of Beckmann
/// α = 0.5 at θi = 1 towards the side, where paths of probability 1e-5 carry it, gave the walk
/// a relative variance of 0.0015 in one run and 17 in another). Such cases are left out of the
/// geometric means (and counted); the median over all cases is shown beside them.
pub const MAX_TAIL_SHARE: f64 = 0.5;

/// The share of Σ (x − mean)² carried by its `TAIL_VALUES` largest terms.
fn tail_share(values: &[f32], mean: f64) -> f64 {
    let mut sq: Vec<f64> = values.iter().map(|&v| (f64::from(v) - mean).powi(2)).collect();
    let total: f64 = sq.iter().sum();
    if total <= 0.0 {
        return 0.0;
    }
    let cut = sq.len().saturating_sub(TAIL_VALUES);
    if cut > 0 {
        sq.select_nth_unstable_by(cut, f64::total_cmp);
    }
    sq[cut..].iter().sum::<f64>() / total
}

impl CaseRun {
    /// Whether its σ̂² rests on more than a handful of values ([`MAX_TAIL_SHARE`]).
    fn reliable(&self) -> bool {
        self.tail_share <= MAX_TAIL_SHARE
    }

    /// ln e and its delta-method variance; `None` where e is not finite and positive.
    fn ln_efficiency(&self) -> Option<(f64, f64)> {
        let (m, v, t) = (self.mean.mean, self.variance, self.timing.ns_per_sample * 1e-9);
        let ln_e = 2.0 * m.abs().ln() - v.ln() - t.ln();
        if !ln_e.is_finite() {
            return None;
        }
        let var = rel2(v, self.variance_se)
            + rel2(self.timing.ns_per_sample, self.timing.ns_se)
            + 4.0 * rel2(m, self.mean.se);
        Some((ln_e, var))
    }
}

/// A geometric mean over the cases with its 95 % interval.
#[derive(Debug, Clone, Copy)]
pub struct Interval {
    pub estimate: f64,
    pub lo: f64,
    pub hi: f64,
    pub cases: usize,
}

impl Interval {
    /// The geometric mean of exp(ln e) over `terms` (ln e, its variance); NaN without terms.
    fn of(terms: &[(f64, f64)]) -> Self {
        if terms.is_empty() {
            return Self { estimate: f64::NAN, lo: f64::NAN, hi: f64::NAN, cases: 0 };
        }
        let j = terms.len() as f64;
        let mean = terms.iter().map(|t| t.0).sum::<f64>() / j;
        let se = terms.iter().map(|t| t.1).sum::<f64>().sqrt() / j;
        Self {
            estimate: mean.exp(),
            lo: (mean - 1.96 * se).exp(),
            hi: (mean + 1.96 * se).exp(),
            cases: terms.len(),
        }
    }

    fn show(&self, digits: usize) -> String {
        if self.cases == 0 {
            return "– (0)".into();
        }
        format!("{:.d$} [{:.d$}, {:.d$}] ({})", self.estimate, self.lo, self.hi, self.cases, d = digits)
    }
}

/// The table: per configuration every estimator's efficiency and the invariance estimator's
/// ratios to the others.
pub struct EfficiencyTable {
    pub runs: Vec<CaseRun>,
    /// (configuration, estimator, efficiency per second).
    pub efficiency: Vec<(usize, TableEst, Interval)>,
    /// (configuration, other estimator, e_invariance / e_other).
    pub ratios: Vec<(usize, TableEst, Interval)>,
    /// (configuration, other estimator, the median over the cases of e_invariance / e_other):
    /// robust to one case whose σ̂² missed its rare paths.
    pub medians: Vec<(usize, TableEst, f64)>,
    /// Evaluations per estimator and case.
    pub samples: usize,
}

/// Measures and reduces the table: `budget.samples` × 4 evaluations per estimator and case
/// in a quick run, × 16 in a full one (a few rare paths carry much of the variance of some
/// cases: Beckmann α = 0.5 at θi = 1 towards the side has order-2 paths of probability about
/// 1e-5 and value about 1, which the walk and the invariance estimator both meet).
pub fn run(opts: &Options, budget: &Budget) -> EfficiencyTable {
    let samples = budget.samples * if opts.size == super::configure::RunSize::Full { 16 } else { 4 };
    let jobs: Vec<(usize, f64, Outgoing)> =
        (0..CONFIGS.len()).flat_map(|c| cases().into_iter().map(move |(t, w)| (c, t, w))).collect();
    let runs: Vec<CaseRun> = super::measure::parallel("invariance table", jobs, opts, |(c, theta_i, wo)| {
        let seed = 0x1A7E_0000 + (c as u64) * 64 + ((theta_i * 10.0) as u64) * 4 + wo as u64;
        let wi = super::configure::dir(theta_i, 0.0);
        let out = wo.direction(theta_i);
        let results = measure_case(CONFIGS[c], wi, out, samples, seed);
        TableEst::ALL
            .into_iter()
            .zip(results)
            .map(|(est, (values, timing))| {
                let (mean, variance) = mean_and_variance(&values);
                CaseRun {
                    config: c,
                    theta_i,
                    wo,
                    est,
                    mean: Estimate { mean, se: (variance / values.len() as f64).sqrt() },
                    variance,
                    variance_se: variance_se(&values, mean),
                    tail_share: tail_share(&values, mean),
                    timing,
                }
            })
            .collect::<Vec<_>>()
    })
    .into_iter()
    .flatten()
    .collect();
    let mut efficiency = Vec::new();
    let mut ratios = Vec::new();
    let mut medians = Vec::new();
    for c in 0..CONFIGS.len() {
        let run_of = |est: TableEst, theta_i: f64, wo: Outgoing| {
            runs.iter().find(|r| r.config == c && r.est == est && r.theta_i == theta_i && r.wo == wo)
        };
        for est in TableEst::ALL {
            let terms: Vec<(f64, f64)> = cases()
                .into_iter()
                .filter_map(|(t, w)| run_of(est, t, w).filter(|r| r.reliable())?.ln_efficiency())
                .collect();
            efficiency.push((c, est, Interval::of(&terms)));
            if est == TableEst::Invariance {
                continue;
            }
            // (ln ratio, its variance, whether both runs are reliable) per case
            let terms: Vec<(f64, f64, bool)> = cases()
                .into_iter()
                .filter_map(|(t, w)| {
                    let (ra, rb) = (run_of(TableEst::Invariance, t, w)?, run_of(est, t, w)?);
                    let ((a, va), (b, vb)) = (ra.ln_efficiency()?, rb.ln_efficiency()?);
                    Some((a - b, va + vb, ra.reliable() && rb.reliable()))
                })
                .collect();
            let reliable: Vec<(f64, f64)> = terms.iter().filter(|t| t.2).map(|t| (t.0, t.1)).collect();
            ratios.push((c, est, Interval::of(&reliable)));
            let mut logs: Vec<f64> = terms.iter().map(|t| t.0).collect();
            logs.sort_by(f64::total_cmp);
            let median = match logs.len() {
                0 => f64::NAN,
                n if n % 2 == 1 => logs[n / 2].exp(),
                n => (0.5 * (logs[n / 2 - 1] + logs[n / 2])).exp(),
            };
            medians.push((c, est, median));
        }
    }
    EfficiencyTable { runs, efficiency, ratios, medians, samples }
}

/// The four estimators' values and timings in one case, their chunks interleaved.
fn measure_case(config: TableConfig, wi: Vec3, wo: Vec3, n: usize, seed: u64) -> Vec<(Vec<f32>, Timing)> {
    fn with_slope<S: MicrosurfaceSlope>(
        slope: S,
        config: TableConfig,
        wi: Vec3,
        wo: Vec3,
        n: usize,
        seed: u64,
    ) -> Vec<(Vec<f32>, Timing)> {
        match config.material {
            TableMaterial::Perfect => interleaved(slope, Conductor::perfect(), wi, wo, n, seed),
            TableMaterial::Copper => interleaved(slope, Conductor::new(ComplexIor::COPPER), wi, wo, n, seed),
            TableMaterial::Diffuse => interleaved(slope, Diffuse::white(), wi, wo, n, seed),
        }
    }
    match config.slope {
        SlopeKind::Ggx => with_slope(Ggx::isotropic(config.alpha).expect("valid α"), config, wi, wo, n, seed),
        SlopeKind::Beckmann => {
            with_slope(Beckmann::isotropic(config.alpha).expect("valid α"), config, wi, wo, n, seed)
        }
    }
}

/// `n` evaluations of each estimator (f·|cos θo|, mean over RGB) in `TIMING_CHUNKS` chunks,
/// one chunk of each estimator in turn, on the thread's CPU clock.
fn interleaved<S: MicrosurfaceSlope, M: Material>(
    slope: S,
    material: M,
    wi: Vec3,
    wo: Vec3,
    n: usize,
    seed: u64,
) -> Vec<(Vec<f32>, Timing)> {
    let invariance = Invariance::new(slope, material).expect("an opaque material");
    let walk = Microsurface::new(UniformHeight, slope, material);
    let pf = PositionFree::new(slope, material, Shadowing::Correlated);
    let all = ScatteringOrder::All;
    let mut rngs: Vec<Rng> = (0..4).map(|k| Rng::seed_from_u64(seed ^ (k << 40))).collect();
    let mut values: Vec<Vec<f32>> = (0..4).map(|_| Vec::with_capacity(n)).collect();
    let mut chunk_ns: Vec<Vec<f64>> = (0..4).map(|_| Vec::with_capacity(TIMING_CHUNKS)).collect();
    let chunk = n.div_ceil(TIMING_CHUNKS).max(1);
    while values[0].len() < n {
        let len = chunk.min(n - values[0].len());
        for (k, est) in TableEst::ALL.into_iter().enumerate() {
            let (rng, out) = (&mut rngs[k], &mut values[k]);
            let start = thread_time();
            for _ in 0..len {
                let v = match est {
                    TableEst::Invariance => {
                        black_box(&invariance).eval(black_box(wi), black_box(wo), all, rng)
                    }
                    TableEst::Walk => black_box(&walk).eval(black_box(wi), black_box(wo), all, rng),
                    TableEst::PtCorrelated => {
                        black_box(&pf).eval(black_box(wi), black_box(wo), Estimator::Pt, all, rng)
                    }
                    TableEst::BdptCorrelated => {
                        black_box(&pf).eval(black_box(wi), black_box(wo), Estimator::Bdpt, all, rng)
                    }
                };
                out.push(v.element_sum() / 3.0);
            }
            chunk_ns[k].push((thread_time() - start).as_secs_f64() * 1e9 / len as f64);
        }
    }
    values
        .into_iter()
        .zip(chunk_ns)
        .map(|(v, per_chunk)| {
            let k = per_chunk.len() as f64;
            let mean = per_chunk.iter().sum::<f64>() / k;
            let var = per_chunk.iter().map(|t| (t - mean).powi(2)).sum::<f64>() / (k - 1.0).max(1.0);
            (v, Timing { ns_per_sample: mean, ns_se: (var / k).sqrt() })
        })
        .collect()
}

impl EfficiencyTable {
    /// The efficiency of `est` in configuration `c` (`None` without a reliable case).
    pub fn efficiency(&self, c: usize, est: TableEst) -> Option<Interval> {
        self.efficiency.iter().find(|e| e.0 == c && e.1 == est && e.2.cases > 0).map(|e| e.2)
    }

    /// e_invariance / e_`est` in configuration `c` (`None` without a reliable case).
    pub fn ratio(&self, c: usize, est: TableEst) -> Option<Interval> {
        self.ratios.iter().find(|e| e.0 == c && e.1 == est && e.2.cases > 0).map(|e| e.2)
    }

    /// The median over the cases of e_invariance / e_`est` in configuration `c`.
    pub fn median(&self, c: usize, est: TableEst) -> Option<f64> {
        self.medians.iter().find(|e| e.0 == c && e.1 == est).map(|e| e.2)
    }

    /// The verdict on the paper's claim against the walk in configuration `c`: `Some(true)`
    /// where the 95 % interval of e_invariance/e_walk lies above 1, `Some(false)` below 1,
    /// `None` where it contains 1.
    pub fn beats_the_walk(&self, c: usize) -> Option<bool> {
        let r = self.ratio(c, TableEst::Walk)?;
        if r.lo > 1.0 {
            Some(true)
        } else if r.hi < 1.0 {
            Some(false)
        } else {
            None
        }
    }

    /// The table as Markdown, with its note and the verdict on the paper's claim.
    pub fn markdown(&self) -> String {
        let mut md = String::from(
            "## Efficiency of the invariance-principle estimator (Cui et al. 2023)\n\n\
             | configuration | invariance | Heitz walk | PT-corr | BDPT-corr | invariance / walk | (median) | invariance / PT-corr | invariance / BDPT-corr |\n\
             |---|---|---|---|---|---|---|---|---|\n",
        );
        for (c, config) in CONFIGS.iter().enumerate() {
            let e = |est| {
                self.efficiency(c, est).map_or("–".into(), |i| format!("{:.3e} ({})", i.estimate, i.cases))
            };
            let r = |est| self.ratio(c, est).map_or("–".into(), |i| i.show(2));
            let median = self.median(c, TableEst::Walk).map_or("–".into(), |m| format!("{m:.2}"));
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {median} | {} | {} |",
                config.label,
                e(TableEst::Invariance),
                e(TableEst::Walk),
                e(TableEst::PtCorrelated),
                e(TableEst::BdptCorrelated),
                r(TableEst::Walk),
                r(TableEst::PtCorrelated),
                r(TableEst::BdptCorrelated),
            );
        }
        let verdict: Vec<String> = (0..CONFIGS.len())
            .filter(|&c| CONFIGS[c].source == Source::Paper)
            .map(|c| {
                let word = match self.beats_the_walk(c) {
                    Some(true) => "holds (interval above 1)",
                    Some(false) => "does not hold (interval below 1)",
                    None => "is not decided (interval contains 1)",
                };
                format!("{}: {word}", CONFIGS[c].label)
            })
            .collect();
        let verdict = verdict.join("; ");
        let _ = writeln!(
            md,
            "\nEfficiency = 1/(relative variance × seconds per evaluation) of f·|cos θo| (all orders), geometric mean over θi ∈ {THETAS:?} \
             and ωo ∈ {{mirror, normal, side}}, in 1/s; ratios with 95 % intervals (delta method over the standard errors of the variances, \
             the times and the means; one run's sampling noise, not changes of load between runs). {} evaluations per estimator and case, \
             the four estimators' {TIMING_CHUNKS} timed chunks interleaved, thread CPU time. The walk and the invariance estimator estimate \
             the same BRDF; PT and BDPT estimate the height-correlated position-free model (a different one). \
             In parentheses: the number of cases in the geometric mean; a case is left out where a run's σ̂² rests on its \
             {TAIL_VALUES} largest values (more than {MAX_TAIL_SHARE} of Σ (x − mean)²: rare paths, which one run meets and another misses, and \
             which no interval built on σ̂² covers). \"(median)\": the median over all cases of the per-case ratio invariance / walk. The paper's claim (less noise than Heitz et al. 2016 at equal time) on this machine — {verdict}. \
             Bitterli and d'Eon 2022, the paper's other baseline, is not in the crate.",
            self.samples
        );
        md
    }

    /// Every run as CSV.
    pub fn csv(&self) -> String {
        let mut s = String::from(
            "config,source,theta_i,wo,estimator,mean,mean_se,variance,variance_se,tail_share,ns_per_eval,ns_se\n",
        );
        for r in &self.runs {
            let _ = writeln!(
                s,
                "{},{:?},{},{},{},{:.6e},{:.3e},{:.6e},{:.3e},{:.4},{:.2},{:.2}",
                CONFIGS[r.config].name,
                CONFIGS[r.config].source,
                r.theta_i,
                r.wo.name(),
                r.est.name(),
                r.mean.mean,
                r.mean.se,
                r.variance,
                r.variance_se,
                r.tail_share,
                r.timing.ns_per_sample,
                r.timing.ns_se
            );
        }
        s
    }
}
