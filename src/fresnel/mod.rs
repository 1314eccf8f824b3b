//! Fresnel reflectance of smooth interfaces (used per microfacet).

mod conductor;
mod dielectric;

pub use conductor::{ComplexIor, fresnel_conductor};
pub use dielectric::fresnel_dielectric;
