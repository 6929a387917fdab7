//! Generated kernels: code generation, the reviewed snapshots of generated
//! source, and custom shapes in programs.
//!
//! One test binary per concern: each file here is a module.

#[path = "../gpu/mod.rs"]
mod gpu;

mod codegen;
#[cfg(feature = "proptest")]
mod custom_node;
mod snapshots;
