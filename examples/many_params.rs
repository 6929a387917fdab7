//! The cost of a scene with many dynamic parameters: a flat union of `N`
//! spheres, each with its own dynamic radius, built in Rust, compiled,
//! turned into OpenCL C, written as a scene file and read back (which
//! compiles it again). Prints one Markdown row: the time of each step and
//! the process's peak memory after them (Linux, from `/proc/self/status`).
//!
//! `cargo run --release --example many_params [-- N]` (default 16,000)

mod common;

use std::time::Instant;

use fractal_sdf::codegen::{self, Options};
use fractal_sdf::file::SceneFile;
use fractal_sdf::prelude::*;

fn main() -> fractal_sdf::Result<()> {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(16_000);
    let side = (1..).find(|s| s * s * s >= n).unwrap_or(1);
    let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    #[allow(clippy::cast_precision_loss)]
    let node = (0..n)
        .map(|i| {
            let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
            let c = dvec3(x as f64, y as f64, z as f64) / side as f64 * 2.0 - 1.0;
            sphere(param(format!("r{i}"), 0.4 / side as f64)).translate(c)
        })
        .reduce(Node::union)
        .expect("at least one sphere");
    let scene = Scene::new(node);
    let build = ms(t);
    let t = Instant::now();
    let compiled = scene.compile()?;
    let compile = ms(t);
    let t = Instant::now();
    let source = codegen::emit(&compiled, &Options::default())?;
    let emit = ms(t);
    let t = Instant::now();
    let text = SceneFile::new(scene).to_text()?;
    let write = ms(t);
    let t = Instant::now();
    let read = SceneFile::parse(&text)?;
    let read_ms = ms(t);
    let t = Instant::now();
    let mut values = read.scene.compile()?.default_values();
    for i in 0..n {
        values.set(&format!("r{i}"), 0.3 / side as f64)?;
    }
    let set_all = ms(t);
    println!(
        "| parameters | build | compile | OpenCL C | write the file | read it | set every value | peak memory |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|");
    println!(
        "| {n} | {build:.0} ms | {compile:.0} ms | {emit:.0} ms ({} kB) | {write:.0} ms ({} kB) | {read_ms:.0} ms | {set_all:.0} ms | {} |",
        source.source.len() / 1000,
        text.len() / 1000,
        common::peak_memory()
    );
    Ok(())
}
