//! Schlick's approximation of the Fresnel reflectance.

use crate::contract::is_cosine;
use glam::Vec3;

/// Schlick's approximation F = F0 + (1 − F0)(1 − |cos θ|)⁵ per channel (Schlick 1994), with
/// F0 the reflectance at normal incidence (`ClassicBrdf`'s specular colour K_s). Its error against the
/// exact dielectric term is below 0.01 for η ∈ [1.3, 1.7] outside total internal reflection.
///
/// Invalid input ([policy](crate#invalid-input)): a `cos_theta` that is NaN or beyond
/// ±(1 + [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE)), or an `f0` with a component
/// that is NaN or outside [0, 1], gives `Vec3::NAN` (a debug assertion in debug builds).
#[must_use]
#[inline]
pub fn fresnel_schlick(cos_theta: f32, f0: Vec3) -> Vec3 {
    require!(
        is_cosine(cos_theta) && f0.cmpge(Vec3::ZERO).all() && f0.cmple(Vec3::ONE).all(),
        Vec3::NAN;
        cos_theta,
        f0
    );
    let m = (1.0 - cos_theta.abs().min(1.0)).max(0.0);
    let m2 = m * m;
    f0 + (Vec3::ONE - f0) * (m2 * m2 * m)
}
