//! The results page `docs/results.md`: the report's tables with the machine and the date of the
//! run in its header, rewritten by every full run. The figures the README and the crate's
//! documentation quote come from it.

use super::configure::{Options, RunSize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

/// Where a full run writes the page: `docs/results.md` of the repository.
pub fn default_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/results.md")
}

/// The page for the tables of one run (`tables`, markdown), the run's wall-clock `seconds` and
/// the machine it ran on.
pub fn page(opts: &Options, tables: &str, seconds: f64) -> String {
    let mut page = String::from("# Results\n\n");
    let _ = writeln!(
        page,
        "Measured by `cargo run --release -p lab --bin report` (full run, {seconds:.0} s wall clock) on {} UTC. \
         Rewritten by every full run: do not edit by hand. Times are single-thread; only ratios carry \
         from one machine to another.\n",
        utc_date_time(SystemTime::now())
    );
    page.push_str("| machine | |\n|---|---|\n");
    for (key, value) in super::write::machine(opts.threads) {
        let _ = writeln!(page, "| {key} | {value} |");
    }
    page.push('\n');
    // the tables' own top-level heading is the page's
    page.push_str(tables.trim_start_matches("# microsurface report\n\n"));
    page
}

/// Writes the page of a full run (a quick run leaves the committed page alone) and returns its
/// path.
pub fn write(opts: &Options, tables: &str, seconds: f64) -> std::io::Result<Option<PathBuf>> {
    if opts.size != RunSize::Full {
        return Ok(None);
    }
    let path = opts.results_page.clone().unwrap_or_else(default_path);
    std::fs::write(&path, page(opts, tables, seconds))?;
    Ok(Some(path))
}

/// "YYYY-MM-DD HH:MM" of a time, in UTC (the civil calendar from days since 1970-01-01).
fn utc_date_time(t: SystemTime) -> String {
    let secs = t.duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs()) as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Howard Hinnant's days-to-civil
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02} {:02}:{:02}", rem / 3600, rem % 3600 / 60)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn dates_are_civil_utc() {
        assert_eq!(utc_date_time(UNIX_EPOCH), "1970-01-01 00:00");
        // 2000-02-29 12:34 UTC (a leap day) = 951 827 640 s
        assert_eq!(utc_date_time(UNIX_EPOCH + Duration::from_secs(951_827_640)), "2000-02-29 12:34");
        // 2026-12-31 23:59 UTC = 1 798 761 540 s
        assert_eq!(utc_date_time(UNIX_EPOCH + Duration::from_secs(1_798_761_540)), "2026-12-31 23:59");
    }
}
