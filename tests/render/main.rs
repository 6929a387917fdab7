//! Rendering through OpenCL (and wgpu): agreement with the CPU, cancelling, cuts,
//! effects, errors, lit fog, global illumination, materials, optics, quality,
//! sizes, frame-to-frame updates, the golden gallery, march bounds, several
//! devices, the speed knobs and the wgpu backend against the OpenCL one.
//!
//! One test binary per concern: each file here is a module.

#[path = "../gpu/mod.rs"]
mod gpu;
/// The Vulkan device and compute-shader runner of the crate's own WGSL
/// tests.
#[cfg(feature = "wgpu")]
#[path = "../../src/codegen/wgsl_tests/device.rs"]
#[allow(dead_code)] // `run`, the distance tests' shader runner
mod wgpu_device;

mod agreement;
mod cancel;
mod cuts;
mod effects;
mod errors;
mod fog;
mod gi;
mod golden;
mod march_bounds;
mod materials;
mod multi_device;
mod optics;
mod outputs;
mod quality;
mod sizes;
mod speed_knobs;
mod updates;
#[cfg(feature = "wgpu")]
mod wgpu;
