//! The intermediate representation: a validated scene lowered to a flat
//! arena of nodes whose parameters are either baked constants or slots in a
//! parameter buffer.
//!
//! Lowering is where validation happens: every parameter is checked against
//! its [`Rule`], and dynamic parameters are given slots. The CPU reference
//! ([`crate::cpu`]) and code generation both read the IR, never the scene
//! tree.

use std::collections::HashMap;

use glam::{DQuat, DVec3};

use crate::error::{Error, Result};
use crate::scene::{CustomShape, Kind, Mapper, Node, Param, Param3, ParamSpec, Rule};

/// A handle to a node in an [`Ir`] arena.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(u32);

impl NodeId {
    /// The node's index in [`Ir::nodes`].
    #[must_use]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// A lowered scalar parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scalar {
    /// A constant, emitted as a literal.
    Baked(f64),
    /// Index of a slot in the parameter buffer.
    Dynamic(u32),
}

/// A lowered vector parameter.
pub type Vector = [Scalar; 3];

/// A lowered node: children are arena handles.
pub type IrNode = Kind<Scalar, Vector, NodeId>;

/// One slot of the parameter buffer.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSlot {
    /// The dynamic parameter's name.
    pub name: String,
    /// Its initial value.
    pub default: f64,
    /// What every value set later must satisfy.
    pub rule: Rule,
    /// Where it was first used, for error messages (`node path`, `param`).
    pub used_at: (String, String),
}

/// A scene's geometry, lowered and validated.
#[derive(Debug, Clone, PartialEq)]
pub struct Ir {
    nodes: Vec<IrNode>,
    root: NodeId,
    slots: Vec<ParamSlot>,
}

impl Ir {
    /// Validates `geometry` and lowers it. Children are stored before their
    /// parents, so the root is the last node.
    ///
    /// # Errors
    /// The first invalid parameter, iteration count or zero direction, with
    /// the node's path (such as `smooth_union/a:translate/sphere`).
    pub fn lower(geometry: &Node) -> Result<Ir> {
        let mut lowering = Lowering {
            nodes: Vec::new(),
            slots: Vec::new(),
            slot_by_name: HashMap::new(),
            path: String::new(),
            operand: None,
            customs: HashMap::new(),
        };
        let root = lowering.lower(geometry, geometry.kind().name().to_string())?;
        Ok(Ir {
            nodes: lowering.nodes,
            root,
            slots: lowering.slots,
        })
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

    /// The scene's outermost baked translation, reached from the root
    /// through colours only (they move nothing), with its node. Programs
    /// for rendering leave that translation out and work in coordinates
    /// relative to it, and the host moves the camera and the lights into
    /// those coordinates in `f64`: a scene placed far from the origin then
    /// keeps the precision it has at the origin, in `F32` too.
    #[must_use]
    pub fn local_frame(&self) -> Option<(DVec3, NodeId)> {
        let mut id = self.root;
        loop {
            match self.node(id) {
                Kind::Color { child, .. } => id = *child,
                Kind::Translate { offset, .. } => return baked3(*offset).map(|o| (o, id)),
                _ => return None,
            }
        }
    }

    /// The parameter buffer's layout: one slot per dynamic parameter name.
    #[must_use]
    pub fn params(&self) -> &[ParamSlot] {
        &self.slots
    }

    /// The parameter buffer filled with every slot's default.
    #[must_use]
    pub fn default_values(&self) -> ParamValues {
        ParamValues {
            names: self.slots.iter().map(|s| s.name.clone()).collect(),
            rules: self.slots.iter().map(|s| s.rule).collect(),
            values: self.slots.iter().map(|s| s.default).collect(),
        }
    }
}

/// Values for the dynamic parameters of one [`Ir`], checked as they are set.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamValues {
    names: Vec<String>,
    rules: Vec<Rule>,
    values: Vec<f64>,
}

impl ParamValues {
    /// Sets the dynamic parameter `name`.
    ///
    /// # Errors
    /// [`Error::UnknownParam`] if there is no such parameter,
    /// [`Error::NonFinite`] or [`Error::OutOfRange`] if `value` breaks the
    /// parameter's rule.
    pub fn set(&mut self, name: &str, value: f64) -> Result<()> {
        let slot = self
            .names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| Error::UnknownParam { name: name.into() })?;
        check_rule("dynamic parameter", name, value, self.rules[slot])?;
        self.values[slot] = value;
        Ok(())
    }

    /// The current value of `name`, if it exists.
    #[must_use]
    pub fn get(&self, name: &str) -> Option<f64> {
        let slot = self.names.iter().position(|n| n == name)?;
        Some(self.values[slot])
    }

    /// The values in slot order, as the parameter buffer holds them.
    #[must_use]
    pub fn as_slice(&self) -> &[f64] {
        &self.values
    }
}

/// The vector's value if every component is baked.
fn baked3(v: Vector) -> Option<DVec3> {
    match v {
        [Scalar::Baked(x), Scalar::Baked(y), Scalar::Baked(z)] => Some(DVec3::new(x, y, z)),
        _ => None,
    }
}

fn check_rule(node: &str, param: &str, value: f64, rule: Rule) -> Result<()> {
    if !value.is_finite() {
        return Err(Error::NonFinite {
            node: node.into(),
            param: param.into(),
            value,
        });
    }
    if !rule.accepts(value) {
        return Err(Error::OutOfRange {
            node: node.into(),
            param: param.into(),
            value,
            expected: rule.describe(),
        });
    }
    Ok(())
}

struct Lowering {
    nodes: Vec<IrNode>,
    slots: Vec<ParamSlot>,
    slot_by_name: HashMap<String, u32>,
    /// The path of the node being lowered.
    path: String,
    /// For a boolean being lowered: how many operands were lowered so far.
    operand: Option<usize>,
    /// The custom shapes met so far, by name.
    customs: HashMap<String, CustomShape>,
}

impl Lowering {
    fn lower(&mut self, node: &Node, path: String) -> Result<NodeId> {
        let saved = std::mem::replace(&mut self.path, path);
        let kind = node.kind();
        check_structure(kind, &self.path)?;
        if let Kind::Custom { shape, .. } = kind {
            self.check_custom(shape)?;
        }
        let saved_operand = std::mem::replace(
            &mut self.operand,
            matches!(kind, Kind::Csg { .. }).then_some(0),
        );
        let lowered = kind.try_map(self)?;
        self.operand = saved_operand;
        self.path = saved;
        let folded = self.fold(lowered);
        let id = NodeId(u32::try_from(self.nodes.len()).expect("fewer than 2^32 nodes"));
        self.nodes.push(folded);
        Ok(id)
    }

    /// Folds what can be folded at compile time: chains of baked
    /// translations, rotations and scales become one node, identity
    /// transforms and a `k = 0` smoothing disappear, and an inner colour
    /// under an outer one (which paints over it) is dropped. A single-child node's child
    /// is always the last node pushed, so merging pops it.
    fn fold(&mut self, node: IrNode) -> IrNode {
        use Scalar::Baked;
        let child_of = |n: &IrNode| match n {
            Kind::Translate { child, .. }
            | Kind::Rotate { child, .. }
            | Kind::Scale { child, .. }
            | Kind::Color { child, .. } => Some(*child),
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
                // The merged node may fold again with what is below it.
                self.fold(m)
            }
            None => node,
        }
    }

    /// One definition per custom shape name in a scene.
    fn check_custom(&mut self, shape: &CustomShape) -> Result<()> {
        match self.customs.get(shape.name()) {
            Some(known) if known != shape => Err(Error::CustomShape {
                name: shape.name().into(),
                reason: "two different shapes with this name are used in one scene".into(),
            }),
            Some(_) => Ok(()),
            None => {
                self.customs.insert(shape.name().into(), shape.clone());
                Ok(())
            }
        }
    }

    fn lower_param(&mut self, p: &Param, param: &str, rule: Rule) -> Result<Scalar> {
        check_rule(&self.path, param, p.default_value(), rule)?;
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
                self.slots.push(ParamSlot {
                    name: name.clone(),
                    default: *default,
                    rule,
                    used_at: (self.path.clone(), param.into()),
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
    type C2 = NodeId;
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

    fn child(&mut self, c: &Node) -> Result<NodeId> {
        // Operands of a boolean are told apart by `a:` and `b:`.
        let label = match self.operand {
            Some(n) => {
                self.operand = Some(n + 1);
                if n == 0 { "a:" } else { "b:" }
            }
            None => "",
        };
        let path = format!("{}/{}{}", self.path, label, c.kind().name());
        self.lower(c, path)
    }
}

/// Checks what the per-parameter rules cannot: iteration ranges, zero
/// directions and relations between parameters (on their default values).
fn check_structure(kind: &crate::scene::NodeKind, path: &str) -> Result<()> {
    if let (Some(value), Some((min, max))) = (kind.iterations(), kind.iteration_range()) {
        if !(min..=max).contains(&value) {
            return Err(Error::Iterations {
                node: path.into(),
                value,
                min,
                max,
            });
        }
    }
    let zero = |param: &str| Error::ZeroVector {
        node: path.into(),
        param: param.into(),
    };
    match kind {
        Kind::Rotate { axis, .. } => {
            if !axis.is_finite() {
                return Err(Error::NonFinite {
                    node: path.into(),
                    param: "axis".into(),
                    value: axis
                        .to_array()
                        .into_iter()
                        .find(|c| !c.is_finite())
                        .unwrap_or(f64::NAN),
                });
            }
            if axis.length() == 0.0 {
                return Err(zero("axis"));
            }
        }
        Kind::Plane { normal, .. } => {
            let n = normal.default_value();
            if n.is_finite() && n.length() == 0.0 {
                return Err(zero("normal"));
            }
        }
        Kind::Custom { shape, args } if args.len() != shape.arity() => {
            return Err(Error::CustomShape {
                name: shape.name().into(),
                reason: format!(
                    "{path}: expects {} parameter values, got {}",
                    shape.arity(),
                    args.len()
                ),
            });
        }
        Kind::RoundBox {
            half_extents,
            radius,
        } => {
            let (r, b) = (radius.default_value(), half_extents.default_value());
            if r > b.min_element() {
                return Err(Error::OutOfRange {
                    node: path.into(),
                    param: "radius".into(),
                    value: r,
                    expected: format!("<= the smallest half extent ({})", b.min_element()),
                });
            }
        }
        _ => {}
    }
    Ok(())
}
