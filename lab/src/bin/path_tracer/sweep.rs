//! The roughness sweep: one sphere per GGX roughness α (columns) and per material and
//! technique (rows), each rendered in its own small scene and labelled in the image; and its
//! white-furnace version (uniform environment of radiance 1, F = 1 conductor, non-absorbing
//! glass), where a sphere that conserves energy vanishes into the background and single
//! scattering darkens as α grows.
//!
//! In the furnace every sphere's mean radiance over the pixels it fully covers is measured
//! with its standard error (the per-pixel standard errors of independent pixels, added in
//! quadrature) and printed in the image: 1 for an energy-conserving model.

use crate::label::{Align, BLACK, Canvas, Fonts, Rgb8, WHITE, Weight, srgb8};
use glam::Vec3;
use lab::tracer::{Camera, Environment, Light, Lighting, Material, RenderStats, Scene, Sphere, render};
use microsurface::{
    Compensated, Compensation, ComplexIor, Conductor, Dielectric, Ggx, MicrofacetBsdf, Technique,
};

/// The roughnesses of the columns.
pub const ALPHAS: [f32; 7] = [0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0];

/// The index of refraction of the glass spheres.
const GLASS_ETA: f32 = 1.5;

/// What a sphere is made of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Substance {
    /// Gold (F = 1 in the furnace).
    Gold,
    /// Glass of η = 1.5 (non-absorbing: the same in the furnace).
    Glass,
}

/// How multiple scattering is handled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// The single-scattering microfacet BSDF (loses the higher orders).
    SingleScattering,
    /// The exact model: the Heitz et al. 2016 random walk.
    Walk,
    /// Single scattering plus the Kulla–Conty 2017 lobe from the albedo tables.
    KullaConty,
    /// Single scattering scaled by Turquin 2019 from the albedo tables.
    Turquin,
}

impl Method {
    pub fn label(self) -> &'static str {
        match self {
            Method::SingleScattering => "single scattering",
            Method::Walk => "exact walk",
            Method::KullaConty => "Kulla–Conty",
            Method::Turquin => "Turquin",
        }
    }

    /// A short name for the sphere labels.
    fn short(self) -> &'static str {
        match self {
            Method::SingleScattering => "single",
            Method::Walk => "walk",
            Method::KullaConty => "Kulla–Conty",
            Method::Turquin => "Turquin",
        }
    }
}

/// One row of the sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Row {
    pub substance: Substance,
    pub method: Method,
}

/// The rows, top to bottom.
pub const ROWS: [Row; 7] = [
    Row { substance: Substance::Gold, method: Method::SingleScattering },
    Row { substance: Substance::Gold, method: Method::Walk },
    Row { substance: Substance::Gold, method: Method::KullaConty },
    Row { substance: Substance::Gold, method: Method::Turquin },
    Row { substance: Substance::Glass, method: Method::SingleScattering },
    Row { substance: Substance::Glass, method: Method::Walk },
    Row { substance: Substance::Glass, method: Method::Turquin },
];

impl Row {
    /// The material's name under `lighting`.
    pub fn substance_label(self, lighting: Lighting) -> &'static str {
        match (self.substance, lighting) {
            (Substance::Gold, Lighting::Studio) => "gold",
            (Substance::Gold, Lighting::Furnace) => "conductor, F = 1",
            (Substance::Glass, _) => "glass, η = 1.5",
        }
    }

    /// The BSDF of this row at roughness α.
    pub fn material(self, alpha: f32, lighting: Lighting) -> Material {
        let slope = Ggx::isotropic(alpha).expect("the sweep's α are valid");
        let conductor = match lighting {
            Lighting::Studio => Conductor::new(ComplexIor::GOLD),
            Lighting::Furnace => Conductor::perfect(),
        };
        let technique = match self.method {
            Method::SingleScattering => Technique::SingleScattering,
            _ => Technique::RandomWalk,
        };
        match (self.substance, self.method) {
            (Substance::Gold, Method::KullaConty | Method::Turquin) => {
                let scheme = if self.method == Method::KullaConty {
                    Compensation::KullaConty
                } else {
                    Compensation::Turquin
                };
                Box::new(Compensated::with_scheme(slope, conductor, scheme).expect("α within the tables"))
            }
            (Substance::Gold, _) => Box::new(
                MicrofacetBsdf::new(slope, conductor).expect("α ≤ MAX_WALK_ALPHA").with_technique(technique),
            ),
            (Substance::Glass, Method::Turquin) => {
                let glass = Dielectric::new(GLASS_ETA).expect("valid η");
                Box::new(
                    Compensated::with_scheme(slope, glass, Compensation::Turquin)
                        .expect("α and η within the tables"),
                )
            }
            (Substance::Glass, Method::KullaConty) => unreachable!("no Kulla–Conty dielectric row"),
            (Substance::Glass, _) => {
                let glass = Dielectric::new(GLASS_ETA).expect("valid η");
                Box::new(
                    MicrofacetBsdf::new(slope, glass).expect("α ≤ MAX_WALK_ALPHA").with_technique(technique),
                )
            }
        }
    }
}

/// The sizes of a sweep image and its sample count.
#[derive(Debug, Clone, Copy)]
pub struct Layout {
    /// Width of one cell (one sphere).
    pub cell_width: u32,
    /// Height of a cell's rendered image.
    pub image_height: u32,
    /// Samples per pixel.
    pub spp: u32,
}

impl Layout {
    /// The default: a 1432 × 1336 image at 64 spp.
    pub const FULL: Self = Self { cell_width: 176, image_height: 146, spp: 64 };
    /// For CI: seconds.
    pub const QUICK: Self = Self { cell_width: 96, image_height: 72, spp: 4 };

    fn caption_height(self) -> u32 {
        34
    }
    fn cell_height(self) -> u32 {
        self.image_height + self.caption_height()
    }
    fn label_width(self) -> u32 {
        200
    }
    fn header_height(self) -> u32 {
        76
    }
    /// The size of the whole image.
    pub fn size(self) -> (u32, u32) {
        (
            self.label_width() + self.cell_width * ALPHAS.len() as u32,
            self.header_height() + self.cell_height() * ROWS.len() as u32,
        )
    }
}

/// The radius of every sphere (at the origin).
const SPHERE_RADIUS: f32 = 1.0;

/// The scene of one cell: a sphere at the origin under `lighting`, and its camera.
fn cell_scene(material: Material, lighting: Lighting) -> (Scene, Camera) {
    let spheres = vec![Sphere { center: Vec3::ZERO, radius: SPHERE_RADIUS, material: 0 }];
    let (light, environment) = match lighting {
        Lighting::Furnace => (None, Environment::Constant(Vec3::ONE)),
        Lighting::Studio => (
            Some(Light { center: Vec3::new(-3.0, 5.0, 4.0), radius: 1.0, radiance: Vec3::splat(10.0) }),
            Environment::Sky {
                zenith: Vec3::new(0.2, 0.3, 0.6),
                horizon: Vec3::new(0.75, 0.78, 0.82),
                ground: Vec3::new(0.18, 0.16, 0.14),
            },
        ),
    };
    let camera = Camera::look_at(Vec3::new(0.0, 0.35, 4.3), Vec3::ZERO, 33.0);
    (Scene { spheres, materials: vec![material], light, environment }, camera)
}

/// Whether the camera ray `d` from `o` hits the sphere.
fn hits_sphere(o: Vec3, d: Vec3) -> bool {
    let b = o.dot(d);
    b < 0.0 && o.length_squared() - b * b <= SPHERE_RADIUS * SPHERE_RADIUS
}

/// A mean radiance with its standard error.
#[derive(Debug, Clone, Copy)]
pub struct Measured {
    pub mean: f64,
    pub se: f64,
}

/// One rendered cell and what was measured on it.
pub struct Cell {
    pub row: Row,
    pub alpha: f32,
    /// The mean radiance (mean over RGB) over the pixels the sphere fully covers.
    pub sphere: Measured,
}

/// The mean over RGB of the pixels whose four corners all see the sphere, with its SE.
fn measure_sphere(camera: &Camera, (w, h): (u32, u32), image: &[[f32; 3]], errors: &[f32]) -> Measured {
    let (mut sum, mut var, mut n) = (0.0f64, 0.0f64, 0usize);
    for y in 0..h {
        for x in 0..w {
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
            if corners
                .iter()
                .all(|&(dx, dy)| hits_sphere(camera.origin, camera.ray(x as f32 + dx, y as f32 + dy, w, h)))
            {
                let i = (y * w + x) as usize;
                sum += image[i].iter().map(|&c| f64::from(c)).sum::<f64>() / 3.0;
                var += f64::from(errors[i]).powi(2);
                n += 1;
            }
        }
    }
    let k = n.max(1) as f64;
    Measured { mean: sum / k, se: var.sqrt() / k }
}

/// Text colours.
const INK: Rgb8 = [235, 235, 235];
const DIM: Rgb8 = [175, 175, 175];
const PANEL: Rgb8 = [38, 38, 42];

/// Renders the sweep under `lighting` on `threads` threads; returns the labelled image and
/// every cell's measurement. `stats.rows_done` counts rendered rows over all cells.
pub fn render_sweep(
    lighting: Lighting,
    layout: Layout,
    threads: usize,
    stats: &RenderStats,
) -> (Canvas, Vec<Cell>) {
    let fonts = Fonts::new();
    let (width, height) = layout.size();
    let mut canvas = Canvas::new(width, height, PANEL);
    let (cw, ih) = (layout.cell_width, layout.image_height);
    let title = match lighting {
        Lighting::Studio => format!(
            "GGX roughness sweep: gold and glass (η = {GLASS_ETA}) under a sky and a spherical light, {} samples per pixel",
            layout.spp
        ),
        Lighting::Furnace => format!(
            "White furnace: uniform environment of radiance 1, F = 1 conductor, non-absorbing glass; {} spp",
            layout.spp
        ),
    };
    let subtitle = match lighting {
        Lighting::Studio => {
            "rows: material and technique; columns: α. Single scattering loses the energy of the higher orders.".to_string()
        }
        Lighting::Furnace => "a sphere that conserves energy vanishes; L: its mean radiance ± standard error (1 = vanished)".to_string(),
    };
    let big = if layout.cell_width >= 150 { 1.0 } else { 0.7 };
    canvas.text(&fonts, &title, 12.0, 8.0, 19.0 * big, Weight::Bold, Align::Left, WHITE);
    canvas.text(&fonts, &subtitle, 12.0, 8.0 + 24.0 * big, 14.0 * big, Weight::Regular, Align::Left, DIM);
    let header_y = layout.header_height() as f32 - 24.0 * big;
    canvas.text(&fonts, "GGX α →", 12.0, header_y, 16.0 * big, Weight::Bold, Align::Left, INK);
    for (j, alpha) in ALPHAS.iter().enumerate() {
        let x = layout.label_width() as f32 + (j as f32 + 0.5) * cw as f32;
        canvas.text(
            &fonts,
            &format!("α = {alpha}"),
            x,
            header_y,
            16.0 * big,
            Weight::Bold,
            Align::Center,
            INK,
        );
    }
    let mut cells = Vec::new();
    for (i, row) in ROWS.iter().enumerate() {
        let y0 = layout.header_height() + i as u32 * layout.cell_height();
        let yc = y0 as f32 + 0.5 * ih as f32;
        canvas.text(
            &fonts,
            row.substance_label(lighting),
            12.0,
            yc - 22.0 * big,
            16.0 * big,
            Weight::Bold,
            Align::Left,
            INK,
        );
        canvas.text(
            &fonts,
            row.method.label(),
            12.0,
            yc + 2.0 * big,
            16.0 * big,
            Weight::Regular,
            Align::Left,
            INK,
        );
        for (j, &alpha) in ALPHAS.iter().enumerate() {
            let x0 = layout.label_width() + j as u32 * cw;
            let (scene, camera) = cell_scene(row.material(alpha, lighting), lighting);
            let seed = 1 + (i * ALPHAS.len() + j) as u64;
            let (image, errors) = render(&scene, &camera, (cw, ih), layout.spp, seed, threads, stats);
            let sphere = measure_sphere(&camera, (cw, ih), &image, &errors);
            let pixels: Vec<Rgb8> = image.iter().map(|&p| srgb8(p)).collect();
            canvas.blit(x0, y0, cw, &pixels);
            // the sphere's own label under it
            let xc = x0 as f32 + 0.5 * cw as f32;
            let cap_y = (y0 + ih) as f32 + 2.0;
            let label = format!("α {alpha} · {}", row.method.short());
            canvas.text(&fonts, &label, xc, cap_y, 12.5 * big, Weight::Regular, Align::Center, INK);
            if lighting == Lighting::Furnace {
                let l = format!("L = {:.4} ± {:.4}", sphere.mean, sphere.se);
                canvas.text(
                    &fonts,
                    &l,
                    xc,
                    cap_y + 15.0 * big,
                    12.5 * big,
                    Weight::Regular,
                    Align::Center,
                    DIM,
                );
            }
            cells.push(Cell { row: *row, alpha, sphere });
        }
    }
    // thin separators between the material groups
    let group_y = layout.header_height() + 4 * layout.cell_height();
    canvas.fill(0, group_y - 1, width, 2, BLACK);
    (canvas, cells)
}
