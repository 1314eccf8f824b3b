//! Importance sampling of the distribution of visible normals (Heitz et al. 2016, supplement
//! §4.2.2): `sample_d_wi` against `d_wi` for GGX and Beckmann, 5 roughnesses × 6 incident
//! angles (60 cases, 10⁶ samples each, fixed seeds).
//!
//! Per case: (1) the moments E[x], E[y], E[z], E[x²], E[y²], E[z²] of the sampled normals
//! agree with their quadrature within z·SE, z from the family-wise level 0.01 over the 360
//! moments; (2) a chi-square goodness-of-fit test at the Šidák level of 0.01 over the 60
//! cases, on equal-area bins over the sphere for broad lobes and over a cap around the mean
//! normal (a few lobe widths wide, from quadrature) for sharp ones; (3) every sample is a
//! finite unit normal of the upper hemisphere visible from ωi. Negative controls show that
//! the same harness rejects wrong samplers.

use glam::Vec3;
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Ggx};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use validation::check::panic_message;
use validation::chi2::SlopeGrid;
use validation::chi2::{Chi2Grid, chi2_test};
use validation::quadrature::{CrossMap, SlopeFamily, VisibleTolerance, integrate_visible};
use validation::{Stats, assert_mean};

const ALPHAS: [(f32, f32); 5] = [(0.05, 0.05), (0.3, 0.3), (1.0, 1.0), (1.0, 0.1), (0.2, 1.5)];
const THETAS: [f64; 6] = [0.0, 0.5, 1.2, 1.55, 2.0, 2.8];
/// Samples per case.
const N: usize = 1_000_000;
/// Samples per negative control (a wrong sampler is rejected with χ² ≫ 10³ already).
const N_CONTROL: usize = 200_000;
/// Family-wise significance of each family of tests.
const FAMILY_ALPHA: f64 = 0.01;
/// Chi-square tests (one per case).
const CASES: usize = 60;
/// Moment tests: six per case.
const MOMENTS: usize = 6 * CASES;
/// Largest SE accepted for a moment (|component| ≤ 1, so σ ≤ 1 and SE ≤ 1e-3 at N = 10⁶):
/// with z ≈ 4.3 a moment bias above ~5e-3 is detected.
const MAX_SE: f64 = 1e-3;
/// Absolute adaptive tolerance of the slope-space quadrature.
const QUAD_TOL: f64 = 1e-7;
/// Relative adaptive tolerance per initial cell (above the f32 rounding of the integrand).
const REL_TOL: f64 = 1e-6;
/// Maximum refinement depth of each initial cell.
const MAX_DEPTH: u32 = 8;
/// The deterministic error of the quadrature moments: the adaptive tolerances (~1e-6) and
/// the f32 rounding of the densities and of ωm (up to ~1e-5 relative where the Beckmann
/// exponent is large), so 1e-4.
const QUAD_EXACT_TOL: f64 = 1e-4;

/// The object-safe part of `MicrosurfaceSlope` used here.
trait SlopeDyn: Send + Sync {
    fn alpha(&self) -> (f32, f32);
    fn d_wi(&self, wi: Vec3, m: Vec3) -> f32;
    /// D_ωi at a normal given in double precision (no rounding of the normal to f32).
    fn d_wi64(&self, wi: Vec3, m: glam::DVec3) -> f64;
    /// The cross map matched to the tails (Beckmann: the cross slope is N(0, ½) whatever the
    /// other, and binned through erf).
    fn cross_map(&self) -> CrossMap;
    fn sample(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3;
    fn visible_integral(&self, w: Vec3, g: &mut dyn FnMut(Vec3) -> f64) -> f64;
}

impl<S: SlopeFamily + Send + Sync> SlopeDyn for S {
    fn alpha(&self) -> (f32, f32) {
        (self.alpha_x(), self.alpha_y())
    }
    fn d_wi(&self, wi: Vec3, m: Vec3) -> f32 {
        MicrosurfaceSlope::d_wi(self, wi, m)
    }
    fn d_wi64(&self, wi: Vec3, m: glam::DVec3) -> f64 {
        MicrosurfaceSlope::d_wi64(self, wi, m)
    }
    fn cross_map(&self) -> CrossMap {
        S::TAILS.cross_map()
    }
    fn sample(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        self.sample_d_wi(wi, u1, u2)
    }
    fn visible_integral(&self, w: Vec3, g: &mut dyn FnMut(Vec3) -> f64) -> f64 {
        integrate_visible(SlopeDyn::alpha(self), S::TAILS.cross_map(), w, TOLERANCE, g)
    }
}

/// The tolerances of the visible-normal quadrature.
const TOLERANCE: VisibleTolerance =
    VisibleTolerance { abs_tol: QUAD_TOL, rel_tol: REL_TOL, max_depth: MAX_DEPTH };

/// One configuration of the suite.
struct Case {
    label: String,
    slope: Box<dyn SlopeDyn>,
    wi: Vec3,
    seed: u64,
}

/// The 60 cases: isotropic roughness at azimuth 0, anisotropic at azimuth 0.7.
fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    for (k, name) in ["ggx", "beckmann"].into_iter().enumerate() {
        for (i, a) in ALPHAS.into_iter().enumerate() {
            for (j, theta) in THETAS.into_iter().enumerate() {
                let phi = if a.0 == a.1 { 0.0 } else { 0.7 };
                let slope: Box<dyn SlopeDyn> = if k == 0 {
                    Box::new(Ggx::new(a.0, a.1).unwrap())
                } else {
                    Box::new(Beckmann::new(a.0, a.1).unwrap())
                };
                let idx = (k * ALPHAS.len() + i) * THETAS.len() + j;
                out.push(Case {
                    label: format!("{name} α = ({}, {}), θi = {theta}, φi = {phi}", a.0, a.1),
                    slope,
                    wi: validation::dir(theta, phi),
                    seed: 0x5eed_0000 + idx as u64,
                });
            }
        }
    }
    assert_eq!(out.len(), CASES);
    out
}

/// The moments ∫ f(ωm) D_ωi(ωm) dωm of f = 1, x, y, z, x², y², z² by quadrature.
fn quadrature_moments(c: &Case) -> [f64; 7] {
    let fs: [fn(Vec3) -> f64; 7] = [
        |_| 1.0,
        |m| f64::from(m.x),
        |m| f64::from(m.y),
        |m| f64::from(m.z),
        |m| f64::from(m.x) * f64::from(m.x),
        |m| f64::from(m.y) * f64::from(m.y),
        |m| f64::from(m.z) * f64::from(m.z),
    ];
    fs.map(|f| c.slope.visible_integral(c.wi, &mut |m| f(m) * f64::from(c.slope.d_wi(c.wi, m))))
}

/// Adaptive tolerance of the expected probabilities (summed over the cells): at most
/// 1e-5 × 10⁶ = 10 expected samples misplaced in all, which moves χ² by ≪ 1 (√(2·dof) ≈ 40).
const CHI2_QUAD_TOL: f64 = 1e-5;
/// Maximum depth of the per-cell quadrature (cells are 1/800 of the cap already).
const CHI2_MAX_DEPTH: u32 = 6;

/// The sample checks: finite, unit, upper hemisphere, visible from ωi.
fn sample_defect(wi: Vec3, m: Vec3) -> Option<String> {
    if !m.is_finite() {
        return Some(format!("not finite: {m:?}"));
    }
    if (m.length() - 1.0).abs() > 1e-5 {
        return Some(format!("not unit: |m| − 1 = {:e}, m = {m:?}", m.length() - 1.0));
    }
    if m.z < 0.0 {
        return Some(format!("below the horizon: m = {m:?}"));
    }
    if wi.dot(m) < -1e-6 {
        return Some(format!("not visible: ωi·m = {:e}, m = {m:?}", wi.dot(m)));
    }
    None
}

/// The slope-space chi-square test (`validation::chi2::slope_chi2`) of a case: 25 u-bins of
/// equal probability (edges from 1024 quadrature strips), each split in 32 equal v-bins.
fn slope_chi2(
    c: &Case,
    sample: impl FnMut() -> Vec3,
    n: usize,
    alpha: f64,
) -> Result<(f64, usize, f64, f64), String> {
    let grid = SlopeGrid { nu: 25, nv: 32, strips: 1024, rel_tol: REL_TOL, max_depth: MAX_DEPTH };
    let (wi, slope) = (c.wi, &c.slope);
    let o = validation::chi2::slope_chi2(
        &c.label,
        slope.alpha(),
        slope.cross_map(),
        wi,
        grid,
        |m| slope.d_wi64(wi, m),
        sample,
        n,
        alpha,
    )?;
    Ok((o.statistic, o.dof, o.p_value, o.integral))
}

/// Runs one case: returns (χ², dof, p, ∫D_ωi), or the failure message.
fn run_case(c: &Case) -> Result<(f64, usize, f64, f64), String> {
    let q = quadrature_moments(c);
    let alpha = validation::sidak(FAMILY_ALPHA, CASES);
    let mut rng = validation::rng(c.seed);
    let mut stats = [Stats::default(); 6];
    let mut defects = (0usize, None::<String>);
    let (wi, slope) = (c.wi, &c.slope);
    let outcome = slope_chi2(
        c,
        || {
            let u1 = rand::RngExt::random::<f32>(&mut rng);
            let u2 = rand::RngExt::random::<f32>(&mut rng);
            let m = slope.sample(wi, u1, u2);
            if let Some(d) = sample_defect(wi, m) {
                defects.0 += 1;
                defects.1.get_or_insert(format!("{d} (u1 = {u1:e}, u2 = {u2:e})"));
            }
            let (x, y, z) = (f64::from(m.x), f64::from(m.y), f64::from(m.z));
            for (s, v) in stats.iter_mut().zip([x, y, z, x * x, y * y, z * z]) {
                s.push(v);
            }
            m
        },
        N,
        alpha,
    )?;
    if defects.0 > 0 {
        return Err(format!(
            "{}: {} defective samples of {N}, first: {}",
            c.label,
            defects.0,
            defects.1.unwrap()
        ));
    }
    let z = validation::family_z(FAMILY_ALPHA, MOMENTS);
    let names = ["E[x]", "E[y]", "E[z]", "E[x²]", "E[y²]", "E[z²]"];
    for (k, name) in names.iter().enumerate() {
        let label = format!("{}: {name} (quadrature ∫D_ωi = {:.8})", c.label, q[0]);
        std::panic::catch_unwind(|| assert_mean(&label, &stats[k], q[k + 1], z, MAX_SE, QUAD_EXACT_TOL))
            .map_err(|e| panic_message(e.as_ref()))?;
    }
    Ok(outcome)
}

/// Supplement §4.2.2 plus a chi-square test, for all 60 cases (two threads).
#[test]
fn vndf_sampling_matches_density_4_2_2() {
    let cases = cases();
    let next = AtomicUsize::new(0);
    let results = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(c) = cases.get(i) else { break };
                    let r = run_case(c);
                    match &r {
                        Ok(o) => println!(
                            "{}: N = {N}, χ² = {:.1}, dof = {}, p = {:.4}, ∫D_ωi = {:.7}",
                            c.label, o.0, o.1, o.2, o.3
                        ),
                        Err(e) => println!("FAILED {e}"),
                    }
                    results.lock().unwrap().push((i, r));
                }
            });
        }
    });
    let results = results.into_inner().unwrap();
    let failures: Vec<&String> = results.iter().filter_map(|(_, r)| r.as_ref().err()).collect();
    let worst = results
        .iter()
        .filter_map(|(i, r)| r.as_ref().ok().map(|o| (o.2, &cases[*i].label)))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((p, label)) = worst {
        println!(
            "worst p-value {p:.4} ({label}); α per test = {:.3e}",
            validation::sidak(FAMILY_ALPHA, CASES)
        );
    }
    assert!(
        failures.is_empty(),
        "{} of {CASES} VNDF sampling cases failed:\n{}",
        failures.len(),
        failures.iter().map(|s| s.as_str()).collect::<Vec<_>>().join("\n")
    );
}

/// Sampled normals are finite, unit, in the upper hemisphere and visible for the extreme
/// uniforms 0, 2⁻²⁴, ½ and the largest f32 below 1, in all 60 configurations.
#[test]
fn vndf_samples_are_valid_at_extreme_uniforms() {
    let us = [0.0, f32::EPSILON / 2.0, 0.5, 1.0 - f32::EPSILON / 2.0];
    assert!(us[3] < 1.0 && us[3] == f32::from_bits(1.0f32.to_bits() - 1));
    let mut bad = Vec::new();
    for c in cases() {
        for u1 in us {
            for u2 in us {
                let m = c.slope.sample(c.wi, u1, u2);
                if let Some(d) = sample_defect(c.wi, m) {
                    bad.push(format!("{}: u1 = {u1:e}, u2 = {u2:e}: {d}", c.label));
                }
            }
        }
    }
    assert!(bad.is_empty(), "{} invalid samples:\n{}", bad.len(), bad.join("\n"));
}

/// Runs the harness on a sampler that is known to be wrong and returns whether it rejected
/// it (the harness panics on rejection).
fn rejects(label: &str, wi: Vec3, pdf: &dyn SlopeDyn, sampler: impl Fn(f32, f32) -> Vec3, seed: u64) -> bool {
    let mut rng = validation::rng(seed);
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        chi2_test(
            label,
            Chi2Grid { quad_tol: CHI2_QUAD_TOL, max_depth: CHI2_MAX_DEPTH, ..Chi2Grid::sphere(40, 40) },
            |m| f64::from(pdf.d_wi(wi, m)),
            || {
                let u1 = rand::RngExt::random::<f32>(&mut rng);
                let u2 = rand::RngExt::random::<f32>(&mut rng);
                Some(sampler(u1, u2))
            },
            N_CONTROL,
            validation::sidak(FAMILY_ALPHA, CASES),
            1.0,
        )
    }))
    .is_err()
}

/// Negative controls: the harness (with the suite's N, grid and significance) rejects
/// samplers that are slightly wrong, so the suite can fail.
#[test]
fn chi2_rejects_wrong_samplers() {
    let wi = validation::dir(0.5, 0.0);
    let ggx = Ggx::isotropic(0.3).unwrap();
    // GGX normals sampled with a roughness 10 % too high
    let wrong_alpha = Ggx::isotropic(0.33).unwrap();
    assert!(
        rejects(
            "GGX α = 0.33 sampled for α = 0.3",
            wi,
            &ggx,
            |u1, u2| wrong_alpha.sample_d_wi(wi, u1, u2),
            91
        ),
        "the chi-square harness accepted GGX normals sampled with α = 0.33 against α = 0.3 (θi = 0.5)"
    );
    // normals from D cos θm (the visible normals seen from the zenith) instead of D_ωi
    let wi = validation::dir(1.2, 0.0);
    assert!(
        rejects("D cos θm sampled for D_ωi", wi, &ggx, |u1, u2| ggx.sample_d_wi(Vec3::Z, u1, u2), 92),
        "the chi-square harness accepted normals from D cos θm against D_ωi (θi = 1.2)"
    );
    // Beckmann density, GGX sampler with the same α
    let beckmann = Beckmann::isotropic(0.3).unwrap();
    assert!(
        rejects("GGX sampled for Beckmann", wi, &beckmann, |u1, u2| ggx.sample_d_wi(wi, u1, u2), 93),
        "the chi-square harness accepted GGX visible normals against the Beckmann D_ωi (α = 0.3, θi = 1.2)"
    );
}

/// Beckmann cases for the tabulated-guess sampler beyond the 60 above: α down to
/// 0.01 and ωi far below the horizon (κ = cot θ/α from 0.01·… to −72.6 and −8.1).
fn beckmann_deep_cases(full: bool) -> Vec<Case> {
    let configs: &[(f32, f64)] = if full {
        &[(0.01, 0.3), (0.01, 1.4), (0.01, 1.6), (0.01, 2.2), (0.5, 0.3), (0.5, 1.4), (0.5, 2.2), (0.5, 2.9)]
    } else {
        &[(0.01, 0.3), (0.01, 1.6), (0.01, 2.2), (0.5, 2.9)]
    };
    configs
        .iter()
        .enumerate()
        .map(|(i, &(a, theta))| Case {
            label: format!("beckmann α = {a}, θi = {theta}"),
            slope: Box::new(Beckmann::isotropic(a).unwrap()),
            wi: validation::dir(theta, 0.3),
            seed: 0x5eed_1700 + i as u64 + if full { 100 } else { 0 },
        })
        .collect()
}

/// The chi-square test in slope space (`slope_chi2`) of `n` Beckmann samples per case, at the
/// Šidák level of the family; panics listing the failures.
fn beckmann_deep_chi2(cases: &[Case], n: usize) {
    let alpha = validation::sidak(FAMILY_ALPHA, cases.len());
    let mut failures = Vec::new();
    for c in cases {
        let mut rng = validation::rng(c.seed);
        let (wi, slope) = (c.wi, &c.slope);
        let r = slope_chi2(
            c,
            || slope.sample(wi, rand::RngExt::random::<f32>(&mut rng), rand::RngExt::random::<f32>(&mut rng)),
            n,
            alpha,
        );
        match r {
            Ok(o) => println!(
                "{}: N = {n}, χ² = {:.1}, dof = {}, p = {:.4}, ∫D_ωi = {:.7}",
                c.label, o.0, o.1, o.2, o.3
            ),
            Err(e) => failures.push(e),
        }
    }
    assert!(failures.is_empty(), "{} Beckmann cases failed:\n{}", failures.len(), failures.join("\n"));
}

/// The Beckmann sampler at α = 0.01 and far below the horizon, 10⁶ samples per case.
#[test]
fn beckmann_vndf_small_roughness_and_deep_views() {
    beckmann_deep_chi2(&beckmann_deep_cases(false), N);
}

/// The same at 10⁷ samples per case and 8 cases (about 20 s in release on two threads).
#[test]
#[ignore = "10⁷ samples per case: minutes in release; run with --ignored"]
fn beckmann_vndf_small_roughness_and_deep_views_1e7() {
    beckmann_deep_chi2(&beckmann_deep_cases(true), 10_000_000);
}
