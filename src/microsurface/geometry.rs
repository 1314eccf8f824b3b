//! Material-independent geometry of the microsurface: masking and the height of the next
//! intersection (Heitz et al. 2016, supplement §3.1).

use crate::contract::{is_direction, is_uniform};
use crate::height::MicrosurfaceHeight;
use crate::rng::cut_tails;
use crate::slope::MicrosurfaceSlope;
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
    /// [`Microsurface::eval_from_below`]: crate::Microsurface::eval_from_below
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
const MIN_HIT_DEPTH: f32 = f32::MIN_POSITIVE;

/// Algorithm 1 of the supplement in log-C¹ space, the state of the random walks: the
/// ln C¹ of the next intersection's height, or `None` if the ray escapes. `ln_c1` = 0 is a ray
/// from above the surface; `lambda` is Λ(ω) for the ray direction with z-component `z`.
///
/// u is cut as in [`next_c1`]. The ray escapes iff it goes up and ln(1 − u) ≤ Λ ln C¹; otherwise
/// ln C¹' = ln C¹ − ln(1 − u)/Λ (above the horizon Λ ≥ 0 and the height increases, below it
/// Λ ≤ −1 and it decreases). One logarithm per intersection, and the masking of the next
/// event is exp(Λ ln C¹'): heights themselves are never needed (supplement §1.1). A horizontal
/// ray (Λ saturated at `f32::MAX`) hits at its own height, or escapes from above the surface.
#[inline(always)]
pub(crate) fn next_ln_c1(z: f32, lambda: f32, ln_c1: f32, u: f32) -> Option<f32> {
    // tails cut and 1 − u: see `next_c1`
    let ln_1mu = (1.0 - cut_tails(u)).ln();
    if z >= 0.0 && (lambda == 0.0 || ln_1mu <= lambda * ln_c1) {
        return None;
    }
    Some((ln_c1 - ln_1mu / lambda).min(-MIN_HIT_DEPTH))
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
/// “Multiple scattering for views below the macrosurface”).
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

/// ln(1 − C¹) from ln C¹: the same point seen from the other side of the interface, in the
/// vertically flipped frame (h ↦ −h; the height distributions are symmetric). Cancellation-free
/// through exp_m1.
#[inline(always)]
pub(crate) fn flip_ln_c1(ln_c1: f32) -> f32 {
    (-ln_c1.exp_m1()).ln()
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
}
