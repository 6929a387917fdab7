//! The expression IR: a straight-line program of scalar operations with
//! `select`, recorded by running a formula on [`Var`]s.
//!
//! A [`Program`] is a list of operations, each naming earlier ones, so it
//! has no cycle, no side effect and no unbounded loop: it always
//! terminates. Identical operations are recorded once (the tape shares
//! common subexpressions), so a printer gets each value once and decides
//! which to name.

use std::cell::RefCell;
use std::collections::HashMap;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use super::num::{Logic, Num};

/// A value's place in a [`Program`]: operations only name earlier places.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ValueId(pub(crate) u32);

impl ValueId {
    /// The index into [`Program::ops`].
    #[must_use]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// An operation of one operand.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Unary {
    /// `-x`
    Neg,
    /// `sqrt(x)`
    Sqrt,
    /// `|x|`
    Abs,
    /// `sin(x)`
    Sin,
    /// `cos(x)`
    Cos,
    /// `acos(x)`
    Acos,
    /// `e^x`
    Exp,
    /// `ln(x)`
    Ln,
    /// `floor(x)`
    Floor,
    /// The nearest integer, halves away from zero (`round(x)`).
    Round,
    /// Whether `x` is finite (a truth value).
    Finite,
    /// Logical not of a truth value.
    Not,
}

/// An operation of two operands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Binary {
    /// `a + b`
    Add,
    /// `a - b`
    Sub,
    /// `a * b`
    Mul,
    /// `a / b`
    Div,
    /// The smaller (the other where one is NaN).
    Min,
    /// The larger (the other where one is NaN).
    Max,
    /// `atan2(a, b)`: the angle of `(b, a)`.
    Atan2,
    /// `a^b`
    Pow,
    /// `sqrt(a^2 + b^2)`
    Hypot,
    /// `a < b` (a truth value).
    Lt,
    /// `a <= b` (a truth value).
    Le,
    /// Both truth values.
    And,
    /// Either truth value.
    Or,
}

impl Binary {
    /// Whether the result is a truth value.
    #[must_use]
    pub fn is_logic(self) -> bool {
        matches!(self, Binary::Lt | Binary::Le | Binary::And | Binary::Or)
    }
}

/// One operation of a [`Program`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Op {
    /// A literal.
    Const(f64),
    /// The program's input number `n` (a scalar argument).
    Input(u32),
    /// An operation of one operand.
    Unary(Unary, ValueId),
    /// An operation of two operands.
    Binary(Binary, ValueId, ValueId),
    /// `sqrt(x^2 + y^2 + z^2)`.
    Length3(ValueId, ValueId, ValueId),
    /// The 3-vector of three numbers.
    Make3(ValueId, ValueId, ValueId),
    /// Component `i` (0, 1, 2) of a 3-vector.
    Component(ValueId, u32),
    /// A numeric [`Unary`] operation on each component of a 3-vector.
    Unary3(Unary, ValueId),
    /// A numeric [`Binary`] operation on each pair of components of two
    /// 3-vectors.
    Binary3(Binary, ValueId, ValueId),
    /// The 3-vector `a` where the truth value `c` holds, else `b`.
    Select3(ValueId, ValueId, ValueId),
    /// `a` where the truth value `c` holds, else `b`.
    Select(ValueId, ValueId, ValueId),
    /// A value of an enclosing program (a loop's body reading the values
    /// around it): how many programs out, and its place there.
    Capture(u32, ValueId),
    /// Loop number `n` of [`Program::loops`]: its value is its final state.
    Loop(u32),
    /// Component `k` of a loop's final state.
    Element(ValueId, u32),
}

/// A bounded loop: its body runs at most `count` times (the index from 0)
/// on the state, which starts as `init`; it stops early where the body says
/// so. Every loop terminates: `count` is a value, not a condition.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Loop {
    /// How many times the body may run (in the enclosing program).
    pub count: ValueId,
    /// The first state (in the enclosing program).
    pub init: Vec<ValueId>,
    /// The body: inputs the index then the state; outputs the next state,
    /// then the `stop_before` truth value if [`Loop::stop_before`], then
    /// the `stop_after` one if [`Loop::stop_after`].
    pub body: Program,
    /// Whether the body gives a truth value that ends the loop before its
    /// step (the state stays as it was).
    pub stop_before: bool,
    /// Whether the body gives a truth value that ends the loop after its
    /// step.
    pub stop_after: bool,
}

impl Loop {
    /// The body's output that ends the loop before the step.
    #[must_use]
    pub fn stop_before_output(&self) -> Option<ValueId> {
        self.stop_before.then(|| self.body.outputs[self.init.len()])
    }

    /// The body's output that ends the loop after the step.
    #[must_use]
    pub fn stop_after_output(&self) -> Option<ValueId> {
        self.stop_after
            .then(|| self.body.outputs[self.init.len() + usize::from(self.stop_before)])
    }

    /// The values of the program `depth` levels out that the body (and
    /// the loops in it) read.
    fn outer_reads(&self, depth: u32, out: &mut Vec<ValueId>) {
        for op in &self.body.ops {
            if let Op::Capture(up, v) = op
                && *up == depth
                && !out.contains(v)
            {
                out.push(*v);
            }
        }
        for inner in &self.body.loops {
            inner.outer_reads(depth + 1, out);
        }
    }
}

impl Op {
    /// Whether the operation gives a 3-vector.
    #[must_use]
    pub fn is_vector(&self) -> bool {
        matches!(
            self,
            Op::Make3(..) | Op::Unary3(..) | Op::Binary3(..) | Op::Select3(..)
        )
    }

    /// Whether the operation gives a truth value rather than a number.
    #[must_use]
    pub fn is_logic(&self) -> bool {
        match self {
            Op::Unary(u, _) => matches!(u, Unary::Finite | Unary::Not),
            Op::Binary(b, ..) => b.is_logic(),
            _ => false,
        }
    }

    /// The values of its own program this operation reads (a loop: its
    /// count, first state and what its body reads of this program).
    #[must_use]
    pub fn operands(&self, loops: &[Loop]) -> Vec<ValueId> {
        match *self {
            Op::Const(_) | Op::Input(_) | Op::Capture(..) => Vec::new(),
            Op::Unary(_, a) | Op::Element(a, _) | Op::Component(a, _) | Op::Unary3(_, a) => {
                vec![a]
            }
            Op::Binary(_, a, b) | Op::Binary3(_, a, b) => vec![a, b],
            Op::Length3(a, b, c)
            | Op::Select(a, b, c)
            | Op::Make3(a, b, c)
            | Op::Select3(a, b, c) => {
                vec![a, b, c]
            }
            Op::Loop(n) => {
                let l = &loops[n as usize];
                let mut v = vec![l.count];
                v.extend_from_slice(&l.init);
                l.outer_reads(1, &mut v);
                v
            }
        }
    }

    /// A hashable key: the variant, a literal's bits or the operation,
    /// and the operands.
    fn key(&self) -> Key {
        let v = |x: ValueId| x.0;
        match *self {
            Op::Const(c) => (0, c.to_bits(), [0; 3]),
            Op::Input(n) => (1, 0, [n, 0, 0]),
            Op::Unary(u, a) => (2, u as u64, [v(a), 0, 0]),
            Op::Binary(b, x, y) => (3, b as u64, [v(x), v(y), 0]),
            Op::Length3(x, y, z) => (4, 0, [v(x), v(y), v(z)]),
            Op::Make3(x, y, z) => (5, 0, [v(x), v(y), v(z)]),
            Op::Component(a, i) => (6, u64::from(i), [v(a), 0, 0]),
            Op::Unary3(u, a) => (7, u as u64, [v(a), 0, 0]),
            Op::Binary3(b, x, y) => (8, b as u64, [v(x), v(y), 0]),
            Op::Select3(c, a, b) => (9, 0, [v(c), v(a), v(b)]),
            Op::Select(c, a, b) => (10, 0, [v(c), v(a), v(b)]),
            Op::Capture(up, a) => (11, u64::from(up), [v(a), 0, 0]),
            Op::Loop(n) => (12, u64::from(n), [0; 3]),
            Op::Element(a, k) => (13, u64::from(k), [v(a), 0, 0]),
        }
    }
}

/// An operation's key on a tape (see [`Op::key`]).
type Key = (u8, u64, [u32; 3]);

/// A recorded formula: operations in order, how many scalar inputs it
/// reads, and which values it returns.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Program {
    /// The operations; each names only earlier ones.
    pub ops: Vec<Op>,
    /// How many scalar inputs it reads (`Op::Input(0..inputs)`).
    pub inputs: u32,
    /// The returned values, in order.
    pub outputs: Vec<ValueId>,
    /// The loops its [`Op::Loop`]s name.
    pub loops: Vec<Loop>,
}

/// A value of a program run: a number, a truth value or a loop's state.
#[derive(Debug, Clone)]
enum Slot<N: Num> {
    Number(N),
    Truth(N::Bool),
    Vector([N; 3]),
    State(Vec<N>),
}

impl<N: Num> Slot<N> {
    fn number(&self) -> N {
        match self {
            Slot::Number(n) => *n,
            // Programs are typed when recorded; a truth value read as a
            // number is the checked programs' bug, and reads as NaN.
            Slot::Truth(_) | Slot::Vector(_) | Slot::State(_) => N::of(f64::NAN),
        }
    }

    fn truth(&self) -> N::Bool {
        match self {
            Slot::Truth(b) => *b,
            Slot::Number(n) => n.finite() & !n.finite(),
            Slot::Vector(_) | Slot::State(_) => N::of(0.0).lt(N::of(0.0)),
        }
    }

    fn vector(&self) -> [N; 3] {
        match self {
            Slot::Vector(v) => *v,
            other => [other.number(); 3],
        }
    }
}

impl Program {
    /// Runs the program on `inputs` in any number type: `f64` or `f32`
    /// for values, intervals for bounds, [`Var`] to record it again.
    /// Missing inputs read as NaN.
    #[must_use]
    pub fn run<N: Num>(&self, inputs: &[N]) -> Vec<N> {
        let slots = self.run_in(inputs, &[]);
        self.outputs
            .iter()
            .map(|v| slots[v.index()].number())
            .collect()
    }

    /// Runs the program with `outer` the slots of the enclosing programs
    /// (innermost last), giving every value's slot.
    fn run_in<N: Num>(&self, inputs: &[N], outer: &[&[Slot<N>]]) -> Vec<Slot<N>> {
        let mut slots: Vec<Slot<N>> = Vec::with_capacity(self.ops.len());
        for op in &self.ops {
            let n = |v: ValueId| slots[v.index()].number();
            let b = |v: ValueId| slots[v.index()].truth();
            let slot = match *op {
                Op::Const(v) => Slot::Number(N::of(v)),
                Op::Input(i) => Slot::Number(
                    inputs
                        .get(i as usize)
                        .copied()
                        .unwrap_or_else(|| N::of(f64::NAN)),
                ),
                Op::Unary(u, a) => match u {
                    Unary::Finite => Slot::Truth(n(a).finite()),
                    Unary::Not => Slot::Truth(!b(a)),
                    _ => Slot::Number(unary(u, n(a))),
                },
                Op::Binary(op, x, y) => match op {
                    Binary::Lt => Slot::Truth(n(x).lt(n(y))),
                    Binary::Le => Slot::Truth(n(x).le(n(y))),
                    Binary::And => Slot::Truth(b(x) & b(y)),
                    Binary::Or => Slot::Truth(b(x) | b(y)),
                    _ => Slot::Number(binary(op, n(x), n(y))),
                },
                Op::Length3(x, y, z) => Slot::Number(N::length3(n(x), n(y), n(z))),
                Op::Make3(x, y, z) => Slot::Vector([n(x), n(y), n(z)]),
                Op::Component(v, i) => Slot::Number(slots[v.index()].vector()[i as usize]),
                Op::Unary3(u, v) => Slot::Vector(N::unary3(u, slots[v.index()].vector())),
                Op::Binary3(b, x, y) => {
                    let (x, y) = (slots[x.index()].vector(), slots[y.index()].vector());
                    Slot::Vector(N::binary3(b, x, y))
                }
                Op::Select3(c, x, y) => {
                    let (x, y) = (slots[x.index()].vector(), slots[y.index()].vector());
                    Slot::Vector(N::select3(b(c), x, y))
                }
                Op::Select(c, x, y) => Slot::Number(N::select(b(c), n(x), n(y))),
                Op::Capture(up, v) => {
                    let at = outer.len().checked_sub(up as usize);
                    at.and_then(|at| outer[at].get(v.index()))
                        .cloned()
                        .unwrap_or(Slot::Number(N::of(f64::NAN)))
                }
                Op::Element(v, k) => match &slots[v.index()] {
                    Slot::State(s) => Slot::Number(s[k as usize]),
                    _ => Slot::Number(N::of(f64::NAN)),
                },
                Op::Loop(index) => {
                    let l = &self.loops[index as usize];
                    let init: Vec<N> = l.init.iter().map(|v| n(*v)).collect();
                    let mut levels: Vec<&[Slot<N>]> = outer.to_vec();
                    levels.push(&slots);
                    Slot::State(run_loop(l, n(l.count), init, &levels))
                }
            };
            slots.push(slot);
        }
        slots
    }

    /// How many times each value is read (by operations and outputs).
    #[must_use]
    pub fn uses(&self) -> Vec<u32> {
        let mut uses = vec![0u32; self.ops.len()];
        for op in &self.ops {
            for v in op.operands(&self.loops) {
                uses[v.index()] += 1;
            }
        }
        for v in &self.outputs {
            uses[v.index()] += 1;
        }
        uses
    }

    /// Which operations an output depends on.
    #[must_use]
    pub fn live(&self) -> Vec<bool> {
        let mut live = vec![false; self.ops.len()];
        for v in &self.outputs {
            live[v.index()] = true;
        }
        for i in (0..self.ops.len()).rev() {
            if live[i] {
                for v in self.ops[i].operands(&self.loops) {
                    live[v.index()] = true;
                }
            }
        }
        live
    }
}

/// Runs a loop in any number type, through [`Num::iterate`].
fn run_loop<N: Num>(l: &Loop, count: N, init: Vec<N>, outer: &[&[Slot<N>]]) -> Vec<N> {
    let k = init.len();
    N::iterate_dyn(count, init, &mut |index: N, state: &[N]| {
        let mut inputs = Vec::with_capacity(k + 1);
        inputs.push(index);
        inputs.extend_from_slice(state);
        let slots = l.body.run_in(&inputs, outer);
        let get = |v: ValueId| slots[v.index()].number();
        let truth = |v: Option<ValueId>| v.map(|v| slots[v.index()].truth());
        Step {
            stop_before: truth(l.stop_before_output()),
            next: l.body.outputs[..k].iter().map(|v| get(*v)).collect(),
            stop_after: truth(l.stop_after_output()),
        }
    })
}

/// One step of a loop (see [`Num::iterate`]).
#[derive(Debug, Clone)]
pub struct Step<N: Num, S = Vec<N>> {
    /// Where this holds, the loop ends before the step: the state stays
    /// as it was.
    pub stop_before: Option<N::Bool>,
    /// The next state.
    pub next: S,
    /// Where this holds, the loop ends after the step.
    pub stop_after: Option<N::Bool>,
}

/// Applies a numeric [`Unary`] operation.
#[inline]
pub(crate) fn unary<N: Num>(u: Unary, a: N) -> N {
    match u {
        Unary::Neg => -a,
        Unary::Sqrt => a.sqrt(),
        Unary::Abs => a.abs(),
        Unary::Sin => a.sin(),
        Unary::Cos => a.cos(),
        Unary::Acos => a.acos(),
        Unary::Exp => a.exp(),
        Unary::Ln => a.ln(),
        Unary::Floor => a.floor(),
        Unary::Round => a.round(),
        Unary::Finite | Unary::Not => N::of(f64::NAN),
    }
}

/// Applies a numeric [`Binary`] operation.
#[inline]
pub(crate) fn binary<N: Num>(op: Binary, a: N, b: N) -> N {
    match op {
        Binary::Add => a + b,
        Binary::Sub => a - b,
        Binary::Mul => a * b,
        Binary::Div => a / b,
        Binary::Min => a.min(b),
        Binary::Max => a.max(b),
        Binary::Atan2 => a.atan2(b),
        Binary::Pow => a.powf(b),
        Binary::Hypot => a.hypot(b),
        Binary::Lt | Binary::Le | Binary::And | Binary::Or => N::of(f64::NAN),
    }
}

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
