//! The tail model of `TabulatedSlope` (`Tail::Continued`: the last ring's factor continued to
//! every slope beyond R_N): normalization with the tail, Λ of a tabulated GGX against the
//! analytic one over the whole sphere (the model is GGX(s) modulated ring by ring, so the
//! tabulated GGX with the tail is GGX up to the rounding of its tables), D, and exact sampling
//! of the directions that see only the tail.

use glam::{DVec3, Vec3};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::tabulated::{TabulatedSlope, Tail};
use microsurface::{Beckmann, Ggx};
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use validation::chi2::SlopeGrid;
use validation::quadrature::CrossMap;
use validation::{dir, rng, sidak, uniform32, uniform64};

fn ggx_p22(alpha: f64) -> impl Fn(f64) -> f64 {
    move |r: f64| {
        let t = 1.0 + r * r / (alpha * alpha);
        1.0 / (PI * alpha * alpha * t * t)
    }
}

/// The non-analytic test distribution of `tabulated.rs`: ½ GGX(0.15) + ½ GGX(0.7).
fn mixture(rings: usize) -> TabulatedSlope {
    let (a, b) = (ggx_p22(0.15), ggx_p22(0.7));
    TabulatedSlope::from_radial_fn(0.3, rings, |r| 0.5 * a(r) + 0.5 * b(r)).unwrap()
}

/// The directions of the sphere the Λ test covers: 4000 polar angles uniform in cos θ (both
/// hemispheres), and f32 directions within sin θ = 10⁻¹ … 10⁻³⁸ of either pole (where z rounds
/// to ±1 and Λ follows from the horizontal components alone).
fn sphere_directions() -> Vec<Vec3> {
    let mut w: Vec<Vec3> =
        (0..4000).map(|i| dir((-1.0 + 2.0 * (i as f64 + 0.5) / 4000.0).acos(), 0.7)).collect();
    for k in 1..=38 {
        let s = 10f32.powi(-k);
        for z in [1.0f32, -1.0] {
            w.push(Vec3::new(s * 0.6, s * 0.8, z * (1.0 - s * s).max(0.0).sqrt()));
        }
    }
    w
}

/// A GGX of roughness α tabulated on N = 256 rings with the continued tail has Λ within 1e-4
/// (relative) of the analytic GGX over the whole sphere, for α = 0.05, 0.5, 1 and a table
/// scale s = α (the model is then GGX exactly: measured 2.3e-8, the rounding of the tables)
/// and s = 0.7 α (the rings modulate GGX(s) towards GGX(α): measured 1.2e-5). Without the
/// tail the table misses the mass beyond R_N ≈ 0.64·257² s, whose first moment dominates Λ
/// near the poles (printed at θ = 0.3 and 1.2: 4e-4 and 6e-5 for α = s = 0.5; near the poles
/// the truncated table's Λ is 0, a relative error of 1).
#[test]
fn continued_tail_reproduces_ggx_lambda() {
    let directions = sphere_directions();
    for alpha in [0.05f32, 0.5, 1.0] {
        let ggx = Ggx::isotropic(alpha).unwrap();
        for scale in [alpha, 0.7 * alpha] {
            let truncated = TabulatedSlope::from_slope(&ggx, scale, 256).unwrap();
            let table = truncated.clone().with_tail(Tail::Continued);
            assert_eq!(table.tail(), Tail::Continued);
            let (s, t) = (&table, &truncated);
            let (mut worst, mut at) = (0.0f64, Vec3::ZERO);
            let mut worst_truncated = 0.0f64;
            for &w in &directions {
                // exactly grazing: Λ = ±∞ for both
                if w.z == 0.0 {
                    continue;
                }
                let la = ggx.lambda64(w);
                let rel = |l: f64| if la == 0.0 { l.abs() } else { (l / la - 1.0).abs() };
                // the f32 form as the walks use it, and the f64 form
                let (l32, l64) = (f64::from(s.lambda(w)), s.lambda64(w));
                let e = rel(l64).max(if la.abs() < 1e30 {
                    rel(l32) - 6e-8 * (1.0 + 1.0 / la.abs())
                } else {
                    0.0
                });
                if e > worst {
                    (worst, at) = (e, w);
                }
                worst_truncated = worst_truncated.max(rel(t.lambda64(w)));
                // the projected area agrees as well (it is (1 + Λ) cos θ)
                let (pa, pt) = (ggx.projected_area64(w), s.projected_area64(w));
                assert!(
                    (pt - pa).abs() <= 1e-4 * pa + 1e-300,
                    "α = {alpha}, s = {scale}, ω = {w}: A {pt} vs {pa}"
                );
            }
            let truncated_at = |theta: f64| {
                let w = dir(theta, 0.7);
                (t.lambda64(w) / ggx.lambda64(w) - 1.0).abs()
            };
            println!(
                "GGX α = {alpha}, s = {scale}, 256 rings: worst |Λ_tab/Λ_GGX − 1| = {worst:.3e} at ω = {at} \
                 with the tail; without: {worst_truncated:.3e}, {:.2e} at θ = 0.3, {:.2e} at θ = 1.2",
                truncated_at(0.3),
                truncated_at(1.2)
            );
            assert!(worst <= 1e-4, "α = {alpha}, s = {scale}: Λ off by {worst:.3e} (relative) at ω = {at}");
        }
    }
}

/// D and P²² of the tabulated GGX with the tail (s = α) are the analytic ones at normals over
/// the whole hemisphere, including far beyond R_N (relative 5e-7: `from_slope` samples the
/// slope's f32 P²², so the ring factors are 1 to within its rounding, measured 1.6e-7), and
/// the GGX-equivalent roughness is α.
#[test]
fn continued_tail_is_ggx() {
    let alpha = 0.5f32;
    let ggx = Ggx::isotropic(alpha).unwrap();
    let table = TabulatedSlope::from_slope(&ggx, alpha, 256).unwrap().with_tail(Tail::Continued);
    let t = &table;
    let mut g = rng(5);
    let mut worst = 0.0f64;
    for _ in 0..20_000 {
        // normals with slope radius tan θm log-uniform from 1e-4 to 1e8
        let r = 10f64.powf(-4.0 + 12.0 * uniform64(&mut g));
        let phi = TAU * uniform64(&mut g);
        let m = DVec3::new(-r * phi.cos(), -r * phi.sin(), 1.0).normalize();
        let (dt, da) = (t.d64(m), ggx.d64(m));
        worst = worst.max((dt / da - 1.0).abs());
        let p = f64::from(t.p22(r as f32, 0.0)) / f64::from(ggx.p22(r as f32, 0.0)) - 1.0;
        assert!(p.abs() < 1e-5, "P22 at r = {r}: relative {p:e}");
    }
    let worst_factor = table.ring_factors().iter().map(|f| (f - 1.0).abs()).fold(0.0, f64::max);
    println!(
        "tabulated GGX with the tail: worst |D_tab/D − 1| = {worst:.2e}, worst |fₖ − 1| = {worst_factor:.2e}"
    );
    assert!(worst < 5e-7 && worst_factor < 5e-7, "D off by {worst:e}, factors by {worst_factor:e}");
    assert!((t.alpha() - alpha).abs() <= 1e-6 * alpha);
    assert_eq!(table.beckmann_alpha(), f32::INFINITY);
}

/// With the tail, ∫D cos θm dωm = 1 over the whole hemisphere (rings and tail), by quadrature
/// of the public `d` up to the horizon, for the coarse 7-ring mixture whose tail beyond
/// R_N = 12.2 holds 1.7e-3 of the mass (1e-6: the f32 rounding of D); the rings alone hold
/// 1 − f_{N−1}·cos²θ′_N. Beckmann's last ring holds nothing: its continued tail is empty.
#[test]
fn continued_tail_normalization() {
    const GL16: [(f64, f64); 8] = [
        (0.095_012_509_837_637_44, 0.189_450_610_455_068_5),
        (0.281_603_550_779_258_9, 0.182_603_415_044_923_6),
        (0.458_016_777_657_227_4, 0.169_156_519_395_002_5),
        (0.617_876_244_402_643_7, 0.149_595_988_816_576_7),
        (0.755_404_408_355_003, 0.124_628_971_255_533_9),
        (0.865_631_202_387_831_7, 0.095_158_511_682_492_8),
        (0.944_575_023_073_232_6, 0.062_253_523_938_647_9),
        (0.989_400_934_991_649_9, 0.027_152_459_411_754_1),
    ];
    let table = mixture(7).with_tail(Tail::Continued);
    let t = &table;
    let mut cuts: Vec<f64> = table.radii().iter().map(|r| r.atan()).collect();
    cuts.push(FRAC_PI_2);
    let mut total = 0.0;
    for w in cuts.windows(2) {
        // the tail piece [atan R_N, π/2] is split geometrically towards the horizon, where the
        // integrand D cos sin ∝ cos³ of the distance... vanishes smoothly
        let pieces: Vec<f64> = if w[1] == FRAC_PI_2 {
            let gap = FRAC_PI_2 - w[0];
            (0..=40).map(|k| FRAC_PI_2 - gap * 0.5f64.powi(k)).chain([FRAC_PI_2]).collect()
        } else {
            w.to_vec()
        };
        for p in pieces.windows(2) {
            let (m, h) = (0.5 * (p[0] + p[1]), 0.5 * (p[1] - p[0]));
            for &(x, wt) in &GL16 {
                for th in [m - h * x, m + h * x] {
                    total += wt * h * t.d64(dir(th, 0.4).as_dvec3()) * th.cos() * th.sin() * TAU;
                }
            }
        }
    }
    let n = table.rings();
    let ring_mass: f64 = table
        .ring_values()
        .iter()
        .zip(table.radii().windows(2))
        .map(|(p, r)| p * PI * (r[1] * r[1] - r[0] * r[0]))
        .sum();
    let factors = table.ring_factors();
    println!(
        "7-ring mixture with the tail: ∫D cos = {total:.9}, rings {ring_mass:.9}, tail factor {:.4} (last ring {:.4})",
        factors[n],
        factors[n - 1]
    );
    assert!((total - 1.0).abs() < 1e-6, "∫D cos = {total}");
    assert!(1.0 - ring_mass > 1e-3, "the tail holds {}", 1.0 - ring_mass);
    assert_eq!(factors[n], factors[n - 1]);
    let beckmann = Beckmann::isotropic(0.5).unwrap();
    let b = TabulatedSlope::from_slope(&beckmann, 0.5, 64).unwrap().with_tail(Tail::Continued);
    assert!(b.ring_factors()[64] < 1e-30, "Beckmann's tail factor {}", b.ring_factors()[64]);
}

/// The directions within the last node of the nadir see only the tail zone, where the table
/// is GGX(s) times the tail factor: the sampler draws them exactly with the spherical cap of
/// GGX(s), so its normals and densities are those of the analytic GGX(s) (same uniforms);
/// a truncated table sees nothing there (+z, density 0). Then the chi-square test in the slope
/// plane (`validation::chi2::slope_chi2`, which resolves the thin crescents far below the
/// horizon) of the 12-ring mixture with the tail at θi = 2.6, 3.0 and 3.12, where the proposal
/// and rejection run with the tail zone visible, and without the tail at θi = 3.05 and 3.1,
/// where only the last ring is visible (a sliver sampled by its own rejection).
#[test]
fn sampling_near_the_nadir() {
    let table = mixture(12).with_tail(Tail::Continued);
    let truncated = mixture(12);
    let ggx = Ggx::isotropic(table.scale()).unwrap();
    let (t, tr) = (&table, &truncated);
    // the last ring's stretched angle θ′_N: a direction sees only the tail when the stretched
    // tan ε′ = s·tan(π − θ) is below cot θ′_N
    let n1 = 13.0f64;
    let cot_last = (FRAC_PI_2 / (n1 * n1)).tan();
    let s = f64::from(table.scale());
    let mut g = rng(17);
    for k in 0..2000 {
        let eps = cot_last / s * uniform64(&mut g).max(1e-3) * 0.999;
        let wi = dir(PI - eps.atan(), TAU * uniform64(&mut g));
        let (u1, u2) = (uniform32(&mut g), uniform32(&mut g));
        let (m, mg) = (t.sample_d_wi(wi, u1, u2), ggx.sample_d_wi(wi, u1, u2));
        assert!((m - mg).length() < 1e-4 * (1.0 + mg.length()), "case {k}: {m} vs GGX {mg}");
        let (dt, dg) = (t.d_wi64(wi, m.as_dvec3()), ggx.d_wi64(wi, m.as_dvec3()));
        assert!(dt > 0.0 && (dt / dg - 1.0).abs() < 1e-4, "case {k}: density {dt} vs GGX {dg}");
        assert_eq!(tr.sample_d_wi(wi, u1, u2), Vec3::Z);
        assert_eq!(tr.projected_area(wi), 0.0);
    }
    let cases = [(t, 2.6), (t, 3.0), (t, 3.12), (tr, 3.05), (tr, 3.1)];
    let alpha = sidak(1e-3, cases.len());
    let grid = SlopeGrid { nu: 16, nv: 12, strips: 256, rel_tol: 1e-6, max_depth: 6 };
    validation::par_map(&cases, |k, &(slope, theta)| {
        let mut g = rng(0x7a1 + k as u64);
        let wi = dir(theta, 0.3 + k as f64);
        let label = format!("12-ring mixture ({:?} tail), θi = {theta}", slope.tail());
        // D_ωi = ⟨ωi, m⟩₊ D(m)/A(ωi), with the projected area computed once
        let area = slope.projected_area64(wi);
        let o = validation::chi2::slope_chi2(
            &label,
            (slope.scale(), slope.scale()),
            CrossMap::Tangent,
            wi,
            grid,
            |m| if m.z > 0.0 { wi.as_dvec3().dot(m).max(0.0) * slope.d64(m) / area } else { 0.0 },
            || slope.sample_d_wi(wi, uniform32(&mut g), uniform32(&mut g)),
            40_000,
            alpha,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        println!(
            "{label}: χ² = {:.1}, dof = {}, p = {:.3}, ∫D_ωi = {:.6}, acceptance {:.3}",
            o.statistic,
            o.dof,
            o.p_value,
            o.integral,
            slope.sampler_acceptance(wi)
        );
    });
}
