//! The renderer-facing single-scattering BSDF of a noncentral (sheared) microsurface: the lobe a
//! renderer that filters its normal maps with LEADR evaluates per texel.

use super::NoncentralMaterial;
use super::slope::Noncentral;
use crate::bsdf::{
    Bsdf, BsdfFlags, BsdfSample, BsdfValue, Hasher, PrimedRng, SampleFlags, Transport, unit_directions,
    unit_view,
};
use crate::error::Error;
use crate::material::{Conductor, Side};
use crate::slope::MicrosurfaceSlope;
use glam::{Vec2, Vec3};

/// The seed of the private generator of the stochastic (diffuse) evaluations and samples; the
/// caller's key decorrelates them (see [`Bsdf`]'s determinism).
const SEED: u64 = 0x6e6f_6e63_656e_7472;

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
    /// min(1, G1(ω)) for both directions (each on its side of the base plane): the part of a
    /// tilted texel that its neighbours would occlude is lost instead of scattered, so the
    /// albedo is ≤ 1 (F ≤ 1, a ≤ 1) and f stays symmetric (reciprocal). Sampling is unchanged
    /// (the visible normals of wo); the weight is the base-plane weight times
    /// min(1, 1/G1(wo))·min(1, 1/G1(wi)), at most w·min(1, G1(wi)) ≤ w for the base-plane
    /// weight w·G1(wi) (w = F for a conductor, 1 for a dielectric, a for diffuse facets).
    Clamped,
}

/// The single-scattering BSDF of a sheared microsurface [`Noncentral<S>`] with a conductor,
/// dielectric or diffuse material ([`NoncentralMaterial`], where the models are), for renderers
/// (the [`Bsdf`] trait): the LEADR lobe of a filtered normal or displacement map (Dupuy 2015,
/// thesis §3.3–3.4; [`LeadrLobe::bsdf`](crate::leadr::LeadrLobe::bsdf)).
///
/// * f(wo, wi) is the research layer's f·|cos θ| of the light path traced from the viewer,
///   [`Noncentral::eval_single_scattering`]`(wo, wi)`, divided by |cos θi| in f32 (as
///   [`MicrofacetBsdf`](crate::MicrofacetBsdf) does), with the clamped masking's factors if
///   chosen ([`NoncentralBsdf::with_masking`]) and, for a transmission in
///   [`Transport::Radiance`] (the default), the factor (η_wo/η_wi)²
///   ([`NoncentralBsdf::with_transport`]). For a conductor
///   f = F(⟨wi, ωh⟩) D(ωh) G1(wo) G1(wi)/(4 cos θo cos θi), D by eq. 3.2, G1 by eq. 3.3.
///   Conductors and diffuse facets are symmetric in (wo, wi); a dielectric's radiance BSDF
///   obeys f(wo, wi)/η_wo² = f(wi, wo)/η_wi².
/// * Sampling from the caller's uniforms: the visible normal of wo from `u` (eq. 3.4, exact),
///   then a dielectric's Fresnel event from `uc`, a diffuse lobe from `uc` and the private
///   generator. Conductors and dielectrics: the density is exact (`exact_pdf`) and the weight
///   is f·|cos θi|/pdf to relative 1e-5 (the half vector eval recomputes from (wo, wi) differs
///   from the sampled one by rounding). Diffuse facets: `eval` is an unbiased estimate
///   (`exact` false, seeded by the arguments and the key), the weight a·G1(wi) is exact
///   given the direction, and `pdf` is an approximation for MIS (see [`NoncentralMaterial`]).
///   Directions that would leave on the wrong side of the base plane are masked by it:
///   `sample` returns `None` for them, and ∫pdf < 1 by their probability. G1 can exceed 1 on a
///   sheared surface (views tilted away from the mean normal), so a weight can exceed F and the
///   albedo 1 (see [`NoncentralMasking`]).
/// * Views below the base plane (wo.z ≤ 0) of an opaque material (e.g. a normal map's
///   backfacing shading frame) see nothing: f, pdf are 0 and `sample` gives `None` (the
///   thesis' G1 is 0 there). A dielectric is seen from inside there (the flipped
///   configuration, η ↦ 1/η).
/// * No specular limit: unlike `MicrofacetBsdf` below [`SMOOTH_ALPHA`](crate::SMOOTH_ALPHA),
///   the lobe stays glossy at every roughness (a LEADR lobe's roughness is never below its
///   base roughness, and the filtered lobes of interest are rough).
/// * Conductors and dielectrics: every method is deterministic and exact
///   (`exact_pdf`, `BsdfValue::exact`), the key unused. Samples whose pdf or f would not be a
///   normal f32 are not returned (at most 4π·`f32::MIN_POSITIVE` of probability), nor those
///   whose weight saturates.
/// * Inputs as for every [`Bsdf`] ([Inputs](Bsdf#inputs)): directions within
///   [`BSDF_DIRECTION_TOLERANCE`](crate::BSDF_DIRECTION_TOLERANCE) of unit length are
///   renormalized and a uniform of 1 is taken as 1 − 2⁻²⁴; other non-unit or non-finite
///   directions and uniforms outside [0, 1] trip a debug assertion and give 0 / `None` in
///   release builds.
///
/// # Examples
/// ```
/// use microsurface::glam::{Vec2, Vec3};
/// use microsurface::{Beckmann, Bsdf, ComplexIor, Conductor, Dielectric, Elliptical};
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
/// // the same sheared facets as glass: uc = 0.9 picks the refraction
/// let glass = NoncentralBsdf::new(surface, Dielectric::new(1.5)?)?;
/// let t = glass.sample(wo, 0.9, Vec2::new(0.3, 0.7)).expect("a refraction below the plane");
/// assert!(t.flags.transmission && t.wi.z < 0.0 && t.eta == 1.5);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoncentralBsdf<S, M = Conductor> {
    surface: Noncentral<S>,
    material: M,
    masking: NoncentralMasking,
    transport: Transport,
}

impl<S: MicrosurfaceSlope, M: NoncentralMaterial> NoncentralBsdf<S, M> {
    /// The single-scattering BSDF of `surface` with `material`, the base-plane masking and
    /// radiance transport.
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
        Ok(Self { surface, material, masking: NoncentralMasking::default(), transport: Transport::default() })
    }

    /// The same BSDF with another masking-shadowing.
    #[must_use]
    pub fn with_masking(self, masking: NoncentralMasking) -> Self {
        Self { masking, ..self }
    }

    /// The same BSDF for another transported quantity: [`Transport::Importance`] drops the
    /// (η_wo/η_wi)² factor of a dielectric's transmissions (no effect on opaque materials).
    #[must_use]
    pub fn with_transport(self, transport: Transport) -> Self {
        Self { transport, ..self }
    }

    /// The masking-shadowing.
    #[inline]
    pub fn masking(&self) -> NoncentralMasking {
        self.masking
    }

    /// The transported quantity.
    #[inline]
    pub fn transport(&self) -> Transport {
        self.transport
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

    /// The factor min(1, G1(ω))/G1(ω) = min(1, A/|cos θ|) of the clamped masking for ω off the
    /// base plane (G1 on ω's side), 1 for the base-plane masking.
    #[inline(always)]
    fn clamp_scale(&self, w: Vec3) -> f32 {
        match self.masking {
            NoncentralMasking::BasePlane => 1.0,
            NoncentralMasking::Clamped => (1.0 / self.surface.g1_on_side(w)).min(1.0) as f32,
        }
    }

    /// The factor of the transported quantity for light from wi to wo: (η_wo/η_wi)² for
    /// radiance, 1 for importance (and for every reflection).
    #[inline(always)]
    fn transport_scale(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self.transport {
            Transport::Radiance => {
                self.material.relative_eta_sq(Side::above_or_inside(wi.z), Side::above_or_inside(wo.z))
            }
            Transport::Importance => 1.0,
        }
    }

    /// The factors of the masking and of the transport applied to the research layer's
    /// (wo, wi) value or weight.
    #[inline(always)]
    fn scale(&self, wo: Vec3, wi: Vec3) -> f32 {
        let masking = match self.masking {
            NoncentralMasking::BasePlane => 1.0,
            NoncentralMasking::Clamped => self.clamp_scale(wo) * self.clamp_scale(wi),
        };
        masking * self.transport_scale(wo, wi)
    }

    /// f for valid directions: the research layer's f·|cos θ| of the path entering along wo and
    /// leaving along wi, divided by |cos θi|, with the masking and transport factors; 0 on the
    /// horizon or if not finite.
    #[inline(always)]
    fn f_checked(&self, wo: Vec3, wi: Vec3, key: u64) -> Vec3 {
        if wo.z == 0.0 || wi.z == 0.0 {
            return Vec3::ZERO;
        }
        // deterministic except for diffuse facets: the generator (and its hash) only on use
        let mut rng = PrimedRng::new(&[], || Hasher::directions(SEED, key, wo, wi));
        let f_cos = self.material.eval_single(&self.surface, wo, wi, &mut rng);
        let f = f_cos / wi.z.abs() * self.scale(wo, wi);
        if f.is_finite() { f } else { Vec3::ZERO }
    }

    /// The density for valid directions, 0 if not finite.
    #[inline(always)]
    fn pdf_checked(&self, wo: Vec3, wi: Vec3) -> f32 {
        let pdf = self.material.pdf_single(&self.surface, wo, wi);
        if pdf.is_finite() { pdf } else { 0.0 }
    }
}

impl<S: MicrosurfaceSlope, M: NoncentralMaterial> Bsdf for NoncentralBsdf<S, M> {
    #[inline]
    fn flags(&self) -> BsdfFlags {
        BsdfFlags {
            reflection: true,
            transmission: M::TRANSMITS,
            glossy: !M::LAMBERTIAN,
            diffuse: M::LAMBERTIAN,
            specular: false,
        }
    }

    #[inline]
    fn eval_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> BsdfValue {
        let exact = M::EXACT_PHASE_PDF;
        unit_directions!(wo, wi, BsdfValue { f: Vec3::ZERO, exact }, self.eval_keyed(wo, wi, key));
        BsdfValue { f: self.f_checked(wo, wi, key), exact }
    }

    #[inline]
    fn sample_keyed(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample> {
        unit_view!(wo, uc, u, None, self.sample_keyed(wo, uc, u, key));
        // the event's uniform from the caller, anything more (a diffuse lobe's second
        // uniform) from the private generator
        let mut rng = PrimedRng::new(&[uc], || Hasher::direction_uniforms(SEED, key, wo, uc, u));
        let s = self.material.sample_single(&self.surface, wo, u, &mut rng)?;
        let wi = s.wo;
        let weight = s.weight * self.scale(wo, wi);
        let pdf = s.pdf;
        // as MicrofacetBsdf: the density and f = weight·pdf/|cos θi| must be normal f32 numbers
        // (eval could not reproduce a subnormal f), and a weight saturated by G1 = f32::MAX
        // is not f·cos/pdf
        if !((f32::MIN_POSITIVE..=f32::MAX).contains(&pdf)
            && weight.is_finite()
            && weight.max_element() < f32::MAX
            && wi.z != 0.0)
        {
            return None;
        }
        let f_max = f64::from(weight.max_element()) * f64::from(pdf) / f64::from(wi.z.abs());
        if f_max < f64::from(f32::MIN_POSITIVE) || f_max > f64::from(f32::MAX) {
            return None;
        }
        let reflection = (wi.z > 0.0) == (wo.z > 0.0);
        let flags = SampleFlags {
            reflection,
            transmission: !reflection,
            specular: false,
            exact_pdf: M::EXACT_PHASE_PDF,
        };
        // η_wi/η_wo of a transmission: relative_eta_sq(a, b) = (η_b/η_a)²
        let eta = if reflection {
            1.0
        } else {
            self.material.relative_eta_sq(Side::above_or_inside(wo.z), Side::above_or_inside(wi.z)).sqrt()
        };
        Some(BsdfSample { wi, weight, pdf, eta, flags })
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        unit_directions!(wo, wi, 0.0, self.pdf(wo, wi));
        self.pdf_checked(wo, wi)
    }

    #[inline]
    fn eval_with_pdf_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> (BsdfValue, f32) {
        let exact = M::EXACT_PHASE_PDF;
        unit_directions!(
            wo,
            wi,
            (BsdfValue { f: Vec3::ZERO, exact }, 0.0),
            self.eval_with_pdf_keyed(wo, wi, key)
        );
        (BsdfValue { f: self.f_checked(wo, wi, key), exact }, self.pdf_checked(wo, wi))
    }
}
