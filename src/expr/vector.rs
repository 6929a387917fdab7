//! The 3-vector every formula is written over, generic over [`Num`]: the
//! same code runs in `f32`, `f64`, intervals and traced variables.

use std::ops::{Add, Div, Mul, Neg, Sub};

use super::num::Num;
use super::ops::{Binary, Unary};

/// A 3-vector in either precision.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct V3<T> {
    /// x
    pub x: T,
    /// y
    pub y: T,
    /// z
    pub z: T,
}

/// Shorthand for [`V3`]'s constructor.
#[must_use]
pub fn v3<T>(x: T, y: T, z: T) -> V3<T> {
    V3 { x, y, z }
}

impl<T: Num> V3<T> {
    /// All components `v`.
    #[must_use]
    pub fn splat(v: T) -> Self {
        v3(v, v, v)
    }

    /// Component `i` (0, 1, 2).
    #[must_use]
    pub fn get(self, i: usize) -> T {
        [self.x, self.y, self.z][i]
    }

    /// A copy with component `i` replaced.
    #[must_use]
    pub fn with(self, i: usize, v: T) -> Self {
        let mut a = [self.x, self.y, self.z];
        a[i] = v;
        v3(a[0], a[1], a[2])
    }

    /// Applies `f` to each component.
    #[must_use]
    pub fn map(self, f: impl Fn(T) -> T) -> Self {
        v3(f(self.x), f(self.y), f(self.z))
    }

    /// Combines two vectors component by component.
    #[must_use]
    pub fn zip(self, o: Self, f: impl Fn(T, T) -> T) -> Self {
        v3(f(self.x, o.x), f(self.y, o.y), f(self.z, o.z))
    }

    /// Dot product.
    #[must_use]
    pub fn dot(self, o: Self) -> T {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Cross product.
    #[must_use]
    pub fn cross(self, o: Self) -> Self {
        v3(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }

    /// Euclidean length.
    #[must_use]
    pub fn length(self) -> T {
        T::length3(self.x, self.y, self.z)
    }

    /// Euclidean length without overflow or underflow in the squares: the
    /// vector is divided by its largest component first. A zero or
    /// non-finite vector gives [`V3::length`].
    #[must_use]
    pub fn safe_length(self) -> T {
        let m = self.abs().max_element();
        T::select(
            m.gt(T::zero()) & m.finite(),
            m * (self / m).length(),
            self.length(),
        )
    }

    /// Component-wise absolute value.
    #[must_use]
    pub fn abs(self) -> Self {
        Self::from_array(T::unary3(Unary::Abs, self.to_array()))
    }

    /// Component-wise minimum.
    #[must_use]
    pub fn min(self, o: Self) -> Self {
        self.op(Binary::Min, o)
    }

    /// Component-wise maximum.
    #[must_use]
    pub fn max(self, o: Self) -> Self {
        self.op(Binary::Max, o)
    }

    /// Component-wise maximum with a scalar.
    #[must_use]
    pub fn max_s(self, s: T) -> Self {
        self.op(Binary::Max, Self::splat(s))
    }

    /// The components as an array.
    #[must_use]
    pub fn to_array(self) -> [T; 3] {
        [self.x, self.y, self.z]
    }

    /// The vector of an array's components.
    #[must_use]
    pub fn from_array([x, y, z]: [T; 3]) -> Self {
        v3(x, y, z)
    }

    /// A component-wise operation (one vector operation when traced).
    fn op(self, b: Binary, o: Self) -> Self {
        Self::from_array(T::binary3(b, self.to_array(), o.to_array()))
    }

    /// The largest component.
    #[must_use]
    pub fn max_element(self) -> T {
        self.x.max(self.y).max(self.z)
    }

    /// `a` where `c` holds, else `b`, component by component.
    #[must_use]
    pub fn select(c: T::Bool, a: Self, b: Self) -> Self {
        Self::from_array(T::select3(c, a.to_array(), b.to_array()))
    }

    /// The smallest component.
    #[must_use]
    pub fn min_element(self) -> T {
        self.x.min(self.y).min(self.z)
    }
}

impl<T: Num> Add for V3<T> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        self.op(Binary::Add, o)
    }
}

impl<T: Num> Sub for V3<T> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        self.op(Binary::Sub, o)
    }
}

impl<T: Num> Mul<T> for V3<T> {
    type Output = Self;
    fn mul(self, s: T) -> Self {
        self.op(Binary::Mul, Self::splat(s))
    }
}

impl<T: Num> Mul for V3<T> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        self.op(Binary::Mul, o)
    }
}

impl<T: Num> Div for V3<T> {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        self.op(Binary::Div, o)
    }
}

impl<T: Num> Div<T> for V3<T> {
    type Output = Self;
    fn div(self, s: T) -> Self {
        self.op(Binary::Div, Self::splat(s))
    }
}

impl<T: Num> Neg for V3<T> {
    type Output = Self;
    fn neg(self) -> Self {
        Self::from_array(T::unary3(Unary::Neg, self.to_array()))
    }
}

impl From<glam::DVec3> for V3<f64> {
    fn from(v: glam::DVec3) -> Self {
        v3(v.x, v.y, v.z)
    }
}

impl From<V3<f64>> for glam::DVec3 {
    fn from(v: V3<f64>) -> Self {
        glam::DVec3::new(v.x, v.y, v.z)
    }
}

impl From<glam::Vec3> for V3<f32> {
    fn from(v: glam::Vec3) -> Self {
        v3(v.x, v.y, v.z)
    }
}

impl From<V3<f32>> for glam::Vec3 {
    fn from(v: V3<f32>) -> Self {
        glam::Vec3::new(v.x, v.y, v.z)
    }
}
