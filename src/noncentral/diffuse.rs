//! Diffuse facets on a sheared microsurface: the stochastic single scattering of the central
//! diffuse material with the separable noncentral masking (see [`NoncentralMaterial`]).

use super::single_scattering::{NoncentralMaterial, saturate};
use super::slope::Noncentral;
use crate::material::Diffuse;
use crate::rng::uniform;
use crate::single_scattering::SingleSample;
use crate::slope::MicrosurfaceSlope;
use core::f32::consts::{FRAC_1_PI, PI};
use glam::{Vec2, Vec3};
use rand::Rng;

impl NoncentralMaterial for Diffuse {
    const LAMBERTIAN: bool = true;

    /// (a/π) ⟨ωo, ωm⟩⁺ G1(ωo) with one ωm ~ D_ωi: unbiased for the model's f·cos θo.
    #[inline]
    fn eval_single<S: MicrosurfaceSlope>(
        &self,
        surface: &Noncentral<S>,
        wi: Vec3,
        wo: Vec3,
        rng: &mut impl Rng,
    ) -> Vec3 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Vec3::ZERO;
        }
        let wm = surface.sample_d_wi_unchecked(wi, uniform(rng), uniform(rng));
        let cos_om = f64::from(wo.dot(wm).max(0.0));
        self.albedo() * saturate(f64::from(FRAC_1_PI) * cos_om * surface.g1_unchecked(wo))
    }

    /// 1/(8π) + ⟨ωo, n⟩⁺/(2π) above the base plane (an approximation, see
    /// [`NoncentralMaterial`]).
    #[inline]
    fn pdf_single<S: MicrosurfaceSlope>(&self, surface: &Noncentral<S>, wi: Vec3, wo: Vec3) -> f32 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        0.125 / PI + 0.5 * FRAC_1_PI * wo.dot(surface.mean_normal()).max(0.0)
    }

    #[inline]
    fn sample_single<S: MicrosurfaceSlope>(
        &self,
        surface: &Noncentral<S>,
        wi: Vec3,
        u: Vec2,
        rng: &mut impl Rng,
    ) -> Option<SingleSample> {
        if wi.z <= 0.0 {
            return None;
        }
        let wm = surface.sample_d_wi_unchecked(wi, u.x, u.y);
        let lobe = self.sample_at_facet(wm, rng);
        // a direction below the base plane is masked by it
        if lobe.wo.z.is_nan() || lobe.wo.z <= 0.0 {
            return None;
        }
        let weight = lobe.weight * saturate(surface.g1_unchecked(lobe.wo));
        Some(SingleSample { wo: lobe.wo, weight, pdf: self.pdf_single(surface, wi, lobe.wo) })
    }
}
