//! `ShadingFrame`: orthonormal, round trips, rejects degenerate normals.

use super::fixtures::*;

#[test]
fn shading_frame_is_orthonormal_and_round_trips() {
    let mut rng = validation::rng(5000);
    let mut normals = vec![
        Vec3::Z,
        -Vec3::Z,
        Vec3::X,
        -Vec3::Y,
        Vec3::new(1e-8, 0.0, -1.0),
        Vec3::new(0.0, 1e-4, -1.0),
        Vec3::new(-1e-3, 1e-3, -1.0),
        Vec3::new(3e-4, -2e-4, -1.0),
        Vec3::new(1e-7, 1e-7, 1.0),
        Vec3::new(0.0, 0.0, -3.5),
        Vec3::new(2.0, -1.0, 0.0),
    ];
    for _ in 0..2000 {
        // random directions, random lengths
        normals.push(uniform_sphere(&mut rng) * (0.1 + 5.0 * uniform32(&mut rng)));
    }
    for n in normals {
        let f = ShadingFrame::from_normal(n).unwrap_or_else(|| panic!("no frame for {n}"));
        let nn = n.normalize();
        let (t, b, z) = (f.to_world(Vec3::X), f.to_world(Vec3::Y), f.to_world(Vec3::Z));
        assert!((f.normal() - nn).length() <= 1e-6, "{n}: normal {}", f.normal());
        assert!((z - nn).length() <= 1e-6, "{n}: to_world(z) = {z}");
        for (name, v) in [("t", t), ("b", b), ("n", z)] {
            assert!((v.length() - 1.0).abs() <= 1e-6, "{n}: |{name}| = {}", v.length());
        }
        assert!(
            t.dot(b).abs() <= 1e-6 && t.dot(z).abs() <= 1e-6 && b.dot(z).abs() <= 1e-6,
            "{n}: {t} {b} {z}"
        );
        assert!((t.cross(b) - z).length() <= 1e-5, "{n}: (t, b, n) is not right-handed");
        assert!((f.to_local(nn) - Vec3::Z).length() <= 1e-6, "{n}: to_local(n) = {}", f.to_local(nn));
        for _ in 0..4 {
            let w = uniform_sphere(&mut rng);
            assert!((f.to_world(f.to_local(w)) - w).length() <= 1e-6, "{n}: round trip of {w}");
            assert!((f.to_local(f.to_world(w)) - w).length() <= 1e-6, "{n}: round trip of {w}");
            assert!((f.to_local(w).length() - 1.0).abs() <= 1e-6);
        }
    }
}

#[test]
fn shading_frame_rejects_degenerate_normals() {
    for n in [
        Vec3::ZERO,
        Vec3::splat(f32::NAN),
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, f32::INFINITY, 1.0),
        Vec3::new(f32::NEG_INFINITY, 0.0, 0.0),
    ] {
        assert!(ShadingFrame::from_normal(n).is_none(), "a frame for {n}");
    }
}

/// `from_normal_tangent`: orthonormal and right-handed, the tangent the Gram–Schmidt
/// projection of the given one (in the plane of n and t, on t's side); degenerate tangents
/// (zero, not finite, parallel to n) fall back to the frame of `from_normal`.
#[test]
fn shading_frame_from_normal_and_tangent() {
    let mut rng = validation::rng(5100);
    for k in 0..3000 {
        let n = uniform_sphere(&mut rng) * (0.1 + 5.0 * uniform32(&mut rng));
        let mut t = uniform_sphere(&mut rng) * (0.1 + 5.0 * uniform32(&mut rng));
        if k % 10 == 0 {
            // nearly parallel, still usable (2e-3 rad away)
            t = n.normalize() + 2e-3 * n.normalize().any_orthonormal_vector();
        }
        let f = ShadingFrame::from_normal_tangent(n, t).expect("a frame");
        let (nn, x, y) = (n.normalize(), f.tangent(), f.bitangent());
        assert!((f.normal() - nn).length() <= 1e-6);
        for v in [x, y] {
            assert!((v.length() - 1.0).abs() <= 1e-6, "{n} {t}: |{v}|");
        }
        assert!(x.dot(y).abs() <= 1e-6 && x.dot(nn).abs() <= 1e-6 && y.dot(nn).abs() <= 1e-6, "{n} {t}");
        assert!((x.cross(y) - nn).length() <= 1e-5, "{n} {t}: not right-handed");
        // the projection in f64; f32 rounding of t·n is amplified by 1/sin∠(t, n)
        let (n64, t64) = (n.as_dvec3().normalize(), t.as_dvec3());
        let along = t64 - t64.dot(n64) * n64;
        let sin = along.length() / t64.length();
        let projected = along.normalize().as_vec3();
        let tol = 1e-6 + 2e-7 / sin as f32;
        assert!(
            (x - projected).length() <= tol,
            "{n} {t}: tangent {x}, expected {projected} (tolerance {tol})"
        );
        assert!((f.to_world(Vec3::X) - x).length() <= 1e-6 && (f.to_local(x) - Vec3::X).length() <= 1e-6);
    }
    let n = Vec3::new(0.3, -0.4, 0.8);
    let fallback = ShadingFrame::from_normal(n).unwrap();
    for t in [Vec3::ZERO, Vec3::NAN, Vec3::new(f32::INFINITY, 0.0, 1.0), n, -3.0 * n, n + 1e-5 * Vec3::X] {
        assert_eq!(ShadingFrame::from_normal_tangent(n, t), Some(fallback), "tangent {t}");
    }
    assert!(ShadingFrame::from_normal_tangent(Vec3::ZERO, Vec3::X).is_none());
    assert!(ShadingFrame::from_normal_tangent(Vec3::NAN, Vec3::X).is_none());
}

/// The tangent orients anisotropic roughness: gold with (αx, αy) = (0.1, 0.5) in the frame of
/// (n, t) equals gold with (0.5, 0.1) in the frame of (n, n × t) for every pair of world
/// directions (exact single scattering, relative 1e-4), and differs from gold with (0.1, 0.5)
/// there (the orientation matters: up to a factor of 2 or more at some pairs).
#[test]
fn the_tangent_orients_anisotropic_roughness() {
    let mut rng = validation::rng(5200);
    let single = |ax, ay| mf(ggx(ax, ay), gold()).with_technique(Technique::SingleScattering);
    let (a, b, wrong) = (single(0.1, 0.5), single(0.5, 0.1), single(0.1, 0.5));
    let (mut compared, mut max_wrong) = (0, 0.0f32);
    for _ in 0..200 {
        let n = uniform_sphere(&mut rng);
        let t = uniform_sphere(&mut rng);
        let fa = ShadingFrame::from_normal_tangent(n, t).unwrap();
        let fb = ShadingFrame::from_normal_tangent(n, n.cross(t)).unwrap();
        for _ in 0..20 {
            let (wo, wi) = (uniform_sphere(&mut rng), uniform_sphere(&mut rng));
            let (wo, wi) = if wo.dot(n) < 0.0 { (-wo, wi) } else { (wo, wi) };
            let wi = if wi.dot(n) < 0.0 { -wi } else { wi };
            let va = a.eval(fa.to_local(wo), fa.to_local(wi)).f.x;
            let vb = b.eval(fb.to_local(wo), fb.to_local(wi)).f.x;
            let vw = wrong.eval(fb.to_local(wo), fb.to_local(wi)).f.x;
            assert!((va - vb).abs() <= 1e-4 * va.max(vb) + 1e-30, "{wo} {wi}: {va} ≠ {vb}");
            if va > 1e-3 {
                compared += 1;
                max_wrong = max_wrong.max((vw / va).max(va / vw.max(1e-30)));
            }
        }
    }
    assert!(
        compared > 1000 && max_wrong > 2.0,
        "{compared} pairs, largest ratio of the wrong orientation {max_wrong}"
    );
}
