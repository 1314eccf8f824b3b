//! The μ profiles of the separable compensation lobes.
//!
//! A lobe's value is a row g of node values linear in x on the albedo tables' scale-invariant
//! direction axis x = √(μ (1 + α)/(μ + α)) ([`DirectionAxis`]: the cell of a cosine costs a
//! division and a square root, shared by two cosines), normalized by its exact cosine-weighted
//! average ([`profile_average`]). What only has to be *some* exact density — the samplers of the
//! lobes and the mixture's lobe probabilities — lives on a per-instance **uniform μ axis**
//! ([`mu_cell`]: one multiply and one truncation per lookup, no division, no root, no branch):
//! [`MuProfile`] samples g(μ) μ by cells of that axis (alias method) and gives its density.

use crate::albedo::floor_index;
use crate::special::GAUSS_LEGENDRE_8;
use crate::special::sin_cos_turns;
use core::f64::consts::PI;
use glam::{Vec2, Vec3};

/// The largest f32 below 1.
const ONE_MINUS_ULP: f32 = 1.0 - f32::EPSILON / 2.0;

/// The scale-invariant direction axis x = √(μ (1 + α)/(μ + α)) of `N`-node rows at a fixed
/// roughness α > 0 (node i at x = i/(N − 1)); (N − 1)² (1 + α) is folded into the root, so that
/// the fractional node t = (N − 1) x = √(min(μ · (N − 1)²(1 + α)/(μ + α), (N − 1)²)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DirectionAxis<const N: usize> {
    alpha: f32,
    /// (N − 1)² (1 + α).
    scale: f32,
}

impl<const N: usize> DirectionAxis<N> {
    /// The last node index, as a float.
    const LAST: f32 = (N - 1) as f32;

    /// The axis at roughness α > 0.
    pub(crate) fn new(alpha: f32) -> Self {
        Self { alpha, scale: Self::LAST * Self::LAST * (1.0 + alpha) }
    }

    /// The cell i ∈ [0, N − 2] of μ ∈ [0, 1] and the fraction within it.
    #[inline(always)]
    pub(crate) fn cell(&self, mu: f32) -> (usize, f32) {
        Self::split((mu * self.scale / (mu + self.alpha)).min(Self::LAST * Self::LAST).sqrt())
    }

    /// The cell and fraction of the fractional node t ∈ [0, N − 1].
    #[inline(always)]
    fn split(t: f32) -> (usize, f32) {
        let i = floor_index(t, N - 2);
        (i, t - i as f32)
    }
}

/// The value at (cell, fraction) of a row of node values, linear in x.
#[inline(always)]
pub(crate) fn row_at<const N: usize>(row: &[f32; N], (i, f): (usize, f32)) -> f32 {
    row[i] + f * (row[i + 1] - row[i])
}

/// The primitives of the closed-form integrals over a piece of the direction axis at roughness
/// α (in f64): with μ = α X/(k − X), X = x², k = 1 + α, and g = a + b x on the piece,
///
/// ∫ (a + b x) d(μ²) = a Δμ² + b Δ(x μ²) − b α² ΔP,   P(x) = ∫ x⁴/(k − x²)² dx
///                   = x + k x/(2 (k − x²)) − (3√k/2) atanh(x/√k).
///
/// The differences of P across a cell lose at most log₂(1/α) bits (1e-13 at α = 1e-3).
struct Primitives {
    alpha: f64,
    k: f64,
    sk: f64,
}

impl Primitives {
    fn new(alpha: f32) -> Self {
        let alpha = f64::from(alpha);
        let k = 1.0 + alpha;
        Self { alpha, k, sk: k.sqrt() }
    }

    /// μ² at x ∈ [0, 1] (1 at x = 1).
    fn mu_sq(&self, x: f64) -> f64 {
        if x >= 1.0 {
            return 1.0;
        }
        let m = self.alpha * x * x / (self.k - x * x);
        m * m
    }

    /// x of μ ∈ [0, 1].
    fn x_of(&self, mu: f64) -> f64 {
        (mu * self.k / (mu + self.alpha)).min(1.0).sqrt()
    }

    fn p(&self, x: f64) -> f64 {
        x + self.k * x / (2.0 * (self.k - x * x)) - 1.5 * self.sk * (x / self.sk).atanh()
    }

    /// ∫ g d(μ²) over [x0, x1] ⊂ one cell [xa, xb] of the row g (ga at xa, gb at xb).
    fn mass(&self, (xa, ga): (f64, f64), (xb, gb): (f64, f64), x0: f64, x1: f64) -> f64 {
        let b = (gb - ga) / (xb - xa);
        let a = ga - b * xa;
        let (m0, m1) = (self.mu_sq(x0), self.mu_sq(x1));
        // ≥ 0 for g ≥ 0; rounding can leave −1e-20 in a cell of g = 0
        (a * (m1 - m0) + b * (x1 * m1 - x0 * m0) - b * self.alpha * self.alpha * (self.p(x1) - self.p(x0)))
            .max(0.0)
    }
}

/// x of node i of an `n`-node axis (exactly 1 at the last).
fn node_x(i: usize, n: usize) -> f64 {
    if i == n - 1 { 1.0 } else { i as f64 / (n - 1) as f64 }
}

/// ḡ = 2∫₀¹ g(μ) μ dμ = ∫ g d(μ²) of the row g (node values at x = i/(N − 1), linear in x
/// between them) at roughness α > 0, in closed form (see [`Primitives`]), in f64.
pub(crate) fn profile_average<const N: usize>(g: &[f32; N], alpha: f32) -> f64 {
    let prim = Primitives::new(alpha);
    (0..N - 1)
        .map(|i| {
            let (xa, xb) = (node_x(i, N), node_x(i + 1, N));
            prim.mass((xa, f64::from(g[i])), (xb, f64::from(g[i + 1])), xa, xb)
        })
        .sum()
}

/// 2∫₀¹ g(x(μ)) μ dμ of a vector function g of the direction coordinate x = √(μ (1 + α)/(μ + α))
/// at roughness α > 0, for g smooth on each of the `cells` equal cells of x (the pieces of a
/// row interpolated on a `cells + 1`-node axis, or on a coarser axis whose cells are unions of
/// these): 8-point Gauss–Legendre per cell in u = √μ, where x(u²) is analytic and the measure
/// 4u³ du smooth (exact to rounding for the piecewise-linear rows of [`profile_average`]).
pub(crate) fn axis_average<const L: usize>(
    alpha: f64,
    cells: usize,
    g: impl Fn(f64) -> [f64; L],
) -> [f64; L] {
    let k = 1.0 + alpha;
    let mu_of = |x: f64| {
        let big_x = x * x;
        if big_x >= 1.0 { 1.0 } else { alpha * big_x / (k - big_x) }
    };
    let mut out = [0.0; L];
    for i in 0..cells {
        let (ua, ub) = (mu_of(i as f64 / cells as f64).sqrt(), mu_of((i + 1) as f64 / cells as f64).sqrt());
        let (mid, half) = (0.5 * (ua + ub), 0.5 * (ub - ua));
        for &(t, w) in &GAUSS_LEGENDRE_8 {
            for u in [mid - half * t, mid + half * t] {
                let mu = u * u;
                let x = (mu * k / (mu + alpha)).min(1.0).sqrt();
                let v = g(x);
                let weight = w * half * 4.0 * u * u * u;
                for (o, v) in out.iter_mut().zip(v) {
                    *o += weight * v;
                }
            }
        }
    }
    out
}

/// The weights w_i = 2∫₀¹ h_i(x(μ)) μ dμ of the hat functions h_i of an `N`-node axis
/// (node i at x = i/(N − 1)) on the direction axis x(μ) = ½ √(μ (1 + α)/(μ + α)) + ½ μ at
/// roughness α > 0 (the loss tables' axis of internal incidence), so that the average
/// 2∫ g μ dμ of a row g linear in x between its nodes is Σ w_i g_i: 8-point Gauss–Legendre per
/// cell in u = √μ, where x(u²) is analytic and the measure 4u³ du smooth, with the cells' ends
/// μ(x) found by bisection (f64).
pub(crate) fn mixed_axis_weights<const N: usize>(alpha: f64) -> [f64; N] {
    let k = 1.0 + alpha;
    let x_of = |mu: f64| 0.5 * (mu * k / (mu + alpha)).min(1.0).sqrt() + 0.5 * mu;
    let mu_of = |x: f64| {
        if x <= 0.0 {
            return 0.0;
        }
        if x >= 1.0 {
            return 1.0;
        }
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..64 {
            let mid = 0.5 * (lo + hi);
            if x_of(mid) < x { lo = mid } else { hi = mid }
        }
        0.5 * (lo + hi)
    };
    let last = (N - 1) as f64;
    let mut w = [0.0; N];
    for i in 0..N - 1 {
        let (ua, ub) = (mu_of(node_x(i, N)).sqrt(), mu_of(node_x(i + 1, N)).sqrt());
        let (mid, half) = (0.5 * (ua + ub), 0.5 * (ub - ua));
        for &(t, gw) in &GAUSS_LEGENDRE_8 {
            for u in [mid - half * t, mid + half * t] {
                let f = (x_of(u * u) * last - i as f64).clamp(0.0, 1.0);
                let weight = gw * half * 4.0 * u * u * u;
                w[i] += weight * (1.0 - f);
                w[i + 1] += weight * f;
            }
        }
    }
    w
}

/// Cells of the uniform μ axis: cell k holds μ ∈ [k/M, (k + 1)/M) (μ = 1 the last).
pub(crate) const MU_CELLS: usize = 32;

/// The cell ⌊M μ⌋ ∈ [0, M − 1] of the uniform μ axis of a cosine μ ∈ [0, 1] (beyond it the
/// nearest cell, NaN the first): one multiply and one truncation.
#[inline(always)]
pub(crate) fn mu_cell(mu: f32) -> usize {
    floor_index(mu * MU_CELLS as f32, MU_CELLS - 1)
}

/// The density (intercept + slope μ²) μ ≥ 0 of a [`MuProfile::line`] (or of a mixture of
/// lines) at |cos θ| = μ in its cell.
#[inline(always)]
pub(crate) fn line_pdf(line: Vec2, mu: f32) -> f32 {
    // (the line is ≥ 0 on its cell; rounding may leave −1e-12 at a node of value 0)
    ((line.x + line.y * (mu * mu)) * mu).max(0.0)
}

/// The cosine at the centre of cell k of the uniform μ axis.
pub(crate) fn mu_cell_centre(k: usize) -> f32 {
    (k as f32 + 0.5) / MU_CELLS as f32
}

/// m_k = ∫ g d(μ²) over each cell of the uniform μ axis, for the row g at roughness α > 0 (in
/// closed form, the pieces of the direction axis inside each cell; Σ m_k = ḡ up to rounding).
pub(crate) fn mu_cell_masses<const N: usize>(g: &[f32; N], alpha: f32) -> [f64; MU_CELLS] {
    let prim = Primitives::new(alpha);
    let mut out = [0.0; MU_CELLS];
    for (k, m) in out.iter_mut().enumerate() {
        let (lo, hi) = (k as f64 / MU_CELLS as f64, (k + 1) as f64 / MU_CELLS as f64);
        let (x0, x1) = (prim.x_of(lo), prim.x_of(hi));
        for i in 0..N - 1 {
            let (xa, xb) = (node_x(i, N), node_x(i + 1, N));
            let (a, b) = (x0.max(xa), x1.min(xb));
            if a < b {
                *m += prim.mass((xa, f64::from(g[i])), (xb, f64::from(g[i + 1])), a, b);
            }
        }
    }
    out
}

/// One column of the alias table: the cell itself below `threshold`, `alias` above it, with the
/// reciprocals that rescale the column's uniform to [0, 1) on either side.
#[derive(Debug, Clone, Copy, PartialEq)]
struct AliasColumn {
    threshold: f32,
    /// 1/threshold (0 for threshold 0).
    below: f32,
    /// 1/(1 − threshold) (0 for threshold 1).
    above: f32,
    alias: u32,
}

/// One cell [k/M, (k + 1)/M] of the uniform μ axis of a [`MuProfile`]: its density ρ in s = μ²,
/// linear from `start` to `end` (the nodes' values), as intercept and slope in s for the
/// density's lookup and as the pieces of the inversion for the sampler.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ProfileCell {
    /// ρ/π at s = 0 of the cell's line: the density is (intercept + slope μ²) μ.
    intercept: f32,
    /// The slope in s of ρ/π.
    slope: f32,
    /// ρ at the cell's ends (unnormalized node values; only their ratio matters).
    start: f32,
    end: f32,
}

/// The sampler of a lobe's μ profile on the uniform μ axis, a density in s = μ² that is
/// continuous and linear in s on each cell [k/M, (k + 1)/M] of μ, with node values that follow
/// the profile's mass ρ_k = (m_{k−1}/Δs_{k−1} + m_k/Δs_k)/2 (m_k = ∫_cell g d(μ²): the mean of the
/// profile over the two cells at the node); φ uniform. Its density in solid angle is ρ(μ²) μ/π.
/// A cell is chosen by its mass (the alias method: a column ⌊M u⌋, then the column's cell or its
/// alias by the rest of u), s within it by inverting the linear density (one root, one
/// division). Density and sampler are branch-free: one multiply and one truncation find a cell
/// or a column, no search (the alias method is not monotone in u: the lobes it samples carry a
/// small part of the energy, where a renderer's stratification of u matters little).
/// Continuous rather than piecewise constant, so that quadratures of the density converge (a
/// step at each of the 32 cell boundaries misled the tests' adaptive quadrature of ∫pdf by 1e-3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MuProfile {
    columns: [AliasColumn; MU_CELLS],
    cells: [ProfileCell; MU_CELLS],
}

impl MuProfile {
    /// No lobe: every density 0 (and a sampler that is never asked).
    pub(crate) const EMPTY: Self = Self {
        columns: [AliasColumn { threshold: 1.0, below: 1.0, above: 0.0, alias: 0 }; MU_CELLS],
        cells: [ProfileCell { intercept: 0.0, slope: 0.0, start: 1.0, end: 1.0 }; MU_CELLS],
    };

    /// The sampler of a profile with the cell masses `masses` (≥ 0; [`Self::EMPTY`] if they sum
    /// to 0). The density is normalized over the cells' masses as stored in f32 (the
    /// probabilities the alias table actually gives).
    pub(crate) fn new(masses: &[f64; MU_CELLS]) -> Self {
        let m = MU_CELLS as f64;
        // Δs of cell k: ((k + 1)² − k²)/M²
        let width = |k: usize| (2 * k + 1) as f64 / (m * m);
        let mean = |k: usize| masses[k].max(0.0) / width(k);
        // node values: the mean of the two cells' densities at an inner node
        let nodes: [f64; MU_CELLS + 1] = core::array::from_fn(|k| match k {
            0 => mean(0),
            MU_CELLS => mean(MU_CELLS - 1),
            _ => 0.5 * (mean(k - 1) + mean(k)),
        });
        let cell_mass: [f64; MU_CELLS] = core::array::from_fn(|k| 0.5 * (nodes[k] + nodes[k + 1]) * width(k));
        let total: f64 = cell_mass.iter().sum();
        // (NaN fails too)
        if total.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            return Self::EMPTY;
        }
        // Vose's alias method, in f64
        let mut scaled: [f64; MU_CELLS] = core::array::from_fn(|k| cell_mass[k] / total * m);
        let mut alias: [usize; MU_CELLS] = core::array::from_fn(|k| k);
        let mut threshold = [1.0f64; MU_CELLS];
        // the work lists of the cells below and above the mean, as fixed stacks (no allocation)
        let (mut small, mut large) = ([0usize; MU_CELLS], [0usize; MU_CELLS]);
        let (mut n_small, mut n_large) = (0, 0);
        for (k, &p) in scaled.iter().enumerate() {
            if p < 1.0 {
                small[n_small] = k;
                n_small += 1;
            } else {
                large[n_large] = k;
                n_large += 1;
            }
        }
        while n_small > 0 && n_large > 0 {
            n_small -= 1;
            let (s, l) = (small[n_small], large[n_large - 1]);
            threshold[s] = scaled[s];
            alias[s] = l;
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                n_large -= 1;
                small[n_small] = l;
                n_small += 1;
            }
        }
        // (what is left holds 1 up to rounding)
        let mut columns = Self::EMPTY.columns;
        for (k, c) in columns.iter_mut().enumerate() {
            let t = threshold[k].clamp(0.0, 1.0) as f32;
            *c = AliasColumn {
                threshold: t,
                below: if t > 0.0 { 1.0 / t } else { 0.0 },
                above: if t < 1.0 { 1.0 / (1.0 - t) } else { 0.0 },
                alias: alias[k] as u32,
            };
        }
        // the probability each cell receives from the stored thresholds, and the density that
        // gives it: the cell's line scaled by prob/mass
        let mut prob = [0.0f64; MU_CELLS];
        for (k, c) in columns.iter().enumerate() {
            prob[k] += f64::from(c.threshold) / m;
            prob[c.alias as usize] += (1.0 - f64::from(c.threshold)) / m;
        }
        let cells = core::array::from_fn(|k| {
            let scale = if cell_mass[k] > 0.0 { prob[k] / (cell_mass[k] * PI) } else { 0.0 };
            let (s0, s1) = ((k as f64 / m).powi(2), ((k + 1) as f64 / m).powi(2));
            let slope = (nodes[k + 1] - nodes[k]) / (s1 - s0);
            ProfileCell {
                intercept: ((nodes[k] - slope * s0) * scale) as f32,
                slope: (slope * scale) as f32,
                start: nodes[k] as f32,
                end: nodes[k + 1] as f32,
            }
        });
        Self { columns, cells }
    }

    /// The density ρ(μ²) μ/π ≥ 0 of a direction with |cos θ| = μ on the hemisphere it was
    /// sampled on: one multiply and one truncation to find the cell, a line in μ².
    #[inline(always)]
    pub(crate) fn pdf(&self, mu: f32) -> f32 {
        line_pdf(self.line(mu_cell(mu)), mu)
    }

    /// The line of cell k ([`mu_cell`]) in μ²: (intercept, slope), the density
    /// ([`line_pdf`]) (intercept + slope μ²) μ. A mixture of profiles has the mixture of their
    /// lines on every cell.
    #[inline(always)]
    pub(crate) fn line(&self, k: usize) -> Vec2 {
        let c = &self.cells[k];
        Vec2::new(c.intercept, c.slope)
    }

    /// A direction in the upper hemisphere from u ∈ [0, 1)²: u.x picks a column and, with what
    /// is left of it, the column's cell or its alias and μ² within that cell; u.y the azimuth.
    /// `None` on the horizon (μ = 0). Branch-free.
    #[inline(always)]
    pub(crate) fn sample(&self, u: Vec2) -> Option<Vec3> {
        let t = u.x * MU_CELLS as f32;
        let k = floor_index(t, MU_CELLS - 1);
        let r = t - k as f32;
        let c = &self.columns[k];
        let (cell, v) =
            if r < c.threshold { (k, r * c.below) } else { (c.alias as usize, (r - c.threshold) * c.above) };
        let v = v.min(ONE_MINUS_ULP);
        // s within the cell where the linear density ρ0 (1 − w) + ρ1 w has the CDF v:
        // w = v (ρ0 + ρ1)/(ρ0 + √(ρ0² + v (ρ1² − ρ0²))) (no cancellation; w = v for ρ0 = ρ1)
        let ProfileCell { start: r0, end: r1, .. } = self.cells[cell];
        let denominator = r0 + (r0 * r0 + v * (r1 * r1 - r0 * r0)).sqrt();
        // (0 only for v = 0 at a node of value 0, where w = v = 0)
        let w = if denominator > 0.0 { (v * (r0 + r1) / denominator).min(1.0) } else { v };
        // μ² = (cell² + w ((cell + 1)² − cell²))/M²
        let kf = cell as f32;
        let mu_sq = (kf * kf + w * (2.0 * kf + 1.0)) * (1.0 / (MU_CELLS * MU_CELLS) as f32);
        let mu = mu_sq.sqrt();
        let sin_theta = (1.0 - mu_sq).max(0.0).sqrt();
        let (sin_phi, cos_phi) = sin_cos_turns(u.y);
        (mu > 0.0).then(|| Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, mu))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form average equals a brute-force quadrature of the same interpolant (in
    /// f64, midpoint rule in ln μ), for rows with and without zero cells, on the conductor's
    /// 32-node and the dielectric's 16-node axes; the uniform-μ cell masses sum to it; the
    /// sampler's densities integrate to 1 over the hemisphere (Σ d_k Δμ²_k = 1) and follow the
    /// masses.
    #[test]
    fn closed_form_average_matches_quadrature() {
        fn check<const N: usize>(rows: &[[f32; N]]) {
            for alpha in [1e-3f32, 0.05, 0.37, 1.0] {
                for row in rows {
                    let average = profile_average(row, alpha);
                    let a = f64::from(alpha);
                    let last = (N - 1) as f64;
                    let lookup = |mu: f64| {
                        let t = (mu * (1.0 + a) / (mu + a)).min(1.0).sqrt() * last;
                        let i = (t as usize).min(N - 2);
                        let (g0, g1) = (f64::from(row[i]), f64::from(row[i + 1]));
                        g0 + (t - i as f64) * (g1 - g0)
                    };
                    // ∫ g(μ) 2μ dμ = 2∫ g(μ) μ² d(ln μ) over ln μ ∈ [ln 1e-9, 0]
                    let (lo, n) = (1e-9f64.ln(), 200_000);
                    let h = -lo / n as f64;
                    let sum: f64 = (0..n)
                        .map(|k| {
                            let mu = (lo + (k as f64 + 0.5) * h).exp();
                            2.0 * lookup(mu) * mu * mu * h
                        })
                        .sum();
                    assert!(
                        (sum - average).abs() <= 1e-7 * average.max(1e-3),
                        "N = {N} α = {alpha}: {sum:e} vs {average:e}"
                    );
                    let masses = mu_cell_masses(row, alpha);
                    let total: f64 = masses.iter().sum();
                    assert!((total - average).abs() <= 1e-12 + 1e-10 * average, "{total:e} vs {average:e}");
                    let profile = MuProfile::new(&masses);
                    // ∫ pdf dω = 2π ∫ ρ(μ²) μ/π dμ: Gauss–Legendre per cell (exact for the line)
                    let m = MU_CELLS as f64;
                    let mut mass = 0.0;
                    for k in 0..MU_CELLS {
                        let (a, b) = (k as f64 / m, (k + 1) as f64 / m);
                        let cell: f64 = [
                            -0.861_136_311_594_053,
                            -0.339_981_043_584_856,
                            0.339_981_043_584_856,
                            0.861_136_311_594_053,
                        ]
                        .iter()
                        .zip([
                            0.347_854_845_137_454,
                            0.652_145_154_862_546,
                            0.652_145_154_862_546,
                            0.347_854_845_137_454,
                        ])
                        .map(|(&x, w)| {
                            let mu = 0.5 * (a + b) + 0.5 * (b - a) * x;
                            w * 0.5 * (b - a) * 2.0 * PI * f64::from(profile.pdf(mu as f32))
                        })
                        .sum();
                        // each cell carries about its share of the profile (the node values
                        // average neighbouring cells)
                        assert!(
                            cell <= 3.0
                                * (masses[k.saturating_sub(1)]
                                    + masses[k]
                                    + masses[(k + 1).min(MU_CELLS - 1)])
                                / total
                                + 1e-6,
                            "cell {k}: {cell}"
                        );
                        mass += cell;
                    }
                    assert!((mass - 1.0).abs() <= 1e-5, "N = {N} α = {alpha}: ∫ pdf dω = {mass}");
                }
            }
        }
        check::<16>(&[
            core::array::from_fn(|i| 0.3 + 0.02 * i as f32),
            core::array::from_fn(|i| if i < 4 { 0.0 } else { (i as f32 * 0.7).sin().abs() }),
            core::array::from_fn(|i| if i == 15 { 1.0 } else { 0.0 }),
        ]);
        check::<32>(&[
            core::array::from_fn(|i| 0.1 + 0.01 * i as f32),
            core::array::from_fn(|i| if i < 9 { 0.0 } else { (i as f32 * 0.3).cos().abs() }),
        ]);
    }

    /// The sampler draws μ with the density it states: 4 bins per cell of the uniform μ axis,
    /// binomial counts against the density's exact integral over each bin (linear in μ² on a
    /// cell: 2π [a μ²/2 + b μ⁴/4]), |count − N p| ≤ z √(N p (1 − p)) with z at the family-wise
    /// level 1 % over the 128 bins; at the extreme uniforms it stays in (0, 1]; an empty profile
    /// has density 0 everywhere.
    #[test]
    fn sampler_matches_its_density() {
        let row: [f32; 32] =
            core::array::from_fn(|i| (i as f32 * 0.37).sin().abs() + if i == 3 { 2.0 } else { 0.0 });
        let profile = MuProfile::new(&mu_cell_masses(&row, 0.2));
        let (n, bins) = (400_000usize, 4 * MU_CELLS);
        let z = validation::family_z(0.01, bins);
        let mut counts = vec![0usize; bins];
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..n {
            let w = profile.sample(Vec2::new(next(), next())).expect("off the horizon");
            assert!((w.length() - 1.0).abs() < 1e-6 && w.z > 0.0);
            counts[((f64::from(w.z) * bins as f64) as usize).min(bins - 1)] += 1;
        }
        for (j, &c) in counts.iter().enumerate() {
            let cell = &profile.cells[j / 4];
            let (a, b) = (f64::from(cell.intercept), f64::from(cell.slope));
            let primitive = |mu: f64| 2.0 * PI * (a * mu * mu / 2.0 + b * mu.powi(4) / 4.0);
            let p = primitive((j + 1) as f64 / bins as f64) - primitive(j as f64 / bins as f64);
            let sd = (n as f64 * p * (1.0 - p)).sqrt();
            assert!(
                (c as f64 - n as f64 * p).abs() <= z * sd,
                "bin {j}: {c} samples, expected {:.1} (SD {sd:.1}, z = {z:.2})",
                n as f64 * p
            );
        }
        for u in [Vec2::ZERO, Vec2::splat(ONE_MINUS_ULP), Vec2::new(ONE_MINUS_ULP, 0.0)] {
            if let Some(w) = profile.sample(u) {
                assert!(w.is_finite() && w.z > 0.0 && w.z <= 1.0);
            }
        }
        assert!((0..=10).all(|i| MuProfile::EMPTY.pdf(i as f32 / 10.0) == 0.0));
        // a profile with empty cells: at the uniforms that land on a column's start (the rest of
        // u.x exactly 0) and at every cosine, finite and non-negative
        let sparse: [f32; 32] = core::array::from_fn(|i| if i < 9 || i == 20 { 0.0 } else { 1.0 });
        let profile = MuProfile::new(&mu_cell_masses(&sparse, 0.05));
        for k in 0..MU_CELLS {
            if let Some(w) = profile.sample(Vec2::new(k as f32 / MU_CELLS as f32, 0.3)) {
                assert!(w.is_finite() && w.z > 0.0 && w.z <= 1.0, "column {k}: {w}");
            }
        }
        assert!((0..=1000).all(|i| profile.pdf(i as f32 / 1000.0) >= 0.0));
    }
}
