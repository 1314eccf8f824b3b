//! The crate's main job: a report of every estimator's accuracy against run time, the lobes
//! and energy per scattering order, and the cost of every model, measured on this machine.
//!
//! `cargo run --release --example report -- [--quick] [--out DIR]` writes CSV files, PNG
//! plots and `summary.md` into DIR (default `target/report`) and prints the summary.

mod plot;
#[path = "../path_tracer/png.rs"]
mod png;
mod run;

const USAGE: &str = "usage: cargo run --release --example report -- [--quick] [--out DIR]

  --quick    a small run (seconds instead of a minute)
  --out DIR  output directory (default target/report)
  --help     print this message

Writes CSV files, PNG plots and summary.md into DIR and prints the summary. A progress bar
goes to stderr when it is a terminal.";

/// Prints the usage and the problem to stderr and exits with status 2.
fn usage_error(problem: &str) -> ! {
    eprintln!("{problem}\n\n{USAGE}");
    std::process::exit(2)
}

fn main() -> std::io::Result<()> {
    use std::io::IsTerminal;
    let mut args = std::env::args().skip(1);
    let mut opts = run::Options {
        quick: false,
        out_dir: run::default_out_dir(),
        threads: std::thread::available_parallelism().map_or(2, |n| n.get()),
        progress: std::io::stderr().is_terminal(),
    };
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--quick" => opts.quick = true,
            "--out" => {
                opts.out_dir = args.next().unwrap_or_else(|| usage_error("--out needs a directory")).into()
            }
            "-h" | "--help" => {
                println!("{USAGE}");
                return Ok(());
            }
            other => usage_error(&format!("unknown argument {other}")),
        }
    }
    let start = std::time::Instant::now();
    let summary = run::run(&opts)?;
    println!("{}", summary.markdown);
    println!(
        "wrote {} files into {} in {:.1} s",
        summary.files.len(),
        opts.out_dir.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
