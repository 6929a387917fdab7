//! Every `Quality` knob reaches the kernel and does what it says, and the
//! evaluation counter counts every distance evaluation.

mod gpu;

use fractal_sdf::prelude::*;
use fractal_sdf::render::{Frame, Renderer};

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
    Quality {
        ao_samples: 0,
        shadow_steps: 0,
        ..Quality::production()
    }
}

fn hits(f: &Frame) -> usize {
    f.hit.iter().filter(|&&h| h).count()
}

#[test]
fn evaluations_count_every_distance_call() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    // No effects: march steps, plus 4 for the normal, 1 to step onto the
    // surface and 1 for the colour on a hit.
    let f = frame(&scene, plain(), Effects::none());
    assert!(hits(&f) > 100);
    for i in 0..f.hit.len() {
        let extra = if f.hit[i] { 6 } else { 0 };
        assert_eq!(f.evaluations[i], f.steps[i] + extra, "pixel {i}");
    }
    // Occlusion adds its samples.
    let ao = Effects {
        shadows: false,
        ..Effects::default()
    };
    let f = frame(
        &scene,
        Quality {
            ao_samples: 3,
            ..plain()
        },
        ao,
    );
    for i in 0..f.hit.len() {
        let extra = if f.hit[i] { 9 } else { 0 };
        assert_eq!(f.evaluations[i], f.steps[i] + extra, "pixel {i}");
    }
    // Shadow rays add at most `shadow_steps` per light, and some add many.
    let shadow_steps = 40;
    let scene = scene.with_lights([gpu::sun(0.0)]);
    let shadows = Effects {
        ambient_occlusion: false,
        ..Effects::default()
    };
    let f = frame(
        &scene,
        Quality {
            shadow_steps,
            ..plain()
        },
        shadows,
    );
    let mut longest = 0;
    for i in 0..f.hit.len() {
        if f.hit[i] {
            let shadow = f.evaluations[i] - f.steps[i] - 6;
            assert!(shadow <= shadow_steps, "pixel {i}: {shadow}");
            longest = longest.max(shadow);
        } else {
            assert_eq!(f.evaluations[i], f.steps[i]);
        }
    }
    assert!(longest > 10, "{longest}");
    assert!(f.mean_evaluations() > f.mean_steps());
}

#[test]
fn max_steps_and_max_distance_end_rays() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let base = frame(&scene, plain(), Effects::none());
    let few = frame(
        &scene,
        Quality {
            max_steps: 3,
            ..plain()
        },
        Effects::none(),
    );
    assert!(few.steps.iter().all(|&s| s <= 3));
    assert!(
        hits(&few) < hits(&base) / 2,
        "{} vs {}",
        hits(&few),
        hits(&base)
    );
    // The camera is about 3.3 from the objects: a shorter reach sees only
    // the nearest floor.
    let near = frame(
        &scene,
        Quality {
            max_distance: 2.5,
            ..plain()
        },
        Effects::none(),
    );
    assert!(hits(&near) < hits(&base));
    for i in 0..near.hit.len() {
        if near.hit[i] {
            assert!(near.depth[i] <= 2.5, "pixel {i}: {}", near.depth[i]);
        }
    }
}

#[test]
fn hit_epsilon_stops_rays_that_many_pixels_short() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let fine = frame(&scene, plain(), Effects::none());
    let coarse = frame(
        &scene,
        Quality {
            hit_epsilon: 8.0,
            ..plain()
        },
        Effects::none(),
    );
    let (mut shorter, mut both) = (0, 0);
    for i in 0..fine.hit.len() {
        if fine.hit[i] && coarse.hit[i] {
            both += 1;
            let t = f64::from(fine.depth[i]);
            let gap = t - f64::from(coarse.depth[i]);
            // Never further than the fine march, never short by more than
            // the coarse threshold (along a grazing ray it can be more
            // than a threshold in depth, so count rather than bound).
            assert!(gap >= -1e-3 * t, "pixel {i}: {gap}");
            if gap > 0.0 {
                shorter += 1;
            }
        }
    }
    assert!(shorter * 2 > both, "{shorter} of {both}");
    assert!(coarse.mean_steps() < fine.mean_steps());
}

#[test]
fn normal_epsilon_blurs_edges() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let sharp = frame(&scene, plain(), Effects::none());
    let blurred = frame(
        &scene,
        Quality {
            normal_epsilon: 30.0,
            ..plain()
        },
        Effects::none(),
    );
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
    // The box's edges and the contact lines turn.
    assert!(changed > 20, "{changed}");
}

#[test]
fn fractal_iterations_override_every_fractal() {
    let Some(_) = gpu::device() else { return };
    let camera = Camera::look_at(dvec3(2.2, 1.6, 2.8), DVec3::ZERO).fov(40.0);
    let scene = |node: Node| Scene::new(node).with_camera(camera);
    let override_to = |n| Quality {
        fractal_iterations: Some(n),
        ..plain()
    };
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
    let three = frame(
        &scene,
        Quality {
            supersampling: 3,
            ..plain()
        },
        Effects::none(),
    );
    let ratio = three.mean_steps() / one.mean_steps();
    assert!((8.0..10.0).contains(&ratio), "{ratio}");
    assert_ne!(one.image, three.image);
    // The AOVs still describe the pixel centre.
    assert_eq!(one.hit, three.hit);
}
