//! Conductor microfacets.

use super::{
    HalfSum, Interaction, LaneMaterial, Material, PhaseSample, Side, g2_reflection, phase_reflection,
    reflect, reflection_density, reflection_half_vector,
};
use crate::contract::{is_cosine, is_direction};
use crate::fresnel::{ComplexIor, conductor_reflectance};
use crate::rng::{uniform, uniform_pair};
use crate::slope::{MicrosurfaceSlope, renormalize};
use glam::{DVec3, Vec3};
use rand::Rng;

/// Below this ωi·ωm the Fresnel weight of a sampled reflection takes the cosine of the half
/// vector recomputed from the f32 directions (as eval does) rather than of ωm: the two differ
/// by about 6e-8/(2 ωi·ωm) rad, below 6e-7 above it (|dF/dcos| ≲ 2 for metals).
const FRESNEL_AT_HALF_VECTOR_BELOW: f32 = 0.05;

/// Conductor microfacets: specular reflection weighted by a Fresnel term
/// (Heitz et al. 2016, supplement §3.2).
///
/// [`Conductor::perfect`] has F = 1 (the supplement's non-absorptive validation baseline);
/// [`Conductor::new`] uses the exact Fresnel term of a complex IOR per RGB channel.
///
/// Its [`Material`] terms, with ωh the normalized ωi + ωo and A the projected area; all 0
/// unless both directions are outside:
/// - phase function p(ωi, ωo) = F(ωi·ωh) D_ωi(ωh)/(4 ωi·ωh) = F D(ωh)/(4 A(ωi))
///   (supplement §3.2); `pdf_phase` is the same without F;
/// - vertex term F(ωi·ωh) D(ωh)/(4 |cos θi|) (Wang et al. 2022, eq. 2);
/// - sampling: ωm from D_ωi, ωo = reflect(ωi, ωm), weight F(ωi·ωm); for ωi·ωm below
///   `FRESNEL_AT_HALF_VECTOR_BELOW` F takes the cosine of the half vector recomputed from the
///   f32 ωi and ωo, as the evaluations do, so that weight = F·(the phase density ratio) holds
///   to f32 precision;
/// - single scattering F(ωi·ωh) D(ωh) G2(ωi, ωo)/(4 cos θi) (the Cook–Torrance BRDF times
///   cos θo), sampled for views above the horizon from the slope's reflection sampler (GGX:
///   the bounded cap of Eto and Tokuyoshi 2023, [`GgxBoundedCap`](crate::vndf::GgxBoundedCap)).
///
/// # Examples
/// ```
/// use microsurface::{ComplexIor, Conductor};
///
/// let gold = Conductor::new(ComplexIor::GOLD);
/// assert_eq!(Conductor::perfect().fresnel(0.3), microsurface::glam::Vec3::ONE);
/// assert!(gold.fresnel(1.0).x > 0.9);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conductor {
    ior: Option<ComplexIor>,
}

impl Conductor {
    /// A perfect mirror facet, F = 1.
    #[must_use]
    pub fn perfect() -> Self {
        Self { ior: None }
    }

    /// A conductor with the given complex IOR.
    #[must_use]
    pub fn new(ior: ComplexIor) -> Self {
        Self { ior: Some(ior) }
    }

    /// The complex index (`None` for the perfect mirror, F = 1).
    #[inline(always)]
    pub(crate) fn ior(&self) -> Option<&ComplexIor> {
        self.ior.as_ref()
    }

    /// The vertex term F(ωi·ωh) D(ωh)/(4 |cos θi|) of a valid reflection half vector with
    /// D(ωh) = `d`; 0 for ωi on the horizon.
    #[inline(always)]
    fn reflection_vertex(&self, wi: Vec3, wh: DVec3, d: f64) -> Vec3 {
        if wi.z == 0.0 {
            return Vec3::ZERO;
        }
        self.reflectance(wi.as_dvec3().dot(wh) as f32) * (d / (4.0 * f64::from(wi.z.abs()))) as f32
    }

    /// The reflection half vector of an outside reflection, `None` for every other
    /// interaction and where the half vector is not a valid facet normal.
    #[inline(always)]
    fn half_vector(it: &Interaction) -> Option<DVec3> {
        if !it.is_outside_reflection() {
            return None;
        }
        reflection_half_vector(it.wi(), it.wo())
    }

    /// The Fresnel term for the cosine between ωi and the facet normal.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `cos_theta` that is NaN or beyond
    /// ±(1 + [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE)) gives `Vec3::NAN` (a debug
    /// assertion in debug builds).
    #[inline(always)]
    #[must_use]
    pub fn fresnel(&self, cos_theta: f32) -> Vec3 {
        require!(is_cosine(cos_theta), Vec3::NAN; cos_theta);
        self.reflectance(cos_theta)
    }

    /// [`Conductor::fresnel`] without the argument check, for the walks' own cosines.
    #[inline(always)]
    fn reflectance(&self, cos_theta: f32) -> Vec3 {
        match &self.ior {
            None => Vec3::ONE,
            Some(ior) => conductor_reflectance(cos_theta, ior),
        }
    }
}

impl Material for Conductor {
    const TRANSMITS: bool = false;
    const EXACT_PHASE_PDF: bool = true;
    const MIRROR_FACETS: bool = true;

    #[inline]
    fn lane_material(&self) -> LaneMaterial {
        LaneMaterial::Conductor(self.ior.map(|ior| ior.constants()))
    }

    #[inline]
    fn eval_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        _rng: &mut impl Rng,
    ) -> Vec3 {
        if let (Some(area), true) = (it.incident_area(), it.is_outside_reflection()) {
            // the walk's next-event estimation: A(ωi) known, the half vector unnormalized
            let Some(sum) = HalfSum::visible(it.wi(), it.wo()) else { return Vec3::ZERO };
            let density = sum.density(slope, area);
            return match &self.ior {
                None => Vec3::splat(density),
                Some(ior) => conductor_reflectance(sum.cos_ih(), ior) * density,
            };
        }
        let Some(wh) = Self::half_vector(it) else { return Vec3::ZERO };
        let wi = it.wi();
        self.reflectance(wi.as_dvec3().dot(wh) as f32) * phase_reflection(slope, wi, wh, it.incident_area())
    }

    #[inline]
    fn pdf_phase_unchecked<S: MicrosurfaceSlope>(&self, slope: &S, it: &Interaction) -> f32 {
        let Some(wh) = Self::half_vector(it) else { return 0.0 };
        phase_reflection(slope, it.wi(), wh, it.incident_area())
    }

    #[inline]
    fn vertex_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        _rng: &mut impl Rng,
    ) -> Vec3 {
        let Some(wh) = Self::half_vector(it) else { return Vec3::ZERO };
        self.reflection_vertex(it.wi(), wh, slope.d64_unchecked(wh))
    }

    /// One half vector and one D for the vertex term and both densities.
    #[inline]
    fn connection_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        _rng: &mut impl Rng,
    ) -> (Vec3, f32, f32) {
        let Some(wh) = Self::half_vector(it) else { return (Vec3::ZERO, 0.0, 0.0) };
        let (wi, wo) = (it.wi(), it.wo());
        let d = slope.d64_unchecked(wh);
        // ωh is also the half vector of ωo → ωi
        let reverse = if wo.as_dvec3().dot(wh) > 0.0 { reflection_density(slope, wo, d) } else { 0.0 };
        (self.reflection_vertex(wi, wh, d), reflection_density(slope, wi, d), reverse)
    }

    #[inline]
    fn sample_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        _side: Side,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        // the uniforms in the order drawn: the visible normal's u1, then u2
        let (u1, u2) = (uniform(rng), uniform(rng));
        self.mirror_reflection_unchecked(wi, slope.sample_d_wi_unchecked(wi, u1, u2))
    }

    /// The visible normal's two uniforms from one 64-bit draw (the walks' stream).
    #[inline]
    fn sample_phase_walk_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        _side: Side,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        let (u1, u2) = uniform_pair(rng);
        self.mirror_reflection_unchecked(wi, slope.sample_d_wi_unchecked(wi, u1, u2))
    }

    #[inline(always)]
    fn mirror_reflection_unchecked(&self, wi: Vec3, wm: Vec3) -> PhaseSample {
        let c = wi.dot(wm);
        let wo = renormalize(reflect(wi, wm), wm);
        // near-perpendicular facets: ωo is within (ulp of ωo)/c of −ωi... the half vector that
        // eval and pdf recompute from the f32 directions is off ωm by ~6e-8/(2c) rad; F takes
        // its cosine, so that the weight is eval's F (f·cos/pdf) exactly
        let cos = match self.ior {
            Some(_) if c < FRESNEL_AT_HALF_VECTOR_BELOW => {
                reflection_half_vector(wi, wo).map_or(c, |wh| wi.as_dvec3().dot(wh) as f32)
            }
            _ => c,
        };
        PhaseSample { wo, weight: self.reflectance(cos), side: Side::Outside }
    }

    /// F(ωi·ωh) D(ωh) G2(ωi, ωo) / (4 cos θi) (the Cook–Torrance BRDF times cos θo).
    #[inline]
    fn eval_single_scattering<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        _rng: &mut impl Rng,
    ) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        let g2 = g2_reflection(slope, wi, wo);
        if g2 == 0.0 {
            return Vec3::ZERO;
        }
        let wh = (wi.as_dvec3() + wo.as_dvec3()).normalize_or_zero();
        let value = (slope.d64_unchecked(wh) * f64::from(g2) / (4.0 * f64::from(wi.z))) as f32;
        self.fresnel(wi.as_dvec3().dot(wh) as f32) * value
    }
}
