//! Frames split across devices: the same device listed twice renders the
//! pixels one device renders, before and after the scene's values change.

use crate::gpu;

use fractal_sdf::prelude::*;
use fractal_sdf::render::{DeviceSelector, RenderOptions, Renderer};

#[test]
fn two_shares_of_one_device_render_the_image_of_one() {
    let Some(device) = gpu::device() else {
        return;
    };
    let scene = fractal_sdf::gallery::benchmark();
    // Small tiles, so that each share has many, in both directions.
    let options = RenderOptions::default()
        .quality(Quality::draft())
        .tile_size(16);
    let twice = [DeviceSelector::exactly(&device), DeviceSelector::auto()];
    let mut one = Renderer::with_options(&scene, &options).unwrap();
    let mut two = Renderer::with_devices(&scene, &options, &twice).unwrap();
    assert_eq!(two.devices().len(), 2);
    // Sizes that are and are not multiples of the tile.
    for (w, h) in [(64, 48), (75, 41)] {
        let (a, b) = (one.render(w, h).unwrap(), two.render(w, h).unwrap());
        assert!(a.pixels().any(|p| p != a.get_pixel(0, 0)), "blank");
        assert_eq!(a.as_raw(), b.as_raw(), "{w}x{h}");
    }
    // Every change reaches both shares.
    let moved = Camera::look_at(dvec3(1.0, 1.8, 3.0), dvec3(0.0, -0.2, 0.0));
    for r in [&mut one, &mut two] {
        r.set_param("orbit.y", 0.9).unwrap();
        r.set_camera(moved).unwrap();
        r.set_lights([Light::point(dvec3(0.0, 3.0, 2.0))]).unwrap();
        r.set_effects(Effects::none()).unwrap();
    }
    let (a, b) = (one.render(64, 48).unwrap(), two.render(64, 48).unwrap());
    assert_eq!(a.as_raw(), b.as_raw(), "after changes");
    // An error in one share is the frame's error.
    assert!(two.set_param("orbit.y", f64::NAN).is_err());
    assert!(Renderer::with_devices(&scene, &options, &[]).is_err());
}
