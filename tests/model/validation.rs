//! Bad input is a typed error naming the node path and the parameter,
//! never a panic: sizes, non-finite numbers, iteration counts, powers,
//! smoothing, zero directions, empty scenes, degenerate cameras, lights
//! and dynamic parameters.

use fractal_sdf::prelude::*;
use fractal_sdf::testing::scene_node;
use proptest::prelude::*;

fn error_of(node: Node) -> Error {
    let err = Scene::new(node.clone()).validate().unwrap_err();
    // Lowering for the CPU reports the same error.
    assert_eq!(
        cpu::Evaluator::new(&node).unwrap_err().to_string(),
        err.to_string()
    );
    err
}

#[track_caller]
fn assert_out_of_range(node: Node, path: &str, name: &str, bad: f64, rule: &str) {
    match error_of(node) {
        Error::OutOfRange {
            node,
            param,
            value,
            expected,
        } => {
            assert_eq!((node.as_str(), param.as_str()), (path, name));
            assert_eq!(value.to_bits(), bad.to_bits());
            assert_eq!(expected, rule);
        }
        other => panic!("expected OutOfRange for {path}/{name}, got {other:?}"),
    }
}

#[track_caller]
fn assert_non_finite(node: Node, path: &str, name: &str) {
    match error_of(node) {
        Error::NonFinite { node, param, value } => {
            assert_eq!((node.as_str(), param.as_str()), (path, name));
            assert!(!value.is_finite());
        }
        other => panic!("expected NonFinite for {path}/{name}, got {other:?}"),
    }
}

#[track_caller]
fn assert_iterations(node: Node, path: &str, bad: u32, range: (u32, u32)) {
    match error_of(node) {
        Error::Iterations {
            node,
            value,
            min,
            max,
        } => {
            assert_eq!(node, path);
            assert_eq!((value, min, max), (bad, range.0, range.1));
        }
        other => panic!("expected Iterations for {path}, got {other:?}"),
    }
}

#[track_caller]
fn assert_zero_vector(node: Node, path: &str, name: &str) {
    match error_of(node) {
        Error::ZeroVector { node, param } => {
            assert_eq!((node.as_str(), param.as_str()), (path, name))
        }
        other => panic!("expected ZeroVector for {path}/{name}, got {other:?}"),
    }
}

#[test]
fn negative_sizes_are_out_of_range() {
    let v = |x, y, z| dvec3(x, y, z);
    assert_out_of_range(sphere(-1.0), "sphere", "radius", -1.0, ">= 0");
    assert_out_of_range(
        cuboid(v(1.0, -0.5, 1.0)),
        "cuboid",
        "half_extents.y",
        -0.5,
        ">= 0",
    );
    assert_out_of_range(
        round_box(v(1.0, 1.0, 1.0), -0.1),
        "round_box",
        "radius",
        -0.1,
        ">= 0",
    );
    assert_out_of_range(torus(-1.0, 0.2), "torus", "major_radius", -1.0, ">= 0");
    assert_out_of_range(torus(1.0, -0.2), "torus", "minor_radius", -0.2, ">= 0");
    assert_out_of_range(cylinder(-1.0, 1.0), "cylinder", "radius", -1.0, ">= 0");
    assert_out_of_range(cylinder(1.0, -1.0), "cylinder", "half_height", -1.0, ">= 0");
    assert_out_of_range(
        capsule(DVec3::ZERO, DVec3::ONE, -0.5),
        "capsule",
        "radius",
        -0.5,
        ">= 0",
    );
    assert_out_of_range(octahedron(-2.0), "octahedron", "size", -2.0, ">= 0");
    assert_out_of_range(
        octahedron_bound(-2.0),
        "octahedron_bound",
        "size",
        -2.0,
        ">= 0",
    );
    assert_out_of_range(
        capped_cone(1.0, -1.0, 0.5),
        "capped_cone",
        "bottom_radius",
        -1.0,
        ">= 0",
    );
    assert_out_of_range(
        capped_cone(-1.0, 1.0, 0.5),
        "capped_cone",
        "half_height",
        -1.0,
        ">= 0",
    );
    assert_out_of_range(
        capped_cone(1.0, 1.0, -0.5),
        "capped_cone",
        "top_radius",
        -0.5,
        ">= 0",
    );
    assert_out_of_range(
        ellipsoid(v(1.0, 0.0, 1.0)),
        "ellipsoid",
        "radii.y",
        0.0,
        "> 0",
    );
    assert_out_of_range(sphere(1.0).scale(0.0), "scale", "factor", 0.0, "> 0");
    assert_out_of_range(sphere(1.0).round(-0.1), "round", "radius", -0.1, ">= 0");
    assert_out_of_range(sphere(1.0).onion(-0.1), "onion", "thickness", -0.1, ">= 0");
    assert_out_of_range(
        sphere(1.0).elongate(v(0.0, 0.0, -1.0)),
        "elongate",
        "extents.z",
        -1.0,
        ">= 0",
    );
    assert_out_of_range(
        sphere(1.0).repeat(v(-2.0, 0.0, 0.0)),
        "repeat",
        "period.x",
        -2.0,
        ">= 0",
    );
    assert_out_of_range(
        sphere(1.0).repeat_limited(v(1.0, -2.0, 0.0), [1, 1, 1]),
        "repeat_limited",
        "period.y",
        -2.0,
        ">= 0",
    );
    assert_out_of_range(
        sphere(1.0).color(v(1.0, -0.1, 0.0)),
        "color",
        "color.y",
        -0.1,
        ">= 0",
    );
}

#[test]
fn a_rounding_radius_larger_than_the_box_is_out_of_range() {
    match error_of(round_box(dvec3(1.0, 0.2, 1.0), 0.5)) {
        Error::OutOfRange {
            node,
            param,
            value,
            expected,
        } => {
            assert_eq!(
                (node.as_str(), param.as_str(), value),
                ("round_box", "radius", 0.5)
            );
            assert_eq!(expected, "<= the smallest half extent (0.2)");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn nan_and_infinite_values_are_non_finite() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_non_finite(sphere(bad), "sphere", "radius");
        assert_non_finite(cuboid(dvec3(1.0, 1.0, bad)), "cuboid", "half_extents.z");
        assert_non_finite(
            sphere(1.0).translate(dvec3(bad, 0.0, 0.0)),
            "translate",
            "offset.x",
        );
        assert_non_finite(sphere(1.0).rotate(DVec3::Y, bad), "rotate", "angle");
        assert_non_finite(
            sphere(1.0).rotate(dvec3(0.0, bad, 1.0), 1.0),
            "rotate",
            "axis",
        );
        assert_non_finite(plane(dvec3(0.0, bad, 0.0), 0.0), "plane", "normal.y");
        assert_non_finite(plane(DVec3::Y, bad), "plane", "offset");
        assert_non_finite(
            capsule(dvec3(bad, 0.0, 0.0), DVec3::ONE, 0.1),
            "capsule",
            "a.x",
        );
        assert_non_finite(sphere(1.0).twist(bad), "twist", "rate");
        assert_non_finite(sphere(1.0).bend(bad), "bend", "rate");
        assert_non_finite(
            sphere(1.0).smooth_union(sphere(1.0), bad),
            "smooth_union",
            "k",
        );
        assert_non_finite(mandelbulb(bad), "mandelbulb", "power");
        assert_non_finite(
            Mandelbulb::new(8.0).bailout(bad).into(),
            "mandelbulb",
            "bailout",
        );
        assert_non_finite(julia([0.0, bad, 0.0, 0.0]), "julia", "c.y");
        assert_non_finite(
            QuaternionJulia::new([0.0.into(), 0.0.into(), 0.0.into(), 0.0.into()])
                .slice_w(bad)
                .into(),
            "julia",
            "slice_w",
        );
        assert_non_finite(Menger::new(2).scale(bad).into(), "menger", "scale");
        assert_non_finite(Sierpinski::new(2).scale(bad).into(), "sierpinski", "scale");
    }
}

#[test]
fn iteration_counts_outside_their_range_are_rejected() {
    let escape = (1, MAX_ESCAPE_ITERATIONS);
    let fold = (0, MAX_FOLD_ITERATIONS);
    assert_iterations(
        Mandelbulb::new(8.0).iterations(0).into(),
        "mandelbulb",
        0,
        escape,
    );
    assert_iterations(
        Mandelbulb::new(8.0).iterations(257).into(),
        "mandelbulb",
        257,
        escape,
    );
    let j = || QuaternionJulia::new([(-0.2).into(), 0.6.into(), 0.2.into(), 0.2.into()]);
    assert_iterations(j().iterations(0).into(), "julia", 0, escape);
    assert_iterations(j().iterations(u32::MAX).into(), "julia", u32::MAX, escape);
    assert_iterations(menger(21), "menger", 21, fold);
    assert_iterations(sierpinski(21), "sierpinski", 21, fold);
    // The ends of the ranges are valid.
    for node in [
        Mandelbulb::new(8.0).iterations(1).into(),
        Mandelbulb::new(8.0).iterations(256).into(),
        j().iterations(256).into(),
        menger(0),
        menger(20),
        sierpinski(0),
        sierpinski(20),
    ] {
        Scene::new(node).validate().unwrap();
    }
}

use fractal_sdf::cpu;
use fractal_sdf::scene::Mandelbulb;
use fractal_sdf::scene::Menger;
use fractal_sdf::scene::PseudoKleinian;
use fractal_sdf::scene::QuaternionJulia;
use fractal_sdf::scene::Sierpinski;
use fractal_sdf::scene::ellipsoid;
use fractal_sdf::scene::octahedron;
use fractal_sdf::scene::octahedron_bound;
use fractal_sdf::scene::param3;
use fractal_sdf::scene::{
    Hybrid, HybridOp, Kifs, KifsFold, MAX_SOLID_ANGLE, Profile, box_frame, capped_torus, cone,
    cone_between, cut_hollow_sphere, cut_sphere, cylinder_between, death_star, extrude,
    infinite_cone, infinite_cylinder, pyramid, quad, revolve, rhombus, round_cone_between,
    rounded_cylinder, solid_angle, tri_prism, triangle,
};
use fractal_sdf::scene::{MAX_ESCAPE_ITERATIONS, MAX_FOLD_ITERATIONS};
use fractal_sdf::scene::{capped_cone, hex_prism, link, round_cone};

#[test]
fn fractal_settings_outside_their_ranges_are_rejected() {
    assert_out_of_range(mandelbulb(1.5), "mandelbulb", "power", 1.5, "in [2, 64]");
    assert_out_of_range(mandelbulb(64.5), "mandelbulb", "power", 64.5, "in [2, 64]");
    assert_out_of_range(
        Mandelbulb::new(8.0).bailout(0.5).into(),
        "mandelbulb",
        "bailout",
        0.5,
        "in [1, 1000000]",
    );
    assert_out_of_range(
        julia([5.0, 0.0, 0.0, 0.0]),
        "julia",
        "c.x",
        5.0,
        "in [-4, 4]",
    );
    assert_out_of_range(
        Menger::new(2).scale(1.5).into(),
        "menger",
        "scale",
        1.5,
        "in [2, 4]",
    );
    assert_out_of_range(
        Sierpinski::new(2).scale(5.0).into(),
        "sierpinski",
        "scale",
        5.0,
        "in [1.5, 4]",
    );
}

#[test]
fn negative_smoothing_is_rejected_for_every_smooth_boolean() {
    let (a, b) = (sphere(1.0), cuboid(DVec3::ONE));
    assert_out_of_range(
        a.clone().smooth_union(b.clone(), -0.1),
        "smooth_union",
        "k",
        -0.1,
        ">= 0",
    );
    assert_out_of_range(
        a.clone().smooth_subtract(b.clone(), -0.1),
        "smooth_subtract",
        "k",
        -0.1,
        ">= 0",
    );
    assert_out_of_range(
        a.smooth_intersect(b, -0.1),
        "smooth_intersect",
        "k",
        -0.1,
        ">= 0",
    );
}

#[test]
fn zero_directions_are_rejected() {
    assert_zero_vector(sphere(1.0).rotate(DVec3::ZERO, 1.0), "rotate", "axis");
    assert_zero_vector(plane(DVec3::ZERO, 1.0), "plane", "normal");
}

#[test]
fn errors_name_the_path_to_the_node() {
    assert_out_of_range(
        sphere(1.0).union(torus(1.0, -0.2)),
        "union/b:torus",
        "minor_radius",
        -0.2,
        ">= 0",
    );
    let deep = sphere(-1.0)
        .translate(DVec3::X)
        .smooth_union(cuboid(DVec3::ONE), 0.1)
        .color(DVec3::ONE);
    assert_out_of_range(
        deep,
        "color/smooth_union/a:translate/sphere",
        "radius",
        -1.0,
        ">= 0",
    );
    let err = error_of(sphere(1.0).union(torus(1.0, -0.2)));
    assert_eq!(
        err.to_string(),
        "union/b:torus: parameter `minor_radius` must be >= 0, got -0.2"
    );
}

#[test]
fn an_empty_scene_is_rejected() {
    assert!(matches!(Scene::empty().validate(), Err(Error::EmptyScene)));
    // Adding geometry makes it valid.
    Scene::empty().add(sphere(1.0)).validate().unwrap();
}

#[track_caller]
fn assert_camera_error(camera: Camera, reason: &str) {
    let err = Scene::new(sphere(1.0))
        .with_camera(camera)
        .validate()
        .unwrap_err();
    match err {
        Error::Camera { reason: r } => assert!(r.contains(reason), "{r:?} lacks {reason:?}"),
        other => panic!("expected a camera error, got {other:?}"),
    }
}

#[test]
fn degenerate_cameras_are_rejected() {
    let p = dvec3(1.0, 2.0, 3.0);
    assert_camera_error(Camera::look_at(p, p), "target equals position");
    for fov in [0.0, 180.0, -10.0, 270.0, f64::NAN, f64::INFINITY] {
        assert_camera_error(Camera::look_at(p, DVec3::ZERO).fov(fov), "field of view");
    }
    assert_camera_error(
        Camera::look_at(p, DVec3::ZERO).orthographic(0.0),
        "orthographic height",
    );
    assert_camera_error(
        Camera::look_at(p, DVec3::ZERO).orthographic(f64::NAN),
        "orthographic height",
    );
    assert_camera_error(
        Camera::look_at(dvec3(f64::NAN, 0.0, 0.0), DVec3::ZERO),
        "finite",
    );
    assert_camera_error(Camera::look_at(DVec3::Y, DVec3::ZERO), "parallel");
    assert_camera_error(
        Camera::look_at(p, DVec3::ZERO).up(DVec3::ZERO),
        "up is zero",
    );
    // Just inside the limits is fine.
    for fov in [1e-3, 179.9] {
        Camera::look_at(p, DVec3::ZERO).fov(fov).validate().unwrap();
    }
}

#[test]
fn bad_lights_name_the_light() {
    let with = |light: Light| Scene::new(sphere(1.0)).with_lights([Light::point(DVec3::Y), light]);
    let err = with(Light::directional(DVec3::ZERO))
        .validate()
        .unwrap_err();
    assert!(
        matches!(&err, Error::ZeroVector { node, param } if node == "light[1]" && param == "direction"),
        "{err:?}"
    );
    let err = with(Light::point(dvec3(0.0, f64::NAN, 0.0)))
        .validate()
        .unwrap_err();
    assert!(
        matches!(&err, Error::NonFinite { node, param, .. } if node == "light[1]" && param == "position"),
        "{err:?}"
    );
    let err = with(Light::point(DVec3::Y).intensity(-1.0))
        .validate()
        .unwrap_err();
    assert!(
        matches!(&err, Error::OutOfRange { param, .. } if param == "intensity"),
        "{err:?}"
    );
    let err = with(Light::point(DVec3::Y).softness(f64::INFINITY))
        .validate()
        .unwrap_err();
    assert!(
        matches!(&err, Error::OutOfRange { param, .. } if param == "softness"),
        "{err:?}"
    );
    let err = with(Light::point(DVec3::Y).color(dvec3(1.0, -1.0, 0.0)))
        .validate()
        .unwrap_err();
    assert!(
        matches!(&err, Error::OutOfRange { param, .. } if param == "color"),
        "{err:?}"
    );
}

#[test]
fn dynamic_parameters_are_checked_when_set() {
    let mut eval = cpu::Evaluator::new(&sphere(param("r", 1.0))).unwrap();
    let err = eval.set_param("r", -1.0).unwrap_err();
    assert!(
        matches!(&err, Error::OutOfRange { node, param, value, expected }
            if node == "sphere" && param == "radius" && *value == -1.0 && expected == ">= 0"),
        "{err:?}"
    );
    // The same text a baked value gets.
    let baked = Scene::new(sphere(-1.0)).validate().unwrap_err();
    assert_eq!(err.to_string(), baked.to_string());
    let err = eval.set_param("r", f64::NAN).unwrap_err();
    assert!(
        matches!(&err, Error::NonFinite { param, .. } if param == "radius"),
        "{err:?}"
    );
    let err = eval.set_param("radius", 2.0).unwrap_err();
    assert!(
        matches!(&err, Error::UnknownParam { name, .. } if name == "radius"),
        "{err:?}"
    );
    // The message lists the names the scene has.
    assert_eq!(
        err.to_string(),
        "the scene has no dynamic parameter named `radius`; it has `r`"
    );
    // Failed sets leave the value alone.
    assert_eq!(eval.values().get("r"), Some(1.0));
    eval.set_param("r", 2.0).unwrap();
    assert_eq!(eval.values().get("r"), Some(2.0));
    // Range rules hold for dynamic fractal settings too.
    let mut bulb = cpu::Evaluator::new(&mandelbulb(param("power", 8.0))).unwrap();
    assert!(matches!(
        bulb.set_param("power", 1.0),
        Err(Error::OutOfRange { .. })
    ));
    assert!(matches!(
        bulb.set_param("power", 65.0),
        Err(Error::OutOfRange { .. })
    ));
    bulb.set_param("power", 2.0).unwrap();
}

#[test]
fn invalid_dynamic_defaults_are_rejected_where_they_are_used() {
    assert_out_of_range(sphere(param("r", -1.0)), "sphere", "radius", -1.0, ">= 0");
    assert_non_finite(
        sphere(1.0).translate(param3("at", dvec3(0.0, f64::NAN, 0.0))),
        "translate",
        "offset.y",
    );
}

#[test]
fn conflicting_declarations_of_one_name_are_rejected() {
    let conflict = |node: Node| match error_of(node) {
        Error::ConflictingParam { name } => name,
        other => panic!("expected ConflictingParam, got {other:?}"),
    };
    // Different defaults.
    assert_eq!(
        conflict(sphere(param("r", 1.0)).union(sphere(param("r", 2.0)))),
        "r"
    );
    // Same default, different rules (radius >= 0, offset finite).
    let offset = [param("x", 1.0), 0.0.into(), 0.0.into()];
    assert_eq!(conflict(sphere(param("x", 1.0)).translate(offset)), "x");
    // The same declaration twice shares one slot.
    let shared = sphere(param("r", 1.0)).union(torus(2.0, param("r", 1.0)));
    let ir = fractal_sdf::ir::Ir::lower(&shared).unwrap();
    assert_eq!(ir.params().len(), 1);
}

/// A value that breaks a rule: non-finite, or negative.
fn bad_size() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        -1e300..-1e-300f64,
    ]
}

/// A value outside `[lo, hi]`, or non-finite.
fn outside(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        (-1e300..lo).prop_filter("below", move |&v| v < lo),
        (hi..1e300).prop_filter("above", move |&v| v > hi),
    ]
}

/// A value that is not finite.
fn not_finite() -> impl Strategy<Value = f64> {
    prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)]
}

/// A node with exactly one invalid setting, and its node name.
fn broken_node() -> impl Strategy<Value = (Node, &'static str)> {
    prop_oneof![
        bad_size().prop_map(|v| (sphere(v), "sphere")),
        bad_size().prop_map(|v| (cuboid(dvec3(1.0, v, 1.0)), "cuboid")),
        bad_size().prop_map(|v| (torus(1.0, v), "torus")),
        bad_size().prop_map(|v| (capped_cone(v, 1.0, 0.5), "capped_cone")),
        bad_size().prop_map(|v| (hex_prism(1.0, v), "hex_prism")),
        bad_size().prop_map(|v| (round_cone(1.0, v, 0.5), "round_cone")),
        bad_size().prop_map(|v| (link(1.0, 0.5, v), "link")),
        outside(-4.0, 4.0).prop_map(|v| (mandelbox(v), "mandelbox")),
        (-1.0..1.0f64).prop_map(|v| (mandelbox(v), "mandelbox")),
        bad_size().prop_map(|v| (sphere(1.0).onion(v), "onion")),
        bad_size().prop_map(|v| (sphere(1.0).smooth_union(sphere(0.5), v), "smooth_union")),
        bad_size().prop_map(|v| (ellipsoid(dvec3(v, 1.0, 1.0)), "ellipsoid")),
        bad_size().prop_map(|v| (sphere(1.0).scale(v), "scale")),
        outside(2.0, 64.0).prop_map(|v| (mandelbulb(v), "mandelbulb")),
        outside(1.0, 1e6).prop_map(|v| (Mandelbulb::new(8.0).bailout(v).into(), "mandelbulb")),
        outside(-4.0, 4.0).prop_map(|v| (julia([0.0, 0.0, v, 0.0]), "julia")),
        outside(2.0, 4.0).prop_map(|v| (Menger::new(2).scale(v).into(), "menger")),
        outside(1.5, 4.0).prop_map(|v| (Sierpinski::new(2).scale(v).into(), "sierpinski")),
        outside(1.1, 4.0).prop_map(|v| (Kifs::new(KifsFold::Octahedral).scale(v).into(), "kifs")),
        (21..=u32::MAX).prop_map(|n| (Kifs::new(KifsFold::Menger).iterations(n).into(), "kifs")),
        outside(2.0, 16.0).prop_map(|v| (
            Hybrid::new()
                .stage(1, [HybridOp::power(v), HybridOp::AddPoint])
                .into(),
            "hybrid"
        )),
        outside(1.0, 1000.0).prop_map(|v| (Hybrid::mandelbox(2.0).bailout(v).into(), "hybrid")),
        outside(0.01, 4.0).prop_map(|v| (Hybrid::mandelbox(2.0).safety(v).into(), "hybrid")),
        bad_size().prop_map(|v| (
            Hybrid::new()
                .stage(2, [HybridOp::sphere_fold(v, 1.0)])
                .into(),
            "hybrid"
        )),
        (25..=1000u32).prop_map(|n| (
            Hybrid::new()
                .stage(n, [HybridOp::AbsFold, HybridOp::AddPoint])
                .into(),
            "hybrid"
        )),
        bad_size().prop_map(|v| (
            PseudoKleinian::new().fold_size([1.0, 1.0, v]).into(),
            "pseudo_kleinian"
        )),
        outside(0.05, 4.0)
            .prop_map(|v| (PseudoKleinian::new().inversion(v).into(), "pseudo_kleinian")),
        outside(1e-4, 2.0)
            .prop_map(|v| (PseudoKleinian::new().thickness(v).into(), "pseudo_kleinian")),
        (257..=u32::MAX).prop_map(|n| (
            PseudoKleinian::new().iterations(n).into(),
            "pseudo_kleinian"
        )),
        bad_size().prop_map(|v| (cut_sphere(v, 0.5), "cut_sphere")),
        bad_size().prop_map(|v| (solid_angle(0.5, v), "solid_angle")),
        outside(0.0, MAX_SOLID_ANGLE).prop_map(|v| (solid_angle(v, 1.0), "solid_angle")),
        outside(0.0, std::f64::consts::PI)
            .prop_map(|v| (capped_torus(v, 1.0, 0.2), "capped_torus")),
        bad_size().prop_map(|v| (capped_torus(1.0, v, 0.2), "capped_torus")),
        bad_size().prop_map(|v| (capped_torus(1.0, 1.0, v), "capped_torus")),
        prop_oneof![bad_size(), Just(0.0)]
            .prop_map(|v| (triangle(DVec3::ZERO, DVec3::X, DVec3::Y, v), "triangle")),
        not_finite().prop_map(|v| (
            quad(DVec3::ZERO, DVec3::X, dvec3(1.0, v, 0.0), DVec3::Y, 0.1),
            "quad"
        )),
        prop_oneof![bad_size(), Just(0.0)].prop_map(|v| (pyramid(v, 1.0), "pyramid")),
        bad_size().prop_map(|v| (box_frame(dvec3(0.5, v, 0.5), 0.1), "box_frame")),
        (0.51..1e300f64).prop_map(|v| (box_frame(dvec3(0.5, 0.6, 0.7), v), "box_frame")),
        bad_size().prop_map(|v| (pyramid(0.5, v), "pyramid")),
        bad_size().prop_map(|v| (rhombus(0.5, 0.5, 0.1, v), "rhombus")),
        bad_size().prop_map(|v| (tri_prism(v, 0.5), "tri_prism")),
        bad_size().prop_map(|v| (rounded_cylinder(0.5, v, 0.1), "rounded_cylinder")),
        (0.51..1e300f64).prop_map(|v| (rounded_cylinder(0.5, 0.6, v), "rounded_cylinder")),
        bad_size().prop_map(|v| (cone(v, 0.5), "cone")),
        bad_size().prop_map(|v| (infinite_cylinder(v), "infinite_cylinder")),
        outside(0.0, std::f64::consts::FRAC_PI_2).prop_map(|v| (infinite_cone(v), "infinite_cone")),
        not_finite().prop_map(|v| (cut_hollow_sphere(1.0, v, 0.1), "cut_hollow_sphere")),
        bad_size().prop_map(|v| (cut_hollow_sphere(1.0, 0.2, v), "cut_hollow_sphere")),
        prop_oneof![bad_size(), Just(0.0)].prop_map(|v| (death_star(1.0, 0.5, v), "death_star")),
        bad_size().prop_map(|v| (death_star(1.0, v, 0.8), "death_star")),
        bad_size().prop_map(|v| (
            cylinder_between(DVec3::ZERO, DVec3::Y, v),
            "cylinder_between"
        )),
        not_finite().prop_map(|v| (
            cylinder_between(dvec3(v, 0.0, 0.0), DVec3::Y, 0.5),
            "cylinder_between"
        )),
        bad_size().prop_map(|v| (cone_between(DVec3::ZERO, DVec3::Y, 0.5, v), "cone_between")),
        not_finite().prop_map(|v| (
            cone_between(DVec3::ZERO, dvec3(0.0, v, 0.0), 0.5, 0.2),
            "cone_between"
        )),
        bad_size().prop_map(|v| (
            round_cone_between(DVec3::ZERO, DVec3::Y, v, 0.2),
            "round_cone_between"
        )),
        bad_size().prop_map(|v| (extrude(Profile::circle(v), 0.5), "extrude")),
        prop_oneof![bad_size(), Just(0.0), 1.01..1e300f64]
            .prop_map(|v| (revolve(Profile::vesica(1.0, v), 0.0), "revolve")),
        prop_oneof![bad_size(), Just(0.0)]
            .prop_map(|v| (revolve(Profile::ellipse(0.5, v), 1.0), "revolve")),
        bad_size().prop_map(|v| (extrude(Profile::rect(0.5, v), 0.5), "extrude")),
        bad_size().prop_map(|v| (revolve(Profile::round_rect(v, 0.5, 0.1), 0.5), "revolve")),
        (0.51..1e300f64).prop_map(|v| (extrude(Profile::round_rect(0.5, 0.6, v), 0.5), "extrude")),
        prop_oneof![bad_size(), Just(0.0)].prop_map(|v| (
            revolve(Profile::segment([0.0, 0.0], [0.0, 1.0], v), 1.0),
            "revolve"
        )),
        bad_size().prop_map(|v| (extrude(Profile::circle(1.0), v), "extrude")),
        not_finite().prop_map(|v| (revolve(Profile::circle(0.2), v), "revolve")),
        not_finite().prop_map(|v| (
            extrude(Profile::polygon([[0.0, 0.0], [1.0, v], [0.0, 1.0]]), 0.5),
            "extrude"
        )),
        (0usize..3).prop_map(|n| (
            extrude(Profile::polygon((0..n).map(|i| [i as f64, 1.0])), 0.5),
            "extrude"
        )),
        Just((
            extrude(
                Profile::polygon((0..65).map(|i| [(i as f64).cos(), (i as f64).sin()])),
                0.5
            ),
            "extrude"
        )),
        Just((
            revolve(Profile::polygon([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]), 0.5),
            "revolve"
        )),
        prop_oneof![Just(0u32), 257..=u32::MAX]
            .prop_map(|n| (Mandelbulb::new(8.0).iterations(n).into(), "mandelbulb")),
        (21..=u32::MAX).prop_map(|n| (menger(n), "menger")),
        Just((sphere(1.0).rotate(DVec3::ZERO, 1.0), "rotate")),
        Just((plane(DVec3::ZERO, 0.0), "plane")),
    ]
}

proptest! {
    /// One bad value anywhere in a valid scene: an error naming the bad
    /// node, never a panic.
    #[test]
    fn invalid_values_anywhere_give_an_error_not_a_panic(
        valid in scene_node(3),
        (broken, name) in broken_node(),
        place in 0u8..4,
    ) {
        let node = match place {
            0 => broken,
            1 => valid.union(broken),
            2 => broken.smooth_subtract(valid, 0.1),
            _ => broken.translate(DVec3::X).color(DVec3::ONE).intersect(valid),
        };
        let err = Scene::new(node.clone()).validate().unwrap_err();
        let message = err.to_string();
        prop_assert!(message.contains(name), "{} does not name {}", message, name);
        prop_assert!(cpu::Evaluator::new(&node).is_err());
    }

    /// Setting a dynamic parameter to a bad value: an error, the old value
    /// kept, never a panic.
    #[test]
    fn invalid_dynamic_values_give_an_error_not_a_panic(bad in bad_size()) {
        let mut eval = cpu::Evaluator::new(&sphere(param("r", 1.0)).twist(param("k", 0.5)))?;
        prop_assert!(eval.set_param("r", bad).is_err());
        prop_assert_eq!(eval.values().get("r"), Some(1.0));
        if !bad.is_finite() {
            prop_assert!(eval.set_param("k", bad).is_err());
        }
    }
}

/// A dynamic value keeps every rule that relates it to other parameters,
/// with the error a baked value gets.
#[test]
fn dynamic_values_keep_relational_rules() {
    let node = round_box(dvec3(0.5, 0.5, 0.5), param("r", 0.1));
    let mut eval = cpu::Evaluator::new(&node).unwrap();
    let err = eval.set_param("r", 0.9).unwrap_err();
    let baked = Scene::new(round_box(dvec3(0.5, 0.5, 0.5), 0.9))
        .validate()
        .unwrap_err();
    assert_eq!(err.to_string(), baked.to_string());
    assert_eq!(
        err.to_string(),
        "round_box: parameter `radius` must be <= the smallest half extent (0.5), got 0.9"
    );
    // The refused value is not kept: the box is still a box.
    assert_eq!(eval.values().get("r"), Some(0.1));
    // At the centre the distance is `(0 - 0.5 + 0.1) - 0.1`, two roundings
    // of values below 1: measured 0; the tolerance is a few ulps of 0.5.
    assert!((eval.distance(DVec3::ZERO) + 0.5).abs() < 1e-15);
    eval.set_param("r", 0.5).unwrap();

    // A dynamic half extent below a baked radius, likewise.
    let node = round_box(param3("b", dvec3(0.5, 0.5, 0.5)), 0.2);
    let mut eval = cpu::Evaluator::new(&node).unwrap();
    let err = eval.set_param("b.y", 0.1).unwrap_err();
    assert!(
        err.to_string()
            .contains("<= the smallest half extent (0.1), got 0.2"),
        "{err}"
    );

    // A plane's dynamic normal cannot become zero.
    let node = plane(param3("n", dvec3(0.0, 1.0, 0.0)), 0.0);
    let mut eval = cpu::Evaluator::new(&node).unwrap();
    eval.set_param("n.y", 0.0).unwrap_err();
    eval.set_param("n.x", 1.0).unwrap();
    eval.set_param("n.y", 0.0).unwrap();
    let err = eval.set_param("n.x", 0.0).unwrap_err();
    assert!(matches!(err, Error::ZeroVector { .. }), "{err}");
}

/// Regression: a twist or bend rate of 1e20 was accepted and rendered
/// black; rates are limited to what marching can follow.
#[test]
fn warp_rates_beyond_the_limit_are_refused() {
    use fractal_sdf::scene::MAX_WARP_RATE;
    for node in [
        sphere(1.0).twist(1e20),
        sphere(1.0).bend(-1e20),
        sphere(1.0).twist(MAX_WARP_RATE * 1.01),
    ] {
        let err = error_of(node);
        assert!(
            matches!(err, Error::OutOfRange { ref param, .. } if param == "rate"),
            "{err}"
        );
    }
    assert!(
        Scene::new(sphere(1.0).twist(MAX_WARP_RATE))
            .validate()
            .is_ok()
    );
}

/// Regression: far from a twisted or bent shape its estimate shrank with
/// the warp's stretch (towards `1 / rate`), whatever the true distance.
/// Now it is at least the distance to the ball around the warped shape,
/// measured here against a sphere on the warp's axis (which the warp
/// leaves unchanged, so its true distance is known).
#[test]
fn a_warped_shape_keeps_its_distance_far_away() {
    for (node, axis) in [
        (sphere(0.5).twist(3.0), dvec3(0.0, 1.0, 0.0)),
        (sphere(0.5).bend(3.0), dvec3(0.0, 0.0, 1.0)),
    ] {
        let eval = cpu::Evaluator::new(&node).unwrap();
        for p in [
            dvec3(20.0, 0.0, 0.0),
            dvec3(0.0, 30.0, 5.0),
            dvec3(-7.0, 3.0, 9.0),
        ] {
            let d = eval.distance(p);
            let exact = p.length() - 0.5;
            assert!(d <= exact + 1e-9, "{p}: {d} overestimates {exact}");
            assert!(d >= 0.9 * exact, "{p} (axis {axis}): {d} against {exact}");
        }
    }
}

/// Regression: a brute-force step of 1e-9 footprints was accepted and
/// rendered only sky (the steps ran out before reaching any set).
#[test]
fn brute_steps_too_small_to_reach_a_set_are_refused() {
    use fractal_sdf::quality::MIN_BRUTE_STEP;
    for step in [1e-9, 0.0, MIN_BRUTE_STEP * 0.99] {
        let err = Quality::production()
            .brute_step(step)
            .validate()
            .unwrap_err();
        assert!(err.to_string().contains("brute_step"), "{err}");
    }
    assert!(
        Quality::production()
            .brute_step(MIN_BRUTE_STEP)
            .validate()
            .is_ok()
    );
}

/// An orbit trap colours a fractal: on anything else, with a degenerate
/// direction, an empty range or a bad palette, compiling says what is
/// wrong and where.
#[test]
fn bad_orbit_traps_say_what_is_wrong() {
    use fractal_sdf::scene::{OrbitColoring, Palette, Trap};
    let invalid = |node: Node| match error_of(node) {
        Error::Invalid { what, reason } => {
            assert_eq!(what, "orbit trap");
            reason
        }
        other => panic!("expected an invalid orbit trap, got {other:?}"),
    };
    let on_sphere = invalid(sphere(1.0).orbit_trap(Trap::point(DVec3::ZERO), Palette::fire()));
    assert!(on_sphere.starts_with("orbit_trap: "), "{on_sphere}");
    assert!(on_sphere.contains("its child is a sphere"), "{on_sphere}");
    // Under a transform the fractal is not the child either.
    let moved = mandelbulb(8.0)
        .translate(DVec3::X)
        .orbit_trap(Trap::point(DVec3::ZERO), Palette::fire());
    assert!(invalid(moved).contains("child is a translate"));

    let flat = OrbitColoring::new(Trap::point(DVec3::ZERO), Palette::grey()).range(0.5, 0.5);
    assert_out_of_range(
        menger(2).orbit_coloring(flat),
        "orbit_trap",
        "far",
        0.5,
        "!= near (0.5)",
    );
    let backwards = Palette::gradient([(0.6, [1.0; 3]), (0.4, [0.0; 3])]);
    let reason = invalid(menger(2).orbit_trap(Trap::point(DVec3::ZERO), backwards));
    assert!(reason.contains("its palette stop 1 is at 0.4"), "{reason}");
    let empty = Palette::gradient([]);
    assert!(invalid(menger(2).orbit_trap(Trap::point(DVec3::ZERO), empty)).contains("0 stops"));

    assert_zero_vector(
        menger(2).orbit_trap(Trap::plane(DVec3::ZERO, 0.0), Palette::fire()),
        "orbit_trap",
        "trap.normal",
    );
    assert_zero_vector(
        menger(2).orbit_trap(Trap::line(DVec3::ONE, DVec3::ZERO), Palette::fire()),
        "orbit_trap",
        "trap.direction",
    );
    assert_out_of_range(
        menger(2).orbit_trap(Trap::sphere(DVec3::ZERO, -1.0), Palette::fire()),
        "orbit_trap",
        "trap.radius",
        -1.0,
        ">= 0",
    );
    assert_non_finite(
        menger(2).orbit_coloring(
            OrbitColoring::new(Trap::point(DVec3::ZERO), Palette::fire()).range(0.0, f64::NAN),
        ),
        "orbit_trap",
        "far",
    );
    // A dynamic direction cannot become zero either.
    let node = menger(2).orbit_trap(
        Trap::plane(param3("n", dvec3(0.0, 0.0, 1.0)), 0.0),
        Palette::fire(),
    );
    let mut eval = cpu::Evaluator::new(&node).unwrap();
    let err = eval.set_param("n.z", 0.0).unwrap_err();
    assert!(matches!(err, Error::ZeroVector { .. }), "{err}");
    // Nor can a dynamic range close up.
    let node = menger(2).orbit_coloring(
        OrbitColoring::new(Trap::point(DVec3::ZERO), Palette::fire())
            .range(param("near", 0.0), param("far", 1.0)),
    );
    let mut eval = cpu::Evaluator::new(&node).unwrap();
    eval.set_param("near", 0.5).unwrap();
    let err = eval.set_param("far", 0.5).unwrap_err();
    assert_eq!(
        err.to_string(),
        "orbit_trap: parameter `far` must be != near (0.5), got 0.5"
    );
    let err = eval.set_param("near", 1.0).unwrap_err();
    assert!(err.to_string().contains("!= near (1)"), "{err}");
}
