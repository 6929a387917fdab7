//! Stereo pairs: two off-axis eyes
//! ([`Camera::eyes`](crate::scene::Camera::eyes)) rendered and laid out in
//! one picture.

use image::{Rgba, RgbaImage};

use super::dispatch::MAX_IMAGE_SIDE;
use super::frames::RenderFrames;
use super::renderer::Renderer;
use crate::error::{Error, Result};
use crate::scene::{Stereo, StereoLayout};

impl Renderer {
    /// Renders both eyes of `stereo` around the current camera, each
    /// `width` × `height`, and lays them out in one picture
    /// ([`StereoLayout::size`]). The camera is left as it was.
    ///
    /// # Errors
    /// As [`render_stereo`].
    pub fn render_stereo(&mut self, width: u32, height: u32, stereo: &Stereo) -> Result<RgbaImage> {
        render_stereo(self, width, height, stereo)
    }
}

/// Renders both eyes of `stereo` around `renderer`'s current camera, each
/// `width` × `height`, on either backend, and lays them out in one
/// picture ([`StereoLayout::size`]). The camera is left as it was.
///
/// # Errors
/// As [`Stereo::eyes`] and the renderer's `render` (each eye's size is
/// checked as a frame's); [`Error::Resolution`] where the laid-out
/// picture would pass the largest side.
pub fn render_stereo<R: RenderFrames>(
    renderer: &mut R,
    width: u32,
    height: u32,
    stereo: &Stereo,
) -> Result<RgbaImage> {
    let (w, h) = (u64::from(width), u64::from(height));
    let (pw, ph) = match stereo.layout {
        StereoLayout::Anaglyph => (w, h),
        StereoLayout::SideBySide => (2 * w, h),
        StereoLayout::OverUnder => (w, 2 * h),
    };
    if pw.max(ph) > u64::from(MAX_IMAGE_SIDE) {
        return Err(Error::Resolution {
            width,
            height,
            reason: format!(
                "the {} picture of two such eyes is {pw}x{ph}, and each side must be at most \
                 {MAX_IMAGE_SIDE} pixels",
                stereo.layout.name()
            ),
        });
    }
    let centre = *renderer.camera();
    let eyes = stereo.eyes(&centre)?;
    let mut images = Vec::with_capacity(2);
    for eye in eyes {
        let image = renderer
            .set_camera(eye)
            .and_then(|()| renderer.render(width, height));
        let failed = image.is_err();
        images.push(image);
        if failed {
            break;
        }
    }
    // The centre camera was valid, so it is taken back.
    renderer.set_camera(centre)?;
    let mut images = images.into_iter();
    let left = images.next().expect("one eye at least")?;
    let right = images.next().expect("two eyes when the first rendered")?;
    Ok(compose(&left, &right, stereo.layout))
}

/// Lays out two eyes' images of the same size.
///
/// # Panics
/// If the images differ in size.
#[must_use]
pub fn compose(left: &RgbaImage, right: &RgbaImage, layout: StereoLayout) -> RgbaImage {
    assert_eq!(left.dimensions(), right.dimensions(), "eyes of one size");
    let (width, height) = left.dimensions();
    let (w, h) = layout.size(width, height);
    match layout {
        StereoLayout::Anaglyph => RgbaImage::from_fn(w, h, |x, y| {
            let l = left.get_pixel(x, y).0;
            let r = right.get_pixel(x, y).0;
            let luma = 0.299 * f64::from(l[0]) + 0.587 * f64::from(l[1]) + 0.114 * f64::from(l[2]);
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let red = luma.round().clamp(0.0, 255.0) as u8;
            Rgba([red, r[1], r[2], 255])
        }),
        StereoLayout::SideBySide | StereoLayout::OverUnder => {
            let mut out = RgbaImage::new(w, h);
            let (dx, dy) = if layout == StereoLayout::SideBySide {
                (width, 0)
            } else {
                (0, height)
            };
            image::imageops::replace(&mut out, left, 0, 0);
            image::imageops::replace(&mut out, right, i64::from(dx), i64::from(dy));
            out
        }
    }
}
