//! Meshes and volumes out of any scene: watertight triangle meshes for 3D
//! printers and modelling tools (binary STL, PLY with colours, OBJ), and
//! voxel grids of signed distances (NRRD) or slice stacks (one PNG per z)
//! for volume tools.
//!
//! Both start from the same regular grid over a box, sampled in bulk: on
//! an OpenCL device through the generated `DE` (feature `opencl`, the
//! default) or on the CPU through the reference evaluator. A mesh samples
//! only the parts of the grid that can hold surface: an octree over blocks
//! of 16³ cells asks the distance at each node's centre and drops every
//! node farther from the scene than its own half-diagonal (a distance
//! estimate never overestimates, so no surface is lost), which makes the
//! cost grow with the surface's area and the shape's volume, not the
//! box's (only nodes outside the shape are dropped: inside a fractal the
//! estimate is no distance).
//!
//! Each block left is meshed dually, as Surface Nets and dual contouring
//! do: a vertex in every cell the surface crosses and a quad around every
//! grid edge it crosses. A cell gets one vertex per separate piece of
//! surface in it (marching cubes' reading of its corners), so two sheets
//! passing through one cell do not share an edge; the blocks are welded
//! by cell, and the grid's outer layer counts as outside, which closes any
//! surface the box cuts: the mesh is watertight. Each vertex is then moved
//! to where the tangent planes at its cell's edge crossings meet (dual
//! contouring's fit, on the exact gradient), which keeps box edges,
//! corners and CSG creases sharp ([`GridOptions::sharp`]), and gets the
//! gradient there as its normal and the scene's colour from `DE_shade`.
//!
//! ```
//! use fractal_sdf::mesh::{self, GridOptions, Sampler};
//! use fractal_sdf::prelude::*;
//!
//! let scene = Scene::new(sphere(1.0)).compile()?;
//! let options = GridOptions::default().resolution(32).sampler(Sampler::Cpu);
//! let mesh = mesh::extract(&scene, &options)?;
//! assert!(mesh.topology().is_closed_manifold());
//! let volume = mesh.volume();
//! assert!((volume - 4.0 / 3.0 * std::f64::consts::PI).abs() < 0.05 * volume);
//! # Ok::<(), fractal_sdf::Error>(())
//! ```
//!
//! The default box is the scene's bound (see [`Ir::bounds`]), tightened by
//! a coarse pass to where the surface is, plus two voxels; a scene without
//! a bound (a plane, an infinite repetition) needs [`GridOptions::bounds`].
//!
//! [`Ir::bounds`]: crate::ir::Ir::bounds

mod cases;
mod dual;
mod extract;
mod grid;
use sample::Sampling;
mod sample;
mod sharpen;
mod volume;
mod write;

pub use extract::{CHUNK, Mesh, MeshStats, Topology, extract, extract_with_progress};
pub use grid::{Aabb, GridOptions, MAX_RESOLUTION, Progress, Stage};
pub use sample::Sampler;
pub use volume::{MAX_VOLUME_SAMPLES, Volume, sample_volume, sample_volume_with_progress};
pub use write::MeshFormat;
