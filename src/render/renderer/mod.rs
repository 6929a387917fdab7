//! The renderer: one scene's program on one device, and the buffers that
//! carry the per-frame inputs (parameters, camera, lights) and outputs.

use std::time::{Duration, Instant};

use glam::DVec3;
use image::RgbaImage;
use ocl::enums::ProfilingInfo;
use ocl::{Buffer, Context, Event, Kernel, MemFlags, Program, Queue};

use super::adaptive::{self, AdaptiveFrame, EdgeThresholds};
use super::aov::{Frame, Layers, Outputs};
use super::buffer::RealBuffer;
use super::cancel::CancelToken;
use super::device::{self, DeviceInfo, DeviceSelector, Selected, opencl};
use super::dispatch::{self, DEFAULT_TILE_SIZE, MAX_IMAGE_SIDE};
use super::memory::{available_host_memory, check_host_memory, frame_host_bytes};
use super::program::{self, BuildInfo};
use super::upscale;
use super::viewport::{Viewport, check_frame_inputs, pack_lights};
use crate::codegen::interface::{
    BRUTE_DEPTHS, BruteArg, CONE_STARTS, ConeArg, Field, RENDER_TILE, RenderArg, camera, layer,
};
use crate::codegen::{self, KernelSource};
use crate::error::{Error, Result};
use crate::ir::{CompiledScene, ParamValues};
use crate::quality::{Effects, Precision, Quality};
use crate::scene::{Camera, Environment, Light, Scene};
use crate::view::FrameTiming;

mod converge;
mod cost;
mod frame;
mod launch;

pub use converge::{ConvergedFrame, StopRule};
pub use cost::EvaluationCost;

use launch::*;

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
    /// What the passes wrote: the image (on every device), or every
    /// output (on this renderer's own).
    outputs: Outputs,
    /// The result once the passes reach the most samples per pixel.
    converged: Option<Converged>,
}

/// A converged progressive result, returned again by later calls.
#[derive(Debug, Clone)]
enum Converged {
    Image(RgbaImage),
    Frame(Box<Frame>),
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
        environment: scene.environment().is_some(),
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
        let source = generate(&scene, &functions, options)?;
        let values = scene.default_values();
        check_inputs(&scene, &values, &source)?;
        let selected = device::select(&options.device)?;
        let context = program::context(&selected)?;
        let queue = profiling_queue(&context, &selected)?;
        let inputs = Inputs::new(
            &queue,
            &source,
            &values,
            scene.lights(),
            scene.environment(),
        )?;
        let targets = Targets::new(&queue, 1, 1, Outputs::Aovs, false)?;
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

    /// The most samples per pixel progressive rendering takes: past it the
    /// sums, kept in `f32`, would round away what a further sample adds.
    pub const MAX_PROGRESSIVE_SAMPLES: u32 = 4096;

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

    /// Every dynamic parameter's current value.
    #[must_use]
    pub fn values(&self) -> &ParamValues {
        &self.values
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

    /// Replaces the environment light, or removes it with `None`. A new
    /// image, rotation or intensity is a new buffer; only adding the first
    /// environment or removing the last changes the program.
    ///
    /// # Errors
    /// [`Error::Environment`] for one that does not validate; else as
    /// [`Renderer::set_effects`].
    pub fn set_environment(&mut self, environment: Option<Environment>) -> Result<()> {
        let had = self.scene.environment().is_some();
        self.scene.set_environment(environment.clone())?;
        self.inputs.environment =
            launch::environment_buffer(&self.queue, self.scene.environment())?;
        if had == environment.is_some() {
            self.kernel
                .set_arg(RenderArg::Environment.index(), &self.inputs.environment)
                .map_err(device::opencl)?;
        } else {
            self.reprogram(self.options.clone())?;
        }
        self.progress = None;
        self.for_partners(|p| p.set_environment(environment.clone()))
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
        let inputs_changed = source.precision != self.source.precision
            || source.constants != self.source.constants
            || source.tables != self.source.tables;
        if inputs_changed {
            self.inputs = Inputs::new(
                &self.queue,
                &source,
                &self.values,
                self.scene.lights(),
                self.scene.environment(),
            )?;
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
        check_device_memory(&device, 3840, 2160, Outputs::Image, false).unwrap();
        // 8K colour: 127 MiB in one buffer.
        let err = check_device_memory(&device, 7680, 4320, Outputs::Image, false).unwrap_err();
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
        let err = check_device_memory(&device, 3840, 2160, Outputs::Aovs, false).unwrap_err();
        assert!(err.to_string().contains("95 MiB"), "{err}");
        device.max_allocation = 1 << 30;
        let err = check_device_memory(&device, 3840, 2160, Outputs::Aovs, false).unwrap_err();
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
