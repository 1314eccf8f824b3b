//! The per-order multiple-scattering energies of the F = 1 conductor, from the exact random
//! walk (Heitz et al. 2016): e_k(μ, α) for k = 2 … K and the tail k > K on the single-scattering
//! table's (x, r) grid, and their cosine-weighted averages over μ, into
//! `src/albedo/generated/orders.rs` and `target/tables/<family>_order_*.f32`.
//!
//! Every cell is the mean of [`WALKS`] walks of its own generator, seeded from (family, cell):
//! the result does not depend on the number of threads. With F = 1 a walk's weight is 1, so
//! e_k is the fraction of walks that leave after exactly k bounces and its standard error is
//! √(e_k (1 − e_k)/N) ≤ 0.5/√N = 1.95e-3.

use super::quadrature::Family;
use super::{N, alpha_of_node, mu_of, par_map};
use microsurface::rand::SeedableRng;
use microsurface::research::{Microsurface, UniformHeight, WalkOutputs};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Channels, Conductor, Directions, Ggx};
use std::fmt::Write as _;

/// Walks per cell: 2¹⁶, so that every cell's standard error is at most 0.5/256 < 2e-3.
pub(crate) const WALKS: usize = 1 << 16;
/// The last order tabulated by itself (orders 2 … K); the tail k > K is one more table.
const K: usize = microsurface::compensation::LAST_TABULATED_ORDER;
/// Tables per family: orders 2 … K and the tail.
const TABLES: usize = K;
/// The generator's seed.
const SEED: u64 = 0x6f72_6465_7273_0016;
/// Cells recomputed by `--quick` with the generator's own seed (bit for bit) and with another
/// seed (within the combined standard error).
const QUICK_CELLS: usize = 3;

type Pcg = rand_pcg::Pcg64Mcg;

/// The per-order tables of one family: `directional[t][cell]`, `average[t][j]`.
pub(crate) struct OrderTables {
    directional: Vec<Vec<f32>>,
    average: Vec<Vec<f32>>,
}

/// A generator for cell `cell` (direction cells 0 … 1023, average cells 1024 … 1055) of a
/// family, from `seed`.
fn generator(seed: u64, family: Family, cell: usize) -> Pcg {
    let f = match family {
        Family::Ggx => 0u64,
        Family::Beckmann => 1,
    };
    let mut state = seed ^ (f << 32) ^ (cell as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    // splitmix64 finalizer: neighbouring cells get unrelated streams
    state = (state ^ (state >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    state = (state ^ (state >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    Pcg::seed_from_u64(state ^ (state >> 31))
}

/// Counts of walks leaving after k = 2 … K bounces and after more, for `walks` walks with the
/// incident cosine drawn by `mu` (fixed, or cosine-weighted), walked in lanes
/// ([`Microsurface::sample_batch`]: GGX in eight f32 lanes, Beckmann by the scalar walk) from a
/// seed drawn after the cosines.
fn count<S: MicrosurfaceSlope>(
    slope: S,
    walks: usize,
    rng: &mut Pcg,
    mut mu: impl FnMut(&mut Pcg) -> f32,
) -> [u64; TABLES] {
    let surface = Microsurface::new(UniformHeight, slope, Conductor::perfect());
    BUFFERS.with_borrow_mut(|b| {
        // a grazing ray sees only the top of the surface: single scattering takes it all
        b.z.clear();
        b.z.extend((0..walks).map(|_| mu(rng)).filter(|&m| m > 0.0));
        let n = b.z.len();
        b.x.clear();
        b.x.extend(b.z.iter().map(|&m| (1.0 - m * m).max(0.0).sqrt()));
        for v in [&mut b.y, &mut b.wx, &mut b.wy, &mut b.wz, &mut b.r, &mut b.g, &mut b.b] {
            v.resize(n, 0.0);
        }
        b.bounces.resize(n, 0);
        let seed = microsurface::rand::Rng::next_u64(rng);
        let mut out = WalkOutputs {
            wo: Channels::new(&mut b.wx, &mut b.wy, &mut b.wz),
            weight: Channels::new(&mut b.r, &mut b.g, &mut b.b),
            bounces: &mut b.bounces,
        };
        let wi = Directions::new(&b.x, &b.y, &b.z).expect("equal lengths");
        surface.sample_batch(&wi, seed, &mut out).expect("equal lengths");
        let mut counts = [0u64; TABLES];
        for &k in &b.bounces {
            let k = k as usize;
            if k >= 2 {
                counts[(k - 2).min(TABLES - 1)] += 1;
            }
        }
        counts
    })
}

/// The walks' inputs and outputs, kept per thread across cells.
#[derive(Default)]
struct Buffers {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    wx: Vec<f32>,
    wy: Vec<f32>,
    wz: Vec<f32>,
    r: Vec<f32>,
    g: Vec<f32>,
    b: Vec<f32>,
    bounces: Vec<u32>,
}

thread_local! {
    static BUFFERS: std::cell::RefCell<Buffers> = std::cell::RefCell::new(Buffers::default());
}

/// The counts of one cell (direction cell or average cell) with `walks` walks from `seed`.
fn cell_counts(family: Family, cell: usize, walks: usize, seed: u64) -> [u64; TABLES] {
    let mut rng = generator(seed, family, cell);
    let (j, fixed_mu) = if cell < N * N {
        let (i, j) = (cell % N, cell / N);
        (j, Some(mu_of(i as f64 / (N - 1) as f64, alpha_of_node(j)) as f32))
    } else {
        (cell - N * N, None)
    };
    let alpha = alpha_of_node(j) as f32;
    // cosine-weighted incidence for the averages: μ = √u, u uniform in (0, 1]
    let mut draw = move |r: &mut Pcg| match fixed_mu {
        Some(m) => m,
        None => (1.0 - microsurface::rand::RngExt::random::<f32>(r)).sqrt(),
    };
    match family {
        Family::Ggx => count(Ggx::isotropic(alpha).expect("α > 0"), walks, &mut rng, &mut draw),
        Family::Beckmann => count(Beckmann::isotropic(alpha).expect("α > 0"), walks, &mut rng, &mut draw),
    }
}

/// The standard error of a fraction e of `walks` Bernoulli trials.
fn standard_error(e: f64, walks: usize) -> f64 {
    (e * (1.0 - e) / walks as f64).sqrt()
}

/// Builds the tables of one family; prints the largest standard error and tail.
pub(crate) fn build(family: Family) -> OrderTables {
    let name = family.name();
    let cells =
        par_map(N * N + N, &format!("{name} e_k(mu, alpha)"), |c| cell_counts(family, c, WALKS, SEED));
    let fraction = |c: u64| (c as f64 / WALKS as f64) as f32;
    let mut directional = vec![vec![0.0f32; N * N]; TABLES];
    let mut average = vec![vec![0.0f32; N]; TABLES];
    let (mut worst_se, mut worst_tail) = (0.0f64, 0.0f32);
    for (c, counts) in cells.iter().enumerate() {
        for (t, &k) in counts.iter().enumerate() {
            let e = fraction(k);
            worst_se = worst_se.max(standard_error(f64::from(e), WALKS));
            if c < N * N {
                directional[t][c] = e;
            } else {
                average[t][c - N * N] = e;
            }
        }
        worst_tail = worst_tail.max(fraction(counts[TABLES - 1]));
    }
    println!(
        "{name}: per-order energies, {WALKS} walks per cell, largest standard error {worst_se:.2e}, largest tail (k > {K}) {worst_tail:.3}"
    );
    assert!(worst_se <= f64::from(microsurface::compensation::ORDER_TABLE_MAX_STANDARD_ERROR));
    OrderTables { directional, average }
}

/// The Rust source of `src/albedo/generated/orders.rs`.
pub(crate) fn source(tables: &[(Family, OrderTables)]) -> String {
    let mut s = format!(
        "//! Generated by `cargo run --release -p tools --bin tables`: do not edit.\n//!\n//! Per-order energies \
         of the F = 1 conductor walk (see `ScatteringOrderTable` for the axes), {WALKS} walks per cell.\n\n"
    );
    for (family, t) in tables {
        let upper = family.name().to_uppercase();
        let _ = writeln!(
            s,
            "/// e_k(μ, α) of {}: orders 2 … {K}, then the tail; row-major, roughness slowest.",
            family.name()
        );
        let _ = writeln!(s, "pub(crate) static {upper}_ORDERS: [[f32; {}]; {TABLES}] = [", N * N);
        for table in &t.directional {
            push_rows(&mut s, table);
        }
        let _ = writeln!(s, "];\n/// The cosine-weighted averages of {}.", family.name());
        let _ = writeln!(s, "pub(crate) static {upper}_ORDERS_AVERAGE: [[f32; {N}]; {TABLES}] = [");
        for table in &t.average {
            push_rows(&mut s, table);
        }
        let _ = writeln!(s, "];");
    }
    s
}

fn push_rows(s: &mut String, values: &[f32]) {
    s.push_str("    [\n");
    for row in values.chunks(8) {
        let _ =
            writeln!(s, "        {},", row.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(", "));
    }
    s.push_str("    ],\n");
}

/// The name of table t in file names.
fn table_name(t: usize) -> String {
    if t == TABLES - 1 { "tail".to_string() } else { (t + 2).to_string() }
}

/// Writes `target/tables/<family>_order_<k|tail>[_average].f32` and appends their layout to
/// `README.txt` (written before by the single-scattering export).
pub(crate) fn export(tables: &[(Family, OrderTables)], dir: &std::path::Path) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    for (family, t) in tables {
        for (k, (d, a)) in t.directional.iter().zip(&t.average).enumerate() {
            for (suffix, values) in [("", d), ("_average", a)] {
                let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
                std::fs::write(
                    dir.join(format!("{}_order_{}{suffix}.f32", family.name(), table_name(k))),
                    bytes,
                )?;
            }
        }
    }
    let text = format!(
        "\n<family>_order_<k>.f32, k = 2 ... {K}, and <family>_order_tail.f32 (orders > {K}): 32 x 32 values\n\
         each, laid out and looked up as <family>_directional.f32 at x = i/31, r = j/31 (its every third\n\
         direction node and every other roughness row): the energy e_k(mu, alpha) that\n\
         leaves the F = 1 conductor after exactly k bounces of the random walk (mean of {WALKS} walks,\n\
         standard error at most {:.1e}). <family>_order_<k>_average.f32: 32 values, their\n\
         cosine-weighted averages 2 int e_k mu dmu at r = j/31 (linear in r). A conductor with a\n\
         per-channel mean Fresnel Fbar has multiple-scattering energy ~ sum_k e_k Fbar^k.\n",
        microsurface::compensation::ORDER_TABLE_MAX_STANDARD_ERROR
    );
    let path = dir.join("README.txt");
    let mut readme = std::fs::read_to_string(&path).unwrap_or_default();
    if !readme.contains("_order_") {
        readme.push_str(&text);
    }
    std::fs::write(path, readme)
}

/// `--quick`: recomputes a few cells with the generator's seed (bit for bit) and a few with
/// another seed (within the combined standard error, z from a Šidák family-wise level of 1e-3).
/// Returns the number of failures.
pub(crate) fn quick() -> usize {
    let mut failures = 0;
    let mut state = 0x5eed_0016_u64;
    let mut next = |m: usize| {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (state >> 33) as usize % m
    };
    let comparisons = 2 * QUICK_CELLS * TABLES; // the independent-seed comparisons, both families
    let z = validation::family_z(1e-3, comparisons);
    for family in [Family::Ggx, Family::Beckmann] {
        let table = match family {
            Family::Ggx => microsurface::compensation::ScatteringOrderTable::GGX,
            Family::Beckmann => microsurface::compensation::ScatteringOrderTable::BECKMANN,
        };
        let shipped = |t: usize, c: usize| {
            if c < N * N { table.directional_nodes(t)[c] } else { table.average_nodes(t)[c - N * N] }
        };
        for _ in 0..QUICK_CELLS {
            let c = next(N * N + N);
            let counts = cell_counts(family, c, WALKS, SEED);
            for (t, &k) in counts.iter().enumerate() {
                let e = (k as f64 / WALKS as f64) as f32;
                if e.to_bits() != shipped(t, c).to_bits() {
                    failures += 1;
                    println!(
                        "{} order table {} cell {c}: recomputed {e:?}, shipped {:?}",
                        family.name(),
                        table_name(t),
                        shipped(t, c)
                    );
                }
            }
            let c = next(N * N + N);
            let counts = cell_counts(family, c, WALKS, SEED ^ 0xa5a5);
            for (t, &k) in counts.iter().enumerate() {
                let (e, s) = (k as f64 / WALKS as f64, f64::from(shipped(t, c)));
                let se = (standard_error(e, WALKS).powi(2) + standard_error(s, WALKS).powi(2)).sqrt();
                if (e - s).abs() > z * se + 1e-7 {
                    failures += 1;
                    println!(
                        "{} order table {} cell {c}: independent estimate {e:.5}, shipped {s:.5}, combined SE {se:.2e}, z = {z:.2}",
                        family.name(),
                        table_name(t)
                    );
                }
            }
        }
    }
    println!(
        "tables --quick: {} per-order cells recomputed ({} comparisons, z = {z:.2}), {failures} differ",
        4 * QUICK_CELLS,
        comparisons
    );
    failures
}
