//! # validation
//!
//! The validation harness of `microsurface`, shared by its integration tests, examples and
//! benches (`publish = false`, like rand_distr's `distr_test`). Shaped like Mitsuba 3's
//! `ChiSquareTest`: a goodness-of-fit test is a **domain** (where the samples are binned) ×
//! an **expectation** (how the expected counts are obtained):
//!
//! | domain | exact density (quadrature) | stochastic estimator |
//! |---|---|---|
//! | sphere of directions, or a cap around a pole | [`chi2::chi2_test`] | [`stochastic::stochastic_chi2`] |
//! | stretched slope plane of the normals visible from ωi | [`chi2::slope_chi2`] | — |
//!
//! Half-vector-space densities (visible normals) are tested in the slope plane, where a
//! sharp lobe is as wide as a broad one.
//!
//! Besides the chi-square tests: one quadrature module ([`quadrature`]: (cos θ, φ)
//! rectangles, the sphere, and the slope-space integrals of visible normals), one f64
//! reference model ([`reference`](mod@reference)), one set of statistical assertions (seeded generators,
//! Šidák-corrected z, mean within z·SE with SE small enough: the crate root), the pooling of
//! low-expectation cells ([`chi2::pool`]), the per-order albedos of the walk and the
//! position-free models in closed form for GGX α = 1 ([`per_order`]), the stability study's
//! configurations
//! ([`stability`]), the LEADR validation ([`leadr`](mod@leadr)), and what the benches share
//! (the measurement clock [`clock`], the pre-generated inputs [`inputs`], the research calls
//! the renderer's techniques wrap [`research`]). The applications built on it (the report, the
//! path tracer, the studies) are the `lab` crate's.
//!
//! # Examples
//!
//! ```
//! use validation::{Stats, assert_mean, family_z, rng, uniform64};
//!
//! // the mean of U(0, 1) is ½: one assertion at the family-wise level 0.01
//! let mut r = rng(1);
//! let mut stats = Stats::default();
//! for _ in 0..10_000 {
//!     stats.push(uniform64(&mut r));
//! }
//! assert_mean("uniform mean", &stats, 0.5, family_z(0.01, 1), 1e-2, 0.0);
//! ```

pub mod check;
pub mod chi2;
pub mod clock;
pub mod inputs;
pub mod leadr;
pub mod per_order;
pub mod quadrature;
pub mod reference;
pub mod research;
pub mod stability;
mod stats;
pub mod stochastic;

pub use stats::{
    Stats, TestRng, assert_mean, assert_refusal_rate, assert_two_sample, dir, family_z, par_map, rng, sidak,
    uniform_sphere, uniform32, uniform64, z_two_sided,
};
