//! The height distributions: the round trip c1(inv_c1(u)) = u, the documented end values,
//! the density against the CDF by quadrature, the Gaussian CDF against statrs, and no NaN.

use microsurface::research::{GaussianHeight, MicrosurfaceHeight, UniformHeight};
use validation::check::ulp32;

/// Half the f32 spacing at 1: the rounding of a value in [½, 1].
const HALF_ULP_1: f64 = f32::EPSILON as f64 * 0.5;

/// The uniforms of the round trip: 0, 1, a dense uniform grid, every f32 within 2¹⁶ ulps of 1,
/// and a log grid of tiny u down to the smallest subnormal.
fn round_trip_uniforms() -> Vec<f32> {
    let mut us = vec![0.0, 1.0, 1e-45, f32::MIN_POSITIVE, 0.5];
    let n = 1 << 20;
    us.extend((1..n).map(|k| (k as f64 / n as f64) as f32));
    let mut u = 1.0f32;
    for _ in 0..(1 << 16) {
        u = u.next_down();
        us.push(u);
    }
    let m = 20_000;
    us.extend(
        (0..=m).map(|k| (0.5f64.ln() + (1e-45f64.ln() - 0.5f64.ln()) * k as f64 / m as f64).exp() as f32),
    );
    us
}

/// The heights of the density and CDF checks: a dense grid of [−20, 20] plus the extremes.
fn height_grid() -> Vec<f32> {
    let n = 400_000;
    let mut hs: Vec<f32> = (0..=n).map(|k| (-20.0 + 40.0 * k as f64 / n as f64) as f32).collect();
    hs.extend([-1.0, 1.0, -1.0f32.next_up(), 1.0f32.next_down(), 1.0f32.next_up(), -1.0f32.next_down()]);
    hs.extend([0.0, -0.0, 16.0, -16.0, 1e30, -1e30, f32::MAX, -f32::MAX]);
    hs
}

/// Checks what both distributions share: no NaN, c1 in [0, 1] and monotone, inv_c1 monotone,
/// c1(±∞) = 1/0 and p1(±∞) = 0.
fn check_common(name: &str, height: impl MicrosurfaceHeight) {
    let mut hs = height_grid();
    hs.sort_by(f32::total_cmp);
    let mut last = 0.0f32;
    for &h in &hs {
        let (p, c) = (height.p1(h), height.c1(h));
        assert!(p.is_finite() && p >= 0.0, "{name}: p1({h}) = {p}");
        assert!((0.0..=1.0).contains(&c), "{name}: c1({h}) = {c}");
        assert!(c >= last, "{name}: c1 decreases at {h}");
        last = c;
    }
    let mut us = round_trip_uniforms();
    us.sort_by(f32::total_cmp);
    let mut last = f32::NEG_INFINITY;
    for &u in &us {
        let h = height.inv_c1(u);
        assert!(h.is_finite(), "{name}: inv_c1({u:e}) = {h}");
        assert!(h >= last, "{name}: inv_c1 decreases at {u:e}");
        last = h;
    }
    assert_eq!(height.c1(f32::INFINITY), 1.0, "{name}: c1(+∞)");
    assert_eq!(height.c1(f32::NEG_INFINITY), 0.0, "{name}: c1(−∞)");
    assert_eq!(height.p1(f32::INFINITY), 0.0, "{name}: p1(+∞)");
    assert_eq!(height.p1(f32::NEG_INFINITY), 0.0, "{name}: p1(−∞)");
}

/// ∫ₐᵇ f by composite 8-point Gauss–Legendre on `panels` equal panels (f64).
fn gauss_legendre(f: impl Fn(f64) -> f64, a: f64, b: f64, panels: usize) -> f64 {
    const NODES: [(f64, f64); 4] = [
        (0.183_434_642_495_649_8, 0.362_683_783_378_362),
        (0.525_532_409_916_329, 0.313_706_645_877_887_3),
        (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
        (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
    ];
    let width = (b - a) / panels as f64;
    let mut sum = 0.0;
    for k in 0..panels {
        let (c, r) = (a + width * (k as f64 + 0.5), 0.5 * width);
        for (x, w) in NODES {
            sum += w * r * (f(c - r * x) + f(c + r * x));
        }
    }
    sum
}

/// c1(h) against ∫ p1 from `lo` to h, cumulated over panels of `step` (the panel edges are at
/// every multiple of `step`, so the uniform density's jumps at ±1 fall on edges).
/// Returns the maximum absolute difference and the total mass.
fn check_c1_is_integral_of_p1(height: impl MicrosurfaceHeight, lo: f64, hi: f64, step: f64) -> (f64, f64) {
    let p1 = |h: f64| f64::from(height.p1(h as f32));
    let (mut cumulative, mut max_diff) = (0.0, 0.0f64);
    let panels = ((hi - lo) / step).round() as usize;
    for k in 0..panels {
        let (a, b) = (lo + step * k as f64, lo + step * (k + 1) as f64);
        cumulative += gauss_legendre(p1, a, b, 1);
        max_diff = max_diff.max((cumulative - f64::from(height.c1(b as f32))).abs());
    }
    (max_diff, cumulative)
}

#[test]
fn uniform_height() {
    let height = UniformHeight;
    check_common("uniform", height);
    // documented end values
    assert_eq!(height.inv_c1(0.0), -1.0);
    assert_eq!(height.inv_c1(1.0), 1.0);
    assert_eq!(height.c1(-1.0), 0.0);
    assert_eq!(height.c1(1.0), 1.0);
    assert_eq!(height.c1(-5.0), 0.0);
    assert_eq!(height.c1(5.0), 1.0);
    assert_eq!(height.p1(0.3), 0.5);
    assert_eq!(height.p1(1.5), 0.0);
    // round trip: 2u − 1 rounds to the f32 spacing of [−1, 1] (at most 2⁻²⁴ absolute), and
    // (h + 1)/2 rounds once more: |c1(inv_c1(u)) − u| ≤ 2⁻²⁴ absolute
    let mut max_err = 0.0f64;
    for u in round_trip_uniforms() {
        let back = height.c1(height.inv_c1(u));
        max_err = max_err.max((f64::from(back) - f64::from(u)).abs());
    }
    println!("uniform: max |c1(inv_c1(u)) − u| = {max_err:.3e} (bound 2⁻²⁴ = {HALF_ULP_1:.3e})");
    assert!(max_err <= HALF_ULP_1, "uniform round trip: {max_err:e}");
    for u in [0.0f32, 1.0, 0.5, 0.25, 0.75] {
        assert_eq!(height.c1(height.inv_c1(u)), u, "uniform round trip is exact at {u}");
    }
    // p1 integrates to 1 and c1 is its integral
    let (diff, mass) = check_c1_is_integral_of_p1(height, -2.0, 2.0, 1.0 / 64.0);
    println!("uniform: ∫p1 = {mass:.12}, max |c1 − ∫p1| = {diff:.3e}");
    assert!((mass - 1.0).abs() < 1e-12, "uniform: ∫p1 = {mass}");
    assert!(diff < 1e-7, "uniform: c1 differs from ∫p1 by {diff:e}");
}

/// C¹ of the standard normal in double precision (statrs).
fn gaussian_c1_reference(h: f64) -> f64 {
    0.5 * statrs::function::erf::erfc(-h / std::f64::consts::SQRT_2)
}

#[test]
fn gaussian_height() {
    let height = GaussianHeight;
    check_common("gaussian", height);
    // documented end values: ∓H_MAX, where c1 rounds to exactly 0 and 1
    assert_eq!(height.inv_c1(0.0), -GaussianHeight::H_MAX);
    assert_eq!(height.inv_c1(1.0), GaussianHeight::H_MAX);
    assert_eq!(height.c1(-GaussianHeight::H_MAX), 0.0);
    assert_eq!(height.c1(GaussianHeight::H_MAX), 1.0);
    assert_eq!(height.c1(height.inv_c1(0.0)), 0.0);
    assert_eq!(height.c1(height.inv_c1(1.0)), 1.0);
    // the extreme finite heights: the quantile of the smallest subnormal 2⁻¹⁴⁹ is
    // −14.121 426 613 (mpmath), so |h| < 14.13 inside (0, 1) (the doc states 14.1)
    let lowest = height.inv_c1(1e-45);
    let highest = height.inv_c1(1.0f32.next_down());
    println!("gaussian: inv_c1(2⁻¹⁴⁹) = {lowest}, inv_c1(1 − 2⁻²⁴) = {highest}");
    assert!((f64::from(lowest) + 14.121_426_613_350_5).abs() < 2e-6, "inv_c1(2⁻¹⁴⁹) = {lowest}");
    assert!(lowest > -14.13 && highest < 14.13);

    // c1 against statrs: within one f32 rounding (relative) wherever the result is normal
    let mut c1_err = 0.0f64;
    for h in height_grid() {
        let reference = gaussian_c1_reference(f64::from(h));
        let c = f64::from(height.c1(h));
        if reference >= f64::from(f32::MIN_POSITIVE) {
            c1_err = c1_err.max((c - reference).abs() / reference);
        } else {
            assert!(c <= f64::from(f32::MIN_POSITIVE), "gaussian c1({h}) = {c:e}");
        }
    }
    println!("gaussian: c1 max relative error vs statrs {c1_err:.3e}");
    assert!(c1_err <= f64::from(f32::EPSILON), "gaussian c1 relative error {c1_err:e}");

    // round trip: the f32 rounding of h (relative 2⁻²⁴) moves C¹ by p1(h)·|h|·2⁻²⁴, which is
    // at most (1 + h²)·2⁻²⁴ relative to the tail mass min(u, 1 − u) (Mills' ratio
    // p1(h)/tail ≤ |h| + 1/|h|); the final rounding of c1 adds half an ulp of u
    let (mut worst, mut worst_u) = (0.0f64, 0.0f32);
    for u in round_trip_uniforms() {
        let h = height.inv_c1(u);
        let back = height.c1(h);
        let (u64_, h64) = (f64::from(u), f64::from(h));
        let tail = u64_.min(1.0 - u64_);
        let bound = 2.0 * (1.0 + h64 * h64) * HALF_ULP_1 * tail + 0.5 * ulp32(f64::from(u));
        let ratio = (f64::from(back) - u64_).abs() / bound;
        if ratio > worst {
            worst = ratio;
            worst_u = u;
        }
    }
    println!("gaussian: max |c1(inv_c1(u)) − u| / bound = {worst:.3} (at u = {worst_u:e})");
    assert!(worst <= 1.0, "gaussian round trip at u = {worst_u:e}: {worst:.3} × the bound");

    // p1 integrates to 1 and c1 is its integral (f32 p1: relative 1e-7)
    let (diff, mass) = check_c1_is_integral_of_p1(height, -16.0, 16.0, 1.0 / 16.0);
    println!("gaussian: ∫p1 = {mass:.12}, max |c1 − ∫p1| = {diff:.3e}");
    assert!((mass - 1.0).abs() < 2e-7, "gaussian: ∫p1 = {mass}");
    assert!(diff < 2e-7, "gaussian: c1 differs from ∫p1 by {diff:e}");
}
