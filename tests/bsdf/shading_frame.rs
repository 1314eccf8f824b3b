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
