//! The cost of a very deep scene: `Scene::add` called N times (a union
//! chain N levels deep), then compiled, turned into OpenCL C, evaluated once
//! on the CPU, rendered on the OpenCL device and dropped. Nothing in the
//! crate recurses on the depth, so this runs on a small stack; the spheres
//! differ only in their positions, so the program loops over a table of
//! them instead of spelling each out.
//!
//! `cargo run --release --example deep_scene [-- 100000]`

use std::time::Instant;

use fractal_sdf::codegen::{self, Options};
use fractal_sdf::cpu;
use fractal_sdf::prelude::*;
use fractal_sdf::render::{RenderOptions, Renderer};

fn main() -> fractal_sdf::Result<()> {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000);
    // A 256 KiB stack: a recursive walk of the tree would overflow it.
    std::thread::Builder::new()
        .stack_size(256 << 10)
        .spawn(move || run(n))
        .expect("a thread starts")
        .join()
        .expect("the thread finishes")
}

fn run(n: usize) -> fractal_sdf::Result<()> {
    let side = (1..).find(|s| s * s * s >= n).unwrap_or(1);
    let t = Instant::now();
    let mut scene = Scene::empty();
    #[allow(clippy::cast_precision_loss)]
    for i in 0..n {
        let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
        let c = dvec3(x as f64, y as f64, z as f64) / side as f64 * 2.0 - 1.0;
        scene = scene.add(sphere(0.4 / side as f64).translate(c));
    }
    println!("build with add: {:?}", t.elapsed());
    let t = Instant::now();
    let compiled = scene.compile()?;
    println!(
        "compile: {:?} ({} IR nodes)",
        t.elapsed(),
        compiled.ir().nodes().len()
    );
    let t = Instant::now();
    let source = codegen::emit(&compiled, &Options::default())?;
    println!(
        "emit: {:?} ({:.1} kB of OpenCL C, {} table values)",
        t.elapsed(),
        source.source.len() as f64 / 1e3,
        source.constants.len()
    );
    let eval = cpu::Evaluator::from_compiled(&compiled);
    let t = Instant::now();
    let d = eval.distance(dvec3(0.0, 0.0, 3.0));
    println!("one CPU distance: {:?} (d = {d:.4})", t.elapsed());
    let scene = scene.with_camera(Camera::look_at(dvec3(2.2, 1.7, 2.9), DVec3::ZERO));
    let t = Instant::now();
    let options = RenderOptions::default().quality(Quality::draft());
    let mut renderer = Renderer::from_compiled(scene.compile()?, &options)?;
    println!("renderer (build the program): {:?}", t.elapsed());
    for frame in ["first", "second"] {
        let t = Instant::now();
        let image = renderer.render(64, 48)?;
        println!("{frame} 64x48 draft frame: {:?}", t.elapsed());
        if frame == "second" {
            fractal_sdf::output::save_png(&image, "out/deep_scene.png")?;
        }
    }
    let t = Instant::now();
    drop((scene, compiled, eval, renderer));
    println!("drop: {:?}", t.elapsed());
    Ok(())
}
