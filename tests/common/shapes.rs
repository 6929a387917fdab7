//! Distances to the thickened triangles and quads, the pyramid, the
//! prisms, cones and cylinders, the cut hollow sphere and the death star,
//! derived from their boundaries: nearest points on triangles (Ericson's
//! Voronoi regions), arcs by angle, rays by angle, signed by membership.

use super::analytic::{closest_on_triangle, revolved_trapezoid, segment_distance};
use super::profiles::{extrude_distance, revolve_distance, with_boundary};
use fractal_sdf::prelude::*;
use fractal_sdf::scene::{Kind, Param, Param3, Profile};
use glam::DVec2;
use std::f64::consts::PI;

/// The exact signed distance of one of these shapes; `None` for any other
/// node.
pub fn distance(node: &Node, p: DVec3) -> Option<f64> {
    let v = |x: &Param| x.default_value();
    let v3 = |x: &Param3| x.default_value();
    Some(match node.kind() {
        Kind::Triangle { a, b, c, thickness } => triangle(p, v3(a), v3(b), v3(c)) - v(thickness),
        Kind::Quad {
            a,
            b,
            c,
            d,
            thickness,
        } => {
            let (a, b, c, d) = (v3(a), v3(b), v3(c), v3(d));
            triangle(p, a, b, c).min(triangle(p, a, c, d)) - v(thickness)
        }
        Kind::Pyramid { half_base, height } => pyramid(p, v(half_base), v(height)),
        Kind::Rhombus {
            half_x,
            half_z,
            half_height,
            radius,
        } => {
            let (x, z, r) = (v(half_x), v(half_z), v(radius));
            let rhombus = Profile::polygon([[x, 0.0], [0.0, z], [-x, 0.0], [0.0, -z]]);
            // The rhombus grown by `r` is convex: its distance is the
            // rhombus's less `r`, and its boundary that far out.
            let grown = |q: DVec2| {
                let d = super::profiles::profile_distance(&rhombus, q) - r;
                (d.abs(), d <= 0.0)
            };
            with_boundary(grown, v(half_height), DVec3::new(p.x, p.z, p.y))
        }
        Kind::TriPrism {
            radius,
            half_height,
        } => {
            // Corners twice the sides' distance out, at 90°, 210° and 330°
            // in the (x, z) plane.
            let corner = 2.0 * v(radius);
            let triangle = Profile::polygon([90.0f64, 210.0, 330.0].map(|deg| {
                let (s, c) = deg.to_radians().sin_cos();
                [corner * c, corner * s]
            }));
            extrude_distance(&triangle, v(half_height), DVec3::new(p.x, p.z, p.y))
        }
        Kind::RoundedCylinder {
            radius,
            half_height,
            rounding,
        } => revolve_distance(
            &Profile::round_rect(v(radius), v(half_height), v(rounding)),
            0.0,
            p,
        ),
        Kind::Cone { radius, height } => {
            let h = v(height);
            revolved_trapezoid(p + DVec3::Y * (0.5 * h), 0.5 * h, v(radius), 0.0)
        }
        Kind::InfiniteCylinder { radius } => DVec2::new(p.x, p.z).length() - v(radius),
        Kind::InfiniteCone { angle } => infinite_cone(p, v(angle)),
        Kind::CutHollowSphere {
            radius,
            height,
            thickness,
        } => cut_hollow_sphere(p, v(radius), v(height)) - v(thickness),
        Kind::DeathStar {
            radius,
            carve_radius,
            carve_distance,
        } => death_star(p, v(radius), v(carve_radius), v(carve_distance)),
        _ => return None,
    })
}

/// The unsigned distance to the triangle `abc`: to its nearest point (by
/// Ericson's Voronoi regions), or to its edges where it has no area.
fn triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    if (b - a).cross(c - a) == DVec3::ZERO {
        return segment_distance(p, a, b)
            .min(segment_distance(p, b, c))
            .min(segment_distance(p, c, a));
    }
    p.distance(closest_on_triangle(p, a, b, c))
}

/// The pyramid on `|x|, |z| <= w` at `y = 0` with its apex at `(0, h,
/// 0)`: the nearest of its four side triangles and the base's two,
/// negative inside the five faces' planes.
fn pyramid(p: DVec3, w: f64, h: f64) -> f64 {
    let apex = DVec3::new(0.0, h, 0.0);
    let c = [(w, w), (w, -w), (-w, -w), (-w, w)].map(|(x, z)| DVec3::new(x, 0.0, z));
    let mut faces: Vec<[DVec3; 3]> = (0..4).map(|i| [c[i], c[(i + 1) % 4], apex]).collect();
    faces.push([c[0], c[1], c[2]]);
    faces.push([c[0], c[2], c[3]]);
    let d = faces
        .iter()
        .map(|[a, b, t]| triangle(p, *a, *b, *t))
        .fold(f64::INFINITY, f64::min);
    let under = |x: f64| h * (x.abs() - w) + w * p.y < 0.0;
    if p.y > 0.0 && under(p.x) && under(p.z) {
        -d
    } else {
        d
    }
}

/// The infinite cone around +y of half-angle `angle`: in the plane through
/// the axis, at the point's angle `theta` from +y and distance `r` from the
/// apex, the side's ray is `|theta - angle|` away in angle: `r sin` of it
/// within a quarter turn, else the apex, `r`.
fn infinite_cone(p: DVec3, angle: f64) -> f64 {
    let rho = DVec2::new(p.x, p.z).length();
    let r = rho.hypot(p.y);
    let theta = rho.atan2(p.y);
    let gap = (theta - angle).abs();
    let d = if gap <= PI / 2.0 { r * gap.sin() } else { r };
    if theta < angle { -d } else { d }
}

/// The unsigned distance to the sphere's arc below the plane `y = h`: the
/// nearest point of the circle by angle in the plane through the axis,
/// clamped to the arc's angles (from the rim's to π).
fn cut_hollow_sphere(p: DVec3, r: f64, h: f64) -> f64 {
    let h = h.clamp(-r, r);
    let q = DVec2::new(DVec2::new(p.x, p.z).length(), p.y);
    let theta = q.x.atan2(q.y);
    let rim = if r > 0.0 { (h / r).acos() } else { 0.0 };
    let t = theta.max(rim);
    q.distance(DVec2::new(r * t.sin(), r * t.cos()))
}

/// The nearest point to `q` of the circle about `centre` of radius `r` where
/// `keep` holds, else of the ends `ends`: the distance along a circle falls
/// to the projection and rises away from it.
pub fn arc_distance(
    q: DVec2,
    centre: DVec2,
    r: f64,
    keep: impl Fn(DVec2) -> bool,
    ends: &[DVec2],
) -> f64 {
    let u = q - centre;
    let nearest = if u == DVec2::ZERO {
        centre + DVec2::new(r, 0.0)
    } else {
        centre + u.normalize() * r
    };
    let to_ends = ends
        .iter()
        .map(|e| q.distance(*e))
        .fold(f64::INFINITY, f64::min);
    if keep(nearest) {
        q.distance(nearest).min(to_ends)
    } else {
        to_ends
    }
}

/// The ball of radius `ra` less the ball of radius `rb` about `(d, 0, 0)`,
/// in the plane through the x axis: its boundary is the big circle outside
/// the small disc and the small circle inside the big disc, meeting at the
/// rim; the distance is the nearer arc's, negative inside the big ball and
/// outside the small one.
fn death_star(p: DVec3, ra: f64, rb: f64, d: f64) -> f64 {
    let q = DVec2::new(p.x, DVec2::new(p.y, p.z).length());
    let (a_centre, b_centre) = (DVec2::ZERO, DVec2::new(d, 0.0));
    // Where the circles cross, if they do.
    let a = (ra * ra - rb * rb + d * d) / (2.0 * d);
    let rims: Vec<DVec2> = if a.abs() < ra {
        let b = (ra * ra - a * a).sqrt();
        vec![DVec2::new(a, b), DVec2::new(a, -b)]
    } else {
        Vec::new()
    };
    let big = arc_distance(q, a_centre, ra, |x| x.distance(b_centre) >= rb, &rims);
    let small = arc_distance(q, b_centre, rb, |x| x.length() <= ra, &rims);
    let dist = big.min(small);
    if q.length() <= ra && q.distance(b_centre) >= rb {
        -dist
    } else {
        dist
    }
}
