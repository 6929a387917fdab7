//! Light from every direction: an equirectangular HDR image around the
//! scene ([`Environment`]).
//!
//! Direction `d` (a unit vector, +Y up) looks up the image at
//! `u = 1/2 + atan2(d.x, -d.z) / 2π` across and `v = acos(d.y) / π` down:
//! the top row is straight up, the bottom row straight down, and the
//! centre of the image lies along −Z, straight ahead of a camera looking
//! down −Z (the default camera's view). Radiances are bilinear between
//! texel centres, wrapping across the seam.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec3;

use crate::error::{Error, Result};

/// The largest side of an environment image, in texels.
pub const MAX_ENVIRONMENT_SIDE: u32 = 8192;

/// An equirectangular image of linear RGB radiance, as an environment
/// light.
///
/// Direction `d` (a unit vector, +Y up) looks up the image at
/// `u = 1/2 + atan2(d.x, -d.z) / 2π` across and `v = acos(d.y) / π` down:
/// the top row is straight up, the bottom row straight down, and the
/// centre of the image lies along −Z, straight ahead of a camera looking
/// down −Z (the default camera's view).
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentMap {
    width: u32,
    height: u32,
    texels: Vec<[f32; 3]>,
}

impl EnvironmentMap {
    /// A map of `width` × `height` texels, row by row from the top.
    ///
    /// # Errors
    /// [`Error::Environment`] for a side of 0 or above
    /// [`MAX_ENVIRONMENT_SIDE`], a texel count other than
    /// `width * height`, or a radiance that is not finite and `>= 0`.
    pub fn new(width: u32, height: u32, texels: Vec<[f32; 3]>) -> Result<Self> {
        let bad = |reason: String| Err(Error::Environment { reason });
        if width == 0 || height == 0 || width.max(height) > MAX_ENVIRONMENT_SIDE {
            return bad(format!(
                "an environment image of {width}x{height} texels: each side must be 1 to \
                 {MAX_ENVIRONMENT_SIDE}"
            ));
        }
        if texels.len() != width as usize * height as usize {
            return bad(format!(
                "{} texels for a {width}x{height} image",
                texels.len()
            ));
        }
        if let Some(i) = texels
            .iter()
            .position(|t| t.iter().any(|c| !(c.is_finite() && *c >= 0.0)))
        {
            let (x, y) = (i % width as usize, i / width as usize);
            return bad(format!(
                "the radiance {:?} at texel ({x}, {y}) is not finite and >= 0",
                texels[i]
            ));
        }
        Ok(EnvironmentMap {
            width,
            height,
            texels,
        })
    }

    /// Reads a Radiance `.hdr` file, or an OpenEXR `.exr` file's RGB
    /// layer (with the `opencl` feature, which brings the OpenEXR reader).
    ///
    /// # Errors
    /// [`Error::Io`] where the file cannot be read; [`Error::Environment`]
    /// for another extension, an image that does not decode, or one
    /// [`EnvironmentMap::new`] refuses.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let bytes = std::fs::read(path)
            .map_err(|source| Error::io(path, "cannot read the environment image", source))?;
        let decoded = match extension.as_deref() {
            Some("hdr") => Self::from_hdr_bytes(&bytes),
            Some("exr") => Self::from_exr_bytes(&bytes),
            _ => Err(Error::Environment {
                reason: "an environment image is a Radiance `.hdr` or an OpenEXR `.exr` file"
                    .into(),
            }),
        };
        decoded.map_err(|e| match e {
            Error::Environment { reason } => Error::Environment {
                reason: format!("{}: {reason}", path.display()),
            },
            other => other,
        })
    }

    /// Decodes the bytes of a Radiance `.hdr` file.
    ///
    /// # Errors
    /// [`Error::Environment`] if they do not decode, or as
    /// [`EnvironmentMap::new`].
    pub fn from_hdr_bytes(bytes: &[u8]) -> Result<Self> {
        let image = image::load_from_memory_with_format(bytes, image::ImageFormat::Hdr)
            .map_err(|e| Error::Environment {
                reason: format!("not a readable Radiance HDR image: {e}"),
            })?
            .into_rgb32f();
        let (width, height) = image.dimensions();
        let texels = image.pixels().map(|p| p.0).collect();
        Self::new(width, height, texels)
    }

    #[cfg(feature = "opencl")]
    fn from_exr_bytes(bytes: &[u8]) -> Result<Self> {
        use exr::prelude::{ReadChannels, ReadLayers};
        let bad = |e: exr::error::Error| Error::Environment {
            reason: format!("not a readable OpenEXR image: {e}"),
        };
        let image = exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .rgb_channels(
                |size, _| (size.width(), vec![[0.0f32; 3]; size.area()]),
                |(width, texels), at, (r, g, b): (f32, f32, f32)| {
                    texels[at.y() * *width + at.x()] = [r, g, b];
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(std::io::Cursor::new(bytes))
            .map_err(bad)?;
        let size = image.layer_data.size;
        let (_, texels) = image.layer_data.channel_data.pixels;
        let side = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
        Self::new(side(size.width()), side(size.height()), texels)
    }

    #[cfg(not(feature = "opencl"))]
    fn from_exr_bytes(_: &[u8]) -> Result<Self> {
        Err(Error::Environment {
            reason: "reading OpenEXR needs the crate's `opencl` feature".into(),
        })
    }

    /// Writes the map as a Radiance `.hdr` file (8-bit mantissas with a
    /// shared exponent: about 1% precision).
    ///
    /// # Errors
    /// [`Error::Io`] where the file cannot be written.
    pub fn save_hdr(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let file = std::fs::File::create(path)
            .map_err(|source| Error::io(path, "cannot write the environment image", source))?;
        let texels: Vec<image::Rgb<f32>> = self.texels.iter().map(|&t| image::Rgb(t)).collect();
        image::codecs::hdr::HdrEncoder::new(std::io::BufWriter::new(file))
            .encode(&texels, self.width as usize, self.height as usize)
            .map_err(|e| {
                Error::io(
                    path,
                    "cannot write the environment image",
                    std::io::Error::other(e),
                )
            })
    }

    /// A clear daylight sky made by formula, the project's own: a blue
    /// zenith paling to a bright horizon, a sun of radius 2.5° towards
    /// `sun` (normalised; above the horizon) with a glow around it, and a
    /// grey-brown ground below the horizon, lit by both. The sun's disc is
    /// about a thousand times as bright as the sky beside it: it gives a
    /// face turned to it three times the light the rest of the sky does,
    /// and casts sharp shadows, which the sky fills softly.
    ///
    /// # Errors
    /// As [`EnvironmentMap::new`] for the size; [`Error::Environment`]
    /// for a sun direction that is not a finite vector above the horizon.
    pub fn sky(width: u32, height: u32, sun: DVec3) -> Result<Self> {
        let sun = crate::math::normalize(sun)
            .filter(|s| s.y > 0.0)
            .ok_or_else(|| Error::Environment {
                reason: format!("the sun {sun} must point above the horizon (y > 0)"),
            })?;
        let mut texels = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                let u = (f64::from(x) + 0.5) / f64::from(width);
                let v = (f64::from(y) + 0.5) / f64::from(height);
                texels.push(sky_radiance(direction(u, v), sun));
            }
        }
        Self::new(width, height, texels)
    }

    /// The image's width in texels.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// The image's height in texels.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The texels, row by row from the top.
    #[must_use]
    pub fn texels(&self) -> &[[f32; 3]] {
        &self.texels
    }

    /// The radiance arriving from direction `d` (need not be unit length):
    /// bilinear between texel centres, as the kernel reads it.
    #[must_use]
    pub fn radiance(&self, d: DVec3) -> [f32; 3] {
        let (u, v) = coordinates(d);
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let fx = u * w - 0.5;
        let fy = (v * h - 0.5).clamp(0.0, h - 1.0);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let texel = |x: f64, y: f64| {
            let x = x.rem_euclid(w) as usize;
            let y = y.min(h - 1.0) as usize;
            self.texels[y * self.width as usize + x].map(f64::from)
        };
        let (a, b) = (texel(x0, y0), texel(x0 + 1.0, y0));
        let (c, e) = (texel(x0, y0 + 1.0), texel(x0 + 1.0, y0 + 1.0));
        #[allow(clippy::cast_possible_truncation)]
        std::array::from_fn(|i| {
            let top = a[i] + (b[i] - a[i]) * tx;
            let bottom = c[i] + (e[i] - c[i]) * tx;
            (top + (bottom - top) * ty) as f32
        })
    }
}

/// An environment light: an [`EnvironmentMap`] turned about the vertical
/// and scaled. Without global illumination it is the background, what
/// mirrors and glass show, and the ambient light (its irradiance on a
/// face, scaled as the sky gradient's); with global illumination it
/// lights the scene exactly, sampled by importance.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Environment {
    /// The image.
    pub map: Arc<EnvironmentMap>,
    /// How far the image is turned about +Y, in degrees (90 brings what
    /// lay along +X to −Z, in front of the default camera).
    pub rotation_degrees: f64,
    /// What every radiance is multiplied by (`>= 0`).
    pub intensity: f64,
    /// The file a scene file names for the image, as it names it (relative
    /// to the scene file's folder, or absolute); `None` for a map made in
    /// memory, which a scene file cannot name.
    pub source: Option<PathBuf>,
}

impl Environment {
    /// `map` unturned at intensity 1, from no file.
    #[must_use]
    pub fn new(map: EnvironmentMap) -> Self {
        Environment {
            map: Arc::new(map),
            rotation_degrees: 0.0,
            intensity: 1.0,
            source: None,
        }
    }

    /// Reads the image at `path` ([`EnvironmentMap::load`]); the
    /// environment names it as `path`.
    ///
    /// # Errors
    /// As [`EnvironmentMap::load`].
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Ok(Environment {
            source: Some(path.to_path_buf()),
            ..Self::new(EnvironmentMap::load(path)?)
        })
    }

    /// Turns the image by `degrees` about +Y.
    #[must_use]
    pub fn rotation_degrees(mut self, degrees: f64) -> Self {
        self.rotation_degrees = degrees;
        self
    }

    /// Scales its radiance by `intensity`.
    #[must_use]
    pub fn intensity(mut self, intensity: f64) -> Self {
        self.intensity = intensity;
        self
    }

    /// Names the file a scene file writes for the image.
    #[must_use]
    pub fn source(mut self, path: impl Into<PathBuf>) -> Self {
        self.source = Some(path.into());
        self
    }

    /// The radiance arriving from direction `d`, turned and scaled.
    #[must_use]
    pub fn radiance(&self, d: DVec3) -> DVec3 {
        let (s, c) = self.rotation_degrees.to_radians().sin_cos();
        // The image turned by r about +Y: look up the direction turned by -r.
        let local = DVec3::new(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
        DVec3::from(self.map.radiance(local).map(f64::from)) * self.intensity
    }

    /// Checks the rotation and intensity.
    ///
    /// # Errors
    /// [`Error::Environment`] for a rotation that is not finite, or an
    /// intensity that is not finite and `>= 0`.
    pub fn validate(&self) -> Result<()> {
        if !self.rotation_degrees.is_finite() {
            return Err(Error::Environment {
                reason: format!("rotation_degrees {} is not finite", self.rotation_degrees),
            });
        }
        if !(self.intensity.is_finite() && self.intensity >= 0.0) {
            return Err(Error::Environment {
                reason: format!("intensity {} is not finite and >= 0", self.intensity),
            });
        }
        Ok(())
    }
}

/// The image coordinates `(u, v)` in `[0, 1]` of direction `d`.
pub(crate) fn coordinates(d: DVec3) -> (f64, f64) {
    let d = d.normalize_or(DVec3::Y);
    let u = 0.5 + d.x.atan2(-d.z) / std::f64::consts::TAU;
    let v = d.y.clamp(-1.0, 1.0).acos() / std::f64::consts::PI;
    (u, v)
}

/// The unit direction at image coordinates `(u, v)`.
pub(crate) fn direction(u: f64, v: f64) -> DVec3 {
    let phi = (u - 0.5) * std::f64::consts::TAU;
    let theta = v * std::f64::consts::PI;
    let (st, ct) = theta.sin_cos();
    DVec3::new(st * phi.sin(), ct, -st * phi.cos())
}

/// The procedural sky's radiance along unit `d`, the sun along unit `sun`.
fn sky_radiance(d: DVec3, sun: DVec3) -> [f32; 3] {
    let zenith = DVec3::new(0.09, 0.18, 0.42);
    let horizon = DVec3::new(0.42, 0.45, 0.5);
    let ground = DVec3::new(0.15, 0.135, 0.12);
    let cos_sun = d.dot(sun);
    let radiance = if d.y >= 0.0 {
        // Paler towards the horizon; a glow and the disc towards the sun.
        let sky = horizon.lerp(zenith, d.y.powf(0.45));
        let glow = DVec3::new(1.0, 0.85, 0.6) * (0.8 * cos_sun.max(0.0).powi(64));
        let disc = if cos_sun > 2.5f64.to_radians().cos() {
            DVec3::new(1.0, 0.95, 0.85) * 400.0
        } else {
            DVec3::ZERO
        };
        sky + glow + disc
    } else {
        // The ground, darker straight down, under a little haze.
        ground * (0.6 + 0.4 * (1.0 + d.y)) + horizon * (0.15 * (1.0 + d.y).powi(8))
    };
    #[allow(clippy::cast_possible_truncation)]
    radiance.to_array().map(|c| c as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_and_coordinates_are_inverse() {
        for (u, v) in [(0.5, 0.5), (0.1, 0.3), (0.9, 0.8), (0.25, 0.01)] {
            let (a, b) = coordinates(direction(u, v));
            assert!((a - u).abs() < 1e-12 && (b - v).abs() < 1e-12, "{u} {v}");
        }
        // The centre looks down -Z, the top straight up.
        assert!(direction(0.5, 0.5).distance(DVec3::NEG_Z) < 1e-12);
        assert!(direction(0.3, 0.0).distance(DVec3::Y) < 1e-12);
    }

    #[test]
    fn bad_maps_are_refused() {
        assert!(EnvironmentMap::new(0, 1, vec![]).is_err());
        assert!(EnvironmentMap::new(2, 1, vec![[1.0; 3]]).is_err());
        assert!(EnvironmentMap::new(1, 1, vec![[f32::NAN, 0.0, 0.0]]).is_err());
        assert!(EnvironmentMap::new(1, 1, vec![[-1.0, 0.0, 0.0]]).is_err());
        assert!(EnvironmentMap::sky(8, 4, DVec3::NEG_Y).is_err());
        let env = Environment::new(EnvironmentMap::new(1, 1, vec![[1.0; 3]]).unwrap());
        assert!(env.clone().intensity(-1.0).validate().is_err());
        assert!(env.rotation_degrees(f64::INFINITY).validate().is_err());
    }

    #[test]
    fn a_turned_map_looks_up_the_turned_direction() {
        // Four columns; the third's centre, u = 5/8, is blue.
        let texels = vec![
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 0.0],
        ];
        let env = Environment::new(EnvironmentMap::new(4, 1, texels).unwrap());
        let at = |env: &Environment, u: f64| env.radiance(direction(u, 0.5)).to_array();
        assert_eq!(at(&env, 0.625), [0.0, 0.0, 1.0]);
        // A quarter turn brings +X (u = 3/4) to -Z (u = 1/2): what lay at
        // u lies at u - 1/4.
        let turned = env.clone().rotation_degrees(90.0);
        let moved = at(&turned, 0.375);
        assert!(
            moved
                .iter()
                .zip([0.0, 0.0, 1.0])
                .all(|(a, b)| (a - b).abs() < 1e-6),
            "{moved:?}"
        );
    }
}
