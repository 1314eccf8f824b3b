//! Energy-compensated dielectrics: the single-scattering microfacet BSDF (reflection and
//! transmission) scaled so that a non-absorbing interface keeps the energy the single bounce
//! loses (Turquin 2019), from this crate's dielectric albedo tables
//! ([`crate::compensation::DielectricAlbedoTable`]).

use super::conductor::{AlbedoTabulated, Tables, check_tabulated};
use crate::albedo::{DIELECTRIC_TABLE_SIZE, DielectricDirection, node_cell};
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, BsdfValue, Transport, valid_direction};
use crate::bsdf::{MicrofacetBsdf, Technique};
use crate::error::Error;
use crate::material::{Dielectric, Side};
use crate::slope::MicrosurfaceSlope;
use glam::{Vec2, Vec3};

/// The last node index of the direction axis, as a float.
const LAST: f32 = (DIELECTRIC_TABLE_SIZE - 1) as f32;

/// A dielectric microfacet BSDF with Turquin's energy compensation: the exact single-scattering
/// BSDF of [`MicrofacetBsdf`] (height-correlated Smith, dielectric Fresnel, reflection and
/// transmission, [`Technique::SingleScattering`]) scaled by the inverse of its albedo at the
/// view direction,
///
/// f(ωo, ωi) = f_ss(ωo, ωi) / E(μo),   E(μo) = R(μo, η_o) + T(μo, η_o),
///
/// with μo = |cos θo| and η_o the relative index seen from the view's side (η above the
/// surface, 1/η below it): Turquin 2019 (*Practical multiple scattering compensation for
/// microfacet models*, the dielectric case: the tabulated albedo of the whole BSDF, Fresnel
/// included, per side of the interface). The lobe keeps the single-scattering shape and its
/// split between reflection and transmission (the higher orders shift energy towards
/// reflection from inside and towards transmission from outside; Turquin's scaling does not
/// model that), and it is not reciprocal.
///
/// **Energy.** With [`Transport::Importance`] (no η² factor), ∫ f(ωo, ωi) |cos θi| dωi over
/// the sphere is (R + T)(μo)/E(μo) = 1 for every view: the expected sample weight is 1, and the
/// error is that of the tables' interpolation of E relative to E. With [`Transport::Radiance`]
/// (the default) transmitted radiance carries the factor (η_wo/η_wi)² = 1/`eta`² of the
/// sample, so the *flux* is conserved: the mean of weight × `eta`² is 1.
///
/// **Tables.** [`crate::compensation::DielectricAlbedoTable`] of the slope family at α = √(αx αy) (anisotropic
/// surfaces are compensated as the isotropic surface of the same slope area), blended in (α, η)
/// once at construction, the direction axis interpolated linearly at run time (one lookup
/// per call). `pdf` and `sample` are those of single scattering: the density is exact and a
/// sample's weight is the single-scattering weight divided by E(μo), i.e. f·|cos θi|/pdf.
///
/// **Special cases.** Effectively smooth surfaces (largest principal roughness [`MicrosurfaceSlope::alpha_max`](crate::slope::MicrosurfaceSlope::alpha_max) < [`crate::SMOOTH_ALPHA`]) and
/// η = 1 are the Dirac lobes of the single-scattering BSDF, uncompensated (the loss vanishes
/// with α). A view on the horizon (μo = 0) has no lobe. Near η = 1 at grazing views E(μo)
/// approaches 0 (single scattering reflects almost nothing and masks every refraction at the
/// top of the surface), and the factor 1/E grows without bound: where f_ss/E would not be a
/// finite f32 the BSDF answers 0 (and `sample` `None`).
///
/// # Examples
/// ```
/// use microsurface::glam::{Vec2, Vec3};
/// use microsurface::{Bsdf, CompensatedDielectric, Dielectric, Ggx, Transport};
///
/// let glass = CompensatedDielectric::new(Ggx::isotropic(0.5)?, Dielectric::new(1.5)?)?
///     .with_transport(Transport::Importance);
/// let wo = Vec3::new(0.6, 0.0, 0.8);
/// let s = glass.sample(wo, 0.7, Vec2::new(0.4, 0.2)).expect("glass scatters");
/// let (f, pdf) = glass.eval_with_pdf(wo, s.wi);
/// assert!((pdf - s.pdf).abs() <= 1e-6 * pdf);
/// assert!((s.weight - f.f * s.wi.z.abs() / pdf).abs().max_element() <= 1e-4 * s.weight.max_element());
/// // beyond the tables
/// assert!(CompensatedDielectric::new(Ggx::isotropic(0.5)?, Dielectric::new(4.0)?).is_err());
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompensatedDielectric<S> {
    single: MicrofacetBsdf<S, Dielectric>,
    /// The tables' roughness √(αx αy).
    alpha: f32,
    /// E = R + T at the direction nodes x = i/15, for views above (0) and below (1) the surface.
    albedo: [[f32; DIELECTRIC_TABLE_SIZE]; 2],
    /// The tables' direction axis of each side's relative index.
    axis: [DielectricDirection; 2],
}

impl<S: AlbedoTabulated> CompensatedDielectric<S> {
    /// The compensated BSDF of a dielectric interface on the given slopes.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if √(αx αy) > [`MAX_TABULATED_ALPHA`](crate::compensation::MAX_TABULATED_ALPHA) (`"alpha"`) or the
    /// relative index η lies outside [1/[`MAX_TABULATED_ETA`](crate::compensation::MAX_TABULATED_ETA), [`MAX_TABULATED_ETA`](crate::compensation::MAX_TABULATED_ETA)] = [1/3, 3]
    /// (`"eta"`): the tables' range, beyond which there is no albedo to compensate with.
    pub fn new(slope: S, dielectric: Dielectric) -> Result<Self, Error> {
        let alpha = slope.albedo_alpha();
        let eta = dielectric.eta();
        check_tabulated(alpha, Some(eta), Tables::Albedo)?;
        let single = MicrofacetBsdf::new(slope, dielectric)?.with_technique(Technique::SingleScattering);
        let mut albedo = [[1.0; DIELECTRIC_TABLE_SIZE]; 2];
        let mut axis = [DielectricDirection::of(eta), DielectricDirection::of(1.0 / eta)];
        // a Dirac lobe is not compensated (and √(αx αy) may underflow to 0 there)
        if !single.is_specular() {
            for ((side, side_axis), seen) in albedo.iter_mut().zip(&mut axis).zip([eta, 1.0 / eta]) {
                let (r, t, row_axis) =
                    S::DIELECTRIC_ALBEDO.direction_row(alpha, seen).ok_or(Tables::Albedo.eta_error(seen))?;
                *side_axis = row_axis;
                for ((e, r), t) in side.iter_mut().zip(r).zip(t) {
                    *e = r + t;
                }
            }
        }
        Ok(Self { single, alpha, albedo, axis })
    }
}

impl<S: MicrosurfaceSlope> CompensatedDielectric<S> {
    /// The same BSDF with the given transport mode (see the type's documentation for what is
    /// conserved in each).
    #[must_use]
    pub fn with_transport(self, transport: Transport) -> Self {
        Self { single: self.single.with_transport(transport), ..self }
    }

    /// The uncompensated single-scattering BSDF of the same material.
    pub fn single_scattering(&self) -> &MicrofacetBsdf<S, Dielectric> {
        &self.single
    }

    /// The roughness the tables are read at, √(αx αy).
    pub fn table_alpha(&self) -> f32 {
        self.alpha
    }

    /// E(μo) = R + T as this BSDF interpolates it for a view on `side` of the surface
    /// ([`Side::Outside`]: above it, seeing η; [`Side::Inside`]: below it, seeing 1/η), for
    /// μo = |cos θo| ∈ [0, 1]; `None` outside (NaN included).
    pub fn directional_albedo(&self, mu: f32, side: Side) -> Option<f32> {
        (0.0..=1.0).contains(&mu).then(|| self.albedo_at(mu, side))
    }

    /// E at |cos θo| = μ for a view on `side`: linear interpolation on the tables' direction
    /// axis of the side's relative index (see [`crate::compensation::DielectricAlbedoTable`]).
    #[inline(always)]
    fn albedo_at(&self, mu: f32, side: Side) -> f32 {
        let side = match side {
            Side::Outside => 0,
            Side::Inside => 1,
        };
        let x = self.axis[side].coordinate(mu);
        let (i, f) = node_cell(x * LAST, DIELECTRIC_TABLE_SIZE);
        let row = &self.albedo[side];
        row[i] + f * (row[i + 1] - row[i])
    }

    /// Turquin's factor 1/E(μo) for the view `wo` (1 on the horizon, where f_ss = 0).
    #[inline(always)]
    fn factor(&self, wo: Vec3) -> f32 {
        if wo.z == 0.0 || self.single.is_specular() {
            return 1.0;
        }
        1.0 / self.albedo_at(wo.z.abs(), Side::above_or_inside(wo.z))
    }

    /// f·factor, or 0 where it is not a finite f32 (see the special cases).
    #[inline(always)]
    fn scaled(v: BsdfValue, factor: f32) -> BsdfValue {
        let f = v.f * factor;
        BsdfValue { f: if f.is_finite() { f } else { Vec3::ZERO }, exact: v.exact }
    }
}

impl<S: MicrosurfaceSlope> Bsdf for CompensatedDielectric<S> {
    #[inline]
    fn flags(&self) -> BsdfFlags {
        self.single.flags()
    }

    #[inline]
    fn eval_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> BsdfValue {
        if !valid_direction(wo) || !valid_direction(wi) {
            return self.single.eval_keyed(wo, wi, key);
        }
        Self::scaled(self.single.eval_valid(wo, wi, key), self.factor(wo))
    }

    #[inline]
    fn sample_keyed(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample> {
        let s = self.single.sample_keyed(wo, uc, u, key)?;
        if s.flags.specular {
            return Some(s);
        }
        let weight = s.weight * self.factor(wo);
        weight.is_finite().then_some(BsdfSample { weight, ..s })
    }

    #[inline(always)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.single.pdf(wo, wi)
    }

    #[inline]
    fn eval_with_pdf_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> (BsdfValue, f32) {
        let (v, pdf) = self.single.eval_with_pdf_keyed(wo, wi, key);
        if !valid_direction(wo) {
            return (v, pdf);
        }
        (Self::scaled(v, self.factor(wo)), pdf)
    }
}
