//! Distances derived independently of `cpu::sdf`: nearest points on
//! segments, triangles and circles, signed distances to 2D polygons for
//! solids of revolution, and a numerical root for the ellipsoid.

use fractal_sdf::prelude::*;
use fractal_sdf::scene::Kind;
use glam::DVec2;

/// The exact signed distance of an exact primitive, possibly under
/// translate, rotate, scale and colour nodes; `None` for anything else.
pub fn exact_distance(node: &Node, p: DVec3) -> Option<f64> {
    Some(match node.kind() {
        Kind::Sphere { radius } => p.length() - radius.default_value(),
        Kind::Cuboid { half_extents } => box_distance(p, half_extents.default_value()),
        Kind::RoundBox {
            half_extents,
            radius,
        } => {
            // A rounded box is the box shrunk by r, grown by a ball of r.
            let r = radius.default_value();
            box_distance(p, half_extents.default_value() - DVec3::splat(r)) - r
        }
        Kind::Torus {
            major_radius,
            minor_radius,
        } => {
            let (big, small) = (major_radius.default_value(), minor_radius.default_value());
            circle_distance(p, big) - small
        }
        Kind::Cylinder {
            radius,
            half_height,
        } => {
            let (r, h) = (radius.default_value(), half_height.default_value());
            revolved_trapezoid(p, h, r, r)
        }
        Kind::Capsule { a, b, radius } => {
            segment_distance(p, a.default_value(), b.default_value()) - radius.default_value()
        }
        Kind::Plane { normal, offset } => {
            p.dot(normal.default_value().normalize()) + offset.default_value()
        }
        Kind::Octahedron { size } => octahedron_distance(p, size.default_value()),
        Kind::CappedCone {
            half_height,
            bottom_radius,
            top_radius,
        } => revolved_trapezoid(
            p,
            half_height.default_value(),
            bottom_radius.default_value(),
            top_radius.default_value(),
        ),
        Kind::HexPrism {
            radius,
            half_height,
        } => hex_prism_distance(p, radius.default_value(), half_height.default_value()),
        Kind::RoundCone {
            half_height,
            bottom_radius,
            top_radius,
        } => round_cone_distance(
            p,
            half_height.default_value(),
            bottom_radius.default_value(),
            top_radius.default_value(),
        ),
        Kind::Link {
            half_length,
            major_radius,
            minor_radius,
        } => {
            link_curve_distance(p, half_length.default_value(), major_radius.default_value())
                - minor_radius.default_value()
        }
        Kind::CutSphere { radius, height } => {
            cut_sphere_distance(p, radius.default_value(), height.default_value())
        }
        Kind::SolidAngle { angle, radius } => {
            solid_angle_distance(p, angle.default_value(), radius.default_value())
        }
        Kind::CappedTorus {
            angle,
            major_radius,
            minor_radius,
        } => {
            arc_distance(p, angle.default_value(), major_radius.default_value())
                - minor_radius.default_value()
        }
        Kind::Triangle { .. }
        | Kind::Quad { .. }
        | Kind::Pyramid { .. }
        | Kind::Rhombus { .. }
        | Kind::TriPrism { .. }
        | Kind::RoundedCylinder { .. }
        | Kind::Cone { .. }
        | Kind::InfiniteCylinder { .. }
        | Kind::InfiniteCone { .. }
        | Kind::CutHollowSphere { .. }
        | Kind::DeathStar { .. } => super::shapes::distance(node, p)?,
        Kind::CylinderBetween { a, b, radius } => {
            let (q, h) = segment_frame(p, a.default_value(), b.default_value());
            let r = radius.default_value();
            revolved_trapezoid(q, h, r, r)
        }
        Kind::ConeBetween {
            a,
            b,
            radius_a,
            radius_b,
        } => {
            let (q, h) = segment_frame(p, a.default_value(), b.default_value());
            revolved_trapezoid(q, h, radius_a.default_value(), radius_b.default_value())
        }
        Kind::RoundConeBetween {
            a,
            b,
            radius_a,
            radius_b,
        } => {
            let (q, h) = segment_frame(p, a.default_value(), b.default_value());
            round_cone_distance(q, h, radius_a.default_value(), radius_b.default_value())
        }
        Kind::Extrude {
            profile,
            half_height,
        } => super::profiles::extrude_distance(profile, half_height.default_value(), p),
        Kind::Revolve { profile, offset } => {
            super::profiles::revolve_distance(profile, offset.default_value(), p)
        }
        Kind::Translate { offset, child } => exact_distance(child, p - offset.default_value())?,
        Kind::Rotate { axis, angle, child } => {
            let rotation = DQuat::from_axis_angle(*axis, angle.default_value());
            exact_distance(child, rotation.inverse() * p)?
        }
        Kind::Scale { factor, child } => {
            let s = factor.default_value();
            s * exact_distance(child, p / s)?
        }
        Kind::Color { child, .. } => exact_distance(child, p)?,
        _ => return None,
    })
}

/// The point `p` turned and moved so that the segment `a`-`b` runs along
/// y from `-h` to `h` (a quaternion taking its direction to +y; a segment
/// of length 0 lies along y already), and `h`.
fn segment_frame(p: DVec3, a: DVec3, b: DVec3) -> (DVec3, f64) {
    let turn = if a == b {
        DQuat::IDENTITY
    } else {
        DQuat::from_rotation_arc((b - a).normalize(), DVec3::Y)
    };
    (turn * (p - 0.5 * (a + b)), 0.5 * a.distance(b))
}

/// Signed distance to the box `[-b, b]`: the gap to the clamped point
/// outside, minus the smallest gap to a face inside.
pub fn box_distance(p: DVec3, b: DVec3) -> f64 {
    let outside = p - p.clamp(-b, b);
    if outside != DVec3::ZERO {
        outside.length()
    } else {
        -(b - p.abs()).min_element()
    }
}

/// Unsigned distance to the circle of radius `r` around the y axis in the
/// plane y = 0, through its nearest point.
pub fn circle_distance(p: DVec3, r: f64) -> f64 {
    let rho = DVec2::new(p.x, p.z).length();
    if rho == 0.0 {
        // Every point of the circle is equally far.
        return (r * r + p.y * p.y).sqrt();
    }
    let nearest = DVec3::new(p.x, 0.0, p.z) * (r / rho);
    p.distance(nearest)
}

/// Unsigned distance to the segment `a`-`b`: to an end, or perpendicular to
/// the line through the cross product.
pub fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    if ab == DVec3::ZERO {
        return p.distance(a);
    }
    let t = (p - a).dot(ab) / ab.length_squared();
    if t <= 0.0 {
        p.distance(a)
    } else if t >= 1.0 {
        p.distance(b)
    } else {
        (p - a).cross(ab).length() / ab.length()
    }
}

/// The nearest point of the triangle `abc` to `p` (Ericson, "Real-Time
/// Collision Detection", 5.1.5), by Voronoi regions.
pub fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Signed distance to the octahedron `|x| + |y| + |z| <= s`. Outside, the
/// nearest point lies on the face in the octant of `|p|` (a triangle);
/// inside, the nearest boundary is that face's plane.
pub fn octahedron_distance(p: DVec3, s: f64) -> f64 {
    let q = p.abs();
    let sum = q.x + q.y + q.z;
    if sum <= s {
        return (sum - s) / 3f64.sqrt();
    }
    let nearest = closest_on_triangle(q, DVec3::X * s, DVec3::Y * s, DVec3::Z * s);
    q.distance(nearest)
}

/// Unsigned distance from `p` to the 2D segment `a`-`b`.
fn segment_distance_2d(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    if ab == DVec2::ZERO {
        return p.distance(a);
    }
    let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

/// Signed distance to a convex polygon with counter-clockwise vertices:
/// the distance to the nearest edge, negative when inside every edge.
pub fn convex_polygon_distance(p: DVec2, vertices: &[DVec2]) -> f64 {
    let edges = || (0..vertices.len()).map(|i| (vertices[i], vertices[(i + 1) % vertices.len()]));
    let unsigned = edges()
        .map(|(a, b)| segment_distance_2d(p, a, b))
        .fold(f64::INFINITY, f64::min);
    let proper: Vec<_> = edges().filter(|(a, b)| a != b).collect();
    let inside = proper.len() >= 3 && proper.iter().all(|(a, b)| (*b - *a).perp_dot(p - *a) > 0.0);
    if inside { -unsigned } else { unsigned }
}

/// Signed distance to the solid of revolution around y whose cross-section
/// (both sides of the axis) is the trapezoid with radius `r1` at `y = -h`
/// and `r2` at `y = +h`: the 2D distance in the (radius, y) half-plane.
pub fn revolved_trapezoid(p: DVec3, h: f64, r1: f64, r2: f64) -> f64 {
    let q = DVec2::new(DVec2::new(p.x, p.z).length(), p.y);
    let section = [
        DVec2::new(-r1, -h),
        DVec2::new(r1, -h),
        DVec2::new(r2, h),
        DVec2::new(-r2, h),
    ];
    convex_polygon_distance(q, &section)
}

/// Signed distance to the prism over the regular hexagon in the xz plane
/// whose corners lie `2r / sqrt(3)` from the axis at 0°, 60°, ... from +x
/// (so its flat sides are `r` from the axis, two facing ±z), from `y = -h`
/// to `h`: the hexagon's 2D distance `a` and the caps' `b = |y| - h`
/// combine as for any extrusion, `|max(a, b, 0)|` outside and `max(a, b)`
/// inside.
pub fn hex_prism_distance(p: DVec3, r: f64, h: f64) -> f64 {
    let corner = 2.0 * r / 3f64.sqrt();
    let hexagon: Vec<DVec2> = (0..6)
        .map(|k| {
            let angle = std::f64::consts::FRAC_PI_3 * f64::from(k);
            DVec2::new(angle.cos(), angle.sin()) * corner
        })
        .collect();
    // Counter-clockwise in (x, z).
    let a = convex_polygon_distance(DVec2::new(p.x, p.z), &hexagon);
    let b = p.y.abs() - h;
    if a > 0.0 || b > 0.0 {
        DVec2::new(a.max(0.0), b.max(0.0)).length()
    } else {
        a.max(b)
    }
}

/// Signed distance to the convex hull of the balls of radius `r1` at
/// `(0, -h, 0)` and `r2` at `(0, h, 0)`: the hull is the union of the balls
/// `c(t) = (0, (2t - 1) h, 0)`, `r(t) = r1 + t (r2 - r1)` for `t` in
/// `[0, 1]`, whose boundary touches each ball it passes on a normal
/// through that ball's centre, so the distance is `min_t |p - c(t)| -
/// r(t)`, inside too. That function of `t` is convex; golden-section
/// search finds its minimum.
pub fn round_cone_distance(p: DVec3, h: f64, r1: f64, r2: f64) -> f64 {
    let f = |t: f64| p.distance(DVec3::new(0.0, (2.0 * t - 1.0) * h, 0.0)) - (r1 + t * (r2 - r1));
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..200 {
        let (x1, x2) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
        if f(x1) <= f(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    f(0.5 * (lo + hi)).min(f(0.0)).min(f(1.0))
}

/// Unsigned distance to the stadium curve in the xy plane: the segments
/// `x = ±r1`, `y` in `[-le, le]`, and the half circles of radius `r1`
/// around `(0, ±le, 0)` on the far sides (`|y| >= le`), each through its
/// nearest point.
pub fn link_curve_distance(p: DVec3, le: f64, r1: f64) -> f64 {
    let sides =
        [-r1, r1].map(|x| segment_distance(p, DVec3::new(x, -le, 0.0), DVec3::new(x, le, 0.0)));
    let arcs = [-le, le].map(|cy| {
        let q = DVec2::new(p.x, p.y - cy);
        // The nearest point of the whole circle, kept if on the half.
        let nearest = if q == DVec2::ZERO {
            DVec2::new(0.0, cy.signum() * r1)
        } else {
            q.normalize() * r1
        };
        if nearest.y * cy.signum() >= 0.0 {
            p.distance(DVec3::new(nearest.x, nearest.y + cy, 0.0))
        } else {
            f64::INFINITY
        }
    });
    sides.into_iter().chain(arcs).fold(f64::INFINITY, f64::min)
}

/// The true signed distance to the ellipsoid with semi-axes `radii`,
/// computed numerically (Eberly, "Distance from a point to an ellipse, an
/// ellipsoid, or a hyperellipsoid"): the nearest point is
/// `x_i = r_i^2 y_i / (r_i^2 + t)` for the root `t > -min(r_i)^2` of
/// `sum (r_i y_i / (r_i^2 + t))^2 = 1`, found by bisection. `y = |p|`
/// must have a non-zero component along the shortest axis.
pub fn ellipsoid_distance(p: DVec3, radii: DVec3) -> f64 {
    let y = p.abs();
    let shortest = radii.min_element();
    assert!(
        (0..3).any(|i| radii[i] == shortest && y[i] > 0.0),
        "the point must be off the plane of the two longer axes"
    );
    let f = |t: f64| {
        (0..3)
            .map(|i| (radii[i] * y[i] / (radii[i] * radii[i] + t)).powi(2))
            .sum::<f64>()
            - 1.0
    };
    let mut lo = -shortest * shortest;
    let mut hi = radii.max_element() * y.length() + 1.0;
    for _ in 0..2000 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if f(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let t = 0.5 * (lo + hi);
    let nearest = DVec3::from_array(std::array::from_fn(|i| {
        radii[i] * radii[i] * y[i] / (radii[i] * radii[i] + t)
    }));
    let distance = y.distance(nearest);
    if t < 0.0 { -distance } else { distance }
}

/// The point at angle `theta` from +y on the circle of radius `r`, in the
/// plane through the axis (`x` the distance from the axis).
fn on_circle(r: f64, theta: f64) -> DVec3 {
    DVec3::new(r * theta.sin(), r * theta.cos(), 0.0)
}

/// The point `p` in the plane through the y axis: its distance from the
/// axis, its height, and its angle from +y in `[0, π]`.
fn meridian(p: DVec3) -> (DVec3, f64) {
    let q = DVec3::new(DVec2::new(p.x, p.z).length(), p.y, 0.0);
    (q, q.x.atan2(q.y))
}

/// Signed distance to the ball of radius `r` cut by the plane `y = h`
/// (within `[-r, r]`), keeping the part below, in the plane through the
/// axis: the nearer of the cut face (a segment) and the arc of the circle
/// below the plane (the nearest point of the circle by angle, clamped to
/// the arc's angles), negative inside.
pub fn cut_sphere_distance(p: DVec3, r: f64, h: f64) -> f64 {
    let h = h.clamp(-r, r);
    let (q, theta) = meridian(p);
    let w = (r * r - h * h).max(0.0).sqrt();
    let face = segment_distance(q, DVec3::new(0.0, h, 0.0), DVec3::new(w, h, 0.0));
    let rim = if r > 0.0 {
        (h / r).clamp(-1.0, 1.0).acos()
    } else {
        0.0
    };
    let arc = q.distance(on_circle(r, theta.clamp(rim, std::f64::consts::PI)));
    let d = face.min(arc);
    if q.length() <= r && q.y <= h { -d } else { d }
}

/// Signed distance to the part of the ball of radius `r` within `angle` of
/// +y, in the plane through the axis: the nearer of the cone's side (a
/// segment from the origin) and the arc (the nearest point of the circle by
/// angle, clamped to `[0, angle]`), negative inside.
pub fn solid_angle_distance(p: DVec3, angle: f64, r: f64) -> f64 {
    let (q, theta) = meridian(p);
    let side = segment_distance(q, DVec3::ZERO, on_circle(r, angle));
    let arc = q.distance(on_circle(r, theta.min(angle)));
    let d = side.min(arc);
    if q.length() <= r && theta <= angle {
        -d
    } else {
        d
    }
}

/// Distance to the arc `major (sin t, cos t, 0)`, `|t| <= angle`: the
/// squared distance is `|p|² + major² − 2 major (x sin t + y cos t)`, whose
/// last term is `R cos(t − φ)` with `φ` the point's angle from +y in the
/// xy plane; folded to `x >= 0`, `φ` is in `[0, π]` and the nearest `t`
/// is `φ` clamped to the arc.
pub fn arc_distance(p: DVec3, angle: f64, major: f64) -> f64 {
    let q = DVec3::new(p.x.abs(), p.y, p.z);
    let phi = q.x.atan2(q.y);
    let t = phi.min(angle);
    q.distance(DVec3::new(major * t.sin(), major * t.cos(), 0.0))
}
