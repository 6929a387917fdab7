//! Camera paths: keyframes (time, position, target) joined by a smooth
//! Catmull-Rom spline that passes through every keyframe, saved and loaded
//! as a small TOML file.
//!
//! ```
//! use fractal_sdf::animation::{CameraPath, Keyframe};
//! use fractal_sdf::prelude::*;
//!
//! let path = CameraPath::new(vec![
//!     Keyframe::new(0.0, dvec3(0.0, 0.5, 3.0), DVec3::ZERO),
//!     Keyframe::new(2.0, dvec3(3.0, 1.0, 0.0), DVec3::ZERO),
//!     Keyframe::new(4.0, dvec3(0.0, 1.5, -3.0), DVec3::ZERO),
//! ])?;
//! let halfway = path.camera_at(1.0, &Camera::default());
//! assert!(halfway.position.x > 0.0 && halfway.position.x < 3.0);
//! let text = path.to_toml()?;
//! assert_eq!(CameraPath::from_toml(&text)?, path);
//! # Ok::<(), fractal_sdf::Error>(())
//! ```

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::scene::Camera;

/// The camera's position and target at a time, in seconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Keyframe {
    /// Time in seconds from the start of the path.
    pub time: f64,
    /// Camera position.
    pub position: [f64; 3],
    /// The point the camera looks at.
    pub target: [f64; 3],
}

impl Keyframe {
    /// A keyframe at `time` seconds.
    #[must_use]
    pub fn new(time: f64, position: DVec3, target: DVec3) -> Self {
        Keyframe {
            time,
            position: position.to_array(),
            target: target.to_array(),
        }
    }
}

/// A camera path through two or more keyframes in increasing time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraPath {
    /// The keyframes, in strictly increasing time.
    #[serde(rename = "keyframe")]
    keyframes: Vec<Keyframe>,
}

impl CameraPath {
    /// A path through `keyframes`.
    ///
    /// # Errors
    /// [`Error::Animation`] if there are fewer than two keyframes, a value is
    /// not finite, or times do not strictly increase.
    pub fn new(keyframes: Vec<Keyframe>) -> Result<Self> {
        let bad = |reason: String| Err(Error::Animation { reason });
        if keyframes.len() < 2 {
            return bad(format!(
                "a path needs at least 2 keyframes, got {}",
                keyframes.len()
            ));
        }
        for (i, k) in keyframes.iter().enumerate() {
            let finite =
                k.time.is_finite() && k.position.iter().chain(&k.target).all(|v| v.is_finite());
            if !finite {
                return bad(format!("keyframe {i} has a non-finite value"));
            }
            if i > 0 && k.time <= keyframes[i - 1].time {
                return bad(format!("keyframe {i}: times must strictly increase"));
            }
        }
        Ok(CameraPath { keyframes })
    }

    /// The keyframes.
    #[must_use]
    pub fn keyframes(&self) -> &[Keyframe] {
        &self.keyframes
    }

    /// Time of the first keyframe.
    #[must_use]
    pub fn start(&self) -> f64 {
        self.keyframes[0].time
    }

    /// Time of the last keyframe.
    #[must_use]
    pub fn end(&self) -> f64 {
        self.keyframes[self.keyframes.len() - 1].time
    }

    /// Length of the path in seconds.
    #[must_use]
    pub fn duration(&self) -> f64 {
        self.end() - self.start()
    }

    /// Interpolated `(position, target)` at `time` (clamped to the path).
    #[must_use]
    pub fn sample(&self, time: f64) -> (DVec3, DVec3) {
        let k = &self.keyframes;
        let t = time.clamp(self.start(), self.end());
        // The segment k[i]..k[i + 1] containing t.
        let i = k
            .windows(2)
            .position(|w| t <= w[1].time)
            .unwrap_or(k.len() - 2);
        let last = k.len() - 1;
        // Neighbours beyond the ends are reflected (2 p_end - p_inner), so the
        // path leaves and enters its ends in a straight line.
        let at = |j: isize, f: fn(&Keyframe) -> [f64; 3]| -> (f64, DVec3) {
            let get = |j: usize| (k[j].time, DVec3::from(f(&k[j])));
            match usize::try_from(j) {
                Ok(j) if j <= last => get(j),
                Ok(_) => {
                    let ((te, pe), (ti, pi)) = (get(last), get(last - 1));
                    (2.0 * te - ti, 2.0 * pe - pi)
                }
                Err(_) => {
                    let ((te, pe), (ti, pi)) = (get(0), get(1));
                    (2.0 * te - ti, 2.0 * pe - pi)
                }
            }
        };
        let i = isize::try_from(i).expect("fewer than 2^63 keyframes");
        let spline = |f: fn(&Keyframe) -> [f64; 3]| {
            catmull_rom(at(i - 1, f), at(i, f), at(i + 1, f), at(i + 2, f), t)
        };
        (spline(|k| k.position), spline(|k| k.target))
    }

    /// `base` (for up direction and projection) moved to the path at `time`.
    #[must_use]
    pub fn camera_at(&self, time: f64, base: &Camera) -> Camera {
        let (position, target) = self.sample(time);
        Camera {
            position,
            target,
            ..*base
        }
    }

    /// The path as TOML text.
    ///
    /// # Errors
    /// [`Error::Animation`] if serialisation fails.
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| Error::Animation {
            reason: e.to_string(),
        })
    }

    /// Parses and checks a path from TOML text.
    ///
    /// # Errors
    /// [`Error::Animation`] if the text is not a valid path.
    pub fn from_toml(text: &str) -> Result<Self> {
        let raw: CameraPath = toml::from_str(text).map_err(|e| Error::Animation {
            reason: e.to_string(),
        })?;
        CameraPath::new(raw.keyframes)
    }
}

/// Time-parameterised Catmull-Rom (the Barry-Goldman pyramid) through `p1`
/// at `t1` and `p2` at `t2`; `p0` and `p3` shape the tangents.
fn catmull_rom(
    (t0, p0): (f64, DVec3),
    (t1, p1): (f64, DVec3),
    (t2, p2): (f64, DVec3),
    (t3, p3): (f64, DVec3),
    t: f64,
) -> DVec3 {
    let lerp = |a: DVec3, b: DVec3, ta: f64, tb: f64| a + (b - a) * ((t - ta) / (tb - ta));
    let a1 = lerp(p0, p1, t0, t1);
    let a2 = lerp(p1, p2, t1, t2);
    let a3 = lerp(p2, p3, t2, t3);
    let b1 = lerp(a1, a2, t0, t2);
    let b2 = lerp(a2, a3, t1, t3);
    lerp(b1, b2, t1, t2)
}
