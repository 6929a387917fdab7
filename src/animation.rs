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

use glam::{DQuat, DVec3, dvec3};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result, fmt_value};
use crate::scene::{Camera, Projection};

/// How a track moves from one key to the next: each key's interpolation
/// shapes the segment that starts at it.
///
/// | interpolation | between the values `a` and `b`, at the fraction `u` of the segment |
/// |---|---|
/// | `Step` | `a` until the next key |
/// | `Linear` | `a + (b − a) u` |
/// | `EaseInOut` | `a + (b − a)(3u² − 2u³)`: starts and stops at rest |
/// | `CatmullRom` (the default) | a time-parameterised Catmull-Rom spline through every key, its tangents from the neighbouring keys (reflected past the ends) |
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Interpolation {
    /// Holds the key's value until the next key.
    Step,
    /// A straight line to the next key's value.
    Linear,
    /// Smoothstep: leaves and arrives with zero speed.
    EaseInOut,
    /// A smooth spline through every key (the default).
    #[default]
    CatmullRom,
}

/// The camera at a time, in seconds: its position and target, and, where
/// every keyframe of a path gives them, its field of view, focus distance,
/// aperture and roll.
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
    /// How the path moves from this keyframe to the next.
    #[serde(default)]
    pub interpolation: Interpolation,
    /// Vertical field of view in degrees, in (0, 180) (perspective).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fov_y_degrees: Option<f64>,
    /// The distance in focus, > 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focus_distance: Option<f64>,
    /// The lens radius, >= 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aperture: Option<f64>,
    /// The camera's turn about its view, in degrees: positive rolls the
    /// camera clockwise as seen from behind it (its up towards its right),
    /// so the picture turns counter-clockwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roll_degrees: Option<f64>,
}

impl Keyframe {
    /// A keyframe at `time` seconds, joined to the next by a Catmull-Rom
    /// spline.
    #[must_use]
    pub fn new(time: f64, position: DVec3, target: DVec3) -> Self {
        Keyframe {
            time,
            position: position.to_array(),
            target: target.to_array(),
            interpolation: Interpolation::CatmullRom,
            fov_y_degrees: None,
            focus_distance: None,
            aperture: None,
            roll_degrees: None,
        }
    }

    /// Sets how the path moves from this keyframe to the next.
    #[must_use]
    pub fn interpolation(mut self, interpolation: Interpolation) -> Self {
        self.interpolation = interpolation;
        self
    }

    /// Sets the vertical field of view, in degrees.
    #[must_use]
    pub fn fov(mut self, degrees: f64) -> Self {
        self.fov_y_degrees = Some(degrees);
        self
    }

    /// Sets the distance in focus.
    #[must_use]
    pub fn focus(mut self, distance: f64) -> Self {
        self.focus_distance = Some(distance);
        self
    }

    /// Sets the lens radius.
    #[must_use]
    pub fn aperture(mut self, radius: f64) -> Self {
        self.aperture = Some(radius);
        self
    }

    /// Sets the roll, in degrees.
    #[must_use]
    pub fn roll(mut self, degrees: f64) -> Self {
        self.roll_degrees = Some(degrees);
        self
    }

    /// The optional tracks: each field's name and value.
    fn optional(&self) -> [(&'static str, Option<f64>); 4] {
        [
            ("fov_y_degrees", self.fov_y_degrees),
            ("focus_distance", self.focus_distance),
            ("aperture", self.aperture),
            ("roll_degrees", self.roll_degrees),
        ]
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
            let finite = k.time.is_finite()
                && k.position.iter().chain(&k.target).all(|v| v.is_finite())
                && k.optional()
                    .iter()
                    .all(|(_, v)| v.is_none_or(f64::is_finite));
            if !finite {
                return bad(format!("keyframe {i} has a non-finite value"));
            }
            if i > 0 && k.time <= keyframes[i - 1].time {
                return bad(format!("keyframe {i}: times must strictly increase"));
            }
            for (field, value) in k.optional() {
                if value.is_some()
                    != keyframes[0]
                        .optional()
                        .iter()
                        .any(|(f, v)| *f == field && v.is_some())
                {
                    return bad(format!(
                        "keyframe {i}: `{field}` must be on every keyframe or on none \
                         (keyframe 0 {} it)",
                        if value.is_some() { "lacks" } else { "has" }
                    ));
                }
                let Some(v) = value else { continue };
                let wrong = match field {
                    "fov_y_degrees" => !(v > 0.0 && v < 180.0),
                    "focus_distance" => v <= 0.0,
                    "aperture" => v < 0.0,
                    _ => false,
                };
                if wrong {
                    let expected = match field {
                        "fov_y_degrees" => "in (0, 180)",
                        "focus_distance" => "> 0",
                        _ => ">= 0",
                    };
                    return bad(format!(
                        "keyframe {i}: `{field}` must be {expected}, got {}",
                        fmt_value(v)
                    ));
                }
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
        (
            self.track(time, |k| Some(DVec3::from(k.position))),
            self.track(time, |k| Some(DVec3::from(k.target))),
        )
    }

    /// One track of the keyframes (`None` where they do not have it) at
    /// `time`.
    fn track(&self, time: f64, value: impl Fn(&Keyframe) -> Option<DVec3>) -> DVec3 {
        interpolate(
            &self.keyframes,
            |k| k.time,
            |k| value(k).unwrap_or(DVec3::ZERO),
            |k| k.interpolation,
            time,
        )
    }

    /// `base` moved to the path at `time`: its position and target, and
    /// its field of view (of a perspective camera), focus distance,
    /// aperture and roll where the keyframes give them. `base` gives the
    /// up direction and the rest.
    ///
    /// ```
    /// use fractal_sdf::animation::{CameraPath, Interpolation, Keyframe};
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::scene::Projection;
    ///
    /// let path = CameraPath::new(vec![
    ///     Keyframe::new(0.0, dvec3(0.0, 0.0, 4.0), DVec3::ZERO)
    ///         .interpolation(Interpolation::Linear)
    ///         .fov(30.0),
    ///     Keyframe::new(2.0, dvec3(0.0, 0.0, 2.0), DVec3::ZERO).fov(60.0),
    /// ])?;
    /// let camera = path.camera_at(0.5, &Camera::default());
    /// assert_eq!(camera.position, dvec3(0.0, 0.0, 3.5));
    /// assert_eq!(camera.projection, Projection::Perspective { fov_y_degrees: 37.5 });
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    #[must_use]
    pub fn camera_at(&self, time: f64, base: &Camera) -> Camera {
        let (position, target) = self.sample(time);
        let first = &self.keyframes[0];
        let scalar = |get: fn(&Keyframe) -> Option<f64>| {
            get(first).map(|_| self.track(time, |k| get(k).map(DVec3::splat)).x)
        };
        let mut camera = Camera {
            position,
            target,
            ..*base
        };
        if let (Some(fov), Projection::Perspective { .. }) =
            (scalar(|k| k.fov_y_degrees), camera.projection)
        {
            // A spline may overshoot between keys: kept inside (0, 180).
            camera.projection = Projection::Perspective {
                fov_y_degrees: fov.clamp(1e-3, 179.999),
            };
        }
        if let Some(focus) = scalar(|k| k.focus_distance) {
            camera.focus_distance = Some(focus.max(f64::MIN_POSITIVE));
        }
        if let Some(aperture) = scalar(|k| k.aperture) {
            camera.aperture = aperture.max(0.0);
        }
        if let Some(roll) = scalar(|k| k.roll_degrees) {
            let view = (target - position).normalize_or_zero();
            if view != DVec3::ZERO {
                camera.up = DQuat::from_axis_angle(view, roll.to_radians()) * base.up;
            }
        }
        camera
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

/// The track through `keys` at `t` (clamped to their times; the first
/// key's value for a NaN): each segment shaped by the interpolation of the
/// key it starts at. Times strictly increase.
fn interpolate<K>(
    keys: &[K],
    time: impl Fn(&K) -> f64,
    value: impl Fn(&K) -> DVec3,
    mode: impl Fn(&K) -> Interpolation,
    t: f64,
) -> DVec3 {
    let last = keys.len() - 1;
    if last == 0 || t.is_nan() {
        return value(&keys[0]);
    }
    let t = t.clamp(time(&keys[0]), time(&keys[last]));
    // The segment keys[i]..keys[i + 1] holding t: the first whose end is
    // at or after t (times increase, so a binary search).
    let i = keys[1..].partition_point(|k| time(k) < t).min(last - 1);
    let get = |j: usize| (time(&keys[j]), value(&keys[j]));
    let ((t1, p1), (t2, p2)) = (get(i), get(i + 1));
    let u = (t - t1) / (t2 - t1);
    match mode(&keys[i]) {
        Interpolation::Step => {
            if u >= 1.0 {
                p2
            } else {
                p1
            }
        }
        Interpolation::Linear => p1 + (p2 - p1) * u,
        Interpolation::EaseInOut => p1 + (p2 - p1) * (u * u * (3.0 - 2.0 * u)),
        Interpolation::CatmullRom => {
            // Neighbours beyond the ends are reflected (2 p_end - p_inner),
            // so the track leaves and enters its ends in a straight line.
            let before = match i.checked_sub(1) {
                Some(j) => get(j),
                None => (2.0 * t1 - t2, 2.0 * p1 - p2),
            };
            let after = if i + 2 <= last {
                get(i + 2)
            } else {
                (2.0 * t2 - t1, 2.0 * p2 - p1)
            };
            catmull_rom(before, (t1, p1), (t2, p2), after, t)
        }
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

/// One key of a parameter's track ([`Motion::Keys`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub struct Key {
    /// Time in seconds.
    pub time: f64,
    /// The parameter's value at that time.
    pub value: f64,
    /// How the track moves from this key to the next.
    #[serde(default)]
    pub interpolation: Interpolation,
}

impl Key {
    /// The value `value` at `time` seconds, joined to the next key by a
    /// Catmull-Rom spline.
    #[must_use]
    pub fn new(time: f64, value: f64) -> Self {
        Key {
            time,
            value,
            interpolation: Interpolation::CatmullRom,
        }
    }

    /// Sets how the track moves from this key to the next.
    #[must_use]
    pub fn interpolation(mut self, interpolation: Interpolation) -> Self {
        self.interpolation = interpolation;
        self
    }
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
    /// `name` through keys at times in seconds, each key's
    /// [`Interpolation`] shaping the way to the next; before the first key
    /// the first value, after the last the last. A vector parameter's
    /// components are parameters of their own (`name.x`, ...).
    Keys {
        /// The dynamic parameter.
        name: String,
        /// At least one key, in strictly increasing time.
        keys: Vec<Key>,
    },
}

impl Motion {
    /// The dynamic parameter (or vector parameter) it moves.
    #[must_use]
    pub fn name(&self) -> &str {
        match self {
            Motion::Oscillate { name, .. }
            | Motion::Orbit { name, .. }
            | Motion::Keys { name, .. } => name,
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
            Motion::Keys { keys, .. } => return self.validate_keys(keys),
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

    /// A track's keys: at least one, at most
    /// [`CameraPath::MAX_KEYFRAMES`], finite, in strictly increasing time.
    fn validate_keys(&self, keys: &[Key]) -> Result<()> {
        let bad = |field, value, expected| {
            Err(Error::Motion {
                name: self.name().to_string(),
                field,
                value,
                expected,
            })
        };
        #[allow(clippy::cast_precision_loss)] // counts far below 2^52
        let count = keys.len() as f64;
        if keys.is_empty() || keys.len() > CameraPath::MAX_KEYFRAMES {
            return bad("keys", count, "between 1 and 1048576 keys");
        }
        for (i, k) in keys.iter().enumerate() {
            if !k.time.is_finite() {
                return bad("time", k.time, "finite");
            }
            if !k.value.is_finite() {
                return bad("value", k.value, "finite");
            }
            if i > 0 && k.time <= keys[i - 1].time {
                return bad("time", k.time, "later than the key before");
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
            Motion::Keys { name, keys } if !keys.is_empty() => {
                let at = interpolate(
                    keys,
                    |k| k.time,
                    |k| DVec3::splat(k.value),
                    |k| k.interpolation,
                    time,
                );
                vec![(name.clone(), at.x)]
            }
            Motion::Keys { .. } => Vec::new(),
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

    /// Each interpolation against values worked by hand, at and between
    /// keys, and clamped outside them.
    #[test]
    fn parameter_tracks_interpolate_as_their_keys_say() {
        let track = |keys: Vec<Key>| Motion::Keys {
            name: "k".into(),
            keys,
        };
        let at = |m: &Motion, t: f64| m.values(t)[0].1;
        use Interpolation::{EaseInOut, Linear, Step};
        let linear = track(vec![
            Key::new(0.0, 2.0).interpolation(Linear),
            Key::new(2.0, 6.0),
        ]);
        for (t, want) in [
            (-1.0, 2.0),
            (0.0, 2.0),
            (0.5, 3.0),
            (1.5, 5.0),
            (2.0, 6.0),
            (9.0, 6.0),
        ] {
            assert!((at(&linear, t) - want).abs() < 1e-12, "linear at {t}");
        }
        let step = track(vec![
            Key::new(0.0, 2.0).interpolation(Step),
            Key::new(1.0, 5.0).interpolation(Step),
            Key::new(3.0, 1.0),
        ]);
        for (t, want) in [(0.0, 2.0), (0.99, 2.0), (1.0, 5.0), (2.9, 5.0), (3.0, 1.0)] {
            assert_eq!(at(&step, t), want, "step at {t}");
        }
        // Smoothstep: u = 1/4 gives 3/16 - 2/64 = 0.15625 of the way.
        let ease = track(vec![
            Key::new(0.0, 0.0).interpolation(EaseInOut),
            Key::new(2.0, 10.0),
        ]);
        for (t, want) in [
            (0.0, 0.0),
            (0.5, 1.5625),
            (1.0, 5.0),
            (1.5, 8.4375),
            (2.0, 10.0),
        ] {
            assert!((at(&ease, t) - want).abs() < 1e-12, "ease at {t}");
        }
        // Catmull-Rom through 0, 1, 0 at unit spacing, the first key's
        // neighbour reflected to -1: the uniform spline's weights at u =
        // 1/2 give (2·0 + (1 + 1)/2 + (-2 + 4)/4 + (1 - 3)/8) / 2 = 0.625.
        let spline = track(vec![
            Key::new(0.0, 0.0),
            Key::new(1.0, 1.0),
            Key::new(2.0, 0.0),
        ]);
        for (t, want) in [
            (0.0, 0.0),
            (0.5, 0.625),
            (1.0, 1.0),
            (1.5, 0.625),
            (2.0, 0.0),
        ] {
            assert!((at(&spline, t) - want).abs() < 1e-12, "spline at {t}");
        }
        // One key holds its value; NaN time takes the first.
        assert_eq!(at(&track(vec![Key::new(3.0, 7.0)]), -5.0), 7.0);
        assert_eq!(at(&spline, f64::NAN), 0.0);
    }

    #[test]
    fn parameter_tracks_refuse_bad_keys_by_field() {
        let track = |keys: Vec<Key>| Motion::Keys {
            name: "power".into(),
            keys,
        };
        let err = |m: Motion| m.validate().unwrap_err().to_string();
        assert!(err(track(vec![])).contains("`keys` must be between 1 and 1048576 keys"));
        assert!(err(track(vec![Key::new(0.0, f64::NAN)])).contains("`value` must be finite"));
        let backwards = track(vec![Key::new(1.0, 0.0), Key::new(1.0, 2.0)]);
        assert!(err(backwards).contains("`time` must be later than the key before, got 1"));
        track(vec![Key::new(0.0, 1.0)]).validate().unwrap();
    }

    /// The camera's optional tracks: field of view, focus, aperture and
    /// roll between keys; a field on some keyframes only is refused.
    #[test]
    fn camera_keyframes_move_the_lens_and_roll() {
        let key = |t: f64, z: f64| {
            Keyframe::new(t, dvec3(0.0, 0.0, z), DVec3::ZERO).interpolation(Interpolation::Linear)
        };
        let path = CameraPath::new(vec![
            key(0.0, 4.0).fov(30.0).focus(4.0).aperture(0.0).roll(0.0),
            key(2.0, 2.0).fov(60.0).focus(2.0).aperture(0.2).roll(90.0),
        ])
        .unwrap();
        let camera = path.camera_at(1.0, &Camera::default());
        assert_eq!(camera.position, dvec3(0.0, 0.0, 3.0));
        assert_eq!(
            camera.projection,
            Projection::Perspective {
                fov_y_degrees: 45.0
            }
        );
        assert_eq!(camera.focus_distance, Some(3.0));
        assert!((camera.aperture - 0.1).abs() < 1e-15);
        // A 45° roll about the view (-z): up leans towards the right (+x).
        let s = 0.5f64.sqrt();
        assert!(
            (camera.up - dvec3(s, s, 0.0)).length() < 1e-12,
            "{}",
            camera.up
        );
        let (right, up, _) = path.camera_at(2.0, &Camera::default()).basis().unwrap();
        assert!((up - DVec3::X).length() < 1e-12 && (right - DVec3::NEG_Y).length() < 1e-12);

        let partly = CameraPath::new(vec![key(0.0, 4.0).fov(30.0), key(1.0, 3.0)]);
        let text = partly.unwrap_err().to_string();
        assert!(
            text.contains("`fov_y_degrees` must be on every keyframe or on none"),
            "{text}"
        );
        let wide = CameraPath::new(vec![key(0.0, 4.0).fov(30.0), key(1.0, 3.0).fov(180.0)]);
        assert!(
            wide.unwrap_err()
                .to_string()
                .contains("must be in (0, 180), got 180")
        );
        // Without optional fields, a path keeps the base camera's lens.
        let plain = CameraPath::new(vec![key(0.0, 4.0), key(1.0, 3.0)]).unwrap();
        let base = Camera::default().lens(0.05).fov(20.0);
        let moved = plain.camera_at(0.5, &base);
        assert_eq!((moved.aperture, moved.projection), (0.05, base.projection));
    }
}
