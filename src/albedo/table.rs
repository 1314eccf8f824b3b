//! The directional and average single-scattering albedo tables and their interpolation.

use super::generated::conductor as data;

/// Direction nodes of a roughness row of [`AlbedoTable`] (x = i/93).
pub const ALBEDO_DIRECTIONS: usize = 94;

/// Roughness rows of [`AlbedoTable`] (r = √α = j/62), and nodes of its E_avg.
pub const ALBEDO_ROUGHNESSES: usize = 63;

/// The largest roughness α the tables cover (their roughness axis is r = √α ∈ [0, 1]).
pub const MAX_TABULATED_ALPHA: f32 = 1.0;

/// The last direction node index, as a float.
const LAST_X: f32 = (ALBEDO_DIRECTIONS - 1) as f32;
/// The last roughness node index, as a float.
const LAST_R: f32 = (ALBEDO_ROUGHNESSES - 1) as f32;

/// The slope family of a table (which shared tables a compensated lobe reads).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Family {
    Ggx,
    Beckmann,
}

/// The single-scattering albedo of an isotropic microfacet conductor with F = 1 and
/// height-correlated Smith masking-shadowing, tabulated for one slope family:
///
/// E(μ, α) = ∫ D(ωh) G2(ωi, ωo) / (4 μ) dωo over the upper hemisphere, with μ = cos θi and
/// G2 = 1/(1 + Λ(ωi) + Λ(ωo)) (Heitz 2014; the first order of the random walk of Heitz et al.
/// 2016), and its cosine-weighted average E_avg(α) = 2 ∫₀¹ E(μ) μ dμ (Kulla and Conty 2017).
///
/// **Axes.** Roughness r = √α ∈ [0, 1] (as in Cycles' tables), 62 equal steps. The direction
/// axis is scale-invariant: node x ∈ [0, 1] holds μ = X α / (1 + α − X) with X = x², so that the
/// sharp feature of E at μ ≈ α (E(0) = 1: a grazing ray sees the top of the surface, from
/// which every reflection escapes, and E dips to ≈ 0.89 at μ ≈ α) is resolved at every α; the
/// row r = 0 holds the α → 0 limit of that profile (evaluated at α = 1e-6). A query (μ, α)
/// maps to x = √(μ (1 + α)/(μ + α)) and is interpolated bilinearly in (x, r), with 93 equal
/// steps of x ([`ALBEDO_DIRECTIONS`] × [`ALBEDO_ROUGHNESSES`] nodes).
///
/// **Accuracy** (measured by the generator, `tables --interpolation --only conductor`, see
/// `DESIGN.md`): every node is within 1e-6 of the exact integral (two quadrature resolutions
/// agree to that). Bilinear interpolation, measured against quadrature at every cell centre and
/// at the midpoint of every cell edge (where a bilinear interpolant is farthest from its
/// nodes), errs by at most 1.9e-4 for GGX (cell centres 1.86e-4, edge midpoints along x
/// 1.21e-4, along r 1.35e-4; RMS ≤ 3.9e-5) and 6.8e-4 for Beckmann (centres 5.87e-4, edges along
/// x 6.73e-4 at μ ≈ 0.97, α ≈ 0.50, along r 3.24e-4; RMS ≤ 6.5e-5). A uniform μ axis of 32
/// nodes errs by up to 7.4e-2.
///
/// # Examples
/// ```
/// use microsurface::compensation::AlbedoTable;
///
/// let e = AlbedoTable::GGX.directional(1.0, 1.0).expect("in range");
/// assert!((e - 0.3069).abs() < 1e-3); // GGX α = 1 at normal incidence
/// let e_avg = AlbedoTable::GGX.average(1.0).expect("in range");
/// assert!(e_avg > 0.0 && e_avg < 1.0);
/// assert_eq!(AlbedoTable::GGX.directional(0.5, 2.0), None); // α beyond the table
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlbedoTable {
    name: &'static str,
    family: Family,
    directional: &'static [f32; ALBEDO_DIRECTIONS * ALBEDO_ROUGHNESSES],
    average: &'static [f32; ALBEDO_ROUGHNESSES],
}

impl AlbedoTable {
    /// The GGX (Trowbridge–Reitz) tables.
    pub const GGX: AlbedoTable = AlbedoTable {
        name: "ggx",
        family: Family::Ggx,
        directional: &data::GGX_DIRECTIONAL,
        average: &data::GGX_AVERAGE,
    };

    /// The Beckmann tables.
    pub const BECKMANN: AlbedoTable = AlbedoTable {
        name: "beckmann",
        family: Family::Beckmann,
        directional: &data::BECKMANN_DIRECTIONAL,
        average: &data::BECKMANN_AVERAGE,
    };

    /// The slope family's name (`"ggx"`, `"beckmann"`).
    #[must_use]
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// E(μ, α), interpolated (see the type's documentation for the axes and the error).
    ///
    /// Returns `None` unless μ ∈ [0, 1] and α ∈ (0, [`MAX_TABULATED_ALPHA`]] (NaN included):
    /// beyond the table there is no value to give.
    #[must_use]
    #[inline]
    pub fn directional(&self, mu: f32, alpha: f32) -> Option<f32> {
        if !((0.0..=1.0).contains(&mu) && alpha > 0.0 && alpha <= MAX_TABULATED_ALPHA) {
            return None;
        }
        Some(self.row(alpha)?.directional(mu))
    }

    /// E_avg(α) = 2 ∫₀¹ E(μ, α) μ dμ, interpolated linearly in r = √α. Its nodes are exact to
    /// 1e-6; the interpolation errs by at most 7.4e-5 (GGX) and 5.9e-5 (Beckmann), measured at
    /// the midpoints between nodes.
    ///
    /// Returns `None` unless α ∈ (0, [`MAX_TABULATED_ALPHA`]].
    #[must_use]
    #[inline]
    pub fn average(&self, alpha: f32) -> Option<f32> {
        Some(self.row(alpha)?.average())
    }

    /// The table at one roughness α ∈ (0, [`MAX_TABULATED_ALPHA`]] (`None` outside, NaN
    /// included): √α and the direction axis formed once for any number of lookups.
    #[inline]
    pub(crate) fn row(&self, alpha: f32) -> Option<AlbedoRow> {
        if !(alpha > 0.0 && alpha <= MAX_TABULATED_ALPHA) {
            return None;
        }
        let (j, fj) = super::node_cell(alpha.sqrt() * LAST_R, ALBEDO_ROUGHNESSES);
        Some(AlbedoRow { table: *self, axis: super::DirectionAxis::new(alpha), j, fj })
    }

    /// The raw node values of E, row-major with the roughness index slowest
    /// (`values[j * ALBEDO_DIRECTIONS + i]` at x = i/93, r = j/62), for export to shaders.
    #[must_use]
    pub fn directional_nodes(&self) -> &'static [f32] {
        self.directional
    }

    /// The number of direction nodes of a roughness row.
    #[must_use]
    pub fn direction_nodes(&self) -> usize {
        ALBEDO_DIRECTIONS
    }

    /// The number of roughness rows.
    #[must_use]
    pub fn roughness_nodes(&self) -> usize {
        ALBEDO_ROUGHNESSES
    }

    /// The slope family.
    pub(crate) fn family(&self) -> Family {
        self.family
    }

    /// The raw node values of E_avg at r = j/62.
    #[must_use]
    pub fn average_nodes(&self) -> &'static [f32] {
        self.average
    }
}

/// An [`AlbedoTable`] at one roughness: E(μ) and E_avg interpolated in the roughness cell
/// (j, fj) of the r axis, on the direction axis of that α.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AlbedoRow {
    table: AlbedoTable,
    axis: super::DirectionAxis,
    j: usize,
    fj: f32,
}

impl AlbedoRow {
    /// E(μ) for μ ∈ [0, 1] (μ rounded above 1 reads x = 1), bilinear in (x, r).
    #[inline]
    pub(crate) fn directional(&self, mu: f32) -> f32 {
        let grid = self.table.directional;
        let (i0, fi) = super::node_cell(self.axis.coordinate(mu) * LAST_X, ALBEDO_DIRECTIONS);
        let row = self.j * ALBEDO_DIRECTIONS + i0;
        let (a, b) = (grid[row], grid[row + 1]);
        let (c, d) = (grid[row + ALBEDO_DIRECTIONS], grid[row + ALBEDO_DIRECTIONS + 1]);
        let lower = a + fi * (b - a);
        let upper = c + fi * (d - c);
        lower + self.fj * (upper - lower)
    }

    /// E_avg, linear in r.
    #[inline]
    pub(crate) fn average(&self) -> f32 {
        let (average, j) = (self.table.average, self.j);
        average[j] + self.fj * (average[j + 1] - average[j])
    }
}
