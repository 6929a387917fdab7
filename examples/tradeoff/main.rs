//! The speed-versus-accuracy trade-off, measured on every fractal of the
//! gallery: each quality preset and sweeps of `max_steps`, `hit_epsilon`,
//! `over_relaxation`, `cone_tile`, `fast_math` and `resolution_scale`,
//! timed (median of several renders after a
//! warm-up) and compared with a `reference` render of the same pixels
//! (F64, 2048 steps, hits located to a thousandth of a pixel): PSNR,
//! SSIM, hit-mask mismatch, mean depth error, and PSNR of both images
//! box-filtered to half size. Two rows check that the reference is
//! converged (`reference ω/2`: half its relaxation factor; `reference
//! ε/10`: a tenth of its `hit_epsilon`). A sweep of `detail`, which
//! changes the surface drawn rather than the accuracy, shows how much the
//! look depends on it. Anti-aliasing is measured apart, at half the size,
//! against a 4×4-sample render, and so are progressive passes, everywhere
//! and at the edges alone (adaptive), against an 8×8-sample render; and
//! `bounces` on the gallery's `materials` scene, against eight bounces.
//! A table says whether each preset is on the
//! measured front (no configuration both faster, by more than 10%, and
//! more accurate, by more than 0.5 dB). Prints
//! markdown tables, writes
//! `out/tradeoff.csv` and plots time against error in `out/tradeoff.png`.
//!
//! ```text
//! cargo run --release --example tradeoff [-- --quick | --size 640x480]
//!     [--scenes mandelbulb,menger] [--no-aa] [--no-bounces]
//! ```
//!
//! `--quick` renders 320×240 with fewer timed runs; `--scenes ''` measures
//! only the bounces. Timings depend on the
//! device and on whatever else the machine is doing.

#[path = "../common/mod.rs"]
mod common;
mod plot;

use std::fmt::Write as _;

use common::measure::{self, Errors, Runs, Timing, compare};
use fractal_sdf::prelude::*;
use fractal_sdf::render::{EdgeThresholds, Frame, RenderOptions, Renderer};
use image::RgbaImage;

/// The fractal scenes of the gallery.
const SCENES: [&str; 4] = ["mandelbulb", "menger", "julia", "sierpinski"];

/// One measured configuration of one scene.
#[derive(Debug, Clone)]
pub struct Row {
    /// Gallery scene.
    pub scene: String,
    /// `preset`, `floor`, `max_steps`, `hit_epsilon`, `over_relaxation`,
    /// `detail` or `aa`.
    pub group: &'static str,
    /// What was varied, e.g. `preview` or `max_steps=64`.
    pub label: String,
    /// Median render time.
    pub timing: Timing,
    /// Reference time divided by this configuration's time.
    pub speedup: f64,
    /// Mean distance evaluations per pixel.
    pub evaluations: f64,
    /// Error against the group's reference.
    pub errors: Errors,
    /// Image size.
    pub size: (u32, u32),
}

/// What is rendered and how often.
#[derive(Clone, Copy)]
struct Study {
    size: (u32, u32),
    runs: Runs,
    effects: Effects,
}

impl Study {
    /// Times `quality` on `scene` and renders one frame with AOVs.
    fn measure(&self, scene: &Scene, quality: Quality) -> Result<(Timing, Frame)> {
        let mut renderer = self.renderer(scene, quality)?;
        let timing = measure::time_renders(&mut renderer, self.size, self.runs)?;
        let frame = renderer.render_with_aovs(self.size.0, self.size.1)?;
        Ok((timing, frame))
    }

    /// One frame with AOVs, untimed.
    fn frame(&self, scene: &Scene, quality: Quality) -> Result<Frame> {
        self.renderer(scene, quality)?
            .render_with_aovs(self.size.0, self.size.1)
    }

    /// Progressive rendering: 1, 4, 16 and 64 passes of production
    /// quality, timed once each (the program built beforehand), against
    /// production with 8×8 samples, the mean of as many samples as the
    /// last row has. Depth and hit mask are the pixel centres'.
    fn progressive(&self, name: &str, scene: &Scene) -> Result<Vec<Row>> {
        let (w, h) = self.size;
        let best = self.frame(scene, Quality::production().supersampling(8))?;
        let mut renderer = self.renderer(scene, Quality::production())?;
        let centre = renderer.render_with_aovs(w, h)?;
        let mut rows: Vec<Row> = Vec::new();
        let mut add = |label: String, ms: f64, evaluations: f64, image: RgbaImage| {
            let row = Row {
                scene: name.to_string(),
                group: "progressive",
                label,
                timing: Timing {
                    median_ms: ms,
                    runs: 1,
                },
                speedup: rows.first().map_or(1.0, |one| one.timing.median_ms / ms),
                evaluations,
                errors: compare(
                    &{
                        let mut frame = centre.clone();
                        frame.image = image;
                        frame
                    },
                    &best,
                ),
                size: self.size,
            };
            eprintln!(
                "  {:<20} {:>9.1} ms  {:>6.1} evals/px  {:>6.2} dB",
                row.label, ms, row.evaluations, row.errors.psnr
            );
            rows.push(row);
        };
        for passes in [1u32, 4, 16, 64] {
            renderer.restart_progressive();
            let start = std::time::Instant::now();
            let mut image = renderer.render_progressive(w, h)?;
            for _ in 1..passes {
                image = renderer.render_progressive(w, h)?;
            }
            let ms = start.elapsed().as_secs_f64() * 1e3;
            let label = if passes == 1 {
                "1 pass".into()
            } else {
                format!("{passes} passes")
            };
            add(
                label,
                ms,
                centre.mean_evaluations() * f64::from(passes),
                image,
            );
            if passes == 1 {
                continue;
            }
            // The same passes at the edges alone.
            let start = std::time::Instant::now();
            let adaptive = renderer.render_adaptive(w, h, passes, &EdgeThresholds::default())?;
            let ms = start.elapsed().as_secs_f64() * 1e3;
            let label = format!(
                "adaptive, {passes} at {:.0}%",
                100.0 * adaptive.refined_fraction()
            );
            add(label, ms, adaptive.mean_evaluations(), adaptive.image);
        }
        Ok(rows)
    }

    fn renderer(&self, scene: &Scene, quality: Quality) -> Result<Renderer> {
        let options = RenderOptions::default()
            .quality(quality)
            .effects(self.effects);
        Renderer::with_options(scene, &options)
    }

    /// Measures every configuration of one group against `reference`.
    fn group(
        &self,
        name: &str,
        scene: &Scene,
        group: &'static str,
        configs: Vec<(String, Quality)>,
        reference: (f64, &Frame),
    ) -> Result<Vec<Row>> {
        let mut rows = Vec::new();
        for (label, quality) in configs {
            let (timing, frame) = self.measure(scene, quality)?;
            let row = Row {
                scene: name.to_string(),
                group,
                label,
                speedup: reference.0 / timing.median_ms,
                evaluations: frame.mean_evaluations(),
                errors: compare(&frame, reference.1),
                timing,
                size: self.size,
            };
            eprintln!(
                "  {:<20} {:>9.1} ms  {:>6.1} evals/px  {:>6.2} dB",
                row.label, row.timing.median_ms, row.evaluations, row.errors.psnr
            );
            rows.push(row);
        }
        Ok(rows)
    }
}

/// The presets with one sample per pixel (march accuracy only).
fn presets() -> Vec<(String, Quality)> {
    [
        ("draft", Quality::draft()),
        ("preview", Quality::preview()),
        ("production", Quality::production()),
        ("reference", Quality::reference()),
    ]
    .into_iter()
    .map(|(n, q)| (n.to_string(), q.supersampling(1)))
    .collect()
}

/// The reference made more careful, one knob at a time: its distance
/// from the reference is the reference's own convergence error.
fn floor() -> Vec<(String, Quality)> {
    let r = reference();
    vec![
        (
            "reference ω/2".to_string(),
            r.over_relaxation(r.over_relaxation / 2.0),
        ),
        (
            "reference ε/10".to_string(),
            r.hit_epsilon(r.hit_epsilon / 10.0),
        ),
    ]
}

/// Production quality with one knob swept. `detail` is last: it changes
/// the surface drawn, so its rows measure a change of look, not of
/// accuracy.
fn sweeps() -> Vec<(&'static str, Vec<(String, Quality)>)> {
    let base = Quality::production();
    let sweep =
        |name: &str, values: &[f64], set: fn(&mut Quality, f64)| -> Vec<(String, Quality)> {
            values
                .iter()
                .map(|&v| {
                    let mut q = base;
                    set(&mut q, v);
                    (format!("{name}={v}"), q)
                })
                .collect()
        };
    vec![
        (
            "max_steps",
            sweep("max_steps", &[32.0, 64.0, 128.0, 256.0], |q, v| {
                q.max_steps = v as u32;
            }),
        ),
        (
            "hit_epsilon",
            sweep("hit_epsilon", &[0.01, 0.15, 0.3, 0.5], |q, v| {
                q.hit_epsilon = v;
            }),
        ),
        (
            "over_relaxation",
            sweep("over_relaxation", &[0.5, 1.3, 1.6, 1.9], |q, v| {
                q.over_relaxation = v;
            }),
        ),
        (
            "cone_tile",
            sweep("cone_tile", &[0.0, 4.0, 16.0], |q, v| {
                q.cone_tile = v as u32;
            }),
        ),
        (
            "fast_math",
            vec![("fast_math".to_string(), base.fast_math(true))],
        ),
        (
            "resolution_scale",
            sweep("resolution_scale", &[2.0, 3.0], |q, v| {
                q.resolution_scale = v as u32;
            }),
        ),
        (
            "detail",
            sweep("detail", &[0.25, 0.4, 0.6, 1.0], |q, v| q.detail = v),
        ),
    ]
}

/// The groups whose rows are speed-versus-accuracy choices (`detail`
/// changes the look, `floor` checks the reference).
const CHOICES: [&str; 7] = [
    "preset",
    "max_steps",
    "hit_epsilon",
    "over_relaxation",
    "cone_tile",
    "fast_math",
    "resolution_scale",
];

/// A configuration beats another only by more than this fraction of its
/// time: timings vary by about ±10% from run to run.
const TIME_MARGIN: f64 = 0.1;

/// ... and by more than this many dB of PSNR.
const PSNR_MARGIN: f64 = 0.5;

/// The rows that are both faster and more accurate (PSNR) than a preset
/// of the same scene, beyond the margins of measurement: a preset with any
/// is off the measured front.
fn dominating<'a>(rows: &'a [Row], preset: &Row) -> Vec<&'a Row> {
    rows.iter()
        .filter(|r| r.scene == preset.scene && CHOICES.contains(&r.group))
        .filter(|r| {
            r.timing.median_ms < (1.0 - TIME_MARGIN) * preset.timing.median_ms
                && r.errors.psnr > preset.errors.psnr + PSNR_MARGIN
        })
        .collect()
}

/// Each preset, and whether a measured configuration beats it on both
/// time and accuracy.
fn front(rows: &[Row]) -> String {
    let mut out = String::from(
        "| scene | preset | ms/frame | PSNR dB | on the front |\n|---|---|---:|---:|---|\n",
    );
    for p in rows.iter().filter(|r| r.group == "preset") {
        let better = dominating(rows, p);
        let verdict = if better.is_empty() {
            "yes".to_string()
        } else {
            let names: Vec<&str> = better.iter().map(|r| r.label.as_str()).collect();
            format!("no: {} faster and more accurate", names.join(", "))
        };
        let _ = writeln!(
            out,
            "| {} | {} | {:.0} | {:.1} | {verdict} |",
            p.scene, p.label, p.timing.median_ms, p.errors.psnr
        );
    }
    out
}

/// The reference at one sample per pixel.
fn reference() -> Quality {
    Quality::reference().supersampling(1)
}

/// Production quality with N×N samples per pixel, N = 1 to 3.
fn anti_aliasing() -> Vec<(String, Quality)> {
    (1..=3)
        .map(|n| {
            let q = Quality::production().supersampling(n);
            (format!("production {n}x{n}"), q)
        })
        .collect()
}

fn table(rows: &[Row], groups: &[&str]) -> String {
    let mut out = String::from(
        "| scene | configuration | ms/frame | speed-up | DE evals/px | PSNR dB | PSNR ½ dB | SSIM | mask % | depth err |\n\
         |---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows.iter().filter(|r| groups.contains(&r.group)) {
        let e = &r.errors;
        let db = |v: f64| {
            if v.is_finite() {
                format!("{v:.1}")
            } else {
                "∞".into()
            }
        };
        let _ = writeln!(
            out,
            "| {} | {} | {:.0} | {:.1}× | {:.0} | {} | {} | {:.4} | {:.2} | {:.1e} |",
            r.scene,
            r.label,
            r.timing.median_ms,
            r.speedup,
            r.evaluations,
            db(e.psnr),
            db(e.psnr_half),
            e.ssim,
            e.mask_pct,
            e.depth
        );
    }
    out
}

fn csv(rows: &[Row], device: &str) -> String {
    let mut out = String::from(
        "scene,group,configuration,width,height,device,median_ms,runs,speedup,evaluations_per_pixel,psnr_db,psnr_half_db,ssim,mask_mismatch_pct,mean_depth_error\n",
    );
    for r in rows {
        let e = &r.errors;
        let _ = writeln!(
            out,
            "{},{},{},{},{},\"{}\",{:.3},{},{:.3},{:.2},{:.3},{:.3},{:.5},{:.4},{:.3e}",
            r.scene,
            r.group,
            r.label,
            r.size.0,
            r.size.1,
            device,
            r.timing.median_ms,
            r.timing.runs,
            r.speedup,
            r.evaluations,
            e.psnr,
            e.psnr_half,
            e.ssim,
            e.mask_pct,
            e.depth
        );
    }
    out
}

fn main() -> std::process::ExitCode {
    common::run(|| {
        let quick = measure::flag("--quick");
        let size = common::size_arg(if quick { (320, 240) } else { (640, 480) });
        let runs = if quick {
            Runs {
                min: 3,
                max: 5,
                budget: std::time::Duration::from_secs(2),
            }
        } else {
            Runs::default()
        };
        let scenes: Vec<String> = measure::value("--scenes").map_or_else(
            || SCENES.iter().map(ToString::to_string).collect(),
            |s| {
                s.split(',')
                    .filter(|n| !n.is_empty())
                    .map(str::to_string)
                    .collect()
            },
        );
        let study = Study {
            size,
            runs,
            effects: Effects::default(),
        };
        let device = fractal_sdf::render::devices()?
            .first()
            .map(|d| d.name.clone())
            .unwrap_or_default();
        eprintln!("{}x{} on {device}", size.0, size.1);
        std::fs::create_dir_all("out")
            .map_err(|e| Error::io("out", "cannot create the directory", e))?;
        let mut rows = Vec::new();
        for name in &scenes {
            let Some(scene) = fractal_sdf::gallery::by_name(name) else {
                eprintln!("error: no gallery scene `{name}`");
                std::process::exit(2);
            };
            eprintln!("{name}: reference");
            let (timing, reference) = study.measure(&scene, reference())?;
            fractal_sdf::output::save_png(&reference.image, format!("out/tradeoff_{name}.png"))?;
            let against = (timing.median_ms, &reference);
            rows.extend(study.group(name, &scene, "preset", presets(), against)?);
            let once = Study {
                runs: Runs {
                    min: 1,
                    max: 1,
                    ..runs
                },
                ..study
            };
            rows.extend(once.group(name, &scene, "floor", floor(), against)?);
            for (group, configs) in sweeps() {
                rows.extend(study.group(name, &scene, group, configs, against)?);
            }
            if !measure::flag("--no-aa") {
                // Anti-aliasing, at half the size, against 4×4 samples of
                // the same march.
                let aa = Study {
                    size: (size.0 / 2, size.1 / 2),
                    ..once
                };
                let best = aa.frame(&scene, Quality::production().supersampling(4))?;
                let mut aa_rows = aa.group(name, &scene, "aa", anti_aliasing(), (1.0, &best))?;
                let one = aa_rows[0].timing.median_ms;
                for r in &mut aa_rows {
                    r.speedup = one / r.timing.median_ms;
                }
                rows.extend(aa_rows);
                rows.extend(aa.progressive(name, &scene)?);
            }
        }
        if !measure::flag("--no-bounces") {
            // Secondary rays, on the gallery's mirrors and glass, against
            // paths eight bounces deep.
            let scene = fractal_sdf::gallery::materials();
            eprintln!("materials: bounces");
            let deepest = Quality::production().bounces(fractal_sdf::quality::MAX_BOUNCES);
            let (timing, best) = study.measure(&scene, deepest)?;
            let configs = (0..=4)
                .map(|n| (format!("bounces={n}"), Quality::production().bounces(n)))
                .collect();
            let against = (timing.median_ms, &best);
            rows.extend(study.group("materials", &scene, "bounces", configs, against)?);
        }
        println!(
            "Measured by `cargo run --release --example tradeoff` at {}x{} on {device}.\n",
            size.0, size.1
        );
        if rows.iter().any(|r| r.group == "preset") {
            println!("March accuracy (1 sample per pixel; error against `reference`):\n");
            println!("{}", table(&rows, &["preset", "floor"]));
            println!("Sweeps of production quality:\n");
            println!(
                "{}",
                table(
                    &rows,
                    &[
                        "max_steps",
                        "hit_epsilon",
                        "over_relaxation",
                        "cone_tile",
                        "fast_math",
                        "resolution_scale"
                    ]
                )
            );
            println!("The presets against every other measured configuration:\n");
            println!("{}", front(&rows));
            println!("The look: `detail` changes the surface drawn (production otherwise):\n");
            println!("{}", table(&rows, &["detail"]));
        }
        if rows.iter().any(|r| r.group == "aa") {
            println!(
                "Anti-aliasing at {}x{} (speed-up: against 1x1; error: against production with 4x4 samples):\n",
                size.0 / 2,
                size.1 / 2
            );
            println!("{}", table(&rows, &["aa"]));
            println!(
                "Progressive and adaptive passes at {}x{} (production, one sample per pass; adaptive: N passes at the refined share of the pixels, one elsewhere; speed-up: against one pass; error: against production with 8x8 samples):\n",
                size.0 / 2,
                size.1 / 2
            );
            println!("{}", table(&rows, &["progressive"]));
        }
        if rows.iter().any(|r| r.group == "bounces") {
            println!(
                "Reflections and refraction: `bounces` on the `materials` scene (speed-up and error: against 8 bounces):\n"
            );
            println!("{}", table(&rows, &["bounces"]));
        }
        let csv_path = "out/tradeoff.csv";
        std::fs::write(csv_path, csv(&rows, &device))
            .map_err(|e| Error::io(csv_path, "cannot write the table", e))?;
        let plot_path = "out/tradeoff.png";
        fractal_sdf::output::save_png(&plot::draw(&rows, size, &device), plot_path)?;
        eprintln!("wrote {csv_path} and {plot_path}");
        Ok(())
    })
}
