//! Animation: camera paths — keyframes (time, position, target) joined by
//! a smooth Catmull-Rom spline that passes through every keyframe, saved and
//! loaded as a small TOML file — and [`Motion`]s, dynamic parameters that
//! change with time.
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

use std::f64::consts::TAU;

use glam::{DVec3, dvec3};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result, fmt_value};
use crate::scene::Camera;

/// The camera's position and target at a time, in seconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
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
    /// The most keyframes a path may have (56 MiB of keyframes), so that
    /// no count given by a caller or a file makes a path that cannot be
    /// held in memory.
    pub const MAX_KEYFRAMES: usize = 1 << 20;

    /// A path through `keyframes`.
    ///
    /// # Errors
    /// [`Error::Animation`] if there are fewer than two keyframes or more
    /// than [`CameraPath::MAX_KEYFRAMES`], a value is not finite, or times
    /// do not strictly increase.
    pub fn new(keyframes: Vec<Keyframe>) -> Result<Self> {
        let bad = |reason: String| Err(Error::Animation { reason });
        if keyframes.len() < 2 {
            return bad(format!(
                "a path needs at least 2 keyframes, got {}",
                keyframes.len()
            ));
        }
        if keyframes.len() > Self::MAX_KEYFRAMES {
            return bad(format!(
                "a path has at most {} keyframes, got {}",
                Self::MAX_KEYFRAMES,
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

    /// One turn around `target` in `duration` seconds: `segments` + 1
    /// keyframes (at least 4 segments) on a horizontal circle of `radius`,
    /// `height` above the target, starting on the +z side and turning
    /// counter-clockwise seen from above; every keyframe looks at `target`.
    ///
    /// ```
    /// use fractal_sdf::animation::CameraPath;
    /// use fractal_sdf::prelude::*;
    /// let orbit = CameraPath::orbit(DVec3::ZERO, 3.0, 1.0, 12.0, 12)?;
    /// let (p, t) = orbit.sample(3.0); // a quarter turn
    /// assert!((p - dvec3(3.0, 1.0, 0.0)).length() < 1e-9);
    /// assert_eq!(t, DVec3::ZERO);
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::Animation`] if a value is not finite, `duration` is not
    /// positive or `segments` is at least [`CameraPath::MAX_KEYFRAMES`];
    /// nothing is allocated before these checks.
    pub fn orbit(
        target: DVec3,
        radius: f64,
        height: f64,
        duration: f64,
        segments: u32,
    ) -> Result<Self> {
        let bad = |reason: String| Err(Error::Animation { reason });
        let segments = segments.max(4);
        if !(duration.is_finite() && duration > 0.0) {
            return bad(format!(
                "an orbit's duration must be a finite number > 0, got {}",
                fmt_value(duration)
            ));
        }
        if let Some((name, value)) = [("radius", radius), ("height", height)]
            .into_iter()
            .find(|(_, v)| !v.is_finite())
        {
            return bad(format!(
                "an orbit's {name} must be finite, got {}",
                fmt_value(value)
            ));
        }
        if !target.is_finite() {
            let [x, y, z] = target.to_array().map(|v| fmt_value(v).to_string());
            return bad(format!(
                "an orbit's target must be finite, got [{x}, {y}, {z}]"
            ));
        }
        if segments as usize >= Self::MAX_KEYFRAMES {
            return bad(format!(
                "an orbit has at most {} segments, got {segments}",
                Self::MAX_KEYFRAMES - 1
            ));
        }
        let keyframes = (0..=segments)
            .map(|i| {
                let f = f64::from(i) / f64::from(segments);
                let (s, c) = (f * TAU).sin_cos();
                let position = target + dvec3(radius * s, height, radius * c);
                Keyframe::new(f * duration, position, target)
            })
            .collect();
        CameraPath::new(keyframes)
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
        // The segment k[i]..k[i + 1] containing t: the first with
        // t <= k[i + 1].time (times increase, so a binary search).
        let i = k[1..].partition_point(|e| e.time < t).min(k.len() - 2);
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

/// A dynamic parameter that moves with time, for animated scenes: its
/// values at a time are set on the renderer before each frame.
///
/// ```
/// use fractal_sdf::animation::Motion;
/// let breathe = Motion::Oscillate {
///     name: "power".into(),
///     center: 8.0,
///     amplitude: 2.0,
///     period: 4.0,
/// };
/// assert_eq!(breathe.values(1.0), [("power".to_string(), 10.0)]);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub enum Motion {
    /// `name` = `center` + `amplitude` · sin(2π t / `period`).
    Oscillate {
        /// The dynamic parameter.
        name: String,
        /// The middle value.
        center: f64,
        /// The largest change from `center`.
        amplitude: f64,
        /// Seconds per cycle.
        period: f64,
    },
    /// The vector parameter `name` (made with
    /// [`param3`](crate::scene::param3), slots `name.x`, `name.y`,
    /// `name.z`) circles `center` horizontally at `radius`, once per
    /// `period` seconds, starting on the +x side.
    Orbit {
        /// The vector parameter's name.
        name: String,
        /// The centre of the circle.
        center: DVec3,
        /// The circle's radius.
        radius: f64,
        /// Seconds per turn.
        period: f64,
    },
}

impl Motion {
    /// The dynamic parameter (or vector parameter) it moves.
    #[must_use]
    pub fn name(&self) -> &str {
        match self {
            Motion::Oscillate { name, .. } | Motion::Orbit { name, .. } => name,
        }
    }

    /// Checks the motion: a period that is a finite number above 0, and
    /// finite values.
    ///
    /// ```
    /// use fractal_sdf::animation::Motion;
    /// let still = Motion::Oscillate {
    ///     name: "power".into(),
    ///     center: 8.0,
    ///     amplitude: 2.0,
    ///     period: f64::NAN,
    /// };
    /// let err = still.validate().unwrap_err();
    /// assert_eq!(
    ///     err.to_string(),
    ///     "motion of `power`: `period` must be a finite number of seconds > 0, got NaN"
    /// );
    /// ```
    ///
    /// # Errors
    /// [`Error::Motion`] naming the first field that is wrong.
    pub fn validate(&self) -> Result<()> {
        let (fields, period) = match self {
            Motion::Oscillate {
                center,
                amplitude,
                period,
                ..
            } => (
                vec![("center", *center), ("amplitude", *amplitude)],
                *period,
            ),
            Motion::Orbit {
                center,
                radius,
                period,
                ..
            } => (
                vec![
                    ("center", center.x),
                    ("center", center.y),
                    ("center", center.z),
                    ("radius", *radius),
                ],
                *period,
            ),
        };
        let bad = |field, value, expected| {
            Err(Error::Motion {
                name: self.name().to_string(),
                field,
                value,
                expected,
            })
        };
        if !(period > 0.0 && period.is_finite()) {
            return bad("period", period, "a finite number of seconds > 0");
        }
        for (field, value) in fields {
            if !value.is_finite() {
                return bad(field, value, "finite");
            }
        }
        Ok(())
    }

    /// The parameter values at `time` seconds, as `(slot name, value)`. A
    /// period that is not positive stands still at the start.
    #[must_use]
    pub fn values(&self, time: f64) -> Vec<(String, f64)> {
        let phase = |period: f64| {
            if period > 0.0 && time.is_finite() {
                TAU * (time / period).fract()
            } else {
                0.0
            }
        };
        match self {
            Motion::Oscillate {
                name,
                center,
                amplitude,
                period,
            } => vec![(name.clone(), center + amplitude * phase(*period).sin())],
            Motion::Orbit {
                name,
                center,
                radius,
                period,
            } => {
                let (s, c) = phase(*period).sin_cos();
                let p = *center + dvec3(radius * c, 0.0, -radius * s);
                ["x", "y", "z"]
                    .into_iter()
                    .zip(p.to_array())
                    .map(|(axis, v)| (format!("{name}.{axis}"), v))
                    .collect()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbits_refuse_counts_they_cannot_hold_before_allocating() {
        let max = CameraPath::MAX_KEYFRAMES;
        for segments in [u32::MAX, u32::try_from(max).unwrap()] {
            let err = CameraPath::orbit(DVec3::ZERO, 1.0, 0.0, 1.0, segments).unwrap_err();
            assert!(
                err.to_string()
                    .contains(&format!("at most {} segments, got {segments}", max - 1)),
                "{err}"
            );
        }
        let path =
            CameraPath::orbit(DVec3::ZERO, 1.0, 0.0, 1.0, u32::try_from(max - 1).unwrap()).unwrap();
        assert_eq!(path.keyframes().len(), max);
        // A binary search finds the segment: a quarter turn is at +x.
        let (p, _) = path.sample(0.25);
        assert!((p - dvec3(1.0, 0.0, 0.0)).length() < 1e-9, "{p}");
    }

    #[test]
    fn orbit_errors_name_the_bad_argument() {
        let err = |r: f64, h: f64, d: f64, t: DVec3| {
            CameraPath::orbit(t, r, h, d, 8).unwrap_err().to_string()
        };
        assert!(
            err(1.0, 0.0, f64::NAN, DVec3::ZERO)
                .contains("duration must be a finite number > 0, got NaN")
        );
        assert!(err(1.0, 0.0, -1e300, DVec3::ZERO).contains("got -1e300"));
        assert!(
            err(f64::INFINITY, 0.0, 1.0, DVec3::ZERO).contains("radius must be finite, got inf")
        );
        assert!(err(1.0, f64::NAN, 1.0, DVec3::ZERO).contains("height must be finite, got NaN"));
        let text = err(1.0, 0.0, 1.0, dvec3(1e300, f64::NAN, 0.0));
        assert!(
            text.contains("target must be finite, got [1e300, NaN, 0]"),
            "{text}"
        );
    }

    #[test]
    fn paths_have_a_bounded_number_of_keyframes() {
        let key = |i: usize| {
            #[allow(clippy::cast_precision_loss)]
            Keyframe::new(i as f64, DVec3::ZERO, DVec3::X)
        };
        let keys: Vec<Keyframe> = (0..=CameraPath::MAX_KEYFRAMES).map(key).collect();
        let err = CameraPath::new(keys).unwrap_err().to_string();
        assert!(
            err.contains("at most 1048576 keyframes, got 1048577"),
            "{err}"
        );
        // The segment search agrees with a linear one.
        let keys: Vec<Keyframe> = [0.0, 0.5, 2.0, 2.5, 7.0]
            .iter()
            .map(|&t| Keyframe::new(t, dvec3(t, t * t, 1.0), DVec3::ZERO))
            .collect();
        let path = CameraPath::new(keys.clone()).unwrap();
        for (t, p) in keys.iter().map(|k| (k.time, k.position)) {
            assert!((path.sample(t).0 - DVec3::from(p)).length() < 1e-12, "{t}");
        }
    }
}
