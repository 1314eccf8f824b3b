//! The 16³ node grids of the dielectric tables (single-scattering albedo and the walk's higher
//! orders): a pair of quantities (reflected, transmitted) for each side of the interface, η
//! slowest and the direction fastest, and their interpolation.

use super::axis::node_cell;

/// Nodes per axis of the dielectric tables: 16 × 16 × 16 per side of the interface.
pub const DIELECTRIC_TABLE_SIZE: usize = 16;

/// The largest relative index the dielectric tables cover; the smallest is its inverse.
pub const MAX_TABULATED_ETA: f32 = 3.0;

/// Which of a family's two dielectric tables: the one of relative indices η ≥ 1 (light
/// arriving from the side of the lower index, external incidence) or the one of η ≤ 1 (from
/// the side of the higher index, internal incidence, with total internal reflection beyond the
/// critical angle). For an interface of index η ≥ 1 (glass in air) light from
/// [`crate::research::Side::Outside`] reads [`EtaRange::AtLeastOne`] at η and light from
/// [`crate::research::Side::Inside`] reads [`EtaRange::AtMostOne`] at 1/η; [`EtaRange::of`] selects by
/// the relative index seen by the light.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EtaRange {
    /// Relative indices η ∈ [1, [`MAX_TABULATED_ETA`]].
    AtLeastOne,
    /// Relative indices η ∈ [1/[`MAX_TABULATED_ETA`], 1].
    AtMostOne,
}

impl EtaRange {
    /// The table of the relative index η seen by the light: [`EtaRange::AtLeastOne`] for
    /// η ≥ 1, [`EtaRange::AtMostOne`] otherwise (NaN included).
    #[must_use]
    #[inline]
    pub fn of(eta: f32) -> Self {
        if eta >= 1.0 { Self::AtLeastOne } else { Self::AtMostOne }
    }
}

/// Nodes per grid.
pub(crate) const NODES: usize = DIELECTRIC_TABLE_SIZE * DIELECTRIC_TABLE_SIZE * DIELECTRIC_TABLE_SIZE;
/// A row of the η axis: 16 × 16 nodes.
const ROW: usize = DIELECTRIC_TABLE_SIZE * DIELECTRIC_TABLE_SIZE;

/// One grid.
pub(crate) type Grid = [f32; NODES];

/// The grids of a dielectric table family: (reflected, transmitted) for light from outside
/// (relative indices η ≥ 1) and from inside (η ≤ 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SideGrids {
    pub(crate) outside: [&'static Grid; 2],
    pub(crate) inside: [&'static Grid; 2],
}

impl SideGrids {
    /// The grids of the relative index η seen by the light, and η folded to ≥ 1 (1/η from
    /// inside).
    #[inline(always)]
    pub(crate) fn of(&self, eta: f32) -> (&[&'static Grid; 2], f32) {
        if eta >= 1.0 { (&self.outside, eta) } else { (&self.inside, 1.0 / eta) }
    }

    /// The (reflected, transmitted) grids of one side.
    #[inline(always)]
    pub(crate) fn side(&self, range: EtaRange) -> [&'static Grid; 2] {
        match range {
            EtaRange::AtLeastOne => self.outside,
            EtaRange::AtMostOne => self.inside,
        }
    }

    /// The raw node values (reflected, transmitted) of one side.
    pub(crate) fn nodes(&self, range: EtaRange) -> (&'static [f32], &'static [f32]) {
        let [r, t] = self.side(range);
        (r, t)
    }

    /// Both quantities of the side of η, interpolated trilinearly at the fractional node
    /// coordinates (i, j, l) ∈ [0, 15]³ (direction, roughness, index).
    #[inline(always)]
    pub(crate) fn at(&self, eta: f32, at: [f32; 3]) -> (f32, f32) {
        let (grids, _) = self.of(eta);
        (trilinear(grids[0], at), trilinear(grids[1], at))
    }

    /// The node index of (i, j, l).
    #[inline(always)]
    pub(crate) fn index(i: usize, j: usize, l: usize) -> usize {
        l * ROW + j * DIELECTRIC_TABLE_SIZE + i
    }
}

/// Trilinear interpolation of a 16³ grid (η slowest, direction fastest) at fractional node
/// coordinates (i, j, l) ∈ [0, 15]³.
#[inline(always)]
fn trilinear(grid: &Grid, at: [f32; 3]) -> f32 {
    let (i, fi) = node_cell(at[0], DIELECTRIC_TABLE_SIZE);
    let (j, fj) = node_cell(at[1], DIELECTRIC_TABLE_SIZE);
    let (l, fl) = node_cell(at[2], DIELECTRIC_TABLE_SIZE);
    let bilinear = |base: usize| {
        let (a, b) = (grid[base], grid[base + 1]);
        let (c, d) = (grid[base + DIELECTRIC_TABLE_SIZE], grid[base + DIELECTRIC_TABLE_SIZE + 1]);
        let lower = a + fi * (b - a);
        let upper = c + fi * (d - c);
        lower + fj * (upper - lower)
    };
    let base = SideGrids::index(i, j, l);
    let near = bilinear(base);
    let far = bilinear(base + ROW);
    near + fl * (far - near)
}
