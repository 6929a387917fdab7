//! The CPU reference: evaluates a scene's distance, colour and normal, and
//! sphere-traces rays, in `f64` or `f32`.
//!
//! It runs the same formulas as the OpenCL kernels and is the oracle every
//! test compares against. It is written for clarity and exactness, not
//! speed.

mod hierarchy;
pub mod sdf;
pub mod shade;

use glam::DVec3;

use crate::math::{
    DEFAULT_COLOR, escape_radius, integer_power, mandelbulb_radius, normalize, rotation_rows,
};
use crate::math::{Real, V3, v3};
use hierarchy::{Hierarchy, Walk};
use sdf::Estimate;

use crate::error::Result;
use std::collections::HashMap;
use std::sync::OnceLock;

use crate::ir::{
    Bound, CompiledScene, Ir, IrNode, NodeId, ParamValues, Reach, Scalar, constant, costs,
    is_hard_union, reach, swaps, union_chain,
};
use crate::math::F32_LIMITS;
use crate::scene::{
    BRUTE_MAX_STEPS, CsgOp, DEFAULT_MATERIAL, INSIDE_HUGE, Kind, MATERIAL_LEN, Node, Palette,
};

/// What the scene is like at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Sample<T> {
    /// Signed distance (or a bound) to the nearest surface.
    pub distance: T,
    /// Linear RGB colour of the nearest surface.
    pub color: V3<T>,
    /// Orbit trap in `[0, 1]` that tints the colour (1 for non-fractal
    /// surfaces, and for fractals a palette paints).
    pub trap: T,
    /// Orbit trap in `[0, 1]` that the shading layers show: `trap`, or on
    /// a fractal a palette paints, the trap the palette reads.
    pub orbit: T,
    /// The nearest surface's material, in
    /// [`Material::values`](crate::scene::Material::values) order.
    pub material: [T; MATERIAL_LEN],
    /// The shape (a leaf of [`Ir`]: a primitive, a fractal, a custom or
    /// inside shape) the nearest surface belongs to: the nearer operand's
    /// across every boolean, smooth or not, and a cut's first.
    pub object: Option<NodeId>,
    /// The material node that sets the nearest surface's material (the
    /// outermost above it, which paints over any inside), `None` where
    /// the default material applies.
    pub material_node: Option<NodeId>,
}

/// Evaluates one scene's geometry on the CPU.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::cpu;
/// let eval = cpu::Evaluator::new(&sphere(1.0))?;
/// assert!((eval.distance(dvec3(3.0, 0.0, 0.0)) - 2.0).abs() < 1e-12);
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Evaluator {
    ir: Ir,
    values: ParamValues,
    /// Each node's bound ([`Ir::bounds`]), where the kernels' code can
    /// evaluate it.
    bounds: Vec<Option<Bound>>,
    /// The roots of trees of hard unions, with their operands in the order
    /// the kernels evaluate them (see `ir::union_chain`).
    chains: HashMap<usize, Vec<NodeId>>,
    /// The reach (`ir::reach`) of each operand that pruning tests, where it
    /// is more than the operand's own bound.
    reaches: HashMap<usize, Reach>,
    /// The smooth unions that evaluate their second operand first
    /// (`ir::swaps`).
    swapped: Vec<bool>,
    /// The chains of at least [`MIN_HIERARCHY`](crate::codegen::MIN_HIERARCHY)
    /// operands with bounds at the current values, by root: their bounded
    /// operands are found through a hierarchy of boxes (the kernels walk
    /// one over a group of alike operands, and loop over others). Built
    /// at the first evaluation after the values change.
    hierarchies: OnceLock<HashMap<usize, Hierarchy>>,
    prune: bool,
    /// Whether samples carry only the distance (as the kernels' `DE`):
    /// booleans then mix no colours or materials.
    distance_only: bool,
}

/// One step of [`Evaluator::eval`]: tasks wait on a stack, samples on
/// another.
enum Task<T> {
    /// Evaluate a node at the point it sees; push its sample.
    Visit(NodeId, V3<T>),
    /// Replace the child's sample with the node's.
    Finish(NodeId, V3<T>),
    /// With the first operand's sample on top, evaluate a boolean's second
    /// operand unless pruning skips it.
    Second(NodeId, V3<T>),
    /// Combine a boolean's two operands' samples.
    Join(NodeId),
    /// With a union tree's sample so far on top, evaluate its operand of
    /// this place unless pruning skips it.
    Chain(usize, usize, V3<T>),
    /// Combine a union tree's sample so far with its next operand's.
    Union,
    /// Go on walking a union tree's hierarchy.
    Walk(Box<Walk<T>>),
}

impl Evaluator {
    /// Validates and lowers `geometry`; dynamic parameters start at their
    /// defaults.
    ///
    /// # Errors
    /// Any validation error of the geometry.
    pub fn new(geometry: &Node) -> Result<Self> {
        Ok(Self::from_ir(Ir::lower(geometry)?))
    }

    /// An evaluator for a compiled scene's geometry (nothing is lowered
    /// again); dynamic parameters start at their defaults.
    #[must_use]
    pub fn from_compiled(scene: &CompiledScene) -> Self {
        Self::from_ir(scene.ir().clone())
    }

    /// An evaluator for an already lowered scene.
    #[must_use]
    pub fn from_ir(ir: Ir) -> Self {
        let values = ir.default_values();
        let bounds: Vec<Option<Bound>> = ir
            .bounds()
            .into_iter()
            .map(|b| b.filter(|b| b.fits(&F32_LIMITS)))
            .collect();
        // The roots of trees of hard unions: hard unions whose parent is
        // not one. Each node is in at most one tree, so this is linear.
        let chains = (0..ir.nodes().len())
            .map(NodeId::from_index)
            .filter(|&id| {
                is_hard_union(ir.node(id))
                    && ir
                        .parent(id)
                        .is_none_or(|parent| !is_hard_union(ir.node(parent)))
            })
            .filter_map(|id| Some((id.index(), union_chain(&ir, id, &bounds)?.operands)))
            .collect::<HashMap<_, _>>();
        let costs = costs(&ir);
        let swapped: Vec<bool> = (0..ir.nodes().len())
            .map(|i| swaps(&ir, NodeId::from_index(i), &bounds, &costs))
            .collect();
        // The operands pruning tests: every chain operand after the first,
        // and the second operand a union or subtraction evaluates.
        let mut tested: Vec<NodeId> = chains.values().flat_map(|o| o[1..].to_vec()).collect();
        for (i, node) in ir.nodes().iter().enumerate() {
            if let Kind::Csg { a, b, .. } = node {
                tested.push(if swapped[i] { *a } else { *b });
            }
        }
        let reaches = tested
            .into_iter()
            .filter_map(|o| {
                let r = reach(&ir, o, &bounds)?;
                (r.parts.len() > 1 || r.parts[0].1 != 0.0).then_some((o.index(), r))
            })
            .collect();
        Evaluator {
            ir,
            values,
            bounds,
            chains,
            reaches,
            swapped,
            hierarchies: OnceLock::new(),
            prune: true,
            distance_only: false,
        }
    }

    /// The hierarchies of the large union trees over their operands'
    /// bounds at the current values, built once after the values change.
    fn hierarchies(&self) -> &HashMap<usize, Hierarchy> {
        self.hierarchies.get_or_init(|| {
            let mut out = HashMap::new();
            if self
                .chains
                .values()
                .all(|o| o.len() < crate::ir::bvh::MIN_HIERARCHY)
            {
                return out;
            }
            let bounds: Vec<Option<Bound>> = self
                .ir
                .bounds_at(self.values.as_slice())
                .into_iter()
                .map(|b| b.filter(|b| b.fits(&F32_LIMITS)))
                .collect();
            for (&root, operands) in &self.chains {
                if let Some(h) = Hierarchy::build(operands, &bounds) {
                    out.insert(root, h);
                }
            }
            out
        })
    }

    /// The same evaluator with the dynamic parameters at `values`.
    #[cfg(feature = "opencl")]
    #[must_use]
    pub(crate) fn with_values(mut self, values: ParamValues) -> Self {
        self.values = values;
        self.hierarchies = OnceLock::new();
        self
    }

    /// The same evaluator giving samples that carry only the distance, as
    /// the kernels' `DE` computes it: booleans mix no colours or
    /// materials (what an operation count of the distance wants).
    #[cfg(feature = "opencl")]
    #[must_use]
    pub(crate) fn distances_only(mut self) -> Self {
        self.distance_only = true;
        self
    }

    /// A boolean of two samples: [`combine`], or with
    /// [`Evaluator::distances_only`] the distance and the nearer sample's
    /// other fields.
    fn join<T: Real>(&self, op: CsgOp, k: Option<T>, a: Sample<T>, b: Sample<T>) -> Sample<T> {
        if !self.distance_only {
            return combine(op, k, a, b);
        }
        let c = sdf::csg(op, a.distance, b.distance, k);
        let near = if op == CsgOp::Cut || c.first_nearer {
            a
        } else {
            b
        };
        Sample {
            distance: c.distance,
            ..near
        }
    }

    /// Turns the pruning of unions and subtractions off or on (it is on,
    /// as in the kernels). Pruning skips an operand whose bound is beyond
    /// the other operand's distance, and evaluates the dearer operand of a
    /// smooth union second, which changes no value: turning it off is how
    /// tests check that.
    #[must_use]
    pub fn with_pruning(mut self, on: bool) -> Self {
        self.prune = on;
        self
    }

    /// A twist's or bend's estimate is at least the distance to the ball
    /// around its warped child (its bound, `ir::warp_ball`), as the kernels
    /// compute it, wherever that bound exists.
    fn warp_floor<T: Real>(&self, id: usize, distance: &mut T, p: V3<T>) {
        if let Some(ball) = &self.bounds[id] {
            *distance = sdf::ball_floor(*distance, p, constant(ball.centre), T::of(ball.radius));
        }
    }

    /// Whether the second operand `b` of a union or subtraction (with
    /// smoothing `k`), seen at `p`, cannot change the result `a` gives: its
    /// bound is positive and beyond `a` (by `k`), so its estimate is too.
    /// The kernels take the same decision (`codegen`).
    fn skips<T: Real>(&self, op: CsgOp, k: T, a: T, b: NodeId, p: V3<T>) -> bool {
        let Some(bound) = self.bounds[b.index()].filter(|_| self.prune) else {
            return false;
        };
        let threshold = match op {
            CsgOp::Union => a + k,
            CsgOp::Subtract => -a + k,
            CsgOp::Intersect | CsgOp::Cut => return false,
        };
        let g = match self.reaches.get(&b.index()) {
            Some(reach) => reach.distance_at(p),
            None => bound.distance_at(p),
        };
        g > threshold && g > T::zero()
    }

    /// The lowered scene.
    #[must_use]
    pub fn ir(&self) -> &Ir {
        &self.ir
    }

    /// The current dynamic parameter values.
    #[must_use]
    pub fn values(&self) -> &ParamValues {
        &self.values
    }

    /// Sets a dynamic parameter.
    ///
    /// # Errors
    /// See [`ParamValues::set`].
    pub fn set_param(&mut self, name: &str, value: f64) -> Result<()> {
        self.values.set(name, value)?;
        self.hierarchies = OnceLock::new();
        Ok(())
    }

    /// Distance at `p` in `f64`.
    #[must_use]
    pub fn distance(&self, p: DVec3) -> f64 {
        self.sample::<f64>(p.into()).distance
    }

    /// Distance at `p` in `f32`, rounding parameters to `f32` as the F32
    /// kernels do.
    #[must_use]
    pub fn distance_f32(&self, p: glam::Vec3) -> f32 {
        self.sample::<f32>(p.into()).distance
    }

    /// Distance, colour and orbit trap at `p`.
    #[must_use]
    pub fn sample<T: Real>(&self, p: V3<T>) -> Sample<T> {
        self.eval(p)
    }

    /// The unit surface normal at `p` by central differences with step `h`.
    #[must_use]
    pub fn normal(&self, p: DVec3, h: f64) -> DVec3 {
        let d = |q: DVec3| self.distance(q);
        let g = DVec3::new(
            d(p + DVec3::X * h) - d(p - DVec3::X * h),
            d(p + DVec3::Y * h) - d(p - DVec3::Y * h),
            d(p + DVec3::Z * h) - d(p - DVec3::Z * h),
        );
        normalize(g).unwrap_or(DVec3::Y)
    }

    fn scalar<T: Real>(&self, s: Scalar) -> T {
        T::of(match s {
            Scalar::Baked(v) => v,
            Scalar::Dynamic(slot) => self.values.as_slice()[slot as usize],
        })
    }

    fn vector<T: Real>(&self, v: [Scalar; 3]) -> V3<T> {
        v3(self.scalar(v[0]), self.scalar(v[1]), self.scalar(v[2]))
    }

    fn leaf<T: Real>(distance: T) -> Sample<T> {
        Sample {
            distance,
            color: V3::splat(T::of(DEFAULT_COLOR[0])),
            trap: T::one(),
            orbit: T::one(),
            material: DEFAULT_MATERIAL.map(T::of),
            object: None,
            material_node: None,
        }
    }

    fn fractal<T: Real>(e: Estimate<T>) -> Sample<T> {
        Sample {
            trap: e.trap,
            orbit: e.trap,
            ..Self::leaf(e.distance)
        }
    }

    /// Evaluates the scene at `p` without recursion, whatever its depth:
    /// a stack of tasks visits each node the result needs, from the root
    /// down, and a stack of samples carries their results up. An operand
    /// that pruning skips is never visited, and a large union walks its
    /// hierarchy (`hierarchy`).
    fn eval<T: Real>(&self, p: V3<T>) -> Sample<T> {
        let mut tasks = vec![Task::Visit(self.ir.root(), p)];
        let mut out: Vec<Sample<T>> = Vec::new();
        while let Some(task) = tasks.pop() {
            match task {
                Task::Visit(id, p) => self.visit(id, p, &mut tasks, &mut out),
                Task::Finish(id, p) => {
                    let child = out.pop().expect("the child's sample");
                    let node = self.ir.node(id);
                    out.push(self.sample_at(id.index(), node, p, Some(child)));
                }
                Task::Second(id, p) => {
                    let Kind::Csg {
                        op,
                        smoothing,
                        a,
                        b,
                        ..
                    } = self.ir.node(id)
                    else {
                        unreachable!("only booleans have a second operand")
                    };
                    let second = if self.prune && self.swapped[id.index()] {
                        a
                    } else {
                        b
                    };
                    let k = smoothing.map_or_else(T::zero, |k| self.scalar(k));
                    let first = out.last().expect("the first operand's sample");
                    if !self.skips(*op, k, first.distance, *second, p) {
                        tasks.push(Task::Join(id));
                        tasks.push(Task::Visit(*second, p));
                    }
                }
                Task::Join(id) => {
                    let Kind::Csg { op, smoothing, .. } = self.ir.node(id) else {
                        unreachable!("only booleans join two operands")
                    };
                    let second = out.pop().expect("the second operand's sample");
                    let first = out.pop().expect("the first operand's sample");
                    let k = smoothing.map(|k| self.scalar(k));
                    out.push(self.join(*op, k, first, second));
                }
                Task::Chain(root, next, p) => {
                    let operands = &self.chains[&root];
                    let Some(&o) = operands.get(next) else {
                        continue;
                    };
                    tasks.push(Task::Chain(root, next + 1, p));
                    let acc = out.last().expect("the first operand's sample");
                    if !self.skips(CsgOp::Union, T::zero(), acc.distance, o, p) {
                        tasks.push(Task::Union);
                        tasks.push(Task::Visit(o, p));
                    }
                }
                Task::Union => {
                    let b = out.pop().expect("the operand's sample");
                    let a = out.pop().expect("the union's sample so far");
                    out.push(self.join(CsgOp::Union, None, a, b));
                }
                Task::Walk(mut walk) => {
                    if walk.waits() {
                        let sample = out.pop().expect("the operand's sample");
                        walk.give(sample, |a, b| self.join(CsgOp::Union, None, a, b));
                    }
                    match walk.next(&self.hierarchies()[&walk.root]) {
                        Some(o) => {
                            let p = walk.p;
                            tasks.push(Task::Walk(walk));
                            tasks.push(Task::Visit(o, p));
                        }
                        None => out.push(walk.result()),
                    }
                }
            }
        }
        out.pop().expect("the root's sample")
    }

    /// Starts the evaluation of node `id` at the point `p` it sees: a leaf
    /// at once, any other node after the children it needs.
    fn visit<T: Real>(
        &self,
        id: NodeId,
        p: V3<T>,
        tasks: &mut Vec<Task<T>>,
        out: &mut Vec<Sample<T>>,
    ) {
        let i = id.index();
        if self.prune && self.hierarchies().contains_key(&i) {
            tasks.push(Task::Walk(Box::new(Walk::new(i, p))));
            return;
        }
        if let Some(operands) = self.chains.get(&i) {
            tasks.push(Task::Chain(i, 1, p));
            tasks.push(Task::Visit(operands[0], p));
            return;
        }
        let node = self.ir.node(id);
        match node {
            Kind::Csg { a, b, .. } => {
                let first = if self.prune && self.swapped[i] { b } else { a };
                tasks.push(Task::Second(id, p));
                tasks.push(Task::Visit(*first, p));
            }
            // Its orbit trap evaluates the fractal.
            Kind::OrbitTrap { .. } => out.push(self.sample_at(i, node, p, None)),
            _ => match node.children().first() {
                Some(&&child) => {
                    tasks.push(Task::Finish(id, p));
                    tasks.push(Task::Visit(child, self.child_point(node, p)));
                }
                None => {
                    let mut sample = self.sample_at(i, node, p, None);
                    sample.object = Some(id);
                    out.push(sample);
                }
            },
        }
    }

    /// The point a node's children see, for the point `p` it sees.
    fn child_point<T: Real>(&self, node: &IrNode, p: V3<T>) -> V3<T> {
        let s = |x: Scalar| self.scalar::<T>(x);
        let v = |x: [Scalar; 3]| self.vector::<T>(x);
        match node {
            Kind::Translate { offset, .. } => sdf::translate(p, v(*offset)),
            Kind::Rotate { axis, angle, .. } => match angle {
                // A baked rotation is a constant matrix (no trigonometry per
                // evaluation); code generation emits the same rows.
                Scalar::Baked(a) => sdf::rotate_rows(p, rotation_rows(*axis, -a)),
                Scalar::Dynamic(_) => {
                    let k = V3::<f64>::from(*axis).cast::<T>();
                    sdf::rotate_axis(p, k, -s(*angle))
                }
            },
            Kind::Scale { factor, .. } => sdf::scale_point(p, s(*factor)),
            Kind::Mirror { axis, .. } => sdf::mirror(p, axis.index()),
            Kind::Elongate { extents, .. } => sdf::elongate(p, v(*extents)),
            Kind::Repeat { period, .. } => sdf::repeat(p, v(*period), None),
            Kind::RepeatLimited { period, limit, .. } => sdf::repeat(p, v(*period), Some(*limit)),
            Kind::Twist { rate, .. } => sdf::twist(p, s(*rate)),
            Kind::Bend { rate, .. } => sdf::bend(p, s(*rate)),
            _ => p,
        }
    }

    /// A node's sample at the point `p` it sees, from its only child's
    /// `sample` where it has one (booleans and unions of many are combined
    /// in [`Evaluator::eval`]).
    #[allow(clippy::too_many_lines)]
    fn sample_at<T: Real>(
        &self,
        id: usize,
        node: &IrNode,
        p: V3<T>,
        child: Option<Sample<T>>,
    ) -> Sample<T> {
        let s = |x: Scalar| self.scalar::<T>(x);
        let v = |x: [Scalar; 3]| self.vector::<T>(x);
        let of = |_: &NodeId| child.expect("a node with a child gets its sample");
        match node {
            Kind::Sphere { radius } => Self::leaf(sdf::sphere(p, s(*radius))),
            Kind::Cuboid { half_extents } => Self::leaf(sdf::cuboid(p, v(*half_extents))),
            Kind::RoundBox {
                half_extents,
                radius,
            } => Self::leaf(sdf::round_box(p, v(*half_extents), s(*radius))),
            Kind::Torus {
                major_radius,
                minor_radius,
            } => Self::leaf(sdf::torus(p, s(*major_radius), s(*minor_radius))),
            Kind::Cylinder {
                radius,
                half_height,
            } => Self::leaf(sdf::cylinder(p, s(*radius), s(*half_height))),
            Kind::Capsule { a, b, radius } => Self::leaf(sdf::capsule(p, v(*a), v(*b), s(*radius))),
            Kind::Plane { normal, offset } => Self::leaf(sdf::plane(p, v(*normal), s(*offset))),
            Kind::Octahedron { size } => Self::leaf(sdf::octahedron(p, s(*size))),
            Kind::OctahedronBound { size } => Self::leaf(sdf::octahedron_bound(p, s(*size))),
            Kind::CappedCone {
                half_height,
                bottom_radius,
                top_radius,
            } => Self::leaf(sdf::capped_cone(
                p,
                s(*half_height),
                s(*bottom_radius),
                s(*top_radius),
            )),
            Kind::HexPrism {
                radius,
                half_height,
            } => Self::leaf(sdf::hex_prism(p, s(*radius), s(*half_height))),
            Kind::RoundCone {
                half_height,
                bottom_radius,
                top_radius,
            } => Self::leaf(sdf::round_cone(
                p,
                s(*half_height),
                s(*bottom_radius),
                s(*top_radius),
            )),
            Kind::CutSphere { radius, height } => {
                Self::leaf(sdf::cut_sphere(p, s(*radius), s(*height)))
            }
            Kind::SolidAngle { angle, radius } => {
                Self::leaf(sdf::solid_angle(p, s(*angle), s(*radius)))
            }
            Kind::CappedTorus {
                angle,
                major_radius,
                minor_radius,
            } => Self::leaf(sdf::capped_torus(
                p,
                s(*angle),
                s(*major_radius),
                s(*minor_radius),
            )),
            Kind::Link {
                half_length,
                major_radius,
                minor_radius,
            } => Self::leaf(sdf::link(
                p,
                s(*half_length),
                s(*major_radius),
                s(*minor_radius),
            )),
            Kind::Triangle { a, b, c, thickness } => {
                Self::leaf(sdf::triangle(p, v(*a), v(*b), v(*c), s(*thickness)))
            }
            Kind::Quad {
                a,
                b,
                c,
                d,
                thickness,
            } => Self::leaf(sdf::quad(p, v(*a), v(*b), v(*c), v(*d), s(*thickness))),
            Kind::Pyramid { half_base, height } => {
                Self::leaf(sdf::pyramid(p, s(*half_base), s(*height)))
            }
            Kind::Rhombus {
                half_x,
                half_z,
                half_height,
                radius,
            } => Self::leaf(sdf::rhombus(
                p,
                s(*half_x),
                s(*half_z),
                s(*half_height),
                s(*radius),
            )),
            Kind::TriPrism {
                radius,
                half_height,
            } => Self::leaf(sdf::tri_prism(p, s(*radius), s(*half_height))),
            Kind::RoundedCylinder {
                radius,
                half_height,
                rounding,
            } => Self::leaf(sdf::rounded_cylinder(
                p,
                s(*radius),
                s(*half_height),
                s(*rounding),
            )),
            Kind::Cone { radius, height } => Self::leaf(sdf::cone(p, s(*radius), s(*height))),
            Kind::InfiniteCylinder { radius } => Self::leaf(sdf::infinite_cylinder(p, s(*radius))),
            Kind::InfiniteCone { angle } => Self::leaf(sdf::infinite_cone(p, s(*angle))),
            Kind::CutHollowSphere {
                radius,
                height,
                thickness,
            } => Self::leaf(sdf::cut_hollow_sphere(
                p,
                s(*radius),
                s(*height),
                s(*thickness),
            )),
            Kind::DeathStar {
                radius,
                carve_radius,
                carve_distance,
            } => Self::leaf(sdf::death_star(
                p,
                s(*radius),
                s(*carve_radius),
                s(*carve_distance),
            )),
            Kind::BoxFrame {
                half_extents,
                thickness,
            } => Self::leaf(sdf::box_frame(p, v(*half_extents), s(*thickness))),
            Kind::CylinderBetween { a, b, radius } => {
                Self::leaf(sdf::cylinder_between(p, v(*a), v(*b), s(*radius)))
            }
            Kind::ConeBetween {
                a,
                b,
                radius_a,
                radius_b,
            } => Self::leaf(sdf::cone_between(
                p,
                v(*a),
                v(*b),
                s(*radius_a),
                s(*radius_b),
            )),
            Kind::RoundConeBetween {
                a,
                b,
                radius_a,
                radius_b,
            } => Self::leaf(sdf::round_cone_between(
                p,
                v(*a),
                v(*b),
                s(*radius_a),
                s(*radius_b),
            )),
            Kind::Extrude {
                profile,
                half_height,
            } => Self::leaf(sdf::extrude(p, &profile.map(|x| s(*x)), s(*half_height))),
            Kind::Revolve { profile, offset } => {
                Self::leaf(sdf::revolve(p, &profile.map(|x| s(*x)), s(*offset)))
            }
            Kind::Ellipsoid { radii } => Self::leaf(sdf::ellipsoid(p, v(*radii))),
            Kind::Mandelbulb(_)
            | Kind::Menger(_)
            | Kind::Julia(_)
            | Kind::Sierpinski(_)
            | Kind::Kifs(_)
            | Kind::Hybrid(_)
            | Kind::Mandelbox(_)
            | Kind::PseudoKleinian(_) => Self::fractal(
                self.fractal_estimate(node, p, None)
                    .expect("a fractal has an estimate"),
            ),
            Kind::Translate { child, .. }
            | Kind::Rotate { child, .. }
            | Kind::Mirror { child, .. }
            | Kind::Elongate { child, .. }
            | Kind::Repeat { child, .. }
            | Kind::RepeatLimited { child, .. } => of(child),
            Kind::Scale { factor, child } => {
                let mut out = of(child);
                out.distance = sdf::scale_distance(out.distance, s(*factor));
                out
            }
            Kind::Round { radius, child } => {
                let mut out = of(child);
                out.distance = sdf::rounded(out.distance, s(*radius));
                out
            }
            Kind::Onion { thickness, child } => {
                let mut out = of(child);
                out.distance = sdf::onion(out.distance, s(*thickness));
                out
            }
            Kind::Twist { rate, child } => {
                let mut out = of(child);
                out.distance = sdf::twisted(out.distance, s(*rate), p);
                self.warp_floor(id, &mut out.distance, p);
                out
            }
            Kind::Bend { rate, child } => {
                let mut out = of(child);
                out.distance = sdf::bent(out.distance, s(*rate), p);
                self.warp_floor(id, &mut out.distance, p);
                out
            }
            Kind::Csg { .. } => unreachable!("booleans are combined as they are evaluated"),
            Kind::Custom { shape, args } => {
                let args: Vec<f64> = args.iter().map(|a| self.scalar::<f64>(*a)).collect();
                let q = p.cast::<f64>().into();
                Self::leaf(T::of(shape.distance(q, &args)))
            }
            Kind::Color { color, child } => Sample {
                color: v(*color),
                ..of(child)
            },
            Kind::Glow { child, .. } => of(child),
            Kind::Material { material, child } => Sample {
                material: material.values().map(|x| s(*x)),
                material_node: Some(NodeId::from_index(id)),
                ..of(child)
            },
            Kind::OrbitTrap { coloring, child } => {
                let shape = sdf::TrapShape::of(&coloring.trap, s);
                let e = self
                    .fractal_estimate(self.ir.node(*child), p, Some(&shape))
                    .expect("validation keeps orbit traps on fractals");
                let t = Palette::position(e.trap, s(coloring.near), s(coloring.far));
                Sample {
                    color: coloring.palette.at(t),
                    orbit: e.trap,
                    object: Some(*child),
                    ..Self::leaf(e.distance)
                }
            }
        }
    }

    /// A fractal's estimate at `p`, its trap the orbit's smallest distance
    /// to `trap` where one is given; `None` for other nodes.
    fn fractal_estimate<T: Real>(
        &self,
        node: &IrNode,
        p: V3<T>,
        trap: Option<&sdf::TrapShape<T>>,
    ) -> Option<Estimate<T>> {
        let s = |x: Scalar| self.scalar::<T>(x);
        let v = |x: [Scalar; 3]| self.vector::<T>(x);
        let count = |n: u32| T::of(f64::from(n));
        Some(match node {
            Kind::Mandelbulb(f) => {
                let power = s(f.power);
                let bailout = s(f.bailout);
                let escape = T::of(escape_radius(power.to_f64(), bailout.to_f64()));
                sdf::mandelbulb_estimate(
                    p,
                    power,
                    count(f.iterations),
                    escape,
                    mandelbulb_radius(power),
                    f.power.baked().and_then(integer_power),
                    trap,
                )
            }
            Kind::Menger(f) => sdf::menger_estimate(p, count(f.iterations), s(f.scale), trap),
            Kind::Julia(f) => sdf::julia_estimate(
                p,
                f.c.map(s),
                s(f.slice_w),
                count(f.iterations),
                s(f.bailout),
                trap,
            ),
            Kind::Sierpinski(f) => {
                sdf::sierpinski_estimate(p, count(f.iterations), s(f.scale), trap)
            }
            Kind::Kifs(f) => sdf::kifs_estimate(
                p,
                count(f.iterations),
                &sdf::KifsParams::new(f.fold, s(f.scale), v(f.offset))
                    .with_turns(f.rotate_before.map(v), f.rotate_after.map(v)),
                trap,
            ),
            Kind::Hybrid(h) => sdf::hybrid_estimate(
                p,
                count(h.iterations),
                &h.map(|x| s(*x)),
                &sdf::hybrid_integer_powers(h),
                trap,
            ),
            Kind::PseudoKleinian(f) => {
                sdf::pseudo_kleinian_estimate(p, count(f.iterations), &f.map(|x| s(*x)), trap)
            }
            Kind::Mandelbox(f) => sdf::mandelbox_estimate(
                p,
                count(f.iterations),
                &sdf::MandelboxParams::new(
                    s(f.scale),
                    s(f.min_radius),
                    s(f.fixed_radius),
                    s(f.fold_limit),
                    f.julia.map(|[x, y, z]| v3(s(x), s(y), s(z))),
                ),
                trap,
            ),
            _ => return None,
        })
    }
}

/// Hard or smooth CSG of two samples. Every operation is a (smooth) minimum
/// of signed operands: union `min(a, b)`, subtraction `-min(-a, b)`,
/// intersection and cut `-min(-a, -b)`. A cut keeps `a`'s colour, trap and
/// material.
fn combine<T: Real>(op: CsgOp, k: Option<T>, a: Sample<T>, b: Sample<T>) -> Sample<T> {
    let c = sdf::csg(op, a.distance, b.distance, k);
    if op == CsgOp::Cut {
        return Sample {
            distance: c.distance,
            ..a
        };
    }
    let (near, far) = if c.first_nearer { (a, b) } else { (b, a) };
    let mix = |u: T, w: T| u + (w - u) * c.blend;
    Sample {
        distance: c.distance,
        color: near.color.zip(far.color, mix),
        trap: mix(near.trap, far.trap),
        orbit: mix(near.orbit, far.orbit),
        material: std::array::from_fn(|i| mix(near.material[i], far.material[i])),
        object: near.object,
        material_node: near.material_node,
    }
}

/// A ray: origin and unit direction.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Ray {
    /// Where the ray starts.
    pub origin: DVec3,
    /// Its unit direction.
    pub direction: DVec3,
}

/// Sphere-tracing settings: the same march, with the same names, as the
/// kernel's `march_ray`.
///
/// A pixel covers `footprint(t) = footprint_base + footprint_per_unit · t`
/// scene units at distance `t` along a ray. The drawn surface is where the
/// distance falls to `detail` footprints; the march steps by the distance
/// to that surface, no shorter than `hit_epsilon` footprints, and locates
/// the crossing to `hit_epsilon` footprints along the ray.
/// `render::Viewport::march_settings` (feature `opencl`) gives the
/// settings of a rendered image.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct MarchSettings {
    /// Give up after this many steps (`MAX_STEPS`).
    pub max_steps: u32,
    /// Give up beyond this distance along the ray (`MAX_DISTANCE`).
    pub max_distance: f64,
    /// The pixel footprint at the ray origin, in scene units.
    pub footprint_base: f64,
    /// Growth of the pixel footprint per unit of ray length.
    pub footprint_per_unit: f64,
    /// The drawn surface, in footprints (`DETAIL`).
    pub detail: f64,
    /// The shortest step and the precision of the located crossing, in
    /// footprints (`HIT_EPSILON`); at most `detail` for a bounded number of
    /// steps along grazing rays.
    pub hit_epsilon: f64,
    /// Relaxation factor ω, in `[0.25, 2)` (`OVER_RELAXATION`; see
    /// [`Quality::over_relaxation`](crate::quality::Quality::over_relaxation)).
    pub over_relaxation: f64,
}

impl MarchSettings {
    /// Scene units covered by one pixel at distance `t` along a ray.
    #[must_use]
    pub fn footprint(&self, t: f64) -> f64 {
        self.footprint_base + self.footprint_per_unit * t
    }
}

impl Default for MarchSettings {
    /// A fixed footprint of `1e-4` (the surface where the distance falls to
    /// `1e-4`), hits located to a tenth of it, 256 steps, 100 units.
    fn default() -> Self {
        MarchSettings {
            max_steps: 256,
            max_distance: 100.0,
            footprint_base: 1e-4,
            footprint_per_unit: 0.0,
            detail: 1.0,
            hit_epsilon: 0.1,
            over_relaxation: 1.0,
        }
    }
}

setters!(MarchSettings {
    /// Sets [`MarchSettings::max_steps`].
    max_steps: u32,
    /// Sets [`MarchSettings::max_distance`].
    max_distance: f64,
    /// Sets [`MarchSettings::footprint_base`].
    footprint_base: f64,
    /// Sets [`MarchSettings::footprint_per_unit`].
    footprint_per_unit: f64,
    /// Sets [`MarchSettings::detail`].
    detail: f64,
    /// Sets [`MarchSettings::hit_epsilon`].
    hit_epsilon: f64,
    /// Sets [`MarchSettings::over_relaxation`].
    over_relaxation: f64,
});

impl Ray {
    /// A ray from `origin` along the unit vector `direction`.
    #[must_use]
    pub fn new(origin: DVec3, direction: DVec3) -> Ray {
        Ray { origin, direction }
    }
}

/// The result of tracing one ray (the kernel's `MarchResult`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Hit {
    /// Whether a surface was reached.
    pub hit: bool,
    /// Distance along the ray where the march stopped (`t`).
    pub depth: f64,
    /// Steps (distance evaluations) taken.
    pub steps: u32,
    /// The angle of the nearest miss: the smallest `d / (t + d)` seen along
    /// the ray, 1 at most, 0 on a hit (drives glow).
    pub closest: f64,
}

/// Sphere-traces `ray` through the scene, exactly as the kernel's
/// `march_ray` does: steps of the distance to the drawn surface (no
/// shorter than `hit_epsilon` footprints; relaxed, with the fallback, when
/// `over_relaxation > 1`), then the crossing located by the Illinois form
/// of regula falsi.
#[must_use]
pub fn march(eval: &Evaluator, ray: Ray, settings: &MarchSettings) -> Hit {
    march_with(eval, ray, settings, None, &mut |_| {})
}

/// [`march`], calling `visit` with every point where it evaluates the
/// distance.
#[cfg(feature = "opencl")]
pub(crate) fn march_visiting(
    eval: &Evaluator,
    ray: Ray,
    settings: &MarchSettings,
    visit: &mut dyn FnMut(DVec3),
) -> Hit {
    march_with(eval, ray, settings, None, visit)
}

/// Brute-force marching of a scene with inside shapes (see
/// [`InsideShape`](crate::scene::InsideShape)), as the kernel's
/// `march_ray` does it: within `region` (the scene's
/// [`Ir::brute_region`]) steps of at most `step` footprints on a lattice
/// that starts `phase` of a step past where the ray enters it, or the
/// sphere tracer's step where that is shorter.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Brute {
    /// The step within the region, in footprints
    /// ([`Quality::brute_step`](crate::quality::Quality::brute_step)).
    pub step: f64,
    /// The sphere the scene's inside shapes lie in.
    pub region: Bound,
    /// Where the lattice starts, in `[0, 1)` of a step.
    pub phase: f64,
}

impl Brute {
    /// The brute-force march of `eval`'s scene with `step` footprints and
    /// `phase`; `None` for a scene without inside shapes.
    #[must_use]
    pub fn of(eval: &Evaluator, step: f64, phase: f64) -> Option<Self> {
        eval.ir().brute_region().map(|region| Brute {
            step,
            region,
            phase,
        })
    }

    /// Where `ray` is within the region: `(enter, exit)`, `enter > exit`
    /// where it misses.
    fn span(&self, ray: Ray) -> (f64, f64) {
        let oc = ray.origin - self.region.centre;
        let b = oc.dot(ray.direction);
        let disc = b * b - (oc.length_squared() - self.region.radius * self.region.radius);
        if disc < 0.0 {
            return (1.0, -1.0);
        }
        let root = disc.sqrt();
        (-b - root, -b + root)
    }
}

/// [`march`] with brute-force steps within inside shapes' region (see
/// [`Brute`]): the kernel's `march_ray` in a program that has them. A
/// crossing into an inside shape, whose value has only a sign, is located
/// by bisection.
#[must_use]
pub fn march_brute(eval: &Evaluator, ray: Ray, settings: &MarchSettings, brute: &Brute) -> Hit {
    march_with(eval, ray, settings, Some(brute), &mut |_| {})
}

/// The kernel's `march_brute_step`: a step from `t` of at most `step` that
/// does not pass the next sample of the lattice (kept in `next`, negative
/// before the first) within `span`.
fn brute_step(t: f64, step: f64, span: (f64, f64), h: f64, phase: f64, next: &mut f64) -> f64 {
    if t + step <= span.0 || t >= span.1 {
        return step;
    }
    if *next < 0.0 {
        *next = t.max(span.0) + phase * h;
    }
    if *next <= t {
        *next = t + h;
    }
    let to_next = *next - t;
    if to_next > step {
        return step;
    }
    *next += h;
    to_next
}

fn march_with(
    eval: &Evaluator,
    ray: Ray,
    settings: &MarchSettings,
    brute: Option<&Brute>,
    visit: &mut dyn FnMut(DVec3),
) -> Hit {
    let surface = |t: f64| settings.detail * settings.footprint(t);
    let visit = std::cell::RefCell::new(visit);
    let distance = |p: DVec3| {
        (visit.borrow_mut())(p);
        eval.distance(p)
    };
    let level = |t: f64| distance(ray.origin + ray.direction * t) - surface(t);
    let lipschitz = 1.0 + settings.detail * settings.footprint_per_unit;
    let mut omega = settings.over_relaxation;
    let mut relaxed = false;
    let (mut t, mut prev_t, mut prev_g) = (0.0, 0.0, 0.0);
    let mut closest: f64 = 1.0;
    let mut steps = 0;
    let stop = |hit, depth, steps, closest| Hit {
        hit,
        depth,
        steps,
        closest,
    };
    let span = brute.map_or((1.0, -1.0), |b| b.span(ray));
    let mut next_sample = -1.0;
    let mut brute_steps = 0;
    // Steps that count towards `max_steps`: brute-force ones do not, up to
    // BRUTE_MAX_STEPS of them.
    let mut i = 0;
    while i < settings.max_steps {
        i += 1;
        let d = distance(ray.origin + ray.direction * t);
        let g = d - surface(t);
        steps += 1;
        if relaxed && (g < 0.0 || prev_g + g < lipschitz * (t - prev_t)) {
            t = prev_t + prev_g / lipschitz;
            omega = 1.0;
            relaxed = false;
            continue;
        }
        if d > 0.0 {
            closest = closest.min(d / (t + d));
        }
        if g <= 0.0 {
            if steps > 1 {
                let (depth, extra) = refine(level, (prev_t, prev_g), (t, g), |t| {
                    settings.hit_epsilon * settings.footprint(t)
                });
                t = depth;
                steps += extra;
            }
            return stop(true, t, steps, 0.0);
        }
        let plain = g / lipschitz;
        let shortest = settings.hit_epsilon * settings.footprint(t);
        relaxed = omega > 1.0 && omega * plain > plain.max(shortest);
        let mut step = (omega * plain).max(shortest);
        if let Some(b) = brute {
            let h = b.step * settings.footprint(t.max(span.0));
            let capped = brute_step(t, step, span, h, b.phase, &mut next_sample);
            if capped < step {
                step = capped;
                relaxed = false;
                if brute_steps < BRUTE_MAX_STEPS {
                    brute_steps += 1;
                    i -= 1;
                }
            }
        }
        prev_t = t;
        prev_g = g;
        t += step;
        if t > settings.max_distance {
            return stop(false, t, steps, closest);
        }
    }
    stop(false, t, steps, closest)
}

/// Most evaluations [`march`] spends locating a crossing.
const REFINE_LIMIT: u32 = 24;

/// Locates a root of `g` between `outside` (`g > 0`) and `inside`
/// (`g <= 0`), `(t, g(t))` pairs, until the bracket is narrower than
/// `tolerance(t)`, by the Illinois form of regula falsi. Returns the inside
/// end of the final bracket and the evaluations spent.
fn refine(
    g: impl Fn(f64) -> f64,
    outside: (f64, f64),
    inside: (f64, f64),
    tolerance: impl Fn(f64) -> f64,
) -> (f64, u32) {
    let ((mut t0, mut g0), (mut t1, mut g1)) = (outside, inside);
    let mut kept = 0; // the end the last step moved: -1 outside, 1 inside
    let mut evaluations = 0;
    while evaluations < REFINE_LIMIT && t1 - t0 > tolerance(t1) {
        // `max` then `min`, like OpenCL's `clamp`: a NaN lands on `t0`.
        let mut t = (t0 + (t1 - t0) * (g0 / (g0 - g1))).max(t0).min(t1);
        // An inside shape's value has a sign and no size: halve the bracket.
        if g0.abs().max(g1.abs()) >= 0.5 * INSIDE_HUGE {
            t = 0.5 * (t0 + t1);
        }
        let v = g(t);
        evaluations += 1;
        if v > 0.0 {
            (t0, g0) = (t, v);
            if kept == -1 {
                g1 *= 0.5;
            }
            kept = -1;
        } else {
            (t1, g1) = (t, v);
            if v == 0.0 {
                break;
            }
            if kept == 1 {
                g0 *= 0.5;
            }
            kept = 1;
        }
    }
    (t1, evaluations)
}

#[cfg(all(test, feature = "opencl"))]
mod distance_only {
    use glam::DVec3;

    use crate::cpu::Evaluator;
    use crate::expr::{Counted, Num, counting};
    use crate::math::V3;
    use crate::scene::{sphere, torus};

    /// Samples that carry only the distance have the distance of full
    /// samples, and cost fewer operations where booleans would mix
    /// colours and materials.
    #[test]
    fn distance_only_samples_keep_the_distance_and_cost_less() {
        let node = sphere(1.0)
            .color(DVec3::X)
            .smooth_union(torus(1.2, 0.3).color(DVec3::Y), 0.2)
            .union(sphere(0.5).translate(DVec3::new(2.0, 0.0, 0.0)));
        let full = Evaluator::new(&node).unwrap();
        let bare = full.clone().distances_only();
        for p in [
            DVec3::new(0.3, 0.2, 1.1),
            DVec3::new(1.9, 0.1, 0.0),
            DVec3::new(-3.0, 2.0, 1.0),
        ] {
            let q = V3::from_array(p.to_array().map(Counted::of));
            let (a, full_ops) = counting(|| full.sample::<Counted>(q));
            let (b, bare_ops) = counting(|| bare.sample::<Counted>(q));
            assert_eq!(a.distance, b.distance, "at {p}");
            assert!(bare_ops.flops() < full_ops.flops(), "at {p}");
        }
        // Nested, the outer count holds the inner one's.
        let ((_, inner), outer) = counting(|| counting(|| Counted::of(1.0) + Counted::of(2.0)));
        assert_eq!((inner.arithmetic, outer.arithmetic), (1, 1));
    }
}
