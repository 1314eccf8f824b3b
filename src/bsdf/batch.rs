//! The batch interface: eval, pdf, eval_with_pdf and sample over many queries at once, in
//! structure-of-arrays slices, with the single-scattering GGX conductor and dielectric run in
//! vector lanes (sixteen f32 with AVX-512, eight with AVX2, four otherwise).
//!
//! # Layout
//!
//! Directions are three `&[f32]` slices (x, y, z), colours three, and every output is a slice
//! the caller provides (nothing is allocated). Consecutive queries fill a vector's lanes: each
//! coordinate of sixteen (or eight) queries is one 512-bit (or 256-bit) load, the layout a
//! wavefront renderer already keeps its rays in (Mitsuba 3 and Dr.Jit, pbrt-v4's GPU wavefront
//! queues) and the one SIMD code needs without transposes.
//!
//! # One formula, two control flows
//!
//! The lanes compute with the same kernels as the scalar calls (`crate::lanes`: GGX Λ, projected
//! area, D and reflection density, the spherical-cap visible normal, the conductor and dielectric
//! Fresnel terms, G2 and G2/G1), generic over the lane type; the transmission's height-correlated
//! G2, a beta function, with the lane form of `crate::special` (the scalar path forms it from f64
//! log-gammas). Where the scalar path branches to a rare form (a half vector within rounding of
//! −ωi, a subnormal density, a cap point near −v̂, a beta function below the normal f32 range,
//! a near-perpendicular facet's Fresnel cosine, a dielectric's Fresnel cosine near the critical
//! angle, a backfacing view, an invalid argument), the lanes compute a mask of the queries
//! their common path covers, and every other query is answered by the scalar call itself. A bad lane therefore gets exactly the scalar contract's
//! answer and its neighbours are untouched.
//!
//! # Accuracy
//!
//! The lanes are f32 throughout. The scalar evaluation forms the half vector, D, Λ and the
//! shadowing in f64; the lanes form D from the unnormalized half vector (homogeneous of degree
//! 0: sums of squares only) and G2/G1 from the projected areas, both of which keep a few f32
//! ulps without f64 (see `tests/batch.rs` for the measured bounds). Densities and samples of a
//! front-facing conductor are the scalar path's f32 kernels themselves: equal bit for bit.

use super::{Bsdf, MicrofacetBsdf, SpecularLimit, Technique};
use crate::error::Error;
use crate::fresnel::{fresnel_dielectric_cosines_of, reflectance_of, transmittance_dielectric_cosines_of};
use crate::lanes::{LaneLoop, Lanes, V3, dispatch};
use crate::material::{LaneMaterial, Material, g2_over_g1_of, reflectance_scaled_of, refraction_scale};
use crate::single_scattering::VISIBLE_SUM_MARGIN;
use crate::slope::{
    F32_DENSITY_MIN_SUM, MicrosurfaceSlope, bounded_area_of, d_of_sum, kappa_of, lambda_and_area_of,
    reflection_density_of, sample_cap_of, sample_cap_scaled_of,
};
use crate::soa::{Channels, Directions, check_len, next_marked};
use crate::special::{beta_1p_of, ln_beta_1p_of};
use glam::{Vec2, Vec3, Vec3A};

/// The outputs of [`BatchBsdf::sample_batch`], one element per query: the sampled direction,
/// the weight f·|cos θi|/pdf, the density and the relative index η_wi/η_wo. A query with no
/// sample (where [`Bsdf::sample`] returns `None`) gets the zero direction, a zero weight, pdf 0
/// and η 1; every sample has pdf > 0.
#[derive(Debug)]
pub struct SampleOutputs<'a> {
    /// The sampled directions ωi.
    pub wi: Channels<'a>,
    /// The weights per RGB channel.
    pub weight: Channels<'a>,
    /// The densities (0: no sample).
    pub pdf: &'a mut [f32],
    /// η_wi/η_wo (1 for a reflection).
    pub eta: &'a mut [f32],
}

impl SampleOutputs<'_> {
    fn check(&self, n: usize) -> Result<(), Error> {
        self.wi.check("wi", n)?;
        self.weight.check("weight", n)?;
        check_len("pdf", n, self.pdf.len())?;
        check_len("eta", n, self.eta.len())
    }

    /// Writes the scalar call's answer for query `i`.
    #[inline]
    pub(crate) fn set(&mut self, i: usize, s: Option<super::BsdfSample>) {
        match s {
            Some(s) => {
                self.wi.set(i, s.wi);
                self.weight.set(i, s.weight);
                self.pdf[i] = s.pdf;
                self.eta[i] = s.eta;
            }
            None => {
                self.wi.set(i, Vec3::ZERO);
                self.weight.set(i, Vec3::ZERO);
                self.pdf[i] = 0.0;
                self.eta[i] = 1.0;
            }
        }
    }
}

/// [`Bsdf`]'s calls over many queries at once: query i of each method is the plain call
/// (`eval`, `pdf`, `eval_with_pdf`, `sample`, key 0) on element i of every slice, up to the
/// bounds each implementation states. Object safe, like [`Bsdf`]: a scene can hold
/// `Vec<Box<dyn BatchBsdf>>` and hand each material the queries of its hits.
///
/// Slices of unequal length are rejected with [`Error::LengthMismatch`] before anything is
/// written. An invalid argument in one query (a direction that is not unit, a uniform outside
/// [0, 1)) gives that query the scalar call's *nothing* (with its debug assertion) and leaves
/// the others untouched.
///
/// The provided methods call the scalar methods query by query. The crate's lobes override
/// them:
///
/// * [`MicrofacetBsdf`]: vectorized loops for single scattering on GGX conductors and
///   dielectrics (η at least 0.05 from 1), the scalar calls for every other configuration;
///   the bounds against the scalar calls are stated on its implementation.
/// * [`Compensated`](crate::Compensated) of a conductor or a dielectric, every scheme: the
///   batch of its single-scattering lobe (in lanes where that has them), then each query's
///   compensation by the scalar calls' own expressions, so that the single-scattering bounds
///   carry over (a conductor's densities bit for bit). Turquin's samples are the
///   single-scattering batch samples with the scalar call's weight factor; the additive
///   schemes sample by the scalar call, query by query.
///
/// # Examples
/// ```
/// use microsurface::{BatchBsdf, Bsdf, Channels, ComplexIor, Conductor, Directions, Ggx};
/// use microsurface::{MicrofacetBsdf, Technique};
///
/// let gold = MicrofacetBsdf::new(Ggx::isotropic(0.5)?, Conductor::new(ComplexIor::GOLD))?
///     .with_technique(Technique::SingleScattering);
/// let wo = ([0.0f32; 16], [0.6f32; 16], [0.8f32; 16]);
/// let wi = ([0.6f32; 16], [0.0f32; 16], [0.8f32; 16]);
/// let (wo, wi) = (Directions::new(&wo.0, &wo.1, &wo.2)?, Directions::new(&wi.0, &wi.1, &wi.2)?);
/// let (mut r, mut g, mut b, mut pdf) = ([0.0; 16], [0.0; 16], [0.0; 16], [0.0; 16]);
/// gold.eval_with_pdf_batch(&wo, &wi, &mut Channels::new(&mut r, &mut g, &mut b), &mut pdf)?;
/// let (f, p) = gold.eval_with_pdf(microsurface::glam::Vec3::new(0.0, 0.6, 0.8), microsurface::glam::Vec3::new(0.6, 0.0, 0.8));
/// assert_eq!(pdf[3], p);
/// assert!((r[3] - f.f.x).abs() <= 1e-5 * f.f.x);
/// # Ok::<(), microsurface::Error>(())
/// ```
pub trait BatchBsdf: Bsdf {
    /// f of every query: `f` receives [`Bsdf::eval`]`(wo[i], wi[i]).f`.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] if a slice is not as long as `wo`.
    fn eval_batch(
        &self,
        wo: &Directions<'_>,
        wi: &Directions<'_>,
        f: &mut Channels<'_>,
    ) -> Result<(), Error> {
        let n = wo.len();
        check_len("wi", n, wi.len())?;
        f.check("f", n)?;
        for i in 0..n {
            f.set(i, self.eval(wo.get(i), wi.get(i)).f);
        }
        Ok(())
    }

    /// The density of every query: `pdf` receives [`Bsdf::pdf`]`(wo[i], wi[i])`.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] if a slice is not as long as `wo`.
    fn pdf_batch(&self, wo: &Directions<'_>, wi: &Directions<'_>, pdf: &mut [f32]) -> Result<(), Error> {
        let n = wo.len();
        check_len("wi", n, wi.len())?;
        check_len("pdf", n, pdf.len())?;
        for (i, p) in pdf.iter_mut().enumerate() {
            *p = self.pdf(wo.get(i), wi.get(i));
        }
        Ok(())
    }

    /// [`BatchBsdf::eval_batch`] and [`BatchBsdf::pdf_batch`] in one pass
    /// ([`Bsdf::eval_with_pdf`]).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] if a slice is not as long as `wo`.
    fn eval_with_pdf_batch(
        &self,
        wo: &Directions<'_>,
        wi: &Directions<'_>,
        f: &mut Channels<'_>,
        pdf: &mut [f32],
    ) -> Result<(), Error> {
        let n = wo.len();
        check_len("wi", n, wi.len())?;
        f.check("f", n)?;
        check_len("pdf", n, pdf.len())?;
        for (i, slot) in pdf.iter_mut().enumerate() {
            let (v, p) = self.eval_with_pdf(wo.get(i), wi.get(i));
            f.set(i, v.f);
            *slot = p;
        }
        Ok(())
    }

    /// A sample for every query: [`Bsdf::sample`]`(wo[i], uc[i], (u1[i], u2[i]))`, written to
    /// `out` (see [`SampleOutputs`] for a query without a sample).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] if a slice is not as long as `wo`.
    fn sample_batch(
        &self,
        wo: &Directions<'_>,
        uc: &[f32],
        u1: &[f32],
        u2: &[f32],
        out: &mut SampleOutputs<'_>,
    ) -> Result<(), Error> {
        sample_each(self, wo, uc, u1, u2, out)
    }
}

/// [`BatchBsdf::sample_batch`] by the scalar call query by query.
pub(crate) fn sample_each<B: Bsdf + ?Sized>(
    bsdf: &B,
    wo: &Directions<'_>,
    uc: &[f32],
    u1: &[f32],
    u2: &[f32],
    out: &mut SampleOutputs<'_>,
) -> Result<(), Error> {
    let n = check_sample_lengths(wo, uc, u1, u2, out)?;
    for i in 0..n {
        out.set(i, bsdf.sample(wo.get(i), uc[i], Vec2::new(u1[i], u2[i])));
    }
    Ok(())
}

fn check_sample_lengths(
    wo: &Directions<'_>,
    uc: &[f32],
    u1: &[f32],
    u2: &[f32],
    out: &SampleOutputs<'_>,
) -> Result<usize, Error> {
    let n = wo.len();
    check_len("uc", n, uc.len())?;
    check_len("u1", n, u1.len())?;
    check_len("u2", n, u2.len())?;
    out.check(n)?;
    Ok(n)
}

/// The lane kernels a [`MicrofacetBsdf`] runs its batch calls with.
#[derive(Debug, Clone, Copy)]
enum Kernel {
    /// GGX (αx, αy) conductor with the Fresnel constants per channel (`None`: F = 1).
    Conductor { ax: f32, ay: f32, fresnel: Option<(Vec3A, Vec3A)> },
    /// GGX (αx, αy) dielectric of index η (and 1/η as the material keeps it); `transport`:
    /// the transport factor of a transmission from above (1/η² for radiance, 1 for
    /// importance), `eta_out` the relative index a transmission's sample reports.
    Dielectric { ax: f32, ay: f32, eta: f32, inv_eta: f32, transport: f32, eta_out: f32 },
}

impl<S: MicrosurfaceSlope, M: Material + SpecularLimit> MicrofacetBsdf<S, M> {
    /// The lane kernels of this BSDF: single scattering (not a Dirac lobe) on GGX, conductor or
    /// dielectric facets.
    fn kernel(&self) -> Option<Kernel> {
        if self.technique() != Technique::SingleScattering || self.is_specular() {
            return None;
        }
        let (ax, ay) = self.surface().slope().ggx_roughness()?;
        if ax.min(ay) < LANES_MIN_ALPHA {
            return None;
        }
        match self.surface().material().lane_material() {
            LaneMaterial::Conductor(fresnel) => Some(Kernel::Conductor { ax, ay, fresnel }),
            // near η = 1 the refraction half vector cancels: the f64 scalar path serves
            LaneMaterial::Dielectric(eta, inv_eta) if (eta - 1.0).abs() >= DIELECTRIC_LANES_MIN_CONTRAST => {
                let transport = self.transport_scale(Vec3::Z, Vec3::NEG_Z);
                let eta_out = self.relative_eta(Vec3::Z, Vec3::NEG_Z);
                Some(Kernel::Dielectric { ax, ay, eta, inv_eta, transport, eta_out })
            }
            _ => None,
        }
    }
}

/// The smallest αx and αy of a GGX lobe whose batch calls run in lanes; a lobe sharper along
/// one axis takes the scalar calls. Toward α = 0 the f32 kernels' intermediate terms leave the
/// normal range: the squared ratio of D's unnormalized form underflows off the sharp axis
/// (about α⁴/h.x⁴, from α ≈ 1e-10), D overflows f32 on it (below αx αy ≈ 1e-39), and at
/// α = 1e-6 the density of an in-plane refraction was already 1.06e-4 from the scalar call's
/// (the batch bound is 1e-4; within it at 1e-5). `tests/batch.rs`
/// (`extreme_anisotropy_batches_are_the_scalar_calls`) checks both sides.
const LANES_MIN_ALPHA: f32 = 1e-4;

/// The smallest |η − 1| of a dielectric whose batch calls run in lanes: |ωo + η ωi| ≥ |η − 1|,
/// so the f32 refraction half vector keeps 2⁻²⁴/0.05 of relative precision.
const DIELECTRIC_LANES_MIN_CONTRAST: f32 = 0.05;

/// Whether a direction is unit (`contract::is_direction`, every lane type).
#[inline(always)]
fn is_direction<L: Lanes>(w: V3<L>) -> L::Mask {
    (w.length_squared() - L::lit(1.0)).abs().le(L::lit(crate::contract::DIRECTION_TOLERANCE))
}

/// A density is one the lanes return where it is a normal f32 (the scalar form's test).
#[inline(always)]
fn normal<L: Lanes>(x: L) -> L::Mask {
    x.ge(L::lit(f32::MIN_POSITIVE)) & x.lt(L::lit(f32::INFINITY))
}

/// The conductor's Fresnel term per channel at cos θ (`conductor_reflectance`).
#[inline(always)]
fn conductor_fresnel<L: Lanes>(fresnel: Option<(Vec3A, Vec3A)>, cos: L) -> [L; 3] {
    match fresnel {
        None => [L::lit(1.0); 3],
        Some((t0, m)) => {
            let c = cos.abs().min(L::lit(1.0));
            let grazing = c.eq(L::lit(0.0));
            let channel =
                |t: f32, k: f32| L::select(grazing, L::lit(1.0), reflectance_of(c, L::lit(t), L::lit(k)));
            [channel(t0.x, m.x), channel(t0.y, m.y), channel(t0.z, m.z)]
        }
    }
}

/// Within this of 0, η² cos² θt = cos² θ + η² − 1 (a cosine near the critical angle of η < 1)
/// leaves a reflection to the scalar call: F has an infinite slope in cos θ at the critical
/// angle, and the lanes' f32 cosine (a few ulps from the scalar's f64 one) moves it by up to
/// 6e-4 relative below 0.01, by at most 1e-5 above it (2²⁰ queries each for η = 1/1.33, 1/1.5
/// and 1/2.5).
const CRITICAL_MARGIN: f32 = 0.01;

/// The dielectric's Fresnel reflectance at cos θ = `c` ∈ [0, 1] with index η
/// (`dielectric_reflectance`, in f32), and whether c is clear of the critical angle
/// ([`CRITICAL_MARGIN`]; always for η ≥ 1 + 0.05).
#[inline(always)]
fn dielectric_fresnel<L: Lanes>(eta: L, c: L) -> (L, L::Mask) {
    let one = L::lit(1.0);
    let c = c.abs().min(one);
    let eta2_cos2_t = c * c + (eta - one) * (eta + one);
    let total = eta2_cos2_t.le(L::lit(0.0));
    let t = eta2_cos2_t.max(L::lit(0.0)).sqrt() / eta;
    let clear = eta2_cos2_t.abs().ge(L::lit(CRITICAL_MARGIN));
    (L::select(total, one, fresnel_dielectric_cosines_of(c, t, eta)), clear)
}

/// Single scattering of a front-facing reflection (ωo, ωi both above the horizon, renderer
/// orientation: the walk enters along ωo): the density D(ωh)/(4 A(ωo)) from the unnormalized
/// h = ωo + ωi, G2/G1(ωo) from the projected areas and the cosine ωo·ωh. f = w·pdf·(G2/G1)/cos θi
/// with w the facet's weight (Fresnel). `ok`: where the density is the scalar f32 form's and
/// ωh is clearly visible.
#[inline(always)]
fn front_reflection<L: Lanes>(ax: L, ay: L, wo: V3<L>, wi: V3<L>) -> (L, L, L, L::Mask) {
    let h = wo.add(wi);
    let wo_h = wo.dot(h);
    let visible = wo_h.gt(L::lit(VISIBLE_SUM_MARGIN));
    let (_, area_o) = lambda_and_area_of(ax, ay, wo);
    let (_, area_i) = lambda_and_area_of(ax, ay, wi);
    let (density, len_sq, t) = reflection_density_of(ax, ay, h, area_o);
    let min = L::lit(F32_DENSITY_MIN_SUM);
    let ok = visible & len_sq.ge(min) & t.ge(min) & normal(density);
    let g2_over_g1 = g2_over_g1_of(area_o, area_i, wo.z, wi.z);
    (density, g2_over_g1, wo_h / len_sq.sqrt(), ok)
}

/// Below these cosines (relative to |ωo + η ωi|) a refraction is left to the scalar f64 form:
/// the validity tests of the half vector change sign within f32 rounding there.
const REFRACTION_MARGIN: f32 = 1e-4;

/// The density of a refraction from ωo (above) to ωi (below) through a GGX dielectric of
/// index η (the phase function of `Dielectric`, Heitz et al. 2016, supplement §3.4):
/// η² (1 − F) D_ωo(ωh) |ωi·ωh|/(ωo·ωh + η ωi·ωh)², with ωh ∝ −(ωo + η ωi) turned up, D from
/// the unnormalized sum ([`d_of_sum`]), and Λ(ωo). `valid`: where the half vector's validity
/// tests (ωh.z > 0, ωo·ωh > 0 > ωi·ωh) hold with a margin (the density is 0 elsewhere); `ok`:
/// where they hold or fail with a margin.
#[inline(always)]
fn transmission_density<L: Lanes>(ax: L, ay: L, eta: L, wo: V3<L>, wi: V3<L>) -> (L, L, L::Mask, L::Mask) {
    let zero = L::lit(0.0);
    let sum = wo.add(wi.scale(eta));
    let up = sum.z.gt(zero);
    let h = V3::select(up, sum, V3::new(-sum.x, -sum.y, -sum.z));
    let len_sq = h.length_squared();
    let len = len_sq.sqrt();
    let inv_len = L::lit(1.0) / len;
    let (cos_ih, cos_oh) = (wo.dot(h) * inv_len, wi.dot(h) * inv_len);
    let margin = L::lit(REFRACTION_MARGIN);
    let valid = h.z.gt(margin * len) & cos_ih.gt(margin) & cos_oh.lt(-margin);
    let invalid = h.z.lt(-margin * len) | cos_ih.lt(-margin) | cos_oh.gt(margin);
    let d = d_of_sum(ax, ay, h, L::lit(core::f32::consts::FRAC_1_PI));
    let (lambda, area) = lambda_and_area_of(ax, ay, wo);
    let transmittance = transmittance_dielectric_cosines_of(cos_ih, -cos_oh, eta);
    // D_ωo(ωh) = cos_ih D/A(ωo) and the Jacobian's 1/|h|² under one division
    let pdf = eta * eta * transmittance * (cos_ih * d) * (-cos_oh) / (area * len_sq);
    let sane = len.gt(L::lit(DIELECTRIC_LANES_MIN_CONTRAST)) & len_sq.ge(L::lit(F32_DENSITY_MIN_SUM));
    (L::select(valid, pdf, zero), lambda, valid, sane & (valid | invalid))
}

/// Below this ln B the transmission's shadowing B(1 + Λ(ωo), 1 + Λ(−ωi)) leaves the normal
/// f32 range of [`beta_1p_of`]: the scalar call answers.
const LN_BETA_MIN: f32 = -87.0;

/// f of a refraction from ωo (above) to ωi (below) through a GGX dielectric (Walter et al.
/// 2007, eq. 21, with the height-correlated masking-shadowing of Heitz 2014, eq. 99, as the
/// scalar `Dielectric` evaluates it, supplement §3.4 of Heitz et al. 2016):
///
/// f = |ωo·ωh| |ωi·ωh| η² (1 − F) D(ωh) B(1 + Λ(ωo), 1 + Λ(−ωi)) / (cos θo |cos θi| (ωo·ωh + η ωi·ωh)²) · s
///   = pdf · (1 + Λ(ωo)) B(1 + Λ(ωo), 1 + Λ(−ωi)) · s/|cos θi|,
///
/// pdf the density of [`transmission_density`] (D_ωo = |ωo·ωh| D/((1 + Λ(ωo)) cos θo)) and s the
/// transport factor. `ok`: where f is a normal f32 and ln B ≥ [`LN_BETA_MIN`], or the pair is
/// not a refraction (f = 0).
#[inline(always)]
fn transmission_value<L: Lanes>(
    ax: L,
    ay: L,
    transport: L,
    wi: V3<L>,
    pdf: L,
    lambda_o: L,
    valid: L::Mask,
) -> (L, L::Mask) {
    let (g2_over_g1, in_range) = transmission_g2_over_g1(ax, ay, wi, lambda_o);
    let f = pdf * g2_over_g1 * (transport / -wi.z);
    let f = L::select(valid, f, L::lit(0.0));
    (f, (valid & in_range & normal(f)) | !valid)
}

/// G2/G1(ωo) of a refraction from ωo (above, Λ(ωo) = `lambda_o`) to ωi (below):
/// (1 + Λ(ωo)) B(1 + Λ(ωo), 1 + Λ(−ωi)) (Heitz 2014, eq. 99, over G1 = 1/(1 + Λ(ωo))), and
/// whether ln B ≥ [`LN_BETA_MIN`] (else the scalar call answers).
#[inline(always)]
fn transmission_g2_over_g1<L: Lanes>(ax: L, ay: L, wi: V3<L>, lambda_o: L) -> (L, L::Mask) {
    let (lambda_i, _) = lambda_and_area_of(ax, ay, V3::new(-wi.x, -wi.y, -wi.z));
    let ln_b = ln_beta_1p_of(lambda_o, lambda_i);
    ((L::lit(1.0) + lambda_o) * beta_1p_of(ln_b), ln_b.ge(L::lit(LN_BETA_MIN)))
}

/// f as the trait returns it: 0 where not finite.
#[inline(always)]
fn finite_or_zero<L: Lanes>(x: L) -> L {
    L::select(x.abs().lt(L::lit(f32::INFINITY)), x, L::lit(0.0))
}

/// What a batch loop computes per query (a const parameter of the loop, so that a density-only
/// loop carries no Fresnel term).
struct Want;

impl Want {
    const EVAL: u8 = 1;
    const PDF: u8 = 2;
    const BOTH: u8 = 3;
}

/// The evaluation of one query of a GGX conductor (renderer orientation) in the common path of
/// the kernels: f, the density, and whether they are the answer (else the scalar call gives it).
#[inline(always)]
fn evaluate_conductor<L: Lanes, const WANT: u8>(
    ax: f32,
    ay: f32,
    fresnel: Option<(Vec3A, Vec3A)>,
    wo: V3<L>,
    wi: V3<L>,
) -> ([L; 3], L, L::Mask) {
    let zero = L::lit(0.0);
    let front = is_direction(wo) & is_direction(wi) & wo.z.gt(zero);
    let above = front & wi.z.gt(zero);
    // a light at or below the horizon of a view from above: no reflection, f = pdf = 0
    let below = front & wi.z.le(zero);
    let (axl, ayl) = (L::lit(ax), L::lit(ay));
    if WANT == Want::PDF {
        // the density alone: no projected area of ωo, no f
        let (pdf, ok_b, wo_h) = bounded_reflection_density(axl, ayl, wo, wi);
        let visible = wo_h.gt(L::lit(VISIBLE_SUM_MARGIN));
        return ([zero; 3], L::select(above, pdf, zero), (above & visible & ok_b) | below);
    }
    let (density, g2_over_g1, cos, ok) = front_reflection(axl, ayl, wo, wi);
    let w = conductor_fresnel(fresnel, cos);
    let scale = density * g2_over_g1 / wi.z;
    let f = w.map(|w| finite_or_zero(L::select(above, w * scale, zero)));
    if WANT & Want::PDF == 0 {
        return (f, zero, (above & ok) | below);
    }
    let (pdf, ok_b, _) = bounded_reflection_density(axl, ayl, wo, wi);
    (f, L::select(above, pdf, zero), (above & ok & ok_b) | below)
}

/// The density of a GGX reflection from the bounded cap the sampler draws from,
/// D(ωh)/(4 A_b(ωo)) with h = ωo + ωi unnormalized, whether it is the scalar f32 form's, and
/// ωo·h.
#[inline(always)]
fn bounded_reflection_density<L: Lanes>(ax: L, ay: L, wo: V3<L>, wi: V3<L>) -> (L, L::Mask, L) {
    let h = wo.add(wi);
    let area_b = bounded_area_of(ax, ay, wo, kappa_of(ax.min(ay), wo));
    let (pdf, len_sq, t) = reflection_density_of(ax, ay, h, area_b);
    let min = L::lit(F32_DENSITY_MIN_SUM);
    (pdf, len_sq.ge(min) & t.ge(min) & normal(pdf), wo.dot(h))
}

/// [`evaluate_conductor`] for a GGX dielectric of index η and transport factor `transport`:
/// reflections and transmissions from above.
#[inline(always)]
fn evaluate_dielectric<L: Lanes, const WANT: u8>(
    ax: f32,
    ay: f32,
    eta: f32,
    transport: f32,
    wo: V3<L>,
    wi: V3<L>,
) -> ([L; 3], L, L::Mask) {
    let zero = L::lit(0.0);
    let front = is_direction(wo) & is_direction(wi) & wo.z.gt(zero);
    let above = front & wi.z.gt(zero);
    let below = front & wi.z.lt(zero);
    let (ax, ay, eta) = (L::lit(ax), L::lit(ay), L::lit(eta));
    let (density, g2_over_g1, cos, ok) = front_reflection(ax, ay, wo, wi);
    let (fr, clear) = dielectric_fresnel(eta, cos);
    let ok = ok & clear;
    let (pdf_transmit, lambda_o, valid_t, ok_t) = transmission_density(ax, ay, eta, wo, wi);
    let pdf = L::select(above, fr * density, pdf_transmit);
    let reflected = L::select(above, fr * density * g2_over_g1 / wi.z, zero);
    if WANT == Want::PDF {
        return ([finite_or_zero(reflected); 3], pdf, (above & ok) | (below & ok_t));
    }
    let (transmitted, ok_f) =
        transmission_value(ax, ay, L::lit(transport), wi, pdf_transmit, lambda_o, valid_t);
    let f = finite_or_zero(L::select(above, reflected, L::select(below, transmitted, zero)));
    ([f; 3], pdf, (above & ok) | (below & ok_t & ok_f))
}

/// The sample of a GGX conductor seen from above (`SingleScattering::sample_mirror_front` and
/// `exact_reflection`, renderer orientation): wi, weight, pdf (0: no sample) and whether they
/// are the answer (else the scalar call gives it).
#[inline(always)]
fn sample_conductor<L: Lanes>(
    ax: f32,
    ay: f32,
    fresnel: Option<(Vec3A, Vec3A)>,
    wo: V3<L>,
    uc: L,
    u1: L,
    u2: L,
) -> (V3<L>, [L; 3], L, L::Mask) {
    let (zero, one) = (L::lit(0.0), L::lit(1.0));
    let (axl, ayl) = (L::lit(ax), L::lit(ay));
    let uniform = |u: L| u.ge(zero) & u.lt(one);
    let valid = is_direction(wo) & wo.z.gt(zero) & uniform(uc) & uniform(u1) & uniform(u2);
    // the bounded cap of Eto and Tokuyoshi 2023 (`sample_bounded_cap`, a view above the horizon)
    let kappa = kappa_of(axl.min(ayl), wo);
    let area_s = bounded_area_of(axl, ayl, wo, kappa);
    let (m, cap_ok) = sample_cap_of(axl, ayl, wo, kappa, u1, u2);
    let c = wo.dot(m);
    // the reflection, renormalized by one Newton step (`renormalize`'s common path)
    let k = L::lit(2.0) * c;
    let r = V3::new(k * m.x - wo.x, k * m.y - wo.y, k * m.z - wo.z);
    let r_len_sq = r.length_squared();
    let nearly_unit = (r_len_sq - one).abs().le(L::lit(1.0 / 4096.0));
    let wi = r.scale(L::lit(1.5) - L::lit(0.5) * r_len_sq);
    let exits = wi.z.gt(zero);
    let (_, area_o) = lambda_and_area_of(axl, ayl, wo);
    let (_, area_i) = lambda_and_area_of(axl, ayl, wi);
    // G2/G1 times A_s/A(ωo): f·cos θi/pdf = F G2 A_s/cos θo (`sample_mirror_front`)
    let last = area_s * wi.z / (area_o * wi.z + wo.z * (area_i - wi.z));
    let h = wo.add(wi);
    let visible = wo.dot(h).gt(L::lit(VISIBLE_SUM_MARGIN));
    let (density, len_sq, t) = reflection_density_of(axl, ayl, h, area_s);
    let min = L::lit(F32_DENSITY_MIN_SUM);
    let density_ok = visible & len_sq.ge(min) & t.ge(min) & normal(density);
    let weight = conductor_fresnel(fresnel, c).map(|w| w * last);
    let w_max = weight[0].max(weight[1]).max(weight[2]);
    // the sample's f = weight·pdf/cos θi is clearly a normal f32 (the scalar test in f64 is
    // weight·pdf ≥ f32::MIN_POSITIVE·cos θi)
    let usable = last.gt(zero) & (w_max * density).ge(L::lit(1e-30)) & w_max.lt(L::lit(f32::INFINITY));
    // a Fresnel cosine below 0.05 is taken from the half vector in f64 by the scalar path
    let fresnel_common =
        if fresnel.is_some() { c.ge(L::lit(FRESNEL_AT_HALF_VECTOR_BELOW)) } else { zero.le(zero) };
    let common = cap_ok & fresnel_common & nearly_unit;
    let some = exits & usable;
    let done = valid & common & (!exits | (density_ok & usable));
    let keep = |x: L| L::select(some, x, zero);
    (V3::new(keep(wi.x), keep(wi.y), keep(wi.z)), weight.map(keep), keep(density), done)
}

/// Below this ωo·ωm a conductor's sampled Fresnel weight takes the half vector's cosine in f64
/// (`Conductor`'s `FRESNEL_AT_HALF_VECTOR_BELOW`): the scalar sampler serves those lanes.
const FRESNEL_AT_HALF_VECTOR_BELOW: f32 = 0.05;

/// A uniform as the scalar sampler draws it from the caller's: ⌊u·2²⁴⌋·2⁻²⁴ for u ∈ [0, 1)
/// (the primed generator's resolution, `bsdf::seed::uniform_bits`), exact.
#[inline(always)]
fn primed_uniform(u: f32) -> f32 {
    const SCALE: f32 = 16_777_216.0;
    ((u * SCALE) as i32) as f32 * (1.0 / SCALE)
}

/// The sample of a GGX dielectric seen from above (`Dielectric`'s `sample_at_facet` and
/// `SingleScattering::sample`, renderer orientation; Heitz et al. 2016, supplement §3.4,
/// Algorithm 7): ωm from the whole visible cap, taken up to its scale m = l ωm, reflection
/// where uc < F(ωo·ωm), refraction otherwise. F (from ωo·m and l²) and the refraction's
/// (ωo·m − l η cos θt)/l² are formed in f64 as the scalar sampler forms them
/// ([`reflectance_scaled_of`], [`refraction_scale`]), so that the event and the direction are the
/// scalar's bit for bit; the weight G2/G1(ωo) (a reflection's from the projected areas, a
/// transmission's the beta function of [`transmission_g2_over_g1`]) times the transport factor,
/// and the density ([`front_reflection`], [`transmission_density`]), in f32. Returns ωi, the
/// weight, the density (0: no sample), η_wi/η_wo and whether they are the answer (else the
/// scalar call gives it).
#[inline(always)]
fn sample_dielectric(
    k: &DielectricQuery,
    wo: V3<f32>,
    uc: f32,
    u1: f32,
    u2: f32,
) -> (V3<f32>, f32, f32, f32, bool) {
    let (ax, ay, eta) = (k.ax, k.ay, k.eta);
    let uniform = |u: f32| (0.0..1.0).contains(&u);
    let valid = is_direction(wo) & (wo.z > 0.0) & uniform(uc) & uniform(u1) & uniform(u2);
    // the normal up to its scale, m = l ωm, as `sample_at_facet` takes it
    let (m, m_len_sq, cap_ok) = sample_cap_scaled_of(ax, ay, wo, 2.0, primed_uniform(u1), primed_uniform(u2));
    let inv_len_sq = 1.0 / m_len_sq;
    let dot = wo.dot(m);
    let c = f64::from(dot.abs());
    let (fresnel, s) = reflectance_scaled_of(f64::from(eta), c, f64::from(m_len_sq));
    let reflects = primed_uniform(uc) < fresnel as f32;
    // `reflect_scaled` and `Dielectric::refract`, then the common path of `renormalize`
    let two_dot = 2.0 * dot * inv_len_sq;
    let r = V3::new(two_dot * m.x - wo.x, two_dot * m.y - wo.y, two_dot * m.z - wo.z);
    let cs = refraction_scale(c, s, inv_len_sq);
    let inv_eta = k.inv_eta;
    let t = V3::new((cs * m.x - wo.x) * inv_eta, (cs * m.y - wo.y) * inv_eta, (cs * m.z - wo.z) * inv_eta);
    let v = V3::select(reflects, r, t);
    let len_sq = v.length_squared();
    let nearly_unit = (len_sq - 1.0).abs() <= 1.0 / 4096.0;
    let wi = v.scale(1.5 - 0.5 * len_sq);
    let exits = if reflects { wi.z > 0.0 } else { wi.z < 0.0 };
    let (density, g2_over_g1_r, cos, ok_r) = front_reflection(ax, ay, wo, wi);
    let (fresnel_r, clear) = dielectric_fresnel(eta, cos);
    let pdf_r = fresnel_r * density;
    let (pdf_t, lambda_o, valid_t, ok_t) = transmission_density(ax, ay, eta, wo, wi);
    let (g2_over_g1_t, in_range) = transmission_g2_over_g1(ax, ay, wi, lambda_o);
    let (weight, pdf, density_ok) = if reflects {
        (g2_over_g1_r, pdf_r, ok_r & clear)
    } else {
        (g2_over_g1_t * k.transport, pdf_t, valid_t & ok_t & in_range)
    };
    // clearly a sample (`finish_sample`'s test is weight·pdf ≥ f32::MIN_POSITIVE·|cos θi|)
    let usable = weight > 0.0 && weight < f32::INFINITY && normal(pdf) && weight * pdf >= 1e-30;
    let some = exits & usable;
    let done = valid & cap_ok & nearly_unit & (!exits | (density_ok & usable));
    let keep = |x: f32| if some { x } else { 0.0 };
    let eta_ratio = if some && !reflects { k.eta_out } else { 1.0 };
    (V3::new(keep(wi.x), keep(wi.y), keep(wi.z)), keep(weight), keep(pdf), eta_ratio, done)
}

/// The evaluation loop: one pass of the f32 kernels over every query (a loop the compiler
/// vectorizes, eight queries per AVX2 instruction), which marks the queries off the kernels'
/// common path with a NaN (no answer of the kernels is NaN), then the scalar call for those.
struct EvalLoop<'s, 'a, 'b, B, const WANT: u8> {
    bsdf: &'s B,
    kernel: Kernel,
    wo: &'s Directions<'a>,
    wi: &'s Directions<'a>,
    f: Option<&'s mut Channels<'b>>,
    pdf: Option<&'s mut [f32]>,
}

impl<B: Bsdf, const WANT: u8> EvalLoop<'_, '_, '_, B, WANT> {
    /// The output that marks the queries left to the scalar call: the density, or f's first
    /// channel.
    #[inline(always)]
    fn marks(&self) -> &[f32] {
        match (&self.f, &self.pdf) {
            (_, Some(pdf)) => pdf,
            (Some(f), None) => f.a,
            (None, None) => &[],
        }
    }

    /// The scalar call for query `i`.
    #[inline(never)]
    fn scalar(&mut self, i: usize) {
        let (wo, wi) = (self.wo.get(i), self.wi.get(i));
        match WANT {
            Want::EVAL => self.f.as_mut().map_or((), |f| f.set(i, self.bsdf.eval(wo, wi).f)),
            Want::PDF => self.pdf.as_mut().map_or((), |p| p[i] = self.bsdf.pdf(wo, wi)),
            _ => {
                let (v, p) = self.bsdf.eval_with_pdf(wo, wi);
                if let Some(f) = self.f.as_mut() {
                    f.set(i, v.f);
                }
                if let Some(pdf) = self.pdf.as_mut() {
                    pdf[i] = p;
                }
            }
        }
    }
}

impl<B: Bsdf, const WANT: u8> EvalLoop<'_, '_, '_, B, WANT> {
    /// The pass of one kernel over every query (a loop without a branch on the kernel, which
    /// the compiler vectorizes), then the scalar call for the marked queries.
    #[inline(always)]
    fn pass<K: QueryKernel<WANT>>(&mut self, kernel: K) {
        let n = self.wo.len();
        let (wo, wi) = (self.wo.slices(), self.wi.slices());
        let mark = |done: bool, x: f32| if done { x } else { f32::NAN };
        match (self.f.as_mut(), self.pdf.as_mut()) {
            (Some(f), Some(pdf)) => {
                let (fa, fb, fc) = f.slices();
                let pdf = &mut pdf[..n];
                for i in 0..n {
                    let (v, p, done) = kernel.eval(at(wo, i), at(wi, i));
                    (fa[i], fb[i], fc[i], pdf[i]) = (v[0], v[1], v[2], mark(done, p));
                }
            }
            (Some(f), None) => {
                let (fa, fb, fc) = f.slices();
                for i in 0..n {
                    let (v, _, done) = kernel.eval(at(wo, i), at(wi, i));
                    (fa[i], fb[i], fc[i]) = (mark(done, v[0]), v[1], v[2]);
                }
            }
            (None, Some(pdf)) => {
                let pdf = &mut pdf[..n];
                for (i, slot) in pdf.iter_mut().enumerate() {
                    let (_, p, done) = kernel.eval(at(wo, i), at(wi, i));
                    *slot = mark(done, p);
                }
            }
            (None, None) => {}
        }
        let mut from = 0;
        while let Some(i) = next_marked(self.marks(), from) {
            self.scalar(i);
            from = i + 1;
        }
    }
}

/// One pass of `$loop` per kernel and Fresnel term, each loop free of branches on them: the
/// dispatch of every lane loop's `run`.
macro_rules! pass_per_kernel {
    ($loop:ident) => {
        match $loop.kernel {
            Kernel::Conductor { ax, ay, fresnel: None } => $loop.pass(MirrorQuery { ax, ay }),
            Kernel::Conductor { ax, ay, fresnel: Some(fresnel) } => {
                $loop.pass(ConductorQuery { ax, ay, fresnel })
            }
            Kernel::Dielectric { ax, ay, eta, inv_eta, transport, eta_out } => {
                $loop.pass(DielectricQuery { ax, ay, eta, inv_eta, transport, eta_out })
            }
        }
    };
}

impl<B: Bsdf, const WANT: u8> LaneLoop for EvalLoop<'_, '_, '_, B, WANT> {
    #[inline(always)]
    fn run(&mut self) {
        pass_per_kernel!(self)
    }
}

/// A kernel evaluated query by query in a batch pass (`#[inline(always)]`, so that the pass
/// compiles it into its own vectorized loop).
trait QueryKernel<const WANT: u8> {
    fn eval(&self, wo: V3<f32>, wi: V3<f32>) -> ([f32; 3], f32, bool);
}

/// A GGX perfect mirror.
struct MirrorQuery {
    ax: f32,
    ay: f32,
}

/// A GGX conductor with its Fresnel constants.
struct ConductorQuery {
    ax: f32,
    ay: f32,
    fresnel: (Vec3A, Vec3A),
}

/// A GGX dielectric with 1/η as the material keeps it, the transport factor of its
/// transmissions and the relative index their samples report.
struct DielectricQuery {
    ax: f32,
    ay: f32,
    eta: f32,
    inv_eta: f32,
    transport: f32,
    eta_out: f32,
}

impl<const WANT: u8> QueryKernel<WANT> for MirrorQuery {
    #[inline(always)]
    fn eval(&self, wo: V3<f32>, wi: V3<f32>) -> ([f32; 3], f32, bool) {
        evaluate_conductor::<f32, WANT>(self.ax, self.ay, None, wo, wi)
    }
}

impl<const WANT: u8> QueryKernel<WANT> for ConductorQuery {
    #[inline(always)]
    fn eval(&self, wo: V3<f32>, wi: V3<f32>) -> ([f32; 3], f32, bool) {
        evaluate_conductor::<f32, WANT>(self.ax, self.ay, Some(self.fresnel), wo, wi)
    }
}

impl<const WANT: u8> QueryKernel<WANT> for DielectricQuery {
    #[inline(always)]
    fn eval(&self, wo: V3<f32>, wi: V3<f32>) -> ([f32; 3], f32, bool) {
        evaluate_dielectric::<f32, WANT>(self.ax, self.ay, self.eta, self.transport, wo, wi)
    }
}

/// Query i of structure-of-arrays slices.
#[inline(always)]
fn at(w: (&[f32], &[f32], &[f32]), i: usize) -> V3<f32> {
    V3::new(w.0[i], w.1[i], w.2[i])
}

/// A sampling kernel run query by query in a batch pass: ωi, the weight, the density (0: no
/// sample), η_wi/η_wo and whether they are the answer.
trait SampleKernel {
    fn sample(&self, wo: V3<f32>, uc: f32, u1: f32, u2: f32) -> (V3<f32>, [f32; 3], f32, f32, bool);
}

impl SampleKernel for MirrorQuery {
    #[inline(always)]
    fn sample(&self, wo: V3<f32>, uc: f32, u1: f32, u2: f32) -> (V3<f32>, [f32; 3], f32, f32, bool) {
        let (w, weight, p, done) = sample_conductor::<f32>(self.ax, self.ay, None, wo, uc, u1, u2);
        (w, weight, p, 1.0, done)
    }
}

impl SampleKernel for ConductorQuery {
    #[inline(always)]
    fn sample(&self, wo: V3<f32>, uc: f32, u1: f32, u2: f32) -> (V3<f32>, [f32; 3], f32, f32, bool) {
        let (w, weight, p, done) =
            sample_conductor::<f32>(self.ax, self.ay, Some(self.fresnel), wo, uc, u1, u2);
        (w, weight, p, 1.0, done)
    }
}

impl SampleKernel for DielectricQuery {
    #[inline(always)]
    fn sample(&self, wo: V3<f32>, uc: f32, u1: f32, u2: f32) -> (V3<f32>, [f32; 3], f32, f32, bool) {
        let (w, weight, p, eta, done) = sample_dielectric(self, wo, uc, u1, u2);
        (w, [weight; 3], p, eta, done)
    }
}

/// The sampling loop, as [`EvalLoop`]: the kernels over every query, then the scalar call for
/// the queries marked with a NaN density.
struct SampleLoop<'s, 'a, 'b, B> {
    bsdf: &'s B,
    kernel: Kernel,
    wo: &'s Directions<'a>,
    uc: &'s [f32],
    u1: &'s [f32],
    u2: &'s [f32],
    out: &'s mut SampleOutputs<'b>,
}

impl<B: Bsdf> SampleLoop<'_, '_, '_, B> {
    /// The pass of one kernel over every query (a loop without a branch on the kernel), then
    /// the scalar call for the marked queries.
    #[inline(always)]
    fn pass<K: SampleKernel>(&mut self, kernel: K) {
        let n = self.wo.len();
        let wo = self.wo.slices();
        let (uc, u1, u2) = (&self.uc[..n], &self.u1[..n], &self.u2[..n]);
        {
            let (wx, wy, wz) = self.out.wi.slices();
            let (ra, rb, rc) = self.out.weight.slices();
            let (pdf, eta) = (&mut self.out.pdf[..n], &mut self.out.eta[..n]);
            for i in 0..n {
                let (w, weight, p, ratio, done) = kernel.sample(at(wo, i), uc[i], u1[i], u2[i]);
                (wx[i], wy[i], wz[i]) = (w.x, w.y, w.z);
                (ra[i], rb[i], rc[i]) = (weight[0], weight[1], weight[2]);
                pdf[i] = if done { p } else { f32::NAN };
                eta[i] = ratio;
            }
        }
        let mut from = 0;
        while let Some(i) = next_marked(self.out.pdf, from) {
            let s = self.bsdf.sample(self.wo.get(i), uc[i], Vec2::new(u1[i], u2[i]));
            self.out.set(i, s);
            from = i + 1;
        }
    }
}

impl<B: Bsdf> LaneLoop for SampleLoop<'_, '_, '_, B> {
    #[inline(always)]
    fn run(&mut self) {
        pass_per_kernel!(self)
    }
}

impl<S: MicrosurfaceSlope, M: Material + SpecularLimit> MicrofacetBsdf<S, M> {
    /// The evaluation loop of a batch call in lanes, or `None` for the scalar one.
    fn eval_loop<'s, 'a, 'b, const WANT: u8>(
        &'s self,
        wo: &'s Directions<'a>,
        wi: &'s Directions<'a>,
        f: Option<&'s mut Channels<'b>>,
        pdf: Option<&'s mut [f32]>,
    ) -> bool {
        let Some(kernel) = self.kernel() else { return false };
        dispatch(&mut EvalLoop::<Self, WANT> { bsdf: self, kernel, wo, wi, f, pdf });
        true
    }
}

/// Eight-lane batch calls for single scattering on GGX conductors and dielectrics (η at least
/// 0.05 from 1), the scalar calls query by query for every other configuration.
///
/// Bounds against the scalar call (`tests/batch.rs`, over views and lights on the whole sphere
/// from α = 10⁻³ to 10, anisotropic, grazing to 10⁻⁶): densities and samples of conductors are
/// equal bit for bit; f of a reflection within 2e-5 relative (the scalar forms D, Λ and G2 in
/// f64, the lanes in f32) plus 4e-6 of f/F for the Fresnel cosine (a dielectric's facet cosine
/// with |cos² θ + η² − 1| below 0.01, near the critical angle of η < 1, where F has an
/// infinite slope, takes the scalar call); a dielectric's densities within 1e-4 relative plus
/// 1e-6 absolute; f of a dielectric's transmission within 1.5e-4 relative plus
/// (4e-6 + 1e-6/pdf) of f (the density's bound carried over, and the lane beta function of the
/// height-correlated G2, `special::ln_beta_1p_of`: 4e-7·(1 + |ln B|) + 3 ulps).
/// A dielectric's samples seen from above: the direction, the event and η equal to the scalar
/// call's bit for bit (the visible normal is the scalar's f32 kernel, the Fresnel choice and
/// the refraction's c − s are formed in f64 as the scalar forms them), the weight within 5e-5
/// relative, the density within the dielectric's density bound (but for transmissions sampled
/// from grazing views of sharp glass at the critical angle, measured up to 1.64e-4 relative:
/// `DESIGN.md`, "Accuracy in f32 lanes").
impl<S: MicrosurfaceSlope, M: Material + SpecularLimit> BatchBsdf for MicrofacetBsdf<S, M> {
    fn eval_batch(
        &self,
        wo: &Directions<'_>,
        wi: &Directions<'_>,
        f: &mut Channels<'_>,
    ) -> Result<(), Error> {
        let n = wo.len();
        check_len("wi", n, wi.len())?;
        f.check("f", n)?;
        if !self.eval_loop::<{ Want::EVAL }>(wo, wi, Some(f), None) {
            for i in 0..n {
                f.set(i, self.eval(wo.get(i), wi.get(i)).f);
            }
        }
        Ok(())
    }

    fn pdf_batch(&self, wo: &Directions<'_>, wi: &Directions<'_>, pdf: &mut [f32]) -> Result<(), Error> {
        let n = wo.len();
        check_len("wi", n, wi.len())?;
        check_len("pdf", n, pdf.len())?;
        if !self.eval_loop::<{ Want::PDF }>(wo, wi, None, Some(pdf)) {
            for (i, p) in pdf.iter_mut().enumerate() {
                *p = self.pdf(wo.get(i), wi.get(i));
            }
        }
        Ok(())
    }

    fn eval_with_pdf_batch(
        &self,
        wo: &Directions<'_>,
        wi: &Directions<'_>,
        f: &mut Channels<'_>,
        pdf: &mut [f32],
    ) -> Result<(), Error> {
        let n = wo.len();
        check_len("wi", n, wi.len())?;
        f.check("f", n)?;
        check_len("pdf", n, pdf.len())?;
        if !self.eval_loop::<{ Want::BOTH }>(wo, wi, Some(f), Some(pdf)) {
            for (i, slot) in pdf.iter_mut().enumerate() {
                let (v, p) = self.eval_with_pdf(wo.get(i), wi.get(i));
                f.set(i, v.f);
                *slot = p;
            }
        }
        Ok(())
    }

    fn sample_batch(
        &self,
        wo: &Directions<'_>,
        uc: &[f32],
        u1: &[f32],
        u2: &[f32],
        out: &mut SampleOutputs<'_>,
    ) -> Result<(), Error> {
        let Some(kernel) = self.kernel() else { return sample_each(self, wo, uc, u1, u2, out) };
        check_sample_lengths(wo, uc, u1, u2, out)?;
        dispatch(&mut SampleLoop { bsdf: self, kernel, wo, uc, u1, u2, out });
        Ok(())
    }
}
