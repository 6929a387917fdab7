//! Timing renders and measuring their error against a reference frame:
//! shared by the `tradeoff` and `deep_zoom` studies.

use std::time::{Duration, Instant};

use fractal_sdf::image::Rgba;
use fractal_sdf::metrics::{mask_mismatch, mean_depth_error, psnr, ssim};
use fractal_sdf::prelude::*;
use fractal_sdf::render::{Frame, Renderer};
use image::RgbaImage;

/// How many timed renders to take.
#[derive(Debug, Clone, Copy)]
pub struct Runs {
    /// At least this many timed renders (after one untimed warm-up).
    pub min: usize,
    /// At most this many.
    pub max: usize,
    /// Stop after `min` once the timed renders have taken this long.
    pub budget: Duration,
}

impl Default for Runs {
    fn default() -> Self {
        Runs {
            min: 3,
            max: 5,
            budget: Duration::from_secs(3),
        }
    }
}

/// The median wall time of a render, in milliseconds, and how many renders
/// it is the median of.
#[derive(Debug, Clone, Copy)]
pub struct Timing {
    /// Median milliseconds per frame.
    pub median_ms: f64,
    /// Timed renders.
    pub runs: usize,
}

/// Renders once to warm up, then times renders until `runs` is satisfied.
pub fn time_renders(renderer: &mut Renderer, size: (u32, u32), runs: Runs) -> Result<Timing> {
    renderer.render(size.0, size.1)?;
    let start = Instant::now();
    let mut times = Vec::new();
    while times.len() < runs.max && (times.len() < runs.min || start.elapsed() < runs.budget) {
        let t = Instant::now();
        renderer.render(size.0, size.1)?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    let n = times.len();
    let median_ms = if n % 2 == 1 {
        times[n / 2]
    } else {
        0.5 * (times[n / 2 - 1] + times[n / 2])
    };
    Ok(Timing { median_ms, runs: n })
}

/// A frame's error against a reference frame of the same size.
#[derive(Debug, Clone, Copy)]
pub struct Errors {
    /// Peak signal-to-noise ratio in dB (infinite when identical).
    pub psnr: f64,
    /// Mean structural similarity.
    pub ssim: f64,
    /// Percentage of pixels whose hit flags differ.
    pub mask_pct: f64,
    /// Mean absolute depth difference where both hit, in scene units.
    pub depth: f64,
    /// PSNR of the two images box-filtered 2×2 (half the resolution, four
    /// samples per pixel): what is left once edge aliasing is averaged.
    pub psnr_half: f64,
}

/// Compares `frame` with `reference`.
pub fn compare(frame: &Frame, reference: &Frame) -> Errors {
    Errors {
        psnr: psnr(&frame.image, &reference.image),
        ssim: ssim(&frame.image, &reference.image),
        mask_pct: 100.0 * mask_mismatch(&frame.hit, &reference.hit),
        depth: mean_depth_error(&frame.depth, &reference.depth, &frame.hit, &reference.hit).0,
        psnr_half: psnr(&half(&frame.image), &half(&reference.image)),
    }
}

/// The image at half the resolution, each pixel the mean of a 2×2 block.
pub fn half(image: &RgbaImage) -> RgbaImage {
    let (w, h) = ((image.width() / 2).max(1), (image.height() / 2).max(1));
    RgbaImage::from_fn(w, h, |x, y| {
        let mut sum = [0u32; 4];
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let p = image.get_pixel(
                (2 * x + dx).min(image.width() - 1),
                (2 * y + dy).min(image.height() - 1),
            );
            for c in 0..4 {
                sum[c] += u32::from(p[c]);
            }
        }
        #[allow(clippy::cast_possible_truncation)] // a mean of four bytes
        Rgba(sum.map(|v| ((v + 2) / 4) as u8))
    })
}

/// Whether `--flag` is on the command line.
pub fn flag(name: &str) -> bool {
    std::env::args().any(|a| a == name)
}

/// The value after `--name` on the command line.
pub fn value(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}
