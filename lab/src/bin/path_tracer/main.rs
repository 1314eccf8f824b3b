//! A small multi-threaded CPU path tracer over the BSDFs of `microsurface`. By default it
//! renders the GGX roughness sweep (gold and glass; single scattering, the exact walk and the
//! compensated lobes) and its white-furnace version, labelled in the images:
//! `cargo run --release -p lab --bin path_tracer -- [--quick] [--spp N] [--out-dir DIR]`;
//! `--showcase` renders one sphere per model instead.

mod label;
mod png;
mod sweep;

use lab::tracer::{Lighting, RenderStats, SHOWCASE_LABELS, render, showcase_scene};
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};
use sweep::{Layout, render_sweep};

const USAGE: &str = "usage: cargo run --release -p lab --bin path_tracer -- [--quick] [--spp N] [--out-dir DIR]
       cargo run --release -p lab --bin path_tracer -- --showcase [--width W] [--height H] [--spp N] [--out FILE.png] [--furnace]

  (default)      the GGX roughness sweep (α from 0.05 to 1; gold and glass; single scattering,
                 exact walk, Kulla–Conty and Turquin; glass Turquin) and its white furnace:
                 DIR/sweep.png and DIR/sweep_furnace.png
  --quick        small cells at 4 spp (seconds, for CI)
  --spp N        samples per pixel (default 64 for the sweep and the showcase)
  --out-dir DIR  output directory of the sweep (default target/path_tracer)
  --showcase     one sphere per model of the crate instead (480x200)
  --width W      showcase image width in pixels (default 480)
  --height H     showcase image height in pixels (default 200)
  --out FILE     showcase output PNG (default target/path_tracer.png)
  --furnace      render the white furnace instead of the showcase
  --help         print this message

A progress bar goes to stderr when it is a terminal.";

/// Prints the usage and the problem to stderr and exits with status 2.
fn usage_error(problem: &str) -> ! {
    eprintln!("{problem}\n\n{USAGE}");
    std::process::exit(2)
}

/// Draws a progress bar of `done()` out of `total` rows on stderr until it is full.
fn progress_bar(total: usize, done: impl Fn() -> usize) {
    loop {
        let d = done();
        let bar = 30 * d.min(total) / total.max(1);
        eprint!("\r[{}{}] {d}/{total} rows", "=".repeat(bar), " ".repeat(30 - bar));
        if d >= total {
            eprintln!();
            break;
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// Renders the sweep and its furnace version into `out_dir`.
fn run_sweep(
    mut layout: Layout,
    spp: Option<u32>,
    out_dir: &std::path::Path,
    threads: usize,
    show_progress: bool,
) {
    if let Some(spp) = spp {
        layout.spp = spp;
    }
    std::fs::create_dir_all(out_dir).expect("create the output directory");
    for (lighting, name) in [(Lighting::Studio, "sweep.png"), (Lighting::Furnace, "sweep_furnace.png")] {
        let stats = RenderStats::default();
        let start = Instant::now();
        let total = sweep::ROWS.len() * sweep::ALPHAS.len() * layout.image_height as usize;
        let (canvas, cells) = std::thread::scope(|s| {
            if show_progress {
                s.spawn(|| progress_bar(total, || stats.rows_done.load(Ordering::Relaxed)));
            }
            render_sweep(lighting, layout, threads, &stats)
        });
        let out = out_dir.join(name);
        png::write_rgb8(&out, canvas.width, canvas.height, &canvas.bytes()).expect("write the PNG");
        println!(
            "rendered {}x{} ({} spheres at {} spp) on {threads} threads in {:.1} s → {} ({} non-finite contributions rejected)",
            canvas.width,
            canvas.height,
            cells.len(),
            layout.spp,
            start.elapsed().as_secs_f64(),
            out.display(),
            stats.rejected.load(Ordering::Relaxed)
        );
        if lighting == Lighting::Furnace {
            println!(
                "white furnace: mean radiance over the pixels each sphere fully covers (1 = vanished), ± SE"
            );
            print!("{:<36}", "row \\ α");
            for c in cells.iter().filter(|c| c.row == sweep::ROWS[0]) {
                print!("{:>17}", c.alpha);
            }
            println!();
            for row in sweep::ROWS {
                print!("{:<36}", format!("{}, {}", row.substance_label(lighting), row.method.label()));
                for c in cells.iter().filter(|c| c.row == row) {
                    print!("{:>17}", format!("{:.4} ± {:.4}", c.sphere.mean, c.sphere.se));
                }
                println!();
            }
        }
    }
}

fn main() {
    use std::io::IsTerminal;
    let mut args = std::env::args().skip(1);
    let (mut width, mut height, mut spp, mut lighting) = (480u32, 200u32, None, Lighting::Studio);
    let (mut showcase, mut quick) = (false, false);
    let mut out = std::path::PathBuf::from("target/path_tracer.png");
    let mut out_dir = std::path::PathBuf::from("target/path_tracer");
    while let Some(arg) = args.next() {
        let mut value = || args.next().unwrap_or_else(|| usage_error(&format!("{arg} needs a value")));
        let mut number = || {
            let v = value();
            v.parse::<u32>()
                .ok()
                .filter(|&n| n > 0)
                .unwrap_or_else(|| usage_error(&format!("{arg} takes a positive whole number, not {v}")))
        };
        match arg.as_str() {
            "--width" => width = number(),
            "--height" => height = number(),
            "--spp" => spp = Some(number()),
            "--out" => out = value().into(),
            "--out-dir" => out_dir = value().into(),
            "--furnace" => lighting = Lighting::Furnace,
            "--showcase" => showcase = true,
            "--quick" => quick = true,
            "-h" | "--help" => {
                println!("{USAGE}");
                return;
            }
            other => usage_error(&format!("unknown argument {other}")),
        }
    }
    let show_progress = std::io::stderr().is_terminal();
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    if !showcase {
        let layout = if quick { Layout::QUICK } else { Layout::FULL };
        run_sweep(layout, spp, &out_dir, threads, show_progress);
        return;
    }
    let spp = spp.unwrap_or(if quick { 4 } else { 64 });
    let (scene, camera) = showcase_scene(lighting);
    let stats = RenderStats::default();
    let start = Instant::now();
    let (image, _) = std::thread::scope(|s| {
        if show_progress {
            s.spawn(|| progress_bar(height as usize, || stats.rows_done.load(Ordering::Relaxed)));
        }
        render(&scene, &camera, (width, height), spp, 1, threads, &stats)
    });
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir).expect("create the output directory");
    }
    png::write_srgb(&out, width, height, &image).expect("write the PNG");
    println!(
        "rendered {width}x{height} at {spp} spp on {threads} threads in {:.1} s → {} ({} non-finite contributions rejected)",
        start.elapsed().as_secs_f64(),
        out.display(),
        stats.rejected.load(Ordering::Relaxed)
    );
    println!(
        "spheres, left to right: {}",
        SHOWCASE_LABELS[..if lighting == Lighting::Furnace { 7 } else { 8 }].join(" | ")
    );
}
