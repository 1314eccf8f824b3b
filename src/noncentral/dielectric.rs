//! Dielectric facets on a sheared microsurface: Walter's BSDF with the sheared D and the
//! separable noncentral masking (see [`NoncentralMaterial`]).

use super::single_scattering::{NoncentralMaterial, reflection_half, saturate};
use super::slope::Noncentral;
use crate::material::{Dielectric, Side, reflect};
use crate::rng::uniform;
use crate::single_scattering::SingleSample;
use crate::slope::MicrosurfaceSlope;
use crate::vector::renormalize;
use glam::{Vec2, Vec3};
use rand::Rng;

/// A configuration in the frame of ωi's side: the interface as seen from there and the two
/// directions flipped through the origin if ωi is inside (Heitz et al. 2016, supplement
/// §3.4), `None` for ωi or ωo on the horizon.
#[inline(always)]
fn seen_from_wi(glass: &Dielectric, wi: Vec3, wo: Vec3) -> Option<(Dielectric, Vec3, Vec3)> {
    if wi.z == 0.0 || wo.z == 0.0 || wi.z.is_nan() || wo.z.is_nan() {
        return None;
    }
    let side = Side::above_or_inside(wi.z);
    Some((glass.seen_from(side), side.frame(wi), side.frame(wo)))
}

impl NoncentralMaterial for Dielectric {
    #[inline]
    fn eval_single<S: MicrosurfaceSlope>(
        &self,
        surface: &Noncentral<S>,
        wi: Vec3,
        wo: Vec3,
        _rng: &mut impl Rng,
    ) -> Vec3 {
        let Some((glass, wi, wo)) = seen_from_wi(self, wi, wo) else { return Vec3::ZERO };
        let g1_i = surface.g1_unchecked(wi);
        let value = if wo.z > 0.0 {
            let Some((wh, cos_ih)) = reflection_half(wi, wo) else { return Vec3::ZERO };
            let (fresnel, _) = glass.reflectance_scaled(cos_ih, 1.0);
            fresnel * surface.d_unchecked(wh) * g1_i * surface.g1_unchecked(wo) / (4.0 * f64::from(wi.z))
        } else {
            let Some(r) = glass.refraction(wi, wo) else { return Vec3::ZERO };
            let eta = f64::from(glass.eta());
            r.cos_ih * (-r.cos_oh) * eta * eta * r.transmittance * surface.d_unchecked(r.wh) * g1_i
                * surface.g1_unchecked(-wo)
                / (f64::from(wi.z) * r.denom_sq)
        };
        Vec3::splat(saturate(value))
    }

    #[inline]
    fn pdf_single<S: MicrosurfaceSlope>(&self, surface: &Noncentral<S>, wi: Vec3, wo: Vec3) -> f32 {
        let Some((glass, wi, wo)) = seen_from_wi(self, wi, wo) else { return 0.0 };
        let density = if wo.z > 0.0 {
            let Some((wh, cos_ih)) = reflection_half(wi, wo) else { return 0.0 };
            let cos_oh = wo.as_dvec3().dot(wh);
            if cos_oh <= 0.0 {
                return 0.0;
            }
            let (fresnel, _) = glass.reflectance_scaled(cos_ih, 1.0);
            fresnel * surface.d_wi_unchecked(wi, wh) / (4.0 * cos_oh)
        } else {
            let Some(r) = glass.refraction(wi, wo) else { return 0.0 };
            let eta = f64::from(glass.eta());
            r.transmittance * surface.d_wi_unchecked(wi, r.wh) * eta * eta * (-r.cos_oh) / r.denom_sq
        };
        density as f32
    }

    #[inline]
    fn sample_single<S: MicrosurfaceSlope>(
        &self,
        surface: &Noncentral<S>,
        wi: Vec3,
        u: Vec2,
        rng: &mut impl Rng,
    ) -> Option<SingleSample> {
        if wi.z == 0.0 {
            return None;
        }
        let side = Side::above_or_inside(wi.z);
        let (glass, wi_local) = (self.seen_from(side), side.frame(wi));
        let wm = surface.sample_d_wi_unchecked(wi_local, u.x, u.y);
        let c = f64::from(wi_local.dot(wm).abs().min(1.0));
        let (fresnel, s) = glass.reflectance_scaled(c, 1.0);
        let (wo_local, g1_o) = if uniform(rng) < fresnel as f32 {
            let wo = renormalize(reflect(wi_local, wm), wm);
            // a reflection below the base plane is masked by it
            if wo.z <= 0.0 {
                return None;
            }
            (wo, surface.g1_unchecked(wo))
        } else {
            let wo = glass.refract(wi_local, wm, c, s);
            // a refraction that would leave above the base plane is masked by it
            if wo.z >= 0.0 || wo.z.is_nan() {
                return None;
            }
            (wo, surface.g1_unchecked(-wo))
        };
        let wo = side.frame(wo_local);
        let pdf = self.pdf_single(surface, wi, wo);
        Some(SingleSample { wo, weight: Vec3::splat(saturate(g1_o)), pdf })
    }
}
