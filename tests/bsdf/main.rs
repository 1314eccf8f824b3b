//! The renderer-facing BSDF API (`Bsdf`, `MicrofacetBsdf`, `ClassicBrdf`, `ShadingFrame`):
//! every technique against its albedo, density and reciprocity (`api`), backfacing single
//! scattering (`backfacing_masking`) and the deep tails of the exact technique (`deep_tails`).

mod api;
mod backfacing_masking;
mod deep_tails;
