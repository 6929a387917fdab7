//! Formulas printed in place: domain operations, distance maps and
//! booleans traced from `cpu::sdf` with their baked values folded.

use super::*;

impl<'a> SceneEmitter<'a> {
    pub(super) fn point(&mut self, expr: String) -> String {
        self.points += 1;
        let name = format!("p{}", self.points);
        self.w.declare(Ty::Real3, &name, &expr);
        name
    }

    /// Writes `formula`, a function of `args` (in order, a point as three
    /// inputs) from [`crate::cpu::sdf`], at this place of the function:
    /// traced into the expression IR with the baked parameters as literals
    /// (so it keeps only the code they leave) and printed by the
    /// writer's printer. Gives each result's expression.
    pub(super) fn inline(
        &mut self,
        args: &[Arg<'_>],
        results: &[Shape],
        formula: impl FnOnce(&[Var]) -> Vec<Var>,
    ) -> Vec<String> {
        let mut inputs: Vec<(String, Shape)> = Vec::new();
        // Each scalar the formula reads: a literal, or the next input.
        let mut reads: Vec<Option<f64>> = Vec::new();
        for arg in args {
            let scalars: &[Scalar] = match arg {
                Arg::Point(name) => {
                    inputs.push(((*name).to_string(), Shape::Vec3));
                    reads.extend([None; 3]);
                    &[]
                }
                Arg::Value(name) => {
                    inputs.push(((*name).to_string(), Shape::Scalar));
                    reads.push(None);
                    &[]
                }
                Arg::Scalar(s) => std::slice::from_ref(s),
                Arg::Vector(v) => v,
            };
            for s in scalars {
                match *s {
                    Scalar::Baked(v) => reads.push(Some(self.w.checked(v))),
                    Scalar::Dynamic(_) => {
                        inputs.push((self.w.scalar(*s), Shape::Scalar));
                        reads.push(None);
                    }
                }
            }
        }
        let count = inputs.iter().map(|(_, s)| s.width()).sum();
        let program = trace(count, |x| {
            let mut next = x.iter();
            let values: Vec<Var> = reads
                .iter()
                .map(|r| match r {
                    Some(v) => Var::of(*v),
                    None => *next.next().expect("an input for each read"),
                })
                .collect();
            formula(&values)
        });
        let named: Vec<(&str, Shape)> = inputs.iter().map(|(n, s)| (n.as_str(), *s)).collect();
        self.inlined += 1;
        let out = self
            .w
            .printer()
            .inline(&named, results, &program, &format!("e{}_", self.inlined))
            .expect("an inline formula reads its arguments and gives its results");
        for line in out.statements.lines() {
            self.w.line(line);
        }
        out.results
    }

    /// The point a node's child sees: `map` of the node's point and `args`.
    pub(super) fn map_point(
        &mut self,
        p: &str,
        args: &[Arg<'_>],
        map: impl FnOnce(V3<Var>, &[Var]) -> V3<Var>,
    ) -> String {
        let mut all = vec![Arg::Point(p)];
        all.extend_from_slice(args);
        let [q] = take(self.inline(&all, &[Shape::Vec3], |a| {
            map(vector(a, 0), &a[3..]).to_array().to_vec()
        }));
        // A point the formula named already needs no second name.
        if q.starts_with('e') && q.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return q;
        }
        self.point(q)
    }

    /// A node's distance `d{id}`, `formula` of its child's distance and
    /// `args`; colour and trap stay the child's.
    pub(super) fn map_distance(
        &mut self,
        id: NodeId,
        child: Vars,
        args: &[Arg<'_>],
        formula: impl FnOnce(Var, &[Var]) -> Var,
    ) -> Vars {
        let mut all = vec![Arg::Value(&child.d)];
        all.extend_from_slice(args);
        let [d] = take(self.inline(&all, &[Shape::Scalar], |a| vec![formula(a[0], &a[1..])]));
        let name = format!("d{}", id.index());
        self.w.declare(Ty::Real, &name, &d);
        Vars { d: name, ..child }
    }

    /// Leaving a union tree entered as one: its other operands' results and
    /// its groups' combined, pairwise, under the names of its union nodes.
    pub(super) fn combine(
        &mut self,
        id: NodeId,
        cluster: Cluster,
        children: Vec<Vars>,
        needs_color: bool,
    ) -> Vars {
        self.label(id);
        let mut groups = cluster.groups;
        // Only the distance: each group's loop starts from the minimum of
        // the operands before it (a floor, other groups), and its walk
        // skips every box beyond that from the start.
        let (min, _) = self.w.min_max();
        let mut bound = children
            .iter()
            .map(|c| c.d.clone())
            .reduce(|a, b| format!("{min}({a}, {b})"));
        for group in cluster.pending {
            let v = self.instance_loop(group, &cluster.p, needs_color, bound.as_deref());
            bound = Some(v.d.clone());
            groups.push(v);
        }
        let mut results = children.into_iter().chain(groups);
        let mut acc = results.next().expect("a union tree has an operand");
        for (union, next) in cluster.unions.into_iter().zip(results) {
            acc = self.csg(union, CsgOp::Union, None, &acc, &next, needs_color);
        }
        acc
    }

    /// A boolean of two results: the distance from [`sdf::csg`], and the
    /// nearer operand's colour and trap, blended across a smooth seam, as
    /// `cpu::combine` computes them.
    pub(super) fn csg(
        &mut self,
        id: NodeId,
        op: CsgOp,
        k: Option<Scalar>,
        a: &Vars,
        b: &Vars,
        needs_color: bool,
    ) -> Vars {
        let v = vars(id);
        // A cut shows its first operand's surface and trap everywhere.
        let surface = self.shade && op != CsgOp::Cut;
        let mut args = vec![Arg::Value(&a.d), Arg::Value(&b.d)];
        args.extend(k.map(Arg::Scalar));
        let blended = surface && k.is_some();
        let mut results = vec![Shape::Scalar];
        if surface {
            results.push(Shape::Scalar);
        }
        if blended {
            results.push(Shape::Scalar);
        }
        let mut out = self
            .inline(&args, &results, |x| {
                let c = sdf::csg(op, x[0], x[1], x.get(2).copied());
                let mut r = vec![c.distance];
                if surface {
                    r.push(c.first_nearer.value());
                }
                if blended {
                    r.push(c.blend);
                }
                r
            })
            .into_iter();
        let d = out.next().expect("a boolean has a distance");
        self.w.declare(Ty::Real, &v.d, &d);
        if !self.shade {
            return v;
        }
        if op == CsgOp::Cut {
            return Vars {
                d: v.d,
                c: a.c.clone(),
                t: a.t.clone(),
            };
        }
        let near = out
            .next()
            .expect("a shaded boolean says which operand is nearer");
        let blend = out.next();
        let c = if needs_color {
            let ty = self.surface_type();
            self.choose(ty, &v.c, &near, (&a.c, &b.c), blend.as_deref())
        } else {
            v.c
        };
        let t = if self.traps() {
            self.choose(Ty::Real2, &v.t, &near, (&a.t, &b.t), blend.as_deref())
        } else {
            self.w.real("1.0")
        };
        Vars { d: v.d, c, t }
    }

    /// The colour or trap of a boolean: the nearer operand's, blended
    /// towards the other's by `blend` across a smooth seam, as
    /// `cpu::combine` computes it. Equal operands need no code (the blend
    /// of a value with itself is that value).
    pub(super) fn choose(
        &mut self,
        ty: Ty,
        var: &str,
        near: &str,
        (a, b): (&str, &str),
        blend: Option<&str>,
    ) -> String {
        if a == b {
            return a.to_string();
        }
        let (first, second) = match blend {
            Some(m) => (self.w.mix(ty, a, b, m), self.w.mix(ty, b, a, m)),
            None => (a.to_string(), b.to_string()),
        };
        let value = self.w.select_typed(ty, near, &first, &second);
        self.w.declare(ty, var, &value);
        var.to_string()
    }
}
