//! The camera of a rendered frame as a small JSON file, for lining the
//! frame (and a mesh exported from the scene) up in a 3D package.

use std::io::Write;
use std::path::Path;

use glam::{DMat3, DQuat, DVec2, DVec3};
use serde::{Deserialize, Serialize};

use super::write_atomic;
use crate::error::{Error, Result};
use crate::scene::{Camera, Projection};

/// The sensor height [`CameraExport`] assumes, in millimetres, to give a
/// focal length (a full-frame sensor's 24 mm).
pub const SENSOR_HEIGHT_MM: f64 = 24.0;

/// A frame's camera, as the renderer uses it, in the terms a 3D package
/// takes: position, orientation, field of view, sensor and image size.
///
/// Positions are in the scene's units (one unit is one metre, or one
/// Blender unit, wherever a package asks). The camera looks along
/// [`CameraExport::forward`], with [`CameraExport::up`] up the image and
/// [`CameraExport::right`] to its right; [`CameraExport::rotation`] is the
/// same orientation as the quaternion that turns a camera looking down its
/// −Z axis with +Y up (Blender's and OpenGL's convention) into it.
///
/// The guide's chapter on outputs has a Blender script that reads the
/// file and sets up a camera that sees what the frame shows.
///
/// ```
/// use fractal_sdf::output::CameraExport;
/// use fractal_sdf::prelude::*;
///
/// let camera = Camera::look_at(dvec3(0.0, 0.0, 4.0), DVec3::ZERO);
/// let exported = CameraExport::new(&camera, (640, 480))?;
/// assert_eq!(exported.forward, [0.0, 0.0, -1.0]);
/// // The target is drawn at the image's centre.
/// let [x, y] = exported.project(DVec3::ZERO).unwrap();
/// assert!((x - 320.0).abs() < 1e-9 && (y - 240.0).abs() < 1e-9);
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct CameraExport {
    /// What the file is: `"fractal-sdf camera"`.
    pub format: String,
    /// The frame's index in its sequence, where it has one.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub frame: Option<u64>,
    /// The frame's time in seconds, where it is one of a sequence.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub time: Option<f64>,
    /// Where the camera is (the centre of its lens).
    pub position: [f64; 3],
    /// The unit direction it looks along.
    pub forward: [f64; 3],
    /// The unit direction up the image.
    pub up: [f64; 3],
    /// The unit direction to the image's right.
    pub right: [f64; 3],
    /// The orientation as a unit quaternion `[w, x, y, z]`: it turns a
    /// camera looking down −Z with +Y up into this one.
    pub rotation: [f64; 4],
    /// `"perspective"` or `"orthographic"`.
    pub projection: String,
    /// Vertical field of view in degrees (perspective).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub fov_y_degrees: Option<f64>,
    /// Horizontal field of view in degrees (perspective).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub fov_x_degrees: Option<f64>,
    /// The focal length in millimetres on a sensor [`SENSOR_HEIGHT_MM`]
    /// high (perspective).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub focal_length_mm: Option<f64>,
    /// The visible height in scene units (orthographic).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub ortho_height: Option<f64>,
    /// The sensor's height in millimetres (the field of view fits it).
    pub sensor_height_mm: f64,
    /// The sensor's width in millimetres: the height times the aspect.
    pub sensor_width_mm: f64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Width over height.
    pub aspect: f64,
    /// The lens shift, in half image heights ([`Camera::shift`]).
    pub shift: [f64; 2],
    /// The lens radius in scene units (0: a pinhole).
    pub aperture: f64,
    /// The distance along the view that is in focus.
    pub focus_distance: f64,
}

impl CameraExport {
    /// The camera of a `width` × `height` frame.
    ///
    /// # Errors
    /// [`Error::Camera`] for a camera without a view (its target at its
    /// position, or up along the view); [`Error::Resolution`] for a zero
    /// side.
    pub fn new(camera: &Camera, (width, height): (u32, u32)) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(Error::Resolution {
                width,
                height,
                reason: "a camera's image needs at least 1 pixel on each side".into(),
            });
        }
        let (right, up, forward) = camera.basis()?;
        let aspect = f64::from(width) / f64::from(height);
        // Columns: where the camera's own x, y and z axes point.
        let rotation = DQuat::from_mat3(&DMat3::from_cols(right, up, -forward)).normalize();
        let (projection, fov_y, ortho) = match camera.projection {
            Projection::Perspective { fov_y_degrees } => ("perspective", Some(fov_y_degrees), None),
            Projection::Orthographic { height } => ("orthographic", None, Some(height)),
        };
        let half_y = fov_y.map(|f| (f.to_radians() / 2.0).tan());
        Ok(CameraExport {
            format: "fractal-sdf camera".into(),
            frame: None,
            time: None,
            position: camera.position.to_array(),
            forward: forward.to_array(),
            up: up.to_array(),
            right: right.to_array(),
            rotation: [rotation.w, rotation.x, rotation.y, rotation.z],
            projection: projection.into(),
            fov_y_degrees: fov_y,
            fov_x_degrees: half_y.map(|h| 2.0 * (h * aspect).atan().to_degrees()),
            focal_length_mm: half_y.map(|h| SENSOR_HEIGHT_MM / 2.0 / h),
            ortho_height: ortho,
            sensor_height_mm: SENSOR_HEIGHT_MM,
            sensor_width_mm: SENSOR_HEIGHT_MM * aspect,
            width,
            height,
            aspect,
            shift: camera.shift.to_array(),
            aperture: camera.aperture,
            focus_distance: camera.focus_distance(),
        })
    }

    /// The same camera as the frame `frame` of a sequence, at `time`
    /// seconds.
    #[must_use]
    pub fn at_frame(mut self, frame: u64, time: f64) -> Self {
        self.frame = Some(frame);
        self.time = Some(time);
        self
    }

    /// Where the renderer draws the point `p`, in image pixels: `(0, 0)`
    /// is the image's top-left corner and the centre of pixel `(i, j)` is
    /// `(i + 0.5, j + 0.5)`. `None` for a point behind a perspective
    /// camera (or in its plane).
    #[must_use]
    pub fn project(&self, p: DVec3) -> Option<[f64; 2]> {
        let d = p - DVec3::from(self.position);
        let (x, y, z) = (
            d.dot(DVec3::from(self.right)),
            d.dot(DVec3::from(self.up)),
            d.dot(DVec3::from(self.forward)),
        );
        let (u, v, half_h) = match (self.fov_y_degrees, self.ortho_height) {
            (Some(fov), _) => {
                if z <= 0.0 {
                    return None;
                }
                (x / z, y / z, (fov.to_radians() / 2.0).tan())
            }
            (None, Some(height)) => (x, y, height / 2.0),
            (None, None) => return None,
        };
        let shift = DVec2::from(self.shift);
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let half_w = half_h * self.aspect;
        Some([
            w / 2.0 * ((u - shift.x * half_h) / half_w + 1.0),
            h / 2.0 * (1.0 + shift.y - v / half_h),
        ])
    }

    /// The export as pretty-printed JSON.
    #[must_use]
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("the export is plain data")
    }

    /// Writes the JSON to `path`, atomically as images are written.
    ///
    /// # Errors
    /// As [`save_png`](super::save_png).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let text = self.to_json() + "\n";
        write_atomic(path.as_ref(), "camera", |mut file| {
            file.write_all(text.as_bytes())
        })
    }

    /// Every frame's camera of a sequence, as one JSON array.
    ///
    /// # Errors
    /// As [`CameraExport::save`].
    pub fn save_all(frames: &[CameraExport], path: impl AsRef<Path>) -> Result<()> {
        let text = serde_json::to_string_pretty(frames).expect("the exports are plain data") + "\n";
        write_atomic(path.as_ref(), "cameras", |mut file| {
            file.write_all(text.as_bytes())
        })
    }
}
