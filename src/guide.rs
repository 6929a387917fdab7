//! The guide: how to use the crate, chapter by chapter, with the measured
//! figures behind its defaults.
//!
//! Each chapter is a module with no items, only documentation; its Rust
//! examples are compiled and run as doctests. The chapters' sources are
//! `docs/guide/*.md` in the repository.
//!
//! 1. [Getting started](getting_started): adding the crate, its features,
//!    what a system needs, a first picture, the gallery and the examples.
//! 2. [Scenes in Rust](scenes): the nodes and their distances, dynamic
//!    parameters, errors, and from a scene to a picture.
//! 3. [Scene files](scene_files): scenes as RON text.
//! 4. [Fractals](fractals): where they lie, and fractals without a
//!    distance estimate, drawn by brute force.
//! 5. [Quality](quality): the presets and knobs, and the measured trade of
//!    speed against accuracy.
//! 6. [Optics](optics): the lens, progressive and adaptive passes, stereo
//!    and cuts.
//! 7. [Outputs](outputs): image formats, OpenEXR layers, exposure and
//!    tone curves, and the camera for a 3D package.
//! 8. [Materials](materials): shading models, reflections and glass.
//! 9. [Light](light): path-traced global illumination, environment,
//!    area and emissive lights, the stopping rule of progressive passes,
//!    and fog lit by the lights.
//! 10. [Animation](animation): motions, camera paths and frame sequences.
//! 11. [Meshes and volumes](meshes): watertight meshes and signed-distance
//!     grids.
//! 12. [The command line](command_line): the `fractal-sdf` command and the
//!     settings file.
//! 13. [The viewer](viewer): the interactive window.
//! 14. [Clusters](clusters): sequences as Slurm job arrays and Kubernetes
//!     Indexed Jobs.
//! 15. [Custom shapes](custom_shapes): shapes of your own, and testing
//!     them.
//! 16. [Performance](performance): the benchmark, render speed, and what
//!     makes rendering faster at the same image.
//! 17. [Backends](backends): OpenCL and wgpu, choosing one, rendering into
//!     an application's texture, and the two compared.
//! 18. [Reliability](reliability): hostile input, the values each
//!     precision holds, and numerical limits.
//! 19. [How it is tested](how_it_is_tested): oracles, tolerances and
//!     mutation testing.
//! 20. [Packaging](packaging): the package, its check, docs.rs, the
//!     minimum Rust and versions.
//! 21. [Architecture](architecture): where the design is described.

// Chapters link to `render` (feature `opencl`, and `wgpu` for its wgpu
// backend) and `testing` (feature `proptest`); without those features the
// links have no target.
#![cfg_attr(
    not(all(feature = "opencl", feature = "proptest", feature = "wgpu")),
    allow(rustdoc::broken_intra_doc_links)
)]

#[doc = include_str!("../docs/guide/getting_started.md")]
pub mod getting_started {}

#[doc = include_str!("../docs/guide/scenes.md")]
pub mod scenes {}

#[doc = include_str!("../docs/guide/scene_files.md")]
pub mod scene_files {}

#[doc = include_str!("../docs/guide/fractals.md")]
pub mod fractals {}

#[doc = include_str!("../docs/guide/quality.md")]
pub mod quality {}

#[doc = include_str!("../docs/guide/optics.md")]
pub mod optics {}

#[doc = include_str!("../docs/guide/outputs.md")]
pub mod outputs {}

#[doc = include_str!("../docs/guide/materials.md")]
pub mod materials {}

#[doc = include_str!("../docs/guide/light.md")]
pub mod light {}

#[doc = include_str!("../docs/guide/animation.md")]
pub mod animation {}

#[doc = include_str!("../docs/guide/meshes.md")]
pub mod meshes {}

#[doc = include_str!("../docs/guide/command_line.md")]
pub mod command_line {}

#[doc = include_str!("../docs/guide/viewer.md")]
pub mod viewer {}

#[doc = include_str!("../docs/guide/clusters.md")]
pub mod clusters {}

#[doc = include_str!("../docs/guide/custom_shapes.md")]
pub mod custom_shapes {}

#[doc = include_str!("../docs/guide/performance.md")]
pub mod performance {}

#[doc = include_str!("../docs/guide/backends.md")]
pub mod backends {}

#[doc = include_str!("../docs/guide/reliability.md")]
pub mod reliability {}

#[doc = include_str!("../docs/guide/how_it_is_tested.md")]
pub mod how_it_is_tested {}

#[doc = include_str!("../docs/guide/packaging.md")]
pub mod packaging {}

#[doc = include_str!("../docs/guide/architecture.md")]
pub mod architecture {}
