//! The special functions (`microsurface::special`): their maximum errors against statrs and
//! mpmath over their whole domains (`functions`), and the accuracy map of every f32 function
//! of the crate against the f64 reference model `validation::reference` (`accuracy_map`).

mod accuracy_map;
mod functions;
