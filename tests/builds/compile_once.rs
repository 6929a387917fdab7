//! A scene is validated and lowered once, and its program generated once:
//! the camera, the lights and dynamic parameters never run code generation.
//!
//! One test in its own binary: the counters are process-wide.

use crate::gpu;

use fractal_sdf::codegen;
use fractal_sdf::cpu;
use fractal_sdf::ir;
use fractal_sdf::prelude::*;
use fractal_sdf::render::{RenderOptions, Renderer};

/// `(lowerings, emissions)` so far.
fn counts() -> (u64, u64) {
    (ir::lowerings(), codegen::emissions())
}

#[test]
fn a_renderer_lowers_once_and_frame_inputs_never_generate_code() {
    let Some(_) = gpu::device() else { return };
    let _turn = crate::serial();
    let scene = gpu::sphere_box_floor();

    // Building a renderer from a scene: one lowering, one program.
    let before = counts();
    let mut r = Renderer::new(&scene, Quality::draft()).unwrap();
    assert_eq!(counts(), (before.0 + 1, before.1 + 1));

    // Frames and every frame input: nothing is lowered or generated.
    let before = counts();
    let builds = r.builds();
    r.render(16, 12).unwrap();
    r.set_lights([gpu::sun(0.0), Light::point(dvec3(0.0, 3.0, 1.0))])
        .unwrap();
    r.set_lights([]).unwrap();
    r.set_camera(Camera::look_at(dvec3(1.0, 2.0, 3.0), DVec3::ZERO))
        .unwrap();
    r.set_param("radius", 0.4).unwrap();
    r.render(16, 12).unwrap();
    assert_eq!(
        counts(),
        before,
        "frame inputs ran lowering or code generation"
    );
    assert_eq!(r.builds(), builds);

    // A new quality generates a program but lowers nothing.
    r.set_quality(Quality::preview()).unwrap();
    assert_eq!(counts(), (before.0, before.1 + 1));

    // A compiled scene feeds every stage without lowering again.
    let compiled = scene.compile().unwrap();
    let before = counts();
    let _eval = cpu::Evaluator::from_compiled(&compiled);
    let _r = Renderer::from_compiled(compiled.clone(), &RenderOptions::default()).unwrap();
    let _source = codegen::emit(&compiled, &codegen::Options::default()).unwrap();
    assert_eq!(counts().0, before.0, "a compiled scene was lowered again");
}
