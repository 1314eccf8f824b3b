//! The research-layer single-scattering BSDF (`SingleScattering`):
//!
//! * `sample` passes a chi-square test against `pdf` (conductor, dielectric from outside and
//!   inside, a backfacing conductor view, GGX and Beckmann), its refusals match the mass ∫pdf
//!   leaves out, and every sample carries exactly `pdf` at its direction (bit for bit) and the
//!   weight f·|cos θo|/pdf (relative 1e-4);
//! * `eval_with_pdf` is `(eval, pdf)` bit for bit, and `eval` is the one-vertex
//!   position-free model with correlated shadowing (`PositionFree::eval_single_scattering`);
//! * invalid directions give 0 / `None` (a debug assertion in debug builds).

use glam::Vec3;
use microsurface::research::{Material, PositionFree, Shadowing, SingleScattering};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, ComplexIor, Conductor, Dielectric, Diffuse, Ggx};
use validation::chi2::{Chi2Grid, chi2_test};
use validation::quadrature::{Domain, integrate_sphere};
use validation::{dir, sidak, uniform32, z_two_sided};

/// The allowance for the quadrature error of ∫pdf (in the ∫pdf ≤ 1 check, and added to z·SE in
/// the refusal rate): a deterministic margin over the absolute tolerance the adaptive
/// quadrature is asked for (1e-5, or 1e-4 in the compensated tests), whose error estimate is
/// not a rigorous bound where a density has a kink (its horizon cut-off); not a statistical
/// allowance.
const MASS_TOLERANCE: f64 = 1e-3;

/// Samples per chi-square test.
const CHI2_N: usize = 200_000;
/// The chi-square tests of this file (one family, level 0.01).
const CHI2_FAMILY: usize = 7;

/// Relative closeness of two RGB values (per channel, relative to the larger channel).
fn rel_close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol * a.abs().max(b.abs()).max_element()
}

/// A random unit direction on the whole sphere.
fn random_direction(rng: &mut validation::TestRng) -> Vec3 {
    let z = 2.0 * uniform32(rng) - 1.0;
    let phi = core::f32::consts::TAU * uniform32(rng);
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z).normalize()
}

/// Chi-square of `sample` against `pdf`, its refusal rate against 1 − ∫pdf, and per sample
/// pdf == `pdf(wi, wo)` and weight = eval/pdf.
fn check_sampler<S: MicrosurfaceSlope, M: Material>(
    label: &str,
    model: &SingleScattering<S, M>,
    wi: Vec3,
    seed: u64,
) {
    let mass = integrate_sphere(&mut |w| f64::from(model.pdf(wi, w)), 16, 32, Domain::Sphere, 1e-5, 7);
    assert!(mass <= 1.0 + MASS_TOLERANCE, "{label}: ∫pdf = {mass} > 1");
    let mut rng = validation::rng(seed);
    let mut eval_rng = validation::rng(seed + 1);
    let grid = Chi2Grid { quad_tol: 1e-5, max_depth: 7, ..Chi2Grid::sphere(20, 40) };
    let out = chi2_test(
        label,
        grid,
        |w| f64::from(model.pdf(wi, w)),
        || {
            let s = model.sample(wi, &mut rng)?;
            let pdf = model.pdf(wi, s.wo);
            assert_eq!(
                s.pdf.to_bits(),
                pdf.to_bits(),
                "{label}: sample pdf {} ≠ pdf {pdf} at {}",
                s.pdf,
                s.wo
            );
            if M::EXACT_PHASE_PDF {
                let expected = model.eval(wi, s.wo, &mut eval_rng) / s.pdf;
                assert!(
                    rel_close(s.weight, expected, 1e-4),
                    "{label}: weight {} ≠ f·|cos θo|/pdf = {expected} at wo = {}",
                    s.weight,
                    s.wo
                );
            }
            Some(s.wo)
        },
        CHI2_N,
        sidak(0.01, CHI2_FAMILY),
        mass,
    );
    // refusals: the sampled directions that cannot leave, whose mass ∫pdf leaves out
    let z = z_two_sided(sidak(0.01, CHI2_FAMILY));
    validation::assert_refusal_rate(label, out.failures, CHI2_N, mass, MASS_TOLERANCE, z);
    println!(
        "{label}: χ² = {:.1}, dof = {}, p = {:.4}, ∫pdf = {mass:.5}",
        out.statistic, out.dof, out.p_value
    );
}

#[test]
fn samples_follow_their_density_and_carry_it() {
    let gold = Conductor::new(ComplexIor::GOLD);
    let glass = Dielectric::new(1.5).unwrap();
    let ggx = Ggx::isotropic(0.5).unwrap();
    let beckmann = Beckmann::new(0.3, 0.6).unwrap();
    check_sampler("gold GGX θ 0.8", &SingleScattering::new(ggx, gold), dir(0.8, 0.3), 11);
    check_sampler("gold Beckmann θ 1.4", &SingleScattering::new(beckmann, gold), dir(1.4, 1.0), 12);
    check_sampler("gold GGX from below θ 1.9", &SingleScattering::new(ggx, gold), dir(1.9, 0.5), 13);
    check_sampler("glass GGX θ 0.5", &SingleScattering::new(ggx, glass), dir(0.5, 2.0), 14);
    check_sampler("glass Beckmann inside θ 2.6", &SingleScattering::new(beckmann, glass), dir(2.6, 0.2), 15);
    // correlated slopes (ρ ≠ 0, φα ≠ 0)
    let e_ggx = microsurface::Elliptical::<Ggx>::from_bivariate(0.5, 0.3, 0.7).unwrap();
    let e_beckmann = microsurface::Elliptical::<Beckmann>::from_ellipse(0.2, 0.6, -1.1).unwrap();
    check_sampler("gold elliptical GGX θ 1.1", &SingleScattering::new(e_ggx, gold), dir(1.1, 2.5), 16);
    check_sampler(
        "glass elliptical Beckmann θ 0.7",
        &SingleScattering::new(e_beckmann, glass),
        dir(0.7, -0.4),
        17,
    );
}

/// `eval_with_pdf` is `(eval, pdf)` bit for bit (deterministic materials), and `eval` is the
/// correlated one-vertex position-free model, over random pairs on the whole sphere.
#[test]
fn eval_with_pdf_is_eval_and_pdf() {
    fn check<S: MicrosurfaceSlope, M: Material>(label: &str, slope: S, material: M, seed: u64) {
        let model = SingleScattering::new(slope, material);
        let pf = PositionFree::new(slope, material, Shadowing::Correlated);
        let mut rng = validation::rng(seed);
        let mut dummy = validation::rng(0);
        let mut nonzero = 0;
        for _ in 0..20_000 {
            let (wi, wo) = (random_direction(&mut rng), random_direction(&mut rng));
            let (f, pdf) = model.eval_with_pdf(wi, wo, &mut dummy);
            let (f1, pdf1) = (model.eval(wi, wo, &mut dummy), model.pdf(wi, wo));
            assert_eq!(pdf.to_bits(), pdf1.to_bits(), "{label}: pdf {pdf} ≠ {pdf1} at {wi}, {wo}");
            assert_eq!(f, f1, "{label}: eval_with_pdf {f} ≠ eval {f1} at {wi}, {wo}");
            assert_eq!(
                f,
                pf.eval_single_scattering(wi, wo, &mut dummy),
                "{label}: ≠ position-free at {wi}, {wo}"
            );
            assert!(f.is_finite() && f.min_element() >= 0.0 && pdf.is_finite() && pdf >= 0.0);
            nonzero += usize::from(f.max_element() > 0.0);
        }
        // the test compares values, not zeros: a good share of the pairs scatter
        assert!(nonzero > 4_000, "{label}: only {nonzero} of 20 000 pairs with f > 0");
    }
    let gold = Conductor::new(ComplexIor::GOLD);
    let glass = Dielectric::new(1.5).unwrap();
    check("gold GGX", Ggx::isotropic(0.5).unwrap(), gold, 21);
    check("gold Beckmann", Beckmann::new(0.2, 0.7).unwrap(), gold, 22);
    check("glass GGX", Ggx::isotropic(0.3).unwrap(), glass, 23);
    check("glass Beckmann", Beckmann::isotropic(0.8).unwrap(), glass, 24);
}

/// The sampler draws what the position-free one-vertex sampler draws from the same uniforms,
/// with its weight (to an f32 ulp), and adds the density.
#[test]
fn sample_is_the_position_free_single_sample() {
    let slope = Beckmann::isotropic(0.4).unwrap();
    let material = Diffuse::new(Vec3::new(0.8, 0.5, 0.2)).unwrap();
    let model = SingleScattering::new(slope, material);
    let pf = PositionFree::new(slope, material, Shadowing::Correlated);
    let mut dirs = validation::rng(31);
    for k in 0..5_000 {
        let wi = random_direction(&mut dirs);
        let a = model.sample(wi, &mut validation::rng(1000 + k));
        let b = pf.sample_single(wi, &mut validation::rng(1000 + k));
        // the same direction; the weight to an f32 ulp (the one-division G2/G1 of a reflection)
        assert_eq!(a.map(|s| s.wo), b.map(|s| s.0), "at {wi}");
        if let (Some(s), Some((_, w))) = (a, b) {
            assert!(rel_close(s.weight, w, 2.0 * f32::EPSILON), "weight {} ≠ {w} at {wi}", s.weight);
        }
        if let Some(s) = a {
            assert_eq!(s.pdf.to_bits(), model.pdf(wi, s.wo).to_bits());
        }
    }
}

/// A named call that returns whether it gave the documented nothing.
type Call = (&'static str, Box<dyn Fn() -> bool>);

/// Invalid directions: 0 and `None` in release builds, a debug assertion in debug builds.
#[test]
fn invalid_directions_give_nothing() {
    let model = SingleScattering::new(Ggx::isotropic(0.5).unwrap(), Conductor::perfect());
    let good = dir(0.5, 0.5);
    for bad in [Vec3::NAN, Vec3::ZERO, 2.0 * good, Vec3::new(f32::INFINITY, 0.0, 0.0)] {
        let calls: [Call; 5] = [
            ("eval wi", Box::new(move || model.eval(bad, good, &mut validation::rng(1)) == Vec3::ZERO)),
            ("eval wo", Box::new(move || model.eval(good, bad, &mut validation::rng(1)) == Vec3::ZERO)),
            ("pdf", Box::new(move || model.pdf(bad, good) == 0.0)),
            (
                "eval_with_pdf",
                Box::new(move || {
                    model.eval_with_pdf(good, bad, &mut validation::rng(1)) == (Vec3::ZERO, 0.0)
                }),
            ),
            ("sample", Box::new(move || model.sample(bad, &mut validation::rng(1)).is_none())),
        ];
        for (name, call) in calls {
            match std::panic::catch_unwind(std::panic::AssertUnwindSafe(&call)) {
                Ok(nothing) => {
                    let debug = cfg!(debug_assertions);
                    assert!(!debug, "{name}({bad}): no debug assertion");
                    assert!(nothing, "{name}({bad}) returned something");
                }
                Err(e) => {
                    let msg = e.downcast_ref::<String>().map_or("", String::as_str);
                    assert!(
                        cfg!(debug_assertions) && msg.starts_with("invalid input"),
                        "{name}({bad}): {msg}"
                    );
                }
            }
        }
    }
}

/// The density of a GGX conductor's front-facing reflection, which `pdf`, `eval_with_pdf` and
/// `sample` form in f32 from the unnormalized half vector (`Ggx`'s stated bound: relative
/// error below 4e-6, independent of α and of the angle between the directions), against an
/// f64 reference D(ωh)/(4 A_b(ωi)) written out here (the bounded cap's area A_b = (L + k cos θi)/2
/// of Eto and Tokuyoshi 2023, eqs. 5, 6 and 8, with a = min(αx, αy), the crate's k for a > 1
/// and its margin of 2⁻²⁰ on 1 + k): every roughness from 1e-4 to 10, anisotropic too,
/// directions down to cos θ = 1e-6 and pairs up to nearly opposite.
#[test]
fn ggx_reflection_density_keeps_its_f32_bound() {
    /// The bound `Ggx::reflection_density_unchecked` states.
    const BOUND: f64 = 4e-6;
    fn reference(ax: f64, ay: f64, wi: Vec3, wo: Vec3) -> f64 {
        let h = (wi.as_dvec3() + wo.as_dvec3()).normalize();
        let t = (h.x / ax).powi(2) + (h.y / ay).powi(2) + h.z * h.z;
        let d = 1.0 / (core::f64::consts::PI * ax * ay * t * t);
        let w = wi.as_dvec3().normalize();
        let q = (ax * w.x).powi(2) + (ay * w.y).powi(2);
        let len = (w.z * w.z + q).sqrt();
        let (a_sq, sin) = (ax.min(ay).powi(2), w.x.hypot(w.y));
        let k = if a_sq <= 1.0 {
            (1.0 - a_sq) * (1.0 + sin) / (1.0 + sin + a_sq * (1.0 - sin))
        } else {
            (1.0 - a_sq) * (1.0 - sin) / (1.0 - sin + a_sq * (1.0 + sin))
        };
        let kappa = ((1.0 + k) * (1.0 + 2f64.powi(-20))).min(2.0);
        // L + k z, written as (L − z) + κ z where k < 0
        let area = 0.5 * if kappa >= 1.0 { len + (kappa - 1.0) * w.z } else { q / (len + w.z) + kappa * w.z };
        d / (4.0 * area)
    }
    let mut rng = validation::rng(41);
    let upper = |rng: &mut validation::TestRng| {
        // cos θ spread over decades down to 1e-6, so grazing pairs are well represented
        let z = 10f32.powf(-6.0 * uniform32(rng)).min(1.0);
        let phi = core::f32::consts::TAU * uniform32(rng);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z).normalize()
    };
    let gold = Conductor::new(ComplexIor::GOLD);
    let (mut worst, mut compared) = (0.0f64, 0usize);
    for (ax, ay) in
        [(1e-4, 1e-4), (1e-3, 1e-3), (0.05, 0.05), (0.5, 0.5), (2.0, 2.0), (10.0, 10.0), (0.02, 0.7)]
    {
        let model = SingleScattering::new(Ggx::new(ax, ay).unwrap(), gold);
        for _ in 0..20_000 {
            let (wi, wo) = (upper(&mut rng), upper(&mut rng));
            if wi.z <= 0.0 || wo.z <= 0.0 {
                continue;
            }
            let exact = reference(f64::from(ax), f64::from(ay), wi, wo);
            if !(exact >= f64::from(f32::MIN_POSITIVE) && exact <= f64::from(f32::MAX)) {
                continue;
            }
            let pdf = f64::from(model.pdf(wi, wo));
            let rel = (pdf - exact).abs() / exact;
            assert!(
                rel <= BOUND,
                "α = ({ax}, {ay}), ωi = {wi}, ωo = {wo}: pdf {pdf:e}, f64 {exact:e}, relative {rel:e}"
            );
            worst = worst.max(rel);
            compared += 1;
        }
    }
    eprintln!(
        "GGX reflection density: {compared} pairs, largest relative error {worst:.2e} (bound {BOUND:e})"
    );
    assert!(compared > 100_000, "only {compared} pairs compared");
}
