//! Lowering: validates a scene tree and writes it into the IR arena,
//! folding what can be folded at compile time.

use std::collections::HashMap;
use std::sync::Arc;

use glam::{DQuat, DVec3};

use super::params::{Constraint, ParamLayout, ParamSlot, Relation, check_rule};
use super::{Ir, IrNode, NodeId, NodePath, PathTree, Scalar, Vector, baked3};
use crate::error::{Error, Result};
use crate::math::{F64_LIMITS, normalize, reduce_angle};
use crate::scene::{
    CustomShape, HybridOp, Kind, MAX_HYBRID_OPS, MAX_PROFILE_VERTICES, Mapper, Node, NodeKind,
    Param, Param3, ParamSpec, Profile, Rule,
};

/// Validates and lowers `geometry` (see [`Ir::lower`]) without recursion,
/// whatever its depth: a work list visits each node twice, on the way down
/// (its own checks and parameters, in the order a recursive walk would
/// meet them) and on the way up (rules relating its parameters, folding,
/// and its place in the arena after its children).
pub(super) fn lower(geometry: &Node) -> Result<Ir> {
    let mut l = Lowering {
        visits: vec![Visit {
            node: Some(geometry.clone()),
            parent: None,
            label: label(geometry.kind()),
            lowered: None,
            id: None,
        }],
        current: 0,
        pending: Vec::new(),
        nodes: Vec::new(),
        labels: Vec::new(),
        parents: Vec::new(),
        slots: Vec::new(),
        constraints: Vec::new(),
        slot_by_name: HashMap::new(),
        placed: Vec::new(),
        operand: None,
        customs: HashMap::new(),
    };
    let mut work = vec![(0, Step::Down)];
    while let Some((v, step)) = work.pop() {
        match step {
            Step::Down => {
                l.down(v)?;
                work.push((v, Step::Up));
                work.extend(l.pending.drain(..).rev().map(|c| (c, Step::Down)));
            }
            Step::Up => l.up(v)?,
        }
    }
    let root = l.visits[0].id.expect("the root is lowered last");
    // Every slot's and constraint's path, in one tree of the visits.
    let tree = Arc::new(PathTree::new(
        l.visits.iter().map(|v| (v.label.clone(), v.parent)),
    ));
    for (place, v) in l.placed {
        let path = NodePath::new(&tree, v);
        match place {
            Place::Slot(i) => l.slots[i].used_at.0 = path,
            Place::Constraint(i) => l.constraints[i].node = path,
        }
    }
    let ir = Ir {
        nodes: l.nodes,
        labels: l.labels,
        parents: l.parents,
        root,
        params: Arc::new(ParamLayout::new(l.slots, l.constraints)),
    };
    // Every value was checked as it was met; folding multiplies and adds
    // them (nested scales, chained translations), so the folded values are
    // checked again.
    ir.check_limits(&F64_LIMITS)?;
    ir.check_inside()?;
    Ok(ir)
}

/// A node's name in paths: its kind, or a custom shape's own name.
fn label(kind: &NodeKind) -> String {
    match kind {
        Kind::Custom { shape, .. } => shape.name().to_string(),
        other => other.name().to_string(),
    }
}

/// A slot or a constraint, by index, whose path is placed at the end.
#[derive(Clone, Copy)]
enum Place {
    Slot(usize),
    Constraint(usize),
}

#[derive(Clone, Copy)]
enum Step {
    Down,
    Up,
}

/// One node of the user's tree met by the walk.
struct Visit {
    node: Option<Node>,
    parent: Option<usize>,
    /// Its step in paths (`b:torus`).
    label: String,
    /// Its parameters, lowered on the way down; children are visit indices.
    lowered: Option<Kind<Scalar, Vector, usize>>,
    /// Its node in the arena, once lowered on the way up.
    id: Option<NodeId>,
}

struct Lowering {
    visits: Vec<Visit>,
    /// The visit being lowered on the way down.
    current: usize,
    /// The children the current visit's parameters mapping met, in order.
    pending: Vec<usize>,
    nodes: Vec<IrNode>,
    labels: Vec<String>,
    parents: Vec<Option<NodeId>>,
    slots: Vec<ParamSlot>,
    /// Rules between parameters that read dynamic ones.
    constraints: Vec<Constraint>,
    slot_by_name: HashMap<String, u32>,
    /// The slots and constraints met so far, each with the visit whose path
    /// it takes once the tree of paths is built.
    placed: Vec<(Place, usize)>,
    /// For a boolean being lowered: how many operands were met so far.
    operand: Option<usize>,
    /// The custom shapes met so far, by name.
    customs: HashMap<String, CustomShape>,
}

impl Lowering {
    /// The path of a visit (`union/b:torus`), built only when needed: for
    /// an error, or where a dynamic parameter is first used.
    fn path(&self, v: usize) -> String {
        let mut steps = vec![self.visits[v].label.as_str()];
        let mut at = v;
        while let Some(parent) = self.visits[at].parent {
            steps.push(&self.visits[parent].label);
            at = parent;
        }
        steps.reverse();
        steps.join("/")
    }

    /// On the way down: the node's own checks and parameters; its children
    /// become visits in `pending`.
    fn down(&mut self, v: usize) -> Result<()> {
        self.current = v;
        // The user's node is needed only here.
        let node = self.visits[v]
            .node
            .take()
            .expect("each node is visited once");
        let kind = node.kind();
        check_structure(kind, || self.path(v))?;
        if let Kind::Custom { shape, .. } = kind {
            self.check_custom(shape)?;
        }
        self.operand = matches!(kind, Kind::Csg { .. }).then_some(0);
        let mut lowered = kind.try_map(self)?;
        match &mut lowered {
            Kind::Rotate { axis, angle, .. } => {
                *axis = normalize(*axis).expect("check_structure refuses other axes");
                // Both twins turn by the reduced angle (dynamic ones are
                // reduced as they are set).
                if let Scalar::Baked(a) = angle {
                    *a = reduce_angle(*a);
                }
            }
            // The KIFS turns' baked angles, likewise.
            Kind::Kifs(f) => {
                for turn in [&mut f.rotate_before, &mut f.rotate_after]
                    .into_iter()
                    .flatten()
                {
                    for angle in turn {
                        if let Scalar::Baked(a) = angle {
                            *a = reduce_angle(*a);
                        }
                    }
                }
            }
            // The hybrid's turns, likewise.
            Kind::Hybrid(h) => {
                for stage in &mut h.stages {
                    for op in &mut stage.ops {
                        if let HybridOp::Rotate { angles } = op {
                            for angle in angles {
                                if let Scalar::Baked(a) = angle {
                                    *a = reduce_angle(*a);
                                }
                            }
                        }
                    }
                }
            }
            // A baked normal is normalised here, in `f64`, whatever its
            // length: both twins receive the same unit vector. A zero one
            // is left for `relate` to refuse.
            Kind::Plane { normal, .. } => {
                if let Some(unit) = baked3(*normal).and_then(normalize) {
                    *normal = unit.to_array().map(Scalar::Baked);
                }
            }
            // A trap's direction, likewise.
            Kind::OrbitTrap { coloring, .. } => {
                if let Some(direction) = coloring.trap.direction_mut()
                    && let Some(unit) = baked3(*direction).and_then(normalize)
                {
                    *direction = unit.to_array().map(Scalar::Baked);
                }
            }
            _ => {}
        }
        self.visits[v].lowered = Some(lowered);
        Ok(())
    }

    /// On the way up, after every child: the rules relating the node's
    /// parameters, folding, and its place in the arena.
    fn up(&mut self, v: usize) -> Result<()> {
        let lowered = self.visits[v]
            .lowered
            .take()
            .expect("lowered on the way down");
        let Ok(node) = lowered.try_map(&mut Children(&self.visits));
        self.relate(&node, v)?;
        let folded = self.fold(node);
        let id = NodeId(u32::try_from(self.nodes.len()).expect("fewer than 2^32 nodes"));
        for child in folded.children() {
            self.parents[child.index()] = Some(id);
        }
        self.nodes.push(folded);
        self.labels.push(self.visits[v].label.clone());
        self.parents.push(None);
        self.visits[v].id = Some(id);
        Ok(())
    }

    /// Checks the rules that relate a node's parameters on their current
    /// values (baked, or the defaults of dynamic ones), and keeps those that
    /// read dynamic parameters for [`ParamValues::set`](super::ParamValues::set).
    fn relate(&mut self, node: &IrNode, v: usize) -> Result<()> {
        let relations: Vec<(&'static str, Relation)> = match node {
            Kind::RoundBox {
                half_extents,
                radius,
            } => vec![(
                "radius",
                Relation::AtMostSmallest {
                    value: *radius,
                    bound: *half_extents,
                    bound_name: "half extent",
                },
            )],
            Kind::Extrude { profile, .. } | Kind::Revolve { profile, .. } => match profile {
                Profile::RoundRect {
                    half_extents: [x, y],
                    radius,
                } => vec![(
                    "profile.radius",
                    Relation::AtMostSmallest {
                        value: *radius,
                        bound: [*x, *y, *y],
                        bound_name: "half extent",
                    },
                )],
                Profile::Vesica {
                    half_length,
                    half_width,
                } => vec![(
                    "profile.half_width",
                    Relation::AtMostSmallest {
                        value: *half_width,
                        bound: [*half_length; 3],
                        bound_name: "half length",
                    },
                )],
                _ => Vec::new(),
            },
            Kind::BoxFrame {
                half_extents,
                thickness,
            } => vec![(
                "thickness",
                Relation::AtMostSmallest {
                    value: *thickness,
                    bound: *half_extents,
                    bound_name: "half extent",
                },
            )],
            Kind::RoundedCylinder {
                radius,
                half_height,
                rounding,
            } => vec![(
                "rounding",
                Relation::AtMostSmallest {
                    value: *rounding,
                    bound: [*radius, *half_height, *half_height],
                    bound_name: "of radius and half height",
                },
            )],
            Kind::Plane { normal, .. } => vec![("normal", Relation::NonZero { vector: *normal })],
            Kind::OrbitTrap { coloring, .. } => {
                let mut relations = vec![(
                    "far",
                    Relation::Distinct {
                        value: coloring.far,
                        other: coloring.near,
                        other_name: "near",
                    },
                )];
                if let Some((name, d)) = coloring.trap.direction() {
                    relations.push((name, Relation::NonZero { vector: *d }));
                }
                relations
            }
            _ => Vec::new(),
        };
        for (param, relation) in relations {
            let constraint = Constraint {
                node: NodePath::pending(),
                param,
                relation,
            };
            let defaults = |s: Scalar| match s {
                Scalar::Baked(v) => v,
                Scalar::Dynamic(slot) => self.slots[slot as usize].default,
            };
            let dynamic = constraint.is_dynamic();
            constraint.check(defaults, || self.path(v))?;
            if dynamic {
                self.placed
                    .push((Place::Constraint(self.constraints.len()), v));
                self.constraints.push(constraint);
            }
        }
        Ok(())
    }

    /// Folds what can be folded at compile time: chains of baked
    /// translations, rotations and scales become one node, identity
    /// transforms (twists and bends of rate 0 too) and a `k = 0` smoothing
    /// disappear, and an inner colour
    /// under an outer one (which paints over it) is dropped. A single-child node's child
    /// is always the last node pushed, so merging pops it.
    fn fold(&mut self, node: IrNode) -> IrNode {
        use Scalar::Baked;
        let child_of = |n: &IrNode| match n {
            Kind::Translate { child, .. }
            | Kind::Rotate { child, .. }
            | Kind::Scale { child, .. }
            | Kind::Color { child, .. }
            | Kind::Material { child, .. }
            | Kind::Twist { child, .. }
            | Kind::Bend { child, .. } => Some(*child),
            _ => None,
        };
        let Some(child) = child_of(&node) else {
            return match node {
                Kind::Csg {
                    op,
                    smoothing: Some(Baked(0.0)),
                    a,
                    b,
                } => Kind::Csg {
                    op,
                    smoothing: None,
                    a,
                    b,
                },
                other => other,
            };
        };
        debug_assert_eq!(child.index() + 1, self.nodes.len());
        let inner = &self.nodes[child.index()];
        let merged = match (&node, inner) {
            (Kind::Translate { offset, .. }, _) if *offset == [Baked(0.0); 3] => {
                Some(inner.clone())
            }
            (
                Kind::Rotate {
                    angle: Baked(a), ..
                },
                _,
            ) if *a == 0.0 => Some(inner.clone()),
            (
                Kind::Scale {
                    factor: Baked(f), ..
                },
                _,
            ) if *f == 1.0 => Some(inner.clone()),
            // A warp of rate 0 is the identity (its estimate would still
            // take the larger of the child's and its ball's distance).
            (Kind::Twist { rate: Baked(r), .. } | Kind::Bend { rate: Baked(r), .. }, _)
                if *r == 0.0 =>
            {
                Some(inner.clone())
            }
            // The outer colour paints over the inner one.
            (
                Kind::Color { color, .. },
                Kind::Color {
                    child: grandchild, ..
                },
            ) => Some(Kind::Color {
                color: *color,
                child: *grandchild,
            }),
            // So does the outer material.
            (
                Kind::Material { material, .. },
                Kind::Material {
                    child: grandchild, ..
                },
            ) => Some(Kind::Material {
                material: material.clone(),
                child: *grandchild,
            }),
            (
                Kind::Translate { offset: outer, .. },
                Kind::Translate {
                    offset: inner_offset,
                    child: grandchild,
                },
            ) => match (baked3(*outer), baked3(*inner_offset)) {
                (Some(o), Some(i)) => Some(Kind::Translate {
                    offset: (o + i).to_array().map(Baked),
                    child: *grandchild,
                }),
                _ => None,
            },
            (
                Kind::Scale {
                    factor: Baked(outer),
                    ..
                },
                Kind::Scale {
                    factor: Baked(inner_factor),
                    child: grandchild,
                },
            ) => Some(Kind::Scale {
                factor: Baked(outer * inner_factor),
                child: *grandchild,
            }),
            (
                Kind::Rotate {
                    axis: a1,
                    angle: Baked(t1),
                    ..
                },
                Kind::Rotate {
                    axis: a2,
                    angle: Baked(t2),
                    child: grandchild,
                },
            ) => {
                let q = DQuat::from_axis_angle(*a1, *t1) * DQuat::from_axis_angle(*a2, *t2);
                let (axis, angle) = q.to_axis_angle();
                Some(Kind::Rotate {
                    axis: if axis.is_finite() { axis } else { DVec3::Y },
                    angle: Baked(if axis.is_finite() { angle } else { 0.0 }),
                    child: *grandchild,
                })
            }
            _ => None,
        };
        match merged {
            Some(m) => {
                self.nodes.pop();
                self.labels.pop();
                self.parents.pop();
                // The merged node may fold again with what is below it
                // (once at most: what is below was folded already).
                self.fold(m)
            }
            None => node,
        }
    }

    /// One definition per custom shape name in a scene (see
    /// [`CustomShape::difference`]).
    fn check_custom(&mut self, shape: &CustomShape) -> Result<()> {
        match self.customs.get(shape.name()) {
            Some(known) => match known.difference(shape) {
                Some(why) => Err(Error::CustomShape {
                    name: shape.name().into(),
                    reason: format!(
                        "{}: two different shapes with this name are used in one scene ({why})",
                        self.path(self.current)
                    ),
                }),
                None => Ok(()),
            },
            None => {
                self.customs.insert(shape.name().into(), shape.clone());
                Ok(())
            }
        }
    }

    fn lower_param(&mut self, p: &Param, param: &str, rule: Rule) -> Result<Scalar> {
        let v = self.current;
        let baked = matches!(p, Param::Value(_));
        check_rule(|| self.path(v), param, p.default_value(), rule, baked)?;
        match p {
            Param::Value(v) => Ok(Scalar::Baked(*v)),
            Param::Dynamic { name, default } => {
                if let Some(&slot) = self.slot_by_name.get(name) {
                    let existing = &self.slots[slot as usize];
                    if existing.default.to_bits() != default.to_bits() || existing.rule != rule {
                        return Err(Error::ConflictingParam { name: name.clone() });
                    }
                    return Ok(Scalar::Dynamic(slot));
                }
                let slot = u32::try_from(self.slots.len()).expect("fewer than 2^32 parameters");
                self.placed.push((Place::Slot(self.slots.len()), v));
                self.slots.push(ParamSlot {
                    name: name.clone(),
                    default: *default,
                    rule,
                    used_at: (NodePath::pending(), param.into()),
                });
                self.slot_by_name.insert(name.clone(), slot);
                Ok(Scalar::Dynamic(slot))
            }
        }
    }
}

impl Mapper<Param, Param3, Node> for Lowering {
    type S2 = Scalar;
    type V2 = Vector;
    type C2 = usize;
    type E = Error;

    fn scalar(&mut self, s: &Param, spec: ParamSpec<'_>) -> Result<Scalar> {
        self.lower_param(s, spec.name, spec.rule)
    }

    fn vector(&mut self, v: &Param3, spec: ParamSpec<'_>) -> Result<Vector> {
        let [x, y, z] = v.components();
        Ok([
            self.lower_param(x, &format!("{}.x", spec.name), spec.rule)?,
            self.lower_param(y, &format!("{}.y", spec.name), spec.rule)?,
            self.lower_param(z, &format!("{}.z", spec.name), spec.rule)?,
        ])
    }

    /// Meets a child: it becomes a visit, lowered after this node's
    /// parameters.
    fn child(&mut self, c: &Node) -> Result<usize> {
        // Operands of a boolean are told apart by `a:` and `b:`.
        let operand = match self.operand {
            Some(n) => {
                self.operand = Some(n + 1);
                if n == 0 { "a:" } else { "b:" }
            }
            None => "",
        };
        let at = self.visits.len();
        self.visits.push(Visit {
            node: Some(c.clone()),
            parent: Some(self.current),
            label: format!("{operand}{}", label(c.kind())),
            lowered: None,
            id: None,
        });
        self.pending.push(at);
        Ok(at)
    }
}

/// Replaces a lowered node's child visits by their nodes in the arena.
struct Children<'a>(&'a [Visit]);

impl Mapper<Scalar, Vector, usize> for Children<'_> {
    type S2 = Scalar;
    type V2 = Vector;
    type C2 = NodeId;
    type E = std::convert::Infallible;

    fn scalar(&mut self, s: &Scalar, _: ParamSpec<'_>) -> Result<Scalar, Self::E> {
        Ok(*s)
    }

    fn vector(&mut self, v: &Vector, _: ParamSpec<'_>) -> Result<Vector, Self::E> {
        Ok(*v)
    }

    fn child(&mut self, c: &usize) -> Result<NodeId, Self::E> {
        Ok(self.0[*c]
            .id
            .expect("children are lowered before their parent"))
    }
}

/// Checks what is not a parameter: iteration ranges, rotation axes and a
/// custom shape's argument count.
fn check_structure(kind: &NodeKind, path: impl Fn() -> String) -> Result<()> {
    if let (Some(value), Some((min, max))) = (kind.iterations(), kind.iteration_range())
        && !(min..=max).contains(&value)
    {
        return Err(Error::Iterations {
            node: path(),
            value,
            min,
            max,
        });
    }
    let zero = |param: &str| Error::ZeroVector {
        node: path(),
        param: param.into(),
    };
    match kind {
        Kind::Rotate { axis, .. } => {
            if !axis.is_finite() {
                return Err(Error::NonFinite {
                    node: path(),
                    param: "axis".into(),
                    value: axis
                        .to_array()
                        .into_iter()
                        .find(|c| !c.is_finite())
                        .unwrap_or(f64::NAN),
                });
            }
            if normalize(*axis).is_none() {
                return Err(zero("axis"));
            }
        }
        Kind::Hybrid(h) if h.ops_per_iteration() > MAX_HYBRID_OPS => {
            return Err(Error::Invalid {
                what: "fractal",
                reason: format!(
                    "{}: {} operations per iteration (each stage's operations times its \
                     repeat count); at most {MAX_HYBRID_OPS}",
                    path(),
                    h.ops_per_iteration()
                ),
            });
        }
        Kind::OrbitTrap { coloring, child } => {
            let invalid = |reason: String| Error::Invalid {
                what: "orbit trap",
                reason: format!("{}: {reason}", path()),
            };
            if !child.kind().is_fractal() {
                return Err(invalid(format!(
                    "colours a fractal by its orbit, and its child is a {} (put the orbit \
                     trap directly on the fractal, inside any transform)",
                    child.kind().name()
                )));
            }
            coloring
                .palette
                .check()
                .map_err(|e| invalid(format!("its palette {e}")))?;
        }
        Kind::Extrude { profile, .. } | Kind::Revolve { profile, .. } => {
            check_profile(profile, &path)?;
        }
        Kind::Custom { shape, args } if args.len() != shape.arity() => {
            return Err(Error::CustomShape {
                name: shape.name().into(),
                reason: format!(
                    "{}: expects {} parameter values, got {}",
                    path(),
                    shape.arity(),
                    args.len()
                ),
            });
        }
        _ => {}
    }
    Ok(())
}

/// A polygon profile's corner count, and that its corners, where all are
/// baked, enclose some area.
fn check_profile(profile: &Profile, path: &impl Fn() -> String) -> Result<()> {
    let Profile::Polygon { vertices } = profile else {
        return Ok(());
    };
    let invalid = |reason: String| Error::Invalid {
        what: "profile",
        reason: format!("{}: {reason}", path()),
    };
    if !(3..=MAX_PROFILE_VERTICES).contains(&vertices.len()) {
        return Err(invalid(format!(
            "a polygon has 3 to {MAX_PROFILE_VERTICES} vertices, and this one has {}",
            vertices.len()
        )));
    }
    let baked = profile.try_map(&mut |s, _| match s {
        Param::Value(v) => Ok(*v),
        Param::Dynamic { .. } => Err(()),
    });
    if let Ok(area) = baked.map(|p| p.twice_area())
        && area == Some(0.0)
    {
        return Err(invalid(
            "the polygon's vertices enclose no area (they lie on one line)".into(),
        ));
    }
    Ok(())
}
