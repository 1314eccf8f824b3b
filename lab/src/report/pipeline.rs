//! The report's stages in order: configure → measure → reduce → plot → write.

use super::configure::{Budget, Options};
use super::reduce::Results;
use std::path::PathBuf;
use std::time::Instant;

/// What one run of the report produced.
pub struct Report {
    pub budget: Budget,
    pub results: Results,
    /// Every file written (CSV, SVG, `summary.md`, `index.html`).
    pub files: Vec<PathBuf>,
    pub markdown: String,
    /// Wall-clock seconds of the whole run.
    pub seconds: f64,
}

/// Runs every stage and writes the files into `opts.out_dir`.
pub fn run(opts: &Options) -> std::io::Result<Report> {
    let start = Instant::now();
    let budget = Budget::new(opts.size);
    let measurements = super::measure::measure(opts, &budget);
    let results = super::reduce::reduce(measurements);
    let figures =
        super::plot::figures(&results, &budget).map_err(|e| std::io::Error::other(e.to_string()))?;
    let written = super::write::write(opts, &budget, &results, &figures, start.elapsed().as_secs_f64())?;
    Ok(Report {
        budget,
        results,
        files: written.files,
        markdown: written.markdown,
        seconds: start.elapsed().as_secs_f64(),
    })
}
