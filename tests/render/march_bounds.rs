//! The march stops past the scene's bounding sphere: the same hits at the
//! same depths, the same image without glow (and within half a step of an
//! 8-bit pixel's glow with it), in fewer steps.

use crate::gpu;

use fractal_sdf::gallery;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Glow;
use fractal_sdf::render::{Frame, Renderer};

/// The scene with a plane far below it, beyond the largest distance a ray
/// travels: the same distances wherever a ray goes, but no bound, so the
/// program marches every ray as it did before rays stopped at the bound.
fn unbounded(scene: &Scene) -> Scene {
    let mut scene = scene.clone();
    let far = plane(DVec3::Y, 1e4);
    scene.geometry = scene.geometry.map(|g| g.union(far));
    scene
}

fn render(scene: &Scene, effects: Effects) -> (Frame, String) {
    let mut quality = gpu::plain(Quality::preview());
    quality.supersampling = 1;
    let mut renderer = Renderer::with_options(scene, &gpu::options(quality, effects)).unwrap();
    let frame = renderer.render_with_aovs(72, 54).unwrap();
    (frame, renderer.source().source.clone())
}

fn total_steps(frame: &Frame) -> u64 {
    frame.steps.iter().map(|&s| u64::from(s)).sum()
}

#[test]
fn rays_stop_past_the_scene_bound_with_the_same_hits() {
    let Some(_) = gpu::device() else { return };
    for name in ["mandelbulb", "julia"] {
        let scene = gallery::by_name(name).unwrap();
        let glow = Effects::default().glow(Glow::new(dvec3(0.6, 0.75, 1.0), 0.6));
        for (effects, what) in [(Effects::default(), "no glow"), (glow, "glow")] {
            let (bounded, source) = render(&scene, effects);
            assert!(source.contains("#define SCENE_BOUND_RADIUS"), "{name}");
            let (full, source) = render(&unbounded(&scene), effects);
            assert!(!source.contains("#define SCENE_BOUND_RADIUS"), "{name}");
            gpu::save(
                &format!("bound_{name}_{}", what.replace(' ', "_")),
                &bounded.image,
            );
            assert_eq!(bounded.hit, full.hit, "{name}, {what}: hit masks");
            for (i, (a, b)) in bounded.depth.iter().zip(&full.depth).enumerate() {
                assert!(
                    a.to_bits() == b.to_bits(),
                    "{name}, {what}: depth at {i}: {a} vs {b}"
                );
            }
            let (a, b) = (total_steps(&bounded), total_steps(&full));
            eprintln!("{name}, {what}: {a} steps with the bound, {b} without");
            assert!(a < b, "{name}, {what}: the bound saves steps ({a} vs {b})");
            // Glow: each channel within one 8-bit step (half a step of
            // linear light, at most one after the gamma); without glow the
            // same bytes.
            let worst = bounded
                .image
                .as_raw()
                .iter()
                .zip(full.image.as_raw())
                .map(|(&x, &y)| x.abs_diff(y))
                .max()
                .unwrap();
            let allowed = if what == "glow" { 1 } else { 0 };
            assert!(
                worst <= allowed,
                "{name}, {what}: a channel differs by {worst}"
            );
        }
    }
}

/// The coarse pass starts rays late but never past their first surface:
/// on every gallery scene, with cones over 4 × 4 and 16 × 16 pixel tiles,
/// every ray starts before the surface the plain march finds (to the
/// precision it locates crossings), and in all they take fewer primary
/// steps. The hit masks agree but where the later start changes which thin
/// feature a ray meets (the shortest step is `hit_epsilon` footprints,
/// and fractal estimates can overestimate a little): measured on PoCL, 1
/// pixel of the 18 renders of 3,072 pixels.
#[test]
fn the_coarse_pass_never_starts_a_ray_past_its_surface() {
    let Some(_) = gpu::device() else { return };
    let mut quality = gpu::plain(Quality::preview());
    quality.supersampling = 1;
    let (w, h) = (64, 48);
    let mut differ = 0;
    for (name, scene) in gallery::all() {
        let mut renderer =
            Renderer::with_options(&scene, &gpu::options(quality, Effects::default())).unwrap();
        let plain = renderer.render_with_aovs(w, h).unwrap();
        assert!(plain.start.iter().all(|&s| s == 0.0));
        for side in [4, 16] {
            renderer.set_quality(quality.cone_tile(side)).unwrap();
            if renderer.source().brute {
                // A cone cannot see a set without a distance: programs
                // that march one by brute force have no coarse pass.
                assert!(!renderer.source().source.contains("cone_starts("));
                assert!(
                    renderer
                        .render_with_aovs(w, h)
                        .unwrap()
                        .start
                        .iter()
                        .all(|&s| s == 0.0)
                );
                continue;
            }
            assert!(
                renderer
                    .source()
                    .source
                    .contains("__kernel void cone_starts")
            );
            let coarse = renderer.render_with_aovs(w, h).unwrap();
            gpu::save(&format!("cone_{name}_{side}"), &coarse.image);
            let view = renderer.viewport(w, h).unwrap();
            let mut late = 0;
            for i in 0..plain.hit.len() {
                differ += usize::from(plain.hit[i] != coarse.hit[i]);
                let start = f64::from(coarse.start[i]);
                late += usize::from(start > 0.0);
                if plain.hit[i] {
                    let t = f64::from(plain.depth[i]);
                    let tolerance = 1e-4 * t + quality.hit_epsilon * view.footprint(t);
                    assert!(
                        start <= t + tolerance,
                        "{name}, tiles of {side}, pixel {i}: starts at {start}, surface at {t}"
                    );
                }
            }
            let (a, b) = (total_steps(&coarse), total_steps(&plain));
            eprintln!(
                "{name}, tiles of {side}: {a} primary steps, {b} without the coarse pass; \
                 {late} of {} rays start late",
                plain.hit.len()
            );
            assert!(late > 0, "{name}, tiles of {side}: no ray starts late");
            assert!(
                a <= b + b / 100,
                "{name}, tiles of {side}: {a} vs {b} steps"
            );
        }
    }
    eprintln!("{differ} pixels whose hit differs");
    assert!(differ <= 12, "{differ} pixels whose hit differs");
}
