//! The dense white-furnace check of the compensated glass: at a grid of (μ, α, η, side) between
//! the tables' nodes, the albedo of the compensated lobe, E_ss + g_R + c ΔT' (the
//! single-scattering albedo by quadrature, exact for the exact single-scattering lobe; the added
//! lobes integrate exactly to the energies they restore, `tests/compensated_glass.rs`), against
//! 1, the albedo of a non-absorbing interface; beside it the loss table's error alone and the
//! walk tables' ΔR + ΔT in its place. Then how often the cap ΔT' = min(ΔT, D) binds at the loss
//! grid's nodes.

use crate::dielectric::dielectric_albedo;
use crate::dielectric_loss::{NODES, SHAPE, node_parameters};
use crate::quadrature::Family;
use crate::{DIELECTRIC_PANELS, Side, par_map, range_of};
use microsurface::compensation::{DielectricLossTable, DielectricWalkTable};
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
    /// 1 − R − T as the loss table interpolates it.
    pub loss: f64,
    /// g_R + c ΔT' as the compensated lobe restores them.
    pub added: f64,
}

impl FurnacePoint {
    /// The compensated albedo minus 1.
    pub fn error(&self) -> f64 {
        self.single + self.added - 1.0
    }
}

fn added(family: Family, side: Side, mu: f64, alpha: f64, eta: f64) -> (f64, f64, f64) {
    let material = Dielectric::new(eta as f32).expect("η in range");
    let side_of = match side {
        Side::Outside => microsurface::research::Side::Outside,
        Side::Inside => microsurface::research::Side::Inside,
    };
    let seen = if side == Side::Outside { eta } else { 1.0 / eta };
    let (lobes, table, loss) = match family {
        Family::Ggx => (
            Compensated::new(Ggx::isotropic(alpha as f32).expect("α"), material)
                .expect("in range")
                .higher_orders(mu as f32, side_of),
            DielectricWalkTable::GGX,
            DielectricLossTable::GGX,
        ),
        Family::Beckmann => (
            Compensated::new(Beckmann::isotropic(alpha as f32).expect("α"), material)
                .expect("in range")
                .higher_orders(mu as f32, side_of),
            DielectricWalkTable::BECKMANN,
            DielectricLossTable::BECKMANN,
        ),
    };
    let (r, t) = lobes.expect("μ in [0, 1]");
    let raw = table.energy(mu as f32, alpha as f32, seen as f32).expect("in range");
    let loss = loss.loss(mu as f32, alpha as f32, seen as f32).expect("in range");
    (f64::from(r + t), f64::from(raw.reflected + raw.transmitted), f64::from(loss))
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
        let (lobes, raw, loss) = added(family, side, mu, alpha, eta);
        FurnacePoint { family, side, mu, alpha, eta, single: r + t, raw, loss, added: lobes }
    });
    let mut sorted: Vec<&FurnacePoint> = out.iter().collect();
    sorted.sort_by(|a, b| b.error().abs().total_cmp(&a.error().abs()));
    for p in sorted.iter().take(25) {
        println!(
            "  {} {} μ {:.3} α {:.2} η {:.2}: albedo − 1 = {:+.4} (E_ss {:.4}, loss table {:+.4}, walk tables \
             {:+.4})",
            p.family.name(),
            p.side.name(),
            p.mu,
            p.alpha,
            p.eta,
            p.error(),
            p.single,
            p.single + p.loss - 1.0,
            p.single + p.raw - 1.0,
        );
    }
    let stats = |of: &[&FurnacePoint], e: &dyn Fn(&FurnacePoint) -> f64| {
        let max = of.iter().map(|p| e(p).abs()).fold(0.0, f64::max);
        let rms = (of.iter().map(|p| e(p) * e(p)).sum::<f64>() / of.len() as f64).sqrt();
        (max, rms)
    };
    for family in [Family::Ggx, Family::Beckmann] {
        for side in [None, Some(Side::Outside), Some(Side::Inside)] {
            let of: Vec<&FurnacePoint> =
                out.iter().filter(|p| p.family == family && side.is_none_or(|s| p.side == s)).collect();
            let (max, rms) = stats(&of, &|p| p.error());
            let (loss, _) = stats(&of, &|p| p.single + p.loss - 1.0);
            let (raw, raw_rms) = stats(&of, &|p| p.single + p.raw - 1.0);
            println!(
                "{} {}: white furnace |albedo − 1| max {max:.2e}, RMS {rms:.2e} ({} points; the loss table \
                 alone: max {loss:.2e}; the walk tables' ΔR + ΔT instead: max {raw:.2e}, RMS {raw_rms:.2e})",
                family.name(),
                side.map_or("both sides", Side::name),
                of.len()
            );
        }
    }
    cap();
    out
}

/// How often the cap ΔT' = min(ΔT, D) binds: at the loss grid's nodes, the walk tables' ΔT
/// interpolated there against the loss table's D (both as the crate's lookups read them).
fn cap() {
    for family in [Family::Ggx, Family::Beckmann] {
        let (walk, loss) = match family {
            Family::Ggx => (DielectricWalkTable::GGX, DielectricLossTable::GGX),
            Family::Beckmann => (DielectricWalkTable::BECKMANN, DielectricLossTable::BECKMANN),
        };
        for side in [Side::Outside, Side::Inside] {
            let d = loss.nodes(range_of(side));
            let (mut capped, mut worst, mut at) = (0, 0.0f32, (0.0, 0.0, 0.0));
            for (k, &dk) in d.iter().enumerate().take(NODES) {
                let (i, j, l) = (k % SHAPE[0], (k / SHAPE[0]) % SHAPE[1], k / (SHAPE[0] * SHAPE[1]));
                let (mu, alpha, eta) = node_parameters(i, j, l, side);
                let dt = walk.energy(mu as f32, alpha as f32, eta as f32).expect("in range").transmitted;
                if dt > dk.max(0.0) {
                    capped += 1;
                    if dt - dk > worst {
                        worst = dt - dk;
                        at = (mu, alpha, eta);
                    }
                }
            }
            println!(
                "{} {}: the cap ΔT' = min(ΔT, D) binds at {capped} of {NODES} loss nodes ({:.1} %), by at most \
                 {worst:.2e} (μ {:.3e} α {:.3} η {:.3})",
                family.name(),
                side.name(),
                100.0 * capped as f64 / NODES as f64,
                at.0,
                at.1,
                at.2
            );
        }
    }
}
