//! What a frame sequence or a stereo pair asks of a renderer, on either
//! backend ([`RenderFrames`]).

use image::RgbaImage;

use super::{RenderOptions, Renderer};
use crate::error::Result;
use crate::scene::Camera;
use crate::view::FrameTiming;

/// The calls a [`Sequence`](crate::sequence::Sequence) or a stereo pair
/// ([`render_stereo`](super::render_stereo)) makes of a renderer: the
/// camera, the dynamic parameters, a frame, and the mean of progressive
/// passes over moments in time (motion blur). [`Renderer`] (OpenCL) and,
/// with the `wgpu` feature, [`WgpuRenderer`](super::WgpuRenderer) have
/// them, so one piece of code renders on either backend.
///
/// ```no_run
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::render::{RenderFrames, Renderer};
///
/// // Any renderer: a turntable of eight frames.
/// fn turntable(r: &mut impl RenderFrames) -> fractal_sdf::Result<Vec<fractal_sdf::image::RgbaImage>> {
///     let base = *r.camera();
///     (0..8)
///         .map(|i| {
///             let angle = f64::from(i) * std::f64::consts::TAU / 8.0;
///             let (s, c) = angle.sin_cos();
///             let p = base.position;
///             let mut camera = base;
///             camera.position = dvec3(c * p.x + s * p.z, p.y, -s * p.x + c * p.z);
///             r.set_camera(camera)?;
///             r.render(160, 120)
///         })
///         .collect()
/// }
/// let scene = Scene::new(mandelbulb(8.0))
///     .with_camera(Camera::look_at(dvec3(0.0, 0.5, 3.0), DVec3::ZERO));
/// let frames = turntable(&mut Renderer::new(&scene, Quality::preview())?)?;
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
pub trait RenderFrames {
    /// The quality and effects it renders with.
    fn options(&self) -> &RenderOptions;

    /// The camera of the next frames.
    fn camera(&self) -> &Camera;

    /// Sets the camera of the next frames (no rebuild).
    ///
    /// # Errors
    /// As the renderer's own `set_camera`.
    fn set_camera(&mut self, camera: Camera) -> Result<()>;

    /// Sets a dynamic parameter of the next frames (no rebuild).
    ///
    /// # Errors
    /// As the renderer's own `set_param`.
    fn set_param(&mut self, name: &str, value: f64) -> Result<()>;

    /// Renders a `width` × `height` frame.
    ///
    /// # Errors
    /// As the renderer's own `render`.
    fn render(&mut self, width: u32, height: u32) -> Result<RgbaImage>;

    /// The mean of one progressive pass at each of `moments`, `set` before
    /// each (motion blur: the camera and parameters at each moment).
    ///
    /// # Errors
    /// As the renderer's own `render_over_time`.
    fn render_over_time<T>(
        &mut self,
        width: u32,
        height: u32,
        moments: &[T],
        set: impl FnMut(&mut Self, &T) -> Result<()>,
    ) -> Result<RgbaImage>
    where
        Self: Sized;

    /// What the last frame cost, where the renderer measured it.
    fn last_timing(&self) -> Option<FrameTiming>;
}

impl RenderFrames for Renderer {
    fn options(&self) -> &RenderOptions {
        Renderer::options(self)
    }

    fn camera(&self) -> &Camera {
        Renderer::camera(self)
    }

    fn set_camera(&mut self, camera: Camera) -> Result<()> {
        Renderer::set_camera(self, camera)
    }

    fn set_param(&mut self, name: &str, value: f64) -> Result<()> {
        Renderer::set_param(self, name, value)
    }

    fn render(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        Renderer::render(self, width, height)
    }

    fn render_over_time<T>(
        &mut self,
        width: u32,
        height: u32,
        moments: &[T],
        set: impl FnMut(&mut Self, &T) -> Result<()>,
    ) -> Result<RgbaImage> {
        Renderer::render_over_time(self, width, height, moments, set)
    }

    fn last_timing(&self) -> Option<FrameTiming> {
        Renderer::last_timing(self)
    }
}

#[cfg(feature = "wgpu")]
impl RenderFrames for super::WgpuRenderer {
    fn options(&self) -> &RenderOptions {
        super::WgpuRenderer::options(self)
    }

    fn camera(&self) -> &Camera {
        super::WgpuRenderer::camera(self)
    }

    fn set_camera(&mut self, camera: Camera) -> Result<()> {
        super::WgpuRenderer::set_camera(self, camera)
    }

    fn set_param(&mut self, name: &str, value: f64) -> Result<()> {
        super::WgpuRenderer::set_param(self, name, value)
    }

    fn render(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        super::WgpuRenderer::render(self, width, height)
    }

    fn render_over_time<T>(
        &mut self,
        width: u32,
        height: u32,
        moments: &[T],
        set: impl FnMut(&mut Self, &T) -> Result<()>,
    ) -> Result<RgbaImage> {
        super::WgpuRenderer::render_over_time(self, width, height, moments, set)
    }

    fn last_timing(&self) -> Option<FrameTiming> {
        super::WgpuRenderer::last_timing(self).map(FrameTiming::wall)
    }
}
