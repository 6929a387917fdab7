//! Emits a scene's distance functions from the IR: straight-line code, one
//! block per node, children before parents, each block headed by a comment
//! naming the node. The same walk writes `DE` (distance only) and
//! `DE_shade` (distance, colour and orbit trap), in OpenCL C or in WGSL:
//! the [`Writer`] spells each statement in its language, and the
//! formulas go to its language's printer.
//!
//! Leaves are table-driven: [`leaf_function`] names each primitive's
//! library function, and its arguments are the node's parameters in the
//! order [`Kind::try_map`](crate::scene::Kind) lists them, the one list of
//! every node's parameters.
//!
//! Wide unions are instanced: the operands of one tree of hard unions that
//! differ only in their values (at least [`MIN_INSTANCES`] of them, such as
//! thousands of coloured spheres placed with `Scene::add`) become one loop
//! over a table of those values, which the program reads from the
//! parameter buffer after the dynamic parameters (a dynamic value is an
//! entry the host copies in). The code stays the size of one operand
//! however many there are, and computes what the unrolled code would; a
//! group of at least [`MIN_HIERARCHY`] is walked through a bounding volume
//! hierarchy (`ir::bvh`) that skips the members too far away to
//! matter.

use std::cell::RefCell;
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::convert::Infallible;
use std::fmt::Write as _;

use super::formulas::vector;
use super::helpers::Helper;
use super::tables::InstanceTables;
use super::writer::{INSTANCE_SLOT, Lang, Param, Ty, Writer};
use crate::cpu::sdf::{self, TrapShape};
use crate::expr::{Num, Shape, Var, trace};
use crate::ir::{
    Bound, Ir, IrNode, NodeId, Reach, Scalar, UnionChain, Vector, constant, costs, reach, swaps,
    union_chain,
};
use crate::math::{
    F32_LIMITS, V3, escape_radius, integer_power, mandelbulb_radius, rotation_rows, v3,
};
use crate::quality::Precision;
use crate::scene::{
    CsgOp, CustomShape, Hybrid, Kind, MAX_ESCAPE_ITERATIONS, MAX_FOLD_ITERATIONS, Mapper, Palette,
    ParamSpec, Profile, Trap,
};

mod inline;
mod instances;

pub use crate::ir::bvh::MIN_HIERARCHY;
pub use instances::MIN_INSTANCES;
use instances::*;

/// The trap of a surface that has none (a `real2`: the trap that tints
/// its colour, and the trap the shading layers show).
fn no_trap(w: &Writer) -> String {
    w.construct(Ty::Real2, &[&w.real("1.0")])
}

/// One node's result: the variable holding its distance, and expressions
/// for its colour and orbit trap (a variable only where one is computed,
/// so `DE_shade` declares nothing it does not read).
struct Vars {
    d: String,
    c: String,
    t: String,
}

/// What a formula written inline reads (see `Emitter::inline`).
#[derive(Clone, Copy)]
enum Arg<'a> {
    /// A point (`real3`) by name.
    Point(&'a str),
    /// A number by name or expression.
    Value(&'a str),
    /// A parameter: a baked one is a literal the trace folds, a dynamic
    /// one its slot.
    Scalar(Scalar),
    /// Three parameters.
    Vector([Scalar; 3]),
}

/// What entering a node leaves to do.
enum Step {
    /// The node is emitted (a leaf).
    Done(Vars),
    /// Its children, with their points and whether they need a colour, come
    /// next; the node is finished when it is left.
    Descend(Vec<(NodeId, String, bool)>),
    /// A tree of hard unions: its operands come next, in the chain's order,
    /// each folded into the minimum so far (within reach of its bound).
    Chain(UnionChain),
}

/// The library function and helper file of each primitive: the table that
/// drives leaf emission. Its arguments are the node's parameters in
/// `try_map` order.
fn leaf_function(node: &IrNode) -> Option<(Helper, &'static str)> {
    Some(match node {
        Kind::Sphere { .. } => (Helper::Sphere, "sd_sphere"),
        Kind::Cuboid { .. } => (Helper::Cuboid, "sd_box"),
        Kind::RoundBox { .. } => (Helper::RoundBox, "sd_round_box"),
        Kind::Torus { .. } => (Helper::Torus, "sd_torus"),
        Kind::Cylinder { .. } => (Helper::Cylinder, "sd_cylinder"),
        Kind::Capsule { .. } => (Helper::Capsule, "sd_capsule"),
        Kind::Plane { .. } => (Helper::Plane, "sd_plane"),
        Kind::Octahedron { .. } => (Helper::Octahedron, "sd_octahedron"),
        Kind::OctahedronBound { .. } => (Helper::OctahedronBound, "sd_octahedron_bound"),
        Kind::CappedCone { .. } => (Helper::CappedCone, "sd_capped_cone"),
        Kind::HexPrism { .. } => (Helper::HexPrism, "sd_hex_prism"),
        Kind::RoundCone { .. } => (Helper::RoundCone, "sd_round_cone"),
        Kind::Link { .. } => (Helper::Link, "sd_link"),
        Kind::CutSphere { .. } => (Helper::CutSphere, "sd_cut_sphere"),
        Kind::SolidAngle { .. } => (Helper::SolidAngle, "sd_solid_angle"),
        Kind::CappedTorus { .. } => (Helper::CappedTorus, "sd_capped_torus"),
        Kind::Triangle { .. } => (Helper::Triangle, "sd_triangle"),
        Kind::Quad { .. } => (Helper::Quad, "sd_quad"),
        Kind::Pyramid { .. } => (Helper::Pyramid, "sd_pyramid"),
        Kind::Rhombus { .. } => (Helper::Rhombus, "sd_rhombus"),
        Kind::TriPrism { .. } => (Helper::TriPrism, "sd_tri_prism"),
        Kind::RoundedCylinder { .. } => (Helper::RoundedCylinder, "sd_rounded_cylinder"),
        Kind::Cone { .. } => (Helper::Cone, "sd_cone"),
        Kind::InfiniteCylinder { .. } => (Helper::InfiniteCylinder, "sd_infinite_cylinder"),
        Kind::InfiniteCone { .. } => (Helper::InfiniteCone, "sd_infinite_cone"),
        Kind::CutHollowSphere { .. } => (Helper::CutHollowSphere, "sd_cut_hollow_sphere"),
        Kind::DeathStar { .. } => (Helper::DeathStar, "sd_death_star"),
        Kind::BoxFrame { .. } => (Helper::BoxFrame, "sd_box_frame"),
        Kind::CylinderBetween { .. } => (Helper::CylinderBetween, "sd_cylinder_between"),
        Kind::ConeBetween { .. } => (Helper::ConeBetween, "sd_cone_between"),
        Kind::RoundConeBetween { .. } => (Helper::RoundConeBetween, "sd_round_cone_between"),
        Kind::Ellipsoid { .. } => (Helper::Ellipsoid, "sd_ellipsoid"),
        _ => return None,
    })
}

/// Collects a node's parameters as source expressions, in `try_map` order.
struct Arguments<'w> {
    w: &'w Writer,
    out: Vec<String>,
}

impl Mapper<Scalar, Vector, NodeId> for Arguments<'_> {
    type S2 = ();
    type V2 = ();
    type C2 = ();
    type E = Infallible;

    fn scalar(&mut self, s: &Scalar, _: ParamSpec<'_>) -> Result<(), Infallible> {
        self.out.push(self.w.scalar(*s));
        Ok(())
    }

    fn vector(&mut self, v: &Vector, _: ParamSpec<'_>) -> Result<(), Infallible> {
        self.out.push(self.w.vector(*v));
        Ok(())
    }

    fn child(&mut self, _: &NodeId) -> Result<(), Infallible> {
        Ok(())
    }
}

pub(crate) struct SceneEmitter<'a> {
    ir: &'a Ir,
    /// For a program in the scene's local frame: the translation it
    /// leaves out (see `Ir::local_frame`).
    frame: Option<NodeId>,
    w: &'a mut Writer,
    /// Whether the function being written carries a surface (`DE_shade`,
    /// `DE_material`) beside the distance.
    shade: bool,
    /// Whether the surface it carries is the material (`DE_material`:
    /// materials in place of colours, no traps) rather than the colour.
    material: bool,
    points: usize,
    /// Formulas written inline so far (their temporaries are named after
    /// their number: `e3_0`).
    inlined: usize,
    iteration_override: Option<u32>,
    /// The helper files the emitted code calls.
    pub(crate) used: BTreeSet<Helper>,
    /// The custom shapes the emitted code calls, by name.
    pub(crate) customs: BTreeMap<String, CustomShape>,
    /// The integer Mandelbulb powers that need a specialised helper.
    pub(crate) powers: BTreeSet<u32>,
    /// The hybrids' helpers, one per structure (their operations and
    /// integer powers), by the structure's description.
    pub(crate) hybrids: BTreeMap<String, HybridHelper>,
    /// The fractal helpers called in their trapped form (by the plain
    /// form's name).
    pub(crate) trapped: BTreeSet<String>,
    /// The trap shapes (the arguments of a trapped form) of the
    /// fractals an orbit trap colours, by the fractal's node, while it is
    /// entered.
    traps: HashMap<NodeId, String>,
    /// The instances' table rows, read from `params[slots + i]`.
    pub(crate) constants: Vec<f64>,
    /// How the tables follow the dynamic values.
    pub(crate) tables: InstanceTables,
    /// Every dynamic parameter's default, by slot: the table entries that
    /// copy one start as it.
    defaults: Vec<f64>,
    /// How many slots the dynamic parameters take before the tables.
    slots: usize,
    /// While a loop body is emitted: its nodes, reading the table row.
    instance: HashMap<NodeId, IrNode>,
    /// Union trees entered as one, until they are left.
    clusters: HashMap<NodeId, Cluster>,
    /// Each node's bound, where the kernel's precision can compute it.
    bounds: Vec<Option<Bound>>,
    /// Each node's rough cost (`ir::costs`): which operand of a smooth
    /// union goes first.
    costs: Vec<f64>,
    /// Booleans whose second operand's block is open.
    gated: BTreeSet<NodeId>,
}

/// A hybrid's helper: its name, the structure it is printed for (the
/// hybrid with its parameters left out), and its baked integer powers.
pub(crate) type HybridHelper = (String, Hybrid<()>, Vec<Option<u32>>);

impl<'a> SceneEmitter<'a> {
    pub(crate) fn new(
        ir: &'a Ir,
        frame: Option<NodeId>,
        w: &'a mut Writer,
        iteration_override: Option<u32>,
    ) -> Self {
        SceneEmitter {
            ir,
            frame,
            w,
            shade: false,
            material: false,
            points: 0,
            inlined: 0,
            iteration_override,
            used: BTreeSet::new(),
            customs: BTreeMap::new(),
            powers: BTreeSet::new(),
            hybrids: BTreeMap::new(),
            trapped: BTreeSet::new(),
            traps: HashMap::new(),
            constants: Vec::new(),
            tables: InstanceTables::default(),
            defaults: ir.default_values().as_slice().to_vec(),
            slots: ir.params().len(),
            instance: HashMap::new(),
            clusters: HashMap::new(),
            bounds: ir
                .bounds()
                .into_iter()
                .map(|b| b.filter(|b| b.fits(&F32_LIMITS)))
                .collect(),
            costs: costs(ir),
            gated: BTreeSet::new(),
        }
    }

    /// Writes `DE` and `DE_shade`, and `DE_material` with `materials`.
    pub(crate) fn emit(&mut self, materials: bool) {
        let functions = [(false, false), (true, false), (true, true)];
        #[cfg(debug_assertions)]
        let mut first_layout: Option<Vec<f64>> = None;
        for (shade, material) in functions.into_iter().take(if materials { 3 } else { 2 }) {
            self.shade = shade;
            self.material = material;
            self.points = 0;
            // Every function lays out the same tables.
            self.constants.clear();
            self.tables = InstanceTables::default();
            let p0 = Param::Value("p0", Ty::Real3);
            let head = match (shade, material) {
                (false, _) => self.w.function_head("DE", Ty::Real, &[p0, Param::Buffer]),
                (true, false) => self.w.function_head(
                    "DE_shade",
                    Ty::Real,
                    &[
                        p0,
                        Param::Buffer,
                        Param::Pointer("color", Ty::Real3),
                        Param::Pointer("trap", Ty::Real2),
                    ],
                ),
                (true, true) => self.w.function_head(
                    "DE_material",
                    Ty::Real,
                    &[p0, Param::Buffer, Param::Pointer("material", Ty::Real16)],
                ),
            };
            self.w.open(head);
            let out = self.node(self.ir.root(), "p0", true);
            if material {
                self.w.line(format!("*material = {};", out.c));
            } else if shade {
                self.w.line(format!("*color = {};", out.c));
                self.w.line(format!("*trap = {};", out.t));
            }
            self.w.line(format!("return {};", out.d));
            self.w.close();
            self.w.line("");
            #[cfg(debug_assertions)]
            match &first_layout {
                Some(first) => debug_assert!(
                    *first == self.constants,
                    "every function lays out the same tables"
                ),
                None => first_layout = Some(self.constants.clone()),
            }
        }
    }

    /// Writes `DE_glow0`, `DE_glow1`, ...: for each glow node of the scene
    /// (in the order [`Ir::glows`] lists them) the distance to its shape
    /// where the scene places it, whatever the booleans above it do with
    /// it (a glow's halo is its own shape's). Each walks the path from the
    /// root, moving the point as every node on it does and leaving out the
    /// other operands of the booleans it passes, and sizes the distance on
    /// the way back as the nodes above do (a scale). Returns how many it
    /// wrote. The instance tables of their loops go after the scene's.
    pub(crate) fn emit_glows(&mut self) -> usize {
        self.shade = false;
        self.material = false;
        let glows = self.ir.glows();
        for (j, &glow) in glows.iter().enumerate() {
            self.points = 0;
            let head = self.w.function_head(
                &format!("DE_glow{j}"),
                Ty::Real,
                &[Param::Value("p0", Ty::Real3), Param::Buffer],
            );
            self.w.open(head);
            self.w
                .comment(&format!("the halo of {}", self.ir.path_tail(glow, 3)));
            // The path from the root, outermost first.
            let mut path = vec![glow];
            while let Some(parent) = self.ir.parent(*path.last().expect("the path has a node")) {
                path.push(parent);
            }
            path.reverse();
            let mut p = "p0".to_string();
            // The single-child nodes passed, to leave on the way back.
            let mut passed: Vec<(NodeId, String)> = Vec::new();
            for pair in path.windows(2) {
                let (node, next) = (pair[0], pair[1]);
                if matches!(
                    self.ir.node(node),
                    Kind::Csg {
                        op: CsgOp::Union,
                        smoothing: None,
                        ..
                    }
                ) {
                    // A hard union moves nothing.
                    continue;
                }
                let Step::Descend(children) = self.enter(node, &p, false) else {
                    unreachable!("a node above another has children")
                };
                let single = children.len() == 1;
                let (_, q, _) = children
                    .into_iter()
                    .find(|(c, _, _)| *c == next)
                    .expect("the path goes through a child");
                if single {
                    passed.push((node, p.clone()));
                }
                p = q;
            }
            let mut v = self.node(glow, &p, false);
            for (node, at) in passed.into_iter().rev() {
                v = self.leave(node, &at, false, vec![v]);
            }
            self.w.line(format!("return {};", v.d));
            self.w.close();
            self.w.line("");
        }
        if glows.is_empty() {
            return 0;
        }
        // Node j's distance and its halo's colour times its strength.
        let head = self.w.function_head(
            "glow_distance",
            Ty::Real,
            &[
                Param::Value("j", Ty::Int),
                Param::Value("p", Ty::Real3),
                Param::Buffer,
            ],
        );
        self.w.open(head);
        self.w.open(self.switch("j"));
        for j in 0..glows.len() {
            let call = self.w.call(&format!("DE_glow{j}"), "p");
            self.case(j, &format!("return {call};"));
        }
        self.end_switch();
        let infinity = self.w.cast(Ty::Real, self.w.infinity());
        self.w.line(format!("return {infinity};"));
        self.w.close();
        self.w.line("");
        let head = self.w.function_head(
            "glow_color",
            Ty::Real3,
            &[Param::Value("j", Ty::Int), Param::Buffer],
        );
        self.w.open(head);
        self.w.open(self.switch("j"));
        for (j, &glow) in glows.iter().enumerate() {
            let Kind::Glow {
                color, strength, ..
            } = self.ir.node(glow)
            else {
                unreachable!("glows lists glow nodes")
            };
            let [r, g, b] = color.map(|c| self.w.scalar(c));
            let k = self.w.scalar(*strength);
            let rgb = self.w.construct(Ty::Real3, &[&r, &g, &b]);
            self.case(j, &format!("return {rgb} * {k};"));
        }
        self.end_switch();
        let zero = self.w.construct(Ty::Real3, &[&self.w.real("0.0")]);
        self.w.line(format!("return {zero};"));
        self.w.close();
        self.w.line("");
        glows.len()
    }

    /// A vector parameter as a `real3` of its three values.
    fn three(&self, v: Vector) -> String {
        let [x, y, z] = v.map(|s| self.w.scalar(s));
        self.w.construct(Ty::Real3, &[&x, &y, &z])
    }

    /// The head of a `switch` on the integer `j`.
    fn switch(&self, j: &str) -> String {
        match self.w.lang() {
            Lang::OpenCl => format!("switch ({j})"),
            Lang::Wgsl => format!("switch {j}"),
        }
    }

    /// One case of a `switch`: the statement for `j`.
    fn case(&mut self, j: usize, statement: &str) {
        match self.w.lang() {
            Lang::OpenCl => self.w.line(format!("case {j}: {statement}")),
            Lang::Wgsl => self.w.line(format!("case {j}: {{ {statement} }}")),
        }
    }

    /// Closes a `switch` (WGSL's needs a default case).
    fn end_switch(&mut self) {
        if self.w.lang() == Lang::Wgsl {
            self.w.line("default: {}");
        }
        self.w.close();
    }

    /// Whether the function being written computes orbit traps.
    fn traps(&self) -> bool {
        self.shade && !self.material
    }

    /// The surface value of a node that sets none: the default colour, or
    /// the default material.
    fn default_surface(&self) -> String {
        if self.material {
            "DEFAULT_MATERIAL".into()
        } else {
            "DEFAULT_COLOR".into()
        }
    }

    /// The type of the surface values: a colour or a material.
    fn surface_type(&self) -> Ty {
        if self.material { Ty::Real16 } else { Ty::Real3 }
    }

    /// A fractal's iteration count under [`Quality::fractal_iterations`]
    /// (a cap), kept within the fractal's valid range.
    ///
    /// [`Quality::fractal_iterations`]: crate::quality::Quality::fractal_iterations
    fn iterations(&self, own: u32, (min, max): (u32, u32)) -> u32 {
        self.iteration_override
            .map_or(own, |cap| own.min(cap).clamp(min, max))
    }

    /// Heads a node's own code with a comment naming it: the last steps of
    /// its path, as validation errors name it.
    fn label(&mut self, id: NodeId) {
        self.w.comment(&self.ir.path_tail(id, 3));
    }

    /// The node's parameters as source expressions, in `try_map` order.
    fn arguments(&self, node: &IrNode) -> String {
        let mut args = Arguments {
            w: &*self.w,
            out: Vec::new(),
        };
        let Ok(_) = node.try_map(&mut args);
        args.out.join(", ")
    }

    /// A leaf: its distance expression, default colour, trap 1.
    fn leaf(&mut self, id: NodeId, expr: String) -> Vars {
        let d = format!("d{}", id.index());
        self.w.declare(Ty::Real, &d, &expr);
        Vars {
            d,
            c: self.default_surface(),
            t: no_trap(self.w),
        }
    }

    /// A solid made of a plane profile (an extrusion or a revolution),
    /// written in place: a polygon's edges unroll, its baked corners
    /// folded into the code.
    fn profile_leaf(
        &mut self,
        id: NodeId,
        p: &str,
        profile: &Profile<Scalar>,
        last: Scalar,
        solid: fn(V3<Var>, &Profile<Var>, Var) -> Var,
    ) -> Vars {
        let mut args = vec![Arg::Point(p)];
        profile.map(|s| args.push(Arg::Scalar(*s)));
        args.push(Arg::Scalar(last));
        let [d] = take(self.inline(&args, &[Shape::Scalar], |a| {
            let mut values = a[3..].iter().copied();
            let shape = profile.map(|_| values.next().expect("one value per number"));
            let last = values.next().expect("the sweep's own value");
            vec![solid(vector(a, 0), &shape, last)]
        }));
        self.leaf(id, d)
    }

    /// A fractal: the helper returns the distance and the trap.
    fn fractal(&mut self, id: NodeId, helper: Helper, args: &str) -> Vars {
        self.used.insert(helper);
        self.fractal_call(id, helper.name(), args)
    }

    /// A call of a fractal function (library or specialised): its trapped
    /// form where an orbit trap colours the node.
    fn fractal_call(&mut self, id: NodeId, function: &str, args: &str) -> Vars {
        let v = vars(id);
        let pair = format!("f{}", id.index());
        match self.traps.remove(&id) {
            Some(trap) => {
                self.trapped.insert(function.to_string());
                let function = super::formulas::fractal_name(function, true);
                self.w
                    .declare(Ty::Real2, &pair, &format!("{function}({args}, {trap})"));
            }
            None => self
                .w
                .declare(Ty::Real2, &pair, &format!("{function}({args})")),
        }
        self.w.declare(Ty::Real, &v.d, &format!("{pair}.x"));
        let t = if self.traps() {
            // The trap tints the colour, and is the trap the layers show.
            let t = self.w.construct(Ty::Real2, &[&format!("{pair}.y")]);
            self.w.declare(Ty::Real2, &v.t, &t);
            v.t
        } else {
            self.w.real("1.0")
        };
        Vars {
            c: self.default_surface(),
            t,
            d: v.d,
        }
    }

    /// Emits the tree under `root` at point `p` without recursion: a work
    /// list enters each node (its comment, and the lines that compute its
    /// children's point) and leaves it after its children (the lines that
    /// combine their results), in the order a recursive walk would.
    /// `needs_color` is false below a colour node, which paints over
    /// whatever colour its child computes, so none is computed.
    fn node(&mut self, root: NodeId, p: &str, needs_color: bool) -> Vars {
        enum Task {
            Enter(NodeId, String, bool),
            /// Between a pruned boolean's operands: opens the block that
            /// evaluates the second only within reach of its bound.
            Gate(NodeId, String, bool, Reach),
            /// After an operand of a chain: the minimum so far and the
            /// operand's result, combined under the name of a union node.
            Fold(NodeId, bool),
            Leave(NodeId, String, bool, usize),
        }
        let mut tasks = vec![Task::Enter(root, p.to_string(), needs_color)];
        let mut results: Vec<Vars> = Vec::new();
        while let Some(task) = tasks.pop() {
            match task {
                Task::Enter(id, p, needs_color) => match self.enter(id, &p, needs_color) {
                    Step::Done(v) => results.push(v),
                    Step::Chain(UnionChain { operands, unions }) => {
                        let mut run = vec![Task::Enter(operands[0], p.clone(), needs_color)];
                        for (&operand, &union) in operands[1..].iter().zip(&unions) {
                            if let Some(reach) = reach(self.ir, operand, &self.bounds) {
                                run.push(Task::Gate(union, p.clone(), needs_color, reach));
                            }
                            run.push(Task::Enter(operand, p.clone(), needs_color));
                            run.push(Task::Fold(union, needs_color));
                        }
                        tasks.extend(run.into_iter().rev());
                    }
                    Step::Descend(children) => {
                        tasks.push(Task::Leave(id, p.clone(), needs_color, children.len()));
                        let gate = self.prunable(id);
                        for (i, (child, q, color)) in children.into_iter().enumerate().rev() {
                            tasks.push(Task::Enter(child, q, color));
                            if let (1, Some(reach)) = (i, &gate) {
                                tasks.push(Task::Gate(id, p.clone(), needs_color, reach.clone()));
                            }
                        }
                    }
                },
                Task::Gate(id, p, needs_color, reach) => {
                    let a = results.last().expect("the first operand has a result");
                    self.open_gate(id, &p, needs_color, a, &reach);
                }
                Task::Fold(union, needs_color) => {
                    let b = results.pop().expect("the operand has a result");
                    let a = results.pop().expect("the chain has a minimum so far");
                    let mut v = self.csg(union, CsgOp::Union, None, &a, &b, needs_color);
                    if self.gated.remove(&union) {
                        v = self.close_gate(union, &v, needs_color);
                    }
                    results.push(v);
                }
                Task::Leave(id, p, needs_color, n) => {
                    let children = results.split_off(results.len() - n);
                    let mut v = self.leave(id, &p, needs_color, children);
                    if self.gated.remove(&id) {
                        v = self.close_gate(id, &v, needs_color);
                    }
                    results.push(v);
                }
            }
        }
        results.pop().expect("the root has a result")
    }

    /// The reach of the operand of a smooth union or a subtraction (hard
    /// unions are chains) that is evaluated second, if it has one.
    fn prunable(&self, id: NodeId) -> Option<Reach> {
        if !self.instance.is_empty() || self.clusters.contains_key(&id) {
            return None;
        }
        match self.ir.node(id) {
            Kind::Csg {
                op: CsgOp::Union | CsgOp::Subtract,
                a,
                b,
                ..
            } => {
                let second = if self.swapped(id) { a } else { b };
                reach(self.ir, *second, &self.bounds)
            }
            _ => None,
        }
    }

    /// Whether the smooth union `id` evaluates its second operand first
    /// (see `ir::swaps`): never inside an instanced loop, whose body is
    /// emitted once for operands whose costs are alike.
    fn swapped(&self, id: NodeId) -> bool {
        self.instance.is_empty() && swaps(self.ir, id, &self.bounds, &self.costs)
    }

    /// Declares the boolean's result as its first operand's, and opens the
    /// block that evaluates the second operand only where it can change
    /// that: where its bound is not beyond the first operand's distance
    /// (plus the smoothing radius), or not positive. Elsewhere the
    /// second's estimate is at least its bound, so the (smooth) minimum is
    /// the first operand's value, colour and trap exactly.
    fn open_gate(&mut self, id: NodeId, p: &str, needs_color: bool, a: &Vars, reach: &Reach) {
        let Kind::Csg { op, smoothing, .. } = self.ir.node(id) else {
            unreachable!("only booleans are gated")
        };
        let i = id.index();
        self.w.comment(&format!(
            "{}: the second operand only within reach of its bound",
            self.ir.path_tail(id, 2)
        ));
        self.w.declare(Ty::Real, &format!("u{i}"), &a.d);
        if self.shade && needs_color {
            let ty = self.surface_type();
            self.w.declare(ty, &format!("uc{i}"), &a.c);
        }
        if self.traps() {
            self.w.declare(Ty::Real2, &format!("ut{i}"), &a.t);
        }
        let first = match op {
            CsgOp::Subtract => format!("-u{i}"),
            _ => format!("u{i}"),
        };
        let threshold = match smoothing {
            Some(k) => format!("{first} + {}", self.w.scalar(*k)),
            None => first,
        };
        let [g] = take(self.inline(&[Arg::Point(p)], &[Shape::Scalar], |a| {
            vec![reach.distance_at(vector(a, 0))]
        }));
        self.w.declare(Ty::Real, &format!("g{i}"), &g);
        let zero = self.w.real("0.0");
        self.w
            .open(format!("if (!(g{i} > {threshold} && g{i} > {zero}))"));
        self.gated.insert(id);
    }

    /// Closes a gate: the boolean's value, computed in the block, becomes
    /// its result.
    fn close_gate(&mut self, id: NodeId, v: &Vars, needs_color: bool) -> Vars {
        let i = id.index();
        self.w.line(format!("u{i} = {};", v.d));
        let c = if self.shade && needs_color {
            self.w.line(format!("uc{i} = {};", v.c));
            format!("uc{i}")
        } else {
            self.default_surface()
        };
        let t = if self.traps() {
            self.w.line(format!("ut{i} = {};", v.t));
            format!("ut{i}")
        } else {
            self.w.real("1.0")
        };
        self.w.close();
        Vars {
            d: format!("u{i}"),
            c,
            t,
        }
    }

    /// Entering a node: a leaf is emitted whole; any other node emits what
    /// comes before its children and names them with their points.
    fn enter(&mut self, id: NodeId, p: &str, needs_color: bool) -> Step {
        let ir = self.ir;
        let rewritten;
        let node = match self.instance.get(&id) {
            Some(n) => {
                rewritten = n.clone();
                &rewritten
            }
            None => ir.node(id),
        };
        if self.frame == Some(id)
            && let Kind::Translate { child, .. } = node
        {
            return Step::Descend(vec![(*child, p.to_string(), needs_color)]);
        }
        if let Kind::Csg {
            op: CsgOp::Union,
            smoothing: None,
            ..
        } = node
        {
            if let Some(step) = self.instanced_union(id, p, needs_color) {
                return step;
            }
            if self.instance.is_empty()
                && let Some(chain) = union_chain(ir, id, &self.bounds)
            {
                self.label(id);
                return Step::Chain(chain);
            }
        }
        if !matches!(
            node,
            Kind::Csg { .. }
                | Kind::Color { .. }
                | Kind::Glow { .. }
                | Kind::Material { .. }
                | Kind::OrbitTrap { .. }
                | Kind::Round { .. }
                | Kind::Onion { .. }
        ) {
            self.label(id);
        }
        if let Some((helper, function)) = leaf_function(node) {
            self.used.insert(helper);
            let args = self.arguments(node);
            return Step::Done(self.leaf(id, format!("{function}({p}, {args})")));
        }
        let w = |this: &Self, s: Scalar| this.w.scalar(s);
        match node {
            Kind::Mandelbulb(f) => {
                let n = self.iterations(f.iterations, (1, MAX_ESCAPE_ITERATIONS));
                // The escape radius: a literal when power and bailout are
                // baked (folded in `f64`, as the CPU computes it).
                let [escape] = take(self.inline(
                    &[Arg::Scalar(f.power), Arg::Scalar(f.bailout)],
                    &[Shape::Scalar],
                    |a| vec![escape_radius(a[0], a[1])],
                ));
                // The radius of the ball that holds the set: a literal when
                // the power is baked, rounded as the CPU computes it.
                let ball = match f.power {
                    Scalar::Baked(p) => self.w.float(match self.w.precision() {
                        Precision::F32 => f64::from(mandelbulb_radius(p as f32)),
                        Precision::F64 => mandelbulb_radius(p),
                    }),
                    Scalar::Dynamic(_) => {
                        let [ball] =
                            take(self.inline(&[Arg::Scalar(f.power)], &[Shape::Scalar], |a| {
                                vec![mandelbulb_radius(a[0])]
                            }));
                        ball
                    }
                };
                match f.power.baked().and_then(integer_power) {
                    Some(power) => {
                        self.powers.insert(power);
                        let args = format!("{p}, {n}, {escape}, {ball}");
                        Step::Done(self.fractal_call(
                            id,
                            &super::formulas::power_helper_name(power),
                            &args,
                        ))
                    }
                    None => {
                        let args = format!("{p}, {}, {n}, {escape}, {ball}", w(self, f.power));
                        Step::Done(self.fractal(id, Helper::Mandelbulb, &args))
                    }
                }
            }
            Kind::Menger(f) => {
                let n = self.iterations(f.iterations, (0, MAX_FOLD_ITERATIONS));
                let args = format!("{p}, {n}, {}", w(self, f.scale));
                Step::Done(self.fractal(id, Helper::Menger, &args))
            }
            Kind::Julia(f) => {
                let n = self.iterations(f.iterations, (1, MAX_ESCAPE_ITERATIONS));
                let [cx, cy, cz, cw] = f.c.map(|s| w(self, s));
                let args = format!(
                    "{p}, {cx}, {cy}, {cz}, {cw}, {}, {n}, {}",
                    w(self, f.slice_w),
                    w(self, f.bailout)
                );
                Step::Done(self.fractal(id, Helper::Julia, &args))
            }
            Kind::Sierpinski(f) => {
                let n = self.iterations(f.iterations, (0, MAX_FOLD_ITERATIONS));
                let args = format!("{p}, {n}, {}", w(self, f.scale));
                Step::Done(self.fractal(id, Helper::Sierpinski, &args))
            }
            Kind::Kifs(f) => {
                let n = self.iterations(f.iterations, (0, MAX_FOLD_ITERATIONS));
                let offset = self.three(f.offset);
                let mut args = format!("{p}, {n}, {}, {offset}", w(self, f.scale));
                let turned = f.rotate_before.is_some() || f.rotate_after.is_some();
                if turned {
                    // A turn left out is no turn: zero angles.
                    for turn in [f.rotate_before, f.rotate_after] {
                        let turn = match turn {
                            Some(a) => self.three(a),
                            None => {
                                let zero = self.w.real("0.0");
                                self.w.construct(Ty::Real3, &[&zero, &zero, &zero])
                            }
                        };
                        let _ = write!(args, ", {turn}");
                    }
                }
                Step::Done(self.fractal(id, Helper::Kifs(f.fold, turned), &args))
            }
            Kind::Hybrid(h) => {
                let n = self.iterations(h.iterations, (0, MAX_ESCAPE_ITERATIONS));
                let mut args = vec![p.to_string(), n.to_string()];
                let shape = h.map(|s| args.push(w(self, *s)));
                let powers = sdf::hybrid_integer_powers(h);
                let key = format!("{shape:?} {powers:?}");
                let count = self.hybrids.len();
                let name = self
                    .hybrids
                    .entry(key)
                    .or_insert_with(|| (format!("hybrid_{count}"), shape, powers))
                    .0
                    .clone();
                Step::Done(self.fractal_call(id, &name, &args.join(", ")))
            }
            Kind::PseudoKleinian(f) => {
                let n = self.iterations(f.iterations, (0, MAX_ESCAPE_ITERATIONS));
                let args = format!(
                    "{p}, {n}, {}, {}, {}, {}",
                    self.three(f.fold_size),
                    w(self, f.inversion),
                    self.three(f.offset),
                    w(self, f.thickness)
                );
                Step::Done(self.fractal(id, Helper::PseudoKleinian, &args))
            }
            Kind::Mandelbox(f) => {
                let n = self.iterations(f.iterations, (1, MAX_ESCAPE_ITERATIONS));
                let mut args = format!(
                    "{p}, {n}, {}, {}, {}, {}",
                    w(self, f.scale),
                    w(self, f.min_radius),
                    w(self, f.fixed_radius),
                    w(self, f.fold_limit)
                );
                let helper = match f.julia {
                    Some(c) => {
                        let _ = write!(args, ", {}", self.three(c));
                        Helper::MandelboxJulia
                    }
                    None => Helper::Mandelbox,
                };
                Step::Done(self.fractal(id, helper, &args))
            }
            Kind::Extrude {
                profile,
                half_height,
            } => Step::Done(self.profile_leaf(id, p, profile, *half_height, sdf::extrude)),
            Kind::Revolve { profile, offset } => {
                Step::Done(self.profile_leaf(id, p, profile, *offset, sdf::revolve))
            }
            Kind::Translate { offset, child } => {
                let q = self.map_point(p, &[Arg::Vector(*offset)], |p, a| {
                    sdf::translate(p, vector(a, 0))
                });
                Step::Descend(vec![(*child, q, needs_color)])
            }
            Kind::Rotate { axis, angle, child } => {
                let q = match angle {
                    Scalar::Baked(a) => {
                        let rows = rotation_rows(*axis, -a);
                        self.map_point(p, &[], |p, _| sdf::rotate_rows(p, rows))
                    }
                    Scalar::Dynamic(_) => {
                        let k = axis.to_array().map(Scalar::Baked);
                        self.map_point(p, &[Arg::Vector(k), Arg::Scalar(*angle)], |p, a| {
                            sdf::rotate_axis(p, vector(a, 0), -a[3])
                        })
                    }
                };
                Step::Descend(vec![(*child, q, needs_color)])
            }
            Kind::Scale { factor, child } => {
                let q =
                    self.map_point(p, &[Arg::Scalar(*factor)], |p, a| sdf::scale_point(p, a[0]));
                Step::Descend(vec![(*child, q, needs_color)])
            }
            Kind::Mirror { axis, child } => {
                let q = self.map_point(p, &[], |p, _| sdf::mirror(p, axis.index()));
                Step::Descend(vec![(*child, q, needs_color)])
            }
            Kind::Round { child, .. } | Kind::Onion { child, .. } => {
                Step::Descend(vec![(*child, p.to_string(), needs_color)])
            }
            Kind::Elongate { extents, child } => {
                let q = self.map_point(p, &[Arg::Vector(*extents)], |p, a| {
                    sdf::elongate(p, vector(a, 0))
                });
                Step::Descend(vec![(*child, q, needs_color)])
            }
            Kind::Repeat { period, child } => {
                let q = self.map_point(p, &[Arg::Vector(*period)], |p, a| {
                    sdf::repeat(p, vector(a, 0), None)
                });
                Step::Descend(vec![(*child, q, needs_color)])
            }
            Kind::RepeatLimited {
                period,
                limit,
                child,
            } => {
                let q = self.map_point(p, &[Arg::Vector(*period)], |p, a| {
                    sdf::repeat(p, vector(a, 0), Some(*limit))
                });
                Step::Descend(vec![(*child, q, needs_color)])
            }
            Kind::Twist { rate, child } => {
                let q = self.map_point(p, &[Arg::Scalar(*rate)], |p, a| sdf::twist(p, a[0]));
                Step::Descend(vec![(*child, q, needs_color)])
            }
            Kind::Bend { rate, child } => {
                let q = self.map_point(p, &[Arg::Scalar(*rate)], |p, a| sdf::bend(p, a[0]));
                Step::Descend(vec![(*child, q, needs_color)])
            }
            Kind::Csg { op, a, b, .. } => {
                // A cut shows its first operand's surface everywhere: the
                // cutter's is never read.
                let a = (*a, needs_color);
                let b = (*b, needs_color && *op != CsgOp::Cut);
                let (a, b) = if self.swapped(id) { (b, a) } else { (a, b) };
                Step::Descend(vec![(a.0, p.to_string(), a.1), (b.0, p.to_string(), b.1)])
            }
            Kind::Custom { shape, .. } => {
                self.customs.insert(shape.name().to_string(), shape.clone());
                let args = self.arguments(node);
                let comma = if args.is_empty() { "" } else { ", " };
                Step::Done(self.leaf(id, format!("{}({p}{comma}{args})", shape.function_name())))
            }
            // Below a colour no colour is needed, below a material no
            // material: each paints over what its child computes.
            Kind::Color { child, .. } => {
                let needs = self.material && needs_color;
                Step::Descend(vec![(*child, p.to_string(), needs)])
            }
            Kind::Material { child, .. } => {
                let needs = !self.material && needs_color;
                Step::Descend(vec![(*child, p.to_string(), needs)])
            }
            Kind::Glow { child, .. } => Step::Descend(vec![(*child, p.to_string(), needs_color)]),
            Kind::OrbitTrap { coloring, child } => {
                if self.traps() && needs_color {
                    let trap = self.trap_shape(&coloring.trap);
                    self.traps.insert(*child, trap);
                }
                Step::Descend(vec![(*child, p.to_string(), needs_color)])
            }
            _ => unreachable!("leaves are emitted from the table above"),
        }
    }

    /// The arguments a trapped fractal helper takes after its own for
    /// `trap` (its ten numbers, the first six as two vectors), as source
    /// expressions: literals where its values are baked.
    fn trap_shape(&mut self, trap: &Trap<Scalar, Vector>) -> String {
        // The trap's values in order; both closures add to the list.
        let args = RefCell::new(Vec::new());
        let Ok(_) = trap.try_map(
            &mut |s, _| {
                args.borrow_mut().push(Arg::Scalar(*s));
                Ok::<_, Infallible>(())
            },
            &mut |v, _| {
                args.borrow_mut().push(Arg::Vector(*v));
                Ok(())
            },
        );
        let args = args.into_inner();
        let values: Vec<String> = if let Some(shape) = TrapShape::baked(trap) {
            // Baked: the numbers, computed here in `f64`.
            shape.values().iter().map(|&v| self.w.float(v)).collect()
        } else {
            self.inline(&args, &[Shape::Scalar; 10], |a| {
                let next = RefCell::new(a.iter().copied());
                let take = || next.borrow_mut().next().expect("one value per input");
                let Ok(trap) = trap
                    .try_map(&mut |_, _| Ok::<_, Infallible>(take()), &mut |_, _| {
                        Ok(v3(take(), take(), take()))
                    });
                TrapShape::new(&trap).values().to_vec()
            })
        };
        // The helper takes the centre and the axis as vectors.
        let [cx, cy, cz, ax, ay, az, across, along, radius, count] = take(values);
        let centre = self.w.construct(Ty::Real3, &[&cx, &cy, &cz]);
        let axis = self.w.construct(Ty::Real3, &[&ax, &ay, &az]);
        format!("{centre}, {axis}, {across}, {along}, {radius}, {count}")
    }

    /// Leaving a node after its children: the lines that combine their
    /// results.
    fn leave(&mut self, id: NodeId, p: &str, needs_color: bool, children: Vec<Vars>) -> Vars {
        if let Some(cluster) = self.clusters.remove(&id) {
            return self.combine(id, cluster, children, needs_color);
        }
        let mut children = children.into_iter();
        let mut child = || children.next().expect("each child has a result");
        let rewritten;
        let node = match self.instance.get(&id) {
            Some(n) => {
                rewritten = n.clone();
                &rewritten
            }
            None => self.ir.node(id),
        };
        if self.frame == Some(id) {
            return child();
        }
        match node {
            Kind::Scale { factor, .. } => {
                let c = child();
                self.map_distance(id, c, &[Arg::Scalar(*factor)], |d, a| {
                    sdf::scale_distance(d, a[0])
                })
            }
            Kind::Round { radius, .. } => {
                let c = child();
                self.label(id);
                self.map_distance(id, c, &[Arg::Scalar(*radius)], |d, a| sdf::rounded(d, a[0]))
            }
            Kind::Onion { thickness, .. } => {
                let c = child();
                self.label(id);
                self.map_distance(id, c, &[Arg::Scalar(*thickness)], |d, a| {
                    sdf::onion(d, a[0])
                })
            }
            Kind::Twist { rate, .. } | Kind::Bend { rate, .. } => {
                // The estimate is raised to the distance to the ball around
                // the warped child where it has that bound (`ir::warp_ball`;
                // the CPU reference does the same).
                let twist = matches!(node, Kind::Twist { .. });
                let ball = self.bounds[id.index()];
                let c = child();
                self.map_distance(id, c, &[Arg::Point(p), Arg::Scalar(*rate)], |d, a| {
                    let q = vector(a, 0);
                    let d = if twist {
                        sdf::twisted(d, a[3], q)
                    } else {
                        sdf::bent(d, a[3], q)
                    };
                    ball.map_or(d, |b| {
                        sdf::ball_floor(d, q, constant(b.centre), Var::of(b.radius))
                    })
                })
            }
            Kind::Csg { op, smoothing, .. } => {
                let (a, b) = (child(), child());
                self.label(id);
                self.csg(id, *op, *smoothing, &a, &b, needs_color)
            }
            Kind::Color { color, .. } => {
                let c = child();
                if !self.shade || self.material || !needs_color {
                    return c;
                }
                self.label(id);
                let v = vars(id);
                let rgb = self.w.vector(*color);
                self.w.declare(Ty::Real3, &v.c, &rgb);
                Vars { c: v.c, ..c }
            }
            Kind::OrbitTrap { coloring, .. } => {
                let c = child();
                if !self.traps() {
                    return c;
                }
                // The fractal's own trap tints no colour here; the layers
                // still show it.
                let raw = format!("({}).x", c.t);
                let t = self.w.construct(Ty::Real2, &[&self.w.real("1.0"), &raw]);
                if !needs_color {
                    return Vars { t, ..c };
                }
                self.label(id);
                let palette = &coloring.palette;
                let args = [
                    Arg::Value(&raw),
                    Arg::Scalar(coloring.near),
                    Arg::Scalar(coloring.far),
                ];
                let [color] = take(self.inline(&args, &[Shape::Vec3], |a| {
                    let c = palette.at(Palette::position(a[0], a[1], a[2]));
                    vec![c.x, c.y, c.z]
                }));
                let v = vars(id);
                self.w.declare(Ty::Real3, &v.c, &color);
                Vars { c: v.c, t, d: c.d }
            }
            Kind::Material { material, .. } => {
                let c = child();
                if !self.material || !needs_color {
                    return c;
                }
                self.label(id);
                let v = vars(id);
                let values = material.values().map(|s| self.w.scalar(*s));
                let values = self.w.material(values);
                self.w.declare(Ty::Real16, &v.c, &values);
                Vars { c: v.c, ..c }
            }
            // Nodes that only move the point pass their child's result on.
            _ => child(),
        }
    }
}

/// The `N` results of an inline formula.
fn take<const N: usize>(results: Vec<String>) -> [String; N] {
    results
        .try_into()
        .unwrap_or_else(|r: Vec<String>| unreachable!("{N} results asked, {} given", r.len()))
}

fn vars(id: NodeId) -> Vars {
    let i = id.index();
    Vars {
        d: format!("d{i}"),
        c: format!("c{i}"),
        t: format!("t{i}"),
    }
}
