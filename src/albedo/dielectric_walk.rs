//! The random walk's higher-order energies of dielectric microsurfaces, split into reflection
//! and transmission, and their interpolation.

use super::axis::scale_invariant_direction;
use super::generated::dielectric_walk as data;
use super::grid::{DIELECTRIC_TABLE_SIZE, EtaRange, MAX_TABULATED_ETA, NODES, SideGrids};
use super::table::MAX_TABULATED_ALPHA;

/// Walks per batch of the generator: a cell's walk count is a multiple of it.
pub const WALK_BATCH: u32 = 4096;

/// The standard error every tabulated walk cell reaches (of ΔR and of ΔT).
pub const MAX_WALK_TABLE_SE: f32 = 2e-3;

/// The last node index, as a float.
const LAST: f32 = (DIELECTRIC_TABLE_SIZE - 1) as f32;

/// The η-axis coordinate u = √((η − 1)/2) ∈ [0, 1] of η ∈ [1, 3] (the single-scattering
/// dielectric tables' axis).
#[inline(always)]
fn eta_coordinate(eta_at_least_one: f32) -> f32 {
    ((eta_at_least_one - 1.0) * 0.5).max(0.0).sqrt().min(1.0)
}

/// The energy a dielectric microsurface scatters after two or more bounces, split by where it
/// leaves.
///
/// # Examples
/// ```
/// use microsurface::compensation::DielectricWalkTable;
///
/// // rough glass (α = 1, η = 1.5) seen from outside at normal incidence
/// let h = DielectricWalkTable::GGX.energy(1.0, 1.0, 1.5).expect("in range");
/// assert!(h.reflected >= 0.0 && h.transmitted > 0.0 && h.reflected + h.transmitted < 1.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HigherOrders {
    /// ΔR: the flux fraction leaving on the incident side after ≥ 2 bounces.
    pub reflected: f32,
    /// ΔT: the flux fraction leaving on the other side after ≥ 2 bounces.
    pub transmitted: f32,
}

/// The exact random walk's (Heitz et al. 2016, supplement §3.4) reflected and transmitted
/// energy of scattering orders ≥ 2, ΔR(μ, α, η) and ΔT(μ, α, η), of an isotropic dielectric
/// microsurface (the model of [`crate::Dielectric`], importance transport: the walk's flux),
/// for one slope family and both sides of the interface. The walk's order 1 is the
/// single-scattering model of [`crate::compensation::DielectricAlbedoTable`], and the walk conserves
/// energy, so R_ss + T_ss + ΔR + ΔT = 1 up to the tables' errors: the higher orders that a
/// compensated lobe ([`crate::Compensated`] with [`crate::Compensation::Walk`]) restores, with their split between the
/// two sides.
///
/// **Axes** (those of [`crate::compensation::DielectricAlbedoTable`]): relative index η ∈ [1, 3] seen from
/// outside and 1/η from inside, on u = √((η − 1)/2); roughness r = √α; direction
/// x = √(μ (1 + α)/(μ + α)); 16 equal steps each, η slowest, direction fastest, trilinear.
/// Rows without walks: r = 0 is the smooth limit (0), u = 0 the index-matched limit (ΔR = 0,
/// ΔT = 1 − T_ss by quadrature); the horizon node x = 0 is estimated at μ = 1e-7.
///
/// **Accuracy.** Each node is a mean of N indicator variables over walks (N a multiple of
/// [`WALK_BATCH`], as many batches as needed for a standard error √(p(1 − p)/N) ≤
/// [`MAX_WALK_TABLE_SE`] of both ΔR and ΔT; [`Self::standard_errors`] gives each node's).
/// Between the nodes the interpolation error adds (measured in `DESIGN.md`).
///
/// # Examples
/// ```
/// use microsurface::compensation::DielectricWalkTable;
///
/// // rough glass seen from air: the higher orders mostly transmit
/// let h = DielectricWalkTable::GGX.energy(0.5, 0.8, 1.5).expect("in range");
/// assert!(h.transmitted > h.reflected);
/// // from inside, total internal reflection keeps them in
/// let h = DielectricWalkTable::GGX.energy(0.5, 0.8, 1.0 / 1.5).expect("in range");
/// assert!(h.reflected > h.transmitted);
/// assert_eq!(DielectricWalkTable::GGX.energy(0.5, 0.8, 4.0), None); // beyond the table
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DielectricWalkTable {
    name: &'static str,
    grids: SideGrids,
    batches: [&'static [u8; NODES]; 2],
}

impl DielectricWalkTable {
    /// The GGX (Trowbridge–Reitz) tables.
    pub const GGX: DielectricWalkTable = DielectricWalkTable {
        name: "ggx",
        grids: SideGrids {
            outside: [&data::GGX_OUTSIDE_REFLECTED, &data::GGX_OUTSIDE_TRANSMITTED],
            inside: [&data::GGX_INSIDE_REFLECTED, &data::GGX_INSIDE_TRANSMITTED],
        },
        batches: [&data::GGX_OUTSIDE_BATCHES, &data::GGX_INSIDE_BATCHES],
    };

    /// The Beckmann tables.
    pub const BECKMANN: DielectricWalkTable = DielectricWalkTable {
        name: "beckmann",
        grids: SideGrids {
            outside: [&data::BECKMANN_OUTSIDE_REFLECTED, &data::BECKMANN_OUTSIDE_TRANSMITTED],
            inside: [&data::BECKMANN_INSIDE_REFLECTED, &data::BECKMANN_INSIDE_TRANSMITTED],
        },
        batches: [&data::BECKMANN_OUTSIDE_BATCHES, &data::BECKMANN_INSIDE_BATCHES],
    };

    /// The slope family's name (`"ggx"`, `"beckmann"`).
    #[must_use]
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// ΔR and ΔT at μ = |cos θi| ∈ [0, 1], α ∈ (0, 1] and the relative index η ∈ [1/3, 3]
    /// seen by the light (η_transmitted side / η_incident side), interpolated.
    ///
    /// Returns `None` outside those ranges (NaN included).
    #[must_use]
    #[inline]
    pub fn energy(&self, mu: f32, alpha: f32, eta: f32) -> Option<HigherOrders> {
        if !((0.0..=1.0).contains(&mu) && alpha > 0.0 && alpha <= MAX_TABULATED_ALPHA && in_eta_range(eta)) {
            return None;
        }
        let (_, eta_ge_1) = self.grids.of(eta);
        let x = scale_invariant_direction(mu, alpha);
        let at = [x * LAST, alpha.sqrt() * LAST, eta_coordinate(eta_ge_1) * LAST];
        let (reflected, transmitted) = self.grids.at(eta, at);
        Some(HigherOrders { reflected, transmitted })
    }

    /// The raw node values (ΔR, ΔT) of one side, `values[(l * 16 + j) * 16 + i]` at x = i/15,
    /// r = j/15, u = l/15 (η = 1 + 2u² from outside, its inverse from inside), for export to
    /// shaders.
    #[must_use]
    pub fn nodes(&self, range: EtaRange) -> (&'static [f32], &'static [f32]) {
        self.grids.nodes(range)
    }

    /// The number of walks behind node `k` of one side (0 for the limit rows, which are not
    /// estimated); `None` for k ≥ 4096.
    #[must_use]
    pub fn walks(&self, range: EtaRange, k: usize) -> Option<u32> {
        let b = self.batches[usize::from(range == EtaRange::AtMostOne)];
        b.get(k).map(|&n| u32::from(n) * WALK_BATCH)
    }

    /// The standard errors √(p(1 − p)/N) of node `k`'s ΔR and ΔT (0 for the limit rows);
    /// `None` for k ≥ 4096.
    #[must_use]
    pub fn standard_errors(&self, range: EtaRange, k: usize) -> Option<(f32, f32)> {
        let n = self.walks(range, k)?;
        let (r, t) = self.nodes(range);
        let se = |p: f32| if n == 0 { 0.0 } else { (p * (1.0 - p) / n as f32).max(0.0).sqrt() };
        Some((se(r[k]), se(t[k])))
    }
}

impl DielectricWalkTable {
    /// The fractional roughness node r·15 of α ∈ (0, 1] (r = √α).
    #[inline(always)]
    pub(crate) fn roughness_node(alpha: f32) -> f32 {
        alpha.sqrt() * LAST
    }

    /// The fractional index node u·15 of η ≥ 1.
    #[inline(always)]
    pub(crate) fn eta_node(eta_at_least_one: f32) -> f32 {
        eta_coordinate(eta_at_least_one) * LAST
    }

    /// The (reflected, transmitted) grids of one side.
    pub(crate) fn grids(&self, range: EtaRange) -> [&'static super::grid::Grid; 2] {
        self.grids.side(range)
    }

    /// The slope family.
    pub(crate) fn family(&self) -> super::Family {
        if self.name == "ggx" { super::Family::Ggx } else { super::Family::Beckmann }
    }
}

/// Whether η lies in [1/3, 3].
#[inline(always)]
fn in_eta_range(eta: f32) -> bool {
    (1.0 / MAX_TABULATED_ETA..=MAX_TABULATED_ETA).contains(&eta)
}
