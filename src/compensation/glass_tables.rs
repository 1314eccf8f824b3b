//! What a compensated dielectric built per hit reads and does not recompute: per slope family,
//! built once (on first use) from the shipped walk tables ([`DielectricWalkTable`]) and
//! single-scattering dielectric tables ([`DielectricAlbedoTable`]).
//!
//! Per side of the walk tables (the relative index seen η ≥ 1 or η ≤ 1):
//! * at every (roughness, index) row of the tables: the samplers of the rows' profiles
//!   ΔR(μ) μ and ΔT(μ) μ at the row's α, their masses, and the sampling mixture's
//!   probabilities of single scattering, reflection and transmission per cell of the uniform μ
//!   axis;
//! * at [`SUBSTEPS`] sub-steps of every roughness cell of every index row: the averages
//!   2∫ · μ dμ of the interpolated ΔR and ΔT at that α (the lobes' normalizations, which depend
//!   on α through the direction axis) and the variance of the ΔT average from the nodes'
//!   standard errors (what splits the reciprocity residual between the sides);
//! * the single-scattering albedo E = R + T of the dielectric tables (Turquin's scheme).

use super::lobe_profile::{
    DirectionAxis, MU_CELLS, MuProfile, mu_cell_centre, mu_cell_masses, profile_average, row_at,
};
use super::shared::boxed;
use crate::albedo::{
    DIELECTRIC_TABLE_SIZE, DielectricAlbedoTable, DielectricWalkTable, EtaRange, Family, Grid, SideGrids,
    floor_index,
};
use glam::Vec4;
use std::sync::OnceLock;

/// Nodes per axis of the walk tables.
const N: usize = DIELECTRIC_TABLE_SIZE;
/// Sub-steps per roughness cell of the tabulated averages.
pub(crate) const SUBSTEPS: usize = 32;
/// The smallest share of the single-scattering lobe in the sampling mixture, relative to the
/// lobes' total: keeps its density positive wherever it scatters.
const MIN_SINGLE_SHARE: f32 = 1e-3;
/// The smallest α of the averages and profiles (α = 0 at r = 0 has only the smooth limit).
const ALPHA_FLOOR: f64 = 1e-9;

/// One row of a side's walk table: the samplers of its two profiles and the mixture.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Row {
    /// The samplers of ΔR(μ) μ and ΔT(μ) μ at the row's α.
    pub(crate) profiles: [MuProfile; 2],
    /// 2∫ΔR μ dμ and 2∫ΔT μ dμ of the row at its α.
    pub(crate) masses: [f32; 2],
    /// Per cell of the uniform μ axis: the probabilities (single scattering, reflection,
    /// transmission, 0) of a view at the cell's centre, E_ss : ΔR : ΔT with E_ss = 1 − ΔR − ΔT
    /// (the walk conserves energy) and at least [`MIN_SINGLE_SHARE`] of the total.
    pub(crate) mixture: [Vec4; MU_CELLS],
}

/// The shared tables of one side.
#[derive(Debug)]
pub(crate) struct GlassSide {
    /// The walk grids (ΔR, ΔT).
    pub(crate) walk: [&'static Grid; 2],
    /// E = R + T of the single-scattering tables.
    pub(crate) single: Box<Grid>,
    /// The rows, index (l·16 + j).
    pub(crate) rows: Box<[Row; N * N]>,
    /// [ΔR̄, ΔT̄, Var(ΔT̄), 0] at sub-step s of roughness cell j of index row l (index
    /// (l·15 + j)(SUBSTEPS + 1) + s).
    pub(crate) averages: Box<[Vec4; N * (N - 1) * (SUBSTEPS + 1)]>,
}

/// The shared tables of one slope family: the side of η ≥ 1 (0) and of η ≤ 1 (1).
#[derive(Debug)]
pub(crate) struct GlassTables {
    pub(crate) sides: [GlassSide; 2],
}

/// The α of the walk tables' roughness node j (r = √α = j/15).
fn node_alpha(j: usize) -> f64 {
    let r = j as f64 / (N - 1) as f64;
    r * r
}

impl GlassTables {
    /// The tables of a family, built on first use.
    #[inline]
    pub(crate) fn of(family: Family) -> &'static Self {
        static GGX: OnceLock<GlassTables> = OnceLock::new();
        static BECKMANN: OnceLock<GlassTables> = OnceLock::new();
        match family {
            Family::Ggx => {
                GGX.get_or_init(|| Self::build(&DielectricWalkTable::GGX, &DielectricAlbedoTable::GGX))
            }
            Family::Beckmann => BECKMANN.get_or_init(|| {
                Self::build(&DielectricWalkTable::BECKMANN, &DielectricAlbedoTable::BECKMANN)
            }),
        }
    }

    fn build(walk: &DielectricWalkTable, single: &DielectricAlbedoTable) -> Self {
        // the averages are linear in the nodes: their weights at each sub-step's α, from the
        // unit rows (shared by every index row and side)
        let weights: Vec<[f64; N]> = (0..(N - 1) * (SUBSTEPS + 1))
            .map(|n| {
                let (j, s) = (n / (SUBSTEPS + 1), n % (SUBSTEPS + 1));
                let r = (j as f64 + s as f64 / SUBSTEPS as f64) / (N - 1) as f64;
                let alpha = (r * r).max(ALPHA_FLOOR) as f32;
                core::array::from_fn(|i| {
                    let mut unit = [0.0f32; N];
                    unit[i] = 1.0;
                    profile_average(&unit, alpha)
                })
            })
            .collect();
        let sides = [EtaRange::AtLeastOne, EtaRange::AtMostOne].map(|range| {
            let grids = walk.grids(range);
            let [r, t] = single.grids(range);
            let row_of = |q: usize, j: usize, l: usize| -> [f32; N] {
                core::array::from_fn(|i| grids[q][SideGrids::index(i, j, l)])
            };
            let rows: Box<[Row; N * N]> = boxed(|n| {
                let (j, l) = (n % N, n / N);
                let alpha = node_alpha(j).max(ALPHA_FLOOR) as f32;
                let (dr, dt) = (row_of(0, j, l), row_of(1, j, l));
                let axis = DirectionAxis::<N>::new(alpha);
                Row {
                    profiles: [dr, dt].map(|g| MuProfile::new(&mu_cell_masses(&g, alpha))),
                    masses: [dr, dt].map(|g| profile_average(&g, alpha) as f32),
                    mixture: core::array::from_fn(|k| {
                        let cell = axis.cell(mu_cell_centre(k));
                        let (er, et) = (row_at(&dr, cell).max(0.0), row_at(&dt, cell).max(0.0));
                        let single = (1.0 - er - et).max(MIN_SINGLE_SHARE * (er + et));
                        let total = single + er + et;
                        if total > 0.0 {
                            let (p0, p1) = (single / total, er / total);
                            Vec4::new(p0, p1, (1.0 - p0 - p1).max(0.0), 0.0)
                        } else {
                            Vec4::new(1.0, 0.0, 0.0, 0.0)
                        }
                    }),
                }
            });
            let variance = |j: usize, l: usize, i: usize| {
                let k = SideGrids::index(i, j, l);
                walk.standard_errors(range, k).map_or(0.0, |(_, t)| f64::from(t) * f64::from(t))
            };
            let averages: Box<[Vec4; N * (N - 1) * (SUBSTEPS + 1)]> = boxed(|n| {
                let s = n % (SUBSTEPS + 1);
                let (j, l) = ((n / (SUBSTEPS + 1)) % (N - 1), n / ((SUBSTEPS + 1) * (N - 1)));
                let f = s as f64 / SUBSTEPS as f64;
                let w = &weights[j * (SUBSTEPS + 1) + s];
                let (mut dr, mut dt, mut var) = (0.0, 0.0, 0.0);
                for i in 0..N {
                    let at = |q: usize, jj: usize| f64::from(grids[q][SideGrids::index(i, jj, l)]);
                    dr += w[i] * (at(0, j) + f * (at(0, j + 1) - at(0, j)));
                    dt += w[i] * (at(1, j) + f * (at(1, j + 1) - at(1, j)));
                    var += w[i]
                        * w[i]
                        * ((1.0 - f) * (1.0 - f) * variance(j, l, i) + f * f * variance(j + 1, l, i));
                }
                Vec4::new(dr as f32, dt as f32, var as f32, 0.0)
            });
            let single: Box<Grid> = boxed(|k| r[k] + t[k]);
            GlassSide { walk: grids, single, rows, averages }
        });
        Self { sides }
    }
}

impl GlassSide {
    /// [ΔR̄, ΔT̄, Var(ΔT̄)] of index row l at the roughness cell (j, f), linear between the
    /// sub-steps.
    #[inline(always)]
    pub(crate) fn averages_at(&self, l: usize, (j, f): (usize, f32)) -> Vec4 {
        let t = f * SUBSTEPS as f32;
        let s = floor_index(t, SUBSTEPS - 1);
        let n = (l * (N - 1) + j) * (SUBSTEPS + 1) + s;
        self.averages[n].lerp(self.averages[n + 1], t - s as f32)
    }
}
