//! The dense white-furnace check of the compensated glass: at a grid of (μ, α, η, side) between
//! the tables' nodes, the albedo of the compensated lobe, E_ss + ΔR + c ΔT (the single-scattering
//! albedo by quadrature, exact for the exact single-scattering lobe; the added lobes integrate
//! exactly to the energies they restore), against 1, the albedo of a non-absorbing interface.

use crate::dielectric::dielectric_albedo;
use crate::quadrature::Family;
use crate::{DIELECTRIC_PANELS, Side, par_map};
use microsurface::compensation::DielectricWalkTable;
use microsurface::{Beckmann, Compensated, Dielectric, Ggx};

/// The roughnesses, indices (seen from outside; 1/η from inside) and view cosines of the check.
pub const ALPHAS: [f64; 9] = [0.02, 0.05, 0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0];
pub const ETAS: [f64; 6] = [1.05, 1.2, 1.33, 1.5, 2.0, 2.6];
pub const MUS: [f64; 10] = [0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.35, 0.55, 0.8, 1.0];

/// One point of the check.
#[derive(Debug, Clone, Copy)]
pub struct FurnacePoint {
    pub family: Family,
    pub side: Side,
    pub mu: f64,
    pub alpha: f64,
    pub eta: f64,
    /// E_ss by quadrature.
    pub single: f64,
    /// ΔR + ΔT as the walk tables interpolate them.
    pub raw: f64,
    /// ΔR + c ΔT as the compensated lobe restores them.
    pub added: f64,
}

impl FurnacePoint {
    /// The compensated albedo minus 1.
    pub fn error(&self) -> f64 {
        self.single + self.added - 1.0
    }
}

fn added(family: Family, side: Side, mu: f64, alpha: f64, eta: f64) -> (f64, f64) {
    let material = Dielectric::new(eta as f32).expect("η in range");
    let side_of = match side {
        Side::Outside => microsurface::research::Side::Outside,
        Side::Inside => microsurface::research::Side::Inside,
    };
    let seen = if side == Side::Outside { eta } else { 1.0 / eta };
    let (lobes, table) = match family {
        Family::Ggx => (
            Compensated::new(Ggx::isotropic(alpha as f32).expect("α"), material)
                .expect("in range")
                .higher_orders(mu as f32, side_of),
            DielectricWalkTable::GGX,
        ),
        Family::Beckmann => (
            Compensated::new(Beckmann::isotropic(alpha as f32).expect("α"), material)
                .expect("in range")
                .higher_orders(mu as f32, side_of),
            DielectricWalkTable::BECKMANN,
        ),
    };
    let (r, t) = lobes.expect("μ in [0, 1]");
    let raw = table.energy(mu as f32, alpha as f32, seen as f32).expect("in range");
    (f64::from(r + t), f64::from(raw.reflected + raw.transmitted))
}

/// Runs the check over the grid.
pub fn run() -> Vec<FurnacePoint> {
    let mut points = Vec::new();
    for family in [Family::Ggx, Family::Beckmann] {
        for side in [Side::Outside, Side::Inside] {
            for &alpha in &ALPHAS {
                for &eta in &ETAS {
                    for &mu in &MUS {
                        points.push((family, side, mu, alpha, eta));
                    }
                }
            }
        }
    }
    let out = par_map(points.len(), "glass furnace", |k| {
        let (family, side, mu, alpha, eta) = points[k];
        let (mu, alpha, eta) = (f64::from(mu as f32), f64::from(alpha as f32), f64::from(eta as f32));
        let seen = if side == Side::Outside { eta } else { 1.0 / eta };
        let (r, t) = dielectric_albedo(family, mu, alpha, seen, DIELECTRIC_PANELS);
        let (lobes, raw) = added(family, side, mu, alpha, eta);
        FurnacePoint { family, side, mu, alpha, eta, single: r + t, raw, added: lobes }
    });
    let mut sorted: Vec<&FurnacePoint> = out.iter().collect();
    sorted.sort_by(|a, b| b.error().abs().total_cmp(&a.error().abs()));
    for p in sorted.iter().take(25) {
        println!(
            "  {} {} μ {:.3} α {:.2} η {:.2}: albedo − 1 = {:+.4} (E_ss {:.4}, walk tables {:+.4}, lobes {:+.4})",
            p.family.name(),
            p.side.name(),
            p.mu,
            p.alpha,
            p.eta,
            p.error(),
            p.single,
            p.single + p.raw - 1.0,
            p.added - p.raw
        );
    }
    for family in [Family::Ggx, Family::Beckmann] {
        for side in [Side::Outside, Side::Inside] {
            let of: Vec<&FurnacePoint> =
                out.iter().filter(|p| p.family == family && p.side == side).collect();
            let max = of.iter().map(|p| p.error().abs()).fold(0.0, f64::max);
            let raw = of.iter().map(|p| (p.single + p.raw - 1.0).abs()).fold(0.0, f64::max);
            let rms = (of.iter().map(|p| p.error() * p.error()).sum::<f64>() / of.len() as f64).sqrt();
            println!(
                "{} {}: white furnace |albedo − 1| max {max:.2e}, RMS {rms:.2e} ({} points; the walk tables \
                 alone, before the reciprocity factors: max {raw:.2e})",
                family.name(),
                side.name(),
                of.len()
            );
        }
    }
    out
}
