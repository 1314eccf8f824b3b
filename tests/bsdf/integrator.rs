//! What an integrator needs: flags, η, the specular limit, the roughness range.

use super::fixtures::*;
use super::weights::{view_in, view_out};

#[test]
fn flags_describe_the_lobes() {
    let rough = |f: BsdfFlags| f.glossy && !f.specular && f.has_non_specular();
    for (_, t) in ALL_TECHNIQUES {
        let f = mf(ggx(0.3, 0.3), gold()).with_technique(t).flags();
        assert!(f.reflection && !f.transmission && rough(f) && !f.diffuse, "gold {t:?}: {f:?}");
        let f = mf(ggx(0.3, 0.3), dielectric()).with_technique(t).flags();
        assert!(f.reflection && f.transmission && rough(f), "glass {t:?}: {f:?}");
        let f = mf(ggx(0.3, 0.3), diffuse()).with_technique(t).flags();
        assert!(
            f.reflection && !f.transmission && f.diffuse && !f.glossy && !f.specular,
            "diffuse {t:?}: {f:?}"
        );
        // diffuse facets have no specular limit
        let f = mf(ggx(1e-4, 1e-4), diffuse()).with_technique(t).flags();
        assert!(f.diffuse && !f.specular, "smooth diffuse {t:?}: {f:?}");
    }
    let c = ClassicBrdf::new(Vec3::splat(0.3), Vec3::splat(0.5), ClassicNdf::Ggx(0.3), ClassicMasking::Exact)
        .unwrap();
    let f = c.flags();
    assert!(f.reflection && !f.transmission && f.diffuse && f.glossy && !f.specular, "{f:?}");
    let c =
        ClassicBrdf::new(Vec3::splat(0.3), Vec3::ZERO, ClassicNdf::Ggx(0.3), ClassicMasking::Exact).unwrap();
    assert!(c.flags().diffuse && !c.flags().glossy);
}

/// The relative index of a sample: η entering the dielectric, 1/η leaving it, 1 for a
/// reflection, and consistent with the side of wi.
#[test]
fn samples_carry_the_relative_index() {
    let mut rng = validation::rng(8400);
    let (mut entering, mut leaving, mut reflected) = (0, 0, 0);
    for (_, t) in ALL_TECHNIQUES {
        let b = mf(ggx(ALPHA_MS, ALPHA_MS), dielectric()).with_technique(t);
        for wo in [view_out(), view_in()] {
            for _ in 0..400 {
                let Some(s) = b.sample_rng(wo, &mut rng) else { continue };
                let expected = match (wo.z > 0.0, s.wi.z > 0.0) {
                    (true, false) => {
                        entering += 1;
                        ETA
                    }
                    (false, true) => {
                        leaving += 1;
                        1.0 / ETA
                    }
                    _ => {
                        reflected += 1;
                        1.0
                    }
                };
                assert!(
                    (s.eta - expected).abs() <= 1e-6 * expected,
                    "{t:?} wo {wo}: η = {} for wi {}",
                    s.eta,
                    s.wi
                );
            }
        }
        let g = mf(ggx(ALPHA_MS, ALPHA_MS), gold()).with_technique(t);
        let s = g.sample(view_out(), 0.5, Vec2::new(0.3, 0.6)).unwrap();
        assert_eq!(s.eta, 1.0);
    }
    assert!(entering > 100 && leaving > 100 && reflected > 100, "{entering} {leaving} {reflected}");
}

/// An opaque BSDF seen from below its shading hemisphere keeps its rough lobe across
/// `SMOOTH_ALPHA`: the albedo of GGX gold at θo = 100° just below the threshold equals the one
/// just above it (both ≈ 0.94; the Dirac limit made it 0), for the walk and single scattering.
#[test]
fn backfacing_views_keep_their_lobe_across_smooth_alpha() {
    use microsurface::SMOOTH_ALPHA;
    const N: usize = 6_000;
    let wo = dir(100f64.to_radians(), 0.3);
    let cases = [("walk", Technique::RandomWalk), ("single", Technique::SingleScattering)];
    let z = family_z(1e-3, cases.len());
    for (k, (tname, t)) in cases.into_iter().enumerate() {
        let stats = [0.99, 1.01].map(|f| {
            let b = mf(ggx(f * SMOOTH_ALPHA, f * SMOOTH_ALPHA), gold()).with_technique(t);
            let mut rng = validation::rng(8600 + k as u64);
            let mut st = Stats::default();
            for _ in 0..N {
                st.push(b.sample_rng(wo, &mut rng).map_or(0.0, |s| f64::from(s.weight.x)));
            }
            st
        });
        assert!(stats[1].mean() > 0.5, "{tname}: albedo above the threshold {}", stats[1].mean());
        assert_two_sample(&format!("{tname}: albedo across SMOOTH_ALPHA"), &stats[0], &stats[1], z, 0.01);
    }
}

/// Both sides of `SMOOTH_ALPHA`: just below, a conductor and a dielectric are Dirac lobes for
/// every technique (eval and pdf 0, the mirror and refraction directions with Fresnel
/// weights, `specular` flags, the event probabilities as pdf); just above, they are glossy
/// and sample near those directions with a density.
#[test]
fn the_specular_limit_below_smooth_alpha() {
    use microsurface::SMOOTH_ALPHA;
    use microsurface::fresnel::fresnel_dielectric;
    let below = SMOOTH_ALPHA * 0.9;
    let above = SMOOTH_ALPHA * 1.1;
    let wo = dir(0.6, 0.4);
    let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
    let f_glass = fresnel_dielectric(wo.z, ETA);
    let mut rng = validation::rng(8500);
    for (tname, t) in ALL_TECHNIQUES {
        // conductor
        let b = mf(ggx(below, 0.5 * below), gold()).with_technique(t);
        assert!(b.flags().specular && !b.flags().glossy && !b.flags().has_non_specular(), "{tname}");
        let s = b.sample_rng(wo, &mut rng).expect("a mirror reflects");
        assert_eq!(s.wi, mirror, "{tname}");
        assert!(rel_close(s.weight, gold().fresnel(wo.z), 1e-6), "{tname}: weight {}", s.weight);
        assert!(s.flags.specular && s.flags.reflection && s.pdf == 1.0 && s.eta == 1.0, "{tname}: {s:?}");
        assert_eq!(b.eval(wo, mirror).f, Vec3::ZERO);
        assert_eq!(b.pdf(wo, mirror), 0.0);
        // seen from below the shading hemisphere (a normal map) the rough lobe answers: its
        // visible facets are the distribution's tails, which do not shrink as α → 0; its
        // samples are flagged specular (pdf 1), and eval and pdf stay 0, as the flags say
        let from_below = b.sample(-wo, 0.5, Vec2::splat(0.5)).expect("the backfacing lobe reflects");
        assert!(from_below.flags.specular && from_below.pdf == 1.0, "{tname}: {from_below:?}");
        assert!(
            from_below.weight.max_element() > 0.0 && from_below.flags.reflection,
            "{tname}: {from_below:?}"
        );
        assert_eq!(b.eval(-wo, from_below.wi).f, Vec3::ZERO, "{tname}");
        assert_eq!(b.pdf(-wo, from_below.wi), 0.0, "{tname}");
        // dielectric: reflection with probability F, refraction (Snell) otherwise
        let d = mf(ggx(below, below), dielectric()).with_technique(t);
        assert!(d.flags().specular && d.flags().transmission && d.flags().reflection, "{tname}");
        let n = 4000;
        let mut refracted = 0;
        for k in 0..n {
            let uc = (k as f32 + 0.5) / n as f32;
            let s = d.sample(wo, uc, Vec2::new(0.3, 0.7)).expect("a smooth interface scatters");
            assert!(s.flags.specular && s.flags.exact_pdf, "{tname}: {s:?}");
            if s.flags.reflection {
                assert_eq!(s.wi, mirror);
                assert!((s.pdf - f_glass).abs() <= 1e-6 && s.weight == Vec3::ONE && s.eta == 1.0, "{s:?}");
            } else {
                refracted += 1;
                // tangential components −wo/η, radiance scaled by 1/η²
                let t_expected = -Vec2::new(wo.x, wo.y) / ETA;
                assert!((Vec2::new(s.wi.x, s.wi.y) - t_expected).length() <= 1e-6 && s.wi.z < 0.0, "{s:?}");
                assert!((s.wi.length() - 1.0).abs() <= 1e-6);
                assert!((s.pdf - (1.0 - f_glass)).abs() <= 1e-6 && s.eta == ETA, "{s:?}");
                assert!(rel_close(s.weight, Vec3::splat(1.0 / (ETA * ETA)), 1e-6), "{s:?}");
            }
            assert_eq!(d.pdf(wo, s.wi), 0.0);
            assert_eq!(d.eval(wo, s.wi).f, Vec3::ZERO);
        }
        // stratified uc: the refracted share is 1 − F up to the grid's resolution
        let share = refracted as f32 / n as f32;
        assert!(
            (share - (1.0 - f_glass)).abs() <= 1.0 / n as f32,
            "{tname}: refracted {share}, 1 − F = {}",
            1.0 - f_glass
        );
        // just above the threshold: glossy, near the specular directions, with a density
        for (label, rough) in [
            ("gold", &mf(ggx(above, above), gold()) as &dyn Bsdf),
            ("glass", &mf(ggx(above, above), dielectric())),
        ] {
            let _ = label;
            assert!(!rough.flags().specular && rough.flags().glossy, "{tname} {label}");
        }
        let rough = mf(ggx(above, above), gold()).with_technique(t);
        let s = rough.sample_rng(wo, &mut rng).expect("gold reflects");
        assert!(!s.flags.specular && s.pdf > 0.0, "{tname}: {s:?}");
        assert!(s.wi.dot(mirror) > 0.999, "{tname}: {} far from the mirror direction", s.wi);
        assert!(rough.eval(wo, s.wi).f.max_element() > 0.0 || t != Technique::SingleScattering, "{tname}");
        assert!(rough.pdf(wo, s.wi) > 0.0, "{tname}");
    }
}

/// An index-matched dielectric (η = 1) is a Dirac transmission at every roughness: light
/// passes straight through with weight 1, and eval and pdf are 0.
#[test]
fn index_matched_dielectric_is_a_specular_transmission() {
    let mut rng = validation::rng(8600);
    for (tname, t) in ALL_TECHNIQUES {
        let b = mf(ggx(0.5, 0.5), Dielectric::new(1.0).unwrap()).with_technique(t);
        let f = b.flags();
        assert!(f.specular && f.transmission && !f.reflection && !f.has_non_specular(), "{tname}: {f:?}");
        for wo in [view_out(), view_in()] {
            let s = b.sample_rng(wo, &mut rng).expect("light passes through");
            assert!((s.wi + wo).length() <= 1e-6, "{tname}: wi = {} for wo = {wo}", s.wi);
            assert!(s.weight == Vec3::ONE && s.pdf == 1.0 && s.eta == 1.0, "{tname}: {s:?}");
            assert!(s.flags.specular && s.flags.transmission && !s.flags.reflection, "{tname}: {s:?}");
            for _ in 0..20 {
                let w = uniform_sphere(&mut rng);
                assert_eq!(b.eval(wo, w).f, Vec3::ZERO);
                assert_eq!(b.pdf(wo, w), 0.0);
            }
            assert_eq!(b.pdf(wo, s.wi), 0.0);
        }
    }
}

/// α above `MAX_WALK_ALPHA` is rejected (walks grow linearly with α); up to it accepted.
#[test]
fn roughness_above_the_walk_range_is_rejected() {
    use microsurface::{Error, MAX_WALK_ALPHA};
    assert!(MicrofacetBsdf::new(ggx(MAX_WALK_ALPHA, 0.1), gold()).is_ok());
    for a in [MAX_WALK_ALPHA * 1.01, 1e6] {
        for r in [
            MicrofacetBsdf::new(ggx(a, 0.5), gold()).err(),
            MicrofacetBsdf::new(beckmann(0.5, a), diffuse()).err(),
        ] {
            match r {
                Some(Error::InvalidParameter { name: "alpha", value, .. }) => assert_eq!(value, a),
                other => panic!("α = {a}: {other:?}"),
            }
        }
    }
}

/// Single scattering uses the caller's uniforms directly: `u` is the visible-normal sample
/// (a GGX conductor: the bounded cap's `GgxBoundedCap.sample(wo, [u.x, u.y, ·])`; a
/// dielectric: `sample_d_wi(wo, u.x, u.y)`; the reflection about it) and `uc` the Fresnel
/// event of a dielectric (reflection iff uc < F(wo·m)). Uniforms on the 2⁻²⁴ grid the crate
/// draws on are passed through exactly.
#[test]
fn single_scattering_sample_is_driven_by_the_callers_uniforms() {
    use microsurface::fresnel::fresnel_dielectric;
    let grid = |x: f32| (x * 16_777_216.0).floor() / 16_777_216.0;
    let slope = ggx(0.4, 0.25);
    let gold_b = mf(slope, gold()).with_technique(Technique::SingleScattering);
    let glass_b = mf(slope, dielectric()).with_technique(Technique::SingleScattering);
    let mut rng = validation::rng(8700);
    let (mut reflections, mut refractions) = (0, 0);
    for _ in 0..2000 {
        let wo = dir(1.4 * uniform64(&mut rng), 2.0 * PI * uniform64(&mut rng));
        let u = Vec2::new(grid(uniform32(&mut rng)), grid(uniform32(&mut rng)));
        let uc = grid(uniform32(&mut rng));
        let m_gold = microsurface::vndf::VisibleNormalSampler::sample(
            &microsurface::vndf::GgxBoundedCap(slope),
            wo,
            [u.x, u.y, 0.0],
        );
        let mirror_gold = 2.0 * wo.dot(m_gold) * m_gold - wo;
        if let Some(s) = gold_b.sample(wo, uc, u) {
            assert!(
                (s.wi - mirror_gold).length() <= 1e-5,
                "wo {wo}, u {u}: wi {} ≠ reflection {mirror_gold}",
                s.wi
            );
        }
        let m = slope.sample_d_wi(wo, u.x, u.y);
        let mirror = 2.0 * wo.dot(m) * m - wo;
        let f = fresnel_dielectric(wo.dot(m), ETA);
        if let Some(s) = glass_b.sample(wo, uc, u) {
            let reflected = s.wi.z > 0.0;
            // a reflection at the facet m is the mirror direction; near F the rounding of the
            // threshold may differ
            if (uc - f).abs() > 1e-5 {
                assert_eq!(reflected, uc < f, "wo {wo}, uc {uc}, F {f}: event");
            }
            if reflected {
                reflections += 1;
                assert!((s.wi - mirror).length() <= 1e-5, "{} ≠ {mirror}", s.wi);
            } else {
                refractions += 1;
            }
        }
    }
    assert!(reflections > 50 && refractions > 500, "{reflections} reflections, {refractions} refractions");
}

/// Single scattering is exact on conductors and dielectrics (deterministic: every key gives
/// the same bits, `exact` is set) and stochastic on diffuse facets, as its documentation and
/// flags say: an unbiased one-sample estimate whose value depends on the key.
#[test]
fn single_scattering_of_diffuse_facets_is_flagged_stochastic() {
    let (wo, wi) = (dir(0.7, 0.2), dir(0.4, 2.5));
    for (label, b, exact) in [
        ("gold", &mf(ggx(0.5, 0.5), gold()).with_technique(Technique::SingleScattering) as &dyn Bsdf, true),
        ("glass", &mf(ggx(0.5, 0.5), dielectric()).with_technique(Technique::SingleScattering), true),
        ("diffuse", &mf(ggx(0.5, 0.5), diffuse()).with_technique(Technique::SingleScattering), false),
    ] {
        let values: Vec<BsdfValue> = (0..16).map(|key| b.eval_keyed(wo, wi, key)).collect();
        assert!(values.iter().all(|v| v.exact == exact), "{label}: {values:?}");
        let distinct = values.iter().filter(|v| v.f != values[0].f).count();
        assert_eq!(distinct > 0, !exact, "{label}: {distinct} keys gave another value");
        let s = b.sample(wo, 0.3, Vec2::new(0.6, 0.2)).expect("a sample");
        assert_eq!(s.flags.exact_pdf, exact, "{label}: {s:?}");
    }
}
