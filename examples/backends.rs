//! The gallery on both backends: each scene file's quality and effects,
//! rendered by the OpenCL backend ([`Renderer`]) and by the wgpu backend
//! ([`WgpuRenderer`]), alternating, three times each. Prints the median
//! frame time and evaluations per pixel of each, the PSNR between the two
//! images (and of their 4×4 blocks' means for a path-traced or
//! brute-forced scene) and
//! the share of pixels whose hit flags differ; writes
//! `out/backend_<scene>_opencl.png` and `out/backend_<scene>_wgpu.png`.
//! Scenes the wgpu backend does not draw yet are listed with its reason.
//! Then the wgpu pipeline's creation, cold and from the cache, and the
//! frame time of a Mandelbulb whose power changes every frame.
//!
//! `cargo run --release --features wgpu --example backends [--size WxH] [SCENE...]`
//! (640×480 and every gallery scene by default; on a machine without a
//! GPU the two are PoCL and Mesa's lavapipe, both on the CPU's cores).

use std::error::Error;
use std::time::Instant;

use fractal_sdf::metrics::{block_psnr, mask_mismatch, psnr};
use fractal_sdf::prelude::*;
use fractal_sdf::render::{RenderOptions, Renderer, WgpuRenderer};

fn main() -> Result<(), Box<dyn Error>> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let (mut width, mut height) = (640, 480);
    if let Some(at) = args.iter().position(|a| a == "--size") {
        let size = args.get(at + 1).ok_or("--size needs WxH")?.clone();
        let (w, h) = size.split_once('x').ok_or("--size needs WxH")?;
        (width, height) = (w.parse()?, h.parse()?);
        args.drain(at..at + 2);
    }
    std::fs::create_dir_all("out")?;
    let mut table = Vec::new();
    for name in fractal_sdf::gallery::names() {
        if !args.is_empty() && !args.iter().any(|a| a == name) {
            continue;
        }
        let file = fractal_sdf::gallery::file(name).expect("a gallery scene");
        let compiled = file.scene.compile()?;
        // Pictures drawn from samples that may go another way where the
        // backends' arithmetic differs in its last bits (a path that
        // bounced elsewhere, a ray that stopped at another filament of an
        // escape-time set): their 4×4 blocks' means say whether the
        // pictures agree.
        let sampled =
            file.effects.global_illumination.is_some() || compiled.ir().has_inside_shapes();
        let mut options = RenderOptions::default();
        options.quality = file.quality.unwrap_or_default();
        options.effects = file.effects;
        let mut wgpu = match WgpuRenderer::from_compiled(compiled.clone(), &options) {
            Ok(r) => r,
            Err(e) => {
                println!("{name}: {e}");
                continue;
            }
        };
        let mut opencl = Renderer::from_compiled(compiled, &options)?;
        if table.is_empty() {
            table.push(format!(
                "{width}×{height}, each scene file's quality and effects; median of 3:\n\
                 | scene | OpenCL ({}) ms | evaluations / pixel | wgpu ({}) ms | \
                 evaluations / pixel | PSNR (dB) | hit flags that differ |\n\
                 |---|---:|---:|---:|---:|---:|---:|",
                opencl.device().name,
                wgpu.adapter().name
            ));
        }
        let (mut cl_ms, mut wg_ms) = (Vec::new(), Vec::new());
        let (mut cl, mut wg) = (None, None);
        for _ in 0..3 {
            let started = Instant::now();
            cl = Some(opencl.render_with_aovs(width, height)?);
            cl_ms.push(started.elapsed().as_secs_f64() * 1e3);
            let started = Instant::now();
            wg = Some(wgpu.render_frame(width, height)?);
            wg_ms.push(started.elapsed().as_secs_f64() * 1e3);
        }
        let (cl, wg) = (cl.expect("rendered"), wg.expect("rendered"));
        cl.image.save(format!("out/backend_{name}_opencl.png"))?;
        wg.image.save(format!("out/backend_{name}_wgpu.png"))?;
        let pixels = f64::from(width * height);
        let cl_evals = cl.evaluations.iter().map(|&e| f64::from(e)).sum::<f64>() / pixels;
        let differ = mask_mismatch(&cl.hit, &wg.hit);
        let blocks = if sampled {
            format!(
                " ({:.1} in 4×4 blocks)",
                block_psnr(&cl.image, &wg.image, 4)
            )
        } else {
            String::new()
        };
        table.push(format!(
            "| {name} | {:.1} | {cl_evals:.1} | {:.1} | {:.1} | {:.1}{blocks} | {:.3}% |",
            median(&mut cl_ms),
            median(&mut wg_ms),
            wg.evaluations_per_pixel(),
            psnr(&cl.image, &wg.image),
            100.0 * differ
        ));
    }
    println!("{}", table.join("\n"));
    pipelines_and_dynamic_frames(width, height)
}

/// The wgpu pipeline built cold and found in the cache, and frames whose
/// dynamic parameter changes each time.
fn pipelines_and_dynamic_frames(width: u32, height: u32) -> Result<(), Box<dyn Error>> {
    let power = fractal_sdf::scene::param("power", 8.0);
    let scene = Scene::new(mandelbulb(power))
        .with_camera(Camera::look_at(dvec3(0.0, 0.5, 3.0), DVec3::ZERO));
    let quality = Quality::production();
    let started = Instant::now();
    let mut cold = WgpuRenderer::new(&scene, quality)?;
    let cold_total = started.elapsed().as_secs_f64() * 1e3;
    let started = Instant::now();
    let cached = WgpuRenderer::new(&scene, quality)?;
    let cached_total = started.elapsed().as_secs_f64() * 1e3;
    println!(
        "\nwgpu pipeline for a dynamic-power Mandelbulb at production: built in {:.1} ms \
         ({cold_total:.1} ms the whole renderer), from the cache in {:.3} ms \
         ({cached_total:.1} ms the whole renderer)",
        cold.pipeline_time().as_secs_f64() * 1e3,
        cached.pipeline_time().as_secs_f64() * 1e3,
    );
    let mut opencl = Renderer::new(&scene, quality)?;
    let (mut still, mut moving, mut cl_moving) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..5 {
        let started = Instant::now();
        cold.render(width, height)?;
        still.push(started.elapsed().as_secs_f64() * 1e3);
        let value = 8.0 + 0.25 * f64::from(i + 1);
        let started = Instant::now();
        cold.set_param("power", value)?;
        cold.render(width, height)?;
        moving.push(started.elapsed().as_secs_f64() * 1e3);
        let started = Instant::now();
        opencl.set_param("power", value)?;
        opencl.render(width, height)?;
        cl_moving.push(started.elapsed().as_secs_f64() * 1e3);
    }
    println!(
        "{width}×{height} frames, median of 5: wgpu {:.1} ms unchanged, {:.1} ms with the power \
         changed before each (pipelines built since the first: {}); OpenCL {:.1} ms with it \
         changed",
        median(&mut still),
        median(&mut moving),
        cold.builds() - 1,
        median(&mut cl_moving),
    );
    Ok(())
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}
