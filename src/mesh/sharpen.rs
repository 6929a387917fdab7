//! Dual contouring's vertex placement on Surface Nets' topology: each
//! vertex moves to the point that best fits the tangent planes where the
//! surface crosses its cell's edges (a quadratic error function over the
//! exact gradients there), so box edges and corners, and the creases of
//! CSG, stay sharp instead of being rounded off by averaging.

use glam::{DMat3, DVec3, Vec3};

use super::Sampling;
use super::grid::Grid;
use crate::error::Result;

/// Pull towards the crossings' mean, in voxel units: it settles the
/// directions the planes leave free (along a flat face, along an edge)
/// and keeps nearly parallel planes from throwing a vertex far away.
const REGULARISATION: f64 = 0.05;

/// How far inside its cell a fitted vertex stays, in voxels: two cells'
/// vertices clamped towards their shared face or corner stay apart.
const INSET: f64 = 1e-3;

/// The step of the differences that give the tangent planes at edge
/// crossings, in voxels: small, so that a plane near a crease is the
/// plane of its own side.
const PLANE_STEP: f64 = 1e-2;

/// The step of the differences that give vertex normals, in voxels: the
/// mesh's own scale, so that detail far below a voxel (which the mesh
/// cannot show) does not make its shading noisy.
const NORMAL_STEP: f64 = 1.0;

/// Steps of regula falsi that move each crossing onto the surface.
const REFINE_ROUNDS: usize = 2;

/// Points whose distances are asked for at once.
const BATCH: usize = 1 << 20;

/// The corners of a tetrahedron around a point: the differences along them
/// give the gradient with four evaluations.
const TETRAHEDRON: [DVec3; 4] = [
    DVec3::new(1.0, -1.0, -1.0),
    DVec3::new(-1.0, -1.0, 1.0),
    DVec3::new(-1.0, 1.0, -1.0),
    DVec3::new(1.0, 1.0, 1.0),
];

/// Where the surface crosses each cell's edges, per vertex: crossings in
/// grid (voxel) coordinates, and each vertex's cell.
#[derive(Default)]
pub(crate) struct Crossings {
    pub points: Vec<Vec3>,
    /// Vertex `v`'s crossings are `points[starts[v]..starts[v + 1]]`.
    pub starts: Vec<u32>,
    pub cells: Vec<[u32; 3]>,
}

impl Crossings {
    /// Records the crossings (grid coordinates) of the next vertex, which
    /// lies in `cell`.
    pub fn push(&mut self, cell: [u32; 3], points: &[Vec3]) {
        if self.starts.is_empty() {
            self.starts.push(0);
        }
        self.points.extend_from_slice(points);
        self.starts
            .push(u32::try_from(self.points.len()).unwrap_or(u32::MAX));
        self.cells.push(cell);
    }

    /// Whether there are more crossings than 32-bit offsets reach.
    pub fn overflowed(&self) -> bool {
        u32::try_from(self.points.len()).is_err()
    }
}

/// Moves every vertex to its cell's best fit of the crossings' tangent
/// planes (kept [`INSET`] inside the cell), and gives it the distance field's gradient there as its
/// normal, except in the grid's outer layer of cells, where a box may cut
/// the scene. Returns the distance evaluations it took.
pub(crate) fn sharpen(
    sampling: &Sampling,
    grid: &Grid,
    crossings: &Crossings,
    positions: &mut [Vec3],
    normals: &mut [Vec3],
) -> Result<u64> {
    let world = |v: DVec3| grid.origin + grid.spacing * v;
    let refined = refine(sampling, grid, &crossings.points)?;
    let at: Vec<DVec3> = refined.iter().map(|p| world(*p)).collect();
    let planes = gradients(sampling, PLANE_STEP * grid.spacing, &at)?;
    // Cells on the grid's outer layer meet the cap where the box cuts the
    // scene: their crossings' planes are the box's, not the scene's, so
    // they keep Surface Nets' mean and the closed field's normal.
    let on_border = |cell: [u32; 3]| (0..3).any(|a| cell[a] == 0 || cell[a] + 1 >= grid.cells[a]);
    for (v, position) in positions.iter_mut().enumerate() {
        if on_border(crossings.cells[v]) {
            continue;
        }
        let range = crossings.starts[v] as usize..crossings.starts[v + 1] as usize;
        let points = &refined[range.clone()];
        let planes = &planes[range];
        #[allow(clippy::cast_precision_loss)] // At most 12.
        let mean = points.iter().sum::<DVec3>() / points.len() as f64;
        let mut a = DMat3::from_diagonal(DVec3::splat(REGULARISATION));
        let mut b = DVec3::ZERO;
        for (p, n) in points.iter().zip(planes) {
            a += outer(*n);
            b += *n * n.dot(*p - mean);
        }
        let fit = mean + a.inverse() * b;
        let cell = DVec3::from_array(crossings.cells[v].map(f64::from));
        let placed = fit.clamp(cell + DVec3::splat(INSET), cell + DVec3::splat(1.0 - INSET));
        if placed.is_finite() {
            *position = world(placed).as_vec3();
        }
    }
    let at: Vec<DVec3> = positions.iter().map(|p| p.as_dvec3()).collect();
    let fitted = normals
        .iter_mut()
        .zip(gradients(sampling, NORMAL_STEP * grid.spacing, &at)?)
        .zip(&crossings.cells);
    for ((n, g), cell) in fitted {
        if g != DVec3::ZERO && !on_border(*cell) {
            *n = g.as_vec3();
        }
    }
    let refining = (2 + REFINE_ROUNDS) * crossings.points.len();
    Ok((TETRAHEDRON.len() * (at.len() + crossings.points.len()) + refining) as u64)
}

/// The crossings (grid coordinates) moved to where the distance is zero
/// on their edges: [`REFINE_ROUNDS`] steps of regula falsi from the
/// edge's ends. Linear interpolation of the samples puts a crossing near
/// an edge or corner of the shape off the surface (the distance at a
/// sample is to the nearest face, not to the crossed one), and the
/// tangent plane through it with it, which rounds convex edges inwards
/// and fills concave ones.
fn refine(sampling: &Sampling, grid: &Grid, points: &[Vec3]) -> Result<Vec<DVec3>> {
    let world = |v: DVec3| grid.origin + grid.spacing * v;
    let mut out = Vec::with_capacity(points.len());
    for batch in points.chunks(BATCH / 2) {
        // Each crossing's edge: the axis along which it is not on a
        // sample, and the edge's first end. One on a sample is exact.
        let edges: Vec<Option<(usize, DVec3)>> = batch
            .iter()
            .map(|p| {
                let p = p.as_dvec3();
                let axis = (0..3).find(|&a| p[a].fract() != 0.0)?;
                let mut start = p;
                start[axis] = p[axis].floor();
                Some((axis, start))
            })
            .collect();
        let along = |(axis, start): (usize, DVec3), t: f64| {
            let mut q = start;
            q[axis] += t;
            q
        };
        let ends: Vec<DVec3> = edges
            .iter()
            .flatten()
            .flat_map(|&e| [along(e, 0.0), along(e, 1.0)])
            .map(world)
            .collect();
        let d = sampling.distances(&ends)?;
        // Per edge with a sign change: the bracket (t, value) at each end.
        let mut brackets: Vec<Option<[(f64, f64); 2]>> = d
            .chunks_exact(2)
            .map(|d| ((d[0] < 0.0) != (d[1] < 0.0)).then_some([(0.0, d[0]), (1.0, d[1])]))
            .collect();
        let secant = |[(t0, d0), (t1, d1)]: [(f64, f64); 2]| {
            let t = t0 + (t1 - t0) * d0 / (d0 - d1);
            if t.is_finite() {
                t.clamp(t0, t1)
            } else {
                0.5 * (t0 + t1)
            }
        };
        let live: Vec<(usize, DVec3)> = edges.iter().flatten().copied().collect();
        for _ in 0..REFINE_ROUNDS {
            let at: Vec<DVec3> = live
                .iter()
                .zip(&brackets)
                .map(|(&e, b)| world(along(e, b.map_or(0.5, secant))))
                .collect();
            let d = sampling.distances(&at)?;
            for (b, d) in brackets.iter_mut().zip(d) {
                if let Some(b) = b {
                    let t = secant(*b);
                    // The new point replaces the end of its own sign.
                    b[usize::from((b[0].1 < 0.0) != (d < 0.0))] = (t, d);
                }
            }
        }
        let mut refined = live.iter().zip(&brackets);
        for (p, e) in batch.iter().zip(&edges) {
            out.push(match e {
                Some(_) => match refined.next() {
                    Some((&e, Some(b))) => along(e, secant(*b)),
                    _ => p.as_dvec3(),
                },
                None => p.as_dvec3(),
            });
        }
    }
    Ok(out)
}

fn outer(n: DVec3) -> DMat3 {
    DMat3::from_cols(n * n.x, n * n.y, n * n.z)
}

/// The unit gradient of the distance at every point, by differences over
/// `step` (zero where it vanishes).
fn gradients(sampling: &Sampling, step: f64, points: &[DVec3]) -> Result<Vec<DVec3>> {
    let mut out = Vec::with_capacity(points.len());
    for batch in points.chunks(BATCH / TETRAHEDRON.len()) {
        let around: Vec<DVec3> = batch
            .iter()
            .flat_map(|p| TETRAHEDRON.map(|k| *p + step * k))
            .collect();
        let d = sampling.distances(&around)?;
        for q in d.chunks_exact(TETRAHEDRON.len()) {
            let g: DVec3 = TETRAHEDRON.iter().zip(q).map(|(k, d)| *k * *d).sum();
            out.push(g.normalize_or_zero());
        }
    }
    Ok(out)
}
