//! Energy compensation: the single-scattering lobe plus the energy of the higher orders restored
//! from tabulated albedos of the exact model (Kulla and Conty 2017; Turquin 2019; the random
//! walk's own higher orders), with deterministic evaluation, exact densities and samplers,
//! built per hit from tables shared by every instance; and the tables themselves.

mod albedo_tabulated;
mod batch;
mod compensated;
mod conductor;
mod conductor_tables;
mod dielectric;
mod fresnel_average;
mod glass_tables;
mod lobe_profile;
mod shared;

pub use crate::albedo::{
    ALBEDO_DIRECTIONS, ALBEDO_ROUGHNESSES, AlbedoTable, DIELECTRIC_TABLE_SIZE, DielectricAlbedo,
    DielectricAlbedoTable, DielectricLossTable, DielectricWalkTable, EtaRange, HigherOrders,
    LAST_TABULATED_ORDER, LOSS_TABLE_SHAPE, MAX_TABULATED_ALPHA, MAX_TABULATED_ETA, MAX_WALK_TABLE_SE,
    ORDER_TABLE_MAX_STANDARD_ERROR, ORDER_TABLE_SIZE, ORDER_TABLES, ScatteringOrderTable, TabulatedOrder,
    WALK_BATCH,
};
pub use albedo_tabulated::AlbedoTabulated;
pub use compensated::{Compensated, CompensatedMaterial, Compensation};
