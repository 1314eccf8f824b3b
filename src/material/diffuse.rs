//! Diffuse (Lambertian) microfacets.

use super::{Material, PhaseSample, g2_reflection};
use crate::basis::basis;
use crate::contract::is_direction;
use crate::error::Error;
use crate::rng::uniform;
use crate::sampling::cosine_hemisphere;
use crate::slope::{MicrosurfaceSlope, normalize_fast};
use core::f32::consts::{FRAC_1_PI, PI};
use glam::Vec3;
use rand::Rng;

/// Lambertian microfacets with an RGB albedo (Heitz et al. 2016, supplement §3.3).
///
/// [`Diffuse::white`] has albedo 1 (the supplement's non-absorptive validation baseline).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Diffuse {
    albedo: Vec3,
}

impl Diffuse {
    /// Diffuse facets with the given albedo per channel.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if a component of `albedo` is NaN or outside [0, 1].
    pub fn new(albedo: Vec3) -> Result<Self, Error> {
        for a in albedo.to_array() {
            Error::check_unit_interval("albedo", a)?;
        }
        Ok(Self { albedo })
    }

    /// Non-absorptive facets, albedo 1.
    pub fn white() -> Self {
        Self { albedo: Vec3::ONE }
    }

    /// The albedo per channel.
    #[inline]
    pub fn albedo(&self) -> Vec3 {
        self.albedo
    }
}

impl Material for Diffuse {
    const TRANSMITS: bool = false;

    /// p(ωi, ωo) = (a/π) ∫⟨ωo, ωm⟩ D_ωi(ωm) dωm, estimated with one ωm drawn from D_ωi
    /// (supplement §3.3, Algorithm 5): unbiased, stochastic.
    #[inline]
    fn eval_phase<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
        rng: &mut impl Rng,
    ) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        self.eval_phase_unchecked(slope, wi, wo, wi_outside, wo_outside, rng)
    }

    #[inline]
    fn eval_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
        rng: &mut impl Rng,
    ) -> Vec3 {
        if !(wi_outside && wo_outside) {
            return Vec3::ZERO;
        }
        let wm = slope.sample_d_wi_unchecked(wi, uniform(rng), uniform(rng));
        self.albedo * (FRAC_1_PI * wo.dot(wm).max(0.0))
    }

    const EXACT_PHASE_PDF: bool = false;

    /// An approximation, 1/(8π) + max(0, cos θo)/(2π) for two outside directions: the exact
    /// density (1/π) ∫⟨ωo, ωm⟩ D_ωi(ωm) dωm has no closed form. Positive on the whole
    /// sphere, so that MIS weights built on it never exclude a path.
    #[inline]
    fn pdf_phase<S: MicrosurfaceSlope>(
        &self,
        _slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
    ) -> f32 {
        require!(is_direction(wi) && is_direction(wo), 0.0; wi, wo);
        self.pdf_phase_unchecked(_slope, wi, wo, wi_outside, wo_outside)
    }

    #[inline]
    fn pdf_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        _slope: &S,
        _wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
    ) -> f32 {
        if !(wi_outside && wo_outside) {
            return 0.0;
        }
        0.125 / PI + 0.5 * FRAC_1_PI * wo.z.max(0.0)
    }

    /// (a/π) ⟨ωo, ωm⟩ A(ωi)/|cos θi| with ωm drawn from D_ωi: an unbiased estimate of the
    /// vertex term (1/|cos θi|) ∫ (a/π) ⟨ωi, ωm⟩⟨ωo, ωm⟩ D(ωm) dωm.
    #[inline]
    fn vertex<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
        rng: &mut impl Rng,
    ) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        self.vertex_unchecked(slope, wi, wo, wi_outside, wo_outside, rng)
    }

    #[inline]
    fn vertex_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        wi_outside: bool,
        wo_outside: bool,
        rng: &mut impl Rng,
    ) -> Vec3 {
        if !(wi_outside && wo_outside) || wi.z == 0.0 {
            return Vec3::ZERO;
        }
        let wm = slope.sample_d_wi_unchecked(wi, uniform(rng), uniform(rng));
        self.albedo * (FRAC_1_PI * wo.dot(wm).max(0.0) * slope.projected_area_unchecked(wi) / wi.z.abs())
    }

    /// ωm from D_ωi, then ωo cosine-distributed about ωm; weight a.
    #[inline]
    fn sample_phase<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        _wi_outside: bool,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        require!(is_direction(wi), PhaseSample { wo: Vec3::NAN, weight: Vec3::ZERO, outside: true }; wi);
        self.sample_phase_unchecked(slope, wi, _wi_outside, rng)
    }

    #[inline]
    fn sample_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        _wi_outside: bool,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        let wm = slope.sample_d_wi_unchecked(wi, uniform(rng), uniform(rng));
        let local = cosine_hemisphere(uniform(rng), uniform(rng));
        let (t, b) = basis(wm);
        let wo = normalize_fast(local.x * t + local.y * b + local.z * wm, wm);
        PhaseSample { wo, weight: self.albedo, outside: true }
    }

    /// (a/π) ⟨ωo, ωm⟩ (1 + Λ(ωi))/(1 + Λ(ωi) + Λ(ωo)) with ωm drawn from D_ωi: the
    /// single-scattering BSDF times cos θo, estimated without bias (Heitz and Dupuy 2015,
    /// supplement §3.3).
    #[inline]
    fn eval_single_scattering<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        rng: &mut impl Rng,
    ) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        let g2 = g2_reflection(slope, wi, wo);
        if g2 == 0.0 {
            return Vec3::ZERO;
        }
        let wm = slope.sample_d_wi_unchecked(wi, uniform(rng), uniform(rng));
        // (1 + Λi)/(1 + Λi + Λo) in f64: the f32 factors saturate near grazing
        let k = 1.0 + slope.lambda64(wi);
        let g2_given_g1 = (k / (k + slope.lambda64(wo))) as f32;
        self.albedo * (FRAC_1_PI * wo.dot(wm).max(0.0) * g2_given_g1)
    }
}
