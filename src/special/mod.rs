//! Special functions used at run time: the error function, its inverse, log-gamma and beta; the
//! sine and cosine of an azimuth in turns.
//!
//! Each public function states its maximum error over its whole domain, measured against
//! `statrs` in `tests/special/functions.rs`.

mod erf;
mod erfcx;
mod erfinv;
mod exp;
mod gamma;
mod gauss_legendre;
mod gaussian;
mod ln;
mod stirling;
mod tail_ratio;
mod trig;

pub use erf::{erf, erfc};
pub(crate) use erf::{erf64, erfc64};
pub(crate) use erfcx::{PSI_SERIES_FROM, erfcx64, one_minus_scaled_erfcx};
pub use erfinv::erfinv;
pub(crate) use erfinv::{NO_LOG_BELOW, erfc_inv_f32, erfinv_central, erfinv_from_both_ends, erfinv64};
pub(crate) use exp::{EXP_NONPOSITIVE_FROM, ROUNDING_MAGIC, exp_nonpositive};
pub use gamma::{beta, ln_beta, ln_gamma};
pub(crate) use gauss_legendre::{GAUSS_LEGENDRE_8, GAUSS_LEGENDRE_16};
pub(crate) use gaussian::gaussian_integral_and_half;
pub(crate) use ln::{exp_f32, ln, ln_1m_exp_f32, ln_f32, ln_of};
pub(crate) use stirling::{beta_1p_of, ln_beta_1p_of};
pub(crate) use tail_ratio::tail_ratio;
pub use trig::sin_cos_turns;
pub(crate) use trig::sin_cos_turns_of;
