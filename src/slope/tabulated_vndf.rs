//! Exact visible-normal sampling of the tabulated slope distribution in constant expected
//! time: a proposal tabulated at construction, corrected exactly by rejection.
//!
//! In the hemisphere stretched by the table's scale s the table is a piecewise-constant
//! density of normals, D′ = fₖ/π on the zone θ′ₖ ≤ θ′ < θ′ₖ₊₁ (see
//! [`TabulatedSlope`](super::TabulatedSlope)), and the visible normals seen from the stretched
//! direction ν have density ∝ fₖ ⟨ν, m⟩₊ (stretch invariance, Heitz et al. 2016, supplement
//! §2.1). The sampler draws them from a majorant and accepts with the exact ratio:
//!
//! * **Cells.** The zones, split where wider than 0.05 rad, times 16 bins of the azimuth
//!   φ ∈ [0, π] around ν (four octants of four bins; the sign of the other coordinate is a fair
//!   coin). Within a cell ⟨ν, m⟩ = a z + b ρ cos φ (ν = (b, 0, a), z = cos θ′, ρ = sin θ′) is
//!   bounded by w̄ = (a·z_ext + b·cos φ_max·ρ_ext)₊ with each term at its extreme, a
//!   positively homogeneous convex function of ν.
//! * **Nodes.** 32 directions uniform in the stretched octahedral coordinate
//!   t = a/(b + |a|) from the zenith to e = 1 + t = 1/16, then two per halving of e down to
//!   the direction below which only the tail zone is visible. Each node stores the cumulative
//!   majorant masses of the cells it sees (f64) and a guide table. A direction between nodes
//!   νₐ and ν_b is ν = λνₐ + μν_b with λ, μ ≥ 0, and by convexity and homogeneity its majorant
//!   of every cell is at most λ times node a's plus μ times node b's: the proposal picks node
//!   a or b in proportion to λQₐ, μQ_b (Q their totals), a cell from that node's table (guide
//!   table, O(1)), a bin by the direction's own majorants (16 multiply-adds), then z uniform
//!   in the cell and τ = tan(φ̂/2) uniform in the bin (the rational map of the circle, no
//!   trigonometry; its Jacobian 2/(1 + τ²) is bounded by its value at the bin's lower end).
//! * **Acceptance.** The proposal density exceeds the target's at every point; the ratio,
//!   ⟨ν, m⟩(1 + τ_lo²)/((1 + τ²) w̄) times the cell's own majorant over the nodes' mixture,
//!   is formed exactly, and the sample is accepted with that probability. Accepted samples
//!   are distributed exactly as D_ν (the density the proposal over-covers is removed
//!   pointwise), whatever the tabulated approximation's quality: it only sets the rate.
//!
//! The first proposal inverts the two uniforms (the first gives node, cell and z, the second
//! the coin, the bin and τ); the acceptance uniform and the uniforms of any further proposal
//! are hashed from the bits of the two (splitmix64). The measured acceptance rate is printed
//! by `tests/tabulated/tabulated.rs` (0.9 or more above the horizon); after 128 rejections
//! the last proposal is returned (probability below 1e-19 at the worst acceptance measured).
//! Directions nearer the nadir than the last node see the tail zone only: there the visible
//! normals are those of the unit GGX lobe, sampled exactly by the spherical cap
//! ([`crate::vndf::sample_visible_hemisphere`]), or nothing for a truncated table.

use super::rings::RingGrid;
use crate::vndf::sample_visible_hemisphere;
use core::f64::consts::{FRAC_PI_2, PI};
use glam::{DVec3, Vec3};

/// Zones wider than this (radians of the stretched angle) are split into cells.
const MAX_CELL_ANGLE: f64 = 0.05;
/// Zones whose ends' angles from the horizon differ by more than this ratio are split too.
const MAX_CELL_RATIO: f64 = 1.25;
/// Intervals uniform in the octahedral coordinate t = a/(b + |a|), from the zenith (t = 1) to
/// t = −½ (e = 1 + t = ½).
const REGULAR_INTERVALS: usize = 24;
/// Where the geometric nodes take over: e = ½.
const E_REGULAR: f64 = 0.5;
/// Geometric nodes per halving of e − e_min, down to 1e-3 e_min.
const GEOMETRIC_PER_OCTAVE: f64 = 2.0;
/// Bins per octant of the azimuth, uniform in τ ∈ [0, tan(π/8)].
const OCTANT_BINS: usize = 4;
/// Bins of the half circle φ ∈ [0, π].
const BINS: usize = 4 * OCTANT_BINS;
/// Proposals before the last one is returned unchecked.
const MAX_TRIALS: u64 = 128;
/// The largest f64 below 1.
const ONE_BELOW: f64 = 1.0 - f64::EPSILON / 2.0;
/// The crate's tail cut (2⁻²⁴) of the z coordinate in the tail zone, whose lower end z = 0 is
/// the horizon (a normal there has no density).
const TAIL_CUT: f64 = 1.0 / 16_777_216.0;

/// tan(π/8) = √2 − 1: the half-angle tangent at the end of an octant.
const TAN_PI_8: f64 = 0.414_213_562_373_095_05;
/// The width of a bin in τ.
const BIN_STEP: f64 = TAN_PI_8 / OCTANT_BINS as f64;

/// The azimuth bins: lower τ, the majorant 2Δτ/(1 + τ_lo²) of their φ-measure, 1 + τ_lo², and
/// the largest cos φ in the bin.
struct Bins {
    tau_lo: [f64; BINS],
    measure: [f64; BINS],
    lo_factor: [f64; BINS],
    cos_max: [f64; BINS],
}

/// The bins, computed at compile time.
const AZIMUTH_BINS: Bins = Bins::new();

impl Bins {
    const fn new() -> Self {
        let mut bins =
            Self { tau_lo: [0.0; BINS], measure: [0.0; BINS], lo_factor: [0.0; BINS], cos_max: [0.0; BINS] };
        let mut j = 0;
        while j < BINS {
            let (lo, hi) = ((j % OCTANT_BINS) as f64 * BIN_STEP, (j % OCTANT_BINS + 1) as f64 * BIN_STEP);
            bins.tau_lo[j] = lo;
            bins.lo_factor[j] = 1.0 + lo * lo;
            bins.measure[j] = 2.0 * BIN_STEP / (1.0 + lo * lo);
            // octants: φ = φ̂, π/2 − φ̂, π/2 + φ̂, π − φ̂, with cos φ̂ = (1 − τ²)/(1 + τ²) and
            // sin φ̂ = 2τ/(1 + τ²)
            bins.cos_max[j] = match j / OCTANT_BINS {
                0 => (1.0 - lo * lo) / (1.0 + lo * lo),
                1 => 2.0 * hi / (1.0 + hi * hi),
                2 => -2.0 * lo / (1.0 + lo * lo),
                _ => -(1.0 - hi * hi) / (1.0 + hi * hi),
            };
            j += 1;
        }
        bins
    }
}

/// A cell: its z = cos θ′ and ρ = sin θ′ ranges and its weight fₖ Δz/π.
#[derive(Debug, Clone, Copy)]
struct Cell {
    z_lo: f64,
    z_hi: f64,
    rho_lo: f64,
    rho_hi: f64,
    weight: f64,
}

/// A node: a stretched direction and the cumulative majorant masses of the cells it sees.
#[derive(Debug, Clone)]
struct Node {
    /// The unit stretched direction (horizontal, vertical).
    b: f64,
    a: f64,
    /// The first cell it sees (cells are ordered from the zenith down).
    first: usize,
    /// Cells from `first` on.
    len: usize,
    /// Where its `len` + 1 cumulative masses start in [`VisibleSampler::cdf`] and its `len`
    /// guide entries in [`VisibleSampler::guide`].
    at: usize,
    guide_at: usize,
    /// The last cell of positive mass (relative to `first`).
    last: usize,
    /// The total majorant mass Q.
    total: f64,
}

/// The sampler's tables (see the module documentation).
#[derive(Debug, Clone)]
pub(super) struct VisibleSampler {
    /// The cells, from the zenith down.
    cells: Vec<Cell>,
    nodes: Vec<Node>,
    /// 1/(νₙ × νₙ₊₁) per interval between nodes.
    inv_det: Vec<f64>,
    cdf: Vec<f64>,
    guide: Vec<u32>,
    /// e = 1 + t of the last node (below it only the tail zone is visible).
    e_min: f64,
    /// Whether the tail zone has mass (then the directions below `e_min` see it).
    tail: bool,
}

impl VisibleSampler {
    /// The tables of the zone factors `factors` (N + 1, the last the tail's) on `grid`.
    pub(super) fn new(grid: &RingGrid, factors: &[f64]) -> Self {
        let n = grid.rings;
        let n1 = n as f64 + 1.0;
        let gamma = |k: f64| {
            let v = 1.0 - k / n1;
            FRAC_PI_2 * v * v
        };
        let mut cells = Vec::new();
        let tail = factors[n] > 0.0;
        for (k, &f) in factors.iter().enumerate().take(if tail { n + 1 } else { n }) {
            // the zone [θ′ₖ, θ′ₖ₊₁] in complements γ (γ_{N+1} = 0: the horizon)
            let (g0, g1) = (gamma(k as f64), if k == n { 0.0 } else { gamma(k as f64 + 1.0) });
            // cells from γ₀ down: at most MAX_CELL_ANGLE wide, and at most a ratio
            // MAX_CELL_RATIO in γ (≈ in z near the horizon, where the outer zones are wide
            // relative to their height: the visible part of a zone seen from near the nadir is
            // a sliver above its lower end); the tail zone's last cell reaches the horizon
            let mut bounds = vec![g0];
            let mut g = g0;
            while g > g1 {
                let next = (g - MAX_CELL_ANGLE).max(g / MAX_CELL_RATIO);
                g = if next <= g1 || (g1 == 0.0 && next < 1e-3 * g0) { g1 } else { next };
                bounds.push(g);
            }
            for (l, pair) in bounds.windows(2).enumerate() {
                // the grid's own values at the zone's ends, so that cells and rings agree
                let (zh, rl) = if l == 0 { (grid.cos[k], grid.sin[k]) } else { pair[0].sin_cos() };
                let (zl, rh) =
                    if pair[1] == g1 { (grid.cos[k + 1], grid.sin[k + 1]) } else { pair[1].sin_cos() };
                cells.push(Cell { z_lo: zl, z_hi: zh, rho_lo: rl, rho_hi: rh, weight: f * (zh - zl) / PI });
            }
        }
        let mut sampler = Self {
            cells,
            nodes: Vec::new(),
            inv_det: Vec::new(),
            cdf: Vec::new(),
            guide: Vec::new(),
            e_min: 0.0,
            tail,
        };
        // below e_min only the tail zone is visible: sin ε′ ≤ cos θ′_N, tan ε′ = cot θ′_N
        let cot_last = grid.cos[n] / grid.sin[n];
        sampler.e_min = cot_last / (1.0 + cot_last);
        let mut directions: Vec<(f64, f64)> = (0..=REGULAR_INTERVALS)
            .map(|i| {
                let t = 1.0 - (2.0 - E_REGULAR) * i as f64 / REGULAR_INTERVALS as f64;
                (1.0 - t.abs(), t)
            })
            .collect();
        // then e = e_min + (½ − e_min)·2^(−j/2), down to 1e-3 e_min, and e_min itself
        let span = E_REGULAR - sampler.e_min;
        let mut j = 1.0;
        loop {
            let d = span * (-j / GEOMETRIC_PER_OCTAVE).exp2();
            if d <= 1e-3 * sampler.e_min {
                directions.push((sampler.e_min, sampler.e_min - 1.0));
                break;
            }
            let e = sampler.e_min + d;
            directions.push((e, e - 1.0));
            j += 1.0;
        }
        for (b, a) in directions {
            let len = b.hypot(a);
            sampler.push_node(b / len, a / len);
        }
        sampler.inv_det =
            sampler.nodes.windows(2).map(|w| 1.0 / (w[0].b * w[1].a - w[0].a * w[1].b)).collect();
        sampler
    }

    /// Adds the node of the unit stretched direction (b, a).
    fn push_node(&mut self, b: f64, a: f64) {
        let masses: Vec<f64> = self
            .cells
            .iter()
            .map(|cell| {
                let octants = majorants(cell, a, b).1;
                cell.weight * ((octants[0] + octants[1]) + (octants[2] + octants[3]))
            })
            .collect();
        let first = masses.iter().position(|m| *m > 0.0).unwrap_or(masses.len());
        let len = masses.len() - first;
        let at = self.cdf.len();
        let guide_at = self.guide.len();
        let mut acc = 0.0;
        self.cdf.push(0.0);
        let mut last = 0;
        for (k, m) in masses[first..].iter().enumerate() {
            acc += m;
            self.cdf.push(acc);
            if *m > 0.0 {
                last = k;
            }
        }
        let total = acc;
        // guide: the first cell whose cumulative mass exceeds i/len of the total
        let mut k = 0;
        for i in 0..len {
            let target = total * i as f64 / len as f64;
            while k + 1 < len && self.cdf[at + k + 1] <= target {
                k += 1;
            }
            self.guide.push(k as u32);
        }
        self.nodes.push(Node { b, a, first, len, at, guide_at, last, total });
    }

    /// The majorant mass of `cell` at `node` (0 if the node does not see it).
    #[inline(always)]
    fn mass(&self, node: &Node, cell: usize) -> f64 {
        if cell < node.first {
            return 0.0;
        }
        let k = node.at + cell - node.first;
        self.cdf[k + 1] - self.cdf[k]
    }

    /// The cell of `node` holding the fraction `u` ∈ [0, 1) of its mass, and the residual
    /// uniform in it.
    #[inline(always)]
    fn pick(&self, node: &Node, u: f64) -> (usize, f64) {
        let cdf = &self.cdf[node.at..=node.at + node.len];
        let target = u * node.total;
        let mut k = self.guide[node.guide_at + ((u * node.len as f64) as usize).min(node.len - 1)] as usize;
        while k + 1 < node.len && cdf[k + 1] <= target {
            k += 1;
        }
        if cdf[k + 1] <= target {
            // u·Q rounded up to Q: the last cell of positive mass, at its top
            return (node.first + node.last, ONE_BELOW);
        }
        let rest = ((target - cdf[k]) / (cdf[k + 1] - cdf[k])).clamp(0.0, ONE_BELOW);
        (node.first + k, rest)
    }

    /// The interval between nodes holding the stretched direction (b, a) (b ≥ 0, any length);
    /// `None` below the last node.
    #[inline(always)]
    fn interval(&self, b: f64, a: f64) -> Option<usize> {
        let den = b + a.abs();
        let t = a / den;
        if t > E_REGULAR - 1.0 {
            let i = ((1.0 - t) * (REGULAR_INTERVALS as f64 / (2.0 - E_REGULAR))) as usize;
            return Some(i.min(REGULAR_INTERVALS - 1));
        }
        let d = b / den - self.e_min;
        if d.is_nan() || d < 0.0 {
            return None;
        }
        let j = (GEOMETRIC_PER_OCTAVE * ((E_REGULAR - self.e_min) / d).log2()) as usize;
        Some((REGULAR_INTERVALS + j).min(self.nodes.len() - 2))
    }

    /// A visible normal of the stretched hemisphere seen from the stretched direction
    /// (b, 0, a) (b ≥ 0; any positive length), in that direction's azimuth frame: exact, from
    /// the uniforms `u1`, `u2` (module documentation). `None` if the direction sees nothing.
    pub(super) fn sample(&self, b: f64, a: f64, u1: f32, u2: f32) -> Option<DVec3> {
        let Some(n) = self.interval(b, a) else { return self.near_nadir(b, a, u1, u2) };
        let (na, nb) = (&self.nodes[n], &self.nodes[n + 1]);
        let inv = self.inv_det[n];
        let lambda = ((b * nb.a - a * nb.b) * inv).max(0.0);
        let mu = ((na.b * a - na.a * b) * inv).max(0.0);
        let (pa, pb) = (lambda * na.total, mu * nb.total);
        let total = pa + pb;
        if !(total > 0.0 && total < f64::INFINITY) {
            return None;
        }
        let key = (u64::from(u1.to_bits()) << 32) | u64::from(u2.to_bits());
        let (mut v1, mut v2) = (f64::from(u1), f64::from(u2));
        let mut last = None;
        for trial in 0..MAX_TRIALS {
            if trial > 0 {
                v1 = unit(mix(key, 3 * trial));
                v2 = unit(mix(key, 3 * trial + 1));
            }
            let x = v1 * total;
            let (node, rest) = if x < pa { (na, x / pa) } else { (nb, ((x - pa) / pb).min(ONE_BELOW)) };
            if node.len == 0 {
                continue;
            }
            let (cell, r1) = self.pick(node, rest);
            let c = &self.cells[cell];
            let (weights, octants) = majorants(c, a, b);
            let sum = (octants[0] + octants[1]) + (octants[2] + octants[3]);
            let mixture = lambda * self.mass(na, cell) + mu * self.mass(nb, cell);
            if !(sum > 0.0 && mixture > 0.0) {
                continue;
            }
            // the coin, then the octant and the bin (the first whose cumulative mass exceeds
            // the target), and τ from the second uniform
            let (flip, v) = if v2 < 0.5 { (false, 2.0 * v2) } else { (true, 2.0 * v2 - 1.0) };
            let target = v * sum;
            let mut acc = 0.0;
            let mut octant = 0;
            while octant < 3 && target >= acc + octants[octant] {
                acc += octants[octant];
                octant += 1;
            }
            let mut bin = octant * OCTANT_BINS;
            while bin + 1 < (octant + 1) * OCTANT_BINS && target >= acc + weights[bin] {
                acc += weights[bin];
                bin += 1;
            }
            if weights[bin] <= 0.0 {
                // rounding put the target past the last bin of positive mass: that bin, at its top
                bin = weights.iter().rposition(|w| *w > 0.0).unwrap_or(0);
                acc = target - weights[bin];
            }
            let r2 = ((target - acc) / weights[bin]).clamp(0.0, ONE_BELOW);
            let bar = bound(c, a, b, bin);
            // the point: z uniform in the cell, τ uniform in the bin; (cos φ, sin φ) =
            // (1 − τ², 2τ)/d, d = 1 + τ², kept unnormalized (everything below is homogeneous)
            let (zl, zh) = (c.z_lo, c.z_hi);
            let r1 = if zl == 0.0 { r1.max(TAIL_CUT) } else { r1 };
            let z = zl + r1 * (zh - zl);
            let rho = ((1.0 - z) * (1.0 + z)).max(0.0).sqrt();
            let tau = AZIMUTH_BINS.tau_lo[bin] + r2 * BIN_STEP;
            let tau2 = tau * tau;
            let d = 1.0 + tau2;
            let (ch, sh) = (1.0 - tau2, 2.0 * tau);
            let (cos_phi, sin_phi) = match bin / OCTANT_BINS {
                0 => (ch, sh),
                1 => (sh, ch),
                2 => (-sh, ch),
                _ => (-ch, sh),
            };
            // d times the stretched normal m
            let m = DVec3::new(rho * cos_phi, if flip { -rho * sin_phi } else { rho * sin_phi }, d * z);
            last = Some(m);
            // accept with probability [⟨ν, m⟩(1 + τ_lo²)/((1 + τ²) w̄)]·[weight·Σ/mixture], the
            // first factor the point's against the bin's bound, the second the cell's own
            // majorant against the nodes' mixture (both ≤ 1, by convexity for the second);
            // ⟨ν, m⟩ = (a·dz + b·ρ cos φ̃)/d: the test multiplied through, without a division
            let dot = a * m.z + b * rho * cos_phi;
            let numerator = dot * AZIMUTH_BINS.lo_factor[bin] * c.weight * sum;
            if numerator > 0.0 && unit(mix(key, 3 * trial + 2)) * (d * d * bar * mixture) < numerator {
                return Some(m);
            }
        }
        last
    }

    /// Directions nearer the nadir than the last node: with a tail, every normal they see is in
    /// the tail zone, where the table is the unit GGX lobe (D′ constant), sampled exactly by
    /// the spherical cap; without one they see nothing.
    fn near_nadir(&self, b: f64, a: f64, u1: f32, u2: f32) -> Option<DVec3> {
        if !self.tail {
            return None;
        }
        let len = b.hypot(a);
        let v = Vec3::new((b / len) as f32, 0.0, (a / len) as f32);
        sample_visible_hemisphere(v, 1.0, u1, u2).as_dvec3().try_normalize()
    }

    /// The total proposal mass λQₐ + μQ_b for the stretched direction (b, a) (b ≥ 0, any
    /// length), in units where the exact visible mass is half the projected area |ν|·A′(ν̂)
    /// (the bins cover half the circle): the acceptance rate is A/(2·this). `None` below the
    /// last node (sampled exactly without rejection).
    pub(super) fn proposal_mass(&self, b: f64, a: f64) -> Option<f64> {
        let n = self.interval(b, a)?;
        let (na, nb) = (&self.nodes[n], &self.nodes[n + 1]);
        let inv = self.inv_det[n];
        let lambda = ((b * nb.a - a * nb.b) * inv).max(0.0);
        let mu = ((na.b * a - na.a * b) * inv).max(0.0);
        Some(lambda * na.total + mu * nb.total)
    }

    /// Heap bytes of the tables.
    pub(super) fn heap_bytes(&self) -> usize {
        self.cells.len() * core::mem::size_of::<Cell>()
            + self.nodes.len() * core::mem::size_of::<Node>()
            + self.inv_det.len() * 8
            + self.cdf.len() * 8
            + self.guide.len() * 4
    }
}

/// The majorant masses Gⱼw̄ⱼ of the bins of `cell` for the direction ν = (b, 0, a) (any
/// length): w̄ⱼ the bound of ⟨ν, m⟩ in the bin ([`bound`]), Gⱼ the bin's φ-measure;
/// and their sums per octant. Branch-free: the first two octants have cos φ ≥ 0 (ρ at
/// its largest), the last two cos φ ≤ 0 (ρ at its smallest).
#[inline(always)]
fn majorants(cell: &Cell, a: f64, b: f64) -> ([f64; BINS], [f64; 4]) {
    let head = a * if a >= 0.0 { cell.z_hi } else { cell.z_lo };
    let (lo, hi) = (b * cell.rho_lo, b * cell.rho_hi);
    let mut w = [0.0; BINS];
    let bins = AZIMUTH_BINS.measure.iter().zip(&AZIMUTH_BINS.cos_max);
    for (j, (wj, (measure, cos))) in w.iter_mut().zip(bins).enumerate() {
        let rho = if j < BINS / 2 { hi } else { lo };
        *wj = measure * (head + cos * rho).max(0.0);
    }
    let mut octants = [0.0; 4];
    for (o, sum) in octants.iter_mut().enumerate() {
        let q = &w[o * OCTANT_BINS..(o + 1) * OCTANT_BINS];
        *sum = (q[0] + q[1]) + (q[2] + q[3]);
    }
    (w, octants)
}

/// The bound w̄ⱼ = (a·z_ext + b·cos φ_max·ρ_ext)₊ of ⟨ν, m⟩ in bin `bin` of `cell`.
#[inline(always)]
fn bound(cell: &Cell, a: f64, b: f64, bin: usize) -> f64 {
    let head = a * if a >= 0.0 { cell.z_hi } else { cell.z_lo };
    let rho = if bin < BINS / 2 { cell.rho_hi } else { cell.rho_lo };
    (head + AZIMUTH_BINS.cos_max[bin] * b * rho).max(0.0)
}

/// splitmix64 of `key` advanced `index` + 1 times (Steele, Lea and Flood 2014): a stream of
/// well-mixed words for the acceptance tests and the further proposals.
#[inline(always)]
fn mix(key: u64, index: u64) -> u64 {
    let mut z = key.wrapping_add((index + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15));
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A uniform in [0, 1) from the top 53 bits of a word.
#[inline(always)]
fn unit(bits: u64) -> f64 {
    (bits >> 11) as f64 * (1.0 / 9_007_199_254_740_992.0)
}
