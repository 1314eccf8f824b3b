//! The per-order multiple-scattering energies of the F = 1 conductor, tabulated from the
//! exact random walk, and their interpolation.

use super::MAX_TABULATED_ALPHA;
use super::generated::orders as orders_data;

/// Nodes per axis of the per-order tables: 32 × 32 for e_k(μ, α), 32 for e_k,avg(α).
pub const ORDER_TABLE_SIZE: usize = 32;

/// The last scattering order with a table of its own: orders 2 … 6 are tabulated one by one,
/// the orders above 6 together (the tail).
pub const LAST_TABULATED_ORDER: usize = 6;

/// The number of tables per slope family: orders 2 … [`LAST_TABULATED_ORDER`] and the tail.
pub const ORDER_TABLES: usize = LAST_TABULATED_ORDER;

/// The largest standard error of a node of the per-order tables (every node, directional and
/// average, is the mean of 2¹⁶ walks: √(e (1 − e)/2¹⁶) ≤ 1.95e-3).
pub const ORDER_TABLE_MAX_STANDARD_ERROR: f32 = 1.96e-3;

/// The last node index, as a float.
const LAST: f32 = (ORDER_TABLE_SIZE - 1) as f32;

/// Which scattering orders a per-order table holds.
///
/// # Examples
/// ```
/// use microsurface::compensation::{ScatteringOrderTable, TabulatedOrder};
///
/// assert_eq!(TabulatedOrder::Exactly(2).index(), Some(0));
/// assert_eq!(TabulatedOrder::Exactly(1).index(), None); // single scattering: `AlbedoTable`
/// // a rough F = 1 conductor seen at normal incidence: the second order carries most of the rest
/// let t = ScatteringOrderTable::GGX;
/// let (e2, tail) = (t.directional(TabulatedOrder::Exactly(2), 1.0, 1.0), t.directional(TabulatedOrder::Tail, 1.0, 1.0));
/// assert!(e2.unwrap() > tail.unwrap());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TabulatedOrder {
    /// Exactly k bounces, 2 ≤ k ≤ [`LAST_TABULATED_ORDER`].
    Exactly(usize),
    /// More than [`LAST_TABULATED_ORDER`] bounces.
    Tail,
}

impl TabulatedOrder {
    /// The index of the order's table (0 for order 2, the tail last); `None` for an order
    /// without a table of its own (k < 2 or k > [`LAST_TABULATED_ORDER`]).
    #[must_use]
    pub fn index(self) -> Option<usize> {
        match self {
            Self::Exactly(k) => (2..=LAST_TABULATED_ORDER).contains(&k).then(|| k - 2),
            Self::Tail => Some(ORDER_TABLES - 1),
        }
    }
}

/// The energy per scattering order of an isotropic microfacet conductor with F = 1, from the
/// exact random walk of Heitz et al. 2016 (the walk's height-correlated multiple scattering),
/// tabulated for one slope family:
///
/// e_k(μ, α) = the probability that a walk entering at cos θ = μ leaves after exactly k
/// bounces (k = 2 … [`LAST_TABULATED_ORDER`], and the tail of all k above), and its
/// cosine-weighted average e_k,avg(α) = 2 ∫₀¹ e_k(μ, α) μ dμ.
///
/// With F = 1, E(μ) + Σ_k e_k(μ) = 1 (E the single-scattering albedo of [`super::AlbedoTable`]):
/// the tables split the energy single scattering loses by order, which a coloured conductor
/// needs, since each further bounce multiplies it by a Fresnel term (Kulla and Conty 2017;
/// Hill's suggestion of E_F ≈ E_ss,F + Σ_k e_k F̄^k per RGB channel).
///
/// **Axes** those of [`super::AlbedoTable`] at a third of its direction resolution and half
/// its roughness resolution (every node here is a node there): r = √α in 31 equal steps (row 0
/// at α = 1e-6), direction node x = i/31 at μ = X α/(1 + α − X), X = x²; bilinear in (x, r).
/// Column x = 0 (μ = 0) is 0: a grazing ray sees only the top of the surface and leaves after
/// one bounce.
///
/// **Accuracy.** Every node is the mean of 2¹⁶ walks of its own seeded generator: standard
/// error √(e (1 − e)/2¹⁶) ≤ [`ORDER_TABLE_MAX_STANDARD_ERROR`] per node (and per average
/// node); the nodes of a cell are independent. Generated (bit for bit reproducibly) by
/// `cargo run --release -p tools --bin tables -- --only orders`.
///
/// # Examples
/// ```
/// use microsurface::compensation::{AlbedoTable, ScatteringOrderTable, TabulatedOrder};
///
/// let (mu, alpha) = (1.0, 1.0);
/// let single = AlbedoTable::GGX.directional(mu, alpha).expect("in range");
/// let higher: f32 = (2..=6)
///     .map(TabulatedOrder::Exactly)
///     .chain([TabulatedOrder::Tail])
///     .map(|k| ScatteringOrderTable::GGX.directional(k, mu, alpha).expect("in range"))
///     .sum();
/// assert!((single + higher - 1.0).abs() < 1e-2); // F = 1 conserves energy
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScatteringOrderTable {
    name: &'static str,
    directional: &'static [[f32; ORDER_TABLE_SIZE * ORDER_TABLE_SIZE]; ORDER_TABLES],
    average: &'static [[f32; ORDER_TABLE_SIZE]; ORDER_TABLES],
}

impl ScatteringOrderTable {
    /// The GGX (Trowbridge–Reitz) tables.
    pub const GGX: ScatteringOrderTable = ScatteringOrderTable {
        name: "ggx",
        directional: &orders_data::GGX_ORDERS,
        average: &orders_data::GGX_ORDERS_AVERAGE,
    };

    /// The Beckmann tables.
    pub const BECKMANN: ScatteringOrderTable = ScatteringOrderTable {
        name: "beckmann",
        directional: &orders_data::BECKMANN_ORDERS,
        average: &orders_data::BECKMANN_ORDERS_AVERAGE,
    };

    /// The slope family's name (`"ggx"`, `"beckmann"`).
    #[must_use]
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// e_k(μ, α), interpolated bilinearly in (x, r).
    ///
    /// Returns `None` for an order without a table ([`TabulatedOrder::index`]) and unless
    /// μ ∈ [0, 1] and α ∈ (0, [`MAX_TABULATED_ALPHA`]] (NaN included).
    #[must_use]
    pub fn directional(&self, order: TabulatedOrder, mu: f32, alpha: f32) -> Option<f32> {
        let t = order.index()?;
        if !((0.0..=1.0).contains(&mu) && alpha > 0.0 && alpha <= MAX_TABULATED_ALPHA) {
            return None;
        }
        let x = super::scale_invariant_direction(mu, alpha) * LAST;
        let (i, fi) = super::node_cell(x, ORDER_TABLE_SIZE);
        let (j, fj) = super::node_cell(alpha.sqrt() * LAST, ORDER_TABLE_SIZE);
        let g = &self.directional[t];
        let row = j * ORDER_TABLE_SIZE + i;
        let lower = g[row] + fi * (g[row + 1] - g[row]);
        let upper =
            g[row + ORDER_TABLE_SIZE] + fi * (g[row + ORDER_TABLE_SIZE + 1] - g[row + ORDER_TABLE_SIZE]);
        Some(lower + fj * (upper - lower))
    }

    /// e_k,avg(α) = 2 ∫₀¹ e_k(μ, α) μ dμ, interpolated linearly in r = √α.
    ///
    /// Returns `None` for an order without a table and unless α ∈ (0, [`MAX_TABULATED_ALPHA`]].
    #[must_use]
    pub fn average(&self, order: TabulatedOrder, alpha: f32) -> Option<f32> {
        let t = order.index()?;
        if !(alpha > 0.0 && alpha <= MAX_TABULATED_ALPHA) {
            return None;
        }
        let (j, f) = super::node_cell(alpha.sqrt() * LAST, ORDER_TABLE_SIZE);
        let a = &self.average[t];
        Some(a[j] + f * (a[j + 1] - a[j]))
    }

    /// The raw nodes of table `t` (0 for order 2 … [`ORDER_TABLES`] − 1 for the tail),
    /// row-major with the roughness index slowest (`values[j * 32 + i]` at x = i/31, r = j/31).
    ///
    /// # Panics
    /// If t ≥ [`ORDER_TABLES`].
    #[must_use]
    pub fn directional_nodes(&self, t: usize) -> &'static [f32] {
        &self.directional[t]
    }

    /// The raw average nodes of table `t` at r = j/31.
    ///
    /// # Panics
    /// If t ≥ [`ORDER_TABLES`].
    #[must_use]
    pub fn average_nodes(&self, t: usize) -> &'static [f32] {
        &self.average[t]
    }
}
