//! The Hausdorff distance between a mesh and the zero set of an exact
//! distance function: the larger of the farthest any point of the mesh
//! lies from the surface, and the farthest any point of the surface lies
//! from the mesh.

use std::collections::HashMap;

use fractal_sdf::mesh::Mesh;
use fractal_sdf::prelude::*;

/// Points per triangle side, and per voxel on the surface side.
const DENSITY: usize = 4;

pub fn distance(mesh: &Mesh, exact: impl Fn(DVec3) -> f64, voxel: f64) -> f64 {
    let tri = |t: &[u32; 3]| t.map(|i| mesh.positions[i as usize].as_dvec3());
    // From the mesh: points spread over every triangle.
    let mut far = 0.0f64;
    for t in &mesh.triangles {
        let [a, b, c] = tri(t);
        for i in 0..=DENSITY {
            for j in 0..=DENSITY - i {
                let (u, v) = (i as f64 / DENSITY as f64, j as f64 / DENSITY as f64);
                far = far.max(exact(a + u * (b - a) + v * (c - a)).abs());
            }
        }
    }
    // From the surface: the mesh's vertices projected onto the surface
    // (by the exact gradient) reach every part of it the mesh comes near;
    // each finds its nearest triangle through a grid of buckets.
    let cell = 2.0 * voxel;
    let key = |p: DVec3| (p / cell).floor().as_ivec3();
    let mut buckets: HashMap<glam::IVec3, Vec<usize>> = HashMap::new();
    for (k, t) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = tri(t);
        let (lo, hi) = (key(a.min(b).min(c)), key(a.max(b).max(c)));
        for x in lo.x..=hi.x {
            for y in lo.y..=hi.y {
                for z in lo.z..=hi.z {
                    buckets.entry(glam::ivec3(x, y, z)).or_default().push(k);
                }
            }
        }
    }
    for p in &mesh.positions {
        let p = p.as_dvec3();
        let h = 1e-6;
        let g = dvec3(
            exact(p + DVec3::X * h) - exact(p - DVec3::X * h),
            exact(p + DVec3::Y * h) - exact(p - DVec3::Y * h),
            exact(p + DVec3::Z * h) - exact(p - DVec3::Z * h),
        )
        .normalize_or_zero();
        let q = p - exact(p) * g;
        let at = key(q);
        let mut best = f64::INFINITY;
        for x in -1..=1 {
            for y in -1..=1 {
                for z in -1..=1 {
                    for &k in buckets
                        .get(&(at + glam::ivec3(x, y, z)))
                        .into_iter()
                        .flatten()
                    {
                        let [a, b, c] = tri(&mesh.triangles[k]);
                        best = best.min((q - closest_on_triangle(q, a, b, c)).length());
                    }
                }
            }
        }
        far = far.max(best.min(cell));
    }
    far
}

/// The point of triangle `abc` nearest `p` (Ericson, Real-Time Collision
/// Detection, 5.1.5).
fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}
