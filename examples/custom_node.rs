//! A user-defined shape next to built-in ones: a hexagonal prism, its
//! distance written once as a Rust function generic over the number type
//! (the CPU reference runs it; the OpenCL C is printed from it).
//!
//! `cargo run --release --example custom_node` writes `out/custom_node.png`.
//! `tests/kernel/custom_node.rs` proves the same shape a bound and checks that the
//! CPU and the device agree, using only the public API.

mod common;
#[path = "common/hex_prism.rs"]
mod hex_prism;

use fractal_sdf::prelude::*;
use fractal_sdf::scene::Param;
use fractal_sdf::scene::octahedron;

fn main() -> std::process::ExitCode {
    common::run(|| {
        let prism = hex_prism::hex_prism()?
            .node([Param::from(0.45), param("length", 0.3)])
            .rotate(DVec3::X, std::f64::consts::FRAC_PI_2)
            .color(dvec3(0.95, 0.55, 0.2));
        let scene = Scene::new(
            prism
                .smooth_union(sphere(0.3).translate(dvec3(0.0, 0.45, 0.0)), 0.15)
                .union(
                    torus(0.35, 0.1)
                        .translate(dvec3(1.1, -0.2, 0.0))
                        .color(dvec3(0.3, 0.6, 0.95)),
                )
                .union(
                    octahedron(0.4)
                        .translate(dvec3(-1.1, -0.1, 0.0))
                        .color(dvec3(0.4, 0.85, 0.45)),
                )
                .union(plane(DVec3::Y, 0.5).color(dvec3(0.55, 0.55, 0.6))),
        )
        .with_camera(Camera::look_at(dvec3(0.0, 1.4, 3.0), dvec3(0.0, 0.0, 0.0)).fov(45.0));
        let size = common::size_arg((640, 480));
        common::render_to_png("custom_node", &scene, &common::gallery_options(), size)
    })
}
