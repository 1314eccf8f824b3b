//! Stage 1, configure: what the report measures (configurations, estimators, directions) and
//! how much (the sample budget of a quick or a full run).

use glam::Vec3;
use microsurface::compensation::AlbedoTabulated;
use microsurface::research::{
    Material, Microsurface, PositionFree, ScatteringOrder, Shadowing, UniformHeight,
};
use microsurface::slope::MicrosurfaceSlope;

use microsurface::{Beckmann, Bsdf, Conductor, Dielectric, Diffuse, Ggx};
use std::path::PathBuf;

pub type Rng = rand_pcg::Pcg64Mcg;

/// What to compute and where to write it.
#[derive(Debug, Clone)]
pub struct Options {
    /// How much to compute.
    pub size: RunSize,
    /// Output directory.
    pub out_dir: PathBuf,
    /// Worker threads.
    pub threads: usize,
    /// Print a progress bar on stderr (`main` sets it only when stderr is a terminal).
    pub progress: bool,
    /// Where a full run writes the results page (`None`: `docs/results.md`).
    pub results_page: Option<PathBuf>,
}

/// How much a run computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunSize {
    /// A small run for CI (seconds instead of minutes): `--quick`.
    Quick,
    /// The published figures.
    Full,
}

/// The default output directory.
pub fn default_out_dir() -> PathBuf {
    PathBuf::from("target").join("report")
}

/// Sample counts of one run.
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    /// Evaluations per estimator and (θi, ωo) of the error study.
    pub samples: usize,
    /// Evaluations of the converged reference, as a multiple of `samples`.
    pub reference_factor: usize,
    /// Bins of θo of a lobe over the upper half plane (twice as many for the dielectric).
    pub lobe_angles: usize,
    /// Sampled scatterings per round of a lobe panel (the pilot is one round).
    pub lobe_samples: usize,
    /// The target standard error of a lobe's total in every bin, relative to its panel's peak.
    pub lobe_rel_se: f64,
    /// The most sampled scatterings of a lobe panel.
    pub lobe_max_samples: usize,
    /// Evaluations of the first order per round at each angle of a lobe.
    pub lobe_evals: usize,
    /// The most evaluations of the first order at an angle of a lobe.
    pub lobe_max_evals: usize,
    /// Sampled walks per surface and θi of the energy table.
    pub energy_walks: usize,
    /// Evaluations of the white furnace ∫f cos dωo per surface and θi.
    pub furnace_samples: usize,
    /// Calls per model and estimator of the cost table.
    pub cost_calls: usize,
    /// Direction cosines per curve of the albedo tables' interpolation error.
    pub table_points: usize,
    /// The roughnesses of the albedo-table curves.
    pub table_alphas: &'static [f32],
}

impl Budget {
    pub fn new(size: RunSize) -> Self {
        if size == RunSize::Quick {
            Self {
                samples: 1 << 10,
                reference_factor: 4,
                lobe_angles: 13,
                lobe_samples: 1 << 12,
                lobe_rel_se: 0.1,
                lobe_max_samples: 1 << 14,
                lobe_evals: 64,
                lobe_max_evals: 256,
                energy_walks: 1 << 10,
                furnace_samples: 1 << 10,
                cost_calls: 2_000,
                table_points: 4,
                table_alphas: &[0.4],
            }
        } else {
            Self {
                samples: 1 << 15,
                reference_factor: 4,
                lobe_angles: 31,
                lobe_samples: 1 << 20,
                lobe_rel_se: 0.003,
                lobe_max_samples: 1 << 26,
                lobe_evals: 1 << 12,
                lobe_max_evals: 1 << 18,
                energy_walks: 1 << 15,
                furnace_samples: 1 << 15,
                cost_calls: 100_000,
                table_points: 25,
                table_alphas: &super::tables::TABLE_ALPHAS,
            }
        }
    }

    /// (name, value, meaning) of every field, for the report's parameter table.
    pub fn describe(&self) -> Vec<(&'static str, String, &'static str)> {
        vec![
            (
                "samples",
                self.samples.to_string(),
                "evaluations per estimator and (θi, ωo) of the error study",
            ),
            (
                "reference_factor",
                self.reference_factor.to_string(),
                "reference evaluations as a multiple of samples",
            ),
            (
                "lobe_angles",
                self.lobe_angles.to_string(),
                "bins of θo per half plane of a lobe (Δθ = 180°/n; slab ±Δθ/2 about the plane)",
            ),
            (
                "lobe_samples",
                self.lobe_samples.to_string(),
                "sampled scatterings per round of a lobe panel (the pilot is one round)",
            ),
            (
                "lobe_rel_se",
                self.lobe_rel_se.to_string(),
                "target SE of a lobe bin's total, relative to its panel's peak",
            ),
            (
                "lobe_max_samples",
                self.lobe_max_samples.to_string(),
                "the most sampled scatterings of a lobe panel",
            ),
            (
                "lobe_evals",
                self.lobe_evals.to_string(),
                "evaluations of the first order per round at each angle of a lobe (two angles per bin)",
            ),
            (
                "lobe_max_evals",
                self.lobe_max_evals.to_string(),
                "the most evaluations of the first order at an angle of a lobe",
            ),
            (
                "energy_walks",
                self.energy_walks.to_string(),
                "sampled walks per surface and θi (energy per order)",
            ),
            (
                "furnace_samples",
                self.furnace_samples.to_string(),
                "evaluations of the white furnace per surface and θi",
            ),
            ("cost_calls", self.cost_calls.to_string(), "calls per model and estimator (cost table)"),
            (
                "table_points",
                self.table_points.to_string(),
                "direction cosines per curve (albedo table error)",
            ),
            (
                "table_alphas",
                format!("{:?}", self.table_alphas),
                "roughnesses of the albedo table error curves",
            ),
        ]
    }
}

/// The estimators compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Est {
    Single,
    /// The compensated conductor (`Compensated`, default scheme): conductors only.
    Compensated,
    Walk,
    PtUncorrelated,
    PtCorrelated,
    BdptUncorrelated,
    BdptCorrelated,
}

impl Est {
    pub const ALL: [Est; 7] = [
        Est::Single,
        Est::Compensated,
        Est::Walk,
        Est::PtUncorrelated,
        Est::PtCorrelated,
        Est::BdptUncorrelated,
        Est::BdptCorrelated,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Est::Single => "single",
            Est::Compensated => "compensated",
            Est::Walk => "heitz-walk",
            Est::PtUncorrelated => "pt-uncorr",
            Est::PtCorrelated => "pt-corr",
            Est::BdptUncorrelated => "bdpt-uncorr",
            Est::BdptCorrelated => "bdpt-corr",
        }
    }

    /// A label for legends.
    pub fn label(self) -> &'static str {
        match self {
            Est::Single => "single scattering (a different model: its error against the walk)",
            Est::Compensated => "compensated lobe (deterministic: its error against the walk)",
            Est::Walk => "Heitz random walk",
            Est::PtUncorrelated => "position-free PT, uncorrelated",
            Est::PtCorrelated => "position-free PT, correlated",
            Est::BdptUncorrelated => "position-free BDPT, uncorrelated",
            Est::BdptCorrelated => "position-free BDPT, correlated",
        }
    }

    /// The model this estimator converges to (single scattering is its own, different model;
    /// its error is measured against the walk's reference).
    pub fn model(self) -> Model {
        match self {
            Est::Single | Est::Compensated | Est::Walk => Model::Walk,
            Est::PtUncorrelated | Est::BdptUncorrelated => Model::Uncorrelated,
            Est::PtCorrelated | Est::BdptCorrelated => Model::Correlated,
        }
    }
}

impl Est {
    /// A deterministic model other than the walk (single scattering, the compensated lobe):
    /// its curve is a bias against the walk's reference at its cost, not a Monte Carlo error.
    pub fn is_biased(self) -> bool {
        matches!(self, Est::Single | Est::Compensated)
    }

    /// Whether the estimator exists for a material (the compensated lobe: conductors).
    pub fn applies_to(self, material: MaterialKind) -> bool {
        self != Est::Compensated || material == MaterialKind::Conductor
    }
}

/// The multiple-scattering models: the Heitz walk and the two position-free models.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Model {
    Walk,
    Uncorrelated,
    Correlated,
}

impl Model {
    pub const ALL: [Model; 3] = [Model::Walk, Model::Uncorrelated, Model::Correlated];

    pub fn name(self) -> &'static str {
        match self {
            Model::Walk => "heitz-walk",
            Model::Uncorrelated => "position-free-uncorr",
            Model::Correlated => "position-free-corr",
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Model::Walk => "Heitz walk",
            Model::Uncorrelated => "position-free, uncorrelated",
            Model::Correlated => "position-free, height-correlated",
        }
    }

    /// The estimator that computes this model's converged reference (its lowest-variance one).
    pub fn reference_estimator(self) -> Est {
        match self {
            Model::Walk => Est::Walk,
            Model::Uncorrelated => Est::BdptUncorrelated,
            Model::Correlated => Est::BdptCorrelated,
        }
    }
}

/// The configurations of the error study.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
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

    pub fn label(self) -> &'static str {
        match self {
            Config::ConductorGgx1 => "conductor (F = 1), GGX α = 1",
            Config::ConductorGgx01 => "conductor (F = 1), GGX α = 0.1",
            Config::DielectricGgx1 => "dielectric (η = 1.5), GGX α = 1",
            Config::DiffuseGgx1 => "diffuse (white), GGX α = 1",
            Config::ConductorBeckmann05 => "conductor (F = 1), Beckmann α = 0.5",
        }
    }

    pub fn surface(self) -> Surface {
        let (material, slope, alpha) = match self {
            Config::ConductorGgx1 => (MaterialKind::Conductor, SlopeKind::Ggx, 1.0),
            Config::ConductorGgx01 => (MaterialKind::Conductor, SlopeKind::Ggx, 0.1),
            Config::DielectricGgx1 => (MaterialKind::Dielectric, SlopeKind::Ggx, 1.0),
            Config::DiffuseGgx1 => (MaterialKind::Diffuse, SlopeKind::Ggx, 1.0),
            Config::ConductorBeckmann05 => (MaterialKind::Conductor, SlopeKind::Beckmann, 0.5),
        };
        Surface { material, slope, alpha }
    }
}

/// The incident angles (rad) of the error study, the energy table and the lobes.
pub const THETAS: [f64; 3] = [0.0, 1.0, 1.5];

/// An outgoing direction of the error study, relative to θi.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Outgoing {
    /// The mirror direction (θo = max(θi, 0.15), opposite azimuth).
    Mirror,
    /// The normal (a 0.6 rad tilt at normal incidence, where the normal is the mirror).
    Normal,
    /// θo = 1.2 at azimuth π/2 (reflecting configurations).
    Side,
    /// Through the macrosurface, θo = π − 0.6 max(θi, 0.3) (the dielectric).
    Transmission,
}

impl Outgoing {
    pub fn name(self) -> &'static str {
        match self {
            Outgoing::Mirror => "mirror",
            Outgoing::Normal => "normal",
            Outgoing::Side => "side",
            Outgoing::Transmission => "transmission",
        }
    }

    /// The three outgoing directions of a configuration.
    pub fn of(config: Config) -> [Outgoing; 3] {
        let third = if config == Config::DielectricGgx1 { Outgoing::Transmission } else { Outgoing::Side };
        [Outgoing::Mirror, Outgoing::Normal, third]
    }

    pub fn direction(self, theta_i: f64) -> Vec3 {
        use std::f64::consts::{FRAC_PI_2, PI};
        match self {
            Outgoing::Mirror => dir(theta_i.max(0.15), PI),
            Outgoing::Normal if theta_i == 0.0 => dir(0.6, 0.0),
            Outgoing::Normal => Vec3::Z,
            Outgoing::Side => dir(1.2, FRAC_PI_2),
            Outgoing::Transmission => dir(PI - 0.6 * theta_i.max(0.3), PI),
        }
    }
}

/// One (configuration, θi, ωo) of the error study; `theta` indexes `THETAS`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Case {
    pub config: Config,
    pub theta: usize,
    pub wo: Outgoing,
}

impl Case {
    pub fn theta_i(self) -> f64 {
        THETAS[self.theta]
    }

    pub fn wi(self) -> Vec3 {
        dir(self.theta_i(), 0.0)
    }

    pub fn wo_dir(self) -> Vec3 {
        self.wo.direction(self.theta_i())
    }

    /// Every case of a configuration, θi-major.
    pub fn all(config: Config) -> Vec<Case> {
        (0..THETAS.len())
            .flat_map(|theta| Outgoing::of(config).map(|wo| Case { config, theta, wo }))
            .collect()
    }
}

/// The materials of the energy table and the lobes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MaterialKind {
    Conductor,
    Dielectric,
    Diffuse,
}

impl MaterialKind {
    pub const ALL: [MaterialKind; 3] =
        [MaterialKind::Conductor, MaterialKind::Dielectric, MaterialKind::Diffuse];

    pub fn name(self) -> &'static str {
        match self {
            MaterialKind::Conductor => "conductor",
            MaterialKind::Dielectric => "dielectric",
            MaterialKind::Diffuse => "diffuse",
        }
    }
}

/// The slope distributions of the energy table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SlopeKind {
    Ggx,
    Beckmann,
}

impl SlopeKind {
    pub fn name(self) -> &'static str {
        match self {
            SlopeKind::Ggx => "ggx",
            SlopeKind::Beckmann => "beckmann",
        }
    }
}

/// A surface of the energy table: material, slope distribution and roughness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    pub material: MaterialKind,
    pub slope: SlopeKind,
    pub alpha: f32,
}

impl Surface {
    pub fn name(self) -> String {
        format!("{} {} a{:.1}", self.material.name(), self.slope.name(), self.alpha)
    }

    /// Every material × slope × α ∈ {0.1, 0.5, 1}.
    pub fn all() -> Vec<Surface> {
        let mut v = Vec::new();
        for material in MaterialKind::ALL {
            for slope in [SlopeKind::Ggx, SlopeKind::Beckmann] {
                for alpha in [0.1, 0.5, 1.0] {
                    v.push(Surface { material, slope, alpha });
                }
            }
        }
        v
    }
}

/// The materials of the lobe figures (GGX α = 1, the configurations of Wang et al. 2022, Fig. 6).
pub const LOBE_MATERIALS: [MaterialKind; 2] = [MaterialKind::Conductor, MaterialKind::Dielectric];

/// The three models behind the estimators, over one slope and material.
pub struct Models<S, M> {
    pub walk: Microsurface<UniformHeight, S, M>,
    pub uncorrelated: PositionFree<S, M>,
    pub correlated: PositionFree<S, M>,
    /// The compensated lobe of the renderer layer (conductors).
    pub compensated: Option<Box<dyn Bsdf>>,
}

impl<S: MicrosurfaceSlope, M: Material> Models<S, M> {
    pub fn new(slope: S, material: M) -> Self {
        Self {
            walk: Microsurface::new(UniformHeight, slope, material),
            uncorrelated: PositionFree::new(slope, material, Shadowing::Uncorrelated),
            correlated: PositionFree::new(slope, material, Shadowing::Correlated),
            compensated: None,
        }
    }

    /// The same models with a compensated lobe.
    pub fn with_compensated(self, lobe: Box<dyn Bsdf>) -> Self {
        Self { compensated: Some(lobe), ..self }
    }

    /// One estimate of f·|cos θo| (mean over RGB).
    #[inline]
    pub fn eval(&self, est: Est, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut Rng) -> f64 {
        let v = match est {
            Est::Single => self.walk.eval_single_scattering(wi, wo, rng),
            // the renderer layer's f(ωo = viewer, ωi = light) times |cos θo|
            Est::Compensated => {
                self.compensated.as_ref().map_or(Vec3::NAN, |b| b.eval(wo, wi).f * wo.z.abs())
            }
            Est::Walk => self.walk.eval(wi, wo, order, rng),
            Est::PtUncorrelated => self.uncorrelated.eval_pt(wi, wo, order, rng),
            Est::PtCorrelated => self.correlated.eval_pt(wi, wo, order, rng),
            Est::BdptUncorrelated => self.uncorrelated.eval_bdpt(wi, wo, order, rng),
            Est::BdptCorrelated => self.correlated.eval_bdpt(wi, wo, order, rng),
        };
        f64::from(v.element_sum()) / 3.0
    }

    /// One sampled scattering of a model.
    pub fn sample(&self, model: Model, wi: Vec3, rng: &mut Rng) -> Option<Scattered> {
        let s = match model {
            Model::Walk => self.walk.sample(wi, rng),
            Model::Uncorrelated => self.uncorrelated.sample(wi, rng),
            Model::Correlated => self.correlated.sample(wi, rng),
        }?;
        Some(Scattered {
            weight: f64::from(s.weight.element_sum()) / 3.0,
            reflected: s.wo.z > 0.0,
            bounces: s.bounces,
            wo: s.wo,
        })
    }
}

/// What `Models::sample` keeps of a sampled scattering.
#[derive(Debug, Clone, Copy)]
pub struct Scattered {
    /// The weight f·cos/pdf, mean over RGB.
    pub weight: f64,
    /// Whether ωo is above the macrosurface.
    pub reflected: bool,
    pub bounces: u32,
    /// The sampled direction.
    pub wo: Vec3,
}

/// The direction at polar angle θ and azimuth φ.
pub fn dir(theta: f64, phi: f64) -> Vec3 {
    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32)
}

/// A computation generic over the models of a surface (static dispatch through `with_surface`).
pub trait WithModels {
    type Out;
    fn go<S: MicrosurfaceSlope, M: Material>(self, models: Models<S, M>) -> Self::Out;
}

/// Runs `task` on the models of `surface`.
pub fn with_surface<T: WithModels>(surface: Surface, task: T) -> T::Out {
    fn on_material<S: AlbedoTabulated + 'static, T: WithModels>(
        slope: S,
        material: MaterialKind,
        task: T,
    ) -> T::Out {
        match material {
            MaterialKind::Conductor => {
                let c = Conductor::perfect();
                let lobe = microsurface::Compensated::new(slope, c).expect("α within the tables");
                task.go(Models::new(slope, c).with_compensated(Box::new(lobe)))
            }
            MaterialKind::Dielectric => task.go(Models::new(slope, Dielectric::new(1.5).expect("valid η"))),
            MaterialKind::Diffuse => task.go(Models::new(slope, Diffuse::white())),
        }
    }
    match surface.slope {
        SlopeKind::Ggx => {
            on_material(Ggx::isotropic(surface.alpha).expect("valid α"), surface.material, task)
        }
        SlopeKind::Beckmann => {
            on_material(Beckmann::isotropic(surface.alpha).expect("valid α"), surface.material, task)
        }
    }
}
