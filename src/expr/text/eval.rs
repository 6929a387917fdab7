//! Running a parsed formula in any number type: values, scopes, masks for
//! branches and breaks, loops as bounded loops of the program.

use std::collections::HashMap;

use super::Formula;
use super::parse::{Block, Expr, Stmt, start};
use super::{FUNCTIONS, MAX_ITERATIONS};
use crate::expr::num::Num;
use crate::expr::num::Step;
use crate::expr::{V3, v3};

/// A value while a formula runs.
#[derive(Debug, Clone, Copy)]
pub(super) enum Value<N: Num> {
    Number(N),
    Vector(V3<N>),
    Truth(N::Bool),
}

impl<N: Num> Value<N> {
    pub(super) fn kind(&self) -> &'static str {
        match self {
            Value::Number(_) => "a number",
            Value::Vector(_) => "a vector",
            Value::Truth(_) => "a truth value",
        }
    }

    fn select(c: N::Bool, a: Self, b: Self) -> Option<Self> {
        Some(match (a, b) {
            (Value::Number(x), Value::Number(y)) => Value::Number(N::select(c, x, y)),
            (Value::Vector(x), Value::Vector(y)) => Value::Vector(V3::select(c, x, y)),
            (Value::Truth(x), Value::Truth(y)) => Value::Truth((c & x) | (!c & y)),
            _ => return None,
        })
    }
}

pub(super) struct Run<'f, N: Num> {
    pub(super) formula: &'f Formula,
    pub(super) vars: Vec<HashMap<String, Value<N>>>,
    /// Where assignments take effect: everywhere (`None`), or where the
    /// truth value holds (inside an `if` or a loop that may have broken).
    pub(super) mask: Option<N::Bool>,
    pub(super) iterations: u64,
}

pub(super) type Eval<T> = Result<T, (usize, String)>;

impl<N: Num> Run<'_, N> {
    fn lookup(&self, name: &str) -> Option<Value<N>> {
        self.vars.iter().rev().find_map(|s| s.get(name).copied())
    }

    pub(super) fn block(&mut self, b: &Block) -> Eval<Option<Value<N>>> {
        self.vars.push(HashMap::new());
        let result = self.block_in_scope(b);
        self.vars.pop();
        result
    }

    fn block_in_scope(&mut self, b: &Block) -> Eval<Option<Value<N>>> {
        for s in &b.stmts {
            self.stmt(s)?;
        }
        b.value.as_ref().map(|e| self.expr(e)).transpose()
    }

    fn assign(&mut self, name: &str, v: Value<N>, at: usize) -> Eval<()> {
        let old = self.lookup(name).ok_or_else(|| {
            (
                at,
                format!("`{name}` is not defined; define it first with `let {name} = ...;`"),
            )
        })?;
        let frame = self
            .vars
            .iter()
            .rposition(|s| s.contains_key(name))
            .unwrap_or(0);
        if frame == 0 {
            return Err((at, format!("`{name}` is an input and cannot be assigned")));
        }
        let new = match self.mask {
            None => match (old, v) {
                (Value::Number(_), Value::Number(_))
                | (Value::Vector(_), Value::Vector(_))
                | (Value::Truth(_), Value::Truth(_)) => v,
                _ => return Err(mismatch(at, name, old, v)),
            },
            Some(m) => Value::select(m, v, old).ok_or_else(|| mismatch(at, name, old, v))?,
        };
        self.vars[frame].insert(name.to_string(), new);
        Ok(())
    }

    fn stmt(&mut self, s: &Stmt) -> Eval<()> {
        match s {
            Stmt::Let(name, e, at) => {
                if matches!(name.as_str(), "p" | "pi") || self.formula.params.contains(name) {
                    return Err((*at, format!("`{name}` is an input; choose another name")));
                }
                let v = self.expr(e)?;
                self.vars
                    .last_mut()
                    .expect("a block has a scope")
                    .insert(name.clone(), v);
            }
            Stmt::Assign(name, e, at) => {
                let v = self.expr(e)?;
                self.assign(name, v, *at)?;
            }
            Stmt::If(c, a, b) => {
                let c = self.truth(c)?;
                let outer = self.mask;
                self.mask = Some(outer.map_or(c, |m| m & c));
                self.block(a)?;
                self.mask = Some(outer.map_or(!c, |m| m & !c));
                self.block(b)?;
                self.mask = outer;
            }
            Stmt::For(name, from, to, body, at) => self.for_loop(name, *from, *to, body, *at)?,
            Stmt::BreakIf(c, at) => {
                if !self.in_loop(*at) {
                    return Err((
                        *at,
                        "`break if` is only allowed directly in a loop's body".into(),
                    ));
                }
                let c = self.truth(c)?;
                self.mask = Some(self.mask.map_or(!c, |m| m & !c));
            }
        }
        Ok(())
    }

    /// A `for` loop, as one bounded loop of the program: its state is
    /// every variable from outside that the body assigns, and a `break if`
    /// ends it after the step (the assignments after the break in that
    /// step do not happen).
    fn for_loop(&mut self, name: &str, from: i64, to: i64, body: &Block, at: usize) -> Eval<()> {
        let count = u64::try_from((to - from).max(0)).unwrap_or(0);
        let outer_iterations = self.iterations;
        self.iterations = outer_iterations.max(1).saturating_mul(count.max(1));
        if self.iterations > MAX_ITERATIONS {
            return Err((
                at,
                format!(
                    "the loop runs {} steps in all (counting the loops around it); the most \
                     is {MAX_ITERATIONS}",
                    self.iterations
                ),
            ));
        }
        let mut names = Vec::new();
        assigned(&body.stmts, &mut names);
        let state: Vec<(String, Value<N>)> = names
            .into_iter()
            .filter_map(|n| {
                let v = self.lookup(&n)?;
                let input = self.vars.iter().rposition(|s| s.contains_key(&n)) == Some(0);
                (!input).then_some((n, v))
            })
            .collect();
        let kinds: Vec<Value<N>> = state.iter().map(|(_, v)| *v).collect();
        let init = flatten(&kinds);
        let outer_mask = self.mask.take();
        let mut failed = None;
        #[allow(clippy::cast_precision_loss)] // |from| <= 1e6
        let start = N::of(from as f64);
        let result = N::iterate_dyn(N::of(count as f64), init, &mut |i, values: &[N]| {
            let mut frame = HashMap::new();
            for ((n, _), v) in state.iter().zip(unflatten(&kinds, values)) {
                frame.insert(n.clone(), v);
            }
            self.vars.push(frame);
            self.vars.push(HashMap::from([(
                name.to_string(),
                Value::Number(start + i),
            )]));
            self.mask = None;
            let run = self.block(body);
            self.vars.pop();
            let frame = self.vars.pop().expect("pushed above");
            let next: Vec<Value<N>> = state
                .iter()
                .map(|(n, old)| frame.get(n).copied().unwrap_or(*old))
                .collect();
            let broke = self.mask.take().map(|m| !m);
            if let Err(e) = run {
                failed.get_or_insert(e);
            }
            Step {
                stop_before: None,
                next: flatten(&next),
                stop_after: broke,
            }
        });
        self.mask = outer_mask;
        self.iterations = outer_iterations;
        if let Some(e) = failed {
            return Err(e);
        }
        for ((n, _), v) in state.iter().zip(unflatten(&kinds, &result)) {
            self.assign(n, v, at)?;
        }
        Ok(())
    }

    /// Whether `at` lies directly within a loop's body.
    fn in_loop(&self, at: usize) -> bool {
        fn within(stmts: &[Stmt], at: usize, looped: bool) -> Option<bool> {
            for s in stmts {
                match s {
                    Stmt::BreakIf(_, a) if *a == at => return Some(looped),
                    Stmt::For(_, _, _, b, _) => {
                        if let Some(r) = within(&b.stmts, at, true) {
                            return Some(r);
                        }
                    }
                    // A break inside an `if` is refused: the loop's body
                    // breaks where it says so, unconditionally placed.
                    Stmt::If(_, a, b) => {
                        if let Some(r) =
                            within(&a.stmts, at, false).or_else(|| within(&b.stmts, at, false))
                        {
                            return Some(r);
                        }
                    }
                    _ => {}
                }
            }
            None
        }
        within(&self.formula.body.stmts, at, false).unwrap_or(false)
    }

    fn truth(&mut self, e: &Expr) -> Eval<N::Bool> {
        match self.expr(e)? {
            Value::Truth(b) => Ok(b),
            v => Err((
                start(e),
                format!("expected a truth value (a comparison), found {}", v.kind()),
            )),
        }
    }

    fn expr(&mut self, e: &Expr) -> Eval<Value<N>> {
        Ok(match e {
            Expr::Num(v) => Value::Number(N::of(*v)),
            Expr::Name(name, at) => self.lookup(name).ok_or_else(|| {
                let mut known: Vec<String> = vec!["p".into()];
                known.extend(self.formula.params.iter().cloned());
                known.push("pi".into());
                for s in self.vars.iter().skip(1) {
                    known.extend(s.keys().cloned());
                }
                (
                    *at,
                    format!(
                        "unknown variable `{name}`; expected one of {}",
                        known.join(", ")
                    ),
                )
            })?,
            Expr::Neg(a) => match self.expr(a)? {
                Value::Number(n) => Value::Number(-n),
                Value::Vector(v) => Value::Vector(-v),
                Value::Truth(_) => {
                    return Err((start(a), "cannot negate a truth value; use `!`".into()));
                }
            },
            Expr::Not(a) => Value::Truth(!self.truth(a)?),
            Expr::Field(a, i, _) => match self.expr(a)? {
                Value::Vector(v) => Value::Number(v.get(*i)),
                v => {
                    return Err((
                        start(a),
                        format!("`.x`, `.y`, `.z` need a vector, found {}", v.kind()),
                    ));
                }
            },
            Expr::Binary(op, a, b, at) => {
                let (x, y) = (self.expr(a)?, self.expr(b)?);
                binary(op, x, y).ok_or_else(|| {
                    (
                        *at,
                        format!("`{op}` cannot combine {} and {}", x.kind(), y.kind()),
                    )
                })?
            }
            Expr::If(c, a, b, at) => {
                let c = self.truth(c)?;
                let outer = self.mask;
                self.mask = Some(outer.map_or(c, |m| m & c));
                let x = self.block(a);
                self.mask = Some(outer.map_or(!c, |m| m & !c));
                let y = self.block(b);
                self.mask = outer;
                let (x, y) = (x?, y?);
                match (x, y) {
                    (Some(x), Some(y)) => Value::select(c, x, y).ok_or_else(|| {
                        (
                            *at,
                            format!("the branches give {} and {}", x.kind(), y.kind()),
                        )
                    })?,
                    _ => {
                        return Err((
                            *at,
                            "an `if` used as a value needs a value in both branches".into(),
                        ));
                    }
                }
            }
            Expr::Call(name, args, at) => {
                let Some(&(_, arity)) = FUNCTIONS.iter().find(|(f, _)| f == name) else {
                    let names: Vec<&str> = FUNCTIONS.iter().map(|(f, _)| *f).collect();
                    return Err((
                        *at,
                        format!(
                            "unknown function `{name}`; expected one of {}",
                            names.join(", ")
                        ),
                    ));
                };
                if args.len() != arity {
                    return Err((
                        *at,
                        format!("`{name}` takes {arity} argument(s), got {}", args.len()),
                    ));
                }
                let values: Vec<Value<N>> =
                    args.iter().map(|a| self.expr(a)).collect::<Eval<_>>()?;
                call(name, &values).ok_or_else(|| {
                    let kinds: Vec<&str> = values.iter().map(Value::kind).collect();
                    (*at, format!("`{name}` cannot take {}", kinds.join(", ")))
                })?
            }
        })
    }
}

/// The names assigned in `stmts`, nested blocks included, each once.
fn assigned(stmts: &[Stmt], out: &mut Vec<String>) {
    for s in stmts {
        match s {
            Stmt::Assign(n, ..) if !out.contains(n) => out.push(n.clone()),
            Stmt::If(_, a, b) => {
                assigned(&a.stmts, out);
                assigned(&b.stmts, out);
            }
            Stmt::For(_, _, _, b, _) => assigned(&b.stmts, out),
            _ => {}
        }
    }
}

/// Values as the numbers of a loop's state: a truth value as 1 or 0.
fn flatten<N: Num>(values: &[Value<N>]) -> Vec<N> {
    let mut out = Vec::new();
    for v in values {
        match v {
            Value::Number(n) => out.push(*n),
            Value::Vector(v) => out.extend([v.x, v.y, v.z]),
            Value::Truth(b) => out.push(N::select(*b, N::one(), N::zero())),
        }
    }
    out
}

/// The values of the kinds of `like` from a loop's state.
fn unflatten<N: Num>(like: &[Value<N>], numbers: &[N]) -> Vec<Value<N>> {
    let mut at = 0;
    like.iter()
        .map(|v| match v {
            Value::Number(_) => {
                at += 1;
                Value::Number(numbers[at - 1])
            }
            Value::Vector(_) => {
                at += 3;
                Value::Vector(v3(numbers[at - 3], numbers[at - 2], numbers[at - 1]))
            }
            Value::Truth(_) => {
                at += 1;
                Value::Truth(numbers[at - 1].gt(N::of(0.5)))
            }
        })
        .collect()
}

fn mismatch<N: Num>(at: usize, name: &str, old: Value<N>, new: Value<N>) -> (usize, String) {
    (
        at,
        format!(
            "`{name}` holds {}; it cannot be given {}",
            old.kind(),
            new.kind()
        ),
    )
}

fn binary<N: Num>(op: &str, x: Value<N>, y: Value<N>) -> Option<Value<N>> {
    use Value::{Number as S, Truth as B, Vector as V};
    Some(match (op, x, y) {
        ("+", S(a), S(b)) => S(a + b),
        ("-", S(a), S(b)) => S(a - b),
        ("*", S(a), S(b)) => S(a * b),
        ("/", S(a), S(b)) => S(a / b),
        ("+", V(a), V(b)) => V(a + b),
        ("-", V(a), V(b)) => V(a - b),
        ("*", V(a), V(b)) => V(a * b),
        ("/", V(a), V(b)) => V(a / b),
        ("*", V(a), S(b)) => V(a * b),
        ("*", S(a), V(b)) => V(b * a),
        ("/", V(a), S(b)) => V(a / b),
        ("<", S(a), S(b)) => B(a.lt(b)),
        ("<=", S(a), S(b)) => B(a.le(b)),
        (">", S(a), S(b)) => B(a.gt(b)),
        (">=", S(a), S(b)) => B(a.ge(b)),
        ("==", S(a), S(b)) => B(a.le(b) & b.le(a)),
        ("!=", S(a), S(b)) => B(a.lt(b) | b.lt(a)),
        ("&&", B(a), B(b)) => B(a & b),
        ("||", B(a), B(b)) => B(a | b),
        _ => return None,
    })
}

fn call<N: Num>(name: &str, a: &[Value<N>]) -> Option<Value<N>> {
    use Value::{Number as S, Vector as V};
    let map = |v: V3<N>, f: fn(N) -> N| V(v.map(f));
    Some(match (name, a) {
        ("sqrt", [S(x)]) => S(x.sqrt()),
        ("abs", [S(x)]) => S(x.abs()),
        ("abs", [V(v)]) => V(v.abs()),
        ("sin", [S(x)]) => S(x.sin()),
        ("cos", [S(x)]) => S(x.cos()),
        ("acos", [S(x)]) => S(x.acos()),
        ("exp", [S(x)]) => S(x.exp()),
        ("log", [S(x)]) => S(x.ln()),
        ("floor", [S(x)]) => S(x.floor()),
        ("floor", [V(v)]) => map(*v, N::floor),
        ("round", [S(x)]) => S(x.round()),
        ("round", [V(v)]) => map(*v, N::round),
        ("fract", [S(x)]) => S(x.fract()),
        ("fract", [V(v)]) => map(*v, N::fract),
        ("min", [S(x), S(y)]) => S(x.min(*y)),
        ("max", [S(x), S(y)]) => S(x.max(*y)),
        ("min", [V(x), V(y)]) => V(x.zip(*y, N::min)),
        ("max", [V(x), V(y)]) => V(x.zip(*y, N::max)),
        ("max", [V(x), S(y)]) => V(x.max_s(*y)),
        ("atan2", [S(y), S(x)]) => S(y.atan2(*x)),
        ("pow", [S(x), S(y)]) => S(x.powf(*y)),
        ("hypot", [S(x), S(y)]) => S(x.hypot(*y)),
        ("clamp", [S(x), S(lo), S(hi)]) => S(x.clamp(*lo, *hi)),
        ("mix", [S(x), S(y), S(t)]) => S(x.mix(*y, *t)),
        ("mix", [V(x), V(y), S(t)]) => V(*x + (*y - *x) * *t),
        ("length", [V(v)]) => S(v.length()),
        ("dot", [V(x), V(y)]) => S(x.dot(*y)),
        ("cross", [V(x), V(y)]) => V(x.cross(*y)),
        ("normalize", [V(v)]) => V(*v / v.length()),
        ("vec3", [S(x), S(y), S(z)]) => V(v3(*x, *y, *z)),
        _ => return None,
    })
}
