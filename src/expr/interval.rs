//! Interval arithmetic: a formula run on intervals gives a range that holds
//! every value it takes over a box.
//!
//! Each operation returns an interval holding the operation's result for
//! every pair of points of its operands' intervals. The plain `f64`
//! operations it is built from round to nearest, which is monotone, so the
//! ends computed for monotone operations bound the rounded values at the
//! points too; the transcendental functions are widened by a few ulps
//! (their library results are not correctly rounded). Anything that could
//! be NaN becomes the whole line.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use super::num::Step;
use super::num::{Logic, MAX_LOOP_STEPS, Num};

/// A closed interval `[lo, hi]` of `f64`, possibly unbounded.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Interval {
    /// The lower end.
    pub lo: f64,
    /// The upper end.
    pub hi: f64,
}

/// A truth value over a box: whether it can be true and whether it can be
/// false somewhere in it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct Maybe {
    /// True somewhere.
    pub can_be_true: bool,
    /// False somewhere.
    pub can_be_false: bool,
}

impl Maybe {
    const fn of(b: bool) -> Self {
        Maybe {
            can_be_true: b,
            can_be_false: !b,
        }
    }

    const UNKNOWN: Maybe = Maybe {
        can_be_true: true,
        can_be_false: true,
    };
}

impl Logic for Maybe {}

impl BitAnd for Maybe {
    type Output = Self;
    fn bitand(self, o: Self) -> Self {
        Maybe {
            can_be_true: self.can_be_true && o.can_be_true,
            can_be_false: self.can_be_false || o.can_be_false,
        }
    }
}

impl BitOr for Maybe {
    type Output = Self;
    fn bitor(self, o: Self) -> Self {
        Maybe {
            can_be_true: self.can_be_true || o.can_be_true,
            can_be_false: self.can_be_false && o.can_be_false,
        }
    }
}

impl Not for Maybe {
    type Output = Self;
    fn not(self) -> Self {
        Maybe {
            can_be_true: self.can_be_false,
            can_be_false: self.can_be_true,
        }
    }
}

/// Relative widening of the transcendental functions' ends.
const SLACK: f64 = 4.0 * f64::EPSILON;

impl Interval {
    /// The whole line.
    pub const ENTIRE: Interval = Interval {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// `[lo, hi]`; the whole line if either end is NaN or `lo > hi`.
    #[must_use]
    pub fn new(lo: f64, hi: f64) -> Self {
        if lo <= hi {
            Interval { lo, hi }
        } else {
            Self::ENTIRE
        }
    }

    /// The single point `v`.
    #[must_use]
    pub fn point(v: f64) -> Self {
        Self::new(v, v)
    }

    /// Whether `v` lies in the interval.
    #[must_use]
    pub fn contains(self, v: f64) -> bool {
        self.lo <= v && v <= self.hi
    }

    /// The smallest interval holding both.
    #[must_use]
    pub fn hull(self, o: Self) -> Self {
        Self::new(self.lo.min(o.lo), self.hi.max(o.hi))
    }

    /// The image under a non-decreasing `f`.
    fn rising(self, f: impl Fn(f64) -> f64) -> Self {
        Self::new(f(self.lo), f(self.hi))
    }

    /// Widens by [`SLACK`] of each end's magnitude.
    fn widen(self) -> Self {
        Self::new(
            self.lo - self.lo.abs() * SLACK - f64::MIN_POSITIVE,
            self.hi + self.hi.abs() * SLACK + f64::MIN_POSITIVE,
        )
    }

    fn square(self) -> Self {
        let a = self.abs();
        Self::new(a.lo * a.lo, a.hi * a.hi)
    }

    fn corners(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let c = [
            f(self.lo, o.lo),
            f(self.lo, o.hi),
            f(self.hi, o.lo),
            f(self.hi, o.hi),
        ];
        if c.iter().any(|v| v.is_nan()) {
            return Self::ENTIRE;
        }
        Self::new(
            c.iter().copied().fold(f64::INFINITY, f64::min),
            c.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    }
}

impl Add for Interval {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self::new(self.lo + o.lo, self.hi + o.hi)
    }
}

impl Sub for Interval {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self::new(self.lo - o.hi, self.hi - o.lo)
    }
}

impl Mul for Interval {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        self.corners(o, |a, b| a * b)
    }
}

impl Div for Interval {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        if o.contains(0.0) {
            return Self::ENTIRE;
        }
        self.corners(o, |a, b| a / b)
    }
}

impl Neg for Interval {
    type Output = Self;
    fn neg(self) -> Self {
        Self::new(-self.hi, -self.lo)
    }
}

/// `f` (`sin`, or `cos` as `sin` shifted by `shift`) over an interval: `[-1, 1]` unless the interval lies between two
/// neighbouring extremes, where `sin` is monotone.
fn sine(x: Interval, shift: f64, f: fn(f64) -> f64) -> Interval {
    use std::f64::consts::PI;
    // sin(x + shift) with extremes at x + shift = pi/2 + k pi.
    if !(x.lo.is_finite() && x.hi.is_finite()) || x.hi - x.lo >= PI {
        return Interval::new(-1.0, 1.0);
    }
    let k_lo = ((x.lo + shift - PI / 2.0) / PI).floor();
    let k_hi = ((x.hi + shift - PI / 2.0) / PI).floor();
    let ends = Interval::new(f(x.lo).min(f(x.hi)), f(x.lo).max(f(x.hi))).widen();
    if k_lo == k_hi {
        return Interval::new(ends.lo.max(-1.0), ends.hi.min(1.0));
    }
    // One extreme inside: +1 at even k + 1, -1 at odd.
    let top = (k_hi.rem_euclid(2.0)) == 0.0;
    if top {
        Interval::new(ends.lo.max(-1.0), 1.0)
    } else {
        Interval::new(-1.0, ends.hi.min(1.0))
    }
}

impl Num for Interval {
    type Bool = Maybe;

    fn of(v: f64) -> Self {
        Self::point(v)
    }
    fn sqrt(self) -> Self {
        if self.lo < 0.0 {
            // sqrt of a negative is NaN somewhere in the box.
            return Self::ENTIRE;
        }
        self.rising(f64::sqrt)
    }
    fn abs(self) -> Self {
        if self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            -self
        } else {
            Self::new(0.0, (-self.lo).max(self.hi))
        }
    }
    fn sin(self) -> Self {
        sine(self, 0.0, f64::sin)
    }
    fn cos(self) -> Self {
        sine(self, std::f64::consts::FRAC_PI_2, f64::cos)
    }
    fn acos(self) -> Self {
        if self.lo < -1.0 || self.hi > 1.0 {
            return Self::ENTIRE;
        }
        Self::new(self.hi.acos(), self.lo.acos()).widen()
    }
    fn exp(self) -> Self {
        let r = self.rising(f64::exp).widen();
        Self::new(r.lo.max(0.0), r.hi)
    }
    fn ln(self) -> Self {
        if self.lo < 0.0 {
            return Self::ENTIRE;
        }
        self.rising(f64::ln).widen()
    }
    fn floor(self) -> Self {
        self.rising(f64::floor)
    }
    fn round(self) -> Self {
        self.rising(f64::round)
    }
    fn min(self, o: Self) -> Self {
        Self::new(self.lo.min(o.lo), self.hi.min(o.hi))
    }
    fn max(self, o: Self) -> Self {
        Self::new(self.lo.max(o.lo), self.hi.max(o.hi))
    }
    fn atan2(self, _x: Self) -> Self {
        Self::new(-std::f64::consts::PI, std::f64::consts::PI).widen()
    }
    fn powf(self, e: Self) -> Self {
        if self.lo <= 0.0 {
            return Self::ENTIRE;
        }
        // x^e is monotone in each argument for x > 0: its extremes are at
        // the corners.
        self.corners(e, f64::powf).widen()
    }
    fn hypot(self, o: Self) -> Self {
        let (a, b) = (self.abs(), o.abs());
        Self::new(a.lo.hypot(b.lo), a.hi.hypot(b.hi)).widen()
    }
    fn length3(x: Self, y: Self, z: Self) -> Self {
        (x.square() + y.square() + z.square()).sqrt()
    }
    fn lt(self, o: Self) -> Maybe {
        if self.hi < o.lo {
            Maybe::of(true)
        } else if self.lo >= o.hi {
            Maybe::of(false)
        } else {
            Maybe::UNKNOWN
        }
    }
    fn le(self, o: Self) -> Maybe {
        if self.hi <= o.lo {
            Maybe::of(true)
        } else if self.lo > o.hi {
            Maybe::of(false)
        } else {
            Maybe::UNKNOWN
        }
    }
    fn finite(self) -> Maybe {
        if self.lo.is_finite() && self.hi.is_finite() {
            Maybe::of(true)
        } else {
            Maybe::UNKNOWN
        }
    }
    fn select(c: Maybe, a: Self, b: Self) -> Self {
        match (c.can_be_true, c.can_be_false) {
            (true, false) => a,
            (false, true) => b,
            _ => a.hull(b),
        }
    }
    /// Every state some point of the box can end with: the loop follows
    /// the state of the points that go on, and gathers the state wherever
    /// some points may stop (their count reached, or a stop that may hold).
    fn iterate_dyn(
        count: Self,
        mut state: Vec<Self>,
        body: &mut dyn FnMut(Self, &[Self]) -> Step<Self>,
    ) -> Vec<Self> {
        let mut ended: Option<Vec<Interval>> = None;
        let mut gather = |state: &[Interval]| {
            ended = Some(match ended.take() {
                None => state.to_vec(),
                Some(e) => e.iter().zip(state).map(|(a, b)| a.hull(*b)).collect(),
            });
        };
        let mut i = 0u32;
        loop {
            let at = f64::from(i);
            // Points whose count is at most `i` end here.
            if at >= count.hi || i >= MAX_LOOP_STEPS {
                break;
            }
            if at >= count.lo {
                gather(&state);
            }
            let step = body(Interval::point(at), &state);
            if let Some(b) = step.stop_before {
                if b.can_be_true && !b.can_be_false {
                    break;
                }
                if b.can_be_true {
                    gather(&state);
                }
            }
            state = step.next;
            if let Some(b) = step.stop_after {
                if b.can_be_true && !b.can_be_false {
                    break;
                }
                if b.can_be_true {
                    gather(&state);
                }
            }
            i += 1;
        }
        gather(&state);
        ended.unwrap_or(state)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sine_holds_its_values() {
        for i in 0..400 {
            let lo = -7.0 + f64::from(i) * 0.037;
            for w in [0.0, 0.1, 0.9, 2.5, 3.3] {
                let x = Interval::new(lo, lo + w);
                let (s, c) = (x.sin(), x.cos());
                for k in 0..=20 {
                    let v = lo + w * f64::from(k) / 20.0;
                    assert!(s.contains(v.sin()), "sin {v} not in {s:?}");
                    assert!(c.contains(v.cos()), "cos {v} not in {c:?}");
                }
            }
        }
    }

    #[test]
    fn division_by_an_interval_holding_zero_is_everything() {
        let r = Interval::point(1.0) / Interval::new(-1.0, 1.0);
        assert_eq!(r, Interval::ENTIRE);
    }
}
