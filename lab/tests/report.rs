//! The report example in its quick mode: every file is written, every number is finite, the
//! figures are consistent (errors fall with time for the unbiased estimators, the furnace and
//! the albedos add up), and every SVG and the HTML page parse and reference only files that
//! exist.

use lab::report::configure::{Config, Est, LOBE_MATERIALS, Options, RunSize};
use lab::report::tables::{Family, Tabulated};
use lab::report::{configure, pipeline};
use std::path::Path;

fn quick_report() -> (pipeline::Report, std::path::PathBuf) {
    let out_dir = std::env::temp_dir().join(format!("microsurface-report-test-{}", std::process::id()));
    let opts = Options {
        size: RunSize::Quick,
        out_dir: out_dir.clone(),
        threads: 2,
        progress: false,
        results_page: None,
    };
    (pipeline::run(&opts).expect("the report runs"), out_dir)
}

/// The file names the report must write.
fn expected_files() -> Vec<String> {
    let mut names: Vec<String> = [
        "errors.csv",
        "efficiency.csv",
        "ratios.csv",
        "energy.csv",
        "cost.csv",
        "lobes.csv",
        "albedo_tables.csv",
        "albedo_tables.svg",
        "decision_map.svg",
        "summary.md",
        "index.html",
    ]
    .map(String::from)
    .to_vec();
    names.extend(Config::ALL.map(|c| format!("error_vs_time_{}.svg", c.name())));
    names.extend(LOBE_MATERIALS.map(|m| format!("lobes_{}.svg", m.name())));
    names
}

/// Every `<text>` of an SVG, concatenated.
fn svg_text(doc: &roxmltree::Document) -> String {
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter_map(|n| n.text())
        .collect::<Vec<_>>()
        .join("\n")
}

fn check_svgs(files: &[std::path::PathBuf]) {
    let mut count = 0;
    for f in files.iter().filter(|f| f.extension().is_some_and(|e| e == "svg")) {
        count += 1;
        let source = std::fs::read_to_string(f).unwrap();
        let doc = roxmltree::Document::parse(&source)
            .unwrap_or_else(|e| panic!("{} is not well-formed XML: {e}", f.display()));
        let root = doc.root_element();
        assert!(root.has_tag_name("svg"), "{}: root element is {:?}", f.display(), root.tag_name());
        for attr in ["width", "height"] {
            let v: f64 = root.attribute(attr).and_then(|v| v.parse().ok()).unwrap_or(0.0);
            assert!(v >= 600.0, "{}: {attr} = {v}, too small to read", f.display());
        }
        // an SVG that references other files could break: the figures are self-contained
        for n in doc.descendants() {
            for a in n.attributes() {
                assert!(
                    a.name() != "href",
                    "{}: <{}> references {}",
                    f.display(),
                    n.tag_name().name(),
                    a.value()
                );
            }
        }
        let text = svg_text(&doc);
        let name = f.file_name().unwrap().to_string_lossy();
        let needed: &[&str] = if name == "decision_map.svg" {
            &[
                "budget 0.5 %",
                "budget 3.0 %",
                "GGX gold",
                "Beckmann glass 2",
                "single",
                "compensated",
                "walk",
                "α",
            ]
        } else if name == "albedo_tables.svg" {
            &["|error|", "μ = cos θ", "α = 0.4", "conductor E", "dielectric R + T", "Beckmann"]
        } else if name.starts_with("error_vs_time") {
            &[
                "time (s, one thread)",
                "relative RMSE",
                "slope −½",
                "single scattering (a different model",
                "θi = 1.5",
            ]
        } else {
            &[
                "f·|cos θo| (sr⁻¹) in the plane of incidence",
                "order 1: ",
                "orders 3+: ",
                "total: ",
                "Heitz walk",
                "uncorrelated",
                "largest SE",
            ]
        };
        for s in needed {
            assert!(text.contains(s), "{name}: no text {s:?}");
        }
        // every number a plotted path or line carries is finite
        for n in doc.descendants().filter(|n| n.has_tag_name("polyline") || n.has_tag_name("path")) {
            for a in ["points", "d"] {
                if let Some(v) = n.attribute(a) {
                    assert!(
                        !v.contains("NaN") && !v.contains("inf"),
                        "{name}: non-finite coordinates in {v}"
                    );
                }
            }
        }
    }
    assert_eq!(
        count,
        Config::ALL.len() + LOBE_MATERIALS.len() + 2,
        "SVG figures (with albedo_tables.svg and decision_map.svg)"
    );
}

fn check_html(dir: &Path) {
    let path = dir.join("index.html");
    let source = std::fs::read_to_string(&path).unwrap();
    // the page is written as well-formed XHTML-compatible HTML, so an XML parser checks that
    // every tag is closed and nested
    let doc = roxmltree::Document::parse_with_options(
        &source,
        roxmltree::ParsingOptions { allow_dtd: true, ..Default::default() },
    )
    .unwrap_or_else(|e| panic!("index.html is not well-formed: {e}"));
    let mut images = Vec::new();
    for n in doc.descendants() {
        for attr in ["src", "href"] {
            if let Some(target) = n.attribute(attr) {
                assert!(
                    !target.contains("://") && !target.starts_with('/'),
                    "index.html links outside: {target}"
                );
                assert!(dir.join(target).is_file(), "index.html references {target}, which does not exist");
                if n.has_tag_name("img") {
                    images.push(target.to_string());
                }
            }
        }
    }
    for name in expected_files().iter().filter(|n| n.ends_with(".svg")) {
        assert!(images.contains(name), "index.html does not show {name}");
    }
    let ids: Vec<&str> = doc.descendants().filter_map(|n| n.attribute("id")).collect();
    for id in [
        "machine",
        "parameters",
        "ratios",
        "choice",
        "error-vs-time",
        "efficiency",
        "lobes",
        "energy",
        "cost",
    ] {
        assert!(ids.contains(&id), "index.html has no section {id}");
    }
    let text: String = doc.descendants().filter_map(|n| n.text()).collect::<Vec<_>>().join(" ");
    for s in ["CPU", "logical cores", "OS", "95 % CI", "lobe_rel_se", "--quick"] {
        assert!(text.contains(s), "index.html does not state {s:?}");
    }
}

#[test]
fn quick_report_is_complete_finite_and_consistent() {
    let (report, dir) = quick_report();
    let results = &report.results;

    // files
    for name in expected_files() {
        assert!(report.files.iter().any(|f| f.ends_with(&name)), "{name} missing");
    }
    for f in &report.files {
        let len = std::fs::metadata(f).expect("written").len();
        assert!(len > 0, "{} is empty", f.display());
    }
    for f in report.files.iter().filter(|f| f.extension().is_some_and(|e| e == "csv")) {
        let text = std::fs::read_to_string(f).unwrap();
        let columns = text.lines().next().unwrap().split(',').count();
        for (i, line) in text.lines().enumerate().skip(1) {
            assert_eq!(line.split(',').count(), columns, "{}:{}: {line}", f.display(), i + 1);
            for field in line.split(',') {
                // an empty field is "not applicable" (single scattering has no efficiency and
                // no sampler, the position-free models no furnace column)
                if let Ok(v) = field.parse::<f64>() {
                    assert!(v.is_finite(), "{}:{}: non-finite {field}", f.display(), i + 1);
                }
            }
        }
    }
    check_svgs(&report.files);
    check_html(&dir);

    // the conductor tables between their nodes keep the interpolation bound their docs state
    // (`AlbedoTable::directional`: 1.2e-3 GGX, 3.7e-3 Beckmann), up to the quadrature's ≲ 1e-5
    for c in results.tables.iter().filter(|c| c.tabulated == Tabulated::Conductor) {
        let bound = if c.family == Family::Ggx { 1.2e-3 } else { 3.7e-3 } + 1e-5;
        assert!(
            c.max_error() <= bound,
            "{:?} α {}: table error {:.2e} > {bound:.2e}",
            c.family,
            c.alpha,
            c.max_error()
        );
        assert!(c.points.len() == report.budget.table_points, "{:?}", c.points);
    }

    // error falls with run time for every stochastic estimator: the RMSE at the largest batch
    // is below the RMSE of single samples wherever the estimator has any variance
    for row in results.efficiency.iter().filter(|r| r.est != Est::Single) {
        if row.std == 0.0 || row.curve.len() < 3 {
            continue;
        }
        let (first, last) = (row.curve.first().unwrap().rel_rmse, row.curve.last().unwrap().rel_rmse);
        assert!(
            last < first,
            "{:?} {}: RMSE does not fall ({first:.3e} → {last:.3e})",
            row.case,
            row.est.name()
        );
        assert!(row.timing.ns_per_sample > 0.0 && row.efficiency.is_some_and(|e| e > 0.0));
    }
    // single scattering is measured against the walk's reference: a different model's error,
    // with no efficiency
    for row in results.efficiency.iter().filter(|r| r.est == Est::Single) {
        let walk = results.row(row.case, Est::Walk).expect("the walk's row");
        assert_eq!(row.reference, walk.reference, "{:?}", row.case);
        assert!(row.efficiency.is_none());
    }

    // (PT and BDPT estimating the same model is tested with adequate sample sizes in
    // tests/position_free/estimators.rs: at the quick report's 1024 samples the PT estimates of
    // near-specular configurations are too heavy-tailed for their sample SE to be trusted)

    // the white furnace of the non-absorptive walks: ∫eval = 1 within 5 SE, and the albedo
    // by sampling (reflected + transmitted) is exactly 1 (weights are 1), for every model
    for e in &results.energy {
        let label = format!("{} {:?} θi = {}", e.surface.name(), e.model, e.theta_i);
        assert!(
            (e.reflected + e.transmitted - 1.0).abs() < 1e-9,
            "{label}: R + T = {}",
            e.reflected + e.transmitted
        );
        assert!((e.orders.iter().sum::<f64>() - 1.0).abs() < 1e-9, "{label}: orders {:?}", e.orders);
        if let Some(f) = e.furnace.filter(|f| f.se > 0.0) {
            assert!((f.mean - 1.0).abs() <= 5.0 * f.se + 1e-3, "{label}: furnace {} ± {}", f.mean, f.se);
        }
    }
    // the lobes per order are estimated directly, so every order (3+ included) is ≥ 0; every
    // panel has its energies and a finite noise level
    assert_eq!(results.lobes.len(), LOBE_MATERIALS.len() * 3 * configure::THETAS.len());
    for panel in &results.lobes {
        assert!(panel.energy.is_some() && panel.peak > 0.0 && panel.max_rel_se.is_finite(), "{panel:?}");
        for p in &panel.points {
            assert!(p.orders.iter().all(|o| o.mean >= 0.0 && o.se.is_finite()), "{p:?}");
            assert!(p.samples >= report.budget.lobe_samples && p.samples <= report.budget.lobe_max_samples);
        }
    }

    // every efficiency ratio comes with a confidence interval around it
    assert_eq!(results.ratios.len(), 2 * Config::ALL.len());
    for r in &results.ratios {
        assert!(
            r.pairs > 0 && r.lo.is_finite() && r.hi.is_finite() && r.lo < r.estimate && r.estimate < r.hi,
            "{r:?}"
        );
    }
    assert!(report.markdown.contains("95 % CI"));
    // the invariance-principle estimator's efficiency table: written, and every ratio with
    // reliable cases a finite interval around its estimate
    assert!(report.files.iter().any(|f| f.ends_with("invariance_efficiency.csv")));
    assert!(report.markdown.contains("Efficiency of the invariance-principle estimator"));
    for (c, est, r) in report.invariance.ratios.iter().filter(|r| r.2.cases > 0) {
        assert!(
            r.lo <= r.estimate && r.estimate <= r.hi && r.lo > 0.0 && r.hi.is_finite(),
            "{c} {est:?}: {r:?}"
        );
    }
    assert!(report.markdown.contains("Efficiency ratios"));
    assert_eq!(results.choices.len(), Config::ALL.len());
    assert!(!results.cost.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}
