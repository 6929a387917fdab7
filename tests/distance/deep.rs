//! Deep and wide scenes: nothing in the crate recurses on the depth of a
//! user's tree. Each test runs on a thread with a small stack, so a
//! recursive walk anywhere would overflow it.

use crate::gpu;

use fractal_sdf::codegen::{self, Options};
use fractal_sdf::cpu;
use fractal_sdf::prelude::*;
use fractal_sdf::render::Renderer;

/// Runs `f` on a thread with a 256 KiB stack.
fn small_stack(f: impl FnOnce() + Send + 'static) {
    std::thread::Builder::new()
        .stack_size(256 << 10)
        .spawn(f)
        .unwrap()
        .join()
        .unwrap();
}

/// A sphere of radius 0.01 at each of `n` points of a grid in [-1, 1]^3,
/// added one by one: a left-deep union chain `n` levels deep.
fn many_spheres(n: usize) -> (Scene, Vec<DVec3>) {
    let side = (1..).find(|s| s * s * s >= n).unwrap();
    let mut scene = Scene::empty();
    let mut centres = Vec::with_capacity(n);
    #[allow(clippy::cast_precision_loss)]
    for i in 0..n {
        let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
        let c = dvec3(x as f64, y as f64, z as f64) / side as f64 * 2.0 - 1.0;
        centres.push(c);
        scene = scene.add(sphere(0.01).translate(c));
    }
    (scene, centres)
}

#[test]
fn a_hundred_thousand_added_nodes_compile_and_evaluate() {
    small_stack(|| {
        let (scene, centres) = many_spheres(100_000);
        let (size, depth) = scene.geometry.as_ref().unwrap().size_and_depth();
        assert_eq!((size, depth), (299_999, 100_001));
        let compiled = scene.compile().unwrap();
        let source = codegen::emit(&compiled, &Options::default()).unwrap();
        assert!(source.source.contains("sd_sphere"));
        let eval = cpu::Evaluator::from_compiled(&compiled);
        for p in [
            dvec3(0.0, 0.0, 3.0),
            dvec3(0.31, -0.7, 0.05),
            centres[77_777],
        ] {
            let nearest = centres
                .iter()
                .map(|c| (p - *c).length() - 0.01)
                .fold(f64::INFINITY, f64::min);
            // The same f64 operations (a difference, a length, a
            // subtraction, a minimum): exact up to a rounding, measured 0
            // at these 3 points; the tolerance is about 20 ulps of 3.
            assert!((eval.distance(p) - nearest).abs() < 1e-14, "at {p}");
        }
        // Comparing, cloning, printing and dropping the tree.
        let twin = many_spheres(100_000).0;
        assert_eq!(scene, twin);
        assert_ne!(scene, many_spheres(99_999).0);
        let text = format!("{:?}", scene.geometry.as_ref().unwrap());
        assert!(
            text.contains("depth: 100001"),
            "{}",
            &text[..text.len().min(200)]
        );
        drop(scene.clone());
        drop((scene, twin));
    });
}

#[test]
fn a_million_deep_chain_is_built_compared_and_dropped() {
    small_stack(|| {
        let chain = |n: usize| (0..n).fold(sphere(1.0), |node, _| node.round(1e-6));
        let deep = chain(1_000_000);
        assert_eq!(deep.size_and_depth(), (1_000_001, 1_000_001));
        assert_eq!(deep, deep.clone());
        assert_eq!(deep, chain(1_000_000));
        assert_ne!(deep, chain(999_999));
        let text = format!("{deep:?}");
        assert!(text.starts_with("Node { kind: \"round\""), "{text}");
        // Lowering, evaluation and code generation of a shorter chain.
        let node = chain(20_000);
        let eval = cpu::Evaluator::new(&node).unwrap();
        let d = eval.distance(dvec3(3.0, 0.0, 0.0));
        // 20,000 subtractions of 1e-6 from a value near 2, each rounded
        // by at most half an ulp (2.2e-16): at most 4.4e-12 off, measured
        // 1.6e-12. The tolerance is about 6 times the measurement.
        assert!((d - (2.0 - 20_000.0 * 1e-6)).abs() < 1e-11, "{d}");
        let compiled = Scene::new(node).compile().unwrap();
        codegen::emit(&compiled, &Options::default()).unwrap();
    });
}

#[test]
fn a_deep_scene_renders_as_the_cpu_reference_draws_it() {
    let Some(_) = gpu::device() else { return };
    // 150 nested transforms and booleans around two spheres.
    let mut node = sphere(0.5);
    for i in 0..150 {
        let step = if i % 2 == 0 { 0.002 } else { -0.002 };
        node = node
            .translate(dvec3(step, 0.0, 0.0))
            .union(sphere(0.05).translate(dvec3(0.0, -2.0, 0.0)))
            .round(1e-4);
    }
    let scene = Scene::new(node).with_camera(Camera::look_at(dvec3(0.0, 0.0, 3.0), DVec3::ZERO));
    let (w, h) = (12, 8);
    let mut renderer = Renderer::new(&scene, gpu::plain(Quality::draft())).unwrap();
    let frame = renderer.render_with_aovs(w, h).unwrap();
    let view = renderer.viewport(w, h).unwrap();
    let settings = view.march_settings(&renderer.options().quality);
    let eval = cpu::Evaluator::new(scene.geometry.as_ref().unwrap()).unwrap();
    for y in 0..h {
        for x in 0..w {
            let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let cpu_hit = cpu::march(&eval, ray, &settings).hit;
            assert_eq!(frame.hit[(y * w + x) as usize], cpu_hit, "pixel ({x}, {y})");
        }
    }
    assert!(frame.hit.iter().any(|&h| h) && frame.hit.iter().any(|&h| !h));
}

/// Where `ray` first comes within `r + a + b t` of any of `centres`, in
/// closed form: the spheres of radius `r` as the marcher draws them, a
/// surface `a + b t` thick (its `detail` times the pixel's footprint
/// `base + per_unit t` at distance `t`). That is the root of
/// `|oc + t u|^2 = (r + a + b t)^2`, a quadratic in `t`.
fn first_intersection(ray: cpu::Ray, centres: &[DVec3], r: f64, a: f64, b: f64) -> Option<f64> {
    centres
        .iter()
        .filter_map(|c| {
            let oc = ray.origin - *c;
            let (ra, u) = (r + a, ray.direction);
            let qa = 1.0 - b * b;
            let qb = oc.dot(u) - ra * b;
            let qc = oc.length_squared() - ra * ra;
            let disc = qb * qb - qa * qc;
            (disc >= 0.0)
                .then(|| (-qb - disc.sqrt()) / qa)
                .filter(|&t| t > 0.0)
        })
        .min_by(f64::total_cmp)
}

#[test]
fn a_hundred_thousand_added_spheres_render() {
    let Some(_) = gpu::device() else { return };
    let (scene, centres) = many_spheres(100_000);
    let scene = scene.with_camera(Camera::look_at(dvec3(2.2, 1.7, 2.9), DVec3::ZERO));
    let compiled = scene.compile().unwrap();
    // One loop, not 100,000 copies of the sphere's code (which would be
    // megabytes): the program is about the size of the marcher itself.
    let source = codegen::emit(&compiled, &Options::default()).unwrap();
    assert!(
        source.source.len() < 56_000,
        "{} bytes",
        source.source.len()
    );
    // The table: four values and a place per sphere, then the nodes of a
    // hierarchy over them (32 values each: four boxes and their contents;
    // with up to eight spheres a leaf, fewer nodes than a tenth of the
    // spheres).
    let nodes = (source.constants.len() - 5 * 100_000) / 32;
    assert_eq!(source.constants.len(), 5 * 100_000 + 32 * nodes);
    assert!(
        (100_000 / 32..100_000 / 10).contains(&nodes),
        "{nodes} nodes"
    );
    let quality = gpu::plain(Quality::draft());
    let options = gpu::options(quality, Effects::none());
    let mut renderer = Renderer::from_compiled(compiled, &options).unwrap();
    let (w, h) = (16, 12);
    let frame = renderer.render_with_aovs(w, h).unwrap();
    // Each pixel against the spheres themselves, in closed form: the same
    // first surface where both find one. Where they disagree (a grazing
    // ray the march steps past, or one that runs out of steps), the pixel
    // must be what the CPU reference's march draws.
    let view = renderer.viewport(w, h).unwrap();
    let settings = view.march_settings(&renderer.options().quality);
    let eval = cpu::Evaluator::new(scene.geometry.as_ref().unwrap()).unwrap();
    let eps = quality.hit_epsilon;
    let (base, per_unit) = (
        view.footprint(0.0),
        view.footprint(1.0) - view.footprint(0.0),
    );
    let (a, b) = (quality.detail * base, quality.detail * per_unit);
    let (mut hits, mut referred) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let i = frame.index(x, y);
            let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let exact = first_intersection(ray, &centres, 0.01, a, b);
            match (frame.hit[i], exact) {
                (true, Some(t)) => {
                    hits += 1;
                    let error = (f64::from(frame.depth[i]) - t).abs();
                    assert!(
                        error <= 2.0 * eps * view.footprint(t) + 1e-4 * t,
                        "pixel ({x}, {y}): {} vs {t}",
                        frame.depth[i]
                    );
                }
                (false, None) => {}
                (hit, _) => {
                    referred += 1;
                    let reference = cpu::march(&eval, ray, &settings);
                    assert_eq!(
                        hit, reference.hit,
                        "pixel ({x}, {y}): {exact:?}, {reference:?}"
                    );
                }
            }
        }
    }
    eprintln!(
        "{hits} hits, {referred} pixels checked against cpu::march, of {}",
        w * h
    );
    assert!(hits > 0);
}

#[test]
fn instanced_spheres_keep_their_table_when_a_parameter_changes() {
    let Some(_) = gpu::device() else { return };
    // 48 instanced spheres whose radius is a dynamic parameter, and one
    // sphere written out.
    let mut scene = Scene::new(sphere(0.3));
    for i in 0..48 {
        let t = f64::from(i) / 48.0 * std::f64::consts::TAU;
        scene = scene.add(sphere(param("r", 0.1)).translate(dvec3(t.cos(), t.sin(), 0.0)));
    }
    let scene = scene.with_camera(Camera::look_at(dvec3(0.0, 0.0, 4.0), DVec3::ZERO));
    let options = gpu::options(gpu::plain(Quality::draft()), Effects::none());
    let mut renderer = Renderer::with_options(&scene, &options).unwrap();
    let (w, h) = (24, 16);
    for r in [0.1, 0.25, 0.05] {
        renderer.set_param("r", r).unwrap();
        let frame = renderer.render_with_aovs(w, h).unwrap();
        let view = renderer.viewport(w, h).unwrap();
        let settings = view.march_settings(&renderer.options().quality);
        let mut eval = cpu::Evaluator::new(scene.geometry.as_ref().unwrap()).unwrap();
        eval.set_param("r", r).unwrap();
        let mut disagree = 0;
        for y in 0..h {
            for x in 0..w {
                let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
                disagree += usize::from(
                    cpu::march(&eval, ray, &settings).hit != frame.hit[frame.index(x, y)],
                );
            }
        }
        // Measured: none.
        assert_eq!(disagree, 0, "r = {r}");
    }
}
