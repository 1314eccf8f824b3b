//! The tabulated anisotropic slope distribution on a 2D slope grid (`GridSlope`): bad input,
//! the exact projected area against brute-force quadrature, the interpolated Λ against it,
//! Λ(−ω) = −1 − Λ(ω), chi-square tests of the exact sampler on the whole sphere on a rotated
//! anisotropic GGX (no analytic model in the crate), agreement with the analytic anisotropic
//! GGX, and the white furnace of the walk.

use glam::Vec3;
use microsurface::research::{Microsurface, ScatteringOrder, UniformHeight};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::tabulated::GridSlope;
use microsurface::{Conductor, Ggx};
use std::f64::consts::{PI, TAU};
use validation::chi2::{Chi2Grid, chi2_test};
use validation::{Stats, assert_mean, dir, family_z, rng, sidak, uniform32, uniform64};

/// GGX (αx, αy) rotated by ψ in the slope plane.
fn rotated_ggx(ax: f64, ay: f64, psi: f64) -> impl Fn(f64, f64) -> f64 {
    move |x, y| {
        let (s, c) = psi.sin_cos();
        let (u, v) = (c * x + s * y, -s * x + c * y);
        let t = 1.0 + u * u / (ax * ax) + v * v / (ay * ay);
        1.0 / (PI * ax * ay * t * t)
    }
}

#[test]
fn bad_input_is_an_error() {
    assert!(GridSlope::from_p22(1.0, 1.0, 2, &[1.0; 16]).is_ok());
    assert!(GridSlope::from_p22(1.0, 1.0, 2, &[1.0; 15]).is_err());
    assert!(GridSlope::from_p22(1.0, 1.0, 2, &[0.0; 16]).is_err());
    let mut neg = [1.0; 16];
    neg[3] = -1.0;
    assert!(GridSlope::from_p22(1.0, 1.0, 2, &neg).is_err());
    neg[3] = f64::NAN;
    assert!(GridSlope::from_p22(1.0, 1.0, 2, &neg).is_err());
    assert!(GridSlope::from_p22(0.0, 1.0, 2, &[1.0; 16]).is_err());
    assert!(GridSlope::from_p22(1.0, 1.0, 0, &[]).is_err());
    assert!(GridSlope::from_fn(1.0, 1.0, 4, |_, _| f64::NAN).is_err());
}

/// The closed-form projected area against brute-force midpoint quadrature over the slope cells
/// (1e-5: the midpoint rule on the kinked integrand), on a small non-separable table.
#[test]
fn projected_area_exact_against_quadrature() {
    let n = 3;
    let m = 2 * n;
    let values: Vec<f64> = (0..m * m).map(|k| 1.0 + ((k * 7) % 5) as f64).collect();
    let t = GridSlope::from_p22(0.6, 0.9, n, &values).unwrap();
    // rebuild the boundaries as the documentation states
    let b = |s: f64| -> Vec<f64> {
        let half: Vec<f64> = (0..=n)
            .map(|k| {
                let v = 1.0 - k as f64 / (n as f64 + 1.0);
                s * (std::f64::consts::FRAC_PI_2 * (1.0 - v * v)).tan()
            })
            .collect();
        half.iter().rev().map(|v| -v).chain(half[1..].iter().copied()).collect()
    };
    let (xs, ys) = (b(0.6), b(0.9));
    let mut total = 0.0;
    for j in 0..m {
        for i in 0..m {
            total += values[j * m + i] * (xs[i + 1] - xs[i]) * (ys[j + 1] - ys[j]);
        }
    }
    let mut g = rng(4);
    for _ in 0..12 {
        let w = dir(uniform64(&mut g) * PI, uniform64(&mut g) * TAU).as_dvec3().normalize();
        let mut quad = 0.0;
        let k = 120;
        for j in 0..m {
            for i in 0..m {
                let (dx, dy) = ((xs[i + 1] - xs[i]) / k as f64, (ys[j + 1] - ys[j]) / k as f64);
                let mut cell = 0.0;
                for a in 0..k {
                    for c in 0..k {
                        let x = xs[i] + (a as f64 + 0.5) * dx;
                        let y = ys[j] + (c as f64 + 0.5) * dy;
                        cell += (w.z - x * w.x - y * w.y).max(0.0);
                    }
                }
                quad += values[j * m + i] / total * cell * dx * dy;
            }
        }
        let exact = t.projected_area_exact(w.as_vec3());
        assert!((quad - exact).abs() < 1e-5 * (1.0 + exact), "ω = {w}: quadrature {quad} vs exact {exact}");
    }
}

/// Interpolated Λ and projected area against the exact sum (rotated GGX, 2 × 24 cells per
/// axis), Λ(−ω) = −1 − Λ(ω) bitwise from above, and the horizon/pole values.
#[test]
fn interpolated_area_and_symmetry() {
    let t = GridSlope::from_fn(0.4, 0.4, 24, rotated_ggx(0.25, 0.6, 0.5)).unwrap();
    let s = &t;
    let mut g = rng(8);
    let mut worst = 0.0f64;
    for _ in 0..3000 {
        let w = dir((uniform64(&mut g) * 2.0 - 1.0).acos(), uniform64(&mut g) * TAU);
        let exact = t.projected_area_exact(w);
        if exact > 1e-4 {
            worst = worst.max((f64::from(s.projected_area(w)) / exact - 1.0).abs());
        }
        if w.z >= 0.0 {
            assert_eq!(s.lambda(-w), -1.0 - s.lambda(w));
        }
    }
    println!("worst relative interpolation error of the projected area: {worst:.3e}");
    assert!(worst < 1e-2, "interpolated projected area off by {worst:.3e}");
    assert_eq!(s.projected_area(Vec3::Z), 1.0);
    assert_eq!(s.projected_area(-Vec3::Z), 0.0);
}

/// Chi-square of `sample_d_wi` on the rotated anisotropic GGX (2 × 8 cells per axis) from
/// directions off the axes, grazing and below the horizon (the harness also checks ∫D_ωi = 1).
#[test]
fn sampler_chi2() {
    let t = GridSlope::from_fn(0.4, 0.4, 8, rotated_ggx(0.25, 0.6, 0.5)).unwrap();
    let s = &t;
    let cases = [(0.0, 0.0), (0.8, 0.7), (1.45, 2.0), (2.1, 4.0)];
    let alpha = sidak(1e-3, cases.len());
    let grid = Chi2Grid { quad_tol: 1e-6, max_depth: 8, ..Chi2Grid::sphere(12, 16) };
    validation::par_map(&cases, |k, &(theta, phi)| {
        let mut g = rng(0x9d + k as u64);
        let wi = dir(theta, phi);
        let out = chi2_test(
            &format!("grid θi = {theta}, φi = {phi}"),
            grid,
            |m| f64::from(s.d_wi(wi, m)),
            || Some(s.sample_d_wi(wi, uniform32(&mut g), uniform32(&mut g))),
            50_000,
            alpha,
            1.0,
        );
        println!(
            "grid θi = {theta}, φi = {phi}: χ² = {:.1}, dof = {}, p = {:.3}",
            out.statistic, out.dof, out.p_value
        );
    });
}

/// Tabulating the anisotropic GGX (0.3, 0.7) with 2 × 48 cells per axis: |ΔΛ| ≤ 1e-2·Λ +
/// 4e-3·αᵢ tan θ. The absolute part is the tail error of the piecewise-constant cells (they
/// overestimate the first moment of GGX's heavy tail, as the rings do, but the grid is coarser:
/// the back-face area error is ≈ 2e-3·αᵢ sin θ measured, interpolation ≤ 2e-5 of it); the
/// interpolation of B is measured separately. Then the white furnace of the walk (conductor
/// F = 1) on the rotated GGX.
#[test]
fn reproduces_ggx_and_white_furnace() {
    let t = GridSlope::from_fn(0.3, 0.7, 48, rotated_ggx(0.3, 0.7, 0.0)).unwrap();
    let ggx = Ggx::new(0.3, 0.7).unwrap();
    let s = &t;
    let mut g = rng(2);
    let (mut worst, mut worst_rel) = (0.0f64, 0.0f64);
    for _ in 0..500 {
        let theta = uniform64(&mut g) * 1.45;
        let w = dir(theta, uniform64(&mut g) * TAU);
        let (lt, la) = (f64::from(s.lambda(w)), f64::from(ggx.lambda(w)));
        let ai = f64::from(ggx.alpha_i(w));
        worst = worst.max((lt - la).abs() / (1e-2 * la + 4e-3 * ai * theta.tan()));
        if la > 1e-2 {
            worst_rel = worst_rel.max((lt / la - 1.0).abs());
        }
    }
    println!(
        "grid GGX (0.3, 0.7), 96 × 96 cells: worst Λ rel. error (Λ > 1e-2) {worst_rel:.3e}, \
         worst Λ error / bound {worst:.2}"
    );
    assert!(worst <= 1.0, "Λ off by {worst:.3} times its bound");

    let rot = GridSlope::from_fn(0.4, 0.4, 12, rotated_ggx(0.25, 0.6, 0.5)).unwrap();
    let surface = Microsurface::new(UniformHeight, &rot, Conductor::perfect());
    let wi = dir(0.9, 1.1);
    let mut stats = Stats::default();
    for _ in 0..60_000 {
        let wo = microsurface::research::sample_cosine_hemisphere(uniform32(&mut g), uniform32(&mut g));
        let pdf = f64::from(wo.z) / PI;
        stats.push(if pdf > 0.0 {
            f64::from(surface.eval(wi, wo, ScatteringOrder::All, &mut g).x) / pdf
        } else {
            0.0
        });
    }
    assert_mean("grid white furnace", &stats, 1.0, family_z(1e-3, 1), 1e-2, 0.0);
}
