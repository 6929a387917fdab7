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
use super::aov::Layers;

/// Two hits whose depths differ by less than this fraction of the nearer
/// show the same surface.
pub const SAME_SURFACE: f32 = 0.05;

/// Weights are fixed-point: `ONE` is a whole rendered pixel along an axis.
const ONE: u32 = 256;

/// Along one axis: for each image pixel, the two rendered pixels around
/// its centre and the weight of the second, out of [`ONE`]
/// (rendered-pixel centres are at integers; the image's edges clamp).
fn axis(size: u32, rendered: u32, scale: u32) -> Vec<(usize, usize, u32)> {
    let k = f64::from(scale);
    (0..size)
        .map(|i| {
            let u = (f64::from(i) + 0.5) / k - 0.5;
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let i0 = (u.floor().max(0.0) as u32).min(rendered - 1);
            let i1 = (i0 + 1).min(rendered - 1);
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let f = ((u - f64::from(i0)).clamp(0.0, 1.0) * f64::from(ONE)).round() as u32;
            (i0 as usize, i1 as usize, f)
        })
        .collect()
}

/// Calls `each(pixel, taps, weights, nearest)` for every image pixel, row
/// by row: the four rendered pixels around it, their weights (out of
/// `ONE²` in all) and which one is the nearest. A tap whose depth says it
/// shows another surface than the nearest gets no weight.
fn for_each_tap(
    (width, height): (u32, u32),
    scale: u32,
    (lw, lh): (u32, u32),
    depth: &[f32],
    mut each: impl FnMut(usize, [usize; 4], [u32; 4], usize),
) {
    let columns = axis(width, lw, scale);
    let rows = axis(height, lh, scale);
    let lw = lw as usize;
    let mut pixel = 0;
    for &(y0, y1, fy) in &rows {
        for &(x0, x1, fx) in &columns {
            let index = [y0 * lw + x0, y0 * lw + x1, y1 * lw + x0, y1 * lw + x1];
            let mut weight = [
                (ONE - fx) * (ONE - fy),
                fx * (ONE - fy),
                (ONE - fx) * fy,
                fx * fy,
            ];
            let mut nearest = 0;
            for i in 1..4 {
                if weight[i] > weight[nearest] {
                    nearest = i;
                }
            }
            let d0 = depth[index[nearest]];
            for i in 0..4 {
                let d = depth[index[i]];
                let same = if d0.is_finite() && d.is_finite() {
                    (d - d0).abs() <= SAME_SURFACE * d.min(d0)
                } else {
                    d0.is_finite() == d.is_finite()
                };
                if !same {
                    weight[i] = 0;
                }
            }
            each(pixel, index, weight, nearest);
            pixel += 1;
        }
    }
}

/// The colour of one image pixel from its taps, rounded to nearest.
fn blend(rgba: &[u8], index: [usize; 4], weight: [u32; 4], out: &mut [u8]) {
    let total: u32 = weight.iter().sum();
    let mut c = [total / 2; 4];
    for (i, w) in index.into_iter().zip(weight) {
        if w > 0 {
            let from = &rgba[4 * i..4 * i + 4];
            for j in 0..4 {
                c[j] += w * u32::from(from[j]);
            }
        }
    }
    for j in 0..4 {
        #[allow(clippy::cast_possible_truncation)]
        {
            out[j] = (c[j] / total) as u8;
        }
    }
}

/// Scales a `lw` × `lh` rendering up to `width` × `height` (`lw` is
/// `width / scale` rounded up, and likewise `lh`): colours blended where
/// the depths agree, the other outputs from the nearest rendered pixel,
/// and each rendered pixel's cost counted once, at the first image pixel
/// of its block.
pub(crate) fn frame(low: &Frame, width: u32, height: u32, scale: u32) -> Frame {
    let (lw, lh) = (low.width(), low.height());
    let n = (width as usize) * (height as usize);
    let mut rgba = vec![0u8; 4 * n];
    let mut out = Frame {
        image: RgbaImage::new(1, 1),
        depth: Vec::with_capacity(n),
        hit: Vec::with_capacity(n),
        normal: Vec::with_capacity(n),
        steps: vec![0; n],
        evaluations: vec![0; n],
        start: Vec::with_capacity(n),
        layers: low.layers.as_ref().map(|_| Layers {
            linear: Vec::with_capacity(n),
            position: Vec::with_capacity(n),
            albedo: Vec::with_capacity(n),
            occlusion: Vec::with_capacity(n),
            shadow: Vec::with_capacity(n),
            trap: Vec::with_capacity(n),
            object: Vec::with_capacity(n),
            material: Vec::with_capacity(n),
        }),
    };
    let from = low.image.as_raw();
    for_each_tap(
        (width, height),
        scale,
        (lw, lh),
        &low.depth,
        |p, index, weight, nearest| {
            blend(from, index, weight, &mut rgba[4 * p..4 * p + 4]);
            let i = index[nearest];
            out.depth.push(low.depth[i]);
            out.hit.push(low.hit[i]);
            out.normal.push(low.normal[i]);
            out.start.push(low.start[i]);
            if let (Some(to), Some(from)) = (&mut out.layers, &low.layers) {
                // Colours blend as the image's do; what the hit is made
                // of comes from the nearest ray, as its depth does.
                let total: u32 = weight.iter().sum();
                let mut linear = [0.0f32; 4];
                for (k, w) in index.into_iter().zip(weight).filter(|&(_, w)| w > 0) {
                    #[allow(clippy::cast_precision_loss)] // weights are small
                    let w = w as f32 / total as f32;
                    for (sum, v) in linear.iter_mut().zip(from.linear[k]) {
                        *sum += w * v;
                    }
                }
                to.linear.push(linear);
                to.position.push(from.position[i]);
                to.albedo.push(from.albedo[i]);
                to.occlusion.push(from.occlusion[i]);
                to.shadow.push(from.shadow[i]);
                to.trap.push(from.trap[i]);
                if !from.object.is_empty() {
                    to.object.push(from.object[i]);
                    to.material.push(from.material[i]);
                }
            }
        },
    );
    for y in 0..lh {
        for x in 0..lw {
            let from = (y * lw + x) as usize;
            let to = (y * scale * width + x * scale) as usize;
            out.steps[to] = low.steps[from];
            out.evaluations[to] = low.evaluations[from];
        }
    }
    out.image = RgbaImage::from_raw(width, height, rgba).expect("four bytes per pixel");
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
    let from = low.as_raw();
    let mut rgba = vec![0u8; 4 * width as usize * height as usize];
    for_each_tap(
        (width, height),
        scale,
        low.dimensions(),
        depth,
        |p, index, weight, _| {
            blend(from, index, weight, &mut rgba[4 * p..4 * p + 4]);
        },
    );
    RgbaImage::from_raw(width, height, rgba).expect("four bytes per pixel")
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
