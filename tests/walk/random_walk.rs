//! The multiple-scattering BSDF of the random walk (Heitz et al. 2016, supplement §4.4):
//! white furnace (4.4.1), reciprocity (4.4.2), single scattering (4.4.3), importance sampling
//! (4.4.4), the C¹-space walk against the height-space walk for both heights, absorptive materials and scattering
//! orders, over materials × heights × slopes × roughness × incident angles.
//!
//! The full matrix (3 materials plus the dielectric lit from inside, 2 heights, 2 slopes,
//! α ∈ {0.5, 1.5, (1.0, 0.3)}) is run for the furnace test with one incident angle per cell,
//! rotated deterministically so that every material meets every angle in {0, 0.8, 1.2, 1.5};
//! the more expensive tests use fixed subsets that cover every factor.
//!
//! Statistics: every Monte Carlo assertion is |mean − expected| ≤ z·SE (or a two-sample
//! |m1 − m2| ≤ z·√(SE1² + SE2²)) with z = `family_z(0.01, m)` for the m assertions of its test
//! function, and asserts an upper bound on SE. `eval` is stochastic, so the chi-square test
//! of `sample` estimates each cell's expected probability by Monte Carlo (`stochastic_chi2`):
//! uniform directions in the cell, one independent `eval` each, refined until the variance
//! of the estimate is at most a tenth of the multinomial variance, and that variance is
//! still included in the statistic (with moment-matched degrees of freedom).
use validation::par_map;
use validation::stochastic::stochastic_chi2;

use glam::{DVec3, Vec3};
use microsurface::research::{
    GaussianHeight, HeightSample, Material, Microsurface, MicrosurfaceGeometry, MicrosurfaceHeight,
    PhaseSample, ScatteringOrder, UniformHeight, WalkSample,
};
use microsurface::research::{Interaction, Side};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, ComplexIor, Conductor, Dielectric, Diffuse, Ggx};
use statrs::distribution::{ContinuousCDF, Normal};
use std::f64::consts::{PI, TAU};
use validation::{Stats, TestRng};

const ALPHAS: [(f32, f32); 3] = [(0.5, 0.5), (1.5, 1.5), (1.0, 0.3)];
const THETAS: [f64; 4] = [0.0, 0.8, 1.2, 1.5];
const ETA: f32 = 1.5;
const PHI_I: f64 = 0.7;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Height {
    Uniform,
    Gaussian,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Slope {
    Ggx,
    Beckmann,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Mat {
    /// F = 1.
    Conductor,
    /// Gold-like complex IOR.
    Gold,
    /// Diffuse with a grey albedo.
    Diffuse(f32),
    /// η = 1.5.
    Dielectric,
}

/// A microsurface, type-erased over height, slope and material.
trait Bsdf: Sync {
    fn name(&self) -> &str;
    fn transmits(&self) -> bool;
    fn eval(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut TestRng) -> Vec3;
    fn sample(&self, wi: Vec3, rng: &mut TestRng) -> Option<WalkSample>;
    fn single(&self, wi: Vec3, wo: Vec3, rng: &mut TestRng) -> Vec3;
    fn sample_phase(&self, wi: Vec3, rng: &mut TestRng) -> PhaseSample;
    /// Whether the phase function is an exact, normalized density (F = 1 conductor,
    /// dielectric): then `phase_sample`/`phase_pdf` can importance-sample the albedo.
    fn exact_phase(&self) -> bool;
    /// A direction from the phase function of ωi on ωi's side of the interface.
    fn phase_sample(&self, wi: Vec3, rng: &mut TestRng) -> Vec3;
    /// Its density (both sides of ωo summed).
    fn phase_pdf(&self, wi: Vec3, wo: Vec3, rng: &mut TestRng) -> f64;
    /// The supplement's walk in height space (see [`reference_eval`]).
    fn reference_eval(&self, wi: Vec3, wo: Vec3, rng: &mut TestRng) -> Vec3;
}

struct Surf<H, S, M> {
    name: String,
    surface: Microsurface<H, S, M>,
    exact_phase: bool,
}

impl<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material> Bsdf for Surf<H, S, M> {
    fn name(&self) -> &str {
        &self.name
    }
    fn transmits(&self) -> bool {
        M::TRANSMITS
    }
    fn eval(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut TestRng) -> Vec3 {
        self.surface.eval(wi, wo, order, rng)
    }
    fn sample(&self, wi: Vec3, rng: &mut TestRng) -> Option<WalkSample> {
        self.surface.sample(wi, rng)
    }
    fn single(&self, wi: Vec3, wo: Vec3, rng: &mut TestRng) -> Vec3 {
        self.surface.eval_single_scattering(wi, wo, rng)
    }
    fn sample_phase(&self, wi: Vec3, rng: &mut TestRng) -> PhaseSample {
        self.surface.sample_phase(wi, rng)
    }
    fn exact_phase(&self) -> bool {
        self.exact_phase
    }
    fn phase_sample(&self, wi: Vec3, rng: &mut TestRng) -> Vec3 {
        self.surface.material().sample_phase(self.surface.slope(), wi, sided(wi.z > 0.0), rng).wo
    }
    fn phase_pdf(&self, wi: Vec3, wo: Vec3, rng: &mut TestRng) -> f64 {
        let (m, s, side) = (self.surface.material(), self.surface.slope(), sided(wi.z > 0.0));
        let mut p = m.eval_phase(s, &Interaction::new(wi, wo, side, Side::Outside), rng).x;
        if M::TRANSMITS {
            p += m.eval_phase(s, &Interaction::new(wi, wo, side, Side::Inside), rng).x;
        }
        f64::from(p)
    }
    fn reference_eval(&self, wi: Vec3, wo: Vec3, rng: &mut TestRng) -> Vec3 {
        reference_eval(self.surface.geometry(), self.surface.material(), wi, wo, rng)
    }
}

/// The supplement's Algorithm 2 (§3.1, §3.4) as printed, in height space: heights from
/// `MicrosurfaceGeometry::sample_height`, shadowing from `g1_at`, heights flipped h ↦ −h on
/// the inside of a dielectric. An implementation independent of the crate's walk, which runs
/// in log-C¹ space and never computes a height.
fn reference_eval<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
    geometry: &MicrosurfaceGeometry<H, S>,
    material: &M,
    wi: Vec3,
    wo: Vec3,
    rng: &mut TestRng,
) -> Vec3 {
    let side = |v: Vec3, outside: bool| if outside { v } else { -v };
    let wo_outside = wo.z > 0.0;
    let mut outside = wi.z > 0.0;
    let mut wr = -wi;
    // the height in the frame of the outside; a walk starts above (below) the whole surface
    let mut h = if outside { f32::INFINITY } else { f32::NEG_INFINITY };
    let (mut throughput, mut sum) = (Vec3::ONE, Vec3::ZERO);
    for _ in 0..microsurface::research::MAX_BOUNCES {
        let u = validation::uniform32(rng);
        match geometry.sample_height(side(wr, outside), if outside { h } else { -h }, u) {
            HeightSample::Escape => break,
            HeightSample::Hit(local) => h = if outside { local } else { -local },
        }
        let phase = material.eval_phase(
            geometry.slope(),
            &Interaction::new(-wr, wo, sided(outside), sided(wo_outside)),
            rng,
        );
        let shadowing = geometry.g1_at(side(wo, wo_outside), if wo_outside { h } else { -h });
        sum += throughput * phase * shadowing;
        let s = material.sample_phase(geometry.slope(), -wr, sided(outside), rng);
        (wr, outside, throughput) = (s.wo, s.side == Side::Outside, throughput * s.weight);
    }
    sum
}

fn gold() -> Conductor {
    Conductor::new(ComplexIor::new(Vec3::new(0.18, 0.42, 1.37), Vec3::new(3.42, 2.35, 1.77)).unwrap())
}

fn with_hs<M: Material + 'static>(
    h: Height,
    s: Slope,
    (ax, ay): (f32, f32),
    m: Mat,
    mat: M,
) -> Box<dyn Bsdf> {
    let name = format!("{m:?} {h:?} {s:?}(αx = {ax}, αy = {ay})");
    let exact_phase = matches!(m, Mat::Conductor | Mat::Dielectric);
    match (h, s) {
        (Height::Uniform, Slope::Ggx) => Box::new(Surf {
            name,
            exact_phase,
            surface: Microsurface::new(UniformHeight, Ggx::new(ax, ay).unwrap(), mat),
        }),
        (Height::Uniform, Slope::Beckmann) => Box::new(Surf {
            name,
            exact_phase,
            surface: Microsurface::new(UniformHeight, Beckmann::new(ax, ay).unwrap(), mat),
        }),
        (Height::Gaussian, Slope::Ggx) => Box::new(Surf {
            name,
            exact_phase,
            surface: Microsurface::new(GaussianHeight, Ggx::new(ax, ay).unwrap(), mat),
        }),
        (Height::Gaussian, Slope::Beckmann) => Box::new(Surf {
            name,
            exact_phase,
            surface: Microsurface::new(GaussianHeight, Beckmann::new(ax, ay).unwrap(), mat),
        }),
    }
}

fn build(h: Height, s: Slope, alpha: (f32, f32), m: Mat) -> Box<dyn Bsdf> {
    match m {
        Mat::Conductor => with_hs(h, s, alpha, m, Conductor::perfect()),
        Mat::Gold => with_hs(h, s, alpha, m, gold()),
        Mat::Diffuse(a) => with_hs(h, s, alpha, m, Diffuse::new(Vec3::splat(a)).unwrap()),
        Mat::Dielectric => with_hs(h, s, alpha, m, Dielectric::new(ETA).unwrap()),
    }
}

/// A uniform direction with cos θ ∈ [z_lo, 1].
fn uniform_dir(z_lo: f64, rng: &mut TestRng) -> Vec3 {
    let z = z_lo + (1.0 - z_lo) * validation::uniform64(rng);
    let phi = TAU * validation::uniform64(rng);
    let s = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), z).as_vec3()
}

/// The albedo ∫ eval(ωi, ωo) dωo per channel by Monte Carlo over ωo on the sphere
/// (transmitting materials) or the upper hemisphere (`upper_only`, or opaque materials).
///
/// ωo is uniform, or — for the F = 1 conductor and the dielectric, whose sharp lobes make the
/// uniform estimator noisy — drawn from the defensive mixture q = ½ uniform + ½ phase function
/// of ωi (an exact density validated by tests/materials.rs; independent of `sample`),
/// with the estimator eval/q.
fn albedo(bsdf: &dyn Bsdf, wi: Vec3, upper_only: bool, n: usize, rng: &mut TestRng) -> [Stats; 3] {
    let z_lo = if bsdf.transmits() && !upper_only { -1.0 } else { 0.0 };
    let area = TAU * (1.0 - z_lo);
    let mixture = bsdf.exact_phase() && !upper_only;
    let mut stats = [Stats::default(); 3];
    for _ in 0..n {
        let wo = if mixture && validation::uniform64(rng) < 0.5 {
            bsdf.phase_sample(wi, rng)
        } else {
            uniform_dir(z_lo, rng)
        };
        let q = if mixture {
            let uniform = if f64::from(wo.z) >= z_lo { 0.5 / area } else { 0.0 };
            uniform + 0.5 * bsdf.phase_pdf(wi, wo, rng)
        } else {
            1.0 / area
        };
        let v = bsdf.eval(wi, wo, ScatteringOrder::All, rng);
        for (c, s) in stats.iter_mut().enumerate() {
            s.push(if v[c] == 0.0 { 0.0 } else { f64::from(v[c]) / q });
        }
    }
    stats
}

fn worst_z(values: &[(f64, f64)]) -> f64 {
    values.iter().map(|(d, se)| (d / se).abs()).fold(0.0, f64::max)
}

// ---------------------------------------------------------------------------------------------
// 4.4.1 white furnace
// ---------------------------------------------------------------------------------------------

#[test]
fn white_furnace_4_4_1() {
    const N: usize = 120_000;
    // (material, height, slope, α index, θi, lit from inside)
    let mut cases = Vec::new();
    for m in [Mat::Conductor, Mat::Diffuse(1.0), Mat::Dielectric] {
        for (hi, h) in [Height::Uniform, Height::Gaussian].into_iter().enumerate() {
            for (si, s) in [Slope::Ggx, Slope::Beckmann].into_iter().enumerate() {
                for a in 0..ALPHAS.len() {
                    let theta = THETAS[(hi + 2 * si + a) % THETAS.len()];
                    cases.push((m, h, s, a, theta, false));
                    if m == Mat::Dielectric {
                        cases.push((m, h, s, a, PI - THETAS[(hi + 2 * si + a + 1) % THETAS.len()], true));
                    }
                }
            }
        }
    }
    let z = validation::family_z(0.01, cases.len());
    let out = par_map(&cases, |i, &(m, h, s, a, theta, inside)| {
        let bsdf = build(h, s, ALPHAS[a], m);
        let wi = validation::dir(theta, PHI_I);
        let mut rng = validation::rng(100 + i as u64);
        // the dielectric's eval is the noisiest (σ̂ ≈ 3.3 against ≈ 2.4): twice the walks
        let n = if m == Mat::Dielectric { 2 * N } else { N };
        let [stats, _, _] = albedo(bsdf.as_ref(), wi, false, n, &mut rng);
        let label = format!("{}: white furnace θi = {theta:.3} (lit from inside: {inside})", bsdf.name());
        // at grazing incidence the dielectric's σ̂ reaches 4.8: SE ≤ 1e-2 there, 8e-3 otherwise
        let max_se = if m == Mat::Dielectric { 1e-2 } else { 8e-3 };
        validation::assert_mean(&label, &stats, 1.0, z, max_se, 0.0);
        (stats.mean() - 1.0, stats.se())
    });
    for (case, (d, se)) in cases.iter().zip(&out) {
        println!(
            "furnace {:?} {:?} {:?} α{:?} θ={:.2}: 1{d:+.4} ± {se:.4}",
            case.0, case.1, case.2, ALPHAS[case.3], case.4
        );
    }
    let max_se = out.iter().map(|o| o.1).fold(0.0, f64::max);
    println!(
        "white furnace: {} cases, N = {N} (dielectric {}), worst |albedo − 1|/SE = {:.2} (z = {z:.2}), largest SE = {max_se:.4}",
        cases.len(),
        2 * N,
        worst_z(&out)
    );
}

// ---------------------------------------------------------------------------------------------
// 4.4.2 reciprocity
// ---------------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug, PartialEq)]
enum Pair {
    /// Both directions above (conductor, diffuse, dielectric reflection).
    Above,
    /// ωi above, ωo below (dielectric transmission).
    Through,
    /// Both below (dielectric, reflection inside).
    Below,
}

#[test]
fn reciprocity_4_4_2() {
    const N: usize = 100_000;
    let pairs = [(0.3, 0.0, 1.1, 2.6), (1.2, 0.5, 0.6, 3.7), (1.5, 1.0, 0.9, 4.4)];
    let mut cases = Vec::new();
    let mut k = 0;
    for h in [Height::Uniform, Height::Gaussian] {
        for s in [Slope::Ggx, Slope::Beckmann] {
            for (m, pair) in [
                (Mat::Conductor, Pair::Above),
                (Mat::Diffuse(1.0), Pair::Above),
                (Mat::Dielectric, Pair::Above),
                (Mat::Dielectric, Pair::Through),
                (Mat::Dielectric, Pair::Below),
            ] {
                cases.push((m, h, s, k % ALPHAS.len(), pairs[k % pairs.len()], pair));
                k += 1;
            }
        }
    }
    let z = validation::family_z(0.01, cases.len());
    let out = par_map(&cases, |i, &(m, h, s, a, (ti, pi, to, po), pair)| {
        let bsdf = build(h, s, ALPHAS[a], m);
        let (mut wi, mut wo) = (validation::dir(ti, pi), validation::dir(to, po));
        // generalized reciprocity f(ωi, ωo)/ηo² = f(ωo, ωi)/ηi²: only crossing pairs differ
        let mut scale_a = 1.0;
        match pair {
            Pair::Above => {}
            Pair::Through => {
                // forward transmission, inside the lobe: ωo's azimuth opposite to ωi's and
                // half the polar angle (off-lobe values are too noisy to test)
                wo = -validation::dir(0.5 * to, pi);
                scale_a = 1.0 / f64::from(ETA * ETA);
            }
            Pair::Below => {
                wi = -wi;
                wo = -wo;
            }
        }
        let mut rng = validation::rng(200 + i as u64);
        let (mut fa, mut fb) = (Stats::default(), Stats::default());
        for _ in 0..N {
            fa.push(
                scale_a * f64::from(bsdf.eval(wi, wo, ScatteringOrder::All, &mut rng).x)
                    / f64::from(wo.z.abs()),
            );
            fb.push(f64::from(bsdf.eval(wo, wi, ScatteringOrder::All, &mut rng).x) / f64::from(wi.z.abs()));
        }
        let label = format!("{}: reciprocity {pair:?} θi = {ti}, θo = {to}", bsdf.name());
        let scale = fa.mean().max(fb.mean());
        assert!(scale > 1e-3, "{label}: vanishing BSDF {scale:e}: the test would be vacuous");
        validation::assert_two_sample(&label, &fa, &fb, z, 0.04 * scale);
        (fa.mean() - fb.mean(), fa.se().hypot(fb.se()))
    });
    println!(
        "BSDF reciprocity: {} cases, N = {N} per side, worst |Δ|/SE = {:.2} (z = {z:.2})",
        cases.len(),
        worst_z(&out)
    );
}

// ---------------------------------------------------------------------------------------------
// 4.4.3 single scattering
// ---------------------------------------------------------------------------------------------

#[test]
fn first_order_equals_single_scattering_4_4_3() {
    const N: usize = 100_000;
    let only1 = ScatteringOrder::only(1).unwrap();
    // (θi, θo) with signs: the dielectric is also lit from inside
    let configs: [(Mat, f64, f64); 6] = [
        (Mat::Conductor, 0.7, 1.2),
        (Mat::Diffuse(1.0), 1.4, 0.5),
        (Mat::Dielectric, 0.4, 1.0),
        (Mat::Dielectric, 1.1, PI - 0.5),
        (Mat::Dielectric, PI - 0.6, PI - 1.0),
        (Mat::Dielectric, PI - 0.3, 0.9),
    ];
    let mut cases = Vec::new();
    for (hi, h) in [Height::Uniform, Height::Gaussian].into_iter().enumerate() {
        for (si, s) in [Slope::Ggx, Slope::Beckmann].into_iter().enumerate() {
            for (c, &(m, ti, to)) in configs.iter().enumerate() {
                cases.push((m, h, s, (hi + si + c) % ALPHAS.len(), ti, to));
            }
        }
    }
    let z = validation::family_z(0.01, cases.len());
    let out = par_map(&cases, |i, &(m, h, s, a, ti, to)| {
        let bsdf = build(h, s, ALPHAS[a], m);
        let (wi, wo) = (validation::dir(ti, PHI_I), validation::dir(to, PHI_I + PI));
        let mut rng = validation::rng(300 + i as u64);
        let (mut walk, mut single) = (Stats::default(), Stats::default());
        for _ in 0..N {
            walk.push(f64::from(bsdf.eval(wi, wo, only1, &mut rng).x));
            single.push(f64::from(bsdf.single(wi, wo, &mut rng).x));
        }
        let label =
            format!("{}: eval(only(1)) vs eval_single_scattering, θi = {ti:.3}, θo = {to:.3}", bsdf.name());
        let scale = walk.mean().max(single.mean());
        assert!(scale > 1e-3, "{label}: vanishing value {scale:e}: the test would be vacuous");
        if single.std() == 0.0 {
            // exact single scattering (conductor, dielectric): one-sample test, f32 tolerance
            validation::assert_mean(&label, &walk, single.mean(), z, 0.01 * scale, 1e-5 * scale);
            (walk.mean() - single.mean(), walk.se())
        } else {
            validation::assert_two_sample(&label, &walk, &single, z, 0.01 * scale);
            (walk.mean() - single.mean(), walk.se().hypot(single.se()))
        }
    });
    println!(
        "single scattering: {} cases, N = {N}, worst |Δ|/SE = {:.2} (z = {z:.2})",
        cases.len(),
        worst_z(&out)
    );
}

// ---------------------------------------------------------------------------------------------
// 4.4.4 importance sampling
// ---------------------------------------------------------------------------------------------

const CHI2_N: usize = 30_000;

#[test]
fn sampling_chi2_4_4_4() {
    // (material, height, slope, α index, θi): every material, height, slope, roughness,
    // grazing incidence and the dielectric lit from inside
    let cases = [
        (Mat::Conductor, Height::Uniform, Slope::Ggx, 0, 0.8),
        (Mat::Conductor, Height::Gaussian, Slope::Beckmann, 2, 1.5),
        (Mat::Conductor, Height::Uniform, Slope::Beckmann, 1, 0.0),
        (Mat::Diffuse(1.0), Height::Gaussian, Slope::Ggx, 1, 1.5),
        (Mat::Diffuse(1.0), Height::Uniform, Slope::Beckmann, 0, 0.8),
        (Mat::Diffuse(1.0), Height::Gaussian, Slope::Ggx, 2, 1.2),
        (Mat::Dielectric, Height::Uniform, Slope::Ggx, 1, 0.8),
        (Mat::Dielectric, Height::Gaussian, Slope::Beckmann, 0, 1.5),
        (Mat::Dielectric, Height::Uniform, Slope::Ggx, 2, 1.2),
        (Mat::Dielectric, Height::Gaussian, Slope::Ggx, 0, PI - 0.8),
        (Mat::Dielectric, Height::Uniform, Slope::Beckmann, 1, PI - 1.5),
    ];
    let alpha = validation::sidak(0.01, cases.len());
    let out = par_map(&cases, |i, &(m, h, s, a, theta)| {
        let bsdf = build(h, s, ALPHAS[a], m);
        let wi = validation::dir(theta, PHI_I);
        let label = format!("{}: sample, θi = {theta:.3}", bsdf.name());
        let mut rng = validation::rng(400 + i as u64);
        let mut eval_rng = validation::rng(500 + i as u64);
        let mut bounces = Stats::default();
        let z_lo = if bsdf.transmits() { -1.0 } else { 0.0 };
        let (nz, nphi) = if bsdf.transmits() { (16, 16) } else { (8, 16) };
        let result = stochastic_chi2(
            &label,
            z_lo,
            nz,
            nphi,
            &mut |wo| f64::from(bsdf.eval(wi, wo, ScatteringOrder::All, &mut eval_rng).x),
            &mut || {
                let s = bsdf.sample(wi, &mut rng)?;
                assert_eq!(s.weight, Vec3::ONE, "{label}: non-absorptive weight");
                assert!(s.bounces >= 1, "{label}: a walk has at least one bounce");
                bounces.push(f64::from(s.bounces));
                Some(s.wo)
            },
            CHI2_N,
            alpha,
        );
        println!(
            "χ² {label}: p = {:.3e}, dof = {:.1}, Σm̂ = {:.4}, noise ratio ≤ {:.3}, mean bounces {:.3}",
            result.p_value,
            result.dof,
            result.mass,
            result.max_ratio,
            bounces.mean()
        );
        result.p_value
    });
    let worst = out.iter().cloned().fold(1.0, f64::min);
    println!(
        "BSDF sampling χ²: {} tests, N = {CHI2_N}, worst p = {worst:.3e} (α = {alpha:.2e})",
        cases.len()
    );
}

// ---------------------------------------------------------------------------------------------
// heights: the walk in C¹ space against the supplement's walk in height space
// ---------------------------------------------------------------------------------------------

/// The crate's walks carry ln C¹ instead of heights, so their results do not depend on the
/// height distribution by construction (supplement §1.1). This test checks that construction:
/// `eval` against the supplement's height-space algorithm ([`reference_eval`]) run on uniform
/// and on Gaussian heights, by two-sample tests on reflected and (dielectric) transmitted ωo and
/// from inside the dielectric.
#[test]
fn walk_in_c1_space_matches_the_height_space_walk_for_both_heights() {
    const N: usize = 200_000;
    let mats = [Mat::Gold, Mat::Diffuse(0.5), Mat::Dielectric];
    let slopes = [(Slope::Ggx, 1), (Slope::Beckmann, 2)];
    let heights = [Height::Uniform, Height::Gaussian];
    let mut cases: Vec<(Mat, Slope, usize, Height, Vec3, Vec3)> = Vec::new();
    for &m in &mats {
        for &(s, a) in &slopes {
            // the dielectric's reflection at α = 1.5 is too weak for a 1 % standard error
            let a = if m == Mat::Dielectric && a == 1 { 0 } else { a };
            for &h in &heights {
                // near the specular directions, where the values are large enough for a 1 %
                // relative standard error
                let back = PHI_I + PI;
                let pairs = if m == Mat::Dielectric {
                    vec![
                        (validation::dir(1.0, PHI_I), validation::dir(1.0, back)),
                        (validation::dir(1.0, PHI_I), validation::dir(PI - 0.6, back)),
                        (validation::dir(PI - 0.3, PHI_I), validation::dir(0.45, back)),
                    ]
                } else {
                    vec![(validation::dir(1.0, PHI_I), validation::dir(0.6, 3.5))]
                };
                cases.extend(pairs.into_iter().map(|(wi, wo)| (m, s, a, h, wi, wo)));
            }
        }
    }
    let z = validation::family_z(0.01, cases.len());
    let out = par_map(&cases, |i, &(m, s, a, h, wi, wo)| {
        let bsdf = build(h, s, ALPHAS[a], m);
        let mut rng = validation::rng(600 + i as u64);
        let (mut walk, mut reference) = (Stats::default(), Stats::default());
        for _ in 0..N {
            walk.push(f64::from(bsdf.eval(wi, wo, ScatteringOrder::All, &mut rng).x));
            reference.push(f64::from(bsdf.reference_eval(wi, wo, &mut rng).x));
        }
        let label = format!(
            "{}: eval (C¹ space) vs height-space walk, ωi.z = {}, ωo.z = {}",
            bsdf.name(),
            wi.z,
            wo.z
        );
        let scale = walk.mean().max(reference.mean());
        assert!(scale > 1e-3, "{label}: vanishing value {scale:e}");
        validation::assert_two_sample(&label, &walk, &reference, z, 0.01 * scale);
        println!(
            "{label}: {:.5} ± {:.5} vs {:.5} ± {:.5}",
            walk.mean(),
            walk.se(),
            reference.mean(),
            reference.se()
        );
        (walk.mean() - reference.mean(), walk.se().hypot(reference.se()))
    });
    println!(
        "C¹ vs height-space walk: {} comparisons, worst |Δ|/SE = {:.2} (z = {z:.2})",
        out.len(),
        worst_z(&out)
    );
}

// ---------------------------------------------------------------------------------------------
// absorptive materials
// ---------------------------------------------------------------------------------------------

#[test]
fn gold_conductor_albedo() {
    const N: usize = 200_000;
    let cases = [(Height::Uniform, Slope::Ggx, 1, 0.8), (Height::Gaussian, Slope::Beckmann, 2, 1.3)];
    // per case and channel: the two-sample equality and the one-sided upper bound
    let z = validation::family_z(0.01, 3 * cases.len());
    let z_one_sided =
        Normal::new(0.0, 1.0).unwrap().inverse_cdf(1.0 - validation::sidak(0.01, 3 * cases.len()));
    let out = par_map(&cases, |i, &(h, s, a, theta)| {
        let bsdf = build(h, s, ALPHAS[a], Mat::Gold);
        let wi = validation::dir(theta, PHI_I);
        let mut rng = validation::rng(700 + i as u64);
        let by_eval = albedo(bsdf.as_ref(), wi, false, N, &mut rng);
        let mut by_sample = [Stats::default(); 3];
        let mut first_fresnel = [Stats::default(); 3];
        for _ in 0..N {
            let w = bsdf.sample(wi, &mut rng).map_or(Vec3::ZERO, |s| s.weight);
            let f = bsdf.sample_phase(wi, &mut rng).weight;
            for c in 0..3 {
                by_sample[c].push(f64::from(w[c]));
                first_fresnel[c].push(f64::from(f[c]));
            }
        }
        let mut res = Vec::new();
        for c in 0..3 {
            let label = format!("{}: channel {c}, θi = {theta}", bsdf.name());
            // every bounce multiplies by F ≤ 1: the albedo is at most the first bounce's mean
            // Fresnel factor E[F(ωi·ωm)], ωm ~ D_ωi (which is itself at most max F = 1)
            let (e, f) = (&by_eval[c], &first_fresnel[c]);
            let se = e.se().hypot(f.se());
            assert!(se <= 5e-3, "{label}: SE {se:.2e} too large");
            assert!(
                e.mean() <= f.mean() + z_one_sided * se,
                "{label}: albedo {:.5} ± {:.5} exceeds the first-bounce Fresnel mean {:.5} ± {:.5} (z = {z_one_sided:.2})",
                e.mean(),
                e.se(),
                f.mean(),
                f.se()
            );
            validation::assert_two_sample(
                &format!("{label}: albedo by eval vs E[weight] of sample"),
                e,
                &by_sample[c],
                z,
                5e-3,
            );
            println!(
                "gold {label}: ∫eval = {:.4} ± {:.4}, E[weight] = {:.4} ± {:.4}, E[F first] = {:.4} ± {:.4}",
                e.mean(),
                e.se(),
                by_sample[c].mean(),
                by_sample[c].se(),
                f.mean(),
                f.se()
            );
            res.push((e.mean() - by_sample[c].mean(), e.se().hypot(by_sample[c].se())));
        }
        // gold absorbs: the blue channel loses much more than the red one
        assert!(by_eval[2].mean() < by_eval[0].mean() - 0.1, "gold must absorb blue more than red");
        res
    });
    let flat: Vec<(f64, f64)> = out.into_iter().flatten().collect();
    println!("gold: worst |∫eval − E[weight]|/SE = {:.2} (z = {z:.2})", worst_z(&flat));
}

#[test]
fn grey_diffuse_sample_weight_matches_albedo() {
    const N: usize = 200_000;
    let cases = [(Height::Gaussian, Slope::Ggx, 1, 0.5), (Height::Uniform, Slope::Beckmann, 2, 1.4)];
    let z = validation::family_z(0.01, cases.len());
    let out = par_map(&cases, |i, &(h, s, a, theta)| {
        let bsdf = build(h, s, ALPHAS[a], Mat::Diffuse(0.5));
        let wi = validation::dir(theta, PHI_I);
        let mut rng = validation::rng(800 + i as u64);
        let [by_eval, _, _] = albedo(bsdf.as_ref(), wi, false, N, &mut rng);
        let mut by_sample = Stats::default();
        for _ in 0..N {
            by_sample.push(bsdf.sample(wi, &mut rng).map_or(0.0, |s| f64::from(s.weight.x)));
        }
        let label = format!("{}: albedo 0.5, θi = {theta}: ∫eval vs E[weight]", bsdf.name());
        validation::assert_two_sample(&label, &by_eval, &by_sample, z, 3e-3);
        assert!(by_eval.mean() < 0.5, "{label}: the albedo must be below the facet albedo");
        println!(
            "{label}: {:.4} ± {:.4} vs {:.4} ± {:.4}",
            by_eval.mean(),
            by_eval.se(),
            by_sample.mean(),
            by_sample.se()
        );
        (by_eval.mean() - by_sample.mean(), by_eval.se().hypot(by_sample.se()))
    });
    println!("grey diffuse: worst |Δ|/SE = {:.2} (z = {z:.2})", worst_z(&out));
}

// ---------------------------------------------------------------------------------------------
// scattering orders
// ---------------------------------------------------------------------------------------------

/// Orders summed: the mass beyond is negligible (tests/walk/cap.rs measures the fraction of
/// walks longer than 64 bounces at α = 2: below 1e-4, and none at these α in its runs).
const MAX_ORDER: u32 = 64;

#[test]
fn orders_sum_to_the_full_bsdf() {
    const N: usize = 30_000;
    let cases = [
        (Mat::Conductor, Height::Uniform, Slope::Ggx, 1, 0.8, 1.1),
        (Mat::Diffuse(1.0), Height::Gaussian, Slope::Beckmann, 1, 1.2, 0.4),
        (Mat::Dielectric, Height::Gaussian, Slope::Ggx, 2, 0.5, PI - 0.7),
    ];
    let z = validation::family_z(0.01, 2 * cases.len());
    let out = par_map(&cases, |i, &(m, h, s, a, ti, to)| {
        let bsdf = build(h, s, ALPHAS[a], m);
        let (wi, wo) = (validation::dir(ti, PHI_I), validation::dir(to, PHI_I + PI));
        let mut rng = validation::rng(900 + i as u64);
        let (mut sum, mut all, mut sum3, mut up3) =
            (Stats::default(), Stats::default(), Stats::default(), Stats::default());
        for _ in 0..N {
            let mut s = 0.0;
            for order in 1..=MAX_ORDER {
                s += f64::from(bsdf.eval(wi, wo, ScatteringOrder::only(order).unwrap(), &mut rng).x);
                if order == 3 {
                    sum3.push(s);
                }
            }
            sum.push(s);
            all.push(f64::from(bsdf.eval(wi, wo, ScatteringOrder::All, &mut rng).x));
            up3.push(f64::from(bsdf.eval(wi, wo, ScatteringOrder::up_to(3).unwrap(), &mut rng).x));
        }
        let label = format!("{}: θi = {ti}, θo = {to:.3}", bsdf.name());
        let scale = all.mean();
        assert!(scale > 1e-3, "{label}: vanishing BSDF {scale:e}");
        validation::assert_two_sample(&format!("{label}: Σ only(n) vs All"), &sum, &all, z, 0.02 * scale);
        validation::assert_two_sample(
            &format!("{label}: Σ_{{n≤3}} only(n) vs up_to(3)"),
            &sum3,
            &up3,
            z,
            0.02 * scale,
        );
        println!(
            "orders {label}: Σ only(n) = {:.5} ± {:.5}, All = {:.5} ± {:.5}, only(1) share {:.3}",
            sum.mean(),
            sum.se(),
            all.mean(),
            all.se(),
            1.0 - (all.mean() - sum3.mean()) / all.mean()
        );
        [
            (sum.mean() - all.mean(), sum.se().hypot(all.se())),
            (sum3.mean() - up3.mean(), sum3.se().hypot(up3.se())),
        ]
    });
    let flat: Vec<(f64, f64)> = out.into_iter().flatten().collect();
    println!("orders: worst |Δ|/SE = {:.2} (z = {z:.2})", worst_z(&flat));
}

/// The side of the interface for an `outside` flag.
fn sided(outside: bool) -> Side {
    if outside { Side::Outside } else { Side::Inside }
}
