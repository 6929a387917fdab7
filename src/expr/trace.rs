//! Tracing: running a formula on [`Var`]s records it as a [`Program`],
//! folding literals and exact identities as it goes and sharing common
//! subexpressions on one tape.

use std::cell::RefCell;
use std::collections::HashMap;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use super::num::{Logic, Num, Step, binary, unary};
use super::ops::{Binary, Unary};
use super::program::*;

/// The operations recorded so far, with one place per distinct operation.
#[derive(Debug, Default)]
struct Tape {
    ops: Vec<Op>,
    loops: Vec<Loop>,
    seen: HashMap<Key, ValueId>,
}

impl Tape {
    fn push(&mut self, op: Op) -> ValueId {
        let op = match self.fold(op) {
            Folded::Value(v) => return v,
            Folded::Op(op) => op,
        };
        let key = op.key();
        if let Some(&v) = self.seen.get(&key) {
            return v;
        }
        let v = ValueId(u32::try_from(self.ops.len()).expect("fewer than 2^32 operations"));
        self.ops.push(op);
        self.seen.insert(key, v);
        v
    }
}

/// An operation after constant folding: another operation to record, or
/// a value already on the tape.
enum Folded {
    Op(Op),
    Value(ValueId),
}

/// The largest literal folding writes: one every precision can hold.
const FOLD_LIMIT: f64 = f32::MAX as f64;

impl Tape {
    /// The literal value `v` holds, if it is one.
    fn constant(&self, v: ValueId) -> Option<f64> {
        match self.ops[v.index()] {
            Op::Const(c) => Some(c),
            _ => None,
        }
    }

    /// The literal every component of `v` holds, for a number or a
    /// vector made of one literal.
    fn uniform(&self, v: ValueId) -> Option<f64> {
        match self.ops[v.index()] {
            Op::Const(c) => Some(c),
            Op::Make3(x, y, z) if x == y && y == z => self.constant(x),
            _ => None,
        }
    }

    /// The operand an exact identity leaves of `x op y`: `x · 1`, `1 · y`,
    /// `x / 1` and `x − (+0)` equal their other operand for every value,
    /// NaN and signed zeros included.
    fn identity(&self, op: Binary, x: ValueId, y: ValueId) -> Option<ValueId> {
        let is = |v: ValueId, c: f64| self.uniform(v).is_some_and(|u| u.to_bits() == c.to_bits());
        match op {
            Binary::Mul if is(y, 1.0) => Some(x),
            Binary::Mul if is(x, 1.0) => Some(y),
            Binary::Div if is(y, 1.0) => Some(x),
            Binary::Sub if is(y, 0.0) => Some(x),
            _ => None,
        }
    }

    /// The truth value `v` holds, if literals decide it.
    fn truth(&self, v: ValueId) -> Option<bool> {
        let c = |v| self.constant(v);
        match self.ops[v.index()] {
            Op::Binary(Binary::Lt, x, y) => Some(c(x)? < c(y)?),
            Op::Binary(Binary::Le, x, y) => Some(c(x)? <= c(y)?),
            Op::Binary(Binary::And, x, y) => Some(self.truth(x)? && self.truth(y)?),
            Op::Binary(Binary::Or, x, y) => Some(self.truth(x)? || self.truth(y)?),
            Op::Unary(Unary::Not, a) => Some(!self.truth(a)?),
            Op::Unary(Unary::Finite, a) => Some(c(a)?.is_finite()),
            _ => None,
        }
    }

    /// Folds an operation on literals to a literal (computed in `f64`,
    /// kept only when it is finite and fits every precision), and a
    /// selection on a decided truth value to the chosen value: a formula
    /// traced with baked parameters prints only the code they leave.
    fn fold(&self, op: Op) -> Folded {
        let literal = |v: f64| {
            if v.is_finite() && v.abs() <= FOLD_LIMIT {
                Some(Op::Const(v))
            } else {
                None
            }
        };
        let folded = match op {
            Op::Unary(u, a) if !matches!(u, Unary::Not | Unary::Finite) => {
                self.constant(a).and_then(|a| literal(unary(u, a)))
            }
            Op::Binary(b, x, y) if !b.is_logic() => {
                if let Some(v) = self.identity(b, x, y) {
                    return Folded::Value(v);
                }
                match (self.constant(x), self.constant(y)) {
                    (Some(x), Some(y)) => literal(binary(b, x, y)),
                    _ => None,
                }
            }
            Op::Binary3(b, x, y) => {
                if let Some(v) = self.identity(b, x, y) {
                    return Folded::Value(v);
                }
                None
            }
            Op::Select(c, a, b) | Op::Select3(c, a, b) => {
                if let Some(t) = self.truth(c) {
                    return Folded::Value(if t { a } else { b });
                }
                None
            }
            _ => None,
        };
        Folded::Op(folded.unwrap_or(op))
    }
}

thread_local! {
    /// The tapes being recorded on this thread, innermost last: a loop's
    /// body is recorded on a tape of its own.
    static TAPES: RefCell<Vec<Tape>> = const { RefCell::new(Vec::new()) };
}

/// The depth of the innermost tape.
fn depth() -> u32 {
    TAPES.with(|t| u32::try_from(t.borrow().len()).unwrap_or(u32::MAX))
}

/// `v`'s place on the innermost tape: a value of an enclosing tape is
/// read through an [`Op::Capture`].
fn resolve(level: u32, id: ValueId) -> ValueId {
    let here = depth();
    assert!(
        level <= here && here > 0,
        "a traced value is used only inside expr::trace, and a loop's values only inside its body"
    );
    if level == here {
        id
    } else {
        push(Op::Capture(here - level, id))
    }
}

fn push(op: Op) -> ValueId {
    TAPES.with(|t| {
        t.borrow_mut()
            .last_mut()
            .expect("a traced value is used only inside expr::trace")
            .push(op)
    })
}

/// Records `op` on the innermost tape, as a value of that tape.
fn record(op: Op) -> Var {
    Var {
        level: depth(),
        id: push(op),
    }
}

/// A number being traced: running a formula on `Var`s records its
/// operations into a [`Program`] (see [`trace`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Var {
    level: u32,
    id: ValueId,
}

impl Var {
    /// Its place on the innermost tape.
    fn here(self) -> ValueId {
        resolve(self.level, self.id)
    }
}

/// A truth value being traced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VarBool(Var);

impl VarBool {
    /// The truth value as a traced value, to return from a program:
    /// printers write it as a condition (running the program reads it as
    /// NaN).
    #[must_use]
    pub fn value(self) -> Var {
        self.0
    }
}

/// Pops the innermost tape when dropped, so that a panic in a formula
/// leaves no tape behind.
struct Pop;

impl Drop for Pop {
    fn drop(&mut self) {
        TAPES.with(|t| t.borrow_mut().pop());
    }
}

/// Records `f` on a new tape with `inputs` inputs.
fn record_program(inputs: u32, f: impl FnOnce(&[Var]) -> Vec<ValueId>) -> Program {
    TAPES.with(|t| t.borrow_mut().push(Tape::default()));
    let guard = Pop;
    let args: Vec<Var> = (0..inputs).map(|i| record(Op::Input(i))).collect();
    let outputs = f(&args);
    let tape = TAPES.with(|t| std::mem::take(t.borrow_mut().last_mut().expect("pushed above")));
    drop(guard);
    Program {
        ops: tape.ops,
        inputs,
        outputs,
        loops: tape.loops,
    }
}

/// Records `f` run on `inputs` scalar inputs as a [`Program`] returning the
/// values `f` returns.
///
/// ```
/// use fractal_sdf::expr::{Num, trace};
/// let program = trace(2, |x| vec![(x[0] * x[0] + x[1] * x[1]).sqrt()]);
/// assert_eq!(program.run(&[3.0_f64, 4.0]), vec![5.0]);
/// ```
pub fn trace(inputs: u32, f: impl FnOnce(&[Var]) -> Vec<Var>) -> Program {
    record_program(inputs, |args| f(args).into_iter().map(Var::here).collect())
}

/// Records a loop: its body on a tape of its own, then the loop and its
/// final state on the enclosing tape.
fn record_loop(
    count: Var,
    init: &[Var],
    body: &mut dyn FnMut(Var, &[Var]) -> Step<Var>,
) -> Vec<Var> {
    let count = count.here();
    let init: Vec<ValueId> = init.iter().map(|v| v.here()).collect();
    let k = init.len();
    let (mut stop_before, mut stop_after) = (false, false);
    let inputs = u32::try_from(k + 1).expect("a loop's state is small");
    let body = record_program(inputs, |args| {
        let step = body(args[0], &args[1..]);
        let mut outputs: Vec<ValueId> = step.next.iter().map(|v| v.here()).collect();
        assert_eq!(outputs.len(), k, "a loop's body keeps the state's size");
        if let Some(b) = step.stop_before {
            stop_before = true;
            outputs.push(b.0.here());
        }
        if let Some(b) = step.stop_after {
            stop_after = true;
            outputs.push(b.0.here());
        }
        outputs
    });
    let index = TAPES.with(|t| {
        let mut tapes = t.borrow_mut();
        let tape = tapes
            .last_mut()
            .expect("a loop is traced inside expr::trace");
        tape.loops.push(Loop {
            count,
            init,
            body,
            stop_before,
            stop_after,
        });
        u32::try_from(tape.loops.len() - 1).expect("fewer than 2^32 loops")
    });
    let state = push(Op::Loop(index));
    (0..k)
        .map(|j| record(Op::Element(state, u32::try_from(j).unwrap_or(u32::MAX))))
        .collect()
}

/// The 3-vector of three traced numbers on the innermost tape: the vector
/// they are the components of, or a new one made of them.
fn vector(c: [Var; 3]) -> ValueId {
    let [x, y, z] = c.map(Var::here);
    let ops = TAPES.with(|t| {
        let tapes = t.borrow();
        let ops = &tapes.last().expect("traced inside expr::trace").ops;
        [x, y, z].map(|v| ops[v.index()])
    });
    if let [
        Op::Component(a, 0),
        Op::Component(b, 1),
        Op::Component(c, 2),
    ] = ops
        && a == b
        && b == c
    {
        return a;
    }
    push(Op::Make3(x, y, z))
}

/// The components of the vector `v` on the innermost tape.
fn components(v: ValueId) -> [Var; 3] {
    [0, 1, 2].map(|i| record(Op::Component(v, i)))
}

impl Logic for VarBool {}

impl BitAnd for VarBool {
    type Output = Self;
    fn bitand(self, o: Self) -> Self {
        VarBool(record(Op::Binary(Binary::And, self.0.here(), o.0.here())))
    }
}

impl BitOr for VarBool {
    type Output = Self;
    fn bitor(self, o: Self) -> Self {
        VarBool(record(Op::Binary(Binary::Or, self.0.here(), o.0.here())))
    }
}

impl Not for VarBool {
    type Output = Self;
    fn not(self) -> Self {
        VarBool(record(Op::Unary(Unary::Not, self.0.here())))
    }
}

macro_rules! var_binary {
    ($trait:ident, $method:ident, $op:ident) => {
        impl $trait for Var {
            type Output = Self;
            fn $method(self, o: Self) -> Self {
                self.binary(Binary::$op, o)
            }
        }
    };
}

var_binary!(Add, add, Add);
var_binary!(Sub, sub, Sub);
var_binary!(Mul, mul, Mul);
var_binary!(Div, div, Div);

impl Neg for Var {
    type Output = Self;
    fn neg(self) -> Self {
        self.unary(Unary::Neg)
    }
}

impl Var {
    fn unary(self, u: Unary) -> Self {
        record(Op::Unary(u, self.here()))
    }

    fn binary(self, b: Binary, o: Self) -> Self {
        let (x, y) = (self.here(), o.here());
        record(Op::Binary(b, x, y))
    }

    fn truth(self, b: Binary, o: Self) -> VarBool {
        VarBool(self.binary(b, o))
    }
}

impl Num for Var {
    type Bool = VarBool;

    fn of(v: f64) -> Self {
        record(Op::Const(v))
    }
    fn sqrt(self) -> Self {
        self.unary(Unary::Sqrt)
    }
    fn abs(self) -> Self {
        self.unary(Unary::Abs)
    }
    fn sin(self) -> Self {
        self.unary(Unary::Sin)
    }
    fn cos(self) -> Self {
        self.unary(Unary::Cos)
    }
    fn acos(self) -> Self {
        self.unary(Unary::Acos)
    }
    fn exp(self) -> Self {
        self.unary(Unary::Exp)
    }
    fn ln(self) -> Self {
        self.unary(Unary::Ln)
    }
    fn floor(self) -> Self {
        self.unary(Unary::Floor)
    }
    fn round(self) -> Self {
        self.unary(Unary::Round)
    }
    fn min(self, o: Self) -> Self {
        self.binary(Binary::Min, o)
    }
    fn max(self, o: Self) -> Self {
        self.binary(Binary::Max, o)
    }
    fn atan2(self, x: Self) -> Self {
        self.binary(Binary::Atan2, x)
    }
    fn powf(self, e: Self) -> Self {
        self.binary(Binary::Pow, e)
    }
    fn hypot(self, o: Self) -> Self {
        self.binary(Binary::Hypot, o)
    }
    fn length3(x: Self, y: Self, z: Self) -> Self {
        let (x, y, z) = (x.here(), y.here(), z.here());
        record(Op::Length3(x, y, z))
    }
    fn unary3(u: Unary, a: [Self; 3]) -> [Self; 3] {
        let a = vector(a);
        components(record(Op::Unary3(u, a)).id)
    }
    fn binary3(b: Binary, x: [Self; 3], y: [Self; 3]) -> [Self; 3] {
        let (x, y) = (vector(x), vector(y));
        components(record(Op::Binary3(b, x, y)).id)
    }
    fn select3(c: VarBool, a: [Self; 3], b: [Self; 3]) -> [Self; 3] {
        if a == b {
            return a;
        }
        let c = c.0.here();
        let (a, b) = (vector(a), vector(b));
        components(record(Op::Select3(c, a, b)).id)
    }
    fn lt(self, o: Self) -> VarBool {
        self.truth(Binary::Lt, o)
    }
    fn le(self, o: Self) -> VarBool {
        self.truth(Binary::Le, o)
    }
    fn finite(self) -> VarBool {
        VarBool(self.unary(Unary::Finite))
    }
    fn select(c: VarBool, a: Self, b: Self) -> Self {
        if a == b {
            return a;
        }
        let (c, a, b) = (c.0.here(), a.here(), b.here());
        record(Op::Select(c, a, b))
    }
    fn iterate_dyn(
        count: Self,
        init: Vec<Self>,
        body: &mut dyn FnMut(Self, &[Self]) -> Step<Self>,
    ) -> Vec<Self> {
        record_loop(count, &init, body)
    }
}
