//! Distance formulas for every primitive, fractal, domain operation and
//! boolean, each written once.
//!
//! Every formula here is generic over [`Num`]: the CPU reference runs it
//! in `f32`/`f64`, bounds run it in intervals, and code generation traces
//! it into the expression IR ([`crate::expr`]) and prints the kernels'
//! helpers from it, so there is no second copy to drift. Value-dependent
//! choices are [`Num::select`]s and the fractals' loops are
//! [`Num::iterate`]s (bounded, with early exits), so tracing records them
//! instead of running them. The conformance tests still compare the CPU
//! and the device on random and spicy points: they now test the printer.
//!
//! Sources: the primitives and smooth minimum follow Inigo Quilez's
//! "distance functions" article; the fractal estimators follow Quilez
//! (quaternion Julia), White/Nylander and Hart (Mandelbulb) and Knighty's
//! kaleidoscopic IFS (Menger, Sierpinski).

use crate::expr::Step;
use crate::math::{
    JULIA_FAR_FIELD, JULIA_FAR_FIELD_SLOPE, Num, Real, V3, escape_radius, julia_radius,
    kifs_radius, mandelbox_extent, mandelbulb_radius, v3,
};
use crate::scene::{CsgOp, KifsFold};

mod hybrid;
mod kleinian;
mod profile;
mod shapes;
mod trap;

pub use kleinian::{PSEUDO_KLEINIAN_SAFETY, pseudo_kleinian, pseudo_kleinian_estimate};
pub use profile::{extrude, profile, revolve};
pub use shapes::{
    box_frame, cone, cut_hollow_sphere, death_star, infinite_cone, infinite_cylinder, pyramid,
    quad, rhombus, rounded_cylinder, tri_prism, triangle, triangle_unsigned,
};

pub use trap::TrapShape;
pub(crate) use trap::TrapSlot;

pub(crate) use hybrid::hybrid_integer_powers;
pub use hybrid::{
    HYBRID_FAR_FIELD, HYBRID_FOLLOW, HYBRID_POWER_REACH, HYBRID_POWER_SAFETY, HYBRID_SAFETY,
    hybrid, hybrid_estimate,
};

/// Exact distance to a sphere of radius `r` at the origin.
#[must_use]
pub fn sphere<T: Num>(p: V3<T>, r: T) -> T {
    p.length() - r
}

/// Quilez's cheap bound of the octahedron `|x| + |y| + |z| <= s`: the
/// distance to the plane of the nearest face, `(|x| + |y| + |z| − s) /
/// √3`. Exact where the nearest point lies inside a face, below the
/// distance elsewhere.
#[must_use]
pub fn octahedron_bound<T: Num>(p: V3<T>, s: T) -> T {
    let p = p.abs();
    (p.x + p.y + p.z - s) * T::of(1.0 / 3f64.sqrt())
}

/// Exact distance to an axis-aligned box with half extents `b`.
#[must_use]
pub fn cuboid<T: Num>(p: V3<T>, b: V3<T>) -> T {
    let q = p.abs() - b;
    q.max_s(T::zero()).length() + q.max_element().min(T::zero())
}

/// Exact distance to a box of half extents `b` with edges rounded by `r`.
#[must_use]
pub fn round_box<T: Num>(p: V3<T>, b: V3<T>, r: T) -> T {
    let q = p.abs() - b + V3::splat(r);
    q.max_s(T::zero()).length() + q.max_element().min(T::zero()) - r
}

/// Exact distance to a torus around the y axis where `minor <= major`
/// (the distance to the tube's centre circle minus `minor`); a thicker
/// torus overlaps itself around the axis, and there this is a bound.
#[must_use]
pub fn torus<T: Num>(p: V3<T>, major: T, minor: T) -> T {
    let qx = p.x.hypot(p.z) - major;
    qx.hypot(p.y) - minor
}

/// Exact distance to a capped cylinder along y.
#[must_use]
pub fn cylinder<T: Num>(p: V3<T>, r: T, h: T) -> T {
    let dx = p.x.hypot(p.z) - r;
    let dy = p.y.abs() - h;
    dx.max(dy).min(T::zero()) + dx.max(T::zero()).hypot(dy.max(T::zero()))
}

/// Exact distance to a capsule around the segment `a`-`b`.
#[must_use]
pub fn capsule<T: Num>(p: V3<T>, a: V3<T>, b: V3<T>, r: T) -> T {
    let pa = p - a;
    let ba = b - a;
    let h = (pa.dot(ba) / ba.dot(ba).max(T::tiny()))
        .max(T::zero())
        .min(T::one());
    (pa - ba * h).length() - r
}

/// Exact distance to the half-space `dot(p, n) + offset <= 0` (`n` is
/// normalised here, after dividing it by its largest component so that no
/// square of a tiny or huge component is formed; a zero `n` gives the
/// constant `offset`).
#[must_use]
pub fn plane<T: Num>(p: V3<T>, n: V3<T>, offset: T) -> T {
    let m = n.abs().max_element();
    let scaled = n / m;
    let n = V3::select(m.gt(T::zero()), scaled / scaled.length(), n);
    p.dot(n) + offset
}

/// Exact distance to the octahedron `|x| + |y| + |z| <= s`.
#[must_use]
pub fn octahedron<T: Num>(p: V3<T>, s: T) -> T {
    let p = p.abs();
    let m = p.x + p.y + p.z - s;
    let three = T::of(3.0);
    let (cx, cy, cz) = (
        (three * p.x).lt(m),
        (three * p.y).lt(m),
        (three * p.z).lt(m),
    );
    let q = V3::select(cx, p, V3::select(cy, v3(p.y, p.z, p.x), v3(p.z, p.x, p.y)));
    let k = (T::of(0.5) * (q.z - q.y + s)).max(T::zero()).min(s);
    T::select(
        cx | cy | cz,
        v3(q.x, q.y - s + k, q.z - k).length(),
        m * T::of(0.577_350_269_189_625_8),
    )
}

/// Exact distance to a capped cone along y: radius `r1` at `-h`, `r2` at
/// `+h`.
#[must_use]
pub fn capped_cone<T: Num>(p: V3<T>, h: T, r1: T, r2: T) -> T {
    let (qx, qy) = (p.x.hypot(p.z), p.y);
    let (k1x, k1y) = (r2, h);
    let (k2x, k2y) = (r2 - r1, T::of(2.0) * h);
    let cap_r = T::select(qy.lt(T::zero()), r1, r2);
    let (cax, cay) = (qx - qx.min(cap_r), qy.abs() - h);
    let k2_len2 = (k2x * k2x + k2y * k2y).max(T::tiny());
    let t = (((k1x - qx) * k2x + (k1y - qy) * k2y) / k2_len2)
        .max(T::zero())
        .min(T::one());
    let (cbx, cby) = (qx - k1x + k2x * t, qy - k1y + k2y * t);
    let s = T::select(cbx.lt(T::zero()) & cay.lt(T::zero()), -T::one(), T::one());
    s * (cax * cax + cay * cay).min(cbx * cbx + cby * cby).sqrt()
}

/// Exact distance to a hexagonal prism along y: the hexagon in the xz
/// plane has its flat sides `r` from the axis (two of them facing ±z) and
/// the prism runs from `-h` to `+h` (Quilez's `sdHexPrism`, its axis
/// turned to y).
#[must_use]
pub fn hex_prism<T: Num>(p: V3<T>, r: T, h: T) -> T {
    // (-cos 30°, sin 30°) and tan 30°.
    let (kx, ky, kz) = (
        T::of(-0.866_025_403_784_438_6),
        T::of(0.5),
        T::of(0.577_350_269_189_625_8),
    );
    let q = p.abs();
    // Fold the hexagon's plane (x, z) into the sector of its +z side.
    let fold = T::of(2.0) * (kx * q.x + ky * q.z).min(T::zero());
    let (x, z) = (q.x - fold * kx, q.z - fold * ky);
    let edge = kz * r;
    let side = z - r;
    let dx = (x - x.clamp(-edge, edge)).hypot(side);
    let d = (T::select(side.lt(T::zero()), -dx, dx), q.y - h);
    d.0.max(d.1).min(T::zero()) + d.0.max(T::zero()).hypot(d.1.max(T::zero()))
}

/// Exact distance to a round cone along y: the convex hull of the ball of
/// radius `r1` at `y = -h` and the ball of radius `r2` at `y = +h`
/// (Quilez's `sdRoundCone`, centred); where one ball holds the other, the
/// larger ball.
#[must_use]
pub fn round_cone<T: Num>(p: V3<T>, h: T, r1: T, r2: T) -> T {
    let length = T::of(2.0) * h;
    let (qx, qy) = (p.x.hypot(p.z), p.y + h);
    let bottom = qx.hypot(qy) - r1;
    let top = qx.hypot(qy - length) - r2;
    // The sine and cosine of the side's slope.
    let b = (r1 - r2) / length.max(T::tiny());
    let a = (T::one() - b * b).max(T::zero()).sqrt();
    let k = -b * qx + a * qy;
    let side = a * qx + b * qy - r1;
    let hull = T::select(
        k.lt(T::zero()),
        bottom,
        T::select(k.gt(a * length), top, side),
    );
    // One ball holds the other: `|r1 - r2| >= 2h`.
    T::select((r1 - r2).abs().ge(length), bottom.min(top), hull)
}

/// The point `p` in the frame of the segment `a`-`b`: as a point of the
/// plane through the segment, its distance from the segment's line as `x`
/// and its height along the segment from the midpoint as `y` (`z` 0), and
/// half the segment's length. A segment of length 0 is taken along y.
/// The solids of revolution along y ([`cylinder`], [`capped_cone`],
/// [`round_cone`]) read only `|p.xz|` and `p.y`, so at this point they
/// give the same solid along the segment.
fn segment_frame<T: Num>(p: V3<T>, a: V3<T>, b: V3<T>) -> (V3<T>, T) {
    let ba = b - a;
    let length = ba.length();
    let axis = V3::select(
        length.gt(T::tiny()),
        ba / length.max(T::tiny()),
        v3(T::zero(), T::one(), T::zero()),
    );
    let q = p - (a + b) * T::of(0.5);
    let y = q.dot(axis);
    (
        v3((q - axis * y).length(), y, T::zero()),
        length * T::of(0.5),
    )
}

/// Exact distance to the capped cylinder of radius `r` around the segment
/// `a`-`b` (Quilez's arbitrary `sdCappedCylinder`), through the segment's
/// frame and [`cylinder`].
#[must_use]
pub fn cylinder_between<T: Num>(p: V3<T>, a: V3<T>, b: V3<T>, r: T) -> T {
    let (q, h) = segment_frame(p, a, b);
    cylinder(q, r, h)
}

/// Exact distance to the capped cone around the segment `a`-`b`, of
/// radius `ra` at `a` and `rb` at `b` (Quilez's arbitrary
/// `sdCappedCone`), through the segment's frame and [`capped_cone`].
#[must_use]
pub fn cone_between<T: Num>(p: V3<T>, a: V3<T>, b: V3<T>, ra: T, rb: T) -> T {
    let (q, h) = segment_frame(p, a, b);
    capped_cone(q, h, ra, rb)
}

/// Exact distance to the convex hull of the ball of radius `ra` about `a`
/// and the ball of radius `rb` about `b` (Quilez's arbitrary
/// `sdRoundCone`), through the segment's frame and [`round_cone`].
#[must_use]
pub fn round_cone_between<T: Num>(p: V3<T>, a: V3<T>, b: V3<T>, ra: T, rb: T) -> T {
    let (q, h) = segment_frame(p, a, b);
    round_cone(q, h, ra, rb)
}

/// Exact distance to a chain link in the xy plane: a tube of radius `r2`
/// around the stadium made of two segments at `x = ±r1` from `y = -le` to
/// `le` and two half circles of radius `r1` (Quilez's `sdLink`); exact
/// where `r2 <= r1`.
#[must_use]
pub fn link<T: Num>(p: V3<T>, le: T, r1: T, r2: T) -> T {
    let y = (p.y.abs() - le).max(T::zero());
    (p.x.hypot(y) - r1).hypot(p.z) - r2
}

/// Exact distance to the ball of radius `r` cut by the plane `y = h`
/// (taken within `[-r, r]`), keeping the part below. Inside, the nearer of
/// the sphere and the plane (the outside of an intersection is the union of
/// the outsides); outside, the plane where the point lies over the cut
/// face, the sphere where its radial projection lies below the plane, and
/// otherwise the cut face's rim.
#[must_use]
pub fn cut_sphere<T: Num>(p: V3<T>, r: T, h: T) -> T {
    let h = h.max(-r).min(r);
    let w = (r * r - h * h).max(T::zero()).sqrt();
    let (rho, y) = (p.x.hypot(p.z), p.y);
    let len = rho.hypot(y);
    let sphere = len - r;
    let plane = y - h;
    let outside = T::select(
        y.gt(h) & rho.le(w),
        plane,
        T::select(
            len.ge(r) & (r * y).le(h * len),
            sphere,
            (rho - w).hypot(plane),
        ),
    );
    T::select(len.le(r) & y.le(h), sphere.max(plane), outside)
}

/// Exact distance to the part of the ball of radius `r` within `angle` of
/// the +y axis. In the plane through the axis the shape is a circular
/// sector: its boundary is the cone's side (the segment from the origin to
/// `r (sin angle, cos angle)`) and the arc, which is nearer than the side
/// only within the cone's directions.
#[must_use]
pub fn solid_angle<T: Num>(p: V3<T>, angle: T, r: T) -> T {
    let (s, c) = (angle.sin(), angle.cos());
    let (rho, y) = (p.x.hypot(p.z), p.y);
    let len = rho.hypot(y);
    let t = (rho * s + y * c).max(T::zero()).min(r);
    let side = (rho - s * t).hypot(y - c * t);
    // Within the cone's directions: on the axis's side of the cone's line,
    // or on the line's own half (the other half meets the axis only where
    // the cone is a ray, `angle` 0).
    let cross = c * rho - s * y;
    let within = cross.lt(T::zero()) | (cross.le(T::zero()) & (rho * s + y * c).ge(T::zero()));
    T::select(
        within & len.le(r),
        -side.min(r - len),
        T::select(within, side.min(len - r), side),
    )
}

/// Exact distance to the tube of radius `minor` around the arc of the
/// circle of radius `major` in the xy plane within `angle` of +y (where
/// `minor <= major` and the end caps do not meet): the distance to the
/// arc's nearest point, minus `minor`. Folded to `x >= 0`, the nearest
/// point is the point's own direction on the circle while its angle from
/// +y is within the arc's, else the arc's end; measured as the length of
/// the difference, with no cancellation near the arc.
#[must_use]
pub fn capped_torus<T: Num>(p: V3<T>, angle: T, major: T, minor: T) -> T {
    let (s, c) = (angle.sin(), angle.cos());
    let x = p.x.abs();
    let rho = x.hypot(p.y);
    // Past the end: the point's angle from +y beyond the arc's (a cross
    // product's sign cannot tell the ray opposite the end from the end).
    let past = x.atan2(p.y).gt(angle);
    let on_axis = rho.le(T::tiny());
    let (ux, uy) = (
        T::select(past, s, T::select(on_axis, T::zero(), x / rho)),
        T::select(past, c, T::select(on_axis, T::one(), p.y / rho)),
    );
    T::length3(x - major * ux, p.y - major * uy, p.z) - minor
}

/// A distance bound for an axis-aligned ellipsoid with semi-axes `r`.
///
/// Outside, Quilez's `k0 (k0 - 1) / k1` with `k0 = |p / r|` and
/// `k1 = |p / r²|`, computed as `(k0 - 1) / |u / r|` with `u = (p / r) / k0`
/// (the same value, as `k1 = k0 |u / r|`) and with lengths that scale
/// first ([`V3::safe_length`]): no square of `p / r` or `p / r²` is
/// formed, so radii from the smallest to the largest a precision allows
/// give a finite bound, never above `|p|`. Inside, that formula
/// overestimates (by up to the ratio of the longest to the shortest
/// semi-axis, and it is 0 at the centre), so the interior uses
/// `(k0 - 1) min(r)`: scaling by `1 / r` stretches no length by more than
/// `1 / min(r)`, so this never exceeds the true depth.
#[must_use]
pub fn ellipsoid<T: Num>(p: V3<T>, r: V3<T>) -> T {
    let q = p / r;
    let k0 = q.safe_length();
    let k1 = (q / k0 / r).safe_length();
    T::select(
        k0.lt(T::one()),
        (k0 - T::one()) * r.min_element(),
        (k0 - T::one()) / k1.max(T::tiny()),
    )
}

/// A distance estimate with its orbit trap in `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Estimate<T> {
    /// The distance estimate (a bound).
    pub distance: T,
    /// The orbit trap, for colouring.
    pub trap: T,
}

/// `x^n` by binary exponentiation, with no multiplication by 1 (`x^0` is
/// 1).
#[must_use]
pub fn pow_int<T: Num>(x: T, n: u32) -> T {
    let mut result: Option<T> = None;
    let mut base = x;
    let mut e = n;
    while e > 0 {
        if e & 1 == 1 {
            result = Some(result.map_or(base, |r| r * base));
        }
        e >>= 1;
        if e > 0 {
            base = base * base;
        }
    }
    result.unwrap_or_else(T::one)
}

/// `(cos, sin)` of `n` times the angle whose cosine and sine are `(c, s)`,
/// by binary exponentiation of `c + i s`: the trig-free integer power.
fn angle_power<T: Num>(c: T, s: T, n: u32) -> (T, T) {
    let mut result: Option<(T, T)> = None;
    let (mut bc, mut bs) = (c, s);
    let mut e = n;
    while e > 0 {
        if e & 1 == 1 {
            result = Some(match result {
                None => (bc, bs),
                Some((rc, rs)) => (rc * bc - rs * bs, rc * bs + rs * bc),
            });
        }
        e >>= 1;
        if e > 0 {
            (bc, bs) = (bc * bc - bs * bs, T::of(2.0) * bc * bs);
        }
    }
    result.unwrap_or((T::one(), T::zero()))
}

/// The unit direction of the triplex power `z^power` of `z` (of length
/// `r`): its polar angle and azimuth times `power`. With `integer`, by
/// binary exponentiation of the angles' cosines and sines, with no
/// trigonometry; on the `z` axis the azimuth is 0.
pub(crate) fn triplex_direction<T: Num>(z: V3<T>, r: T, power: T, integer: Option<u32>) -> V3<T> {
    let (st, ct, sp, cp) = match integer {
        Some(n) => {
            let rho = z.x.hypot(z.y);
            let inv_r = T::one() / r.max(T::tiny());
            let (ct, st) = angle_power(z.z * inv_r, rho * inv_r, n);
            // On the z axis the azimuth is 0.
            let off_axis = rho.gt(T::tiny());
            let (cp, sp) = angle_power(
                T::select(off_axis, z.x / rho, T::one()),
                T::select(off_axis, z.y / rho, T::zero()),
                n,
            );
            (st, ct, sp, cp)
        }
        None => {
            let cos_theta = (z.z / r.max(T::tiny())).clamp(-T::one(), T::one());
            let theta = cos_theta.acos() * power;
            let phi = z.y.atan2(z.x) * power;
            (theta.sin(), theta.cos(), phi.sin(), phi.cos())
        }
    };
    v3(st * cp, st * sp, ct)
}

/// Tom Lowe's box fold of one coordinate: reflected back where it is
/// beyond `±limit`.
pub(crate) fn box_fold<T: Num>(v: T, limit: T) -> T {
    v.clamp(-limit, limit) * T::of(2.0) - v
}

/// The sphere fold's scale of a point at squared radius `r2`: `fixed2 /
/// min2` within the inner radius, `fixed2 / r2` between the radii, 1
/// beyond (`min2` at most `fixed2`).
pub(crate) fn sphere_fold_factor<T: Num>(r2: T, min2: T, fixed2: T) -> T {
    T::select(
        r2.lt(min2),
        (fixed2 / min2).min(T::derivative_cap()),
        T::select(r2.lt(fixed2), fixed2 / r2.max(T::tiny()), T::one()),
    )
}

/// Beyond `MANDELBULB_FAR_FIELD` times [`mandelbulb_radius`] the
/// Mandelbulb's distance is the distance to its bounding ball alone.
///
/// The escape-time estimate grows like `0.5 r ln r` far from the set, faster
/// than the distance: it overestimates from about 4 to 5 times the radius
/// (measured over powers 2 to 64, bailouts 1 to 1e6, 4 to 32 iterations; 2
/// times for power 2). At 1.5 times the ball bound is as large as the
/// estimate for power 8, and the estimate is sound there for every power.
pub const MANDELBULB_FAR_FIELD: f64 = 1.5;

/// The Mandelbulb distance estimate `0.5 ln(r) r / dr`, bounded by the
/// ball that holds the set.
///
/// `integer_power` selects the trig-free form (`Some(n)` must equal
/// `power`); otherwise the map uses `acos`/`atan2`/`sin`/`cos`. The orbit
/// trap is the smallest `|z|` reached, clamped to `[0, 1]`. The orbit
/// escapes beyond `bailout`, or sooner if `r^power` would pass
/// [`Num::magnitude_cap`] (only for large powers and bailouts): see
/// [`escape_radius`]. The formula itself is
/// [`mandelbulb_estimate`].
#[must_use]
pub fn mandelbulb<T: Real>(
    p: V3<T>,
    power: T,
    iterations: u32,
    bailout: T,
    integer_power: Option<u32>,
) -> Estimate<T> {
    // Escape before r^power passes the magnitude cap: beyond it r^power
    // overflows to infinity (and NaN), and once `dr` is capped a huge r
    // inflates the estimate.
    let escape = T::of(escape_radius(power.to_f64(), bailout.to_f64()));
    let count = T::of(f64::from(iterations));
    mandelbulb_estimate(
        p,
        power,
        count,
        escape,
        mandelbulb_radius(power),
        integer_power,
        None,
    )
}

/// The Mandelbulb estimate, written once (the CPU reference and the
/// kernels' `mandelbulb` helpers): `iterations` steps at most, escaping
/// beyond `escape`, in the ball of radius `ball`.
///
/// With `outer = |p| - ball` (a proven lower bound of the distance outside
/// the ball, and an upper bound of the depth inside it): beyond
/// [`MANDELBULB_FAR_FIELD`]` * ball` the result is `outer` and the trap 1
/// (what the orbit gives there, as `|z| > 1`), with no iteration; nearer,
/// it is `max(estimate, outer)`. The maximum of two lower bounds is one,
/// so rays from far away land on the ball instead of overshooting the set.
#[must_use]
pub fn mandelbulb_estimate<T: Num>(
    p: V3<T>,
    power: T,
    iterations: T,
    escape: T,
    ball: T,
    integer_power: Option<u32>,
    trap: Option<&TrapShape<T>>,
) -> Estimate<T> {
    let slot = TrapSlot::new(trap);
    let r0 = p.length();
    let outer = r0 - ball;
    let far = r0.gt(T::of(MANDELBULB_FAR_FIELD) * ball);
    let count = T::select(far, T::zero(), iterations);
    let start = [p.x, p.y, p.z, T::one(), slot.start(T::one(), p)];
    let [x, y, z, dr, trap] = T::iterate(count, start, |_, [x, y, z, dr, trap]| {
        let z = v3(x, y, z);
        let r = z.length();
        let trap = slot.own(trap, || r);
        // r^(power - 1), by repeated multiplication in the integer form.
        let r_pow = match integer_power {
            Some(n) => pow_int(r, n - 1),
            None => r.powf(power - T::one()),
        };
        let dr = (power * r_pow * dr + T::one()).min(T::derivative_cap());
        let z = triplex_direction(z, r, power, integer_power) * (r_pow * r) + p;
        let trap = slot.shape_within(trap, z, z.length().le(escape));
        Step {
            stop_before: Some(r.gt(escape)),
            next: [z.x, z.y, z.z, dr, trap],
            stop_after: None,
        }
    });
    let r = v3(x, y, z).length();
    let estimate = (T::of(0.5) * r.max(T::tiny()).ln() * r / dr).max(outer);
    Estimate {
        distance: T::select(far, outer, estimate),
        trap: slot.end(trap, |t| T::select(far, T::one(), t)),
    }
}

/// The Menger sponge (KIFS form) distance bound: fold into the fundamental
/// region, scale about the kept cube, and finish with the exact box
/// distance divided by `scale^iterations`.
#[must_use]
pub fn menger<T: Num>(p: V3<T>, iterations: u32, scale: T) -> Estimate<T> {
    menger_estimate(p, T::of(f64::from(iterations)), scale, None)
}

/// [`menger`] with the iteration count as a number: the formula written
/// once (the kernels' `menger` helper).
#[must_use]
pub fn menger_estimate<T: Num>(
    p: V3<T>,
    iterations: T,
    scale: T,
    trap: Option<&TrapShape<T>>,
) -> Estimate<T> {
    let slot = TrapSlot::new(trap);
    let shift = scale - T::one();
    let start = [p.x, p.y, p.z, T::one(), slot.start(T::one(), p)];
    let [x, y, z, s, trap] = T::iterate(iterations, start, |_, [x, y, z, s, trap]| {
        let z = v3(x, y, z).abs();
        // Sort the components, largest first.
        let z = V3::select(z.x.lt(z.y), v3(z.y, z.x, z.z), z);
        let z = V3::select(z.x.lt(z.z), v3(z.z, z.y, z.x), z);
        let z = V3::select(z.y.lt(z.z), v3(z.x, z.z, z.y), z);
        let trap = slot.own(trap, || z.length() * T::of(0.577_350_269_189_625_8));
        let w = v3(z.x * scale - shift, z.y * scale - shift, z.z * scale);
        let wz = T::select(w.z.gt(T::of(0.5) * shift), w.z - shift, w.z);
        let trap = slot.shape(trap, v3(w.x, w.y, wz));
        Step {
            stop_before: None,
            next: [w.x, w.y, wz, s * scale, trap],
            stop_after: None,
        }
    });
    Estimate {
        distance: cuboid(v3(x, y, z), V3::splat(T::one())) / s,
        trap,
    }
}

/// Distance bound to the tetrahedron with vertices `(1,1,1)`, `(-1,-1,1)`,
/// `(1,-1,-1)`, `(-1,1,-1)`: the largest signed face-plane distance.
#[must_use]
pub fn tetrahedron<T: Num>(z: V3<T>) -> T {
    let a = (-z.x - z.y - z.z).max(z.x + z.y - z.z);
    let b = (-z.x + z.y + z.z).max(z.x - z.y + z.z);
    (a.max(b) - T::one()) * T::of(0.577_350_269_189_625_8)
}

/// The Sierpinski tetrahedron (KIFS form) distance bound: reflect towards
/// the vertex `(1,1,1)`, scale about it, finish with the tetrahedron bound
/// divided by `scale^iterations`.
#[must_use]
pub fn sierpinski<T: Num>(p: V3<T>, iterations: u32, scale: T) -> Estimate<T> {
    sierpinski_estimate(p, T::of(f64::from(iterations)), scale, None)
}

/// [`sierpinski`] with the iteration count as a number: the formula
/// written once (the kernels' `sierpinski` helper).
#[must_use]
pub fn sierpinski_estimate<T: Num>(
    p: V3<T>,
    iterations: T,
    scale: T,
    trap: Option<&TrapShape<T>>,
) -> Estimate<T> {
    let slot = TrapSlot::new(trap);
    let shift = scale - T::one();
    let start = [p.x, p.y, p.z, T::one(), slot.start(T::one(), p)];
    let [x, y, z, s, trap] = T::iterate(iterations, start, |_, [x, y, z, s, trap]| {
        let z = v3(x, y, z);
        let z = V3::select((z.x + z.y).lt(T::zero()), v3(-z.y, -z.x, z.z), z);
        let z = V3::select((z.x + z.z).lt(T::zero()), v3(-z.z, z.y, -z.x), z);
        let z = V3::select((z.y + z.z).lt(T::zero()), v3(z.x, -z.z, -z.y), z);
        let trap = slot.own(trap, || z.length() * T::of(0.577_350_269_189_625_8));
        let w = z * scale - V3::splat(shift);
        let trap = slot.shape(trap, w);
        Step {
            stop_before: None,
            next: [w.x, w.y, w.z, s * scale, trap],
            stop_after: None,
        }
    });
    Estimate {
        distance: tetrahedron(v3(x, y, z)) / s,
        trap,
    }
}

/// A kaleidoscopic IFS's parameters as numbers (see
/// [`scene::Kifs`](crate::scene::Kifs)).
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub struct KifsParams<T> {
    /// The mirrors of each iteration.
    pub fold: KifsFold,
    /// The scale of each iteration, greater than 1.
    pub scale: T,
    /// The point each iteration scales about.
    pub offset: V3<T>,
    /// Angles in radians about `x`, `y`, `z` of the turn before the fold.
    pub rotate_before: Option<V3<T>>,
    /// Angles in radians about `x`, `y`, `z` of the turn after the fold.
    pub rotate_after: Option<V3<T>>,
}

impl<T: Num> KifsParams<T> {
    /// The parameters of `fold` with no turns.
    #[must_use]
    pub fn new(fold: KifsFold, scale: T, offset: V3<T>) -> Self {
        KifsParams {
            fold,
            scale,
            offset,
            rotate_before: None,
            rotate_after: None,
        }
    }

    /// With turns before and after the fold.
    #[must_use]
    pub fn with_turns(mut self, before: Option<V3<T>>, after: Option<V3<T>>) -> Self {
        self.rotate_before = before;
        self.rotate_after = after;
        self
    }
}

/// An orbit stops being followed once it passes this many times the radius
/// of [`kifs_radius`]: the estimate is then `(|z_k| − R) / s^k` after the
/// `k` steps taken, a lower bound of the full one (each later step
/// multiplies `|z| − R` by at least `s`) and at least 31/33 of it (each
/// multiplies `|z| + R` by at most `s`).
pub const KIFS_FOLLOW: f64 = 32.0;

/// A turn by angles about `x`, then `y`, then `z`, as the cosines and
/// sines of the three angles (computed once, outside the loop).
pub(crate) fn turn<T: Num>(angles: V3<T>) -> impl Fn(V3<T>) -> V3<T> {
    let (cx, sx) = (angles.x.cos(), angles.x.sin());
    let (cy, sy) = (angles.y.cos(), angles.y.sin());
    let (cz, sz) = (angles.z.cos(), angles.z.sin());
    move |z: V3<T>| {
        let z = v3(z.x, cx * z.y - sx * z.z, sx * z.y + cx * z.z);
        let z = v3(cy * z.x + sy * z.z, z.y, cy * z.z - sy * z.x);
        v3(cz * z.x - sz * z.y, sz * z.x + cz * z.y, z.z)
    }
}

/// The reflection of `z` across the plane through the origin normal to the
/// unit `n`, where `z` lies on the side `n` points to.
fn reflect_from<T: Num>(z: V3<T>, n: V3<T>) -> V3<T> {
    z - n * (T::of(2.0) * z.dot(n).max(T::zero()))
}

/// `|z|`, then the coordinates sorted, largest first.
fn octahedral_fold<T: Num>(z: V3<T>) -> V3<T> {
    let z = z.abs();
    let z = V3::select(z.x.lt(z.y), v3(z.y, z.x, z.z), z);
    let z = V3::select(z.x.lt(z.z), v3(z.z, z.y, z.x), z);
    V3::select(z.y.lt(z.z), v3(z.x, z.z, z.y), z)
}

/// The fold of [`KifsFold`] (the Menger fold's mirror after the scale is
/// applied by [`kifs_estimate`]).
pub(crate) fn kifs_fold<T: Num>(fold: KifsFold, z: V3<T>) -> V3<T> {
    match fold {
        KifsFold::Tetrahedral => {
            let z = V3::select((z.x + z.y).lt(T::zero()), v3(-z.y, -z.x, z.z), z);
            let z = V3::select((z.x + z.z).lt(T::zero()), v3(-z.z, z.y, -z.x), z);
            V3::select((z.y + z.z).lt(T::zero()), v3(z.x, -z.z, -z.y), z)
        }
        KifsFold::Octahedral | KifsFold::Menger => octahedral_fold(z),
        KifsFold::Icosahedral => {
            // Knighty's icosahedral mirrors, with the golden ratio φ.
            let phi = 0.5 * (1.0 + 5f64.sqrt());
            let unit = |v: [f64; 3]| {
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                v3(T::of(v[0] / l), T::of(v[1] / l), T::of(v[2] / l))
            };
            let n1 = unit([-phi, phi - 1.0, 1.0]);
            let n2 = unit([1.0, -phi, phi + 1.0]);
            let mut z = z;
            for _ in 0..3 {
                z = reflect_from(reflect_from(z.abs(), n1), n2);
            }
            z
        }
    }
}

/// [`kifs_estimate`] with an integer iteration count.
#[must_use]
pub fn kifs<T: Num>(p: V3<T>, iterations: u32, k: &KifsParams<T>) -> Estimate<T> {
    kifs_estimate(p, T::of(f64::from(iterations)), k, None)
}

/// A kaleidoscopic IFS (Knighty) distance bound: each step turns the
/// point, folds it, turns it again and scales it by `s` about the offset
/// (for the Menger fold with no shift along `z`, then a mirror across
/// `z = offset.z (s − 1) / 2`). The drawn set is the points whose orbit is
/// within the radius `R` of [`kifs_radius`] after `iterations` steps, and
/// `(|z_n| − R) / s^n` never overestimates the distance to it (the proof is
/// at [`kifs_radius`]). An orbit past [`KIFS_FOLLOW`] `· R` stops early,
/// with a lower bound of the estimate. The trap is the orbit's smallest
/// radius over `R`.
#[must_use]
pub fn kifs_estimate<T: Num>(
    p: V3<T>,
    iterations: T,
    k: &KifsParams<T>,
    trap: Option<&TrapShape<T>>,
) -> Estimate<T> {
    let slot = TrapSlot::new(trap);
    let menger = k.fold == KifsFold::Menger;
    let o = k.offset;
    let radius = kifs_radius([o.x, o.y, o.z], menger);
    let follow = (radius * T::of(KIFS_FOLLOW)).max(T::tiny());
    let follow2 = follow * follow;
    let grow = k.scale - T::one();
    let shift = v3(
        o.x * grow,
        o.y * grow,
        if menger { T::zero() } else { o.z * grow },
    );
    let height = T::of(0.5) * o.z * grow;
    let before = k.rotate_before.map(turn);
    let after = k.rotate_after.map(turn);
    let start = [p.x, p.y, p.z, T::one(), slot.start(p.dot(p), p)];
    let [x, y, z, s, trap] = T::iterate(iterations, start, |_, [x, y, z, s, trap]| {
        let mut z = v3(x, y, z);
        if let Some(turn) = &before {
            z = turn(z);
        }
        z = kifs_fold(k.fold, z);
        if let Some(turn) = &after {
            z = turn(z);
        }
        let mut w = z * k.scale - shift;
        if menger {
            w.z = height - (w.z - height).abs();
        }
        let r2 = w.dot(w);
        Step {
            stop_before: None,
            next: [
                w.x,
                w.y,
                w.z,
                s * k.scale,
                slot.shape_within(slot.own(trap, || r2), w, r2.le(radius * radius)),
            ],
            stop_after: Some(r2.gt(follow2)),
        }
    });
    Estimate {
        distance: (v3(x, y, z).length() - radius) / s,
        trap: slot.end(trap, |t| (t.sqrt() / radius.max(T::tiny())).min(T::one())),
    }
}

/// The Mandelbox's parameters as numbers (see
/// [`scene::Mandelbox`](crate::scene::Mandelbox)).
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub struct MandelboxParams<T> {
    /// The scale of each iteration; its magnitude is greater than 1.
    pub scale: T,
    /// Inside this radius the sphere fold scales by `(fixed / min)^2`.
    pub min_radius: T,
    /// Between the two radii it inverts in the sphere of this radius.
    pub fixed_radius: T,
    /// The box fold reflects each coordinate beyond `±fold_limit`.
    pub fold_limit: T,
    /// Julia mode: the constant added in each iteration instead of `p`.
    pub julia: Option<V3<T>>,
}

/// The Mandelbox's estimate is multiplied by this safety factor: the
/// running-derivative estimate is not a proven bound. The largest ratio of
/// estimate to distance found against brute-force membership is 1.00
/// (`tests/distance/mandelbox.rs`, and the table in the
/// [fractals chapter](crate::guide::fractals#the-mandelbox) of the guide);
/// the factor covers 1.25, a margin for what sampling misses.
pub const MANDELBOX_SAFETY: f64 = 0.8;

/// An orbit stops being followed once its largest coordinate passes this
/// many times the escape threshold (and the fixed radius): from there the
/// rest of the orbit only scales it, and the estimate uses a lower bound
/// of its value after every step, within about 1/16 of it.
pub const MANDELBOX_FOLLOW: f64 = 16.0;

impl<T: Num> MandelboxParams<T> {
    /// The parameters in Mandelbrot mode (`julia: None`) or Julia mode.
    #[must_use]
    pub fn new(
        scale: T,
        min_radius: T,
        fixed_radius: T,
        fold_limit: T,
        julia: Option<V3<T>>,
    ) -> Self {
        MandelboxParams {
            scale,
            min_radius,
            fixed_radius,
            fold_limit,
            julia,
        }
    }
}

/// [`mandelbox_estimate`] with an integer iteration count.
#[must_use]
pub fn mandelbox<T: Num>(p: V3<T>, iterations: u32, m: &MandelboxParams<T>) -> Estimate<T> {
    mandelbox_estimate(p, T::of(f64::from(iterations)), m, None)
}

/// The Mandelbox (Tom Lowe's box fold and sphere fold) distance estimate.
///
/// The drawn set is the points of the cube of
/// [`mandelbox_extent`] whose orbit's largest coordinate `a` is at
/// most the escape threshold `A` after `iterations` steps. Since an orbit
/// past `A` never returns, the sets shrink as the count grows, towards the
/// Mandelbox itself. The estimate is `(a_n − A) / dr_n` with the running
/// derivative `dr` (continuous across the set's edge, negative inside),
/// times [`MANDELBOX_SAFETY`], and at least the distance to the cube. An
/// orbit past [`MANDELBOX_FOLLOW`] `· A` (and the fixed radius) stops
/// early, with a lower bound of the estimate after the steps it skips. The trap is the orbit's smallest
/// radius over the fixed radius.
#[must_use]
pub fn mandelbox_estimate<T: Num>(
    p: V3<T>,
    iterations: T,
    m: &MandelboxParams<T>,
    trap: Option<&TrapShape<T>>,
) -> Estimate<T> {
    let slot = TrapSlot::new(trap);
    let fixed2 = m.fixed_radius * m.fixed_radius;
    let min2 = (m.min_radius * m.min_radius).min(fixed2);
    let limit = m.fold_limit;
    let (half_side, escape) =
        mandelbox_extent(m.scale, m.fold_limit, m.julia.map(|c| [c.x, c.y, c.z]));
    // Past the fixed radius too, the sphere fold leaves the orbit alone.
    let follow = (escape * T::of(MANDELBOX_FOLLOW)).max(m.fixed_radius);
    // Julia mode adds a constant and no derivative; Mandelbrot mode adds p.
    let (c, add) = match m.julia {
        Some(c) => (c, T::zero()),
        None => (p, T::one()),
    };
    let scale_abs = m.scale.abs();
    let largest = |z: V3<T>| z.x.abs().max(z.y.abs()).max(z.z.abs());
    let start = [p.x, p.y, p.z, T::one(), slot.start(p.dot(p), p), T::zero()];
    let [x, y, z, dr, trap, steps] =
        T::iterate(iterations, start, |_, [x, y, z, dr, trap, steps]| {
            // The box fold, then the sphere fold.
            let z = v3(x, y, z).map(|v| box_fold(v, limit));
            let k = sphere_fold_factor(z.dot(z), min2, fixed2);
            let z = z * (k * m.scale) + c;
            let dr = (dr * k * scale_abs + add).min(T::derivative_cap());
            Step {
                stop_before: None,
                next: [
                    z.x,
                    z.y,
                    z.z,
                    dr,
                    slot.shape_within(slot.own(trap, || z.dot(z)), z, largest(z).le(escape)),
                    steps + T::one(),
                ],
                stop_after: Some(largest(z).gt(follow)),
            }
        });
    // An orbit stopped early: the `m` steps it skips would multiply
    // `a - A` by at least `|s|^m` (each step keeps `a' - A >= |s| (a - A)`
    // while `|c|∞` is at most the one `A` allows: in the cube) and the
    // derivative by `|s|^m` plus the sum of the added 1s, so there this is
    // at most the estimate after every step. Otherwise `rest` is 1.
    let rest = ((iterations - steps) * scale_abs.ln()).exp();
    let added = add * (T::one() - T::one() / rest) / (scale_abs - T::one());
    let estimate = (largest(v3(x, y, z)) - escape) / (dr + added).max(T::tiny());
    Estimate {
        distance: (T::of(MANDELBOX_SAFETY) * estimate).max(cuboid(p, V3::splat(half_side))),
        trap: slot.end(trap, |t| {
            (t.sqrt() / m.fixed_radius.max(T::tiny())).min(T::one())
        }),
    }
}

/// The escape-time estimate is used as is only where the bailout is at
/// least `JULIA_TRUSTED_BAILOUT` times [`julia_radius`]. With a smaller
/// bailout `ln|z| / 2^n` is a poor value of the potential and the estimate
/// overestimates near the tips of the set: measured on the real axis of
/// real `c`, by up to 1.55 at 1.5 radii and 1.25 at 2 (1.02 for the
/// constants whose critical orbit stays within [`JULIA_CRITICAL_RADIUS`]),
/// and at most 0.98 of the distance at 2.5 radii.
pub const JULIA_TRUSTED_BAILOUT: f64 = 2.5;

/// The escape-time estimate is used as is only while the critical orbit
/// `0, c, c^2 + c, ...` stays within this radius for the point's iterations
/// and [`JULIA_CRITICAL_MARGIN`] more (see [`julia`]). Within the unit
/// ball would do for the argument there; 0.9 leaves a margin (the real
/// constants near -1, whose orbit reaches 0.9 to 1, came within 0.998 of
/// the distance at 2 radii).
pub const JULIA_CRITICAL_RADIUS: f64 = 0.9;

/// Extra steps of the critical orbit checked beyond a point's own.
pub const JULIA_CRITICAL_MARGIN: u32 = 2;

/// Steps [`julia_bound`] follows an orbit beyond where the escape loop
/// stopped, to prove escape for points just outside the ball.
pub const JULIA_BOUND_EXTRA: u32 = 2;

/// Whether the critical orbit `w_0 = 0, w_(k+1) = w_k^2 + c` leaves the
/// ball `|w|^2 <= radius2` within `steps` steps.
///
/// The orbit of 0 stays in the plane spanned by 1 and `c`'s vector part,
/// where quaternion multiplication is complex multiplication, so it is
/// iterated as the complex orbit of `c' = c.x + i |(c.y, c.z, c.w)|`: the
/// quaternion set contains its critical point 0 exactly when `c'` is in
/// the Mandelbrot set.
#[must_use]
pub fn julia_critical_leaves<T: Num<Bool = bool>>(c: [T; 4], steps: u32, radius2: T) -> bool {
    critical_leaves(c, T::of(f64::from(steps)), radius2)
}

/// [`julia_critical_leaves`] with the step count as a number, for any
/// [`Num`].
fn critical_leaves<T: Num>(c: [T; 4], steps: T, radius2: T) -> T::Bool {
    let cy = (c[1] * c[1] + c[2] * c[2] + c[3] * c[3]).sqrt();
    let [_, _, left] = T::iterate(steps, [T::zero(), T::zero(), T::zero()], |_, [x, y, _]| {
        let two_x = T::of(2.0) * x;
        let x = x * x - y * y + c[0];
        let y = two_x * y + cy;
        let leaves = (x * x + y * y).gt(radius2);
        Step {
            stop_before: None,
            next: [x, y, T::select(leaves, T::one(), T::zero())],
            stop_after: Some(leaves),
        }
    });
    left.gt(T::of(0.5))
}

/// A proven lower bound of the distance from `(p, w)` to the points whose
/// orbits never leave the ball of radius `edge` (for `edge` = the smaller
/// of [`julia_radius`] and the bailout, the Julia set's points within the
/// bailout), from the first `steps + 1` points of its orbit; 0 where none
/// of them proves escape.
///
/// Proof. Let `z_k` be the orbit of the point and `y_k` that of a point at
/// distance `e_0` from it. Since `y^2 - z^2 = y (y - z) + (y - z) z`, the
/// gaps `e_k = |y_k - z_k|` obey `e_(k+1) <= 2 |z_k| e_k + e_k^2`. So
/// `e_k < T_k = |z_k| - edge` (then `|y_k| > edge`: `y` escapes, or leaves
/// the bailout) whenever `e_0 <= h_0(h_1(... h_(k-1)(T_k)))`, where
/// `h_j(t) = sqrt(|z_j|^2 + t) - |z_j|` inverts `e -> 2 |z_j| e + e^2`.
/// The square root is concave, so below its tangent at any `tau_j >= 0`:
/// `h_j(t) >= t / (alpha_j + beta_j t)` with `s = sqrt(|z_j|^2 + tau_j)`,
/// `alpha_j = |z_j| + s - tau_j / (2 s)` and `beta_j = 1 / (2 s)`. These
/// fractions compose to `t / (A_k + B_k t)` with `A_(k+1) = A_k alpha_k`
/// and `B_(k+1) = A_k beta_k + B_k` (from `A_0 = 1`, `B_0 = 0`), computed
/// forward along the orbit; so `T_k / (A_k + B_k T_k)` is a lower bound
/// for every `k`, and the result is the largest. Unlike the derivative
/// (`A_k` for `tau = 0`), it stays small where the orbit passes near the
/// critical point 0 (the tangent keeps `alpha` at least `sqrt(tau) / 2`).
///
/// The tangent points only make it tight: `tau_j = guess * D_j`, the gap
/// the linearised orbit (derivative `D_j`) gives for a start gap `guess`.
/// `A` and `B` are capped at [`Num::derivative_cap`] (a cap of `A` can
/// only raise a bound that is already below `T / 1e30`) and the orbit
/// stops at [`Num::magnitude_cap`], so nothing overflows.
#[must_use]
pub fn julia_bound<T: Num>(p: V3<T>, c: [T; 4], w: T, steps: u32, edge: T, guess: T) -> T {
    orbit_bound(p, c, w, T::of(f64::from(steps) + 1.0), edge, guess)
}

/// [`julia_bound`] over the first `points` points of the orbit (`steps +
/// 1`), the count as a number.
fn orbit_bound<T: Num>(p: V3<T>, c: [T; 4], w: T, points: T, edge: T, guess: T) -> T {
    let cap = T::derivative_cap();
    let far2 = T::magnitude_cap() * T::magnitude_cap();
    let mz2 = p.x * p.x + p.y * p.y + p.z * p.z + w * w;
    let start = [
        p.x,
        p.y,
        p.z,
        w,
        mz2,
        T::one(),
        T::zero(),
        T::one(),
        T::zero(),
    ];
    let [.., best] = T::iterate(points, start, |_, [z0, z1, z2, z3, mz2, a, b, d, best]| {
        let stop = mz2.gt(far2);
        let r = mz2.sqrt();
        let t = r - edge;
        let best = T::select(t.gt(T::zero()), best.max(t / (a + b * t)), best);
        // The last point's step is computed and not used: only `best` is.
        let d = (d * T::of(2.0) * r).min(cap);
        let tau = (guess * d).min(cap);
        let s = (mz2 + tau).sqrt().max(T::tiny());
        let half_inv = T::of(0.5) / s;
        let b = (a * half_inv + b).min(cap);
        let a = (a * (r + s - tau * half_inv)).min(cap);
        let z = square_plus(z0, z1, z2, z3, c);
        let mz2 = z[0] * z[0] + z[1] * z[1] + z[2] * z[2] + z[3] * z[3];
        Step {
            stop_before: Some(stop),
            next: [z[0], z[1], z[2], z[3], mz2, a, b, d, best],
            stop_after: None,
        }
    });
    best
}

/// `z^2 + c` for the quaternion `z = (x, y, z, w)`, real part first.
fn square_plus<T: Num>(z0: T, z1: T, z2: T, z3: T, c: [T; 4]) -> [T; 4] {
    let two_x = T::of(2.0) * z0;
    [
        z0 * z0 - z1 * z1 - z2 * z2 - z3 * z3 + c[0],
        two_x * z1 + c[1],
        two_x * z2 + c[2],
        two_x * z3 + c[3],
    ]
}

/// The quaternion Julia estimate for `z -> z^2 + c` at the point `(p, w)`
/// (real part first), and its orbit trap (the smallest `|z|` reached,
/// clamped to `[0, 1]`).
///
/// The set is the points whose orbits stay within `edge`, the smaller of
/// the bailout and [`julia_radius`] (for a bailout of at least that radius,
/// the whole filled Julia set). The result is, by three rules:
///
/// 1. Beyond [`JULIA_FAR_FIELD`]` * edge`: [`JULIA_FAR_FIELD_SLOPE`] times
///    the distance to the ball of radius `edge`, and trap 1, with no
///    iteration. Proven.
/// 2. Nearer, where it is trusted, the escape-time estimate `0.5 |z| ln|z|
///    / |dz|` (with `|dz|` the product of `2 |z_k|`, the largest stretch of
///    each step): the bailout is at least [`JULIA_TRUSTED_BAILOUT`] radii
///    and the critical orbit (see [`julia_critical_leaves`]) stays within
///    [`JULIA_CRITICAL_RADIUS`] for the point's iterations and
///    [`JULIA_CRITICAL_MARGIN`] more. Not proven; measured (see
///    `tests/distance/julia.rs`): within 0.98 of the distance at points that
///    escape, and at most a thin band above it at points that do not.
/// 3. Otherwise the smaller of that estimate and [`julia_bound`]: a proven
///    bound where the orbit proves escape within [`JULIA_BOUND_EXTRA`]
///    steps of where the loop stopped, else at most 0 (inside).
///
/// Everything is computed from `c` per evaluation, so a dynamic `c` gets
/// the same guarantee at every value.
///
/// Why the critical orbit: near a point whose orbit passes through the
/// critical point 0 the derivative vanishes and the escape-time estimate
/// explodes. When 0 is in the set (the critical orbit stays bounded) such
/// points are near the set. When it is not (`c' = c.x + i |(c.y, c.z,
/// c.w)|` is outside the Mandelbrot set, and the set's slice through 1 and
/// `c`, the complex Julia set of `c'`, is dust) they can be far from it:
/// the estimate overestimated by any factor there (5.3 at 0.8 on 12
/// iterations; over the constants of the property test, by at least 16 at
/// points that escape and 128 at points that do not).
/// While the critical orbit is within the unit ball, the orbit of a point
/// near 0 ends within it too, so the estimate there is negative; a critical
/// orbit that reaches beyond it (escaping, or attracted to a cycle outside
/// the unit ball) also made points inside the set positive, up to 4.6e13.
/// The gallery's constant is outside the Mandelbrot set too, but its
/// critical orbit stays within 0.85 for 16 steps, so with its 11
/// iterations it keeps the escape-time estimate. The escape loop stops
/// before the running derivative would pass [`Num::derivative_cap`]
/// (capped, it let `|z|` keep growing and inflated the estimate: by a
/// factor of 256 at a point 3.1e-5 from a connected set with bailout 1e6
/// and 36 iterations).
#[must_use]
pub fn julia<T: Num>(p: V3<T>, c: [T; 4], w: T, iterations: u32, bailout: T) -> Estimate<T> {
    julia_estimate(p, c, w, T::of(f64::from(iterations)), bailout, None)
}

/// [`julia`] with the iteration count as a number: the formula written
/// once (the kernels' `julia` helper).
#[must_use]
pub fn julia_estimate<T: Num>(
    p: V3<T>,
    c: [T; 4],
    w: T,
    iterations: T,
    bailout: T,
    trap: Option<&TrapShape<T>>,
) -> Estimate<T> {
    let slot = TrapSlot::new(trap);
    let radius = julia_radius(c);
    let edge = radius.min(bailout);
    let mz2 = p.x * p.x + p.y * p.y + p.z * p.z + w * w;
    let r0 = mz2.sqrt();
    let far = r0.gt(T::of(JULIA_FAR_FIELD) * edge);
    let bailout2 = bailout * bailout;
    let count = T::select(far, T::zero(), iterations);
    let start = [
        p.x,
        p.y,
        p.z,
        w,
        mz2,
        T::one(),
        slot.start(mz2, p),
        T::zero(),
    ];
    let [.., mz2, md2, trap, n] =
        T::iterate(count, start, |_, [z0, z1, z2, z3, mz2, md2, trap, n]| {
            let next = md2 * T::of(4.0) * mz2;
            let z = square_plus(z0, z1, z2, z3, c);
            let mz2 = z[0] * z[0] + z[1] * z[1] + z[2] * z[2] + z[3] * z[3];
            Step {
                stop_before: Some(next.gt(T::derivative_cap())),
                next: [
                    z[0],
                    z[1],
                    z[2],
                    z[3],
                    mz2,
                    next,
                    slot.shape_within(
                        slot.own(trap, || mz2),
                        v3(z[0], z[1], z[2]),
                        mz2.le(bailout2),
                    ),
                    n + T::one(),
                ],
                stop_after: Some(mz2.gt(bailout2)),
            }
        });
    let ratio = (mz2 / md2.max(T::tiny())).sqrt();
    let estimate = T::of(0.25) * mz2.max(T::tiny()).ln() * ratio;
    // The critical orbit is followed only where the bailout alone does not
    // already call for the bound, and neither runs far away.
    let critical = T::of(JULIA_CRITICAL_RADIUS);
    let distrust = bailout.lt(T::of(JULIA_TRUSTED_BAILOUT) * radius);
    let margin = T::of(f64::from(JULIA_CRITICAL_MARGIN));
    let orbit_steps = T::select(distrust | far, T::zero(), n + margin);
    let bounded = distrust | critical_leaves(c, orbit_steps, critical * critical);
    let extra = T::of(f64::from(JULIA_BOUND_EXTRA) + 1.0);
    let points = T::select(bounded & !far, n + extra, T::zero());
    let bound = orbit_bound(p, c, w, points, edge, ratio);
    let near = T::select(bounded, estimate.min(bound), estimate);
    Estimate {
        distance: T::select(far, T::of(JULIA_FAR_FIELD_SLOPE) * (r0 - edge), near),
        trap: slot.end(trap, |t| T::select(far, T::one(), t.sqrt().min(T::one()))),
    }
}

/// Rotates `p` by `angle` around the unit axis `k` (Rodrigues' formula).
#[must_use]
pub fn rotate_axis<T: Num>(p: V3<T>, k: V3<T>, angle: T) -> V3<T> {
    let (sn, cs) = (angle.sin(), angle.cos());
    p * cs + k.cross(p) * sn + k * (k.dot(p) * (T::one() - cs))
}

/// The polynomial smooth minimum of radius `k` and its blend factor: the
/// result is `min(a, b) - h^2 k / 4` with `h = max(k - |a - b|, 0) / k`, so
/// it is at most `k / 4` below `min(a, b)`, and exactly `min(a, b)` when
/// `k = 0`. The second value is the weight of the larger operand's colour,
/// in `[0, 0.5]`.
#[must_use]
pub fn smooth_min<T: Num>(a: T, b: T, k: T) -> (T, T) {
    let h = (k - (a - b).abs()).max(T::zero()) / k;
    let m = h * h * T::of(0.5);
    let hard = k.le(T::zero());
    (
        T::select(hard, a.min(b), a.min(b) - m * k * T::of(0.5)),
        T::select(hard, T::zero(), m),
    )
}

/// The twist's local Lipschitz factor `t/2 + sqrt(1 + t^2/4)` at
/// `t = |k| rho`: the largest stretch of the map `p -> rotate_y(k p.y) p` at
/// distance `rho` from the y axis. The root is a `hypot`, so a large `t`
/// gives a large factor rather than an infinite one (which would make
/// every distance 0).
fn twist_stretch<T: Num>(k: T, rho: T) -> T {
    let half = T::of(0.5) * k.abs() * rho;
    half + T::one().hypot(half)
}

/// The bend's local Lipschitz factor `1 + |k| rho` at distance `rho` from
/// the z axis.
fn bend_stretch<T: Num>(k: T, rho: T) -> T {
    T::one() + k.abs() * rho
}

/// Turns the child's distance `d` at the warped point into a bound in the
/// unwarped space, for a warp whose stretch grows with `rho`: with
/// `L0 = stretch(rho)` and `L1 = stretch(rho + |d| / L0)`, every point of
/// the ball of radius `|d| / L1` maps within `|d|` of the warped point, so
/// `d / L1` never overestimates.
fn warp_bound<T: Num>(d: T, rho: T, stretch: impl Fn(T) -> T) -> T {
    let reach = d.abs() / stretch(rho);
    d / stretch(rho + reach)
}

/// The distance bound of a twisted child: `d / L(rho + |d| / L(rho))` with
/// the twist stretch `L`.
#[must_use]
pub fn twist_bound<T: Num>(d: T, k: T, rho: T) -> T {
    warp_bound(d, rho, |r| twist_stretch(k, r))
}

/// The distance bound of a bent child: `d / L(rho + |d| / L(rho))` with
/// the bend stretch `L`.
#[must_use]
pub fn bend_bound<T: Num>(d: T, k: T, rho: T) -> T {
    warp_bound(d, rho, |r| bend_stretch(k, r))
}

// Domain operations: the point a child sees, and what becomes of its
// distance.

/// The point a child translated by `offset` sees.
#[must_use]
pub fn translate<T: Num>(p: V3<T>, offset: V3<T>) -> V3<T> {
    p - offset
}

/// `p` times the constant matrix `rows` (a baked rotation), row by row,
/// left to right: zero entries are left out and `±1` entries need no
/// product (each exact, so the value is the full product's).
#[must_use]
pub fn rotate_rows<T: Num>(p: V3<T>, rows: [V3<f64>; 3]) -> V3<T> {
    V3::from_array(rows.map(|row| {
        let mut sum: Option<T> = None;
        for (i, a) in row.to_array().into_iter().enumerate() {
            let x = p.get(i);
            sum = match (sum, a) {
                (_, 0.0) => sum,
                (None, 1.0) => Some(x),
                (None, -1.0) => Some(-x),
                (None, _) => Some(T::of(a) * x),
                (Some(s), 1.0) => Some(s + x),
                (Some(s), -1.0) => Some(s - x),
                (Some(s), _) if a < 0.0 => Some(s - T::of(-a) * x),
                (Some(s), _) => Some(s + T::of(a) * x),
            };
        }
        sum.unwrap_or_else(T::zero)
    }))
}

/// The point a child scaled by `factor` sees.
#[must_use]
pub fn scale_point<T: Num>(p: V3<T>, factor: T) -> V3<T> {
    p / factor
}

/// The distance of a child scaled by `factor`, from the child's.
#[must_use]
pub fn scale_distance<T: Num>(d: T, factor: T) -> T {
    d * factor
}

/// The point a child mirrored across the plane `axis = 0` sees.
#[must_use]
pub fn mirror<T: Num>(p: V3<T>, axis: usize) -> V3<T> {
    p.with(axis, p.get(axis).abs())
}

/// The point a child elongated by `extents` sees: `p` less its clamp into
/// the box `±extents`.
#[must_use]
pub fn elongate<T: Num>(p: V3<T>, extents: V3<T>) -> V3<T> {
    p - p.max(-extents).min(extents)
}

/// The point a repeated child sees: `p` folded into the cell of size
/// `period` around the origin (no folding on an axis of period 0), the
/// cell index clamped to `±limit` if given.
#[must_use]
pub fn repeat<T: Num>(p: V3<T>, period: V3<T>, limit: Option<[u32; 3]>) -> V3<T> {
    let axis = |i: usize| {
        let (x, c) = (p.get(i), period.get(i));
        let mut cell = (x / c).round();
        if let Some(l) = limit {
            let l = T::of(f64::from(l[i]));
            cell = cell.max(-l).min(l);
        }
        T::select(c.gt(T::zero()), x - c * cell, x)
    };
    v3(axis(0), axis(1), axis(2))
}

/// The point a child twisted about the y axis at `rate` radians per unit
/// sees.
#[must_use]
pub fn twist<T: Num>(p: V3<T>, rate: T) -> V3<T> {
    let a = rate * p.y;
    let (s, c) = (a.sin(), a.cos());
    v3(c * p.x - s * p.z, p.y, s * p.x + c * p.z)
}

/// The point a child bent about the z axis at `rate` radians per unit
/// sees.
#[must_use]
pub fn bend<T: Num>(p: V3<T>, rate: T) -> V3<T> {
    let a = rate * p.x;
    let (s, c) = (a.sin(), a.cos());
    v3(c * p.x - s * p.y, s * p.x + c * p.y, p.z)
}

/// A twisted child's distance bound at `p`, from its distance `d`.
#[must_use]
pub fn twisted<T: Num>(d: T, rate: T, p: V3<T>) -> T {
    twist_bound(d, rate, p.x.hypot(p.z))
}

/// A bent child's distance bound at `p`, from its distance `d`.
#[must_use]
pub fn bent<T: Num>(d: T, rate: T, p: V3<T>) -> T {
    bend_bound(d, rate, p.x.hypot(p.y))
}

/// `d` raised to the distance from `p` to the ball of `radius` around
/// `centre`, where the ball holds the shape (a warp's estimate is then
/// never below the ball's).
#[must_use]
pub fn ball_floor<T: Num>(d: T, p: V3<T>, centre: V3<T>, radius: T) -> T {
    d.max((p - centre).length() - radius)
}

/// A rounded child's distance: `radius` less.
#[must_use]
pub fn rounded<T: Num>(d: T, radius: T) -> T {
    d - radius
}

/// An onion's distance: a shell of `thickness` around the child's surface.
#[must_use]
pub fn onion<T: Num>(d: T, thickness: T) -> T {
    d.abs() - thickness
}

/// A boolean of two distances (see [`csg`]).
#[derive(Clone, Copy)]
#[non_exhaustive]
pub struct Boolean<T: Num> {
    /// The combined distance.
    pub distance: T,
    /// Where it holds, the first operand is the nearer: its colour shows.
    pub first_nearer: T::Bool,
    /// The weight of the farther operand's colour across a smooth seam, in
    /// `[0, 0.5]` (0 for a hard boolean).
    pub blend: T,
}

/// Hard (`k` = `None`) or smooth CSG of the distances `a` and `b`: every
/// operation is a (smooth) minimum of signed operands: union `min(a, b)`,
/// subtraction `-min(-a, b)`, intersection and cut `-min(-a, -b)`.
#[must_use]
pub fn csg<T: Num>(op: CsgOp, a: T, b: T, k: Option<T>) -> Boolean<T> {
    let (x, y) = match op {
        CsgOp::Union => (a, b),
        CsgOp::Subtract => (-a, b),
        CsgOp::Intersect | CsgOp::Cut => (-a, -b),
    };
    let (m, blend) = match k {
        Some(k) => smooth_min(x, y, k),
        None => (x.min(y), T::zero()),
    };
    Boolean {
        distance: if op == CsgOp::Union { m } else { -m },
        first_nearer: x.lt(y),
        blend,
    }
}
