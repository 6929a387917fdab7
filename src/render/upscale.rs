//! Scaling a frame rendered at a fraction of the image's resolution
//! ([`Quality::resolution_scale`](crate::quality::Quality::resolution_scale))
//! up to the image's size, guided by depth.
//!
//! Each image pixel blends the (up to) four rendered pixels around it with
//! bilinear weights, but only those that show the same surface as the
//! nearest of them: both missed, or both hit at depths within
//! [`SAME_SURFACE`] of each other (relative). Silhouettes stay as sharp
//! as the rendered pixels, rather than blending an object's colour into
//! the background behind it; smooth surfaces are interpolated.

use image::RgbaImage;

use super::Frame;

/// Two hits whose depths differ by less than this fraction of the nearer
/// show the same surface.
pub const SAME_SURFACE: f64 = 0.05;

/// Where an image pixel's colour comes from: up to four rendered pixels
/// and their weights (summing to 1), the nearest first.
fn taps(
    x: u32,
    y: u32,
    scale: u32,
    (lw, lh): (u32, u32),
    depth: &[f32],
) -> ([usize; 4], [f64; 4], usize) {
    let k = f64::from(scale);
    // The image pixel's centre in rendered-pixel coordinates (centres at
    // integers).
    let u = (f64::from(x) + 0.5) / k - 0.5;
    let v = (f64::from(y) + 0.5) / k - 0.5;
    let clampi = |c: f64, n: u32| {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let i = c.floor().max(0.0) as u32;
        i.min(n - 1)
    };
    let (x0, y0) = (clampi(u, lw), clampi(v, lh));
    let (x1, y1) = ((x0 + 1).min(lw - 1), (y0 + 1).min(lh - 1));
    let fx = (u - f64::from(x0)).clamp(0.0, 1.0);
    let fy = (v - f64::from(y0)).clamp(0.0, 1.0);
    let at = |x: u32, y: u32| (y * lw + x) as usize;
    let index = [at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1)];
    let mut weight = [
        (1.0 - fx) * (1.0 - fy),
        fx * (1.0 - fy),
        (1.0 - fx) * fy,
        fx * fy,
    ];
    let nearest = (0..4)
        .max_by(|&a, &b| weight[a].total_cmp(&weight[b]))
        .expect("four taps");
    let d0 = f64::from(depth[index[nearest]]);
    let same = |d: f64| {
        if d0.is_finite() && d.is_finite() {
            (d - d0).abs() <= SAME_SURFACE * d.min(d0)
        } else {
            d0.is_finite() == d.is_finite()
        }
    };
    let mut total = 0.0;
    for i in 0..4 {
        if !same(f64::from(depth[index[i]])) {
            weight[i] = 0.0;
        }
        total += weight[i];
    }
    for w in &mut weight {
        *w /= total;
    }
    (index, weight, nearest)
}

/// Scales a `lw` × `lh` rendering up to `width` × `height` (`lw` is
/// `width / scale` rounded up, and likewise `lh`): colours blended where
/// the depths agree, the other outputs from the nearest rendered pixel,
/// and each rendered pixel's cost counted once, at the first image pixel
/// of its block.
pub(crate) fn frame(low: &Frame, width: u32, height: u32, scale: u32) -> Frame {
    let (lw, lh) = (low.width(), low.height());
    let n = (width as usize) * (height as usize);
    let mut image = RgbaImage::new(width, height);
    let mut out = Frame {
        image: RgbaImage::new(1, 1),
        depth: Vec::with_capacity(n),
        hit: Vec::with_capacity(n),
        normal: Vec::with_capacity(n),
        steps: vec![0; n],
        evaluations: vec![0; n],
        start: Vec::with_capacity(n),
    };
    let rgba = low.image.as_raw();
    for y in 0..height {
        for x in 0..width {
            let (index, weight, nearest) = taps(x, y, scale, (lw, lh), &low.depth);
            let mut c = [0.0f64; 4];
            for (&i, &w) in index.iter().zip(&weight) {
                for (channel, value) in c.iter_mut().zip(&rgba[4 * i..4 * i + 4]) {
                    *channel += w * f64::from(*value);
                }
            }
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            image.put_pixel(
                x,
                y,
                image::Rgba(c.map(|v| v.round().clamp(0.0, 255.0) as u8)),
            );
            let i = index[nearest];
            out.depth.push(low.depth[i]);
            out.hit.push(low.hit[i]);
            out.normal.push(low.normal[i]);
            out.start.push(low.start[i]);
        }
    }
    for y in 0..lh {
        for x in 0..lw {
            let from = (y * lw + x) as usize;
            let to = (y * scale * width + x * scale) as usize;
            out.steps[to] = low.steps[from];
            out.evaluations[to] = low.evaluations[from];
        }
    }
    out.image = image;
    out
}

/// Scales a rendered image up, as [`frame`] does its colours.
pub(crate) fn image(
    low: &RgbaImage,
    depth: &[f32],
    width: u32,
    height: u32,
    scale: u32,
) -> RgbaImage {
    let (lw, lh) = low.dimensions();
    let rgba = low.as_raw();
    RgbaImage::from_fn(width, height, |x, y| {
        let (index, weight, _) = taps(x, y, scale, (lw, lh), depth);
        let mut c = [0.0f64; 4];
        for (&i, &w) in index.iter().zip(&weight) {
            for (channel, value) in c.iter_mut().zip(&rgba[4 * i..4 * i + 4]) {
                *channel += w * f64::from(*value);
            }
        }
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        image::Rgba(c.map(|v| v.round().clamp(0.0, 255.0) as u8))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rendered 2 × 1 image: a hit on the left, a miss on the right.
    fn edge() -> (RgbaImage, Vec<f32>) {
        let mut low = RgbaImage::new(2, 1);
        low.put_pixel(0, 0, image::Rgba([200, 100, 0, 255]));
        low.put_pixel(1, 0, image::Rgba([0, 0, 100, 255]));
        (low, vec![1.0, f32::INFINITY])
    }

    #[test]
    fn silhouettes_stay_sharp() {
        let (low, depth) = edge();
        let up = image(&low, &depth, 4, 2, 2);
        for y in 0..2 {
            assert_eq!(up.get_pixel(0, y), low.get_pixel(0, 0));
            assert_eq!(up.get_pixel(1, y), low.get_pixel(0, 0));
            assert_eq!(up.get_pixel(2, y), low.get_pixel(1, 0));
            assert_eq!(up.get_pixel(3, y), low.get_pixel(1, 0));
        }
    }

    #[test]
    fn one_surface_is_interpolated() {
        let (low, _) = edge();
        let up = image(&low, &[1.0, 1.01], 4, 2, 2);
        // Pixel 1's centre is a quarter of the way to the second sample.
        assert_eq!(up.get_pixel(1, 0).0, [150, 75, 25, 255]);
        assert_eq!(up.get_pixel(0, 0), low.get_pixel(0, 0));
    }

    #[test]
    fn a_scale_of_one_copies() {
        let (low, depth) = edge();
        assert_eq!(image(&low, &depth, 2, 1, 1), low);
    }
}
