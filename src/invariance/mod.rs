//! The invariance-principle estimator of the multiple-bounce Smith BRDF (Cui, Pan, Yang,
//! Zhang, Yan and Wang 2023): [`Invariance`], whose documentation holds the derivation; its
//! depth law (`depth_law`), evaluation (`eval`) and sampling (`sample`), one file each.

mod depth_law;
mod eval;
mod sample;

use crate::error::Error;
use crate::height::UniformHeight;
use crate::material::Material;
use crate::microsurface::{Microsurface, incident_area};
use crate::slope::MicrosurfaceSlope;
use glam::Vec3;

/// Below this rate σ₀ = Λ(−ωi) of a view from below, the methods use the walk from below
/// ([`Microsurface::eval_from_below`]): 1e-200 keeps every product of the state within f64.
pub const MIN_FIRST_RATE: f64 = 1e-200;

/// The invariance-principle estimator of the multiple-bounce Smith BRDF of an opaque
/// microsurface (Cui, Pan, Yang, Zhang, Yan and Wang 2023, “Multiple-bounce Smith Microfacet
/// BRDFs using the Invariance Principle”, SIGGRAPH Asia): the Heitz et al. 2016 random walk's
/// BRDF with every height integrated out in closed form, so that a path is a sequence of
/// directions only.
///
/// # The model it estimates
///
/// The Heitz et al. 2016 walk on an opaque microsurface (supplement §3.1), not the
/// position-free models of Wang et al. 2022: for F = 1 and GGX α = 1 its per-order albedos
/// agree with the walk's exact quadrature (`validation::per_order`, orders 1–3) and differ
/// from the height-correlated position-free model's from order 2 on (`tests/invariance.rs`).
///
/// Assumptions: Smith's, as in the walk: heights and slopes uncorrelated, so that a ray along
/// d meets the surface at the rate |Λ(d)| per unit of the depth τ = −ln C¹(h) whatever the
/// height distribution (supplement §1.1); Λ(−ω) = −1 − Λ(ω) on the whole sphere; and an
/// opaque material (light stays on the outer side, so depths are measured in one frame).
/// Neither isotropy nor a particular slope distribution is assumed: the estimator is generic
/// over [`MicrosurfaceSlope`](crate::slope::MicrosurfaceSlope) (GGX, Beckmann, anisotropic,
/// elliptical, tabulated) and over the opaque materials ([`Conductor`](crate::Conductor) with
/// its RGB Fresnel term, and [`Diffuse`](crate::Diffuse) facets); a dielectric is rejected by
/// [`Invariance::new`].
///
/// # Derivation
///
/// A path of order k enters along d₀ = −ωi, scatters at vertices 1 … k at depths τ₁ … τ_k,
/// and leaves along d_k = ωo; segment j joins vertex j to j + 1 (vertex 0 and the exit at
/// τ = 0). With σ_j = |Λ(d_j)| (1 + Λ(−d_j) for a downward d_j, Λ(d_j) for an upward one) the
/// walk's density of the path factors into direction terms and one depth integral:
///
/// ```text
/// f_k(ωi, ωo)|cos θo| = ∫ Π_{j<k} σ_j p(d_j → d_{j+1}) · G(σ₀, …, σ_k) dd₁ … dd_{k−1},
/// G = ∫ Π_{j<k} e^{−σ_j |τ_{j+1} − τ_j|} · e^{−σ_k τ_k} dτ₁ … dτ_k,
/// ```
///
/// over the depths each segment's direction allows (τ_{j+1} > τ_j going down, < going up),
/// with p the phase function (for mirror facets σ_j p = F D(ωh)/(4|cos θ_j|), the vertex term
/// of Wang et al. 2022, eq. 2: the hazard σ_j cancels the projected area A(−d_j) = σ_j|cos θ_j|
/// of the visible-normal density). G is the paper's shadowing-masking function of a whole path
/// of directions: it depends on the directions only through the σ's, since in τ the Smith
/// microsurface is a homogeneous semi-infinite medium. The paper derives it with the
/// invariance principle (the reflection of a semi-infinite medium is unchanged by a thin layer
/// added on top); here it is computed exactly by Laplace transforms.
///
/// G is evaluated segment by segment through the Laplace transform Φ_j(s) of the density
/// φ_j(τ) of vertex j's depth (`DepthLaw`): Φ₁(s) = 1/(s + σ₀); a downward segment of
/// rate a gives Φ(s)/(s + a); an upward segment of rate b that hits gives
/// (Φ(s) − Φ(b))/(b − s); and G = Φ_k(σ_k). Normalized by Φ_j(0), Ψ_j = Φ_j/Φ_j(0) is the
/// depth's moment generating function: Ψ_j(Λ(ωo)) is the probability that ωo leaves vertex j
/// unmasked given the path's directions (order 1: (1 + Λi)/(1 + Λi + Λo), the height-correlated
/// G2/G1), and 1 − Ψ_j(b) the probability that an upward segment of rate b hits.
///
/// Per-order structure: on mirror facets a reflection only raises a ray (d′.z = d.z −
/// 2(d·m)m.z > d.z for a facet it meets, d·m < 0, m.z > 0), so a conductor's path goes down
/// for a while and then only up, and G is a sum over the interleavings of the two chains'
/// depths, each interleaving a product of 1/(σ_down + σ_up) — the form of the paper's path
/// shadowing-masking function and of its released implementation. Diffuse facets can send an
/// upward ray down again; the suffix-product basis of `DepthLaw` is exact for those paths too
/// (checked against the sum over all depth orderings in its tests).
///
/// # The estimators
///
/// * [`Invariance::eval`]: path tracing with next-event estimation towards ωo at every vertex,
///   directions drawn from the phase function (exact visible-normal sampling): the
///   contribution of order j + 1 is (Π w)·P·p(d_j → ωo)·Ψ_{j+1}(Λ(ωo)), w the sample weights
///   (Fresnel), P the probability that segment j hits given the directions (1 going down).
///   After that next-event term the path goes on with probability P (Russian roulette with
///   the walk's own law, deferred by one vertex: see [`Invariance::eval`]). Unbiased for every
///   order; the masking of ωo and the hits of the upward segments are exact conditional
///   expectations given the directions, where the walk draws heights (Rao–Blackwell).
/// * [`Invariance::sample`]: the walk's law of exit directions with the depths integrated out:
///   an upward segment leaves with probability Ψ(b); the weight is the product of the phase
///   sample weights, f·|cos θo|/pdf exactly (1 for F = 1). Its density has no closed form (as
///   the walk's); the renderer layer pairs it with the position-free model's approximate MIS
///   density, as for the walk.
///
/// Light from below the macrosurface (a backfacing view) enters with σ₀ = Λ(−ωi) and is
/// handled the same way; where Λ(−ωi) < [`MIN_FIRST_RATE`] (Beckmann seen from so far below
/// that it nears f64 underflow) both methods use the walk from below
/// ([`Microsurface::eval_from_below`], the same model), which works in ln Λ.
///
/// # API
///
/// Research layer: `eval(wi, wo)` with ωi the direction light arrives from returns
/// f·|cos θo| per RGB channel, stochastic and unbiased; `sample(wi)` returns a direction
/// with the weight f·|cos θo|/pdf. Generic over the slope distribution and the opaque
/// materials ([`Conductor`](crate::Conductor), [`Diffuse`](crate::Diffuse)).
///
/// # Examples
/// ```
/// use microsurface::{ComplexIor, Conductor, Ggx};
/// use microsurface::research::{Invariance, Microsurface, ScatteringOrder, UniformHeight};
/// use microsurface::glam::Vec3;
/// use microsurface::rand::SeedableRng;
///
/// let gold = Invariance::new(Ggx::isotropic(0.5)?, Conductor::new(ComplexIor::GOLD))?;
/// let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(7);
/// let (wi, wo) = (Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.3, 0.1, 0.949).normalize());
/// // f·|cos θo|, all orders: the same BRDF as the random walk's, with less noise
/// let n = 4000;
/// let mean = (0..n).map(|_| gold.eval(wi, wo, ScatteringOrder::All, &mut rng)).sum::<Vec3>() / n as f32;
/// let walk = Microsurface::new(UniformHeight, Ggx::isotropic(0.5)?, Conductor::new(ComplexIor::GOLD));
/// let walk_mean = (0..n).map(|_| walk.eval(wi, wo, ScatteringOrder::All, &mut rng)).sum::<Vec3>() / n as f32;
/// assert!((mean - walk_mean).abs().max_element() < 0.05 * walk_mean.max_element());
/// // order 1 is the exact single scattering term
/// let first = ScatteringOrder::only(1).expect("orders start at 1");
/// let single = walk.eval_single_scattering(wi, wo, &mut rng);
/// assert!((gold.eval(wi, wo, first, &mut rng) - single).abs().max_element() <= 1e-5 * single.max_element());
/// // a sampled exit direction with its weight (the Fresnel terms along the path)
/// let s = gold.sample(wi, &mut rng).expect("light from above always leaves");
/// assert!(s.wo.z > 0.0 && s.weight.max_element() <= 1.0);
/// // a dielectric is not covered
/// assert!(Invariance::new(Ggx::isotropic(0.5)?, microsurface::Dielectric::new(1.5)?).is_err());
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Invariance<S, M> {
    slope: S,
    material: M,
}

impl<S: MicrosurfaceSlope, M: Material> Invariance<S, M> {
    /// The estimator for the slope distribution `slope` and the opaque material `material`.
    ///
    /// # Errors
    /// [`Error::UnsupportedMaterial`] for a material that transmits (a dielectric): its paths
    /// cross the interface, where the depth of one side is not that of the other.
    pub fn new(slope: S, material: M) -> Result<Self, Error> {
        if M::TRANSMITS {
            return Err(Error::UnsupportedMaterial {
                model: "Invariance",
                expected: "an opaque material (Conductor or Diffuse)",
            });
        }
        Ok(Self { slope, material })
    }

    /// The slope distribution.
    #[inline]
    pub fn slope(&self) -> &S {
        &self.slope
    }

    /// The material.
    #[inline]
    pub fn material(&self) -> &M {
        &self.material
    }

    /// The entry segment d₀ = −ωi (ωi off the horizon): its rate σ₀ = |Λ(−ωi)| (1 + Λ(ωi)
    /// from above, in f32 as the walk takes it; Λ(−ωi) from below, in f64) and the projected
    /// area A(ωi) = Λ(−ωi)·(−cos θi) where it is a normal f32; `None` where σ₀ <
    /// [`MIN_FIRST_RATE`] (the walk from below answers).
    #[inline(always)]
    fn entry(&self, wi: Vec3) -> Option<(f64, Option<f32>)> {
        let d = -wi;
        let lambda =
            if wi.z > 0.0 { f64::from(self.slope.lambda_unchecked(d)) } else { self.slope.lambda64(d) };
        let rate = lambda.abs();
        (rate >= MIN_FIRST_RATE).then(|| (rate, incident_area(d.z, lambda as f32)))
    }

    /// The random walk of the same microsurface (the model this estimates), for the views
    /// from below where σ₀ < [`MIN_FIRST_RATE`].
    #[inline]
    fn walk(&self) -> Microsurface<UniformHeight, S, M> {
        Microsurface::new(UniformHeight, self.slope, self.material)
    }
}
