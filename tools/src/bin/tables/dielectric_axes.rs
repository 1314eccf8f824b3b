//! The node axes of the dielectric albedo tables (f64 mirror of `microsurface`'s lookup, with
//! the inverse maps that place the nodes), and the measurement of a table design's
//! interpolation error from the nodes around random points only.
//!
//! Direction: the log/√ blend B(μ) = ½ ln(μ/μf)/ln(1/μf) + ½ (√μ − √μf)/(1 − √μf) (μf = 1e-6;
//! B = 0 below μf) from outside. From inside (relative index η < 1 seen by the light) the
//! critical cosine μc = √(1 − η²) sits on the knee node K: x = (K/15) L(μ/μc) for μ ≤ μc, with
//! L(t) = ½ B(t) + ½ (1 − √(1 − t)) (the shipped [`BelowKnee::Symmetric`]; B(t) alone was
//! measured too), and
//! x = K/15 + (1 − K/15) √((μ − μc)/(1 − μc)) above; the η = 1 row of the inside table holds
//! the limit μc → 0 of that axis (its nodes ≤ K at μ = 0), so every row of the table is placed
//! on the same axis as the lookups that read it.
//! Roughness: r = B(α) (row 0 at α = 1e-6). Index: η = 1 + 2u³ (η ≥ 1; 1/η from inside).

use crate::Side;

/// Below this μ (relative to μc from inside) the direction axis is 0.
pub const MU_FLOOR: f64 = 1e-6;
/// The roughness at which the r = 0 row is evaluated.
pub const ALPHA_LIMIT: f64 = 1e-6;

/// A design of the dielectric axes (the knee node of the inside direction axis and the power
/// of the η axis).
#[derive(Debug, Clone, Copy)]
pub struct Axes {
    /// Nodes per axis.
    pub nodes: usize,
    /// The node the critical cosine sits on from inside.
    pub knee: usize,
    /// η = 1 + 2u^power.
    pub eta_power: f64,
    /// The roughness axis.
    pub roughness: Roughness,
    /// The direction axis below the knee (from inside).
    pub below_knee: BelowKnee,
    /// The direction axis of each side: outside, inside.
    pub direction: [Direction; 2],
    /// Nodes of the roughness and index axes (0: `nodes`).
    pub other_nodes: [usize; 2],
}

/// The direction axis of one side of a design.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// B(μ) from outside, the knee axis from inside.
    Blend,
    /// The conductor's scale-invariant x = √(μ (1 + α)/(μ + α)).
    ScaleInvariant,
    /// From inside: the knee at μc, scale-invariant in t = μ/μc at α/μc below it.
    KneeScaleInvariant,
    /// ½ √(μ (1 + α)/(μ + α)) + ½ μ^p (p in thousandths).
    Mixed(u32),
}

fn mixed(mu: f64, alpha: f64, p: u32) -> f64 {
    0.5 * (mu * (1.0 + alpha) / (mu + alpha)).min(1.0).sqrt() + 0.5 * mu.powf(f64::from(p) / 1000.0)
}

/// The roughness axis of a design.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Roughness {
    /// r = √α (the conductor's).
    Sqrt,
    /// r = B(α).
    Blend,
}

/// The inside direction axis below the knee, in t = μ/μc.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BelowKnee {
    /// B(t).
    Blend,
    /// ½ B(t) + ½ (1 − √(1 − t)).
    Symmetric,
}

/// The shipped design.
pub const SHIPPED: Axes = Axes {
    nodes: 16,
    knee: 7,
    eta_power: 3.0,
    roughness: Roughness::Blend,
    below_knee: BelowKnee::Symmetric,
    direction: [Direction::Blend, Direction::Blend],
    other_nodes: [0, 0],
};

/// B(μ) ∈ [0, 1].
pub fn blend(mu: f64) -> f64 {
    let mu = mu.max(MU_FLOOR);
    0.5 * (mu / MU_FLOOR).ln() / (1.0 / MU_FLOOR).ln()
        + 0.5 * (mu.sqrt() - MU_FLOOR.sqrt()) / (1.0 - MU_FLOOR.sqrt())
}

/// μ = B⁻¹(b) for b ∈ (0, 1] (μf at b = 0).
pub fn blend_inverse(b: f64) -> f64 {
    if b <= 0.0 {
        return MU_FLOOR;
    }
    if b >= 1.0 {
        return 1.0;
    }
    // B is increasing: bisection in ln μ
    let (mut lo, mut hi) = (MU_FLOOR.ln(), 0.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if blend(mid.exp()) < b {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (0.5 * (lo + hi)).exp()
}

/// ½ B(t) + ½ (1 − √(1 − t)) for t ∈ [0, 1].
pub fn knee_blend(t: f64) -> f64 {
    0.5 * blend(t) + 0.5 * (1.0 - (1.0 - t).max(0.0).sqrt())
}

/// The inverse of [`knee_blend`].
pub fn knee_blend_inverse(b: f64) -> f64 {
    if b <= 0.0 {
        return MU_FLOOR;
    }
    if b >= 1.0 {
        return 1.0;
    }
    let (mut lo, mut hi) = (MU_FLOOR.ln(), 0.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if knee_blend(mid.exp()) < b {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (0.5 * (lo + hi)).exp()
}

/// The critical cosine √(1 − η²) of η < 1 (0 for η ≥ 1).
pub fn critical_cosine(eta_seen: f64) -> f64 {
    (1.0 - eta_seen * eta_seen).max(0.0).sqrt()
}

impl Axes {
    fn last(&self) -> f64 {
        (self.nodes - 1) as f64
    }

    /// The last node of axis a (0: direction, 1: roughness, 2: index).
    pub fn last_of(&self, a: usize) -> f64 {
        let n = if a == 0 || self.other_nodes[a - 1] == 0 { self.nodes } else { self.other_nodes[a - 1] };
        (n - 1) as f64
    }

    /// The fraction of the direction axis below the knee.
    fn knee_x(&self) -> f64 {
        self.knee as f64 / self.last()
    }

    /// The direction coordinate x ∈ [0, 1] of μ on the table of `side` for light seeing η
    /// (inside: η ≤ 1 and the knee axis at μc = √(1 − η²)).
    pub fn direction(&self, mu: f64, alpha: f64, eta_seen: f64, side: Side) -> f64 {
        if self.direction[side as usize] == Direction::ScaleInvariant {
            return (mu * (1.0 + alpha) / (mu + alpha)).min(1.0).sqrt();
        }
        if let Direction::Mixed(p) = self.direction[side as usize] {
            return mixed(mu, alpha, p);
        }
        if side == Side::Outside {
            return blend(mu);
        }
        let mu_c = critical_cosine(eta_seen);
        let k = self.knee_x();
        if self.direction[side as usize] == Direction::KneeScaleInvariant {
            if mu <= mu_c {
                let (t, a) = (mu / mu_c, alpha / mu_c);
                return k * (t * (1.0 + a) / (t + a)).min(1.0).sqrt();
            }
            return k + (1.0 - k) * ((mu - mu_c) / (1.0 - mu_c)).sqrt();
        }
        if mu <= mu_c {
            k * if self.below_knee == BelowKnee::Symmetric { knee_blend(mu / mu_c) } else { blend(mu / mu_c) }
        } else {
            k + (1.0 - k) * ((mu - mu_c) / (1.0 - mu_c)).sqrt()
        }
    }

    /// μ of direction coordinate x (the inverse of [`Self::direction`]; μf-floored).
    pub fn mu_of(&self, x: f64, alpha: f64, eta_seen: f64, side: Side) -> f64 {
        if self.direction[side as usize] == Direction::ScaleInvariant {
            let big_x = x * x;
            return if big_x >= 1.0 { 1.0 } else { big_x * alpha / (1.0 + alpha - big_x) };
        }
        if let Direction::Mixed(p) = self.direction[side as usize] {
            if x <= 0.0 {
                return 0.0;
            }
            if x >= 1.0 {
                return 1.0;
            }
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mixed(mid, alpha, p) < x { lo = mid } else { hi = mid }
            }
            return 0.5 * (lo + hi);
        }
        if side == Side::Outside {
            return blend_inverse(x);
        }
        let mu_c = critical_cosine(eta_seen);
        let k = self.knee_x();
        if x <= k {
            if mu_c == 0.0 {
                0.0
            } else if self.direction[side as usize] == Direction::KneeScaleInvariant {
                let a = alpha / mu_c;
                let big_x = (x / k) * (x / k);
                if big_x >= 1.0 { mu_c } else { mu_c * big_x * a / (1.0 + a - big_x) }
            } else if self.below_knee == BelowKnee::Symmetric {
                mu_c * knee_blend_inverse(x / k)
            } else {
                mu_c * blend_inverse(x / k)
            }
        } else {
            let s = (x - k) / (1.0 - k);
            (mu_c + (1.0 - mu_c) * s * s).min(1.0)
        }
    }

    /// η ≥ 1 of η coordinate u ∈ [0, 1].
    pub fn eta_of(&self, u: f64) -> f64 {
        1.0 + 2.0 * u.powf(self.eta_power)
    }

    /// u of η ≥ 1.
    pub fn eta_coordinate(&self, eta_at_least_one: f64) -> f64 {
        ((eta_at_least_one - 1.0) * 0.5).max(0.0).powf(1.0 / self.eta_power).min(1.0)
    }

    /// α of roughness node j.
    pub fn alpha_of_node(&self, j: usize) -> f64 {
        let r = j as f64 / self.last_of(1);
        if self.roughness == Roughness::Blend { blend_inverse(r) } else { (r * r).max(ALPHA_LIMIT) }
    }

    /// (μ, α, η seen) of node (i, j, l) of the table of `side`.
    pub fn node(&self, i: usize, j: usize, l: usize, side: Side) -> (f64, f64, f64) {
        let alpha = self.alpha_of_node(j);
        let eta = self.eta_of(l as f64 / self.last_of(2));
        let eta_seen = if side == Side::Inside { 1.0 / eta } else { eta };
        (self.mu_of(i as f64 / self.last(), alpha, eta_seen, side), alpha, eta_seen)
    }

    /// The fractional node coordinates (x, r, u)·(nodes − 1) of a lookup at (μ, α, η seen).
    pub fn coordinates(&self, mu: f64, alpha: f64, eta_seen: f64) -> [f64; 3] {
        let side = if eta_seen < 1.0 { Side::Inside } else { Side::Outside };
        let eta_ge_1 = if side == Side::Inside { 1.0 / eta_seen } else { eta_seen };
        [
            self.direction(mu, alpha, eta_seen, side).clamp(0.0, 1.0) * self.last_of(0),
            if self.roughness == Roughness::Blend { blend(alpha.min(1.0)) } else { alpha.sqrt().min(1.0) }
                * self.last_of(1),
            self.eta_coordinate(eta_ge_1) * self.last_of(2),
        ]
    }
}
