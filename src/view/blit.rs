//! [`blit_scaled`]: an image into a window's pixel buffer.

use image::RgbaImage;

/// Writes `image` into `pixels`, a `width` × `height` window buffer of
/// `0x00RRGGBB` words (as `softbuffer` and most window systems take them),
/// scaled to fill it by nearest-neighbour sampling — so an image rendered
/// at a reduced size fills the window.
///
/// ```
/// use fractal_sdf::image::{Rgba, RgbaImage};
/// let image = RgbaImage::from_fn(2, 1, |x, _| Rgba([if x == 0 { 255 } else { 0 }, 0, 9, 255]));
/// let mut pixels = vec![0; 4 * 2];
/// fractal_sdf::view::blit_scaled(&image, 4, 2, &mut pixels);
/// assert_eq!(pixels, [0xff0009, 0xff0009, 0x000009, 0x000009,
///                     0xff0009, 0xff0009, 0x000009, 0x000009]);
/// ```
///
/// # Panics
/// If `pixels` holds fewer than `width × height` words.
pub fn blit_scaled(image: &RgbaImage, width: u32, height: u32, pixels: &mut [u32]) {
    let (w, h) = (width as usize, height as usize);
    assert!(pixels.len() >= w * h, "the pixel buffer is too small");
    let (iw, ih) = (image.width() as usize, image.height() as usize);
    if iw == 0 || ih == 0 {
        pixels[..w * h].fill(0);
        return;
    }
    let raw = image.as_raw();
    for (y, row) in pixels.chunks_exact_mut(w.max(1)).take(h).enumerate() {
        let sy = (y * ih / h).min(ih - 1);
        for (x, out) in row.iter_mut().enumerate() {
            let sx = (x * iw / w).min(iw - 1);
            let p = &raw[(sy * iw + sx) * 4..][..3];
            *out = (u32::from(p[0]) << 16) | (u32::from(p[1]) << 8) | u32::from(p[2]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    #[test]
    fn blit_fills_the_window_from_any_size() {
        let image = RgbaImage::from_fn(3, 2, |x, y| Rgba([x as u8, y as u8, 200, 255]));
        // Same size: a plain copy.
        let mut same = vec![0; 6];
        blit_scaled(&image, 3, 2, &mut same);
        assert_eq!(
            same,
            [0x0000c8, 0x0100c8, 0x0200c8, 0x0001c8, 0x0101c8, 0x0201c8]
        );
        // Upscaled 2x: each pixel becomes a 2x2 block.
        let mut big = vec![0; 6 * 4];
        blit_scaled(&image, 6, 4, &mut big);
        assert_eq!(big[0], big[1]);
        assert_eq!(big[6 + 1], same[0]);
        assert_eq!(big[3 * 6 + 5], same[5]);
        // Downscaled and odd sizes stay in bounds; extra words are untouched.
        let mut small = vec![7; 3];
        blit_scaled(&image, 2, 1, &mut small);
        assert_eq!(small, [same[0], same[1], 7]);
        let mut empty_src = vec![9; 4];
        blit_scaled(&RgbaImage::new(0, 0), 2, 2, &mut empty_src);
        assert_eq!(empty_src, [0; 4]);
    }
}
