//! Orbit traps and palettes (see [`scene::OrbitTrap`](crate::scene::OrbitTrap)),
//! written once for the CPU reference and the kernels: the fractals'
//! formulas take an optional [`TrapShape`] and keep the orbit's smallest
//! distance to it in place of their own trap.

use crate::ir::{Scalar, Vector, baked3};
use crate::math::{Num, V3, v3};
use crate::scene::Trap;

/// A trap as numbers, one formula for every [`Trap`]: the distance from
/// `z` is `| |across v + along axis (axis · v)| − radius |` with
/// `v = z − centre` (for a line, `v` less its part along the line: the
/// perpendicular, with no cancellation far from it).
///
/// | trap | `centre` | `axis` | `across` | `along` | `radius` |
/// |---|---|---|---|---|---|
/// | point | the point | 0 | 1 | 0 | 0 |
/// | sphere | its centre | 0 | 1 | 0 | its radius |
/// | plane | `offset · n` | the unit normal `n` | 0 | 1 | 0 |
/// | line | its point | its unit direction | 1 | −1 | 0 |
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
    /// Subtracted from the root: a sphere's radius.
    pub radius: T,
}

impl<T: Num> TrapShape<T> {
    /// The numbers of `trap` (its directions normalised here).
    #[must_use]
    pub fn new(trap: &Trap<T, V3<T>>) -> Self {
        let unit = |d: V3<T>| d * (T::one() / d.length().max(T::tiny()));
        let (zero, one) = (T::zero(), T::one());
        let none = V3::splat(zero);
        match *trap {
            Trap::Point { centre } => TrapShape {
                centre,
                axis: none,
                across: one,
                along: zero,
                radius: zero,
            },
            Trap::Sphere { centre, radius } => TrapShape {
                centre,
                axis: none,
                across: one,
                along: zero,
                radius,
            },
            Trap::Plane { normal, offset } => {
                let n = unit(normal);
                TrapShape {
                    centre: n * offset,
                    axis: n,
                    across: zero,
                    along: one,
                    radius: zero,
                }
            }
            Trap::Line { point, direction } => TrapShape {
                centre: point,
                axis: unit(direction),
                across: one,
                along: -one,
                radius: zero,
            },
        }
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
    /// `centre`, `axis` (three each), `across`, `along`, `radius`.
    #[must_use]
    pub fn values(&self) -> [T; 9] {
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
        ]
    }

    /// The trap from [`TrapShape::values`]' numbers.
    #[must_use]
    pub fn from_values(v: &[T]) -> Self {
        TrapShape {
            centre: v3(v[0], v[1], v[2]),
            axis: v3(v[3], v[4], v[5]),
            across: v[6],
            along: v[7],
            radius: v[8],
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

/// A formula's trap: its own where `shape` is `None`, else the orbit's
/// smallest distance to the shape.
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
        self.shape.map_or(own, |s| s.distance(p))
    }

    /// The value after the orbit reaches `z`.
    pub(crate) fn step(&self, trap: T, z: V3<T>, own: impl FnOnce() -> T) -> T {
        trap.min(self.shape.map_or_else(own, |s| s.distance(z)))
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
