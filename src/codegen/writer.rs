//! A small source writer: indentation, a fixed statement style, the one
//! place float literals are formatted, and the spelling of the few
//! statements and expressions the scene functions write in OpenCL C or in
//! WGSL (a declaration, a vector, a choice, a loop).

use std::cell::Cell;
use std::fmt::Write as _;

use crate::expr::{OpenCl, Printer, Wgsl};
use crate::ir::Scalar;
use crate::quality::Precision;
use crate::scene::MATERIAL_LEN;

/// The language a [`Writer`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Lang {
    OpenCl,
    Wgsl,
}

/// The types the scene functions declare: each language's name for them
/// (`real` and its vectors, `uint` and `int` are aliases in WGSL's
/// prelude, which no local name of the scene functions can hide, as `u{i}`
/// for node 32 would hide `u32`; WGSL has no 16-vector, and its
/// `real16`, a material, is a 4 × 4 matrix, which the render module's
/// `material_select` and `material_mix` choose and blend).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Ty {
    Real,
    Real2,
    Real3,
    Real4,
    Real16,
    Uint,
    Int,
    Bool,
}

/// Slot numbers from here up name the entries of the current instance's
/// table row (`q[slot - INSTANCE_SLOT]`) while an instanced union's loop
/// body is emitted: no scene has a billion dynamic parameters.
pub(crate) const INSTANCE_SLOT: u32 = 1 << 30;

/// A parameter of a scene function.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Param<'a> {
    /// A value.
    Value(&'a str, Ty),
    /// A pointer the function writes through.
    Pointer(&'a str, Ty),
    /// The parameter buffer.
    Buffer,
}

/// Accumulates OpenCL C or WGSL source with an indentation level.
pub(crate) struct Writer {
    lang: Lang,
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
        Self::in_language(Lang::OpenCl, precision)
    }

    /// A writer of WGSL (single precision only).
    pub(crate) fn wgsl() -> Self {
        Self::in_language(Lang::Wgsl, Precision::F32)
    }

    fn in_language(lang: Lang, precision: Precision) -> Self {
        Writer {
            lang,
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
            Scalar::Dynamic(slot) if slot >= INSTANCE_SLOT => match self.lang {
                Lang::OpenCl => format!("q[{}]", slot - INSTANCE_SLOT),
                Lang::Wgsl => format!("params[q + {}u]", slot - INSTANCE_SLOT),
            },
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
            self.construct(Ty::Real3, &[&x])
        } else {
            self.construct(Ty::Real3, &[&x, &y, &z])
        }
    }

    /// The language written.
    pub(crate) fn lang(&self) -> Lang {
        self.lang
    }

    /// The printer of formulas in the language written.
    pub(crate) fn printer(&self) -> &'static dyn Printer {
        match self.lang {
            Lang::OpenCl => &OpenCl,
            Lang::Wgsl => &Wgsl,
        }
    }

    /// The language's name of a type.
    pub(crate) fn ty(&self, ty: Ty) -> &'static str {
        match (self.lang, ty) {
            (_, Ty::Real) => "real",
            (_, Ty::Real2) => "real2",
            (_, Ty::Real3) => "real3",
            (_, Ty::Real4) => "real4",
            (_, Ty::Real16) => "real16",
            (_, Ty::Bool) => "bool",
            (_, Ty::Uint) => "uint",
            (_, Ty::Int) => "int",
        }
    }

    /// Declares the variable `name` of type `ty`, holding `value`.
    pub(crate) fn declare(&mut self, ty: Ty, name: &str, value: &str) {
        let line = match self.lang {
            Lang::OpenCl => format!("{} {name} = {value};", self.ty(ty)),
            Lang::Wgsl => format!("var {name}: {} = {value};", self.ty(ty)),
        };
        self.line(line);
    }

    /// Declares the array `name` of `len` values of type `ty`.
    pub(crate) fn array(&mut self, ty: Ty, name: &str, len: usize) {
        let line = match self.lang {
            Lang::OpenCl => format!("{} {name}[{len}];", self.ty(ty)),
            Lang::Wgsl => format!("var {name}: array<{}, {len}>;", self.ty(ty)),
        };
        self.line(line);
    }

    /// A value of type `ty` made of `parts` (one part fills a vector).
    pub(crate) fn construct(&self, ty: Ty, parts: &[&str]) -> String {
        let parts = parts.join(", ");
        match self.lang {
            Lang::OpenCl => format!("({})({parts})", self.ty(ty)),
            Lang::Wgsl => format!("{}({parts})", self.ty(ty)),
        }
    }

    /// A material of `values` (the lanes after them zero).
    pub(crate) fn material(&self, values: [String; MATERIAL_LEN]) -> String {
        const LANES: usize = 16;
        const _: () = assert!(MATERIAL_LEN <= LANES);
        let zero = self.float(0.0);
        let lanes: Vec<String> = values
            .into_iter()
            .chain(std::iter::repeat_n(zero, LANES - MATERIAL_LEN))
            .collect();
        let parts: Vec<&str> = lanes.iter().map(String::as_str).collect();
        self.construct(Ty::Real16, &parts)
    }

    /// The value of type `ty` a fraction `m` of the way from `a` to `b`:
    /// `a + (b - a) m`, lane by lane.
    pub(crate) fn mix(&self, ty: Ty, a: &str, b: &str, m: &str) -> String {
        match (self.lang, ty) {
            (Lang::Wgsl, Ty::Real16) => format!("material_mix({a}, {b}, {m})"),
            _ => format!("mix({a}, {b}, {m})"),
        }
    }

    /// Of type `ty`, `a` where `c` holds, else `b`.
    pub(crate) fn select_typed(&self, ty: Ty, c: &str, a: &str, b: &str) -> String {
        match (self.lang, ty) {
            (Lang::Wgsl, Ty::Real16) => format!("material_select({b}, {a}, {c})"),
            _ => self.select(c, a, b),
        }
    }

    /// `a` where `c` holds, else `b` (`c` is a boolean, or in OpenCL a
    /// number that is nonzero where it holds).
    pub(crate) fn select(&self, c: &str, a: &str, b: &str) -> String {
        match self.lang {
            Lang::OpenCl => format!("{c} ? {a} : {b}"),
            Lang::Wgsl => format!("select({b}, {a}, {c})"),
        }
    }

    /// The number `text` (a decimal) as a value of the precision, in an
    /// expression that mixes it with vectors and numbers alike.
    pub(crate) fn real(&self, text: &str) -> String {
        match self.lang {
            Lang::OpenCl => format!("R({text})"),
            Lang::Wgsl => text.to_string(),
        }
    }

    /// The smaller and the larger of two values: the function names.
    pub(crate) fn min_max(&self) -> (&'static str, &'static str) {
        match self.lang {
            Lang::OpenCl => ("fmin", "fmax"),
            Lang::Wgsl => ("min", "max"),
        }
    }

    /// A distance beyond every other: OpenCL's infinity; in WGSL, whose
    /// implementations may assume no value is infinite, 1e19, beyond the
    /// largest magnitude a value of the scene may have (1e18) and with a
    /// finite square, which the hierarchy walk takes.
    pub(crate) fn infinity(&self) -> &'static str {
        match self.lang {
            Lang::OpenCl => "INFINITY",
            Lang::Wgsl => "FSDF_INFINITY",
        }
    }

    /// `value` converted to type `ty`.
    pub(crate) fn cast(&self, ty: Ty, value: &str) -> String {
        match self.lang {
            Lang::OpenCl => format!("({}){value}", self.ty(ty)),
            Lang::Wgsl => format!("{}({value})", self.ty(ty)),
        }
    }

    /// Opens a loop of `i` (a `uint`) from `start` while below `end`.
    pub(crate) fn open_for(&mut self, i: &str, start: &str, end: &str) {
        let head = match self.lang {
            Lang::OpenCl => format!("for (uint {i} = {start}; {i} < {end}; {i}++)"),
            Lang::Wgsl => format!("for (var {i}: uint = {start}; {i} < {end}; {i}++)"),
        };
        self.open(head);
    }

    /// Declares `name`, the index in the parameter buffer at which values
    /// start `offset` after `base` (in OpenCL a pointer there, in WGSL the
    /// index: a read of entry `k` from it is [`Writer::at`]).
    pub(crate) fn declare_offset(&mut self, name: &str, base: usize, offset: &str) {
        let line = match self.lang {
            Lang::OpenCl => format!("__global const real* {name} = params + {base}u + {offset};"),
            Lang::Wgsl => format!("let {name} = {base}u + {offset};"),
        };
        self.line(line);
    }

    /// Entry `k` from an offset [`Writer::declare_offset`] named.
    pub(crate) fn at(&self, name: &str, k: usize) -> String {
        match self.lang {
            Lang::OpenCl => format!("{name}[{k}]"),
            Lang::Wgsl => format!("params[{name} + {k}u]"),
        }
    }

    /// Four entries from an offset as a `real4`: entries `4k` to `4k + 3`.
    pub(crate) fn load4(&self, name: &str, k: usize) -> String {
        match self.lang {
            Lang::OpenCl => format!("vload4({k}, {name})"),
            Lang::Wgsl => {
                let e: Vec<String> = (0..4).map(|j| self.at(name, 4 * k + j)).collect();
                format!("real4({})", e.join(", "))
            }
        }
    }

    /// Lane `j` of a `real4`.
    pub(crate) fn lane(&self, j: usize) -> String {
        match self.lang {
            Lang::OpenCl => format!("s{j}"),
            Lang::Wgsl => ["x", "y", "z", "w"][j].to_string(),
        }
    }

    /// The head of a scene function: its name, result and parameters.
    /// The parameter buffer is an argument in OpenCL and a binding in
    /// WGSL.
    pub(crate) fn function_head(&self, name: &str, result: Ty, params: &[Param<'_>]) -> String {
        let params: Vec<String> = params
            .iter()
            .filter_map(|p| match (self.lang, p) {
                (Lang::OpenCl, Param::Value(p, ty)) => Some(format!("{} {p}", self.ty(*ty))),
                (Lang::OpenCl, Param::Pointer(p, ty)) => Some(format!("{}* {p}", self.ty(*ty))),
                (Lang::OpenCl, Param::Buffer) => Some("__global const real* params".into()),
                (Lang::Wgsl, Param::Value(p, ty)) => Some(format!("{p}: {}", self.ty(*ty))),
                (Lang::Wgsl, Param::Pointer(p, ty)) => {
                    Some(format!("{p}: ptr<function, {}>", self.ty(*ty)))
                }
                (Lang::Wgsl, Param::Buffer) => None,
            })
            .collect();
        let params = params.join(", ");
        match self.lang {
            Lang::OpenCl => format!("{} {name}({params})", self.ty(result)),
            Lang::Wgsl => format!("fn {name}({params}) -> {}", self.ty(result)),
        }
    }

    /// The arguments of a call of a scene function: `args`, and in OpenCL
    /// the parameter buffer after them.
    pub(crate) fn call(&self, name: &str, args: &str) -> String {
        match self.lang {
            Lang::OpenCl => format!("{name}({args}, params)"),
            Lang::Wgsl => format!("{name}({args})"),
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

/// Formats `v` as an OpenCL C literal of `precision` (in `F32`, a WGSL
/// literal too) that reads back as
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
