//! The invariance-principle estimator (Cui et al. 2023, `Invariance`): per-order albedos
//! against the exact quadrature of the walk (F = 1, GGX α = 1) and against the walk's own
//! per-order albedos elsewhere (Beckmann, other α, anisotropy, a coloured conductor, diffuse
//! facets), reciprocity, the white furnace, the renderer technique, the rejected dielectric and
//! a finiteness fuzz over the crate's input domain.
//!
//! Statistics: every Monte Carlo assertion is |difference| ≤ z·SE with z = `family_z(0.01, m)`
//! (Šidák over the m assertions of its test function), and asserts an upper bound on SE so
//! that it can fail. Albedos ∫ f·|cos θo| dωo are estimated from `eval` at ωo drawn from a
//! mixture with an exact density: ½ the first bounce's phase function (`Material::pdf_phase`)
//! + ½ a cosine lobe (the cosine lobe alone for diffuse facets, whose `pdf_phase` is approximate). Accumulation is in f64; every generator is a fixed-seed PCG.

use glam::{DVec3, Vec2, Vec3};
use microsurface::research::{
    Interaction, Invariance, Material, Microsurface, ScatteringOrder, Side, UniformHeight,
    sample_cosine_hemisphere,
};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{
    Beckmann, Bsdf, ComplexIor, Conductor, Dielectric, Diffuse, Error, Ggx, MicrofacetBsdf, Technique,
};
use rand::RngExt;
use std::f64::consts::PI;
use validation::per_order::{Model as Reference, albedo as quadrature, gauss_legendre};
use validation::{Stats, TestRng, assert_mean, assert_two_sample, family_z, par_map, uniform64};

fn only(n: u32) -> ScatteringOrder {
    ScatteringOrder::only(n).expect("orders start at 1")
}

/// The direction at polar angle θ and azimuth φ.
fn dir(theta: f64, phi: f64) -> Vec3 {
    DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()).as_vec3()
}

/// ωo from ½ the phase function of ωi + ½ a cosine lobe, with its exact density (the cosine
/// lobe alone where the phase function's density is not exact: diffuse facets).
fn mixture<S: MicrosurfaceSlope, M: Material>(slope: &S, m: &M, wi: Vec3, rng: &mut TestRng) -> (Vec3, f64) {
    let share = if M::EXACT_PHASE_PDF { 0.5 } else { 0.0 };
    let wo = if uniform64(rng) < share {
        m.sample_phase(slope, wi, Side::Outside, rng).wo
    } else {
        sample_cosine_hemisphere(rng.random::<f32>(), rng.random::<f32>())
    };
    let phase =
        if share > 0.0 { f64::from(m.pdf_phase(slope, &Interaction::reflection(wi, wo))) } else { 0.0 };
    let cosine = if wo.z > 0.0 { f64::from(wo.z) / PI } else { 0.0 };
    (wo, share * phase + (1.0 - share) * cosine)
}

/// The estimates of the albedos of `orders` (and of all orders, last) from `n` evaluations,
/// per RGB channel: mean of eval/pdf at ωo from `mixture`.
fn eval_albedos<S: MicrosurfaceSlope, M: Material>(
    inv: &Invariance<S, M>,
    wi: Vec3,
    orders: u32,
    n: usize,
    rng: &mut TestRng,
) -> Vec<[Stats; 3]> {
    let mut st = vec![[Stats::default(), Stats::default(), Stats::default()]; orders as usize + 1];
    for _ in 0..n {
        let (wo, pdf) = mixture(inv.slope(), inv.material(), wi, rng);
        for (k, s) in st.iter_mut().enumerate() {
            let order = if k as u32 == orders { ScatteringOrder::All } else { only(k as u32 + 1) };
            let v = if wo.z > 0.0 && pdf > 0.0 {
                inv.eval(wi, wo, order, rng).as_dvec3() / pdf
            } else {
                DVec3::ZERO
            };
            for c in 0..3 {
                s[c].push(v[c]);
            }
        }
    }
    st
}

/// The walk's albedos of `orders` (and of all, last) per channel, from the weights of `n`
/// sampled walks binned by their number of bounces.
fn walk_albedos<S: MicrosurfaceSlope, M: Material>(
    walk: &Microsurface<UniformHeight, S, M>,
    wi: Vec3,
    orders: u32,
    n: usize,
    rng: &mut TestRng,
) -> Vec<[Stats; 3]> {
    let mut st = vec![[Stats::default(), Stats::default(), Stats::default()]; orders as usize + 1];
    for _ in 0..n {
        let s = walk.sample(wi, rng);
        for (k, stats) in st.iter_mut().enumerate() {
            let counts = s.is_some_and(|s| k as u32 == orders || s.bounces == k as u32 + 1);
            let w = if counts { s.map_or(DVec3::ZERO, |s| s.weight.as_dvec3()) } else { DVec3::ZERO };
            for c in 0..3 {
                stats[c].push(w[c]);
            }
        }
    }
    st
}

// ---------------------------------------------------------------------------------------------
// Unbiasedness per order
// ---------------------------------------------------------------------------------------------

/// Per-order albedos (orders 1, 2, 3) of a perfect conductor with GGX α = 1 at θi ∈ {0, 1,
/// 1.5}, against the deterministic quadrature of the walk (`validation::per_order`, independent
/// of the crate): `eval` with `ScatteringOrder::only` (N = 40 000 each) and the bounce
/// histogram of `sample` (N = 200 000). Each estimate within z·SE of the walk's quadrature
/// (Šidák over 3 θi × 3 orders × 2 estimates), SE ≤ 2.5e-3 asserted. At θi ∈ {0, 1} the
/// height-correlated position-free model differs from the walk by more than 0.01 at orders 2
/// and 3 (asserted), so the test tells the two models apart: `eval` is also asserted to lie
/// more than z·SE away from that model there.
#[test]
fn per_order_albedos_against_quadrature() {
    const N_EVAL: usize = 40_000;
    const N_SAMPLE: usize = 200_000;
    let thetas = [0.0f64, 1.0, 1.5];
    let rule = gauss_legendre(10);
    let slope = Ggx::isotropic(1.0).expect("valid roughness");
    let inv = Invariance::new(slope, Conductor::perfect()).expect("a conductor");
    let jobs: Vec<(usize, bool)> = (0..3).flat_map(|t| [(t, false), (t, true)]).collect();
    let results = par_map(&jobs, |i, &(t, by_sample)| {
        let mut rng = validation::rng(0x1a7_0000 + i as u64);
        let wi = dir(thetas[t], 0.0);
        if by_sample {
            let mut st = vec![Stats::default(); 3];
            for _ in 0..N_SAMPLE {
                let b = inv.sample(wi, &mut rng).map(|s| s.bounces);
                for (k, s) in st.iter_mut().enumerate() {
                    s.push(if b == Some(k as u32 + 1) { 1.0 } else { 0.0 });
                }
            }
            st
        } else {
            eval_albedos(&inv, wi, 3, N_EVAL, &mut rng).into_iter().take(3).map(|c| c[0]).collect()
        }
    });
    let z = family_z(0.01, jobs.len() * 3);
    for (&(t, by_sample), st) in jobs.iter().zip(&results) {
        let cos_i = thetas[t].cos();
        for (k, st) in st.iter().enumerate() {
            let walk = quadrature(Reference::Walk, cos_i, k + 1, &rule);
            let correlated = quadrature(Reference::Correlated, cos_i, k + 1, &rule);
            let label = format!(
                "θi = {} order {} ({})",
                thetas[t],
                k + 1,
                if by_sample { "sample histogram" } else { "eval" }
            );
            println!(
                "{label}: N = {}, mean {:.5}, SE {:.5}, z = {:.2} (walk quadrature {walk:.5}; correlated {correlated:.5})",
                st.n,
                st.mean(),
                st.se(),
                (st.mean() - walk) / st.se()
            );
            assert_mean(&label, st, walk, z, 2.5e-3, 0.0);
            if !by_sample && k > 0 && thetas[t] < 1.5 {
                assert!((correlated - walk).abs() > 0.01, "{label}: the models do not differ");
                assert!(
                    (st.mean() - correlated).abs() > z * st.se(),
                    "{label}: indistinguishable from the correlated position-free model"
                );
            }
        }
    }
}

/// Per-order albedos (orders 1–3 and all) of `eval` against the walk's bounce histogram,
/// elsewhere than the quadrature's configuration: Beckmann α = 0.5, GGX α = 0.3 at grazing
/// incidence, anisotropic GGX (0.15, 0.9), Beckmann α = 2, gold conductors (per RGB channel)
/// and white diffuse facets (whose paths, unlike a mirror's, can go down again after going
/// up). Two-sample z-test,
/// Šidák over every (configuration, order, channel); each combined SE ≤ 8e-3 asserted (order
/// 4 carries 3e-4 of the albedo at Beckmann α = 0.5, too little for this N to resolve).
#[test]
fn per_order_albedos_against_the_walk() {
    const N_EVAL: usize = 40_000;
    const N_WALK: usize = 200_000;
    const ORDERS: u32 = 3;
    let gold = Conductor::new(ComplexIor::GOLD);
    let perfect = Conductor::perfect();
    let beckmann = |a: f32| Beckmann::isotropic(a).expect("valid roughness");
    let ggx = |ax: f32, ay: f32| Ggx::new(ax, ay).expect("valid roughness");
    let configs: Vec<(&str, f64)> = vec![
        ("Beckmann α = 0.5, F = 1", 0.7),
        ("GGX α = 0.3, F = 1", 1.3),
        ("GGX (0.15, 0.9) gold", 1.0),
        ("Beckmann α = 2 gold", 0.4),
        ("GGX α = 0.7 gold", 1.45),
        ("GGX α = 0.8 white diffuse", 0.6),
    ];
    let results = par_map(&configs, |i, &(_, theta)| {
        let mut rng = validation::rng(0x2b0_0000 + i as u64);
        let wi = dir(theta, 0.7);
        fn run<S: MicrosurfaceSlope, M: Material>(
            s: S,
            m: M,
            wi: Vec3,
            rng: &mut TestRng,
        ) -> (Vec<[Stats; 3]>, Vec<[Stats; 3]>) {
            let inv = Invariance::new(s, m).expect("opaque");
            let walk = Microsurface::new(UniformHeight, s, m);
            (eval_albedos(&inv, wi, ORDERS, N_EVAL, rng), walk_albedos(&walk, wi, ORDERS, N_WALK, rng))
        }
        match i {
            0 => run(beckmann(0.5), perfect, wi, &mut rng),
            1 => run(ggx(0.3, 0.3), perfect, wi, &mut rng),
            2 => run(ggx(0.15, 0.9), gold, wi, &mut rng),
            3 => run(beckmann(2.0), gold, wi, &mut rng),
            4 => run(ggx(0.7, 0.7), gold, wi, &mut rng),
            _ => run(ggx(0.8, 0.8), Diffuse::white(), wi, &mut rng),
        }
    });
    let z = family_z(0.01, configs.len() * (ORDERS as usize + 1) * 3);
    for ((label, theta), (eval, walk)) in configs.iter().zip(&results) {
        for k in 0..=ORDERS as usize {
            let order = if k == ORDERS as usize { "all".to_string() } else { (k + 1).to_string() };
            for c in 0..3 {
                let l = format!("{label}, θi = {theta}, order {order}, channel {c}");
                let (a, b) = (&eval[k][c], &walk[k][c]);
                let se = (a.se().powi(2) + b.se().powi(2)).sqrt();
                if c == 0 {
                    println!(
                        "{l}: eval N = {} mean {:.5} SE {:.5}; walk N = {} mean {:.5} SE {:.5}; z = {:.2}",
                        a.n,
                        a.mean(),
                        a.se(),
                        b.n,
                        b.mean(),
                        b.se(),
                        (a.mean() - b.mean()) / se
                    );
                }
                assert_two_sample(&l, a, b, z, 8e-3);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Reciprocity and energy
// ---------------------------------------------------------------------------------------------

/// The walk's BRDF is reciprocal (Heitz et al. 2016, §6.2), and so is this estimate of it:
/// f(ωi, ωo) = eval(ωi, ωo)/cos θo against f(ωo, ωi) = eval(ωo, ωi)/cos θi, N = 30 000 each,
/// two-sample z-test per channel (Šidák over every pair and channel), SE ≤ 2 % of the value.
#[test]
fn reciprocity() {
    const N: usize = 30_000;
    let pairs = [
        (dir(0.3, 0.0), dir(1.1, 2.0)),
        (dir(1.3, 0.4), dir(0.6, 3.0)),
        (dir(1.45, 0.0), dir(1.4, 3.1)),
        (dir(0.9, 1.0), dir(0.2, 5.0)),
    ];
    let configs = ["GGX α = 1 gold", "Beckmann α = 0.4 F = 1", "GGX (0.2, 0.7) gold"];
    let jobs: Vec<(usize, usize)> =
        (0..configs.len()).flat_map(|c| (0..pairs.len()).map(move |p| (c, p))).collect();
    let results = par_map(&jobs, |i, &(c, p)| {
        let mut rng = validation::rng(0x3c1_0000 + i as u64);
        let (wi, wo) = pairs[p];
        fn both<S: MicrosurfaceSlope, M: Material>(
            inv: Invariance<S, M>,
            wi: Vec3,
            wo: Vec3,
            rng: &mut TestRng,
        ) -> [[Stats; 3]; 2] {
            let mut st: [[Stats; 3]; 2] = Default::default();
            for _ in 0..N {
                let f = inv.eval(wi, wo, ScatteringOrder::All, rng).as_dvec3() / f64::from(wo.z);
                let g = inv.eval(wo, wi, ScatteringOrder::All, rng).as_dvec3() / f64::from(wi.z);
                for k in 0..3 {
                    st[0][k].push(f[k]);
                    st[1][k].push(g[k]);
                }
            }
            st
        }
        let gold = Conductor::new(ComplexIor::GOLD);
        match c {
            0 => both(Invariance::new(Ggx::isotropic(1.0).unwrap(), gold).unwrap(), wi, wo, &mut rng),
            1 => both(
                Invariance::new(Beckmann::isotropic(0.4).unwrap(), Conductor::perfect()).unwrap(),
                wi,
                wo,
                &mut rng,
            ),
            _ => both(Invariance::new(Ggx::new(0.2, 0.7).unwrap(), gold).unwrap(), wi, wo, &mut rng),
        }
    });
    let z = family_z(0.01, jobs.len() * 3);
    for (&(c, p), st) in jobs.iter().zip(&results) {
        for (k, (a, b)) in st[0].iter().zip(&st[1]).enumerate() {
            let l = format!("{} pair {p} channel {k}", configs[c]);
            let se = (a.se().powi(2) + b.se().powi(2)).sqrt();
            println!(
                "{l}: f(ωi, ωo) {:.5} ± {:.5}, f(ωo, ωi) {:.5} ± {:.5}, z = {:.2}",
                a.mean(),
                a.se(),
                b.mean(),
                b.se(),
                (a.mean() - b.mean()) / se
            );
            assert!(se <= 0.02 * a.mean().max(b.mean()), "{l}: not resolved");
            assert_two_sample(&l, a, b, z, f64::INFINITY);
        }
    }
}

/// White furnace: a perfect conductor reflects everything, ∫ f·cos θo dωo = 1 over all
/// orders, for GGX and Beckmann at α ∈ {0.2, 1, 3} and θi ∈ {0, 1.2, 1.5}: the mean of
/// eval/pdf (N = 20 000; 60 000 at α = 3, whose multiply scattered light is noisiest) within
/// z·SE of 1, SE ≤ 0.012. And every `sample` of it returns, with
/// weight 1 and a direction above the horizon (2 000 per case).
#[test]
fn white_furnace() {
    const N: usize = 20_000;
    let jobs: Vec<(bool, f32, f64)> = [false, true]
        .into_iter()
        .flat_map(|b| {
            [0.2f32, 1.0, 3.0].into_iter().flat_map(move |a| [0.0, 1.2, 1.5].map(move |t| (b, a, t)))
        })
        .collect();
    let results = par_map(&jobs, |i, &(beckmann, alpha, theta)| {
        let mut rng = validation::rng(0x4d2_0000 + i as u64);
        let wi = dir(theta, 0.3);
        let n = if alpha > 2.0 { 3 * N } else { N };
        fn furnace<S: MicrosurfaceSlope>(s: S, wi: Vec3, n: usize, rng: &mut TestRng) -> Stats {
            let inv = Invariance::new(s, Conductor::perfect()).unwrap();
            for _ in 0..2000 {
                let s = inv.sample(wi, rng).expect("a perfect mirror loses nothing");
                assert!(s.weight == Vec3::ONE && s.wo.z > 0.0 && s.wo.is_normalized(), "{s:?}");
            }
            let st = eval_albedos(&inv, wi, 0, n, rng);
            st[0][0]
        }
        if beckmann {
            furnace(Beckmann::isotropic(alpha).unwrap(), wi, n, &mut rng)
        } else {
            furnace(Ggx::isotropic(alpha).unwrap(), wi, n, &mut rng)
        }
    });
    let z = family_z(0.01, jobs.len());
    for (&(beckmann, alpha, theta), st) in jobs.iter().zip(&results) {
        let l = format!("{} α = {alpha}, θi = {theta}", if beckmann { "Beckmann" } else { "GGX" });
        println!(
            "{l}: N = {}, albedo {:.5} ± {:.5}, z = {:.2}",
            st.n,
            st.mean(),
            st.se(),
            (st.mean() - 1.0) / st.se()
        );
        assert_mean(&l, st, 1.0, z, 0.012, 0.0);
    }
}

// ---------------------------------------------------------------------------------------------
// The renderer technique, the rejected material, finiteness
// ---------------------------------------------------------------------------------------------

/// `Technique::Invariance` of a `MicrofacetBsdf` estimates the same BSDF as the random walk
/// (gold, GGX α = 0.6): f at three (wo, wi) pairs, N = 20 000 keyed evaluations each, within
/// z·SE of the walk technique's (two-sample, Šidák over 3 pairs × 3 channels), SE ≤ 2 % of f;
/// its samples' weights average to the walk technique's albedo.
#[test]
fn renderer_technique_estimates_the_walks_bsdf() {
    const N: u64 = 20_000;
    let gold = MicrofacetBsdf::new(Ggx::isotropic(0.6).unwrap(), Conductor::new(ComplexIor::GOLD)).unwrap();
    let inv = gold.with_technique(Technique::Invariance);
    assert_eq!(inv.technique(), Technique::Invariance);
    let pairs =
        [(dir(0.5, 0.0), dir(0.7, 3.0)), (dir(1.2, 0.0), dir(0.1, 1.0)), (dir(1.4, 0.2), dir(1.3, 1.5))];
    let z = family_z(0.01, 3 * 3 + 3);
    for (wo, wi) in pairs {
        let mut st: [[Stats; 3]; 2] = Default::default();
        for key in 0..N {
            for (b, s) in [&inv, &gold].into_iter().zip(st.iter_mut()) {
                let f = b.eval_keyed(wo, wi, key).f.as_dvec3();
                for (k, channel) in s.iter_mut().enumerate() {
                    channel.push(f[k]);
                }
            }
        }
        for (k, (a, b)) in st[0].iter().zip(&st[1]).enumerate() {
            let l = format!("wo = {wo}, wi = {wi}, channel {k}");
            assert!(a.se() <= 0.02 * b.mean(), "{l}: not resolved");
            assert_two_sample(&l, a, b, z, f64::INFINITY);
        }
    }
    let mut rng = validation::rng(77);
    let wo = dir(0.8, 0.0);
    let mut st: [Stats; 2] = Default::default();
    for _ in 0..40_000 {
        let (uc, u) = (rng.random::<f32>(), Vec2::new(rng.random::<f32>(), rng.random::<f32>()));
        for (b, s) in [&inv, &gold].into_iter().zip(st.iter_mut()) {
            let w = b.sample(wo, uc, u).map_or(0.0, |s| f64::from(s.weight.element_sum()) / 3.0);
            s.push(w);
        }
    }
    assert_two_sample("sampled albedo, Invariance against RandomWalk", &st[0], &st[1], z, 2e-3);
}

/// A dielectric is not covered: `Invariance::new` returns `Error::UnsupportedMaterial`, whose
/// message names the model; `with_technique(Technique::Invariance)` on a dielectric BSDF is a
/// contract violation (a debug assertion; in release builds the BSDF is unchanged).
#[test]
fn dielectrics_are_refused() {
    let glass = Dielectric::new(1.5).unwrap();
    let err = Invariance::new(Ggx::isotropic(0.5).unwrap(), glass).expect_err("a dielectric");
    assert!(matches!(err, Error::UnsupportedMaterial { model: "Invariance", .. }), "{err:?}");
    assert!(err.to_string().contains("Invariance"), "{err}");
    assert!(Invariance::new(Ggx::isotropic(0.5).unwrap(), Diffuse::white()).is_ok());
    let bsdf = MicrofacetBsdf::new(Ggx::isotropic(0.5).unwrap(), glass).unwrap();
    let result = std::panic::catch_unwind(|| bsdf.with_technique(Technique::Invariance));
    if cfg!(debug_assertions) {
        let payload = result.expect_err("a debug assertion");
        assert!(validation::check::panic_message(&*payload).starts_with("invalid input"));
    } else {
        assert_eq!(result.expect("no panic in release builds").technique(), Technique::RandomWalk);
    }
}

/// No NaN, infinity or panic over the crate's fuzz domain: α from 1e-4 to 10 and anisotropy
/// to 1e4 (GGX and Beckmann, gold and F = 1), views and lights on, near and below the horizon
/// with signed zeros (`validation::check::EDGE_VIEW_COSINES`, ±0 components) and uniform on
/// the sphere; `eval` (all orders and order 2) finite and ≥ 0, `sample` finite with a unit
/// direction above the horizon; and the renderer technique at the extreme uniforms (u = 0
/// and 1⁻, `assert_finite_at_edges`) and on the sphere (`assert_finite_on_sphere`).
#[test]
fn finite_over_the_fuzz_domain() {
    use validation::check::{EDGE_VIEW_COSINES, assert_finite_at_edges, assert_finite_on_sphere, edge_view};
    let roughness: [(f32, f32); 7] =
        [(1e-4, 1e-4), (1e-2, 1e-2), (0.5, 0.5), (10.0, 10.0), (1e-3, 10.0), (10.0, 1e-3), (1e-4, 1.0)];
    let mut directions: Vec<Vec3> = EDGE_VIEW_COSINES.iter().map(|&z| edge_view(z)).collect();
    directions.extend([
        Vec3::new(-0.0, 0.0, 1.0),
        Vec3::new(0.0, -0.0, -1.0),
        Vec3::new(1.0, 0.0, -0.0),
        Vec3::new(0.0, -1.0, 0.0),
        Vec3::new(-0.6, 0.0, 0.8),
        Vec3::new(0.0, 0.6, -0.8),
    ]);
    fn check<
        S: MicrosurfaceSlope + 'static,
        M: Material + microsurface::research::SpecularLimit + 'static,
    >(
        s: S,
        m: M,
        label: &str,
        directions: &[Vec3],
        rng: &mut TestRng,
    ) {
        let inv = Invariance::new(s, m).unwrap();
        let mut dirs = directions.to_vec();
        dirs.extend((0..24).map(|_| validation::uniform_sphere(rng)));
        for &wi in &dirs {
            for &wo in &dirs {
                for order in [ScatteringOrder::All, only(2)] {
                    let v = inv.eval(wi, wo, order, rng);
                    assert!(v.is_finite() && v.min_element() >= 0.0, "{label}: eval({wi}, {wo}) = {v}");
                }
            }
            for _ in 0..4 {
                if let Some(smp) = inv.sample(wi, rng) {
                    assert!(
                        smp.weight.is_finite() && smp.wo.is_normalized() && smp.wo.z > 0.0,
                        "{label}: sample({wi}) = {smp:?}"
                    );
                }
            }
        }
        let bsdf =
            MicrofacetBsdf::new(s, m).unwrap().without_smooth_limit().with_technique(Technique::Invariance);
        assert_finite_at_edges(&bsdf, &dirs, label);
        assert_finite_on_sphere(&bsdf, 200, rng, label);
    }
    let mut rng = validation::rng(0x5e5);
    for (ax, ay) in roughness {
        let gold = Conductor::new(ComplexIor::GOLD);
        let ggx = Ggx::new(ax, ay).unwrap();
        let beckmann = Beckmann::new(ax, ay).unwrap();
        check(ggx, gold, &format!("GGX ({ax}, {ay}) gold"), &directions, &mut rng);
        check(beckmann, Conductor::perfect(), &format!("Beckmann ({ax}, {ay}) F = 1"), &directions, &mut rng);
    }
}
