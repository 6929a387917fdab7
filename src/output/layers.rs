//! Writing a rendered frame with its layers: OpenEXR with named channels,
//! 16-bit PNG and TIFF, and each arbitrary output value (AOV) as a 16-bit
//! PNG beside the image.

use std::io::{self, Cursor, Write};
use std::path::{Path, PathBuf};

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, SmallVec, Vec2,
    WritableImage,
};
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};

use super::{check_size, image_extension, save_image, save_tiff, write_atomic};
use crate::error::{Error, Result};
use crate::quality::{Effects, display};
use crate::render::{Frame, Layers};

/// An output of a rendered frame besides its colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[non_exhaustive]
pub enum Aov {
    /// Distance along the pixel-centre ray to the surface (`+∞` on a
    /// miss).
    Depth,
    /// World-space unit normal.
    Normal,
    /// World-space position of the hit.
    Position,
    /// Linear base colour before any light.
    Albedo,
    /// Ambient occlusion: 1 open, towards 0 in creases.
    Occlusion,
    /// The lights' visibility: 1 lit, 0 in shadow.
    Shadow,
    /// The orbit-trap value that tints a fractal, or that a palette
    /// reads on a fractal it paints (1 on other surfaces).
    Trap,
    /// Distance evaluations the pixel's colour cost.
    Evaluations,
    /// The fraction of the pixel's samples (over every pass) whose ray
    /// hit a surface: a matte of what is not background.
    Coverage,
    /// Which shape the hit belongs to ([`Layers::object`]: 1 for the
    /// scene's first shape, 0 on a miss), for a matte of any object.
    Object,
    /// Which material the hit has ([`Layers::material`]: 1 for the scene's
    /// first material node, 0 for the default material and on a miss).
    Material,
}

impl Aov {
    /// Every output, in the order files list them.
    pub const ALL: [Aov; 11] = [
        Aov::Depth,
        Aov::Normal,
        Aov::Position,
        Aov::Albedo,
        Aov::Occlusion,
        Aov::Shadow,
        Aov::Trap,
        Aov::Evaluations,
        Aov::Coverage,
        Aov::Object,
        Aov::Material,
    ];

    /// The output's name: its layer in an OpenEXR file, the suffix of its
    /// PNG, and its name on the command line (`depth`, `normal`,
    /// `position`, `albedo`, `ao`, `shadow`, `trap`, `evaluations`,
    /// `coverage`, `object`, `material`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Aov::Depth => "depth",
            Aov::Normal => "normal",
            Aov::Position => "position",
            Aov::Albedo => "albedo",
            Aov::Occlusion => "ao",
            Aov::Shadow => "shadow",
            Aov::Trap => "trap",
            Aov::Evaluations => "evaluations",
            Aov::Coverage => "coverage",
            Aov::Object => "object",
            Aov::Material => "material",
        }
    }

    /// The output named `name` (as [`Aov::name`] writes it, any case).
    ///
    /// # Errors
    /// [`Error::Invalid`] naming every output, for any other name.
    pub fn from_name(name: &str) -> Result<Aov> {
        Aov::ALL
            .into_iter()
            .find(|a| a.name().eq_ignore_ascii_case(name.trim()))
            .ok_or_else(|| Error::Invalid {
                what: "output",
                reason: format!(
                    "`{name}` is not an output; the outputs are {}",
                    Aov::ALL.map(Aov::name).join(", ")
                ),
            })
    }

    /// The channels of its OpenEXR layer, after the layer's name and a
    /// dot (`depth.Z`, `normal.X`, ...).
    #[must_use]
    pub fn channels(self) -> &'static [&'static str] {
        match self {
            Aov::Depth => &["Z"],
            Aov::Normal | Aov::Position => &["X", "Y", "Z"],
            Aov::Albedo => &["R", "G", "B"],
            Aov::Occlusion
            | Aov::Shadow
            | Aov::Trap
            | Aov::Evaluations
            | Aov::Coverage
            | Aov::Object
            | Aov::Material => &["Y"],
        }
    }

    /// Whether the output needs the frame's shading [`Layers`].
    fn needs_layers(self) -> bool {
        !matches!(self, Aov::Depth | Aov::Normal | Aov::Evaluations)
    }

    /// The output's values, channel by channel, one per pixel.
    fn values(self, frame: &Frame) -> Result<Vec<Vec<f32>>> {
        let layers = if self.needs_layers() {
            Some(layers(frame, self.name())?)
        } else {
            None
        };
        let split = |v: &[[f32; 3]]| (0..3).map(|c| v.iter().map(|p| p[c]).collect()).collect();
        #[allow(clippy::cast_precision_loss)] // counts far below 2^24
        Ok(match (self, layers) {
            (Aov::Depth, _) => vec![frame.depth.clone()],
            (Aov::Normal, _) => split(&frame.normal),
            (Aov::Evaluations, _) => vec![frame.evaluations.iter().map(|&e| e as f32).collect()],
            (Aov::Position, Some(l)) => split(&l.position),
            (Aov::Albedo, Some(l)) => split(&l.albedo),
            (Aov::Occlusion, Some(l)) => vec![l.occlusion.clone()],
            (Aov::Shadow, Some(l)) => vec![l.shadow.clone()],
            (Aov::Trap, Some(l)) => vec![l.trap.clone()],
            (Aov::Coverage, Some(l)) => vec![l.linear.iter().map(|c| c[3]).collect()],
            (Aov::Object | Aov::Material, Some(l)) if l.object.is_empty() => {
                return Err(Error::Invalid {
                    what: "output",
                    reason: format!(
                        "the frame has no object ids, which {} needs: fill them with \
                         Renderer::identify",
                        self.name()
                    ),
                });
            }
            // Ids far below 2^24: exact in a float.
            (Aov::Object, Some(l)) => vec![l.object.iter().map(|&k| k as f32).collect()],
            (Aov::Material, Some(l)) => vec![l.material.iter().map(|&k| k as f32).collect()],
            (_, None) => unreachable!("the layers were read above"),
        })
    }
}

/// Bits per channel of a PNG or TIFF image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Bits {
    /// 8 bits: the renderer's image as it is.
    #[default]
    Eight,
    /// 16 bits: the linear colour through the display transform on the
    /// host, without the 8-bit rounding (needs the frame's [`Layers`]).
    Sixteen,
}

/// How [`save_frame`] writes a frame.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FrameOutput {
    /// The outputs to write besides the colour.
    pub aovs: Vec<Aov>,
    /// Bits per channel of a PNG or TIFF colour image.
    pub bits: Bits,
    /// The display transform of 16-bit images: the effects the frame was
    /// rendered with (their exposure is already in the linear colour, so
    /// only the tone curve and gamma apply).
    pub effects: Effects,
}

impl FrameOutput {
    /// The colour alone, 8 bits per channel, for frames rendered with
    /// `effects`.
    #[must_use]
    pub fn new(effects: Effects) -> Self {
        FrameOutput {
            aovs: Vec::new(),
            bits: Bits::Eight,
            effects,
        }
    }

    /// Writes `aovs` too.
    #[must_use]
    pub fn aovs(mut self, aovs: impl IntoIterator<Item = Aov>) -> Self {
        self.aovs = aovs.into_iter().collect();
        self
    }

    /// Writes the colour with `bits` per channel.
    #[must_use]
    pub fn bits(mut self, bits: Bits) -> Self {
        self.bits = bits;
        self
    }

    /// Whether writing to `path` needs the frame's [`Layers`]
    /// ([`Renderer::render_layers`](crate::render::Renderer::render_layers)
    /// renders them): an OpenEXR file, 16 bits, or an output made of them.
    ///
    /// # Errors
    /// As [`image_extension`].
    pub fn needs_layers(&self, path: &Path) -> Result<bool> {
        Ok(image_extension(path)?.as_deref() == Some("exr")
            || self.bits == Bits::Sixteen
            || self.aovs.iter().any(|a| a.needs_layers()))
    }

    /// Checks that the format `path` names can hold these outputs, before
    /// anything is rendered.
    ///
    /// # Errors
    /// As [`image_extension`]; [`Error::Invalid`] for 16 bits in a JPEG
    /// (8 bits a channel) or an OpenEXR file (32-bit floats).
    pub fn check(&self, path: &Path) -> Result<()> {
        let holds = match image_extension(path)?.as_deref() {
            Some("jpg" | "jpeg") => "8 bits per channel",
            Some("exr") => "32-bit floats",
            _ => return Ok(()),
        };
        if self.bits == Bits::Sixteen {
            return Err(Error::Invalid {
                what: "output",
                reason: format!(
                    "{} holds {holds}: 16 bits apply to a .png or .tif",
                    path.display()
                ),
            });
        }
        Ok(())
    }

    /// Whether writing needs the frame's object and material ids
    /// ([`Renderer::identify`](crate::render::Renderer::identify) fills
    /// them).
    #[must_use]
    pub fn needs_ids(&self) -> bool {
        self.aovs
            .iter()
            .any(|a| matches!(a, Aov::Object | Aov::Material))
    }

    /// Whether writing needs the frame's depth and normal outputs at
    /// least ([`Renderer::render_with_aovs`](crate::render::Renderer::render_with_aovs)).
    #[must_use]
    pub fn needs_aovs(&self) -> bool {
        !self.aovs.is_empty()
    }
}

/// Writes `frame` to `path` in the format its extension names, with the
/// outputs `output` asks for, and returns every file written.
///
/// - **`.exr`**: one OpenEXR file (lossless ZIP compression, 32-bit
///   floats) whose channels `R`, `G`, `B` hold the exposed linear colour
///   before the tone curve, background included, with `A` 1 (the image is
///   opaque, as its PNG is), and each output a layer of its own:
///   `depth.Z`, `normal.X`..`Z`, `position.X`..`Z`, `albedo.R`..`B`,
///   `ao.Y`, `shadow.Y`, `trap.Y`, `evaluations.Y`, `coverage.Y`,
///   `object.Y`, `material.Y`.
/// - **`.png`, `.tif`/`.tiff`**: the colour at 8 or 16 bits
///   ([`FrameOutput::bits`]); **`.jpg`/`.jpeg`**: at 8 bits.
/// - For every format but OpenEXR, each output is a 16-bit PNG beside the
///   image, named after it and the output (`out.png` → `out.depth.png`):
///   depth as grey from white at the nearest hit to black at the farthest
///   (0 on a miss), normals as `0.5 + 0.5 n`, positions scaled into the
///   box of the frame's hits, albedo, occlusion, shadow, trap and coverage
///   clipped to `[0, 1]` (linear, no gamma), evaluations scaled by the
///   frame's largest count, object and material ids as the 16-bit values
///   themselves (ids past 65,535 clip).
///
/// Each file is written atomically, as [`save_png`](super::save_png)
/// writes.
///
/// ```no_run
/// use fractal_sdf::output::{Aov, FrameOutput, save_frame};
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::render::Renderer;
///
/// let scene = Scene::new(mandelbulb(8.0));
/// let mut renderer = Renderer::new(&scene, Quality::preview())?;
/// let frame = renderer.render_layers(320, 240)?;
/// let output = FrameOutput::new(Effects::default()).aovs([Aov::Depth, Aov::Normal]);
/// save_frame(&frame, "bulb.exr", &output)?;
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
///
/// # Errors
/// As [`save_image`] and [`FrameOutput::check`]; [`Error::Invalid`] where
/// the frame lacks what the format or an output needs (its layers, or
/// AOVs: render it with
/// [`Renderer::render_layers`](crate::render::Renderer::render_layers)).
pub fn save_frame(
    frame: &Frame,
    path: impl AsRef<Path>,
    output: &FrameOutput,
) -> Result<Vec<PathBuf>> {
    let path = path.as_ref();
    let extension = image_extension(path)?;
    check_size(frame.width(), frame.height(), path, "an image")?;
    if output.needs_aovs() && frame.depth.len() != frame.image.len() / 4 {
        return Err(missing("outputs besides the colour", "AOVs"));
    }
    output.check(path)?;
    if extension.as_deref() == Some("exr") {
        write_exr(frame, path, &output.aovs)?;
        return Ok(vec![path.to_path_buf()]);
    }
    // The outputs beside the image go first: where the image is on disk,
    // so are they (a sequence resumes by its frames' images).
    let mut beside = Vec::with_capacity(output.aovs.len());
    for &aov in &output.aovs {
        let target = aov_path(path, aov);
        let (pixels, color) = aov_png(frame, aov)?;
        write_png16(&target, frame.width(), frame.height(), &pixels, color)?;
        beside.push(target);
    }
    match extension.as_deref() {
        Some("tif" | "tiff") => write_tiff(frame, path, output)?,
        _ if output.bits == Bits::Sixteen => {
            let rgba = sixteen_bit(frame, &output.effects)?;
            write_png16(
                path,
                frame.width(),
                frame.height(),
                &rgba,
                ExtendedColorType::Rgba16,
            )?;
        }
        _ => save_image(&frame.image, path)?,
    }
    let mut written = vec![path.to_path_buf()];
    written.extend(beside);
    Ok(written)
}

/// Where [`save_frame`] writes `aov` beside the image at `path`:
/// `out.png` → `out.depth.png`.
#[must_use]
pub fn aov_path(path: &Path, aov: Aov) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    path.with_file_name(format!("{stem}.{}.png", aov.name()))
}

fn missing(what: &str, how: &str) -> Error {
    Error::Invalid {
        what: "output",
        reason: format!(
            "the frame has no {how}, which {what} need: render it with \
             Renderer::render_layers"
        ),
    }
}

fn layers<'a>(frame: &'a Frame, what: &str) -> Result<&'a Layers> {
    frame
        .layers
        .as_ref()
        .ok_or_else(|| missing(what, "shading layers"))
}

/// The colour through the display transform at 16 bits, RGBA.
fn sixteen_bit(frame: &Frame, effects: &Effects) -> Result<Vec<u16>> {
    let layers = layers(frame, "16-bit colour")?;
    // The linear colour holds the exposure already.
    let effects = effects.exposure(0.0);
    let mut out = Vec::with_capacity(layers.linear.len() * 4);
    for &[r, g, b, _] in &layers.linear {
        let shown = display([r, g, b], &effects);
        out.extend(shown.map(unit_to_u16));
        out.push(u16::MAX);
    }
    Ok(out)
}

/// `v` in `[0, 1]` as a 16-bit value, rounded to nearest.
#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // clamped first
fn unit_to_u16(v: f32) -> u16 {
    (v.clamp(0.0, 1.0) * 65535.0).round() as u16
}

/// An output as 16-bit PNG samples: grey or RGB.
fn aov_png(frame: &Frame, aov: Aov) -> Result<(Vec<u16>, ExtendedColorType)> {
    let channels = aov.values(frame)?;
    let n = frame.depth.len();
    let hits = || (0..n).filter(|&i| frame.hit[i]);
    // Each channel's range over the hits, for the outputs shown by it.
    let range = |c: &[f32]| {
        hits()
            .map(|i| c[i])
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            })
    };
    let scaled = |v: f32, (lo, hi): (f32, f32)| {
        if hi > lo { (v - lo) / (hi - lo) } else { 1.0 }
    };
    let mapped: Vec<Vec<f32>> = match aov {
        Aov::Depth => {
            let r = range(&channels[0]);
            let near_white = |i: usize| {
                if frame.hit[i] {
                    // 1/65535 at the farthest, so a hit is never a miss.
                    (1.0 - scaled(channels[0][i], r)).max(1.0 / 65535.0)
                } else {
                    0.0
                }
            };
            vec![(0..n).map(near_white).collect()]
        }
        Aov::Normal => channels
            .iter()
            .map(|c| c.iter().map(|v| 0.5 + 0.5 * v).collect())
            .collect(),
        Aov::Position => {
            let box_of_hits: Vec<(f32, f32)> = channels.iter().map(|c| range(c)).collect();
            channels
                .iter()
                .zip(box_of_hits)
                .map(|(c, r)| {
                    (0..n)
                        .map(|i| if frame.hit[i] { scaled(c[i], r) } else { 0.0 })
                        .collect()
                })
                .collect()
        }
        Aov::Evaluations => {
            let most = channels[0].iter().copied().fold(0.0f32, f32::max).max(1.0);
            vec![channels[0].iter().map(|v| v / most).collect()]
        }
        Aov::Albedo | Aov::Occlusion | Aov::Shadow | Aov::Trap | Aov::Coverage => channels,
        // The ids themselves as 16-bit values (a matte is `value == k`).
        Aov::Object | Aov::Material => channels
            .iter()
            .map(|c| c.iter().map(|v| v / 65535.0).collect())
            .collect(),
    };
    let color = if mapped.len() == 3 {
        ExtendedColorType::Rgb16
    } else {
        ExtendedColorType::L16
    };
    let mut out = Vec::with_capacity(n * mapped.len());
    for i in 0..n {
        out.extend(mapped.iter().map(|c| unit_to_u16(c[i])));
    }
    Ok((out, color))
}

/// Writes 16-bit samples as a PNG.
fn write_png16(
    path: &Path,
    width: u32,
    height: u32,
    samples: &[u16],
    color: ExtendedColorType,
) -> Result<()> {
    let bytes = native_bytes(samples);
    write_atomic(path, "image", |file| {
        let mut writer = io::BufWriter::new(file);
        PngEncoder::new(&mut writer)
            .write_image(&bytes, width, height, color)
            .map_err(super::io_error)?;
        writer.flush()
    })
}

/// 16-bit samples as the encoders take them: native order bytes.
fn native_bytes(samples: &[u16]) -> Vec<u8> {
    samples.iter().flat_map(|s| s.to_ne_bytes()).collect()
}

/// Writes the colour as a TIFF at 8 or 16 bits.
fn write_tiff(frame: &Frame, path: &Path, output: &FrameOutput) -> Result<()> {
    let (bytes, color) = match output.bits {
        Bits::Eight => (frame.image.as_raw().clone(), ExtendedColorType::Rgba8),
        Bits::Sixteen => (
            native_bytes(&sixteen_bit(frame, &output.effects)?),
            ExtendedColorType::Rgba16,
        ),
    };
    save_tiff(path, &bytes, (frame.width(), frame.height()), color)
}

/// Writes the OpenEXR file: the colour, opaque, then each output's layer.
fn write_exr(frame: &Frame, path: &Path, aovs: &[Aov]) -> Result<()> {
    let linear = &layers(frame, "an OpenEXR file")?.linear;
    let channel =
        |name: String, values: Vec<f32>| AnyChannel::new(name.as_str(), FlatSamples::F32(values));
    let mut channels: Vec<AnyChannel<FlatSamples>> = ["R", "G", "B"]
        .into_iter()
        .enumerate()
        .map(|(c, name)| channel(name.into(), linear.iter().map(|p| p[c]).collect()))
        .collect();
    channels.push(channel("A".into(), vec![1.0; linear.len()]));
    for &aov in aovs {
        for (name, values) in aov.channels().iter().zip(aov.values(frame)?) {
            channels.push(channel(format!("{}.{name}", aov.name()), values));
        }
    }
    let size = Vec2(frame.width() as usize, frame.height() as usize);
    let attributes = LayerAttributes {
        software_name: Some(concat!("fractal-sdf ", env!("CARGO_PKG_VERSION")).into()),
        ..LayerAttributes::default()
    };
    let layer = Layer::new(
        size,
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let mut encoded = Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut encoded)
        .map_err(|e| {
            Error::io(
                path,
                "cannot encode the OpenEXR file",
                io::Error::new(io::ErrorKind::InvalidData, e.to_string()),
            )
        })?;
    let encoded = encoded.into_inner();
    write_atomic(path, "image", |mut file| file.write_all(&encoded))
}
