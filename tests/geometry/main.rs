//! The geometry of the microsurface (Heitz et al. 2016, supplement §4.1): the height
//! distributions (`heights`) and the intersections with the microsurface, tests 4.1.1–4.1.5
//! (`masking`).

mod heights;
mod masking;
