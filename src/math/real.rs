//! The scalar and vector types the CPU reference is generic over, so one
//! set of formulas runs in both `f64` and `f32` (the two precisions the
//! OpenCL kernels are compiled in).

use std::ops::{Add, Div, Mul, Neg, Sub};

use num_traits::{Float, FloatConst};

/// A floating-point type the reference evaluator can run in: `f32` or `f64`.
pub trait Real: Float + FloatConst + std::fmt::Debug + Send + Sync + 'static {
    /// Converts from `f64` (rounding to nearest for `f32`).
    fn of(v: f64) -> Self;
    /// The smallest magnitude used to guard divisions and logarithms. The
    /// OpenCL kernels use the same value (`1e-30`, a normal `f32`).
    fn tiny() -> Self {
        Self::of(super::REAL_TINY)
    }
    /// The cap on fractal running derivatives, so they never overflow to
    /// infinity (`1e30` in both precisions).
    fn derivative_cap() -> Self {
        Self::of(super::DERIVATIVE_CAP)
    }
    /// The largest magnitude an escape-time iteration may produce (`1e18`
    /// in both precisions): the squared length of a vector this long stays
    /// below `f32::MAX`, and dividing it by a capped derivative stays tiny.
    fn magnitude_cap() -> Self {
        Self::of(super::MAGNITUDE_CAP)
    }
}

impl Real for f32 {
    #[allow(clippy::cast_possible_truncation)]
    fn of(v: f64) -> Self {
        v as f32
    }
}

impl Real for f64 {
    fn of(v: f64) -> Self {
        v
    }
}

/// A 3-vector in either precision.
#[derive(Debug, Clone, Copy, PartialEq)]
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

impl<T: Real> V3<T> {
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
        self.dot(self).sqrt()
    }

    /// Euclidean length without overflow or underflow in the squares: the
    /// vector is divided by its largest component first (the kernels'
    /// `safe_length`, in `kernels/sdf/length.cl`). A zero or non-finite
    /// vector gives [`V3::length`].
    #[must_use]
    pub fn safe_length(self) -> T {
        let m = self.abs().max_element();
        if m > T::zero() && m.is_finite() {
            m * (self / m).length()
        } else {
            self.length()
        }
    }

    /// Component-wise absolute value.
    #[must_use]
    pub fn abs(self) -> Self {
        self.map(T::abs)
    }

    /// Component-wise maximum with a scalar.
    #[must_use]
    pub fn max_s(self, s: T) -> Self {
        self.map(|c| c.max(s))
    }

    /// The largest component.
    #[must_use]
    pub fn max_element(self) -> T {
        self.x.max(self.y).max(self.z)
    }

    /// The smallest component.
    #[must_use]
    pub fn min_element(self) -> T {
        self.x.min(self.y).min(self.z)
    }

    /// Converts to the other precision.
    #[must_use]
    pub fn cast<U: Real>(self) -> V3<U> {
        v3(
            U::of(self.x.to_f64().unwrap_or(f64::NAN)),
            U::of(self.y.to_f64().unwrap_or(f64::NAN)),
            U::of(self.z.to_f64().unwrap_or(f64::NAN)),
        )
    }
}

impl<T: Real> Add for V3<T> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        self.zip(o, |a, b| a + b)
    }
}

impl<T: Real> Sub for V3<T> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        self.zip(o, |a, b| a - b)
    }
}

impl<T: Real> Mul<T> for V3<T> {
    type Output = Self;
    fn mul(self, s: T) -> Self {
        self.map(|c| c * s)
    }
}

impl<T: Real> Mul for V3<T> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        self.zip(o, |a, b| a * b)
    }
}

impl<T: Real> Div for V3<T> {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        self.zip(o, |a, b| a / b)
    }
}

impl<T: Real> Div<T> for V3<T> {
    type Output = Self;
    fn div(self, s: T) -> Self {
        self.map(|c| c / s)
    }
}

impl<T: Real> Neg for V3<T> {
    type Output = Self;
    fn neg(self) -> Self {
        self.map(|c| -c)
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
