//! The node vocabulary: one enum, [`Kind`], shared by the user-facing scene
//! tree ([`Node`]) and the lowered IR, so every node type, its parameters
//! and their validity rules are written down exactly once.

use std::f64::consts::FRAC_PI_2;
use std::fmt;
use std::sync::{Arc, OnceLock};

use glam::DVec3;

use super::custom::CustomShape;
use super::fractal::{Kifs, Mandelbox, Mandelbulb, Menger, QuaternionJulia, Sierpinski};
use super::hybrid::Hybrid;
use super::kleinian::PseudoKleinian;
use super::material::Material;
use super::param::{Param, Param3};
use super::profile::Profile;
use super::rule::{ParamSpec, Rule, spec};
use super::trap::OrbitColoring;

/// The largest iteration count accepted by the escape-time fractals
/// (Mandelbulb, quaternion Julia).
pub const MAX_ESCAPE_ITERATIONS: u32 = 256;

/// The largest iteration count accepted by the folding fractals (Menger
/// sponge, Sierpinski tetrahedron). Each level shrinks detail by the fractal's
/// scale, so 20 levels of a scale-3 sponge are already below `f64` precision.
pub const MAX_FOLD_ITERATIONS: u32 = 20;

/// The largest half-angle of a [`solid_angle`](crate::scene::solid_angle),
/// in radians: at π the cone's side would shrink to the −y axis inside the
/// ball, a line that is no part of the shape's surface.
pub const MAX_SOLID_ANGLE: f64 = 3.1;

/// A coordinate axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum Axis {
    /// The x axis.
    X,
    /// The y axis.
    Y,
    /// The z axis.
    Z,
}

impl Axis {
    /// The axis index: 0, 1 or 2.
    #[must_use]
    pub fn index(self) -> usize {
        self as usize
    }
}

/// The largest magnitude of a twist's or bend's rate, in radians per unit
/// (16 turns per unit). The warp stretches space by about `|rate| rho / 2`
/// at distance `rho` from its axis and its estimate shrinks as much, so
/// a larger rate leaves marching without the steps to reach the surface:
/// scale the scene up instead.
pub const MAX_WARP_RATE: f64 = 100.0;

/// The rule of a twist's or bend's rate.
const WARP_RATE: Rule = Rule::Range(-MAX_WARP_RATE, MAX_WARP_RATE);

/// The boolean operation of a [`Kind::Csg`] node.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum CsgOp {
    /// Everything in `a` or `b`: `min(a, b)`.
    Union,
    /// `a` with `b` carved out of it: `max(a, -b)`.
    Subtract,
    /// Only what is in both: `max(a, b)`.
    Intersect,
    /// `a` cut by `b`: only what is in both, as [`CsgOp::Intersect`], but
    /// showing `a`'s colour and orbit trap everywhere, the face `b` cuts
    /// included: a cross-section (see [`Node::cut`]).
    Cut,
}

/// Every node type, generic over how a scalar (`S`), a vector (`V`) and a
/// child (`C`) are stored.
///
/// The scene tree uses [`NodeKind`] (`Param`, `Param3`, `Node`); the IR uses
/// slots and arena handles. All sizes are in scene units, all angles in
/// radians. "Exact" means the value is the Euclidean distance; "bound" means
/// it never exceeds it (so rays never skip a surface).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Kind<S, V, C> {
    /// A sphere at the origin. Exact.
    Sphere {
        /// Radius, at least 0.
        radius: S,
    },
    /// An axis-aligned box at the origin. Exact.
    Cuboid {
        /// Half the size along each axis, each at least 0.
        half_extents: V,
    },
    /// A box with rounded edges; its outer size is `half_extents`. Exact.
    RoundBox {
        /// Half the outer size along each axis, each at least 0.
        half_extents: V,
        /// Edge radius, from 0 to the smallest half extent.
        radius: S,
    },
    /// A torus around the y axis. Exact where `minor_radius <=
    /// major_radius`; a thicker torus overlaps itself around the axis,
    /// where the distance is a bound.
    Torus {
        /// Distance from the centre to the middle of the tube.
        major_radius: S,
        /// Radius of the tube.
        minor_radius: S,
    },
    /// A capped cylinder along the y axis. Exact.
    Cylinder {
        /// Radius, at least 0.
        radius: S,
        /// Half the height, at least 0.
        half_height: S,
    },
    /// A capsule: all points within `radius` of the segment `a`-`b`. Exact.
    Capsule {
        /// One end of the segment.
        a: V,
        /// The other end of the segment.
        b: V,
        /// Radius, at least 0.
        radius: S,
    },
    /// The half-space `dot(p, normal) + offset <= 0`, normal normalised.
    /// Exact.
    Plane {
        /// The outward normal; must not be zero. Only its direction counts:
        /// a baked normal of any finite length is normalised in `f64` when
        /// the scene is compiled, a dynamic one by both twins after scaling
        /// it by its largest component.
        normal: V,
        /// Signed offset along the normal.
        offset: S,
    },
    /// A regular octahedron `|x| + |y| + |z| <= size`. Exact.
    Octahedron {
        /// Distance from the centre to each vertex, at least 0.
        size: S,
    },
    /// Quilez's cheap bound of the octahedron `|x| + |y| + |z| <= size`:
    /// `(|x| + |y| + |z| − size) / √3`, the distance to the nearest face's
    /// plane. A bound: exact where the nearest point is inside a face,
    /// below the distance near the edges and vertices.
    OctahedronBound {
        /// Distance from the centre to each vertex, at least 0.
        size: S,
    },
    /// A cone along y, cut at `±half_height`, with radius `bottom_radius` at
    /// `-half_height` and `top_radius` at `+half_height`. Exact.
    CappedCone {
        /// Half the height, at least 0.
        half_height: S,
        /// Radius at the bottom cap, at least 0.
        bottom_radius: S,
        /// Radius at the top cap, at least 0.
        top_radius: S,
    },
    /// A hexagonal prism along y, two flat sides facing ±z. Exact.
    HexPrism {
        /// The distance from the axis to each flat side, at least 0.
        radius: S,
        /// Half the height, at least 0.
        half_height: S,
    },
    /// A round cone along y: the convex hull of a ball at each end. Exact.
    RoundCone {
        /// Half the distance between the balls' centres, at least 0.
        half_height: S,
        /// Radius of the ball at `-half_height`, at least 0.
        bottom_radius: S,
        /// Radius of the ball at `+half_height`, at least 0.
        top_radius: S,
    },
    /// A chain link in the xy plane, long along y: a tube around two
    /// straight sides joined by half circles. Exact where `minor_radius <=
    /// major_radius` (a thicker tube overlaps itself inside).
    Link {
        /// Half the length of the straight sides, at least 0.
        half_length: S,
        /// Radius of the half circles (half the link's width), at least 0.
        major_radius: S,
        /// Radius of the tube, at least 0.
        minor_radius: S,
    },
    /// The ball of `radius` about the origin cut by the plane
    /// `y = height`, keeping the part below. Exact.
    CutSphere {
        /// The ball's radius, at least 0.
        radius: S,
        /// The cutting plane's height, any finite value: taken as
        /// `±radius` beyond them (the whole ball above, its lowest point
        /// below).
        height: S,
    },
    /// The part of the ball of `radius` about the origin within `angle` of
    /// the +y axis: a cone of half-angle `angle` capped by the sphere.
    /// Exact.
    SolidAngle {
        /// The cone's half-angle in radians, in `[0, MAX_SOLID_ANGLE]`
        /// (3.1; past π/2 the cone opens downwards).
        angle: S,
        /// The ball's radius, at least 0.
        radius: S,
    },
    /// A torus cut to an arc: the tube of radius `minor_radius` around the
    /// arc of the circle of radius `major_radius` in the xy plane within
    /// `angle` of the +y axis, capped by half balls. Exact where the tube
    /// is no thicker than the arc's radius and its two caps do not meet
    /// (`minor <= major`, and `minor <= major sin(angle)` past a quarter
    /// turn short of the whole torus).
    CappedTorus {
        /// The arc's half-angle in radians, in `[0, π]` (π: the whole
        /// torus).
        angle: S,
        /// The arc's radius, at least 0.
        major_radius: S,
        /// The tube's radius, at least 0.
        minor_radius: S,
    },
    /// All points within `thickness` of the triangle `abc`: a thickened triangle, its edges rounded. Exact.
    Triangle {
        /// One corner.
        a: V,
        /// The second corner.
        b: V,
        /// The third corner.
        c: V,
        /// How far the solid reaches from the triangle, greater than 0.
        thickness: S,
    },
    /// All points within `thickness` of the quadrilateral `abcd` (the triangles `abc` and `acd`): a thickened quad, its edges rounded. Exact where the quad is flat and convex; otherwise exact outside and a bound inside.
    Quad {
        /// One corner.
        a: V,
        /// The second corner.
        b: V,
        /// The third corner.
        c: V,
        /// The fourth corner.
        d: V,
        /// How far the solid reaches from the quad, greater than 0.
        thickness: S,
    },
    /// A pyramid on the square `|x|, |z| <= half_base` at `y = 0` with its apex at `(0, height, 0)`. Exact.
    Pyramid {
        /// Half the side of the square base, greater than 0.
        half_base: S,
        /// The apex's height above the base, at least 0.
        height: S,
    },
    /// A rhombus in the xz plane with half diagonals `half_x` and `half_z`, grown by `radius` in its plane (its corners rounded), between `y = ±half_height`. Exact.
    Rhombus {
        /// Half the diagonal along x, at least 0.
        half_x: S,
        /// Half the diagonal along z, at least 0.
        half_z: S,
        /// Half the height along y, at least 0.
        half_height: S,
        /// How far the rhombus grows in its plane, rounding its corners, at least 0.
        radius: S,
    },
    /// A prism along y over the equilateral triangle in the xz plane whose sides lie `radius` from the axis, a corner towards +z. Exact.
    TriPrism {
        /// The distance from the axis to each side, at least 0.
        radius: S,
        /// Half the height, at least 0.
        half_height: S,
    },
    /// A cylinder along y of outer `radius` between `y = ±half_height`, its rims rounded by `rounding`. Exact.
    RoundedCylinder {
        /// Radius, at least 0.
        radius: S,
        /// Half the height, at least 0.
        half_height: S,
        /// Radius of the rounded rims, from 0 to the smaller of `radius` and `half_height`.
        rounding: S,
    },
    /// A cone with its apex at the origin and its base, a disc of `radius`, at `y = -height`. Exact.
    Cone {
        /// Radius of the base, at least 0.
        radius: S,
        /// Height, at least 0.
        height: S,
    },
    /// An infinite cylinder of `radius` around the y axis. Exact.
    InfiniteCylinder {
        /// Radius, at least 0.
        radius: S,
    },
    /// An infinite cone with its apex at the origin, opening around +y with the half-angle `angle`. Exact.
    InfiniteCone {
        /// The half-angle in radians, in `[0, π/2]`.
        angle: S,
    },
    /// A shell of `thickness` about the sphere of `radius` about the origin, cut by the plane `y = height`, keeping the part below: a bowl. Exact.
    CutHollowSphere {
        /// The sphere's radius, at least 0.
        radius: S,
        /// The cutting plane's height, any finite value: taken as `±radius` beyond them.
        height: S,
        /// Half the shell's thickness, at least 0.
        thickness: S,
    },
    /// The ball of `radius` about the origin with the ball of `carve_radius` about `(carve_distance, 0, 0)` carved from it. Exact.
    DeathStar {
        /// The ball's radius, at least 0.
        radius: S,
        /// The carved ball's radius, at least 0.
        carve_radius: S,
        /// How far along +x the carved ball's centre lies, greater than 0.
        carve_distance: S,
    },
    /// The edges of a box: twelve square bars of `thickness` along the edges of the box of `half_extents`. Exact outside; inside, a bound (where bars meet, the depth can exceed the deepest bar's).
    BoxFrame {
        /// Half the outer size along each axis, each at least 0.
        half_extents: V,
        /// The edges' thickness, from 0 to the smallest half extent.
        thickness: S,
    },
    /// A capped cylinder around the segment from `a` to `b`. Exact.
    CylinderBetween {
        /// The centre of one cap.
        a: V,
        /// The centre of the other cap.
        b: V,
        /// Radius, at least 0.
        radius: S,
    },
    /// A capped cone around the segment from `a` to `b`, of radius
    /// `radius_a` at `a` and `radius_b` at `b`. Exact.
    ConeBetween {
        /// The centre of one cap.
        a: V,
        /// The centre of the other cap.
        b: V,
        /// Radius at `a`, at least 0.
        radius_a: S,
        /// Radius at `b`, at least 0.
        radius_b: S,
    },
    /// A round cone between two balls: the convex hull of the ball of
    /// `radius_a` about `a` and the ball of `radius_b` about `b`. Exact.
    RoundConeBetween {
        /// The centre of one ball.
        a: V,
        /// The centre of the other ball.
        b: V,
        /// Radius of the ball about `a`, at least 0.
        radius_a: S,
        /// Radius of the ball about `b`, at least 0.
        radius_b: S,
    },
    /// A plane shape in the xy plane extruded along z: the prism of
    /// `profile` between `z = ±half_height`. Exact.
    Extrude {
        /// The cross-section.
        profile: Profile<S>,
        /// Half the height along z, at least 0.
        half_height: S,
    },
    /// The solid swept by a plane shape turning around the y axis: the
    /// profile's x axis runs out from the axis, its origin at `offset`
    /// (so a circle of radius `r` at offset `R` sweeps a torus). Exact
    /// where the profile lies at `x >= -offset`; a profile reaching past
    /// the axis sweeps only its part at `x >= -offset`, and there the
    /// distance is a bound.
    Revolve {
        /// The cross-section.
        profile: Profile<S>,
        /// How far the profile's origin lies from the axis, any finite
        /// value.
        offset: S,
    },
    /// An axis-aligned ellipsoid. A bound, not exact: outside, the distance
    /// is underestimated away from the axes (Quilez's `k0 (k0 - 1) / k1`,
    /// which is not 1-Lipschitz near thin ellipsoids); inside, the depth is
    /// `(k0 - 1)` times the shortest semi-axis.
    Ellipsoid {
        /// Semi-axes, each greater than 0.
        radii: V,
    },
    /// See [`Mandelbulb`].
    Mandelbulb(Mandelbulb<S>),
    /// See [`Menger`].
    Menger(Menger<S>),
    /// See [`QuaternionJulia`].
    Julia(QuaternionJulia<S>),
    /// See [`Sierpinski`].
    Sierpinski(Sierpinski<S>),
    /// See [`Mandelbox`].
    Mandelbox(Mandelbox<S>),
    /// See [`PseudoKleinian`].
    PseudoKleinian(PseudoKleinian<S>),
    /// See [`Kifs`].
    Kifs(Kifs<S>),
    /// See [`Hybrid`].
    Hybrid(Hybrid<S>),
    /// Moves the child by `offset`. Preserves exactness.
    Translate {
        /// The translation.
        offset: V,
        /// The moved node.
        child: C,
    },
    /// Rotates the child by `angle` radians around the unit vector `axis`
    /// (right-handed). Preserves exactness.
    Rotate {
        /// The rotation axis, normalised; must not be zero.
        axis: DVec3,
        /// The angle in radians, any finite value: it is reduced modulo a
        /// full turn ([`math::reduce_angle`](crate::math::reduce_angle))
        /// before either twin uses it, baked or dynamic.
        angle: S,
        /// The rotated node.
        child: C,
    },
    /// Uniform scale; the distance is rescaled, so exactness is preserved.
    Scale {
        /// The scale factor, greater than 0.
        factor: S,
        /// The scaled node.
        child: C,
    },
    /// Mirror symmetry across the plane through the origin normal to `axis`:
    /// the child's positive half appears on both sides. Exact when the child
    /// is symmetric or lies entirely on the positive side; a bound otherwise.
    Mirror {
        /// The axis normal to the mirror plane.
        axis: Axis,
        /// The mirrored node.
        child: C,
    },
    /// Rounds the child: grows it by `radius` (`d - radius`).
    Round {
        /// The rounding radius, at least 0.
        radius: S,
        /// The rounded node.
        child: C,
    },
    /// A shell of the child's surface: `|d| - thickness`.
    Onion {
        /// Half the shell thickness, at least 0.
        thickness: S,
        /// The shelled node.
        child: C,
    },
    /// Stretches the child by inserting `extents` of straight material at
    /// the origin along each axis (`p - clamp(p, -h, h)`). Exact outside,
    /// a bound inside.
    Elongate {
        /// How far to stretch along each axis (each half), at least 0.
        extents: V,
        /// The elongated node.
        child: C,
    },
    /// Infinite repetition with cell size `period` (0 on an axis: no
    /// repetition there). Exact when the child fits in half a cell.
    Repeat {
        /// Cell size along each axis, at least 0.
        period: V,
        /// The repeated node.
        child: C,
    },
    /// Repetition limited to cells `-limit..=limit` on each axis.
    RepeatLimited {
        /// Cell size along each axis, at least 0.
        period: V,
        /// How many copies each side of the original, per axis.
        limit: [u32; 3],
        /// The repeated node.
        child: C,
    },
    /// Twists the child around the y axis by `rate` radians per unit of y.
    /// The twist stretches space by up to `L(rho) = t/2 + sqrt(1 + t^2/4)`,
    /// `t = |rate| rho`, at distance `rho` from the y axis; the child's
    /// distance `d` is divided by `L(rho + |d| / L(rho))`, the largest
    /// stretch within reach, so the result stays a bound. Where the child
    /// has a bound, the estimate is also at least the distance to the ball
    /// around the twisted child (the twist keeps height and distance from
    /// the axis), so far from the shape it stays a distance, and the twist
    /// slows and darkens nothing around it.
    Twist {
        /// Radians of twist per unit along y, at most [`MAX_WARP_RATE`] in
        /// magnitude.
        rate: S,
        /// The twisted node.
        child: C,
    },
    /// Bends the child in the xy plane by `rate` radians per unit of x.
    /// Local stretch `L(rho) = 1 + |rate| rho` (rho: length of `p.xy`); the
    /// distance is divided by `L(rho + |d| / L(rho))`, so it stays a bound.
    /// Where the child has a bound, the estimate is also at least the
    /// distance to the ball around the bent child (the bend keeps `p.z`
    /// and the length of `p.xy`), so far from the shape it stays a
    /// distance.
    Bend {
        /// Radians of bend per unit along x, at most [`MAX_WARP_RATE`] in
        /// magnitude.
        rate: S,
        /// The bent node.
        child: C,
    },
    /// A boolean of two nodes, hard (`smoothing: None`) or smooth with the
    /// polynomial smooth minimum of radius `k`, which deviates from the hard
    /// operation by at most `k / 4` and equals it at `k = 0`. Colours blend
    /// across the smooth seam.
    Csg {
        /// Union, subtraction or intersection.
        op: CsgOp,
        /// The smoothing radius `k >= 0`, or `None` for the hard operation.
        smoothing: Option<S>,
        /// The first operand.
        a: C,
        /// The second operand.
        b: C,
    },
    /// A user-defined shape (see [`CustomShape`]) with its parameter values.
    Custom {
        /// The shape's definition.
        shape: CustomShape,
        /// One value per declared parameter, in order.
        args: Vec<S>,
    },
    /// Paints the child (every surface below this node) with a linear RGB
    /// colour.
    Color {
        /// Linear RGB, each at least 0.
        color: V,
        /// The painted node.
        child: C,
    },
    /// A halo around the child: rays that pass near its surfaces and hit
    /// nothing take `color` times `strength`, fading with the angle they
    /// pass at, as [`Effects::glow`](crate::quality::Effects::glow) does
    /// for the whole scene. The distance is the child's.
    Glow {
        /// Linear RGB, each at least 0.
        color: V,
        /// How bright, at least 0 (0.5 subtle, 2 strong).
        strength: S,
        /// The node that glows.
        child: C,
    },
    /// Gives the child (every surface below this node) a material: how it
    /// answers light (see [`Material`]).
    Material {
        /// The material's values.
        material: Material<S>,
        /// The node it covers.
        child: C,
    },
    /// Colours the child, a fractal, by its orbit trap through a palette
    /// (see [`OrbitColoring`]). The distance is the child's.
    OrbitTrap {
        /// The trap, the palette and the range of trap values shown.
        coloring: OrbitColoring<S, V>,
        /// The fractal.
        child: C,
    },
}

/// Converts the scalars, vectors and children of a [`Kind`] into another
/// representation, failing with `E`. Used by lowering and validation.
pub(crate) trait Mapper<S, V, C> {
    type S2;
    type V2;
    type C2;
    type E;
    fn scalar(&mut self, s: &S, spec: ParamSpec<'_>) -> Result<Self::S2, Self::E>;
    fn vector(&mut self, v: &V, spec: ParamSpec<'_>) -> Result<Self::V2, Self::E>;
    fn child(&mut self, c: &C) -> Result<Self::C2, Self::E>;
}

/// The result of mapping a `Kind<S, V, C>` with `M`.
pub(crate) type Mapped<S, V, C, M> =
    Kind<<M as Mapper<S, V, C>>::S2, <M as Mapper<S, V, C>>::V2, <M as Mapper<S, V, C>>::C2>;

impl<S, V, C> Kind<S, V, C> {
    /// The node type's name, as used in error messages.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Kind::Sphere { .. } => "sphere",
            Kind::Cuboid { .. } => "cuboid",
            Kind::RoundBox { .. } => "round_box",
            Kind::Torus { .. } => "torus",
            Kind::Cylinder { .. } => "cylinder",
            Kind::Capsule { .. } => "capsule",
            Kind::Plane { .. } => "plane",
            Kind::Octahedron { .. } => "octahedron",
            Kind::OctahedronBound { .. } => "octahedron_bound",
            Kind::CappedCone { .. } => "capped_cone",
            Kind::HexPrism { .. } => "hex_prism",
            Kind::RoundCone { .. } => "round_cone",
            Kind::Link { .. } => "link",
            Kind::CutSphere { .. } => "cut_sphere",
            Kind::SolidAngle { .. } => "solid_angle",
            Kind::CappedTorus { .. } => "capped_torus",
            Kind::Triangle { .. } => "triangle",
            Kind::Quad { .. } => "quad",
            Kind::Pyramid { .. } => "pyramid",
            Kind::Rhombus { .. } => "rhombus",
            Kind::TriPrism { .. } => "tri_prism",
            Kind::RoundedCylinder { .. } => "rounded_cylinder",
            Kind::Cone { .. } => "cone",
            Kind::InfiniteCylinder { .. } => "infinite_cylinder",
            Kind::InfiniteCone { .. } => "infinite_cone",
            Kind::CutHollowSphere { .. } => "cut_hollow_sphere",
            Kind::DeathStar { .. } => "death_star",
            Kind::BoxFrame { .. } => "box_frame",
            Kind::CylinderBetween { .. } => "cylinder_between",
            Kind::ConeBetween { .. } => "cone_between",
            Kind::RoundConeBetween { .. } => "round_cone_between",
            Kind::Extrude { .. } => "extrude",
            Kind::Revolve { .. } => "revolve",
            Kind::Ellipsoid { .. } => "ellipsoid",
            Kind::Mandelbulb(_) => "mandelbulb",
            Kind::Menger(_) => "menger",
            Kind::Julia(_) => "julia",
            Kind::Sierpinski(_) => "sierpinski",
            Kind::Mandelbox(_) => "mandelbox",
            Kind::PseudoKleinian(_) => "pseudo_kleinian",
            Kind::Kifs(_) => "kifs",
            Kind::Hybrid(_) => "hybrid",
            Kind::Translate { .. } => "translate",
            Kind::Rotate { .. } => "rotate",
            Kind::Scale { .. } => "scale",
            Kind::Mirror { .. } => "mirror",
            Kind::Round { .. } => "round",
            Kind::Onion { .. } => "onion",
            Kind::Elongate { .. } => "elongate",
            Kind::Repeat { .. } => "repeat",
            Kind::RepeatLimited { .. } => "repeat_limited",
            Kind::Twist { .. } => "twist",
            Kind::Bend { .. } => "bend",
            Kind::Csg { op, smoothing, .. } => match (op, smoothing.is_some()) {
                (CsgOp::Union, false) => "union",
                (CsgOp::Subtract, false) => "subtract",
                (CsgOp::Intersect, false) => "intersect",
                (CsgOp::Union, true) => "smooth_union",
                (CsgOp::Subtract, true) => "smooth_subtract",
                (CsgOp::Intersect, true) => "smooth_intersect",
                (CsgOp::Cut, false) => "cut",
                (CsgOp::Cut, true) => "smooth_cut",
            },
            Kind::Custom { .. } => "custom",
            Kind::Color { .. } => "color",
            Kind::Glow { .. } => "glow",
            Kind::Material { .. } => "material",
            Kind::OrbitTrap { .. } => "orbit_trap",
        }
    }

    /// The node's children, mutably, in order (`a` before `b`).
    pub(crate) fn children_mut(&mut self) -> Vec<&mut C> {
        match self {
            Kind::Translate { child, .. }
            | Kind::Rotate { child, .. }
            | Kind::Scale { child, .. }
            | Kind::Mirror { child, .. }
            | Kind::Round { child, .. }
            | Kind::Onion { child, .. }
            | Kind::Elongate { child, .. }
            | Kind::Repeat { child, .. }
            | Kind::RepeatLimited { child, .. }
            | Kind::Twist { child, .. }
            | Kind::Bend { child, .. }
            | Kind::Color { child, .. }
            | Kind::Glow { child, .. }
            | Kind::Material { child, .. }
            | Kind::OrbitTrap { child, .. } => vec![child],
            Kind::Csg { a, b, .. } => vec![a, b],
            _ => vec![],
        }
    }

    /// The node's children, in order (`a` before `b`).
    #[must_use]
    pub fn children(&self) -> Vec<&C> {
        match self {
            Kind::Sphere { .. }
            | Kind::Cuboid { .. }
            | Kind::RoundBox { .. }
            | Kind::Torus { .. }
            | Kind::Cylinder { .. }
            | Kind::Capsule { .. }
            | Kind::Plane { .. }
            | Kind::Octahedron { .. }
            | Kind::OctahedronBound { .. }
            | Kind::CappedCone { .. }
            | Kind::HexPrism { .. }
            | Kind::RoundCone { .. }
            | Kind::Link { .. }
            | Kind::CutSphere { .. }
            | Kind::SolidAngle { .. }
            | Kind::CappedTorus { .. }
            | Kind::Triangle { .. }
            | Kind::Quad { .. }
            | Kind::Pyramid { .. }
            | Kind::Rhombus { .. }
            | Kind::TriPrism { .. }
            | Kind::RoundedCylinder { .. }
            | Kind::Cone { .. }
            | Kind::InfiniteCylinder { .. }
            | Kind::InfiniteCone { .. }
            | Kind::CutHollowSphere { .. }
            | Kind::DeathStar { .. }
            | Kind::BoxFrame { .. }
            | Kind::CylinderBetween { .. }
            | Kind::ConeBetween { .. }
            | Kind::RoundConeBetween { .. }
            | Kind::Extrude { .. }
            | Kind::Revolve { .. }
            | Kind::Ellipsoid { .. }
            | Kind::Mandelbulb(_)
            | Kind::Menger(_)
            | Kind::Julia(_)
            | Kind::Sierpinski(_)
            | Kind::Mandelbox(_)
            | Kind::PseudoKleinian(_)
            | Kind::Kifs(_)
            | Kind::Hybrid(_)
            | Kind::Custom { .. } => vec![],
            Kind::Translate { child, .. }
            | Kind::Rotate { child, .. }
            | Kind::Scale { child, .. }
            | Kind::Mirror { child, .. }
            | Kind::Round { child, .. }
            | Kind::Onion { child, .. }
            | Kind::Elongate { child, .. }
            | Kind::Repeat { child, .. }
            | Kind::RepeatLimited { child, .. }
            | Kind::Twist { child, .. }
            | Kind::Bend { child, .. }
            | Kind::Color { child, .. }
            | Kind::Glow { child, .. }
            | Kind::Material { child, .. }
            | Kind::OrbitTrap { child, .. } => vec![child],
            Kind::Csg { a, b, .. } => vec![a, b],
        }
    }

    /// Whether this is one of the fractals.
    #[must_use]
    pub fn is_fractal(&self) -> bool {
        matches!(
            self,
            Kind::Mandelbulb(_)
                | Kind::Menger(_)
                | Kind::Julia(_)
                | Kind::Sierpinski(_)
                | Kind::Mandelbox(_)
                | Kind::PseudoKleinian(_)
                | Kind::Kifs(_)
                | Kind::Hybrid(_)
        )
    }

    /// The node's iteration count, for the fractals.
    #[must_use]
    pub fn iterations(&self) -> Option<u32> {
        match self {
            Kind::Mandelbulb(m) => Some(m.iterations),
            Kind::Menger(m) => Some(m.iterations),
            Kind::Julia(j) => Some(j.iterations),
            Kind::Sierpinski(s) => Some(s.iterations),
            Kind::Mandelbox(b) => Some(b.iterations),
            Kind::PseudoKleinian(k) => Some(k.iterations),
            Kind::Kifs(k) => Some(k.iterations),
            Kind::Hybrid(h) => Some(h.iterations),
            _ => None,
        }
    }

    /// The allowed iteration range, for the fractals.
    #[must_use]
    pub fn iteration_range(&self) -> Option<(u32, u32)> {
        match self {
            Kind::Mandelbulb(_) | Kind::Julia(_) | Kind::Mandelbox(_) => {
                Some((1, MAX_ESCAPE_ITERATIONS))
            }
            Kind::Menger(_) | Kind::Sierpinski(_) | Kind::Kifs(_) => Some((0, MAX_FOLD_ITERATIONS)),
            Kind::Hybrid(_) | Kind::PseudoKleinian(_) => Some((0, MAX_ESCAPE_ITERATIONS)),
            _ => None,
        }
    }

    /// Rebuilds the node with every scalar, vector and child converted by
    /// `m`, which sees each parameter's name and rule. This match is the one
    /// place that lists which parameters each node has.
    pub(crate) fn try_map<M>(&self, m: &mut M) -> Result<Mapped<S, V, C, M>, M::E>
    where
        M: Mapper<S, V, C>,
    {
        use Rule::{Angle, Direction, Finite, Magnitude, NonNegative, Positive, Range};
        Ok(match self {
            Kind::Sphere { radius } => Kind::Sphere {
                radius: m.scalar(radius, spec("radius", NonNegative))?,
            },
            Kind::Cuboid { half_extents } => Kind::Cuboid {
                half_extents: m.vector(half_extents, spec("half_extents", NonNegative))?,
            },
            Kind::RoundBox {
                half_extents,
                radius,
            } => Kind::RoundBox {
                half_extents: m.vector(half_extents, spec("half_extents", NonNegative))?,
                radius: m.scalar(radius, spec("radius", NonNegative))?,
            },
            Kind::Torus {
                major_radius,
                minor_radius,
            } => Kind::Torus {
                major_radius: m.scalar(major_radius, spec("major_radius", NonNegative))?,
                minor_radius: m.scalar(minor_radius, spec("minor_radius", NonNegative))?,
            },
            Kind::Cylinder {
                radius,
                half_height,
            } => Kind::Cylinder {
                radius: m.scalar(radius, spec("radius", NonNegative))?,
                half_height: m.scalar(half_height, spec("half_height", NonNegative))?,
            },
            Kind::Capsule { a, b, radius } => Kind::Capsule {
                a: m.vector(a, spec("a", Finite))?,
                b: m.vector(b, spec("b", Finite))?,
                radius: m.scalar(radius, spec("radius", NonNegative))?,
            },
            Kind::Plane { normal, offset } => Kind::Plane {
                normal: m.vector(normal, spec("normal", Direction))?,
                offset: m.scalar(offset, spec("offset", Finite))?,
            },
            Kind::Octahedron { size } => Kind::Octahedron {
                size: m.scalar(size, spec("size", NonNegative))?,
            },
            Kind::OctahedronBound { size } => Kind::OctahedronBound {
                size: m.scalar(size, spec("size", NonNegative))?,
            },
            Kind::CappedCone {
                half_height,
                bottom_radius,
                top_radius,
            } => Kind::CappedCone {
                half_height: m.scalar(half_height, spec("half_height", NonNegative))?,
                bottom_radius: m.scalar(bottom_radius, spec("bottom_radius", NonNegative))?,
                top_radius: m.scalar(top_radius, spec("top_radius", NonNegative))?,
            },
            Kind::HexPrism {
                radius,
                half_height,
            } => Kind::HexPrism {
                radius: m.scalar(radius, spec("radius", NonNegative))?,
                half_height: m.scalar(half_height, spec("half_height", NonNegative))?,
            },
            Kind::RoundCone {
                half_height,
                bottom_radius,
                top_radius,
            } => Kind::RoundCone {
                half_height: m.scalar(half_height, spec("half_height", NonNegative))?,
                bottom_radius: m.scalar(bottom_radius, spec("bottom_radius", NonNegative))?,
                top_radius: m.scalar(top_radius, spec("top_radius", NonNegative))?,
            },
            Kind::Link {
                half_length,
                major_radius,
                minor_radius,
            } => Kind::Link {
                half_length: m.scalar(half_length, spec("half_length", NonNegative))?,
                major_radius: m.scalar(major_radius, spec("major_radius", NonNegative))?,
                minor_radius: m.scalar(minor_radius, spec("minor_radius", NonNegative))?,
            },
            Kind::CutSphere { radius, height } => Kind::CutSphere {
                radius: m.scalar(radius, spec("radius", NonNegative))?,
                height: m.scalar(height, spec("height", Finite))?,
            },
            Kind::SolidAngle { angle, radius } => Kind::SolidAngle {
                angle: m.scalar(angle, spec("angle", Range(0.0, MAX_SOLID_ANGLE)))?,
                radius: m.scalar(radius, spec("radius", NonNegative))?,
            },
            Kind::CappedTorus {
                angle,
                major_radius,
                minor_radius,
            } => Kind::CappedTorus {
                angle: m.scalar(angle, spec("angle", Range(0.0, std::f64::consts::PI)))?,
                major_radius: m.scalar(major_radius, spec("major_radius", NonNegative))?,
                minor_radius: m.scalar(minor_radius, spec("minor_radius", NonNegative))?,
            },
            Kind::Triangle { a, b, c, thickness } => Kind::Triangle {
                a: m.vector(a, spec("a", Finite))?,
                b: m.vector(b, spec("b", Finite))?,
                c: m.vector(c, spec("c", Finite))?,
                thickness: m.scalar(thickness, spec("thickness", Positive))?,
            },
            Kind::Quad {
                a,
                b,
                c,
                d,
                thickness,
            } => Kind::Quad {
                a: m.vector(a, spec("a", Finite))?,
                b: m.vector(b, spec("b", Finite))?,
                c: m.vector(c, spec("c", Finite))?,
                d: m.vector(d, spec("d", Finite))?,
                thickness: m.scalar(thickness, spec("thickness", Positive))?,
            },
            Kind::Pyramid { half_base, height } => Kind::Pyramid {
                half_base: m.scalar(half_base, spec("half_base", Positive))?,
                height: m.scalar(height, spec("height", NonNegative))?,
            },
            Kind::Rhombus {
                half_x,
                half_z,
                half_height,
                radius,
            } => Kind::Rhombus {
                half_x: m.scalar(half_x, spec("half_x", NonNegative))?,
                half_z: m.scalar(half_z, spec("half_z", NonNegative))?,
                half_height: m.scalar(half_height, spec("half_height", NonNegative))?,
                radius: m.scalar(radius, spec("radius", NonNegative))?,
            },
            Kind::TriPrism {
                radius,
                half_height,
            } => Kind::TriPrism {
                radius: m.scalar(radius, spec("radius", NonNegative))?,
                half_height: m.scalar(half_height, spec("half_height", NonNegative))?,
            },
            Kind::RoundedCylinder {
                radius,
                half_height,
                rounding,
            } => Kind::RoundedCylinder {
                radius: m.scalar(radius, spec("radius", NonNegative))?,
                half_height: m.scalar(half_height, spec("half_height", NonNegative))?,
                rounding: m.scalar(rounding, spec("rounding", NonNegative))?,
            },
            Kind::Cone { radius, height } => Kind::Cone {
                radius: m.scalar(radius, spec("radius", NonNegative))?,
                height: m.scalar(height, spec("height", NonNegative))?,
            },
            Kind::InfiniteCylinder { radius } => Kind::InfiniteCylinder {
                radius: m.scalar(radius, spec("radius", NonNegative))?,
            },
            Kind::InfiniteCone { angle } => Kind::InfiniteCone {
                angle: m.scalar(angle, spec("angle", Range(0.0, FRAC_PI_2)))?,
            },
            Kind::CutHollowSphere {
                radius,
                height,
                thickness,
            } => Kind::CutHollowSphere {
                radius: m.scalar(radius, spec("radius", NonNegative))?,
                height: m.scalar(height, spec("height", Finite))?,
                thickness: m.scalar(thickness, spec("thickness", NonNegative))?,
            },
            Kind::DeathStar {
                radius,
                carve_radius,
                carve_distance,
            } => Kind::DeathStar {
                radius: m.scalar(radius, spec("radius", NonNegative))?,
                carve_radius: m.scalar(carve_radius, spec("carve_radius", NonNegative))?,
                carve_distance: m.scalar(carve_distance, spec("carve_distance", Positive))?,
            },
            Kind::BoxFrame {
                half_extents,
                thickness,
            } => Kind::BoxFrame {
                half_extents: m.vector(half_extents, spec("half_extents", NonNegative))?,
                thickness: m.scalar(thickness, spec("thickness", NonNegative))?,
            },
            Kind::CylinderBetween { a, b, radius } => Kind::CylinderBetween {
                a: m.vector(a, spec("a", Finite))?,
                b: m.vector(b, spec("b", Finite))?,
                radius: m.scalar(radius, spec("radius", NonNegative))?,
            },
            Kind::ConeBetween {
                a,
                b,
                radius_a,
                radius_b,
            } => Kind::ConeBetween {
                a: m.vector(a, spec("a", Finite))?,
                b: m.vector(b, spec("b", Finite))?,
                radius_a: m.scalar(radius_a, spec("radius_a", NonNegative))?,
                radius_b: m.scalar(radius_b, spec("radius_b", NonNegative))?,
            },
            Kind::RoundConeBetween {
                a,
                b,
                radius_a,
                radius_b,
            } => Kind::RoundConeBetween {
                a: m.vector(a, spec("a", Finite))?,
                b: m.vector(b, spec("b", Finite))?,
                radius_a: m.scalar(radius_a, spec("radius_a", NonNegative))?,
                radius_b: m.scalar(radius_b, spec("radius_b", NonNegative))?,
            },
            Kind::Extrude {
                profile,
                half_height,
            } => Kind::Extrude {
                profile: profile.try_map(&mut |s, spec| m.scalar(s, spec))?,
                half_height: m.scalar(half_height, spec("half_height", NonNegative))?,
            },
            Kind::Revolve { profile, offset } => Kind::Revolve {
                profile: profile.try_map(&mut |s, spec| m.scalar(s, spec))?,
                offset: m.scalar(offset, spec("offset", Finite))?,
            },
            Kind::Ellipsoid { radii } => Kind::Ellipsoid {
                radii: m.vector(radii, spec("radii", Positive))?,
            },
            Kind::Mandelbulb(f) => Kind::Mandelbulb(Mandelbulb {
                power: m.scalar(&f.power, spec("power", Range(2.0, 64.0)))?,
                iterations: f.iterations,
                bailout: m.scalar(&f.bailout, spec("bailout", Range(1.0, 1e6)))?,
            }),
            Kind::Menger(f) => Kind::Menger(Menger {
                iterations: f.iterations,
                scale: m.scalar(&f.scale, spec("scale", Range(2.0, 4.0)))?,
            }),
            Kind::Julia(f) => Kind::Julia(QuaternionJulia {
                c: [
                    m.scalar(&f.c[0], spec("c.x", Range(-4.0, 4.0)))?,
                    m.scalar(&f.c[1], spec("c.y", Range(-4.0, 4.0)))?,
                    m.scalar(&f.c[2], spec("c.z", Range(-4.0, 4.0)))?,
                    m.scalar(&f.c[3], spec("c.w", Range(-4.0, 4.0)))?,
                ],
                iterations: f.iterations,
                bailout: m.scalar(&f.bailout, spec("bailout", Range(1.0, 1e6)))?,
                slice_w: m.scalar(&f.slice_w, spec("slice_w", Finite))?,
            }),
            Kind::Sierpinski(f) => Kind::Sierpinski(Sierpinski {
                iterations: f.iterations,
                scale: m.scalar(&f.scale, spec("scale", Range(1.5, 4.0)))?,
            }),
            Kind::Mandelbox(f) => Kind::Mandelbox(Mandelbox {
                scale: m.scalar(&f.scale, spec("scale", Magnitude(1.1, 4.0)))?,
                min_radius: m.scalar(&f.min_radius, spec("min_radius", Positive))?,
                fixed_radius: m.scalar(&f.fixed_radius, spec("fixed_radius", Positive))?,
                fold_limit: m.scalar(&f.fold_limit, spec("fold_limit", Positive))?,
                iterations: f.iterations,
                julia: match &f.julia {
                    Some([x, y, z]) => Some([
                        m.scalar(x, spec("julia.x", Finite))?,
                        m.scalar(y, spec("julia.y", Finite))?,
                        m.scalar(z, spec("julia.z", Finite))?,
                    ]),
                    None => None,
                },
            }),
            Kind::PseudoKleinian(f) => {
                let three = |m: &mut M, v: &[S; 3], name: &str, rule| -> Result<[_; 3], M::E> {
                    Ok([
                        m.scalar(&v[0], spec(&format!("{name}.x"), rule))?,
                        m.scalar(&v[1], spec(&format!("{name}.y"), rule))?,
                        m.scalar(&v[2], spec(&format!("{name}.z"), rule))?,
                    ])
                };
                Kind::PseudoKleinian(PseudoKleinian {
                    fold_size: three(m, &f.fold_size, "fold_size", Positive)?,
                    inversion: m.scalar(&f.inversion, spec("inversion", Range(0.05, 4.0)))?,
                    offset: three(m, &f.offset, "offset", Finite)?,
                    thickness: m.scalar(&f.thickness, spec("thickness", Range(1e-4, 2.0)))?,
                    iterations: f.iterations,
                })
            }
            Kind::Kifs(f) => {
                let scale = m.scalar(&f.scale, spec("scale", Range(1.1, 4.0)))?;
                let mut three = |v: &[S; 3], names: [&str; 3], rule: Rule| {
                    let [x, y, z] = v;
                    Ok([
                        m.scalar(x, spec(names[0], rule))?,
                        m.scalar(y, spec(names[1], rule))?,
                        m.scalar(z, spec(names[2], rule))?,
                    ])
                };
                let before = ["rotate_before.x", "rotate_before.y", "rotate_before.z"];
                let after = ["rotate_after.x", "rotate_after.y", "rotate_after.z"];
                Kind::Kifs(Kifs {
                    fold: f.fold,
                    scale,
                    offset: three(&f.offset, ["offset.x", "offset.y", "offset.z"], Finite)?,
                    rotate_before: match &f.rotate_before {
                        Some(a) => Some(three(a, before, Angle)?),
                        None => None,
                    },
                    rotate_after: match &f.rotate_after {
                        Some(a) => Some(three(a, after, Angle)?),
                        None => None,
                    },
                    iterations: f.iterations,
                })
            }
            Kind::Hybrid(h) => Kind::Hybrid(h.try_map(&mut |s, spec| m.scalar(s, spec))?),
            Kind::Translate { offset, child } => Kind::Translate {
                offset: m.vector(offset, spec("offset", Finite))?,
                child: m.child(child)?,
            },
            Kind::Rotate { axis, angle, child } => Kind::Rotate {
                axis: *axis,
                angle: m.scalar(angle, spec("angle", Angle))?,
                child: m.child(child)?,
            },
            Kind::Scale { factor, child } => Kind::Scale {
                factor: m.scalar(factor, spec("factor", Positive))?,
                child: m.child(child)?,
            },
            Kind::Mirror { axis, child } => Kind::Mirror {
                axis: *axis,
                child: m.child(child)?,
            },
            Kind::Round { radius, child } => Kind::Round {
                radius: m.scalar(radius, spec("radius", NonNegative))?,
                child: m.child(child)?,
            },
            Kind::Onion { thickness, child } => Kind::Onion {
                thickness: m.scalar(thickness, spec("thickness", NonNegative))?,
                child: m.child(child)?,
            },
            Kind::Elongate { extents, child } => Kind::Elongate {
                extents: m.vector(extents, spec("extents", NonNegative))?,
                child: m.child(child)?,
            },
            Kind::Repeat { period, child } => Kind::Repeat {
                period: m.vector(period, spec("period", NonNegative))?,
                child: m.child(child)?,
            },
            Kind::RepeatLimited {
                period,
                limit,
                child,
            } => Kind::RepeatLimited {
                period: m.vector(period, spec("period", NonNegative))?,
                limit: *limit,
                child: m.child(child)?,
            },
            Kind::Twist { rate, child } => Kind::Twist {
                rate: m.scalar(rate, spec("rate", WARP_RATE))?,
                child: m.child(child)?,
            },
            Kind::Bend { rate, child } => Kind::Bend {
                rate: m.scalar(rate, spec("rate", WARP_RATE))?,
                child: m.child(child)?,
            },
            Kind::Csg {
                op,
                smoothing,
                a,
                b,
            } => Kind::Csg {
                op: *op,
                smoothing: match smoothing {
                    Some(k) => Some(m.scalar(k, spec("k", NonNegative))?),
                    None => None,
                },
                a: m.child(a)?,
                b: m.child(b)?,
            },
            Kind::Custom { shape, args } => Kind::Custom {
                shape: shape.clone(),
                args: args
                    .iter()
                    .zip(shape.params())
                    .map(|(a, (name, rule))| m.scalar(a, spec(name, rule)))
                    .collect::<Result<_, _>>()?,
            },
            Kind::Color { color, child } => Kind::Color {
                color: m.vector(color, spec("color", NonNegative))?,
                child: m.child(child)?,
            },
            Kind::Glow {
                color,
                strength,
                child,
            } => Kind::Glow {
                color: m.vector(color, spec("color", NonNegative))?,
                strength: m.scalar(strength, spec("strength", NonNegative))?,
                child: m.child(child)?,
            },
            Kind::Material { material, child } => Kind::Material {
                material: material.try_map(|s, spec| m.scalar(s, spec))?,
                child: m.child(child)?,
            },
            Kind::OrbitTrap { coloring, child } => {
                // Both closures need the mapper: they take turns.
                let m = std::cell::RefCell::new(m);
                let coloring = coloring.try_map(
                    &mut |s, spec| m.borrow_mut().scalar(s, spec),
                    &mut |v, spec| m.borrow_mut().vector(v, spec),
                )?;
                Kind::OrbitTrap {
                    coloring,
                    child: m.into_inner().child(child)?,
                }
            }
        })
    }
}

/// The node kind of the user-facing scene tree.
pub type NodeKind = Kind<Param, Param3, Node>;

/// A node of a scene: a shape, a fractal, or an operation on other nodes.
///
/// Build nodes with the free functions ([`sphere`](super::sphere),
/// [`mandelbulb`](super::mandelbulb), ...) and combine them with the methods
/// of [`Node`]. A `Node` is a plain value: clone it (cheaply:
/// subtrees are shared), compare it, keep it in a `Vec`. Nothing about a
/// node recurses on its depth: dropping, comparing, printing and compiling
/// a chain of a million nodes needs no deeper stack than one node.
#[derive(Clone)]
pub struct Node(Arc<NodeKind>);

impl Node {
    /// The node's kind and parameters.
    #[must_use]
    pub fn kind(&self) -> &NodeKind {
        &self.0
    }

    /// The number of nodes in the tree below and including this one, and
    /// its depth (1 for a leaf), counted without recursion.
    #[must_use]
    pub fn size_and_depth(&self) -> (usize, usize) {
        let (mut size, mut depth) = (0, 0);
        let mut stack = vec![(self, 1)];
        while let Some((node, level)) = stack.pop() {
            size += 1;
            depth = depth.max(level);
            stack.extend(node.kind().children().into_iter().map(|c| (c, level + 1)));
        }
        (size, depth)
    }

    /// A shared leaf that stands in for the children a dropped node gives
    /// up (see `Drop`).
    fn placeholder() -> Node {
        static PLACEHOLDER: OnceLock<Node> = OnceLock::new();
        PLACEHOLDER
            .get_or_init(|| {
                Node(Arc::new(Kind::Sphere {
                    radius: Param::Value(0.0),
                }))
            })
            .clone()
    }
}

impl From<NodeKind> for Node {
    fn from(kind: NodeKind) -> Self {
        Node(Arc::new(kind))
    }
}

impl Drop for Node {
    /// Drops the tree without recursion: a node this handle owns alone
    /// gives its children to a work list before it goes (replacing them with
    /// a shared placeholder), so each drop frees one node.
    fn drop(&mut self) {
        let Some(kind) = Arc::get_mut(&mut self.0) else {
            return;
        };
        let mut orphans: Vec<Node> = Vec::new();
        for child in kind.children_mut() {
            orphans.push(std::mem::replace(child, Node::placeholder()));
        }
        while let Some(mut node) = orphans.pop() {
            if let Some(kind) = Arc::get_mut(&mut node.0) {
                for child in kind.children_mut() {
                    orphans.push(std::mem::replace(child, Node::placeholder()));
                }
            }
        }
    }
}

impl PartialEq for Node {
    /// Structural equality, compared without recursion (shared subtrees
    /// are equal at once).
    fn eq(&self, other: &Self) -> bool {
        let mut pairs = vec![(self, other)];
        while let Some((a, b)) = pairs.pop() {
            if Arc::ptr_eq(&a.0, &b.0) {
                continue;
            }
            if shallow(a.kind()) != shallow(b.kind()) {
                return false;
            }
            pairs.extend(a.kind().children().into_iter().zip(b.kind().children()));
        }
        true
    }
}

/// A node's own values with its children left out, for comparing one level.
fn shallow(kind: &NodeKind) -> Kind<Param, Param3, ()> {
    struct Values;
    impl Mapper<Param, Param3, Node> for Values {
        type S2 = Param;
        type V2 = Param3;
        type C2 = ();
        type E = std::convert::Infallible;
        fn scalar(&mut self, s: &Param, _: ParamSpec<'_>) -> Result<Param, Self::E> {
            Ok(s.clone())
        }
        fn vector(&mut self, v: &Param3, _: ParamSpec<'_>) -> Result<Param3, Self::E> {
            Ok(v.clone())
        }
        fn child(&mut self, _: &Node) -> Result<(), Self::E> {
            Ok(())
        }
    }
    let Ok(values) = kind.try_map(&mut Values);
    values
}

/// Trees deeper than this print as a summary.
const DEBUG_DEPTH: usize = 64;

impl fmt::Debug for Node {
    /// The node's kind, as `Kind`'s `Debug` prints it; a tree deeper than 64
    /// levels prints as a summary (its root kind, size and depth), so
    /// printing never recurses deeply.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (size, depth) = self.size_and_depth();
        if depth > DEBUG_DEPTH {
            return f
                .debug_struct("Node")
                .field("kind", &self.kind().name())
                .field("nodes", &size)
                .field("depth", &depth)
                .finish_non_exhaustive();
        }
        fmt::Debug::fmt(self.kind(), f)
    }
}
