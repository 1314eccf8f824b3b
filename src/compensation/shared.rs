//! What the energy-compensated BSDFs share: the error of an index beyond the tables, the
//! reference to shared tables and their boxed construction, the value of invalid arguments, and
//! the final filter of a sample drawn from a sampling mixture.

use crate::bsdf::{BsdfSample, BsdfValue, SampleFlags};
use crate::error::Error;
use glam::Vec3;

/// The largest f32 below 1: where a rescaled lobe-choice uniform is kept below 1.
pub(crate) const ONE_MINUS_ULP: f32 = 1.0 - f32::EPSILON / 2.0;

/// The value of invalid arguments (the documented nothing of [`crate::Bsdf::eval`]).
pub(crate) const NOTHING: BsdfValue = BsdfValue { f: Vec3::ZERO, exact: true };

/// A boxed array of N elements `f(0)`, …, `f(N − 1)`, built on the heap (the shared tables are
/// too large for the stack).
pub(crate) fn boxed<T, const N: usize>(f: impl FnMut(usize) -> T) -> Box<[T; N]> {
    let v: Vec<T> = (0..N).map(f).collect();
    match v.into_boxed_slice().try_into() {
        Ok(b) => b,
        Err(_) => unreachable!("N elements"),
    }
}

/// The error of a relative index `value` outside the dielectric tables' range.
pub(crate) fn eta_error(value: f32) -> Error {
    Error::InvalidParameter {
        name: "eta",
        value,
        expected: "a relative index in [1/3, 3] (MAX_TABULATED_ETA), the dielectric compensation tables' range",
    }
}

/// A reference to tables shared by every instance of a compensated BSDF: compared by address,
/// printed by name.
pub(crate) struct Shared<T: 'static>(pub(crate) &'static T);

impl<T> Clone for Shared<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Shared<T> {}

impl<T> PartialEq for Shared<T> {
    fn eq(&self, other: &Self) -> bool {
        core::ptr::eq(self.0, other.0)
    }
}

impl<T> core::fmt::Debug for Shared<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "Shared<{}>({:p})", core::any::type_name::<T>(), self.0)
    }
}

/// The sample of direction `wi` drawn from a compensated BSDF's sampling mixture, from f·|cos θi|
/// (`f_cos`) and the mixture's density `pdf` at `wi`; `eta` is η_wi/η_wo of a transmission (a
/// reflection has 1). `None` unless the density is a normal finite f32, `wi` is off the horizon,
/// the weight f_cos/pdf is finite and f = f_cos/|cos θi| is a normal f32 (the filter of the
/// single-scattering sampler: a subnormal f has lost its precision). The last test is made in
/// f64, where f32::MIN_POSITIVE · |cos θi| is a normal number: in f32 that product is subnormal,
/// and an x86 core takes a microcode assist of about a hundred cycles to produce it (it had
/// doubled the time of the conductor's compensated sample).
#[inline(always)]
pub(crate) fn mixture_sample(wo: Vec3, wi: Vec3, f_cos: Vec3, pdf: f32, eta: f32) -> Option<BsdfSample> {
    if !(f32::MIN_POSITIVE..=f32::MAX).contains(&pdf) || wi.z == 0.0 {
        return None;
    }
    let weight = f_cos * (1.0 / pdf);
    if !weight.is_finite()
        || f64::from(f_cos.max_element()) < f64::from(f32::MIN_POSITIVE) * f64::from(wi.z.abs())
    {
        return None;
    }
    let reflection = (wi.z > 0.0) == (wo.z > 0.0);
    let flags = SampleFlags { reflection, transmission: !reflection, specular: false, exact_pdf: true };
    Some(BsdfSample { wi, weight, pdf, eta: if reflection { 1.0 } else { eta }, flags })
}
