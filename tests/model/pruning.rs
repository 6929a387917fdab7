//! Bounds and pruned unions: every node's bound stays below its own
//! estimate wherever the bound is positive, so a union or subtraction that
//! skips an operand beyond its bound computes exactly what it computes
//! without skipping, at every point.

use fractal_sdf::cpu::{Evaluator, Sample};
use fractal_sdf::ir::Ir;
use fractal_sdf::prelude::*;
use fractal_sdf::scene::param3;
use fractal_sdf::testing::{fractal_node, point, scene_node};
use proptest::prelude::*;

/// Points near the scene and far from it.
fn points() -> impl Strategy<Value = Vec<DVec3>> {
    prop::collection::vec(prop_oneof![3 => point(3.0), 1 => point(40.0)], 24)
}

fn same(a: Sample<f64>, b: Sample<f64>) -> bool {
    let bits =
        |s: Sample<f64>| [s.distance, s.color.x, s.color.y, s.color.z, s.trap].map(f64::to_bits);
    bits(a) == bits(b)
}

/// Checks the bound of the root of `node` against its estimate at `ps`.
fn check_root_bound(node: &Node, ps: &[DVec3]) -> Result<usize, TestCaseError> {
    let ir = Ir::lower(node).expect("strategies give valid scenes");
    let Some(bound) = ir.bounds()[ir.root().index()] else {
        return Ok(0);
    };
    prop_assert!(bound.slope > 0.0 && bound.slope <= 1.0, "{bound:?}");
    let eval = Evaluator::from_ir(ir).with_pruning(false);
    let mut checked = 0;
    for &p in ps {
        let g = bound.distance(p);
        if g > 0.0 {
            let d = eval.distance(p);
            prop_assert!(
                d >= g,
                "{node:?} at {p}: estimate {d} below its bound {g} ({bound:?})"
            );
            checked += 1;
        }
    }
    Ok(checked)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// The guarantee of every bound, on whole random scenes: where the
    /// bound is positive the scene's estimate is at least the bound.
    #[test]
    fn bounds_never_exceed_the_estimate(node in scene_node(3), ps in points()) {
        check_root_bound(&node, &ps)?;
    }

    /// Each fractal, whose bound is a property of its formula rather than
    /// of its shape, at every setting the strategies draw.
    #[test]
    fn fractal_bounds_never_exceed_the_estimate(node in fractal_node(), ps in points()) {
        check_root_bound(&node, &ps)?;
    }

    /// Pruning changes no value: distance, colour and trap are bit for bit
    /// those of the evaluation that skips nothing.
    #[test]
    fn pruned_scenes_equal_unpruned(node in scene_node(4), ps in points()) {
        let pruned = Evaluator::new(&node).expect("valid");
        let full = pruned.clone().with_pruning(false);
        for &p in &ps {
            let (a, b) = (pruned.sample::<f64>(p.into()), full.sample::<f64>(p.into()));
            prop_assert!(same(a, b), "{node:?} at {p}: pruned {a:?}, unpruned {b:?}");
            let (a, b) = (pruned.sample::<f32>(p.as_vec3().into()), full.sample::<f32>(p.as_vec3().into()));
            prop_assert!(
                a.distance.to_bits() == b.distance.to_bits() && a.trap.to_bits() == b.trap.to_bits(),
                "{node:?} at {p} in f32: pruned {a:?}, unpruned {b:?}"
            );
        }
    }
}

/// Unions of many spheres in a row: pruning skips most of them at most
/// points, and the value stays the unpruned one everywhere.
#[test]
fn a_row_of_spheres_is_pruned_exactly() {
    let mut scene = Scene::new(sphere(0.3));
    for i in 1..12 {
        scene = scene.add(sphere(0.3).translate(dvec3(f64::from(i), 0.0, 0.0)));
    }
    let node = scene.geometry.expect("geometry");
    let pruned = Evaluator::new(&node).expect("valid");
    let full = pruned.clone().with_pruning(false);
    let mut n = 0;
    for i in 0..400 {
        let x = -2.0 + 0.04 * f64::from(i);
        for y in [0.0, 0.2, 1.0, 5.0] {
            let p = dvec3(x, y, 0.1);
            assert_eq!(
                pruned.distance(p).to_bits(),
                full.distance(p).to_bits(),
                "{p}"
            );
            n += 1;
        }
    }
    assert_eq!(n, 1600);
}

/// What has a bound and what has none.
#[test]
fn bounds_follow_the_tree() {
    let bound = |n: Node| {
        let ir = Ir::lower(&n).expect("valid");
        ir.bounds()[ir.root().index()]
    };
    let b = bound(sphere(0.5).translate(dvec3(1.0, 2.0, 3.0))).expect("bounded");
    assert!((b.centre - dvec3(1.0, 2.0, 3.0)).length() < 1e-12);
    assert!(b.radius >= 0.5 && b.radius < 0.5001);
    // Rotated a quarter turn about z, (1, 0, 0) goes to (0, 1, 0).
    let b = bound(
        sphere(0.5)
            .translate(dvec3(1.0, 0.0, 0.0))
            .rotate(DVec3::Z, std::f64::consts::FRAC_PI_2),
    )
    .expect("bounded");
    assert!((b.centre - dvec3(0.0, 1.0, 0.0)).length() < 1e-12, "{b:?}");
    // A union holds both; a plane, a dynamic translation and a twist none.
    let b = bound(
        sphere(1.0)
            .translate(dvec3(-2.0, 0.0, 0.0))
            .union(sphere(1.0).translate(dvec3(2.0, 0.0, 0.0))),
    )
    .expect("bounded");
    assert!(
        b.centre.length() < 1e-12 && (3.0..3.001).contains(&b.radius),
        "{b:?}"
    );
    assert!(bound(plane(DVec3::Y, 0.0)).is_none());
    assert!(bound(sphere(1.0).translate(param3("at", dvec3(0.0, 0.0, 0.0)))).is_none());
    // A twist keeps the distance from its axis and the height: the ball
    // around the cylinder its child's ball sweeps.
    let b = bound(sphere(1.0).translate(dvec3(0.5, 0.0, 0.0)).twist(1.0)).expect("bounded");
    assert!(b.centre.length() < 1e-12, "{b:?}");
    assert!((b.radius - 1.5f64.hypot(1.0)).abs() < 1e-12, "{b:?}");
    assert!(bound(sphere(1.0).twist(1.0).translate(param3("at", DVec3::ZERO))).is_none());
    // A subtraction is within its first operand; a union with a plane has
    // no bound.
    let b = bound(sphere(1.0).subtract(plane(DVec3::Y, 0.0))).expect("bounded");
    assert!((1.0..1.001).contains(&b.radius));
    assert!(bound(sphere(1.0).union(plane(DVec3::Y, 0.0))).is_none());
}

/// A smooth union evaluates its dearer operand second, behind a gate, and
/// a gate tests each part of a union tree rather than the sphere around
/// them all; the values stay the unpruned ones.
#[test]
fn smooth_unions_evaluate_the_dearer_operand_second() {
    let far = dvec3(3.0, 0.0, 0.0);
    let node = mandelbulb(8.0)
        .smooth_union(sphere(0.5).translate(far), 0.1)
        .smooth_union(torus(0.4, 0.1).translate(-far), 0.1);
    let scene = Scene::new(node.clone()).compile().expect("valid");
    let source = fractal_sdf::codegen::emit(&scene, &fractal_sdf::codegen::Options::default())
        .expect("valid")
        .source;
    let de = &source[source.find("real DE(").expect("DE")..];
    let de = &de[..de.find("\n}").expect("DE ends")];
    let at = |what: &str| de.find(what).unwrap_or_else(|| panic!("{what} in\n{de}"));
    // The torus, then the sphere, then the bulb: the dearest last, and
    // each behind a gate.
    assert!(at("sd_torus(") < at("sd_sphere("), "{de}");
    assert!(at("sd_sphere(") < at("mandelbulb"), "{de}");
    let gates = de.matches("if (!(g").count();
    assert_eq!(gates, 2, "{de}");
    // The first gate tests the bulb's and the sphere's spheres apart,
    // each lowered by the smoothing above it.
    let first_gate = &de[at("real g")..];
    let first_gate = &first_gate[..first_gate.find('\n').expect("a line")];
    assert!(
        first_gate.starts_with("real g") && first_gate.contains("fmin("),
        "{first_gate}"
    );
    assert_eq!(first_gate.matches("length(").count(), 2, "{first_gate}");

    let pruned = Evaluator::new(&node).expect("valid");
    let full = pruned.clone().with_pruning(false);
    for i in 0..200 {
        let x = -4.0 + 0.04 * f64::from(i);
        for y in [0.0, 0.3, 1.0] {
            let p = dvec3(x, y, 0.05);
            let (a, b) = (pruned.sample::<f64>(p.into()), full.sample::<f64>(p.into()));
            assert_eq!(a.distance.to_bits(), b.distance.to_bits(), "{p}");
            assert_eq!(a.color, b.color, "{p}");
            assert_eq!(a.trap.to_bits(), b.trap.to_bits(), "{p}");
        }
    }
}
