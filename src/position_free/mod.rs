//! Position-free multiple-bounce microfacet BSDFs (Wang, Jin, Fan, Yang, Holzschuch and Yan
//! 2022, “Position-free Multiple-bounce Computations for Smith Microfacet BSDFs”).
//!
//! A light path inside the microsurface is a sequence of directions; every vertex has the
//! same statistics, so no heights are traced. The path contribution is a product of vertex
//! terms (the local BSDF of one bounce without shadowing, [`Material::vertex`]) and
//! shadowing factors ([`Shadowing`]). The BSDF is estimated by path tracing with next-event
//! estimation ([`PositionFree::eval_pt`]) or by bidirectional path tracing with the balance
//! heuristic ([`PositionFree::eval_bdpt`]).

mod bdpt;
mod pt;
mod roulette;

use crate::contract::is_direction;
use crate::material::Material;
use crate::microsurface::{MAX_BOUNCES, ScatteringOrder, WalkSample};
use crate::path::{Exit, Incident, PathModel, Shadowing, inv_g1};
use crate::rng::uniform;
use crate::slope::MicrosurfaceSlope;
use glam::Vec3;
use rand::Rng;
use roulette::{BDPT_ROULETTE_FROM, PeakScales, ROULETTE_FROM_BOUNCE, Roulette};

/// Which estimator evaluates the position-free BSDF.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Estimator {
    /// Unidirectional path tracing with next-event estimation (Wang et al. 2022, eqs. 24–26).
    Pt,
    /// Bidirectional path tracing, all connection strategies, balance heuristic
    /// (Wang et al. 2022, eqs. 27–29).
    #[default]
    Bdpt,
}

/// A position-free multiple-bounce BSDF: slope distribution `S`, material `M`, and a
/// [`Shadowing`] model. No height distribution is needed.
///
/// Directions follow the crate's conventions (local frame, both pointing away from the
/// surface); evaluations return f·|cos θo| per RGB channel. A dielectric is evaluated from
/// inside for ωi.z < 0; an opaque material accepts ωi below the horizon as light arriving
/// from below the macrosurface (a backfacing view under a normal map), every estimator
/// included.
///
/// # Examples
/// ```
/// use microsurface::{Conductor, Ggx};
/// use microsurface::research::{Estimator, PositionFree, ScatteringOrder, Shadowing};
/// use microsurface::glam::Vec3;
/// use microsurface::rand::SeedableRng;
///
/// let surface = PositionFree::new(Ggx::isotropic(1.0)?, Conductor::perfect(), Shadowing::Correlated);
/// let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
/// let (wi, wo) = (Vec3::new(0.6, 0.0, 0.8), Vec3::Z);
/// // BDPT and PT estimate the same BSDF (f·|cos θo|), here all orders
/// let bdpt = surface.eval(wi, wo, Estimator::Bdpt, ScatteringOrder::All, &mut rng);
/// let pt = surface.eval(wi, wo, Estimator::Pt, ScatteringOrder::All, &mut rng);
/// assert!(bdpt.x > 0.0 && pt.x > 0.0);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionFree<S, M> {
    /// The vertex terms and shadowing factors of the model.
    model: PathModel<S, M>,
    /// The scales of the phase function's peak for the camera paths' roulette.
    peaks: PeakScales,
}

impl<S: MicrosurfaceSlope, M: Material> PositionFree<S, M> {
    /// A position-free BSDF with the given slope distribution, material and shadowing model.
    pub fn new(slope: S, material: M, shadowing: Shadowing) -> Self {
        Self { model: PathModel::new(slope, material, shadowing), peaks: PeakScales::new(&slope, &material) }
    }

    /// The slope distribution.
    #[inline]
    pub fn slope(&self) -> &S {
        &self.model.slope
    }

    /// The material.
    #[inline]
    pub fn material(&self) -> &M {
        &self.model.material
    }

    /// The shadowing model.
    #[inline]
    pub fn shadowing(&self) -> Shadowing {
        self.model.shadowing
    }

    /// Evaluates f·|cos θo| with the chosen estimator and orders; unbiased and stochastic.
    ///
    /// Invalid input ([policy](crate#invalid-input)): checked by the estimators
    /// ([`PositionFree::eval_pt`], [`PositionFree::eval_bdpt`]): 0 for a `wi` or `wo` that is
    /// not a unit direction.
    pub fn eval(
        &self,
        wi: Vec3,
        wo: Vec3,
        estimator: Estimator,
        order: ScatteringOrder,
        rng: &mut impl Rng,
    ) -> Vec3 {
        match estimator {
            Estimator::Pt => self.eval_pt(wi, wo, order, rng),
            Estimator::Bdpt => self.eval_bdpt(wi, wo, order, rng),
        }
    }

    /// The single-bounce term v(ωi, ωo)·S_last (the path of one vertex): the microfacet BSDF
    /// times |cos θo| with this model's masking-shadowing — G1(ωi)G1(ωo) uncorrelated,
    /// 1/(1 + Λ(ωi) + Λ(ωo)) or B(1 + Λ(ωi), 1 + Λ(−ωo)) correlated. Exact, except for diffuse
    /// facets (unbiased estimate).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    pub fn eval_single_scattering(&self, wi: Vec3, wo: Vec3, rng: &mut impl Rng) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        self.model.eval_single_scattering(wi, wo, rng)
    }

    /// Samples an outgoing direction with the position-free random walk (Wang et al. 2022,
    /// §4.3): each bounce draws a visible normal (exact full-spherical VNDF sampling) and an
    /// event; a direction that can leave the surface does so with the probability the
    /// shadowing model gives (G1(ωo) uncorrelated; G2/G1(ωin) correlated).
    ///
    /// The weight is f·|cos θo|/pdf exactly: the product of the sample weights (Fresnel for
    /// conductors, albedo for diffuse facets, 1 for dielectrics). `None` if ωi cannot light
    /// the material (on the horizon, or at the nadir of an opaque material, where no facet
    /// faces it), or the walk reached [`crate::research::MAX_BOUNCES`].
    ///
    /// Nearly index-matched dielectrics at grazing incidence: a refraction through an
    /// interface with η ≈ 1 barely turns the ray, and this model's exit probability per vertex
    /// then falls to about 2^−Λ (it forgets the height a vertex was reached at, which the
    /// height-tracing walk keeps), so its paths grow as |η − 1| → 0: no path is lost to
    /// [`crate::research::MAX_BOUNCES`] down to |η − 1| = 1e-5 (`tests/walk/cap.rs`), while within one or
    /// two f32 ulps of 1 nearly all grazing paths are (path lengths measured in DESIGN.md,
    /// “The bounce cap”). η = 1 itself is transparent ([`crate::research::Material::is_transparent`]).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` that is not a unit direction gives
    /// `None` (a debug assertion in debug builds).
    pub fn sample(&self, wi: Vec3, rng: &mut impl Rng) -> Option<WalkSample> {
        require!(is_direction(wi), None; wi);
        let mut at = PathModel::<S, M>::incident(wi)?;
        if self.model.material.is_transparent() {
            // the Dirac ωo = −ωi of an interface that does not interact (see `Material`)
            return Some(WalkSample { wo: -wi, weight: Vec3::ONE, bounces: 1 });
        }
        if wi.z < 0.0 && self.model.sees_nothing(at, inv_g1(&self.model.slope, at.in_frame())) {
            // ωi at the nadir of an opaque material: no facet faces it (projected area 0)
            return None;
        }
        let mut weight = Vec3::ONE;
        for bounces in 1..=MAX_BOUNCES {
            let s = self.model.material.sample_phase_unchecked(&self.model.slope, at.w, at.side, rng);
            weight *= s.weight;
            if weight == Vec3::ZERO {
                return None;
            }
            let out = self.model.exit(s.wo, s.side);
            if out.can_exit() {
                let k_in = inv_g1(&self.model.slope, at.in_frame());
                // P(exit) = S_last/(S_last + S_middle) = S_last/G1(ωin)
                if f64::from(uniform(rng)) < self.model.relative_shadowing(at, k_in, out).last {
                    return Some(WalkSample { wo: s.wo, weight, bounces });
                }
            }
            at = Incident { w: -s.wo, side: s.side };
        }
        None
    }

    /// Samples the single-bounce term: ωo from the phase function (exact full-spherical VNDF
    /// sampling and the material's event choice), weighted by w·S_last/G1(ωi) so that the
    /// weight is v·S_last·|cos θo|/pdf exactly. Returns (ωo, weight); `None` if ωi cannot light
    /// the material or the sampled direction cannot leave the surface.
    ///
    /// Precision: the weight is w·k_in·S_last with the masking ratio Λo/Λ(−ωi) of a
    /// backfacing ωi formed in f64, from logarithms where Λ underflows
    /// (`relative_shadowing`), so that it equals f·|cos θo|/pdf at the returned f32 direction
    /// to a few f32 ulps (16 ulps tested, `tests/bsdf/backfacing_masking.rs`) for every roughness.
    /// Resolution: for a backfacing ωi the reflection ωo = −ωi + 2(ωi·ωm)ωm leaves within
    /// 2ωi·ωm of −ωi; eval and pdf recompute the half vector from the directions the f32
    /// vectors represent, and it moves by about 2⁻²⁴/(2ωi·ωm) rad along the facets ωi grazes.
    /// Where the visible normals' ωi·ωm is ≲ 1e-6 (Beckmann α = 1e-4 below θ ≈ 1.6, α = 1e-3
    /// below θ ≈ 2.3; not GGX, whose visible lobe is wide) the sampled f32 normal itself no
    /// longer resolves ωi·ωm: the density at the returned direction is then not resolved (it
    /// may be subnormal or 0, and the renderer interface drops such samples).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` that is not a unit direction gives
    /// `None` (a debug assertion in debug builds).
    pub fn sample_single(&self, wi: Vec3, rng: &mut impl Rng) -> Option<(Vec3, Vec3)> {
        require!(is_direction(wi), None; wi);
        let m = &self.model;
        let at = PathModel::<S, M>::incident(wi)?;
        let s = m.material.sample_phase_unchecked(&m.slope, at.w, at.side, rng);
        let k_in = inv_g1(&m.slope, at.in_frame());
        let last = m.relative_shadowing(at, k_in, m.exit(s.wo, s.side)).last;
        let weight = s.weight * last as f32;
        (last > 0.0 && weight.is_finite()).then_some((s.wo, weight))
    }

    /// The density of [`PositionFree::sample_single`]: the phase function's sampling density
    /// (exact for conductors and dielectrics).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    pub fn pdf_single(&self, wi: Vec3, wo: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wo), 0.0; wi, wo);
        let (Some(start), Some(wo_side)) =
            (PathModel::<S, M>::incident(wi), PathModel::<S, M>::exit_side(wo))
        else {
            return 0.0;
        };
        self.model.material.pdf_phase_unchecked(&self.model.slope, &start.to(wo, wo_side))
    }

    /// An approximate density of [`PositionFree::sample`], for multiple importance sampling
    /// in a renderer: 0.8 × the single-bounce sampling density of ωo plus 0.2 × a cosine lobe
    /// on ωo's side (divided between both sides for a dielectric). Like the papers' `pdf()`,
    /// it is **not** the density of what `sample` draws (which has no closed form); the
    /// weights of `sample` never use it.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    pub fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wo), 0.0; wi, wo);
        self.model.mis_pdf(wi, wo)
    }
}

impl Exit {
    /// Whether the direction can leave the surface.
    #[inline(always)]
    pub(crate) fn can_exit(self) -> bool {
        self.lambda.is_some()
    }
}

impl<S: MicrosurfaceSlope, M: Material> PathModel<S, M> {
    /// Whether the incident state `at` with 1 + L̃ = `k_in` sees no microsurface: Λ(−ωin) = 0
    /// exactly (straight from below), told apart from a Λ(−ωin) that only underflows f64
    /// (Beckmann, |cot θ|/αᵢ > 26.6) by ln Λ (−∞ only in the first case).
    #[inline]
    pub(crate) fn sees_nothing(&self, at: Incident, k_in: f64) -> bool {
        k_in == 0.0 && self.slope.ln_lambda(-at.in_frame()) == f64::NEG_INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{Conductor, Side};
    use crate::path::PDF_COSINE_SHARE;
    use crate::sampling::cosine_hemisphere;
    use crate::slope::Beckmann;
    use rand::SeedableRng;
    use rand_pcg::Pcg64Mcg;

    /// θi = 120°: with Beckmann α = 0.02, a = |cot θi|/αᵢ = 28.9 and Λ(−ωi) ≈ e^{−a²}
    /// underflows f64.
    fn from_below() -> Vec3 {
        let t = 120f32.to_radians();
        Vec3::new(t.sin(), 0.0, t.cos())
    }

    fn smooth_mirror(shadowing: Shadowing) -> PositionFree<Beckmann, Conductor> {
        PositionFree::new(
            Beckmann::isotropic(0.02).expect("valid roughness"),
            Conductor::perfect(),
            shadowing,
        )
    }

    /// Smooth Beckmann seen from below where Λ(−ωi) underflows f64: the position-free walk of
    /// a perfect mirror returns every path, upwards, with weight 1 (energy is conserved), for
    /// both shadowing models. Before, the nadir test took the underflowed Λ(−ωi) = 0 for “no
    /// facet faces ωi” and returned `None` for all of them.
    #[test]
    fn sample_from_below_sees_smooth_beckmann() {
        for shadowing in [Shadowing::Correlated, Shadowing::Uncorrelated] {
            let pf = smooth_mirror(shadowing);
            let mut rng = Pcg64Mcg::seed_from_u64(41);
            for k in 0..2000 {
                let s = pf
                    .sample(from_below(), &mut rng)
                    .unwrap_or_else(|| panic!("{shadowing:?}: path {k} lost"));
                assert!(s.weight == Vec3::ONE && s.wo.z > 0.0, "{shadowing:?}: {s:?}");
            }
        }
    }

    /// The same surface: path tracing's albedo ∫ f·cos dωo is 1 for a perfect mirror.
    /// Estimated as the mean of eval_pt/pdf over N = 20 000 directions drawn from the mixture
    /// whose density is [`PositionFree::pdf`] (0.8 phase sampling, 0.2 cosine), within z σ̂/√N,
    /// z = 3.29 (Šidák, family-wise 1e-3 over the two shadowing models), resolving 1 %. Before,
    /// the path stopped after the first vertex (its incident 1 + L̃ underflowed to 0) and the
    /// multiple scattering was lost (mean 0.915, 25 σ̂/√N below 1).
    #[test]
    fn pt_from_below_conserves_energy_for_smooth_beckmann() {
        for shadowing in [Shadowing::Correlated, Shadowing::Uncorrelated] {
            assert_albedo_from_below_is_one(shadowing, Estimator::Pt, 20_000, 0.01, 3.29);
        }
    }

    /// The same for bidirectional path tracing with correlated shadowing, N = 80 000 so that
    /// σ̂/√N ≤ 0.0025 (σ̂ ≈ 0.55: 0.002), z = 3.29 (two-sided 1e-3). Before, the balance weight of
    /// a camera path whose own density evaluated to 0 was 0/0 = NaN and the path was dropped:
    /// 0.9912 ± 0.0009 (N = 400 000), 4.4 σ̂/√N below 1 at this N; those zero densities, and the
    /// remaining deficit (0.9966 ± 0.0020 here), came from the reflection half vector of the
    /// unnormalized f32 directions (see the uncorrelated test below).
    #[test]
    fn bdpt_from_below_conserves_energy_for_smooth_beckmann() {
        assert_albedo_from_below_is_one(Shadowing::Correlated, Estimator::Bdpt, 80_000, 0.0025, 3.29);
    }

    /// The same for the uncorrelated model (σ̂ ≈ 0.50). Before, eval and pdf formed the half
    /// vector of these near-forward reflections (ωo within 2ωi·ωm ≈ 2e-4 of −ωi) from the
    /// unnormalized f32 vectors, and their lengths' rounding lost the sign of ωi·ωh for 0.8 %
    /// of the phase-sampled directions: eval 0 where the sampler put mass, 0.9903 ± 0.0018, 5.4
    /// σ̂/√N below 1 (all of it at order 1, which is the whole albedo of this model here: the
    /// order-2 share Λ(ωo)/(1 + Λ(ωo)) underflows).
    #[test]
    fn bdpt_uncorrelated_from_below_conserves_energy_for_smooth_beckmann() {
        assert_albedo_from_below_is_one(Shadowing::Uncorrelated, Estimator::Bdpt, 80_000, 0.0025, 3.29);
    }

    /// White diffuse facets seen from below a smooth surface (Beckmann α = 0.02, θi = 120°,
    /// a = 28.9, correlated): BDPT conserves energy, in total and at order 3. The albedo
    /// ∫ f·cos dωo is the mean of eval_bdpt/pdf over N = 100 000 cosine-distributed ωo (exact
    /// density): it is 1 (every walk of `sample` returns with weight 1), within z σ̂/√N with
    /// σ̂/√N ≤ 0.005 asserted (σ̂ ≈ 0.8). Order 3 (`Only(3)`, N = 200 000, σ̂/√N ≤ 0.0006) is
    /// compared with the share of `sample`'s walks that leave after 3 bounces (N = 200 000,
    /// binomial SE), within z times the SE of the difference. z = 3.48: Šidák over the two
    /// assertions at family-wise 1e-3, two-sided. Before, the balance weights used the diffuse
    /// density 1/(8π) for the light sub-path's incident directions below the horizon, which it
    /// practically never samples (true density ≤ A(ωin)/(π A(ωout)) ≈ e^{−a²}), and the diffuse
    /// vertex term of an interior connection, which carries Λ(−ωin), underflowed f32 for
    /// 1e-290 < Λ(−ωin) < 1e-38: 0.8978 ± 0.0022 in total (46 SE low); with the density fixed
    /// alone, order 3 was 0.0360 ± 0.0004 against the walks' 0.0397 ± 0.0004 (6.0 SE low).
    /// Measured after: 0.9974 ± 0.0026 and 0.0391 ± 0.0005.
    #[test]
    fn bdpt_diffuse_from_below_conserves_energy() {
        const Z: f64 = 3.48;
        let pf = PositionFree::new(
            Beckmann::isotropic(0.02).expect("valid roughness"),
            crate::material::Diffuse::white(),
            Shadowing::Correlated,
        );
        let wi = from_below();
        let mut rng = Pcg64Mcg::seed_from_u64(53);
        let albedo = |order: ScatteringOrder, n: usize, rng: &mut Pcg64Mcg| {
            let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let wo = cosine_hemisphere(uniform(rng), uniform(rng));
                let pdf = f64::from(wo.z) * core::f64::consts::FRAC_1_PI;
                let x = if pdf > 0.0 { f64::from(pf.eval_bdpt(wi, wo, order, rng).x) / pdf } else { 0.0 };
                (sum, sum_sq) = (sum + x, sum_sq + x * x);
            }
            let mean = sum / n as f64;
            (mean, (sum_sq / n as f64 - mean * mean).max(0.0).sqrt() / (n as f64).sqrt())
        };
        let n = 100_000;
        let (mean, se) = albedo(ScatteringOrder::All, n, &mut rng);
        let report = format!("all orders: N = {n}, mean {mean}, σ̂/√N {se}, z = {Z}, expected 1");
        println!("{report}");
        assert!(se <= 0.005, "not resolved: {report}");
        assert!((mean - 1.0).abs() <= Z * se, "{report}");

        let n = 200_000;
        let third = ScatteringOrder::only(3).expect("order 3");
        let (mean, se) = albedo(third, n, &mut rng);
        let walks = (0..n).filter(|_| pf.sample(wi, &mut rng).is_some_and(|s| s.bounces == 3)).count();
        let share = walks as f64 / n as f64;
        let share_se = (share * (1.0 - share) / n as f64).sqrt();
        let se_diff = (se * se + share_se * share_se).sqrt();
        let report =
            format!("order 3: N = {n}, BDPT mean {mean} (σ̂/√N {se}), walks {share} (SE {share_se}), z = {Z}");
        println!("{report}");
        assert!(se <= 0.0006, "not resolved: {report}");
        assert!((mean - share).abs() <= Z * se_diff, "{report}");
    }

    /// Russian roulette ends the paths lit from below a smooth surface (correlated shadowing):
    /// the mean number of sampled directions per evaluation of a perfect mirror seen from
    /// below, over ωo from the mixture of [`PositionFree::pdf`], is at most `bound` (a count,
    /// not a time): mean ≤ bound + z σ̂/√N with z = 3.6 (one-sided, Šidák over the 6 means at
    /// family-wise 1e-3) and σ̂/√N ≤ 0.25 asserted. Before the phase-peak cap of the survival
    /// probability (`Roulette::survival`), roulette never ended them: G1 of the next incident
    /// direction grows as fast as the throughput falls, and the mean was 182 extensions for PT
    /// and the 48-vertex cap for BDPT's camera sub-path at every a from 5 to 28.9 (Beckmann
    /// α = 0.02), 25 for GGX at a = 28.9; measured after: 3.8 and 2.5 (Beckmann), 16 (GGX).
    #[test]
    fn paths_from_below_end() {
        let beckmann = Beckmann::isotropic(0.02).expect("valid roughness");
        let ggx = crate::slope::Ggx::isotropic(0.02).expect("valid roughness");
        let correlated = Shadowing::Correlated;
        for theta in [95.71f32, 120.0] {
            let pf = PositionFree::new(beckmann, Conductor::perfect(), correlated);
            assert_paths_from_below_end(&pf, theta, "Beckmann", [6.0, 6.0]);
        }
        let pf = PositionFree::new(ggx, Conductor::perfect(), correlated);
        assert_paths_from_below_end(&pf, 120.0, "GGX", [20.0, 20.0]);
    }

    /// The mean counts of `paths_from_below_end` at θi = `theta` degrees: PT's extensions and
    /// the length of BDPT's camera sub-path, each at most its entry of `bounds`.
    fn assert_paths_from_below_end<S: MicrosurfaceSlope>(
        pf: &PositionFree<S, Conductor>,
        theta: f32,
        label: &str,
        bounds: [f64; 2],
    ) {
        const N: usize = 4000;
        const Z: f64 = 3.6;
        let t = theta.to_radians();
        let wi = Vec3::new(t.sin(), 0.0, t.cos());
        let mut rng = Pcg64Mcg::seed_from_u64(47);
        let mut counts = [[0.0f64; 2]; 2];
        for _ in 0..N {
            let wo = if uniform(&mut rng) < 1.0 - PDF_COSINE_SHARE {
                pf.material().sample_phase(pf.slope(), wi, Side::Outside, &mut rng).wo
            } else {
                cosine_hemisphere(uniform(&mut rng), uniform(&mut rng))
            };
            let (_, extensions) = pf.eval_pt_counted(wi, wo, ScatteringOrder::All, &mut rng);
            let (_, camera, _) = pf.eval_bdpt_counted(wi, wo, ScatteringOrder::All, &mut rng);
            for (c, x) in counts.iter_mut().zip([f64::from(extensions), camera as f64]) {
                c[0] += x;
                c[1] += x * x;
            }
        }
        for (name, (c, bound)) in
            ["PT extensions", "BDPT camera sub-path"].iter().zip(counts.iter().zip(bounds))
        {
            let mean = c[0] / N as f64;
            let sd = (c[1] / N as f64 - mean * mean).max(0.0).sqrt();
            let se = sd / (N as f64).sqrt();
            let report = format!(
                "{label} α = 0.02, θi = {theta}°, {name}: N = {N}, mean {mean}, σ̂ {sd}, σ̂/√N {se}, z = {Z}, bound {bound}"
            );
            println!("{report}");
            assert!(se <= 0.25, "not resolved: {report}");
            assert!(mean <= bound + Z * se, "{report}");
        }
    }

    /// The albedo ∫ f·cos dωo of the perfect mirror of `smooth_mirror` seen from
    /// `from_below()` by `estimator` is 1: the mean of f·cos/pdf over N directions drawn from
    /// the mixture whose density is [`PositionFree::pdf`] (0.8 phase sampling, 0.2 cosine)
    /// agrees within z σ̂/√N, and σ̂/√N ≤ `max_se`.
    fn assert_albedo_from_below_is_one(
        shadowing: Shadowing,
        estimator: Estimator,
        n: usize,
        max_se: f64,
        z: f64,
    ) {
        let wi = from_below();
        let pf = smooth_mirror(shadowing);
        let mut rng = Pcg64Mcg::seed_from_u64(43);
        let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let wo = if uniform(&mut rng) < 1.0 - PDF_COSINE_SHARE {
                pf.material().sample_phase(pf.slope(), wi, Side::Outside, &mut rng).wo
            } else {
                cosine_hemisphere(uniform(&mut rng), uniform(&mut rng))
            };
            let pdf = f64::from(pf.pdf(wi, wo));
            let f = match estimator {
                Estimator::Pt => pf.eval_pt(wi, wo, ScatteringOrder::All, &mut rng),
                Estimator::Bdpt => pf.eval_bdpt(wi, wo, ScatteringOrder::All, &mut rng),
            };
            let x = if pdf > 0.0 { f64::from(f.x) / pdf } else { 0.0 };
            (sum, sum_sq) = (sum + x, sum_sq + x * x);
        }
        let mean = sum / n as f64;
        let sd = (sum_sq / n as f64 - mean * mean).max(0.0).sqrt();
        let se = sd / (n as f64).sqrt();
        let report =
            format!("{estimator:?}, {shadowing:?}: N = {n}, mean {mean}, σ̂ {sd}, σ̂/√N {se}, z = {z}");
        assert!(se <= max_se, "not resolved: {report}");
        assert!((mean - 1.0).abs() <= z * se, "{report}");
    }
}
