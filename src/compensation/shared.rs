//! What the energy-compensated BSDFs share: the tables' range check of their constructors and
//! the final filter of a sample drawn from a sampling mixture.

use crate::albedo::{MAX_TABULATED_ALPHA, MAX_TABULATED_ETA};
use crate::bsdf::{BsdfSample, SampleFlags};
use crate::error::Error;
use glam::Vec3;

/// The largest f32 below 1: where a rescaled lobe-choice uniform is kept below 1.
pub(crate) const ONE_MINUS_ULP: f32 = 1.0 - f32::EPSILON / 2.0;

/// `Ok` if the roughness `alpha` = √(αx αy) lies within the albedo tables' range
/// (≤ [`MAX_TABULATED_ALPHA`]) and, for a dielectric, its relative index `eta` within
/// [1/[`MAX_TABULATED_ETA`], [`MAX_TABULATED_ETA`]]; otherwise [`Error::InvalidParameter`] naming
/// `"alpha"` or `"eta"`, with `tables` (the tables' name) in its `expected`.
pub(crate) fn check_tabulated(alpha: f32, eta: Option<f32>, tables: Tables) -> Result<(), Error> {
    if alpha > MAX_TABULATED_ALPHA {
        return Err(Error::InvalidParameter { name: "alpha", value: alpha, expected: tables.alpha() });
    }
    match eta {
        Some(eta) if !(1.0 / MAX_TABULATED_ETA..=MAX_TABULATED_ETA).contains(&eta) => {
            Err(tables.eta_error(eta))
        }
        _ => Ok(()),
    }
}

/// Which tables a compensated BSDF reads (for the message of a rejected parameter).
#[derive(Debug, Clone, Copy)]
pub(crate) enum Tables {
    /// The single-scattering albedo tables.
    Albedo,
    /// The random walk's dielectric tables.
    Walk,
}

impl Tables {
    fn alpha(self) -> &'static str {
        match self {
            Self::Albedo => "√(αx αy) at most 1 (MAX_TABULATED_ALPHA), the albedo tables' range",
            Self::Walk => "√(αx αy) at most 1 (MAX_TABULATED_ALPHA), the walk tables' range",
        }
    }

    /// The error of a relative index `value` outside the tables' range.
    pub(crate) fn eta_error(self, value: f32) -> Error {
        let expected = match self {
            Self::Albedo => {
                "a relative index in [1/3, 3] (MAX_TABULATED_ETA), the dielectric albedo tables' range"
            }
            Self::Walk => {
                "a relative index in [1/3, 3] (MAX_TABULATED_ETA), the dielectric walk tables' range"
            }
        };
        Error::InvalidParameter { name: "eta", value, expected }
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
