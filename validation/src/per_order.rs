//! Reference per-order albedos for a perfect conductor (F = 1) with GGX α = 1, computed
//! without the crate, from the formulas, in f64.
//!
//! GGX α = 1: D(m) = 1/(π (m.x² + m.y² + m.z²)²) = 1/π on the upper hemisphere, and
//! Λ(ω) = (−1 + √(1 + tan²θ))/2 = (1/ω.z − 1)/2 on the whole sphere (signed: it is
//! (1 − z)/(2z) ≥ 0 above, and (1/z − 1)/2 = −1 − Λ(−ω) ≤ −1 below). Everything below
//! depends only on the z components of the directions:
//!
//! * the phase function of a bounce with incident ωin (pointing away) is
//!   D(h)/(4 |ωin.z| |1 + Λ(ωin)|) = 1/(2π (1 + ωin.z)) on the cap ωo.z > −ωin.z (h.z > 0):
//!   the next ray's z is uniform on (z, 1) where z is the current ray's z (the first ray has
//!   z₀ = −cos θi);
//! * the vertex term (F = 1) is D(h)/(4 |ωin.z|), and with K = |1 + Λ(ωin)| =
//!   (1 − z)/(2|z|) (z the ray arriving at the vertex) it is K × that phase function, so
//!   the position-free order-n albedo is E[Π_{j<n} Kⱼ·middleⱼ · Kₙ·lastₙ · 1{zₙ > 0}] over
//!   zⱼ ~ U(zⱼ₋₁, 1) (Wang et al. 2022, eqs. 7–8, 12–13, 16–18, regrouped per vertex), with
//!   Λⱼ = Λ(zⱼ) of an up-going zⱼ:
//!
//!   | | uncorrelated | height-correlated |
//!   |---|---|---|
//!   | K·middle, zⱼ < 0 | 1 | 1 |
//!   | K·middle, zⱼ > 0 | Λⱼ/(1 + Λⱼ) | Λⱼ/(K + Λⱼ) |
//!   | K·last | 1/(1 + Λₙ) | K/(K + Λₙ) |
//!
//! * the Heitz et al. 2016 walk in depth ℓ = −ln C¹(h) ≥ 0 (supplement, `sampleHeight`): a
//!   down-going ray (z < 0) goes deeper by an Exp(μ) distance, μ = −Λ(z) = (1 − z)/(2|z|); an
//!   up-going ray from depth ℓ leaves with probability e^{−Λℓ}, otherwise rises by an Exp(Λ)
//!   distance shorter than ℓ. The first hit is at ℓ₁ ~ Exp(a), a = 1 + Λ(ωi). With
//!   A(c) = a/(a + c) = E[e^{−cℓ₁}], the probability of leaving after exactly n bounces along
//!   z₁ … zₙ (zₙ > 0, c = Λ(zₙ)) integrates the depths in closed form:
//!
//!   | n | path | weight |
//!   |---|---|---|
//!   | 1 | | A(c) |
//!   | 2 | z₁ < 0 | μ₁/(μ₁ + c) · A(c) |
//!   | 2 | z₁ > 0 | Λ₁ a/((a + c)(a + Λ₁)) |
//!   | 3 | z₁, z₂ < 0 | μ₁/(μ₁ + c) · μ₂/(μ₂ + c) · A(c) |
//!   | 3 | z₁ < 0 < z₂ | Λ₂ μ₁ a (μ₁ + a + Λ₂ + c)/((μ₁ + c)(a + c)(μ₁ + Λ₂)(a + Λ₂)) |
//!   | 3 | 0 < z₁ (< z₂) | Λ₁ Λ₂ a/((a + Λ₁)(a + Λ₂)(a + c)) |
//!
//!   (an up-going segment that hits contributes λ∫₀^ℓ e^{−λx} g(ℓ − x) dx; the divided
//!   differences that this leaves cancel in closed form.)
//!
//! Order 1 of the correlated model equals the walk's (K₁ = a). From order 2 on they differ:
//! the position-free correlated term K/(K + Λ) of a vertex is the probability that a ray
//! arriving from the distance along zⱼ₋₁ finds its exit free, whereas the walk's ray started
//! at the previous vertex, inside the surface (for z₁ < 0 the walk's weight is the
//! position-free one times A(c) < 1).
//!
//! Shared by the position-free estimators' tests (`tests/position_free/estimators.rs`) and
//! the invariance-principle estimator's (`tests/invariance.rs`).

/// Which model the reference integrates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Model {
    /// The Heitz et al. 2016 walk (orders 1–3).
    Walk,
    /// The height-correlated position-free model of Wang et al. 2022.
    Correlated,
    /// The uncorrelated position-free model of Wang et al. 2022.
    Uncorrelated,
}

/// Λ(z) of GGX α = 1, signed, on the whole sphere.
fn lambda(z: f64) -> f64 {
    (1.0 - z) / (2.0 * z)
}

/// |1 + Λ| of the direction −z (the incident direction at the vertex a ray along z hits).
fn k_of(z: f64) -> f64 {
    (1.0 - z) / (2.0 * z.abs())
}

/// The weight of a path z₀ = −cos θi, z₁ … zₙ (zₙ > 0) in the expectation over zⱼ ~
/// U(zⱼ₋₁, 1).
fn weight(model: Model, z: &[f64]) -> f64 {
    let n = z.len() - 1;
    let c = lambda(z[n]);
    match model {
        Model::Walk => {
            let a = k_of(z[0]);
            let big_a = |c: f64| a / (a + c);
            match n {
                1 => big_a(c),
                2 if z[1] < 0.0 => {
                    let mu = -lambda(z[1]);
                    mu / (mu + c) * big_a(c)
                }
                2 => {
                    let l1 = lambda(z[1]);
                    l1 * a / ((a + c) * (a + l1))
                }
                3 if z[1] < 0.0 && z[2] < 0.0 => {
                    let (m1, m2) = (-lambda(z[1]), -lambda(z[2]));
                    m1 / (m1 + c) * m2 / (m2 + c) * big_a(c)
                }
                3 if z[1] < 0.0 => {
                    let (m1, l2) = (-lambda(z[1]), lambda(z[2]));
                    l2 * m1 * a * (m1 + a + l2 + c) / ((m1 + c) * (a + c) * (m1 + l2) * (a + l2))
                }
                3 => {
                    let (l1, l2) = (lambda(z[1]), lambda(z[2]));
                    l1 * l2 * a / ((a + l1) * (a + l2) * (a + c))
                }
                _ => unreachable!("orders 1–3"),
            }
        }
        Model::Correlated | Model::Uncorrelated => {
            let mut w = 1.0;
            for j in 1..=n {
                let k = k_of(z[j - 1]);
                let up = z[j] > 0.0;
                let l = if up { lambda(z[j]) } else { 0.0 };
                w *= match (model, j == n, up) {
                    (_, false, false) => 1.0,
                    (Model::Correlated, false, true) => l / (k + l),
                    (_, false, true) => l / (1.0 + l),
                    (Model::Correlated, true, _) => k / (k + l),
                    (_, true, _) => 1.0 / (1.0 + l),
                };
            }
            w
        }
    }
}

/// Gauss–Legendre nodes and weights on [0, 1] (Newton on Pₙ).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            (0.5 * (1.0 - x), 1.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// Panel breaks on [0, 1], graded geometrically towards both ends (the integrands vary
/// fastest near z = 0, where Λ → ∞, and at the ends of the shrinking ranges).
const BREAKS: [f64; 11] = [0.0, 1e-4, 1e-3, 1e-2, 0.05, 0.2, 0.5, 0.8, 0.95, 0.99, 1.0];

/// The mean of f over (lo, hi), split at 0 where the range straddles it (the weights
/// switch formula there), on graded panels of `rule`.
fn mean(lo: f64, hi: f64, rule: &[(f64, f64)], f: &mut dyn FnMut(f64) -> f64) -> f64 {
    let mut integral = |a: f64, b: f64| {
        let mut s = 0.0;
        for p in BREAKS.windows(2) {
            let (pa, pb) = (a + (b - a) * p[0], a + (b - a) * p[1]);
            for &(x, w) in rule {
                s += w * (pb - pa) * f(pa + (pb - pa) * x);
            }
        }
        s
    };
    let total = if lo < 0.0 && hi > 0.0 { integral(lo, 0.0) + integral(0.0, hi) } else { integral(lo, hi) };
    total / (hi - lo)
}

/// E[weight · 1{zₙ > 0}] over zⱼ ~ U(zⱼ₋₁, 1) (order n = depth of `z` to come).
fn nested(model: Model, z: &mut Vec<f64>, order: usize, rule: &[(f64, f64)]) -> f64 {
    let prev = *z.last().unwrap();
    let last = z.len() == order;
    // the last direction leaves: only zₙ > 0 counts, with density 1/(1 − zₙ₋₁)
    let lo = if last { prev.max(0.0) } else { prev };
    let share = (1.0 - lo) / (1.0 - prev);
    share
        * mean(lo, 1.0, rule, &mut |zj| {
            z.push(zj);
            let v = if last { weight(model, z) } else { nested(model, z, order, rule) };
            z.pop();
            v
        })
}

/// The order-`order` albedo of `model` at incidence cos θi = `cos_i`, with `rule` (nodes
/// and weights on [0, 1]) on every panel.
pub fn albedo(model: Model, cos_i: f64, order: usize, rule: &[(f64, f64)]) -> f64 {
    nested(model, &mut vec![-cos_i], order, rule)
}
