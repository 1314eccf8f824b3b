//! Complex indices of refraction of common metals, per RGB channel.

use super::ComplexIor;
use glam::Vec3;

// RGB values (η, k) of the LabPBR material standard's table of hard-coded metals, compiled by
// C. Hindefjord ("RGB IOR for metals") from the measured spectral data on refractiveindex.info
// (Rakić 1998 for aluminium; Johnson and Christy 1972 for copper, gold and silver).

impl ComplexIor {
    /// Copper: η = (0.27105, 0.67693, 1.31640), k = (3.60920, 2.62480, 2.29210).
    pub const COPPER: ComplexIor =
        ComplexIor::from_parts(Vec3::new(0.27105, 0.67693, 1.31640), Vec3::new(3.60920, 2.62480, 2.29210));
    /// Gold: η = (0.18299, 0.42108, 1.37340), k = (3.42420, 2.34590, 1.77040).
    pub const GOLD: ComplexIor =
        ComplexIor::from_parts(Vec3::new(0.18299, 0.42108, 1.37340), Vec3::new(3.42420, 2.34590, 1.77040));
    /// Aluminium: η = (1.34560, 0.96521, 0.61722), k = (7.47460, 6.39950, 5.30310).
    pub const ALUMINIUM: ComplexIor =
        ComplexIor::from_parts(Vec3::new(1.34560, 0.96521, 0.61722), Vec3::new(7.47460, 6.39950, 5.30310));
    /// Silver: η = (0.15943, 0.14512, 0.13547), k = (3.92910, 3.19000, 2.38080).
    pub const SILVER: ComplexIor =
        ComplexIor::from_parts(Vec3::new(0.15943, 0.14512, 0.13547), Vec3::new(3.92910, 3.19000, 2.38080));
}
