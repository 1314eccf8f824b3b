//! Fresnel reflectance of smooth interfaces (used per microfacet).

mod conductor;
mod dielectric;
mod presets;
mod schlick;

pub(crate) use conductor::conductor_reflectance;
pub use conductor::{ComplexIor, fresnel_conductor};
pub use dielectric::fresnel_dielectric;
pub(crate) use dielectric::{dielectric_reflectance, fresnel_dielectric_cosines};
pub use schlick::fresnel_schlick;
