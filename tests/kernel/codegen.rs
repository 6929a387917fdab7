//! Code generation: only what the scene needs, dynamic versus baked
//! parameters, folding, and safe identifiers.

use fractal_sdf::codegen::{self, Options};
use fractal_sdf::cpu;
use fractal_sdf::ir::Ir;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Glow;
use fractal_sdf::quality::Precision;

fn source(geometry: Node, options: &Options) -> String {
    codegen::emit(&Scene::new(geometry).compile().unwrap(), options)
        .unwrap()
        .source
}

#[test]
fn sphere_scene_contains_no_fractal_helper_and_no_disabled_effect() {
    let options = Options::default().effects(Effects::none());
    let src = source(sphere(1.0), &options);
    for absent in [
        "mandelbulb",
        "menger",
        "julia",
        "sierpinski",
        "angle_power",
        "sd_box",
        "smooth_min",
        "#ifdef",
        "AO_SAMPLES",
        "SHADOW_STEPS",
        "GLOW_",
        "FOG_",
    ] {
        assert!(
            !src.contains(absent),
            "sphere scene source contains `{absent}`"
        );
    }
    assert!(src.contains("real sd_sphere("));
}

#[test]
fn effects_that_are_on_are_defined() {
    let options = Options::default().effects(
        Effects::default()
            .glow(Some(Glow::new(dvec3(1.0, 0.5, 0.2), 1.0)))
            .fog_density(0.1),
    );
    let src = source(sphere(1.0), &options);
    for present in ["AO_SAMPLES", "SHADOW_STEPS", "GLOW_STRENGTH", "FOG_DENSITY"] {
        assert!(
            src.contains(&format!("#define {present}")),
            "missing {present}"
        );
        // The effect's code is compiled in and uses the constant.
        assert!(
            src.matches(present).count() >= 2,
            "{present} is defined but unused"
        );
    }
    assert!(
        !src.contains("#ifdef"),
        "feature blocks are resolved by code generation"
    );
}

#[test]
fn fractal_helpers_are_printed_once_and_stand_alone() {
    let src = source(
        menger(3)
            .union(sierpinski(3))
            .union(menger(2).translate(DVec3::X)),
        &Options::default(),
    );
    assert_eq!(src.matches("real2 menger(").count(), 1);
    assert_eq!(src.matches("real2 sierpinski(").count(), 1);
    // The box and tetrahedron they end with are part of their formulas.
    assert!(!src.contains("sd_box") && !src.contains("sd_tetrahedron"));
    assert!(!src.contains("mandelbulb"));
}

#[test]
fn integer_power_eight_uses_the_trig_free_form() {
    let src = source(mandelbulb(8.0), &Options::default());
    assert!(src.contains("mandelbulb_p8(p0, 12, R(2.0), 1.1040895f)"));
    assert!(!src.contains("acos"), "power 8 must not use trigonometry");

    let src = source(mandelbulb(7.5), &Options::default());
    assert!(src.contains("acos"));
    assert!(!src.contains("angle_power"));

    // A dynamic power cannot be specialised.
    let src = source(mandelbulb(param("power", 8.0)), &Options::default());
    assert!(src.contains(
        "mandelbulb(p0, params[0] /* power */, 12, fmin(R(2.0), pow(R(1e18), R(1.0) / params[0] /* power */)), pow(R(2.0), R(1.0) / (params[0] /* power */ - R(1.0))))"
    ));
}

#[test]
fn dynamic_values_keep_the_source_but_change_the_distance() {
    let scene = |r: f64| Scene::new(sphere(param("radius", r)).translate(dvec3(0.5, 0.0, 0.0)));
    let (one, two) = (scene(1.0).compile().unwrap(), scene(2.0).compile().unwrap());
    let a = codegen::emit(&one, &Options::default()).unwrap();
    let b = codegen::emit(&two, &Options::default()).unwrap();
    assert_eq!(a.source, b.source);
    assert_eq!(a.hash, b.hash);
    assert_eq!(one.params().slots()[0].default, 1.0);
    assert_eq!(two.params().slots()[0].default, 2.0);

    let mut eval = cpu::Evaluator::new(scene(1.0).geometry.as_ref().unwrap()).unwrap();
    let p = dvec3(3.0, 0.0, 0.0);
    let before = eval.distance(p);
    eval.set_param("radius", 2.0).unwrap();
    assert_eq!(before - 1.0, eval.distance(p));
}

#[test]
fn baked_values_change_the_source_and_hash() {
    let a = codegen::emit(
        &Scene::new(sphere(1.0)).compile().unwrap(),
        &Options::default(),
    )
    .unwrap();
    let b = codegen::emit(
        &Scene::new(sphere(1.5)).compile().unwrap(),
        &Options::default(),
    )
    .unwrap();
    assert_ne!(a.source, b.source);
    assert_ne!(a.hash, b.hash);
}

#[test]
fn baked_iteration_counts_are_constant_loop_bounds_and_can_be_overridden() {
    let mut options = Options::default();
    let src = source(menger(4), &options);
    assert!(src.contains("menger(p0, 4, 3.0f)"));
    options.quality.fractal_iterations = Some(2);
    let src = source(menger(4), &options);
    assert!(src.contains("menger(p0, 2, 3.0f)"));
    // A cap: fewer iterations than the cap stay as they are.
    options.quality.fractal_iterations = Some(6);
    let src = source(menger(4), &options);
    assert!(src.contains("menger(p0, 4, 3.0f)"));
}

#[test]
fn f64_source_declares_double_precision() {
    let options = Options::default().quality(Quality::default().precision(Precision::F64));
    let src = source(sphere(0.1), &options);
    assert!(src.contains("#pragma OPENCL EXTENSION cl_khr_fp64 : enable"));
    assert!(src.contains("typedef double real;"));
    assert!(src.contains("sd_sphere(p0, 0.1)"));
}

#[test]
fn chains_of_baked_transforms_fold_into_one_node() {
    let chain = sphere(1.0)
        .translate(dvec3(1.0, 0.0, 0.0))
        .translate(dvec3(0.0, 2.0, 0.0))
        .scale(2.0)
        .scale(0.25)
        .rotate(DVec3::Z, 0.3)
        .rotate(DVec3::Z, 0.2)
        .smooth_union(torus(1.0, 0.2), 0.0);
    let ir = Ir::lower(&chain).unwrap();
    // sphere, translate, scale, rotate, torus, union.
    assert_eq!(ir.nodes().len(), 6, "{:#?}", ir.nodes());
    let unfolded = cpu::Evaluator::new(&chain).unwrap();
    let p = dvec3(0.3, -0.7, 1.1);
    let by_hand = {
        let q = DQuat::from_axis_angle(DVec3::Z, -0.5) * p;
        let s = (q / 0.5 - dvec3(1.0, 2.0, 0.0)).length() - 1.0;
        // The torus about y: the distance to the circle of radius 1 in the
        // xz plane, less the tube's radius.
        let ring = dvec3(p.x, 0.0, p.z).normalize() * 1.0;
        let torus = p.distance(ring) - 0.2;
        (s * 0.5).min(torus)
    };
    // Two computations of the same value (Rodrigues' formula against
    // glam's quaternion, the folded torus against the circle's nearest
    // point), each a few roundings of numbers below 3: measured 0 at this
    // point; the tolerance is about 20 ulps of 2.
    approx::assert_relative_eq!(unfolded.distance(p), by_hand, epsilon = 1e-14);
    let src = source(chain, &Options::default());
    assert!(
        !src.contains("smooth_min"),
        "k = 0 must fold to the hard union"
    );
}

#[test]
fn dynamic_parameter_names_never_reach_the_source() {
    let name = "r\"); } __kernel void evil() { /*";
    let src = source(sphere(param(name, 1.0)), &Options::default());
    // The name is only a comment beside its slot, with every character
    // that could end the comment or start code replaced.
    assert!(!src.contains("evil()"));
    assert!(!src.contains("/*\";"), "{src}");
    assert!(
        src.contains("params[0] /* r??? ? __kernel void evil?? ? /? */"),
        "{src}"
    );
    for line in src.lines().filter(|l| l.contains("evil")) {
        assert!(line.contains("sd_sphere(p0, params[0] /* r??? "), "{line}");
    }
}

/// Every variable `DE` and `DE_shade` declare is read afterwards: no colour
/// or trap is computed that a colour node paints over, and no blend of a
/// value with itself.
#[test]
fn generated_functions_declare_nothing_they_do_not_read() {
    let painted_union = sphere(1.0)
        .union(cuboid(dvec3(0.5, 0.5, 0.5)).color(dvec3(0.0, 1.0, 0.0)))
        .smooth_union(torus(1.0, 0.2), 0.1)
        .color(dvec3(1.0, 0.0, 0.0));
    let mut scenes: Vec<(String, Scene)> = fractal_sdf::gallery::all()
        .into_iter()
        .map(|(name, scene)| (name.to_string(), scene))
        .collect();
    scenes.push(("painted union".into(), Scene::new(painted_union)));
    for (name, scene) in scenes {
        let compiled = scene.compile().unwrap();
        let src = codegen::emit(&compiled, &Options::default())
            .unwrap()
            .source;
        for function in ["real DE(", "real DE_shade("] {
            let start = src.find(function).unwrap();
            let body = &src[start..start + src[start..].find("\n}\n").unwrap()];
            let lines: Vec<&str> = body.lines().collect();
            // The signature's own parameters aside.
            for (i, line) in lines.iter().enumerate().skip(1) {
                let Some(declared) = declared_variable(line) else {
                    continue;
                };
                let read = lines[i + 1..].iter().any(|later| mentions(later, declared))
                    || line.matches(declared).count() > 1;
                assert!(
                    read,
                    "{name}: `{declared}` is never read in {function}...\n{line}"
                );
            }
        }
    }
}

/// The variable a line such as `    real3 c4 = ...;` or `    real t0;`
/// declares.
fn declared_variable(line: &str) -> Option<&str> {
    let rest = line.trim_start();
    let rest = ["real3 ", "real2 ", "real "]
        .iter()
        .find_map(|ty| rest.strip_prefix(ty))?;
    let end = rest.find([' ', ';'])?;
    Some(&rest[..end])
}

/// Whether `line` uses the identifier `name` (not as part of a longer one).
fn mentions(line: &str, name: &str) -> bool {
    line.match_indices(name).any(|(at, _)| {
        let before = line[..at].chars().next_back();
        let after = line[at + name.len()..].chars().next();
        let ident = |c: Option<char>| c.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_');
        !ident(before) && !ident(after)
    })
}

/// Each block of generated code says which node it comes from, and each
/// dynamic read which parameter it is.
#[test]
fn generated_blocks_name_their_nodes_and_parameters() {
    let node = sphere(param("radius", 1.0))
        .union(torus(1.0, 0.2).translate(dvec3(0.0, 2.0, 0.0)))
        .color(dvec3(1.0, 0.5, 0.0));
    let src = source(node, &Options::default());
    assert!(src.contains("/* color/union/a:sphere */"), "{src}");
    assert!(src.contains("/* color/union/b:translate */"), "{src}");
    // Paths keep their last three steps.
    assert!(src.contains("/* .../union/b:translate/torus */"), "{src}");
    assert!(src.contains("/* color/union */"), "{src}");
    assert!(
        src.contains("sd_sphere(p0, params[0] /* radius */)"),
        "{src}"
    );
    // So do deep ones.
    let deep = (0..10).fold(sphere(1.0), |n, _| n.round(0.01));
    let src = source(deep, &Options::default());
    assert!(src.contains("/* .../round/round/sphere */"), "{src}");
}

/// `n` spheres of different sizes and colours, placed with `Scene::add`.
fn added_spheres(n: u32) -> Scene {
    (0..n).fold(Scene::empty(), |scene, i| {
        let t = f64::from(i) / f64::from(n);
        scene.add(
            sphere(0.1 + t)
                .translate(dvec3(t, 0.0, -t))
                .color(dvec3(t, 0.5, 0.5)),
        )
    })
}

#[test]
fn wide_unions_become_one_loop_over_a_table() {
    let emit =
        |scene: Scene| codegen::emit(&scene.compile().unwrap(), &Options::default()).unwrap();
    let small = emit(added_spheres(1_000));
    let large = emit(added_spheres(5_000));
    // The code is one operand's, whatever the count: only numbers (the
    // table's and the nodes' places, and node numbers in names) differ.
    assert!(large.source.len() - small.source.len() < 100);
    assert!(
        small.source.contains("walked through") && small.source.contains("while (bp"),
        "{}",
        small.scene_part()
    );
    // Every member's values (colour, offset, radius) and its place in the
    // union, in the order of the hierarchy's leaves, then its nodes.
    let rows: Vec<&[f64]> = small.constants[..8 * 999].chunks(8).collect();
    let mut places: Vec<usize> = rows.iter().map(|r| r[7] as usize).collect();
    places.sort_unstable();
    assert!(places.iter().copied().eq(0..999));
    let t = 1.0 / 1000.0;
    let first = rows.iter().find(|r| r[7] == 0.0).unwrap();
    assert_eq!(&first[..7], &[t, 0.5, 0.5, t, 0.0, -t, 0.1 + t]);
    assert_eq!((small.constants.len() - 8 * 999) % 32, 0);
    // A group smaller than MIN_HIERARCHY is looped over, in order.
    let looped = emit(added_spheres(20));
    assert!(
        looped.source.contains("for (uint i = 0u; i < 19u; i++)"),
        "{}",
        looped.scene_part()
    );
    let t = 1.0 / 20.0;
    assert_eq!(looped.constants.len(), 7 * 19);
    assert_eq!(&looped.constants[..7], &[t, 0.5, 0.5, t, 0.0, -t, 0.1 + t]);
    // Fewer than MIN_INSTANCES alike operands are written out.
    let few = emit(added_spheres(
        u32::try_from(codegen::MIN_INSTANCES).unwrap(),
    ));
    assert!(!few.source.contains("for (uint i"), "{}", few.scene_part());
    assert!(few.constants.is_empty());
}

#[test]
fn effects_that_cost_nothing_leave_no_code() {
    // Each effect switched on but given nothing to do: no samples, no
    // steps, no strength, no density.
    let options = Options::default()
        .quality(Quality::default().ao_samples(0).shadow_steps(0))
        .effects(
            Effects::default()
                .ambient_occlusion(true)
                .shadows(true)
                .glow(Some(Glow::new(dvec3(1.0, 0.5, 0.2), 0.0)))
                .fog_density(0.0),
        );
    assert!(codegen::Effect::enabled(&options).is_empty());
    let src = source(sphere(1.0), &options);
    for absent in ["AO_SAMPLES", "SHADOW_STEPS", "GLOW_", "FOG_"] {
        assert!(!src.contains(absent), "`{absent}` with nothing to do");
    }
}

#[test]
fn a_custom_region_maps_exactly_its_own_lines() {
    // Signature on line 9, body on lines 10 and 11, closing brace on 12.
    let region = codegen::CustomRegion {
        shape: "gyroid".into(),
        first_line: 10,
        lines: 2,
    };
    let mapped: Vec<Option<usize>> = (0..15).map(|line| region.body_line(line)).collect();
    let mut expected = vec![None; 15];
    for (line, body) in [(9, 0), (10, 1), (11, 2), (12, 3)] {
        expected[line] = Some(body);
    }
    assert_eq!(mapped, expected);
}

#[test]
fn hash_of_is_the_program_hash_and_tells_programs_apart() {
    let a = source_of(sphere(1.0));
    let b = source_of(sphere(2.0));
    assert_eq!(codegen::KernelSource::hash_of(&a.source), a.hash);
    assert_eq!(codegen::KernelSource::hash_of(&b.source), b.hash);
    assert_ne!(a.hash, b.hash);
    // FNV-1a of the empty string is its offset basis.
    assert_eq!(codegen::KernelSource::hash_of(""), 0xcbf2_9ce4_8422_2325);
}

fn source_of(node: Node) -> codegen::KernelSource {
    codegen::emit(&Scene::new(node).compile().unwrap(), &Options::default()).unwrap()
}

#[test]
fn a_custom_shape_s_region_covers_its_body_exactly() {
    let body = "real a = p.x;\nreal b = p.y;\nreal c = p.z;\nreturn length((real3)(a, b, c)) - r;";
    let shape = fractal_sdf::scene::CustomShape::new(
        "blob",
        &[("r", fractal_sdf::scene::Rule::Positive)],
        |p, a| p.length() - a[0],
        body,
    )
    .unwrap();
    let k = source_of(shape.node([0.5]));
    let [region] = k.custom_regions.as_slice() else {
        panic!("{:?}", k.custom_regions)
    };
    assert_eq!(region.lines, 4);
    let lines: Vec<&str> = k.source.lines().collect();
    // Lines are counted from 1: the body's first line is `first_line`.
    let shown: Vec<&str> = (region.first_line..region.first_line + region.lines)
        .map(|n| lines[n - 1].trim())
        .collect();
    assert_eq!(shown, body.lines().map(str::trim).collect::<Vec<_>>());
    assert!(lines[region.first_line + region.lines - 1].trim() == "}");
}

#[test]
fn a_custom_parameter_named_like_the_program_s_own_functions_is_refused() {
    // `menger` is a helper of the program: not an OpenCL word, so the shape
    // is made, but the program it would join refuses it.
    let shape = fractal_sdf::scene::CustomShape::new(
        "blob",
        &[("menger", fractal_sdf::scene::Rule::Positive)],
        |p, a| p.length() - a[0],
        "return length(p) - menger;",
    )
    .unwrap();
    let compiled = Scene::new(shape.node([0.5])).compile().unwrap();
    let err = codegen::emit(&compiled, &Options::default()).unwrap_err();
    assert!(
        err.to_string().contains("menger") && err.to_string().contains("generated program"),
        "{err}"
    );
}

/// A fractal's helper returns its far-field value before its iterations:
/// a point outside the ball that holds the set costs one length, not the
/// loops and logarithms of the estimate (which the printed formula would
/// otherwise compute and then discard).
#[test]
fn fractal_helpers_return_early_in_their_far_field() {
    let bulb = mandelbulb(param("power", 8.0));
    let julia = julia([-0.2, 0.6, 0.2, 0.2]);
    for (name, node) in [("real2 mandelbulb(", bulb), ("real2 julia(", julia)] {
        let text = source(node, &Options::default());
        let start = text
            .find(name)
            .unwrap_or_else(|| panic!("{name} in\n{text}"));
        let body = &text[start..start + text[start..].find("\n}\n").unwrap()];
        let early = body.find("return").expect("a return");
        let first_loop = body.find("for (").expect("a loop");
        assert!(early < first_loop, "{body}");
        assert_eq!(body.matches("return").count(), 2, "{body}");
    }
}
