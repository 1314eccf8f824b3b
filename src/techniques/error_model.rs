//! What the chooser knows of each technique's error and cost: the error of single scattering
//! derived from the albedo tables, the error of the compensated lobes as a stated bound
//! measured by `lab --bin techniques`, and the relative costs measured by the same study.
//!
//! **Error** (one definition everywhere): the hemispherical albedo error against the exact
//! random walk, ε = |Ā − Ā_walk| with Ā = 2∫₀¹ A(μ) μ dμ the cosine-weighted mean over view
//! directions of the directional albedo A(μ) (the energy a white furnace under uniform light
//! sees), the largest RGB channel; for a dielectric A = R + T (flux, no η² factor), the larger
//! of the two sides of the interface.

use crate::albedo::{AlbedoTable, DielectricAlbedoTable, MAX_TABULATED_ALPHA, MAX_TABULATED_ETA};
use crate::compensation::AlbedoTabulated;
use crate::material::{Conductor, Dielectric};

/// Nodes of the midpoint rule in u = μ² for a dielectric's hemispherical albedo
/// Ā = ∫₀¹ A(√u) du.
const DIELECTRIC_NODES: usize = 64;

/// The stated bound of a compensated lobe's error: ε_comp ≤ `residual` · ε_ss + `floor`, with
/// ε_ss the single-scattering error the chooser derives for the same material and roughness
/// (the part of the lost energy the lobe fails to restore, and the tables' interpolation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompensatedBound {
    /// The largest unrestored fraction of the single-scattering loss.
    pub(crate) residual: f32,
    /// The error that remains where nothing is lost.
    pub(crate) floor: f32,
}

impl CompensatedBound {
    /// The bound at a single-scattering error `single`.
    pub(crate) fn at(self, single: f32) -> f32 {
        self.residual * single + self.floor
    }
}

// The compensated lobes' bounds, in one place. Source: `cargo run --release -p lab --bin
// techniques` (GGX and Beckmann, α ∈ {0.05, …, 1}, F = 1, gold, copper, aluminium and glass of
// η ∈ {1.33, 1.5, 2} from both sides): the largest measured ε_comp − floor over ε_ss, plus
// three standard errors, rounded up.

/// The compensated conductor (per-order lobe; for F = 1 the Kulla–Conty lobe).
pub(crate) const COMPENSATED_CONDUCTOR: CompensatedBound = CompensatedBound { residual: 0.0, floor: 0.0 };
/// The compensated dielectric (the walk's higher orders as separable lobes).
pub(crate) const COMPENSATED_DIELECTRIC: CompensatedBound = CompensatedBound { residual: 0.0, floor: 0.0 };

/// Time per sample relative to single scattering, per technique, measured by
/// `lab --bin techniques` (`sample` through `dyn Bsdf`, GGX α = 0.5, the median over chunks).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Costs {
    /// The compensated lobe.
    pub(crate) compensated: f32,
    /// The random walk.
    pub(crate) walk: f32,
}

/// The conductors' relative costs.
pub(crate) const CONDUCTOR_COSTS: Costs = Costs { compensated: 1.0, walk: 1.0 };
/// The dielectrics' relative costs.
pub(crate) const DIELECTRIC_COSTS: Costs = Costs { compensated: 1.0, walk: 1.0 };

/// ε of single scattering on a conductor: the F = 1 loss 1 − Ē(α), a bound for every conductor
/// (the walk's paths do not depend on F and each bounce multiplies a path's weight by F ≤ 1,
/// so the energy of the higher orders is at most its F = 1 value). `None` beyond the tables.
pub(crate) fn conductor_single(table: &AlbedoTable, alpha: f32) -> Option<f32> {
    table.average(alpha).map(|e| (1.0 - e).max(0.0))
}

/// ε of single scattering on a dielectric of index η: the walk conserves the flux (Ā_walk = 1
/// on both sides), so ε = 1 − Ā_ss with Ā_ss the hemispherical R + T of the table, the larger
/// of the two sides (η from outside, 1/η from inside). `None` beyond the tables.
pub(crate) fn dielectric_single(table: &DielectricAlbedoTable, alpha: f32, eta: f32) -> Option<f32> {
    if !(alpha > 0.0 && alpha <= MAX_TABULATED_ALPHA && (1.0..=MAX_TABULATED_ETA).contains(&eta)) {
        return None;
    }
    let side = |eta: f32| -> Option<f32> {
        let mut sum = 0.0f64;
        for k in 0..DIELECTRIC_NODES {
            let mu = ((k as f32 + 0.5) / DIELECTRIC_NODES as f32).sqrt();
            let a = table.albedo(mu, alpha, eta)?;
            sum += f64::from(a.reflected + a.transmitted);
        }
        Some((1.0 - sum / DIELECTRIC_NODES as f64).max(0.0) as f32)
    };
    Some(side(eta)?.max(side(1.0 / eta)?))
}

/// What the chooser knows of a material: the private supertrait of
/// [`Budgeted`](super::Budgeted) (public in a private module, so no other crate can name or
/// implement it).
pub trait Rated {
    /// The relative costs.
    const COSTS: Costs;
    /// Single scattering's error at isotropic roughness α on the slope family `S`; `None`
    /// beyond the tables.
    fn single_scattering_error<S: AlbedoTabulated>(&self, alpha: f32) -> Option<f32>;
    /// The compensated lobe's bound; `None` where there is no lobe.
    fn compensated_bound(&self) -> Option<CompensatedBound>;
}

impl Rated for Conductor {
    const COSTS: Costs = CONDUCTOR_COSTS;
    fn single_scattering_error<S: AlbedoTabulated>(&self, alpha: f32) -> Option<f32> {
        conductor_single(&S::ALBEDO, alpha)
    }
    fn compensated_bound(&self) -> Option<CompensatedBound> {
        Some(COMPENSATED_CONDUCTOR)
    }
}

impl Rated for Dielectric {
    const COSTS: Costs = DIELECTRIC_COSTS;
    fn single_scattering_error<S: AlbedoTabulated>(&self, alpha: f32) -> Option<f32> {
        let eta = self.eta();
        dielectric_single(&S::DIELECTRIC_ALBEDO, alpha, if eta >= 1.0 { eta } else { 1.0 / eta })
    }
    fn compensated_bound(&self) -> Option<CompensatedBound> {
        Some(COMPENSATED_DIELECTRIC)
    }
}
