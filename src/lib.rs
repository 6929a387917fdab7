//! # fractal-sdf
//!
//! Write 3D scenes — primitives, transforms, smooth CSG and the fractals
//! Mandelbulb, Menger sponge, quaternion Julia and Sierpinski tetrahedron —
//! as typed Rust values; evaluate them exactly on the CPU, or compile them to
//! OpenCL C and ray-march them on any OpenCL device.
//!
//! ## The pipeline
//!
//! Each stage is a module and a function of the previous stage's output:
//!
//! 1. [`scene`]: the typed scene ([`Node`], [`Scene`]) and its builder API.
//! 2. [`ir`]: [`Scene::compile`] validates and lowers a scene, once, into a
//!    [`CompiledScene`]: a flat arena whose parameters are baked constants or
//!    dynamic slots, with every parameter rule, the camera and the lights.
//!    Every later stage takes the compiled scene.
//! 3. [`cpu`]: the reference evaluator (distance, colour, normal, sphere
//!    tracing) in `f64` and `f32`; the oracle for every test.
//! 4. `render` (feature `opencl`, on by default): the OpenCL executor —
//!    device choice, program build and cache, tiled ray marching into an
//!    image with depth, hit, normal and step outputs.
//! 5. [`output`]: saving images (atomic PNG writes).
//!
//! Around the pipeline:
//!
//! - [`gallery`]: ready-made scenes, their animated parameters and the
//!   benchmark scene and path.
//! - [`animation`]: camera paths (Catmull-Rom through keyframes, orbits,
//!   TOML) and [`Motion`](animation::Motion)s of dynamic parameters.
//! - [`sequence`]: numbered frame files, frame ranges and resuming; with
//!   `opencl`, rendering a path to them.
//! - [`view`]: interactive viewing, independent of any window toolkit: a
//!   fly-through camera, the [`Key`](view::Key)s and what they do, view
//!   settings, key scripts, the resolution choice while the view moves,
//!   frame timings and statistics, and copying a frame into a window.
//! - [`metrics`]: comparing images (PSNR, SSIM, hit masks, depth buffers),
//!   to measure how far a render is from a reference.
//!
//! Images are [`image::RgbaImage`]s. The [`image`] crate (with PNG
//! support) is re-exported, so cropping, converting or saving them needs no
//! dependency of your own: `use fractal_sdf::image::RgbaImage;`.
//!
//! With the `proptest` feature, the `testing` module offers strategies for valid
//! scenes and checkers for the distance invariants (Lipschitz bound, never
//! overestimating, exactness), to property-test your own nodes.
//!
//! ## A tour
//!
//! Build a scene from a fractal and a smoothly blended pair of primitives,
//! then ask the CPU reference for distances:
//!
//! ```
//! use fractal_sdf::prelude::*;
//!
//! // A Mandelbulb of power 8, moved to the left.
//! let bulb = mandelbulb(8.0).translate(dvec3(-1.5, 0.0, 0.0));
//! // A sphere melting into a box, painted orange, on the right.
//! let blob = sphere(0.6)
//!     .smooth_union(cuboid(dvec3(0.4, 0.4, 0.4)).translate(dvec3(0.5, 0.0, 0.0)), 0.2)
//!     .color(dvec3(1.0, 0.5, 0.1))
//!     .translate(dvec3(1.5, 0.0, 0.0));
//! let scene = Scene::new(bulb.union(blob)).compile()?;
//!
//! let eval = cpu::Evaluator::from_compiled(&scene);
//! // Far from everything, the distance is positive and finite...
//! let far = eval.distance(dvec3(0.0, 5.0, 0.0));
//! assert!(far > 3.0 && far.is_finite());
//! // ...and the centre of the sphere is inside.
//! assert!(eval.distance(dvec3(1.5, 0.0, 0.0)) < 0.0);
//! # Ok::<(), fractal_sdf::Error>(())
//! ```
//!
//! Bad input is a typed error that names the node and the parameter, never a
//! panic:
//!
//! ```
//! use fractal_sdf::prelude::*;
//! let err = Scene::new(sphere(1.0).union(torus(1.0, -0.2))).validate().unwrap_err();
//! assert_eq!(
//!     err.to_string(),
//!     "union/b:torus: parameter `minor_radius` must be >= 0, got -0.2"
//! );
//! ```
#![warn(missing_docs)]
// On docs.rs (nightly rustdoc with `--cfg docsrs`), mark the items each
// feature adds; an ordinary build never sets `docsrs`.
#![cfg_attr(docsrs, feature(doc_cfg))]

pub mod animation;
pub mod codegen;
pub mod cpu;
pub mod error;
pub mod gallery;
pub mod ir;
pub mod math;
pub mod metrics;
pub mod output;
pub mod quality;
#[cfg(feature = "opencl")]
pub mod render;
pub mod scene;
pub mod sequence;
#[cfg(feature = "proptest")]
pub mod testing;
pub mod view;

pub use error::{Error, Result};
pub use ir::CompiledScene;
pub use scene::{Node, Scene};

/// The [`image`](https://docs.rs/image) crate, whose `RgbaImage` every
/// render returns, with its PNG codec.
pub use image;

/// Everything needed to write scenes: `use fractal_sdf::prelude::*;`.
pub mod prelude {
    pub use crate::cpu;
    pub use crate::error::{Error, Result};
    pub use crate::ir::CompiledScene;
    pub use crate::quality::{Effects, Glow, Precision, Preset, Quality};
    pub use crate::scene::{
        Axis, Camera, Light, Mandelbulb, Menger, Node, Param, Param3, Projection, QuaternionJulia,
        Scene, Sierpinski, capped_cone, capsule, cuboid, cylinder, ellipsoid, julia, mandelbulb,
        menger, octahedron, param, param3, plane, round_box, sierpinski, sphere, torus,
    };
    pub use glam::{DQuat, DVec3, EulerRot, Vec3, dvec3, vec3};
    pub use image::RgbaImage;
}
