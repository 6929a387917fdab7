//! A custom shape tested the way a user would test their own: with the
//! public API and `fractal_sdf::testing` only. The hexagonal prism of
//! `examples/custom_node.rs` is a 1-Lipschitz bound that never overestimates,
//! and its OpenCL twin matches its Rust definition; deliberately broken
//! variants are caught.

mod gpu;
#[path = "../examples/common/hex_prism.rs"]
mod hex_prism;

use fractal_sdf::prelude::*;
use fractal_sdf::render::DeviceSelector;
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

#[test]
fn hex_prism_twin_matches_on_the_device() {
    if gpu::device().is_none() {
        return;
    }
    let points = random_points(2000, 1.5, 11);
    let node = prism(0.45, 0.3);
    for (precision, tolerance) in [(Precision::F32, 1e-4), (Precision::F64, 1e-10)] {
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
    assert!((err.measured - 2.0).abs() < 1e-9, "{err}");
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
}

#[test]
fn a_custom_body_that_does_not_compile_reports_the_build_log() {
    if gpu::device().is_none() {
        return;
    }
    let broken = CustomShape::new("broken", &[], |p, _| p.length(), "return length(p) +;")
        .unwrap()
        .node(Vec::<f64>::new());
    let err =
        fractal_sdf::render::Renderer::new(&Scene::new(broken), Quality::draft()).unwrap_err();
    match err {
        Error::Build {
            log, kernel_source, ..
        } => {
            assert!(!log.is_empty());
            assert!(kernel_source.contains("real custom_broken(real3 p)"));
        }
        other => panic!("expected a build error, got {other}"),
    }
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
