//! Orbit traps against an oracle that shares no code with the formulas:
//! each orbit iterated from its fractal's definition (the Mandelbulb's
//! power in spherical coordinates with `powf`, `acos` and `atan2`; the
//! Menger sponge's fold by sorting; the Mandelbox's folds by cases), each
//! trap's distance from its own closed form (a cross product for a line,
//! the plane's equation; the smooth iteration count as its sum), and the
//! palette read back through a grey ramp.

use fractal_sdf::cpu::Evaluator;
use fractal_sdf::prelude::*;
use fractal_sdf::scene::QuaternionJulia;
use fractal_sdf::scene::{OrbitColoring, Palette, Param, Trap};
use fractal_sdf::testing::random_points;

/// A trap, by definition.
#[derive(Clone, Copy, Debug)]
enum Shape {
    Point(DVec3),
    Sphere(DVec3, f64),
    Plane(DVec3, f64),
    Line(DVec3, DVec3),
    /// The smooth iteration count: the sum of `e^(-|z|)`.
    Iterations,
}

impl Shape {
    fn distance(self, z: DVec3) -> f64 {
        match self {
            Shape::Point(c) => z.distance(c),
            Shape::Sphere(c, r) => (z.distance(c) - r).abs(),
            // The plane `n · z + d = 0`.
            Shape::Plane(n, d) => (n.normalize().dot(z) + d).abs(),
            Shape::Line(q, u) => (z - q).cross(u.normalize()).length(),
            Shape::Iterations => z.length(),
        }
    }

    /// The trap value of an orbit: its smallest distance, or for the
    /// iteration count the sum over its points.
    fn of(self, orbit: &[DVec3]) -> f64 {
        match self {
            Shape::Iterations => orbit.iter().map(|z| (-z.length()).exp()).sum(),
            _ => orbit
                .iter()
                .map(|&z| self.distance(z))
                .fold(f64::INFINITY, f64::min),
        }
    }

    fn trap(self) -> Trap {
        match self {
            Shape::Point(c) => Trap::point(c),
            Shape::Sphere(c, r) => Trap::sphere(c, r),
            Shape::Plane(n, d) => Trap::plane(n, d),
            Shape::Line(q, u) => Trap::line(q, u),
            Shape::Iterations => Trap::Iterations,
        }
    }
}

const SHAPES: [Shape; 5] = [
    Shape::Point(DVec3::new(0.3, -0.2, 0.1)),
    Shape::Sphere(DVec3::new(0.0, 0.2, 0.0), 0.7),
    Shape::Plane(DVec3::new(1.0, 2.0, -0.5), 0.25),
    Shape::Line(DVec3::new(0.1, 0.0, -0.3), DVec3::new(0.0, 1.0, 1.0)),
    Shape::Iterations,
];

/// Trap values up to this span the grey ramp (more than any count of the
/// orbits below: at most 9 points).
const FAR: f64 = 16.0;

/// The trap value the CPU reference paints at `p`, read back from a grey
/// ramp from 0 to [`FAR`].
fn painted(fractal: &Node, shape: Shape, p: DVec3) -> f64 {
    let ramp = Palette::gradient([(0.0, [0.0; 3]), (1.0, [1.0; 3])]);
    let node = fractal
        .clone()
        .orbit_coloring(OrbitColoring::new(shape.trap(), ramp).range(0.0, FAR));
    let sample = Evaluator::new(&node).unwrap().sample::<f64>(p.into());
    let color: DVec3 = sample.color.into();
    assert!(color.x == color.y && color.y == color.z, "{color:?}");
    // The trap the shading layers show is the one the palette reads.
    if color.x > 0.0 && color.x < 1.0 {
        assert!(
            (sample.orbit - color.x * FAR).abs() <= 1e-9,
            "orbit {} against painted {}",
            sample.orbit,
            color.x * FAR
        );
    }
    color.x * FAR
}

/// The orbit of `p` under the power-`n` Mandelbulb, by definition: `z0 =
/// p`, then `z^n + p` with the radius raised to `n` and both angles times
/// `n`, while it stays within the bailout (at most `iterations` steps);
/// `None` where a radius is so near the bailout that rounding decides
/// whether the orbit stops.
fn bulb_orbit(p: DVec3, n: f64, iterations: u32, bailout: f64) -> Option<Vec<DVec3>> {
    let mut z = p;
    let mut points = Vec::new();
    for _ in 0..=iterations {
        let r = z.length();
        if (r - bailout).abs() < 1e-6 {
            return None;
        }
        if r > bailout {
            break;
        }
        points.push(z);
        let (theta, phi) = ((z.z / r).acos() * n, z.y.atan2(z.x) * n);
        z = r.powf(n)
            * DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            )
            + p;
    }
    Some(points)
}

/// The classic Menger sponge's orbit: the point, then at each level its
/// coordinates' magnitudes sorted largest first (the fold), scaled by 3
/// about the corner cube and shifted back into the cube.
fn menger_orbit(p: DVec3, iterations: u32) -> Vec<DVec3> {
    let mut z = p;
    let mut points = vec![p];
    for _ in 0..iterations {
        let mut a = z.abs().to_array();
        a.sort_by(|x, y| y.total_cmp(x));
        z = DVec3::new(3.0 * a[0] - 2.0, 3.0 * a[1] - 2.0, 3.0 * a[2]);
        if z.z > 1.0 {
            z.z -= 2.0;
        }
        points.push(z);
    }
    points
}

/// The Mandelbox's orbit (scale `s`, radii 0.5 and 1, fold limit 1): the
/// point, then each `s · sphere_fold(box_fold(z)) + p` while its largest
/// coordinate is at most the escape threshold `escape` (past it an orbit
/// never returns); `None` where a coordinate is within rounding of it.
fn mandelbox_orbit(p: DVec3, s: f64, iterations: u32, escape: f64) -> Option<Vec<DVec3>> {
    let fold = |v: f64| {
        if v > 1.0 {
            2.0 - v
        } else if v < -1.0 {
            -2.0 - v
        } else {
            v
        }
    };
    let mut z = p;
    let mut points = vec![p];
    for _ in 0..iterations {
        let b = DVec3::new(fold(z.x), fold(z.y), fold(z.z));
        let r2 = b.length_squared();
        let k = if r2 < 0.25 {
            4.0
        } else if r2 < 1.0 {
            1.0 / r2
        } else {
            1.0
        };
        z = b * k * s + p;
        let largest = z.abs().max_element();
        if (largest - escape).abs() < 1e-9 {
            return None;
        }
        if largest > escape {
            break;
        }
        points.push(z);
    }
    Some(points)
}

/// The orbit of the quaternion `p.x + p.y i + p.z j + w k` under `z² + c`
/// (`c` real part first), by glam's quaternion product, while it stays
/// within the bailout; each point seen as its first three components.
fn julia_orbit(p: DVec3, c: [f64; 4], w: f64, iterations: u32, bailout: f64) -> Option<Vec<DVec3>> {
    // glam keeps the real part in `w`.
    let c = DQuat::from_xyzw(c[1], c[2], c[3], c[0]);
    let mut z = DQuat::from_xyzw(p.y, p.z, w, p.x);
    let mut points = vec![p];
    for _ in 0..iterations {
        z = z * z + c;
        let r = z.length();
        if (r - bailout).abs() < 1e-9 {
            return None;
        }
        if r > bailout {
            break;
        }
        points.push(DVec3::new(z.w, z.x, z.y));
    }
    Some(points)
}

/// The Sierpinski tetrahedron's orbit (scale 2): the point, then at each
/// level the point reflected across each of the planes `x + y = 0`,
/// `x + z = 0` and `y + z = 0` it lies behind, in turn, and scaled by 2
/// about the vertex `(1, 1, 1)`.
fn sierpinski_orbit(p: DVec3, iterations: u32) -> Vec<DVec3> {
    let normals = [
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(0.0, 1.0, 1.0),
    ]
    .map(DVec3::normalize);
    let mut z = p;
    let mut points = vec![p];
    for _ in 0..iterations {
        for n in normals {
            let side = z.dot(n);
            if side < 0.0 {
                z -= 2.0 * side * n;
            }
        }
        z = 2.0 * z - DVec3::ONE;
        points.push(z);
    }
    points
}

/// Checks the painted trap values of `fractal` against `oracle` at random
/// points in the ball of `radius`, returning the largest difference and
/// how many were compared.
fn check(
    name: &str,
    fractal: &Node,
    radius: f64,
    oracle: impl Fn(DVec3) -> Option<Vec<DVec3>>,
) -> (f64, usize) {
    let mut worst: f64 = 0.0;
    let mut compared = 0;
    for shape in SHAPES {
        // Points in the ball of `radius` (within 1.5 times a Mandelbulb's
        // own ball: beyond, its formula follows no orbit).
        for p in random_points(800, radius, 0x0b17) {
            if p.length() > radius {
                continue;
            }
            let Some(orbit) = oracle(p) else {
                continue;
            };
            let expected = shape.of(&orbit);
            if expected >= FAR {
                continue;
            }
            let got = painted(fractal, shape, p);
            let error = (got - expected).abs();
            assert!(
                error <= 1e-9,
                "{name}, {shape:?} at {p}: painted {got}, the orbit comes within {expected}"
            );
            worst = worst.max(error);
            compared += 1;
        }
    }
    assert!(compared > 1900, "{name}: {compared} points compared");
    (worst, compared)
}

#[test]
fn orbit_traps_paint_the_orbits_nearest_approach() {
    let bulb = check(
        "mandelbulb",
        &fractal_sdf::scene::Mandelbulb::new(8.0)
            .iterations(6)
            .into(),
        1.3,
        |p| bulb_orbit(p, 8.0, 6, 2.0),
    );
    let real = check(
        "mandelbulb of power 5.5",
        &fractal_sdf::scene::Mandelbulb::new(5.5)
            .iterations(6)
            .into(),
        1.3,
        |p| bulb_orbit(p, 5.5, 6, 2.0),
    );
    let sponge = check("menger", &menger(4), 1.5, |p| Some(menger_orbit(p, 4)));
    let (_, escape) = fractal_sdf::math::mandelbox_extent(2.0, 1.0, None);
    let boxed = check(
        "mandelbox",
        &fractal_sdf::scene::Mandelbox::new(2.0).iterations(8).into(),
        2.0,
        |p| mandelbox_orbit(p, 2.0, 8, escape),
    );
    let c = [-0.2, 0.6, 0.2, 0.2];
    let set = check(
        "julia",
        &QuaternionJulia::new(c.map(Param::from))
            .iterations(8)
            .into(),
        1.4,
        |p| julia_orbit(p, c, 0.0, 8, 4.0),
    );
    let tetra = check("sierpinski", &sierpinski(5), 1.5, |p| {
        Some(sierpinski_orbit(p, 5))
    });
    let compared = [bulb, real, sponge, boxed, set, tetra]
        .iter()
        .map(|r| r.1)
        .sum::<usize>();
    eprintln!(
        "orbit traps, {compared} points: largest difference from the oracle {:.1e} \
         (Mandelbulb 8), {:.1e} (5.5), {:.1e} (Menger), {:.1e} (Mandelbox), {:.1e} (Julia), \
         {:.1e} (Sierpinski)",
        bulb.0, real.0, sponge.0, boxed.0, set.0, tetra.0
    );
}

/// The colour is the palette's at the trap value's place between `near`
/// and `far`, clamped at the ends, reversed when `far` is below `near`.
#[test]
fn the_range_places_trap_values_on_the_palette() {
    let fire = Palette::fire();
    let shape = Shape::Point(DVec3::ZERO);
    for p in random_points(50, 1.5, 7) {
        let m = shape.of(&menger_orbit(p, 3));
        for (near, far) in [(0.0, 1.0), (0.2, 0.6), (1.0, 0.0)] {
            let node = menger(3)
                .orbit_coloring(OrbitColoring::new(shape.trap(), fire.clone()).range(near, far));
            let color: DVec3 = Evaluator::new(&node)
                .unwrap()
                .sample::<f64>(p.into())
                .color
                .into();
            let t = ((m - near) / (far - near)).clamp(0.0, 1.0);
            let expected = DVec3::from_array(fire.color(t));
            assert!(
                color.distance(expected) < 1e-12,
                "{near}..{far} at {p}: {color} for trap {m}, expected {expected}"
            );
        }
    }
}

/// On the device, the trap the layers show for a fractal a palette paints
/// (the fourth value `eval_points` writes) is the CPU reference's, and the
/// trap that tints its colour stays 1.
#[test]
fn the_device_reports_the_trap_a_palette_reads() {
    use fractal_sdf::quality::Precision;
    use fractal_sdf::render::{DeviceSelector, PointEvaluator};
    let Some(_) = crate::gpu::device() else {
        return;
    };
    let shape = Shape::Sphere(DVec3::new(0.0, 0.2, 0.0), 0.7);
    let node = menger(4).orbit_coloring(OrbitColoring::new(shape.trap(), Palette::fire()));
    let cpu = Evaluator::new(&node).unwrap();
    let points = random_points(400, 1.4, 0x7a9);
    let device = PointEvaluator::new(&node, Precision::F32, &DeviceSelector::auto())
        .unwrap()
        .eval(&points)
        .unwrap();
    let mut worst: f64 = 0.0;
    for (p, s) in points.iter().zip(&device) {
        let want = cpu.sample::<f64>((*p).into()).orbit;
        worst = worst.max((s.orbit - want).abs() / want.abs().max(1.0));
        assert_eq!(s.trap, 1.0, "a palette's fractal is not tinted");
    }
    eprintln!(
        "trap the layers show: largest difference from the CPU {worst:.1e} over {} points",
        points.len()
    );
    assert!(worst < 1e-4, "{worst}");
}
