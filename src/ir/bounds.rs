//! Bounding spheres of the nodes of a scene: what lets a union skip an
//! operand the point cannot be near, and a ray skip the space around the
//! scene.
//!
//! A node's [`Bound`] is a sphere and a slope with one guarantee: wherever
//! `slope · (|p − centre| − radius)` is positive, the node's distance
//! estimate at `p` is at least that much. For an exact distance (every
//! primitive but the plane) any sphere around the shape will do, slope 1;
//! for an estimate it is a property of the formula, proved for each in
//! [`Bound`]'s construction below. Because the bound never exceeds the
//! node's own estimate there, a union whose first operand is nearer than
//! the second's bound has the first operand's value exactly, and code
//! generation and the CPU reference skip the second. Pruning changes no
//! value, only the cost.
//!
//! Bounds are computed from baked values. A node whose extent depends on a
//! dynamic value it cannot bound over the value's whole range (a dynamic
//! translation, scale or rounding radius) has no bound, and neither does a
//! plane, an unlimited repetition or a custom shape with a distance
//! estimate (an inside shape is bounded by its stated bounds). A twist or
//! a bend is bounded where its child is (`warp_ball`).

use glam::DVec3;

use std::convert::Infallible;

use super::{Ir, IrNode, NodeId, Scalar, Vector, baked3};
use crate::math::{
    JULIA_FAR_FIELD, JULIA_FAR_FIELD_SLOPE, Limits, Num, V3, julia_radius, kifs_radius,
    mandelbox_extent, mandelbulb_radius, rotation_rows,
};
use crate::scene::{Axis, CsgOp, HybridOp, KifsFold, Kind, Mapper, ParamSpec, Profile};

/// A conservative bounding sphere of a node, in the coordinates the node
/// sees: wherever `slope · (|p − centre| − radius) > 0`, the node's
/// distance estimate at `p` is at least that value. Pruning reads it as
/// [`Bound::distance`], a little lower still.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Bound {
    /// The sphere's centre.
    pub centre: DVec3,
    /// The sphere's radius.
    pub radius: f64,
    /// How fast the estimate grows at least, away from the sphere, in
    /// `(0, 1]`: 1 for exact distances.
    pub slope: f64,
}

/// The bound reads `|p − centre|` shortened by this fraction, so that the
/// rounding of a kernel's precision (a few units in the last place of
/// `|p|`, where the node's own estimate computes the same length another
/// way, such as after a rotation) can never put the bound above an
/// estimate it equals in exact arithmetic (a sphere bounding itself).
pub const SHRINK: f64 = 1.0 - 1e-4;

/// `√3`: the circumradius of the unit cube and of the Sierpinski
/// tetrahedron's starting tetrahedron.
const SQRT_3: f64 = 1.732_050_807_568_877_2;

impl Bound {
    fn sphere(centre: DVec3, radius: f64) -> Self {
        Bound {
            centre,
            radius,
            slope: 1.0,
        }
    }

    fn with_slope(self, slope: f64) -> Self {
        Bound {
            slope: self.slope.min(slope),
            ..self
        }
    }

    /// The value the guarantee is about, as pruning computes it: `slope ·
    /// (SHRINK |p − centre| − radius)`, a little below `slope · (|p −
    /// centre| − radius)`.
    #[must_use]
    pub fn distance(&self, p: DVec3) -> f64 {
        self.slope * ((p - self.centre).length() * SHRINK - self.radius)
    }

    /// [`Bound::distance`] in any number type, as the CPU reference and
    /// the kernels compute it (a slope of 1 needs no product).
    pub(crate) fn distance_at<T: Num>(&self, p: V3<T>) -> T {
        let g = (p - constant(self.centre)).length() * T::of(SHRINK) - T::of(self.radius);
        if self.slope < 1.0 {
            T::of(self.slope) * g
        } else {
            g
        }
    }

    /// Whether code in a precision with `limits` can evaluate the bound
    /// (its centre and radius within the precision's magnitudes).
    #[must_use]
    pub fn fits(&self, limits: &Limits) -> bool {
        let ok = |v: f64| v.is_finite() && v.abs() <= limits.max;
        self.centre.to_array().into_iter().all(ok) && ok(self.radius) && self.slope > 0.0
    }

    /// The sphere grown by `by` along the distance estimate: a node whose
    /// estimate is its child's less `by` (rounding, a smooth blend).
    fn grow(self, by: f64) -> Self {
        Bound {
            radius: self.radius + by / self.slope,
            ..self
        }
    }

    /// The smallest sphere around both, with the smaller slope.
    pub(crate) fn around(self, other: Bound) -> Self {
        let (a, b) = if self.radius >= other.radius {
            (self, other)
        } else {
            (other, self)
        };
        let gap = (b.centre - a.centre).length();
        let slope = a.slope.min(b.slope);
        if gap + b.radius <= a.radius {
            return Bound { slope, ..a };
        }
        let radius = 0.5 * (gap + a.radius + b.radius);
        let centre = a.centre + (b.centre - a.centre) * ((radius - a.radius) / gap);
        Bound {
            centre,
            radius,
            slope,
        }
    }
}

impl Ir {
    /// Every node's bound, by [`NodeId::index`](super::NodeId::index):
    /// `None` where a node has none. Computed in one pass over the arena
    /// (children come before parents).
    #[must_use]
    pub fn bounds(&self) -> Vec<Option<Bound>> {
        let mut out: Vec<Option<Bound>> = Vec::with_capacity(self.nodes().len());
        for node in self.nodes() {
            let b = bound(node, &out);
            out.push(b);
        }
        out
    }

    /// Every node's bound at the dynamic parameters' `values` (by slot):
    /// [`Ir::bounds`] with each dynamic value read as if it were baked. It
    /// holds for those values only.
    pub(crate) fn bounds_at(&self, values: &[f64]) -> Vec<Option<Bound>> {
        let mut read = Baking(|slot: u32| values.get(slot as usize).copied());
        let mut out: Vec<Option<Bound>> = Vec::with_capacity(self.nodes().len());
        for node in self.nodes() {
            let Ok(baked) = node.try_map(&mut read);
            let b = bound(&baked, &out);
            out.push(b);
        }
        out
    }
}

/// Reads a node's dynamic values as baked ones: `Baking(f)` turns
/// `Dynamic(slot)` into `Baked(v)` where `f(slot)` is `Some(v)`.
pub(crate) struct Baking<F>(pub(crate) F);

impl<F: Fn(u32) -> Option<f64>> Baking<F> {
    fn read(&self, s: Scalar) -> Scalar {
        match s {
            Scalar::Dynamic(slot) => (self.0)(slot).map_or(s, Scalar::Baked),
            Scalar::Baked(_) => s,
        }
    }
}

impl<F: Fn(u32) -> Option<f64>> Mapper<Scalar, Vector, NodeId> for Baking<F> {
    type S2 = Scalar;
    type V2 = Vector;
    type C2 = NodeId;
    type E = Infallible;

    fn scalar(&mut self, s: &Scalar, _: ParamSpec<'_>) -> Result<Scalar, Infallible> {
        Ok(self.read(*s))
    }

    fn vector(&mut self, v: &Vector, _: ParamSpec<'_>) -> Result<Vector, Infallible> {
        Ok(v.map(|s| self.read(s)))
    }

    fn child(&mut self, c: &NodeId) -> Result<NodeId, Infallible> {
        Ok(*c)
    }
}

/// The bound of one node from its children's.
pub(crate) fn bound(node: &IrNode, done: &[Option<Bound>]) -> Option<Bound> {
    let of = |c: &NodeId| done[c.index()];
    let baked = Scalar::baked;
    let origin = DVec3::ZERO;
    Some(match node {
        Kind::Sphere { radius } => Bound::sphere(origin, baked(*radius)?),
        Kind::Cuboid { half_extents } => Bound::sphere(origin, baked3(*half_extents)?.length()),
        Kind::RoundBox { half_extents, .. } => {
            // The rounding lies inside the box.
            Bound::sphere(origin, baked3(*half_extents)?.length())
        }
        Kind::Torus {
            major_radius,
            minor_radius,
        } => Bound::sphere(origin, baked(*major_radius)? + baked(*minor_radius)?),
        Kind::Cylinder {
            radius,
            half_height,
        } => Bound::sphere(origin, baked(*radius)?.hypot(baked(*half_height)?)),
        Kind::Capsule { a, b, radius } => {
            let (a, b) = (baked3(*a)?, baked3(*b)?);
            let centre = 0.5 * (a + b);
            Bound::sphere(centre, 0.5 * (b - a).length() + baked(*radius)?)
        }
        Kind::Octahedron { size } => Bound::sphere(origin, baked(*size)?),
        // `|x| + |y| + |z| >= |p|`, so the bound is at least
        // `(|p| − size) / √3`.
        Kind::OctahedronBound { size } => {
            Bound::sphere(origin, baked(*size)?).with_slope(1.0 / 3f64.sqrt())
        }
        Kind::CappedCone {
            half_height,
            bottom_radius,
            top_radius,
        } => {
            let r = baked(*bottom_radius)?.max(baked(*top_radius)?);
            Bound::sphere(origin, r.hypot(baked(*half_height)?))
        }
        // The hexagon's corners are `2 / sqrt(3)` times its flat sides'
        // distance from the axis.
        Kind::HexPrism {
            radius,
            half_height,
        } => Bound::sphere(
            origin,
            (baked(*radius)? * 2.0 / 3f64.sqrt()).hypot(baked(*half_height)?),
        ),
        // The hull of two balls lies in the ball around the origin that
        // holds both.
        Kind::RoundCone {
            half_height,
            bottom_radius,
            top_radius,
        } => {
            let r = baked(*bottom_radius)?.max(baked(*top_radius)?);
            Bound::sphere(origin, baked(*half_height)? + r)
        }
        Kind::Link {
            half_length,
            major_radius,
            minor_radius,
        } => Bound::sphere(
            origin,
            baked(*half_length)? + baked(*major_radius)? + baked(*minor_radius)?,
        ),
        // Both lie in their ball.
        Kind::CutSphere { radius, .. } | Kind::SolidAngle { radius, .. } => {
            Bound::sphere(origin, baked(*radius)?)
        }
        // Within the tube's radius of a circle of the arc's.
        Kind::CappedTorus {
            major_radius,
            minor_radius,
            ..
        } => Bound::sphere(origin, baked(*major_radius)? + baked(*minor_radius)?),
        // Within the thickness of the ball about the corners' centroid
        // that holds them.
        Kind::Triangle { a, b, c, thickness } => {
            corners_ball(&[baked3(*a)?, baked3(*b)?, baked3(*c)?], baked(*thickness)?)
        }
        Kind::Quad {
            a,
            b,
            c,
            d,
            thickness,
        } => corners_ball(
            &[baked3(*a)?, baked3(*b)?, baked3(*c)?, baked3(*d)?],
            baked(*thickness)?,
        ),
        // The base's corners and the apex.
        Kind::Pyramid { half_base, height } => Bound::sphere(
            origin,
            (baked(*half_base)? * 2f64.sqrt()).max(baked(*height)?),
        ),
        Kind::Rhombus {
            half_x,
            half_z,
            half_height,
            radius,
        } => Bound::sphere(
            origin,
            (baked(*half_x)?.max(baked(*half_z)?) + baked(*radius)?).hypot(baked(*half_height)?),
        ),
        Kind::TriPrism {
            radius,
            half_height,
        } => Bound::sphere(origin, (2.0 * baked(*radius)?).hypot(baked(*half_height)?)),
        Kind::RoundedCylinder {
            radius,
            half_height,
            ..
        } => Bound::sphere(origin, baked(*radius)?.hypot(baked(*half_height)?)),
        // The base's rim and the apex lie in the ball about the axis's
        // middle.
        Kind::Cone { radius, height } => {
            let h = baked(*height)?;
            Bound::sphere(
                DVec3::new(0.0, -0.5 * h, 0.0),
                (0.5 * h).hypot(baked(*radius)?),
            )
        }
        Kind::CutHollowSphere {
            radius, thickness, ..
        } => Bound::sphere(origin, baked(*radius)? + baked(*thickness)?),
        Kind::DeathStar { radius, .. } => Bound::sphere(origin, baked(*radius)?),
        Kind::BoxFrame { half_extents, .. } => {
            Bound::sphere(origin, baked3(*half_extents)?.length())
        }
        // Each lies in the ball about the segment's midpoint that holds
        // its caps (the cylinder and the cone) or its balls.
        Kind::CylinderBetween { a, b, radius } => {
            let (a, b) = (baked3(*a)?, baked3(*b)?);
            Bound::sphere(0.5 * (a + b), (0.5 * a.distance(b)).hypot(baked(*radius)?))
        }
        Kind::ConeBetween {
            a,
            b,
            radius_a,
            radius_b,
        } => {
            let (a, b) = (baked3(*a)?, baked3(*b)?);
            let r = baked(*radius_a)?.max(baked(*radius_b)?);
            Bound::sphere(0.5 * (a + b), (0.5 * a.distance(b)).hypot(r))
        }
        Kind::RoundConeBetween {
            a,
            b,
            radius_a,
            radius_b,
        } => {
            let (a, b) = (baked3(*a)?, baked3(*b)?);
            let r = baked(*radius_a)?.max(baked(*radius_b)?);
            Bound::sphere(0.5 * (a + b), 0.5 * a.distance(b) + r)
        }
        // The profile lies in its disc; the extrusion's is the cylinder of
        // that disc, the revolution's a torus about the axis.
        Kind::Extrude {
            profile,
            half_height,
        } => Bound::sphere(
            origin,
            baked_profile(profile)?.extent().hypot(baked(*half_height)?),
        ),
        Kind::Revolve { profile, offset } => Bound::sphere(
            origin,
            baked(*offset)?.abs() + baked_profile(profile)?.extent(),
        ),
        // The estimate is `(k0 − 1) / |u / r|` with `k0 = |p / r|` and `u`
        // a unit vector, so it is at least `(k0 − 1) min(r)`, and
        // `k0 >= |p| / max(r)`: at least `min(r) / max(r) · (|p| − max(r))`,
        // inside too (there it is `(k0 − 1) min(r)`).
        Kind::Ellipsoid { radii } => {
            let r = baked3(*radii)?;
            Bound::sphere(origin, r.max_element()).with_slope(r.min_element() / r.max_element())
        }
        // `max(estimate, |p| − rho)` everywhere (see `cpu::sdf::mandelbulb`),
        // and `rho` falls with the power: 2 at the smallest power bounds
        // every dynamic one.
        Kind::Mandelbulb(f) => {
            let power = baked(f.power).unwrap_or(2.0);
            Bound::sphere(origin, mandelbulb_radius(power))
        }
        // Both are folds that keep `|z|` (absolute values, permutations,
        // reflections in planes through the origin) followed by
        // `z -> s z − v` with `|v| <= √3 (s − 1)`, so after n steps
        // `|z_n| / s^n >= |p| − √3 (1 − s^−n)`; the last box distance is at
        // least `|z_n| − √3`, and the tetrahedron's face-plane bound at
        // least `(|z_n| − √3) / 3`. Divided by `s^n`: `|p| − √3`, for every
        // scale (at least 1.5) and iteration count.
        Kind::Menger(_) => Bound::sphere(origin, SQRT_3),
        Kind::Sierpinski(_) => Bound::sphere(origin, SQRT_3).with_slope(1.0 / 3.0),
        // The estimate is at least the exact distance to the cube of the
        // set's extent, so at least `|p| − √3 half_side`.
        Kind::Mandelbox(f) => {
            let julia = match f.julia {
                Some(c) => {
                    let [x, y, z] = c.map(baked);
                    Some([x?, y?, z?])
                }
                None => None,
            };
            let (half_side, _) = mandelbox_extent(baked(f.scale)?, baked(f.fold_limit)?, julia);
            Bound::sphere(origin, half_side * SQRT_3)
        }
        // Each step keeps `|z| − R` at least `s` times larger, so the
        // estimate is at least `|p| − R`.
        Kind::Kifs(f) => {
            let [x, y, z] = f.offset.map(baked);
            Bound::sphere(
                origin,
                kifs_radius([x?, y?, z?], f.fold == KifsFold::Menger),
            )
        }
        // The set lies in the ball of the bailout, and the estimate is at
        // least the distance to it.
        Kind::Hybrid(h) => Bound::sphere(origin, baked(h.bailout)?),
        // Beyond `JULIA_FAR_FIELD · edge` the estimate is exactly
        // `JULIA_FAR_FIELD_SLOPE (|(p, w)| − edge)`; the bound is that
        // slope beyond that radius (the largest edge of any constant in
        // range when `c` or the bailout is dynamic).
        Kind::Julia(f) => {
            let edge = match (f.c.map(baked), baked(f.bailout)) {
                ([Some(x), Some(y), Some(z), Some(w)], Some(bailout)) => {
                    julia_radius([x, y, z, w]).min(bailout)
                }
                _ => julia_radius([8.0, 0.0, 0.0, 0.0]),
            };
            Bound::sphere(origin, JULIA_FAR_FIELD * edge).with_slope(JULIA_FAR_FIELD_SLOPE)
        }
        Kind::Translate { offset, child } => {
            let b = of(child)?;
            Bound {
                centre: b.centre + baked3(*offset)?,
                ..b
            }
        }
        Kind::Rotate { axis, angle, child } => {
            let b = of(child)?;
            match angle {
                // The child sees `R(−angle) p`: its centre is at
                // `R(angle) centre`.
                Scalar::Baked(a) => {
                    let rows = rotation_rows(*axis, *a).map(DVec3::from);
                    let c = b.centre;
                    Bound {
                        centre: DVec3::new(rows[0].dot(c), rows[1].dot(c), rows[2].dot(c)),
                        ..b
                    }
                }
                // Every angle: a sphere around the origin.
                Scalar::Dynamic(_) => Bound {
                    centre: origin,
                    radius: b.radius + b.centre.length(),
                    ..b
                },
            }
        }
        Kind::Scale { factor, child } => {
            let b = of(child)?;
            let f = baked(*factor)?;
            Bound {
                centre: b.centre * f,
                radius: b.radius * f,
                ..b
            }
        }
        // The child sees `p` with one coordinate made positive: a sphere
        // around the child's and its mirror image.
        Kind::Mirror { axis, child } => {
            let b = of(child)?;
            let i = axis.index();
            let mut centre = b.centre;
            centre[i] = 0.0;
            Bound {
                centre,
                radius: b.radius + b.centre[i].abs(),
                ..b
            }
        }
        // The child sees `p` moved by at most `|extents|`.
        Kind::Elongate { extents, child } => {
            let b = of(child)?;
            Bound {
                radius: b.radius + baked3(*extents)?.length(),
                ..b
            }
        }
        // Every cell within the limits: the child sees `p` moved by at most
        // `|period · limit|`.
        Kind::RepeatLimited {
            period,
            limit,
            child,
        } => {
            let b = of(child)?;
            let period = baked3(*period)?;
            let reach = (period * DVec3::new(limit[0].into(), limit[1].into(), limit[2].into()))
                .abs()
                .length();
            Bound {
                centre: origin,
                radius: b.radius + b.centre.length() + reach,
                ..b
            }
        }
        Kind::Round { radius, child } => of(child)?.grow(baked(*radius)?),
        // Where the bound is positive the child's estimate is above the
        // thickness, so its absolute value is itself.
        Kind::Onion { thickness, child } => of(child)?.grow(baked(*thickness)?),
        Kind::Color { child, .. }
        | Kind::Glow { child, .. }
        | Kind::Material { child, .. }
        | Kind::OrbitTrap { child, .. } => of(child)?,
        Kind::Csg {
            op,
            smoothing,
            a,
            b,
        } => {
            let k = match smoothing {
                None => 0.0,
                Some(k) => baked(*k)?,
            };
            match op {
                // The smooth minimum is at most `k / 4` below the minimum.
                CsgOp::Union => of(a)?.around(of(b)?).grow(0.25 * k),
                // Both are at least the first operand's estimate (the smooth
                // forms too: `−smooth_min(−a, b) >= −min(−a, b)`).
                CsgOp::Subtract => of(a)?,
                CsgOp::Intersect | CsgOp::Cut => match (of(a), of(b)) {
                    (Some(x), Some(y)) => {
                        if x.radius <= y.radius {
                            x
                        } else {
                            y
                        }
                    }
                    (x, y) => x.or(y)?,
                },
            }
        }
        // The estimate is at least the distance to this ball (see
        // `warp_ball`), so the bound holds with slope 1.
        Kind::Twist { child, .. } => warp_ball(Axis::Y, of(child)?),
        Kind::Bend { child, .. } => warp_ball(Axis::Z, of(child)?),
        // Unbounded.
        Kind::Plane { .. }
        | Kind::PseudoKleinian(_)
        | Kind::InfiniteCylinder { .. }
        | Kind::InfiniteCone { .. }
        | Kind::Repeat { .. } => {
            return None;
        }
        // An inside shape's value is `INSIDE_HUGE` outside its bounds; a
        // shape written once is at most 0 only in the box interval
        // arithmetic finds for its baked values.
        Kind::Custom { shape, args } => {
            if let Some(bounds) = shape.inside_bounds() {
                let (centre, radius) = bounds.ball();
                Bound::sphere(centre, radius)
            } else {
                let values: Vec<f64> = args.iter().map(|a| baked(*a)).collect::<Option<_>>()?;
                let [lo, hi] = shape.surface_box(&values)?;
                Bound::sphere(0.5 * (lo + hi), 0.5 * (hi - lo).length())
            }
        }
    })
}

/// The ball around a warped child whose own bound is `child`: a twist
/// turns each point about the y axis (a bend about the z axis) by an angle
/// that depends on the point, which keeps its distance from that `axis`
/// and its coordinate along it. The child's shape lies in its ball, so the
/// warped shape lies in the cylinder of the points whose distance from the
/// axis and coordinate along it the ball allows, and in the ball around
/// that cylinder, centred on the axis. Its distance never exceeds the
/// distance to the warped shape, so the warp's estimate is the larger of
/// its Lipschitz-scaled child estimate and this ball's distance
/// (`cpu::Evaluator` and code generation): far from the shape the estimate
/// no longer shrinks with the stretch of the warp there, and the bound
/// holds with slope 1.
pub(crate) fn warp_ball(axis: Axis, child: Bound) -> Bound {
    let i = axis.index();
    let mut centre = DVec3::ZERO;
    centre[i] = child.centre[i];
    let mut radial = child.centre;
    radial[i] = 0.0;
    Bound::sphere(centre, (radial.length() + child.radius).hypot(child.radius))
}

/// `v` as a vector of literals.
pub(crate) fn constant<T: Num>(v: DVec3) -> V3<T> {
    V3::from_array(v.to_array().map(T::of))
}

/// A tree of hard unions, flattened: its operands in the order pruning
/// evaluates them, and its union nodes (which name the partial results).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct UnionChain {
    /// The operands without a bound first (a plane's distance is a good
    /// threshold to test the others against, and it has no bound to test),
    /// then the bounded ones; each group in the tree's order, left to
    /// right.
    pub(crate) operands: Vec<NodeId>,
    /// The tree's union nodes, root first.
    pub(crate) unions: Vec<NodeId>,
}

/// The chain of the tree of hard unions rooted at `id`, if `id` is a hard
/// union. The minimum of the operands in any order is the tree's value
/// exactly (a hard minimum is associative and commutative); only the colour
/// on an exact tie between two operands, which goes to the later one, can
/// differ from the tree's.
pub(crate) fn union_chain(ir: &Ir, id: NodeId, bounds: &[Option<Bound>]) -> Option<UnionChain> {
    if !is_hard_union(ir.node(id)) {
        return None;
    }
    let (mut operands, mut unions) = (Vec::new(), Vec::new());
    let mut stack = vec![id];
    while let Some(at) = stack.pop() {
        match ir.node(at) {
            Kind::Csg { a, b, .. } if is_hard_union(ir.node(at)) => {
                unions.push(at);
                stack.push(*b);
                stack.push(*a);
            }
            _ => operands.push(at),
        }
    }
    let (unbounded, bounded): (Vec<NodeId>, Vec<NodeId>) = operands
        .into_iter()
        .partition(|o| bounds[o.index()].is_none());
    Some(UnionChain {
        operands: unbounded.into_iter().chain(bounded).collect(),
        unions,
    })
}

/// Whether `node` is a union without smoothing.
pub(crate) fn is_hard_union(node: &IrNode) -> bool {
    matches!(
        node,
        Kind::Csg {
            op: CsgOp::Union,
            smoothing: None,
            ..
        }
    )
}

/// The most spheres a [`Reach`] holds; a tree with more is bounded by its
/// own sphere.
const MAX_REACH_PARTS: usize = 8;

/// A lower bound of a node's estimate made of its union tree's parts:
/// wherever `min_i (g_i(p) − offset_i)` is positive, with `g_i` the
/// [`Bound::distance`] of part `i`, the node's estimate is at least that.
/// A hard union's estimate is the minimum of its operands', and a smooth
/// union's at most `k / 4` below it, so the parts of a union tree (through
/// colour nodes, which change no distance) are its operands' bounds, each
/// lowered by the smoothing radii above it. Tighter than the sphere around
/// them all: a point between two far-apart fractals is far from both.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Reach {
    pub(crate) parts: Vec<(Bound, f64)>,
}

impl Reach {
    /// The least of its parts' bound distances, each less its offset, at
    /// `p`: as the CPU reference and the kernels compute it.
    pub(crate) fn distance_at<T: Num>(&self, p: V3<T>) -> T {
        self.parts
            .iter()
            .map(|(bound, offset)| {
                let g = bound.distance_at(p);
                if *offset > 0.0 { g - T::of(*offset) } else { g }
            })
            .reduce(Num::min)
            .expect("a reach has parts")
    }
}

/// The reach of `id`, where it has a bound: at most [`MAX_REACH_PARTS`]
/// parts, found by walking down at most that many union nodes.
pub(crate) fn reach(ir: &Ir, id: NodeId, bounds: &[Option<Bound>]) -> Option<Reach> {
    let own = bounds[id.index()]?;
    let fallback = Reach {
        parts: vec![(own, 0.0)],
    };
    let mut parts = Vec::new();
    let mut stack = vec![(id, 0.0)];
    while let Some((at, offset)) = stack.pop() {
        let k = match ir.node(at) {
            Kind::Csg {
                op: CsgOp::Union,
                smoothing: None,
                ..
            } => Some(0.0),
            Kind::Csg {
                op: CsgOp::Union,
                smoothing: Some(k),
                ..
            } => k.baked().map(|k| 0.25 * k),
            _ => None,
        };
        match (ir.node(at), k) {
            (Kind::Csg { a, b, .. }, Some(k)) => {
                stack.push((*b, offset + k));
                stack.push((*a, offset + k));
            }
            (
                Kind::Color { child, .. }
                | Kind::Glow { child, .. }
                | Kind::Material { child, .. }
                | Kind::OrbitTrap { child, .. },
                _,
            ) => {
                stack.push((*child, offset));
            }
            _ => match bounds[at.index()] {
                Some(b) => parts.push((b, offset)),
                None => return Some(fallback),
            },
        }
        if parts.len() + stack.len() > MAX_REACH_PARTS {
            return Some(fallback);
        }
    }
    Some(Reach { parts })
}

/// A rough cost of evaluating each node's estimate (children come before
/// parents), to choose which operand of a smooth union is evaluated first:
/// the other is skipped where it cannot change the result, so the dearer
/// one goes second.
pub(crate) fn costs(ir: &Ir) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(ir.nodes().len());
    for node in ir.nodes() {
        let own = match node {
            Kind::Mandelbulb(f) => {
                let per = match f.power.baked() {
                    Some(p) if p.fract() == 0.0 => 8.0,
                    Some(_) => 20.0,
                    None => 30.0,
                };
                per * f64::from(f.iterations)
            }
            Kind::Julia(f) => 6.0 * f64::from(f.iterations),
            Kind::Menger(f) => 4.0 * f64::from(f.iterations),
            Kind::Sierpinski(f) => 3.0 * f64::from(f.iterations),
            Kind::Mandelbox(f) => 6.0 * f64::from(f.iterations),
            Kind::PseudoKleinian(f) => 5.0 * f64::from(f.iterations),
            Kind::Kifs(f) => {
                let fold = if f.fold == KifsFold::Icosahedral {
                    9.0
                } else {
                    3.0
                };
                let turns = [&f.rotate_before, &f.rotate_after];
                let turns = turns.iter().filter(|t| t.is_some()).count();
                #[allow(clippy::cast_precision_loss)]
                let per_step = fold + 2.0 * turns as f64;
                per_step * f64::from(f.iterations)
            }
            Kind::Hybrid(h) => {
                // A power's trigonometry or angle doubling against a fold's
                // few selects.
                let per_step: f64 = h
                    .unrolled()
                    .map(|(_, _, op)| match op {
                        HybridOp::Power { .. } => 20.0,
                        HybridOp::BulbSquare { .. } => 8.0,
                        HybridOp::QuaternionSquare => 4.0,
                        HybridOp::Fold(KifsFold::Icosahedral) => 9.0,
                        _ => 3.0,
                    })
                    .sum();
                per_step * f64::from(h.iterations)
            }
            Kind::Custom { .. } => 10.0,
            _ => 1.0,
        };
        let children: f64 = node.children().iter().map(|c| out[c.index()]).sum();
        out.push(own + children);
    }
    out
}

/// Whether the smooth union `id` evaluates its second operand first: where
/// only the second has a bound (the first is then the threshold, as in a
/// chain), or both have one and the first costs more. A smooth minimum is
/// symmetric, so the order changes no distance; only the colour of an exact
/// tie between the operands can go to the other one.
pub(crate) fn swaps(ir: &Ir, id: NodeId, bounds: &[Option<Bound>], costs: &[f64]) -> bool {
    let Kind::Csg {
        op: CsgOp::Union,
        smoothing: Some(_),
        a,
        b,
    } = ir.node(id)
    else {
        return false;
    };
    match (bounds[a.index()], bounds[b.index()]) {
        (Some(_), None) => true,
        (Some(_), Some(_)) => costs[a.index()] > costs[b.index()],
        _ => false,
    }
}

/// The profile's values, where all are baked.
fn baked_profile(profile: &Profile<Scalar>) -> Option<Profile<f64>> {
    profile.try_map(&mut |s, _| s.baked().ok_or(())).ok()
}

/// The ball about the corners' centroid that holds them, grown by `grow`.
fn corners_ball(corners: &[DVec3], grow: f64) -> Bound {
    #[allow(clippy::cast_precision_loss)]
    let centre = corners.iter().sum::<DVec3>() / corners.len() as f64;
    let radius = corners
        .iter()
        .map(|c| c.distance(centre))
        .fold(0.0, f64::max);
    Bound::sphere(centre, radius + grow)
}
