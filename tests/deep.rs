//! Deep and wide scenes: nothing in the crate recurses on the depth of a
//! user's tree. Each test runs on a thread with a small stack, so a
//! recursive walk anywhere would overflow it.

mod gpu;

use fractal_sdf::codegen::{self, Options};
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
            assert!((eval.distance(p) - nearest).abs() < 1e-12, "at {p}");
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
        assert!((d - (2.0 - 20_000.0 * 1e-6)).abs() < 1e-9, "{d}");
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
    let mut renderer = Renderer::new(&scene, Quality::draft()).unwrap();
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
