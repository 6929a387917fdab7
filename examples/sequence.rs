//! Renders a camera path to numbered PNGs, then (with `ffmpeg` on the
//! `PATH`) an MP4.
//!
//! `cargo run --release --example sequence -- fractal_mix --seconds 4 --fps 24`
//!
//! Frames go to `out/seq/frame_00000.png`, ... Frames already on disk are
//! skipped, so an interrupted run resumes where it stopped; `--frames a..b`
//! renders a sub-range. Run with `--help` for every option.

mod common;

use std::path::{Path, PathBuf};

use fractal_sdf::animation::CameraPath;
use fractal_sdf::gallery;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Preset;
use fractal_sdf::render::Renderer;
use fractal_sdf::sequence::{Encoded, Sequence, parse_range};
use indicatif::{ProgressBar, ProgressStyle};

const HELP: &str = "\
fractal-sdf sequence: render a camera path to numbered PNG frames.

USAGE: sequence [SCENE] [OPTIONS]

SCENE is a gallery scene name (default fractal_mix). Animated parameters
(such as fractal_mix's Mandelbulb power) move with the frames' times.

OPTIONS:
  --path FILE        a camera path in TOML (default: one orbit around the
                     scene's camera target, at the camera's distance and height)
  --seconds S        length of the built-in orbit (default 4)
  --fps R            frames per second (default 24)
  --size WxH         image size (default 640x480)
  --quality NAME     draft, preview, production (default) or reference
  --frames RANGE     render only these frames: a..b, a..=b, a.., ..b or n
  --out DIR          where the frames go (default out/seq)
  --video FILE       the MP4 to encode with ffmpeg (default DIR.mp4)
  -h, --help         this text

A path file lists keyframes:
  [[keyframe]]
  time = 0.0
  position = [0.0, 1.0, 3.0]
  target = [0.0, 0.0, 0.0]
";

/// One turn around the scene camera's target, at its distance and height.
fn orbit(scene: &Scene, seconds: f64) -> Result<CameraPath> {
    let c = &scene.camera;
    let offset = c.position - c.target;
    let radius = offset.with_y(0.0).length().max(1e-3);
    CameraPath::orbit(c.target, radius, offset.y, seconds, 16)
}

fn read_path(file: &Path) -> Result<CameraPath> {
    let text = std::fs::read_to_string(file)
        .map_err(|source| Error::io(file, "cannot read the camera path", source))?;
    CameraPath::from_toml(&text)
}

fn encode(seq: &Sequence, video: &Path) {
    match seq.encode(video) {
        Encoded::Written => println!("video -> {}", video.display()),
        other => println!("{other}"),
    }
}

fn main() -> std::process::ExitCode {
    common::run(|| {
        let mut a = pico_args::Arguments::from_env();
        if a.contains(["-h", "--help"]) {
            print!("{HELP}");
            return Ok(());
        }
        let u = common::usage;
        let size = match a.opt_value_from_str::<_, String>("--size").map_err(u)? {
            Some(s) => common::parse_size(&s)?,
            None => (640, 480),
        };
        let preset = match a.opt_value_from_str::<_, String>("--quality").map_err(u)? {
            Some(q) => common::parse_preset(&q)?,
            None => Preset::Production,
        };
        let path_file: Option<PathBuf> = a.opt_value_from_str("--path").map_err(u)?;
        let seconds: f64 = a.opt_value_from_str("--seconds").map_err(u)?.unwrap_or(4.0);
        let fps: f64 = a.opt_value_from_str("--fps").map_err(u)?.unwrap_or(24.0);
        let range: Option<String> = a.opt_value_from_str("--frames").map_err(u)?;
        let out: PathBuf = a
            .opt_value_from_str("--out")
            .map_err(u)?
            .unwrap_or_else(|| "out/seq".into());
        let video: PathBuf = a
            .opt_value_from_str("--video")
            .map_err(u)?
            .unwrap_or_else(|| out.with_extension("mp4"));
        let name: String = a
            .opt_free_from_str()
            .map_err(u)?
            .unwrap_or_else(|| "fractal_mix".into());
        let rest = a.finish();
        if !rest.is_empty() {
            return Err(common::usage(format!("unexpected arguments {rest:?}")));
        }

        let scene = common::gallery_scene(&name)?;
        let path = match &path_file {
            Some(file) => read_path(file)?,
            None => orbit(&scene, seconds)?,
        };
        let seq = Sequence::for_duration(&out, fps, path.duration())?;
        let range = match &range {
            Some(r) => parse_range(r, seq.frames())?,
            None => 0..seq.frames(),
        };
        let todo = seq.remaining(range.clone(), size);
        println!(
            "{name}: frames {}..{} of {} at {fps} fps, {}x{}, {} quality -> {}/ ({} whole on disk already)",
            range.start,
            range.end,
            seq.frames(),
            size.0,
            size.1,
            preset.name(),
            out.display(),
            range.len() - todo.len(),
        );

        if !todo.is_empty() {
            let options = common::gallery_options().quality(preset.quality());
            let mut renderer = Renderer::with_options(&scene, &options)?;
            let bar = ProgressBar::new(todo.len() as u64);
            bar.set_style(
                ProgressStyle::with_template(
                    "{bar:40} {pos}/{len} frames  {elapsed_precise} elapsed, ETA {eta}  {msg}",
                )
                .expect("a valid template"),
            );
            let motions = gallery::motions(&name);
            seq.render(&mut renderer, &path, &motions, &todo, size, |frame| {
                if let Some(t) = frame.timing {
                    bar.set_message(format!("{:.0} ms/frame", t.total.as_secs_f64() * 1e3));
                }
                bar.inc(1);
            })?;
            bar.finish();
        }
        if seq.remaining(0..seq.frames(), size).is_empty() {
            encode(&seq, &video);
        } else {
            println!("some frames are still missing: run again without --frames to finish");
        }
        Ok(())
    })
}
