//! Fresnel reflectance of a conductor (complex index of refraction), per RGB channel.

use crate::contract::is_cosine;
use crate::error::Error;
use crate::lanes::Lanes;
use glam::{Vec3, Vec3A};

/// A complex index of refraction η + i k per RGB channel, relative to the outside medium.
#[derive(Clone, Copy, PartialEq)]
pub struct ComplexIor {
    eta: Vec3,
    k: Vec3,
    /// η² − k² − 1 per channel: t = η² − k² − sin²θ of the Fresnel term is `t0` + cos²θ.
    t0: Vec3A,
    /// 4η²k² per channel.
    four_eta_k_sq: Vec3A,
}

impl core::fmt::Debug for ComplexIor {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("ComplexIor").field("eta", &self.eta).field("k", &self.k).finish()
    }
}

impl ComplexIor {
    /// The index η + i k with the constants of its Fresnel term (the callers check the domain).
    pub(super) const fn from_parts(eta: Vec3, k: Vec3) -> Self {
        const fn sq(e: f32, k: f32) -> f32 {
            e * e - k * k - 1.0
        }
        const fn m(e: f32, k: f32) -> f32 {
            4.0 * (e * e) * (k * k)
        }
        Self {
            eta,
            k,
            t0: Vec3A::new(sq(eta.x, k.x), sq(eta.y, k.y), sq(eta.z, k.z)),
            four_eta_k_sq: Vec3A::new(m(eta.x, k.x), m(eta.y, k.y), m(eta.z, k.z)),
        }
    }

    /// The largest accepted η and k: beyond any material (the Fresnel term is 1 within 4e-6
    /// there), and far enough below f32's range that the squares of the Fresnel term's
    /// constants (η² k² ~ 10²⁴) stay finite.
    pub const MAX: f32 = 1e6;

    /// A complex IOR with real part `eta` ∈ (0, [`Self::MAX`]] and extinction
    /// `k` ∈ [0, [`Self::MAX`]] per channel.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if a component of `eta` or `k` is outside its range (NaN
    /// and infinities included).
    #[inline]
    pub fn new(eta: Vec3, k: Vec3) -> Result<Self, Error> {
        // the three channels of each condition in one SIMD comparison (NaN fails every one); the
        // error names the first bad channel
        let (e, kk, max) = (Vec3A::from(eta), Vec3A::from(k), Vec3A::splat(Self::MAX));
        let valid = e.cmpgt(Vec3A::ZERO) & e.cmple(max) & kk.cmpge(Vec3A::ZERO) & kk.cmple(max);
        if !valid.all() {
            return Err(Self::invalid(eta, k));
        }
        Ok(Self::from_parts(eta, k))
    }

    /// The error of an index [`Self::new`] rejects: its first channel out of range.
    #[cold]
    fn invalid(eta: Vec3, k: Vec3) -> Error {
        let eta_error = eta
            .to_array()
            .into_iter()
            .find(|&e| !(e > 0.0 && e <= Self::MAX))
            .map(|value| Error::InvalidParameter { name: "eta", value, expected: "in (0, 1e6]" });
        let k_error = || {
            k.to_array()
                .into_iter()
                .find(|&v| !(0.0..=Self::MAX).contains(&v))
                .map(|value| Error::InvalidParameter { name: "k", value, expected: "in [0, 1e6]" })
        };
        // one of the two exists (the conditions are those of `new`); a NaN η otherwise
        eta_error.or_else(k_error).unwrap_or(Error::InvalidParameter {
            name: "eta",
            value: f32::NAN,
            expected: "in (0, 1e6]",
        })
    }

    /// F0 = F(cos θ = 1) = ((η − 1)² + k²)/((η + 1)² + k²) per channel (in SIMD lanes): the
    /// Fresnel term at normal incidence in closed form (one division; the general expression of
    /// [`fresnel_conductor`] reduces to it at cos θ = 1).
    #[must_use]
    #[inline(always)]
    pub(crate) fn normal_reflectance(&self) -> Vec3A {
        let (eta, k) = (Vec3A::from(self.eta), Vec3A::from(self.k));
        let k2 = k * k;
        let (m, p) = (eta - Vec3A::ONE, eta + Vec3A::ONE);
        (m * m + k2) / (p * p + k2)
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
/// F = (Rs + Rp)/2 (Born and Wolf, Principles of Optics, §14.2), evaluated as Rs R/(R + S)
/// with R and S the numerator's and denominator's terms of Rp/Rs (one division), from
/// η² − k² − 1 and 4η²k² precomputed with the index. F ∈ [0, 1]; 1 at grazing. In f32 the
/// absolute error is below 2e-6 against a complex-arithmetic f64 evaluation (measured
/// 8.5e-7 over the presets and 40 random indices, `tests/fresnel.rs`).
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
    // the three channels in one SIMD register (Vec3A): one division and one square root
    // instruction per step for the three
    Vec3::from(reflectance_of(Vec3A::splat(cos_theta), ior.t0, ior.four_eta_k_sq))
}

/// The conductor's reflectance of [`conductor_reflectance`] for every lane type (the three
/// channels of one cosine, or one channel of several), for cos θ = `c` ∈ (0, 1] (the caller
/// handles grazing, where it is 1) and the channel's constants `t0` = η² − k² − 1 and
/// `four_eta_k_sq` = 4η²k².
#[must_use]
#[inline(always)]
pub(crate) fn reflectance_of<L: Lanes>(c: L, t0: L, four_eta_k_sq: L) -> L {
    let (zero, one) = (L::lit(0.0), L::lit(1.0));
    let c2 = c * c;
    let s2 = one - c2;
    // t = η² − k² − sin²θ and a² + b² = √(t² + 4η²k²), from the index's constants
    let t = t0 + c2;
    let a2b2 = (t * t + four_eta_k_sq).sqrt();
    let a = (L::lit(0.5) * (a2b2 + t)).max(zero).sqrt();
    // Rs = (P − Q)/(P + Q) and Rp = Rs (R − S)/(R + S) with P = a² + b² + cos²θ, Q = 2a cos θ,
    // R = cos²θ (a² + b²) + s⁴, S = Q s²: (Rs + Rp)/2 = Rs R/(R + S), one division
    let p = a2b2 + c2;
    let q = L::lit(2.0) * a * c;
    let r = c2 * a2b2 + s2 * s2;
    let f = (p - q) * r / ((p + q) * (r + q * s2));
    f.clamp(zero, one)
}

impl ComplexIor {
    /// The per-channel constants of the Fresnel term (η² − k² − 1, 4η²k²), for the batch kernels.
    #[inline(always)]
    pub(crate) fn constants(&self) -> (Vec3A, Vec3A) {
        (self.t0, self.four_eta_k_sq)
    }
}
