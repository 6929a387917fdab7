//! Frame-to-frame changes (parameters, camera, lights) reuse the program;
//! quality and effects changes build a new one, once.

use crate::gpu;

use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{RenderOptions, Renderer};

#[test]
fn camera_lights_and_parameters_change_the_image_without_a_rebuild() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let mut r = Renderer::new(&scene, gpu::quick()).unwrap();
    let builds = r.builds();
    let source = r.source().clone();
    let (w, h) = (64, 48);
    let first = r.render(w, h).unwrap();
    assert_eq!(r.render(w, h).unwrap(), first, "rendering is deterministic");

    // A dynamic parameter.
    r.set_param("radius", 0.3).unwrap();
    assert_eq!(r.param("radius"), Some(0.3));
    let smaller = r.render_with_aovs(w, h).unwrap();
    assert_ne!(smaller.image, first);
    r.set_param("radius", 0.5).unwrap();
    assert_eq!(r.render(w, h).unwrap(), first, "setting the parameter back");

    // The camera, including a switch to orthographic.
    r.set_camera(Camera::look_at(dvec3(3.0, 2.0, 0.5), dvec3(0.0, 0.3, 0.0)))
        .unwrap();
    let moved = r.render(w, h).unwrap();
    assert_ne!(moved, first);
    r.set_camera(scene.camera.orthographic(3.0)).unwrap();
    assert_ne!(r.render(w, h).unwrap(), first);
    r.set_camera(scene.camera).unwrap();

    // Lights: a different direction, then a different number of lights.
    r.set_lights([gpu::sun(0.0)]).unwrap();
    let one_light = r.render(w, h).unwrap();
    assert_ne!(one_light, first);
    r.set_lights([
        gpu::sun(0.0),
        Light::point(dvec3(0.0, 1.0, 1.0)).intensity(2.0),
    ])
    .unwrap();
    assert_ne!(r.render(w, h).unwrap(), one_light);
    r.set_lights([]).unwrap();
    let ambient = r.render(w, h).unwrap();
    assert!(gpu::luminance(&ambient, 32, 40, 2) < gpu::luminance(&one_light, 32, 40, 2));
    r.set_lights(scene.lights.clone()).unwrap();
    assert_eq!(r.render(w, h).unwrap(), first, "restoring the lights");

    assert_eq!(r.builds(), builds, "no frame-to-frame change rebuilds");
    assert_eq!(r.source(), &source);
}

#[test]
fn bad_frame_inputs_are_rejected_and_leave_the_renderer_usable() {
    let Some(_) = gpu::device() else { return };
    let mut r = Renderer::new(&gpu::sphere_box_floor(), Quality::draft()).unwrap();
    let before = r.render(16, 12).unwrap();
    assert!(matches!(
        r.set_param("nope", 1.0),
        Err(Error::UnknownParam { .. })
    ));
    assert!(matches!(
        r.set_param("radius", -1.0),
        Err(Error::OutOfRange { .. })
    ));
    assert!(matches!(
        r.set_param("radius", f64::NAN),
        Err(Error::NonFinite { .. })
    ));
    let camera = Camera::look_at(DVec3::ZERO, DVec3::ZERO);
    assert!(matches!(r.set_camera(camera), Err(Error::Camera { .. })));
    let bad_light = Light::directional(DVec3::ZERO);
    assert!(matches!(
        r.set_lights([bad_light]),
        Err(Error::ZeroVector { .. })
    ));
    assert_eq!(r.render(16, 12).unwrap(), before);
}

#[test]
fn quality_and_effects_changes_rebuild_once_then_hit_the_cache() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    // A quality no other test uses, so this test's first build is its own.
    let quality = gpu::quick().max_steps(177);
    let mut r = Renderer::new(&scene, quality).unwrap();
    assert_eq!(r.builds(), 1);
    assert!(!r.build_info().cached);
    let first = r.build_info().clone();
    assert!(r.build_info().device.contains(&r.device().name));
    let plain = r.render(32, 24).unwrap();

    r.set_effects(Effects::none()).unwrap();
    assert_eq!(r.builds(), 2);
    assert!(!r.source().source.contains("#define ENABLE_AO"));
    let flat = r.render(32, 24).unwrap();
    assert_ne!(flat, plain);

    // Back to the first settings: the cached program, no compiler run.
    r.set_effects(Effects::default()).unwrap();
    assert_eq!(r.builds(), 2);
    assert!(r.build_info().cached);
    assert_eq!(r.render(32, 24).unwrap(), plain);
    // A second renderer of the same scene and settings shares it too.
    let twin = Renderer::new(&scene, quality).unwrap();
    assert_eq!(twin.builds(), 0);
    assert!(twin.build_info().cached);
    // ...and reports the build it was compiled in.
    assert_eq!(twin.build_info().build_time, first.build_time);
    assert_eq!(twin.build_info().source_hash, first.source_hash);

    // Quality is compiled in.
    r.set_quality(quality.supersampling(2)).unwrap();
    assert_eq!(r.builds(), 3);
    assert!(r.source().source.contains("#define SUPERSAMPLING 2"));
}

#[test]
fn f64_renders_where_the_device_supports_it() {
    let Some(device) = gpu::device() else { return };
    let quality = gpu::quick().precision(Precision::F64);
    let result = Renderer::new(&gpu::sphere_box_floor(), quality);
    if !gpu::fp64(&device) {
        assert!(matches!(result, Err(Error::Fp64Unsupported { .. })));
        return;
    }
    let mut r = result.unwrap();
    assert!(r.source().source.contains("typedef double real;"));
    let wide = r.render_with_aovs(48, 32).unwrap();
    let mut narrow = Renderer::new(&gpu::sphere_box_floor(), gpu::quick()).unwrap();
    let f32_frame = narrow.render_with_aovs(48, 32).unwrap();
    let same = (0..wide.hit.len())
        .filter(|&i| wide.hit[i] == f32_frame.hit[i])
        .count();
    assert!(
        same * 100 >= wide.hit.len() * 99,
        "F64 and F32 hit masks differ"
    );
    // Precision can change on the fly.
    r.set_quality(gpu::quick()).unwrap();
    assert_eq!(r.render(48, 32).unwrap(), f32_frame.image);
}

#[test]
fn hand_written_functions_survive_lights_quality_and_effects() {
    let Some(_) = gpu::device() else { return };
    let functions = include_str!("../../benches/mandelbulb_handwritten.cl");
    let scene = fractal_sdf::gallery::mandelbulb().compile().unwrap();
    let mut r =
        Renderer::with_scene_functions(scene, &RenderOptions::default(), functions).unwrap();
    let hand_written = |r: &Renderer| r.source().source.contains(functions);
    assert!(hand_written(&r));
    r.set_lights([gpu::sun(0.1)]).unwrap();
    assert!(
        hand_written(&r),
        "set_lights swapped in a generated program"
    );
    r.set_quality(Quality::draft()).unwrap();
    assert!(
        hand_written(&r),
        "set_quality swapped in a generated program"
    );
    r.set_effects(Effects::default().ambient_occlusion(false))
        .unwrap();
    assert!(
        hand_written(&r),
        "set_effects swapped in a generated program"
    );
    assert!(!r.source().source.contains("#define ENABLE_AO"));
}
