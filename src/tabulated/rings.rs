//! The ring grid of the tabulated slope distribution (Dupuy 2015, §4.2) and the closed forms
//! its model is built from: the rings' geometry in the stretched hemisphere, the back-face
//! area of a ring of the unit GGX lobe, and the constant-time ring lookup of a slope radius.

use core::f64::consts::FRAC_PI_2;

/// The ring grid of N rings at slope scale s: stretched angles θ′ₖ = (π/2)(1 − (1 − k/(N+1))²),
/// k = 0 … N, radii Rₖ = s·tan θ′ₖ, and a last zone θ′ ∈ [θ′_N, π/2) (the tail). Every angle is
/// computed from its complement γₖ = π/2 − θ′ₖ = (π/2)(1 − k/(N+1))², accurate near the
/// horizon where the radii reach 0.64 (N+1)² s.
#[derive(Debug, Clone)]
pub(super) struct RingGrid {
    /// The slope scale s.
    pub(super) scale: f64,
    /// The number of rings N.
    pub(super) rings: usize,
    /// Rₖ, k = 0 … N (R₀ = 0).
    pub(super) radii: Vec<f64>,
    /// Rₖ², k = 0 … N.
    pub(super) radii_sq: Vec<f64>,
    /// The stretched radii R′ₖ = tan θ′ₖ, k = 0 … N.
    pub(super) stretched: Vec<f64>,
    /// cos θ′ₖ and sin θ′ₖ, k = 0 … N + 1 (θ′_{N+1} = π/2).
    pub(super) cos: Vec<f64>,
    pub(super) sin: Vec<f64>,
    /// The mass of zone k under GGX(s), cos²θ′ₖ − cos²θ′ₖ₊₁, k = 0 … N (zone N is the tail,
    /// of mass cos²θ′_N).
    pub(super) ggx_mass: Vec<f64>,
}

impl RingGrid {
    /// The grid of `rings` ≥ 1 rings at scale `scale` > 0 (the callers validate both).
    pub(super) fn new(scale: f64, rings: usize) -> Self {
        let n1 = rings as f64 + 1.0;
        let gamma = |k: usize| {
            let v = 1.0 - k as f64 / n1;
            FRAC_PI_2 * v * v
        };
        let mut cos = Vec::with_capacity(rings + 2);
        let mut sin = Vec::with_capacity(rings + 2);
        let mut stretched = Vec::with_capacity(rings + 1);
        for k in 0..=rings {
            let (c, s, t) = if k == 0 {
                (1.0, 0.0, 0.0)
            } else {
                let (sg, cg) = gamma(k).sin_cos();
                (sg, cg, cg / sg)
            };
            cos.push(c);
            sin.push(s);
            stretched.push(t);
        }
        cos.push(0.0);
        sin.push(1.0);
        let radii: Vec<f64> = stretched.iter().map(|t| scale * t).collect();
        let radii_sq = radii.iter().map(|r| r * r).collect();
        // cos²θ′ₖ − cos²θ′ₖ₊₁ = sin(θ′ₖ₊₁ − θ′ₖ) sin(θ′ₖ₊₁ + θ′ₖ) = sin(γₖ − γₖ₊₁) sin(γₖ + γₖ₊₁),
        // with γₖ − γₖ₊₁ = (π/2)(vₖ + vₖ₊₁)/(N+1) formed without cancellation
        let ggx_mass = (0..=rings)
            .map(|k| {
                if k == rings {
                    cos[k] * cos[k]
                } else {
                    let (vk, vn) = (1.0 - k as f64 / n1, 1.0 - (k + 1) as f64 / n1);
                    let diff = FRAC_PI_2 * (vk + vn) / n1;
                    diff.sin() * (gamma(k) + gamma(k + 1)).sin()
                }
            })
            .collect();
        Self { scale, rings, radii, radii_sq, stretched, cos, sin, ggx_mass }
    }

    /// Calls `visit(k, ΔSₖ)` for the zones k = `first` … N with ΔSₖ = S(R′ₖ₊₁, c) − S(R′ₖ, c)
    /// the back-face area of zone k of the unit lobe at the stretched visibility line `c` ≥ 0
    /// ([`back_area`]; zone N, the tail, reaches R′ = ∞). Zones inside the line (R′ₖ₊₁ ≤ c)
    /// give 0: `first` may be the ring holding c to skip them.
    pub(super) fn for_zones(&self, c: f64, first: usize, mut visit: impl FnMut(usize, f64)) {
        let n = self.rings;
        let mut prev = back_area(self.stretched[first], c);
        for k in first..=n {
            let next = if k == n { back_area(f64::INFINITY, c) } else { back_area(self.stretched[k + 1], c) };
            visit(k, next - prev);
            prev = next;
        }
    }

    /// Σₖ fₖ ΔSₖ over the zones k ≥ `first` ([`Self::for_zones`]) for the zone factors `factors`
    /// (N + 1 of them): π/(s|ω_xy|) times the back-face area of the table at
    /// c = |ω.z|/(s|ω_xy|).
    pub(super) fn back_sum(&self, factors: &[f64], c: f64, first: usize) -> f64 {
        let mut total = 0.0;
        self.for_zones(c, first, |k, ds| {
            if factors[k] > 0.0 {
                total += factors[k] * ds;
            }
        });
        total
    }
}

/// The largest ratio of successive terms the series of [`back_area`] is used for (t = V/c).
const SERIES_BELOW: f64 = 0.5;
/// A cap on the series' terms (t² ≤ ¼ per term: 30 terms reach 1e-18 relative).
const SERIES_TERMS: usize = 40;

/// The back-face area of the unit GGX lobe restricted to slopes of radius below `r`, seen at
/// the visibility line x = `c` ≥ 0 of the stretched slope plane:
/// S(R, c) = ∫∫_{x > c, x² + y² < R²} (x − c)/(1 + x² + y²)² dx dy (R = ∞ allowed).
///
/// In polar coordinates and with V = √(R² − c²), k = √(1 + c²) (the antiderivatives of
/// 2r√(r² − c²)/(1 + r²)² and of 2rc·acos(c/r)/(1 + r²)², by parts),
/// S = k·atan(V/k) − c·atan(V/c) − (V − c·atan(V/c))/(1 + R²) for R > c, and 0 for R ≤ c;
/// S(∞, c) = (π/2)(k − c), S(R, 0) = atan R − R/(1 + R²). The closed form loses (c/V)² to
/// cancellation as V → 0; below V/c = ½ the integral is summed instead as a series in V/c:
/// S = (2c³/k⁴) ∫₀^{V/c} y(y − atan y)/(1 + βy²)² dy with β = c²/k², whose coefficients are
/// sums of positive terms (a few dozen terms for 1e-16); below R = 1 the closed form is
/// rearranged as c·e(V/c)·R²/(1 + R²) − k·e(V/k), e(y) = y − atan y, whose terms are O(R³)
/// instead of O(R). Relative error below 1e-13 for R from 7.7e-4 (the first ring of 4096) to
/// 1.1e7 (the last), measured against quadrature in the unit tests.
pub(super) fn back_area(r: f64, c: f64) -> f64 {
    if r <= c {
        return 0.0;
    }
    if r.is_infinite() {
        // c = |z|/(s h) ≤ 1/(f32 subnormal)² ≈ 5e89 for every f32 direction and scale: c² ≤ 3e179
        return FRAC_PI_2 / ((1.0 + c * c).sqrt() + c);
    }
    if c == 0.0 {
        // 2∫₀^R v²/(1 + v²)² dv
        if r < SERIES_BELOW {
            let (r2, mut power, mut sum) = (r * r, r * r * r, 0.0);
            for m in 0..SERIES_TERMS {
                let term = (m as f64 + 1.0) * power / (2.0 * m as f64 + 3.0);
                sum += if m % 2 == 0 { term } else { -term };
                if term <= 1e-18 * sum.abs() {
                    break;
                }
                power *= r2;
            }
            return 2.0 * sum;
        }
        return r.atan() - r / (1.0 + r * r);
    }
    let v = ((r - c) * (r + c)).sqrt();
    let t = v / c;
    let k = (1.0 + c * c).sqrt();
    if t >= SERIES_BELOW {
        if r < 1.0 {
            // the same as c·e(t)·R²/(1 + R²) − k·e(V/k), e(y) = y − atan y, both terms O(R³):
            // the form below would cancel its O(R) terms down to O(R³)
            return c * excess(t) * (r * r / (1.0 + r * r)) - k * excess(v / k);
        }
        // k atan(V/k) − c atan(V/c) = atan(V/k)/(k + c) − c·atan(V/((k + c)(ck + V²)))
        let head = (v / k).atan() / (k + c) - c * (v / ((k + c) * (c * k + v * v))).atan();
        return head - (v - c * t.atan()) / (1.0 + r * r);
    }
    // the series: ∫₀^t y e(y)(1 + βy²)⁻² dy = Σⱼ aⱼ t^{2j+3}/(2j+3), e(y) = y − atan y,
    // aⱼ = (−1)^{j+1} Σ_{i<j} (i + 1) βⁱ/(2(j − i) + 1)
    let beta = c * c / (1.0 + c * c);
    let t2 = t * t;
    let mut power = t2 * t2 * t;
    let mut sum = 0.0;
    for j in 1..=SERIES_TERMS {
        let mut a = 0.0;
        let mut beta_i = 1.0;
        for i in 0..j {
            a += (i as f64 + 1.0) * beta_i / (2.0 * (j - i) as f64 + 1.0);
            beta_i *= beta;
        }
        let term = a * power / (2.0 * j as f64 + 3.0);
        sum += if j % 2 == 1 { term } else { -term };
        if term <= 1e-18 * sum.abs() {
            break;
        }
        power *= t2;
    }
    // 2c³/k⁴ = 2 (c/k²)(c²/k²), without overflow
    2.0 * (c / (1.0 + c * c)) * beta * sum
}

/// e(y) = y − atan y ≥ 0 for y ≥ 0, by its series below 0.1 (where the difference cancels).
fn excess(y: f64) -> f64 {
    if y < 0.1 {
        let y2 = y * y;
        // y³/3 − y⁵/5 + … − y²¹/21: the next term is below 1e-20 of the first
        let mut sum = 0.0;
        for n in (1..=10).rev() {
            let sign = if n % 2 == 1 { 1.0 } else { -1.0 };
            sum = sign / (2.0 * n as f64 + 1.0) + y2 * sum;
        }
        return y * y2 * sum;
    }
    y - y.atan()
}

/// The ring of a squared slope radius in constant time: the float bits of r² (exponent and the
/// top mantissa bits, a piecewise-linear log₂) index a table of the ring holding each cell's
/// lower end, and a short walk over the exact boundaries Rₖ² finishes (the cells are at most
/// as wide, in log r², as the narrowest ring, so the walk takes at most a step or two).
#[derive(Debug, Clone)]
pub(super) struct RingLookup {
    /// 52 − (mantissa bits of the key).
    shift: u32,
    /// The key of the first cell.
    first_key: u64,
    /// The ring holding the lower end of each cell.
    start: Vec<u16>,
}

/// The most mantissa bits of the lookup key (2¹³ cells per octave).
const MAX_KEY_BITS: u32 = 13;

impl RingLookup {
    /// The lookup of the boundaries R₁² < … < R_N² (`radii_sq`, with R₀² = 0 first).
    pub(super) fn new(radii_sq: &[f64]) -> Self {
        let n = radii_sq.len() - 1;
        // the narrowest ring in log₂ r² (ring 0 reaches r = 0: infinitely wide)
        let narrowest = (1..n).map(|k| (radii_sq[k + 1] / radii_sq[k]).log2()).fold(f64::INFINITY, f64::min);
        // a cell spans at most 2^−bits/ln 2 in log₂
        let bits = if narrowest.is_finite() {
            ((1.0 / (core::f64::consts::LN_2 * narrowest)).log2().ceil().max(2.0) as u32).min(MAX_KEY_BITS)
        } else {
            2
        };
        let shift = 52 - bits;
        let key = |v: f64| v.to_bits() >> shift;
        // cells from just below R₁² to just above R_N²
        let first_key = key(radii_sq[1]).saturating_sub(1);
        let last_key = key(radii_sq[n]) + 1;
        let start = (first_key..=last_key)
            .map(|cell| {
                let low = f64::from_bits(cell << shift);
                radii_sq[1..].partition_point(|&b| b <= low) as u16
            })
            .collect();
        Self { shift, first_key, start }
    }

    /// The ring k with Rₖ² ≤ r² < Rₖ₊₁² (N for r² ≥ R_N², the tail), for r² ≥ 0 or +∞.
    #[inline(always)]
    pub(super) fn ring(&self, r2: f64, radii_sq: &[f64]) -> usize {
        let n = radii_sq.len() - 1;
        let cell =
            ((r2.to_bits() >> self.shift).saturating_sub(self.first_key) as usize).min(self.start.len() - 1);
        let mut k = usize::from(self.start[cell]);
        while k < n && r2 >= radii_sq[k + 1] {
            k += 1;
        }
        k
    }

    /// Heap bytes.
    pub(super) fn heap_bytes(&self) -> usize {
        self.start.len() * core::mem::size_of::<u16>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::special::GAUSS_LEGENDRE_8;

    /// S(R, c) against Gauss–Legendre quadrature of its defining integral in polar coordinates,
    /// ∫_c^R 2r(√(r² − c²) − c·acos(c/r))/(1 + r²)² dr, on both sides of the series' regime
    /// boundary and near c = 0 and for large c.
    #[test]
    fn back_area_against_quadrature() {
        // composite Gauss–Legendre (8 nodes on each of 256 panels) in ψ, v = √(r² − c²) =
        // k tan ψ (k² = 1 + c²), where the integrand 2v(v − c atan(v/c))/(v² + k²)² dv becomes
        // 2 sin ψ cos ψ (v − c atan(v/c))/k² dψ, smooth and bounded
        let quad = |r: f64, c: f64| {
            let k2 = 1.0 + c * c;
            let k = k2.sqrt();
            let psi_max = (((r - c) * (r + c)).sqrt() / k).atan();
            let f = |psi: f64| {
                let v = k * psi.tan();
                // g = c (t − atan t), t = v/c, by its series where the difference cancels
                let t = v / c;
                let g = if c == 0.0 {
                    v
                } else if t < 0.1 {
                    let t2 = t * t;
                    c * t
                        * t2
                        * (1.0 / 3.0 - t2 * (1.0 / 5.0 - t2 * (1.0 / 7.0 - t2 * (1.0 / 9.0 - t2 / 11.0))))
                } else {
                    v - c * t.atan()
                };
                2.0 * psi.sin() * psi.cos() * g / k2
            };
            let panels = 256;
            let h = psi_max / panels as f64;
            let mut sum = 0.0;
            for p in 0..panels {
                let mid = (p as f64 + 0.5) * h;
                for (x, w) in GAUSS_LEGENDRE_8 {
                    sum += w * 0.5 * h * (f(mid - 0.5 * h * x) + f(mid + 0.5 * h * x));
                }
            }
            sum
        };
        let mut worst = 0.0f64;
        // the ring radii the model uses: R′₁ ≥ 7.7e-4 (N = 4096) up to R′_N ≈ 1.1e7
        for r in [7.7e-4f64, 0.01, 0.1, 0.45, 1.0, 10.0, 1e3, 1.1e7] {
            for t in [f64::INFINITY, 1e-4, 0.01, 0.3, 0.49, 0.5, 0.51, 1.0, 5.0, 300.0, 1e6] {
                // c = R/√(1 + t²): t = V/c (c = 0 for t = ∞)
                let c = if t.is_infinite() { 0.0 } else { r / (1.0 + t * t).sqrt() };
                let (exact, q) = (back_area(r, c), quad(r, c));
                let rel = (exact / q - 1.0).abs();
                worst = worst.max(rel / (1.0 + 1e-6 / (r * r)));
                // the closed form loses up to 1/R² to cancellation (1e-15/R²: 2e-9 at R′₁)
                assert!(
                    rel < 1e-12 + 1e-15 / (r * r),
                    "S({r}, {c}) (t = {t}): {exact:e} vs quadrature {q:e} ({rel:e})"
                );
            }
        }
        for c in [0.0f64, 1e-9, 0.1, 3.0, 2e3, 1e9] {
            // R = ∞ against a large finite R: S(∞) − S(R) ≈ 2/R (the lobe's first moment
            // beyond R), 8c/(πR) of S(∞) ≈ π/(4c)
            let whole = back_area(f64::INFINITY, c);
            let big = 1e12 * c.max(1.0);
            let rel = (whole / back_area(big, c) - 1.0).abs();
            assert!(rel < 1e-11, "S(∞, {c}) = {whole:e}: {rel:e} from S({big:e}, {c})");
        }
        println!("worst relative error of S against quadrature (over 1 + 1e-6/R²): {worst:.2e}");
    }

    /// The lookup finds the ring of every boundary, just below it and between boundaries.
    #[test]
    fn lookup_finds_every_ring() {
        for (scale, rings) in [(0.5, 1usize), (0.3, 7), (1.0, 64), (0.05, 256), (2.0, 4096)] {
            let grid = RingGrid::new(scale, rings);
            let lookup = RingLookup::new(&grid.radii_sq);
            let sq = &grid.radii_sq;
            assert_eq!(lookup.ring(0.0, sq), 0);
            assert_eq!(lookup.ring(f64::INFINITY, sq), rings);
            for k in 1..=rings {
                assert_eq!(lookup.ring(sq[k], sq), k, "boundary {k} of {rings}");
                let below = f64::from_bits(sq[k].to_bits() - 1);
                assert_eq!(lookup.ring(below, sq), k - 1, "below boundary {k} of {rings}");
                let mid = if k < rings { 0.5 * (sq[k] + sq[k + 1]) } else { 2.0 * sq[k] };
                assert_eq!(lookup.ring(mid, sq), k);
            }
        }
    }

    /// The zone masses under GGX(s) sum to 1 with the tail.
    #[test]
    fn zone_masses_sum_to_one() {
        for rings in [1usize, 7, 256, 4096] {
            let grid = RingGrid::new(0.4, rings);
            let total: f64 = grid.ggx_mass.iter().sum();
            assert!((total - 1.0).abs() < 1e-13, "{rings} rings: {total}");
            assert!(grid.ggx_mass.iter().all(|m| *m > 0.0));
        }
    }
}
