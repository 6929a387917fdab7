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
    /// Whether `x` is finite (a truth value).
    Finite,
    /// Logical not of a truth value.
    Not,
}

/// An operation of two operands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
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
    /// `a` where the truth value `c` holds, else `b`.
    Select(ValueId, ValueId, ValueId),
}

impl Op {
    /// Whether the operation gives a truth value rather than a number.
    #[must_use]
    pub fn is_logic(&self) -> bool {
        match self {
            Op::Unary(u, _) => matches!(u, Unary::Finite | Unary::Not),
            Op::Binary(b, ..) => b.is_logic(),
            _ => false,
        }
    }

    /// The values this operation reads.
    #[must_use]
    pub fn operands(&self) -> Vec<ValueId> {
        match *self {
            Op::Const(_) | Op::Input(_) => Vec::new(),
            Op::Unary(_, a) => vec![a],
            Op::Binary(_, a, b) => vec![a, b],
            Op::Length3(a, b, c) | Op::Select(a, b, c) => vec![a, b, c],
        }
    }

    /// A hashable key: literals by their bits.
    fn key(&self) -> Key {
        match *self {
            Op::Const(v) => Key::Const(v.to_bits()),
            Op::Input(n) => Key::Input(n),
            Op::Unary(u, a) => Key::Unary(u, a),
            Op::Binary(b, x, y) => Key::Binary(b, x, y),
            Op::Length3(x, y, z) => Key::Length3(x, y, z),
            Op::Select(c, a, b) => Key::Select(c, a, b),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    Const(u64),
    Input(u32),
    Unary(Unary, ValueId),
    Binary(Binary, ValueId, ValueId),
    Length3(ValueId, ValueId, ValueId),
    Select(ValueId, ValueId, ValueId),
}

/// A recorded formula: operations in order, how many scalar inputs it
/// reads, and which values it returns.
#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    /// The operations; each names only earlier ones.
    pub ops: Vec<Op>,
    /// How many scalar inputs it reads (`Op::Input(0..inputs)`).
    pub inputs: u32,
    /// The returned values, in order.
    pub outputs: Vec<ValueId>,
}

/// A value of a program run: a number or a truth value.
#[derive(Debug, Clone, Copy)]
enum Slot<N: Num> {
    Number(N),
    Truth(N::Bool),
}

impl<N: Num> Slot<N> {
    fn number(self) -> N {
        match self {
            Slot::Number(n) => n,
            // Programs are typed when recorded; a truth value read as a
            // number is the checked programs' bug, and reads as NaN.
            Slot::Truth(_) => N::of(f64::NAN),
        }
    }

    fn truth(self) -> N::Bool {
        match self {
            Slot::Truth(b) => b,
            Slot::Number(n) => n.finite() & !n.finite(),
        }
    }
}

impl Program {
    /// Runs the program on `inputs` in any number type: `f64` or `f32`
    /// for values, intervals for bounds, [`Var`] to record it again.
    /// Missing inputs read as NaN.
    #[must_use]
    pub fn run<N: Num>(&self, inputs: &[N]) -> Vec<N> {
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
                Op::Select(c, x, y) => Slot::Number(N::select(b(c), n(x), n(y))),
            };
            slots.push(slot);
        }
        self.outputs
            .iter()
            .map(|v| slots[v.index()].number())
            .collect()
    }

    /// How many times each value is read (by operations and outputs).
    #[must_use]
    pub fn uses(&self) -> Vec<u32> {
        let mut uses = vec![0u32; self.ops.len()];
        for op in &self.ops {
            for v in op.operands() {
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
                for v in self.ops[i].operands() {
                    live[v.index()] = true;
                }
            }
        }
        live
    }
}

/// Applies a numeric [`Unary`] operation.
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
        Unary::Finite | Unary::Not => N::of(f64::NAN),
    }
}

/// Applies a numeric [`Binary`] operation.
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
    seen: HashMap<Key, ValueId>,
}

impl Tape {
    fn push(&mut self, op: Op) -> ValueId {
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

thread_local! {
    /// The tapes being recorded on this thread, innermost last.
    static TAPES: RefCell<Vec<Tape>> = const { RefCell::new(Vec::new()) };
}

fn record(op: Op) -> ValueId {
    TAPES.with(|t| {
        t.borrow_mut()
            .last_mut()
            .expect("a traced value is used only inside expr::trace")
            .push(op)
    })
}

/// A number being traced: running a formula on `Var`s records its
/// operations into a [`Program`] (see [`trace`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Var(pub(crate) ValueId);

/// A truth value being traced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VarBool(pub(crate) ValueId);

/// Records `f` run on `inputs` scalar inputs as a [`Program`] returning the
/// values `f` returns.
///
/// ```
/// use fractal_sdf::expr::{Num, trace};
/// let program = trace(2, |x| vec![(x[0] * x[0] + x[1] * x[1]).sqrt()]);
/// assert_eq!(program.run(&[3.0_f64, 4.0]), vec![5.0]);
/// ```
pub fn trace(inputs: u32, f: impl FnOnce(&[Var]) -> Vec<Var>) -> Program {
    TAPES.with(|t| t.borrow_mut().push(Tape::default()));
    // The tape is popped even if `f` panics, so a later trace starts clean.
    struct Pop;
    impl Drop for Pop {
        fn drop(&mut self) {
            TAPES.with(|t| t.borrow_mut().pop());
        }
    }
    let guard = Pop;
    let args: Vec<Var> = (0..inputs).map(|i| Var(record(Op::Input(i)))).collect();
    let outputs: Vec<ValueId> = f(&args).into_iter().map(|v| v.0).collect();
    let tape = TAPES.with(|t| std::mem::take(t.borrow_mut().last_mut().expect("pushed above")));
    drop(guard);
    Program {
        ops: tape.ops,
        inputs,
        outputs,
    }
}

impl Logic for VarBool {}

impl BitAnd for VarBool {
    type Output = Self;
    fn bitand(self, o: Self) -> Self {
        VarBool(record(Op::Binary(Binary::And, self.0, o.0)))
    }
}

impl BitOr for VarBool {
    type Output = Self;
    fn bitor(self, o: Self) -> Self {
        VarBool(record(Op::Binary(Binary::Or, self.0, o.0)))
    }
}

impl Not for VarBool {
    type Output = Self;
    fn not(self) -> Self {
        VarBool(record(Op::Unary(Unary::Not, self.0)))
    }
}

macro_rules! var_binary {
    ($trait:ident, $method:ident, $op:ident) => {
        impl $trait for Var {
            type Output = Self;
            fn $method(self, o: Self) -> Self {
                Var(record(Op::Binary(Binary::$op, self.0, o.0)))
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
        Var(record(Op::Unary(u, self.0)))
    }

    fn binary(self, b: Binary, o: Self) -> Self {
        Var(record(Op::Binary(b, self.0, o.0)))
    }
}

impl Num for Var {
    type Bool = VarBool;

    fn of(v: f64) -> Self {
        Var(record(Op::Const(v)))
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
        Var(record(Op::Length3(x.0, y.0, z.0)))
    }
    fn lt(self, o: Self) -> VarBool {
        VarBool(record(Op::Binary(Binary::Lt, self.0, o.0)))
    }
    fn le(self, o: Self) -> VarBool {
        VarBool(record(Op::Binary(Binary::Le, self.0, o.0)))
    }
    fn finite(self) -> VarBool {
        VarBool(record(Op::Unary(Unary::Finite, self.0)))
    }
    fn select(c: VarBool, a: Self, b: Self) -> Self {
        if a == b {
            return a;
        }
        Var(record(Op::Select(c.0, a.0, b.0)))
    }
}
