//! The camera as the kernel sees it: the ray through each pixel and the
//! size of a pixel at each distance, plus the packed light list.
//!
//! Nothing here touches OpenCL; the buffers are packed from the layouts in
//! `src/codegen/interface.rs`, which the kernel
//! reads through the header's `#define`s.

use glam::{DVec2, DVec3};

use crate::codegen::interface::{Field, camera, light, put};
use crate::cpu::{MarchSettings, Ray};
use crate::error::{Error, Result};
use crate::math::{Limits, Magnitude, normalize};
use crate::quality::{Precision, Quality};
use crate::scene::{Camera, Light, LightSource, Projection};

/// A camera fixed to an image size: the rays the kernel traces and the
/// pixel footprint that scales its hit threshold.
///
/// The kernel traces exactly these rays (pixel centres when
/// [`Quality::supersampling`] is 1), so a test can march them on the CPU
/// with [`cpu::march`](crate::cpu::march) and [`Viewport::march_settings`]
/// and compare.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::quality::Precision;
/// use fractal_sdf::render::Viewport;
/// let view = Viewport::new(&Camera::look_at(dvec3(0.0, 0.0, 5.0), DVec3::ZERO), 64, 64, Precision::F32)?;
/// // The centre of the image looks straight ahead.
/// let ray = view.ray(32.0, 32.0);
/// assert!((ray.direction - dvec3(0.0, 0.0, -1.0)).length() < 1e-12);
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viewport {
    origin: DVec3,
    right: DVec3,
    up: DVec3,
    forward: DVec3,
    half_w: f64,
    half_h: f64,
    orthographic: bool,
    footprint_base: f64,
    footprint_per_unit: f64,
    width: u32,
    height: u32,
    shift: DVec2,
    aperture: f64,
    focus: f64,
}

impl Viewport {
    /// The viewport of `camera` for a `width` × `height` image.
    ///
    /// The pixel footprint at distance `t` along a ray is
    /// `base + per_unit · t`. A perspective camera's `per_unit` is the
    /// height of a pixel at unit distance, `2·tan(fov/2) / height`; its
    /// `base` is a floor that keeps the hit threshold above zero at `t = 0`
    /// and above the rounding of the positions the kernel evaluates: eight
    /// units in the last place ([`Viewport::relative_floor`]) of the scene
    /// scale, the camera's distance from the origin plus its distance to
    /// its target. Both terms scale with the scene, so a scene scaled by
    /// `s` and seen from `s` times as far has thresholds `s` times as
    /// large. An orthographic camera's footprint is the constant
    /// `height / pixels`.
    ///
    /// # Errors
    /// [`Error::Camera`] for a degenerate camera, [`Error::Resolution`] if a
    /// side is 0.
    pub fn new(camera: &Camera, width: u32, height: u32, precision: Precision) -> Result<Self> {
        Self::in_frame(camera, width, height, precision, DVec3::ZERO)
    }

    /// As [`Viewport::new`] for a program whose positions are relative to
    /// the scene point `origin` (a
    /// [`KernelSource::origin`](crate::codegen::KernelSource::origin)):
    /// the rounding floor follows the camera's distance from `origin`, not
    /// from the world's origin. Rays stay in world coordinates.
    ///
    /// # Errors
    /// As [`Viewport::new`].
    pub fn in_frame(
        camera: &Camera,
        width: u32,
        height: u32,
        precision: Precision,
        origin: DVec3,
    ) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(Error::Resolution {
                width,
                height,
                reason: "width and height must be at least 1".into(),
            });
        }
        let (right, up, forward) = camera.basis()?;
        let aspect = f64::from(width) / f64::from(height);
        let scale =
            (camera.position - origin).length() + (camera.target - camera.position).length();
        let relative_floor = Self::relative_floor(precision);
        let (half_h, orthographic, footprint_base, footprint_per_unit) = match camera.projection {
            Projection::Perspective { fov_y_degrees } => {
                let half_h = (fov_y_degrees.to_radians() * 0.5).tan();
                let per_unit = 2.0 * half_h / f64::from(height);
                (half_h, false, scale * relative_floor, per_unit)
            }
            Projection::Orthographic { height: visible } => {
                (visible * 0.5, true, visible / f64::from(height), 0.0)
            }
        };
        Ok(Viewport {
            origin: camera.position,
            right,
            up,
            forward,
            half_w: half_h * aspect,
            half_h,
            orthographic,
            footprint_base,
            footprint_per_unit,
            width,
            height,
            shift: camera.shift,
            aperture: camera.aperture,
            focus: camera.focus_distance(),
        })
    }

    /// Eight units in the last place of a number in `[1, 2)` in the
    /// kernel's precision: `2^-20` (about 9.5e-7) in `F32`, `2^-49` (about
    /// 1.8e-15) in `F64`. Times the scene scale it is the smallest footprint
    /// a [`Viewport`] uses: positions are rounded to about a sixteenth of
    /// it, so a deep zoom can resolve detail down to it and no further.
    ///
    /// ```
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::quality::Precision;
    /// use fractal_sdf::render::Viewport;
    /// assert_eq!(Viewport::relative_floor(Precision::F32), 8.0 * f64::from(f32::EPSILON));
    /// assert_eq!(Viewport::relative_floor(Precision::F64), 8.0 * f64::EPSILON);
    /// ```
    #[must_use]
    pub fn relative_floor(precision: Precision) -> f64 {
        precision.limits().resolution
    }

    /// The ray through image position `(x, y)` in pixels, `(0, 0)` being the
    /// top-left corner: the centre of pixel `(i, j)` is `(i + 0.5, j + 0.5)`.
    /// It passes through the centre of the lens, so it is the same with or
    /// without one.
    #[must_use]
    pub fn ray(&self, x: f64, y: f64) -> Ray {
        let u = (2.0 * x / f64::from(self.width) - 1.0) * self.half_w + self.shift.x * self.half_h;
        let v = (1.0 - 2.0 * y / f64::from(self.height) + self.shift.y) * self.half_h;
        if self.orthographic {
            Ray {
                origin: self.origin + self.right * u + self.up * v,
                direction: self.forward,
            }
        } else {
            Ray {
                origin: self.origin,
                direction: normalize(self.forward + self.right * u + self.up * v)
                    .unwrap_or(self.forward),
            }
        }
    }

    /// The ray through image position `(x, y)` that leaves the lens at
    /// `lens`, a point of the unit disc scaled to the aperture: it meets
    /// [`Viewport::ray`] on the plane in focus. Without a lens (aperture
    /// 0) it is [`Viewport::ray`].
    #[must_use]
    pub fn lens_ray(&self, x: f64, y: f64, lens: DVec2) -> Ray {
        let centre = self.ray(x, y);
        if self.aperture <= 0.0 {
            return centre;
        }
        let focus =
            centre.origin + centre.direction * (self.focus / centre.direction.dot(self.forward));
        let origin = centre.origin + (self.right * lens.x + self.up * lens.y) * self.aperture;
        Ray {
            origin,
            direction: normalize(focus - origin).unwrap_or(centre.direction),
        }
    }

    /// Scene units covered by one pixel at distance `t` along a ray.
    #[must_use]
    pub fn footprint(&self, t: f64) -> f64 {
        self.footprint_base + self.footprint_per_unit * t
    }

    /// The CPU reference's settings for the same march as the kernel: this
    /// viewport's pixel footprints, and the quality's march knobs.
    #[must_use]
    pub fn march_settings(&self, quality: &Quality) -> MarchSettings {
        MarchSettings {
            max_steps: quality.max_steps,
            max_distance: quality.max_distance,
            footprint_base: self.footprint_base,
            footprint_per_unit: self.footprint_per_unit,
            detail: quality.detail,
            hit_epsilon: quality.hit_epsilon,
            over_relaxation: quality.over_relaxation,
        }
    }

    /// The image size.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The kernel's camera buffer ([`camera`] layout), with the camera
    /// moved into a frame whose origin is the scene point `origin`. The
    /// subtraction happens here in `f64`, so a camera near a distant origin
    /// reaches an `F32` kernel with small, exact coordinates.
    ///
    /// The kernel renders one pixel for every `scale` × `scale` pixels of
    /// the image ([`Quality::resolution_scale`](crate::quality::Quality::resolution_scale)).
    pub(crate) fn pack(&self, origin: DVec3, scale: u32) -> [f64; camera::LEN] {
        let mut c = [0.0; camera::LEN];
        put(&mut c, camera::ORIGIN, &(self.origin - origin).to_array());
        put(
            &mut c,
            camera::ORTHOGRAPHIC,
            &[f64::from(u8::from(self.orthographic))],
        );
        put(&mut c, camera::RIGHT, &self.right.to_array());
        put(&mut c, camera::HALF_WIDTH, &[self.half_w]);
        put(&mut c, camera::UP, &self.up.to_array());
        put(&mut c, camera::HALF_HEIGHT, &[self.half_h]);
        put(&mut c, camera::FORWARD, &self.forward.to_array());
        put(&mut c, camera::FOOTPRINT_BASE, &[self.footprint_base]);
        put(
            &mut c,
            camera::FOOTPRINT_PER_UNIT,
            &[self.footprint_per_unit],
        );
        put(&mut c, camera::IMAGE_WIDTH, &[f64::from(self.width)]);
        put(&mut c, camera::IMAGE_HEIGHT, &[f64::from(self.height)]);
        put(&mut c, camera::PIXEL_SCALE, &[f64::from(scale)]);
        put(&mut c, camera::SHIFT, &self.shift.to_array());
        put(&mut c, camera::APERTURE, &[self.aperture]);
        put(&mut c, camera::FOCUS_DISTANCE, &[self.focus]);
        c
    }
}

/// Checks what a frame hands the kernel, the packed camera and lights,
/// against the `limits` of its precision: the camera's position in the
/// program's frame, its projection (half the view's width and height) and
/// pixel footprints; each point light's position, each light's radiance
/// (colour times intensity) and softness. Unit vectors (the camera's
/// basis, light directions) are normalised in `f64` and need no check.
///
/// # Errors
/// [`Error::Precision`] naming `camera` or `light[i]` and the value.
pub(crate) fn check_frame_inputs(
    view: &Viewport,
    lights: &[Light],
    origin: DVec3,
    limits: &Limits,
) -> Result<()> {
    let check = |node: &str, param: &str, values: &[f64], magnitude| {
        for &value in values {
            if let Some(limit) = limits.crossed(value, magnitude) {
                return Err(Error::Precision {
                    node: node.into(),
                    param: param.into(),
                    value,
                    precision: limits.precision,
                    limit,
                });
            }
        }
        Ok(())
    };
    let c = view.pack(origin, 1);
    let at = |f: Field| &c[f.offset..f.offset + f.len];
    let (extent, footprint) = if view.orthographic {
        ("orthographic height", "orthographic height per pixel")
    } else {
        ("field of view", "distance to the scene")
    };
    check(
        "camera",
        "position",
        at(camera::ORIGIN),
        Magnitude::Coordinate,
    )?;
    check("camera", extent, at(camera::HALF_WIDTH), Magnitude::Size)?;
    check("camera", extent, at(camera::HALF_HEIGHT), Magnitude::Size)?;
    check(
        "camera",
        footprint,
        at(camera::FOOTPRINT_BASE),
        Magnitude::Size,
    )?;
    check(
        "camera",
        "field of view per pixel",
        at(camera::FOOTPRINT_PER_UNIT),
        Magnitude::Size,
    )?;
    check("camera", "lens shift", at(camera::SHIFT), Magnitude::Size)?;
    check("camera", "aperture", at(camera::APERTURE), Magnitude::Size)?;
    check(
        "camera",
        "focus distance",
        at(camera::FOCUS_DISTANCE),
        Magnitude::Size,
    )?;
    let packed = pack_lights(lights, origin);
    for (i, (entry, l)) in packed.chunks_exact(light::STRIDE).zip(lights).enumerate() {
        let node = format!("light[{i}]");
        let at = |f: Field| &entry[f.offset..f.offset + f.len];
        if matches!(
            l.source,
            LightSource::Point { .. } | LightSource::Sphere { .. } | LightSource::Rect { .. }
        ) {
            check(
                &node,
                "position",
                at(light::POSITION),
                Magnitude::Coordinate,
            )?;
        }
        check(
            &node,
            "color × intensity",
            at(light::RADIANCE),
            Magnitude::Size,
        )?;
        check(&node, "softness", at(light::SOFTNESS), Magnitude::Size)?;
        check(&node, "radius", at(light::RADIUS), Magnitude::Size)?;
        check(&node, "u", at(light::EDGE_U), Magnitude::Size)?;
        check(&node, "v", at(light::EDGE_V), Magnitude::Size)?;
    }
    Ok(())
}

/// The kernel's light buffer ([`light`] layout), point lights moved into
/// the frame whose origin is the scene point `origin` (as
/// [`Viewport::pack`]); at least one (unused) entry so the buffer is never
/// empty.
pub(crate) fn pack_lights(lights: &[Light], origin: DVec3) -> Vec<f64> {
    let mut out = vec![0.0; light::STRIDE * lights.len().max(1)];
    for (entry, l) in out.chunks_exact_mut(light::STRIDE).zip(lights) {
        let (v, kind) = match l.source {
            LightSource::Directional { direction } => (
                // Validation refuses a zero direction; any length is fine.
                normalize(direction).unwrap_or(DVec3::ZERO),
                light::KIND_DIRECTIONAL,
            ),
            LightSource::Point { position } => (position - origin, light::KIND_POINT),
            LightSource::Sphere { position, radius } => {
                put(entry, light::RADIUS, &[radius]);
                (position - origin, light::KIND_SPHERE)
            }
            LightSource::Rect { position, u, v } => {
                put(entry, light::EDGE_U, &u.to_array());
                put(entry, light::EDGE_V, &v.to_array());
                (position - origin, light::KIND_RECT)
            }
        };
        put(entry, light::POSITION, &v.to_array());
        put(entry, light::KIND, &[kind]);
        put(entry, light::RADIANCE, &(l.color * l.intensity).to_array());
        put(entry, light::SOFTNESS, &[l.softness]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;

    fn camera() -> Camera {
        Camera::look_at(dvec3(1.0, 2.0, 6.0), dvec3(0.0, 0.5, 0.0)).fov(60.0)
    }

    #[test]
    fn corner_rays_span_the_field_of_view() {
        let (w, h) = (80, 40);
        let view = Viewport::new(&camera(), w, h, Precision::F32).unwrap();
        let (right, up, forward) = camera().basis().unwrap();
        let top = view.ray(f64::from(w) / 2.0, 0.0).direction;
        // The top edge is half the vertical field of view above forward.
        let angle = top.dot(forward).acos().to_degrees();
        assert!((angle - 30.0).abs() < 1e-9, "{angle}");
        assert!(top.dot(up) > 0.0);
        // The right edge: tan(half horizontal fov) = aspect * tan(30°).
        let side = view.ray(f64::from(w), f64::from(h) / 2.0).direction;
        let tan = side.dot(right) / side.dot(forward);
        assert!((tan - 2.0 * 30f64.to_radians().tan()).abs() < 1e-9, "{tan}");
    }

    #[test]
    fn perspective_footprint_is_one_pixel_at_unit_distance() {
        let view = Viewport::new(&camera(), 100, 50, Precision::F32).unwrap();
        let a = view.ray(50.0, 25.0).direction;
        let b = view.ray(50.0, 26.0).direction;
        // One pixel apart at distance 1 at the image centre: the footprint
        // (off-axis it overestimates, which only makes thresholds safer).
        let gap = (a - b).length();
        let fp = view.footprint(1.0) - view.footprint(0.0);
        assert!((gap / fp - 1.0).abs() < 0.05, "{gap} vs {fp}");
        assert!(view.footprint(0.0) > 0.0);
        let q = Quality::production();
        let settings = view.march_settings(&q);
        assert_eq!(settings.footprint(1.0), view.footprint(1.0));
        assert_eq!(
            (settings.detail, settings.hit_epsilon),
            (q.detail, q.hit_epsilon)
        );
    }

    #[test]
    fn orthographic_rays_are_parallel_and_offset() {
        let cam = camera().orthographic(4.0);
        let view = Viewport::new(&cam, 40, 40, Precision::F64).unwrap();
        let a = view.ray(0.0, 0.0);
        let b = view.ray(40.0, 40.0);
        assert_eq!(a.direction, b.direction);
        assert!(((a.origin - b.origin).length() - 4.0 * 2f64.sqrt()).abs() < 1e-9);
        assert!((view.footprint(123.0) - 0.1).abs() < 1e-15);
        assert_eq!(view.pack(DVec3::ZERO, 1)[camera::ORTHOGRAPHIC.offset], 1.0);
    }

    #[test]
    fn zero_size_is_a_resolution_error() {
        let err = Viewport::new(&camera(), 0, 10, Precision::F32).unwrap_err();
        assert!(matches!(err, Error::Resolution { width: 0, .. }), "{err}");
    }

    #[test]
    fn lights_pack_normalised_directions_and_radiance() {
        let lights = [
            Light::directional(dvec3(0.0, 2.0, 0.0)).intensity(2.0),
            Light::point(dvec3(1.0, 2.0, 3.0)).softness(0.0),
            Light::sphere(dvec3(0.0, 4.0, 0.0), 0.5).softness(0.0),
        ];
        let packed = pack_lights(&lights, DVec3::ZERO);
        assert_eq!(packed.len(), 3 * light::STRIDE);
        let at = |i: usize, n: usize| &packed[i * light::STRIDE..][..n];
        assert_eq!(at(0, 9), &[0.0, 1.0, 0.0, 0.0, 2.0, 2.0, 2.0, 0.05, 0.0]);
        assert_eq!(at(1, 9), &[1.0, 2.0, 3.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0]);
        assert_eq!(at(2, 9), &[0.0, 4.0, 0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 0.5]);
        assert_eq!(pack_lights(&[], DVec3::ZERO).len(), light::STRIDE);
        // Into a frame far away: point lights move, directions do not.
        let origin = dvec3(1e7, -1e7, 3.0);
        let moved = pack_lights(&lights, origin);
        assert_eq!(&moved[..9], at(0, 9));
        assert_eq!(&moved[light::STRIDE..][..3], &[1.0 - 1e7, 2.0 + 1e7, 0.0]);
    }
}
