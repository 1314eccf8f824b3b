//! What a compensated dielectric built per hit reads and does not recompute: per slope family,
//! built once (on first use) from the shipped walk tables ([`DielectricWalkTable`]), loss
//! tables ([`DielectricLossTable`]) and single-scattering dielectric tables
//! ([`DielectricAlbedoTable`]).
//!
//! Per side of the tables (the relative index seen η ≥ 1 or η ≤ 1):
//! * on the loss table's grid: the added lobes' node values (D, ΔT'), D = 1 − R_ss − T_ss of
//!   the loss table and ΔT' = min(ΔT, D), the walk's ΔT interpolated at the node and capped by
//!   the loss (so that D − c ΔT' ≥ 0 at every node for any c ≤ 1), and at [`SUBSTEPS`] sub-steps
//!   of every roughness cell of every index row their averages 2∫ · μ dμ at that α (the lobes'
//!   normalizations, which depend on α through the direction axis);
//! * at every (roughness, index) row of the walk tables: the samplers of the light profiles
//!   (D − ΔT' + κ D)(μ) μ for the reflection lobe (the share κ of the loss bounds the ratio of
//!   the hit's g_R to it) and ΔT'(μ) μ for the transmission lobe, at the row's nodes and α, and
//!   their masses;
//! * the single-scattering albedo E = R + T of the dielectric tables (Turquin's scheme).

use super::lobe_profile::{MuProfile, mixed_axis_weights, mu_cell_masses, profile_average};
use super::shared::boxed;
use crate::albedo::{
    DIELECTRIC_TABLE_SIZE, DielectricAlbedoTable, DielectricLossTable, DielectricWalkTable, EtaRange, Family,
    Grid, LOSS_NODES, LOSS_TABLE_SHAPE, SideGrids, floor_index,
};
use glam::Vec2;
use std::sync::OnceLock;

/// Nodes per axis of the walk tables.
const N: usize = DIELECTRIC_TABLE_SIZE;
/// Nodes of the loss tables' direction, roughness and index axes.
const NX: usize = LOSS_TABLE_SHAPE[0];
const NR: usize = LOSS_TABLE_SHAPE[1];
const NU: usize = LOSS_TABLE_SHAPE[2];
/// Averages per side: (SUBSTEPS + 1) per roughness cell of every index row.
const AVERAGES: usize = NU * (NR - 1) * (SUBSTEPS + 1);
/// Sub-steps per roughness cell of the tabulated averages.
pub(crate) const SUBSTEPS: usize = 32;
/// The share κ of the loss D in the reflection lobe's sampled profile D − ΔT' + κ D.
const REFLECTION_LOSS_SHARE: f32 = 0.1;
/// The smallest α of the averages and profiles (α = 0 at r = 0 has only the smooth limit).
const ALPHA_FLOOR: f64 = 1e-9;

/// One row of a side's walk table: the samplers of its two profiles and the mixture.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Row {
    /// The samplers of the reflection and transmission lobes' light profiles,
    /// (D − ΔT' + κ D)(μ) μ and ΔT'(μ) μ, at the row's α.
    pub(crate) profiles: [MuProfile; 2],
    /// The profiles' masses 2∫ · μ dμ at the row's α.
    pub(crate) masses: [f32; 2],
}

/// The shared tables of one side.
#[derive(Debug)]
pub(crate) struct GlassSide {
    /// The added lobes' node values (D, ΔT') on the loss table's grid, index (l·24 + j)·24 + i.
    pub(crate) lobes: Box<[Vec2; LOSS_NODES]>,
    /// [D̄, ΔT̄'] at sub-step s of roughness cell j of index row l of the loss grid (index
    /// (l·23 + j)(SUBSTEPS + 1) + s).
    pub(crate) averages: Box<[Vec2; AVERAGES]>,
    /// E = R + T of the single-scattering tables.
    pub(crate) single: Box<Grid>,
    /// The walk tables' rows, index (l·16 + j).
    pub(crate) rows: Box<[Row; N * N]>,
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
            Family::Ggx => GGX.get_or_init(|| {
                Self::build(&DielectricWalkTable::GGX, &DielectricLossTable::GGX, &DielectricAlbedoTable::GGX)
            }),
            Family::Beckmann => BECKMANN.get_or_init(|| {
                Self::build(
                    &DielectricWalkTable::BECKMANN,
                    &DielectricLossTable::BECKMANN,
                    &DielectricAlbedoTable::BECKMANN,
                )
            }),
        }
    }

    fn build(walk: &DielectricWalkTable, loss: &DielectricLossTable, single: &DielectricAlbedoTable) -> Self {
        // the averages are linear in the nodes: their weights at each sub-step's α, per
        // direction axis (shared by every index row)
        let weights = |side: usize| -> Vec<[f64; NX]> {
            (0..(NR - 1) * (SUBSTEPS + 1))
                .map(|n| {
                    let (j, s) = (n / (SUBSTEPS + 1), n % (SUBSTEPS + 1));
                    let r = (j as f64 + s as f64 / SUBSTEPS as f64) / (NR - 1) as f64;
                    let alpha = (r * r).max(ALPHA_FLOOR);
                    if side == 1 {
                        return mixed_axis_weights::<NX>(alpha);
                    }
                    core::array::from_fn(|i| {
                        let mut unit = [0.0f32; NX];
                        unit[i] = 1.0;
                        profile_average(&unit, alpha as f32)
                    })
                })
                .collect()
        };
        let sides = [EtaRange::AtLeastOne, EtaRange::AtMostOne].map(|range| {
            let side = usize::from(range == EtaRange::AtMostOne);
            let grids = walk.grids(range);
            let [r, t] = single.grids(range);
            let row_of = |q: usize, j: usize, l: usize| -> [f32; N] {
                core::array::from_fn(|i| grids[q][SideGrids::index(i, j, l)])
            };
            let rows: Box<[Row; N * N]> = boxed(|n| {
                let (j, l) = (n % N, n / N);
                let alpha = node_alpha(j).max(ALPHA_FLOOR) as f32;
                // the index of the walk tables' row l (u = √((η − 1)/2) = l/15), as seen
                let u = l as f32 / (N - 1) as f32;
                let eta = 1.0 + 2.0 * u * u;
                let seen = if side == 0 { eta } else { 1.0 / eta };
                // the lobes' profiles at the row's nodes (x = i/15 on the scale-invariant
                // axis): the loss D split as the lobes split it, ΔT' = min(ΔT, D) and the
                // reflection the rest
                let walk_t = row_of(1, j, l);
                let split = |i: usize| {
                    let big_x = (i as f32 / (N - 1) as f32).powi(2);
                    let mu = if big_x >= 1.0 { 1.0 } else { big_x * alpha / (1.0 + alpha - big_x) };
                    let d = loss.loss(mu, alpha, seen).unwrap_or(0.0).max(0.0);
                    let t = walk_t[i].max(0.0).min(d);
                    (d - t, t)
                };
                // the reflection lobe samples D − ΔT' + κ D: the hit's g_R = D − c_a ΔT'
                // (c_a ≤ 1) plus a share of the loss, which bounds the ratio of g_R to the
                // sampled profile where the row's split and the hit's differ; the transmission
                // lobe ΔT'
                let dr: [f32; N] =
                    core::array::from_fn(|i| split(i).0 + REFLECTION_LOSS_SHARE * (split(i).0 + split(i).1));
                let dt: [f32; N] = core::array::from_fn(|i| split(i).1);
                Row {
                    profiles: [dr, dt].map(|g| MuProfile::new(&mu_cell_masses(&g, alpha))),
                    masses: [dr, dt].map(|g| profile_average(&g, alpha) as f32),
                }
            });
            // the lobes' nodes: the loss, and the walk's ΔT at the node capped by it
            let d = loss.grid(range);
            let lobes: Box<[Vec2; LOSS_NODES]> = boxed(|k| {
                let (i, j, l) = (k % NX, (k / NX) % NR, k / (NX * NR));
                let (mu, alpha, eta) = DielectricLossTable::node_parameters(i, j, l, range);
                let seen = if side == 0 { eta } else { 1.0 / eta };
                let dt = walk.energy(mu, alpha, seen).map_or(0.0, |h| h.transmitted.max(0.0));
                let dd = d[k].max(0.0);
                Vec2::new(dd, dt.min(dd))
            });
            let w = weights(side);
            let averages: Box<[Vec2; AVERAGES]> = boxed(|n| {
                let s = n % (SUBSTEPS + 1);
                let (j, l) = ((n / (SUBSTEPS + 1)) % (NR - 1), n / ((SUBSTEPS + 1) * (NR - 1)));
                let f = s as f64 / SUBSTEPS as f64;
                let w = &w[j * (SUBSTEPS + 1) + s];
                let (mut dd, mut dt) = (0.0, 0.0);
                for (i, wi) in w.iter().enumerate() {
                    let at = |jj: usize| lobes[DielectricLossTable::index(i, jj, l)].as_dvec2();
                    let v = at(j) + f * (at(j + 1) - at(j));
                    dd += wi * v.x;
                    dt += wi * v.y;
                }
                Vec2::new(dd as f32, dt as f32)
            });
            let single: Box<Grid> = boxed(|k| r[k] + t[k]);
            GlassSide { lobes, averages, single, rows }
        });
        Self { sides }
    }
}

impl GlassSide {
    /// [D̄, ΔT̄'] of the loss grid's index row l at the roughness cell (j, f), linear between
    /// the sub-steps.
    #[inline(always)]
    pub(crate) fn averages_at(&self, l: usize, (j, f): (usize, f32)) -> Vec2 {
        let t = f * SUBSTEPS as f32;
        let s = floor_index(t, SUBSTEPS - 1);
        let n = (l * (NR - 1) + j) * (SUBSTEPS + 1) + s;
        self.averages[n].lerp(self.averages[n + 1], t - s as f32)
    }
}
