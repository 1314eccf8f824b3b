//! Conductor facets on a sheared microsurface.

use super::single_scattering::{NoncentralMaterial, reflection_half, saturate};
use super::slope::Noncentral;
use crate::material::Conductor;
use crate::single_scattering::SingleSample;
use crate::slope::MicrosurfaceSlope;
use crate::vector::normalize_fast;
use glam::{Vec2, Vec3};
use rand::Rng;

impl NoncentralMaterial for Conductor {
    #[inline]
    fn eval_single<S: MicrosurfaceSlope>(
        &self,
        surface: &Noncentral<S>,
        wi: Vec3,
        wo: Vec3,
        _rng: &mut impl Rng,
    ) -> Vec3 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Vec3::ZERO;
        }
        let Some((wh, cos_ih)) = reflection_half(wi, wo) else { return Vec3::ZERO };
        let value = surface.d_unchecked(wh) * surface.g1_unchecked(wi) * surface.g1_unchecked(wo)
            / (4.0 * f64::from(wi.z));
        self.fresnel(cos_ih as f32) * saturate(value)
    }

    #[inline]
    fn pdf_single<S: MicrosurfaceSlope>(&self, surface: &Noncentral<S>, wi: Vec3, wo: Vec3) -> f32 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        reflection_density(surface, wi, wo)
    }

    #[inline]
    fn sample_single<S: MicrosurfaceSlope>(
        &self,
        surface: &Noncentral<S>,
        wi: Vec3,
        u: Vec2,
        _rng: &mut impl Rng,
    ) -> Option<SingleSample> {
        if wi.z <= 0.0 {
            return None;
        }
        let wh = surface.sample_d_wi_unchecked(wi, u.x, u.y);
        let cos_ih = wi.dot(wh);
        let wo = normalize_fast(2.0 * cos_ih * wh - wi, Vec3::Z);
        if wo.z <= 0.0 {
            return None;
        }
        let weight = self.fresnel(cos_ih.max(0.0)) * saturate(surface.g1_unchecked(wo));
        Some(SingleSample { wo, weight, pdf: reflection_density(surface, wi, wo) })
    }
}

/// The density D_ωi(ωh)/(4⟨ωo, ωh⟩) of a reflection about the visible normal ωh, for ωi and ωo
/// above the base plane (0 where ωi does not see ωh).
#[inline(always)]
pub(crate) fn reflection_density<S: MicrosurfaceSlope>(surface: &Noncentral<S>, wi: Vec3, wo: Vec3) -> f32 {
    let Some((wh, _)) = reflection_half(wi, wo) else { return 0.0 };
    let cos_oh = wo.as_dvec3().dot(wh);
    if cos_oh <= 0.0 {
        return 0.0;
    }
    (surface.d_wi_unchecked(wi, wh) / (4.0 * cos_oh)) as f32
}
