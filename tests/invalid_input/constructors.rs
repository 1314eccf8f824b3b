//! Every constructor rejects NaN, ±∞ and out-of-range values with
//! `Error::InvalidParameter { name, value, expected }` naming the offending parameter; the
//! error's Display names it too, and `Error` is a `std::error::Error`; the reported value is
//! the rejected one bit for bit (−0 included), and legal values around the limits are accepted.
use glam::{Vec2, Vec3};
use microsurface::{
    Beckmann, Bsdf, ClassicBrdf, ClassicMasking, ClassicNdf, Compensated, Compensation, ComplexIor,
    Conductor, Dielectric, Diffuse, Ggx, MicrofacetBsdf,
};
use validation::check::assert_rejects;

const NON_FINITE: [f32; 3] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];

#[test]
fn roughness_constructors() {
    for bad in NON_FINITE.into_iter().chain([0.0, -0.0, -1.0, -f32::MIN_POSITIVE]) {
        assert_rejects(Ggx::new(bad, 0.5), "alpha_x", bad);
        assert_rejects(Ggx::new(0.5, bad), "alpha_y", bad);
        assert_rejects(Beckmann::new(bad, 0.5), "alpha_x", bad);
        assert_rejects(Beckmann::new(0.5, bad), "alpha_y", bad);
        assert_rejects(Ggx::isotropic(bad), "alpha_x", bad);
        assert_rejects(Beckmann::isotropic(bad), "alpha_x", bad);
    }
    for good in [1e-4, 0.5, 4.0, f32::MIN_POSITIVE, 1e4] {
        assert!(Ggx::new(good, good).is_ok() && Beckmann::new(good, good).is_ok(), "α = {good}");
    }
}

#[test]
fn dielectric() {
    for bad in NON_FINITE.into_iter().chain([0.0, -1.5]) {
        assert_rejects(Dielectric::new(bad), "eta", bad);
    }
    for good in [0.25, 1.0, 1.0 + 1e-6, 4.0] {
        assert!(Dielectric::new(good).is_ok(), "η = {good}");
    }
}

#[test]
fn diffuse() {
    for bad in NON_FINITE.into_iter().chain([-0.1, 1.0 + f32::EPSILON, 2.0]) {
        for ch in 0..3 {
            let mut a = Vec3::splat(0.5);
            a[ch] = bad;
            assert_rejects(Diffuse::new(a), "albedo", bad);
        }
    }
    assert!(Diffuse::new(Vec3::ZERO).is_ok() && Diffuse::new(Vec3::ONE).is_ok());
}

#[test]
fn complex_ior() {
    for bad in NON_FINITE.into_iter().chain([0.0, -1.0]) {
        for ch in 0..3 {
            let mut e = Vec3::ONE;
            e[ch] = bad;
            assert_rejects(ComplexIor::new(e, Vec3::ONE), "eta", bad);
        }
    }
    for bad in NON_FINITE.into_iter().chain([-1e-3]) {
        for ch in 0..3 {
            let mut k = Vec3::ONE;
            k[ch] = bad;
            assert_rejects(ComplexIor::new(Vec3::ONE, k), "k", bad);
        }
    }
    assert!(ComplexIor::new(Vec3::ONE, Vec3::ZERO).is_ok());
}

#[test]
fn classic_brdf() {
    let ndf = ClassicNdf::Ggx(0.3);
    let m = ClassicMasking::Exact;
    for bad in NON_FINITE.into_iter().chain([-0.1, 1.5]) {
        for ch in 0..3 {
            let mut c = Vec3::splat(0.5);
            c[ch] = bad;
            assert_rejects(ClassicBrdf::new(c, Vec3::splat(0.5), ndf, m), "kd", bad);
            assert_rejects(ClassicBrdf::new(Vec3::splat(0.5), c, ndf, m), "ks", bad);
        }
    }
    for bad in NON_FINITE.into_iter().chain([0.0, -1.0]) {
        assert_rejects(ClassicBrdf::new(Vec3::ONE, Vec3::ONE, ClassicNdf::Ggx(bad), m), "alpha", bad);
        assert_rejects(ClassicBrdf::new(Vec3::ONE, Vec3::ONE, ClassicNdf::Beckmann(bad), m), "alpha", bad);
    }
    for bad in NON_FINITE.into_iter().chain([-1.0]) {
        assert_rejects(
            ClassicBrdf::new(Vec3::ONE, Vec3::ONE, ClassicNdf::Phong(bad), m),
            "phong_exponent",
            bad,
        );
    }
    assert_rejects(ClassicBrdf::new(Vec3::ZERO, Vec3::ZERO, ndf, m), "kd + ks", 0.0);
    assert!(ClassicBrdf::new(Vec3::ONE, Vec3::ZERO, ClassicNdf::Phong(0.0), m).is_ok());
}

#[test]
fn error_trait_and_display() {
    fn takes_std_error(_: &dyn std::error::Error) {}
    let err = Ggx::new(f32::NAN, 1.0).unwrap_err();
    takes_std_error(&err);
    let boxed: Box<dyn std::error::Error + Send + Sync> = Box::new(err);
    assert!(boxed.to_string().contains("alpha_x"));
    assert!(boxed.source().is_none());
    let shown = Dielectric::new(-2.0).unwrap_err().to_string();
    assert!(shown.contains("eta") && shown.contains("-2"), "{shown}");
}

const BAD_POSITIVE: [f32; 7] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -0.0, -1.0, -1e-30];

#[test]
fn roughness_must_be_finite_and_positive() {
    for v in BAD_POSITIVE {
        assert_rejects(Ggx::new(v, 0.5), "alpha_x", v);
        assert_rejects(Ggx::new(0.5, v), "alpha_y", v);
        assert_rejects(Ggx::isotropic(v), "alpha_x", v);
        assert_rejects(Beckmann::new(v, 0.5), "alpha_x", v);
        assert_rejects(Beckmann::new(0.5, v), "alpha_y", v);
        assert_rejects(Beckmann::isotropic(v), "alpha_x", v);
    }
    for v in [1e-4, 0.5, 1.0, 2.0, 10.0] {
        assert!(Ggx::new(v, v).is_ok() && Beckmann::new(v, v).is_ok(), "α = {v} must be accepted");
    }
}

#[test]
fn ior_and_albedo_must_be_in_range() {
    for v in BAD_POSITIVE {
        assert_rejects(Dielectric::new(v), "eta", v);
        assert_rejects(ComplexIor::new(Vec3::new(1.0, v, 1.0), Vec3::ONE), "eta", v);
    }
    for v in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, -1e-30] {
        assert_rejects(ComplexIor::new(Vec3::ONE, Vec3::new(1.0, 1.0, v)), "k", v);
    }
    for v in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1e-7, 1.000_001, 2.0, -1.0] {
        assert_rejects(Diffuse::new(Vec3::new(0.5, v, 0.5)), "albedo", v);
    }
    assert!(Diffuse::new(Vec3::new(0.0, 1.0, 0.5)).is_ok());
    assert!(ComplexIor::new(Vec3::ONE, Vec3::ZERO).is_ok());
    // beyond ComplexIor::MAX the Fresnel term's constants would overflow f32 (η² k² at 1e10)
    for v in [1.000_001e6, 1e10, 1e20, f32::MAX] {
        assert_rejects(ComplexIor::new(Vec3::new(1.0, v, 1.0), Vec3::ONE), "eta", v);
        assert_rejects(ComplexIor::new(Vec3::ONE, Vec3::new(v, 1.0, 1.0)), "k", v);
    }
    let max = Vec3::splat(ComplexIor::MAX);
    for ior in [ComplexIor::new(max, max), ComplexIor::new(max, Vec3::ZERO), ComplexIor::new(Vec3::ONE, max)]
    {
        let ior = ior.expect("at the largest accepted index");
        let (slope, conductor) = (Ggx::isotropic(0.5).unwrap(), Conductor::new(ior));
        let single = MicrofacetBsdf::new(slope, conductor).unwrap();
        let compensated = [Compensation::Walk, Compensation::KullaConty, Compensation::Turquin]
            .map(|scheme| Compensated::with_scheme(slope, conductor, scheme).unwrap());
        let bsdfs = std::iter::once(&single as &dyn Bsdf).chain(compensated.iter().map(|c| c as &dyn Bsdf));
        let (wo, wi) = (Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.6, 0.0, 0.8));
        for (n, bsdf) in bsdfs.enumerate() {
            let f = bsdf.eval(wo, wi).f;
            assert!(f.is_finite() && f.min_element() > 0.0, "type {n}, {ior:?}: f = {f}");
            let s = bsdf.sample(wo, 0.5, Vec2::splat(0.3)).expect("a mirror-like lobe samples");
            assert!(s.weight.is_finite() && s.weight.min_element() > 0.0, "type {n}, {ior:?}: {s:?}");
        }
    }
    assert!(Dielectric::new(1.0).is_ok() && Dielectric::new(1e-3).is_ok() && Dielectric::new(1e3).is_ok());
}
