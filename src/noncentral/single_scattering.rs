//! The single-scattering BSDF of a material on a sheared microsurface (Dupuy 2015, eq. 2.9 with
//! eqs. 3.2–3.4 and the separable G2): the trait the materials implement
//! (`conductor.rs`, `dielectric.rs`, `diffuse.rs`) and the research-layer calls.

use super::slope::Noncentral;
use crate::contract::is_direction;
use crate::material::Material;
use crate::rng::uniform;
use crate::single_scattering::SingleSample;
use crate::slope::MicrosurfaceSlope;
use glam::{DVec3, Vec2, Vec3};
use rand::Rng;

/// The materials single scattering on a [`Noncentral`] surface (and so
/// [`NoncentralBsdf`](crate::leadr::NoncentralBsdf)) is defined for: [`Conductor`](crate::Conductor),
/// [`Dielectric`](crate::Dielectric) and [`Diffuse`](crate::Diffuse).
///
/// Sealed. Every model is the thesis' noncentral microfacet BSDF (Dupuy 2015, eq. 2.9 with
/// eqs. 3.2–3.4) with the separable masking-shadowing G1(ωi)·G1(ωo), each G1 by eq. 3.3 taken on
/// the side of the base plane its direction lies on, and the base plane masking what would
/// leave on the wrong side of it. With ωh the half vector, D the sheared D of eq. 3.2 and
/// f·|cos θo| in the research layer's convention (light arriving from ωi):
///
/// * **Conductor**: F(⟨ωi, ωh⟩) D(ωh) G1(ωi) G1(ωo)/(4 cos θi) for ωi, ωo above the base
///   plane; sampled by ωh ~ D_ωi (eq. 3.4) and the mirror reflection, weight F·G1(ωo).
/// * **Dielectric** (Walter's BSDF on the sheared facets): reflection as the conductor with the
///   dielectric F; transmission from ωi above to ωo below
///   ⟨ωi, ωh⟩ |⟨ωo, ωh⟩| η² (1 − F) D(ωh) G1(ωi) G1(−ωo) / (cos θi (⟨ωi, ωh⟩ + η⟨ωo, ωh⟩)²) with
///   ωh ∝ −(ωi + η ωo) turned up. The transmitted side's masking is G1(−ωo): seen from inside,
///   the facets are the same sheared surface flipped through the origin (ω ↦ −ω keeps every
///   slope, so D and the mean slope are unchanged), masked by eq. 3.3 against the base plane's
///   area |cos θo|. A view from inside (ωi below) is the flipped configuration with η ↦ 1/η.
///   Sampled by ωh ~ D_ωi, the Fresnel event (one uniform) and the reflection or refraction;
///   weight G1 of the outgoing direction on its side (the Fresnel term chooses the event).
///   Reflections that leave below the base plane and refractions that leave above it are masked
///   by it (`None`, their probability missing from ∫pdf). Reciprocal in the radiance form
///   f(ωi → ωo)/ηo² = f(ωo → ωi)/ηi².
/// * **Diffuse**: (a/π) G1(ωo) ∫⟨ωo, ωm⟩⁺ D_ωi(ωm) dωm for ωi, ωo above the base plane,
///   estimated without bias from one ωm ~ D_ωi, as the central diffuse material does (Heitz and
///   Dupuy 2015; supplement §3.3): f itself is symmetric,
///   (a/π) G1(ωi) G1(ωo)/(cos θi cos θo) ∫⟨ωi, ωm⟩⁺⟨ωo, ωm⟩⁺ D dωm. Sampled by ωm ~ D_ωi
///   and a cosine lobe about ωm, weight a·G1(ωo) (exact given the direction); the density of
///   that sampler has no closed form, so `pdf` is the documented approximation
///   1/(8π) + ⟨ωo, n⟩⁺/(2π) (n the mean normal) for ωo above the base plane, for MIS weights
///   only.
///
/// The limits are the conductor's (see [`Noncentral`] and
/// [`NoncentralMasking`](crate::leadr::NoncentralMasking)): G1 > 1 for directions tilted away
/// from the mean normal, so the albedo can exceed 1 unless the masking is clamped; the
/// separable G2 ignores the correlation of masking and shadowing; what a real displacement's
/// neighbouring texels occlude or receive is not modelled.
pub trait NoncentralMaterial: Material + crate::sealed::Sealed {
    /// Whether the facets are Lambertian (the renderer's `diffuse` flag, a stochastic eval and
    /// an approximate density).
    #[doc(hidden)]
    const LAMBERTIAN: bool = false;

    /// [`Noncentral::eval_single_scattering`] for valid directions.
    #[doc(hidden)]
    fn eval_single<S: MicrosurfaceSlope>(
        &self,
        surface: &Noncentral<S>,
        wi: Vec3,
        wo: Vec3,
        rng: &mut impl Rng,
    ) -> Vec3;

    /// [`Noncentral::pdf_single_scattering`] for valid directions.
    #[doc(hidden)]
    fn pdf_single<S: MicrosurfaceSlope>(&self, surface: &Noncentral<S>, wi: Vec3, wo: Vec3) -> f32;

    /// [`Noncentral::sample_single_scattering`] for valid arguments, the visible normal from the
    /// uniforms `u` and any further uniform (the dielectric's event, the diffuse lobe) from
    /// `rng`.
    #[doc(hidden)]
    fn sample_single<S: MicrosurfaceSlope>(
        &self,
        surface: &Noncentral<S>,
        wi: Vec3,
        u: Vec2,
        rng: &mut impl Rng,
    ) -> Option<SingleSample>;
}

/// The reflection half vector (ωi + ωo)/‖·‖ in f64 and ⟨ωi, ωh⟩, for ωi and ωo above the base
/// plane; `None` where ωi does not see it (ωo = −ωi within rounding). The one form the noncentral
/// reflections' eval and pdf share. Both directions are renormalized in f64 first: f32 unit
/// vectors are unit to ±1 ulp, and ⟨ωi, ωh⟩ − ⟨ωo, ωh⟩ = (‖ωi‖² − ‖ωo‖²)/‖ωi + ωo‖ would
/// otherwise make ⟨ωi, ωh⟩ depend on the order of the pair by up to 1e-7/‖ωi + ωo‖, which the
/// Fresnel term amplifies near grazing and near total internal reflection (1e-5 relative
/// asymmetry measured); renormalized, the two orders agree to f64 rounding.
#[inline(always)]
pub(crate) fn reflection_half(wi: Vec3, wo: Vec3) -> Option<(DVec3, f64)> {
    let (i, o) = (wi.as_dvec3().normalize(), wo.as_dvec3().normalize());
    let wh = (i + o).normalize_or_zero();
    let cos_ih = i.dot(wh);
    (cos_ih > 0.0).then_some((wh, cos_ih))
}

/// An f64 value rounded to f32, saturated at `f32::MAX` (G1 can overflow f32 for views that
/// see almost nothing of a steep surface).
#[inline(always)]
pub(crate) fn saturate(value: f64) -> f32 {
    value.min(f64::from(f32::MAX)) as f32
}

impl<S: MicrosurfaceSlope> Noncentral<S> {
    /// The single-scattering BSDF times |cos θo| of a material on the sheared microsurface, for
    /// light arriving from ωi and leaving along ωo (the research layer's convention, as
    /// [`SingleScattering::eval`](crate::research::SingleScattering::eval)); the models are on
    /// [`NoncentralMaterial`]. Exact (evaluated in f64, saturated to `f32::MAX`) for conductors
    /// and dielectrics, which never draw from `rng`; an unbiased one-sample estimate for
    /// diffuse facets. 0 where the model is 0 (an opaque material's directions below the base
    /// plane, directions on the horizon).
    ///
    /// Invalid input ([policy](crate#invalid-input)): non-unit directions give 0.
    #[must_use]
    pub fn eval_single_scattering<M: NoncentralMaterial>(
        &self,
        material: &M,
        wi: Vec3,
        wo: Vec3,
        rng: &mut impl Rng,
    ) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        material.eval_single(self, wi, wo, rng)
    }

    /// The density over ωo of [`Self::sample_single_scattering`]: for a conductor
    /// D_ωi(ωh)/(4⟨ωo, ωh⟩) for a reflection ωo above the base plane; for a dielectric
    /// F D_ωi(ωh)/(4⟨ωo, ωh⟩) (reflection) and (1 − F) D_ωi(ωh) η² |⟨ωo, ωh⟩|/(⟨ωi, ωh⟩ +
    /// η⟨ωo, ωh⟩)² (transmission); 0 on the wrong side of the base plane (those samples are
    /// not returned). For diffuse facets the approximation of [`NoncentralMaterial`] (the
    /// exact density has no closed form).
    ///
    /// Invalid input ([policy](crate#invalid-input)): non-unit directions give 0.
    #[must_use]
    pub fn pdf_single_scattering<M: NoncentralMaterial>(&self, material: &M, wi: Vec3, wo: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wo), 0.0; wi, wo);
        material.pdf_single(self, wi, wo)
    }

    /// Samples the single scattering of a material from ωi (see [`NoncentralMaterial`]): the
    /// visible normal ωh ~ D_ωi (eq. 3.4) from the first two uniforms of `rng`, then the
    /// material's event (a dielectric's Fresnel choice: one more uniform; a diffuse lobe: two
    /// more). The weight is f·|cos θo|/pdf with [`Self::eval_single_scattering`] and
    /// [`Self::pdf_single_scattering`] (for diffuse facets with the exact density of the
    /// sampler, which `pdf` approximates), the density the one `pdf_single_scattering` gives at
    /// the returned direction. `None` where ωo would leave on the wrong side of the base plane
    /// (the base plane masks it), for ωi on the horizon and for an opaque material's ωi below
    /// the base plane.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a non-unit `wi` gives `None`.
    #[must_use]
    pub fn sample_single_scattering<M: NoncentralMaterial>(
        &self,
        material: &M,
        wi: Vec3,
        rng: &mut impl Rng,
    ) -> Option<SingleSample> {
        require!(is_direction(wi), None; wi);
        let u = Vec2::new(uniform(rng), uniform(rng));
        material.sample_single(self, wi, u, rng)
    }

    /// G1 of a direction on its own side of the base plane: G1(ω) above it, G1(−ω) below it
    /// (the inside of a dielectric sees the surface flipped through the origin, with the same
    /// slopes), 0 on it.
    #[inline(always)]
    pub(crate) fn g1_on_side(&self, w: Vec3) -> f64 {
        if w.z < 0.0 { self.g1_unchecked(-w) } else { self.g1_unchecked(w) }
    }
}
