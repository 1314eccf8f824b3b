//! The report example in its quick mode: every file is written, every number is finite, and
//! the figures are consistent (errors fall with time for the unbiased estimators, the
//! references and the furnace agree with one another).

#[path = "../examples/report/plot.rs"]
mod plot;
#[path = "../examples/path_tracer/png.rs"]
mod png;
#[path = "../examples/report/run.rs"]
mod run;

use run::{Config, Options};

fn quick_report() -> run::Summary {
    let out_dir = std::env::temp_dir().join(format!("microsurface-report-test-{}", std::process::id()));
    let opts = Options { quick: true, out_dir, threads: 2, progress: false };
    run::run(&opts).expect("the report runs")
}

#[test]
fn quick_report_is_complete_finite_and_consistent() {
    let summary = quick_report();

    // files
    for name in
        ["errors.csv", "efficiency.csv", "ratios.csv", "energy.csv", "cost.csv", "lobes.csv", "summary.md"]
    {
        assert!(summary.files.iter().any(|f| f.ends_with(name)), "{name} missing");
    }
    for config in Config::ALL {
        let png = format!("error_vs_time_{}.png", config.name());
        assert!(summary.files.iter().any(|f| f.ends_with(&png)), "{png} missing");
    }
    for f in &summary.files {
        let len = std::fs::metadata(f).expect("written").len();
        assert!(len > 0, "{} is empty", f.display());
    }
    for f in summary.files.iter().filter(|f| f.extension().is_some_and(|e| e == "csv")) {
        let text = std::fs::read_to_string(f).unwrap();
        for (i, line) in text.lines().enumerate().skip(1) {
            for field in line.split(',') {
                if let Ok(v) = field.parse::<f64>() {
                    // the single-scattering rows carry NaN for "no sampler" (cost table) and an
                    // infinite efficiency (a deterministic estimator has no variance)
                    let deterministic = line.contains(" single,") || line.contains(",single,");
                    assert!(v.is_finite() || deterministic, "{}:{}: non-finite {field}", f.display(), i + 1);
                }
            }
        }
    }

    // error falls with run time for every stochastic estimator: the RMSE at the largest batch
    // is below the RMSE of single samples wherever the estimator has any variance
    for row in &summary.efficiency {
        if row.std == 0.0 || row.curve.len() < 3 {
            continue;
        }
        let first = row.curve.first().unwrap().2;
        let last = row.curve.last().unwrap().2;
        assert!(
            last < first,
            "{} θi = {} {} {}: RMSE does not fall ({first:.3e} → {last:.3e})",
            row.config.name(),
            row.theta_i,
            row.wo,
            row.est.name()
        );
        assert!(row.ns_per_sample > 0.0 && row.efficiency > 0.0);
    }

    // (PT and BDPT estimating the same model is tested with adequate sample sizes in
    // tests/position_free.rs: at the quick report's 1024 samples the PT estimates of
    // near-specular configurations are too heavy-tailed for their sample SE to be trusted)

    // the white furnace of the non-absorptive walks: ∫eval = 1 within 5 SE, and the albedo
    // by sampling (reflected + transmitted) is exactly 1 (weights are 1)
    for (label, theta, r, t, orders, _, furnace, furnace_se) in &summary.energy {
        assert!((r + t - 1.0).abs() < 1e-9, "{label} θi = {theta}: R + T = {}", r + t);
        assert!((orders.iter().sum::<f64>() - 1.0).abs() < 1e-9);
        if *furnace_se > 0.0 {
            assert!(
                (furnace - 1.0).abs() <= 5.0 * furnace_se + 1e-3,
                "{label} θi = {theta}: furnace {furnace} ± {furnace_se}"
            );
        }
    }
    // the lobes per order are estimated directly, so every order (3+ included) is ≥ 0
    let lobes = summary.files.iter().find(|f| f.ends_with("lobes.csv")).expect("lobes.csv");
    let text = std::fs::read_to_string(lobes).unwrap();
    for (i, line) in text.lines().enumerate().skip(1) {
        for field in line.split(',').skip(3) {
            let v: f64 = field.parse().expect("a number");
            assert!(v >= 0.0, "lobes.csv:{}: negative value {field} in {line}", i + 1);
        }
    }

    // every efficiency ratio comes with a confidence interval around it
    assert_eq!(summary.ratios.len(), Config::ALL.len());
    for (config, a, b) in &summary.ratios {
        for r in [a, b] {
            assert!(
                r.pairs > 0 && r.lo.is_finite() && r.hi.is_finite() && r.lo < r.estimate && r.estimate < r.hi,
                "{}: ratio {r:?}",
                config.name()
            );
        }
    }
    assert!(summary.markdown.contains("95 % CI"));

    assert!(!summary.cost.is_empty());
    assert!(summary.markdown.contains("Efficiency ratios"));
}
