//! The private supertrait that seals the crate's extension traits ([`MicrosurfaceSlope`],
//! [`VCavitySlope`], [`MicrosurfaceHeight`], [`Material`]): it is public inside a private module, so it can
//! bound a public trait, but no other crate can name it, hence none can implement those
//! traits.
//!
//! [`MicrosurfaceSlope`]: crate::slope::MicrosurfaceSlope
//! [`VCavitySlope`]: crate::vndf::VCavitySlope
//! [`MicrosurfaceHeight`]: crate::research::MicrosurfaceHeight
//! [`Material`]: crate::research::Material

/// Implemented by the crate's slope and height distributions and materials only.
pub trait Sealed {}
