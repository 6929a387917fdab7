//! Cut planes: a shape cut open shows its own colour and orbit trap on
//! the cut face, and a cut moves without a new program.

use crate::gpu;

use fractal_sdf::prelude::*;
use fractal_sdf::render::Renderer;
use fractal_sdf::scene::param3;
use image::RgbaImage;

const SIDE: u32 = 64;

/// Seen along -x from +x, orthographic, 3 units high: a unit disc at the
/// origin covers a circle of radius 64 / 3 pixels.
fn camera() -> Camera {
    Camera::look_at(dvec3(5.0, 0.0, 0.0), DVec3::ZERO).orthographic(3.0)
}

/// No lights and no effects: a surface is its albedo times the sky's
/// ambient light, so a red surface has no green and a green one no red.
fn render(geometry: Node) -> (Renderer, RgbaImage) {
    let scene = Scene::new(geometry).with_camera(camera()).with_lights([]);
    let options = gpu::options(gpu::plain(gpu::quick()), Effects::none());
    let mut renderer = Renderer::with_options(&scene, &options).unwrap();
    let image = renderer.render(SIDE, SIDE).unwrap();
    (renderer, image)
}

/// Pixels that show a red surface, and pixels that show a green one.
fn red_and_green(image: &RgbaImage) -> (usize, usize) {
    let red = image.pixels().filter(|p| p.0[0] > 0 && p.0[1] == 0).count();
    let green = image.pixels().filter(|p| p.0[0] == 0 && p.0[1] > 0).count();
    (red, green)
}

/// Pixels covered by the face a plane `depth` units from its centre cuts
/// from a unit sphere, the side away from the camera kept. Every surface
/// is drawn `Quality::DETAIL` pixels (δ units) out: the face is the grown
/// sphere's section by the plane moved δ towards the camera, of radius
/// `sqrt((1 + δ)² - (depth - δ)²)`.
fn disc_pixels(depth: f64) -> f64 {
    let unit = 3.0 / f64::from(SIDE);
    let grown = Quality::DETAIL * unit;
    let radius = ((1.0 + grown).powi(2) - (depth - grown).powi(2)).sqrt();
    std::f64::consts::PI * (radius / unit).powi(2)
}

#[test]
fn a_cut_through_a_sphere_shows_a_disc_of_the_right_radius_in_the_spheres_colour() {
    let Some(_) = gpu::device() else { return };
    let ball = || sphere(1.0).color(dvec3(1.0, 0.0, 0.0));
    let cutter = || {
        plane(
            param3("cut_normal", dvec3(1.0, 0.0, 0.0)),
            param("cut", 0.0),
        )
    };
    // The x > 0 half is cut away: from +x the camera sees the flat face,
    // a disc of radius 1, red, as the sphere is.
    let (mut renderer, image) = render(ball().cut(cutter().color(dvec3(0.0, 1.0, 0.0))));
    gpu::save("cut_sphere", &image);
    let (red, green) = red_and_green(&image);
    let expected = disc_pixels(0.0);
    eprintln!("cut face: {red} red pixels, {expected:.0} expected; {green} green");
    assert_eq!(green, 0, "the cutter's colour never shows");
    assert!(
        (red as f64 - expected).abs() < 0.02 * expected,
        "{red} pixels"
    );
    // An intersection shows the cutter's colour on the same face.
    let (_, image) = render(ball().intersect(cutter().color(dvec3(0.0, 1.0, 0.0))));
    let (_, green) = red_and_green(&image);
    assert!(
        (green as f64 - expected).abs() < 0.02 * expected,
        "{green} pixels"
    );
    // The cut moves to x = -0.6 (offset 0.6) without a new program: all
    // that is left lies behind a face of radius 0.8.
    let builds = renderer.builds();
    renderer.set_param("cut", 0.6).unwrap();
    let moved = renderer.render(SIDE, SIDE).unwrap();
    assert_eq!(renderer.builds(), builds);
    let (red, _) = red_and_green(&moved);
    let expected = disc_pixels(0.6);
    assert!(
        (red as f64 - expected).abs() < 0.02 * expected,
        "{red} pixels, {expected:.0}"
    );
}

#[test]
fn a_fractal_cut_open_shows_its_orbit_traps_inside() {
    let Some(_) = gpu::device() else { return };
    // Power-8 Mandelbulb, cut along x = 0 and seen from +x.
    let bulb = mandelbulb(8.0).color(dvec3(1.0, 0.0, 0.0));
    let (mut renderer, _) = render(bulb.cut_plane(dvec3(1.0, 0.0, 0.0), 0.0));
    let frame = renderer.render_with_aovs(SIDE, SIDE).unwrap();
    gpu::save("cut_mandelbulb", &frame.image);
    // The face: hits whose normal is the plane's, +x. Flat and lit by
    // the same sky, it would be one colour with a trap of 1 (a sphere's);
    // the orbit traps tint it over many.
    let rgba = frame.image.as_raw();
    let mut shades: Vec<&[u8]> = (0..frame.hit.len())
        .filter(|&i| frame.hit[i] && frame.normal[i][0] > 0.999)
        .map(|i| &rgba[4 * i..4 * i + 3])
        .collect();
    let face = shades.len();
    shades.sort_unstable();
    shades.dedup();
    eprintln!("{face} pixels of the face, {} shades", shades.len());
    assert!(face as f64 > 0.5 * disc_pixels(0.0), "{face}");
    assert!(shades.len() > 20, "{} shades", shades.len());
}
