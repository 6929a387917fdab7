//! Scenes as values and as files: validation, the laws of the builders,
//! bounds and extents, the testing toolkit's checkers, dynamic parameters,
//! pruning, inside shapes, scene files, animation paths, the module
//! architecture, and hostile input from code and from files.
//!
//! One test binary per concern: each file here is a module.

#[path = "../common/mod.rs"]
mod common;
#[path = "../gpu/mod.rs"]
mod gpu;

mod animation;
mod architecture;
#[cfg(feature = "proptest")]
mod checkers;
#[cfg(feature = "proptest")]
mod dynamic;
#[cfg(feature = "proptest")]
mod extents;
#[cfg(feature = "proptest")]
mod fuzz;
#[cfg(feature = "proptest")]
mod hostile;
mod hostile_files;
#[cfg(feature = "proptest")]
mod inside;
#[cfg(feature = "proptest")]
mod laws;
#[cfg(feature = "proptest")]
mod pruning;
mod public_api;
#[cfg(feature = "proptest")]
mod scene_files;
#[cfg(feature = "proptest")]
mod validation;
