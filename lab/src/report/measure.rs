//! Stage 2, measure: every estimator's per-sample values and timing in every case of the error
//! study, the converged references, the energy per order, the lobes per order and the cost.
//! Nothing here is reduced beyond means and standard errors.

use super::configure::{
    Budget, Case, Config, Est, LOBE_MATERIALS, MaterialKind, Model, Models, Options, Rng, SlopeKind, Surface,
    THETAS, WithModels, dir, with_surface,
};
use super::tables::{self, TableCurve};
use glam::Vec3;
use microsurface::research::{Material, ScatteringOrder};
use microsurface::slope::MicrosurfaceSlope;
use rand::SeedableRng;
use std::hint::black_box;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// A mean with its standard error.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Estimate {
    pub mean: f64,
    pub se: f64,
}

impl Estimate {
    /// The mean of `values` and its standard error σ̂/√n.
    pub fn of(values: impl Iterator<Item = f64> + Clone) -> Self {
        let (n, sum) = values.clone().fold((0usize, 0.0), |(n, s), v| (n + 1, s + v));
        let n = n.max(1) as f64;
        let mean = sum / n;
        let var = values.map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        Self { mean, se: (var / n).sqrt() }
    }
}

/// The measured cost of one estimator run: the mean time per sample and its standard error
/// from `TIMING_CHUNKS` separately timed chunks of the run.
#[derive(Debug, Clone, Copy)]
pub struct Timing {
    pub ns_per_sample: f64,
    pub ns_se: f64,
}

/// The number of separately timed chunks of an estimator run (for the SE of its cost).
pub const TIMING_CHUNKS: usize = 16;

/// Per-sample values of one estimator in one case, with its timing.
pub struct EstimatorRun {
    pub case: Case,
    pub est: Est,
    pub values: Vec<f32>,
    pub timing: Timing,
}

/// The converged reference of one model in one case.
#[derive(Debug, Clone, Copy)]
pub struct Reference {
    pub case: Case,
    pub model: Model,
    pub value: Estimate,
}

/// The energy of one surface, model and θi: albedo split by side and by scattering order
/// (from sampled scatterings, weight × indicator), and for the walk the white furnace
/// ∫f cos dωo by Monte Carlo over ωo.
#[derive(Debug, Clone, Copy)]
pub struct EnergyRow {
    pub surface: Surface,
    pub model: Model,
    pub theta_i: f64,
    pub reflected: f64,
    pub transmitted: f64,
    /// Orders 1, 2, 3 and 4+.
    pub orders: [f64; 4],
    pub mean_bounces: f64,
    pub furnace: Option<Estimate>,
}

/// One point of a lobe: f·|cos θo| per order in the plane of incidence.
#[derive(Debug, Clone, Copy)]
pub struct LobePoint {
    pub material: MaterialKind,
    pub model: Model,
    pub theta_i: f64,
    /// Signed angle from the normal, positive on the mirror side (φo = π); |θo| > π/2 below.
    pub theta_o: f64,
    /// Orders 1 (by `eval` at θo), 2 and 3+ (bin averages of f·|cos θo| over `LobeBins`).
    pub orders: [Estimate; 3],
    /// Their sum, with its own SE (a sample counts in one order only, so the orders'
    /// estimates are correlated).
    pub total: Estimate,
    /// Sampled scatterings of the panel.
    pub samples: usize,
}

impl LobePoint {
    /// The total over orders.
    pub fn total(&self) -> Estimate {
        self.total
    }
}

/// The cost of one estimator on one surface.
#[derive(Debug, Clone, Copy)]
pub struct CostRow {
    pub surface: Surface,
    pub est: Est,
    pub ns_per_eval: f64,
    /// `None` for single scattering (no sampler of its own).
    pub ns_per_sample: Option<f64>,
    pub mean_bounces: Option<f64>,
}

/// Everything measured.
pub struct Measurements {
    pub runs: Vec<EstimatorRun>,
    pub references: Vec<Reference>,
    pub energy: Vec<EnergyRow>,
    pub lobes: Vec<LobePoint>,
    pub cost: Vec<CostRow>,
    pub tables: Vec<TableCurve>,
}

/// Runs every measurement.
pub fn measure(opts: &Options, budget: &Budget) -> Measurements {
    let (runs, references) = error_study(opts, budget);
    Measurements {
        runs,
        references,
        energy: energy(opts, budget),
        lobes: lobes(opts, budget),
        cost: cost(budget),
        tables: table_errors(opts, budget),
    }
}

/// The albedo tables against quadrature of the model they tabulate, between their nodes.
fn table_errors(opts: &Options, budget: &Budget) -> Vec<TableCurve> {
    let points = budget.table_points;
    parallel("albedo tables", tables::jobs(budget.table_alphas), opts, |(family, tabulated, alpha)| {
        tables::curve(family, tabulated, alpha, points)
    })
}

/// Runs `jobs` on `threads` workers, reporting progress on stderr.
pub(crate) fn parallel<T: Send, R: Send>(
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

/// `n` evaluations of one estimator, single-threaded, timed in `TIMING_CHUNKS` chunks. The
/// model and both directions pass through `black_box` on every call, so that nothing that
/// depends on them is hoisted out of the timed loop (the error study estimates one value, so
/// its inputs cannot rotate; `cost` rotates pre-generated directions).
struct TimedRun {
    est: Est,
    wi: Vec3,
    wo: Vec3,
    n: usize,
    seed: u64,
}

impl WithModels for TimedRun {
    type Out = (Vec<f32>, Timing);

    fn go<S: MicrosurfaceSlope, M: Material>(self, m: Models<S, M>) -> Self::Out {
        let Self { est, wi, wo, n, seed } = self;
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
}

/// What an error-study job computes.
#[derive(Clone, Copy)]
enum Role {
    /// A run of the error study, `samples` evaluations.
    Study(Est),
    /// A model's converged reference, `samples × reference_factor` evaluations.
    Reference(Model),
}

/// The error study: every estimator in every case, and every model's reference.
fn error_study(opts: &Options, budget: &Budget) -> (Vec<EstimatorRun>, Vec<Reference>) {
    let mut jobs = Vec::new();
    for config in Config::ALL {
        for case in Case::all(config) {
            let material = config.surface().material;
            jobs.extend(
                Est::ALL.into_iter().filter(|e| e.applies_to(material)).map(|est| (case, Role::Study(est))),
            );
            jobs.extend(Model::ALL.map(|model| (case, Role::Reference(model))));
        }
    }
    let jobs: Vec<_> = jobs.into_iter().enumerate().collect();
    let done = parallel("error vs time", jobs, opts, |(i, (case, role))| {
        let (est, n) = match role {
            Role::Study(est) => (est, budget.samples),
            Role::Reference(model) => (model.reference_estimator(), budget.samples * budget.reference_factor),
        };
        let task = TimedRun { est, wi: case.wi(), wo: case.wo_dir(), n, seed: 0x5EED_0000 + i as u64 };
        (case, role, with_surface(case.config.surface(), task))
    });
    let (mut runs, mut references) = (Vec::new(), Vec::new());
    for (case, role, (values, timing)) in done {
        match role {
            Role::Study(est) => runs.push(EstimatorRun { case, est, values, timing }),
            Role::Reference(model) => references.push(Reference {
                case,
                model,
                value: Estimate::of(values.iter().map(|&v| f64::from(v))),
            }),
        }
    }
    (runs, references)
}

/// Albedo per order from sampled scatterings and (for the walk) the white furnace.
struct EnergyTask {
    surface: Surface,
    model: Model,
    theta_i: f64,
    walks: usize,
    furnace: usize,
    seed: u64,
}

impl WithModels for EnergyTask {
    type Out = EnergyRow;

    fn go<S: MicrosurfaceSlope, M: Material>(self, m: Models<S, M>) -> Self::Out {
        let mut rng = Rng::seed_from_u64(self.seed);
        let wi = dir(self.theta_i, 0.0);
        let mut row = EnergyRow {
            surface: self.surface,
            model: self.model,
            theta_i: self.theta_i,
            reflected: 0.0,
            transmitted: 0.0,
            orders: [0.0; 4],
            mean_bounces: 0.0,
            furnace: None,
        };
        let n = self.walks as f64;
        for _ in 0..self.walks {
            if let Some(s) = m.sample(self.model, wi, &mut rng) {
                let w = s.weight / n;
                if s.reflected {
                    row.reflected += w
                } else {
                    row.transmitted += w
                }
                row.orders[(s.bounces as usize).clamp(1, 4) - 1] += w;
                row.mean_bounces += f64::from(s.bounces) / n;
            }
        }
        if self.model != Model::Walk {
            return row;
        }
        // ωo from a mixture of the uniform sphere and (when its density is exact) the
        // first-bounce phase function, so that sharp lobes (α = 0.1) are found
        let walk = &m.walk;
        let phase_share = if M::EXACT_PHASE_PDF { 0.5 } else { 0.0 };
        let furnace: Vec<f64> = (0..self.furnace)
            .map(|_| {
                let u0: f64 = rand::RngExt::random(&mut rng);
                let wo = if u0 < phase_share {
                    walk.sample_phase(wi, &mut rng).wo
                } else {
                    let u1: f64 = rand::RngExt::random(&mut rng);
                    let u2: f64 = rand::RngExt::random(&mut rng);
                    dir((1.0 - 2.0 * u1).acos(), std::f64::consts::TAU * u2)
                };
                let phase =
                    if phase_share > 0.0 { f64::from(walk.eval_phase(wi, wo, &mut rng).x) } else { 0.0 };
                let density = (1.0 - phase_share) / (4.0 * std::f64::consts::PI) + phase_share * phase;
                f64::from(walk.eval(wi, wo, ScatteringOrder::All, &mut rng).x) / density
            })
            .collect();
        row.furnace = Some(Estimate::of(furnace.iter().copied()));
        row
    }
}

/// The energy table: the walk on every surface, and the position-free models on the lobe
/// surfaces (GGX α = 1, conductor and dielectric).
fn energy(opts: &Options, budget: &Budget) -> Vec<EnergyRow> {
    let mut jobs = Vec::new();
    for surface in Surface::all() {
        let lobe_surface = surface.slope == SlopeKind::Ggx
            && surface.alpha == 1.0
            && LOBE_MATERIALS.contains(&surface.material);
        let models: &[Model] = if lobe_surface { &Model::ALL } else { &[Model::Walk] };
        for &model in models {
            for theta_i in THETAS {
                jobs.push((surface, model, theta_i));
            }
        }
    }
    parallel("energy per order", jobs, opts, |(surface, model, theta_i)| {
        let seed = (surface.alpha * 1e3) as u64
            ^ ((theta_i * 1e3) as u64) << 16
            ^ (surface.material as u64 + 1) << 32
            ^ (surface.slope as u64 + 1) << 40
            ^ (model as u64) << 48;
        let (walks, furnace) = (budget.energy_walks, budget.furnace_samples);
        with_surface(surface, EnergyTask { surface, model, theta_i, walks, furnace, seed })
    })
}

/// The lobe angles: the midpoints of `n` equal steps over the upper half plane (−π/2, π/2),
/// and for the dielectric of `2n` steps over the whole circle; never horizontal, where f·cos
/// vanishes and the estimators' weights are least stable.
pub fn lobe_angles(material: MaterialKind, n: usize) -> Vec<f64> {
    use std::f64::consts::{FRAC_PI_2, PI};
    let count = if material == MaterialKind::Dielectric { 2 * n } else { n };
    (0..count).map(|k| -FRAC_PI_2 + PI * (k as f64 + 0.5) / n as f64).collect()
}

/// The sampled directions of a lobe histogram: bins of θo in the plane of incidence.
///
/// A bin is the patch of directions whose signed polar angle in the plane of incidence lies
/// in one of `lobe_angles`' steps (width Δθ = π/n) and whose distance from that plane is at
/// most Δθ/2 (|ωo·y| ≤ sin(Δθ/2), the y axis normal to the plane): about Δθ × Δθ at every θo,
/// on the mirror side (φo = π) or on the side of ωi (φo = 0). Each sampled scattering lands in
/// at most one bin, and the estimate of a bin is the bin average of f·|cos θo| per order:
/// (1/N) Σ w·1[ωo ∈ bin, order] / Ω_bin with w = f·|cos θo|/pdf the sample's weight — unbiased
/// for that average, and far less noisy than per-direction `eval` since every sample counts.
/// The lobes take orders 2 and 3+ from it (broad lobes, which the bin average barely smooths),
/// interpolated linearly between the bins' centres, and the first order, the sharpest, from
/// `eval` at `LOBE_EVAL_REFINEMENT` angles per bin (`FirstOrderTask`).
struct LobeBins {
    /// Bins over the half plane (the dielectric has twice as many, over the full circle).
    n: usize,
    full_circle: bool,
    /// sin of the half-width of the slab about the plane of incidence.
    slab: f64,
    /// The solid angle of every bin.
    solid_angle: Vec<f64>,
}

impl LobeBins {
    fn new(material: MaterialKind, n: usize) -> Self {
        use std::f64::consts::{FRAC_PI_2, PI};
        let full_circle = material == MaterialKind::Dielectric;
        let count = if full_circle { 2 * n } else { n };
        let width = PI / n as f64;
        let slab = (0.5 * width).sin();
        // Ω = ∫ over the bin's signed angles s of 2 asin(min(1, h / sin θ)) sin θ ds, θ = |s|
        // folded into [0, π] (one side of the plane: the slab's azimuths there), by the midpoint
        // rule on 64 steps per bin (the integrand is smooth except where sin θ = h, which only
        // the bins at the poles contain; there it is bounded and 64 steps give < 1e-4).
        let steps = 64;
        let solid_angle = (0..count)
            .map(|k| {
                let lo = -FRAC_PI_2 + width * k as f64;
                (0..steps)
                    .map(|i| {
                        let s = lo + width * (i as f64 + 0.5) / steps as f64;
                        let sin_theta = s.sin().abs();
                        let half = if sin_theta <= slab { FRAC_PI_2 } else { (slab / sin_theta).asin() };
                        2.0 * half * sin_theta * width / steps as f64
                    })
                    .sum()
            })
            .collect();
        Self { n, full_circle, slab, solid_angle }
    }

    fn len(&self) -> usize {
        self.solid_angle.len()
    }

    /// The two bins whose centres enclose the j-th of the angles `lobe_angles` gives for
    /// `refinement` × n steps, and the linear weight t of the second: periodic over the full
    /// circle, the end bins' values held constant over the half plane's outer half bins.
    fn between_centres(&self, j: usize, refinement: usize) -> ([usize; 2], f64) {
        let m = self.len();
        // the fine angle's position in units of bins, from the first bin's centre
        let u = (j as f64 + 0.5) / refinement as f64 - 0.5;
        let k = u.floor();
        let t = u - k;
        if self.full_circle {
            let k0 = (k as i64).rem_euclid(m as i64) as usize;
            ([k0, (k0 + 1) % m], t)
        } else if k < 0.0 {
            ([0, 0], 0.0)
        } else if k as usize + 1 >= m {
            ([m - 1, m - 1], 0.0)
        } else {
            ([k as usize, k as usize + 1], t)
        }
    }

    /// The bin of direction `wo` (ωi in the x–z plane at φ = 0), if it is in one.
    fn bin(&self, wo: Vec3) -> Option<usize> {
        use std::f64::consts::{FRAC_PI_2, PI, TAU};
        let (x, y, z) = (f64::from(wo.x), f64::from(wo.y), f64::from(wo.z));
        if y.abs() > self.slab || (!self.full_circle && z <= 0.0) {
            return None;
        }
        // the signed angle of `lobe_angles`: ωo = (−sin s, ·, cos s), positive on the mirror side
        let theta = z.clamp(-1.0, 1.0).acos();
        let mut s = if x <= 0.0 { theta } else { -theta };
        if s < -FRAC_PI_2 {
            s += TAU;
        }
        let k = ((s + FRAC_PI_2) / (PI / self.n as f64)).floor();
        (k >= 0.0 && (k as usize) < self.len()).then_some(k as usize)
    }
}

/// Per-bin, per-order sums of the sampled weights w and of w² (orders 1, 2, 3+), and of the
/// total's w² (a sample counts in one order only).
#[derive(Debug, Clone, Default)]
struct LobeSums {
    samples: usize,
    sum: Vec<[f64; 3]>,
    sum2: Vec<[f64; 3]>,
    total2: Vec<f64>,
}

impl LobeSums {
    fn new(bins: usize) -> Self {
        Self { samples: 0, sum: vec![[0.0; 3]; bins], sum2: vec![[0.0; 3]; bins], total2: vec![0.0; bins] }
    }

    fn merge(&mut self, other: &Self) {
        self.samples += other.samples;
        for b in 0..self.sum.len() {
            for k in 0..3 {
                self.sum[b][k] += other.sum[b][k];
                self.sum2[b][k] += other.sum2[b][k];
            }
            self.total2[b] += other.total2[b];
        }
    }

    /// The mean and standard error of Σ w·1[bin, order]/Ω over the samples, from its sums.
    fn estimate(&self, sum: f64, sum2: f64, solid_angle: f64) -> Estimate {
        let n = self.samples.max(1) as f64;
        let mean = sum / n;
        let var = ((sum2 - n * mean * mean) / (n - 1.0).max(1.0)).max(0.0);
        Estimate { mean: mean / solid_angle, se: (var / n).sqrt() / solid_angle }
    }

    /// The estimates of bin b: orders 1, 2, 3+ and the total.
    fn bin(&self, b: usize, solid_angle: f64) -> ([Estimate; 3], Estimate) {
        let orders = [0, 1, 2].map(|k| self.estimate(self.sum[b][k], self.sum2[b][k], solid_angle));
        let total = self.estimate(self.sum[b].iter().sum(), self.total2[b], solid_angle);
        (orders, total)
    }

    /// The estimate of bin b's orders 2 and up (a sample counts in one order only).
    fn higher_orders(&self, b: usize, solid_angle: f64) -> Estimate {
        self.estimate(self.sum[b][1] + self.sum[b][2], self.sum2[b][1] + self.sum2[b][2], solid_angle)
    }

    /// The largest SE of a bin's orders 2 and up relative to the largest total (all orders).
    fn rel_se(&self, bins: &LobeBins) -> f64 {
        let peak = (0..bins.len()).map(|b| self.bin(b, bins.solid_angle[b]).1.mean).fold(0.0, f64::max);
        let se = (0..bins.len()).map(|b| self.higher_orders(b, bins.solid_angle[b]).se).fold(0.0, f64::max);
        if peak > 0.0 { se / peak } else { f64::INFINITY }
    }
}

/// `samples` sampled scatterings of one model for one ωi, histogrammed into `bins`.
struct LobeTask<'a> {
    model: Model,
    wi: Vec3,
    bins: &'a LobeBins,
    samples: usize,
    seed: u64,
}

impl WithModels for LobeTask<'_> {
    type Out = LobeSums;

    fn go<S: MicrosurfaceSlope, M: Material>(self, m: Models<S, M>) -> Self::Out {
        let mut rng = Rng::seed_from_u64(self.seed);
        let mut sums = LobeSums::new(self.bins.len());
        sums.samples = self.samples;
        for _ in 0..self.samples {
            let Some(s) = m.sample(self.model, self.wi, &mut rng) else { continue };
            let Some(b) = self.bins.bin(s.wo) else { continue };
            let k = (s.bounces as usize).clamp(1, 3) - 1;
            sums.sum[b][k] += s.weight;
            sums.sum2[b][k] += s.weight * s.weight;
            sums.total2[b] += s.weight * s.weight;
        }
        sums
    }
}

/// The first order of a lobe is evaluated at this many angles per histogram bin (the orders
/// 2 and 3+ are interpolated linearly between the bins' centres there): the first order is the
/// sharpest, and its `eval` is cheap.
const LOBE_EVAL_REFINEMENT: usize = 2;

/// The share of a lobe's SE target given to its first order (in quadrature): small, since the
/// first order's `eval` costs one vertex and has a small variance.
const FIRST_ORDER_SHARE: f64 = 0.25;

/// Running sums of one estimated quantity.
#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    n: usize,
    sum: f64,
    sum2: f64,
}

impl Sums {
    fn add(&mut self, v: f64) {
        self.n += 1;
        self.sum += v;
        self.sum2 += v * v;
    }

    fn estimate(&self) -> Estimate {
        let n = self.n.max(1) as f64;
        let mean = self.sum / n;
        let var = ((self.sum2 - n * mean * mean) / (n - 1.0).max(1.0)).max(0.0);
        Estimate { mean, se: (var / n).sqrt() }
    }
}

/// The first order of f·|cos θo| at one direction by the model's `eval`, in rounds of `round`
/// evaluations until its SE is at most `target_se` or `max` evaluations are reached.
struct FirstOrderTask {
    est: Est,
    wi: Vec3,
    wo: Vec3,
    round: usize,
    target_se: f64,
    max: usize,
    seed: u64,
}

impl WithModels for FirstOrderTask {
    type Out = Sums;

    fn go<S: MicrosurfaceSlope, M: Material>(self, m: Models<S, M>) -> Self::Out {
        let mut rng = Rng::seed_from_u64(self.seed);
        let mut sums = Sums::default();
        let first = ScatteringOrder::only(1).expect("n > 0");
        loop {
            for _ in 0..self.round {
                sums.add(m.eval(self.est, self.wi, self.wo, first, &mut rng));
            }
            if sums.estimate().se <= self.target_se || sums.n >= self.max {
                break sums;
            }
        }
    }
}

/// The estimator of a model's first order: the walk's `eval` and the position-free PT.
fn lobe_estimator(model: Model) -> Est {
    match model {
        Model::Walk => Est::Walk,
        Model::Uncorrelated => Est::PtUncorrelated,
        Model::Correlated => Est::PtCorrelated,
    }
}

/// The lobes per order of the walk and both position-free models (GGX α = 1), histogrammed
/// from each model's own sampled scatterings (`LobeBins`, orders 2 and 3+) and evaluated at
/// each bin's centre (order 1), in two passes: a pilot round of `lobe_samples` scatterings per
/// panel gives the SE of its noisiest bin of orders 2+; the panel then gets as many further
/// rounds as make the SE of the points interpolated from it (0.79 × a bin's) √(1 − s²)
/// `lobe_rel_se` × its peak (SE ∝ 1/√N), at most
/// `lobe_max_samples` scatterings in all; the first order (cheap: one vertex) gets evaluations
/// until its SE is s `lobe_rel_se` × the peak (s = `FIRST_ORDER_SHARE`), at most
/// `lobe_max_evals`; so the total's SE is at most `lobe_rel_se` × the peak (the report states
/// the SE reached).
fn lobes(opts: &Options, budget: &Budget) -> Vec<LobePoint> {
    let mut panels = Vec::new();
    for material in LOBE_MATERIALS {
        for model in Model::ALL {
            for theta_i in THETAS {
                panels.push((material, model, theta_i));
            }
        }
    }
    let bins = LOBE_MATERIALS.map(|m| LobeBins::new(m, budget.lobe_angles));
    let bins_of =
        |material: MaterialKind| &bins[LOBE_MATERIALS.iter().position(|&m| m == material).expect("lobe")];
    let round = |&(material, model, theta_i): &(MaterialKind, Model, f64), index: u64| {
        let surface = Surface { material, slope: SlopeKind::Ggx, alpha: 1.0 };
        let seed =
            ((material as u64) << 40) ^ ((model as u64) << 36) ^ ((theta_i * 1e3) as u64) << 20 ^ index;
        let task = LobeTask {
            model,
            wi: dir(theta_i, 0.0),
            bins: bins_of(material),
            samples: budget.lobe_samples,
            seed,
        };
        with_surface(surface, task)
    };
    let pilot = parallel("lobes (pilot)", panels.clone(), opts, |p| round(&p, 0));
    let max_rounds = (budget.lobe_max_samples / budget.lobe_samples).max(1);
    let mut jobs = Vec::new();
    for (i, (p, sums)) in panels.iter().zip(&pilot).enumerate() {
        // a plotted point interpolates two bins at weights 1/4 and 3/4 (`LOBE_EVAL_REFINEMENT` = 2):
        // its SE is √(1/16 + 9/16) = 0.79 × theirs
        let interpolated = (0.0625f64 + 0.5625).sqrt();
        let needed = (interpolated * sums.rel_se(bins_of(p.0)) / budget.lobe_rel_se).powi(2)
            / (1.0 - FIRST_ORDER_SHARE.powi(2));
        let rounds =
            if needed.is_finite() { (needed.ceil() as usize).clamp(1, max_rounds) } else { max_rounds };
        jobs.extend((1..rounds).map(|r| (i, r as u64)));
    }
    let more = parallel("lobes per order", jobs.clone(), opts, |(i, r)| round(&panels[i], r));
    let mut totals = pilot;
    for ((i, _), sums) in jobs.iter().zip(&more) {
        totals[*i].merge(sums);
    }
    let mut first_jobs = Vec::new();
    for (&(material, model, theta_i), sums) in panels.iter().zip(&totals) {
        let bins = bins_of(material);
        let peak = (0..bins.len()).map(|b| sums.bin(b, bins.solid_angle[b]).1.mean).fold(0.0, f64::max);
        for theta_o in lobe_angles(material, LOBE_EVAL_REFINEMENT * budget.lobe_angles) {
            first_jobs.push((material, model, theta_i, theta_o, peak));
        }
    }
    let first =
        parallel("lobes (first order)", first_jobs, opts, |(material, model, theta_i, theta_o, peak)| {
            let surface = Surface { material, slope: SlopeKind::Ggx, alpha: 1.0 };
            let seed = ((material as u64) << 40)
                ^ ((model as u64) << 36)
                ^ ((theta_i * 1e3) as u64) << 20
                ^ ((theta_o + 4.0) * 1e5) as u64
                ^ 1 << 60;
            let task = FirstOrderTask {
                est: lobe_estimator(model),
                wi: dir(theta_i, 0.0),
                wo: Vec3::new(-(theta_o.sin()) as f32, 0.0, theta_o.cos() as f32),
                round: budget.lobe_evals,
                target_se: budget.lobe_rel_se * FIRST_ORDER_SHARE * peak,
                max: budget.lobe_max_evals,
                seed,
            };
            with_surface(surface, task).estimate()
        });
    let mut first = first.into_iter();
    let mut points = Vec::new();
    for ((material, model, theta_i), sums) in panels.into_iter().zip(totals) {
        let bins = bins_of(material);
        let fine = lobe_angles(material, LOBE_EVAL_REFINEMENT * budget.lobe_angles);
        for (j, theta_o) in fine.into_iter().enumerate() {
            let ([b0, b1], t) = bins.between_centres(j, LOBE_EVAL_REFINEMENT);
            let lerp = |e0: Estimate, e1: Estimate| Estimate {
                mean: (1.0 - t) * e0.mean + t * e1.mean,
                se: ((1.0 - t) * e0.se).hypot(t * e1.se),
            };
            let (h0, h1) = (sums.bin(b0, bins.solid_angle[b0]).0, sums.bin(b1, bins.solid_angle[b1]).0);
            let higher = lerp(
                sums.higher_orders(b0, bins.solid_angle[b0]),
                sums.higher_orders(b1, bins.solid_angle[b1]),
            );
            let order1 = first.next().expect("one first-order estimate per point");
            let orders = [order1, lerp(h0[1], h1[1]), lerp(h0[2], h1[2])];
            // independent estimates: the SEs add in quadrature
            let total = Estimate { mean: order1.mean + higher.mean, se: order1.se.hypot(higher.se) };
            points.push(LobePoint {
                material,
                model,
                theta_i,
                theta_o,
                orders,
                total,
                samples: sums.samples,
            });
        }
    }
    points
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

/// The incident angle of the cost table.
pub const COST_THETA_I: f64 = 0.5;

/// The surfaces of the cost table.
pub fn cost_surfaces() -> [Surface; 4] {
    let s = |material, slope| Surface { material, slope, alpha: 0.5 };
    [
        s(MaterialKind::Conductor, SlopeKind::Ggx),
        s(MaterialKind::Conductor, SlopeKind::Beckmann),
        s(MaterialKind::Dielectric, SlopeKind::Ggx),
        s(MaterialKind::Diffuse, SlopeKind::Ggx),
    ]
}

/// Single-threaded cost per call of every estimator on one surface, like the criterion
/// benches: ωi fixed, the ωo of `eval` rotated through `COST_DIRECTIONS` pre-generated
/// directions, the model and every input behind `black_box`.
struct CostTask {
    surface: Surface,
    n: usize,
}

impl WithModels for CostTask {
    type Out = Vec<CostRow>;

    fn go<S: MicrosurfaceSlope, M: Material>(self, m: Models<S, M>) -> Self::Out {
        let (wi, n) = (dir(COST_THETA_I, 0.0), self.n);
        let wos = cost_directions(M::TRANSMITS);
        let mut rng = Rng::seed_from_u64(99);
        let mut rows = Vec::new();
        for est in Est::ALL.into_iter().filter(|e| e.applies_to(self.surface.material)) {
            let start = Instant::now();
            let mut acc = 0.0;
            for i in 0..n {
                let wo = wos[i & (COST_DIRECTIONS - 1)];
                acc += black_box(&m).eval(est, black_box(wi), black_box(wo), ScatteringOrder::All, &mut rng);
            }
            let ns_per_eval = start.elapsed().as_secs_f64() * 1e9 / n as f64;
            black_box(acc);
            let (ns_per_sample, mean_bounces) = if est.is_biased() {
                (None, None)
            } else {
                let start = Instant::now();
                let mut bounces = 0.0;
                for _ in 0..n {
                    let s = black_box(&m).sample(est.model(), black_box(wi), &mut rng);
                    bounces += s.map_or(0.0, |s| f64::from(s.bounces));
                }
                black_box(bounces);
                (Some(start.elapsed().as_secs_f64() * 1e9 / n as f64), Some(bounces / n as f64))
            };
            rows.push(CostRow { surface: self.surface, est, ns_per_eval, ns_per_sample, mean_bounces });
        }
        rows
    }
}

/// The cost table (single thread, sequential, so that the timings do not compete).
fn cost(budget: &Budget) -> Vec<CostRow> {
    cost_surfaces()
        .into_iter()
        .flat_map(|surface| with_surface(surface, CostTask { surface, n: budget.cost_calls }))
        .collect()
}

#[cfg(test)]
mod lobe_bin_tests {
    use super::*;
    use statrs::distribution::{ContinuousCDF, Normal};

    /// The bins tile the slab |ωo·y| ≤ h about the plane of incidence: their solid angles add
    /// up to its area (2πh over the upper hemisphere, 4πh over the sphere), and the direction
    /// at every plotted angle falls in its own bin.
    #[test]
    fn lobe_bins_tile_the_slab_and_hold_their_angles() {
        for material in LOBE_MATERIALS {
            let bins = LobeBins::new(material, 31);
            let area: f64 = bins.solid_angle.iter().sum();
            let expected = if bins.full_circle { 4.0 } else { 2.0 } * std::f64::consts::PI * bins.slab;
            assert!((area / expected - 1.0).abs() < 1e-4, "{material:?}: Σ Ω = {area}, slab {expected}");
            for (k, s) in lobe_angles(material, 31).into_iter().enumerate() {
                let wo = Vec3::new(-(s.sin()) as f32, 0.0, s.cos() as f32);
                assert_eq!(bins.bin(wo), Some(k), "{material:?}: θo = {s}");
            }
            let off_plane = Vec3::new(0.0, (2.0 * bins.slab) as f32, 1.0).normalize();
            assert_eq!(bins.bin(off_plane), None);
        }
    }

    /// Every fine angle lies between the centres of the two bins it is interpolated from.
    #[test]
    fn fine_angles_interpolate_between_enclosing_bin_centres() {
        for material in LOBE_MATERIALS {
            let (n, r) = (31, LOBE_EVAL_REFINEMENT);
            let bins = LobeBins::new(material, n);
            let centres = lobe_angles(material, n);
            let width = std::f64::consts::PI / n as f64;
            for (j, s) in lobe_angles(material, r * n).into_iter().enumerate() {
                let ([b0, b1], t) = bins.between_centres(j, r);
                assert!((0.0..1.0).contains(&t), "{material:?} j = {j}: t = {t}");
                // the interpolated position, unwrapped past the last bin on the full circle
                let c1 = centres[b1] + if b1 < b0 { std::f64::consts::TAU } else { 0.0 };
                let at = (1.0 - t) * centres[b0] + t * c1;
                let expected = if b0 == b1 { centres[b0] } else { s };
                // the same angle, up to a turn (the full circle wraps)
                let off = (at - expected).rem_euclid(std::f64::consts::TAU);
                assert!(
                    off.min(std::f64::consts::TAU - off) < 1e-12,
                    "{material:?} j = {j}: {at} vs {expected}"
                );
                assert!(b0 == b1 || (c1 - centres[b0] - width).abs() < 1e-12);
                if b0 == b1 {
                    assert!((s - centres[b0]).abs() <= 0.5 * width, "{material:?} j = {j}: held bin too far");
                }
            }
        }
    }

    /// Uniform directions on the sphere with weight 4π estimate 1 in every bin: each bin's
    /// solid angle, the poles' included, is the one its samples see (Šidák, family-wise 1e-3).
    #[test]
    fn lobe_bins_estimate_a_constant_lobe() {
        let bins = LobeBins::new(MaterialKind::Dielectric, 31);
        let n = 1usize << 21;
        let mut sums = LobeSums::new(bins.len());
        sums.samples = n;
        let mut rng = Rng::seed_from_u64(0xB1_25);
        let w = 4.0 * std::f64::consts::PI;
        for _ in 0..n {
            let u1: f64 = rand::RngExt::random(&mut rng);
            let u2: f64 = rand::RngExt::random(&mut rng);
            let wo = dir((1.0 - 2.0 * u1).acos(), std::f64::consts::TAU * u2);
            if let Some(b) = bins.bin(wo) {
                sums.sum[b][1] += w;
                sums.sum2[b][1] += w * w;
                sums.total2[b] += w * w;
            }
        }
        let m = bins.len();
        let z = Normal::standard().inverse_cdf(1.0 - 0.5 * (1.0 - (1.0 - 1e-3f64).powf(1.0 / m as f64)));
        for b in 0..m {
            let (_, total) = sums.bin(b, bins.solid_angle[b]);
            assert!(total.se < 0.05, "bin {b}: SE {} too large to test anything", total.se);
            assert!(
                (total.mean - 1.0).abs() <= z * total.se,
                "bin {b}: N = {n}, mean {} (expected 1), σ̂/√N = {}, z = {z}",
                total.mean,
                total.se
            );
        }
    }
}
