//! Stage 5, write: the CSV files, `summary.md`, the SVG figures and the HTML page
//! `index.html` (every figure and table, the machine and the run's parameters).

use super::configure::{Budget, Config, Est, Model, Options, RunSize};
use super::measure::{TIMING_CHUNKS, cost_surfaces};
use super::plot::Figure;
use super::reduce::{RatioKind, Results};
use microsurface::techniques::{Candidates, ChosenTechnique};
use std::fmt::Write as _;
use std::path::PathBuf;

/// What was written.
pub struct Written {
    pub files: Vec<PathBuf>,
    pub markdown: String,
}

/// A table: a caption, a header and rows of cells (plain text, escaped when written as HTML).
struct Table {
    id: &'static str,
    caption: String,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
    note: String,
}

impl Table {
    fn markdown(&self) -> String {
        let mut md = format!("## {}\n\n| {} |\n|", self.caption, self.header.join(" | "));
        md.push_str(&"---|".repeat(self.header.len()));
        md.push('\n');
        for row in &self.rows {
            let _ = writeln!(md, "| {} |", row.join(" | "));
        }
        if !self.note.is_empty() {
            let _ = writeln!(md, "\n{}", self.note);
        }
        md
    }

    fn html(&self) -> String {
        let mut h = format!("<h2 id=\"{}\">{}</h2>\n<table>\n<thead><tr>", self.id, escape(&self.caption));
        for c in &self.header {
            let _ = write!(h, "<th>{}</th>", escape(c));
        }
        h.push_str("</tr></thead>\n<tbody>\n");
        for row in &self.rows {
            h.push_str("<tr>");
            for c in row {
                let _ = write!(h, "<td>{}</td>", escape(c));
            }
            h.push_str("</tr>\n");
        }
        h.push_str("</tbody>\n</table>\n");
        if !self.note.is_empty() {
            let _ = writeln!(h, "<p class=\"note\">{}</p>", escape(&self.note));
        }
        h
    }
}

/// Escapes text for HTML and XML.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn ratio_table(results: &Results) -> Table {
    let mut rows = Vec::new();
    for config in Config::ALL {
        let mut row = vec![config.label().to_string()];
        for kind in [RatioKind::PtOverWalk, RatioKind::BdptOverPt] {
            if let Some(r) = results.ratios.iter().find(|r| r.config == config && r.kind == kind) {
                row.push(format!("{:.2} [{:.2}, {:.2}]", r.estimate, r.lo, r.hi));
                row.push(format!("{:.2}, {:.2}", r.variance_ratio, r.cost_ratio));
            }
        }
        rows.push(row);
    }
    Table {
        id: "ratios",
        caption: "Efficiency ratios (geometric means over θi ∈ {0, 1, 1.5} and three ωo)".into(),
        header: vec![
            "configuration".into(),
            "PT-corr / Heitz walk [95 % CI]".into(),
            "variance ÷, cost ×".into(),
            "BDPT-corr / PT-corr [95 % CI]".into(),
            "variance ÷, cost ×".into(),
        ],
        rows,
        note: format!(
            "Efficiency = 1 / (relative variance × seconds per sample); a ratio above 1 means the first estimator reaches a given error sooner. \
             The interval propagates (delta method) the standard errors of the sample variances (from the variance of the squared deviations), \
             of the times per sample ({TIMING_CHUNKS} timed chunks per run) and of the references; it covers one run's sampling noise, not changes of machine load \
             between runs. \"variance ÷\": how many times lower the first estimator's relative variance is; \"cost ×\": how many times more it costs per sample \
             (geometric means)."
        ),
    }
}

fn choice_table(results: &Results) -> Table {
    let ests: Vec<Est> = Est::ALL.into_iter().filter(|&e| !e.is_biased()).collect();
    let mut header = vec!["configuration".to_string()];
    header.extend(ests.iter().map(|e| e.name().to_string()));
    header.push("most efficient".into());
    let rows = results
        .choices
        .iter()
        .map(|c| {
            let mut row = vec![c.config.label().to_string()];
            for e in &ests {
                let v = c.relative_to_walk.iter().find(|(x, _)| x == e).map_or(f64::NAN, |x| x.1);
                row.push(format!("{v:.2}"));
            }
            row.push(c.best.name().to_string());
            row
        })
        .collect();
    Table {
        id: "choice",
        caption: "Technique choice: efficiency relative to the Heitz walk (geometric mean over θi and ωo)".into(),
        header,
        rows,
        note: "Above 1: reaches a given relative error sooner than the walk on this machine. The uncorrelated and correlated \
               position-free models are different models from the walk (and from each other): choose the model first, then its \
               fastest estimator. Single scattering is left out: it is a different model, exact and cheapest, and loses the higher orders."
            .into(),
    }
}

/// The technique chooser's decision map in words: per slope family, material and budget, the
/// roughnesses at which the choice changes.
fn decision_table() -> Table {
    let mut header = vec!["slopes, material".to_string()];
    header.extend(super::decision::BUDGETS.iter().map(|b| format!("budget {:.1} %", b * 100.0)));
    let rows = super::decision::map()
        .iter()
        .map(|row| {
            let mut cells = vec![row.label.clone()];
            cells.extend(row.choices.iter().map(|c| super::decision::transitions(c)));
            cells
        })
        .collect();
    let (lo, hi) = super::decision::ALPHA_RANGE;
    Table {
        id: "decision",
        caption: "Technique chooser: the cheapest technique within an albedo error budget, over α".into(),
        header,
        rows,
        note: format!(
            "microsurface::techniques::Choice on {} log-spaced α from {lo} to {hi}: where the choice changes along α (\"single < 0.1 ≤ compensated\": \
             single scattering below α = 0.1, the compensated lobe from there). Error: the hemispherical albedo error against the walk; \
             single scattering's from the albedo tables, the compensated lobes' bounds measured by `lab --bin techniques`. \
             Costs per bounce relative to single scattering: compensated {:.2} (conductor) and {:.2} (glass), walk {:.2} and {:.2}.",
            super::decision::ALPHA_STEPS,
            cost(true, ChosenTechnique::Compensated),
            cost(false, ChosenTechnique::Compensated),
            cost(true, ChosenTechnique::RandomWalk),
            cost(false, ChosenTechnique::RandomWalk),
        ),
    }
}

/// The chooser's cost of a technique on GGX α = 0.5 (gold or glass).
fn cost(conductor: bool, t: ChosenTechnique) -> f32 {
    let slope = microsurface::Ggx::isotropic(0.5).expect("valid α");
    let candidates = if conductor {
        Candidates::new(&slope, &microsurface::Conductor::perfect())
    } else {
        Candidates::new(&slope, &microsurface::Dielectric::new(1.5).expect("valid η"))
    }
    .expect("valid");
    match t {
        ChosenTechnique::SingleScattering => 1.0,
        ChosenTechnique::Compensated => candidates.compensated_cost,
        ChosenTechnique::RandomWalk => candidates.walk_cost,
    }
}

fn efficiency_table(results: &Results) -> Table {
    let mut header = vec!["configuration".to_string(), "θi".into(), "ωo".into()];
    header.extend(Est::ALL.iter().filter(|&&e| !e.is_biased()).map(|e| e.name().to_string()));
    let rows = results
        .efficiency
        .iter()
        .filter(|r| r.est == Est::Walk)
        .map(|walk| {
            let mut row = vec![
                walk.case.config.name().to_string(),
                walk.case.theta_i().to_string(),
                walk.case.wo.name().into(),
            ];
            for est in Est::ALL.into_iter().filter(|&e| !e.is_biased()) {
                let e = results.row(walk.case, est).and_then(|r| r.efficiency).unwrap_or(f64::NAN);
                row.push(format!("{e:.3e}"));
            }
            row
        })
        .collect();
    Table {
        id: "efficiency",
        caption: "Efficiency per estimator and case (1/s: 1 / (relative variance × seconds per sample))"
            .into(),
        header,
        rows,
        note: String::new(),
    }
}

fn energy_table(results: &Results) -> Table {
    let rows = results
        .energy
        .iter()
        .map(|e| {
            let mut row = vec![e.surface.name(), e.model.name().to_string(), e.theta_i.to_string()];
            row.push(format!("{:.4}", e.reflected));
            row.push(format!("{:.4}", e.transmitted));
            row.extend(e.orders.iter().map(|o| format!("{o:.4}")));
            row.push(format!("{:.2}", e.mean_bounces));
            row.push(e.furnace.map_or("—".into(), |f| format!("{:.3} ± {:.3}", f.mean, f.se)));
            row
        })
        .collect();
    Table {
        id: "energy",
        caption: "Energy per scattering order (albedo from sampled scatterings; white furnace ∫f cos dωo ± SE for the walk)".into(),
        header: ["surface", "model", "θi", "R", "T", "order 1", "order 2", "order 3", "order 4+", "bounces", "furnace"]
            .map(String::from)
            .to_vec(),
        rows,
        note: "R + T = 1 for these non-absorptive surfaces (sampled weights are 1); the furnace integrates eval over the sphere.".into(),
    }
}

fn cost_table(results: &Results) -> Table {
    let rows = results
        .cost
        .iter()
        .map(|c| {
            vec![
                c.surface.name(),
                c.est.name().to_string(),
                format!("{:.0}", c.ns_per_eval),
                c.ns_per_sample.map_or("—".into(), |s| format!("{s:.0}")),
                c.mean_bounces.map_or("—".into(), |b| format!("{b:.2}")),
            ]
        })
        .collect();
    Table {
        id: "cost",
        caption: format!(
            "Cost (single thread, θi = {}, α = 0.5; eval rotates 1024 pre-generated ωo, uniform on the hemisphere or, for the dielectric, the sphere; inputs behind black_box)",
            super::measure::COST_THETA_I
        ),
        header: ["surface", "estimator", "ns / eval", "ns / sample", "mean bounces of sample"]
            .map(String::from)
            .to_vec(),
        rows,
        note: format!("{} surfaces; single scattering has no sampler of its own.", cost_surfaces().len()),
    }
}

fn lobe_table(results: &Results) -> Table {
    let rows = results
        .lobes
        .iter()
        .map(|p| {
            vec![
                p.material.name().to_string(),
                p.model.name().to_string(),
                p.theta_i.to_string(),
                format!("{:.4}", p.peak),
                format!("{:.2} %", 100.0 * p.max_rel_se),
                format!("{}–{}", p.samples.0, p.samples.1),
            ]
        })
        .collect();
    Table {
        id: "lobe-noise",
        caption: "Lobe noise: the largest standard error of a plotted total, relative to the panel's peak".into(),
        header: ["material", "model", "θi", "peak f·|cos θo| (sr⁻¹)", "largest SE / peak", "sampled scatterings"]
            .map(String::from)
            .to_vec(),
        rows,
        note: "Orders 2 and 3+ of a panel are a histogram of its model's own sampled scatterings, in bins of θo in the plane of \
               incidence (Δθ × ±Δθ/2 about it): a pilot round gives the SE of its noisiest bin, and the panel gets as many rounds as make \
               the SE of the points interpolated from it (0.79 × a bin's) √(1 − 0.25²) × the target fraction of the panel's peak; order 1 is evaluated at twice as many angles (orders 2 and 3+ \
               interpolated linearly between the bins' centres there) until its SE is 0.25 × the target (the parameters below), or the \
               caps are reached; the figures state the largest SE of a plotted total reached."
            .into(),
    }
}

/// (name, value) of the machine the report ran on.
pub(crate) fn machine(threads: usize) -> Vec<(&'static str, String)> {
    let read = |p: &str| std::fs::read_to_string(p).unwrap_or_default();
    let cpu = read("/proc/cpuinfo")
        .lines()
        .find(|l| l.starts_with("model name"))
        .and_then(|l| l.split(':').nth(1))
        .map_or_else(|| "unknown".to_string(), |s| s.trim().to_string());
    let os = read("/etc/os-release")
        .lines()
        .find_map(|l| l.strip_prefix("PRETTY_NAME="))
        .map_or_else(|| std::env::consts::OS.to_string(), |s| s.trim_matches('"').to_string());
    let kernel = read("/proc/sys/kernel/osrelease").trim().to_string();
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let load = read("/proc/loadavg").split_whitespace().take(3).collect::<Vec<_>>().join(" ");
    vec![
        ("CPU", cpu),
        ("logical cores (available_parallelism)", cores.to_string()),
        ("worker threads", threads.to_string()),
        ("OS", format!("{os}, {} {}", std::env::consts::OS, std::env::consts::ARCH)),
        ("kernel", if kernel.is_empty() { "unknown".into() } else { kernel }),
        ("load average at the end (1, 5, 15 min)", if load.is_empty() { "unknown".into() } else { load }),
    ]
}

fn csv_files(results: &Results) -> Vec<(&'static str, String)> {
    let mut errors = String::from("config,theta_i,wo,estimator,samples,time_s,rel_rmse\n");
    let mut eff = String::from(
        "config,theta_i,wo,estimator,mean,std,variance_se,ns_per_sample,ns_se,reference,reference_se,efficiency_per_s\n",
    );
    for r in &results.efficiency {
        let key =
            format!("{},{},{},{}", r.case.config.name(), r.case.theta_i(), r.case.wo.name(), r.est.name());
        for p in &r.curve {
            let _ = writeln!(errors, "{key},{},{:.3e},{:.4e}", p.samples, p.seconds, p.rel_rmse);
        }
        let _ = writeln!(
            eff,
            "{key},{:.6e},{:.4e},{:.4e},{:.1},{:.2},{:.6e},{:.2e},{}",
            r.mean,
            r.std,
            r.variance_se,
            r.timing.ns_per_sample,
            r.timing.ns_se,
            r.reference.mean,
            r.reference.se,
            r.efficiency.map_or(String::new(), |e| format!("{e:.4e}"))
        );
    }
    let mut ratios = String::from("config,ratio,estimate,ci95_lo,ci95_hi,variance_ratio,cost_ratio,pairs\n");
    for r in &results.ratios {
        let _ = writeln!(
            ratios,
            "{},{},{:.4},{:.4},{:.4},{:.4},{:.4},{}",
            r.config.name(),
            r.kind.name(),
            r.estimate,
            r.lo,
            r.hi,
            r.variance_ratio,
            r.cost_ratio,
            r.pairs
        );
    }
    let mut energy = String::from(
        "material,slope,alpha,model,theta_i,reflected,transmitted,order1,order2,order3,order4plus,mean_bounces,furnace,furnace_se\n",
    );
    for e in &results.energy {
        let (f, fse) = e
            .furnace
            .map_or((String::new(), String::new()), |f| (format!("{:.5}", f.mean), format!("{:.5}", f.se)));
        let _ = writeln!(
            energy,
            "{},{},{},{},{},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{:.3},{f},{fse}",
            e.surface.material.name(),
            e.surface.slope.name(),
            e.surface.alpha,
            e.model.name(),
            e.theta_i,
            e.reflected,
            e.transmitted,
            e.orders[0],
            e.orders[1],
            e.orders[2],
            e.orders[3],
            e.mean_bounces
        );
    }
    let mut lobes = String::from(
        "material,model,theta_i,theta_o,order1,order1_se,order2,order2_se,order3plus,order3plus_se,total,total_se\n",
    );
    for panel in &results.lobes {
        for p in &panel.points {
            let _ = write!(lobes, "{},{},{},{:.4}", p.material.name(), p.model.name(), p.theta_i, p.theta_o);
            for o in p.orders.iter().chain(std::iter::once(&p.total())) {
                let _ = write!(lobes, ",{:.5e},{:.2e}", o.mean, o.se);
            }
            lobes.push('\n');
        }
    }
    let mut cost = String::from("surface,estimator,ns_per_eval,ns_per_sample,mean_bounces_of_sample\n");
    for c in &results.cost {
        let _ = writeln!(
            cost,
            "{},{},{:.1},{},{}",
            c.surface.name(),
            c.est.name(),
            c.ns_per_eval,
            c.ns_per_sample.map_or(String::new(), |s| format!("{s:.1}")),
            c.mean_bounces.map_or(String::new(), |b| format!("{b:.3}"))
        );
    }
    let mut tables = String::from("family,table,alpha,mu,table_value,quadrature,error\n");
    for c in &results.tables {
        for &(mu, t, q) in &c.points {
            let _ = writeln!(
                tables,
                "{},{:?},{},{:.6e},{:.7},{:.7},{:.3e}",
                c.family.label(),
                c.tabulated,
                c.alpha,
                mu,
                t,
                q,
                t - q
            );
        }
    }
    vec![
        ("errors.csv", errors),
        ("efficiency.csv", eff),
        ("ratios.csv", ratios),
        ("energy.csv", energy),
        ("lobes.csv", lobes),
        ("cost.csv", cost),
        ("albedo_tables.csv", tables),
    ]
}

/// The path tracer's sweep images with their captions: rendered by
/// `cargo run --release -p lab --bin path_tracer` and committed under `docs/`.
const RENDERS: [(&str, &str); 2] = [
    (
        "sweep.png",
        "GGX roughness sweep rendered by the example path tracer (next-event estimation, MIS, Russian roulette): \
         columns α = 0.05 … 1, rows gold (complex IOR per RGB) with single scattering, the exact Heitz walk, Kulla–Conty and Turquin \
         compensation from the crate's albedo tables, then glass (η = 1.5) with single scattering, the walk and Turquin \
         compensation (`Compensated` with `Compensation::Turquin`, reflection and transmission, both sides); a sky, a ground colour below the horizon and a spherical light; 64 samples per pixel, sRGB, \
         clamped to [0, 1]. Single scattering darkens with α: it loses the energy of the higher orders.",
    ),
    (
        "sweep_furnace.png",
        "The same sweep in the white furnace: a uniform environment of radiance 1, F = 1 conductors and non-absorbing glass \
         (η = 1.5), no light. A sphere that conserves energy vanishes into the background; under each sphere, L is its mean \
         radiance over the pixels it fully covers ± the standard error (1 = vanished). Single scattering darkens with α (to L ≈ 0.40 \
         for the conductor and 0.28 for glass at α = 1); the walk vanishes; the conductor's Kulla–Conty and Turquin vanish within \
         the tables' interpolation error (≤ 1.2e-3 of albedo for GGX); Turquin-compensated glass stays within 1 % of 1 (−0.9 % at \
         α = 0.5, +0.8 % at α = 1, several standard errors).",
    ),
];

/// A figure of the HTML page: the SVG, its title as the alternative text and `caption`.
fn figure_html(f: &Figure, caption: &str) -> String {
    format!(
        "<figure><img src=\"{}\" alt=\"{}\"/><figcaption>{}</figcaption></figure>\n",
        escape(&f.file),
        escape(&f.title),
        escape(caption)
    )
}

/// Copies the sweep images from `docs/` into `out_dir`; returns the (file, caption) of those
/// that exist.
fn copy_renders(out_dir: &std::path::Path, files: &mut Vec<PathBuf>) -> Vec<(&'static str, &'static str)> {
    let docs = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs");
    RENDERS
        .into_iter()
        .filter(|(name, _)| {
            let to = out_dir.join(name);
            let copied = std::fs::copy(docs.join(name), &to).is_ok();
            if copied {
                files.push(to);
            }
            copied
        })
        .collect()
}

/// The HTML section of the renders.
fn renders_html(renders: &[(&str, &str)]) -> String {
    let mut h = String::from("<h2 id=\"render\">Rendered roughness sweep and its white furnace</h2>\n");
    if renders.is_empty() {
        h.push_str("<p>No render found under docs/: <code>cargo run --release -p lab --bin path_tracer</code> renders them.</p>\n");
    }
    for (file, caption) in renders {
        let _ = writeln!(
            h,
            "<figure><img src=\"{0}\" alt=\"{1}\"/><figcaption>{1}</figcaption></figure>",
            escape(file),
            escape(caption)
        );
    }
    h
}

/// The caption of a lobe figure: what is plotted and the noise reached.
fn lobe_caption(results: &Results, budget: &Budget, file: &str, title: &str) -> String {
    let panels = results.lobes.iter().filter(|p| file == format!("lobes_{}.svg", p.material.name()));
    let worst = panels.map(|p| p.max_rel_se).fold(0.0, f64::max);
    format!(
        "{title}: f·|cos θo| (sr⁻¹) per scattering order (1, 2, 3+) and their total in the plane of incidence, against the signed \
         θo, for θi = 0, 1, 1.5 rad (rows) and the Heitz walk and both position-free models (columns). Order 1 is the walk's eval \
         (position-free: PT) at each θo; orders 2 and 3+ are histograms of the model's own sampled scatterings, interpolated \
         linearly between the bins' centres: bin averages over \
         {:.1}° of θo × ±{:.1}° about the plane (broad lobes that the bins barely smooth). Largest standard error of a \
         plotted total: {:.2} % of its panel's peak (target {} %). Legends: each order's albedo from sampled scatterings.",
        180.0 / budget.lobe_angles as f64,
        90.0 / budget.lobe_angles as f64,
        100.0 * worst,
        100.0 * budget.lobe_rel_se
    )
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1120px;margin:2em auto;padding:0 1em;color:#222;line-height:1.4}\
table{border-collapse:collapse;margin:0.5em 0 1em;font-size:0.9em}th,td{border:1px solid #ccc;padding:2px 8px;text-align:right}\
th{background:#f2f2f2}td:first-child,th:first-child{text-align:left}img{max-width:100%;border:1px solid #eee}\
.note{font-size:0.9em;color:#444}figure{margin:1em 0}figcaption{font-size:0.9em;color:#444}\
.kv td{text-align:left}";

/// Writes every file of the report.
pub fn write(
    opts: &Options,
    budget: &Budget,
    results: &Results,
    figures: &[Figure],
    seconds: f64,
) -> std::io::Result<Written> {
    std::fs::create_dir_all(&opts.out_dir)?;
    let mut files = Vec::new();
    let renders = copy_renders(&opts.out_dir, &mut files);
    let mut put = |name: &str, content: &str| -> std::io::Result<String> {
        let path = opts.out_dir.join(name);
        std::fs::write(&path, content)?;
        files.push(path);
        Ok(name.to_string())
    };
    let mut names = Vec::new();
    for (name, content) in csv_files(results) {
        names.push(put(name, &content)?);
    }
    for f in figures {
        names.push(put(&f.file, &f.svg)?);
    }
    let (ratio, choice, efficiency, energy, cost, lobe, decision) = (
        ratio_table(results),
        choice_table(results),
        efficiency_table(results),
        energy_table(results),
        cost_table(results),
        lobe_table(results),
        decision_table(),
    );
    let mut markdown = String::from("# microsurface report\n\n");
    for t in [&ratio, &choice, &decision, &energy, &cost, &lobe] {
        markdown.push_str(&t.markdown());
        markdown.push('\n');
    }
    names.push(put("summary.md", &markdown)?);

    let mut parameters: Vec<(String, String)> = vec![
        ("mode".into(), if opts.size == RunSize::Quick { "--quick".into() } else { "full".into() }),
        ("run time (s, measurement and plotting)".into(), format!("{seconds:.1}")),
    ];
    for (name, value, meaning) in budget.describe() {
        parameters.push((format!("{name}: {meaning}"), value));
    }
    parameters.push(("θi (rad)".into(), "0, 1, 1.5".into()));
    parameters.push((
        "ωo".into(),
        "mirror (θo = max(θi, 0.15)), normal (0.6 rad at θi = 0), side (θo = 1.2, φo = π/2) or for the dielectric transmission (θo = π − 0.6 max(θi, 0.3))".into(),
    ));
    parameters.push(("models of the lobes".into(), Model::ALL.map(|m| m.label()).join("; ")));
    let kv = |rows: &[(String, String)]| {
        let mut h = String::from("<table class=\"kv\">\n<tbody>\n");
        for (k, v) in rows {
            let _ = writeln!(h, "<tr><td>{}</td><td>{}</td></tr>", escape(k), escape(v));
        }
        h.push_str("</tbody>\n</table>\n");
        h
    };
    let machine: Vec<(String, String)> =
        machine(opts.threads).into_iter().map(|(k, v)| (k.to_string(), v)).collect();

    let mut html = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n<title>microsurface report</title>\n<style>{STYLE}</style>\n</head>\n<body>\n\
         <h1>microsurface report</h1>\n<p>Every estimator's error against run time, the efficiency ratios with 95 % confidence intervals, the lobes and \
         energy per scattering order and the cost of every model, measured on the machine below. The CSV files beside this page hold every number.</p>\n"
    );
    html.push_str("<h2 id=\"machine\">Machine</h2>\n");
    html.push_str(&kv(&machine));
    html.push_str("<h2 id=\"parameters\">Parameters of this run</h2>\n");
    html.push_str(&kv(&parameters));
    html.push_str(&ratio.html());
    html.push_str(&choice.html());
    html.push_str(&decision.html());
    for f in figures.iter().filter(|f| f.file == "decision_map.svg") {
        html.push_str(&figure_html(f, &f.title));
    }
    html.push_str("<h2 id=\"error-vs-time\">Error against run time</h2>\n<p>One panel per (θi, ωo) that the ratios average. \
        Single scattering and the compensated lobe (conductors) are deterministic models other than the walk: their curves \
        are their error against the walk's converged reference at their cost (a bias that no number of samples removes: the floor \
        an unbiased estimator reaches in that time), not a Monte Carlo error. The compensated lobe restores the energy with a separable \
        lobe of the wrong shape: where the walk's value is tiny (views at right angles to the plane of grazing light) its relative \
        error is large, and its curve is clipped at the top edge of the panel.</p>\n");
    for f in figures.iter().filter(|f| f.file.starts_with("error_vs_time")) {
        html.push_str(&figure_html(f, &f.title));
    }
    html.push_str(&efficiency.html());
    html.push_str("<h2 id=\"lobes\">Lobes per scattering order</h2>\n<p>The analogue of Wang et al. 2022, Fig. 6: the walk and both position-free models side by side.</p>\n");
    for f in figures.iter().filter(|f| f.file.starts_with("lobes")) {
        html.push_str(&figure_html(f, &lobe_caption(results, budget, &f.file, &f.title)));
    }
    html.push_str(&lobe.html());
    html.push_str(
        "<h2 id=\"albedo-tables\">Albedo tables</h2>\n<p>The shipped single-scattering albedo tables (the input of the \
        compensated lobes) between their nodes, against an adaptive quadrature of the model they tabulate. Data: \
        <a href=\"albedo_tables.csv\">albedo_tables.csv</a>.</p>\n",
    );
    for f in figures.iter().filter(|f| f.file == "albedo_tables.svg") {
        html.push_str(&figure_html(f, &f.title));
    }
    html.push_str(&renders_html(&renders));
    html.push_str(&energy.html());
    html.push_str(&cost.html());
    html.push_str("<h2 id=\"files\">Files</h2>\n<ul>\n");
    for name in &names {
        let _ = writeln!(html, "<li><a href=\"{0}\">{0}</a></li>", escape(name));
    }
    html.push_str("</ul>\n</body>\n</html>\n");
    put("index.html", &html)?;
    Ok(Written { files, markdown })
}
