//! [`KeyScript`]: key presses scheduled by frame number.

use std::fmt;
use std::str::FromStr;

use super::{Key, KeyBindings};
use crate::error::{Error, Result};

/// Key presses scheduled by frame number, for unattended runs.
///
/// In text, a script is a comma-separated list of `KEY` or `KEY@FRAME`,
/// with keys named as in [`Key`]: `"g,3"` presses `g` before frame 1 and
/// `3` before frame 2; `"g@5,3@5"` presses both before frame 5. A key
/// without `@FRAME` comes one frame after the previous key (the first at
/// frame 1, so frame 0 shows the start). Only keys with an [`Action`](super::Action) can
/// be scripted (by default, or in the [`KeyBindings`] given to
/// [`KeyScript::parse_with`]): a movement key is held, not pressed.
///
/// ```
/// use fractal_sdf::view::{Action, Key, KeyScript};
///
/// let script: KeyScript = "g, 3@4, o".parse()?;
/// assert_eq!(script.keys_at(1).collect::<Vec<_>>(), [Key::G]);
/// assert_eq!(Action::for_key(Key::G), Some(Action::ToggleGlow));
/// assert_eq!(script.keys_at(4).count(), 1);
/// assert_eq!(script.last_frame(), Some(5));
/// // The same script, built from keys, and written back as text.
/// let built = KeyScript::new([(1, Key::G), (4, Key::Digit3), (5, Key::O)])?;
/// assert_eq!(built, script);
/// assert_eq!(built.to_string(), "g@1, 3@4, o@5");
/// assert!(KeyScript::parse("z").is_err()); // `z` has no action
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct KeyScript {
    /// `(frame, key)`, sorted by frame (stable: script order within one).
    presses: Vec<(u64, Key)>,
}

fn invalid(reason: String) -> Error {
    Error::Invalid {
        what: "key script",
        reason,
    }
}

impl KeyScript {
    /// A script pressing each `key` before its `frame`.
    ///
    /// # Errors
    /// [`Error::Invalid`] naming a key that has no [`Action`](super::Action).
    pub fn new(presses: impl IntoIterator<Item = (u64, Key)>) -> Result<Self> {
        Self::new_with(presses, &KeyBindings::default())
    }

    /// A script pressing each `key` before its `frame`, with keys bound
    /// as in `bindings`.
    ///
    /// # Errors
    /// [`Error::Invalid`] naming a key that has no action in `bindings`.
    pub fn new_with(
        presses: impl IntoIterator<Item = (u64, Key)>,
        bindings: &KeyBindings,
    ) -> Result<Self> {
        let mut presses: Vec<(u64, Key)> = presses.into_iter().collect();
        if let Some((_, key)) = presses
            .iter()
            .find(|(_, key)| bindings.action(*key).is_none())
        {
            let keys: Vec<String> = bindings.iter().map(|(_, k)| k.to_string()).collect();
            return Err(invalid(format!(
                "`{key}` has no action (scriptable keys: {})",
                keys.join(", ")
            )));
        }
        presses.sort_by_key(|&(frame, _)| frame);
        Ok(KeyScript { presses })
    }

    /// Parses a script written as text (see [`KeyScript`]; spaces around
    /// items are ignored, and so is the case of key names).
    ///
    /// # Errors
    /// [`Error::Invalid`] naming an unknown key, a key without an action,
    /// a bad frame number (frames are `0..=u64::MAX`) or a key that would
    /// come after the last frame.
    pub fn parse(text: &str) -> Result<Self> {
        Self::parse_with(text, &KeyBindings::default())
    }

    /// Parses a script whose keys are bound as in `bindings`.
    ///
    /// # Errors
    /// As [`KeyScript::parse`], for a key without an action in `bindings`.
    pub fn parse_with(text: &str, bindings: &KeyBindings) -> Result<Self> {
        let mut presses = Vec::new();
        // The frame of a key without `@FRAME`; `None` after the last frame.
        let mut next = Some(1u64);
        for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (key, frame) = match item.split_once('@') {
                Some((key, frame)) => {
                    let frame = frame.trim().parse::<u64>().map_err(|_| {
                        invalid(format!(
                            "`{item}`: the frame must be a whole number from 0 to {}",
                            u64::MAX
                        ))
                    })?;
                    (key, frame)
                }
                None => (
                    item,
                    next.ok_or_else(|| {
                        invalid(format!(
                            "`{item}` would come after frame {}, the last one",
                            u64::MAX
                        ))
                    })?,
                ),
            };
            let key = key.parse::<Key>().map_err(|e| match e {
                Error::Invalid { reason, .. } => invalid(reason),
                other => other,
            })?;
            presses.push((frame, key));
            next = frame.checked_add(1);
        }
        Self::new_with(presses, bindings)
    }

    /// The keys pressed before frame `frame`, in script order. Each has an
    /// action in the bindings the script was made with.
    pub fn keys_at(&self, frame: u64) -> impl Iterator<Item = Key> + '_ {
        self.presses
            .iter()
            .filter(move |(f, _)| *f == frame)
            .map(|&(_, key)| key)
    }

    /// The frame of the last press, if any.
    #[must_use]
    pub fn last_frame(&self) -> Option<u64> {
        self.presses.last().map(|&(f, _)| f)
    }

    /// Whether the script presses nothing.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.presses.is_empty()
    }
}

impl FromStr for KeyScript {
    type Err = Error;

    /// [`KeyScript::parse`].
    fn from_str(text: &str) -> Result<Self> {
        Self::parse(text)
    }
}

impl fmt::Display for KeyScript {
    /// Every press as `KEY@FRAME`, separated by `, `; [`KeyScript::parse`]
    /// reads it back.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, (frame, key)) in self.presses.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            write!(f, "{key}@{frame}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::Preset;
    use crate::view::Action;

    fn actions(script: &KeyScript, frame: u64) -> Vec<Action> {
        script.keys_at(frame).filter_map(Action::for_key).collect()
    }

    #[test]
    fn key_scripts_schedule_presses_by_frame() {
        let s = KeyScript::parse("g,3").unwrap();
        assert_eq!(s.keys_at(0).count(), 0);
        assert_eq!(actions(&s, 1), [Action::ToggleGlow]);
        assert_eq!(actions(&s, 2), [Action::Quality(Preset::Production)]);
        let s = KeyScript::parse(" G@7 , o@2, h ").unwrap();
        assert_eq!(s.last_frame(), Some(7));
        assert_eq!(actions(&s, 3), [Action::ToggleShadows]);
        assert_eq!(actions(&s, 7), [Action::ToggleGlow]);
        let both = KeyScript::parse("g@5,1@5").unwrap();
        assert_eq!(both.keys_at(5).collect::<Vec<_>>(), [Key::G, Key::Digit1]);
        assert!(KeyScript::parse("").unwrap().is_empty());
        assert_eq!(KeyScript::default().to_string(), "");
    }

    #[test]
    fn bad_scripts_say_what_is_wrong() {
        let err = KeyScript::parse("g,hyper").unwrap_err().to_string();
        assert!(err.contains("key script: unknown key `hyper`"), "{err}");
        let err = KeyScript::parse("x").unwrap_err().to_string();
        assert!(err.contains("`x` has no action"), "{err}");
        let err = KeyScript::parse("g@soon").unwrap_err().to_string();
        assert!(err.contains("`g@soon`"), "{err}");
        let err = KeyScript::parse("w@3").unwrap_err().to_string();
        assert!(err.contains("`w` has no action"), "{err}");
        assert!(KeyScript::new([(1, Key::ArrowUp)]).is_err());
    }

    #[test]
    fn frame_numbers_never_wrap() {
        let last = u64::MAX;
        let s = KeyScript::parse(&format!("g@{last}")).unwrap();
        assert_eq!(s.last_frame(), Some(last));
        assert_eq!(s.to_string().parse::<KeyScript>().unwrap(), s);
        let err = KeyScript::parse(&format!("g@{last},h")).unwrap_err();
        assert!(matches!(err, Error::Invalid { .. }), "{err}");
        assert!(
            err.to_string()
                .contains(&format!("`h` would come after frame {last}, the last one")),
            "{err}"
        );
        // A key after the last frame is fine once an explicit frame follows.
        let s = KeyScript::parse(&format!("g@{},h,o@3", last - 1)).unwrap();
        assert_eq!(s.last_frame(), Some(last));
        for text in [
            "g@18446744073709551616",
            "g@-1",
            "g@1e3",
            "g@99999999999999999999999",
        ] {
            let err = KeyScript::parse(text).unwrap_err().to_string();
            assert!(err.contains("whole number from 0 to"), "{text}: {err}");
        }
    }

    #[test]
    fn scripts_follow_rebound_keys() {
        let keys = KeyBindings::from_names([("toggle_glow", "l")]).unwrap();
        let s = KeyScript::parse_with("l,o", &keys).unwrap();
        let scripted: Vec<Option<Action>> = (1..=2)
            .flat_map(|f| s.keys_at(f).map(|k| keys.action(k)).collect::<Vec<_>>())
            .collect();
        assert_eq!(
            scripted,
            [
                Some(Action::ToggleGlow),
                Some(Action::ToggleAmbientOcclusion)
            ]
        );
        let err = KeyScript::parse_with("g", &keys).unwrap_err().to_string();
        assert!(err.contains("`g` has no action"), "{err}");
        assert!(err.contains(", l,"), "the scriptable keys list `l`: {err}");
    }

    #[test]
    fn text_round_trips() {
        for text in ["", "g", "escape@9, 1@2, f12, space@2"] {
            let s: KeyScript = text.parse().unwrap();
            assert_eq!(s.to_string().parse::<KeyScript>().unwrap(), s, "{text}");
        }
    }
}
