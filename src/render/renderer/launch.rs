//! What a launch needs: kernels and their arguments, the input and output
//! buffers, the cone and brute-force passes, and the checks of sizes and
//! memory made before anything is allocated.

use super::*;

/// An in-order queue with profiling enabled, or a plain one on a device
/// that refuses profiling.
pub(super) fn profiling_queue(context: &Context, selected: &Selected) -> Result<Queue> {
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
pub(super) fn profiled_time(events: &[Event]) -> Option<Duration> {
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
pub(super) fn check_device_memory(
    info: &DeviceInfo,
    width: u32,
    height: u32,
    outputs: Outputs,
    progressive: bool,
) -> Result<()> {
    let wanted = Targets::bytes(width, height, outputs, progressive);
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
pub(super) fn check_inputs(
    scene: &CompiledScene,
    values: &ParamValues,
    source: &KernelSource,
) -> Result<()> {
    let limits = source.precision.limits();
    values.check_within(limits)?;
    let view = Viewport::in_frame(scene.camera(), 1, 1, source.precision, source.origin)?;
    check_frame_inputs(&view, scene.lights(), source.origin, limits)
}

/// The options code generation does not check (it checks the quality and
/// the effects, once, when it generates the program).
pub(super) fn validate(options: &RenderOptions) -> Result<()> {
    if options.tile_size == 0 {
        return Err(Error::TileSize {
            value: options.tile_size,
        });
    }
    Ok(())
}

pub(super) fn check_size(width: u32, height: u32) -> Result<()> {
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

pub(super) fn too_large(width: u32, height: u32, why: &str) -> Error {
    Error::Resolution {
        width,
        height,
        reason: format!("too large for this device: {why}"),
    }
}

/// A zeroed host vector of `width × height × per_pixel` values, or a
/// resolution error if the memory is not available.
pub(super) fn host_vec<T: Default + Clone>(
    width: u32,
    height: u32,
    per_pixel: usize,
) -> Result<Vec<T>> {
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
pub(super) const MIN_CONE_TILE: u32 = 2;

/// Tiles of the coarse pass with sides of `side` pixels over a `width` ×
/// `height` rendering.
pub(super) fn cone_tiles(width: u32, height: u32, side: u32) -> usize {
    width.div_ceil(side) as usize * height.div_ceil(side) as usize
}

/// The coarse pass's kernel, for a program that has one, with its
/// buffers bound ([`CONE_STARTS`] lists its arguments).
pub(super) fn make_cone(
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
pub(super) struct BrutePass {
    pub(super) kernel: Kernel,
    pub(super) depths: Buffer<f32>,
    pub(super) steps: Buffer<u32>,
    /// Samples the buffers hold.
    pub(super) len: usize,
}

impl BrutePass {
    /// The pass of a program that marches inside shapes by brute force,
    /// with buffers of one sample until a frame sizes them.
    pub(super) fn new(
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

    pub(super) fn buffers(queue: &Queue, len: usize) -> Result<(Buffer<f32>, Buffer<u32>)> {
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
    pub(super) fn run(
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
pub(super) fn make_kernel(
    program: &Program,
    queue: &Queue,
    inputs: &Inputs,
    t: &Targets,
) -> Result<Kernel> {
    let mut b = Kernel::builder();
    b.program(program).name(KERNEL_NAME).queue(queue.clone());
    for (arg, _) in RENDER_TILE {
        match arg {
            RenderArg::Params => inputs.params.push_arg(&mut b),
            RenderArg::Camera => inputs.camera.push_arg(&mut b),
            RenderArg::Lights => inputs.lights.push_arg(&mut b),
            RenderArg::Environment => {
                b.arg(&inputs.environment);
            }
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
            RenderArg::Linear => {
                b.arg(&t.linear);
            }
            RenderArg::Layers => {
                b.arg(&t.layers);
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
pub(super) fn local_size(kernel: &Kernel, selected: &Selected) -> Result<(usize, usize)> {
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
pub(super) struct Inputs {
    pub(super) precision: Precision,
    pub(super) params: RealBuffer,
    pub(super) camera: RealBuffer,
    pub(super) lights: RealBuffer,
    /// The environment light (floats at every precision).
    pub(super) environment: Buffer<f32>,
    /// The dynamic values the instance tables in `params` were last
    /// filled with, where some of their entries copy one.
    filled: Option<Vec<f64>>,
}

impl Inputs {
    /// The buffers for `source`: its parameter buffer holds the dynamic
    /// values, which each frame rewrites, then the program's constants.
    pub(super) fn new(
        queue: &Queue,
        source: &KernelSource,
        values: &ParamValues,
        lights: &[Light],
        environment: Option<&Environment>,
    ) -> Result<Self> {
        let precision = source.precision;
        Ok(Inputs {
            precision,
            params: RealBuffer::new(queue, precision, &source.param_buffer(values.as_slice()))?,
            camera: RealBuffer::new(queue, precision, &[0.0; camera::LEN])?,
            lights: RealBuffer::new(queue, precision, &pack_lights(lights, DVec3::ZERO))?,
            environment: environment_buffer(queue, environment)?,
            filled: (!source.tables.is_baked()).then(|| values.as_slice().to_vec()),
        })
    }

    /// Writes this frame's values; a light list of a new length gets a new
    /// buffer (and a new kernel argument), never a new program.
    pub(super) fn upload(
        &mut self,
        queue: &Queue,
        kernel: &Kernel,
        camera: &[f64; camera::LEN],
        values: &ParamValues,
        lights: &[Light],
        source: &KernelSource,
    ) -> Result<()> {
        let origin = source.origin;
        // The dynamic values only: the constants after them stay, unless
        // their tables copy a value that changed (then they are filled and
        // their hierarchies fitted again; a change elsewhere leaves them).
        match &mut self.filled {
            Some(filled) if source.tables.differ(filled, values.as_slice()) => {
                self.params.write(&source.param_buffer(values.as_slice()))?;
                filled.clear();
                filled.extend_from_slice(values.as_slice());
            }
            Some(filled) => {
                self.params.write(values.as_slice())?;
                filled.clear();
                filled.extend_from_slice(values.as_slice());
            }
            None => self.params.write(values.as_slice())?,
        }
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
        // A compiled scene holds at most `MAX_LIGHTS` (`i32::MAX`) lights.
        #[allow(clippy::cast_possible_truncation, clippy::cast_possible_wrap)]
        let count = lights.len() as i32;
        kernel
            .set_arg(RenderArg::LightCount.index(), count)
            .map_err(opencl)
    }
}

/// The environment light's buffer on the device
/// ([`environment::pack`](super::super::environment::pack)).
pub(super) fn environment_buffer(
    queue: &Queue,
    environment: Option<&Environment>,
) -> Result<Buffer<f32>> {
    let packed = super::super::environment::pack(environment);
    Buffer::builder()
        .queue(queue.clone())
        .flags(MemFlags::new().read_only())
        .len(packed.len())
        .copy_host_slice(&packed)
        .build()
        .map_err(opencl)
}

/// The per-pixel outputs on the device. Without AOVs, the AOV buffers hold
/// one element each (the kernel does not write them); so does the
/// accumulation buffer outside progressive rendering.
#[derive(Debug)]
pub(super) struct Targets {
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) outputs: Outputs,
    pub(super) progressive: bool,
    pub(super) rgba: Buffer<u8>,
    pub(super) depth: Buffer<f32>,
    pub(super) hit: Buffer<u8>,
    pub(super) normals: Buffer<f32>,
    pub(super) steps: Buffer<u32>,
    pub(super) evaluations: Buffer<u32>,
    /// The coarse pass's start distances, one per tile of at least 2 × 2
    /// pixels (see [`cone_tiles`]).
    pub(super) starts: Buffer<f32>,
    /// Progressive rendering's sums of linear colours, an RGB and a spare
    /// `f32` per pixel.
    pub(super) accumulation: Buffer<f32>,
    /// The pixels adaptive supersampling refines, a byte per pixel.
    pub(super) refine: Buffer<u8>,
    /// The exposed linear colour and coverage, four per pixel with layers.
    pub(super) linear: Buffer<f32>,
    /// The shading layers, [`layer::STRIDE`] per pixel with layers.
    pub(super) layers: Buffer<f32>,
}

impl Targets {
    pub(super) fn new(
        queue: &Queue,
        width: u32,
        height: u32,
        outputs: Outputs,
        progressive: bool,
    ) -> Result<Self> {
        let pixels = width as usize * height as usize;
        let aov_pixels = if outputs >= Outputs::Aovs { pixels } else { 1 };
        let layer_pixels = if outputs >= Outputs::Layers {
            pixels
        } else {
            1
        };
        let summed_pixels = if progressive { pixels } else { 1 };
        Ok(Targets {
            width,
            height,
            outputs,
            progressive,
            linear: output(queue, layer_pixels * 4)?,
            layers: output(queue, layer_pixels * layer::STRIDE)?,
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
    pub(super) fn bytes(width: u32, height: u32, outputs: Outputs, progressive: bool) -> Vec<u64> {
        let pixels = u64::from(width) * u64::from(height);
        let aov = if outputs >= Outputs::Aovs { pixels } else { 1 };
        let layered = if outputs >= Outputs::Layers {
            pixels
        } else {
            1
        };
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
            layered * 16,
            layered * layer::STRIDE as u64 * 4,
        ]
    }

    /// Binds the output buffers to their arguments.
    pub(super) fn bind(&self, k: &Kernel) -> Result<()> {
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
        k.set_arg(RenderArg::Linear.index(), &self.linear)
            .map_err(opencl)?;
        k.set_arg(RenderArg::Layers.index(), &self.layers)
            .map_err(opencl)?;
        // Stand-ins until a brute-force pass binds its own.
        k.set_arg(RenderArg::BruteDepths.index(), &self.starts)
            .map_err(opencl)?;
        k.set_arg(RenderArg::BruteSteps.index(), &self.steps)
            .map_err(opencl)
    }

    pub(super) fn fits(
        &self,
        width: u32,
        height: u32,
        outputs: Outputs,
        progressive: bool,
    ) -> bool {
        self.width == width
            && self.height == height
            && self.outputs >= outputs
            && (self.progressive || !progressive)
    }
}

pub(super) fn output<T: ocl::OclPrm>(queue: &Queue, len: usize) -> Result<Buffer<T>> {
    Buffer::builder()
        .queue(queue.clone())
        .flags(MemFlags::new().write_only())
        .len(len.max(1))
        .build()
        .map_err(opencl)
}

/// A frame at the rendered resolution: its colours, and its depth where it
/// is to be scaled up.
pub(super) struct Rendered {
    pub(super) image: RgbaImage,
    pub(super) depth: Option<Vec<f32>>,
}

impl Rendered {
    /// The image at `width` × `height`, scaled up by `scale` (see
    /// `upscale`).
    pub(super) fn scaled(self, width: u32, height: u32, scale: u32) -> RgbaImage {
        match self.depth {
            Some(depth) if scale > 1 => upscale::image(&self.image, &depth, width, height, scale),
            _ => self.image,
        }
    }
}
