//! The renderer: one scene's program on one device, and the buffers that
//! carry the per-frame inputs (parameters, camera, lights) and outputs.

use std::time::{Duration, Instant};

use glam::DVec3;
use image::RgbaImage;
use ocl::enums::ProfilingInfo;
use ocl::{Buffer, Context, Event, Kernel, MemFlags, Program, Queue};

use super::adaptive::{self, AdaptiveFrame, EdgeThresholds};
use super::aov::Frame;
use super::buffer::RealBuffer;
use super::cancel::CancelToken;
use super::device::{self, DeviceInfo, DeviceSelector, Selected, opencl};
use super::dispatch::{self, DEFAULT_TILE_SIZE, MAX_IMAGE_SIDE};
use super::memory::{available_host_memory, check_host_memory, frame_host_bytes};
use super::program::{self, BuildInfo};
use super::upscale;
use super::viewport::{Viewport, check_frame_inputs, pack_lights};
use crate::codegen::interface::{
    BRUTE_DEPTHS, BruteArg, CONE_STARTS, ConeArg, RENDER_TILE, RenderArg, camera,
};
use crate::codegen::{self, KernelSource};
use crate::error::{Error, Result};
use crate::ir::{CompiledScene, ParamValues};
use crate::quality::{Effects, Precision, Quality};
use crate::scene::{Camera, Light, Scene};
use crate::view::FrameTiming;

/// Everything that decides how a scene is rendered, apart from the scene.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RenderOptions {
    /// Accuracy knobs (compiled into the program).
    pub quality: Quality,
    /// Lighting effects (compiled into the program).
    pub effects: Effects,
    /// Which OpenCL device to use.
    pub device: DeviceSelector,
    /// Side of the square tiles the image is launched in, in pixels. Each
    /// tile is one kernel launch, which cannot be interrupted: smaller
    /// tiles make [`RenderOptions::deadline`] and
    /// [`RenderOptions::cancel`] take effect sooner.
    pub tile_size: u32,
    /// The longest a frame may take: once it has passed, no further tile is
    /// launched and the frame fails with [`Error::Deadline`] after the
    /// tiles in flight finish. A watchdog bounds that wait too: a launch
    /// still running at twice the deadline (a custom shape whose body
    /// never ends, say) is abandoned and the frame fails at once; OpenCL
    /// cannot stop a launch, so the device may go on running it, and the
    /// renderer refuses further frames (make a new one). `None`: no limit.
    pub deadline: Option<Duration>,
    /// A token that stops a frame between tiles, from any thread (see
    /// [`CancelToken`]); the frame fails with [`Error::Cancelled`].
    pub cancel: Option<CancelToken>,
}

impl Default for RenderOptions {
    /// Production quality, default effects, automatic device, 256-pixel
    /// tiles, no deadline, no cancellation.
    fn default() -> Self {
        RenderOptions {
            quality: Quality::default(),
            effects: Effects::default(),
            device: DeviceSelector::default(),
            tile_size: DEFAULT_TILE_SIZE,
            deadline: None,
            cancel: None,
        }
    }
}

setters!(RenderOptions {
    /// Sets [`RenderOptions::quality`].
    quality: Quality,
    /// Sets [`RenderOptions::effects`].
    effects: Effects,
    /// Sets [`RenderOptions::device`].
    device: DeviceSelector,
    /// Sets [`RenderOptions::tile_size`].
    tile_size: u32,
    /// Sets [`RenderOptions::deadline`].
    deadline: Option<Duration>,
    /// Sets [`RenderOptions::cancel`].
    cancel: Option<CancelToken>,
});

/// Tiles in flight at once: the next tile is launched when the one before
/// the last has finished, so the device stays busy while the renderer
/// can still stop between tiles.
const TILES_IN_FLIGHT: usize = 2;

const KERNEL_NAME: &str = "render_tile";
const CONE_KERNEL_NAME: &str = "cone_starts";

/// The brute-force pass of programs that march inside shapes.
const BRUTE_KERNEL_NAME: &str = "brute_depths";

/// Renders one scene on one OpenCL device.
///
/// It is built from a [`CompiledScene`]: the scene is validated and lowered
/// once, and the program generated and compiled once (or taken from the
/// process-wide cache). Changing dynamic parameters, the camera or the
/// lights between frames only rewrites small buffers and never runs code
/// generation; changing the quality or effects generates a new program.
///
/// ```no_run
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::render::Renderer;
///
/// let scene = Scene::new(sphere(param("radius", 1.0)).union(plane(dvec3(0.0, 1.0, 0.0), 1.0)));
/// let mut renderer = Renderer::new(&scene, Quality::preview())?;
/// let image = renderer.render(320, 240)?;
/// renderer.set_param("radius", 0.8)?; // no recompilation
/// let smaller = renderer.render(320, 240)?;
/// fractal_sdf::output::save_png(&smaller, "out/sphere.png")?;
/// # let _ = image;
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
#[derive(Debug)]
pub struct Renderer {
    selected: Selected,
    context: Context,
    queue: Queue,
    scene: CompiledScene,
    options: RenderOptions,
    values: ParamValues,
    functions: SceneFunctions,
    source: KernelSource,
    build: BuildInfo,
    builds: u64,
    kernel: Kernel,
    /// The coarse pass, in a program that has one
    /// ([`Quality::cone_tile`]).
    cone: Option<Kernel>,
    /// The brute-force pass, in a program that marches inside shapes
    /// ([`Quality::brute_step`]).
    brute: Option<BrutePass>,
    local: (usize, usize),
    inputs: Inputs,
    targets: Targets,
    timing: Option<FrameTiming>,
    /// Renderers on further devices that draw a share of every frame's
    /// tiles (see [`Renderer::with_devices`]).
    partners: Vec<Renderer>,
    /// This renderer's share of the tiles, `(k, n)`: the tiles whose index
    /// is `k` modulo `n`.
    share: (usize, usize),
    /// The progressive pass the next launch is, or -1 for a frame of its
    /// own (the kernel's `pass`).
    pass: i32,
    /// The progressive passes accumulated so far, and the image size they
    /// are for; `None` once anything that changes the image has changed.
    progress: Option<Progress>,
    /// Whether launches render only the pixels of the refine buffer
    /// (the kernel's `refine_only`).
    refine_only: bool,
    /// Whether a launch was abandoned at its frame's watchdog (see
    /// [`RenderOptions::deadline`]): the device may still be running it,
    /// so the renderer refuses further frames and, when dropped, leaves its
    /// OpenCL objects to the process's end rather than wait for it.
    abandoned: bool,
}

impl Drop for Renderer {
    fn drop(&mut self) {
        if self.abandoned {
            // Releasing the last reference to a queue waits for its
            // commands on some platforms: one reference more, never
            // released, keeps this drop from waiting on a launch that may
            // never end.
            std::mem::forget(self.queue.clone());
            std::mem::forget(self.context.clone());
            std::mem::forget(self.kernel.clone());
        }
    }
}

/// Progressive rendering's state: the passes in the accumulation buffers.
#[derive(Debug, Clone)]
struct Progress {
    width: u32,
    height: u32,
    passes: u32,
    /// The image once the passes reach the most samples per pixel.
    converged: Option<RgbaImage>,
}

/// Where a renderer's `DE` and `DE_shade` come from.
#[derive(Debug, Clone)]
enum SceneFunctions {
    /// Code generation, from the compiled scene.
    Generated,
    /// Hand-written functions, kept through quality and effect changes.
    HandWritten(String),
}

/// The program for a scene's functions and options. This is the one place
/// the renderer runs code generation.
fn generate(
    scene: &CompiledScene,
    functions: &SceneFunctions,
    options: &RenderOptions,
) -> Result<KernelSource> {
    let options = codegen::Options {
        quality: options.quality,
        effects: options.effects,
        target: codegen::Target::Render,
    };
    match functions {
        SceneFunctions::Generated => codegen::emit(scene, &options),
        SceneFunctions::HandWritten(f) => codegen::emit_handwritten(f, &options),
    }
}

impl Renderer {
    /// A renderer for `scene` with `quality`, the default effects and the
    /// automatically chosen device.
    ///
    /// # Errors
    /// See [`Renderer::with_options`].
    pub fn new(scene: &Scene, quality: Quality) -> Result<Self> {
        Self::with_options(
            scene,
            &RenderOptions {
                quality,
                ..RenderOptions::default()
            },
        )
    }

    /// A renderer for `scene` with explicit options: compiles the scene
    /// and calls [`Renderer::from_compiled`].
    ///
    /// # Errors
    /// See [`Renderer::from_compiled`].
    pub fn with_options(scene: &Scene, options: &RenderOptions) -> Result<Self> {
        Self::from_compiled(scene.compile()?, options)
    }

    /// A renderer for a compiled scene (nothing is validated or lowered
    /// again).
    ///
    /// # Errors
    /// Quality, effects and [`Error::TileSize`] errors;
    /// [`Error::NoPlatform`], [`Error::NoDevice`];
    /// [`Error::Fp64Unsupported`] for `F64` on a device without it;
    /// [`Error::Build`] with the compiler log and the source, or
    /// [`Error::CustomShapeBuild`] when the compiler rejects a custom
    /// shape's body.
    pub fn from_compiled(scene: CompiledScene, options: &RenderOptions) -> Result<Self> {
        Self::build(scene, options, SceneFunctions::Generated)
    }

    /// A renderer running hand-written scene functions: `scene_functions`
    /// defines `DE` and `DE_shade` as the contract in [`crate::render`]
    /// says, and the program around them is generated for the options (see
    /// [`codegen::emit_handwritten`]); quality and effect changes keep
    /// them. The scene supplies the dynamic parameters, the camera and the
    /// lights. For experiments and for measuring generated code against
    /// hand-written code.
    ///
    /// # Errors
    /// As [`Renderer::from_compiled`].
    pub fn with_scene_functions(
        scene: CompiledScene,
        options: &RenderOptions,
        scene_functions: impl Into<String>,
    ) -> Result<Self> {
        Self::build(
            scene,
            options,
            SceneFunctions::HandWritten(scene_functions.into()),
        )
    }

    fn build(
        scene: CompiledScene,
        options: &RenderOptions,
        functions: SceneFunctions,
    ) -> Result<Self> {
        validate(options)?;
        check_light_count(scene.lights())?;
        let source = generate(&scene, &functions, options)?;
        let values = scene.default_values();
        check_inputs(&scene, &values, &source)?;
        let selected = device::select(&options.device)?;
        let context = program::context(&selected)?;
        let queue = profiling_queue(&context, &selected)?;
        let inputs = Inputs::new(&queue, &source, &values, scene.lights())?;
        let targets = Targets::new(&queue, 1, 1, true, false)?;
        let (program, build, compiled) = program::build(&selected, &context, &source)?;
        let kernel = make_kernel(&program, &queue, &inputs, &targets)?;
        let cone = make_cone(&program, &queue, &inputs, &targets, &source)?;
        let brute = BrutePass::new(&program, &queue, &inputs, &source)?;
        let local = local_size(&kernel, &selected)?;
        Ok(Renderer {
            selected,
            context,
            queue,
            scene,
            options: options.clone(),
            values,
            functions,
            source,
            build,
            builds: u64::from(compiled),
            kernel,
            cone,
            brute,
            local,
            inputs,
            targets,
            timing: None,
            partners: Vec::new(),
            share: (0, 1),
            pass: -1,
            progress: None,
            refine_only: false,
            abandoned: false,
        })
    }

    /// A renderer that splits every frame across several devices: the
    /// image's tiles are dealt out in turn (tile `i` to device `i mod n`),
    /// each device renders its tiles in its own thread, and the frame is
    /// put together from them. Every device runs the same program, so the
    /// image is the one a single device renders where the devices compute
    /// alike (the same device listed twice gives identical pixels); the
    /// camera, lights, parameters, quality and effects set on this
    /// renderer apply to every device. [`Renderer::device`] and
    /// [`Renderer::last_timing`] describe the first device;
    /// [`Renderer::render_with_aovs`] renders on the first device alone.
    /// `options.device` is not used.
    ///
    /// ```no_run
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::render::{DeviceSelector, RenderOptions, Renderer, devices};
    ///
    /// let every: Vec<DeviceSelector> = devices()?.iter().map(DeviceSelector::exactly).collect();
    /// let scene = Scene::new(mandelbulb(8.0));
    /// let mut renderer = Renderer::with_devices(&scene, &RenderOptions::default(), &every)?;
    /// let image = renderer.render(640, 480)?;
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::NoDevice`] for an empty list; else as
    /// [`Renderer::with_options`], for each device.
    pub fn with_devices(
        scene: &Scene,
        options: &RenderOptions,
        devices: &[DeviceSelector],
    ) -> Result<Self> {
        let Some((first, rest)) = devices.split_first() else {
            return Err(Error::NoDevice {
                selection: "an empty list of devices".into(),
                available: device::devices()
                    .map(|all| {
                        all.iter()
                            .map(DeviceInfo::label)
                            .collect::<Vec<_>>()
                            .join(", ")
                    })
                    .unwrap_or_default(),
            });
        };
        let compiled = scene.compile()?;
        let on = |device: &DeviceSelector| RenderOptions {
            device: device.clone(),
            ..options.clone()
        };
        let mut renderer = Self::from_compiled(compiled.clone(), &on(first))?;
        renderer.partners = rest
            .iter()
            .map(|d| Self::from_compiled(compiled.clone(), &on(d)))
            .collect::<Result<_>>()?;
        Ok(renderer)
    }

    /// The devices this renderer splits frames across: its own, then those
    /// of [`Renderer::with_devices`].
    #[must_use]
    pub fn devices(&self) -> Vec<&DeviceInfo> {
        std::iter::once(self.device())
            .chain(self.partners.iter().map(Renderer::device))
            .collect()
    }

    /// Applies `change` to every partner renderer.
    fn for_partners(&mut self, change: impl Fn(&mut Renderer) -> Result<()>) -> Result<()> {
        self.partners.iter_mut().try_for_each(change)
    }

    /// Renders a frame with the partners: each device its share of the
    /// tiles, at once, then the partners' tiles copied into this one's.
    fn render_shared(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        let n = self.partners.len() + 1;
        let mut partners = std::mem::take(&mut self.partners);
        let (mine, theirs) = std::thread::scope(|s| {
            let handles: Vec<_> = partners
                .iter_mut()
                .enumerate()
                .map(|(i, p)| s.spawn(move || p.render_share(width, height, (i + 1, n))))
                .collect();
            let mine = self.render_share(width, height, (0, n));
            let theirs: Vec<Result<Rendered>> = handles
                .into_iter()
                .map(|h| h.join().expect("a device's thread does not panic"))
                .collect();
            (mine, theirs)
        });
        self.partners = partners;
        let mut low = mine?;
        let theirs = theirs.into_iter().collect::<Result<Vec<_>>>()?;
        let (lw, lh) = low.image.dimensions();
        let span = |y: u32, x: u32, w: u32| {
            let start = (y * lw + x) as usize;
            start..start + w as usize
        };
        for (i, tile) in dispatch::tiles(lw, lh, self.options.tile_size).enumerate() {
            let Some(from) = (i % n).checked_sub(1).map(|p| &theirs[p]) else {
                continue;
            };
            for y in tile.y..tile.y + tile.height {
                let pixels = span(y, tile.x, tile.width);
                let bytes = 4 * pixels.start..4 * pixels.end;
                let (dst, src): (&mut [u8], &[u8]) = (&mut low.image, &from.image);
                dst[bytes.clone()].copy_from_slice(&src[bytes]);
                if let (Some(dst), Some(src)) = (&mut low.depth, &from.depth) {
                    dst[pixels.clone()].copy_from_slice(&src[pixels]);
                }
            }
        }
        Ok(low.scaled(width, height, self.scale()))
    }

    /// Renders this renderer's `share` of the tiles (the rest of the image
    /// is left as it was), at the rendered resolution.
    fn render_share(&mut self, width: u32, height: u32, share: (usize, usize)) -> Result<Rendered> {
        self.share = share;
        let image = self.render_low(width, height);
        self.share = (0, 1);
        image
    }

    /// Image pixels per rendered pixel along each axis
    /// ([`Quality::resolution_scale`]).
    fn scale(&self) -> u32 {
        self.options.quality.resolution_scale.max(1)
    }

    /// Renders a `width` × `height` image.
    ///
    /// # Errors
    /// [`Error::Resolution`] for a zero side, a side above 32768, an image
    /// whose buffers the device cannot hold, or one whose host memory (the
    /// copies read back, and a CPU device's buffers) exceeds what the
    /// machine has available (`MemAvailable`, and the process's cgroup
    /// limit, on Linux) — each with the numbers; [`Error::Precision`] for a
    /// camera or lights the program's precision cannot compute with at this
    /// size; [`Error::Cancelled`] or [`Error::Deadline`] when
    /// [`RenderOptions::cancel`] or [`RenderOptions::deadline`] stops the
    /// frame between tiles; [`Error::OpenCl`] if the device fails.
    pub fn render(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        if self.partners.is_empty() {
            self.render_alone(width, height)
        } else {
            self.render_shared(width, height)
        }
    }

    /// Renders one more progressive pass of a `width` × `height` image and
    /// returns the mean of every pass so far.
    ///
    /// The first pass is the frame [`Renderer::render`] draws. Each later
    /// pass adds [`Quality::supersampling`]² new samples to every pixel,
    /// each at its own point in the pixel and on the lens
    /// ([`Camera::aperture`]), and the image converges on the mean over
    /// the pixel and the lens: edges smooth out and depth of field
    /// becomes a soft blur. The sums are kept on the device, so a pass
    /// costs one frame's samples whatever the count.
    ///
    /// Changing the camera, lights, a parameter, the quality, the effects
    /// or the size starts again from the first pass; so does
    /// [`Renderer::restart_progressive`]. Past
    /// [`Renderer::MAX_PROGRESSIVE_SAMPLES`] samples per pixel the image
    /// has converged, and a further call renders no more passes but
    /// returns it again.
    ///
    /// ```no_run
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::render::Renderer;
    ///
    /// let camera = Camera::look_at(dvec3(0.0, 0.5, 3.0), DVec3::ZERO).lens(0.08);
    /// let scene = Scene::new(mandelbulb(8.0)).with_camera(camera);
    /// let mut renderer = Renderer::new(&scene, Quality::preview())?;
    /// let mut image = renderer.render_progressive(320, 240)?;
    /// while renderer.progressive_passes() < 16 {
    ///     image = renderer.render_progressive(320, 240)?;
    /// }
    /// # let _ = image;
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`Renderer::render`]; after a failed pass the next call starts
    /// again from the first.
    pub fn render_progressive(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        let last = self.most_passes();
        let done = match &self.progress {
            Some(p) if (p.width, p.height) == (width, height) => {
                if let Some(image) = &p.converged {
                    return Ok(image.clone());
                }
                p.passes
            }
            _ => 0,
        };
        // Sums lost with buffers made anew (for another size) start again.
        let (lw, lh) = self.rendered_size(width, height);
        let done = if self.targets.fits(lw, lh, false, true) {
            done
        } else {
            0
        };
        self.progress = None;
        self.set_pass(i32::try_from(done).expect("passes are at most 4096"));
        let image = self.render(width, height);
        self.set_pass(-1);
        let image = image?;
        let passes = done + 1;
        self.progress = Some(Progress {
            width,
            height,
            passes,
            converged: (passes == last).then(|| image.clone()),
        });
        Ok(image)
    }

    /// The progressive passes in the last image of
    /// [`Renderer::render_progressive`]: 0 before the first, or after
    /// anything that restarts it.
    #[must_use]
    pub fn progressive_passes(&self) -> u32 {
        self.progress.as_ref().map_or(0, |p| p.passes)
    }

    /// Makes the next [`Renderer::render_progressive`] start from its
    /// first pass.
    pub fn restart_progressive(&mut self) {
        self.progress = None;
    }

    /// The most samples per pixel progressive rendering takes: past it the
    /// sums, kept in `f32`, would round away what a further sample adds.
    pub const MAX_PROGRESSIVE_SAMPLES: u32 = 4096;

    /// Renders a `width` × `height` image with adaptive supersampling: a
    /// first pass with its outputs everywhere, then `passes - 1` further
    /// progressive passes only at the pixels that differ from a neighbour
    /// by more than `thresholds` ([`adaptive::edges`]: a silhouette, a
    /// crease, a depth step, a colour edge such as a shadow's). A refined
    /// pixel is the mean of every pass's samples, exactly the pixel
    /// [`Renderer::render_progressive`] gives after as many passes; the
    /// rest keep their first sample. It renders on the first device alone,
    /// as [`Renderer::render_with_aovs`] does, and starts the progressive
    /// passes again.
    ///
    /// ```no_run
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::render::{EdgeThresholds, Renderer};
    ///
    /// let mut renderer = Renderer::new(&fractal_sdf::gallery::csg(), Quality::production())?;
    /// let frame = renderer.render_adaptive(640, 480, 16, &EdgeThresholds::default())?;
    /// println!("{:.0}% of the pixels refined", 100.0 * frame.refined_fraction());
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::Quality`] for `passes` of 0 or past
    /// [`Renderer::MAX_PROGRESSIVE_SAMPLES`] samples per pixel; else as
    /// [`Renderer::render`].
    pub fn render_adaptive(
        &mut self,
        width: u32,
        height: u32,
        passes: u32,
        thresholds: &EdgeThresholds,
    ) -> Result<AdaptiveFrame> {
        let most = self.most_passes();
        if passes == 0 || passes > most {
            return Err(Error::Quality {
                setting: "adaptive passes",
                value: f64::from(passes),
                expected: format!("in 1..={most} at this supersampling"),
            });
        }
        self.progress = None;
        let frame = self.refine_adaptively(width, height, passes, thresholds);
        self.pass = -1;
        self.refine_only = false;
        frame
    }

    fn refine_adaptively(
        &mut self,
        width: u32,
        height: u32,
        passes: u32,
        thresholds: &EdgeThresholds,
    ) -> Result<AdaptiveFrame> {
        self.pass = 0;
        let first = self.render_with_aovs(width, height)?;
        let marked = adaptive::edges(&first, thresholds);
        // The rendered pixels: one for every `scale` × `scale` of the
        // image, refined if any of them is marked.
        let scale = self.scale();
        let (lw, lh) = self.rendered_size(width, height);
        let mut refined = vec![false; lw as usize * lh as usize];
        for (i, _) in marked.iter().enumerate().filter(|(_, m)| **m) {
            let (x, y) = (i as u32 % width / scale, i as u32 / width / scale);
            refined[(y * lw + x) as usize] = true;
        }
        let bytes: Vec<u8> = refined.iter().map(|&r| u8::from(r)).collect();
        self.targets.refine.write(&bytes).enq().map_err(opencl)?;
        self.refine_only = true;
        let mut image = first.image.clone();
        for pass in 1..passes {
            self.pass = i32::try_from(pass).expect("passes are at most 4096");
            image = self.render_low(width, height)?.scaled(width, height, scale);
        }
        Ok(AdaptiveFrame {
            image,
            first,
            refined,
            passes,
        })
    }

    /// The most progressive passes at the quality's supersampling: as many
    /// as make [`Renderer::MAX_PROGRESSIVE_SAMPLES`], one at least.
    fn most_passes(&self) -> u32 {
        let per_pass = self.options.quality.supersampling.max(1).pow(2);
        (Self::MAX_PROGRESSIVE_SAMPLES / per_pass).max(1)
    }

    /// Sets the kernel's `pass` here and on the partners.
    fn set_pass(&mut self, pass: i32) {
        self.pass = pass;
        for p in &mut self.partners {
            p.set_pass(pass);
        }
    }

    /// Renders the image on this renderer's own device.
    fn render_alone(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        let start = Instant::now();
        let low = self.render_low(width, height)?;
        let image = low.scaled(width, height, self.scale());
        if let Some(t) = &mut self.timing {
            t.total = start.elapsed();
        }
        Ok(image)
    }

    /// Renders this renderer's share of the tiles on its own device, at the
    /// rendered resolution (with depth, to scale it up by, when that is
    /// smaller than the image's).
    fn render_low(&mut self, width: u32, height: u32) -> Result<Rendered> {
        let start = Instant::now();
        let scaled = self.scale() > 1;
        let kernel = self.run(width, height, scaled)?;
        let read = Instant::now();
        let (lw, lh) = self.rendered_size(width, height);
        let mut rgba = host_vec::<u8>(lw, lh, 4)?;
        self.targets.rgba.read(&mut rgba).enq().map_err(opencl)?;
        let depth = if scaled {
            let mut depth = host_vec::<f32>(lw, lh, 1)?;
            self.targets.depth.read(&mut depth).enq().map_err(opencl)?;
            Some(depth)
        } else {
            None
        };
        self.record_timing(start, read, kernel);
        Ok(Rendered {
            image: RgbaImage::from_raw(lw, lh, rgba).expect("buffer has width * height * 4 bytes"),
            depth,
        })
    }

    /// The size the kernel renders for a `width` × `height` image: smaller
    /// by [`Quality::resolution_scale`], rounded up.
    fn rendered_size(&self, width: u32, height: u32) -> (u32, u32) {
        let k = self.scale();
        (width.div_ceil(k), height.div_ceil(k))
    }

    /// Renders a `width` × `height` image with depth, hit mask, normal and
    /// cost outputs (see [`Frame`]).
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_with_aovs(&mut self, width: u32, height: u32) -> Result<Frame> {
        let start = Instant::now();
        let kernel = self.run(width, height, true)?;
        let read = Instant::now();
        let (image_w, image_h, scale) = (width, height, self.scale());
        let (width, height) = self.rendered_size(width, height);
        let t = &self.targets;
        let mut rgba = host_vec::<u8>(width, height, 4)?;
        let mut depth = host_vec::<f32>(width, height, 1)?;
        let mut hit = host_vec::<u8>(width, height, 1)?;
        let mut normals = host_vec::<f32>(width, height, 3)?;
        let mut steps = host_vec::<u32>(width, height, 1)?;
        let mut evaluations = host_vec::<u32>(width, height, 1)?;
        t.rgba.read(&mut rgba).enq().map_err(opencl)?;
        t.depth.read(&mut depth).enq().map_err(opencl)?;
        t.hit.read(&mut hit).enq().map_err(opencl)?;
        t.normals.read(&mut normals).enq().map_err(opencl)?;
        t.steps.read(&mut steps).enq().map_err(opencl)?;
        t.evaluations.read(&mut evaluations).enq().map_err(opencl)?;
        let starts = self.starts(width, height)?;
        let frame = Frame {
            start: starts,
            image: RgbaImage::from_raw(width, height, rgba)
                .expect("buffer has width * height * 4 bytes"),
            depth,
            hit: hit.into_iter().map(|h| h != 0).collect(),
            normal: normals
                .chunks_exact(3)
                .map(|n| [n[0], n[1], n[2]])
                .collect(),
            steps,
            evaluations,
        };
        let frame = if scale > 1 {
            upscale::frame(&frame, image_w, image_h, scale)
        } else {
            frame
        };
        self.record_timing(start, read, kernel);
        Ok(frame)
    }

    /// What the last frame cost: kernel time (from OpenCL profiling
    /// events), readback and the whole call. `None` before the first frame
    /// and after a failed one.
    ///
    /// ```no_run
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::render::Renderer;
    ///
    /// let mut renderer = Renderer::new(&Scene::new(sphere(1.0)), Quality::preview())?;
    /// renderer.render(320, 240)?;
    /// let t = renderer.last_timing().expect("a frame was rendered");
    /// println!("kernel {:?}, readback {:?}, total {:?}", t.kernel, t.readback, t.total);
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    #[must_use]
    pub fn last_timing(&self) -> Option<FrameTiming> {
        self.timing
    }

    /// Sets a dynamic parameter for the next frames (no recompilation).
    ///
    /// # Errors
    /// [`Error::UnknownParam`], or the error a baked value would get: the
    /// parameter's own rule, or a rule relating it to other parameters
    /// (see [`ParamValues::set`]), or [`Error::Precision`] for a value the
    /// program's precision cannot compute with.
    pub fn set_param(&mut self, name: &str, value: f64) -> Result<()> {
        let limits = self.source.precision.limits();
        self.values.set_within(name, value, limits)?;
        self.progress = None;
        self.for_partners(|p| p.set_param(name, value))
    }

    /// The current value of a dynamic parameter.
    #[must_use]
    pub fn param(&self, name: &str) -> Option<f64> {
        self.values.get(name)
    }

    /// Moves the camera (no recompilation).
    ///
    /// # Errors
    /// [`Error::Camera`] if the camera is degenerate; [`Error::Precision`]
    /// if the program's precision cannot compute with it.
    pub fn set_camera(&mut self, camera: Camera) -> Result<()> {
        let view = Viewport::in_frame(&camera, 1, 1, self.source.precision, self.source.origin)?;
        let limits = self.source.precision.limits();
        check_frame_inputs(&view, &[], self.source.origin, limits)?;
        self.scene.set_camera(camera)?;
        self.progress = None;
        self.for_partners(|p| p.set_camera(camera))
    }

    /// The camera.
    #[must_use]
    pub fn camera(&self) -> &Camera {
        self.scene.camera()
    }

    /// Replaces the lights, any number of them. The lights and their count
    /// are kernel arguments: this never generates or compiles code.
    ///
    /// # Errors
    /// The first invalid light, as [`Scene::compile`] reports it;
    /// [`Error::TooManyLights`]; [`Error::Precision`] for a light the
    /// program's precision cannot compute with.
    pub fn set_lights(&mut self, lights: impl IntoIterator<Item = Light>) -> Result<()> {
        let lights: Vec<Light> = lights.into_iter().collect();
        check_light_count(&lights)?;
        let mut scene = self.scene.clone();
        scene.set_lights(lights.clone())?;
        check_inputs(&scene, &self.values, &self.source)?;
        self.for_partners(|p| p.set_lights(lights.iter().copied()))?;
        self.scene = scene;
        self.progress = None;
        Ok(())
    }

    /// The lights.
    #[must_use]
    pub fn lights(&self) -> &[Light] {
        self.scene.lights()
    }

    /// The compiled scene this renderer draws, with the current camera and
    /// lights.
    #[must_use]
    pub fn scene(&self) -> &CompiledScene {
        &self.scene
    }

    /// Changes the quality: a new program (compiled unless cached).
    ///
    /// # Errors
    /// As [`Renderer::with_options`].
    pub fn set_quality(&mut self, quality: Quality) -> Result<()> {
        let options = RenderOptions {
            quality,
            ..self.options.clone()
        };
        self.reprogram(options)?;
        self.for_partners(|p| p.set_quality(quality))
    }

    /// Changes the effects: a new program (compiled unless cached).
    ///
    /// # Errors
    /// As [`Renderer::with_options`].
    pub fn set_effects(&mut self, effects: Effects) -> Result<()> {
        let options = RenderOptions {
            effects,
            ..self.options.clone()
        };
        self.reprogram(options)?;
        self.for_partners(|p| p.set_effects(effects))
    }

    /// The options in use.
    #[must_use]
    pub fn options(&self) -> &RenderOptions {
        &self.options
    }

    /// The device this renderer runs on.
    #[must_use]
    pub fn device(&self) -> &DeviceInfo {
        &self.selected.info
    }

    /// How the current program was obtained, and how long it took to build.
    #[must_use]
    pub fn build_info(&self) -> &BuildInfo {
        &self.build
    }

    /// Programs this renderer has had the OpenCL compiler build (programs
    /// found in the cache do not count). Frames, parameter, camera and
    /// light changes never add to it.
    #[must_use]
    pub fn builds(&self) -> u64 {
        self.builds
    }

    /// The OpenCL C source of the current program.
    #[must_use]
    pub fn source(&self) -> &KernelSource {
        &self.source
    }

    /// The viewport of the current camera for a `width` × `height` image:
    /// the exact rays and hit thresholds the kernel uses.
    ///
    /// # Errors
    /// As [`Viewport::new`].
    pub fn viewport(&self, width: u32, height: u32) -> Result<Viewport> {
        Viewport::in_frame(
            self.scene.camera(),
            width,
            height,
            self.source.precision,
            self.source.origin,
        )
    }

    fn reprogram(&mut self, options: RenderOptions) -> Result<()> {
        validate(&options)?;
        let source = generate(&self.scene, &self.functions, &options)?;
        check_inputs(&self.scene, &self.values, &source)?;
        self.load(source)?;
        self.options = options;
        self.progress = None;
        Ok(())
    }

    /// Switches to the program `source` (built now or taken from the
    /// cache).
    fn load(&mut self, source: KernelSource) -> Result<()> {
        let (program, build, compiled) = program::build(&self.selected, &self.context, &source)?;
        let inputs_changed =
            source.precision != self.source.precision || source.constants != self.source.constants;
        if inputs_changed {
            self.inputs = Inputs::new(&self.queue, &source, &self.values, self.scene.lights())?;
        }
        self.kernel = make_kernel(&program, &self.queue, &self.inputs, &self.targets)?;
        self.cone = make_cone(&program, &self.queue, &self.inputs, &self.targets, &source)?;
        self.brute = BrutePass::new(&program, &self.queue, &self.inputs, &source)?;
        self.local = local_size(&self.kernel, &self.selected)?;
        self.source = source;
        self.build = build;
        self.builds += u64::from(compiled);
        Ok(())
    }

    fn record_timing(&mut self, start: Instant, read: Instant, kernel: (Duration, bool)) {
        let end = Instant::now();
        self.timing = Some(FrameTiming {
            kernel: kernel.0,
            readback: end - read,
            total: end - start,
            profiled: kernel.1,
        });
    }

    /// Each rendered pixel's start distance: its tile's, read back from the
    /// coarse pass, or 0 without one.
    fn starts(&self, width: u32, height: u32) -> Result<Vec<f32>> {
        let side = self.source.cone_tile;
        let mut out = host_vec::<f32>(width, height, 1)?;
        if side == 0 {
            return Ok(out);
        }
        let columns = width.div_ceil(side);
        let mut tiles = vec![0.0f32; cone_tiles(width, height, side)];
        self.targets.starts.read(&mut tiles).enq().map_err(opencl)?;
        for y in 0..height {
            for x in 0..width {
                out[(y * width + x) as usize] = tiles[((y / side) * columns + x / side) as usize];
            }
        }
        Ok(out)
    }

    /// Launches the coarse pass over a `width` × `height` rendering: the
    /// start distance of every tile's rays (see `kernels/march.cl`).
    fn coarse_pass(&self, cone: &Kernel, width: u32, height: u32) -> Result<Event> {
        let side = self.source.cone_tile;
        let set = |a: ConeArg, v: i32| cone.set_arg(a.index(), v).map_err(opencl);
        #[allow(clippy::cast_possible_wrap)] // sizes are at most MAX_IMAGE_SIDE
        {
            set(ConeArg::Width, width as i32)?;
            set(ConeArg::Height, height as i32)?;
        }
        self.inputs.params.set_arg(cone, ConeArg::Params.index())?;
        self.inputs.camera.set_arg(cone, ConeArg::Camera.index())?;
        cone.set_arg(ConeArg::Starts.index(), &self.targets.starts)
            .map_err(opencl)?;
        let global = (
            width.div_ceil(side).next_multiple_of(8) as usize,
            height.div_ceil(side).next_multiple_of(8) as usize,
        );
        let mut event = Event::empty();
        // SAFETY: every buffer argument is alive in `self`, and the kernel
        // bounds-checks every work item against the grid of tiles.
        unsafe {
            cone.cmd()
                .global_work_size(global)
                .enew(&mut event)
                .enq()
                .map_err(opencl)?;
        }
        Ok(event)
    }

    /// Waits for `event` (a tile launch; the queue is in order, so every
    /// command before it too). Under a deadline the wait is a watchdog: a
    /// launch still running at twice the deadline (the frame's time, then
    /// as long again for the launches in flight) is given up, and the
    /// [`Error::Deadline`] to fail the frame with is returned: the caller
    /// marks the renderer abandoned. `(tiles, total)`: the tiles launched
    /// so far and the frame's, for the error.
    fn settle(
        &self,
        event: Option<&Event>,
        launched: Instant,
        (tiles, total): (usize, usize),
    ) -> Result<Option<Error>> {
        let Some(event) = event else { return Ok(None) };
        let Some(deadline) = self.options.deadline else {
            return event.wait_for().map(|()| None).map_err(opencl);
        };
        let mut pause = Duration::from_micros(50);
        while !event.is_complete().map_err(opencl)? {
            if launched.elapsed() >= deadline.saturating_mul(2) {
                return Ok(Some(Error::Deadline {
                    deadline,
                    tiles,
                    total,
                }));
            }
            std::thread::sleep(pause);
            pause = (pause * 2).min(Duration::from_millis(5));
        }
        Ok(None)
    }

    /// The error that stops a frame before its next tile, if any: a
    /// cancelled token, or a deadline that has passed.
    fn stop(&self, launched: Instant, tiles: usize, total: usize) -> Option<Error> {
        if self
            .options
            .cancel
            .as_ref()
            .is_some_and(CancelToken::is_cancelled)
        {
            return Some(Error::Cancelled { tiles, total });
        }
        match self.options.deadline {
            Some(deadline) if launched.elapsed() >= deadline => Some(Error::Deadline {
                deadline,
                tiles,
                total,
            }),
            _ => None,
        }
    }

    /// Uploads the frame's inputs, launches every tile and waits for them.
    /// Returns the kernel time and whether it comes from profiling events.
    fn run(&mut self, width: u32, height: u32, aovs: bool) -> Result<(Duration, bool)> {
        if self.abandoned {
            return Err(Error::OpenCl(
                "an earlier frame's launch was abandoned at its deadline and may still be \
                 running on the device: make a new renderer"
                    .into(),
            ));
        }
        self.timing = None;
        check_size(width, height)?;
        let view = self.viewport(width, height)?;
        // The kernel renders `width` × `height` pixels, each covering
        // `scale` × `scale` pixels of the image `view` maps.
        let scale = self.scale();
        let (width, height) = self.rendered_size(width, height);
        let info = &self.selected.info;
        let progressive = self.pass >= 0;
        if self.targets.fits(width, height, aovs, progressive) {
            let host = frame_host_bytes(info, width, height, aovs, None);
            check_host_memory(width, height, host, available_host_memory())?;
        } else {
            // Free the old buffers first so their memory can be reused.
            self.targets = Targets::new(&self.queue, 1, 1, false, false)?;
            check_device_memory(info, width, height, aovs, progressive)?;
            let device = Targets::bytes(width, height, aovs, progressive)
                .iter()
                .sum();
            let host = frame_host_bytes(info, width, height, aovs, Some(device));
            check_host_memory(width, height, host, available_host_memory())?;
            self.targets = Targets::new(&self.queue, width, height, aovs, progressive)
                .map_err(|e| too_large(width, height, &format!("{e}")))?;
        }
        check_frame_inputs(
            &view,
            self.scene.lights(),
            self.source.origin,
            self.source.precision.limits(),
        )?;
        self.inputs.upload(
            &self.queue,
            &self.kernel,
            &view.pack(self.source.origin, scale),
            &self.values,
            self.scene.lights(),
            self.source.origin,
        )?;
        let k = &self.kernel;
        let t = &self.targets;
        let set = |a: RenderArg, v: i32| k.set_arg(a.index(), v).map_err(opencl);
        #[allow(clippy::cast_possible_wrap)] // sizes are at most MAX_IMAGE_SIDE
        {
            set(RenderArg::Width, width as i32)?;
            set(RenderArg::Height, height as i32)?;
        }
        set(RenderArg::WriteAovs, i32::from(aovs))?;
        set(RenderArg::Pass, self.pass)?;
        set(RenderArg::RefineOnly, i32::from(self.refine_only))?;
        t.bind(k)?;
        let launched = Instant::now();
        let mut events: Vec<Event> = Vec::new();
        // The queue is in order: every tile starts after the coarse pass.
        let coarse = match &self.cone {
            Some(cone) => Some(self.coarse_pass(cone, width, height)?),
            None => None,
        };
        let brute = match &mut self.brute {
            Some(pass) => {
                let samples = self.options.quality.supersampling.max(1).pow(2);
                Some(pass.run(
                    &self.queue,
                    &self.inputs,
                    k,
                    (width, height, samples),
                    self.pass,
                )?)
            }
            None => None,
        };
        let (share, shares) = self.share;
        let mine = || {
            dispatch::tiles(width, height, self.options.tile_size)
                .enumerate()
                .filter(move |(i, _)| i % shares == share)
                .map(|(_, tile)| tile)
        };
        let total = mine().count();
        for tile in mine() {
            if let Some(stop) = self.stop(launched, events.len(), total) {
                // Let the tiles in flight finish before the buffers are
                // touched again.
                if let Some(e) = self.settle(events.last(), launched, (events.len(), total))? {
                    self.abandoned = true;
                    return Err(e);
                }
                return Err(stop);
            }
            let before = events.len().checked_sub(TILES_IN_FLIGHT);
            if let Some(e) =
                self.settle(before.map(|i| &events[i]), launched, (events.len(), total))?
            {
                self.abandoned = true;
                return Err(e);
            }
            #[allow(clippy::cast_possible_wrap)]
            {
                set(RenderArg::X0, tile.x as i32)?;
                set(RenderArg::Y0, tile.y as i32)?;
                set(RenderArg::TileWidth, tile.width as i32)?;
                set(RenderArg::TileHeight, tile.height as i32)?;
            }
            let global = dispatch::global_size(tile, self.local);
            // SAFETY: every buffer argument is alive in `self`, and the
            // kernel bounds-checks every work item against the tile.
            let mut event = Event::empty();
            unsafe {
                k.cmd()
                    .global_work_size(global)
                    .local_work_size(self.local)
                    .enew(&mut event)
                    .enq()
                    .map_err(opencl)?;
            }
            events.push(event);
        }
        if let Some(e) = self.settle(events.last(), launched, (total, total))? {
            self.abandoned = true;
            return Err(e);
        }
        self.queue.finish().map_err(opencl)?;
        events.extend(coarse);
        events.extend(brute);
        Ok(match profiled_time(&events) {
            Some(kernel) => (kernel, true),
            None => (launched.elapsed(), false),
        })
    }
}

/// An in-order queue with profiling enabled, or a plain one on a device
/// that refuses profiling.
fn profiling_queue(context: &Context, selected: &Selected) -> Result<Queue> {
    Queue::new(
        context,
        selected.device,
        Some(ocl::flags::QUEUE_PROFILING_ENABLE),
    )
    .or_else(|_| Queue::new(context, selected.device, None))
    .map_err(opencl)
}

/// The summed run time of finished kernel launches, from their profiling
/// events; `None` if any event has no profiling information.
fn profiled_time(events: &[Event]) -> Option<Duration> {
    let mut total = 0u64;
    for event in events {
        let at = |what| event.profiling_info(what).ok()?.time().ok();
        let (start, end) = (at(ProfilingInfo::Start)?, at(ProfilingInfo::End)?);
        total += end.checked_sub(start)?;
    }
    Some(Duration::from_nanos(total))
}

/// A clear error, before anything is allocated, for an image whose output
/// buffers the device cannot hold.
fn check_device_memory(
    info: &DeviceInfo,
    width: u32,
    height: u32,
    aovs: bool,
    progressive: bool,
) -> Result<()> {
    let wanted = Targets::bytes(width, height, aovs, progressive);
    let largest = wanted.iter().copied().max().unwrap_or(0);
    let total: u64 = wanted.iter().sum();
    let mib = |b: u64| b.div_ceil(1 << 20);
    if info.max_allocation > 0 && largest > info.max_allocation {
        return Err(too_large(
            width,
            height,
            &format!(
                "an output buffer needs {} MiB but `{}` allows {} MiB per buffer",
                mib(largest),
                info.label(),
                mib(info.max_allocation)
            ),
        ));
    }
    if info.global_memory > 0 && total > info.global_memory {
        return Err(too_large(
            width,
            height,
            &format!(
                "the outputs need {} MiB but `{}` has {} MiB",
                mib(total),
                info.label(),
                mib(info.global_memory)
            ),
        ));
    }
    Ok(())
}

/// Checks what a program's frames hand its kernel against the limits of
/// its precision: the dynamic values, and the camera and lights as packed
/// for a 1 × 1 image (each frame checks its own size again).
fn check_inputs(scene: &CompiledScene, values: &ParamValues, source: &KernelSource) -> Result<()> {
    let limits = source.precision.limits();
    values.check_within(limits)?;
    let view = Viewport::in_frame(scene.camera(), 1, 1, source.precision, source.origin)?;
    check_frame_inputs(&view, scene.lights(), source.origin, limits)
}

fn validate(options: &RenderOptions) -> Result<()> {
    options.quality.validate()?;
    options.effects.validate_for(options.quality.precision)?;
    if options.tile_size == 0 {
        return Err(Error::TileSize {
            value: options.tile_size,
        });
    }
    Ok(())
}

/// The light count is an `int` kernel argument.
fn check_light_count(lights: &[Light]) -> Result<()> {
    const MAX: usize = i32::MAX as usize;
    if lights.len() > MAX {
        return Err(Error::TooManyLights {
            count: lights.len(),
            max: MAX,
        });
    }
    Ok(())
}

fn check_size(width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(Error::Resolution {
            width,
            height,
            reason: "width and height must be at least 1".into(),
        });
    }
    if width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
        return Err(Error::Resolution {
            width,
            height,
            reason: format!("each side must be at most {MAX_IMAGE_SIDE} pixels"),
        });
    }
    Ok(())
}

fn too_large(width: u32, height: u32, why: &str) -> Error {
    Error::Resolution {
        width,
        height,
        reason: format!("too large for this device: {why}"),
    }
}

/// A zeroed host vector of `width × height × per_pixel` values, or a
/// resolution error if the memory is not available.
fn host_vec<T: Default + Clone>(width: u32, height: u32, per_pixel: usize) -> Result<Vec<T>> {
    let len = width as usize * height as usize * per_pixel;
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| {
        too_large(
            width,
            height,
            &format!(
                "cannot allocate {} MiB on the host",
                (len * std::mem::size_of::<T>()) >> 20
            ),
        )
    })?;
    v.resize(len, T::default());
    Ok(v)
}

/// The smallest side of the coarse pass's tiles
/// ([`Quality::cone_tile`](crate::quality::Quality::cone_tile)): the start
/// buffer is sized for it.
const MIN_CONE_TILE: u32 = 2;

/// Tiles of the coarse pass with sides of `side` pixels over a `width` ×
/// `height` rendering.
fn cone_tiles(width: u32, height: u32, side: u32) -> usize {
    width.div_ceil(side) as usize * height.div_ceil(side) as usize
}

/// The coarse pass's kernel, for a program that has one, with its
/// buffers bound ([`CONE_STARTS`] lists its arguments).
fn make_cone(
    program: &Program,
    queue: &Queue,
    inputs: &Inputs,
    t: &Targets,
    source: &KernelSource,
) -> Result<Option<Kernel>> {
    if source.cone_tile == 0 {
        return Ok(None);
    }
    let mut b = Kernel::builder();
    b.program(program)
        .name(CONE_KERNEL_NAME)
        .queue(queue.clone());
    for (arg, _) in CONE_STARTS {
        match arg {
            ConeArg::Params => inputs.params.push_arg(&mut b),
            ConeArg::Camera => inputs.camera.push_arg(&mut b),
            ConeArg::Width | ConeArg::Height => {
                b.arg(0i32);
            }
            ConeArg::Starts => {
                b.arg(&t.starts);
            }
        }
    }
    b.build().map(Some).map_err(opencl)
}

/// The brute-force pass (`brute_depths`) and the depths and evaluations it
/// leaves for `render_tile`, one per sample of a pass and pixel.
#[derive(Debug)]
struct BrutePass {
    kernel: Kernel,
    depths: Buffer<f32>,
    steps: Buffer<u32>,
    /// Samples the buffers hold.
    len: usize,
}

impl BrutePass {
    /// The pass of a program that marches inside shapes by brute force,
    /// with buffers of one sample until a frame sizes them.
    fn new(
        program: &Program,
        queue: &Queue,
        inputs: &Inputs,
        source: &KernelSource,
    ) -> Result<Option<Self>> {
        if !source.brute {
            return Ok(None);
        }
        let (depths, steps) = Self::buffers(queue, 1)?;
        let mut b = Kernel::builder();
        b.program(program)
            .name(BRUTE_KERNEL_NAME)
            .queue(queue.clone());
        for (arg, _) in BRUTE_DEPTHS {
            match arg {
                BruteArg::Params => inputs.params.push_arg(&mut b),
                BruteArg::Camera => inputs.camera.push_arg(&mut b),
                BruteArg::Width | BruteArg::Height | BruteArg::Pass => {
                    b.arg(0i32);
                }
                BruteArg::Depths => {
                    b.arg(&depths);
                }
                BruteArg::Steps => {
                    b.arg(&steps);
                }
            }
        }
        let kernel = b.build().map_err(opencl)?;
        Ok(Some(BrutePass {
            kernel,
            depths,
            steps,
            len: 1,
        }))
    }

    fn buffers(queue: &Queue, len: usize) -> Result<(Buffer<f32>, Buffer<u32>)> {
        let make = || {
            Buffer::builder()
                .queue(queue.clone())
                .flags(MemFlags::new().read_write())
                .len(len.max(1))
        };
        Ok((
            make().build().map_err(opencl)?,
            Buffer::<u32>::builder()
                .queue(queue.clone())
                .flags(MemFlags::new().read_write())
                .len(len.max(1))
                .build()
                .map_err(opencl)?,
        ))
    }

    /// Launches the pass over `samples` samples of every pixel of a
    /// `width` × `height` rendering, and points `render`'s arguments at
    /// what it leaves.
    fn run(
        &mut self,
        queue: &Queue,
        inputs: &Inputs,
        render: &Kernel,
        (width, height, samples): (u32, u32, u32),
        pass: i32,
    ) -> Result<Event> {
        let len = width as usize * height as usize * samples as usize;
        if self.len < len {
            let (depths, steps) =
                Self::buffers(queue, len).map_err(|e| too_large(width, height, &format!("{e}")))?;
            self.depths = depths;
            self.steps = steps;
            self.len = len;
        }
        let k = &self.kernel;
        let set = |a: BruteArg, v: i32| k.set_arg(a.index(), v).map_err(opencl);
        #[allow(clippy::cast_possible_wrap)] // sizes are at most MAX_IMAGE_SIDE
        {
            set(BruteArg::Width, width as i32)?;
            set(BruteArg::Height, height as i32)?;
        }
        set(BruteArg::Pass, pass)?;
        inputs.params.set_arg(k, BruteArg::Params.index())?;
        inputs.camera.set_arg(k, BruteArg::Camera.index())?;
        k.set_arg(BruteArg::Depths.index(), &self.depths)
            .map_err(opencl)?;
        k.set_arg(BruteArg::Steps.index(), &self.steps)
            .map_err(opencl)?;
        render
            .set_arg(RenderArg::BruteDepths.index(), &self.depths)
            .map_err(opencl)?;
        render
            .set_arg(RenderArg::BruteSteps.index(), &self.steps)
            .map_err(opencl)?;
        let global = (
            width.next_multiple_of(8) as usize,
            height.next_multiple_of(8) as usize,
        );
        let mut event = Event::empty();
        // SAFETY: every buffer argument is alive in `self` or `inputs`, and
        // the kernel bounds-checks every work item against the image.
        unsafe {
            k.cmd()
                .global_work_size(global)
                .enew(&mut event)
                .enq()
                .map_err(opencl)?;
        }
        Ok(event)
    }
}

/// The kernel with every argument bound: buffers to the current ones,
/// scalars to 0 until a frame sets them. Positions come from
/// [`RENDER_TILE`], the one list of `render_tile`'s arguments.
fn make_kernel(program: &Program, queue: &Queue, inputs: &Inputs, t: &Targets) -> Result<Kernel> {
    let mut b = Kernel::builder();
    b.program(program).name(KERNEL_NAME).queue(queue.clone());
    for (arg, _) in RENDER_TILE {
        match arg {
            RenderArg::Params => inputs.params.push_arg(&mut b),
            RenderArg::Camera => inputs.camera.push_arg(&mut b),
            RenderArg::Lights => inputs.lights.push_arg(&mut b),
            RenderArg::Rgba => {
                b.arg(&t.rgba);
            }
            RenderArg::Depth => {
                b.arg(&t.depth);
            }
            RenderArg::Hit => {
                b.arg(&t.hit);
            }
            RenderArg::Normals => {
                b.arg(&t.normals);
            }
            RenderArg::Steps => {
                b.arg(&t.steps);
            }
            RenderArg::Evaluations => {
                b.arg(&t.evaluations);
            }
            RenderArg::Starts => {
                b.arg(&t.starts);
            }
            RenderArg::Accumulation => {
                b.arg(&t.accumulation);
            }
            RenderArg::Pass => {
                b.arg(-1i32);
            }
            RenderArg::Refine => {
                b.arg(&t.refine);
            }
            // Stand-ins of the right types until a brute-force pass binds
            // its own (only its programs read them).
            RenderArg::BruteDepths => {
                b.arg(&t.starts);
            }
            RenderArg::BruteSteps => {
                b.arg(&t.steps);
            }
            RenderArg::LightCount
            | RenderArg::Width
            | RenderArg::Height
            | RenderArg::X0
            | RenderArg::Y0
            | RenderArg::TileWidth
            | RenderArg::TileHeight
            | RenderArg::WriteAovs
            | RenderArg::RefineOnly => {
                b.arg(0i32);
            }
        }
    }
    b.build().map_err(opencl)
}

/// The work-group shape: 8 × 8 shrunk to what the device and the compiled
/// kernel allow.
fn local_size(kernel: &Kernel, selected: &Selected) -> Result<(usize, usize)> {
    use ocl::enums::{KernelWorkGroupInfo, KernelWorkGroupInfoResult};
    let mut max = selected.info.max_work_group_size;
    if let Ok(KernelWorkGroupInfoResult::WorkGroupSize(n)) =
        kernel.wg_info(selected.device, KernelWorkGroupInfo::WorkGroupSize)
    {
        max = max.min(n);
    }
    Ok(dispatch::local_size(max))
}

/// The per-frame inputs: dynamic parameters, camera and lights.
#[derive(Debug)]
struct Inputs {
    precision: Precision,
    params: RealBuffer,
    camera: RealBuffer,
    lights: RealBuffer,
}

impl Inputs {
    /// The buffers for `source`: its parameter buffer holds the dynamic
    /// values, which each frame rewrites, then the program's constants.
    fn new(
        queue: &Queue,
        source: &KernelSource,
        values: &ParamValues,
        lights: &[Light],
    ) -> Result<Self> {
        let precision = source.precision;
        Ok(Inputs {
            precision,
            params: RealBuffer::new(queue, precision, &source.param_buffer(values.as_slice()))?,
            camera: RealBuffer::new(queue, precision, &[0.0; camera::LEN])?,
            lights: RealBuffer::new(queue, precision, &pack_lights(lights, DVec3::ZERO))?,
        })
    }

    /// Writes this frame's values; a light list of a new length gets a new
    /// buffer (and a new kernel argument), never a new program.
    fn upload(
        &mut self,
        queue: &Queue,
        kernel: &Kernel,
        camera: &[f64; camera::LEN],
        values: &ParamValues,
        lights: &[Light],
        origin: DVec3,
    ) -> Result<()> {
        // The dynamic values only: the constants after them stay.
        self.params.write(values.as_slice())?;
        self.camera.write(camera)?;
        let packed = pack_lights(lights, origin);
        if packed.len() == self.lights.len() {
            self.lights.write(&packed)?;
        } else {
            self.lights = RealBuffer::new(queue, self.precision, &packed)?;
        }
        self.params.set_arg(kernel, RenderArg::Params.index())?;
        self.camera.set_arg(kernel, RenderArg::Camera.index())?;
        self.lights.set_arg(kernel, RenderArg::Lights.index())?;
        check_light_count(lights)?;
        #[allow(clippy::cast_possible_truncation, clippy::cast_possible_wrap)] // checked above
        let count = lights.len() as i32;
        kernel
            .set_arg(RenderArg::LightCount.index(), count)
            .map_err(opencl)
    }
}

/// The per-pixel outputs on the device. Without AOVs, the AOV buffers hold
/// one element each (the kernel does not write them); so does the
/// accumulation buffer outside progressive rendering.
#[derive(Debug)]
struct Targets {
    width: u32,
    height: u32,
    aovs: bool,
    progressive: bool,
    rgba: Buffer<u8>,
    depth: Buffer<f32>,
    hit: Buffer<u8>,
    normals: Buffer<f32>,
    steps: Buffer<u32>,
    evaluations: Buffer<u32>,
    /// The coarse pass's start distances, one per tile of at least 2 × 2
    /// pixels (see [`cone_tiles`]).
    starts: Buffer<f32>,
    /// Progressive rendering's sums of linear colours, an RGB and a spare
    /// `f32` per pixel.
    accumulation: Buffer<f32>,
    /// The pixels adaptive supersampling refines, a byte per pixel.
    refine: Buffer<u8>,
}

impl Targets {
    fn new(queue: &Queue, width: u32, height: u32, aovs: bool, progressive: bool) -> Result<Self> {
        let pixels = width as usize * height as usize;
        let aov_pixels = if aovs { pixels } else { 1 };
        let summed_pixels = if progressive { pixels } else { 1 };
        Ok(Targets {
            width,
            height,
            aovs,
            progressive,
            rgba: output(queue, pixels * 4)?,
            depth: output(queue, aov_pixels)?,
            hit: output(queue, aov_pixels)?,
            normals: output(queue, aov_pixels * 3)?,
            steps: output(queue, aov_pixels)?,
            evaluations: output(queue, aov_pixels)?,
            starts: Buffer::builder()
                .queue(queue.clone())
                .flags(MemFlags::new().read_write())
                .len(cone_tiles(width, height, MIN_CONE_TILE).max(1))
                .build()
                .map_err(opencl)?,
            accumulation: Buffer::builder()
                .queue(queue.clone())
                .flags(MemFlags::new().read_write())
                .len(summed_pixels * 4)
                .build()
                .map_err(opencl)?,
            refine: Buffer::builder()
                .queue(queue.clone())
                .flags(MemFlags::new().read_only())
                .len(summed_pixels)
                .build()
                .map_err(opencl)?,
        })
    }

    /// Bytes of each output buffer for an image.
    fn bytes(width: u32, height: u32, aovs: bool, progressive: bool) -> Vec<u64> {
        let pixels = u64::from(width) * u64::from(height);
        let aov = if aovs { pixels } else { 1 };
        let summed = if progressive { pixels } else { 1 };
        let starts = cone_tiles(width, height, MIN_CONE_TILE) as u64 * 4;
        vec![
            pixels * 4,
            aov * 4,
            aov,
            aov * 12,
            aov * 4,
            aov * 4,
            starts,
            summed * 16,
            summed,
        ]
    }

    /// Binds the output buffers to their arguments.
    fn bind(&self, k: &Kernel) -> Result<()> {
        k.set_arg(RenderArg::Rgba.index(), &self.rgba)
            .map_err(opencl)?;
        k.set_arg(RenderArg::Depth.index(), &self.depth)
            .map_err(opencl)?;
        k.set_arg(RenderArg::Hit.index(), &self.hit)
            .map_err(opencl)?;
        k.set_arg(RenderArg::Normals.index(), &self.normals)
            .map_err(opencl)?;
        k.set_arg(RenderArg::Steps.index(), &self.steps)
            .map_err(opencl)?;
        k.set_arg(RenderArg::Evaluations.index(), &self.evaluations)
            .map_err(opencl)?;
        k.set_arg(RenderArg::Starts.index(), &self.starts)
            .map_err(opencl)?;
        k.set_arg(RenderArg::Accumulation.index(), &self.accumulation)
            .map_err(opencl)?;
        k.set_arg(RenderArg::Refine.index(), &self.refine)
            .map_err(opencl)?;
        // Stand-ins until a brute-force pass binds its own.
        k.set_arg(RenderArg::BruteDepths.index(), &self.starts)
            .map_err(opencl)?;
        k.set_arg(RenderArg::BruteSteps.index(), &self.steps)
            .map_err(opencl)
    }

    fn fits(&self, width: u32, height: u32, aovs: bool, progressive: bool) -> bool {
        self.width == width
            && self.height == height
            && (self.aovs || !aovs)
            && (self.progressive || !progressive)
    }
}

fn output<T: ocl::OclPrm>(queue: &Queue, len: usize) -> Result<Buffer<T>> {
    Buffer::builder()
        .queue(queue.clone())
        .flags(MemFlags::new().write_only())
        .len(len.max(1))
        .build()
        .map_err(opencl)
}

/// A frame at the rendered resolution: its colours, and its depth where it
/// is to be scaled up.
struct Rendered {
    image: RgbaImage,
    depth: Option<Vec<f32>>,
}

impl Rendered {
    /// The image at `width` × `height`, scaled up by `scale` (see
    /// `upscale`).
    fn scaled(self, width: u32, height: u32, scale: u32) -> RgbaImage {
        match self.depth {
            Some(depth) if scale > 1 => upscale::image(&self.image, &depth, width, height, scale),
            _ => self.image,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::device::DeviceKind;
    use crate::render::device::tests::fake;

    #[test]
    fn oversized_outputs_are_refused_with_the_numbers() {
        let mut device = fake("Small", "gpu", DeviceKind::Gpu);
        device.max_allocation = 64 << 20;
        device.global_memory = 128 << 20;
        // 4K colour: 32 MiB in one buffer.
        check_device_memory(&device, 3840, 2160, false, false).unwrap();
        // 8K colour: 127 MiB in one buffer.
        let err = check_device_memory(&device, 7680, 4320, false, false).unwrap_err();
        let text = err.to_string();
        assert!(
            matches!(err, Error::Resolution { width: 7680, .. }),
            "{text}"
        );
        assert!(
            text.contains("127 MiB") && text.contains("64 MiB per buffer"),
            "{text}"
        );
        // 4K with AOVs: 95 MiB of normals.
        let err = check_device_memory(&device, 3840, 2160, true, false).unwrap_err();
        assert!(err.to_string().contains("95 MiB"), "{err}");
        device.max_allocation = 1 << 30;
        let err = check_device_memory(&device, 3840, 2160, true, false).unwrap_err();
        assert!(
            err.to_string()
                .contains("238 MiB but `Small / gpu` has 128 MiB"),
            "{err}"
        );
    }

    #[test]
    fn sizes_are_checked_before_anything_else() {
        assert!(check_size(1, 1).is_ok());
        assert!(check_size(MAX_IMAGE_SIDE, 1).is_ok());
        assert!(matches!(check_size(0, 5), Err(Error::Resolution { .. })));
        assert!(matches!(
            check_size(MAX_IMAGE_SIDE + 1, 5),
            Err(Error::Resolution { .. })
        ));
    }
}
