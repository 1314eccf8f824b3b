//! Integration tests of the position-free multiple-bounce BSDFs (Wang et al. 2022):
//! energy conservation (white furnace), agreement of the PT and BDPT estimators, the
//! single-bounce paths, per-order decomposition, reciprocity, the comparison with the
//! Heitz et al. 2016 random walk, the BDPT sub-path cap and degenerate inputs.
//!
//! Statistics: every Monte Carlo assertion is |difference| ≤ z·SE (+ a stated deterministic
//! tolerance), with z = `family_z(0.01, m)` for the m assertions of its test function, and
//! asserts an upper bound on SE so that it can fail. Albedos ∫ f·|cos θo| dωo are estimated by
//! importance sampling ωo from a mixture whose density is known exactly:
//! 0.8 × the single-bounce phase function (`Material::sample_phase`, density
//! `Material::pdf_phase` summed over both mechanisms) + 0.2 × a cosine lobe on ωo's side (split
//! between both sides for a dielectric). The phase component follows the sharp single-bounce
//! lobe at low roughness; the cosine component covers the multiply scattered light.
//! Accumulation is in f64; every generator is a fixed-seed PCG.
use validation::par_map;

use glam::Vec3;
use microsurface::research::{
    Estimator, Material, Microsurface, PositionFree, ScatteringOrder, Shadowing, UniformHeight, WalkSample,
    sample_cosine_hemisphere,
};
use microsurface::research::{Interaction, Side};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, ComplexIor, Conductor, Dielectric, Diffuse, Ggx};
use rand::RngExt;
use std::f64::consts::{PI, TAU};
use validation::{Stats, TestRng, family_z, uniform64};

const ETA: f32 = 1.5;
/// Azimuth of the incident directions (so that anisotropic roughness matters).
const PHI_I: f64 = 0.7;
/// Share of the phase-function component of the importance-sampling mixture.
const PHASE_SHARE: f64 = 0.8;

const ALL: ScatteringOrder = ScatteringOrder::All;

fn only(n: u32) -> ScatteringOrder {
    ScatteringOrder::only(n).unwrap()
}

fn up_to(n: u32) -> ScatteringOrder {
    ScatteringOrder::up_to(n).unwrap()
}

/// A position-free BSDF, type-erased over slope and material.
trait Model: Sync {
    fn label(&self) -> String;
    fn eval(&self, wi: Vec3, wo: Vec3, est: Estimator, order: ScatteringOrder, rng: &mut TestRng) -> Vec3;
    fn single(&self, wi: Vec3, wo: Vec3, rng: &mut TestRng) -> Vec3;
    fn sample(&self, wi: Vec3, rng: &mut TestRng) -> Option<WalkSample>;
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f32;
    /// ωo drawn from the importance-sampling mixture.
    fn mix_sample(&self, wi: Vec3, rng: &mut TestRng) -> Vec3;
    /// The exact density of `mix_sample`.
    fn mix_pdf(&self, wi: Vec3, wo: Vec3) -> f64;
}

struct Pf<S, M>(PositionFree<S, M>, &'static str);

impl<S: MicrosurfaceSlope, M: Material> Model for Pf<S, M> {
    fn label(&self) -> String {
        let s = self.0.slope();
        format!("{} α=({}, {}) {:?}", self.1, s.alpha_x(), s.alpha_y(), self.0.shadowing())
    }
    fn eval(&self, wi: Vec3, wo: Vec3, est: Estimator, order: ScatteringOrder, rng: &mut TestRng) -> Vec3 {
        self.0.eval(wi, wo, est, order, rng)
    }
    fn single(&self, wi: Vec3, wo: Vec3, rng: &mut TestRng) -> Vec3 {
        self.0.eval_single_scattering(wi, wo, rng)
    }
    fn sample(&self, wi: Vec3, rng: &mut TestRng) -> Option<WalkSample> {
        self.0.sample(wi, rng)
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        self.0.pdf(wi, wo)
    }
    fn mix_sample(&self, wi: Vec3, rng: &mut TestRng) -> Vec3 {
        if uniform64(rng) < PHASE_SHARE {
            self.0.material().sample_phase(self.0.slope(), wi, side(wi.z > 0.0), rng).wo
        } else {
            let w = sample_cosine_hemisphere(rng.random::<f32>(), rng.random::<f32>());
            if M::TRANSMITS && uniform64(rng) < 0.5 { -w } else { w }
        }
    }
    fn mix_pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        let (m, s, out) = (self.0.material(), self.0.slope(), wi.z > 0.0);
        let mut phase = f64::from(m.pdf_phase(s, &Interaction::new(wi, wo, side(out), side(out))));
        let cosine = if M::TRANSMITS {
            phase += f64::from(m.pdf_phase(s, &Interaction::new(wi, wo, side(out), side(!out))));
            f64::from(wo.z).abs() / (2.0 * PI)
        } else {
            f64::from(wo.z).max(0.0) / PI
        };
        PHASE_SHARE * phase + (1.0 - PHASE_SHARE) * cosine
    }
}

fn boxed<S: MicrosurfaceSlope + 'static, M: Material + 'static>(
    slope: S,
    material: M,
    shadowing: Shadowing,
    name: &'static str,
) -> Box<dyn Model> {
    Box::new(Pf(PositionFree::new(slope, material, shadowing), name))
}

fn conductor(slope: impl MicrosurfaceSlope + 'static, sh: Shadowing) -> Box<dyn Model> {
    boxed(slope, Conductor::perfect(), sh, "conductor F=1")
}

fn dielectric(slope: impl MicrosurfaceSlope + 'static, sh: Shadowing) -> Box<dyn Model> {
    boxed(slope, Dielectric::new(ETA).unwrap(), sh, "dielectric η=1.5")
}

/// Gold-like complex IOR (absorptive, different per channel).
fn gold() -> Conductor {
    Conductor::new(ComplexIor::new(Vec3::new(0.143, 0.374, 1.442), Vec3::new(3.983, 2.385, 1.603)).unwrap())
}

fn ggx(ax: f32, ay: f32) -> Ggx {
    Ggx::new(ax, ay).unwrap()
}

fn beckmann(ax: f32, ay: f32) -> Beckmann {
    Beckmann::new(ax, ay).unwrap()
}

/// Incident direction at polar angle θ (azimuth `PHI_I`), from below if `inside`.
fn incident(theta: f64, inside: bool) -> Vec3 {
    let w = validation::dir(theta, PHI_I);
    if inside { -w } else { w }
}

/// Cells of the guiding histogram along cos θ and φ (whole sphere, equal area).
const GUIDE_NZ: usize = 32;
const GUIDE_NPHI: usize = 64;
/// Walks of the pilot run that builds the guiding histogram.
const GUIDE_PILOT: usize = 100_000;

/// The importance-sampling density of ωo for the albedo estimates: a mixture of the
/// single-bounce phase function and a cosine lobe (`Model::mix_sample`, weight 1/2) and a
/// piecewise-constant density on a 32 × 64 equal-area grid of the sphere (weight 1/2), built
/// from an independent pilot run of `PositionFree::sample` (whose exit directions follow the
/// multiply scattered lobe), plus one prior count per cell. The pilot is independent of the
/// estimate, so the estimator stays unbiased; the density is exact and evaluable.
struct Guide {
    cdf: Vec<f64>,
    density: Vec<f64>,
}

fn guide_cell(w: Vec3) -> usize {
    let w = w.as_dvec3().normalize();
    let iz = (((w.z.clamp(-1.0, 1.0) + 1.0) / 2.0 * GUIDE_NZ as f64) as usize).min(GUIDE_NZ - 1);
    let ip = ((w.y.atan2(w.x).rem_euclid(TAU) / TAU * GUIDE_NPHI as f64) as usize).min(GUIDE_NPHI - 1);
    iz * GUIDE_NPHI + ip
}

impl Guide {
    fn new(m: &dyn Model, wi: Vec3, rng: &mut TestRng) -> Self {
        let cells = GUIDE_NZ * GUIDE_NPHI;
        let mut mass = vec![1.0 / cells as f64; cells];
        let mut total = 1.0;
        for _ in 0..GUIDE_PILOT {
            if let Some(s) = m.sample(wi, rng) {
                let w = f64::from(s.weight.max_element());
                if w > 0.0 && s.wo.is_finite() {
                    mass[guide_cell(s.wo)] += w;
                    total += w;
                }
            }
        }
        let area = 4.0 * PI / cells as f64;
        let density = mass.iter().map(|m| m / total / area).collect();
        let mut acc = 0.0;
        let cdf = mass
            .iter()
            .map(|m| {
                acc += m / total;
                acc
            })
            .collect();
        Self { cdf, density }
    }

    fn sample(&self, m: &dyn Model, wi: Vec3, rng: &mut TestRng) -> Vec3 {
        if uniform64(rng) < 0.5 {
            return m.mix_sample(wi, rng);
        }
        let u = uniform64(rng) * self.cdf[self.cdf.len() - 1];
        let c = self.cdf.partition_point(|&x| x <= u).min(self.cdf.len() - 1);
        let (iz, ip) = (c / GUIDE_NPHI, c % GUIDE_NPHI);
        let z = -1.0 + 2.0 * (iz as f64 + uniform64(rng)) / GUIDE_NZ as f64;
        let phi = TAU * (ip as f64 + uniform64(rng)) / GUIDE_NPHI as f64;
        let s = (1.0 - z * z).max(0.0).sqrt();
        glam::DVec3::new(s * phi.cos(), s * phi.sin(), z).as_vec3()
    }

    fn pdf(&self, m: &dyn Model, wi: Vec3, wo: Vec3) -> f64 {
        0.5 * m.mix_pdf(wi, wo) + 0.5 * self.density[guide_cell(wo)]
    }
}

/// Importance-sampled estimates of ∫ eval(ωi, ωo) dωo (channel `ch`) for each order in
/// `orders` (independent evaluations on shared ωo), `n` samples.
fn albedos(
    m: &dyn Model,
    wi: Vec3,
    est: Estimator,
    orders: &[ScatteringOrder],
    ch: usize,
    n: usize,
    rng: &mut TestRng,
) -> Vec<Stats> {
    let guide = Guide::new(m, wi, rng);
    let mut stats = vec![Stats::default(); orders.len()];
    for _ in 0..n {
        let wo = guide.sample(m, wi, rng);
        let q = guide.pdf(m, wi, wo);
        for (s, &order) in stats.iter_mut().zip(orders) {
            let v = if q > 0.0 { f64::from(m.eval(wi, wo, est, order, rng)[ch]) / q } else { 0.0 };
            s.push(v);
        }
    }
    stats
}

/// Importance-sampled estimate of ∫ eval(ωi, ωo) dωo (channel `ch`), `n` samples.
fn albedo(
    m: &dyn Model,
    wi: Vec3,
    est: Estimator,
    order: ScatteringOrder,
    ch: usize,
    n: usize,
    rng: &mut TestRng,
) -> Stats {
    albedos(m, wi, est, &[order], ch, n, rng)[0]
}

/// Mean of `n` evaluations at one (ωi, ωo), channel x.
fn point(
    m: &dyn Model,
    wi: Vec3,
    wo: Vec3,
    est: Estimator,
    order: ScatteringOrder,
    n: usize,
    rng: &mut TestRng,
) -> Stats {
    let mut stats = Stats::default();
    for _ in 0..n {
        stats.push(f64::from(m.eval(wi, wo, est, order, rng).x));
    }
    stats
}

// ---------------------------------------------------------------------------------------------
// White furnace
// ---------------------------------------------------------------------------------------------

/// Non-absorptive microsurfaces integrate to 1: ∫ f·|cos θo| dωo over the sphere = 1 for the
/// perfect conductor and for the dielectric η = 1.5 (reflection + transmission, lit from
/// outside and from inside), for both shadowing models and both estimators.
///
/// Matrix: θi ∈ {0, 0.8, 1.5} × α ∈ {0.1, 0.5, 1, (1, 0.1)} × {GGX, Beckmann} ×
/// {conductor, dielectric outside, dielectric inside} (72 cells), each run with one of the four
/// (shadowing, estimator) pairs drawn by a fixed-seed generator (every factor level meets both
/// shadowing models and both estimators).
/// Tolerance: z·SE + 1e-4 (the energy of paths beyond the BDPT cap, bounded in
/// `bdpt_subpath_cap_loses_negligible_energy`); SE ≤ 3e-3 asserted for the conductor, SE ≤
/// 6e-2 for the dielectric (whose worst runs have σ̂ ≈ 5–13 per sample within the budget; a
/// known gap, see the report).
#[test]
fn white_furnace() {
    const N_PT: usize = 60_000;
    const N_PT_CONDUCTOR: usize = 250_000;
    const N_BDPT: usize = 24_000;
    const N_BDPT_CONDUCTOR: usize = 56_000;
    let thetas = [0.0, 0.8, 1.5];
    let alphas = [(0.1, 0.1), (0.5, 0.5), (1.0, 1.0), (1.0, 0.1)];
    let mut coin = validation::rng(0xf0_4ace);
    let mut runs = Vec::new();
    for &theta in &thetas {
        for &(ax, ay) in &alphas {
            for ndf in 0..2 {
                for mat in 0..3 {
                    let pair = coin.random_range(0..4u32);
                    let sh = if pair & 1 == 0 { Shadowing::Uncorrelated } else { Shadowing::Correlated };
                    let est = if pair & 2 == 0 { Estimator::Pt } else { Estimator::Bdpt };
                    runs.push((theta, ax, ay, ndf, mat, sh, est));
                }
            }
        }
    }
    let z = family_z(0.01, runs.len());
    let results = par_map(&runs, |i, &(theta, ax, ay, ndf, mat, sh, est)| {
        let model = match (ndf, mat) {
            (0, 0) => conductor(ggx(ax, ay), sh),
            (0, _) => dielectric(ggx(ax, ay), sh),
            (_, 0) => conductor(beckmann(ax, ay), sh),
            (_, _) => dielectric(beckmann(ax, ay), sh),
        };
        let wi = incident(theta, mat == 2);
        let mut rng = validation::rng(0xf0_0000 + i as u64);
        let n = match (est, mat) {
            (Estimator::Pt, 0) => N_PT_CONDUCTOR,
            (Estimator::Pt, _) => N_PT,
            (Estimator::Bdpt, 0) => N_BDPT_CONDUCTOR,
            (Estimator::Bdpt, _) => N_BDPT,
        };
        let stats = albedo(model.as_ref(), wi, est, ALL, 0, n, &mut rng);
        let label = format!(
            "furnace {} {} θi={theta}{} {est:?}",
            model.label(),
            if ndf == 0 { "GGX" } else { "Beckmann" },
            if mat == 2 { " (inside)" } else { "" }
        );
        (label, stats)
    });
    let mut worst = (0.0f64, String::new());
    let mut max_se = 0.0f64;
    for (label, stats) in &results {
        let dev = (stats.mean() - 1.0).abs() / stats.se();
        if dev > worst.0 {
            worst = (dev, format!("{label}: {:.5} ± {:.5}", stats.mean(), stats.se()));
        }
        max_se = max_se.max(stats.se());
    }
    println!(
        "furnace: {} runs, z = {z:.2}, largest SE {max_se:.2e}, worst |m−1|/SE = {:.2} ({})",
        results.len(),
        worst.0,
        worst.1
    );
    for (label, stats) in &results {
        println!("  {label}: {:.5} ± {:.5}", stats.mean(), stats.se());
    }
    for (i, (label, stats)) in results.iter().enumerate() {
        // the dielectric estimators are heavy-tailed (PT NEE into sharp lobes, chains of
        // from-below incidences): the budget only reaches SE ≲ 2.5e-2 for their worst runs
        let max_se = if runs[i].4 == 0 { 3e-3 } else { 6e-2 };
        validation::assert_mean(label, stats, 1.0, z, max_se, 1e-4);
    }
}

/// The white furnace over correlated slopes (`Elliptical` GGX and Beckmann, ρ ≠ 0, φα ≠ 0):
/// the perfect conductor integrates to 1 for PT and BDPT, both shadowing models, at two views.
/// Tolerance z·SE + 1e-4 (the BDPT cap, as in `white_furnace`); SE ≤ 3e-3 asserted.
#[test]
fn white_furnace_elliptical() {
    use microsurface::Elliptical;
    const N_PT: usize = 100_000;
    const N_BDPT: usize = 40_000;
    let mut runs = Vec::new();
    for ndf in 0..2 {
        for (theta, phi) in [(0.6, 1.1), (1.3, -2.4)] {
            for sh in [Shadowing::Uncorrelated, Shadowing::Correlated] {
                for est in [Estimator::Pt, Estimator::Bdpt] {
                    runs.push((ndf, theta, phi, sh, est));
                }
            }
        }
    }
    let z = family_z(0.01, runs.len());
    let results = par_map(&runs, |i, &(ndf, theta, phi, sh, est)| {
        let model = if ndf == 0 {
            conductor(Elliptical::<Ggx>::from_bivariate(0.7, 0.3, -0.6).unwrap(), sh)
        } else {
            conductor(Elliptical::<Beckmann>::from_ellipse(0.8, 0.2, 0.9).unwrap(), sh)
        };
        let wi = validation::dir(theta, phi);
        let mut rng = validation::rng(0xe1_0000 + i as u64);
        let n = if est == Estimator::Pt { N_PT } else { N_BDPT };
        let stats = albedo(model.as_ref(), wi, est, ALL, 0, n, &mut rng);
        let label = format!(
            "furnace elliptical {} θi={theta} φi={phi} {sh:?} {est:?}",
            if ndf == 0 { "GGX" } else { "Beckmann" }
        );
        (label, stats)
    });
    for (label, stats) in &results {
        validation::assert_mean(label, stats, 1.0, z, 3e-3, 1e-4);
    }
}

/// Draws per order (`orders`, independent evaluations on shared importance-sampled ωo): the
/// raw per-sample values eval/q, for derived quantities (differences of orders).
fn albedo_samples(
    m: &dyn Model,
    wi: Vec3,
    est: Estimator,
    orders: &[ScatteringOrder],
    n: usize,
    rng: &mut TestRng,
) -> Vec<Vec<f64>> {
    let guide = Guide::new(m, wi, rng);
    let mut out = vec![Vec::with_capacity(n); orders.len()];
    for _ in 0..n {
        let wo = guide.sample(m, wi, rng);
        let q = guide.pdf(m, wi, wo);
        for (o, &order) in out.iter_mut().zip(orders) {
            o.push(if q > 0.0 { f64::from(m.eval(wi, wo, est, order, rng).x) / q } else { 0.0 });
        }
    }
    out
}

fn stats_of(values: impl IntoIterator<Item = f64>) -> Stats {
    let mut s = Stats::default();
    for v in values {
        s.push(v);
    }
    s
}

/// Asserts a two-sample agreement with a relative bound on the combined SE.
fn assert_agree(label: &str, a: &Stats, b: &Stats, z: f64, rel_se: f64) {
    let scale = a.mean().abs().max(b.mean().abs()).max(1e-3);
    validation::assert_two_sample(label, a, b, z, rel_se * scale);
}

// ---------------------------------------------------------------------------------------------
// PT and BDPT
// ---------------------------------------------------------------------------------------------

/// The two estimators are unbiased estimates of the same BSDF: E[eval_pt] = E[eval_bdpt] for
/// a gold conductor, a dielectric (reflection, transmission, lit from inside) and white-ish
/// diffuse facets, both shadowing models, at two (ωi, ωo) each. Combined SE ≤ 2 % asserted.
#[test]
fn pt_and_bdpt_agree() {
    const N_PT: usize = 60_000;
    const N_BDPT: usize = 20_000;
    let mut cases: Vec<(Box<dyn Model>, Vec3, Vec3)> = Vec::new();
    for sh in [Shadowing::Uncorrelated, Shadowing::Correlated] {
        let cond = || boxed(ggx(0.5, 0.5), gold(), sh, "gold GGX");
        let diel = || boxed(ggx(1.0, 1.0), Dielectric::new(ETA).unwrap(), sh, "dielectric GGX");
        let diff = || {
            boxed(beckmann(0.8, 0.8), Diffuse::new(Vec3::new(0.8, 0.5, 0.2)).unwrap(), sh, "diffuse Beckmann")
        };
        cases.push((cond(), validation::dir(0.3, 0.0), validation::dir(0.9, 2.5)));
        cases.push((cond(), validation::dir(1.3, 0.0), validation::dir(1.2, 0.2)));
        cases.push((diel(), validation::dir(0.5, 0.0), validation::dir(0.8, 2.0)));
        cases.push((diel(), validation::dir(0.5, 0.0), validation::dir(2.4, 1.0)));
        cases.push((diel(), validation::dir(1.2, 0.0), validation::dir(2.9, 0.5)));
        cases.push((diel(), -validation::dir(0.6, 0.0), validation::dir(2.5, 2.0)));
        cases.push((diel(), -validation::dir(0.3, 0.0), validation::dir(0.7, 1.0)));
        cases.push((diff(), validation::dir(0.4, 0.0), validation::dir(1.0, 2.0)));
        cases.push((diff(), validation::dir(1.4, 0.0), validation::dir(0.2, 1.0)));
    }
    let z = family_z(0.01, cases.len());
    let results = par_map(&cases, |i, (m, wi, wo)| {
        let mut rng = validation::rng(0xb0_0000 + i as u64);
        let pt = point(m.as_ref(), *wi, *wo, Estimator::Pt, ALL, N_PT, &mut rng);
        let bdpt = point(m.as_ref(), *wi, *wo, Estimator::Bdpt, ALL, N_BDPT, &mut rng);
        (format!("PT vs BDPT {} ωi={wi} ωo={wo}", m.label()), pt, bdpt)
    });
    for (label, pt, bdpt) in &results {
        println!(
            "{label}: PT {:.5} ± {:.5}, BDPT {:.5} ± {:.5}, diff/SE {:.2}",
            pt.mean(),
            pt.se(),
            bdpt.mean(),
            bdpt.se(),
            (pt.mean() - bdpt.mean()) / (pt.se().powi(2) + bdpt.se().powi(2)).sqrt()
        );
    }
    for (label, pt, bdpt) in &results {
        assert_agree(label, pt, bdpt, z, 0.03);
    }
}

// ---------------------------------------------------------------------------------------------
// Single bounce
// ---------------------------------------------------------------------------------------------

/// Paths of one vertex: eval_pt and eval_bdpt with only(1) return exactly (bit for bit)
/// eval_single_scattering for conductors and dielectrics, and the correlated single
/// scattering equals the Heitz walk's single scattering (G2 = 1/(1 + Λi + Λo) for reflection,
/// B(1 + Λi, 1 + Λ(−ωo)) for transmission) within 1e-4 relative (f32 vs f64 shadowing
/// factors). The uncorrelated one equals it times G1(ωi)G1(ωo)/G2 for reflection.
#[test]
fn single_bounce_paths() {
    let mut rng = validation::rng(0x51);
    let mut worst = 0.0f64;
    let mut checked = 0;
    for (ax, ay) in [(0.2, 0.2), (0.7, 0.7), (1.0, 0.3)] {
        let heitz_c = Microsurface::new(UniformHeight, ggx(ax, ay), gold());
        let heitz_d = Microsurface::new(UniformHeight, beckmann(ax, ay), Dielectric::new(ETA).unwrap());
        for sh in [Shadowing::Uncorrelated, Shadowing::Correlated] {
            let c = PositionFree::new(ggx(ax, ay), gold(), sh);
            let d = PositionFree::new(beckmann(ax, ay), Dielectric::new(ETA).unwrap(), sh);
            for _ in 0..2000 {
                let wi = sphere(&mut rng);
                let wo = sphere(&mut rng);
                for (single, pt, bdpt, heitz, label) in [
                    (
                        c.eval_single_scattering(wi, wo, &mut rng),
                        c.eval_pt(wi, wo, only(1), &mut rng),
                        c.eval_bdpt(wi, wo, only(1), &mut rng),
                        heitz_c.eval_single_scattering(wi, wo, &mut rng),
                        "conductor",
                    ),
                    (
                        d.eval_single_scattering(wi, wo, &mut rng),
                        d.eval_pt(wi, wo, only(1), &mut rng),
                        d.eval_bdpt(wi, wo, only(1), &mut rng),
                        heitz_d.eval_single_scattering(wi, wo, &mut rng),
                        "dielectric",
                    ),
                ] {
                    assert_eq!(pt, single, "{label} {sh:?} α=({ax},{ay}) ωi={wi} ωo={wo}: PT only(1)");
                    assert_eq!(bdpt, single, "{label} {sh:?} α=({ax},{ay}) ωi={wi} ωo={wo}: BDPT only(1)");
                    assert!(single.is_finite() && single.min_element() >= 0.0);
                    if sh == Shadowing::Correlated {
                        let rel = ((single - heitz).abs() / heitz.max(Vec3::splat(1e-30))).max_element();
                        if single != heitz {
                            worst = worst.max(f64::from(rel));
                        }
                        assert!(
                            (single - heitz).abs().max_element() <= 1e-4 * heitz.max_element() + 1e-7,
                            "{label} α=({ax},{ay}) ωi={wi} ωo={wo}: correlated single {single} vs Heitz {heitz}"
                        );
                        checked += 1;
                    }
                }
            }
        }
    }
    println!("single scattering: {checked} correlated comparisons, worst relative difference {worst:.2e}");
}

/// A uniform direction on the sphere.
fn sphere(rng: &mut TestRng) -> Vec3 {
    let z = 2.0 * uniform64(rng) - 1.0;
    let phi = TAU * uniform64(rng);
    let s = (1.0 - z * z).max(0.0).sqrt();
    glam::DVec3::new(s * phi.cos(), s * phi.sin(), z).as_vec3()
}

// ---------------------------------------------------------------------------------------------
// Orders
// ---------------------------------------------------------------------------------------------

/// Σ_{n≤K} eval(only(n)) = eval(up_to(K)) (K = 6) and Σ_{n≤64} eval(only(n)) = eval(All)
/// (two-sample), for PT and BDPT, correlated conductor and dielectric (transmission) and
/// uncorrelated conductor. The energy of orders > 64 is measured with `sample` and printed:
/// it is far below the resolution.
#[test]
fn orders_sum_to_the_whole() {
    const N: usize = 12_000;
    let models = [
        (
            conductor(ggx(0.7, 0.7), Shadowing::Correlated),
            validation::dir(0.6, 0.0),
            validation::dir(1.0, 2.0),
        ),
        (
            conductor(beckmann(1.0, 1.0), Shadowing::Uncorrelated),
            validation::dir(1.2, 0.0),
            validation::dir(0.3, 1.0),
        ),
        (
            dielectric(ggx(0.7, 0.7), Shadowing::Correlated),
            validation::dir(0.6, 0.0),
            validation::dir(2.5, 2.0),
        ),
    ];
    let mut cases = Vec::new();
    for (mi, _) in models.iter().enumerate() {
        for est in [Estimator::Pt, Estimator::Bdpt] {
            for k in [6u32, 64] {
                cases.push((mi, est, k));
            }
        }
    }
    let z = family_z(0.01, cases.len());
    let results = par_map(&cases, |i, &(mi, est, k)| {
        let (m, wi, wo) = &models[mi];
        let mut rng = validation::rng(0x0d_0000 + i as u64);
        let mut sum = Stats::default();
        let mut whole = Stats::default();
        let target = if k == 64 { ALL } else { up_to(k) };
        for _ in 0..N {
            let s: f64 = (1..=k).map(|n| f64::from(m.eval(*wi, *wo, est, only(n), &mut rng).x)).sum();
            sum.push(s);
            whole.push(f64::from(m.eval(*wi, *wo, est, target, &mut rng).x));
        }
        let mut tail = 0u64;
        for _ in 0..200_000 {
            if m.sample(*wi, &mut rng).is_none_or(|s| s.bounces > k) {
                tail += 1;
            }
        }
        (format!("{} {est:?} Σ only(1..={k}) vs {target:?}", m.label()), sum, whole, tail as f64 / 200_000.0)
    });
    for (label, sum, whole, tail) in &results {
        println!(
            "{label}: {:.5} ± {:.5} vs {:.5} ± {:.5}; albedo of orders > K by sample(): {tail:.1e}",
            sum.mean(),
            sum.se(),
            whole.mean(),
            whole.se()
        );
    }
    for (label, sum, whole, _) in &results {
        assert_agree(label, sum, whole, z, 0.03);
    }
}

// ---------------------------------------------------------------------------------------------
// Reciprocity
// ---------------------------------------------------------------------------------------------

/// The uncorrelated model is reciprocal: f(ωi, ωo)/ηo² = f(ωo, ωi)/ηi² (η = 1 outside, 1.5
/// inside), f = eval/|cos θo|, two-sample with PT, for a gold conductor (anisotropic GGX) and
/// the dielectric (reflection outside, transmission, reflection inside). The correlated model
/// is not (Wang et al. 2022, §5): its relative asymmetry |f(ωi, ωo) − f(ωo, ωi)|/f is
/// measured and printed; only finiteness is asserted for it.
#[test]
fn reciprocity() {
    const N: usize = 60_000;
    let pairs = [
        (validation::dir(0.3, 0.2), validation::dir(1.1, 2.5)),
        (validation::dir(1.3, 0.0), validation::dir(0.6, 1.0)),
        (validation::dir(0.5, 0.4), validation::dir(2.7, 0.4 + std::f64::consts::PI)),
        (-validation::dir(0.4, 0.0), -validation::dir(1.0, 1.5)),
    ];
    let mut cases = Vec::new();
    for sh in [Shadowing::Uncorrelated, Shadowing::Correlated] {
        for (pi, &(wi, wo)) in pairs.iter().enumerate() {
            if pi < 2 {
                cases.push((boxed(ggx(0.6, 0.3), gold(), sh, "gold GGX"), wi, wo));
            }
            cases.push((
                boxed(beckmann(0.7, 0.7), Dielectric::new(ETA).unwrap(), sh, "dielectric Beckmann"),
                wi,
                wo,
            ));
        }
    }
    let n_unc = cases.iter().filter(|c| c.0.label().contains("Uncorrelated")).count();
    let z = family_z(0.01, n_unc);
    let results = par_map(&cases, |i, (m, wi, wo)| {
        let mut rng = validation::rng(0x4ec_0000 + i as u64);
        let eta_sq = |w: Vec3| if w.z < 0.0 { f64::from(ETA * ETA) } else { 1.0 };
        let mut fwd = Stats::default();
        let mut bwd = Stats::default();
        for _ in 0..N {
            let a = f64::from(m.eval(*wi, *wo, Estimator::Pt, ALL, &mut rng).x);
            fwd.push(a / f64::from(wo.z.abs()) / eta_sq(*wo));
            let b = f64::from(m.eval(*wo, *wi, Estimator::Pt, ALL, &mut rng).x);
            bwd.push(b / f64::from(wi.z.abs()) / eta_sq(*wi));
        }
        (format!("reciprocity {} ωi={wi} ωo={wo}", m.label()), fwd, bwd)
    });
    for (label, fwd, bwd) in &results {
        let asym = (fwd.mean() - bwd.mean()).abs() / (0.5 * (fwd.mean() + bwd.mean()));
        let se = (fwd.se().powi(2) + bwd.se().powi(2)).sqrt() / (0.5 * (fwd.mean() + bwd.mean()));
        println!(
            "{label}: f/ηo² = {:.5} ± {:.5}, reversed {:.5} ± {:.5}, asymmetry {asym:.4} ± {se:.4}",
            fwd.mean(),
            fwd.se(),
            bwd.mean(),
            bwd.se()
        );
        assert!(asym.is_finite() && fwd.mean() > 0.0 && bwd.mean() > 0.0, "{label}");
    }
    for (label, fwd, bwd) in &results {
        if label.contains("Uncorrelated") {
            assert_agree(label, fwd, bwd, z, 0.03);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Against the Heitz et al. 2016 random walk
// ---------------------------------------------------------------------------------------------

/// The correlated and uncorrelated position-free models (PT, importance sampled) next to the
/// Heitz 2016 random walk (bounce histogram of `Microsurface::sample`, non-absorptive so every
/// walk has weight 1) on identical configurations: perfect conductor and dielectric η = 1.5,
/// GGX α = 1, θi ∈ {0, 1, 1.5}, per order (1, 2, 3, 4+, printed) and in total. Totals of the
/// correlated model and the walk agree within z·SE (both conserve energy). The position-free
/// `sample` bounce histogram must match the PT per-order albedos of the same model exactly in
/// expectation (two-sample, both models). The per-order energies of the models differ (the
/// paper's Fig. 6 calls the lobes "close for all bounces"; they are not): the conductor's are
/// asserted against exact quadrature in `per_order_albedos_against_quadrature`.
#[test]
fn against_the_heitz_random_walk() {
    heitz_comparison();
}

fn heitz_comparison() {
    const N_PT: usize = 60_000;
    const N_WALK: usize = 100_000;
    let orders = [only(1), only(2), only(3), ALL];
    let mut cases = Vec::new();
    for mat in 0..2 {
        for theta in [0.0, 1.0, 1.5] {
            cases.push((mat, theta));
        }
    }
    // per case: total (corr vs walk) + 4 orders × 2 models (PT vs own sample)
    let z = family_z(0.01, cases.len() * (1 + 8));
    let results = par_map(&cases, |i, &(mat, theta)| {
        let mut rng = validation::rng(0x4e17_0000 + i as u64);
        let wi = incident(theta, false);
        let slope = ggx(1.0, 1.0);
        // walk: fraction of exits per order
        let walk_hist = |sample: &mut dyn FnMut(&mut TestRng) -> Option<u32>, rng: &mut TestRng| {
            let mut st = vec![Stats::default(); 5];
            for _ in 0..N_WALK {
                let b = sample(rng);
                for (k, s) in st.iter_mut().enumerate() {
                    let hit = match (k, b) {
                        (_, None) => false,
                        (4, Some(_)) => true,
                        (3, Some(b)) => b >= 4,
                        (k, Some(b)) => b as usize == k + 1,
                    };
                    s.push(if hit { 1.0 } else { 0.0 });
                }
            }
            st
        };
        let heitz = if mat == 0 {
            let w = Microsurface::new(UniformHeight, slope, Conductor::perfect());
            walk_hist(&mut |r| w.sample(wi, r).map(|s| s.bounces), &mut rng)
        } else {
            let w = Microsurface::new(UniformHeight, slope, Dielectric::new(ETA).unwrap());
            walk_hist(&mut |r| w.sample(wi, r).map(|s| s.bounces), &mut rng)
        };
        let mut per_model = Vec::new();
        for sh in [Shadowing::Correlated, Shadowing::Uncorrelated] {
            let m = if mat == 0 { conductor(slope, sh) } else { dielectric(slope, sh) };
            let v = albedo_samples(m.as_ref(), wi, Estimator::Pt, &orders, N_PT, &mut rng);
            let mut st: Vec<Stats> = (0..3).map(|k| stats_of(v[k].iter().copied())).collect();
            st.push(stats_of((0..N_PT).map(|j| v[3][j] - v[0][j] - v[1][j] - v[2][j])));
            st.push(stats_of(v[3].iter().copied()));
            let own = walk_hist(&mut |r| m.sample(wi, r).map(|s| s.bounces), &mut rng);
            per_model.push((st, own));
        }
        (
            format!("{} GGX α=1 θi={theta}", if mat == 0 { "conductor F=1" } else { "dielectric η=1.5" }),
            heitz,
            per_model,
        )
    });
    for (label, heitz, pm) in &results {
        println!("{label}");
        println!(
            "  order | heitz walk        | wang correlated (PT) | wang uncorrelated (PT) | corr sample() | unc sample()"
        );
        for (k, name) in ["1", "2", "3", "4+", "total"].iter().enumerate() {
            println!(
                "  {name:>5} | {:.4} ± {:.4} | {:.4} ± {:.4}      | {:.4} ± {:.4}        | {:.4}        | {:.4}",
                heitz[k].mean(),
                heitz[k].se(),
                pm[0].0[k].mean(),
                pm[0].0[k].se(),
                pm[1].0[k].mean(),
                pm[1].0[k].se(),
                pm[0].1[k].mean(),
                pm[1].1[k].mean()
            );
        }
    }
    for (label, heitz, pm) in &results {
        for (k, (a, b)) in pm[0].0.iter().zip(heitz).enumerate() {
            let se = (a.se().powi(2) + b.se().powi(2)).sqrt();
            assert!(se <= 0.01, "{label} order {k}: SE {se:.2e} too large");
            if k < 4 {
                continue;
            }
            let tol = 0.0;
            let diff = (a.mean() - b.mean()).abs();
            assert!(
                diff <= tol + z * se,
                "{label} order index {k}: correlated {:.5} ± {:.5} (N = {}, σ̂ = {:.3}) vs Heitz {:.5} ± {:.5}: \
                 |diff| {diff:.4} > {tol} + z·SE = {tol} + {z:.2} × {se:.2e}",
                a.mean(),
                a.se(),
                a.n,
                a.std(),
                b.mean(),
                b.se()
            );
        }
        for (st, own) in pm {
            for k in 0..4 {
                assert_two_sample(
                    &format!("{label} order index {k}: PT vs own sample()"),
                    &st[k],
                    &own[k],
                    z,
                    0.01,
                );
            }
        }
    }
}

use validation::assert_two_sample;

// ---------------------------------------------------------------------------------------------
// Per order against deterministic quadrature (conductor F = 1, GGX α = 1)
// ---------------------------------------------------------------------------------------------

use validation::per_order as per_order_reference;

/// Per-order albedos (orders 1, 2, 3) of a perfect conductor with GGX α = 1 at θi ∈ {0, 1,
/// 1.5}, against the deterministic quadrature of `per_order_reference` (independent of the
/// crate's code): the Heitz walk's bounce histogram (`Microsurface::sample`, uniform heights),
/// and for both position-free shadowing models the PT and BDPT estimates (`eval` with
/// `ScatteringOrder::only`, ωo drawn from ½ cosine + ½ uniform on the upper hemisphere) and
/// the bounce histogram of
/// `PositionFree::sample`. Each estimate within z·SE of its reference (Šidák over all
/// 3 θi × 3 orders × 7 estimates), SE ≤ 2.5e-3 asserted. The quadrature is run with 6 and 10
/// Gauss–Legendre points per panel and must agree to 1e-7 (measured: ≤ 5e-9; far below the
/// SEs). Also asserted: the correlated model equals the walk at order 1 (to 1e-9) and departs
/// from it by more than 0.01 at orders 2 and 3 for θi ∈ {0, 1} (the difference the README
/// states; at θi = 1.5 it is 0.002).
#[test]
fn per_order_albedos_against_quadrature() {
    use per_order_reference::{Model as Ref, albedo as reference, gauss_legendre};
    const N_WALK: usize = 200_000;
    const N_PT: usize = 40_000;
    const N_BDPT: usize = 12_000;
    let thetas = [0.0f64, 1.0, 1.5];
    let (coarse, fine) = (gauss_legendre(6), gauss_legendre(10));
    let mut expected = Vec::new();
    for &theta in &thetas {
        let mut per_model = Vec::new();
        for model in [Ref::Walk, Ref::Correlated, Ref::Uncorrelated] {
            let mut per_order = Vec::new();
            for order in 1..=3 {
                let a = reference(model, theta.cos(), order, &coarse);
                let b = reference(model, theta.cos(), order, &fine);
                assert!((a - b).abs() <= 1e-7, "quadrature {model:?} θi={theta} order {order}: {a} vs {b}");
                per_order.push(b);
            }
            per_model.push(per_order);
        }
        expected.push(per_model);
    }
    for (t, &theta) in thetas.iter().enumerate() {
        let [walk, corr, unc] = [&expected[t][0], &expected[t][1], &expected[t][2]];
        println!(
            "quadrature θi={theta}: walk {walk:.5?}, correlated {corr:.5?}, uncorrelated {unc:.5?}, \
             correlated − walk {:+.5?}",
            (0..3).map(|k| corr[k] - walk[k]).collect::<Vec<_>>()
        );
        assert!(
            (corr[0] - walk[0]).abs() <= 1e-9,
            "θi={theta}: order 1 correlated {} vs walk {}",
            corr[0],
            walk[0]
        );
        // the departure the README states (at θi = 1.5 order 1 dominates and they nearly agree)
        for k in (1..3).filter(|_| theta < 1.5) {
            assert!(
                (corr[k] - walk[k]).abs() > 0.01,
                "θi={theta} order {}: correlated {} vs walk {}",
                k + 1,
                corr[k],
                walk[k]
            );
        }
    }

    let slope = ggx(1.0, 1.0);
    let histogram = |sample: &mut dyn FnMut(&mut TestRng) -> Option<u32>, n: usize, rng: &mut TestRng| {
        let mut st = vec![Stats::default(); 3];
        for _ in 0..n {
            let b = sample(rng);
            for (k, s) in st.iter_mut().enumerate() {
                s.push(if b == Some(k as u32 + 1) { 1.0 } else { 0.0 });
            }
        }
        st
    };
    // (θ index, estimate): 0 walk, 1/2 PT, 3/4 BDPT, 5/6 own sample() (correlated, uncorrelated)
    let jobs: Vec<(usize, usize)> = (0..thetas.len()).flat_map(|t| (0..7).map(move |e| (t, e))).collect();
    let results = par_map(&jobs, |i, &(t, e)| {
        let mut rng = validation::rng(0x9e7_0000 + i as u64);
        let wi = incident(thetas[t], false);
        let sh = if e % 2 == 1 { Shadowing::Correlated } else { Shadowing::Uncorrelated };
        let pf = PositionFree::new(slope, Conductor::perfect(), sh);
        match e {
            0 => {
                let walk = Microsurface::new(UniformHeight, slope, Conductor::perfect());
                (
                    "Heitz walk sample()".to_string(),
                    histogram(&mut |r| walk.sample(wi, r).map(|s| s.bounces), N_WALK, &mut rng),
                )
            }
            1..=4 => {
                let (est, n) = if e <= 2 { (Estimator::Pt, N_PT) } else { (Estimator::Bdpt, N_BDPT) };
                let mut st = vec![Stats::default(); 3];
                for _ in 0..n {
                    // ½ cosine + ½ uniform on the upper hemisphere
                    let wo = if uniform64(&mut rng) < 0.5 {
                        sample_cosine_hemisphere(rng.random::<f32>(), rng.random::<f32>())
                    } else {
                        let (z, phi) = (uniform64(&mut rng), TAU * uniform64(&mut rng));
                        let s = (1.0 - z * z).sqrt();
                        glam::DVec3::new(s * phi.cos(), s * phi.sin(), z).as_vec3()
                    };
                    let pdf = 0.5 * f64::from(wo.z) / PI + 0.5 / TAU;
                    for (k, s) in st.iter_mut().enumerate() {
                        let v = pf.eval(wi, wo, est, only(k as u32 + 1), &mut rng).x;
                        s.push(if wo.z > 0.0 { f64::from(v) / pdf } else { 0.0 });
                    }
                }
                (format!("{sh:?} {est:?} eval"), st)
            }
            _ => (
                format!("{sh:?} sample()"),
                histogram(&mut |r| pf.sample(wi, r).map(|s| s.bounces), N_WALK, &mut rng),
            ),
        }
    });
    let z = family_z(0.01, results.len() * 3);
    for (&(t, e), (label, st)) in jobs.iter().zip(&results) {
        let reference = &expected[t][match e {
            0 => 0,
            _ if e % 2 == 1 => 1,
            _ => 2,
        }];
        for k in 0..3 {
            println!(
                "  θi={} {label} order {}: {:.5} ± {:.5} (quadrature {:.5})",
                thetas[t],
                k + 1,
                st[k].mean(),
                st[k].se(),
                reference[k]
            );
        }
    }
    for (&(t, e), (label, st)) in jobs.iter().zip(&results) {
        let reference = &expected[t][match e {
            0 => 0,
            _ if e % 2 == 1 => 1,
            _ => 2,
        }];
        for k in 0..3 {
            let l = format!("conductor F=1 GGX α=1 θi={} {label} order {}", thetas[t], k + 1);
            validation::assert_mean(&l, &st[k], reference[k], z, 2.5e-3, 0.0);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// BDPT sub-path cap
// ---------------------------------------------------------------------------------------------

/// BDPT builds paths of at most 2·BDPT_MAX_SUBPATH + 1 = 97 vertices. The albedo carried by
/// longer paths is measured with the model's own `sample` bounce histogram on a very rough
/// dielectric (GGX α = 2, θi = 1.5, from outside and inside, both models) — the worst case for
/// long paths — and asserted below 1e-4 with a one-sided Wilson bound at z; also
/// eval_bdpt(All) = eval_pt(All) there (PT has no cap) at two directions (two-sample).
#[test]
fn bdpt_subpath_cap_loses_negligible_energy() {
    use microsurface::research::MAX_BOUNCES;
    const N_WALK: usize = 400_000;
    let cap = 2 * 48 + 1;
    let mut cases = Vec::new();
    for sh in [Shadowing::Uncorrelated, Shadowing::Correlated] {
        for inside in [false, true] {
            cases.push((sh, inside));
        }
    }
    let z = family_z(0.01, cases.len() * 3);
    let results = par_map(&cases, |i, &(sh, inside)| {
        let m = dielectric(ggx(2.0, 2.0), sh);
        let wi = incident(1.5, inside);
        let mut rng = validation::rng(0xca9_0000 + i as u64);
        let mut long = 0u64;
        let mut lost = 0u64;
        for _ in 0..N_WALK {
            match m.sample(wi, &mut rng) {
                Some(s) if s.bounces as usize > cap => long += 1,
                Some(_) => {}
                None => lost += 1,
            }
        }
        let mut pairs = Vec::new();
        for wo in [validation::dir(1.4, 2.0), validation::dir(2.0, 0.5)] {
            let pt = point(m.as_ref(), wi, wo, Estimator::Pt, ALL, 60_000, &mut rng);
            let bdpt = point(m.as_ref(), wi, wo, Estimator::Bdpt, ALL, 20_000, &mut rng);
            pairs.push((wo, pt, bdpt));
        }
        (format!("{} α=2 θi=1.5{}", m.label(), if inside { " inside" } else { "" }), long + lost, pairs)
    });
    for (label, long, pairs) in &results {
        let n = N_WALK as f64;
        let p = *long as f64 / n;
        let upper = (p + z * z / (2.0 * n) + z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt())
            / (1.0 + z * z / n);
        println!(
            "{label}: walks longer than {cap} bounces (or > MAX_BOUNCES = {MAX_BOUNCES}): {long} / {N_WALK}, upper bound {upper:.2e}"
        );
        assert!(upper < 1e-4, "{label}: share of paths beyond the BDPT cap ≤ {upper:.2e} (not < 1e-4)");
        for (wo, pt, bdpt) in pairs {
            println!(
                "  ωo={wo}: PT {:.5} ± {:.5}, BDPT {:.5} ± {:.5}",
                pt.mean(),
                pt.se(),
                bdpt.mean(),
                bdpt.se()
            );
            assert_agree(&format!("{label} ωo={wo}: PT vs BDPT"), pt, bdpt, z, 0.03);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Degenerate input
// ---------------------------------------------------------------------------------------------

/// Grazing ωi (z = 0 and 1e-7), ωo = −ωi, η = 1 and 1 + 1e-6, α = 1e-3 and 4: every method
/// returns finite, non-negative values (and `sample` finite directions and weights).
#[test]
fn degenerate_input_stays_finite() {
    let mut rng = validation::rng(0xbad);
    let mut models: Vec<Box<dyn Model>> = Vec::new();
    for sh in [Shadowing::Uncorrelated, Shadowing::Correlated] {
        for a in [1e-3f32, 0.5, 4.0] {
            models.push(conductor(ggx(a, a), sh));
            models.push(boxed(beckmann(a, a), gold(), sh, "gold"));
            models.push(boxed(ggx(a, a), Diffuse::white(), sh, "diffuse"));
            for eta in [1.0f32, 1.0 + 1e-6, ETA] {
                models.push(boxed(ggx(a, a), Dielectric::new(eta).unwrap(), sh, "dielectric"));
                models.push(boxed(beckmann(a, a), Dielectric::new(eta).unwrap(), sh, "dielectric"));
            }
        }
    }
    let g = (1.0f32 - 1e-14).sqrt();
    let dirs = [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(g, 0.0, 1e-7),
        Vec3::new(g, 0.0, -1e-7),
        Vec3::Z,
        -Vec3::Z,
        validation::dir(0.7, 1.0),
        -validation::dir(0.7, 1.0),
    ];
    let mut count = 0;
    for m in &models {
        for &wi in &dirs {
            let mut wos: Vec<Vec3> = dirs.to_vec();
            wos.push(-wi);
            wos.push(Vec3::new(-wi.x, -wi.y, wi.z)); // mirror direction
            for &wo in &wos {
                for _ in 0..20 {
                    for est in [Estimator::Pt, Estimator::Bdpt] {
                        for order in [ALL, only(1), only(3), up_to(2)] {
                            let v = m.eval(wi, wo, est, order, &mut rng);
                            assert!(
                                v.is_finite() && v.min_element() >= 0.0,
                                "{}: eval {est:?} {order:?} ωi={wi} ωo={wo} = {v}",
                                m.label()
                            );
                            count += 1;
                        }
                    }
                    let s = m.single(wi, wo, &mut rng);
                    assert!(
                        s.is_finite() && s.min_element() >= 0.0,
                        "{}: single ωi={wi} ωo={wo} = {s}",
                        m.label()
                    );
                }
                let p = m.pdf(wi, wo);
                assert!(p.is_finite() && p >= 0.0, "{}: pdf ωi={wi} ωo={wo} = {p}", m.label());
            }
            for _ in 0..200 {
                if let Some(s) = m.sample(wi, &mut rng) {
                    assert!(
                        s.wo.is_finite()
                            && s.weight.is_finite()
                            && s.weight.min_element() >= 0.0
                            && s.bounces >= 1,
                        "{}: sample ωi={wi}: {s:?}",
                        m.label()
                    );
                }
            }
        }
    }
    println!("degenerate input: {} models, {count} evaluations, all finite", models.len());
}

/// The side of the interface for the test tables' `outside` flags.
fn side(outside: bool) -> Side {
    if outside { Side::Outside } else { Side::Inside }
}
