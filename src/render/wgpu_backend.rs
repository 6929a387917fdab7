//! The wgpu backend (feature `wgpu`): the scene's WGSL module
//! ([`codegen::emit_wgsl`]) run as a compute shader through wgpu, into an
//! image or into a texture the application owns. The crate builds wgpu
//! with its Vulkan backend (Mesa's lavapipe where there is no GPU); the
//! module itself is plain WGSL, for any WebGPU device.
//!
//! [`WgpuRenderer`] draws what [`Renderer`](super::Renderer) draws, from
//! the same formulas, constants and buffer layouts
//! (`kernels/wgsl/render.wgsl` is the OpenCL kernel's march and shading,
//! line for line): the march with glow and glow nodes, tetrahedral
//! normals, ambient occlusion, hard and soft shadows, every light kind,
//! fog (uniform, or lit with its light shafts), materials (shading
//! models, emission, subsurface light, reflections and transparency), an
//! environment image's light and sky, path-traced global illumination
//! (`kernels/wgsl/paths.wgsl`), supersampling, depth of field and the
//! resolution scale. What it does not draw yet it refuses with
//! [`Error::Unsupported`] rather than draw something else: double
//! precision and custom shapes written in OpenCL C (inside shapes of the
//! user's among them; the built-in escape-time sets are drawn, by brute
//! force, `kernels/wgsl/brute.wgsl`). The coarse pass
//! ([`Quality::cone_tile`], `kernels/wgsl/cone.wgsl`) starts each tile's
//! rays where its cone stopped, as on OpenCL; relaxed math
//! ([`Quality::fast_math`]) is left to the driver.
//!
//! ```no_run
//! use fractal_sdf::prelude::*;
//! use fractal_sdf::render::WgpuRenderer;
//!
//! let scene = Scene::new(mandelbulb(8.0))
//!     .with_camera(Camera::look_at(dvec3(0.0, 0.5, 3.0), DVec3::ZERO));
//! let mut renderer = WgpuRenderer::new(&scene, Quality::preview())?;
//! println!("on {}", renderer.adapter().name);
//! renderer.render(320, 240)?.save("bulb.png")?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::sync::{Mutex, OnceLock, PoisonError};
use std::time::{Duration, Instant};

use image::RgbaImage;

use super::RenderOptions;
use super::aov::Frame;
use super::dispatch::MAX_IMAGE_SIDE;
use super::upscale;
use super::viewport::{Viewport, check_frame_inputs, pack_lights};
use crate::codegen::interface::{camera, light};
use crate::codegen::{self, KernelSource, Target};
use crate::error::{Error, Result};
use crate::ir::{CompiledScene, ParamValues};
use crate::quality::{Effects, Precision, Quality};
use crate::scene::{Camera, Light, Scene};

/// The side of the render kernel's workgroups (`@workgroup_size(8, 8)`).
const WORKGROUP: u32 = 8;

/// The bindings of the render kernel's group 0 after the parameters
/// ([`codegen::WGSL_PARAMS`]): `kernels/wgsl/render.wgsl`.
const CAMERA: u32 = 1;
const LIGHTS: u32 = 2;
const FRAME: u32 = 3;
const IMAGE: u32 = 4;
const AOVS: u32 = 5;
const ENVIRONMENT: u32 = 6;
const ACCUMULATION: u32 = 7;
/// The depths and evaluations of each sample the brute-force pass marched.
const BRUTE_DEPTHS: u32 = 8;
/// The distance each tile's rays start at, from the coarse pass.
const CONE_STARTS: u32 = 9;

/// The format of the texture the render kernel writes: a texture given to
/// [`WgpuRenderer::render_to_texture`] must have it, and
/// `TextureUsages::STORAGE_BINDING`.
pub const WGPU_TEXTURE_FORMAT: ::wgpu::TextureFormat = ::wgpu::TextureFormat::Rgba8Unorm;

/// A frame from [`WgpuRenderer::render_frame`]: the image and, for the ray
/// through each pixel's centre, whether it hit, how far along it and what
/// the pixel cost (row-major, at the rendered resolution's pixels scaled
/// up to the image's).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct WgpuFrame {
    /// The image.
    pub image: RgbaImage,
    /// Distance along the centre ray to the surface, `f32::INFINITY` on a
    /// miss.
    pub depth: Vec<f32>,
    /// Whether the centre ray hit the surface.
    pub hit: Vec<bool>,
    /// Distance evaluations of the pixel's colour: the primary march's,
    /// the normal's, the shading's, occlusion's and the shadow rays'.
    pub evaluations: Vec<u32>,
    /// Distance evaluations of the primary march alone.
    pub steps: Vec<u32>,
}

impl WgpuFrame {
    /// Mean distance evaluations per pixel.
    #[must_use]
    pub fn evaluations_per_pixel(&self) -> f64 {
        let total: u64 = self.evaluations.iter().map(|&e| u64::from(e)).sum();
        total as f64 / self.evaluations.len().max(1) as f64
    }
}

/// A progressive image: its size, the passes it holds and the image.
struct Progress {
    size: (u32, u32),
    passes: u32,
    image: RgbaImage,
}

/// A wgpu device and its queue, and what the adapter says of itself.
struct Gpu {
    device: ::wgpu::Device,
    queue: ::wgpu::Queue,
    adapter: ::wgpu::AdapterInfo,
}

/// A renderer on the wgpu backend: [`Renderer`](super::Renderer)'s calls
/// for a frame (parameters, camera, lights, quality, effects,
/// [`render`](Self::render)), on a wgpu device, drawing the OpenCL
/// backend's picture from the scene compiled to WGSL. Changing a dynamic
/// parameter, the camera or the lights writes a buffer: the pipeline is
/// built once. What it draws and what it refuses, and how it compares:
/// the [backends chapter](crate::guide::backends).
///
/// ```no_run
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::render::WgpuRenderer;
///
/// let scene = Scene::new(mandelbulb(8.0))
///     .with_camera(Camera::look_at(dvec3(0.0, 0.5, 3.0), DVec3::ZERO));
/// let mut renderer = WgpuRenderer::new(&scene, Quality::preview())?;
/// renderer.render(320, 240)?.save("bulb.png")?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct WgpuRenderer {
    scene: CompiledScene,
    options: RenderOptions,
    values: ParamValues,
    source: KernelSource,
    gpu: Gpu,
    pipeline: Pipeline,
    pipeline_time: Duration,
    builds: u64,
    params: ::wgpu::Buffer,
    /// The dynamic values the parameter buffer holds; `None` where it
    /// must be written whole before the next frame.
    written: Option<Vec<f64>>,
    camera: ::wgpu::Buffer,
    lights: ::wgpu::Buffer,
    /// The environment light ([`super::environment::pack`]).
    environment: ::wgpu::Buffer,
    frame: ::wgpu::Buffer,
    /// The image the last frame rendered into.
    texture: Option<::wgpu::Texture>,
    /// The per-pixel values of the last frame that asked for them.
    outputs: Option<::wgpu::Buffer>,
    /// One pixel's per-pixel values: bound where a frame asks for none.
    no_outputs: ::wgpu::Buffer,
    /// The progressive passes' sums, per rendered pixel.
    sums: Option<::wgpu::Buffer>,
    /// One pixel's sums: bound for a frame of its own.
    no_accumulation: ::wgpu::Buffer,
    /// The brute-force pass's depths, per sample of a pass, where the
    /// scene has inside shapes; one sample's stand-in otherwise.
    brute_depths: ::wgpu::Buffer,
    /// The coarse pass's starting distances, per tile, where the program
    /// has the pass; one tile's stand-in otherwise.
    cone_starts: ::wgpu::Buffer,
    /// The progressive image so far.
    progress: Option<Progress>,
    timing: Option<Duration>,
}

impl std::fmt::Debug for WgpuRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WgpuRenderer")
            .field("adapter", &self.gpu.adapter.name)
            .field("backend", &self.gpu.adapter.backend)
            .field("options", &self.options)
            .finish_non_exhaustive()
    }
}

/// The adapters wgpu finds on this machine, on every backend it was built
/// with (the crate builds it with Vulkan).
#[must_use]
pub fn wgpu_adapters() -> Vec<::wgpu::AdapterInfo> {
    let instance = instance();
    pollster::block_on(instance.enumerate_adapters(::wgpu::Backends::all()))
        .into_iter()
        .map(|a| a.get_info())
        .collect()
}

fn instance() -> ::wgpu::Instance {
    ::wgpu::Instance::new(::wgpu::InstanceDescriptor::new_without_display_handle_from_env())
}

pub(super) fn wgpu_error(what: &str, detail: impl std::fmt::Display) -> Error {
    Error::Wgpu(format!("{what}: {detail}"))
}

/// Runs `f` and turns the validation, out-of-memory and internal errors
/// wgpu reports while it runs into [`Error::Wgpu`] (rather than wgpu's
/// default, a panic).
pub(super) fn checked<T>(device: &::wgpu::Device, what: &str, f: impl FnOnce() -> T) -> Result<T> {
    let internal = device.push_error_scope(::wgpu::ErrorFilter::Internal);
    let memory = device.push_error_scope(::wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(::wgpu::ErrorFilter::Validation);
    let value = f();
    let invalid = pollster::block_on(validation.pop());
    let short = pollster::block_on(memory.pop());
    let failed = pollster::block_on(internal.pop());
    match invalid.or(short).or(failed) {
        Some(e) => Err(wgpu_error(what, e)),
        None => Ok(value),
    }
}

impl WgpuRenderer {
    /// A renderer for `scene` with `quality` and the default effects, on
    /// the adapter wgpu chooses.
    ///
    /// # Errors
    /// As [`WgpuRenderer::from_compiled`].
    pub fn new(scene: &Scene, quality: Quality) -> Result<Self> {
        let options = RenderOptions {
            quality,
            ..RenderOptions::default()
        };
        Self::from_compiled(scene.compile()?, &options)
    }

    /// A renderer for a compiled scene on the adapter wgpu chooses (its
    /// default request: `WGPU_BACKEND` and `WGPU_ADAPTER_NAME` steer it),
    /// whose device every renderer made this way shares: the first finds
    /// it, and a scene built before (by any of them, with the same
    /// quality and effects) takes its pipeline from the cache of the
    /// last 64.
    /// [`RenderOptions::device`], `tile_size`, `deadline` and `cancel`
    /// are the OpenCL backend's and are not used: a frame is one dispatch,
    /// which runs to its end.
    ///
    /// # Errors
    /// [`Error::Unsupported`] for what the backend does not draw (see the
    /// [backends chapter](crate::guide::backends)), double precision among it; [`Error::Wgpu`] where
    /// wgpu finds no adapter or the driver rejects the shader; quality,
    /// effects and input errors as [`Renderer::from_compiled`](super::Renderer::from_compiled).
    pub fn from_compiled(scene: CompiledScene, options: &RenderOptions) -> Result<Self> {
        let (device, queue) = shared_device()?;
        Self::with_device(scene, options, device, queue)
    }

    /// A renderer on the application's own device and queue: for
    /// [`render_to_texture`](Self::render_to_texture) into the
    /// application's textures.
    ///
    /// # Errors
    /// As [`WgpuRenderer::from_compiled`].
    pub fn with_device(
        scene: CompiledScene,
        options: &RenderOptions,
        device: ::wgpu::Device,
        queue: ::wgpu::Queue,
    ) -> Result<Self> {
        let source = module(&scene, options)?;
        let values = scene.default_values();
        let limits = Precision::F32.limits();
        values.check_within(limits)?;
        let view = Viewport::in_frame(scene.camera(), 1, 1, Precision::F32, source.origin)?;
        check_frame_inputs(&view, scene.lights(), source.origin, limits)?;
        let adapter = device.adapter_info();
        let started = Instant::now();
        let (pipeline, built) = pipeline(&device, &source)?;
        let pipeline_time = started.elapsed();
        let storage = ::wgpu::BufferUsages::STORAGE | ::wgpu::BufferUsages::COPY_DST;
        let params = buffer(
            &device,
            "parameters",
            4 * source.param_buffer(values.as_slice()).len().max(1),
            storage,
        );
        let camera = buffer(&device, "camera", 4 * camera::LEN, storage);
        let lights = buffer(
            &device,
            "lights",
            4 * light_reals(scene.lights().len()),
            storage,
        );
        let no_outputs = buffer(&device, "no pixels", 16, output_usage());
        let no_accumulation = buffer(&device, "no sums", 16, ::wgpu::BufferUsages::STORAGE);
        let brute_depths = buffer(&device, "no depths", 8, ::wgpu::BufferUsages::STORAGE);
        let cone_starts = buffer(&device, "no starts", 4, ::wgpu::BufferUsages::STORAGE);
        let packed = super::environment::pack(scene.environment());
        let environment = buffer(&device, "environment", 4 * packed.len(), storage);
        let bytes: Vec<u8> = packed.iter().flat_map(|v| v.to_le_bytes()).collect();
        queue.write_buffer(&environment, 0, &bytes);
        let frame = buffer(
            &device,
            "frame",
            32,
            ::wgpu::BufferUsages::UNIFORM | ::wgpu::BufferUsages::COPY_DST,
        );
        let mut renderer = WgpuRenderer {
            scene,
            options: options.clone(),
            values,
            written: None,
            source,
            gpu: Gpu {
                device,
                queue,
                adapter,
            },
            pipeline,
            pipeline_time,
            builds: u64::from(built),
            params,
            camera,
            lights,
            environment,
            frame,
            texture: None,
            outputs: None,
            no_outputs,
            sums: None,
            no_accumulation,
            brute_depths,
            cone_starts,
            progress: None,
            timing: None,
        };
        renderer.write_lights();
        Ok(renderer)
    }

    /// The adapter the renderer runs on.
    #[must_use]
    pub fn adapter(&self) -> &::wgpu::AdapterInfo {
        &self.gpu.adapter
    }

    /// The device the renderer runs on: textures for
    /// [`render_to_texture`](Self::render_to_texture) come from it.
    #[must_use]
    pub fn device(&self) -> &::wgpu::Device {
        &self.gpu.device
    }

    /// The queue the renderer submits its frames to.
    #[must_use]
    pub fn queue(&self) -> &::wgpu::Queue {
        &self.gpu.queue
    }

    /// The WGSL module the renderer runs.
    #[must_use]
    pub fn source(&self) -> &KernelSource {
        &self.source
    }

    /// How long getting the current render pipeline took: the driver's
    /// build, or the cache's lookup.
    #[must_use]
    pub fn pipeline_time(&self) -> Duration {
        self.pipeline_time
    }

    /// Pipelines this renderer has had the driver build (those found in
    /// the cache do not count). Frames, parameter, camera and light
    /// changes never add to it.
    #[must_use]
    pub fn builds(&self) -> u64 {
        self.builds
    }

    /// The options the renderer renders with.
    #[must_use]
    pub fn options(&self) -> &RenderOptions {
        &self.options
    }

    /// Sets the quality: a new module and pipeline (from the cache where
    /// one was built for it), keeping the parameters, camera and lights.
    ///
    /// # Errors
    /// As [`WgpuRenderer::from_compiled`]; the renderer is unchanged.
    pub fn set_quality(&mut self, quality: Quality) -> Result<()> {
        let mut options = self.options.clone();
        options.quality = quality;
        self.set_options(options)
    }

    /// Sets the effects, as [`WgpuRenderer::set_quality`] the quality.
    ///
    /// # Errors
    /// As [`WgpuRenderer::set_quality`].
    pub fn set_effects(&mut self, effects: Effects) -> Result<()> {
        let mut options = self.options.clone();
        options.effects = effects;
        self.set_options(options)
    }

    fn set_options(&mut self, options: RenderOptions) -> Result<()> {
        let source = module(&self.scene, &options)?;
        let started = Instant::now();
        let (pipeline, built) = pipeline(&self.gpu.device, &source)?;
        self.pipeline_time = started.elapsed();
        self.builds += u64::from(built);
        self.pipeline = pipeline;
        self.source = source;
        self.options = options;
        self.progress = None;
        let size = 4 * self
            .source
            .param_buffer(self.values.as_slice())
            .len()
            .max(1);
        if self.params.size() as usize != size {
            self.params = buffer(
                &self.gpu.device,
                "parameters",
                size,
                ::wgpu::BufferUsages::STORAGE | ::wgpu::BufferUsages::COPY_DST,
            );
        }
        self.written = None;
        Ok(())
    }

    /// How long the last frame took on the device, from submission to the
    /// end of its work (with the copies into the buffers it is read back
    /// from, not the reading).
    #[must_use]
    pub fn last_timing(&self) -> Option<Duration> {
        self.timing
    }

    /// The compiled scene.
    #[must_use]
    pub fn scene(&self) -> &CompiledScene {
        &self.scene
    }

    /// Sets a dynamic parameter: a buffer write, never a new pipeline.
    ///
    /// # Errors
    /// As [`Renderer::set_param`](super::Renderer::set_param), in single
    /// precision.
    pub fn set_param(&mut self, name: &str, value: f64) -> Result<()> {
        self.values
            .set_within(name, value, Precision::F32.limits())?;
        self.progress = None;
        Ok(())
    }

    /// The current value of a dynamic parameter.
    #[must_use]
    pub fn param(&self, name: &str) -> Option<f64> {
        self.values.get(name)
    }

    /// Every dynamic parameter's current value.
    #[must_use]
    pub fn values(&self) -> &ParamValues {
        &self.values
    }

    /// Sets the camera.
    ///
    /// # Errors
    /// As [`Renderer::set_camera`](super::Renderer::set_camera).
    pub fn set_camera(&mut self, camera: Camera) -> Result<()> {
        let view = Viewport::in_frame(&camera, 1, 1, Precision::F32, self.source.origin)?;
        check_frame_inputs(&view, &[], self.source.origin, Precision::F32.limits())?;
        self.progress = None;
        self.scene.set_camera(camera)
    }

    /// The camera.
    #[must_use]
    pub fn camera(&self) -> &Camera {
        self.scene.camera()
    }

    /// Replaces the lights.
    ///
    /// # Errors
    /// As [`Renderer::set_lights`](super::Renderer::set_lights).
    pub fn set_lights(&mut self, lights: impl IntoIterator<Item = Light>) -> Result<()> {
        let lights: Vec<Light> = lights.into_iter().collect();
        let mut scene = self.scene.clone();
        scene.set_lights(lights)?;
        let view = Viewport::in_frame(scene.camera(), 1, 1, Precision::F32, self.source.origin)?;
        check_frame_inputs(
            &view,
            scene.lights(),
            self.source.origin,
            Precision::F32.limits(),
        )?;
        self.scene = scene;
        self.write_lights();
        self.progress = None;
        Ok(())
    }

    /// Renders a `width` × `height` image.
    ///
    /// # Errors
    /// [`Error::Resolution`] for a zero side or one above
    /// [`MAX_IMAGE_SIDE`]; [`Error::Precision`] for a camera the single
    /// precision cannot compute with at this size; [`Error::Wgpu`] if the
    /// device fails.
    pub fn render(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        // The depths scale the image up; at full resolution only the image
        // is needed.
        let scaled = self.options.quality.resolution_scale > 1;
        self.progress = None;
        Ok(self.draw(width, height, scaled, None)?.image)
    }

    /// Renders one more progressive pass of a `width` × `height` image and
    /// returns the mean of every pass so far, as
    /// [`Renderer::render_progressive`](super::Renderer::render_progressive)
    /// does: each pass takes [`Quality::supersampling`]² new samples a
    /// pixel, at new points in the pixel and on the lens, summed on the
    /// device. Changing the parameters, camera, lights, quality, effects
    /// or size, or a frame of its own, starts again from the first pass.
    /// Past [`Renderer::MAX_PROGRESSIVE_SAMPLES`](super::Renderer::MAX_PROGRESSIVE_SAMPLES)
    /// samples a pixel the image has converged, and a further call returns
    /// it again.
    ///
    /// # Errors
    /// As [`WgpuRenderer::render`].
    pub fn render_progressive(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        let per_pass = self.options.quality.supersampling.max(1).pow(2);
        let pass = match &self.progress {
            Some(p) if p.size == (width, height) => p.passes,
            _ => 0,
        };
        let limit = super::Renderer::MAX_PROGRESSIVE_SAMPLES;
        if let Some(p) = self
            .progress
            .as_ref()
            .filter(|_| (pass + 1) * per_pass > limit)
        {
            // Converged: no more passes.
            return Ok(p.image.clone());
        }
        let scaled = self.options.quality.resolution_scale > 1;
        self.progress = None;
        let image = self.draw(width, height, scaled, Some(pass))?.image;
        self.progress = Some(Progress {
            size: (width, height),
            passes: pass + 1,
            image: image.clone(),
        });
        Ok(image)
    }

    /// One progressive pass at each of `moments`, `set` before each (the
    /// camera, parameters or lights at that moment): the mean of them all,
    /// motion blur as [`Renderer::render_over_time`](super::Renderer::render_over_time)
    /// draws it. The progressive image starts again afterwards.
    ///
    /// # Errors
    /// [`Error::Quality`] for no moments or more than progressive
    /// rendering holds at the quality's supersampling; the first error of
    /// `set` or of a pass; otherwise as [`WgpuRenderer::render`].
    pub fn render_over_time<T>(
        &mut self,
        width: u32,
        height: u32,
        moments: &[T],
        mut set: impl FnMut(&mut Self, &T) -> Result<()>,
    ) -> Result<RgbaImage> {
        let per_pass = self.options.quality.supersampling.max(1).pow(2);
        let most = (super::Renderer::MAX_PROGRESSIVE_SAMPLES / per_pass).max(1);
        let count = u32::try_from(moments.len()).unwrap_or(u32::MAX);
        if count == 0 || count > most {
            return Err(Error::Quality {
                setting: "moments",
                value: f64::from(count),
                expected: format!("1 to {most} for the quality's samples"),
            });
        }
        let scaled = self.options.quality.resolution_scale > 1;
        let mut last = None;
        for (pass, moment) in (0u32..).zip(moments) {
            let drawn =
                set(self, moment).and_then(|()| self.draw(width, height, scaled, Some(pass)));
            // Each pass goes on from the sums of the last, whatever `set`
            // changed; no progressive image continues from them.
            self.progress = None;
            last = Some(drawn?.image);
        }
        Ok(last.expect("at least one moment"))
    }

    /// The progressive passes the current image holds (0 before the
    /// first).
    #[must_use]
    pub fn progressive_passes(&self) -> u32 {
        self.progress.as_ref().map_or(0, |p| p.passes)
    }

    /// Renders a `width` × `height` image with each pixel's depth, hit and
    /// cost (scaled up as the OpenCL backend scales its per-pixel outputs:
    /// depth and hit from the nearest rendered pixel, each rendered
    /// pixel's cost at the first image pixel of its block).
    ///
    /// # Errors
    /// As [`WgpuRenderer::render`].
    pub fn render_frame(&mut self, width: u32, height: u32) -> Result<WgpuFrame> {
        self.progress = None;
        self.draw(width, height, true, None)
    }

    /// Renders and reads back the image, and with `outputs` the per-pixel
    /// values (empty without); progressive pass `pass`, or a frame of its
    /// own.
    fn draw(
        &mut self,
        width: u32,
        height: u32,
        outputs: bool,
        pass: Option<u32>,
    ) -> Result<WgpuFrame> {
        check_size(width, height)?;
        let scale = self.options.quality.resolution_scale.max(1);
        let (w, h) = (width.div_ceil(scale), height.div_ceil(scale));
        self.check_fits(w, h, outputs || pass.is_some())?;
        self.write_frame((width, height), scale, outputs, pass)?;
        let (pw, ph) = if outputs { (w, h) } else { (1, 1) };
        let (texture, aovs) = self.targets((w, h), (pw, ph))?;
        let accumulation = match pass {
            Some(_) => self.accumulation(w, h)?,
            None => self.no_accumulation.clone(),
        };
        let view = texture.create_view(&::wgpu::TextureViewDescriptor::default());
        let image_bytes = padded_row(w) as usize * h as usize;
        let image_staging = buffer(&self.gpu.device, "image readback", image_bytes, read_back());
        let aov_bytes = aovs.size() as usize;
        let aov_staging = buffer(&self.gpu.device, "pixel readback", aov_bytes, read_back());
        self.dispatch(&view, (&aovs, &accumulation), w, h, |encoder| {
            encoder.copy_texture_to_buffer(
                texture.as_image_copy(),
                ::wgpu::TexelCopyBufferInfo {
                    buffer: &image_staging,
                    layout: ::wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(padded_row(w)),
                        rows_per_image: Some(h),
                    },
                },
                texture.size(),
            );
            if outputs {
                encoder.copy_buffer_to_buffer(&aovs, 0, &aov_staging, 0, aov_bytes as u64);
            }
        })?;
        let rows = read(&self.gpu.device, &image_staging)?;
        let mut rgba = Vec::with_capacity(4 * w as usize * h as usize);
        for row in rows.chunks_exact(padded_row(w) as usize) {
            rgba.extend_from_slice(&row[..4 * w as usize]);
        }
        let image = RgbaImage::from_raw(w, h, rgba).expect("four bytes per pixel");
        if !outputs {
            return Ok(WgpuFrame {
                image,
                depth: Vec::new(),
                hit: Vec::new(),
                evaluations: Vec::new(),
                steps: Vec::new(),
            });
        }
        let pixels: Vec<[f32; 4]> = read(&self.gpu.device, &aov_staging)?
            .chunks_exact(16)
            .map(|b| {
                let f = |i: usize| f32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
                [f(0), f(4), f(8), f(12)]
            })
            .collect();
        let n = pixels.len();
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // counts below 2^24
        let low = Frame {
            image,
            depth: pixels
                .iter()
                .map(|p| if p[1] > 0.5 { p[0] } else { f32::INFINITY })
                .collect(),
            hit: pixels.iter().map(|p| p[1] > 0.5).collect(),
            normal: vec![[0.0; 3]; n],
            steps: pixels.iter().map(|p| p[3] as u32).collect(),
            evaluations: pixels.iter().map(|p| p[2] as u32).collect(),
            start: vec![0.0; n],
            layers: None,
        };
        let frame = if scale > 1 {
            upscale::frame(&low, width, height, scale)
        } else {
            low
        };
        Ok(WgpuFrame {
            image: frame.image,
            depth: frame.depth,
            hit: frame.hit,
            evaluations: frame.evaluations,
            steps: frame.steps,
        })
    }

    /// Whether the device holds a `width` × `height` rendering (with the
    /// per-pixel values where `outputs`): [`Error::Resolution`] with the
    /// device's limit where it does not.
    fn check_fits(&self, width: u32, height: u32, outputs: bool) -> Result<()> {
        let limits = self.gpu.device.limits();
        let side = limits.max_texture_dimension_2d;
        if width > side || height > side {
            return Err(Error::Resolution {
                width,
                height,
                reason: format!(
                    "the wgpu device renders images up to {side} pixels a side (render at most \
                     that, or use the OpenCL backend)"
                ),
            });
        }
        let bytes = 16 * u64::from(width) * u64::from(height);
        let most = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        if outputs && bytes > most {
            return Err(Error::Resolution {
                width,
                height,
                reason: format!(
                    "the per-pixel values take {bytes} bytes, more than the {most} the wgpu \
                     device binds at once (render the image alone, or a smaller one)"
                ),
            });
        }
        Ok(())
    }

    /// Renders a frame the size of `view` into it, on the renderer's
    /// device (see [`WgpuRenderer::with_device`]), without a copy through
    /// the CPU: the texture must be [`WGPU_TEXTURE_FORMAT`] with
    /// `TextureUsages::STORAGE_BINDING`. The resolution scale is not
    /// applied (every pixel of the texture is rendered).
    ///
    /// # Errors
    /// As [`WgpuRenderer::render`]; [`Error::Wgpu`] for a texture of
    /// another format, usage or device.
    pub fn render_to_texture(
        &mut self,
        view: &::wgpu::TextureView,
        width: u32,
        height: u32,
    ) -> Result<()> {
        check_size(width, height)?;
        self.check_fits(width, height, false)?;
        self.write_frame((width, height), 1, false, None)?;
        let (aovs, accumulation) = (self.no_outputs.clone(), self.no_accumulation.clone());
        self.dispatch(view, (&aovs, &accumulation), width, height, |_| {})
    }

    /// Records the render kernel over `width` × `height` pixels into
    /// `view` and `aovs`, then `after`, submits and waits.
    fn dispatch(
        &mut self,
        view: &::wgpu::TextureView,
        (aovs, accumulation): (&::wgpu::Buffer, &::wgpu::Buffer),
        width: u32,
        height: u32,
        after: impl FnOnce(&mut ::wgpu::CommandEncoder),
    ) -> Result<()> {
        if self.pipeline.brute.is_some() {
            self.fit_brute_depths(width, height)?;
        }
        let tile = self.source.cone_tile;
        let tiles = (width.div_ceil(tile.max(1)), height.div_ceil(tile.max(1)));
        if self.pipeline.cone.is_some() {
            self.fit_cone_starts(tiles)?;
        }
        let device = &self.gpu.device;
        let entries = [
            (codegen::WGSL_PARAMS.1, self.params.as_entire_binding()),
            (CAMERA, self.camera.as_entire_binding()),
            (LIGHTS, self.lights.as_entire_binding()),
            (FRAME, self.frame.as_entire_binding()),
            (IMAGE, ::wgpu::BindingResource::TextureView(view)),
            (AOVS, aovs.as_entire_binding()),
            (ENVIRONMENT, self.environment.as_entire_binding()),
            (ACCUMULATION, accumulation.as_entire_binding()),
            (BRUTE_DEPTHS, self.brute_depths.as_entire_binding()),
            (CONE_STARTS, self.cone_starts.as_entire_binding()),
        ];
        let commands = checked(device, "the render pass", || {
            let group = device.create_bind_group(&::wgpu::BindGroupDescriptor {
                label: Some("fractal-sdf render"),
                layout: &self.pipeline.layout,
                entries: &entries
                    .map(|(binding, resource)| ::wgpu::BindGroupEntry { binding, resource }),
            });
            let mut encoder =
                device.create_command_encoder(&::wgpu::CommandEncoderDescriptor::default());
            {
                let mut pass =
                    encoder.begin_compute_pass(&::wgpu::ComputePassDescriptor::default());
                let groups = (width.div_ceil(WORKGROUP), height.div_ceil(WORKGROUP));
                pass.set_bind_group(codegen::WGSL_PARAMS.0, &group, &[]);
                if let Some(cone) = &self.pipeline.cone {
                    // The coarse pass: where each tile's rays start.
                    pass.set_pipeline(cone);
                    pass.dispatch_workgroups(
                        tiles.0.div_ceil(WORKGROUP),
                        tiles.1.div_ceil(WORKGROUP),
                        1,
                    );
                }
                if let Some(brute) = &self.pipeline.brute {
                    // Inside shapes: every sample marched first, for the
                    // render kernel to take normals from the neighbours'.
                    pass.set_pipeline(brute);
                    pass.dispatch_workgroups(groups.0, groups.1, 1);
                }
                pass.set_pipeline(&self.pipeline.compute);
                pass.dispatch_workgroups(groups.0, groups.1, 1);
            }
            after(&mut encoder);
            encoder.finish()
        })?;
        let started = Instant::now();
        checked(device, "the frame", || self.gpu.queue.submit([commands]))?;
        device
            .poll(::wgpu::PollType::wait_indefinitely())
            .map_err(|e| wgpu_error("the frame", e))?;
        self.timing = Some(started.elapsed());
        Ok(())
    }

    /// A buffer of a starting distance for each of `tiles` (columns, rows)
    /// of the coarse pass, made anew where the count changed.
    fn fit_cone_starts(&mut self, (columns, rows): (u32, u32)) -> Result<()> {
        let bytes = 4 * u64::from(columns) * u64::from(rows);
        if self.cone_starts.size() == bytes {
            return Ok(());
        }
        let device = &self.gpu.device;
        let size = usize::try_from(bytes).map_err(|_| Error::Wgpu("too many tiles".into()))?;
        self.cone_starts = checked(device, "the coarse pass's starts", || {
            buffer(device, "starts", size, ::wgpu::BufferUsages::STORAGE)
        })?;
        Ok(())
    }

    /// A brute-force depth buffer for every sample of a pass at
    /// `width` × `height` rendered pixels, made anew where the size
    /// changed: [`Error::Resolution`] where the device cannot bind it.
    fn fit_brute_depths(&mut self, width: u32, height: u32) -> Result<()> {
        let samples = u64::from(self.options.quality.supersampling).pow(2);
        let bytes = 8 * samples * u64::from(width) * u64::from(height);
        if self.brute_depths.size() == bytes {
            return Ok(());
        }
        let device = &self.gpu.device;
        let limits = device.limits();
        let most = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        if bytes > most {
            return Err(Error::Resolution {
                width,
                height,
                reason: format!(
                    "the brute-force depths of its {samples} samples a pixel take {bytes} \
                     bytes, more than the {most} the wgpu device binds at once (render a \
                     smaller image, or with less supersampling)"
                ),
            });
        }
        let size = usize::try_from(bytes).map_err(|_| Error::Resolution {
            width,
            height,
            reason: "the brute-force depths do not fit in memory".into(),
        })?;
        self.brute_depths = checked(device, "the brute-force depths", || {
            buffer(device, "depths", size, ::wgpu::BufferUsages::STORAGE)
        })?;
        Ok(())
    }

    /// The image texture of `image` pixels and the per-pixel buffer of
    /// `outputs` pixels, made anew where a size changed.
    fn targets(
        &mut self,
        image: (u32, u32),
        outputs: (u32, u32),
    ) -> Result<(::wgpu::Texture, ::wgpu::Buffer)> {
        let device = &self.gpu.device;
        let fits = self.texture.as_ref().is_some_and(|t| {
            let size = t.size();
            (size.width, size.height) == image
        });
        if !fits {
            let texture = checked(device, "the frame's image", || {
                device.create_texture(&::wgpu::TextureDescriptor {
                    label: Some("fractal-sdf image"),
                    size: ::wgpu::Extent3d {
                        width: image.0,
                        height: image.1,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: ::wgpu::TextureDimension::D2,
                    format: WGPU_TEXTURE_FORMAT,
                    usage: ::wgpu::TextureUsages::STORAGE_BINDING | ::wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                })
            })?;
            self.texture = Some(texture);
        }
        let bytes = 16 * outputs.0 as usize * outputs.1 as usize;
        let aovs = if bytes == self.no_outputs.size() as usize {
            self.no_outputs.clone()
        } else {
            if self
                .outputs
                .as_ref()
                .is_none_or(|b| b.size() as usize != bytes)
            {
                self.outputs = Some(checked(device, "the frame's per-pixel values", || {
                    buffer(device, "pixels", bytes, output_usage())
                })?);
            }
            self.outputs.clone().expect("made above")
        };
        Ok((self.texture.clone().expect("made above"), aovs))
    }

    /// The progressive sums of a `width` × `height` rendering, made anew
    /// where the size changed.
    fn accumulation(&mut self, width: u32, height: u32) -> Result<::wgpu::Buffer> {
        let bytes = 16 * width as usize * height as usize;
        if self
            .sums
            .as_ref()
            .is_none_or(|b| b.size() as usize != bytes)
        {
            let device = &self.gpu.device;
            self.sums = Some(checked(device, "the progressive sums", || {
                buffer(device, "sums", bytes, ::wgpu::BufferUsages::STORAGE)
            })?);
        }
        Ok(self.sums.clone().expect("made above"))
    }

    /// Writes the camera for a `width` × `height` image rendered at one
    /// pixel in `scale` × `scale`, and the frame's sizes.
    fn write_frame(
        &mut self,
        (width, height): (u32, u32),
        scale: u32,
        aovs: bool,
        pass: Option<u32>,
    ) -> Result<()> {
        self.write_params();
        let view = Viewport::in_frame(
            self.scene.camera(),
            width,
            height,
            Precision::F32,
            self.source.origin,
        )?;
        check_frame_inputs(
            &view,
            self.scene.lights(),
            self.source.origin,
            Precision::F32.limits(),
        )?;
        let camera = view.pack(self.source.origin, scale);
        self.gpu
            .queue
            .write_buffer(&self.camera, 0, &floats(&camera));
        let lights = u32::try_from(self.scene.lights().len()).expect("a few lights");
        // `Frame` in render.wgsl: four unsigned, then the pass (-1 for a
        // frame of its own), in a 32-byte buffer.
        let pass = pass.map_or(-1, |p| i32::try_from(p).expect("passes are capped"));
        let frame = [
            width.div_ceil(scale),
            height.div_ceil(scale),
            lights,
            u32::from(aovs),
        ];
        let mut bytes: Vec<u8> = frame.iter().flat_map(|v| v.to_le_bytes()).collect();
        bytes.extend_from_slice(&pass.to_le_bytes());
        bytes.resize(32, 0);
        self.gpu.queue.write_buffer(&self.frame, 0, &bytes);
        Ok(())
    }

    /// Writes the dynamic values that changed since the last frame, as
    /// the OpenCL renderer does: the values alone, unless the instance
    /// tables copy one that changed (then the tables are filled and their
    /// hierarchies fitted again, once for every value set since).
    fn write_params(&mut self) {
        let values = self.values.as_slice();
        match &self.written {
            Some(written) if same_bits(written, values) => return,
            Some(written) if !self.source.tables.differ(written, values) => {
                self.gpu
                    .queue
                    .write_buffer(&self.params, 0, &floats(values));
            }
            _ => {
                let mut bytes = floats(&self.source.param_buffer(values));
                bytes.resize(self.params.size() as usize, 0);
                self.gpu.queue.write_buffer(&self.params, 0, &bytes);
            }
        }
        self.written = Some(values.to_vec());
    }

    fn write_lights(&mut self) {
        let lights = self.scene.lights();
        let reals = light_reals(lights.len());
        if self.lights.size() as usize != 4 * reals {
            self.lights = buffer(
                &self.gpu.device,
                "lights",
                4 * reals,
                ::wgpu::BufferUsages::STORAGE | ::wgpu::BufferUsages::COPY_DST,
            );
        }
        let packed = pack_lights(lights, self.source.origin);
        self.gpu
            .queue
            .write_buffer(&self.lights, 0, &floats(&packed));
    }
}

/// The scene's WGSL module for rendering with `options`.
fn module(scene: &CompiledScene, options: &RenderOptions) -> Result<KernelSource> {
    codegen::emit_wgsl(
        scene,
        &codegen::Options::default()
            .quality(options.quality)
            .effects(options.effects)
            .target(Target::Render)
            .environment(scene.environment().is_some()),
    )
}

/// The device and queue [`WgpuRenderer::from_compiled`] renderers share,
/// or why there is none.
static SHARED: OnceLock<std::result::Result<(::wgpu::Device, ::wgpu::Queue), String>> =
    OnceLock::new();

/// The device and queue [`WgpuRenderer::from_compiled`] renderers share,
/// found on the first call.
pub(super) fn shared_device() -> Result<(::wgpu::Device, ::wgpu::Queue)> {
    let found = SHARED.get_or_init(|| {
        let adapter = pollster::block_on(::wgpu::util::initialize_adapter_from_env_or_default(
            &instance(),
            None,
        ))
        .map_err(|e| {
            format!(
                "no wgpu adapter (on Linux without a GPU, install Mesa's lavapipe: \
                 `apt-get install mesa-vulkan-drivers`): {e}"
            )
        })?;
        // The adapter's own limits: images and per-pixel buffers as large
        // as it holds, not WebGPU's defaults (8192 pixels a side).
        let descriptor = ::wgpu::DeviceDescriptor {
            label: Some("fractal-sdf"),
            required_limits: adapter.limits(),
            ..::wgpu::DeviceDescriptor::default()
        };
        pollster::block_on(adapter.request_device(&descriptor))
            .map_err(|e| format!("no wgpu device: {e}"))
    });
    found.clone().map_err(Error::Wgpu)
}

/// A render pipeline, the brute-force pass's where the scene has inside
/// shapes, the coarse pass's where the program has one, and the layout of
/// their bind group.
#[derive(Clone)]
struct Pipeline {
    compute: ::wgpu::ComputePipeline,
    brute: Option<::wgpu::ComputePipeline>,
    cone: Option<::wgpu::ComputePipeline>,
    layout: ::wgpu::BindGroupLayout,
}

/// How many pipelines the cache keeps, the most recently used.
const PIPELINE_CACHE_CAPACITY: usize = 64;

/// The pipeline of `source` on `device`: on the shared device, from the
/// cache of the pipelines built last (by source hash) where it is there;
/// otherwise built by the driver (an application's own device is not
/// kept alive by a cache). Returns whether it was built.
fn pipeline(device: &::wgpu::Device, source: &KernelSource) -> Result<(Pipeline, bool)> {
    static CACHE: Mutex<Vec<(u64, Pipeline)>> = Mutex::new(Vec::new());
    let shared = matches!(SHARED.get(), Some(Ok((d, _))) if d == device);
    let found = shared.then(|| {
        let mut entries = CACHE.lock().unwrap_or_else(PoisonError::into_inner);
        let at = entries.iter().position(|(hash, _)| *hash == source.hash)?;
        // The most recently used last.
        let entry = entries.remove(at);
        let pipeline = entry.1.clone();
        entries.push(entry);
        Some(pipeline)
    });
    if let Some(pipeline) = found.flatten() {
        return Ok((pipeline, false));
    }
    let pipeline = checked(device, "the render shader", || {
        let module = device.create_shader_module(::wgpu::ShaderModuleDescriptor {
            label: Some("fractal-sdf render"),
            source: ::wgpu::ShaderSource::Wgsl(source.source.as_str().into()),
        });
        let layout = bind_group_layout(device);
        let pipeline_layout = device.create_pipeline_layout(&::wgpu::PipelineLayoutDescriptor {
            label: Some("fractal-sdf render"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let entry = |name: &str| {
            device.create_compute_pipeline(&::wgpu::ComputePipelineDescriptor {
                label: Some(name),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(name),
                compilation_options: ::wgpu::PipelineCompilationOptions::default(),
                cache: None,
            })
        };
        Pipeline {
            compute: entry("render"),
            brute: source.brute.then(|| entry("brute_pass")),
            cone: (source.cone_tile > 0).then(|| entry("cone_pass")),
            layout,
        }
    })?;
    if shared {
        let mut entries = CACHE.lock().unwrap_or_else(PoisonError::into_inner);
        if entries.len() >= PIPELINE_CACHE_CAPACITY {
            entries.remove(0);
        }
        entries.push((source.hash, pipeline.clone()));
    }
    Ok((pipeline, true))
}

/// The render kernel's bindings (every one, including those a scene's
/// kernel does not read: the parameters of a scene without dynamic ones).
fn bind_group_layout(device: &::wgpu::Device) -> ::wgpu::BindGroupLayout {
    let storage = |binding, read_only| ::wgpu::BindGroupLayoutEntry {
        binding,
        visibility: ::wgpu::ShaderStages::COMPUTE,
        ty: ::wgpu::BindingType::Buffer {
            ty: ::wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    device.create_bind_group_layout(&::wgpu::BindGroupLayoutDescriptor {
        label: Some("fractal-sdf render"),
        entries: &[
            storage(codegen::WGSL_PARAMS.1, true),
            storage(CAMERA, true),
            storage(LIGHTS, true),
            ::wgpu::BindGroupLayoutEntry {
                binding: FRAME,
                visibility: ::wgpu::ShaderStages::COMPUTE,
                ty: ::wgpu::BindingType::Buffer {
                    ty: ::wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            ::wgpu::BindGroupLayoutEntry {
                binding: IMAGE,
                visibility: ::wgpu::ShaderStages::COMPUTE,
                ty: ::wgpu::BindingType::StorageTexture {
                    access: ::wgpu::StorageTextureAccess::WriteOnly,
                    format: WGPU_TEXTURE_FORMAT,
                    view_dimension: ::wgpu::TextureViewDimension::D2,
                },
                count: None,
            },
            storage(AOVS, false),
            storage(ENVIRONMENT, true),
            storage(ACCUMULATION, false),
            storage(BRUTE_DEPTHS, false),
            storage(CONE_STARTS, false),
        ],
    })
}

/// Reals in the light buffer for `count` lights (at least one light's).
fn light_reals(count: usize) -> usize {
    light::STRIDE * count.max(1)
}

fn check_size(width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 || width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
        return Err(Error::Resolution {
            width,
            height,
            reason: format!("each side must be between 1 and {MAX_IMAGE_SIDE} pixels"),
        });
    }
    Ok(())
}

/// A row of `width` RGBA8 pixels, padded to wgpu's copy alignment.
fn padded_row(width: u32) -> u32 {
    (4 * width).next_multiple_of(::wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
}

fn output_usage() -> ::wgpu::BufferUsages {
    ::wgpu::BufferUsages::STORAGE | ::wgpu::BufferUsages::COPY_SRC
}

pub(super) fn read_back() -> ::wgpu::BufferUsages {
    ::wgpu::BufferUsages::MAP_READ | ::wgpu::BufferUsages::COPY_DST
}

pub(super) fn buffer(
    device: &::wgpu::Device,
    label: &str,
    bytes: usize,
    usage: ::wgpu::BufferUsages,
) -> ::wgpu::Buffer {
    device.create_buffer(&::wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes as u64,
        usage,
        mapped_at_creation: false,
    })
}

/// Whether `a` and `b` hold the same values, bit for bit.
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// `values` as the little-endian `f32`s the shader reads.
fn floats(values: &[f64]) -> Vec<u8> {
    values
        .iter()
        .flat_map(|&v| (v as f32).to_le_bytes())
        .collect()
}

/// The contents of a buffer that a finished submission copied into.
pub(super) fn read(device: &::wgpu::Device, staging: &::wgpu::Buffer) -> Result<Vec<u8>> {
    let (send, receive) = std::sync::mpsc::channel();
    staging
        .slice(..)
        .map_async(::wgpu::MapMode::Read, move |r| {
            let _ = send.send(r);
        });
    device
        .poll(::wgpu::PollType::wait_indefinitely())
        .map_err(|e| wgpu_error("reading the frame back", e))?;
    receive
        .recv()
        .map_err(|e| wgpu_error("reading the frame back", e))?
        .map_err(|e| wgpu_error("reading the frame back", e))?;
    let bytes = staging
        .slice(..)
        .get_mapped_range()
        .map_err(|e| wgpu_error("reading the frame back", e))?
        .to_vec();
    staging.unmap();
    Ok(bytes)
}
