//! Energy compensation: the single-scattering lobe plus the energy of the higher orders restored
//! from tabulated albedos of the exact model (Kulla and Conty 2017; Turquin 2019), with
//! deterministic evaluation, exact densities and samplers; and the tables themselves.

mod conductor;
mod kulla_conty_dielectric;
mod lobe_profile;
mod shared;
mod turquin_dielectric;

pub use crate::albedo::{
    ALBEDO_TABLE_SIZE, AlbedoTable, DIELECTRIC_TABLE_SIZE, DielectricAlbedo, DielectricAlbedoTable,
    DielectricWalkTable, EtaRange, HigherOrders, LAST_TABULATED_ORDER, MAX_TABULATED_ALPHA,
    MAX_TABULATED_ETA, MAX_WALK_TABLE_SE, ORDER_TABLE_MAX_STANDARD_ERROR, ORDER_TABLES, ScatteringOrderTable,
    TabulatedOrder, WALK_BATCH,
};
pub use conductor::{AlbedoTabulated, CompensatedConductor, Compensation};
pub use kulla_conty_dielectric::{KullaContyDielectric, WalkTabulated};
pub use turquin_dielectric::CompensatedDielectric;
