//! More of Quilez's exact primitives: thickened triangles and quads, the
//! pyramid, prisms and cylinders built on the plane profiles, cones, the
//! cut hollow sphere and the death star.

use super::profile::{extrusion, profile};
use super::{capped_cone, revolve};
use crate::math::{Num, V3, v3};
use crate::scene::Profile;

/// The squared distance from `p` to the segment `a`-`b`.
fn segment_squared<T: Num>(p: V3<T>, a: V3<T>, b: V3<T>) -> T {
    let (ba, pa) = (b - a, p - a);
    let h = (pa.dot(ba) / ba.dot(ba).max(T::tiny()))
        .max(T::zero())
        .min(T::one());
    let d = ba * h - pa;
    d.dot(d)
}

/// The unsigned distance from `p` to the triangle `abc` (Quilez's
/// `udTriangle`): to the nearest edge where `p` lies beyond one, else to
/// the triangle's plane. A triangle of no area is its edges.
#[must_use]
pub fn triangle_unsigned<T: Num>(p: V3<T>, a: V3<T>, b: V3<T>, c: V3<T>) -> T {
    let (ba, cb, ac) = (b - a, c - b, a - c);
    let (pa, pb, pc) = (p - a, p - b, p - c);
    let normal = ba.cross(ac);
    let zero = T::zero();
    // Inside all three edges' planes (through the edge, along the normal).
    let within = ba.cross(normal).dot(pa).ge(zero)
        & cb.cross(normal).dot(pb).ge(zero)
        & ac.cross(normal).dot(pc).ge(zero);
    let area = normal.dot(normal);
    let edges = segment_squared(p, a, b)
        .min(segment_squared(p, b, c))
        .min(segment_squared(p, c, a));
    let across = normal.dot(pa);
    let plane = across * across / area.max(T::tiny());
    T::select(within & area.gt(zero), plane, edges).sqrt()
}

/// Exact distance to the points within `t` of the triangle `abc`.
#[must_use]
pub fn triangle<T: Num>(p: V3<T>, a: V3<T>, b: V3<T>, c: V3<T>, t: T) -> T {
    triangle_unsigned(p, a, b, c) - t
}

/// The distance to the points within `t` of the quadrilateral `abcd`, the
/// triangles `abc` and `acd`: exact where it is flat and convex.
#[must_use]
pub fn quad<T: Num>(p: V3<T>, a: V3<T>, b: V3<T>, c: V3<T>, d: V3<T>, t: T) -> T {
    triangle_unsigned(p, a, b, c).min(triangle_unsigned(p, a, c, d)) - t
}

/// The distance to the twelve square bars of thickness `t` along the edges
/// of the box of half extents `b` (Quilez's `sdBoxFrame`): folded to one
/// octant, the nearest of the three bars there, each a box. Exact outside;
/// inside, the depth in the deepest bar, a bound (where bars meet the
/// frame can be deeper).
#[must_use]
pub fn box_frame<T: Num>(p: V3<T>, b: V3<T>, t: T) -> T {
    let zero = T::zero();
    let e = T::of(0.5) * t;
    let p = p.abs() - b;
    let q = (p + V3::splat(e)).abs() - V3::splat(e);
    let bar = |x: T, y: T, z: T| {
        T::length3(x.max(zero), y.max(zero), z.max(zero)) + x.max(y.max(z)).min(zero)
    };
    bar(p.x, q.y, q.z)
        .min(bar(q.x, p.y, q.z))
        .min(bar(q.x, q.y, p.z))
}

/// Exact distance to the pyramid on the square `|x|, |z| <= w` at `y = 0`
/// with its apex at `(0, h, 0)`. Outside, the distance to the nearer of
/// the base and the side facing the point (the point folded to `x >= z >=
/// 0`, where that side is the one facing +x); inside, the depth below the
/// nearest face's plane.
#[must_use]
pub fn pyramid<T: Num>(p: V3<T>, w: T, h: T) -> T {
    let zero = T::zero();
    let (x, z) = (p.x.abs(), p.z.abs());
    let (x, z) = (x.max(z), x.min(z));
    let q = v3(x, p.y, z);
    let apex = v3(zero, h, zero);
    let side = triangle_unsigned(q, v3(w, zero, w), v3(w, zero, -w), apex);
    let (bx, bz) = ((x - w).max(zero), (z - w).max(zero));
    let base = T::length3(bx, p.y, bz);
    // The side's plane: the normal `(h, w, 0)`, through `(w, 0, 0)`.
    let slant = (h * (x - w) + w * p.y) / h.hypot(w).max(T::tiny());
    let inside = slant.lt(zero) & p.y.gt(zero);
    let depth = slant.max(-p.y);
    T::select(inside, depth, side.min(base))
}

/// The rhombus with half diagonals `la` along x and `lb` along z, grown by
/// `r` in its plane, between `y = ±h` (Quilez's `sdRhombus`): exact.
#[must_use]
pub fn rhombus<T: Num>(p: V3<T>, la: T, lb: T, h: T, r: T) -> T {
    let zero = T::zero();
    let corners = vec![[la, zero], [zero, lb], [-la, zero], [zero, -lb]];
    let d = profile(p.x, p.z, &Profile::Polygon { vertices: corners }) - r;
    extrusion(d, p.y, h)
}

/// Exact distance to the prism along y over the equilateral triangle in
/// the xz plane whose sides lie `r` from the axis, a corner towards +z,
/// between `y = ±h`.
#[must_use]
pub fn tri_prism<T: Num>(p: V3<T>, r: T, h: T) -> T {
    let (s, two) = (T::of(3f64.sqrt()) * r, T::of(2.0) * r);
    let corners = vec![[T::zero(), two], [-s, -r], [s, -r]];
    let d = profile(p.x, p.z, &Profile::Polygon { vertices: corners });
    extrusion(d, p.y, h)
}

/// Exact distance to the cylinder of radius `r` along y between `y = ±h`
/// with its rims rounded by `e`: the rounded rectangle of half extents
/// `(r, h)` turned around y.
#[must_use]
pub fn rounded_cylinder<T: Num>(p: V3<T>, r: T, h: T, e: T) -> T {
    let section = Profile::RoundRect {
        half_extents: [r, h],
        radius: e,
    };
    revolve(p, &section, T::zero())
}

/// Exact distance to the cone with its apex at the origin and its base, a
/// disc of radius `r`, at `y = -h`: the capped cone of radii `r` and 0.
#[must_use]
pub fn cone<T: Num>(p: V3<T>, r: T, h: T) -> T {
    let half = T::of(0.5) * h;
    capped_cone(v3(p.x, p.y + half, p.z), half, r, T::zero())
}

/// Exact distance to the infinite cylinder of radius `r` around the y axis.
#[must_use]
pub fn infinite_cylinder<T: Num>(p: V3<T>, r: T) -> T {
    p.x.hypot(p.z) - r
}

/// Exact distance to the infinite cone with its apex at the origin,
/// opening around +y with the half-angle `angle` (in `[0, π/2]`): in the
/// plane through the axis, the distance to the ray of the side (or to the
/// apex, past it), negative inside.
#[must_use]
pub fn infinite_cone<T: Num>(p: V3<T>, angle: T) -> T {
    let (s, c) = (angle.sin(), angle.cos());
    let (rho, y) = (p.x.hypot(p.z), p.y);
    let along = (rho * s + y * c).max(T::zero());
    let d = (rho - s * along).hypot(y - c * along);
    T::select((rho * c - y * s).lt(T::zero()), -d, d)
}

/// Exact distance to the shell of thickness `2t` about the sphere of
/// radius `r` cut by the plane `y = h` (taken within `[-r, r]`), keeping
/// the part below (Quilez's `sdCutHollowSphere`): the distance to the
/// sphere's arc below the cut, minus `t`.
#[must_use]
pub fn cut_hollow_sphere<T: Num>(p: V3<T>, r: T, h: T, t: T) -> T {
    let h = h.clamp(-r, r);
    let w = (r * r - h * h).max(T::zero()).sqrt();
    let (rho, y) = (p.x.hypot(p.z), p.y);
    // Nearer +y than the rim, by angle, the nearest point is the rim (a
    // comparison of products cannot tell the axis above a rim at the
    // bottom).
    let rim = (rho - w).hypot(y - h);
    let above = rho.atan2(y).lt(w.atan2(h));
    T::select(above, rim, (rho.hypot(y) - r).abs()) - t
}

/// Exact distance to the death star: the ball of radius `ra` about the
/// origin with the ball of radius `rb` about `(d, 0, 0)` carved from it
/// (Quilez's `sdDeathStar`). Where the spheres meet, in the plane
/// through the x axis, points beyond the rim's cone are nearest the rim;
/// elsewhere the carve is exact.
#[must_use]
pub fn death_star<T: Num>(p: V3<T>, ra: T, rb: T, d: T) -> T {
    let zero = T::zero();
    let d = d.max(T::tiny());
    let a = (ra * ra - rb * rb + d * d) / (T::of(2.0) * d);
    let b = (ra * ra - a * a).max(zero).sqrt();
    let (x, rho) = (p.x, p.y.hypot(p.z));
    let rim = (x - a).hypot(rho - b);
    let carved = (x.hypot(rho) - ra).max(rb - (x - d).hypot(rho));
    T::select((x * b - rho * a).gt(d * (b - rho).max(zero)), rim, carved)
}
