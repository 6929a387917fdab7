//! The crate's one error type.

use std::fmt;
use std::path::PathBuf;

/// Everything that can go wrong, from a bad scene value to an OpenCL build
/// failure. Every variant says what was wrong and where.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A parameter is NaN or infinite.
    #[error("{node}: parameter `{param}` must be finite, got {}", fmt_value(*.value))]
    NonFinite {
        /// Path of the node in the scene, such as `root/union.a/sphere`.
        node: String,
        /// The parameter's name.
        param: String,
        /// The offending value.
        value: f64,
    },
    /// A parameter is finite but outside its allowed range.
    #[error("{node}: parameter `{param}` must be {expected}, got {}", fmt_value(*.value))]
    OutOfRange {
        /// Path of the node in the scene.
        node: String,
        /// The parameter's name.
        param: String,
        /// The offending value.
        value: f64,
        /// What the value must be, such as `">= 0"`.
        expected: String,
    },
    /// A finite value the kernel's precision cannot compute with: its
    /// magnitude passes one of the precision's limits
    /// ([`math::Limits`](crate::math::Limits)), so its squares, products or
    /// quotients in the kernel would overflow, underflow or fall below
    /// what the precision resolves.
    #[error(
        "{node}: `{param}` = {} cannot be represented safely in {precision} \
         (its magnitude passes the limit {limit:e}); {}",
        fmt_value(*.value),
        precision_hint(precision)
    )]
    Precision {
        /// Path of the node in the scene, or `camera`, `light[i]`,
        /// `quality`, `effects`.
        node: String,
        /// The parameter's or setting's name.
        param: String,
        /// The offending value.
        value: f64,
        /// The precision: `"F32"` or `"F64"`.
        precision: &'static str,
        /// The limit it passes (see [`math::Limits`](crate::math::Limits)).
        limit: f64,
    },
    /// A fractal's iteration count is outside its allowed range.
    #[error("{node}: iterations must be in {min}..={max}, got {value}")]
    Iterations {
        /// Path of the node in the scene.
        node: String,
        /// The offending count.
        value: u32,
        /// The smallest allowed count.
        min: u32,
        /// The largest allowed count.
        max: u32,
    },
    /// A direction (rotation axis, plane normal, light direction) is zero.
    #[error("{node}: `{param}` must not be a zero-length vector")]
    ZeroVector {
        /// Path of the node in the scene.
        node: String,
        /// The parameter's name.
        param: String,
    },
    /// A custom shape's definition or use is invalid.
    #[error("custom shape `{name}`: {reason}")]
    CustomShape {
        /// The shape's name.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// A custom shape's text formula does not parse or check: where, and
    /// what was expected.
    #[error("custom shape `{name}`: formula line {line}, column {column}: {message}")]
    Formula {
        /// The shape's name.
        name: String,
        /// The line, from 1.
        line: usize,
        /// The column, in characters from 1.
        column: usize,
        /// What is wrong, and what was expected.
        message: String,
    },
    /// An inside shape (see [`InsideShape`](crate::scene::InsideShape))
    /// is used where a distance is needed, or its scene cannot be marched.
    #[error("inside shape `{name}` at {node}: {reason}")]
    InsideShape {
        /// The shape's name.
        name: String,
        /// Path of the node that uses it in the scene.
        node: String,
        /// What is wrong, and what is allowed instead.
        reason: String,
    },
    /// A camera path is invalid.
    #[error("camera path: {reason}")]
    Animation {
        /// What is wrong.
        reason: String,
    },
    /// A motion of a dynamic parameter ([`Motion`](crate::animation::Motion))
    /// is invalid: a period that is not a finite number above 0, or a
    /// value that is not finite.
    #[error("motion of `{name}`: `{field}` must be {expected}, got {}", fmt_value(*.value))]
    Motion {
        /// The dynamic parameter it moves.
        name: String,
        /// The field as written: `period`, `center`, `amplitude`, `radius`.
        field: &'static str,
        /// The offending value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// Text given to a parser (a key script, a frame range, a size) does
    /// not say what it should.
    #[error("invalid {what}: {reason}")]
    Invalid {
        /// What was being read, such as `"key script"`.
        what: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// A scene file cannot be read: a syntax error, an unknown node, field
    /// or custom shape, an unsupported format version, or a value that
    /// does not validate.
    #[error("{}:{line}:{column}: {reason}", file.display())]
    SceneFile {
        /// The file, or `<scene>` for text read with
        /// [`SceneFile::parse`](crate::file::SceneFile::parse).
        file: PathBuf,
        /// The line of the offending text, from 1.
        line: usize,
        /// The column (in characters) of the offending text, from 1.
        column: usize,
        /// What is wrong, with the node's path in the scene tree where a
        /// node's value is wrong (`union/b:translate/sphere: ...`).
        reason: String,
        /// The validation error, where the file parsed but a value is
        /// wrong (a scene built in Rust with that value gives this error).
        #[source]
        cause: Option<Box<Error>>,
    },
    /// The scene has no geometry.
    #[error("the scene is empty: add geometry with `Scene::new(node)` or `Scene::add`")]
    EmptyScene,
    /// An environment light ([`Environment`](crate::scene::Environment))
    /// or its image is invalid.
    #[error("environment: {reason}")]
    Environment {
        /// What is wrong.
        reason: String,
    },
    /// The camera cannot form an image.
    #[error("degenerate camera: {reason}")]
    Camera {
        /// What is wrong with it.
        reason: String,
    },
    /// A requested image size is zero or too large.
    #[error("invalid resolution {width}x{height}: {reason}")]
    Resolution {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
        /// Why it cannot be rendered.
        reason: String,
    },
    /// A quality setting is out of range.
    #[error("quality setting `{setting}` must be {expected}, got {}", fmt_value(*.value))]
    Quality {
        /// The setting's name.
        setting: &'static str,
        /// The offending value.
        value: f64,
        /// What it must be.
        expected: String,
    },
    /// An effects setting ([`Effects`](crate::quality::Effects)) is out of
    /// range.
    #[error("effects setting `{setting}` must be {expected}, got {}", fmt_value(*.value))]
    Effects {
        /// The setting's name, as a scene file writes it (`gamma`,
        /// `glow.strength`).
        setting: &'static str,
        /// The offending value.
        value: f64,
        /// What it must be.
        expected: String,
    },
    /// The renderer's tile side is zero.
    #[error("tile size must be at least 1 pixel, got {value}")]
    TileSize {
        /// The offending tile side.
        value: u32,
    },
    /// More lights than the kernel's light count can address.
    #[error("too many lights: {count} (at most {max})")]
    TooManyLights {
        /// How many lights were given.
        count: usize,
        /// The most the renderer takes.
        max: usize,
    },
    /// No dynamic parameter has this name.
    #[error(
        "the scene has no dynamic parameter named `{name}`; {}",
        known_params(known)
    )]
    UnknownParam {
        /// The name that was asked for.
        name: String,
        /// The names the scene's dynamic parameters have (a vector
        /// parameter's as `name.x`, `name.y`, `name.z`), in order.
        known: Vec<String>,
    },
    /// One dynamic parameter name is used with different defaults or by
    /// parameters with different rules.
    #[error("dynamic parameter `{name}` is declared twice with different defaults or rules")]
    ConflictingParam {
        /// The parameter's name.
        name: String,
    },
    /// A render was cancelled through its `render::CancelToken` before
    /// every tile was launched.
    #[error("render cancelled after {tiles} of {total} tiles")]
    Cancelled {
        /// Tiles launched before the cancellation was seen.
        tiles: usize,
        /// Tiles in the image.
        total: usize,
    },
    /// A render ran past its deadline before every tile was launched.
    #[error("render passed its deadline of {deadline:?} after {tiles} of {total} tiles")]
    Deadline {
        /// The time the render was given.
        deadline: std::time::Duration,
        /// Tiles launched before the deadline passed.
        tiles: usize,
        /// Tiles in the image.
        total: usize,
    },
    /// No OpenCL platform is installed.
    #[error(
        "no OpenCL platform found ({detail}); install one, e.g. on Debian: \
         `sudo apt-get install ocl-icd-opencl-dev pocl-opencl-icd`"
    )]
    NoPlatform {
        /// What the OpenCL loader said.
        detail: String,
    },
    /// No OpenCL device matches the selection.
    #[error("no OpenCL device matches {selection}; available: {available}")]
    NoDevice {
        /// The selection that found nothing.
        selection: String,
        /// The devices that exist.
        available: String,
    },
    /// A backend cannot do what was asked (the WGSL backend and double
    /// precision, say); `instead` says what can.
    #[error("the {backend} backend cannot {what}: {instead}")]
    Unsupported {
        /// The backend: `WGSL`.
        backend: &'static str,
        /// What it cannot do.
        what: String,
        /// What to do instead.
        instead: String,
    },
    /// Double precision was requested on a device without `cl_khr_fp64`.
    #[error(
        "device `{device}` does not support double precision (cl_khr_fp64); use Precision::F32"
    )]
    Fp64Unsupported {
        /// The device's name.
        device: String,
    },
    /// The OpenCL compiler rejected the generated program.
    #[error("OpenCL program build failed on `{device}`:\n{log}")]
    Build {
        /// The device it was built for.
        device: String,
        /// The compiler's build log.
        log: String,
        /// The complete generated source.
        kernel_source: String,
    },
    /// The OpenCL compiler rejected the body of a custom shape: the
    /// message is about a line of the shape's definition, told as a line
    /// of its body (see [`CustomShape`](crate::scene::CustomShape)). The
    /// whole build failure, with the full log and program, is `build`.
    #[error("custom shape `{shape}`, {}: {message}", custom_place(*line, text))]
    CustomShapeBuild {
        /// The shape's name.
        shape: String,
        /// The line of the body the compiler complained about, counted
        /// from 1 (the first line of the string the shape was given); 0
        /// for the function's signature, one past the body's last line for
        /// its closing brace.
        line: usize,
        /// The column in that line, counted from 1 (0 if the compiler did
        /// not say).
        column: usize,
        /// That line, as written.
        text: String,
        /// The compiler's message about it.
        message: String,
        /// The build failure as the compiler reported it: an
        /// [`Error::Build`] with the device, the full log (about lines of
        /// the whole program) and the program.
        #[source]
        build: Box<Error>,
    },
    /// Any other OpenCL failure.
    #[error("OpenCL error: {0}")]
    OpenCl(String),
    /// A wgpu failure: no adapter, a shader the driver rejected, a device
    /// lost.
    #[error("wgpu error: {0}")]
    Wgpu(String),
    /// Reading or writing a file failed.
    #[error("{path}: {action}: {source}")]
    Io {
        /// The file that was to be read or written (for an image, the
        /// target named by the caller, never a temporary file).
        path: PathBuf,
        /// What failed, such as `"cannot write the image"`.
        action: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// Encoding an image failed.
    #[error("image encoding failed: {0}")]
    Image(#[from] image::ImageError),
}

impl Error {
    /// The compiler's build log, for a build failure ([`Error::Build`] or
    /// [`Error::CustomShapeBuild`]).
    #[must_use]
    pub fn build_log(&self) -> Option<&str> {
        match self {
            Error::Build { log, .. } => Some(log),
            Error::CustomShapeBuild { build, .. } => build.build_log(),
            _ => None,
        }
    }

    /// The complete program that failed to build, for a build failure
    /// ([`Error::Build`] or [`Error::CustomShapeBuild`]).
    #[must_use]
    pub fn kernel_source(&self) -> Option<&str> {
        match self {
            Error::Build { kernel_source, .. } => Some(kernel_source),
            Error::CustomShapeBuild { build, .. } => build.kernel_source(),
            _ => None,
        }
    }

    /// [`Error::Io`]: `action` failed on `path` with `source`.
    pub fn io(path: impl Into<PathBuf>, action: impl Into<String>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            action: action.into(),
            source,
        }
    }
}

/// Where in a custom shape's definition a compiler message points.
fn custom_place(line: usize, text: &str) -> String {
    if line == 0 {
        format!("in its signature `{}`", text.trim())
    } else {
        format!("line {line} of its body: `{}`", text.trim())
    }
}

/// A number as error messages write it: in the shortest form that reads
/// back to the same value, in scientific notation when it is very large or
/// very small (`1e300`, `-2.5e-7`), plainly otherwise (`0.25`, `-3`,
/// `NaN`, `inf`), so a message never holds hundreds of digits.
#[must_use]
pub(crate) fn fmt_value(value: f64) -> impl fmt::Display {
    FmtValue(value)
}

struct FmtValue(f64);

impl fmt::Display for FmtValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        let magnitude = v.abs();
        if v.is_finite() && (magnitude >= 1e16 || (magnitude != 0.0 && magnitude < 1e-5)) {
            write!(f, "{v:e}")
        } else {
            write!(f, "{v}")
        }
    }
}

/// The list of dynamic parameters an [`Error::UnknownParam`] offers.
fn known_params(known: &[String]) -> String {
    if known.is_empty() {
        "it has none".into()
    } else {
        let names: Vec<String> = known.iter().map(|n| format!("`{n}`")).collect();
        format!("it has {}", names.join(", "))
    }
}

/// What an [`Error::Precision`] suggests.
fn precision_hint(precision: &str) -> &'static str {
    if precision == "F32" {
        "render in Precision::F64, or rescale the scene"
    } else {
        "rescale the scene"
    }
}

/// `Result` with the crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_print_short_and_round_trip() {
        assert_eq!(fmt_value(1e300).to_string(), "1e300");
        assert_eq!(fmt_value(-2.5e-7).to_string(), "-2.5e-7");
        assert_eq!(fmt_value(0.25).to_string(), "0.25");
        assert_eq!(fmt_value(0.5).to_string(), "0.5");
        assert_eq!(fmt_value(f64::NAN).to_string(), "NaN");
    }

    #[test]
    fn precision_errors_print_their_value_short() {
        let err = Error::Precision {
            node: "camera".into(),
            param: "position.z".into(),
            value: 1e300,
            precision: "F64",
            limit: 1e150,
        };
        assert_eq!(
            err.to_string(),
            "camera: `position.z` = 1e300 cannot be represented safely in F64 (its magnitude \
             passes the limit 1e150); rescale the scene"
        );
    }

    #[test]
    fn numbers_in_messages_are_short_and_exact() {
        let cases = [
            (1e300, "1e300"),
            (-1e300, "-1e300"),
            (f64::MAX, "1.7976931348623157e308"),
            (1e16, "1e16"),
            (9_999_999_999_999_998.0, "9999999999999998"),
            (123_456.5, "123456.5"),
            (0.1, "0.1"),
            (1e-5, "0.00001"),
            (9.5e-6, "9.5e-6"),
            (f64::MIN_POSITIVE, "2.2250738585072014e-308"),
            (5e-324, "5e-324"),
            (0.0, "0"),
            (-0.0, "-0"),
            (f64::NAN, "NaN"),
            (f64::INFINITY, "inf"),
            (f64::NEG_INFINITY, "-inf"),
        ];
        for (v, text) in cases {
            let shown = fmt_value(v).to_string();
            assert_eq!(shown, text);
            if v.is_finite() {
                assert_eq!(
                    shown.parse::<f64>().unwrap().to_bits(),
                    v.to_bits(),
                    "{text}"
                );
            }
        }
    }

    #[test]
    fn every_number_of_a_message_goes_through_the_helper() {
        let node = || "root/torus".to_string();
        let param = || "minor_radius".to_string();
        let errors = [
            Error::NonFinite {
                node: node(),
                param: param(),
                value: f64::NEG_INFINITY,
            },
            Error::OutOfRange {
                node: node(),
                param: param(),
                value: -1e300,
                expected: ">= 0".into(),
            },
            Error::Quality {
                setting: "gamma",
                value: 1e-300,
                expected: "> 0".into(),
            },
        ];
        let texts: Vec<String> = errors.iter().map(ToString::to_string).collect();
        assert_eq!(
            texts,
            [
                "root/torus: parameter `minor_radius` must be finite, got -inf",
                "root/torus: parameter `minor_radius` must be >= 0, got -1e300",
                "quality setting `gamma` must be > 0, got 1e-300",
            ]
        );
    }
}
