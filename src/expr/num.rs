//! The number type every formula is written over.
//!
//! A formula is a Rust function generic over [`Num`]. Run with `f32` or
//! `f64` it computes a value (the CPU reference, the mesher, the testing
//! toolkit); with [`Interval`](super::Interval) it bounds a value over a
//! box; with [`Var`](super::Var) it records an expression
//! ([`Program`](super::Program)) that a printer turns into kernel source.
//!
//! Control flow that depends on a value is written as [`Num::select`], not
//! `if`: the condition of a traced value is not known when the formula
//! runs. Both operands are evaluated, one is kept.

use std::fmt::Debug;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use super::ops::{Binary, Unary};

/// The smallest magnitude used to guard divisions and logarithms, in both
/// twins (`REAL_TINY` in the kernels; a normal `f32`).
pub const REAL_TINY: f64 = 1e-30;

/// The cap on fractal running derivatives, so they never overflow to
/// infinity (`DERIVATIVE_CAP` in the kernels).
pub const DERIVATIVE_CAP: f64 = 1e30;

/// The largest magnitude an escape-time iteration may produce
/// (`MAGNITUDE_CAP` in the kernels): the squared length of a vector this
/// long stays below `f32::MAX`, and dividing it by a capped derivative
/// stays tiny.
pub const MAGNITUDE_CAP: f64 = 1e18;

/// The most steps a loop takes in plain numbers, whatever its count: a
/// count of infinity still ends.
pub const MAX_LOOP_STEPS: u32 = 1 << 20;

/// A truth value of a [`Num`]: `bool` for plain numbers, a maybe for
/// intervals, a recorded comparison for traced values.
pub trait Logic:
    Copy + Debug + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
}

impl Logic for bool {}

/// A number a formula can be evaluated, bounded or traced with.
///
/// The method names are those of `f64`; each has the IEEE meaning for the
/// plain types. `min` and `max` return the other operand when one is NaN
/// (as `fmin`/`fmax` do in OpenCL C).
pub trait Num:
    Copy
    + Debug
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The truth values comparisons give.
    type Bool: Logic;

    /// A literal (rounded to the precision for `f32`).
    fn of(v: f64) -> Self;

    /// `0`.
    #[must_use]
    fn zero() -> Self {
        Self::of(0.0)
    }

    /// `1`.
    #[must_use]
    fn one() -> Self {
        Self::of(1.0)
    }

    /// The smallest magnitude used to guard divisions and logarithms
    /// (`1e-30`, a normal `f32`).
    #[must_use]
    fn tiny() -> Self {
        Self::of(REAL_TINY)
    }

    /// The cap on fractal running derivatives (`1e30`).
    #[must_use]
    fn derivative_cap() -> Self {
        Self::of(DERIVATIVE_CAP)
    }

    /// The largest magnitude an escape-time iteration may produce (`1e18`).
    #[must_use]
    fn magnitude_cap() -> Self {
        Self::of(MAGNITUDE_CAP)
    }

    /// Square root.
    #[must_use]
    fn sqrt(self) -> Self;
    /// Absolute value.
    #[must_use]
    fn abs(self) -> Self;
    /// Sine.
    #[must_use]
    fn sin(self) -> Self;
    /// Cosine.
    #[must_use]
    fn cos(self) -> Self;
    /// Arc cosine.
    #[must_use]
    fn acos(self) -> Self;
    /// `e^x`.
    #[must_use]
    fn exp(self) -> Self;
    /// Natural logarithm.
    #[must_use]
    fn ln(self) -> Self;
    /// Largest integer not above.
    #[must_use]
    fn floor(self) -> Self;
    /// The nearest integer, halves away from zero.
    #[must_use]
    fn round(self) -> Self;
    /// The smaller operand.
    #[must_use]
    fn min(self, o: Self) -> Self;
    /// The larger operand.
    #[must_use]
    fn max(self, o: Self) -> Self;
    /// `atan2(self, x)`, the angle of `(x, self)`.
    #[must_use]
    fn atan2(self, x: Self) -> Self;
    /// `self^e`.
    #[must_use]
    fn powf(self, e: Self) -> Self;
    /// `sqrt(self^2 + o^2)`, computed as written for the plain types (as
    /// [`Num::length3`] is): the kernels print it as the length of a
    /// 2-vector, which PoCL computes about twice as fast as its `hypot`,
    /// and the two sides must round alike. The precisions' limits
    /// ([`F32_LIMITS`](crate::math::F32_LIMITS)) keep every square finite.
    #[must_use]
    fn hypot(self, o: Self) -> Self;
    /// `sqrt(x^2 + y^2 + z^2)`: the length of a 3-vector (one operation,
    /// so a printer can use the backend's vector `length`).
    #[must_use]
    fn length3(x: Self, y: Self, z: Self) -> Self {
        (x * x + y * y + z * z).sqrt()
    }

    /// A numeric [`Unary`] operation on each component of a 3-vector (one
    /// vector operation when traced).
    #[must_use]
    fn unary3(u: Unary, a: [Self; 3]) -> [Self; 3] {
        a.map(|x| unary(u, x))
    }

    /// A numeric [`Binary`] operation on each pair of components (one
    /// vector operation when traced).
    #[must_use]
    fn binary3(b: Binary, x: [Self; 3], y: [Self; 3]) -> [Self; 3] {
        [0, 1, 2].map(|i| binary(b, x[i], y[i]))
    }

    /// The 3-vector `a` where `c` holds, else `b`.
    #[must_use]
    fn select3(c: Self::Bool, a: [Self; 3], b: [Self; 3]) -> [Self; 3] {
        [0, 1, 2].map(|i| Self::select(c, a[i], b[i]))
    }

    /// `self < o`.
    fn lt(self, o: Self) -> Self::Bool;
    /// `self <= o`.
    fn le(self, o: Self) -> Self::Bool;
    /// Whether finite (neither infinite nor NaN).
    fn finite(self) -> Self::Bool;
    /// `a` where `c` holds, else `b`.
    #[must_use]
    fn select(c: Self::Bool, a: Self, b: Self) -> Self;

    /// Runs `body` at most `count` times (the index from 0) on a state that
    /// starts as `init`, with the state's size known only at run time (see
    /// [`Num::iterate`]).
    fn iterate_dyn(
        count: Self,
        init: Vec<Self>,
        body: &mut dyn FnMut(Self, &[Self]) -> Step<Self>,
    ) -> Vec<Self>;

    /// A bounded loop: runs `body` at most `count` times (index `0, 1,
    /// ...`) on a state that starts as `init`. Each step gives the next
    /// state and, optionally, where the loop ends before the step (keeping
    /// the state) or after it. Traced, it is one loop in the program, not
    /// an unrolled copy per step.
    ///
    /// ```
    /// use fractal_sdf::expr::{Num, Step};
    /// // Doubles until past 100, at most 10 times.
    /// let [x] = f64::iterate(10.0, [3.0], |_, [x]| Step {
    ///     stop_before: None,
    ///     next: [2.0 * x],
    ///     stop_after: Some(2.0 * x > 100.0),
    /// });
    /// assert_eq!(x, 192.0);
    /// ```
    fn iterate<const K: usize>(
        count: Self,
        init: [Self; K],
        mut body: impl FnMut(Self, [Self; K]) -> Step<Self, [Self; K]>,
    ) -> [Self; K] {
        let out = Self::iterate_dyn(count, init.to_vec(), &mut |i, s: &[Self]| {
            let step = body(i, std::array::from_fn(|j| s[j]));
            Step {
                stop_before: step.stop_before,
                next: step.next.to_vec(),
                stop_after: step.stop_after,
            }
        });
        std::array::from_fn(|j| out[j])
    }

    /// `self > o`.
    fn gt(self, o: Self) -> Self::Bool {
        o.lt(self)
    }
    /// `self >= o`.
    fn ge(self, o: Self) -> Self::Bool {
        o.le(self)
    }
    /// `min(max(self, lo), hi)`.
    #[must_use]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        self.max(lo).min(hi)
    }
    /// `self + (o - self) t`.
    #[must_use]
    fn mix(self, o: Self, t: Self) -> Self {
        self + (o - self) * t
    }
    /// `self - floor(self)`.
    #[must_use]
    fn fract(self) -> Self {
        self - self.floor()
    }
}

/// A loop in plain numbers: at most `count` steps (and
/// [`MAX_LOOP_STEPS`]), stopping where a step says so.
pub(super) fn plain_loop<N: Num<Bool = bool> + PartialOrd, S>(
    count: N,
    index: impl Fn(u32) -> N,
    mut state: S,
    mut body: impl FnMut(N, &S) -> Step<N, S>,
) -> S {
    let mut i = 0u32;
    while index(i) < count && i < MAX_LOOP_STEPS {
        let step = body(index(i), &state);
        if step.stop_before == Some(true) {
            break;
        }
        state = step.next;
        if step.stop_after == Some(true) {
            break;
        }
        i += 1;
    }
    state
}

macro_rules! plain {
    ($t:ty) => {
        impl Num for $t {
            type Bool = bool;
            #[allow(clippy::cast_possible_truncation)]
            fn of(v: f64) -> Self {
                v as $t
            }
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            fn abs(self) -> Self {
                <$t>::abs(self)
            }
            fn sin(self) -> Self {
                <$t>::sin(self)
            }
            fn cos(self) -> Self {
                <$t>::cos(self)
            }
            fn acos(self) -> Self {
                <$t>::acos(self)
            }
            fn exp(self) -> Self {
                <$t>::exp(self)
            }
            fn ln(self) -> Self {
                <$t>::ln(self)
            }
            fn floor(self) -> Self {
                <$t>::floor(self)
            }
            fn round(self) -> Self {
                <$t>::round(self)
            }
            fn min(self, o: Self) -> Self {
                <$t>::min(self, o)
            }
            fn max(self, o: Self) -> Self {
                <$t>::max(self, o)
            }
            fn atan2(self, x: Self) -> Self {
                <$t>::atan2(self, x)
            }
            fn powf(self, e: Self) -> Self {
                <$t>::powf(self, e)
            }
            fn hypot(self, o: Self) -> Self {
                (self * self + o * o).sqrt()
            }
            fn lt(self, o: Self) -> bool {
                self < o
            }
            fn le(self, o: Self) -> bool {
                self <= o
            }
            fn finite(self) -> bool {
                <$t>::is_finite(self)
            }
            fn select(c: bool, a: Self, b: Self) -> Self {
                if c { a } else { b }
            }
            fn iterate_dyn(
                count: Self,
                state: Vec<Self>,
                body: &mut dyn FnMut(Self, &[Self]) -> Step<Self>,
            ) -> Vec<Self> {
                #[allow(clippy::cast_precision_loss)]
                plain_loop(count, |i| i as $t, state, |i, s: &Vec<Self>| body(i, s))
            }
            fn iterate<const K: usize>(
                count: Self,
                state: [Self; K],
                mut body: impl FnMut(Self, [Self; K]) -> Step<Self, [Self; K]>,
            ) -> [Self; K] {
                #[allow(clippy::cast_precision_loss)]
                plain_loop(count, |i| i as $t, state, |i, s: &[Self; K]| body(i, *s))
            }
        }
    };
}

plain!(f32);
plain!(f64);

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
