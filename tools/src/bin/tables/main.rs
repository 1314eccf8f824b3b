//! Generates the crate's albedo tables, on all cores, and exports them for shaders: the
//! single-scattering tables by deterministic quadrature (`src/albedo/generated/conductor.rs`: conductor E and
//! E_avg; `src/albedo/generated/dielectric.rs`: dielectric R and T) and the random walk's tables by
//! seeded Monte Carlo (`src/albedo/generated/orders.rs`: the conductor's energy per order;
//! `src/albedo/generated/dielectric_walk.rs`: the dielectric's higher orders ΔR, ΔT).
//!
//! ```sh
//! cargo run --release -p tools --bin tables            # rebuild both and target/tables/
//! cargo run --release -p tools --bin tables -- --only dielectric   # or conductor, orders, walk-dielectric
//! cargo run --release -p tools --bin tables -- --quick # recompute a subset, check it against the shipped tables
//! ```
//!
//! Quadrature is deterministic, so a rebuild reproduces the shipped tables bit for bit
//! whatever the number of threads. Every conductor node is computed at two resolutions (6 and
//! 8 panels of 16-point Gauss–Legendre per variable); the run fails if they differ by more than
//! 1e-6. Dielectric nodes use 2 panels per variable and piece (see `dielectric.rs`), and every
//! 7th node is recomputed at 3; the run fails if they differ by more than 1e-5.

mod dielectric;
mod dielectric_axes;
mod dielectric_loss;
mod furnace;
mod orders;
mod quadrature;
mod walk_dielectric;

use dielectric::dielectric_albedo;
use dielectric_axes::{Axes, BelowKnee, Roughness};
use quadrature::{Family, gauss_legendre, single_scattering_albedo};
use std::fmt::Write as _;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Nodes per axis of the per-order tables (as `microsurface::compensation::ORDER_TABLE_SIZE`).
const N: usize = 32;
/// Direction nodes of the conductor albedo table (x = i/93: every third one a node of the
/// per-order tables).
const NX: usize = 94;
/// Roughness nodes of the conductor albedo table (r = j/62: every other row is a row of the
/// per-order tables).
const NR: usize = 63;
/// The roughness at which the r = 0 row (the α → 0 limit profile) is evaluated.
const ALPHA_LIMIT: f64 = 1e-6;
/// Quadrature panels per variable for the shipped values, and for the error estimate.
const PANELS: usize = 8;
const CHECK_PANELS: usize = 6;
/// Largest accepted disagreement of the two resolutions.
const MAX_QUADRATURE_ERROR: f64 = 1e-6;
/// Panels of the E_avg integral over X (half of them for its error estimate).
const AVERAGE_PANELS: usize = 12;
/// Cells recomputed by `--quick`.
const QUICK_CELLS: usize = 24;

/// The α of roughness node j of an axis r = √α with `nodes` nodes.
fn alpha_at(j: usize, nodes: usize) -> f64 {
    let r = j as f64 / (nodes - 1) as f64;
    (r * r).max(ALPHA_LIMIT)
}

/// The α of roughness node j of the per-order tables.
fn alpha_of_node(j: usize) -> f64 {
    alpha_at(j, N)
}

/// The α of roughness row j of the conductor albedo table.
fn alpha_of_row(j: usize) -> f64 {
    alpha_at(j, NR)
}

/// μ of direction coordinate x at roughness α: μ = X α/(1 + α − X), X = x².
fn mu_of(x: f64, alpha: f64) -> f64 {
    let big_x = x * x;
    if big_x >= 1.0 { 1.0 } else { big_x * alpha / (1.0 + alpha - big_x) }
}

/// E at node (i, j) of the conductor albedo table.
fn node(family: Family, i: usize, j: usize, panels: usize) -> f64 {
    let alpha = alpha_of_row(j);
    single_scattering_albedo(family, mu_of(i as f64 / (NX - 1) as f64, alpha), alpha, panels)
}

/// Below this μ the E_avg integrand is dropped: ∫₀^μ E μ dμ ≤ μ²/2 = 5e-15.
const AVERAGE_MU_MIN: f64 = 1e-7;

/// E_avg(α) = 2∫ E μ dμ = 2∫ E μ² d(ln μ) over ln μ ∈ [ln 1e-7, 0], with `outer` panels over
/// ln μ and `panels` for each E: E varies on the scale of μ itself (its features sit at μ ≈ α
/// and at μ → 0), which a logarithmic variable resolves at every α.
fn average(family: Family, alpha: f64, outer: usize, panels: usize) -> f64 {
    2.0 * gauss_legendre(AVERAGE_MU_MIN.ln(), 0.0, outer, |t| {
        let mu = t.exp();
        single_scattering_albedo(family, mu, alpha, panels) * mu * mu
    })
}

/// Runs `f` on every index in 0..n on all cores; results in index order.
fn par_map<T: Send>(n: usize, label: &str, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let threads = std::thread::available_parallelism().map_or(1, |t| t.get());
    let show = std::io::stderr().is_terminal();
    let mut parts: Vec<Vec<(usize, T)>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut out = Vec::new();
                    loop {
                        let k = next.fetch_add(1, Ordering::Relaxed);
                        if k >= n {
                            break;
                        }
                        out.push((k, f(k)));
                        let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                        if show && (d.is_multiple_of(8) || d == n) {
                            let bar = "#".repeat(40 * d / n);
                            eprint!("\r{label:>24} [{bar:<40}] {d}/{n}");
                        }
                    }
                    out
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().expect("worker panicked")).collect()
    });
    if show {
        eprintln!();
    }
    let mut all: Vec<(usize, T)> = parts.drain(..).flatten().collect();
    all.sort_by_key(|(k, _)| *k);
    all.into_iter().map(|(_, v)| v).collect()
}

/// The shipped tables of one family, computed.
struct Tables {
    directional: Vec<f32>,
    average: Vec<f32>,
}

fn build(family: Family) -> Tables {
    let name = family.name();
    let cells = par_map(NX * NR, &format!("{name} E(mu, alpha)"), |k| {
        let (i, j) = (k % NX, k / NX);
        let fine = node(family, i, j, PANELS);
        let coarse = node(family, i, j, CHECK_PANELS);
        (fine, (fine - coarse).abs())
    });
    let worst = cells.iter().map(|c| c.1).fold(0.0, f64::max);
    println!("{name}: E nodes, largest disagreement of {CHECK_PANELS} and {PANELS} panels: {worst:.2e}");
    assert!(
        worst <= MAX_QUADRATURE_ERROR,
        "{name}: quadrature error estimate {worst:.2e} > {MAX_QUADRATURE_ERROR:e}"
    );
    let averages = par_map(NR, &format!("{name} E_avg(alpha)"), |j| {
        let alpha = alpha_of_row(j);
        let fine = average(family, alpha, AVERAGE_PANELS, PANELS);
        (fine, (fine - average(family, alpha, AVERAGE_PANELS / 2, CHECK_PANELS)).abs())
    });
    let worst = averages.iter().map(|c| c.1).fold(0.0, f64::max);
    println!("{name}: E_avg nodes, largest disagreement: {worst:.2e}");
    assert!(worst <= MAX_QUADRATURE_ERROR, "{name}: E_avg error estimate {worst:.2e}");
    Tables {
        directional: cells.iter().map(|c| c.0 as f32).collect(),
        average: averages.iter().map(|c| c.0 as f32).collect(),
    }
}

/// Where an interpolated value is checked against quadrature, relative to the table's cells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Probe {
    /// The centre of a cell (both coordinates halfway between nodes).
    Centre,
    /// The midpoint of a cell edge along the direction axis (on a roughness row).
    DirectionEdge,
    /// The midpoint of a cell edge along the roughness axis (on a direction column).
    RoughnessEdge,
}

/// The dense check of the conductor table: the interpolated E against direct quadrature at
/// every cell centre and every midpoint of a cell edge (both kinds), where a bilinear
/// interpolant is farthest from its nodes. Per probe kind: (max, RMS, (μ, α) of the max).
fn interpolation_error(family: Family) -> Vec<(Probe, f64, f64, (f64, f64))> {
    let table = table_of(family);
    let (nx, nr) = (table.direction_nodes(), table.roughness_nodes());
    let (lx, lr) = ((nx - 1) as f64, (nr - 1) as f64);
    let mut points = Vec::new();
    for j in 0..nr {
        for i in 0..nx {
            let (x, r) = (i as f64 / lx, j as f64 / lr);
            let (xc, rc) = ((i as f64 + 0.5) / lx, (j as f64 + 0.5) / lr);
            if i + 1 < nx && j + 1 < nr {
                points.push((Probe::Centre, xc, rc));
            }
            if i + 1 < nx {
                points.push((Probe::DirectionEdge, xc, r));
            }
            if j + 1 < nr {
                points.push((Probe::RoughnessEdge, x, rc));
            }
        }
    }
    let errors = par_map(points.len(), &format!("{} interpolation", family.name()), |k| {
        let (_, x, r) = points[k];
        probe_error(family, x, r)
    });
    [Probe::Centre, Probe::DirectionEdge, Probe::RoughnessEdge]
        .into_iter()
        .map(|probe| {
            let of: Vec<&(f64, (f64, f64))> =
                points.iter().zip(&errors).filter(|(p, _)| p.0 == probe).map(|(_, e)| e).collect();
            let worst = of.iter().fold(&(0.0, (0.0, 0.0)), |w, e| if e.0 > w.0 { e } else { w });
            let rms = (of.iter().map(|e| e.0 * e.0).sum::<f64>() / of.len() as f64).sqrt();
            (probe, worst.0, rms, worst.1)
        })
        .collect()
}

/// The largest interpolation error of E the shipped tables' documentation states (cell centres
/// and edge midpoints, from `--interpolation`): GGX, Beckmann. `--quick` checks probes against it.
const STATED_E_ERROR: [f64; 2] = [STATED_GGX, STATED_BECKMANN];
const STATED_GGX: f64 = 1.9e-4;
const STATED_BECKMANN: f64 = 6.8e-4;
/// Probes of the interpolation error recomputed by `--quick` per family.
const QUICK_PROBES: usize = 12;

/// Quadrature panels of the dense check's reference values (`--quick` measures their own error
/// against [`CHECK_PANELS`] at its probes).
const DENSE_PANELS: usize = 4;

/// |E interpolated − E by quadrature| at the direction and roughness coordinates (x, r), and the
/// (μ, α) of the point: the lookup at the f32 coordinates, the quadrature at the same values.
fn probe_error(family: Family, x: f64, r: f64) -> (f64, (f64, f64)) {
    let table = table_of(family);
    let alpha = (r * r).max(ALPHA_LIMIT);
    let mu = mu_of(x, alpha);
    let (mu32, alpha32) = (mu as f32, alpha as f32);
    let exact = single_scattering_albedo(family, f64::from(mu32), f64::from(alpha32), DENSE_PANELS);
    let e = (f64::from(table.directional(mu32, alpha32).expect("in range")) - exact).abs();
    (e, (f64::from(mu32), f64::from(alpha32)))
}

/// The interpolation error of E_avg at the midpoints between its nodes against quadrature.
fn average_interpolation_error(family: Family) -> f64 {
    let table = table_of(family);
    let nr = table.roughness_nodes();
    let avg_errors = par_map(nr - 1, &format!("{} E_avg interpolation", family.name()), |j| {
        let r = (j as f64 + 0.5) / (nr - 1) as f64;
        let exact = average(family, r * r, AVERAGE_PANELS / 2, CHECK_PANELS);
        (f64::from(table.average((r * r) as f32).expect("in range")) - exact).abs()
    });
    avg_errors.iter().copied().fold(0.0, f64::max)
}

fn table_of(family: Family) -> microsurface::compensation::AlbedoTable {
    match family {
        Family::Ggx => microsurface::compensation::AlbedoTable::GGX,
        Family::Beckmann => microsurface::compensation::AlbedoTable::BECKMANN,
    }
}

/// The Rust source of `src/albedo/generated/conductor.rs`.
fn source(tables: &[(Family, Tables)]) -> String {
    let mut s = String::from(
        "//! Generated by `cargo run --release -p tools --bin tables`: do not edit.\n//!\n//! Single-scattering albedo \
         nodes (see `AlbedoTable` for the axes).\n\n",
    );
    for (family, t) in tables {
        let upper = family.name().to_uppercase();
        let _ = writeln!(s, "/// E(μ, α) of {}, row-major, roughness slowest.", family.name());
        let _ = writeln!(s, "pub(crate) static {upper}_DIRECTIONAL: [f32; {}] = [", NX * NR);
        for row in t.directional.chunks(8) {
            let _ =
                writeln!(s, "    {},", row.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(", "));
        }
        let _ = writeln!(s, "];\n/// E_avg(α) of {}.", family.name());
        let _ = writeln!(s, "pub(crate) static {upper}_AVERAGE: [f32; {NR}] = [");
        for row in t.average.chunks(8) {
            let _ =
                writeln!(s, "    {},", row.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(", "));
        }
        let _ = writeln!(s, "];");
    }
    s
}

/// Writes little-endian f32 exports with a description of their layout.
fn export(tables: &[(Family, Tables)], dir: &std::path::Path) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    for (family, t) in tables {
        for (suffix, values) in [("directional", &t.directional), ("average", &t.average)] {
            let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
            std::fs::write(dir.join(format!("{}_{suffix}.f32", family.name())), bytes)?;
        }
    }
    write_readme(dir)
}

/// Writes `README.txt`, the layout of every export.
fn write_readme(dir: &std::path::Path) -> std::io::Result<()> {
    let (lx, lr) = (NX - 1, NR - 1);
    let mut readme = format!(
        "Little-endian f32 arrays, no header.\n\n\
         <family>_directional.f32: {NR} x {NX} values E[j][i], j (roughness) slowest.\n\
         r = j/{lr}, alpha = r^2 (row j = 0: the alpha -> 0 limit profile); x = i/{lx},\n\
         mu = X alpha/(1 + alpha - X) with X = x^2. Lookup of (mu, alpha):\n\
         x = sqrt(mu (1 + alpha)/(mu + alpha)), r = sqrt(alpha), bilinear in (x, r) at ({lx} x, {lr} r).\n\
         <family>_average.f32: {NR} values E_avg[j] at r = j/{lr}, linear in r.\n\n"
    );
    readme.push_str(
        "<family>_dielectric_<side>_<reflected|transmitted>.f32: 16 x 16 x 16 values V[l][j][i],\n\
         l (eta) slowest, i (direction) fastest: the single-scattering reflected / transmitted\n\
         (flux) albedo of a dielectric with light from <side> (outside: relative index eta;\n\
         inside: 1/eta). With B(v) = 0.5 ln(v/1e-6)/ln(1e6) + 0.5 (sqrt(v) - 1e-3)/(1 - 1e-3)\n\
         for v >= 1e-6 (0 below): u = l/15, eta = 1 + 2 u^3 in [1, 3]; r = j/15 = B(alpha)\n\
         (row 0: alpha = 1e-6); x = i/15 = B(mu) for light from outside, and from inside, with\n\
         e = 1/eta and the critical cosine mc = sqrt(1 - e^2), k = 7/15:\n\
         x = k (0.5 B(mu/mc) + 0.5 (1 - sqrt(1 - mu/mc))) for mu <= mc,\n\
         x = k + (1 - k) sqrt((mu - mc)/(1 - mc)) above (row l = 0: mc = 0).\n\
         Lookup of (mu, alpha, eta seen): the table of the side (eta >= 1: outside, else inside\n\
         at 1/eta), x as above with the eta seen, r = B(alpha), u = cbrt((eta - 1)/2),\n\
         trilinear in (x, r, u) at (15 x, 15 r, 15 u).\n",
    );
    readme.push_str(
        "\nSee microsurface::compensation::AlbedoTable and microsurface::compensation::DielectricAlbedoTable for the definitions and the \
         measured errors.\n",
    );
    std::fs::write(dir.join("README.txt"), readme)
}

/// Nodes per axis of the dielectric tables (as `microsurface::compensation::DIELECTRIC_TABLE_SIZE`).
const ND: usize = microsurface::compensation::DIELECTRIC_TABLE_SIZE;
/// Quadrature panels (16-point Gauss–Legendre) per variable and piece of the shipped
/// dielectric nodes, and of their error estimate (the integrand is split at all its kinks and
/// graded towards its square-root features, so few panels suffice).
const DIELECTRIC_PANELS: usize = 2;
const DIELECTRIC_CHECK_PANELS: usize = 3;
/// The error estimate is computed at every `DIELECTRIC_CHECK_STRIDE`-th node (a fixed subset of
/// 1/7 of the nodes; 7 is prime to 16, so the subset visits every direction, roughness and η
/// index): the check at every node would more than double the generator's time.
const DIELECTRIC_CHECK_STRIDE: usize = 7;
/// Largest accepted disagreement of the two resolutions of a dielectric node.
const MAX_DIELECTRIC_ERROR: f64 = 1e-5;
/// Dielectric nodes recomputed by `--quick` per family and side.
const QUICK_DIELECTRIC_CELLS: usize = 6;
/// Random cell-interior points at which `--interpolation` measures the dielectric lookups, per
/// family and side.
const INTERPOLATION_POINTS: usize = 256;

/// The side light arrives from: outside the relative index of the η axis is η, inside 1/η.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Side {
    Outside,
    Inside,
}

impl Side {
    fn name(self) -> &'static str {
        match self {
            Side::Outside => "outside",
            Side::Inside => "inside",
        }
    }
}

/// (R, T) at dielectric node k = (l·ND + j)·ND + i (η slowest, direction fastest) of the
/// shipped axes.
fn dielectric_node(family: Family, side: Side, k: usize, panels: usize) -> (f64, f64) {
    let (i, j, l) = (k % ND, (k / ND) % ND, k / (ND * ND));
    let (mu, alpha, eta) = dielectric_axes::SHIPPED.node(i, j, l, side);
    dielectric_albedo(family, mu, alpha, eta, panels)
}

/// The dielectric tables of one family and side: R and T nodes.
struct DielectricTables {
    reflected: Vec<f32>,
    transmitted: Vec<f32>,
}

fn build_dielectric(family: Family, side: Side) -> DielectricTables {
    let label = format!("{} {} R, T", family.name(), side.name());
    let cells = par_map(ND * ND * ND, &label, |k| {
        let (r, t) = dielectric_node(family, side, k, DIELECTRIC_PANELS);
        let check = if k % DIELECTRIC_CHECK_STRIDE == 0 {
            let (rc, tc) = dielectric_node(family, side, k, DIELECTRIC_CHECK_PANELS);
            (r - rc).abs().max((t - tc).abs())
        } else {
            0.0
        };
        (r, t, check)
    });
    let worst = cells.iter().map(|c| c.2).fold(0.0, f64::max);
    for (k, c) in cells.iter().enumerate() {
        if c.2 > MAX_DIELECTRIC_ERROR / 4.0 {
            let (i, j, l) = (k % ND, (k / ND) % ND, k / (ND * ND));
            println!("  node {k} = ({i}, {j}, {l}): R {:.7}, T {:.7}, disagreement {:.1e}", c.0, c.1, c.2);
        }
    }
    println!(
        "{label}: largest disagreement of {DIELECTRIC_PANELS} and {DIELECTRIC_CHECK_PANELS} panels (every \
         {DIELECTRIC_CHECK_STRIDE}th node): {worst:.2e}"
    );
    assert!(worst <= MAX_DIELECTRIC_ERROR, "{label}: quadrature error estimate {worst:.2e}");
    DielectricTables {
        reflected: cells.iter().map(|c| c.0 as f32).collect(),
        transmitted: cells.iter().map(|c| c.1 as f32).collect(),
    }
}

fn dielectric_table_of(family: Family) -> microsurface::compensation::DielectricAlbedoTable {
    match family {
        Family::Ggx => microsurface::compensation::DielectricAlbedoTable::GGX,
        Family::Beckmann => microsurface::compensation::DielectricAlbedoTable::BECKMANN,
    }
}

/// The table light from `side` reads (outside η ≥ 1, inside 1/η ≤ 1).
fn range_of(side: Side) -> microsurface::compensation::EtaRange {
    match side {
        Side::Outside => microsurface::compensation::EtaRange::AtLeastOne,
        Side::Inside => microsurface::compensation::EtaRange::AtMostOne,
    }
}

/// The interpolation error of the shipped dielectric lookups at the measurement points
/// ([`measurement_point`]) against direct quadrature: (max, RMS) of R, of T and of R + T.
fn dielectric_interpolation_error(family: Family, side: Side, uniform: bool) -> [(f64, f64); 3] {
    let table = dielectric_table_of(family);
    let label = format!("{} {} interpolation", family.name(), side.name());
    let errors = par_map(INTERPOLATION_POINTS, &label, |k| {
        let (mu, alpha, eta_side) = measurement_point(k, side, uniform);
        let (er, et) = dielectric_albedo(family, mu, alpha, eta_side, DIELECTRIC_PANELS);
        let v = table.albedo(mu as f32, alpha as f32, eta_side as f32).expect("in range");
        let e = ((f64::from(v.reflected) - er).abs(), (f64::from(v.transmitted) - et).abs());
        let total = (f64::from(v.reflected + v.transmitted) - er - et).abs();
        if std::env::var_os("TABLES_DEBUG").is_some() && e.0.max(e.1) > 0.05 {
            println!("  μ {mu:e} α {alpha:e} η {eta_side}: quadrature R {er} T {et}, lookup {v:?}");
        }
        (e.0, e.1, total)
    });
    let stats = |e: &dyn Fn(&(f64, f64, f64)) -> f64| {
        let max = errors.iter().map(e).fold(0.0, f64::max);
        let rms = (errors.iter().map(|v| e(v) * e(v)).sum::<f64>() / errors.len() as f64).sqrt();
        (max, rms)
    };
    [stats(&|v| v.0), stats(&|v| v.1), stats(&|v| v.2)]
}

/// The Rust source of `src/albedo/generated/dielectric.rs`.
fn dielectric_source(tables: &[(Family, Side, DielectricTables)]) -> String {
    let mut s = String::from(
        "//! Generated by `cargo run --release -p tools --bin tables`: do not edit.\n//!\n//! Dielectric \
         single-scattering albedo nodes (see `DielectricAlbedoTable` for the axes).\n\n",
    );
    for (family, side, t) in tables {
        for (what, values) in [("REFLECTED", &t.reflected), ("TRANSMITTED", &t.transmitted)] {
            let upper = family.name().to_uppercase();
            let side_upper = side.name().to_uppercase();
            let _ = writeln!(
                s,
                "/// {} albedo of {}, light from {}, η slowest, direction fastest.",
                what.to_lowercase(),
                family.name(),
                side.name()
            );
            // rustfmt would put each value on its own line (some exceed its short-element width)
            let _ = writeln!(s, "#[rustfmt::skip]");
            let _ = writeln!(s, "pub(crate) static {upper}_{side_upper}_{what}: [f32; {}] = [", ND * ND * ND);
            for row in values.chunks(8) {
                let _ = writeln!(
                    s,
                    "    {},",
                    row.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(", ")
                );
            }
            let _ = writeln!(s, "];");
        }
    }
    s
}

/// Writes the dielectric f32 exports.
fn dielectric_export(
    tables: &[(Family, Side, DielectricTables)],
    dir: &std::path::Path,
) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    for (family, side, t) in tables {
        for (what, values) in [("reflected", &t.reflected), ("transmitted", &t.transmitted)] {
            let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
            std::fs::write(
                dir.join(format!("{}_dielectric_{}_{what}.f32", family.name(), side.name())),
                bytes,
            )?;
        }
    }
    Ok(())
}

/// `--quick`: recomputes a fixed pseudo-random subset of nodes and checks them bit for bit.
fn quick() {
    // the generator's layout is the one the crate reads (`src/albedo/table.rs`; a rebuild with
    // other NX, NR is read once the crate's constants follow)
    let shipped = (table_of(Family::Ggx).direction_nodes(), table_of(Family::Ggx).roughness_nodes());
    assert_eq!((NX, NR), shipped, "the generator's conductor layout is not the crate's");
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut failures = 0;
    let mut dense_reference: f64 = 0.0;
    for family in [Family::Ggx, Family::Beckmann] {
        let table = table_of(family);
        for _ in 0..QUICK_CELLS {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            let k = (state >> 33) as usize % (NX * NR);
            let value = node(family, k % NX, k / NX, PANELS) as f32;
            let shipped = table.directional_nodes()[k];
            if value.to_bits() != shipped.to_bits() {
                failures += 1;
                println!("{} node {k}: recomputed {value:?}, shipped {shipped:?}", family.name());
            }
        }
        // the dense check's probes: a cell centre or an edge midpoint of a pseudo-random cell
        for _ in 0..QUICK_PROBES {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            let (i, j) = ((state >> 33) as usize % (NX - 1), (state >> 45) as usize % (NR - 1));
            let (x, r) = match (state >> 60) % 3 {
                0 => (i as f64 + 0.5, j as f64 + 0.5),
                1 => (i as f64 + 0.5, j as f64),
                _ => (i as f64, j as f64 + 0.5),
            };
            let (x, r) = (x / (NX - 1) as f64, r / (NR - 1) as f64);
            let (e, (mu, alpha)) = probe_error(family, x, r);
            let reference = |panels| single_scattering_albedo(family, mu, alpha, panels);
            dense_reference = dense_reference.max((reference(DENSE_PANELS) - reference(CHECK_PANELS)).abs());
            let stated = STATED_E_ERROR[usize::from(family == Family::Beckmann)];
            if e > stated {
                failures += 1;
                println!(
                    "{} E at μ {mu:.5}, α {alpha:.5}: interpolation error {e:.2e} > {stated:.1e}",
                    family.name()
                );
            }
        }
        let j = (state >> 40) as usize % NR;
        let value = average(family, alpha_of_row(j), AVERAGE_PANELS, PANELS) as f32;
        if value.to_bits() != table.average_nodes()[j].to_bits() {
            failures += 1;
            println!(
                "{} E_avg node {j}: recomputed {value:?}, shipped {:?}",
                family.name(),
                table.average_nodes()[j]
            );
        }
    }
    println!(
        "conductor E: {} probes of the interpolation error within the stated bound; the dense check's \
         {DENSE_PANELS}-panel reference within {dense_reference:.1e} of {CHECK_PANELS} panels there",
        2 * QUICK_PROBES
    );
    let mut dielectric_nodes = 0;
    for family in [Family::Ggx, Family::Beckmann] {
        let table = dielectric_table_of(family);
        for side in [Side::Outside, Side::Inside] {
            for _ in 0..QUICK_DIELECTRIC_CELLS {
                state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                let k = (state >> 33) as usize % (ND * ND * ND);
                let (r, t) = dielectric_node(family, side, k, DIELECTRIC_PANELS);
                let (sr, st) = table.nodes(range_of(side));
                dielectric_nodes += 1;
                if (r as f32).to_bits() != sr[k].to_bits() || (t as f32).to_bits() != st[k].to_bits() {
                    failures += 1;
                    println!(
                        "{} {} node {k}: recomputed ({r:?}, {t:?}), shipped ({:?}, {:?})",
                        family.name(),
                        side.name(),
                        sr[k],
                        st[k]
                    );
                }
            }
        }
    }
    // the shipped dielectric source is exactly what the generator writes for its nodes
    let mut shipped = Vec::new();
    for family in [Family::Ggx, Family::Beckmann] {
        for side in [Side::Outside, Side::Inside] {
            let (r, t) = dielectric_table_of(family).nodes(range_of(side));
            shipped.push((family, side, DielectricTables { reflected: r.to_vec(), transmitted: t.to_vec() }));
        }
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src/albedo/generated/dielectric.rs");
    if std::fs::read_to_string(&path).ok().as_deref() != Some(dielectric_source(&shipped).as_str()) {
        failures += 1;
        println!("{} is not the generator's text for its own nodes", path.display());
    }
    // the walk tables: a few cells recomputed with another seed, within the combined SE
    let walk_table = |family: Family| match family {
        Family::Ggx => microsurface::compensation::DielectricWalkTable::GGX,
        Family::Beckmann => microsurface::compensation::DielectricWalkTable::BECKMANN,
    };
    let shipped_cell = |family: Family, side: Side, k: usize| {
        let t = walk_table(family);
        let (r, tr) = t.nodes(range_of(side));
        walk_dielectric::Cell {
            reflected: f64::from(r[k]),
            transmitted: f64::from(tr[k]),
            walks: t.walks(range_of(side), k).expect("node index"),
        }
    };
    failures += walk_dielectric::quick(&shipped_cell);
    let mut shipped = Vec::new();
    for family in [Family::Ggx, Family::Beckmann] {
        for side in [Side::Outside, Side::Inside] {
            let cells = (0..walk_dielectric::NODES).map(|k| shipped_cell(family, side, k)).collect();
            shipped.push((family, side, cells));
        }
    }
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src/albedo/generated/dielectric_walk.rs");
    if std::fs::read_to_string(&path).ok().as_deref() != Some(walk_dielectric::source(&shipped).as_str()) {
        failures += 1;
        println!("{} is not the generator's text for its own nodes", path.display());
    }
    failures += dielectric_loss::quick(&mut state);
    println!(
        "tables --quick: {} nodes recomputed (and {dielectric_nodes} dielectric R, T pairs, walk cells within \
         their combined SE), {failures} differ",
        2 * (QUICK_CELLS + 1)
    );
    let failures = failures + orders::quick();
    assert_eq!(failures, 0, "the shipped tables are not reproduced bit for bit");
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--help" || a == "-h") {
        println!(
            "usage: cargo run --release -p tools --bin tables [-- --quick | --interpolation] [--only conductor|dielectric|orders|walk-dielectric]\n\n  \
             (no flag)        rebuild src/albedo/generated/conductor.rs, src/albedo/generated/dielectric.rs and target/tables/*.f32,\n                   \
             print the quadrature error estimates\n  --interpolation  measure the lookups' interpolation error against \
             quadrature (dielectric: --uniform for mu uniform)\n  --design K P N M R S [family] [side]  measure a dielectric \
             axis design (knee node K, eta = 1 + 2u^P, N nodes, M points, log roughness R, symmetric knee S: 0/1) \
             from the nodes around the points only\n  --quick          recompute a subset of nodes and check them against the shipped tables bit for \
             bit\n  --only X         rebuild (or measure) only the conductor (E, E_avg) or only the dielectric tables,\n                   \
             or only the walk's per-order energies (orders: src/albedo/generated/orders.rs), or only the walk's higher orders\n                   \
             of dielectrics, ΔR and ΔT (walk-dielectric: src/albedo/generated/dielectric_walk.rs)"
        );
        return;
    }
    let only = args.iter().position(|a| a == "--only").and_then(|k| args.get(k + 1)).map(String::as_str);
    let (conductor, dielectric) =
        (only.is_none() || only == Some("conductor"), only.is_none() || only == Some("dielectric"));
    let per_order = only.is_none() || only == Some("orders"); // the walk's per-order energies (orders.rs)
    let walk = only.is_none() || only == Some("walk-dielectric");
    let loss = only.is_none() || only == Some("dielectric-loss");
    if std::env::var_os("TABLES_WALK_PROBE").is_some() {
        walk_dielectric::probe();
        return;
    }
    if args.iter().any(|a| a == "--furnace") {
        furnace::run();
        return;
    }
    if let Some(k) = args.iter().position(|a| a == "--furnace-design") {
        // --furnace-design NODES [ETA_POWER] [sqrt] [scale-invariant-outside] [scale-invariant-inside]
        let nodes = args.get(k + 1).and_then(|v| v.parse::<usize>().ok()).unwrap_or(16);
        let eta_power = args.get(k + 2).and_then(|v| v.parse::<f64>().ok()).unwrap_or(3.0);
        let si = |name: &str| {
            if args.iter().any(|a| a == name) {
                dielectric_axes::Direction::ScaleInvariant
            } else {
                dielectric_axes::Direction::Blend
            }
        };
        let axes = Axes {
            nodes,
            knee: (7 * (nodes - 1)).div_ceil(15),
            eta_power,
            roughness: if args.iter().any(|a| a == "sqrt") { Roughness::Sqrt } else { Roughness::Blend },
            direction: [
                if let Some(p) =
                    args.iter().find_map(|a| a.strip_prefix("mix-out=").and_then(|v| v.parse().ok()))
                {
                    dielectric_axes::Direction::Mixed(p)
                } else {
                    si("scale-invariant-outside")
                },
                if let Some(p) =
                    args.iter().find_map(|a| a.strip_prefix("mix-in=").and_then(|v| v.parse().ok()))
                {
                    dielectric_axes::Direction::Mixed(p)
                } else if args.iter().any(|a| a == "knee-si") {
                    dielectric_axes::Direction::KneeScaleInvariant
                } else {
                    si("scale-invariant-inside")
                },
            ],
            other_nodes: [
                args.iter().find_map(|a| a.strip_prefix("r=").and_then(|v| v.parse().ok())).unwrap_or(0),
                args.iter().find_map(|a| a.strip_prefix("u=").and_then(|v| v.parse().ok())).unwrap_or(0),
            ],
            ..dielectric_axes::SHIPPED
        };
        for family in [Family::Ggx, Family::Beckmann] {
            for side in [Side::Outside, Side::Inside] {
                let mut at = Vec::new();
                for &alpha in &furnace::ALPHAS {
                    for &eta in &furnace::ETAS {
                        for &mu in &furnace::MUS {
                            at.push((mu, alpha, if side == Side::Outside { eta } else { 1.0 / eta }));
                        }
                    }
                }
                let [_, _, (em, er)] = design_error_at(family, side, axes, &at);
                println!("{} {} {axes:?}: R + T max {em:.2e}, RMS {er:.2e}", family.name(), side.name());
            }
        }
        return;
    }
    if args.iter().any(|a| a == "--quick") {
        quick();
        return;
    }
    if let Some(k) = args.iter().position(|a| a == "--design") {
        // --design KNEE POWER NODES POINTS LOG_ROUGHNESS SYMMETRIC_KNEE [ggx|beckmann] [outside|inside] [--uniform]
        let num = |d: usize| args.get(k + d).and_then(|v| v.parse::<f64>().ok());
        let axes = Axes {
            knee: num(1).map_or(dielectric_axes::SHIPPED.knee, |v| v as usize),
            eta_power: num(2).unwrap_or(dielectric_axes::SHIPPED.eta_power),
            nodes: num(3).map_or(dielectric_axes::SHIPPED.nodes, |v| v as usize),
            roughness: num(5).map_or(dielectric_axes::SHIPPED.roughness, |v| {
                if v == 0.0 { Roughness::Sqrt } else { Roughness::Blend }
            }),
            below_knee: num(6).map_or(dielectric_axes::SHIPPED.below_knee, |v| {
                if v == 0.0 { BelowKnee::Blend } else { BelowKnee::Symmetric }
            }),
            direction: dielectric_axes::SHIPPED.direction,
            other_nodes: [0, 0],
        };
        let points = num(4).map_or(INTERPOLATION_POINTS, |v| v as usize);
        let uniform = args.iter().any(|a| a == "--uniform");
        for family in [Family::Ggx, Family::Beckmann] {
            if args.iter().any(|a| a == "ggx" || a == "beckmann") && !args.iter().any(|a| a == family.name())
            {
                continue;
            }
            for side in [Side::Outside, Side::Inside] {
                if args.iter().any(|a| a == "outside" || a == "inside")
                    && !args.iter().any(|a| a == side.name())
                {
                    continue;
                }
                let [(rm, rr), (tm, tr), (em, er)] = design_error(family, side, axes, points, uniform);
                println!(
                    "{} from {} {axes:?}: R max {rm:.2e}, RMS {rr:.2e}; T max {tm:.2e}, RMS {tr:.2e}; R + T max \
                     {em:.2e}, RMS {er:.2e}",
                    family.name(),
                    side.name()
                );
            }
        }
        return;
    }
    if args.iter().any(|a| a == "--interpolation") {
        for family in [Family::Ggx, Family::Beckmann] {
            if conductor {
                for (probe, max, rms, (mu, alpha)) in interpolation_error(family) {
                    println!(
                        "{}: interpolation error of E at {probe:?} probes: max {max:.2e} (μ {mu:.4}, α {alpha:.4}), \
                         RMS {rms:.2e}",
                        family.name()
                    );
                }
                println!(
                    "{}: E_avg interpolation error, max {:.2e}",
                    family.name(),
                    average_interpolation_error(family)
                );
            }
            if dielectric {
                for side in [Side::Outside, Side::Inside] {
                    let uniform = args.iter().any(|a| a == "--uniform");
                    let [(rm, rr), (tm, tr), (em, er)] =
                        dielectric_interpolation_error(family, side, uniform);
                    println!(
                        "{} dielectric from {}: interpolation error at {INTERPOLATION_POINTS} random points: R max \
                         {rm:.2e}, RMS {rr:.2e}; T max {tm:.2e}, RMS {tr:.2e}; R + T max {em:.2e}, RMS {er:.2e}",
                        family.name(),
                        side.name()
                    );
                }
            }
            if loss {
                for side in [Side::Outside, Side::Inside] {
                    let uniform = args.iter().any(|a| a == "--uniform");
                    let mu_min = 1e-3;
                    let [own, walk] = dielectric_loss::interpolation_error(family, side, uniform, mu_min);
                    for (what, [all, above]) in [("loss table", own), ("walk tables' ΔR + ΔT", walk)] {
                        println!(
                            "{} dielectric loss from {}, {what}: interpolation error at {INTERPOLATION_POINTS} random \
                             points: max {:.2e} (μ {:.3e}, α {:.3e}, η {:.4}), RMS {:.2e}; at μ ≥ {mu_min:e}: max {:.2e} \
                             (μ {:.3e}, α {:.3e}, η {:.4}), RMS {:.2e}",
                            family.name(),
                            side.name(),
                            all.0,
                            all.2.0,
                            all.2.1,
                            all.2.2,
                            all.1,
                            above.0,
                            above.2.0,
                            above.2.1,
                            above.2.2,
                            above.1
                        );
                    }
                }
            }
        }
        return;
    }
    let start = std::time::Instant::now();
    let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    let mut changed = false;
    if conductor {
        let tables: Vec<(Family, Tables)> =
            [Family::Ggx, Family::Beckmann].into_iter().map(|f| (f, build(f))).collect();
        changed |= write_if_changed(&root.join("src/albedo/generated/conductor.rs"), &source(&tables));
        export(&tables, &root.join("target/tables")).expect("write target/tables");
    }
    if per_order {
        let tables: Vec<_> =
            [Family::Ggx, Family::Beckmann].into_iter().map(|f| (f, orders::build(f))).collect();
        changed |= write_if_changed(&root.join("src/albedo/generated/orders.rs"), &orders::source(&tables));
        orders::export(&tables, &root.join("target/tables")).expect("write target/tables");
    }
    if dielectric {
        let mut tables = Vec::new();
        for family in [Family::Ggx, Family::Beckmann] {
            for side in [Side::Outside, Side::Inside] {
                tables.push((family, side, build_dielectric(family, side)));
            }
        }
        changed |=
            write_if_changed(&root.join("src/albedo/generated/dielectric.rs"), &dielectric_source(&tables));
        dielectric_export(&tables, &root.join("target/tables")).expect("write target/tables");
    }
    if loss {
        let mut tables = Vec::new();
        for family in [Family::Ggx, Family::Beckmann] {
            for side in [Side::Outside, Side::Inside] {
                let t0 = std::time::Instant::now();
                tables.push((family, side, dielectric_loss::build(family, side)));
                println!("  {:.1} s", t0.elapsed().as_secs_f64());
            }
        }
        changed |= write_if_changed(
            &root.join("src/albedo/generated/dielectric_loss.rs"),
            &dielectric_loss::source(&tables),
        );
        dielectric_loss::export(&tables, &root.join("target/tables")).expect("write target/tables");
    }
    if walk {
        let mut tables = Vec::new();
        for family in [Family::Ggx, Family::Beckmann] {
            for side in [Side::Outside, Side::Inside] {
                let t0 = std::time::Instant::now();
                tables.push((family, side, walk_dielectric::build(family, side)));
                println!("  {:.1} s", t0.elapsed().as_secs_f64());
            }
        }
        changed |= write_if_changed(
            &root.join("src/albedo/generated/dielectric_walk.rs"),
            &walk_dielectric::source(&tables),
        );
        walk_dielectric::export(&tables, &root.join("target/tables")).expect("write target/tables");
    }
    println!(
        "done in {:.1} s ({} CPU threads)",
        start.elapsed().as_secs_f64(),
        std::thread::available_parallelism().map_or(1, |t| t.get())
    );
    if changed {
        println!(
            "the tables changed: rebuild and run with --interpolation to measure the interpolation error"
        );
    }
}

/// Writes `text` to `path`; whether the file changed.
fn write_if_changed(path: &std::path::Path, text: &str) -> bool {
    let changed = std::fs::read_to_string(path).map_or(true, |old| old != text);
    std::fs::write(path, text).unwrap_or_else(|e| panic!("write {}: {e}", path.display()));
    println!("wrote {} ({})", path.display(), if changed { "changed" } else { "unchanged" });
    changed
}

/// The pseudo-random measurement points of `--interpolation` and `--design`: (μ, α, η seen)
/// for point k of `side`, with (x, r, u) uniform and α = max(r², 1e-4), μ = x²α/(1 + α − x²)
/// (the conductor's scale-invariant axis) and η = 1 + 2u² (the sampling of the first
/// measurement, kept fixed so that every design is measured at the same points), or, with
/// `uniform`, μ uniform in [0, 1].
fn measurement_point(k: usize, side: Side, uniform: bool) -> (f64, f64, f64) {
    let mut state = (k as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    let mut next = || {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let (x, r, u) = (next(), next(), next());
    let alpha = (r * r).max(1e-4);
    let mu = if uniform { x } else { mu_of(x, alpha) };
    let eta = 1.0 + 2.0 * u * u;
    (mu, alpha, if side == Side::Outside { eta } else { 1.0 / eta })
}

/// A measurement point (μ, α, η seen) and its cell (index, fraction) on each axis.
type Located = ((f64, f64, f64), [(usize, f64); 3]);

/// `--design`: the interpolation error of a table design (axes) at `points` measurement points,
/// computing only the nodes at the corners of the points' cells: (max, RMS) of R, T, R + T.
fn design_error(family: Family, side: Side, axes: Axes, points: usize, uniform: bool) -> [(f64, f64); 3] {
    let at: Vec<(f64, f64, f64)> = (0..points).map(|k| measurement_point(k, side, uniform)).collect();
    design_error_at(family, side, axes, &at)
}

/// [`design_error`] at the given points (μ, α, η seen).
fn design_error_at(family: Family, side: Side, axes: Axes, at: &[(f64, f64, f64)]) -> [(f64, f64); 3] {
    let points = at.len();
    let lasts = [0, 1, 2].map(|a| axes.last_of(a) as usize);
    let located: Vec<Located> = at
        .iter()
        .map(|&p| {
            let at = axes.coordinates(p.0, p.1, p.2);
            (
                p,
                [0, 1, 2].map(|a| {
                    let t = at[a];
                    let i = (t as usize).min(lasts[a] - 1);
                    (i, t - i as f64)
                }),
            )
        })
        .collect();
    let mut keys: Vec<(usize, usize, usize)> = Vec::new();
    for (_, c) in &located {
        for d in 0..8 {
            keys.push((c[0].0 + (d & 1), c[1].0 + ((d >> 1) & 1), c[2].0 + (d >> 2)));
        }
    }
    keys.sort_unstable();
    keys.dedup();
    let label = format!("{} {} design nodes", family.name(), side.name());
    let values = par_map(keys.len() + points, &label, |k| {
        if k < keys.len() {
            let (i, j, l) = keys[k];
            let (mu, alpha, eta) = axes.node(i, j, l, side);
            dielectric_albedo(family, mu, alpha, eta, DIELECTRIC_PANELS)
        } else {
            let (mu, alpha, eta) = located[k - keys.len()].0;
            dielectric_albedo(family, mu, alpha, eta, DIELECTRIC_PANELS)
        }
    });
    let node = |key: (usize, usize, usize)| values[keys.binary_search(&key).expect("computed")];
    let errors: Vec<(f64, f64, f64)> = located
        .iter()
        .enumerate()
        .map(|(k, (p, c))| {
            let mut v = [0.0; 2];
            for d in 0..8 {
                let w: f64 = (0..3).map(|a| if (d >> a) & 1 == 1 { c[a].1 } else { 1.0 - c[a].1 }).product();
                let n = node((c[0].0 + (d & 1), c[1].0 + ((d >> 1) & 1), c[2].0 + (d >> 2)));
                v[0] += w * n.0;
                v[1] += w * n.1;
            }
            let exact = values[keys.len() + k];
            let e = ((v[0] - exact.0).abs(), (v[1] - exact.1).abs(), (v[0] + v[1] - exact.0 - exact.1).abs());
            if std::env::var_os("TABLES_DEBUG").is_some() && e.0.max(e.1).max(e.2) > 0.02 {
                println!(
                    "  μ {:.3e} α {:.3e} η {:.4}: quadrature R {:.4} T {:.4}, interpolated R {:.4} T {:.4} at {:?}",
                    p.0, p.1, p.2, exact.0, exact.1, v[0], v[1], c
                );
            }
            e
        })
        .collect();
    println!("{label}: {} nodes, {points} points", keys.len());
    let stats = |e: &dyn Fn(&(f64, f64, f64)) -> f64| {
        let max = errors.iter().map(e).fold(0.0, f64::max);
        let rms = (errors.iter().map(|v| e(v) * e(v)).sum::<f64>() / errors.len() as f64).sqrt();
        (max, rms)
    };
    [stats(&|v| v.0), stats(&|v| v.1), stats(&|v| v.2)]
}
