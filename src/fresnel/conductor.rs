//! Fresnel reflectance of a conductor (complex index of refraction), per RGB channel.

use crate::contract::is_cosine;
use crate::error::Error;
use glam::{Vec3, Vec3A};

/// A complex index of refraction η + i k per RGB channel, relative to the outside medium.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ComplexIor {
    pub(super) eta: Vec3,
    pub(super) k: Vec3,
}

impl ComplexIor {
    /// A complex IOR with real part `eta` > 0 and extinction `k` ≥ 0 per channel.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if a component of `eta` is not finite and > 0, or a
    /// component of `k` is not finite and ≥ 0.
    pub fn new(eta: Vec3, k: Vec3) -> Result<Self, Error> {
        for e in eta.to_array() {
            Error::check_positive("eta", e)?;
        }
        for e in k.to_array() {
            Error::check_non_negative("k", e)?;
        }
        Ok(Self { eta, k })
    }

    /// Real part η.
    #[must_use]
    #[inline]
    pub fn eta(&self) -> Vec3 {
        self.eta
    }

    /// Extinction coefficient k.
    #[must_use]
    #[inline]
    pub fn k(&self) -> Vec3 {
        self.k
    }
}

/// Unpolarized Fresnel reflectance of a smooth conductor, exact for a complex IOR, per channel.
///
/// `cos_theta_i` = |ωi·ωm| ∈ [0, 1]. With s² = sin²θi, t = η² − k² − s²,
/// a² + b² = √(t² + 4η²k²), a = √((a² + b² + t)/2):
/// Rs = (a² + b² − 2a cos θ + cos²θ)/(a² + b² + 2a cos θ + cos²θ),
/// Rp = Rs (cos²θ (a² + b²) − 2a cos θ s² + s⁴)/(cos²θ (a² + b²) + 2a cos θ s² + s⁴),
/// F = (Rs + Rp)/2 (Born and Wolf, Principles of Optics, §14.2). F ∈ [0, 1]; 1 at grazing.
///
/// Invalid input ([policy](crate#invalid-input)): a `cos_theta_i` that is NaN or beyond
/// ±(1 + [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE)) gives `Vec3::NAN` (a debug
/// assertion in debug builds).
#[must_use]
#[inline]
pub fn fresnel_conductor(cos_theta_i: f32, ior: &ComplexIor) -> Vec3 {
    require!(is_cosine(cos_theta_i), Vec3::NAN; cos_theta_i);
    conductor_reflectance(cos_theta_i, ior)
}

/// [`fresnel_conductor`] without the argument check, for cosines the crate formed itself.
#[must_use]
#[inline(always)]
pub(crate) fn conductor_reflectance(cos_theta_i: f32, ior: &ComplexIor) -> Vec3 {
    let cos_theta = cos_theta_i.abs().min(1.0);
    if cos_theta == 0.0 {
        // grazing: every interface reflects fully (and the formula would be 0/0 at η = 1, k = 0)
        return Vec3::ONE;
    }
    // the three channels in one SIMD register (Vec3A): the same IEEE operations lane by lane as
    // the scalar Vec3 form (whose powf(0.5) the compiler emitted as a square root), so the same
    // bits, with one division and one square root instruction per step instead of three
    let c = Vec3A::splat(cos_theta);
    let c2 = c * c;
    let s2 = Vec3A::ONE - c2;
    let (eta, k) = (Vec3A::from(ior.eta), Vec3A::from(ior.k));
    let t = eta * eta - k * k - s2;
    let a2b2 = (t * t + 4.0 * eta * eta * k * k).sqrt();
    let a = (0.5 * (a2b2 + t)).max(Vec3A::ZERO).sqrt();
    let rs = (a2b2 - 2.0 * a * c + c2) / (a2b2 + 2.0 * a * c + c2);
    let rp = rs * (c2 * a2b2 - 2.0 * a * c * s2 + s2 * s2) / (c2 * a2b2 + 2.0 * a * c * s2 + s2 * s2);
    Vec3::from((0.5 * (rs + rp)).clamp(Vec3A::ZERO, Vec3A::ONE))
}
