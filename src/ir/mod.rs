//! The intermediate representation: a validated scene lowered to a flat
//! arena of nodes whose parameters are either baked constants or slots in a
//! parameter buffer.
//!
//! Lowering is where validation happens, once: every parameter is checked
//! against its [`Rule`](crate::scene::Rule), rules that relate parameters
//! are checked (and kept, when they read dynamic ones, for
//! [`ParamValues::set`]), and dynamic parameters are given slots.
//! [`Scene::compile`](crate::scene::Scene::compile) lowers the geometry and checks
//! the camera and lights into a [`CompiledScene`], the value every later
//! stage receives: the CPU reference ([`crate::cpu`]), code generation
//! ([`crate::codegen`]) and the renderer read it, never the scene tree.

mod bounds;
pub(crate) mod bvh;
mod compiled;
mod inside;
mod lower;
mod params;
mod path;

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;

pub(crate) use bounds::{
    Baking, Reach, UnionChain, bound, constant, costs, is_hard_union, reach, swaps, union_chain,
};
pub use bounds::{Bound, SHRINK};
pub use compiled::{CompiledScene, MAX_LIGHTS};
pub use params::{Constraint, ParamLayout, ParamSlot, ParamValues, Relation};
pub use path::NodePath;
pub(crate) use path::PathTree;

use crate::error::Result;
use crate::math::Limits;
use crate::scene::{Kind, Mapper, Node, ParamSpec};

/// A handle to a node in an [`Ir`] arena.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(u32);

impl NodeId {
    /// The handle of the node at `index` in [`Ir::nodes`].
    pub(crate) fn from_index(index: usize) -> Self {
        NodeId(u32::try_from(index).expect("fewer than 2^32 nodes"))
    }

    /// The node's index in [`Ir::nodes`].
    #[must_use]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// A lowered scalar parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Scalar {
    /// A constant, emitted as a literal.
    Baked(f64),
    /// Index of a slot in the parameter buffer.
    Dynamic(u32),
}

impl Scalar {
    /// The value, if it is baked.
    #[must_use]
    pub fn baked(self) -> Option<f64> {
        match self {
            Scalar::Baked(v) => Some(v),
            Scalar::Dynamic(_) => None,
        }
    }
}

/// A lowered vector parameter.
pub type Vector = [Scalar; 3];

/// A lowered node: children are arena handles.
pub type IrNode = Kind<Scalar, Vector, NodeId>;

/// A scene's geometry, lowered and validated.
#[derive(Debug, Clone, PartialEq)]
pub struct Ir {
    nodes: Vec<IrNode>,
    /// Each node's step in its path (`b:torus`), and its parent: the path
    /// of any node is rebuilt on demand, so deep scenes keep one short
    /// label per node.
    labels: Vec<String>,
    parents: Vec<Option<NodeId>>,
    root: NodeId,
    params: Arc<ParamLayout>,
}

static LOWERINGS: AtomicU64 = AtomicU64::new(0);

/// How many times geometry has been lowered in this process. Building a
/// renderer, an evaluator or a program from a [`CompiledScene`] lowers
/// nothing; each [`Scene::compile`](crate::scene::Scene::compile) lowers once.
#[must_use]
pub fn lowerings() -> u64 {
    LOWERINGS.load(Ordering::Relaxed)
}

impl Ir {
    /// Validates `geometry` and lowers it. Children are stored before their
    /// parents, so the root is the last node.
    ///
    /// # Errors
    /// The first invalid parameter, iteration count or zero direction, with
    /// the node's path (such as `smooth_union/a:translate/sphere`).
    pub fn lower(geometry: &Node) -> Result<Ir> {
        LOWERINGS.fetch_add(1, Ordering::Relaxed);
        lower::lower(geometry)
    }

    /// Every node; children come before parents.
    #[must_use]
    pub fn nodes(&self) -> &[IrNode] {
        &self.nodes
    }

    /// The node behind a handle.
    #[must_use]
    pub fn node(&self, id: NodeId) -> &IrNode {
        &self.nodes[id.index()]
    }

    /// The root of the geometry.
    #[must_use]
    pub fn root(&self) -> NodeId {
        self.root
    }

    /// The node's parent, `None` for the root.
    #[must_use]
    pub fn parent(&self, id: NodeId) -> Option<NodeId> {
        self.parents[id.index()]
    }

    /// The scene's shapes (its leaves: primitives, fractals, custom and
    /// inside shapes) in the order the scene writes them (depth first,
    /// operands in order): shape `k` of this list is object `k + 1` in a
    /// frame's [`Layers::object`](crate::render::Layers::object).
    #[must_use]
    pub fn objects(&self) -> Vec<NodeId> {
        self.preorder(|n| n.children().is_empty())
    }

    /// The scene's material nodes in the order the scene writes them:
    /// node `k` of this list is material `k + 1` in a frame's
    /// [`Layers::material`](crate::render::Layers::material).
    #[must_use]
    pub fn materials(&self) -> Vec<NodeId> {
        self.preorder(|n| matches!(n, Kind::Material { .. }))
    }

    /// The scene's glow nodes ([`Node::glow`](crate::scene::Node::glow))
    /// in the order the scene writes them.
    #[must_use]
    pub fn glows(&self) -> Vec<NodeId> {
        self.preorder(|n| matches!(n, Kind::Glow { .. }))
    }

    /// The nodes `keep` chooses, depth first from the root, each node's
    /// children in order.
    fn preorder(&self, keep: impl Fn(&IrNode) -> bool) -> Vec<NodeId> {
        let mut out = Vec::new();
        let mut stack = vec![self.root];
        while let Some(id) = stack.pop() {
            let node = self.node(id);
            if keep(node) {
                out.push(id);
            }
            stack.extend(node.children().into_iter().rev().copied());
        }
        out
    }

    /// The path of a node, as validation errors name it
    /// (`union/b:torus`).
    #[must_use]
    pub fn path(&self, id: NodeId) -> String {
        self.path_tail(id, usize::MAX)
    }

    /// The last `steps` steps of a node's path, after `.../` when the path is
    /// longer: a label that stays short in deep scenes.
    #[must_use]
    pub fn path_tail(&self, id: NodeId, steps: usize) -> String {
        let mut labels = vec![self.labels[id.index()].as_str()];
        let mut at = id;
        while let Some(parent) = self.parents[at.index()] {
            if labels.len() == steps {
                labels.push("...");
                break;
            }
            labels.push(&self.labels[parent.index()]);
            at = parent;
        }
        labels.reverse();
        labels.join("/")
    }

    /// The scene's outermost baked translation, reached from the root
    /// through colours and materials only (they move nothing), with its node. Programs
    /// for rendering leave that translation out and work in coordinates
    /// relative to it, and the host moves the camera and the lights into
    /// those coordinates in `f64`: a scene placed far from the origin then
    /// keeps the precision it has at the origin, in `F32` too.
    #[must_use]
    pub fn local_frame(&self) -> Option<(DVec3, NodeId)> {
        let mut id = self.root;
        loop {
            match self.node(id) {
                Kind::Color { child, .. }
                | Kind::Glow { child, .. }
                | Kind::Material { child, .. } => id = *child,
                Kind::Translate { offset, .. } => return baked3(*offset).map(|o| (o, id)),
                _ => return None,
            }
        }
    }

    /// Checks every baked value against the `limits` of a kernel
    /// precision: code generation does, before it writes any value as a
    /// literal of that precision. Dynamic values are checked where they are
    /// uploaded ([`ParamValues::check_within`]).
    ///
    /// # Errors
    /// [`Error::Precision`](crate::Error::Precision) for the first baked
    /// value beyond `limits`, with its node's path.
    pub fn check_limits(&self, limits: &Limits) -> Result<()> {
        for (i, node) in self.nodes.iter().enumerate() {
            let id = NodeId(u32::try_from(i).expect("fewer than 2^32 nodes"));
            node.try_map(&mut BakedLimits {
                limits,
                node: || self.path(id),
            })?;
        }
        Ok(())
    }

    /// The parameter buffer's slots: one per dynamic parameter name.
    #[must_use]
    pub fn params(&self) -> &[ParamSlot] {
        self.params.slots()
    }

    /// The parameter buffer's layout: its slots and the rules between
    /// parameters that [`ParamValues::set`] keeps.
    #[must_use]
    pub fn layout(&self) -> &ParamLayout {
        &self.params
    }

    /// The parameter buffer filled with every slot's default.
    #[must_use]
    pub fn default_values(&self) -> ParamValues {
        ParamValues::defaults(Arc::clone(&self.params))
    }
}

/// Checks the baked values of one node against a precision's limits.
struct BakedLimits<'a, F> {
    limits: &'a Limits,
    node: F,
}

impl<F: Fn() -> String> Mapper<Scalar, Vector, NodeId> for BakedLimits<'_, F> {
    type S2 = ();
    type V2 = ();
    type C2 = ();
    type E = crate::error::Error;

    fn scalar(&mut self, s: &Scalar, spec: ParamSpec<'_>) -> Result<()> {
        match s {
            Scalar::Baked(v) => {
                params::check_limits(&self.node, spec.name, *v, spec.rule, true, self.limits)
            }
            Scalar::Dynamic(_) => Ok(()),
        }
    }

    fn vector(&mut self, v: &Vector, spec: ParamSpec<'_>) -> Result<()> {
        for (s, axis) in v.iter().zip(["x", "y", "z"]) {
            let name = format!("{}.{axis}", spec.name);
            self.scalar(
                s,
                ParamSpec {
                    name: &name,
                    ..spec
                },
            )?;
        }
        Ok(())
    }

    fn child(&mut self, _: &NodeId) -> Result<()> {
        Ok(())
    }
}

/// The vector's value if every component is baked.
pub(crate) fn baked3(v: Vector) -> Option<DVec3> {
    match v {
        [Scalar::Baked(x), Scalar::Baked(y), Scalar::Baked(z)] => Some(DVec3::new(x, y, z)),
        _ => None,
    }
}
