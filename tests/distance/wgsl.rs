//! Whole scenes' functions in WGSL, the third backend of the
//! conformance: every gallery scene's module (for rendering and for
//! evaluation) validates with naga, and its `DE` and `DE_shade` run on a
//! Vulkan device through wgpu (Mesa's lavapipe where there is no GPU) to
//! the CPU reference's distances and colours in single precision.

use glam::Vec3;

use crate::wgpu_device::{device, run};
use fractal_sdf::Error;
use fractal_sdf::codegen::{KernelSource, Language, Options, Target, WGSL_PARAMS, emit_wgsl};
use fractal_sdf::cpu::Evaluator;
use fractal_sdf::gallery;
use fractal_sdf::ir::CompiledScene;
use fractal_sdf::quality::{Precision, Quality};

/// Parses and validates a module.
fn validate(name: &str, source: &str) {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
}

/// The gallery's scenes, compiled.
fn scenes() -> Vec<(&'static str, CompiledScene)> {
    gallery::all()
        .into_iter()
        .map(|(name, scene)| (name, scene.compile().expect("gallery scenes compile")))
        .collect()
}

#[test]
fn every_gallery_scene_prints_as_valid_wgsl() {
    let mut printed = 0;
    for (name, scene) in scenes() {
        for target in [Target::Render, Target::Evaluate] {
            let options = Options::default().target(target);
            let module = emit_wgsl(&scene, &options).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(module.language, Language::Wgsl);
            assert!(module.source.contains("fn DE(p0: real3) -> real {"));
            validate(name, &module.source);
            printed += 1;
        }
    }
    assert_eq!(printed, 2 * gallery::names().len());
}

#[test]
fn double_precision_is_a_typed_error_that_names_the_way_to_deep_zoom() {
    let (_, scene) = scenes().swap_remove(0);
    let options = Options::default().quality(Quality::default().precision(Precision::F64));
    let error = emit_wgsl(&scene, &options).expect_err("WGSL has no double precision");
    assert!(matches!(
        error,
        Error::Unsupported {
            backend: "WGSL",
            ..
        }
    ));
    let message = error.to_string();
    assert!(
        message.contains("F64") && message.contains("OpenCL"),
        "{message}"
    );
}

/// Deterministic points in `[-extent, extent]³` (xorshift64).
fn points(count: usize, extent: f32, seed: u64) -> Vec<Vec3> {
    let mut s = seed;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        #[allow(clippy::cast_precision_loss)]
        let unit = (s >> 40) as f32 / (1u64 << 24) as f32;
        (2.0 * unit - 1.0) * extent
    };
    (0..count)
        .map(|_| Vec3::new(next(), next(), next()))
        .collect()
}

/// A shader that writes, for each point, `DE`, `DE_shade`'s distance and
/// its colour.
fn evaluator(module: &KernelSource, count: usize) -> String {
    let (group, binding) = WGSL_PARAMS;
    assert_eq!((group, binding), (0, 0), "the harness binds inputs from 0");
    format!(
        "{}\n\
         @group(0) @binding(1) var<storage, read> points: array<f32>;\n\
         @group(0) @binding(2) var<storage, read_write> outputs: array<f32>;\n\
         @compute @workgroup_size(64)\n\
         fn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
         \x20   let i = id.x;\n\
         \x20   if (i >= {count}u || arrayLength(&params) == 0u) {{ return; }}\n\
         \x20   let p = real3(points[3u * i], points[3u * i + 1u], points[3u * i + 2u]);\n\
         \x20   var color = real3(0.0);\n\
         \x20   var trap = real2(0.0);\n\
         \x20   outputs[5u * i] = DE(p);\n\
         \x20   outputs[5u * i + 1u] = DE_shade(p, &color, &trap);\n\
         \x20   outputs[5u * i + 2u] = color.x;\n\
         \x20   outputs[5u * i + 3u] = color.y;\n\
         \x20   outputs[5u * i + 4u] = color.z;\n\
         }}\n",
        module.source
    )
}

/// Runs `module`'s `DE` and `DE_shade` on the device at the points `at`
/// with the dynamic values `values`: five numbers a point, the two
/// distances and the colour.
fn evaluate(
    gpu: &(wgpu::Device, wgpu::Queue),
    module: &KernelSource,
    values: &[f64],
    at: &[Vec3],
) -> Vec<f32> {
    #[allow(clippy::cast_possible_truncation)]
    let params: Vec<f32> = module
        .param_buffer(values)
        .iter()
        .map(|&v| v as f32)
        // A binding is never empty.
        .chain([0.0])
        .collect();
    let flat: Vec<f32> = at.iter().flat_map(|p| p.to_array()).collect();
    let count = at.len();
    run(
        gpu,
        &evaluator(module, count),
        &[&params, &flat],
        5 * count,
        count,
    )
}

/// Every gallery scene's `DE` and `DE_shade` (for evaluation: no local
/// frame), run on the device at 512 points in `[-3, 3]³`, give the CPU
/// reference's single-precision distance and colour within
/// `1e-3 · max(1, |cpu|)`: the distance of two single-precision
/// libraries' `sin`, `pow` and `acos`, carried through a fractal's
/// iterations. The largest difference is printed.
#[test]
fn every_gallery_scene_runs_on_wgpu_as_the_cpu_reference_computes_it() {
    let Some(gpu) = device() else { return };
    const TOLERANCE: f32 = 1e-3;
    let count = 512;
    let options = Options::default().target(Target::Evaluate);
    let mut worst = (0.0f32, "", "", Vec3::ZERO);
    let mut checked = 0;
    for (name, scene) in scenes() {
        let module = emit_wgsl(&scene, &options).expect("the scene prints");
        let at = points(count, 3.0, 0x9e37_79b9_7f4a_7c15);
        let (error, what, p) = compare(&gpu, &scene, &module, &at, (TOLERANCE, TOLERANCE))
            .unwrap_or_else(|failure| panic!("{name}: {failure}"));
        if error > worst.0 {
            worst = (error, name, what, p);
        }
        checked += 1;
    }
    println!(
        "{checked} scenes; largest relative difference {:e} ({} {} at {})",
        worst.0, worst.1, worst.2, worst.3
    );
    assert_eq!(checked, gallery::names().len());
}

/// Runs `module` (the WGSL of `scene`, for evaluation) at the points `at`
/// with the scene's default values, and compares its `DE`, `DE_shade`
/// and colour with the CPU reference's in `f32`: each within `tolerance ·
/// max(1, |cpu|)` (the distances with `tolerance.0`, the colour's
/// channels with `tolerance.1`). Returns the largest relative difference,
/// what it was and where, or the first point beyond the tolerance.
pub(crate) fn compare(
    gpu: &(wgpu::Device, wgpu::Queue),
    scene: &CompiledScene,
    module: &KernelSource,
    at: &[Vec3],
    (distance, colour): (f32, f32),
) -> Result<(f32, &'static str, Vec3), String> {
    let got = evaluate(gpu, module, scene.default_values().as_slice(), at);
    let cpu = Evaluator::from_compiled(scene);
    let mut worst = (0.0f32, "", Vec3::ZERO);
    for (p, g) in at.iter().zip(got.chunks_exact(5)) {
        let s = cpu.sample::<f32>((*p).into());
        let color = Vec3::from(s.color);
        let pairs = [
            ("DE", g[0], s.distance, distance),
            ("DE_shade", g[1], s.distance, distance),
            ("red", g[2], color.x, colour),
            ("green", g[3], color.y, colour),
            ("blue", g[4], color.z, colour),
        ];
        for (what, device, cpu, tolerance) in pairs {
            if !cpu.is_finite() {
                return Err(format!("the CPU's {what} at {p} is {cpu}"));
            }
            let error = (device - cpu).abs() / cpu.abs().max(1.0);
            // A NaN from the device fails too.
            if error.is_nan() || error > tolerance {
                return Err(format!(
                    "{what} at {p}: device {device}, CPU {cpu} (relative {error:e})"
                ));
            }
            if error > worst.0 {
                worst = (error, what, *p);
            }
        }
    }
    Ok(worst)
}

/// 400 coloured spheres, every fourth placed by a dynamic position and all
/// sized by one dynamic radius: one loop over a table, walked through a
/// bounding volume hierarchy, whose boxes the host fits again when the
/// values change; a floor through them, which `DE`'s walk starts from.
/// After moving them, the device's distances and colours are the CPU
/// reference's at 512 points.
#[test]
fn instances_walked_through_a_hierarchy_run_on_wgpu_as_on_the_cpu() {
    use fractal_sdf::prelude::*;
    use fractal_sdf::scene::{Param3, param3};
    let Some(gpu) = device() else { return };
    let mut scene = Scene::empty();
    #[allow(clippy::cast_precision_loss)]
    for i in 0..400 {
        let t = i as f64 * 0.37;
        let at = dvec3(
            t.cos() * 2.0,
            (t * 0.61).sin() * 2.0,
            (t * 0.23).cos() * 2.0,
        );
        let placed: Param3 = if i % 4 == 0 {
            param3(&format!("s{i}"), at)
        } else {
            at.into()
        };
        let tint = dvec3((t * 1.3).sin().abs(), (t * 0.7).cos().abs(), 0.5);
        scene = scene.add(sphere(param("r", 0.15)).translate(placed).color(tint));
    }
    let scene = scene.add(plane(DVec3::Y, 0.5).color(dvec3(0.8, 0.8, 0.8)));
    let compiled = scene.compile().expect("the scene compiles");
    let options = Options::default().target(Target::Evaluate);
    let module = emit_wgsl(&compiled, &options).expect("the scene prints");
    assert!(module.source.contains("walked through"), "no hierarchy");
    // The helper, and one call in each of DE and DE_shade.
    assert_eq!(module.source.matches("sd_sphere(").count(), 3, "unrolled");
    let mut eval = Evaluator::from_compiled(&compiled);
    let mut values = compiled.default_values();
    for i in (0..400).step_by(8) {
        for (axis, v) in [("x", 0.3), ("y", -0.2), ("z", 0.1)] {
            let name = format!("s{i}.{axis}");
            let moved = values.get(&name).expect("a position") + v;
            values.set(&name, moved).expect("a position");
            eval.set_param(&name, moved).expect("a position");
        }
    }
    values.set("r", 0.12).expect("the radius");
    eval.set_param("r", 0.12).expect("the radius");
    let at = points(512, 2.5, 0x2545_f491_4f6c_dd1d);
    let got = evaluate(&gpu, &module, values.as_slice(), &at);
    let mut worst = 0.0f32;
    for (p, g) in at.iter().zip(got.chunks_exact(5)) {
        let s = eval.sample::<f32>((*p).into());
        let color = Vec3::from(s.color);
        for (what, device, cpu) in [
            ("DE", g[0], s.distance),
            ("DE_shade", g[1], s.distance),
            ("red", g[2], color.x),
            ("green", g[3], color.y),
            ("blue", g[4], color.z),
        ] {
            let error = (device - cpu).abs() / cpu.abs().max(1.0);
            assert!(error <= 1e-5, "{what} at {p}: device {device}, CPU {cpu}");
            worst = worst.max(error);
        }
    }
    println!("largest relative difference {worst:e}");
}

/// The scene functions name their values after their nodes (`u32` for the
/// gate of node 32, `f16` for a fractal's pair): in WGSL a local name
/// hides a predeclared type of that name, so the loops and casts after
/// them spell their types through the prelude's aliases (`uint`, `int`),
/// never by the names a value may take. (naga resolves a type by its
/// name wherever a type is expected, so it accepts either spelling; an
/// implementation that follows the specification's scoping would not.) A
/// scene with a gate named `u32` and a walk over instances after it
/// validates, and its functions name no type a value may hide.
#[test]
fn value_names_never_hide_the_types_the_loops_use() {
    use fractal_sdf::prelude::*;
    // Leading shapes (two nodes each with their union, or three when
    // moved) shift the gates' numbers through every remainder of the six
    // nodes a pair takes, so that one gate is node 32.
    let mut hidden = 0;
    for lead in 0..6 {
        let mut scene = Scene::empty();
        for _ in 0..lead % 3 {
            scene = scene.add(sphere(0.05));
        }
        if lead >= 3 {
            scene = scene.add(sphere(0.05).translate(dvec3(0.0, -2.0, 0.0)));
        }
        #[allow(clippy::cast_precision_loss)]
        for i in 0..12 {
            let at = dvec3(i as f64 * 0.9, 0.0, 0.0);
            let pair = sphere(0.3).smooth_union(
                cuboid(dvec3(0.2, 0.2, 0.2)).translate(dvec3(0.3, 0.0, 0.0)),
                0.1,
            );
            scene = scene.add(pair.translate(at));
        }
        #[allow(clippy::cast_precision_loss)]
        for i in 0..40 {
            scene = scene.add(sphere(0.1).translate(dvec3(i as f64 * 0.3, 2.0, 0.0)));
        }
        let compiled = scene.compile().expect("the scene compiles");
        for target in [Target::Render, Target::Evaluate] {
            let module =
                emit_wgsl(&compiled, &Options::default().target(target)).expect("the scene prints");
            assert!(module.source.contains("walked through"), "no hierarchy");
            validate("a gate named u32", &module.source);
            let functions = module
                .source
                .split("/* ---- scene ---- */")
                .nth(1)
                .expect("the scene's functions");
            for typed in [": u32", "u32(", "<u32", ": i32", "i32(", "<i32"] {
                assert!(!functions.contains(typed), "`{typed}` in the functions");
            }
            if module.source.contains("var u32: real") {
                hidden += 1;
            }
        }
    }
    assert!(hidden > 0, "no value named u32: the test tests nothing");
}
