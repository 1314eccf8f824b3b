//! Material-independent geometry of the microsurface: masking and the height of the next
//! intersection (Heitz et al. 2016, supplement §3.1).

use crate::contract::{is_direction, is_uniform};
use crate::height::MicrosurfaceHeight;
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
    /// C⁻¹(C¹(h0) / (1 − u)^{1/Λ(ω)}). `h0` may be +∞ (a ray arriving from above the surface).
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
/// Computed in log space: the ray escapes iff ln(1 − u) ≤ Λ ln c1, and otherwise
/// c1' = exp(ln c1 − ln(1 − u)/Λ) (in this form c1 = 0 gives 0, not 0·∞), which lies in
/// [0, c1] below the horizon and in [c1, 1) above it.
#[inline(always)]
pub(crate) fn next_c1(z: f32, lambda: f32, c1: f32, u: f32) -> Option<f32> {
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
/// The ray escapes iff it goes up and ln(1 − u) ≤ Λ ln C¹; otherwise
/// ln C¹' = ln C¹ − ln(1 − u)/Λ (above the horizon Λ ≥ 0 and the height increases, below it
/// Λ ≤ −1 and it decreases). One logarithm per intersection, and the masking of the next
/// event is exp(Λ ln C¹'): heights themselves are never needed (supplement §1.1). A horizontal
/// ray (Λ saturated at `f32::MAX`) hits at its own height, or escapes from above the surface.
#[inline(always)]
pub(crate) fn next_ln_c1(z: f32, lambda: f32, ln_c1: f32, u: f32) -> Option<f32> {
    // 1 − u: see `next_c1`
    let ln_1mu = (1.0 - u).ln();
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
