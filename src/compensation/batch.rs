//! The batch calls of the compensated lobes ([`BatchBsdf`]): single scattering's batch (in
//! vector lanes where [`MicrofacetBsdf`] has them, by its scalar calls elsewhere), then one pass
//! over the queries that ends each as the scalar call ends it, with the same functions: the
//! added lobe or Turquin's factor on f, the sampling mixture on the density, Turquin's factor
//! on a sample's weight. A conductor's pass runs those functions in three stages per block of
//! queries (vectorized, the table reads, vectorized); a dielectric's, query by query, from its
//! tables' values at the hit laid out for the batch.
//!
//! The scalar calls renormalize directions that drifted from unit length on entry
//! (`unit_directions!`), and single scattering's batch answers such a query with its own
//! scalar call, at the renormalized directions. The pass therefore composes only the queries
//! whose directions are unit as given (the entry test of the scalar calls, which then use them
//! unchanged) and gives every other query the compensated scalar call itself: the
//! renormalized directions, or the contract's *nothing*.

use super::compensated::{Compensated, Compensation};
use super::conductor::{DirectionFactors, mixture_of};
use super::dielectric::GlassFactors;
use crate::bsdf::{BatchBsdf, Bsdf, BsdfSample, MicrofacetBsdf, SampleOutputs, sample_each};
use crate::contract::is_direction;
use crate::error::Error;
use crate::lanes::{LaneLoop, dispatch};
use crate::material::{Conductor, Dielectric};
use crate::slope::MicrosurfaceSlope;
use crate::soa::{Channels, Directions, next_marked};
use glam::{Vec2, Vec3};

/// What a compensated lobe's scalar calls compute after single scattering, at valid
/// directions (the material's own functions, which the scalar calls end with), and the passes
/// of a batch that compose them.
trait Composition: Bsdf {
    /// The single-scattering BSDF inside.
    type Single: BatchBsdf;
    fn single(&self) -> &Self::Single;
    /// A Dirac lobe: single scattering's answers, uncompensated.
    fn dirac(&self) -> bool;
    fn scheme(&self) -> Compensation;
    fn turquin_weight(&self, wo: Vec3, weight: Vec3) -> Option<Vec3>;
    /// f of every query whose directions are unit as given, from single scattering's f in `f`;
    /// every other query is marked with a NaN in f's first channel.
    fn compose_f(&self, wo: Slices<'_>, wi: Slices<'_>, f: SlicesMut<'_>);
    /// The density of every query whose directions are unit as given, from single
    /// scattering's in `pdf`; every other query is marked with a NaN.
    fn compose_pdf(&self, wo: Slices<'_>, wi: Slices<'_>, pdf: &mut [f32]);
    /// [`Composition::compose_f`] and the density of the same queries from single
    /// scattering's in `pdf`.
    fn compose_f_pdf(&self, wo: Slices<'_>, wi: Slices<'_>, f: SlicesMut<'_>, pdf: &mut [f32]);
}

/// Three coordinate slices of equal length.
type Slices<'a> = (&'a [f32], &'a [f32], &'a [f32]);
/// Three mutable channel slices of equal length.
type SlicesMut<'a> = (&'a mut [f32], &'a mut [f32], &'a mut [f32]);

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
    #[inline(always)]
    fn turquin_weight(&self, wo: Vec3, weight: Vec3) -> Option<Vec3> {
        Compensated::<S, Conductor>::turquin_weight(self, wo, weight)
    }
    /// In three stages per block of queries: the coordinates and weights in vectorized lanes,
    /// the lookups query by query, f in vectorized lanes; the lookups from the lobes'
    /// [`Column`](super::conductor::Column) in a batch of at least [`column_queries`] queries,
    /// else from the lobes' tables.
    fn compose_f(&self, wo: Slices<'_>, wi: Slices<'_>, f: SlicesMut<'_>) {
        if f.0.len() >= column_queries(self.scheme) {
            let column = self.lobes.column(self.scheme);
            dispatch(&mut ConductorStages { bsdf: self, factors: &column, wo, wi, f });
        } else {
            dispatch(&mut ConductorStages { bsdf: self, factors: &self.lobes, wo, wi, f });
        }
    }
    /// In three stages per block of queries, as f's: which queries mix, in vectorized lanes;
    /// the mixture's parts query by query; the density in vectorized lanes.
    fn compose_pdf(&self, wo: Slices<'_>, wi: Slices<'_>, pdf: &mut [f32]) {
        dispatch(&mut DensityStages { bsdf: self, wo, wi, pdf });
    }
    fn compose_f_pdf(&self, wo: Slices<'_>, wi: Slices<'_>, f: SlicesMut<'_>, pdf: &mut [f32]) {
        self.compose_f(wo, wi, f);
        // (the queries f's pass leaves to the scalar call take its density too)
        if self.lobes.mixing {
            self.compose_pdf(wo, wi, pdf);
        }
    }
}

/// The three stages of a compensated conductor's density over a batch (see
/// [`Composition::compose_pdf`]).
struct DensityStages<'s, 'a, 'b, S> {
    bsdf: &'s Compensated<S, Conductor>,
    wo: Slices<'a>,
    wi: Slices<'a>,
    pdf: &'b mut [f32],
}

impl<S: MicrosurfaceSlope> LaneLoop for DensityStages<'_, '_, '_, S> {
    #[inline(always)]
    fn run(&mut self) {
        // (a copy, as in the stages of f)
        let bsdf = &{ *self.bsdf };
        let pdf = &mut *self.pdf;
        let n = pdf.len();
        let (wo, wi) = (cut(self.wo, n), cut(self.wi, n));
        for start in (0..n).step_by(BLOCK) {
            let m = BLOCK.min(n - start);
            // which queries mix: 1 or 0, NaN marking a query the pass does not compose
            let mut weight = [0.0f32; BLOCK];
            for (k, slot) in weight[..m].iter_mut().enumerate() {
                let (o, w) = (at(wo, start + k), at(wi, start + k));
                let mixes = if bsdf.mixes_at(o.z, w.z) { 1.0 } else { 0.0 };
                *slot = if as_given(o, w) { mixes } else { f32::NAN };
            }
            // the mixture's parts (at any cosine: a cell's index is clamped to the table)
            let (mut share, mut added) = ([0.0f32; BLOCK], [0.0f32; BLOCK]);
            for k in 0..m {
                (share[k], added[k]) = bsdf.lobes.mixture_parts(wo.2[start + k], wi.2[start + k]);
            }
            // the density
            let pdf = &mut pdf[start..start + m];
            for k in 0..m {
                let mixed = mixture_of((share[k], added[k]), pdf[k]);
                let v = if weight[k] > 0.0 { mixed } else { pdf[k] };
                pdf[k] = if weight[k].is_nan() { f32::NAN } else { v };
            }
        }
    }
}

/// The three stages of a compensated conductor's f over a batch (see
/// [`Composition::compose_f`]), compiled by [`dispatch`] for the CPU's vector instructions.
struct ConductorStages<'s, 'a, 'b, S, F> {
    bsdf: &'s Compensated<S, Conductor>,
    factors: &'s F,
    wo: Slices<'a>,
    wi: Slices<'a>,
    f: SlicesMut<'b>,
}

/// Queries per block of [`ConductorStages`] (the first stage's outputs, on the stack).
const BLOCK: usize = 64;

impl<S: MicrosurfaceSlope, F: DirectionFactors> LaneLoop for ConductorStages<'_, '_, '_, S, F> {
    #[inline(always)]
    fn run(&mut self) {
        // (one copy of the stages per scheme: loops without a branch on it)
        match self.bsdf.scheme {
            Compensation::Walk => self.stages(Compensation::Walk),
            Compensation::KullaConty => self.stages(Compensation::KullaConty),
            Compensation::Turquin => self.stages(Compensation::Turquin),
        }
    }
}

impl<S: MicrosurfaceSlope, F: DirectionFactors> ConductorStages<'_, '_, '_, S, F> {
    #[inline(always)]
    fn stages(&mut self, scheme: Compensation) {
        // (a copy: the loops' reads of it cannot alias the outputs, which lets the compiler
        // vectorize them)
        let bsdf = &{ *self.bsdf };
        let (fa, fb, fc) = (&mut *self.f.0, &mut *self.f.1, &mut *self.f.2);
        let n = fa.len();
        let (fb, fc) = (&mut fb[..n], &mut fc[..n]);
        let (wo, wi) = (cut(self.wo, n), cut(self.wi, n));
        for start in (0..n).step_by(BLOCK) {
            let m = BLOCK.min(n - start);
            let (mut xo, mut xi, mut weight) = ([0.0f32; BLOCK], [0.0f32; BLOCK], [0.0f32; BLOCK]);
            // the coordinates and weights (a NaN weight marks a query the pass does not compose)
            for k in 0..m {
                let (o, w) = (at(wo, start + k), at(wi, start + k));
                let (a, b, c) = bsdf.coordinates_of(scheme, o.z, w.z);
                (xo[k], xi[k], weight[k]) = (a, b, if as_given(o, w) { c } else { f32::NAN });
            }
            // the lookups
            let mut lookups = [[0.0f32; BLOCK]; 3];
            for k in 0..m {
                let v = bsdf.lookups_at(scheme, self.factors, xo[k], xi[k]);
                (lookups[0][k], lookups[1][k], lookups[2][k]) = (v.x, v.y, v.z);
            }
            // f
            let (fa, fb, fc) =
                (&mut fa[start..start + m], &mut fb[start..start + m], &mut fc[start..start + m]);
            for k in 0..m {
                let v = Vec3::new(lookups[0][k], lookups[1][k], lookups[2][k]);
                let f = bsdf.compose(scheme, Vec3::new(fa[k], fb[k], fc[k]), v, weight[k]);
                (fa[k], fb[k], fc[k]) = (f.x, f.y, f.z);
            }
        }
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
    #[inline(always)]
    fn turquin_weight(&self, wo: Vec3, weight: Vec3) -> Option<Vec3> {
        Compensated::<S, Dielectric>::turquin_weight(self, wo, weight)
    }
    /// Query by query, the tables' values from the lobes'
    /// [`GlassColumn`](super::dielectric::GlassColumn) in a batch of at least
    /// [`GLASS_COLUMN_QUERIES`] queries, else from the lobes' tables.
    fn compose_f(&self, wo: Slices<'_>, wi: Slices<'_>, f: SlicesMut<'_>) {
        if f.0.len() >= GLASS_COLUMN_QUERIES {
            glass_f(self, &self.lobes.column(self.scheme), wo, wi, f);
        } else {
            glass_f(self, &self.lobes, wo, wi, f);
        }
    }
    /// Query by query, as f's.
    fn compose_pdf(&self, wo: Slices<'_>, wi: Slices<'_>, pdf: &mut [f32]) {
        if pdf.len() >= GLASS_COLUMN_QUERIES {
            glass_pdf(self, &self.lobes.column(self.scheme), wo, wi, pdf);
        } else {
            glass_pdf(self, &self.lobes, wo, wi, pdf);
        }
    }
    /// Query by query, as f's, the lobes read at the view once for both.
    fn compose_f_pdf(&self, wo: Slices<'_>, wi: Slices<'_>, f: SlicesMut<'_>, pdf: &mut [f32]) {
        if f.0.len() >= GLASS_COLUMN_QUERIES {
            glass_f_pdf(self, &self.lobes.column(self.scheme), wo, wi, f, pdf);
        } else {
            glass_f_pdf(self, &self.lobes, wo, wi, f, pdf);
        }
    }
}

/// The batch size from which a compensated dielectric lays out its tables' values at its
/// (roughness, index) ([`GlassColumn`](super::dielectric::GlassColumn)). Its construction
/// costs about 4300 instructions (Turquin's 1300); in a batch of 1024 queries it saves 56
/// (Turquin's f) to 205 (`eval_with_pdf` of the additive schemes) instructions per query
/// against the lobes' own tables, so that it pays from about 30 queries.
const GLASS_COLUMN_QUERIES: usize = 32;

/// [`Composition::compose_f`] of a compensated dielectric with the tables' values from
/// `factors`.
fn glass_f<S: MicrosurfaceSlope, F: GlassFactors>(
    bsdf: &Compensated<S, Dielectric>,
    factors: &F,
    wo: Slices<'_>,
    wi: Slices<'_>,
    (fa, fb, fc): SlicesMut<'_>,
) {
    let n = fa.len();
    let (fb, fc, wo, wi) = (&mut fb[..n], &mut fc[..n], cut(wo, n), cut(wi, n));
    for i in 0..n {
        let (o, w) = (at(wo, i), at(wi, i));
        if as_given(o, w) {
            let v = bsdf.compensated_f(factors, o, w, Vec3::new(fa[i], fb[i], fc[i]));
            (fa[i], fb[i], fc[i]) = (v.x, v.y, v.z);
        } else {
            fa[i] = f32::NAN;
        }
    }
}

/// [`Composition::compose_pdf`] of a compensated dielectric with the tables' values from
/// `factors`.
fn glass_pdf<S: MicrosurfaceSlope, F: GlassFactors>(
    bsdf: &Compensated<S, Dielectric>,
    factors: &F,
    wo: Slices<'_>,
    wi: Slices<'_>,
    pdf: &mut [f32],
) {
    let (wo, wi) = (cut(wo, pdf.len()), cut(wi, pdf.len()));
    for (i, p) in pdf.iter_mut().enumerate() {
        let (o, w) = (at(wo, i), at(wi, i));
        *p = if as_given(o, w) { bsdf.compensated_pdf(factors, o, w, *p) } else { f32::NAN };
    }
}

/// [`Composition::compose_f_pdf`] of a compensated dielectric with the tables' values from
/// `factors`.
fn glass_f_pdf<S: MicrosurfaceSlope, F: GlassFactors>(
    bsdf: &Compensated<S, Dielectric>,
    factors: &F,
    wo: Slices<'_>,
    wi: Slices<'_>,
    (fa, fb, fc): SlicesMut<'_>,
    pdf: &mut [f32],
) {
    let n = fa.len();
    let (fb, fc, pdf, wo, wi) = (&mut fb[..n], &mut fc[..n], &mut pdf[..n], cut(wo, n), cut(wi, n));
    for i in 0..n {
        let (o, w) = (at(wo, i), at(wi, i));
        if as_given(o, w) {
            let (v, p) = bsdf.compensated(factors, o, w, Vec3::new(fa[i], fb[i], fc[i]), pdf[i]);
            (fa[i], fb[i], fc[i], pdf[i]) = (v.x, v.y, v.z, p);
        } else {
            fa[i] = f32::NAN;
        }
    }
}

/// The batch size from which a compensated conductor lays out its direction factors at its
/// roughness ([`Column`](super::conductor::Column)), per scheme. In a batch of 1024 queries it
/// saves 24 (Turquin) to 146 (the walk's orders) instructions per query of f, its construction
/// included; it costs about 9000 instructions with the walk's series and a few hundred without,
/// so that it pays from about 60 and 15 queries.
fn column_queries(scheme: Compensation) -> usize {
    if scheme == Compensation::Walk { 64 } else { 16 }
}

/// Whether the scalar calls take a query's directions as given (no renormalization).
#[inline(always)]
fn as_given(wo: Vec3, wi: Vec3) -> bool {
    is_direction(wo) & is_direction(wi)
}

/// The first `n` queries of structure-of-arrays slices (one bounds check for a loop's
/// reads).
#[inline(always)]
fn cut(w: Slices<'_>, n: usize) -> Slices<'_> {
    (&w.0[..n], &w.1[..n], &w.2[..n])
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
    let (wo, wi) = (cut(wo.slices(), fa.len()), cut(wi.slices(), fa.len()));
    bsdf.compose_f(wo, wi, (&mut *fa, &mut *fb, &mut *fc));
    let mut from = 0;
    while let Some(i) = next_marked(fa, from) {
        let v = scalar_eval(bsdf, at(wo, i), at(wi, i));
        (fa[i], fb[i], fc[i]) = (v.x, v.y, v.z);
        from = i + 1;
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
    let (wo, wi) = (cut(wo.slices(), pdf.len()), cut(wi.slices(), pdf.len()));
    bsdf.compose_pdf(wo, wi, pdf);
    let mut from = 0;
    while let Some(i) = next_marked(pdf, from) {
        pdf[i] = scalar_pdf(bsdf, at(wo, i), at(wi, i));
        from = i + 1;
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
    let (wo, wi) = (cut(wo.slices(), fa.len()), cut(wi.slices(), fa.len()));
    bsdf.compose_f_pdf(wo, wi, (&mut *fa, &mut *fb, &mut *fc), pdf);
    let mut from = 0;
    while let Some(i) = next_marked(fa, from) {
        let (v, p) = scalar_eval_with_pdf(bsdf, at(wo, i), at(wi, i));
        (fa[i], fb[i], fc[i], pdf[i]) = (v.x, v.y, v.z, p);
        from = i + 1;
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

/// The batch calls of the compensated conductor: single scattering's batch (vector lanes on GGX),
/// then each query's compensation by the scalar calls' own functions (see the bounds on
/// [`BatchBsdf`] for [`MicrofacetBsdf`], which carry over: 1 − E and the mixture density are
/// the scalar call's bits, so densities are equal bit for bit and f errs by single scattering's
/// error, scaled by Turquin's factor for that scheme, and for the walk's orders by the series'
/// rounding, within 1e-6 per channel of its cell's largest value). Turquin's samples are single
/// scattering's batch samples with the scalar call's weight factor (bit for bit); the additive
/// schemes sample by the scalar call, query by query.
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
/// batch (vector lanes on GGX, η at least 0.05 from 1), then each query's compensation by the
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
