//! The last step of the mesher: the dual mesh made a closed 2-manifold
//! whose vertices all lie at distinct positions.
//!
//! A dual mesh has two flaws a cell-by-cell reading cannot avoid. Where
//! one piece of surface on each side of a cell face touches it along two
//! separate segments, the two pieces' vertices are joined by an edge of
//! four triangles: a tube pinched flat. And a vertex's triangles may form
//! two fans that meet only at it. Both are found vertex by vertex: two of
//! a vertex's triangles are joined where they share an edge that exactly
//! two triangles share, traversed in opposite directions, and every group
//! of triangles so joined beyond the first gets a copy of the vertex.
//! Splitting one end of a pinched edge makes its four triangles two pairs
//! at the other end, which then splits too, and the tube opens into four
//! vertices. Each copy moves a little towards the centre of its own fan,
//! so the copies, and the sheets they belong to, are apart.
//!
//! Then vertices that still share a position (two pieces of one cell
//! whose fitted points were clamped to the same place, or points that
//! round to the same `f32`) are moved apart the same way: files without
//! indices (STL) and tools that weld equal positions would otherwise
//! join them into non-manifold edges again.

use std::collections::HashMap;

use glam::Vec3;

/// How far each copy of a split vertex moves towards the centre of its
/// own fan, as a fraction of the way.
const SEPARATION: f32 = 0.1;

/// How far a vertex whose fan has shrunk to a point moves along its
/// normal, in voxels.
const NUDGE: f64 = 1e-3;

/// Rounds of moving vertices that share a position.
const ROUNDS: usize = 4;

/// What [`repair`] changed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Repair {
    /// Vertices whose triangles formed more than one fan.
    pub split: usize,
    /// Vertices moved off a position another vertex holds.
    pub separated: usize,
}

/// Splits vertices whose triangles form more than one fan and moves
/// vertices off positions another vertex holds (see the module's docs).
/// New vertices are appended, with their original's normal.
/// `voxel` is the grid's cell size.
pub(crate) fn repair(
    positions: &mut Vec<Vec3>,
    normals: &mut Vec<Vec3>,
    triangles: &mut [[u32; 3]],
    voxel: f64,
) -> Repair {
    let split = split_fans(positions, normals, triangles);
    #[allow(clippy::cast_possible_truncation)] // A small positive length.
    let nudge = (NUDGE * voxel) as f32;
    let separated = separate(positions, normals, triangles, nudge);
    Repair { split, separated }
}

/// Each vertex's triangles, as `(start, list)`: vertex `v`'s triangles
/// are `list[start[v]..start[v + 1]]`.
fn incidence(vertices: usize, triangles: &[[u32; 3]]) -> (Vec<usize>, Vec<u32>) {
    let mut start = vec![0usize; vertices + 1];
    for t in triangles {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for v in 0..vertices {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut list = vec![0u32; start[vertices]];
    for (f, t) in triangles.iter().enumerate() {
        for &v in t {
            list[fill[v as usize]] = u32::try_from(f).unwrap_or(u32::MAX);
            fill[v as usize] += 1;
        }
    }
    (start, list)
}

fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Gives every fan of a vertex beyond the first a vertex of its own.
/// Returns how many vertices were split.
fn split_fans(
    positions: &mut Vec<Vec3>,
    normals: &mut Vec<Vec3>,
    triangles: &mut [[u32; 3]],
) -> usize {
    let original = positions.len();
    let (start, list) = incidence(original, triangles);
    let mut split = 0;
    // Moves to make once every fan is known: (vertex, its fan's centre).
    let mut moves: Vec<(u32, Vec3)> = Vec::new();
    let mut parent = Vec::new();
    let mut ends: Vec<(u32, bool, usize)> = Vec::new();
    for v in 0..original {
        let fan = &list[start[v]..start[v + 1]];
        if fan.len() < 2 {
            continue;
        }
        let v32 = u32::try_from(v).unwrap_or(u32::MAX);
        // Each triangle's two edges at `v`: (other end, leaves `v`).
        ends.clear();
        for (i, &f) in fan.iter().enumerate() {
            let t = triangles[f as usize];
            let k = t.iter().position(|&x| x == v32).unwrap_or(0);
            ends.push((t[(k + 1) % 3], true, i));
            ends.push((t[(k + 2) % 3], false, i));
        }
        ends.sort_unstable();
        parent.clear();
        parent.extend(0..fan.len());
        for group in ends.chunk_by(|a, b| a.0 == b.0) {
            // A manifold edge: one triangle arriving, one leaving.
            if let [(_, false, a), (_, true, b)] = group {
                let (ra, rb) = (root(&mut parent, *a), root(&mut parent, *b));
                parent[ra] = rb;
            }
        }
        let mut fans: Vec<usize> = Vec::new();
        for i in 0..fan.len() {
            let r = root(&mut parent, i);
            if !fans.contains(&r) {
                fans.push(r);
            }
        }
        if fans.len() < 2 {
            continue;
        }
        split += 1;
        let p = positions[v];
        for (n, &r) in fans.iter().enumerate() {
            let index = if n == 0 {
                v32
            } else {
                let Ok(index) = u32::try_from(positions.len()) else {
                    return split;
                };
                positions.push(p);
                normals.push(normals[v]);
                index
            };
            let mut sum = Vec3::ZERO;
            let mut count = 0.0f32;
            for i in 0..fan.len() {
                if root(&mut parent, i) != r {
                    continue;
                }
                let t = &mut triangles[fan[i] as usize];
                for x in t.iter_mut() {
                    if *x == v32 {
                        *x = index;
                    } else {
                        sum += positions[*x as usize];
                        count += 1.0;
                    }
                }
            }
            if count > 0.0 {
                moves.push((index, sum / count));
            }
        }
    }
    for (v, centre) in moves {
        let p = &mut positions[v as usize];
        *p = p.lerp(centre, SEPARATION);
    }
    split
}

/// A position's bits, with `-0.0` read as `0.0`.
fn key(p: Vec3) -> [u32; 3] {
    p.to_array().map(|c| (c + 0.0).to_bits())
}

/// Moves every vertex that shares its position with an earlier one
/// towards the centre of its neighbours, or by `nudge` along its normal
/// where that centre is the position itself (a fan shrunk to a point).
/// Returns how many moved.
fn separate(positions: &mut [Vec3], normals: &[Vec3], triangles: &[[u32; 3]], nudge: f32) -> usize {
    let mut moved = 0;
    for _ in 0..ROUNDS {
        let mut seen: HashMap<[u32; 3], u32> = HashMap::with_capacity(positions.len());
        let mut again: Vec<bool> = vec![false; positions.len()];
        let mut any = false;
        for (v, p) in positions.iter().enumerate() {
            let v = u32::try_from(v).unwrap_or(u32::MAX);
            if *seen.entry(key(*p)).or_insert(v) != v {
                again[v as usize] = true;
                any = true;
            }
        }
        if !any {
            break;
        }
        let mut sum = vec![Vec3::ZERO; positions.len()];
        let mut count = vec![0.0f32; positions.len()];
        for t in triangles {
            for k in 0..3 {
                let v = t[k] as usize;
                if again[v] {
                    for j in [(k + 1) % 3, (k + 2) % 3] {
                        sum[v] += positions[t[j] as usize];
                        count[v] += 1.0;
                    }
                }
            }
        }
        for v in (0..positions.len()).filter(|&v| again[v]) {
            let p = positions[v];
            let centre = if count[v] > 0.0 { sum[v] / count[v] } else { p };
            let mut q = p.lerp(centre, SEPARATION);
            if key(q) == key(p) {
                q = p + nudge * normals[v];
            }
            positions[v] = q;
            moved += 1;
        }
    }
    moved
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two tetrahedra that share the edge 0–1 (four triangles on it).
    fn pinched() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 0.5),
            Vec3::new(1.0, 1.0, 0.5),
            Vec3::new(-1.0, 0.0, 0.5),
            Vec3::new(-1.0, -1.0, 0.5),
        ];
        let tetrahedron = |[a, b, c, d]: [u32; 4]| [[a, b, c], [a, c, d], [a, d, b], [b, d, c]];
        let mut triangles = tetrahedron([0, 1, 2, 3]).to_vec();
        triangles.extend(tetrahedron([0, 1, 4, 5]));
        (positions, triangles)
    }

    fn edge_uses(triangles: &[[u32; 3]]) -> HashMap<(u32, u32), usize> {
        let mut uses = HashMap::new();
        for t in triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        uses
    }

    #[test]
    fn a_pinched_edge_opens() {
        let (mut positions, mut triangles) = pinched();
        assert!(edge_uses(&triangles).values().any(|&n| n == 4));
        let mut normals = vec![Vec3::Z; positions.len()];
        let repair = repair(&mut positions, &mut normals, &mut triangles, 1.0);
        assert_eq!(repair.split, 2);
        assert_eq!(positions.len(), 8);
        assert_eq!(normals.len(), 8);
        assert!(edge_uses(&triangles).values().all(|&n| n == 2));
        let keys: std::collections::HashSet<_> = positions.iter().map(|p| key(*p)).collect();
        assert_eq!(keys.len(), positions.len());
    }

    #[test]
    fn shared_positions_move_apart() {
        let (mut positions, triangles) = pinched();
        positions[3] = positions[2];
        let normals = vec![Vec3::Z; positions.len()];
        let moved = separate(&mut positions, &normals, &triangles, 1e-3);
        assert_eq!(moved, 1);
        assert_ne!(key(positions[2]), key(positions[3]));
        // A fan shrunk to a point moves along its normal.
        let mut point = vec![Vec3::ONE; 3];
        // (Two moves in the first round land together; one more parts them.)
        let moved = separate(&mut point, &[Vec3::Z; 3], &[[0, 1, 2]], 1e-3);
        assert_eq!(moved, 3);
        let keys: std::collections::HashSet<_> = point.iter().map(|p| key(*p)).collect();
        assert_eq!(keys.len(), 3);
    }
}
