//! The smooth limit of a microfacet material: the Dirac lobes of a flat facet, which a
//! [`MicrofacetBsdf`](super::MicrofacetBsdf) uses when it is effectively smooth.

use crate::fresnel::fresnel_dielectric;
use crate::material::{Conductor, Dielectric, Diffuse, Material};
use glam::Vec3;

/// One event of a perfectly smooth interface seen from ωo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpecularEvent {
    /// The direction light arrives from: the mirror direction (−ωo.x, −ωo.y, ωo.z), or the
    /// refracted direction.
    pub wi: Vec3,
    /// The Dirac lobe's per-channel weight divided by `probability` (before any transport
    /// factor (η_wo/η_wi)²): the Fresnel reflectance of a conductor, 1 for a dielectric whose
    /// Fresnel term chooses the event.
    pub weight: Vec3,
    /// The probability with which this event was chosen, in (0, 1].
    pub probability: f32,
}

/// The limit α → 0 of a material (and, for a dielectric of η = 1, its exact form at every
/// roughness): the Dirac lobes of a flat facet.
///
/// Implemented by the crate's materials; a user-defined [`Material`] without a specular
/// limit (like [`Diffuse`], which tends to a Lambertian plane) implements it with the
/// defaults.
pub trait SpecularLimit: Material {
    /// Whether the material's limit α → 0 is a Dirac lobe ([`SpecularLimit::sample_specular`]
    /// samples it); false for facets that stay rough in their own right (diffuse facets).
    const SMOOTH_IS_SPECULAR: bool = false;

    /// Whether the material is a Dirac lobe at every roughness (a dielectric with η = 1: every
    /// refraction through any microfacet leaves the direction unchanged and the Fresnel
    /// reflectance is 0, so light passes straight through).
    #[inline]
    fn always_specular(&self) -> bool {
        false
    }

    /// Samples the flat facet's event for ωo with the uniform `uc` ∈ [0, 1); `None` if the
    /// material has no specular limit or nothing leaves (a conductor seen from below).
    #[inline]
    fn sample_specular(&self, wo: Vec3, uc: f32) -> Option<SpecularEvent> {
        let _ = (wo, uc);
        None
    }
}

/// The mirror direction of ωo about +z.
#[inline(always)]
fn mirror(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}

impl SpecularLimit for Conductor {
    const SMOOTH_IS_SPECULAR: bool = true;

    #[inline]
    fn sample_specular(&self, wo: Vec3, _uc: f32) -> Option<SpecularEvent> {
        // a backfacing view sees no facet of a flat mirror
        (wo.z > 0.0).then(|| SpecularEvent { wi: mirror(wo), weight: self.fresnel(wo.z), probability: 1.0 })
    }
}

impl SpecularLimit for Diffuse {}

impl SpecularLimit for Dielectric {
    const SMOOTH_IS_SPECULAR: bool = true;

    #[inline]
    fn always_specular(&self) -> bool {
        self.eta() == 1.0
    }

    /// Reflection with probability F, refraction with probability 1 − F (Snell's law about
    /// +z, total internal reflection when F = 1).
    fn sample_specular(&self, wo: Vec3, uc: f32) -> Option<SpecularEvent> {
        if wo.z == 0.0 {
            return None;
        }
        // η_t/η_i for light crossing from wo's side to the other
        let eta = if wo.z > 0.0 { self.eta() } else { 1.0 / self.eta() };
        let cos_o = wo.z.abs();
        let f = fresnel_dielectric(cos_o, eta);
        if uc < f {
            return Some(SpecularEvent { wi: mirror(wo), weight: Vec3::ONE, probability: f });
        }
        // sin²θt = sin²θo/η², computed as (1 − cos²θo)/η² in f64
        let (c, e) = (f64::from(cos_o), f64::from(eta));
        let sin2_t = (1.0 - c * c).max(0.0) / (e * e);
        let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
        let t = -wo.as_dvec3() / e;
        let wi = glam::DVec3::new(t.x, t.y, -f64::from(wo.z.signum()) * cos_t).normalize().as_vec3();
        Some(SpecularEvent { wi, weight: Vec3::ONE, probability: 1.0 - f })
    }
}
