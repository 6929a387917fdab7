//! Every `Quality` knob reaches the kernel and does what it says, and the
//! evaluation counter counts every distance evaluation.

use crate::gpu;

use fractal_sdf::cpu::Evaluator;
use fractal_sdf::prelude::*;
use fractal_sdf::render::{Frame, Renderer};
use fractal_sdf::scene::Mandelbulb;

const W: u32 = 96;
const H: u32 = 64;

fn frame(scene: &Scene, quality: Quality, effects: Effects) -> Frame {
    Renderer::with_options(scene, &gpu::options(quality, effects))
        .unwrap()
        .render_with_aovs(W, H)
        .unwrap()
}

/// Plain sphere tracing, no effects: the baseline the cases vary.
fn plain() -> Quality {
    Quality::production().ao_samples(0).shadow_steps(0)
}

fn hits(f: &Frame) -> usize {
    f.hit.iter().filter(|&&h| h).count()
}

#[test]
fn evaluations_count_every_distance_call() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    // No effects: march steps (with the refinement of the hit), plus 4 for
    // the normal and 1 for the colour on a hit.
    let f = frame(&scene, plain(), Effects::none());
    // Measured: 5,760 of the 6,144 pixels hit.
    assert!(hits(&f) > 100);
    for i in 0..f.hit.len() {
        let extra = if f.hit[i] { 5 } else { 0 };
        assert_eq!(f.evaluations[i], f.steps[i] + extra, "pixel {i}");
    }
    // Occlusion adds its samples.
    let ao = Effects::default().shadows(false);
    let f = frame(&scene, plain().ao_samples(3), ao);
    for i in 0..f.hit.len() {
        let extra = if f.hit[i] { 8 } else { 0 };
        assert_eq!(f.evaluations[i], f.steps[i] + extra, "pixel {i}");
    }
    // Shadow rays add at most `shadow_steps` per light, and some add many.
    let shadow_steps = 40;
    let scene = scene.with_lights([gpu::sun(0.0)]);
    let shadows = Effects::default().ambient_occlusion(false);
    let f = frame(&scene, plain().shadow_steps(shadow_steps), shadows);
    let mut longest = 0;
    for i in 0..f.hit.len() {
        if f.hit[i] {
            let shadow = f.evaluations[i] - f.steps[i] - 5;
            assert!(shadow <= shadow_steps, "pixel {i}: {shadow}");
            longest = longest.max(shadow);
        } else {
            assert_eq!(f.evaluations[i], f.steps[i]);
        }
    }
    // Measured: the longest shadow ray takes all 40 steps.
    assert!(longest > 10, "{longest}");
    assert!(f.mean_evaluations() > f.mean_steps());
}

#[test]
fn max_steps_and_max_distance_end_rays() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let base = frame(&scene, plain(), Effects::none());
    let few = frame(&scene, plain().max_steps(3), Effects::none());
    // Measured: no pixel hits within 3 steps (5,760 without the limit),
    // and 460 within 2.5 units.
    assert!(few.steps.iter().all(|&s| s <= 3));
    assert!(
        hits(&few) < hits(&base) / 2,
        "{} vs {}",
        hits(&few),
        hits(&base)
    );
    // The camera is about 3.3 from the objects: a shorter reach sees only
    // the nearest floor.
    let near = frame(&scene, plain().max_distance(2.5), Effects::none());
    assert!(hits(&near) < hits(&base));
    for i in 0..near.hit.len() {
        if near.hit[i] {
            assert!(near.depth[i] <= 2.5, "pixel {i}: {}", near.depth[i]);
        }
    }
}

/// For every pixel that hits, the exact distance at the hit over the
/// pixel footprint there, in pixels: where on the detail surface the hit
/// was located.
/// Also returns the growth of the footprint per unit of depth.
fn hit_offsets(scene: &Scene, quality: Quality) -> (Frame, Vec<f64>, f64) {
    let mut renderer =
        Renderer::with_options(scene, &gpu::options(quality, Effects::none())).unwrap();
    let frame = renderer.render_with_aovs(W, H).unwrap();
    let view = renderer.viewport(W, H).unwrap();
    let eval = Evaluator::new(scene.geometry.as_ref().unwrap()).unwrap();
    let mut offsets = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let i = frame.index(x, y);
            if frame.hit[i] {
                let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let t = f64::from(frame.depth[i]);
                offsets.push(eval.distance(ray.origin + ray.direction * t) / view.footprint(t));
            }
        }
    }
    let per_unit = view.footprint(1.0) - view.footprint(0.0);
    (frame, offsets, per_unit)
}

#[test]
fn detail_sets_the_surface_and_hit_epsilon_how_closely_hits_find_it() {
    let Some(_) = gpu::device() else { return };
    // Exact distances: a hit at depth t lies `detail` footprints from the
    // surface, less at most `hit_epsilon` (the located crossing is the
    // inside end of a bracket that narrow along the ray, and the distance
    // to the detail surface changes no faster than `lipschitz` times the
    // distance moved).
    let scene = gpu::sphere_box_floor();
    for (detail, hit_epsilon) in [(0.5, 0.01), (0.5, 0.4), (6.0, 0.05), (6.0, 3.0)] {
        let quality = plain().detail(detail).hit_epsilon(hit_epsilon);
        let (frame, offsets, per_unit) = hit_offsets(&scene, quality);
        let lipschitz = 1.0 + detail * per_unit;
        assert!(offsets.len() > 3000, "{} hits", offsets.len());
        // Depths are f32: allow their rounding, a thousandth of a pixel.
        // The rounding, 2^-24 of the depth over a footprint of about an
        // 88th of it (40 degrees over 64 rows), is 5e-6 pixels: measured,
        // the offsets went past `detail` by at most 6.5e-6 pixels (and
        // never below the lower bound) over 23,808 hits in the 4 cases;
        // the slack is about 150 times that.
        let far = frame
            .depth
            .iter()
            .filter(|d| d.is_finite())
            .fold(0.0f32, |a, &d| a.max(d));
        let slack = 1e-3 + 1e-6 * f64::from(far);
        let (lo, hi) = offsets
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), &o| {
                (lo.min(o), hi.max(o))
            });
        eprintln!("detail {detail}, hit_epsilon {hit_epsilon}: offsets {lo:.4} to {hi:.4} px");
        assert!(hi <= detail + slack, "{hi} > {detail}");
        assert!(
            lo >= detail - lipschitz * hit_epsilon - slack,
            "{lo} < {detail} - {hit_epsilon}"
        );
    }
}

#[test]
fn a_coarser_hit_epsilon_takes_fewer_steps_to_the_same_surface() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let fine = frame(&scene, plain().hit_epsilon(0.001), Effects::none());
    let coarse = frame(&scene, plain().hit_epsilon(0.5), Effects::none());
    assert_eq!(fine.hit, coarse.hit);
    // Measured: the coarse march takes 0.45 of the fine one's steps.
    assert!(
        coarse.mean_steps() < 0.9 * fine.mean_steps(),
        "{} vs {}",
        coarse.mean_steps(),
        fine.mean_steps()
    );
}

#[test]
fn normal_epsilon_blurs_edges() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let sharp = frame(&scene, plain(), Effects::none());
    let blurred = frame(&scene, plain().normal_epsilon(30.0), Effects::none());
    let mut changed = 0;
    for i in 0..sharp.hit.len() {
        if sharp.hit[i] && blurred.hit[i] {
            let (a, b) = (sharp.normal[i], blurred.normal[i]);
            let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            if dot < 0.99 {
                changed += 1;
            }
        }
    }
    // The box's edges and the contact lines turn: measured 2,802 pixels'
    // normals turned by more than 8 degrees.
    assert!(changed > 20, "{changed}");
}

#[test]
fn fractal_iterations_override_every_fractal() {
    let Some(_) = gpu::device() else { return };
    let camera = Camera::look_at(dvec3(2.2, 1.6, 2.8), DVec3::ZERO).fov(40.0);
    let scene = |node: Node| Scene::new(node).with_camera(camera);
    let override_to = |n| plain().fractal_iterations(Some(n));
    let bulb = |n| Node::from(Mandelbulb::new(8.0).iterations(n));
    let both = |n| menger(n).union(bulb(n).translate(dvec3(0.0, 1.2, 0.0)));
    let overridden = frame(&scene(both(4)), override_to(2), Effects::none());
    let own = frame(&scene(both(2)), plain(), Effects::none());
    let deep = frame(&scene(both(4)), plain(), Effects::none());
    assert_eq!(overridden.image, own.image);
    assert_ne!(overridden.image, deep.image);
}

#[test]
fn supersampling_traces_n_by_n_samples() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let one = frame(&scene, plain(), Effects::none());
    let three = frame(&scene, plain().supersampling(3), Effects::none());
    // Nine samples a pixel: measured 9.09 times the steps.
    let ratio = three.mean_steps() / one.mean_steps();
    assert!((8.0..10.0).contains(&ratio), "{ratio}");
    assert_ne!(one.image, three.image);
    // The AOVs still describe the pixel centre.
    assert_eq!(one.hit, three.hit);
}
