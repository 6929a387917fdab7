//! Instancing: the operands of one tree of hard unions that differ only in
//! their values become one loop over a table of those values, walked
//! through a bounding volume hierarchy where the group is large.

use super::super::tables::{Refit, chain_bound};
use super::*;
use crate::ir::SHRINK;
use crate::ir::bvh::{Bvh, MIN_HIERARCHY, NODE_LEN, STACK, WIDTH};

impl<'a> SceneEmitter<'a> {
    /// Enters the union tree under `id` as one: its operands that differ
    /// only in their values, at least [`MIN_INSTANCES`] alike, are emitted
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
        let mut groups: HashMap<String, Vec<Member>> = HashMap::new();
        for &operand in &operands {
            if let Some(Instance {
                shape,
                values,
                copies,
                ..
            }) = instance(ir, operand, &self.defaults)
            {
                let group = groups.entry(shape.clone()).or_insert_with(|| {
                    order.push(shape);
                    Vec::new()
                });
                group.push(Member {
                    id: operand,
                    values,
                    copies,
                });
            }
        }
        order.retain(|shape| groups[shape].len() >= MIN_INSTANCES);
        if order.is_empty() {
            return None;
        }
        let mut looped = BTreeSet::new();
        let (mut results, mut pending) = (Vec::new(), Vec::new());
        for shape in &order {
            let members = groups.remove(shape).expect("each shape has its group");
            looped.extend(members.iter().map(|m| m.id));
            // Laid out now, in the order every function meets the groups
            // (they all read one parameter buffer); `DE` writes the loop
            // later.
            let group = self.lay_out(members);
            if self.shade {
                results.push(self.instance_loop(group, p, needs_color, None));
            } else {
                pending.push(group);
            }
        }
        self.clusters.insert(
            id,
            Cluster {
                unions,
                groups: results,
                pending,
                p: p.to_string(),
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
    /// unions would). A group of at least [`MIN_HIERARCHY`] members that
    /// all have bounds is walked through a bounding volume hierarchy
    /// instead ([`bvh`](super::bvh)), which skips the members too far away
    /// to change the minimum.
    ///
    /// `bound`, where given, is a distance the union already has (its other
    /// operands' minimum): the loop starts from it, so that a walk skips
    /// every box beyond it from the start. The minimum is the same.
    pub(super) fn instance_loop(
        &mut self,
        group: Group,
        p: &str,
        needs_color: bool,
        bound: Option<&str>,
    ) -> Vars {
        let Group {
            members,
            chain,
            hierarchy,
            start,
            row,
            nodes,
        } = group;
        let first = members[0].id;
        let stride = members[0].values.len();
        let r = first.index();
        let (d, c, t) = (format!("dg{r}"), format!("cg{r}"), format!("tg{r}"));
        let colour = self.shade && needs_color;
        // Folded with infinity as the unions fold their operands, so that a
        // bound that is not a number starts the walk as none would.
        let (min, _) = self.w.min_max();
        let start_at = bound.map_or_else(
            || self.w.infinity().to_string(),
            |b| format!("{min}({b}, {})", self.w.cast(Ty::Real, self.w.infinity())),
        );
        self.w.declare(Ty::Real, &d, &start_at);
        if colour {
            let (ty, default) = (self.surface_type(), self.default_surface());
            self.w.declare(ty, &c, &default);
        }
        if self.traps() {
            self.w.declare(Ty::Real2, &t, &super::no_trap(self.w));
        }
        match &hierarchy {
            Some(bvh) => self.hierarchy_open(&members, bvh, (start, row, nodes), r, p),
            None => {
                self.w.comment(&format!(
                    "{} instances of {}: {stride} values each from params[{start}]",
                    members.len(),
                    self.ir.path_tail(first, 2)
                ));
                self.w.open_for("i", "0u", &format!("{}u", members.len()));
            }
        }
        self.w.declare_offset("q", start, &format!("i * {row}u"));
        self.instance = chain.into_iter().collect();
        let v = self.node(first, p, needs_color);
        self.instance.clear();
        if self.shade {
            // The later member on a tie: by its place in the union, which
            // a hierarchy's table keeps after the member's values.
            let nearer = match &hierarchy {
                Some(_) => {
                    let k = self.w.cast(Ty::Uint, &self.w.at("q", stride));
                    self.w.declare(Ty::Uint, "k", &k);
                    format!("{} < {d} || ({} == {d} && k >= kg{r})", v.d, v.d)
                }
                None => format!("{} <= {d}", v.d),
            };
            self.w.open(format!("if ({nearer})"));
            self.w.line(format!("{d} = {};", v.d));
            if colour {
                self.w.line(format!("{c} = {};", v.c));
            }
            if self.traps() {
                self.w.line(format!("{t} = {};", v.t));
            }
            if hierarchy.is_some() {
                self.w.line(format!("kg{r} = k;"));
            }
            self.w.close();
        } else {
            let (min, _) = self.w.min_max();
            self.w.line(format!("{d} = {min}({d}, {});", v.d));
        }
        self.w.close();
        if hierarchy.is_some() {
            self.hierarchy_close();
        }
        Vars {
            d,
            c: if colour { c } else { self.default_surface() },
            t: if self.traps() { t } else { self.w.real("1.0") },
        }
    }

    /// Lays out a group's table in the parameter buffer: each member's
    /// values in turn, or, for a group walked through a hierarchy, each
    /// member's values and its place in the union in the order of the
    /// leaves, then the hierarchy's nodes.
    pub(super) fn lay_out(&mut self, members: Vec<Member>) -> Group {
        let chain = instance(self.ir, members[0].id, &self.defaults)
            .expect("members are instances")
            .chain;
        let template = template(&chain);
        let stride = members[0].values.len();
        let hierarchy = if members.len() >= MIN_HIERARCHY {
            let bounds: Option<Vec<Bound>> = members
                .iter()
                .map(|m| chain_bound(&template, &m.values))
                .collect();
            bounds.and_then(|b| Bvh::build(&b))
        } else {
            None
        };
        let table = self.constants.len();
        let start = self.slots + table;
        let Some(bvh) = &hierarchy else {
            for m in &members {
                self.table_row(m);
            }
            return Group {
                members,
                chain,
                hierarchy,
                start,
                row: stride,
                nodes: 0,
            };
        };
        for &i in &bvh.order {
            self.table_row(&members[i]);
            self.constants.push(i as f64);
        }
        let nodes = self.slots + self.constants.len();
        let row = stride + 1;
        if members.iter().any(|m| !m.copies.is_empty()) {
            self.tables.refits.push(Refit {
                table,
                row,
                members: members.len(),
                nodes: self.constants.len(),
                count: bvh.len(),
                chain: template,
                slope: bvh.slope,
            });
        }
        self.constants.extend_from_slice(&bvh.nodes);
        Group {
            members,
            chain,
            hierarchy,
            start,
            row,
            nodes,
        }
    }

    /// Opens the walk of a group laid out at `(start, row, nodes)` (its
    /// table, row length and nodes) down to the loop over a leaf's members.
    fn hierarchy_open(
        &mut self,
        members: &[Member],
        bvh: &Bvh,
        (start, row, nodes): (usize, usize, usize),
        r: usize,
        p: &str,
    ) {
        let stride = row - 1;
        self.w.comment(&format!(
            "{} instances of {}: {stride} values and a place each from params[{start}] - \
             walked through {} nodes of {WIDTH} boxes from params[{nodes}]",
            members.len(),
            self.ir.path_tail(members[0].id, 2),
            bvh.len()
        ));
        let (refs, counts, gaps, sp) = (
            format!("bs{r}"),
            format!("bc{r}"),
            format!("bd{r}"),
            format!("bp{r}"),
        );
        let d = format!("dg{r}");
        if self.shade {
            self.w.declare(Ty::Uint, &format!("kg{r}"), "0u");
        }
        // An entry may hold a member nearer than the minimum so far where
        // its gap (the squared distance from the point to its box, times
        // the squared smallest slope, shortened as bounds are:
        // `Bound::distance`) is zero or below the minimum's square.
        let k = bvh.slope * SHRINK;
        let k2 = self.w.float(k * k);
        let zero = self.w.real("0.0");
        let open = |g: &str| format!("({g} <= {zero} || ({d} > {zero} && {g} < {d} * {d}))");
        self.w.array(Ty::Uint, &refs, STACK);
        self.w.array(Ty::Int, &counts, STACK);
        self.w.array(Ty::Real, &gaps, STACK);
        self.w.line(format!(
            "{refs}[0] = 0u; {counts}[0] = 0; {gaps}[0] = {zero};"
        ));
        self.w.declare(Ty::Uint, &sp, "1u");
        self.w.open(format!("while ({sp} > 0u)"));
        self.w.line(format!("{sp}--;"));
        let closed = format!("!{}", open(&format!("{gaps}[{sp}]")));
        match self.w.lang() {
            Lang::OpenCl => self.w.line(format!("if ({closed}) continue;")),
            Lang::Wgsl => self.w.line(format!("if ({closed}) {{ continue; }}")),
        }
        match self.w.lang() {
            Lang::OpenCl => self.w.line(format!(
                "uint first = {refs}[{sp}]; int count = {counts}[{sp}];"
            )),
            Lang::Wgsl => {
                self.w.declare(Ty::Uint, "first", &format!("{refs}[{sp}]"));
                self.w.declare(Ty::Int, "count", &format!("{counts}[{sp}]"));
            }
        }
        self.w.open("if (count == 0)");
        self.w
            .declare_offset("node", nodes, &format!("first * {NODE_LEN}u"));
        // One vector lane per entry. Each axis's gap is capped at 1e18
        // (the precisions' largest magnitude), so that its square stays
        // finite at any point a scale makes huge: a smaller gap only opens
        // more entries.
        const { assert!(WIDTH == 4, "a node's boxes load as one real4 an axis") };
        let (_, max) = self.w.min_max();
        // WGSL clamps a vector between vectors.
        let (low, high) = match self.w.lang() {
            Lang::OpenCl => (zero.clone(), self.w.real("1e18")),
            Lang::Wgsl => (
                self.w.construct(Ty::Real4, &[&zero]),
                self.w.construct(Ty::Real4, &["1e18"]),
            ),
        };
        for (axis, c) in ["x", "y", "z"].iter().enumerate() {
            let (lo, hi) = (self.w.load4("node", axis), self.w.load4("node", axis + 3));
            let gap = format!("clamp({max}({lo} - {p}.{c}, {p}.{c} - {hi}), {low}, {high})");
            self.w.declare(Ty::Real4, &format!("g{c}"), &gap);
        }
        self.w.declare(
            Ty::Real4,
            "gap",
            &format!("{k2} * (gx * gx + gy * gy + gz * gz)"),
        );
        match self.w.lang() {
            Lang::OpenCl => self.w.line(format!(
                "real{WIDTH} to = vload{WIDTH}(6, node), n = vload{WIDTH}(7, node);"
            )),
            Lang::Wgsl => {
                self.w.declare(Ty::Real4, "to", &self.w.load4("node", 6));
                self.w.declare(Ty::Real4, "n", &self.w.load4("node", 7));
            }
        }
        let lanes: Vec<String> = (0..WIDTH).map(|j| self.w.lane(j)).collect();
        for (j, l) in lanes.iter().enumerate() {
            let o = format!("n.{l} >= {zero} && {}", open(&format!("gap.{l}")));
            self.w.declare(Ty::Bool, &format!("o{j}"), &o);
        }
        // The open entries go on the stack, the nearest last: it is taken
        // off first.
        self.w.declare(Ty::Uint, "m", &format!("{WIDTH}u"));
        self.w.declare(Ty::Real, "mg", self.w.infinity());
        for (j, l) in lanes.iter().enumerate() {
            self.w.line(format!(
                "if (o{j} && gap.{l} < mg) {{ m = {j}u; mg = gap.{l}; }}"
            ));
        }
        for (j, l) in lanes.iter().enumerate() {
            let (to, n) = (
                self.w.cast(Ty::Uint, &format!("to.{l}")),
                self.w.cast(Ty::Int, &format!("n.{l}")),
            );
            self.w.line(format!(
                "if (o{j} && m != {j}u) {{ {refs}[{sp}] = {to}; {counts}[{sp}] = {n}; \
                 {gaps}[{sp}] = gap.{l}; {sp}++; }}"
            ));
        }
        self.w.open(format!("if (m < {WIDTH}u)"));
        let pick = |v: &str| {
            let mut chain = format!("{v}.{}", lanes[WIDTH - 1]);
            for j in (0..WIDTH - 1).rev() {
                let lane = format!("{v}.{}", lanes[j]);
                chain = self.w.select(&format!("m == {j}u"), &lane, &chain);
            }
            format!("({chain})")
        };
        let (to, n) = (
            self.w.cast(Ty::Uint, &pick("to")),
            self.w.cast(Ty::Int, &pick("n")),
        );
        self.w.line(format!("{refs}[{sp}] = {to};"));
        self.w.line(format!("{counts}[{sp}] = {n};"));
        self.w.line(format!("{gaps}[{sp}] = mg;"));
        self.w.line(format!("{sp}++;"));
        self.w.close();
        self.w.line("continue;");
        self.w.close();
        let end = format!("first + {}", self.w.cast(Ty::Uint, "count"));
        self.w.open_for("i", "first", &end);
    }

    /// Appends a member's row of values to the tables, noting the entries
    /// that copy a dynamic parameter.
    fn table_row(&mut self, m: &Member) {
        let at = self.constants.len();
        self.tables
            .copies
            .extend(m.copies.iter().map(|&(entry, slot)| (at + entry, slot)));
        self.constants.extend_from_slice(&m.values);
    }

    /// Closes a leaf's loop and the walk.
    fn hierarchy_close(&mut self) {
        self.w.close();
    }
}

/// The fewest operands of one tree of hard unions, alike but for their
/// values, that code generation emits as one loop over a table of
/// those values (see [`KernelSource::constants`](crate::codegen::KernelSource)).
pub const MIN_INSTANCES: usize = 16;

/// Rewrites a node's values as entries of an instance's table row, in
/// `try_map` order, and collects them: a baked value as itself, a dynamic
/// one as its default, noted as a copy of its slot.
pub(super) struct Rewrite<'a> {
    pub(super) values: Vec<f64>,
    /// `(entry, slot)` for each entry that holds a dynamic value.
    pub(super) copies: Vec<(usize, u32)>,
    /// Every dynamic parameter's default, by slot.
    pub(super) defaults: &'a [f64],
}

impl Rewrite<'_> {
    pub(super) fn slot(&mut self, s: Scalar) -> Scalar {
        let entry = self.values.len();
        match s {
            Scalar::Baked(v) => self.values.push(v),
            Scalar::Dynamic(slot) => {
                self.copies.push((entry, slot));
                self.values.push(self.defaults[slot as usize]);
            }
        }
        Scalar::Dynamic(INSTANCE_SLOT.saturating_add(u32::try_from(entry).unwrap_or(u32::MAX)))
    }
}

impl Mapper<Scalar, Vector, NodeId> for Rewrite<'_> {
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
/// values only through the literals it reads (primitives, and the
/// transforms, colours and modifiers that take no decision on a value).
pub(super) struct Instance {
    /// The chain, rewritten to read its values from a table row.
    pub(super) chain: Vec<(NodeId, IrNode)>,
    /// Its shape: equal for operands that differ only in their values.
    pub(super) shape: String,
    /// Its values, in the order of the table row (a dynamic value's
    /// default in its entry).
    pub(super) values: Vec<f64>,
    /// `(entry, slot)` for each entry of the row that holds a dynamic value.
    pub(super) copies: Vec<(usize, u32)>,
}

/// A group of instances laid out in the parameter buffer
/// ([`SceneEmitter::lay_out`]), its loop not yet written.
pub(super) struct Group {
    members: Vec<Member>,
    /// The first member's chain, rewritten to read its values from a row.
    chain: Vec<(NodeId, IrNode)>,
    /// The hierarchy it is walked through, if any.
    hierarchy: Option<Bvh>,
    /// Where its table starts in the parameter buffer.
    start: usize,
    /// Its row length: a member's values, and its place where walked.
    row: usize,
    /// Where the hierarchy's nodes start in the parameter buffer (walked
    /// groups only).
    nodes: usize,
}

/// One operand of an instanced group: its node, its row of values, and
/// the entries of the row that copy a dynamic parameter.
pub(super) struct Member {
    pub(super) id: NodeId,
    pub(super) values: Vec<f64>,
    pub(super) copies: Vec<(usize, u32)>,
}

/// The operand under `root` as an instance, if it is one; `defaults` are
/// the dynamic parameters' defaults, by slot.
pub(super) fn instance(ir: &Ir, root: NodeId, defaults: &[f64]) -> Option<Instance> {
    let mut rewrite = Rewrite {
        values: Vec::new(),
        copies: Vec::new(),
        defaults,
    };
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
        copies: rewrite.copies,
    })
}

/// An instance's chain (root first) from the leaf up, each node's child
/// renumbered to the node before it: what [`chain_bound`] bounds.
fn template(chain: &[(NodeId, IrNode)]) -> Vec<IrNode> {
    chain
        .iter()
        .rev()
        .enumerate()
        .map(|(i, (_, node))| {
            let Ok(renumbered) = node.try_map(&mut Renumber(i));
            renumbered
        })
        .collect()
}

/// Renumbers the child of the node at place `.0` of a leaf-first chain.
struct Renumber(usize);

impl Mapper<Scalar, Vector, NodeId> for Renumber {
    type S2 = Scalar;
    type V2 = Vector;
    type C2 = NodeId;
    type E = Infallible;

    fn scalar(&mut self, s: &Scalar, _: ParamSpec<'_>) -> Result<Scalar, Infallible> {
        Ok(*s)
    }

    fn vector(&mut self, v: &Vector, _: ParamSpec<'_>) -> Result<Vector, Infallible> {
        Ok(*v)
    }

    fn child(&mut self, _: &NodeId) -> Result<NodeId, Infallible> {
        Ok(NodeId::from_index(self.0 - 1))
    }
}

/// A union tree entered as one: its union nodes (whose names the results
/// are combined under) and the results of its instanced groups.
pub(super) struct Cluster {
    pub(super) unions: Vec<NodeId>,
    pub(super) groups: Vec<Vars>,
    /// Where only the distance is wanted (`DE`): the groups, laid out,
    /// whose loops are emitted after the union's other operands, from
    /// their minimum.
    pub(super) pending: Vec<Group>,
    /// The point the union is evaluated at.
    pub(super) p: String,
}
