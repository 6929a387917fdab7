//! The OpenCL executor: chooses a device, builds (and caches) the scene's
//! program, and ray-marches it in tiles into an image and per-pixel
//! outputs. The only module that talks to OpenCL (feature `opencl`).
//!
//! ```no_run
//! use fractal_sdf::prelude::*;
//! use fractal_sdf::render::{Renderer, devices};
//!
//! for d in devices()? {
//!     println!("{}", d.label());
//! }
//! let scene = Scene::new(sphere(1.0));
//! let mut renderer = Renderer::new(&scene, Quality::preview())?;
//! let frame = renderer.render_with_aovs(64, 48)?;
//! println!("{:.0}% covered, built in {:?}", 100.0 * frame.coverage(), renderer.build_info().build_time);
//! # Ok::<(), fractal_sdf::Error>(())
//! ```
//!
//! # The program contract
//!
//! A program is one OpenCL C 1.2 source
//! ([`KernelSource`](crate::codegen::KernelSource)): a header, the scene's
//! distance functions, then the render kernel: `kernels/march.cl` (the
//! marcher), `shade.cl`, `optics.cl`, `paths.cl` and `render.cl` (kernel
//! `render_tile`). The header defines:
//!
//! - `real`, `real2`, `real3`, `real4` (`float*` or `double*`, the latter
//!   with `#pragma OPENCL EXTENSION cl_khr_fp64 : enable`), and `R(x)`, which
//!   turns a literal into a `real` one;
//! - `REAL_TINY`, `MAX_STEPS`, `MAX_DISTANCE`, `DETAIL`, `HIT_EPSILON` and
//!   `NORMAL_EPSILON` (multiples of the pixel footprint), `OVER_RELAXATION`,
//!   `SUPERSAMPLING` (N for N×N samples), `GAMMA`, `EXPOSURE_SCALE`,
//!   `SKY_TOP`, `SKY_BOTTOM` (`real3`), from [`Quality`](crate::quality::Quality) and
//!   [`Effects`](crate::quality::Effects);
//! - only for the effects that are on: `ENABLE_AO` with `AO_SAMPLES` and
//!   `AO_DISTANCE`; `ENABLE_SHADOWS` with `SHADOW_STEPS`; `ENABLE_GLOW` with
//!   `GLOW_COLOR` and `GLOW_STRENGTH`; `ENABLE_FOG` with `FOG_DENSITY`;
//! - the kernel interface from
//!   `src/codegen/interface.rs` (internal): the argument lists
//!   `RENDER_TILE_ARGS` and `EVAL_POINTS_ARGS`, the camera buffer's field
//!   offsets `CAMERA_*` and the light buffer's `LIGHT_*` and
//!   `LIGHT_STRIDE`.
//!
//! and the scene provides
//!
//! ```c
//! real DE(real3 p, __global const real* params);
//! real DE_shade(real3 p, __global const real* params, real3* color, real* trap);
//! ```
//!
//! `params` holds the dynamic parameters in slot order (at least one
//! element); `DE_shade` also returns the linear RGB albedo and an orbit trap
//! in `[0, 1]` (1 for non-fractal surfaces). Camera, lights and the light
//! count are kernel arguments, so none of them is in the source.

mod adaptive;
mod aov;
mod buffer;
mod cache;
mod cancel;
mod device;
mod dispatch;
mod environment;
mod frames;
mod memory;
mod points;
mod program;
mod renderer;
mod sampling;
mod stereo;
mod upscale;
mod viewport;
#[cfg(feature = "wgpu")]
mod wgpu_backend;
#[cfg(feature = "wgpu")]
mod wgpu_points;

/// The wgpu crate the wgpu backend is built on: name its types (devices,
/// textures) through this path to get the same version.
#[cfg(feature = "wgpu")]
pub use ::wgpu;
pub use adaptive::{AdaptiveFrame, EdgeThresholds, edges};
pub use aov::{Frame, Layers};
pub use cancel::CancelToken;
pub use device::{DEVICE_ENV, DeviceInfo, DeviceKind, DeviceSelector, devices};
pub use dispatch::{DEFAULT_TILE_SIZE, MAX_IMAGE_SIDE};
pub use frames::RenderFrames;
pub use points::{PointEvaluator, PointSample};
pub use program::{BuildInfo, PROGRAM_CACHE_CAPACITY, program_builds};
pub use renderer::{ConvergedFrame, EvaluationCost, RenderOptions, Renderer, StopRule};
pub use sampling::{SamplePoint, brute_phase, sample_point};
pub use stereo::{compose, render_stereo};
pub use viewport::Viewport;
#[cfg(feature = "wgpu")]
pub use wgpu_backend::{WGPU_TEXTURE_FORMAT, WgpuFrame, WgpuRenderer, wgpu_adapters};
#[cfg(feature = "wgpu")]
pub use wgpu_points::WgpuPointEvaluator;
