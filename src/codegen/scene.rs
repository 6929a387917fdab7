//! Emits a scene's distance functions from the IR: straight-line code, one
//! block per node, children before parents. The same walk writes `DE`
//! (distance only) and `DE_shade` (distance, colour and orbit trap).

use std::collections::{BTreeMap, BTreeSet};

use super::writer::Writer;
use crate::cpu::integer_power;
use crate::ir::{Ir, NodeId, Scalar};
use crate::quality::Precision;
use crate::scene::{CsgOp, CustomShape, Kind};

/// The variables holding one node's result.
struct Vars {
    d: String,
    c: String,
    t: String,
}

pub(crate) struct SceneEmitter<'a> {
    ir: &'a Ir,
    /// For a program in the scene's local frame: the translation it
    /// leaves out (see `Ir::local_frame`).
    frame: Option<NodeId>,
    w: &'a mut Writer,
    shade: bool,
    points: usize,
    iteration_override: Option<u32>,
    /// Names of the helper functions the emitted code calls.
    pub(crate) used: BTreeSet<&'static str>,
    /// The custom shapes the emitted code calls, by name.
    pub(crate) customs: BTreeMap<String, CustomShape>,
    /// The integer Mandelbulb powers that need a specialised helper.
    pub(crate) powers: BTreeSet<u32>,
}

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
            points: 0,
            iteration_override,
            used: BTreeSet::new(),
            customs: BTreeMap::new(),
            powers: BTreeSet::new(),
        }
    }

    /// Writes `DE` and `DE_shade`.
    pub(crate) fn emit(&mut self) {
        for shade in [false, true] {
            self.shade = shade;
            self.points = 0;
            if shade {
                self.w.open(
                    "real DE_shade(real3 p0, __global const real* params, real3* color, real* trap)",
                );
            } else {
                self.w
                    .open("real DE(real3 p0, __global const real* params)");
            }
            let out = self.node(self.ir.root(), "p0");
            if shade {
                self.w.line(format!("*color = {};", out.c));
                self.w.line(format!("*trap = {};", out.t));
            }
            self.w.line(format!("return {};", out.d));
            self.w.close();
            self.w.line("");
        }
    }

    fn point(&mut self, expr: String) -> String {
        self.points += 1;
        let name = format!("p{}", self.points);
        self.w.line(format!("real3 {name} = {expr};"));
        name
    }

    /// A fractal's iteration count under [`Quality::fractal_iterations`]
    /// (a cap), kept within the fractal's valid range.
    ///
    /// [`Quality::fractal_iterations`]: crate::quality::Quality::fractal_iterations
    fn iterations(&self, own: u32, (min, max): (u32, u32)) -> u32 {
        self.iteration_override
            .map_or(own, |cap| own.min(cap).clamp(min, max))
    }

    /// A leaf: its distance expression, default colour, trap 1.
    fn leaf(&mut self, id: NodeId, helper: &'static str, expr: String) -> Vars {
        if !helper.is_empty() {
            self.used.insert(helper);
        }
        let v = vars(id);
        self.w.line(format!("real {} = {expr};", v.d));
        if self.shade {
            self.w.line(format!("real3 {} = DEFAULT_COLOR;", v.c));
            self.w.line(format!("real {} = R(1.0);", v.t));
        }
        v
    }

    /// A fractal: the helper writes the trap through a pointer.
    fn fractal(&mut self, id: NodeId, helper: &'static str, args: String) -> Vars {
        self.used.insert(helper);
        self.fractal_call(id, helper, &args)
    }

    /// A call of a fractal function (library or specialised).
    fn fractal_call(&mut self, id: NodeId, function: &str, args: &str) -> Vars {
        let v = vars(id);
        self.w.line(format!("real {};", v.t));
        self.w
            .line(format!("real {} = {function}({args}, &{});", v.d, v.t));
        if self.shade {
            self.w.line(format!("real3 {} = DEFAULT_COLOR;", v.c));
        }
        v
    }

    /// A node that changes only the child's distance, by `expr` of `{d}`.
    fn post(&mut self, id: NodeId, child: Vars, expr: &str) -> Vars {
        let d = format!("d{}", id.index());
        self.w
            .line(format!("real {d} = {};", expr.replace("{d}", &child.d)));
        Vars { d, ..child }
    }

    #[allow(clippy::too_many_lines)]
    fn node(&mut self, id: NodeId, p: &str) -> Vars {
        let ir = self.ir;
        if self.frame == Some(id) {
            if let Kind::Translate { child, .. } = ir.node(id) {
                return self.node(*child, p);
            }
        }
        let w = |this: &Self, s: Scalar| this.w.scalar(s);
        let v3 = |this: &Self, v: [Scalar; 3]| this.w.vector(v);
        match ir.node(id) {
            Kind::Sphere { radius } => {
                let e = format!("sd_sphere({p}, {})", w(self, *radius));
                self.leaf(id, "sphere", e)
            }
            Kind::Cuboid { half_extents } => {
                let e = format!("sd_box({p}, {})", v3(self, *half_extents));
                self.leaf(id, "cuboid", e)
            }
            Kind::RoundBox {
                half_extents,
                radius,
            } => {
                let e = format!(
                    "sd_round_box({p}, {}, {})",
                    v3(self, *half_extents),
                    w(self, *radius)
                );
                self.leaf(id, "round_box", e)
            }
            Kind::Torus {
                major_radius,
                minor_radius,
            } => {
                let e = format!(
                    "sd_torus({p}, {}, {})",
                    w(self, *major_radius),
                    w(self, *minor_radius)
                );
                self.leaf(id, "torus", e)
            }
            Kind::Cylinder {
                radius,
                half_height,
            } => {
                let e = format!(
                    "sd_cylinder({p}, {}, {})",
                    w(self, *radius),
                    w(self, *half_height)
                );
                self.leaf(id, "cylinder", e)
            }
            Kind::Capsule { a, b, radius } => {
                let e = format!(
                    "sd_capsule({p}, {}, {}, {})",
                    v3(self, *a),
                    v3(self, *b),
                    w(self, *radius)
                );
                self.leaf(id, "capsule", e)
            }
            Kind::Plane { normal, offset } => {
                let e = format!("sd_plane({p}, {}, {})", v3(self, *normal), w(self, *offset));
                self.leaf(id, "plane", e)
            }
            Kind::Octahedron { size } => {
                let e = format!("sd_octahedron({p}, {})", w(self, *size));
                self.leaf(id, "octahedron", e)
            }
            Kind::CappedCone {
                half_height,
                bottom_radius,
                top_radius,
            } => {
                let e = format!(
                    "sd_capped_cone({p}, {}, {}, {})",
                    w(self, *half_height),
                    w(self, *bottom_radius),
                    w(self, *top_radius)
                );
                self.leaf(id, "capped_cone", e)
            }
            Kind::Ellipsoid { radii } => {
                let e = format!("sd_ellipsoid({p}, {})", v3(self, *radii));
                self.leaf(id, "ellipsoid", e)
            }
            Kind::Mandelbulb(f) => {
                let n = self.iterations(f.iterations, (1, crate::scene::MAX_ESCAPE_ITERATIONS));
                // The escape radius: a literal when power and bailout are
                // baked, as the CPU computes it.
                let escape = match (f.power, f.bailout) {
                    (Scalar::Baked(p), Scalar::Baked(b)) => {
                        self.w.float(crate::cpu::sdf::escape_radius(p, b))
                    }
                    _ => format!(
                        "fmin({}, pow(MAGNITUDE_CAP, R(1.0) / {}))",
                        w(self, f.bailout),
                        w(self, f.power)
                    ),
                };
                // The radius of the ball that holds the set: a literal when
                // the power is baked, rounded as the CPU computes it.
                let ball = match f.power {
                    Scalar::Baked(p) => self.w.float(match self.w.precision() {
                        Precision::F32 => f64::from(crate::cpu::sdf::mandelbulb_radius(p as f32)),
                        Precision::F64 => crate::cpu::sdf::mandelbulb_radius(p),
                    }),
                    Scalar::Dynamic(_) => {
                        format!("pow(R(2.0), R(1.0) / ({} - R(1.0)))", w(self, f.power))
                    }
                };
                match integer_power(f.power) {
                    Some(power) => {
                        self.powers.insert(power);
                        let args = format!("{p}, {n}, {escape}, {ball}");
                        self.fractal_call(id, &super::power::helper_name(power), &args)
                    }
                    None => {
                        let args = format!("{p}, {}, {n}, {escape}, {ball}", w(self, f.power));
                        self.fractal(id, "mandelbulb", args)
                    }
                }
            }
            Kind::Menger(f) => {
                let n = self.iterations(f.iterations, (0, crate::scene::MAX_FOLD_ITERATIONS));
                let args = format!("{p}, {n}, {}", w(self, f.scale));
                self.fractal(id, "menger", args)
            }
            Kind::Julia(f) => {
                let n = self.iterations(f.iterations, (1, crate::scene::MAX_ESCAPE_ITERATIONS));
                let [cx, cy, cz, cw] = f.c.map(|s| w(self, s));
                let args = format!(
                    "{p}, (real4)({cx}, {cy}, {cz}, {cw}), {}, {n}, {}",
                    w(self, f.slice_w),
                    w(self, f.bailout)
                );
                self.fractal(id, "julia", args)
            }
            Kind::Sierpinski(f) => {
                let n = self.iterations(f.iterations, (0, crate::scene::MAX_FOLD_ITERATIONS));
                let args = format!("{p}, {n}, {}", w(self, f.scale));
                self.fractal(id, "sierpinski", args)
            }
            Kind::Translate { offset, child } => {
                let q = self.point(format!("{p} - {}", v3(self, *offset)));
                self.node(*child, &q)
            }
            Kind::Rotate { axis, angle, child } => {
                let q = match angle {
                    Scalar::Baked(a) => {
                        let rows = crate::cpu::rotation_rows(*axis, -a);
                        let [x, y, z] = rows.map(|r| self.dot_row([r.x, r.y, r.z], p));
                        self.point(format!("(real3)({x}, {y}, {z})"))
                    }
                    Scalar::Dynamic(_) => {
                        self.used.insert("rotate");
                        let k = v3(self, axis.to_array().map(Scalar::Baked));
                        let a = format!("-{}", w(self, *angle));
                        self.point(format!("rotate_axis({p}, {k}, {a})"))
                    }
                };
                self.node(*child, &q)
            }
            Kind::Scale { factor, child } => {
                let f = w(self, *factor);
                let q = self.point(format!("{p} / {f}"));
                let c = self.node(*child, &q);
                self.post(id, c, &format!("{{d}} * {f}"))
            }
            Kind::Mirror { axis, child } => {
                let q = self.point(p.to_string());
                let a = ["x", "y", "z"][axis.index()];
                self.w.line(format!("{q}.{a} = fabs({q}.{a});"));
                self.node(*child, &q)
            }
            Kind::Round { radius, child } => {
                let c = self.node(*child, p);
                let r = w(self, *radius);
                self.post(id, c, &format!("{{d}} - {r}"))
            }
            Kind::Onion { thickness, child } => {
                let c = self.node(*child, p);
                let t = w(self, *thickness);
                self.post(id, c, &format!("fabs({{d}}) - {t}"))
            }
            Kind::Elongate { extents, child } => {
                let h = v3(self, *extents);
                let q = self.point(format!("{p} - clamp({p}, -{h}, {h})"));
                self.node(*child, &q)
            }
            Kind::Repeat { period, child } => {
                let q = self.repeat(p, *period, None);
                self.node(*child, &q)
            }
            Kind::RepeatLimited {
                period,
                limit,
                child,
            } => {
                let q = self.repeat(p, *period, Some(*limit));
                self.node(*child, &q)
            }
            Kind::Twist { rate, child } => {
                let k = w(self, *rate);
                let i = id.index();
                self.w.line(format!("real s{i} = sin({k} * {p}.y);"));
                self.w.line(format!("real k{i} = cos({k} * {p}.y);"));
                let q = self.point(format!(
                    "(real3)(k{i} * {p}.x - s{i} * {p}.z, {p}.y, s{i} * {p}.x + k{i} * {p}.z)"
                ));
                let c = self.node(*child, &q);
                self.used.insert("warp");
                let rho = format!("hypot({p}.x, {p}.z)");
                self.post(id, c, &format!("twist_bound({{d}}, {k}, {rho})"))
            }
            Kind::Bend { rate, child } => {
                let k = w(self, *rate);
                let i = id.index();
                self.w.line(format!("real s{i} = sin({k} * {p}.x);"));
                self.w.line(format!("real k{i} = cos({k} * {p}.x);"));
                let q = self.point(format!(
                    "(real3)(k{i} * {p}.x - s{i} * {p}.y, s{i} * {p}.x + k{i} * {p}.y, {p}.z)"
                ));
                let c = self.node(*child, &q);
                self.used.insert("warp");
                let rho = format!("hypot({p}.x, {p}.y)");
                self.post(id, c, &format!("bend_bound({{d}}, {k}, {rho})"))
            }
            Kind::Csg {
                op,
                smoothing,
                a,
                b,
            } => {
                let (a, b) = (self.node(*a, p), self.node(*b, p));
                self.csg(id, *op, *smoothing, &a, &b)
            }
            Kind::Custom { shape, args } => {
                let mut call = format!("{}({p}", shape.function_name());
                for a in args {
                    call.push_str(", ");
                    call.push_str(&w(self, *a));
                }
                call.push(')');
                self.customs.insert(shape.name().to_string(), shape.clone());
                self.leaf(id, "", call)
            }
            Kind::Color { color, child } => {
                let c = self.node(*child, p);
                if !self.shade {
                    return c;
                }
                let v = vars(id);
                self.w
                    .line(format!("real3 {} = {};", v.c, v3(self, *color)));
                Vars { c: v.c, ..c }
            }
        }
    }

    /// `row · p` as the CPU's `dot_row` computes it: non-zero terms, left to
    /// right; `±1` entries need no multiplication.
    fn dot_row(&self, row: [f64; 3], p: &str) -> String {
        let mut sum = String::new();
        for (a, axis) in row.into_iter().zip(["x", "y", "z"]) {
            if a == 0.0 {
                continue;
            }
            let term = match a {
                1.0 => format!("{p}.{axis}"),
                -1.0 => format!("-{p}.{axis}"),
                _ => format!("{} * {p}.{axis}", self.w.float(a)),
            };
            if sum.is_empty() {
                sum = term;
            } else if let Some(negated) = term.strip_prefix('-') {
                sum = format!("{sum} - {negated}");
            } else {
                sum = format!("{sum} + {term}");
            }
        }
        if sum.is_empty() { "R(0.0)".into() } else { sum }
    }

    /// Folds `p` into a repetition cell, axis by axis, as `cpu::repeat` does.
    fn repeat(&mut self, p: &str, period: [Scalar; 3], limit: Option<[u32; 3]>) -> String {
        let q = self.point(p.to_string());
        for (i, axis) in ["x", "y", "z"].into_iter().enumerate() {
            let c = self.w.scalar(period[i]);
            let mut cell = format!("round({p}.{axis} / {c})");
            if let Some(l) = limit {
                let l = self.w.float(f64::from(l[i]));
                cell = format!("clamp({cell}, -{l}, {l})");
            }
            let fold = format!("{p}.{axis} - {c} * {cell}");
            match period[i] {
                Scalar::Baked(v) if v > 0.0 => self.w.line(format!("{q}.{axis} = {fold};")),
                Scalar::Baked(_) => {}
                Scalar::Dynamic(_) => self
                    .w
                    .line(format!("{q}.{axis} = {c} > R(0.0) ? {fold} : {p}.{axis};")),
            }
        }
        q
    }

    /// Every boolean is a (smooth) minimum of signed operands, as in
    /// `cpu::combine`.
    fn csg(&mut self, id: NodeId, op: CsgOp, k: Option<Scalar>, a: &Vars, b: &Vars) -> Vars {
        let i = id.index();
        let (x, y) = match op {
            CsgOp::Union => (a.d.clone(), b.d.clone()),
            CsgOp::Subtract => (format!("-{}", a.d), b.d.clone()),
            CsgOp::Intersect => (format!("-{}", a.d), format!("-{}", b.d)),
        };
        let sign = if op == CsgOp::Union { "" } else { "-" };
        let v = vars(id);
        self.w.line(format!("real x{i} = {x};"));
        self.w.line(format!("real y{i} = {y};"));
        match k {
            Some(k) => {
                self.used.insert("smooth_min");
                let k = self.w.scalar(k);
                self.w
                    .line(format!("real2 m{i} = smooth_min(x{i}, y{i}, {k});"));
                self.w.line(format!("real {} = {sign}m{i}.x;", v.d));
                if self.shade {
                    let mix = |u: &str, w: &str| format!("mix({u}, {w}, m{i}.y)");
                    self.w.line(format!(
                        "real3 {} = x{i} < y{i} ? {} : {};",
                        v.c,
                        mix(&a.c, &b.c),
                        mix(&b.c, &a.c)
                    ));
                    self.w.line(format!(
                        "real {} = x{i} < y{i} ? {} : {};",
                        v.t,
                        mix(&a.t, &b.t),
                        mix(&b.t, &a.t)
                    ));
                }
            }
            None => {
                self.w
                    .line(format!("real {} = {sign}fmin(x{i}, y{i});", v.d));
                if self.shade {
                    self.w
                        .line(format!("real3 {} = x{i} < y{i} ? {} : {};", v.c, a.c, b.c));
                    self.w
                        .line(format!("real {} = x{i} < y{i} ? {} : {};", v.t, a.t, b.t));
                }
            }
        }
        v
    }
}

fn vars(id: NodeId) -> Vars {
    let i = id.index();
    Vars {
        d: format!("d{i}"),
        c: format!("c{i}"),
        t: format!("t{i}"),
    }
}
