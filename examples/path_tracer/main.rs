//! A small multi-threaded CPU path tracer rendering one sphere per model of `microsurface`:
//! `cargo run --release --example path_tracer -- [--width W] [--height H] [--spp N]
//! [--out FILE.png] [--furnace]`.

mod png;
mod tracer;

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};
use tracer::{RenderStats, SHOWCASE_LABELS, render, showcase_scene};

fn main() {
    let mut args = std::env::args().skip(1);
    let (mut width, mut height, mut spp, mut furnace) = (480u32, 200u32, 64u32, false);
    let mut out = std::path::PathBuf::from("target/path_tracer.png");
    while let Some(arg) = args.next() {
        let mut value = || args.next().unwrap_or_else(|| panic!("{arg} needs a value"));
        match arg.as_str() {
            "--width" => width = value().parse().expect("--width takes a number"),
            "--height" => height = value().parse().expect("--height takes a number"),
            "--spp" => spp = value().parse().expect("--spp takes a number"),
            "--out" => out = value().into(),
            "--furnace" => furnace = true,
            other => panic!("unknown argument {other}"),
        }
    }
    let (scene, camera) = showcase_scene(furnace);
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let stats = RenderStats::default();
    let start = Instant::now();
    let (image, _) = std::thread::scope(|s| {
        let progress = s.spawn(|| {
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
