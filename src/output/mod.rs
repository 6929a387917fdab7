//! Saving images to disk, and checking saved ones.
//!
//! The format follows the file's extension: PNG, JPEG and TIFF for images
//! ([`save_image`]); with a rendered frame's layers ([`save_frame`]), also
//! OpenEXR with named layers, 16-bit PNG and TIFF, and each arbitrary
//! output value as a 16-bit PNG.
//!
//! Every error names the file the caller asked for (never a temporary
//! file) and says what failed.

mod camera;
#[cfg(feature = "opencl")]
mod layers;

pub use camera::{CameraExport, SENSOR_HEIGHT_MM};

#[cfg(feature = "opencl")]
pub use layers::{Aov, Bits, FrameOutput, aov_path, save_frame};

use std::collections::{HashMap, HashSet};
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{LazyLock, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant, SystemTime};

use image::codecs::jpeg::JpegEncoder;
use image::codecs::png::PngEncoder;
use image::codecs::tiff::TiffEncoder;
use image::{ExtendedColorType, ImageEncoder, ImageError, RgbaImage};

use crate::error::{Error, Result};

/// Saves `image` as a PNG at `path`, creating missing parent directories.
///
/// The write is atomic: the PNG goes to a temporary file in the same
/// directory (`.NAME.PID-N.png.tmp`), which is flushed to disk and then
/// renamed over the file, so a reader never sees a half-written image and
/// a failed write leaves any earlier file intact. The temporary file is
/// removed on every failure, panics included.
///
/// - **Symbolic links** are written through: the image replaces the file
///   the link points to (following chains of links; a dangling link gets
///   its target created), and the link stays.
/// - **A target that exists and is not a regular file** (a device such as
///   `/dev/stdout`, a FIFO) is written in place, not replaced. A directory
///   is refused.
/// - **Stale temporary files** — left by a process that was killed while
///   writing — are removed from the target's directory before the write:
///   files named like this function's temporary files whose process is
///   gone (on Linux: no `/proc/PID`), or that carry this process's id
///   but are not being written by it (an earlier process had the id), or,
///   on any system, that nobody has written to for
///   [`STALE_TEMPORARY_AGE`]. A directory is swept at most once per
///   [`SWEEP_INTERVAL`] by a process, so writing many frames into one
///   large directory does not list it for every frame. A process id
///   reused by another live process keeps a dead writer's file until it is
///   that old; a writer on another machine sharing the directory counts as
///   gone.
///
/// ```
/// use fractal_sdf::image::{self, Rgba, RgbaImage};
///
/// let dir = std::env::temp_dir().join("fractal-sdf-doc");
/// let image = RgbaImage::from_pixel(2, 2, Rgba([255, 0, 0, 255]));
/// fractal_sdf::output::save_png(&image, dir.join("nested/red.png"))?;
/// assert_eq!(image::open(dir.join("nested/red.png")).unwrap().to_rgba8(), image);
/// # std::fs::remove_dir_all(dir).ok();
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
///
/// # Errors
/// [`Error::Io`] naming `path` and what failed (following a link, creating
/// the directory or the temporary file, writing — including a full disk —,
/// renaming; a directory in the way); [`Error::Resolution`] for an image
/// with a zero side, which PNG cannot hold.
pub fn save_png(image: &RgbaImage, path: impl AsRef<Path>) -> Result<()> {
    let target = path.as_ref();
    check_pixels(image, target, "a PNG")?;
    write_atomic(target, "image", |file| encode(image, file))
}

/// The image formats this library writes, by file extension: PNG, JPEG,
/// TIFF and OpenEXR (OpenEXR only from a rendered frame's linear colour,
/// through `save_frame`).
pub const IMAGE_EXTENSIONS: [&str; 6] = ["png", "jpg", "jpeg", "tif", "tiff", "exr"];

/// Saves `image` in the format its path's extension names (`.png`;
/// `.jpg`/`.jpeg` for a JPEG of quality 95 without the alpha channel;
/// `.tif`/`.tiff` for an RGBA TIFF), atomically as [`save_png`] writes;
/// the extension's case does not matter, and a path without one (a device
/// such as `/dev/stdout`) gets a PNG. An OpenEXR file holds linear colour,
/// which an 8-bit image no longer has: `save_frame` writes one from a
/// frame rendered with its layers.
///
/// ```
/// use fractal_sdf::image::{Rgba, RgbaImage};
///
/// let dir = std::env::temp_dir().join("fractal-sdf-doc-formats");
/// let image = RgbaImage::from_pixel(2, 2, Rgba([255, 0, 0, 255]));
/// fractal_sdf::output::save_image(&image, dir.join("red.jpg"))?;
/// assert_eq!(&std::fs::read(dir.join("red.jpg")).unwrap()[..3], &[0xff, 0xd8, 0xff]);
/// assert!(fractal_sdf::output::save_image(&image, dir.join("red.xyz")).is_err());
/// # std::fs::remove_dir_all(dir).ok();
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
///
/// # Errors
/// As [`save_png`]; an [`Error::Io`] of kind `Unsupported` naming the
/// supported extensions for a path whose extension is none of
/// [`IMAGE_EXTENSIONS`] (nothing is written); [`Error::Invalid`] for an
/// OpenEXR path.
pub fn save_image(image: &RgbaImage, path: impl AsRef<Path>) -> Result<()> {
    let target = path.as_ref();
    let extension = image_extension(target)?;
    match extension.as_deref() {
        None | Some("png") => save_png(image, target),
        Some("exr") => Err(Error::Invalid {
            what: "output",
            reason: format!(
                "{} is an OpenEXR file, which holds linear colour: an 8-bit image has \
                 none. Render the frame with Renderer::render_layers and write it with \
                 output::save_frame, or choose .png, .jpg or .tif",
                target.display()
            ),
        }),
        Some("tif" | "tiff") => {
            check_pixels(image, target, "a TIFF")?;
            save_tiff(
                target,
                image.as_raw(),
                image.dimensions(),
                ExtendedColorType::Rgba8,
            )
        }
        _ => {
            check_pixels(image, target, "a JPEG")?;
            write_atomic(target, "image", |file| encode_jpeg(image, file))
        }
    }
}

/// Writes `samples` (native-order bytes of `color`) as a TIFF, atomically.
pub(crate) fn save_tiff(
    target: &Path,
    samples: &[u8],
    (width, height): (u32, u32),
    color: ExtendedColorType,
) -> Result<()> {
    // The TIFF encoder seeks: encode in memory, then write.
    let mut encoded = io::Cursor::new(Vec::new());
    TiffEncoder::new(&mut encoded)
        .write_image(samples, width, height, color)
        .map_err(|e| Error::io(target, "cannot encode the TIFF", io_error(e)))?;
    let encoded = encoded.into_inner();
    write_atomic(target, "image", |mut file| file.write_all(&encoded))
}

/// An encoder's error as an I/O error, so that callers name the file.
pub(crate) fn io_error(e: ImageError) -> io::Error {
    match e {
        ImageError::IoError(e) => e,
        other => io::Error::new(io::ErrorKind::InvalidData, other),
    }
}

/// The lower-case extension of an image path [`save_image`] can write
/// (`None` for a path without one), checked before anything is rendered.
///
/// # Errors
/// As [`save_image`] for an extension it does not write.
pub fn image_extension(target: &Path) -> Result<Option<String>> {
    let extension = target
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        None => Ok(None),
        Some(e) if IMAGE_EXTENSIONS.contains(&e) => Ok(extension),
        other => Err(Error::io(
            target,
            "cannot choose an image format",
            io::Error::new(
                io::ErrorKind::Unsupported,
                format!(
                    "`.{}` is not a format this library writes: the file name must end in \
                     one of .{}",
                    other.unwrap_or_default(),
                    IMAGE_EXTENSIONS.join(", .")
                ),
            ),
        )),
    }
}

/// An [`Error::Resolution`] for an image with a zero side, which `format`
/// cannot hold.
fn check_pixels(image: &RgbaImage, target: &Path, format: &str) -> Result<()> {
    check_size(image.width(), image.height(), target, format)
}

/// An [`Error::Resolution`] for a `width` × `height` image with a zero
/// side, which `format` cannot hold.
pub(crate) fn check_size(width: u32, height: u32, target: &Path, format: &str) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(Error::Resolution {
            width,
            height,
            reason: format!(
                "{format} needs at least 1 pixel on each side; nothing was written to {}",
                target.display()
            ),
        });
    }
    Ok(())
}

/// Writes a file the way [`save_png`] does: into a temporary file beside
/// `target`, synced, then renamed over it, so that the file is either
/// whole or absent; through symbolic links; into devices and FIFOs as a
/// shell redirection would. `what` names the content in errors (`"image"`,
/// `"scene"`).
pub(crate) fn write_atomic(
    target: &Path,
    what: &str,
    write: impl Fn(&File) -> io::Result<()>,
) -> Result<()> {
    let fail = |action: String| move |source| Error::io(target, action, source);
    match fs::metadata(target) {
        Ok(m) if m.is_dir() => {
            return Err(fail(format!("cannot replace a directory with the {what}"))(
                io::Error::new(io::ErrorKind::IsADirectory, "it is a directory"),
            ));
        }
        Ok(m) if !m.is_file() => {
            // A device or FIFO: write into it, as a shell redirection would.
            let file = OpenOptions::new()
                .write(true)
                .open(target)
                .map_err(fail("cannot open it for writing".into()))?;
            return write(&file).map_err(fail(format!("cannot write the {what}")));
        }
        _ => {}
    }
    let file = resolve_links(target).map_err(fail("cannot follow the symbolic link".into()))?;
    if file.file_name().is_none() {
        return Err(fail(format!("cannot save the {what} there"))(
            io::Error::new(io::ErrorKind::InvalidInput, "the path names no file"),
        ));
    }
    let through = if file == target {
        String::new()
    } else {
        format!(" (through the link, at {})", file.display())
    };
    let dir = match file.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    fs::create_dir_all(&dir).map_err(fail(format!(
        "cannot create the directory {}",
        dir.display()
    )))?;
    sweep_stale_temporaries(&dir);
    let temp = Temporary::create(&dir, &file).map_err(|(at, e)| {
        fail(format!(
            "cannot create the temporary file {}{through}",
            at.display()
        ))(e)
    })?;
    write(&temp.file)
        .and_then(|()| temp.file.sync_all())
        .map_err(fail(format!(
            "cannot write the {what} (to the temporary file {}){through}",
            temp.path.display()
        )))?;
    temp.persist(&file).map_err(fail(format!(
        "cannot replace the file with the new {what}{through}"
    )))
}

/// Encodes `image` as an RGBA PNG into `out`. Every failure is an I/O
/// error, so that callers name the file.
fn encode(image: &RgbaImage, out: impl Write) -> io::Result<()> {
    let mut writer = BufWriter::new(out);
    PngEncoder::new(&mut writer)
        .write_image(
            image.as_raw(),
            image.width(),
            image.height(),
            ExtendedColorType::Rgba8,
        )
        .map_err(io_error)?;
    writer.flush()
}

/// Encodes `image` as a JPEG of quality 95, its alpha dropped.
fn encode_jpeg(image: &RgbaImage, out: impl Write) -> io::Result<()> {
    let rgb = image::DynamicImage::ImageRgba8(image.clone()).to_rgb8();
    let mut writer = BufWriter::new(out);
    JpegEncoder::new_with_quality(&mut writer, 95)
        .write_image(
            rgb.as_raw(),
            rgb.width(),
            rgb.height(),
            ExtendedColorType::Rgb8,
        )
        .map_err(io_error)?;
    writer.flush()
}

/// The file `path` names once symbolic links are followed: `path` itself
/// if it is not a link (or does not exist), else the end of its chain of
/// links, which may not exist yet.
fn resolve_links(path: &Path) -> io::Result<PathBuf> {
    const MAX_LINKS: usize = 40;
    let mut at = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match fs::symlink_metadata(&at) {
            Ok(m) if m.file_type().is_symlink() => {
                let next = fs::read_link(&at)?;
                at = match at.parent() {
                    Some(dir) if next.is_relative() => dir.join(next),
                    _ => next,
                };
            }
            _ => return Ok(at),
        }
    }
    Err(io::Error::other(format!(
        "more than {MAX_LINKS} symbolic links in a row (a loop?)"
    )))
}

/// A temporary file, removed when dropped unless it was renamed into place.
struct Temporary {
    path: PathBuf,
    /// The file name, as listed in [`in_flight`].
    name: String,
    file: File,
    kept: bool,
}

const TEMPORARY_SUFFIX: &str = ".png.tmp";

/// The names of this process's temporary files that exist now: a sweep
/// leaves them alone, and removes any other file with this process's id,
/// left by an earlier process that had the same id.
fn in_flight() -> MutexGuard<'static, HashSet<String>> {
    static IN_FLIGHT: LazyLock<Mutex<HashSet<String>>> = LazyLock::new(Mutex::default);
    IN_FLIGHT.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Temporary {
    /// A new file in `dir` unique to this process and call:
    /// `.NAME.PID-N.png.tmp`, for the image `file`.
    fn create(dir: &Path, file: &Path) -> std::result::Result<Self, (PathBuf, io::Error)> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let image = file
            .file_name()
            .map_or_else(|| "image".into(), |n| n.to_string_lossy().into_owned());
        let mut attempts = 0;
        loop {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let name = format!(".{image}.{}-{n}{TEMPORARY_SUFFIX}", std::process::id());
            let path = dir.join(&name);
            // Listed before it exists, so that no sweep sees it unlisted.
            in_flight().insert(name.clone());
            match File::create_new(&path) {
                Ok(file) => {
                    return Ok(Temporary {
                        path,
                        name,
                        file,
                        kept: false,
                    });
                }
                Err(e) => {
                    in_flight().remove(&name);
                    attempts += 1;
                    // A name taken by a file nobody removed: take the next.
                    if e.kind() != io::ErrorKind::AlreadyExists || attempts == 8 {
                        return Err((path, e));
                    }
                }
            }
        }
    }

    /// Renames the file to `to`.
    fn persist(mut self, to: &Path) -> io::Result<()> {
        fs::rename(&self.path, to)?;
        self.kept = true;
        Ok(())
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        if !self.kept {
            // Best effort: nothing more can be done about a failure here.
            let _ = fs::remove_file(&self.path);
        }
        in_flight().remove(&self.name);
    }
}

/// A temporary file that nobody has written to for this long is stale,
/// whatever its process.
pub const STALE_TEMPORARY_AGE: Duration = Duration::from_secs(60 * 60);

/// The shortest time between two sweeps of one directory by a process.
pub const SWEEP_INTERVAL: Duration = Duration::from_secs(60);

/// The process id of a temporary file's name, if the name is one that
/// [`save_png`] makes: `.NAME.PID-N.png.tmp`.
fn temporary_owner(name: &str) -> Option<u32> {
    let stem = name.strip_prefix('.')?.strip_suffix(TEMPORARY_SUFFIX)?;
    let (image, tag) = stem.rsplit_once('.')?;
    let (pid, n) = tag.split_once('-')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if image.is_empty() || !digits(n) || !digits(pid) {
        return None;
    }
    pid.parse().ok()
}

/// Whether a process with this id exists; `None` where that cannot be
/// told (no `/proc`).
fn process_alive(pid: u32) -> Option<bool> {
    let proc = Path::new("/proc");
    proc.join("self")
        .exists()
        .then(|| proc.join(pid.to_string()).exists())
}

/// Whether a temporary file owned by `pid`, last written `age` ago, is
/// stale (see [`save_png`]); `ours`: one this process is writing now.
fn is_stale(pid: u32, age: Duration, ours: bool, alive: impl Fn(u32) -> Option<bool>) -> bool {
    if ours {
        return false;
    }
    // This process's id on a file it is not writing: an earlier process's.
    age >= STALE_TEMPORARY_AGE || pid == std::process::id() || alive(pid) == Some(false)
}

/// Removes the stale temporary files in `dir` (best effort), at most once
/// per [`SWEEP_INTERVAL`] per directory.
fn sweep_stale_temporaries(dir: &Path) {
    static SWEPT: Mutex<Option<HashMap<PathBuf, Instant>>> = Mutex::new(None);
    {
        let mut swept = SWEPT.lock().unwrap_or_else(PoisonError::into_inner);
        let swept = swept.get_or_insert_with(HashMap::new);
        let now = Instant::now();
        // Only directories swept within the interval are remembered.
        swept.retain(|_, at| now.duration_since(*at) < SWEEP_INTERVAL);
        if swept.contains_key(dir) {
            return;
        }
        swept.insert(dir.to_path_buf(), now);
    }
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    let now = SystemTime::now();
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        let Some(pid) = temporary_owner(name) else {
            continue;
        };
        let Ok(meta) = entry.metadata() else { continue };
        if !meta.is_file() {
            continue;
        }
        let age = meta
            .modified()
            .ok()
            .and_then(|m| now.duration_since(m).ok())
            .unwrap_or_default();
        let ours = in_flight().contains(name);
        if is_stale(pid, age, ours, process_alive) {
            let _ = fs::remove_file(entry.path());
        }
    }
}

/// Checks that `path` holds a whole image of `width` × `height` pixels in
/// the format its extension names: a PNG as [`verify_png`] checks it
/// (without decoding), any other format by reading it whole (an OpenEXR
/// file's every channel, with the `opencl` feature that brings its
/// reader).
///
/// # Errors
/// [`Error::Io`] if the file cannot be read; [`Error::Invalid`] saying
/// what is wrong with it.
pub fn verify_image(path: impl AsRef<Path>, (width, height): (u32, u32)) -> Result<()> {
    let path = path.as_ref();
    let extension = image_extension(path)?;
    let bad = |reason: String| Error::Invalid {
        what: "image file",
        reason: format!("{}: {reason}", path.display()),
    };
    let size = match extension.as_deref() {
        None | Some("png") => return verify_png(path, (width, height)),
        Some("exr") => exr_size(path).map_err(bad)?,
        Some(_) => {
            let image = image::ImageReader::open(path)
                .map_err(|e| Error::io(path, "cannot read the image", e))?
                .with_guessed_format()
                .map_err(|e| Error::io(path, "cannot read the image", e))?
                .decode()
                .map_err(|e| bad(e.to_string()))?;
            (image.width(), image.height())
        }
    };
    if size == (width, height) {
        Ok(())
    } else {
        Err(bad(format!(
            "{}x{} pixels, not {width}x{height}",
            size.0, size.1
        )))
    }
}

/// The size of the OpenEXR image at `path`, read whole.
#[cfg(feature = "opencl")]
fn exr_size(path: &Path) -> std::result::Result<(u32, u32), String> {
    use exr::prelude::{ReadChannels, ReadLayers};
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_file(path)
        .map_err(|e| e.to_string())?;
    let layer = image.layer_data.first().ok_or("no layers")?;
    let size = layer.size;
    Ok((
        u32::try_from(size.0).map_err(|e| e.to_string())?,
        u32::try_from(size.1).map_err(|e| e.to_string())?,
    ))
}

/// Without the `opencl` feature there is no OpenEXR reader.
#[cfg(not(feature = "opencl"))]
fn exr_size(_path: &Path) -> std::result::Result<(u32, u32), String> {
    Err("reading OpenEXR files needs the `opencl` feature".into())
}

/// Checks that `path` holds a whole PNG image of `width` × `height`
/// pixels, without decoding it: the PNG signature, an `IHDR` chunk of that
/// size first, and a chain of chunks, with image data, that ends with
/// `IEND` exactly at the end of the file. A file cut short anywhere — such
/// as one left by a copy that was interrupted — fails; damage inside a
/// chunk's data would pass (compressed data is not read).
///
/// ```
/// use fractal_sdf::image::RgbaImage;
/// use fractal_sdf::output::{save_png, verify_png};
///
/// let path = std::env::temp_dir().join("fractal-sdf-verify-doc.png");
/// save_png(&RgbaImage::new(4, 3), &path)?;
/// verify_png(&path, (4, 3))?;
/// assert!(verify_png(&path, (3, 4)).is_err());
/// let bytes = std::fs::read(&path).unwrap();
/// std::fs::write(&path, &bytes[..bytes.len() - 1]).unwrap();
/// assert!(verify_png(&path, (4, 3)).is_err());
/// # std::fs::remove_file(path).ok();
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
///
/// # Errors
/// [`Error::Io`] if the file cannot be read; [`Error::Invalid`] saying
/// what is wrong with it.
pub fn verify_png(path: impl AsRef<Path>, (width, height): (u32, u32)) -> Result<()> {
    let path = path.as_ref();
    let bad = |reason: String| Error::Invalid {
        what: "PNG file",
        reason: format!("{}: {reason}", path.display()),
    };
    let read = |e| Error::io(path, "cannot read the image", e);
    let file = File::open(path).map_err(read)?;
    let meta = file.metadata().map_err(read)?;
    let length = meta.len();
    if !meta.is_file() {
        return Err(bad("not a regular file".into()));
    }
    let mut r = BufReader::new(file);
    let mut head = [0u8; 8 + 8 + 13 + 4];
    match r.read_exact(&mut head) {
        Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => {
            return Err(bad(format!("truncated: {length} bytes")));
        }
        other => other.map_err(read)?,
    }
    if head[..8] != PNG_SIGNATURE {
        return Err(bad("not a PNG file (no PNG signature)".into()));
    }
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    if be(&head[8..12]) != 13 || &head[12..16] != b"IHDR" {
        return Err(bad("no IHDR chunk first".into()));
    }
    let size = (be(&head[16..20]), be(&head[20..24]));
    if size != (width, height) {
        return Err(bad(format!(
            "the image is {}x{}, expected {width}x{height}",
            size.0, size.1
        )));
    }
    let mut at = head.len() as u64;
    let mut data = false;
    loop {
        let mut chunk = [0u8; 8];
        match r.read_exact(&mut chunk) {
            Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => {
                return Err(bad(format!(
                    "truncated: {length} bytes, ending before the IEND chunk"
                )));
            }
            other => other.map_err(read)?,
        }
        let len = u64::from(be(&chunk[..4]));
        // Type and data length, data, CRC.
        let end = at + 8 + len + 4;
        if end > length {
            return Err(bad(format!(
                "truncated: {length} bytes, a chunk reaches to byte {end}"
            )));
        }
        match &chunk[4..] {
            b"IEND" if end == length => break,
            b"IEND" => {
                return Err(bad(format!("{} bytes after the IEND chunk", length - end)));
            }
            b"IDAT" => data = true,
            _ => {}
        }
        #[allow(clippy::cast_possible_wrap)] // at most a file's length
        r.seek_relative((len + 4) as i64).map_err(read)?;
        at = end;
    }
    if !data {
        return Err(bad("no image data (IDAT chunk)".into()));
    }
    Ok(())
}

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("fractal-sdf-output-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        dir
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn writes_creates_directories_and_leaves_no_temporary_file() {
        let dir = scratch("ok");
        let path = dir.join("a/b/img.png");
        let image = RgbaImage::from_fn(3, 2, |x, y| Rgba([x as u8 * 80, y as u8 * 100, 7, 255]));
        save_png(&image, &path).unwrap();
        assert_eq!(image::open(&path).unwrap().to_rgba8(), image);
        verify_png(&path, (3, 2)).unwrap();
        // Overwrites in place.
        let other = RgbaImage::from_pixel(1, 1, Rgba([1, 2, 3, 4]));
        save_png(&other, &path).unwrap();
        assert_eq!(image::open(&path).unwrap().to_rgba8(), other);
        assert_eq!(names(&dir.join("a/b")), ["img.png"]);
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn failure_is_an_io_error_naming_the_target() {
        let dir = scratch("fail");
        fs::create_dir_all(&dir).unwrap();
        // A file where a directory is needed.
        let blocker = dir.join("file");
        fs::write(&blocker, b"x").unwrap();
        let target = blocker.join("img.png");
        let err = save_png(&RgbaImage::new(1, 1), &target).unwrap_err();
        match &err {
            Error::Io { path, action, .. } => {
                assert_eq!(path, &target, "{err}");
                assert!(action.contains("cannot create the directory"), "{err}");
            }
            other => panic!("expected Error::Io, got {other:?}"),
        }
        // A directory in the way is refused before anything is written,
        // and survives.
        let occupied = dir.join("dir.png");
        fs::create_dir_all(occupied.join("inside")).unwrap();
        let err = save_png(&RgbaImage::new(1, 1), &occupied).unwrap_err();
        assert!(
            matches!(err, Error::Io { ref path, .. } if path == &occupied),
            "{err}"
        );
        assert!(err.to_string().contains("directory"), "{err}");
        assert!(occupied.join("inside").is_dir());
        assert_eq!(names(&dir), ["dir.png", "file"]);
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_full_disk_is_an_error_naming_the_target() {
        /// Accepts `room` bytes, then fails as a full disk does.
        struct Full {
            room: usize,
        }
        impl Write for Full {
            fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
                if self.room == 0 {
                    return Err(io::Error::from_raw_os_error(28)); // ENOSPC
                }
                let n = buf.len().min(self.room);
                self.room -= n;
                Ok(n)
            }
            fn flush(&mut self) -> io::Result<()> {
                Ok(())
            }
        }
        let image = RgbaImage::from_fn(64, 64, |x, y| Rgba([(x * y) as u8, 0, 0, 255]));
        for room in [0, 10, 1000] {
            let err = encode(&image, Full { room }).unwrap_err();
            assert_eq!(err.raw_os_error(), Some(28), "{err}");
        }
        let err = Error::io(
            "out/a.png",
            "cannot write the image",
            io::Error::from_raw_os_error(28),
        );
        assert!(
            err.to_string()
                .starts_with("out/a.png: cannot write the image: No space left on device"),
            "{err}"
        );
    }

    #[test]
    fn temporary_names_are_recognised_exactly() {
        let pid = std::process::id();
        assert_eq!(temporary_owner(".img.png.123-0.png.tmp"), Some(123));
        assert_eq!(temporary_owner(".a.b.png.7-42.png.tmp"), Some(7));
        assert_eq!(
            temporary_owner(&format!(".frame_00001.png.{pid}-9{TEMPORARY_SUFFIX}")),
            Some(pid)
        );
        for other in [
            "img.png",
            ".img.png",
            ".img.png.12-3.png",
            "img.png.12-3.png.tmp",
            ".img.png.x-3.png.tmp",
            ".img.png.12-.png.tmp",
            ".img.png.-3.png.tmp",
            "..12-3.png.tmp",
            ".img.png.99999999999-3.png.tmp",
        ] {
            assert_eq!(temporary_owner(other), None, "{other}");
        }
    }

    #[test]
    fn staleness_needs_a_dead_owner_or_an_old_file() {
        let me = std::process::id();
        let young = Duration::from_secs(5);
        let dead = |_| Some(false);
        let alive = |_| Some(true);
        let unknown = |_| None;
        assert!(is_stale(me + 1, young, false, dead));
        assert!(!is_stale(me + 1, young, false, alive));
        assert!(!is_stale(me + 1, young, false, unknown));
        // This process's id: stale unless this process is writing it.
        assert!(is_stale(me, young, false, alive));
        for alive in [dead, alive, unknown] {
            assert!(!is_stale(me, young, true, alive));
            assert!(!is_stale(me, STALE_TEMPORARY_AGE * 2, true, alive));
            assert!(is_stale(me, STALE_TEMPORARY_AGE, false, alive));
            assert!(is_stale(me + 1, STALE_TEMPORARY_AGE, false, alive));
        }
        if Path::new("/proc/self").exists() {
            assert_eq!(process_alive(me), Some(true));
            assert_eq!(process_alive(u32::MAX), Some(false));
        }
    }

    #[test]
    fn a_panic_while_writing_removes_the_temporary_file() {
        let dir = scratch("panic");
        fs::create_dir_all(&dir).unwrap();
        let path = dir.join("img.png");
        let result = std::panic::catch_unwind(|| {
            let temp = Temporary::create(&dir, &path).unwrap();
            assert!(temp.path.is_file());
            assert!(in_flight().contains(&temp.name));
            panic!("the encoder failed");
        });
        assert!(result.is_err());
        assert!(names(&dir).is_empty(), "{:?}", names(&dir));
        // A name that is taken is skipped, not an error.
        let next = Temporary::create(&dir, &path).unwrap();
        let n: u64 = next.name[next.name.rfind('-').unwrap() + 1..]
            .trim_end_matches(TEMPORARY_SUFFIX)
            .parse()
            .unwrap();
        let pid = std::process::id();
        for k in 1..4 {
            fs::write(dir.join(format!(".img.png.{pid}-{}.png.tmp", n + k)), b"x").unwrap();
        }
        let name = next.name.clone();
        drop(next);
        assert!(!in_flight().contains(&name));
        let taken = Temporary::create(&dir, &path).unwrap();
        assert!(taken.path.is_file());
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn verify_png_says_what_is_wrong() {
        let dir = scratch("verify");
        let path = dir.join("img.png");
        save_png(&RgbaImage::new(5, 4), &path).unwrap();
        let whole = fs::read(&path).unwrap();
        verify_png(&path, (5, 4)).unwrap();
        let check = |bytes: &[u8]| {
            fs::write(&path, bytes).unwrap();
            verify_png(&path, (5, 4)).unwrap_err().to_string()
        };
        let err = verify_png(&path, (4, 5)).unwrap_err().to_string();
        assert!(err.contains("5x4, expected 4x5"), "{err}");
        for cut in [0, 7, 8, 20, 33, 40, whole.len() - 12, whole.len() - 1] {
            let err = check(&whole[..cut]);
            assert!(err.contains("truncated"), "{cut}: {err}");
            assert!(err.contains(&*path.to_string_lossy()), "{err}");
        }
        let mut longer = whole.clone();
        longer.extend_from_slice(b"junk");
        assert!(check(&longer).contains("4 bytes after the IEND"));
        let mut foreign = whole.clone();
        foreign[1] = b'J';
        assert!(check(&foreign).contains("no PNG signature"));
        let err = verify_png(dir.join("missing.png"), (5, 4)).unwrap_err();
        assert!(matches!(err, Error::Io { .. }), "{err}");
        let err = verify_png(&dir, (5, 4)).unwrap_err().to_string();
        assert!(err.contains("not a regular file"), "{err}");
        fs::remove_dir_all(dir).unwrap();
    }
}
