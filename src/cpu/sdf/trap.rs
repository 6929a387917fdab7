//! Orbit traps (see [`scene::OrbitColoring`](crate::scene::OrbitColoring)),
//! written once for the CPU reference and the kernels: the fractals'
//! formulas take an optional [`TrapShape`] and keep the orbit's smallest
//! distance to it (or its smooth count) in place of their own trap.

use crate::ir::{Scalar, Vector, baked3};
use crate::math::{Num, V3, v3};
use crate::scene::Trap;

/// A trap as numbers, one formula for every [`Trap`]: the distance from
/// `z` is `| |across v + along axis (axis · v)| − radius |` with
/// `v = z − centre` (for a line, `v` less its part along the line: the
/// perpendicular, with no cancellation far from it).
///
/// With `count` 0 the trap value is the orbit's smallest distance; with
/// `count` 1 it is the sum of `e^(−distance)` over the orbit (the
/// iteration count, smoothed: each point near the origin adds about 1, an
/// escaped one almost nothing).
///
/// | trap | `centre` | `axis` | `across` | `along` | `radius` | `count` |
/// |---|---|---|---|---|---|---|
/// | point | the point | 0 | 1 | 0 | 0 | 0 |
/// | sphere | its centre | 0 | 1 | 0 | its radius | 0 |
/// | plane | `−offset · n` | the unit normal `n` | 0 | 1 | 0 | 0 |
/// | line | its point | its unit direction | 1 | −1 | 0 | 0 |
/// | iterations | 0 | 0 | 1 | 0 | 0 | 1 |
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct TrapShape<T> {
    /// The point distances are measured from.
    pub centre: V3<T>,
    /// A unit direction, or 0.
    pub axis: V3<T>,
    /// The weight of `v`.
    pub across: T,
    /// The weight of `v`'s part along `axis`.
    pub along: T,
    /// Subtracted from the length: a sphere's radius.
    pub radius: T,
    /// 1 to sum `e^(−distance)` over the orbit, 0 to keep the smallest
    /// distance.
    pub count: T,
}

impl<T: Num> TrapShape<T> {
    /// The numbers of `trap` (its directions normalised here).
    #[must_use]
    pub fn new(trap: &Trap<T, V3<T>>) -> Self {
        // Scaled by the largest component first, as the plane's normal:
        // a tiny direction's length would underflow in `f32`.
        let unit = |d: V3<T>| {
            let m = d.abs().max_element();
            let scaled = d / m;
            V3::select(m.gt(T::zero()), scaled / scaled.length(), d)
        };
        let (zero, one) = (T::zero(), T::one());
        let none = V3::splat(zero);
        match *trap {
            Trap::Point { centre } => TrapShape {
                centre,
                axis: none,
                across: one,
                along: zero,
                radius: zero,
                count: zero,
            },
            Trap::Sphere { centre, radius } => TrapShape {
                centre,
                axis: none,
                across: one,
                along: zero,
                radius,
                count: zero,
            },
            Trap::Plane { normal, offset } => {
                let n = unit(normal);
                TrapShape {
                    centre: n * -offset,
                    axis: n,
                    across: zero,
                    along: one,
                    radius: zero,
                    count: zero,
                }
            }
            Trap::Line { point, direction } => TrapShape {
                centre: point,
                axis: unit(direction),
                across: one,
                along: -one,
                radius: zero,
                count: zero,
            },
            Trap::Iterations => TrapShape {
                centre: none,
                axis: none,
                across: one,
                along: zero,
                radius: zero,
                count: one,
            },
        }
    }

    /// The trap value of the orbit's first point `p`.
    #[must_use]
    pub fn first(&self, p: V3<T>) -> T {
        let d = self.distance(p);
        T::select(self.counts(), (-d).exp(), d)
    }

    /// The trap value `trap` so far, after the orbit reaches `z`.
    #[must_use]
    pub fn step(&self, trap: T, z: V3<T>) -> T {
        let d = self.distance(z);
        T::select(self.counts(), trap + (-d).exp(), trap.min(d))
    }

    fn counts(&self) -> T::Bool {
        self.count.gt(T::of(0.5))
    }

    /// The distance from `z` to the trap.
    #[must_use]
    pub fn distance(&self, z: V3<T>) -> T {
        let v = z - self.centre;
        let w = v * self.across + self.axis * (self.along * self.axis.dot(v));
        (w.length() - self.radius).abs()
    }

    /// The numbers of a trap of the scene's parameters as the kernels
    /// receive them: where every value is baked, computed here in `f64`
    /// (code generation prints them as literals) and rounded to `T`;
    /// otherwise computed in `T` from `value`'s values, as a kernel
    /// computes them.
    pub(crate) fn of(trap: &Trap<Scalar, Vector>, value: impl Fn(Scalar) -> T) -> Self {
        match TrapShape::baked(trap) {
            Some(shape) => TrapShape::from_values(&shape.values().map(T::of)),
            None => {
                let Ok(trap) = trap.try_map(
                    &mut |s, _| Ok::<_, std::convert::Infallible>(value(*s)),
                    &mut |v, _| Ok(v3(value(v[0]), value(v[1]), value(v[2]))),
                );
                TrapShape::new(&trap)
            }
        }
    }

    /// The trap's numbers in the order a kernel helper takes them:
    /// `centre`, `axis` (three each), `across`, `along`, `radius`,
    /// `count`.
    #[must_use]
    pub fn values(&self) -> [T; 10] {
        let (c, a) = (self.centre, self.axis);
        [
            c.x,
            c.y,
            c.z,
            a.x,
            a.y,
            a.z,
            self.across,
            self.along,
            self.radius,
            self.count,
        ]
    }

    /// The trap from [`TrapShape::values`]' numbers.
    #[must_use]
    pub fn from_values(v: &[T; 10]) -> Self {
        TrapShape {
            centre: v3(v[0], v[1], v[2]),
            axis: v3(v[3], v[4], v[5]),
            across: v[6],
            along: v[7],
            radius: v[8],
            count: v[9],
        }
    }
}

impl TrapShape<f64> {
    /// The numbers of a trap whose values are all baked; `None` where one
    /// is dynamic.
    pub(crate) fn baked(trap: &Trap<Scalar, Vector>) -> Option<Self> {
        let trap = trap
            .try_map(&mut |s, _| s.baked().ok_or(()), &mut |v, _| {
                baked3(*v).map(|d| v3(d.x, d.y, d.z)).ok_or(())
            })
            .ok()?;
        Some(TrapShape::new(&trap))
    }
}

/// A formula's trap: its own where `shape` is `None`, else the shape's
/// value of the orbit (see [`TrapShape`]).
pub(crate) struct TrapSlot<'a, T> {
    shape: Option<&'a TrapShape<T>>,
}

impl<'a, T: Num> TrapSlot<'a, T> {
    pub(crate) fn new(shape: Option<&'a TrapShape<T>>) -> Self {
        TrapSlot { shape }
    }

    /// The value before the first iterate: the formula's `own`, or the
    /// distance of the point itself (the orbit's start).
    pub(crate) fn start(&self, own: T, p: V3<T>) -> T {
        self.shape.map_or(own, |s| s.first(p))
    }

    /// The formula's own trap after a step (`own` its measure of the
    /// point), where there is no shape.
    pub(crate) fn own(&self, trap: T, own: impl FnOnce() -> T) -> T {
        match self.shape {
            Some(_) => trap,
            None => trap.min(own()),
        }
    }

    /// The shape's value after the orbit reaches `z`, where there is a
    /// shape. The shapes see the point and then each iterate once, where
    /// a formula may measure its own trap elsewhere in its step.
    pub(crate) fn shape(&self, trap: T, z: V3<T>) -> T {
        match self.shape {
            Some(s) => s.step(trap, z),
            None => trap,
        }
    }

    /// [`TrapSlot::shape`] for an iterate that counts only `within` the
    /// fractal's bailout: an escaped point is no part of the orbit a
    /// shape sees (and its size would only amplify rounding).
    pub(crate) fn shape_within(&self, trap: T, z: V3<T>, within: T::Bool) -> T {
        match self.shape {
            Some(s) => T::select(within, s.step(trap, z), trap),
            None => trap,
        }
    }

    /// The value returned: the formula's normalisation of its own, or the
    /// smallest distance as it is.
    pub(crate) fn end(&self, trap: T, own: impl FnOnce(T) -> T) -> T {
        match self.shape {
            Some(_) => trap,
            None => own(trap),
        }
    }
}
