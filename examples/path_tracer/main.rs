//! A small multi-threaded CPU path tracer rendering one sphere per model of `microsurface`:
//! `cargo run --release --example path_tracer -- [--width W] [--height H] [--spp N]
//! [--out FILE.png] [--furnace]`.

mod png;

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};
use validation::tracer::{RenderStats, SHOWCASE_LABELS, render, showcase_scene};

const USAGE: &str = "usage: cargo run --release --example path_tracer -- [--width W] [--height H] [--spp N] [--out FILE.png] [--furnace]

  --width W      image width in pixels (default 480)
  --height H     image height in pixels (default 200)
  --spp N        samples per pixel (default 64)
  --out FILE     output PNG (default target/path_tracer.png)
  --furnace      render the white furnace instead of the showcase
  --help         print this message

A progress bar goes to stderr when it is a terminal.";

/// Prints the usage and the problem to stderr and exits with status 2.
fn usage_error(problem: &str) -> ! {
    eprintln!("{problem}\n\n{USAGE}");
    std::process::exit(2)
}

fn main() {
    use std::io::IsTerminal;
    let mut args = std::env::args().skip(1);
    let (mut width, mut height, mut spp, mut furnace) = (480u32, 200u32, 64u32, false);
    let mut out = std::path::PathBuf::from("target/path_tracer.png");
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
            "--spp" => spp = number(),
            "--out" => out = value().into(),
            "--furnace" => furnace = true,
            "-h" | "--help" => {
                println!("{USAGE}");
                return;
            }
            other => usage_error(&format!("unknown argument {other}")),
        }
    }
    let show_progress = std::io::stderr().is_terminal();
    let (scene, camera) = showcase_scene(furnace);
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let stats = RenderStats::default();
    let start = Instant::now();
    let (image, _) = std::thread::scope(|s| {
        let progress = s.spawn(|| {
            if !show_progress {
                return;
            }
            loop {
                let done = stats.rows_done.load(Ordering::Relaxed);
                let bar = 30 * done / height as usize;
                eprint!("\r[{}{}] {done}/{height} rows", "=".repeat(bar), " ".repeat(30 - bar));
                if done >= height as usize {
                    eprintln!();
                    break;
                }
                std::thread::sleep(Duration::from_millis(200));
            }
        });
        let result = render(&scene, &camera, (width, height), spp, 1, threads, &stats);
        progress.join().expect("progress thread");
        result
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
    println!("spheres, left to right: {}", SHOWCASE_LABELS[..if furnace { 7 } else { 8 }].join(" | "));
}
