//! The node axes of the albedo tables, shared by the tables' lookups and the compensated
//! lobes that interpolate a precomputed row of them.

use glam::Vec4;

/// The conductor tables' scale-invariant direction coordinate x = √(μ (1 + α)/(μ + α)) ∈ [0, 1]
/// (μ = x² α/(1 + α − x²)), for μ ∈ [0, 1] and α > 0: the sharp feature of the F = 1 albedo
/// at μ ≈ α sits at the same x for every α (see `DESIGN.md`, "Single-scattering albedo
/// tables").
#[inline(always)]
pub(crate) fn scale_invariant_direction(mu: f32, alpha: f32) -> f32 {
    DirectionAxis::new(alpha).coordinate(mu)
}

/// The scale-invariant direction axis x = √(μ (1 + α)/(μ + α)) at one roughness α, with 1 + α
/// computed once: the axis of the conductor tables and of the dielectric walk tables, read per
/// hit by the compensated lobes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DirectionAxis {
    alpha: f32,
    one_plus_alpha: f32,
}

impl DirectionAxis {
    /// The axis of a Dirac lobe (never read; α = 1).
    pub(crate) const NONE: Self = Self { alpha: 1.0, one_plus_alpha: 2.0 };

    /// The axis at roughness α > 0.
    #[inline(always)]
    pub(crate) fn new(alpha: f32) -> Self {
        Self { alpha, one_plus_alpha: 1.0 + alpha }
    }

    /// The coordinates x of two cosines in [0, 1] from one division.
    #[inline(always)]
    pub(crate) fn coordinates(self, mu_o: f32, mu_i: f32) -> (f32, f32) {
        let (so, si) = (mu_o + self.alpha, mu_i + self.alpha);
        let inv = self.one_plus_alpha / (so * si);
        ((mu_o * si * inv).min(1.0).sqrt(), (mu_i * so * inv).min(1.0).sqrt())
    }

    /// The coordinate x of one cosine in [0, 1].
    #[inline(always)]
    pub(crate) fn coordinate(self, mu: f32) -> f32 {
        (mu * self.one_plus_alpha / (mu + self.alpha)).min(1.0).sqrt()
    }
}

/// The cell index i ∈ [0, `nodes` − 2] and the fraction within it of the fractional node
/// coordinate t ∈ [0, `nodes` − 1] of an axis with `nodes` ≤ 256 nodes (t beyond the last node
/// extrapolates the last cell; callers clamp their coordinates to [0, 1] first).
#[inline(always)]
pub(crate) fn node_cell(t: f32, nodes: usize) -> (usize, f32) {
    let i = floor_index(t, nodes - 2);
    (i, t - i as f32)
}

/// ⌊t⌋ clamped to [0, `last`] (NaN and negative t give 0), for `last` < 256: through the
/// saturating conversion to u8, which compiles to a clamp and one conversion instruction (the
/// saturating conversion to usize costs about a dozen instructions, to u32 about eight).
#[inline(always)]
pub(crate) fn floor_index(t: f32, last: usize) -> usize {
    debug_assert!(last < 256);
    usize::from(t as u8).min(last)
}

/// 1.5 · 2²³: a float x ∈ [−2²², 2²²) plus this lies in [2²³, 2²⁴), where the floats are the
/// integers: the sum is x rounded to an integer n (ties to even), and its bits are those of
/// this constant plus n.
const ROUND: f32 = 12_582_912.0;

/// The cells of four fractional node coordinates at once, in SIMD lanes, branch-free: for each
/// lane t ∈ [0, 2²²) the cell n = round(t − ½) ≤ `last_cell` (a whole number ≥ 0: t − ½ ≥ −½
/// rounds to 0 or above; `last_cell` < 2²²) and the fraction t − n, in [0, 1] for
/// t ∈ [0, `last_cell` + 1] (n = ⌊t⌋, but at a whole t, where n may be the cell below with
/// fraction 1: the same interpolant). The rounding adds and subtracts [`ROUND`] (exact);
/// [`lane_indices`] reads n as an integer.
#[inline(always)]
pub(crate) fn node_cells(t: Vec4, last_cell: Vec4) -> (Vec4, Vec4) {
    let n = ((t - Vec4::splat(0.5)).min(last_cell) + Vec4::splat(ROUND)) - Vec4::splat(ROUND);
    (n, t - n)
}

/// The whole numbers n ∈ [0, 2²²) of the lanes of [`node_cells`] (or of sums of such cells'
/// whole multiples below 2²²) as indices: from the bits of n + [`ROUND`] (one SIMD addition;
/// the indices a caller does not read cost nothing).
#[inline(always)]
pub(crate) fn lane_indices(n: Vec4) -> [usize; 4] {
    (n + Vec4::splat(ROUND)).to_array().map(|x| (x.to_bits() - ROUND.to_bits()) as usize)
}

/// Below this value the log/√ blend axis [`log_sqrt_blend`] is 0 (its lookups read the first
/// node).
pub(crate) const BLEND_FLOOR: f32 = 1e-6;
/// ln(1/[`BLEND_FLOOR`]).
const LN_INV_BLEND_FLOOR: f32 = 13.815_511;
/// √[`BLEND_FLOOR`].
const SQRT_BLEND_FLOOR: f32 = 1e-3;

/// The dielectric tables' log/√ blend B(v) = ½ ln(v/vf)/ln(1/vf) + ½ (√v − √vf)/(1 − √vf)
/// ∈ [0, 1] for v ∈ [vf, 1], vf = [`BLEND_FLOOR`] (0 below vf): the logarithmic half resolves
/// features at a scale set by v itself (the masking at μ ≈ α, the slow decay of the
/// transmission as μ → 0, small α), the square-root half the Fresnel term's dependence on μ
/// (see `DESIGN.md`, "Dielectric albedo tables").
#[inline(always)]
pub(crate) fn log_sqrt_blend(v: f32) -> f32 {
    let v = v.max(BLEND_FLOOR);
    (0.5 / LN_INV_BLEND_FLOOR) * (v * (1.0 / BLEND_FLOOR)).ln()
        + (0.5 / (1.0 - SQRT_BLEND_FLOOR)) * (v.sqrt() - SQRT_BLEND_FLOOR)
}

/// The direction node the critical cosine sits on in the dielectric tables of internal
/// incidence (η < 1), as a fraction of the axis: 7/15.
pub(crate) const KNEE: f32 = 7.0 / 15.0;

/// The direction axis of a dielectric table row: from outside (η ≥ 1) x = B(μ); from inside
/// (η < 1) the critical cosine μc = √(1 − η²) is pinned to the node [`KNEE`]:
/// x = KNEE · (½ B(t) + ½ (1 − √(1 − t))) with t = μ/μc for μ ≤ μc, and
/// x = KNEE + (1 − KNEE) √((μ − μc)/(1 − μc)) above (so the onset of total internal
/// reflection sits on the same node in every η row, 1 − F ∝ √(μ − μc) is linear in x above it,
/// and the rough lobe's fall from total reflection just below it is resolved as well).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum DielectricDirection {
    /// x = B(μ).
    Outside,
    /// The knee axis of the critical cosine `mu_c` > 0, with 1/μc and 1/(1 − μc).
    Inside { mu_c: f32, inv_mu_c: f32, inv_above: f32 },
}

impl DielectricDirection {
    /// The axis of light seeing the relative index η ∈ [1/3, 3].
    #[inline(always)]
    pub(crate) fn of(eta: f32) -> Self {
        if eta >= 1.0 {
            return Self::Outside;
        }
        // η < 1 in f32 is at most 1 − 2⁻²⁴: μc ≥ 3.4e-4
        let mu_c = ((1.0 - eta) * (1.0 + eta)).sqrt();
        Self::Inside { mu_c, inv_mu_c: 1.0 / mu_c, inv_above: 1.0 / (1.0 - mu_c) }
    }

    /// x ∈ [0, 1] of μ ∈ [0, 1].
    #[inline(always)]
    pub(crate) fn coordinate(&self, mu: f32) -> f32 {
        match *self {
            Self::Outside => log_sqrt_blend(mu),
            Self::Inside { mu_c, inv_mu_c, inv_above } => {
                if mu <= mu_c {
                    let t = mu * inv_mu_c;
                    KNEE * (0.5 * log_sqrt_blend(t) + 0.5 * (1.0 - (1.0 - t).max(0.0).sqrt()))
                } else {
                    KNEE + (1.0 - KNEE) * ((mu - mu_c) * inv_above).min(1.0).sqrt()
                }
            }
        }
        .min(1.0)
    }
}
