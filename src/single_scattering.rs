//! The single-scattering microfacet BSDF with height-correlated Smith masking-shadowing, on
//! the whole sphere of incident directions: its evaluation, its sampling density and a sampler
//! that returns the sample with its density.

use crate::contract::is_direction;
use crate::material::{Material, Side};
use crate::path::{Incident, PathModel, Shadowing, VertexRole};
use crate::rng::uniform;
use crate::slope::MicrosurfaceSlope;
use glam::Vec3;
use rand::Rng;

/// An f32 value of ωi·(ωi + ωo) above this is positive in exact arithmetic (its rounding error
/// is below 3 ulps of 2, 4e-7).
pub(crate) const VISIBLE_SUM_MARGIN: f32 = 1e-6;

/// An outgoing direction sampled from the single-scattering BSDF, with its weight and density.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SingleSample {
    /// The outgoing direction ωo (unit).
    pub wo: Vec3,
    /// f·|cos θo|/pdf per RGB channel.
    pub weight: Vec3,
    /// The solid-angle density of ωo, the value [`SingleScattering::pdf`] gives at (ωi, ωo).
    pub pdf: f32,
}

/// The single-scattering microfacet BSDF of slope distribution `S` and material `M`: the
/// Cook–Torrance / Walter BSDF with height-correlated Smith masking-shadowing (Heitz 2014,
/// “Understanding the Masking-Shadowing Function”, eq. 99; Heitz et al. 2016, supplement
/// §3.2–3.4), extended to incident directions below the macrosurface for opaque materials
/// (a backfacing view under a normal map: Tokuyoshi's full-spherical masking
/// G1(ωi) = 1/|1 + Λ(ωi)|, Wang et al. 2022, eqs. 10 and 17).
///
/// Research-layer convention: `eval(wi, wo)` returns f·|cos θo| for light arriving from ωi and
/// leaving along ωo, both pointing away from the surface in the local frame:
///
/// * reflection: f·|cos θo| = F(ωi·ωh) D(ωh) G2(ωi, ωo) / (4 |cos θi|), with
///   G2 = 1/(1 + Λ(ωi) + Λ(ωo)) (from below: 1/(Λ(−ωi) + Λ(ωo)));
/// * transmission through a dielectric: Walter's BTDF with G2 = B(1 + Λ(ωi), 1 + Λ(−ωo)) (B the
///   beta function, supplement §3.4);
/// * diffuse facets: an unbiased one-sample estimate (the only stochastic case).
///
/// The sampler draws the visible normal from D_ωi exactly (on the whole sphere) and the event
/// from the material's phase function; its density is the phase function's, which is exact for
/// conductors and dielectrics ([`Material::EXACT_PHASE_PDF`]) and a documented approximation
/// for diffuse facets. It is the position-free model of Wang et al. 2022 truncated to one
/// vertex (`PositionFree::eval_single_scattering` with correlated shadowing), computed without
/// any of the multiple-scattering machinery.
///
/// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit direction
/// gives 0 from [`SingleScattering::eval`] and [`SingleScattering::pdf`] and `None` from
/// [`SingleScattering::sample`] (a debug assertion in debug builds).
///
/// # Examples
///
/// ```
/// use microsurface::glam::Vec3;
/// use microsurface::{ComplexIor, Conductor, Ggx};
/// use microsurface::research::SingleScattering;
/// use rand::SeedableRng;
///
/// let gold = SingleScattering::new(Ggx::isotropic(0.5)?, Conductor::new(ComplexIor::GOLD));
/// let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
/// let wi = Vec3::new(0.6, 0.0, 0.8);
/// // `None` when the reflected direction points into the surface (its probability is 1 − ∫pdf)
/// let s = (0..100).find_map(|_| gold.sample(wi, &mut rng)).expect("gold reflects");
/// // the sample carries its density, the one `pdf` gives at its direction
/// assert_eq!(s.pdf, gold.pdf(wi, s.wo));
/// // and its weight is f·|cos θo|/pdf there
/// let f_cos = gold.eval(wi, s.wo, &mut rng);
/// assert!((s.weight - f_cos / s.pdf).abs().max_element() <= 1e-5 * s.weight.max_element());
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SingleScattering<S, M> {
    /// The one-vertex position-free model with height-correlated shadowing: its incident
    /// states, exit data and relative shadowing factors are those of the single-scattering BSDF.
    model: PathModel<S, M>,
}

impl<S: MicrosurfaceSlope, M: Material> SingleScattering<S, M> {
    /// The single-scattering BSDF of the given slope distribution and material.
    #[inline]
    pub fn new(slope: S, material: M) -> Self {
        Self { model: PathModel::new(slope, material, Shadowing::Correlated) }
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

    /// f·|cos θo| (see the type's documentation); 0 for ωi on the horizon, for an opaque
    /// material's ωo at or below it and where ωi sees no microsurface. Exact (a few f32 ulps,
    /// the masking in f64) except for diffuse facets (unbiased estimate).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    #[inline]
    pub fn eval(&self, wi: Vec3, wo: Vec3, rng: &mut impl Rng) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        self.eval_unchecked(wi, wo, rng)
    }

    /// The density with which [`SingleScattering::sample`] draws ωo: the material's phase-function
    /// density (exact for conductors and dielectrics), except for a conductor with ωi and ωo
    /// above the horizon: D(ωh)/(4 A_s(ωi)) with A_s the area of the slope's reflection sampler
    /// (`sample_mirror_front`): the projected area A, or for GGX the bounded cap's
    /// A_b = (L + k cos θi)/2 ≤ A (Eto and Tokuyoshi 2023, eq. 8, see
    /// [`GgxBoundedCap`](crate::vndf::GgxBoundedCap)). GGX evaluates it in f32 from the unnormalized
    /// half vector (relative error below 4e-6 for every α and pair of directions), other
    /// slopes in f64 (a few f32 ulps); `sample` and `eval_with_pdf` return the same bits.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    #[inline]
    pub fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wo), 0.0; wi, wo);
        self.pdf_unchecked(wi, wo)
    }

    /// [`SingleScattering::eval`] and [`SingleScattering::pdf`] in one call, which share the
    /// half vector, D and Λ(ωi) where the material computes them together
    /// ([`Material::connection`]).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives (0, 0) (a debug assertion in debug builds).
    #[inline]
    pub fn eval_with_pdf(&self, wi: Vec3, wo: Vec3, rng: &mut impl Rng) -> (Vec3, f32) {
        require!(is_direction(wi) && is_direction(wo), (Vec3::ZERO, 0.0); wi, wo);
        self.eval_with_pdf_unchecked(wi, wo, rng)
    }

    /// Samples ωo: a visible normal from D_ωi (exact, whole sphere), the material's event, and
    /// the weight w·G2/G1(ωi) = f·|cos θo|/pdf (w the phase sample's weight: F for a conductor,
    /// the albedo of a diffuse facet, 1 for a dielectric), with the density of ωo
    /// ([`SingleScattering::pdf`] at the returned direction, bit for bit). The masking ratio
    /// is formed in f64 (from logarithms where Λ underflows, backfacing Beckmann views), so
    /// that the weight equals f·|cos θo|/pdf at the returned f32 direction to a few f32 ulps;
    /// for a conductor seen from above the horizon it is formed from the f32 projected areas
    /// (a few f32 ulps, see `sample_mirror_front`) and the density is GGX's f32 form (relative
    /// error below 4e-6, see
    /// [`SingleScattering::pdf`]), so the weight equals f·|cos θo|/pdf to within 1e-5 (with
    /// the Fresnel term taken at the sampled normal, see [`Conductor`](crate::Conductor)).
    /// `None` if ωi cannot light the material (on the horizon, or at the nadir of an opaque
    /// material) or the sampled direction cannot leave the surface. Resolution limit of
    /// backfacing Beckmann views below α ≈ 1e-3: see [`crate::research::PositionFree::sample_single`].
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` that is not a unit direction gives
    /// `None` (a debug assertion in debug builds).
    #[inline]
    pub fn sample(&self, wi: Vec3, rng: &mut impl Rng) -> Option<SingleSample> {
        require!(is_direction(wi), None; wi);
        self.sample_unchecked(wi, rng)
    }

    /// [`SingleScattering::eval`] for directions the caller has validated.
    #[inline(always)]
    pub(crate) fn eval_unchecked(&self, wi: Vec3, wo: Vec3, rng: &mut impl Rng) -> Vec3 {
        self.model.eval_single_scattering(wi, wo, rng)
    }

    /// The approximate density of the multiple-scattering techniques' samples that the
    /// renderer uses for MIS weights, for validated directions: 0.8 × this BSDF's sampling
    /// density plus 0.2 × a cosine lobe on ωo's side (see `PathModel::mis_pdf`).
    #[inline(always)]
    pub(crate) fn mis_pdf_unchecked(&self, wi: Vec3, wo: Vec3) -> f32 {
        self.model.mis_pdf(wi, wo)
    }

    /// [`SingleScattering::pdf`] for directions the caller has validated.
    #[inline(always)]
    pub(crate) fn pdf_unchecked(&self, wi: Vec3, wo: Vec3) -> f32 {
        if M::MIRROR_FACETS && wi.z > 0.0 && wo.z > 0.0 {
            return Self::mirror_density(&self.model.slope, wi, wo);
        }
        let (Some(start), Some(wo_side)) =
            (PathModel::<S, M>::incident(wi), PathModel::<S, M>::exit_side(wo))
        else {
            return 0.0;
        };
        self.density(start, wo, wo_side)
    }

    /// [`SingleScattering::eval_with_pdf`] for directions the caller has validated.
    #[inline(always)]
    pub(crate) fn eval_with_pdf_unchecked(&self, wi: Vec3, wo: Vec3, rng: &mut impl Rng) -> (Vec3, f32) {
        let (Some(at), Some(wo_side)) = (PathModel::<S, M>::incident(wi), PathModel::<S, M>::exit_side(wo))
        else {
            return (Vec3::ZERO, 0.0);
        };
        let k_in = self.model.incident_k(at);
        let front = at.in_frame().z > 0.0;
        if !front {
            // a backfacing ωi (under a normal map): `connect` forms the value (for k_in < 1 as
            // phase × relative shadowing, where the vertex term would underflow), and the
            // density is the phase function's, as `pdf` computes it
            let out = self.model.exit(wo, wo_side);
            let f_cos = self.model.connect_known(at, k_in, out, VertexRole::Last, rng).as_vec3();
            return (f_cos, self.density(at, wo, wo_side));
        }
        let m = &self.model.material;
        let (vertex, pdf) = if M::MIRROR_FACETS {
            // the density `pdf` and `sample` give (wo is above the horizon: `exit_side`)
            let vertex = m.vertex_unchecked(&self.model.slope, &at.to(wo, wo_side), rng);
            (vertex, Self::mirror_density(&self.model.slope, wi, wo))
        } else {
            let (vertex, pdf, _) = m.connection_unchecked(&self.model.slope, &at.to(wo, wo_side), rng);
            (vertex, pdf)
        };
        let factor = self.model.shadowing_factor(at, k_in, self.model.exit(wo, wo_side), VertexRole::Last);
        ((vertex.as_dvec3() * factor).as_vec3(), pdf)
    }

    /// [`SingleScattering::sample`] for a direction the caller has validated.
    #[inline(always)]
    pub(crate) fn sample_unchecked(&self, wi: Vec3, rng: &mut impl Rng) -> Option<SingleSample> {
        if M::MIRROR_FACETS && wi.z > 0.0 {
            // the uniforms in the order the material's own sampler draws them
            let (u1, u2) = (uniform(rng), uniform(rng));
            return Self::sample_mirror_front(&self.model.slope, &self.model.material, wi, u1, u2);
        }
        let at = PathModel::<S, M>::incident(wi)?;
        let (slope, m) = (&self.model.slope, &self.model.material);
        let s = m.sample_phase_unchecked(slope, at.w, at.side, rng);
        let k_in = self.model.incident_k(at);
        let out = self.model.exit(s.wo, s.side);
        let last = if let (true, Some(lambda_o), true) = (k_in >= 1.0, out.lambda, at.side == out.side) {
            // a reflection from a front-facing ωi: G2/G1 = (1 + Λi)/(1 + Λi + Λo), one division
            // (the relative factor 1/(1 + Λo/k_in) of the general form below, to an f64 ulp)
            k_in / (k_in + lambda_o)
        } else {
            self.model.relative_shadowing(at, k_in, out).last
        };
        let weight = s.weight * last as f32;
        if !(last > 0.0 && weight.is_finite()) {
            return None;
        }
        // the density at the returned f32 direction, as `pdf` computes it
        let pdf = m.pdf_phase_unchecked(slope, &at.to(s.wo, s.side));
        Some(SingleSample { wo: s.wo, weight, pdf })
    }

    /// [`SingleScattering::sample`] of mirror facets ([`Material::MIRROR_FACETS`]: conductors)
    /// seen from above the horizon (ωi.z > 0, unit), from the two uniforms of the visible
    /// normal: ωm from the slope's reflection sampler
    /// ([`MicrosurfaceSlope::sample_mirror_normal_unchecked`]: D_ωi, or GGX's bounded cap of
    /// area A_s = A_b, which leaves out only normals that reflect below the horizon),
    /// ωo = reflect(ωi, ωm), the weight F·G2 A_s/zi = F·(G2/G1)·(A_s/Ai) with G2/G1 = (1 + Λi)/(1 +
    /// Λi + Λo) from the f32 projected areas A = (1 + Λ) cos θ, as As zo/(Ai zo + zi (Ao − zo))
    /// (z = cos θ; one division, and Ai is the density's): the rounding of Ao − zo = Λo zo,
    /// which cancels where Λo is small, is at most ε Ao, and relative to the denominator (at
    /// least zi zo max(1, Λo)) that is at most 3ε, so the ratio keeps a few f32 ulps; and
    /// the density `pdf` gives at the returned direction. The weight is finite (F ∈ [0, 1],
    /// G2/G1 ∈ (0, 1]) and ωo unit (renormalized). `None` if ωo points into the surface or
    /// lies within rounding of −ωi (no visible half vector: eval is 0 there).
    /// Takes the slope and the material by reference (the renderer layer holds them, and
    /// copying them into a `SingleScattering` costs as much as a Λ).
    #[inline(always)]
    pub(crate) fn sample_mirror_front(
        slope: &S,
        material: &M,
        wi: Vec3,
        u1: f32,
        u2: f32,
    ) -> Option<SingleSample> {
        let (wm, area_s) = slope.sample_mirror_normal_unchecked(wi, u1, u2);
        let s = material.mirror_reflection_unchecked(wi, wm);
        let exits = s.wo.z > 0.0;
        if !exits {
            return None;
        }
        // G2/G1 = (1 + Λi)/(1 + Λi + Λo) with 1 + Λ = A/cos θ: Ai zo/(Ai zo + zi (Ao − zo)),
        // times As/Ai for a sampler of area As (f·cos/pdf = F G2 As/zi)
        let (zi, zo) = (wi.z, s.wo.z);
        let (area_i, area_o) = (slope.projected_area_unchecked(wi), slope.projected_area_unchecked(s.wo));
        let last = area_s * zo / (area_i * zo + zi * (area_o - zo));
        let pdf = Self::mirror_density_over(slope, wi, s.wo, area_s);
        (last > 0.0 && pdf > 0.0).then(|| SingleSample { wo: s.wo, weight: s.weight * last, pdf })
    }

    /// The density of a reflection of mirror facets ([`Material::MIRROR_FACETS`]) between ωi
    /// and ωo strictly above the horizon as `sample_mirror_front` draws it: D(ωh)/(4 A_s(ωi))
    /// from the slope ([`MicrosurfaceSlope::mirror_sampling_area_unchecked`] and
    /// [`MicrosurfaceSlope::reflection_density_over_unchecked`]; for GGX in f32, relative error
    /// below 4e-6), the one function `pdf`, `eval_with_pdf` and `sample` share, so that their
    /// densities agree bit for bit.
    /// 0 where the half vector is not a facet normal ωi can see (ωi·(ωi + ωo) ≤ 0, in f64 as
    /// the reflection half vector is tested for `eval`: only for ωo within
    /// rounding of −ωi, where the f32 directions' lengths decide the sign).
    #[inline(always)]
    pub(crate) fn mirror_density(slope: &S, wi: Vec3, wo: Vec3) -> f32 {
        Self::mirror_density_over(slope, wi, wo, slope.mirror_sampling_area_unchecked(wi))
    }

    /// [`Self::mirror_density`] with the sampler's area A_s(ωi) known (the sampler returns it).
    #[inline(always)]
    fn mirror_density_over(slope: &S, wi: Vec3, wo: Vec3, area_s: f32) -> f32 {
        // the f32 dot product of ωi with ωi + ωo (|ωi + ωo| ≤ 2) is within 4e-7 of the exact one
        let visible = wi.dot(wi + wo) > VISIBLE_SUM_MARGIN || {
            let w = wi.as_dvec3();
            w.dot(w + wo.as_dvec3()) > 0.0
        };
        if !visible {
            return 0.0;
        }
        slope.reflection_density_over_unchecked(wi, wo, area_s)
    }

    /// The phase-function density of ωo from the incident state `at`.
    #[inline(always)]
    fn density(&self, at: Incident, wo: Vec3, wo_side: Side) -> f32 {
        self.model.material.pdf_phase_unchecked(&self.model.slope, &at.to(wo, wo_side))
    }
}
