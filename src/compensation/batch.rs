//! The batch calls of the compensated lobes ([`BatchBsdf`]): single scattering's batch (in
//! eight lanes where [`MicrofacetBsdf`] has them, by its scalar calls elsewhere), then one pass
//! over the queries that ends each as the scalar call ends it, with the same expression: the
//! added lobe or Turquin's factor on f, the sampling mixture on the density, Turquin's factor
//! on a sample's weight.
//!
//! The scalar calls renormalize directions that drifted from unit length on entry
//! (`unit_directions!`), and single scattering's batch answers such a query with its own
//! scalar call, at the renormalized directions. The pass therefore composes only the queries
//! whose directions are unit as given (the entry test of the scalar calls, which then use them
//! unchanged) and gives every other query the compensated scalar call itself: the
//! renormalized directions, or the contract's *nothing*.

use super::compensated::{Compensated, Compensation};
use super::conductor::{Column, ConductorLobes, DirectionFactors};
use crate::bsdf::{BatchBsdf, Bsdf, BsdfSample, MicrofacetBsdf, SampleOutputs, sample_each};
use crate::contract::is_direction;
use crate::error::Error;
use crate::material::{Conductor, Dielectric};
use crate::slope::MicrosurfaceSlope;
use crate::soa::{Channels, Directions};
use glam::{Vec2, Vec3, Vec3A};

/// What a compensated lobe's scalar calls compute after single scattering, at valid
/// directions (the material's own functions, which the scalar calls end with).
trait Composition: Bsdf {
    /// The single-scattering BSDF inside.
    type Single: BatchBsdf;
    fn single(&self) -> &Self::Single;
    /// A Dirac lobe: single scattering's answers, uncompensated.
    fn dirac(&self) -> bool;
    fn scheme(&self) -> Compensation;
    /// What f's compensation reads, prepared for a batch of `n` queries.
    type Factors<'a>
    where
        Self: 'a;
    fn factors(&self, n: usize) -> Self::Factors<'_>;
    fn compensated_f(&self, factors: &Self::Factors<'_>, wo: Vec3, wi: Vec3, f_ss: Vec3) -> Vec3;
    fn compensated_pdf(&self, wo: Vec3, wi: Vec3, pdf_ss: f32) -> f32;
    /// Both of the above (a material whose two read the same cells reads them once).
    fn compensated(
        &self,
        factors: &Self::Factors<'_>,
        wo: Vec3,
        wi: Vec3,
        f_ss: Vec3,
        pdf_ss: f32,
    ) -> (Vec3, f32);
    fn turquin_weight(&self, wo: Vec3, weight: Vec3) -> Option<Vec3>;
}

impl<S: MicrosurfaceSlope> Composition for Compensated<S, Conductor> {
    type Single = MicrofacetBsdf<S, Conductor>;
    #[inline(always)]
    fn single(&self) -> &Self::Single {
        &self.single
    }
    #[inline(always)]
    fn dirac(&self) -> bool {
        self.single.is_specular()
    }
    #[inline(always)]
    fn scheme(&self) -> Compensation {
        self.scheme
    }
    type Factors<'a>
        = ConductorFactors<'a>
    where
        Self: 'a;
    #[inline]
    fn factors(&self, n: usize) -> ConductorFactors<'_> {
        if n >= COLUMN_QUERIES && self.scheme != Compensation::Turquin {
            ConductorFactors::Column(self.lobes.column())
        } else {
            ConductorFactors::Lobes(&self.lobes)
        }
    }
    #[inline(always)]
    fn compensated_f(&self, factors: &ConductorFactors<'_>, wo: Vec3, wi: Vec3, f_ss: Vec3) -> Vec3 {
        Compensated::<S, Conductor>::compensated_f(self, factors, wo, wi, f_ss)
    }
    #[inline(always)]
    fn compensated_pdf(&self, wo: Vec3, wi: Vec3, pdf_ss: f32) -> f32 {
        Compensated::<S, Conductor>::compensated_pdf(self, wo, wi, pdf_ss)
    }
    #[inline(always)]
    fn compensated(
        &self,
        factors: &ConductorFactors<'_>,
        wo: Vec3,
        wi: Vec3,
        f_ss: Vec3,
        pdf_ss: f32,
    ) -> (Vec3, f32) {
        (self.compensated_f(factors, wo, wi, f_ss), self.compensated_pdf(wo, wi, pdf_ss))
    }
    #[inline(always)]
    fn turquin_weight(&self, wo: Vec3, weight: Vec3) -> Option<Vec3> {
        Compensated::<S, Conductor>::turquin_weight(self, wo, weight)
    }
}

impl<S: MicrosurfaceSlope> Composition for Compensated<S, Dielectric> {
    type Single = MicrofacetBsdf<S, Dielectric>;
    #[inline(always)]
    fn single(&self) -> &Self::Single {
        &self.single
    }
    #[inline(always)]
    fn dirac(&self) -> bool {
        self.single.is_specular()
    }
    #[inline(always)]
    fn scheme(&self) -> Compensation {
        self.scheme
    }
    type Factors<'a>
        = ()
    where
        Self: 'a;
    #[inline(always)]
    fn factors(&self, _n: usize) {}
    #[inline(always)]
    fn compensated_f(&self, _factors: &(), wo: Vec3, wi: Vec3, f_ss: Vec3) -> Vec3 {
        Compensated::<S, Dielectric>::compensated_f(self, wo, wi, f_ss)
    }
    #[inline(always)]
    fn compensated_pdf(&self, wo: Vec3, wi: Vec3, pdf_ss: f32) -> f32 {
        Compensated::<S, Dielectric>::compensated_pdf(self, wo, wi, pdf_ss)
    }
    #[inline(always)]
    fn compensated(&self, _factors: &(), wo: Vec3, wi: Vec3, f_ss: Vec3, pdf_ss: f32) -> (Vec3, f32) {
        Compensated::<S, Dielectric>::compensated(self, wo, wi, f_ss, pdf_ss)
    }
    #[inline(always)]
    fn turquin_weight(&self, wo: Vec3, weight: Vec3) -> Option<Vec3> {
        Compensated::<S, Dielectric>::turquin_weight(self, wo, weight)
    }
}

/// The batch size from which a compensated conductor tabulates its direction factors at its
/// roughness ([`Column`]: about 4500 instructions, which save about 150 per query).
const COLUMN_QUERIES: usize = 64;

/// Where a compensated conductor's batch reads its direction factors: the lobes' tables, or
/// their [`Column`] for a batch of at least [`COLUMN_QUERIES`] queries (of an additive scheme:
/// Turquin's reads one factor per query).
// (on the stack for one batch call: boxing the column would allocate on the hot path)
#[allow(clippy::large_enum_variant)]
enum ConductorFactors<'a> {
    Lobes(&'a ConductorLobes),
    Column(Column),
}

impl DirectionFactors for ConductorFactors<'_> {
    #[inline(always)]
    fn complement_at(&self, x: f32) -> f32 {
        match self {
            Self::Lobes(lobes) => lobes.complement_at(x),
            Self::Column(column) => column.complement_at(x),
        }
    }
    #[inline(always)]
    fn walk_factor_at(&self, x: f32) -> Vec3A {
        match self {
            Self::Lobes(lobes) => lobes.walk_factor_at(x),
            Self::Column(column) => column.walk_factor_at(x),
        }
    }
}

/// Whether the scalar calls take a query's directions as given (no renormalization).
#[inline(always)]
fn as_given(wo: Vec3, wi: Vec3) -> bool {
    is_direction(wo) & is_direction(wi)
}

/// The first `n` queries of structure-of-arrays slices (one bounds check for the loop's
/// reads).
#[inline(always)]
fn first<'a>(w: &Directions<'a>, n: usize) -> (&'a [f32], &'a [f32], &'a [f32]) {
    let (x, y, z) = w.slices();
    (&x[..n], &y[..n], &z[..n])
}

/// Query i of structure-of-arrays slices.
#[inline(always)]
fn at(w: (&[f32], &[f32], &[f32]), i: usize) -> Vec3 {
    Vec3::new(w.0[i], w.1[i], w.2[i])
}

/// The compensated scalar calls of a query whose directions are not unit as given (off the
/// loops' path).
#[cold]
#[inline(never)]
fn scalar_eval<B: Bsdf>(bsdf: &B, wo: Vec3, wi: Vec3) -> Vec3 {
    bsdf.eval(wo, wi).f
}

#[cold]
#[inline(never)]
fn scalar_pdf<B: Bsdf>(bsdf: &B, wo: Vec3, wi: Vec3) -> f32 {
    bsdf.pdf(wo, wi)
}

#[cold]
#[inline(never)]
fn scalar_eval_with_pdf<B: Bsdf>(bsdf: &B, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
    let (v, pdf) = bsdf.eval_with_pdf(wo, wi);
    (v.f, pdf)
}

#[cold]
#[inline(never)]
fn scalar_sample<B: Bsdf>(bsdf: &B, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
    bsdf.sample(wo, uc, u)
}

fn eval_batch<B: Composition>(
    bsdf: &B,
    wo: &Directions<'_>,
    wi: &Directions<'_>,
    f: &mut Channels<'_>,
) -> Result<(), Error> {
    bsdf.single().eval_batch(wo, wi, f)?;
    if bsdf.dirac() {
        return Ok(());
    }
    let (fa, fb, fc) = f.slices();
    let (wo, wi) = (first(wo, fa.len()), first(wi, fa.len()));
    let factors = bsdf.factors(fa.len());
    for i in 0..fa.len() {
        let (o, w) = (at(wo, i), at(wi, i));
        let v = if as_given(o, w) {
            bsdf.compensated_f(&factors, o, w, Vec3::new(fa[i], fb[i], fc[i]))
        } else {
            scalar_eval(bsdf, o, w)
        };
        (fa[i], fb[i], fc[i]) = (v.x, v.y, v.z);
    }
    Ok(())
}

fn pdf_batch<B: Composition>(
    bsdf: &B,
    wo: &Directions<'_>,
    wi: &Directions<'_>,
    pdf: &mut [f32],
) -> Result<(), Error> {
    bsdf.single().pdf_batch(wo, wi, pdf)?;
    // Turquin's density is single scattering's (its scalar `pdf` is single scattering's call)
    if bsdf.dirac() || bsdf.scheme() == Compensation::Turquin {
        return Ok(());
    }
    let (wo, wi) = (first(wo, pdf.len()), first(wi, pdf.len()));
    for (i, p) in pdf.iter_mut().enumerate() {
        let (o, w) = (at(wo, i), at(wi, i));
        *p = if as_given(o, w) { bsdf.compensated_pdf(o, w, *p) } else { scalar_pdf(bsdf, o, w) };
    }
    Ok(())
}

fn eval_with_pdf_batch<B: Composition>(
    bsdf: &B,
    wo: &Directions<'_>,
    wi: &Directions<'_>,
    f: &mut Channels<'_>,
    pdf: &mut [f32],
) -> Result<(), Error> {
    bsdf.single().eval_with_pdf_batch(wo, wi, f, pdf)?;
    if bsdf.dirac() {
        return Ok(());
    }
    let (fa, fb, fc) = f.slices();
    let pdf = &mut pdf[..fa.len()];
    let (wo, wi) = (first(wo, fa.len()), first(wi, fa.len()));
    let factors = bsdf.factors(fa.len());
    for i in 0..fa.len() {
        let (o, w) = (at(wo, i), at(wi, i));
        let (v, p) = if as_given(o, w) {
            bsdf.compensated(&factors, o, w, Vec3::new(fa[i], fb[i], fc[i]), pdf[i])
        } else {
            scalar_eval_with_pdf(bsdf, o, w)
        };
        (fa[i], fb[i], fc[i], pdf[i]) = (v.x, v.y, v.z, p);
    }
    Ok(())
}

/// Turquin's scheme samples single scattering: its batch, then each sample's weight scaled.
/// The additive schemes sample a mixture whose lobe choice depends on the query: the scalar
/// call query by query.
fn sample_batch<B: Composition>(
    bsdf: &B,
    wo: &Directions<'_>,
    uc: &[f32],
    u1: &[f32],
    u2: &[f32],
    out: &mut SampleOutputs<'_>,
) -> Result<(), Error> {
    if bsdf.scheme() != Compensation::Turquin || bsdf.dirac() {
        return sample_each(bsdf, wo, uc, u1, u2, out);
    }
    bsdf.single().sample_batch(wo, uc, u1, u2, out)?;
    let views = wo.slices();
    for i in 0..wo.len() {
        let o = at(views, i);
        if !is_direction(o) {
            out.set(i, scalar_sample(bsdf, o, uc[i], Vec2::new(u1[i], u2[i])));
        } else if out.pdf[i] > 0.0 {
            // a sample (a query without one has pdf 0 in both calls)
            match bsdf.turquin_weight(o, out.weight.get(i)) {
                Some(weight) => out.weight.set(i, weight),
                None => out.set(i, None),
            }
        }
    }
    Ok(())
}

/// The batch calls of the compensated conductor: single scattering's batch (eight lanes on GGX),
/// then each query's compensation by the scalar calls' own expression (see the bounds on
/// [`BatchBsdf`] for [`MicrofacetBsdf`], which carry over: the added lobe and the mixture
/// density are the scalar call's bits, so densities are equal bit for bit and f errs by single
/// scattering's error alone, scaled by Turquin's factor for that scheme). Turquin's samples are
/// single scattering's batch samples with the scalar call's weight factor (bit for bit); the
/// additive schemes sample by the scalar call, query by query.
impl<S: MicrosurfaceSlope> BatchBsdf for Compensated<S, Conductor> {
    fn eval_batch(
        &self,
        wo: &Directions<'_>,
        wi: &Directions<'_>,
        f: &mut Channels<'_>,
    ) -> Result<(), Error> {
        eval_batch(self, wo, wi, f)
    }

    fn pdf_batch(&self, wo: &Directions<'_>, wi: &Directions<'_>, pdf: &mut [f32]) -> Result<(), Error> {
        pdf_batch(self, wo, wi, pdf)
    }

    fn eval_with_pdf_batch(
        &self,
        wo: &Directions<'_>,
        wi: &Directions<'_>,
        f: &mut Channels<'_>,
        pdf: &mut [f32],
    ) -> Result<(), Error> {
        eval_with_pdf_batch(self, wo, wi, f, pdf)
    }

    fn sample_batch(
        &self,
        wo: &Directions<'_>,
        uc: &[f32],
        u1: &[f32],
        u2: &[f32],
        out: &mut SampleOutputs<'_>,
    ) -> Result<(), Error> {
        sample_batch(self, wo, uc, u1, u2, out)
    }
}

/// The batch calls of the compensated dielectric, as the conductor's: single scattering's
/// batch (eight lanes on GGX, η at least 0.05 from 1), then each query's compensation by the
/// scalar calls' own expression. f and the density err by single scattering's batch bounds
/// ([`MicrofacetBsdf`]'s), carried through the added lobe, the mixture's weight of
/// single scattering and Turquin's factor; Turquin's samples are single scattering's batch
/// samples (direction, event and η bit for bit) with the scalar call's weight factor.
impl<S: MicrosurfaceSlope> BatchBsdf for Compensated<S, Dielectric> {
    fn eval_batch(
        &self,
        wo: &Directions<'_>,
        wi: &Directions<'_>,
        f: &mut Channels<'_>,
    ) -> Result<(), Error> {
        eval_batch(self, wo, wi, f)
    }

    fn pdf_batch(&self, wo: &Directions<'_>, wi: &Directions<'_>, pdf: &mut [f32]) -> Result<(), Error> {
        pdf_batch(self, wo, wi, pdf)
    }

    fn eval_with_pdf_batch(
        &self,
        wo: &Directions<'_>,
        wi: &Directions<'_>,
        f: &mut Channels<'_>,
        pdf: &mut [f32],
    ) -> Result<(), Error> {
        eval_with_pdf_batch(self, wo, wi, f, pdf)
    }

    fn sample_batch(
        &self,
        wo: &Directions<'_>,
        uc: &[f32],
        u1: &[f32],
        u2: &[f32],
        out: &mut SampleOutputs<'_>,
    ) -> Result<(), Error> {
        sample_batch(self, wo, uc, u1, u2, out)
    }
}
