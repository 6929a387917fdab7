//! The OpenCL marcher agrees with the CPU reference, ray for ray.

use crate::gpu;

use fractal_sdf::cpu::{self, Evaluator, Ray};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{Frame, Renderer};
use fractal_sdf::scene::Projection;

/// The ray through the centre of pixel `(x, y)` of a `w` x `h` image,
/// derived here from the camera's definition (a look-at frame with `up`
/// made orthogonal, rows from the top), not with the library's viewport.
fn pixel_ray(camera: &Camera, w: u32, h: u32, x: u32, y: u32) -> Ray {
    let forward = (camera.target - camera.position).normalize();
    let right = forward.cross(camera.up).normalize();
    let up = right.cross(forward);
    let aspect = f64::from(w) / f64::from(h);
    // -1..1 across the image, at the pixel's centre.
    let sx = 2.0 * (f64::from(x) + 0.5) / f64::from(w) - 1.0;
    let sy = 1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(h);
    match camera.projection {
        Projection::Perspective { fov_y_degrees } => {
            let half = (fov_y_degrees.to_radians() / 2.0).tan();
            Ray::new(
                camera.position,
                (forward + right * (sx * half * aspect) + up * (sy * half)).normalize(),
            )
        }
        Projection::Orthographic { height } => Ray::new(
            camera.position + right * (sx * height / 2.0 * aspect) + up * (sy * height / 2.0),
            forward,
        ),
        other => panic!("no reference ray for {other:?}"),
    }
}

/// Pixels whose hit, or depth where both hit, may disagree with the CPU
/// reference. Measured on PoCL: none, on 6,144 perspective and 4,800
/// orthographic F64 pixels, and none between plain and over-relaxed
/// marches. Two allow for a silhouette pixel where both marches end
/// within rounding of the hit threshold on another host.
const ALLOWED_MISMATCHES: usize = 2;

/// Compares a frame's hit mask and depth with `cpu::march` on the same rays
/// and thresholds; returns the pixels whose hit differs and the pixels
/// both hit whose depth differs.
fn compare(renderer: &Renderer, frame: &Frame, scene: &Scene) -> (usize, usize) {
    let (w, h) = (frame.width(), frame.height());
    let view = renderer.viewport(w, h).unwrap();
    let settings = view.march_settings(&renderer.options().quality);
    let eval = Evaluator::new(scene.geometry.as_ref().unwrap()).unwrap();
    let (mut hit_mismatches, mut depth_mismatches) = (0, 0);
    let mut worst = 0.0f64;
    for y in 0..h {
        for x in 0..w {
            let i = frame.index(x, y);
            let ray = pixel_ray(&scene.camera, w, h, x, y);
            let theirs = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            // The same ray from the same f64 inputs in another order of
            // operations: measured worst 8.9e-16 (origins) and 3.3e-16
            // (directions) over 10,944 pixels; the tolerance is about 10
            // and 30 times those.
            assert!(
                ray.origin.abs_diff_eq(theirs.origin, 1e-14)
                    && ray.direction.abs_diff_eq(theirs.direction, 1e-14),
                "pixel ({x}, {y}): {ray:?} from the camera, {theirs:?} from the viewport"
            );
            let reference = cpu::march(&eval, ray, &settings);
            if reference.hit != frame.hit[i] {
                hit_mismatches += 1;
            }
            if reference.hit && frame.hit[i] {
                let t = reference.depth;
                // Both marches locate the crossing to `hit_epsilon`
                // footprints; float rounding may change a step. Measured:
                // at most 0.73 of this (orthographic, F64: 0.85 of the
                // footprint term) and 0.0025 in the perspective F32 render.
                let tolerance = 1e-4 * t + view.footprint(t) * settings_eps(renderer);
                let error = (f64::from(frame.depth[i]) - t).abs();
                worst = worst.max(error / tolerance);
                if error > tolerance {
                    depth_mismatches += 1;
                }
            }
        }
    }
    eprintln!("largest depth error: {worst:.3} of the tolerance");
    (hit_mismatches, depth_mismatches)
}

fn settings_eps(renderer: &Renderer) -> f64 {
    renderer.options().quality.hit_epsilon
}

#[test]
fn hit_mask_and_depth_match_the_cpu_reference() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let quality = Quality::production();
    let mut renderer =
        Renderer::with_options(&scene, &gpu::options(quality, Effects::none())).unwrap();
    let frame = renderer.render_with_aovs(96, 64).unwrap();
    gpu::save("agreement_perspective", &frame.image);
    let (hits, depths) = compare(&renderer, &frame, &scene);
    eprintln!("disagreeing: {hits} hit masks, {depths} depths");
    assert_agreement(hits, depths);
    // Misses have infinite depth and no normal; hits a unit normal, to the
    // f32 `normalize`: measured worst 1.2e-7 (one f32 ulp) over 5,760
    // hits; the tolerance is about 80 times that, room for a GPU's
    // `normalize` a few ulps off.
    for i in 0..frame.hit.len() {
        let n = frame.normal[i];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if frame.hit[i] {
            assert!(
                frame.depth[i].is_finite() && (len - 1.0).abs() < 1e-5,
                "pixel {i}"
            );
        } else {
            assert!(frame.depth[i] == f32::INFINITY && len == 0.0, "pixel {i}");
        }
    }
}

#[test]
fn orthographic_and_f64_match_the_cpu_reference() {
    let Some(device) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let camera = Camera::look_at(dvec3(2.0, 2.5, 3.0), dvec3(0.0, 0.3, 0.0)).orthographic(3.0);
    let scene = scene.with_camera(camera);
    let mut quality = Quality::production();
    if gpu::fp64(&device) {
        quality.precision = Precision::F64;
    }
    let mut renderer =
        Renderer::with_options(&scene, &gpu::options(quality, Effects::none())).unwrap();
    let frame = renderer.render_with_aovs(80, 60).unwrap();
    gpu::save("agreement_orthographic", &frame.image);
    let (hits, depths) = compare(&renderer, &frame, &scene);
    eprintln!("disagreeing: {hits} hit masks, {depths} depths");
    assert_agreement(hits, depths);
    assert!(
        frame.coverage() > 0.99,
        "the floor fills the orthographic view"
    );
}

#[test]
fn over_relaxation_finds_the_same_surface_in_fewer_steps() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let frame = |over_relaxation: f64| {
        let quality = Quality::production().over_relaxation(over_relaxation);
        let mut r =
            Renderer::with_options(&scene, &gpu::options(quality, Effects::none())).unwrap();
        let f = r.render_with_aovs(96, 64).unwrap();
        (r, f)
    };
    let (renderer, plain) = frame(1.0);
    let (_, relaxed) = frame(1.6);
    // The same pixels hit, and each over-relaxed hit is located on the
    // surface the plain march found: both ends of both final brackets lie
    // within `hit_epsilon` footprints of the one crossing.
    let view = renderer.viewport(96, 64).unwrap();
    let eps = renderer.options().quality.hit_epsilon;
    let (mut same_hit, mut both, mut same_depth) = (0, 0, 0);
    for y in 0..64 {
        for x in 0..96 {
            let i = plain.index(x, y);
            same_hit += usize::from(plain.hit[i] == relaxed.hit[i]);
            if plain.hit[i] && relaxed.hit[i] {
                both += 1;
                let t = f64::from(plain.depth[i]);
                let gap = (f64::from(relaxed.depth[i]) - t).abs();
                // Measured: gaps at most 0.49 of the first term, so the
                // second, for the f32 depths' rounding (2^-24 t each), was
                // never needed.
                same_depth += usize::from(gap <= 2.0 * eps * view.footprint(t) + 1e-5 * t);
            }
        }
    }
    eprintln!("over-relaxed: {same_hit} same hits of 6144, {same_depth} of {both} same depths");
    assert_agreement(6144 - same_hit, both - same_depth);
    let mean =
        |f: &Frame| f.steps.iter().map(|&s| f64::from(s)).sum::<f64>() / f.steps.len() as f64;
    let (m1, m2) = (mean(&plain), mean(&relaxed));
    eprintln!("mean steps: {m1:.1} plain, {m2:.1} over-relaxed");
    assert!(m2 < m1, "over-relaxation saves steps: {m2} vs {m1}");
}

// A renderer can move to another thread: checked when this file compiles,
// not counted as a test.
const _: fn() = || {
    fn send<T: Send>() {}
    send::<Renderer>();
};

/// At most [`ALLOWED_MISMATCHES`] hit masks, and depths where both hit,
/// disagree.
fn assert_agreement(hits: usize, depths: usize) {
    assert!(
        hits <= ALLOWED_MISMATCHES,
        "{hits} hit masks disagree (at most {ALLOWED_MISMATCHES} may)"
    );
    assert!(
        depths <= ALLOWED_MISMATCHES,
        "{depths} depths disagree where both hit (at most {ALLOWED_MISMATCHES} may)"
    );
}

/// With supersampling the colour samples are jittered, but the AOVs trace
/// the pixel's centre: the same depth, hit and normal as one sample per
/// pixel, bit for bit (the same ray through the same program).
#[test]
fn supersampled_aovs_trace_the_pixel_centre() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let frame = |supersampling: u32| {
        let quality = Quality::production().supersampling(supersampling);
        let mut r =
            Renderer::with_options(&scene, &gpu::options(quality, Effects::none())).unwrap();
        r.render_with_aovs(48, 32).unwrap()
    };
    let (one, four) = (frame(1), frame(2));
    let differ = |a: &[f32], b: &[f32]| {
        a.iter()
            .zip(b)
            .filter(|(x, y)| x.to_bits() != y.to_bits())
            .count()
    };
    assert!(one.hit == four.hit, "hit masks differ");
    assert_eq!(
        differ(&one.depth, &four.depth),
        0,
        "pixels whose depth differs"
    );
    let (n1, n4): (Vec<f32>, Vec<f32>) = (one.normal.concat(), four.normal.concat());
    assert_eq!(differ(&n1, &n4), 0, "normal components that differ");
    // The colours differ: the jittered samples smooth the edges.
    assert_ne!(one.image, four.image);
}
