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
//! surface the box cuts. Each vertex is then moved to where the tangent
//! planes at its cell's edge crossings meet (dual contouring's fit, on
//! the exact gradient, kept a thousandth of a voxel inside its cell),
//! which keeps box edges, corners and CSG creases sharp
//! ([`GridOptions::sharp`]), and gets the gradient there as its normal
//! and the scene's colour from `DE_shade`.
//!
//! A dual mesh still pinches where one piece on each side of a cell face
//! touches it along two separate segments (an edge of four triangles),
//! and a vertex's triangles can form two fans that meet only at it. A
//! last pass splits every vertex whose triangles form more than one fan
//! (joined across edges of exactly two triangles), which opens the
//! pinches, and moves each copy a tenth of the way towards its own fan's
//! centre; then it moves apart any vertices that still share a position.
//!
//! # What a mesh is
//!
//! - **Closed and oriented**: every edge is shared by two triangles that
//!   traverse it in opposite directions, counter-clockwise seen from
//!   outside, so [`Mesh::volume`] is the enclosed volume.
//! - **A 2-manifold**: no edge has more than two triangles and no vertex
//!   more than one fan; [`Mesh::topology`] counts any exception and
//!   `fractal-sdf mesh` prints the counts instead of "closed 2-manifold".
//!   None was found in any mesh measured: every gallery scene at 48
//!   cells (those with a floor cut by a box), the Mandelbulb at 128, the
//!   quaternion Julia set at 128 and 256, and Menger sponges rotated off
//!   the grid's axes at 128 cells (`tests/mesh.rs`, where the dual mesh
//!   alone had 6,300 edges of four triangles and 14 shared positions).
//! - **Every vertex at its own position** ([`Mesh::duplicate_positions`]
//!   is zero), so an STL file, which has no indices, and tools that weld
//!   equal positions (slicers, `trimesh`) see the same surface.
//! - **Accurate in volume**: the enclosed volume of smooth shapes
//!   converges at second order in the voxel size (the sphere +0.006% at
//!   128 cells); shapes with edges keep them, because each crossing is
//!   moved onto the surface before the fit (the Menger
//!   sponge of level 4 −0.25% at 128 cells, where linear crossings lost
//!   4.93%); only features smaller than about a voxel are lost. The table,
//!   and the command that measures it, is `docs/mesh-volumes.md`.
//! - **Not checked**: that no two triangles intersect (dual contouring's
//!   fitted vertices can fold a sheet where a feature is thinner than a
//!   voxel).
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
mod manifold;
use sample::Sampling;
mod sample;
mod sharpen;
mod triangles;
mod volume;
mod write;

pub use extract::{extract, extract_with_progress};
pub use grid::{Aabb, CHUNK, GridOptions, MAX_RESOLUTION, Progress, Stage};
pub use sample::Sampler;
pub use triangles::{Mesh, MeshStats, Topology};
pub use volume::{
    BAND_VOXELS, MAX_VOLUME_SAMPLES, Volume, sample_volume, sample_volume_with_progress,
};
pub use write::MeshFormat;
