//! Material-independent geometry of the microsurface: masking and the height of the next
//! intersection (Heitz et al. 2016, supplement §3.1).

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
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        if w.z <= 0.0 {
            return 0.0;
        }
        1.0 / (1.0 + self.slope.lambda(w))
    }

    /// The masking function at height h, G1(ω, h) = C¹(h)^Λ(ω) for ω.z > 0 and 0 for ω.z ≤ 0
    /// (supplement §3.1): the probability that a ray leaving height h in direction ω escapes.
    /// `h` may be +∞ (above the surface: 1).
    #[inline]
    pub fn g1_at(&self, w: Vec3, h: f32) -> f32 {
        if w.z <= 0.0 {
            return 0.0;
        }
        escape_probability(self.height.c1(h), self.slope.lambda(w))
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
    #[inline]
    pub fn sample_height(&self, w: Vec3, h0: f32, u: f32) -> HeightSample {
        if w.z == 0.0 {
            return if h0 == f32::INFINITY { HeightSample::Escape } else { HeightSample::Hit(h0) };
        }
        match next_c1(w.z, self.slope.lambda(w), self.height.c1(h0), u) {
            Some(c) => HeightSample::Hit(self.height.inv_c1(c)),
            None => HeightSample::Escape,
        }
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
