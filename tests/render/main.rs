//! Rendering through OpenCL: agreement with the CPU, cancelling, cuts,
//! effects, errors, lit fog, global illumination, materials, optics, quality,
//! sizes, frame-to-frame updates, the golden gallery, march bounds, several
//! devices and the speed knobs.
//!
//! One test binary per concern: each file here is a module.

#[path = "../gpu/mod.rs"]
mod gpu;
/// The Vulkan device and compute-shader runner of the crate's own WGSL
/// tests.
#[path = "../../src/codegen/wgsl_tests/device.rs"]
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
mod wgsl;
