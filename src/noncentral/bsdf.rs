//! The renderer-facing single-scattering BSDF of a noncentral (sheared) microsurface: the lobe a
//! renderer that filters its normal maps with LEADR evaluates per texel.

use super::NoncentralMaterial;
use super::slope::Noncentral;
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, BsdfValue, SampleFlags, unit_directions, unit_view};
use crate::error::Error;
use crate::material::Conductor;
use crate::slope::MicrosurfaceSlope;
use glam::{Vec2, Vec3};

/// The masking-shadowing of a [`NoncentralBsdf`]: the thesis' G1 (eq. 3.3), or that G1 clamped
/// to 1 so that the lobe conserves energy.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NoncentralMasking {
    /// G1(ω) = cos θ/A(ω) (Dupuy 2015, eq. 3.3), normalized to the base plane's projected
    /// area: it exceeds 1 for views tilted away from the mean normal, and so can the albedo
    /// (perfect conductor, GGX α = 0.1, x̃n = (1, 0), θo = 1.2 at φo = 0: 5.8). The model
    /// [`Noncentral::eval_single_scattering`] and the LEADR validation use.
    #[default]
    BasePlane,
    /// min(1, G1(ω)) for both directions: the part of a tilted texel that its neighbours
    /// would occlude is lost instead of scattered, so the albedo is ≤ 1 (F ≤ 1) and f stays
    /// symmetric. Sampling is unchanged (the visible normals of wo); the weight is
    /// F·min(1, G1(wi))·min(1, G1(wo))/G1(wo).
    Clamped,
}

/// The single-scattering BSDF of a sheared microsurface [`Noncentral<S>`] with a conductor, for
/// renderers (the [`Bsdf`] trait): the LEADR lobe of a filtered normal or displacement map
/// (Dupuy 2015, thesis §3.3–3.4; [`LeadrLobe::bsdf`](crate::leadr::LeadrLobe::bsdf)).
///
/// * f(wo, wi) = F(⟨wi, ωh⟩) D(ωh) G1(wo) G1(wi) / (4 cos θo cos θi), ωh = (wo + wi)/‖·‖, with D
///   by eq. 3.2, G1 by eq. 3.3 and the separable G2 (see [`Noncentral`]) for wo and wi above
///   the base plane, 0 otherwise ([`NoncentralMasking::BasePlane`], the default;
///   [`NoncentralBsdf::with_masking`] chooses the energy-conserving
///   [`NoncentralMasking::Clamped`]). f is symmetric in (wo, wi); [`Bsdf::eval`] is
///   [`Noncentral::eval_single_scattering`]`(wo, wi)` (the light path traced from the viewer,
///   as [`MicrofacetBsdf`](crate::MicrofacetBsdf) does) divided by cos θi in f32.
/// * Sampling: ωh from the visible normals of wo (eq. 3.4, exact), wi its mirror image; the
///   density is D_wo(ωh)/(4⟨wi, ωh⟩) and the weight F·G1(wi) = f·cos θi/pdf to relative 1e-5
///   (the half vector eval recomputes from (wo, wi) differs from the sampled one by rounding).
///   Reflections that would leave below the base plane are masked by it: `sample` returns
///   `None` for them, and ∫pdf < 1 by their probability. G1 can exceed 1 on a sheared
///   surface (views tilted away from the mean normal), so a weight can exceed F and the
///   albedo 1 (see [`NoncentralMasking`]).
/// * Views below the base plane (wo.z ≤ 0, e.g. a normal map's backfacing shading frame) see
///   nothing: f, pdf are 0 and `sample` gives `None` (the thesis' G1 is 0 there).
/// * No specular limit: unlike `MicrofacetBsdf` below [`SMOOTH_ALPHA`](crate::SMOOTH_ALPHA),
///   the lobe stays glossy at every roughness (a LEADR lobe's roughness is never below its
///   base roughness, and the filtered lobes of interest are rough).
/// * Every method is deterministic and exact (`exact_pdf`, `BsdfValue::exact`); `uc` and the
///   key are unused. Samples whose pdf or f would not be a normal f32 are not returned (at most
///   4π·`f32::MIN_POSITIVE` of probability), nor those whose weight saturates.
/// * Inputs as for every [`Bsdf`] ([Inputs](Bsdf#inputs)): directions within
///   [`BSDF_DIRECTION_TOLERANCE`](crate::BSDF_DIRECTION_TOLERANCE) of unit length are
///   renormalized and a uniform of 1 is taken as 1 − 2⁻²⁴; other non-unit or non-finite
///   directions and uniforms outside [0, 1] trip a debug assertion and give 0 / `None` in
///   release builds.
///
/// Dielectrics are not supported (see [`NoncentralMaterial`]).
///
/// # Examples
/// ```
/// use microsurface::glam::{Vec2, Vec3};
/// use microsurface::{Beckmann, Bsdf, ComplexIor, Conductor, Elliptical};
/// use microsurface::leadr::{Noncentral, NoncentralBsdf};
///
/// let slope = Elliptical::<Beckmann>::from_bivariate(0.3, 0.2, 0.5)?;
/// let surface = Noncentral::new(slope, Vec2::new(0.4, -0.1))?;
/// let bsdf = NoncentralBsdf::new(surface, Conductor::new(ComplexIor::GOLD))?;
/// let wo = Vec3::new(0.3, 0.2, 0.9).normalize();
/// let s = bsdf.sample(wo, 0.5, Vec2::new(0.3, 0.7)).expect("a reflection above the plane");
/// let (f, pdf) = bsdf.eval_with_pdf(wo, s.wi);
/// assert!(f.exact && pdf > 0.0);
/// assert!((f.f * s.wi.z / pdf - s.weight).abs().max_element() < 1e-4);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoncentralBsdf<S, M = Conductor> {
    surface: Noncentral<S>,
    material: M,
    masking: NoncentralMasking,
}

impl<S: MicrosurfaceSlope, M: NoncentralMaterial> NoncentralBsdf<S, M> {
    /// The single-scattering BSDF of `surface` with `material`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`"mean_slope"`) if the mean slope's squared norm
    /// x̃n² + ỹn² is not finite in f32 (|x̃n| ≳ 1.3·10¹⁹): the mean normal
    /// (−x̃n, −ỹn, 1)/‖·‖ and the shear of the f32 directions are then undefined.
    pub fn new(surface: Noncentral<S>, material: M) -> Result<Self, Error> {
        let mean = surface.mean_slope();
        let norm_sq = mean.length_squared();
        if !norm_sq.is_finite() {
            return Err(Error::InvalidParameter {
                name: "mean_slope",
                value: norm_sq,
                expected: "x̃n² + ỹn² finite",
            });
        }
        Ok(Self { surface, material, masking: NoncentralMasking::default() })
    }

    /// The same BSDF with another masking-shadowing.
    #[must_use]
    pub fn with_masking(self, masking: NoncentralMasking) -> Self {
        Self { masking, ..self }
    }

    /// The masking-shadowing.
    #[inline]
    pub fn masking(&self) -> NoncentralMasking {
        self.masking
    }

    /// The factor min(1, G1(ω))/G1(ω) = min(1, A(ω)/cos θ) of the clamped masking for ω above
    /// the base plane, 1 for the base-plane masking.
    #[inline(always)]
    fn clamp_scale(&self, w: Vec3) -> f32 {
        match self.masking {
            NoncentralMasking::BasePlane => 1.0,
            NoncentralMasking::Clamped => (1.0 / self.surface.g1(w)).min(1.0),
        }
    }

    /// The sheared microsurface.
    #[inline]
    pub fn surface(&self) -> &Noncentral<S> {
        &self.surface
    }

    /// The material.
    #[inline]
    pub fn material(&self) -> &M {
        &self.material
    }

    /// f for valid directions: the research layer's f·cos θo of the path entering along wo and
    /// leaving along wi, divided by cos θi; 0 below the base plane or if not finite.
    #[inline(always)]
    fn f_checked(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let f = self.material.eval_single(&self.surface, wo, wi) / wi.z;
        let f = match self.masking {
            NoncentralMasking::BasePlane => f,
            NoncentralMasking::Clamped => f * (self.clamp_scale(wo) * self.clamp_scale(wi)),
        };
        if f.is_finite() { f } else { Vec3::ZERO }
    }

    /// The density for valid directions, 0 if not finite.
    #[inline(always)]
    fn pdf_checked(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let pdf = self.surface.pdf_single_scattering(wo, wi);
        if pdf.is_finite() { pdf } else { 0.0 }
    }
}

impl<S: MicrosurfaceSlope, M: NoncentralMaterial> Bsdf for NoncentralBsdf<S, M> {
    #[inline]
    fn flags(&self) -> BsdfFlags {
        BsdfFlags { reflection: true, transmission: false, glossy: true, diffuse: false, specular: false }
    }

    #[inline]
    fn eval_keyed(&self, wo: Vec3, wi: Vec3, _key: u64) -> BsdfValue {
        unit_directions!(wo, wi, BsdfValue::ZERO, self.eval_keyed(wo, wi, 0));
        BsdfValue { f: self.f_checked(wo, wi), exact: true }
    }

    #[inline]
    fn sample_keyed(&self, wo: Vec3, uc: f32, u: Vec2, _key: u64) -> Option<BsdfSample> {
        unit_view!(wo, uc, u, None, self.sample_keyed(wo, uc, u, 0));
        if wo.z <= 0.0 {
            return None;
        }
        let mut s = self.material.sample_single(&self.surface, wo, u)?;
        let wi = s.wo;
        if self.masking == NoncentralMasking::Clamped {
            s.weight *= self.clamp_scale(wo) * self.clamp_scale(wi);
        }
        let pdf = self.pdf_checked(wo, wi);
        // as MicrofacetBsdf: the density and f = weight·pdf/cos θi must be normal f32 numbers
        // (eval could not reproduce a subnormal f), and a weight saturated by G1 = f32::MAX
        // is not f·cos/pdf
        if !(pdf >= f32::MIN_POSITIVE && s.weight.is_finite() && s.weight.max_element() < f32::MAX)
            || wi.z <= 0.0
        {
            return None;
        }
        let f_max = f64::from(s.weight.max_element()) * f64::from(pdf) / f64::from(wi.z);
        if f_max < f64::from(f32::MIN_POSITIVE) || f_max > f64::from(f32::MAX) {
            return None;
        }
        let flags = SampleFlags { reflection: true, transmission: false, specular: false, exact_pdf: true };
        Some(BsdfSample { wi, weight: s.weight, pdf, eta: 1.0, flags })
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        unit_directions!(wo, wi, 0.0, self.pdf(wo, wi));
        self.pdf_checked(wo, wi)
    }

    #[inline]
    fn eval_with_pdf_keyed(&self, wo: Vec3, wi: Vec3, _key: u64) -> (BsdfValue, f32) {
        unit_directions!(wo, wi, (BsdfValue::ZERO, 0.0), self.eval_with_pdf_keyed(wo, wi, 0));
        (BsdfValue { f: self.f_checked(wo, wi), exact: true }, self.pdf_checked(wo, wi))
    }
}
