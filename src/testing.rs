//! Property-testing toolkit: strategies that build only valid scenes,
//! invariant checkers, and independent membership tests for the fractals.
//! Enabled by the `proptest` cargo feature.
//!
//! - [Strategies](#strategies) generate points, rays, rotations and nodes
//!   whose parameters always pass validation: [`exact_node`] (distances
//!   are exact), [`bounded_node`] (distances are 1-Lipschitz bounds),
//!   [`fractal_node`] and [`scene_node`] (anything).
//! - Checkers ([`check_lipschitz`], [`check_never_overestimates`],
//!   [`check_exact`]) examine every input, return what they tested
//!   ([`Tested`]) and fail when that is below their minimum, and on failure
//!   return the worst violation as a [`Failure`] that says where, what was
//!   measured and what was allowed. [`near_surface_points`] samples where
//!   an estimate is most at risk, using only a membership test. They accept anything that is a [`DistanceField`]: a
//!   [`Node`](crate::scene::Node), a [`cpu::Evaluator`](crate::cpu::Evaluator) or a
//!   closure `Fn(DVec3) -> f64`. [`check_device_matches_cpu`] (feature
//!   `opencl`) runs a node's generated OpenCL code on a device and compares
//!   it with the CPU reference, and [`check_inside_matches_device`] does
//!   the same for an [`InsideShape`](crate::scene::InsideShape)'s
//!   membership test. [`check_inside_agrees_with_de`] checks that a
//!   distance estimate and a membership test describe the same set.
//! - [`parameter_sites`] and [`substitute`] list and replace every scalar
//!   parameter of any node kind, from the one list of every node's
//!   parameters: for driving hostile values through every parameter.
//! - Membership tests ([`mandelbulb_inside`], [`julia_inside`],
//!   [`menger_inside`], [`sierpinski_inside`]) decide whether a point is in
//!   a fractal without using any distance-estimator code: they are the
//!   independent oracle the estimators are checked against.
//!
//! Testing your own node takes a few lines:
//!
//! ```
//! use fractal_sdf::prelude::*;
//! use fractal_sdf::testing::{self, point_pair};
//! use proptest::prelude::*;
//!
//! fn my_shape(k: f64) -> Node {
//!     sphere(0.8).smooth_union(cuboid(dvec3(0.3, 1.0, 0.3)), k)
//! }
//!
//! proptest!(ProptestConfig::with_cases(16), |(
//!     k in 0.0..0.5,
//!     pairs in prop::collection::vec(point_pair(3.0, 0.5), 32),
//! )| {
//!     testing::check_lipschitz(&my_shape(k), 1.0, &pairs)?;
//! });
//! ```
//!
//! # Strategies
//!
//! Parameters are drawn from bounded ranges that validation accepts; sizes
//! are sometimes exactly zero, and some scalars are dynamic parameters
//! (named after their value, so two draws of one name always agree).

mod check;
#[cfg(feature = "opencl")]
mod device;
mod membership;
mod sample;
mod sites;
mod strategy;

pub use check::{
    Check, DistanceField, Failure, GeneratedProgram, LIPSCHITZ_TOLERANCE, MIN_BALL_FRACTION,
    ROUNDING_ALLOWANCE, SHELL_FACTOR, Tested, check_exact, check_inside_agrees_with_de,
    check_lipschitz, check_never_overestimates,
};
#[cfg(feature = "opencl")]
pub use device::{
    check_device_matches_cpu, check_inside_matches_device, random_points, spicy_points,
};
pub use membership::{
    hybrid_inside, julia_inside, kifs_inside, mandelbox_inside, mandelbulb_inside, menger_inside,
    pseudo_kleinian_inside, sierpinski_inside,
};
pub use sample::near_surface_points;
pub use sites::{Site, parameter_sites, substitute};
pub use strategy::{
    bounded_node, box_frame_node, capped_cone_node, capped_torus_node, capsule_node,
    cone_between_node, cone_node, cuboid_node, cut_hollow_sphere_node, cut_sphere_node,
    cylinder_between_node, cylinder_node, death_star_node, ellipsoid_node, exact_node,
    exact_primitive, extrude_node, fractal_node, hex_prism_node, hybrid_node, hybrid_op,
    infinite_cone_node, infinite_cylinder_node, julia_node, kifs_node, link_node, mandelbox_node,
    mandelbulb_node, menger_node, octahedron_bound_node, octahedron_node, orbit_trap_node, palette,
    plane_node, point, point_pair, profile, pseudo_kleinian_node, pyramid_node, quad_node, ray,
    repeated_node, revolve_node, rhombus_node, rotation, round_box_node, round_cone_between_node,
    round_cone_node, rounded_cylinder_node, scene_node, sierpinski_node, solid_angle_node,
    sphere_node, torus_node, trap, tri_prism_node, triangle_node, unit_vector,
};
