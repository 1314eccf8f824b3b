//! The slope families with compensation tables.

use crate::albedo::{AlbedoTable, DielectricAlbedoTable, DielectricWalkTable, ScatteringOrderTable};
use crate::slope::{AxisAlignedSlope, Beckmann, Elliptical, Ggx, MicrosurfaceSlope};

/// A slope family with the crate's compensation tables (GGX, Beckmann, and their elliptical
/// rotations): the families a [`super::Compensated`] BSDF can be built on.
pub trait AlbedoTabulated: MicrosurfaceSlope {
    /// The family's conductor tables (F = 1).
    const ALBEDO: AlbedoTable;
    /// The family's dielectric tables (reflected and transmitted, both sides).
    const DIELECTRIC_ALBEDO: DielectricAlbedoTable;
    /// The family's per-order energies of the F = 1 walk.
    const ORDERS: ScatteringOrderTable;
    /// The family's higher-order dielectric tables of the walk.
    const DIELECTRIC_WALK: DielectricWalkTable;

    /// The isotropic roughness the tables are read at: √(αx αy), the geometric mean of the
    /// principal radii (for an [`Elliptical`](crate::Elliptical) slope √(α₁ α₂), which is
    /// invariant under its rotation).
    #[inline]
    fn albedo_alpha(&self) -> f32 {
        (self.alpha_x() * self.alpha_y()).sqrt()
    }
}

impl AlbedoTabulated for Ggx {
    const ALBEDO: AlbedoTable = AlbedoTable::GGX;
    const DIELECTRIC_ALBEDO: DielectricAlbedoTable = DielectricAlbedoTable::GGX;
    const ORDERS: ScatteringOrderTable = ScatteringOrderTable::GGX;
    const DIELECTRIC_WALK: DielectricWalkTable = DielectricWalkTable::GGX;
}

impl AlbedoTabulated for Beckmann {
    const ALBEDO: AlbedoTable = AlbedoTable::BECKMANN;
    const DIELECTRIC_ALBEDO: DielectricAlbedoTable = DielectricAlbedoTable::BECKMANN;
    const ORDERS: ScatteringOrderTable = ScatteringOrderTable::BECKMANN;
    const DIELECTRIC_WALK: DielectricWalkTable = DielectricWalkTable::BECKMANN;
}

impl<S: AxisAlignedSlope + AlbedoTabulated> AlbedoTabulated for Elliptical<S> {
    const ALBEDO: AlbedoTable = S::ALBEDO;
    const DIELECTRIC_ALBEDO: DielectricAlbedoTable = S::DIELECTRIC_ALBEDO;
    const ORDERS: ScatteringOrderTable = S::ORDERS;
    const DIELECTRIC_WALK: DielectricWalkTable = S::DIELECTRIC_WALK;

    /// √(α₁ α₂): the compensated lobe of the rotated ellipse is that of the axis-aligned one.
    #[inline]
    fn albedo_alpha(&self) -> f32 {
        self.axis_aligned().albedo_alpha()
    }
}
