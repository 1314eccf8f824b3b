//! The distribution of visible normals (Heitz et al. 2016, supplement §4.2) and its samplers
//! (`microsurface::vndf`): normalization of D, D_ωi and the projected area, test 4.2.1
//! (`normalization`); importance sampling of `sample_d_wi`, test 4.2.2 (`sampling`); every
//! named sampler against its own density on the whole sphere (`samplers`); the extreme
//! uniforms (`tails`); the bounded cap's bound, its tails and its fuzz domain (`bounded`).

mod bounded;
mod normalization;
mod samplers;
mod sampling;
mod tails;
