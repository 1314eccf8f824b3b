//! Stiff random walks: the Heitz et al. 2016 walk and the position-free PT and BDPT estimators
//! (both shadowing models) at α = 1e-3, at α = 4, at θi = 1.57 rad and for a dielectric lit
//! from inside near the critical angle. Used by `tests/walk/stiff.rs` (assertions) and
//! `lab/src/bin/stability.rs` (the report).
//!
//! Albedo: ∫ eval(ωi, ωo) dωo by importance-sampled Monte Carlo, ωo drawn from the mixture
//! 0.8 × the material's phase-function sampler (whose exact density `pdf_phase` is summed over
//! both sides) + 0.2 × a cosine lobe (split between both hemispheres for a dielectric); one
//! independent `eval` per direction, so each sample is unbiased and the standard error is
//! the sample's. Walk length: the `bounces` of `sample()`.

use crate::{Stats, TestRng};
use glam::Vec3;
use microsurface::research::{
    Estimator, Material, Microsurface, PositionFree, ScatteringOrder, Shadowing, UniformHeight, WalkSample,
    sample_cosine_hemisphere,
};
use microsurface::research::{Interaction, Side};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Conductor, Dielectric, Ggx};
use rand::RngExt;
use std::f64::consts::PI;

/// Share of the phase-function sampler in the mixture density.
pub const PHASE_SHARE: f64 = 0.8;

/// The five estimators of a configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tech {
    Walk,
    Pf(Estimator, Shadowing),
}

pub const TECHS: [Tech; 5] = [
    Tech::Walk,
    Tech::Pf(Estimator::Pt, Shadowing::Uncorrelated),
    Tech::Pf(Estimator::Pt, Shadowing::Correlated),
    Tech::Pf(Estimator::Bdpt, Shadowing::Uncorrelated),
    Tech::Pf(Estimator::Bdpt, Shadowing::Correlated),
];

impl Tech {
    pub fn name(&self) -> String {
        match self {
            Tech::Walk => "Heitz walk".into(),
            Tech::Pf(e, s) => format!("{e:?} {s:?}"),
        }
    }
}

/// A model with its estimator, type-erased.
pub trait Model: Sync {
    fn eval(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut TestRng) -> Vec3;
    fn single(&self, wi: Vec3, wo: Vec3, rng: &mut TestRng) -> Vec3;
    fn sample(&self, wi: Vec3, rng: &mut TestRng) -> Option<WalkSample>;
    fn mix_sample(&self, wi: Vec3, rng: &mut TestRng) -> Vec3 {
        self.sample_with(wi, PHASE_SHARE, rng)
    }
    fn mix_pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.pdf_with(wi, wo, PHASE_SHARE)
    }
    /// The mixture with the given share of the phase-function sampler.
    fn sample_with(&self, wi: Vec3, share: f64, rng: &mut TestRng) -> Vec3;
    fn pdf_with(&self, wi: Vec3, wo: Vec3, share: f64) -> f64;
}

struct Impl<S, M> {
    slope: S,
    material: M,
    tech: Tech,
}

impl<S: MicrosurfaceSlope, M: Material> Model for Impl<S, M> {
    fn eval(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut TestRng) -> Vec3 {
        match self.tech {
            Tech::Walk => {
                Microsurface::new(UniformHeight, self.slope, self.material).eval(wi, wo, order, rng)
            }
            Tech::Pf(e, s) => PositionFree::new(self.slope, self.material, s).eval(wi, wo, e, order, rng),
        }
    }
    fn single(&self, wi: Vec3, wo: Vec3, rng: &mut TestRng) -> Vec3 {
        match self.tech {
            Tech::Walk => Microsurface::new(UniformHeight, self.slope, self.material)
                .eval_single_scattering(wi, wo, rng),
            Tech::Pf(_, s) => {
                PositionFree::new(self.slope, self.material, s).eval_single_scattering(wi, wo, rng)
            }
        }
    }
    fn sample(&self, wi: Vec3, rng: &mut TestRng) -> Option<WalkSample> {
        match self.tech {
            Tech::Walk => Microsurface::new(UniformHeight, self.slope, self.material).sample(wi, rng),
            Tech::Pf(_, s) => PositionFree::new(self.slope, self.material, s).sample(wi, rng),
        }
    }
    fn sample_with(&self, wi: Vec3, share: f64, rng: &mut TestRng) -> Vec3 {
        if rng.random::<f64>() < share {
            let side = if wi.z > 0.0 { Side::Outside } else { Side::Inside };
            self.material.sample_phase(&self.slope, wi, side, rng).wo
        } else {
            let w = sample_cosine_hemisphere(rng.random::<f32>(), rng.random::<f32>());
            if M::TRANSMITS && rng.random::<f64>() < 0.5 { -w } else { w }
        }
    }
    fn pdf_with(&self, wi: Vec3, wo: Vec3, share: f64) -> f64 {
        let (m, s) = (&self.material, &self.slope);
        let out = if wi.z > 0.0 { Side::Outside } else { Side::Inside };
        let mut phase = f64::from(m.pdf_phase(s, &Interaction::new(wi, wo, out, Side::Outside)))
            + f64::from(m.pdf_phase(s, &Interaction::new(wi, wo, out, Side::Inside)));
        if !M::TRANSMITS {
            phase = f64::from(m.pdf_phase(s, &Interaction::reflection(wi, wo)));
        }
        let cosine =
            if M::TRANSMITS { f64::from(wo.z).abs() / (2.0 * PI) } else { f64::from(wo.z).max(0.0) / PI };
        share * phase + (1.0 - share) * cosine
    }
}

/// A stiff configuration.
#[derive(Debug, Clone, Copy)]
pub struct Config {
    pub name: &'static str,
    pub beckmann: bool,
    pub alpha: f32,
    /// η of a dielectric, or None for the perfect conductor (F = 1).
    pub eta: Option<f32>,
    /// Polar angle of ωi (> π/2: lit from inside).
    pub theta: f64,
    /// Albedo samples per estimator.
    pub n: usize,
    /// Sampled walks for the walk-length statistics.
    pub walks: usize,
    /// The stated bound on the mean number of bounces of `sample()`.
    pub max_mean_bounces: f64,
    /// The largest standard error of the albedo that keeps the test meaningful.
    pub max_se: f64,
}

impl Config {
    pub fn wi(&self) -> Vec3 {
        let (s, c) = self.theta.sin_cos();
        Vec3::new(s as f32, 0.0, c as f32)
    }

    pub fn model(&self, tech: Tech) -> Box<dyn Model> {
        fn boxed<S: MicrosurfaceSlope + 'static, M: Material + 'static>(
            s: S,
            m: M,
            tech: Tech,
        ) -> Box<dyn Model> {
            Box::new(Impl { slope: s, material: m, tech })
        }
        match (self.beckmann, self.eta) {
            (false, None) => boxed(Ggx::isotropic(self.alpha).unwrap(), Conductor::perfect(), tech),
            (true, None) => boxed(Beckmann::isotropic(self.alpha).unwrap(), Conductor::perfect(), tech),
            (false, Some(e)) => boxed(Ggx::isotropic(self.alpha).unwrap(), Dielectric::new(e).unwrap(), tech),
            (true, Some(e)) => {
                boxed(Beckmann::isotropic(self.alpha).unwrap(), Dielectric::new(e).unwrap(), tech)
            }
        }
    }

    pub fn label(&self) -> String {
        format!(
            "{} ({} α={} {} θi={:.4})",
            self.name,
            if self.beckmann { "Beckmann" } else { "GGX" },
            self.alpha,
            match self.eta {
                None => "conductor F=1".to_string(),
                Some(e) => format!("dielectric η={e}"),
            },
            self.theta
        )
    }
}

/// The critical angle of η = 1.5 seen from inside: asin(1/1.5).
pub fn critical_angle() -> f64 {
    (1.0f64 / 1.5).asin()
}

/// The stiff configurations.
pub fn configs() -> Vec<Config> {
    let base = Config {
        name: "",
        beckmann: false,
        alpha: 1e-3,
        eta: None,
        theta: 0.7,
        n: 20_000,
        walks: 20_000,
        max_mean_bounces: 0.0,
        max_se: 0.0,
    };
    let tc = critical_angle();
    let mut v = vec![
        Config { name: "near-specular", max_mean_bounces: 1.01, max_se: 1.5e-3, n: 200_000, ..base },
        Config {
            name: "near-specular",
            beckmann: true,
            max_mean_bounces: 1.01,
            max_se: 1.5e-3,
            n: 200_000,
            ..base
        },
        Config { name: "very rough", alpha: 4.0, max_mean_bounces: 10.0, max_se: 1.5e-2, n: 80_000, ..base },
        Config { name: "grazing", alpha: 0.5, theta: 1.57, max_mean_bounces: 1.5, max_se: 3e-3, ..base },
    ];
    for d in [-0.02, 0.0, 0.02] {
        v.push(Config {
            name: "inside, near TIR",
            alpha: 0.3,
            eta: Some(1.5),
            theta: std::f64::consts::PI - (tc + d),
            max_mean_bounces: 1.5,
            max_se: 1.5e-2,
            n: 60_000,
            ..base
        });
    }
    v
}

/// One estimator on one configuration.
#[derive(Debug, Clone)]
pub struct Run {
    pub config: Config,
    pub tech: Tech,
    /// ∫ eval dωo per sample (channel 0).
    pub albedo: Stats,
    /// Bounces of `sample()`.
    pub bounces: Stats,
    /// Walks that returned None (cap reached or absorbed): must be 0 here.
    pub dropped: usize,
}

pub fn run(config: Config, tech: Tech, seed: u64) -> Run {
    let model = config.model(tech);
    let wi = config.wi();
    let mut rng = crate::rng(seed);
    let mut albedo = Stats::default();
    for _ in 0..config.n {
        let wo = model.mix_sample(wi, &mut rng);
        let p = model.mix_pdf(wi, wo);
        let f = model.eval(wi, wo, ScatteringOrder::All, &mut rng).x;
        albedo.push(if p > 0.0 { f64::from(f) / p } else { 0.0 });
    }
    let mut bounces = Stats::default();
    let mut dropped = 0;
    for _ in 0..config.walks {
        match model.sample(wi, &mut rng) {
            Some(s) => bounces.push(f64::from(s.bounces)),
            None => dropped += 1,
        }
    }
    Run { config, tech, albedo, bounces, dropped }
}

/// Order-1 energy against the single-scattering integral, paired on the same directions drawn
/// from the phase function alone (both vanish where its density does), and the energy of the
/// orders ≥ 2 with the mixture density: (order-1 albedo, single-scattering albedo, their
/// difference, multiple-scattering albedo).
pub fn order_one(config: Config, tech: Tech, seed: u64) -> [Stats; 4] {
    let model = config.model(tech);
    let wi = config.wi();
    let mut rng = crate::rng(seed);
    let [mut o1, mut ss, mut diff, mut multi] = [Stats::default(); 4];
    let only1 = ScatteringOrder::only(1).unwrap();
    for _ in 0..config.n {
        let wo = model.sample_with(wi, 1.0, &mut rng);
        let p = model.pdf_with(wi, wo, 1.0);
        let (a, b) = if p > 0.0 {
            (
                f64::from(model.eval(wi, wo, only1, &mut rng).x) / p,
                f64::from(model.single(wi, wo, &mut rng).x) / p,
            )
        } else {
            (0.0, 0.0)
        };
        o1.push(a);
        ss.push(b);
        diff.push(a - b);
        let wo = model.mix_sample(wi, &mut rng);
        let p = model.mix_pdf(wi, wo);
        let higher = if p > 0.0 {
            let all = f64::from(model.eval(wi, wo, ScatteringOrder::All, &mut rng).x);
            let first = f64::from(model.eval(wi, wo, only1, &mut rng).x);
            (all - first) / p
        } else {
            0.0
        };
        multi.push(higher);
    }
    [o1, ss, diff, multi]
}

/// Runs every estimator on every configuration on up to two threads.
pub fn all_runs() -> Vec<Run> {
    let jobs: Vec<(Config, Tech, u64)> = configs()
        .into_iter()
        .enumerate()
        .flat_map(|(i, c)| {
            TECHS.iter().enumerate().map(move |(j, &t)| (c, t, 0x57_1ff0_0000 + (i * 16 + j) as u64))
        })
        .collect();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let out = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| {
                loop {
                    let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(&(c, t, seed)) = jobs.get(k) else { break };
                    let r = run(c, t, seed);
                    out.lock().unwrap().push((k, r));
                }
            });
        }
    });
    let mut v = out.into_inner().unwrap();
    v.sort_by_key(|(k, _)| *k);
    v.into_iter().map(|(_, r)| r).collect()
}

/// The stiff-walk table in markdown.
pub fn markdown_table(runs: &[Run]) -> String {
    let mut s = String::from(
        "| configuration | estimator | albedo ± SE | (albedo − 1)/SE | mean bounces ± SE (bound) | dropped |\n|---|---|---|---|---|---|\n",
    );
    for r in runs {
        s.push_str(&format!(
            "| {} | {} | {:.5} ± {:.5} | {:+.2} | {:.3} ± {:.3} ({}) | {} |\n",
            r.config.label(),
            r.tech.name(),
            r.albedo.mean(),
            r.albedo.se(),
            (r.albedo.mean() - 1.0) / r.albedo.se(),
            r.bounces.mean(),
            r.bounces.se(),
            r.config.max_mean_bounces,
            r.dropped
        ));
    }
    s
}
