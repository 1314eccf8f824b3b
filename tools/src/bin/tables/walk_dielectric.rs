//! The higher-order energies of dielectric microsurfaces from the exact random walk (Heitz et
//! al. 2016, supplement §3.4): ΔR(μ, α, η) and ΔT(μ, α, η), the flux the walk reflects and
//! transmits after two or more bounces, for light from outside (η) and from inside (1/η), GGX
//! and Beckmann, on the nodes of the single-scattering dielectric tables (16³ per side).
//!
//! Each cell is the mean of indicator variables over walks from its own seeded stream (the
//! walk's weight is 1 for a dielectric: importance transport, flux): 1 if the walk left after
//! ≥ 2 bounces on the incident side (ΔR) or on the other side (ΔT). Batches of
//! [`BATCH`] walks are added until both standard errors √(p̂(1 − p̂)/N) are at most
//! [`TARGET_SE`] (at most [`MAX_BATCHES`], where √(¼/N) < [`TARGET_SE`] holds for every p):
//! the stopping rule depends only on the cell's stream, so the tables are reproduced bit for
//! bit whatever the number of threads. The batch count is shipped with the values, so the
//! standard error of every cell is known.
//!
//! Rows without walks: α → 0 (r = 0) is the smooth limit, ΔR = ΔT = 0; η = 1 (u = 0) is the
//! index-matched limit, where Fresnel vanishes (ΔR = 0) and the walk's total R + T = 1 makes
//! ΔT = 1 − T_ss exactly (T_ss by the single-scattering tables' quadrature, within 1e-5); the
//! walk itself would cross a nearly index-matched interface about Λ(ωi) times at grazing
//! incidence (10⁴–10⁶ bounces). The direction node x = 0 (μ = 0, a ray on the horizon, which
//! no walk can start) is estimated at μ = [`MU_HORIZON`].

use crate::Side;
use crate::par_map;
use crate::quadrature::Family;
use microsurface::glam::Vec3;
use microsurface::rand::SeedableRng;
use microsurface::research::{Microsurface, UniformHeight};
use microsurface::{Beckmann, Dielectric, Ggx};
use std::fmt::Write as _;

/// Nodes per axis (as the single-scattering dielectric tables).
pub const ND: usize = microsurface::compensation::DIELECTRIC_TABLE_SIZE;
/// Nodes per table.
pub const NODES: usize = ND * ND * ND;
/// Walks per batch.
pub const BATCH: u32 = 4096;
/// The largest batch count; √(¼/(32 · 4096)) = 1.4e-3.
pub const MAX_BATCHES: u32 = 32;
/// The standard error every cell reaches.
pub const TARGET_SE: f64 = 2e-3;
/// The cosine at which the horizon node x = 0 is estimated.
pub const MU_HORIZON: f64 = 1e-7;
/// Cells `--quick` recomputes per family and side (each one batch, within the combined SE).
const QUICK_WALK_CELLS: usize = 4;

/// μ of direction coordinate x at roughness α (as the single-scattering tables').
fn mu_of(x: f64, alpha: f64) -> f64 {
    let big_x = x * x;
    if big_x >= 1.0 { 1.0 } else { big_x * alpha / (1.0 + alpha - big_x) }
}

/// (μ, α, η ≥ 1) of node k = (l·ND + j)·ND + i.
fn node_parameters(k: usize) -> (f64, f64, f64) {
    let (i, j, l) = (k % ND, (k / ND) % ND, k / (ND * ND));
    let last = (ND - 1) as f64;
    let r = j as f64 / last;
    let alpha = r * r;
    let u = l as f64 / last;
    let mu = if i == 0 { MU_HORIZON } else { mu_of(i as f64 / last, alpha.max(1e-6)) };
    (mu, alpha, 1.0 + 2.0 * u * u)
}

/// The walk estimate of one cell: ΔR, ΔT and the number of walks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    pub reflected: f64,
    pub transmitted: f64,
    pub walks: u32,
}

impl Cell {
    /// The standard errors √(p̂(1 − p̂)/N) of ΔR and ΔT (0 for a cell without walks).
    pub fn standard_errors(&self) -> (f64, f64) {
        let n = f64::from(self.walks.max(1));
        let se = |p: f64| if self.walks == 0 { 0.0 } else { (p * (1.0 - p) / n).sqrt() };
        (se(self.reflected), se(self.transmitted))
    }
}

/// The seed of batch b of cell k (family, side): one splitmix64 stream per batch.
fn seed(family: Family, side: Side, k: usize, batch: u32, salt: u64) -> u64 {
    let mut z =
        salt ^ ((family as u64) << 62) ^ ((side as u64) << 61) ^ ((k as u64) << 20) ^ u64::from(batch);
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Counts of (order ≥ 2 reflected, order ≥ 2 transmitted) in `n` walks from ωi at (μ, α, η).
fn walk_counts(family: Family, side: Side, mu: f64, alpha: f64, eta: f64, n: u32, seed: u64) -> (u32, u32) {
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    let z = if side == Side::Outside { mu } else { -mu };
    let wi = Vec3::new(s as f32, 0.0, z as f32).normalize();
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    let material = Dielectric::new(eta as f32).expect("η in [1, 3]");
    let mut count = |sample: &mut dyn FnMut(&mut rand_pcg::Pcg64Mcg) -> Option<(Vec3, u32)>| {
        let (mut r, mut t) = (0, 0);
        for _ in 0..n {
            // a walk that reached the bounce cap (`None`) lost its energy: counts as neither
            if let Some((wo, bounces)) = sample(&mut rng)
                && bounces >= 2
            {
                if (wo.z > 0.0) == (wi.z > 0.0) {
                    r += 1;
                } else {
                    t += 1;
                }
            }
        }
        (r, t)
    };
    match family {
        Family::Ggx => {
            let m = Microsurface::new(UniformHeight, Ggx::isotropic(alpha as f32).expect("α > 0"), material);
            count(&mut |rng| m.sample(wi, rng).map(|w| (w.wo, w.bounces)))
        }
        Family::Beckmann => {
            let m =
                Microsurface::new(UniformHeight, Beckmann::isotropic(alpha as f32).expect("α > 0"), material);
            count(&mut |rng| m.sample(wi, rng).map(|w| (w.wo, w.bounces)))
        }
    }
}

/// The single-scattering T at (μ, α) and η = 1 (the same from either side), by the
/// single-scattering tables' quadrature: the η = 1 row's complement.
fn single_transmitted(family: Family, mu: f64, alpha: f64) -> f64 {
    crate::dielectric::dielectric_albedo(family, mu, alpha, 1.0, crate::DIELECTRIC_PANELS).1
}

/// Estimates cell k with batches seeded by `salt` until both SEs reach `target` (or
/// `max_batches`).
pub fn cell(family: Family, side: Side, k: usize, salt: u64, target: f64, max_batches: u32) -> Cell {
    let (mu, alpha, eta) = node_parameters(k);
    if alpha == 0.0 {
        return Cell { reflected: 0.0, transmitted: 0.0, walks: 0 };
    }
    if eta == 1.0 {
        let t = single_transmitted(family, mu, alpha);
        return Cell { reflected: 0.0, transmitted: (1.0 - t).max(0.0), walks: 0 };
    }
    let (mut r, mut t, mut n) = (0u64, 0u64, 0u32);
    for b in 0..max_batches {
        let (cr, ct) = walk_counts(family, side, mu, alpha, eta, BATCH, seed(family, side, k, b, salt));
        r += u64::from(cr);
        t += u64::from(ct);
        n += BATCH;
        let c = Cell { reflected: r as f64 / f64::from(n), transmitted: t as f64 / f64::from(n), walks: n };
        let (sr, st) = c.standard_errors();
        if sr.max(st) <= target {
            break;
        }
    }
    Cell { reflected: r as f64 / f64::from(n), transmitted: t as f64 / f64::from(n), walks: n }
}

/// The seed salt of the shipped tables.
pub const SHIPPED_SALT: u64 = 0x5eed_0016_0000_0000;

/// Builds the tables of one family and side.
pub fn build(family: Family, side: Side) -> Vec<Cell> {
    let label = format!("{} {} ΔR, ΔT", family.name(), side.name());
    let cells = par_map(NODES, &label, |k| cell(family, side, k, SHIPPED_SALT, TARGET_SE, MAX_BATCHES));
    let worst = cells.iter().map(|c| c.standard_errors().0.max(c.standard_errors().1)).fold(0.0, f64::max);
    let walks: u64 = cells.iter().map(|c| u64::from(c.walks)).sum();
    println!("{label}: {walks} walks, largest standard error {worst:.2e}");
    assert!(worst <= TARGET_SE, "{label}: standard error {worst:.2e} above {TARGET_SE:e}");
    cells
}

/// The Rust source of `src/albedo/generated/dielectric_walk.rs`.
pub fn source(tables: &[(Family, Side, Vec<Cell>)]) -> String {
    let mut s = String::from(
        "//! Generated by `cargo run --release -p tools --bin tables -- --only walk-dielectric`: do not edit.\n//!\n\
         //! The random walk's reflected and transmitted energy of orders ≥ 2 of dielectric microsurfaces\n\
         //! (see `DielectricWalkTable` for the axes), and the walks per cell.\n\n",
    );
    for (family, side, cells) in tables {
        let upper = family.name().to_uppercase();
        let side_upper = side.name().to_uppercase();
        for (what, value) in [
            ("REFLECTED", &(|c: &Cell| format!("{:?}", c.reflected as f32)) as &dyn Fn(&Cell) -> String),
            ("TRANSMITTED", &|c: &Cell| format!("{:?}", c.transmitted as f32)),
        ] {
            let _ = writeln!(
                s,
                "/// {} energy of orders ≥ 2 of {}, light from {}, η slowest, direction fastest.",
                what.to_lowercase(),
                family.name(),
                side.name()
            );
            let _ = writeln!(s, "#[rustfmt::skip]");
            let _ = writeln!(s, "pub(crate) static {upper}_{side_upper}_{what}: [f32; {NODES}] = [");
            for row in cells.chunks(8) {
                let _ = writeln!(s, "    {},", row.iter().map(value).collect::<Vec<_>>().join(", "));
            }
            let _ = writeln!(s, "];");
        }
        let _ = writeln!(
            s,
            "/// Batches of {BATCH} walks per cell of {}, light from {} (0: a limit row without walks).",
            family.name(),
            side.name()
        );
        let _ = writeln!(s, "#[rustfmt::skip]");
        let _ = writeln!(s, "pub(crate) static {upper}_{side_upper}_BATCHES: [u8; {NODES}] = [");
        for row in cells.chunks(32) {
            let _ = writeln!(
                s,
                "    {},",
                row.iter().map(|c| (c.walks / BATCH).to_string()).collect::<Vec<_>>().join(", ")
            );
        }
        let _ = writeln!(s, "];");
    }
    s
}

/// Writes the f32 exports (ΔR, ΔT and their standard errors).
pub fn export(tables: &[(Family, Side, Vec<Cell>)], dir: &std::path::Path) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    for (family, side, cells) in tables {
        type Part = fn(&Cell) -> f64;
        let parts: [(&str, Part); 4] = [
            ("reflected", |c| c.reflected),
            ("transmitted", |c| c.transmitted),
            ("reflected_se", |c| c.standard_errors().0),
            ("transmitted_se", |c| c.standard_errors().1),
        ];
        for (what, f) in parts {
            let bytes: Vec<u8> = cells.iter().flat_map(|c| (f(c) as f32).to_le_bytes()).collect();
            std::fs::write(
                dir.join(format!("{}_walk_dielectric_{}_{what}.f32", family.name(), side.name())),
                bytes,
            )?;
        }
    }
    std::fs::write(
        dir.join("README_walk_dielectric.txt"),
        "Little-endian f32 arrays, no header.\n\n\
         <family>_walk_dielectric_<side>_<reflected|transmitted>.f32: 16 x 16 x 16 values V[l][j][i],\n\
         l (eta) slowest, i (direction) fastest: the random walk's reflected / transmitted (flux)\n\
         energy of scattering orders >= 2 (Delta R, Delta T) of a dielectric with light from <side>\n\
         (outside: relative index eta; inside: 1/eta); the _se files hold each value's standard\n\
         error. Axes as the single-scattering dielectric exports: u = l/15, eta = 1 + 2 u^2 in\n\
         [1, 3]; r = j/15, alpha = r^2; x = i/15, mu = X alpha/(1 + alpha - X) with X = x^2 (node\n\
         x = 0 estimated at mu = 1e-7). Lookup of (mu, alpha, eta): x = sqrt(mu (1 + alpha)/(mu +\n\
         alpha)), r = sqrt(alpha), u = sqrt((eta - 1)/2), trilinear in (x, r, u) at (15 x, 15 r, 15 u).\n\
         See microsurface::compensation::DielectricWalkTable and microsurface::Compensated.\n",
    )?;
    Ok(())
}

/// `--quick`: recomputes a few pseudo-random cells per family and side with another seed (one
/// batch each) and compares them with the shipped values within the combined standard error
/// (Šidák over all compared values, family-wise level 1e-3); the limit rows are compared
/// exactly. Returns the number of failures.
pub fn quick(shipped: &dyn Fn(Family, Side, usize) -> Cell) -> usize {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let comparisons = (2 * 2 * QUICK_WALK_CELLS * 2) as f64;
    let z = sidak_z(1e-3, comparisons);
    let mut failures = 0;
    for family in [Family::Ggx, Family::Beckmann] {
        for side in [Side::Outside, Side::Inside] {
            for _ in 0..QUICK_WALK_CELLS {
                state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                let k = (state >> 33) as usize % NODES;
                let a = shipped(family, side, k);
                let b = cell(family, side, k, 0x0bad_5eed, 0.0, 1);
                let (sa, sb) = (a.standard_errors(), b.standard_errors());
                for (what, x, y, se) in [
                    ("ΔR", a.reflected, b.reflected, sa.0.hypot(sb.0)),
                    ("ΔT", a.transmitted, b.transmitted, sa.1.hypot(sb.1)),
                ] {
                    // the limit rows have no walks and must agree exactly
                    let bound = if a.walks == 0 { 1e-6 } else { z * se };
                    if (x - y).abs() > bound {
                        failures += 1;
                        println!(
                            "{} {} walk cell {k}: {what} shipped {x:.5} ({} walks), recomputed {y:.5} ({} walks), \
                             combined SE {se:.2e}, z {z:.2}",
                            family.name(),
                            side.name(),
                            a.walks,
                            b.walks
                        );
                    }
                }
            }
        }
    }
    failures
}

/// The two-sided normal quantile of the Šidák per-comparison level for family-wise `level`
/// over `m` comparisons (bisection on erfc).
fn sidak_z(level: f64, m: f64) -> f64 {
    let per = 1.0 - (1.0 - level).powf(1.0 / m);
    let (mut lo, mut hi) = (0.0f64, 10.0f64);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if f64::from(microsurface::special::erfc((mid / std::f64::consts::SQRT_2) as f32)) > per {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// `TABLES_WALK_PROBE=1`: the cost of one batch at a few cells (sizing the run).
pub fn probe() {
    for family in [Family::Ggx, Family::Beckmann] {
        for side in [Side::Outside, Side::Inside] {
            for (i, j, l) in
                [(8, 15, 5), (1, 15, 1), (0, 15, 8), (15, 15, 15), (8, 8, 8), (3, 4, 2), (8, 15, 1)]
            {
                let k = (l * ND + j) * ND + i;
                let t0 = std::time::Instant::now();
                let c = cell(family, side, k, 1, 0.0, 1);
                let ns = t0.elapsed().as_secs_f64() * 1e9 / f64::from(BATCH);
                println!(
                    "{} {} ({i},{j},{l}) {:?}: ΔR {:.4} ΔT {:.4}, {ns:.0} ns/walk",
                    family.name(),
                    side.name(),
                    node_parameters(k),
                    c.reflected,
                    c.transmitted
                );
            }
        }
    }
}
