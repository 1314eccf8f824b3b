//! Extraction of slope distributions and Fresnel terms from BRDFs by power iteration (Dupuy
//! 2015, §4.2, Algorithms 1–3): bad input, round trips on the crate's own single-scattering
//! GGX and Beckmann BRDFs (height-correlated G2) and on the thesis' backscattering model
//! (eq. 4.3, monostatic G1), the convergence of the iteration, Fresnel extraction, the α fits,
//! and the extraction's cost.

use glam::Vec3;
use microsurface::fresnel::fresnel_conductor;
use microsurface::research::{Microsurface, UniformHeight};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::tabulated::{
    BackscatterShadowing, TabulatedSlope, extract_fresnel, extract_isotropic, extract_isotropic_fn,
};
use microsurface::{Beckmann, ComplexIor, Conductor, Error, Ggx};
use std::f64::consts::FRAC_PI_2;
use validation::dir;

/// The backscattering f_r(o, o) of the crate's single-scattering conductor on `slope`.
fn crate_backscatter<S: MicrosurfaceSlope>(slope: S, ior: Option<ComplexIor>) -> impl Fn(f64) -> f64 {
    let material = ior.map_or(Conductor::perfect(), Conductor::new);
    let surface = Microsurface::new(UniformHeight, slope, material);
    move |theta: f64| {
        let o = dir(theta, 0.0);
        let mut g = validation::rng(0);
        f64::from(surface.eval_single_scattering(o, o, &mut g).x) / f64::from(o.z)
    }
}

/// Max relative error of the extracted ring values against the truth's ring values (ring
/// averages) over θ′ ≤ 60°, and max |ΔG1| over θ ∈ (0, π/2).
fn compare<S: MicrosurfaceSlope>(
    extracted: &TabulatedSlope,
    truth: &S,
    truth_table: &TabulatedSlope,
) -> (f64, f64) {
    let n1 = extracted.rings() as f64 + 1.0;
    let mut worst_p = 0.0f64;
    for (k, (a, b)) in extracted.ring_values().iter().zip(truth_table.ring_values()).enumerate() {
        let v = 1.0 - (k as f64 + 0.5) / n1;
        if FRAC_PI_2 * (1.0 - v * v) > 60f64.to_radians() {
            break;
        }
        worst_p = worst_p.max((a / b - 1.0).abs());
    }
    let mut worst_g1 = 0.0f64;
    for i in 1..60 {
        let w = dir(FRAC_PI_2 * i as f64 / 60.0, 0.0);
        let ge = 1.0 / (1.0 + f64::from(extracted.lambda(w)));
        let gt = 1.0 / (1.0 + f64::from(truth.lambda(w)));
        worst_g1 = worst_g1.max((ge - gt).abs());
    }
    (worst_p, worst_g1)
}

#[test]
fn bad_input_is_an_error() {
    let hc = BackscatterShadowing::HeightCorrelated;
    let cases: [(&str, Result<_, Error>); 6] = [
        ("empty", extract_isotropic(0.5, &[], 4, hc)),
        ("all zero", extract_isotropic(0.5, &[0.0; 16], 4, hc)),
        ("negative", extract_isotropic(0.5, &[1.0, -1.0, 1.0], 4, hc)),
        ("NaN", extract_isotropic(0.5, &[1.0, f64::NAN], 4, hc)),
        ("no iterations", extract_isotropic(0.5, &[1.0; 4], 0, hc)),
        ("fn infinite", extract_isotropic_fn(0.5, 8, 4, hc, |_| f64::INFINITY)),
    ];
    for (label, r) in cases {
        assert!(matches!(r, Err(Error::InvalidParameter { .. })), "{label}: expected an error, got {r:?}");
    }
    assert!(extract_isotropic(f32::NAN, &[1.0; 4], 4, hc).is_err());
}

/// Round trip on the crate's single-scattering conductor (F = 1, height-correlated G2), N = 128
/// rings at s = α, eight iterations: the extracted ring values within 1 % of the truth's ring
/// averages for θ′ ≤ 60° (collocation at the ring centres against ring averages: O(δθ′²)), G1
/// within 2e-3, F0 = 1 within 3e-3·α (the table drops GGX's r⁻⁴ tail beyond R_N, whose
/// back-face moment the data's 1 + 2Λ contains: the same error as in `TabulatedSlope`'s Λ,
/// growing with α), and the α fits (GGX: E|x̃|; Beckmann: √E[r²]) within 1 %.
#[test]
fn round_trip_on_the_crates_single_scattering() {
    let rings = 128;
    for alpha in [0.2f32, 0.5, 1.0] {
        let ggx = Ggx::isotropic(alpha).unwrap();
        let beck = Beckmann::isotropic(alpha).unwrap();
        for (label, truth_table, result, is_ggx) in [
            (
                "GGX",
                TabulatedSlope::from_slope(&ggx, alpha, rings).unwrap(),
                extract_isotropic_fn(
                    alpha,
                    rings,
                    8,
                    BackscatterShadowing::HeightCorrelated,
                    crate_backscatter(ggx, None),
                ),
                true,
            ),
            (
                "Beckmann",
                TabulatedSlope::from_slope(&beck, alpha, rings).unwrap(),
                extract_isotropic_fn(
                    alpha,
                    rings,
                    8,
                    BackscatterShadowing::HeightCorrelated,
                    crate_backscatter(beck, None),
                ),
                false,
            ),
        ] {
            let e = result.unwrap();
            let (worst_p, worst_g1) = if is_ggx {
                compare(&e.slope, &ggx, &truth_table)
            } else {
                compare(&e.slope, &beck, &truth_table)
            };
            let fit = if is_ggx { e.slope.alpha() } else { e.slope.beckmann_alpha() };
            let fit_err = f64::from(fit) / f64::from(alpha) - 1.0;
            println!(
                "{label} α = {alpha}: F0 = {:.6}, worst P rel. error {worst_p:.2e}, worst |ΔG1| {worst_g1:.2e}, \
                 fitted α = {fit:.5} ({fit_err:+.2e}), residuals {:?}",
                e.f0,
                e.residuals.iter().map(|r| format!("{r:.1e}")).collect::<Vec<_>>()
            );
            // the thesis' four iterations, for comparison (printed: for GGX the iterate is not
            // yet converged below the discretization error, e.g. F0 − 1 doubles at α = 0.2)
            let data: Vec<f64> = if is_ggx {
                (0..rings)
                    .map(|i| crate_backscatter(ggx, None)(TabulatedSlope::ring_centre_angle(alpha, rings, i)))
                    .collect()
            } else {
                (0..rings)
                    .map(|i| {
                        crate_backscatter(beck, None)(TabulatedSlope::ring_centre_angle(alpha, rings, i))
                    })
                    .collect()
            };
            let e4 = extract_isotropic(alpha, &data, 4, BackscatterShadowing::HeightCorrelated).unwrap();
            let (p4, g4) = if is_ggx {
                compare(&e4.slope, &ggx, &truth_table)
            } else {
                compare(&e4.slope, &beck, &truth_table)
            };
            println!(
                "    after 4 iterations: F0 = {:.6}, worst P rel. error {p4:.2e}, worst |ΔG1| {g4:.2e}",
                e4.f0
            );
            assert!((e.f0 - 1.0).abs() < 3e-3 * f64::from(alpha), "{label} α = {alpha}: F0 = {}", e.f0);
            assert!(worst_p < 1e-2, "{label} α = {alpha}: P off by {worst_p:.3e}");
            assert!(worst_g1 < 2e-3, "{label} α = {alpha}: G1 off by {worst_g1:.3e}");
            assert!(fit_err.abs() < 1e-2, "{label} α = {alpha}: fitted α = {fit}");
        }
    }
}

/// Round trip on the thesis' backscattering model (eq. 4.3, F0 = 0.7, monostatic G1) of
/// Beckmann α = 0.3, and the convergence of the power iteration: the residual after m = 1…8
/// multiplications decreases, and four (the thesis' choice) reach the stated level.
#[test]
fn round_trip_monostatic_and_convergence() {
    let alpha = 0.3f32;
    let beck = Beckmann::isotropic(alpha).unwrap();
    let s = &beck;
    let f0 = 0.7;
    let data = |theta: f64| {
        let o = dir(theta, 0.0);
        let g1 = 1.0 / (1.0 + f64::from(s.lambda(o)));
        f0 * s.d64(o.as_dvec3()) * g1 / (4.0 * theta.cos().powi(2))
    };
    let e = extract_isotropic_fn(alpha, 128, 8, BackscatterShadowing::Monostatic, data).unwrap();
    let truth = TabulatedSlope::from_slope(&beck, alpha, 128).unwrap();
    let (worst_p, worst_g1) = compare(&e.slope, &beck, &truth);
    println!(
        "monostatic Beckmann: F0 = {:.6}, P {worst_p:.2e}, G1 {worst_g1:.2e}, residuals {:?}",
        e.f0, e.residuals
    );
    assert!((e.f0 - f0).abs() < 1e-3 * f0);
    assert!(worst_p < 1e-2 && worst_g1 < 2e-3);
    // decreasing until it reaches the rounding level
    for m in 1..e.residuals.len() {
        assert!(
            e.residuals[m] <= e.residuals[m - 1] * 1.0001 || e.residuals[m] < 1e-12,
            "residual grew at {m}: {:?}",
            e.residuals
        );
    }
    assert!(e.residuals[3] < 1e-10, "four iterations: residual {:.3e}", e.residuals[3]);
}

/// Fresnel extraction (Algorithm 2) from the crate's single-scattering gold conductor on
/// GGX α = 0.5: the extracted F(θd) within 2 % of the exact Fresnel (red channel) for θd up to
/// 75°, and the eigenvalue within 1 % of F(0).
#[test]
fn fresnel_round_trip() {
    let alpha = 0.5;
    let ggx = Ggx::isotropic(alpha).unwrap();
    let gold = ComplexIor::new(Vec3::new(0.143, 0.374, 1.442), Vec3::new(3.983, 2.385, 1.603)).unwrap();
    let e = extract_isotropic_fn(
        alpha,
        128,
        8,
        BackscatterShadowing::HeightCorrelated,
        crate_backscatter(ggx, Some(gold)),
    )
    .unwrap();
    let f_normal = f64::from(fresnel_conductor(1.0, &gold).x);
    println!("gold: F0 extracted {:.5}, exact {f_normal:.5}", e.f0);
    assert!((e.f0 / f_normal - 1.0).abs() < 1e-2);
    let surface = Microsurface::new(UniformHeight, ggx, Conductor::new(gold));
    let bins = 12;
    let fresnel = extract_fresnel(&e.slope, BackscatterShadowing::HeightCorrelated, bins, 24, 24, |i, o| {
        let mut g = validation::rng(0);
        f64::from(surface.eval_single_scattering(i, o, &mut g).x) / f64::from(o.z)
    });
    for (b, f) in fresnel.iter().enumerate() {
        let theta_d = (b as f64 + 0.5) * FRAC_PI_2 / bins as f64;
        let exact = f64::from(fresnel_conductor(theta_d.cos() as f32, &gold).x);
        let f = f.expect("valid configurations");
        println!("θd = {:.1}°: F extracted {f:.5}, exact {exact:.5}", theta_d.to_degrees());
        if theta_d < 75f64.to_radians() {
            assert!((f / exact - 1.0).abs() < 2e-2, "θd = {theta_d}: {f} vs {exact}");
        }
    }
}

/// The cost of the extraction at N = 256 (printed; no timed assertion).
#[test]
fn extraction_cost() {
    let ggx = Ggx::isotropic(0.5).unwrap();
    let data: Vec<f64> = (0..256)
        .map(|i| crate_backscatter(ggx, None)(TabulatedSlope::ring_centre_angle(0.5, 256, i)))
        .collect();
    let start = std::time::Instant::now();
    let e = extract_isotropic(0.5, &data, 4, BackscatterShadowing::HeightCorrelated).unwrap();
    println!("N = 256, 4 iterations: {:.2} ms, F0 = {:.5}", start.elapsed().as_secs_f64() * 1e3, e.f0);
    assert!(e.f0.is_finite());
}

/// Beyond the thesis: extraction from a BRDF with multiple scattering (the crate's walk on a
/// conductor F = 1 with GGX α = 1, where single scattering keeps about 69 % of the energy at
/// normal incidence... and the rest leaves after two or more bounces). Measured: the thesis'
/// single-scattering inversion of the walk's backscattering, and an inversion that models
/// multiple scattering by iterating the extraction on f_walk − (higher orders of the walk on the
/// current estimate), each against the true GGX (F0, fitted α, max |ΔG1|, max relative P error).
///
/// Asserted: the single-scattering inversion is biased (its F0 exceeds 1 by more than 5σ of
/// the data's noise: backscattered multiple scattering is read as extra specular energy), and
/// eight rounds of the multiple-scattering-aware inversion bring F0 back within 4σ + 2e-3 of 1
/// and the fitted α closer to the truth. Measured (4000 walks per angle, 48 angles): the
/// single-scattering inversion gives F0 = 2.47, α = 0.63, max |ΔG1| = 0.16; rounds 1–8 of the
/// corrected inversion give F0 = 1.57, 1.28, 1.17, 1.13, 1.11, 1.10, 1.09, 1.08 and α = 0.79,
/// 0.86, 0.90, 0.91, 0.92, 0.935, 0.939, 0.939 (max |ΔG1| 0.021 after 8): the error halves in
/// the first rounds, then the progress slows to a few per cent per round (not converged after
/// eight; the per-ring P stays noisy, 30–50 % relative at θ′ ≤ 60°, from the data's noise).
#[test]
fn multiple_scattering_inversion() {
    use microsurface::research::ScatteringOrder;
    let alpha = 1.0f32;
    let rings = 48;
    let samples = 4000;
    let ggx = Ggx::isotropic(alpha).unwrap();
    let truth = TabulatedSlope::from_slope(&ggx, alpha, rings).unwrap();
    let angles: Vec<f64> = (0..rings).map(|i| TabulatedSlope::ring_centre_angle(alpha, rings, i)).collect();
    // the walk's backscattering (all orders) and its standard error, per angle; and the higher
    // orders (all minus the exact single scattering) of the walk on a given slope
    let backscatter = |slope: &TabulatedSlope, seed: u64| -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let surface = Microsurface::new(UniformHeight, slope, Conductor::perfect());
        let rows = validation::par_map(&angles, |i, &theta| {
            let o = dir(theta, 0.0);
            let mut g = validation::rng(seed + i as u64);
            let mut st = validation::Stats::default();
            for _ in 0..samples {
                st.push(f64::from(surface.eval(o, o, ScatteringOrder::All, &mut g).x) / f64::from(o.z));
            }
            let single = f64::from(surface.eval_single_scattering(o, o, &mut g).x) / f64::from(o.z);
            (st.mean(), st.se(), st.mean() - single)
        });
        (
            rows.iter().map(|r| r.0).collect(),
            rows.iter().map(|r| r.1).collect(),
            rows.iter().map(|r| r.2).collect(),
        )
    };
    // the data: the walk on the (tabulated) truth, so that the table is the exact answer
    let (data, data_se, _) = backscatter(&truth, 1000);
    let summary = |label: &str, e: &microsurface::tabulated::Extraction| {
        let (p, g1) = compare(&e.slope, &ggx, &truth);
        println!(
            "{label}: F0 = {:.4}, fitted α = {:.4}, max |ΔG1| = {g1:.3e}, max P rel. error (θ′ ≤ 60°) = {p:.3e}",
            e.f0,
            e.slope.alpha()
        );
    };
    let hc = BackscatterShadowing::HeightCorrelated;
    let single = extract_isotropic(alpha, &data, 8, hc).unwrap();
    summary("single-scattering inversion", &single);
    // the noise of F0: the eigenvalue is a weighted mean of the data ratios; bound its SE by
    // the largest relative SE of the data
    let rel_se = data.iter().zip(&data_se).map(|(d, s)| s / d).fold(0.0f64, f64::max);
    println!("largest relative SE of the data: {rel_se:.2e} ({samples} walks per angle, {rings} angles)");
    assert!(single.f0 - 1.0 > 5.0 * rel_se, "single-scattering inversion F0 = {}", single.f0);
    let mut estimate = single.clone();
    for round in 1..=8 {
        let (_, _, higher) = backscatter(&estimate.slope, 2000 * round);
        let corrected: Vec<f64> = data.iter().zip(&higher).map(|(d, h)| (d - h).max(0.0)).collect();
        estimate = extract_isotropic(alpha, &corrected, 8, hc).unwrap();
        summary(&format!("multiple-scattering-aware inversion, round {round}"), &estimate);
    }
    assert!((estimate.f0 - 1.0).abs() <= 4.0 * rel_se + 2e-3, "corrected F0 = {}", estimate.f0);
    assert!(
        (estimate.slope.alpha() - alpha).abs() < (single.slope.alpha() - alpha).abs(),
        "the corrected fit is not closer: {} vs {}",
        estimate.slope.alpha(),
        single.slope.alpha()
    );
}

/// Algorithm 1 on the 2D grid: round trip on the crate's single-scattering anisotropic GGX
/// (0.3, 0.6) (F = 1, height-correlated G2), 2 × 24 cells per axis: F0 within 2e-2 of 1, Λ
/// within 15 % of the grid tabulation of the truth (cell averages; the extraction collocates
/// at the cell centres) where Λ > 1e-2, and the GGX-equivalent roughnesses within 3 % of the
/// tabulated truth's; the residuals after 1–8 iterations are printed. The errors are the
/// collocation error of the coarse grid: measured at 2 × 16 cells F0 = 1.019, Λ 15 %, α +2.7 %;
/// at 2 × 24 cells F0 = 1.010, Λ 8.7 %, α +1.5 % (about (16/24)^1.7).
#[test]
fn anisotropic_round_trip() {
    use microsurface::tabulated::{GridSlope, extract_anisotropic_fn};
    let ggx = Ggx::new(0.3, 0.6).unwrap();
    let surface = Microsurface::new(UniformHeight, ggx, Conductor::perfect());
    let start = std::time::Instant::now();
    let e = extract_anisotropic_fn(0.3, 0.6, 24, 8, BackscatterShadowing::HeightCorrelated, |o| {
        let mut g = validation::rng(0);
        f64::from(surface.eval_single_scattering(o, o, &mut g).x) / f64::from(o.z)
    })
    .unwrap();
    let elapsed = start.elapsed().as_secs_f64();
    let truth = GridSlope::from_fn(0.3, 0.6, 24, |x, y| {
        let t = 1.0 + x * x / 0.09 + y * y / 0.36;
        1.0 / (std::f64::consts::PI * 0.18 * t * t)
    })
    .unwrap();
    let (s, t) = (&e.slope, &truth);
    let mut worst = 0.0f64;
    for i in 1..30 {
        for k in 0..8 {
            let w = dir(1.5 * i as f64 / 30.0, k as f64 * 0.785);
            let (le, lt) = (f64::from(s.lambda(w)), f64::from(t.lambda(w)));
            if lt > 1e-2 {
                worst = worst.max((le / lt - 1.0).abs());
            }
        }
    }
    println!(
        "anisotropic GGX (0.3, 0.6), 48 × 48 cells ({} ms): F0 = {:.5}, worst Λ rel. error vs the tabulated truth {worst:.3e}, \
         α = ({:.4}, {:.4}) vs tabulated truth ({:.4}, {:.4}), residuals {:?}",
        (elapsed * 1e3) as u32,
        e.f0,
        s.alpha_x(),
        s.alpha_y(),
        t.alpha_x(),
        t.alpha_y(),
        e.residuals.iter().map(|r| format!("{r:.1e}")).collect::<Vec<_>>()
    );
    assert!((e.f0 - 1.0).abs() < 2e-2, "F0 = {}", e.f0);
    assert!(worst < 0.15, "Λ off by {worst:.3e}");
    assert!((s.alpha_x() / t.alpha_x() - 1.0).abs() < 3e-2 && (s.alpha_y() / t.alpha_y() - 1.0).abs() < 3e-2);
}

/// The Fresnel extraction (Algorithm 2) on the 2D grid, the anisotropic path written once with
/// the isotropic one (`extract_fresnel` takes any slope and averages over the half vector's
/// azimuth for an anisotropic one). With the exact slope, the analytic anisotropic GGX
/// (0.3, 0.6), the crate's single-scattering gold conductor on it gives back gold's Fresnel
/// (red channel) within 1e-6 for θd up to 75° (measured 2e-8: the BRDF is that model's own
/// D G F/(4 cos cos)): the configurations and the average are right.
/// Then the round trip: the grid extracted from that BRDF (2 × 24 cells per axis, eight
/// iterations), F(θd) from the same BRDF on the grid within 3 % (measured 2.2 %: the grid's D
/// and Λ at this resolution; 8 % at 2 × 16 cells), and the eigenvalue F0 within 2 % of F(0)
/// (measured 1.0 %).
#[test]
fn grid_fresnel_round_trip() {
    use microsurface::tabulated::extract_anisotropic_fn;
    let ggx = Ggx::new(0.3, 0.6).unwrap();
    let gold = ComplexIor::new(Vec3::new(0.143, 0.374, 1.442), Vec3::new(3.983, 2.385, 1.603)).unwrap();
    let surface = Microsurface::new(UniformHeight, ggx, Conductor::new(gold));
    let brdf = |i: Vec3, o: Vec3| {
        let mut g = validation::rng(0);
        f64::from(surface.eval_single_scattering(i, o, &mut g).x) / f64::from(o.z)
    };
    let hc = BackscatterShadowing::HeightCorrelated;
    let bins = 8;
    let worst_error = |fresnel: &[Option<f64>], label: &str| {
        let mut worst = 0.0f64;
        for (b, f) in fresnel.iter().enumerate() {
            let theta_d = (b as f64 + 0.5) * FRAC_PI_2 / bins as f64;
            let exact = f64::from(fresnel_conductor(theta_d.cos() as f32, &gold).x);
            let f = f.expect("valid configurations");
            println!("{label}, θd = {:.1}°: F extracted {f:.5}, exact {exact:.5}", theta_d.to_degrees());
            if theta_d < 75f64.to_radians() {
                worst = worst.max((f / exact - 1.0).abs());
            }
        }
        worst
    };
    let exact_slope = worst_error(&extract_fresnel(ggx, hc, bins, 16, 16, brdf), "analytic GGX (0.3, 0.6)");
    assert!(exact_slope < 1e-6, "F(θd) on the exact slope off by {exact_slope:.3e}");
    let e = extract_anisotropic_fn(0.3, 0.6, 24, 8, hc, |o| brdf(o, o)).unwrap();
    let worst = worst_error(&extract_fresnel(&e.slope, hc, bins, 16, 16, brdf), "grid 2 × 24");
    let f_normal = f64::from(fresnel_conductor(1.0, &gold).x);
    println!(
        "grid gold: F0 extracted {:.5}, exact {f_normal:.5}; worst F(θd) relative error {worst:.3e} (exact slope {exact_slope:.1e})",
        e.f0
    );
    assert!((e.f0 / f_normal - 1.0).abs() < 2e-2, "F0 = {} vs {f_normal}", e.f0);
    assert!(worst < 3e-2, "F(θd) off by {worst:.3e}");
}
