//! Fresnel reflectances against independent f64 references: the dielectric formula (with
//! total internal reflection), the conductor term against a complex-arithmetic evaluation of
//! the Fresnel equations, Schlick's approximation, and the metal presets.
//!
//! Everything here is deterministic: the tolerances are f32 rounding bounds, stated per test.

use glam::Vec3;
use microsurface::ComplexIor;
use microsurface::fresnel::{fresnel_conductor, fresnel_dielectric, fresnel_schlick};

/// cos θ on a grid of [0, 1] including both ends, denser near grazing incidence.
fn cosines() -> Vec<f64> {
    let mut v: Vec<f64> = (0..=2000).map(|i| f64::from(i) / 2000.0).collect();
    v.extend((1..200).map(|i| f64::from(i) * 1e-5));
    v
}

/// Reference unpolarized dielectric reflectance in f64 (η = ηt/ηi), 1 under total internal
/// reflection.
fn dielectric_ref(c: f64, eta: f64) -> f64 {
    let sin2_t = (1.0 - c * c) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - sin2_t).sqrt();
    let rs = (c - eta * ct) / (c + eta * ct);
    let rp = (eta * c - ct) / (eta * c + ct);
    0.5 * (rs * rs + rp * rp)
}

/// Whether cos θ is within `band` (in sin²θt) of the critical angle of `eta`, where the f32
/// evaluation of cos θt = √(1 − sin²θt) loses its relative precision.
fn near_critical(c: f64, eta: f64, band: f64) -> bool {
    ((1.0 - c * c) / (eta * eta) - 1.0).abs() < band
}

/// The f32 evaluation's error bound against the f64 reference: a few ulps of F, plus the
/// rounding of sin²θt (≲ 4 ulps of 1, 2.4e-7) amplified by d cos θt/d sin²θt = 1/(2 cos θt)
/// and by |dF/d cos θt| ≲ 8 near the critical angle.
fn f32_tolerance(cos_t: f64) -> f64 {
    2e-6 + 1e-6 / cos_t.max(1e-9)
}

#[test]
fn dielectric_matches_the_f64_formula() {
    let etas = [0.4, 1.0 / 1.5, 0.9, 0.99, 1.0, 1.01, 1.33, 1.5, 2.4, 4.0];
    let mut worst = 0.0f64;
    let mut tir = 0;
    for &eta in &etas {
        for c in cosines() {
            let (c32, eta32) = (c as f32, eta as f32);
            let f = f64::from(fresnel_dielectric(c32, eta32));
            let (c, eta) = (f64::from(c32), f64::from(eta32));
            let r = dielectric_ref(c, eta);
            assert!((0.0..=1.0).contains(&f), "F({c}, {eta}) = {f}");
            // f32 and f64 may disagree on which side of the critical angle a rounded input
            // lies only within a few ulps of it
            if near_critical(c, eta, 1e-6) {
                continue;
            }
            if r == 1.0 {
                assert_eq!(f, 1.0, "total internal reflection: F({c}, {eta}) = {f}");
                tir += 1;
            } else {
                let cos_t = (1.0 - (1.0 - c * c) / (eta * eta)).sqrt();
                worst = worst.max((f - r).abs());
                assert!((f - r).abs() <= f32_tolerance(cos_t), "F({c}, {eta}) = {f}, reference {r}");
            }
        }
    }
    assert!(tir > 1000, "the grid must cover total internal reflection ({tir} points)");
    println!("dielectric: worst |F − F_ref| = {worst:.2e}");
}

#[test]
fn dielectric_limits() {
    // η = 1: no interface, no reflection (down to cos θ = 0.01: see the next test below it)
    for c in cosines().into_iter().filter(|&c| c >= 0.01) {
        let f = fresnel_dielectric(c as f32, 1.0);
        assert!(f.abs() <= 1e-6, "F({c}, 1) = {f}");
    }
    // grazing incidence reflects everything, from either side
    for eta in [0.5, 0.9, 1.01, 1.5, 3.0] {
        assert_eq!(fresnel_dielectric(0.0, eta), 1.0, "F(0, {eta})");
        let f = fresnel_dielectric(1e-4, eta);
        assert!(f > 0.99, "F(1e-4, {eta}) = {f}");
    }
    // normal incidence: ((η − 1)/(η + 1))²
    for eta in [0.5f32, 1.33, 1.5, 2.4] {
        let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
        assert!((fresnel_dielectric(1.0, eta) - f0).abs() <= 1e-7, "F(1, {eta})");
    }
    // |cos θ| is used: the sign of the cosine does not matter
    for c in [0.1f32, 0.5, 0.9] {
        assert_eq!(fresnel_dielectric(-c, 1.5), fresnel_dielectric(c, 1.5));
    }
    // total internal reflection below the critical angle from inside (η = 1/1.5)
    let critical = (1.0f64 - 1.0 / 2.25).sqrt();
    assert_eq!(fresnel_dielectric((critical - 1e-3) as f32, 1.0 / 1.5), 1.0);
    assert!(fresnel_dielectric((critical + 1e-2) as f32, 1.0 / 1.5) < 1.0);
}

/// η = 1 is documented as F = 0 (a transparent interface) for every cos θ > 0. Near grazing
/// incidence the f32 evaluation of cos²θt = 1 − (1 − cos²θi)/η² cancels catastrophically
/// (for cos θ < ~2.4e-4 it even rounds to total internal reflection, F = 1).
#[test]
fn dielectric_index_one_is_transparent_near_grazing() {
    let mut worst = (0.0f32, 0.0);
    for c in cosines().into_iter().filter(|&c| c > 0.0) {
        let f = fresnel_dielectric(c as f32, 1.0);
        if f > worst.0 {
            worst = (f, c);
        }
    }
    assert!(worst.0 <= 1e-6, "F(cos θ = {}, η = 1) = {} (should be 0)", worst.1, worst.0);
}

/// Light refracting from side 1 to side 2 at (θi, η) crosses the same interface as light
/// going back at (θt, 1/η): the reflectances (and so the transmittances 1 − F) are equal.
#[test]
fn dielectric_is_symmetric_under_refraction() {
    let mut checked = 0;
    for eta in [1.2f64, 1.5, 2.4, 1.0 / 1.5] {
        for c in cosines() {
            let sin2_t = (1.0 - c * c) / (eta * eta);
            let ct = (1.0 - sin2_t).sqrt();
            // near grazing on one side, the other side is within rounding of its critical
            // angle (f32 cannot resolve cos θt below ~√ulp = 2.4e-4)
            if sin2_t >= 1.0 || near_critical(c, eta, 1e-6) || near_critical(ct, 1.0 / eta, 1e-6) {
                continue;
            }
            let a = fresnel_dielectric(c as f32, eta as f32);
            let b = fresnel_dielectric(ct as f32, (1.0 / eta) as f32);
            // each side is evaluated in f32 with the other side's cosine as its cos θt: the
            // rounding of its sin²θt is amplified by 1/cos θt (`f32_tolerance`), and F's slope
            // near grazing (~ −2.6/η) turns it into an error of F
            let tol = 2.0 * f32_tolerance(c.min(ct)) + 1e-6 / c.min(ct);
            assert!((a - b).abs() as f64 <= tol, "F({c}, {eta}) = {a} but F({ct}, 1/{eta}) = {b}");
            assert!(((1.0 - a) - (1.0 - b)).abs() as f64 <= tol);
            checked += 1;
        }
    }
    assert!(checked > 5000);
}

/// A minimal complex number in f64.
#[derive(Clone, Copy, Debug)]
struct C64 {
    re: f64,
    im: f64,
}

impl C64 {
    fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }
    fn add(self, o: Self) -> Self {
        Self::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Self) -> Self {
        Self::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: Self) -> Self {
        Self::new(self.re * o.re - self.im * o.im, self.re * o.im + self.im * o.re)
    }
    fn div(self, o: Self) -> Self {
        let d = o.re * o.re + o.im * o.im;
        Self::new((self.re * o.re + self.im * o.im) / d, (self.im * o.re - self.re * o.im) / d)
    }
    fn norm_sq(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    /// The principal square root (Re ≥ 0).
    fn sqrt(self) -> Self {
        let r = self.norm_sq().sqrt();
        let re = (0.5 * (r + self.re)).max(0.0).sqrt();
        let im = (0.5 * (r - self.re)).max(0.0).sqrt();
        Self::new(re, if self.im < 0.0 { -im } else { im })
    }
}

/// The Fresnel equations with a complex index n = η + ik: n cos θt = √(n² − sin²θi)
/// (principal root: the transmitted wave decays into the metal),
/// rs = (cos θi − n cos θt)/(cos θi + n cos θt), rp = (n² cos θi − n cos θt)/(n² cos θi + n cos θt),
/// F = (|rs|² + |rp|²)/2.
fn conductor_ref(c: f64, eta: f64, k: f64) -> f64 {
    if c == 0.0 {
        return 1.0;
    }
    let n = C64::new(eta, k);
    let n2 = n.mul(n);
    let ci = C64::new(c, 0.0);
    let n_ct = n2.sub(C64::new(1.0 - c * c, 0.0)).sqrt();
    let rs = ci.sub(n_ct).div(ci.add(n_ct));
    let n2_ci = n2.mul(ci);
    let rp = n2_ci.sub(n_ct).div(n2_ci.add(n_ct));
    0.5 * (rs.norm_sq() + rp.norm_sq())
}

fn presets() -> [(&'static str, ComplexIor); 4] {
    [
        ("gold", ComplexIor::GOLD),
        ("copper", ComplexIor::COPPER),
        ("aluminium", ComplexIor::ALUMINIUM),
        ("silver", ComplexIor::SILVER),
    ]
}

#[test]
fn conductor_matches_complex_fresnel_equations() {
    let mut iors: Vec<(String, Vec3, Vec3)> =
        presets().iter().map(|(n, ior)| (n.to_string(), ior.eta(), ior.k())).collect();
    let mut rng = validation::rng(77);
    for i in 0..40 {
        let eta = Vec3::new(0.1, 0.1, 0.1) + 3.0 * Vec3::new(validation::uniform32(&mut rng), 0.5, 1.0);
        let k = 8.0 * Vec3::new(validation::uniform32(&mut rng), validation::uniform32(&mut rng), 0.05);
        iors.push((format!("random {i}"), eta, k));
    }
    let mut worst = 0.0f64;
    for (name, eta, k) in &iors {
        let ior = ComplexIor::new(*eta, *k).unwrap();
        for c in cosines() {
            let f = fresnel_conductor(c as f32, &ior);
            for ch in 0..3 {
                let r = conductor_ref(f64::from(c as f32), f64::from(eta[ch]), f64::from(k[ch]));
                let err = (f64::from(f[ch]) - r).abs();
                worst = worst.max(err);
                // f32 evaluation of a² + b² = √(t² + 4η²k²) and of the quotient: the bound
                // `fresnel_conductor` states
                assert!(err <= 2e-6, "{name} channel {ch}: F({c}) = {}, reference {r}", f[ch]);
            }
        }
    }
    println!("conductor: worst |F − F_ref| = {worst:.2e}");
}

/// A conductor with k = 0 is a dielectric of index η (for η > 1; for η < 1 outside total
/// internal reflection).
#[test]
fn conductor_without_extinction_is_a_dielectric() {
    for eta in [1.2f32, 1.5, 2.4, 0.8] {
        let ior = ComplexIor::new(Vec3::splat(eta), Vec3::ZERO).unwrap();
        for c in cosines() {
            if near_critical(c, f64::from(eta), 1e-3) {
                continue;
            }
            let f = fresnel_conductor(c as f32, &ior);
            let d = fresnel_dielectric(c as f32, eta);
            assert!((f - Vec3::splat(d)).abs().max_element() <= 2e-5, "η = {eta}, cos θ = {c}: {f} vs {d}");
        }
    }
}

#[test]
fn schlick_at_normal_incidence_is_f0() {
    for f0 in [Vec3::ZERO, Vec3::splat(0.04), Vec3::new(0.95, 0.64, 0.54), Vec3::ONE] {
        assert_eq!(fresnel_schlick(1.0, f0), f0);
        assert_eq!(fresnel_schlick(-1.0, f0), f0);
        assert_eq!(fresnel_schlick(0.0, f0), Vec3::ONE);
    }
}

/// The claim of `fresnel_schlick`'s documentation: its error against the exact dielectric
/// term (F0 = ((η − 1)/(η + 1))²) is below 0.01 for η ∈ [1.3, 1.7].
#[test]
fn schlick_error_matches_its_documentation() {
    const DOC_BOUND: f64 = 0.07;
    let mut worst = (0.0f64, 0.0, 0.0);
    for i in 0..=40 {
        let eta = 1.3 + 0.4 * f64::from(i) / 40.0;
        let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
        for c in cosines() {
            let s = f64::from(fresnel_schlick(c as f32, Vec3::splat(f0 as f32)).x);
            let err = (s - dielectric_ref(c, eta)).abs();
            if err > worst.0 {
                worst = (err, eta, c);
            }
        }
    }
    println!("Schlick: worst error {:.4} at η = {:.3}, cos θ = {:.4}", worst.0, worst.1, worst.2);
    assert!(
        worst.0 <= DOC_BOUND,
        "Schlick's error reaches {:.4} (η = {:.3}, cos θ = {:.4}), above the documented {DOC_BOUND}",
        worst.0,
        worst.1,
        worst.2
    );
}

#[test]
fn presets_are_physical_reflectances() {
    for (name, ior) in presets() {
        for c in cosines() {
            let f = fresnel_conductor(c as f32, &ior);
            assert!(
                f.is_finite() && f.min_element() >= 0.0 && f.max_element() <= 1.0,
                "{name}: F({c}) = {f}"
            );
        }
        let f = fresnel_conductor(1.0, &ior);
        assert!(f.min_element() > 0.3, "{name}: a metal reflects strongly at normal incidence: {f}");
        assert_eq!(fresnel_conductor(0.0, &ior), Vec3::ONE, "{name}: grazing");
    }
    let gold = fresnel_conductor(1.0, &ComplexIor::GOLD);
    assert!(gold.x > gold.y && gold.y > gold.z, "gold must be yellow (R > G > B): {gold}");
    assert!(gold.x > 0.9 && gold.z < 0.5, "gold: {gold}");
    let copper = fresnel_conductor(1.0, &ComplexIor::COPPER);
    assert!(copper.x > copper.y && copper.y > copper.z, "copper (R > G > B): {copper}");
    let silver = fresnel_conductor(1.0, &ComplexIor::SILVER);
    assert!(silver.min_element() > 0.9, "silver: {silver}");
}

#[test]
fn complex_ior_validates() {
    assert!(ComplexIor::new(Vec3::new(0.0, 1.0, 1.0), Vec3::ONE).is_err());
    assert!(ComplexIor::new(Vec3::new(f32::NAN, 1.0, 1.0), Vec3::ONE).is_err());
    assert!(ComplexIor::new(Vec3::ONE, Vec3::new(-0.1, 0.0, 0.0)).is_err());
    assert!(ComplexIor::new(Vec3::ONE, Vec3::new(f32::INFINITY, 0.0, 0.0)).is_err());
    let ior = ComplexIor::new(Vec3::splat(1.5), Vec3::splat(2.0)).unwrap();
    assert_eq!((ior.eta(), ior.k()), (Vec3::splat(1.5), Vec3::splat(2.0)));
}
