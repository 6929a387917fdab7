//! The camera's optics: the thin lens (depth of field), progressive
//! passes, off-axis stereo eyes and the lens shift they use, each checked
//! against the CPU twin of the rays the kernel traces
//! ([`Viewport::lens_ray`], [`sample_point`]) or against geometry.

use crate::gpu;

use fractal_sdf::cpu::{self, Evaluator};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{
    DeviceSelector, EdgeThresholds, Renderer, Viewport, compose, sample_point,
};
use fractal_sdf::scene::{Stereo, StereoLayout};
use glam::dvec2;
use image::RgbaImage;

/// A pure red sphere: only its pixels have no green (the sky has some), so
/// a pixel's green channel says whether its rays hit it.
fn red(node: Node) -> Node {
    node.color(dvec3(1.0, 0.0, 0.0))
}

/// A renderer without effects or lights: the red sphere is red times the
/// sky's ambient light, with no green anywhere.
fn renderer(scene: &Scene, quality: Quality) -> Renderer {
    let scene = scene.clone().with_lights([]);
    Renderer::with_options(&scene, &gpu::options(quality, Effects::none())).unwrap()
}

fn covered(image: &RgbaImage, x: u32, y: u32) -> bool {
    image.get_pixel(x, y).0[1] == 0
}

/// The x coordinate of the centre of the red pixels, in pixels.
fn centroid_x(image: &RgbaImage) -> f64 {
    let (mut sum, mut n) = (0.0, 0.0);
    for (x, y, _) in image.enumerate_pixels() {
        if covered(image, x, y) {
            sum += f64::from(x) + 0.5;
            n += 1.0;
        }
    }
    assert!(n > 0.0, "the sphere is in view");
    sum / n
}

fn psnr(a: &RgbaImage, b: &RgbaImage) -> f64 {
    let mse = a
        .pixels()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..3).map(move |c| (f64::from(p.0[c]) - f64::from(q.0[c])).powi(2)))
        .sum::<f64>()
        / (3.0 * f64::from(a.width() * a.height()));
    10.0 * (255.0 * 255.0 / mse.max(1e-12)).log10()
}

#[test]
fn a_closed_lens_is_the_pinhole_image_exactly() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor().with_lights([gpu::sun(0.05)]);
    let quality = gpu::quick().supersampling(2);
    let pinhole = Renderer::new(&scene, quality)
        .unwrap()
        .render(64, 48)
        .unwrap();
    // Aperture 0 with a focus distance of its own: still a pinhole.
    let camera = scene.camera.lens(0.0).focus(1.0);
    let mut closed = Renderer::new(&scene.clone().with_camera(camera), quality).unwrap();
    assert_eq!(closed.render(64, 48).unwrap(), pinhole);
    // The first progressive pass is the frame of its own.
    assert_eq!(closed.render_progressive(64, 48).unwrap(), pinhole);
    assert_eq!(closed.progressive_passes(), 1);
}

#[test]
fn lens_rays_are_the_cpu_twins() {
    let Some(_) = gpu::device() else { return };
    // A sphere well in front of the plane in focus: its edge blurs over
    // several pixels, so which pixels a lens ray hits depends on where on
    // the lens it leaves.
    let camera = Camera::look_at(dvec3(0.0, 0.0, 4.0), DVec3::ZERO)
        .fov(30.0)
        .lens(0.3)
        .focus(8.0);
    let ball = red(sphere(1.0));
    let scene = Scene::new(ball.clone()).with_camera(camera);
    let (w, h) = (48, 36);
    // The coarse pass too: it must widen its cones by the lens, or rays
    // leaving the lens off-centre start past the sphere.
    for (supersampling, cone) in [(1, 0), (2, 0), (1, 4)] {
        let quality = gpu::plain(gpu::quick())
            .supersampling(supersampling)
            .cone_tile(cone);
        let mut r = renderer(&scene, quality);
        let view = Viewport::new(&camera, w, h, Precision::F32).unwrap();
        let settings = view.march_settings(&quality);
        let eval = Evaluator::new(&ball).unwrap();
        // The sky alone: the sphere moved behind the camera.
        let sky = renderer(
            &Scene::new(ball.clone().translate(dvec3(0.0, 0.0, 50.0))).with_camera(camera),
            quality,
        )
        .render(w, h)
        .unwrap();
        // Pixels the CPU says every sample hits, or every sample misses,
        // by a margin: (image, all hit, none hit).
        for pass in 0..3 {
            let image = r.render_progressive(w, h).unwrap();
            let (mut checked, mut partly) = (0, 0);
            for y in 0..h {
                for x in 0..w {
                    // Every sample of passes 0..=pass, and the closest
                    // any ray comes to the sphere's edge.
                    let per = supersampling * supersampling;
                    let (mut hits, mut margin) = (0, f64::INFINITY);
                    for j in 0..(pass + 1) * per {
                        let s = sample_point(w, x, y, j, supersampling);
                        let ray = view.lens_ray(
                            f64::from(x) + s.offset.x,
                            f64::from(y) + s.offset.y,
                            s.lens,
                        );
                        let hit = cpu::march(&eval, ray, &settings);
                        hits += u32::from(hit.hit);
                        let to = -ray.origin;
                        let miss = (to - ray.direction * to.dot(ray.direction)).length();
                        margin = margin.min((miss - 1.0).abs());
                    }
                    if margin < 0.02 {
                        continue;
                    }
                    let all = (pass + 1) * per;
                    checked += 1;
                    if hits > 0 && hits < all {
                        partly += 1;
                    }
                    // All hit: no green at all; none: the sky; some: a
                    // green between.
                    let green = image.get_pixel(x, y).0[1];
                    let sky = sky.get_pixel(x, y);
                    if hits == all {
                        assert_eq!(green, 0, "pass {pass}, ({x}, {y}): every sample hits");
                    } else if hits == 0 {
                        // The sky's gradient over the rows a pixel's
                        // samples span: a few levels near the bottom.
                        let p = image.get_pixel(x, y);
                        assert!(
                            (0..3).all(|c| p.0[c].abs_diff(sky.0[c]) <= 3),
                            "pass {pass}, ({x}, {y}): no hit, {p:?} against the sky's {sky:?}"
                        );
                    } else {
                        // The mean of the samples' linear colours: the
                        // sky's green times the share that misses.
                        let sky_linear = (f64::from(sky.0[1]) / 255.0).powf(2.2);
                        let missed = f64::from(all - hits) / f64::from(all);
                        let expected = 255.0 * (missed * sky_linear).powf(1.0 / 2.2);
                        assert!(
                            (f64::from(green) - expected).abs() <= 4.0,
                            "pass {pass}, ({x}, {y}): {hits} of {all} hit, green {green}, \
                             expected {expected:.1}"
                        );
                    }
                }
            }
            assert!(checked > w * h / 2, "{checked} pixels checked");
            if pass > 0 || supersampling > 1 {
                assert!(partly > 20, "the blurred edge is wide: {partly} pixels");
            }
        }
    }
}

/// Pixels along the image's middle row that are neither all sphere nor
/// all sky: the width of the sphere's blurred edges.
fn edge_width(image: &RgbaImage) -> u32 {
    let y = image.height() / 2;
    let sky = image.get_pixel(0, y).0[1];
    (0..image.width())
        .filter(|&x| {
            let g = image.get_pixel(x, y).0[1];
            g > 0 && g < sky.saturating_sub(2)
        })
        .count() as u32
}

#[test]
fn only_what_is_off_the_plane_in_focus_blurs_and_by_the_circle_of_confusion() {
    let Some(_) = gpu::device() else { return };
    let (w, h) = (96, 48);
    let at = |z: f64| {
        let camera = Camera::look_at(dvec3(0.0, 0.0, 4.0), DVec3::ZERO)
            .fov(30.0)
            .lens(0.1)
            .focus(4.0);
        Scene::new(red(sphere(0.5)).translate(dvec3(0.0, 0.0, z))).with_camera(camera)
    };
    let converged = |scene: &Scene| {
        let mut r = renderer(scene, gpu::plain(gpu::quick()));
        let mut image = r.render_progressive(w, h).unwrap();
        while r.progressive_passes() < 64 {
            image = r.render_progressive(w, h).unwrap();
        }
        image
    };
    // In focus (the sphere's silhouette 4 - 0.06 away, within 1.5% of the
    // plane in focus): antialiased edges only, as a pinhole's.
    let sharp = converged(&at(0.0));
    let pinhole = {
        let scene = at(0.0);
        let scene = scene.clone().with_camera(scene.camera.lens(0.0));
        converged(&scene)
    };
    gpu::save("optics_in_focus", &sharp);
    assert!(edge_width(&sharp) <= edge_width(&pinhole) + 2);
    // Out of focus, 2 units nearer: a lens ray leaving the lens r from
    // its centre passes r |1 - d / f| from the centre's ray at depth d,
    // r |1 / d - 1 / f| at unit distance, so the blur circle is
    // 2 a |1 / d - 1 / f| across there, in units of a pixel's size.
    let blurred = converged(&at(2.0));
    gpu::save("optics_out_of_focus", &blurred);
    let view = Viewport::new(&at(2.0).camera, w, h, Precision::F32).unwrap();
    let pixel = view.footprint(1.0) - view.footprint(0.0);
    // The silhouette is about 1.94 from the camera.
    let diameter = 2.0 * 0.1 * (1.0 / 1.94 - 1.0 / 4.0) / pixel;
    let measured = f64::from(edge_width(&blurred)) / 2.0;
    eprintln!(
        "blur: {measured} px per edge, circle of confusion {diameter:.1} px; in focus {} vs pinhole {}",
        edge_width(&sharp),
        edge_width(&pinhole)
    );
    assert!(
        measured > 0.6 * diameter && measured < 1.4 * diameter + 1.0,
        "each edge blurs over the circle of confusion: {measured} px, expected {diameter:.1}"
    );
}

#[test]
fn progressive_passes_converge_on_the_supersampled_image() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor().with_lights([gpu::sun(0.1)]);
    let (w, h) = (64, 48);
    let quality = gpu::quick();
    let reference = Renderer::new(&scene, quality.supersampling(8))
        .unwrap()
        .render(w, h)
        .unwrap();
    let mut r = Renderer::new(&scene, quality).unwrap();
    let mut scores = Vec::new();
    for passes in 1..=64 {
        let image = r.render_progressive(w, h).unwrap();
        assert_eq!(r.progressive_passes(), passes);
        if [1, 4, 16, 64].contains(&passes) {
            scores.push(psnr(&image, &reference));
        }
    }
    eprintln!("PSNR against 8x8 supersampling after 1, 4, 16, 64 passes: {scores:.1?}");
    for pair in scores.windows(2) {
        assert!(
            pair[1] > pair[0] + 2.0,
            "each fourfold adds detail: {scores:?}"
        );
    }
    assert!(scores[3] > 38.0, "{scores:?}");
    // A new camera starts again: the next pass is a frame of its own.
    let moved = scene.camera.up(dvec3(0.1, 1.0, 0.0));
    r.set_camera(moved).unwrap();
    let first = r.render_progressive(w, h).unwrap();
    assert_eq!(r.progressive_passes(), 1);
    assert_eq!(first, r.render(w, h).unwrap());
    // So does another size.
    r.render_progressive(w, h).unwrap();
    let small = r.render_progressive(w / 2, h / 2).unwrap();
    assert_eq!(r.progressive_passes(), 1);
    assert_eq!(small, r.render(w / 2, h / 2).unwrap());
    // And sums lost to buffers made anew at the same size (a frame with
    // outputs needs buffers that progressive ones do not have).
    r.render_progressive(w, h).unwrap();
    r.render_progressive(w, h).unwrap();
    r.render_with_aovs(w, h).unwrap();
    let again = r.render_progressive(w, h).unwrap();
    assert_eq!(r.progressive_passes(), 1);
    assert_eq!(again, r.render(w, h).unwrap());
}

#[test]
fn progressive_passes_agree_across_devices_scales_and_precisions() {
    let Some(device) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor().with_lights([gpu::sun(0.05)]);
    let (w, h) = (48, 36);
    let passes = |r: &mut Renderer| {
        let first = r.render_progressive(w, h).unwrap();
        let mut last = first.clone();
        for _ in 1..3 {
            last = r.render_progressive(w, h).unwrap();
        }
        (first, last)
    };
    // The same device twice splits every pass's tiles: the same image.
    let quality = gpu::quick();
    let (_, alone) = passes(&mut Renderer::new(&scene, quality).unwrap());
    let twice = [
        DeviceSelector::exactly(&device),
        DeviceSelector::exactly(&device),
    ];
    let options = gpu::options(quality, Effects::default());
    let mut shared = Renderer::with_devices(&scene, &options, &twice).unwrap();
    assert_eq!(passes(&mut shared).1, alone);
    // A resolution scale and F64: the first pass is still the frame of
    // its own, and the passes refine it.
    let mut qualities = vec![quality.resolution_scale(2)];
    if gpu::fp64(&device) {
        qualities.push(quality.precision(Precision::F64));
    }
    for quality in qualities {
        let mut r = Renderer::new(&scene, quality).unwrap();
        let plain = r.render(w, h).unwrap();
        let (first, last) = passes(&mut r);
        assert_eq!(first, plain, "{quality:?}");
        assert_ne!(last, plain, "{quality:?}");
        assert_eq!(last.dimensions(), (w, h));
    }
}

#[test]
fn progressive_rendering_stops_at_its_sample_limit() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    // 8 x 8 samples a pass: the limit is 64 passes.
    let mut r = Renderer::new(&scene, gpu::quick().supersampling(8)).unwrap();
    let limit = Renderer::MAX_PROGRESSIVE_SAMPLES / 64;
    let mut last = r.render_progressive(16, 12).unwrap();
    while r.progressive_passes() < limit {
        last = r.render_progressive(16, 12).unwrap();
    }
    assert_eq!(r.render_progressive(16, 12).unwrap(), last);
    assert_eq!(r.progressive_passes(), limit);
    r.restart_progressive();
    assert_eq!(r.progressive_passes(), 0);
    assert_eq!(
        r.render_progressive(16, 12).unwrap(),
        r.render(16, 12).unwrap()
    );
}

#[test]
fn stereo_disparity_vanishes_at_convergence_and_crosses_in_front() {
    let Some(_) = gpu::device() else { return };
    let (w, h) = (160, 60);
    let centre = Camera::look_at(dvec3(0.0, 0.0, 5.0), DVec3::ZERO).fov(30.0);
    let (separation, convergence) = (0.4, 5.0);
    let [left, right] = centre.eyes(separation, convergence).unwrap();
    for z in [0.0, 2.0, -3.0] {
        let scene = Scene::new(red(sphere(0.3)).translate(dvec3(0.0, 0.0, z)));
        let mut r = renderer(&scene.clone().with_camera(left), gpu::plain(gpu::quick()));
        let seen_left = r.render(w, h).unwrap();
        r.set_camera(right).unwrap();
        let seen_right = r.render(w, h).unwrap();
        let disparity = centroid_x(&seen_left) - centroid_x(&seen_right);
        // Expected: s (1/d - 1/c) at unit distance, in pixels.
        let view = Viewport::new(&centre, w, h, Precision::F32).unwrap();
        let pixel = view.footprint(1.0) - view.footprint(0.0);
        let depth = 5.0 - z;
        let expected = separation * (1.0 / depth - 1.0 / convergence) / pixel;
        eprintln!("sphere at depth {depth}: disparity {disparity:.2} px, expected {expected:.2}");
        assert!(
            (disparity - expected).abs() < 0.05 * expected.abs() + 0.1,
            "depth {depth}: {disparity} px, expected {expected}"
        );
        // Its centre, on the axis, is where the centre camera sees it when
        // at the convergence distance; both eyes look straight ahead.
        if z == 0.0 {
            assert!((centroid_x(&seen_left) - f64::from(w) / 2.0).abs() < 0.1);
        }
    }
}

#[test]
fn stereo_pictures_lay_out_the_eyes() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor().with_lights([gpu::sun(0.05)]);
    let mut r = Renderer::new(&scene, gpu::quick()).unwrap();
    let stereo = Stereo::new(StereoLayout::SideBySide).separation(0.1);
    let [left, right] = stereo.eyes(&scene.camera).unwrap();
    let pair = r.render_stereo(40, 30, &stereo).unwrap();
    assert_eq!(r.camera(), &scene.camera, "the camera is restored");
    r.set_camera(left).unwrap();
    let seen_left = r.render(40, 30).unwrap();
    r.set_camera(right).unwrap();
    let seen_right = r.render(40, 30).unwrap();
    assert_ne!(seen_left, seen_right);
    assert_eq!(
        pair,
        compose(&seen_left, &seen_right, StereoLayout::SideBySide)
    );
    assert_eq!(pair.dimensions(), (80, 30));
    assert_eq!(
        image::imageops::crop_imm(&pair, 40, 0, 40, 30).to_image(),
        seen_right
    );
    r.set_camera(scene.camera).unwrap();
    let over = r
        .render_stereo(40, 30, &stereo.layout(StereoLayout::OverUnder))
        .unwrap();
    assert_eq!(over.dimensions(), (40, 60));
    assert_eq!(
        image::imageops::crop_imm(&over, 0, 0, 40, 30).to_image(),
        seen_left
    );
    let anaglyph = r
        .render_stereo(40, 30, &stereo.layout(StereoLayout::Anaglyph))
        .unwrap();
    for (x, y, p) in anaglyph.enumerate_pixels() {
        let (l, rr) = (seen_left.get_pixel(x, y).0, seen_right.get_pixel(x, y).0);
        assert_eq!(&p.0[1..3], &rr[1..3], "green and blue from the right eye");
        let luma = 0.299 * f64::from(l[0]) + 0.587 * f64::from(l[1]) + 0.114 * f64::from(l[2]);
        assert!(
            (f64::from(p.0[0]) - luma).abs() <= 0.5,
            "red from the left eye's brightness"
        );
    }
}

#[test]
fn bad_optics_are_refused_clearly() {
    let camera = Camera::default();
    let err = |c: Camera| c.validate().unwrap_err().to_string();
    assert!(err(camera.lens(-0.1)).contains("aperture must be finite and >= 0, got -0.1"));
    assert!(err(camera.lens(f64::NAN)).contains("aperture"));
    assert!(err(camera.focus(0.0)).contains("focus distance must be finite and > 0, got 0"));
    assert!(err(camera.shifted(dvec2(f64::INFINITY, 0.0))).contains("lens shift must be finite"));
    let stereo = |c: &Camera, s: f64, d: f64| c.eyes(s, d).unwrap_err().to_string();
    assert!(
        stereo(&camera.orthographic(2.0), 0.1, 3.0).contains("stereo needs a perspective camera")
    );
    assert!(
        stereo(&camera, -0.1, 3.0).contains("eye separation must be finite and >= 0, got -0.1")
    );
    assert!(
        stereo(&camera, 0.1, 0.0).contains("convergence distance must be finite and > 0, got 0")
    );
    // A scene whose camera has a bad lens does not compile.
    let scene = Scene::new(sphere(1.0)).with_camera(camera.lens(-1.0));
    assert!(matches!(scene.compile(), Err(Error::Camera { .. })));
}

#[test]
fn adaptive_supersampling_refines_the_edges_as_uniform_passes_do() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor().with_lights([gpu::sun(0.05)]);
    let (w, h) = (128, 96);
    let quality = gpu::quick();
    let mut r = Renderer::new(&scene, quality).unwrap();
    let frame = r
        .render_adaptive(w, h, 8, &EdgeThresholds::default())
        .unwrap();
    gpu::save("adaptive", &frame.image);
    let mask = RgbaImage::from_fn(w, h, |x, y| {
        let on = frame.refined[(y * w + x) as usize];
        image::Rgba(if on { [255, 0, 0, 255] } else { [0, 0, 0, 255] })
    });
    gpu::save("adaptive_mask", &mask);
    let uniform = {
        let mut u = Renderer::new(&scene, quality).unwrap();
        let mut image = u.render_progressive(w, h).unwrap();
        while u.progressive_passes() < 8 {
            image = u.render_progressive(w, h).unwrap();
        }
        image
    };
    let plain = Renderer::new(&scene, quality)
        .unwrap()
        .render(w, h)
        .unwrap();
    assert_eq!(
        frame.first.image, plain,
        "the first pass is the plain frame"
    );
    // A refined pixel is the uniform passes' pixel, byte for byte; the
    // rest keep their first sample.
    for (i, &refined) in frame.refined.iter().enumerate() {
        let (x, y) = (i as u32 % w, i as u32 / w);
        let expected = if refined { &uniform } else { &plain };
        assert_eq!(
            frame.image.get_pixel(x, y),
            expected.get_pixel(x, y),
            "({x}, {y})"
        );
    }
    // The silhouettes are refined and the open floor is not: a few
    // pixels in ten.
    let share = frame.refined_fraction();
    eprintln!("{:.1}% of the pixels refined", 100.0 * share);
    assert!(share > 0.05 && share < 0.4, "{share}");
    let view = r.viewport(w, h).unwrap();
    let (ox, oy) = gpu::project(&view, dvec3(0.0, 0.0, 1.0));
    assert!(!frame.refined[(oy * w + ox) as usize], "the open floor");
    for i in 0..frame.refined.len() - 1 {
        if frame.first.hit[i] != frame.first.hit[i + 1] && (i + 1) % w as usize != 0 {
            assert!(
                frame.refined[i] && frame.refined[i + 1],
                "a silhouette at {i}"
            );
        }
    }
    // Closer to 8 uniform passes than the plain frame is, for a fraction
    // of the cost.
    assert!(psnr(&frame.image, &uniform) > psnr(&plain, &uniform) + 6.0);
    assert!(frame.mean_evaluations() < 0.6 * 8.0 * frame.first.mean_evaluations());
    // Bad pass counts are refused.
    let err = r
        .render_adaptive(w, h, 0, &EdgeThresholds::default())
        .unwrap_err();
    assert!(err.to_string().contains("adaptive passes"), "{err}");
    // Afterwards a frame is a frame of its own again.
    assert_eq!(r.render(w, h).unwrap(), plain);
    // With a resolution scale of 2 the mask is at the rendered size, and
    // the image at the asked one.
    let mut scaled = Renderer::new(&scene, quality.resolution_scale(2)).unwrap();
    let plain = scaled.render(w, h).unwrap();
    let frame = scaled
        .render_adaptive(w, h, 4, &EdgeThresholds::default())
        .unwrap();
    assert_eq!(frame.refined.len(), (w as usize / 2) * (h as usize / 2));
    assert_eq!(frame.first.image, plain);
    assert_eq!(frame.image.dimensions(), (w, h));
    assert_ne!(frame.image, plain);
    let share = frame.refined_fraction();
    assert!(share > 0.05 && share < 0.6, "{share}");
}

/// Motion blur by shutter samples: a ball that crosses the view during a
/// frame's open shutter smears along its path (it covers more pixels, none
/// of them as fully as the ball at rest), and one sample is the frame
/// without blur, exactly.
#[test]
fn a_moving_ball_blurs_over_the_open_shutter() {
    use fractal_sdf::animation::{CameraPath, Interpolation, Key, Keyframe, Motion};
    use fractal_sdf::sequence::{MotionBlur, Sequence};
    let Some(_) = gpu::device() else { return };
    let scene = Scene::new(sphere(0.3).translate(fractal_sdf::scene::param3("at", DVec3::ZERO)))
        .with_camera(Camera::look_at(dvec3(0.0, 0.0, 4.0), DVec3::ZERO));
    let keys = vec![
        Key::new(0.0, -1.5).interpolation(Interpolation::Linear),
        Key::new(1.0, 1.5),
    ];
    let motions = [Motion::Keys {
        name: "at.x".into(),
        keys,
    }];
    let (at, target) = (scene.camera.position, scene.camera.target);
    let path = CameraPath::new(vec![
        Keyframe::new(0.0, at, target),
        Keyframe::new(1.0, at, target),
    ])
    .unwrap();
    let dir = std::env::temp_dir().join(format!("fractal-sdf-blur-{}", std::process::id()));
    let options = gpu::options(gpu::plain(Quality::preview()), Effects::none());
    let frame = |blur: MotionBlur, name: &str| {
        let seq = Sequence::new(dir.join(name), 2.0, 2)
            .unwrap()
            .motion_blur(blur)
            .unwrap();
        let mut renderer = Renderer::with_options(&scene, &options).unwrap();
        seq.render(&mut renderer, &path, &motions, &[1], (64, 32), |_| {})
            .unwrap();
        image::open(seq.frame_path(1)).unwrap().to_rgba8()
    };
    let sharp = frame(MotionBlur::none(), "sharp");
    let blurred = frame(MotionBlur::new(16, 1.0), "blurred");
    // The background alone: the ball far out of view.
    let empty = {
        let mut renderer = Renderer::with_options(&scene, &options).unwrap();
        renderer.set_param("at.x", 100.0).unwrap();
        renderer.render(64, 32).unwrap()
    };
    let away = |image: &RgbaImage| -> Vec<u8> {
        image
            .pixels()
            .zip(empty.pixels())
            .map(|(p, q)| (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap())
            .collect()
    };
    let touched = |image: &RgbaImage| away(image).into_iter().filter(|&d| d > 8).count();
    let (sharp_count, blurred_count) = (touched(&sharp), touched(&blurred));
    // Over the half second the shutter is open the ball moves 1.5 units,
    // two and a half times its width.
    assert!(sharp_count > 20, "{sharp_count} pixels of the ball");
    assert!(
        blurred_count > 2 * sharp_count,
        "{blurred_count} against {sharp_count}"
    );
    // No pixel of the smear is as far from the background as the ball's
    // at rest.
    let far = |image: &RgbaImage| away(image).into_iter().max().unwrap();
    assert!(
        far(&blurred) < far(&sharp),
        "{} against {}",
        far(&blurred),
        far(&sharp)
    );
    // One sample is the frame without blur.
    let direct = {
        let mut renderer = Renderer::with_options(&scene, &options).unwrap();
        renderer.set_param("at.x", 0.0).unwrap();
        renderer.render(64, 32).unwrap()
    };
    assert_eq!(sharp, direct);
    for bad in [
        MotionBlur::new(0, 0.5),
        MotionBlur::new(4, 0.0),
        MotionBlur::new(4, 1.5),
    ] {
        assert!(
            Sequence::new(&dir, 2.0, 2)
                .unwrap()
                .motion_blur(bad)
                .is_err()
        );
    }
    // 256 moments of 8x8 samples are more than progressive rendering
    // holds: refused before a frame is rendered.
    let many = Sequence::new(dir.join("many"), 2.0, 2)
        .unwrap()
        .motion_blur(MotionBlur::new(256, 0.5))
        .unwrap();
    let fine = gpu::options(
        gpu::plain(Quality::preview().supersampling(8)),
        Effects::none(),
    );
    let mut renderer = Renderer::with_options(&scene, &fine).unwrap();
    let err = many
        .render(&mut renderer, &path, &motions, &[0], (8, 8), |_| {})
        .unwrap_err()
        .to_string();
    assert!(err.contains("at most 64 moments"), "{err}");
    assert!(!many.frame_path(0).exists());
    let _ = std::fs::remove_dir_all(&dir);
}
