//! The expression IR: a straight-line program of scalar operations with
//! `select`, recorded by running a formula on [`Var`]s.
//!
//! A [`Program`] is a list of operations, each naming earlier ones, so it
//! has no cycle, no side effect and no unbounded loop: it always
//! terminates. Identical operations are recorded once (the tape shares
//! common subexpressions), so a printer gets each value once and decides
//! which to name.

use super::num::{Num, Step, binary, unary};
use super::ops::{Binary, Unary};

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
    pub(super) fn key(&self) -> Key {
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
pub(super) type Key = (u8, u64, [u32; 3]);

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
    /// for values, intervals for bounds, [`Var`](super::Var) to record it again.
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
