//! Shapes given by a membership test instead of a distance estimate (see
//! [`InsideShape`]).

use glam::DVec3;

use super::custom::{CustomShape, InsideBounds};
use super::node::Node;
use super::param::Param;
use super::rule::Rule;
use crate::error::Result;

/// A user-defined shape given by a membership test: a Rust function (the
/// CPU reference) and its OpenCL C twin, with the region the set lies in.
/// It draws the escape-time sets that have no usable distance estimate,
/// by brute-force marching. Cheap to clone (shared).
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::cpu;
/// use fractal_sdf::scene::{InsideBounds, InsideShape, Rule};
///
/// // A ball of radius r, known only by |p| < r.
/// let ball = InsideShape::new(
///     "ball",
///     &[("r", Rule::Positive)],
///     InsideBounds::sphere(DVec3::ZERO, 2.0),
///     |p, a| p.length() < a[0],
///     "return length(p) < r;",
/// )?;
/// let eval = cpu::Evaluator::new(&ball.node([1.0]))?;
/// assert!(eval.distance(dvec3(0.5, 0.0, 0.0)) < 0.0);
/// assert!(eval.distance(dvec3(1.5, 0.0, 0.0)) > 0.0);
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
///
/// The OpenCL body is the body of a function
/// `int inside_NAME(real3 p, real PARAM1, ...)` that returns nonzero where
/// `p` is in the set. It runs only within the bounds: the set is clipped
/// to them. The wgpu backend (feature `wgpu`) draws the built-in sets,
/// [`mandelbulb`](Self::mandelbulb) and [`mandelbox`](Self::mandelbox),
/// whose tests are written in WGSL too, and refuses a shape whose test is
/// OpenCL C alone. Names follow [`CustomShape`]'s rules, and the function
/// `inside_NAME` may not be a name the generated program already uses.
///
/// # How a scene uses one
///
/// An inside shape is a [`CustomShape`] whose value is `-INSIDE_HUGE` in
/// the set and [`INSIDE_HUGE`](super::INSIDE_HUGE) outside it: a value of
/// the right sign and no size. Hard unions, subtractions, intersections
/// and cuts with distance-estimated shapes keep membership exactly (the
/// minimum of a distance and `±INSIDE_HUGE` is inside where either is),
/// and every transform, mirror, limited repetition, elongation and colour
/// moves or paints it like any node.
///
/// A renderer marches a scene that holds one by *brute force* within the
/// shapes' bounds: steps of
/// [`Quality::brute_step`](crate::quality::Quality::brute_step) pixel
/// footprints, jittered per pixel and pass, or the distance to the nearest
/// distance-estimated surface where that is shorter (mixed scenes are
/// still sphere-traced), and outside the bounds the usual sphere tracing.
/// The first step that lands in the set is refined by bisection to
/// [`Quality::hit_epsilon`](crate::quality::Quality::hit_epsilon)
/// footprints. Normals and ambient occlusion come from the depth of
/// neighbouring pixels (screen space, see
/// [`Quality::screen_normals`](crate::quality::Quality::screen_normals)).
///
/// What needs a distance is refused with an
/// [`Error::InsideShape`](crate::Error::InsideShape): a smooth boolean,
/// rounding, an onion shell, a twist or a bend over an inside shape; an
/// unlimited repetition or dynamic transform over one (its bounds would
/// be unbounded); and materials in the same scene (secondary rays need a
/// normal at every hit).
#[derive(Clone, Debug, PartialEq)]
pub struct InsideShape(CustomShape);

impl InsideShape {
    /// Defines an inside shape called `name` with parameters
    /// `(name, rule)`, the region its set lies in, a CPU membership test
    /// and its OpenCL C body.
    ///
    /// # Errors
    /// [`Error::CustomShape`](crate::Error::CustomShape) for a bad name or
    /// an empty body (as [`CustomShape::new`]), or bounds that are not
    /// finite or not of positive size.
    pub fn new<F>(
        name: &str,
        params: &[(&str, Rule)],
        bounds: InsideBounds,
        test: F,
        opencl_body: &str,
    ) -> Result<Self>
    where
        F: Fn(DVec3, &[f64]) -> bool + Send + Sync + 'static,
    {
        CustomShape::new_inside(name, params, bounds, test, opencl_body).map(InsideShape)
    }

    /// The Mandelbulb as an escape-time set, `mandelbulb_escape`:
    /// parameters `power` (1 to 64) and `iterations` (1 to
    /// [`MAX_ESCAPE_ITERATIONS`](super::MAX_ESCAPE_ITERATIONS), rounded
    /// down). A point is in the set when its orbit `z -> z^power + p` (the
    /// triplex power) stays within radius 2 for every iteration, as
    /// [`mandelbulb_contains`] decides. Bounded by the ball of radius 2,
    /// outside which every orbit escapes at once. It is the set
    /// [`mandelbulb`](super::mandelbulb) estimates the distance to, so the
    /// two forms of one power can be compared.
    #[must_use]
    pub fn mandelbulb() -> Self {
        let shape = CustomShape::new_inside(
            "mandelbulb_escape",
            &[
                ("power", Rule::Range(1.0, 64.0)),
                ("iterations", Rule::Range(1.0, 256.0)),
            ],
            InsideBounds::sphere(DVec3::ZERO, MANDELBULB_BAILOUT),
            |p, a| mandelbulb_contains(p, a[0], iterations(a[1]), MANDELBULB_BAILOUT),
            MANDELBULB_BODY,
        )
        .map(|shape| shape.with_wgsl_test(MANDELBULB_WGSL));
        InsideShape(shape.expect("the built-in Mandelbulb test is a valid shape"))
    }

    /// Tom Lowe's Mandelbox as an escape-time set, `mandelbox_escape`,
    /// drawn by its inside test alone (the [`Mandelbox`](super::Mandelbox)
    /// node draws a larger set of the same map from a distance estimate).
    /// Parameters `scale`
    /// (the classic −1.5; from −2 to −1 the set stays within the bounds)
    /// and `iterations` (1 to 256, rounded down). Each iteration folds the
    /// point into the cube `[-1, 1]^3` (a box fold), inverts it in the
    /// sphere of radius 1 (at most 4 times, within radius 0.5), scales it
    /// and adds `p`; the point is in the set when the orbit stays within
    /// radius 4 (see [`mandelbox_contains`]). Bounded by the cube of half
    /// side 2.25.
    #[must_use]
    pub fn mandelbox() -> Self {
        let shape = CustomShape::new_inside(
            "mandelbox_escape",
            &[
                ("scale", Rule::Range(-4.0, 4.0)),
                ("iterations", Rule::Range(1.0, 256.0)),
            ],
            InsideBounds::cuboid(DVec3::ZERO, DVec3::splat(MANDELBOX_HALF_SIDE)),
            |p, a| mandelbox_contains(p, a[0], iterations(a[1])),
            MANDELBOX_BODY,
        )
        .map(|shape| shape.with_wgsl_test(MANDELBOX_WGSL));
        InsideShape(shape.expect("the built-in Mandelbox test is a valid shape"))
    }

    /// The built-in inside shape called `name`, if there is one: what a
    /// scene file's `Custom(name: "mandelbox_escape", ..)` finds without
    /// being given the shape.
    #[must_use]
    pub fn builtin(name: &str) -> Option<Self> {
        match name {
            "mandelbulb_escape" => Some(Self::mandelbulb()),
            "mandelbox_escape" => Some(Self::mandelbox()),
            _ => None,
        }
    }

    /// A node of this shape with the given parameter values.
    #[must_use]
    pub fn node<P: Into<Param>>(&self, args: impl IntoIterator<Item = P>) -> Node {
        self.0.node(args)
    }

    /// Whether `p` is in the set (within the bounds) for these parameter
    /// values, by the CPU test.
    #[must_use]
    pub fn contains(&self, p: DVec3, args: &[f64]) -> bool {
        self.0.distance(p, args) < 0.0
    }

    /// The region the set is clipped to.
    #[must_use]
    pub fn bounds(&self) -> InsideBounds {
        self.0.inside_bounds().expect("an inside shape has bounds")
    }

    /// The shape as scenes hold it: a [`CustomShape`] whose value is
    /// `±INSIDE_HUGE`. Pass it to
    /// [`SceneFile::parse_with`](crate::file::SceneFile::parse_with) to read
    /// files that name it.
    #[must_use]
    pub fn shape(&self) -> &CustomShape {
        &self.0
    }
}

impl From<InsideShape> for CustomShape {
    fn from(shape: InsideShape) -> Self {
        shape.0
    }
}

/// The most steps a ray takes within inside shapes' bounds, besides
/// [`Quality::max_steps`](crate::quality::Quality::max_steps): a ray still short of the set
/// after these many brute-force steps is a miss.
pub const BRUTE_MAX_STEPS: u32 = 16384;

/// The escape radius of [`InsideShape::mandelbulb`].
pub const MANDELBULB_BAILOUT: f64 = 2.0;

/// The half side of [`InsideShape::mandelbox`]'s bounding cube.
pub const MANDELBOX_HALF_SIDE: f64 = 2.25;

/// The escape radius of [`InsideShape::mandelbox`].
pub const MANDELBOX_BAILOUT: f64 = 4.0;

/// An iteration count parameter as the OpenCL twins read it: truncated.
fn iterations(value: f64) -> u32 {
    // Validation holds the value to [1, 256].
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let n = value as u32;
    n
}

const MANDELBULB_BODY: &str = "real3 z = p;
for (int i = 0; i < (int)iterations; ++i) {
    real r = length(z);
    if (r > R(2.0)) {
        return 0;
    }
    if (r == R(0.0)) {
        z = p;
        continue;
    }
    real polar = acos(clamp(z.z / r, R(-1.0), R(1.0))) * power;
    real azimuth = atan2(z.y, z.x) * power;
    z = pow(r, power) * (real3)(sin(polar) * cos(azimuth), sin(polar) * sin(azimuth), cos(polar)) + p;
}
return length(z) <= R(2.0);";

const MANDELBOX_BODY: &str = "real3 z = p;
for (int i = 0; i < (int)iterations; ++i) {
    z = clamp(z, R(-1.0), R(1.0)) * R(2.0) - z;
    real r2 = dot(z, z);
    real k = r2 < R(0.25) ? R(4.0) : (r2 < R(1.0) ? R(1.0) / r2 : R(1.0));
    z = z * (scale * k) + p;
    if (dot(z, z) > R(16.0)) {
        return 0;
    }
}
return 1;";

/// [`MANDELBULB_BODY`] in WGSL, for the wgpu backend.
const MANDELBULB_WGSL: &str = "var z = p;
for (var i = 0; i < i32(iterations); i++) {
    let r = length(z);
    if (r > 2.0) {
        return false;
    }
    if (r == 0.0) {
        z = p;
        continue;
    }
    let polar = acos(clamp(z.z / r, -1.0, 1.0)) * power;
    let azimuth = atan2(z.y, z.x) * power;
    z = pow(r, power) * real3(sin(polar) * cos(azimuth), sin(polar) * sin(azimuth), cos(polar)) + p;
}
return length(z) <= 2.0;";

/// [`MANDELBOX_BODY`] in WGSL, for the wgpu backend.
const MANDELBOX_WGSL: &str = "var z = p;
for (var i = 0; i < i32(iterations); i++) {
    z = clamp(z, real3(-1.0), real3(1.0)) * 2.0 - z;
    let r2 = dot(z, z);
    var k = 1.0;
    if (r2 < 0.25) {
        k = 4.0;
    } else if (r2 < 1.0) {
        k = 1.0 / r2;
    }
    z = z * (scale * k) + p;
    if (dot(z, z) > 16.0) {
        return false;
    }
}
return true;";

/// Whether `p` is in the Mandelbulb of `power` at `iterations` iterations:
/// the orbit `z0 = p`, `z(k+1) = z(k)^power + p` (the triplex power in
/// spherical coordinates: the radius raised to `power`, the polar angle
/// from +z and the azimuth around z multiplied by `power`) stays within
/// `bailout` for `k = 0..=iterations`.
#[must_use]
pub fn mandelbulb_contains(p: DVec3, power: f64, iterations: u32, bailout: f64) -> bool {
    let mut z = p;
    for _ in 0..iterations {
        let r = z.length();
        if r > bailout {
            return false;
        }
        z = if r == 0.0 {
            p
        } else {
            let polar = (z.z / r).clamp(-1.0, 1.0).acos() * power;
            let azimuth = z.y.atan2(z.x) * power;
            let direction = DVec3::new(
                polar.sin() * azimuth.cos(),
                polar.sin() * azimuth.sin(),
                polar.cos(),
            );
            direction * r.powf(power) + p
        };
    }
    z.length() <= bailout
}

/// Whether `p` is in the Mandelbox of `scale` at `iterations` iterations
/// (the set of [`InsideShape::mandelbox`], not clipped to its bounds).
#[must_use]
pub fn mandelbox_contains(p: DVec3, scale: f64, iterations: u32) -> bool {
    let mut z = p;
    for _ in 0..iterations {
        z = z.clamp(DVec3::splat(-1.0), DVec3::splat(1.0)) * 2.0 - z;
        let r2 = z.length_squared();
        let k = if r2 < 0.25 {
            4.0
        } else if r2 < 1.0 {
            1.0 / r2
        } else {
            1.0
        };
        z = z * (scale * k) + p;
        if z.length_squared() > MANDELBOX_BAILOUT * MANDELBOX_BAILOUT {
            return false;
        }
    }
    true
}
