//! Counting the work a formula does: [`Counted`] is an `f64` that tallies
//! every operation done on it, so running a formula (or the CPU
//! reference's whole scene) on it tells how many operations one
//! evaluation costs, beside its value.
//!
//! ```
//! use fractal_sdf::expr::{Counted, Num, counting};
//! let (r, ops) = counting(|| {
//!     let (x, y) = (Counted::of(3.0), Counted::of(4.0));
//!     (x * x + y * y).sqrt()
//! });
//! assert_eq!(r.value(), 5.0);
//! assert_eq!((ops.arithmetic, ops.calls), (4, 0));
//! ```

use std::cell::Cell;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::num::{Num, Step, plain_loop};

/// Operations counted by kind (see [`counting`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct Operations {
    /// Operations a vector unit does in one instruction: `+ − × ÷`,
    /// square roots, `min`, `max`, `|x|`, `floor`, rounding, comparisons
    /// and selections.
    pub arithmetic: u64,
    /// Calls to functions a library computes with a polynomial or an
    /// iteration: `sin`, `cos`, `acos`, `exp`, `ln`, `atan2` and `pow`.
    pub calls: u64,
}

/// The operations a call costs, roughly, in [`Operations::flops`]: a
/// vectorised `sin`, `exp` or `ln` is a range reduction and a polynomial of
/// about this many multiplications and additions.
pub const CALL_FLOPS: u64 = 20;

impl Operations {
    /// Floating-point operations: each arithmetic operation one, each call
    /// [`CALL_FLOPS`].
    #[must_use]
    pub fn flops(&self) -> u64 {
        self.arithmetic + CALL_FLOPS * self.calls
    }
}

impl Add for Operations {
    type Output = Operations;
    fn add(self, o: Operations) -> Operations {
        Operations {
            arithmetic: self.arithmetic + o.arithmetic,
            calls: self.calls + o.calls,
        }
    }
}

thread_local! {
    static COUNT: Cell<Operations> = const { Cell::new(Operations { arithmetic: 0, calls: 0 }) };
}

fn arithmetic() {
    COUNT.with(|c| {
        let mut n = c.get();
        n.arithmetic += 1;
        c.set(n);
    });
}

fn call() {
    COUNT.with(|c| {
        let mut n = c.get();
        n.calls += 1;
        c.set(n);
    });
}

/// Runs `f` and gives its result with the operations done on
/// [`Counted`] numbers on this thread while it ran. Nested, the outer
/// count includes the inner one's.
pub fn counting<R>(f: impl FnOnce() -> R) -> (R, Operations) {
    let before = COUNT.with(Cell::take);
    let r = f();
    let ops = COUNT.with(|c| c.replace(before + c.get()));
    (r, ops)
}

/// An `f64` that counts the operations done on it (see [`counting`]).
/// Its values are those of `f64`.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct Counted(f64);

impl Counted {
    /// The value.
    #[must_use]
    pub fn value(self) -> f64 {
        self.0
    }
}

macro_rules! counted_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for Counted {
            type Output = Counted;
            fn $method(self, o: Counted) -> Counted {
                arithmetic();
                Counted(self.0 $op o.0)
            }
        }
    };
}

counted_op!(Add, add, +);
counted_op!(Sub, sub, -);
counted_op!(Mul, mul, *);
counted_op!(Div, div, /);

impl Neg for Counted {
    type Output = Counted;
    fn neg(self) -> Counted {
        arithmetic();
        Counted(-self.0)
    }
}

/// An operation of one operand, counted as `kind`.
fn one(kind: fn(), x: Counted, f: fn(f64) -> f64) -> Counted {
    kind();
    Counted(f(x.0))
}

/// An operation of two operands, counted as `kind`.
fn two(kind: fn(), x: Counted, y: Counted, f: fn(f64, f64) -> f64) -> Counted {
    kind();
    Counted(f(x.0, y.0))
}

impl Num for Counted {
    type Bool = bool;

    fn of(v: f64) -> Self {
        Counted(v)
    }
    fn sqrt(self) -> Self {
        one(arithmetic, self, f64::sqrt)
    }
    fn abs(self) -> Self {
        one(arithmetic, self, f64::abs)
    }
    fn sin(self) -> Self {
        one(call, self, f64::sin)
    }
    fn cos(self) -> Self {
        one(call, self, f64::cos)
    }
    fn acos(self) -> Self {
        one(call, self, f64::acos)
    }
    fn exp(self) -> Self {
        one(call, self, f64::exp)
    }
    fn ln(self) -> Self {
        one(call, self, f64::ln)
    }
    fn floor(self) -> Self {
        one(arithmetic, self, f64::floor)
    }
    fn round(self) -> Self {
        one(arithmetic, self, f64::round)
    }
    fn min(self, o: Self) -> Self {
        two(arithmetic, self, o, f64::min)
    }
    fn max(self, o: Self) -> Self {
        two(arithmetic, self, o, f64::max)
    }
    fn atan2(self, x: Self) -> Self {
        two(call, self, x, f64::atan2)
    }
    fn powf(self, e: Self) -> Self {
        two(call, self, e, f64::powf)
    }
    fn hypot(self, o: Self) -> Self {
        (self * self + o * o).sqrt()
    }
    fn lt(self, o: Self) -> bool {
        arithmetic();
        self.0 < o.0
    }
    fn le(self, o: Self) -> bool {
        arithmetic();
        self.0 <= o.0
    }
    fn finite(self) -> bool {
        arithmetic();
        self.0.is_finite()
    }
    fn select(c: bool, a: Self, b: Self) -> Self {
        arithmetic();
        if c { a } else { b }
    }
    fn iterate_dyn(
        count: Self,
        state: Vec<Self>,
        body: &mut dyn FnMut(Self, &[Self]) -> Step<Self>,
    ) -> Vec<Self> {
        plain_loop(
            count,
            |i| Counted(f64::from(i)),
            state,
            |i, s: &Vec<Self>| body(i, s),
        )
    }
}
