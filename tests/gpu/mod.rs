//! Shared helpers for the OpenCL render tests: the device check, fixture
//! scenes and pixel measurements.
#![allow(dead_code)] // each test binary uses a different subset

use fractal_sdf::prelude::*;
use fractal_sdf::render::{DeviceInfo, DeviceSelector, Frame, RenderOptions};
use fractal_sdf::scene::LightSource;
use image::RgbaImage;

/// Whether a missing OpenCL device (or fp64 on it) must fail the tests
/// rather than skip them: under `make test` (`FRACTAL_SDF_REQUIRE_DEVICE=1`,
/// which installs PoCL first) and in CI.
pub fn required() -> bool {
    std::env::var("FRACTAL_SDF_REQUIRE_DEVICE").is_ok_and(|v| v == "1")
        || std::env::var("CI").is_ok_and(|v| v == "true" || v == "1")
}

/// Records a skipped check where `make test` prints it after the run
/// (`target/tmp/skipped.txt`), and on stderr.
pub fn skipped(what: &str, why: &str) {
    use std::io::Write as _;
    let note = format!("{}: {what}: {why}", env!("CARGO_CRATE_NAME"));
    eprintln!("note: skipped {note}");
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("skipped.txt");
    if let Ok(mut file) = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
    {
        let _ = writeln!(file, "{note}");
    }
}

/// The device the tests render on, the one a renderer picks by itself; or
/// `None` where no OpenCL platform is installed: the test then returns
/// early and the skip is recorded. Where a device is [`required`], its
/// absence fails the test instead.
pub fn device() -> Option<DeviceInfo> {
    match DeviceSelector::auto().resolve() {
        Ok(device) => Some(device),
        Err(e @ (Error::NoPlatform { .. } | Error::NoDevice { .. })) => {
            assert!(!required(), "OpenCL is required here: {e}");
            skipped("OpenCL render test", &e.to_string());
            None
        }
        Err(other) => panic!("choosing an OpenCL device failed: {other}"),
    }
}

/// Whether `device` runs `F64` kernels. Where a device is [`required`],
/// one without fp64 fails the test (PoCL has it); elsewhere the skip is
/// recorded.
pub fn fp64(device: &DeviceInfo) -> bool {
    if !device.fp64 {
        assert!(
            !required(),
            "fp64 is required here, and {} lacks it",
            device.label()
        );
        skipped("F64 check", &format!("no fp64 on {}", device.label()));
    }
    device.fp64
}

/// Saves an image for inspection when `FRACTAL_SDF_TEST_OUT` names a
/// directory.
pub fn save(name: &str, image: &RgbaImage) {
    if let Ok(dir) = std::env::var("FRACTAL_SDF_TEST_OUT") {
        let path = std::path::Path::new(&dir).join(format!("{name}.png"));
        fractal_sdf::output::save_png(image, path).expect("save test image");
    }
}

/// The floor: the plane y = 0.
pub fn floor() -> Node {
    plane(dvec3(0.0, 1.0, 0.0), 0.0)
}

/// A sphere of dynamic radius `radius` (default 0.5) resting on the floor
/// at x = -0.6, and an orange box at x = 0.6.
pub fn sphere_box_floor() -> Scene {
    let ball = sphere(param("radius", 0.5)).translate(dvec3(-0.6, 0.5, 0.0));
    let block = cuboid(dvec3(0.35, 0.35, 0.35))
        .color(dvec3(0.9, 0.45, 0.1))
        .translate(dvec3(0.6, 0.35, 0.1));
    Scene::new(floor().union(ball).union(block))
        .with_camera(Camera::look_at(dvec3(0.0, 1.4, 3.2), dvec3(0.0, 0.35, 0.0)).fov(40.0))
}

/// A directional light with the given softness from above, right and
/// behind the scene, so shadows fall towards the camera.
pub fn sun(softness: f64) -> Light {
    Light::directional(dvec3(0.5, 1.0, -0.6)).softness(softness)
}

/// Options on the first device with the given quality and effects.
pub fn options(quality: Quality, effects: Effects) -> RenderOptions {
    RenderOptions::default().quality(quality).effects(effects)
}

/// A quick quality: production thresholds, fewer steps, and every ray
/// marched from the camera ([`plain`]).
pub fn quick() -> Quality {
    plain(
        Quality::production()
            .max_steps(192)
            .ao_samples(5)
            .shadow_steps(96),
    )
}

/// Mean luminance (0–255) of the pixels in a square of half side `r`
/// around `(x, y)`.
pub fn luminance(image: &RgbaImage, x: u32, y: u32, r: u32) -> f64 {
    let mut sum = 0.0;
    let mut n = 0.0;
    for j in y.saturating_sub(r)..=(y + r).min(image.height() - 1) {
        for i in x.saturating_sub(r)..=(x + r).min(image.width() - 1) {
            let p = image.get_pixel(i, j).0;
            sum += 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]);
            n += 1.0;
        }
    }
    sum / n
}

/// The pixel whose centre ray passes closest to the world point `p`.
pub fn project(view: &fractal_sdf::render::Viewport, p: DVec3) -> (u32, u32) {
    let (w, h) = view.size();
    let mut best = (0, 0, f64::INFINITY);
    for y in 0..h {
        for x in 0..w {
            let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let to = p - ray.origin;
            let miss = (to - ray.direction * to.dot(ray.direction)).length();
            if miss < best.2 {
                best = (x, y, miss);
            }
        }
    }
    (best.0, best.1)
}

/// Whether a directional light is the only light and points as given.
pub fn direction_of(light: &Light) -> Option<DVec3> {
    match light.source {
        LightSource::Directional { direction } => Some(direction.normalize()),
        _ => None,
    }
}

/// Fails on any sign of a NaN in a frame: a black pixel (a NaN anywhere in
/// a pixel's shading turns it black, and the fixtures always have a lit,
/// non-black background), a non-finite normal, a NaN depth, or a hit flag
/// that disagrees with the depth.
pub fn assert_no_nan(frame: &Frame, what: &str) {
    for (x, y, p) in frame.image.enumerate_pixels() {
        assert!(p.0[..3] != [0, 0, 0], "{what}: black pixel at ({x}, {y})");
    }
    for i in 0..frame.hit.len() {
        let n = frame.normal[i];
        assert!(n.iter().all(|c| c.is_finite()), "{what}: normal {i} {n:?}");
        assert!(!frame.depth[i].is_nan(), "{what}: depth {i}");
        assert_eq!(
            frame.hit[i],
            frame.depth[i].is_finite(),
            "{what}: pixel {i}"
        );
    }
}

/// `quality` without the knobs that change pixels for speed (the coarse
/// pass, the resolution scale, relaxed math): every pixel rendered, every
/// ray marched from the camera, exact math. For tests that compare pixels
/// with the CPU reference or count tiles.
pub fn plain(quality: Quality) -> Quality {
    quality.cone_tile(0).resolution_scale(1).fast_math(false)
}

/// The OpenImageIO command `oiiotool`, an OpenEXR reader independent of
/// the library's writer; or `None` where it is not installed: the caller
/// returns early and the skip is recorded. Where checks are [`required`]
/// (`make test` installs it through `scripts/setup.sh`), its absence fails
/// the test.
pub fn oiiotool() -> Option<&'static str> {
    let found = std::process::Command::new("oiiotool")
        .arg("--version")
        .output()
        .is_ok_and(|out| out.status.success());
    if !found {
        assert!(
            !required(),
            "oiiotool is required here: scripts/setup.sh installs it (Debian's \
             openimageio-tools)"
        );
        skipped("OpenEXR check", "oiiotool is not installed");
        return None;
    }
    Some("oiiotool")
}

/// The channel names and every pixel's values of an OpenEXR file as
/// `oiiotool` reads them (`--info -v` and `--dumpdata`), pixels in row
/// order.
pub fn read_exr(path: &std::path::Path) -> (Vec<String>, Vec<Vec<f32>>) {
    let run = |args: &[&str]| {
        let out = std::process::Command::new("oiiotool")
            .args(args)
            .arg(path)
            .output()
            .expect("oiiotool runs");
        assert!(
            out.status.success(),
            "oiiotool {args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).expect("oiiotool prints text")
    };
    let info = run(&["--info", "-v"]);
    let list = info
        .lines()
        .find_map(|l| l.trim().strip_prefix("channel list:"))
        .unwrap_or_else(|| panic!("no channel list in:\n{info}"));
    let channels: Vec<String> = list.split(',').map(|c| c.trim().to_string()).collect();
    let dump = run(&["--dumpdata"]);
    let pixels: Vec<Vec<f32>> = dump
        .lines()
        .filter_map(|l| l.trim().strip_prefix("Pixel ("))
        .map(|l| {
            let values = l.split_once("):").expect("Pixel (x, y): values").1;
            values
                .split_whitespace()
                .map(|v| v.parse().unwrap_or_else(|_| panic!("value {v}")))
                .collect()
        })
        .collect();
    (channels, pixels)
}

/// The unit direction of the ray through the centre of each pixel of a
/// `width` × `height` image, row by row, from the camera's exported frame
/// (an independent statement of the renderer's projection).
pub fn pixel_rays(camera: &Camera, (width, height): (u32, u32)) -> Vec<DVec3> {
    let e = fractal_sdf::output::CameraExport::new(camera, (width, height)).unwrap();
    let half_h = (e.fov_y_degrees.unwrap().to_radians() / 2.0).tan();
    let half_w = half_h * e.aspect;
    let (forward, right, up) = (
        DVec3::from(e.forward),
        DVec3::from(e.right),
        DVec3::from(e.up),
    );
    let mut out = Vec::new();
    for j in 0..height {
        for i in 0..width {
            let u = ((f64::from(i) + 0.5) / (f64::from(width) / 2.0) - 1.0) * half_w;
            let v = (1.0 - (f64::from(j) + 0.5) / (f64::from(height) / 2.0)) * half_h;
            out.push((forward + right * u + up * v).normalize());
        }
    }
    out
}

/// An inside shape: the ball of radius 1 at the origin, known only by its
/// membership test, in a sphere of radius 1.5.
pub fn inside_ball() -> fractal_sdf::scene::InsideShape {
    use fractal_sdf::scene::{InsideBounds, InsideShape};
    InsideShape::new(
        "ball",
        &[],
        InsideBounds::sphere(DVec3::ZERO, 1.5),
        |p, _| p.length() < 1.0,
        "return length(p) < 1.0f;",
    )
    .unwrap()
}
