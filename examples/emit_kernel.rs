//! Prints the OpenCL C generated for an example scene.
//!
//! `cargo run --example emit_kernel -- [sphere|mandelbulb|menger|julia|sierpinski|csg] [f32|f64]`

use fractal_sdf::codegen::{self, Options};
use fractal_sdf::prelude::*;

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "csg".into());
    let precision = match args.next().as_deref() {
        Some("f64") => Precision::F64,
        _ => Precision::F32,
    };
    let geometry = match name.as_str() {
        "sphere" => sphere(1.0),
        "mandelbulb" => mandelbulb(8.0),
        "menger" => menger(4),
        "julia" => julia([-0.2, 0.6, 0.2, 0.2]),
        "sierpinski" => sierpinski(6),
        "csg" => sphere(param("radius", 0.8))
            .smooth_union(
                cuboid(dvec3(0.5, 0.5, 0.5)).translate(dvec3(0.7, 0.0, 0.0)),
                0.2,
            )
            .subtract(cylinder(0.25, 2.0))
            .color(dvec3(1.0, 0.4, 0.1))
            .union(plane(dvec3(0.0, 1.0, 0.0), 1.0)),
        other => {
            eprintln!(
                "unknown scene `{other}`; try sphere, mandelbulb, menger, julia, sierpinski or csg"
            );
            std::process::exit(2);
        }
    };
    let options = Options {
        quality: Quality {
            precision,
            ..Quality::default()
        },
        ..Options::default()
    };
    let kernel = codegen::emit(&Scene::new(geometry), &options)?;
    print!("{}", kernel.source);
    eprintln!(
        "{} lines, hash {:016x}",
        kernel.source.lines().count(),
        kernel.hash
    );
    Ok(())
}
