//! Height distributions of the microsurface (Heitz et al. 2016, supplement §1).
//!
//! The BSDFs of the Smith model do not depend on the height distribution (supplement §1.1):
//! heights only enter through C¹(h). [`UniformHeight`] is the cheaper choice;
//! [`GaussianHeight`] is provided because the supplement validates both.

mod gaussian;
mod uniform;

pub use gaussian::GaussianHeight;
pub use uniform::UniformHeight;

/// A distribution of microsurface heights: its density `p1`, CDF `c1` and inverse CDF `inv_c1`
/// (`MicrosurfaceHeight` in Heitz et al. 2016, supplement §1.1).
///
/// Heights are in the units of the distribution; `c1` accepts ±∞ (a ray starting above the
/// whole surface has h = +∞ and C¹(h) = 1).
///
/// Sealed: implemented by [`UniformHeight`] and [`GaussianHeight`] only. The Smith BSDFs do
/// not depend on the height distribution (supplement §1.1), so a distribution of one's own
/// would change nothing the crate computes but the walk's intermediate heights; sealing lets
/// the walks rely on the contract: `c1` is a continuous CDF from 0 at −∞ to 1 at +∞, `p1` its
/// derivative and `inv_c1` its inverse on [0, 1].
///
/// Invalid input ([policy](crate#invalid-input)): a NaN height or a `u` that is NaN or outside
/// [0, 1] trips a debug assertion in debug builds; release builds return 0 from `p1` (a
/// density) and NaN from `c1` and `inv_c1`.
pub trait MicrosurfaceHeight: crate::sealed::Sealed + Copy + core::fmt::Debug + Send + Sync {
    /// The height density P¹(h).
    fn p1(&self, h: f32) -> f32;

    /// The height CDF C¹(h) = ∫₋∞ʰ P¹(t) dt ∈ [0, 1].
    fn c1(&self, h: f32) -> f32;

    /// The inverse CDF: the height h with C¹(h) = u, for u ∈ [0, 1].
    ///
    /// Finite on all of [0, 1]; the end values are documented by each distribution.
    fn inv_c1(&self, u: f32) -> f32;
}
