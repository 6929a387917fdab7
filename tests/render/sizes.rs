//! Any image size renders, tiling changes nothing, and no pixel is NaN.

use crate::gpu;

use fractal_sdf::prelude::*;
use fractal_sdf::quality::Preset;
use fractal_sdf::render::{Frame, Renderer};

/// No NaN in the frame (see `gpu::assert_no_nan`), and every pixel opaque.
fn assert_no_nan(frame: &Frame, what: &str) {
    gpu::assert_no_nan(frame, what);
    for (x, y, p) in frame.image.enumerate_pixels() {
        assert_eq!(p.0[3], 255, "{what}: alpha at ({x}, {y})");
    }
}

#[test]
fn odd_sizes_render_with_every_pixel_written() {
    let Some(_) = gpu::device() else { return };
    let mut r = Renderer::new(&gpu::sphere_box_floor(), gpu::quick()).unwrap();
    for (w, h) in [(1, 1), (7, 3), (3, 7), (97, 61)] {
        let frame = r.render_with_aovs(w, h).unwrap();
        assert_eq!(frame.image.dimensions(), (w, h));
        assert_eq!(frame.depth.len(), (w * h) as usize);
        assert_no_nan(&frame, &format!("{w}x{h}"));
        let image = r.render(w, h).unwrap();
        assert_eq!(
            image, frame.image,
            "{w}x{h}: render and render_with_aovs differ"
        );
    }
    // A single pixel looks at the middle of the scene.
    let centre = r.render_with_aovs(1, 1).unwrap();
    assert!(centre.hit[0]);
}

#[test]
fn tiled_images_equal_untiled_ones() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let quality = gpu::quick().supersampling(2);
    let frame = |tile_size: u32| {
        let options = gpu::options(quality, Effects::default()).tile_size(tile_size);
        Renderer::with_options(&scene, &options)
            .unwrap()
            .render_with_aovs(97, 61)
            .unwrap()
    };
    let whole = frame(256);
    gpu::save("sizes_97x61_ss2", &whole.image);
    assert_no_nan(&whole, "untiled");
    // 16 divides the local size; 7 and 13 cut work groups and the image
    // edge at odd places.
    for tile in [16, 13, 7] {
        assert_eq!(frame(tile), whole, "tile size {tile}");
    }
    // Jittered supersampling is deterministic.
    assert_eq!(frame(256), whole);
}

#[test]
fn awkward_cameras_and_lights_give_no_nan() {
    let Some(_) = gpu::device() else { return };
    let base = gpu::sphere_box_floor();
    let sphere_centre = dvec3(-0.6, 0.5, 0.0);
    let cases: Vec<(&str, Scene)> = vec![
        (
            "camera at the sphere's centre",
            base.clone()
                .with_camera(Camera::look_at(sphere_centre, dvec3(0.0, 0.5, 1.0))),
        ),
        (
            "camera on the floor",
            base.clone()
                .with_camera(Camera::look_at(dvec3(0.0, 0.0, 3.0), dvec3(0.0, 0.3, 0.0))),
        ),
        (
            "point light on the floor and inside the box",
            base.clone().with_lights([
                Light::point(dvec3(0.0, 0.0, 1.0)),
                Light::point(dvec3(0.6, 0.35, 0.1)).intensity(5.0),
            ]),
        ),
        (
            "grazing light, hard and very soft",
            base.clone().with_lights([
                Light::directional(dvec3(1.0, 0.0, 0.0)).softness(0.0),
                Light::directional(dvec3(0.0, 1e-3, -1.0)).softness(10.0),
            ]),
        ),
        (
            "looking straight down",
            base.clone().with_camera(
                Camera::look_at(dvec3(0.0, 4.0, 0.0), DVec3::ZERO).up(dvec3(0.0, 0.0, -1.0)),
            ),
        ),
    ];
    let effects = Effects::default()
        .fog_density(0.05)
        .glow(Some(fractal_sdf::quality::Glow::new(
            dvec3(0.2, 0.5, 1.0),
            2.0,
        )));
    let mut r = Renderer::with_options(&base, &gpu::options(gpu::quick(), effects)).unwrap();
    for (what, scene) in cases {
        r.set_camera(scene.camera).unwrap();
        r.set_lights(scene.lights.clone()).unwrap();
        let frame = r.render_with_aovs(48, 32).unwrap();
        assert_no_nan(&frame, what);
    }
}

#[test]
fn zero_and_oversized_resolutions_are_errors() {
    let Some(_) = gpu::device() else { return };
    let mut r = Renderer::new(&gpu::sphere_box_floor(), Quality::draft()).unwrap();
    for (w, h) in [(0, 10), (10, 0), (0, 0), (40_000, 1), (1, 40_000)] {
        let err = r.render(w, h).unwrap_err();
        assert!(
            matches!(err, Error::Resolution { width, height, .. } if (width, height) == (w, h)),
            "{w}x{h}: {err}"
        );
        assert!(r.render_with_aovs(w, h).is_err());
    }
    // The renderer still works afterwards.
    assert_eq!(r.render(5, 4).unwrap().dimensions(), (5, 4));
}

#[test]
fn renders_8k() {
    let Some(_) = gpu::device() else { return };
    let scene = Scene::new(sphere(0.5))
        .with_camera(Camera::look_at(dvec3(0.0, 0.0, 4.0), DVec3::ZERO).fov(40.0));
    let mut r =
        Renderer::with_options(&scene, &gpu::options(Quality::draft(), Effects::none())).unwrap();
    let image = r.render(7680, 4320).unwrap();
    assert_eq!(image.dimensions(), (7680, 4320));
    // The sphere's disc, radius tan(asin(r / d)) at unit distance, over the
    // image plane, 2 tan(20°) high.
    let radius = (0.5f64 / 4.0).asin().tan() / (2.0 * 20f64.to_radians().tan());
    let expected = std::f64::consts::PI * radius * radius * 4320.0 / 7680.0;
    // The background is a vertical gradient: a pixel is covered when it
    // differs from the background at the left edge of its row.
    let covered = image
        .enumerate_pixels()
        .filter(|(_, y, p)| {
            let sky = image.get_pixel(0, *y);
            (0..3).any(|c| p[c].abs_diff(sky[c]) > 2)
        })
        .count();
    #[allow(clippy::cast_precision_loss)]
    let coverage = covered as f64 / (7680.0 * 4320.0);
    assert!(
        (coverage / expected - 1.0).abs() < 0.1,
        "covered {coverage}, expected {expected}"
    );
}

/// Regression: a tiny image must still see a shape that fills the view, at
/// every preset (draft traces fewer rays than pixels).
#[test]
fn a_shape_filling_the_view_is_hit_at_the_smallest_sizes() {
    let Some(_) = gpu::device() else { return };
    let scene = Scene::new(sphere(1.0))
        .with_camera(Camera::look_at(dvec3(0.0, 0.0, 1.6), DVec3::ZERO).fov(45.0));
    for preset in Preset::ALL {
        let mut r = Renderer::new(&scene, preset.quality()).unwrap();
        for (w, h) in [(1, 1), (2, 1), (1, 2), (3, 3)] {
            let frame = r.render_with_aovs(w, h).unwrap();
            assert!(
                frame.hit.iter().all(|&h| h),
                "{} at {w}x{h}: {:?}",
                preset.name(),
                frame.hit
            );
        }
    }
}

/// Regression: a side-by-side pair of eyes wider together than the
/// largest image side saturated its width instead of being refused.
#[test]
fn a_stereo_picture_past_the_largest_side_is_refused() {
    let Some(_) = gpu::device() else { return };
    use fractal_sdf::scene::{Stereo, StereoLayout};
    let mut r = Renderer::new(&gpu::sphere_box_floor(), gpu::quick()).unwrap();
    let stereo = Stereo::new(StereoLayout::SideBySide);
    let side = fractal_sdf::render::MAX_IMAGE_SIDE;
    let err = r.render_stereo(side, 8, &stereo).unwrap_err();
    assert!(matches!(err, Error::Resolution { .. }), "{err}");
    assert!(err.to_string().contains("side-by-side"), "{err}");
}
