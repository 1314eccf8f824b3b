//! Single scattering on noncentral (sheared) microsurfaces (Dupuy 2015, thesis §3.2): the
//! research-layer BSDFs of a [`Noncentral`](crate::slope::Noncentral) slope distribution with a
//! material, which the renderer's `NoncentralBsdf` and the LEADR lobes are built on.

mod single_scattering;

pub use single_scattering::NoncentralMaterial;
