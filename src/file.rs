//! Scene files: a scene, how to render it and how it moves, as text.
//!
//! The format is [RON](https://github.com/ron-rs/ron) (Rusty Object
//! Notation), chosen over TOML because a scene is a tree: a node inside an
//! operation inside a union reads in RON as it is written in Rust
//! (`Translate(offset: (1, 0, 0), child: Sphere(radius: 0.5))`), where
//! TOML would need a table header per node or one long inline table. RON
//! also reports every syntax error with its line and column.
//!
//! ```ron
//! // A fractal-sdf scene, format version 1.
//! (
//!     version: 1,
//!     geometry: Union([
//!         Mandelbulb(power: param("power", 8), iterations: 10),
//!         Translate(offset: (0, -1.2, 0), child: Cuboid(half_extents: (3, 0.05, 3))),
//!     ]),
//!     camera: (position: (0, 0.6, 3.2), target: (0, 0, 0)),
//!     lights: [(source: Directional(direction: (0.6, 0.8, 0.4)))],
//!     quality: (preset: Production, supersampling: 2),
//!     effects: (glow: Some((color: (0.6, 0.75, 1), strength: 0.6))),
//!     motions: [Oscillate(name: "power", center: 8, amplitude: 2, period: 4)],
//! )
//! ```
//!
//! - **Nodes** are written as in Rust's [`Kind`], with
//!   the booleans named: `Union([a, b, ...])` (any number of operands, what
//!   [`Scene::add`] builds), `Subtract(a: .., b: ..)`, `Intersect(a: ..,
//!   b: ..)`, `SmoothUnion(k: 0.1, a: .., b: ..)` and the other smooth
//!   forms, and `Custom(name: "gyroid", args: [0.1])` for a shape passed to
//!   [`SceneFile::parse_with`] or a built-in inside shape
//!   ([`InsideShape::builtin`]: `Custom(name: "mandelbox_escape", args:
//!   [-1.5, 12])`). Fractal settings left out take the
//!   builders' defaults (Mandelbulb: 12 iterations, bailout 2).
//! - **Numbers**: a parameter is a number (baked) or `param("name",
//!   default)` (dynamic, see [`param`](crate::scene::param)); a vector is `(x, y,
//!   z)`, one number for all three, or `param3("name", (x, y, z))`.
//! - **Everything but `version` and `geometry` may be left out**: the
//!   camera and lights default as in [`Scene::new`], `quality` to none
//!   (the renderer's, or the user's default preset; a quality names a
//!   preset and changes any of its settings),
//!   `effects` to [`Effects::default`]. `path` is a camera path (keyframes
//!   `(time: 0, position: (0, 1, 3), target: (0, 0, 0))`) and `motions` move dynamic
//!   parameters (see [`Motion`]).
//! - A misspelt field or node is an error, not ignored.
//!
//! Loading validates the scene exactly as [`Scene::compile`] does, and the
//! quality, effects, camera path and motions as a renderer would. Every
//! error is an [`Error::SceneFile`] naming the file, the line and column of
//! the offending node or setting, and what is wrong (a node's path in the
//! tree, such as `union/b:translate/sphere`, comes with it).
//!
//! ```
//! use fractal_sdf::prelude::*;
//! use fractal_sdf::SceneFile;
//!
//! let file = SceneFile::parse("(version: 1, geometry: Sphere(radius: 1))")?;
//! assert_eq!(file.scene.geometry, Some(sphere(1.0)));
//!
//! let err = SceneFile::parse("(version: 1,\n geometry: Sphere(radius: -1))").unwrap_err();
//! assert_eq!(err.to_string(), "<scene>:2:12: sphere: parameter `radius` must be >= 0, got -1");
//! # Ok::<(), fractal_sdf::Error>(())
//! ```

use std::cell::Cell;
use std::collections::HashMap;
use std::fmt;
use std::io::Write;
use std::path::Path;

use glam::DVec3;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::ser::{SerializeTupleVariant, Serializer};
use serde::{Deserialize, Serialize};

use crate::animation::{CameraPath, Keyframe, Motion};
use crate::error::{Error, Result};
use crate::quality::{Effects, Precision, Preset, Quality, ScreenNormals};
use crate::scene::{
    Axis, Camera, CsgOp, CustomShape, InsideShape, Kind, Light, Mandelbulb, Material, Menger, Node,
    NodeKind, Param, Param3, QuaternionJulia, Scene, Sierpinski, param3,
};

/// The format version this library reads and writes.
pub const FORMAT_VERSION: u32 = 1;

/// The deepest nesting of nodes a scene file may have (the operands of one
/// `Union([...])` are one level below it). Reading and writing recurse on
/// the nesting, so it is bounded; a scene built with [`Scene::add`] from
/// any number of shapes is one level deep.
pub const MAX_NESTING: usize = 64;

/// The name in errors of text read with [`SceneFile::parse`].
const TEXT: &str = "<scene>";

/// A scene and how to render it, as read from or written to a scene file
/// (see the [module documentation](self) for the format).
#[derive(Debug, Clone, PartialEq)]
pub struct SceneFile {
    /// Geometry, camera and lights.
    pub scene: Scene,
    /// How accurately to render it, or `None` where the file leaves that to
    /// whoever renders it (the `fractal-sdf` command and the viewer then
    /// use the user's default preset).
    pub quality: Option<Quality>,
    /// Lighting effects.
    pub effects: Effects,
    /// A camera path for sequences, if the file has one.
    pub path: Option<CameraPath>,
    /// Motions of dynamic parameters over time.
    pub motions: Vec<Motion>,
}

impl SceneFile {
    /// `scene` with no quality of its own, the default effects, no camera
    /// path and no motions.
    #[must_use]
    pub fn new(scene: Scene) -> Self {
        SceneFile {
            scene,
            quality: None,
            effects: Effects::default(),
            path: None,
            motions: Vec::new(),
        }
    }

    /// Reads a scene file's text; errors name the file `<scene>`.
    ///
    /// # Errors
    /// [`Error::SceneFile`] for a syntax error, an unknown node, field or
    /// custom shape, a format version other than [`FORMAT_VERSION`], or a
    /// value that does not validate.
    pub fn parse(text: &str) -> Result<Self> {
        Self::parse_with(text, &[])
    }

    /// Reads a scene file's text whose `Custom(name: ..)` nodes name the
    /// shapes in `shapes`.
    ///
    /// # Errors
    /// As [`SceneFile::parse`].
    pub fn parse_with(text: &str, shapes: &[CustomShape]) -> Result<Self> {
        read(text, Path::new(TEXT), shapes)
    }

    /// Reads the scene file at `path`.
    ///
    /// # Errors
    /// [`Error::Io`] if it cannot be read; else as [`SceneFile::parse`],
    /// with the file's path in the error.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        Self::load_with(path, &[])
    }

    /// Reads the scene file at `path` whose `Custom(name: ..)` nodes name
    /// the shapes in `shapes`.
    ///
    /// # Errors
    /// As [`SceneFile::load`].
    pub fn load_with(path: impl AsRef<Path>, shapes: &[CustomShape]) -> Result<Self> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)
            .map_err(|source| Error::io(path, "cannot read the scene file", source))?;
        read(&text, path, shapes)
    }

    /// The scene file's text. Writing then reading gives back an equal
    /// value; numbers are written in full (`f64` round trips exactly).
    ///
    /// # Errors
    /// [`Error::Invalid`] if the scene has no geometry or its nodes are
    /// nested deeper than [`MAX_NESTING`]; the quality's or the effects'
    /// error if they do not validate.
    pub fn to_text(&self) -> Result<String> {
        let invalid = |reason: String| Error::Invalid {
            what: "scene to write",
            reason,
        };
        let geometry = self
            .scene
            .geometry
            .as_ref()
            .ok_or_else(|| invalid("the scene is empty".into()))?;
        // What would not read back is not written.
        match &self.quality {
            Some(quality) => {
                quality.validate()?;
                self.effects.validate_for(quality.precision)?;
            }
            None => self.effects.validate()?,
        }
        let nesting = nesting(geometry);
        if nesting > MAX_NESTING {
            return Err(invalid(format!(
                "its nodes are nested {nesting} deep; a scene file holds at most {MAX_NESTING}"
            )));
        }
        let repr = FileRepr {
            version: FORMAT_VERSION,
            geometry: Located::new(NodeRepr::from_node(geometry)),
            camera: Located::new(self.scene.camera),
            lights: self
                .scene
                .lights
                .iter()
                .copied()
                .map(Located::new)
                .collect(),
            quality: self
                .quality
                .as_ref()
                .map(|q| Located::new(QualityRepr::from_quality(q))),
            effects: Located::new(self.effects),
            path: self
                .path
                .as_ref()
                .map(|p| Located::new(p.keyframes().to_vec())),
            motions: self.motions.iter().cloned().map(Located::new).collect(),
        };
        let compact = options()
            .to_string(&repr)
            .map_err(|e| invalid(e.to_string()))?;
        let body = layout(&compact);
        Ok(format!(
            "// A fractal-sdf scene, format version {FORMAT_VERSION}.\n{body}\n"
        ))
    }

    /// Writes the scene file to `path`, atomically (a reader sees the old
    /// file or the new one, never a part).
    ///
    /// # Errors
    /// As [`SceneFile::to_text`], or [`Error::Io`] if it cannot be written.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let text = self.to_text()?;
        crate::output::write_atomic(path.as_ref(), "scene", |mut file| {
            file.write_all(text.as_bytes())
        })
    }
}

impl From<Scene> for SceneFile {
    fn from(scene: Scene) -> Self {
        SceneFile::new(scene)
    }
}

/// The widest line [`layout`] writes where a value fits.
const WIDTH: usize = 80;

/// One piece of compact RON: text, or a bracketed group of comma-separated
/// items.
enum Piece {
    Text(String),
    Group(char, Vec<Vec<Piece>>, char),
}

/// Lays out compact RON (no white space) for people: a bracketed group
/// that fits on its line stays on it, a longer one gets a line per item.
fn layout(compact: &str) -> String {
    let chars: Vec<char> = compact.chars().collect();
    let mut at = 0;
    let items = pieces(&chars, &mut at);
    let mut out = String::new();
    for item in &items {
        item_layout(item, 0, &mut out);
    }
    out
}

/// Reads items up to the closing bracket at `at` (or the end).
fn pieces(chars: &[char], at: &mut usize) -> Vec<Vec<Piece>> {
    let mut items = vec![Vec::new()];
    let mut text = String::new();
    let flush = |text: &mut String, items: &mut Vec<Vec<Piece>>| {
        if !text.is_empty() {
            items
                .last_mut()
                .expect("one item")
                .push(Piece::Text(std::mem::take(text)));
        }
    };
    while let Some(&c) = chars.get(*at) {
        *at += 1;
        match c {
            '"' => {
                text.push(c);
                while let Some(&c) = chars.get(*at) {
                    *at += 1;
                    text.push(c);
                    if c == '\\' {
                        if let Some(&next) = chars.get(*at) {
                            *at += 1;
                            text.push(next);
                        }
                    } else if c == '"' {
                        break;
                    }
                }
            }
            '(' | '[' | '{' => {
                flush(&mut text, &mut items);
                let inner = pieces(chars, at);
                let close = chars.get(*at - 1).copied().unwrap_or(')');
                items
                    .last_mut()
                    .expect("one item")
                    .push(Piece::Group(c, inner, close));
            }
            ')' | ']' | '}' => break,
            ',' => {
                flush(&mut text, &mut items);
                items.push(Vec::new());
            }
            ':' => text.push_str(": "),
            c => text.push(c),
        }
    }
    flush(&mut text, &mut items);
    items.retain(|item| !item.is_empty());
    items
}

fn flat(item: &[Piece], out: &mut String) {
    for piece in item {
        match piece {
            Piece::Text(t) => out.push_str(t),
            Piece::Group(open, items, close) => {
                out.push(*open);
                for (i, item) in items.iter().enumerate() {
                    if i > 0 {
                        out.push_str(", ");
                    }
                    flat(item, out);
                }
                out.push(*close);
            }
        }
    }
}

fn item_layout(item: &[Piece], indent: usize, out: &mut String) {
    let mut one_line = String::new();
    flat(item, &mut one_line);
    let Some((Piece::Group(open, items, close), head)) = item.split_last() else {
        out.push_str(&one_line);
        return;
    };
    if indent + one_line.chars().count() <= WIDTH || items.is_empty() {
        out.push_str(&one_line);
        return;
    }
    flat(head, out);
    out.push(*open);
    // `Union([...])`: the list opens on the variant's line.
    if let [only] = items.as_slice()
        && let [Piece::Group(inner_open, inner, inner_close)] = only.as_slice()
    {
        out.push(*inner_open);
        lines(inner, indent, out);
        out.push(*inner_close);
    } else {
        lines(items, indent, out);
    }
    out.push(*close);
}

/// `items` one per line, indented one step more than `indent`, and the
/// closing bracket's indent.
fn lines(items: &[Vec<Piece>], indent: usize, out: &mut String) {
    out.push('\n');
    for item in items {
        out.push_str(&" ".repeat(indent + 4));
        item_layout(item, indent + 4, out);
        out.push_str(",\n");
    }
    out.push_str(&" ".repeat(indent));
}

// ---------------------------------------------------------------------------
// Reading

/// Parses, converts and validates; every error located in `text`.
fn read(text: &str, file: &Path, shapes: &[CustomShape]) -> Result<SceneFile> {
    let at = |line: usize, column: usize, reason: String, cause: Option<Error>| Error::SceneFile {
        file: file.to_path_buf(),
        line,
        column,
        reason,
        cause: cause.map(Box::new),
    };
    let syntax = |e: ron::error::SpannedError| {
        let reason = match e.code {
            ron::Error::ExceededRecursionLimit => {
                format!("nodes are nested more than {MAX_NESTING} deep")
            }
            code => code.to_string(),
        };
        at(e.span.start.line, e.span.start.col, reason, None)
    };

    // The version first, so that a file from a newer format says so
    // rather than failing on a field this version does not know.
    let version: VersionOnly = options().from_str(text).map_err(syntax)?;
    if version.version != FORMAT_VERSION {
        let (line, column) = text
            .find("version")
            .map_or((1, 1), |i| line_and_column(text, i));
        return Err(at(
            line,
            column,
            format!(
                "format version {} is not supported: this library reads version {FORMAT_VERSION}",
                version.version
            ),
            None,
        ));
    }

    let repr: FileRepr = Sites::counting(|| options().from_str(text)).map_err(syntax)?;
    // RON passes a parameter's spelling (`param(..)`) through unread: a
    // misspelt one is found here.
    if let Some((offset, name)) = unknown_name(text) {
        let (line, column) = line_and_column(text, offset);
        return Err(at(
            line,
            column,
            format!(
                "`{name}(..)` is not a node, a setting or a parameter form \
                 (`param(\"name\", default)`, `param3(\"name\", (x, y, z))`)"
            ),
            None,
        ));
    }
    let located = |site: usize, error: Error| match locate(text, site) {
        Some((line, column)) => at(line, column, error.to_string(), Some(error)),
        None => at(1, 1, error.to_string(), Some(error)),
    };
    let mut sites = SiteMap::default();
    let geometry = repr
        .geometry
        .to_node(shapes, &mut sites, 1)
        .map_err(|(site, e)| located(site, e))?;
    let scene = Scene {
        geometry: Some(geometry),
        lights: repr.lights.iter().map(|l| l.value).collect(),
        camera: repr.camera.value,
    };
    let compiled = scene.compile().map_err(|e| {
        let site = sites
            .site_of(&scene, &repr, &e)
            .unwrap_or(repr.geometry.site);
        located(site, e)
    })?;

    let quality = match &repr.quality {
        Some(q) => {
            let quality = q.value.to_quality();
            quality.validate().map_err(|e| located(q.site, e))?;
            Some(quality)
        }
        None => None,
    };
    // Without a quality of its own, a file is held to the limits of `F64`
    // (which `compile` checked) and its effects to those of any precision.
    let precision = quality.map_or(Precision::F64, |q| q.precision);
    repr.effects
        .value
        .validate_for(precision)
        .map_err(|e| located(repr.effects.site, e))?;
    let path = match &repr.path {
        Some(keys) => Some(CameraPath::new(keys.value.clone()).map_err(|e| located(keys.site, e))?),
        None => None,
    };
    // What a renderer of this precision would refuse: baked values and
    // dynamic defaults beyond its limits, and every value a motion reaches.
    let limits = precision.limits();
    compiled.ir().check_limits(limits).map_err(|e| {
        let site = sites
            .site_of(&scene, &repr, &e)
            .unwrap_or(repr.geometry.site);
        located(site, e)
    })?;
    let defaults = compiled.default_values();
    for slot in compiled.params().slots() {
        let value = defaults.get(&slot.name).unwrap_or(f64::NAN);
        defaults
            .clone()
            .set_within(&slot.name, value, limits)
            .map_err(|e| {
                let site = sites
                    .site_of(&scene, &repr, &e)
                    .unwrap_or(repr.geometry.site);
                located(site, e)
            })?;
    }
    for motion in &repr.motions {
        for (name, value) in extremes(&motion.value) {
            if !compiled.params().slots().iter().any(|s| s.name == name) {
                return Err(located(motion.site, Error::UnknownParam { name }));
            }
            defaults
                .clone()
                .set_within(&name, value, limits)
                .map_err(|e| located(motion.site, e))?;
        }
    }
    Ok(SceneFile {
        scene,
        quality,
        effects: repr.effects.value,
        path,
        motions: repr.motions.into_iter().map(|m| m.value).collect(),
    })
}

/// The values a motion reaches at its extremes, per slot: an oscillation's
/// `center ± amplitude`, an orbit's centre `± radius` across x and z.
fn extremes(motion: &Motion) -> Vec<(String, f64)> {
    match motion {
        Motion::Oscillate {
            name,
            center,
            amplitude,
            ..
        } => vec![
            (name.clone(), center - amplitude),
            (name.clone(), center + amplitude),
        ],
        Motion::Orbit {
            name,
            center,
            radius,
            ..
        } => vec![
            (format!("{name}.x"), center.x - radius),
            (format!("{name}.x"), center.x + radius),
            (format!("{name}.y"), center.y),
            (format!("{name}.z"), center.z - radius),
            (format!("{name}.z"), center.z + radius),
        ],
    }
}

/// RON with `Some` optional around values (`supersampling: 2`), and room
/// for [`MAX_NESTING`] levels of nodes (each takes a few of RON's levels).
fn options() -> ron::Options {
    ron::Options::default()
        .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
        .with_recursion_limit(4 * MAX_NESTING + 16)
}

/// The version field alone; every other field is skipped.
#[derive(Deserialize)]
struct VersionOnly {
    version: u32,
}

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
const STOP: &str = "fractal-sdf: stop at the marked site";

/// Numbering sites while parsing.
struct Sites;

impl Sites {
    /// Runs `parse` with sites numbered from 0 (and `stop` marked), then
    /// clears the counter.
    fn run<T>(stop: Option<usize>, parse: impl FnOnce() -> T) -> T {
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

    fn counting<T>(parse: impl FnOnce() -> T) -> T {
        Self::run(None, parse)
    }
}

/// The line and column where the parser meets `site`.
fn locate(text: &str, site: usize) -> Option<(usize, usize)> {
    let result: ron::error::SpannedResult<FileRepr> =
        Sites::run(Some(site), || options().from_str(text));
    match result {
        Err(e) if e.code == ron::Error::Message(STOP.into()) => {
            Some(skip_blank(text, e.span.end.line, e.span.end.col))
        }
        _ => None,
    }
}

/// Every name a file may write before `(`: the nodes, the parameter forms,
/// and the enum variants and structs of the settings.
const NAMES: &[&str] = &[
    "Sphere",
    "Cuboid",
    "RoundBox",
    "Torus",
    "Cylinder",
    "Capsule",
    "Plane",
    "Octahedron",
    "CappedCone",
    "Ellipsoid",
    "Mandelbulb",
    "Menger",
    "Julia",
    "Sierpinski",
    "Translate",
    "Rotate",
    "Scale",
    "Mirror",
    "Round",
    "Onion",
    "Elongate",
    "Repeat",
    "RepeatLimited",
    "Twist",
    "Bend",
    "Color",
    "Material",
    "Union",
    "Subtract",
    "Intersect",
    "SmoothUnion",
    "SmoothSubtract",
    "SmoothIntersect",
    "Cut",
    "SmoothCut",
    "Custom",
    "param",
    "param3",
    "Some",
    "Perspective",
    "Orthographic",
    "Directional",
    "Point",
    "Oscillate",
    "Orbit",
    "Camera",
    "Light",
    "Glow",
    "Effects",
    "Keyframe",
];

/// The first name written before `(` that is not one of [`NAMES`] (outside
/// strings and comments), with its byte offset.
fn unknown_name(text: &str) -> Option<(usize, &str)> {
    let bytes = text.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => {
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
            }
            b'r' if text[i..].starts_with("r#") || text[i..].starts_with("r\"") => {
                let hashes = text[i + 1..].bytes().take_while(|&b| b == b'#').count();
                let close = format!("\"{}", "#".repeat(hashes));
                let body = i + 2 + hashes;
                i = text
                    .get(body..)
                    .and_then(|rest| rest.find(&close))
                    .map_or(bytes.len(), |at| body + at + close.len());
            }
            b'/' if text[i..].starts_with("//") => {
                i = text[i..].find('\n').map_or(bytes.len(), |at| i + at);
            }
            b'/' if text[i..].starts_with("/*") => {
                i = text[i + 2..]
                    .find("*/")
                    .map_or(bytes.len(), |at| i + 2 + at + 2);
            }
            b if b.is_ascii_alphabetic() || b == b'_' => {
                let start = i;
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                    i += 1;
                }
                let name = &text[start..i];
                let next = text[i..].trim_start();
                if next.starts_with('(') && !NAMES.contains(&name) {
                    return Some((start, name));
                }
            }
            _ => i += 1,
        }
    }
    None
}

/// The line and column (from 1, in characters) of byte `offset` of `text`.
fn line_and_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
    (line, column)
}

/// The first line and column at or after (`line`, `column`) that is not
/// white space or a comment: where the value there starts.
fn skip_blank(text: &str, line: usize, column: usize) -> (usize, usize) {
    let (mut line, mut column) = (line, column);
    let mut rest = text
        .split_inclusive('\n')
        .nth(line.saturating_sub(1))
        .map(|l| l.chars().skip(column.saturating_sub(1)).collect::<String>())
        .unwrap_or_default();
    let mut lines = text.split_inclusive('\n').skip(line);
    loop {
        let trimmed = rest.trim_start();
        column += rest.chars().count() - trimmed.chars().count();
        if !trimmed.is_empty() && !trimmed.starts_with("//") {
            return (line, column);
        }
        match lines.next() {
            Some(next) => {
                rest = next.to_string();
                line += 1;
                column = 1;
            }
            None => return (line, column),
        }
    }
}

/// A value of the file with its site.
#[derive(Debug, Clone, PartialEq)]
struct Located<T> {
    site: usize,
    value: T,
}

impl<T> Located<T> {
    /// A value to write (sites matter only when reading).
    fn new(value: T) -> Self {
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

/// Which site each node of the converted tree came from.
#[derive(Default)]
struct SiteMap {
    nodes: HashMap<*const NodeKind, usize>,
}

impl SiteMap {
    fn insert(&mut self, node: &Node, site: usize) {
        self.nodes.insert(std::ptr::from_ref(node.kind()), site);
    }

    fn insert_new(&mut self, node: &Node, site: usize) {
        self.nodes
            .entry(std::ptr::from_ref(node.kind()))
            .or_insert(site);
    }

    /// The site of what a validation error names: a node's path, the
    /// camera, or a light.
    fn site_of(&self, scene: &Scene, repr: &FileRepr, e: &Error) -> Option<usize> {
        let node = match e {
            Error::Camera { .. } => return Some(repr.camera.site),
            Error::CustomShape { name, .. } => return self.custom_site(scene, name),
            Error::NonFinite { node, .. }
            | Error::OutOfRange { node, .. }
            | Error::Precision { node, .. }
            | Error::Iterations { node, .. }
            | Error::ZeroVector { node, .. } => node,
            _ => return None,
        };
        if node == "camera" {
            return Some(repr.camera.site);
        }
        if let Some(i) = node
            .strip_prefix("light[")
            .and_then(|rest| rest.strip_suffix(']'))
            .and_then(|i| i.parse::<usize>().ok())
        {
            return repr.lights.get(i).map(|l| l.site);
        }
        let mut at = scene.geometry.as_ref()?;
        for step in node.split('/').skip(1) {
            let children = at.kind().children();
            at = match step.split_once(':') {
                Some(("b", _)) => children.get(1)?,
                _ => children.first()?,
            };
        }
        self.nodes.get(&std::ptr::from_ref(at.kind())).copied()
    }

    /// The site of the first node of the custom shape `name`.
    fn custom_site(&self, scene: &Scene, name: &str) -> Option<usize> {
        let mut stack = vec![scene.geometry.as_ref()?];
        while let Some(node) = stack.pop() {
            if let Kind::Custom { shape, .. } = node.kind()
                && shape.name() == name
            {
                return self.nodes.get(&std::ptr::from_ref(node.kind())).copied();
            }
            stack.extend(node.kind().children().into_iter().rev());
        }
        None
    }
}

// ---------------------------------------------------------------------------
// The file's shape

/// A whole file.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileRepr {
    version: u32,
    geometry: Located<NodeRepr>,
    #[serde(default)]
    camera: Located<Camera>,
    #[serde(default = "default_lights")]
    lights: Vec<Located<Light>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    quality: Option<Located<QualityRepr>>,
    #[serde(default)]
    effects: Located<Effects>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    path: Option<Located<Vec<Keyframe>>>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    motions: Vec<Located<Motion>>,
}

fn default_lights() -> Vec<Located<Light>> {
    Scene::empty()
        .lights
        .into_iter()
        .map(Located::new)
        .collect()
}

/// A quality preset and the settings that differ from it.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct QualityRepr {
    preset: Preset,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    max_steps: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    detail: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    hit_epsilon: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    max_distance: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    normal_epsilon: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    ao_samples: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    shadow_steps: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    fractal_iterations: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    precision: Option<Precision>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    over_relaxation: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    supersampling: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    fast_math: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    resolution_scale: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cone_tile: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    bounces: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    brute_step: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    screen_normals: Option<ScreenNormals>,
}

impl QualityRepr {
    /// The preset `quality` differs least from, and the differences.
    fn from_quality(quality: &Quality) -> Self {
        let diff = |preset: Preset| {
            let p = preset.quality();
            let differs = |same: bool| (!same).then_some(());
            QualityRepr {
                preset,
                max_steps: differs(p.max_steps == quality.max_steps).map(|()| quality.max_steps),
                detail: differs(p.detail == quality.detail).map(|()| quality.detail),
                hit_epsilon: differs(p.hit_epsilon == quality.hit_epsilon)
                    .map(|()| quality.hit_epsilon),
                max_distance: differs(p.max_distance == quality.max_distance)
                    .map(|()| quality.max_distance),
                normal_epsilon: differs(p.normal_epsilon == quality.normal_epsilon)
                    .map(|()| quality.normal_epsilon),
                ao_samples: differs(p.ao_samples == quality.ao_samples)
                    .map(|()| quality.ao_samples),
                shadow_steps: differs(p.shadow_steps == quality.shadow_steps)
                    .map(|()| quality.shadow_steps),
                // No preset caps iterations: a cap is always written.
                fractal_iterations: quality.fractal_iterations,
                precision: differs(p.precision == quality.precision).map(|()| quality.precision),
                over_relaxation: differs(p.over_relaxation == quality.over_relaxation)
                    .map(|()| quality.over_relaxation),
                supersampling: differs(p.supersampling == quality.supersampling)
                    .map(|()| quality.supersampling),
                fast_math: differs(p.fast_math == quality.fast_math).map(|()| quality.fast_math),
                resolution_scale: differs(p.resolution_scale == quality.resolution_scale)
                    .map(|()| quality.resolution_scale),
                cone_tile: differs(p.cone_tile == quality.cone_tile).map(|()| quality.cone_tile),
                bounces: differs(p.bounces == quality.bounces).map(|()| quality.bounces),
                brute_step: differs(p.brute_step == quality.brute_step)
                    .map(|()| quality.brute_step),
                screen_normals: differs(p.screen_normals == quality.screen_normals)
                    .map(|()| quality.screen_normals),
            }
        };
        Preset::ALL
            .into_iter()
            .rev()
            .map(diff)
            .min_by_key(QualityRepr::changes)
            .expect("four presets")
    }

    fn changes(&self) -> usize {
        [
            self.max_steps.is_some(),
            self.detail.is_some(),
            self.hit_epsilon.is_some(),
            self.max_distance.is_some(),
            self.normal_epsilon.is_some(),
            self.ao_samples.is_some(),
            self.shadow_steps.is_some(),
            self.fractal_iterations.is_some(),
            self.precision.is_some(),
            self.over_relaxation.is_some(),
            self.supersampling.is_some(),
            self.fast_math.is_some(),
            self.resolution_scale.is_some(),
            self.cone_tile.is_some(),
            self.bounces.is_some(),
            self.brute_step.is_some(),
            self.screen_normals.is_some(),
        ]
        .into_iter()
        .filter(|&b| b)
        .count()
    }

    fn to_quality(&self) -> Quality {
        let p = self.preset.quality();
        Quality {
            max_steps: self.max_steps.unwrap_or(p.max_steps),
            detail: self.detail.unwrap_or(p.detail),
            hit_epsilon: self.hit_epsilon.unwrap_or(p.hit_epsilon),
            max_distance: self.max_distance.unwrap_or(p.max_distance),
            normal_epsilon: self.normal_epsilon.unwrap_or(p.normal_epsilon),
            ao_samples: self.ao_samples.unwrap_or(p.ao_samples),
            shadow_steps: self.shadow_steps.unwrap_or(p.shadow_steps),
            fractal_iterations: self.fractal_iterations.or(p.fractal_iterations),
            precision: self.precision.unwrap_or(p.precision),
            over_relaxation: self.over_relaxation.unwrap_or(p.over_relaxation),
            supersampling: self.supersampling.unwrap_or(p.supersampling),
            fast_math: self.fast_math.unwrap_or(p.fast_math),
            resolution_scale: self.resolution_scale.unwrap_or(p.resolution_scale),
            cone_tile: self.cone_tile.unwrap_or(p.cone_tile),
            bounces: self.bounces.unwrap_or(p.bounces),
            brute_step: self.brute_step.unwrap_or(p.brute_step),
            screen_normals: self.screen_normals.unwrap_or(p.screen_normals),
        }
    }
}

type Child = Box<Located<NodeRepr>>;

fn twelve() -> u32 {
    12
}
fn two() -> Param {
    Param::Value(2.0)
}
fn three() -> Param {
    Param::Value(3.0)
}
fn four() -> Param {
    Param::Value(4.0)
}
fn zero() -> Param {
    Param::Value(0.0)
}

/// A material as written in a file: only the values that differ from
/// [`Material::default`] need be named.
#[derive(Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
struct MaterialRepr {
    #[serde(skip_serializing_if = "Option::is_none")]
    roughness: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    specular: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    shininess: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    subsurface: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    scatter_depth: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    reflectivity: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    transparency: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    ior: Option<Param>,
}

impl MaterialRepr {
    fn from_material(m: &Material) -> Self {
        let defaults = Material::default();
        let [a, b, c, d, e, f, g, h] = std::array::from_fn(|i| {
            let (value, default) = (m.values()[i], defaults.values()[i]);
            (value != default).then(|| value.clone())
        });
        MaterialRepr {
            roughness: a,
            specular: b,
            shininess: c,
            subsurface: d,
            scatter_depth: e,
            reflectivity: f,
            transparency: g,
            ior: h,
        }
    }

    fn to_material(&self) -> Material {
        let defaults = Material::default();
        let given = [
            &self.roughness,
            &self.specular,
            &self.shininess,
            &self.subsurface,
            &self.scatter_depth,
            &self.reflectivity,
            &self.transparency,
            &self.ior,
        ];
        Material::from_values(std::array::from_fn(|i| {
            given[i]
                .clone()
                .unwrap_or_else(|| defaults.values()[i].clone())
        }))
    }
}

/// A node as written in a file.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
enum NodeRepr {
    Sphere {
        radius: Param,
    },
    Cuboid {
        half_extents: Param3,
    },
    RoundBox {
        half_extents: Param3,
        radius: Param,
    },
    Torus {
        major_radius: Param,
        minor_radius: Param,
    },
    Cylinder {
        radius: Param,
        half_height: Param,
    },
    Capsule {
        a: Param3,
        b: Param3,
        radius: Param,
    },
    Plane {
        normal: Param3,
        offset: Param,
    },
    Octahedron {
        size: Param,
    },
    CappedCone {
        half_height: Param,
        bottom_radius: Param,
        top_radius: Param,
    },
    Ellipsoid {
        radii: Param3,
    },
    Mandelbulb {
        power: Param,
        #[serde(default = "twelve")]
        iterations: u32,
        #[serde(default = "two")]
        bailout: Param,
    },
    Menger {
        iterations: u32,
        #[serde(default = "three")]
        scale: Param,
    },
    Julia {
        c: [Param; 4],
        #[serde(default = "twelve")]
        iterations: u32,
        #[serde(default = "four")]
        bailout: Param,
        #[serde(default = "zero")]
        slice_w: Param,
    },
    Sierpinski {
        iterations: u32,
        #[serde(default = "two")]
        scale: Param,
    },
    Translate {
        offset: Param3,
        child: Child,
    },
    Rotate {
        axis: DVec3,
        angle: Param,
        child: Child,
    },
    Scale {
        factor: Param,
        child: Child,
    },
    Mirror {
        axis: Axis,
        child: Child,
    },
    Round {
        radius: Param,
        child: Child,
    },
    Onion {
        thickness: Param,
        child: Child,
    },
    Elongate {
        extents: Param3,
        child: Child,
    },
    Repeat {
        period: Param3,
        child: Child,
    },
    RepeatLimited {
        period: Param3,
        limit: [u32; 3],
        child: Child,
    },
    Twist {
        rate: Param,
        child: Child,
    },
    Bend {
        rate: Param,
        child: Child,
    },
    Color {
        color: Param3,
        child: Child,
    },
    Material {
        material: MaterialRepr,
        child: Child,
    },
    Union(Vec<Located<NodeRepr>>),
    Subtract {
        a: Child,
        b: Child,
    },
    Intersect {
        a: Child,
        b: Child,
    },
    SmoothUnion {
        k: Param,
        a: Child,
        b: Child,
    },
    SmoothSubtract {
        k: Param,
        a: Child,
        b: Child,
    },
    SmoothIntersect {
        k: Param,
        a: Child,
        b: Child,
    },
    Cut {
        a: Child,
        b: Child,
    },
    SmoothCut {
        k: Param,
        a: Child,
        b: Child,
    },
    Custom {
        name: String,
        args: Vec<Param>,
    },
}

/// How deep `node` nests in a file: a chain of hard unions down their
/// first operands is one `Union([...])`, one level. Counted without
/// recursion.
fn nesting(node: &Node) -> usize {
    let mut deepest = 0;
    let mut stack = vec![(node, 1)];
    while let Some((node, level)) = stack.pop() {
        deepest = deepest.max(level);
        match union_operands(node) {
            Some(operands) => stack.extend(operands.into_iter().map(|n| (n, level + 1))),
            None => stack.extend(node.kind().children().into_iter().map(|n| (n, level + 1))),
        }
    }
    deepest
}

/// The operands of a chain of hard unions down their first operands, in
/// order (`(a ∪ b) ∪ c` gives `a, b, c`), or `None` if `node` is not a
/// hard union.
fn union_operands(node: &Node) -> Option<Vec<&Node>> {
    let is_union = |n: &Node| {
        matches!(
            n.kind(),
            Kind::Csg {
                op: CsgOp::Union,
                smoothing: None,
                ..
            }
        )
    };
    if !is_union(node) {
        return None;
    }
    let mut tail = Vec::new();
    let mut at = node;
    while let Kind::Csg { a, b, .. } = at.kind() {
        if !is_union(at) {
            break;
        }
        tail.push(b);
        at = a;
    }
    tail.push(at);
    tail.reverse();
    Some(tail)
}

impl NodeRepr {
    /// The file form of `node` (nested at most [`MAX_NESTING`] deep).
    fn from_node(node: &Node) -> NodeRepr {
        let child = |c: &Node| Box::new(Located::new(NodeRepr::from_node(c)));
        if let Some(operands) = union_operands(node) {
            return NodeRepr::Union(
                operands
                    .into_iter()
                    .map(|n| Located::new(NodeRepr::from_node(n)))
                    .collect(),
            );
        }
        match node.kind().clone() {
            Kind::Sphere { radius } => NodeRepr::Sphere { radius },
            Kind::Cuboid { half_extents } => NodeRepr::Cuboid { half_extents },
            Kind::RoundBox {
                half_extents,
                radius,
            } => NodeRepr::RoundBox {
                half_extents,
                radius,
            },
            Kind::Torus {
                major_radius,
                minor_radius,
            } => NodeRepr::Torus {
                major_radius,
                minor_radius,
            },
            Kind::Cylinder {
                radius,
                half_height,
            } => NodeRepr::Cylinder {
                radius,
                half_height,
            },
            Kind::Capsule { a, b, radius } => NodeRepr::Capsule { a, b, radius },
            Kind::Plane { normal, offset } => NodeRepr::Plane { normal, offset },
            Kind::Octahedron { size } => NodeRepr::Octahedron { size },
            Kind::CappedCone {
                half_height,
                bottom_radius,
                top_radius,
            } => NodeRepr::CappedCone {
                half_height,
                bottom_radius,
                top_radius,
            },
            Kind::Ellipsoid { radii } => NodeRepr::Ellipsoid { radii },
            Kind::Mandelbulb(Mandelbulb {
                power,
                iterations,
                bailout,
            }) => NodeRepr::Mandelbulb {
                power,
                iterations,
                bailout,
            },
            Kind::Menger(Menger { iterations, scale }) => NodeRepr::Menger { iterations, scale },
            Kind::Julia(QuaternionJulia {
                c,
                iterations,
                bailout,
                slice_w,
            }) => NodeRepr::Julia {
                c,
                iterations,
                bailout,
                slice_w,
            },
            Kind::Sierpinski(Sierpinski { iterations, scale }) => {
                NodeRepr::Sierpinski { iterations, scale }
            }
            Kind::Translate { offset, child: c } => NodeRepr::Translate {
                offset,
                child: child(&c),
            },
            Kind::Rotate {
                axis,
                angle,
                child: c,
            } => NodeRepr::Rotate {
                axis,
                angle,
                child: child(&c),
            },
            Kind::Scale { factor, child: c } => NodeRepr::Scale {
                factor,
                child: child(&c),
            },
            Kind::Mirror { axis, child: c } => NodeRepr::Mirror {
                axis,
                child: child(&c),
            },
            Kind::Round { radius, child: c } => NodeRepr::Round {
                radius,
                child: child(&c),
            },
            Kind::Onion {
                thickness,
                child: c,
            } => NodeRepr::Onion {
                thickness,
                child: child(&c),
            },
            Kind::Elongate { extents, child: c } => NodeRepr::Elongate {
                extents,
                child: child(&c),
            },
            Kind::Repeat { period, child: c } => NodeRepr::Repeat {
                period,
                child: child(&c),
            },
            Kind::RepeatLimited {
                period,
                limit,
                child: c,
            } => NodeRepr::RepeatLimited {
                period,
                limit,
                child: child(&c),
            },
            Kind::Twist { rate, child: c } => NodeRepr::Twist {
                rate,
                child: child(&c),
            },
            Kind::Bend { rate, child: c } => NodeRepr::Bend {
                rate,
                child: child(&c),
            },
            Kind::Color { color, child: c } => NodeRepr::Color {
                color,
                child: child(&c),
            },
            Kind::Material { material, child: c } => NodeRepr::Material {
                material: MaterialRepr::from_material(&material),
                child: child(&c),
            },
            Kind::Csg {
                op,
                smoothing,
                a,
                b,
            } => {
                let (a, b) = (child(&a), child(&b));
                match (op, smoothing) {
                    (CsgOp::Union, None) => NodeRepr::Union(vec![*a, *b]),
                    (CsgOp::Subtract, None) => NodeRepr::Subtract { a, b },
                    (CsgOp::Intersect, None) => NodeRepr::Intersect { a, b },
                    (CsgOp::Union, Some(k)) => NodeRepr::SmoothUnion { k, a, b },
                    (CsgOp::Subtract, Some(k)) => NodeRepr::SmoothSubtract { k, a, b },
                    (CsgOp::Intersect, Some(k)) => NodeRepr::SmoothIntersect { k, a, b },
                    (CsgOp::Cut, None) => NodeRepr::Cut { a, b },
                    (CsgOp::Cut, Some(k)) => NodeRepr::SmoothCut { k, a, b },
                }
            }
            Kind::Custom { shape, args } => NodeRepr::Custom {
                name: shape.name().to_string(),
                args,
            },
        }
    }
}

impl Located<NodeRepr> {
    /// The node this file node describes, recording where each node came
    /// from. `level` is its nesting (the parser bounds it); an error names
    /// the site it belongs to.
    fn to_node(
        &self,
        shapes: &[CustomShape],
        sites: &mut SiteMap,
        level: usize,
    ) -> std::result::Result<Node, (usize, Error)> {
        let site = self.site;
        let fail = |reason: String| {
            (
                site,
                Error::Invalid {
                    what: "scene file",
                    reason,
                },
            )
        };
        if level > MAX_NESTING {
            return Err(fail(format!(
                "nodes are nested more than {MAX_NESTING} deep"
            )));
        }
        let mut child = |c: &Child| c.to_node(shapes, sites, level + 1);
        let csg = |op, smoothing: Option<&Param>, a: Node, b: Node| -> Node {
            Kind::Csg {
                op,
                smoothing: smoothing.cloned(),
                a,
                b,
            }
            .into()
        };
        let node: Node = match &self.value {
            NodeRepr::Sphere { radius } => Kind::Sphere {
                radius: radius.clone(),
            }
            .into(),
            NodeRepr::Cuboid { half_extents } => Kind::Cuboid {
                half_extents: half_extents.clone(),
            }
            .into(),
            NodeRepr::RoundBox {
                half_extents,
                radius,
            } => Kind::RoundBox {
                half_extents: half_extents.clone(),
                radius: radius.clone(),
            }
            .into(),
            NodeRepr::Torus {
                major_radius,
                minor_radius,
            } => Kind::Torus {
                major_radius: major_radius.clone(),
                minor_radius: minor_radius.clone(),
            }
            .into(),
            NodeRepr::Cylinder {
                radius,
                half_height,
            } => Kind::Cylinder {
                radius: radius.clone(),
                half_height: half_height.clone(),
            }
            .into(),
            NodeRepr::Capsule { a, b, radius } => Kind::Capsule {
                a: a.clone(),
                b: b.clone(),
                radius: radius.clone(),
            }
            .into(),
            NodeRepr::Plane { normal, offset } => Kind::Plane {
                normal: normal.clone(),
                offset: offset.clone(),
            }
            .into(),
            NodeRepr::Octahedron { size } => Kind::Octahedron { size: size.clone() }.into(),
            NodeRepr::CappedCone {
                half_height,
                bottom_radius,
                top_radius,
            } => Kind::CappedCone {
                half_height: half_height.clone(),
                bottom_radius: bottom_radius.clone(),
                top_radius: top_radius.clone(),
            }
            .into(),
            NodeRepr::Ellipsoid { radii } => Kind::Ellipsoid {
                radii: radii.clone(),
            }
            .into(),
            NodeRepr::Mandelbulb {
                power,
                iterations,
                bailout,
            } => Mandelbulb {
                power: power.clone(),
                iterations: *iterations,
                bailout: bailout.clone(),
            }
            .into(),
            NodeRepr::Menger { iterations, scale } => Menger {
                iterations: *iterations,
                scale: scale.clone(),
            }
            .into(),
            NodeRepr::Julia {
                c,
                iterations,
                bailout,
                slice_w,
            } => QuaternionJulia {
                c: c.clone(),
                iterations: *iterations,
                bailout: bailout.clone(),
                slice_w: slice_w.clone(),
            }
            .into(),
            NodeRepr::Sierpinski { iterations, scale } => Sierpinski {
                iterations: *iterations,
                scale: scale.clone(),
            }
            .into(),
            NodeRepr::Translate { offset, child: c } => Kind::Translate {
                offset: offset.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Rotate {
                axis,
                angle,
                child: c,
            } => Kind::Rotate {
                axis: *axis,
                angle: angle.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Scale { factor, child: c } => Kind::Scale {
                factor: factor.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Mirror { axis, child: c } => Kind::Mirror {
                axis: *axis,
                child: child(c)?,
            }
            .into(),
            NodeRepr::Round { radius, child: c } => Kind::Round {
                radius: radius.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Onion {
                thickness,
                child: c,
            } => Kind::Onion {
                thickness: thickness.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Elongate { extents, child: c } => Kind::Elongate {
                extents: extents.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Repeat { period, child: c } => Kind::Repeat {
                period: period.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::RepeatLimited {
                period,
                limit,
                child: c,
            } => Kind::RepeatLimited {
                period: period.clone(),
                limit: *limit,
                child: child(c)?,
            }
            .into(),
            NodeRepr::Twist { rate, child: c } => Kind::Twist {
                rate: rate.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Bend { rate, child: c } => Kind::Bend {
                rate: rate.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Color { color, child: c } => Kind::Color {
                color: color.clone(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Material { material, child: c } => Kind::Material {
                material: material.to_material(),
                child: child(c)?,
            }
            .into(),
            NodeRepr::Union(operands) => {
                let mut operands = operands.iter();
                let first = operands
                    .next()
                    .ok_or_else(|| fail("a union needs at least one operand".into()))?;
                let mut node = first.to_node(shapes, sites, level + 1)?;
                for operand in operands {
                    let b = operand.to_node(shapes, sites, level + 1)?;
                    node = csg(CsgOp::Union, None, node, b);
                    // Each union of the chain stands at the list.
                    sites.insert(&node, site);
                }
                node
            }
            NodeRepr::Subtract { a, b } => csg(CsgOp::Subtract, None, child(a)?, child(b)?),
            NodeRepr::Intersect { a, b } => csg(CsgOp::Intersect, None, child(a)?, child(b)?),
            NodeRepr::SmoothUnion { k, a, b } => csg(CsgOp::Union, Some(k), child(a)?, child(b)?),
            NodeRepr::SmoothSubtract { k, a, b } => {
                csg(CsgOp::Subtract, Some(k), child(a)?, child(b)?)
            }
            NodeRepr::SmoothIntersect { k, a, b } => {
                csg(CsgOp::Intersect, Some(k), child(a)?, child(b)?)
            }
            NodeRepr::Cut { a, b } => csg(CsgOp::Cut, None, child(a)?, child(b)?),
            NodeRepr::SmoothCut { k, a, b } => csg(CsgOp::Cut, Some(k), child(a)?, child(b)?),
            NodeRepr::Custom { name, args } => {
                // Shapes given first, then the built-in inside shapes.
                let builtin = InsideShape::builtin(name).map(CustomShape::from);
                let shape = shapes
                    .iter()
                    .find(|s| s.name() == name)
                    .or(builtin.as_ref());
                let shape = shape.ok_or_else(|| {
                    let known: Vec<&str> = shapes.iter().map(CustomShape::name).collect();
                    fail(if known.is_empty() {
                        format!(
                            "no custom shape named `{name}` was given to read this file with \
                             (`SceneFile::parse_with` or `load_with` take them), and no built-in \
                             inside shape has that name"
                        )
                    } else {
                        format!(
                            "no custom shape named `{name}`; the shapes given are {}",
                            known.join(", ")
                        )
                    })
                })?;
                Kind::Custom {
                    shape: shape.clone(),
                    args: args.clone(),
                }
                .into()
            }
        };
        // A one-operand union is its operand, which keeps its own site.
        sites.insert_new(&node, site);
        Ok(node)
    }
}

// ---------------------------------------------------------------------------
// Parameters: a number, or `param("name", default)`; vectors `(x, y, z)`,
// one number, or `param3("name", (x, y, z))`.

impl Serialize for Param {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            Param::Value(v) => s.serialize_f64(*v),
            Param::Dynamic { name, default } => {
                // A tuple variant, so that RON writes its name.
                let mut t = s.serialize_tuple_variant("Param", 1, "param", 2)?;
                t.serialize_field(name)?;
                t.serialize_field(default)?;
                t.end()
            }
        }
    }
}

/// What one item of a parameter's syntax is: a number, a name (the first
/// item of `param3(..)`), or a dynamic parameter.
enum Item {
    Param(Param),
    Name(String),
}

struct ItemVisitor;

impl<'de> Visitor<'de> for ItemVisitor {
    type Value = Item;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number or param(\"name\", default)")
    }

    fn visit_f64<E>(self, v: f64) -> std::result::Result<Item, E> {
        Ok(Item::Param(Param::Value(v)))
    }

    #[allow(clippy::cast_precision_loss)] // Integers in a file are sizes and counts.
    fn visit_i64<E>(self, v: i64) -> std::result::Result<Item, E> {
        Ok(Item::Param(Param::Value(v as f64)))
    }

    #[allow(clippy::cast_precision_loss)]
    fn visit_u64<E>(self, v: u64) -> std::result::Result<Item, E> {
        Ok(Item::Param(Param::Value(v as f64)))
    }

    fn visit_str<E>(self, v: &str) -> std::result::Result<Item, E> {
        Ok(Item::Name(v.to_string()))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<Item, A::Error> {
        let name: String = seq
            .next_element()?
            .ok_or_else(|| de::Error::invalid_length(0, &"param(\"name\", default)"))?;
        let default: f64 = seq
            .next_element()?
            .ok_or_else(|| de::Error::invalid_length(1, &"param(\"name\", default)"))?;
        if seq.next_element::<de::IgnoredAny>()?.is_some() {
            return Err(de::Error::invalid_length(3, &"param(\"name\", default)"));
        }
        Ok(Item::Param(Param::Dynamic { name, default }))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> std::result::Result<Item, A::Error> {
        let (mut name, mut default) = (None, None);
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "name" => name = Some(map.next_value::<String>()?),
                "default" => default = Some(map.next_value::<f64>()?),
                other => return Err(de::Error::unknown_field(other, &["name", "default"])),
            }
        }
        Ok(Item::Param(Param::Dynamic {
            name: name.ok_or_else(|| de::Error::missing_field("name"))?,
            default: default.ok_or_else(|| de::Error::missing_field("default"))?,
        }))
    }
}

impl<'de> Deserialize<'de> for Item {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_any(ItemVisitor)
    }
}

impl<'de> Deserialize<'de> for Param {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        match Item::deserialize(d)? {
            Item::Param(p) => Ok(p),
            Item::Name(name) => Err(de::Error::custom(format!(
                "expected a number or param(\"name\", default), found the string \"{name}\""
            ))),
        }
    }
}

impl Param3 {
    /// The name `n` if the three components are `param3(n, ..)`'s slots.
    fn vector_name(&self) -> Option<&str> {
        let name = self.x.name()?.strip_suffix(".x")?;
        (self.y.name()?.strip_suffix(".y")? == name && self.z.name()?.strip_suffix(".z")? == name)
            .then_some(name)
    }
}

impl Serialize for Param3 {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        if let Some(name) = self.vector_name() {
            let mut t = s.serialize_tuple_variant("Param3", 1, "param3", 2)?;
            t.serialize_field(name)?;
            t.serialize_field(&self.default_value())?;
            t.end()
        } else {
            (&self.x, &self.y, &self.z).serialize(s)
        }
    }
}

struct Param3Visitor;

impl<'de> Visitor<'de> for Param3Visitor {
    type Value = Param3;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a vector (x, y, z), a number, or param3(\"name\", (x, y, z))")
    }

    fn visit_f64<E>(self, v: f64) -> std::result::Result<Param3, E> {
        Ok(Param3::from(v))
    }

    #[allow(clippy::cast_precision_loss)]
    fn visit_i64<E>(self, v: i64) -> std::result::Result<Param3, E> {
        Ok(Param3::from(v as f64))
    }

    #[allow(clippy::cast_precision_loss)]
    fn visit_u64<E>(self, v: u64) -> std::result::Result<Param3, E> {
        Ok(Param3::from(v as f64))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<Param3, A::Error> {
        let short = |n| de::Error::invalid_length(n, &Param3Visitor);
        match seq.next_element::<Item>()?.ok_or_else(|| short(0))? {
            Item::Name(name) => {
                let default: DVec3 = seq.next_element()?.ok_or_else(|| short(1))?;
                if seq.next_element::<de::IgnoredAny>()?.is_some() {
                    return Err(short(3));
                }
                Ok(param3(&name, default))
            }
            Item::Param(x) => {
                let y: Param = seq.next_element()?.ok_or_else(|| short(1))?;
                let z: Param = seq.next_element()?.ok_or_else(|| short(2))?;
                if seq.next_element::<de::IgnoredAny>()?.is_some() {
                    return Err(short(4));
                }
                Ok(Param3 { x, y, z })
            }
        }
    }
}

impl<'de> Deserialize<'de> for Param3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_any(Param3Visitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{param, sphere};

    #[test]
    fn a_chain_of_unions_is_one_level() {
        let mut scene = Scene::empty();
        for i in 0..1000 {
            scene = scene.add(sphere(0.1).translate(DVec3::new(f64::from(i), 0.0, 0.0)));
        }
        let geometry = scene.geometry.as_ref().unwrap();
        assert_eq!(nesting(geometry), 3);
        let file = SceneFile::new(scene.clone());
        let back = SceneFile::parse(&file.to_text().unwrap()).unwrap();
        assert_eq!(back.scene, scene);
    }

    #[test]
    fn dynamic_parameters_keep_their_names() {
        let node = sphere(param("r", 0.5)).translate(param3("at", DVec3::X));
        let text = SceneFile::new(Scene::new(node.clone())).to_text().unwrap();
        assert!(text.contains("param(\"r\", 0.5)"), "{text}");
        assert!(text.contains("param3(\"at\", (1.0, 0.0, 0.0))"), "{text}");
        assert_eq!(SceneFile::parse(&text).unwrap().scene.geometry, Some(node));
    }
}
