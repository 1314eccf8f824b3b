//! The private supertrait that seals the crate's extension traits ([`MicrosurfaceSlope`],
//! [`VCavitySlope`], [`MicrosurfaceHeight`]): it is public inside a private module, so it can
//! bound a public trait, but no other crate can name it, hence none can implement those
//! traits.
//!
//! [`MicrosurfaceSlope`]: crate::MicrosurfaceSlope
//! [`VCavitySlope`]: crate::VCavitySlope
//! [`MicrosurfaceHeight`]: crate::MicrosurfaceHeight

/// Implemented by the crate's slope and height distributions only.
pub trait Sealed {}
