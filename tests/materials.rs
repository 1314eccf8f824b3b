//! The phase functions of the microsurface materials (Heitz et al. 2016, supplement §4.3):
//! energy conservation (4.3.1), reciprocity (4.3.2) and importance sampling (4.3.3), for the
//! perfect conductor, the dielectric (both sides of the interface) and the white diffuse
//! material, on GGX and Beckmann with α ∈ {0.3, 1.0, (1.0, 0.1)}, for incident directions on
//! the whole sphere (the random walk calls the phase functions from below the horizon).
//!
//! Statistics: every Monte Carlo assertion is |mean − expected| ≤ z·SE with
//! z = `family_z(0.01, m)` for the m assertions of its test function, and asserts an upper
//! bound on SE; chi-square tests use the Šidák-corrected level `sidak(0.01, m)`.
//!
//! The diffuse phase function is stochastic (one visible normal per call), so its chi-square
//! test cannot use a pointwise density. Its expected cell probabilities are estimated by Monte
//! Carlo instead: `PER_CELL` uniform directions per cell, one independent `eval_phase` each;
//! the statistic Σ (O − N m̂)² / (N m̂ + N² Var m̂) includes the variance of the estimated
//! expectation, and its degrees of freedom are moment-matched, k − Σ m/(1 + N Var m̂/m)
//! (k − 1 when the expectation is exact, k when its noise dominates). See `stochastic_chi2`.
use validation::par_map;
use validation::stochastic::{StochasticGrid, stochastic_chi2_with};
use validation::uniform_sphere;

use glam::Vec3;
use microsurface::research::{Interaction, Side};
use microsurface::research::{Material, Microsurface, PhaseSample, UniformHeight};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, ComplexIor, Conductor, Dielectric, Diffuse, Ggx};
use std::f64::consts::PI;
use validation::chi2::{Chi2Grid, chi2_test};
use validation::quadrature::{Domain, integrate_sphere};
use validation::{Stats, TestRng};

const ALPHAS: [(f32, f32); 3] = [(0.3, 0.3), (1.0, 1.0), (1.0, 0.1)];
const ETA: f32 = 1.5;
/// Azimuth of every incident direction (so that anisotropic roughness matters).
const PHI_I: f64 = 0.7;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Conductor,
    Dielectric,
    Diffuse,
}

/// A microsurface seen through its phase functions, type-erased over slope and material.
trait Phase: Sync {
    fn name(&self) -> &str;
    fn kind(&self) -> Kind;
    /// The material's phase function (channel x) for the given sides (`Material::eval_phase`).
    fn sided(&self, wi: Vec3, wo: Vec3, wi_out: bool, wo_out: bool, rng: &mut TestRng) -> f64;
    /// `Material::sample_phase`.
    fn sample_sided(&self, wi: Vec3, wi_out: bool, rng: &mut TestRng) -> PhaseSample;
    /// `Microsurface::eval_phase` (ωi outside, both sides of ωo summed), channel x.
    fn eval(&self, wi: Vec3, wo: Vec3, rng: &mut TestRng) -> f64;
    /// `Microsurface::sample_phase`.
    fn sample(&self, wi: Vec3, rng: &mut TestRng) -> PhaseSample;
    /// Smith Λ of the slope distribution.
    fn lambda(&self, w: Vec3) -> f64;

    /// The phase function summed over the sides of ωo: the density of `sample_sided`'s ωo.
    fn total(&self, wi: Vec3, wo: Vec3, wi_out: bool, rng: &mut TestRng) -> f64 {
        if self.kind() == Kind::Dielectric {
            self.sided(wi, wo, wi_out, true, rng) + self.sided(wi, wo, wi_out, false, rng)
        } else {
            self.sided(wi, wo, true, true, rng)
        }
    }

    /// σ(−ω)/area = (1 + Λ(ω)) cos θ, in f64 from the library's Λ.
    fn smith_area(&self, w: Vec3) -> f64 {
        (1.0 + self.lambda(w)) * f64::from(w.z)
    }
}

struct Surface<S, M> {
    name: String,
    kind: Kind,
    surface: Microsurface<UniformHeight, S, M>,
}

impl<S: MicrosurfaceSlope, M: Material> Phase for Surface<S, M> {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> Kind {
        self.kind
    }
    fn sided(&self, wi: Vec3, wo: Vec3, wi_out: bool, wo_out: bool, rng: &mut TestRng) -> f64 {
        f64::from(
            self.surface
                .material()
                .eval_phase(self.surface.slope(), &Interaction::new(wi, wo, side(wi_out), side(wo_out)), rng)
                .x,
        )
    }
    fn sample_sided(&self, wi: Vec3, wi_out: bool, rng: &mut TestRng) -> PhaseSample {
        self.surface.material().sample_phase(self.surface.slope(), wi, side(wi_out), rng)
    }
    fn eval(&self, wi: Vec3, wo: Vec3, rng: &mut TestRng) -> f64 {
        f64::from(self.surface.eval_phase(wi, wo, rng).x)
    }
    fn sample(&self, wi: Vec3, rng: &mut TestRng) -> PhaseSample {
        self.surface.sample_phase(wi, rng)
    }
    fn lambda(&self, w: Vec3) -> f64 {
        f64::from(self.surface.slope().lambda(w))
    }
}

fn boxed<S: MicrosurfaceSlope + 'static, M: Material + 'static>(
    slope_name: &str,
    slope: S,
    kind: Kind,
    material: M,
) -> Box<dyn Phase> {
    let name = format!("{kind:?} {slope_name}(αx = {}, αy = {})", slope.alpha_x(), slope.alpha_y());
    Box::new(Surface { name, kind, surface: Microsurface::new(UniformHeight, slope, material) })
}

fn with_material<S: MicrosurfaceSlope + 'static>(slope_name: &str, slope: S, kind: Kind) -> Box<dyn Phase> {
    match kind {
        Kind::Conductor => boxed(slope_name, slope, kind, Conductor::perfect()),
        Kind::Dielectric => boxed(slope_name, slope, kind, Dielectric::new(ETA).unwrap()),
        Kind::Diffuse => boxed(slope_name, slope, kind, Diffuse::white()),
    }
}

/// Every slope × α × material of `kinds`.
fn surfaces(kinds: &[Kind]) -> Vec<Box<dyn Phase>> {
    let mut out = Vec::new();
    for &(ax, ay) in &ALPHAS {
        for &kind in kinds {
            out.push(with_material("GGX", Ggx::new(ax, ay).unwrap(), kind));
            out.push(with_material("Beckmann", Beckmann::new(ax, ay).unwrap(), kind));
        }
    }
    out
}

fn wi_at(theta: f64) -> Vec3 {
    validation::dir(theta, PHI_I)
}

// ---------------------------------------------------------------------------------------------
// 4.3.1 energy conservation
// ---------------------------------------------------------------------------------------------

/// Incident directions for energy conservation: zenith to below the horizon.
const NORM_THETAS: [f64; 5] = [0.0, 0.9, 1.5, 1.9, 2.2];
/// Tolerance of the sphere quadrature of an exact f32 density. The error is dominated by the
/// discontinuous edges of the lobes at grazing incidence (θi = 1.5: the dielectric's
/// transmission lobe ends abruptly where the facets turn vertical, with density ≈ 5 at the
/// edge) and by the lobes of grazing facets seen from below the horizon, which the adaptive
/// Gauss–Legendre rule resolves slowly: 32×64 cells give errors up to 8e-4 there (a brute
/// 8000×16000 midpoint rule still moves by ±4e-4); elsewhere the integrals match 1 to 1e-5.
/// The same 1e-3 is the normalization tolerance of the chi-square harness.
const QUAD_TOL: f64 = 1e-3;

#[test]
fn energy_conservation_exact_quadrature_4_3_1() {
    // (surface, θi, side of ωi): the dielectric also from inside the interface
    let surfaces = surfaces(&[Kind::Conductor, Kind::Dielectric]);
    let mut cases = Vec::new();
    for (s, surface) in surfaces.iter().enumerate() {
        for &theta in &NORM_THETAS {
            cases.push((s, theta, true));
            if surface.kind() == Kind::Dielectric {
                // from inside, the mirrored direction (θ ↦ π − θ): the flipped configuration
                // then sees the same incidence as outside
                cases.push((s, PI - theta, false));
            }
        }
    }
    let worst = par_map(&cases, |_, &(s, theta, wi_out)| {
        let surface = &surfaces[s];
        let wi = wi_at(theta);
        let mut rng = validation::rng(0); // unused: the densities are exact
        let mut f = |wo: Vec3| {
            if wi_out { surface.eval(wi, wo, &mut rng) } else { surface.total(wi, wo, false, &mut rng) }
        };
        let integral = integrate_sphere(&mut f, 32, 64, Domain::Sphere, 1e-5, 6);
        assert!(
            (integral - 1.0).abs() <= QUAD_TOL,
            "{}: ∫p(ωi, ωo)dωo = {integral:.6} ≠ 1 (θi = {theta}, ωi outside = {wi_out})",
            surface.name()
        );
        if (integral - 1.0).abs() > 1e-5 {
            println!(
                "{}: θi = {theta:.3}, outside = {wi_out}: ∫p − 1 = {:.2e}",
                surface.name(),
                integral - 1.0
            );
        }
        (integral - 1.0).abs()
    });
    let worst = worst.iter().cloned().fold(0.0, f64::max);
    println!("exact phase functions: {} cases, worst |∫p − 1| = {worst:.2e}", cases.len());
}

#[test]
fn energy_conservation_diffuse_monte_carlo_4_3_1() {
    // ∫p dωo = E[4π p(ωi, ωo)] for ωo uniform on the sphere; p is itself stochastic, and one
    // eval per ωo keeps the estimator unbiased.
    const N: usize = 200_000;
    let surfaces = surfaces(&[Kind::Diffuse]);
    let cases: Vec<(usize, f64)> =
        (0..surfaces.len()).flat_map(|s| NORM_THETAS.iter().map(move |&t| (s, t))).collect();
    let z = validation::family_z(0.01, cases.len());
    let out = par_map(&cases, |i, &(s, theta)| {
        let surface = &surfaces[s];
        let wi = wi_at(theta);
        let mut rng = validation::rng(1000 + i as u64);
        let mut stats = Stats::default();
        for _ in 0..N {
            let wo = uniform_sphere(&mut rng);
            stats.push(4.0 * PI * surface.eval(wi, wo, &mut rng));
        }
        let label = format!("{}: diffuse ∫p dωo, θi = {theta}", surface.name());
        validation::assert_mean(&label, &stats, 1.0, z, 5e-3, 0.0);
        (stats.mean(), stats.se())
    });
    let worst = out.iter().map(|(m, se)| ((m - 1.0) / se).abs()).fold(0.0, f64::max);
    println!("diffuse ∫p: {} cases, N = {N}, worst |mean − 1|/SE = {worst:.2} (z = {z:.2})", cases.len());
}

// ---------------------------------------------------------------------------------------------
// 4.3.2 reciprocity
// ---------------------------------------------------------------------------------------------

/// Pairs (θi, φi, θo, φo) on the outside of the interface, some below the horizon.
const RECIPROCITY_PAIRS: [(f64, f64, f64, f64); 6] = [
    (0.3, 0.0, 1.0, 2.5),
    (0.8, 0.7, 0.5, 3.5),
    (1.2, 1.0, 1.45, 4.0),
    (1.5, 0.2, 0.2, 3.0),
    (1.9, 0.5, 0.7, 3.8),
    (0.6, 2.0, 1.75, 5.0),
];
/// Relative tolerance of the exact reciprocity (f32 evaluation of D, Λ, F).
const RECIPROCITY_REL_TOL: f64 = 1e-4;

fn assert_rel(label: &str, a: f64, b: f64) -> f64 {
    assert!(a.is_finite() && b.is_finite() && a > 0.0 && b > 0.0, "{label}: {a:e} vs {b:e}");
    let rel = (a - b).abs() / a.max(b);
    assert!(rel <= RECIPROCITY_REL_TOL, "{label}: {a:.8e} vs {b:.8e}, relative difference {rel:.2e}");
    if rel > 1e-5 {
        println!("{label}: {a:.8e} vs {b:.8e}, relative difference {rel:.2e}");
    }
    rel
}

#[test]
fn reciprocity_exact_4_3_2() {
    let mut rng = validation::rng(0); // unused: exact densities
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for surface in surfaces(&[Kind::Conductor, Kind::Dielectric]) {
        for &(ti, pi, to, po) in &RECIPROCITY_PAIRS {
            let (wi, wo) = (validation::dir(ti, pi), validation::dir(to, po));
            // reflection: (1 + Λ(ωi)) cos θi p(ωi, ωo) = (1 + Λ(ωo)) cos θo p(ωo, ωi)
            let a = surface.smith_area(wi) * surface.sided(wi, wo, true, true, &mut rng);
            let b = surface.smith_area(wo) * surface.sided(wo, wi, true, true, &mut rng);
            let label = format!("{}: reflection reciprocity θi = {ti}, θo = {to}", surface.name());
            if a > 1e-30 || b > 1e-30 {
                worst = worst.max(assert_rel(&label, a, b));
                checked += 1;
            }
            if surface.kind() == Kind::Dielectric && wi.z > 0.0 && wo.z > 0.0 {
                // transmission from outside (η_i = 1) to inside (η_o = η), ωo' = −ωo below:
                // σ_out(ωi) p(ωi, ωo')/η_o² = σ_in(ωo') p(ωo', ωi)/η_i², where inside areas are
                // those of the flipped configuration, σ_in(ω) = (1 + Λ(−ω)) cos θ(−ω).
                let wt = -wo;
                let a = surface.smith_area(wi) * surface.sided(wi, wt, true, false, &mut rng)
                    / f64::from(ETA * ETA);
                let b = surface.smith_area(-wt) * surface.sided(wt, wi, false, true, &mut rng);
                let label = format!("{}: transmission reciprocity θi = {ti}, θo = {to}", surface.name());
                if a > 1e-30 || b > 1e-30 {
                    worst = worst.max(assert_rel(&label, a, b));
                    checked += 1;
                }
            }
        }
    }
    assert!(checked >= 60, "too few non-zero configurations ({checked}): the test would be vacuous");
    println!("exact phase reciprocity: {checked} pairs, worst relative difference {worst:.2e}");
}

#[test]
fn reciprocity_diffuse_two_sample_4_3_2() {
    const N: usize = 100_000;
    let surfaces = surfaces(&[Kind::Diffuse]);
    let cases: Vec<(usize, usize)> =
        (0..surfaces.len()).flat_map(|s| (0..RECIPROCITY_PAIRS.len()).map(move |p| (s, p))).collect();
    let z = validation::family_z(0.01, cases.len());
    let out = par_map(&cases, |i, &(s, p)| {
        let surface = &surfaces[s];
        let (ti, pi, to, po) = RECIPROCITY_PAIRS[p];
        let (wi, wo) = (validation::dir(ti, pi), validation::dir(to, po));
        let mut rng = validation::rng(2000 + i as u64);
        let (ai, ao) = (surface.smith_area(wi), surface.smith_area(wo));
        let (mut a, mut b) = (Stats::default(), Stats::default());
        for _ in 0..N {
            a.push(ai * surface.eval(wi, wo, &mut rng));
            b.push(ao * surface.eval(wo, wi, &mut rng));
        }
        let label = format!("{}: diffuse reciprocity θi = {ti}, θo = {to}", surface.name());
        let scale = a.mean().max(b.mean());
        assert!(scale > 1e-4, "{label}: vanishing phase function {scale:e}: vacuous");
        validation::assert_two_sample(&label, &a, &b, z, 0.03 * scale);
        (a.mean() - b.mean()).abs() / (a.se().hypot(b.se()))
    });
    let worst = out.iter().cloned().fold(0.0, f64::max);
    println!(
        "diffuse phase reciprocity: {} cases, N = {N} each side, worst |Δ|/SE = {worst:.2} (z = {z:.2})",
        cases.len()
    );
}

// ---------------------------------------------------------------------------------------------
// 4.3.3 importance sampling
// ---------------------------------------------------------------------------------------------

/// Incident directions of the sampling tests: moderate, grazing, below the horizon.
const SAMPLE_THETAS: [f64; 3] = [0.4, 1.5, 2.2];
/// The inside incident direction of the dielectric (pointing down: a ray going up inside).
const INSIDE_THETA: f64 = 2.5;
const CHI2_N: usize = 100_000;

#[test]
fn sampling_chi2_exact_4_3_3() {
    // (surface, θi, ωi outside)
    let surfaces = surfaces(&[Kind::Conductor, Kind::Dielectric]);
    let mut cases = Vec::new();
    for (s, surface) in surfaces.iter().enumerate() {
        for &theta in &SAMPLE_THETAS {
            cases.push((s, theta, true));
        }
        if surface.kind() == Kind::Dielectric {
            cases.push((s, INSIDE_THETA, false));
        }
    }
    let alpha = validation::sidak(0.01, cases.len());
    // the dielectric's branch probabilities: z-tests, one per dielectric case
    let dielectric_cases = cases.iter().filter(|c| surfaces[c.0].kind() == Kind::Dielectric).count();
    let z = validation::family_z(0.01, dielectric_cases);
    let p_values = par_map(&cases, |i, &(s, theta, wi_out)| {
        let surface = &surfaces[s];
        let wi = wi_at(theta);
        let label = format!("{}: sample_phase, θi = {theta}, ωi outside = {wi_out}", surface.name());
        let mut rng = validation::rng(3000 + i as u64);
        let mut dummy = validation::rng(0);
        let mut same_side = 0usize;
        let pdf = |wo: Vec3| {
            if wi_out {
                surface.eval(wi, wo, &mut validation::rng(0))
            } else {
                surface.total(wi, wo, false, &mut dummy)
            }
        };
        let outcome = chi2_test(
            &label,
            // expected counts to 1e-5 of N (a relative 1e-5 of each expectation is far below
            // the multinomial noise); the harness default 1e-7 at depth 10 costs minutes on
            // the discontinuous lobe edges
            Chi2Grid { quad_tol: 1e-5, max_depth: 6, ..Chi2Grid::sphere(20, 40) },
            pdf,
            || {
                let s = if wi_out {
                    surface.sample(wi, &mut rng)
                } else {
                    surface.sample_sided(wi, false, &mut rng)
                };
                assert_eq!(s.weight, Vec3::ONE, "{label}: non-absorptive weight");
                assert!(s.wo.is_normalized(), "{label}: ωo = {} not unit", s.wo);
                same_side += usize::from(s.side == side(wi_out));
                Some(s.wo)
            },
            CHI2_N,
            alpha,
            1.0,
        );
        if surface.kind() == Kind::Dielectric {
            // probability of staying on ωi's side = ∫ p(ωi, ωo, same side) dωo (quadrature)
            let mut g = |wo: Vec3| surface.sided(wi, wo, wi_out, wi_out, &mut dummy);
            let p_same = integrate_sphere(&mut g, 32, 64, Domain::Sphere, 1e-5, 6);
            let mut stats = Stats::default();
            // the indicator's mean and SE, from the counts
            for k in 0..CHI2_N {
                stats.push(if k < same_side { 1.0 } else { 0.0 });
            }
            validation::assert_mean(
                &format!("{label}: reflection probability"),
                &stats,
                p_same,
                z,
                2e-3,
                1e-4,
            );
        }
        outcome.p_value
    });
    let worst = p_values.iter().cloned().fold(1.0, f64::min);
    println!(
        "exact phase sampling χ²: {} tests, N = {CHI2_N}, worst p = {worst:.3e} (α = {alpha:.2e})",
        cases.len()
    );
}

/// Cells of `stochastic_chi2` along cos θ and φ (about +z, over the whole sphere).
const DIFFUSE_NZ: usize = 10;
const DIFFUSE_NPHI: usize = 20;
/// Uniform directions (one stochastic eval each) per cell for the expected probabilities.
const PER_CELL: usize = 10_000;
const DIFFUSE_CHI2_N: usize = 50_000;
/// The largest noise ratio N·Var(m̂)/m of a cell at which the test keeps its power.
const MAX_NOISE_RATIO: f64 = 0.25;

#[test]
fn sampling_chi2_diffuse_stochastic_density_4_3_3() {
    let surfaces = surfaces(&[Kind::Diffuse]);
    let cases: Vec<(usize, f64)> =
        (0..surfaces.len()).flat_map(|s| SAMPLE_THETAS.iter().map(move |&t| (s, t))).collect();
    let alpha = validation::sidak(0.01, cases.len());
    let out = par_map(&cases, |i, &(s, theta)| {
        let surface = &surfaces[s];
        let wi = wi_at(theta);
        let label = format!("{}: sample_phase, θi = {theta}", surface.name());
        let mut rng = validation::rng(4000 + i as u64);
        let mut expectation_rng = validation::rng(5000 + i as u64);
        let grid = StochasticGrid {
            z_lo: -1.0,
            nz: DIFFUSE_NZ,
            nphi: DIFFUSE_NPHI,
            cell_start: PER_CELL,
            cell_max: PER_CELL,
            noise_ratio: 0.0,
            max_noise_ratio: MAX_NOISE_RATIO,
        };
        stochastic_chi2_with(
            &label,
            grid,
            &mut |wo| surface.eval(wi, wo, &mut expectation_rng),
            &mut || {
                let s = surface.sample(wi, &mut rng);
                assert_eq!(s.weight, Vec3::ONE, "{label}: white diffuse weight");
                assert_eq!(s.side, Side::Outside);
                Some(s.wo)
            },
            DIFFUSE_CHI2_N,
            alpha,
        )
    });
    let worst = out.iter().map(|o| o.p_value).fold(1.0, f64::min);
    let worst_ratio = out.iter().map(|o| o.max_ratio).fold(0.0, f64::max);
    println!(
        "diffuse phase sampling χ²: {} tests, N = {DIFFUSE_CHI2_N}, {PER_CELL} evals per cell, worst p = {worst:.3e} \
         (α = {alpha:.2e}), largest N·Var(m̂)/m = {worst_ratio:.3}",
        cases.len()
    );
}

// ---------------------------------------------------------------------------------------------
// the combined connection evaluation
// ---------------------------------------------------------------------------------------------

/// `Material::connection` (one half vector and one D for a conductor) returns exactly the
/// vertex term and both phase-function densities of the separate calls, for random direction
/// pairs on the whole sphere and every side combination.
#[test]
fn connection_equals_vertex_and_both_densities() {
    fn check<S: MicrosurfaceSlope, M: Material>(
        label: &str,
        slope: S,
        material: M,
        rng: &mut TestRng,
    ) -> usize {
        let mut checked = 0;
        for _ in 0..20_000 {
            let (wi, wo) = (uniform_sphere(rng), uniform_sphere(rng));
            for (a, b) in [(true, true), (true, false), (false, true), (false, false)] {
                let (v, forward, reverse) =
                    material.connection(&slope, &Interaction::new(wi, wo, side(a), side(b)), rng);
                let expected = (
                    material.vertex(&slope, &Interaction::new(wi, wo, side(a), side(b)), rng),
                    material.pdf_phase(&slope, &Interaction::new(wi, wo, side(a), side(b))),
                    material.pdf_phase(&slope, &Interaction::new(wo, wi, side(b), side(a))),
                );
                assert_eq!(
                    (v, forward, reverse),
                    expected,
                    "{label}: ωi = {wi}, ωo = {wo}, sides ({a}, {b})"
                );
                checked += usize::from(forward > 0.0);
            }
        }
        assert!(checked > 1000, "{label}: only {checked} non-zero densities checked");
        checked
    }
    let mut rng = validation::rng(0xc0ec);
    let gold = ComplexIor::new(Vec3::new(0.18, 0.42, 1.37), Vec3::new(3.42, 2.35, 1.77)).unwrap();
    for (ax, ay) in [(0.05, 0.05), (0.5, 0.5), (1.0, 0.2)] {
        check("conductor GGX", Ggx::new(ax, ay).unwrap(), Conductor::perfect(), &mut rng);
        check("gold GGX", Ggx::new(ax, ay).unwrap(), Conductor::new(gold), &mut rng);
        check("gold Beckmann", Beckmann::new(ax, ay).unwrap(), Conductor::new(gold), &mut rng);
    }
}

/// The side of the interface for the test tables' `outside` flags.
fn side(outside: bool) -> Side {
    if outside { Side::Outside } else { Side::Inside }
}
