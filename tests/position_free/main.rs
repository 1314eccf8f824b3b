//! The position-free estimators of Wang et al. 2022 (`PositionFree`): energy, PT against
//! BDPT, orders, reciprocity, against the random walk (`estimators`), and `sample` against the
//! averaged evaluation (`sampling`).

mod estimators;
mod sampling;
