//! The random walk of Heitz et al. 2016 (`Microsurface`): supplement §4.4, tests 4.4.1–4.4.4
//! (`random_walk`), the bounce cap (`cap`), stiff walks (`stiff`) and views below the
//! macrosurface, with the position-free estimators beside it (`backfacing_views`).

mod backfacing_views;
mod cap;
mod lanes;
mod random_walk;
mod stiff;
