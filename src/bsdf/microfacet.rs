//! The renderer-facing BSDF of a microsurface, with a choice of technique.

use super::seed::{Hasher, PrimedPcg, PrimedRng};
use super::sidedness::{Facing, Sidedness, mirror_z};
use super::specular::SpecularLimit;
use super::walk_density::walk_exit_density;
use super::{
    Bsdf, BsdfFlags, BsdfSample, BsdfValue, SampleFlags, Transport, renormalized, unit_directions, unit_view,
};
use crate::error::Error;
use crate::height::UniformHeight;
#[cfg(feature = "invariance")]
use crate::invariance::Invariance;
use crate::material::{Material, Side};
use crate::microsurface::{Microsurface, ScatteringOrder, WalkSample};
#[cfg(feature = "position-free")]
use crate::path::Shadowing;
#[cfg(feature = "position-free")]
use crate::position_free::{Estimator, PositionFree};
use crate::single_scattering::SingleScattering;
use crate::slope::MicrosurfaceSlope;
use glam::{Vec2, Vec3};
use rand::Rng;

/// Orders tabulated separately by [`EnergyByOrder`].
const TABULATED_ORDERS: usize = 8;

/// Below this roughness (max(αx, αy) < 10⁻³, pbrt-v4's `EffectivelySmooth` threshold) a
/// conductor or dielectric [`MicrofacetBsdf`] is treated as perfectly smooth: a Dirac lobe
/// (the mirror and refraction directions with Fresnel weights), `eval` and `pdf` are 0 and
/// `flags().specular` is set. The lobes of α < 10⁻³ are narrower than 0.06° and the energy
/// of the higher orders vanishes with α, so the Dirac lobe is the limit every technique
/// converges to; a density that narrow is useless to an integrator (NEE and MIS never hit
/// it). Diffuse facets have no specular limit and are unaffected. An opaque surface seen from
/// below its shading hemisphere (a normal map) sees only the tails of its distribution, whose
/// lobe does not shrink to a direction as α → 0: `sample` keeps drawing those views from the
/// rough technique at every roughness (unbiased weights), but flags the samples `specular`
/// (with pdf 1, the probability of the event) and `eval` and `pdf` stay 0 there, so that the
/// BSDF is a Dirac BSDF on the whole sphere, as its flags say: an integrator skips light
/// sampling on it and finds the light of those views through `sample` alone.
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// The largest roughness [`MicrofacetBsdf::new`] accepts: max(αx, αy) ≤ 10.
///
/// A walk's length grows linearly with α: for a perfect GGX conductor seen at normal
/// incidence the mean number of bounces was measured at 2.3 (α = 1), 9.2 (α = 4), 26 (α = 10)
/// and 305 (α = 100), i.e. about 2.7α, and a sample's cost with it (≈ 2.6 µs at α = 10 on the
/// development machine). From α ≈ 300 on walks reach the bounce cap [`crate::research::MAX_BOUNCES`]
/// and lose their energy (at α = 10⁶ every walk does: 0.33 ms per sample and no light).
/// Roughnesses above 10 describe no real surface, so the renderer layer rejects them rather
/// than let a scene's cost explode; the research layer ([`Microsurface`], [`PositionFree`])
/// still accepts them.
pub const MAX_WALK_ALPHA: f32 = 10.0;

/// How a [`MicrofacetBsdf`] evaluates and samples its microsurface: the choice that lets a
/// renderer pay only for what its scene needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Technique {
    /// The classic single-scattering microfacet BSDF (Cook–Torrance / Walter) with
    /// height-correlated Smith masking-shadowing: on conductors and dielectrics, exact eval,
    /// pdf and sample (the caller's uniforms drive the visible-normal sample and the Fresnel
    /// event directly); loses the energy of higher orders. On diffuse facets it is
    /// **stochastic**: their single-scattering BSDF (a/π)∫⟨ωo, ωm⟩⁺ D_ωi(ωm) G2/G1 dωm has no
    /// closed form and `eval` returns an unbiased one-sample estimate (one visible normal drawn
    /// from a hash of the arguments and the key; `BsdfValue::exact` is false, and so is the
    /// samples' `exact_pdf`: the density is the documented approximation of
    /// [`Diffuse`](crate::Diffuse)'s phase function). A fixed quadrature over the visible
    /// normals is no substitute at a comparable cost: ⟨ωo, ωm⟩⁺ has a kink across the visible
    /// normals, and a 4 × 4 midpoint rule in the sampler's uniforms (16 visible normals, 16×
    /// the estimate's) is off by up to 63 % of the value for GGX α = 0.5 and 100 % at α = 1
    /// (8 × 8: 2.4 % and 41 %). Valid for backfacing view directions (normal mapping): the
    /// view's masking is the full-spherical 1/|1 + Λ| and the VNDF is sampled exactly on the
    /// whole sphere (Tokuyoshi), so estimates stay unbiased. A sample's weight equals
    /// f·|cos θi|/pdf at its direction to a few f32 ulps (1e-5 with a Fresnel term or GGX's f32
    /// conductor density, see [`crate::research::SingleScattering::pdf`]) for every
    /// roughness; samples whose pdf or f would be subnormal are not returned (at most
    /// 4π·`f32::MIN_POSITIVE` of probability). See [`crate::research::SingleScattering::sample`] for the f32
    /// resolution limit of backfacing Beckmann views below α ≈ 1e-3.
    SingleScattering,
    /// The height-tracing random walk of Heitz et al. 2016: stochastic eval, exact sample
    /// weights, approximate pdf for MIS weights only: on conductors of GGX and Beckmann slopes
    /// (α within the albedo tables) seen and lit from above, the F = 1 walk's exit density
    /// (the exact single-scattering part plus a Kulla–Conty lobe of the lost energy, from the
    /// shared albedo tables); elsewhere 0.8 × the single-scattering density + 0.2 × a cosine
    /// lobe. See `DESIGN.md`, "The MIS density of the stochastic techniques". Valid for backfacing views of opaque materials (normal
    /// mapping): the walk starts with the full-spherical first intersection
    /// (`Microsurface::eval_from_below`, DESIGN.md), and F = 1 conserves energy there, except
    /// for smooth Beckmann surfaces seen from well below (|cot θo|/α ≳ 9.6), where the walk's
    /// f32 Λ underflows and it returns nothing (see `Microsurface::eval_from_below`).
    #[default]
    RandomWalk,
    /// The position-free estimators of Wang et al. 2022: stochastic eval, exact sample
    /// weights, approximate pdf (that of [`Technique::RandomWalk`]). Valid for backfacing views of opaque materials, whose first
    /// vertex is a vertex reached from below (DESIGN.md); for Beckmann seen from so far below
    /// that Λ underflows f64 (|cot θo|/α ≳ 26.6) `sample` returns nothing and eval keeps only
    /// the first order.
    #[cfg(feature = "position-free")]
    PositionFree {
        /// PT or BDPT.
        estimator: Estimator,
        /// Height-correlated or uncorrelated shadowing.
        shadowing: Shadowing,
    },
    /// The invariance-principle estimator of Cui et al. 2023 ([`Invariance`]): the random
    /// walk's BSDF (the same model as [`Technique::RandomWalk`]) with the heights integrated
    /// out, stochastic eval with less variance, exact sample weights, approximate pdf (the
    /// position-free model's, as for the walk). Opaque materials only (conductors, diffuse
    /// facets): [`MicrofacetBsdf::with_technique`] refuses it for a dielectric. Valid for
    /// backfacing views, as the walk.
    #[cfg(feature = "invariance")]
    Invariance,
}

/// The share of a BSDF's albedo carried by each scattering order, estimated from sampled
/// walks (the per-order energy tables of Heitz et al. 2016 and Wang et al. 2022, Fig. 6).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnergyByOrder {
    /// Energy (mean sample weight, averaged over RGB) of orders 1 to 8.
    pub per_order: [f64; TABULATED_ORDERS],
    /// Energy of orders above 8.
    pub beyond: f64,
    /// The number of walks.
    pub walks: usize,
}

impl EnergyByOrder {
    /// The total albedo.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.per_order.iter().sum::<f64>() + self.beyond
    }

    /// The energy a truncation of the BSDF after `max_order` bounces leaves out.
    #[must_use]
    pub fn left_out(&self, max_order: u32) -> f64 {
        let kept: f64 = self.per_order.iter().take(max_order as usize).sum();
        self.total() - kept
    }
}

/// The renderer-facing BSDF of a microsurface with slope distribution `S` and material `M`,
/// evaluated with a chosen [`Technique`] and truncated to a chosen [`ScatteringOrder`].
///
/// The microsurface BSDF does not depend on the height distribution (Heitz et al. 2016,
/// §3.2: the walk is invariant under a monotonic change of heights), so there is none to
/// choose here; the height distribution matters only to the geometry queries of the research
/// layer ([`crate::research::MicrosurfaceGeometry`]).
///
/// Orientation: the research-layer models are evaluated and sampled *from the viewer* — the
/// walk enters along the renderer's `wo` and leaves along `wi` (the adjoint orientation), with
/// the (η_wo/η_wi)² factor of radiance transport for dielectrics. For the non-reciprocal
/// height-correlated position-free model this is the model with the roles of the two
/// directions exchanged, which keeps `eval`, `sample` and `pdf` consistent with one another.
///
/// Randomness: every method is a pure function of its arguments, the BSDF's seed
/// ([`MicrofacetBsdf::with_seed`]) and the caller's key (the `_keyed` methods of [`Bsdf`]):
/// a stochastic `eval` seeds a PCG generator with a hash of the bits of (seed, key, wo, wi);
/// `sample` gives the caller's uniforms to the first bounce (u to the visible normal, uc to
/// the next decision: the Fresnel event of a dielectric, the exit test of a conductor) and
/// draws the rest from a generator seeded with a hash of (seed, key, wo, uc, u).
///
/// # Examples
///
/// ```
/// use microsurface::glam::{Vec2, Vec3};
/// use microsurface::{Bsdf, ComplexIor, Conductor, Ggx, MicrofacetBsdf, Technique};
///
/// // gold with multiple scattering (the random walk, all orders)
/// let gold = MicrofacetBsdf::new(Ggx::isotropic(0.5)?, Conductor::new(ComplexIor::GOLD))?;
/// let wo = Vec3::new(0.5, 0.0, 0.866); // towards the viewer, shading frame
/// let s = gold.sample(wo, 0.3, Vec2::new(0.6, 0.1)).expect("gold reflects");
/// assert!(s.flags.reflection && !s.flags.specular && s.eta == 1.0);
/// let (f, pdf) = gold.eval_with_pdf(wo, s.wi);
/// assert!(f.f.is_finite() && pdf > 0.0);
/// // the same BSDF for one pixel of a renderer that decorrelates its pixels
/// let f_pixel = gold.eval_keyed(wo, s.wi, 1234).f;
/// assert!(f_pixel.is_finite());
/// // single scattering is exact and cheaper, and loses the higher orders
/// let single = gold.with_technique(Technique::SingleScattering);
/// assert!(single.eval(wo, s.wi).exact);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MicrofacetBsdf<S, M> {
    surface: Microsurface<UniformHeight, S, M>,
    technique: Technique,
    order: ScatteringOrder,
    transport: Transport,
    seed: u64,
    specular: bool,
    /// What views from below the shading plane give (opaque materials).
    sidedness: Sidedness,
    /// Mirror facets ([`Material::MIRROR_FACETS`]) with single scattering and no Dirac limit:
    /// the sample of a view from above is the exact reflection off a visible normal drawn
    /// from the caller's uniforms (the one flag the trait's fast path tests).
    exact_mirror: bool,
}

impl<S: MicrosurfaceSlope, M: Material + SpecularLimit> MicrofacetBsdf<S, M> {
    /// A BSDF with the random-walk technique (all orders of multiple scattering), radiance
    /// transport and seed 0. Effectively smooth surfaces (the largest principal roughness
    /// [`MicrosurfaceSlope::alpha_max`] < [`SMOOTH_ALPHA`], whatever the frame's rotation) of
    /// conductors and dielectrics, and dielectrics of η = 1 at any roughness, are Dirac lobes.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`"alpha"`) if [`MicrosurfaceSlope::alpha_max`] >
    /// [`MAX_WALK_ALPHA`], where walks stop being bounded in time.
    pub fn new(slope: S, material: M) -> Result<Self, Error> {
        let alpha = slope.alpha_max();
        // a slope's roughness is finite and > 0 (its constructor checks it)
        if alpha > MAX_WALK_ALPHA {
            return Err(Error::InvalidParameter {
                name: "alpha",
                value: alpha,
                expected: "at most 10 (MAX_WALK_ALPHA)",
            });
        }
        let specular = material.always_specular() || (M::SMOOTH_IS_SPECULAR && alpha < SMOOTH_ALPHA);
        Ok(Self {
            surface: Microsurface::new(UniformHeight, slope, material),
            technique: Technique::default(),
            order: ScatteringOrder::All,
            transport: Transport::default(),
            seed: 0,
            specular,
            sidedness: Sidedness::default(),
            exact_mirror: false,
        }
        .with_derived())
    }

    /// The BSDF with its derived flag `exact_mirror` recomputed (after a change of technique
    /// or of the Dirac limit).
    #[inline]
    fn with_derived(self) -> Self {
        let exact_mirror =
            M::MIRROR_FACETS && self.technique == Technique::SingleScattering && !self.specular;
        Self { exact_mirror, ..self }
    }

    /// The same BSDF evaluated as a rough microfacet lobe however smooth it is: the Dirac limit
    /// below [`SMOOTH_ALPHA`] is not applied (a dielectric of η = 1, which has no rough lobe,
    /// stays a Dirac lobe). For references and tests below α = 10⁻³, where the lobe is valid
    /// but too narrow for an integrator to use.
    #[must_use]
    pub fn without_smooth_limit(self) -> Self {
        let specular = self.surface.material().always_specular();
        Self { specular, ..self }.with_derived()
    }

    /// The same BSDF evaluated with another technique.
    ///
    /// Invalid input ([policy](crate#invalid-input)): [`Technique::Invariance`] for a material
    /// that transmits (a dielectric, which that estimator does not cover) is a contract
    /// violation: a debug assertion in debug builds, the BSDF unchanged in release builds.
    pub fn with_technique(self, technique: Technique) -> Self {
        #[cfg(feature = "invariance")]
        require!(!(M::TRANSMITS && technique == Technique::Invariance), self; technique);
        Self { technique, ..self }.with_derived()
    }

    /// The same BSDF truncated to the given orders (ignored by single scattering).
    pub fn with_order(self, order: ScatteringOrder) -> Self {
        Self { order, ..self }
    }

    /// The same BSDF for another transport mode.
    pub fn with_transport(self, transport: Transport) -> Self {
        Self { transport, ..self }
    }

    /// The same BSDF with another seed for the private generators of its stochastic
    /// techniques (pbrt's `--seed`): two BSDFs that differ only by their seed give
    /// independent estimates. Deterministic techniques ignore it.
    pub fn with_seed(self, seed: u64) -> Self {
        Self { seed, ..self }
    }

    /// The same BSDF with another answer for views from below the shading plane (see
    /// [`Sidedness`]; the default is [`Sidedness::BackfacingLobe`]). Ignored by dielectrics,
    /// whose views from below are views from inside.
    #[must_use]
    pub fn with_sidedness(self, sidedness: Sidedness) -> Self {
        Self { sidedness, ..self }
    }

    /// What views from below the shading plane give (for opaque materials).
    pub fn sidedness(&self) -> Sidedness {
        self.sidedness
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The underlying microsurface (uniform heights: see the type's documentation).
    pub fn surface(&self) -> &Microsurface<UniformHeight, S, M> {
        &self.surface
    }

    /// The technique.
    pub fn technique(&self) -> Technique {
        self.technique
    }

    /// Whether the BSDF is a Dirac lobe (effectively smooth, or an index-matched dielectric).
    /// An effectively smooth opaque BSDF seen from below its shading hemisphere (a normal map)
    /// samples its rough lobe, which does not shrink to a direction as α → 0, and flags those
    /// samples specular (see [`SMOOTH_ALPHA`]).
    pub fn is_specular(&self) -> bool {
        self.specular
    }

    /// The position-free model with the given shadowing over the same slope and material.
    #[cfg(feature = "position-free")]
    #[inline(always)]
    fn position_free(&self, shadowing: Shadowing) -> PositionFree<S, M> {
        PositionFree::new(*self.surface.slope(), *self.surface.material(), shadowing)
    }

    /// The invariance-principle estimator over the same slope and material, `None` for a
    /// material that transmits (which `with_technique` keeps from choosing it).
    #[cfg(feature = "invariance")]
    #[inline(always)]
    fn invariance(&self) -> Option<Invariance<S, M>> {
        Invariance::new(*self.surface.slope(), *self.surface.material()).ok()
    }

    /// The single-scattering BSDF over the same slope and material.
    #[inline(always)]
    fn single(&self) -> SingleScattering<S, M> {
        SingleScattering::new(*self.surface.slope(), *self.surface.material())
    }

    /// (η_wo/η_wi)² for radiance transport across a dielectric, 1 otherwise.
    #[inline(always)]
    pub(super) fn transport_scale(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self.transport {
            // the research layer's relative_eta_sq(light from, light to): light goes wi → wo
            Transport::Radiance => self
                .surface
                .material()
                .relative_eta_sq(Side::above_or_inside(wi.z), Side::above_or_inside(wo.z)),
            Transport::Importance => 1.0,
        }
    }

    /// η_wi/η_wo: the relative index of a transmission from wo's side to wi's side.
    #[inline(always)]
    pub(super) fn relative_eta(&self, wo: Vec3, wi: Vec3) -> f32 {
        if (wi.z > 0.0) == (wo.z > 0.0) {
            1.0
        } else {
            // relative_eta_sq(a, b) = (η_b/η_a)²
            self.surface
                .material()
                .relative_eta_sq(Side::above_or_inside(wo.z), Side::above_or_inside(wi.z))
                .sqrt()
        }
    }

    /// Whether the Dirac lobe's sample answers for the view `wo` of an effectively smooth
    /// BSDF: every view of a dielectric, the views from above of an opaque one. Seen from below
    /// the shading hemisphere (a normal map) an opaque surface's visible facets are the tails
    /// of the distribution, whose lobe does not shrink to a direction as α → 0 (GGX gold at
    /// θo = 100°: walk albedo 0.942 at α = 1.01e-3): the rough technique samples it at every
    /// roughness, flagged specular (see [`SMOOTH_ALPHA`]).
    #[inline(always)]
    fn dirac(&self, wo: Vec3) -> bool {
        self.specular && (M::TRANSMITS || wo.z > 0.0)
    }

    /// How the view `wo` is answered: dielectrics as given, opaque materials by their
    /// [`Sidedness`].
    #[inline(always)]
    fn facing(&self, wo: Vec3) -> Facing {
        if M::TRANSMITS { Facing::AsGiven } else { self.sidedness.facing(wo) }
    }

    /// Whether `eval` is exact (not a stochastic estimate): a Dirac BSDF's 0, single
    /// scattering of conductors and dielectrics.
    #[inline(always)]
    fn exact_eval(&self) -> bool {
        self.specular || (self.technique == Technique::SingleScattering && M::EXACT_PHASE_PDF)
    }

    /// The energy per scattering order for the view direction `wo`, from `walks` sampled
    /// walks of this BSDF's technique (single scattering uses the random walk): what a
    /// truncation to n orders would leave out is [`EnergyByOrder::left_out`]. The energies are
    /// albedos (importance transport): the radiance factor (η_wo/η_wi)² of a dielectric is not
    /// applied. An analysis tool, not a renderer call: it takes a generator.
    pub fn energy_by_order(&self, wo: Vec3, walks: usize, rng: &mut impl Rng) -> EnergyByOrder {
        let mut table = EnergyByOrder { walks, ..EnergyByOrder::default() };
        for _ in 0..walks {
            // the walk enters along the view direction
            let sample = match self.technique {
                #[cfg(feature = "position-free")]
                Technique::PositionFree { shadowing, .. } => self.position_free(shadowing).sample(wo, rng),
                _ => self.surface.sample(wo, rng),
            };
            if let Some(WalkSample { weight, bounces, .. }) = sample {
                let w = f64::from(weight.element_sum()) / (3.0 * walks as f64);
                match table.per_order.get_mut(bounces as usize - 1) {
                    Some(slot) => *slot += w,
                    None => table.beyond += w,
                }
            }
        }
        table
    }

    /// f·|cos| of the research layer for light entering along `walk_in` and leaving along
    /// `walk_out` (its `eval(wi, wo)` = f·|cos θo|): called with the renderer's (wo, wi).
    #[inline(always)]
    fn research_f_cos_out(&self, walk_in: Vec3, walk_out: Vec3, rng: &mut impl Rng) -> Vec3 {
        match self.technique {
            Technique::SingleScattering => self.single().eval_unchecked(walk_in, walk_out, rng),
            Technique::RandomWalk => self.surface.eval(walk_in, walk_out, self.order, rng),
            #[cfg(feature = "position-free")]
            Technique::PositionFree { estimator, shadowing } => {
                self.position_free(shadowing).eval(walk_in, walk_out, estimator, self.order, rng)
            }
            #[cfg(feature = "invariance")]
            Technique::Invariance => match self.invariance() {
                Some(invariance) => invariance.eval(walk_in, walk_out, self.order, rng),
                None => self.surface.eval(walk_in, walk_out, self.order, rng),
            },
        }
    }

    /// The research layer's density of the exit direction `walk_out` of a walk entering
    /// along `walk_in` (exact for single scattering, approximate otherwise).
    #[inline(always)]
    fn research_pdf_out(&self, walk_in: Vec3, walk_out: Vec3) -> f32 {
        match self.technique {
            Technique::SingleScattering => self.single().pdf_unchecked(walk_in, walk_out),
            // a conductor seen and lit from above: the F = 1 walk's exit density (walk_density.rs)
            _ if M::MIRROR_FACETS && walk_in.z > 0.0 && walk_out.z > 0.0 => {
                walk_exit_density(self.surface.slope(), walk_in, walk_out)
                    .unwrap_or_else(|| self.single().mis_pdf_unchecked(walk_in, walk_out))
            }
            _ => self.single().mis_pdf_unchecked(walk_in, walk_out),
        }
    }

    /// f for valid, non-horizontal directions of a non-specular BSDF: the research layer's
    /// f·|cos| of the walk entering along wo and leaving along wi, divided by |cos θi|, with
    /// the transport factor; 0 if not finite.
    #[inline(always)]
    fn f_checked(&self, wo: Vec3, wi: Vec3, key: u64) -> Vec3 {
        let (walk_in, walk_out) = (wo, wi);
        let seed = self.seed;
        let hash = || Hasher::directions(seed, key, wo, wi);
        let f = if self.technique == Technique::SingleScattering {
            // deterministic except for diffuse facets: the generator (and its hash) only on use
            let f_cos_wi = self.research_f_cos_out(walk_in, walk_out, &mut PrimedRng::new(&[], hash));
            f_cos_wi * (self.transport_scale(wo, wi) / wi.z.abs())
        } else {
            // stochastic: the seeded generator itself, without the primed generator's
            // bookkeeping on each of the walk's draws; the factor from f·|cos θi| to f ahead
            // of the estimate, so that its division runs alongside it (glass walk eval 134 →
            // 122 ns; single scattering's eval lost 2 % that way, so it keeps the factor after)
            let scale = self.transport_scale(wo, wi) / wi.z.abs();
            self.research_f_cos_out(walk_in, walk_out, &mut hash().generator()) * scale
        };
        if f.is_finite() { f } else { Vec3::ZERO }
    }

    /// The sample of direction `wi` with the research layer's finite weight and density `pdf`
    /// (exact or not: `exact_pdf`): the transport factor applied, and `None` unless the density
    /// and the BSDF value f = weight·pdf/|cos θi| the sample implies are normal f32 numbers: a
    /// subnormal one has lost its precision, and eval could not reproduce
    /// weight = f·|cos θi|/pdf (deep tails: Beckmann dielectric α = 1 at cos θo = 1e-3 gave
    /// f = 2e-45, 33 % off). Dropping such samples loses at most 4π·f32::MIN_POSITIVE of
    /// probability and π·f32::MIN_POSITIVE of energy.
    #[inline(always)]
    fn finish_sample(
        &self,
        wo: Vec3,
        wi: Vec3,
        weight: Vec3,
        pdf: f32,
        exact_pdf: bool,
    ) -> Option<BsdfSample> {
        self.finish_sample_if(true, wo, wi, weight, pdf, exact_pdf)
    }

    /// [`Self::finish_sample`] if `usable` (the caller's own checks, folded into the same
    /// single test).
    #[inline(always)]
    fn finish_sample_if(
        &self,
        usable: bool,
        wo: Vec3,
        wi: Vec3,
        weight: Vec3,
        pdf: f32,
        exact_pdf: bool,
    ) -> Option<BsdfSample> {
        let weight = weight * self.transport_scale(wo, wi);
        let w_max = weight.max_element();
        // f = weight·pdf/|cos θi| ≥ f32::MIN_POSITIVE without the division: both products are
        // exact in f64 (of two f32s, and of a power of two and an f32). NaN fails every
        // comparison, and so does wi.z = 0 (where f would be ∞ or NaN); f cannot overflow f64
        // (at most f32::MAX²/2⁻¹⁴⁹)
        let usable = usable
            & (f32::MIN_POSITIVE..=f32::MAX).contains(&pdf)
            & (f64::from(w_max) * f64::from(pdf) >= f64::from(f32::MIN_POSITIVE) * f64::from(wi.z.abs()))
            & (wi.z != 0.0)
            & (w_max <= f32::MAX);
        if !usable {
            return None;
        }
        // light never crosses an opaque surface: under a normal map wo and wi may lie on
        // opposite sides of the shading plane, and that is still a reflection
        let reflection = !M::TRANSMITS || (wi.z > 0.0) == (wo.z > 0.0);
        let flags = SampleFlags { reflection, transmission: !reflection, specular: false, exact_pdf };
        Some(BsdfSample { wi, weight, pdf, eta: self.relative_eta(wo, wi), flags })
    }

    /// The sample of an exact single-scattering reflection above the horizon (`wi.z > 0`, a
    /// finite weight) if its density and the BSDF value it implies are normal f32 numbers (see
    /// `sample_keyed`).
    #[inline(always)]
    fn exact_reflection(&self, wo: Vec3, wi: Vec3, weight: Vec3, pdf: f32) -> Option<BsdfSample> {
        // f = weight·pdf/cos θi ≥ f32::MIN_POSITIVE without the division (both products are
        // exact in f64)
        let f_times_cos = f64::from(weight.max_element()) * f64::from(pdf);
        if !((f32::MIN_POSITIVE..=f32::MAX).contains(&pdf)
            && f_times_cos >= f64::from(f32::MIN_POSITIVE) * f64::from(wi.z))
        {
            return None;
        }
        let flags = SampleFlags { reflection: true, transmission: false, specular: false, exact_pdf: true };
        let weight = weight * self.transport_scale(wo, wi);
        Some(BsdfSample { wi, weight, pdf, eta: 1.0, flags })
    }

    /// The Dirac lobe's sample.
    #[inline]
    fn sample_specular(&self, wo: Vec3, uc: f32) -> Option<BsdfSample> {
        let e = self.surface.material().sample_specular(wo, uc)?;
        let weight = e.weight * self.transport_scale(wo, e.wi);
        let reflection = (e.wi.z > 0.0) == (wo.z > 0.0);
        let flags = SampleFlags { reflection, transmission: !reflection, specular: true, exact_pdf: true };
        let eta = self.relative_eta(wo, e.wi);
        (weight.is_finite() && e.probability > 0.0).then_some(BsdfSample {
            wi: e.wi,
            weight,
            pdf: e.probability,
            eta,
            flags,
        })
    }
    /// [`Bsdf::eval_keyed`] for directions the caller has validated (`unit_directions!`, and
    /// renormalized here if they drifted): the compensated lobes validate once for both their
    /// own term and this one.
    #[inline(always)]
    pub(crate) fn eval_valid(&self, wo: Vec3, wi: Vec3, key: u64) -> BsdfValue {
        self.eval_unit(renormalized(wo), renormalized(wi), key)
    }

    /// [`Bsdf::eval_keyed`] for unit directions.
    #[inline(always)]
    fn eval_unit(&self, wo: Vec3, wi: Vec3, key: u64) -> BsdfValue {
        let exact = self.exact_eval();
        let (wo, wi) = match self.facing(wo) {
            Facing::AsGiven => (wo, wi),
            Facing::Mirrored => (mirror_z(wo), mirror_z(wi)),
            Facing::Nothing => return BsdfValue { f: Vec3::ZERO, exact },
        };
        // a Dirac BSDF has no density on the whole sphere (see `SMOOTH_ALPHA`)
        if wi.z == 0.0 || self.specular {
            return BsdfValue { f: Vec3::ZERO, exact };
        }
        BsdfValue { f: self.f_checked(wo, wi, key), exact }
    }

    /// [`Bsdf::sample_keyed`] for valid arguments, except the exact mirror reflection.
    #[inline(never)]
    fn sample_general_outlined(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample> {
        self.sample_general(wo, uc, u, key)
    }

    /// [`Bsdf::sample_keyed`] for valid arguments (see `sample_general_outlined`): the view
    /// answered by its [`Sidedness`].
    #[inline(always)]
    fn sample_general(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample> {
        match self.facing(wo) {
            Facing::AsGiven => self.sample_facing(wo, uc, u, key),
            Facing::Mirrored => {
                let s = self.sample_facing(mirror_z(wo), uc, u, key)?;
                Some(BsdfSample { wi: mirror_z(s.wi), ..s })
            }
            Facing::Nothing => None,
        }
    }

    /// [`Bsdf::sample_keyed`] for valid arguments and a view the lobe answers as it is.
    #[inline(always)]
    fn sample_facing(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample> {
        if self.specular {
            if self.dirac(wo) {
                return self.sample_specular(wo, uc);
            }
            // a smooth opaque surface seen from below (a normal map): the rough lobe's sample,
            // flagged specular with the probability 1 of the event (see `SMOOTH_ALPHA`)
            let s = self.sample_rough(wo, uc, u, key)?;
            let flags = SampleFlags { specular: true, exact_pdf: true, ..s.flags };
            return Some(BsdfSample { pdf: 1.0, flags, ..s });
        }
        self.sample_rough(wo, uc, u, key)
    }

    /// The rough technique's sample for valid arguments.
    #[inline(always)]
    fn sample_rough(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample> {
        // (the exact mirror reflection of a view from above was handled by `sample_keyed`)
        let seed = self.seed;
        let hash = || Hasher::direction_uniforms(seed, key, wo, uc, u);
        let uniforms = [u.x, u.y, uc];
        let walk_in = wo;
        let s = match self.technique {
            Technique::SingleScattering => {
                // at most the phase function's uniforms: the private generator (and its hash)
                // is built only if a material draws more than the caller gave. The research
                // sample's weight is finite and its direction unit (`SingleScattering::sample`)
                let mut rng = PrimedRng::new(&uniforms, hash);
                let s = self.single().sample_unchecked(walk_in, &mut rng)?;
                return self.finish_sample(wo, s.wo, s.weight, s.pdf, M::EXACT_PHASE_PDF);
            }
            Technique::RandomWalk => {
                // the walk draws the height of its first intersection first: from the private
                // generator, so that the caller's uniforms drive the first visible normal
                let mut rng = PrimedPcg::after_one_private(&uniforms, hash());
                self.surface.sample(walk_in, &mut rng)
            }
            #[cfg(feature = "position-free")]
            Technique::PositionFree { shadowing, .. } => {
                // the estimators draw beyond the caller's uniforms from the first bounce on
                let mut rng = PrimedPcg::new(&uniforms, hash());
                self.position_free(shadowing).sample(walk_in, &mut rng)
            }
            #[cfg(feature = "invariance")]
            Technique::Invariance => {
                // the first visible normal from (u.x, u.y), the first exit test from uc
                let mut rng = PrimedPcg::new(&uniforms, hash());
                match self.invariance() {
                    Some(invariance) => invariance.sample(walk_in, &mut rng),
                    None => self.surface.sample(walk_in, &mut rng),
                }
            }
        };
        let s = s?;
        let (walk_out, weight) = (s.wo, s.weight);
        let pdf = self.research_pdf_out(walk_in, walk_out);
        // every check in one test (one branch): the order, a finite weight (its components are
        // ≥ 0, so a finite sum means finite components) and a unit direction, then those of
        // `finish_sample`
        let usable =
            self.order.includes(s.bounces) & weight.element_sum().is_finite() & super::is_direction(walk_out);
        self.finish_sample_if(usable, wo, walk_out, weight, pdf, false)
    }
}

impl<S: MicrosurfaceSlope, M: Material + SpecularLimit> Bsdf for MicrofacetBsdf<S, M> {
    #[inline]
    fn flags(&self) -> BsdfFlags {
        let index_matched = self.surface.material().always_specular();
        BsdfFlags {
            reflection: !index_matched,
            transmission: M::TRANSMITS,
            glossy: !self.specular && M::SMOOTH_IS_SPECULAR,
            diffuse: !M::SMOOTH_IS_SPECULAR,
            specular: self.specular,
        }
    }

    #[inline]
    fn eval_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> BsdfValue {
        unit_directions!(
            wo,
            wi,
            BsdfValue { f: Vec3::ZERO, exact: self.exact_eval() },
            self.eval_keyed(wo, wi, key)
        );
        self.eval_unit(wo, wi, key)
    }

    #[inline]
    fn sample_keyed(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample> {
        unit_view!(wo, uc, u, None, self.sample_keyed(wo, uc, u, key));
        if M::MIRROR_FACETS && self.exact_mirror && wo.z > 0.0 {
            // a conductor seen from above: the caller's (u.x, u.y) are the visible normal's
            // uniforms, taken as they are (no generator, no hash); the research sample's
            // weight is finite and its direction unit and above the horizon by construction
            let (slope, material) = (self.surface.slope(), self.surface.material());
            let s = SingleScattering::sample_mirror_front(slope, material, wo, u.x, u.y)?;
            return self.exact_reflection(wo, s.wo, s.weight, s.pdf);
        }
        if M::MIRROR_FACETS {
            // out of line: the fast path above keeps a small frame
            self.sample_general_outlined(wo, uc, u, key)
        } else {
            self.sample_general(wo, uc, u, key)
        }
    }

    /// One validation of the directions for both; single scattering also shares the half
    /// vector, D and Λ of the view ([`SingleScattering::eval_with_pdf`]).
    #[inline]
    fn eval_with_pdf_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> (BsdfValue, f32) {
        let exact = self.exact_eval();
        let nothing = (BsdfValue { f: Vec3::ZERO, exact }, 0.0);
        unit_directions!(wo, wi, nothing, self.eval_with_pdf_keyed(wo, wi, key));
        let (wo, wi) = match self.facing(wo) {
            Facing::AsGiven => (wo, wi),
            Facing::Mirrored => (mirror_z(wo), mirror_z(wi)),
            Facing::Nothing => return nothing,
        };
        // a Dirac BSDF has no density on the whole sphere (see `SMOOTH_ALPHA`)
        if self.specular {
            return nothing;
        }
        if self.technique == Technique::SingleScattering && wi.z != 0.0 {
            // one half vector, D and Λ(wo) for both (the walk enters along wo)
            let seed = self.seed;
            let mut rng = PrimedRng::new(&[], || Hasher::directions(seed, key, wo, wi));
            let (f_cos_wi, pdf) = self.single().eval_with_pdf_unchecked(wo, wi, &mut rng);
            let f = f_cos_wi * (self.transport_scale(wo, wi) / wi.z.abs());
            let f = if f.is_finite() { f } else { Vec3::ZERO };
            return (BsdfValue { f, exact }, if pdf.is_finite() { pdf } else { 0.0 });
        }
        let pdf = self.research_pdf_out(wo, wi);
        let pdf = if pdf.is_finite() { pdf } else { 0.0 };
        if wi.z == 0.0 {
            return (BsdfValue { f: Vec3::ZERO, exact }, pdf);
        }
        (BsdfValue { f: self.f_checked(wo, wi, key), exact }, pdf)
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        unit_directions!(wo, wi, 0.0, self.pdf(wo, wi));
        let pdf = if M::MIRROR_FACETS && self.exact_mirror && wo.z > 0.0 {
            // the exact reflection density (the single-scattering density of a view from
            // above: 0 for a light below the horizon), without the Dirac, sidedness and
            // technique tests (a view from above is answered as it is)
            if wi.z > 0.0 {
                SingleScattering::<S, M>::mirror_density(self.surface.slope(), wo, wi)
            } else {
                0.0
            }
        } else {
            let (wo, wi) = match self.facing(wo) {
                Facing::AsGiven => (wo, wi),
                Facing::Mirrored => (mirror_z(wo), mirror_z(wi)),
                Facing::Nothing => return 0.0,
            };
            // a Dirac BSDF has no density on the whole sphere (see `SMOOTH_ALPHA`)
            if self.specular {
                return 0.0;
            }
            self.research_pdf_out(wo, wi)
        };
        if pdf.is_finite() { pdf } else { 0.0 }
    }
}
