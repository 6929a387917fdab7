//! A small source writer: indentation, a fixed statement style and the one
//! place float literals are formatted.

use std::cell::Cell;
use std::fmt::Write as _;

use crate::ir::Scalar;
use crate::quality::Precision;

/// Slot numbers from here up name the entries of the current instance's
/// table row (`q[slot - INSTANCE_SLOT]`) while an instanced union's loop
/// body is emitted: no scene has a billion dynamic parameters.
pub(crate) const INSTANCE_SLOT: u32 = 1 << 30;

/// Accumulates OpenCL C source with an indentation level.
pub(crate) struct Writer {
    out: String,
    indent: usize,
    precision: Precision,
    /// Each parameter slot's name, as a comment safe to emit.
    slot_names: Vec<String>,
    /// The first value asked for as a literal that the precision cannot
    /// hold: code generation returns an error for it rather than emit it.
    unwritable: Cell<Option<f64>>,
}

impl Writer {
    pub(crate) fn new(precision: Precision) -> Self {
        Writer {
            out: String::new(),
            indent: 0,
            precision,
            slot_names: Vec::new(),
            unwritable: Cell::new(None),
        }
    }

    /// Names the parameter slots, so each read of the buffer says which
    /// parameter it is.
    pub(crate) fn name_slots<'n>(&mut self, names: impl IntoIterator<Item = &'n str>) {
        self.slot_names = names.into_iter().map(comment_text).collect();
    }

    /// Bytes written so far.
    pub(crate) fn len(&self) -> usize {
        self.out.len()
    }

    /// Lines written so far (newlines).
    pub(crate) fn lines(&self) -> usize {
        self.out.matches('\n').count()
    }

    /// Writes a `/* ... */` comment line; `text` is made safe for a comment.
    pub(crate) fn comment(&mut self, text: &str) {
        self.line(format!("/* {} */", comment_text(text)));
    }

    /// Writes one line at the current indentation.
    pub(crate) fn line(&mut self, text: impl AsRef<str>) {
        let text = text.as_ref();
        if !text.is_empty() {
            self.out.extend(std::iter::repeat_n("    ", self.indent));
            self.out.push_str(text);
        }
        self.out.push('\n');
    }

    /// Writes a block of text verbatim (used for the embedded kernels).
    pub(crate) fn raw(&mut self, text: &str) {
        self.out.push_str(text);
        if !text.ends_with('\n') {
            self.out.push('\n');
        }
    }

    /// Opens a `{` block.
    pub(crate) fn open(&mut self, head: impl AsRef<str>) {
        self.line(format!("{} {{", head.as_ref()));
        self.indent += 1;
    }

    /// Closes a block.
    pub(crate) fn close(&mut self) {
        self.indent -= 1;
        self.line("}");
    }

    /// A float literal of the kernel's precision that reads back as exactly
    /// `v` rounded to that precision: `1.0f`, `(-0.5f)`, `1e-30f`. F64 has no
    /// suffix. Values the precision cannot hold never reach code generation
    /// (validation and the precision's limits refuse them); if one did, it
    /// is written as `0` and kept for [`Writer::unwritable`], so that code
    /// generation returns an error instead of a program holding `inf`.
    pub(crate) fn float(&self, v: f64) -> String {
        literal(self.checked(v), self.precision)
    }

    /// `v` where the precision holds it; otherwise 0, and `v` is kept for
    /// [`Writer::unwritable`] (see [`Writer::float`]).
    pub(crate) fn checked(&self, v: f64) -> f64 {
        if fits(v, self.precision) {
            v
        } else {
            if self.unwritable.get().is_none() {
                self.unwritable.set(Some(v));
            }
            0.0
        }
    }

    /// The first value [`Writer::float`] could not write, if any.
    pub(crate) fn unwritable(&self) -> Option<f64> {
        self.unwritable.get()
    }

    /// The precision literals are written in.
    pub(crate) fn precision(&self) -> Precision {
        self.precision
    }

    /// A scalar parameter: a literal, or a read of the parameter buffer.
    pub(crate) fn scalar(&self, s: Scalar) -> String {
        match s {
            Scalar::Baked(v) => self.float(v),
            Scalar::Dynamic(slot) if slot >= INSTANCE_SLOT => {
                format!("q[{}]", slot - INSTANCE_SLOT)
            }
            Scalar::Dynamic(slot) => match self.slot_names.get(slot as usize) {
                Some(name) => format!("params[{slot}] /* {name} */"),
                None => format!("params[{slot}]"),
            },
        }
    }

    /// A vector parameter as a `real3` expression.
    pub(crate) fn vector(&self, v: [Scalar; 3]) -> String {
        let [x, y, z] = v.map(|s| self.scalar(s));
        if x == y && y == z {
            format!("(real3)({x})")
        } else {
            format!("(real3)({x}, {y}, {z})")
        }
    }

    pub(crate) fn finish(self) -> String {
        self.out
    }
}

/// `text` as comment text: characters outside a plain set (letters, digits,
/// space and `_ . : / - [ ]`) become `?`, so no user string can close the
/// comment, continue a line or smuggle a directive.
fn comment_text(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || " _.:/-[]".contains(c) {
                c
            } else {
                '?'
            }
        })
        .collect()
}

/// Whether `v` is finite in `precision`.
fn fits(v: f64, precision: Precision) -> bool {
    #[allow(clippy::cast_possible_truncation)]
    match precision {
        Precision::F32 => (v as f32).is_finite(),
        Precision::F64 => v.is_finite(),
    }
}

/// Formats `v` as an OpenCL C literal of `precision` that reads back as
/// exactly `v` rounded to that precision: `1.0f`, `(-0.5f)`, `1e-30f` (F64
/// has no suffix). Negative values are parenthesised.
///
/// # Panics
/// If `v` is NaN or infinite, or finite but beyond `f32` in an F32
/// literal (it would read back as infinity).
#[must_use]
pub fn literal(v: f64, precision: Precision) -> String {
    assert!(
        fits(v, precision),
        "non-finite literal {v} reached code generation for {precision:?}"
    );
    let mut s = String::new();
    match precision {
        // Debug formatting is the shortest text that parses back to the same
        // value, with a `.` or an exponent, so it is a valid C float constant.
        #[allow(clippy::cast_possible_truncation)]
        Precision::F32 => write!(s, "{:?}f", v as f32),
        Precision::F64 => write!(s, "{v:?}"),
    }
    .expect("writing to a String cannot fail");
    if s.starts_with('-') {
        format!("({s})")
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_round_trip_exactly() {
        for v in [
            0.0,
            1.0,
            -0.5,
            0.1,
            1e-30,
            1e30,
            std::f64::consts::PI,
            1.0 / 3.0,
        ] {
            let f = literal(v, Precision::F32);
            #[allow(clippy::cast_possible_truncation)]
            let expect = v as f32;
            let text = f.trim_matches(['(', ')']).trim_end_matches('f');
            assert_eq!(text.parse::<f32>().unwrap(), expect, "{f}");
            assert!(
                f.contains('.') || f.contains('e'),
                "{f} is not a float constant"
            );
            let d = literal(v, Precision::F64);
            assert_eq!(d.trim_matches(['(', ')']).parse::<f64>().unwrap(), v, "{d}");
        }
    }

    #[test]
    fn values_a_precision_cannot_hold_are_kept_not_written() {
        let w = Writer::new(Precision::F32);
        assert_eq!(w.float(1.5), "1.5f");
        assert_eq!(w.unwritable(), None);
        assert_eq!(w.float(1e300), "0.0f");
        assert_eq!(w.float(f64::NAN), "0.0f");
        assert_eq!(w.unwritable(), Some(1e300));
        let w = Writer::new(Precision::F64);
        assert_eq!(w.float(1e300), "1e300");
        assert_eq!(w.unwritable(), None);
    }

    #[test]
    fn comments_cannot_be_closed_by_user_text() {
        assert_eq!(comment_text("radius"), "radius");
        assert_eq!(comment_text("a*/ b\nc\\"), "a?/ b?c?");
        let mut w = Writer::new(Precision::F32);
        w.name_slots(["*/ evil();"]);
        assert_eq!(w.scalar(Scalar::Dynamic(0)), "params[0] /* ?/ evil??? */");
    }

    #[test]
    #[should_panic(expected = "non-finite")]
    fn non_finite_literals_are_refused() {
        let _ = literal(f64::NAN, Precision::F32);
    }

    #[test]
    #[should_panic(expected = "non-finite")]
    fn literals_beyond_f32_are_refused() {
        let _ = literal(1e39, Precision::F32);
    }
}
