//! Stage 4, plot: the report's figures as SVG with `plotters` (its SVG backend writes text as
//! SVG `<text>`, so no font files are needed): error against run time as small multiples over
//! every (θi, ωo), and the lobes per order of the walk and both position-free models.

use super::configure::{Budget, Case, Config, Est, LOBE_MATERIALS, MaterialKind, Model, THETAS};
use super::decision;
use super::reduce::{LobePanel, Results};
use super::tables::{self, Family, Tabulated};
use microsurface::techniques::ChosenTechnique;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// A rendered figure: its file name, its SVG text and a caption for the HTML page.
pub struct Figure {
    pub file: String,
    pub svg: String,
    pub title: String,
}

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
type PlotResult<T> = Result<T, Box<dyn std::error::Error>>;

/// A palette that stays distinguishable in print (the first six of Tableau 10).
const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];
const GRAY: RGBColor = RGBColor(110, 110, 110);
const LIGHT: RGBColor = RGBColor(215, 215, 215);
const FONT: &str = "sans-serif";

fn est_color(est: Est) -> RGBColor {
    match est {
        Est::Single => GRAY,
        Est::Compensated => PALETTE[5],
        Est::Walk => PALETTE[0],
        Est::PtUncorrelated => PALETTE[1],
        Est::PtCorrelated => PALETTE[2],
        Est::BdptUncorrelated => PALETTE[3],
        Est::BdptCorrelated => PALETTE[4],
    }
}

/// 10 to an integer power, with superscript digits.
fn power_of_ten(v: f64) -> String {
    let e = v.log10().round() as i32;
    let sup: String = e
        .to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            d => ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'][d.to_digit(10).unwrap_or(0) as usize],
        })
        .collect();
    format!("10{sup}")
}

/// Text lines at (x, y), `size` px, `gap` px apart.
fn text_lines(area: &Area, lines: &[String], (x, y): (i32, i32), size: u32, gap: i32) -> PlotResult<()> {
    for (i, line) in lines.iter().enumerate() {
        area.draw(&Text::new(line.clone(), (x, y + i as i32 * gap), (FONT, size).into_font()))?;
    }
    Ok(())
}

/// A legend entry: a line sample and its label, at (x, y).
fn legend_entry(
    area: &Area,
    (x, y): (i32, i32),
    color: RGBColor,
    dashed: bool,
    label: &str,
) -> PlotResult<()> {
    if dashed {
        for k in 0..3 {
            area.draw(&PathElement::new(
                vec![(x + 10 * k, y + 7), (x + 10 * k + 6, y + 7)],
                color.stroke_width(3),
            ))?;
        }
    } else {
        area.draw(&PathElement::new(vec![(x, y + 7), (x + 26, y + 7)], color.stroke_width(3)))?;
    }
    area.draw(&Text::new(label.to_string(), (x + 34, y - 1), (FONT, 15).into_font()))?;
    Ok(())
}

/// Every figure of the report.
pub fn figures(results: &Results, budget: &Budget) -> PlotResult<Vec<Figure>> {
    let mut figures = Vec::new();
    for config in Config::ALL {
        figures.push(error_vs_time(results, config, budget)?);
    }
    for material in LOBE_MATERIALS {
        figures.push(lobes(results, material, budget)?);
    }
    figures.push(table_errors(results, budget)?);
    figures.push(decision_map()?);
    Ok(figures)
}

/// Relative RMSE against single-thread time, one panel per (θi, ωo).
fn error_vs_time(results: &Results, config: Config, budget: &Budget) -> PlotResult<Figure> {
    let (w, h) = (1080u32, 1000u32);
    let mut svg = String::new();
    let cases = Case::all(config);
    let rows: Vec<_> = results.efficiency.iter().filter(|r| r.case.config == config).collect();
    let positive = |v: f64| v.is_finite() && v > 0.0;
    // the axes from every estimator but the compensated lobe, whose relative error can be huge
    // where the walk's value is tiny (its separable lobe has the right energy, not the right
    // shape): its curve is clipped at the top edge instead
    let pts = rows
        .iter()
        .filter(|r| r.est != Est::Compensated)
        .flat_map(|r| r.curve.iter())
        .filter(|p| positive(p.seconds) && positive(p.rel_rmse));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in pts {
        (x0, x1, y0, y1) = (x0.min(p.seconds), x1.max(p.seconds), y0.min(p.rel_rmse), y1.max(p.rel_rmse));
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (1e-7, 1e-3, 1e-3, 1.0);
    }
    let decade = |v: f64, up: bool| 10f64.powf(if up { v.log10().ceil() } else { v.log10().floor() });
    // a hair beyond the decades, so that the end labels are drawn
    let (x0, x1, y0, y1) = (
        decade(x0, false) * 0.98,
        decade(x1, true) * 1.02,
        decade(y0, false) * 0.98,
        decade(y1, true) * 1.02,
    );
    let title = format!("Relative RMSE against single-thread run time: {}", config.label());
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let (header, grid) = root.split_vertically(176);
        text_lines(
            &header,
            &[
                title.clone(),
                format!(
                    "Each curve: the RMSE of the mean of n evaluations (disjoint batches of one run of {} evaluations) against its model's",
                    budget.samples
                ),
                format!(
                    "converged reference ({}× the samples, from the model's lowest-variance estimator), divided by that reference; log–log axes.",
                    budget.reference_factor
                ),
            ],
            (12, 8),
            15,
            22,
        )?;
        for (k, est) in Est::ALL.iter().enumerate() {
            let (col, row) = (k % 2, k / 2);
            let at = (12 + col as i32 * 530, 80 + row as i32 * 22);
            legend_entry(&header, at, est_color(*est), est.is_biased(), est.label())?;
        }
        legend_entry(
            &header,
            (542, 80 + 3 * 22),
            BLACK,
            true,
            "slope −½ (the Monte Carlo rate), through the walk's first point",
        )?;
        let panels = grid.split_evenly((THETAS.len(), 3));
        for (panel, case) in panels.iter().zip(&cases) {
            let caption = format!("θi = {}, ωo: {}", case.theta_i(), case.wo.name());
            let mut chart = ChartBuilder::on(panel)
                .caption(caption, (FONT, 17))
                .margin(6)
                .margin_right(14)
                .x_label_area_size(42)
                .y_label_area_size(62)
                .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
            chart
                .configure_mesh()
                .x_desc("time (s, one thread)")
                .y_desc("relative RMSE")
                .x_labels(6)
                .y_labels(6)
                .x_label_formatter(&|v| power_of_ten(*v))
                .y_label_formatter(&|v| power_of_ten(*v))
                .label_style((FONT, 14))
                .axis_desc_style((FONT, 15))
                .light_line_style(WHITE)
                .bold_line_style(LIGHT)
                .draw()?;
            // the Monte Carlo rate: slope −½ through the walk's first point
            if let Some(first) = results.row(*case, Est::Walk).and_then(|r| r.curve.first()) {
                let line = [x0, x1].map(|t| (t, first.rel_rmse * (t / first.seconds).powf(-0.5)));
                chart.draw_series(DashedLineSeries::new(line, 3, 5, BLACK.stroke_width(1)))?;
            }
            for est in Est::ALL {
                let Some(row) = results.row(*case, est) else { continue };
                let points: Vec<(f64, f64)> = row
                    .curve
                    .iter()
                    .filter(|p| positive(p.seconds) && positive(p.rel_rmse))
                    .map(|p| (p.seconds, p.rel_rmse.min(y1)))
                    .collect();
                let style = est_color(est).stroke_width(2);
                if est.is_biased() {
                    chart.draw_series(DashedLineSeries::new(points, 6, 4, style))?;
                } else {
                    chart.draw_series(LineSeries::new(points, style))?;
                }
            }
        }
        root.present()?;
    }
    Ok(Figure { file: format!("error_vs_time_{}.svg", config.name()), svg, title })
}

/// A round step for the radial scale: the smallest 1, 2, 2.5 or 5 × 10^k of at least a quarter
/// of `r` (two to four labelled circles).
fn radial_step(r: f64) -> f64 {
    let raw = r / 4.0;
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0].into_iter().map(|m| m * p).find(|s| *s >= raw).unwrap_or(10.0 * p)
}

/// Lobes per order: rows θi, columns the three models.
fn lobes(results: &Results, material: MaterialKind, budget: &Budget) -> PlotResult<Figure> {
    let full_circle = material == MaterialKind::Dielectric;
    let (pw, ph) = (360u32, if full_circle { 430u32 } else { 300u32 });
    let header_h = 134u32;
    let (w, h) = (3 * pw, header_h + THETAS.len() as u32 * ph);
    let panels: Vec<&LobePanel> = results.lobes.iter().filter(|p| p.material == material).collect();
    let worst = panels.iter().map(|p| p.max_rel_se).fold(0.0, f64::max);
    let what = match material {
        MaterialKind::Conductor => "conductor (F = 1)",
        MaterialKind::Dielectric => "dielectric (η = 1.5)",
        MaterialKind::Diffuse => "diffuse",
    };
    let title = format!("Lobes per scattering order, {what}, GGX α = 1");
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let (header, grid) = root.split_vertically(header_h);
        text_lines(
            &header,
            &[
                title.clone(),
                format!(
                    "f·|cos θo| (sr⁻¹) in the plane of incidence, against θo; ωi is the gray ray (on the right), the mirror direction on the left{}.",
                    if full_circle { ", transmission below the horizon" } else { "" }
                ),
                "Radial circles in sr⁻¹, one scale per row; legends: the albedo of each order (from sampled scatterings of the same model).".to_string(),
                format!(
                    "Order 1: eval at θo (walk; position-free: PT). Orders 2, 3+: histograms of the model's own samples, bins {:.1}° of θo × ±{:.1}° about the plane;",
                    180.0 / budget.lobe_angles as f64,
                    90.0 / budget.lobe_angles as f64,
                ),
                format!(
                    "{:.1}–{:.1} million samples per panel, for an SE ≤ {} % of the panel's peak; largest SE of a plotted total: {:.2} % of its panel's peak.",
                    panels.iter().map(|p| p.samples.0).min().unwrap_or(0) as f64 * 1e-6,
                    panels.iter().map(|p| p.samples.1).max().unwrap_or(0) as f64 * 1e-6,
                    100.0 * budget.lobe_rel_se,
                    100.0 * worst
                ),
            ],
            (12, 8),
            15,
            24,
        )?;
        let cells = grid.split_evenly((THETAS.len(), Model::ALL.len()));
        for (k, theta_i) in THETAS.into_iter().enumerate() {
            let row: Vec<&&LobePanel> = panels.iter().filter(|p| p.theta_i == theta_i).collect();
            let r_max = row.iter().map(|p| p.peak).fold(1e-12, f64::max) * 1.04;
            for (j, model) in Model::ALL.into_iter().enumerate() {
                let Some(panel) = row.iter().find(|p| p.model == model) else { continue };
                lobe_panel(&cells[k * Model::ALL.len() + j], panel, r_max, full_circle)?;
            }
        }
        root.present()?;
    }
    Ok(Figure { file: format!("lobes_{}.svg", material.name()), svg, title })
}

/// A labelled curve in data coordinates.
struct Curve {
    label: String,
    color: RGBColor,
    points: Vec<(f64, f64)>,
}

/// One polar panel: the orders 1, 2, 3+ and their total.
fn lobe_panel(area: &Area, panel: &LobePanel, r_max: f64, full_circle: bool) -> PlotResult<()> {
    let (title_h, legend_h) = (24u32, 44u32);
    let (top, rest) = area.split_vertically(title_h);
    let (_, ah) = rest.dim_in_pixel();
    let (plot, legend) = rest.split_vertically(ah.saturating_sub(legend_h));
    top.draw(&Text::new(
        format!("{}, θi = {}", panel.model.label(), panel.theta_i),
        (10, 4),
        (FONT, 16).into_font(),
    ))?;
    let (y_lo, y_hi) =
        if full_circle { (-1.04 * r_max, 1.04 * r_max) } else { (-0.08 * r_max, 1.04 * r_max) };
    let (pw, ph) = plot.dim_in_pixel();
    let half_w = ((y_hi - y_lo) * f64::from(pw) / f64::from(ph.max(1)) / 2.0).max(1.06 * r_max);
    let mut chart = ChartBuilder::on(&plot).margin(4).build_cartesian_2d(-half_w..half_w, y_lo..y_hi)?;
    let step = radial_step(r_max);
    let circle_end = if full_circle { std::f64::consts::TAU } else { std::f64::consts::PI };
    let circles: Vec<f64> = (1..).map(|k| f64::from(k) * step).take_while(|r| *r <= r_max * 1.0001).collect();
    for &r in &circles {
        let circle: Vec<(f64, f64)> = (0..=180)
            .map(|i| {
                let a = circle_end * f64::from(i) / 180.0;
                (r * a.cos(), r * a.sin())
            })
            .collect();
        chart.draw_series(LineSeries::new(circle, LIGHT.stroke_width(1)))?;
        chart.draw_series(std::iter::once(Text::new(
            format!("{}", (r * 1e6).round() / 1e6),
            (r, 0.0),
            (FONT, 13).into_font().color(&GRAY).pos(Pos::new(HPos::Right, VPos::Top)),
        )))?;
    }
    chart.draw_series(LineSeries::new([(-half_w, 0.0), (half_w, 0.0)], GRAY.stroke_width(1)))?;
    let (si, ci) = (panel.theta_i.sin(), panel.theta_i.cos());
    chart.draw_series(LineSeries::new([(0.0, 0.0), (r_max * si, r_max * ci)], GRAY.stroke_width(2)))?;
    chart.draw_series(std::iter::once(Text::new(
        "ωi".to_string(),
        (r_max * si * 0.9 + 0.03 * r_max, r_max * ci * 0.9),
        (FONT, 14).into_font().color(&GRAY),
    )))?;
    let polar = |t: f64, v: f64| (-v * t.sin(), v * t.cos());
    let mut series: Vec<Curve> = Vec::new();
    let energy = |k: usize| panel.energy.map(|e| if k < 2 { e[k] } else { e[2] + e[3] });
    for (k, name) in ["order 1", "order 2", "orders 3+"].into_iter().enumerate() {
        let pts = panel.points.iter().map(|p| polar(p.theta_o, p.orders[k].mean)).collect();
        let label = match energy(k) {
            Some(e) => format!("{name}: {e:.3}"),
            None => name.to_string(),
        };
        series.push(Curve { label, color: PALETTE[k], points: pts });
    }
    let total_pts = panel.points.iter().map(|p| polar(p.theta_o, p.total().mean)).collect();
    let total_label = match panel.energy {
        Some(e) => format!("total: {:.3}", e.iter().sum::<f64>()),
        None => "total".to_string(),
    };
    series.push(Curve { label: total_label, color: BLACK, points: total_pts });
    for Curve { color, points, .. } in &series {
        let mut pts = points.clone();
        if full_circle && let Some(&p) = pts.first() {
            pts.push(p);
        }
        chart.draw_series(LineSeries::new(pts, color.stroke_width(2)))?;
    }
    for (i, Curve { label, color, .. }) in series.iter().enumerate() {
        let (col, row) = (i % 2, i / 2);
        legend.draw(&PathElement::new(
            vec![(10 + col as i32 * 175, 9 + row as i32 * 20), (30 + col as i32 * 175, 9 + row as i32 * 20)],
            color.stroke_width(3),
        ))?;
        legend.draw(&Text::new(
            label.clone(),
            (36 + col as i32 * 175, 1 + row as i32 * 20),
            (FONT, 15).into_font(),
        ))?;
    }
    Ok(())
}

/// The floor of the table-error axis: errors below it (at the nodes) are drawn on it.
const TABLE_ERROR_FLOOR: f64 = 1e-7;

/// The albedo tables' interpolation error: |table − quadrature| against μ, one curve per α,
/// rows the slope families, columns the tables.
fn table_errors(results: &Results, budget: &Budget) -> PlotResult<Figure> {
    let (w, h) = (1380u32, 760u32);
    let title =
        "Albedo tables: interpolation error against quadrature of the model they tabulate".to_string();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let (header, grid) = root.split_vertically(118);
        text_lines(
            &header,
            &[
                title.clone(),
                format!(
                    "|table − quadrature| at {} log-spaced μ = cos θ per curve, at roughnesses between the nodes; the quadrature integrates the crate's single-scattering",
                    budget.table_points
                ),
                "MicrofacetBsdf over the visible normals (adaptive, ≲ 1e-7). Dielectrics: R + T, importance transport; inside = the relative index 1/η. Log–log axes.".to_string(),
            ],
            (12, 8),
            15,
            22,
        )?;
        for (k, alpha) in tables::TABLE_ALPHAS.iter().enumerate() {
            legend_entry(&header, (12 + k as i32 * 170, 86), PALETTE[k], false, &format!("α = {alpha}"))?;
        }
        let panels = grid.split_evenly((Family::ALL.len(), Tabulated::ALL.len()));
        for (i, family) in Family::ALL.into_iter().enumerate() {
            for (j, tabulated) in Tabulated::ALL.into_iter().enumerate() {
                let curves: Vec<_> = results
                    .tables
                    .iter()
                    .filter(|c| c.family == family && c.tabulated == tabulated)
                    .collect();
                let worst = curves.iter().map(|c| c.max_error()).fold(0.0, f64::max);
                let caption = format!("{}, {}: max {:.1e}", family.label(), tabulated.label(), worst);
                let mut chart = ChartBuilder::on(&panels[i * Tabulated::ALL.len() + j])
                    .caption(caption, (FONT, 16))
                    .margin(6)
                    .margin_right(14)
                    .x_label_area_size(42)
                    .y_label_area_size(62)
                    .build_cartesian_2d(
                        (tables::MIN_MU * 0.98..1.02).log_scale(),
                        (TABLE_ERROR_FLOOR * 0.98..1.02).log_scale(),
                    )?;
                chart
                    .configure_mesh()
                    .x_desc("μ = cos θ")
                    .y_desc("|error|")
                    .x_labels(4)
                    .y_labels(8)
                    .x_label_formatter(&|v| power_of_ten(*v))
                    .y_label_formatter(&|v| power_of_ten(*v))
                    .label_style((FONT, 14))
                    .axis_desc_style((FONT, 15))
                    .light_line_style(WHITE)
                    .bold_line_style(LIGHT)
                    .draw()?;
                for curve in curves {
                    let k = tables::TABLE_ALPHAS.iter().position(|&a| a == curve.alpha).unwrap_or(0);
                    let points: Vec<(f64, f64)> = curve
                        .points
                        .iter()
                        .map(|&(mu, t, q)| (mu, (t - q).abs().max(TABLE_ERROR_FLOOR)))
                        .collect();
                    chart.draw_series(LineSeries::new(points, PALETTE[k].stroke_width(2)))?;
                }
            }
        }
        root.present()?;
    }
    Ok(Figure { file: "albedo_tables.svg".into(), svg, title })
}

/// The colour of a chosen technique on the decision map.
fn technique_color(t: ChosenTechnique) -> RGBColor {
    match t {
        ChosenTechnique::SingleScattering => LIGHT,
        ChosenTechnique::Compensated => PALETTE[1],
        ChosenTechnique::RandomWalk => PALETTE[0],
    }
}

/// The technique chooser's decision map: one panel per budget, α across, slope family and
/// material down, the chosen technique coloured.
fn decision_map() -> PlotResult<Figure> {
    let rows = decision::map();
    let alphas = decision::alphas();
    let (w, h) = (1380u32, 150 + 36 * rows.len() as u32);
    let title = "Technique chooser: the cheapest technique within an albedo error budget".to_string();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let (header, grid) = root.split_vertically(96);
        text_lines(
            &header,
            &[
                title.clone(),
                "microsurface::techniques::Choice per slope family and material (rows) and roughness α (log axis); error: the hemispherical albedo error against the walk.".to_string(),
            ],
            (12, 8),
            15,
            22,
        )?;
        for (k, t) in
            [ChosenTechnique::SingleScattering, ChosenTechnique::Compensated, ChosenTechnique::RandomWalk]
                .into_iter()
                .enumerate()
        {
            legend_entry(&header, (12 + k as i32 * 220, 76), technique_color(t), false, decision::short(t))?;
        }
        let panels = grid.split_evenly((1, decision::BUDGETS.len()));
        let step = (alphas[1] / alphas[0]).sqrt();
        for (b, budget) in decision::BUDGETS.iter().enumerate() {
            let n = rows.len() as f64;
            let mut chart = ChartBuilder::on(&panels[b])
                .caption(format!("budget {:.1} %", budget * 100.0), (FONT, 16))
                .margin(6)
                .margin_right(14)
                .x_label_area_size(42)
                .y_label_area_size(if b == 0 { 150 } else { 8 })
                .build_cartesian_2d(
                    (f64::from(alphas[0] / step)..f64::from(alphas[alphas.len() - 1] * step)).log_scale(),
                    0.0..n,
                )?;
            chart
                .configure_mesh()
                .x_desc("α")
                .x_labels(4)
                .y_labels(0)
                .x_label_formatter(&|v| format!("{v:.2}"))
                .label_style((FONT, 13))
                .axis_desc_style((FONT, 15))
                .disable_mesh()
                .draw()?;
            for (i, row) in rows.iter().enumerate() {
                let y = n - i as f64;
                if b == 0 {
                    // the row's label, right-aligned left of the panel's plotting area
                    let (px, py) = chart.backend_coord(&(f64::from(alphas[0] / step), y - 0.5));
                    let style =
                        TextStyle::from((FONT, 13).into_font()).pos(Pos::new(HPos::Right, VPos::Center));
                    root.draw(&Text::new(row.label.clone(), (px - 8, py), style))?;
                }
                chart.draw_series(row.choices[b].iter().zip(&alphas).map(|(c, &a)| {
                    Rectangle::new(
                        [(f64::from(a / step), y - 0.92), (f64::from(a * step), y - 0.08)],
                        technique_color(c.technique).filled(),
                    )
                }))?;
            }
        }
        root.present()?;
    }
    Ok(Figure { file: "decision_map.svg".into(), svg, title })
}
