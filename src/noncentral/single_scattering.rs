//! The single-scattering BSDF of a material on a sheared microsurface (Dupuy 2015, eq. 2.9 with
//! eqs. 3.2–3.4 and the separable G2).

use super::slope::Noncentral;
use crate::contract::{is_direction, is_uniform};
use crate::material::{Conductor, Material};
use crate::microsurface::WalkSample;
use crate::slope::MicrosurfaceSlope;
use crate::vector::normalize_fast;
use glam::{Vec2, Vec3};

/// The materials single scattering on a [`Noncentral`] surface (and so
/// [`NoncentralBsdf`](crate::leadr::NoncentralBsdf)) is defined for: [`Conductor`] only.
///
/// Sealed. The thesis' noncentral BRDF (Dupuy 2015, eq. 2.9 with eqs. 3.2–3.3) is a reflection
/// model; a dielectric's refraction through the sheared facets (with the transmitted side's
/// masking below the base plane, where eq. 3.3 gives 0) is not derived here, so
/// [`Dielectric`](crate::Dielectric) and [`Diffuse`](crate::Diffuse) do not implement this
/// trait and `NoncentralBsdf<S, Dielectric>` does not compile.
pub trait NoncentralMaterial: Material + crate::sealed::Sealed {
    /// [`Noncentral::eval_single_scattering`] for valid directions.
    #[doc(hidden)]
    fn eval_single<S: MicrosurfaceSlope>(&self, surface: &Noncentral<S>, wi: Vec3, wo: Vec3) -> Vec3;

    /// [`Noncentral::sample_single_scattering`] for valid arguments.
    #[doc(hidden)]
    fn sample_single<S: MicrosurfaceSlope>(
        &self,
        surface: &Noncentral<S>,
        wi: Vec3,
        u: Vec2,
    ) -> Option<WalkSample>;
}

impl NoncentralMaterial for Conductor {
    #[inline]
    fn eval_single<S: MicrosurfaceSlope>(&self, surface: &Noncentral<S>, wi: Vec3, wo: Vec3) -> Vec3 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Vec3::ZERO;
        }
        let wh = (wi.as_dvec3() + wo.as_dvec3()).normalize_or_zero();
        let cos_ih = wi.as_dvec3().dot(wh);
        if cos_ih <= 0.0 {
            return Vec3::ZERO;
        }
        let value = surface.d_unchecked(wh) * surface.g1_unchecked(wi) * surface.g1_unchecked(wo)
            / (4.0 * f64::from(wi.z));
        self.fresnel(cos_ih as f32) * value.min(f64::from(f32::MAX)) as f32
    }

    #[inline]
    fn sample_single<S: MicrosurfaceSlope>(
        &self,
        surface: &Noncentral<S>,
        wi: Vec3,
        u: Vec2,
    ) -> Option<WalkSample> {
        if wi.z <= 0.0 {
            return None;
        }
        let wh = surface.sample_d_wi_unchecked(wi, u.x, u.y);
        let cos_ih = wi.dot(wh);
        let wo = normalize_fast(2.0 * cos_ih * wh - wi, Vec3::Z);
        if wo.z <= 0.0 {
            return None;
        }
        let weight =
            self.fresnel(cos_ih.max(0.0)) * (surface.g1_unchecked(wo).min(f64::from(f32::MAX)) as f32);
        Some(WalkSample { wo, weight, bounces: 1 })
    }
}

impl<S: MicrosurfaceSlope> Noncentral<S> {
    /// The single-scattering BRDF times |cos θo| of a material on the sheared microsurface (the
    /// research layer's convention, as
    /// [`Microsurface::eval_single_scattering`](crate::research::Microsurface::eval_single_scattering)).
    /// For a conductor: F(⟨ωi, ωh⟩) D(ωh) G1(ωi) G1(ωo)/(4 cos θi) with ωh = (ωi + ωo)/‖·‖
    /// (Dupuy 2015, eq. 2.9 with eqs. 3.2–3.3 and the separable G2, see the type's
    /// documentation), for ωi and ωo above the base plane; 0 otherwise. Evaluated in f64,
    /// saturated to `f32::MAX`.
    ///
    /// Invalid input ([policy](crate#invalid-input)): non-unit directions give 0.
    #[must_use]
    pub fn eval_single_scattering<M: NoncentralMaterial>(&self, material: &M, wi: Vec3, wo: Vec3) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        material.eval_single(self, wi, wo)
    }

    /// The density over ωo of [`Self::sample_single_scattering`]: D_ωi(ωh)/(4⟨ωo, ωh⟩) for a
    /// reflection ωo above the base plane, 0 otherwise (the samples that would leave below it
    /// are not returned).
    ///
    /// Invalid input ([policy](crate#invalid-input)): non-unit directions give 0.
    #[must_use]
    pub fn pdf_single_scattering(&self, wi: Vec3, wo: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wo), 0.0; wi, wo);
        if wo.z <= 0.0 {
            return 0.0;
        }
        let wh = (wi.as_dvec3() + wo.as_dvec3()).normalize_or_zero();
        let cos_oh = wo.as_dvec3().dot(wh);
        if cos_oh <= 0.0 {
            return 0.0;
        }
        (self.d_wi_unchecked(wi, wh) / (4.0 * cos_oh)) as f32
    }

    /// Samples the single-scattering reflection of a material from ωi above the base plane.
    /// For a conductor: ωh from D_ωi (eq. 3.4), ωo its mirror reflection, weight
    /// F(⟨ωi, ωh⟩)·G1(ωo) (= f|cos θo|/pdf with [`Self::eval_single_scattering`] and
    /// [`Self::pdf_single_scattering`]); `bounces` is 1. `None` where ωo would leave below the
    /// base plane (the base plane masks it) and for ωi at or below the horizon.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a non-unit `wi` or a uniform outside
    /// [0, 1] gives `None`.
    #[must_use]
    pub fn sample_single_scattering<M: NoncentralMaterial>(
        &self,
        material: &M,
        wi: Vec3,
        u1: f32,
        u2: f32,
    ) -> Option<WalkSample> {
        require!(is_direction(wi) && is_uniform(u1) && is_uniform(u2), None; wi, u1, u2);
        material.sample_single(self, wi, Vec2::new(u1, u2))
    }
}
