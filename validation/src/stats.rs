//! The statistical assertions: seeded generators, standard-error tests (mean within z·SE,
//! SE small enough to mean something), Šidák-corrected significance, and helpers to draw
//! directions and run cases on both cores.

use rand::SeedableRng;
use statrs::distribution::{ContinuousCDF, Normal};

/// The generator of every statistical test: PCG with a fixed seed.
pub type TestRng = rand_pcg::Pcg64Mcg;

/// A seeded PCG generator.
pub fn rng(seed: u64) -> TestRng {
    TestRng::seed_from_u64(seed)
}

/// A uniform f64 in [0, 1).
pub fn uniform64(rng: &mut TestRng) -> f64 {
    rand::RngExt::random::<f64>(rng)
}

/// A uniform f32 in [0, 1).
pub fn uniform32(rng: &mut TestRng) -> f32 {
    rand::RngExt::random::<f32>(rng)
}

/// The per-test significance that keeps the family-wise level `family_alpha` over `m` tests
/// (Šidák): 1 − (1 − α)^{1/m}.
pub fn sidak(family_alpha: f64, m: usize) -> f64 {
    1.0 - (1.0 - family_alpha).powf(1.0 / m as f64)
}

/// The two-sided standard-normal critical value for significance `alpha`.
pub fn z_two_sided(alpha: f64) -> f64 {
    Normal::new(0.0, 1.0).unwrap().inverse_cdf(1.0 - 0.5 * alpha)
}

/// The z of a family of `m` two-sided tests at family-wise significance `family_alpha`.
pub fn family_z(family_alpha: f64, m: usize) -> f64 {
    z_two_sided(sidak(family_alpha, m))
}

/// Running mean and variance (Welford, f64).
#[derive(Debug, Clone, Copy, Default)]
pub struct Stats {
    pub n: u64,
    mean: f64,
    m2: f64,
}

impl Stats {
    pub fn push(&mut self, x: f64) {
        self.n += 1;
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (x - self.mean);
    }

    pub fn mean(&self) -> f64 {
        self.mean
    }

    /// Sample standard deviation σ̂.
    pub fn std(&self) -> f64 {
        if self.n < 2 { 0.0 } else { (self.m2 / (self.n - 1) as f64).sqrt() }
    }

    /// Standard error σ̂/√N.
    pub fn se(&self) -> f64 {
        self.std() / (self.n as f64).sqrt()
    }
}

/// Asserts |mean − expected| ≤ z·SE + `exact_tol` and SE ≤ `max_se` (so that the test can fail).
///
/// `exact_tol` covers the deterministic error of `expected` itself (e.g. an f32 analytic
/// value or a quadrature), never the statistical error. Prints N, mean, σ̂, SE and z on failure.
pub fn assert_mean(label: &str, stats: &Stats, expected: f64, z: f64, max_se: f64, exact_tol: f64) {
    let se = stats.se();
    assert!(
        se <= max_se,
        "{label}: standard error {se:.3e} > {max_se:.1e}: the test would be meaningless \
         (N = {}, mean = {:.6e}, σ̂ = {:.3e})",
        stats.n,
        stats.mean(),
        stats.std()
    );
    let diff = (stats.mean() - expected).abs();
    assert!(
        diff <= z * se + exact_tol,
        "{label}: |mean − expected| = {diff:.3e} > z·SE + tol = {z:.2} × {se:.3e} + {exact_tol:.1e} \
         (N = {}, mean = {:.6e}, expected = {expected:.6e}, σ̂ = {:.3e})",
        stats.n,
        stats.mean(),
        stats.std()
    );
}

/// Asserts that a sampler refuses (returns nothing) as often as its density says: the refusal
/// rate failures/N is binomial with p = 1 − `mass`, so |failures/N − p| ≤ z·√(p(1 − p)/N) +
/// `mass_tol`, where `mass` = ∫pdf comes from a quadrature whose deterministic error is
/// `mass_tol` (never the statistical error). Prints N, the rate, p, SE and z on failure.
pub fn assert_refusal_rate(label: &str, failures: usize, n: usize, mass: f64, mass_tol: f64, z: f64) {
    let p_none = (1.0 - mass).clamp(0.0, 1.0);
    let se = (p_none * (1.0 - p_none) / n as f64).sqrt();
    let frac = failures as f64 / n as f64;
    assert!(
        (frac - p_none).abs() <= z * se + mass_tol,
        "{label}: sample refused {frac:.5} of the time, 1 − ∫pdf = {p_none:.5} \
         (N = {n}, SE = {se:.2e}, z = {z:.2}, quadrature tolerance {mass_tol:.1e})"
    );
}

/// Asserts that two independent estimates agree: |m1 − m2| ≤ z·√(SE1² + SE2²), and that the
/// combined SE is at most `max_se`.
pub fn assert_two_sample(label: &str, a: &Stats, b: &Stats, z: f64, max_se: f64) {
    let se = (a.se().powi(2) + b.se().powi(2)).sqrt();
    assert!(se <= max_se, "{label}: combined SE {se:.3e} > {max_se:.1e} (N = {}, {})", a.n, b.n);
    let diff = (a.mean() - b.mean()).abs();
    assert!(
        diff <= z * se,
        "{label}: |m1 − m2| = {diff:.3e} > z·SE = {z:.2} × {se:.3e} \
         (N1 = {}, m1 = {:.6e}, σ̂1 = {:.3e}; N2 = {}, m2 = {:.6e}, σ̂2 = {:.3e})",
        a.n,
        a.mean(),
        a.std(),
        b.n,
        b.mean(),
        b.std()
    );
}

/// A uniform direction on the sphere (f64 arithmetic, rounded to f32): z = 2u₁ − 1,
/// φ = 2πu₂.
pub fn uniform_sphere(rng: &mut TestRng) -> glam::Vec3 {
    let z = 2.0 * uniform64(rng) - 1.0;
    let phi = std::f64::consts::TAU * uniform64(rng);
    let s = (1.0 - z * z).max(0.0).sqrt();
    glam::DVec3::new(s * phi.cos(), s * phi.sin(), z).as_vec3()
}

/// A unit direction from spherical angles.
pub fn dir(theta: f64, phi: f64) -> glam::Vec3 {
    glam::Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32)
}

/// Maps `f` over `items` on two threads (the machine's cores), results in input order. A
/// panic in `f` fails the test (the scope re-raises it).
pub fn par_map<T: Sync, R: Send>(items: &[T], f: impl Fn(usize, &T) -> R + Sync) -> Vec<R> {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};
    let next = AtomicUsize::new(0);
    let out: Mutex<Vec<Option<R>>> = Mutex::new((0..items.len()).map(|_| None).collect());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= items.len() {
                        break;
                    }
                    let r = f(i, &items[i]);
                    out.lock().unwrap()[i] = Some(r);
                }
            });
        }
    });
    out.into_inner().unwrap().into_iter().map(Option::unwrap).collect()
}
