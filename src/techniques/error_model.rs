//! What the chooser knows of each technique's error and cost: the error of single scattering
//! derived from the albedo tables, the error of the compensated lobes as a bound measured by
//! `lab --bin techniques`, and the relative costs measured by the same study.
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

/// The slope families with tables, as an index into the per-family constants below.
fn family<S: AlbedoTabulated>() -> usize {
    match S::ALBEDO.name() {
        "ggx" => 0,
        _ => 1,
    }
}

// The measured data, in one place. Source: `cargo run --release -p lab --bin techniques` (GGX
// and Beckmann, α ∈ {0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1}, F = 1, gold, copper, aluminium and
// glass of η ∈ {1.33, 1.5, 2} from both sides, 2¹⁸ views per technique and side), which prints
// the values below from its measurements (the largest over the grid plus three standard
// errors, rounded up to 10⁻³) and checks them in its `--quick` run.

/// The compensated conductor's error bound (per-order lobe; for F = 1 the Kulla–Conty lobe),
/// GGX and Beckmann: what the lobe misses of the coloured metals' higher orders (the
/// per-bounce Fresnel term taken as its average) and the tables' interpolation.
pub(crate) const COMPENSATED_CONDUCTOR: [f32; 2] = [0.007, 0.008];
/// The compensated dielectric's error bound (the walk's higher orders as separable lobes),
/// GGX and Beckmann.
pub(crate) const COMPENSATED_DIELECTRIC: [f32; 2] = [0.006, 0.005];
/// The relative margin of a dielectric's single-scattering error for the interpolation of its
/// tables (whose pointwise errors reach 10⁻¹ near η = 1 and largely cancel in the
/// hemispherical mean): the walk's loss measured over the grid, plus three standard errors, is
/// at most 1.014 (GGX) and 1.019 (Beckmann) times 1 − Ā_ss of the tables.
const DIELECTRIC_SINGLE_MARGIN: f32 = 0.02;
/// The margin of a conductor's single-scattering error: the interpolation error of the
/// average albedo table Ē(α) (at most 7.4e-5 for GGX and 5.9e-5 for Beckmann, measured by
/// the generator, see [`AlbedoTable::average`]).
const CONDUCTOR_SINGLE_MARGIN: f32 = 7.4e-5;

/// Time per bounce of a path tracer with next-event estimation (one `sample`, one
/// `eval_with_pdf` towards a light) relative to single scattering, measured by
/// `lab --bin techniques` (through `dyn Bsdf`, GGX α = 0.5, gold and glass of η = 1.5, the
/// median over chunks, one thread at a load of 4–5 on two cores; two runs back to back differed
/// by up to 25 %: the order is what carries, single < compensated < walk).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Costs {
    /// The compensated lobe.
    pub(crate) compensated: f32,
    /// The random walk.
    pub(crate) walk: f32,
}

/// The conductors' relative costs.
pub(crate) const CONDUCTOR_COSTS: Costs = Costs { compensated: 1.48, walk: 2.11 };
/// The dielectrics' relative costs.
pub(crate) const DIELECTRIC_COSTS: Costs = Costs { compensated: 1.17, walk: 1.32 };

/// ε of single scattering on a conductor: the F = 1 loss 1 − Ē(α), a bound for every conductor
/// (the walk's paths do not depend on F and each bounce multiplies a path's weight by F ≤ 1,
/// so the energy of the higher orders is at most its F = 1 value). `None` beyond the tables.
pub(crate) fn conductor_single(table: &AlbedoTable, alpha: f32) -> Option<f32> {
    table.average(alpha).map(|e| (1.0 - e).max(0.0) + CONDUCTOR_SINGLE_MARGIN)
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
    Some(side(eta)?.max(side(1.0 / eta)?) * (1.0 + DIELECTRIC_SINGLE_MARGIN))
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
    /// The compensated lobe's error bound on the slope family `S`; `None` where there is no
    /// lobe.
    fn compensated_error<S: AlbedoTabulated>(&self) -> Option<f32>;
}

impl Rated for Conductor {
    const COSTS: Costs = CONDUCTOR_COSTS;
    fn single_scattering_error<S: AlbedoTabulated>(&self, alpha: f32) -> Option<f32> {
        conductor_single(&S::ALBEDO, alpha)
    }
    fn compensated_error<S: AlbedoTabulated>(&self) -> Option<f32> {
        Some(COMPENSATED_CONDUCTOR[family::<S>()])
    }
}

impl Rated for Dielectric {
    const COSTS: Costs = DIELECTRIC_COSTS;
    fn single_scattering_error<S: AlbedoTabulated>(&self, alpha: f32) -> Option<f32> {
        let eta = self.eta();
        dielectric_single(&S::DIELECTRIC_ALBEDO, alpha, if eta >= 1.0 { eta } else { 1.0 / eta })
    }
    fn compensated_error<S: AlbedoTabulated>(&self) -> Option<f32> {
        Some(COMPENSATED_DIELECTRIC[family::<S>()])
    }
}
