//! Elliptical anisotropy with correlation (Dupuy 2015, thesis §2.3): the parameter conversions,
//! D against eq. 2.26, the normalization and projected-area identities, the rotation identity,
//! the sampler's chi-square fit and the constructors' rejections.

use glam::Vec3;
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Elliptical, Error, Ggx};

/// Eq. 2.26 written out independently: the standard density at the decorrelated slopes, and
/// their squared radius (Beckmann's exponent).
fn d_eq_2_26(p_std: fn(f64, f64) -> f64, (ax, ay, rho): (f64, f64, f64), wm: Vec3) -> (f64, f64) {
    let m = wm.as_dvec3();
    if m.z <= 0.0 {
        return (0.0, f64::INFINITY);
    }
    let (x, y) = (-m.x / m.z, -m.y / m.z);
    let root = (1.0 - rho * rho).sqrt();
    let scale = ax * ay * root;
    let (u, v) = (x / ax, (ax * y - rho * ay * x) / scale);
    (p_std(u, v) / (scale * m.z.powi(4)), u * u + v * v)
}

fn beckmann_std(x: f64, y: f64) -> f64 {
    (-(x * x) - y * y).exp() / std::f64::consts::PI
}

fn ggx_std(x: f64, y: f64) -> f64 {
    1.0 / (std::f64::consts::PI * (1.0 + x * x + y * y).powi(2))
}

/// Eqs. 2.29–2.31 in f64.
fn bivariate_of(a1: f32, a2: f32, phi: f32) -> (f64, f64, f64) {
    let (a1, a2, phi) = (f64::from(a1), f64::from(a2), f64::from(phi));
    let (s1, s2, c2) = (a1 * a1, a2 * a2, (2.0 * phi).cos());
    let ax = (0.5 * (s1 + s2 + (s1 - s2) * c2)).sqrt();
    let ay = (0.5 * (s1 + s2 - (s1 - s2) * c2)).sqrt();
    (ax, ay, (s1 - s2) / (ax * ay) * phi.cos() * phi.sin())
}

const ELLIPSES: [(f32, f32, f32); 5] =
    [(0.5, 0.1, 0.3), (0.2, 0.6, -1.1), (0.05, 0.3, 0.78), (1.0, 1.0, 0.4), (0.4, 0.02, 1.5)];

#[test]
fn conversions_round_trip_and_d_matches_eq_2_26() {
    for &(a1, a2, phi) in &ELLIPSES {
        let e = Elliptical::<Beckmann>::from_ellipse(a1, a2, phi).unwrap();
        let b = e.bivariate();
        let back = Elliptical::<Beckmann>::from_bivariate(b.0, b.1, b.2).unwrap();
        let (b1, b2, bphi) = back.ellipse();
        // the same ellipse: radii sorted, angle modulo π (or any angle when isotropic)
        let (big, small) = if a1 >= a2 { (a1, a2) } else { (a2, a1) };
        assert!(
            (b1 - big).abs() <= 1e-5 * big && (b2 - small).abs() <= 1e-4 * small,
            "{a1} {a2} {phi}: {b1} {b2}"
        );
        if a1 != a2 {
            let major = if a1 >= a2 { phi } else { phi + std::f32::consts::FRAC_PI_2 };
            let diff = (major - bphi).rem_euclid(std::f32::consts::PI);
            assert!(diff.min(std::f32::consts::PI - diff) < 1e-4, "{a1} {a2} {phi}: φ {bphi}");
        }
        let exact = bivariate_of(a1, a2, phi);
        let given = (f64::from(b.0), f64::from(b.1), f64::from(b.2));
        for k in 0..200 {
            let wm = validation::dir(1.5 * (k as f64 / 200.0), 0.7 * k as f64).normalize();
            for (p_std, d, params, label) in [
                (beckmann_std as fn(f64, f64) -> f64, e.d64(wm.as_dvec3()), exact, "beckmann, ellipse"),
                (
                    ggx_std,
                    Elliptical::<Ggx>::from_ellipse(a1, a2, phi).unwrap().d64(wm.as_dvec3()),
                    exact,
                    "ggx, ellipse",
                ),
                (beckmann_std, back.d64(wm.as_dvec3()), given, "beckmann, bivariate"),
                (
                    ggx_std,
                    Elliptical::<Ggx>::from_bivariate(b.0, b.1, b.2).unwrap().d64(wm.as_dvec3()),
                    given,
                    "ggx, bivariate",
                ),
            ] {
                let (expected, radius_sq) = d_eq_2_26(p_std, params, wm);
                // (below 1e-290 both are f64 subnormals, compared as such) f64 arithmetic on an
                // exponent r²: relative error ~r²·1e-15, and the f32
                // radii (α₁, α₂) of the internal ellipse: 2r²·6e-8
                let tol = 1e-6 + 2e-7 * radius_sq;
                assert!(
                    (d - expected).abs() <= tol * expected || (d < 1e-290 && expected < 1e-290),
                    "{label} {a1} {a2} {phi} {wm}: {d} vs {expected}"
                );
            }
        }
    }
}

#[test]
fn constructors_reject_invalid_parameters() {
    let bad = |r: Result<Elliptical<Beckmann>, Error>, name: &str| match r {
        Err(Error::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
        other => panic!("{name}: expected a rejection, got {other:?}"),
    };
    bad(Elliptical::from_bivariate(0.3, 0.3, 1.0), "rho");
    bad(Elliptical::from_bivariate(0.3, 0.3, -1.0), "rho");
    bad(Elliptical::from_bivariate(0.3, 0.3, f32::NAN), "rho");
    bad(Elliptical::from_bivariate(0.3, 0.3, 1.5), "rho");
    bad(Elliptical::from_bivariate(0.0, 0.3, 0.0), "alpha_x");
    bad(Elliptical::from_bivariate(0.3, -0.1, 0.0), "alpha_y");
    bad(Elliptical::from_bivariate(f32::INFINITY, 0.3, 0.0), "alpha_x");
    bad(Elliptical::from_ellipse(f32::NAN, 0.3, 0.0), "alpha_1");
    bad(Elliptical::from_ellipse(0.3, 0.0, 0.0), "alpha_2");
    bad(Elliptical::from_ellipse(0.3, 0.2, f32::INFINITY), "phi");
    assert!(Elliptical::<Ggx>::from_bivariate(0.3, 0.2, 0.999_999).is_ok());
}

use microsurface::research::{Microsurface, UniformHeight};
use microsurface::{ComplexIor, Conductor, Dielectric};
use std::f64::consts::PI;
use validation::chi2::{Chi2Grid, chi2_test};
use validation::quadrature::{Domain, integrate_sphere};

/// Correlations of the identity tests, up to |ρ| = 0.99.
const RHOS: [f32; 5] = [-0.99, -0.6, 0.0, 0.8, 0.99];
/// Marginals (αx, αy) of the identity tests.
const MARGINALS: [(f32, f32); 2] = [(0.3, 0.3), (0.6, 0.25)];
/// Views (θ, φ) of the projected-area identities: above, grazing, below the horizon.
const VIEWS: [(f64, f64); 3] = [(1.1, 0.4), (1.5, 2.2), (2.3, -1.3)];

/// The quadrature's absolute tolerance on the hemisphere; the identities assert 20× it.
const QUAD_TOL: f64 = 1e-6;

/// The quadrature of ∫ f over the upper hemisphere: 24 × 48 cells, adaptive to depth 6.
fn hemisphere(f: &mut impl FnMut(Vec3) -> f64) -> f64 {
    integrate_sphere(f, 24, 48, Domain::UpperHemisphere, QUAD_TOL, 6)
}

/// ∫ D_ωi over the hemisphere to the absolute accuracy of [`hemisphere`]: D_ωi is ⟨ω, m⟩⁺D
/// divided by A(ω), so the tolerance is scaled by A (at the same depth) instead of the bound
/// growing as 1/A.
fn visible_normals(f: &mut impl FnMut(Vec3) -> f64, area: f64) -> f64 {
    integrate_sphere(f, 24, 48, Domain::UpperHemisphere, QUAD_TOL * area.min(1.0), 6)
}

fn identities<S: MicrosurfaceSlope>(label: &str, slope: &S) {
    // eq. 2.8: ∫ D cos θm = 1
    let norm = hemisphere(&mut |m| slope.d64(m.as_dvec3()) * f64::from(m.z));
    assert!((norm - 1.0).abs() < 2e-5, "{label}: ∫ D cos θm = {norm:.8}");
    for (theta, phi) in VIEWS {
        let w = validation::dir(theta, phi).normalize();
        // signed: ∫⟨ω, m⟩ D = cos θ; clamped: ∫⟨ω, m⟩⁺ D = A(ω) = (1 + Λ(ω)) cos θ
        let signed = hemisphere(&mut |m| slope.d64(m.as_dvec3()) * f64::from(w.dot(m)));
        let clamped = hemisphere(&mut |m| slope.d64(m.as_dvec3()) * f64::from(w.dot(m)).max(0.0));
        let area = slope.projected_area64(w);
        let from_lambda = (1.0 + slope.lambda64(w)) * f64::from(w.z);
        assert!(
            (signed - f64::from(w.z)).abs() < 2e-5,
            "{label} {w}: ∫⟨ω,m⟩D = {signed:.8}, cos θ = {}",
            w.z
        );
        assert!((clamped - area).abs() < 2e-5, "{label} {w}: ∫⟨ω,m⟩⁺D = {clamped:.8}, A = {area:.8}");
        assert!(
            (from_lambda - area).abs() < 1e-6 * (1.0 + area),
            "{label} {w}: (1 + Λ) cos θ = {from_lambda:.8}, A = {area:.8}"
        );
        if area > 1e-3 {
            let visible = visible_normals(&mut |m| slope.d_wi64(w, m.as_dvec3()), area);
            assert!(
                (visible - 1.0).abs() < 20.0 * QUAD_TOL,
                "{label} {w}: ∫ D_ωi = {visible:.8} (A = {area:.3e})"
            );
        }
    }
}

#[test]
fn normalization_and_projected_area_up_to_rho_0_99() {
    let mut cases = Vec::new();
    for &(ax, ay) in &MARGINALS {
        for &rho in &RHOS {
            cases.push((ax, ay, rho));
        }
    }
    validation::par_map(&cases, |_, &(ax, ay, rho)| {
        identities(
            &format!("beckmann ({ax}, {ay}, ρ {rho})"),
            &Elliptical::<Beckmann>::from_bivariate(ax, ay, rho).unwrap(),
        );
        identities(
            &format!("ggx ({ax}, {ay}, ρ {rho})"),
            &Elliptical::<Ggx>::from_bivariate(ax, ay, rho).unwrap(),
        );
    });
}

/// The correlated projected roughness: Λ of the ellipse equals Λ of the isotropic distribution
/// of roughness αᵢ(ω) (the Smith Λ depends on ω through cot θ/αᵢ only).
#[test]
fn alpha_i_carries_the_correlation() {
    for &rho in &RHOS {
        let e = Elliptical::<Beckmann>::from_bivariate(0.4, 0.2, rho).unwrap();
        for k in 0..64 {
            let w = validation::dir(0.3 + 2.5 * k as f64 / 64.0, 0.37 * k as f64).normalize();
            let iso = Beckmann::isotropic(e.alpha_i(w)).unwrap();
            let (a, b) = (e.lambda64(w), iso.lambda64(w));
            assert!((a - b).abs() <= 1e-5 * (1.0 + a.abs()), "ρ {rho} {w}: Λ {a} vs Λ(αᵢ) {b}");
        }
    }
}

/// The rotated ellipse (α₁, α₂, φα) seen from (θ, ψ) is the axis-aligned (α₁, α₂) seen from
/// (θ, ψ − φα): D, Λ, and the walk's albedo per scattering order as two independent estimates
/// (unpaired seeds, so that the check does not reduce to running the same arithmetic twice):
/// |Δ| ≤ z √(SE₁² + SE₂²) with the combined SE asserted ≤ 3e-3 (a rotation by +φα instead of
/// −φα moves order 1 by far more; checked by flipping the sign once).
#[test]
fn rotation_identity_for_d_lambda_and_walk_albedo_per_order() {
    const ROTATIONS: [(f32, f32, f32); 3] = [(0.6, 0.15, 0.7), (0.3, 0.9, -1.2), (1.0, 0.25, 2.0)];
    const ORDERS: usize = 4;
    const WALKS: usize = 60_000;
    const VIEWS_PER_CASE: usize = 3;
    let z = validation::family_z(0.01, ROTATIONS.len() * VIEWS_PER_CASE * 2 * ORDERS);
    for &(a1, a2, phi) in &ROTATIONS {
        let e = Elliptical::<Beckmann>::from_ellipse(a1, a2, phi).unwrap();
        let aligned = Beckmann::new(a1, a2).unwrap();
        let ge = Elliptical::<Ggx>::from_ellipse(a1, a2, phi).unwrap();
        let ga = Ggx::new(a1, a2).unwrap();
        for k in 0..100 {
            let (theta, psi) = (3.0 * k as f64 / 100.0, 0.61 * k as f64);
            let (w, w_aligned) = (validation::dir(theta, psi), validation::dir(theta, psi - f64::from(phi)));
            let rel = |a: f64, b: f64| (a - b).abs() / (a.abs().max(b.abs()).max(1e-300));
            let (d, d_aligned) = (e.d64(w.as_dvec3()), aligned.d64(w_aligned.as_dvec3()));
            // the two f32 directions differ by their roundings (~1e-7): D's condition 2t
            let t = (-(d * PI * f64::from(a1 * a2) * f64::from(w.z).powi(4)).ln()).max(0.0);
            assert!(
                rel(d, d_aligned) < 1e-6 * (1.0 + t) || d < 1e-290,
                "{a1} {a2} {phi} {w}: D {d} vs {d_aligned}"
            );
            let (l, l_aligned) = (e.lambda64(w), aligned.lambda64(w_aligned));
            assert!(rel(l, l_aligned) < 1e-4 || (l - l_aligned).abs() < 1e-12, "{w}: Λ {l} vs {l_aligned}");
            let (g, g_aligned) = (ge.lambda64(w), ga.lambda64(w_aligned));
            assert!(
                rel(g, g_aligned) < 1e-4 || (g - g_aligned).abs() < 1e-12,
                "{w}: GGX Λ {g} vs {g_aligned}"
            );
        }
        for (v, (theta, psi)) in [(0.4, 0.3), (1.2, 2.0), (1.45, -2.5)].into_iter().enumerate() {
            let (wi, wi_aligned) =
                (validation::dir(theta, psi), validation::dir(theta, psi - f64::from(phi)));
            for (material, name) in [(0, "gold"), (1, "glass")] {
                let seed = 1000 + 10 * v as u64 + material;
                let per_order = |slope_is_elliptical: bool| {
                    let mut rng = validation::rng(if slope_is_elliptical { seed } else { seed + 500_000 });
                    let mut orders: Vec<Vec<f64>> = (0..ORDERS).map(|_| Vec::with_capacity(WALKS)).collect();
                    for _ in 0..WALKS {
                        let s = match (material, slope_is_elliptical) {
                            (0, true) => {
                                Microsurface::new(UniformHeight, e, Conductor::new(ComplexIor::GOLD))
                                    .sample(wi, &mut rng)
                            }
                            (0, false) => {
                                Microsurface::new(UniformHeight, aligned, Conductor::new(ComplexIor::GOLD))
                                    .sample(wi_aligned, &mut rng)
                            }
                            (_, true) => Microsurface::new(UniformHeight, e, Dielectric::new(1.5).unwrap())
                                .sample(wi, &mut rng),
                            (_, false) => {
                                Microsurface::new(UniformHeight, aligned, Dielectric::new(1.5).unwrap())
                                    .sample(wi_aligned, &mut rng)
                            }
                        };
                        let (weight, bounces) =
                            s.map_or((0.0, 0), |s| (f64::from(s.weight.x), s.bounces as usize));
                        for (order, values) in orders.iter_mut().enumerate() {
                            let this = bounces == order + 1 || (order + 1 == ORDERS && bounces >= ORDERS);
                            values.push(if this { weight } else { 0.0 });
                        }
                    }
                    orders
                };
                let (a, b) = (per_order(true), per_order(false));
                for order in 0..ORDERS {
                    // two independent estimates of the same albedo
                    let mut level = validation::Stats::default();
                    let mut aligned_level = validation::Stats::default();
                    for (x, y) in a[order].iter().zip(&b[order]) {
                        level.push(*x);
                        aligned_level.push(*y);
                    }
                    let label = format!(
                        "{name} ({a1}, {a2}, φ {phi}) θ {theta} order {}{}",
                        order + 1,
                        if order + 1 == ORDERS { "+" } else { "" }
                    );
                    validation::assert_two_sample(&label, &level, &aligned_level, z, 3e-3);
                    assert!(level.mean() > 0.0 || order > 1, "{label}: no energy in this order");
                }
            }
        }
    }
}

#[test]
fn sampler_chi2() {
    // (ellipse, view θ, view φ): above and below the horizon, strong correlation
    const CASES: [((f32, f32, f32), f64, f64); 6] = [
        ((0.5, 0.1, 0.3), 0.7, 1.0),
        ((0.2, 0.8, -1.0), 1.3, -2.0),
        ((0.9, 0.3, 0.785), 1.57, 0.5),
        ((0.4, 0.04, 2.4), 0.2, 0.0),
        ((0.6, 0.3, 1.3), 2.0, 2.5),
        ((1.2, 0.5, -0.4), 2.7, -0.9),
    ];
    const N: usize = 200_000;
    let alpha = validation::sidak(0.01, 2 * CASES.len());
    validation::par_map(&CASES, |i, &((a1, a2, phi), theta, psi)| {
        let wi = validation::dir(theta, psi).normalize();
        let grid = Chi2Grid { quad_tol: 1e-5, max_depth: 7, ..Chi2Grid::sphere(30, 40) };
        let b = Elliptical::<Beckmann>::from_ellipse(a1, a2, phi).unwrap();
        let mut rng = validation::rng(77 + i as u64);
        chi2_test(
            &format!("beckmann ({a1}, {a2}, φ {phi}) from {wi}"),
            grid,
            |m| b.d_wi64(wi, m.as_dvec3()),
            || Some(b.sample_d_wi(wi, validation::uniform32(&mut rng), validation::uniform32(&mut rng))),
            N,
            alpha,
            1.0,
        );
        let g = Elliptical::<Ggx>::from_ellipse(a1, a2, phi).unwrap();
        let mut rng = validation::rng(177 + i as u64);
        chi2_test(
            &format!("ggx ({a1}, {a2}, φ {phi}) from {wi}"),
            grid,
            |m| g.d_wi64(wi, m.as_dvec3()),
            || Some(g.sample_d_wi(wi, validation::uniform32(&mut rng), validation::uniform32(&mut rng))),
            N,
            alpha,
            1.0,
        );
    });
}

/// A correlated slope with equal marginals is an ellipse at φα = 45°: is anisotropic: the isotropic table
/// must reject it (it accepted every slope with αx = αy before).
#[test]
fn isotropic_table_rejects_a_correlated_slope() {
    let rotated = Elliptical::<Beckmann>::from_bivariate(0.3, 0.3, 0.6).unwrap();
    let (a1, a2, phi) = rotated.ellipse();
    assert!(a1 > 1.5 * a2 && (phi - std::f32::consts::FRAC_PI_4).abs() < 1e-6, "({a1}, {a2}, {phi})");
    assert!(microsurface::tabulated::TabulatedSlope::from_slope(&rotated, 4.0, 64).is_err());
    let round = Elliptical::<Beckmann>::from_ellipse(0.3, 0.3, 1.0).unwrap();
    assert!(microsurface::tabulated::TabulatedSlope::from_slope(&round, 4.0, 64).is_ok());
    assert!(
        microsurface::tabulated::TabulatedSlope::from_slope(&Beckmann::isotropic(0.3).unwrap(), 4.0, 64)
            .is_ok()
    );
}

/// The compensated conductor of a rotated ellipse is the axis-aligned one seen from rotated
/// directions (its tables are read at √(α₁ α₂), not at the marginals' √(αx αy)).
#[test]
fn compensated_conductor_is_rotation_invariant() {
    use microsurface::{Bsdf, Compensated, Compensation};
    let (a1, a2, phi) = (0.5f32, 0.15f32, 0.9f32);
    let conductor = Conductor::new(ComplexIor::GOLD);
    for scheme in [Compensation::KullaConty, Compensation::Turquin, Compensation::Walk] {
        let e = Compensated::with_scheme(
            Elliptical::<Ggx>::from_ellipse(a1, a2, phi).unwrap(),
            conductor,
            scheme,
        )
        .unwrap();
        let a = Compensated::with_scheme(Ggx::new(a1, a2).unwrap(), conductor, scheme).unwrap();
        for k in 0..50 {
            let (t_o, p_o, t_i, p_i) =
                (1.5 * k as f64 / 50.0, 0.9 * k as f64, 1.4 * (k as f64 * 0.37).fract(), 2.1 * k as f64);
            let (wo, wi) = (validation::dir(t_o, p_o), validation::dir(t_i, p_i));
            let (wo_a, wi_a) =
                (validation::dir(t_o, p_o - f64::from(phi)), validation::dir(t_i, p_i - f64::from(phi)));
            let (fe, fa) = (e.eval(wo, wi).f, a.eval(wo_a, wi_a).f);
            assert!(
                (fe - fa).abs().max_element() <= 1e-4 * fa.max_element() + 1e-6,
                "{scheme:?} {wo} {wi}: {fe} vs {fa}"
            );
        }
    }
}

/// `MicrofacetBsdf`'s roughness limits depend on the ellipse, not on the frame's rotation: the
/// walk-length limit rejects α₁ = 13 at every φα (the marginals at φα = π/4 are only
/// ≈ 13/√2 < 10), and the Dirac switch below `SMOOTH_ALPHA` = 1e-3 does not flip at π/4 for an
/// ellipse whose largest radius is above it (the marginals there are ≈ 1.2e-3/√2).
#[test]
fn bsdf_roughness_limits_are_rotation_invariant() {
    use glam::Vec2;
    use microsurface::{Bsdf, MicrofacetBsdf};
    let gold = Conductor::new(ComplexIor::GOLD);
    let wo = Vec3::new(0.6, 0.0, 0.8);
    for phi in [0.0, std::f32::consts::FRAC_PI_4, 2.0] {
        for (a1, a2) in [(13.0, 0.05), (0.05, 13.0)] {
            let slope = Elliptical::<Ggx>::from_ellipse(a1, a2, phi).unwrap();
            assert_eq!(slope.alpha_max(), 13.0, "({a1}, {a2}, φ {phi})");
            match MicrofacetBsdf::new(slope, gold) {
                Err(Error::InvalidParameter { name: "alpha", .. }) => {}
                other => panic!("({a1}, {a2}, φ {phi}): expected the walk limit, got {other:?}"),
            }
        }
        for (a1, a2, specular) in [(1.2e-3, 1e-4, false), (9e-4, 1e-4, true)] {
            let slope = Elliptical::<Beckmann>::from_ellipse(a1, a2, phi).unwrap();
            let bsdf = MicrofacetBsdf::new(slope, gold).unwrap();
            let s = bsdf.sample(wo, 0.3, Vec2::new(0.6, 0.1)).expect("gold reflects");
            assert_eq!(s.flags.specular, specular, "({a1}, {a2}, φ {phi}): specular flag");
        }
    }
}

/// The bivariate form that `from_ellipse` derives is always accepted by `from_bivariate`, down
/// to ellipses too thin for an f32 ρ (|ρ| rounds to 1 from α₂/α₁ ≈ 2⁻¹² on at φα = π/4).
#[test]
fn thin_ellipses_round_trip_through_the_bivariate_form() {
    for (a1, a2) in [(1.0, 1e-4), (1e-4, 1.0), (1.0, 1e-7), (3.0, 2e-4), (0.5, 0.5 * 2f32.powi(-12))] {
        for phi in [std::f32::consts::FRAC_PI_4, -std::f32::consts::FRAC_PI_4, 0.3, 1.2, 2.5] {
            let e = Elliptical::<Ggx>::from_ellipse(a1, a2, phi).unwrap();
            let (ax, ay, rho) = e.bivariate();
            assert!(rho.abs() < 1.0, "({a1}, {a2}, φ {phi}): ρ = {rho}");
            let back = Elliptical::<Ggx>::from_bivariate(ax, ay, rho)
                .unwrap_or_else(|err| panic!("({a1}, {a2}, φ {phi}) → ({ax}, {ay}, {rho}): {err:?}"));
            // the major radius survives; the minor one is what the f32 ρ can represent
            let (b1, _, _) = back.ellipse();
            let big = a1.max(a2);
            assert!((b1 - big).abs() <= 1e-5 * big, "({a1}, {a2}, φ {phi}): α₁ {b1}");
        }
    }
}
