//! The LEADR validation (Dupuy 2015, §3.3–3.4), shared by `lab/src/bin/leadr` and
//! `tests/leadr.rs`: the procedural displacement map and the naive normal-map MIP LEADR is
//! compared against ([`surface`]), and the relative L1 error of a filtered lobe against the
//! supersampled ground truth, measured on the crate's own noncentral lobes ([`validate`]).

pub mod surface;
pub mod validate;
