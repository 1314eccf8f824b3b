//! LEADR mapping (Dupuy 2015, §3.3–3.4) against the supersampled ground truth and the naive
//! normal-map MIP: an error table of single texels, and a picture of a displacement-mapped
//! plane receding to the horizon.
//!
//! `cargo run --release -p lab --bin leadr [-- --quick] [--out DIR]` (default `target/leadr`).
//! Writes `leadr.png` (mirror facets), `leadr_glass.png` (glass, η = 1.5: the LEADR-filtered
//! noncentral dielectric) and `leadr_diffuse.png` (Lambertian facets): top row supersampled |
//! LEADR | naive; bottom row the MIP level used per pixel (black 0, white the coarsest) |
//! 2 × |LEADR − reference| | 2 × |naive − reference| (tone-mapped values).

mod render;

use glam::DVec3;
use microsurface::leadr::LeadrMap;
use microsurface::{Beckmann, Dielectric, Diffuse};
use render::{Facets, Scene};
use validation::leadr::surface::{NormalMip, direction, procedural_height_map};
use validation::leadr::validate::{filter_errors, texel_lobe};

/// RMS slope per axis of the procedural displacement.
const RMS_SLOPE: f64 = 0.2;
/// The coarse texels whose errors are averaged per level.
const TEXELS: [(usize, usize); 4] = [(0, 0), (1, 2), (2, 1), (3, 3)];

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let out = args
        .iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1))
        .map_or_else(|| std::path::PathBuf::from("target/leadr"), std::path::PathBuf::from);
    std::fs::create_dir_all(&out).expect("create the output directory");

    let size = if quick { 64 } else { 128 };
    let map = procedural_height_map(size, RMS_SLOPE, 1);
    let normals = NormalMip::new(&map);
    table(&map, &normals, quick);

    // the picture
    let alpha = 0.15;
    let leadr = LeadrMap::from_height_map(&map, Beckmann::isotropic(alpha as f32).expect("a roughness"))
        .expect("a map");
    let (width, height) = if quick { (160, 100) } else { (320, 200) };
    let facets = [
        ("leadr.png", "mirror", Facets::Mirror),
        ("leadr_glass.png", "glass η 1.5", Facets::Glass(Dielectric::new(1.5).expect("a valid η"))),
        ("leadr_diffuse.png", "diffuse", Facets::Diffuse(Diffuse::white())),
    ];
    for (file, name, facets) in facets {
        let scene = Scene {
            leadr: &leadr,
            normals: &normals,
            alpha,
            size,
            tile: 0.5,
            // low sun ahead of the camera: a glint on the receding plane
            light: DVec3::new(0.0, 0.95, 0.3).normalize(),
            width,
            height,
            max_samples: if quick { 8 } else { 24 },
            facets,
        };
        picture(&scene, &leadr, name, &out.join(file));
    }
}

/// Renders `scene`, prints the per-band error of LEADR and the naive MIP against the
/// supersampled reference and writes the panels to `path`.
fn picture(scene: &Scene, leadr: &LeadrMap, name: &str, path: &std::path::Path) {
    let (width, height, alpha) = (scene.width, scene.height, scene.alpha);
    let panels = scene.render();
    let [reference, leadr_img, naive_img] = &panels.images;
    // exposure: the reference's mean radiance maps to 1 − 1/e
    let lit: Vec<f64> =
        reference.iter().zip(&panels.lod).filter(|(_, l)| !l.is_nan()).map(|(v, _)| *v).collect();
    let exposure = lit.len() as f64 / lit.iter().sum::<f64>();
    let tone = |v: f64| 1.0 - (-exposure * v).exp();
    println!(
        "\npicture, {name} ({width} × {height} per panel, α = {alpha}): error of the tone-mapped pixels against the supersampled reference"
    );
    println!("{:<28} {:>12} {:>12}", "rows (distance)", "LEADR", "naive");
    let bands = [(0.15, 0.25, "far (up to the horizon)"), (0.25, 0.45, "middle"), (0.45, 1.0, "near")];
    for (from, to, name) in bands {
        let rows = (from * height as f64) as usize..(to * height as f64) as usize;
        let (mut el, mut en, mut sum) = (0.0, 0.0, 0.0);
        for y in rows {
            for x in 0..width {
                let i = y * width + x;
                if panels.lod[i].is_nan() {
                    continue;
                }
                let r = tone(reference[i]);
                el += (tone(leadr_img[i]) - r).abs();
                en += (tone(naive_img[i]) - r).abs();
                sum += r;
            }
        }
        println!("{name:<28} {:>11.1}% {:>11.1}%", 100.0 * el / sum, 100.0 * en / sum);
    }
    let top = (leadr.level_count() - 1) as f64;
    let mut rgb = vec![0u8; 3 * width * 3 * height * 2];
    let mut put = |panel: usize, row: usize, values: &dyn Fn(usize) -> f64| {
        for y in 0..height {
            for x in 0..width {
                let v = (values(y * width + x).clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0).round() as u8;
                let o = 3 * ((row * height + y) * 3 * width + panel * width + x);
                rgb[o..o + 3].copy_from_slice(&[v, v, v]);
            }
        }
    };
    for (k, img) in panels.images.iter().enumerate() {
        put(k, 0, &|i| tone(img[i]));
    }
    put(0, 1, &|i| if panels.lod[i].is_nan() { 0.0 } else { panels.lod[i] / top });
    put(1, 1, &|i| 2.0 * (tone(leadr_img[i]) - tone(reference[i])).abs());
    put(2, 1, &|i| 2.0 * (tone(naive_img[i]) - tone(reference[i])).abs());
    let file = std::io::BufWriter::new(std::fs::File::create(path).expect("create the PNG"));
    let mut encoder = png::Encoder::new(file, (3 * width) as u32, (2 * height) as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header().and_then(|mut w| w.write_image_data(&rgb)).expect("write the PNG");
    println!("wrote {}", path.display());
}

/// The table: relative L1 error of the BRDF of a coarse texel (mean over `TEXELS`) against the
/// average BRDF of its fine texels, LEADR and naive.
fn table(map: &microsurface::leadr::HeightMap, normals: &NormalMip, quick: bool) {
    let alphas: &[f32] = if quick { &[0.1, 0.3] } else { &[0.1, 0.2, 0.4] };
    let levels: &[usize] = if quick { &[1, 2, 3] } else { &[1, 2, 3, 4] };
    let thetas: &[f64] = if quick { &[0.0, 60.0, 80.0] } else { &[0.0, 30.0, 60.0, 75.0, 85.0] };
    println!(
        "relative L1 error ∫|f − f_ref| cos dωo / ∫ f_ref cos dωo of a coarse texel's BRDF against the mean of its fine texels' BRDFs\n\
         ({}² map, RMS slope {RMS_SLOPE} per axis; mean over {} coarse texels; light at azimuth 30°)",
        map.width(),
        TEXELS.len()
    );
    println!(
        "{:>6} {:>6} {:>8} {:>7} {:>10} {:>10} {:>8}",
        "alpha", "level", "texels", "theta", "LEADR", "naive", "ratio"
    );
    for &alpha in alphas {
        let leadr =
            LeadrMap::from_height_map(map, Beckmann::isotropic(alpha).expect("a roughness")).expect("a map");
        for &level in levels {
            let n = 1usize << level;
            for &theta in thetas {
                let wi = direction(theta, 30.0).as_dvec3();
                let (mut e_leadr, mut e_naive) = (0.0, 0.0);
                for (x, y) in TEXELS {
                    let reference: Vec<_> = (0..n * n)
                        .map(|i| leadr.lobe(0, (x * n + i % n) as isize, (y * n + i / n) as isize))
                        .collect();
                    let filtered = leadr.lobe(level, x as isize, y as isize);
                    let naive = texel_lobe(normals.slope(level, x as isize, y as isize), alpha);
                    let e = filter_errors(wi, &reference, &[filtered, naive], 1.0);
                    e_leadr += e[0].relative_l1 / TEXELS.len() as f64;
                    e_naive += e[1].relative_l1 / TEXELS.len() as f64;
                }
                println!(
                    "{alpha:>6} {level:>6} {:>8} {theta:>6}° {e_leadr:>10.4} {e_naive:>10.4} {:>8.2}",
                    n * n,
                    e_leadr / e_naive
                );
            }
        }
    }
}
