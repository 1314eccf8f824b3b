//! Degenerate but legal inputs (grazing and near-grazing directions, ωo = −ωi, the
//! poles, η = 1 and η = 1 + 1e-6) give finite results from every evaluation and sampling
//! routine.

use glam::Vec3;
use microsurface::research::{
    GaussianHeight, Material, Microsurface, MicrosurfaceHeight, ScatteringOrder, UniformHeight,
};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, ComplexIor, Conductor, Dielectric, Diffuse, Ggx};
use validation::TestRng;

/// Degenerate direction pairs: grazing (z = 0 and 1e-7, both sides), the poles, ωo = −ωi
/// and ωo = ωi.
fn degenerate_pairs() -> Vec<(Vec3, Vec3)> {
    let grazing = Vec3::new(0.6, 0.8, 0.0);
    let near = Vec3::new(0.6, 0.8, 1e-7).normalize();
    let near_below = Vec3::new(0.6, 0.8, -1e-7).normalize();
    let normal = Vec3::new(0.3, -0.2, 0.93).normalize();
    let mut pairs = Vec::new();
    for wi in [grazing, -grazing, near, near_below, Vec3::Z, -Vec3::Z, normal, -normal] {
        for wo in [wi, -wi, grazing, near, near_below, Vec3::Z, -Vec3::Z, normal, -normal] {
            pairs.push((wi, wo));
        }
    }
    pairs
}

fn check<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
    label: &str,
    surface: Microsurface<H, S, M>,
    rng: &mut TestRng,
) -> usize {
    let mut checked = 0;
    for (wi, wo) in degenerate_pairs() {
        for _ in 0..20 {
            let ctx = format!("{label}: ωi = {wi}, ωo = {wo}");
            for order in
                [ScatteringOrder::All, ScatteringOrder::only(1).unwrap(), ScatteringOrder::up_to(3).unwrap()]
            {
                let v = surface.eval(wi, wo, order, rng);
                assert!(v.is_finite() && v.min_element() >= 0.0, "{ctx}: eval({order:?}) = {v}");
            }
            let v = surface.eval_single_scattering(wi, wo, rng);
            assert!(v.is_finite() && v.min_element() >= 0.0, "{ctx}: eval_single_scattering = {v}");
            let v = surface.eval_phase(wi, wo, rng);
            assert!(v.is_finite() && v.min_element() >= 0.0, "{ctx}: eval_phase = {v}");
            let p = surface.sample_phase(wi, rng);
            assert!(p.wo.is_finite() && p.weight.is_finite(), "{ctx}: sample_phase = {p:?}");
            assert!((p.wo.length() - 1.0).abs() < 1e-3, "{ctx}: sample_phase ωo = {} not unit", p.wo);
            if let Some(s) = surface.sample(wi, rng) {
                assert!(s.wo.is_finite() && s.weight.is_finite(), "{ctx}: sample = {s:?}");
                assert!((s.wo.length() - 1.0).abs() < 1e-3, "{ctx}: sample ωo = {} not unit", s.wo);
            }
            checked += 1;
        }
    }
    checked
}

fn check_materials<H: MicrosurfaceHeight, S: MicrosurfaceSlope>(h: H, s: S, rng: &mut TestRng) -> usize {
    let gold = ComplexIor::new(Vec3::new(0.18, 0.42, 1.37), Vec3::new(3.42, 2.35, 1.77)).unwrap();
    let name = format!("{h:?} {s:?}");
    let mut n =
        check(&format!("{name} perfect conductor"), Microsurface::new(h, s, Conductor::perfect()), rng);
    n += check(&format!("{name} gold"), Microsurface::new(h, s, Conductor::new(gold)), rng);
    n += check(
        &format!("{name} η=1 conductor"),
        Microsurface::new(h, s, Conductor::new(ComplexIor::new(Vec3::ONE, Vec3::ZERO).unwrap())),
        rng,
    );
    n += check(&format!("{name} diffuse"), Microsurface::new(h, s, Diffuse::white()), rng);
    for eta in [1.0, 1.0 + 1e-6, 1.5, 1.0 / 1.5] {
        n += check(
            &format!("{name} dielectric η = {eta}"),
            Microsurface::new(h, s, Dielectric::new(eta).unwrap()),
            rng,
        );
    }
    n
}

#[test]
fn degenerate_inputs_give_finite_results() {
    let mut rng = validation::rng(99);
    let mut n = 0;
    for (ax, ay) in [(0.5, 0.5), (1.0, 0.1), (2.0, 2.0), (1e-3, 1e-3)] {
        n += check_materials(UniformHeight, Ggx::new(ax, ay).unwrap(), &mut rng);
        n += check_materials(GaussianHeight, Beckmann::new(ax, ay).unwrap(), &mut rng);
    }
    assert!(n > 10_000);
}
