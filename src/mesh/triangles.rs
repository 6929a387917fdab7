//! The triangle mesh a scene is extracted to, its statistics and its
//! topology.

use std::collections::HashMap;

use glam::Vec3;

/// A triangle mesh in the scene's coordinates.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals, pointing out of the shape (the distance
    /// field's gradient).
    pub normals: Vec<Vec3>,
    /// Vertex colours (8-bit, gamma-encoded as the renderer's images):
    /// the scene's colour at each vertex, from `DE_shade`.
    pub colors: Vec<[u8; 3]>,
    /// Triangles as vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// The grid's cell size.
    pub voxel_size: f64,
    /// What the extraction cost.
    pub stats: MeshStats,
}

/// What an extraction cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct MeshStats {
    /// Cells along each axis of the grid.
    pub cells: [u32; 3],
    /// Blocks of [`CHUNK`](super::CHUNK)³ cells in the grid.
    pub blocks: u64,
    /// Blocks the octree kept and sampled.
    pub blocks_sampled: u64,
    /// Distance evaluations in all (octree centres, block samples, vertex
    /// colours).
    pub evaluations: u64,
}

/// How a mesh's edges are shared: a closed 2-manifold surface shares
/// every edge between exactly two triangles that traverse it in opposite
/// directions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct Topology {
    /// Distinct edges.
    pub edges: usize,
    /// Edges of only one triangle: holes.
    pub boundary_edges: usize,
    /// Edges of more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges two triangles traverse in the same direction: flipped
    /// orientation.
    pub misoriented_edges: usize,
}

impl Topology {
    /// Whether every edge joins exactly two consistently oriented
    /// triangles.
    #[must_use]
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary_edges == 0 && self.non_manifold_edges == 0 && self.misoriented_edges == 0
    }
}

impl Mesh {
    /// How the mesh's edges are shared.
    #[must_use]
    pub fn topology(&self) -> Topology {
        // Per undirected edge: (triangles, this direction minus the other).
        let mut edges: HashMap<(u32, u32), (u32, i32)> = HashMap::new();
        for t in &self.triangles {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                let e = edges.entry((a.min(b), a.max(b))).or_default();
                e.0 += 1;
                e.1 += if a < b { 1 } else { -1 };
            }
        }
        let mut out = Topology {
            edges: edges.len(),
            ..Topology::default()
        };
        for (count, balance) in edges.values() {
            match count {
                1 => out.boundary_edges += 1,
                2 if *balance != 0 => out.misoriented_edges += 1,
                2 => {}
                _ => out.non_manifold_edges += 1,
            }
        }
        out
    }

    /// Vertices at a position an earlier vertex holds (`-0.0` and `0.0`
    /// are one position): zero for every mesh [`extract`](super::extract()) makes, so that
    /// files without indices (STL) and tools that weld equal positions
    /// see the same surface as the indices.
    #[must_use]
    pub fn duplicate_positions(&self) -> usize {
        let mut seen = std::collections::HashSet::with_capacity(self.positions.len());
        self.positions
            .iter()
            .filter(|p| !seen.insert(p.to_array().map(|c| (c + 0.0).to_bits())))
            .count()
    }

    /// The enclosed volume (the divergence theorem over the triangles):
    /// positive for a closed mesh oriented outwards.
    #[must_use]
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize].as_dvec3());
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// The total area of the triangles.
    #[must_use]
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize].as_dvec3());
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }
}
