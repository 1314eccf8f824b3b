//! One energy-compensated microfacet BSDF for conductors and dielectrics, built per hit: the
//! exact single-scattering lobe plus the energy of the higher orders restored by a
//! [`Compensation`] scheme from the crate's tables.

use super::albedo_tabulated::AlbedoTabulated;
use crate::bsdf::{MicrofacetBsdf, SpecularLimit, Technique, Transport};
use crate::error::Error;
use crate::material::Material;
use crate::slope::MicrosurfaceSlope;

/// How a [`Compensated`] BSDF restores the energy single scattering loses. Every scheme
/// applies to conductors and to dielectrics; each is the same idea for both.
///
/// **The default** is [`Compensation::Walk`] for both materials, the scheme with the lowest
/// measured error against the random walk (`lab --bin compensation -- --quick`: GGX,
/// α, μo ∈ {0.1, 0.5, 1}, 2 × 10⁴ samples per cell, largest standard error of a difference
/// 3.2e-3; glass η ∈ {1.33, 1.5, 2} from both sides):
///
/// | albedo error against the walk, max / RMS | `Walk` | `KullaConty` | `Turquin` |
/// |---|---|---|---|
/// | conductor, F = 1 | 0.0025 / 0.0010 | 0.0030 / 0.0013 | 0.0040 / 0.0020 |
/// | gold, copper, aluminium (per RGB channel) | 0.031 / 0.008 | 0.043 / 0.018 | 0.070 / 0.026 |
/// | glass, R and T of either side | 0.012 / 0.005 | (= `Walk`) | 0.34 / 0.14 |
///
/// For F = 1 `Walk` and `KullaConty` are the same lobe (their figures differ by the samples).
/// For coloured metals `Walk` follows the walk's split of the loss by order (within 0.004 at
/// α = 1, against 0.032–0.043 for `KullaConty`); both miss the grazing-facet Fresnel of the
/// higher orders at small α and grazing views (gold at α = 0.1: 0.031 and 0.032).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Compensation {
    /// The random walk's higher orders, tabulated (the default), added as reciprocal separable
    /// lobes g(μo) g(μi)/(π ḡ) whose albedo is the tabulated energy.
    ///
    /// Conductors: per RGB channel g(μ) = (1 − E(μ)) Σ_k φ_k(μ) F̄ᵏ, the single-scattering
    /// loss split over the orders k = 2 … 6 by the F = 1 walk's fractions φ_k
    /// ([`super::ScatteringOrderTable`]; the orders beyond 6 placed at order 7), each
    /// weighted by F̄ᵏ, F̄ = F_avg (one Fresnel factor per bounce). For F = 1 it is
    /// [`Compensation::KullaConty`].
    ///
    /// Dielectrics: the walk's reflected and transmitted energy of orders ≥ 2, ΔR and ΔT of
    /// each side of the interface ([`super::DielectricWalkTable`]), as one reflection lobe and
    /// one transmission lobe made reciprocal across the interface.
    #[default]
    Walk,
    /// Kulla and Conty 2017 (*Revisiting Physically Based Shading at Imageworks*): additive,
    /// reciprocal separable lobes from the single-scattering loss.
    ///
    /// Conductors: f_ms = F_ms (1 − E(μo)) (1 − E(μi))/(π (1 − E_avg)),
    /// F_ms = F_avg² E_avg/(1 − F_avg (1 − E_avg)) per RGB channel (each further bounce weighted
    /// by F_avg, escaping with E_avg). For F = 1 its albedo is exactly 1 − E(μo).
    ///
    /// Dielectrics: a non-absorbing interface has no Fresnel series to choose: the separable
    /// lobes are those of [`Compensation::Walk`], whose energy is the walk's own.
    KullaConty,
    /// Turquin 2019 (*Practical multiple scattering compensation for microfacet models*): the
    /// single-scattering lobe scaled by the missing energy of the view direction, keeping its
    /// shape and its sampler; not reciprocal.
    ///
    /// Conductors: f_ss (1 + F0 (1 − E(μo))/E(μo)), F0 = F(1) per RGB channel.
    /// Dielectrics: f_ss/E(μo), E = R + T of the single-scattering dielectric tables on the
    /// view's side.
    Turquin,
}

/// The materials a [`Compensated`] BSDF exists for: [`crate::Conductor`] and
/// [`crate::Dielectric`]. Sealed (through [`Material`]).
pub trait CompensatedMaterial: Material + SpecularLimit {
    /// The per-hit state of the material's compensation (a few scalars and references to
    /// tables shared by every instance).
    #[doc(hidden)]
    type Lobes: Copy + core::fmt::Debug + PartialEq + Send + Sync;

    /// The lobes of the single-scattering BSDF `single` (rough or not) of a slope family
    /// with tables.
    #[doc(hidden)]
    fn lobes<S: AlbedoTabulated>(
        single: &MicrofacetBsdf<S, Self>,
        scheme: Compensation,
    ) -> Result<Self::Lobes, Error>;

    /// The lobes for another transport mode.
    #[doc(hidden)]
    #[must_use]
    fn lobes_with_transport(lobes: Self::Lobes, transport: Transport) -> Self::Lobes;
}

/// An energy-compensated microfacet BSDF: the exact single-scattering lobe of
/// [`MicrofacetBsdf`] (height-correlated Smith, [`Technique::SingleScattering`]) plus the
/// energy of the higher orders restored by a [`Compensation`] scheme, for a conductor
/// ([`crate::Conductor`]: a BRDF) or a dielectric ([`crate::Dielectric`]: a BSDF, both sides of
/// the interface). Deterministic: `eval` is exact (of this model), `pdf` is the exact density
/// of `sample`, and a sample's weight is f·|cos θi|/pdf at its direction.
///
/// **Built per hit.** Construction reads shared tables (the shipped albedo tables and what
/// is derived from them once, on first use, per slope family) and computes a few per-hit
/// scalars: no per-instance table, no heap allocation, so that a renderer builds it at
/// every hit from textured parameters, as pbrt-v4's `GetBxDF` (the cost of construction
/// against the calls of a prebuilt BSDF is in `DESIGN.md`, "Speed of the compensated lobes").
/// The type is `Copy` and small: `size_of` is 224 bytes for a GGX conductor, 288 for GGX glass,
/// 240 and 320 on Beckmann slopes (`tests/per_hit.rs`; the single-scattering
/// [`MicrofacetBsdf`] inside takes 128, 40, 144 and 64 of them).
///
/// **Tables.** The tables are read at α = √(αx αy) (an anisotropic surface is compensated as
/// the isotropic surface of the same slope area: an approximation that restores about half of
/// the missing energy, `lab --bin compensation`), for GGX, Beckmann and their elliptical
/// rotations ([`AlbedoTabulated`]), α ≤ [`super::MAX_TABULATED_ALPHA`] and, for a dielectric,
/// η ∈ [1/[`super::MAX_TABULATED_ETA`], [`super::MAX_TABULATED_ETA`]]. The conductor's lobes are
/// detailed in `conductor.rs`'s type documentation ([`Compensated`] of [`crate::Conductor`]),
/// the dielectric's in `dielectric.rs`.
///
/// **Special cases.** Effectively smooth surfaces (largest principal roughness below
/// [`crate::SMOOTH_ALPHA`]) and index-matched dielectrics are the Dirac lobes of the
/// single-scattering BSDF, uncompensated (the energy the single bounce loses vanishes with α).
/// A conductor seen from below the horizon (a backfacing shading normal) is single scattering
/// unchanged.
///
/// # Examples
/// ```
/// use microsurface::glam::{Vec2, Vec3};
/// use microsurface::{Bsdf, Compensated, Compensation, ComplexIor, Conductor, Dielectric, Ggx};
///
/// // per hit, from the textured roughness and index: the default scheme (the walk's orders)
/// let gold = Compensated::new(Ggx::isotropic(0.6)?, Conductor::new(ComplexIor::GOLD))?;
/// let wo = Vec3::new(0.5, 0.0, 0.866);
/// let s = gold.sample(wo, 0.3, Vec2::new(0.6, 0.1)).expect("gold reflects");
/// let (f, pdf) = gold.eval_with_pdf(wo, s.wi);
/// assert!(f.exact && (pdf - s.pdf).abs() <= 1e-6 * pdf);
/// // reciprocal
/// let back = gold.eval(s.wi, wo).f;
/// assert!((back - f.f).abs().max_element() <= 1e-4 * f.f.max_element());
/// // glass with Turquin's scaling
/// let glass = Compensated::with_scheme(Ggx::isotropic(0.3)?, Dielectric::new(1.5)?, Compensation::Turquin)?;
/// assert!(glass.sample(wo, 0.7, Vec2::new(0.4, 0.2)).is_some());
/// // beyond the tables
/// assert!(Compensated::new(Ggx::isotropic(1.5)?, Conductor::perfect()).is_err());
/// assert!(Compensated::new(Ggx::isotropic(0.5)?, Dielectric::new(4.0)?).is_err());
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Compensated<S, M: CompensatedMaterial> {
    pub(super) single: MicrofacetBsdf<S, M>,
    pub(super) lobes: M::Lobes,
    pub(super) scheme: Compensation,
    /// The tables' roughness √(αx αy).
    pub(super) alpha: f32,
}

impl<S: AlbedoTabulated, M: CompensatedMaterial> Compensated<S, M> {
    /// The compensated BSDF of `material` on the given slopes with the default scheme
    /// ([`Compensation::Walk`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if √(αx αy) > [`super::MAX_TABULATED_ALPHA`] (`"alpha"`) or,
    /// for a dielectric, the relative index η lies outside [1/3, 3] (`"eta"`): the tables'
    /// range, beyond which there is no energy to restore from; or if the slopes are rejected
    /// by [`MicrofacetBsdf::new`].
    #[inline]
    pub fn new(slope: S, material: M) -> Result<Self, Error> {
        Self::with_scheme(slope, material, Compensation::default())
    }

    /// The compensated BSDF of `material` on the given slopes with the given scheme.
    ///
    /// # Errors
    /// As [`Self::new`].
    #[inline]
    pub fn with_scheme(slope: S, material: M, scheme: Compensation) -> Result<Self, Error> {
        let alpha = slope.albedo_alpha();
        // the slope's roughnesses are finite and > 0; their product may overflow to ∞ (rejected)
        if alpha > super::MAX_TABULATED_ALPHA {
            return Err(Error::InvalidParameter {
                name: "alpha",
                value: alpha,
                expected: "√(αx αy) at most 1 (MAX_TABULATED_ALPHA), the compensation tables' range",
            });
        }
        let single = MicrofacetBsdf::new(slope, material)?.with_technique(Technique::SingleScattering);
        let lobes = M::lobes(&single, scheme)?;
        Ok(Self { single, lobes, scheme, alpha })
    }
}

impl<S: MicrosurfaceSlope, M: CompensatedMaterial> Compensated<S, M> {
    /// The scheme.
    pub fn scheme(&self) -> Compensation {
        self.scheme
    }

    /// The uncompensated single-scattering BSDF of the same material.
    pub fn single_scattering(&self) -> &MicrofacetBsdf<S, M> {
        &self.single
    }

    /// The roughness the tables are read at, √(αx αy).
    pub fn table_alpha(&self) -> f32 {
        self.alpha
    }

    /// The same BSDF with the given transport mode ([`Transport::Radiance`] by default): a
    /// dielectric's transmissions carry (η_wo/η_wi)² for radiance, 1 for importance (the flux);
    /// a conductor does not transmit.
    #[must_use]
    pub fn with_transport(self, transport: Transport) -> Self {
        Self {
            single: self.single.with_transport(transport),
            lobes: M::lobes_with_transport(self.lobes, transport),
            ..self
        }
    }
}
