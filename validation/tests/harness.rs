//! The chi-square harness rejects a wrong sampler and accepts a right one (it can fail).
use glam::Vec3;
use validation::chi2::{Chi2Grid, chi2_test};

#[test]
fn harness_accepts_cosine_and_rejects_uniform() {
    let mut rng = validation::rng(11);
    let cosine = |w: Vec3| (w.z.max(0.0) as f64) / std::f64::consts::PI;
    let out = chi2_test(
        "cosine",
        Chi2Grid::sphere(10, 20),
        cosine,
        || {
            Some(microsurface::research::sample_cosine_hemisphere(
                validation::uniform32(&mut rng),
                validation::uniform32(&mut rng),
            ))
        },
        200_000,
        1e-3,
        1.0,
    );
    assert!(out.dof > 50);
    let mut rng = validation::rng(12);
    let wrong = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        chi2_test(
            "uniform hemisphere against cosine",
            Chi2Grid::sphere(10, 20),
            cosine,
            || {
                let z = validation::uniform32(&mut rng);
                let phi = std::f32::consts::TAU * validation::uniform32(&mut rng);
                let s = (1.0 - z * z).sqrt();
                Some(Vec3::new(s * phi.cos(), s * phi.sin(), z))
            },
            200_000,
            1e-3,
            1.0,
        )
    }));
    assert!(wrong.is_err(), "the harness must reject a wrong sampler");
}
