//! The performance benchmark: the gallery's `benchmark` scene (a fractal
//! and primitives, two lights, ambient occlusion, soft shadows and glow)
//! along its fixed camera path, timed frame by frame.
//!
//! `cargo run --release --example benchmark -- --resolution 1920x1080 --frames 60 --runs 3`
//!
//! Prints the resolution, duration, frame count, minimum, maximum and
//! average frame time and frame rate, the kernel time (from OpenCL
//! profiling events) apart from the readback, and the device, driver,
//! OpenCL version and CPU; writes every run and their mean to
//! `out/benchmark.csv`. Run with `--help` for every option.

mod common;

use std::fmt::Write as _;
use std::time::{Duration, Instant};

use fractal_sdf::gallery;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Glow;
use fractal_sdf::quality::Preset;
use fractal_sdf::render::{RenderOptions, Renderer};
use fractal_sdf::view::FrameStats;

const HELP: &str = "\
fractal-sdf benchmark: time the benchmark scene along its camera path.

USAGE: benchmark [OPTIONS]

OPTIONS:
  --resolution WxH   image size (default 640x480)
  --frames N         frames per run, spread evenly over the 10 s path (default 30)
  --seconds S        instead: render for S seconds per run, the camera at the
                     elapsed time (so slower devices see fewer frames)
  --runs K           runs, averaged (default 3)
  --quality NAME     draft, preview, production (default) or reference
  --csv FILE         where to write the results (default out/benchmark.csv)
  -h, --help         this text
";

/// How long one run lasts.
#[derive(Debug, Clone, Copy)]
enum Length {
    Frames(u32),
    Seconds(f64),
}

/// One run's measurements.
#[derive(Debug, Clone, Copy)]
struct Run {
    duration: Duration,
    frames: FrameStats,
    kernel: FrameStats,
    readback: FrameStats,
}

impl Run {
    /// The reported values, in [`COLUMNS`] order.
    fn values(&self) -> [f64; 10] {
        let ms = |d: Option<Duration>| d.map_or(f64::NAN, |d| d.as_secs_f64() * 1e3);
        #[allow(clippy::cast_precision_loss)]
        let n = self.frames.count() as f64;
        // The seed's definition: average frame time = duration / frames.
        let average_ms = self.duration.as_secs_f64() * 1e3 / n;
        [
            n,
            self.duration.as_secs_f64(),
            ms(self.frames.min()),
            ms(self.frames.max()),
            average_ms,
            1e3 / average_ms,
            self.frames.min_fps().unwrap_or(f64::NAN),
            self.frames.max_fps().unwrap_or(f64::NAN),
            ms(self.kernel.mean()),
            ms(self.readback.mean()),
        ]
    }
}

const COLUMNS: [&str; 10] = [
    "frames",
    "duration_s",
    "min_ms",
    "max_ms",
    "avg_ms",
    "avg_fps",
    "min_fps",
    "max_fps",
    "kernel_ms",
    "readback_ms",
];

/// A value with about four significant digits (whole numbers as they are).
fn number(x: f64) -> String {
    if x.fract() == 0.0 && x.abs() < 1e15 {
        format!("{x:.0}")
    } else if x.abs() >= 100.0 {
        format!("{x:.1}")
    } else if x.abs() >= 1.0 {
        format!("{x:.3}")
    } else {
        format!("{x:.5}")
    }
}

/// Renders one run.
fn run(renderer: &mut Renderer, size: (u32, u32), length: Length) -> Result<Run> {
    let path = gallery::benchmark_path()?;
    let motions = gallery::motions("benchmark");
    let base = *renderer.camera();
    let mut result = Run {
        duration: Duration::ZERO,
        frames: FrameStats::new(),
        kernel: FrameStats::new(),
        readback: FrameStats::new(),
    };
    let start = Instant::now();
    for i in 0u32.. {
        let t = match length {
            Length::Frames(n) if i >= n => break,
            Length::Frames(n) => path.duration() * f64::from(i) / f64::from(n),
            Length::Seconds(s) if start.elapsed().as_secs_f64() >= s => break,
            Length::Seconds(_) => start.elapsed().as_secs_f64() % path.duration(),
        };
        renderer.set_camera(path.camera_at(path.start() + t, &base))?;
        for m in &motions {
            for (name, value) in m.values(t) {
                renderer.set_param(&name, value)?;
            }
        }
        let frame = Instant::now();
        renderer.render(size.0, size.1)?;
        result.frames.push(frame.elapsed());
        let timing = renderer.last_timing().expect("a frame was rendered");
        result.kernel.push(timing.kernel);
        result.readback.push(timing.readback);
    }
    result.duration = start.elapsed();
    Ok(result)
}

fn main() -> std::process::ExitCode {
    common::run(|| {
        let mut a = pico_args::Arguments::from_env();
        if a.contains(["-h", "--help"]) {
            print!("{HELP}");
            return Ok(());
        }
        let u = common::usage;
        let size = match a
            .opt_value_from_str::<_, String>("--resolution")
            .map_err(u)?
        {
            Some(s) => common::parse_size(&s)?,
            None => (640, 480),
        };
        let frames: Option<u32> = a.opt_value_from_str("--frames").map_err(u)?;
        let seconds: Option<f64> = a.opt_value_from_str("--seconds").map_err(u)?;
        let length = match (frames, seconds) {
            (Some(_), Some(_)) => {
                return Err(common::usage("give --frames or --seconds, not both"));
            }
            (Some(0), _) => return Err(common::usage("--frames must be at least 1")),
            (Some(n), None) => Length::Frames(n),
            (None, Some(s)) if s > 0.0 && s.is_finite() => Length::Seconds(s),
            (None, Some(s)) => {
                return Err(common::usage(format!("--seconds must be > 0, got {s}")));
            }
            (None, None) => Length::Frames(30),
        };
        let runs: u32 = a
            .opt_value_from_str("--runs")
            .map_err(u)?
            .unwrap_or(3)
            .max(1);
        let preset = match a.opt_value_from_str::<_, String>("--quality").map_err(u)? {
            Some(q) => common::parse_preset(&q)?,
            None => Preset::Production,
        };
        let csv: String = a
            .opt_value_from_str("--csv")
            .map_err(u)?
            .unwrap_or_else(|| "out/benchmark.csv".into());
        let rest = a.finish();
        if !rest.is_empty() {
            return Err(common::usage(format!("unexpected arguments {rest:?}")));
        }

        // Ambient occlusion and shadows are on by default.
        let options = RenderOptions::default()
            .quality(preset.quality())
            .effects(Effects::default().glow(Some(Glow::new(dvec3(0.6, 0.75, 1.0), 0.6))));
        let mut renderer = Renderer::with_options(&gallery::benchmark(), &options)?;
        let device = renderer.device().clone();
        let cpu = common::cpu_model();
        println!("fractal-sdf benchmark");
        println!(
            "  scene       benchmark: Mandelbulb, Menger sponge, torus, orbiting sphere, floor;"
        );
        println!(
            "              2 soft-shadowed lights; AO, soft shadows, glow; {} quality",
            preset.name()
        );
        println!("  resolution  {}x{}", size.0, size.1);
        println!(
            "  device      {} ({:?}, {} compute units)",
            device.label(),
            device.kind,
            device.compute_units
        );
        println!("  driver      {}", device.driver_version);
        println!(
            "  opencl      {} / {}",
            device.opencl_version, device.opencl_c_version
        );
        println!("  cpu         {cpu}");
        println!(
            "  build       {:.0} ms{}",
            renderer.build_info().build_time.as_secs_f64() * 1e3,
            if renderer.build_info().cached {
                " (cached)"
            } else {
                ""
            }
        );
        // One untimed frame allocates the output buffers.
        renderer.render(size.0, size.1)?;

        println!();
        let header: Vec<String> = std::iter::once("run".to_string())
            .chain(COLUMNS.iter().map(|c| (*c).to_string()))
            .collect();
        let print_row = |label: &str, v: &[f64; 10]| {
            let mut line = format!("{label:>5} {:>7}", number(v[0]));
            for x in &v[1..] {
                let _ = write!(line, " {:>11}", number(*x));
            }
            println!("{line}");
        };
        let mut line = format!("{:>5} {:>7}", header[0], header[1]);
        for h in &header[2..] {
            let _ = write!(line, " {h:>11}");
        }
        println!("{line}");
        let mut rows = Vec::new();
        for k in 1..=runs {
            let r = run(&mut renderer, size, length)?;
            let v = r.values();
            print_row(&k.to_string(), &v);
            rows.push(v);
        }
        let mut mean = [0.0; 10];
        for row in &rows {
            for (m, x) in mean.iter_mut().zip(row) {
                *m += x / f64::from(runs);
            }
        }
        print_row("mean", &mean);
        let profiled = renderer.last_timing().is_some_and(|t| t.profiled);
        println!(
            "\nkernel_ms: device time per frame from {}; readback_ms: copying the image to the host.",
            if profiled {
                "OpenCL profiling events"
            } else {
                "host timing (the device reports no profiling events)"
            }
        );

        let mut text = format!(
            "run,{},width,height,quality,device,driver,opencl,cpu\n",
            COLUMNS.join(",")
        );
        let quote = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
        let labels = (1..=runs)
            .map(|k| k.to_string())
            .chain(["mean".to_string()]);
        for (label, row) in labels.zip(rows.iter().chain([&mean])) {
            let values: Vec<String> = row.iter().map(|x| number(*x)).collect();
            let _ = writeln!(
                text,
                "{label},{},{},{},{},{},{},{},{}",
                values.join(","),
                size.0,
                size.1,
                preset.name(),
                quote(&device.label()),
                quote(&device.driver_version),
                quote(&device.opencl_version),
                quote(&cpu)
            );
        }
        if let Some(dir) = std::path::Path::new(&csv).parent() {
            std::fs::create_dir_all(dir)
                .map_err(|source| Error::io(dir, "cannot create the directory", source))?;
        }
        std::fs::write(&csv, text)
            .map_err(|source| Error::io(&csv, "cannot write the table", source))?;
        println!("-> {csv}");
        Ok(())
    })
}
