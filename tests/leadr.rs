//! LEADR mapping (Dupuy 2015, §3.3–3.4): the moments, the pyramid, the moments → lobe
//! conversion and its covariance floor, bad input, and the filtering claim (the lobe of a
//! coarse texel against the average of its fine texels' BRDFs).
//!
//! The filtering errors are deterministic (a fixed procedural map, a midpoint quadrature whose
//! convergence is checked), not statistical: the bounds are the measured values with a margin,
//! stated at each assertion.

use glam::{DVec2, DVec3, Vec2, Vec3};
use microsurface::leadr::{
    CovarianceTreatment, HeightMap, LeadrLobe, LeadrMap, MIN_EIGENVALUE_RATIO, MIN_LEADR_ALPHA, SlopeMoments,
};
use microsurface::{Beckmann, Error};
use validation::leadr::surface::{NormalMip, direction, procedural_height_map};
use validation::leadr::validate::{filter_error, filter_errors, texel_lobe};

/// The validation map: 64 × 64 texels, RMS slope 0.2 per axis, fixed seed.
fn validation_map() -> HeightMap {
    procedural_height_map(64, 0.2, 1)
}

/// The coarse texels whose errors are measured at each level.
const TEXELS: [(usize, usize); 4] = [(0, 0), (1, 2), (2, 1), (3, 3)];

/// The errors (LEADR, naive normal MIP) of the coarse texel (x, y) of `level` for light from θ
/// (azimuth 30°), relative L1 against the average BRDF of its 4^level fine texels.
fn errors(
    leadr: &LeadrMap,
    normals: &NormalMip,
    alpha: f32,
    level: usize,
    (x, y): (usize, usize),
    theta: f64,
) -> (f64, f64) {
    let n = 1usize << level;
    let reference: Vec<LeadrLobe> =
        (0..n * n).map(|i| leadr.lobe(0, (x * n + i % n) as isize, (y * n + i / n) as isize)).collect();
    let wi = direction(theta, 30.0).as_dvec3();
    let filtered = leadr.lobe(level, x as isize, y as isize);
    let naive = texel_lobe(normals.slope(level, x as isize, y as isize), alpha);
    let e = filter_errors(wi, &reference, &[filtered, naive], 1.0);
    (e[0].relative_l1, e[1].relative_l1)
}

/// Where the thesis says LEADR holds (coarse texels over many fine ones, views up to 60°), the
/// filtered lobe reproduces the average of the fine texels' BRDFs far better than the naive
/// normal MIP with the base roughness, and within a stated bound.
///
/// Measured (mean over the 4 texels; worst per-texel ratio LEADR/naive over all cells 0.49):
/// α = 0.1: LEADR 0.29–0.34, naive 0.95–1.36; α = 0.3: LEADR 0.058–0.14, naive 0.20–0.40.
///
/// The bounds, and what they protect against. The errors are deterministic (a fixed map, a
/// midpoint quadrature converged to 1e-3, [`error_metric_quadrature_converges`]), so the
/// margins only have to absorb that and floating-point library differences; they are kept
/// small enough to catch modelling defects (each measured by substituting the defect's lobe):
/// - per texel, LEADR < 0.6 × naive (measured worst 0.49): LEADR keeps the spread of the
///   slopes that the naive MIP throws away, by a clear factor;
/// - per (α, level), the mean LEADR error ≤ the measured maximum over θ ≤ 60° + 0.02
///   (α = 0.1) or + 0.01 (α = 0.3), 6–14 % of the values and 10–20 × the quadrature's
///   convergence. A covariance off by a factor 2 (the ½ of Σ = ½ α² dropped or doubled) gives
///   0.49–0.66 and fails every cell; a dropped correlation ρ fails level 3 (α = 0.1: 0.341
///   against the bound 0.33; α = 0.3: 0.102 against 0.097).
#[test]
fn leadr_beats_the_naive_normal_mip() {
    let map = validation_map();
    let normals = NormalMip::new(&map);
    // (α, [bound on the mean LEADR error at levels 2, 3, 4]); measured maxima
    // α = 0.1: 0.338, 0.307, 0.308; α = 0.3: 0.070, 0.087, 0.136
    for (alpha, bounds) in [(0.1f32, [0.36, 0.33, 0.33]), (0.3, [0.08, 0.097, 0.147])] {
        let leadr = LeadrMap::from_height_map(&map, Beckmann::isotropic(alpha).unwrap()).unwrap();
        for (level, bound) in [2usize, 3, 4].into_iter().zip(bounds) {
            for theta in [0.0, 30.0, 60.0] {
                let (mut mean_leadr, mut mean_naive) = (0.0, 0.0);
                for texel in TEXELS {
                    let (e, e_naive) = errors(&leadr, &normals, alpha, level, texel, theta);
                    assert!(
                        e < 0.6 * e_naive,
                        "α {alpha} level {level} θ {theta}° texel {texel:?}: LEADR {e:.4} vs naive {e_naive:.4}"
                    );
                    mean_leadr += e / TEXELS.len() as f64;
                    mean_naive += e_naive / TEXELS.len() as f64;
                }
                assert!(
                    mean_leadr <= bound,
                    "α {alpha} level {level} θ {theta}°: mean LEADR error {mean_leadr:.4} > {bound} (naive {mean_naive:.4})"
                );
            }
        }
    }
}

/// The breakdown at grazing views the README states, pinned on the README's (the example's)
/// 128² map: at α = 0.1, level 2 (16 sharp, distinct fine lobes), LEADR's mean error exceeds the
/// naive MIP's at 75° and 85° (measured ratios 1.42 and 1.69), while up to 60° it is 0.29–0.37 of
/// it. Smith masking is not linear in the slope distribution, so the one wide lobe's G1 and the
/// average of the fine texels' G1 part. Deterministic; the thresholds are the README's claim
/// (ratio > 1 at grazing views, < 0.5 at 0–60°), not fitted to the measurement.
#[test]
fn leadr_breaks_down_at_grazing_views() {
    let map = procedural_height_map(128, 0.2, 1);
    let normals = NormalMip::new(&map);
    let alpha = 0.1;
    let leadr = LeadrMap::from_height_map(&map, Beckmann::isotropic(alpha).unwrap()).unwrap();
    let mean_ratio = |theta: f64| {
        let (mut mean_leadr, mut mean_naive) = (0.0, 0.0);
        for texel in TEXELS {
            let (e, e_naive) = errors(&leadr, &normals, alpha, 2, texel, theta);
            mean_leadr += e;
            mean_naive += e_naive;
        }
        (mean_leadr / mean_naive, mean_leadr / TEXELS.len() as f64, mean_naive / TEXELS.len() as f64)
    };
    for theta in [0.0, 60.0] {
        let (ratio, l, n) = mean_ratio(theta);
        assert!(ratio < 0.5, "θ {theta}°: LEADR/naive {ratio:.3} (LEADR {l:.4}, naive {n:.4})");
    }
    for theta in [75.0, 85.0] {
        let (ratio, l, n) = mean_ratio(theta);
        assert!(ratio > 1.0, "θ {theta}°: LEADR/naive {ratio:.3} (LEADR {l:.4}, naive {n:.4})");
    }
}

/// The quadrature of the error metric has converged: doubling the node density changes the
/// relative L1 error by less than 1e-3 (measured 3e-4 and below) and the albedo by less than 1e-6.
#[test]
fn error_metric_quadrature_converges() {
    let map = validation_map();
    let leadr = LeadrMap::from_height_map(&map, Beckmann::isotropic(0.1).unwrap()).unwrap();
    let reference: Vec<LeadrLobe> = (0..64).map(|i| leadr.lobe(0, i % 8, i / 8)).collect();
    let filtered = leadr.lobe(3, 0, 0);
    for theta in [0.0, 60.0] {
        let wi = direction(theta, 30.0).as_dvec3();
        let (a, b) =
            (filter_error(wi, &reference, &filtered, 1.0), filter_error(wi, &reference, &filtered, 2.0));
        assert!(
            (a.relative_l1 - b.relative_l1).abs() < 1e-3 && (a.albedo - b.albedo).abs() < 1e-6,
            "θ {theta}: {a:?} vs {b:?}"
        );
        // a single texel against itself: no error, and the quadrature sees its whole lobe
        let one = filter_error(wi, &reference[..1], &reference[0], 1.0);
        assert!(one.relative_l1 == 0.0 && one.albedo > 0.5 && one.albedo.is_finite(), "{one:?}");
    }
}

/// Level ℓ holds exactly the moments of the 4^ℓ input texels under it (linear filtering), up to
/// f32 rounding, and texel moments are (x̃, ỹ, x̃² + αx²/2, ỹ² + αy²/2, x̃ỹ).
#[test]
fn pyramid_is_the_average_of_the_input_texels() {
    let map = procedural_height_map(16, 0.3, 7);
    let base = Beckmann::new(0.2, 0.05).unwrap();
    let leadr = LeadrMap::from_height_map(&map, base).unwrap();
    assert_eq!(leadr.level_count(), 5);
    let s = map.slope(3, 5);
    let t = leadr.level(0).texel(3, 5).to_array();
    let expected = [s.x, s.y, s.x * s.x + 0.02, s.y * s.y + 0.00125, s.x * s.y];
    for (a, b) in t.iter().zip(expected) {
        assert!((a - b).abs() <= 1e-6 * (1.0 + b.abs()), "{t:?} vs {expected:?}");
    }
    for level in 1..5 {
        let n = 1usize << level;
        let size = 16 / n;
        for (x, y) in [(0, 0), (size - 1, 0), (size / 2, size - 1)] {
            let fine: Vec<SlopeMoments> = (0..n * n)
                .map(|i| leadr.level(0).texel((x * n + i % n) as isize, (y * n + i / n) as isize))
                .collect();
            let direct = SlopeMoments::average(&fine).unwrap().to_array();
            let filtered = leadr.level(level).texel(x as isize, y as isize).to_array();
            for (a, b) in direct.iter().zip(filtered) {
                // one f32 rounding per level
                assert!(
                    (a - b).abs() <= 4.0 * level as f32 * f32::EPSILON * (1.0 + a.abs()),
                    "{direct:?} vs {filtered:?}"
                );
            }
        }
    }
    // trilinear lookups are the exact blend of the levels (texel centres of level 1)
    let uv = Vec2::new(0.5 / 8.0, 0.5 / 8.0);
    let blend = leadr.trilinear(uv, 1.5).to_array();
    let (a, b) = (leadr.level(1).bilinear(uv).to_array(), leadr.level(2).bilinear(uv).to_array());
    for i in 0..5 {
        assert!((blend[i] - 0.5 * (a[i] + b[i])).abs() <= 1e-6 * (1.0 + a[i].abs()));
    }
    assert_eq!(leadr.level(1).bilinear(uv), leadr.level(1).texel(0, 0));
}

/// A normal map gives the same moments as the height map whose slopes it holds.
#[test]
fn normal_map_matches_height_map() {
    let map = procedural_height_map(8, 0.4, 3);
    let base = Beckmann::isotropic(0.15).unwrap();
    let normals: Vec<Vec3> = (0..64)
        .map(|i| {
            let s = map.slope(i % 8, i / 8);
            Vec3::new(-s.x, -s.y, 1.0) * 2.5 // need not be unit
        })
        .collect();
    let a = LeadrMap::from_height_map(&map, base).unwrap();
    let b = LeadrMap::from_normal_map(8, 8, &normals, base).unwrap();
    for level in 0..a.level_count() {
        for (p, q) in a.level(level).texels().iter().zip(b.level(level).texels()) {
            for (u, v) in p.to_array().iter().zip(q.to_array()) {
                assert!((u - v).abs() <= 1e-6 * (1.0 + u.abs()), "level {level}: {p:?} vs {q:?}");
            }
        }
    }
}

/// Moments → lobe → moments is the identity up to rounding, for correlated anisotropic lobes.
#[test]
fn lobe_round_trip() {
    let base = Beckmann::isotropic(0.1).unwrap();
    let texels: Vec<SlopeMoments> = [(0.3, -0.1), (0.5, 0.2), (-0.2, 0.4), (0.1, 0.1)]
        .iter()
        .map(|&(x, y)| SlopeMoments::from_slope(Vec2::new(x, y), base).unwrap())
        .collect();
    let m = SlopeMoments::average(&texels).unwrap();
    let lobe = LeadrLobe::from_moments(&m);
    assert_eq!(lobe.treatment(), CovarianceTreatment::AsGiven);
    assert!(lobe.rho().abs() > 0.1, "a correlated test case: {lobe:?}");
    let back = lobe.moments().to_array();
    for (a, b) in back.iter().zip(m.to_array()) {
        assert!((a - b).abs() <= 1e-6 * (1.0 + b.abs()), "{back:?} vs {m:?}");
    }
}

/// Moments that are not a valid covariance get the Frobenius-nearest covariance whose
/// eigenvalues are ≥ the floor: the same eigenvectors, the eigenvalues below the floor raised to
/// it, the mean slope kept; the result is finite.
#[test]
fn invalid_covariance_is_floored_to_the_nearest_valid_one() {
    let floor = 0.5 * f64::from(MIN_LEADR_ALPHA).powi(2);
    // Σ with eigenvalues 0.3 and −0.1 (rotated by 30°), mean slope (0.2, −0.4)
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let (l1, l2) = (0.3, -0.1);
    let cov = [l1 * c * c + l2 * s * s, l1 * s * s + l2 * c * c, (l1 - l2) * c * s];
    let mean = DVec2::new(0.2, -0.4);
    let m = SlopeMoments::new(
        mean.x as f32,
        mean.y as f32,
        (cov[0] + mean.x * mean.x) as f32,
        (cov[1] + mean.y * mean.y) as f32,
        (cov[2] + mean.x * mean.y) as f32,
    )
    .unwrap();
    let lobe = LeadrLobe::from_moments(&m);
    assert_eq!(lobe.treatment(), CovarianceTreatment::EigenvalueFloored);
    assert_eq!(lobe.mean_slope(), m.mean());
    let got = lobe.covariance().map(f64::from);
    let want = [l1 * c * c + floor * s * s, l1 * s * s + floor * c * c, (l1 - floor) * c * s];
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() < 1e-6, "{got:?} vs {want:?}");
    }
    // nearest: no valid covariance (eigenvalues ≥ floor) of a small family around it is closer
    let dist = |a: [f64; 3]| {
        ((a[0] - cov[0]).powi(2) + (a[1] - cov[1]).powi(2) + 2.0 * (a[2] - cov[2]).powi(2)).sqrt()
    };
    let best = dist(got);
    for k in 0..200 {
        let t = k as f64 / 200.0 * std::f64::consts::PI;
        for (a, b) in [(0.3, floor), (0.31, floor), (0.29, 0.01), (0.3, 0.002)] {
            let cand = [
                a * t.cos().powi(2) + b * t.sin().powi(2),
                a * t.sin().powi(2) + b * t.cos().powi(2),
                (a - b) * t.cos() * t.sin(),
            ];
            assert!(dist(cand) >= best - 1e-9, "candidate {cand:?} is closer than {got:?}");
        }
    }
    // degenerate and extreme moments: always finite, within the documented bounds
    for e in [
        [0.0, 0.0, 0.0, 0.0, 0.0],
        [1.0, 1.0, 0.0, 0.0, 5.0],
        [0.0, 0.0, -1.0, -1.0, 0.0],
        [1e19, -1e19, 1e38, 1e38, -1e38],
        [0.0, 0.0, 3e38, 1e-30, 0.0],
        [0.0, 0.0, 1.0, 1.0, 1.0],
    ] {
        let l = LeadrLobe::from_moments(&SlopeMoments::new(e[0], e[1], e[2], e[3], e[4]).unwrap());
        let ok = [l.alpha_x(), l.alpha_y(), l.rho()].iter().all(|v| v.is_finite())
            && l.alpha_x() >= MIN_LEADR_ALPHA * 0.999
            && l.alpha_y() >= MIN_LEADR_ALPHA * 0.999
            && l.rho().abs() <= 1.0 - 0.25 * MIN_EIGENVALUE_RATIO;
        assert!(ok, "{e:?} → {l:?}");
    }
}

/// Non-finite and out-of-domain input is rejected with an error naming the parameter.
#[test]
fn bad_input_is_rejected() {
    let base = Beckmann::isotropic(0.1).unwrap();
    let name = |r: Result<_, Error>| match r {
        Err(Error::InvalidParameter { name, .. }) => name,
        _ => "accepted",
    };
    assert_eq!(name(SlopeMoments::new(0.0, f32::NAN, 1.0, 1.0, 0.0).map(|_| ())), "e2");
    assert_eq!(name(SlopeMoments::new(0.0, 0.0, f32::INFINITY, 1.0, 0.0).map(|_| ())), "e3");
    assert_eq!(name(SlopeMoments::from_slope(Vec2::new(f32::NAN, 0.0), base).map(|_| ())), "slope");
    assert_eq!(name(SlopeMoments::from_slope(Vec2::new(0.0, 1e20), base).map(|_| ())), "slope");
    assert_eq!(name(SlopeMoments::from_normal(Vec3::new(0.0, 0.0, 0.0), base).map(|_| ())), "normal");
    assert_eq!(name(SlopeMoments::from_normal(Vec3::new(1.0, 0.0, -0.1), base).map(|_| ())), "normal");
    assert_eq!(name(SlopeMoments::from_normal(Vec3::new(1.0, f32::NAN, 1.0), base).map(|_| ())), "normal");
    assert_eq!(name(HeightMap::new(2, 2, 1.0, vec![0.0, 1.0, f32::NAN, 0.0]).map(|_| ())), "heights");
    assert_eq!(name(HeightMap::new(2, 2, 1.0, vec![0.0; 3]).map(|_| ())), "heights");
    assert_eq!(name(HeightMap::new(0, 2, 1.0, vec![]).map(|_| ())), "width");
    assert_eq!(name(HeightMap::new(1, 1, 0.0, vec![0.0]).map(|_| ())), "texel_size");
    let odd = HeightMap::new(3, 2, 1.0, vec![0.0; 6]).unwrap();
    assert_eq!(name(LeadrMap::from_height_map(&odd, base).map(|_| ())), "width");
    let steep = HeightMap::new(4, 1, 1e-30, vec![0.0, 3e38, 0.0, 0.0]).unwrap();
    assert_eq!(name(LeadrMap::from_height_map(&steep, base).map(|_| ())), "slope");
    assert_eq!(name(LeadrMap::from_normal_map(2, 2, &[Vec3::Z; 3], base).map(|_| ())), "normals");
    assert_eq!(
        name(LeadrMap::from_normal_map(2, 2, &[Vec3::Z, Vec3::Z, Vec3::Z, -Vec3::Z], base).map(|_| ())),
        "normal"
    );
}

/// A lookup under test.
type Lookup<'a> = Box<dyn Fn() -> SlopeMoments + 'a>;

/// Invalid lookup arguments ([policy](microsurface#invalid-input)): a non-finite `uv` or a NaN
/// `lod` trips the debug assertion; release builds return texel (0, 0) of the level (level 0
/// for `trilinear`).
#[test]
fn invalid_lookups_follow_the_policy() {
    let map = LeadrMap::from_height_map(&procedural_height_map(8, 0.3, 5), Beckmann::isotropic(0.2).unwrap())
        .unwrap();
    let calls: [(&str, Lookup, SlopeMoments); 4] = [
        (
            "bilinear NaN",
            Box::new(|| map.level(1).bilinear(Vec2::new(f32::NAN, 0.2))),
            map.level(1).texel(0, 0),
        ),
        (
            "bilinear ∞",
            Box::new(|| map.level(2).bilinear(Vec2::new(0.1, f32::INFINITY))),
            map.level(2).texel(0, 0),
        ),
        ("trilinear uv", Box::new(|| map.trilinear(Vec2::new(f32::NAN, 0.2), 1.0)), map.level(0).texel(0, 0)),
        (
            "trilinear lod",
            Box::new(|| map.trilinear(Vec2::new(0.3, 0.2), f32::NAN)),
            map.level(0).texel(0, 0),
        ),
    ];
    for (name, call, nothing) in calls {
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(&call));
        if cfg!(debug_assertions) {
            let message = result.expect_err(name);
            let text = message.downcast_ref::<String>().map(String::as_str).unwrap_or("");
            assert!(text.starts_with("invalid input"), "{name}: {text}");
        } else {
            assert_eq!(result.expect(name), nothing, "{name}");
        }
    }
    // valid extremes are lookups, not violations: wrapping coordinates and clamped levels
    assert_eq!(map.trilinear(Vec2::new(1.25, -0.75), 99.0), map.level(3).texel(0, 0));
    assert_eq!(
        map.trilinear(Vec2::new(0.3, 0.2), f32::NEG_INFINITY),
        map.level(0).bilinear(Vec2::new(0.3, 0.2))
    );
}

/// An independent oracle for the crate's noncentral lobe: the slope density N(mean, Σ)
/// (Dupuy 2015, eq. 3.2) and Smith's G1 (eq. 3.3) in closed form, A(k) = E[(k.z − k.xy·h̃)⁺]
/// = s φ(c/s) + c Φ(c/s) for the Gaussian of mean c = k.z − k.xy·mean, variance s² = k.xyᵀ Σ k.xy.
struct ClosedForm {
    mean: DVec2,
    cov: [f64; 3],
}

impl ClosedForm {
    fn new(lobe: &LeadrLobe) -> Self {
        Self { mean: lobe.mean_slope().as_dvec2(), cov: lobe.covariance().map(f64::from) }
    }

    fn p22(&self, s: DVec2) -> f64 {
        let [xx, yy, xy] = self.cov;
        let det = xx * yy - xy * xy;
        let d = s - self.mean;
        let q = (yy * d.x * d.x + xx * d.y * d.y - 2.0 * xy * d.x * d.y) / det;
        (-0.5 * q).exp() / (2.0 * std::f64::consts::PI * det.sqrt())
    }

    fn g1(&self, k: DVec3) -> f64 {
        if k.z <= 0.0 {
            return 0.0;
        }
        let c = k.z - k.x * self.mean.x - k.y * self.mean.y;
        let [xx, yy, xy] = self.cov;
        let s = (k.x * k.x * xx + k.y * k.y * yy + 2.0 * k.x * k.y * xy).sqrt();
        let t = c / s;
        let area = s * (-0.5 * t * t).exp() / (2.0 * std::f64::consts::PI).sqrt()
            + c * 0.5 * libm::erfc(-t * std::f64::consts::FRAC_1_SQRT_2);
        k.z / area
    }
}

/// The crate's noncentral correlated Beckmann ([`LeadrLobe::slope`], which the filtering
/// validation evaluates) against the independent closed form [`ClosedForm`]: D (eq. 3.2) and
/// G1 (eq. 3.3) agree to 1e-5 relative at 2 000 random direction pairs of lobes with mean
/// slopes, anisotropy and correlation.
#[test]
fn closed_form_matches_the_crate_noncentral_slope() {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(11);
    let base = Beckmann::isotropic(0.1).unwrap();
    let slopes = [(0.3, -0.1), (0.5, 0.2), (-0.2, 0.4), (0.1, 0.1), (0.0, -0.6)];
    let texels: Vec<SlopeMoments> =
        slopes.iter().map(|&(x, y)| SlopeMoments::from_slope(Vec2::new(x, y), base).unwrap()).collect();
    let lobes = [
        LeadrLobe::from_moments(&SlopeMoments::average(&texels).unwrap()),
        LeadrLobe::from_moments(&SlopeMoments::average(&texels[1..3]).unwrap()),
        LeadrLobe::from_moments(&texels[4]),
    ];
    let mut worst = (0.0f64, 0.0f64);
    for lobe in &lobes {
        let crate_slope = lobe.slope();
        let closed = ClosedForm::new(lobe);
        for _ in 0..2_000 / lobes.len() {
            let wi = direction(85.0 * rng.random::<f64>(), 360.0 * rng.random::<f64>());
            let wh = direction(60.0 * rng.random::<f64>(), 360.0 * rng.random::<f64>());
            let h = wh.as_dvec3();
            let d_closed = closed.p22(DVec2::new(-h.x / h.z, -h.y / h.z)) / h.z.powi(4);
            let d_crate = crate_slope.d64(h);
            let g_closed = closed.g1(wi.as_dvec3());
            let g_crate = f64::from(crate_slope.g1(wi));
            let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-300);
            worst.0 = worst.0.max(if d_crate > 1e-30 { rel(d_closed, d_crate) } else { 0.0 });
            worst.1 = worst.1.max(rel(g_closed, g_crate));
        }
    }
    assert!(
        worst.0 < 1e-5 && worst.1 < 1e-5,
        "worst relative differences: D {:e}, G1 {:e}",
        worst.0,
        worst.1
    );
}

/// Rounding breaks the covariance of steep, smooth texels: at mean slope ±60 with α = 1e-3 the
/// variance α²/2 = 5e-7 is far below the f32 spacing of E₃ ≈ 3600 (2.4e-4), so the stored moments
/// lose it and the difference E₃ − E₁² is rounding noise of either sign. Every lobe of the
/// pyramid is still finite, with roughness ≥ `MIN_LEADR_ALPHA`, and the floor is what caught it.
#[test]
fn rounding_of_steep_texels_is_floored() {
    let base = Beckmann::isotropic(1e-3).unwrap();
    let normals: Vec<Vec3> = (0..16)
        .map(|i| {
            let s = if i % 2 == 0 { 60.0 } else { -60.0 + 1e-3 * i as f32 };
            Vec3::new(-s, 0.3 * s, 1.0)
        })
        .collect();
    let map = LeadrMap::from_normal_map(4, 4, &normals, base).unwrap();
    let mut floored = 0;
    for level in 0..map.level_count() {
        for (i, t) in map.level(level).texels().iter().enumerate() {
            let l = LeadrLobe::from_moments(t);
            let ok = [l.alpha_x(), l.alpha_y(), l.rho()].iter().all(|v| v.is_finite())
                && l.alpha_x() >= 0.999 * MIN_LEADR_ALPHA
                && l.alpha_y() >= 0.999 * MIN_LEADR_ALPHA
                && l.rho().abs() < 1.0;
            assert!(ok, "level {level} texel {i}: {t:?} → {l:?}");
            floored += usize::from(l.treatment() == CovarianceTreatment::EigenvalueFloored);
        }
    }
    assert!(floored > 0, "the test case must exercise the floor");
}

/// The linear slope map of §3.4 (stretching, shearing, height scaling): transformed moments are
/// the moments of the transformed slopes with the transformed base covariance, the map commutes
/// with the MIP filtering, and non-finite or overflowing maps are rejected.
#[test]
fn slope_map_transforms_moments() {
    use glam::Mat2;
    let a = Mat2::from_cols(Vec2::new(1.5, 0.3), Vec2::new(-0.4, 0.8));
    let base = Beckmann::isotropic(0.2).unwrap();
    let s = Vec2::new(0.3, -0.7);
    let t = SlopeMoments::from_slope(s, base).unwrap().transformed(a).unwrap();
    let ws = (a * s).as_dvec2();
    let ad = a.as_dmat2();
    let base_cov = ad * ad.transpose() * 0.02; // A (α²/2 I) Aᵀ
    let expected = [
        ws.x,
        ws.y,
        ws.x * ws.x + base_cov.x_axis.x,
        ws.y * ws.y + base_cov.y_axis.y,
        ws.x * ws.y + base_cov.y_axis.x,
    ];
    for (g, w) in t.to_array().iter().zip(expected) {
        assert!((f64::from(*g) - w).abs() < 1e-6, "{t:?} vs {expected:?}");
    }
    // commutes with filtering: level 2 transformed = average of the transformed input texels
    let map = LeadrMap::from_height_map(&procedural_height_map(8, 0.3, 9), base).unwrap();
    let coarse = map.level(2).texel(1, 0).transformed(a).unwrap().to_array();
    let fine: Vec<SlopeMoments> =
        (0..16).map(|i| map.level(0).texel(4 + i % 4, i / 4).transformed(a).unwrap()).collect();
    let direct = SlopeMoments::average(&fine).unwrap().to_array();
    for (c, d) in coarse.iter().zip(direct) {
        assert!((c - d).abs() <= 1e-6 * (1.0 + d.abs()), "{coarse:?} vs {direct:?}");
    }
    // a height scale β scales the mean by β and the lobe's roughness by β
    let lobe = LeadrLobe::from_moments(&map.level(1).texel(0, 0));
    let scaled = LeadrLobe::from_moments(
        &map.level(1).texel(0, 0).transformed(Mat2::from_diagonal(Vec2::splat(2.0))).unwrap(),
    );
    assert!(
        (scaled.alpha_x() - 2.0 * lobe.alpha_x()).abs() < 1e-5 && (scaled.rho() - lobe.rho()).abs() < 1e-5
    );
    assert!((scaled.mean_slope() - 2.0 * lobe.mean_slope()).length() < 1e-6);
    // bad maps
    let m = SlopeMoments::from_slope(s, base).unwrap();
    let name = |r: Result<SlopeMoments, Error>| match r {
        Err(Error::InvalidParameter { name, .. }) => name,
        _ => "accepted",
    };
    assert_eq!(name(m.transformed(Mat2::from_cols(Vec2::new(f32::NAN, 0.0), Vec2::Y))), "slope_map");
    assert_eq!(name(m.transformed(Mat2::from_diagonal(Vec2::splat(1e30)))), "slope_map");
}

/// Every finite uv is a valid, wrapping lookup: far-out coordinates (±1e30, ±1e10 + 0.25, which
/// f32 rounds to ±1e10, and exactly representable ±(2²⁰ + 0.25)) give the lookup at uv mod 1,
/// bilinear and trilinear. Before the fix, floor(uv · width) saturated the texel index and the
/// neighbour's index overflowed (a panic in debug builds, the wrong texel in release).
#[test]
fn far_out_uv_wraps() {
    let map = LeadrMap::from_height_map(&procedural_height_map(8, 0.3, 5), Beckmann::isotropic(0.2).unwrap())
        .unwrap();
    let exact = 2f32.powi(20) + 0.25; // representable: the f32 spacing at 2²⁰ is 0.125
    let far = [1e30f32, -1e30, 1e10 + 0.25, -1e10 - 0.25, exact, -exact];
    for &u in &far {
        for &v in &[0.375f32, u, -u] {
            let uv = Vec2::new(u, v);
            let wrapped = Vec2::new(f64::from(u).rem_euclid(1.0) as f32, f64::from(v).rem_euclid(1.0) as f32);
            for level in [0, 1, 3] {
                let got = std::panic::catch_unwind(|| map.level(level).bilinear(uv));
                let got = got.unwrap_or_else(|_| panic!("level {level}: bilinear({uv}) panicked"));
                assert_eq!(got, map.level(level).bilinear(wrapped), "level {level}: uv {uv} vs {wrapped}");
            }
            assert_eq!(map.trilinear(uv, 1.5), map.trilinear(wrapped, 1.5), "trilinear: uv {uv}");
        }
    }
}

/// Every lobe [`LeadrLobe::from_moments`] makes is a valid crate lobe, even of extreme finite
/// moments (|E| up to f32::MAX): `slope()` is infallible, and its D and G1 are finite.
#[test]
fn extreme_moments_give_valid_slopes() {
    let big = f32::MAX;
    for e in [
        [big, -big, big, big, 0.0],
        [big, big, 0.0, 0.0, big],
        [-big, big, big, -big, -big],
        [1e19, -1e19, 1e38, 1e38, -1e38],
        [0.0, 0.0, big, 1e-30, 0.0],
        [0.0, 0.0, 0.0, 0.0, 0.0],
    ] {
        let lobe = LeadrLobe::from_moments(&SlopeMoments::new(e[0], e[1], e[2], e[3], e[4]).unwrap());
        let slope = lobe.slope();
        let (d, g) = (slope.d(slope.mean_normal()), slope.g1(Vec3::Z));
        assert!(d.is_finite() && g.is_finite() && g >= 0.0, "{e:?} → {lobe:?}: D {d}, G1 {g}");
    }
}
