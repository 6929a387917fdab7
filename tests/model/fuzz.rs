//! Whole-pipeline fuzzing: random valid scenes go through validation, code
//! generation, an OpenCL build and a tiny render without a panic, a build
//! failure or a NaN; random invalid inputs always give a typed error.
//!
//! `make test` runs 64 scenes; set `FUZZ_CASES` for more
//! (`FUZZ_CASES=2000 cargo test --release --features proptest --test model fuzz`).

use crate::gpu;

use fractal_sdf::prelude::*;
use fractal_sdf::quality::Glow;
use fractal_sdf::render::Renderer;
use fractal_sdf::scene::Mandelbulb;
use fractal_sdf::scene::Menger;
use fractal_sdf::scene::QuaternionJulia;
use fractal_sdf::scene::Sierpinski;
use fractal_sdf::testing::scene_node;
use proptest::prelude::*;
use proptest::test_runner::{Config, FileFailurePersistence, TestRunner};

fn cases(default: u32) -> u32 {
    std::env::var("FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

#[test]
fn random_scenes_build_and_render_without_nan() {
    if gpu::device().is_none() {
        return;
    }
    let mut runner = TestRunner::new(Config {
        cases: cases(64),
        // A failing scene is kept, and tried first on every later run.
        failure_persistence: Some(Box::new(FileFailurePersistence::Direct(
            "tests/model/fuzz.proptest-regressions",
        ))),
        source_file: Some(file!()),
        ..Config::default()
    });
    let effects = Effects::default()
        .glow(Some(Glow::new(dvec3(1.0, 0.8, 0.5), 1.0)))
        .fog_density(0.05);
    let options = fractal_sdf::render::RenderOptions::default()
        .quality(Quality::draft())
        .effects(effects);
    runner
        .run(&scene_node(3), |node| {
            let scene = Scene::new(node)
                .with_camera(Camera::look_at(dvec3(2.5, 1.5, 3.0), DVec3::ZERO).fov(50.0));
            let mut renderer = Renderer::with_options(&scene, &options)
                .map_err(|e| TestCaseError::fail(format!("{e}")))?;
            let frame = renderer
                .render_with_aovs(16, 12)
                .map_err(|e| TestCaseError::fail(format!("{e}")))?;
            for i in 0..frame.hit.len() {
                let n = frame.normal[i];
                prop_assert!(n.iter().all(|c| c.is_finite()), "normal {:?} at {}", n, i);
                if frame.hit[i] {
                    prop_assert!(frame.depth[i].is_finite() && frame.depth[i] >= 0.0);
                    // The kernel's f32 `normalize`: measured worst 1.2e-7
                    // (one f32 ulp) over 7,963 normals (PROPTEST_RNG_SEED=
                    // 20261201; 1.8e-7 in three other seeds, on PoCL). The
                    // tolerance is about 55 times the larger, room for a
                    // GPU's `normalize` a few ulps off.
                    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                    prop_assert!((len - 1.0).abs() < 1e-5, "normal length {} at {}", len, i);
                }
            }
            Ok(())
        })
        .unwrap();
}

/// A number that may well be invalid somewhere.
fn wild() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(-1.0),
        Just(0.0),
        Just(1e300),
        Just(-1e-300),
        -10.0..10.0f64,
    ]
}

proptest! {
    /// Every node type with a wild value: validation either accepts it
    /// (when the value happens to be allowed) or returns a typed error;
    /// nothing panics, and NaN or infinite values are always refused.
    #[test]
    fn wild_values_give_typed_errors(v in wild(), which in 0usize..14, n in 0u32..400) {
        let node = match which {
            0 => sphere(v),
            1 => cuboid(dvec3(1.0, v, 1.0)),
            2 => torus(1.0, v),
            3 => capsule(DVec3::ZERO, dvec3(0.0, v, 0.0), 0.2),
            4 => plane(dvec3(v, 0.0, 0.0), 0.0),
            5 => Mandelbulb::new(v).iterations(n).into(),
            6 => Menger::new(n).scale(v).into(),
            7 => QuaternionJulia::new([v.into(), 0.0.into(), 0.0.into(), 0.0.into()]).iterations(n).into(),
            8 => Sierpinski::new(n).scale(v).into(),
            9 => sphere(1.0).smooth_union(sphere(0.5), v),
            10 => sphere(1.0).scale(v),
            11 => sphere(1.0).rotate(dvec3(v, 0.0, 0.0), 1.0),
            12 => sphere(1.0).twist(v),
            _ => sphere(1.0).color(dvec3(v, 0.5, 0.5)),
        };
        let result = Scene::new(node).validate();
        if !v.is_finite() {
            prop_assert!(
                matches!(result, Err(Error::NonFinite { .. } | Error::Iterations { .. })),
                "{:?}", result
            );
        }
        if let Err(e) = result {
            prop_assert!(!e.to_string().is_empty());
            prop_assert!(matches!(
                e,
                Error::NonFinite { .. }
                    | Error::OutOfRange { .. }
                    | Error::Iterations { .. }
                    | Error::ZeroVector { .. }
                    | Error::Precision { .. }
            ), "{}", e);
        }
    }

    /// Wild cameras and resolutions are refused with typed errors too.
    #[test]
    fn wild_cameras_give_typed_errors(v in wild(), fov in wild()) {
        let camera = Camera::look_at(dvec3(0.0, 0.0, v), DVec3::ZERO).fov(fov);
        match Scene::new(sphere(1.0)).with_camera(camera).validate() {
            Ok(()) => prop_assert!(v.is_finite() && v != 0.0 && fov > 0.0 && fov < 180.0),
            Err(e) => prop_assert!(matches!(e, Error::Camera { .. } | Error::Precision { .. }), "{}", e),
        }
    }
}

/// Random valid scenes (of every node kind the strategy builds, without
/// inside shapes) print as WGSL that parses and validates as a WebGPU
/// implementation reads it (naga), for rendering and for evaluation.
#[test]
fn random_scenes_print_as_valid_wgsl() {
    use fractal_sdf::codegen::{self, Options, Target};
    let mut runner = TestRunner::new(Config {
        cases: cases(64),
        failure_persistence: None,
        ..Config::default()
    });
    runner
        .run(&scene_node(3), |node| {
            let scene = Scene::new(node).compile().expect("valid scenes compile");
            for target in [Target::Render, Target::Evaluate] {
                let options = Options::default().target(target);
                let module = codegen::emit_wgsl(&scene, &options)
                    .map_err(|e| TestCaseError::fail(e.to_string()))?;
                let source = &module.source;
                let parsed = naga::front::wgsl::parse_str(source)
                    .map_err(|e| TestCaseError::fail(e.emit_to_string(source)))?;
                naga::valid::Validator::new(
                    naga::valid::ValidationFlags::all(),
                    naga::valid::Capabilities::empty(),
                )
                .validate(&parsed)
                .map_err(|e| TestCaseError::fail(e.emit_to_string(source)))?;
            }
            Ok(())
        })
        .unwrap();
}
