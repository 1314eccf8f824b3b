//! The μ profile of a separable compensation lobe, g(μ) μ with g linear on the cells of the
//! albedo tables' scale-invariant direction axis: its exact cosine-weighted average and a
//! sampler with an exact density.

use crate::albedo::{DIELECTRIC_TABLE_SIZE, node_cell, scale_invariant_direction};
use crate::special::sin_cos_turns;
use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3};

/// Nodes of the direction axis (those of the dielectric tables).
pub(crate) const PROFILE_NODES: usize = DIELECTRIC_TABLE_SIZE;
/// The last node index, as a float.
const LAST: f32 = (PROFILE_NODES - 1) as f32;

/// The cell i ∈ [0, 14] of the direction axis x = √(μ (1 + α)/(μ + α)) that holds μ ∈ [0, 1],
/// and the fraction within it.
#[inline(always)]
pub(crate) fn profile_cell(mu: f32, alpha: f32) -> (usize, f32) {
    node_cell(scale_invariant_direction(mu, alpha) * LAST, PROFILE_NODES)
}

/// The cells of two cosines at once ([`profile_cell`] of each), sharing one division:
/// x² = μo k (μi + α)/((μo + α)(μi + α)) and likewise for μi (k = 1 + α; a few ulps from the
/// separate computation).
#[inline(always)]
pub(crate) fn profile_cells(mu_o: f32, mu_i: f32, alpha: f32) -> ((usize, f32), (usize, f32)) {
    let k = 1.0 + alpha;
    let (so, si) = (mu_o + alpha, mu_i + alpha);
    let inv = 1.0 / (so * si);
    let xo = (mu_o * k * si * inv).min(1.0).sqrt();
    let xi = (mu_i * k * so * inv).min(1.0).sqrt();
    (node_cell(xo * LAST, PROFILE_NODES), node_cell(xi * LAST, PROFILE_NODES))
}

/// The value at (cell, fraction) of a row of node values, linear in x.
#[inline(always)]
pub(crate) fn row_at(row: &[f32; PROFILE_NODES], (i, f): (usize, f32)) -> f32 {
    row[i] + f * (row[i + 1] - row[i])
}

/// The sampler of g(μ) μ for g ≥ 0 linear in x on each cell of an `N`-node direction axis
/// x = √(μ (1 + α)/(μ + α)) (node i at x = i/(N − 1)): cell i is chosen with probability
/// M_i/ḡ (M_i = ∫_cell g d(μ²), ḡ = Σ M_i = 2∫₀¹ g μ dμ), μ² uniform within it, φ uniform, so
/// its density in solid angle is d_i μ/π with d_i = P_i/Δμ²_i: the profile with g replaced by
/// its mean over the cell (the weight g/mean lies in [0, 2] for a linear g). The conductor's
/// lobes use the 32 nodes of its tables, the dielectric's the 16 of theirs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LobeProfile<const N: usize> {
    /// Cumulative probabilities of the cells (0 first, 1 last).
    cdf: [f32; N],
    /// μ² at the direction nodes.
    mu_sq: [f32; N],
    /// d_i per cell (the last entry unused, 0).
    density: [f32; N],
}

impl<const N: usize> LobeProfile<N> {
    /// No lobe.
    pub(crate) const EMPTY: Self = Self { cdf: [0.0; N], mu_sq: [0.0; N], density: [0.0; N] };

    /// ḡ = 2∫₀¹ g(μ) μ dμ of the row g (node values at x = i/(N − 1), linear in x between
    /// them) at roughness α, in closed form, and the sampler of g μ. With μ = α X/(k − X),
    /// X = x², k = 1 + α, on a cell where g = a + b x:
    ///
    /// ∫ (a + b x) d(μ²) = a Δμ² + b Δ(x μ²) − b α² ΔP,   P(x) = ∫ x⁴/(k − x²)² dx
    ///                   = x + k x/(2 (k − x²)) − (3√k/2) atanh(x/√k).
    ///
    /// In f64 (the differences of P across a cell lose at most log₂(1/α) bits, 1e-13 at
    /// α = 1e-3). The empty sampler for ḡ = 0.
    pub(crate) fn new(g: &[f32; N], alpha: f32) -> (f64, Self) {
        let alpha = f64::from(alpha);
        let k = 1.0 + alpha;
        let sk = k.sqrt();
        let mu_sq = |x: f64| {
            if x >= 1.0 {
                return 1.0;
            }
            let m = alpha * x * x / (k - x * x);
            m * m
        };
        let p = |x: f64| x + k * x / (2.0 * (k - x * x)) - 1.5 * sk * (x / sk).atanh();
        let h = 1.0 / (N - 1) as f64;
        let x_of = |i: usize| if i == N - 1 { 1.0 } else { i as f64 * h };
        // cell masses; the last entry stays 0
        let mut masses = [0.0f64; N];
        for (i, mass) in masses.iter_mut().enumerate().take(N - 1) {
            let (x0, x1) = (x_of(i), x_of(i + 1));
            let (g0, g1) = (f64::from(g[i]), f64::from(g[i + 1]));
            let b = (g1 - g0) / h;
            let a = g0 - b * x0;
            let (m0, m1) = (mu_sq(x0), mu_sq(x1));
            // ≥ 0 for g ≥ 0; rounding can leave −1e-20 in a cell of g = 0
            *mass = (a * (m1 - m0) + b * (x1 * m1 - x0 * m0) - b * alpha * alpha * (p(x1) - p(x0))).max(0.0);
        }
        let total: f64 = masses[..N - 1].iter().sum();
        let mut profile = Self::EMPTY;
        if total > 0.0 {
            let mut acc = 0.0;
            for (i, mass) in masses.iter().enumerate() {
                profile.mu_sq[i] = mu_sq(x_of(i)) as f32;
                profile.cdf[i] = (acc / total) as f32;
                acc += mass;
            }
            profile.cdf[N - 1] = 1.0;
            for i in 0..N - 1 {
                let prob = f64::from(profile.cdf[i + 1]) - f64::from(profile.cdf[i]);
                let width = f64::from(profile.mu_sq[i + 1]) - f64::from(profile.mu_sq[i]);
                profile.density[i] = if width > 0.0 { (prob / width) as f32 } else { 0.0 };
            }
        }
        (total, profile)
    }

    /// The cumulative probabilities of the cells (0 first, 1 last; all 0 for no lobe).
    #[cfg(test)]
    pub(crate) fn cdf(&self) -> &[f32; N] {
        &self.cdf
    }

    /// The density d_i μ/π of a direction with |cos θ| = μ in cell i (the hemisphere it was
    /// sampled on).
    #[inline(always)]
    pub(crate) fn pdf(&self, cell: usize, mu: f32) -> f32 {
        self.density[cell] * mu * FRAC_1_PI
    }

    /// A direction in the upper hemisphere from u ∈ [0, 1)²: a cell by its probability, μ²
    /// uniform in the cell, φ uniform. `None` on the horizon (μ = 0).
    #[inline(always)]
    pub(crate) fn sample(&self, u: Vec2) -> Option<Vec3> {
        let cdf = &self.cdf;
        // the first cell whose cumulative probability exceeds u.x
        let i = cdf[1..].partition_point(|&c| c <= u.x).min(N - 2);
        let width = cdf[i + 1] - cdf[i];
        let v = if width > 0.0 { ((u.x - cdf[i]) / width).clamp(0.0, 1.0) } else { 0.5 };
        let (m0, m1) = (self.mu_sq[i], self.mu_sq[i + 1]);
        let mu_sq = m0 + v * (m1 - m0);
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
    /// f64, midpoint rule in ln μ), for rows with and without zero cells; the sampler's
    /// cumulative probabilities rise from 0 to 1 and its densities integrate to 1 over the
    /// hemisphere (Σ d_i Δμ²_i = 1).
    #[test]
    fn closed_form_average_matches_quadrature() {
        let rows: [[f32; PROFILE_NODES]; 3] = [
            core::array::from_fn(|i| 0.3 + 0.02 * i as f32),
            core::array::from_fn(|i| if i < 4 { 0.0 } else { (i as f32 * 0.7).sin().abs() }),
            core::array::from_fn(|i| if i == 15 { 1.0 } else { 0.0 }),
        ];
        for alpha in [1e-3f32, 0.05, 0.37, 1.0] {
            for row in &rows {
                let (average, profile) = LobeProfile::new(row, alpha);
                let a = f64::from(alpha);
                let lookup = |mu: f64| {
                    let t = (mu * (1.0 + a) / (mu + a)).min(1.0).sqrt() * f64::from(LAST);
                    let i = (t as usize).min(PROFILE_NODES - 2);
                    let (g0, g1) = (f64::from(row[i]), f64::from(row[i + 1]));
                    g0 + (t - i as f64) * (g1 - g0)
                };
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
                    "α = {alpha}: {sum:e} vs {average:e}"
                );
                let cdf = profile.cdf;
                assert!(
                    cdf[0] == 0.0 && cdf[PROFILE_NODES - 1] == 1.0 && cdf.windows(2).all(|w| w[0] <= w[1])
                );
                let mass: f64 = (0..PROFILE_NODES - 1)
                    .map(|i| {
                        f64::from(profile.density[i])
                            * (f64::from(profile.mu_sq[i + 1]) - f64::from(profile.mu_sq[i]))
                    })
                    .sum();
                assert!((mass - 1.0).abs() <= 1e-5, "α = {alpha}: Σ d Δμ² = {mass}");
            }
        }
    }
}
