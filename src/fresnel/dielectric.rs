//! Fresnel reflectance of a dielectric interface.

use crate::contract::{is_cosine, is_index};
use crate::lanes::Lanes;

/// Unpolarized Fresnel reflectance of a smooth dielectric interface, with total internal
/// reflection.
///
/// `cos_theta_i` = |ωi·ωm| ∈ [0, 1] is the cosine on the incident side, `eta` = ηt/ηi > 0 the
/// relative index across the interface. With sin²θt = (1 − cos²θi)/η²: F = 1 when
/// sin²θt ≥ 1 (total internal reflection, possible for η < 1), otherwise
/// F = ½(Rs² + Rp²), Rs = (cos θi − η cos θt)/(cos θi + η cos θt),
/// Rp = (η cos θi − cos θt)/(η cos θi + cos θt). F = 0 at η = 1; F = 1 at grazing incidence.
///
/// Invalid input ([policy](crate#invalid-input)): a `cos_theta_i` that is NaN or beyond
/// ±(1 + [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE)), or an `eta` that is not finite
/// and > 0, gives NaN (a debug assertion in debug builds).
#[must_use]
#[inline]
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    require!(is_cosine(cos_theta_i) && is_index(eta), f32::NAN; cos_theta_i, eta);
    dielectric_reflectance(cos_theta_i, eta)
}

/// [`fresnel_dielectric`] without the argument check, for the crate's own cosines and indices.
#[must_use]
#[inline(always)]
pub(crate) fn dielectric_reflectance(cos_theta_i: f32, eta: f32) -> f32 {
    let c = f64::from(cos_theta_i.abs().min(1.0));
    let eta = f64::from(eta);
    // η² cos²θt = c² + (η − 1)(η + 1): no rounding of (1 − c²)/η² to 1 near grazing
    let eta2_cos2_t = c * c + (eta - 1.0) * (eta + 1.0);
    if eta2_cos2_t <= 0.0 {
        return 1.0;
    }
    fresnel_dielectric_cosines(c, eta2_cos2_t.sqrt() / eta, eta) as f32
}

/// The unpolarized dielectric reflectance from both cosines, cos θi = `c` and cos θt = `t`
/// (both ≥ 0), with relative index η = ηt/ηi, in double precision:
/// Rs = (c − η t)/(c + η t), Rp = (η c − t)/(η c + t), F = (Rs² + Rp²)/2. Callers that know
/// cos θt from the geometry (a refraction through a known facet) pass it directly instead of
/// recomputing it from a rounded cos θi near the critical angle.
#[must_use]
#[inline]
pub(crate) fn fresnel_dielectric_cosines(c: f64, t: f64, eta: f64) -> f64 {
    fresnel_dielectric_cosines_of(c, t, eta)
}

/// [`fresnel_dielectric_cosines`] for every lane type.
#[must_use]
#[inline(always)]
pub(crate) fn fresnel_dielectric_cosines_of<L: Lanes>(c: L, t: L, eta: L) -> L {
    let (num_s, den_s) = (c - eta * t, c + eta * t);
    let (num_p, den_p) = (eta * c - t, eta * c + t);
    let zero = L::lit(0.0);
    // (one division for both ratios)
    let inv = L::lit(1.0) / (den_s * den_p);
    let (rs, rp) = (num_s * den_p * inv, num_p * den_s * inv);
    L::select(den_s.le(zero) | den_p.le(zero), L::lit(1.0), L::lit(0.5) * (rs * rs + rp * rp))
}

/// The unpolarized dielectric transmittance 1 − F of [`fresnel_dielectric_cosines_of`] for
/// every lane type, without its cancellation where F is close to 1 (grazing incidence):
/// 1 − Rs² = 4ηct/(c + ηt)² and 1 − Rp² = 4ηct/(ηc + t)², so
/// 1 − F = 2ηct (1/(c + ηt)² + 1/(ηc + t)²), formed as 2ηct ((c + ηt)² + (ηc + t)²) q² with
/// q = 1/((c + ηt)(ηc + t)): a few ulps relative to the transmittance itself
/// (1 − F formed by subtraction is a few ulps of 1). Homogeneous of degree 0 in (c, t), so
/// cosines given with a common positive scale serve as well. 0 where a denominator is not
/// positive (F = 1 there).
#[must_use]
#[inline(always)]
pub(crate) fn transmittance_dielectric_cosines_of<L: Lanes>(c: L, t: L, eta: L) -> L {
    let (den_s, den_p) = (c + eta * t, eta * c + t);
    let zero = L::lit(0.0);
    let two_eta_ct = L::lit(2.0) * eta * c * t;
    // 2ηct (den_s² + den_p²)/(den_s den_p)²: one division, its reciprocal squared as two
    // factors (no fourth power of the denominators, which would overflow f32 from η ≈ 6e9)
    let q = L::lit(1.0) / (den_s * den_p);
    let value = (two_eta_ct * q) * ((den_s * den_s + den_p * den_p) * q);
    L::select(den_s.le(zero) | den_p.le(zero), zero, value)
}
