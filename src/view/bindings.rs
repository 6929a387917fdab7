//! What each key does: the actions ([`Action`]) and the table that binds
//! keys to them ([`KeyBindings`]).

use super::Key;
use super::control::Movement;
use crate::error::{Error, Result};
use crate::quality::Preset;

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
    /// `v`: stereo off, then each [`StereoLayout`](crate::scene::StereoLayout) in turn.
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
