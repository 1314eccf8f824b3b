//! The batch interface: eval, pdf, eval_with_pdf and sample over many queries at once, in
//! structure-of-arrays slices, with the single-scattering GGX conductor and dielectric run in
//! eight f32 lanes.
//!
//! # Layout
//!
//! Directions are three `&[f32]` slices (x, y, z), colours three, and every output is a slice
//! the caller provides (nothing is allocated). Eight consecutive queries form one chunk: each
//! coordinate of a chunk is one 256-bit load, the layout a wavefront renderer already keeps its
//! rays in (Mitsuba 3 and Dr.Jit, pbrt-v4's GPU wavefront queues) and the one SIMD code needs
//! without transposes. The last `len % 8` queries take the scalar calls.
//!
//! # One formula, two control flows
//!
//! The lanes compute with the same kernels as the scalar calls (`crate::lanes`: GGX Λ, projected
//! area, D and reflection density, the spherical-cap visible normal, the conductor and dielectric
//! Fresnel terms, G2 and G2/G1), generic over the lane type. Where the scalar path branches to a
//! rare form (a half vector within rounding of −ωi, a subnormal density, a cap point near −v̂,
//! a near-perpendicular facet's Fresnel cosine, a backfacing view, an invalid argument), the
//! lanes compute a mask of the queries their common path covers, and every other query is
//! answered by the scalar call itself. A bad lane therefore gets exactly the scalar contract's
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
use crate::fresnel::{fresnel_dielectric_cosines_of, reflectance_of};
use crate::lanes::{F32x8, LaneLoop, Lanes, M32x8, V3, WIDTH, dispatch};
use crate::material::{LaneMaterial, Material, g2_over_g1_of};
use crate::single_scattering::VISIBLE_SUM_MARGIN;
use crate::slope::{
    F32_DENSITY_MIN_SUM, MicrosurfaceSlope, d_of_sum, lambda_and_area_of, reflection_density_of,
    sample_spherical_cap_of,
};
use crate::soa::{Channels, Directions, check_len};
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
    fn set(&mut self, i: usize, s: Option<super::BsdfSample>) {
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
/// The provided methods call the scalar methods query by query; [`MicrofacetBsdf`] overrides
/// them with eight-lane loops for single scattering on GGX conductors and dielectrics.
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
        for i in 0..n {
            pdf[i] = self.pdf(wo.get(i), wi.get(i));
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
        for i in 0..n {
            let (v, p) = self.eval_with_pdf(wo.get(i), wi.get(i));
            f.set(i, v.f);
            pdf[i] = p;
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
        let n = check_sample_lengths(wo, uc, u1, u2, out)?;
        for i in 0..n {
            out.set(i, self.sample(wo.get(i), uc[i], Vec2::new(u1[i], u2[i])));
        }
        Ok(())
    }
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
    /// GGX (αx, αy) dielectric of index η.
    Dielectric { ax: f32, ay: f32, eta: f32 },
}

impl<S: MicrosurfaceSlope, M: Material + SpecularLimit> MicrofacetBsdf<S, M> {
    /// The lane kernels of this BSDF: single scattering (not a Dirac lobe) on GGX, conductor or
    /// dielectric facets.
    fn kernel(&self) -> Option<Kernel> {
        if self.technique() != Technique::SingleScattering || self.is_specular() {
            return None;
        }
        let (ax, ay) = self.surface().slope().ggx_roughness()?;
        match self.surface().material().lane_material() {
            LaneMaterial::Conductor(fresnel) => Some(Kernel::Conductor { ax, ay, fresnel }),
            // near η = 1 the refraction half vector cancels: the f64 scalar path serves
            LaneMaterial::Dielectric(eta) if (eta - 1.0).abs() >= DIELECTRIC_LANES_MIN_CONTRAST => {
                Some(Kernel::Dielectric { ax, ay, eta })
            }
            _ => None,
        }
    }
}

/// The smallest |η − 1| of a dielectric whose batch calls run in lanes: |ωo + η ωi| ≥ |η − 1|,
/// so the f32 refraction half vector keeps 2⁻²⁴/0.05 of relative precision.
const DIELECTRIC_LANES_MIN_CONTRAST: f32 = 0.05;

/// The mask of unit directions (`contract::is_direction` in each lane).
#[inline(always)]
fn is_direction(w: V3<F32x8>) -> M32x8 {
    (w.length_squared() - F32x8::lit(1.0)).abs().le(F32x8::lit(crate::contract::DIRECTION_TOLERANCE))
}

/// The per-lane results of an evaluation: f per channel and the density, with the mask of the
/// lanes they hold (the others take the scalar call).
struct Evaluated {
    f: [F32x8; 3],
    pdf: F32x8,
    /// The lanes whose f is held.
    done_f: M32x8,
    /// The lanes whose density is held.
    done_pdf: M32x8,
}

/// A density is one the lanes return where it is a normal f32 (the scalar form's test).
#[inline(always)]
fn normal(x: F32x8) -> M32x8 {
    x.ge(F32x8::lit(f32::MIN_POSITIVE)) & x.lt(F32x8::lit(f32::INFINITY))
}

/// f32 lanes of a scalar.
#[inline(always)]
fn splat(x: f32) -> F32x8 {
    F32x8::lit(x)
}

/// The conductor's Fresnel term per channel at cos θ ∈ (0, 1] (`conductor_reflectance`).
#[inline(always)]
fn conductor_fresnel(fresnel: Option<(Vec3A, Vec3A)>, cos: F32x8) -> [F32x8; 3] {
    match fresnel {
        None => [splat(1.0); 3],
        Some((t0, m)) => {
            let c = cos.abs().min(splat(1.0));
            let grazing = c.eq(splat(0.0));
            let channel =
                |t: f32, k: f32| F32x8::select(grazing, splat(1.0), reflectance_of(c, splat(t), splat(k)));
            [channel(t0.x, m.x), channel(t0.y, m.y), channel(t0.z, m.z)]
        }
    }
}

/// The dielectric's Fresnel reflectance at cos θ = `c` ∈ [0, 1] with index η
/// (`dielectric_reflectance`, in f32).
#[inline(always)]
fn dielectric_fresnel(eta: F32x8, c: F32x8) -> F32x8 {
    let c = c.abs().min(splat(1.0));
    let eta2_cos2_t = c * c + (eta - splat(1.0)) * (eta + splat(1.0));
    let total = eta2_cos2_t.le(splat(0.0));
    let t = eta2_cos2_t.max(splat(0.0)).sqrt() / eta;
    F32x8::select(total, splat(1.0), fresnel_dielectric_cosines_of(c, t, eta))
}

/// Single scattering of a front-facing reflection (ωo, ωi both above the horizon, renderer
/// orientation: the walk enters along ωo): the density D(ωh)/(4 A(ωo)) from the unnormalized
/// h = ωo + ωi, G2/G1(ωo) from the projected areas and the cosine ωo·ωh. f = w·pdf·(G2/G1)/cos θi
/// with w the facet's weight (Fresnel). `ok`: the lanes where the density is the scalar f32
/// form's and ωh is clearly visible.
#[inline(always)]
fn front_reflection(ax: F32x8, ay: F32x8, wo: V3<F32x8>, wi: V3<F32x8>) -> (F32x8, F32x8, F32x8, M32x8) {
    let h = wo.add(wi);
    let visible = wo.dot(h).gt(splat(VISIBLE_SUM_MARGIN));
    let (_, area_o) = lambda_and_area_of(ax, ay, wo);
    let (_, area_i) = lambda_and_area_of(ax, ay, wi);
    let (density, len_sq, t) = reflection_density_of(ax, ay, h, area_o);
    let min = splat(F32_DENSITY_MIN_SUM);
    let ok = visible & len_sq.ge(min) & t.ge(min) & normal(density);
    let g2_over_g1 = g2_over_g1_of(area_o, area_i, wo.z, wi.z);
    let cos = wo.dot(h) / len_sq.sqrt();
    (density, g2_over_g1, cos, ok)
}

/// The evaluation lanes of a chunk (renderer orientation), `None` in `done` where the scalar
/// call must answer.
#[inline(always)]
fn evaluate<const WANT: u8>(kernel: Kernel, wo: V3<F32x8>, wi: V3<F32x8>) -> Evaluated {
    let want_f = WANT & Want::EVAL != 0;
    let valid = is_direction(wo) & is_direction(wi);
    let zero = splat(0.0);
    let front = valid & wo.z.gt(zero);
    match kernel {
        Kernel::Conductor { ax, ay, fresnel } => {
            let (ax, ay) = (splat(ax), splat(ay));
            let above = front & wi.z.gt(zero);
            // a light at or below the horizon of a view from above: no reflection, f = pdf = 0
            let below = front & wi.z.le(zero);
            let (density, g2_over_g1, cos, ok) = front_reflection(ax, ay, wo, wi);
            let f = if want_f {
                let w = conductor_fresnel(fresnel, cos);
                let scale = density * g2_over_g1 / wi.z;
                w.map(|w| F32x8::select(above, w * scale, zero))
            } else {
                [zero; 3]
            };
            let done = (above & ok) | below;
            Evaluated { f, pdf: F32x8::select(above, density, zero), done_f: done, done_pdf: done }
        }
        Kernel::Dielectric { ax, ay, eta } => {
            let (ax, ay, eta_l) = (splat(ax), splat(ay), splat(eta));
            let above = front & wi.z.gt(zero);
            let (density, g2_over_g1, cos, ok) = front_reflection(ax, ay, wo, wi);
            let fr = dielectric_fresnel(eta_l, cos);
            let f_reflect = fr * density * g2_over_g1 / wi.z;
            let pdf_reflect = fr * density;
            // transmission from above: the density of the refraction ωo → ωi
            let below = front & wi.z.lt(zero);
            let (pdf_transmit, ok_t) = transmission_density(ax, ay, eta_l, wo, wi);
            let pdf = F32x8::select(above, pdf_reflect, pdf_transmit);
            let f = F32x8::select(above, f_reflect, zero);
            // a transmission's f (its G2 is a beta function) is the scalar call's
            Evaluated { f: [f; 3], pdf, done_f: above & ok, done_pdf: (above & ok) | (below & ok_t) }
        }
    }
}

/// Below these cosines (relative to |ωo + η ωi|) a refraction is left to the scalar f64 form:
/// the validity tests of the half vector change sign within f32 rounding there.
const REFRACTION_MARGIN: f32 = 1e-4;

/// The density of a refraction from ωo (above) to ωi (below) through a GGX dielectric of
/// index η (the phase function of `Dielectric`, Heitz et al. 2016, supplement §3.4):
/// η² (1 − F) D_ωo(ωh) |ωi·ωh|/(ωo·ωh + η ωi·ωh)², with ωh ∝ −(ωo + η ωi) turned up, D from
/// the unnormalized sum ([`d_of_sum`]). `ok`: the lanes where the half vector's validity tests
/// (ωh.z > 0, ωo·ωh > 0 > ωi·ωh) hold with a margin; 0 where they clearly fail.
#[inline(always)]
fn transmission_density(ax: F32x8, ay: F32x8, eta: F32x8, wo: V3<F32x8>, wi: V3<F32x8>) -> (F32x8, M32x8) {
    let zero = splat(0.0);
    let sum = wo.add(wi.scale(eta));
    let up = sum.z.gt(zero);
    let h = V3::select(up, sum, V3::new(-sum.x, -sum.y, -sum.z));
    let len_sq = h.length_squared();
    let len = len_sq.sqrt();
    let (cos_ih, cos_oh) = (wo.dot(h) / len, wi.dot(h) / len);
    let margin = splat(REFRACTION_MARGIN);
    let valid = h.z.gt(margin * len) & cos_ih.gt(margin) & cos_oh.lt(-margin);
    let invalid = h.z.lt(-margin * len) | cos_ih.lt(-margin) | cos_oh.gt(margin);
    let d = d_of_sum(ax, ay, h, splat(core::f32::consts::FRAC_1_PI));
    let (_, area) = lambda_and_area_of(ax, ay, wo);
    let transmittance = splat(1.0) - fresnel_dielectric_cosines_of(cos_ih, -cos_oh, eta);
    let d_wi = cos_ih * d / area;
    let pdf = eta * eta * transmittance * d_wi * (-cos_oh) / len_sq;
    let sane = len.gt(splat(DIELECTRIC_LANES_MIN_CONTRAST)) & len_sq.ge(splat(F32_DENSITY_MIN_SUM));
    (F32x8::select(valid, pdf, zero), sane & (valid | invalid))
}

/// The sample lanes of a GGX conductor seen from above (`SingleScattering::sample_mirror_front`
/// in lanes, renderer orientation): wi, weight, pdf and the lanes they hold; a lane whose
/// sample does not exist (it points into the surface) is held with pdf 0.
#[inline(always)]
fn sample_conductor(
    ax: f32,
    ay: f32,
    fresnel: Option<(Vec3A, Vec3A)>,
    wo: V3<F32x8>,
    uc: F32x8,
    u1: F32x8,
    u2: F32x8,
) -> (V3<F32x8>, [F32x8; 3], F32x8, M32x8) {
    let (zero, one) = (splat(0.0), splat(1.0));
    let (axl, ayl) = (splat(ax), splat(ay));
    let uniform = |u: F32x8| u.ge(zero) & u.lt(one);
    let valid = is_direction(wo) & wo.z.gt(zero) & uniform(uc) & uniform(u1) & uniform(u2);
    let (m, cap_ok) = sample_spherical_cap_of(axl, ayl, wo, u1, u2);
    let c = wo.dot(m);
    // the reflection, renormalized by one Newton step (`renormalize`'s common path)
    let k = splat(2.0) * c;
    let r = V3::new(k * m.x - wo.x, k * m.y - wo.y, k * m.z - wo.z);
    let r_len_sq = r.length_squared();
    let nearly_unit = (r_len_sq - one).abs().le(splat(1.0 / 4096.0));
    let wi = r.scale(splat(1.5) - splat(0.5) * r_len_sq);
    let exits = wi.z.gt(zero);
    let weight = conductor_fresnel(fresnel, c);
    let (_, area_o) = lambda_and_area_of(axl, ayl, wo);
    let (_, area_i) = lambda_and_area_of(axl, ayl, wi);
    let last = g2_over_g1_of(area_o, area_i, wo.z, wi.z);
    let h = wo.add(wi);
    let visible = wo.dot(h).gt(splat(VISIBLE_SUM_MARGIN));
    let (density, len_sq, t) = reflection_density_of(axl, ayl, h, area_o);
    let min = splat(F32_DENSITY_MIN_SUM);
    let density_ok = visible & len_sq.ge(min) & t.ge(min) & normal(density);
    let weight = weight.map(|w| w * last);
    let w_max = weight[0].max(weight[1]).max(weight[2]);
    // the sample's f = weight·pdf/cos θi is clearly a normal f32 (the scalar test in f64 is
    // weight·pdf ≥ f32::MIN_POSITIVE·cos θi)
    let usable = last.gt(zero) & (w_max * density).ge(splat(1e-30)) & w_max.lt(splat(f32::INFINITY));
    // a Fresnel cosine below 0.05 is taken from the half vector in f64 by the scalar path
    let common = cap_ok
        & (c.ge(splat(FRESNEL_AT_HALF_VECTOR_BELOW))
            | splat(f32::from(u8::from(fresnel.is_none()))).gt(zero))
        & nearly_unit;
    let some = exits & usable;
    let done = valid & common & (!exits | (density_ok & usable));
    let keep = |x: F32x8| F32x8::select(some, x, zero);
    (V3::new(keep(wi.x), keep(wi.y), keep(wi.z)), weight.map(keep), keep(density), done)
}

/// Below this ωo·ωm a conductor's sampled Fresnel weight takes the half vector's cosine in f64
/// (`Conductor`'s `FRESNEL_AT_HALF_VECTOR_BELOW`): the scalar sampler serves those lanes.
const FRESNEL_AT_HALF_VECTOR_BELOW: f32 = 0.05;

/// What a batch loop computes per query (a const parameter of the loop, so that a density-only
/// loop carries no Fresnel term).
struct Want;

impl Want {
    const EVAL: u8 = 1;
    const PDF: u8 = 2;
    const BOTH: u8 = 3;
}

/// The evaluation loop over chunks of eight queries.
struct EvalLoop<'s, 'a, 'b, B, const WANT: u8> {
    bsdf: &'s B,
    kernel: Kernel,
    wo: &'s Directions<'a>,
    wi: &'s Directions<'a>,
    f: Option<&'s mut Channels<'b>>,
    pdf: Option<&'s mut [f32]>,
}

impl<B: Bsdf, const WANT: u8> EvalLoop<'_, '_, '_, B, WANT> {
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

/// f as the trait returns it: 0 where not finite.
#[inline(always)]
fn finite_or_zero(x: F32x8) -> F32x8 {
    F32x8::select(x.abs().lt(splat(f32::INFINITY)), x, splat(0.0))
}

impl<B: Bsdf, const WANT: u8> LaneLoop for EvalLoop<'_, '_, '_, B, WANT> {
    #[inline(always)]
    fn run(&mut self) {
        let n = self.wo.len();
        let chunks = n / WIDTH * WIDTH;
        let mut i = 0;
        while i < chunks {
            let (wo, wi) = (self.wo.lanes(i), self.wi.lanes(i));
            let e = evaluate::<WANT>(self.kernel, wo, wi);
            if let Some(f) = self.f.as_mut() {
                f.store(i, e.f.map(finite_or_zero));
            }
            if let Some(pdf) = self.pdf.as_mut() {
                finite_or_zero(e.pdf).store(&mut pdf[i..]);
            }
            let done = match WANT {
                Want::EVAL => e.done_f,
                Want::PDF => e.done_pdf,
                _ => e.done_f & e.done_pdf,
            };
            let mut rest = !done.bits() & 0xff;
            while rest != 0 {
                let lane = rest.trailing_zeros() as usize;
                self.scalar(i + lane);
                rest &= rest - 1;
            }
            i += WIDTH;
        }
        for k in chunks..n {
            self.scalar(k);
        }
    }
}

/// The sampling loop over chunks of eight queries (GGX conductors).
struct SampleLoop<'s, 'a, 'b, B> {
    bsdf: &'s B,
    ax: f32,
    ay: f32,
    fresnel: Option<(Vec3A, Vec3A)>,
    wo: &'s Directions<'a>,
    uc: &'s [f32],
    u1: &'s [f32],
    u2: &'s [f32],
    out: &'s mut SampleOutputs<'b>,
}

impl<B: Bsdf> SampleLoop<'_, '_, '_, B> {
    #[inline(never)]
    fn scalar(&mut self, i: usize) {
        let s = self.bsdf.sample(self.wo.get(i), self.uc[i], Vec2::new(self.u1[i], self.u2[i]));
        self.out.set(i, s);
    }
}

impl<B: Bsdf> LaneLoop for SampleLoop<'_, '_, '_, B> {
    #[inline(always)]
    fn run(&mut self) {
        let n = self.wo.len();
        let chunks = n / WIDTH * WIDTH;
        let mut i = 0;
        while i < chunks {
            let wo = self.wo.lanes(i);
            let (uc, u1, u2) =
                (F32x8::load(&self.uc[i..]), F32x8::load(&self.u1[i..]), F32x8::load(&self.u2[i..]));
            let (wi, weight, pdf, done) = sample_conductor(self.ax, self.ay, self.fresnel, wo, uc, u1, u2);
            self.out.wi.store(i, [wi.x, wi.y, wi.z]);
            self.out.weight.store(i, weight);
            pdf.store(&mut self.out.pdf[i..]);
            splat(1.0).store(&mut self.out.eta[i..]);
            let mut rest = !done.bits() & 0xff;
            while rest != 0 {
                let lane = rest.trailing_zeros() as usize;
                self.scalar(i + lane);
                rest &= rest - 1;
            }
            i += WIDTH;
        }
        for k in chunks..n {
            self.scalar(k);
        }
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
/// f64, the lanes in f32) plus 4e-6 of f/F for the Fresnel cosine; a dielectric's densities
/// within 2e-5 relative plus 1e-6 absolute. Glass transmission eval and glass samples run the
/// scalar calls (the transmission's height-correlated G2 is a beta function, which has no lane
/// kernel yet).
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
            for i in 0..n {
                pdf[i] = self.pdf(wo.get(i), wi.get(i));
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
            for i in 0..n {
                let (v, p) = self.eval_with_pdf(wo.get(i), wi.get(i));
                f.set(i, v.f);
                pdf[i] = p;
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
        let n = check_sample_lengths(wo, uc, u1, u2, out)?;
        if let Some(Kernel::Conductor { ax, ay, fresnel }) = self.kernel() {
            dispatch(&mut SampleLoop { bsdf: self, ax, ay, fresnel, wo, uc, u1, u2, out });
        } else {
            for i in 0..n {
                out.set(i, self.sample(wo.get(i), uc[i], Vec2::new(u1[i], u2[i])));
            }
        }
        Ok(())
    }
}
