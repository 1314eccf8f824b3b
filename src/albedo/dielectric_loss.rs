//! The energy single scattering loses at a dielectric interface, 1 − R − T, and its
//! interpolation.

use super::generated::dielectric_loss as data;
use super::grid::{EtaRange, MAX_TABULATED_ETA};
use super::table::MAX_TABULATED_ALPHA;

/// Nodes of the loss tables' direction, roughness and index axes: 24 × 24 × 32 per side of the
/// interface.
pub const LOSS_TABLE_SHAPE: [usize; 3] = [24, 24, 32];

/// Nodes per direction row.
const NX: usize = LOSS_TABLE_SHAPE[0];
/// Nodes per (roughness, direction) plane.
const PLANE: usize = LOSS_TABLE_SHAPE[0] * LOSS_TABLE_SHAPE[1];
/// Nodes per grid.
pub(crate) const LOSS_NODES: usize = LOSS_TABLE_SHAPE[0] * LOSS_TABLE_SHAPE[1] * LOSS_TABLE_SHAPE[2];

/// One grid of a loss table.
pub(crate) type LossGrid = [f32; LOSS_NODES];

/// The last direction and roughness node, and the last index node, as floats.
const LAST_X: f32 = (LOSS_TABLE_SHAPE[0] - 1) as f32;
const LAST_R: f32 = (LOSS_TABLE_SHAPE[1] - 1) as f32;
const LAST_U: f32 = (LOSS_TABLE_SHAPE[2] - 1) as f32;

/// The energy single scattering loses at a dielectric interface, D(μ, α, η) = 1 − R(μ) − T(μ)
/// with R and T the single-scattering albedos of [`crate::compensation::DielectricAlbedoTable`]
/// (the same model and quadrature, nodes within 1e-5), for one slope family and both sides of
/// the interface: the energy the random walk carries in its orders ≥ 2 (the walk conserves
/// energy, so D = ΔR + ΔT of [`crate::compensation::DielectricWalkTable`] up to that table's
/// noise), without noise and on axes of its own. It is the energy reference of the compensated
/// glass ([`crate::Compensated`] with [`crate::Compensation::Walk`]), whose white furnace is
/// exact up to this table's interpolation error.
///
/// **Axes** (trilinear in (x, r, u); `DESIGN.md`, "Compensated glass with the walk's split",
/// has the measurements behind them):
/// - index: the relative index seen by the light is η ∈ [1, 3] from outside and 1/η from
///   inside, on u = ∛((η − 1)/2) (η = 1 + 2u³), 32 equal steps;
/// - roughness: r = √α, 24 equal steps (the row r = 0 is evaluated at α = 1e-6);
/// - direction, from outside: the scale-invariant x = √(μ (1 + α)/(μ + α)) of the conductor
///   tables (the masking feature at μ ≈ α on the same node for every α), 24 equal steps;
/// - direction, from inside: x = ½ √(μ (1 + α)/(μ + α)) + ½ μ, which keeps half the
///   resolution of the scale-invariant axis at μ ≈ α and spreads the rest evenly in μ, where
///   total internal reflection sets in (at μc = √(1 − η²)) and a rough lobe's loss changes
///   across the whole range.
///
/// **Accuracy.** Nodes within 1e-5 of the quadrature's limit. Interpolation error against
/// direct quadrature (`cargo run --release -p tools --bin tables -- --interpolation --only
/// dielectric-loss`, 256 random points per family and side, μ ≥ 1e-3): at most 7.7e-3 (GGX,
/// outside), 7.2e-3 (GGX, inside), 1.1e-2 (Beckmann, outside) and 5.1e-2 (Beckmann, inside),
/// the worst within 0.003 of η = 1, where the loss changes fastest in η; RMS 1.1e-3 to 4.7e-3.
/// Closer to the horizon (μ < 1e-3) the first direction cell errs by up to 6.5e-2. On the
/// white-furnace grid of the compensated glass (η ≥ 1.05, μ ≥ 0.005) the error is at most
/// 3.3e-3 (GGX) and 6.7e-3 (Beckmann).
///
/// # Examples
/// ```
/// use microsurface::compensation::{DielectricAlbedoTable, DielectricLossTable};
///
/// // rough glass (α = 0.5, η = 1.5) seen from air at μ = 0.5
/// let d = DielectricLossTable::GGX.loss(0.5, 0.5, 1.5).expect("in range");
/// let ss = DielectricAlbedoTable::GGX.albedo(0.5, 0.5, 1.5).expect("in range");
/// assert!(d > 0.0 && (d - (1.0 - ss.reflected - ss.transmitted)).abs() < 0.02);
/// assert_eq!(DielectricLossTable::GGX.loss(0.5, 0.5, 4.0), None); // beyond the table
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DielectricLossTable {
    name: &'static str,
    /// The grids of light from outside (η ≥ 1) and from inside (η ≤ 1).
    grids: [&'static LossGrid; 2],
}

impl DielectricLossTable {
    /// The GGX (Trowbridge–Reitz) tables.
    pub const GGX: DielectricLossTable =
        DielectricLossTable { name: "ggx", grids: [&data::GGX_OUTSIDE, &data::GGX_INSIDE] };

    /// The Beckmann tables.
    pub const BECKMANN: DielectricLossTable =
        DielectricLossTable { name: "beckmann", grids: [&data::BECKMANN_OUTSIDE, &data::BECKMANN_INSIDE] };

    /// The slope family's name (`"ggx"`, `"beckmann"`).
    #[must_use]
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// 1 − R − T at μ = |cos θi| ∈ [0, 1], α ∈ (0, 1] and the relative index η ∈ [1/3, 3]
    /// seen by the light (η_transmitted side / η_incident side), interpolated.
    ///
    /// Returns `None` outside those ranges (NaN included).
    #[must_use]
    #[inline]
    pub fn loss(&self, mu: f32, alpha: f32, eta: f32) -> Option<f32> {
        if !((0.0..=1.0).contains(&mu)
            && alpha > 0.0
            && alpha <= MAX_TABULATED_ALPHA
            && (1.0 / MAX_TABULATED_ETA..=MAX_TABULATED_ETA).contains(&eta))
        {
            return None;
        }
        let side = usize::from(eta < 1.0);
        let eta_ge_1 = if side == 0 { eta } else { 1.0 / eta };
        let x = loss_direction(side, mu, mu * (1.0 + alpha) / (mu + alpha));
        let (i, fx) = super::node_cell(x * LAST_X, NX);
        let (j, fr) = super::node_cell(Self::roughness_node(alpha), LOSS_TABLE_SHAPE[1]);
        let (l, fu) = super::node_cell(Self::eta_node(eta_ge_1), LOSS_TABLE_SHAPE[2]);
        let grid = self.grids[side];
        let at = |k: usize| grid[k] + fx * (grid[k + 1] - grid[k]);
        let base = Self::index(i, j, l);
        let near = at(base) + fr * (at(base + NX) - at(base));
        let far = at(base + PLANE) + fr * (at(base + PLANE + NX) - at(base + PLANE));
        Some(near + fu * (far - near))
    }

    /// (μ, α, η ≥ 1) of node (i, j, l) on the axes above (i, j < 24, l < 32; η is the index
    /// axis' value, seen as 1/η by light from inside): α = r² (1e-6 at r = 0), η = 1 + 2u³,
    /// and μ the direction axis inverted (from outside in closed form, μ = X α/(1 + α − X);
    /// from inside by bisection in f64), μ = 0 at x = 0 and 1 at x = 1.
    ///
    /// # Panics
    /// If a node index is beyond its axis.
    #[must_use]
    pub fn node_parameters(i: usize, j: usize, l: usize, range: EtaRange) -> (f32, f32, f32) {
        let [nx, nr, nu] = LOSS_TABLE_SHAPE;
        assert!(i < nx && j < nr && l < nu, "loss node ({i}, {j}, {l}) beyond the {nx} × {nr} × {nu} grid");
        let (x, r, u) = (i as f64 / (nx - 1) as f64, j as f64 / (nr - 1) as f64, l as f64 / (nu - 1) as f64);
        let alpha = (r * r).max(1e-6);
        let scale_invariant = |x: f64| {
            let big_x = x * x;
            if big_x >= 1.0 { 1.0 } else { big_x * alpha / (1.0 + alpha - big_x) }
        };
        let mu = if range == EtaRange::AtLeastOne || i == 0 || i == nx - 1 {
            scale_invariant(x)
        } else {
            let x_of = |mu: f64| 0.5 * (mu * (1.0 + alpha) / (mu + alpha)).min(1.0).sqrt() + 0.5 * mu;
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..64 {
                let mid = 0.5 * (lo + hi);
                if x_of(mid) < x { lo = mid } else { hi = mid }
            }
            0.5 * (lo + hi)
        };
        (mu as f32, alpha as f32, (1.0 + 2.0 * u * u * u) as f32)
    }

    /// The raw node values of one side, `values[(l * 24 + j) * 24 + i]` at x = i/23, r = j/23,
    /// u = l/31 on the axes of the type's documentation, for export to shaders.
    #[must_use]
    pub fn nodes(&self, range: EtaRange) -> &'static [f32] {
        self.grid(range)
    }
}

impl DielectricLossTable {
    /// The grid of one side.
    pub(crate) fn grid(&self, range: EtaRange) -> &'static LossGrid {
        self.grids[usize::from(range == EtaRange::AtMostOne)]
    }

    /// The node index of (i, j, l).
    #[inline(always)]
    pub(crate) fn index(i: usize, j: usize, l: usize) -> usize {
        (l * LOSS_TABLE_SHAPE[1] + j) * NX + i
    }

    /// The fractional roughness node r·23 of α ∈ (0, 1].
    #[inline(always)]
    pub(crate) fn roughness_node(alpha: f32) -> f32 {
        alpha.sqrt().min(1.0) * LAST_R
    }

    /// The fractional index node u·31 of η ≥ 1.
    #[inline(always)]
    pub(crate) fn eta_node(eta_at_least_one: f32) -> f32 {
        ((eta_at_least_one - 1.0) * 0.5).max(0.0).cbrt().min(1.0) * LAST_U
    }
}

/// The direction coordinate x ∈ [0, 1] of μ on the loss table of `side` (0: η ≥ 1, 1: η ≤ 1),
/// from X = μ (1 + α)/(μ + α), the square of the scale-invariant coordinate.
#[inline(always)]
pub(crate) fn loss_direction(side: usize, mu: f32, big_x: f32) -> f32 {
    let x = big_x.min(1.0).sqrt();
    if side == 0 { x } else { 0.5 * x + 0.5 * mu.min(1.0) }
}
