//! Noncentral (sheared) microsurfaces (Dupuy 2015, thesis §3.2): the slope distribution
//! offset by a mean slope, single scattering on it with a conductor, dielectric or diffuse
//! material, and its renderer BSDF, the lobe a LEADR-filtered texel evaluates.

mod bsdf;
mod conductor;
mod dielectric;
mod diffuse;
mod single_scattering;
mod slope;

pub use bsdf::{NoncentralBsdf, NoncentralMasking};
pub use single_scattering::NoncentralMaterial;
pub use slope::Noncentral;
