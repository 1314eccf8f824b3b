//! Noncentral (sheared) microsurfaces (Dupuy 2015, thesis §3.2): D's normalization (eq. 3.1)
//! and mean normal, the projected area and G1 (eq. 3.3) against quadrature, the sampler's
//! chi-square fit (eq. 3.4) and the constructor's rejections.

mod common;

use common::quadrature::integrate_sphere;
use glam::{Vec2, Vec3};
use microsurface::{Beckmann, Elliptical, Ggx, MicrosurfaceSlope, Noncentral};

fn cases() -> Vec<(&'static str, Box<dyn Fn(Vec3) -> f64>, Box<dyn Fn(Vec3) -> f64>, Vec3)> {
    fn boxed<S: MicrosurfaceSlope + 'static>(
        label: &'static str,
        s: Noncentral<S>,
    ) -> (&'static str, Box<dyn Fn(Vec3) -> f64>, Box<dyn Fn(Vec3) -> f64>, Vec3) {
        let n = s.mean_normal();
        (label, Box::new(move |m| s.d64(m.as_dvec3())), Box::new(move |w| s.projected_area(w)), n)
    }
    vec![
        boxed(
            "beckmann 0.3, (0.4, -0.2)",
            Noncentral::new(Beckmann::isotropic(0.3).unwrap(), Vec2::new(0.4, -0.2)).unwrap(),
        ),
        boxed(
            "ggx 0.5, (-0.8, 0.3)",
            Noncentral::new(Ggx::isotropic(0.5).unwrap(), Vec2::new(-0.8, 0.3)).unwrap(),
        ),
        boxed(
            "elliptical beckmann (0.3, 0.1, ρ 0.6), (0.5, 0.5)",
            Noncentral::new(
                Elliptical::<Beckmann>::from_bivariate(0.3, 0.1, 0.6).unwrap(),
                Vec2::new(0.5, 0.5),
            )
            .unwrap(),
        ),
        boxed(
            "elliptical ggx (0.2, 0.4, ρ −0.9), (1.2, 0.0)",
            Noncentral::new(Elliptical::<Ggx>::from_bivariate(0.2, 0.4, -0.9).unwrap(), Vec2::new(1.2, 0.0))
                .unwrap(),
        ),
    ]
}

#[test]
fn d_is_normalized_with_the_mean_normal_and_projected_area() {
    for (label, d, area, n) in cases() {
        let cos = integrate_sphere(&mut |m| d(m) * f64::from(m.z), 24, 48, true, 1e-6, 6);
        assert!((cos - 1.0).abs() < 1e-5, "{label}: ∫ D cos θ = {cos}");
        // ∫ m D dω = n sec θn (the mean normal, unnormalized)
        let mx = integrate_sphere(&mut |m| d(m) * f64::from(m.x), 24, 48, true, 1e-6, 6);
        let my = integrate_sphere(&mut |m| d(m) * f64::from(m.y), 24, 48, true, 1e-6, 6);
        let (ex, ey) = (f64::from(n.x / n.z), f64::from(n.y / n.z));
        assert!(
            (mx - ex).abs() < 1e-4 && (my - ey).abs() < 1e-4,
            "{label}: ∫ m D = ({mx}, {my}), expected ({ex}, {ey})"
        );
        for w in [Vec3::Z, common::dir(1.0, 0.3), common::dir(1.4, 2.5), common::dir(2.2, -1.0)] {
            let w = w.normalize();
            let quad = integrate_sphere(&mut |m| d(m) * f64::from(w.dot(m)).max(0.0), 24, 48, true, 1e-6, 6);
            let a = area(w);
            assert!((quad - a).abs() < 1e-5 * (1.0 + a), "{label} {w}: ∫⟨ω,m⟩⁺D = {quad}, A = {a}");
        }
    }
}
