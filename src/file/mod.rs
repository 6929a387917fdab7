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
//! The [reference](mod@reference) lists every node, field, unit and default: shapes,
//! fractals, operations, booleans, cut planes (`CutPlane(normal: ..,
//! offset: .., child: ..)`), materials, the camera, lights, quality,
//! effects, camera paths and motions. **Angles are in radians** (the
//! camera's `fov_y_degrees` says its own unit), as in the Rust API and
//! for dynamic parameters.
//!
//! - **Nodes** are written as in Rust's [`Kind`], with
//!   the booleans named: `Union([a, b, ...])` (any number of operands, what
//!   [`Scene::add`] builds), `Subtract(a: .., b: ..)`, `Intersect(a: ..,
//!   b: ..)`, `SmoothUnion(k: 0.1, a: .., b: ..)` and the other smooth
//!   forms, and `Custom(name: "gyroid", args: [0.1])` for a shape passed to
//!   [`SceneFile::parse_with`] or a built-in inside shape
//!   ([`InsideShape::builtin`](crate::scene::InsideShape::builtin): `Custom(name: "mandelbox_escape", args:
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
//! use fractal_sdf::file::SceneFile;
//!
//! let file = SceneFile::parse("(version: 1, geometry: Sphere(radius: 1))")?;
//! assert_eq!(file.scene.geometry, Some(sphere(1.0)));
//!
//! let err = SceneFile::parse("(version: 1,\n geometry: Sphere(radius: -1))").unwrap_err();
//! assert_eq!(err.to_string(), "<scene>:2:12: sphere: parameter `radius` must be >= 0, got -1");
//! # Ok::<(), fractal_sdf::Error>(())
//! ```

use std::io::Write;
use std::path::Path;

use serde::Deserialize;

mod catalogue;
mod convert;
mod layout;
mod locate;
pub mod reference;
mod schema;
mod sites;
mod values;

pub use catalogue::{NodeCategory, NodeKindInfo, node_kinds};
use convert::nesting;
use layout::layout;
use locate::{SiteMap, line_and_column, locate, unknown_name};
use schema::{EnvironmentRepr, FileRepr, FormulaParam, FormulaRepr, NodeRepr, QualityRepr};
use sites::{Located, Sites};

use crate::animation::{CameraPath, Motion};
use crate::error::{Error, Result};
use crate::quality::{Effects, Precision, Quality};
use crate::scene::{CustomShape, Environment, EnvironmentMap, Kind, Node, Rule, Scene};

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
#[non_exhaustive]
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
        read(text, Path::new(TEXT), Path::new(""), shapes)
    }

    /// Reads a scene file's text as if it lay in `folder`: the image of
    /// its environment, named relative to the file, is found there (with
    /// [`SceneFile::parse`], in the working directory).
    ///
    /// # Errors
    /// As [`SceneFile::parse`].
    pub fn parse_in(text: &str, folder: impl AsRef<Path>) -> Result<Self> {
        read(text, Path::new(TEXT), folder.as_ref(), &[])
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
        let folder = path.parent().unwrap_or(Path::new(""));
        read(&text, path, folder, shapes)
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
        let environment = match &self.scene.environment {
            Some(e) => {
                e.validate()?;
                let image = e.source.clone().ok_or_else(|| {
                    invalid(
                        "its environment's image was made in memory, and a scene file names \
                         an image file: write it with `EnvironmentMap::save_hdr` and name it \
                         with `Environment::source`"
                            .into(),
                    )
                })?;
                Some(Located::new(EnvironmentRepr {
                    image,
                    rotation_degrees: e.rotation_degrees,
                    intensity: e.intensity,
                }))
            }
            None => None,
        };
        let nesting = nesting(geometry);
        if nesting > MAX_NESTING {
            return Err(invalid(format!(
                "its nodes are nested {nesting} deep; a scene file holds at most {MAX_NESTING}"
            )));
        }
        let repr = FileRepr {
            version: FORMAT_VERSION,
            formulas: formulas(geometry)
                .into_iter()
                .map(|(shape, text)| {
                    Located::new(FormulaRepr {
                        name: shape.name().to_string(),
                        params: shape
                            .params()
                            .map(|(n, r)| FormulaParam::from_rule(n, r))
                            .collect(),
                        distance: text,
                    })
                })
                .collect(),
            geometry: Located::new(NodeRepr::from_node(geometry)),
            camera: Located::new(self.scene.camera),
            lights: self
                .scene
                .lights
                .iter()
                .copied()
                .map(Located::new)
                .collect(),
            environment,
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

/// The distinct text-formula shapes in `node`, with their texts, in the
/// order a depth-first walk first meets them (a work list: scenes may be
/// deeper than the stack).
fn formulas(node: &Node) -> Vec<(CustomShape, String)> {
    let mut out: Vec<(CustomShape, String)> = Vec::new();
    let mut todo = vec![node];
    while let Some(node) = todo.pop() {
        if let Kind::Custom { shape, .. } = node.kind()
            && let Some(text) = shape.formula_text()
            && !out.iter().any(|(s, _)| s.name() == shape.name())
        {
            out.push((shape.clone(), text.to_string()));
        }
        todo.extend(node.kind().children().into_iter().rev());
    }
    out
}

// ---------------------------------------------------------------------------
// Reading

/// Parses, converts and validates; every error located in `text`.
fn read(text: &str, file: &Path, folder: &Path, shapes: &[CustomShape]) -> Result<SceneFile> {
    // A byte order mark some editors write is not part of the text.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
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
            ron::Error::ExpectedDifferentStructName { expected, found } => format!(
                "`{found}(..)` is not a {}: write `{expected}(..)`, or just `(..)`, with \
                 the fields the scene-file reference lists",
                expected.to_lowercase()
            ),
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
    // The file's own formulas first, then the shapes given.
    let mut all: Vec<CustomShape> = Vec::with_capacity(repr.formulas.len() + shapes.len());
    for f in &repr.formulas {
        let params: Vec<(&str, Rule)> = f
            .value
            .params
            .iter()
            .map(|p| (p.name.as_str(), p.rule()))
            .collect();
        let shape = CustomShape::parse(&f.value.name, &params, &f.value.distance)
            .map_err(|e| located(f.site, e))?;
        if all.iter().any(|s| s.name() == shape.name()) {
            return Err(located(
                f.site,
                Error::CustomShape {
                    name: shape.name().to_string(),
                    reason: "two formulas have this name".into(),
                },
            ));
        }
        all.push(shape);
    }
    all.extend(shapes.iter().cloned());
    let mut sites = SiteMap::default();
    let geometry = repr
        .geometry
        .to_node(&all, &mut sites, 1)
        .map_err(|(site, e)| located(site, e))?;
    let environment = match &repr.environment {
        Some(e) => Some(read_environment(&e.value, folder).map_err(|err| located(e.site, err))?),
        None => None,
    };
    let scene = Scene {
        geometry: Some(geometry),
        lights: repr.lights.iter().map(|l| l.value).collect(),
        camera: repr.camera.value,
        environment,
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
    // Each default set again within the limits: one copy of the values,
    // each set to what it already holds.
    let mut checked = compiled.default_values();
    for slot in compiled.params().slots() {
        let value = checked.get(&slot.name).unwrap_or(f64::NAN);
        checked.set_within(&slot.name, value, limits).map_err(|e| {
            let site = sites
                .site_of(&scene, &repr, &e)
                .unwrap_or(repr.geometry.site);
            located(site, e)
        })?;
    }
    for motion in &repr.motions {
        motion
            .value
            .validate()
            .map_err(|e| located(motion.site, e))?;
        for (name, value) in extremes(&motion.value) {
            let Some(default) = checked.get(&name) else {
                let known = compiled.params().slots().iter();
                let known = known.map(|s| s.name.clone()).collect();
                return Err(located(motion.site, Error::UnknownParam { name, known }));
            };
            // Each extreme checked on the one copy, then the default back.
            checked
                .set_within(&name, value, limits)
                .and_then(|()| checked.set_within(&name, default, limits))
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

/// The environment a file names: its image read relative to `folder`,
/// the file's, and named again as the file names it.
fn read_environment(repr: &EnvironmentRepr, folder: &Path) -> Result<Environment> {
    let environment = Environment::new(EnvironmentMap::load(folder.join(&repr.image))?)
        .rotation_degrees(repr.rotation_degrees)
        .intensity(repr.intensity)
        .source(repr.image.clone());
    environment.validate()?;
    Ok(environment)
}

/// The values a motion reaches at its extremes, per slot: an oscillation's
/// `center ± amplitude`, an orbit's centre `± radius` across x and z, a
/// track's keys and samples between them.
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
        // Every key's value and, between keys, where a spline may
        // overshoot them: 32 samples a segment.
        Motion::Keys { keys, .. } => keys
            .windows(2)
            .flat_map(|w| {
                (0..32).map(move |j| w[0].time + (w[1].time - w[0].time) * f64::from(j) / 32.0)
            })
            .chain(keys.iter().map(|k| k.time))
            .flat_map(|t| motion.values(t))
            .collect(),
    }
}

/// RON with `Some` optional around values (`supersampling: 2`), and room
/// for [`MAX_NESTING`] levels of nodes (each takes a few of RON's levels).
pub(super) fn options() -> ron::Options {
    ron::Options::default()
        .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
        .with_recursion_limit(4 * MAX_NESTING + 16)
}

/// The version field alone; every other field is skipped.
#[derive(Deserialize)]
struct VersionOnly {
    version: u32,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{param, param3, sphere};
    use glam::DVec3;

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
