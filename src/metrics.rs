//! Comparing images: how far a render is from a reference — after
//! changing a [`Quality`](crate::quality::Quality) knob, a device or the
//! precision — as numbers a test can bound.
//!
//! - [`psnr`] and [`ssim`] compare two colour images (higher is closer;
//!   identical images give infinity and 1), and [`block_psnr`] compares
//!   the means of blocks of pixels: two path-traced pictures of few
//!   samples, without their grain;
//! - [`mask_mismatch`] and [`mean_depth_error`] compare the per-pixel hit
//!   flags and depths of two renders (the renderer's `Frame`, feature
//!   `opencl`), where the colours alone would hide a missed surface.
//!
//! The crate's own accuracy tests and the `tradeoff` example measure with
//! these.
//!
//! ```
//! use fractal_sdf::image::{Rgba, RgbaImage};
//! use fractal_sdf::metrics::{psnr, ssim};
//!
//! let a = RgbaImage::from_pixel(16, 16, Rgba([100, 150, 200, 255]));
//! let mut b = a.clone();
//! b.put_pixel(3, 4, Rgba([110, 150, 200, 255]));
//! assert!(psnr(&a, &a).is_infinite());
//! assert!(psnr(&a, &b) > 40.0);
//! assert!(ssim(&a, &b) < 1.0 && ssim(&a, &b) > 0.9);
//! ```

use image::RgbaImage;

/// Peak signal-to-noise ratio in dB over the RGB channels (8-bit peak
/// 255); `f64::INFINITY` for identical images.
///
/// # Panics
/// If the images differ in size.
#[must_use]
pub fn psnr(a: &RgbaImage, b: &RgbaImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions(), "images differ in size");
    let mut sum = 0.0;
    let mut count = 0usize;
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        for c in 0..3 {
            let d = f64::from(pa[c]) - f64::from(pb[c]);
            sum += d * d;
            count += 1;
        }
    }
    if count == 0 || sum == 0.0 {
        return f64::INFINITY;
    }
    #[allow(clippy::cast_precision_loss)]
    let mse = sum / count as f64;
    10.0 * (255.0 * 255.0 / mse).log10()
}

/// [`psnr`] between the two images averaged over blocks of `k`×`k`
/// pixels (a partial block at the right or bottom edge left out): what a
/// Monte Carlo picture converges to, without the grain of its samples.
/// Two renders whose samples differ here and there (a path that bounced
/// elsewhere) agree in their block means where the pictures are the same.
///
/// ```
/// use fractal_sdf::image::{Rgba, RgbaImage};
/// use fractal_sdf::metrics::{block_psnr, psnr};
///
/// // The same grey, drawn as grain: one bright pixel in four.
/// let flat = RgbaImage::from_pixel(8, 8, Rgba([64, 64, 64, 255]));
/// let grain = RgbaImage::from_fn(8, 8, |x, y| {
///     let v = if x % 2 == 0 && y % 2 == 0 { 253 } else { 1 };
///     Rgba([v, v, v, 255])
/// });
/// assert!(psnr(&flat, &grain) < 10.0);
/// assert!(block_psnr(&flat, &grain, 2).is_infinite());
/// ```
///
/// # Panics
/// If the images differ in size, or `k` is 0 or larger than either side
/// (no whole block to compare).
#[must_use]
pub fn block_psnr(a: &RgbaImage, b: &RgbaImage, k: u32) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions(), "images differ in size");
    assert!(
        k > 0 && k <= a.width() && k <= a.height(),
        "blocks of 1 pixel to the image's shorter side"
    );
    psnr(&block_means(a, k), &block_means(b, k))
}

/// The image averaged over blocks of `k`×`k` pixels, rounded to 8 bits.
fn block_means(image: &RgbaImage, k: u32) -> RgbaImage {
    let area = k * k;
    RgbaImage::from_fn(image.width() / k, image.height() / k, |x, y| {
        let mut sum = [0u32; 4];
        for dy in 0..k {
            for dx in 0..k {
                let p = image.get_pixel(x * k + dx, y * k + dy).0;
                for (s, v) in sum.iter_mut().zip(p) {
                    *s += u32::from(v);
                }
            }
        }
        image::Rgba(sum.map(|s| u8::try_from((s + area / 2) / area).unwrap_or(u8::MAX)))
    })
}

/// Luma (Rec. 601) of each pixel, in `[0, 255]`.
fn luma(img: &RgbaImage) -> Vec<f64> {
    img.pixels()
        .map(|p| 0.299 * f64::from(p[0]) + 0.587 * f64::from(p[1]) + 0.114 * f64::from(p[2]))
        .collect()
}

/// Mean structural similarity of the luma channels over 8×8 windows with
/// stride 4 (Wang et al. 2004 constants): 1 for identical images, lower for
/// structural differences.
///
/// # Panics
/// If the images differ in size.
#[must_use]
pub fn ssim(a: &RgbaImage, b: &RgbaImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions(), "images differ in size");
    let (w, h) = (a.width() as usize, a.height() as usize);
    let (la, lb) = (luma(a), luma(b));
    let (c1, c2) = ((0.01f64 * 255.0).powi(2), (0.03f64 * 255.0).powi(2));
    let win = 8.min(w).min(h).max(1);
    let (mut total, mut windows) = (0.0, 0u32);
    let mut y = 0;
    while y + win <= h {
        let mut x = 0;
        while x + win <= w {
            let idx = |i: usize| (y + i / win) * w + x + i % win;
            #[allow(clippy::cast_precision_loss)]
            let n = (win * win) as f64;
            let (mut ma, mut mb) = (0.0, 0.0);
            for i in 0..win * win {
                ma += la[idx(i)];
                mb += lb[idx(i)];
            }
            ma /= n;
            mb /= n;
            let (mut va, mut vb, mut cov) = (0.0, 0.0, 0.0);
            for i in 0..win * win {
                let (da, db) = (la[idx(i)] - ma, lb[idx(i)] - mb);
                va += da * da;
                vb += db * db;
                cov += da * db;
            }
            let denom = if n > 1.0 { n - 1.0 } else { 1.0 };
            va /= denom;
            vb /= denom;
            cov /= denom;
            total += ((2.0 * ma * mb + c1) * (2.0 * cov + c2))
                / ((ma * ma + mb * mb + c1) * (va + vb + c2));
            windows += 1;
            x += 4.min(win);
        }
        y += 4.min(win);
    }
    if windows == 0 {
        1.0
    } else {
        total / f64::from(windows)
    }
}

/// Fraction of pixels whose hit flags differ, in `[0, 1]`.
///
/// # Panics
/// If the masks differ in length.
#[must_use]
pub fn mask_mismatch(a: &[bool], b: &[bool]) -> f64 {
    assert_eq!(a.len(), b.len(), "masks differ in length");
    if a.is_empty() {
        return 0.0;
    }
    let differ = a.iter().zip(b).filter(|(x, y)| x != y).count();
    #[allow(clippy::cast_precision_loss)]
    let fraction = differ as f64 / a.len() as f64;
    fraction
}

/// Mean absolute depth difference over pixels that both depth buffers hit
/// (finite depths), and the number of such pixels.
///
/// # Panics
/// If the buffers differ in length.
#[must_use]
pub fn mean_depth_error(a: &[f32], b: &[f32], hit_a: &[bool], hit_b: &[bool]) -> (f64, usize) {
    assert_eq!(a.len(), b.len(), "depth buffers differ in length");
    let mut sum = 0.0;
    let mut n = 0usize;
    for i in 0..a.len() {
        if hit_a[i] && hit_b[i] {
            sum += (f64::from(a[i]) - f64::from(b[i])).abs();
            n += 1;
        }
    }
    #[allow(clippy::cast_precision_loss)]
    let mean = if n == 0 { 0.0 } else { sum / n as f64 };
    (mean, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    fn noise(w: u32, h: u32, seed: u32) -> RgbaImage {
        let mut s = seed.wrapping_mul(2_654_435_761).max(1);
        RgbaImage::from_fn(w, h, |_, _| {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            let v = s.to_le_bytes();
            Rgba([v[0], v[1], v[2], 255])
        })
    }

    #[test]
    fn psnr_of_a_known_error() {
        let a = RgbaImage::from_pixel(10, 10, Rgba([100, 100, 100, 255]));
        let b = RgbaImage::from_pixel(10, 10, Rgba([110, 100, 100, 255]));
        // MSE = 100 / 3 over RGB.
        let expected = 10.0 * (255.0f64 * 255.0 / (100.0 / 3.0)).log10();
        assert!((psnr(&a, &b) - expected).abs() < 1e-9);
    }

    #[test]
    fn ssim_separates_structure_from_noise() {
        let a = noise(32, 32, 1);
        let b = noise(32, 32, 2);
        assert!((ssim(&a, &a) - 1.0).abs() < 1e-12);
        assert!(ssim(&a, &b) < 0.2, "{}", ssim(&a, &b));
    }

    #[test]
    fn mask_and_depth_comparisons() {
        assert!(
            (mask_mismatch(&[true, false, true, true], &[true, true, true, false]) - 0.5).abs()
                < 1e-12
        );
        let (e, n) = mean_depth_error(
            &[1.0, 2.0, 5.0],
            &[1.5, 2.0, 9.0],
            &[true, true, false],
            &[true, true, true],
        );
        assert_eq!(n, 2);
        assert!((e - 0.25).abs() < 1e-12);
    }
}
