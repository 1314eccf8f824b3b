//! Intersections with the microsurface (Heitz et al. 2016, supplement §4.1): tests 4.1.1–4.1.5
//! with exact expectations, the distribution of the hit heights (Kolmogorov–Smirnov) and the
//! special cases of `sample_height`, for both heights × both slopes × several roughnesses.
//!
//! Notation: Λi = Λ(ωi), Λo = Λ(ωo); c = C¹(h). A ray leaving c0 = C¹(h0) upwards in ω escapes
//! with probability c0^Λ(ω); otherwise it hits at c ∈ [c0, 1) with P(hit, c ≤ x) = 1 − (c0/x)^Λ.
//! A downward ray always hits, with P(c ≤ x) = (x/c0)^|Λ(ω)|, |Λ(ω)| = 1 + Λ(−ω).

use glam::Vec3;
use microsurface::research::{
    GaussianHeight, HeightSample, MicrosurfaceGeometry, MicrosurfaceHeight, UniformHeight,
};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Ggx};
use statrs::function::{beta as sbeta, erf as serf};
use validation::{Stats, TestRng, assert_mean, dir, family_z, sidak, uniform32, uniform64};

/// Samples per expectation: SE ≤ √(¼/N) = 1.6e-3 for a probability.
const N: usize = 100_000;
/// The largest standard error a probability estimate may have and still mean something.
const MAX_SE: f64 = 2e-3;
/// The deterministic error of the f64 expectations computed from the f32 Λ and C¹ (relative
/// 1e-6 at most): far below z·SE ≈ 6e-3, it does not hide any statistical discrepancy.
const EXACT_TOL: f64 = 1e-5;
/// Family-wise significance of every test family.
const FAMILY_ALPHA: f64 = 0.01;
/// The roughnesses (αx, αy) tested: isotropic and anisotropic.
const ALPHAS: [(f32, f32); 4] = [(0.3, 0.3), (1.0, 1.0), (1.0, 0.1), (0.2, 1.5)];
/// Number of surfaces: 2 heights × 2 slopes × the roughnesses.
const SURFACES: usize = 4 * ALPHAS.len();

/// C¹ in double precision, independent of the crate.
trait ReferenceC1 {
    fn c1_ref(&self, h: f32) -> f64;
}

impl ReferenceC1 for UniformHeight {
    fn c1_ref(&self, h: f32) -> f64 {
        (0.5 * (f64::from(h) + 1.0)).clamp(0.0, 1.0)
    }
}

impl ReferenceC1 for GaussianHeight {
    fn c1_ref(&self, h: f32) -> f64 {
        0.5 * serf::erfc(-f64::from(h) / std::f64::consts::SQRT_2)
    }
}

/// A test run on every surface.
trait Visitor {
    fn visit<H: MicrosurfaceHeight + ReferenceC1, S: MicrosurfaceSlope>(
        &mut self,
        label: &str,
        geometry: MicrosurfaceGeometry<H, S>,
    );
}

/// Calls `v` on the 16 surfaces, in a fixed order.
fn for_each_surface(v: &mut impl Visitor) {
    for (ax, ay) in ALPHAS {
        let (ggx, beckmann) = (Ggx::new(ax, ay).unwrap(), Beckmann::new(ax, ay).unwrap());
        v.visit(&format!("uniform/ggx({ax},{ay})"), MicrosurfaceGeometry::new(UniformHeight, ggx));
        v.visit(&format!("uniform/beckmann({ax},{ay})"), MicrosurfaceGeometry::new(UniformHeight, beckmann));
        v.visit(&format!("gaussian/ggx({ax},{ay})"), MicrosurfaceGeometry::new(GaussianHeight, ggx));
        v.visit(
            &format!("gaussian/beckmann({ax},{ay})"),
            MicrosurfaceGeometry::new(GaussianHeight, beckmann),
        );
    }
}

/// A direction at polar angle θ with a random azimuth.
fn random_azimuth(theta: f64, rng: &mut TestRng) -> Vec3 {
    dir(theta, std::f64::consts::TAU * uniform64(rng))
}

fn lambda<H: MicrosurfaceHeight, S: MicrosurfaceSlope>(g: &MicrosurfaceGeometry<H, S>, w: Vec3) -> f64 {
    f64::from(g.slope().lambda(w))
}

fn escaped(s: HeightSample) -> f64 {
    if s == HeightSample::Escape { 1.0 } else { 0.0 }
}

/// The height of a hit (panics on escape).
fn hit(s: HeightSample, what: &str) -> f32 {
    match s {
        HeightSample::Hit(h) => {
            assert!(h.is_finite(), "{what}: hit at {h}");
            h
        }
        HeightSample::Escape => panic!("{what}: a downward ray escaped"),
    }
}

/// B(a, b) = exp(ln B) by statrs (independent of the crate).
fn beta(a: f64, b: f64) -> f64 {
    sbeta::ln_beta(a, b).exp()
}

// ---------------------------------------------------------------------------------------------
// 4.1.1 masking
// ---------------------------------------------------------------------------------------------

/// Polar angles of the single-direction tests (0 is straight up: always escapes).
const THETAS: [f64; 4] = [0.0, 0.6, 1.1, 1.5];

struct Masking {
    rng: TestRng,
    z: f64,
}

impl Visitor for Masking {
    fn visit<H: MicrosurfaceHeight + ReferenceC1, S: MicrosurfaceSlope>(
        &mut self,
        label: &str,
        g: MicrosurfaceGeometry<H, S>,
    ) {
        for theta in THETAS {
            let wo = random_azimuth(theta, &mut self.rng);
            let expected = 1.0 / (1.0 + lambda(&g, wo));
            assert!((f64::from(g.g1(wo)) - expected).abs() <= 1e-6, "{label}: g1({wo}) = {}", g.g1(wo));
            let (mut escape, mut g1_at) = (Stats::default(), Stats::default());
            for _ in 0..N {
                let h = g.height().inv_c1(uniform32(&mut self.rng));
                escape.push(escaped(g.sample_height(wo, h, uniform32(&mut self.rng))));
                g1_at.push(f64::from(g.g1_at(wo, h)));
            }
            let what = format!("4.1.1 {label} θo = {theta}: P(escape) = 1/(1 + Λ)");
            assert_mean(&what, &escape, expected, self.z, MAX_SE, EXACT_TOL);
            let what = format!("4.1.1 {label} θo = {theta}: E[g1_at(ωo, h)] = 1/(1 + Λ)");
            assert_mean(&what, &g1_at, expected, self.z, MAX_SE, EXACT_TOL);
        }
    }
}

#[test]
fn masking_4_1_1() {
    let z = family_z(FAMILY_ALPHA, SURFACES * THETAS.len() * 2);
    for_each_surface(&mut Masking { rng: validation::rng(411), z });
}

// ---------------------------------------------------------------------------------------------
// 4.1.2–4.1.5: pairs of directions
// ---------------------------------------------------------------------------------------------

/// (θi, θo) of the two-direction tests.
const PAIRS: [(f64, f64); 4] = [(0.3, 1.5), (1.5, 0.3), (1.0, 1.0), (1.5, 1.5)];

struct MaskingShadowing {
    rng: TestRng,
    z: f64,
    /// ωo below the horizon, the second ray traced as `sample_height(−ωo, −h, u)` (4.1.3).
    transmission: bool,
}

impl Visitor for MaskingShadowing {
    fn visit<H: MicrosurfaceHeight + ReferenceC1, S: MicrosurfaceSlope>(
        &mut self,
        label: &str,
        g: MicrosurfaceGeometry<H, S>,
    ) {
        for (theta_i, theta_o) in PAIRS {
            let wi = random_azimuth(theta_i, &mut self.rng);
            let mut wo = random_azimuth(theta_o, &mut self.rng);
            if self.transmission {
                wo = -wo;
            }
            // the escape events of the two rays are independent given h, with probabilities
            // c^Λi and c^Λo (reflection) or (1 − c)^Λ(−ωo) (transmission, flipped surface)
            let expected = if self.transmission {
                beta(1.0 + lambda(&g, wi), 1.0 + lambda(&g, -wo))
            } else {
                1.0 / (1.0 + lambda(&g, wi) + lambda(&g, wo))
            };
            let (mut both, mut product) = (Stats::default(), Stats::default());
            for _ in 0..N {
                let h = g.height().inv_c1(uniform32(&mut self.rng));
                let out_i = g.sample_height(wi, h, uniform32(&mut self.rng));
                let (out_o, g1_o) = if self.transmission {
                    (g.sample_height(-wo, -h, uniform32(&mut self.rng)), g.g1_at(-wo, -h))
                } else {
                    (g.sample_height(wo, h, uniform32(&mut self.rng)), g.g1_at(wo, h))
                };
                both.push(escaped(out_i) * escaped(out_o));
                product.push(f64::from(g.g1_at(wi, h)) * f64::from(g1_o));
            }
            let test = if self.transmission { "4.1.3" } else { "4.1.2" };
            let what = format!("{test} {label} θi = {theta_i}, θo = {theta_o}: P(both escape)");
            assert_mean(&what, &both, expected, self.z, MAX_SE, EXACT_TOL);
            let what = format!("{test} {label} θi = {theta_i}, θo = {theta_o}: E[G1(ωi, h) G1(ωo, h)]");
            assert_mean(&what, &product, expected, self.z, MAX_SE, EXACT_TOL);
        }
    }
}

#[test]
fn masking_shadowing_4_1_2() {
    let z = family_z(FAMILY_ALPHA, SURFACES * PAIRS.len() * 2);
    for_each_surface(&mut MaskingShadowing { rng: validation::rng(412), z, transmission: false });
}

#[test]
fn masking_shadowing_transmission_4_1_3() {
    let z = family_z(FAMILY_ALPHA, SURFACES * PAIRS.len() * 2);
    for_each_surface(&mut MaskingShadowing { rng: validation::rng(413), z, transmission: true });
}

/// C¹(h0) values of the starting heights of 4.1.4/4.1.5: the supplement's invC1(0.99), inside
/// the surface, and +∞ (above it), where its formula is exact.
const START_C1: [Option<f32>; 2] = [Some(0.99), None];

struct ShadowingGivenMasking {
    rng: TestRng,
    z: f64,
    transmission: bool,
}

impl Visitor for ShadowingGivenMasking {
    fn visit<H: MicrosurfaceHeight + ReferenceC1, S: MicrosurfaceSlope>(
        &mut self,
        label: &str,
        g: MicrosurfaceGeometry<H, S>,
    ) {
        for start in START_C1 {
            let h0 = start.map_or(f32::INFINITY, |u| g.height().inv_c1(u));
            let c0 = if h0 == f32::INFINITY { 1.0 } else { g.height().c1_ref(h0) };
            for (theta_i, theta_o) in PAIRS {
                let wi = random_azimuth(theta_i, &mut self.rng);
                let mut wo = random_azimuth(theta_o, &mut self.rng);
                if self.transmission {
                    wo = -wo;
                }
                // the hit from ωi has c ∈ [0, c0] with density a c^(a−1)/c0^a, a = 1 + Λi
                let a = 1.0 + lambda(&g, wi);
                let expected = if self.transmission {
                    // ∫ (1 − c)^Λ(−ωo) a c^(a−1)/c0^a dc = a B(a, b) I_c0(a, b)/c0^a
                    let b = 1.0 + lambda(&g, -wo);
                    let incomplete = if c0 >= 1.0 { 1.0 } else { sbeta::beta_reg(a, b, c0) };
                    a * beta(a, b) * incomplete / c0.powf(a)
                } else {
                    // ∫ c^Λo a c^(a−1)/c0^a dc = c0^Λo a/(a + Λo)
                    let lo = lambda(&g, wo);
                    c0.powf(lo) * a / (a + lo)
                };
                let (mut escape, mut g1_at) = (Stats::default(), Stats::default());
                for _ in 0..N {
                    let h = hit(g.sample_height(-wi, h0, uniform32(&mut self.rng)), label);
                    let u = uniform32(&mut self.rng);
                    let (out, g1) = if self.transmission {
                        (g.sample_height(-wo, -h, u), g.g1_at(-wo, -h))
                    } else {
                        (g.sample_height(wo, h, u), g.g1_at(wo, h))
                    };
                    escape.push(escaped(out));
                    g1_at.push(f64::from(g1));
                }
                let test = if self.transmission { "4.1.5" } else { "4.1.4" };
                let what =
                    format!("{test} {label} C¹(h0) = {c0:.6}, θi = {theta_i}, θo = {theta_o}: P(escape)");
                assert_mean(&what, &escape, expected, self.z, MAX_SE, EXACT_TOL);
                let what =
                    format!("{test} {label} C¹(h0) = {c0:.6}, θi = {theta_i}, θo = {theta_o}: E[G1(ωo, h)]");
                assert_mean(&what, &g1_at, expected, self.z, MAX_SE, EXACT_TOL);
            }
        }
    }
}

#[test]
fn shadowing_given_masking_4_1_4() {
    let z = family_z(FAMILY_ALPHA, SURFACES * START_C1.len() * PAIRS.len() * 2);
    for_each_surface(&mut ShadowingGivenMasking { rng: validation::rng(414), z, transmission: false });
}

#[test]
fn shadowing_given_masking_transmission_4_1_5() {
    let z = family_z(FAMILY_ALPHA, SURFACES * START_C1.len() * PAIRS.len() * 2);
    for_each_surface(&mut ShadowingGivenMasking { rng: validation::rng(415), z, transmission: true });
}

// ---------------------------------------------------------------------------------------------
// The distribution of the hit heights (Kolmogorov–Smirnov)
// ---------------------------------------------------------------------------------------------

/// The Kolmogorov survival function Q(λ) = 2 Σ (−1)^(j−1) exp(−2j²λ²).
fn kolmogorov_q(lambda: f64) -> f64 {
    if lambda < 0.2 {
        return 1.0;
    }
    let mut sum = 0.0;
    for j in 1..=100 {
        let j = f64::from(j);
        let term = (-2.0 * j * j * lambda * lambda).exp();
        sum += if j as u32 % 2 == 1 { term } else { -term };
        if term < 1e-16 {
            break;
        }
    }
    (2.0 * sum).clamp(0.0, 1.0)
}

/// The one-sample KS statistic D of values already transformed by the hypothesised CDF (so
/// uniform under the hypothesis), and its p-value (Stephens' finite-N correction).
fn ks_uniform(mut u: Vec<f64>) -> (f64, f64) {
    u.sort_by(f64::total_cmp);
    let n = u.len() as f64;
    let mut d = 0.0f64;
    for (i, &x) in u.iter().enumerate() {
        d = d.max((i + 1) as f64 / n - x).max(x - i as f64 / n);
    }
    let sqrt_n = n.sqrt();
    (d, kolmogorov_q((sqrt_n + 0.12 + 0.11 / sqrt_n) * d))
}

/// Attempts per KS case; a case is tested when its expected number of hits is at least
/// `MIN_HITS` (decided from the exact hit probability, before sampling).
const KS_ATTEMPTS: usize = 64_000;
const MIN_HITS: f64 = 4_000.0;
/// Downward polar angles (π: straight down, C¹(h)/C¹(h0) uniform) and upward ones.
const KS_DOWN: [f64; 4] = [std::f64::consts::PI, 2.6, 2.0, 1.65];
const KS_UP: [f64; 3] = [1.5, 1.2, 0.8];
/// C¹(h0) of the KS starting heights (None: h0 = +∞, only for downward rays).
const KS_START: [Option<f32>; 3] = [Some(0.3), Some(0.9), None];

/// One KS case: the p-value and the escape statistics.
struct KsCase {
    label: String,
    p: f64,
    d: f64,
    hits: usize,
}

struct HitHeights {
    rng: TestRng,
    cases: Vec<KsCase>,
    z: f64,
    escape_tests: usize,
}

impl Visitor for HitHeights {
    fn visit<H: MicrosurfaceHeight + ReferenceC1, S: MicrosurfaceSlope>(
        &mut self,
        label: &str,
        g: MicrosurfaceGeometry<H, S>,
    ) {
        let height = *g.height();
        for start in KS_START {
            let h0 = start.map_or(f32::INFINITY, |u| height.inv_c1(u));
            let c0 = if h0 == f32::INFINITY { 1.0 } else { height.c1_ref(h0) };
            for theta in KS_DOWN.iter().chain(&KS_UP) {
                let up = *theta < std::f64::consts::FRAC_PI_2;
                let w = random_azimuth(*theta, &mut self.rng);
                let l = lambda(&g, w);
                // P(escape) = c0^Λ upwards, 0 downwards
                let p_escape = if up { c0.powf(l) } else { 0.0 };
                if up && start.is_none() {
                    // from above the surface an upward ray always escapes
                    for _ in 0..1000 {
                        let u = uniform32(&mut self.rng);
                        assert_eq!(g.sample_height(w, h0, u), HeightSample::Escape, "{label}: up from +∞");
                    }
                    continue;
                }
                let what = format!("{label} from C¹(h0) = {c0:.4} θ = {theta:.3} (Λ = {l:.4e})");
                // the hypothesised CDF of C¹(h_hit), given a hit
                let cdf = |x: f64| -> f64 {
                    if up {
                        // (1 − (c0/x)^Λ)/(1 − c0^Λ) on [c0, 1]
                        ((l * (c0 / x).ln()).exp_m1() / (l * c0.ln()).exp_m1()).clamp(0.0, 1.0)
                    } else {
                        // (x/c0)^|Λ| on [0, c0]
                        (x / c0).powf(-l).clamp(0.0, 1.0)
                    }
                };
                let expected_hits = KS_ATTEMPTS as f64 * (1.0 - p_escape);
                let mut escapes = Stats::default();
                let mut transformed = Vec::with_capacity(KS_ATTEMPTS);
                for _ in 0..KS_ATTEMPTS {
                    match g.sample_height(w, h0, uniform32(&mut self.rng)) {
                        HeightSample::Escape => {
                            assert!(up, "{what}: a downward ray escaped");
                            escapes.push(1.0);
                        }
                        HeightSample::Hit(h) => {
                            assert!(h.is_finite(), "{what}: hit at {h}");
                            escapes.push(0.0);
                            let c = height.c1_ref(h);
                            // hits lie on the ray's side of h0 (up to the f32 rounding of h)
                            let slack = 1e-6 * c0 + 1e-7;
                            assert!(
                                if up { c >= c0 - slack } else { c <= c0 + slack },
                                "{what}: hit at C¹ = {c}"
                            );
                            transformed.push(cdf(c));
                        }
                    }
                }
                // the escape rate is tested where the normal approximation of the binomial holds
                // (at least 25 expected events of each kind; decided from the exact p)
                let n_att = KS_ATTEMPTS as f64;
                if up && n_att * p_escape.min(1.0 - p_escape) >= 25.0 {
                    self.escape_tests += 1;
                    assert_mean(
                        &format!("{what}: P(escape) = c0^Λ"),
                        &escapes,
                        p_escape,
                        self.z,
                        2.5e-3,
                        EXACT_TOL,
                    );
                    assert!((f64::from(g.g1_at(w, h0)) - p_escape).abs() < 1e-5, "{what}: g1_at");
                }
                if expected_hits >= MIN_HITS {
                    let hits = transformed.len();
                    let (d, p) = ks_uniform(transformed);
                    self.cases.push(KsCase { label: what, p, d, hits });
                }
            }
        }
    }
}

#[test]
fn hit_heights_follow_their_distribution() {
    // escape-rate tests: up directions × finite starts × surfaces
    let escape_family = SURFACES * KS_UP.len() * 2;
    let mut v = HitHeights {
        rng: validation::rng(4100),
        cases: Vec::new(),
        z: family_z(FAMILY_ALPHA, escape_family),
        escape_tests: 0,
    };
    for_each_surface(&mut v);
    // the family size is the number of candidate escape tests (conservative: some are skipped)
    println!("escape rates: {} of {escape_family} cases tested", v.escape_tests);
    assert!(v.escape_tests >= escape_family / 2, "too few escape-rate tests: {}", v.escape_tests);
    // the KS family: every case with enough expected hits (all downward ones, and the
    // upward ones whose Λ is not negligible)
    let m = v.cases.len();
    let alpha = sidak(FAMILY_ALPHA, m);
    let down_cases = SURFACES * KS_DOWN.len() * KS_START.len();
    println!("KS: {m} cases ({down_cases} downward), per-test α = {alpha:.3e}");
    assert!(m >= down_cases + SURFACES, "too few upward KS cases: {m}");
    let worst = v.cases.iter().min_by(|a, b| a.p.total_cmp(&b.p)).unwrap();
    println!(
        "KS: smallest p = {:.3e} (D = {:.4}, {} hits) for {}",
        worst.p, worst.d, worst.hits, worst.label
    );
    for case in &v.cases {
        assert!(
            case.p >= alpha,
            "KS rejects the hit heights of {}: D = {:.4}, n = {}, p = {:.3e} < α = {alpha:.3e}",
            case.label,
            case.d,
            case.hits,
            case.p
        );
    }
}

/// The KS harness can fail: straight down from C¹ = 0.9 the hit's C¹/0.9 is uniform, and a CDF
/// with exponent 1.1 instead of 1 is rejected.
#[test]
fn ks_rejects_a_wrong_hit_distribution() {
    let g = MicrosurfaceGeometry::new(UniformHeight, Ggx::isotropic(1.0).unwrap());
    let h0 = g.height().inv_c1(0.9);
    let c0 = UniformHeight.c1_ref(h0);
    let mut rng = validation::rng(4101);
    let (mut right, mut wrong) = (Vec::new(), Vec::new());
    for _ in 0..KS_ATTEMPTS {
        let c = UniformHeight.c1_ref(hit(g.sample_height(-Vec3::Z, h0, uniform32(&mut rng)), "down"));
        right.push((c / c0).min(1.0));
        wrong.push((c / c0).min(1.0).powf(1.1));
    }
    let (_, p_right) = ks_uniform(right);
    let (d, p_wrong) = ks_uniform(wrong);
    println!("KS control: p(right) = {p_right:.3}, p(wrong) = {p_wrong:.3e} (D = {d:.4})");
    assert!(p_right >= 0.01, "KS rejects the right distribution: p = {p_right}");
    assert!(p_wrong < 1e-6, "KS accepts a wrong exponent: p = {p_wrong}");
}

// ---------------------------------------------------------------------------------------------
// Special cases (deterministic)
// ---------------------------------------------------------------------------------------------

struct SpecialCases {
    rng: TestRng,
}

impl Visitor for SpecialCases {
    fn visit<H: MicrosurfaceHeight + ReferenceC1, S: MicrosurfaceSlope>(
        &mut self,
        label: &str,
        g: MicrosurfaceGeometry<H, S>,
    ) {
        let height = *g.height();
        let finite = [height.inv_c1(0.0), height.inv_c1(1e-30), -0.5, 0.0, 0.5, height.inv_c1(1.0), 100.0];
        let mut us = vec![0.0f32, 0.5, 1.0f32.next_down()];
        us.extend((0..200).map(|_| uniform32(&mut self.rng)));
        // straight up: Λ = 0, always escapes, from anywhere (also the very bottom, where 0^0 = 1)
        assert_eq!(g.slope().lambda(Vec3::Z), 0.0, "{label}: Λ(+z)");
        assert_eq!(g.g1(Vec3::Z), 1.0, "{label}: g1(+z)");
        for &h0 in finite.iter().chain(&[f32::INFINITY, f32::NEG_INFINITY]) {
            assert_eq!(g.g1_at(Vec3::Z, h0), 1.0, "{label}: g1_at(+z, {h0})");
            for &u in &us {
                assert_eq!(
                    g.sample_height(Vec3::Z, h0, u),
                    HeightSample::Escape,
                    "{label}: up from {h0}, u = {u}"
                );
            }
        }
        // horizontal: hits at h0 itself, escapes from +∞; never masked-free (g1 = 0)
        for k in 0..8 {
            let phi = std::f32::consts::TAU * k as f32 / 8.0;
            let w = Vec3::new(phi.cos(), phi.sin(), 0.0);
            assert_eq!(g.g1(w), 0.0, "{label}: g1 horizontal");
            for &h0 in &finite {
                assert_eq!(g.g1_at(w, h0), 0.0, "{label}: g1_at horizontal");
                for &u in &us {
                    assert_eq!(
                        g.sample_height(w, h0, u),
                        HeightSample::Hit(h0),
                        "{label}: horizontal from {h0}"
                    );
                }
            }
            for &u in &us {
                assert_eq!(
                    g.sample_height(w, f32::INFINITY, u),
                    HeightSample::Escape,
                    "{label}: horizontal from +∞"
                );
            }
        }
        // downward rays (including straight down and from +∞) always hit, at finite heights in
        // the support, below h0; g1 and g1_at are 0 below the horizon
        for theta in [std::f64::consts::PI, 2.5, 1.6, std::f64::consts::FRAC_PI_2 + 1e-4] {
            let w = random_azimuth(theta, &mut self.rng);
            assert_eq!(g.g1(w), 0.0, "{label}: g1 below the horizon");
            for &h0 in finite.iter().chain(&[f32::INFINITY]) {
                assert_eq!(g.g1_at(w, h0), 0.0, "{label}: g1_at below the horizon");
                for &u in &us {
                    let h = hit(g.sample_height(w, h0, u), label);
                    assert!(h >= height.inv_c1(0.0) && h <= height.inv_c1(1.0), "{label}: hit at {h}");
                    assert!(
                        height.c1_ref(h) <= height.c1_ref(h0) * (1.0 + 1e-6) + 1e-7,
                        "{label}: {h} above {h0}"
                    );
                }
            }
        }
        // upward rays from +∞ always escape and are never masked there
        for theta in [0.1, 1.0, 1.5, std::f64::consts::FRAC_PI_2 - 1e-4] {
            let w = random_azimuth(theta, &mut self.rng);
            assert_eq!(g.g1_at(w, f32::INFINITY), 1.0, "{label}: g1_at(ω, +∞)");
            for &u in &us {
                assert_eq!(g.sample_height(w, f32::INFINITY, u), HeightSample::Escape, "{label}: up from +∞");
            }
            // and every hit of an upward ray is finite and no lower than h0
            for &h0 in &finite {
                for &u in &us {
                    if let HeightSample::Hit(h) = g.sample_height(w, h0, u) {
                        assert!(h.is_finite(), "{label}: hit at {h}");
                        assert!(
                            height.c1_ref(h) >= height.c1_ref(h0) * (1.0 - 1e-6) - 1e-7,
                            "{label}: upward hit {h} below {h0}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn sample_height_special_cases() {
    for_each_surface(&mut SpecialCases { rng: validation::rng(4102) });
}
