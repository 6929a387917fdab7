//! Plane profiles and the two sweeps that make solids of them: extrusion
//! along z and revolution around y (Quilez's `opExtrusion` and
//! `opRevolution`, and his exact 2D distances).

use crate::expr::Step;
use crate::math::{Num, V3};
use crate::scene::Profile;

/// Exact signed distance from the point `(x, y)` to `profile`.
#[must_use]
pub fn profile<T: Num>(x: T, y: T, profile: &Profile<T>) -> T {
    let zero = T::zero();
    match profile {
        Profile::Circle { radius } => x.hypot(y) - *radius,
        Profile::Rect {
            half_extents: [bx, by],
        } => rect(x, y, *bx, *by),
        Profile::RoundRect {
            half_extents: [bx, by],
            radius,
        } => rect(x, y, *bx - *radius, *by - *radius) - *radius,
        Profile::Segment { a, b, radius } => {
            let [px, py] = [x - a[0], y - a[1]];
            let [ex, ey] = [b[0] - a[0], b[1] - a[1]];
            let h = ((px * ex + py * ey) / (ex * ex + ey * ey).max(T::tiny()))
                .max(zero)
                .min(T::one());
            (px - ex * h).hypot(py - ey * h) - *radius
        }
        Profile::Polygon { vertices } => polygon(x, y, vertices),
        Profile::Ellipse { radii: [a, b] } => ellipse(x, y, *a, *b),
        Profile::Vesica {
            half_length,
            half_width,
        } => vesica(x, y, *half_length, *half_width),
    }
}

/// The vesica pointed at `(0, ±b)`, `w` wide each side of the y axis
/// (Quilez's `sdVesica`): the overlap of the discs of radius `(b² + w²) /
/// 2w` about `(∓d, 0)`, `d = (b² - w²) / 2w`. Folded to the first
/// quadrant, a point beyond the line from the far disc's centre through
/// the tip is nearest the tip; elsewhere it is nearest the arc.
fn vesica<T: Num>(x: T, y: T, b: T, w: T) -> T {
    let two_w = T::of(2.0) * w.max(T::tiny());
    let (d, r) = ((b * b - w * w) / two_w, (b * b + w * w) / two_w);
    let (x, y) = (x.abs(), y.abs());
    let tip = x.hypot(y - b);
    let arc = (x + d).hypot(y) - r;
    T::select(((y - b) * d).gt(x * b), tip, arc)
}

/// Bisection steps of the ellipse's root: the bracket shrinks by `2^-64`
/// before two Newton steps finish the root.
const ELLIPSE_STEPS: f64 = 64.0;

/// The ellipse of semi-axes `a` along x and `b` along y (after Eberly,
/// "Distance from a point to an ellipse"): folded to the first quadrant
/// with the longer axis first, the nearest point is `(r y0 / (σ + r - 1),
/// y1 / σ)` (`r` the squared ratio of the axes, `z` the point in units of
/// the axes) for the root `σ` of `(r z0 / (σ + r - 1))² + (z1 / σ)² = 1`,
/// found by bisection and polished by two Newton steps within the bracket
/// (solving for `σ` rather than Eberly's `σ - 1` keeps the small root of a
/// point near the centre free of cancellation); on the longer axis the
/// nearest point is found directly.
fn ellipse<T: Num>(x: T, y: T, a: T, b: T) -> T {
    let (zero, one, half) = (T::zero(), T::one(), T::of(0.5));
    let swap = b.gt(a);
    let (e0, e1) = (T::select(swap, b, a), T::select(swap, a, b));
    let (y0, y1) = (
        T::select(swap, y.abs(), x.abs()),
        T::select(swap, x.abs(), y.abs()),
    );
    let (z0, z1) = (y0 / e0, y1 / e1);
    let g = z0 * z0 + z1 * z1 - one;
    let r = (e0 / e1) * (e0 / e1);
    let (rz0, c) = (r * z0, r - one);
    let top = T::select(g.lt(zero), one, rz0.hypot(z1));
    let terms = |s: T| (rz0 / (s + c), z1 / s);
    let [lo, hi] = T::iterate(T::of(ELLIPSE_STEPS), [z1, top], |_, [lo, hi]| {
        let s = half * (lo + hi);
        let (u, v) = terms(s);
        let beyond = (u * u + v * v - one).gt(zero);
        Step {
            stop_before: None,
            next: [T::select(beyond, s, lo), T::select(beyond, hi, s)],
            stop_after: None,
        }
    });
    let mut s = half * (lo + hi);
    for _ in 0..2 {
        let (u, v) = terms(s);
        let slope = -T::of(2.0) * (u * u / (s + c) + v * v / s);
        s = (s - (u * u + v * v - one) / slope).clamp(lo, hi);
    }
    let off_axis = (y0 - r * y0 / (s + c)).hypot(y1 - y1 / s);
    // On the longer axis: the nearest point is off it while the point is
    // within the centre of curvature of its end.
    let (numerator, denominator) = (e0 * y0, e0 * e0 - e1 * e1);
    let inner = numerator.lt(denominator);
    let t = numerator / denominator.max(T::tiny());
    let across = (one - t * t).max(zero).sqrt();
    let on_axis = T::select(inner, (e0 * t - y0).hypot(e1 * across), (y0 - e0).abs());
    let d = T::select(y1.gt(zero), off_axis, on_axis);
    T::select(g.lt(zero), -d, d)
}

/// The rectangle of half extents `bx`, `by` about the origin.
fn rect<T: Num>(x: T, y: T, bx: T, by: T) -> T {
    let zero = T::zero();
    let (qx, qy) = (x.abs() - bx, y.abs() - by);
    qx.max(zero).hypot(qy.max(zero)) + qx.max(qy).min(zero)
}

/// The polygon through `v`: the distance to its nearest edge, negative
/// where a ray towards +x crosses its edges an odd number of times.
fn polygon<T: Num>(x: T, y: T, v: &[[T; 2]]) -> T {
    let Some(last) = v.last() else {
        return T::of(f64::INFINITY);
    };
    // The smallest squared distance, with one square root at the end.
    let (lx, ly) = (x - last[0], y - last[1]);
    let mut nearest = lx * lx + ly * ly;
    let mut inside: Option<T::Bool> = None;
    let mut j = v.len() - 1;
    for (i, vi) in v.iter().enumerate() {
        let vj = v[j];
        let [ex, ey] = [vj[0] - vi[0], vj[1] - vi[1]];
        let [wx, wy] = [x - vi[0], y - vi[1]];
        let h = ((wx * ex + wy * ey) / (ex * ex + ey * ey).max(T::tiny()))
            .max(T::zero())
            .min(T::one());
        let (dx, dy) = (wx - ex * h, wy - ey * h);
        nearest = nearest.min(dx * dx + dy * dy);
        // The edge crosses the point's height, the point left of it going
        // up or right of it going down: the ray crosses it.
        let (up, down, left) = (y.ge(vi[1]), y.lt(vj[1]), (ey * wx).lt(ex * wy));
        let crosses = (up & down & left) | (!up & !down & !left);
        inside = Some(match inside {
            Some(odd) => (odd & !crosses) | (!odd & crosses),
            None => crosses,
        });
        j = i;
    }
    let nearest = nearest.sqrt();
    match inside {
        Some(inside) => T::select(inside, -nearest, nearest),
        None => nearest,
    }
}

/// Exact distance to `profile` in the xy plane extruded along z to
/// `±half_height`.
#[must_use]
pub fn extrude<T: Num>(p: V3<T>, profile: &Profile<T>, half_height: T) -> T {
    extrusion(self::profile(p.x, p.y, profile), p.z, half_height)
}

/// The extrusion of a plane shape whose signed distance at the point is
/// `d` between `±half_height` along the axis the point is `z` along.
pub(crate) fn extrusion<T: Num>(d: T, z: T, half_height: T) -> T {
    let zero = T::zero();
    let h = z.abs() - half_height;
    d.max(h).min(zero) + d.max(zero).hypot(h.max(zero))
}

/// The solid swept by `profile` turning around the y axis, its x axis
/// moved out to `offset`: the profile's distance at `(|p.xz| - offset,
/// p.y)`. Exact where the profile lies at `x >= -offset`; past the axis,
/// the solid is the sweep of the profile's part at `x >= -offset` and this
/// is a bound.
#[must_use]
pub fn revolve<T: Num>(p: V3<T>, profile: &Profile<T>, offset: T) -> T {
    self::profile(p.x.hypot(p.z) - offset, p.y, profile)
}
