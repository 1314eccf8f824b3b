//! Assertions and helpers shared by the deterministic tests: rejected parameters, caught
//! panics, f32 spacings, finite answers at a BSDF's edges, relative comparisons of values, a
//! sample from fresh uniforms.

use crate::{TestRng, uniform_sphere, uniform32};
use glam::{Vec2, Vec3};
use microsurface::{Bsdf, BsdfSample, Error};

/// The largest f32 below 1: the top uniform a renderer's sampler can hand over.
pub const ONE_MINUS: f32 = 1.0 - f32::EPSILON / 2.0;

/// The view cosines of [`assert_finite_at_edges`]: near, on and just below the horizon, and ±0.5.
pub const EDGE_VIEW_COSINES: [f32; 8] = [1e-7, 1e-4, 0.01, 0.0, -1e-7, -1e-4, 0.5, -0.5];

/// The unit view of cosine `z` in the xz plane.
#[must_use]
pub fn edge_view(z: f32) -> Vec3 {
    Vec3::new((1.0 - z * z).sqrt(), 0.0, z)
}

/// No NaN or infinity at a BSDF's edges: for every view of [`EDGE_VIEW_COSINES`], `sample`
/// at the extreme uniforms (0 and [`ONE_MINUS`]) and at an interior pair returns a finite
/// weight with a positive finite pdf and a finite `eval_with_pdf` at its direction, and
/// `eval_with_pdf` is finite at every direction of `wis`. `label` names the BSDF on failure.
#[track_caller]
pub fn assert_finite_at_edges(b: &dyn Bsdf, wis: &[Vec3], label: &str) {
    for z in EDGE_VIEW_COSINES {
        let wo = edge_view(z);
        for (uc, u) in [(0.0, Vec2::ZERO), (ONE_MINUS, Vec2::splat(ONE_MINUS)), (0.5, Vec2::new(0.3, 0.9))] {
            if let Some(s) = b.sample(wo, uc, u) {
                assert!(s.weight.is_finite() && s.pdf.is_finite() && s.pdf > 0.0, "{label} wo = {wo}: {s:?}");
                let (v, pdf) = b.eval_with_pdf(wo, s.wi);
                assert!(v.f.is_finite() && pdf.is_finite(), "{label} wo = {wo} wi = {}", s.wi);
            }
        }
        for &wi in wis {
            let (v, pdf) = b.eval_with_pdf(wo, wi);
            assert!(v.f.is_finite() && pdf.is_finite(), "{label} wo = {wo} wi = {wi}");
        }
    }
}

/// No NaN or infinity from `eval`, `pdf`, `eval_with_pdf` or `sample` at `n` pairs of
/// directions uniform on the sphere (both sides of the surface) and fresh uniforms: the
/// scan for the tables' rows and cells where a lobe's construction could go non-finite.
/// `label` names the BSDF on failure.
#[track_caller]
pub fn assert_finite_on_sphere(b: &dyn Bsdf, n: usize, rng: &mut TestRng, label: &str) {
    for _ in 0..n {
        let (wo, wi) = (uniform_sphere(rng), uniform_sphere(rng));
        let (f, pdf) = (b.eval(wo, wi).f, b.pdf(wo, wi));
        let (v, q) = b.eval_with_pdf(wo, wi);
        assert!(
            f.is_finite() && pdf.is_finite() && v.f.is_finite() && q.is_finite(),
            "{label} wo = {wo} wi = {wi}: f = {f}, pdf = {pdf}, eval_with_pdf = ({}, {q})",
            v.f
        );
        if let Some(s) = draw(b, wo, rng) {
            assert!(
                s.weight.is_finite() && s.pdf.is_finite() && s.pdf > 0.0 && s.wi.is_finite(),
                "{label} wo = {wo}: {s:?}"
            );
        }
    }
}

/// Asserts that `result` is `Error::InvalidParameter` for `name` with the rejected `value`
/// (the same bits, or both NaN), a non-empty `expected`, and a Display that names `name`.
#[track_caller]
pub fn assert_rejects<T: std::fmt::Debug>(result: Result<T, Error>, name: &str, value: f32) {
    let err = match result {
        Ok(x) => panic!("`{name}` = {value} was accepted: {x:?}"),
        Err(err) => err,
    };
    match &err {
        Error::InvalidParameter { name: n, value: v, expected } => {
            assert_eq!(*n, name, "wrong parameter named for {name} = {value}");
            assert!(
                v.to_bits() == value.to_bits() || (v.is_nan() && value.is_nan()),
                "{name}: reported value {v}, passed {value}"
            );
            assert!(!expected.is_empty(), "{name}: empty `expected`");
        }
        #[allow(unreachable_patterns)]
        other => panic!("`{name}` = {value}: unexpected error {other:?}"),
    }
    let shown = err.to_string();
    assert!(shown.contains(name), "Display `{shown}` does not name `{name}`");
}

/// A sample of `b` for the view `wo` from three fresh uniforms of `rng` (uc, then u).
pub fn draw<B: Bsdf + ?Sized>(b: &B, wo: Vec3, rng: &mut TestRng) -> Option<BsdfSample> {
    let uc = uniform32(rng);
    let u = Vec2::new(uniform32(rng), uniform32(rng));
    b.sample(wo, uc, u)
}

/// Asserts that the flags of a non-specular sample with an exact density name the side it
/// leaves on for the view `wo` (transmission exactly when `wi` crosses the plane), and returns
/// whether it crossed.
#[track_caller]
pub fn assert_side_flags(label: &str, wo: Vec3, s: &BsdfSample) -> bool {
    let crossed = (s.wi.z > 0.0) != (wo.z > 0.0);
    assert!(
        s.flags.exact_pdf && s.flags.transmission == crossed && s.flags.reflection != crossed,
        "{label}: flags {:?}",
        s.flags
    );
    crossed
}

/// |a − b| ≤ rel·max(|a|, |b|) componentwise against the largest component: the relative
/// comparison of two BSDF values or weights.
#[must_use]
pub fn rel_close(a: Vec3, b: Vec3, rel: f32) -> bool {
    let scale = a.abs().max(b.abs()).max_element();
    (a - b).abs().max_element() <= rel * scale
}

/// The message of a caught panic (`String` or `&str` payloads).
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else {
        "(non-string panic)".to_string()
    }
}

/// The spacing of the f32 numbers at |v| (2⁻¹⁴⁹ in and below the subnormal range): for an
/// f32 value v, `v.next_up() − v`.
pub fn ulp32(v: f64) -> f64 {
    let v = v.abs();
    let e = if v == 0.0 { -1023 } else { ((v.to_bits() >> 52) & 0x7ff) as i32 - 1023 };
    2f64.powi(e.max(-126) - 23)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ulp32_is_the_f32_spacing() {
        for v in [0.0f32, f32::from_bits(1), 1e-40, f32::MIN_POSITIVE, 0.1, 0.5, 1.0, 3.0, 1e30] {
            let expected = if v == 0.0 { f64::from(f32::from_bits(1)) } else { f64::from(v.next_up() - v) };
            assert_eq!(ulp32(f64::from(v)), expected, "v = {v:e}");
        }
    }

    #[test]
    fn panic_message_reads_both_payloads() {
        let owned = std::panic::catch_unwind(|| panic!("{}", 42)).unwrap_err();
        let borrowed = std::panic::catch_unwind(|| panic!("static")).unwrap_err();
        assert_eq!(panic_message(owned.as_ref()), "42");
        assert_eq!(panic_message(borrowed.as_ref()), "static");
    }
}
