//! Stage 3, reduce: errors against run time, efficiencies and their ratios with confidence
//! intervals, the technique choice, and the lobe panels with their noise level.

use super::configure::{Case, Config, Est, MaterialKind, Model, THETAS};
use super::measure::{CostRow, EnergyRow, Estimate, LobePoint, Measurements, Timing};
use super::tables::TableCurve;
use std::collections::HashMap;

/// One point of an error-against-time curve: the RMSE of the mean of `samples` evaluations
/// (over the run's disjoint batches of that size) against the reference, relative to it.
#[derive(Debug, Clone, Copy)]
pub struct CurvePoint {
    pub samples: usize,
    pub seconds: f64,
    pub rel_rmse: f64,
}

/// One estimator in one case.
#[derive(Debug, Clone)]
pub struct EfficiencyRow {
    pub case: Case,
    pub est: Est,
    pub mean: f64,
    pub std: f64,
    /// Standard error of the sample variance σ̂² (`variance_se`).
    pub variance_se: f64,
    pub timing: Timing,
    /// The converged reference of the estimator's model (the walk's for single scattering).
    pub reference: Estimate,
    /// 1/(relative variance × seconds per sample); `None` for single scattering, whose error
    /// against the walk is a bias, not a variance.
    pub efficiency: Option<f64>,
    pub curve: Vec<CurvePoint>,
}

/// Which efficiency ratio.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RatioKind {
    /// Position-free PT (correlated) over the Heitz walk.
    PtOverWalk,
    /// Position-free BDPT over PT (both correlated).
    BdptOverPt,
}

impl RatioKind {
    pub fn name(self) -> &'static str {
        match self {
            RatioKind::PtOverWalk => "pt-corr/heitz-walk",
            RatioKind::BdptOverPt => "bdpt-corr/pt-corr",
        }
    }

    pub fn estimators(self) -> (Est, Est) {
        match self {
            RatioKind::PtOverWalk => (Est::PtCorrelated, Est::Walk),
            RatioKind::BdptOverPt => (Est::BdptCorrelated, Est::PtCorrelated),
        }
    }
}

/// A ratio of efficiencies, geometric mean over θi and ωo, with its 95 % confidence interval.
///
/// Per (θi, ωo) the log ratio is ln e_a − ln e_b with e = reference²/(σ̂² t); its variance is
/// propagated by the delta method from the standard errors of both sample variances
/// (`variance_se`), of both times per sample (over the timed chunks) and, where the two
/// estimators have different references, of both references. The geometric mean's log is the
/// mean of the J log ratios with SE √(Σ var)/J; the interval is exp(mean ± 1.96 SE). It covers
/// the sampling noise of one run (not a change of machine load between runs, nor the
/// unreliability of σ̂² for heavy-tailed estimators).
#[derive(Debug, Clone, Copy)]
pub struct Ratio {
    pub config: Config,
    pub kind: RatioKind,
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

/// The technique choice of one configuration: every estimator's efficiency relative to the
/// walk's (geometric mean over the cases), and the most efficient one.
#[derive(Debug, Clone)]
pub struct Choice {
    pub config: Config,
    pub relative_to_walk: Vec<(Est, f64)>,
    pub best: Est,
}

/// One panel of a lobe figure: a model at one θi.
#[derive(Debug, Clone)]
pub struct LobePanel {
    pub material: MaterialKind,
    pub model: Model,
    pub theta_i: f64,
    pub points: Vec<LobePoint>,
    /// The largest total f·|cos θo| of the panel.
    pub peak: f64,
    /// The largest standard error of the total, relative to `peak`.
    pub max_rel_se: f64,
    /// The albedo per order (1, 2, 3, 4+) of the same model from sampled scatterings.
    pub energy: Option<[f64; 4]>,
    /// The fewest and the most evaluations per order of a point.
    pub samples: (usize, usize),
}

/// Everything the plots and the writer need.
pub struct Results {
    pub efficiency: Vec<EfficiencyRow>,
    pub ratios: Vec<Ratio>,
    pub choices: Vec<Choice>,
    pub energy: Vec<EnergyRow>,
    pub lobes: Vec<LobePanel>,
    pub cost: Vec<CostRow>,
    pub tables: Vec<TableCurve>,
}

impl Results {
    /// The row of one estimator in one case.
    pub fn row(&self, case: Case, est: Est) -> Option<&EfficiencyRow> {
        self.efficiency.iter().find(|r| r.case == case && r.est == est)
    }
}

/// The sample mean and variance.
pub(crate) fn mean_and_variance(values: &[f32]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let var = values.iter().map(|&v| (f64::from(v) - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, var)
}

/// The standard error of the sample variance: the standard deviation of the squared
/// deviations (x − mean)² over √n (delta method; it needs a finite fourth moment, so for
/// heavy-tailed estimators it is itself uncertain).
pub(crate) fn variance_se(values: &[f32], mean: f64) -> f64 {
    let n = values.len() as f64;
    let sq: Vec<f64> = values.iter().map(|&v| (f64::from(v) - mean).powi(2)).collect();
    let m = sq.iter().sum::<f64>() / n;
    let v = sq.iter().map(|q| (q - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (v / n).sqrt()
}

/// The error curve of a run: batches of 1, 2, 4, … samples while at least 16 batches remain.
fn curve(values: &[f32], timing: Timing, reference: f64) -> Vec<CurvePoint> {
    let scale = if reference != 0.0 { reference.abs() } else { 1.0 };
    let mut points = Vec::new();
    let mut batch = 1;
    while batch * 16 <= values.len() {
        let batches = values.len() / batch;
        let mse = values
            .chunks_exact(batch)
            .map(|c| (c.iter().map(|&v| f64::from(v)).sum::<f64>() / batch as f64 - reference).powi(2))
            .sum::<f64>()
            / batches as f64;
        let seconds = batch as f64 * timing.ns_per_sample * 1e-9;
        points.push(CurvePoint { samples: batch, seconds, rel_rmse: mse.sqrt() / scale });
        batch *= 2;
    }
    points
}

/// Reduces the measurements.
pub fn reduce(m: Measurements) -> Results {
    let references: HashMap<(Case, Model), Estimate> =
        m.references.iter().map(|r| ((r.case, r.model), r.value)).collect();
    let efficiency: Vec<EfficiencyRow> = m
        .runs
        .iter()
        .map(|run| {
            let (mean, var) = mean_and_variance(&run.values);
            let reference = references[&(run.case, run.est.model())];
            let scale = if reference.mean != 0.0 { reference.mean.abs() } else { 1.0 };
            let rel_var = var / (scale * scale);
            let efficiency = (!run.est.is_biased()).then(|| {
                if rel_var > 0.0 { 1.0 / (rel_var * run.timing.ns_per_sample * 1e-9) } else { f64::INFINITY }
            });
            EfficiencyRow {
                case: run.case,
                est: run.est,
                mean,
                std: var.sqrt(),
                variance_se: variance_se(&run.values, mean),
                timing: run.timing,
                reference,
                efficiency,
                curve: curve(&run.values, run.timing, reference.mean),
            }
        })
        .collect();
    let index: HashMap<(Case, Est), &EfficiencyRow> =
        efficiency.iter().map(|r| ((r.case, r.est), r)).collect();
    let mut ratios = Vec::new();
    let mut choices = Vec::new();
    for config in Config::ALL {
        for kind in [RatioKind::PtOverWalk, RatioKind::BdptOverPt] {
            ratios.push(ratio(config, kind, &index));
        }
        choices.push(choice(config, &index));
    }
    let lobes = lobe_panels(&m.lobes, &m.energy);
    Results { efficiency, ratios, choices, energy: m.energy, lobes, cost: m.cost, tables: m.tables }
}

/// Relative variance of an estimate's value: (se/x)².
pub(crate) fn rel2(x: f64, se: f64) -> f64 {
    if x != 0.0 { (se / x).powi(2) } else { 0.0 }
}

/// The logarithms behind a ratio in one case.
struct LogTerms {
    /// ln(e_a / e_b).
    ratio: f64,
    /// Its delta-method variance.
    variance: f64,
    /// ln of the relative-variance ratio σ̂²_b/σ̂²_a.
    variance_ratio: f64,
    /// ln of the cost ratio t_a/t_b.
    cost_ratio: f64,
}

fn ratio(config: Config, kind: RatioKind, index: &HashMap<(Case, Est), &EfficiencyRow>) -> Ratio {
    let (a, b) = kind.estimators();
    let terms: Vec<LogTerms> = Case::all(config)
        .into_iter()
        .filter_map(|case| {
            let (ra, rb) = (index.get(&(case, a))?, index.get(&(case, b))?);
            let q = ra.efficiency? / rb.efficiency?;
            if !(q.is_finite() && q > 0.0) {
                return None;
            }
            let (va, vb) = (ra.std * ra.std, rb.std * rb.std);
            let mut var_ln = rel2(va, ra.variance_se)
                + rel2(vb, rb.variance_se)
                + rel2(ra.timing.ns_per_sample, ra.timing.ns_se)
                + rel2(rb.timing.ns_per_sample, rb.timing.ns_se);
            if a.model() != b.model() {
                var_ln += 4.0
                    * (rel2(ra.reference.mean, ra.reference.se) + rel2(rb.reference.mean, rb.reference.se));
            }
            let rel_var = |r: &EfficiencyRow| r.std * r.std / (r.reference.mean * r.reference.mean);
            Some(LogTerms {
                ratio: q.ln(),
                variance: var_ln,
                variance_ratio: (rel_var(rb) / rel_var(ra)).ln(),
                cost_ratio: (ra.timing.ns_per_sample / rb.timing.ns_per_sample).ln(),
            })
        })
        .collect();
    let j = terms.len() as f64;
    let mean = |f: fn(&LogTerms) -> f64| terms.iter().map(f).sum::<f64>() / j;
    let (ln_q, se) = (mean(|t| t.ratio), terms.iter().map(|t| t.variance).sum::<f64>().sqrt() / j);
    Ratio {
        config,
        kind,
        estimate: ln_q.exp(),
        lo: (ln_q - 1.96 * se).exp(),
        hi: (ln_q + 1.96 * se).exp(),
        variance_ratio: mean(|t| t.variance_ratio).exp(),
        cost_ratio: mean(|t| t.cost_ratio).exp(),
        pairs: terms.len(),
    }
}

/// Every unbiased estimator's efficiency relative to the walk's, geometric mean over the cases
/// where both are finite and positive.
fn choice(config: Config, index: &HashMap<(Case, Est), &EfficiencyRow>) -> Choice {
    let relative_to_walk: Vec<(Est, f64)> = Est::ALL
        .into_iter()
        .filter(|&e| !e.is_biased())
        .map(|est| {
            let logs: Vec<f64> = Case::all(config)
                .into_iter()
                .filter_map(|case| {
                    let q =
                        index.get(&(case, est))?.efficiency? / index.get(&(case, Est::Walk))?.efficiency?;
                    (q.is_finite() && q > 0.0).then(|| q.ln())
                })
                .collect();
            (est, (logs.iter().sum::<f64>() / logs.len().max(1) as f64).exp())
        })
        .collect();
    let best = relative_to_walk.iter().max_by(|a, b| a.1.total_cmp(&b.1)).map_or(Est::Walk, |b| b.0);
    Choice { config, relative_to_walk, best }
}

fn lobe_panels(points: &[LobePoint], energy: &[EnergyRow]) -> Vec<LobePanel> {
    let mut panels = Vec::new();
    for material in super::configure::LOBE_MATERIALS {
        for model in Model::ALL {
            for theta_i in THETAS {
                let points: Vec<LobePoint> = points
                    .iter()
                    .filter(|p| p.material == material && p.model == model && p.theta_i == theta_i)
                    .copied()
                    .collect();
                let peak = points.iter().map(|p| p.total().mean).fold(0.0, f64::max);
                let max_se = points.iter().map(|p| p.total().se).fold(0.0, f64::max);
                let energy = energy
                    .iter()
                    .find(|e| {
                        e.surface.material == material
                            && e.surface.alpha == 1.0
                            && e.surface.slope == super::configure::SlopeKind::Ggx
                            && e.model == model
                            && e.theta_i == theta_i
                    })
                    .map(|e| e.orders);
                panels.push(LobePanel {
                    material,
                    model,
                    theta_i,
                    points: points.clone(),
                    peak,
                    max_rel_se: if peak > 0.0 { max_se / peak } else { 0.0 },
                    energy,
                    samples: (
                        points.iter().map(|p| p.samples).min().unwrap_or(0),
                        points.iter().map(|p| p.samples).max().unwrap_or(0),
                    ),
                });
            }
        }
    }
    panels
}
