//! The report: every estimator's accuracy against run time, the lobes
//! and energy per scattering order, and the cost of every model, measured on this machine.
//!
//! `cargo run --release -p lab --bin report -- [--quick] [--out DIR] [--results FILE]` writes CSV
//! files, SVG figures, `summary.md` and the page `index.html` into DIR (default
//! `target/report`), prints the summary and, in a full run, rewrites the results page
//! `docs/results.md` (or FILE) that the docs quote. The stages (`lab::report`), one file each: `configure` (what and how much), `measure`
//! (per-sample values, timings, references, energy, lobes, cost), `reduce` (errors against
//! time, efficiency ratios with confidence intervals, lobe panels), `plot` (SVG figures) and
//! `write` (CSV, Markdown, HTML); `pipeline` runs them in order.

use lab::report::{configure, pipeline};

const USAGE: &str = "usage: cargo run --release -p lab --bin report -- [--quick] [--out DIR] [--results FILE]

  --quick         a small run (seconds instead of minutes); leaves the results page alone
  --out DIR       output directory (default target/report)
  --results FILE  where a full run writes the results page (default docs/results.md)
  --help          print this message

Writes CSV files, SVG figures, summary.md and index.html into DIR, prints the summary and, in a
full run, rewrites the results page. A progress bar goes to stderr when it is a terminal.";

/// Prints the usage and the problem to stderr and exits with status 2.
fn usage_error(problem: &str) -> ! {
    eprintln!("{problem}\n\n{USAGE}");
    std::process::exit(2)
}

/// Stage 1 (configure) from the command line.
fn options() -> Option<configure::Options> {
    use std::io::IsTerminal;
    let mut args = std::env::args().skip(1);
    let mut opts = configure::Options {
        size: configure::RunSize::Full,
        out_dir: configure::default_out_dir(),
        threads: std::thread::available_parallelism().map_or(2, |n| n.get()),
        progress: std::io::stderr().is_terminal(),
        results_page: None,
    };
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--quick" => opts.size = configure::RunSize::Quick,
            "--out" => {
                opts.out_dir = args.next().unwrap_or_else(|| usage_error("--out needs a directory")).into()
            }
            "--results" => {
                opts.results_page =
                    Some(args.next().unwrap_or_else(|| usage_error("--results needs a file")).into())
            }
            "-h" | "--help" => {
                println!("{USAGE}");
                return None;
            }
            other => usage_error(&format!("unknown argument {other}")),
        }
    }
    Some(opts)
}

fn main() -> std::io::Result<()> {
    let Some(opts) = options() else { return Ok(()) };
    let report = pipeline::run(&opts)?;
    println!("{}", report.markdown);
    println!(
        "wrote {} files into {} in {:.1} s (open {})",
        report.files.len(),
        opts.out_dir.display(),
        report.seconds,
        opts.out_dir.join("index.html").display()
    );
    Ok(())
}
