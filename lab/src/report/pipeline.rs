//! The report's stages in order: configure → measure → reduce → plot → write.

use super::configure::{Budget, Options};
use super::invariance::EfficiencyTable;
use super::reduce::Results;
use std::path::PathBuf;
use std::time::Instant;

/// What one run of the report produced.
pub struct Report {
    pub budget: Budget,
    pub results: Results,
    /// The efficiency table of the invariance-principle estimator.
    pub invariance: EfficiencyTable,
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
    let mut written = super::write::write(opts, &budget, &results, &figures, start.elapsed().as_secs_f64())?;
    // the invariance-principle estimator's efficiency table, after the other stages (timed
    // on its own), appended to summary.md and written as CSV
    let invariance = super::invariance::run(opts, &budget);
    let table = invariance.markdown();
    let csv = opts.out_dir.join("invariance_efficiency.csv");
    std::fs::write(&csv, invariance.csv())?;
    written.files.push(csv);
    let summary = opts.out_dir.join("summary.md");
    let mut md = std::fs::read_to_string(&summary).unwrap_or_default();
    md.push('\n');
    md.push_str(&table);
    std::fs::write(&summary, &md)?;
    written.markdown.push('\n');
    written.markdown.push_str(&table);
    if let Some(page) = super::results_page::write(opts, &written.markdown, start.elapsed().as_secs_f64())? {
        written.files.push(page);
    }
    Ok(Report {
        budget,
        results,
        invariance,
        files: written.files,
        markdown: written.markdown,
        seconds: start.elapsed().as_secs_f64(),
    })
}
