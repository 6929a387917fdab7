//! The fly-through camera ([`FlyCamera`]) and the keys that move it
//! ([`Movement`]).

use std::f64::consts::{FRAC_PI_2, TAU};

use glam::{DVec3, dvec3};

use super::Key;
use crate::scene::Camera;

/// A first-person camera: a position, a heading (`yaw`) and an elevation
/// (`pitch`), moved by keys at `speed` units per second and turned by mouse
/// motion at `sensitivity` radians per pixel.
///
/// Yaw 0 looks down −z; positive yaw turns right. Pitch is kept inside
/// ±[`FlyCamera::MAX_PITCH`] so the view never flips over the pole.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct FlyCamera {
    /// Where the camera is.
    pub position: DVec3,
    /// Heading in radians, in `[0, 2π)`.
    pub yaw: f64,
    /// Elevation in radians; positive looks up.
    pub pitch: f64,
    /// Movement speed in scene units per second.
    pub speed: f64,
    /// Radians turned per pixel of mouse motion.
    pub sensitivity: f64,
}

impl FlyCamera {
    /// The steepest pitch, just short of straight up or down (89°).
    pub const MAX_PITCH: f64 = FRAC_PI_2 * (89.0 / 90.0);
    /// The slowest speed [`FlyCamera::change_speed`] allows.
    pub const MIN_SPEED: f64 = 1e-4;
    /// The fastest speed [`FlyCamera::change_speed`] allows.
    pub const MAX_SPEED: f64 = 1e4;
    /// The default mouse sensitivity: 0.004 radians per pixel.
    pub const DEFAULT_SENSITIVITY: f64 = 0.004;

    /// A camera at `position` looking along `direction` (any non-zero
    /// vector), moving at 1 unit per second.
    #[must_use]
    pub fn new(position: DVec3, direction: DVec3) -> Self {
        let d = direction.try_normalize().unwrap_or(DVec3::NEG_Z);
        let pitch = d.y.clamp(-1.0, 1.0).asin();
        let yaw = d.x.atan2(-d.z).rem_euclid(TAU);
        FlyCamera {
            position,
            yaw,
            pitch: pitch.clamp(-Self::MAX_PITCH, Self::MAX_PITCH),
            speed: 1.0,
            sensitivity: Self::DEFAULT_SENSITIVITY,
        }
    }

    /// Takes over a scene camera's position and view direction; the speed
    /// crosses the distance to its target in about three seconds.
    #[must_use]
    pub fn from_camera(camera: &Camera) -> Self {
        let to_target = camera.target - camera.position;
        FlyCamera {
            speed: (to_target.length() / 3.0).clamp(Self::MIN_SPEED, Self::MAX_SPEED),
            ..Self::new(camera.position, to_target)
        }
    }

    /// The unit view direction.
    #[must_use]
    pub fn forward(&self) -> DVec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        dvec3(cp * sy, sp, -cp * cy)
    }

    /// The unit direction to the right of the view, level with the ground.
    #[must_use]
    pub fn right(&self) -> DVec3 {
        let (sy, cy) = self.yaw.sin_cos();
        dvec3(cy, 0.0, sy)
    }

    /// Turns by a mouse motion of `dx`, `dy` pixels (right and down are
    /// positive, as window systems report them).
    pub fn look(&mut self, dx: f64, dy: f64) {
        if !(dx.is_finite() && dy.is_finite()) {
            return;
        }
        self.yaw = (self.yaw + dx * self.sensitivity).rem_euclid(TAU);
        self.pitch = (self.pitch - dy * self.sensitivity).clamp(-Self::MAX_PITCH, Self::MAX_PITCH);
    }

    /// Multiplies the speed by 1.25 per step (negative steps slow down),
    /// within [`FlyCamera::MIN_SPEED`]..=[`FlyCamera::MAX_SPEED`].
    pub fn change_speed(&mut self, steps: f64) {
        if steps.is_finite() {
            self.speed = (self.speed * 1.25f64.powf(steps)).clamp(Self::MIN_SPEED, Self::MAX_SPEED);
        }
    }

    /// Moves for `dt` seconds with the keys held in `keys`; returns whether
    /// the camera moved. Diagonal movement is as fast as straight movement.
    pub fn advance(&mut self, keys: Movement, dt: f64) -> bool {
        let [right, up, forward] = keys.axes();
        let step = self.right() * right + DVec3::Y * up + self.forward() * forward;
        let Some(direction) = step.try_normalize() else {
            return false;
        };
        if !(dt.is_finite() && dt > 0.0) {
            return false;
        }
        self.position += direction * self.speed * dt;
        true
    }

    /// `base` (for its projection) moved to this camera's position and
    /// view, with y up.
    #[must_use]
    pub fn camera(&self, base: &Camera) -> Camera {
        Camera {
            position: self.position,
            target: self.position + self.forward(),
            up: DVec3::Y,
            ..*base
        }
    }
}

/// Which movement keys are held: W/S (or the up and down arrows) forward
/// and back, A/D (or the left and right arrows) left and right, E/Q up and
/// down.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct Movement {
    /// W or the up arrow.
    pub forward: bool,
    /// S or the down arrow.
    pub back: bool,
    /// A or the left arrow.
    pub left: bool,
    /// D or the right arrow.
    pub right: bool,
    /// E.
    pub up: bool,
    /// Q.
    pub down: bool,
}

impl Movement {
    /// Records a press (`pressed`) or release of `key`; returns whether it
    /// is a movement key.
    pub fn set(&mut self, key: Key, pressed: bool) -> bool {
        let held = match key {
            Key::W | Key::ArrowUp => &mut self.forward,
            Key::S | Key::ArrowDown => &mut self.back,
            Key::A | Key::ArrowLeft => &mut self.left,
            Key::D | Key::ArrowRight => &mut self.right,
            Key::E => &mut self.up,
            Key::Q => &mut self.down,
            _ => return false,
        };
        *held = pressed;
        true
    }

    /// The keys that move the camera: `w`, `a`, `s`, `d`, `e`, `q` and the
    /// arrows. No [`Action`](super::Action) may be bound to one.
    pub const KEYS: [Key; 10] = [
        Key::W,
        Key::A,
        Key::S,
        Key::D,
        Key::E,
        Key::Q,
        Key::ArrowUp,
        Key::ArrowDown,
        Key::ArrowLeft,
        Key::ArrowRight,
    ];

    /// Whether `key` moves the camera (one of [`Movement::KEYS`]).
    #[must_use]
    pub fn is_movement_key(key: Key) -> bool {
        Movement::default().set(key, true)
    }

    /// `[right, up, forward]`, each −1, 0 or 1 (opposite keys cancel).
    #[must_use]
    pub fn axes(&self) -> [f64; 3] {
        let axis = |plus: bool, minus: bool| f64::from(i8::from(plus) - i8::from(minus));
        [
            axis(self.right, self.left),
            axis(self.up, self.down),
            axis(self.forward, self.back),
        ]
    }

    /// Whether the held keys move the camera.
    #[must_use]
    pub fn is_moving(&self) -> bool {
        self.axes() != [0.0; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::{Effects, Glow, Preset, Quality};
    use crate::view::{Action, KeyBindings, ViewSettings};
    use approx::assert_relative_eq;

    fn close(a: DVec3, b: DVec3) {
        assert!(a.abs_diff_eq(b, 1e-12), "{a} != {b}");
    }

    fn held(keys: &[Key]) -> Movement {
        let mut m = Movement::default();
        for &k in keys {
            assert!(m.set(k, true), "{k} is a movement key");
        }
        m
    }

    #[test]
    fn direction_round_trips_through_yaw_and_pitch() {
        for d in [
            dvec3(0.0, 0.0, -1.0),
            dvec3(1.0, 0.0, 0.0),
            dvec3(-2.0, 1.0, 3.0),
            dvec3(0.3, -0.8, -0.1),
        ] {
            let fly = FlyCamera::new(DVec3::ZERO, d);
            close(fly.forward(), d.normalize());
            assert!(fly.right().dot(fly.forward()).abs() < 1e-12);
            assert_relative_eq!(fly.right().length(), 1.0, epsilon = 1e-12);
        }
        // Straight up is clamped just short of the pole.
        let up = FlyCamera::new(DVec3::ZERO, DVec3::Y);
        assert_relative_eq!(up.pitch, FlyCamera::MAX_PITCH);
        // A zero direction falls back to -z.
        close(
            FlyCamera::new(DVec3::ZERO, DVec3::ZERO).forward(),
            DVec3::NEG_Z,
        );
    }

    #[test]
    fn wasd_moves_relative_to_the_view_at_speed() {
        // Looking down +x: forward is +x, right is +z.
        let mut fly = FlyCamera::new(DVec3::ZERO, DVec3::X);
        fly.speed = 4.0;
        assert!(fly.advance(held(&[Key::W]), 0.5));
        close(fly.position, dvec3(2.0, 0.0, 0.0));
        fly.advance(held(&[Key::D]), 0.25);
        close(fly.position, dvec3(2.0, 0.0, 1.0));
        fly.advance(held(&[Key::E]), 0.25);
        assert_relative_eq!(fly.position.y, 1.0, epsilon = 1e-12);
        fly.advance(held(&[Key::Q, Key::S]), 0.25);
        let diagonal = dvec3(-1.0, -1.0, 0.0).normalize();
        close(fly.position, dvec3(2.0, 1.0, 1.0) + diagonal);
        // Opposite keys cancel; nothing held or no time moves nothing.
        let before = fly.position;
        assert!(!fly.advance(held(&[Key::A, Key::D]), 1.0));
        assert!(!fly.advance(Movement::default(), 1.0));
        assert!(!fly.advance(held(&[Key::W]), 0.0));
        assert!(!fly.advance(held(&[Key::W]), f64::NAN));
        assert_eq!(fly.position, before);
    }

    #[test]
    fn releasing_a_key_stops_it() {
        let mut m = held(&[Key::W, Key::ArrowLeft]);
        assert_eq!(m.axes(), [-1.0, 0.0, 1.0]);
        m.set(Key::W, false);
        m.set(Key::ArrowLeft, false);
        assert!(!m.is_moving());
        assert!(!m.set(Key::G, true), "g is not a movement key");
    }

    #[test]
    fn mouse_turns_and_pitch_is_clamped() {
        let mut fly = FlyCamera::new(DVec3::ZERO, DVec3::NEG_Z);
        fly.sensitivity = 0.01;
        fly.look(50.0, 0.0); // right by 0.5 rad
        assert_relative_eq!(fly.yaw, 0.5, epsilon = 1e-12);
        assert!(fly.forward().x > 0.0, "turned right");
        fly.look(0.0, -10.0); // mouse up: look up 0.1 rad
        assert_relative_eq!(fly.pitch, 0.1, epsilon = 1e-12);
        fly.look(0.0, -1e6);
        assert_relative_eq!(fly.pitch, FlyCamera::MAX_PITCH);
        fly.look(-1e3, 1e6);
        assert_relative_eq!(fly.pitch, -FlyCamera::MAX_PITCH);
        assert!((0.0..TAU).contains(&fly.yaw));
        let before = fly;
        fly.look(f64::NAN, 1.0);
        assert_eq!(fly, before);
    }

    #[test]
    fn scrolling_scales_speed_within_bounds() {
        let mut fly = FlyCamera::new(DVec3::ZERO, DVec3::X);
        fly.change_speed(2.0);
        assert_relative_eq!(fly.speed, 1.5625, epsilon = 1e-12);
        fly.change_speed(-2.0);
        assert_relative_eq!(fly.speed, 1.0, epsilon = 1e-12);
        fly.change_speed(1e6);
        assert_relative_eq!(fly.speed, FlyCamera::MAX_SPEED);
        fly.change_speed(-1e6);
        assert_relative_eq!(fly.speed, FlyCamera::MIN_SPEED);
    }

    #[test]
    fn from_camera_keeps_the_view_and_projection() {
        let base = Camera::look_at(dvec3(0.0, 3.0, 4.0), dvec3(0.0, 0.0, 0.0)).orthographic(2.0);
        let fly = FlyCamera::from_camera(&base);
        assert_relative_eq!(fly.speed, 5.0 / 3.0, epsilon = 1e-12);
        let cam = fly.camera(&base);
        assert_eq!(cam.position, base.position);
        assert_eq!(cam.projection, base.projection);
        let dir = (cam.target - cam.position).normalize();
        close(dir, dvec3(0.0, -0.6, -0.8));
        cam.validate().unwrap();
    }

    #[test]
    fn actions_change_settings_and_report_it() {
        let mut s = ViewSettings::default();
        assert_eq!(s.summary(), "preview, AO, shadows");
        assert!(s.effects().glow.is_none());
        assert!(s.apply(Action::ToggleGlow));
        assert_eq!(s.effects().glow, Some(s.glow_style));
        assert!(s.apply(Action::ToggleAmbientOcclusion));
        assert!(s.apply(Action::ToggleShadows));
        assert!(!s.effects().ambient_occlusion && !s.effects().shadows);
        assert!(s.apply(Action::Quality(Preset::Production)));
        assert_eq!(s.quality(), Quality::production());
        assert!(!s.apply(Action::Quality(Preset::Production)), "no change");
        assert!(!s.apply(Action::Screenshot));
        assert_eq!(s.summary(), "production, glow");
        // Stereo cycles through every layout and back to one eye.
        for layout in ["anaglyph", "side-by-side", "over-under"] {
            assert!(s.apply(Action::CycleStereo));
            assert_eq!(s.summary(), format!("production, glow, {layout}"));
        }
        assert!(s.apply(Action::CycleStereo));
        assert_eq!(s.stereo, None);
    }

    #[test]
    fn each_action_has_its_own_key_and_no_movement_key_has_one() {
        for action in Action::ALL {
            assert_eq!(Action::for_key(action.key()), Some(action));
            assert!(!Movement::default().set(action.key(), true), "{action:?}");
        }
        let mut keys: Vec<Key> = Action::ALL.iter().map(|a| a.key()).collect();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), Action::ALL.len());
        for (key, preset) in [Key::Digit1, Key::Digit2, Key::Digit3, Key::Digit4]
            .into_iter()
            .zip(Preset::ALL)
        {
            assert_eq!(Action::for_key(key), Some(Action::Quality(preset)));
        }
        for key in [Key::W, Key::ArrowUp, Key::Z, Key::Digit5] {
            assert_eq!(Action::for_key(key), None);
        }
    }

    #[test]
    fn action_names_are_unique_snake_case_and_round_trip() {
        let mut names: Vec<&str> = Action::ALL.iter().map(|a| a.name()).collect();
        for action in Action::ALL {
            assert_eq!(Action::from_name(action.name()), Some(action));
            assert!(
                action
                    .name()
                    .chars()
                    .all(|c| c.is_ascii_lowercase() || c == '_'),
                "{}",
                action.name()
            );
        }
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Action::ALL.len());
        assert_eq!(
            Action::ToggleAmbientOcclusion.name(),
            "toggle_ambient_occlusion"
        );
        assert_eq!(
            Action::Quality(Preset::Reference).name(),
            "quality_reference"
        );
        assert_eq!(Action::from_name("Quit"), None);
        assert_eq!(Action::from_name("toggle glow"), None);
    }

    #[test]
    fn default_bindings_are_the_action_keys() {
        let keys = KeyBindings::default();
        for action in Action::ALL {
            assert_eq!(keys.key(action), action.key());
            assert_eq!(keys.action(action.key()), Some(action));
        }
        for key in Key::ALL.iter().copied() {
            assert_eq!(keys.action(key), Action::for_key(key), "{key}");
        }
        assert_eq!(KeyBindings::from_names::<&str, &str>([]).unwrap(), keys);
        assert_eq!(keys.iter().count(), Action::ALL.len());
    }

    #[test]
    fn rebinding_moves_an_action_and_frees_its_old_key() {
        let keys = KeyBindings::from_names([("quit", "X"), ("quality_draft", "f1")]).unwrap();
        assert_eq!(keys.key(Action::Quit), Key::X);
        assert_eq!(keys.action(Key::X), Some(Action::Quit));
        assert_eq!(keys.action(Key::Escape), None);
        assert_eq!(keys.action(Key::F1), Some(Action::Quality(Preset::Draft)));
        assert_eq!(keys.action(Key::Digit1), None);
        // Untouched actions keep their keys.
        assert_eq!(keys.key(Action::ToggleGlow), Key::G);
        // Two actions may swap keys.
        let swapped =
            KeyBindings::from_names([("toggle_glow", "o"), ("toggle_ambient_occlusion", "g")])
                .unwrap();
        assert_eq!(swapped.action(Key::O), Some(Action::ToggleGlow));
        assert_eq!(swapped.action(Key::G), Some(Action::ToggleAmbientOcclusion));
        // From a settings map.
        let mut map = std::collections::BTreeMap::new();
        map.insert("screenshot".to_string(), "p".to_string());
        let keys = KeyBindings::from_names(&map).unwrap();
        assert_eq!(keys.action(Key::P), Some(Action::Screenshot));
    }

    #[test]
    fn bad_bindings_say_what_is_wrong() {
        let err = |names: &[(&str, &str)]| {
            KeyBindings::from_names(names.iter().copied())
                .unwrap_err()
                .to_string()
        };
        let e = err(&[("toggle_glowing", "l")]);
        assert!(
            e.contains("key bindings: unknown action `toggle_glowing`"),
            "{e}"
        );
        assert!(
            e.contains("toggle_ambient_occlusion, toggle_shadows"),
            "{e}"
        );
        let e = err(&[("toggle_glow", "hyper")]);
        assert!(e.contains("`toggle_glow`: unknown key `hyper`"), "{e}");
        // Movement keys, including `q` (down).
        for key in ["q", "w", "arrowleft", "E"] {
            let e = err(&[("quit", key)]);
            assert!(e.contains("moves the camera"), "{key}: {e}");
            assert!(e.contains("`quit`"), "{key}: {e}");
        }
        // A key taken by an action left on its default.
        let e = err(&[("toggle_glow", "o")]);
        assert!(
            e.contains("`o` is bound to both `toggle_ambient_occlusion` and `toggle_glow`"),
            "{e}"
        );
        // Two rebound actions on one key.
        let e = err(&[("quit", "x"), ("screenshot", "x")]);
        assert!(
            e.contains("`x` is bound to both `screenshot` and `quit`"),
            "{e}"
        );
        let e = err(&[("quit", "x"), ("quit", "z")]);
        assert!(e.contains("`quit` is bound twice"), "{e}");
    }

    #[test]
    fn bind_checks_and_leaves_bad_bindings_unchanged() {
        let mut keys = KeyBindings::default();
        keys.bind(Action::Screenshot, Key::P).unwrap();
        assert_eq!(keys.action(Key::P), Some(Action::Screenshot));
        let before = keys.clone();
        assert!(keys.bind(Action::Quit, Key::P).is_err());
        assert!(keys.bind(Action::Quit, Key::ArrowUp).is_err());
        assert_eq!(keys, before);
        for key in Movement::KEYS {
            assert!(Movement::is_movement_key(key), "{key}");
        }
        let moving = Key::ALL
            .iter()
            .filter(|&&k| Movement::is_movement_key(k))
            .count();
        assert_eq!(moving, Movement::KEYS.len());
    }

    #[test]
    fn a_custom_quality_holds_until_a_preset_is_picked() {
        let mut s = ViewSettings::default();
        s.take_quality(Quality::draft());
        assert_eq!((s.preset, s.custom_quality), (Preset::Draft, None));
        let custom = Quality::production().supersampling(2);
        s.take_quality(custom);
        assert_eq!(s.quality(), custom);
        assert_eq!(s.summary(), "custom, AO, shadows");
        assert!(s.apply(Action::Quality(Preset::Draft)));
        assert_eq!(s.quality(), Quality::draft());
        assert_eq!(s.custom_quality, None);
        // Picking the preset the custom quality was based on still
        // changes it.
        s.take_quality(Quality::draft().supersampling(2));
        assert!(s.apply(Action::Quality(Preset::Draft)));
    }

    #[test]
    fn taken_effects_become_the_switches() {
        let glow = Glow::new(dvec3(1.0, 0.0, 0.0), 0.3);
        let effects = Effects::default()
            .ambient_occlusion(false)
            .glow(glow)
            .gamma(1.8);
        let mut s = ViewSettings::default();
        s.take_effects(effects);
        assert_eq!(s.effects(), effects);
        assert!(s.glow && !s.ambient_occlusion && s.shadows);
        assert!(s.apply(Action::ToggleGlow));
        assert_eq!(s.effects().glow, None);
        assert!(s.apply(Action::ToggleGlow));
        assert_eq!(s.effects().glow, Some(glow), "the file's glow style");
        s.take_effects(Effects::default());
        assert_eq!(s.effects(), Effects::default());
    }
}
