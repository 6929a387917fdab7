//! The CPU reference of the kernels' surface shading (`march_shade` in
//! `kernels/shade.cl`): the sky's ambient light and every light's diffuse
//! (Lambert or Oren–Nayar), Blinn–Phong highlight and subsurface terms,
//! with the same formulas, in `f64`. It leaves out what needs more than
//! the surface point: ambient occlusion and shadows (render with those
//! effects off to compare), and the secondary rays of reflective and
//! transparent materials.

use glam::DVec3;

use super::Evaluator;
use crate::scene::{Light, LightSource, Material};

/// The sky's colours, whose hemisphere lights every surface
/// ([`Effects::sky_bottom`](crate::quality::Effects::sky_bottom) and
/// [`Effects::sky_top`](crate::quality::Effects::sky_top)).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Sky {
    /// Linear RGB below the horizon.
    pub bottom: DVec3,
    /// Linear RGB overhead.
    pub top: DVec3,
}

impl Sky {
    /// A sky from its colour overhead and below the horizon.
    #[must_use]
    pub fn new(top: DVec3, bottom: DVec3) -> Sky {
        Sky { bottom, top }
    }
}

/// The kernels' strength of the sky's hemisphere light
/// (`MARCH_AMBIENT`).
pub const AMBIENT: f64 = 0.5;

/// How many points along the inward normal [`thinness`] samples
/// (`MARCH_SCATTER_SAMPLES`).
pub const SCATTER_SAMPLES: u32 = 4;

/// The lit linear colour of the surface point `p` of `eval`'s scene with
/// unit outward normal `n`, seen along the unit direction `rd`, under
/// `lights` and `sky`; occlusion 1 and no shadows. `p`,
/// `n` and `rd` are in the scene's coordinates, as the renderer's AOVs
/// give them.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::cpu;
/// use fractal_sdf::cpu::shade;
///
/// let eval = cpu::Evaluator::new(&sphere(1.0).material(Material::oren_nayar(0.5)))?;
/// let lights = [Light::directional(dvec3(0.0, 0.0, 1.0))];
/// let p = dvec3(0.0, 0.0, 1.0);
/// let effects = Effects::default();
/// let sky = shade::Sky::new(effects.sky_top, effects.sky_bottom);
/// let lit = shade::shade(&eval, p, p, -p, &lights, sky);
/// assert!(lit.x > 0.5);
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
#[must_use]
pub fn shade(eval: &Evaluator, p: DVec3, n: DVec3, rd: DVec3, lights: &[Light], sky: Sky) -> DVec3 {
    let sample = eval.sample::<f64>(p.into());
    let albedo = DVec3::from(sample.color) * trap_tint(sample.trap);
    let m: Material<f64> = Material::from_values(sample.material);
    let ambient = sky.bottom.lerp(sky.top, 0.5 + 0.5 * n.y);
    let mut color = albedo * ambient * AMBIENT + albedo * m.emission;
    let through = if m.subsurface > 0.0 && m.scatter_depth > 0.0 {
        m.subsurface * thinness(eval, p, n, m.scatter_depth)
    } else {
        0.0
    };
    for light in lights {
        let mut radiance = light.color * light.intensity;
        let to_light = match light.source {
            LightSource::Directional { direction } => direction.normalize(),
            // Direct lighting takes a sphere light for a point light.
            LightSource::Point { position }
            | LightSource::Sphere { position, .. }
            | LightSource::Rect { position, .. } => {
                let delta = position - p;
                let dist2 = delta.length_squared().max(crate::math::REAL_TINY);
                radiance /= dist2;
                delta / dist2.sqrt()
            }
        };
        // A rectangle lights its own side, dimming with the angle.
        if let LightSource::Rect { u, v, .. } = light.source {
            radiance *= u.cross(v).normalize_or_zero().dot(-to_light).max(0.0);
        }
        let ndl = n.dot(to_light);
        if ndl < 0.0 {
            color += radiance * albedo * (through * -ndl);
        }
        if ndl <= 0.0 {
            continue;
        }
        let diffuse = oren_nayar(m.roughness, n, to_light, -rd, ndl);
        let half = (to_light - rd).normalize();
        let specular = m.specular * n.dot(half).max(0.0).powf(m.shininess);
        color += radiance * (albedo * (diffuse * ndl) + DVec3::splat(specular * ndl));
    }
    color
}

/// Oren–Nayar's diffuse light relative to Lambert's (1 at `sigma` 0) for
/// unit normal `n`, light direction `l` and view direction `v`, with
/// `ndl = n·l > 0` (`march_oren_nayar`): `A + B max(0, cos(φl − φv))
/// sin α tan β`, `A = 1 − σ²/(2(σ² + 0.33))`, `B = 0.45 σ²/(σ² + 0.09)`,
/// α and β the larger and smaller angle of `l` and `v` from `n`.
#[must_use]
pub fn oren_nayar(sigma: f64, n: DVec3, l: DVec3, v: DVec3, ndl: f64) -> f64 {
    if sigma <= 0.0 {
        return 1.0;
    }
    let s2 = sigma * sigma;
    let a = 1.0 - 0.5 * s2 / (s2 + 0.33);
    let b = 0.45 * s2 / (s2 + 0.09);
    let ndv = n.dot(v).clamp(1e-4, 1.0);
    let (lt, vt) = (l - n * ndl, v - n * ndv);
    let norms = lt.length() * vt.length();
    let cos_phi = if norms > crate::math::REAL_TINY {
        (lt.dot(vt) / norms).max(0.0)
    } else {
        0.0
    };
    let (cos_alpha, cos_beta) = (ndl.min(ndv), ndl.max(ndv));
    let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
    let tan_beta = (1.0 - cos_beta * cos_beta).max(0.0).sqrt() / cos_beta;
    a + b * cos_phi * sin_alpha * tan_beta
}

/// How thin the shape is below `p` (outward normal `n`) down to `depth`:
/// 0 where it is solid that deep, towards 1 where it ends sooner
/// (`march_thinness`).
#[must_use]
pub fn thinness(eval: &Evaluator, p: DVec3, n: DVec3, depth: f64) -> f64 {
    let solid: f64 = (1..=SCATTER_SAMPLES)
        .map(|i| {
            let h = depth * f64::from(i) / f64::from(SCATTER_SAMPLES);
            (-eval.distance(p - n * h) / h).clamp(0.0, 1.0)
        })
        .sum();
    1.0 - solid / f64::from(SCATTER_SAMPLES)
}

/// The kernels' orbit-trap tint (`march_trap_tint`): a cosine palette that
/// fades to white as the trap reaches 1.
#[must_use]
pub fn trap_tint(trap: f64) -> DVec3 {
    let t = trap.clamp(0.0, 1.0);
    let phase = DVec3::new(0.0, 0.1, 0.2) + DVec3::splat(t);
    let cosine = DVec3::from((std::f64::consts::TAU * phase).to_array().map(f64::cos));
    (DVec3::splat(0.5) + 0.5 * cosine).lerp(DVec3::ONE, t)
}

/// The share of light a clear surface reflects, arriving from index 1 at
/// an angle with cosine `cos_i` onto index `ior`: Fresnel's equations for
/// unpolarised light, 0 for `ior` 1 and 1 on total internal reflection
/// (`march_fresnel`).
#[must_use]
pub fn fresnel(cos_i: f64, ior: f64) -> f64 {
    let sin_t2 = (1.0 - cos_i * cos_i) / (ior * ior);
    if sin_t2 >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let rs = (cos_i - ior * cos_t) / (cos_i + ior * cos_t);
    let rp = (cos_t - ior * cos_i) / (cos_t + ior * cos_i);
    0.5 * (rs * rs + rp * rp)
}

/// `rd` refracted through a surface with unit normal `n` facing it, from
/// index 1 into index `1 / eta`; `None` on total internal reflection
/// (`march_refract`).
#[must_use]
pub fn refract(rd: DVec3, n: DVec3, eta: f64) -> Option<DVec3> {
    let cos_i = -n.dot(rd);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    (k >= 0.0).then(|| eta * rd + (eta * cos_i - k.sqrt()) * n)
}
