//! Math shared by the CPU reference ([`crate::cpu`]) and code generation
//! ([`crate::codegen`]): the numeric guards both twins use, the scalar types
//! the reference is generic over, the values that code generation bakes
//! into literals exactly as the reference computes them, robust vector
//! normalisation, and the magnitudes each kernel precision can compute
//! with ([`Limits`]). Keeping them here, below every stage, is what lets the two
//! twins agree without either reaching into the other.

mod limits;
mod real;

use glam::DVec3;

pub(crate) use crate::expr::{DERIVATIVE_CAP, MAGNITUDE_CAP, REAL_TINY, V3, v3};
pub use limits::{F32_LIMITS, F64_LIMITS, Limits, Magnitude, reduce_angle};
pub(crate) use real::Num;
pub use real::Real;

/// The linear RGB colour of surfaces that no `color` node paints
/// (`DEFAULT_COLOR` in the kernels).
pub const DEFAULT_COLOR: [f64; 3] = [0.8, 0.8, 0.8];

/// The radius beyond which a Mandelbulb orbit escapes: `bailout`, or less
/// where `r^power` would pass [`MAGNITUDE_CAP`]. Computed in
/// `f64`; code generation emits the same value as a literal.
#[must_use]
pub fn escape_radius<T: Num>(power: T, bailout: T) -> T {
    bailout.min(T::of(MAGNITUDE_CAP).powf(T::one() / power))
}

/// The radius `2^(1 / (power - 1))` of the ball that holds the Mandelbulb
/// of `power`, and every point where its estimate is at most 0, for any
/// number of iterations and any bailout.
///
/// Proof. The power map scales lengths exactly, `|z^n| = |z|^n` (it is a
/// unit direction times `r^n`). Let `|p| > rho`, so `|p|^(n-1) > 2`. If
/// `|z_k| >= |p|` (true for `z_0 = p`), then `|z_(k+1)| = |z_k^n + p| >=
/// |z_k|^n - |p| >= |z_k| (|z_k|^(n-1) - 1) >= |z_k| (|p|^(n-1) - 1) >
/// |z_k|`. So the orbit grows strictly (and without bound): it never stays
/// bounded, and wherever the iteration stops (escaped or not) `|z| > |p| >
/// 1`, so `ln |z| > 0` and the estimate is positive. Hence for `|p| > rho`
/// the distance to the set is at least `|p| - rho`.
///
/// ```
/// use fractal_sdf::math::mandelbulb_radius;
/// assert_eq!(mandelbulb_radius(2.0_f64), 2.0);
/// assert!((mandelbulb_radius(8.0_f64) - 1.104).abs() < 1e-3);
/// ```
#[must_use]
pub fn mandelbulb_radius<T: Num>(power: T) -> T {
    T::of(2.0).powf(T::one() / (power - T::one()))
}

/// `(half_side, escape)` for the Mandelbox of `scale` (magnitude above 1)
/// and `fold_limit`, in Mandelbrot mode or with the Julia constant
/// `julia`: the set lies in the cube `[-half_side, half_side]^3`, and an
/// orbit whose largest coordinate passes `escape` grows without bound.
///
/// Proof. Each step lowers the largest coordinate's magnitude `a` by at
/// most `2L` (the box fold reflects a coordinate beyond `±L` in that
/// plane), never shrinks it (the sphere fold scales by at least 1),
/// multiplies it by `|s|` and adds at most `|c|∞`, so `a' >= |s| (a − 2L)
/// − |c|∞`, which is more than `a` once `a > (2L|s| + |c|∞) / (|s| − 1)`:
/// the escape threshold, and from there each step adds more than the
/// last. In Julia mode that is also the half side. In Mandelbrot mode
/// (`c = p`), follow one coordinate `x > L` of `p` alone (the sphere fold
/// only scales it further): with a negative scale `x' = |s| (x − 2L) + x`,
/// more than `x` once `x > 2L`, and the same holds at every later step (the
/// coordinate stays above `x`, and each step adds at least `|s| (x − 2L)`);
/// with a positive one the sign alternates: from `m > 2L` on the positive
/// side, `m' = s (m − 2L) − x` on the negative one, and from there `m'' =
/// s (m' − 2L) + x`, so `m'' − m = (s² − 1) (m − T)` with `T = 2Ls / (s − 1)
/// + x / (s + 1)`. Starting at `m = x > 2L (s + 1) / (s − 1)` puts `m`
/// above `T` and `m' = (s − 1) x − 2Ls` above `2L` (so each fold reflects
/// as written), and `m` only grows from there, each two steps by more
/// than the last. Either way the orbit grows without bound, so those are
/// the half sides, and inside the cube `|c|∞` is at most the half side.
///
/// ```
/// use fractal_sdf::math::mandelbox_extent;
/// assert_eq!(mandelbox_extent(2.0_f64, 1.0, None), (6.0, 10.0));
/// assert_eq!(mandelbox_extent(-1.5_f64, 1.0, None), (2.0, 10.0));
/// ```
#[must_use]
pub fn mandelbox_extent<T: Num>(scale: T, fold_limit: T, julia: Option<[T; 3]>) -> (T, T) {
    let s = scale.abs();
    let two_l = T::of(2.0) * fold_limit;
    // The largest |c|∞ in the cube: the constant's, or the half side.
    let c_max = match julia {
        Some([x, y, z]) => x.abs().max(y.abs()).max(z.abs()),
        None => T::select(
            scale.lt(T::zero()),
            two_l,
            two_l * (s + T::one()) / (s - T::one()),
        ),
    };
    let escape = (two_l * s + c_max) / (s - T::one());
    match julia {
        Some(_) => (escape, escape),
        None => (c_max, escape),
    }
}

/// The radius `R` of the ball about the origin that holds a kaleidoscopic
/// IFS ([`scene::Kifs`](crate::scene::Kifs)) of `offset`, for every scale
/// and turn: `|offset|`, or `|(offset.x, offset.y)| + |offset.z|` for the
/// Menger fold (`menger`).
///
/// Proof. One step is `z → M(s · T(z) − c)`: `T` turns and folds across
/// planes through the origin, so `|T(z)| = |z|`; `c` is the shift
/// `offset · (s − 1)` (with no `z` part for the Menger fold); `M` is
/// nothing, or the Menger fold's mirror across a plane at distance
/// `h = |offset.z| (s − 1) / 2` from the origin, which moves no point
/// nearer the origin than `2h` less. So `|z'| ≥ s |z| − |c| − 2h`, and with
/// `R = (|c| + 2h) / (s − 1)` (the radius above) `|z'| − R ≥ s (|z| − R)`:
/// past `R` an orbit grows by a factor `s > 1` each step and never returns.
/// The drawn set after `n` steps (the points whose orbit is then within
/// `R`) therefore only shrinks as `n` grows, and since each step is
/// `s`-Lipschitz (turns, folds and mirrors are 1-Lipschitz), a point whose
/// orbit is at `|z_n|` lies at least `(|z_n| − R) / s^n` from it.
///
/// ```
/// use fractal_sdf::math::kifs_radius;
/// assert_eq!(kifs_radius([3.0_f64, 0.0, 4.0], false), 5.0);
/// assert_eq!(kifs_radius([3.0_f64, 4.0, 1.0], true), 6.0);
/// ```
#[must_use]
pub fn kifs_radius<T: Num>(offset: [T; 3], menger: bool) -> T {
    let [x, y, z] = offset;
    if menger {
        x.hypot(y) + z.abs()
    } else {
        T::length3(x, y, z)
    }
}

/// The Mandelbulb power as an integer, when the trig-free integer form
/// applies to a baked `power`: an integer in `[2, 64]`. The CPU reference
/// and code generation make the same choice through it.
#[must_use]
pub fn integer_power(power: f64) -> Option<u32> {
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    (power.fract() == 0.0 && (2.0..=64.0).contains(&power)).then_some(power as u32)
}

/// `v` scaled to unit length, computed without overflow or underflow
/// however large or small its components (it is first divided by its
/// largest component); `None` for a zero or non-finite vector.
///
/// ```
/// use fractal_sdf::math::normalize;
/// use glam::dvec3;
/// assert_eq!(normalize(dvec3(0.0, 1e200, 0.0)), Some(dvec3(0.0, 1.0, 0.0)));
/// assert_eq!(normalize(dvec3(3e-300, 0.0, 4e-300)), Some(dvec3(0.6, 0.0, 0.8)));
/// assert_eq!(normalize(dvec3(0.0, 0.0, 0.0)), None);
/// ```
#[must_use]
pub fn normalize(v: DVec3) -> Option<DVec3> {
    let largest = v.abs().max_element();
    if !(largest.is_finite() && largest > 0.0) {
        return None;
    }
    let scaled = v / largest;
    Some(scaled / scaled.length())
}

/// The rows of the matrix rotating by `angle` around the unit `axis`,
/// computed in `f64`.
///
/// Entries within `1e-15` of 0 or ±1 are snapped to them, so quarter turns
/// are exact permutations (and code generation can drop the zero terms).
#[must_use]
pub fn rotation_rows(axis: DVec3, angle: f64) -> [V3<f64>; 3] {
    let snap = |v: f64| {
        let r = v.round();
        if (v - r).abs() < 1e-15 { r } else { v }
    };
    let m = glam::DMat3::from_axis_angle(axis, angle).transpose();
    [m.x_axis, m.y_axis, m.z_axis].map(|row| V3::from(row).map(snap))
}

/// The radius `1/2 + sqrt(1/4 + |c|)` of the ball that holds the quaternion
/// Julia set of `c` (the points whose orbits stay bounded).
///
/// Proof. It is the positive root of `r^2 - r - |c|`. For quaternions
/// `|z^2| = |z|^2`, so if `|z| > r` then `|z^2 + c| >= |z|^2 - |c| > |z|`,
/// and the excess `|z|^2 - |z| - |c|` grows with `|z|`: the orbit grows
/// without bound. Hence every bounded orbit stays within the ball, and a
/// point whose orbit ever leaves it is not in the set.
///
/// ```
/// use fractal_sdf::math::julia_radius;
/// assert_eq!(julia_radius([-2.0_f64, 0.0, 0.0, 0.0]), 2.0);
/// assert_eq!(julia_radius([0.0_f64, 0.0, 0.0, 0.0]), 1.0);
/// ```
#[must_use]
pub fn julia_radius<T: Num>(c: [T; 4]) -> T {
    let half = T::of(0.5);
    let norm = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2] + c[3] * c[3]).sqrt();
    half + (half * half + norm).sqrt()
}

/// Beyond `JULIA_FAR_FIELD` times the radius of its ball (the smaller of
/// [`julia_radius`] and the bailout) the quaternion Julia estimate is
/// [`JULIA_FAR_FIELD_SLOPE`] times the distance to that ball. Far from the
/// set the escape-time estimate grows like `0.5 r ln r`, faster than the
/// distance: it overestimates from about 2.3 radii, by 1.36 at 10 units
/// and 6.9 at 1e6 (measured over constants in and near the Mandelbrot
/// set), and every ray from a camera 10 units from the gallery's set
/// stepped past it. Up to 1.5 radii it was within 0.97 of the distance.
pub const JULIA_FAR_FIELD: f64 = 1.5;

/// The far-field estimate is `JULIA_FAR_FIELD_SLOPE` times the ball's
/// distance. The ball's exact distance grows by exactly the step along a
/// ray leaving it straight outward, and the soft-shadow penumbra estimate
/// (`march_shadow`) reads two distance spheres that touch that way as a
/// surface grazing the ray: shadow rays from the set, which start inside
/// the ball, came out dark. A slope below 1 keeps them apart (and costs
/// far-away rays about 8% more steps).
pub const JULIA_FAR_FIELD_SLOPE: f64 = 0.9;
