//! Data-driven microfacet models (Dupuy 2015): the tabulated isotropic slope distribution
//! (`tabulated`), the anisotropic slope grid (`grid`), the extraction by power iteration
//! (`extraction`) and the MERL file format (`merl`).

mod extraction;
mod fuzz;
mod grid;
mod merl;
mod tabulated;
mod tail;
