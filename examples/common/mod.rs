//! Shared by the examples: render one gallery scene to `out/NAME.png` and
//! print what it cost.
#![allow(dead_code)] // each example uses a different subset

pub mod measure;
pub mod sheet;

use std::time::Instant;

use fractal_sdf::prelude::*;
use fractal_sdf::quality::Glow;
use fractal_sdf::quality::Preset;
use fractal_sdf::render::{RenderOptions, Renderer};

/// Runs an example's body, printing an error (with its message, not its
/// debug form) and exiting with status 1 if it fails.
pub fn run(body: impl FnOnce() -> Result<()>) -> std::process::ExitCode {
    match body() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// Image size from `--size WxH` on the command line, or `default`.
pub fn size_arg(default: (u32, u32)) -> (u32, u32) {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == "--size")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.split_once('x'))
        .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)))
        .unwrap_or(default)
}

/// Renders `scene` at `size` with `options` to `out/NAME.png`, printing the
/// device, build and render times.
pub fn render_to_png(
    name: &str,
    scene: &Scene,
    options: &RenderOptions,
    size: (u32, u32),
) -> Result<()> {
    let start = Instant::now();
    let mut renderer = Renderer::with_options(scene, options)?;
    let build = renderer.build_info().clone();
    let t = Instant::now();
    // A lens's blur needs more samples than edges do: four passes. Paths
    // of light need more still: eight give a grainy first look (the
    // `global_illumination` example renders until the noise is low).
    let passes = if options.effects.global_illumination.is_some() {
        8
    } else if scene.camera.aperture > 0.0 {
        4
    } else {
        1
    };
    let image = if passes == 1 {
        renderer.render(size.0, size.1)?
    } else {
        let mut image = renderer.render_progressive(size.0, size.1)?;
        for _ in 1..passes {
            image = renderer.render_progressive(size.0, size.1)?;
        }
        image
    };
    let render_time = t.elapsed();
    let path = format!("out/{name}.png");
    fractal_sdf::output::save_png(&image, &path)?;
    println!(
        "{name:<12} {}x{} on {}: build {:.0} ms{}, render {:.0} ms, total {:.0} ms -> {path}",
        size.0,
        size.1,
        renderer.device().name,
        build.build_time.as_secs_f64() * 1e3,
        if build.cached { " (cached)" } else { "" },
        render_time.as_secs_f64() * 1e3,
        start.elapsed().as_secs_f64() * 1e3,
    );
    Ok(())
}

/// The options the gallery renders with: production quality with 2×2
/// supersampling and a soft glow.
pub fn gallery_options() -> RenderOptions {
    RenderOptions::default()
        .quality(Quality::production().supersampling(2))
        .effects(Effects::default().glow(Glow::new(dvec3(0.6, 0.75, 1.0), 0.6)))
}

/// A command-line error as the crate's error type.
pub fn usage(e: impl std::fmt::Display) -> Error {
    Error::Invalid {
        what: "command line",
        reason: format!("{e} (see --help)"),
    }
}

/// Parses `WxH`, such as `640x480`.
pub fn parse_size(text: &str) -> Result<(u32, u32)> {
    text.split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
        .filter(|&(w, h)| w > 0 && h > 0)
        .ok_or_else(|| usage(format!("`{text}` is not a size like 640x480")))
}

/// Parses a quality preset name.
pub fn parse_preset(text: &str) -> Result<Preset> {
    Preset::from_name(text).ok_or_else(|| {
        let names: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
        usage(format!(
            "unknown quality `{text}` (one of: {})",
            names.join(", ")
        ))
    })
}

/// The gallery scene called `name`, or an error listing the names.
pub fn gallery_scene(name: &str) -> Result<Scene> {
    fractal_sdf::gallery::by_name(name).ok_or_else(|| {
        usage(format!(
            "unknown scene `{name}` (one of: {})",
            fractal_sdf::gallery::names().join(", ")
        ))
    })
}

/// The CPU's model name from `/proc/cpuinfo` (Linux), or `unknown`.
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

/// The process's peak resident memory, where the system says it (Linux,
/// `VmHWM` in `/proc/self/status`).
pub fn peak_memory() -> String {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<u64>().ok())
        })
        .map_or_else(|| "n/a".into(), |kb| format!("{} MB", kb / 1024))
}
