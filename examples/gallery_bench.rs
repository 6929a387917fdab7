//! Times every gallery scene and counts its distance evaluations, to
//! compare two builds of the library.
//!
//! `cargo run --release --example gallery_bench [-- --size 640x480 --runs 3 --out DIR]`
//!
//! For each scene: the program build time (cold: the program cache is
//! cleared first, and cached: the same scene built again), the median
//! render time of `--runs` renders after one warm-up, and the mean
//! distance evaluations per pixel of the primary march. Writes
//! `DIR/NAME.png` (default `out/bench`) and a CSV table to
//! `DIR/gallery_bench.csv`, and prints it.

mod common;

use std::fmt::Write as _;
use std::time::Instant;

use common::measure::{Runs, flag, time_renders, value};
use fractal_sdf::prelude::*;
use fractal_sdf::render::{RenderOptions, Renderer};

fn main() -> std::process::ExitCode {
    common::run(|| {
        let size = common::size_arg((640, 480));
        let runs: usize = value("--runs").and_then(|r| r.parse().ok()).unwrap_or(3);
        let dir = value("--out").unwrap_or_else(|| "out/bench".to_string());
        std::fs::create_dir_all(&dir).map_err(common::usage)?;
        let only = value("--scene");
        let mut csv =
            String::from("scene,build_ms,cached_build_ms,render_ms,evaluations_per_pixel\n");
        for (name, scene) in fractal_sdf::gallery::all() {
            if only.as_deref().is_some_and(|o| o != name) {
                continue;
            }
            // The plain gallery settings, one pass: a lens renders its
            // single pass too, so both builds draw the same samples.
            let options = RenderOptions::default().quality(Quality::production());
            let t = Instant::now();
            let mut renderer = Renderer::with_options(&scene, &options)?;
            let build_ms = t.elapsed().as_secs_f64() * 1e3;
            let t = Instant::now();
            drop(Renderer::with_options(&scene, &options)?);
            let cached_ms = t.elapsed().as_secs_f64() * 1e3;
            let timing = time_renders(
                &mut renderer,
                size,
                Runs {
                    min: runs,
                    max: runs,
                    budget: std::time::Duration::ZERO,
                },
            )?;
            let frame = renderer.render_with_aovs(size.0, size.1)?;
            fractal_sdf::output::save_png(&frame.image, format!("{dir}/{name}.png"))?;
            let line = format!(
                "{name},{build_ms:.0},{cached_ms:.0},{:.1},{:.2}",
                timing.median_ms,
                frame.mean_evaluations()
            );
            if !flag("--quiet") {
                println!("{line}");
            }
            writeln!(csv, "{line}").ok();
        }
        std::fs::write(format!("{dir}/gallery_bench.csv"), csv).map_err(common::usage)?;
        Ok(())
    })
}
