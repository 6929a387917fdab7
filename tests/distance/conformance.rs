//! Conformance: every node type's OpenCL twin and WGSL twin, and composite
//! scenes, agree with the CPU reference on 10,000 random points plus
//! "spicy" ones (the origin, the axes, fractal bailout spheres, ±1e6), in
//! both precisions on OpenCL and in single precision on wgpu, and are
//! finite everywhere.
//!
//! Tolerances: the device result `g` and the CPU reference `c` (evaluated in
//! the same precision) must satisfy `|g - c| <= tol * max(1, |c|)` at every
//! point, colours too; see [`tolerance`] for the values and where they come
//! from. The check is the public `testing::check_device_matches_cpu`, and
//! each run prints the worst error it measured.

use crate::gpu;

use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{DeviceInfo, DeviceKind, DeviceSelector, PointEvaluator};
use fractal_sdf::scene::Axis;
use fractal_sdf::scene::Mandelbulb;
use fractal_sdf::scene::QuaternionJulia;
use fractal_sdf::scene::ellipsoid;
use fractal_sdf::scene::octahedron;
use fractal_sdf::scene::param3;
use fractal_sdf::scene::{CustomShape, Rule};
use fractal_sdf::scene::{
    Hybrid, HybridOp, Kifs, KifsFold, Mandelbox, OrbitColoring, Palette, Profile, Trap, box_frame,
    capped_cone, capped_torus, cone, cone_between, cut_hollow_sphere, cut_sphere, cylinder_between,
    death_star, extrude, hex_prism, infinite_cone, infinite_cylinder, kifs, link, pyramid, quad,
    revolve, rhombus, round_cone, round_cone_between, rounded_cylinder, solid_angle, tri_prism,
    triangle,
};
use fractal_sdf::testing::{check_device_matches_cpu, random_points, spicy_points};

fn gyroid() -> CustomShape {
    CustomShape::new(
        "gyroid",
        &[("thickness", Rule::NonNegative)],
        |p, a| {
            let g = p.x.sin() * p.y.cos() + p.y.sin() * p.z.cos() + p.z.sin() * p.x.cos();
            g.abs() / 1.5 - a[0]
        },
        "real g = sin(p.x) * cos(p.y) + sin(p.y) * cos(p.z) + sin(p.z) * cos(p.x);\n\
         return fabs(g) / R(1.5) - thickness;",
    )
    .expect("a valid custom shape")
}

/// Wide unions emitted as loops over tables: 40 coloured spheres and 24
/// scaled, rounded boxes (two groups of instances, one with a dynamic
/// rounding radius), among a torus and a plane that stay unrolled.
fn instanced() -> Node {
    let mut scene = Scene::new(torus(0.5, 0.1)).add(plane(DVec3::Y, 2.0));
    for i in 0..40 {
        let t = f64::from(i) / 40.0;
        let at = dvec3((t * 19.0).sin(), (t * 7.0).cos(), 2.0 * t - 1.0) * 1.5;
        scene = scene.add(
            sphere(0.1 + 0.2 * t)
                .translate(at)
                .color(dvec3(t, 1.0 - t, 0.5)),
        );
    }
    for i in 0..24 {
        let t = f64::from(i) / 24.0;
        let at = dvec3(2.0 * t - 1.0, 0.4, (t * 11.0).sin());
        let block = cuboid(dvec3(0.2, 0.1 + t * 0.1, 0.15)).round(param("rounding", 0.03));
        scene = scene.add(block.scale(0.5 + t).translate(at));
    }
    scene.geometry.expect("the scene has geometry")
}

/// One node of every kind, and composites.
fn nodes() -> Vec<(&'static str, Node)> {
    let s = || sphere(0.6);
    let b = || cuboid(dvec3(0.5, 0.3, 0.4));
    let mut v = vec![
        ("sphere", sphere(0.8)),
        ("cuboid", b()),
        ("round_box", round_box(dvec3(0.5, 0.4, 0.3), 0.1)),
        ("torus", torus(0.7, 0.2)),
        ("cylinder", cylinder(0.4, 0.6)),
        (
            "capsule",
            capsule(dvec3(-0.3, -0.5, 0.1), dvec3(0.4, 0.6, -0.2), 0.25),
        ),
        ("plane", plane(dvec3(0.2, 1.0, -0.3), 0.4)),
        // A dynamic normal reaches the kernel as given and is normalised
        // there.
        (
            "plane_dynamic_normal",
            plane(param3("n", dvec3(0.4, 2.0, -0.6)), 0.4),
        ),
        ("octahedron", octahedron(0.9)),
        ("capped_cone", capped_cone(0.6, 0.5, 0.2)),
        ("hex_prism", hex_prism(0.5, 0.7)),
        ("round_cone", round_cone(0.5, 0.4, 0.15)),
        ("round_cone_ball", round_cone(0.1, 0.6, 0.2)),
        ("link", link(0.4, 0.35, 0.1)),
        ("cut_sphere", cut_sphere(0.6, 0.25)),
        ("cut_sphere_low", cut_sphere(0.6, -0.4)),
        ("solid_angle", solid_angle(0.7, 0.6)),
        ("solid_angle_wide", solid_angle(2.4, 0.6)),
        ("capped_torus", capped_torus(1.0, 0.6, 0.15)),
        (
            "capped_torus_dynamic_wide",
            capped_torus(param("arc", 2.6), 0.6, param("tube", 0.2)),
        ),
        (
            "triangle",
            triangle(
                dvec3(-0.5, -0.3, 0.1),
                dvec3(0.5, -0.2, -0.2),
                dvec3(0.0, 0.6, 0.2),
                0.05,
            ),
        ),
        (
            "quad_dynamic",
            quad(
                dvec3(-0.5, -0.4, 0.0),
                dvec3(0.5, -0.4, 0.0),
                param3("quad_c", dvec3(0.4, 0.5, 0.1)),
                dvec3(-0.4, 0.4, 0.1),
                param("quad_t", 0.04),
            ),
        ),
        ("pyramid", pyramid(0.5, 0.8)),
        (
            "box_frame_dynamic",
            box_frame(dvec3(0.6, 0.4, 0.5), param("frame_t", 0.08)),
        ),
        ("rhombus", rhombus(0.6, 0.3, 0.1, 0.05)),
        ("tri_prism", tri_prism(0.3, 0.5)),
        (
            "rounded_cylinder_dynamic",
            rounded_cylinder(0.5, param("cyl_h", 0.4), param("cyl_e", 0.1)),
        ),
        ("cone", cone(0.4, 0.8)),
        ("infinite_cylinder", infinite_cylinder(0.3)),
        ("infinite_cone", infinite_cone(0.5)),
        ("cut_hollow_sphere", cut_hollow_sphere(0.6, 0.2, 0.04)),
        (
            "cut_hollow_sphere_dynamic_low",
            cut_hollow_sphere(0.6, param("bowl_cut", -0.45), 0.03),
        ),
        ("death_star", death_star(0.6, 0.4, 0.7)),
        (
            "cylinder_between",
            cylinder_between(dvec3(-0.3, -0.4, 0.1), dvec3(0.4, 0.3, -0.2), 0.25),
        ),
        (
            "cone_between_dynamic",
            cone_between(
                param3("cone_a", dvec3(0.2, -0.5, 0.0)),
                dvec3(-0.1, 0.5, 0.3),
                param("cone_ra", 0.4),
                0.1,
            ),
        ),
        (
            "round_cone_between",
            round_cone_between(dvec3(0.0, -0.3, -0.3), dvec3(0.2, 0.4, 0.3), 0.3, 0.12),
        ),
        (
            "extrude_polygon",
            extrude(
                Profile::polygon([[0.0, 0.6], [-0.5, -0.3], [0.1, 0.0], [0.5, -0.4]]),
                0.3,
            ),
        ),
        (
            "extrude_round_rect_dynamic",
            extrude(
                Profile::round_rect(0.5, param("rect_y", 0.3), param("corner", 0.1)),
                param("depth", 0.2),
            ),
        ),
        (
            "revolve_segment",
            revolve(Profile::segment([0.1, -0.4], [0.3, 0.4], 0.1), 0.3),
        ),
        (
            "revolve_dynamic_polygon",
            revolve(
                Profile::Polygon {
                    vertices: vec![
                        [0.0.into(), (-0.5).into()],
                        [param("rim", 0.6), 0.0.into()],
                        [0.0.into(), 0.5.into()],
                    ],
                },
                param("ring", 0.2),
            ),
        ),
        ("revolve_circle", revolve(Profile::circle(0.2), 0.5)),
        ("extrude_ellipse", extrude(Profile::ellipse(0.6, 0.25), 0.3)),
        ("revolved_vesica", revolve(Profile::vesica(0.6, 0.2), 0.0)),
        (
            "revolve_ellipse_dynamic",
            revolve(Profile::ellipse(param("ell_a", 0.15), 0.4), 0.4),
        ),
        ("extrude_rect", extrude(Profile::rect(0.4, 0.2), 0.5)),
        ("mandelbox", mandelbox(-1.5)),
        (
            "mandelbox_julia",
            Mandelbox::new(2.0).julia([0.4, -0.3, 0.2]).into(),
        ),
        ("kifs_tetrahedral", kifs(KifsFold::Tetrahedral)),
        ("kifs_octahedral", kifs(KifsFold::Octahedral)),
        ("kifs_icosahedral", kifs(KifsFold::Icosahedral)),
        ("kifs_menger", kifs(KifsFold::Menger)),
        (
            "kifs_turned_dynamic",
            Kifs::new(KifsFold::Icosahedral)
                .scale(param("kifs_scale", 2.4))
                .rotate_before([0.3.into(), param("kifs_turn", -0.5), 0.1.into()])
                .iterations(9)
                .into(),
        ),
        ("hybrid_mandelbox", Hybrid::mandelbox(-1.5).into()),
        (
            "hybrid_bulb_box",
            Hybrid::new()
                .stage(2, [HybridOp::power(8.0), HybridOp::AddPoint])
                .stage(1, Hybrid::mandelbox(2.0).stages[0].ops.clone())
                .iterations(6)
                .into(),
        ),
        (
            "hybrid_every_op_dynamic",
            Hybrid::new()
                .stage(
                    1,
                    [
                        HybridOp::surf_fold(1.0, param("hy_limit", 0.8)),
                        HybridOp::sphere_fold(0.4, 1.0),
                        HybridOp::scale_about(param("hy_scale", -1.7), [0.1, 0.0, -0.2]),
                        HybridOp::rotate([0.2.into(), param("hy_turn", -0.4), 0.0.into()]),
                        HybridOp::AbsFold,
                        HybridOp::plane_fold(
                            [1.0.into(), param("hy_normal", 0.5), 0.0.into()],
                            0.1,
                        ),
                        HybridOp::Fold(KifsFold::Icosahedral),
                        HybridOp::power(param("hy_power", 2.5)),
                        HybridOp::add_constant([0.2.into(), (-0.1).into(), param("hy_c", 0.3)]),
                        HybridOp::AddPoint,
                    ],
                )
                .iterations(5)
                .bailout(param("hy_bailout", 6.0))
                .into(),
        ),
        ("ellipsoid", ellipsoid(dvec3(0.7, 0.4, 0.5))),
        ("mandelbulb_int", mandelbulb(8.0)),
        ("mandelbulb_trig", mandelbulb(7.3)),
        ("mandelbulb_dynamic", mandelbulb(param("power", 5.0))),
        ("menger", menger(4)),
        ("julia", julia([-0.2, 0.6, 0.2, 0.2])),
        // Outside the Mandelbrot set, and a bailout below 2.5 radii: the
        // proven bound.
        ("julia_dust", julia([0.2548, -0.4865, -0.4641, 0.0956])),
        (
            "julia_dynamic_bailout_2",
            QuaternionJulia::new([param("cx", -1.3), 0.1.into(), 0.0.into(), 0.0.into()])
                .bailout(2.0)
                .slice_w(0.2)
                .into(),
        ),
        ("sierpinski", sierpinski(6)),
        ("translate", b().translate(dvec3(0.3, -0.2, 0.1))),
        ("rotate", b().rotate(dvec3(1.0, 2.0, 0.5), 0.7)),
        ("rotate_dynamic", b().rotate(DVec3::Y, param("angle", 0.4))),
        ("scale", b().scale(1.7)),
        (
            "mirror",
            b().translate(dvec3(0.4, 0.0, 0.0)).mirror(Axis::X),
        ),
        ("round", b().round(0.1)),
        ("onion", s().onion(0.05)),
        ("elongate", s().elongate(dvec3(0.3, 0.0, 0.2))),
        ("repeat", sphere(0.2).repeat(dvec3(0.7, 0.0, 0.9))),
        (
            "repeat_limited",
            sphere(0.2).repeat_limited(dvec3(0.6, 0.6, 0.0), [2, 1, 0]),
        ),
        // Orbit traps: each trap on a fractal, the palette's colour
        // compared; dynamic trap values reach the kernel as given.
        (
            "orbit_trap_point_bulb",
            mandelbulb(8.0).orbit_trap(Trap::point([0.3, 0.2, -0.1]), Palette::fire()),
        ),
        (
            "orbit_trap_plane_menger",
            menger(3).orbit_coloring(
                OrbitColoring::new(
                    Trap::plane(param3("trap_n", dvec3(0.2, 1.0, 0.4)), param("trap_d", 0.3)),
                    Palette::viridis(),
                )
                .range(0.0, param("trap_far", 2.0)),
            ),
        ),
        (
            "orbit_trap_sphere_mandelbox",
            mandelbox(-1.5).orbit_trap(Trap::sphere([0.5, 0.0, 0.5], 0.8), Palette::ocean()),
        ),
        (
            "orbit_trap_line_julia",
            julia([-0.2, 0.6, 0.2, 0.2]).orbit_coloring(
                OrbitColoring::new(
                    Trap::line([0.0, 0.1, 0.0], [1.0, 1.0, 0.0]),
                    Palette::magma(),
                )
                .range(0.8, 0.0),
            ),
        ),
        (
            "orbit_trap_kifs_hybrid_sierpinski",
            kifs(KifsFold::Octahedral)
                .orbit_trap(Trap::plane([0.0, 0.0, 1.0], 0.5), Palette::copper())
                .union(
                    Node::from(Hybrid::mandelbox(2.0))
                        .orbit_trap(Trap::point([0.0, 0.0, 0.0]), Palette::rainbow())
                        .translate(dvec3(1.0, 0.0, 0.0)),
                )
                .union(
                    sierpinski(4)
                        .orbit_trap(Trap::sphere([1.0, 1.0, 1.0], 0.5), Palette::grey())
                        .translate(dvec3(0.0, 1.0, 0.0)),
                ),
        ),
        (
            "orbit_trap_iterations_julia_hybrid",
            julia([-0.2, 0.6, 0.2, 0.2])
                .orbit_coloring(
                    OrbitColoring::new(Trap::Iterations, Palette::viridis()).range(0.0, 12.0),
                )
                .union(
                    Node::from(Hybrid::mandelbox(-1.5))
                        .orbit_coloring(
                            OrbitColoring::new(Trap::Iterations, Palette::fire()).range(0.0, 8.0),
                        )
                        .translate(dvec3(0.0, 0.0, 1.0)),
                ),
        ),
        (
            "orbit_trap_dynamic_power",
            Node::from(Mandelbulb::new(param("trap_power", 5.0)).iterations(4)).orbit_trap(
                Trap::line([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
                Palette::gradient([
                    (0.0, [0.1, 0.0, 0.2]),
                    (0.3, [0.9, 0.5, 0.1]),
                    (1.0, [1.0; 3]),
                ]),
            ),
        ),
        ("twist", b().twist(1.5)),
        ("bend", b().bend(0.9)),
        ("union", s().union(b().translate(dvec3(0.5, 0.0, 0.0)))),
        ("subtract", b().subtract(s())),
        ("intersect", b().intersect(s())),
        (
            "smooth_union",
            s().smooth_union(b().translate(dvec3(0.5, 0.0, 0.0)), 0.3),
        ),
        ("smooth_subtract", b().smooth_subtract(s(), 0.2)),
        (
            "smooth_intersect",
            b().smooth_intersect(s(), param("k", 0.2)),
        ),
        ("color", s().color(dvec3(0.2, 0.4, 0.9))),
        ("custom", gyroid().node([0.1]).intersect(sphere(1.5))),
        ("instanced_union", instanced()),
    ];
    for (name, scene) in fractal_sdf::gallery::all() {
        let name: &'static str = Box::leak(format!("gallery_{name}").into_boxed_str());
        v.push((name, scene.geometry.expect("gallery scenes have geometry")));
    }
    v
}

/// The tolerance per precision and device class. On a CPU device (PoCL,
/// where `make test` and CI run) the worst errors measured over every node
/// below and 10,065 points are 5.0e-6 in F32 (`orbit_trap_dynamic_power`:
/// the trigonometric map, a colour from its orbit) and 2.3e-15 in F64
/// (the same node; 7.8e-16 for distances alone, `julia_dynamic_bailout_2`);
/// the tolerances are about 4 times those. Other devices (GPUs) are not measured here: their single-precision
/// built-ins may be several ulps from correctly rounded (OpenCL C allows up
/// to 4 for `sin`, `cos` and `atan2`, 16 for `pow`), which the iterated
/// fractal maps amplify, so they keep the looser 1e-4 and 1e-10 until a
/// measurement says otherwise.
fn tolerance(precision: Precision, device: &DeviceInfo) -> f64 {
    match (precision, device.kind) {
        (Precision::F32, DeviceKind::Cpu) => 2e-5,
        (Precision::F64, DeviceKind::Cpu) => 1e-14,
        (Precision::F64, _) => 1e-10,
        _ => 1e-4,
    }
}

fn check_all(precision: Precision) {
    let Some(device) = gpu::device() else {
        return;
    };
    if precision == Precision::F64 && !gpu::fp64(&device) {
        return;
    }
    let mut points = random_points(10_000, 2.5, 0x5eed);
    points.extend(spicy_points());
    let tolerance = tolerance(precision, &device);
    let mut worst = (0.0, "");
    let failures: Vec<String> = nodes()
        .into_iter()
        .filter_map(|(name, node)| {
            match check_device_matches_cpu(
                &node,
                &DeviceSelector::auto(),
                precision,
                &points,
                tolerance,
            ) {
                Ok(tested) => {
                    assert_eq!(tested.inputs, points.len());
                    if tested.worst * tolerance > worst.0 {
                        worst = (tested.worst * tolerance, name);
                    }
                    None
                }
                Err(f) => Some(format!("{name} ({precision:?}): {f}")),
            }
        })
        .collect();
    eprintln!(
        "{precision:?}: worst relative error {:.2e} ({}), tolerance {tolerance:.0e}",
        worst.0, worst.1
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn opencl_f32_matches_the_cpu_reference() {
    check_all(Precision::F32);
}

#[test]
fn opencl_f64_matches_the_cpu_reference() {
    check_all(Precision::F64);
}

/// The same nodes and points on the third backend: each node's WGSL
/// (`codegen::emit_wgsl`, for evaluation) run on a Vulkan device through
/// wgpu (Mesa's lavapipe where there is no GPU) gives the CPU reference's
/// single-precision distances within `DISTANCE · max(1, |cpu|)` and
/// colours within `COLOUR · max(1, |cpu|)`. WGSL's built-ins are not
/// OpenCL's: Vulkan computes `pow(x, y)` as `exp2(y · log2(x))`, whose
/// error grows with the exponent, and a fractal's iterations carry it.
/// Measured on lavapipe: distances 1.05e-3 for the Mandelbulb with a
/// dynamic power (`mandelbulb_dynamic`), 5.7e-4 for every other node; a
/// colour 6.9e-3 (`orbit_trap_dynamic_power`: an orbit trap's colour comes
/// from the iteration whose orbit passes nearest, and where two pass
/// almost as near, `pow`'s error can pick the other). The tolerances are
/// 5e-3 and 2e-2 (PoCL's OpenCL keeps 2e-5 for both). The inside shape
/// (the escape-time Mandelbulb) prints, with its test in WGSL, and
/// agrees in sign at every point; the node WGSL does not print (a custom
/// shape written in OpenCL C) is the typed error, and is counted.
#[test]
fn wgpu_f32_matches_the_cpu_reference() {
    use fractal_sdf::Error;
    use fractal_sdf::codegen::{Options, Target, emit_wgsl};
    const DISTANCE: f32 = 5e-3;
    const COLOUR: f32 = 2e-2;
    let Some(gpu) = crate::wgpu_device::device() else {
        return;
    };
    let mut points = random_points(10_000, 2.5, 0x5eed);
    points.extend(spicy_points());
    #[allow(clippy::cast_possible_truncation)]
    let at: Vec<glam::Vec3> = points.iter().map(|p| p.as_vec3()).collect();
    let options = Options::default().target(Target::Evaluate);
    let (mut checked, mut refused) = (0, Vec::new());
    let mut worst = (0.0f32, "", "", glam::Vec3::ZERO);
    let mut failures = Vec::new();
    for (name, node) in nodes() {
        let scene = Scene::new(node).compile().expect("the node compiles");
        let module = match emit_wgsl(&scene, &options) {
            Ok(module) => module,
            Err(Error::Unsupported { .. }) => {
                refused.push(name);
                continue;
            }
            Err(e) => panic!("{name}: {e}"),
        };
        match crate::wgsl::compare(&gpu, &scene, &module, &at, (DISTANCE, COLOUR)) {
            Ok((error, what, p)) if error > worst.0 => worst = (error, name, what, p),
            Ok(_) => {}
            Err(failure) => failures.push(format!("{name}: {failure}")),
        }
        checked += 1;
    }
    eprintln!(
        "wgpu: {checked} nodes, worst relative error {:.2e} ({} {} at {}), tolerances \
         {DISTANCE:.0e} and {COLOUR:.0e}; not printed in WGSL: {}",
        worst.0,
        worst.1,
        worst.2,
        worst.3,
        refused.join(", ")
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert_eq!(checked + refused.len(), nodes().len());
    assert!(refused.len() <= 1, "refused: {}", refused.join(", "));
}

#[test]
fn dynamic_values_reach_the_device() {
    if gpu::device().is_none() {
        return;
    }
    let node = sphere(param("radius", 1.0)).translate(dvec3(0.5, 0.0, 0.0));
    let mut device = PointEvaluator::new(&node, Precision::F64, &DeviceSelector::auto()).unwrap();
    let p = dvec3(3.0, 0.0, 0.0);
    let before = device.eval(&[p]).unwrap()[0].distance;
    device.set_param("radius", 2.0).unwrap();
    let after = device.eval(&[p]).unwrap()[0].distance;
    assert_eq!(before, 1.5);
    assert_eq!(after, 0.5);
}
