//! The compensated dielectric: the single-scattering microfacet BSDF (reflection and
//! transmission) plus the energy of the higher orders, built per hit from shared tables
//! ([`GlassTables`]).
//!
//! **The walk's split** ([`Compensation::Walk`], and [`Compensation::KullaConty`], which is the
//! same for a dielectric): two separable lobes,
//!
//! f = f_ss + f_R + f_T,
//! f_R(ωo, ωi) = g_a(μo) g_a(μi) / (π ḡ_a)                      (ωi on the view's side a),
//! f_T(ωo, ωi) = c_a ΔT'_a(μo) · ΔT'_b(μi) / (π ΔT̄'_b)          (ωi on the other side b),
//! g_s = D_s − c_s ΔT'_s,
//!
//! with, for light from side s, D_s = 1 − R_ss − T_ss the energy single scattering loses
//! ([`super::DielectricLossTable`]: deterministic quadrature), ΔT_s the walk's transmitted energy
//! of orders ≥ 2 ([`super::DielectricWalkTable`]: the walk of Heitz et al. 2016, supplement
//! §3.4) and ΔT'_s = min(ΔT_s, D_s), the walk's value capped by the loss at each node of the
//! loss table's grid (where both are tabulated for the lobes); ḡ = 2∫₀¹ g(μ) μ dμ of the
//! interpolated row, and μ = |cos θ|: Kulla and Conty's separable lobe (2017) applied to each
//! side's reflected and transmitted higher orders, their total from the loss table and their
//! split between the sides from the walk.
//!
//! **Energy** (importance transport, the flux): ∫ f_R cos dωi = g_a(μo) and
//! ∫ f_T |cos| dωi = c_a ΔT'_a(μo) for every view, so the albedo is
//! R_ss + T_ss + D_a(μo) = 1 up to the loss table's interpolation error alone: the reflection
//! lobe takes what the transmission lobe leaves of the loss, whatever the walk tables' errors
//! and the factor c_a. The lobes' split follows the walk's within the walk tables' errors.
//!
//! **Reciprocity.** Detailed balance in a medium of index n (equilibrium radiance ∝ n²) makes
//! the flux BSDF of a transmission satisfy n_a² f(ωa, ωb) = n_b² f(ωb, ωa) (Veach 1997, §5.2,
//! in importance form): the rank-1 f_T satisfies it if and only if
//! n_a² c_a ΔT̄'_a = n_b² c_b ΔT̄'_b, which the walk's own higher orders satisfy up to the
//! tables' noise and interpolation. The factors c enforce it exactly: with
//! R = η² ΔT̄'_in/ΔT̄'_out, c_out = min(1, R) and c_in = min(1, 1/R), so that the side whose
//! average is the larger gives up the residual to its reflection lobe;
//! [`Compensated::transmission_mismatch`] reports 1/R − 1. The reflection lobe, a symmetric
//! rank-1 product, is reciprocal on its side.
//!
//! **Non-negative without a clamp.** ΔT' ≤ D at every node and c ≤ 1 make every node value
//! of g_s non-negative, so the interpolated profile is, and its average is the same linear
//! function of the nodes as the lookup (the normalizations are exact, up to the averages'
//! interpolation between sub-steps of α).
//!
//! **Sampling.** A mixture chosen by the view's energies: per cell of a uniform μ axis of the
//! view (32 cells) the probabilities of the single-scattering sample, the reflection lobe and
//! the transmission lobe are the energies 1 − D : D − ΔT' : ΔT' at the cell's centre (the
//! first at least 1e-3 of the total), blended bilinearly between the four (roughness, index) rows of
//! the walk tables around the hit; each lobe samples the walk's light profile ΔR(μi) μi or
//! ΔT(μi) μi on its hemisphere as the mixture of the four rows' profiles (each at its row's α,
//! chosen with probability ∝ blend weight × mass), each a density continuous and linear in μi²
//! on the cells of the uniform μ axis (alias method). The sampled profiles are the walk's, not
//! the lobes' g and ΔT' (any density is exact for the mixture): `pdf` is the exact mixture
//! density, and a sample's weight is f·|cos θi|/pdf at its direction.
//!
//! **Turquin** ([`Compensation::Turquin`]): f = f_ss/E(μo), E = R + T of the single-scattering
//! dielectric tables ([`super::DielectricAlbedoTable`]) on the view's side, interpolated
//! trilinearly at (μo, α, η); `pdf` and `sample` are those of single scattering. With
//! [`Transport::Importance`] the expected sample weight is 1 for every view, up to the table's
//! interpolation error relative to E. Near η = 1 at grazing views E → 0: where f_ss/E would not
//! be a finite f32 the BSDF answers 0 (and `sample` `None`).

use super::compensated::{Compensated, CompensatedMaterial, Compensation};
use super::glass_tables::{GlassSide, GlassTables};
use super::lobe_profile::{MU_CELLS, line_pdf, mu_cell};
use super::shared::{NOTHING, ONE_MINUS_ULP, Shared, eta_error, mixture_sample};
use crate::albedo::{
    DIELECTRIC_TABLE_SIZE, DielectricAlbedoTable, DielectricDirection, DielectricLossTable,
    DielectricWalkTable, DirectionAxis, LOSS_TABLE_SHAPE, MAX_TABULATED_ETA, node_cell,
};
use crate::bsdf::{
    Bsdf, BsdfFlags, BsdfSample, BsdfValue, MicrofacetBsdf, Transport, unit_directions, unit_view,
};
use crate::compensation::AlbedoTabulated;
use crate::error::Error;
use crate::material::{Dielectric, Side};
use crate::single_scattering::SingleScattering;
use crate::slope::MicrosurfaceSlope;
use core::f32::consts::PI;
use glam::{Vec2, Vec3, Vec4};

/// Nodes per axis of the dielectric tables.
const N: usize = DIELECTRIC_TABLE_SIZE;
/// The last node index, as a float.
const LAST: f32 = (N - 1) as f32;
/// The smallest share of the single-scattering lobe in the sampling mixture, relative to the
/// added lobes' total: keeps its density positive wherever it scatters.
const MIN_SINGLE_SHARE: f32 = 1e-3;
/// Nodes of the loss grid's direction and roughness axes, per (roughness, direction) plane,
/// and of its index axis.
const NX: usize = LOSS_TABLE_SHAPE[0];
const NR: usize = LOSS_TABLE_SHAPE[1];
const PLANE: usize = NX * NR;
const NU: usize = LOSS_TABLE_SHAPE[2];
/// The loss grid's fractional direction node t = a √X + b μ of each table side (0: η ≥ 1,
/// t = 23 x; 1: η ≤ 1, t = 23 (½ x + ½ μ)), with x = √X the scale-invariant coordinate.
const LOSS_DIRECTION: [(f32, f32); 2] =
    [((NX - 1) as f32, 0.0), (0.5 * (NX - 1) as f32, 0.5 * (NX - 1) as f32)];

/// The per-hit state of a compensated dielectric.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DielectricLobes {
    tables: Shared<GlassTables>,
    /// Whether the lobes answer (a rough surface and η ≠ 1).
    active: bool,
    /// The table side (0: η ≥ 1, 1: η ≤ 1) of a view from outside (0) and inside (1).
    table_side: [usize; 2],
    /// η_wi/η_wo of a transmission from outside (η) and from inside (1/η).
    transmitted_eta: [f32; 2],
    /// The walk tables' cell (the samplers' rows): the row index l·16 + j of the lower
    /// (roughness, index) corner, the roughness cell and its fraction, and the index fraction.
    corner: usize,
    walk_row: (usize, f32),
    walk_u: f32,
    /// The scale-invariant direction axis at the hit's α (the loss grid's coordinates derive
    /// from it).
    axis: DirectionAxis,
    /// The loss grid's cell: the row index l·24 + j of the lower (roughness, index) corner, and
    /// the roughness and index fractions.
    loss_corner: usize,
    loss_f: (f32, f32),
    /// The added lobes' scales per view side: [1/(π ḡ_R,a), c_a/(π ΔT̄'_b) × transport].
    scales: [[f32; 2]; 2],
    /// [c_a/(π ΔT̄'_b)] before the transport factor, per view side.
    transmitted_scale: [f32; 2],
    /// c_a per view side.
    c: [f32; 2],
    /// Per view side and crossing: the probabilities of the four rows' profiles (lower
    /// corner, +r, +u, +r +u) in the light's sampler, cumulated.
    corners: [[Vec4; 2]; 2],
    /// 1/R − 1, the tables' reciprocity residual.
    mismatch: f32,
    /// Turquin: the single-scattering tables' cell (node of the lower corner, roughness and
    /// index fractions) and each view side's direction axis.
    single_base: usize,
    single_f: (f32, f32),
    single_axis: [DielectricDirection; 2],
}

impl DielectricLobes {
    /// The lobes of a Dirac lobe: none.
    #[inline(always)]
    fn none(tables: &'static GlassTables, eta: f32) -> Self {
        Self {
            tables: Shared(tables),
            active: false,
            table_side: [0, 1],
            transmitted_eta: [eta, 1.0 / eta],
            corner: 0,
            walk_row: (0, 0.0),
            walk_u: 0.0,
            axis: DirectionAxis::NONE,
            loss_corner: 0,
            loss_f: (0.0, 0.0),
            scales: [[0.0; 2]; 2],
            transmitted_scale: [0.0; 2],
            c: [1.0; 2],
            corners: [[Vec4::ONE; 2]; 2],
            mismatch: 0.0,
            single_base: 0,
            single_f: (0.0, 0.0),
            single_axis: [DielectricDirection::Outside; 2],
        }
    }

    /// The tables of the table side of a view side.
    #[inline(always)]
    fn side(&self, view: usize) -> &GlassSide {
        &self.tables.0.sides[self.table_side[view]]
    }

    /// The loss grid's fractional direction node of a cosine μ with scale-invariant coordinate
    /// x on the table of view side `view`.
    #[inline(always)]
    fn loss_node(&self, view: usize, x: f32, mu: f32) -> f32 {
        let (a, b) = LOSS_DIRECTION[self.table_side[view]];
        a * x + b * mu
    }

    /// The lobes' values (D, ΔT') of view side `view` at the loss grid's direction node i,
    /// bilinear at this hit's (roughness, index) cell.
    #[inline(always)]
    fn lobe_node(&self, view: usize, i: usize) -> Vec2 {
        let grid = &self.side(view).lobes;
        let base = self.loss_corner * NX + i;
        let (fr, fu) = self.loss_f;
        let near = grid[base].lerp(grid[base + NX], fr);
        let far = grid[base + PLANE].lerp(grid[base + PLANE + NX], fr);
        near.lerp(far, fu)
    }

    /// The lobes' values (D, ΔT') of view side `view` at the loss grid's fractional direction
    /// node t: trilinear at this hit's (roughness, index) cell, the nodes from `factors`.
    #[inline(always)]
    fn lobe_values<F: GlassFactors>(factors: &F, view: usize, t: f32) -> Vec2 {
        let (i, fx) = node_cell(t, NX);
        let (low, high) = factors.lobe_nodes(view, i);
        low.lerp(high, fx)
    }

    /// The weights of (D, ΔT') in the μ profile of the lobe of a view on side `a` and a light
    /// crossing (`c` = 1: ΔT', on either side) or not (g_R = D − c_a ΔT').
    #[inline(always)]
    fn profile_weights(&self, a: usize, c: usize) -> Vec2 {
        let t = c as f32;
        Vec2::new(1.0 - t, t - (1.0 - t) * self.c[a])
    }

    /// The lobes' values (D, ΔT') at |cos θ| = `mu` on side `a` (a view's, or a light's on
    /// the side its lobe is read at): what the added lobe and the mixture read at the view,
    /// read once per call.
    #[inline(always)]
    fn values_at<F: GlassFactors>(&self, factors: &F, a: usize, mu: f32) -> Vec2 {
        Self::lobe_values(factors, a, self.loss_node(a, self.axis.coordinate(mu), mu))
    }

    /// The added lobe f_R or f_T for a view on side `a` with lobe values `vo`
    /// ([`Self::values_at`]) and a light crossing (`c` = 1) or not at |cos θi| = `mu_i`, both
    /// off the horizon.
    #[inline(always)]
    fn added<F: GlassFactors>(&self, factors: &F, a: usize, c: usize, vo: Vec2, mu_i: f32) -> f32 {
        let vi = self.values_at(factors, a ^ c, mu_i);
        let w = self.profile_weights(a, c);
        // (both profiles are ≥ 0 at every node; rounding may leave −1e-9)
        vo.dot(w).max(0.0) * vi.dot(w).max(0.0) * self.scales[a][c]
    }

    /// The mixture's probabilities (single, reflection, transmission, 0) of a view on side `a`
    /// with lobe values `v` ([`Self::values_at`]): the lobes' energies at the view,
    /// 1 − D : g_R : c_a ΔT' (their sum D), the first at least [`MIN_SINGLE_SHARE`] of D.
    #[inline(always)]
    fn mixture(&self, a: usize, v: Vec2) -> Vec4 {
        let d = v.x.max(0.0);
        let t = (self.c[a] * v.y).clamp(0.0, d);
        let single = (1.0 - d).max(MIN_SINGLE_SHARE * d);
        let scale = 1.0 / (single + d);
        Vec4::new(single * scale, (d - t) * scale, t * scale, 0.0)
    }

    /// The line ([`MuProfile::line`](super::lobe_profile::MuProfile::line)) in μ cell k of
    /// the light's profile for a view on side `a` and a light crossing (`c`) or not: the four
    /// rows' lines mixed by the rows' probabilities (the profile's density is the mixture of
    /// theirs).
    #[inline(always)]
    fn profile_line(&self, a: usize, c: usize, k: usize) -> Vec2 {
        let rows = &self.side(a ^ c).rows;
        let n = self.corner;
        let cum = self.corners[a][c];
        let line = |row: usize| rows[row].profiles[c].line(k);
        line(n) * cum.x
            + line(n + 1) * (cum.y - cum.x)
            + line(n + N) * (cum.z - cum.y)
            + line(n + N + 1) * (cum.w - cum.z)
    }

    /// The density of the light's profile for a view on side `a` and a light crossing (`c`)
    /// or not, at |cos θi| = `mu_i`, its line from `factors`.
    #[inline(always)]
    fn profile_pdf<F: GlassFactors>(factors: &F, a: usize, c: usize, mu_i: f32) -> f32 {
        line_pdf(factors.profile_line(a, c, mu_cell(mu_i)), mu_i)
    }

    /// The mixture density at wi (off the horizon) for a view on side `a` with probabilities
    /// `p` and single scattering's density `pdf_ss`.
    #[inline(always)]
    fn mixture_pdf<F: GlassFactors>(factors: &F, a: usize, p: Vec4, wo: Vec3, wi: Vec3, pdf_ss: f32) -> f32 {
        let c = crossing(wo, wi);
        p.x * pdf_ss + p[1 + c] * Self::profile_pdf(factors, a, c, wi.z.abs())
    }

    /// E = R + T of the single-scattering tables for a view on side `a` at the tables'
    /// direction node i, bilinear at this hit's (roughness, index) cell.
    #[inline(always)]
    fn single_node(&self, a: usize, i: usize) -> f32 {
        let grid = &self.side(a).single;
        let base = self.single_base + i;
        let (fr, fu) = self.single_f;
        let near = grid[base] + fr * (grid[base + N] - grid[base]);
        let far = grid[base + N * N] + fr * (grid[base + N * N + N] - grid[base + N * N]);
        near + fu * (far - near)
    }

    /// E = R + T of the single-scattering tables for a view on side `a` at |cos θo| = `mu`,
    /// the nodes from `factors`.
    #[inline(always)]
    fn single_albedo<F: GlassFactors>(&self, factors: &F, a: usize, mu: f32) -> f32 {
        let x = self.single_axis[a].coordinate(mu);
        let (i, fx) = node_cell(x * LAST, N);
        let (low, high) = factors.single_nodes(a, i);
        low + fx * (high - low)
    }

    /// The values the queries of a batch read at this hit's (roughness, index), for every node
    /// of the direction axes ([`GlassColumn`]): E's for Turquin's scheme, the lobes' and the
    /// light profiles' lines for the others.
    pub(super) fn column(&self, scheme: Compensation) -> GlassColumn {
        let mut column = GlassColumn {
            lobes: [[Vec2::ZERO; NX]; 2],
            lines: [[[Vec2::ZERO; MU_CELLS]; 2]; 2],
            single: [[0.0; N]; 2],
        };
        if !self.active {
            return column;
        }
        for view in 0..2 {
            if scheme == Compensation::Turquin {
                for (i, e) in column.single[view].iter_mut().enumerate() {
                    *e = self.single_node(view, i);
                }
                continue;
            }
            for (i, v) in column.lobes[view].iter_mut().enumerate() {
                *v = self.lobe_node(view, i);
            }
            for (c, lines) in column.lines[view].iter_mut().enumerate() {
                for (k, line) in lines.iter_mut().enumerate() {
                    *line = self.profile_line(view, c, k);
                }
            }
        }
        column
    }
}

/// Where a compensated dielectric's queries read the tables' values at the hit's (roughness,
/// index): blended from the shared tables query by query ([`DielectricLobes`]), or read from a
/// batch's [`GlassColumn`], which holds the same blends, computed by the same functions, at
/// every node (the same bits).
pub(super) trait GlassFactors {
    /// The lobes' values (D, ΔT') of view side `view` at the loss grid's direction nodes i and
    /// i + 1 (i ≤ 22, the loss grid's last cell).
    fn lobe_nodes(&self, view: usize, i: usize) -> (Vec2, Vec2);
    /// The light profile's line in μ cell k for a view on side `a` and a crossing `c`
    /// ([`DielectricLobes::profile_line`]).
    fn profile_line(&self, a: usize, c: usize, k: usize) -> Vec2;
    /// E of view side `view` at the single-scattering tables' direction nodes i and i + 1
    /// (Turquin's scheme).
    fn single_nodes(&self, view: usize, i: usize) -> (f32, f32);
}

impl GlassFactors for DielectricLobes {
    #[inline(always)]
    fn lobe_nodes(&self, view: usize, i: usize) -> (Vec2, Vec2) {
        (self.lobe_node(view, i), self.lobe_node(view, i + 1))
    }
    #[inline(always)]
    fn profile_line(&self, a: usize, c: usize, k: usize) -> Vec2 {
        DielectricLobes::profile_line(self, a, c, k)
    }
    #[inline(always)]
    fn single_nodes(&self, view: usize, i: usize) -> (f32, f32) {
        (self.single_node(view, i), self.single_node(view, i + 1))
    }
}

/// A compensated dielectric's values at its (roughness, index) for every node of the
/// direction axes, laid out for a batch ([`DielectricLobes::column`]; 1.5 KiB): each query then
/// reads two nodes per lobe value (where the lobes blend eight table entries) and one line per
/// profile density (where they read four rows).
pub(super) struct GlassColumn {
    /// (D, ΔT') per view side and loss grid direction node.
    lobes: [[Vec2; NX]; 2],
    /// The light profiles' lines per view side, crossing and μ cell.
    lines: [[[Vec2; MU_CELLS]; 2]; 2],
    /// E per view side and single-scattering direction node.
    single: [[f32; N]; 2],
}

impl GlassFactors for GlassColumn {
    #[inline(always)]
    fn lobe_nodes(&self, view: usize, i: usize) -> (Vec2, Vec2) {
        (self.lobes[view][i], self.lobes[view][i + 1])
    }
    #[inline(always)]
    fn profile_line(&self, a: usize, c: usize, k: usize) -> Vec2 {
        self.lines[a][c][k]
    }
    #[inline(always)]
    fn single_nodes(&self, view: usize, i: usize) -> (f32, f32) {
        (self.single[view][i], self.single[view][i + 1])
    }
}

/// Whether the light crosses the interface (1) or stays on the view's side (0).
#[inline(always)]
fn crossing(wo: Vec3, wi: Vec3) -> usize {
    usize::from((wi.z > 0.0) != (wo.z > 0.0))
}

/// The index of the view's side: outside (0), inside (1).
#[inline(always)]
fn side_of(wo: Vec3) -> usize {
    usize::from(wo.z < 0.0)
}

/// The cumulated probabilities of four corners with bilinear weights (fr, fu) and masses m.
#[inline(always)]
fn corner_probabilities(fr: f32, fu: f32, m: [f32; 4]) -> Vec4 {
    let w = Vec4::new((1.0 - fr) * (1.0 - fu), fr * (1.0 - fu), (1.0 - fr) * fu, fr * fu) * Vec4::from(m);
    let total = w.element_sum();
    if total > 0.0 {
        let w = w / total;
        Vec4::new(w.x, w.x + w.y, w.x + w.y + w.z, 1.0)
    } else {
        Vec4::ONE
    }
}

impl CompensatedMaterial for Dielectric {
    type Lobes = DielectricLobes;

    #[inline]
    fn lobes<S: AlbedoTabulated>(
        single: &MicrofacetBsdf<S, Self>,
        scheme: Compensation,
    ) -> Result<DielectricLobes, Error> {
        let eta = single.surface().material().eta();
        if !(1.0 / MAX_TABULATED_ETA..=MAX_TABULATED_ETA).contains(&eta) {
            return Err(eta_error(eta));
        }
        let tables = GlassTables::of(S::DIELECTRIC_WALK.family());
        let mut lobes = DielectricLobes::none(tables, eta);
        // a Dirac lobe is not compensated (and √(αx αy) may underflow to 0 there)
        if single.is_specular() {
            return Ok(lobes);
        }
        lobes.active = true;
        let alpha = single.surface().slope().albedo_alpha();
        let eta_ge_1 = eta.max(1.0 / eta);
        // the table side seen from outside (η) and from inside (1/η)
        lobes.table_side = if eta >= 1.0 { [0, 1] } else { [1, 0] };
        if scheme == Compensation::Turquin {
            let (j, fr) = node_cell(DielectricAlbedoTable::roughness_node(alpha), N);
            let (l, fu) = node_cell(DielectricAlbedoTable::eta_node(eta_ge_1), N);
            lobes.single_base = (l * N + j) * N;
            lobes.single_f = (fr, fu);
            lobes.single_axis = [DielectricDirection::of(eta), DielectricDirection::of(1.0 / eta)];
            return Ok(lobes);
        }
        let row = node_cell(DielectricWalkTable::roughness_node(alpha), N);
        let (l, fu) = node_cell(DielectricWalkTable::eta_node(eta_ge_1), N);
        lobes.corner = l * N + row.0;
        lobes.walk_row = row;
        lobes.walk_u = fu;
        lobes.axis = DirectionAxis::new(alpha);
        let loss_row = node_cell(DielectricLossTable::roughness_node(alpha), NR);
        let (ll, loss_u) = node_cell(DielectricLossTable::eta_node(eta_ge_1), NU);
        lobes.loss_corner = ll * NR + loss_row.0;
        lobes.loss_f = (loss_row.1, loss_u);
        // the averages [D̄, ΔT̄'] of each view side, blended in u
        let average = |view: usize| {
            let side = lobes.side(view);
            side.averages_at(ll, loss_row).lerp(side.averages_at(ll + 1, loss_row), loss_u)
        };
        // (not `array::map`, whose closures are not inlined)
        let averages = [average(0), average(1)];
        // reciprocity: c_out ΔT̄'_out = η² c_in ΔT̄'_in (n_out = 1, n_in = η), both c ≤ 1
        let (m_out, m_in) = (averages[0].y, eta * eta * averages[1].y);
        let c = if m_out > 0.0 && m_in > 0.0 {
            // (one division: the ratio's reciprocal from the same quotient)
            let (ratio, inverse) = (m_in / m_out, m_out / m_in);
            lobes.mismatch = inverse - 1.0;
            if ratio >= 1.0 { [1.0, inverse] } else { [ratio, 1.0] }
        } else {
            [0.0, 0.0]
        };
        lobes.c = c;
        // the four normalizations in one division: 1/(π ḡ_a) and c_a/(π ΔT̄'_b) per view side
        let denominators = Vec4::new(
            averages[0].x - c[0] * averages[0].y,
            averages[1].x - c[1] * averages[1].y,
            averages[1].y,
            averages[0].y,
        );
        let numerators = Vec4::new(1.0, 1.0, c[0], c[1]);
        let positive = denominators.cmpgt(Vec4::ZERO);
        let scales = Vec4::select(positive, numerators / (PI * denominators), Vec4::ZERO);
        lobes.scales[0][0] = scales.x;
        lobes.scales[1][0] = scales.y;
        lobes.transmitted_scale = [scales.z, scales.w];
        // the light profiles' rows: reflection on the view's side, transmission on the other
        let n = row.0 + l * N;
        for view in 0..2 {
            for cross in 0..2 {
                let rows = &lobes.side(view ^ cross).rows;
                let m = [
                    rows[n].masses[cross],
                    rows[n + 1].masses[cross],
                    rows[n + N].masses[cross],
                    rows[n + N + 1].masses[cross],
                ];
                lobes.corners[view][cross] = corner_probabilities(row.1, fu, m);
            }
        }
        Ok(DielectricLobes::with_transport(lobes, Transport::Radiance))
    }

    #[inline]
    fn lobes_with_transport(lobes: DielectricLobes, transport: Transport) -> DielectricLobes {
        DielectricLobes::with_transport(lobes, transport)
    }
}

impl DielectricLobes {
    /// The transmission scales for `transport`: (η_wo/η_wi)² for radiance, from outside 1/η²
    /// and from inside η².
    #[inline(always)]
    fn with_transport(mut self, transport: Transport) -> Self {
        let [eta, inv_eta] = self.transmitted_eta;
        let factors = match transport {
            Transport::Radiance => [inv_eta * inv_eta, eta * eta],
            Transport::Importance => [1.0, 1.0],
        };
        for ((scales, transmitted), factor) in self.scales.iter_mut().zip(self.transmitted_scale).zip(factors)
        {
            scales[1] = transmitted * factor;
        }
        self
    }
}

/// The compensated dielectric's queries.
impl<S: MicrosurfaceSlope> Compensated<S, Dielectric> {
    /// ΔT̄'_out/(η² ΔT̄'_in) − 1: how far the walk's transmitted higher orders, as the lobes
    /// interpolate them, are from the reciprocity of the walk's own (0 without transmission
    /// lobes, and for Turquin's scheme).
    pub fn transmission_mismatch(&self) -> f32 {
        self.lobes.mismatch
    }

    /// The added albedo (g_R, c ΔT') of a view with |cos θo| = μ ∈ [0, 1] on `side`: the
    /// energies of the reflection and transmission lobes as this BSDF interpolates them
    /// (importance transport; their sum is the loss table's 1 − R_ss − T_ss); `None` outside
    /// [0, 1] (NaN included) and for Turquin's scheme.
    pub fn higher_orders(&self, mu: f32, side: Side) -> Option<(f32, f32)> {
        if !(0.0..=1.0).contains(&mu) || self.scheme == Compensation::Turquin {
            return None;
        }
        let l = &self.lobes;
        if !l.active {
            return Some((0.0, 0.0));
        }
        let a = usize::from(side == Side::Inside);
        let v = l.values_at(l, a, mu);
        Some(((v.x - l.c[a] * v.y).max(0.0), l.c[a] * v.y))
    }

    /// E(μo) = R + T of the single-scattering tables for a view on `side`
    /// ([`Side::Outside`]: above the surface, seeing η; [`Side::Inside`]: below it, seeing
    /// 1/η), as Turquin's scheme interpolates it, for μo = |cos θo| ∈ [0, 1]; `None` outside
    /// (NaN included) and for the other schemes.
    pub fn directional_albedo(&self, mu: f32, side: Side) -> Option<f32> {
        if !(0.0..=1.0).contains(&mu) || self.scheme != Compensation::Turquin {
            return None;
        }
        if !self.lobes.active {
            return Some(1.0);
        }
        Some(self.lobes.single_albedo(&self.lobes, usize::from(side == Side::Inside), mu))
    }

    /// Whether the added lobes answer for (wo, wi): a rough surface, valid directions off the
    /// horizon.
    #[inline(always)]
    fn compensates(&self, wo: Vec3, wi: Vec3) -> bool {
        self.lobes.active && wo.z != 0.0 && wi.z != 0.0
    }

    /// Turquin's factor 1/E(μo) for the view `wo` (1 on the horizon, where f_ss = 0), E's
    /// nodes from `factors`.
    #[inline(always)]
    fn turquin_factor<F: GlassFactors>(&self, factors: &F, wo: Vec3) -> f32 {
        if wo.z == 0.0 || !self.lobes.active {
            return 1.0;
        }
        1.0 / self.lobes.single_albedo(factors, side_of(wo), wo.z.abs())
    }

    /// f·factor, or 0 where it is not a finite f32 (see Turquin's special cases).
    #[inline(always)]
    fn scaled(f: Vec3, factor: f32) -> Vec3 {
        let f = f * factor;
        if f.is_finite() { f } else { Vec3::ZERO }
    }

    /// The view's side and its lobes' values ([`DielectricLobes::values_at`]) where the added
    /// lobes answer (an additive scheme on a rough surface, valid directions off the horizon):
    /// what f and the density read at the view.
    #[inline(always)]
    fn view_values<F: GlassFactors>(&self, factors: &F, wo: Vec3, wi: Vec3) -> Option<(usize, Vec2)> {
        (self.scheme != Compensation::Turquin && self.compensates(wo, wi)).then(|| {
            let a = side_of(wo);
            (a, self.lobes.values_at(factors, a, wo.z.abs()))
        })
    }

    /// f_ss plus the added lobe of the light's side, for a view `(a, vo)` of
    /// [`Self::view_values`].
    #[inline(always)]
    fn added_f<F: GlassFactors>(
        &self,
        factors: &F,
        (a, vo): (usize, Vec2),
        wo: Vec3,
        wi: Vec3,
        f_ss: Vec3,
    ) -> Vec3 {
        f_ss + Vec3::splat(self.lobes.added(factors, a, crossing(wo, wi), vo, wi.z.abs()))
    }

    /// The sampling mixture's density from single scattering's `pdf_ss`, for a view `(a, vo)`
    /// of [`Self::view_values`].
    #[inline(always)]
    fn mixture_density<F: GlassFactors>(
        &self,
        factors: &F,
        (a, vo): (usize, Vec2),
        wo: Vec3,
        wi: Vec3,
        pdf_ss: f32,
    ) -> f32 {
        DielectricLobes::mixture_pdf(factors, a, self.lobes.mixture(a, vo), wo, wi, pdf_ss)
    }

    /// f at valid directions from single scattering's `f_ss` at the same directions: f_ss
    /// scaled by Turquin's factor, or f_ss plus the added lobe of the light's side where the
    /// lobes answer. Every evaluation of the BSDF (`eval`, the batch calls; `eval_with_pdf`
    /// through [`Self::compensated`]) ends with this expression; the tables' values at the
    /// hit from `factors` (the lobes, or a batch's [`GlassColumn`]).
    #[inline(always)]
    pub(super) fn compensated_f<F: GlassFactors>(&self, factors: &F, wo: Vec3, wi: Vec3, f_ss: Vec3) -> Vec3 {
        if self.scheme == Compensation::Turquin {
            return Self::scaled(f_ss, self.turquin_factor(factors, wo));
        }
        self.view_values(factors, wo, wi).map_or(f_ss, |v| self.added_f(factors, v, wo, wi, f_ss))
    }

    /// The density at valid directions from single scattering's `pdf_ss` at the same
    /// directions: the sampling mixture's density where the lobes answer (not Turquin's), else
    /// `pdf_ss`. Every density of the BSDF but the sample's (`pdf`, the batch calls;
    /// `eval_with_pdf` through [`Self::compensated`]) ends with this expression.
    #[inline(always)]
    pub(super) fn compensated_pdf<F: GlassFactors>(
        &self,
        factors: &F,
        wo: Vec3,
        wi: Vec3,
        pdf_ss: f32,
    ) -> f32 {
        self.view_values(factors, wo, wi).map_or(pdf_ss, |v| self.mixture_density(factors, v, wo, wi, pdf_ss))
    }

    /// [`Self::compensated_f`] and [`Self::compensated_pdf`] with the lobes read at the view
    /// once (`eval_with_pdf`, scalar and batch).
    #[inline(always)]
    pub(super) fn compensated<F: GlassFactors>(
        &self,
        factors: &F,
        wo: Vec3,
        wi: Vec3,
        f_ss: Vec3,
        pdf_ss: f32,
    ) -> (Vec3, f32) {
        if self.scheme == Compensation::Turquin {
            return (Self::scaled(f_ss, self.turquin_factor(factors, wo)), pdf_ss);
        }
        match self.view_values(factors, wo, wi) {
            Some(v) => {
                (self.added_f(factors, v, wo, wi, f_ss), self.mixture_density(factors, v, wo, wi, pdf_ss))
            }
            None => (f_ss, pdf_ss),
        }
    }

    /// Turquin's sample weight from single scattering's sample `weight` (not a Dirac lobe's)
    /// for the view `wo` (valid); `None` where not finite. Every sample of Turquin's scheme
    /// (`sample`, the batch call) ends with this expression.
    #[inline(always)]
    pub(super) fn turquin_weight(&self, wo: Vec3, weight: Vec3) -> Option<Vec3> {
        let weight = weight * self.turquin_factor(&self.lobes, wo);
        weight.is_finite().then_some(weight)
    }

    /// Single scattering's density at valid directions off the horizon of a rough surface:
    /// its research-layer density without the trait's repeated checks (the same bits as
    /// `self.single.pdf(wo, wi)`).
    #[inline(always)]
    fn single_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let surface = self.single.surface();
        let pdf = SingleScattering::new(*surface.slope(), *surface.material()).pdf_unchecked(wo, wi);
        if pdf.is_finite() { pdf } else { 0.0 }
    }
}

impl<S: MicrosurfaceSlope> Bsdf for Compensated<S, Dielectric> {
    #[inline]
    fn flags(&self) -> BsdfFlags {
        self.single.flags()
    }

    #[inline]
    fn eval_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> BsdfValue {
        unit_directions!(wo, wi, NOTHING, self.eval_keyed(wo, wi, key));
        let v = self.single.eval_valid(wo, wi, key);
        BsdfValue { f: self.compensated_f(&self.lobes, wo, wi, v.f), ..v }
    }

    #[inline]
    fn sample_keyed(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample> {
        unit_view!(wo, uc, u, None, self.sample_keyed(wo, uc, u, key));
        if self.scheme == Compensation::Turquin {
            let s = self.single.sample_keyed(wo, uc, u, key)?;
            if s.flags.specular {
                return Some(s);
            }
            return Some(BsdfSample { weight: self.turquin_weight(wo, s.weight)?, ..s });
        }
        let lobes = &self.lobes;
        if !lobes.active || wo.z == 0.0 {
            return self.single.sample_keyed(wo, uc, u, key);
        }
        let a = side_of(wo);
        let vo = lobes.values_at(lobes, a, wo.z.abs());
        let p = lobes.mixture(a, vo);
        let (wi, f_cos_ss, pdf_ss) = if uc < p.x {
            // the single-scattering lobe: its sample carries f·|cos θi| (weight × pdf) and its
            // density
            let s = self.single.sample_keyed(wo, (uc / p.x).min(ONE_MINUS_ULP), u, key)?;
            (s.wi, s.weight * s.pdf, s.pdf)
        } else {
            // the added lobe of the light's side, and one of its four rows' profiles by the
            // rest of uc (its cumulated probabilities scaled to the lobe's share: no division)
            let c = usize::from(uc >= p.x + p.y);
            let (start, share) = if c == 0 { (p.x, p.y) } else { (p.x + p.y, p.z) };
            let cum = lobes.corners[a][c] * share;
            let v = uc - start;
            let corner = usize::from(v >= cum.x) + usize::from(v >= cum.y) + usize::from(v >= cum.z);
            let n = lobes.corner + [0, 1, N, N + 1][corner];
            let w = lobes.side(a ^ c).rows[n].profiles[c].sample(u)?;
            // its direction on the view's side, mirrored through the interface for a
            // transmission
            let wi = if (wo.z > 0.0) == (c == 0) { w } else { -w };
            // f and the density as eval and pdf compute them
            (wi, self.single.eval_keyed(wo, wi, key).f * wi.z.abs(), self.single_pdf(wo, wi))
        };
        if wi.z == 0.0 {
            return None;
        }
        let c = crossing(wo, wi);
        let f_cos = f_cos_ss + Vec3::splat(lobes.added(lobes, a, c, vo, wi.z.abs()) * wi.z.abs());
        let eta = lobes.transmitted_eta[a];
        mixture_sample(wo, wi, f_cos, DielectricLobes::mixture_pdf(lobes, a, p, wo, wi, pdf_ss), eta)
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        unit_directions!(wo, wi, 0.0, self.pdf(wo, wi));
        if self.scheme == Compensation::Turquin || !self.compensates(wo, wi) {
            return self.single.pdf(wo, wi);
        }
        self.compensated_pdf(&self.lobes, wo, wi, self.single_pdf(wo, wi))
    }

    #[inline]
    fn eval_with_pdf_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> (BsdfValue, f32) {
        unit_directions!(wo, wi, (NOTHING, 0.0), self.eval_with_pdf_keyed(wo, wi, key));
        let (v, pdf_ss) = self.single.eval_with_pdf_keyed(wo, wi, key);
        let (f, pdf) = self.compensated(&self.lobes, wo, wi, v.f, pdf_ss);
        (BsdfValue { f, ..v }, pdf)
    }
}
