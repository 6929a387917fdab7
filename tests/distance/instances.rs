//! Unions of many alike shapes walked through a bounding volume hierarchy,
//! in the kernels and in the CPU reference: on random sets of instances
//! both give the plain union's distance and colour, which the CPU reference
//! computes operand by operand with pruning off; instances moved by
//! dynamic parameters are found where they moved to (the hierarchies
//! fitted or built again); and the program holds one copy of an
//! instance's code however many there are.

use crate::gpu;

use fractal_sdf::codegen::{self, MIN_HIERARCHY, Options};
use fractal_sdf::cpu;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{DeviceKind, DeviceSelector, PointEvaluator};
use fractal_sdf::scene::{Param3, param3};
use fractal_sdf::testing::{check_device_matches_cpu, point, random_points};
use proptest::prelude::*;

/// One instance: its centre, its size, and a colour.
type Placed = (DVec3, f64, f64);

/// The instance of `kind` (a sphere, a box or a torus) at `placed`.
fn shape(kind: u8, (centre, size, hue): Placed) -> Node {
    let node = match kind {
        0 => sphere(size),
        1 => cuboid(dvec3(size, 0.5 * size, 0.8 * size)),
        _ => torus(size, 0.3 * size),
    };
    node.translate(centre).color(dvec3(hue, 1.0 - hue, 0.5))
}

/// A set of instances: some spread over the region, some crowded round one
/// point (overlapping, so that ties and nested boxes occur), and copies of
/// a few (exact ties, which the later one wins).
fn instances() -> impl Strategy<Value = (u8, Vec<Placed>)> {
    let placed = (point(2.0), 0.01..0.4f64, 0.0..1.0f64);
    let crowded = (point(0.2), 0.05..0.3f64, 0.0..1.0f64);
    (
        0u8..3,
        prop::collection::vec(placed, MIN_HIERARCHY..300),
        prop::collection::vec(crowded, 0..40),
        0usize..4,
    )
        .prop_map(|(kind, mut spread, crowded, copies)| {
            spread.extend(crowded);
            let again: Vec<Placed> = spread.iter().take(copies).copied().collect();
            spread.extend(again);
            (kind, spread)
        })
}

/// Points everywhere, and on, just off and just inside every instance's
/// bounding sphere, where the walk decides.
fn points_near(set: &[Placed], seed: u64) -> Vec<DVec3> {
    let mut points = random_points(1000, 2.6, seed);
    let directions = random_points(set.len(), 1.0, seed + 1);
    for (&(c, r, _), d) in set.iter().zip(directions) {
        let u = d.try_normalize().unwrap_or(DVec3::X);
        for k in [0.5, 0.99, 1.0, 1.01, 1.5, 3.0] {
            points.push(c + u * (r * 1.3 * k));
        }
    }
    points
}

fn tolerance(precision: Precision, kind: DeviceKind) -> f64 {
    match (precision, kind) {
        (Precision::F32, DeviceKind::Cpu) => 2e-5,
        (Precision::F64, DeviceKind::Cpu) => 1e-14,
        (Precision::F64, _) => 1e-10,
        _ => 1e-4,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]

    /// The walk skips a box only where the bounds say nothing in it can be
    /// nearer than what was found: the union's value and colour are the
    /// plain union's at every point, in both precisions. With a floor
    /// through the set and a shape of another kind in the union, the walk
    /// starts from their distance (negative below the floor).
    #[test]
    fn a_walked_union_is_the_plain_union(
        (kind, set) in instances(),
        seed in 0u64..1000,
        floor in prop::option::of(-1.2..1.2f64),
    ) {
        let mut node = set
            .iter()
            .map(|&placed| shape(kind, placed))
            .reduce(Node::union)
            .expect("instances");
        let mut points = points_near(&set, seed);
        if let Some(h) = floor {
            node = node
                .union(plane(DVec3::Y, -h).color(dvec3(0.9, 0.9, 0.9)))
                .union(capsule(dvec3(-0.6, h, -0.2), dvec3(0.6, h, 0.1), 0.05));
            points.extend((0..200).map(|i| {
                let x = f64::from(i % 20) * 0.12 - 1.2;
                let z = f64::from(i / 20) * 0.25 - 1.2;
                dvec3(x, h + 0.02 * f64::from(i % 7) - 0.06, z)
            }));
        }
        let walked = cpu::Evaluator::new(&node).unwrap();
        let tested = walks_like_plain(&walked, &points);
        prop_assert!(tested.is_ok(), "{}", tested.unwrap_err());
        let source = codegen::emit(&Scene::new(node.clone()).compile().unwrap(), &Options::default())
            .unwrap();
        prop_assert!(source.source.contains("walked through"), "no hierarchy");
        let tested = device_matches_cpu(&node, &points);
        prop_assert!(tested.is_ok(), "{}", tested.unwrap_err());
    }
}

/// The CPU reference's walk of `walked`'s unions gives, at every point,
/// in both precisions, the very sample (distance, colour, object,
/// material) that evaluating every operand in turn gives.
fn walks_like_plain(walked: &cpu::Evaluator, points: &[DVec3]) -> Result<(), String> {
    let plain = walked.clone().with_pruning(false);
    for p in points {
        let (a, b) = (
            walked.sample::<f64>((*p).into()),
            plain.sample::<f64>((*p).into()),
        );
        if a != b {
            return Err(format!("F64 at {p}: walked {a:?}, plain {b:?}"));
        }
        let q = p.as_vec3().into();
        let (a, b) = (walked.sample::<f32>(q), plain.sample::<f32>(q));
        if a != b {
            return Err(format!("F32 at {p}: walked {a:?}, plain {b:?}"));
        }
    }
    Ok(())
}

/// Spheres on a ring, each placed by a dynamic parameter of its own.
fn moving(n: usize) -> (Node, Vec<DVec3>) {
    let at: Vec<DVec3> = (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            dvec3(t.cos(), 0.3 * (3.0 * t).sin(), t.sin()) * 1.5
        })
        .collect();
    let node = at
        .iter()
        .enumerate()
        .map(|(i, &c)| sphere(0.05 + 0.002 * i as f64).translate(param3(&format!("c{i}"), c)))
        .reduce(Node::union)
        .expect("spheres");
    (node, at)
}

/// Instances whose positions are dynamic share one loop and one hierarchy;
/// moved anywhere (scattered, gathered, swapped far across the tree), the
/// CPU reference's hierarchy, built again at the new values, finds each
/// where it now is (its samples are those of every sphere evaluated in
/// turn), and so does the device's, fitted again: its distances are the
/// CPU reference's.
#[test]
fn moved_instances_are_found_where_they_moved() {
    let n = 200;
    let (node, at) = moving(n);
    let mut cpu = cpu::Evaluator::new(&node).unwrap();
    let scattered = random_points(n, 2.0, 7);
    for (round, to) in [at[..].to_vec(), scattered.clone()].iter().enumerate() {
        let mut points = random_points(500, 3.5, 3 + round as u64);
        for (i, c) in to.iter().enumerate() {
            for (axis, v) in ["x", "y", "z"].iter().zip(c.to_array()) {
                cpu.set_param(&format!("c{i}.{axis}"), v).unwrap();
            }
            points.extend([*c, *c + unit_vector_at(i) * 0.06]);
        }
        walks_like_plain(&cpu, &points).unwrap();
    }
    let Some(device) = gpu::device() else { return };
    let compiled = Scene::new(node.clone()).compile().unwrap();
    let source = codegen::emit(&compiled, &Options::default()).unwrap();
    assert!(source.source.contains("walked through"), "no hierarchy");
    assert!(!source.tables.is_baked());
    assert_eq!(
        source.source.matches("sd_sphere(").count(),
        3,
        "one call a function"
    );
    let precision = Precision::F32;
    let tolerance = tolerance(precision, device.kind);
    let mut gpu = PointEvaluator::new(&node, precision, &DeviceSelector::auto()).unwrap();
    let moves: [Box<dyn Fn(usize) -> DVec3>; 4] = [
        Box::new(|i| at[i]),
        Box::new(|i| scattered[i]),
        Box::new(|i| at[i] * 0.1),
        Box::new(|i| at[(i + n / 2) % n] + dvec3(0.0, 2.0, 0.0)),
    ];
    for (round, to) in moves.iter().enumerate() {
        let mut points = random_points(2000, 3.5, 11 + round as u64);
        for i in 0..n {
            let c = to(i);
            for (axis, v) in ["x", "y", "z"].iter().zip(c.to_array()) {
                let name = format!("c{i}.{axis}");
                gpu.set_param(&name, v).unwrap();
                cpu.set_param(&name, v).unwrap();
            }
            let u = unit_vector_at(i);
            points.extend([c, c + u * 0.06, c + u * 0.3]);
        }
        let got = gpu.distances(&points).unwrap();
        for (p, g) in points.iter().zip(got) {
            let c = f64::from(cpu.distance_f32(p.as_vec3()));
            assert!(
                (g - c).abs() <= tolerance * c.abs().max(1.0),
                "round {round}, at {p}: device {g}, CPU {c}"
            );
        }
    }
}

/// A walked union with another walked union among its operands (boxes,
/// moved and rounded as one) and a floor: `DE` writes each walk after the
/// union's other operands, from their distance, while every function lays
/// out the two groups' tables in the same order (the debug build checks
/// it). The device's distances and colours are the CPU reference's.
#[test]
#[allow(clippy::cast_precision_loss)]
fn a_walked_union_within_a_walked_union_reads_its_own_table() {
    let boxes = (0..40)
        .map(|i| {
            let a = i as f64 * 0.31;
            cuboid(dvec3(0.08, 0.05, 0.06))
                .translate(dvec3(a.cos(), 0.4 * (2.0 * a).sin(), a.sin()))
                .color(dvec3(0.9, 0.3, 0.1))
        })
        .reduce(Node::union)
        .expect("boxes")
        .round(0.02)
        .translate(dvec3(0.3, 0.5, 0.0));
    let node = (0..48)
        .map(|i| {
            let a = i as f64 * 0.47;
            sphere(0.1 + 0.002 * i as f64)
                .translate(dvec3(1.2 * a.sin(), 0.3 * a.cos(), 1.2 * (0.7 * a).cos()))
                .color(dvec3(0.1, 0.4, 0.9))
        })
        .reduce(Node::union)
        .expect("spheres")
        .union(boxes)
        .union(plane(DVec3::Y, 0.45));
    let source = codegen::emit(
        &Scene::new(node.clone()).compile().unwrap(),
        &Options::default(),
    )
    .unwrap();
    assert_eq!(
        source.source.matches("walked through").count(),
        4,
        "two walks in each function"
    );
    let mut points = random_points(400, 1.8, 7);
    points.extend((0..200).map(|i| {
        dvec3(
            f64::from(i % 20) * 0.1 - 1.0,
            -0.45,
            f64::from(i / 20) * 0.2 - 1.0,
        )
    }));
    device_matches_cpu(&node, &points).unwrap();
}

/// The device's distances and colours of `node` at `points` are the CPU
/// reference's, in single precision and, where the device has it, double
/// (nothing to check without a device).
fn device_matches_cpu(node: &Node, points: &[DVec3]) -> Result<(), String> {
    let Some(device) = gpu::device() else {
        return Ok(());
    };
    for precision in [Precision::F32, Precision::F64] {
        if precision == Precision::F64 && !gpu::fp64(&device) {
            continue;
        }
        let tolerance = tolerance(precision, device.kind);
        check_device_matches_cpu(node, &DeviceSelector::auto(), precision, points, tolerance)
            .map_err(|e| format!("{precision:?}: {e}"))?;
    }
    Ok(())
}

/// A fixed direction per index, spread over the sphere.
fn unit_vector_at(i: usize) -> DVec3 {
    let t = i as f64;
    dvec3((t * 2.4).cos(), (t * 0.7).sin(), (t * 1.3).sin())
        .try_normalize()
        .unwrap_or(DVec3::Y)
}

/// A thousand spheres, baked or dynamic, are one loop over a table walked
/// through a hierarchy: the sphere's function is defined once and called
/// once in each of the two scene functions, not a thousand times.
#[test]
fn a_thousand_spheres_are_one_walked_loop() {
    for dynamic in [false, true] {
        let node = (0..1000)
            .map(|i| {
                // No sphere at the origin: a zero translation vanishes.
                let c = dvec3(
                    f64::from(i % 10),
                    f64::from(i / 10 % 10),
                    f64::from(i / 100),
                ) + 0.5;
                let placed: Param3 = if dynamic {
                    param3(&format!("c{i}"), c)
                } else {
                    c.into()
                };
                sphere(0.3).translate(placed)
            })
            .reduce(Node::union)
            .expect("spheres");
        let compiled = Scene::new(node).compile().unwrap();
        let source = codegen::emit(&compiled, &Options::default()).unwrap();
        assert_eq!(source.source.matches("sd_sphere(").count(), 3, "{dynamic}");
        assert_eq!(
            source.source.matches("walked through").count(),
            2,
            "{dynamic}"
        );
        assert!(
            source.source.len() < 60_000,
            "{} bytes",
            source.source.len()
        );
        assert_eq!(source.tables.is_baked(), !dynamic);
    }
}

/// Far out, under a scale that makes the walk's coordinates huge (beyond
/// the precisions' limits, up to where the spheres' own lengths would
/// overflow single precision), the walked union is still the plain union:
/// finite, and the CPU reference's value.
#[test]
fn a_walked_union_under_a_tiny_scale_is_finite_far_out() {
    let Some(device) = gpu::device() else { return };
    let node = (0..40)
        .map(|i| {
            let t = f64::from(i) / 40.0 * std::f64::consts::TAU;
            sphere(0.1).translate(dvec3(t.cos(), t.sin(), 0.0))
        })
        .reduce(Node::union)
        .expect("spheres")
        .scale(1e-6);
    let points = [
        dvec3(1e13, 0.0, 0.0),
        dvec3(-1e12, 3e12, 0.5),
        dvec3(0.0, 0.0, 1.0),
    ];
    let tolerance = tolerance(Precision::F32, device.kind);
    let tested = check_device_matches_cpu(
        &node,
        &DeviceSelector::auto(),
        Precision::F32,
        &points,
        tolerance,
    );
    assert!(tested.is_ok(), "{}", tested.unwrap_err());
}
