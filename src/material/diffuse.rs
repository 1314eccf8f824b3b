//! Diffuse (Lambertian) microfacets.

use super::{Interaction, Material, PhaseSample, Side, g2_reflection};
use crate::basis::basis;
use crate::contract::is_direction;
use crate::error::Error;
use crate::rng::{uniform, uniform_pair};
use crate::sampling::{cosine_about, cosine_hemisphere};
use crate::slope::{MicrosurfaceSlope, normalize_fast};
use core::f32::consts::{FRAC_1_PI, PI};
use glam::Vec3;
use rand::Rng;

/// Lambertian microfacets with an RGB albedo (Heitz et al. 2016, supplement §3.3).
///
/// [`Diffuse::white`] has albedo 1 (the supplement's non-absorptive validation baseline).
///
/// Its [`Material`] terms, all 0 unless both directions are outside, with ωm drawn from
/// D_ωi where an integral over the visible normals is estimated:
/// - phase function p(ωi, ωo) = (a/π) ∫⟨ωo, ωm⟩ D_ωi(ωm) dωm, estimated with one ωm
///   (supplement §3.3, Algorithm 5): unbiased, stochastic;
/// - `pdf_phase`: an approximation, 1/(8π) + max(0, cos θo)/(2π): the exact density
///   (1/π) ∫⟨ωo, ωm⟩ D_ωi(ωm) dωm has no closed form. Positive on the whole sphere, so that
///   MIS weights built on it never exclude a path;
/// - vertex term: (a/π) ⟨ωo, ωm⟩ A(ωi)/|cos θi|, an unbiased estimate of
///   (1/|cos θi|) ∫ (a/π) ⟨ωi, ωm⟩⟨ωo, ωm⟩ D(ωm) dωm;
/// - sampling: ωm from D_ωi, then ωo cosine-distributed about ωm; weight a;
/// - single scattering: see [`Material::eval_single_scattering`] below.
///
/// # Examples
/// ```
/// use microsurface::Diffuse;
/// use microsurface::glam::Vec3;
///
/// assert_eq!(Diffuse::white().albedo(), Vec3::ONE);
/// assert!(Diffuse::new(Vec3::new(0.5, 1.5, 0.2)).is_err());
/// ```
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
    #[must_use]
    pub fn white() -> Self {
        Self { albedo: Vec3::ONE }
    }

    /// The albedo per channel.
    #[inline]
    #[must_use]
    pub fn albedo(&self) -> Vec3 {
        self.albedo
    }
}

impl Diffuse {
    /// A direction from the Lambertian lobe of the facet with normal `wm` (cosine-weighted
    /// about ωm), weighted by the albedo.
    #[inline(always)]
    fn sample_at_facet(&self, wm: Vec3, rng: &mut impl Rng) -> PhaseSample {
        let local = cosine_hemisphere(uniform(rng), uniform(rng));
        let (t, b) = basis(wm);
        let wo = normalize_fast(local.x * t + local.y * b + local.z * wm, wm);
        PhaseSample { wo, weight: self.albedo, side: Side::Outside }
    }

    /// [`Diffuse::sample_at_facet`] as the walks draw it: the same lobe as normalize(ωm + s),
    /// s uniform on the sphere ([`cosine_about`]: no frame about ωm), from one 64-bit draw.
    #[inline(always)]
    fn sample_at_facet_walk(&self, wm: Vec3, rng: &mut impl Rng) -> PhaseSample {
        let (u1, u2) = uniform_pair(rng);
        PhaseSample { wo: cosine_about(wm, u1, u2), weight: self.albedo, side: Side::Outside }
    }
}

impl Material for Diffuse {
    const TRANSMITS: bool = false;
    const EXACT_PHASE_PDF: bool = false;

    #[inline]
    fn eval_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        rng: &mut impl Rng,
    ) -> Vec3 {
        if !it.is_outside_reflection() {
            return Vec3::ZERO;
        }
        let wm = slope.sample_d_wi_unchecked(it.wi(), uniform(rng), uniform(rng));
        self.albedo * (FRAC_1_PI * it.wo().dot(wm).max(0.0))
    }

    #[inline]
    fn pdf_phase_unchecked<S: MicrosurfaceSlope>(&self, _slope: &S, it: &Interaction) -> f32 {
        if !it.is_outside_reflection() {
            return 0.0;
        }
        0.125 / PI + 0.5 * FRAC_1_PI * it.wo().z.max(0.0)
    }

    #[inline]
    fn vertex_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        rng: &mut impl Rng,
    ) -> Vec3 {
        let wi = it.wi();
        if !it.is_outside_reflection() || wi.z == 0.0 {
            return Vec3::ZERO;
        }
        let wm = slope.sample_d_wi_unchecked(wi, uniform(rng), uniform(rng));
        self.albedo * (FRAC_1_PI * it.wo().dot(wm).max(0.0) * slope.projected_area_unchecked(wi) / wi.z.abs())
    }

    #[inline]
    fn sample_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        _side: Side,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        let wm = slope.sample_d_wi_unchecked(wi, uniform(rng), uniform(rng));
        self.sample_at_facet(wm, rng)
    }

    /// Both pairs of uniforms (the visible normal's, the lobe's) from one 64-bit draw each,
    /// the lobe without a frame (the walks' stream).
    #[inline]
    fn sample_phase_walk_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        _side: Side,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        let (u1, u2) = uniform_pair(rng);
        let wm = slope.sample_d_wi_unchecked(wi, u1, u2);
        self.sample_at_facet_walk(wm, rng)
    }

    /// One visible facet ωm ~ D_ωi for both: the estimate (a/π)⟨ωo, ωm⟩⁺ of the phase function
    /// (unbiased given the walk so far, as in `eval_phase`) and the direction sampled from the
    /// same facet. Saves one visible-normal sample per bounce of the walk's `eval`; the walk's
    /// random stream differs from that of the separate calls.
    #[inline]
    fn eval_and_sample_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        rng: &mut impl Rng,
    ) -> (Vec3, PhaseSample) {
        let (u1, u2) = uniform_pair(rng);
        let wm = slope.sample_d_wi_unchecked(it.wi(), u1, u2);
        let phase = if it.is_outside_reflection() {
            self.albedo * (FRAC_1_PI * it.wo().dot(wm).max(0.0))
        } else {
            Vec3::ZERO
        };
        (phase, self.sample_at_facet_walk(wm, rng))
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
