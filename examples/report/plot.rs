//! A small raster plotter for the report: log–log line charts and polar lobe plots, with an
//! 8×8 bitmap font (`font8x8`), written to PNG. No system fonts needed.

use font8x8::legacy::BASIC_LEGACY;

pub type Rgb = [u8; 3];

pub const WHITE: Rgb = [255, 255, 255];
pub const BLACK: Rgb = [0, 0, 0];
pub const GRID: Rgb = [225, 225, 225];
/// A palette that stays distinguishable in print.
pub const PALETTE: [Rgb; 7] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [23, 190, 207],
];

pub struct Canvas {
    pub width: u32,
    pub height: u32,
    pixels: Vec<Rgb>,
}

impl Canvas {
    pub fn new(width: u32, height: u32) -> Self {
        Self { width, height, pixels: vec![WHITE; (width * height) as usize] }
    }

    pub fn set(&mut self, x: i32, y: i32, c: Rgb) {
        if x >= 0 && y >= 0 && (x as u32) < self.width && (y as u32) < self.height {
            self.pixels[(y as u32 * self.width + x as u32) as usize] = c;
        }
    }

    /// A line of the given thickness (Bresenham with a square brush).
    pub fn line(&mut self, (x0, y0): (f32, f32), (x1, y1): (f32, f32), c: Rgb, thickness: i32) {
        if !(x0.is_finite() && y0.is_finite() && x1.is_finite() && y1.is_finite()) {
            return;
        }
        let steps = ((x1 - x0).abs().max((y1 - y0).abs()).ceil() as i32).clamp(1, 10_000);
        for s in 0..=steps {
            let t = s as f32 / steps as f32;
            let (x, y) = ((x0 + t * (x1 - x0)).round() as i32, (y0 + t * (y1 - y0)).round() as i32);
            for dx in 0..thickness {
                for dy in 0..thickness {
                    self.set(x + dx - thickness / 2, y + dy - thickness / 2, c);
                }
            }
        }
    }

    /// Text with the 8×8 font, top-left at (x, y), scaled by an integer factor.
    pub fn text(&mut self, x: i32, y: i32, s: &str, c: Rgb, scale: i32) {
        for (i, ch) in s.chars().enumerate() {
            let glyph = BASIC_LEGACY.get(ch as usize).copied().unwrap_or(BASIC_LEGACY[b'?' as usize]);
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..8 {
                    if bits & (1 << col) != 0 {
                        for sy in 0..scale {
                            for sx in 0..scale {
                                self.set(
                                    x + (i as i32 * 8 + col) * scale + sx,
                                    y + row as i32 * scale + sy,
                                    c,
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    /// Copies `other` with its top-left corner at (x, y).
    pub fn blit(&mut self, other: &Canvas, x: i32, y: i32) {
        for oy in 0..other.height {
            for ox in 0..other.width {
                self.set(x + ox as i32, y + oy as i32, other.pixels[(oy * other.width + ox) as usize]);
            }
        }
    }

    pub fn text_width(s: &str, scale: i32) -> i32 {
        s.chars().count() as i32 * 8 * scale
    }

    pub fn save(&self, path: &std::path::Path) -> std::io::Result<()> {
        let bytes: Vec<u8> = self.pixels.iter().flatten().copied().collect();
        super::png::write_rgb8(path, self.width, self.height, &bytes)
    }
}

/// A named series of points.
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub color: Rgb,
}

/// A log–log line chart with decade grid lines and a legend.
pub fn loglog_chart(canvas: &mut Canvas, title: &str, x_label: &str, y_label: &str, series: &[Series]) {
    let (w, h) = (canvas.width as f32, canvas.height as f32);
    let (left, right, top, bottom) = (58.0, w - 12.0, 26.0, h - 34.0);
    let finite = |v: f64| v.is_finite() && v > 0.0;
    let pts = series.iter().flat_map(|s| s.points.iter().copied()).filter(|&(x, y)| finite(x) && finite(y));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in pts {
        (x0, x1, y0, y1) = (x0.min(x.log10()), x1.max(x.log10()), y0.min(y.log10()), y1.max(y.log10()));
    }
    if x0 > x1 {
        return;
    }
    let (x0, x1, y0, y1) =
        (x0.floor(), x1.ceil().max(x0.floor() + 1.0), y0.floor(), y1.ceil().max(y0.floor() + 1.0));
    let px = |x: f64| left + ((x.log10() - x0) / (x1 - x0)) as f32 * (right - left);
    let py = |y: f64| bottom - ((y.log10() - y0) / (y1 - y0)) as f32 * (bottom - top);
    for d in (x0 as i32)..=(x1 as i32) {
        let x = px(10f64.powi(d));
        canvas.line((x, top), (x, bottom), GRID, 1);
        let label = format!("1e{d}");
        canvas.text(x as i32 - Canvas::text_width(&label, 1) / 2, bottom as i32 + 6, &label, BLACK, 1);
    }
    for d in (y0 as i32)..=(y1 as i32) {
        let y = py(10f64.powi(d));
        canvas.line((left, y), (right, y), GRID, 1);
        let label = format!("1e{d}");
        canvas.text(left as i32 - Canvas::text_width(&label, 1) - 4, y as i32 - 4, &label, BLACK, 1);
    }
    canvas.line((left, bottom), (right, bottom), BLACK, 1);
    canvas.line((left, top), (left, bottom), BLACK, 1);
    canvas.text(left as i32, 6, title, BLACK, 1);
    canvas.text((right as i32) - Canvas::text_width(x_label, 1), h as i32 - 14, x_label, BLACK, 1);
    canvas.text(4, top as i32 - 14, y_label, BLACK, 1);
    for (i, s) in series.iter().enumerate() {
        let pts: Vec<(f32, f32)> =
            s.points.iter().filter(|&&(x, y)| finite(x) && finite(y)).map(|&(x, y)| (px(x), py(y))).collect();
        for pair in pts.windows(2) {
            canvas.line(pair[0], pair[1], s.color, 2);
        }
        let ly = top as i32 + 4 + 11 * i as i32;
        let lx = right as i32 - 8 * 18;
        canvas.line((lx as f32, ly as f32 + 4.0), (lx as f32 + 14.0, ly as f32 + 4.0), s.color, 3);
        canvas.text(lx + 18, ly, &s.label, BLACK, 1);
    }
}

/// A polar plot of lobes in the incidence plane: each series holds (θ, r) with θ measured
/// from the normal (positive towards +x, |θ| > π/2 below the surface). The radius scale is
/// shared by all series; `notes` are printed under the title.
pub fn polar_chart(canvas: &mut Canvas, title: &str, notes: &[String], series: &[Series], incident: f64) {
    let (w, h) = (canvas.width as f32, canvas.height as f32);
    let below = series
        .iter()
        .any(|s| s.points.iter().any(|&(t, r)| t.abs() > std::f64::consts::FRAC_PI_2 && r > 0.0));
    let (cx, cy) = (w * 0.5, if below { h * 0.55 } else { h * 0.85 });
    let radius = if below { (h * 0.38).min(w * 0.42) } else { (h * 0.7).min(w * 0.45) };
    let r_max =
        series.iter().flat_map(|s| s.points.iter().map(|p| p.1)).fold(0.0f64, |a, b| a.max(b)).max(1e-12);
    for k in 1..=4 {
        let r = radius * k as f32 / 4.0;
        let mut prev = None;
        for i in 0..=180 {
            let t = std::f32::consts::PI * (i as f32 / 180.0) * if below { 2.0 } else { 1.0 }
                - std::f32::consts::FRAC_PI_2;
            let p = (cx + r * t.sin(), cy - r * t.cos());
            if let Some(q) = prev {
                canvas.line(q, p, GRID, 1);
            }
            prev = Some(p);
        }
    }
    canvas.line((cx - radius, cy), (cx + radius, cy), BLACK, 1);
    let (si, ci) = (incident.sin() as f32, incident.cos() as f32);
    canvas.line((cx, cy), (cx - radius * si, cy - radius * ci), [120, 120, 120], 1);
    canvas.text(8, 6, title, BLACK, 1);
    for (i, n) in notes.iter().enumerate() {
        canvas.text(8, 18 + 10 * i as i32, n, BLACK, 1);
    }
    for (i, s) in series.iter().enumerate() {
        let pts: Vec<(f32, f32)> = s
            .points
            .iter()
            .map(|&(t, r)| {
                let rr = radius * (r / r_max) as f32;
                (cx + rr * t.sin() as f32, cy - rr * t.cos() as f32)
            })
            .collect();
        for pair in pts.windows(2) {
            canvas.line(pair[0], pair[1], s.color, 2);
        }
        let ly = h as i32 - 12 - 11 * (series.len() - 1 - i) as i32;
        canvas.line((8.0, ly as f32 + 4.0), (22.0, ly as f32 + 4.0), s.color, 3);
        canvas.text(26, ly, &s.label, BLACK, 1);
    }
}
