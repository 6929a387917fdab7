//! Saving images to disk.

use std::fs::{self, File};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder, RgbaImage};

use crate::error::{Error, Result};

/// Saves `image` as a PNG at `path`, creating missing parent directories.
///
/// The write is atomic: the PNG goes to a temporary file in the same
/// directory, which is then renamed over `path`, so a reader never sees a
/// half-written image and a failed write leaves any earlier file intact.
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
/// [`Error::Io`] with the path that failed (creating the directory, writing
/// or renaming); [`Error::Image`] if encoding fails.
pub fn save_png(image: &RgbaImage, path: impl AsRef<Path>) -> Result<()> {
    let path = path.as_ref();
    let io = |at: &Path| {
        let at = at.to_path_buf();
        move |source| Error::Io { path: at, source }
    };
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    fs::create_dir_all(&parent).map_err(io(&parent))?;
    let temp = temp_path(&parent, path);
    let written = write_png(image, &temp);
    let result = written.and_then(|()| fs::rename(&temp, path).map_err(io(path)));
    if result.is_err() {
        // Best effort: the temporary file may not exist.
        let _ = fs::remove_file(&temp);
    }
    result
}

fn write_png(image: &RgbaImage, temp: &Path) -> Result<()> {
    let io = |source| Error::Io {
        path: temp.to_path_buf(),
        source,
    };
    let file = File::create(temp).map_err(io)?;
    let mut writer = BufWriter::new(file);
    PngEncoder::new(&mut writer).write_image(
        image.as_raw(),
        image.width(),
        image.height(),
        ExtendedColorType::Rgba8,
    )?;
    writer.flush().map_err(io)?;
    writer.get_ref().sync_all().map_err(io)
}

/// A name in `dir` unique to this process and call: `.NAME.PID-N.png.tmp`.
fn temp_path(dir: &Path, path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .map_or_else(|| "image".into(), |n| n.to_string_lossy().into_owned());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    dir.join(format!(".{name}.{}-{n}.png.tmp", std::process::id()))
}

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

    #[test]
    fn writes_creates_directories_and_leaves_no_temporary_file() {
        let dir = scratch("ok");
        let path = dir.join("a/b/img.png");
        let image = RgbaImage::from_fn(3, 2, |x, y| Rgba([x as u8 * 80, y as u8 * 100, 7, 255]));
        save_png(&image, &path).unwrap();
        assert_eq!(image::open(&path).unwrap().to_rgba8(), image);
        // Overwrites in place.
        let other = RgbaImage::from_pixel(1, 1, Rgba([1, 2, 3, 4]));
        save_png(&other, &path).unwrap();
        assert_eq!(image::open(&path).unwrap().to_rgba8(), other);
        let left: Vec<_> = fs::read_dir(dir.join("a/b")).unwrap().collect();
        assert_eq!(left.len(), 1, "{left:?}");
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn failure_is_an_io_error_naming_the_path() {
        let dir = scratch("fail");
        fs::create_dir_all(&dir).unwrap();
        // A file where a directory is needed.
        let blocker = dir.join("file");
        fs::write(&blocker, b"x").unwrap();
        let target = blocker.join("img.png");
        let err = save_png(&RgbaImage::new(1, 1), &target).unwrap_err();
        match &err {
            Error::Io { path, .. } => assert!(path.starts_with(&blocker), "{err}"),
            other => panic!("expected Error::Io, got {other:?}"),
        }
        // Renaming onto a directory fails, and the earlier content survives.
        let occupied = dir.join("dir.png");
        fs::create_dir_all(occupied.join("inside")).unwrap();
        let err = save_png(&RgbaImage::new(1, 1), &occupied).unwrap_err();
        assert!(
            matches!(err, Error::Io { ref path, .. } if path == &occupied),
            "{err}"
        );
        assert!(occupied.join("inside").is_dir());
        let names: Vec<String> = fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert!(names.iter().all(|n| !n.ends_with(".tmp")), "{names:?}");
        fs::remove_dir_all(dir).unwrap();
    }
}
