//! The bounded cap (Eto and Tokuyoshi 2023) against the spherical cap (Dupuy and Benyoub 2023)
//! for GGX reflection off a perfect mirror (F = 1): per roughness and view angle, the share of
//! samples that reflect below the horizon, the variance of the sample weight f·cos/pdf among
//! the reflections that leave, and the variance of the one-sample albedo estimate (the weight,
//! 0 for a refused sample), with the ratio bounded/spherical of the latter (the variance ratio
//! at equal sample count; at equal time multiply by the cost ratio of the samplers from
//! `benches/vndf.rs`).
//!
//! Both samplers go through the same code here: ωm from the sampler, ωo = reflect(ωi, ωm), the
//! weight f·cos θo/pdf with f·cos θo from `SingleScattering::eval` and the reflection density
//! pdf_vndf(ωm)/(4 ωi·ωm) of the sampler's own density. Rows: α ∈ {0.05, 0.1, 0.2, 0.5, 1}
//! isotropic and αx = 1, αy = 0.25 (view azimuth 0.7 rad); columns θo ∈ {0°, 30°, 60°, 80°, 89°}.
//!
//! `cargo run --release -p lab --bin bounded_vndf -- [--samples N]` (default 1 000 000 per cell,
//! a fixed seed); prints a Markdown table.

use glam::Vec3;
use microsurface::research::SingleScattering;
use microsurface::vndf::{GgxBoundedCap, GgxSphericalCap, VisibleNormalSampler};
use microsurface::{Conductor, Ggx};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// The statistics of one sampler at one configuration.
#[derive(Debug, Clone, Copy, Default)]
struct Stats {
    n: usize,
    accepted: usize,
    sum: f64,
    sum_sq: f64,
}

impl Stats {
    fn add(&mut self, w: Option<f64>) {
        self.n += 1;
        if let Some(w) = w {
            self.accepted += 1;
            self.sum += w;
            self.sum_sq += w * w;
        }
    }

    /// The albedo estimate (mean weight, refusals as 0).
    fn mean(&self) -> f64 {
        self.sum / self.n as f64
    }

    /// The variance of the one-sample albedo estimate.
    fn estimate_variance(&self) -> f64 {
        self.sum_sq / self.n as f64 - self.mean().powi(2)
    }

    /// The variance of the weight among the samples that leave.
    fn weight_variance(&self) -> f64 {
        let a = self.accepted.max(1) as f64;
        (self.sum_sq / a - (self.sum / a).powi(2)).max(0.0)
    }

    fn refused(&self) -> f64 {
        1.0 - self.accepted as f64 / self.n as f64
    }
}

fn weight<V: VisibleNormalSampler>(
    sampler: &V,
    model: &SingleScattering<Ggx, Conductor>,
    wi: Vec3,
    u: [f32; 3],
    rng: &mut Pcg64Mcg,
) -> Option<f64> {
    let wm = sampler.sample(wi, u);
    let c = wi.dot(wm);
    let wo = (2.0 * c * wm - wi).normalize();
    if wo.z <= 0.0 {
        return None;
    }
    let pdf = f64::from(sampler.pdf(wi, wm)) / (4.0 * f64::from(c));
    let f_cos = f64::from(model.eval(wi, wo, rng).x);
    (pdf > 0.0).then(|| f_cos / pdf)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let mut samples = 1_000_000usize;
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--samples" => samples = args.next().and_then(|v| v.parse().ok()).expect("--samples N"),
            other => panic!("unknown argument {other}; usage: bounded_vndf [--samples N]"),
        }
    }
    let rows: [(f32, f32); 6] = [(0.05, 0.05), (0.1, 0.1), (0.2, 0.2), (0.5, 0.5), (1.0, 1.0), (1.0, 0.25)];
    let thetas_deg = [0.0f32, 30.0, 60.0, 80.0, 89.0];
    let phi = 0.7f32;
    println!("GGX reflection, F = 1, {samples} samples per cell: spherical cap (S) against bounded cap (B)");
    println!();
    println!(
        "| α | θo | refused S | refused B | Var w S | Var w B | Var est S | Var est B | B/S est | albedo S | albedo B |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let mut rng = Pcg64Mcg::seed_from_u64(2023);
    for (ax, ay) in rows {
        let ggx = Ggx::new(ax, ay).expect("valid roughness");
        let model = SingleScattering::new(ggx, Conductor::perfect());
        let (cap, bounded) = (GgxSphericalCap(ggx), GgxBoundedCap(ggx));
        for theta_deg in thetas_deg {
            let t = theta_deg.to_radians();
            let wi = Vec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos()).normalize();
            let (mut s, mut b) = (Stats::default(), Stats::default());
            for _ in 0..samples {
                // the same uniforms for both samplers
                let u = [rng.random::<f32>(), rng.random::<f32>(), 0.0];
                s.add(weight(&cap, &model, wi, u, &mut rng));
                b.add(weight(&bounded, &model, wi, u, &mut rng));
            }
            let alpha = if ax == ay { format!("{ax}") } else { format!("({ax}, {ay})") };
            println!(
                "| {alpha} | {theta_deg}° | {:.4} | {:.4} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:.3} | {:.4} | {:.4} |",
                s.refused(),
                b.refused(),
                s.weight_variance(),
                b.weight_variance(),
                s.estimate_variance(),
                b.estimate_variance(),
                b.estimate_variance() / s.estimate_variance(),
                s.mean(),
                b.mean(),
            );
        }
    }
}
