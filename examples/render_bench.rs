//! Render speed per fractal, resolution and effects, and the generated
//! Mandelbulb kernel against a hand-written one.
//!
//! `cargo run --release --example render_bench [-- --runs 5 --quick]`
//!
//! Prints markdown tables and writes `out/render_bench.csv`. Each time is
//! the median of `--runs` renders after one warm-up render (the program
//! build is never timed). `--quick` renders only 320×240.

mod common;

use std::fmt::Write as _;
use std::time::Instant;

use fractal_sdf::gallery;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Glow;
use fractal_sdf::render::{RenderOptions, Renderer};

/// Median milliseconds of `runs` renders, after one warm-up.
fn time_ms(renderer: &mut Renderer, (w, h): (u32, u32), runs: usize) -> Result<f64> {
    renderer.render(w, h)?;
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let t = Instant::now();
            renderer
                .render(w, h)
                .map(|_| t.elapsed().as_secs_f64() * 1e3)
        })
        .collect::<Result<_>>()?;
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

fn arg_value(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    let i = args.iter().position(|a| a == name)?;
    args.get(i + 1).cloned()
}

fn effects_on() -> Effects {
    Effects::default().glow(Some(Glow::new(dvec3(0.6, 0.75, 1.0), 0.6)))
}

fn main() -> std::process::ExitCode {
    common::run(|| {
        let runs: usize = arg_value("--runs")
            .and_then(|r| r.parse().ok())
            .unwrap_or(5);
        let quick = std::env::args().any(|a| a == "--quick");
        let sizes: &[(u32, u32)] = if quick {
            &[(320, 240)]
        } else {
            &[(320, 240), (640, 480)]
        };
        let quality = Quality::production();
        let mut csv = String::from("scene,width,height,effects,ms_per_frame\n");

        let mut device = String::new();
        println!("| scene | resolution | effects on (ms) | effects off (ms) |");
        println!("|---|---|---:|---:|");
        for name in ["mandelbulb", "menger", "julia", "sierpinski"] {
            let scene = gallery::by_name(name).expect("a gallery scene");
            for &size in sizes {
                let mut row = Vec::new();
                for (label, effects) in [("on", effects_on()), ("off", Effects::none())] {
                    let options = RenderOptions::default().quality(quality).effects(effects);
                    let mut renderer = Renderer::with_options(&scene, &options)?;
                    device.clone_from(&renderer.device().label());
                    let ms = time_ms(&mut renderer, size, runs)?;
                    writeln!(csv, "{name},{},{},{label},{ms:.2}", size.0, size.1)
                        .expect("writing to a String");
                    row.push(ms);
                }
                println!(
                    "| {name} | {}×{} | {:.1} | {:.1} |",
                    size.0, size.1, row[0], row[1]
                );
            }
        }

        // The same scene and settings, generated versus hand-written scene
        // functions; renders alternate so drift affects both alike.
        let size = *sizes.last().expect("at least one size");
        let scene = gallery::mandelbulb();
        let options = RenderOptions::default()
            .quality(quality)
            .effects(effects_on());
        let scene = scene.compile()?;
        let mut generated = Renderer::from_compiled(scene.clone(), &options)?;
        let mut handwritten = Renderer::with_scene_functions(
            scene,
            &options,
            include_str!("../benches/mandelbulb_handwritten.cl"),
        )?;
        let same = fractal_sdf::metrics::psnr(
            &generated.render(size.0, size.1)?,
            &handwritten.render(size.0, size.1)?,
        );
        let (mut g, mut h) = (Vec::new(), Vec::new());
        for _ in 0..runs {
            g.push(time_ms(&mut generated, size, 1)?);
            h.push(time_ms(&mut handwritten, size, 1)?);
        }
        g.sort_by(f64::total_cmp);
        h.sort_by(f64::total_cmp);
        let (g, h) = (g[runs / 2], h[runs / 2]);
        println!();
        println!("| Mandelbulb {}×{} | ms/frame |", size.0, size.1);
        println!("|---|---:|");
        println!("| generated kernel | {g:.1} |");
        println!("| hand-written kernel | {h:.1} |");
        println!("| ratio generated / hand-written | {:.3} |", g / h);
        println!();
        println!("images agree to {same:.1} dB PSNR; device: {device}; median of {runs} runs");
        writeln!(csv, "mandelbulb_generated,{},{},on,{g:.2}", size.0, size.1).expect("String");
        writeln!(
            csv,
            "mandelbulb_handwritten,{},{},on,{h:.2}",
            size.0, size.1
        )
        .expect("String");
        std::fs::create_dir_all("out")
            .map_err(|source| Error::io("out", "cannot create the directory", source))?;
        std::fs::write("out/render_bench.csv", csv).map_err(|source| {
            Error::io("out/render_bench.csv", "cannot write the table", source)
        })?;
        Ok(())
    })
}
