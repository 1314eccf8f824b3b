//! Energy-compensated conductors and dielectrics (`Compensated`): the sampler against its density
//! (chi-square), the sample weights against eval·cos/pdf, the white furnace (F = 1) within the
//! albedo tables' interpolation error, the normalization of the Kulla–Conty lobe, its
//! reciprocity, and the constructor's range.

use microsurface::compensation::{
    ALBEDO_DIRECTIONS, ALBEDO_ROUGHNESSES, AlbedoTable, AlbedoTabulated, ORDER_TABLE_SIZE, ORDER_TABLES,
};
use microsurface::glam::{Vec2, Vec3};
use microsurface::research::Side;
use microsurface::{
    Beckmann, Bsdf, Compensated, Compensation, ComplexIor, Conductor, Dielectric, Ggx, Transport,
};
use validation::check::{assert_finite_at_edges, assert_finite_on_sphere, assert_side_flags, draw};
use validation::chi2::{BsdfChi2, sampler_chi2};
use validation::quadrature::{Domain, integrate_sphere};
use validation::{Stats, assert_mean, dir, family_z, sidak, uniform32};

/// The tables' largest interpolation error of E (measured by the generator's dense check,
/// `AlbedoTable`).
const TABLE_ERROR_GGX: f64 = 1.9e-4;
const TABLE_ERROR_BECKMANN: f64 = 6.8e-4;

fn ggx(a: f32) -> Ggx {
    Ggx::isotropic(a).unwrap()
}

fn beckmann(a: f32) -> Beckmann {
    Beckmann::isotropic(a).unwrap()
}

fn gold() -> Conductor {
    Conductor::new(ComplexIor::GOLD)
}

/// |a − b| ≤ rel·max(|a|, |b|), or both below the normal f32 range (subnormal values carry
/// no relative precision).
fn rel_close(a: Vec3, b: Vec3, rel: f32) -> bool {
    let scale = a.abs().max(b.abs()).max_element();
    validation::check::rel_close(a, b, rel) || scale < f32::MIN_POSITIVE
}

/// The chi-square cases: (label, BSDF, θo).
fn chi2_cases() -> Vec<(String, Box<dyn Bsdf>, f64)> {
    let mut v: Vec<(String, Box<dyn Bsdf>, f64)> = vec![];
    let kc = Compensation::KullaConty;
    for (a, theta, scheme) in [(0.3f32, 0.5f64, kc), (1.0, 1.3, Compensation::Turquin)] {
        v.push((
            format!("{scheme:?} GGX gold α = {a} θo = {theta}"),
            Box::new(Compensated::with_scheme(ggx(a), gold(), scheme).unwrap()),
            theta,
        ));
    }
    for (a, theta) in [(0.08f32, 1.4f64), (1.0, 0.3)] {
        v.push((
            format!("KullaConty Beckmann gold α = {a} θo = {theta}"),
            Box::new(Compensated::with_scheme(beckmann(a), gold(), kc).unwrap()),
            theta,
        ));
    }
    // the per-order lobe (its own per-channel profile, the Kulla–Conty sampler)
    let copper = Conductor::new(ComplexIor::COPPER);
    let aluminium = Conductor::new(ComplexIor::ALUMINIUM);
    v.push((
        "Walk GGX copper α = 0.8 θo = 0.7".into(),
        Box::new(Compensated::with_scheme(ggx(0.8), copper, Compensation::Walk).unwrap()),
        0.7,
    ));
    v.push((
        "Walk Beckmann aluminium α = 0.4 θo = 1.2".into(),
        Box::new(Compensated::with_scheme(beckmann(0.4), aluminium, Compensation::Walk).unwrap()),
        1.2,
    ));
    // anisotropic slopes (the tables at √(αx αy)): the sampler is still exact
    v.push((
        "KullaConty GGX gold αx = 0.2, αy = 0.8".into(),
        Box::new(
            Compensated::with_scheme(Ggx::new(0.2, 0.8).unwrap(), gold(), Compensation::KullaConty).unwrap(),
        ),
        0.9,
    ));
    v
}

/// `sample` against `pdf` (chi-square, 20 × 40 cells of the sphere, 100 000 samples, family-wise
/// level 1 % over the cases); every sample has an exact pdf equal to `pdf(wo, wi)` and a weight
/// equal to eval·cos θi/pdf (relative 1e-4); the sampler refuses (reflections below the
/// horizon) exactly the mass 1 − ∫pdf (binomial, z·SE + the quadrature's 1e-3).
#[test]
fn sample_matches_pdf_and_weights_match_eval() {
    let cases = chi2_cases();
    let alpha = sidak(0.01, cases.len());
    let z = family_z(0.01, cases.len());
    for (k, (label, b, theta)) in cases.iter().enumerate() {
        // (the single-scattering lobe's reflections below the horizon are refused: ∫pdf < 1)
        let each = |s: &microsurface::BsdfSample| {
            assert!(s.flags.reflection && !s.flags.specular, "{label}: flags {:?}", s.flags);
        };
        let mut rng = validation::rng(1600 + k as u64);
        let settings = BsdfChi2::sphere(100_000, 1e-4, 6, 1e-6);
        sampler_chi2(label, b.as_ref(), dir(*theta, 0.4), settings, &mut rng, each, alpha, z);
    }
}

/// The white furnace: with F = 1 the mean sample weight (the albedo ∫ f cos dωi, unbiased given
/// the chi-square and weight tests) is 1 within z·SE plus the table's interpolation error ε
/// (Kulla–Conty: albedo − 1 = E_exact(μo) − E_table(μo); Turquin: E_exact/E_table − 1, so
/// ε/E_table(μo)), for α ∈ {0.05, 0.2, 0.5, 1} and μo ∈ {0.1, 0.4, 0.7, 1}, both families and
/// both schemes (64 cases, family-wise level 1 %; each asserts SE ≤ 2e-3 for Kulla–Conty (its σ̂ ≈ 0.45 comes from the refused single-scattering samples below the horizon) and 5e-3 for Turquin, N = 80 000).
#[test]
fn white_furnace_within_table_error() {
    let alphas = [0.05f32, 0.2, 0.5, 1.0];
    let mus = [0.1f32, 0.4, 0.7, 1.0];
    let z = family_z(0.01, 64);
    let n = 80_000;
    let mut worst: f64 = 0.0;
    #[allow(clippy::too_many_arguments)]
    fn run<S: AlbedoTabulated>(
        slope: S,
        table: AlbedoTable,
        eps: f64,
        mu: f32,
        n: usize,
        z: f64,
        seed: u64,
        worst: &mut f64,
    ) {
        let alpha = slope.alpha_x();
        for scheme in [Compensation::KullaConty, Compensation::Turquin] {
            let b = Compensated::with_scheme(slope, Conductor::perfect(), scheme).unwrap();
            let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
            let mut rng = validation::rng(seed + u64::from(scheme == Compensation::Turquin));
            let mut stats = Stats::default();
            for _ in 0..n {
                stats.push(draw(&b, wo, &mut rng).map_or(0.0, |s| f64::from(s.weight.x)));
            }
            let e_table = f64::from(table.directional(mu, alpha).unwrap());
            let tol = match scheme {
                // (the per-order lobe is Kulla–Conty's for F = 1: `per_order_is_kulla_conty_for_f1`)
                Compensation::KullaConty | Compensation::Walk => eps,
                Compensation::Turquin => eps / e_table,
            };
            let label = format!("white furnace {} {scheme:?} α = {alpha} μo = {mu}", table.name());
            // Turquin's weights are the single-scattering weights over E(μo) (up to 3.3 at α = 1)
            let max_se = if scheme == Compensation::KullaConty { 2e-3 } else { 5e-3 };
            assert_mean(&label, &stats, 1.0, z, max_se, tol);
            println!("{label}: mean {:.5}, SE {:.1e}, tol {tol:.1e}", stats.mean(), stats.se());
            *worst = worst.max((stats.mean() - 1.0).abs());
        }
    }
    let mut seed = 1700;
    for &a in &alphas {
        for &mu in &mus {
            run(ggx(a), AlbedoTable::GGX, TABLE_ERROR_GGX, mu, n, z, seed, &mut worst);
            run(beckmann(a), AlbedoTable::BECKMANN, TABLE_ERROR_BECKMANN, mu, n, z, seed + 2, &mut worst);
            seed += 4;
        }
    }
    println!("white furnace: largest |albedo − 1| = {worst:.2e} (N = {n} per case, z = {z:.2})");
}

/// The Kulla–Conty lobe f_KC − f_ss integrates to F_ms (1 − E(μo)) over the hemisphere (by
/// adaptive quadrature, to 2e-5 relative + 1e-6; the E_avg it is normalized by is the exact average
/// of the interpolated E), for gold (coloured F_ms) and F = 1 (F_ms = 1).
#[test]
fn kulla_conty_lobe_is_normalized() {
    for (a, mu) in [(0.1f32, 0.3f32), (0.5, 0.8), (1.0, 0.05), (1.0, 1.0)] {
        for (name, conductor) in [("gold", gold()), ("F = 1", Conductor::perfect())] {
            let b = Compensated::with_scheme(ggx(a), conductor, Compensation::KullaConty).unwrap();
            let ss = *b.single_scattering();
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            // the channels' sum (each channel's F_ms comes from the same formula)
            let lobe = integrate_sphere(
                &mut |w| f64::from((b.eval(wo, w).f - ss.eval(wo, w).f).element_sum() * w.z),
                8,
                16,
                Domain::UpperHemisphere,
                1e-6,
                6,
            );
            let c_o = 1.0 - f64::from(b.directional_albedo(mu).unwrap());
            let fms = b.fresnel_multiple_scattering();
            if name == "F = 1" {
                assert!((fms - Vec3::ONE).abs().max_element() < 1e-6, "F_ms = {fms} for F = 1");
            }
            let expected = f64::from(fms.element_sum()) * c_o;
            assert!(
                (lobe - expected).abs() <= 2e-5 * expected + 1e-6,
                "{name} α = {a} μo = {mu}: ∫ Σ f_ms cos = {lobe:.7e}, Σ F_ms (1 − E) = {expected:.7e}"
            );
        }
    }
}

/// The per-order lobe's albedo at a node of the order tables (μ at x = i/31, α at r = j/31,
/// also a node of the albedo table, where the lobe's interpolation is exact) is the documented
/// model g = (1 − E) Σ_k e_k F̄^k/Σ_k e_k (the orders above 6 placed at order 7), computed here
/// from the raw nodes of the tables (relative 1e-4: the f32 round trip of μ), and the lobe
/// f_ms = f − f_ss integrates to it (adaptive quadrature of the channels weighted 1, 2, 4;
/// 2e-5 relative + 1e-6), for gold and aluminium, GGX and Beckmann.
#[test]
fn per_order_lobe_has_the_model_albedo() {
    fn run<S: AlbedoTabulated>(
        slope_of: impl Fn(f32) -> S,
        table: AlbedoTable,
        orders: microsurface::compensation::ScatteringOrderTable,
    ) {
        let n = ORDER_TABLE_SIZE;
        // the albedo table's node of an order node: x = i/31 = (i·93/31)/93, r = j/31 = (j·62/31)/62
        let (sx, sr) = ((ALBEDO_DIRECTIONS - 1) / (n - 1), (ALBEDO_ROUGHNESSES - 1) / (n - 1));
        for (name, conductor) in [("gold", gold()), ("aluminium", Conductor::new(ComplexIor::ALUMINIUM))] {
            for (i, j) in [(8usize, 31usize), (20, 17), (29, 25), (31, 10)] {
                let r = j as f64 / (n - 1) as f64;
                let alpha = (r * r) as f32;
                let x2 = (i as f64 / (n - 1) as f64).powi(2);
                let mu = if i == n - 1 {
                    1.0
                } else {
                    (x2 * f64::from(alpha) / (1.0 + f64::from(alpha) - x2)) as f32
                };
                let b = Compensated::with_scheme(slope_of(alpha), conductor, Compensation::Walk).unwrap();
                let got = b.multiple_scattering_albedo(mu).unwrap();
                let node = j * n + i;
                let e: Vec<f64> =
                    (0..ORDER_TABLES).map(|t| f64::from(orders.directional_nodes(t)[node])).collect();
                let total: f64 = e.iter().sum();
                let c = 1.0 - f64::from(table.directional_nodes()[j * sr * ALBEDO_DIRECTIONS + i * sx]);
                let f_avg = b.fresnel_average();
                for ch in 0..3 {
                    let fb = f64::from(f_avg[ch]);
                    // orders 2 … 6, and the tail at order 7
                    let w: f64 = (0..ORDER_TABLES).map(|t| e[t] * fb.powi(t as i32 + 2)).sum();
                    let expected = if total > 0.0 { c * w / total } else { c * fb * fb };
                    let g = f64::from(got[ch]);
                    assert!(
                        (g - expected).abs() <= 1e-4 * expected + 1e-7,
                        "{} {name} node ({i}, {j}) channel {ch}: lobe albedo {g:.6e}, model {expected:.6e}",
                        table.name()
                    );
                }
                // one integral of the channels weighted 1, 2, 4 (a channel's error cannot hide)
                let weights = Vec3::new(1.0, 2.0, 4.0);
                let ss = *b.single_scattering();
                let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
                let lobe = integrate_sphere(
                    &mut |w| f64::from((b.eval(wo, w).f - ss.eval(wo, w).f).dot(weights) * w.z),
                    8,
                    16,
                    Domain::UpperHemisphere,
                    1e-6,
                    6,
                );
                let g = f64::from(got.dot(weights));
                assert!(
                    (lobe - g).abs() <= 2e-5 * g + 1e-6,
                    "{} {name} α = {alpha} μo = {mu}: ∫ f_ms cos · (1, 2, 4) = {lobe:.7e}, g(μo) · (1, 2, 4) = {g:.7e}",
                    table.name()
                );
            }
        }
    }
    run(ggx, AlbedoTable::GGX, microsurface::compensation::ScatteringOrderTable::GGX);
    run(beckmann, AlbedoTable::BECKMANN, microsurface::compensation::ScatteringOrderTable::BECKMANN);
}

/// For F = 1 (F̄ = 1) the per-order lobe is the Kulla–Conty lobe: the same f to relative 1e-5
/// (their arithmetic differs in rounding only), on random pairs at every roughness row of the
/// albedo table (α = (j/62)², every second one a row of the order tables, where the lobe is
/// built from one row alone, so that a node the walk recorded as e₆ = 0 with a tail > 0 is met
/// as it is) and between rows, GGX and Beckmann.
#[test]
fn per_order_is_kulla_conty_for_f1() {
    fn run<S: AlbedoTabulated>(name: &str, slope_of: impl Fn(f32) -> S, seed: u64) {
        let mut rng = validation::rng(seed);
        let last = (ALBEDO_ROUGHNESSES - 1) as f32;
        let rows = (1..ALBEDO_ROUGHNESSES).map(|j| (j as f32 / last).powi(2));
        for a in rows.chain([0.05f32, 0.3]) {
            let kc = Compensated::with_scheme(slope_of(a), Conductor::perfect(), Compensation::KullaConty)
                .unwrap();
            let po = Compensated::with_scheme(slope_of(a), Conductor::perfect(), Compensation::Walk).unwrap();
            for _ in 0..100 {
                let mut d = || {
                    let z = uniform32(&mut rng);
                    dir(f64::from(z).acos(), std::f64::consts::TAU * f64::from(uniform32(&mut rng)))
                };
                let (wo, wi) = (d(), d());
                let (f, g) = (kc.eval(wo, wi).f, po.eval(wo, wi).f);
                assert!(
                    rel_close(f, g, 1e-5),
                    "{name} α = {a}: Kulla–Conty {f}, per-order {g} at wo = {wo}, wi = {wi}"
                );
                assert_eq!(kc.pdf(wo, wi), po.pdf(wo, wi), "{name} α = {a}: the samplers differ");
            }
        }
    }
    run("GGX", ggx, 1850);
    run("Beckmann", beckmann, 1851);
}

/// No non-finite value from any compensated conductor on a roughness scan: every row of the
/// albedo table, α = (j/62)², where a lobe is built from one row's nodes alone, and 64
/// roughnesses between and across them; five metals (F = 1 among them), all three schemes, GGX
/// and Beckmann, 40 random pairs each (a node of the order tables with e₆ = 0 and a tail once
/// made the per-order lobe of F = 1 NaN: DESIGN.md, “Per-order conductor tables”).
#[test]
fn every_compensated_conductor_is_finite_on_a_roughness_scan() {
    let mut rng = validation::rng(1852);
    let last = (ALBEDO_ROUGHNESSES - 1) as f32;
    let alphas: Vec<f32> = (1..ALBEDO_ROUGHNESSES)
        .map(|j| (j as f32 / last).powi(2))
        .chain((1..=64).map(|k| (k as f32 / 64.0).powi(2)))
        .collect();
    let metals = [
        ("F = 1", Conductor::perfect()),
        ("gold", gold()),
        ("copper", Conductor::new(ComplexIor::COPPER)),
        ("aluminium", Conductor::new(ComplexIor::ALUMINIUM)),
        ("silver", Conductor::new(ComplexIor::SILVER)),
    ];
    for &a in &alphas {
        for (name, c) in metals {
            for scheme in [Compensation::KullaConty, Compensation::Turquin, Compensation::Walk] {
                let b = Compensated::with_scheme(ggx(a), c, scheme).unwrap();
                assert_finite_on_sphere(&b, 40, &mut rng, &format!("GGX {name} {scheme:?} α = {a}"));
                let b = Compensated::with_scheme(beckmann(a), c, scheme).unwrap();
                assert_finite_on_sphere(&b, 40, &mut rng, &format!("Beckmann {name} {scheme:?} α = {a}"));
            }
        }
    }
}

/// F_avg from its table over the complex index equals a 20 000-step midpoint rule to 2e-5 for
/// the metal presets (the table's stated error; `fresnel_average.rs` measures it against a
/// 1024-point quadrature over the whole index plane).
#[test]
fn fresnel_average_is_accurate() {
    for ior in [ComplexIor::GOLD, ComplexIor::COPPER, ComplexIor::ALUMINIUM, ComplexIor::SILVER] {
        let c = Conductor::new(ior);
        let b = Compensated::with_scheme(ggx(0.5), c, Compensation::KullaConty).unwrap();
        let n = 20_000;
        let mut reference = [0.0f64; 3];
        for k in 0..n {
            let mu = (k as f64 + 0.5) / n as f64;
            let f = c.fresnel(mu as f32);
            for (ch, r) in reference.iter_mut().enumerate() {
                *r += 2.0 * f64::from(f[ch]) * mu / n as f64;
            }
        }
        let got = b.fresnel_average();
        for ch in 0..3 {
            assert!(
                (f64::from(got[ch]) - reference[ch]).abs() < 2e-5,
                "{ior:?}: F_avg {got} vs {reference:?}"
            );
        }
    }
}

/// Kulla–Conty and the per-order lobe are reciprocal: f(ωo, ωi) = f(ωi, ωo) (relative 1e-4, the single-scattering
/// lobe's f32 rounding), on 2000 random pairs of upper-hemisphere directions per case.
#[test]
fn kulla_conty_is_reciprocal() {
    let mut rng = validation::rng(1800);
    for (a, scheme) in
        [0.05f32, 0.3, 1.0].into_iter().flat_map(|a| [(a, Compensation::KullaConty), (a, Compensation::Walk)])
    {
        let b = Compensated::with_scheme(beckmann(a), gold(), scheme).unwrap();
        for _ in 0..2000 {
            let mut d = || {
                let z = uniform32(&mut rng);
                let phi = std::f64::consts::TAU * f64::from(uniform32(&mut rng));
                dir(f64::from(z).acos(), phi)
            };
            let (wo, wi) = (d(), d());
            if wo.z <= 0.0 || wi.z <= 0.0 {
                continue;
            }
            let (f, g) = (b.eval(wo, wi).f, b.eval(wi, wo).f);
            assert!(
                rel_close(f, g, 1e-4),
                "{scheme:?} α = {a}: f(wo, wi) = {f}, f(wi, wo) = {g} at wo = {wo}, wi = {wi}"
            );
        }
    }
}

/// The constructor rejects √(αx αy) > 1 (beyond the tables), accepts the range's end and an
/// anisotropic surface inside it; smooth surfaces are the single-scattering Dirac mirror.
#[test]
fn constructor_range_and_smooth_limit() {
    for (ax, ay) in [(1.01f32, 1.01f32), (2.0, 0.6), (5.0, 5.0)] {
        let r = Compensated::with_scheme(Ggx::new(ax, ay).unwrap(), gold(), Compensation::KullaConty);
        assert!(
            matches!(r, Err(microsurface::Error::InvalidParameter { name: "alpha", .. })),
            "αx = {ax}, αy = {ay}: {r:?}"
        );
    }
    assert!(Compensated::with_scheme(ggx(1.0), gold(), Compensation::Turquin).is_ok());
    let aniso =
        Compensated::with_scheme(Ggx::new(2.0, 0.25).unwrap(), gold(), Compensation::KullaConty).unwrap();
    assert!((aniso.table_alpha() - 0.5f32.sqrt()).abs() < 1e-6);
    let smooth = Compensated::with_scheme(ggx(1e-4), gold(), Compensation::KullaConty).unwrap();
    assert!(smooth.flags().specular);
    let wo = dir(0.5, 0.0);
    assert_eq!(
        smooth.sample(wo, 0.3, Vec2::new(0.2, 0.7)),
        smooth.single_scattering().sample(wo, 0.3, Vec2::new(0.2, 0.7))
    );
    assert_eq!(smooth.pdf(wo, Vec3::Z), 0.0);
}

/// Backfacing views (a shading normal turned away) have no table: the lobe is the
/// single-scattering lobe, bit for bit.
#[test]
fn backfacing_views_are_single_scattering() {
    let b = Compensated::with_scheme(ggx(0.4), gold(), Compensation::KullaConty).unwrap();
    let ss = *b.single_scattering();
    let wo = dir(1.8, 0.3);
    let mut rng = validation::rng(1900);
    for _ in 0..200 {
        let uc = uniform32(&mut rng);
        let u = Vec2::new(uniform32(&mut rng), uniform32(&mut rng));
        assert_eq!(b.sample(wo, uc, u), ss.sample(wo, uc, u));
        let wi = dir(f64::from(uniform32(&mut rng)) * 1.5, 2.0);
        assert_eq!(b.eval_with_pdf(wo, wi), ss.eval_with_pdf(wo, wi));
    }
}

/// Invalid arguments (NaN, non-unit or zero directions; uniforms outside [0, 1]) trip the debug
/// assertion in debug builds and give the documented nothing in release builds: f = 0, pdf = 0,
/// `None`.
#[test]
fn invalid_input_gives_nothing() {
    let ok = dir(0.5, 0.2);
    let bad = [Vec3::NAN, Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, Vec3::new(f32::INFINITY, 0.0, 1.0)];
    for scheme in [Compensation::KullaConty, Compensation::Turquin, Compensation::Walk] {
        let b = Compensated::with_scheme(ggx(0.4), gold(), scheme).unwrap();
        let check = |label: &str, call: &dyn Fn() -> bool| {
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(call));
            if cfg!(debug_assertions) {
                assert!(r.is_err(), "{scheme:?} {label}: no debug assertion");
            } else {
                assert!(r.expect("no panic in release"), "{scheme:?} {label}: not nothing");
            }
        };
        for w in bad {
            check("eval(bad, ok)", &|| b.eval(w, ok).f == Vec3::ZERO);
            check("eval(ok, bad)", &|| b.eval(ok, w).f == Vec3::ZERO);
            check("pdf(bad, ok)", &|| b.pdf(w, ok) == 0.0);
            check("pdf(ok, bad)", &|| b.pdf(ok, w) == 0.0);
            check("eval_with_pdf(ok, bad)", &|| {
                b.eval_with_pdf(ok, w) == (microsurface::BsdfValue::ZERO, 0.0)
            });
            check("sample(bad)", &|| b.sample(w, 0.5, Vec2::splat(0.5)).is_none());
        }
        // (a uniform of exactly 1 is valid: tests/invalid_input/renderer.rs)
        let above_one = 1.0 + f32::EPSILON;
        for (uc, u) in
            [(above_one, Vec2::splat(0.5)), (0.5, Vec2::new(f32::NAN, 0.2)), (-0.1, Vec2::splat(0.5))]
        {
            check("sample(uniforms)", &|| b.sample(ok, uc, u).is_none());
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Compensated dielectrics with Turquin's scaling
// ---------------------------------------------------------------------------------------------

/// The dielectric tables' measured interpolation error of R + T (max at 256 random points,
/// `cargo run --release -p tools --bin tables -- --interpolation --only dielectric`), per family
/// (GGX, Beckmann) and side (outside, inside).
const DIELECTRIC_TABLE_ERROR: [[f64; 2]; 2] = [[4.80e-2, 6.17e-2], [7.50e-2, 1.30e-1]];
/// The error of E at a node: quadrature 1e-5 (checked by the generator) and the f32 rounding
/// of the node's coordinates 2e-5 (`tests/albedo.rs`).
const NODE_ERROR: f64 = 3e-5;

/// The dielectric tables' axis blend B(v) = ½ ln(v/vf)/ln(1/vf) + ½ (√v − √vf)/(1 − √vf),
/// vf = 1e-6.
fn blend(v: f64) -> f64 {
    let floor = 1e-6f64;
    let v = v.max(floor);
    0.5 * (v / floor).ln() / (1.0 / floor).ln() + 0.5 * (v.sqrt() - floor.sqrt()) / (1.0 - floor.sqrt())
}

/// The v ∈ [1e-6, 1] at which the increasing f reaches b (bisection in ln v).
fn inverse(f: impl Fn(f64) -> f64, b: f64) -> f64 {
    let (mut lo, mut hi) = (1e-6f64.ln(), 0.0f64);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if f(mid.exp()) < b {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (0.5 * (lo + hi)).exp()
}

/// B⁻¹.
fn blend_inverse(b: f64) -> f64 {
    inverse(blend, b)
}

fn glass(eta: f32) -> Dielectric {
    Dielectric::new(eta).unwrap()
}

/// `sample` against `pdf` over the whole sphere (reflection and transmission; chi-square,
/// 20 × 40 cells, 100 000 samples, family-wise level 1 %), views from both sides; every sample
/// has an exact pdf equal to `pdf(wo, wi)`, the flags of its side, and a weight equal to
/// eval·|cos θi|/pdf (relative 1e-4); the sampler refuses exactly the mass 1 − ∫pdf.
#[test]
fn dielectric_sample_matches_pdf_and_weights_match_eval() {
    let cases: Vec<(String, Box<dyn Bsdf>, f64)> = vec![
        (
            "GGX glass η = 1.5 α = 0.3 θo = 0.5".into(),
            Box::new(Compensated::with_scheme(ggx(0.3), glass(1.5), Compensation::Turquin).unwrap()),
            0.5,
        ),
        (
            "GGX glass η = 1.5 α = 0.8 θo = 2.2 (inside)".into(),
            Box::new(Compensated::with_scheme(ggx(0.8), glass(1.5), Compensation::Turquin).unwrap()),
            2.2,
        ),
        (
            "Beckmann η = 2.5 α = 0.5 θo = 1.2, importance".into(),
            Box::new(
                Compensated::with_scheme(beckmann(0.5), glass(2.5), Compensation::Turquin)
                    .unwrap()
                    .with_transport(Transport::Importance),
            ),
            1.2,
        ),
    ];
    let alpha = sidak(0.01, cases.len());
    let z = family_z(0.01, cases.len());
    for (k, (label, b, theta)) in cases.iter().enumerate() {
        let wo = dir(*theta, 0.4);
        let each = |s: &microsurface::BsdfSample| {
            assert_side_flags(label, wo, s);
        };
        let mut rng = validation::rng(2600 + k as u64);
        let settings = BsdfChi2::sphere(100_000, 1e-4, 6, 1e-6);
        sampler_chi2(label, b.as_ref(), wo, settings, &mut rng, each, alpha, z);
    }
}

/// The white furnace of non-absorbing glass at the tables' nodes: with importance transport the
/// mean sample weight (∫ f |cos θi| dωi over the sphere, reflection and transmission) is 1
/// within z·SE plus the nodes' error relative to E (quadrature 1e-5, f32 coordinates 2e-5); with
/// radiance transport the same uniforms give the same samples, and weight × `eta`² is the
/// importance weight (flux is conserved, radiance is scaled by the squared index ratio).
/// At nodes because between them the dielectric tables interpolate poorly (up to 0.55 in R + T,
/// `DESIGN.md`): this checks the compensation itself. α at r = j/15 for j ∈ {5, 10, 15}, η at
/// u = l/15 for l ∈ {7, 12} (η = 1.44, 2.28), μo at x = i/15 for i ∈ {4, 9, 14}, views from
/// outside and inside, both families (72 cases, family-wise level 1 %, N = 160 000,
/// SE ≤ 1e-2: σ̂ reaches 2.4 at α = 1, μo = 0.037, where 1/E is large). Left out: η = 1.08 (l = 3), whose weights 1/E at grazing views have σ̂ up to 7
/// (α = 1, μo = 0.037), more than a fast test can average.
#[test]
fn dielectric_white_furnace_at_the_nodes() {
    let z = family_z(0.01, 72);
    let n = 160_000;
    let mut worst: f64 = 0.0;
    let mut seed = 2700;
    fn run<S: AlbedoTabulated>(
        slope: S,
        eta: f32,
        mus: [f32; 2],
        n: usize,
        z: f64,
        seed: u64,
        worst: &mut f64,
    ) {
        let alpha = slope.alpha_x();
        let imp = Compensated::with_scheme(slope, glass(eta), Compensation::Turquin)
            .unwrap()
            .with_transport(Transport::Importance);
        let rad = imp.with_transport(Transport::Radiance);
        for above in [true, false] {
            let mu = mus[usize::from(!above)];
            let s = (1.0 - mu * mu).max(0.0).sqrt();
            let wo = Vec3::new(s, 0.0, if above { mu } else { -mu });
            let mut rng = validation::rng(seed + u64::from(above));
            let mut stats = Stats::default();
            for _ in 0..n {
                let uc = uniform32(&mut rng);
                let u = Vec2::new(uniform32(&mut rng), uniform32(&mut rng));
                let a = imp.sample(wo, uc, u);
                let b = rad.sample(wo, uc, u);
                // (one of the two may drop a grazing sample whose f is subnormal in its scaling)
                if let (Some(a), Some(b)) = (a, b) {
                    assert_eq!(a.wi, b.wi, "radiance and importance sample alike");
                    assert!(rel_close(a.weight, b.weight * (b.eta * b.eta), 1e-5), "{a:?} vs {b:?}");
                }
                stats.push(a.map_or(0.0, |x| f64::from(x.weight.x)));
            }
            let e_table = f64::from(imp.directional_albedo(mu, side_of(above)).unwrap());
            let tol = NODE_ERROR / e_table;
            let label = format!(
                "dielectric white furnace {} α = {alpha} η = {eta} μo = {mu} {}",
                S::ALBEDO.name(),
                if above { "outside" } else { "inside" }
            );
            assert_mean(&label, &stats, 1.0, z, 1e-2, tol);
            *worst = worst.max((stats.mean() - 1.0).abs());
        }
    }
    // the nodes (x, r, u) = (i, j, l)/15 of the tables' axes (`DielectricAlbedoTable`):
    // α = B⁻¹(r), η = 1 + 2u³, μ = B⁻¹(x) from outside and on the knee axis from inside
    for j in [5u32, 10, 15] {
        let alpha = blend_inverse(f64::from(j) / 15.0) as f32;
        // (i = 7: μ = 0.033 from outside; below, the weights' SE at α = 1 exceeds 1e-2)
        for i in [7u32, 9, 14] {
            let x = f64::from(i) / 15.0;
            for l in [9u32, 12] {
                let eta = 1.0 + 2.0 * (f64::from(l) / 15.0).powi(3);
                let mu_c = (1.0 - 1.0 / (eta * eta)).sqrt();
                let knee = 7.0 / 15.0;
                let inside = if x <= knee {
                    mu_c * inverse(|t| 0.5 * blend(t) + 0.5 * (1.0 - (1.0 - t).max(0.0).sqrt()), x / knee)
                } else {
                    let s = (x - knee) / (1.0 - knee);
                    mu_c + (1.0 - mu_c) * s * s
                };
                let mus = [blend_inverse(x) as f32, inside.min(1.0) as f32];
                let eta = eta as f32;
                run(ggx(alpha), eta, mus, n, z, seed, &mut worst);
                run(beckmann(alpha), eta, mus, n, z, seed + 2, &mut worst);
                seed += 4;
            }
        }
    }
    println!("dielectric white furnace: largest |albedo − 1| = {worst:.2e} (N = {n} per case, z = {z:.2})");
}

/// The white furnace of glass between the nodes: the mean weight minus 1 is within z·SE plus
/// the tables' measured interpolation error of R + T relative to E (`DESIGN.md`: 0.048 GGX and
/// 0.075 Beckmann from outside, 0.062 / 0.13 from inside), at the glass of the README's table
/// (η = 1.5, α ∈ {0.1, 0.5}, μo ∈ {0.3, 0.8}).
#[test]
fn dielectric_white_furnace_between_the_nodes() {
    let z = family_z(0.01, 16);
    let n = 40_000;
    let mut seed = 2900;
    for (family, err) in [(0usize, DIELECTRIC_TABLE_ERROR[0]), (1, DIELECTRIC_TABLE_ERROR[1])] {
        for a in [0.1f32, 0.5] {
            for mu in [0.3f32, 0.8] {
                let b: Compensated<Ggx, Dielectric> =
                    Compensated::with_scheme(ggx(a), glass(1.5), Compensation::Turquin).unwrap();
                let bb: Compensated<Beckmann, Dielectric> =
                    Compensated::with_scheme(beckmann(a), glass(1.5), Compensation::Turquin).unwrap();
                for above in [true, false] {
                    let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, if above { mu } else { -mu });
                    let mut rng = validation::rng(seed);
                    seed += 1;
                    let mut stats = Stats::default();
                    let e_table = if family == 0 {
                        b.directional_albedo(mu, side_of(above))
                    } else {
                        bb.directional_albedo(mu, side_of(above))
                    };
                    for _ in 0..n {
                        let s = if family == 0 {
                            draw(&b.with_transport(Transport::Importance), wo, &mut rng)
                        } else {
                            draw(&bb.with_transport(Transport::Importance), wo, &mut rng)
                        };
                        stats.push(s.map_or(0.0, |x| f64::from(x.weight.x)));
                    }
                    let e_table = f64::from(e_table.unwrap());
                    let label = format!("glass furnace family {family} α = {a} μo = {mu} above {above}");
                    assert_mean(&label, &stats, 1.0, z, 5e-3, err[usize::from(!above)] / e_table);
                    println!("{label}: mean {:.4}, SE {:.1e}", stats.mean(), stats.se());
                }
            }
        }
    }
}

/// The constructor rejects √(αx αy) > 1 and η outside [1/3, 3] (beyond the tables) with the
/// parameter's name, accepts the ends of the range; smooth surfaces are the single-scattering
/// Dirac lobes.
#[test]
fn dielectric_constructor_range_and_smooth_limit() {
    for (ax, ay) in [(1.01f32, 1.01f32), (2.0, 0.6)] {
        let r = Compensated::with_scheme(Ggx::new(ax, ay).unwrap(), glass(1.5), Compensation::Turquin);
        assert!(matches!(r, Err(microsurface::Error::InvalidParameter { name: "alpha", .. })), "{r:?}");
    }
    for eta in [3.01f32, 0.33, 10.0] {
        let r = Compensated::with_scheme(ggx(0.5), glass(eta), Compensation::Turquin);
        assert!(
            matches!(r, Err(microsurface::Error::InvalidParameter { name: "eta", .. })),
            "η = {eta}: {r:?}"
        );
    }
    for eta in [3.0f32, 1.0 / 3.0, 1.0, 1.0001] {
        assert!(Compensated::with_scheme(ggx(1.0), glass(eta), Compensation::Turquin).is_ok(), "η = {eta}");
    }
    let smooth = Compensated::with_scheme(ggx(1e-4), glass(1.5), Compensation::Turquin).unwrap();
    assert!(smooth.flags().specular);
    let wo = dir(0.5, 0.0);
    assert_eq!(
        smooth.sample(wo, 0.3, Vec2::new(0.2, 0.7)),
        smooth.single_scattering().sample(wo, 0.3, Vec2::new(0.2, 0.7))
    );
}

/// No NaN or infinity at the edges: η near 1 at grazing views (E → 0), views on the horizon,
/// the extreme uniforms.
#[test]
fn dielectric_edges_are_finite() {
    for eta in [1.0001f32, 1.01, 1.0 / 1.01, 3.0, 1.0 / 3.0] {
        for a in [1e-3f32, 0.1, 1.0] {
            let b = Compensated::with_scheme(ggx(a), glass(eta), Compensation::Turquin).unwrap();
            let wis = [Vec3::Z, -Vec3::Z, dir(1.5, 1.0), dir(1.7, 0.0)];
            assert_finite_at_edges(&b, &wis, &format!("η = {eta} α = {a}"));
        }
    }
}

/// The side of a view above (`true`) or below the surface.
fn side_of(above: bool) -> Side {
    if above { Side::Outside } else { Side::Inside }
}
