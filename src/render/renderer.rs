//! The renderer: one scene's program on one device, and the buffers that
//! carry the per-frame inputs (parameters, camera, lights) and outputs.

use std::time::{Duration, Instant};

use glam::DVec3;
use image::RgbaImage;
use ocl::enums::ProfilingInfo;
use ocl::{Buffer, Context, Event, Kernel, MemFlags, Program, Queue};

use super::aov::Frame;
use super::buffer::RealBuffer;
use super::device::{self, DeviceInfo, DeviceSelector, Selected, opencl};
use super::dispatch::{self, DEFAULT_TILE_SIZE, MAX_IMAGE_SIDE};
use super::program::{self, BuildInfo, ProgramSource};
use super::viewport::{Viewport, pack_lights};
use crate::codegen;
use crate::error::{Error, Result};
use crate::ir::{Ir, ParamValues};
use crate::quality::{Effects, Precision, Quality};
use crate::scene::{Camera, Light, Scene};
use crate::timing::FrameTiming;

/// Everything that decides how a scene is rendered, apart from the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Accuracy knobs (compiled into the program).
    pub quality: Quality,
    /// Lighting effects (compiled into the program).
    pub effects: Effects,
    /// Which OpenCL device to use.
    pub device: DeviceSelector,
    /// Side of the square tiles the image is launched in, in pixels.
    pub tile_size: u32,
}

impl Default for RenderOptions {
    /// Production quality, default effects, automatic device, 256-pixel
    /// tiles.
    fn default() -> Self {
        RenderOptions {
            quality: Quality::default(),
            effects: Effects::default(),
            device: DeviceSelector::default(),
            tile_size: DEFAULT_TILE_SIZE,
        }
    }
}

/// The kernel's argument positions (see `render_tile` in `march.cl`).
mod arg {
    pub const PARAMS: u32 = 0;
    pub const CAMERA: u32 = 1;
    pub const LIGHTS: u32 = 2;
    pub const LIGHT_COUNT: u32 = 3;
    pub const WIDTH: u32 = 4;
    pub const HEIGHT: u32 = 5;
    pub const X0: u32 = 6;
    pub const Y0: u32 = 7;
    pub const TILE_W: u32 = 8;
    pub const TILE_H: u32 = 9;
    pub const WRITE_AOVS: u32 = 10;
    pub const RGBA: u32 = 11;
    pub const DEPTH: u32 = 12;
    pub const HIT: u32 = 13;
    pub const NORMALS: u32 = 14;
    pub const STEPS: u32 = 15;
    pub const EVALUATIONS: u32 = 16;
}

const KERNEL_NAME: &str = "render_tile";

/// Renders one scene on one OpenCL device.
///
/// The program is compiled once (or taken from the process-wide cache);
/// changing dynamic parameters, the camera or the lights between frames
/// only rewrites small buffers. Changing the quality or effects generates
/// a new program.
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
    scene: Scene,
    options: RenderOptions,
    values: ParamValues,
    source: ProgramSource,
    build: BuildInfo,
    builds: u64,
    kernel: Kernel,
    local: (usize, usize),
    inputs: Inputs,
    targets: Targets,
    timing: Option<FrameTiming>,
}

/// Generates the program for a scene. This is the one place that turns a
/// scene into OpenCL C.
fn generate(scene: &Scene, options: &RenderOptions) -> Result<ProgramSource> {
    let options = codegen::Options {
        quality: options.quality,
        effects: options.effects,
        target: codegen::Target::Render,
    };
    codegen::emit(scene, &options).map(|k| ProgramSource {
        source: k.source,
        precision: k.precision,
        origin: k.origin,
    })
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

    /// A renderer for `scene` with explicit options.
    ///
    /// # Errors
    /// Scene, quality and effects validation errors; [`Error::NoPlatform`],
    /// [`Error::NoDevice`]; [`Error::Fp64Unsupported`] for `F64` on a device
    /// without it; [`Error::Build`] with the compiler log and the source.
    pub fn with_options(scene: &Scene, options: &RenderOptions) -> Result<Self> {
        validate(scene, options)?;
        let source = generate(scene, options)?;
        Self::with_source(scene, options, source)
    }

    /// A renderer running a given program for `scene`: the source must meet
    /// the contract in [`crate::render`]. The scene supplies the dynamic
    /// parameters, the camera and the lights.
    ///
    /// # Errors
    /// As [`Renderer::with_options`].
    pub fn with_source(
        scene: &Scene,
        options: &RenderOptions,
        source: ProgramSource,
    ) -> Result<Self> {
        validate(scene, options)?;
        let geometry = scene.geometry.as_ref().ok_or(Error::EmptyScene)?;
        let values = Ir::lower(geometry)?.default_values();
        let selected = device::select(&options.device)?;
        let context = program::context(&selected)?;
        let queue = profiling_queue(&context, &selected)?;
        let inputs = Inputs::new(&queue, source.precision, &values, &scene.lights)?;
        let targets = Targets::new(&queue, 1, 1, true)?;
        let (program, build, compiled) = program::build(&selected, &context, &source)?;
        let kernel = make_kernel(&program, &queue, &inputs, &targets)?;
        let local = local_size(&kernel, &selected)?;
        Ok(Renderer {
            selected,
            context,
            queue,
            scene: scene.clone(),
            options: options.clone(),
            values,
            source,
            build,
            builds: u64::from(compiled),
            kernel,
            local,
            inputs,
            targets,
            timing: None,
        })
    }

    /// Renders a `width` × `height` image.
    ///
    /// # Errors
    /// [`Error::Resolution`] for a zero side, a side above 32768 or an image
    /// whose buffers cannot be allocated; [`Error::OpenCl`] if the device
    /// fails.
    pub fn render(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        let start = Instant::now();
        let kernel = self.run(width, height, false)?;
        let read = Instant::now();
        let mut rgba = host_vec::<u8>(width, height, 4)?;
        self.targets.rgba.read(&mut rgba).enq().map_err(opencl)?;
        self.record_timing(start, read, kernel);
        Ok(RgbaImage::from_raw(width, height, rgba).expect("buffer has width * height * 4 bytes"))
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
        self.record_timing(start, read, kernel);
        Ok(Frame {
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
        })
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
    /// [`Error::UnknownParam`], or the parameter's range error.
    pub fn set_param(&mut self, name: &str, value: f64) -> Result<()> {
        self.values.set(name, value)
    }

    /// The current value of a dynamic parameter.
    #[must_use]
    pub fn param(&self, name: &str) -> Option<f64> {
        self.values.get(name)
    }

    /// Moves the camera (no recompilation).
    ///
    /// # Errors
    /// [`Error::Camera`] if the camera is degenerate.
    pub fn set_camera(&mut self, camera: Camera) -> Result<()> {
        camera.validate()?;
        self.scene.camera = camera;
        Ok(())
    }

    /// The camera.
    #[must_use]
    pub fn camera(&self) -> &Camera {
        &self.scene.camera
    }

    /// Replaces the lights, any number of them. The lights and their count
    /// are kernel arguments, so this recompiles nothing — unless the
    /// program generator specialises on the lights, in which case the
    /// program for the new set is built (or taken from the cache).
    ///
    /// # Errors
    /// The first invalid light, as [`Scene::validate`] reports it; build
    /// errors as for [`Renderer::with_options`].
    pub fn set_lights(&mut self, lights: impl IntoIterator<Item = Light>) -> Result<()> {
        let scene = self.scene.clone().with_lights(lights);
        scene.validate()?;
        let source = generate(&scene, &self.options)?;
        self.scene = scene;
        if source != self.source {
            self.load(source)?;
        }
        Ok(())
    }

    /// The lights.
    #[must_use]
    pub fn lights(&self) -> &[Light] {
        &self.scene.lights
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
        self.reprogram(options)
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
        self.reprogram(options)
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
    pub fn source(&self) -> &ProgramSource {
        &self.source
    }

    /// The viewport of the current camera for a `width` × `height` image:
    /// the exact rays and hit thresholds the kernel uses.
    ///
    /// # Errors
    /// As [`Viewport::new`].
    pub fn viewport(&self, width: u32, height: u32) -> Result<Viewport> {
        Viewport::in_frame(
            &self.scene.camera,
            width,
            height,
            self.source.precision,
            self.source.origin,
        )
    }

    fn reprogram(&mut self, options: RenderOptions) -> Result<()> {
        validate(&self.scene, &options)?;
        let source = generate(&self.scene, &options)?;
        self.load(source)?;
        self.options = options;
        Ok(())
    }

    /// Switches to the program `source` (built now or taken from the
    /// cache).
    fn load(&mut self, source: ProgramSource) -> Result<()> {
        let (program, build, compiled) = program::build(&self.selected, &self.context, &source)?;
        let precision_changed = source.precision != self.source.precision;
        if precision_changed {
            self.inputs = Inputs::new(
                &self.queue,
                source.precision,
                &self.values,
                &self.scene.lights,
            )?;
        }
        self.kernel = make_kernel(&program, &self.queue, &self.inputs, &self.targets)?;
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

    /// Uploads the frame's inputs, launches every tile and waits for them.
    /// Returns the kernel time and whether it comes from profiling events.
    fn run(&mut self, width: u32, height: u32, aovs: bool) -> Result<(Duration, bool)> {
        self.timing = None;
        check_size(width, height)?;
        let view = self.viewport(width, height)?;
        if !self.targets.fits(width, height, aovs) {
            // Free the old buffers first so their memory can be reused.
            self.targets = Targets::new(&self.queue, 1, 1, false)?;
            check_device_memory(&self.selected.info, width, height, aovs)?;
            self.targets = Targets::new(&self.queue, width, height, aovs)
                .map_err(|e| too_large(width, height, &format!("{e}")))?;
        }
        self.inputs.upload(
            &self.queue,
            &self.kernel,
            &view,
            &self.values,
            &self.scene.lights,
            self.source.origin,
        )?;
        let k = &self.kernel;
        let t = &self.targets;
        let set = |i: u32, v: i32| k.set_arg(i, v).map_err(opencl);
        #[allow(clippy::cast_possible_wrap)] // sizes are at most MAX_IMAGE_SIDE
        {
            set(arg::WIDTH, width as i32)?;
            set(arg::HEIGHT, height as i32)?;
        }
        set(arg::WRITE_AOVS, i32::from(aovs))?;
        k.set_arg(arg::RGBA, &t.rgba).map_err(opencl)?;
        k.set_arg(arg::DEPTH, &t.depth).map_err(opencl)?;
        k.set_arg(arg::HIT, &t.hit).map_err(opencl)?;
        k.set_arg(arg::NORMALS, &t.normals).map_err(opencl)?;
        k.set_arg(arg::STEPS, &t.steps).map_err(opencl)?;
        k.set_arg(arg::EVALUATIONS, &t.evaluations)
            .map_err(opencl)?;
        let launched = Instant::now();
        let mut events = Vec::new();
        for tile in dispatch::tiles(width, height, self.options.tile_size) {
            #[allow(clippy::cast_possible_wrap)]
            {
                set(arg::X0, tile.x as i32)?;
                set(arg::Y0, tile.y as i32)?;
                set(arg::TILE_W, tile.width as i32)?;
                set(arg::TILE_H, tile.height as i32)?;
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
        self.queue.finish().map_err(opencl)?;
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
fn check_device_memory(info: &DeviceInfo, width: u32, height: u32, aovs: bool) -> Result<()> {
    let wanted = Targets::bytes(width, height, aovs);
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

fn validate(scene: &Scene, options: &RenderOptions) -> Result<()> {
    scene.validate()?;
    options.quality.validate()?;
    options.effects.validate()?;
    if options.tile_size == 0 {
        return Err(Error::Quality {
            setting: "tile_size",
            value: 0.0,
            expected: ">= 1".into(),
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

fn make_kernel(program: &Program, queue: &Queue, inputs: &Inputs, t: &Targets) -> Result<Kernel> {
    let mut b = Kernel::builder();
    b.program(program).name(KERNEL_NAME).queue(queue.clone());
    inputs.params.push_arg(&mut b);
    inputs.camera.push_arg(&mut b);
    inputs.lights.push_arg(&mut b);
    for _ in arg::LIGHT_COUNT..=arg::WRITE_AOVS {
        b.arg(0i32);
    }
    b.arg(&t.rgba)
        .arg(&t.depth)
        .arg(&t.hit)
        .arg(&t.normals)
        .arg(&t.steps)
        .arg(&t.evaluations);
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
    fn new(
        queue: &Queue,
        precision: Precision,
        values: &ParamValues,
        lights: &[Light],
    ) -> Result<Self> {
        Ok(Inputs {
            precision,
            params: RealBuffer::new(queue, precision, values.as_slice())?,
            camera: RealBuffer::new(queue, precision, &[0.0; super::viewport::CAMERA_LEN])?,
            lights: RealBuffer::new(queue, precision, &pack_lights(lights, DVec3::ZERO))?,
        })
    }

    /// Writes this frame's values; a light list of a new length gets a new
    /// buffer (and a new kernel argument), never a new program.
    fn upload(
        &mut self,
        queue: &Queue,
        kernel: &Kernel,
        view: &Viewport,
        values: &ParamValues,
        lights: &[Light],
        origin: DVec3,
    ) -> Result<()> {
        self.params.write(values.as_slice())?;
        self.camera.write(&view.pack(origin))?;
        let packed = pack_lights(lights, origin);
        if packed.len() == self.lights.len() {
            self.lights.write(&packed)?;
        } else {
            self.lights = RealBuffer::new(queue, self.precision, &packed)?;
        }
        self.params.set_arg(kernel, arg::PARAMS)?;
        self.camera.set_arg(kernel, arg::CAMERA)?;
        self.lights.set_arg(kernel, arg::LIGHTS)?;
        let count =
            i32::try_from(lights.len()).map_err(|_| Error::OpenCl("too many lights".into()))?;
        kernel.set_arg(arg::LIGHT_COUNT, count).map_err(opencl)
    }
}

/// The per-pixel outputs on the device. Without AOVs, the AOV buffers hold
/// one element each (the kernel does not write them).
#[derive(Debug)]
struct Targets {
    width: u32,
    height: u32,
    aovs: bool,
    rgba: Buffer<u8>,
    depth: Buffer<f32>,
    hit: Buffer<u8>,
    normals: Buffer<f32>,
    steps: Buffer<u32>,
    evaluations: Buffer<u32>,
}

impl Targets {
    fn new(queue: &Queue, width: u32, height: u32, aovs: bool) -> Result<Self> {
        let pixels = width as usize * height as usize;
        let aov_pixels = if aovs { pixels } else { 1 };
        Ok(Targets {
            width,
            height,
            aovs,
            rgba: output(queue, pixels * 4)?,
            depth: output(queue, aov_pixels)?,
            hit: output(queue, aov_pixels)?,
            normals: output(queue, aov_pixels * 3)?,
            steps: output(queue, aov_pixels)?,
            evaluations: output(queue, aov_pixels)?,
        })
    }

    /// Bytes of each output buffer for an image.
    fn bytes(width: u32, height: u32, aovs: bool) -> Vec<u64> {
        let pixels = u64::from(width) * u64::from(height);
        let aov = if aovs { pixels } else { 1 };
        vec![pixels * 4, aov * 4, aov, aov * 12, aov * 4, aov * 4]
    }

    fn fits(&self, width: u32, height: u32, aovs: bool) -> bool {
        self.width == width && self.height == height && (self.aovs || !aovs)
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
        check_device_memory(&device, 3840, 2160, false).unwrap();
        // 8K colour: 127 MiB in one buffer.
        let err = check_device_memory(&device, 7680, 4320, false).unwrap_err();
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
        let err = check_device_memory(&device, 3840, 2160, true).unwrap_err();
        assert!(err.to_string().contains("95 MiB"), "{err}");
        device.max_allocation = 1 << 30;
        let err = check_device_memory(&device, 3840, 2160, true).unwrap_err();
        assert!(
            err.to_string()
                .contains("230 MiB but `Small / gpu` has 128 MiB"),
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
