//! What a frame's outputs cost: the gallery's `mandelbulb` at 640×480 (its
//! own quality) rendered as an image, with AOVs and with every layer, and
//! written as an 8-bit PNG, a 16-bit PNG, a 16-bit TIFF and an OpenEXR
//! file with every output. Each render is the median of five, alternating
//! between the three kinds; prints Markdown tables.
//!
//! `cargo run --release --example outputs [-- SCENE]`

use std::time::Instant;

use fractal_sdf::output::{Aov, Bits, FrameOutput, save_frame, save_png};
use fractal_sdf::prelude::*;
use fractal_sdf::render::{Frame, RenderOptions, Renderer};

fn main() -> fractal_sdf::Result<()> {
    let name = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "mandelbulb".into());
    let file = fractal_sdf::gallery::file(&name).expect("a gallery scene");
    let effects = file.effects;
    let options = RenderOptions::default()
        .quality(file.quality.unwrap_or_else(Quality::production))
        .effects(effects);
    let mut renderer = Renderer::with_options(&file.scene, &options)?;
    let (w, h) = (640, 480);
    let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
    // One of each first: buffers made, kernels warm.
    let mut frame: Frame = renderer.render_layers(w, h)?;
    renderer.render_with_aovs(w, h)?;
    renderer.render(w, h)?;
    let mut times = [Vec::new(), Vec::new(), Vec::new()];
    for _ in 0..5 {
        let t = Instant::now();
        renderer.render(w, h)?;
        times[0].push(ms(t));
        let t = Instant::now();
        renderer.render_with_aovs(w, h)?;
        times[1].push(ms(t));
        let t = Instant::now();
        frame = renderer.render_layers(w, h)?;
        times[2].push(ms(t));
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    println!("{name} at {w}x{h} on {}:\n", renderer.device().label());
    println!("| render | ms (median of 5) |\n|---|---:|");
    let labels = [
        "`render` (the image)",
        "`render_with_aovs`",
        "`render_layers`",
    ];
    for (label, t) in labels.into_iter().zip(&mut times) {
        println!("| {label} | {:.0} |", median(t));
    }

    let dir = std::env::temp_dir().join(format!("fractal-sdf-outputs-{}", std::process::id()));
    let all = FrameOutput::new(effects).aovs(Aov::ALL);
    let deep = FrameOutput::new(effects).bits(Bits::Sixteen);
    println!("\n| file | ms to write | size |\n|---|---:|---:|");
    let row =
        |label: &str, file: &str, write: &dyn Fn(&std::path::Path) -> fractal_sdf::Result<()>| {
            let path = dir.join(file);
            let t = Instant::now();
            write(&path)?;
            let took = ms(t);
            let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
            #[allow(clippy::cast_precision_loss)]
            let kib = bytes as f64 / 1024.0;
            println!("| {label} | {took:.0} | {kib:.0} KiB |");
            Ok::<(), fractal_sdf::Error>(())
        };
    row("8-bit PNG", "a.png", &|p| save_png(&frame.image, p))?;
    row("16-bit PNG", "b.png", &|p| {
        save_frame(&frame, p, &deep).map(|_| ())
    })?;
    row("16-bit TIFF", "c.tif", &|p| {
        save_frame(&frame, p, &deep).map(|_| ())
    })?;
    row("OpenEXR, every output", "d.exr", &|p| {
        save_frame(&frame, p, &all).map(|_| ())
    })?;
    std::fs::remove_dir_all(dir).ok();
    Ok(())
}
