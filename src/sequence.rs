//! Frame sequences: a camera path rendered to numbered images
//! (`frame_00000.png`, `frame_00001.png`, ...; or TIFF, JPEG or OpenEXR
//! frames with their outputs, [`Sequence::format`]) at a frame rate,
//! resumable (whole frames already on disk are skipped; cut-short ones
//! are rendered again) and renderable in sub-ranges.
//!
//! ```
//! use fractal_sdf::sequence::{Sequence, parse_range};
//!
//! let seq = Sequence::for_duration("out/seq", 24.0, 2.0)?;
//! assert_eq!(seq.frames(), 48);
//! assert_eq!(seq.frame_path(7), std::path::Path::new("out/seq/frame_00007.png"));
//! assert_eq!(seq.time(12), 0.5);
//! assert_eq!(parse_range("10..20", seq.frames())?, 10..20);
//! # Ok::<(), fractal_sdf::Error>(())
//! ```

use std::ops::Range;
use std::path::{Path, PathBuf};

use crate::animation::CameraPath;
use crate::error::{Error, Result, fmt_value};
use crate::output::CameraExport;
use crate::scene::Camera;
#[cfg(feature = "opencl")]
use crate::{
    animation::Motion,
    render::{RenderFrames, Renderer},
    view::FrameTiming,
};

/// The file name of frame `index`: `frame_00042.png`.
#[must_use]
pub fn frame_name(index: u32) -> String {
    format!("frame_{index:05}.png")
}

/// The `printf`-style pattern matching [`frame_name`], for encoders such as
/// `ffmpeg`.
pub const FRAME_PATTERN: &str = "frame_%05d.png";

/// A sequence of `frames` images at `fps` frames per second, stored in
/// `dir`. Frame `i` shows time `i / fps` seconds from the start.
#[derive(Debug, Clone, PartialEq)]
pub struct Sequence {
    dir: PathBuf,
    fps: f64,
    frames: u32,
    blur: MotionBlur,
    /// The frames' file extension, lower case: `png` unless
    /// [`Sequence::format`] chose another.
    extension: String,
    /// The outputs written with each frame, where asked for.
    #[cfg(feature = "opencl")]
    output: Option<crate::output::FrameOutput>,
}

/// Motion blur by shutter samples ([`Sequence::motion_blur`]): each frame
/// the mean of `samples` moments spread evenly over the time its shutter
/// is open, `shutter` of a frame's duration from the frame's time on (so
/// every frame, the first included, stays within the path and is blurred
/// alike).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct MotionBlur {
    /// The moments a frame is the mean of; 1 is no blur.
    pub samples: u32,
    /// The fraction of a frame's duration the shutter is open, in `(0, 1]`
    /// (0.5 is a film camera's 180° shutter).
    pub shutter: f64,
}

impl MotionBlur {
    /// The most moments a frame may be the mean of.
    pub const MAX_SAMPLES: u32 = 256;

    /// `samples` moments over `shutter` of each frame's duration.
    #[must_use]
    pub fn new(samples: u32, shutter: f64) -> Self {
        MotionBlur { samples, shutter }
    }

    /// No blur: one moment, at the frame's time.
    #[must_use]
    pub fn none() -> Self {
        MotionBlur::new(1, 0.5)
    }

    fn validate(&self) -> Result<()> {
        if !(1..=Self::MAX_SAMPLES).contains(&self.samples) {
            return Err(invalid(format!(
                "motion blur takes 1 to {} samples a frame, got {}",
                Self::MAX_SAMPLES,
                self.samples
            )));
        }
        if !(self.shutter > 0.0 && self.shutter <= 1.0) {
            return Err(invalid(format!(
                "the shutter is open for a fraction of a frame in (0, 1], got {}",
                fmt_value(self.shutter)
            )));
        }
        Ok(())
    }
}

fn invalid(reason: String) -> Error {
    Error::Invalid {
        what: "frame sequence",
        reason,
    }
}

/// [`Error::Invalid`] unless `fps` is a positive finite number.
fn check_fps(fps: f64) -> Result<()> {
    if fps.is_finite() && fps > 0.0 {
        Ok(())
    } else {
        Err(invalid(format!(
            "the frame rate must be a finite number > 0, got {}",
            fmt_value(fps)
        )))
    }
}

impl Sequence {
    /// The most frames a sequence may have: almost 5 days at 24 frames per
    /// second. Lists of a sequence's frames ([`Sequence::remaining`]) stay
    /// below 40 MB.
    pub const MAX_FRAMES: u32 = 10_000_000;

    /// A sequence of `frames` frames at `fps`.
    ///
    /// # Errors
    /// [`Error::Invalid`] if `fps` is not a positive finite number or
    /// `frames` is 0 or above [`Sequence::MAX_FRAMES`].
    pub fn new(dir: impl Into<PathBuf>, fps: f64, frames: u32) -> Result<Self> {
        check_fps(fps)?;
        if frames == 0 {
            return Err(invalid("a sequence needs at least 1 frame".into()));
        }
        if frames > Self::MAX_FRAMES {
            return Err(invalid(format!(
                "{frames} frames are too many (at most {})",
                Self::MAX_FRAMES
            )));
        }
        Ok(Sequence {
            dir: dir.into(),
            fps,
            frames,
            blur: MotionBlur::none(),
            extension: "png".into(),
            #[cfg(feature = "opencl")]
            output: None,
        })
    }

    /// The sequence with each frame blurred over the time its shutter is
    /// open ([`MotionBlur`]).
    ///
    /// # Errors
    /// [`Error::Invalid`] for a sample count outside `1..=`
    /// [`MotionBlur::MAX_SAMPLES`] or a shutter outside `(0, 1]`.
    pub fn motion_blur(mut self, blur: MotionBlur) -> Result<Self> {
        blur.validate()?;
        self.blur = blur;
        Ok(self)
    }

    /// The moments frame `index` is the mean of, in seconds from the
    /// start: its time alone without blur, else `samples` moments at the
    /// middles of equal parts of the time the shutter is open, from the
    /// frame's time on.
    #[must_use]
    pub fn moments(&self, index: u32) -> Vec<f64> {
        let t = self.time(index);
        if self.blur.samples == 1 {
            return vec![t];
        }
        let open = self.blur.shutter / self.fps;
        let n = f64::from(self.blur.samples);
        (0..self.blur.samples)
            .map(|k| t + open * (f64::from(k) + 0.5) / n)
            .collect()
    }

    /// A sequence covering `seconds` at `fps`: `round(seconds × fps)`
    /// frames, at least 1. The last frame is one frame before the end, so
    /// a looping path (such as an orbit) repeats without a doubled frame.
    ///
    /// # Errors
    /// [`Error::Invalid`] naming the argument that is wrong: a frame rate
    /// or a duration that is not a positive finite number, or the two
    /// together needing more than [`Sequence::MAX_FRAMES`] frames.
    pub fn for_duration(dir: impl Into<PathBuf>, fps: f64, seconds: f64) -> Result<Self> {
        check_fps(fps)?;
        if !(seconds.is_finite() && seconds > 0.0) {
            return Err(invalid(format!(
                "the duration must be a finite number > 0, got {} s",
                fmt_value(seconds)
            )));
        }
        // Both are positive and finite: the product is positive, maybe
        // infinite.
        let count = (seconds * fps).round();
        if count > f64::from(Self::MAX_FRAMES) {
            return Err(invalid(format!(
                "{} s at {} frames per second is {} frames, too many (at most {})",
                fmt_value(seconds),
                fmt_value(fps),
                fmt_value(count),
                Self::MAX_FRAMES
            )));
        }
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let frames = (count as u32).max(1);
        Self::new(dir, fps, frames)
    }

    /// The directory the frames are stored in.
    #[must_use]
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Frames per second.
    #[must_use]
    pub fn fps(&self) -> f64 {
        self.fps
    }

    /// The number of frames.
    #[must_use]
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// The sequence with its frames written in the format `extension`
    /// names: `png` (the default), `tif`/`tiff`, `jpg`/`jpeg`, or `exr`
    /// (OpenEXR, the linear colour with the outputs of
    /// [`Sequence::outputs`] as layers). Frame 42 is then
    /// `frame_00042.exr`.
    ///
    /// ```
    /// use fractal_sdf::sequence::Sequence;
    /// let seq = Sequence::new("out/seq", 24.0, 48)?.format("exr")?;
    /// assert_eq!(seq.frame_path(7), std::path::Path::new("out/seq/frame_00007.exr"));
    /// assert!(Sequence::new("out/seq", 24.0, 48)?.format("gif").is_err());
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::Invalid`] for an extension that is not one of
    /// [`IMAGE_EXTENSIONS`](crate::output::IMAGE_EXTENSIONS).
    pub fn format(mut self, extension: &str) -> Result<Self> {
        let lower = extension
            .trim()
            .trim_start_matches('.')
            .to_ascii_lowercase();
        if !crate::output::IMAGE_EXTENSIONS.contains(&lower.as_str()) {
            return Err(invalid(format!(
                "`{extension}` is not a format this library writes frames in: {}",
                crate::output::IMAGE_EXTENSIONS.join(", ")
            )));
        }
        self.extension = lower;
        Ok(self)
    }

    /// The frames' file extension (`png` by default).
    #[must_use]
    pub fn extension(&self) -> &str {
        &self.extension
    }

    /// Where frame `index` is stored.
    #[must_use]
    pub fn frame_path(&self, index: u32) -> PathBuf {
        self.dir
            .join(format!("frame_{index:05}.{}", self.extension))
    }

    /// The time frame `index` shows, in seconds from the start.
    #[must_use]
    pub fn time(&self, index: u32) -> f64 {
        f64::from(index) / self.fps
    }

    /// The camera of frame `index`: `base` moved along `path` to the
    /// frame's time (counted from the path's first keyframe).
    #[must_use]
    pub fn camera(&self, path: &CameraPath, index: u32, base: &Camera) -> Camera {
        path.camera_at(path.start() + self.time(index), base)
    }

    /// Every frame's camera, as [`CameraExport`]s with their frame and
    /// time, for `width` × `height` frames.
    ///
    /// # Errors
    /// As [`CameraExport::new`].
    pub fn camera_exports(
        &self,
        path: &CameraPath,
        base: &Camera,
        size: (u32, u32),
    ) -> Result<Vec<CameraExport>> {
        (0..self.frames)
            .map(|i| {
                CameraExport::new(&self.camera(path, i, base), size)
                    .map(|c| c.at_frame(u64::from(i), self.time(i)))
            })
            .collect()
    }

    /// The frames of `range` (clipped to the sequence) that are not on
    /// disk as whole `width` × `height` images, in order: missing frames,
    /// and frames that [`verify_image`](crate::output::verify_image)
    /// rejects — cut short (by a copy that was interrupted, a full disk),
    /// of another size, not of the format — which rendering writes again.
    #[must_use]
    pub fn remaining(&self, range: Range<u32>, (width, height): (u32, u32)) -> Vec<u32> {
        let range = range.start..range.end.min(self.frames);
        range
            .filter(|&i| crate::output::verify_image(self.frame_path(i), (width, height)).is_err())
            .collect()
    }

    /// Encodes the frames into an MP4 at `output` with `ffmpeg` from the
    /// `PATH` (the command [`Sequence::ffmpeg_args`] gives), waiting for
    /// it. Never fails: the outcome says what happened, with the command
    /// to run by hand where it did not succeed.
    #[must_use]
    pub fn encode(&self, output: &Path) -> Encoded {
        let args = self.ffmpeg_args(output);
        let command = format!("ffmpeg {}", args.join(" "));
        match std::process::Command::new("ffmpeg")
            .args(&args)
            .stdin(std::process::Stdio::null())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .status()
        {
            Ok(status) if status.success() => Encoded::Written,
            Ok(status) => Encoded::Failed {
                status: status.to_string(),
                command,
            },
            Err(_) => Encoded::NoFfmpeg { command },
        }
    }

    /// The arguments of the `ffmpeg` command that encodes the frames into
    /// an H.264 MP4 at `output`:
    /// `-y -framerate R -i DIR/frame_%05d.png -pix_fmt yuv420p OUTPUT`
    /// (the frames' own extension in place of `png`).
    #[must_use]
    pub fn ffmpeg_args(&self, output: &Path) -> Vec<String> {
        vec![
            "-y".into(),
            "-framerate".into(),
            format!("{}", self.fps),
            "-i".into(),
            self.dir
                .join(format!("frame_%05d.{}", self.extension))
                .display()
                .to_string(),
            "-pix_fmt".into(),
            "yuv420p".into(),
            output.display().to_string(),
        ]
    }
}

/// What [`Sequence::encode`] did.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Encoded {
    /// The video was written.
    Written,
    /// `ffmpeg` is not on the `PATH`; `command` encodes the video once it
    /// is installed.
    NoFfmpeg {
        /// The `ffmpeg` command line.
        command: String,
    },
    /// `ffmpeg` ran and failed.
    Failed {
        /// How it exited.
        status: String,
        /// The `ffmpeg` command line, to run by hand and see why.
        command: String,
    },
}

impl std::fmt::Display for Encoded {
    /// A line for the user: done, or the command to run.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Encoded::Written => f.write_str("video written"),
            Encoded::NoFfmpeg { command } => write!(
                f,
                "ffmpeg is not installed; to make a video, install it (Debian: \
                 `sudo apt-get install ffmpeg`) and run:\n  {command}"
            ),
            Encoded::Failed { status, command } => {
                write!(f, "ffmpeg failed ({status}); the command was:\n  {command}")
            }
        }
    }
}

/// A frame [`Sequence::render`] has just written.
#[cfg(feature = "opencl")]
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RenderedFrame {
    /// The frame's index in the sequence.
    pub index: u32,
    /// Where it was saved.
    pub path: PathBuf,
    /// What rendering it cost.
    pub timing: Option<FrameTiming>,
}

#[cfg(feature = "opencl")]
impl Sequence {
    /// The sequence with `output`'s outputs written with every frame
    /// ([`FrameOutput::aovs`](crate::output::FrameOutput::aovs): layers of
    /// an OpenEXR frame, 16-bit PNGs beside any other; and its
    /// [`bits`](crate::output::FrameOutput::bits)), as
    /// [`save_frame`](crate::output::save_frame) writes them. Its effects
    /// are replaced by the renderer's when the frames are rendered.
    #[must_use]
    pub fn outputs(mut self, output: crate::output::FrameOutput) -> Self {
        self.output = Some(output);
        self
    }

    /// Renders the frames `indices` of this sequence at `width` × `height`
    /// and saves each to [`Sequence::frame_path`] (atomically, so an
    /// interrupted run leaves only whole frames). Frame `i` shows the
    /// camera on `path` at `path.start() + time(i)` (with the renderer's
    /// current camera's projection) and the `motions` at `time(i)`; with
    /// [`Sequence::motion_blur`], the mean of progressive passes at each of
    /// its [`Sequence::moments`] instead, the camera and motions set for
    /// each. Frames in a format that holds more than 8 bits (OpenEXR, or
    /// 16 bits), or with [`Sequence::outputs`], are rendered with their
    /// shading layers (and object ids where asked for) and written by
    /// [`save_frame`](crate::output::save_frame). `on_frame` is called
    /// after each frame is saved.
    ///
    /// Pass [`Sequence::remaining`] as `indices` to resume a sequence.
    ///
    /// # Errors
    /// [`Error::Invalid`], before anything is rendered, for an index that
    /// is not a frame of the sequence or more moments of motion blur than
    /// progressive rendering holds at the quality's supersampling, and
    /// [`Error::Motion`] for a motion
    /// that does not validate ([`Motion::validate`]); then the first render, parameter or
    /// file error; the frames saved before it stay on disk.
    pub fn render(
        &self,
        renderer: &mut Renderer,
        path: &CameraPath,
        motions: &[Motion],
        indices: &[u32],
        (width, height): (u32, u32),
        mut on_frame: impl FnMut(&RenderedFrame),
    ) -> Result<()> {
        let (output, layered) = self.prepare(renderer, motions, indices)?;
        if !layered {
            return self.images(renderer, path, motions, indices, (width, height), on_frame);
        }
        let base = *renderer.camera();
        for &index in indices {
            let moments = self.moments(index);
            let file = self.frame_path(index);
            let at = |r: &mut Renderer, t: f64| moment(r, path, &base, motions, t);
            let mut frame = if let [t] = moments[..] {
                at(renderer, t)?;
                renderer.render_layers(width, height)?
            } else {
                renderer.render_layers_over_time(width, height, &moments, |r, &t| at(r, t))?
            };
            if output.needs_ids() {
                // The layers are the first moment's: so are the ids.
                at(renderer, moments[0])?;
                renderer.identify(&mut frame)?;
            }
            crate::output::save_frame(&frame, &file, &output)?;
            on_frame(&RenderedFrame {
                index,
                path: file,
                timing: renderer.last_timing(),
            });
        }
        Ok(())
    }

    /// [`Sequence::render`] on either backend ([`RenderFrames`]: the wgpu
    /// backend's [`WgpuRenderer`](crate::render::WgpuRenderer) too), for
    /// frames that are 8-bit images alone (PNG, TIFF or JPEG, no
    /// [`Sequence::outputs`] beyond the image).
    ///
    /// # Errors
    /// As [`Sequence::render`]; [`Error::Invalid`] before anything is
    /// rendered where the frames need the shading layers (OpenEXR, 16 bits
    /// or other outputs), which [`Sequence::render`] writes with the OpenCL
    /// backend.
    pub fn render_images<R: RenderFrames>(
        &self,
        renderer: &mut R,
        path: &CameraPath,
        motions: &[Motion],
        indices: &[u32],
        size: (u32, u32),
        on_frame: impl FnMut(&RenderedFrame),
    ) -> Result<()> {
        let (_, layered) = self.prepare(renderer, motions, indices)?;
        if layered {
            return Err(invalid(
                "frames with the shading layers (OpenEXR, 16 bits or outputs beside the image) \
                 are written by Sequence::render, on the OpenCL backend: write 8-bit PNG, TIFF \
                 or JPEG frames here"
                    .into(),
            ));
        }
        self.images(renderer, path, motions, indices, size, on_frame)
    }

    /// Checks the frames, motions and motion blur before anything is
    /// rendered: the outputs to write, and whether they need the shading
    /// layers.
    fn prepare<R: RenderFrames>(
        &self,
        renderer: &R,
        motions: &[Motion],
        indices: &[u32],
    ) -> Result<(crate::output::FrameOutput, bool)> {
        if let Some(&index) = indices.iter().find(|&&i| i >= self.frames) {
            return Err(invalid(format!(
                "frame {index} is not in the sequence (frames 0..{})",
                self.frames
            )));
        }
        for motion in motions {
            motion.validate()?;
        }
        // Each moment a progressive pass of the quality's samples.
        let supersampling = renderer.options().quality.supersampling;
        let samples = supersampling.max(1).pow(2);
        let most = Renderer::MAX_PROGRESSIVE_SAMPLES / samples;
        if self.blur.samples > most {
            return Err(invalid(format!(
                "{} moments of motion blur take {} samples a pixel at {supersampling}x\
                 {supersampling} supersampling, more than the {} progressive rendering holds: \
                 use at most {most} moments",
                self.blur.samples,
                self.blur.samples * samples,
                Renderer::MAX_PROGRESSIVE_SAMPLES
            )));
        }
        let mut output = self
            .output
            .clone()
            .unwrap_or_else(|| crate::output::FrameOutput::new(renderer.options().effects));
        output.effects = renderer.options().effects;
        let probe = self.frame_path(0);
        output.check(&probe)?;
        let layered = output.needs_layers(&probe)? || output.needs_aovs();
        Ok((output, layered))
    }

    /// Renders and saves the frames `indices` as 8-bit images.
    fn images<R: RenderFrames>(
        &self,
        renderer: &mut R,
        path: &CameraPath,
        motions: &[Motion],
        indices: &[u32],
        (width, height): (u32, u32),
        mut on_frame: impl FnMut(&RenderedFrame),
    ) -> Result<()> {
        let base = *renderer.camera();
        for &index in indices {
            let moments = self.moments(index);
            let file = self.frame_path(index);
            let at = |r: &mut R, t: f64| moment(r, path, &base, motions, t);
            let image = if let [t] = moments[..] {
                at(renderer, t)?;
                renderer.render(width, height)?
            } else {
                renderer.render_over_time(width, height, &moments, |r, &t| at(r, t))?
            };
            crate::output::save_image(&image, &file)?;
            on_frame(&RenderedFrame {
                index,
                path: file,
                timing: renderer.last_timing(),
            });
        }
        Ok(())
    }
}

/// Sets `renderer`'s camera to `path`'s at time `t` (with `base`'s
/// projection) and its parameters to the `motions`' values at `t`.
#[cfg(feature = "opencl")]
fn moment<R: RenderFrames>(
    renderer: &mut R,
    path: &CameraPath,
    base: &Camera,
    motions: &[Motion],
    t: f64,
) -> Result<()> {
    renderer.set_camera(path.camera_at(path.start() + t, base))?;
    for motion in motions {
        for (name, value) in motion.values(t) {
            renderer.set_param(&name, value)?;
        }
    }
    Ok(())
}

/// Parses a frame range of a sequence of `total` frames: `a..b` (frames a
/// to b − 1), `a..=b`, `a..` (to the end), `..b`, `..` (all) or a single
/// frame `n`.
///
/// ```
/// use fractal_sdf::sequence::parse_range;
/// assert_eq!(parse_range("5..=7", 24)?, 5..8);
/// assert_eq!(parse_range("20..", 24)?, 20..24);
/// assert_eq!(parse_range("3", 24)?, 3..4);
/// assert!(parse_range("20..30", 24).is_err());
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
///
/// # Errors
/// [`Error::Invalid`] if the text is not a range, the range is empty or it
/// reaches past the last frame.
pub fn parse_range(text: &str, total: u32) -> Result<Range<u32>> {
    let bad = |reason: String| Error::Invalid {
        what: "frame range",
        reason,
    };
    let number = |s: &str| -> Result<Option<u32>> {
        let s = s.trim();
        if s.is_empty() {
            return Ok(None);
        }
        s.parse::<u32>()
            .map(Some)
            .map_err(|_| bad(format!("`{text}`: `{s}` is not a frame number")))
    };
    let text = text.trim();
    // Ends are counted in u64, so that `..=4294967295` ends one past the
    // largest u32 rather than being cut back to it.
    let (start, end) = if let Some((a, b)) = text.split_once("..=") {
        let end = number(b)?.ok_or_else(|| bad(format!("`{text}`: `..=` needs an end")))?;
        (number(a)?.unwrap_or(0), u64::from(end) + 1)
    } else if let Some((a, b)) = text.split_once("..") {
        (
            number(a)?.unwrap_or(0),
            u64::from(number(b)?.unwrap_or(total)),
        )
    } else {
        let n = number(text)?.ok_or_else(|| bad("the range is empty".into()))?;
        (n, u64::from(n) + 1)
    };
    if u64::from(start) >= end {
        return Err(bad(format!("`{text}` contains no frame")));
    }
    if end > u64::from(total) {
        return Err(bad(format!(
            "`{text}` reaches past the last frame ({} of frames 0..{total})",
            end - 1
        )));
    }
    // `end` is at most `total` here.
    let range = start..u32::try_from(end).unwrap_or(total);
    Ok(range)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_named_in_sortable_order() {
        assert_eq!(frame_name(0), "frame_00000.png");
        assert_eq!(frame_name(42), "frame_00042.png");
        assert_eq!(frame_name(123_456), "frame_123456.png");
        let mut names: Vec<String> = [10, 2, 100, 1].map(frame_name).to_vec();
        names.sort();
        assert_eq!(names, [1, 2, 10, 100].map(frame_name));
    }

    #[test]
    fn a_range_to_the_largest_frame_number_keeps_its_end() {
        // `..=u32::MAX` ends past any sequence's last frame (frames are
        // numbered below u32::MAX): refused, never cut back to fit.
        for text in ["0..=4294967295", "4294967295", "4294967294..=4294967295"] {
            let err = parse_range(text, u32::MAX).unwrap_err().to_string();
            assert!(
                err.contains("(4294967295 of frames 0..4294967295)"),
                "{text}: {err}"
            );
        }
        assert_eq!(parse_range("..=4294967294", u32::MAX).unwrap(), 0..u32::MAX);
        assert_eq!(
            parse_range("4294967294", u32::MAX).unwrap(),
            4294967294..u32::MAX
        );
        assert_eq!(parse_range("5..", u32::MAX).unwrap(), 5..u32::MAX);
    }

    #[test]
    fn frame_count_and_times_follow_the_rate() {
        let s = Sequence::for_duration("d", 30.0, 10.0).unwrap();
        assert_eq!(s.frames(), 300);
        assert_eq!(s.time(0), 0.0);
        assert_eq!(s.time(150), 5.0);
        assert_eq!(Sequence::for_duration("d", 24.0, 0.01).unwrap().frames(), 1);
        assert!(Sequence::for_duration("d", 24.0, 0.0).is_err());
        assert!(Sequence::for_duration("d", 24.0, f64::INFINITY).is_err());
        assert!(Sequence::for_duration("d", 1e9, 1e9).is_err());
        assert!(Sequence::new("d", 0.0, 10).is_err());
        assert!(Sequence::new("d", f64::NAN, 10).is_err());
        let err = Sequence::new("d", 24.0, 0).unwrap_err().to_string();
        assert!(err.contains("at least 1 frame"), "{err}");
    }

    #[test]
    fn errors_blame_the_argument_that_is_wrong() {
        let message = |fps: f64, seconds: f64| {
            let err = Sequence::for_duration("d", fps, seconds).unwrap_err();
            assert!(matches!(err, Error::Invalid { .. }), "{err}");
            err.to_string()
        };
        for fps in [f64::NAN, f64::INFINITY, 0.0, -24.0] {
            for seconds in [1.0, f64::NAN] {
                let err = message(fps, seconds);
                assert!(err.contains("frame rate"), "{fps}, {seconds}: {err}");
            }
        }
        for seconds in [f64::NAN, f64::NEG_INFINITY, 0.0, -1.0] {
            let err = message(24.0, seconds);
            assert!(err.contains("duration"), "{seconds}: {err}");
        }
        let err = message(1e300, 1e300);
        assert!(
            err.contains("1e300 s at 1e300 frames per second is inf frames"),
            "{err}"
        );
        let err = message(1e3, 1e5);
        assert!(
            err.contains("is 100000000 frames, too many (at most 10000000)"),
            "{err}"
        );
        assert_eq!(
            Sequence::for_duration("d", 1e-300, 1.0).unwrap().frames(),
            1,
            "rounds up to one frame"
        );
    }

    #[test]
    fn frame_counts_are_bounded() {
        let max = Sequence::MAX_FRAMES;
        assert_eq!(Sequence::new("d", 24.0, max).unwrap().frames(), max);
        for frames in [max + 1, u32::MAX] {
            let err = Sequence::new("d", 24.0, frames).unwrap_err().to_string();
            assert!(err.contains("too many"), "{err}");
        }
        // Lists of frames never reach past the sequence.
        let s = Sequence::new("/nonexistent-fractal-sdf", 24.0, 3).unwrap();
        assert_eq!(s.remaining(0..u32::MAX, (4, 4)), [0, 1, 2]);
        assert!(s.remaining(u32::MAX - 1..u32::MAX, (4, 4)).is_empty());
    }

    #[test]
    fn ranges_parse_like_rust_ranges() {
        assert_eq!(parse_range("0..24", 24).unwrap(), 0..24);
        assert_eq!(parse_range(" 2 .. 5 ", 24).unwrap(), 2..5);
        assert_eq!(parse_range("2..=5", 24).unwrap(), 2..6);
        assert_eq!(parse_range("..3", 24).unwrap(), 0..3);
        assert_eq!(parse_range("..", 24).unwrap(), 0..24);
        assert_eq!(parse_range("23", 24).unwrap(), 23..24);
        assert_eq!(parse_range("..=23", 24).unwrap(), 0..24);
        for bad in ["5..5", "7..3", "24", "0..25", "a..b", "", "1..=", "-1..3"] {
            let err = parse_range(bad, 24).expect_err(bad);
            assert!(matches!(err, Error::Invalid { .. }), "{bad}: {err}");
        }
        let err = parse_range("20..30", 24).unwrap_err().to_string();
        assert!(err.contains("past the last frame (29"), "{err}");
    }

    #[test]
    fn remaining_skips_only_whole_frames_on_disk() {
        use image::RgbaImage;
        let dir = std::env::temp_dir().join(format!("fractal-sdf-seq-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let size = (6, 4);
        let s = Sequence::new(&dir, 24.0, 8).unwrap();
        assert_eq!(s.remaining(0..8, size), [0, 1, 2, 3, 4, 5, 6, 7]);
        for i in [0, 2, 3, 6, 7] {
            crate::output::save_png(&RgbaImage::new(size.0, size.1), s.frame_path(i)).unwrap();
        }
        // A directory with a frame's name is not a frame.
        std::fs::create_dir(s.frame_path(5)).unwrap();
        // Frame 6 was cut short, frame 7 has another size.
        let whole = std::fs::read(s.frame_path(6)).unwrap();
        std::fs::write(s.frame_path(6), &whole[..whole.len() - 5]).unwrap();
        crate::output::save_png(&RgbaImage::new(5, 4), s.frame_path(7)).unwrap();
        assert_eq!(s.remaining(0..8, size), [1, 4, 5, 6, 7]);
        assert_eq!(s.remaining(2..4, size), Vec::<u32>::new());
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn ffmpeg_reads_the_numbered_frames() {
        let s = Sequence::new("out/seq", 30.0, 10).unwrap();
        let args = s.ffmpeg_args(Path::new("out/seq.mp4"));
        assert_eq!(
            args.join(" "),
            "-y -framerate 30 -i out/seq/frame_%05d.png -pix_fmt yuv420p out/seq.mp4"
        );
        let pattern = FRAME_PATTERN.replace("%05d", "00007");
        assert_eq!(pattern, frame_name(7));
    }
}
