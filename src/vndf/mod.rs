//! Visible-normal samplers, each with its exact density, and the V-cavity masking model
//! (Tokuyoshi, “Unbiased VNDF Sampling for Backfacing Shading Normals”, supplement).
//!
//! Every sampler here is valid on the whole sphere of incident directions, including
//! directions below the (shading-normal) horizon, and `pdf` integrates to one for each of
//! them. A renderer picks one by type.
//!
//! Invalid input ([policy](crate#invalid-input)), for every sampler, density and helper here:
//! a `wi` or `wm` that is zero, has a NaN or ±∞ component, or is not unit within
//! [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE), or a uniform outside [0, 1], trips a
//! debug assertion in debug builds; release builds return a NaN normal from the samplers, 0
//! from the densities and NaN from the other quantities (normalization, masking, hit
//! probability).

mod beckmann_newton;
mod bounded_cap;
mod disk_band;
mod ggx_disk;
mod smith;
mod spherical_cap;
mod vcavity;

pub use beckmann_newton::BeckmannNewton;
pub use bounded_cap::GgxBoundedCap;
pub use ggx_disk::GgxDisk;
pub use smith::SmithVndf;
pub use spherical_cap::GgxSphericalCap;
pub use vcavity::{VCavity, VCavitySlope};

use crate::contract::is_direction;
use crate::slope::MicrosurfaceSlope;
use glam::Vec3;

/// A sampler of microfacet normals visible from an incident direction, with its density.
pub trait VisibleNormalSampler: Copy + core::fmt::Debug + Send + Sync {
    /// A normal ωm (unit, ωm.z ≥ 0) visible from ωi, from uniforms in [0, 1). Smith samplers
    /// use `u[0]` and `u[1]`; V-cavity samplers also `u[2]`. Every quantile is inverted with
    /// its tails cut at 2⁻²⁴ (u used as clamp(u, 2⁻²⁴, 1 − 2⁻²⁴), the crate's tail policy): no
    /// sample lies beyond the last 2⁻²⁴ of the distribution, at either end.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` that is not a unit direction or a
    /// uniform outside [0, 1] gives `Vec3::NAN` (a debug assertion in debug builds).
    fn sample(&self, wi: Vec3, u: [f32; 3]) -> Vec3;

    /// The solid-angle density of [`VisibleNormalSampler::sample`] at ωm.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wm` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    fn pdf(&self, wi: Vec3, wm: Vec3) -> f32;
}

/// The Smith normalization factor G(i, m)/H(i) = |i·n| / ∫ D(ω) max(i·ω, 0) dω · χ⁺(i·m)
/// (Tokuyoshi, supplement §1, eq. 1), for any incident direction i.
///
/// With it, D_i(m) = G(i, m)/H(i) · ⟨i, m⟩ D(m)/|i·n| integrates to one also for backfacing
/// i. The integral is the slope's projected area: GGX (i_z + √(αx² i_x² + αy² i_y² + i_z²))/2,
/// Beckmann (i_z erfc(−i_z/√B) + √(B/π) exp(−i_z²/B))/2 with B = αx² i_x² + αy² i_y²,
/// evaluated in their cancellation-free forms for i_z < 0. It equals the full-spherical
/// masking 1/|1 + Λ(i)| of Wang et al. 2022 (eq. 10). Zero where i sees no microsurface;
/// saturates at `f32::MAX` near the nadir.
///
/// Invalid input ([policy](crate#invalid-input)): a `wi` or `wm` that is not a unit direction
/// gives NaN (a debug assertion in debug builds).
#[must_use]
#[inline]
pub fn smith_normalization<S: MicrosurfaceSlope>(slope: &S, wi: Vec3, wm: Vec3) -> f32 {
    require!(is_direction(wi) && is_direction(wm), f32::NAN; wi, wm);
    if wi.dot(wm) <= 0.0 {
        return 0.0;
    }
    // the area in f64: below the horizon it is Λ(−i)|i_z|, an f32 subnormal for low roughness
    // long before the ratio leaves the f32 range; saturates like Λ near the nadir
    let area = slope.projected_area64(wi);
    if area > 0.0 {
        (f64::from(wi.z.abs()) / area).min(f64::from(f32::MAX)) as f32
    } else if wi.x == 0.0 && wi.y == 0.0 {
        0.0
    } else {
        // the area underflowed f64 (Beckmann, |cot θ|/αᵢ > 26.6): the ratio is far above f32::MAX
        f32::MAX
    }
}
