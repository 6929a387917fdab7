//! The fluent builder API: free functions that make shapes, and methods on
//! [`Node`] that transform and combine them.
//!
//! Nothing here validates: building never fails, and [`Scene::validate`]
//! (or anything that compiles a scene) reports every bad value with the node
//! and parameter it belongs to.
//!
//! [`Scene::validate`]: super::Scene::validate

use glam::{DQuat, DVec3, DVec4, EulerRot};

use super::custom::CustomShape;
use super::fractal::{Kifs, KifsFold, Mandelbox, Mandelbulb, Menger, QuaternionJulia, Sierpinski};
use super::material::Material;
use super::node::{Axis, CsgOp, Kind, Node};
use super::param::{Param, Param3};
use super::profile::Profile;
use super::trap::{OrbitColoring, Palette, Trap};

/// A sphere of `radius` at the origin.
#[must_use]
pub fn sphere(radius: impl Into<Param>) -> Node {
    Kind::Sphere {
        radius: radius.into(),
    }
    .into()
}

/// An axis-aligned box at the origin with the given half extents.
#[must_use]
pub fn cuboid(half_extents: impl Into<Param3>) -> Node {
    Kind::Cuboid {
        half_extents: half_extents.into(),
    }
    .into()
}

/// A box of the given half extents whose edges are rounded by `radius`.
#[must_use]
pub fn round_box(half_extents: impl Into<Param3>, radius: impl Into<Param>) -> Node {
    Kind::RoundBox {
        half_extents: half_extents.into(),
        radius: radius.into(),
    }
    .into()
}

/// A torus around the y axis (exact where `minor_radius <=
/// major_radius`).
#[must_use]
pub fn torus(major_radius: impl Into<Param>, minor_radius: impl Into<Param>) -> Node {
    Kind::Torus {
        major_radius: major_radius.into(),
        minor_radius: minor_radius.into(),
    }
    .into()
}

/// A capped cylinder along the y axis.
#[must_use]
pub fn cylinder(radius: impl Into<Param>, half_height: impl Into<Param>) -> Node {
    Kind::Cylinder {
        radius: radius.into(),
        half_height: half_height.into(),
    }
    .into()
}

/// A capsule around the segment from `a` to `b`.
#[must_use]
pub fn capsule(a: impl Into<Param3>, b: impl Into<Param3>, radius: impl Into<Param>) -> Node {
    Kind::Capsule {
        a: a.into(),
        b: b.into(),
        radius: radius.into(),
    }
    .into()
}

/// The half-space below the plane `dot(p, normal) + offset = 0`.
#[must_use]
pub fn plane(normal: impl Into<Param3>, offset: impl Into<Param>) -> Node {
    Kind::Plane {
        normal: normal.into(),
        offset: offset.into(),
    }
    .into()
}

/// A regular octahedron with vertices at distance `size` on each axis.
#[must_use]
pub fn octahedron(size: impl Into<Param>) -> Node {
    Kind::Octahedron { size: size.into() }.into()
}

/// Quilez's cheap bound of the octahedron of [`octahedron`]: the distance
/// to the nearest face's plane, below the true distance near the edges
/// and vertices (see [`Kind::OctahedronBound`]).
#[must_use]
pub fn octahedron_bound(size: impl Into<Param>) -> Node {
    Kind::OctahedronBound { size: size.into() }.into()
}

/// A hexagonal prism along y from `-half_height` to `+half_height`, its
/// flat sides `radius` from the axis (two of them facing ±z).
#[must_use]
pub fn hex_prism(radius: impl Into<Param>, half_height: impl Into<Param>) -> Node {
    Kind::HexPrism {
        radius: radius.into(),
        half_height: half_height.into(),
    }
    .into()
}

/// A round cone along y: the convex hull of the ball of `bottom_radius`
/// centred at `-half_height` and the ball of `top_radius` at
/// `+half_height`.
#[must_use]
pub fn round_cone(
    half_height: impl Into<Param>,
    bottom_radius: impl Into<Param>,
    top_radius: impl Into<Param>,
) -> Node {
    Kind::RoundCone {
        half_height: half_height.into(),
        bottom_radius: bottom_radius.into(),
        top_radius: top_radius.into(),
    }
    .into()
}

/// A chain link in the xy plane, centred on the origin and long along y:
/// a tube of `minor_radius` around two straight sides of `2 half_length`
/// at `x = ±major_radius`, joined by half circles of `major_radius`.
#[must_use]
pub fn link(
    half_length: impl Into<Param>,
    major_radius: impl Into<Param>,
    minor_radius: impl Into<Param>,
) -> Node {
    Kind::Link {
        half_length: half_length.into(),
        major_radius: major_radius.into(),
        minor_radius: minor_radius.into(),
    }
    .into()
}

/// The ball of `radius` about the origin cut by the plane `y = height`,
/// keeping the part below (a height beyond `±radius` is taken as
/// `±radius`).
#[must_use]
pub fn cut_sphere(radius: impl Into<Param>, height: impl Into<Param>) -> Node {
    Kind::CutSphere {
        radius: radius.into(),
        height: height.into(),
    }
    .into()
}

/// The part of the ball of `radius` about the origin within `angle`
/// radians (in `[0, MAX_SOLID_ANGLE]`, 3.1) of the +y axis: a cone capped
/// by the sphere.
#[must_use]
pub fn solid_angle(angle: impl Into<Param>, radius: impl Into<Param>) -> Node {
    Kind::SolidAngle {
        angle: angle.into(),
        radius: radius.into(),
    }
    .into()
}

/// A torus cut to an arc: the tube of `minor_radius` around the arc of the
/// circle of `major_radius` in the xy plane within `angle` radians (in
/// `[0, π]`) of the +y axis, its ends capped by half balls. Exact where
/// `minor_radius <= major_radius` and the caps do not meet.
#[must_use]
pub fn capped_torus(
    angle: impl Into<Param>,
    major_radius: impl Into<Param>,
    minor_radius: impl Into<Param>,
) -> Node {
    Kind::CappedTorus {
        angle: angle.into(),
        major_radius: major_radius.into(),
        minor_radius: minor_radius.into(),
    }
    .into()
}

/// All points within `thickness` (greater than 0) of the triangle with corners `a`, `b` and `c`: a thickened triangle, its edges rounded.
#[must_use]
pub fn triangle(
    a: impl Into<Param3>,
    b: impl Into<Param3>,
    c: impl Into<Param3>,
    thickness: impl Into<Param>,
) -> Node {
    Kind::Triangle {
        a: a.into(),
        b: b.into(),
        c: c.into(),
        thickness: thickness.into(),
    }
    .into()
}

/// All points within `thickness` (greater than 0) of the quadrilateral with corners `a`, `b`, `c`, `d` in order (the triangles `abc` and `acd`): exact where it is flat and convex.
#[must_use]
pub fn quad(
    a: impl Into<Param3>,
    b: impl Into<Param3>,
    c: impl Into<Param3>,
    d: impl Into<Param3>,
    thickness: impl Into<Param>,
) -> Node {
    Kind::Quad {
        a: a.into(),
        b: b.into(),
        c: c.into(),
        d: d.into(),
        thickness: thickness.into(),
    }
    .into()
}

/// A pyramid on the square `|x|, |z| <= half_base` at `y = 0`, its apex `height` above the origin.
#[must_use]
pub fn pyramid(half_base: impl Into<Param>, height: impl Into<Param>) -> Node {
    Kind::Pyramid {
        half_base: half_base.into(),
        height: height.into(),
    }
    .into()
}

/// A rhombus in the xz plane with half diagonals `half_x` and `half_z`, grown by `radius` in its plane, between `y = ±half_height`.
#[must_use]
pub fn rhombus(
    half_x: impl Into<Param>,
    half_z: impl Into<Param>,
    half_height: impl Into<Param>,
    radius: impl Into<Param>,
) -> Node {
    Kind::Rhombus {
        half_x: half_x.into(),
        half_z: half_z.into(),
        half_height: half_height.into(),
        radius: radius.into(),
    }
    .into()
}

/// A prism along y over the equilateral triangle in the xz plane whose sides lie `radius` from the axis (a corner towards +z), between `y = ±half_height`.
#[must_use]
pub fn tri_prism(radius: impl Into<Param>, half_height: impl Into<Param>) -> Node {
    Kind::TriPrism {
        radius: radius.into(),
        half_height: half_height.into(),
    }
    .into()
}

/// A cylinder along y of outer `radius` between `y = ±half_height`, its rims rounded by `rounding` (at most the smaller of the two).
#[must_use]
pub fn rounded_cylinder(
    radius: impl Into<Param>,
    half_height: impl Into<Param>,
    rounding: impl Into<Param>,
) -> Node {
    Kind::RoundedCylinder {
        radius: radius.into(),
        half_height: half_height.into(),
        rounding: rounding.into(),
    }
    .into()
}

/// A cone with its apex at the origin and its base, a disc of `radius`, at `y = -height`.
#[must_use]
pub fn cone(radius: impl Into<Param>, height: impl Into<Param>) -> Node {
    Kind::Cone {
        radius: radius.into(),
        height: height.into(),
    }
    .into()
}

/// An infinite cylinder of `radius` around the y axis.
#[must_use]
pub fn infinite_cylinder(radius: impl Into<Param>) -> Node {
    Kind::InfiniteCylinder {
        radius: radius.into(),
    }
    .into()
}

/// An infinite cone with its apex at the origin, opening around +y with the half-angle `angle` (radians, in `[0, π/2]`; π/2 is the half-space above the xz plane).
#[must_use]
pub fn infinite_cone(angle: impl Into<Param>) -> Node {
    Kind::InfiniteCone {
        angle: angle.into(),
    }
    .into()
}

/// A bowl: the shell of `thickness` about the sphere of `radius`, cut by the plane `y = height`, keeping the part below.
#[must_use]
pub fn cut_hollow_sphere(
    radius: impl Into<Param>,
    height: impl Into<Param>,
    thickness: impl Into<Param>,
) -> Node {
    Kind::CutHollowSphere {
        radius: radius.into(),
        height: height.into(),
        thickness: thickness.into(),
    }
    .into()
}

/// The ball of `radius` about the origin with the ball of `carve_radius` about `(carve_distance, 0, 0)` carved from it.
#[must_use]
pub fn death_star(
    radius: impl Into<Param>,
    carve_radius: impl Into<Param>,
    carve_distance: impl Into<Param>,
) -> Node {
    Kind::DeathStar {
        radius: radius.into(),
        carve_radius: carve_radius.into(),
        carve_distance: carve_distance.into(),
    }
    .into()
}

/// The edges of the box of `half_extents`: twelve square bars of `thickness` (at most the smallest half extent). Exact outside, a bound inside.
#[must_use]
pub fn box_frame(half_extents: impl Into<Param3>, thickness: impl Into<Param>) -> Node {
    Kind::BoxFrame {
        half_extents: half_extents.into(),
        thickness: thickness.into(),
    }
    .into()
}

/// A capped cylinder of `radius` around the segment from `a` to `b`.
#[must_use]
pub fn cylinder_between(
    a: impl Into<Param3>,
    b: impl Into<Param3>,
    radius: impl Into<Param>,
) -> Node {
    Kind::CylinderBetween {
        a: a.into(),
        b: b.into(),
        radius: radius.into(),
    }
    .into()
}

/// A capped cone around the segment from `a` to `b`, of radius `radius_a`
/// at `a` and `radius_b` at `b`.
#[must_use]
pub fn cone_between(
    a: impl Into<Param3>,
    b: impl Into<Param3>,
    radius_a: impl Into<Param>,
    radius_b: impl Into<Param>,
) -> Node {
    Kind::ConeBetween {
        a: a.into(),
        b: b.into(),
        radius_a: radius_a.into(),
        radius_b: radius_b.into(),
    }
    .into()
}

/// The convex hull of the ball of `radius_a` about `a` and the ball of
/// `radius_b` about `b`: a round cone between two points.
#[must_use]
pub fn round_cone_between(
    a: impl Into<Param3>,
    b: impl Into<Param3>,
    radius_a: impl Into<Param>,
    radius_b: impl Into<Param>,
) -> Node {
    Kind::RoundConeBetween {
        a: a.into(),
        b: b.into(),
        radius_a: radius_a.into(),
        radius_b: radius_b.into(),
    }
    .into()
}

/// The prism of `profile`, a plane shape in the xy plane, between
/// `z = ±half_height`. Exact.
///
/// ```
/// use fractal_sdf::scene::{Profile, extrude};
///
/// // A five-pointed star, a tenth of a unit thick.
/// let star = extrude(
///     Profile::polygon((0..10).map(|i| {
///         let (r, a) = (if i % 2 == 0 { 1.0 } else { 0.4 }, i as f64 * 0.2 * std::f64::consts::PI);
///         [r * a.sin(), r * a.cos()]
///     })),
///     0.05,
/// );
/// # let _ = star;
/// ```
#[must_use]
pub fn extrude(profile: Profile, half_height: impl Into<Param>) -> Node {
    Kind::Extrude {
        profile,
        half_height: half_height.into(),
    }
    .into()
}

/// The solid swept by `profile` turning around the y axis, its x axis
/// running out from the axis with its origin at `offset`: a circle of
/// radius `r` at offset `R` sweeps a torus, a rectangle at offset 0 a
/// cylinder. Exact where the profile lies at `x >= -offset`.
///
/// ```
/// use fractal_sdf::scene::{Profile, revolve};
///
/// // A bowl: the cross-section of its wall and base, turned.
/// let bowl = revolve(
///     Profile::polygon([[0.0, -0.5], [0.6, -0.5], [0.9, 0.3], [0.8, 0.3], [0.52, -0.42], [0.0, -0.42]]),
///     0.0,
/// );
/// # let _ = bowl;
/// ```
#[must_use]
pub fn revolve(profile: Profile, offset: impl Into<Param>) -> Node {
    Kind::Revolve {
        profile,
        offset: offset.into(),
    }
    .into()
}

/// A capped cone along y from radius `bottom_radius` at `-half_height` to
/// `top_radius` at `+half_height`.
#[must_use]
pub fn capped_cone(
    half_height: impl Into<Param>,
    bottom_radius: impl Into<Param>,
    top_radius: impl Into<Param>,
) -> Node {
    Kind::CappedCone {
        half_height: half_height.into(),
        bottom_radius: bottom_radius.into(),
        top_radius: top_radius.into(),
    }
    .into()
}

/// An axis-aligned ellipsoid with the given semi-axes (a distance bound).
#[must_use]
pub fn ellipsoid(radii: impl Into<Param3>) -> Node {
    Kind::Ellipsoid {
        radii: radii.into(),
    }
    .into()
}

/// A Mandelbulb of `power` with 12 iterations and bailout 2, centred on
/// the origin. It lies in the ball of radius `2^(1/(power - 1))` about the
/// origin (about 1.104 for power 8, which reaches it; 2 for power 2),
/// whatever the iterations and bailout. Build a [`Mandelbulb`] for other
/// settings.
#[must_use]
pub fn mandelbulb(power: impl Into<Param>) -> Node {
    Mandelbulb::new(power).into()
}

/// The classic Menger sponge (scale 3) with `iterations` levels. It fills
/// the cube `[-1, 1]^3`: 0 levels is that solid cube, and every level keeps
/// its eight corners.
#[must_use]
pub fn menger(iterations: u32) -> Node {
    Menger::new(iterations).into()
}

/// A quaternion Julia set for the constant `c` = (x, y, z, w), with 12
/// iterations, bailout 4 and the slice w = 0, centred on the origin. It
/// lies in the ball of radius `(1 + sqrt(1 + 4|c|)) / 2` about the origin
/// (beyond it every orbit grows): 1 for `c = 0`, about 1.47 for
/// `[-0.2, 0.6, 0.2, 0.2]`, 2 for `|c| = 2`.
#[must_use]
pub fn julia(c: [f64; 4]) -> Node {
    QuaternionJulia::new(c.map(Param::from)).into()
}

/// The classic Sierpinski tetrahedron (scale 2) with `iterations` levels.
/// It lies in the regular tetrahedron with vertices `(1, 1, 1)`,
/// `(-1, -1, 1)`, `(1, -1, -1)` and `(-1, 1, -1)` (inside the cube
/// `[-1, 1]^3`): 0 levels is that solid tetrahedron, and every level keeps
/// the four vertices.
#[must_use]
pub fn sierpinski(iterations: u32) -> Node {
    Sierpinski::new(iterations).into()
}

/// A Mandelbox of `scale` (2 and −1.5 are classic; its magnitude in `[1.1,
/// 4]`) with fold limit 1, radii 0.5 and 1 and 16 iterations, centred on
/// the origin. Scale 2 lies in the cube `[-6, 6]^3`, scale −1.5 in `[-2,
/// 2]^3`. Build a [`Mandelbox`] for other settings.
#[must_use]
pub fn mandelbox(scale: impl Into<Param>) -> Node {
    Mandelbox::new(scale).into()
}

impl Mandelbox {
    /// A Mandelbox of `scale` with the usual folds: fold limit 1, minimum
    /// radius 0.5, fixed radius 1; 16 iterations.
    #[must_use]
    pub fn new(scale: impl Into<Param>) -> Self {
        Mandelbox {
            scale: scale.into(),
            min_radius: 0.5.into(),
            fixed_radius: 1.0.into(),
            fold_limit: 1.0.into(),
            iterations: 16,
            julia: None,
        }
    }

    /// Sets the sphere fold's inner radius.
    #[must_use]
    pub fn min_radius(mut self, radius: impl Into<Param>) -> Self {
        self.min_radius = radius.into();
        self
    }

    /// Sets the sphere fold's outer radius.
    #[must_use]
    pub fn fixed_radius(mut self, radius: impl Into<Param>) -> Self {
        self.fixed_radius = radius.into();
        self
    }

    /// Sets the box fold's half side.
    #[must_use]
    pub fn fold_limit(mut self, limit: impl Into<Param>) -> Self {
        self.fold_limit = limit.into();
        self
    }

    /// Sets the iteration count.
    #[must_use]
    pub fn iterations(mut self, iterations: u32) -> Self {
        self.iterations = iterations;
        self
    }

    /// Julia mode: adds the constant `c` in each iteration instead of the
    /// point.
    #[must_use]
    pub fn julia(mut self, c: [impl Into<Param>; 3]) -> Self {
        self.julia = Some(c.map(Into::into));
        self
    }
}

/// A kaleidoscopic IFS with the classic settings of `fold`: offset
/// `(1, 1, 1)` and scale 2 (the Sierpinski tetrahedron) for
/// [`KifsFold::Tetrahedral`], `(1, 0, 0)` and 2 (the Sierpinski octahedron)
/// for [`KifsFold::Octahedral`], the vertex `(0.8507, 0.5257, 0)` and `φ²`
/// for [`KifsFold::Icosahedral`], `(1, 1, 1)` and 3 (the Menger sponge)
/// for [`KifsFold::Menger`]; no turns, 12 iterations (8 for the Menger
/// fold). Build a [`Kifs`] to change them.
#[must_use]
pub fn kifs(fold: KifsFold) -> Node {
    Kifs::new(fold).into()
}

impl Kifs {
    /// A kaleidoscopic IFS with the classic settings of `fold` (see
    /// [`kifs`]).
    #[must_use]
    pub fn new(fold: KifsFold) -> Self {
        let (offset, scale, iterations) = match fold {
            KifsFold::Tetrahedral => ([1.0, 1.0, 1.0], 2.0, 12),
            KifsFold::Octahedral => ([1.0, 0.0, 0.0], 2.0, 12),
            KifsFold::Icosahedral => {
                // The unit vertex (φ, 1, 0) / |(φ, 1, 0)|, and φ².
                let phi = 0.5 * (1.0 + 5f64.sqrt());
                let norm = phi.hypot(1.0);
                ([phi / norm, 1.0 / norm, 0.0], phi * phi, 12)
            }
            KifsFold::Menger => ([1.0, 1.0, 1.0], 3.0, 8),
        };
        Kifs {
            fold,
            scale: scale.into(),
            offset: offset.map(Into::into),
            rotate_before: None,
            rotate_after: None,
            iterations,
        }
    }

    /// Sets the scale of each iteration.
    #[must_use]
    pub fn scale(mut self, scale: impl Into<Param>) -> Self {
        self.scale = scale.into();
        self
    }

    /// Sets the point each iteration scales about.
    #[must_use]
    pub fn offset(mut self, offset: [impl Into<Param>; 3]) -> Self {
        self.offset = offset.map(Into::into);
        self
    }

    /// Turns the point before each fold: by `angles[0]` radians about `x`,
    /// then `angles[1]` about `y`, then `angles[2]` about `z`.
    #[must_use]
    pub fn rotate_before(mut self, angles: [impl Into<Param>; 3]) -> Self {
        self.rotate_before = Some(angles.map(Into::into));
        self
    }

    /// Turns the point after each fold, as
    /// [`rotate_before`](Kifs::rotate_before).
    #[must_use]
    pub fn rotate_after(mut self, angles: [impl Into<Param>; 3]) -> Self {
        self.rotate_after = Some(angles.map(Into::into));
        self
    }

    /// Sets the iteration count.
    #[must_use]
    pub fn iterations(mut self, iterations: u32) -> Self {
        self.iterations = iterations;
        self
    }
}

impl Mandelbulb {
    /// A Mandelbulb of `power` with 12 iterations and bailout 2.
    #[must_use]
    pub fn new(power: impl Into<Param>) -> Self {
        Mandelbulb {
            power: power.into(),
            iterations: 12,
            bailout: 2.0.into(),
        }
    }

    /// Sets the iteration count.
    #[must_use]
    pub fn iterations(mut self, iterations: u32) -> Self {
        self.iterations = iterations;
        self
    }

    /// Sets the escape radius.
    #[must_use]
    pub fn bailout(mut self, bailout: impl Into<Param>) -> Self {
        self.bailout = bailout.into();
        self
    }
}

impl Menger {
    /// A classic (scale 3) sponge with `iterations` levels.
    #[must_use]
    pub fn new(iterations: u32) -> Self {
        Menger {
            iterations,
            scale: 3.0.into(),
        }
    }

    /// Sets the scale factor of each level.
    #[must_use]
    pub fn scale(mut self, scale: impl Into<Param>) -> Self {
        self.scale = scale.into();
        self
    }
}

impl QuaternionJulia {
    /// A Julia set for `c` with 12 iterations, bailout 4, slice w = 0.
    #[must_use]
    pub fn new(c: [Param; 4]) -> Self {
        QuaternionJulia {
            c,
            iterations: 12,
            bailout: 4.0.into(),
            slice_w: 0.0.into(),
        }
    }

    /// Sets the iteration count.
    #[must_use]
    pub fn iterations(mut self, iterations: u32) -> Self {
        self.iterations = iterations;
        self
    }

    /// Sets the escape radius.
    #[must_use]
    pub fn bailout(mut self, bailout: impl Into<Param>) -> Self {
        self.bailout = bailout.into();
        self
    }

    /// Sets the w coordinate of the rendered 3D slice.
    #[must_use]
    pub fn slice_w(mut self, w: impl Into<Param>) -> Self {
        self.slice_w = w.into();
        self
    }
}

impl Sierpinski {
    /// A classic (scale 2) tetrahedron with `iterations` levels.
    #[must_use]
    pub fn new(iterations: u32) -> Self {
        Sierpinski {
            iterations,
            scale: 2.0.into(),
        }
    }

    /// Sets the scale factor of each level.
    #[must_use]
    pub fn scale(mut self, scale: impl Into<Param>) -> Self {
        self.scale = scale.into();
        self
    }
}

/// Transforms, domain operations, booleans and colour.
impl Node {
    /// Moves the node by `offset`.
    #[must_use]
    pub fn translate(self, offset: impl Into<Param3>) -> Node {
        Kind::Translate {
            offset: offset.into(),
            child: self,
        }
        .into()
    }

    /// Rotates the node by `angle` radians around `axis` (normalised here; a
    /// zero axis is reported by validation).
    #[must_use]
    pub fn rotate(self, axis: impl Into<DVec3>, angle: impl Into<Param>) -> Node {
        Kind::Rotate {
            axis: axis.into(),
            angle: angle.into(),
            child: self,
        }
        .into()
    }

    /// Rotates the node by a quaternion of any non-zero length (normalised
    /// here without overflow). A quaternion that is zero or not finite is
    /// no rotation: validation reports it as a zero or non-finite `axis`.
    #[must_use]
    pub fn rotate_quat(self, rotation: DQuat) -> Node {
        if !rotation.is_finite() {
            return self.rotate(DVec3::NAN, 0.0);
        }
        let largest = DVec4::from(rotation).abs().max_element();
        if largest == 0.0 {
            return self.rotate(DVec3::ZERO, 0.0);
        }
        let scaled = DQuat::from_vec4(DVec4::from(rotation) / largest);
        let (axis, angle) = scaled.normalize().to_axis_angle();
        if angle == 0.0 || !axis.is_finite() {
            return self.rotate(DVec3::Y, 0.0);
        }
        self.rotate(axis, angle)
    }

    /// Rotates the node by Euler angles in radians, applied in `order`.
    #[must_use]
    pub fn rotate_euler(self, order: EulerRot, a: f64, b: f64, c: f64) -> Node {
        self.rotate_quat(DQuat::from_euler(order, a, b, c))
    }

    /// Scales the node uniformly by `factor` (distances are rescaled, so an
    /// exact shape stays exact).
    #[must_use]
    pub fn scale(self, factor: impl Into<Param>) -> Node {
        Kind::Scale {
            factor: factor.into(),
            child: self,
        }
        .into()
    }

    /// Mirrors the node's positive half across the plane normal to `axis`.
    #[must_use]
    pub fn mirror(self, axis: Axis) -> Node {
        Kind::Mirror { axis, child: self }.into()
    }

    /// Grows the node by `radius`, rounding its edges.
    #[must_use]
    pub fn round(self, radius: impl Into<Param>) -> Node {
        Kind::Round {
            radius: radius.into(),
            child: self,
        }
        .into()
    }

    /// Keeps only a shell of `thickness` around the node's surface.
    #[must_use]
    pub fn onion(self, thickness: impl Into<Param>) -> Node {
        Kind::Onion {
            thickness: thickness.into(),
            child: self,
        }
        .into()
    }

    /// Stretches the node by `extents` along each axis.
    #[must_use]
    pub fn elongate(self, extents: impl Into<Param3>) -> Node {
        Kind::Elongate {
            extents: extents.into(),
            child: self,
        }
        .into()
    }

    /// Repeats the node forever with cell size `period` (0: not on that axis).
    #[must_use]
    pub fn repeat(self, period: impl Into<Param3>) -> Node {
        Kind::Repeat {
            period: period.into(),
            child: self,
        }
        .into()
    }

    /// Repeats the node in cells `-limit..=limit` per axis.
    #[must_use]
    pub fn repeat_limited(self, period: impl Into<Param3>, limit: [u32; 3]) -> Node {
        Kind::RepeatLimited {
            period: period.into(),
            limit,
            child: self,
        }
        .into()
    }

    /// Twists the node around y by `rate` radians per unit.
    #[must_use]
    pub fn twist(self, rate: impl Into<Param>) -> Node {
        Kind::Twist {
            rate: rate.into(),
            child: self,
        }
        .into()
    }

    /// Bends the node in the xy plane by `rate` radians per unit of x.
    #[must_use]
    pub fn bend(self, rate: impl Into<Param>) -> Node {
        Kind::Bend {
            rate: rate.into(),
            child: self,
        }
        .into()
    }

    /// Paints the node with a linear RGB colour.
    #[must_use]
    pub fn color(self, rgb: impl Into<Param3>) -> Node {
        Kind::Color {
            color: rgb.into(),
            child: self,
        }
        .into()
    }

    /// A halo of `color` (linear RGB) and `strength` around the node:
    /// rays that pass near it and hit nothing take its colour, fading
    /// with the angle they pass it at (see
    /// [`Effects::glow`](crate::quality::Effects::glow), the same for the
    /// whole scene). Halos of several nodes add up.
    ///
    /// ```
    /// use fractal_sdf::prelude::*;
    /// let lamp = sphere(0.3).glow(dvec3(1.0, 0.6, 0.2), 1.5);
    /// # let _ = lamp;
    /// ```
    #[must_use]
    pub fn glow(self, color: impl Into<Param3>, strength: impl Into<Param>) -> Node {
        Kind::Glow {
            color: color.into(),
            strength: strength.into(),
            child: self,
        }
        .into()
    }

    /// Gives the node a material: how its surfaces answer light (see
    /// [`Material`]). An outer material replaces an inner one, as an outer
    /// colour does.
    #[must_use]
    pub fn material(self, material: Material) -> Node {
        Kind::Material {
            material,
            child: self,
        }
        .into()
    }

    /// Colours the node, a fractal, by its orbit trap: the smallest distance
    /// from its orbit to `trap`, from 0 to 1 spanning `palette` (see
    /// [`OrbitColoring`], and [`Node::orbit_coloring`] for another range). The
    /// colour replaces the fractal's own; an outer colour paints over it.
    /// Compiling refuses a node that is not a fractal.
    ///
    /// ```
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::scene::{Palette, Trap};
    ///
    /// let bulb = mandelbulb(8.0).orbit_trap(Trap::point([0.0, 0.0, 0.0]), Palette::ocean());
    /// assert!(Scene::new(bulb).compile().is_ok());
    /// ```
    #[must_use]
    pub fn orbit_trap(self, trap: Trap, palette: Palette) -> Node {
        self.orbit_coloring(OrbitColoring::new(trap, palette))
    }

    /// Colours the node, a fractal, by its orbit trap (see
    /// [`Node::orbit_trap`]).
    #[must_use]
    pub fn orbit_coloring(self, coloring: OrbitColoring) -> Node {
        Kind::OrbitTrap {
            coloring,
            child: self,
        }
        .into()
    }

    fn csg(self, op: CsgOp, smoothing: Option<Param>, other: impl Into<Node>) -> Node {
        Kind::Csg {
            op,
            smoothing,
            a: self,
            b: other.into(),
        }
        .into()
    }

    /// Everything in `self` or `other`.
    #[must_use]
    pub fn union(self, other: impl Into<Node>) -> Node {
        self.csg(CsgOp::Union, None, other)
    }

    /// `self` with `other` carved out.
    #[must_use]
    pub fn subtract(self, other: impl Into<Node>) -> Node {
        self.csg(CsgOp::Subtract, None, other)
    }

    /// Only what is in both `self` and `other`.
    #[must_use]
    pub fn intersect(self, other: impl Into<Node>) -> Node {
        self.csg(CsgOp::Intersect, None, other)
    }

    /// `self` cut by `cutter`: only what is in both, like
    /// [`Node::intersect`], but the face the cutter makes shows `self`'s
    /// colour and orbit trap at that point, so a fractal cut open shows its
    /// inside coloured by how its orbits behave there. The cutter is any
    /// shape: a half-space for a cross-section ([`Node::cut_plane`]), a box
    /// for a cut-away corner. Its parameters can be dynamic, so a cut moves
    /// through a scene without a new program.
    ///
    /// ```
    /// use fractal_sdf::prelude::*;
    /// // A sphere cut open along x = 0: only its x < 0 half is left.
    /// let half = sphere(1.0).color(dvec3(1.0, 0.2, 0.1)).cut_plane(dvec3(1.0, 0.0, 0.0), 0.0);
    /// let eval = fractal_sdf::cpu::Evaluator::new(&half)?;
    /// assert!(eval.distance(dvec3(-0.5, 0.0, 0.0)) < 0.0);
    /// assert!(eval.distance(dvec3(0.5, 0.0, 0.0)) > 0.0);
    /// // The cut face keeps the sphere's colour.
    /// let face = eval.sample::<f64>(dvec3(0.0, 0.3, 0.0).into());
    /// assert_eq!(DVec3::from(face.color), dvec3(1.0, 0.2, 0.1));
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    #[must_use]
    pub fn cut(self, cutter: impl Into<Node>) -> Node {
        self.csg(CsgOp::Cut, None, cutter)
    }

    /// `self` cut by the plane `dot(p, normal) + offset = 0`: the side the
    /// normal points to is removed ([`Node::cut`] with a [`plane`]). Give
    /// `normal` and `offset` as dynamic parameters to move the cut
    /// without a new program.
    #[must_use]
    pub fn cut_plane(self, normal: impl Into<Param3>, offset: impl Into<Param>) -> Node {
        self.cut(plane(normal, offset))
    }

    /// Union with a smooth blend of radius `k` (`k = 0` is the hard union).
    #[must_use]
    pub fn smooth_union(self, other: impl Into<Node>, k: impl Into<Param>) -> Node {
        self.csg(CsgOp::Union, Some(k.into()), other)
    }

    /// Subtraction with a smooth seam of radius `k`.
    #[must_use]
    pub fn smooth_subtract(self, other: impl Into<Node>, k: impl Into<Param>) -> Node {
        self.csg(CsgOp::Subtract, Some(k.into()), other)
    }

    /// Intersection with a smooth seam of radius `k`.
    #[must_use]
    pub fn smooth_intersect(self, other: impl Into<Node>, k: impl Into<Param>) -> Node {
        self.csg(CsgOp::Intersect, Some(k.into()), other)
    }
}

impl CustomShape {
    /// A node of this shape with the given parameter values (plain numbers
    /// or [`param`](super::param) for dynamic ones). A wrong number of
    /// values is reported by validation.
    #[must_use]
    pub fn node<P: Into<Param>>(&self, args: impl IntoIterator<Item = P>) -> Node {
        Kind::Custom {
            shape: self.clone(),
            args: args.into_iter().map(Into::into).collect(),
        }
        .into()
    }
}
