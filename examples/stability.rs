//! The crate's stability report: the accuracy map (worst cases per function of the f32 crate
//! against a double-precision reference on a dense grid over the whole parameter domain) and
//! the stiff-walk table (white-furnace albedo ± standard error and mean walk length of every
//! estimator at α = 1e-3, α = 4, θi = 1.57 rad and near total internal reflection).
//!
//! `cargo run --release --example stability` prints both as markdown. The same measurements
//! are asserted by `tests/accuracy_map.rs` and `tests/stiff.rs`.
#[path = "../tests/common/mod.rs"]
mod common;
#[path = "stability/reference.rs"]
mod reference;
#[path = "stability/stiff.rs"]
mod stiff;

const USAGE: &str = "usage: cargo run --release --example stability

Prints the accuracy map and the stiff-walk table as markdown. Takes no arguments other than
--help.";

fn main() {
    if let Some(arg) = std::env::args().nth(1) {
        if arg == "-h" || arg == "--help" {
            println!("{USAGE}");
            return;
        }
        eprintln!("unknown argument {arg}\n\n{USAGE}");
        std::process::exit(2);
    }
    println!("# Stability report\n");
    println!("## Accuracy map\n");
    println!(
        "Error e = |value − reference| / max(|reference|, floor), reference in f64 (statrs) on the same \
         f32 inputs; floor = {:.0e} (relative error wherever |reference| ≥ 1e-30), {:.0e} for reflectances. \
         Grid: α log-spaced over [1e-4, 4] (12 isotropic, 5 anisotropic up to 1e4:1), cos θ from ±1 down to \
         1e-9 and exactly 0, 6 azimuths (4 for pairs of directions). Three worst cases per function.\n",
        reference::TINY,
        reference::REFLECTANCE_FLOOR
    );
    let map = reference::accuracy_map();
    println!("{}", reference::markdown_table(&map));
    println!("## Stiff walks\n");
    println!(
        "∫ eval dωo by importance sampling (mixture {:.0}% phase function + {:.0}% cosine, exact densities); \
         expected 1 (non-absorptive). Mean bounces of `sample()` against the stated bound.\n",
        100.0 * stiff::PHASE_SHARE,
        100.0 * (1.0 - stiff::PHASE_SHARE)
    );
    println!("{}", stiff::markdown_table(&stiff::all_runs()));
}
