//! Strategies that build only valid values.
//!
//! (They return `impl Strategy`, which is already `#[must_use]`.)

use std::f64::consts::PI;

use glam::{DQuat, DVec3};
use proptest::prelude::*;

use crate::cpu::Ray;
use crate::scene::{
    Axis, CsgOp, Hybrid, HybridOp, Kifs, KifsFold, Kind, MAX_ESCAPE_ITERATIONS,
    MAX_FOLD_ITERATIONS, MAX_SOLID_ANGLE, Mandelbox, Mandelbulb, Menger, Node, OrbitColoring,
    Palette, Param, Param3, Profile, PseudoKleinian, QuaternionJulia, Sierpinski, Trap, box_frame,
    capped_cone, capped_torus, capsule, cone, cone_between, cuboid, cut_hollow_sphere, cut_sphere,
    cylinder, cylinder_between, death_star, ellipsoid, extrude, hex_prism, infinite_cone,
    infinite_cylinder, link, octahedron, octahedron_bound, param, plane, pyramid, quad, revolve,
    rhombus, round_box, round_cone, round_cone_between, rounded_cylinder, solid_angle, sphere,
    torus, tri_prism, triangle,
};

/// The largest size (radius, half extent, height) the primitive strategies
/// draw.
const MAX_SIZE: f64 = 1.5;

/// A size in `[0, max]`: mostly in `[0.05, max]`, sometimes exactly 0.
fn size(max: f64) -> impl Strategy<Value = f64> + Clone {
    prop_oneof![1 => Just(0.0), 15 => 0.05..=max]
}

/// A scalar parameter: usually baked, sometimes dynamic. A dynamic
/// parameter is named after its tag (which fixes its rule) and its value,
/// so equal names always carry equal defaults and rules.
fn scalar(
    tag: &'static str,
    value: impl Strategy<Value = f64> + Clone,
) -> impl Strategy<Value = Param> + Clone {
    (value, prop::bool::weighted(0.2)).prop_map(move |(v, dynamic)| {
        if dynamic {
            param(format!("{tag}#{:016x}", v.to_bits()), v)
        } else {
            Param::Value(v)
        }
    })
}

/// Three components from one strategy.
fn vector(component: impl Strategy<Value = f64> + Clone) -> impl Strategy<Value = DVec3> + Clone {
    (component.clone(), component.clone(), component).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

/// A vector parameter (baked).
fn vector_param(
    component: impl Strategy<Value = f64> + Clone,
) -> impl Strategy<Value = Param3> + Clone {
    vector(component).prop_map(Param3::from)
}

/// A point in the cube `[-extent, extent]^3`.
///
/// # Panics
/// If `extent` is negative or not finite.
///
/// ```
/// use fractal_sdf::testing::point;
/// use proptest::prelude::*;
/// proptest!(|(p in point(2.0))| prop_assert!(p.abs().max_element() <= 2.0));
/// ```
pub fn point(extent: f64) -> impl Strategy<Value = DVec3> + Clone {
    assert!(
        extent >= 0.0 && extent.is_finite(),
        "extent must be finite and >= 0"
    );
    vector(-extent..=extent)
}

/// A unit vector, uniformly distributed on the sphere.
///
/// ```
/// use fractal_sdf::testing::unit_vector;
/// use proptest::prelude::*;
/// proptest!(|(u in unit_vector())| prop_assert!((u.length() - 1.0).abs() < 1e-12));
/// ```
pub fn unit_vector() -> impl Strategy<Value = DVec3> + Clone {
    // Archimedes: z uniform in [-1, 1] and a uniform angle give a uniform
    // point on the sphere.
    (-1.0..=1.0f64, 0.0..(2.0 * PI)).prop_map(|(z, phi): (f64, f64)| {
        let rho = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(rho * phi.cos(), rho * phi.sin(), z).normalize()
    })
}

/// A rotation: a unit axis and an angle in `[-pi, pi]`.
pub fn rotation() -> impl Strategy<Value = DQuat> + Clone {
    (unit_vector(), -PI..=PI).prop_map(|(axis, angle)| DQuat::from_axis_angle(axis, angle))
}

/// A ray from a point in `[-extent, extent]^3` in a uniform direction.
///
/// # Panics
/// If `extent` is negative or not finite.
pub fn ray(extent: f64) -> impl Strategy<Value = Ray> + Clone {
    (point(extent), unit_vector()).prop_map(|(origin, direction)| Ray { origin, direction })
}

/// Two points for a Lipschitz check: `p` in `[-extent, extent]^3` and `q`
/// at a distance from `p` spread log-uniformly over
/// `[1e-6 * max_separation, max_separation]`, in a uniform direction.
///
/// # Panics
/// If `extent` is negative or not finite, or `max_separation` is not
/// positive and finite.
pub fn point_pair(extent: f64, max_separation: f64) -> impl Strategy<Value = (DVec3, DVec3)> {
    assert!(
        max_separation > 0.0 && max_separation.is_finite(),
        "max_separation must be finite and > 0"
    );
    (point(extent), unit_vector(), 0.0..=6.0f64)
        .prop_map(move |(p, u, decades)| (p, p + u * (max_separation * 10f64.powf(-decades))))
}

/// A sphere of radius in `[0, 1.5]`.
pub fn sphere_node() -> impl Strategy<Value = Node> + Clone {
    scalar("sphere.radius", size(MAX_SIZE)).prop_map(sphere)
}

/// A box with half extents in `[0, 1.5]`.
pub fn cuboid_node() -> impl Strategy<Value = Node> + Clone {
    vector_param(size(MAX_SIZE)).prop_map(cuboid)
}

/// A rounded box: half extents in `[0, 1.5]`, rounding radius at most the
/// smallest half extent.
pub fn round_box_node() -> impl Strategy<Value = Node> + Clone {
    (vector(size(MAX_SIZE)), 0.0..=1.0f64).prop_map(|(b, f)| round_box(b, f * b.min_element()))
}

/// A torus: major radius in `[0, 1.5]`, minor radius in `[0, 0.6]` and at
/// most the major one (where the torus is exact).
pub fn torus_node() -> impl Strategy<Value = Node> + Clone {
    (size(MAX_SIZE), size(0.6))
        .prop_flat_map(|(major, minor)| {
            (
                scalar("torus.major_radius", Just(major)),
                scalar("torus.minor_radius", Just(minor.min(major))),
            )
        })
        .prop_map(|(major, minor)| torus(major, minor))
}

/// A capped cylinder: radius and half height in `[0, 1.5]`.
pub fn cylinder_node() -> impl Strategy<Value = Node> + Clone {
    (
        scalar("cylinder.radius", size(MAX_SIZE)),
        scalar("cylinder.half_height", size(MAX_SIZE)),
    )
        .prop_map(|(r, h)| cylinder(r, h))
}

/// A capsule between two points of `[-1.5, 1.5]^3`, radius in `[0, 0.8]`.
pub fn capsule_node() -> impl Strategy<Value = Node> + Clone {
    (
        point(MAX_SIZE),
        point(MAX_SIZE),
        scalar("capsule.radius", size(0.8)),
    )
        .prop_map(|(a, b, r)| capsule(a, b, r))
}

/// A half-space: a normal of length in `[0.1, 10]` (validation normalises
/// it) and an offset in `[-2, 2]`.
pub fn plane_node() -> impl Strategy<Value = Node> + Clone {
    (
        unit_vector(),
        0.1..=10.0f64,
        scalar("plane.offset", -2.0..=2.0f64),
    )
        .prop_map(|(n, len, offset)| plane(n * len, offset))
}

/// A regular octahedron of size in `[0, 1.5]`.
pub fn octahedron_node() -> impl Strategy<Value = Node> + Clone {
    scalar("octahedron.size", size(MAX_SIZE)).prop_map(octahedron)
}

/// A capped cone: half height and both cap radii in `[0, 1.5]`.
pub fn capped_cone_node() -> impl Strategy<Value = Node> + Clone {
    (
        scalar("capped_cone.half_height", size(MAX_SIZE)),
        scalar("capped_cone.bottom_radius", size(MAX_SIZE)),
        scalar("capped_cone.top_radius", size(MAX_SIZE)),
    )
        .prop_map(|(h, r1, r2)| capped_cone(h, r1, r2))
}

/// A hexagonal prism: radius (to the flat sides) and half height in
/// `[0, 1.5]`.
pub fn hex_prism_node() -> impl Strategy<Value = Node> + Clone {
    (
        scalar("hex_prism.radius", size(MAX_SIZE)),
        scalar("hex_prism.half_height", size(MAX_SIZE)),
    )
        .prop_map(|(r, h)| hex_prism(r, h))
}

/// A round cone: half height and both radii in `[0, 1.5]` (so sometimes
/// one ball holds the other).
pub fn round_cone_node() -> impl Strategy<Value = Node> + Clone {
    (
        scalar("round_cone.half_height", size(MAX_SIZE)),
        scalar("round_cone.bottom_radius", size(MAX_SIZE)),
        scalar("round_cone.top_radius", size(MAX_SIZE)),
    )
        .prop_map(|(h, r1, r2)| round_cone(h, r1, r2))
}

/// A chain link: half length and major radius in `[0, 1.5]`, the tube's
/// radius at most the major radius (where the link is exact).
pub fn link_node() -> impl Strategy<Value = Node> + Clone {
    (size(MAX_SIZE), size(MAX_SIZE), 0.0..=1.0f64)
        .prop_flat_map(|(le, r1, t)| {
            (
                scalar("link.half_length", Just(le)),
                scalar("link.major_radius", Just(r1)),
                scalar("link.minor_radius", Just(r1 * t)),
            )
        })
        .prop_map(|(le, r1, r2)| link(le, r1, r2))
}

/// A cut sphere: radius in `[0, 1.5]`, the cutting plane's height
/// anywhere from beyond the bottom to beyond the top.
pub fn cut_sphere_node() -> impl Strategy<Value = Node> + Clone {
    (size(MAX_SIZE), -1.2..=1.2f64)
        .prop_flat_map(|(r, t)| {
            (
                scalar("cut_sphere.radius", Just(r)),
                scalar("cut_sphere.height", Just(r * t)),
            )
        })
        .prop_map(|(r, h)| cut_sphere(r, h))
}

/// A solid angle: half-angle in `[0, MAX_SOLID_ANGLE]` (often 0, π/2 or
/// the top of the range), radius in `[0, 1.5]`.
pub fn solid_angle_node() -> impl Strategy<Value = Node> + Clone {
    let angle = prop_oneof![
        3 => 0.0..=MAX_SOLID_ANGLE,
        1 => Just(0.0),
        1 => Just(std::f64::consts::FRAC_PI_2),
        1 => Just(MAX_SOLID_ANGLE),
    ];
    (
        scalar("solid_angle.angle", angle),
        scalar("solid_angle.radius", size(MAX_SIZE)),
    )
        .prop_map(|(a, r)| solid_angle(a, r))
}

/// A capped torus where it is exact: half-angle in `[0, π]` (often a
/// quarter turn or the whole torus), arc radius in `[0, 1.5]`, and a tube
/// no thicker than the arc's radius, nor than `major sin(angle)` past a
/// quarter turn short of the whole torus (where the end caps would meet).
pub fn capped_torus_node() -> impl Strategy<Value = Node> + Clone {
    let angle = prop_oneof![
        3 => 0.0..=PI,
        1 => Just(0.0),
        1 => Just(PI / 2.0),
        1 => Just(PI),
    ];
    (angle, size(MAX_SIZE), 0.0..=1.0f64)
        .prop_flat_map(|(a, major, t)| {
            let room = if a > PI / 2.0 && a < PI { a.sin() } else { 1.0 };
            (
                scalar("capped_torus.angle", Just(a)),
                scalar("capped_torus.major", Just(major)),
                scalar("capped_torus.minor", Just(t * major * room)),
            )
        })
        .prop_map(|(a, major, minor)| capped_torus(a, major, minor))
}

/// A thickened triangle with corners in `[-1, 1]^3` (one time in eight
/// two of them the same), thickness in `[0.02, 0.4]`.
pub fn triangle_node() -> impl Strategy<Value = Node> + Clone {
    (
        segment_ends(),
        point(1.0),
        scalar("triangle.thickness", 0.02..=0.4f64),
    )
        .prop_map(|((a, b), c, t)| triangle(a, b, c, t))
}

/// A thickened quad where it is exact: flat and convex, its corners on a
/// circle of radius `[0.2, 1]` in a random plane about a point in
/// `[-0.5, 0.5]^3`, thickness in `[0.02, 0.4]`.
pub fn quad_node() -> impl Strategy<Value = Node> + Clone {
    (
        rotation(),
        point(0.5),
        0.2..=1.0f64,
        prop::array::uniform4(0.0..1.0f64),
        scalar("quad.thickness", 0.02..=0.4f64),
    )
        .prop_map(|(turn, centre, r, mut angles, t)| {
            angles.sort_by(f64::total_cmp);
            let [a, b, c, d] = angles.map(|u| {
                let (s, k) = (u * 2.0 * PI).sin_cos();
                centre + turn * DVec3::new(r * k, 0.0, r * s)
            });
            quad(a, b, c, d, t)
        })
}

/// A pyramid: half base in `[0.05, 1]`, height in `[0, 1.5]`.
pub fn pyramid_node() -> impl Strategy<Value = Node> + Clone {
    (
        scalar("pyramid.half_base", 0.05..=1.0f64),
        scalar("pyramid.height", size(MAX_SIZE)),
    )
        .prop_map(|(w, h)| pyramid(w, h))
}

/// A rounded rhombus: half diagonals and half height in `[0, 1]`, radius
/// in `[0, 0.5]`.
pub fn rhombus_node() -> impl Strategy<Value = Node> + Clone {
    (
        scalar("rhombus.half_x", size(1.0)),
        scalar("rhombus.half_z", size(1.0)),
        scalar("rhombus.half_height", size(1.0)),
        scalar("rhombus.radius", size(0.5)),
    )
        .prop_map(|(x, z, h, r)| rhombus(x, z, h, r))
}

/// A triangular prism: radius and half height in `[0, 1]`.
pub fn tri_prism_node() -> impl Strategy<Value = Node> + Clone {
    (
        scalar("tri_prism.radius", size(1.0)),
        scalar("tri_prism.half_height", size(1.0)),
    )
        .prop_map(|(r, h)| tri_prism(r, h))
}

/// A rounded cylinder: radius and half height in `[0, 1.2]`, rounding up
/// to the smaller.
pub fn rounded_cylinder_node() -> impl Strategy<Value = Node> + Clone {
    (size(1.2), size(1.2), 0.0..=1.0f64)
        .prop_flat_map(|(r, h, t)| {
            (
                scalar("rounded_cylinder.radius", Just(r)),
                scalar("rounded_cylinder.half_height", Just(h)),
                scalar("rounded_cylinder.rounding", Just(t * r.min(h))),
            )
        })
        .prop_map(|(r, h, e)| rounded_cylinder(r, h, e))
}

/// A cone: radius and height in `[0, 1.5]`.
pub fn cone_node() -> impl Strategy<Value = Node> + Clone {
    (
        scalar("cone.radius", size(MAX_SIZE)),
        scalar("cone.height", size(MAX_SIZE)),
    )
        .prop_map(|(r, h)| cone(r, h))
}

/// An infinite cylinder of radius in `[0, 1.5]`.
pub fn infinite_cylinder_node() -> impl Strategy<Value = Node> + Clone {
    scalar("infinite_cylinder.radius", size(MAX_SIZE)).prop_map(infinite_cylinder)
}

/// An infinite cone: half-angle in `[0, π/2]` (often either end).
pub fn infinite_cone_node() -> impl Strategy<Value = Node> + Clone {
    let angle = prop_oneof![
        4 => 0.0..=PI / 2.0,
        1 => Just(0.0),
        1 => Just(PI / 2.0),
    ];
    scalar("infinite_cone.angle", angle).prop_map(infinite_cone)
}

/// A cut hollow sphere where it is exact: radius in `[0, 1.5]`, the cut
/// anywhere (sometimes past the sphere), the shell no thicker than the
/// rim's radius (the sphere's, where the plane misses it).
pub fn cut_hollow_sphere_node() -> impl Strategy<Value = Node> + Clone {
    (size(MAX_SIZE), -1.2..=1.2f64, 0.0..=1.0f64)
        .prop_flat_map(|(r, k, u)| {
            let h = r * k;
            let rim = if h.abs() >= r {
                r
            } else {
                (r * r - h * h).sqrt()
            };
            (
                scalar("cut_hollow_sphere.radius", Just(r)),
                scalar("cut_hollow_sphere.height", Just(h)),
                scalar("cut_hollow_sphere.thickness", Just(u * rim)),
            )
        })
        .prop_map(|(r, h, t)| cut_hollow_sphere(r, h, t))
}

/// A death star: radius in `[0.2, 1.5]`, the carve's centre `(0, 2.5]`
/// along x, its radius in `[0.05, 1.5]` and short of holding the ball.
pub fn death_star_node() -> impl Strategy<Value = Node> + Clone {
    (0.2..=MAX_SIZE, 0.05..=2.5f64, 0.0..=1.0f64)
        .prop_flat_map(|(ra, d, u)| {
            let rb = 0.05 + u * (MAX_SIZE.min(ra + d - 0.05) - 0.05);
            (
                scalar("death_star.radius", Just(ra)),
                scalar("death_star.carve_radius", Just(rb)),
                scalar("death_star.carve_distance", Just(d)),
            )
        })
        .prop_map(|(ra, rb, d)| death_star(ra, rb, d))
}

/// The two ends of a segment in `[-1, 1]^3`, one time in eight the same
/// point.
fn segment_ends() -> impl Strategy<Value = (DVec3, DVec3)> + Clone {
    prop_oneof![
        7 => (point(1.0), point(1.0)),
        1 => point(1.0).prop_map(|a| (a, a)),
    ]
}

/// A capped cylinder around a segment in `[-1, 1]^3` (sometimes of length
/// 0), radius in `[0, 0.75]`.
pub fn cylinder_between_node() -> impl Strategy<Value = Node> + Clone {
    (
        segment_ends(),
        scalar("cylinder_between.radius", size(0.75)),
    )
        .prop_map(|((a, b), r)| cylinder_between(a, b, r))
}

/// A capped cone around a segment in `[-1, 1]^3` (sometimes of length 0),
/// each radius in `[0, 0.75]`.
pub fn cone_between_node() -> impl Strategy<Value = Node> + Clone {
    (
        segment_ends(),
        scalar("cone_between.radius_a", size(0.75)),
        scalar("cone_between.radius_b", size(0.75)),
    )
        .prop_map(|((a, b), ra, rb)| cone_between(a, b, ra, rb))
}

/// A round cone between balls about the ends of a segment in `[-1, 1]^3`
/// (sometimes of length 0, or with one ball holding the other), each
/// radius in `[0, 0.75]`.
pub fn round_cone_between_node() -> impl Strategy<Value = Node> + Clone {
    (
        segment_ends(),
        scalar("round_cone_between.radius_a", size(0.75)),
        scalar("round_cone_between.radius_b", size(0.75)),
    )
        .prop_map(|((a, b), ra, rb)| round_cone_between(a, b, ra, rb))
}

/// A plane profile's values: a disc, a rectangle, a rounded rectangle, a
/// segment's stadium, an ellipse (sometimes a circle), a vesica, or a
/// polygon of 3 to 12 corners in either winding,
/// star-shaped about a point near the origin (so its edges never cross),
/// sometimes with a corner repeated (an edge of length 0).
fn profile_values() -> impl Strategy<Value = Profile<f64>> + Clone {
    let corner = (0.0..=0.8f64, 0.1..=1.2f64);
    let polygon = (
        prop::collection::vec(corner, 3..=12),
        (-0.4..=0.4f64, -0.4..=0.4f64),
        any::<bool>(),
        prop::option::weighted(0.15, any::<prop::sample::Index>()),
    )
        .prop_map(|(corners, centre, reversed, repeated)| {
            let n = corners.len() as f64;
            let mut vertices: Vec<[f64; 2]> = corners
                .iter()
                .enumerate()
                .map(|(i, (jitter, r))| {
                    let a = (i as f64 + jitter) * 2.0 * PI / n;
                    [centre.0 + r * a.cos(), centre.1 + r * a.sin()]
                })
                .collect();
            if reversed {
                vertices.reverse();
            }
            if let Some(i) = repeated {
                let i = i.index(vertices.len());
                vertices.insert(i, vertices[i]);
            }
            Profile::Polygon { vertices }
        });
    let at = (-1.0..=1.0f64, -1.0..=1.0f64).prop_map(|(x, y)| [x, y]);
    prop_oneof![
        1 => size(1.0).prop_map(|radius| Profile::Circle { radius }),
        1 => (size(1.0), size(1.0)).prop_map(|(x, y)| Profile::Rect {
            half_extents: [x, y]
        }),
        1 => (size(1.0), size(1.0), 0.0..=1.0f64).prop_map(|(x, y, t)| Profile::RoundRect {
            half_extents: [x, y],
            radius: t * x.min(y),
        }),
        1 => (at.clone(), at, 0.02..=0.5f64).prop_map(|(a, b, radius)| Profile::Segment {
            a,
            b,
            radius
        }),
        1 => prop_oneof![
            3 => (0.05..=1.0f64, 0.05..=1.0f64).prop_map(|(a, b)| [a, b]),
            1 => (0.05..=1.0f64).prop_map(|a| [a, a]),
        ]
        .prop_map(|radii| Profile::Ellipse { radii }),
        1 => (0.1..=1.0f64, 0.05..=1.0f64).prop_map(|(half_length, u)| Profile::Vesica {
            half_length,
            half_width: u * half_length,
        }),
        3 => polygon,
    ]
}

/// A profile from its values: all baked, or (one time in five) all
/// dynamic, each named after its place and value.
fn profile_params(values: &Profile<f64>, dynamic: bool) -> Profile {
    let Ok(profile) = values.try_map(&mut |v, spec| {
        Ok::<_, std::convert::Infallible>(if dynamic {
            param(format!("{}#{:016x}", spec.name, v.to_bits()), *v)
        } else {
            Param::Value(*v)
        })
    });
    profile
}

/// A plane profile (see [`extrude_node`]).
pub fn profile() -> impl Strategy<Value = Profile> + Clone {
    (profile_values(), prop::bool::weighted(0.2)).prop_map(|(v, d)| profile_params(&v, d))
}

/// A profile extruded to a half height in `[0, 1]`: a disc, a rectangle,
/// a rounded rectangle, a stadium or a simple polygon (star-shaped, in
/// either winding, sometimes with an edge of length 0).
pub fn extrude_node() -> impl Strategy<Value = Node> + Clone {
    (profile(), scalar("extrude.half_height", size(1.0))).prop_map(|(p, h)| extrude(p, h))
}

/// A profile revolved where it is exact: its origin at an offset that
/// keeps it at `x >= -offset` (touching the axis one time in four).
pub fn revolve_node() -> impl Strategy<Value = Node> + Clone {
    (
        profile_values(),
        prop::bool::weighted(0.2),
        prop_oneof![1 => Just(0.0), 3 => 0.0..=0.8f64],
    )
        .prop_flat_map(|(values, dynamic, gap)| {
            let offset = gap - profile_left(&values).min(0.0);
            (
                Just(profile_params(&values, dynamic)),
                scalar("revolve.offset", Just(offset)),
            )
        })
        .prop_map(|(p, offset)| revolve(p, offset))
}

/// The profile's smallest x.
fn profile_left(profile: &Profile<f64>) -> f64 {
    match profile {
        Profile::Circle { radius } => -radius,
        Profile::Rect { half_extents } | Profile::RoundRect { half_extents, .. } => {
            -half_extents[0]
        }
        Profile::Segment { a, b, radius } => a[0].min(b[0]) - radius,
        Profile::Polygon { vertices } => {
            vertices.iter().map(|v| v[0]).fold(f64::INFINITY, f64::min)
        }
        Profile::Ellipse { radii } => -radii[0],
        Profile::Vesica { half_width, .. } => -half_width,
    }
}

/// A box frame (exact outside, a bound inside): half extents in `[0,
/// 1.2]`, thickness up to the smallest.
pub fn box_frame_node() -> impl Strategy<Value = Node> + Clone {
    (vector(size(1.2)), 0.0..=1.0f64)
        .prop_flat_map(|(b, u)| {
            (
                Just(b),
                scalar("box_frame.thickness", Just(u * b.min_element())),
            )
        })
        .prop_map(|(b, t)| box_frame(b, t))
}

/// Quilez's octahedron bound (not exact) of size in `[0, 1.5]`.
pub fn octahedron_bound_node() -> impl Strategy<Value = Node> + Clone {
    scalar("octahedron.size", size(MAX_SIZE)).prop_map(octahedron_bound)
}

/// An ellipsoid (a distance bound, not exact) with semi-axes in
/// `[0.05, 1.5]`.
pub fn ellipsoid_node() -> impl Strategy<Value = Node> + Clone {
    vector(0.05..=MAX_SIZE).prop_map(ellipsoid)
}

/// Any exact primitive (not the ellipsoid), untransformed.
pub fn exact_primitive() -> impl Strategy<Value = Node> + Clone {
    prop_oneof![
        sphere_node(),
        cuboid_node(),
        round_box_node(),
        torus_node(),
        cylinder_node(),
        capsule_node(),
        plane_node(),
        octahedron_node(),
        capped_cone_node(),
        hex_prism_node(),
        round_cone_node(),
        link_node(),
        cut_sphere_node(),
        solid_angle_node(),
        capped_torus_node(),
        triangle_node(),
        quad_node(),
        pyramid_node(),
        rhombus_node(),
        tri_prism_node(),
        rounded_cylinder_node(),
        cone_node(),
        infinite_cylinder_node(),
        infinite_cone_node(),
        cut_hollow_sphere_node(),
        death_star_node(),
        cylinder_between_node(),
        cone_between_node(),
        round_cone_between_node(),
        extrude_node(),
        revolve_node(),
    ]
}

/// A distance-preserving transform.
#[derive(Debug, Clone)]
enum Rigid {
    Translate(DVec3),
    Rotate(DQuat),
    Scale(f64),
}

impl Rigid {
    fn apply(self, node: Node) -> Node {
        match self {
            Rigid::Translate(v) => node.translate(v),
            Rigid::Rotate(q) => node.rotate_quat(q),
            Rigid::Scale(s) => node.scale(s),
        }
    }
}

fn rigid() -> impl Strategy<Value = Rigid> + Clone {
    prop_oneof![
        point(2.0).prop_map(Rigid::Translate),
        rotation().prop_map(Rigid::Rotate),
        (0.25..=4.0f64).prop_map(Rigid::Scale),
    ]
}

fn transformed(node: impl Strategy<Value = Node>, max: usize) -> impl Strategy<Value = Node> {
    (node, prop::collection::vec(rigid(), 0..=max))
        .prop_map(|(n, ts)| ts.into_iter().fold(n, |n, t| t.apply(n)))
}

/// Any exact primitive under up to three translations, rotations and
/// uniform scales, all of which keep the distance exact.
pub fn exact_node() -> impl Strategy<Value = Node> + Clone {
    transformed(exact_primitive(), 3).boxed()
}

/// A shape symmetric under each axis' sign flip, with the half extents of
/// its bounding box.
fn symmetric_shape() -> impl Strategy<Value = (Node, DVec3)> {
    prop_oneof![
        size(MAX_SIZE).prop_map(|r| (sphere(r), DVec3::splat(r))),
        vector(size(MAX_SIZE)).prop_map(|b| (cuboid(b), b)),
        (vector(size(MAX_SIZE)), 0.0..=1.0f64)
            .prop_map(|(b, f)| (round_box(b, f * b.min_element()), b)),
        (size(MAX_SIZE), size(0.6)).prop_map(|(big, small)| (
            torus(big, small),
            DVec3::new(big + small, small, big + small)
        )),
        (size(MAX_SIZE), size(MAX_SIZE)).prop_map(|(r, h)| (cylinder(r, h), DVec3::new(r, h, r))),
        size(MAX_SIZE).prop_map(|s| (octahedron(s), DVec3::splat(s))),
    ]
}

/// Repetition that stays a distance bound: a shape symmetric under each
/// axis' sign flip, repeated (infinitely or within limits) with a period
/// per axis of 0 (no repetition) or at least twice the shape's extent, so
/// every copy lies inside its own cell.
pub fn repeated_node() -> impl Strategy<Value = Node> + Clone {
    let period = prop_oneof![1 => Just(None), 3 => (0.0..=1.0f64).prop_map(Some)];
    (
        symmetric_shape(),
        period.clone(),
        period.clone(),
        period,
        prop::option::of([0u32..=3, 0..=3, 0..=3]),
    )
        .prop_map(|((shape, extent), px, py, pz, limit)| {
            let cell = |gap: Option<f64>, e: f64| gap.map_or(0.0, |g| 2.0 * e + g + 0.01);
            let period = DVec3::new(cell(px, extent.x), cell(py, extent.y), cell(pz, extent.z));
            match limit {
                Some(limit) => shape.repeat_limited(period, limit),
                None => shape.repeat(period),
            }
        })
        .boxed()
}

fn axis() -> impl Strategy<Value = Axis> + Clone {
    prop_oneof![Just(Axis::X), Just(Axis::Y), Just(Axis::Z)]
}

fn color() -> impl Strategy<Value = DVec3> + Clone {
    vector(0.0..=1.0f64)
}

/// A boolean of two nodes: one of the four operations, hard or smooth
/// with `k` in `[0, 1]` (sometimes exactly 0).
fn csg(a: Node, b: Node, op: u8, smoothing: Option<f64>) -> Node {
    match (op % 4, smoothing) {
        (0, None) => a.union(b),
        (1, None) => a.subtract(b),
        (2, None) => a.intersect(b),
        (_, None) => a.cut(b),
        (0, Some(k)) => a.smooth_union(b, k),
        (1, Some(k)) => a.smooth_subtract(b, k),
        (2, Some(k)) => a.smooth_intersect(b, k),
        (_, Some(k)) => Node::from(Kind::Csg {
            op: CsgOp::Cut,
            smoothing: Some(k.into()),
            a,
            b,
        }),
    }
}

fn smoothing() -> impl Strategy<Value = Option<f64>> + Clone {
    prop_oneof![
        2 => Just(None),
        1 => Just(Some(0.0)),
        3 => (0.0..=1.0f64).prop_map(Some),
    ]
}

/// Operations that keep a 1-Lipschitz distance bound 1-Lipschitz.
fn lipschitz_ops(inner: BoxedStrategy<Node>) -> impl Strategy<Value = Node> {
    prop_oneof![
        (inner.clone(), rigid()).prop_map(|(n, t)| t.apply(n)),
        (inner.clone(), -3.0..=3.0f64).prop_map(|(n, k)| n.twist(k)),
        (inner.clone(), -3.0..=3.0f64).prop_map(|(n, k)| n.bend(k)),
        (inner.clone(), axis()).prop_map(|(n, a)| n.mirror(a)),
        (inner.clone(), 0.0..=0.3f64).prop_map(|(n, r)| n.round(r)),
        (inner.clone(), 0.0..=0.2f64).prop_map(|(n, t)| n.onion(t)),
        (inner.clone(), vector(0.0..=0.5f64)).prop_map(|(n, e)| n.elongate(e)),
        (inner.clone(), color()).prop_map(|(n, c)| n.color(c)),
        (inner.clone(), color(), 0.0..=2.0f64).prop_map(|(n, c, s)| n.glow(c, s)),
        (inner.clone(), inner, 0u8..3, smoothing()).prop_map(|(a, b, op, k)| csg(a, b, op, k)),
    ]
}

/// Nodes whose distance is a 1-Lipschitz bound, so it never overestimates:
/// exact primitives and bounded repetitions ([`repeated_node`]) as leaves,
/// combined to depth 3 by transforms, twist and bend (rates in `[-3, 3]`),
/// mirror, round, onion, elongate, colour, glow and hard and smooth
/// booleans.
///
/// The ellipsoid is not here: outside it is a bound, but not a 1-Lipschitz
/// one near thin ellipsoids.
pub fn bounded_node() -> impl Strategy<Value = Node> + Clone {
    let leaf = prop_oneof![
        6 => exact_node(),
        1 => repeated_node(),
    ];
    leaf.prop_recursive(3, 12, 2, lipschitz_ops).boxed()
}

/// An iteration count in `min..=max`, often small, sometimes an end of the
/// range.
fn iterations(min: u32, max: u32, usual: u32) -> impl Strategy<Value = u32> {
    prop_oneof![
        4 => min..=usual,
        1 => Just(min),
        1 => Just(max),
        1 => min..=max,
    ]
}

/// An escape radius in `[1, 1e6]`: usually near 2 to 4, sometimes an end
/// of the range.
fn bailout() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => 1.5..=8.0f64,
        1 => Just(1.0),
        1 => Just(1e6),
        1 => 1.0..=1e6f64,
    ]
}

/// A Mandelbulb with any valid settings: power in `[2, 64]` (integer or
/// not, baked or dynamic, so both the trig-free and the trigonometric
/// form are drawn), iterations in `1..=256`, bailout in `[1, 1e6]`.
pub fn mandelbulb_node() -> impl Strategy<Value = Node> + Clone {
    let power = prop_oneof![
        3 => (2u32..=16).prop_map(f64::from),
        2 => 2.0..=16.0f64,
        1 => (17u32..=64).prop_map(f64::from),
        1 => 16.0..=64.0f64,
    ];
    (
        scalar("mandelbulb.power", power),
        iterations(1, MAX_ESCAPE_ITERATIONS, 16),
        bailout(),
    )
        .prop_map(|(power, n, b)| Mandelbulb::new(power).iterations(n).bailout(b).into())
        .boxed()
}

/// A Menger sponge with 0 to 20 levels and a scale in `[2, 4]` (often the
/// classic 3).
pub fn menger_node() -> impl Strategy<Value = Node> + Clone {
    let scale = prop_oneof![Just(3.0), 2.0..=4.0f64];
    (iterations(0, MAX_FOLD_ITERATIONS, 6), scale)
        .prop_map(|(n, s)| Menger::new(n).scale(s).into())
        .boxed()
}

/// A quaternion Julia set: `c` in `[-1.5, 1.5]^4` (sometimes up to the
/// valid `[-4, 4]^4`), iterations in `1..=256`, bailout in `[1, 1e6]`,
/// slice `w` in `[-2, 2]`.
pub fn julia_node() -> impl Strategy<Value = Node> + Clone {
    let component = prop_oneof![4 => -1.5..=1.5f64, 1 => -4.0..=4.0f64];
    (
        [
            scalar("julia.c", component.clone()),
            scalar("julia.c", component.clone()),
            scalar("julia.c", component.clone()),
            scalar("julia.c", component),
        ],
        iterations(1, MAX_ESCAPE_ITERATIONS, 16),
        bailout(),
        -2.0..=2.0f64,
    )
        .prop_map(|(c, n, b, w)| {
            QuaternionJulia::new(c)
                .iterations(n)
                .bailout(b)
                .slice_w(w)
                .into()
        })
        .boxed()
}

/// A Sierpinski tetrahedron with 0 to 20 levels and a scale in `[1.5, 4]`
/// (often the classic 2).
pub fn sierpinski_node() -> impl Strategy<Value = Node> + Clone {
    let scale = prop_oneof![Just(2.0), 1.5..=4.0f64];
    (iterations(0, MAX_FOLD_ITERATIONS, 8), scale)
        .prop_map(|(n, s)| Sierpinski::new(n).scale(s).into())
        .boxed()
}

/// A Mandelbox: scale often the classic −1.5 or 2, otherwise of magnitude
/// in `[1.1, 4]` with either sign; radii in `[0.1, 1]` and `[0.5, 1.5]`,
/// fold limit in `[0.5, 1.5]`, iterations in `1..=256`, and a Julia
/// constant in `[-1.5, 1.5]^3` one time in four.
pub fn mandelbox_node() -> impl Strategy<Value = Node> + Clone {
    let scale = prop_oneof![
        1 => Just(-1.5),
        1 => Just(2.0),
        2 => (1.1..=4.0f64, any::<bool>()).prop_map(|(s, neg)| if neg { -s } else { s }),
    ];
    let component = || scalar("mandelbox.julia", -1.5..=1.5f64);
    let julia = prop::option::weighted(0.25, [component(), component(), component()]);
    (
        scalar("mandelbox.scale", scale),
        scalar("mandelbox.min_radius", 0.1..=1.0f64),
        scalar("mandelbox.fixed_radius", 0.5..=1.5f64),
        scalar("mandelbox.fold_limit", 0.5..=1.5f64),
        iterations(1, MAX_ESCAPE_ITERATIONS, 16),
        julia,
    )
        .prop_map(|(s, min, fixed, limit, n, julia)| {
            let m = Mandelbox::new(s)
                .min_radius(min)
                .fixed_radius(fixed)
                .fold_limit(limit)
                .iterations(n);
            match julia {
                Some(c) => m.julia(c).into(),
                None => m.into(),
            }
        })
        .boxed()
}

/// A kaleidoscopic IFS of any fold: often its classic settings,
/// otherwise a scale in `[1.1, 4]` and an offset in `[-1.5, 1.5]^3`; each
/// turn one time in three, with angles in `[-π, π]`; 0 to 20 iterations.
pub fn kifs_node() -> impl Strategy<Value = Node> + Clone {
    let fold = prop_oneof![
        Just(KifsFold::Tetrahedral),
        Just(KifsFold::Octahedral),
        Just(KifsFold::Icosahedral),
        Just(KifsFold::Menger),
    ];
    let component = |tag: &'static str| scalar(tag, -1.5..=1.5f64);
    let offset = prop::option::weighted(
        0.5,
        [
            component("kifs.offset"),
            component("kifs.offset"),
            component("kifs.offset"),
        ],
    );
    let angle = || scalar("kifs.angle", -std::f64::consts::PI..=std::f64::consts::PI);
    let turn = || prop::option::weighted(0.3, [angle(), angle(), angle()]);
    (
        fold,
        prop::option::weighted(0.5, scalar("kifs.scale", 1.1..=4.0f64)),
        offset,
        turn(),
        turn(),
        iterations(0, MAX_FOLD_ITERATIONS, 8),
    )
        .prop_map(|(fold, scale, offset, before, after, n)| {
            let mut k = Kifs::new(fold).iterations(n);
            if let Some(s) = scale {
                k = k.scale(s);
            }
            if let Some(o) = offset {
                k = k.offset(o);
            }
            k.rotate_before = before;
            k.rotate_after = after;
            k.into()
        })
        .boxed()
}

/// Knighty's pseudo-Kleinian fractal: often the published preset,
/// otherwise fold sizes in `[0.5, 1.2]`, an inversion in `[0.3, 2]`, an
/// offset in `[-0.3, 0.3]^3` one time in three, a thickness in `[0.005,
/// 0.1]`; 0 to [`MAX_ESCAPE_ITERATIONS`] iterations, usually at most 10.
pub fn pseudo_kleinian_node() -> impl Strategy<Value = Node> + Clone {
    let size = || scalar("kleinian.size", 0.5..=1.2f64);
    let component = || scalar("kleinian.offset", -0.3..=0.3f64);
    let settings = (
        [size(), size(), size()],
        scalar("kleinian.inversion", 0.3..=2.0f64),
        prop::option::weighted(0.3, [component(), component(), component()]),
        scalar("kleinian.thickness", 0.005..=0.1f64),
    );
    (
        prop::option::weighted(0.7, settings),
        iterations(0, MAX_ESCAPE_ITERATIONS, 10),
    )
        .prop_map(|(settings, n)| {
            let mut k = PseudoKleinian::new().iterations(n);
            if let Some((size, inversion, offset, thickness)) = settings {
                k = k.fold_size(size).inversion(inversion).thickness(thickness);
                if let Some(c) = offset {
                    k = k.offset(c);
                }
            }
            k.into()
        })
        .boxed()
}

/// Any of the fractals with valid parameters (hybrids small and rare).
pub fn fractal_node() -> impl Strategy<Value = Node> + Clone {
    prop_oneof![
        4 => mandelbulb_node(),
        4 => menger_node(),
        4 => julia_node(),
        4 => sierpinski_node(),
        4 => mandelbox_node(),
        4 => kifs_node(),
        4 => pseudo_kleinian_node(),
        // Small and rare: every operation is written out in the kernel,
        // which an OpenCL compiler takes its time over, and whole scenes
        // hold many fractals ([`hybrid_node`] has the full range).
        1 => hybrid_of_size(2, 3, 1),
    ]
}

/// A trap of every kind, with values near the fractals (20% dynamic
/// scalars); directions are never zero.
pub fn trap() -> impl Strategy<Value = Trap> + Clone {
    let at = || vector_param(-1.0..=1.0f64);
    let direction = || unit_vector().prop_map(Param3::from);
    prop_oneof![
        at().prop_map(Trap::point),
        (at(), scalar("trap.radius", 0.0..=1.0f64)).prop_map(|(c, r)| Trap::sphere(c, r)),
        (direction(), scalar("trap.offset", -1.0..=1.0f64)).prop_map(|(n, d)| Trap::plane(n, d)),
        (at(), direction()).prop_map(|(q, u)| Trap::line(q, u)),
        Just(Trap::Iterations),
    ]
}

/// A named palette, or a gradient of 1 to 5 stops.
pub fn palette() -> impl Strategy<Value = Palette> + Clone {
    let names: Vec<&'static str> = Palette::names().collect();
    let gradient = prop::collection::vec((0.0..=1.0f64, color()), 1..=5).prop_map(|mut stops| {
        stops.sort_by(|a, b| a.0.total_cmp(&b.0));
        stops.dedup_by(|a, b| a.0 == b.0);
        Palette::gradient(stops.into_iter().map(|(t, c)| (t, c.to_array())))
    });
    prop_oneof![
        prop::sample::select(names).prop_map(|n| Palette::named(n).expect("a named palette")),
        gradient,
    ]
}

/// A fractal ([`fractal_node`]) coloured by an orbit trap: a random trap
/// and palette, and a range that may be reversed.
pub fn orbit_trap_node() -> impl Strategy<Value = Node> + Clone {
    let range = (
        scalar("trap.near", -0.5..=0.5f64),
        scalar("trap.far", 0.6..=2.0f64),
        any::<bool>(),
    );
    (fractal_node(), trap(), palette(), range).prop_map(|(f, trap, palette, (near, far, flip))| {
        let coloring = OrbitColoring::new(trap, palette);
        let coloring = if flip {
            coloring.range(far, near)
        } else {
            coloring.range(near, far)
        };
        f.orbit_coloring(coloring)
    })
}

/// One random hybrid operation of every kind, with parameters in their
/// valid ranges (20% dynamic); powers are the integers 2 to 8 (a real
/// power's map is discontinuous across the half-plane `y = 0, x < 0`,
/// where no estimate from a derivative holds).
pub fn hybrid_op() -> impl Strategy<Value = HybridOp> + Clone {
    let size = |tag| scalar(tag, 0.3..=1.5f64);
    let coordinate = |tag| scalar(tag, -1.0..=1.0f64);
    let three = move |tag| [coordinate(tag), coordinate(tag), coordinate(tag)];
    let angle = || scalar("hybrid.angle", -std::f64::consts::PI..=std::f64::consts::PI);
    let fold = prop_oneof![
        Just(KifsFold::Tetrahedral),
        Just(KifsFold::Octahedral),
        Just(KifsFold::Icosahedral),
        Just(KifsFold::Menger),
    ];
    let power = (2u32..=8).prop_map(f64::from);
    let factor = (0.5..=3.0f64, any::<bool>()).prop_map(|(s, neg)| if neg { -s } else { s });
    prop_oneof![
        size("hybrid.limit").prop_map(|l| HybridOp::BoxFold { limit: l }),
        (size("hybrid.limit"), size("hybrid.limit")).prop_map(|(x, y)| HybridOp::SurfFold {
            limit_x: x,
            limit_y: y
        }),
        (scalar("hybrid.min", 0.1..=1.0f64), size("hybrid.fixed")).prop_map(|(m, f)| {
            HybridOp::SphereFold {
                min_radius: m,
                fixed_radius: f,
            }
        }),
        (scalar("hybrid.factor", factor), three("hybrid.center")).prop_map(|(f, c)| {
            HybridOp::Scale {
                factor: f,
                center: c,
            }
        }),
        [angle(), angle(), angle()].prop_map(|a| HybridOp::Rotate { angles: a }),
        Just(HybridOp::AbsFold),
        (three("hybrid.normal"), coordinate("hybrid.offset")).prop_map(|(n, o)| {
            HybridOp::PlaneFold {
                normal: n,
                offset: o,
            }
        }),
        fold.prop_map(HybridOp::Fold),
        scalar("hybrid.power", power).prop_map(|p| HybridOp::Power { power: p }),
        any::<bool>().prop_map(|negate_z| HybridOp::BulbSquare { negate_z }),
        Just(HybridOp::QuaternionSquare),
        Just(HybridOp::AddPoint),
        three("hybrid.c").prop_map(|c| HybridOp::AddConstant { c }),
    ]
}

/// Random hybrids: one to three stages of one to four operations
/// ([`hybrid_op`]), each repeated up to twice, 0 to 8 iterations and a
/// bailout of 2 to 16.
pub fn hybrid_node() -> impl Strategy<Value = Node> + Clone {
    hybrid_of_size(3, 4, 2)
}

/// Random hybrids of at most `stages` stages of at most `ops` operations,
/// each repeated at most `repeat` times.
fn hybrid_of_size(stages: usize, ops: usize, repeat: u32) -> impl Strategy<Value = Node> + Clone {
    let stage = (1u32..=repeat, prop::collection::vec(hybrid_op(), 1..=ops));
    (
        prop::collection::vec(stage, 1..=stages),
        0u32..=8,
        scalar("hybrid.bailout", 2.0..=16.0f64),
    )
        .prop_map(|(stages, n, bailout)| {
            stages
                .into_iter()
                .fold(Hybrid::new(), |h, (repeat, ops)| h.stage(repeat, ops))
                .iterations(n)
                .bailout(bailout)
                .into()
        })
}

/// Whole scenes: random trees of depth at most `depth` (and a size that
/// grows with it) mixing every node type: exact primitives, ellipsoids,
/// fractals, every transform and domain operation (twist and bend with
/// rates in `[-3, 3]`, repetition with any period and any child) and hard
/// and smooth booleans. They always validate; their distances need not be
/// bounds.
pub fn scene_node(depth: u32) -> impl Strategy<Value = Node> + Clone {
    let leaf = prop_oneof![
        6 => exact_node(),
        1 => ellipsoid_node(),
        1 => box_frame_node(),
        1 => octahedron_bound_node(),
        2 => fractal_node(),
        1 => orbit_trap_node(),
    ];
    leaf.prop_recursive(depth, 4 * depth + 4, 2, |inner| {
        let period = vector(prop_oneof![Just(0.0), 0.5..=4.0f64]);
        prop_oneof![
            4 => lipschitz_ops(inner.clone()),
            1 => (inner.clone(), period.clone()).prop_map(|(n, c)| n.repeat(c)),
            1 => (inner, period, [0u32..=3, 0..=3, 0..=3])
                .prop_map(|(n, c, l)| n.repeat_limited(c, l)),
        ]
    })
    .boxed()
}
