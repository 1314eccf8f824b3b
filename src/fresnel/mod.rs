//! Fresnel reflectance of smooth interfaces (used per microfacet).

mod conductor;
mod dielectric;
mod presets;
mod schlick;

pub use conductor::{ComplexIor, fresnel_conductor};
pub(crate) use conductor::{conductor_reflectance, reflectance_of};
pub use dielectric::fresnel_dielectric;
pub(crate) use dielectric::{
    dielectric_reflectance, fresnel_dielectric_cosines_of, transmittance_dielectric_cosines_of,
};
pub use schlick::fresnel_schlick;
