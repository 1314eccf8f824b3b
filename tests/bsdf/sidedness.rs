//! `Sidedness`: views from below the shading plane of opaque BSDFs answered by the backfacing
//! lobe (the default), mirrored (two-sided) or not at all (black); dielectrics ignore it.

use super::fixtures::*;
use microsurface::Sidedness;

fn mirror(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, -w.z)
}

/// Every call of `b` with sidedness `TwoSided` for a view from below equals the call of the
/// default BSDF `base` at the mirrored directions, bit for bit (the stochastic techniques hash
/// the mirrored directions); `Black` gives nothing from below; views from above are unchanged.
fn check_sides(label: &str, base: &dyn Bsdf, two: &dyn Bsdf, black: &dyn Bsdf, rng: &mut TestRng) -> usize {
    let mut lit = 0;
    for _ in 0..300 {
        let (wo, wi) = (uniform_sphere(rng), uniform_sphere(rng));
        let key = rand::Rng::next_u64(rng);
        let (uc, u) = (uniform32(rng), Vec2::new(uniform32(rng), uniform32(rng)));
        if wo.z < 0.0 {
            let (m_o, m_i) = (mirror(wo), mirror(wi));
            assert_eq!(
                two.eval_keyed(wo, wi, key),
                base.eval_keyed(m_o, m_i, key),
                "{label}: eval {wo} {wi}"
            );
            assert_eq!(two.pdf(wo, wi), base.pdf(m_o, m_i), "{label}: pdf {wo} {wi}");
            assert_eq!(
                two.eval_with_pdf_keyed(wo, wi, key),
                base.eval_with_pdf_keyed(m_o, m_i, key),
                "{label}"
            );
            let s = two.sample_keyed(wo, uc, u, key);
            let expected = base.sample_keyed(m_o, uc, u, key).map(|s| BsdfSample { wi: mirror(s.wi), ..s });
            assert_eq!(s, expected, "{label}: sample {wo}");
            lit += usize::from(s.is_some_and(|s| s.wi.z < 0.0 && s.flags.reflection));
            assert_eq!(black.eval_keyed(wo, wi, key).f, Vec3::ZERO, "{label}: black eval {wo}");
            assert_eq!(black.pdf(wo, wi), 0.0, "{label}: black pdf {wo}");
            assert_eq!(black.eval_with_pdf_keyed(wo, wi, key).1, 0.0, "{label}");
            assert!(black.sample_keyed(wo, uc, u, key).is_none(), "{label}: black sample {wo}");
        } else {
            for b in [two, black] {
                assert_eq!(b.eval_keyed(wo, wi, key), base.eval_keyed(wo, wi, key), "{label}: from above");
                assert_eq!(b.pdf(wo, wi), base.pdf(wo, wi), "{label}: from above");
                assert_eq!(b.sample_keyed(wo, uc, u, key), base.sample_keyed(wo, uc, u, key), "{label}");
            }
        }
    }
    lit
}

#[test]
fn sidedness_mirrors_or_blackens_views_from_below() {
    let mut rng = validation::rng(9300);
    for (tname, t) in ALL_TECHNIQUES {
        for (mname, alpha) in [("gold", 0.3), ("smooth gold", 1e-4)] {
            let b = mf(ggx(alpha, 0.7 * alpha), gold()).with_technique(t);
            assert_eq!(b.sidedness(), Sidedness::BackfacingLobe);
            let (two, black) = (b.with_sidedness(Sidedness::TwoSided), b.with_sidedness(Sidedness::Black));
            let lit = check_sides(&format!("{mname} {tname}"), &b, &two, &black, &mut rng);
            assert!(lit > 50, "{mname} {tname}: {lit} two-sided reflections below");
        }
        let b = mf(beckmann(0.4, 0.4), diffuse()).with_technique(t);
        let (two, black) = (b.with_sidedness(Sidedness::TwoSided), b.with_sidedness(Sidedness::Black));
        assert!(check_sides(&format!("diffuse {tname}"), &b, &two, &black, &mut rng) > 50);
        // a dielectric's view from below is a view from inside: unchanged
        let glass = mf(ggx(0.3, 0.3), dielectric()).with_technique(t);
        for s in [Sidedness::TwoSided, Sidedness::Black] {
            let other = glass.with_sidedness(s);
            for _ in 0..50 {
                let (wo, wi) = (-uniform_sphere(&mut rng).abs(), uniform_sphere(&mut rng));
                assert_eq!(other.eval_keyed(wo, wi, 3), glass.eval_keyed(wo, wi, 3));
                assert_eq!(other.sample(wo, 0.4, Vec2::splat(0.3)), glass.sample(wo, 0.4, Vec2::splat(0.3)));
            }
        }
    }
    // the classic BRDF: nothing from below by default (no backfacing lobe), mirrored two-sided
    let c = ClassicBrdf::new(Vec3::splat(0.3), Vec3::splat(0.5), ClassicNdf::Ggx(0.3), ClassicMasking::Exact)
        .unwrap()
        .with_sidedness(Sidedness::Black);
    let default = c.with_sidedness(Sidedness::BackfacingLobe);
    let two = c.with_sidedness(Sidedness::TwoSided);
    assert!(check_sides("classic", &default, &two, &c, &mut rng) > 50);
    for _ in 0..100 {
        let (wo, wi) = (-uniform_sphere(&mut rng).abs(), uniform_sphere(&mut rng));
        assert_eq!(default.eval(wo, wi).f, Vec3::ZERO);
        assert!(default.sample(wo, 0.5, Vec2::splat(0.4)).is_none());
    }
}
