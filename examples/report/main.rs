//! The crate's main job: a report of every estimator's accuracy against run time, the lobes
//! and energy per scattering order, and the cost of every model, measured on this machine.
//!
//! `cargo run --release --example report -- [--quick] [--out DIR]` writes CSV files, PNG
//! plots and `summary.md` into DIR (default `target/report`) and prints the summary.

mod plot;
#[path = "../path_tracer/png.rs"]
mod png;
mod run;

fn main() -> std::io::Result<()> {
    let mut args = std::env::args().skip(1);
    let mut opts = run::Options {
        quick: false,
        out_dir: run::default_out_dir(),
        threads: std::thread::available_parallelism().map_or(2, |n| n.get()),
        progress: true,
    };
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--quick" => opts.quick = true,
            "--out" => opts.out_dir = args.next().expect("--out needs a directory").into(),
            other => panic!("unknown argument {other} (use --quick, --out DIR)"),
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
