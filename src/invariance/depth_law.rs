//! The law of the current vertex's depth given the directions of a path so far, as a
//! position-free state: the Laplace transform of its density, kept in a basis in which every
//! update is a sum of positive terms.

/// The downward segments kept inline before the state spills to the heap. A conductor's path
/// has one run of them, at its start (a mirror reflection only raises a ray: see the module
/// documentation of `invariance`), so this is the rare long dive; diffuse facets can add
/// segments after an upward one.
const INLINE: usize = 8;

/// Rescale the coefficients when their sum leaves [1e-150, 1e150] (they are kept
/// unnormalized, see [`DepthLaw`]).
const RESCALE_BELOW: f64 = 1e-150;
const RESCALE_ABOVE: f64 = 1e150;

/// One downward segment of the path (or the first segment of a path lit from below).
#[derive(Debug, Clone, Copy, Default)]
struct Segment {
    /// Its rate a > 0: |Λ| of its direction, the intersection rate per unit depth.
    rate: f64,
    /// y(σo) = a/(σo + a) at the exit rate σo of the evaluation (1 without one).
    at_exit: f64,
    /// Its coefficient C in Ψ(s) = Σ C_d Q_d(s) / Σ C_d (unnormalized).
    coefficient: f64,
}

/// The segments: inline up to [`INLINE`], then on the heap (long paths only).
#[derive(Debug, Clone)]
enum Segments {
    Inline { len: usize, items: [Segment; INLINE] },
    Heap(Vec<Segment>),
}

impl Segments {
    #[inline(always)]
    fn one(segment: Segment) -> Self {
        let mut items = [Segment::default(); INLINE];
        items[0] = segment;
        Self::Inline { len: 1, items }
    }

    #[inline(always)]
    fn push(&mut self, segment: Segment) {
        match self {
            Self::Inline { len, items } if *len < INLINE => {
                items[*len] = segment;
                *len += 1;
            }
            Self::Inline { len, items } => {
                let mut v = Vec::with_capacity(4 * INLINE);
                v.extend_from_slice(&items[..*len]);
                v.push(segment);
                *self = Self::Heap(v);
            }
            Self::Heap(v) => v.push(segment),
        }
    }

    #[inline(always)]
    fn as_mut_slice(&mut self) -> &mut [Segment] {
        match self {
            Self::Inline { len, items } => &mut items[..*len],
            Self::Heap(v) => v,
        }
    }
}

/// The law of the depth of a path's current vertex given the directions d₀ … d_j of its
/// segments, in the depth τ = −ln C¹(h) ≥ 0 of the Smith microsurface (Heitz et al. 2016,
/// supplement §1.1: a height enters the model only through C¹), in which a ray along d
/// meets the surface at the constant rate |Λ(d)| per unit depth.
///
/// Its density φ_j(τ) has the Laplace transform Φ_j(s) = ∫ φ_j(τ) e^{−sτ} dτ, and:
///
/// * Φ(s)/Φ(0) = E[e^{−sτ}] is the probability that a ray with Λ = s leaving the vertex
///   upwards escapes (the masking C¹^Λ averaged over the depth);
/// * a segment going down with rate a (τ′ > τ, transmittance e^{−a(τ′−τ)}) multiplies it:
///   Φ′(s) = Φ(s)/(s + a);
/// * a segment going up with rate b that hits (τ′ < τ) takes a divided difference:
///   Φ′(s) = (Φ(s) − Φ(b))/(b − s), and it hits with probability 1 − Φ(b)/Φ(0).
///
/// The entry segment from above (rate a₀ = 1 + Λ(ωi)) gives Φ₁(s) = 1/(s + a₀); from below
/// (rate Λ(−ωi)) the same form. This state keeps the normalized transform Ψ = Φ/Φ(0) as
/// Ψ(s) = Σ_d C_d Q_d(s) / Σ_d C_d over the downward segments d in path order, with
/// Q_d(s) = Π_{l ≥ d} y_l(s), y_l(s) = a_l/(s + a_l) ∈ (0, 1] (suffix products; Q_d(0) = 1):
///
/// * down (rate a): a new segment with C = 0; every Q_d gains the factor y_a;
/// * up (rate b): by the Leibniz rule for divided differences, −y_l[s, b] = y_l(s) y_l(b)/a_l,
///   the new coefficients are t_i = (S_{i−1} + C_i)/(b + a_i) with S_i = a_i t_i (S₀ = 0),
///   and the hit probability is b Σ t_i / Σ C_i.
///
/// Every update adds and multiplies positive numbers (no subtraction, so no cancellation for
/// nearly equal rates); a step costs O(1) down and O(N) up, N the number of downward
/// segments. The coefficients are unnormalized and rescaled when their sum leaves
/// [1e-150, 1e150].
#[derive(Debug, Clone)]
pub(crate) struct DepthLaw {
    segments: Segments,
    /// Σ_d C_d.
    norm: f64,
    /// The exit rate σo = Λ(ωo) of the evaluation (0 without one).
    exit_rate: f64,
    /// Σ_d C_d Q_d(σo), unnormalized.
    exit_sum: f64,
}

impl DepthLaw {
    /// The law at the first vertex: the entry segment has rate `first_rate` > 0, and
    /// [`Self::escape_at_exit`] answers for the exit rate `exit_rate` ≥ 0.
    #[inline(always)]
    pub(crate) fn new(first_rate: f64, exit_rate: f64) -> Self {
        let at_exit = y(first_rate, exit_rate);
        let segment = Segment { rate: first_rate, at_exit, coefficient: 1.0 };
        Self { segments: Segments::one(segment), norm: 1.0, exit_rate, exit_sum: at_exit }
    }

    /// E[e^{−σo τ}]: the probability that a ray along ωo (Λ(ωo) = σo) leaves the current
    /// vertex without meeting the surface, given the path so far. In [0, 1].
    #[inline(always)]
    pub(crate) fn escape_at_exit(&self) -> f64 {
        (self.exit_sum / self.norm).min(1.0)
    }

    /// The next segment goes down with rate `rate` = |Λ(d)| ≥ 1 (it always meets the
    /// surface).
    #[inline(always)]
    pub(crate) fn down(&mut self, rate: f64) {
        let at_exit = y(rate, self.exit_rate);
        self.exit_sum *= at_exit;
        self.segments.push(Segment { rate, at_exit, coefficient: 0.0 });
    }

    /// The next segment goes up with rate `rate` = Λ(d) ≥ 0: returns the probability that it
    /// meets the surface, 1 − Ψ(rate) = rate·Σ t_i/Σ C_i (in [0, 1]), and turns the state into
    /// the law of the next vertex given that it does. Where it returns 0 (a ray straight up,
    /// or a Λ that underflowed) the path has ended and the state must not be used again.
    #[inline(always)]
    pub(crate) fn up(&mut self, rate: f64) -> f64 {
        let (mut carried, mut sum, mut exit_sum) = (0.0, 0.0, 0.0);
        // one pass: the new coefficients t_i, their sum and Horner's Σ t_d Q_d(σo)
        for s in self.segments.as_mut_slice() {
            let t = (carried + s.coefficient) / (rate + s.rate);
            carried = s.rate * t;
            s.coefficient = t;
            sum += t;
            exit_sum = (exit_sum + t) * s.at_exit;
        }
        let hit = rate * sum / self.norm;
        if hit.is_nan() || hit <= 0.0 {
            return 0.0;
        }
        self.norm = sum;
        self.exit_sum = exit_sum;
        if !(RESCALE_BELOW..=RESCALE_ABOVE).contains(&sum) {
            self.rescale();
        }
        hit.min(1.0)
    }

    /// Divides the coefficients by their sum.
    #[cold]
    fn rescale(&mut self) {
        let inv = 1.0 / self.norm;
        for s in self.segments.as_mut_slice() {
            s.coefficient *= inv;
        }
        self.exit_sum *= inv;
        self.norm = 1.0;
    }

    /// Ψ(s) = E[e^{−sτ}] for any s ≥ 0 (Horner over the segments; for tests and callers
    /// without a fixed exit rate).
    #[cfg(test)]
    fn escape(&mut self, s: f64) -> f64 {
        let mut h = 0.0;
        for seg in self.segments.as_mut_slice().iter() {
            h = (h + seg.coefficient) * y(seg.rate, s);
        }
        h / self.norm
    }
}

/// y(s) = a/(s + a) ∈ (0, 1]: 1 at s = 0 (also for a = 0).
#[inline(always)]
fn y(a: f64, s: f64) -> f64 {
    if s == 0.0 { 1.0 } else { a / (s + a) }
}

#[cfg(test)]
mod tests {
    use super::DepthLaw;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    /// Φ(s) of a path with segment rates `rates[j]` (segment 0 down from the top; `down[j]`
    /// whether segment j goes down), ending at its last vertex, with an exit segment of rate
    /// `s` back to the top: the depth integral by the gap formula, an independent closed form.
    /// Order the k vertices by depth (every order the directions allow); the depths' gaps are
    /// independent exponential integrals, ∫ e^{−rδ} dδ = 1/r, r the summed rate of the segments
    /// spanning the gap. Exact; k! orders.
    fn gap_formula(rates: &[f64], down: &[bool], s: f64) -> f64 {
        let k = rates.len();
        let mut order: Vec<usize> = (1..=k).collect();
        let mut total = 0.0;
        permute(&mut order, 0, &mut |perm| {
            // rank[v]: 0 for the top (vertex 0 and the exit), 1.. by depth
            let mut rank = vec![0usize; k + 1];
            for (r, &v) in perm.iter().enumerate() {
                rank[v] = r + 1;
            }
            // segment j joins vertices j and j + 1; the exit joins vertex k and the top
            for j in 0..k {
                let deeper = if down[j] { rank[j + 1] > rank[j] } else { rank[j + 1] < rank[j] };
                if !deeper {
                    return;
                }
            }
            let mut product = 1.0;
            for m in 1..=k {
                let mut r = 0.0;
                for j in 0..k {
                    let (lo, hi) = (rank[j].min(rank[j + 1]), rank[j].max(rank[j + 1]));
                    if lo < m && m <= hi {
                        r += rates[j];
                    }
                }
                if rank[k] >= m {
                    r += s;
                }
                product /= r;
            }
            total += product;
        });
        total
    }

    fn permute(v: &mut Vec<usize>, i: usize, f: &mut dyn FnMut(&[usize])) {
        if i == v.len() {
            f(v);
            return;
        }
        for j in i..v.len() {
            v.swap(i, j);
            permute(v, i + 1, f);
            v.swap(i, j);
        }
    }

    /// The state against the gap formula on 400 random paths of 1 to 7 segments, zigzags
    /// (down after up) included, with rates drawn so that many are nearly equal: Ψ(s) at the
    /// exit rate and at three other points, and every up step's hit probability 1 − Ψ(b), to
    /// a relative 1e-12 (the formula's own rounding is of that order).
    #[test]
    fn matches_the_gap_formula() {
        let mut rng = Pcg64Mcg::seed_from_u64(5);
        let mut zigzags = 0;
        for case in 0..400 {
            let k = 1 + case % 7;
            let exit = if case % 5 == 0 { 1e-3 } else { rng.random::<f64>() * 3.0 };
            let base = 1.0 + rng.random::<f64>();
            let mut rates = vec![base];
            let mut down = vec![true];
            let mut law = DepthLaw::new(base, exit);
            for _ in 1..k {
                let go_down = rng.random::<bool>();
                // a third of the rates repeat the previous one within 1e-9
                let rate = if rng.random::<f64>() < 0.33 {
                    rates.last().unwrap() * (1.0 + 1e-9 * rng.random::<f64>())
                } else if go_down {
                    1.0 + 4.0 * rng.random::<f64>()
                } else {
                    5.0 * rng.random::<f64>().powi(3)
                };
                let rate = if go_down { rate.max(1.0) } else { rate };
                if go_down {
                    law.down(rate);
                } else {
                    let expected = 1.0 - gap_formula(&rates, &down, rate) / gap_formula(&rates, &down, 0.0);
                    let hit = law.up(rate);
                    assert!(
                        (hit - expected).abs() <= 1e-12 * expected.max(1e-3),
                        "case {case}: hit {hit} vs {expected}"
                    );
                }
                rates.push(rate);
                down.push(go_down);
            }
            zigzags += usize::from((1..k).any(|i| !down[i] && down[i + 1..].contains(&true)));
            let zero = gap_formula(&rates, &down, 0.0);
            for s in [exit, 0.0, 0.37, 2.5] {
                let expected = gap_formula(&rates, &down, s) / zero;
                let got = if s == exit { law.escape_at_exit() } else { law.escape(s) };
                assert!(
                    (got - expected).abs() <= 1e-12 * expected,
                    "case {case}, rates {rates:?}, down {down:?}, s = {s}: {got} vs {expected}"
                );
            }
        }
        assert!(zigzags > 50, "only {zigzags} paths with a segment down after one up");
    }

    /// Many segments: the coefficients spill to the heap and are rescaled, and the state
    /// stays a probability law (Ψ(0) = 1, Ψ decreasing, hit probabilities in [0, 1]).
    #[test]
    fn long_paths_stay_normalized() {
        let mut rng = Pcg64Mcg::seed_from_u64(9);
        let mut law = DepthLaw::new(1.5, 0.2);
        for step in 0..2000 {
            if step % 3 == 2 {
                let hit = law.up(1e3 * rng.random::<f64>());
                assert!((0.0..=1.0).contains(&hit));
            } else {
                law.down(1.0 + rng.random::<f64>());
            }
            let (e0, e1, e2) = (law.escape(0.0), law.escape(0.2), law.escape(5.0));
            assert!((e0 - 1.0).abs() < 1e-12 && e1 <= 1.0 && e2 <= e1 && e2 >= 0.0, "step {step}");
            assert!((law.escape_at_exit() - e1).abs() <= 1e-12, "step {step}");
        }
    }
}
