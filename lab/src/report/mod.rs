//! The crate's report: every estimator's accuracy against run time, the lobes and energy per
//! scattering order, and the cost of every model, measured on this machine (run by
//! `lab/src/bin/report.rs` and, in its quick mode, by `lab/tests/report.rs`).
//!
//! The stages, one file each: [`configure`] (what and how much), [`measure`] (per-sample
//! values, timings, references, energy, lobes, cost), [`reduce`] (errors against time,
//! efficiency ratios with confidence intervals, lobe panels), [`tables`] (the albedo tables'
//! interpolation error), [`decision`] (the technique chooser's decision map), [`plot`] (SVG
//! figures) and
//! [`write`](mod@write) (CSV, Markdown, HTML); [`pipeline`] runs them in order, then the
//! efficiency table of the invariance-principle estimator ([`invariance`](mod@invariance)); a
//! full run rewrites the results page `docs/results.md` ([`results_page`]).

pub mod configure;
pub mod decision;
pub mod invariance;
pub mod measure;
pub mod pipeline;
pub mod plot;
pub mod reduce;
pub mod results_page;
pub mod tables;
pub mod write;
