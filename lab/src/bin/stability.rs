//! The crate's stability report: the accuracy map (worst cases per function of the f32 crate
//! against a double-precision reference on a dense grid over the whole parameter domain) and
//! the stiff-walk table (white-furnace albedo ± standard error and mean walk length of every
//! estimator at α = 1e-3, α = 4, θi = 1.57 rad and near total internal reflection).
//!
//! `cargo run --release -p lab --bin stability` prints both as markdown (`validation::stability`).
//! The same measurements are asserted by `tests/special/accuracy_map.rs` and
//! `tests/walk/stiff.rs`.

const USAGE: &str = "usage: cargo run --release -p lab --bin stability

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
    print!("{}", validation::stability::markdown());
}
