//! The box and the regular grid a scene is sampled on, and the octree
//! that finds the parts of the grid that can hold surface.

use glam::DVec3;

use super::sample::{Sampler, Sampling};
use crate::error::{Error, Result, fmt_value};
use crate::ir::{Bound, CompiledScene, union_chain};
use crate::quality::Precision;

/// Cells along a block's edge: the unit the octree drops or keeps.
pub const CHUNK: u32 = 16;

/// The most cells along a grid's longest side.
pub const MAX_RESOLUTION: u32 = 4096;

/// Cells along the longest side of the coarse grid that tightens a
/// scene's bound to where its surface is.
const TIGHTEN_RESOLUTION: u32 = 64;

/// Voxels of room around the surface in a box found from the scene.
const MARGIN_VOXELS: f64 = 2.0;

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Aabb {
    /// The corner with the smallest coordinates.
    pub min: DVec3,
    /// The corner with the largest coordinates.
    pub max: DVec3,
}

impl Aabb {
    /// The box between two corners.
    #[must_use]
    pub fn new(min: DVec3, max: DVec3) -> Self {
        Aabb { min, max }
    }

    /// The cube of half side `half` around `centre`.
    #[must_use]
    pub fn cube(centre: DVec3, half: f64) -> Self {
        Aabb::new(centre - DVec3::splat(half), centre + DVec3::splat(half))
    }

    /// The box's extent along each axis.
    #[must_use]
    pub fn size(&self) -> DVec3 {
        self.max - self.min
    }

    /// The box's centre.
    #[must_use]
    pub fn centre(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    fn validate(&self) -> Result<()> {
        let finite =
            self.min.is_finite() && self.max.is_finite() && (self.max - self.min).is_finite();
        if !finite || !self.min.cmplt(self.max).all() {
            return Err(Error::Invalid {
                what: "grid bounds",
                reason: format!(
                    "the box from {} to {} must be finite with min < max on every axis",
                    self.min, self.max
                ),
            });
        }
        let side = (self.max - self.min).min_element();
        let reach = self.min.abs().max(self.max.abs()).max_element();
        if side < MIN_BOX_SIDE || side < MIN_RELATIVE_SIDE * reach {
            return Err(Error::Invalid {
                what: "grid bounds",
                reason: format!(
                    "the box from {} to {} is {} wide on its narrowest axis: at least {} and \
                     {} of its largest coordinate are needed to tell its samples apart",
                    self.min,
                    self.max,
                    fmt_value(side),
                    fmt_value(MIN_BOX_SIDE),
                    fmt_value(MIN_RELATIVE_SIDE)
                ),
            });
        }
        Ok(())
    }
}

/// The narrowest a sampled box may be on any axis.
const MIN_BOX_SIDE: f64 = 1e-12;

/// The narrowest a sampled box may be on any axis, as a share of its
/// largest coordinate: single precision (device sampling) keeps about
/// seven digits, so a narrower box would sample the same points again.
const MIN_RELATIVE_SIDE: f64 = 1e-5;

/// Where and how finely a scene is sampled for a mesh or a volume.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct GridOptions {
    /// The box to sample; `None`: the scene's bound, tightened to its
    /// surface, plus two voxels on every side.
    pub bounds: Option<Aabb>,
    /// Cells along the box's longest side, in `1..=MAX_RESOLUTION`
    /// (default 128): a resolution of 512 samples like a 512³ grid.
    pub resolution: u32,
    /// Where distances are computed.
    pub sampler: Sampler,
    /// The precision of the device's program (the CPU computes in the
    /// same precision).
    pub precision: Precision,
    /// Meshes only: place each vertex where the tangent planes at its
    /// cell's edge crossings meet (dual contouring's fit, on exact
    /// gradients: four more evaluations per crossing and per vertex), so
    /// box edges, corners and CSG creases stay sharp, and take normals
    /// from the gradient at the vertex; `false`: Surface Nets' mean of the
    /// crossings and the grid's gradient. Default `true`. Scenes with an
    /// inside-only shape ([`InsideShape`](crate::scene::InsideShape)) have
    /// no gradient and always take the mean.
    pub sharp: bool,
    /// Dynamic parameters to set before sampling, by name (the rest keep
    /// their defaults).
    pub params: Vec<(String, f64)>,
}

impl Default for GridOptions {
    fn default() -> Self {
        GridOptions {
            bounds: None,
            resolution: 128,
            sampler: Sampler::default(),
            precision: Precision::F32,
            sharp: true,
            params: Vec::new(),
        }
    }
}

impl GridOptions {
    /// Samples `bounds` instead of the scene's bound.
    #[must_use]
    pub fn bounds(mut self, bounds: Aabb) -> Self {
        self.bounds = Some(bounds);
        self
    }

    /// Cells along the box's longest side.
    #[must_use]
    pub fn resolution(mut self, resolution: u32) -> Self {
        self.resolution = resolution;
        self
    }

    /// Where distances are computed.
    #[must_use]
    pub fn sampler(mut self, sampler: Sampler) -> Self {
        self.sampler = sampler;
        self
    }

    /// The precision distances are computed in.
    #[must_use]
    pub fn precision(mut self, precision: Precision) -> Self {
        self.precision = precision;
        self
    }

    /// Sets a dynamic parameter before sampling.
    #[must_use]
    pub fn param(mut self, name: impl Into<String>, value: f64) -> Self {
        self.params.push((name.into(), value));
        self
    }

    /// Whether mesh vertices are fitted to the tangent planes (see
    /// [`GridOptions::sharp`](#structfield.sharp)).
    #[must_use]
    pub fn sharp(mut self, sharp: bool) -> Self {
        self.sharp = sharp;
        self
    }

    fn validate(&self) -> Result<()> {
        if !(1..=MAX_RESOLUTION).contains(&self.resolution) {
            return Err(Error::Invalid {
                what: "grid resolution",
                reason: format!(
                    "{} cells along the longest side; it must be in 1..={MAX_RESOLUTION}",
                    self.resolution
                ),
            });
        }
        if let Some(b) = &self.bounds {
            b.validate()?;
        }
        Ok(())
    }
}

/// What a long extraction is doing, for progress bars.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Stage {
    /// Finding the box from the scene's bound (coarse culling).
    Bounds,
    /// Walking the octree down to the blocks that can hold surface.
    Culling,
    /// Sampling blocks and meshing them; `done`/`total` count blocks.
    Sampling,
    /// Fitting vertices to the tangent planes; `total` counts vertices.
    Sharpening,
    /// Colouring vertices; `done`/`total` count vertices.
    Shading,
}

/// One progress report: `done` of `total` units of `stage`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct Progress {
    /// What is being done.
    pub stage: Stage,
    /// Units finished.
    pub done: u64,
    /// Units in all.
    pub total: u64,
}

/// A regular grid: sample `(i, j, k)`, for `0 ≤ i ≤ cells[0]` and so on,
/// lies at `origin + spacing · (i, j, k)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Grid {
    pub origin: DVec3,
    pub spacing: f64,
    pub cells: [u32; 3],
}

impl Grid {
    /// The grid of `resolution` cells along `bounds`' longest side,
    /// centred on it.
    fn over(bounds: Aabb, resolution: u32) -> Self {
        let size = bounds.size();
        let spacing = size.max_element() / f64::from(resolution);
        let cells = size.to_array().map(|s| {
            // At most `resolution`: the cast cannot truncate.
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let n = ((s / spacing) - 1e-9).ceil().max(1.0) as u32;
            n
        });
        let span = DVec3::from_array(cells.map(f64::from)) * spacing;
        Grid {
            origin: bounds.centre() - 0.5 * span,
            spacing,
            cells,
        }
    }

    /// The position of grid sample `(i, j, k)` (any integers).
    pub fn point(&self, at: [i64; 3]) -> DVec3 {
        #[allow(clippy::cast_precision_loss)] // Grid indices are small.
        let index = DVec3::new(at[0] as f64, at[1] as f64, at[2] as f64);
        self.origin + self.spacing * index
    }
}

/// The grid a scene is sampled on for `options`, with the sampler built.
pub(crate) fn plan(
    scene: &CompiledScene,
    options: &GridOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<(Grid, Sampling)> {
    options.validate()?;
    let mut sampling = Sampling::new(scene, &options.sampler, options.precision)?;
    for (name, value) in &options.params {
        sampling.set_param(name, *value)?;
    }
    let bounds = match options.bounds {
        Some(b) => b,
        None => {
            let found = scene_box(scene)?;
            // An inside-only shape's value is no distance: nothing can
            // be proved empty, so its bound stays whole.
            let tight = if scene.ir().has_inside_shapes() {
                found
            } else {
                tighten(&sampling, found, progress)?
            };
            let margin = MARGIN_VOXELS * tight.size().max_element() / f64::from(options.resolution);
            Aabb::new(
                tight.min - DVec3::splat(margin),
                tight.max + DVec3::splat(margin),
            )
        }
    };
    Ok((Grid::over(bounds, options.resolution), sampling))
}

/// The box around the scene's bounding sphere.
fn scene_box(scene: &CompiledScene) -> Result<Aabb> {
    let ir = scene.ir();
    let bounds = ir.bounds();
    let around = |b: Bound| Aabb::cube(b.centre, b.radius.max(f64::MIN_POSITIVE));
    if let Some(b) = bounds[ir.root().index()] {
        return Ok(around(b));
    }
    // A union with a floor: name the box of the parts that have a bound.
    let parts = union_chain(ir, ir.root(), &bounds).map(|chain| {
        chain
            .operands
            .iter()
            .filter_map(|id| bounds[id.index()])
            .map(around)
            .reduce(|a, b| Aabb::new(a.min.min(b.min), a.max.max(b.max)))
    });
    let hint = match parts.flatten() {
        Some(b) => format!(
            "; its bounded parts lie within {:.3},{:.3},{:.3},{:.3},{:.3},{:.3} \
             (MINX,MINY,MINZ,MAXX,MAXY,MAXZ)",
            b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z
        ),
        None => String::new(),
    };
    Err(Error::Invalid {
        what: "grid bounds",
        reason: format!(
            "the scene has no bound (it holds a plane, an unlimited repetition, a custom \
             shape or a dynamic size): give the box to sample{hint}"
        ),
    })
}

/// `found` shrunk to the cells of a coarse grid that can hold surface.
fn tighten(sampling: &Sampling, found: Aabb, progress: &mut dyn FnMut(Progress)) -> Result<Aabb> {
    let grid = Grid::over(found, TIGHTEN_RESOLUTION);
    let (cells, _) = occupied(sampling, &grid, 1, 0, grid.cells, Stage::Bounds, progress)?;
    if cells.is_empty() {
        return Err(Error::Invalid {
            what: "grid bounds",
            reason: format!(
                "no surface within the scene's bound, from {} to {}: give the box to sample",
                found.min, found.max
            ),
        });
    }
    let mut lo = [u32::MAX; 3];
    let mut hi = [0u32; 3];
    for c in &cells {
        for a in 0..3 {
            lo[a] = lo[a].min(c[a]);
            hi[a] = hi[a].max(c[a] + 1);
        }
    }
    let corner = |at: [u32; 3]| grid.point(at.map(i64::from));
    Ok(Aabb::new(corner(lo), corner(hi)))
}

/// The leaves of an octree over `count` leaves of `leaf` cells each (a
/// leaf at `l` covers the grid's samples `l·leaf ..= l·leaf + leaf + pad`)
/// that can hold surface: every node whose centre is farther from the
/// scene than the node's half-diagonal (and a voxel of slack for
/// rounding) is dropped with everything below it. Also returns the
/// distance evaluations it took.
pub(crate) fn occupied(
    sampling: &Sampling,
    grid: &Grid,
    leaf: u32,
    pad: u32,
    count: [u32; 3],
    stage: Stage,
    progress: &mut dyn FnMut(Progress),
) -> Result<(Vec<[u32; 3]>, u64)> {
    let mut evaluations = 0u64;
    let mut frontier = vec![([0u32; 3], count)];
    let mut leaves = Vec::new();
    let total = u64::from(count[0]) * u64::from(count[1]) * u64::from(count[2]);
    let mut settled = 0u64;
    while !frontier.is_empty() {
        let centres: Vec<DVec3> = frontier
            .iter()
            .map(|(lo, hi)| {
                let a = grid.point(lo.map(|l| i64::from(l * leaf)));
                let b = grid.point([0, 1, 2].map(|i| i64::from(hi[i] * leaf + pad)));
                0.5 * (a + b)
            })
            .collect();
        evaluations += centres.len() as u64;
        let distances = sampling.distances(&centres)?;
        let mut next = Vec::new();
        for ((lo, hi), d) in frontier.into_iter().zip(distances) {
            let a = grid.point(lo.map(|l| i64::from(l * leaf)));
            let b = grid.point([0, 1, 2].map(|i| i64::from(hi[i] * leaf + pad)));
            let reach = 0.5 * (b - a).length() + grid.spacing;
            let volume = (0..3).map(|i| u64::from(hi[i] - lo[i])).product::<u64>();
            // NaN is kept: only a number can prove a node empty.
            if d > reach {
                settled += volume;
                continue;
            }
            if volume == 1 {
                leaves.push(lo);
                settled += 1;
                continue;
            }
            split(lo, hi, &mut next);
        }
        progress(Progress {
            stage,
            done: settled,
            total,
        });
        frontier = next;
    }
    leaves.sort_unstable_by_key(|l| (l[2], l[1], l[0]));
    Ok((leaves, evaluations))
}

/// Every leaf of a grid of `count` leaves, in the order [`occupied`]
/// gives them: for scenes whose values are no distances, where nothing
/// can be dropped.
pub(crate) fn every_leaf(count: [u32; 3]) -> Vec<[u32; 3]> {
    let mut out = Vec::new();
    for z in 0..count[2] {
        for y in 0..count[1] {
            for x in 0..count[0] {
                out.push([x, y, z]);
            }
        }
    }
    out
}

/// The children of the node `lo..hi`: each axis longer than one leaf
/// halved.
fn split(lo: [u32; 3], hi: [u32; 3], out: &mut Vec<([u32; 3], [u32; 3])>) {
    let halves = |a: usize| {
        let mid = lo[a] + (hi[a] - lo[a]) / 2;
        if hi[a] - lo[a] > 1 {
            vec![(lo[a], mid), (mid, hi[a])]
        } else {
            vec![(lo[a], hi[a])]
        }
    };
    for &(z0, z1) in &halves(2) {
        for &(y0, y1) in &halves(1) {
            for &(x0, x1) in &halves(0) {
                out.push(([x0, y0, z0], [x1, y1, z1]));
            }
        }
    }
}
