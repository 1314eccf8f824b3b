//! The renderer layer's inputs at their boundaries, for every type implementing `Bsdf`:
//! directions within `BSDF_DIRECTION_TOLERANCE` (|‖ω‖ − 1| ≤ 1e-2) of unit length are
//! renormalized and answered (the value of the renormalized direction, bit for bit, for the
//! types that renormalize on entry; the compensated lobes' added terms read their tables at
//! the caller's cosines, within 2 % of it); a uniform of exactly 1 is taken as 1 − 2⁻²⁴; just
//! beyond either boundary, and for NaN, infinite or zero input, the documented nothing, with a
//! debug assertion naming the argument and its value (checked in both build modes, see
//! `policy`).

use super::policy::{Report, quiet_violations};
use glam::{Vec2, Vec3};
use microsurface::leadr::{Noncentral, NoncentralBsdf};
use microsurface::research::{Estimator, Shadowing};
use microsurface::{
    BSDF_DIRECTION_TOLERANCE, Bsdf, BsdfSample, BsdfValue, ClassicBrdf, ClassicMasking, ClassicNdf,
    Compensated, Compensation, ComplexIor, Conductor, Dielectric, Diffuse, Ggx, MicrofacetBsdf, Technique,
};

/// 1 − 2⁻²⁴, what a uniform of 1 stands for.
const ONE_MINUS: f32 = 1.0 - f32::EPSILON / 2.0;

/// Every renderer type, and whether it renormalizes on entry (its answer for a drifted
/// direction is exactly that for the renormalized one).
fn models() -> Vec<(String, Box<dyn Bsdf>, bool)> {
    let ggx = Ggx::new(0.3, 0.2).unwrap();
    let gold = Conductor::new(ComplexIor::GOLD);
    let glass = Dielectric::new(1.5).unwrap();
    let diffuse = Diffuse::new(Vec3::new(0.8, 0.5, 0.3)).unwrap();
    let mut v: Vec<(String, Box<dyn Bsdf>, bool)> = Vec::new();
    for (t, technique) in [
        ("single", Technique::SingleScattering),
        ("walk", Technique::RandomWalk),
        ("pt", Technique::PositionFree { estimator: Estimator::Pt, shadowing: Shadowing::Correlated }),
        ("bdpt", Technique::PositionFree { estimator: Estimator::Bdpt, shadowing: Shadowing::Uncorrelated }),
    ] {
        v.push((
            format!("gold {t}"),
            Box::new(MicrofacetBsdf::new(ggx, gold).unwrap().with_technique(technique)),
            true,
        ));
        v.push((
            format!("glass {t}"),
            Box::new(MicrofacetBsdf::new(ggx, glass).unwrap().with_technique(technique)),
            true,
        ));
        v.push((
            format!("diffuse {t}"),
            Box::new(MicrofacetBsdf::new(ggx, diffuse).unwrap().with_technique(technique)),
            true,
        ));
    }
    let classic =
        ClassicBrdf::new(Vec3::splat(0.3), Vec3::splat(0.5), ClassicNdf::Ggx(0.3), ClassicMasking::Exact);
    v.push(("classic".into(), Box::new(classic.unwrap()), true));
    let noncentral = NoncentralBsdf::new(Noncentral::new(ggx, Vec2::new(0.2, -0.1)).unwrap(), gold).unwrap();
    v.push(("noncentral".into(), Box::new(noncentral), true));
    for scheme in [Compensation::KullaConty, Compensation::Turquin, Compensation::Walk] {
        v.push((
            format!("compensated gold {scheme:?}"),
            Box::new(Compensated::with_scheme(ggx, gold, scheme).unwrap()),
            false,
        ));
    }
    v.push((
        "Turquin glass".into(),
        Box::new(Compensated::with_scheme(ggx, glass, Compensation::Turquin).unwrap()),
        false,
    ));
    v.push((
        "Kulla-Conty glass".into(),
        Box::new(Compensated::with_scheme(ggx, glass, Compensation::Walk).unwrap()),
        false,
    ));
    v
}

fn dir(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
}

/// The crate's renormalization of a drifted direction.
fn renormalized(w: Vec3) -> Vec3 {
    w / w.length_squared().sqrt()
}

fn close(a: Vec3, b: Vec3, rel: f32) -> bool {
    (a - b).abs().max_element() <= rel * a.max_element().max(b.max_element())
}

/// Drifted lengths, inside the tolerance (answered) and just outside it (nothing).
#[test]
fn drifted_directions_are_renormalized_and_beyond_the_tolerance_rejected() {
    quiet_violations();
    assert_eq!(BSDF_DIRECTION_TOLERANCE, 1e-2);
    let mut r = Report::default();
    let (wo, wi) = (dir(0.6, 0.3), dir(0.5, 0.3 + core::f32::consts::PI));
    let (uc, u) = (0.3, Vec2::new(0.6, 0.2));
    // the f32 instance-transform drift, and both ends of the tolerance
    let inside = [1.0 + 6e-4, 1.0 - 6e-4, 1.0 + 0.99e-2, 1.0 - 0.99e-2];
    let outside = [1.0 + 1.01e-2, 1.0 - 1.01e-2, 2.0, 0.5, 0.0];
    for (label, b, exact) in models() {
        let key = 17;
        let f = b.eval_keyed(wo, wi, key).f;
        let pdf = b.pdf(wo, wi);
        let s = b.sample_keyed(wo, uc, u, key);
        assert!(
            f.max_element() > 0.0 && pdf > 0.0 && s.is_some(),
            "{label}: the unit directions have no value"
        );
        for k in inside {
            let (d_o, d_i) = (k * wo, k * wi);
            let l = format!("{label}: |ω| = {k}");
            if exact {
                let (r_o, r_i) = (renormalized(d_o), renormalized(d_i));
                let e = b.eval_keyed(r_o, r_i, key);
                r.expect_valid(
                    &format!("{l}: eval(wo)"),
                    || b.eval_keyed(d_o, r_i, key),
                    |v| *v == e && v.f.max_element() > 0.0,
                );
                r.expect_valid(&format!("{l}: eval(wi)"), || b.eval_keyed(r_o, d_i, key), |v| *v == e);
                let p = b.pdf(r_o, r_i);
                r.expect_valid(&format!("{l}: pdf"), || b.pdf(d_o, d_i), |x| *x == p && p > 0.0);
                let ep = b.eval_with_pdf_keyed(r_o, r_i, key);
                r.expect_valid(
                    &format!("{l}: eval_with_pdf"),
                    || b.eval_with_pdf_keyed(d_o, d_i, key),
                    |x| *x == ep,
                );
                let s = b.sample_keyed(r_o, uc, u, key);
                r.expect_valid(
                    &format!("{l}: sample"),
                    || b.sample_keyed(d_o, uc, u, key),
                    |x| *x == s && s.is_some(),
                );
            } else {
                // the added lobes read their tables at the caller's cosines (within 1e-2 of the
                // unit ones): within 2 % of the unit answer
                r.expect_valid(
                    &format!("{l}: eval"),
                    || b.eval_keyed(d_o, d_i, key),
                    |v: &BsdfValue| close(v.f, f, 2e-2),
                );
                r.expect_valid(&format!("{l}: pdf"), || b.pdf(d_o, d_i), |p| (p - pdf).abs() <= 2e-2 * pdf);
                r.expect_valid(
                    &format!("{l}: sample"),
                    || b.sample_keyed(d_o, uc, u, key),
                    |s: &Option<BsdfSample>| {
                        s.is_some_and(|s| {
                            s.weight.is_finite() && s.pdf > 0.0 && (s.wi.length() - 1.0).abs() < 1e-5
                        })
                    },
                );
            }
        }
        for k in outside {
            let (d_o, d_i) = (k * wo, k * wi);
            let l = format!("{label}: |ω| = {k}");
            let says =
                |name: &str| [format!("`{name}` = Vec3("), format!("is not a unit direction (|{name}| = ")];
            let (so, si) = (says("wo"), says("wi"));
            let (so, si) = ([so[0].as_str(), so[1].as_str()], [si[0].as_str(), si[1].as_str()]);
            let zero = |v: &BsdfValue| v.f == Vec3::ZERO;
            r.expect_nothing_saying(&format!("{l}: eval(wo)"), || b.eval_keyed(d_o, wi, key), zero, &so);
            r.expect_nothing_saying(&format!("{l}: eval(wi)"), || b.eval_keyed(wo, d_i, key), zero, &si);
            r.expect_nothing_saying(&format!("{l}: pdf(wo)"), || b.pdf(d_o, wi), |p| *p == 0.0, &so);
            r.expect_nothing_saying(&format!("{l}: pdf(wi)"), || b.pdf(wo, d_i), |p| *p == 0.0, &si);
            r.expect_nothing_saying(
                &format!("{l}: eval_with_pdf(wi)"),
                || b.eval_with_pdf_keyed(wo, d_i, key),
                |(v, p)| v.f == Vec3::ZERO && *p == 0.0,
                &si,
            );
            r.expect_nothing_saying(
                &format!("{l}: sample(wo)"),
                || b.sample_keyed(d_o, uc, u, key),
                Option::is_none,
                &so,
            );
        }
        for bad in [Vec3::NAN, Vec3::new(0.0, f32::INFINITY, 1.0), Vec3::ZERO] {
            let l = format!("{label}: wo = {bad}");
            let needle = format!("`wo` = {bad:?}");
            r.expect_nothing_saying(
                &l,
                || b.sample_keyed(bad, uc, u, key),
                Option::is_none,
                &[needle.as_str()],
            );
        }
    }
    r.finish("drifted_directions_are_renormalized_and_beyond_the_tolerance_rejected", 800);
}

/// A uniform of exactly 1 is the largest f32 below 1; −0 is 0; above 1, below 0, NaN and ∞
/// are rejected, naming the argument.
#[test]
fn uniforms_of_one_are_the_largest_below_one() {
    quiet_violations();
    let mut r = Report::default();
    let wo = dir(0.6, 0.3);
    for (label, b, exact) in models() {
        for wo in [wo, Vec3::new(-wo.x, wo.y, -wo.z)] {
            for (uc, u) in [
                (1.0f32, Vec2::new(0.5, 0.5)),
                (0.5, Vec2::new(1.0, 0.5)),
                (0.5, Vec2::new(0.5, 1.0)),
                (1.0, Vec2::ONE),
                (-0.0, Vec2::new(-0.0, 0.0)),
            ] {
                let l = format!("{label}: sample({wo}, {uc}, {u})");
                if exact {
                    let (uc1, u1) = (uc.min(ONE_MINUS), u.min(Vec2::splat(ONE_MINUS)));
                    let expected = b.sample_keyed(wo, uc1, u1, 5);
                    r.expect_valid(&l, || b.sample_keyed(wo, uc, u, 5), |s| *s == expected);
                } else {
                    r.expect_valid(
                        &l,
                        || b.sample_keyed(wo, uc, u, 5),
                        |s: &Option<BsdfSample>| {
                            s.is_none_or(|s| s.weight.is_finite() && s.pdf > 0.0 && s.wi.is_finite())
                        },
                    );
                }
            }
            let above = 1.0 + f32::EPSILON;
            for bad in [above, -1e-7, -1.0, f32::NAN, f32::INFINITY] {
                let needle = format!("`uc` = {bad:?} is not a uniform");
                let l = format!("{label}: sample(uc = {bad})");
                r.expect_nothing_saying(
                    &l,
                    || b.sample_keyed(wo, bad, Vec2::splat(0.5), 5),
                    Option::is_none,
                    &[needle.as_str()],
                );
                let u = Vec2::new(0.5, bad);
                let needle = format!("`u` = {u:?}");
                let l = format!("{label}: sample(u = {u})");
                r.expect_nothing_saying(
                    &l,
                    || b.sample_keyed(wo, 0.5, u, 5),
                    Option::is_none,
                    &[needle.as_str()],
                );
            }
        }
    }
    r.finish("uniforms_of_one_are_the_largest_below_one", 500);
}
