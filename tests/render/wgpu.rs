//! The wgpu backend (`WgpuRenderer`, feature `wgpu`) against the OpenCL
//! renderer: every gallery scene it draws, drawn on a Vulkan device (Mesa's
//! lavapipe where there is no GPU) with each scene file's quality and
//! effects, is the OpenCL picture; frame-to-frame changes write buffers;
//! what it does not draw is a typed error.

use crate::gpu;
use crate::wgpu_device::device;

use fractal_sdf::Error;
use fractal_sdf::metrics::{block_psnr, mask_mismatch, psnr};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{RenderOptions, Renderer, WGPU_TEXTURE_FORMAT, WgpuRenderer};

const WIDTH: u32 = 96;
const HEIGHT: u32 = 72;

/// Whether both backends are here: OpenCL and a Vulkan adapter (each a
/// failure where the run requires it).
fn backends() -> bool {
    gpu::device().is_some() && device().is_some()
}

/// The two backends' images of `compiled` at 96×72: (wgpu, OpenCL).
fn on_both(
    compiled: &fractal_sdf::ir::CompiledScene,
    options: &RenderOptions,
    name: &str,
) -> (image::RgbaImage, image::RgbaImage) {
    let drawn = WgpuRenderer::from_compiled(compiled.clone(), options)
        .unwrap()
        .render(WIDTH, HEIGHT)
        .unwrap();
    let image = Renderer::from_compiled(compiled.clone(), options)
        .unwrap()
        .render(WIDTH, HEIGHT)
        .unwrap();
    gpu::save(&format!("wgpu_{name}"), &drawn);
    (drawn, image)
}

/// The PSNR between the two backends' images of `compiled` at 96×72.
fn between_backends(
    compiled: &fractal_sdf::ir::CompiledScene,
    options: &RenderOptions,
    name: &str,
) -> f64 {
    let (drawn, image) = on_both(compiled, options, name);
    let db = psnr(&image, &drawn);
    println!("{name}: {db:.1} dB");
    db
}

/// Pictures drawn from samples that may go another way: path-traced
/// light, and the brute-force march of an escape-time set. The two
/// backends draw each sample with the same random numbers, but where
/// their single-precision arithmetic differs in its last bits (on a
/// fractal's surface, or at the boundary of a set whose membership flips
/// under any change of a point there) a path may bounce elsewhere, or a
/// ray stop at another filament, so single pixels differ by a sample's
/// grain while the picture is the same. Returns (the PSNR of the pixels,
/// of 4×4 blocks' means) and holds them to 35 and 45 dB.
fn sampled_pictures_agree(
    drawn: &image::RgbaImage,
    image: &image::RgbaImage,
    name: &str,
) -> (f64, f64) {
    let db = psnr(image, drawn);
    let mean_db = block_psnr(image, drawn, 4);
    println!("{name}: {db:.1} dB, 4x4 blocks {mean_db:.1} dB");
    assert!(db >= 35.0, "{name}: {db:.1} dB between the backends");
    assert!(
        mean_db >= 45.0,
        "{name}: {mean_db:.1} dB between 4x4 blocks"
    );
    (db, mean_db)
}

fn options(file: &fractal_sdf::file::SceneFile) -> RenderOptions {
    let mut options = RenderOptions::default();
    options.quality = file.quality.unwrap_or_default();
    options.effects = file.effects;
    options
}

/// At 96×72 with each scene file's quality (2×2 supersampling, 4×4 through
/// a lens) and effects (glow, occlusion, shadows), the two backends draw
/// the same picture of every gallery scene: PSNR at least 60 dB and at
/// most 0.1% of the pixels' hit flags different (measured here: 67.5 dB
/// for `keyframes` to identical, no hit flag different: the backends take
/// the same steps from the same coarse pass, and differ only in the
/// roundings of the functions they call).
/// The path-traced `gi` and the brute-force `mandelbulb_escape` are held
/// as sampled pictures ([`sampled_pictures_agree`], and at most 0.5% of
/// the hit flags: 0.145% measured for `mandelbulb_escape`).
#[test]
fn every_gallery_scene_is_the_opencl_picture() {
    if !backends() {
        return;
    }
    let mut failures = Vec::new();
    let mut drawn = 0;
    for name in fractal_sdf::gallery::names() {
        let file = fractal_sdf::gallery::file(name).expect("a gallery scene");
        let compiled = file.scene.compile().expect("gallery scenes compile");
        let options = options(&file);
        let sampled =
            options.effects.global_illumination.is_some() || compiled.ir().has_inside_shapes();
        let mut wgpu = WgpuRenderer::from_compiled(compiled.clone(), &options)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let drawn_by_wgpu = wgpu.render_frame(WIDTH, HEIGHT).expect("the wgpu frame");
        let mut opencl = Renderer::from_compiled(compiled, &options).expect("the renderer");
        let frame = opencl.render_with_aovs(WIDTH, HEIGHT).expect("the frame");
        let db = psnr(&frame.image, &drawn_by_wgpu.image);
        let differ = mask_mismatch(&frame.hit, &drawn_by_wgpu.hit);
        println!(
            "{name}: {db:.1} dB, {:.3}% hit flags differ",
            100.0 * differ
        );
        assert!(
            drawn_by_wgpu.hit.iter().any(|&h| h),
            "{name}: the wgpu frame hits nothing"
        );
        if sampled {
            sampled_pictures_agree(&drawn_by_wgpu.image, &frame.image, name);
        } else if db < 60.0 {
            failures.push(format!("{name}: {db:.1} dB"));
        }
        // The brute-force march's filaments: a little more.
        let most = if sampled { 0.005 } else { 0.001 };
        if differ > most {
            failures.push(format!("{name}: {:.3}% hit flags differ", 100.0 * differ));
        }
        drawn += 1;
    }
    assert!(
        failures.is_empty(),
        "pictures differ:\n{}",
        failures.join("\n")
    );
    assert_eq!(drawn, fractal_sdf::gallery::names().len());
}

/// The shipped scene files beyond the gallery (fog lit by a light, with
/// its shafts through a sponge; a shape given as a text formula; lamps
/// that light a path-traced scene; the white furnace) are the OpenCL
/// picture too (measured: 91.3, 91.3, 88.3 dB and identical).
#[test]
fn the_scene_files_are_the_opencl_picture() {
    if !backends() {
        return;
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for name in ["fog", "custom_formula", "lamps", "furnace"] {
        let file = fractal_sdf::file::SceneFile::load(root.join(format!("{name}.ron")))
            .expect("a shipped scene file");
        let compiled = file.scene.compile().expect("it compiles");
        let options = options(&file);
        let (drawn, image) = on_both(&compiled, &options, name);
        if options.effects.global_illumination.is_some() {
            sampled_pictures_agree(&drawn, &image, name);
        } else {
            let db = psnr(&image, &drawn);
            println!("{name}: {db:.1} dB");
            assert!(db >= 60.0, "{name}: {db:.1} dB between the backends");
        }
    }
}

/// Single precision is all WGSL has: double precision is the typed
/// error, and it names the OpenCL backend.
#[test]
fn double_precision_is_refused_with_the_way_to_deep_zoom() {
    let mut options = RenderOptions::default();
    options.quality = Quality::production().precision(Precision::F64);
    let scene = Scene::new(sphere(1.0)).compile().unwrap();
    match WgpuRenderer::from_compiled(scene, &options) {
        Err(e @ Error::Unsupported { .. }) => {
            let message = e.to_string();
            assert!(message.contains("double precision"), "{message}");
            assert!(message.contains("OpenCL"), "{message}");
        }
        other => panic!("expected the unsupported error, got {other:?}"),
    }
}

/// Every light a path samples, on the wgpu backend as on OpenCL: an
/// environment image drawn by importance, emissive shapes drawn in their
/// bounding cones, a sphere light and a rectangle light drawn over their
/// surfaces, through glass, a mirror and a rough surface, after four
/// progressive passes.
#[test]
fn every_light_a_path_samples_is_the_opencl_picture() {
    if !backends() {
        return;
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let shapes = [
        sphere(0.6)
            .material(Material::glass(1.5))
            .translate(dvec3(-0.8, 0.0, 0.0)),
        sphere(0.5)
            .material(Material::mirror())
            .translate(dvec3(0.6, 0.0, 0.3)),
        sphere(0.25)
            .material(Material::default().emission(4.0))
            .color(dvec3(1.0, 0.5, 0.2))
            .translate(dvec3(0.0, 0.9, -0.6)),
        mandelbulb(8.0)
            .material(Material::default().roughness(0.6))
            .scale(0.5)
            .translate(dvec3(0.1, -0.2, -0.9)),
        plane(dvec3(0.0, 1.0, 0.0), 0.7),
    ]
    .into_iter()
    .reduce(Node::union)
    .unwrap();
    let mut scene = Scene::new(shapes)
        .with_camera(Camera::look_at(dvec3(0.0, 0.6, 3.4), dvec3(0.0, -0.1, 0.0)))
        .with_lights(vec![
            Light::sphere(dvec3(2.0, 2.5, 1.5), 0.4).intensity(3.0),
            Light::rect(
                dvec3(-2.0, 2.0, 0.5),
                dvec3(0.5, 0.0, 0.0),
                dvec3(0.0, 0.0, 0.5),
            )
            .color(dvec3(0.8, 0.9, 1.0))
            .intensity(2.0),
        ]);
    scene.environment =
        Some(fractal_sdf::scene::Environment::load(root.join("scenes/sky.hdr")).unwrap());
    let compiled = scene.compile().unwrap();
    let mut options = RenderOptions::default();
    options.quality = Quality::preview().resolution_scale(1);
    options.effects = options
        .effects
        .global_illumination(fractal_sdf::quality::GlobalIllumination::new(4));
    let mut wgpu = WgpuRenderer::from_compiled(compiled.clone(), &options).unwrap();
    let mut opencl = Renderer::from_compiled(compiled, &options).unwrap();
    let (mut drawn, mut image) = (None, None);
    for _ in 0..4 {
        drawn = Some(wgpu.render_progressive(WIDTH, HEIGHT).unwrap());
        image = Some(opencl.render_progressive(WIDTH, HEIGHT).unwrap());
    }
    let (drawn, image) = (drawn.unwrap(), image.unwrap());
    gpu::save("wgpu_every_light", &drawn);
    sampled_pictures_agree(&drawn, &image, "every light");
}

/// Inside shapes beside distance-estimated ones, marched by brute force
/// within their region and sphere-traced outside it: the escape-time
/// Mandelbox on a floor beside a ball, its normals from the neighbours'
/// central differences, its occlusion from their depths and its shadow on
/// the floor sampled along the shadow rays, over two progressive passes
/// whose brute-force lattices start elsewhere, are the OpenCL picture. An
/// inside shape of the user's, whose test is OpenCL C, is the typed error.
#[test]
fn inside_shapes_are_the_opencl_picture() {
    if !backends() {
        return;
    }
    use fractal_sdf::quality::ScreenNormals;
    use fractal_sdf::scene::{InsideBounds, InsideShape, Rule};
    let mandelbox = InsideShape::mandelbox().node([-1.5, 12.0]).scale(0.4);
    let scene = Scene::new(
        mandelbox
            .union(sphere(0.3).translate(dvec3(1.3, -0.5, 0.2)))
            .union(plane(dvec3(0.0, 1.0, 0.0), 0.9)),
    )
    .with_camera(Camera::look_at(dvec3(1.2, 1.0, 2.6), dvec3(0.2, -0.3, 0.0)))
    .with_lights(vec![Light::directional(dvec3(0.4, 1.0, 0.5)).softness(0.0)]);
    let compiled = scene.compile().unwrap();
    let mut options = RenderOptions::default();
    options.quality = Quality::preview()
        .resolution_scale(1)
        .supersampling(1)
        .screen_normals(ScreenNormals::Differences);
    let mut wgpu = WgpuRenderer::from_compiled(compiled.clone(), &options).unwrap();
    let mut opencl = Renderer::from_compiled(compiled, &options).unwrap();
    let (mut drawn, mut image) = (None, None);
    for _ in 0..2 {
        drawn = Some(wgpu.render_progressive(WIDTH, HEIGHT).unwrap());
        image = Some(opencl.render_progressive(WIDTH, HEIGHT).unwrap());
    }
    let (drawn, image) = (drawn.unwrap(), image.unwrap());
    gpu::save("wgpu_inside_shapes", &drawn);
    sampled_pictures_agree(&drawn, &image, "inside shapes");

    let ball = InsideShape::new(
        "ball",
        &[("r", Rule::Positive)],
        InsideBounds::sphere(DVec3::ZERO, 2.0),
        |p, a| p.length() < a[0],
        "return length(p) < r;",
    )
    .unwrap();
    let scene = Scene::new(ball.node([1.0])).compile().unwrap();
    match WgpuRenderer::from_compiled(scene, &RenderOptions::default()) {
        Err(Error::Unsupported { what, instead, .. }) => {
            assert!(
                what.contains("inside shape `ball`, written in OpenCL C"),
                "{what}"
            );
            assert!(instead.contains("OpenCL backend"), "{instead}");
        }
        other => panic!("expected the unsupported error, got {other:?}"),
    }
}

/// A frame sequence with motion blur (a ball crossing the view while the
/// shutter is open) renders on the wgpu backend through
/// `Sequence::render_images` as `Sequence::render` renders it on OpenCL,
/// and a stereo pair through `render_stereo` as on OpenCL: the same code
/// drives either renderer (`RenderFrames`). Frames with the shading
/// layers are refused before anything is rendered.
#[test]
fn sequences_and_stereo_pairs_are_the_opencl_frames() {
    use fractal_sdf::animation::{CameraPath, Interpolation, Key, Keyframe, Motion};
    use fractal_sdf::render::{RenderFrames, render_stereo};
    use fractal_sdf::scene::{Stereo, StereoLayout};
    use fractal_sdf::sequence::{MotionBlur, Sequence};
    if !backends() {
        return;
    }
    let scene = Scene::new(
        sphere(0.3)
            .translate(fractal_sdf::scene::param3("at", DVec3::ZERO))
            .union(plane(dvec3(0.0, 1.0, 0.0), 0.5)),
    )
    .with_camera(Camera::look_at(dvec3(0.0, 0.4, 4.0), DVec3::ZERO));
    let motions = [Motion::Keys {
        name: "at.x".into(),
        keys: vec![
            Key::new(0.0, -1.5).interpolation(Interpolation::Linear),
            Key::new(1.0, 1.5),
        ],
    }];
    let (at, target) = (scene.camera.position, scene.camera.target);
    let path = CameraPath::new(vec![
        Keyframe::new(0.0, at, target),
        Keyframe::new(1.0, at, target),
    ])
    .unwrap();
    let compiled = scene.compile().unwrap();
    let mut options = RenderOptions::default();
    options.quality = Quality::preview().resolution_scale(1);
    let mut wgpu = WgpuRenderer::from_compiled(compiled.clone(), &options).unwrap();
    let mut opencl = Renderer::from_compiled(compiled, &options).unwrap();
    let dir = std::env::temp_dir().join(format!("fractal-sdf-wgpu-seq-{}", std::process::id()));
    let sequence = |name: &str| {
        Sequence::new(dir.join(name), 2.0, 2)
            .unwrap()
            .motion_blur(MotionBlur::new(8, 1.0))
            .unwrap()
    };
    let (on_wgpu, on_opencl) = (sequence("wgpu"), sequence("opencl"));
    let mut timed = 0;
    on_wgpu
        .render_images(&mut wgpu, &path, &motions, &[0, 1], (WIDTH, HEIGHT), |f| {
            timed += usize::from(f.timing.is_some());
        })
        .unwrap();
    assert_eq!(timed, 2, "every frame reports its time");
    on_opencl
        .render(
            &mut opencl,
            &path,
            &motions,
            &[0, 1],
            (WIDTH, HEIGHT),
            |_| {},
        )
        .unwrap();
    let frame = |seq: &Sequence, i| image::open(seq.frame_path(i)).unwrap().to_rgba8();
    for i in 0..2 {
        let db = psnr(&frame(&on_opencl, i), &frame(&on_wgpu, i));
        println!("motion-blurred frame {i}: {db:.1} dB");
        assert!(db >= 60.0, "frame {i}: {db:.1} dB between the backends");
    }
    // The blur is there: the first frame differs from the ball at rest at
    // its first moment.
    wgpu.set_param("at.x", -1.5).unwrap();
    let still = RenderFrames::render(&mut wgpu, WIDTH, HEIGHT).unwrap();
    assert!(psnr(&still, &frame(&on_wgpu, 0)) < 35.0, "no blur");

    let stereo = Stereo::new(StereoLayout::SideBySide);
    let drawn = render_stereo(&mut wgpu, WIDTH, HEIGHT, &stereo).unwrap();
    opencl.set_param("at.x", -1.5).unwrap();
    let image = opencl.render_stereo(WIDTH, HEIGHT, &stereo).unwrap();
    assert_eq!(drawn.dimensions(), (2 * WIDTH, HEIGHT));
    let db = psnr(&image, &drawn);
    println!("stereo pair: {db:.1} dB");
    assert!(db >= 60.0, "{db:.1} dB between the stereo pairs");

    let layered = Sequence::new(dir.join("exr"), 2.0, 2)
        .unwrap()
        .format("exr")
        .unwrap();
    let refused = layered.render_images(&mut wgpu, &path, &motions, &[0], (WIDTH, HEIGHT), |_| {});
    assert!(
        matches!(&refused, Err(Error::Invalid { reason, .. }) if reason.contains("OpenCL")),
        "{refused:?}"
    );
    assert!(!layered.frame_path(0).exists());
    std::fs::remove_dir_all(&dir).ok();
}

/// A dynamic parameter, the camera and the lights change with a buffer
/// write: the picture is the one a renderer built with the new values
/// draws, on the same pipeline.
#[test]
fn parameters_camera_and_lights_change_the_picture_on_the_same_pipeline() {
    if device().is_none() {
        return;
    }
    let scene = gpu::sphere_box_floor();
    let (w, h) = (64, 48);
    let mut r = WgpuRenderer::new(&scene, gpu::quick()).unwrap();
    let builds = r.builds();
    let first = r.render(w, h).unwrap();
    assert_eq!(r.render(w, h).unwrap(), first, "rendering is deterministic");
    r.set_param("radius", 0.3).unwrap();
    assert_eq!(r.param("radius"), Some(0.3));
    let smaller = r.render(w, h).unwrap();
    assert_ne!(smaller, first);
    let camera = Camera::look_at(dvec3(3.0, 2.0, 0.5), dvec3(0.0, 0.3, 0.0));
    r.set_camera(camera).unwrap();
    let light = Light::directional(dvec3(-1.0, 1.0, 0.2));
    r.set_lights([light]).unwrap();
    let moved = r.render(w, h).unwrap();

    assert_eq!(r.builds(), builds, "frame-to-frame changes build nothing");

    // A second renderer of the scene takes the pipeline from the cache.
    let mut fresh = WgpuRenderer::new(&scene, gpu::quick()).unwrap();
    assert_eq!(fresh.builds(), 0, "the pipeline comes from the cache");
    fresh.set_param("radius", 0.3).unwrap();
    assert_eq!(fresh.render(w, h).unwrap(), smaller);
    // A quality change builds a new pipeline once; changing back finds
    // the first in the cache.
    let mut other = gpu::quick();
    other.ao_samples += 1;
    fresh.set_quality(other).unwrap();
    assert_eq!(fresh.builds(), 1);
    assert_ne!(fresh.render(w, h).unwrap(), smaller);
    fresh.set_quality(gpu::quick()).unwrap();
    assert_eq!(fresh.builds(), 1);
    assert_eq!(fresh.render(w, h).unwrap(), smaller);
    let built = scene.clone().with_camera(camera).with_lights([light]);
    let mut fresh = WgpuRenderer::new(&built, gpu::quick()).unwrap();
    fresh.set_param("radius", 0.3).unwrap();
    assert_eq!(fresh.render(w, h).unwrap(), moved);
    assert_ne!(moved, smaller);
    assert!(matches!(
        r.set_param("radius", f64::NAN),
        Err(Error::NonFinite { .. })
    ));
}

/// Forty spheres placed by dynamic positions (a walked instance table)
/// and a box with a dynamic size outside the table.
#[allow(clippy::cast_precision_loss)]
fn moving_spheres(positions: &[DVec3], size: f64) -> Scene {
    let spheres = positions
        .iter()
        .enumerate()
        .map(|(i, &at)| {
            sphere(0.12)
                .translate(fractal_sdf::scene::param3(&format!("s{i}"), at))
                .color(dvec3(0.2 + 0.015 * i as f64, 0.5, 0.8))
        })
        .reduce(Node::union)
        .unwrap();
    let size = fractal_sdf::scene::param("size", size);
    Scene::new(
        spheres
            .union(
                cuboid(dvec3(0.2, 0.2, 0.2))
                    .round(size)
                    .translate(dvec3(0.0, 0.9, 0.0)),
            )
            .union(plane(DVec3::Y, 1.0)),
    )
    .with_camera(Camera::look_at(dvec3(0.0, 1.5, 3.5), DVec3::ZERO))
}

/// Moving every instance of a walked table is written once, at the next
/// frame: the picture is a renderer's built with the new positions, and
/// the OpenCL renderer's after the same moves; a value outside the tables
/// changed after them changes the picture too.
#[test]
#[allow(clippy::cast_precision_loss)]
fn moving_every_instance_is_the_picture_of_the_new_positions() {
    if !backends() {
        return;
    }
    let (w, h) = (64, 48);
    let ring = |turn: f64| -> Vec<DVec3> {
        (0..40)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 40.0 + turn;
                dvec3(a.cos(), 0.3 * (3.0 * a).sin() + 0.2 * turn, a.sin())
            })
            .collect()
    };
    let (before, after) = (ring(0.0), ring(0.4));
    let scene = moving_spheres(&before, 0.05);
    let mut wgpu = WgpuRenderer::new(&scene, gpu::quick()).unwrap();
    let mut opencl = Renderer::new(&scene, gpu::quick()).unwrap();
    let first = wgpu.render(w, h).unwrap();
    for (i, at) in after.iter().enumerate() {
        for (axis, v) in ["x", "y", "z"].iter().zip(at.to_array()) {
            let name = format!("s{i}.{axis}");
            wgpu.set_param(&name, v).unwrap();
            opencl.set_param(&name, v).unwrap();
        }
    }
    let moved = wgpu.render(w, h).unwrap();
    assert_ne!(moved, first, "the spheres moved");
    let built = WgpuRenderer::new(&moving_spheres(&after, 0.05), gpu::quick())
        .unwrap()
        .render(w, h)
        .unwrap();
    let db = psnr(&built, &moved);
    println!("moved against built there: {db:.1} dB");
    assert!(db >= 60.0, "moved against built there: {db:.1} dB");
    let db = psnr(&opencl.render(w, h).unwrap(), &moved);
    println!("moved on wgpu against OpenCL: {db:.1} dB");
    assert!(db >= 60.0, "moved on wgpu against OpenCL: {db:.1} dB");

    // A value the tables do not copy: the values alone are written.
    wgpu.set_param("size", 0.15).unwrap();
    let rounder = wgpu.render(w, h).unwrap();
    assert_ne!(rounder, moved);
    let built = WgpuRenderer::new(&moving_spheres(&after, 0.15), gpu::quick())
        .unwrap()
        .render(w, h)
        .unwrap();
    let db = psnr(&built, &rounder);
    assert!(db >= 60.0, "a value outside the tables: {db:.1} dB");
    assert_eq!(wgpu.render(w, h).unwrap(), rounder, "nothing changed");
}

/// Into the application's texture: the pixels `render` returns, with no
/// copy through the CPU on the way.
#[test]
fn a_frame_rendered_into_a_texture_is_the_image() {
    if device().is_none() {
        return;
    }
    let (w, h) = (40, 30);
    let mut r = WgpuRenderer::new(&gpu::sphere_box_floor(), gpu::quick()).unwrap();
    let image = r.render(w, h).unwrap();
    let device = r.device().clone();
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        ..texture_descriptor(w, h)
    });
    let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
    r.render_to_texture(&view, w, h).unwrap();
    let row = (4 * w).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(row * h),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(h),
            },
        },
        texture.size(),
    );
    r.queue().submit([encoder.finish()]);
    staging
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.unwrap());
    device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    let bytes = staging.slice(..).get_mapped_range().unwrap().to_vec();
    let pixels: Vec<u8> = bytes
        .chunks_exact(row as usize)
        .flat_map(|r| r[..4 * w as usize].to_vec())
        .collect();
    assert_eq!(pixels, image.into_raw());

    // An image wider than the device's textures is the typed error
    // with the limit, before anything is allocated.
    let side = device.limits().max_texture_dimension_2d + 1;
    if side <= fractal_sdf::render::MAX_IMAGE_SIDE {
        match r.render(side, 1) {
            Err(Error::Resolution { reason, .. }) => {
                assert!(reason.contains(&(side - 1).to_string()), "{reason}");
            }
            other => panic!("expected the resolution error, got {other:?}"),
        }
    }

    // A texture of another format is the typed error, not a panic.
    let wrong = device.create_texture(&wgpu::TextureDescriptor {
        format: wgpu::TextureFormat::Rgba16Float,
        ..texture_descriptor(w, h)
    });
    let view = wrong.create_view(&wgpu::TextureViewDescriptor::default());
    assert!(matches!(
        r.render_to_texture(&view, w, h),
        Err(Error::Wgpu(_))
    ));
}

fn texture_descriptor(w: u32, h: u32) -> wgpu::TextureDescriptor<'static> {
    wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: WGPU_TEXTURE_FORMAT,
        usage: wgpu::TextureUsages::STORAGE_BINDING,
        view_formats: &[],
    }
}

/// Materials through every way the scene functions carry a surface: blended
/// across a smooth union's seam (`material_mix`), chosen by a hard union,
/// kept by a subtraction and an intersection, and as a row of a table of
/// alike operands (an instanced union of 24 spheres, each a material of
/// its own). Each prints as valid WGSL and renders as on OpenCL.
#[test]
fn materials_in_every_boolean_are_the_opencl_picture() {
    let glass = || Material::glass(1.5);
    let rough = || Material::oren_nayar(0.5);
    let shiny = Material::blinn_phong(0.8, 0.0);
    let floor = gpu::floor().material(Material::mirror().reflectivity(0.3));
    let blended = sphere(0.5)
        .material(glass())
        .smooth_union(cuboid(dvec3(0.4, 0.3, 0.3)).material(rough()), 0.3)
        .translate(dvec3(-0.8, 0.5, 0.0));
    let carved = cuboid(dvec3(0.4, 0.4, 0.4))
        .material(shiny)
        .subtract(sphere(0.5).material(glass()))
        .intersect(sphere(0.6).material(rough()))
        .translate(dvec3(0.8, 0.4, 0.0));
    let mut scene = Scene::new(floor.union(blended).union(carved))
        .with_camera(Camera::look_at(dvec3(0.0, 1.6, 3.6), dvec3(0.0, 0.4, 0.0)).fov(45.0));
    for i in 0..24 {
        let angle = f64::from(i) * std::f64::consts::TAU / 24.0;
        let material = if i % 2 == 0 {
            glass()
        } else {
            rough().reflectivity(0.5)
        };
        scene = scene.add(sphere(0.08).material(material).translate(dvec3(
            1.6 * angle.cos(),
            0.08,
            1.6 * angle.sin() - 0.5,
        )));
    }
    let compiled = scene.compile().unwrap();
    let mut options = RenderOptions::default();
    options.quality = Quality::production();
    let module = fractal_sdf::codegen::emit_wgsl(
        &compiled,
        &fractal_sdf::codegen::Options::default().target(fractal_sdf::codegen::Target::Render),
    )
    .unwrap();
    for used in ["material_mix", "material_select", "fn DE_material"] {
        assert!(module.source.contains(used), "no {used} in the module");
    }
    let parsed = naga::front::wgsl::parse_str(&module.source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&module.source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&parsed)
    .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&module.source)));
    if !backends() {
        return;
    }
    let db = between_backends(&compiled, &options, "materials_in_every_boolean");
    assert!(db >= 60.0, "{db:.1} dB between the backends");
}

/// An environment image lights the scene, shows behind it and in its
/// mirrors and glass on the wgpu backend as on OpenCL.
#[test]
fn an_environment_image_is_the_opencl_picture() {
    if !backends() {
        return;
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut file = fractal_sdf::gallery::file("materials").unwrap();
    file.scene.environment =
        Some(fractal_sdf::scene::Environment::load(root.join("scenes/sky.hdr")).unwrap());
    let compiled = file.scene.compile().unwrap();
    let options = options(&file);
    let db = between_backends(&compiled, &options, "under_an_environment");
    assert!(db >= 40.0, "{db:.1} dB between the backends");
}

/// Progressive passes: each pass adds new samples in the pixel and on the
/// lens, and after four the blur of the lens scene is the OpenCL
/// backend's after four (measured: identical); the first pass is the frame of
/// its own, a change starts again, and the count says how many the image
/// holds.
#[test]
fn progressive_passes_converge_as_on_opencl() {
    if !backends() {
        return;
    }
    let file = fractal_sdf::gallery::file("depth_of_field").unwrap();
    let compiled = file.scene.compile().unwrap();
    let mut options = options(&file);
    options.quality = options.quality.supersampling(1);
    let mut wgpu = WgpuRenderer::from_compiled(compiled.clone(), &options).unwrap();
    let mut opencl = Renderer::from_compiled(compiled, &options).unwrap();
    let single = wgpu.render(WIDTH, HEIGHT).unwrap();
    assert_eq!(wgpu.render_progressive(WIDTH, HEIGHT).unwrap(), single);
    let mut first_db = 0.0;
    let (mut drawn, mut image) = (single.clone(), single.clone());
    for pass in 1..=4 {
        if pass > 1 {
            drawn = wgpu.render_progressive(WIDTH, HEIGHT).unwrap();
        }
        image = opencl.render_progressive(WIDTH, HEIGHT).unwrap();
        if pass == 1 {
            first_db = psnr(&image, &drawn);
        }
    }
    assert_eq!(wgpu.progressive_passes(), 4);
    assert_ne!(drawn, single, "the passes changed nothing");
    let db = psnr(&image, &drawn);
    println!("depth of field: one pass {first_db:.1} dB, four passes {db:.1} dB");
    assert!(
        db >= 40.0,
        "{db:.1} dB between the backends after four passes"
    );
    // The image moves towards the converged blur: four passes differ from
    // one pass by more than the backends differ from each other.
    assert!(psnr(&single, &drawn) < db);
    // A change (the camera, set again) starts again from the first pass.
    let camera = *wgpu.camera();
    wgpu.set_camera(camera).unwrap();
    assert_eq!(wgpu.progressive_passes(), 0);
    assert_eq!(wgpu.render_progressive(WIDTH, HEIGHT).unwrap(), single);
}
