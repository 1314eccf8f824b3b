//! Bad input: invalid directions give the documented nothing through every technique.

use super::densities::classic_models;
use super::fixtures::*;
use super::weights::{Visit, visit_all_slopes};

/// Invalid directions: zero, NaN, infinite, non-unit.
fn bad_directions() -> Vec<Vec3> {
    let w = dir(0.6, 0.3);
    vec![
        Vec3::ZERO,
        Vec3::splat(f32::NAN),
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, 0.0, f32::INFINITY),
        2.0 * w,
        0.5 * w,
        -3.0 * w,
    ]
}

/// Valid directions on the horizon: zero, without a debug assertion.
fn horizon_directions() -> [Vec3; 2] {
    [Vec3::X, Vec3::new(0.6, -0.8, 0.0)]
}

/// In debug builds `call` must trip the trait's debug assertion; in release builds it must
/// return "nothing" (`is_nothing`).
fn nothing_or_debug_panic<T>(label: &str, call: impl FnOnce() -> T, is_nothing: impl Fn(&T) -> bool) {
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(call));
    if cfg!(debug_assertions) {
        assert!(r.is_err(), "{label}: no debug assertion for an invalid argument");
    } else {
        let v = r.unwrap_or_else(|_| panic!("{label}: panicked in a release build"));
        assert!(is_nothing(&v), "{label}: returned something for an invalid argument");
    }
}

/// Zero f, zero pdf and no sample (release) or a debug assertion (debug) for invalid
/// directions and uniforms; zero without an assertion on the horizon; zero below the surface
/// for reflection-only models (`backfacing_view_valid`: the microfacet BSDFs accept
/// backfacing views, see the normal-mapping tests); finite, non-negative values for random
/// and grazing directions.
pub(super) fn check_bad_input<B: Bsdf>(
    label: &str,
    b: &B,
    reflection_only: bool,
    backfacing_view_valid: bool,
    seed: u64,
) {
    let mut rng = validation::rng(seed);
    let (good_o, good_i) = (dir(0.6, 0.3), dir(0.8, 2.0));
    let zero_f = |v: &BsdfValue| v.f == Vec3::ZERO;
    let zero_pdf = |p: &f32| *p == 0.0;
    for bad in bad_directions() {
        let key = rand::Rng::next_u64(&mut rng);
        nothing_or_debug_panic(
            &format!("{label}: eval(wo = {bad})"),
            || b.eval_keyed(bad, good_i, key),
            zero_f,
        );
        nothing_or_debug_panic(
            &format!("{label}: eval(wi = {bad})"),
            || b.eval_keyed(good_o, bad, key),
            zero_f,
        );
        let s = &format!("{label}: sample(wo = {bad})");
        nothing_or_debug_panic(s, || b.sample(bad, 0.3, Vec2::new(0.6, 0.2)), Option::is_none);
        nothing_or_debug_panic(&format!("{label}: pdf(wo = {bad})"), || b.pdf(bad, good_i), zero_pdf);
        nothing_or_debug_panic(&format!("{label}: pdf(wi = {bad})"), || b.pdf(good_o, bad), zero_pdf);
        let both = &format!("{label}: eval_with_pdf(wi = {bad})");
        nothing_or_debug_panic(both, || b.eval_with_pdf(good_o, bad), |(v, p)| zero_f(v) && *p == 0.0);
    }
    // (a uniform of exactly 1 is valid, taken as 1 − 2⁻²⁴: tests/invalid_input/renderer.rs)
    let above_one = 1.0 + f32::EPSILON;
    for (uc, u) in [
        (above_one, Vec2::new(0.5, 0.5)),
        (-0.1, Vec2::new(0.5, 0.5)),
        (0.5, Vec2::new(f32::NAN, 0.5)),
        (0.5, Vec2::new(0.5, above_one)),
        (f32::INFINITY, Vec2::ZERO),
    ] {
        let s = &format!("{label}: sample(uc = {uc}, u = {u})");
        nothing_or_debug_panic(s, || b.sample(good_o, uc, u), Option::is_none);
    }
    for h in horizon_directions() {
        assert_eq!(b.eval_rng(good_o, h, &mut rng).f, Vec3::ZERO, "{label}: eval(wi = {h})");
        assert!(b.sample_rng(h, &mut rng).is_none(), "{label}: sample(wo = {h})");
        assert_eq!(b.pdf(h, good_i), 0.0, "{label}: pdf(wo = {h})");
        assert_eq!(b.pdf(good_o, h), 0.0, "{label}: pdf(wi = {h})");
    }
    if reflection_only {
        for _ in 0..50 {
            let (below, above) =
                (-dir(0.3 + 1.2 * uniform64(&mut rng), 6.0 * uniform64(&mut rng)), dir(0.7, 1.0));
            assert_eq!(b.eval_rng(above, below, &mut rng).f, Vec3::ZERO, "{label}: wi below {below}");
            assert_eq!(b.pdf(above, below), 0.0, "{label}: pdf at wi below {below}");
            if !backfacing_view_valid {
                assert_eq!(b.eval_rng(below, above, &mut rng).f, Vec3::ZERO, "{label}: wo below {below}");
                assert_eq!(b.pdf(below, above), 0.0, "{label}: pdf for wo below {below}");
                assert!(b.sample_rng(below, &mut rng).is_none(), "{label}: sample for wo below {below}");
            }
        }
    }
    // random and nearly grazing directions: everything finite
    let grazing = [1e-7f32, -1e-7, 1e-4, -1e-4, 0.9999, -0.9999];
    for k in 0..200 {
        let mut wo = uniform_sphere(&mut rng);
        let mut wi = uniform_sphere(&mut rng);
        if k < 36 {
            let (zo, zi) = (grazing[k % 6], grazing[k / 6]);
            wo = Vec3::new((1.0 - zo * zo).sqrt(), 0.0, zo);
            wi = Vec3::new(-(1.0 - zi * zi).sqrt() * 0.6, (1.0 - zi * zi).sqrt() * 0.8, zi);
        }
        let f = b.eval_rng(wo, wi, &mut rng).f;
        assert!(f.is_finite() && f.min_element() >= 0.0, "{label}: eval({wo}, {wi}) = {f}");
        let p = b.pdf(wo, wi);
        assert!(p.is_finite() && p >= 0.0, "{label}: pdf({wo}, {wi}) = {p}");
        if let Some(s) = b.sample_rng(wo, &mut rng) {
            assert!(s.weight.is_finite() && s.weight.min_element() >= 0.0, "{label}: {s:?} for {wo}");
            assert!(s.pdf.is_finite() && s.pdf > 0.0 && s.wi.is_finite(), "{label}: {s:?} for {wo}");
        }
    }
}

struct BadInput(u64);

impl Visit for BadInput {
    fn visit<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
        &mut self,
        label: &str,
        b: &Mf<S, M>,
        _: bool,
        _: &[Vec3],
    ) {
        self.0 += 1;
        // every technique accepts backfacing views of opaque materials (tests/walk/backfacing_views.rs)
        check_bad_input(label, b, !M::TRANSMITS, true, self.0);
    }
}

#[test]
fn invalid_directions_give_zero() {
    let mut v = BadInput(6000);
    visit_all_slopes(&mut v, &ALL_TECHNIQUES);
    for ndf in [ClassicNdf::Phong(30.0), ClassicNdf::Beckmann(0.3), ClassicNdf::Ggx(0.3)] {
        for (label, b, _) in classic_models(ndf) {
            v.0 += 1;
            check_bad_input(&label, &b, true, false, v.0);
        }
    }
}
