//! Choosing a technique: what each one is, what it costs, how far it is from the exact model,
//! and a chooser that picks the cheapest one within an albedo error budget.
//!
//! | technique | type | eval | exact model? | use when |
//! |---|---|---|---|---|
//! | single scattering | [`MicrofacetBsdf`](crate::MicrofacetBsdf) + [`Technique::SingleScattering`](crate::Technique::SingleScattering) | exact, exact pdf | no: loses the higher orders | smooth to moderate roughness, or a budget that tolerates the loss |
//! | compensated lobe | [`Compensated`](crate::Compensated) (default scheme [`Compensation::Walk`](crate::Compensation::Walk)) | exact (of the lobe), exact pdf | no: restores the lost energy from tables of the walk | rough metals and glass in production |
//! | random walk | [`MicrofacetBsdf`](crate::MicrofacetBsdf) (default [`Technique::RandomWalk`](crate::Technique::RandomWalk)) | unbiased estimate, exact sample weights | yes (Heitz et al. 2016) | references, the rough end, anisotropic surfaces |
//! | invariance principle | [`Technique::Invariance`](crate::Technique::Invariance) | unbiased, less noise | yes (the walk's model) | the walk's model with less noise on rough conductors |
//! | position-free PT, BDPT | [`Technique::PositionFree`](crate::Technique::PositionFree) | unbiased | a different model (Wang et al. 2022) | research comparisons |
//!
//! # Error: one definition
//!
//! The **error** of a technique is its hemispherical albedo error against the exact random
//! walk: ε = |Ā − Ā_walk|, with Ā = 2∫₀¹ A(μ) μ dμ the cosine-weighted mean over view
//! directions of the directional albedo A(μ) = ∫ f |cos θi| dωi (the energy a white furnace
//! under uniform light sees), the largest RGB channel; for a dielectric A = R + T (flux, no
//! η² factor), on the worse side of the interface. A budget of 1 % is ε ≤ 0.01. A single view
//! can err more than the mean: single scattering's loss peaks at grazing views μ ≈ α (for
//! F = 1 about 0.11 at every α, a sliver of the hemisphere when α is small).
//!
//! * **Single scattering** loses the energy of the higher orders: for a conductor at most the
//!   F = 1 loss 1 − Ē(α) of the albedo tables (the walk's paths do not depend on F and every
//!   bounce multiplies a path's weight by F ≤ 1, so this bounds every conductor's loss, tightly
//!   for the bright metals); for a dielectric 1 − Ā_ss (the walk conserves the flux).
//! * **The compensated lobes** restore that energy from tables; what they miss (the per-bounce
//!   Fresnel term of coloured metals, the split between reflection and transmission, the
//!   tables' interpolation) is bounded per slope family and material class by the largest
//!   error measured against the walk by `cargo run --release -p lab --bin techniques` (plus
//!   three standard errors): 0.7 % (GGX) and 0.8 % (Beckmann) for conductors, 0.6 % and 0.5 %
//!   for dielectrics.
//! * **The walk** and the estimators of its model are unbiased: no error, noise instead (the
//!   report's error-against-time plots show how fast it falls).
//!
//! # The chooser
//!
//! [`Choice::new`] takes the slope, the material and the budget, and returns the cheapest
//! technique within it with its error bound and its cost relative to single scattering; call it
//! per material (a table lookup). [`Choice::build`] makes the BSDF, a [`ChosenBsdf`] (`Copy`,
//! no allocation, object safe through [`Bsdf`](crate::Bsdf)): call it per hit.
//!
//! ```
//! use microsurface::glam::{Vec2, Vec3};
//! use microsurface::techniques::Choice;
//! use microsurface::{Bsdf, Dielectric, Ggx};
//!
//! let glass = Dielectric::new(1.5)?;
//! let slope = Ggx::isotropic(0.5)?;
//! let choice = Choice::new(&slope, &glass, 0.01)?; // per material
//! println!("{:?}: error ≤ {:.4}, {:.1}× single scattering", choice.technique, choice.error, choice.cost);
//! let bsdf = choice.build(slope, glass)?; // per hit
//! let s = bsdf.sample(Vec3::Z, 0.5, Vec2::new(0.3, 0.7));
//! assert!(s.is_some_and(|s| s.weight.is_finite()));
//! # Ok::<(), microsurface::Error>(())
//! ```
//!
//! # The figures
//!
//! The measured costs, and per slope family, material and roughness the measured errors beside
//! the chooser's (single scattering's error from the tables, the compensated lobes' bounds) and
//! its choices, written by `cargo run --release -p lab --bin techniques` (its full run;
//! `--quick` checks that the shipped bounds hold). The report's results page has the decision
//! map over α.
//!
#![doc = include_str!("../../docs/techniques.md")]

mod choice;
mod error_model;

pub use choice::{Budgeted, Candidates, Choice, ChosenBsdf, ChosenTechnique};
