//! The bounded cap of `GgxBoundedCap` (Eto and Tokuyoshi 2023) beyond its chi-square test
//! against its density (`samplers`):
//!
//! - the bound loses no reflection: every ωo above the horizon has its half vector kept
//!   (density > 0) over the fuzz domain (α from 1e-4 to 10, anisotropy to 1e4, views from the
//!   zenith to 1e-6 rad from grazing, light directions down to 1e-6 above the horizon), and the
//!   bound is tight for isotropic GGX (a light 1e-2 below the horizon beside the view is
//!   excluded), so the test is not vacuous;
//! - the density is the spherical cap's scaled by A/A_b on the kept normals, and the spherical
//!   cap's below the horizon;
//! - the extreme uniforms u = 0 and 1 − 2⁻²⁴ land inside the bounded cap with the tails the
//!   crate's tail policy gives them (at least 2⁻²⁶ of the bounded cap beyond them), and every
//!   sample of the fuzz domain is a finite unit normal with a finite positive density.

use glam::{DVec3, Vec3};
use microsurface::Ggx;
use microsurface::slope::MicrosurfaceSlope;
use microsurface::vndf::{GgxBoundedCap, GgxSphericalCap, VisibleNormalSampler};
use std::f64::consts::FRAC_PI_2;
use validation::{rng, uniform32};

/// The roughness pairs of the fuzz domain: α from 1e-4 to 10, anisotropy to 1e4.
const FUZZ_ALPHAS: [(f32, f32); 10] = [
    (1e-4, 1e-4),
    (1e-3, 1e-3),
    (0.05, 0.05),
    (0.5, 0.5),
    (1.0, 1.0),
    (2.0, 2.0),
    (10.0, 10.0),
    (1e-3, 10.0),
    (10.0, 1e-3),
    (0.3, 1.7),
];

/// The largest uniform, 1 − 2⁻²⁴.
const U_MAX: f32 = 1.0 - 1.0 / 16_777_216.0;

/// A unit direction above the horizon with cos θ spread over decades down to 1e-6.
fn upper(r: &mut validation::TestRng) -> Vec3 {
    let z = 10f32.powf(-6.0 * uniform32(r)).min(1.0);
    let phi = core::f32::consts::TAU * uniform32(r);
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z).normalize()
}

/// The bound of eqs. 5–6 in f64 (with the crate's k for a > 1 and its margin: 1 + k raised by
/// 2⁻²⁰ relative): k for a view above the horizon.
fn reference_k(ax: f64, ay: f64, wi: DVec3) -> f64 {
    let a_sq = ax.min(ay).powi(2);
    let w = wi.normalize();
    let sin = w.x.hypot(w.y);
    let k = if a_sq <= 1.0 {
        (1.0 - a_sq) * (1.0 + sin) / (1.0 + sin + a_sq * (1.0 - sin))
    } else {
        (1.0 - a_sq) * (1.0 - sin) / (1.0 - sin + a_sq * (1.0 + sin))
    };
    ((1.0 + k) * (1.0 + 2f64.powi(-20))).min(2.0) - 1.0
}

/// The stretched view v̂ and the cap point c = reflect(−v̂, n̂) of a normal, in f64.
fn cap_point(ax: f64, ay: f64, wi: DVec3, wm: DVec3) -> (DVec3, DVec3) {
    let v = DVec3::new(ax * wi.x, ay * wi.y, wi.z).normalize();
    let n = DVec3::new(wm.x / ax, wm.y / ay, wm.z).normalize();
    (v, 2.0 * v.dot(n) * n - v)
}

/// Every reflection above the horizon has its half vector kept: over the fuzz roughnesses and
/// 20 000 random pairs each (views and lights spread over decades of cos θ down to 1e-6), plus
/// the extremal pair of the bound (the light on the horizon beside the view, where the bound
/// is attained for isotropic GGX), the bounded density of ωh is positive.
#[test]
fn the_bound_keeps_every_reflection_above_the_horizon() {
    let mut r = rng(61);
    let mut failures = Vec::new();
    let mut checked = 0usize;
    for (ax, ay) in FUZZ_ALPHAS {
        let sampler = GgxBoundedCap(Ggx::new(ax, ay).unwrap());
        for i in 0..20_000 {
            let wi = upper(&mut r);
            let wo = if i % 4 == 0 {
                // the extremal light: on (or 1e-6 above) the horizon at the view's azimuth
                Vec3::new(wi.x, wi.y, 1e-6 * wi.x.hypot(wi.y)).normalize_or(Vec3::X)
            } else {
                upper(&mut r)
            };
            // the normal as the sampler would return it (f32), and its exact reflection: for
            // nearly opposite f32 directions the f64 half vector does not reflect ωi onto ωo
            // exactly (its error ~ε/|ωi + ωo|), so the pair is judged by that reflection
            let h = (wi.as_dvec3() + wo.as_dvec3()).normalize().as_vec3();
            let (w, m) = (wi.as_dvec3(), h.as_dvec3());
            let reflected = 2.0 * w.dot(m) * m - w;
            if !(reflected.z > 0.0 && h.z > 0.0) {
                continue;
            }
            checked += 1;
            let p = sampler.pdf(wi, h);
            if !(p > 0.0 && p.is_finite()) && failures.len() < 10 {
                failures.push(format!("α = ({ax}, {ay}), wi = {wi}, wo = {wo}: bounded pdf(ωh = {h}) = {p}"));
            }
        }
    }
    eprintln!("bound: {checked} reflections above the horizon checked, {} lost", failures.len());
    assert!(checked > 150_000, "only {checked} pairs checked");
    assert!(failures.is_empty(), "reflections lost by the bound:\n{}", failures.join("\n"));
}

/// The bound is tight for isotropic GGX (below α = 1): the normal that reflects the view onto
/// the light 1e-2 rad below the horizon beside it is excluded (density 0 although the
/// spherical cap has it), and the excluded normals are exactly those whose cap point lies
/// below −b (checked against the f64 reference of eq. 5 on 2 000 random visible normals per
/// roughness, away from the boundary by 1e-4 of the cap).
#[test]
fn the_bound_is_eq5_and_tight() {
    let mut r = rng(62);
    let (mut excluded, mut kept) = (0usize, 0usize);
    for alpha in [0.05f32, 0.2, 0.5, 0.9] {
        let ggx = Ggx::isotropic(alpha).unwrap();
        let (bounded, cap) = (GgxBoundedCap(ggx), GgxSphericalCap(ggx));
        for theta in [0.0f32, 0.5, 1.0, 1.4] {
            let wi = Vec3::new(theta.sin(), 0.0, theta.cos());
            if theta > 0.0 {
                let below = Vec3::new(1e-2f32.cos(), 0.0, -1e-2f32.sin());
                let h = (wi + below).normalize();
                assert!(cap.pdf(wi, h) > 0.0, "α = {alpha}, θ = {theta}: the spherical cap has ωh = {h}");
                assert_eq!(bounded.pdf(wi, h), 0.0, "α = {alpha}, θ = {theta}: ωh = {h} reflects below");
            }
            let k = reference_k(f64::from(alpha), f64::from(alpha), wi.as_dvec3());
            for _ in 0..2_000 {
                let wm = ggx.sample_d_wi(wi, uniform32(&mut r), uniform32(&mut r));
                let (v, c) = cap_point(f64::from(alpha), f64::from(alpha), wi.as_dvec3(), wm.as_dvec3());
                let b = k * v.z;
                let margin = (c.z + b) / (1.0 + b);
                if margin.abs() < 1e-4 {
                    continue;
                }
                let p = bounded.pdf(wi, wm);
                assert_eq!(
                    p > 0.0,
                    margin > 0.0,
                    "α = {alpha}, θ = {theta}, ωm = {wm}: c.z + b = {margin:e}, pdf {p}"
                );
                if margin > 0.0 {
                    kept += 1;
                    // A/A_b = (1 + v̂.z)/(1 + b) on the kept normals
                    let ratio = f64::from(p) / f64::from(cap.pdf(wi, wm));
                    let expected = (1.0 + v.z) / (1.0 + b);
                    assert!(
                        (ratio / expected - 1.0).abs() < 1e-5,
                        "α = {alpha}, θ = {theta}: pdf ratio {ratio} ≠ (1 + v̂.z)/(1 + b) = {expected}"
                    );
                } else {
                    excluded += 1;
                }
            }
        }
    }
    eprintln!("eq. 5: {kept} kept and {excluded} excluded normals agree with the reference");
    assert!(excluded > 1_000 && kept > 10_000, "kept {kept}, excluded {excluded}");
}

/// Views on or below the horizon sample the whole visible cap: the density is D_ωi, and the
/// same uniforms give the spherical cap's normal.
#[test]
fn views_below_the_horizon_keep_the_spherical_cap() {
    let mut r = rng(63);
    for (ax, ay) in FUZZ_ALPHAS {
        let ggx = Ggx::new(ax, ay).unwrap();
        let (bounded, cap) = (GgxBoundedCap(ggx), GgxSphericalCap(ggx));
        for _ in 0..500 {
            let w = upper(&mut r);
            let wi = Vec3::new(w.x, w.y, -w.z);
            let u = [uniform32(&mut r), uniform32(&mut r), 0.0];
            let wm = bounded.sample(wi, u);
            assert_eq!(wm, cap.sample(wi, u), "α = ({ax}, {ay}), wi = {wi}, u = {u:?}");
            assert_eq!(
                bounded.pdf(wi, wm).to_bits(),
                cap.pdf(wi, wm).to_bits(),
                "α = ({ax}, {ay}), wi = {wi}, ωm = {wm}"
            );
        }
    }
}

/// The extreme uniforms u1 = 0 and 1 − 2⁻²⁴ (the cap's height): u1 = 0 leaves at least 2⁻²⁶ of
/// the bounded cap above the sample; u1 = 1 − 2⁻²⁴ lands within the density's support (not
/// more than its tolerance of 2⁻²⁰ of the cap below the f64 bound, where the normal resolves
/// the cap height, v̂·n̂ ≥ 1e-5 as in `tails.rs`); and every sample of the fuzz
/// domain (views from the zenith to below the horizon, both uniforms at 0, 1 − 2⁻²⁴ and between)
/// is a finite unit normal with a finite positive bounded density.
#[test]
fn extreme_uniforms_and_the_fuzz_domain() {
    const MIN_TAIL: f64 = 1.0 / (1u64 << 26) as f64;
    const BOUND_TOLERANCE: f64 = 1.0 / (1u64 << 20) as f64;
    let us = [0.0f32, 0.25, 0.5, 0.8, U_MAX];
    let mut failures = Vec::new();
    let (mut checked, mut smallest, mut lowest) = (0usize, f64::INFINITY, f64::INFINITY);
    for (ax, ay) in FUZZ_ALPHAS {
        let ggx = Ggx::new(ax, ay).unwrap();
        let sampler = GgxBoundedCap(ggx);
        for theta in [0.0f64, 0.3, 1.0, 1.45, FRAC_PI_2 - 1e-4, FRAC_PI_2 - 1e-7, 1.7, 2.8] {
            for phi in [0.0f64, 0.7, 2.0] {
                let wi = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()).as_vec3();
                for u1 in us {
                    for u2 in us {
                        let wm = sampler.sample(wi, [u1, u2, 0.5]);
                        let p = sampler.pdf(wi, wm);
                        checked += 1;
                        let tag =
                            format!("α = ({ax}, {ay}), θ = {theta}, φ = {phi}, u = ({u1}, {u2}): ωm = {wm}");
                        if !(wm.is_finite() && (wm.length() - 1.0).abs() < 1e-5 && wm.z >= 0.0) {
                            failures.push(format!("{tag}: not a unit upper normal"));
                            continue;
                        }
                        if !(p > 0.0 && p.is_finite()) {
                            failures.push(format!("{tag}: density {p:e}"));
                        }
                        if wi.z <= 0.0 || !(u1 == 0.0 || u1 == U_MAX) {
                            continue;
                        }
                        let (axd, ayd) = (f64::from(ax), f64::from(ay));
                        let (v, c) = cap_point(axd, ayd, wi.as_dvec3(), wm.as_dvec3());
                        let b = reference_k(axd, ayd, wi.as_dvec3()) * v.z;
                        let n = DVec3::new(f64::from(wm.x) / axd, f64::from(wm.y) / ayd, f64::from(wm.z))
                            .normalize();
                        // 1 − c.z and c.z + b, the first without cancellation
                        if u1 == 0.0 {
                            let tail = (c.x * c.x + c.y * c.y) / (1.0 + c.z) / (1.0 + b);
                            smallest = smallest.min(tail);
                            if tail.is_nan() || tail < MIN_TAIL {
                                failures.push(format!("{tag}: tail above the sample {tail:.3e} < 2⁻²⁶"));
                            }
                        } else if v.dot(n) >= 1e-5 {
                            // the bottom of the cap: its f32 bound κ = 1 + k is rounded (~6 ulps,
                            // as much as the 2⁻²⁴ step of u1 at the bottom), so the sample is
                            // only required to lie within the density's support, which extends
                            // 2⁻²⁰ of the cap below the bound (the pdf's tolerance)
                            let depth = (c.z + b) / (1.0 + b);
                            lowest = lowest.min(depth);
                            if depth.is_nan() || depth < -BOUND_TOLERANCE {
                                failures.push(format!("{tag}: {depth:.3e} of the cap below the bound"));
                            }
                        }
                    }
                }
            }
        }
    }
    eprintln!(
        "bounded cap: {checked} samples, smallest tail above {smallest:.3e}, lowest bottom sample {lowest:.3e} \
         of the cap from the bound, {} failures",
        failures.len()
    );
    assert!(smallest.is_finite(), "no tail checked");
    assert!(failures.is_empty(), "{} failures:\n{}", failures.len(), failures.join("\n"));
}
