//! # fractal-sdf
//!
//! Write 3D scenes — primitives, transforms, smooth CSG and the fractals
//! Mandelbulb, Menger sponge, quaternion Julia and Sierpinski tetrahedron —
//! as typed Rust values; evaluate them exactly on the CPU, or compile them to
//! OpenCL C and ray-march them on any OpenCL device.
//!
//! ## Guide
//!
//! The [`guide`] explains the crate chapter by chapter: getting started,
//! scenes in Rust and in files, fractals, quality and its measured cost,
//! optics, materials, animation, meshes, the command line, clusters,
//! custom shapes, performance, reliability, testing and packaging. Its
//! examples are doctests.
//!
//! ## The pipeline
//!
//! Each stage is a module and a function of the previous stage's output:
//!
//! 1. [`scene`]: the typed scene ([`Node`](scene::Node), [`Scene`](scene::Scene)) and its builder API.
//! 2. [`ir`]: [`Scene::compile`](scene::Scene::compile) validates and lowers a scene, once, into a
//!    [`CompiledScene`](ir::CompiledScene): a flat arena whose parameters are baked constants or
//!    dynamic slots, with every parameter rule, the camera and the lights.
//!    Every later stage takes the compiled scene.
//! 3. [`cpu`]: the reference evaluator (distance, colour, normal, sphere
//!    tracing) in `f64` and `f32`; the oracle for every test.
//! 4. `render` (feature `opencl`, on by default): the OpenCL executor —
//!    device choice, program build and cache, tiled ray marching into an
//!    image with depth, hit, normal and step outputs.
//! 5. [`output`]: saving images (atomic PNG writes).
//! 6. [`mesh`]: geometry instead of pixels: watertight meshes (STL, PLY,
//!    OBJ) and volumes of signed distances (NRRD, PNG slices), sampled on
//!    the device or the CPU.
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
//! ## Features
//!
//! | feature | default | adds |
//! |---|---|---|
//! | `opencl` | on | `render`, the OpenCL executor, and rendering in [`sequence`]; needs an OpenCL loader to link and a platform to run |
//! | `proptest` | off | `testing`, the property-testing toolkit |
//! | `viewer` | off | the window of the repository's `viewer` example; nothing in the library |
//!
//! ## A tour
//!
//! ### Scenes
//!
//! Build a scene from a fractal and a smoothly blended pair of primitives,
//! then ask the CPU reference for distances:
//!
//! ```
//! use fractal_sdf::prelude::*;
//! use fractal_sdf::cpu;
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
//!
//! ### Rendering
//!
//! With the `opencl` feature (on by default), `render::Renderer` compiles a
//! scene to OpenCL C, builds it for the first GPU (else the first OpenCL
//! device; `FRACTAL_SDF_DEVICE` or a `DeviceSelector` chooses another) and
//! ray-marches images in tiles. [`Quality`](quality::Quality) presets trade
//! speed for accuracy; [`Effects`](quality::Effects) switch ambient
//! occlusion, shadows and glow. The program is built once and cached.
//!
//! ```no_run
//! # #[cfg(feature = "opencl")] {
//! use fractal_sdf::prelude::*;
//! use fractal_sdf::render::Renderer;
//!
//! let scene = Scene::new(mandelbulb(8.0).union(plane(dvec3(0.0, 1.0, 0.0), 1.2)))
//!     .with_camera(Camera::look_at(dvec3(2.0, 1.4, 2.8), dvec3(0.0, -0.1, 0.0)));
//! let mut renderer = Renderer::new(&scene, Quality::preview())?;
//! let image = renderer.render(640, 480)?; // an image::RgbaImage
//! fractal_sdf::output::save_png(&image, "out/bulb.png")?; // atomic write
//! # }
//! # Ok::<(), fractal_sdf::Error>(())
//! ```
//!
//! Without an OpenCL platform, `Renderer::new` returns
//! [`Error::NoPlatform`], whose message says what to install.
//!
//! ### Dynamic parameters
//!
//! Every number in a scene is either baked into the generated program (a
//! plain `1.0`) or a named dynamic parameter (`param("radius", 1.0)`, see
//! [`scene::param`]): a slot in a buffer, changed between frames without
//! building a new program, and held to the same rules as a baked value. The CPU
//! reference and the renderer (`Renderer::set_param`) take the same names;
//! [`animation::Motion`] moves them with time.
//!
//! ```
//! use fractal_sdf::prelude::*;
//! use fractal_sdf::cpu;
//!
//! let scene = Scene::new(sphere(param("radius", 1.0))).compile()?;
//! let mut eval = cpu::Evaluator::from_compiled(&scene);
//! assert!((eval.distance(dvec3(2.0, 0.0, 0.0)) - 1.0).abs() < 1e-12);
//! eval.set_param("radius", 1.5)?;
//! assert!((eval.distance(dvec3(2.0, 0.0, 0.0)) - 0.5).abs() < 1e-12);
//! // A dynamic value gets the error a baked one would.
//! assert!(eval.set_param("radius", -1.0).is_err());
//! # Ok::<(), fractal_sdf::Error>(())
//! ```
//!
//! ### Testing your own shapes
//!
//! With the `proptest` feature (usually in `[dev-dependencies]`, next to
//! `proptest` itself), `testing` offers strategies that build only valid
//! points, rays, nodes and scenes, and checkers for the invariants every
//! distance estimate must keep: `check_lipschitz`,
//! `check_never_overestimates`, `check_exact`, and (with `opencl`)
//! `check_device_matches_cpu` for a shape's OpenCL twin. A checker returns
//! the worst violation it found, which fails a proptest case:
//!
//! ```
//! # #[cfg(feature = "proptest")] {
//! use fractal_sdf::prelude::*;
//! use fractal_sdf::testing::{check_lipschitz, point_pair};
//! use proptest::prelude::*;
//!
//! proptest!(ProptestConfig::with_cases(8), |(
//!     k in 0.0..0.5,
//!     pairs in prop::collection::vec(point_pair(3.0, 0.5), 32),
//! )| {
//!     let shape = sphere(0.8).smooth_union(cuboid(dvec3(0.3, 1.0, 0.3)), k);
//!     check_lipschitz(&shape, 1.0, &pairs)?;
//! });
//! # }
//! ```
#![warn(missing_docs)]
// On docs.rs (nightly rustdoc with `--cfg docsrs`), mark the items each
// feature adds; an ordinary build never sets `docsrs`.
#![cfg_attr(docsrs, feature(doc_cfg))]

#[macro_use]
mod macros;

pub mod animation;
pub mod codegen;
pub mod cpu;
mod error;
pub mod expr;
pub mod file;
pub mod gallery;
pub mod guide;
pub mod ir;
pub mod math;
pub mod mesh;
pub mod metrics;
pub mod output;
pub mod quality;
#[cfg(feature = "opencl")]
pub mod render;
pub mod scene;
pub mod sequence;
pub mod settings;
#[cfg(feature = "proptest")]
pub mod testing;
pub mod view;

pub use error::{Error, Result};

/// The [`image`](https://docs.rs/image) crate, whose `RgbaImage` every
/// render returns, with its PNG codec.
pub use image;

/// The [`glam`](https://docs.rs/glam) crate, whose `f64` vectors and
/// quaternions every scene is written in.
pub use glam;

/// What a first scene needs, in 25 names: `use fractal_sdf::prelude::*;`.
///
/// The scene and its parts, the quality, the common shapes and fractals,
/// dynamic parameters, the crate's error, and glam's `DVec3`, `dvec3` and
/// `DQuat`. Everything else is named through its module
/// (`fractal_sdf::scene::ellipsoid`, `fractal_sdf::cpu::Evaluator`,
/// `fractal_sdf::glam::EulerRot`).
pub mod prelude {
    pub use crate::error::{Error, Result};
    pub use crate::quality::{Effects, Quality};
    pub use crate::scene::{
        Camera, Light, Material, Node, Scene, capsule, cuboid, cylinder, julia, mandelbox,
        mandelbulb, menger, param, plane, round_box, sierpinski, sphere, torus,
    };
    pub use glam::{DQuat, DVec3, dvec3};
}
