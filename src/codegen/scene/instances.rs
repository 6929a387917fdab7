//! Instancing: the operands of one tree of hard unions that differ only in
//! baked values become one loop over a table of those values.

use super::*;

impl<'a> SceneEmitter<'a> {
    /// Enters the union tree under `id` as one: its operands that differ
    /// only in baked values, at least [`MIN_INSTANCES`] alike, are emitted
    /// now as one loop each, and the others are its children. `None` (the
    /// union is entered as usual) when no such group exists.
    pub(super) fn instanced_union(
        &mut self,
        id: NodeId,
        p: &str,
        needs_color: bool,
    ) -> Option<Step> {
        let ir = self.ir;
        let (mut operands, mut unions) = (Vec::new(), Vec::new());
        let mut stack = vec![id];
        while let Some(at) = stack.pop() {
            match ir.node(at) {
                Kind::Csg {
                    op: CsgOp::Union,
                    smoothing: None,
                    a,
                    b,
                } => {
                    unions.push(at);
                    stack.push(*b);
                    stack.push(*a);
                }
                _ => operands.push(at),
            }
        }
        if operands.len() < MIN_INSTANCES {
            return None;
        }
        // Operands grouped by shape, groups in the order they first appear.
        let mut order: Vec<String> = Vec::new();
        let mut groups: HashMap<String, Vec<(NodeId, Vec<f64>)>> = HashMap::new();
        for &operand in &operands {
            if let Some(Instance { shape, values, .. }) = instance(ir, operand) {
                let group = groups.entry(shape.clone()).or_insert_with(|| {
                    order.push(shape);
                    Vec::new()
                });
                group.push((operand, values));
            }
        }
        order.retain(|shape| groups[shape].len() >= MIN_INSTANCES);
        if order.is_empty() {
            return None;
        }
        let mut looped = BTreeSet::new();
        let mut results = Vec::new();
        for shape in &order {
            let members = &groups[shape];
            looped.extend(members.iter().map(|(operand, _)| *operand));
            results.push(self.instance_loop(members, p, needs_color));
        }
        self.clusters.insert(
            id,
            Cluster {
                unions,
                groups: results,
            },
        );
        let rest = operands.into_iter().filter(|o| !looped.contains(o));
        Some(Step::Descend(
            rest.map(|o| (o, p.to_string(), needs_color)).collect(),
        ))
    }

    /// One loop over a group of instances: the first member's code, reading
    /// each member's values from its row of the table. Keeps the nearest
    /// member's colour and trap (the later one on a tie, as the unrolled
    /// unions would).
    pub(super) fn instance_loop(
        &mut self,
        members: &[(NodeId, Vec<f64>)],
        p: &str,
        needs_color: bool,
    ) -> Vars {
        let (first, _) = members[0];
        let chain = instance(self.ir, first)
            .expect("members are instances")
            .chain;
        let stride = members[0].1.len();
        let start = self.slots + self.constants.len();
        for (_, values) in members {
            self.constants.extend_from_slice(values);
        }
        let r = first.index();
        let (d, c, t) = (format!("dg{r}"), format!("cg{r}"), format!("tg{r}"));
        let colour = self.shade && needs_color;
        self.w.comment(&format!(
            "{} instances of {}: {stride} values each from params[{start}]",
            members.len(),
            self.ir.path_tail(first, 2)
        ));
        self.w.line(format!("real {d} = INFINITY;"));
        if colour {
            let (ty, default) = (self.surface_type(), self.default_surface());
            self.w.line(format!("{ty} {c} = {default};"));
        }
        if self.traps() {
            self.w.line(format!("real2 {t} = {};", super::NO_TRAP));
        }
        self.w
            .open(format!("for (uint i = 0u; i < {}u; i++)", members.len()));
        self.w.line(format!(
            "__global const real* q = params + {start}u + i * {stride}u;"
        ));
        self.instance = chain.into_iter().collect();
        let v = self.node(first, p, needs_color);
        self.instance.clear();
        if self.shade {
            self.w.open(format!("if ({} <= {d})", v.d));
            self.w.line(format!("{d} = {};", v.d));
            if colour {
                self.w.line(format!("{c} = {};", v.c));
            }
            if self.traps() {
                self.w.line(format!("{t} = {};", v.t));
            }
            self.w.close();
        } else {
            self.w.line(format!("{d} = fmin({d}, {});", v.d));
        }
        self.w.close();
        Vars {
            d,
            c: if colour { c } else { self.default_surface() },
            t: if self.traps() { t } else { "R(1.0)".into() },
        }
    }
}

/// The fewest operands of one tree of hard unions, alike but for their
/// baked values, that code generation emits as one loop over a table of
/// those values (see [`KernelSource::constants`](crate::codegen::KernelSource)).
pub const MIN_INSTANCES: usize = 16;

/// Rewrites a node's baked values as entries of an instance's table row,
/// in `try_map` order, and collects the values.
pub(super) struct Rewrite {
    pub(super) values: Vec<f64>,
}

impl Rewrite {
    pub(super) fn slot(&mut self, s: Scalar) -> Scalar {
        match s {
            Scalar::Baked(v) => {
                let entry = u32::try_from(self.values.len()).unwrap_or(u32::MAX);
                self.values.push(v);
                Scalar::Dynamic(INSTANCE_SLOT.saturating_add(entry))
            }
            dynamic @ Scalar::Dynamic(_) => dynamic,
        }
    }
}

impl Mapper<Scalar, Vector, NodeId> for Rewrite {
    type S2 = Scalar;
    type V2 = Vector;
    type C2 = NodeId;
    type E = Infallible;

    fn scalar(&mut self, s: &Scalar, _: ParamSpec<'_>) -> Result<Scalar, Infallible> {
        Ok(self.slot(*s))
    }

    fn vector(&mut self, v: &Vector, _: ParamSpec<'_>) -> Result<Vector, Infallible> {
        Ok(v.map(|s| self.slot(s)))
    }

    fn child(&mut self, c: &NodeId) -> Result<NodeId, Infallible> {
        Ok(*c)
    }
}

/// Forgets a node's children, so that what is left describes its shape.
pub(super) struct Skeleton;

impl Mapper<Scalar, Vector, NodeId> for Skeleton {
    type S2 = Scalar;
    type V2 = Vector;
    type C2 = ();
    type E = Infallible;

    fn scalar(&mut self, s: &Scalar, _: ParamSpec<'_>) -> Result<Scalar, Infallible> {
        Ok(*s)
    }

    fn vector(&mut self, v: &Vector, _: ParamSpec<'_>) -> Result<Vector, Infallible> {
        Ok(*v)
    }

    fn child(&mut self, _: &NodeId) -> Result<(), Infallible> {
        Ok(())
    }
}

/// An instanceable operand: a chain of nodes whose code depends on their
/// baked values only through the literals it reads (primitives, and the
/// transforms, colours and modifiers that take no decision on a value).
pub(super) struct Instance {
    /// The chain, rewritten to read its baked values from a table row.
    pub(super) chain: Vec<(NodeId, IrNode)>,
    /// Its shape: equal for operands that differ only in baked values.
    pub(super) shape: String,
    /// Its baked values, in the order of the table row.
    pub(super) values: Vec<f64>,
}

/// The operand under `root` as an instance, if it is one.
pub(super) fn instance(ir: &Ir, root: NodeId) -> Option<Instance> {
    let mut rewrite = Rewrite { values: Vec::new() };
    let (mut chain, mut shape) = (Vec::new(), String::new());
    let mut at = Some(root);
    while let Some(id) = at {
        let node = ir.node(id);
        let plain = matches!(
            node,
            Kind::Translate { .. }
                | Kind::Scale { .. }
                | Kind::Color { .. }
                | Kind::Glow { .. }
                | Kind::Material { .. }
                | Kind::Round { .. }
                | Kind::Onion { .. }
                | Kind::Elongate { .. }
                | Kind::Mirror { .. }
        );
        if !plain && leaf_function(node).is_none() {
            return None;
        }
        let Ok(rewritten) = node.try_map(&mut rewrite);
        let Ok(kind) = rewritten.try_map(&mut Skeleton);
        write!(shape, "{kind:?};").expect("writing to a String cannot fail");
        at = rewritten.children().first().map(|&&c| c);
        chain.push((id, rewritten));
    }
    Some(Instance {
        chain,
        shape,
        values: rewrite.values,
    })
}

/// A union tree entered as one: its union nodes (whose names the results
/// are combined under) and the results of its instanced groups.
pub(super) struct Cluster {
    pub(super) unions: Vec<NodeId>,
    pub(super) groups: Vec<Vars>,
}
