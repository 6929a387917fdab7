//! Dense voxel grids of signed distances: NRRD files (a short text header
//! and raw little-endian `f32`, which volume tools such as 3D Slicer,
//! ParaView and Fiji read) and PNG slice stacks.
//!
//! The stored values are clamped to a narrow band of
//! ±[`BAND_VOXELS`] samples' spacings around the surface. Far from the
//! surface a value says little: inside a fractal its estimate is no
//! distance, and an inside-only shape ([`InsideShape`]) has no distance
//! at all, only a sign (±10¹⁵). Unclamped, those values span twenty
//! orders of magnitude and a viewer's transfer function or iso-surface
//! slider has nothing to hold on to; clamped, every value is within a few
//! spacings, the sign is kept (negative inside), and a value inside the
//! band is the scene's own estimate.
//!
//! [`InsideShape`]: crate::scene::InsideShape

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use glam::DVec3;
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};

use super::grid::{Progress, Stage, plan};
use super::{CHUNK, GridOptions};
use crate::error::{Error, Result};
use crate::ir::CompiledScene;
use crate::output::write_atomic;

/// The most samples a volume may hold (2 GiB of `f32`).
pub const MAX_VOLUME_SAMPLES: u64 = 1 << 29;

/// The half width of the band a volume's values are clamped to, in
/// samples' spacings: every stored value lies in
/// `[-BAND_VOXELS · spacing, BAND_VOXELS · spacing]`.
pub const BAND_VOXELS: f64 = 3.0;

/// Signed distances at every sample of a regular grid: negative inside,
/// clamped to ±[`BAND_VOXELS`] spacings (see [`Volume::band`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Volume {
    /// The position of sample `(0, 0, 0)`.
    pub origin: DVec3,
    /// The distance between neighbouring samples.
    pub spacing: f64,
    /// Samples along each axis.
    pub dims: [u32; 3],
    /// The distances, `x` fastest, then `y`, then `z`; each within
    /// [`Volume::band`] of zero, with the scene's sign (a sample where
    /// the scene gives no number counts as outside).
    pub distances: Vec<f32>,
}

impl Volume {
    /// The largest magnitude a stored value has: [`BAND_VOXELS`] times
    /// the spacing (as an `f32`).
    #[must_use]
    pub fn band(&self) -> f32 {
        band(self.spacing)
    }

    /// The index of sample `(i, j, k)` in [`Volume::distances`].
    #[must_use]
    pub fn index(&self, [i, j, k]: [u32; 3]) -> usize {
        let [nx, ny, _] = self.dims.map(|d| d as usize);
        i as usize + nx * (j as usize + ny * k as usize)
    }

    /// The position of sample `(i, j, k)`.
    #[must_use]
    pub fn point(&self, at: [u32; 3]) -> DVec3 {
        self.origin + self.spacing * DVec3::from_array(at.map(f64::from))
    }

    /// The distance at sample `(i, j, k)`.
    #[must_use]
    pub fn distance(&self, at: [u32; 3]) -> f32 {
        self.distances[self.index(at)]
    }

    /// Writes the volume as an NRRD file: the header names the type
    /// (`float`), the sizes, the spacing and the position of the first
    /// sample (`axis mins`), then the distances follow raw.
    ///
    /// # Errors
    /// [`Error::Io`] naming `path` and what failed.
    pub fn write_nrrd(&self, path: impl AsRef<Path>) -> Result<()> {
        write_atomic(path.as_ref(), "volume", |file| {
            let mut out = BufWriter::new(file);
            let [x, y, z] = self.dims;
            let h = self.spacing;
            let o = self.origin;
            write!(
                out,
                "NRRD0004\n# signed distances written by fractal-sdf: negative inside\n\
                 # clamped to +-{} ({BAND_VOXELS} spacings)\n\
                 type: float\ndimension: 3\nsizes: {x} {y} {z}\nspacings: {h} {h} {h}\n\
                 axis mins: {} {} {}\nendian: little\nencoding: raw\n\n",
                self.band(),
                o.x,
                o.y,
                o.z
            )?;
            for d in &self.distances {
                out.write_all(&d.to_le_bytes())?;
            }
            out.flush()
        })
    }

    /// Writes one 8-bit grey PNG per `z` into `dir` (`slice_0000.png`,
    /// ...): 255 where the sample is inside, 0 outside. Returns the files
    /// in order.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file and what failed.
    pub fn write_slices(&self, dir: impl AsRef<Path>) -> Result<Vec<PathBuf>> {
        let [nx, ny, nz] = self.dims;
        let digits = nz.to_string().len().max(4);
        let mut files = Vec::with_capacity(nz as usize);
        for k in 0..nz {
            let start = self.index([0, 0, k]);
            let layer = &self.distances[start..start + (nx * ny) as usize];
            let pixels: Vec<u8> = layer
                .iter()
                .map(|d| if *d < 0.0 { 255 } else { 0 })
                .collect();
            let path = dir.as_ref().join(format!("slice_{k:0digits$}.png"));
            write_atomic(&path, "slice", |file| {
                PngEncoder::new(BufWriter::new(file))
                    .write_image(&pixels, nx, ny, ExtendedColorType::L8)
                    .map_err(std::io::Error::other)
            })?;
            files.push(path);
        }
        Ok(files)
    }
}

/// The signed distances of `scene` at every sample of the grid `options`
/// describe: `resolution + 1` samples along the box's longest side.
///
/// # Errors
/// As [`extract`](super::extract); [`Error::Invalid`] for a grid of more
/// than [`MAX_VOLUME_SAMPLES`].
pub fn sample_volume(scene: &CompiledScene, options: &GridOptions) -> Result<Volume> {
    sample_volume_with_progress(scene, options, &mut |_| {})
}

/// [`sample_volume`], reporting progress as it goes.
///
/// # Errors
/// As [`sample_volume`].
pub fn sample_volume_with_progress(
    scene: &CompiledScene,
    options: &GridOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Volume> {
    let (grid, sampling) = plan(scene, options, progress)?;
    let dims = grid.cells.map(|c| c + 1);
    let samples: u64 = dims.iter().map(|&d| u64::from(d)).product();
    if samples > MAX_VOLUME_SAMPLES {
        return Err(Error::Invalid {
            what: "volume size",
            reason: format!(
                "{}×{}×{} samples is more than {MAX_VOLUME_SAMPLES}: lower the resolution",
                dims[0], dims[1], dims[2]
            ),
        });
    }
    let mut volume = Volume {
        origin: grid.origin,
        spacing: grid.spacing,
        dims,
        distances: vec![0.0; usize::try_from(samples).expect("checked above")],
    };
    let count = dims.map(|d| d.div_ceil(CHUNK));
    let mut starts = Vec::new();
    for z in 0..count[2] {
        for y in 0..count[1] {
            for x in 0..count[0] {
                starts.push([x, y, z].map(|i| i32::try_from(i * CHUNK).expect("grids are small")));
            }
        }
    }
    let per = (CHUNK as usize).pow(3);
    let band = band(grid.spacing);
    let total = starts.len() as u64;
    let mut done = 0u64;
    for batch in starts.chunks(256) {
        let values = sampling.blocks(grid.origin, grid.spacing, CHUNK, batch)?;
        for (start, block) in batch.iter().zip(values.chunks_exact(per)) {
            for (s, d) in block.iter().enumerate() {
                let s = u32::try_from(s).expect("a block is small");
                let local = [s % CHUNK, (s / CHUNK) % CHUNK, s / (CHUNK * CHUNK)];
                let at = [0, 1, 2].map(|a| start[a].unsigned_abs() + local[a]);
                if (0..3).all(|a| at[a] < dims[a]) {
                    let i = volume.index(at);
                    volume.distances[i] = if d.is_nan() {
                        band
                    } else {
                        d.clamp(-band, band)
                    };
                }
            }
        }
        done += batch.len() as u64;
        progress(Progress {
            stage: Stage::Sampling,
            done,
            total,
        });
    }
    Ok(volume)
}

/// [`BAND_VOXELS`] spacings as an `f32`, at least the smallest positive
/// one (so that a clamped value keeps its sign).
fn band(spacing: f64) -> f32 {
    #[allow(clippy::cast_possible_truncation)] // Grids are far below f32::MAX.
    let band = (BAND_VOXELS * spacing) as f32;
    band.max(f32::MIN_POSITIVE)
}
