//! Distances: exact primitives against independent oracles, fractal
//! estimates, Lipschitz bounds, the smooth minimum, CPU against device
//! conformance (OpenCL, and WGSL through wgpu), formulas written once,
//! numerics at the extremes and deep scenes.
//!
//! One test binary per concern: each file here is a module.

#[path = "../common/mod.rs"]
mod common;
#[path = "../gpu/mod.rs"]
mod gpu;
/// The Vulkan device and compute-shader runner of the crate's own WGSL
/// tests.
#[path = "../../src/codegen/wgsl_tests/device.rs"]
mod wgpu_device;

#[cfg(feature = "proptest")]
mod conformance;
mod deep;
#[cfg(feature = "proptest")]
mod exact;
mod extremes;
#[cfg(feature = "proptest")]
mod formulas;
#[cfg(feature = "proptest")]
mod fractals;
#[cfg(feature = "proptest")]
mod hybrid;
#[cfg(feature = "proptest")]
mod instances;
#[cfg(feature = "proptest")]
mod julia;
#[cfg(feature = "proptest")]
mod kifs;
#[cfg(feature = "proptest")]
mod kleinian;
#[cfg(feature = "proptest")]
mod lipschitz;
#[cfg(feature = "proptest")]
mod mandelbox;
mod numeric;
#[cfg(feature = "proptest")]
mod orbit_trap;
#[cfg(feature = "proptest")]
mod ratio;
mod smooth_oracle;
mod wgsl;
