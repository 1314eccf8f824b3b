//! Data-driven microsurfaces (Dupuy 2015, thesis ch. 4): slope distributions tabulated on
//! rings (isotropic) or on a grid (anisotropic), NDF extraction from measured BRDFs by power
//! iteration, and the MERL BRDF reader.

mod extract;
mod grid;
mod merl;
mod radial;
mod rings;
mod vndf;

pub use extract::{
    BackscatterShadowing, Extraction, GridExtraction, extract_anisotropic, extract_anisotropic_fn,
    extract_fresnel, extract_isotropic, extract_isotropic_fn,
};
pub use grid::GridSlope;
pub use merl::{MERL_PHI_D, MERL_THETA_D, MERL_THETA_H, MerlBrdf, MerlError, half_diff_angles};
pub use radial::{MAX_RINGS, StretchedTabulated, TabulatedSlope, Tail};
