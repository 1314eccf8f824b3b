//! Material-independent geometry of the microsurface: masking and the height of the next
//! intersection (Heitz et al. 2016, supplement §3.1).

use crate::contract::{is_direction, is_uniform};
use crate::height::MicrosurfaceHeight;
use crate::lanes::Lanes;
use crate::rng::{TAIL_CUT, cut_tails};
use crate::slope::MicrosurfaceSlope;
use crate::special::{ln, ln_1m_exp_f32, ln_f32};
use glam::Vec3;

/// Where a ray leaving a point of the microsurface goes next (supplement §3.1, Algorithm 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HeightSample {
    /// The ray intersects the microsurface again, at this height.
    Hit(f32),
    /// The ray leaves the microsurface without further intersection.
    Escape,
}

/// A microsurface without a material: a height distribution and a slope distribution.
///
/// It answers the geometric questions of the Smith model: masking G1, masking at a height,
/// and the height of the next intersection along a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MicrosurfaceGeometry<H, S> {
    height: H,
    slope: S,
}

impl<H: MicrosurfaceHeight, S: MicrosurfaceSlope> MicrosurfaceGeometry<H, S> {
    /// Combines a height and a slope distribution.
    pub fn new(height: H, slope: S) -> Self {
        Self { height, slope }
    }

    /// The height distribution.
    #[inline]
    pub fn height(&self) -> &H {
        &self.height
    }

    /// The slope distribution.
    #[inline]
    pub fn slope(&self) -> &S {
        &self.slope
    }

    /// The masking function averaged over heights, G1(ω) = 1/(1 + Λ(ω)) for ω.z > 0 and 0 for
    /// ω.z ≤ 0 (supplement §3.1). In [0, 1]; 1 at the zenith, 0 at the horizon.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `w` that is not a unit direction gives
    /// NaN (a debug assertion in debug builds).
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        require!(is_direction(w), f32::NAN; w);
        if w.z <= 0.0 {
            return 0.0;
        }
        1.0 / (1.0 + self.slope.lambda_unchecked(w))
    }

    /// The masking function at height h, G1(ω, h) = C¹(h)^Λ(ω) for ω.z > 0 and 0 for ω.z ≤ 0
    /// (supplement §3.1): the probability that a ray leaving height h in direction ω escapes.
    /// `h` may be +∞ (above the surface: 1).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `w` that is not a unit direction or a
    /// NaN `h` gives NaN (a debug assertion in debug builds).
    #[inline]
    pub fn g1_at(&self, w: Vec3, h: f32) -> f32 {
        require!(is_direction(w) && !h.is_nan(), f32::NAN; w, h);
        if w.z <= 0.0 {
            return 0.0;
        }
        escape_probability(self.height.c1(h), self.slope.lambda_unchecked(w))
    }

    /// Samples the height of the next intersection of a ray leaving height `h0` in direction
    /// `w`, from one uniform `u` ∈ [0, 1) (supplement §3.1, Algorithm 1).
    ///
    /// The ray escapes with probability G1(ω, h0); otherwise the next height is
    /// C⁻¹(C¹(h0) / (1 − u)^{1/Λ(ω)}), with u cut to [2⁻²⁴, 1 − 2⁻²⁴] (the crate's tail
    /// policy: u = 0 would hit at h0 itself). The heights are resolved to the f32 spacing of
    /// C¹: within 2⁻²⁵ of C¹ = 1 (a grazing ray from above, |Λ| > 2) C¹ rounds to 1 and the
    /// hit is reported at the end value `inv_c1(1)` (the random walks work in ln C¹ instead and
    /// resolve it). `h0` may be +∞ (a ray arriving from above the surface).
    /// Special cases: a ray straight up (Λ = 0) always escapes; a downward ray always hits
    /// (below h0; straight down, uniformly in C¹ below h0); a horizontal ray hits at h0
    /// itself, or escapes if h0 = +∞.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `w` that is not a unit direction, a
    /// NaN `h0` or a `u` outside [0, 1] gives `HeightSample::Hit(NaN)` (a debug assertion in
    /// debug builds).
    #[inline]
    pub fn sample_height(&self, w: Vec3, h0: f32, u: f32) -> HeightSample {
        require!(is_direction(w) && !h0.is_nan() && is_uniform(u), HeightSample::Hit(f32::NAN); w, h0, u);
        if w.z == 0.0 {
            return if h0 == f32::INFINITY { HeightSample::Escape } else { HeightSample::Hit(h0) };
        }
        match next_c1(w.z, self.slope.lambda_unchecked(w), self.height.c1(h0), u) {
            Some(c) => HeightSample::Hit(self.height.inv_c1(c)),
            None => HeightSample::Escape,
        }
    }
}

impl<H: MicrosurfaceHeight, S: MicrosurfaceSlope> MicrosurfaceGeometry<H, S> {
    /// Samples the height of the first intersection of a ray arriving from below the
    /// macrosurface, lit (or seen) from `wi` with ωi.z < 0 (the ray travels along −ωi,
    /// upwards), from one uniform `u` ∈ [0, 1): h₁ = C⁻¹(exp(ln(1 − u)/Λ(−ωi))), whose C¹ has
    /// the CDF C^{1/G1(ωi)} with the full-spherical G1(ωi) = 1/|1 + Λ(ωi)| (Wang et al. 2022,
    /// eq. 10): the visible-height distribution of a ray from above (Algorithm 1 of the
    /// supplement started at h = +∞) extended to the lower hemisphere. The height-space form
    /// of the random walk's backfacing start ([`Microsurface::eval_from_below`]); further
    /// heights follow from [`MicrosurfaceGeometry::sample_height`].
    ///
    /// `None` if ωi is not below the horizon, or if Λ(−ωi) = 0 (ωi at the nadir sees no
    /// microsurface). In f32, C¹ = exp(ln C¹) leaves the normal range for ln C¹ < −87, which
    /// happens with probability e^{−87 Λ(−ωi)} (2e-4 for Λ(−ωi) = 0.1): the height then
    /// saturates towards C⁻¹(0) and loses the depth; and the height itself resolves C¹ only
    /// to its own rounding near the bottom (uniform heights: h = 2C¹ − 1, C¹ to ~6e-8, below
    /// which h = −1 and C¹ = 0, where no ray escapes). Deep first hits (views from well below
    /// the horizon, E[ln C¹₁] = −1/Λ(−ωi)) are therefore only usable with a height
    /// distribution that resolves its tail (Gaussian); the C¹-space walk carries ln C¹ and has
    /// no such floor.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` that is not a unit direction or a
    /// uniform outside [0, 1] gives `None` (a debug assertion in debug builds).
    ///
    /// [`Microsurface::eval_from_below`]: crate::research::Microsurface::eval_from_below
    #[inline]
    pub fn sample_height_from_below(&self, wi: Vec3, u: f32) -> Option<f32> {
        require!(is_direction(wi) && is_uniform(u), None; wi, u);
        if wi.z >= 0.0 {
            return None;
        }
        let ln_c1 = first_ln_c1_from_below(self.slope.lambda(-wi), u)?;
        Some(self.height.inv_c1(ln_c1.exp()))
    }
}

/// C¹(h)^Λ for Λ ≥ 0: the probability of escaping from a point whose height has CDF value
/// `c1`. 0^0 = 1 (a ray straight up from the bottom escapes).
#[inline(always)]
pub(crate) fn escape_probability(c1: f32, lambda: f32) -> f32 {
    c1.powf(lambda)
}

/// Algorithm 1 of the supplement in C¹ space: the CDF value of the next intersection's
/// height, or `None` if the ray escapes. `lambda` is Λ(ω) for the ray direction with
/// z-component `z`.
///
/// u is cut to [2⁻²⁴, 1 − 2⁻²⁴] (the crate's tail policy): u = 0 would put 2⁻²⁴ of the hits at
/// the starting height itself (for a ray from above, at the top of the surface), where the
/// model has nothing beyond.
///
/// Computed in log space: the ray escapes iff ln(1 − u) ≤ Λ ln c1, and otherwise
/// c1' = exp(ln c1 − ln(1 − u)/Λ) (in this form c1 = 0 gives 0, not 0·∞), which lies in
/// [0, c1] below the horizon and in [c1, 1) above it.
#[inline(always)]
pub(crate) fn next_c1(z: f32, lambda: f32, c1: f32, u: f32) -> Option<f32> {
    // the crate's tail policy: u = 0 would hit at c1 itself (nothing of the model beyond)
    let u = cut_tails(u);
    // ln(1 − u) with 1 − u exact for u ≥ ½ and for every multiple of 2⁻²⁴ (the crate's
    // uniforms); elsewhere 1 − u rounds by at most ½ ulp, which moves the height quantile by
    // less than 6e-8 — cheaper than ln_1p, whose extra accuracy for tiny u is irrelevant here
    let ln_1mu = (1.0 - u).ln();
    if z > 0.0 {
        if c1 >= 1.0 || lambda == 0.0 || ln_1mu <= lambda * c1.ln() {
            return None;
        }
        Some((c1.ln() - ln_1mu / lambda).exp().min(1.0))
    } else {
        // Λ ≤ −1 below the horizon; Λ = −1 − Λ(−ω) saturates at −f32::MAX at the horizon
        Some(c1 * (ln_1mu / -lambda).exp())
    }
}

/// The smallest |ln C¹| of a point where a ray hit the microsurface: hits lie strictly inside
/// the surface (C¹ < 1), also after rounding, so that the point on the other side of a
/// dielectric interface has ln C¹ = ln(1 − C¹) finite.
pub(crate) const MIN_HIT_DEPTH: f32 = f32::MIN_POSITIVE;

/// Algorithm 1 of the supplement in log-C¹ space, the state of the random walks: the
/// ln C¹ of the next intersection's height, or `None` if the ray escapes. `ln_c1` = 0 is a ray
/// from above the surface; `lambda` is Λ(ω) for the ray direction with z-component `z`.
///
/// u is cut as in [`next_c1`]. The ray escapes iff it goes up and ln(1 − u) ≤ Λ ln C¹; otherwise
/// ln C¹' = ln C¹ − ln(1 − u)/Λ (above the horizon Λ ≥ 0 and the height increases, below it
/// Λ ≤ −1 and it decreases). One logarithm per intersection, and the masking of the next
/// event is exp(Λ ln C¹'): heights themselves are never needed (supplement §1.1). A horizontal
/// ray (Λ saturated at `f32::MAX`) hits at its own height, or escapes from above the surface.
///
/// An escape needs no logarithm where −u ≤ Λ ln C¹ already: ln(1 − u) ≤ −u, so the test
/// ln(1 − u) ≤ Λ ln C¹ holds, and it also holds in floating point (see the body). The decisions
/// are those of the logarithm itself, bit for bit; most rays going up escape this way.
#[inline(always)]
pub(crate) fn next_ln_c1(z: f32, lambda: f32, ln_c1: f32, u: f32) -> Option<f32> {
    // tails cut and 1 − u: see `next_c1`
    let one_minus_u = 1.0 - cut_tails(u);
    if z >= 0.0 && escapes_without_log(lambda, ln_c1, one_minus_u) {
        return None;
    }
    // the logarithm inline (`special::ln_f32`, correctly rounded but for 0.002 ulp)
    let (next, escapes) = step_ln_c1(z, lambda, ln_c1, ln_f32(one_minus_u));
    if escapes { None } else { Some(next) }
}

/// The first intersection of a ray from above the surface (ln C¹ = 0) going down, for a walk
/// that may need its point on both sides of the interface (a dielectric's), with
/// Λ(ωi) = `lambda_i` ≥ 0 for the incident direction ωi = −ωr: its C¹ has the CDF
/// c^{1 + Λ(ωi)} (Algorithm 1 from h = +∞, as [`next_ln_c1`] draws it from ln C¹ = 0), drawn
/// as max(C, W) of the independent C = 1 − u1, uniform, and W = V^{1/Λ(ωi)}, V = 1 − u2
/// (P(max(C, W) ≤ c) = c · c^{Λ(ωi)}), the uniforms cut as in [`next_c1`].
///
/// Returns C itself (in (0, 1), a positive number) where C is the maximum: its point is then
/// known on both sides without an exponential, ln C¹ = ln C and ln(1 − C¹) = ln u1 (1 − C is
/// exact: the uniforms are multiples of 2⁻²⁴), one logarithm for whichever side the walk
/// needs. Otherwise ln C¹ = ln W = ln V/Λ(ωi) (at most −[`MIN_HIT_DEPTH`]). C is the maximum
/// for sure, without a logarithm, where u2 C > Λ(ωi) u1 (products of f32, exact in f64):
/// ln W ≤ −u2/Λ(ωi) < −u1/C ≤ ln C; elsewhere the f64 logarithms decide (relative error below
/// 1e-10). The bound leaves 7 % of the draws to the logarithms at Λ(ωi) = 0.018, 24 % at 0.1
/// and 55 % at 0.5, and W is the maximum with probability Λ(ωi)/(1 + Λ(ωi)): the form pays
/// where Λ(ωi) is small (the walks take it up to Λ(ωi) = 0.5).
#[inline(always)]
pub(crate) fn first_hit_two_sided(lambda_i: f32, u1: f32, u2: f32) -> f32 {
    // the uniforms are at most 1 − 2⁻²⁴ already (`crate::rng::uniform`): the lower cut of u1
    // alone, and u2's cut only ahead of its logarithm (it only raises u2, so the bound below
    // holds for the uncut u2 too)
    let u1 = u1.max(TAIL_CUT);
    let c = 1.0 - u1;
    if f64::from(u2) * f64::from(c) > f64::from(lambda_i) * f64::from(u1) {
        return c;
    }
    let (ln_v, lambda_i) = (ln(f64::from(1.0 - cut_tails(u2))), f64::from(lambda_i));
    if ln_v > lambda_i * ln(f64::from(c)) { ((ln_v / lambda_i) as f32).min(-MIN_HIT_DEPTH) } else { c }
}

/// Whether a ray going up (z ≥ 0) with Λ = `lambda` from ln C¹ = `ln_c1` escapes for the
/// uniform 1 − u = `one_minus_u` without the logarithm (every lane type): Λ = 0, or
/// −u′ = (1 − u) − 1 ≤ Λ ln C¹ with u′ the uniform 1 − u stands for (exact for 1 − u ≥ ½;
/// below, where the subtraction may round by 2⁻²⁵, ln(1 − u) < −u′ − 0.19): then
/// ln(1 − u) ≤ −u′ ≤ Λ ln C¹, and the f32 logarithm (within 1e-10 of ln(1 − u), which is below
/// −u′ by u′²/2 ≥ 2⁻⁴⁹ relative to u′) would round to at most the f32 Λ ln C¹ too.
#[inline(always)]
pub(crate) fn escapes_without_log<L: Lanes>(lambda: L, ln_c1: L, one_minus_u: L) -> L::Mask {
    lambda.eq(L::lit(0.0)) | (one_minus_u - L::lit(1.0)).le(lambda * ln_c1)
}

/// Algorithm 1's step in ln C¹ space from ln(1 − u) = `ln_1mu` (every lane type): the next
/// ln C¹ = ln C¹ − ln(1 − u)/Λ (at most −[`MIN_HIT_DEPTH`]), and whether the ray escapes instead
/// (it goes up, z ≥ 0, and ln(1 − u) ≤ Λ ln C¹).
#[inline(always)]
pub(crate) fn step_ln_c1<L: Lanes>(z: L, lambda: L, ln_c1: L, ln_1mu: L) -> (L, L::Mask) {
    let escapes = z.ge(L::lit(0.0)) & ln_1mu.le(lambda * ln_c1);
    ((ln_c1 - ln_1mu / lambda).min(L::lit(-MIN_HIT_DEPTH)), escapes)
}

/// ln C¹ of the first intersection of a ray arriving from below the macrosurface, for an
/// opaque microsurface lit (or seen) from ωi with ωi.z < 0, from one uniform `u` ∈ [0, 1);
/// `lambda_up` = Λ(−ωi) = |1 + Λ(ωi)| = 1/G1(ωi), the full-spherical masking's inverse (Wang
/// et al. 2022, eq. 10). `None` if Λ(−ωi) = 0 (ωi at the nadir, or Λ underflowed): ωi then
/// sees no microsurface (projected area 0).
///
/// ln C¹₁ = ln(1 − u)/Λ(−ωi): the first hit's C¹ has the CDF C^{1/G1(ωi)}. From above,
/// Algorithm 1 of the supplement started at h = +∞ gives C^{1 + Λ(ωi)} = C^{1/G1(ωi)}, the
/// visible-height distribution G1(ωi, h)/G1(ωi); below the horizon the full-spherical Smith
/// model keeps that form with 1/G1(ωi) = A(ωi)/|cos θi| (A the projected area of the facets
/// facing ωi). A literal ray from h = −∞ does not work: hits occur at the rate Λ(−ωi) per
/// unit of ln C¹, so from ln C¹ = −∞ the first hit is at C¹ = 0 almost surely and nothing
/// escapes (0^Λ = 0), the hemispherical model's black result. This choice makes the walk's
/// single-scattering term the full-spherical height-correlated one, E[C^{Λ(ωo)}] =
/// Λ(−ωi)/(Λ(−ωi) + Λ(ωo)), i.e. G2 = 1/(Λ(−ωi) + Λ(ωo)) (Wang et al. 2022, eq. 17), and the
/// first vertex the position-free model's vertex reached from below (see DESIGN.md,
/// “Views from below in the walk”).
///
/// The result lies in [−f32::MAX, −f32::MIN_POSITIVE]. ln(1 − u)/Λ overflows only for
/// Λ(−ωi) < 5e-38 (GGX: ωi within ~1e-19 rad of the nadir; Beckmann: a denormal Λ, smooth
/// surfaces seen from well below). There the depth is not representable in f32; the clamp
/// keeps the walk's arithmetic finite (no 0·∞, no NaN), but the walk is then inaccurate
/// (the later escape probabilities e^{Λ(ω) ln C¹}, with Λ(ω) of the same tiny order, are
/// distorted). See DESIGN.md for this limitation.
#[inline]
pub(crate) fn first_ln_c1_from_below(lambda_up: f32, u: f32) -> Option<f32> {
    if lambda_up.is_nan() || lambda_up <= 0.0 {
        return None;
    }
    // 1 − u: see `next_c1`; the tails cut at 2⁻²⁴ like every quantile (u = 0 would put the
    // first hit at the very top, ln C¹ = −MIN_HIT_DEPTH)
    let ln_1mu = (1.0 - cut_tails(u)).ln();
    Some((ln_1mu / lambda_up).clamp(f32::MIN, -MIN_HIT_DEPTH))
}

/// The depth of a point of a walk that entered from below the macrosurface, in the scale of
/// its first hit: s = −ln C¹ · Λ(−ωi) ≥ 0, with ln Λ(−ωi) (`ln_lambda_in`) kept alongside.
///
/// Seen from below, the first hit has ln C¹₁ = ln(1 − u)/Λ(−ωi) (`first_ln_c1_from_below`),
/// and Λ(−ωi) ≈ e^{−a²} (Beckmann, a = |cot θi|/αᵢ) underflows f32 from a ≈ 9.6 and f64 from
/// a ≈ 26.6, where ln C¹ itself is no longer representable. In this scale the first depth is
/// s₁ = −ln(1 − u) and every quantity of Algorithm 1 (supplement §3.1) is a ratio of Λs, formed
/// as exp(ln Λ − ln Λ(−ωi)) from [`MicrosurfaceSlope::ln_lambda`]: the masking C¹^Λ(ω) =
/// exp(−s Λ(ω)/Λ(−ωi)), the escape test −ln(1 − u) ≥ s Λ(ω)/Λ(−ωi) of an upward ray, and the
/// next depth s ∓ (−ln(1 − u)) Λ(−ωi)/|Λ(ω)|. Exact reformulation of the ln C¹ walk; relative
/// error of the ratios ~1e-13·a² (that of ln Λ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ScaledDepth {
    /// −ln C¹ · Λ(−ωi).
    s: f64,
    /// ln Λ(−ωi), finite.
    ln_lambda_in: f64,
}

impl ScaledDepth {
    /// The first hit of a ray arriving from below with ln Λ(−ωi) = `ln_lambda_in`, from one
    /// uniform `u` (tails cut as in [`next_c1`]); `None` where ωi sees no microsurface
    /// (Λ(−ωi) = 0: ωi at the nadir) or ln Λ is NaN.
    #[inline]
    pub(crate) fn first(ln_lambda_in: f64, u: f32) -> Option<Self> {
        if !(ln_lambda_in > f64::NEG_INFINITY && ln_lambda_in < f64::INFINITY) {
            return None;
        }
        Some(Self { s: exponential(u).max(f64::MIN_POSITIVE), ln_lambda_in })
    }

    /// The masking C¹^Λ(ω) = exp(−s Λ(ω)/Λ(−ωi)) of an upward direction with ln Λ(ω) =
    /// `ln_lambda`: the probability that a ray from this point escapes along it (supplement
    /// §3.1). In [0, 1].
    #[inline]
    pub(crate) fn escape_probability(self, ln_lambda: f64) -> f64 {
        (-self.s * (ln_lambda - self.ln_lambda_in).exp()).exp()
    }

    /// The next hit of the ray `w` leaving this point, or `None` if it escapes, from one
    /// uniform `u` (Algorithm 1 of the supplement in this scale). A horizontal ray hits at its
    /// own depth.
    #[inline]
    pub(crate) fn next<S: MicrosurfaceSlope>(self, slope: &S, w: Vec3, u: f32) -> Option<Self> {
        let e = exponential(u);
        let s = if w.z > 0.0 {
            // Λ(ω)/Λ(−ωi); the ray escapes iff −ln(1 − u) ≥ Λ(ω)·(−ln C¹)
            let ratio = (slope.ln_lambda(w) - self.ln_lambda_in).exp();
            if e >= ratio * self.s {
                return None;
            }
            self.s - e / ratio
        } else {
            // |Λ(ω)| = 1 + Λ(−ω) ≥ 1 going down (+∞ horizontally: no step)
            self.s + e * (self.ln_lambda_in - slope.lambda64(-w).ln_1p()).exp()
        };
        Some(Self { s: s.max(f64::MIN_POSITIVE), ln_lambda_in: self.ln_lambda_in })
    }
}

/// −ln(1 − u) with the tails cut (u = 0 would hit at the starting point itself) and 1 − u
/// rounded as in [`next_c1`]: the exponential variate of Algorithm 1.
#[inline(always)]
fn exponential(u: f32) -> f64 {
    -f64::from((1.0 - cut_tails(u)).ln())
}

/// ln(1 − C¹) from ln C¹: the same point seen from the other side of the interface, in the
/// vertically flipped frame (h ↦ −h; the height distributions are symmetric; supplement §3.4).
///
/// ln(1 − eˣ) without cancellation on either side of x = −ln 2 (Mächler 2012, “Accurately
/// computing log(1 − exp(−|a|))”; in f64 and inline, `ln_1m_exp_f32`): ln(−x) plus a
/// series near the top (x → 0⁻, 1 − C¹ small) and ln of the rounded 1 − eˣ plus its rounding
/// error below (C¹ < ½, the result small). Within 0.51 f32 ulp for every hit depth
/// x ∈ [−f32::MAX, −f32::MIN_POSITIVE]; −0 where eˣ underflows (x < −104).
#[inline(always)]
pub(crate) fn flip_ln_c1(ln_c1: f32) -> f32 {
    ln_1m_exp_f32(ln_c1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tail policy in ln C¹ space (where the walks resolve it): at u = 0 a ray from above
    /// hits with 2⁻²⁴ of the hits above it (before: at the very top, ln C¹ = −1e-38), an upward
    /// ray with 2⁻²⁴ of the hits below it (before: at its own height).
    #[test]
    fn next_ln_c1_cuts_the_tails_at_the_uniforms_spacing() {
        let bucket = 2f64.powi(-24);
        for lambda in [-1.0f32, -1.5, -7.0, -1e3] {
            // downward from above: P(C′ > c) = 1 − c^|Λ|
            let ln_c = next_ln_c1(-0.5, lambda, 0.0, 0.0).expect("a downward ray hits");
            let above = -(f64::from(-lambda) * f64::from(ln_c)).exp_m1();
            assert!(above >= 0.5 * bucket, "Λ = {lambda}: {above:e} of the hits above the u = 0 hit");
        }
        for lambda in [0.01f32, 0.5, 3.0] {
            // upward from ln C¹ = −10⁻³ (where f32 resolves the step): the hits below the
            // sample, 1 − (c1/c′)^Λ
            let ln_c1 = -1e-3f32;
            let ln_c = next_ln_c1(0.5, lambda, ln_c1, 0.0).expect("an upward ray from inside hits at u = 0");
            let below = -(f64::from(lambda) * (f64::from(ln_c1) - f64::from(ln_c))).exp_m1();
            assert!(below >= 0.5 * bucket, "Λ = {lambda}: {below:e} of the hits below the u = 0 hit");
        }
    }
    /// The f32 units in the last place between `a` and the exact `b`, relative to |b|.
    fn ulps(a: f32, b: f64) -> f64 {
        (f64::from(a) - b).abs() / (b.abs() * f64::from(f32::EPSILON))
    }

    /// ln C¹' = ln C¹ − ln(1 − u)/Λ for a ray going down (Algorithm 1 in log-C¹ space),
    /// against the same formula in f64: within 4 f32 ulps (two roundings of the inputs' ln and
    /// one of the quotient), and deeper for larger u.
    #[test]
    fn next_ln_c1_going_down_follows_algorithm_1() {
        let mut worst = 0.0f64;
        for &lambda in &[-1.0f32, -1.3, -4.0, -250.0] {
            for &ln_c1 in &[0.0f32, -1e-6, -0.7, -30.0] {
                let mut previous = f32::INFINITY;
                for k in 1..1000 {
                    let u = k as f32 / 1000.0;
                    let got = next_ln_c1(-0.6, lambda, ln_c1, u).expect("a downward ray always hits");
                    let expected = f64::from(ln_c1) - f64::from(1.0 - u).ln() / f64::from(lambda);
                    worst = worst.max(ulps(got, expected));
                    assert!(got <= previous, "Λ = {lambda}, ln C¹ = {ln_c1}: not deeper at u = {u}");
                    assert!(got <= -MIN_HIT_DEPTH, "a hit lies strictly inside the surface");
                    previous = got;
                }
            }
        }
        assert!(worst <= 4.0, "{worst} ulps");
    }

    /// A ray going up escapes from above the surface always, and from ln C¹ < 0 with the
    /// probability G1(ω, h) = C¹^Λ (supplement §3.1): on a grid of M uniforms the escaping
    /// share is C¹^Λ within the grid's resolution 1/M (plus the cut tails, 2⁻²⁴).
    #[test]
    fn next_ln_c1_going_up_escapes_with_probability_c1_to_the_lambda() {
        const M: u32 = 1 << 16;
        for &lambda in &[0.05f32, 0.5, 3.0] {
            for k in 1..M {
                let u = k as f32 / M as f32;
                assert_eq!(next_ln_c1(0.4, lambda, 0.0, u), None, "from above, Λ = {lambda}, u = {u}");
            }
            for &ln_c1 in &[-0.01f32, -0.5, -3.0] {
                let mut escaped = 0u32;
                for k in 0..M {
                    let u = (k as f32 + 0.5) / M as f32;
                    match next_ln_c1(0.4, lambda, ln_c1, u) {
                        None => escaped += 1,
                        Some(next) => assert!(next > ln_c1 && next <= -MIN_HIT_DEPTH, "{next} from {ln_c1}"),
                    }
                }
                let share = f64::from(escaped) / f64::from(M);
                let expected = (f64::from(lambda) * f64::from(ln_c1)).exp();
                assert!(
                    (share - expected).abs() <= 1.5 / f64::from(M),
                    "Λ = {lambda}, ln C¹ = {ln_c1}: escaped {share}, C¹^Λ = {expected}"
                );
            }
        }
        // straight up (Λ = 0) always escapes, even from the bottom
        assert_eq!(next_ln_c1(1.0, 0.0, -50.0, 0.5), None);
    }

    /// The escapes decided without the logarithm (−u ≤ Λ ln C¹) are exactly those the
    /// logarithm decides: `next_ln_c1` against the plain form, bit for bit, for rays going up
    /// over Λ from 1e-7 to `f32::MAX`, depths from −1e-38 to −100, and uniforms on the crate's
    /// 2⁻²⁴ grid and off it (including its extremes).
    #[test]
    fn next_ln_c1_escapes_without_the_logarithm_as_with_it() {
        let plain = |lambda: f32, ln_c1: f32, u: f32| {
            let ln_1mu = ln_f32(1.0 - cut_tails(u));
            if lambda == 0.0 || ln_1mu <= lambda * ln_c1 {
                return None;
            }
            Some((ln_c1 - ln_1mu / lambda).min(-MIN_HIT_DEPTH))
        };
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let (mut escaped, mut hit) = (0u32, 0u32);
        for k in 0..2_000_000u32 {
            let bits = next();
            let lambda = if k % 97 == 0 {
                f32::MAX
            } else {
                10f32.powf(-7.0 + 10.0 * (bits >> 40) as f32 / 16_777_216.0)
            };
            let ln_c1 =
                -(10f32.powf(-38.0 + 40.0 * ((bits >> 16) & 0xff_ffff) as f32 / 16_777_216.0)).min(100.0);
            let u = match k % 4 {
                0 => (bits & 0xff_ffff) as f32 / 16_777_216.0,
                1 => f32::from_bits(0x3f80_0000 | (bits as u32 & 0x7f_ffff)) - 1.0,
                2 => ((bits & 0xff) as f32) / 16_777_216.0,
                _ => 1.0 - ((bits & 0xff) as f32 + 1.0) / 16_777_216.0,
            };
            let got = next_ln_c1(0.5, lambda, ln_c1, u);
            assert_eq!(
                got.map(f32::to_bits),
                plain(lambda, ln_c1, u).map(f32::to_bits),
                "Λ = {lambda:e}, ln C¹ = {ln_c1:e}, u = {u:e}"
            );
            if got.is_some() { hit += 1 } else { escaped += 1 }
        }
        assert!(escaped > 100_000 && hit > 100_000, "escaped {escaped}, hit {hit}");
        assert_eq!(next_ln_c1(0.5, 0.0, -1.0, 0.3), None);
    }

    /// A horizontal ray (Λ saturated at f32::MAX) hits at its own height, or escapes from
    /// above the surface.
    #[test]
    fn next_ln_c1_of_a_horizontal_ray_stays_at_its_height() {
        for u in [0.0f32, 0.3, 0.999] {
            assert_eq!(next_ln_c1(0.0, f32::MAX, 0.0, u), None);
            let next = next_ln_c1(0.0, f32::MAX, -0.25, u).expect("a horizontal ray inside hits");
            assert_eq!(next, -0.25, "u = {u}");
        }
    }

    /// ln(1 − C¹) from ln C¹ against f64 on the whole range of hit depths, within 4 f32 ulps:
    /// relative accuracy near the top (ln C¹ → 0⁻, where 1 − C¹ → 0) and near the bottom
    /// (ln C¹ → −∞, where ln(1 − C¹) → 0⁻). Before, ln(−expm1(x)) rounded 1 − eˣ to f32 and
    /// lost the small result below x ≈ −1 (150 ulps at x = −5, all of it from x ≈ −17 on).
    #[test]
    fn flip_ln_c1_is_accurate_at_every_depth() {
        let mut x = -MIN_HIT_DEPTH;
        let mut worst = (0.0f64, 0.0f32);
        while x > -80.0 {
            // ln(1 − eˣ) in f64, cancellation-free on both sides of −ln 2
            let x64 = f64::from(x);
            let expected =
                if x64 > -core::f64::consts::LN_2 { (-x64.exp_m1()).ln() } else { (-x64.exp()).ln_1p() };
            let e = ulps(flip_ln_c1(x), expected);
            if e > worst.0 {
                worst = (e, x);
            }
            x *= 1.37;
        }
        assert!(worst.0 <= 4.0, "{} ulps at ln C¹ = {}", worst.0, worst.1);
    }

    /// ln C¹₁ = ln(1 − u)/Λ(−ωi) of the first hit from below, `None` where ωi sees nothing
    /// (Λ(−ωi) = 0 or NaN), and clamped finite where the quotient overflows.
    #[test]
    fn first_ln_c1_from_below_is_the_visible_height_quantile() {
        assert_eq!(first_ln_c1_from_below(0.0, 0.5), None);
        assert_eq!(first_ln_c1_from_below(f32::NAN, 0.5), None);
        for lambda in [1e-3f32, 0.2, 1.0, 40.0] {
            for u in [0.0f32, 0.1, 0.5, 0.9, 1.0] {
                let got = first_ln_c1_from_below(lambda, u).expect("a hit");
                let expected = f64::from(1.0 - cut_tails(u)).ln() / f64::from(lambda);
                assert!(ulps(got, expected) <= 2.0 || got == -MIN_HIT_DEPTH, "Λ = {lambda}, u = {u}: {got}");
            }
        }
        assert_eq!(first_ln_c1_from_below(1e-45, 0.9), Some(f32::MIN), "overflow is clamped");
    }
    /// The scaled depth is the ln C¹ walk in other units: where Λ(−ωi) is representable its
    /// first hit, its steps (up, down, escaping or not) and its masking equal those of
    /// `first_ln_c1_from_below`, `next_ln_c1` and C¹^Λ with s = −ln C¹·Λ(−ωi), to the f32
    /// precision of the latter (1e-5 relative).
    #[test]
    fn scaled_depth_is_the_ln_c1_walk_in_the_first_hits_scale() {
        use crate::slope::Ggx;
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
        let slope = Ggx::isotropic(0.6).expect("valid roughness");
        let up_in = Vec3::new(0.6, 0.0, 0.8); // −ωi of a ray from below
        let lambda_in = slope.lambda64(up_in);
        let steps = [
            (Vec3::new(0.0, 0.6, 0.8), 0.3f32),
            (Vec3::new(0.8, 0.0, 0.6), 0.05),
            (Vec3::new(0.6, 0.0, -0.8), 0.7),
        ];
        let mut escaped = 0;
        for u0 in [0.1f32, 0.5, 0.9] {
            let depth = ScaledDepth::first(slope.ln_lambda(up_in), u0).expect("ωi sees the surface");
            let ln_c1 = first_ln_c1_from_below(lambda_in as f32, u0).expect("ωi sees the surface");
            assert!(rel(depth.s, -f64::from(ln_c1) * lambda_in) <= 1e-5, "u = {u0}");
            let wo = Vec3::new(-0.28, 0.0, 0.96);
            let masking = (f64::from(slope.lambda_unchecked(wo)) * f64::from(ln_c1)).exp();
            assert!(rel(depth.escape_probability(slope.ln_lambda(wo)), masking) <= 1e-5, "u = {u0}");
            for (w, u) in steps {
                match (depth.next(&slope, w, u), next_ln_c1(w.z, slope.lambda_unchecked(w), ln_c1, u)) {
                    (None, None) => escaped += 1,
                    (Some(d), Some(c)) => {
                        assert!(rel(d.s, -f64::from(c) * lambda_in) <= 1e-5, "{w}, u = {u}")
                    }
                    (d, c) => panic!("{w}, u = {u}: scaled {d:?}, ln C¹ {c:?}"),
                }
            }
        }
        assert!(escaped > 0, "an escape is among the cases");
        assert_eq!(ScaledDepth::first(f64::NEG_INFINITY, 0.5), None, "ωi at the nadir sees nothing");
    }
}
