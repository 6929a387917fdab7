//! Bad settings and bad programs are typed errors with what is needed to
//! fix them.

use crate::gpu;

use fractal_sdf::prelude::*;
use fractal_sdf::render::{DeviceSelector, RenderOptions, Renderer, devices};

#[test]
fn a_build_failure_carries_the_log_and_the_source() {
    let Some(_) = gpu::device() else { return };
    let functions = "real DE(real3 p, __global const real* params) { return undefined_name; }\n";
    let err = Renderer::with_scene_functions(
        gpu::sphere_box_floor().compile().unwrap(),
        &RenderOptions::default(),
        functions,
    )
    .unwrap_err();
    match &err {
        Error::Build {
            device,
            log,
            kernel_source,
        } => {
            assert!(!device.is_empty());
            assert!(log.contains("undefined_name"), "log: {log}");
            assert!(kernel_source.contains(functions), "the source is kept");
            assert!(
                kernel_source.contains("render_tile"),
                "the whole program is kept"
            );
        }
        other => panic!("expected Error::Build, got {other:?}"),
    }
    assert!(err.to_string().contains("undefined_name"));
}

#[test]
fn invalid_settings_are_refused_before_anything_runs() {
    let scene = gpu::sphere_box_floor();
    let bad_quality = RenderOptions::default().quality(Quality::draft().max_steps(0));
    let err = Renderer::with_options(&scene, &bad_quality).unwrap_err();
    assert!(
        matches!(
            err,
            Error::Quality {
                setting: "max_steps",
                ..
            }
        ),
        "{err}"
    );

    let bad_effects = RenderOptions::default().effects(Effects::default().gamma(0.0));
    let err = Renderer::with_options(&scene, &bad_effects).unwrap_err();
    assert!(
        matches!(
            err,
            Error::Effects {
                setting: "gamma",
                ..
            }
        ),
        "{err}"
    );

    let no_tiles = RenderOptions::default().tile_size(0);
    let err = Renderer::with_options(&scene, &no_tiles).unwrap_err();
    assert!(matches!(err, Error::TileSize { value: 0 }), "{err}");
    assert_eq!(err.to_string(), "tile size must be at least 1 pixel, got 0");

    let err = Renderer::new(&Scene::empty(), Quality::draft()).unwrap_err();
    assert!(matches!(err, Error::EmptyScene), "{err}");
}

#[test]
fn an_unmatched_device_selector_lists_the_devices() {
    let Some(device) = gpu::device() else { return };
    let options =
        RenderOptions::default().device(DeviceSelector::device("no such device anywhere"));
    let err = Renderer::with_options(&gpu::sphere_box_floor(), &options).unwrap_err();
    assert!(matches!(err, Error::NoDevice { .. }), "{err}");
    assert!(err.to_string().contains(&device.name), "{err}");
    // Selecting the device by its own names works.
    let options = RenderOptions::default().device({
        let mut selector = DeviceSelector::device(device.name.clone());
        selector.platform = Some(device.platform.to_uppercase());
        selector
    });
    let r = Renderer::with_options(&gpu::sphere_box_floor(), &options).unwrap();
    assert_eq!(r.device(), &device);
    // And by its place in the list, which tells apart devices of one name.
    let all = fractal_sdf::render::devices().unwrap();
    let at = all.iter().position(|d| d == &device).unwrap();
    assert_eq!(DeviceSelector::at(at).resolve().unwrap(), device);
    let err = DeviceSelector::at(all.len()).resolve().unwrap_err();
    assert!(matches!(err, Error::NoDevice { .. }), "{err}");
    assert!(err.to_string().contains("device number"), "{err}");
}

#[test]
fn devices_describe_themselves() {
    let Some(_) = gpu::device() else { return };
    for d in devices().unwrap() {
        assert!(!d.name.is_empty() && !d.platform.is_empty());
        assert!(
            d.opencl_version.starts_with("OpenCL"),
            "{}",
            d.opencl_version
        );
        assert!(d.compute_units >= 1 && d.max_work_group_size >= 1);
        assert!(d.label().contains(" / "));
    }
}
