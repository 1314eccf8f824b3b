//! Noncentral (sheared) microsurfaces (Dupuy 2015, thesis §3.2): D against eq. 3.2, its
//! normalization (eq. 3.1) and mean normal, the projected area against quadrature, G1 against
//! eq. 3.3, the sampler's chi-square fit (eq. 3.4) and the constructor's rejections.

use glam::{Vec2, Vec3};
use microsurface::leadr::Noncentral;
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Elliptical, Error, Ggx};
use std::f64::consts::PI;
use validation::chi2::{Chi2Grid, chi2_test};
use validation::quadrature::{Domain, integrate_sphere};

/// Views (θ, φ): above the horizon facing and away from the tilt, grazing, below.
const VIEWS: [(f64, f64); 5] = [(0.0, 0.0), (1.0, 0.3), (1.3, 3.5), (1.55, 2.0), (2.2, -1.0)];

/// The quadrature's absolute tolerance on the hemisphere; ∫ D_ωi is asserted to 20× it.
const QUAD_TOL: f64 = 1e-6;

fn hemisphere(f: &mut impl FnMut(Vec3) -> f64) -> f64 {
    integrate_sphere(f, 24, 48, Domain::UpperHemisphere, QUAD_TOL, 6)
}

/// ∫ D_ωi over the hemisphere to the absolute accuracy of [`hemisphere`]: D_ωi is ⟨ω, m⟩⁺D
/// divided by A(ω), so the tolerance is scaled by A (at the same depth) instead of the bound
/// growing as 1/A.
fn visible_normals(f: &mut impl FnMut(Vec3) -> f64, area: f64) -> f64 {
    integrate_sphere(f, 24, 48, Domain::UpperHemisphere, QUAD_TOL * area.min(1.0), 6)
}

fn identities<S: MicrosurfaceSlope>(label: &str, s: &Noncentral<S>) {
    let d = |m: Vec3| s.d64(m.as_dvec3());
    let cos = hemisphere(&mut |m| d(m) * f64::from(m.z));
    assert!((cos - 1.0).abs() < 1e-5, "{label}: ∫ D cos θ = {cos}");
    // ∫ m D dω = n sec θn (the mean normal, unnormalized)
    let mx = hemisphere(&mut |m| d(m) * f64::from(m.x));
    let my = hemisphere(&mut |m| d(m) * f64::from(m.y));
    let (ex, ey) = (-f64::from(s.mean_slope().x), -f64::from(s.mean_slope().y));
    assert!(
        (mx - ex).abs() < 1e-4 && (my - ey).abs() < 1e-4,
        "{label}: ∫ m D = ({mx}, {my}), expected ({ex}, {ey})"
    );
    let n = s.mean_normal();
    assert!(
        (f64::from(n.x / n.z) - ex).abs() < 1e-6 && (f64::from(n.y / n.z) - ey).abs() < 1e-6,
        "{label}: n = {n}"
    );
    for (theta, phi) in VIEWS {
        let w = validation::dir(theta, phi).normalize();
        let quad = hemisphere(&mut |m| d(m) * f64::from(w.dot(m)).max(0.0));
        let a = f64::from(s.projected_area(w));
        assert!((quad - a).abs() < 1e-5 * (1.0 + a), "{label} {w}: ∫⟨ω,m⟩⁺D = {quad}, A = {a}");
        if a > 1e-3 {
            let visible = visible_normals(&mut |m| f64::from(s.d_wi(w, m)), a);
            assert!((visible - 1.0).abs() < 20.0 * QUAD_TOL, "{label} {w}: ∫ D_ωi = {visible} (A = {a:.3e})");
        }
    }
}

#[test]
fn d_is_normalized_with_the_mean_normal_and_projected_area() {
    identities(
        "beckmann 0.3, (0.4, -0.2)",
        &Noncentral::new(Beckmann::isotropic(0.3).unwrap(), Vec2::new(0.4, -0.2)).unwrap(),
    );
    identities(
        "ggx 0.5, (-0.8, 0.3)",
        &Noncentral::new(Ggx::isotropic(0.5).unwrap(), Vec2::new(-0.8, 0.3)).unwrap(),
    );
    identities(
        "elliptical beckmann (0.3, 0.1, ρ 0.6), (0.5, 0.5)",
        &Noncentral::new(Elliptical::<Beckmann>::from_bivariate(0.3, 0.1, 0.6).unwrap(), Vec2::new(0.5, 0.5))
            .unwrap(),
    );
    identities(
        "elliptical ggx (0.2, 0.4, ρ −0.9), (1.2, 0.0)",
        &Noncentral::new(Elliptical::<Ggx>::from_bivariate(0.2, 0.4, -0.9).unwrap(), Vec2::new(1.2, 0.0))
            .unwrap(),
    );
}

/// Eq. 3.2 written out for the correlated Beckmann distribution.
#[test]
fn d_matches_eq_3_2() {
    let (ax, ay, rho, xn, yn) = (0.35f32, 0.2f32, -0.4f32, 0.3f32, -0.6f32);
    let s = Noncentral::new(Elliptical::<Beckmann>::from_bivariate(ax, ay, rho).unwrap(), Vec2::new(xn, yn))
        .unwrap();
    let (ax, ay, rho, xn, yn) = (f64::from(ax), f64::from(ay), f64::from(rho), f64::from(xn), f64::from(yn));
    let root = (1.0 - rho * rho).sqrt();
    for k in 0..300 {
        let m = validation::dir(1.5 * k as f64 / 300.0, 0.83 * k as f64).normalize().as_dvec3();
        let (x, y) = (-m.x / m.z - xn, -m.y / m.z - yn);
        let (u, v) = (x / ax, (ax * y - rho * ay * x) / (ax * ay * root));
        let expected = (-(u * u) - v * v).exp() / (PI * ax * ay * root * m.z.powi(4));
        let d = s.d64(m);
        // f32 radii of the internal ellipse: relative 2r²·6e-8 of the exponent r²
        let tol = 1e-6 + 2e-7 * (u * u + v * v);
        assert!(
            (d - expected).abs() <= tol * expected || (d < 1e-290 && expected < 1e-290),
            "{m}: {d} vs {expected}"
        );
    }
}

/// G1 by eq. 3.3: (cos θ/c) G1_S(k′) with c = ⟨ω, n⟩ sec θn and k′ = (ω.x, ω.y, c)/‖·‖, for the
/// views with c > 0, where the central G1_S(k′) = 1/(1 + Λ_S(k′)) is the thesis' G1_std.
#[test]
fn g1_matches_eq_3_3() {
    let central = Elliptical::<Ggx>::from_bivariate(0.3, 0.5, 0.7).unwrap();
    let mean = Vec2::new(0.7, -0.4);
    let s = Noncentral::new(central, mean).unwrap();
    let (mut above, mut exceeds_one) = (0, 0);
    for k in 0..400 {
        let w = validation::dir(1.56 * k as f64 / 400.0, 0.71 * k as f64).normalize();
        let c = f64::from(w.z) - f64::from(w.x) * f64::from(mean.x) - f64::from(w.y) * f64::from(mean.y);
        let g1 = f64::from(s.g1(w));
        assert!(g1.is_finite() && g1 > 0.0, "{w}: G1 = {g1}");
        if c <= 0.0 {
            continue;
        }
        above += 1;
        let k_prime = glam::DVec3::new(f64::from(w.x), f64::from(w.y), c).normalize().as_vec3();
        let expected = f64::from(w.z) / c / (1.0 + central.lambda64(k_prime));
        assert!((g1 - expected).abs() <= 1e-5 * expected, "{w}: G1 = {g1}, eq. 3.3 = {expected}");
        exceeds_one += usize::from(g1 > 1.0);
    }
    assert!(above > 300 && exceeds_one > 10, "{above} views with c > 0, {exceeds_one} with G1 > 1");
    // the central case is the central G1 itself
    let flat = Noncentral::new(central, Vec2::ZERO).unwrap();
    for k in 0..100 {
        let w = validation::dir(1.56 * k as f64 / 100.0, 1.3 * k as f64).normalize();
        let expected = 1.0 / (1.0 + central.lambda64(w));
        assert!((f64::from(flat.g1(w)) - expected).abs() <= 1e-6 * expected, "{w}");
    }
    assert_eq!(s.g1(Vec3::new(0.6, 0.0, -0.8)), 0.0);
}

#[test]
fn sampler_chi2() {
    const N: usize = 200_000;
    const CASES: usize = 8;
    let alpha = validation::sidak(0.01, CASES);
    let grid = Chi2Grid { quad_tol: 1e-5, max_depth: 7, ..Chi2Grid::sphere(30, 40) };
    let run = |i: usize,
               label: &str,
               d_wi: &dyn Fn(Vec3, Vec3) -> f64,
               sample: &dyn Fn(Vec3, f32, f32) -> Vec3,
               wi: Vec3| {
        let mut rng = validation::rng(300 + i as u64);
        chi2_test(
            &format!("{label} from {wi}"),
            grid,
            |m| d_wi(wi, m),
            || Some(sample(wi, validation::uniform32(&mut rng), validation::uniform32(&mut rng))),
            N,
            alpha,
            1.0,
        );
    };
    let b = Noncentral::new(Beckmann::isotropic(0.3).unwrap(), Vec2::new(0.5, -0.3)).unwrap();
    let g = Noncentral::new(Ggx::new(0.4, 0.2).unwrap(), Vec2::new(-0.9, 0.2)).unwrap();
    let eb =
        Noncentral::new(Elliptical::<Beckmann>::from_bivariate(0.4, 0.15, 0.8).unwrap(), Vec2::new(0.6, 0.6))
            .unwrap();
    let eg = Noncentral::new(Elliptical::<Ggx>::from_bivariate(0.2, 0.5, -0.7).unwrap(), Vec2::new(0.0, 1.5))
        .unwrap();
    let views = [
        validation::dir(0.6, 0.4),
        validation::dir(1.4, 3.6),
        validation::dir(2.1, 1.0),
        validation::dir(1.2, 0.3),
    ];
    let views: Vec<Vec3> = views.iter().map(|w| w.normalize()).collect();
    validation::par_map(&[0usize, 1, 2, 3], |_, &j| match j {
        0 => {
            run(
                0,
                "beckmann 0.3, (0.5, −0.3)",
                &|wi, m| f64::from(b.d_wi(wi, m)),
                &|wi, u1, u2| b.sample_d_wi(wi, u1, u2),
                views[0],
            );
            run(
                1,
                "beckmann 0.3, (0.5, −0.3)",
                &|wi, m| f64::from(b.d_wi(wi, m)),
                &|wi, u1, u2| b.sample_d_wi(wi, u1, u2),
                views[2],
            );
        }
        1 => {
            run(
                2,
                "ggx (0.4, 0.2), (−0.9, 0.2)",
                &|wi, m| f64::from(g.d_wi(wi, m)),
                &|wi, u1, u2| g.sample_d_wi(wi, u1, u2),
                views[1],
            );
            run(
                3,
                "ggx (0.4, 0.2), (−0.9, 0.2)",
                &|wi, m| f64::from(g.d_wi(wi, m)),
                &|wi, u1, u2| g.sample_d_wi(wi, u1, u2),
                views[3],
            );
        }
        2 => {
            let l = "elliptical beckmann (0.4, 0.15, ρ 0.8), (0.6, 0.6)";
            run(4, l, &|wi, m| f64::from(eb.d_wi(wi, m)), &|wi, u1, u2| eb.sample_d_wi(wi, u1, u2), views[1]);
            run(5, l, &|wi, m| f64::from(eb.d_wi(wi, m)), &|wi, u1, u2| eb.sample_d_wi(wi, u1, u2), views[3]);
        }
        _ => {
            let l = "elliptical ggx (0.2, 0.5, ρ −0.7), (0, 1.5)";
            run(6, l, &|wi, m| f64::from(eg.d_wi(wi, m)), &|wi, u1, u2| eg.sample_d_wi(wi, u1, u2), views[0]);
            run(7, l, &|wi, m| f64::from(eg.d_wi(wi, m)), &|wi, u1, u2| eg.sample_d_wi(wi, u1, u2), views[2]);
        }
    });
}

#[test]
fn constructor_rejects_non_finite_mean_slopes() {
    let slope = Beckmann::isotropic(0.2).unwrap();
    for (mean, name) in [
        (Vec2::new(f32::NAN, 0.0), "mean_slope.x"),
        (Vec2::new(0.0, f32::INFINITY), "mean_slope.y"),
        (Vec2::new(f32::NEG_INFINITY, 1.0), "mean_slope.x"),
    ] {
        match Noncentral::new(slope, mean) {
            Err(Error::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
            other => panic!("{mean}: expected a rejection, got {other:?}"),
        }
    }
    assert!(Noncentral::new(slope, Vec2::new(1e6, -1e6)).is_ok());
}

/// The single-scattering sampler: its directions fit its density (χ², with the mass that leaves
/// below the base plane missing), and its mean weight is the albedo ∫ f|cos θo| dωo of the
/// evaluation (so weight = f|cos θo|/pdf).
#[test]
fn single_scattering_sampler_matches_eval_and_pdf() {
    use microsurface::{ComplexIor, Conductor};
    const N: usize = 200_000;
    let conductor = Conductor::new(ComplexIor::GOLD);
    let s = Noncentral::new(
        Elliptical::<Beckmann>::from_bivariate(0.35, 0.2, 0.5).unwrap(),
        Vec2::new(0.6, -0.3),
    )
    .unwrap();
    let views = [
        validation::dir(0.5, 0.2).normalize(),
        validation::dir(1.2, 2.8).normalize(),
        validation::dir(1.0, -0.3).normalize(),
    ];
    // one 1 % budget for both families (a χ² test and a mean test per view): Šidák over 2 × views
    let tests = 2 * views.len();
    let alpha = validation::sidak(0.01, tests);
    let z = validation::family_z(0.01, tests);
    validation::par_map(&views, |i, &wi| {
        let mass = integrate_sphere(
            &mut |wo| f64::from(s.pdf_single_scattering(&conductor, wi, wo)),
            24,
            48,
            Domain::UpperHemisphere,
            1e-6,
            7,
        );
        let mut rng = validation::rng(500 + i as u64);
        chi2_test(
            &format!("single scattering from {wi}"),
            Chi2Grid { quad_tol: 1e-5, max_depth: 7, ..Chi2Grid::sphere(30, 40) },
            |wo| f64::from(s.pdf_single_scattering(&conductor, wi, wo)),
            || s.sample_single_scattering(&conductor, wi, &mut rng).map(|x| x.wo),
            N,
            alpha,
            mass,
        );
        let mut unused = validation::rng(0);
        let albedo = integrate_sphere(
            &mut |wo| f64::from(s.eval_single_scattering(&conductor, wi, wo, &mut unused).x),
            24,
            48,
            Domain::UpperHemisphere,
            1e-6,
            7,
        );
        let mut rng = validation::rng(600 + i as u64);
        let mut weights = validation::Stats::default();
        for _ in 0..N {
            let w = s.sample_single_scattering(&conductor, wi, &mut rng);
            if let Some(w) = w {
                assert_eq!(w.pdf, s.pdf_single_scattering(&conductor, wi, w.wo), "the sample's density");
            }
            weights.push(w.map_or(0.0, |w| f64::from(w.weight.x)));
        }
        // G1(ωo) > 1 away from the tilt makes the weights spread (σ̂ ≈ 1.2 at θ = 1.2): SE ≤ 5e-3
        validation::assert_mean(&format!("albedo from {wi}"), &weights, albedo, z, 5e-3, 1e-5);
    });
}

/// A view far behind a steep mean plane (Beckmann α = 0.05, mean slope 2, θ = 1.2 towards +x:
/// the central view is at cot θ′ ≈ −1.6, a ≈ 32, where the projected area underflows f64): the
/// sampled normals have a positive, finite density (D_ωi was 0 there, formed as D/A with A = 0,
/// while the sampler still returned normals).
#[test]
fn density_of_normals_seen_from_far_behind_the_mean_plane() {
    let s = Noncentral::new(Beckmann::isotropic(0.05).unwrap(), Vec2::new(2.0, 0.0)).unwrap();
    let wi = validation::dir(1.2, 0.0).normalize();
    assert_eq!(s.projected_area(wi), 0.0, "the case must be one where A underflows");
    let mut rng = validation::rng(900);
    for _ in 0..1000 {
        let wm = s.sample_d_wi(wi, validation::uniform32(&mut rng), validation::uniform32(&mut rng));
        let density = s.d_wi(wi, wm);
        assert!(wm.z > 0.0 && wi.dot(wm) > 0.0, "{wm}");
        assert!(density > 0.0 && density.is_finite(), "{wm}: D_ωi = {density}");
    }
    // and it is their density (χ² on the whole sphere), for α = 0.2, where the lobe is wide
    // enough for the harness' quadrature (A = 2.6e-32, beyond f32 but not f64)
    let s = Noncentral::new(Beckmann::isotropic(0.2).unwrap(), Vec2::new(2.0, 0.0)).unwrap();
    let mut rng = validation::rng(902);
    chi2_test(
        &format!("far behind the mean plane, from {wi}"),
        Chi2Grid { quad_tol: 1e-5, max_depth: 7, ..Chi2Grid::sphere(30, 40) },
        |m| f64::from(s.d_wi(wi, m)),
        || Some(s.sample_d_wi(wi, validation::uniform32(&mut rng), validation::uniform32(&mut rng))),
        100_000,
        0.01,
        1.0,
    );
}
