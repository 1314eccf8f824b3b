//! # lab
//!
//! The applications built on `microsurface` and its validation harness (`publish = false`):
//!
//! * [`report`]: the report of error against run time of every estimator, with the lobes, the
//!   energy per order, the cost and the albedo tables (`cargo run --release -p lab --bin report`);
//! * [`tracer`]: the core of the path tracer that renders the roughness sweep and its white
//!   furnace (`--bin path_tracer`);
//! * the studies run as binaries: `compensation` (the compensated lobes against the walk),
//!   `stability` (the stability report), `leadr` (LEADR filtering: error table and picture).

pub mod report;
pub mod tracer;
