//! Exact primitives equal their analytic distance within [`TOLERANCE`]
//! (in f64), alone and under translate, rotate and uniform scale. The analytic
//! distances in `common::analytic` are derived independently of
//! `cpu::sdf` (nearest points on segments, circles and triangles, 2D
//! polygons for solids of revolution).

use crate::common::analytic::{self, exact_distance};
use fractal_sdf::cpu;
use fractal_sdf::prelude::*;
use fractal_sdf::scene::Kind;
use fractal_sdf::scene::octahedron;
use fractal_sdf::scene::{capped_cone, hex_prism, link, round_cone};
use fractal_sdf::testing::{self, Failure, check_exact, point};
use proptest::prelude::*;

/// The largest error allowed, relative to `max(1, |d|)`: the evaluator and
/// the independent oracle compute the same distance by different
/// formulas, each a few roundings. Measured worst 5.8e-15 over 184,000
/// points across the tests below (PROPTEST_RNG_SEED=20261201; 5.9e-15 at
/// most with seeds 1 to 3); the tolerance is about 17 times that.
const TOLERANCE: f64 = 1e-13;

/// The origin, points on the axes and near the shapes' surfaces.
fn spicy_points() -> Vec<DVec3> {
    let mut points = vec![DVec3::ZERO];
    for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
        for t in [-2.0, -1.0, -0.5, -1e-9, 1e-9, 0.25, 0.5, 1.0, 1.5, 3.0] {
            points.push(axis * t);
        }
    }
    points
}

fn check_node(node: &Node, random: &[DVec3]) -> Result<(), Failure> {
    let analytic = |p| exact_distance(node, p).expect("an exact node");
    check_exact(node, analytic, random, TOLERANCE)?;
    check_exact(node, analytic, &spicy_points(), TOLERANCE)?;
    Ok(())
}

macro_rules! exact {
    ($($name:ident: $strategy:expr;)*) => {
        proptest! {
            $(
                #[test]
                fn $name(
                    node in $strategy,
                    points in prop::collection::vec(point(3.0), 32),
                ) {
                    check_node(&node, &points)?;
                }
            )*
        }
    };
}

exact! {
    sphere_is_exact: testing::sphere_node();
    cuboid_is_exact: testing::cuboid_node();
    round_box_is_exact: testing::round_box_node();
    torus_is_exact: testing::torus_node();
    cylinder_is_exact: testing::cylinder_node();
    capsule_is_exact: testing::capsule_node();
    plane_is_exact: testing::plane_node();
    octahedron_is_exact: testing::octahedron_node();
    capped_cone_is_exact: testing::capped_cone_node();
    hex_prism_is_exact: testing::hex_prism_node();
    round_cone_is_exact: testing::round_cone_node();
    link_is_exact: testing::link_node();
    cut_sphere_is_exact: testing::cut_sphere_node();
    solid_angle_is_exact: testing::solid_angle_node();
    capped_torus_is_exact: testing::capped_torus_node();
    triangle_is_exact: testing::triangle_node();
    quad_is_exact: testing::quad_node();
    pyramid_is_exact: testing::pyramid_node();
    rhombus_is_exact: testing::rhombus_node();
    tri_prism_is_exact: testing::tri_prism_node();
    rounded_cylinder_is_exact: testing::rounded_cylinder_node();
    cone_is_exact: testing::cone_node();
    infinite_cylinder_is_exact: testing::infinite_cylinder_node();
    infinite_cone_is_exact: testing::infinite_cone_node();
    cut_hollow_sphere_is_exact: testing::cut_hollow_sphere_node();
    death_star_is_exact: testing::death_star_node();
    cylinder_between_is_exact: testing::cylinder_between_node();
    cone_between_is_exact: testing::cone_between_node();
    round_cone_between_is_exact: testing::round_cone_between_node();
    extrude_is_exact: testing::extrude_node();
    revolve_is_exact: testing::revolve_node();
    transformed_primitives_are_exact: testing::exact_node();
}

proptest! {
    /// Points close to the surface, where sign and nearest-feature
    /// decisions are made.
    #[test]
    fn exact_near_the_surface(
        node in testing::exact_node(),
        rays in prop::collection::vec(testing::ray(2.0), 8),
    ) {
        let eval = cpu::Evaluator::new(&node)?;
        // Walk each ray to its surface crossing, then probe both sides.
        let mut points = Vec::new();
        for ray in rays {
            let hit = cpu::march(&eval, ray, &cpu::MarchSettings::default().footprint_base(1e-7).max_distance(20.0));
            if hit.hit {
                let p = ray.origin + ray.direction * hit.depth;
                for s in [-1e-3, -1e-6, 0.0, 1e-6, 1e-3] {
                    points.push(p + ray.direction * s);
                }
            }
        }
        // A shape no ray reaches (a zero-size one) has nothing near its
        // surface to probe here: `degenerate_shapes_are_exact` covers it.
        prop_assume!(!points.is_empty(), "no ray reached the surface");
        check_node(&node, &points)?;
    }
}

#[test]
fn known_values() {
    let cases: [(Node, DVec3, f64); 13] = [
        (sphere(1.0), dvec3(3.0, 0.0, 0.0), 2.0),
        (cuboid(dvec3(1.0, 2.0, 3.0)), dvec3(4.0, 6.0, 3.0), 5.0),
        (cuboid(dvec3(1.0, 2.0, 3.0)), DVec3::ZERO, -1.0),
        (torus(1.0, 0.25), dvec3(1.0, 0.0, 0.0), -0.25),
        (cylinder(1.0, 1.0), dvec3(4.0, 5.0, 0.0), 5.0),
        (plane(dvec3(0.0, 2.0, 0.0), 1.0), dvec3(7.0, 2.0, 3.0), 3.0),
        (octahedron(1.0), dvec3(1.0, 1.0, 1.0), 2.0 / 3f64.sqrt()),
        (capped_cone(1.0, 1.0, 0.0), dvec3(0.0, 2.0, 0.0), 1.0),
        // Beyond a flat side, and beyond a cap.
        (hex_prism(1.0, 2.0), dvec3(0.0, 0.5, 3.0), 2.0),
        (hex_prism(1.0, 2.0), dvec3(0.0, 3.0, 0.0), 1.0),
        // Beyond the top ball, and level with the bottom one.
        (round_cone(1.0, 1.0, 0.5), dvec3(0.0, 4.0, 0.0), 2.5),
        (round_cone(1.0, 1.0, 0.5), dvec3(0.0, -1.0, 3.0), 2.0),
        // Beside a straight side.
        (link(1.0, 0.5, 0.25), dvec3(2.0, 0.5, 0.0), 1.25),
    ];
    for (node, p, expected) in cases {
        // Distances up to 5, all but one (2 / sqrt(3)) exact in binary:
        // measured 0 for the evaluator and the oracle alike; the tolerance
        // is about 11 ulps of 5.
        let d = cpu::Evaluator::new(&node).unwrap().distance(p);
        assert!(
            (d - expected).abs() < 1e-14,
            "{node:?} at {p}: {d} != {expected}"
        );
        let independent = exact_distance(&node, p).unwrap();
        assert!(
            (independent - expected).abs() < 1e-14,
            "{node:?}: oracle {independent}"
        );
    }
}

#[test]
fn degenerate_shapes_are_exact() {
    let nodes = [
        sphere(0.0),
        cuboid(DVec3::ZERO),
        cuboid(dvec3(1.0, 0.0, 0.5)),
        round_box(dvec3(0.5, 0.5, 0.5), 0.5),
        torus(0.0, 0.5),
        torus(1.0, 0.0),
        cylinder(0.0, 1.0),
        cylinder(1.0, 0.0),
        capsule(DVec3::ONE, DVec3::ONE, 0.5),
        octahedron(0.0),
        capped_cone(0.0, 1.0, 0.5),
        capped_cone(1.0, 0.0, 0.0),
        capped_cone(1.0, 1.0, 1.0),
        capped_cone(1.0, 0.0, 1.0),
        hex_prism(0.0, 1.0),
        hex_prism(1.0, 0.0),
        round_cone(0.0, 1.0, 0.5),
        round_cone(0.5, 1.0, 0.0),
        round_cone(0.5, 0.0, 1.0),
        round_cone(0.2, 1.0, 0.5),
        link(0.0, 0.5, 0.25),
        link(1.0, 0.0, 0.25),
        link(1.0, 0.5, 0.0),
    ];
    let mut grid = Vec::new();
    for i in -4..=4 {
        for j in -4..=4 {
            for k in -4..=4 {
                grid.push(
                    dvec3(f64::from(i), f64::from(j), f64::from(k)) * 0.3 + dvec3(1e-3, 0.0, 0.0),
                );
            }
        }
    }
    for node in nodes {
        if let Err(e) = check_node(&node, &grid) {
            panic!("{node:?}: {e}");
        }
    }
}

/// A torus whose tube is thicker than its major radius overlaps itself
/// around the axis: there the formula is a bound, not the distance (which
/// is why the exact tests draw `minor <= major`). At the centre of
/// `torus(0.1, 0.5)` the formula gives `0.1 - 0.5` while the surface is
/// `sqrt(0.5² - 0.1²)` away along the axis; everywhere it never
/// overestimates the distance to the points within 0.5 of the circle.
#[test]
fn a_self_overlapping_torus_is_a_bound() {
    let node = torus(0.1, 0.5);
    let eval = cpu::Evaluator::new(&node).unwrap();
    let centre = eval.distance(DVec3::ZERO);
    let depth = (0.5f64 * 0.5 - 0.1 * 0.1).sqrt();
    assert!((centre + 0.4).abs() < 1e-15, "{centre}");
    assert!(-centre < depth, "{centre} against the depth {depth}");
    let inside = |p: DVec3| analytic::circle_distance(p, 0.1) <= 0.5;
    let points = testing::near_surface_points(inside, 1.0, 0.3, 256, 7);
    testing::check_never_overestimates(&node, inside, &points, 32).unwrap();
}

/// A link whose tube is thicker than its half circles overlaps itself:
/// the formula is then a bound, never above the distance to the points
/// within the tube's radius of the stadium curve.
#[test]
fn a_self_overlapping_link_is_a_bound() {
    let node = link(0.5, 0.1, 0.4);
    let inside = |p: DVec3| analytic::link_curve_distance(p, 0.5, 0.1) <= 0.4;
    let points = testing::near_surface_points(inside, 1.5, 0.3, 256, 11);
    testing::check_never_overestimates(&node, inside, &points, 32).unwrap();
    // Between the straight sides the formula gives 0.1 - 0.4; the surface
    // is sqrt(0.4² - 0.1²) away along z.
    let centre = cpu::Evaluator::new(&node).unwrap().distance(DVec3::ZERO);
    assert!(-centre < (0.4f64 * 0.4 - 0.1 * 0.1).sqrt(), "{centre}");
}

#[test]
fn the_oracle_agrees_with_brute_force_on_the_ellipsoid_of_a_sphere() {
    // The numerical ellipsoid distance used by the bound tests, checked on
    // a sphere where the answer is known.
    for p in [
        dvec3(2.0, 0.3, 0.5),
        dvec3(0.1, -0.2, 0.3),
        dvec3(0.0, 0.0, 0.9),
    ] {
        // Bisection to the last bit: measured worst 4.4e-16 at these 3
        // points; the tolerance is about 20 times that.
        let d = analytic::ellipsoid_distance(p, DVec3::splat(1.0));
        assert!((d - (p.length() - 1.0)).abs() < 1e-14, "{p}: {d}");
    }
}

/// The evaluator's conveniences: the f32 distance is the f32 sample's, and
/// the normal of a sphere points away from its centre.
#[test]
fn f32_distances_and_normals() {
    let eval = cpu::Evaluator::new(&sphere(1.0).translate(dvec3(0.5, 0.0, 0.0))).unwrap();
    for p in [
        dvec3(2.0, 1.0, -1.0),
        dvec3(0.5, 0.2, 0.0),
        dvec3(-3.0, 0.0, 0.25),
    ] {
        let expected = (p - dvec3(0.5, 0.0, 0.0)).length() - 1.0;
        let d32 = eval.distance_f32(p.as_vec3());
        // f32 arithmetic on f32-rounded inputs: a few ulps of values near 3.
        assert!(
            (f64::from(d32) - expected).abs() < 1e-6,
            "{p}: {d32} vs {expected}"
        );
        let n = eval.normal(p, 1e-5);
        let outward = (p - dvec3(0.5, 0.0, 0.0)).normalize();
        // Central differences of an exact distance: error O(h^2).
        assert!(n.abs_diff_eq(outward, 1e-8), "{p}: {n} vs {outward}");
    }
}

/// The listing's exact primitives (`fractal-sdf nodes`) are exactly the
/// primitives the tests above hold to an oracle: every kind
/// [`testing::exact_primitive`] draws, by its file name.
#[test]
fn the_listing_calls_exact_only_the_primitives_tested_here() {
    use proptest::strategy::{Strategy, ValueTree};
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let strategy = testing::exact_primitive();
    let mut drawn: Vec<String> = (0..2000)
        .map(|_| {
            let node = strategy.new_tree(&mut runner).unwrap().current();
            // The file name of `round_box` is `RoundBox`.
            node.kind()
                .name()
                .split('_')
                .map(|w| w[..1].to_uppercase() + &w[1..])
                .collect()
        })
        .collect();
    drawn.sort();
    drawn.dedup();
    let mut listed: Vec<String> = fractal_sdf::file::node_kinds()
        .into_iter()
        .filter(|n| n.exact == Some(true))
        .map(|n| n.name.to_string())
        .collect();
    listed.sort();
    assert_eq!(drawn, listed);
}

/// The twelve bars of a box frame of half extents `b` and thickness `t`:
/// each a box along one axis, in one of the four corners of the other two.
fn frame_bars(b: DVec3, t: f64) -> Vec<(DVec3, DVec3)> {
    let mut bars = Vec::new();
    for axis in 0..3 {
        let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
        for (sj, sk) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            let (mut centre, mut half) = (DVec3::ZERO, DVec3::splat(0.5 * t));
            centre[j] = sj * (b[j] - 0.5 * t);
            centre[k] = sk * (b[k] - 0.5 * t);
            half[axis] = b[axis];
            bars.push((centre, half));
        }
    }
    bars
}

proptest! {
    /// Quilez's octahedron bound: against the exact octahedron's oracle,
    /// the same sign and never a larger magnitude; exact out from a face's
    /// centre.
    #[test]
    fn octahedron_bound_never_exceeds_the_distance(
        node in testing::octahedron_bound_node(),
        points in prop::collection::vec(point(3.0), 48),
    ) {
        let Kind::OctahedronBound { size } = node.kind() else {
            unreachable!("the strategy draws octahedron bounds")
        };
        let s = size.default_value();
        let eval = cpu::Evaluator::new(&node)?;
        for &p in &points {
            let (d, oracle) = (eval.distance(p), analytic::octahedron_distance(p, s));
            prop_assert!(
                d * oracle > 0.0 || oracle.abs() <= TOLERANCE,
                "sign at {p}: {d} against {oracle}"
            );
            prop_assert!(
                d.abs() <= oracle.abs() + TOLERANCE,
                "above the distance at {p}: {d} against {oracle}"
            );
        }
        // Exact where the nearest point is inside a face: out from a
        // face's centre along its normal.
        let p = DVec3::splat(s / 3.0) + DVec3::ONE * (0.5 / 3f64.sqrt());
        prop_assert!((eval.distance(p) - 0.5).abs() <= TOLERANCE);
    }

    /// A box frame is the union of its twelve bars: outside, its distance
    /// is the nearest bar's (within the exact tolerance); inside, it never
    /// exceeds the depth to the nearest point outside every bar (sampled).
    #[test]
    fn box_frame_is_exact_outside_and_a_bound_inside(
        node in testing::box_frame_node(),
        points in prop::collection::vec(point(1.5), 48),
    ) {
        let Kind::BoxFrame { half_extents, thickness } = node.kind() else {
            unreachable!("the strategy draws box frames")
        };
        let bars = frame_bars(half_extents.default_value(), thickness.default_value());
        let nearest = |p: DVec3| {
            bars.iter()
                .map(|(c, h)| analytic::box_distance(p - *c, *h))
                .fold(f64::INFINITY, f64::min)
        };
        let eval = cpu::Evaluator::new(&node)?;
        for &p in &points {
            let (d, oracle) = (eval.distance(p), nearest(p));
            if oracle > 0.0 {
                prop_assert!(
                    (d - oracle).abs() <= TOLERANCE * oracle.max(1.0),
                    "outside at {p}: {d} against {oracle}"
                );
            }
        }
        // Inside a frame with room for sampled points (not a flat or thin
        // one), about its bars.
        let (b, t) = (half_extents.default_value(), thickness.default_value());
        if t >= 0.05 {
            let inside = |p: DVec3| nearest(p) <= 0.0;
            let near = testing::near_surface_points(inside, 1.1 * b.length(), t, 64, 3);
            testing::check_never_overestimates(&node, inside, &near, 32)?;
        }
    }
}
