//! The node axes of the albedo tables, shared by the tables' lookups and the compensated
//! lobes that interpolate a precomputed row of them.

/// The conductor tables' scale-invariant direction coordinate x = √(μ (1 + α)/(μ + α)) ∈ [0, 1]
/// (μ = x² α/(1 + α − x²)), for μ ∈ [0, 1] and α > 0: the sharp feature of the F = 1 albedo
/// at μ ≈ α sits at the same x for every α (see `DESIGN.md`, "Single-scattering albedo
/// tables").
#[inline(always)]
pub(crate) fn scale_invariant_direction(mu: f32, alpha: f32) -> f32 {
    (mu * (1.0 + alpha) / (mu + alpha)).min(1.0).sqrt()
}

/// The cell index i ∈ [0, `nodes` − 2] and the fraction within it of the fractional node
/// coordinate t ∈ [0, `nodes` − 1] of an axis with `nodes` nodes (t beyond the last node
/// extrapolates the last cell; callers clamp their coordinates to [0, 1] first).
#[inline(always)]
pub(crate) fn node_cell(t: f32, nodes: usize) -> (usize, f32) {
    let i = (t as usize).min(nodes - 2);
    (i, t - i as f32)
}
