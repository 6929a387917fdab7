//! The crate's one error type.

use std::path::PathBuf;

/// Everything that can go wrong, from a bad scene value to an OpenCL build
/// failure. Every variant says what was wrong and where.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A parameter is NaN or infinite.
    #[error("{node}: parameter `{param}` must be finite, got {value}")]
    NonFinite {
        /// Path of the node in the scene, such as `root/union.a/sphere`.
        node: String,
        /// The parameter's name.
        param: String,
        /// The offending value.
        value: f64,
    },
    /// A parameter is finite but outside its allowed range.
    #[error("{node}: parameter `{param}` must be {expected}, got {value}")]
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
        "{node}: `{param}` = {value} cannot be represented safely in {precision} \
         (its magnitude passes the limit {limit:e}); {}",
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
    /// A camera path is invalid.
    #[error("camera path: {reason}")]
    Animation {
        /// What is wrong.
        reason: String,
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
    /// The scene has no geometry.
    #[error("the scene is empty: add geometry with `Scene::new(node)` or `Scene::add`")]
    EmptyScene,
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
    #[error("quality setting `{setting}` must be {expected}, got {value}")]
    Quality {
        /// The setting's name.
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
    #[error("the scene has no dynamic parameter named `{name}`")]
    UnknownParam {
        /// The name that was asked for.
        name: String,
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
    /// Any other OpenCL failure.
    #[error("OpenCL error: {0}")]
    OpenCl(String),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// Encoding an image failed.
    #[error("image encoding failed: {0}")]
    Image(#[from] image::ImageError),
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
