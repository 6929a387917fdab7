//! Whether a point belongs to a fractal, decided from the fractal's
//! definition (escape time, ternary digits, sub-tetrahedra) and sharing no
//! code with the distance estimators in [`cpu::sdf`](crate::cpu::sdf):
//! these are the oracle the estimators are checked against.

use glam::{DMat3, DQuat, DVec3};

/// Whether `p` is in the Mandelbulb of `power` at `iterations` iterations:
/// the orbit `z0 = p`, `z(k+1) = z(k)^power + p` (the triplex power in
/// spherical coordinates: the radius raised to `power`, the polar angle
/// from +z and the azimuth around z multiplied by `power`) stays within
/// `bailout` for `k = 0..=iterations`.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::testing::mandelbulb_inside;
/// assert!(mandelbulb_inside(DVec3::ZERO, 8.0, 12, 2.0));
/// assert!(!mandelbulb_inside(dvec3(1.5, 0.0, 0.0), 8.0, 12, 2.0));
/// ```
#[must_use]
pub fn mandelbulb_inside(p: DVec3, power: f64, iterations: u32, bailout: f64) -> bool {
    crate::scene::mandelbulb_contains(p, power, iterations, bailout)
}

/// Whether `p` is in the 3D slice at `w = slice_w` of the quaternion Julia
/// set of `c` (real part first, as in the scene's `c`): the orbit of the
/// quaternion `z0 = p.x + p.y i + p.z j + slice_w k` under
/// `z -> z * z + c` stays within `bailout` for `k = 0..=iterations`.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::testing::julia_inside;
/// let c = [-0.2, 0.6, 0.2, 0.2];
/// assert!(!julia_inside(dvec3(2.0, 0.0, 0.0), c, 0.0, 12, 4.0));
/// ```
#[must_use]
pub fn julia_inside(p: DVec3, c: [f64; 4], slice_w: f64, iterations: u32, bailout: f64) -> bool {
    // glam's quaternions keep the real part in `w`.
    let c = DQuat::from_xyzw(c[1], c[2], c[3], c[0]);
    let mut z = DQuat::from_xyzw(p.y, p.z, slice_w, p.x);
    for _ in 0..iterations {
        if z.length() > bailout {
            return false;
        }
        z = z * z + c;
    }
    z.length() <= bailout
}

/// Whether `p` is in the classic (scale 3) Menger sponge on `[-1, 1]^3`
/// with `iterations` levels, by ternary digits: at each level the current
/// cell is split into 27, and the point is removed if at least two of its
/// three coordinates lie in the open middle third. Level 0 is the solid
/// cube. Points exactly on a cell boundary may go either way.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::testing::menger_inside;
/// assert!(menger_inside(dvec3(0.99, 0.99, 0.99), 3));
/// // The corner cube of level 3 is removed around (0.9, 0.9, 0.9).
/// assert!(!menger_inside(dvec3(0.9, 0.9, 0.9), 3));
/// assert!(!menger_inside(DVec3::ZERO, 1));
/// assert!(menger_inside(DVec3::ZERO, 0));
/// ```
#[must_use]
pub fn menger_inside(p: DVec3, iterations: u32) -> bool {
    let mut u = (p + DVec3::ONE) * 0.5;
    if u.min_element() < 0.0 || u.max_element() > 1.0 {
        return false;
    }
    for _ in 0..iterations {
        let s = u * 3.0;
        let middle = s.to_array().iter().filter(|&&c| c > 1.0 && c < 2.0).count();
        if middle >= 2 {
            return false;
        }
        let digit = s.floor().clamp(DVec3::ZERO, DVec3::splat(2.0));
        u = s - digit;
    }
    true
}

/// The vertices of the Sierpinski tetrahedron.
const VERTICES: [DVec3; 4] = [
    DVec3::new(1.0, 1.0, 1.0),
    DVec3::new(-1.0, -1.0, 1.0),
    DVec3::new(1.0, -1.0, -1.0),
    DVec3::new(-1.0, 1.0, -1.0),
];

/// Whether `p` is in the solid tetrahedron [`VERTICES`], from its
/// barycentric coordinates.
fn in_tetrahedron(p: DVec3) -> bool {
    let [v0, v1, v2, v3] = VERTICES;
    let edges = DMat3::from_cols(v1 - v0, v2 - v0, v3 - v0);
    let l = edges.inverse() * (p - v0);
    l.min_element() >= 0.0 && l.x + l.y + l.z <= 1.0
}

/// Whether `p` is in the classic (scale 2) Sierpinski tetrahedron with
/// vertices `(1,1,1)`, `(-1,-1,1)`, `(1,-1,-1)`, `(-1,1,-1)` and
/// `iterations` levels, by recursive containment: the point must lie in the
/// tetrahedron `T`, and at each level in one of the four half-size
/// sub-tetrahedra `v_i + (T - v_i) / 2`, which then becomes `T`. Level 0 is
/// the solid tetrahedron.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::testing::sierpinski_inside;
/// assert!(sierpinski_inside(dvec3(0.99, 0.99, 0.99), 5));
/// assert!(sierpinski_inside(DVec3::ZERO, 0));
/// assert!(!sierpinski_inside(dvec3(0.0, 0.0, -0.2), 1));
/// ```
#[must_use]
pub fn sierpinski_inside(p: DVec3, iterations: u32) -> bool {
    if !in_tetrahedron(p) {
        return false;
    }
    let mut z = p;
    for _ in 0..iterations {
        // z is in v + (T - v) / 2 exactly when 2 z - v is in T.
        match VERTICES
            .iter()
            .map(|&v| 2.0 * z - v)
            .find(|&q| in_tetrahedron(q))
        {
            Some(q) => z = q,
            None => return false,
        }
    }
    true
}

/// Whether `p` is in the Mandelbox `m` as drawn (its parameters' default
/// values), from the definition in [`Mandelbox`](crate::scene::Mandelbox):
/// `p` lies in the cube of half side `h` and, for `iterations` steps of
/// box fold, sphere fold, scale and add, no coordinate of the orbit's
/// point passes the escape threshold `(2 L |s| + c) / (|s| − 1)`, where
/// `c` is `h` (or the largest coordinate of the Julia constant) and `h`
/// is `2 L (s + 1) / (s − 1)` for a positive scale, `2 L` for a negative
/// one, the threshold itself in Julia mode.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::scene::Mandelbox;
/// use fractal_sdf::testing::mandelbox_inside;
/// let m = Mandelbox::new(-1.5).iterations(12);
/// assert!(mandelbox_inside(DVec3::ZERO, &m));
/// assert!(!mandelbox_inside(dvec3(2.1, 0.0, 0.0), &m));
/// ```
#[must_use]
pub fn mandelbox_inside(p: DVec3, m: &crate::scene::Mandelbox) -> bool {
    let s = m.scale.default_value();
    let l = m.fold_limit.default_value();
    let fixed = m.fixed_radius.default_value();
    let min = m.min_radius.default_value().min(fixed);
    let julia = m.julia.as_ref().map(|c| {
        DVec3::new(
            c[0].default_value(),
            c[1].default_value(),
            c[2].default_value(),
        )
    });
    let grow = |c: f64| (2.0 * l * s.abs() + c) / (s.abs() - 1.0);
    let (half_side, threshold) = match julia {
        Some(c) => (grow(c.abs().max_element()), grow(c.abs().max_element())),
        None if s < 0.0 => (2.0 * l, grow(2.0 * l)),
        None => {
            let h = 2.0 * l * (s + 1.0) / (s - 1.0);
            (h, grow(h))
        }
    };
    if p.abs().max_element() > half_side {
        return false;
    }
    let c = julia.unwrap_or(p);
    let mut z = p;
    for _ in 0..m.iterations {
        // The box fold: each coordinate beyond ±L reflected in that plane.
        for i in 0..3 {
            if z[i] > l {
                z[i] = 2.0 * l - z[i];
            } else if z[i] < -l {
                z[i] = -2.0 * l - z[i];
            }
        }
        // The sphere fold.
        let r = z.length();
        if r < min {
            z *= (fixed / min).powi(2);
        } else if r < fixed {
            z *= (fixed / r).powi(2);
        }
        z = s * z + c;
        if z.abs().max_element() > threshold {
            return false;
        }
    }
    true
}

/// Whether `p` is in the kaleidoscopic IFS `k` as drawn (its parameters'
/// default values), from the definition in [`Kifs`](crate::scene::Kifs):
/// after `iterations` steps the orbit is within the radius `R` (`|offset|`,
/// or `|(offset.x, offset.y)| + |offset.z|` for the Menger fold). Each
/// step is written here as the mirrors it is made of, each a reflection
/// `z − 2 (z·n) n` of the points on the wrong side of a plane, and the
/// turns as quaternions.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::scene::{Kifs, KifsFold};
/// use fractal_sdf::testing::kifs_inside;
/// let k = Kifs::new(KifsFold::Tetrahedral).iterations(6);
/// assert!(kifs_inside(dvec3(1.0, 1.0, 1.0), &k));
/// assert!(!kifs_inside(DVec3::ZERO, &k));
/// ```
#[must_use]
pub fn kifs_inside(p: DVec3, k: &crate::scene::Kifs) -> bool {
    use crate::scene::KifsFold;
    let three = |v: &[crate::scene::Param; 3]| {
        DVec3::new(
            v[0].default_value(),
            v[1].default_value(),
            v[2].default_value(),
        )
    };
    let s = k.scale.default_value();
    let offset = three(&k.offset);
    let menger = k.fold == KifsFold::Menger;
    let radius = if menger {
        offset.truncate().length() + offset.z.abs()
    } else {
        offset.length()
    };
    let turn = |angles: Option<&[crate::scene::Param; 3]>| {
        angles.map_or(DQuat::IDENTITY, |a| {
            let a = three(a);
            DQuat::from_rotation_z(a.z) * DQuat::from_rotation_y(a.y) * DQuat::from_rotation_x(a.x)
        })
    };
    let (before, after) = (
        turn(k.rotate_before.as_ref()),
        turn(k.rotate_after.as_ref()),
    );
    // Reflect `z` where `z·n` has the sign `keep` does not want.
    let mirror = |z: DVec3, n: DVec3, keep_positive: bool| {
        let n = n.normalize();
        let d = z.dot(n);
        if (keep_positive && d < 0.0) || (!keep_positive && d > 0.0) {
            z - 2.0 * d * n
        } else {
            z
        }
    };
    let coordinate_planes = |z: DVec3| {
        let z = mirror(z, DVec3::X, true);
        let z = mirror(z, DVec3::Y, true);
        mirror(z, DVec3::Z, true)
    };
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut z = p;
    for _ in 0..k.iterations {
        z = before * z;
        z = match k.fold {
            KifsFold::Tetrahedral => {
                let z = mirror(z, DVec3::new(1.0, 1.0, 0.0), true);
                let z = mirror(z, DVec3::new(1.0, 0.0, 1.0), true);
                mirror(z, DVec3::new(0.0, 1.0, 1.0), true)
            }
            KifsFold::Icosahedral => {
                let mut z = z;
                for _ in 0..3 {
                    z = coordinate_planes(z);
                    z = mirror(z, DVec3::new(-phi, phi - 1.0, 1.0), false);
                    z = mirror(z, DVec3::new(1.0, -phi, phi + 1.0), false);
                }
                z
            }
            KifsFold::Octahedral | KifsFold::Menger => {
                // The cube's mirrors: the coordinate planes, then the
                // planes that order the coordinates, largest first.
                let z = coordinate_planes(z);
                let z = mirror(z, DVec3::new(1.0, -1.0, 0.0), true);
                let z = mirror(z, DVec3::new(1.0, 0.0, -1.0), true);
                mirror(z, DVec3::new(0.0, 1.0, -1.0), true)
            }
        };
        z = after * z;
        if menger {
            z = s * z - (s - 1.0) * DVec3::new(offset.x, offset.y, 0.0);
            let h = offset.z * (s - 1.0) / 2.0;
            if z.z > h {
                z.z = 2.0 * h - z.z;
            }
        } else {
            z = s * z - (s - 1.0) * offset;
        }
    }
    z.length() <= radius
}

/// Whether `p` is in Knighty's pseudo-Kleinian set `k` as drawn (its
/// parameters' default values), from the definition in
/// [`PseudoKleinian`](crate::scene::PseudoKleinian): after `iterations`
/// steps of a reflection of each coordinate beyond the fold size, an
/// inversion of a point within the sphere of squared radius `inversion`,
/// and the offset added, the orbit ends where `√(x² + y²) · |z|` is below
/// the thickness. Written by cases, with no code of the estimator.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::scene::PseudoKleinian;
/// use fractal_sdf::testing::pseudo_kleinian_inside;
/// let k = PseudoKleinian::new();
/// // The plane z = 0 and the z axis are in it; a point off both is not.
/// assert!(pseudo_kleinian_inside(dvec3(0.3, 0.2, 0.0), &k));
/// assert!(pseudo_kleinian_inside(dvec3(0.0, 0.0, 0.4), &k));
/// assert!(!pseudo_kleinian_inside(dvec3(0.3, 0.2, 0.3), &k.clone().iterations(0)));
/// ```
#[must_use]
pub fn pseudo_kleinian_inside(p: DVec3, k: &crate::scene::PseudoKleinian) -> bool {
    let value = crate::scene::Param::default_value;
    let three = |v: &[crate::scene::Param; 3]| DVec3::new(value(&v[0]), value(&v[1]), value(&v[2]));
    let size = three(&k.fold_size);
    let offset = three(&k.offset);
    let inversion = value(&k.inversion);
    let mut z = p;
    for _ in 0..k.iterations {
        z = DVec3::new(
            reflect_beyond(z.x, size.x),
            reflect_beyond(z.y, size.y),
            reflect_beyond(z.z, size.z),
        );
        let r2 = z.length_squared();
        if r2 > 0.0 && r2 < inversion {
            z *= inversion / r2;
        }
        z += offset;
    }
    z.x.hypot(z.y) * z.z.abs() < value(&k.thickness)
}

/// Whether `p` is in the hybrid `h` as drawn (its parameters' default
/// values), from the definition in [`Hybrid`](crate::scene::Hybrid): `p`
/// is within the ball of radius `bailout`, and so is the orbit at the end
/// of each of `iterations` iterations, and no operation takes it past 16
/// times the bailout. Each operation is written
/// here from its definition: the folds as reflections in planes, the
/// sphere fold by cases, the turns as quaternions, the power in spherical
/// coordinates with `powf`, `acos` and `atan2`.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::scene::Hybrid;
/// use fractal_sdf::testing::hybrid_inside;
/// let h = Hybrid::mandelbox(2.0).iterations(8);
/// assert!(hybrid_inside(DVec3::ZERO, &h));
/// assert!(!hybrid_inside(dvec3(7.0, 0.0, 0.0), &h));
/// ```
#[must_use]
pub fn hybrid_inside(p: DVec3, h: &crate::scene::Hybrid) -> bool {
    use crate::scene::{HybridOp, KifsFold};
    // Written out here rather than read from the library.
    const FOLLOW: f64 = 16.0;
    let value = crate::scene::Param::default_value;
    let three = |v: &[crate::scene::Param; 3]| DVec3::new(value(&v[0]), value(&v[1]), value(&v[2]));
    let bailout = value(&h.bailout);
    // Reflect `z` across the plane through `at` normal to `n` where it is
    // on the side `n` points away from.
    let mirror = |z: DVec3, n: DVec3, at: f64| {
        let n = n.normalize();
        let d = z.dot(n) - at;
        if d < 0.0 { z - 2.0 * d * n } else { z }
    };
    let box_fold = reflect_beyond;
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let step = |z: DVec3, op: &HybridOp| -> DVec3 {
        match op {
            HybridOp::BoxFold { limit } => {
                let l = value(limit);
                DVec3::new(box_fold(z.x, l), box_fold(z.y, l), box_fold(z.z, l))
            }
            HybridOp::SurfFold { limit_x, limit_y } => DVec3::new(
                box_fold(z.x, value(limit_x)),
                box_fold(z.y, value(limit_y)),
                z.z,
            ),
            HybridOp::SphereFold {
                min_radius,
                fixed_radius,
            } => {
                let fixed = value(fixed_radius);
                let min = value(min_radius).min(fixed);
                let r = z.length();
                if r < min {
                    z * (fixed / min).powi(2)
                } else if r < fixed {
                    z * (fixed / r).powi(2)
                } else {
                    z
                }
            }
            HybridOp::Scale { factor, center } => {
                let c = three(center);
                c + value(factor) * (z - c)
            }
            HybridOp::Rotate { angles } => {
                let a = three(angles);
                DQuat::from_rotation_z(a.z)
                    * DQuat::from_rotation_y(a.y)
                    * DQuat::from_rotation_x(a.x)
                    * z
            }
            HybridOp::AbsFold => z.abs(),
            HybridOp::PlaneFold { normal, offset } => {
                let n = three(normal);
                if n == DVec3::ZERO {
                    z
                } else {
                    mirror(z, n, value(offset))
                }
            }
            HybridOp::Fold(fold) => match fold {
                KifsFold::Tetrahedral => {
                    let z = mirror(z, DVec3::new(1.0, 1.0, 0.0), 0.0);
                    let z = mirror(z, DVec3::new(1.0, 0.0, 1.0), 0.0);
                    mirror(z, DVec3::new(0.0, 1.0, 1.0), 0.0)
                }
                KifsFold::Icosahedral => {
                    let mut z = z;
                    for _ in 0..3 {
                        z = mirror(
                            mirror(mirror(z, DVec3::X, 0.0), DVec3::Y, 0.0),
                            DVec3::Z,
                            0.0,
                        );
                        z = mirror(z, DVec3::new(phi, 1.0 - phi, -1.0), 0.0);
                        z = mirror(z, DVec3::new(-1.0, phi, -phi - 1.0), 0.0);
                    }
                    z
                }
                _ => {
                    let z = mirror(
                        mirror(mirror(z, DVec3::X, 0.0), DVec3::Y, 0.0),
                        DVec3::Z,
                        0.0,
                    );
                    let z = mirror(z, DVec3::new(1.0, -1.0, 0.0), 0.0);
                    let z = mirror(z, DVec3::new(1.0, 0.0, -1.0), 0.0);
                    mirror(z, DVec3::new(0.0, 1.0, -1.0), 0.0)
                }
            },
            HybridOp::Power { power } => {
                let n = value(power);
                let r = z.length();
                if r == 0.0 {
                    return z;
                }
                let theta = (z.z / r).clamp(-1.0, 1.0).acos() * n;
                let azimuth = z.y.atan2(z.x) * n;
                r.powf(n)
                    * DVec3::new(
                        theta.sin() * azimuth.cos(),
                        theta.sin() * azimuth.sin(),
                        theta.cos(),
                    )
            }
            HybridOp::BulbSquare { negate_z } => {
                let r = z.length();
                if r == 0.0 {
                    return z;
                }
                let latitude = 2.0 * (z.z / r).clamp(-1.0, 1.0).asin();
                let azimuth = 2.0 * z.y.atan2(z.x);
                let sign = if *negate_z { -1.0 } else { 1.0 };
                r * r
                    * DVec3::new(
                        latitude.cos() * azimuth.cos(),
                        latitude.cos() * azimuth.sin(),
                        sign * latitude.sin(),
                    )
            }
            HybridOp::QuaternionSquare => {
                // glam's quaternions keep the real part in `w`.
                let q = DQuat::from_xyzw(z.y, z.z, 0.0, z.x);
                let q2 = q * q;
                DVec3::new(q2.w, q2.x, q2.y)
            }
            HybridOp::AddPoint => z + p,
            HybridOp::AddConstant { c } => z + three(c),
        }
    };
    if p.length() > bailout {
        return false;
    }
    let mut z = p;
    for _ in 0..h.iterations {
        for stage in &h.stages {
            for _ in 0..stage.repeat {
                for op in &stage.ops {
                    z = step(z, op);
                    if z.length() > FOLLOW * bailout {
                        return false;
                    }
                }
            }
        }
        if z.length() > bailout {
            return false;
        }
    }
    true
}

/// A coordinate beyond `±l` reflected back across that limit (the box
/// fold, by cases).
fn reflect_beyond(v: f64, l: f64) -> f64 {
    if v > l {
        2.0 * l - v
    } else if v < -l {
        -2.0 * l - v
    } else {
        v
    }
}
