//! The mesher: a vertex for every piece of surface in a grid cell (see
//! [`cases`](super::cases)), and a quad around every grid edge the surface
//! crosses, joining the pieces of the four cells around the edge that
//! hold it. Blocks of the grid are meshed one at a time and welded by
//! cell, so the mesh is watertight across blocks.

use std::collections::HashMap;

use glam::{DVec3, Vec3};

use super::cases::{EDGES, NONE, case, corner, edge};
use super::grid::{CHUNK, Grid};
use super::sharpen::Crossings;
use super::triangles::Mesh;

/// Samples along a sampled block's edge: the block's `CHUNK + 1` corners
/// and one more, so that the cells on its far faces are whole (they are
/// shared with the next block, which finds the same vertices in them).
pub(crate) const SIDE: u32 = CHUNK + 2;

/// Cells along a block's edge whose vertices it finds.
const CELLS: usize = CHUNK as usize + 1;

fn sample_index(at: [u32; 3]) -> usize {
    let s = SIDE as usize;
    at[0] as usize + s * (at[1] as usize + s * at[2] as usize)
}

fn cell_index(at: [u32; 3]) -> usize {
    at[0] as usize + CELLS * (at[1] as usize + CELLS * at[2] as usize)
}

/// Builds the mesh block by block.
pub(crate) struct Mesher {
    grid: Grid,
    /// Vertex of each (cell, piece) found so far.
    vertices: HashMap<u64, u32>,
    mesh: Mesh,
    crossings: Crossings,
    /// This block's cells' cases and their pieces' vertices.
    masks: Vec<u8>,
    slots: Vec<u32>,
    /// Set when the mesh outgrows 32-bit indices.
    overflow: bool,
}

impl Mesher {
    pub fn new(grid: Grid) -> Self {
        Mesher {
            grid,
            vertices: HashMap::new(),
            mesh: Mesh {
                voxel_size: grid.spacing,
                ..Mesh::default()
            },
            crossings: Crossings::default(),
            masks: vec![0; CELLS.pow(3)],
            slots: vec![u32::MAX; 4 * CELLS.pow(3)],
            overflow: false,
        }
    }

    /// Whether the mesh has outgrown 32-bit vertex indices (what STL, PLY
    /// and OBJ readers take): vertices or edge crossings past 2³² − 1.
    pub fn overflowed(&self) -> bool {
        self.overflow || self.crossings.overflowed()
    }

    /// Meshes the block whose first sample is grid sample `start`, from
    /// its `SIDE³` distances (`x` fastest).
    pub fn add(&mut self, start: [u32; 3], sdf: &[f32]) {
        let inside = |at: [u32; 3]| sdf[sample_index(at)] < 0.0;
        // Cells: their cases, and a vertex per piece.
        let all = 0..u32::try_from(CELLS).expect("small");
        for z in all.clone() {
            for y in all.clone() {
                for x in all.clone() {
                    let cell = [x, y, z];
                    let mut mask = 0u8;
                    for i in 0..8 {
                        let c = corner(i);
                        if inside([x + c[0], y + c[1], z + c[2]]) {
                            mask |= 1 << i;
                        }
                    }
                    self.masks[cell_index(cell)] = mask;
                    if mask != 0 && mask != 255 {
                        self.cell(start, cell, mask, sdf);
                    }
                }
            }
        }
        // Quads around the crossing edges this block owns: those starting
        // on its near faces (not its far ones, which the next block owns)
        // whose four cells it holds.
        for axis in 0..3 {
            let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
            for z in 0..=CHUNK {
                for y in 0..=CHUNK {
                    for x in 0..=CHUNK {
                        let s = [x, y, z];
                        if s[axis] >= CHUNK || s[b] == 0 || s[c] == 0 {
                            continue;
                        }
                        let mut e = s;
                        e[axis] += 1;
                        let (from, to) = (inside(s), inside(e));
                        if from == to {
                            continue;
                        }
                        self.quad(s, axis, from);
                    }
                }
            }
        }
    }

    /// The vertices of the pieces of `cell` (block coordinates).
    fn cell(&mut self, start: [u32; 3], cell: [u32; 3], mask: u8, sdf: &[f32]) {
        let case = case(mask);
        let d: [f32; 8] = std::array::from_fn(|i| {
            let c = corner(i);
            sdf[sample_index([cell[0] + c[0], cell[1] + c[1], cell[2] + c[2]])]
        });
        let global = [0, 1, 2].map(|a| start[a] + cell[a]);
        let stride = u64::from(self.grid.cells[0]) + 2;
        let layer = stride * (u64::from(self.grid.cells[1]) + 2);
        let key =
            u64::from(global[0]) + stride * u64::from(global[1]) + layer * u64::from(global[2]);
        for piece in 0..case.pieces {
            let Ok(next) = u32::try_from(self.mesh.positions.len()) else {
                self.overflow = true;
                return;
            };
            let index = *self
                .vertices
                .entry(4 * key + u64::from(piece))
                .or_insert(next);
            self.slots[4 * cell_index(cell) + usize::from(piece)] = index;
            if index != next {
                continue;
            }
            let corner_at = |i: usize| Vec3::from_array(corner(i).map(|c| c as f32));
            let points: Vec<Vec3> = EDGES
                .iter()
                .zip(case.piece)
                .filter(|(_, p)| *p == piece)
                .map(|(&(a, b), _)| {
                    let t = d[a] / (d[a] - d[b]);
                    corner_at(a).lerp(corner_at(b), t)
                })
                .collect();
            #[allow(clippy::cast_precision_loss)] // At most 12.
            let mean = points.iter().copied().sum::<Vec3>() / points.len() as f32;
            let base = Vec3::from_array(global.map(|g| {
                #[allow(clippy::cast_precision_loss)] // Grid indices are small.
                let g = g as f32;
                g
            }));
            let world = self.grid.origin + self.grid.spacing * (base + mean).as_dvec3();
            self.mesh.positions.push(world.as_vec3());
            self.mesh
                .normals
                .push(trilinear_gradient(&d, mean).normalize_or_zero());
            let at: Vec<Vec3> = points.iter().map(|p| base + *p).collect();
            self.crossings.push(global, &at);
        }
    }

    /// The quad around the edge from block sample `s` along `axis`, facing
    /// the edge's outside end.
    fn quad(&mut self, s: [u32; 3], axis: usize, starts_inside: bool) {
        let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
        // The four cells around the edge, counter-clockwise seen from the
        // edge's far end: offsets (−,−), (+,−), (+,+), (−,+) along (b, c).
        let around = [(1, 1), (0, 1), (0, 0), (1, 0)].map(|(db, dc)| {
            let mut cell = s;
            cell[b] -= db;
            cell[c] -= dc;
            let mut from = [0u32; 3];
            from[b] = db;
            from[c] = dc;
            let mut to = from;
            to[axis] = 1;
            let index = |o: [u32; 3]| (o[0] + 2 * o[1] + 4 * o[2]) as usize;
            let piece = case(self.masks[cell_index(cell)]).piece[edge(index(from), index(to))];
            debug_assert_ne!(
                piece, NONE,
                "a crossing edge belongs to a piece of each cell"
            );
            self.slots[4 * cell_index(cell) + usize::from(piece)]
        });
        let [v0, v1, v2, v3] = if starts_inside {
            around
        } else {
            [around[3], around[2], around[1], around[0]]
        };
        // Split along the shorter diagonal.
        let p = |v: u32| self.mesh.positions[v as usize];
        if p(v0).distance_squared(p(v2)) <= p(v1).distance_squared(p(v3)) {
            self.mesh.triangles.push([v0, v1, v2]);
            self.mesh.triangles.push([v0, v2, v3]);
        } else {
            self.mesh.triangles.push([v0, v1, v3]);
            self.mesh.triangles.push([v1, v2, v3]);
        }
    }

    pub fn finish(self) -> (Mesh, Crossings) {
        (self.mesh, self.crossings)
    }
}

/// The gradient of the trilinear interpolation of a cell's corner values
/// `d` at `u` in the cell.
fn trilinear_gradient(d: &[f32; 8], u: Vec3) -> Vec3 {
    let mut g = DVec3::ZERO;
    for (a, b) in EDGES {
        let along = (a ^ b).trailing_zeros() as usize;
        let ca = corner(a);
        let weight: f64 = (0..3)
            .filter(|&j| j != along)
            .map(|j| {
                let t = f64::from(u[j]);
                if ca[j] == 1 { t } else { 1.0 - t }
            })
            .product();
        g[along] += f64::from(d[b] - d[a]) * weight;
    }
    g.as_vec3()
}
