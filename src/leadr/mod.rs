//! LEAN/LEADR mapping: linear filtering of displacement and normal maps into noncentral
//! anisotropic Beckmann lobes (Dupuy 2015, §3.3–3.4; Dupuy et al. 2013; Olano and Baker 2010).
//!
//! A displacement map's slopes, together with the base microsurface's roughness, are stored
//! as five raw slope moments per texel ([`SlopeMoments`]), which average linearly over texels
//! and so can be MIP-mapped ([`LeadrMap`]); each texel's moments give back the noncentral
//! Beckmann lobe of the same first and second moments ([`LeadrLobe`]). Beckmann only: GGX's
//! second slope moments diverge.

#[cfg(feature = "data-driven")]
mod downsample;
#[cfg(feature = "data-driven")]
mod fft;
mod height_map;
mod histogram;
mod lobe;
mod map;
mod moments;

pub use crate::noncentral::{Noncentral, NoncentralBsdf, NoncentralMasking, NoncentralMaterial};
#[cfg(feature = "data-driven")]
pub use downsample::{Displacement, DownsampledSlope};
pub use height_map::HeightMap;
pub use histogram::{MAX_HISTOGRAM_BINS, SlopeHistogram};
pub use lobe::{CovarianceTreatment, LeadrLobe, MIN_EIGENVALUE_RATIO, MIN_LEADR_ALPHA};
pub use map::{LeadrMap, MomentLevel};
pub use moments::SlopeMoments;
