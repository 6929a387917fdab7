//! Sites: every node and setting of a file is a [`Located`] value,
//! numbered in the order the parser meets it.

use std::cell::Cell;

use serde::de::{self, Deserializer};
use serde::ser::Serializer;
use serde::{Deserialize, Serialize};

// ---------------------------------------------------------------------------
// Locating errors
//
// Every node and setting of a file is a `Located` value, numbered in the
// order the parser meets it (its site). An error found after parsing names
// a site; parsing again with that site marked stops the parser there, and
// the parser's position is the error's line and column.

thread_local! {
    /// The next site's number, and the site to stop at (if any).
    static SITES: Cell<(usize, Option<usize>)> = const { Cell::new((0, None)) };
}

/// The message of the error that stops the parser at the marked site.
pub(super) const STOP: &str = "fractal-sdf: stop at the marked site";

/// Numbering sites while parsing.
pub(super) struct Sites;

impl Sites {
    /// Runs `parse` with sites numbered from 0 (and `stop` marked), then
    /// clears the counter.
    pub(super) fn run<T>(stop: Option<usize>, parse: impl FnOnce() -> T) -> T {
        struct Reset;
        impl Drop for Reset {
            fn drop(&mut self) {
                SITES.with(|s| s.set((0, None)));
            }
        }
        SITES.with(|s| s.set((0, stop)));
        let _reset = Reset;
        parse()
    }

    pub(super) fn counting<T>(parse: impl FnOnce() -> T) -> T {
        Self::run(None, parse)
    }
}

/// A value of the file with its site.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Located<T> {
    pub(super) site: usize,
    pub(super) value: T,
}

impl<T> Located<T> {
    /// A value to write (sites matter only when reading).
    pub(super) fn new(value: T) -> Self {
        Located {
            site: usize::MAX,
            value,
        }
    }
}

impl<T: Default> Default for Located<T> {
    fn default() -> Self {
        Located::new(T::default())
    }
}

impl<T: Serialize> Serialize for Located<T> {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        self.value.serialize(s)
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Located<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let (site, stop) = SITES.with(|s| {
            let (next, stop) = s.get();
            s.set((next + 1, stop));
            (next, stop)
        });
        if stop == Some(site) {
            return Err(de::Error::custom(STOP));
        }
        Ok(Located {
            site,
            value: T::deserialize(d)?,
        })
    }
}
