//! A custom shape tested the way a user would test their own: with the
//! public API and `fractal_sdf::testing` only. The hexagonal prism of
//! `examples/custom_node.rs` is a 1-Lipschitz bound that never overestimates,
//! and its OpenCL twin matches its Rust definition; deliberately broken
//! variants are caught.

use crate::gpu;
#[path = "../../examples/common/hex_prism.rs"]
mod hex_prism;

use fractal_sdf::codegen::{self, Options, Target};
use fractal_sdf::cpu;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Glow;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{DeviceInfo, DeviceKind, DeviceSelector};
use fractal_sdf::scene::Param;
use fractal_sdf::scene::capped_cone;
use fractal_sdf::scene::ellipsoid;
use fractal_sdf::scene::octahedron;
use fractal_sdf::scene::{CustomShape, Rule};
use fractal_sdf::testing::{
    Check, check_device_matches_cpu, check_lipschitz, check_never_overestimates, point, point_pair,
    random_points,
};
use proptest::prelude::*;

/// Independent membership: inside the hexagon of inradius `r` (|x| and the
/// two 60° rotations of it within r of the centre line) and |z| <= h.
fn inside_prism(p: DVec3, r: f64, h: f64) -> bool {
    let (s, c) = (60f64.to_radians().sin(), 60f64.to_radians().cos());
    let axes = [(0.0, 1.0), (s, c), (-s, c)];
    p.z.abs() <= h && axes.iter().all(|(ax, ay)| (ax * p.x + ay * p.y).abs() <= r)
}

fn prism(r: f64, h: f64) -> Node {
    hex_prism::hex_prism().unwrap().node([r, h])
}

proptest! {
    #[test]
    fn hex_prism_is_1_lipschitz(
        r in 0.1..1.0f64,
        h in 0.0..1.0f64,
        pairs in prop::collection::vec(point_pair(2.0, 0.3), 64),
    ) {
        check_lipschitz(&prism(r, h), 1.0, &pairs)?;
    }

    #[test]
    fn hex_prism_never_overestimates(
        r in 0.1..1.0f64,
        h in 0.05..1.0f64,
        points in prop::collection::vec(point(2.0), 16),
    ) {
        check_never_overestimates(&prism(r, h), |p| inside_prism(p, r, h), &points, 32)?;
    }
}

/// The relative tolerance of the prism's device results. On a CPU device
/// (PoCL) the worst errors measured over the 2,000 points below are
/// 2.4e-7 in F32 and 1.7e-16 in F64; the tolerances are about 40 and 60
/// times those. GPUs are not measured here and keep 1e-4 and 1e-10, as in
/// `tests/distance/conformance.rs`.
fn device_tolerance(precision: Precision, device: &DeviceInfo) -> f64 {
    match (precision, device.kind) {
        (Precision::F32, DeviceKind::Cpu) => 1e-5,
        (Precision::F64, DeviceKind::Cpu) => 1e-14,
        (Precision::F64, _) => 1e-10,
        _ => 1e-4,
    }
}

#[test]
fn hex_prism_twin_matches_on_the_device() {
    let Some(device) = gpu::device() else {
        return;
    };
    let points = random_points(2000, 1.5, 11);
    let node = prism(0.45, 0.3);
    for precision in [Precision::F32, Precision::F64] {
        let tolerance = device_tolerance(precision, &device);
        check_device_matches_cpu(
            &node,
            &DeviceSelector::auto(),
            precision,
            &points,
            tolerance,
        )
        .unwrap_or_else(|f| panic!("{precision:?}: {f}"));
    }
}

/// A shape whose distance is twice the truth: an overestimate.
fn doubled_sphere() -> Node {
    CustomShape::new(
        "doubled_sphere",
        &[("radius", Rule::NonNegative)],
        |p, a| 2.0 * (p.length() - a[0]),
        "return R(2.0) * (length(p) - radius);",
    )
    .unwrap()
    .node([1.0])
}

#[test]
fn an_overestimating_shape_is_caught() {
    let node = doubled_sphere();
    let far = [dvec3(3.0, 0.0, 0.0), dvec3(0.0, -2.0, 1.0)];
    let err = check_never_overestimates(&node, |p| p.length() <= 1.0, &far, 32).unwrap_err();
    assert_eq!(err.check, Check::NeverOverestimates);
    assert!(err.factor() > 1.5, "{err}");
    let err =
        check_lipschitz(&node, 1.0, &[(dvec3(2.0, 0.0, 0.0), dvec3(2.5, 0.0, 0.0))]).unwrap_err();
    assert_eq!(err.check, Check::Lipschitz);
    // The slope between the pair is (3 - 2) / 0.5, every value a small
    // dyadic fraction: exact (measured 0); the tolerance admits a few
    // roundings of 2.
    assert!((err.measured - 2.0).abs() < 1e-14, "{err}");
}

#[test]
fn a_twin_that_drifted_from_its_reference_is_caught() {
    if gpu::device().is_none() {
        return;
    }
    // The OpenCL body forgot to subtract the radius.
    let drifted = CustomShape::new(
        "drifted_sphere",
        &[("radius", Rule::NonNegative)],
        |p, a| p.length() - a[0],
        "return length(p);",
    )
    .unwrap()
    .node([0.5]);
    let points = random_points(100, 2.0, 3);
    // The drift is 0.5 at every point of the cube [-2, 2]^3, where the
    // reference distance is below 3: any relative tolerance below 0.16
    // flags all 100 points; this one is the F32 tolerance a GPU gets above.
    let err = check_device_matches_cpu(
        &drifted,
        &DeviceSelector::auto(),
        Precision::F32,
        &points,
        1e-4,
    )
    .unwrap_err();
    assert_eq!(err.check, Check::DeviceMatchesCpu);
    assert_eq!(err.violations, 100, "{err}");
    // The report keeps the program the device ran, and says where it is.
    let program = err.program.as_deref().expect("the program is kept");
    assert!(
        program
            .source
            .contains("real custom_drifted_sphere(real3 p, real radius)")
    );
    let path = program.path.as_ref().expect("the program is saved");
    assert_eq!(std::fs::read_to_string(path).unwrap(), program.source);
    assert!(
        err.to_string().contains(&path.display().to_string()),
        "{err}"
    );
}

/// The gyroid with a typo on the second line of its body.
fn misspelt_gyroid() -> Node {
    CustomShape::new(
        "gyroid",
        &[("thickness", Rule::NonNegative)],
        |p, a| (p.x.sin() * p.y.cos()).abs() - a[0],
        "real g = sin(p.x) * cos(p.y);\n    retur fabs(g) - thickness;",
    )
    .unwrap()
    .node([0.1])
}

#[test]
fn a_custom_body_that_does_not_compile_is_reported_by_its_own_line() {
    if gpu::device().is_none() {
        return;
    }
    let scene = Scene::new(misspelt_gyroid().union(sphere(1.0)));
    let err = fractal_sdf::render::Renderer::new(&scene, Quality::draft()).unwrap_err();
    let shown = err.to_string();
    match err {
        Error::CustomShapeBuild {
            shape,
            line,
            text,
            message,
            build,
            ..
        } => {
            assert_eq!(shape, "gyroid");
            assert_eq!(line, 2, "{shown}");
            assert_eq!(text.trim(), "retur fabs(g) - thickness;");
            assert!(message.contains("retur"), "{message}");
            // The whole failure is kept: the full log and program.
            assert!(build.build_log().is_some_and(|log| log.contains("retur")));
            assert!(
                build
                    .kernel_source()
                    .is_some_and(|s| s.contains("real custom_gyroid(real3 p, real thickness)"))
            );
        }
        other => panic!("expected a custom shape build error, got {other}"),
    }
    assert!(
        shown.starts_with(
            "custom shape `gyroid`, line 2 of its body: `retur fabs(g) - thickness;`: "
        ),
        "{shown}"
    );
    // A body whose last line breaks is found in the evaluation program too.
    let broken = CustomShape::new("broken", &[], |p, _| p.length(), "return length(p) +;")
        .unwrap()
        .node(Vec::<f64>::new());
    let err =
        fractal_sdf::render::PointEvaluator::new(&broken, Precision::F32, &DeviceSelector::auto())
            .unwrap_err();
    assert!(
        matches!(&err, Error::CustomShapeBuild { shape, line: 1, .. } if shape == "broken"),
        "{err}"
    );
}

#[test]
fn a_device_check_that_does_not_build_is_a_build_failure_with_its_program() {
    if gpu::device().is_none() {
        return;
    }
    let points = random_points(10, 1.0, 5);
    let f = check_device_matches_cpu(
        &misspelt_gyroid(),
        &DeviceSelector::auto(),
        Precision::F32,
        &points,
        1e-4,
    )
    .unwrap_err();
    assert_eq!(f.check, Check::Build);
    let shown = f.to_string();
    assert!(!shown.contains("does not validate"), "{shown}");
    assert!(shown.contains("line 2 of its body"), "{shown}");
    let program = f.program.as_deref().expect("the program is kept");
    assert!(program.source.contains("real custom_gyroid("));
    let path = program.path.as_ref().expect("the program is saved");
    assert_eq!(std::fs::read_to_string(path).unwrap(), program.source);
    assert!(shown.contains(&path.display().to_string()), "{shown}");
}

#[test]
fn custom_shape_definitions_are_checked() {
    let bad_name = CustomShape::new("no spaces", &[], |_, _| 0.0, "return R(0.0);");
    assert!(matches!(bad_name, Err(Error::CustomShape { .. })));
    let injected = CustomShape::new(
        "x",
        &[("a); } //", Rule::Finite)],
        |_, _| 0.0,
        "return R(0.0);",
    );
    assert!(matches!(injected, Err(Error::CustomShape { .. })));
    let shadow = CustomShape::new("x", &[("p", Rule::Finite)], |_, _| 0.0, "return R(0.0);");
    assert!(matches!(shadow, Err(Error::CustomShape { .. })));
    // A wrong number of values is a validation error, not a panic.
    let node = hex_prism::hex_prism().unwrap().node([1.0]);
    assert!(matches!(
        Scene::new(node).validate(),
        Err(Error::CustomShape { .. })
    ));
    // Dynamic values follow the declared rules.
    let node = hex_prism::hex_prism()
        .unwrap()
        .node([Param::from(-1.0), 0.5.into()]);
    assert!(matches!(
        Scene::new(node).validate(),
        Err(Error::OutOfRange { .. })
    ));
}

#[test]
fn custom_bodies_that_would_leave_their_function_are_refused_before_compiling() {
    let define = |body: &str| CustomShape::new("blob", &[], |p, _| p.length() - 1.0, body);
    let refused = [
        (
            "return length(p)\0 - R(1.0);",
            "a NUL byte (line 1 of the body)",
        ),
        (
            "return length(p) - R(1.0);\u{7}",
            "control character U+0007",
        ),
        (
            "return length(p) - R(1.0);\n}\nreal DE(real3 p) {\n    return R(0.0);",
            "closes a brace it did not open (line 2 of the body)",
        ),
        (
            "if (p.x > R(0.0)) {\n    return R(1.0);",
            "leaves 1 brace(s) open",
        ),
    ];
    for (body, says) in refused {
        match define(body) {
            Err(err @ Error::CustomShape { .. }) => {
                let text = err.to_string();
                assert!(text.starts_with("custom shape `blob`: "), "{text}");
                assert!(text.contains(says), "{body:?}: {text}");
            }
            other => panic!("{body:?} was not refused: {other:?}"),
        }
    }
    // A macro of a generated name is refused by code generation, before
    // anything is compiled.
    let directives = [
        (
            "#define DE broken\nreturn length(p) - R(1.0);",
            "`#define DE` (line 1 of the body)",
        ),
        (
            "  # undef DE_shade\nreturn length(p) - R(1.0);",
            "`#undef DE_shade`",
        ),
        (
            "#define custom_other 1\nreturn R(0.0);",
            "`#define custom_other`",
        ),
    ];
    for (body, says) in directives {
        let shape = define(body).unwrap();
        let compiled = Scene::new(shape.node(Vec::<f64>::new())).compile().unwrap();
        match codegen::emit(&compiled, &Options::default()) {
            Err(err @ Error::CustomShape { .. }) => {
                let text = err.to_string();
                assert!(text.contains(says), "{body:?}: {text}");
            }
            other => panic!("{body:?} was not refused: {:?}", other.err()),
        }
    }
    // Braces in blocks, comments and character literals, and macros of
    // the body's own, are fine.
    for body in [
        "{\n    real r = length(p); // }\n    return r - R(1.0);\n}",
        "/* } */ return length(p) - R(1.0);",
        "#define RADIUS_OF_BLOB R(1.0)\nreturn length(p) - RADIUS_OF_BLOB;",
        "\treturn length(p) - R(1.0);\r\n",
    ] {
        assert!(define(body).is_ok(), "{body:?}: {:?}", define(body).err());
    }
}

/// The reason a parameter name is refused, if it is.
/// Why a shape with parameter `param` is refused: by `CustomShape::new`
/// (OpenCL's words, reserved spellings), or when a program using it is
/// generated (names the program itself defines or calls).
fn refusal(param: &str) -> Option<String> {
    let made = CustomShape::new(
        "shape",
        &[(param, Rule::Finite)],
        |_, _| 0.0,
        "return R(0.0);",
    )
    .and_then(|shape| {
        let scene = Scene::new(shape.node([0.0])).compile()?;
        codegen::emit(&scene, &codegen::Options::default())
    });
    match made {
        Ok(_) => None,
        Err(Error::CustomShape { name, reason }) => {
            assert_eq!(name, "shape");
            assert!(reason.contains(&format!("`{param}`")), "{reason}");
            Some(reason)
        }
        Err(other) => panic!("{param}: {other}"),
    }
}

#[test]
fn names_with_a_meaning_in_opencl_or_the_program_are_refused() {
    for name in [
        "p",
        "params",
        "DETAIL",
        "GAMMA",
        "R",
        "REAL_TINY",
        "MAX_STEPS",
        "CAMERA_ORIGIN",
        "LIGHT_STRIDE",
        "RENDER_TILE_ARGS",
        "EVAL_POINTS_ARGS",
        "ENABLE_AO",
        "M_PI",
        "FLT_MAX",
        "real",
        "real3",
        "real16",
        "float3",
        "double",
        "uint",
        "half",
        "kernel",
        "__kernel",
        "global",
        "constant",
        "restrict",
        "return",
        "sin",
        "length",
        "clamp",
        "fabs",
        "mix",
        "convert_float",
        "native_sqrt",
        "vload3",
        "__x",
        "_Hidden",
        "DE",
        "DE_shade",
        "sd_sphere",
        "sd_future",
        "menger",
        "march_ray",
        "render_tile",
        "eval_points",
        "custom_gyroid",
        "mandelbulb_p8",
        "cl_khr_fp64",
    ] {
        assert!(refusal(name).is_some(), "`{name}` is accepted");
    }
    for name in [
        "radius",
        "half_length",
        "thickness",
        "k",
        "t",
        "x0",
        "Radius",
        "m_pi",
    ] {
        assert_eq!(refusal(name), None, "`{name}` is refused");
    }
}

/// The names `source` defines at file scope: macros, typedefs and
/// functions (lines that start a declaration with a name before `(`).
fn defined_names(source: &str) -> Vec<String> {
    let word = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut names = Vec::new();
    for line in source.lines() {
        if let Some(rest) = line.trim_start().strip_prefix("#define ") {
            names.push(word(rest.trim_start()));
        } else if let Some(rest) = line.strip_prefix("typedef ") {
            if let Some(name) = rest
                .strip_suffix(';')
                .and_then(|r| r.split_whitespace().last())
            {
                names.push(name.to_string());
            }
        } else if line.starts_with("} ") && line.ends_with(';') {
            names.push(word(line[2..].trim_start())); // typedef struct { ... } Name;
        } else if line.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
            && line.contains('(')
            && !line.starts_with("typedef")
        {
            let head = &line[..line.find('(').unwrap()];
            names.push(word(head.split_whitespace().last().unwrap_or("")));
        }
    }
    names.retain(|n| !n.is_empty());
    names
}

/// Every `#define`, typedef and function any generated program holds is
/// refused as a parameter name: read from programs for a scene with every
/// helper, in both precisions, for both targets, every effect on.
#[test]
fn every_name_the_code_generator_defines_is_refused() {
    let b = || cuboid(dvec3(0.5, 0.3, 0.4));
    let every_helper = sphere(0.5)
        .union(b().rotate(dvec3(1.0, 2.0, 0.5), 0.7))
        .union(round_box(dvec3(0.5, 0.4, 0.3), 0.1))
        .union(torus(0.7, 0.2).twist(1.5))
        .union(cylinder(0.4, 0.6).bend(0.9))
        .union(capsule(dvec3(-0.3, -0.5, 0.1), dvec3(0.4, 0.6, -0.2), 0.25))
        .union(plane(dvec3(0.2, 1.0, -0.3), 0.4))
        .union(octahedron(0.9).smooth_union(capped_cone(0.6, 0.5, 0.2), 0.3))
        .union(ellipsoid(dvec3(0.7, 0.4, 0.5)))
        .union(mandelbulb(8.0).union(mandelbulb(7.3)))
        .union(menger(3).union(julia([-0.2, 0.6, 0.2, 0.2])))
        .union(sierpinski(4));
    let scene = Scene::new(every_helper).compile().unwrap();
    let effects = Effects::default()
        .ambient_occlusion(true)
        .shadows(true)
        .glow(Some(Glow::new(DVec3::ONE, 1.0)))
        .fog_density(0.5);
    let mut checked = 0;
    for precision in [Precision::F32, Precision::F64] {
        for target in [Target::Render, Target::Evaluate] {
            let options = Options::default()
                .quality(Quality::default().precision(precision))
                .effects(effects)
                .target(target);
            let source = codegen::emit(&scene, &options).unwrap().source;
            let names = defined_names(&source);
            for must in [
                "DETAIL",
                "REAL_TINY",
                "real3",
                "sd_sphere",
                "mandelbulb_p8",
                "DE_shade",
            ] {
                assert!(names.iter().any(|n| n == must), "{must} not read");
            }
            for name in names {
                assert!(
                    refusal(&name).is_some(),
                    "`{name}` is accepted ({precision:?}, {target:?})"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 200, "{checked}");
}

#[test]
fn shape_names_are_free_identifiers() {
    // Shape names are free (the function is `custom_NAME`), as long as
    // they are identifiers.
    for name in ["DETAIL", "sin", "real", "p"] {
        let shape = CustomShape::new(name, &[], |p, _| p.length(), "return length(p);").unwrap();
        assert_eq!(shape.function_name(), format!("custom_{name}"));
    }
    let long = "x".repeat(49);
    assert!(CustomShape::new(&long, &[], |_, _| 0.0, "return R(0.0);").is_err());
}

#[test]
fn a_broken_rule_names_the_shape_and_its_parameter() {
    let prism = hex_prism::hex_prism().unwrap();
    let scene = Scene::new(sphere(1.0).union(prism.node([-1.0, 0.5])));
    match scene.validate() {
        Err(Error::OutOfRange { node, param, .. }) => {
            assert_eq!(node, "union/b:hex_prism");
            assert_eq!(param, "radius");
        }
        other => panic!("expected an out-of-range error, got {other:?}"),
    }
    let err = Scene::new(prism.node([0.5, f64::NAN]))
        .validate()
        .unwrap_err();
    assert!(
        err.to_string()
            .starts_with("hex_prism: parameter `half_length`"),
        "{err}"
    );
    // A dynamic value set later is checked against the same rule.
    let node = prism.node([param("r", 0.5), 0.5.into()]);
    let mut eval = cpu::Evaluator::new(&node.union(sphere(1.0))).unwrap();
    let err = eval.set_param("r", -2.0).unwrap_err().to_string();
    assert!(err.contains("hex_prism") && err.contains("radius"), "{err}");
    assert!(!err.contains("custom"), "{err}");
}

fn ball() -> CustomShape {
    CustomShape::new(
        "ball",
        &[],
        |p, _| p.length() - 1.0,
        "return length(p) - R(1.0);",
    )
    .unwrap()
}

fn ball_of(radius: f64) -> CustomShape {
    CustomShape::new(
        "ball",
        &[],
        move |p, _| p.length() - radius,
        "return length(p) - R(1.0);",
    )
    .unwrap()
}

#[test]
fn two_shapes_of_one_name_must_be_one_definition() {
    // The same constructor, a capture-free closure: one shape.
    assert_eq!(ball(), ball());
    Scene::new(
        ball()
            .node(Vec::<f64>::new())
            .union(ball().node(Vec::<f64>::new())),
    )
    .validate()
    .unwrap();
    // The same name, parameters and body, another Rust function: refused,
    // or the CPU would compute two shapes where the device has one.
    let other = CustomShape::new(
        "ball",
        &[],
        |p, _| p.length() - 2.0,
        "return length(p) - R(1.0);",
    )
    .unwrap();
    assert_ne!(ball(), other);
    let err = Scene::new(
        ball()
            .node(Vec::<f64>::new())
            .union(other.node(Vec::<f64>::new())),
    )
    .validate()
    .unwrap_err();
    match &err {
        Error::CustomShape { name, reason } => {
            assert_eq!(name, "ball");
            assert!(reason.contains("CPU functions differ"), "{reason}");
            assert!(reason.contains("union/b:ball"), "{reason}");
        }
        other => panic!("{other}"),
    }
    // A closure that captures a value: only clones of one handle agree.
    let (one, two) = (ball_of(1.0), ball_of(2.0));
    assert_ne!(one, two);
    let err = Scene::new(
        one.node(Vec::<f64>::new())
            .union(two.node(Vec::<f64>::new())),
    )
    .validate()
    .unwrap_err();
    assert!(err.to_string().contains("clone"), "{err}");
    let clone = one.clone();
    assert_eq!(one, clone);
    Scene::new(
        one.node(Vec::<f64>::new())
            .union(clone.node(Vec::<f64>::new())),
    )
    .validate()
    .unwrap();
}
