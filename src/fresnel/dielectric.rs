//! Fresnel reflectance of a dielectric interface.

/// Unpolarized Fresnel reflectance of a smooth dielectric interface, with total internal
/// reflection.
///
/// `cos_theta_i` = |ωi·ωm| ∈ [0, 1] is the cosine on the incident side, `eta` = ηt/ηi > 0 the
/// relative index across the interface. With sin²θt = (1 − cos²θi)/η²: F = 1 when
/// sin²θt ≥ 1 (total internal reflection, possible for η < 1), otherwise
/// F = ½(Rs² + Rp²), Rs = (cos θi − η cos θt)/(cos θi + η cos θt),
/// Rp = (η cos θi − cos θt)/(η cos θi + cos θt). F = 0 at η = 1; F = 1 at grazing incidence.
#[inline]
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    let c = cos_theta_i.abs().min(1.0);
    let sin2_t = (1.0 - c * c) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (c - eta * cos_t) / (c + eta * cos_t);
    let rp = (eta * c - cos_t) / (eta * c + cos_t);
    0.5 * (rs * rs + rp * rp)
}
