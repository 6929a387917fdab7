//! The fly-through camera ([`FlyCamera`]), the keys that move it
//! ([`Movement`]), and the keys that change what is drawn ([`Action`],
//! [`ViewSettings`]).

use std::f64::consts::{FRAC_PI_2, TAU};

use glam::{DVec3, dvec3};

use super::Key;
use crate::error::{Error, Result};
use crate::quality::{Effects, Glow, Preset, Quality};
use crate::scene::{Camera, StereoLayout};

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
    /// arrows. No [`Action`] may be bound to one.
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

/// What a key press asks for, other than movement. Each action has one
/// default key ([`Action::key`]) and a name ([`Action::name`]) by which a
/// settings file rebinds it ([`KeyBindings`]); the keys without one are
/// free for the window's own use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Action {
    /// `o`: ambient occlusion on or off.
    ToggleAmbientOcclusion,
    /// `h`: shadows on or off.
    ToggleShadows,
    /// `g`: glow on or off.
    ToggleGlow,
    /// `v`: stereo off, then each [`StereoLayout`] in turn.
    CycleStereo,
    /// `1`–`4`: draft, preview, production, reference quality.
    Quality(Preset),
    /// `space`: pause or resume the animated parameters.
    ToggleAnimation,
    /// `r`: back to the scene's own camera.
    ResetCamera,
    /// `f12`: save a screenshot.
    Screenshot,
    /// `escape`: quit.
    Quit,
}

impl Action {
    /// Every action, in the order a help text lists them.
    pub const ALL: [Action; 12] = [
        Action::ToggleAmbientOcclusion,
        Action::ToggleShadows,
        Action::ToggleGlow,
        Action::CycleStereo,
        Action::Quality(Preset::Draft),
        Action::Quality(Preset::Preview),
        Action::Quality(Preset::Production),
        Action::Quality(Preset::Reference),
        Action::ToggleAnimation,
        Action::ResetCamera,
        Action::Screenshot,
        Action::Quit,
    ];

    /// The key that asks for this action.
    #[must_use]
    pub fn key(self) -> Key {
        match self {
            Action::ToggleAmbientOcclusion => Key::O,
            Action::ToggleShadows => Key::H,
            Action::ToggleGlow => Key::G,
            Action::CycleStereo => Key::V,
            Action::Quality(Preset::Draft) => Key::Digit1,
            Action::Quality(Preset::Preview) => Key::Digit2,
            Action::Quality(Preset::Production) => Key::Digit3,
            Action::Quality(Preset::Reference) => Key::Digit4,
            Action::ToggleAnimation => Key::Space,
            Action::ResetCamera => Key::R,
            Action::Screenshot => Key::F12,
            Action::Quit => Key::Escape,
        }
    }

    /// The stable snake_case name of the action, by which settings files
    /// bind it to a key: `toggle_ambient_occlusion`, `toggle_shadows`,
    /// `toggle_glow`, `cycle_stereo`, `quality_draft`, `quality_preview`,
    /// `quality_production`, `quality_reference`, `toggle_animation`,
    /// `reset_camera`, `screenshot` and `quit`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Action::ToggleAmbientOcclusion => "toggle_ambient_occlusion",
            Action::ToggleShadows => "toggle_shadows",
            Action::ToggleGlow => "toggle_glow",
            Action::CycleStereo => "cycle_stereo",
            Action::Quality(Preset::Draft) => "quality_draft",
            Action::Quality(Preset::Preview) => "quality_preview",
            Action::Quality(Preset::Production) => "quality_production",
            Action::Quality(Preset::Reference) => "quality_reference",
            Action::ToggleAnimation => "toggle_animation",
            Action::ResetCamera => "reset_camera",
            Action::Screenshot => "screenshot",
            Action::Quit => "quit",
        }
    }

    /// The action called `name` (see [`Action::name`]; exact, lower case).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Action> {
        Self::ALL.into_iter().find(|a| a.name() == name)
    }

    /// The action's place in [`Action::ALL`].
    fn index(self) -> usize {
        Self::ALL
            .iter()
            .position(|&a| a == self)
            .expect("every action is in Action::ALL")
    }

    /// The action `key` asks for by default, if any (movement keys have
    /// none: see [`Movement::set`]); [`KeyBindings::action`] with rebound
    /// keys.
    #[must_use]
    pub fn for_key(key: Key) -> Option<Action> {
        Self::ALL.into_iter().find(|a| a.key() == key)
    }

    /// What the action does, for help texts, such as `toggle glow`.
    #[must_use]
    pub fn description(self) -> &'static str {
        match self {
            Action::ToggleAmbientOcclusion => "toggle ambient occlusion",
            Action::ToggleShadows => "toggle shadows",
            Action::ToggleGlow => "toggle glow",
            Action::CycleStereo => "stereo: off, anaglyph, side by side, over-under",
            Action::Quality(Preset::Draft) => "draft quality",
            Action::Quality(Preset::Preview) => "preview quality",
            Action::Quality(Preset::Production) => "production quality",
            Action::Quality(Preset::Reference) => "reference quality",
            Action::ToggleAnimation => "pause or resume the animation",
            Action::ResetCamera => "reset the camera",
            Action::Screenshot => "save a screenshot",
            Action::Quit => "quit",
        }
    }
}

/// Which key asks for each [`Action`]: the defaults ([`Action::key`]) with
/// some rebound, such as from a settings file's `[viewer.keys]` table
/// (action name to key name, see [`crate::settings`]).
///
/// Every action keeps exactly one key; no two actions share one, and none
/// is a movement key ([`Movement::KEYS`]).
///
/// ```
/// use fractal_sdf::view::{Action, Key, KeyBindings};
///
/// let keys = KeyBindings::from_names([("toggle_glow", "l"), ("screenshot", "p")])?;
/// assert_eq!(keys.key(Action::ToggleGlow), Key::L);
/// assert_eq!(keys.action(Key::P), Some(Action::Screenshot));
/// assert_eq!(keys.action(Key::G), None, "g is free now");
/// assert_eq!(keys.action(Key::O), Some(Action::ToggleAmbientOcclusion));
///
/// let err = KeyBindings::from_names([("quit", "w")]).unwrap_err();
/// assert!(err.to_string().contains("`w` moves the camera"), "{err}");
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyBindings {
    /// The key of each action, in the order of [`Action::ALL`].
    keys: [Key; Action::ALL.len()],
}

impl Default for KeyBindings {
    /// Every action on its [`Action::key`].
    fn default() -> Self {
        KeyBindings {
            keys: Action::ALL.map(Action::key),
        }
    }
}

fn bindings_error(reason: String) -> Error {
    Error::Invalid {
        what: "key bindings",
        reason,
    }
}

impl KeyBindings {
    /// The defaults with each `(action name, key name)` of `names` rebound
    /// (names as [`Action::name`] and [`Key`] write them; key names ignore
    /// case). Two actions may swap keys.
    ///
    /// # Errors
    /// [`Error::Invalid`] naming an unknown action or key, an action given
    /// twice, a movement key, or a key that two actions would share (one of
    /// them may be an action left on its default key).
    pub fn from_names<A, K>(names: impl IntoIterator<Item = (A, K)>) -> Result<Self>
    where
        A: AsRef<str>,
        K: AsRef<str>,
    {
        let mut bindings = KeyBindings::default();
        let mut given = [false; Action::ALL.len()];
        for (action, key) in names {
            let (action, key) = (action.as_ref(), key.as_ref());
            let Some(a) = Action::from_name(action) else {
                let names: Vec<&str> = Action::ALL.iter().map(|a| a.name()).collect();
                return Err(bindings_error(format!(
                    "unknown action `{action}` (actions: {})",
                    names.join(", ")
                )));
            };
            let k = key.parse::<Key>().map_err(|e| match e {
                Error::Invalid { reason, .. } => bindings_error(format!("`{action}`: {reason}")),
                other => other,
            })?;
            if std::mem::replace(&mut given[a.index()], true) {
                return Err(bindings_error(format!("`{action}` is bound twice")));
            }
            bindings.keys[a.index()] = k;
        }
        bindings.check()?;
        Ok(bindings)
    }

    /// Binds `action` to `key`.
    ///
    /// # Errors
    /// [`Error::Invalid`] if `key` is a movement key or another action's
    /// key (the bindings are then unchanged).
    pub fn bind(&mut self, action: Action, key: Key) -> Result<()> {
        let mut bound = self.clone();
        bound.keys[action.index()] = key;
        bound.check()?;
        *self = bound;
        Ok(())
    }

    /// No movement key, and no key twice.
    fn check(&self) -> Result<()> {
        for (i, (&action, &key)) in Action::ALL.iter().zip(&self.keys).enumerate() {
            if Movement::is_movement_key(key) {
                let keys: Vec<&str> = Movement::KEYS.iter().map(|k| k.name()).collect();
                return Err(bindings_error(format!(
                    "`{}`: `{key}` moves the camera (the movement keys are {})",
                    action.name(),
                    keys.join(", ")
                )));
            }
            if let Some(j) = self.keys[..i].iter().position(|&k| k == key) {
                return Err(bindings_error(format!(
                    "`{key}` is bound to both `{}` and `{}`",
                    Action::ALL[j].name(),
                    action.name()
                )));
            }
        }
        Ok(())
    }

    /// The key bound to `action`.
    #[must_use]
    pub fn key(&self, action: Action) -> Key {
        self.keys[action.index()]
    }

    /// The action bound to `key`, if any.
    #[must_use]
    pub fn action(&self, key: Key) -> Option<Action> {
        self.keys
            .iter()
            .position(|&k| k == key)
            .map(|i| Action::ALL[i])
    }

    /// Every action with its key, in the order of [`Action::ALL`].
    pub fn iter(&self) -> impl Iterator<Item = (Action, Key)> + '_ {
        Action::ALL.into_iter().zip(self.keys.iter().copied())
    }
}

/// The quality preset and effect switches of an interactive view.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct ViewSettings {
    /// The quality preset.
    pub preset: Preset,
    /// A quality that is no preset (a scene file's), used instead of
    /// `preset` until a quality action picks a preset.
    pub custom_quality: Option<Quality>,
    /// Ambient occlusion on (the draft preset has no AO samples, so it
    /// shows none either way).
    pub ambient_occlusion: bool,
    /// Shadows on (none in the draft preset).
    pub shadows: bool,
    /// Glow on.
    pub glow: bool,
    /// The glow used when it is on.
    pub glow_style: Glow,
    /// Everything else about the effects (background, fog, gamma).
    pub base: Effects,
    /// The stereo layout, or `None` for one eye.
    pub stereo: Option<StereoLayout>,
}

impl Default for ViewSettings {
    /// Preview quality, AO and shadows on, a soft blue glow off.
    fn default() -> Self {
        ViewSettings {
            preset: Preset::Preview,
            custom_quality: None,
            ambient_occlusion: true,
            shadows: true,
            glow: false,
            glow_style: Glow {
                color: dvec3(0.6, 0.75, 1.0),
                strength: 0.8,
            },
            base: Effects::default(),
            stereo: None,
        }
    }
}

impl ViewSettings {
    /// The quality to render with: the custom one if set, else the
    /// preset's.
    #[must_use]
    pub fn quality(&self) -> Quality {
        self.custom_quality.unwrap_or_else(|| self.preset.quality())
    }

    /// Renders with `quality` from now on: its preset if it is one, else as
    /// [`ViewSettings::custom_quality`].
    pub fn take_quality(&mut self, quality: Quality) {
        match Preset::ALL.into_iter().find(|p| p.quality() == quality) {
            Some(preset) => {
                self.preset = preset;
                self.custom_quality = None;
            }
            None => self.custom_quality = Some(quality),
        }
    }

    /// Renders with `effects` from now on: its switches become the
    /// switches, its glow (if any) the glow style, and the rest the base.
    pub fn take_effects(&mut self, effects: Effects) {
        self.ambient_occlusion = effects.ambient_occlusion;
        self.shadows = effects.shadows;
        self.glow = effects.glow.is_some();
        if let Some(glow) = effects.glow {
            self.glow_style = glow;
        }
        self.base = effects;
    }

    /// The effects to render with.
    #[must_use]
    pub fn effects(&self) -> Effects {
        Effects {
            ambient_occlusion: self.ambient_occlusion,
            shadows: self.shadows,
            glow: self.glow.then_some(self.glow_style),
            ..self.base
        }
    }

    /// Applies an action; returns whether the settings changed (a new
    /// quality or new effects mean a new program; stereo does not).
    pub fn apply(&mut self, action: Action) -> bool {
        let before = *self;
        match action {
            Action::ToggleAmbientOcclusion => self.ambient_occlusion ^= true,
            Action::ToggleShadows => self.shadows ^= true,
            Action::ToggleGlow => self.glow ^= true,
            Action::CycleStereo => {
                let all = StereoLayout::ALL;
                self.stereo = match self.stereo {
                    None => Some(all[0]),
                    Some(layout) => {
                        let i = all.iter().position(|&l| l == layout).expect("a layout");
                        all.get(i + 1).copied()
                    }
                };
            }
            Action::Quality(p) => {
                self.preset = p;
                self.custom_quality = None;
            }
            _ => {}
        }
        *self != before
    }

    /// A short description, such as `preview, AO, shadows, glow,
    /// anaglyph` (`custom` for a custom quality).
    #[must_use]
    pub fn summary(&self) -> String {
        let quality = if self.custom_quality.is_some() {
            "custom"
        } else {
            self.preset.name()
        };
        let mut parts = vec![quality];
        for (on, name) in [
            (self.ambient_occlusion, "AO"),
            (self.shadows, "shadows"),
            (self.glow, "glow"),
        ] {
            if on {
                parts.push(name);
            }
        }
        parts.extend(self.stereo.map(StereoLayout::name));
        parts.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
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
