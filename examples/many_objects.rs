//! Scenes of many objects: `N` coloured spheres scattered through a cube
//! over a floor, their positions baked or dynamic. Such a union compiles
//! to one loop over a table of the spheres, walked through a bounding
//! volume hierarchy, so compiling, memory and frames grow slowly with
//! `N`, and moving every sphere is a buffer update.
//!
//! Prints a Markdown table: compiling (validation, lowering, OpenCL C and
//! the program's build, not taken from PoCL's cache), the process's peak
//! memory, a 640×480 production frame (median of three, after one that
//! compiles the kernels), its distance evaluations per pixel, and for
//! dynamic positions the time to set all of them and to fill the tables
//! and fit the hierarchy again; last, the time the CPU reference takes to
//! name the object under every pixel of a frame (`Renderer::identify`,
//! which walks the same hierarchy on the host's threads).
//! Each row runs in a process of its own, so that its peak memory is its
//! own (Linux, from `/proc/self/status`).
//!
//! `cargo run --release --example many_objects` (1,000, 10,000 and 100,000
//! spheres, baked and dynamic), or `-- N baked|dynamic` for one row; the
//! 100,000 baked spheres' frame is written to `out/many_objects.png`.
//! With `--features wgpu` and `--backend wgpu` (before the row's
//! arguments, if any) the same table is measured on the wgpu backend,
//! less the object ids, which belong to the OpenCL renderer; compiling is
//! then the WGSL module and its pipeline, and the 100,000 baked spheres'
//! frame is `out/many_objects_wgpu.png`.

mod common;

use std::process::Command;
use std::time::Instant;

use fractal_sdf::prelude::*;
use fractal_sdf::render::{RenderFrames, RenderOptions, Renderer};
use fractal_sdf::scene::{Param3, param3};

const HEADER: &str = "| spheres | positions | compile | peak memory | 640×480 production frame | evaluations / pixel | set every position | fill the tables and refit |";

fn main() -> fractal_sdf::Result<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let wgpu = match args.iter().position(|a| a == "--backend") {
        Some(i) if args.get(i + 1).map(String::as_str) == Some("wgpu") => {
            args.drain(i..=i + 1);
            true
        }
        Some(i) if args.get(i + 1).map(String::as_str) == Some("opencl") => {
            args.drain(i..=i + 1);
            false
        }
        Some(_) => return Err(common::usage("--backend takes opencl or wgpu")),
        None => false,
    };
    if let [n, mode] = args.as_slice() {
        let n: usize = n.parse().expect("a sphere count");
        println!("{}", row(n, mode == "dynamic", wgpu)?);
        return Ok(());
    }
    if wgpu {
        println!("{HEADER}\n|---:|---|---:|---:|---:|---:|---:|---:|");
    } else {
        println!("{HEADER} object ids (CPU) |\n|---:|---|---:|---:|---:|---:|---:|---:|---:|");
    }
    let me = std::env::current_exe().expect("the example's path");
    let backend = if wgpu { "wgpu" } else { "opencl" };
    for n in [1_000, 10_000, 100_000] {
        for mode in ["baked", "dynamic"] {
            // Each program compiled afresh, not taken from PoCL's cache.
            let out = Command::new(&me)
                .args(["--backend", backend, &n.to_string(), mode])
                .env("POCL_KERNEL_CACHE", "0")
                .output()
                .expect("the example runs");
            let text = String::from_utf8_lossy(&out.stdout);
            match text.lines().last() {
                Some(line) if out.status.success() => println!("{line}"),
                _ => println!(
                    "| {n} | {mode} | failed: {} |",
                    String::from_utf8_lossy(&out.stderr).trim()
                ),
            }
        }
    }
    Ok(())
}

/// The centre, radius and colour of sphere `i` of `n`: a jittered grid
/// filling the cube `[-1, 1]³`.
#[allow(clippy::cast_precision_loss)]
fn placed(i: usize, n: usize) -> (DVec3, f64, DVec3) {
    let side = (1..).find(|s| s * s * s >= n).unwrap_or(1);
    let cell = 2.0 / side as f64;
    let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
    let hash = |k: usize| ((i * 2_654_435_761 + k * 40_503) % 1000) as f64 / 1000.0 - 0.5;
    let grid = dvec3(x as f64, y as f64, z as f64) + 0.5 + 0.5 * dvec3(hash(1), hash(2), hash(3));
    let centre = grid * cell - 1.0;
    let radius = cell * (0.2 + 0.15 * (hash(4) + 0.5));
    let colour = (centre * 0.5 + 0.5).clamp(DVec3::splat(0.05), DVec3::ONE);
    (centre, radius, colour)
}

fn scene(n: usize, dynamic: bool) -> Scene {
    let spheres = (0..n)
        .map(|i| {
            let (centre, radius, colour) = placed(i, n);
            let at: Param3 = if dynamic {
                param3(&format!("s{i}"), centre)
            } else {
                centre.into()
            };
            sphere(radius).translate(at).color(colour)
        })
        .reduce(Node::union)
        .expect("at least one sphere");
    Scene::new(spheres.union(plane(DVec3::Y, 1.05)))
        .with_camera(Camera::look_at(dvec3(2.4, 1.6, 3.2), dvec3(0.0, -0.1, 0.0)))
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Moves every sphere of `n` a little: the positions of a dynamic row.
#[allow(clippy::cast_precision_loss)]
fn move_all(
    n: usize,
    mut set: impl FnMut(&str, f64) -> fractal_sdf::Result<()>,
) -> fractal_sdf::Result<()> {
    for i in 0..n {
        let (centre, ..) = placed(i, n);
        let moved = centre + dvec3(0.0, 0.1 * (i as f64 * 0.37).sin(), 0.0);
        for (axis, v) in ["x", "y", "z"].iter().zip(moved.to_array()) {
            set(&format!("s{i}.{axis}"), v)?;
        }
    }
    Ok(())
}

/// The median of three 640×480 frames (the 100,000 baked spheres' saved
/// to `png`), and for dynamic positions the time to set every position and
/// the time `refit` takes to fill the tables and fit the boxes again.
fn frames_and_moves<R: RenderFrames>(
    renderer: &mut R,
    n: usize,
    dynamic: bool,
    png: &str,
    refit: impl Fn(&R) -> usize,
) -> fractal_sdf::Result<(f64, String, String)> {
    let mut times = Vec::new();
    for _ in 0..3 {
        let t = Instant::now();
        let image = renderer.render(640, 480)?;
        times.push(ms(t));
        if n == 100_000 && !dynamic {
            std::fs::create_dir_all("out").ok();
            fractal_sdf::output::save_png(&image, png)?;
        }
    }
    times.sort_by(f64::total_cmp);
    if !dynamic {
        return Ok((times[1], "(a new program)".into(), String::new()));
    }
    let t = Instant::now();
    move_all(n, |name, v| renderer.set_param(name, v))?;
    let set = ms(t);
    let t = Instant::now();
    assert!(refit(renderer) > 0);
    let refitted = ms(t);
    Ok((
        times[1],
        format!("{set:.0} ms"),
        format!("{refitted:.1} ms"),
    ))
}

fn row(n: usize, dynamic: bool, wgpu: bool) -> fractal_sdf::Result<String> {
    if wgpu {
        return wgpu_row(n, dynamic);
    }
    let scene = scene(n, dynamic);
    let t = Instant::now();
    // The tree of nodes is not needed once compiled: dropped here, it
    // leaves the peak (100,000 spheres' tree is about 180 MB).
    let compiled = scene.compile()?;
    drop(scene);
    let options = RenderOptions::default().quality(Quality::production());
    let mut renderer = Renderer::from_compiled(compiled, &options)?;
    let compile = ms(t);
    let (w, h) = (640, 480);
    let frame = renderer.render_with_aovs(w, h)?;
    let evaluations: f64 =
        frame.evaluations.iter().map(|&e| f64::from(e)).sum::<f64>() / f64::from(w * h);
    let (frame, set, refit) =
        frames_and_moves(&mut renderer, n, dynamic, "out/many_objects.png", |r| {
            r.source().param_buffer(r.values().as_slice()).len()
        })?;
    // Read before the layered frame's buffers add to it.
    let peak = common::peak_memory();
    let mut layered = renderer.render_layers(w, h)?;
    let t = Instant::now();
    renderer.identify(&mut layered)?;
    let ids = ms(t);
    Ok(format!(
        "| {n} | {} | {compile:.0} ms | {} | {:.0} ms | {evaluations:.1} | {set} | {refit} | {ids:.0} ms |",
        if dynamic { "dynamic" } else { "baked" },
        peak,
        frame,
    ))
}

/// A row on the wgpu backend: the same scene, frames and moves.
#[cfg(feature = "wgpu")]
fn wgpu_row(n: usize, dynamic: bool) -> fractal_sdf::Result<String> {
    use fractal_sdf::render::WgpuRenderer;
    let scene = scene(n, dynamic);
    let t = Instant::now();
    let compiled = scene.compile()?;
    drop(scene);
    let options = RenderOptions::default().quality(Quality::production());
    let mut renderer = WgpuRenderer::from_compiled(compiled, &options)?;
    let compile = ms(t);
    let (w, h) = (640, 480);
    let evaluations = renderer.render_frame(w, h)?.evaluations_per_pixel();
    let (frame, set, refit) = frames_and_moves(
        &mut renderer,
        n,
        dynamic,
        "out/many_objects_wgpu.png",
        |r| r.source().param_buffer(r.values().as_slice()).len(),
    )?;
    Ok(format!(
        "| {n} | {} | {compile:.0} ms | {} | {:.0} ms | {evaluations:.1} | {set} | {refit} |",
        if dynamic { "dynamic" } else { "baked" },
        common::peak_memory(),
        frame,
    ))
}

#[cfg(not(feature = "wgpu"))]
fn wgpu_row(_: usize, _: bool) -> fractal_sdf::Result<String> {
    Err(common::usage(
        "--backend wgpu needs the wgpu feature: cargo run --release --features wgpu --example many_objects -- --backend wgpu",
    ))
}
