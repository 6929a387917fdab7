//! Dynamic parameters: setting a value changes the distance exactly as
//! baking that value would, and never changes the lowered structure (so
//! no recompilation is needed).

use crate::common::fixtures;
use approx::relative_eq;
use fractal_sdf::cpu;
use fractal_sdf::ir::{Ir, Scalar};
use fractal_sdf::prelude::*;
use fractal_sdf::scene::Kind;
use fractal_sdf::testing::point;
use proptest::prelude::*;

/// [`fixtures::dynamic_scene`] with its parameters baked.
fn baked_dynamic_scene(radius: f64, offset: DVec3, blend: f64) -> Node {
    sphere(radius)
        .translate(offset)
        .smooth_union(cuboid(dvec3(0.3, 0.3, 0.3)), blend)
}

#[test]
fn setting_a_value_changes_the_distance() {
    let mut eval = cpu::Evaluator::new(&sphere(param("r", 1.0))).unwrap();
    let p = dvec3(3.0, 0.0, 0.0);
    assert_eq!(eval.distance(p), 2.0);
    eval.set_param("r", 2.5).unwrap();
    assert_eq!(eval.distance(p), 0.5);
}

#[test]
fn the_fixture_declares_one_slot_per_name() {
    let ir = Ir::lower(&fixtures::dynamic_scene()).unwrap();
    let names: Vec<_> = ir.params().iter().map(|s| s.name.as_str()).collect();
    // Slots follow lowering order: a boolean's `k` before its operands.
    assert_eq!(
        names,
        ["blend", "offset.x", "offset.y", "offset.z", "radius"]
    );
    let values = ir.default_values();
    assert_eq!(values.as_slice(), [0.2, 0.5, 0.0, 0.0, 0.8]);
    let (node, param) = &ir.params()[4].used_at;
    assert_eq!(
        (node.to_string().as_str(), param.as_str()),
        ("smooth_union/a:translate/sphere", "radius")
    );
}

#[test]
fn one_name_drives_every_use() {
    let ring = torus(1.0, param("thickness", 0.1)).union(sphere(param("thickness", 0.1)));
    let mut eval = cpu::Evaluator::new(&ring).unwrap();
    assert_eq!(eval.ir().params().len(), 1);
    eval.set_param("thickness", 0.3).unwrap();
    let baked = cpu::Evaluator::new(&torus(1.0, 0.3).union(sphere(0.3))).unwrap();
    for p in [DVec3::ZERO, dvec3(1.0, 0.5, 0.0), dvec3(0.2, 0.0, 1.4)] {
        assert_eq!(eval.distance(p), baked.distance(p));
    }
}

#[test]
fn a_dynamic_power_uses_the_trigonometric_form_and_follows_its_value() {
    let node = fixtures::mandelbulb_trig_scene();
    let ir = Ir::lower(&node).unwrap();
    let Kind::Mandelbulb(bulb) = ir.node(ir.root()) else {
        panic!("not a Mandelbulb")
    };
    assert!(matches!(bulb.power, Scalar::Dynamic(_)));
    assert_eq!(bulb.power.baked(), None);
    let mut eval = cpu::Evaluator::from_ir(ir);
    let p = dvec3(0.3, 0.9, 0.5);
    let before = eval.distance(p);
    eval.set_param("power", 3.0).unwrap();
    let after = eval.distance(p);
    assert_ne!(before, after);
    // The same as a baked power 3 (which takes the trig-free form), up to
    // the two forms' different roundings: measured 3.6e-16 relative at
    // this point. The tolerance is about 55 times that, room for another
    // platform's `sin` and `cos` rounding differently.
    let baked = cpu::Evaluator::new(&mandelbulb(3.0)).unwrap().distance(p);
    assert!(
        relative_eq!(after, baked, max_relative = 2e-14),
        "{after} vs {baked}"
    );
}

proptest! {
    /// Any valid values, set at run time, give exactly the distances (and
    /// colours) of the scene with those values baked in; the lowered nodes
    /// and the parameter layout stay as they were.
    #[test]
    fn set_values_match_baked_values_and_keep_the_structure(
        radius in 0.0..2.0f64,
        offset in point(2.0),
        blend in 0.0..1.0f64,
        points in prop::collection::vec(point(3.0), 16),
    ) {
        let mut eval = cpu::Evaluator::new(&fixtures::dynamic_scene())?;
        let structure = (eval.ir().nodes().to_vec(), eval.ir().params().to_vec());
        eval.set_param("radius", radius)?;
        eval.set_param("offset.x", offset.x)?;
        eval.set_param("offset.y", offset.y)?;
        eval.set_param("offset.z", offset.z)?;
        eval.set_param("blend", blend)?;
        prop_assert_eq!(&structure.0, &eval.ir().nodes().to_vec());
        prop_assert_eq!(&structure.1, &eval.ir().params().to_vec());
        let baked = cpu::Evaluator::new(&baked_dynamic_scene(radius, offset, blend))?;
        for p in points {
            prop_assert_eq!(eval.sample::<f64>(p.into()), baked.sample::<f64>(p.into()));
            prop_assert_eq!(eval.distance_f32(p.as_vec3()), baked.distance_f32(p.as_vec3()));
        }
    }

    /// Lowering the same scene with different dynamic defaults gives the
    /// same nodes: only the parameter buffer differs.
    #[test]
    fn defaults_do_not_change_the_lowered_nodes(a in 0.0..2.0f64, b in 0.0..2.0f64) {
        let (x, y) = (Ir::lower(&sphere(param("r", a)))?, Ir::lower(&sphere(param("r", b)))?);
        prop_assert_eq!(x.nodes(), y.nodes());
        let (dx, dy) = (x.default_values(), y.default_values());
        prop_assert_eq!(dx.as_slice(), [a]);
        prop_assert_eq!(dy.as_slice(), [b]);
    }

    /// Changing a radius moves the surface: outside a sphere the distance
    /// falls by exactly the growth.
    #[test]
    fn growing_a_dynamic_radius_moves_the_surface(
        r0 in 0.0..1.0f64,
        grow in 0.001..1.0f64,
        p in point(3.0).prop_filter("outside", |p| p.length() > 2.0),
    ) {
        let mut eval = cpu::Evaluator::new(&sphere(param("r", r0)))?;
        let before = eval.distance(p);
        eval.set_param("r", r0 + grow)?;
        let after = eval.distance(p);
        prop_assert!(after < before);
        // A few roundings of values below 6 (an ulp is 8.9e-16): measured
        // worst 5.8e-16 over 256 cases (PROPTEST_RNG_SEED=20261201; 8.7e-16
        // in three other seeds); the tolerance is about 11 times the larger.
        prop_assert!(relative_eq!(before - after, grow, epsilon = 1e-14));
    }
}

/// Every parameter of a deep union chain names its own node's path, the
/// whole way from the root, and an out-of-range value set later names it
/// too: the paths are kept as one shared tree, not written out per slot.
#[test]
fn deep_parameters_name_their_whole_path() {
    let n = 300;
    let node = (0..n)
        .map(|i| sphere(param(format!("r{i}"), 0.1)))
        .reduce(Node::union)
        .unwrap();
    let ir = Scene::new(node).compile().unwrap();
    let slots = ir.params().slots();
    // The chain is left-deep: the first sphere is n − 1 unions down, the
    // last one union down.
    let first = slots[0].used_at.0.to_string();
    assert_eq!(first, format!("union/{}a:sphere", "a:union/".repeat(n - 2)));
    let last = slots[n - 1].used_at.0.to_string();
    assert_eq!(last, "union/b:sphere");
    let mut values = ir.default_values();
    let err = values.set("r0", -1.0).unwrap_err().to_string();
    assert!(err.contains(&first), "{err}");
}
