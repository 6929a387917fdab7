//! Named fixture scenes: one place that defines what "the Mandelbulb scene"
//! is for tests, golden renders and benchmarks alike.

use fractal_sdf::prelude::*;
use fractal_sdf::scene::Axis;
use fractal_sdf::scene::Mandelbulb;
use fractal_sdf::scene::capped_cone;
use fractal_sdf::scene::ellipsoid;
use fractal_sdf::scene::octahedron;
use fractal_sdf::scene::param3;

/// The classic power-8 Mandelbulb (12 iterations, bailout 2; the power is
/// a baked integer, so it uses the trig-free form).
pub fn mandelbulb_scene() -> Node {
    mandelbulb(8.0)
}

/// The power-8 Mandelbulb with a dynamic power, which always uses the
/// trigonometric form.
pub fn mandelbulb_trig_scene() -> Node {
    Mandelbulb::new(param("power", 8.0)).into()
}

/// A Mandelbulb of a non-integer power.
pub fn fractional_mandelbulb_scene() -> Node {
    Mandelbulb::new(7.5).iterations(16).into()
}

/// The classic Menger sponge, 4 levels.
pub fn menger_scene() -> Node {
    menger(4)
}

/// A quaternion Julia set, as in the ASCII example.
pub fn julia_scene() -> Node {
    julia([-0.2, 0.6, 0.2, 0.2])
}

/// The Julia constant of [`julia_scene`].
pub const JULIA_C: [f64; 4] = [-0.2, 0.6, 0.2, 0.2];

/// The classic Sierpinski tetrahedron, 6 levels.
pub fn sierpinski_scene() -> Node {
    sierpinski(6)
}

/// Every exact primitive, side by side on a 3 x 3 grid.
pub fn primitives_scene() -> Node {
    let shapes = [
        sphere(0.5),
        cuboid(dvec3(0.4, 0.3, 0.5)),
        round_box(dvec3(0.4, 0.4, 0.4), 0.1),
        torus(0.4, 0.1),
        cylinder(0.3, 0.5),
        capsule(dvec3(-0.3, -0.3, 0.0), dvec3(0.3, 0.3, 0.0), 0.15),
        octahedron(0.5),
        capped_cone(0.5, 0.4, 0.1),
        ellipsoid(dvec3(0.5, 0.3, 0.2)),
    ];
    let grid = shapes.into_iter().enumerate().map(|(i, s)| {
        let (x, z) = ((i % 3) as f64 - 1.0, (i / 3) as f64 - 1.0);
        s.translate(dvec3(1.5 * x, 0.0, 1.5 * z))
    });
    let floor = plane(dvec3(0.0, 1.0, 0.0), 0.6);
    grid.fold(floor, Node::union)
}

/// Smooth and hard booleans with colours: a rounded box melted into a
/// sphere, drilled by a cylinder.
pub fn csg_scene() -> Node {
    let body = sphere(0.7).color(dvec3(0.9, 0.3, 0.2)).smooth_union(
        round_box(dvec3(0.5, 0.2, 0.5), 0.05)
            .translate(dvec3(0.0, -0.5, 0.0))
            .color(dvec3(0.2, 0.4, 0.9)),
        0.3,
    );
    body.subtract(cylinder(0.25, 2.0).rotate(DVec3::X, std::f64::consts::FRAC_PI_2))
        .smooth_intersect(cuboid(dvec3(1.0, 1.0, 1.0)), 0.1)
}

/// Domain operations: a twisted box, a bent capsule, a repeated shell.
pub fn domain_scene() -> Node {
    let twisted = cuboid(dvec3(0.3, 1.0, 0.3)).twist(1.5);
    let bent = capsule(dvec3(-1.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), 0.15)
        .bend(0.5)
        .translate(dvec3(0.0, 0.0, 1.5));
    let shells = sphere(0.2)
        .onion(0.03)
        .repeat_limited(dvec3(0.6, 0.0, 0.6), [2, 0, 2])
        .translate(dvec3(0.0, -1.2, 0.0));
    twisted.union(bent).union(shells).union(
        octahedron(0.3)
            .elongate(dvec3(0.2, 0.0, 0.0))
            .mirror(Axis::X),
    )
}

/// Dynamic parameters: a sphere whose radius, position and blend radius
/// can change without rebuilding.
pub fn dynamic_scene() -> Node {
    sphere(param("radius", 0.8))
        .translate(param3("offset", dvec3(0.5, 0.0, 0.0)))
        .smooth_union(cuboid(dvec3(0.3, 0.3, 0.3)), param("blend", 0.2))
}

/// Every fixture with its name.
pub fn all() -> Vec<(&'static str, Node)> {
    vec![
        ("mandelbulb", mandelbulb_scene()),
        ("mandelbulb_trig", mandelbulb_trig_scene()),
        ("fractional_mandelbulb", fractional_mandelbulb_scene()),
        ("menger", menger_scene()),
        ("julia", julia_scene()),
        ("sierpinski", sierpinski_scene()),
        ("primitives", primitives_scene()),
        ("csg", csg_scene()),
        ("domain", domain_scene()),
        ("dynamic", dynamic_scene()),
    ]
}
