//! How close candidate MIS densities of the stochastic techniques are to the distribution the
//! random walk actually samples: for each configuration, N walk samples of `MicrofacetBsdf`
//! (random-walk technique) are binned on 16 × 32 equal-area cells of the sphere, and each
//! candidate density q, normalized over the cells (MIS needs its shape only), is integrated
//! per cell (adaptive Gauss–Legendre). Printed: the χ² distance Σ (p̂ − q)²/q (1 + it is the
//! second moment Σ p̂²/q, the variance factor of q as an importance density for what the walk
//! samples; its sampling-noise floor is about (cells − 1)/N) and KL(p̂ ‖ q).
//!
//! Candidates: `phase+cos` the research layer's approximate density (`PositionFree::pdf`:
//! 0.8 × the single-bounce phase density + 0.2 × a cosine lobe), which dielectrics keep as
//! `Bsdf::pdf`; `Bsdf::pdf` the stochastic techniques' density of `MicrofacetBsdf`; for
//! conductors (F = 1, whose walk exits with the density f·cos of the energy-conserving
//! model): `kulla-conty` the F = 1 Kulla–Conty BRDF × cos (`Compensated` conductor, which
//! integrates to 1; `Bsdf::pdf` is this density for tabulated conductors), `per-order` the
//! per-order lobe, `mixture` the compensated conductor's sampling density; for glass
//! (non-absorbing): the Kulla–Conty dielectric's f·|cos| and its mixture density.
//!
//! `cargo run --release -p lab --bin mis_density -- [--samples N]` (default 200 000 per
//! configuration, fixed seeds).

use glam::{Vec2, Vec3};
use microsurface::research::{PositionFree, Shadowing};
use microsurface::{Bsdf, Compensated, Compensation, Conductor, Dielectric, Ggx, MicrofacetBsdf};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

const NZ: usize = 16;
const NPHI: usize = 32;

fn cell_of(w: Vec3) -> usize {
    let z = f64::from(w.z).clamp(-1.0, 1.0);
    let iz = (((z + 1.0) / 2.0 * NZ as f64) as usize).min(NZ - 1);
    let phi = f64::from(w.y).atan2(f64::from(w.x)).rem_euclid(std::f64::consts::TAU);
    let ip = ((phi / std::f64::consts::TAU * NPHI as f64) as usize).min(NPHI - 1);
    iz * NPHI + ip
}

/// The masses of a density over the cells, normalized to 1.
fn masses(q: &dyn Fn(Vec3) -> f64) -> Vec<f64> {
    let mut f = |z: f64, phi: f64| {
        let s = (1.0 - z * z).max(0.0).sqrt();
        q(Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32))
    };
    let mut m = vec![0.0; NZ * NPHI];
    for iz in 0..NZ {
        let (z0, z1) = (-1.0 + 2.0 * iz as f64 / NZ as f64, -1.0 + 2.0 * (iz + 1) as f64 / NZ as f64);
        for ip in 0..NPHI {
            let tau = std::f64::consts::TAU;
            let (p0, p1) = (tau * ip as f64 / NPHI as f64, tau * (ip + 1) as f64 / NPHI as f64);
            m[iz * NPHI + ip] = validation::quadrature::integrate(&mut f, z0, z1, p0, p1, 1e-7, 5).max(0.0);
        }
    }
    let total: f64 = m.iter().sum();
    m.iter().map(|x| x / total).collect()
}

/// (χ² distance, KL) of the empirical distribution `p` from `q`.
fn distances(p: &[f64], q: &[f64]) -> (f64, f64) {
    let (mut chi2, mut kl) = (0.0, 0.0);
    for (&a, &b) in p.iter().zip(q) {
        if b > 0.0 {
            chi2 += (a - b).powi(2) / b;
            if a > 0.0 {
                kl += a * (a / b).ln();
            }
        } else if a > 0.0 {
            chi2 = f64::INFINITY;
            kl = f64::INFINITY;
        }
    }
    (chi2, kl)
}

fn histogram(walk: &dyn Bsdf, wo: Vec3, n: usize, seed: u64) -> (Vec<f64>, usize) {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut h = vec![0.0; NZ * NPHI];
    let mut got = 0;
    for _ in 0..n {
        let (uc, u) = (rng.random::<f32>(), Vec2::new(rng.random(), rng.random()));
        if let Some(s) = walk.sample(wo, uc, u) {
            h[cell_of(s.wi)] += 1.0;
            got += 1;
        }
    }
    (h.iter().map(|x| x / got.max(1) as f64).collect(), got)
}

fn report(
    label: &str,
    walk: &dyn Bsdf,
    wo: Vec3,
    n: usize,
    seed: u64,
    candidates: &[(&str, &dyn Fn(Vec3) -> f64)],
) {
    let (p, got) = histogram(walk, wo, n, seed);
    let occupied = p.iter().filter(|&&x| x > 0.0).count();
    print!("| {label} | {:.1e} |", (occupied.max(1) - 1) as f64 / got as f64);
    for (_, q) in candidates {
        let (chi2, kl) = distances(&p, &masses(q));
        print!(" {chi2:.3e} / {kl:.3e} |");
    }
    println!();
}

fn main() {
    let mut args = std::env::args().skip(1);
    let mut n = 200_000usize;
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--samples" => n = args.next().and_then(|v| v.parse().ok()).expect("--samples N"),
            other => panic!("unknown argument {other}; usage: mis_density [--samples N]"),
        }
    }
    let thetas = [0.0f32, 45.0, 75.0];
    println!(
        "χ² distance / KL of each density from the walk's sampled directions ({n} samples, 16 × 32 cells)"
    );
    println!();
    println!("| conductor F = 1 | noise floor | phase+cos | Bsdf::pdf | kulla-conty | per-order | mixture |");
    println!("|---|---|---|---|---|---|---|");
    let mut seed = 1;
    for alpha in [0.2f32, 0.5, 1.0] {
        let ggx = Ggx::isotropic(alpha).expect("valid α");
        let walk = MicrofacetBsdf::new(ggx, Conductor::perfect()).expect("α ≤ 10");
        let kc =
            Compensated::with_scheme(ggx, Conductor::perfect(), Compensation::KullaConty).expect("α ≤ 1");
        let po = Compensated::with_scheme(ggx, Conductor::perfect(), Compensation::Walk).expect("α ≤ 1");
        let research = PositionFree::new(ggx, Conductor::perfect(), Shadowing::Correlated);
        for t in thetas {
            let r = t.to_radians();
            let wo = Vec3::new(r.sin(), 0.0, r.cos());
            let old = |w: Vec3| f64::from(research.pdf(wo, w));
            let today = |w: Vec3| f64::from(walk.pdf(wo, w));
            let kc_f = |w: Vec3| f64::from(kc.eval(wo, w).f.x * w.z.abs());
            let po_f = |w: Vec3| f64::from(po.eval(wo, w).f.x * w.z.abs());
            let mix = |w: Vec3| f64::from(kc.pdf(wo, w));
            seed += 1;
            report(
                &format!("GGX α = {alpha}, θo = {t}°"),
                &walk,
                wo,
                n,
                seed,
                &[
                    ("phase+cos", &old),
                    ("Bsdf::pdf", &today),
                    ("kulla-conty", &kc_f),
                    ("per-order", &po_f),
                    ("mixture", &mix),
                ],
            );
        }
    }
    println!();
    println!("| glass η = 1.5 | noise floor | phase+cos = Bsdf::pdf | kulla-conty | mixture |");
    println!("|---|---|---|---|---|");
    for alpha in [0.2f32, 0.5, 1.0] {
        let ggx = Ggx::isotropic(alpha).expect("valid α");
        let glass = Dielectric::new(1.5).expect("valid η");
        let walk = MicrofacetBsdf::new(ggx, glass).expect("α ≤ 10");
        let kc = Compensated::with_scheme(ggx, glass, Compensation::Walk).expect("tabulated η");
        for t in thetas {
            let r = t.to_radians();
            let wo = Vec3::new(r.sin(), 0.0, r.cos());
            let today = |w: Vec3| f64::from(walk.pdf(wo, w));
            let kc_f = |w: Vec3| f64::from(kc.eval(wo, w).f.x * w.z.abs());
            let mix = |w: Vec3| f64::from(kc.pdf(wo, w));
            seed += 1;
            report(
                &format!("GGX α = {alpha}, θo = {t}°"),
                &walk,
                wo,
                n,
                seed,
                &[("phase+cos", &today), ("kulla-conty", &kc_f), ("mixture", &mix)],
            );
        }
    }
}
