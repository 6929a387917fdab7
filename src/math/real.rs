//! The scalar types the CPU reference is generic over, so one set of
//! formulas runs in both `f64` and `f32` (the two precisions the OpenCL
//! kernels are compiled in).

pub use crate::expr::Num;
use crate::expr::{V3, v3};

/// A floating-point type the reference evaluator can run in: `f32` or `f64`.
///
/// A [`Num`] whose comparisons are plain `bool`s, with an order and a
/// conversion to `f64`: what the evaluator's own control flow needs
/// beyond the formulas.
pub trait Real: Num<Bool = bool> + PartialOrd + Send + Sync {
    /// The value as `f64` (exact).
    fn to_f64(self) -> f64;
}

impl Real for f32 {
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}

impl Real for f64 {
    fn to_f64(self) -> f64 {
        self
    }
}

/// Counts the CPU reference's operations (see [`counting`](crate::expr::counting)).
impl Real for crate::expr::Counted {
    fn to_f64(self) -> f64 {
        self.value()
    }
}

impl<T: Real> V3<T> {
    /// Converts to the other precision.
    #[must_use]
    pub fn cast<U: Real>(self) -> V3<U> {
        v3(
            U::of(self.x.to_f64()),
            U::of(self.y.to_f64()),
            U::of(self.z.to_f64()),
        )
    }
}
