//! Integration tests of the renderer-facing BSDF API (`Bsdf`, `ShadingFrame`, `Transport`,
//! `MicrofacetBsdf` with every technique, `ClassicBrdf`, `EnergyByOrder`).
//!
//! The matrix: `ClassicBrdf` with Phong, Beckmann and GGX normals and both maskings;
//! `MicrofacetBsdf` with a perfect conductor (F = 1), gold, a dielectric η = 1.5 in radiance
//! and importance transport and coloured diffuse facets, over GGX and Beckmann slopes, with
//! single scattering, the random walk and the four position-free variants.
//!
//! * Exact densities (`ClassicBrdf`; single scattering on conductors and dielectrics): the
//!   samples pass a chi-square test against `pdf` (the samples that `sample` refuses, `None`,
//!   account for the mass ∫pdf leaves out, checked by a binomial test), every sample's weight
//!   is eval·|cos θi|/pdf (relative 1e-4) and ∫pdf ≤ 1 by quadrature.
//! * Stochastic models: E[weight] equals the albedo ∫ f·|cos θi| dωi, estimated independently
//!   by importance sampling `eval` with a proposal of exactly known density; every sample
//!   lands where `pdf` > 0 and carries consistent flags.
//!
//! Statistics: every Monte Carlo assertion is |m1 − m2| ≤ z·√(SE1² + SE2²) with
//! z = `family_z(0.01, m)` for the m assertions of its test function, and bounds the combined
//! SE so that the test can fail; chi-square tests run at the Šidák-corrected level
//! `sidak(0.01, CHI2_FAMILY)` over all chi-square tests of this file. Every generator is a
//! fixed-seed PCG.
//!
//! Files by concern: `weights` (stochastic models: weight against the albedo), `densities`
//! (exact densities: chi-square, weights, ∫pdf ≤ 1; normal mapping), `reciprocity` (transport
//! modes), `shading_frame`, `energy_by_order`, `invalid_directions`, `classic` (ClassicBrdf
//! specifics), `determinism` (object safety, determinism, decorrelation, stratified sampling),
//! `integrator` (flags, η, the specular limit, the roughness range), `backfacing_masking` and
//! `deep_tails`, `noncentral` and `noncentral_materials` (the sheared lobes of LEADR with
//! conductors, glass and diffuse facets); `fixtures` holds what they share.

mod backfacing_masking;
mod classic;
mod deep_tails;
mod densities;
mod determinism;
mod elliptical;
mod energy_by_order;
mod fixtures;
mod integrator;
mod invalid_directions;
mod noncentral;
mod noncentral_materials;
mod reciprocity;
mod roulette;
mod shading_frame;
mod sidedness;
mod weights;
