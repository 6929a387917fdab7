//! Brute force against the distance estimate: the gallery's Mandelbulb
//! (power 8, 10 iterations) drawn from its estimate (`mandelbulb`) and
//! from its escape-time test alone (`mandelbulb_escape`, an
//! `InsideShape`), with the same camera, at several brute-force step
//! lengths. Prints Markdown tables for the guide (`docs/guide/fractals.md`,
//! "Brute force against the estimate"):
//!
//! - per step length: the share of pixels whose hit flag agrees with the
//!   estimate's image, the mean depth difference where both hit (in scene
//!   units) and its median (in pixel footprints), milliseconds per frame
//!   and distance evaluations per pixel;
//! - per normal method ([`ScreenNormals`]): the mean and median angle
//!   between the screen-space normals and the estimate's normals where both
//!   hit the same surface (within two footprints of each other);
//! - progressive passes: how the jittered steps' noise averages away,
//!   as the PSNR of 1, 4 and 16 passes against 64.
//!
//! `cargo run --release --example brute_force [-- --size 640x480] [--quick]`
//!
//! `--quick` measures at 320×240 with fewer step lengths. Times depend on
//! the device and the machine's load; evaluation counts do not.

mod common;

use std::time::Instant;

use common::measure::compare;
use fractal_sdf::gallery;
use fractal_sdf::metrics::psnr;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::ScreenNormals;
use fractal_sdf::render::{Frame, RenderOptions, Renderer};
use glam::Vec3;

fn options(quality: Quality) -> RenderOptions {
    RenderOptions::default().quality(quality)
}

/// A frame with its AOVs and the milliseconds it took (after one untimed
/// render that builds the program).
fn timed(scene: &Scene, quality: Quality, (w, h): (u32, u32)) -> Result<(Frame, f64)> {
    let mut renderer = Renderer::with_options(scene, &options(quality))?;
    renderer.render(8, 8)?;
    let start = Instant::now();
    let frame = renderer.render_with_aovs(w, h)?;
    Ok((frame, start.elapsed().as_secs_f64() * 1e3))
}

fn evaluations_per_pixel(frame: &Frame) -> f64 {
    let total: u64 = frame.evaluations.iter().map(|&e| u64::from(e)).sum();
    total as f64 / frame.evaluations.len() as f64
}

fn angle_degrees(a: [f32; 3], b: [f32; 3]) -> f64 {
    let (a, b) = (Vec3::from(a).as_dvec3(), Vec3::from(b).as_dvec3());
    a.normalize()
        .dot(b.normalize())
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

fn main() -> std::process::ExitCode {
    common::run(|| {
        let quick = common::measure::flag("--quick");
        let size = common::size_arg(if quick { (320, 240) } else { (640, 480) });
        let steps: &[f64] = if quick {
            &[4.0, 1.0]
        } else {
            &[8.0, 4.0, 2.0, 1.0, 0.5]
        };
        let estimated = gallery::mandelbulb();
        let escape = gallery::mandelbulb_escape();
        let quality = Quality::production();
        let (de, de_ms) = timed(&estimated, quality, size)?;
        let footprint = {
            let renderer = Renderer::with_options(&estimated, &options(quality))?;
            let view = renderer.viewport(size.0, size.1)?;
            move |t: f64| view.march_settings(&quality).footprint(t)
        };

        println!(
            "Mandelbulb power 8, 10 iterations, {}×{}, production quality, one sample per pixel; \
             the distance estimate took {de_ms:.0} ms and {:.0} evaluations per pixel.\n",
            size.0,
            size.1,
            evaluations_per_pixel(&de)
        );
        println!(
            "| brute step (footprints) | hit flags agree | mean depth difference | median, in \
             footprints | ms/frame | evals/px |"
        );
        println!("|---:|---:|---:|---:|---:|---:|");
        for &step in steps {
            let (frame, ms) = timed(&escape, quality.brute_step(step), size)?;
            let errors = compare(&frame, &de);
            let mut footprints: Vec<f64> = (0..de.depth.len())
                .filter(|&i| de.hit[i] && frame.hit[i])
                .map(|i| {
                    let t = f64::from(de.depth[i]);
                    (f64::from(frame.depth[i]) - t).abs() / footprint(t)
                })
                .collect();
            footprints.sort_by(f64::total_cmp);
            println!(
                "| {step} | {:.2}% | {:.4} | {:.2} | {ms:.0} | {:.0} |",
                100.0 - errors.mask_pct,
                errors.depth,
                footprints.get(footprints.len() / 2).copied().unwrap_or(0.0),
                evaluations_per_pixel(&frame)
            );
        }

        println!("\n| normals | mean angle to the estimate's | median | pixels |");
        println!("|---|---:|---:|---:|");
        for method in [ScreenNormals::Differences, ScreenNormals::LeastSquares] {
            let q = quality.brute_step(1.0).screen_normals(method);
            let (frame, _) = timed(&escape, q, size)?;
            let mut angles = Vec::new();
            for i in 0..de.depth.len() {
                let t = f64::from(de.depth[i]);
                let same = de.hit[i]
                    && frame.hit[i]
                    && (f64::from(frame.depth[i]) - t).abs() < 2.0 * footprint(t);
                if same {
                    angles.push(angle_degrees(frame.normal[i], de.normal[i]));
                }
            }
            angles.sort_by(f64::total_cmp);
            let mean = angles.iter().sum::<f64>() / angles.len().max(1) as f64;
            println!(
                "| {method:?} | {mean:.1}° | {:.1}° | {} |",
                angles[angles.len() / 2],
                angles.len()
            );
        }

        println!("\n| progressive passes (brute step 1) | PSNR against 64 passes | ms |");
        println!("|---:|---:|---:|");
        let mut renderer = Renderer::with_options(&escape, &options(quality.brute_step(1.0)))?;
        let small = (size.0 / 2, size.1 / 2);
        let mut images = Vec::new();
        let start = Instant::now();
        let mut times = Vec::new();
        for pass in 1..=64u32 {
            let image = renderer.render_progressive(small.0, small.1)?;
            if [1, 4, 16, 64].contains(&pass) {
                images.push((pass, image));
                times.push(start.elapsed().as_secs_f64() * 1e3);
            }
        }
        let reference = images.last().expect("64 passes").1.clone();
        for ((pass, image), ms) in images.iter().zip(&times).take(3) {
            println!("| {pass} | {:.1} dB | {ms:.0} |", psnr(image, &reference));
        }
        let path = std::path::Path::new("out/brute-force-64-passes.png");
        std::fs::create_dir_all("out").map_err(common::usage)?;
        reference.save(path).map_err(common::usage)?;
        eprintln!("wrote {}", path.display());
        Ok(())
    })
}
