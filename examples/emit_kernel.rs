//! Prints the OpenCL C generated for a gallery scene.
//!
//! `cargo run --example emit_kernel -- [SCENE] [f32|f64]`, where SCENE is one
//! of the gallery's names (default `csg`).

use fractal_sdf::codegen::{self, Options};
use fractal_sdf::gallery;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "csg".into());
    let precision = match args.next().as_deref() {
        Some("f64") => Precision::F64,
        _ => Precision::F32,
    };
    let Some(scene) = gallery::by_name(&name) else {
        eprintln!(
            "unknown scene `{name}`; choose one of: {}",
            gallery::names().join(", ")
        );
        std::process::exit(2);
    };
    let options = Options::default().quality(Quality::default().precision(precision));
    let scene = scene.compile()?;
    let kernel = codegen::emit(&scene, &options)?;
    print!("{}", kernel.source);
    eprintln!(
        "{name}: {} lines, {} dynamic parameters, hash {:016x}",
        kernel.source.lines().count(),
        scene.params().slots().len(),
        kernel.hash
    );
    Ok(())
}
