//! A frame's outputs for compositing: the linear colour and the shading
//! layers, the display transform written once for the kernel and the host,
//! OpenEXR files read back by an independent reader, and the exported
//! camera.

use crate::gpu;

use fractal_sdf::cpu::Evaluator;
use fractal_sdf::output::{Aov, Bits, CameraExport, FrameOutput, save_frame};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::{Encoding, Precision, ToneMap, display};
use fractal_sdf::render::{Frame, Renderer, Viewport};
use glam::dvec2;

const W: u32 = 96;
const H: u32 = 64;

fn layered(scene: &Scene, quality: Quality, effects: Effects) -> Frame {
    let mut r = Renderer::with_options(scene, &gpu::options(quality, effects)).unwrap();
    r.render_layers(W, H).unwrap()
}

/// The box-and-sphere scene under one bright sun: lit faces go past 1.
fn bright_scene() -> Scene {
    gpu::sphere_box_floor().with_lights([gpu::sun(0.0).intensity(3.0)])
}

/// The largest difference, in 8-bit steps, between the kernel's image and
/// the host's display transform of the linear colour.
fn display_gap(frame: &Frame, effects: &Effects) -> u8 {
    let layers = frame.layers.as_ref().unwrap();
    // The linear colour holds the exposure already.
    let effects = effects.exposure(0.0);
    let mut worst = 0;
    for (i, pixel) in frame.image.pixels().enumerate() {
        let [r, g, b, _] = layers.linear[i];
        let shown = display([r, g, b], &effects);
        for (c, v) in shown.into_iter().enumerate() {
            let want = (v * 255.0).round() as i32;
            worst = worst.max((want - i32::from(pixel.0[c])).unsigned_abs() as u8);
        }
    }
    worst
}

/// The display transform is written once: the kernel's 8-bit image is the
/// host's transform of the linear colour, for every tone curve, exposure
/// and gamma, and the linear colour is not clipped.
#[test]
fn the_image_is_the_linear_colour_through_one_display_transform() {
    let Some(_) = gpu::device() else { return };
    let scene = bright_scene();
    let quality = gpu::quick().supersampling(1);
    let cases = [
        Effects::default(),
        Effects::default().exposure(1.0).tone_map(ToneMap::Reinhard),
        Effects::default()
            .exposure(-0.5)
            .tone_map(ToneMap::Filmic)
            .gamma(1.8),
        Effects::none().gamma(1.0).exposure(2.0),
        Effects::default()
            .tone_map(ToneMap::Filmic)
            .encoding(Encoding::Srgb),
    ];
    let mut plain_bright = 0.0;
    for effects in cases {
        let frame = layered(&scene, quality, effects);
        let gap = display_gap(&frame, &effects);
        assert!(
            gap <= 1,
            "{effects:?}: 8-bit image {gap} steps from the host's transform"
        );
        let layers = frame.layers.as_ref().unwrap();
        let over = layers
            .linear
            .iter()
            .filter(|c| c[..3].iter().any(|&v| v > 1.0))
            .count();
        if effects == Effects::default() {
            plain_bright = over as f64 / layers.linear.len() as f64;
        }
    }
    // The sun at 3 lights the box's faces past 1: the linear colour keeps
    // them, where the 8-bit image clips.
    assert!(plain_bright > 0.02, "{plain_bright} of the pixels above 1");
}

/// Exposure scales the linear colour by 2^stops, and the tone curves map
/// it as their formulas say.
#[test]
fn exposure_scales_the_linear_colour() {
    let Some(_) = gpu::device() else { return };
    let scene = bright_scene();
    let quality = gpu::quick().supersampling(1);
    let base = layered(&scene, quality, Effects::default());
    let brighter = layered(&scene, quality, Effects::default().exposure(1.5));
    let (a, b) = (base.layers.unwrap(), brighter.layers.unwrap());
    let scale = 1.5f32.exp2();
    for (x, y) in a.linear.iter().zip(&b.linear) {
        for c in 0..3 {
            assert!(
                (y[c] - scale * x[c]).abs() <= 1e-5 * (1.0 + y[c].abs()),
                "{x:?} exposed {y:?}"
            );
        }
        assert_eq!(x[3], y[3], "coverage does not change");
    }
}

/// What each layer says about a hit, against the camera and the CPU
/// reference: the position lies on the ray at the depth and on the
/// surface; the albedo is the node's colour; with the effects off,
/// occlusion and shadow are 1; the coverage of a single-sample pixel is
/// its hit.
#[test]
fn the_layers_describe_the_hit() {
    let Some(_) = gpu::device() else { return };
    let scene = bright_scene();
    let frame = layered(&scene, gpu::quick().supersampling(1), Effects::none());
    let layers = frame.layers.as_ref().unwrap();
    let view = Viewport::new(&scene.camera, W, H, Precision::F32).unwrap();
    let cpu = Evaluator::new(scene.geometry.as_ref().unwrap()).unwrap();
    let mut boxed = 0;
    for y in 0..H {
        for x in 0..W {
            let i = frame.index(x, y);
            let coverage = layers.linear[i][3];
            if !frame.hit[i] {
                assert_eq!(coverage, 0.0);
                assert_eq!(layers.position[i], [0.0; 3]);
                assert_eq!(layers.albedo[i], [0.0; 3]);
                continue;
            }
            assert_eq!(coverage, 1.0);
            let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let on_ray = ray.origin + ray.direction * f64::from(frame.depth[i]);
            let p = DVec3::from(layers.position[i].map(f64::from));
            assert!((p - on_ray).length() < 1e-4, "({x}, {y}): {p} vs {on_ray}");
            // Within the hit threshold: a few pixel footprints (the image
            // is 2 tan(20°) units high a unit away).
            let d = cpu.distance(p);
            let footprint =
                2.0 * 20f64.to_radians().tan() / f64::from(H) * f64::from(frame.depth[i]);
            assert!(
                d.abs() < 1e-4 + 2.0 * footprint,
                "({x}, {y}): the surface is {d} away"
            );
            assert_eq!(layers.occlusion[i], 1.0);
            assert_eq!(layers.shadow[i], 1.0);
            assert_eq!(layers.trap[i], 1.0, "no trap colours the scene");
            // The colour is the nearest shape's: the box's (0.9, 0.45,
            // 0.1), or the default elsewhere. Hits near an edge between
            // two shapes may take either.
            let q = (p - dvec3(0.6, 0.35, 0.1)).abs() - DVec3::splat(0.35);
            let to_box = q.max(DVec3::ZERO).length() + q.max_element().min(0.0);
            let to_other = ((p - dvec3(-0.6, 0.5, 0.0)).length() - 0.5).min(p.y);
            if (to_box - to_other).abs() < 2.0 * footprint {
                continue;
            }
            let want = if to_box < to_other {
                boxed += 1;
                [0.9, 0.45, 0.1]
            } else {
                [0.8, 0.8, 0.8]
            };
            for (got, want) in layers.albedo[i].into_iter().zip(want) {
                assert!(
                    (f64::from(got) - want).abs() < 1e-5,
                    "({x}, {y}) at {p}: albedo {:?}",
                    layers.albedo[i]
                );
            }
        }
    }
    assert!(boxed > 100, "{boxed} box pixels");
}

/// The shadow layer against shadow rays marched on the CPU, hard shadows:
/// a floor point is in shadow where the exact distance along its ray to
/// the sun falls to zero.
#[test]
fn the_shadow_layer_matches_shadow_rays_on_the_cpu() {
    let Some(_) = gpu::device() else { return };
    let scene = bright_scene();
    let sun = gpu::direction_of(&scene.lights[0]).unwrap();
    let effects = Effects::none().shadows(true);
    let frame = layered(&scene, gpu::quick().supersampling(1), effects);
    let layers = frame.layers.as_ref().unwrap();
    let cpu = Evaluator::new(scene.geometry.as_ref().unwrap()).unwrap();
    let blocked = |p: DVec3| {
        let mut t = 0.02;
        while t < 20.0 {
            let d = cpu.distance(p + sun * t);
            if d < 1e-4 {
                return true;
            }
            t += d.max(1e-4);
        }
        false
    };
    let (mut floor, mut agree, mut shadowed) = (0, 0, 0);
    for i in 0..frame.hit.len() {
        if !frame.hit[i] || frame.normal[i][1] < 0.999 {
            continue;
        }
        let p = DVec3::from(layers.position[i].map(f64::from));
        let dark = blocked(p);
        let layer = layers.shadow[i];
        assert!((0.0..=1.0).contains(&layer));
        floor += 1;
        shadowed += usize::from(dark);
        agree += usize::from(dark == (layer < 0.5));
    }
    assert!(
        shadowed > 50,
        "{shadowed} of {floor} floor pixels in shadow"
    );
    // Pixels on a shadow's edge may go either way.
    assert!(
        agree as f64 >= 0.98 * floor as f64,
        "{agree} of {floor} floor pixels agree"
    );
}

/// Ambient occlusion in its layer: 1 on open floor, darker where the
/// sphere meets the floor; the orbit-trap values that tint a fractal vary
/// across it.
#[test]
fn occlusion_and_trap_layers_hold_their_values() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor().with_lights([]);
    let effects = Effects::none().ambient_occlusion(true).ao_distance(0.5);
    let frame = layered(&scene, gpu::quick().supersampling(1), effects);
    let layers = frame.layers.as_ref().unwrap();
    let at = |i: usize| DVec3::from(layers.position[i].map(f64::from));
    // Hits lie within a few footprints of the surface they stopped at.
    let floor = |i: usize| frame.hit[i] && at(i).y < 0.04 && frame.normal[i][1] > 0.9;
    let open: Vec<f32> = (0..frame.hit.len())
        .filter(|&i| floor(i) && at(i).z > 1.0)
        .map(|i| layers.occlusion[i])
        .collect();
    let crease: Vec<f32> = (0..frame.hit.len())
        .filter(|&i| floor(i) && dvec2(at(i).x + 0.6, at(i).z).length() < 0.35)
        .map(|i| layers.occlusion[i])
        .collect();
    assert!(
        open.len() > 50 && crease.len() > 5,
        "{} open and {} crease pixels",
        open.len(),
        crease.len()
    );
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
    assert!(mean(&open) > 0.97, "open floor occlusion {}", mean(&open));
    assert!(mean(&crease) < 0.8, "crease occlusion {}", mean(&crease));

    let trapped =
        Scene::new(mandelbulb(8.0)).with_camera(Camera::look_at(dvec3(0.0, 0.0, 2.6), DVec3::ZERO));
    let frame = layered(&trapped, gpu::quick().supersampling(1), Effects::none());
    let layers = frame.layers.as_ref().unwrap();
    let traps: Vec<f32> = (0..frame.hit.len())
        .filter(|&i| frame.hit[i])
        .map(|i| layers.trap[i])
        .collect();
    assert!(traps.iter().all(|t| (0.0..=1.0).contains(t)));
    let spread = traps.iter().copied().fold(f32::NEG_INFINITY, f32::max)
        - traps.iter().copied().fold(f32::INFINITY, f32::min);
    assert!(spread > 0.2, "trap values spread over {spread}");
}

/// Progressive passes average the linear colour and the coverage: after
/// eight passes of one sample, coverage is a count of eighths, fractional
/// along edges, and the image is still the transform of the mean.
#[test]
fn progressive_layers_average_colour_and_coverage() {
    let Some(_) = gpu::device() else { return };
    let scene = bright_scene();
    let quality = gpu::quick().supersampling(1);
    let mut r = Renderer::with_options(&scene, &gpu::options(quality, Effects::default())).unwrap();
    let mut frame = r.render_progressive_layers(W, H).unwrap();
    for _ in 1..8 {
        frame = r.render_progressive_layers(W, H).unwrap();
    }
    assert_eq!(r.progressive_passes(), 8);
    assert!(display_gap(&frame, &Effects::default()) <= 1);
    let layers = frame.layers.as_ref().unwrap();
    let mut edges = 0;
    for c in layers.linear.iter().map(|c| c[3]) {
        let eighths = c * 8.0;
        assert!((eighths - eighths.round()).abs() < 1e-5, "coverage {c}");
        edges += usize::from(c > 0.0 && c < 1.0);
    }
    assert!(edges > 20, "{edges} pixels partly covered");
}

/// An OpenEXR file holds the linear colour and every output as named
/// channels, which an independent reader (`oiiotool`) lists and reads back
/// with the values the frame has.
#[test]
fn openexr_layers_read_back_through_oiiotool() {
    let Some(_) = gpu::device() else { return };
    let Some(_) = gpu::oiiotool() else { return };
    let scene = gpu::sphere_box_floor().with_lights([gpu::sun(0.2).intensity(2.0)]);
    let quality = gpu::quick().supersampling(2);
    let mut r = Renderer::with_options(&scene, &gpu::options(quality, Effects::default())).unwrap();
    let (w, h) = (24, 16);
    let mut frame = r.render_layers(w, h).unwrap();
    r.identify(&mut frame).unwrap();
    let dir = std::env::temp_dir().join(format!("fractal-sdf-exr-{}", std::process::id()));
    let path = dir.join("frame.exr");
    let output = FrameOutput::new(Effects::default()).aovs(Aov::ALL);
    let written = save_frame(&frame, &path, &output).unwrap();
    assert_eq!(written, std::slice::from_ref(&path));

    let (channels, pixels) = gpu::read_exr(&path);
    let mut want: Vec<String> = ["R", "G", "B", "A"].map(String::from).to_vec();
    for aov in Aov::ALL {
        for c in aov.channels() {
            want.push(format!("{}.{c}", aov.name()));
        }
    }
    let mut sorted = channels.clone();
    sorted.sort();
    want.sort();
    assert_eq!(sorted, want, "the channels oiiotool lists");
    assert_eq!(pixels.len(), (w * h) as usize);

    let layers = frame.layers.as_ref().unwrap();
    let value = |name: &str, i: usize| -> f32 {
        let (layer, c) = name.split_once('.').unwrap_or(("", name));
        let xyz = |v: [f32; 3]| v["XYZRGB".find(c).unwrap() % 3];
        match layer {
            "" if c == "A" => 1.0,
            "" => layers.linear[i]["RGB".find(c).unwrap()],
            "coverage" => layers.linear[i][3],
            "depth" => frame.depth[i],
            "normal" => xyz(frame.normal[i]),
            "position" => xyz(layers.position[i]),
            "albedo" => xyz(layers.albedo[i]),
            "ao" => layers.occlusion[i],
            "shadow" => layers.shadow[i],
            "trap" => layers.trap[i],
            "evaluations" => frame.evaluations[i] as f32,
            "object" => layers.object[i] as f32,
            "material" => layers.material[i] as f32,
            other => panic!("unexpected layer {other}"),
        }
    };
    let mut misses = 0;
    for (i, read) in pixels.iter().enumerate() {
        assert_eq!(read.len(), channels.len());
        for (name, &got) in channels.iter().zip(read) {
            let want = value(name, i);
            if want.is_infinite() {
                misses += 1;
                assert_eq!(got, want, "{name} at pixel {i}");
            } else {
                assert!(
                    (got - want).abs() <= 1e-6 * want.abs().max(1.0),
                    "{name} at pixel {i}: read {got}, wrote {want}"
                );
            }
        }
    }
    assert!(misses > 0, "the sky's depth reads back as infinity");
    std::fs::remove_dir_all(dir).ok();
}

/// 16-bit PNGs and TIFFs hold the same picture as the 8-bit image, finer;
/// each output is a 16-bit PNG beside the image; a JPEG refuses 16 bits.
#[test]
fn sixteen_bit_images_and_output_pngs() {
    let Some(_) = gpu::device() else { return };
    let scene = bright_scene();
    let mut r =
        Renderer::with_options(&scene, &gpu::options(gpu::quick(), Effects::default())).unwrap();
    let frame = r.render_layers(W, H).unwrap();
    let dir = std::env::temp_dir().join(format!("fractal-sdf-16-{}", std::process::id()));
    let sixteen = FrameOutput::new(Effects::default()).bits(Bits::Sixteen);
    for name in ["deep.png", "deep.tif"] {
        let path = dir.join(name);
        save_frame(&frame, &path, &sixteen).unwrap();
        let read = image::open(&path).unwrap().to_rgba16();
        let mut fine = 0;
        for (a, b) in read.pixels().zip(frame.image.pixels()) {
            for c in 0..3 {
                let eight = f64::from(a.0[c]) / 257.0;
                assert!((eight - f64::from(b.0[c])).abs() <= 1.0, "{name}");
                fine += usize::from(a.0[c] % 257 != 0);
            }
        }
        assert!(fine > 1000, "{name}: {fine} channels between 8-bit steps");
    }
    for (name, says) in [("deep.jpg", "8 bits"), ("deep.exr", "32-bit floats")] {
        let err = save_frame(&frame, dir.join(name), &sixteen).unwrap_err();
        assert!(err.to_string().contains(says), "{err}");
        assert!(!dir.join(name).exists());
    }

    let png = dir.join("plain.png");
    let with = FrameOutput::new(Effects::default()).aovs([Aov::Depth, Aov::Normal, Aov::Albedo]);
    let written = save_frame(&frame, &png, &with).unwrap();
    assert_eq!(written.len(), 4);
    let depth = image::open(dir.join("plain.depth.png")).unwrap();
    assert!(matches!(depth, image::DynamicImage::ImageLuma16(_)));
    let depth = depth.to_luma16();
    for (i, p) in depth.pixels().enumerate() {
        assert_eq!(p.0[0] == 0, !frame.hit[i], "a miss is black, a hit is not");
    }
    let normal = image::open(dir.join("plain.normal.png")).unwrap();
    assert!(matches!(normal, image::DynamicImage::ImageRgb16(_)));
    std::fs::remove_dir_all(dir).ok();
}

/// Reprojects `p` through the exported camera's JSON, read as a 3D
/// package would: position and axes, field of view or height, image size
/// and shift. Pixels from the top-left corner.
fn reproject(json: &serde_json::Value, p: DVec3) -> [f64; 2] {
    let v3 = |key: &str| {
        let a = json[key].as_array().unwrap();
        DVec3::new(
            a[0].as_f64().unwrap(),
            a[1].as_f64().unwrap(),
            a[2].as_f64().unwrap(),
        )
    };
    let num = |key: &str| json[key].as_f64().unwrap();
    let d = p - v3("position");
    let (x, y, z) = (d.dot(v3("right")), d.dot(v3("up")), d.dot(v3("forward")));
    // The image plane's half height at unit distance (or the view's).
    let (u, v, half) = if json["projection"] == "perspective" {
        (
            x / z,
            y / z,
            (num("fov_y_degrees").to_radians() / 2.0).tan(),
        )
    } else {
        (x, y, num("ortho_height") / 2.0)
    };
    let shift = &json["shift"];
    let (sx, sy) = (shift[0].as_f64().unwrap(), shift[1].as_f64().unwrap());
    // Normalised image coordinates: -1 to 1 across the height.
    let ny = v / half - sy;
    let nx = u / half - sx;
    let (w, h) = (num("width"), num("height"));
    [w / 2.0 + nx * h / 2.0, h / 2.0 * (1.0 - ny)]
}

/// The exported camera reprojects every point the renderer drew (the
/// position layer) to the pixel it was drawn at, for a perspective, a
/// shifted and an orthographic camera; its quaternion turns −Z into the
/// view and +Y into up.
#[test]
fn the_exported_camera_reprojects_drawn_points_to_their_pixels() {
    let Some(_) = gpu::device() else { return };
    let base = gpu::sphere_box_floor();
    let cameras = [
        base.camera,
        base.camera.shifted(dvec2(0.3, -0.2)).fov(55.0),
        Camera::look_at(dvec3(1.5, 2.0, 3.0), dvec3(0.0, 0.3, 0.0)).orthographic(2.5),
    ];
    for camera in cameras {
        let scene = base.clone().with_camera(camera);
        let frame = layered(&scene, gpu::quick().supersampling(1), Effects::none());
        let layers = frame.layers.as_ref().unwrap();
        let exported = CameraExport::new(&camera, (W, H)).unwrap();
        let json: serde_json::Value = serde_json::from_str(&exported.to_json()).unwrap();
        let mut worst: f64 = 0.0;
        let mut drawn = 0;
        for y in 0..H {
            for x in 0..W {
                let i = frame.index(x, y);
                if !frame.hit[i] {
                    continue;
                }
                let p = DVec3::from(layers.position[i].map(f64::from));
                let [px, py] = reproject(&json, p);
                let (cx, cy) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
                worst = worst.max((px - cx).abs()).max((py - cy).abs());
                let [lx, ly] = exported.project(p).unwrap();
                assert!((lx - px).abs() < 1e-9 && (ly - py).abs() < 1e-9);
                drawn += 1;
            }
        }
        assert!(drawn > 1000, "{drawn} pixels drawn");
        assert!(
            worst < 0.5,
            "{camera:?}: a drawn point reprojects {worst} px away"
        );

        let q = &json["rotation"];
        let q = DQuat::from_xyzw(
            q[1].as_f64().unwrap(),
            q[2].as_f64().unwrap(),
            q[3].as_f64().unwrap(),
            q[0].as_f64().unwrap(),
        );
        let (right, up, forward) = camera.basis().unwrap();
        assert!((q * DVec3::NEG_Z - forward).length() < 1e-9);
        assert!((q * DVec3::Y - up).length() < 1e-9);
        assert!((q * DVec3::X - right).length() < 1e-9);
    }
}

/// A scene whose outermost node is a translation renders in a frame about
/// that point; positions come back in the scene's frame, and misses keep
/// 0. At a resolution scale of 2 the layers fill the whole image, each
/// from the nearest rendered pixel.
#[test]
fn positions_are_in_the_scene_frame_at_any_resolution_scale() {
    let Some(_) = gpu::device() else { return };
    let centre = dvec3(40.0, 3.0, -25.0);
    let scene = Scene::new(sphere(0.5).translate(centre))
        .with_camera(Camera::look_at(centre + dvec3(0.0, 0.4, 2.5), centre));
    for scale in [1, 2] {
        let quality = gpu::quick().supersampling(1).resolution_scale(scale);
        let frame = layered(&scene, quality, Effects::none());
        let layers = frame.layers.as_ref().unwrap();
        assert_eq!(layers.position.len(), (W * H) as usize);
        let (mut hits, mut worst) = (0, 0.0f64);
        for i in 0..frame.hit.len() {
            let p = DVec3::from(layers.position[i].map(f64::from));
            if frame.hit[i] {
                hits += 1;
                worst = worst.max(((p - centre).length() - 0.5).abs());
            } else {
                assert_eq!(layers.position[i], [0.0; 3], "scale {scale}: a miss");
            }
        }
        assert!(hits > 500, "scale {scale}: {hits} hits");
        assert!(
            worst < 0.02,
            "scale {scale}: a position {worst} off the sphere"
        );
    }
}

/// Passes with every output run on the renderer's own device and do not
/// continue passes of the image alone, nor the other way round.
#[test]
fn layer_passes_and_image_passes_start_each_other_again() {
    let Some(_) = gpu::device() else { return };
    let scene = bright_scene();
    let quality = gpu::quick().supersampling(1);
    let mut r = Renderer::with_options(&scene, &gpu::options(quality, Effects::default())).unwrap();
    for _ in 0..3 {
        r.render_progressive_layers(W, H).unwrap();
    }
    assert_eq!(r.progressive_passes(), 3);
    r.render_progressive(W, H).unwrap();
    assert_eq!(r.progressive_passes(), 1);
    r.render_progressive(W, H).unwrap();
    r.render_progressive_layers(W, H).unwrap();
    assert_eq!(r.progressive_passes(), 1);
}

/// Object and material ids against the shapes' own distances: each hit
/// belongs to the shape whose exact distance at its position is least
/// (worked out here from the centres and sizes), numbered in the order
/// the scene writes them, and has the material of the material node
/// outermost above that shape.
#[test]
fn object_and_material_ids_name_the_shape_at_each_hit() {
    let Some(_) = gpu::device() else { return };
    let centres = [
        dvec3(-1.2, 0.0, 0.0),
        dvec3(0.0, 0.2, -0.4),
        dvec3(1.2, 0.0, 0.0),
    ];
    let radii = [0.5, 0.6, 0.45];
    let ball = |i: usize| sphere(radii[i]).translate(centres[i]);
    // Written order: ball 0, ball 1 (smoothly joined to ball 0), ball 2,
    // the floor. Materials: ball 1 a mirror; ball 2 inside two material
    // nodes, the outer one (written first) painting over the inner.
    let glossy = Material::blinn_phong(0.8, 64.0);
    let scene = Scene::new(
        ball(0)
            .smooth_union(ball(1).material(Material::mirror()), 0.2)
            .union(ball(2).material(Material::glass(1.5)).material(glossy))
            .union(plane(DVec3::Y, 0.5)),
    )
    .with_camera(Camera::look_at(dvec3(0.0, 1.2, 4.0), dvec3(0.0, 0.0, 0.0)));
    let options = gpu::options(gpu::plain(Quality::preview()), Effects::default());
    let mut renderer = Renderer::with_options(&scene, &options).unwrap();
    let mut frame = renderer.render_layers(W, H).unwrap();
    let written = FrameOutput::new(Effects::default()).aovs([Aov::Object]);
    let path = std::env::temp_dir().join(format!("fractal-sdf-ids-{}.exr", std::process::id()));
    let err = save_frame(&frame, &path, &written).unwrap_err().to_string();
    assert!(err.contains("Renderer::identify"), "{err}");
    renderer.identify(&mut frame).unwrap();
    let layers = frame.layers.as_ref().unwrap();
    let compiled = scene.compile().unwrap();
    let ir = compiled.ir();
    assert_eq!(ir.objects().len(), 4, "three balls and a floor");
    // The glass, painted over whole, is no node of its own.
    assert_eq!(ir.materials().len(), 2);
    let (mut agree, mut hits, mut seen) = (0, 0, [0u32; 5]);
    for i in 0..frame.depth.len() {
        if !frame.hit[i] {
            assert_eq!((layers.object[i], layers.material[i]), (0, 0), "a miss");
            continue;
        }
        hits += 1;
        let p = glam::Vec3::from(layers.position[i]).as_dvec3();
        let mut distances: Vec<f64> = (0..3).map(|k| p.distance(centres[k]) - radii[k]).collect();
        distances.push(p.y + 0.5);
        let nearest = (0..4)
            .min_by(|&a, &b| distances[a].total_cmp(&distances[b]))
            .unwrap();
        // The materials in written order: the mirror (1), then the glossy
        // node (2) outside the glass.
        let material = [0, 1, 2, 0][nearest];
        let want = (u32::try_from(nearest).unwrap() + 1, material);
        seen[want.0 as usize] += 1;
        if (layers.object[i], layers.material[i]) == want {
            agree += 1;
        }
    }
    let share = f64::from(agree) / f64::from(hits);
    eprintln!("ids: {agree} of {hits} hits agree with the nearest shape; per shape {seen:?}");
    assert!(
        seen[1..].iter().all(|&n| n > 50),
        "every shape seen: {seen:?}"
    );
    assert!(share > 0.99, "{share}");
}
