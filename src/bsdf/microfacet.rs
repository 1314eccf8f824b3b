//! The renderer-facing BSDF of a microsurface, with a choice of technique.

use super::{Bsdf, BsdfSample, BsdfValue, SampleFlags, Transport, is_direction};
use crate::height::MicrosurfaceHeight;
use crate::material::Material;
use crate::microsurface::{Microsurface, ScatteringOrder, WalkSample};
use crate::position_free::{Estimator, PositionFree, Shadowing};
use crate::slope::MicrosurfaceSlope;
use glam::Vec3;
use rand::Rng;

/// Orders tabulated separately by [`EnergyByOrder`].
const TABULATED_ORDERS: usize = 8;

/// How a [`MicrofacetBsdf`] evaluates and samples its microsurface: the choice that lets a
/// renderer pay only for what its scene needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Technique {
    /// The classic single-scattering microfacet BSDF (Cook–Torrance / Walter) with
    /// height-correlated Smith masking-shadowing: exact eval, pdf and sample; loses the
    /// energy of higher orders. Valid for backfacing view directions (normal mapping): the
    /// view's masking is the full-spherical 1/|1 + Λ| and the VNDF is sampled exactly on the
    /// whole sphere (Tokuyoshi), so estimates stay unbiased. A sample's weight equals
    /// f·|cos θi|/pdf at its direction to a few f32 ulps (1e-5 with a Fresnel term) for every
    /// roughness; samples whose pdf or f would be subnormal are not returned (at most
    /// 4π·`f32::MIN_POSITIVE` of probability). See `PositionFree::sample_single` for the f32
    /// resolution limit of backfacing Beckmann views below α ≈ 1e-3.
    SingleScattering,
    /// The height-tracing random walk of Heitz et al. 2016: stochastic eval, exact sample
    /// weights, approximate pdf.
    #[default]
    RandomWalk,
    /// The position-free estimators of Wang et al. 2022: stochastic eval, exact sample
    /// weights, approximate pdf.
    PositionFree {
        /// PT or BDPT.
        estimator: Estimator,
        /// Height-correlated or uncorrelated shadowing.
        shadowing: Shadowing,
    },
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
    pub fn total(&self) -> f64 {
        self.per_order.iter().sum::<f64>() + self.beyond
    }

    /// The energy a truncation of the BSDF after `max_order` bounces leaves out.
    pub fn left_out(&self, max_order: u32) -> f64 {
        let kept: f64 = self.per_order.iter().take(max_order as usize).sum();
        self.total() - kept
    }
}

/// The BSDF of a microsurface with height distribution `H`, slope distribution `S` and
/// material `M`, evaluated with a chosen [`Technique`] and truncated to a chosen
/// [`ScatteringOrder`]; statically dispatched.
///
/// It uses the adjoint orientation of the models (they are evaluated and sampled starting
/// from `wo`), with the (η_wo/η_wi)² factor of radiance transport for dielectrics. For the
/// non-reciprocal height-correlated position-free model this is the model with the roles of
/// the two directions exchanged, which keeps `eval`, `sample` and `pdf` consistent with one
/// another.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MicrofacetBsdf<H, S, M> {
    surface: Microsurface<H, S, M>,
    technique: Technique,
    order: ScatteringOrder,
    transport: Transport,
}

impl<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material> MicrofacetBsdf<H, S, M> {
    /// A BSDF with the random-walk technique, all orders, radiance transport.
    pub fn new(height: H, slope: S, material: M) -> Self {
        Self {
            surface: Microsurface::new(height, slope, material),
            technique: Technique::default(),
            order: ScatteringOrder::All,
            transport: Transport::default(),
        }
    }

    /// The same BSDF evaluated with another technique.
    pub fn with_technique(self, technique: Technique) -> Self {
        Self { technique, ..self }
    }

    /// The same BSDF truncated to the given orders (ignored by single scattering).
    pub fn with_order(self, order: ScatteringOrder) -> Self {
        Self { order, ..self }
    }

    /// The same BSDF for another transport mode.
    pub fn with_transport(self, transport: Transport) -> Self {
        Self { transport, ..self }
    }

    /// The underlying microsurface.
    pub fn surface(&self) -> &Microsurface<H, S, M> {
        &self.surface
    }

    /// The technique.
    pub fn technique(&self) -> Technique {
        self.technique
    }

    /// The position-free model with the given shadowing over the same slope and material.
    #[inline(always)]
    fn position_free(&self, shadowing: Shadowing) -> PositionFree<S, M> {
        PositionFree::new(*self.surface.slope(), *self.surface.material(), shadowing)
    }

    /// (η_wo/η_wi)² for radiance transport across a dielectric, 1 otherwise.
    #[inline(always)]
    fn transport_scale(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self.transport {
            Transport::Radiance => self.surface.material().relative_eta_sq(wi.z > 0.0, wo.z > 0.0),
            Transport::Importance => 1.0,
        }
    }

    /// The energy per scattering order for the view direction `wo`, from `walks` sampled
    /// walks of this BSDF's technique (single scattering uses the random walk): what a
    /// truncation to n orders would leave out is [`EnergyByOrder::left_out`]. The energies are
    /// albedos (importance transport): the radiance factor (η_wo/η_wi)² of a dielectric is not
    /// applied.
    pub fn energy_by_order(&self, wo: Vec3, walks: usize, rng: &mut impl Rng) -> EnergyByOrder {
        let mut table = EnergyByOrder { walks, ..EnergyByOrder::default() };
        for _ in 0..walks {
            let sample = match self.technique {
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

    /// f(wo → wi)·|cos θi| in the model's own orientation (light from `wo`).
    #[inline]
    fn adjoint_eval(&self, wo: Vec3, wi: Vec3, rng: &mut impl Rng) -> Vec3 {
        match self.technique {
            Technique::SingleScattering => {
                self.position_free(Shadowing::Correlated).eval_single_backfacing(wo, wi, rng)
            }
            Technique::RandomWalk => self.surface.eval(wo, wi, self.order, rng),
            Technique::PositionFree { estimator, shadowing } => {
                self.position_free(shadowing).eval(wo, wi, estimator, self.order, rng)
            }
        }
    }
}

impl<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material> Bsdf for MicrofacetBsdf<H, S, M> {
    fn eval(&self, wo: Vec3, wi: Vec3, rng: &mut impl Rng) -> BsdfValue {
        let exact = self.technique == Technique::SingleScattering && M::EXACT_PHASE_PDF;
        if !is_direction(wo) || !is_direction(wi) || wi.z == 0.0 {
            return BsdfValue { f: Vec3::ZERO, exact };
        }
        let f = self.adjoint_eval(wo, wi, rng) * (self.transport_scale(wo, wi) / wi.z.abs());
        BsdfValue { f: if f.is_finite() { f } else { Vec3::ZERO }, exact }
    }

    fn sample(&self, wo: Vec3, rng: &mut impl Rng) -> Option<BsdfSample> {
        if !is_direction(wo) {
            return None;
        }
        let (wi, weight, exact_pdf) = match self.technique {
            Technique::SingleScattering => {
                let (wi, weight) = self.position_free(Shadowing::Correlated).sample_single(wo, rng)?;
                (wi, weight, M::EXACT_PHASE_PDF)
            }
            Technique::RandomWalk => {
                let s = self.surface.sample(wo, rng).filter(|s| self.order.includes(s.bounces))?;
                (s.wo, s.weight, false)
            }
            Technique::PositionFree { shadowing, .. } => {
                let s = self
                    .position_free(shadowing)
                    .sample(wo, rng)
                    .filter(|s| self.order.includes(s.bounces))?;
                (s.wo, s.weight, false)
            }
        };
        let pdf = self.pdf(wo, wi);
        let weight = weight * self.transport_scale(wo, wi);
        // the density and the BSDF value f = weight·pdf/|cos θi| the sample implies must be
        // normal f32 numbers: a subnormal one has lost its precision, and eval could not
        // reproduce weight = f·|cos θi|/pdf (deep tails: Beckmann dielectric α = 1 at
        // cos θo = 1e-3 gave f = 2e-45, 33 % off). Dropping such samples loses at most
        // 4π·f32::MIN_POSITIVE of probability and π·f32::MIN_POSITIVE of energy.
        if !(pdf >= f32::MIN_POSITIVE && pdf.is_finite() && weight.is_finite() && is_direction(wi))
            || wi.z == 0.0
        {
            return None;
        }
        let f_max = f64::from(weight.max_element()) * f64::from(pdf) / f64::from(wi.z.abs());
        if f_max < f64::from(f32::MIN_POSITIVE) {
            return None;
        }
        let reflection = (wi.z > 0.0) == (wo.z > 0.0);
        let flags = SampleFlags { reflection, transmission: !reflection, specular: false, exact_pdf };
        Some(BsdfSample { wi, weight, pdf, flags })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !is_direction(wo) || !is_direction(wi) {
            return 0.0;
        }
        let pf = self.position_free(Shadowing::Correlated);
        let pdf = match self.technique {
            Technique::SingleScattering => pf.pdf_single(wo, wi),
            _ => pf.pdf(wo, wi),
        };
        if pdf.is_finite() { pdf } else { 0.0 }
    }
}
