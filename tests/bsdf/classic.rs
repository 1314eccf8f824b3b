//! `ClassicBrdf` specifics.

use super::fixtures::*;

/// The documented accuracy of the rational masking: relative error below 0.5 % against the
/// exact Smith G1, for Beckmann and Phong.
#[test]
fn classic_rational_masking_is_within_half_a_percent() {
    let (kd, ks) = (Vec3::splat(0.2), Vec3::splat(0.5));
    let mut worst = 0.0f32;
    for ndf in [
        ClassicNdf::Beckmann(0.1),
        ClassicNdf::Beckmann(0.5),
        ClassicNdf::Beckmann(1.2),
        ClassicNdf::Phong(5.0),
        ClassicNdf::Phong(80.0),
    ] {
        let exact = ClassicBrdf::new(kd, ks, ndf, ClassicMasking::Exact).unwrap();
        let rational = ClassicBrdf::new(kd, ks, ndf, ClassicMasking::Rational).unwrap();
        for i in 1..2000 {
            let v = dir(f64::from(i) / 2000.0 * std::f64::consts::FRAC_PI_2, 0.4);
            let (e, r) = (exact.g1(v), rational.g1(v));
            assert!(e > 0.0 && e <= 1.0, "{ndf:?}: G1({v}) = {e}");
            worst = worst.max((r / e - 1.0).abs());
            assert!((r / e - 1.0).abs() <= 5e-3, "{ndf:?}: rational G1 {r} vs exact {e} at {v}");
        }
    }
    println!("rational masking: worst relative error {worst:.4}");
}

#[test]
fn classic_rejects_invalid_parameters() {
    let ok = (Vec3::splat(0.5), Vec3::splat(0.5));
    let m = ClassicMasking::Exact;
    assert!(ClassicBrdf::new(ok.0, ok.1, ClassicNdf::Ggx(0.3), m).is_ok());
    assert!(ClassicBrdf::new(Vec3::new(1.1, 0.0, 0.0), ok.1, ClassicNdf::Ggx(0.3), m).is_err());
    assert!(ClassicBrdf::new(ok.0, Vec3::new(0.0, f32::NAN, 0.0), ClassicNdf::Ggx(0.3), m).is_err());
    assert!(ClassicBrdf::new(ok.0, Vec3::new(0.0, -0.1, 0.0), ClassicNdf::Ggx(0.3), m).is_err());
    assert!(ClassicBrdf::new(Vec3::ZERO, Vec3::ZERO, ClassicNdf::Ggx(0.3), m).is_err());
    assert!(ClassicBrdf::new(ok.0, ok.1, ClassicNdf::Phong(-1.0), m).is_err());
    assert!(ClassicBrdf::new(ok.0, ok.1, ClassicNdf::Phong(f32::INFINITY), m).is_err());
    assert!(ClassicBrdf::new(ok.0, ok.1, ClassicNdf::Beckmann(0.0), m).is_err());
    assert!(ClassicBrdf::new(ok.0, ok.1, ClassicNdf::Ggx(f32::NAN), m).is_err());
}

#[test]
fn classic_is_reciprocal() {
    let mut rng = validation::rng(7000);
    for ndf in [ClassicNdf::Phong(30.0), ClassicNdf::Beckmann(0.3), ClassicNdf::Ggx(0.3)] {
        let b = ClassicBrdf::new(
            Vec3::new(0.3, 0.4, 0.5),
            Vec3::new(0.6, 0.5, 0.4),
            ndf,
            ClassicMasking::Rational,
        )
        .unwrap();
        for _ in 0..5000 {
            let (wo, wi) = (uniform_sphere(&mut rng), uniform_sphere(&mut rng));
            let (a, c) = (b.eval_rng(wo, wi, &mut rng).f, b.eval_rng(wi, wo, &mut rng).f);
            assert!(rel_close(a, c, 1e-5), "{ndf:?}: f({wo}, {wi}) = {a} ≠ {c}");
            assert!(a.is_finite() && a.min_element() >= 0.0);
        }
    }
}
