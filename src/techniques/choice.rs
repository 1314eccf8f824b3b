//! The chooser: the cheapest technique whose error against the exact walk stays within a
//! budget, per material, and the BSDF it names, per hit.

use super::error_model::Rated;
use crate::bsdf::{
    Bsdf, BsdfFlags, BsdfSample, BsdfValue, MAX_WALK_ALPHA, MicrofacetBsdf, SMOOTH_ALPHA, Technique,
    Transport,
};
use crate::compensation::{AlbedoTabulated, Compensated, CompensatedMaterial};
use crate::error::Error;
use crate::material::{Conductor, Dielectric};
use glam::{Vec2, Vec3};

/// The techniques the chooser picks from, cheapest first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ChosenTechnique {
    /// [`MicrofacetBsdf`] with [`Technique::SingleScattering`]: exact, deterministic, loses
    /// the energy of the higher orders.
    SingleScattering,
    /// The compensated lobe of the material, [`Compensated`] with its default scheme
    /// ([`Compensation::Walk`](crate::Compensation::Walk)); deterministic, restores the lost
    /// energy from the tables of the walk.
    Compensated,
    /// [`MicrofacetBsdf`] with [`Technique::RandomWalk`]: the exact model, stochastic.
    RandomWalk,
}

/// A technique chosen for a material and an albedo error budget, with its expected error and
/// cost: what [`Choice::new`] returns and [`Choice::build`] turns into a BSDF.
///
/// `error` is the hemispherical albedo error against the exact random walk, |Ā − Ā_walk| with
/// Ā = 2∫₀¹ A(μ) μ dμ over view directions, the largest RGB channel, for a dielectric R + T
/// (flux) on the worse side of the interface (see the [module's page](super)); it is an upper
/// bound of the model (single scattering's loss for F = 1 bounds every conductor's), up to the
/// tables' interpolation error and the measurement behind the compensated lobes' bound.
/// `cost` is the time per sample relative to single scattering, measured on the development
/// machine (ratios carry from one machine to another roughly).
///
/// # Examples
/// ```
/// use microsurface::techniques::{Choice, ChosenTechnique};
/// use microsurface::{Bsdf, ComplexIor, Conductor, Ggx};
///
/// let gold = Conductor::new(ComplexIor::GOLD);
/// // per material: smooth gold within 1 % of the walk's albedo needs no more than single scattering
/// let smooth = Choice::new(&Ggx::isotropic(0.05)?, &gold, 0.01)?;
/// assert_eq!(smooth.technique, ChosenTechnique::SingleScattering);
/// assert!(smooth.error <= 0.01 && smooth.cost == 1.0);
/// // rough gold loses more: a compensated lobe or the walk
/// let rough = Choice::new(&Ggx::isotropic(0.8)?, &gold, 0.01)?;
/// assert!(rough.technique > ChosenTechnique::SingleScattering && rough.error <= 0.01);
/// // per hit: the BSDF the choice names
/// let bsdf = rough.build(Ggx::isotropic(0.8)?, gold)?;
/// assert!(bsdf.flags().reflection);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Choice {
    /// The technique.
    pub technique: ChosenTechnique,
    /// Its expected error bound (hemispherical albedo, absolute).
    pub error: f32,
    /// Its time per sample relative to single scattering (1 for single scattering).
    pub cost: f32,
}

/// The errors and costs of every technique for one material and roughness, from which
/// [`Choice::new`] picks: for the report's decision map and the techniques page.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidates {
    /// Single scattering's error (`None`: no table covers the material and roughness).
    pub single: Option<f32>,
    /// The compensated lobe's error bound (`None`: no table, or an anisotropic slope).
    pub compensated: Option<f32>,
    /// The relative cost of the compensated lobe.
    pub compensated_cost: f32,
    /// The relative cost of the walk.
    pub walk_cost: f32,
}

impl Candidates {
    /// The errors and costs for a slope and a material (see [`Choice::new`] for the rules).
    ///
    /// # Errors
    /// As [`Choice::new`].
    pub fn new<S: AlbedoTabulated, M: Budgeted>(slope: &S, material: &M) -> Result<Self, Error> {
        let alpha_max = slope.alpha_max();
        if alpha_max > MAX_WALK_ALPHA {
            return Err(Error::InvalidParameter {
                name: "alpha",
                value: alpha_max,
                expected: "max(αx, αy) at most 10 (MAX_WALK_ALPHA)",
            });
        }
        let costs = M::COSTS;
        // a Dirac mirror (or refraction) loses nothing
        let single = if alpha_max < SMOOTH_ALPHA {
            Some(0.0)
        } else {
            // anisotropic surfaces: the isotropic surface of the largest roughness
            // (the loss grows with α)
            material.single_scattering_error::<S>(alpha_max)
        };
        let isotropic = slope.alpha_x() == slope.alpha_y();
        let compensated = match single {
            Some(_) if isotropic => material.compensated_error::<S>(),
            _ => None,
        };
        Ok(Self { single, compensated, compensated_cost: costs.compensated, walk_cost: costs.walk })
    }

    /// The cheapest technique whose error is at most `budget`.
    fn choose(&self, budget: f32) -> Choice {
        match (self.single, self.compensated) {
            (Some(e), _) if e <= budget => {
                Choice { technique: ChosenTechnique::SingleScattering, error: e, cost: 1.0 }
            }
            (_, Some(e)) if e <= budget => {
                Choice { technique: ChosenTechnique::Compensated, error: e, cost: self.compensated_cost }
            }
            _ => Choice { technique: ChosenTechnique::RandomWalk, error: 0.0, cost: self.walk_cost },
        }
    }
}

impl Choice {
    /// The cheapest technique for `material` on `slope` whose hemispherical albedo error
    /// against the exact walk is at most `budget` (0.01 for 1 %): single scattering where the
    /// energy it loses is within the budget, the compensated lobe where its stated bound is,
    /// the random walk (unbiased: error 0, noise instead) otherwise. Deterministic and cheap
    /// (a table lookup for conductors, 128 for dielectrics): call it per material, not per hit.
    ///
    /// * Single scattering's error: conductors 1 − Ē(α) of the slope family's
    ///   [`AlbedoTable`](crate::compensation::AlbedoTable) (the F = 1 loss, which bounds every
    ///   conductor's) plus the interpolation error of Ē (3 · 10⁻⁴); dielectrics 1 − Ā_ss of
    ///   the [`DielectricAlbedoTable`](crate::compensation::DielectricAlbedoTable) (the walk
    ///   conserves the flux, Ā_ss by a 64-point rule in μ²), the worse side, plus 2 % of
    ///   it for the table's interpolation (measured against the walk).
    /// * The compensated lobe's error: a bound per slope family and material class, measured
    ///   against the walk (the page [`techniques`](super) gives the figures).
    /// * Surfaces smoother than [`SMOOTH_ALPHA`] are Dirac lobes: single scattering, error 0.
    /// * Anisotropic slopes are rated as the isotropic surface of their largest roughness
    ///   (single scattering loses more as α grows), and never get the compensated lobe (it
    ///   compensates at √(αx αy) and restores about half of what is lost).
    /// * Beyond the tables (√(αx αy) > 1, dielectrics with η outside [1/3, 3]): the walk.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a `budget` that is NaN, infinite or negative
    /// (`"budget"`) and for max(αx, αy) > [`MAX_WALK_ALPHA`] (`"alpha"`), where even the walk is
    /// refused.
    pub fn new<S: AlbedoTabulated, M: Budgeted>(slope: &S, material: &M, budget: f32) -> Result<Self, Error> {
        let budget = Error::check_non_negative("budget", budget)?;
        Ok(Candidates::new(slope, material)?.choose(budget))
    }

    /// The BSDF of the chosen technique for `slope` and `material` (those of [`Choice::new`];
    /// with others the technique is kept, its error statement is not). Cheap: build it per hit.
    ///
    /// # Errors
    /// Those of [`MicrofacetBsdf::new`] and of the compensated lobe's constructor.
    pub fn build<S: AlbedoTabulated, M: Budgeted>(
        self,
        slope: S,
        material: M,
    ) -> Result<ChosenBsdf<S, M>, Error> {
        let microfacet = |technique| {
            Ok(ChosenBsdf::Microfacet(MicrofacetBsdf::new(slope, material)?.with_technique(technique)))
        };
        match self.technique {
            ChosenTechnique::SingleScattering => microfacet(Technique::SingleScattering),
            ChosenTechnique::RandomWalk => microfacet(Technique::RandomWalk),
            ChosenTechnique::Compensated => Ok(ChosenBsdf::Compensated(Compensated::new(slope, material)?)),
        }
    }
}

/// A material the chooser rates: conductors and dielectrics (diffuse facets have no
/// compensated lobe, and their single scattering is stochastic).
pub trait Budgeted: CompensatedMaterial + Copy + Rated {
    /// The compensated lobe as a [`Bsdf`] (it is one for every budgeted material).
    #[doc(hidden)]
    type Lobe<S: AlbedoTabulated>: Bsdf;
    /// The identity, seen as [`Self::Lobe`].
    #[doc(hidden)]
    fn lobe<S: AlbedoTabulated>(lobe: &Compensated<S, Self>) -> &Self::Lobe<S>;
}

impl Budgeted for Conductor {
    type Lobe<S: AlbedoTabulated> = Compensated<S, Conductor>;
    #[inline]
    fn lobe<S: AlbedoTabulated>(lobe: &Compensated<S, Self>) -> &Self::Lobe<S> {
        lobe
    }
}

impl Budgeted for Dielectric {
    type Lobe<S: AlbedoTabulated> = Compensated<S, Dielectric>;
    #[inline]
    fn lobe<S: AlbedoTabulated>(lobe: &Compensated<S, Self>) -> &Self::Lobe<S> {
        lobe
    }
}

/// The BSDF a [`Choice`] names: single scattering or the walk ([`MicrofacetBsdf`]), or the
/// material's compensated lobe. `Copy`, no allocation; implements [`Bsdf`] by forwarding.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ChosenBsdf<S: AlbedoTabulated, M: Budgeted> {
    /// Single scattering or the random walk.
    Microfacet(MicrofacetBsdf<S, M>),
    /// The compensated lobe.
    Compensated(Compensated<S, M>),
}

impl<S: AlbedoTabulated, M: Budgeted> ChosenBsdf<S, M> {
    /// The same BSDF with the given transport mode ([`Transport::Radiance`] by default;
    /// [`Transport::Importance`] for paths from the lights): matters to dielectrics only.
    #[must_use]
    pub fn with_transport(self, transport: Transport) -> Self {
        match self {
            Self::Microfacet(b) => Self::Microfacet(b.with_transport(transport)),
            Self::Compensated(b) => Self::Compensated(b.with_transport(transport)),
        }
    }
}

/// Forwards a call to the variant's BSDF.
macro_rules! forward {
    ($self:ident, $b:ident => $call:expr) => {
        match $self {
            ChosenBsdf::Microfacet($b) => $call,
            ChosenBsdf::Compensated(lobe) => {
                let $b = M::lobe(lobe);
                $call
            }
        }
    };
}

impl<S: AlbedoTabulated, M: Budgeted> Bsdf for ChosenBsdf<S, M> {
    fn flags(&self) -> BsdfFlags {
        forward!(self, b => b.flags())
    }
    fn eval_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> BsdfValue {
        forward!(self, b => b.eval_keyed(wo, wi, key))
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        forward!(self, b => b.pdf(wo, wi))
    }
    fn eval_with_pdf_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> (BsdfValue, f32) {
        forward!(self, b => b.eval_with_pdf_keyed(wo, wi, key))
    }
    fn sample_keyed(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample> {
        forward!(self, b => b.sample_keyed(wo, uc, u, key))
    }
}
