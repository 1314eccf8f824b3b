//! What a compensated conductor built per hit reads and does not recompute: per slope family,
//! built once (on first use) from the shipped albedo and per-order tables, everything that
//! depends on the roughness alone.
//!
//! * the complements 1 − E of the albedo table's nodes (exact in f64, rounded once);
//! * the walk's order fractions φ_k = e_k/Σ_j e_j at the per-order tables' nodes;
//! * the averages over the hemisphere (2∫ · μ dμ) of the interpolated 1 − E and of
//!   (1 − E) φ_k, tabulated at [`SUBSTEPS`] sub-steps of every roughness cell of the albedo
//!   table (linear between them) — the normalizations of the added lobes, which depend on α
//!   through the direction axis as well as through the rows' blend;
//! * per roughness row, the sampler of its profile (1 − E(μ)) μ at the row's α, the profile's
//!   mass and the sampling mixture's probability of single scattering per cell of the uniform
//!   μ axis (E at the cell's centre);
//! * a reference to the table of F_avg over the complex index (shared by the families).

use super::fresnel_average::FresnelAverageTable;
use super::lobe_profile::{
    DirectionAxis, MU_CELLS, MuProfile, axis_average, mu_cell_centre, mu_cell_masses, profile_average, row_at,
};
use super::shared::boxed;
use crate::albedo::{
    ALBEDO_DIRECTIONS, ALBEDO_ROUGHNESSES, AlbedoTable, Family, ORDER_TABLE_SIZE, ORDER_TABLES,
    ScatteringOrderTable, lane_indices, node_cell, node_cells,
};
use glam::Vec4;
use std::sync::OnceLock;

/// Sub-steps per roughness cell of the tabulated averages (steps of r = √α of 1/1984).
pub(crate) const SUBSTEPS: usize = 32;
/// Roughness cells of the albedo table.
const CELLS: usize = ALBEDO_ROUGHNESSES - 1;
/// Sub-steps of the whole roughness axis r ∈ [0, 1].
const STEPS: usize = CELLS * SUBSTEPS;
/// The roughness of the albedo table's row 0 (its α → 0 limit profile).
const ALPHA_LIMIT: f64 = 1e-6;
/// The smallest α of the averages (α = 0 at r = 0 has only the limit).
const ALPHA_FLOOR: f64 = 1e-9;

/// The profile of one roughness row, at the row's own α.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Row {
    /// The sampler of (1 − E(μ)) μ.
    pub(crate) profile: MuProfile,
    /// 2∫(1 − E) μ dμ: the profile's mass (0 for a row without loss).
    pub(crate) mass: f32,
    /// E at the centre of each cell of the uniform μ axis: the sampling mixture's probability
    /// of the single-scattering lobe (any positive value gives an exact mixture density).
    pub(crate) single: [f32; MU_CELLS],
}

/// The shared tables of one slope family.
#[derive(Debug)]
pub(crate) struct ConductorTables {
    /// 1 − E at the albedo table's nodes, roughness slowest.
    pub(crate) complement: Box<[f32; ALBEDO_DIRECTIONS * ALBEDO_ROUGHNESSES]>,
    /// The order fractions (φ_2 … φ_6, φ_tail) at the per-order tables' nodes, as two lanes of
    /// four (the last two 0), roughness slowest.
    pub(crate) fractions: Box<[[Vec4; 2]; ORDER_TABLE_SIZE * ORDER_TABLE_SIZE]>,
    /// [C, m_2, …, m_6, m_tail, 0] at the sub-steps g = 0 … [`STEPS`] of the roughness axis,
    /// r = g/STEPS (sub-step s = g − j SUBSTEPS of roughness cell j): C = 2∫(1 − E) μ dμ and
    /// m_k = 2∫(1 − E) φ_k μ dμ of the interpolants at that roughness.
    pub(crate) averages: Box<[[Vec4; 2]; STEPS + 1]>,
    /// The rows' profiles.
    pub(crate) rows: Box<[Row; ALBEDO_ROUGHNESSES]>,
    /// The table of F_avg over the complex index (one for every family: a reference here, so
    /// that a per-hit construction checks one lazily built table, not two).
    pub(crate) fresnel: &'static FresnelAverageTable,
}

/// The cells of a roughness r = √α ∈ [0, 1] on the three roughness axes of the tables, each
/// as (cell, fraction in it): found together, in the SIMD lanes ([`node_cells`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RoughnessCells {
    /// The albedo table's roughness cell.
    pub(crate) row: (usize, f32),
    /// The per-order tables' roughness cell.
    pub(crate) order_row: (usize, f32),
    /// The cell of the averages' sub-steps ([`ConductorTables::averages_at`]).
    pub(crate) step: (usize, f32),
}

impl RoughnessCells {
    /// The cells of r ∈ [0, 1].
    #[inline(always)]
    pub(crate) fn of(r: f32) -> Self {
        let last = |nodes: usize| (nodes - 1) as f32;
        let t =
            Vec4::splat(r) * Vec4::new(last(ALBEDO_ROUGHNESSES), last(ORDER_TABLE_SIZE), STEPS as f32, 0.0);
        let (n, f) = node_cells(t, Vec4::new(last(CELLS), last(ORDER_TABLE_SIZE - 1), last(STEPS), 0.0));
        let [row, order_row, step, _] = lane_indices(n);
        Self { row: (row, f.x), order_row: (order_row, f.y), step: (step, f.z) }
    }
}

/// The α of the albedo table's row j.
fn row_alpha(j: usize) -> f64 {
    let r = j as f64 / CELLS as f64;
    (r * r).max(ALPHA_LIMIT)
}

impl ConductorTables {
    /// The tables of a family, built on first use.
    #[inline]
    pub(crate) fn of(family: Family) -> &'static Self {
        static GGX: OnceLock<ConductorTables> = OnceLock::new();
        static BECKMANN: OnceLock<ConductorTables> = OnceLock::new();
        match family {
            Family::Ggx => GGX.get_or_init(|| Self::build(&AlbedoTable::GGX, &ScatteringOrderTable::GGX)),
            Family::Beckmann => {
                BECKMANN.get_or_init(|| Self::build(&AlbedoTable::BECKMANN, &ScatteringOrderTable::BECKMANN))
            }
        }
    }

    fn build(albedo: &AlbedoTable, orders: &ScatteringOrderTable) -> Self {
        let nodes = albedo.directional_nodes();
        let complement: Box<[f32; ALBEDO_DIRECTIONS * ALBEDO_ROUGHNESSES]> =
            boxed(|n| (1.0 - f64::from(nodes[n])) as f32);
        let fractions: Box<[[Vec4; 2]; ORDER_TABLE_SIZE * ORDER_TABLE_SIZE]> = boxed(|n| {
            let e: [f64; ORDER_TABLES] = core::array::from_fn(|k| f64::from(orders.directional_nodes(k)[n]));
            let total: f64 = e.iter().sum();
            // (no walk left after two or more bounces: pure order 2)
            let phi: [f32; 8] = core::array::from_fn(|k| match k {
                _ if k >= ORDER_TABLES => 0.0,
                _ if total > 0.0 => (e[k] / total) as f32,
                0 => 1.0,
                _ => 0.0,
            });
            [Vec4::from_slice(&phi[..4]), Vec4::from_slice(&phi[4..])]
        });
        let row = |j: usize| -> [f32; ALBEDO_DIRECTIONS] {
            core::array::from_fn(|i| complement[j * ALBEDO_DIRECTIONS + i])
        };
        let rows: Box<[Row; ALBEDO_ROUGHNESSES]> = boxed(|j| {
            let c = row(j);
            let alpha = row_alpha(j) as f32;
            let axis = DirectionAxis::<ALBEDO_DIRECTIONS>::new(alpha);
            Row {
                profile: MuProfile::new(&mu_cell_masses(&c, alpha)),
                mass: profile_average(&c, alpha) as f32,
                single: core::array::from_fn(|k| 1.0 - row_at(&c, axis.cell(mu_cell_centre(k)))),
            }
        });
        let averages: Box<[[Vec4; 2]; STEPS + 1]> = boxed(|g| {
            // (the last sub-step is the end of the last cell)
            let j = (g / SUBSTEPS).min(CELLS - 1);
            let s = g - j * SUBSTEPS;
            let r = (j as f64 + s as f64 / SUBSTEPS as f64) / CELLS as f64;
            let alpha = (r * r).max(ALPHA_FLOOR);
            let f = s as f64 / SUBSTEPS as f64;
            let (lo, hi) = (row(j), row(j + 1));
            let blended: [f32; ALBEDO_DIRECTIONS] = core::array::from_fn(|i| {
                (f64::from(lo[i]) + f * (f64::from(hi[i]) - f64::from(lo[i]))) as f32
            });
            // the order rows around r, and the fraction between them
            let (jo, fo) = node_cell((r * (ORDER_TABLE_SIZE - 1) as f64) as f32, ORDER_TABLE_SIZE);
            let fo = f64::from(fo);
            let last_x = (ALBEDO_DIRECTIONS - 1) as f64;
            let last_o = (ORDER_TABLE_SIZE - 1) as f64;
            let m = axis_average(alpha, ALBEDO_DIRECTIONS - 1, |x| {
                // 1 − E and the fractions at x, interpolated as the lobe interpolates them
                let t = (x * last_x).min(last_x);
                let i = (t as usize).min(ALBEDO_DIRECTIONS - 2);
                let fi = t - i as f64;
                let c = f64::from(blended[i]) + fi * (f64::from(blended[i + 1]) - f64::from(blended[i]));
                let t = (x * last_o).min(last_o);
                let io = (t as usize).min(ORDER_TABLE_SIZE - 2);
                let fx = t - io as f64;
                let phi = |i: usize, j: usize, k: usize| {
                    let v = fractions[j * ORDER_TABLE_SIZE + i];
                    f64::from(if k < 4 { v[0][k] } else { v[1][k - 4] })
                };
                let mut out = [0.0; 8];
                out[0] = c;
                for (k, o) in out[1..=ORDER_TABLES].iter_mut().enumerate() {
                    let near = phi(io, jo, k) + fx * (phi(io + 1, jo, k) - phi(io, jo, k));
                    let far = phi(io, jo + 1, k) + fx * (phi(io + 1, jo + 1, k) - phi(io, jo + 1, k));
                    *o = c * (near + fo * (far - near));
                }
                out
            });
            // C in closed form (the quadrature of the others is checked against it in the tests)
            let mut v = m.map(|x| x as f32);
            v[0] = profile_average(&blended, alpha as f32) as f32;
            [Vec4::from_slice(&v[..4]), Vec4::from_slice(&v[4..])]
        });
        Self { complement, fractions, averages, rows, fresnel: FresnelAverageTable::get() }
    }

    /// The averages [C, m_2, …, m_tail, 0] at the sub-step cell `(g, w)` of the roughness
    /// axis ([`RoughnessCells::step`]), linear between the sub-steps.
    #[inline(always)]
    pub(crate) fn averages_at(&self, (g, w): (usize, f32)) -> [Vec4; 2] {
        let pair = &self.averages[g..g + 2];
        let (a, b) = (pair[0], pair[1]);
        [a[0].lerp(b[0], w), a[1].lerp(b[1], w)]
    }

    /// C = 1 − E_avg at the sub-step cell `step` of the roughness axis: the first of
    /// [`Self::averages_at`].
    #[inline(always)]
    pub(crate) fn complement_average(&self, step: (usize, f32)) -> f32 {
        self.averages_at(step)[0].x
    }

    /// 1 − E at the direction cell `(i, fx)` of the roughness cell `(j, fr)`, bilinear.
    #[inline(always)]
    pub(crate) fn complement_at(&self, (i, fx): (usize, f32), (j, fr): (usize, f32)) -> f32 {
        let n = j * ALBEDO_DIRECTIONS + i;
        let c = &self.complement;
        let upper = n + ALBEDO_DIRECTIONS;
        bilinear([c[n], c[upper], c[n + 1], c[upper + 1]], fx, fr)
    }

    /// The order fractions at the direction cell `(i, fx)` of the per-order roughness cell
    /// `(j, fr)`, bilinear.
    #[inline(always)]
    pub(crate) fn fractions_at(&self, (i, fx): (usize, f32), (j, fr): (usize, f32)) -> [Vec4; 2] {
        let n = j * ORDER_TABLE_SIZE + i;
        let p = &self.fractions;
        let at = |lane: usize| {
            let lower = p[n][lane].lerp(p[n + 1][lane], fx);
            let upper = p[n + ORDER_TABLE_SIZE][lane].lerp(p[n + ORDER_TABLE_SIZE + 1][lane], fx);
            lower.lerp(upper, fr)
        };
        [at(0), at(1)]
    }
}

/// 1 − E in a cell from its corners (lower row, upper row) at the lower direction node, then at
/// the upper one: linear in the direction fraction `fx`, then in the roughness fraction `fr`
/// (the one order in which the compensated conductor interpolates it, so that every reader
/// gets the same bits).
#[inline(always)]
pub(crate) fn bilinear([a, b, c, d]: [f32; 4], fx: f32, fr: f32) -> f32 {
    let (lower, upper) = (a + fx * (c - a), b + fx * (d - b));
    lower + fr * (upper - lower)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The averages: C at every sub-step equals its closed form and the quadrature of the
    /// order averages sums to it (Σ_k φ_k = 1), to 1e-6 relative; between the sub-steps the
    /// linear interpolation of C is within 4e-4 (relative) of the closed form at α ≥ 1e-3 and
    /// 4e-5 at α ≥ 1e-2, measured at the midpoints of every sub-step of both families.
    #[test]
    fn averages_are_exact_at_the_substeps_and_close_between() {
        for (family, albedo) in [(Family::Ggx, AlbedoTable::GGX), (Family::Beckmann, AlbedoTable::BECKMANN)] {
            let t = ConductorTables::of(family);
            let (mut worst_sum, mut worst_small, mut worst_large): (f64, f64, f64) = (0.0, 0.0, 0.0);
            for j in 0..CELLS {
                for s in 0..=SUBSTEPS {
                    let v = t.averages[j * SUBSTEPS + s];
                    let sum: f32 = v[0].y + v[0].z + v[0].w + v[1].x + v[1].y + v[1].z;
                    if v[0].x > 1e-6 {
                        worst_sum = worst_sum.max(f64::from((sum - v[0].x).abs() / v[0].x));
                    }
                    if s == SUBSTEPS {
                        continue;
                    }
                    // the midpoint of the sub-step
                    let f = (s as f32 + 0.5) / SUBSTEPS as f32;
                    let r = (j as f32 + f) / CELLS as f32;
                    let alpha = r * r;
                    let row: [f32; ALBEDO_DIRECTIONS] = core::array::from_fn(|i| {
                        let lo = f64::from(t.complement[j * ALBEDO_DIRECTIONS + i]);
                        let hi = f64::from(t.complement[(j + 1) * ALBEDO_DIRECTIONS + i]);
                        (lo + f64::from(f) * (hi - lo)) as f32
                    });
                    let exact = profile_average(&row, alpha);
                    let got = f64::from(t.averages_at((j * SUBSTEPS + s, 0.5))[0].x);
                    let e = (got - exact).abs() / exact;
                    if alpha >= 1e-2 {
                        worst_large = worst_large.max(e);
                    } else if alpha >= 1e-3 {
                        worst_small = worst_small.max(e);
                    }
                }
            }
            println!(
                "{}: Σ m_k against C {worst_sum:.1e}; C between sub-steps {worst_small:.1e} (α ≥ 1e-3), \
                 {worst_large:.1e} (α ≥ 1e-2)",
                albedo.name()
            );
            assert!(worst_sum <= 1e-6 && worst_small <= 4e-4 && worst_large <= 4e-5);
        }
    }
}
