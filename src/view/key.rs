//! [`Key`]: the keys of a keyboard, by position, with their textual names.

use std::fmt;
use std::str::FromStr;

use crate::error::Error;

macro_rules! keys {
    ($($variant:ident $name:literal,)*) => {
        /// A key of the keyboard, by its position on a US layout (so `W`
        /// is the key left of `E` whatever a layout prints on it).
        ///
        /// In text — key scripts, configuration files, help — a key is its
        /// lower-case name: `a` to `z`, `0` to `9`, `f1` to `f12`,
        /// `arrowup`, `arrowdown`, `arrowleft`, `arrowright`, `space`,
        /// `enter`, `escape`, `tab` and `backspace`. [`Display`](fmt::Display)
        /// writes that name and [`FromStr`] reads it back (ignoring case).
        ///
        /// ```
        /// use fractal_sdf::view::Key;
        ///
        /// assert_eq!("F12".parse::<Key>()?, Key::F12);
        /// assert_eq!(Key::ArrowUp.to_string(), "arrowup");
        /// assert_eq!(Key::Digit3.name(), "3");
        /// assert!("hyper".parse::<Key>().is_err());
        /// # Ok::<(), fractal_sdf::Error>(())
        /// ```
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[non_exhaustive]
        pub enum Key {
            $(
                #[doc = concat!("The key named `", $name, "`.")]
                $variant,
            )*
        }

        impl Key {
            /// Every key, in the order of the list above.
            pub const ALL: &'static [Key] = &[$(Key::$variant),*];

            /// The key's name in text, such as `w`, `3`, `f12` or `space`.
            #[must_use]
            pub fn name(self) -> &'static str {
                match self {
                    $(Key::$variant => $name,)*
                }
            }
        }
    };
}

keys! {
    A "a", B "b", C "c", D "d", E "e", F "f", G "g", H "h", I "i", J "j",
    K "k", L "l", M "m", N "n", O "o", P "p", Q "q", R "r", S "s", T "t",
    U "u", V "v", W "w", X "x", Y "y", Z "z",
    Digit0 "0", Digit1 "1", Digit2 "2", Digit3 "3", Digit4 "4",
    Digit5 "5", Digit6 "6", Digit7 "7", Digit8 "8", Digit9 "9",
    F1 "f1", F2 "f2", F3 "f3", F4 "f4", F5 "f5", F6 "f6",
    F7 "f7", F8 "f8", F9 "f9", F10 "f10", F11 "f11", F12 "f12",
    ArrowUp "arrowup", ArrowDown "arrowdown", ArrowLeft "arrowleft", ArrowRight "arrowright",
    Space "space", Enter "enter", Escape "escape", Tab "tab", Backspace "backspace",
}

impl fmt::Display for Key {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(self.name())
    }
}

impl FromStr for Key {
    type Err = Error;

    /// The key called `name` (see [`Key`]), ignoring case and surrounding
    /// spaces.
    ///
    /// # Errors
    /// [`Error::Invalid`] naming the unknown key.
    fn from_str(name: &str) -> Result<Self, Error> {
        let name = name.trim();
        Key::ALL
            .iter()
            .copied()
            .find(|k| k.name().eq_ignore_ascii_case(name))
            .ok_or_else(|| Error::Invalid {
                what: "key",
                reason: format!(
                    "unknown key `{name}` (keys: a-z, 0-9, f1-f12, arrowup, arrowdown, \
                     arrowleft, arrowright, space, enter, escape, tab, backspace)"
                ),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_round_trips_and_is_unique() {
        assert_eq!(Key::ALL.len(), 26 + 10 + 12 + 4 + 5);
        let mut names: Vec<&str> = Key::ALL.iter().map(|k| k.name()).collect();
        for &key in Key::ALL {
            assert_eq!(key.to_string().parse::<Key>().unwrap(), key);
            assert_eq!(key.name().to_uppercase().parse::<Key>().unwrap(), key);
            assert_eq!(key.name(), key.name().to_ascii_lowercase());
        }
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Key::ALL.len());
    }

    #[test]
    fn names_read_as_expected() {
        assert_eq!(" w ".parse::<Key>().unwrap(), Key::W);
        assert_eq!("0".parse::<Key>().unwrap(), Key::Digit0);
        assert_eq!("ArrowLeft".parse::<Key>().unwrap(), Key::ArrowLeft);
        assert_eq!(format!("[{:>5}]", Key::Tab), "[  tab]");
        for bad in ["", "f13", "ctrl", "ww", "arrow up"] {
            let err = bad.parse::<Key>().unwrap_err().to_string();
            assert!(err.contains("unknown key"), "{bad}: {err}");
        }
    }
}
