//! The shipped table nodes, written by the table generator (`tools/tables`) and reproduced by it
//! bit for bit; not edited by hand and not formatted (kept as the generator writes them).

#[rustfmt::skip]
pub(crate) mod conductor;
#[rustfmt::skip]
pub(crate) mod dielectric;
#[rustfmt::skip]
pub(crate) mod dielectric_loss;
#[rustfmt::skip]
pub(crate) mod dielectric_walk;
#[rustfmt::skip]
pub(crate) mod orders;
