//! Distances to extruded and revolved plane profiles, derived from their
//! boundaries: the unsigned distance to the nearest boundary piece (an
//! edge through the cross product, an arc through its centre), signed by a
//! membership test (a winding number for polygons); a revolution's
//! distance is the smallest over every turn of the profile, searched
//! numerically rather than taken in the point's own meridian.

use super::analytic::segment_distance;
use fractal_sdf::scene::{Param, Profile};
use glam::{DVec2, DVec3};

/// The profile's numbers.
fn values(profile: &Profile) -> Profile<f64> {
    let v = |p: &Param| p.default_value();
    let two = |p: &[Param; 2]| [v(&p[0]), v(&p[1])];
    match profile {
        Profile::Circle { radius } => Profile::Circle { radius: v(radius) },
        Profile::Rect { half_extents } => Profile::Rect {
            half_extents: two(half_extents),
        },
        Profile::RoundRect {
            half_extents,
            radius,
        } => Profile::RoundRect {
            half_extents: two(half_extents),
            radius: v(radius),
        },
        Profile::Segment { a, b, radius } => Profile::Segment {
            a: two(a),
            b: two(b),
            radius: v(radius),
        },
        Profile::Polygon { vertices } => Profile::Polygon {
            vertices: vertices.iter().map(two).collect(),
        },
        Profile::Ellipse { radii } => Profile::Ellipse { radii: two(radii) },
        Profile::Vesica {
            half_length,
            half_width,
        } => Profile::Vesica {
            half_length: v(half_length),
            half_width: v(half_width),
        },
        _ => panic!("a profile the oracle does not know"),
    }
}

/// Unsigned distance from `q` to the segment `a`-`b`, in the plane `z = 0`
/// ([`segment_distance`]: to an end, or the perpendicular through the
/// cross product).
fn edge(q: DVec2, a: DVec2, b: DVec2) -> f64 {
    segment_distance(q.extend(0.0), a.extend(0.0), b.extend(0.0))
}

/// The polygon's winding number about `q`: the sum of the angles its
/// edges turn through seen from `q`, in whole turns.
fn winding(q: DVec2, vertices: &[DVec2]) -> i64 {
    let n = vertices.len();
    let turn: f64 = (0..n)
        .map(|i| {
            let (a, b) = (vertices[i] - q, vertices[(i + 1) % n] - q);
            a.perp_dot(b).atan2(a.dot(b))
        })
        .sum();
    (turn / std::f64::consts::TAU).round() as i64
}

fn corners(half: [f64; 2]) -> [DVec2; 4] {
    let [x, y] = half;
    [
        DVec2::new(-x, -y),
        DVec2::new(x, -y),
        DVec2::new(x, y),
        DVec2::new(-x, y),
    ]
}

/// The unsigned distance from `q` to the profile's boundary, and whether
/// `q` is in the profile.
fn boundary(profile: &Profile<f64>, q: DVec2) -> (f64, bool) {
    match profile {
        Profile::Circle { radius } => ((q.length() - radius).abs(), q.length() <= *radius),
        Profile::Rect { half_extents } => {
            let c = corners(*half_extents);
            let d = (0..4)
                .map(|i| edge(q, c[i], c[(i + 1) % 4]))
                .fold(f64::INFINITY, f64::min);
            let inside = q.x.abs() <= half_extents[0] && q.y.abs() <= half_extents[1];
            (d, inside)
        }
        Profile::RoundRect {
            half_extents: [hx, hy],
            radius: r,
        } => {
            // Four straight sides between the arcs' ends, and four quarter
            // circles about the inner rectangle's corners, each facing out
            // from its corner.
            let (ix, iy) = (hx - r, hy - r);
            let sides = [
                (DVec2::new(-ix, -hy), DVec2::new(ix, -hy)),
                (DVec2::new(-ix, *hy), DVec2::new(ix, *hy)),
                (DVec2::new(-hx, -iy), DVec2::new(-hx, iy)),
                (DVec2::new(*hx, -iy), DVec2::new(*hx, iy)),
            ];
            let mut d = sides
                .iter()
                .map(|(a, b)| edge(q, *a, *b))
                .fold(f64::INFINITY, f64::min);
            let mut inside =
                (q.x.abs() <= *hx && q.y.abs() <= iy) || (q.x.abs() <= ix && q.y.abs() <= *hy);
            for c in corners([ix, iy]) {
                let u = q - c;
                // On the quarter facing out from the corner; elsewhere the
                // arc's nearest point is an end, which a side holds.
                if u.x * c.x.signum() >= 0.0 && u.y * c.y.signum() >= 0.0 {
                    d = d.min((u.length() - r).abs());
                }
                inside |= u.length() <= *r;
            }
            (d, inside)
        }
        Profile::Segment { a, b, radius } => {
            let d = edge(q, DVec2::from(*a), DVec2::from(*b));
            ((d - radius).abs(), d <= *radius)
        }
        Profile::Vesica {
            half_length: b,
            half_width: w,
        } => {
            // Two arcs meeting at the tips: the circle through `(w, 0)` and
            // both tips, its centre on the x axis found from those three
            // points, and its mirror.
            let tips = [DVec2::new(0.0, *b), DVec2::new(0.0, -*b)];
            let centre_x = (w * w - b * b) / (2.0 * w);
            let radius = DVec2::new(centre_x, 0.0).distance(tips[0]);
            let mut d = f64::INFINITY;
            let mut inside = true;
            for side in [1.0, -1.0] {
                let centre = DVec2::new(side * centre_x, 0.0);
                let keep = |x: DVec2| x.x * side >= 0.0;
                d = d.min(super::shapes::arc_distance(q, centre, radius, keep, &tips));
                inside &= q.distance(centre) <= radius;
            }
            (d, inside)
        }
        Profile::Ellipse { radii: [a, b] } => {
            let inside = (q.x / a).powi(2) + (q.y / b).powi(2) <= 1.0;
            (ellipse_boundary(q, *a, *b), inside)
        }
        Profile::Polygon { vertices } => {
            let v: Vec<DVec2> = vertices.iter().copied().map(DVec2::from).collect();
            let n = v.len();
            let d = (0..n)
                .map(|i| edge(q, v[i], v[(i + 1) % n]))
                .fold(f64::INFINITY, f64::min);
            (d, winding(q, &v) != 0)
        }
        _ => unreachable!(),
    }
}

/// The distance from `q` to the ellipse `(a cos u, b sin u)`: the smallest
/// over its parameter (see [`minimise_over_turn`]).
fn ellipse_boundary(q: DVec2, a: f64, b: f64) -> f64 {
    // A point's distance along an ellipse has at most two valleys, each
    // wider than a grid step of 3 degrees.
    minimise_over_turn(120, |u| q.distance(DVec2::new(a * u.cos(), b * u.sin())))
}

/// The smallest value of `f` over a turn: a grid of `points`, then golden
/// sections within a grid step of its best three points.
fn minimise_over_turn(points: usize, f: impl Fn(f64) -> f64) -> f64 {
    let step = std::f64::consts::TAU / points as f64;
    let mut grid: Vec<(f64, f64)> = (0..points)
        .map(|i| (f(i as f64 * step), i as f64 * step))
        .collect();
    grid.sort_by(|a, b| a.0.total_cmp(&b.0));
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut best = grid[0].0;
    for &(_, u) in &grid[..3] {
        let (mut lo, mut hi) = (u - step, u + step);
        for _ in 0..64 {
            let (x1, x2) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
            if f(x1) <= f(x2) {
                hi = x2;
            } else {
                lo = x1;
            }
        }
        best = best.min(f(0.5 * (lo + hi)));
    }
    best
}

/// The signed distance from `q` to the profile.
pub fn profile_distance(profile: &Profile, q: DVec2) -> f64 {
    let (d, inside) = boundary(&values(profile), q);
    if inside { -d } else { d }
}

/// Signed distance to the prism of `profile` between `z = ±h`: the nearer
/// of its walls (the profile's boundary times `[-h, h]`) and the cap on
/// the point's side (the profile at `z = ±h`).
pub fn extrude_distance(profile: &Profile, h: f64, p: DVec3) -> f64 {
    let profile = values(profile);
    with_boundary(|q| boundary(&profile, q), h, p)
}

/// Signed distance to the prism between `z = ±h` over the plane region
/// whose boundary's distance and membership at a point `boundary` gives.
pub fn with_boundary(boundary: impl Fn(DVec2) -> (f64, bool), h: f64, p: DVec3) -> f64 {
    let (b, within) = boundary(DVec2::new(p.x, p.y));
    let over = p.z.abs() - h;
    let wall = b.hypot(over.max(0.0));
    let cap = if within { over.abs() } else { b.hypot(over) };
    let d = wall.min(cap);
    if within && over <= 0.0 { -d } else { d }
}

/// Signed distance to the solid `profile` sweeps turning around the y axis
/// with its origin at `offset` (where the profile lies at `x >= -offset`):
/// the smallest distance to the profile's boundary turned by any angle,
/// found by a search over the turn ([`minimise_over_turn`]), signed by
/// whether the point's meridian lies in the profile.
pub fn revolve_distance(profile: &Profile, offset: f64, p: DVec3) -> f64 {
    let profile = values(profile);
    // The distance to the boundary turned by `phi`: in its plane, and
    // across it.
    let at = |phi: f64| {
        let (s, c) = phi.sin_cos();
        let (u, w) = (p.x * c + p.z * s, p.z * c - p.x * s);
        boundary(&profile, DVec2::new(u - offset, p.y)).0.hypot(w)
    };
    // The distance along the turn has its valley at the point's own
    // meridian, wider than a grid step of 5 degrees.
    let best = minimise_over_turn(72, at);
    let meridian = DVec2::new(p.x.hypot(p.z) - offset, p.y);
    if boundary(&profile, meridian).1 {
        -best
    } else {
        best
    }
}
