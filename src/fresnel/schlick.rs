//! Schlick's approximation of the Fresnel reflectance.

use glam::Vec3;

/// Schlick's approximation F = F0 + (1 − F0)(1 − |cos θ|)⁵ per channel (Schlick 1994), with
/// F0 the reflectance at normal incidence (`ClassicBrdf`'s specular colour K_s). Its error against the
/// exact dielectric term is below 0.01 for η ∈ [1.3, 1.7] outside total internal reflection.
#[inline]
pub fn fresnel_schlick(cos_theta: f32, f0: Vec3) -> Vec3 {
    let m = (1.0 - cos_theta.abs().min(1.0)).max(0.0);
    let m2 = m * m;
    f0 + (Vec3::ONE - f0) * (m2 * m2 * m)
}
