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

/// The event a pair of directions describes.
#[derive(Clone, Copy)]
enum Scattering {
    /// Both directions on one side: a reflection, evaluated in the frame of that side (the
    /// directions flipped through the origin inside, η ↦ 1/η; Heitz et al. 2016, supplement
    /// §3.4).
    Reflection(Side),
    /// One direction on each side: a refraction, evaluated in the outside frame with the
    /// interface's η whichever way the light travels, so that the two directions of travel
    /// share every rounding (reciprocity to f64 precision).
    Transmission { outside: Vec3, inside: Vec3 },
}

/// The event of (ωi, ωo), `None` for a direction on the horizon (or NaN).
#[inline(always)]
fn scattering(wi: Vec3, wo: Vec3) -> Option<Scattering> {
    if wi.z == 0.0 || wo.z == 0.0 || wi.z.is_nan() || wo.z.is_nan() {
        return None;
    }
    let (side_i, side_o) = (Side::above_or_inside(wi.z), Side::above_or_inside(wo.z));
    Some(if side_i == side_o {
        Scattering::Reflection(side_i)
    } else if side_i.is_outside() {
        Scattering::Transmission { outside: wi, inside: wo }
    } else {
        Scattering::Transmission { outside: wo, inside: wi }
    })
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
        let value = match scattering(wi, wo) {
            None => return Vec3::ZERO,
            Some(Scattering::Reflection(side)) => {
                let (glass, wi, wo) = (self.seen_from(side), side.frame(wi), side.frame(wo));
                let Some((wh, cos_ih)) = reflection_half(wi, wo) else { return Vec3::ZERO };
                let (fresnel, _) = glass.reflectance_scaled(cos_ih, 1.0);
                fresnel * surface.d_unchecked(wh) * surface.g1_unchecked(wi) * surface.g1_unchecked(wo)
                    / (4.0 * f64::from(wi.z))
            }
            Some(Scattering::Transmission { outside, inside }) => {
                let Some(r) = self.refraction(outside, inside) else { return Vec3::ZERO };
                // the symmetric part ⟨a, ωh⟩ |⟨b, ωh⟩| (1 − F) D G1(a) G1(−b)/(⟨a, ωh⟩ + η⟨b, ωh⟩)²
                let common = r.cos_ih
                    * (-r.cos_oh)
                    * r.transmittance
                    * surface.d_unchecked(r.wh)
                    * surface.g1_unchecked(outside)
                    * surface.g1_unchecked(-inside)
                    / r.denom_sq;
                if wi.z > 0.0 {
                    let eta = f64::from(self.eta());
                    common * eta * eta / f64::from(wi.z)
                } else {
                    common / f64::from(-wi.z)
                }
            }
        };
        Vec3::splat(saturate(value))
    }

    #[inline]
    fn pdf_single<S: MicrosurfaceSlope>(&self, surface: &Noncentral<S>, wi: Vec3, wo: Vec3) -> f32 {
        let density = match scattering(wi, wo) {
            None => return 0.0,
            Some(Scattering::Reflection(side)) => {
                let (glass, wi, wo) = (self.seen_from(side), side.frame(wi), side.frame(wo));
                let Some((wh, cos_ih)) = reflection_half(wi, wo) else { return 0.0 };
                let cos_oh = wo.as_dvec3().dot(wh);
                if cos_oh <= 0.0 {
                    return 0.0;
                }
                let (fresnel, _) = glass.reflectance_scaled(cos_ih, 1.0);
                fresnel * surface.d_wi_unchecked(wi, wh) / (4.0 * cos_oh)
            }
            Some(Scattering::Transmission { outside, inside }) => {
                let Some(r) = self.refraction(outside, inside) else { return 0.0 };
                // the Jacobian |⟨ωo, ωh⟩|/(⟨ωi, ωh⟩ + η_o/η_i ⟨ωo, ωh⟩)² of ωi's side, written
                // with the outside's η (the same for both directions of travel)
                if wi.z > 0.0 {
                    let eta = f64::from(self.eta());
                    r.transmittance * surface.d_wi_unchecked(wi, r.wh) * eta * eta * (-r.cos_oh) / r.denom_sq
                } else {
                    r.transmittance * surface.d_wi_unchecked(-wi, r.wh) * r.cos_ih / r.denom_sq
                }
            }
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
            let wo = glass.refract(wi_local, wm, c, s, 1.0);
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
