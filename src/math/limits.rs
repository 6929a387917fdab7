//! What each kernel precision can compute with: the one table of the
//! magnitudes a value may take, which every stage checks against.
//!
//! The kernel squares lengths (`length`, `dot`), divides coordinates by
//! sizes (a scale factor, a repetition period, an ellipsoid's radii) and
//! multiplies distances by pixel footprints. For all of that to stay
//! finite and resolved, a value must lie within its precision's
//! [`Limits`]:
//!
//! | precision | largest magnitude | smallest nonzero size | resolution |
//! |---|---|---|---|
//! | `F32` | `1e18` | `1e-18` | `2^-20` (about `9.5e-7`) |
//! | `F64` | `1e150` | `1e-150` | `2^-49` (about `1.8e-15`) |
//!
//! - The largest magnitude `max`: the sum of three squares of values this
//!   large stays below the type's largest finite number (`3 · 1e36 <
//!   3.4e38` in `f32`, `3 · 1e300 < 1.8e308` in `f64`), and so does a
//!   coordinate divided by the smallest size (`1e18 / 1e-18 = 1e36`).
//! - The smallest nonzero size `min = 1 / max`: its square is still a
//!   normal number (`1e-36 > f32::MIN_POSITIVE`, `1e-300 >
//!   f64::MIN_POSITIVE`), so lengths of vectors this small do not flush to
//!   zero.
//! - The resolution: eight units in the last place of a number in `[1,
//!   2)`. Positions are rounded to about a sixteenth of it (relative to
//!   the scene's scale), so the smallest pixel footprint is this much of
//!   the scene's scale (`render::Viewport::relative_floor`); a quality knob
//!   measured in footprints below it asks for a threshold finer than the
//!   rounding squared, which nothing can compute.
//!
//! Scene values are held to the `F64` limits when a scene is compiled (the
//! CPU reference computes in `f64`), and to the limits of the kernel's
//! precision when a program is generated (baked values) and when a
//! renderer uploads them (dynamic values, the camera, the lights).

use std::f64::consts::TAU;

/// The magnitudes a value may take in one kernel precision.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Limits {
    /// The precision's name, as messages say it: `"F32"` or `"F64"`.
    pub precision: &'static str,
    /// The largest magnitude of any value.
    pub max: f64,
    /// The smallest nonzero magnitude of a size (a value the kernel
    /// squares or divides by).
    pub min: f64,
    /// The smallest knob measured in pixel footprints: eight units in the
    /// last place of a number in `[1, 2)`.
    pub resolution: f64,
}

/// The limits of the `F32` kernels.
pub const F32_LIMITS: Limits = Limits {
    precision: "F32",
    max: 1e18,
    min: 1e-18,
    resolution: 8.0 * f32::EPSILON as f64,
};

/// The limits of the `F64` kernels and of the CPU reference.
pub const F64_LIMITS: Limits = Limits {
    precision: "F64",
    max: 1e150,
    min: 1e-150,
    resolution: 8.0 * f64::EPSILON,
};

/// How the kernel uses a value, which decides the limits it keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Magnitude {
    /// Only added and multiplied (a coordinate, an offset, a rate): its
    /// magnitude is at most `max`.
    Coordinate,
    /// Squared or divided by (a radius, a factor, a period): 0, or a
    /// magnitude from `min` to `max`.
    Size,
    /// Reduced or normalised in `f64` before any kernel sees it (a baked
    /// direction, an angle): any finite value.
    Free,
}

impl Limits {
    /// The limit `v` passes, if it passes one: `max` or `min` (with the
    /// sign of `v`). A non-finite value passes `max`.
    #[must_use]
    pub fn crossed(&self, v: f64, magnitude: Magnitude) -> Option<f64> {
        let a = v.abs();
        match magnitude {
            Magnitude::Free => None,
            _ if a.is_nan() || a > self.max => Some(self.max.copysign(v)),
            Magnitude::Size if a != 0.0 && a < self.min => Some(self.min.copysign(v)),
            _ => None,
        }
    }
}

/// `angle` reduced modulo the `f64` value of 2π, exactly (`%` is exact):
/// in `(-2π, 2π)` with the sign of `angle`, and unchanged when already
/// there. Every rotation angle is reduced so before the CPU reference or a
/// kernel uses it, so both turn by the same angle however large it is
/// (beyond about `1e15` radians an `f64` angle no longer resolves a turn,
/// so the rotation is arbitrary, but finite and the same everywhere).
#[must_use]
pub fn reduce_angle(angle: f64) -> f64 {
    angle % TAU
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_limits_keep_squares_and_quotients_finite_and_normal() {
        let f = F32_LIMITS;
        #[allow(clippy::cast_possible_truncation)]
        let (max, min) = (f.max as f32, f.min as f32);
        assert!((3.0 * max * max).is_finite());
        assert!((max / min).is_finite() && (min * min).is_normal());
        let d = F64_LIMITS;
        assert!((3.0 * d.max * d.max).is_finite());
        assert!((d.max / d.min).is_finite() && (d.min * d.min).is_normal());
    }

    #[test]
    fn sizes_keep_a_floor_and_coordinates_do_not() {
        let l = F32_LIMITS;
        assert_eq!(l.crossed(1e-30, Magnitude::Coordinate), None);
        assert_eq!(l.crossed(-1e-30, Magnitude::Size), Some(-1e-18));
        assert_eq!(l.crossed(0.0, Magnitude::Size), None);
        assert_eq!(l.crossed(-2e18, Magnitude::Coordinate), Some(-1e18));
        assert_eq!(l.crossed(f64::NAN, Magnitude::Size), Some(1e18));
        assert_eq!(l.crossed(1e300, Magnitude::Free), None);
    }

    #[test]
    fn angles_reduce_exactly_and_keep_small_ones() {
        for a in [0.0, 0.5, -3.0, 6.0] {
            assert_eq!(reduce_angle(a), a);
        }
        let r = reduce_angle(1e300);
        assert!(r.is_finite() && r.abs() < TAU);
        assert!((reduce_angle(TAU + 1.0) - 1.0).abs() < 1e-15);
    }
}
