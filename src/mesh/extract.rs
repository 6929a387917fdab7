//! Triangle meshes of the blocks the octree keeps, welded into one
//! watertight mesh, with vertices fitted to the surface and coloured.

use glam::{DVec3, Vec3};

use super::dual::{Mesher, SIDE};
use super::grid::{CHUNK, Grid, Progress, Stage, every_leaf, occupied, plan};
use super::manifold::repair;
use super::sharpen::sharpen;
use super::triangles::{Mesh, MeshStats};
use super::{GridOptions, Sampling};
use crate::error::{Error, Result};
use crate::ir::CompiledScene;

/// Blocks sampled per call to the sampler.
const BATCH: usize = 256;

/// Vertices coloured per call to the sampler.
const SHADE_BATCH: usize = 1 << 18;

/// Display gamma of vertex colours (the renderer's default).
const GAMMA: f64 = 2.2;

/// The mesh of `scene`'s surface over the grid `options` describe.
///
/// # Errors
/// [`Error::Invalid`](crate::Error::Invalid) for a resolution outside
/// `1..=MAX_RESOLUTION`, a box that is not finite with `min < max`, or a
/// scene without a bound and no box; the sampler's errors (no OpenCL
/// platform, a build failure, ...).
pub fn extract(scene: &CompiledScene, options: &GridOptions) -> Result<Mesh> {
    extract_with_progress(scene, options, &mut |_| {})
}

/// [`extract`], reporting progress as it goes.
///
/// # Errors
/// As [`extract`].
pub fn extract_with_progress(
    scene: &CompiledScene,
    options: &GridOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Mesh> {
    let (grid, sampling) = plan(scene, options, progress)?;
    let count = grid.cells.map(|c| c.div_ceil(CHUNK));
    // Inside-only shapes give a sign, not a distance: no block can be
    // dropped, and there are no tangent planes to fit.
    let signs_only = scene.ir().has_inside_shapes();
    let (blocks, octree) = if signs_only {
        (every_leaf(count), 0)
    } else {
        occupied(&sampling, &grid, CHUNK, 1, count, Stage::Culling, progress)?
    };
    let mut mesher = Mesher::new(grid);
    let total = blocks.len() as u64;
    let per = (SIDE as usize).pow(3);
    for (n, batch) in blocks.chunks(BATCH).enumerate() {
        let starts: Vec<[i32; 3]> = batch
            .iter()
            .map(|b| b.map(|i| i32::try_from(i * CHUNK).expect("grids are small")))
            .collect();
        let mut values = sampling.blocks(grid.origin, grid.spacing, SIDE, &starts)?;
        for (block, sdf) in batch.iter().zip(values.chunks_exact_mut(per)) {
            let start = block.map(|i| i * CHUNK);
            close_at_the_border(&grid, start, sdf);
            mesher.add(start, sdf);
        }
        if mesher.overflowed() {
            return Err(Error::Invalid {
                what: "mesh size",
                reason: format!(
                    "more than 2³² − 1 vertices or edge crossings at {} cells across: lower \
                     the resolution or sample a smaller box",
                    options.resolution
                ),
            });
        }
        progress(Progress {
            stage: Stage::Sampling,
            done: ((n + 1) * BATCH).min(blocks.len()) as u64,
            total,
        });
    }
    let (mut mesh, crossings) = mesher.finish();
    let mut sharpening = 0;
    if options.sharp && !signs_only {
        progress(Progress {
            stage: Stage::Sharpening,
            done: 0,
            total: mesh.positions.len() as u64,
        });
        sharpening = sharpen(
            &sampling,
            &grid,
            &crossings,
            &mut mesh.positions,
            &mut mesh.normals,
        )?;
    }
    repair(
        &mut mesh.positions,
        &mut mesh.normals,
        &mut mesh.triangles,
        grid.spacing,
    );
    mesh.colors = shade(&sampling, &mesh.positions, progress)?;
    mesh.stats = MeshStats {
        cells: grid.cells,
        blocks: count.iter().map(|&c| u64::from(c)).product(),
        blocks_sampled: total,
        evaluations: octree + sharpening + total * per as u64 + mesh.positions.len() as u64,
    };
    Ok(mesh)
}

/// Makes the grid's outer layer (and anything past it) outside, so that
/// the mesh is closed where the box cuts the scene.
///
/// A sample that is not a number (no estimate gives one, but a custom
/// shape might) counts as outside too, so no vertex is placed from it.
fn close_at_the_border(grid: &Grid, start: [u32; 3], sdf: &mut [f32]) {
    #[allow(clippy::cast_possible_truncation)] // A positive f32 is enough.
    let outside = grid.spacing as f32;
    for d in sdf.iter_mut().filter(|d| d.is_nan()) {
        *d = outside;
    }
    let inside = |a: usize, at: u32| at > 0 && at < grid.cells[a];
    if (0..3).all(|a| inside(a, start[a]) && inside(a, start[a] + SIDE - 1)) {
        return;
    }
    let side = SIDE as usize;
    for (i, d) in sdf.iter_mut().enumerate() {
        let at = [i % side, (i / side) % side, i / (side * side)]
            .map(|c| u32::try_from(c).expect("a block is small"));
        if !(0..3).all(|a| inside(a, start[a] + at[a])) {
            *d = outside;
        }
    }
}

/// Gamma-encoded 8-bit colours of the scene at `points`.
fn shade(
    sampling: &Sampling,
    points: &[Vec3],
    progress: &mut dyn FnMut(Progress),
) -> Result<Vec<[u8; 3]>> {
    let mut out = Vec::with_capacity(points.len());
    for batch in points.chunks(SHADE_BATCH) {
        let at: Vec<DVec3> = batch.iter().map(|p| p.as_dvec3()).collect();
        for c in sampling.colors(&at)? {
            out.push(c.to_array().map(|v| {
                #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // In 0..=255.
                let byte = (v.clamp(0.0, 1.0).powf(1.0 / GAMMA) * 255.0).round() as u8;
                byte
            }));
        }
        progress(Progress {
            stage: Stage::Shading,
            done: out.len() as u64,
            total: points.len() as u64,
        });
    }
    Ok(out)
}
