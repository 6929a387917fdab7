//! The scene's distance and colour at arbitrary points on the wgpu backend
//! ([`WgpuPointEvaluator`]): what meshes and volumes sample, without
//! OpenCL.

use glam::DVec3;

use super::wgpu_backend::{buffer, checked, read, read_back, shared_device, wgpu_error};
use crate::codegen::{self, KernelSource, Options, Target, WGSL_PARAMS};
use crate::error::Result;
use crate::ir::{CompiledScene, ParamValues};
use crate::quality::Precision;

/// Points evaluated in one dispatch: 64 an invocation group, within every
/// device's limit of groups along one axis.
const CHUNK: usize = 1 << 20;

/// The shader's bindings after the scene's parameters (binding 0).
const POINTS: u32 = 1;
const OUTPUTS: u32 = 2;

/// Evaluates a scene's `DE` (and `DE_shade`'s colour) at arbitrary points
/// through wgpu, in single precision: the scene's WGSL module
/// ([`codegen::emit_wgsl`], for evaluation) with two compute entry points.
/// [`PointEvaluator`](super::PointEvaluator)'s calls on the wgpu backend,
/// for [`mesh::Sampler::Wgpu`](crate::mesh::Sampler::Wgpu).
///
/// ```no_run
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::render::WgpuPointEvaluator;
///
/// let scene = Scene::new(sphere(1.0)).compile()?;
/// let points = WgpuPointEvaluator::from_compiled(&scene)?;
/// let d = points.distances(&[dvec3(2.0, 0.0, 0.0)])?;
/// assert!((d[0] - 1.0).abs() < 1e-6);
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
#[derive(Clone)]
pub struct WgpuPointEvaluator {
    values: ParamValues,
    source: KernelSource,
    device: ::wgpu::Device,
    queue: ::wgpu::Queue,
    layout: ::wgpu::BindGroupLayout,
    distances: ::wgpu::ComputePipeline,
    colors: ::wgpu::ComputePipeline,
    params: ::wgpu::Buffer,
}

impl std::fmt::Debug for WgpuPointEvaluator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WgpuPointEvaluator")
            .field("adapter", &self.device.adapter_info().name)
            .finish_non_exhaustive()
    }
}

impl WgpuPointEvaluator {
    /// An evaluator of `scene` on the device the wgpu renderers share.
    ///
    /// # Errors
    /// As [`codegen::emit_wgsl`] (a custom shape written in OpenCL C is
    /// [`Error::Unsupported`](crate::Error::Unsupported)); [`Error::Precision`](crate::Error::Precision) for a parameter
    /// single precision cannot hold; [`Error::Wgpu`](crate::Error::Wgpu) where wgpu finds no
    /// adapter or rejects the shader.
    pub fn from_compiled(scene: &CompiledScene) -> Result<Self> {
        let source = codegen::emit_wgsl(scene, &Options::default().target(Target::Evaluate))?;
        let values = scene.default_values();
        values.check_within(Precision::F32.limits())?;
        let (device, queue) = shared_device()?;
        let shader = format!("{}\n{}", source.source, ENTRY_POINTS);
        let (layout, distances, colors) = checked(&device, "the point shader", || {
            let module = device.create_shader_module(::wgpu::ShaderModuleDescriptor {
                label: Some("fractal-sdf points"),
                source: ::wgpu::ShaderSource::Wgsl(shader.as_str().into()),
            });
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
            let layout = device.create_bind_group_layout(&::wgpu::BindGroupLayoutDescriptor {
                label: Some("fractal-sdf points"),
                entries: &[
                    storage(WGSL_PARAMS.1, true),
                    storage(POINTS, true),
                    storage(OUTPUTS, false),
                ],
            });
            let pipeline_layout =
                device.create_pipeline_layout(&::wgpu::PipelineLayoutDescriptor {
                    label: Some("fractal-sdf points"),
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
            (layout, entry("point_distances"), entry("point_colors"))
        })?;
        let storage = ::wgpu::BufferUsages::STORAGE | ::wgpu::BufferUsages::COPY_DST;
        let reals = source.param_buffer(values.as_slice()).len().max(1);
        let params = buffer(&device, "parameters", 4 * reals, storage);
        let evaluator = WgpuPointEvaluator {
            values,
            source,
            device,
            queue,
            layout,
            distances,
            colors,
            params,
        };
        evaluator.write_params();
        Ok(evaluator)
    }

    /// The adapter it runs on.
    #[must_use]
    pub fn adapter(&self) -> ::wgpu::AdapterInfo {
        self.device.adapter_info()
    }

    /// Sets a dynamic parameter (a buffer write).
    ///
    /// # Errors
    /// As [`PointEvaluator::set_param`](super::PointEvaluator::set_param),
    /// in single precision.
    pub fn set_param(&mut self, name: &str, value: f64) -> Result<()> {
        self.values
            .set_within(name, value, Precision::F32.limits())?;
        self.write_params();
        Ok(())
    }

    /// `DE` at every point, in single precision.
    ///
    /// # Errors
    /// [`Error::Wgpu`](crate::Error::Wgpu) if a buffer or the dispatch fails.
    pub fn distances(&self, points: &[DVec3]) -> Result<Vec<f64>> {
        let out = self.run(&self.distances, points, 1)?;
        Ok(out.into_iter().map(f64::from).collect())
    }

    /// `DE_shade`'s colour (linear RGB) at every point.
    ///
    /// # Errors
    /// As [`WgpuPointEvaluator::distances`].
    pub fn colors(&self, points: &[DVec3]) -> Result<Vec<DVec3>> {
        let out = self.run(&self.colors, points, 4)?;
        Ok(out
            .chunks_exact(4)
            .map(|c| DVec3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2])))
            .collect())
    }

    fn write_params(&self) {
        let reals = self.source.param_buffer(self.values.as_slice());
        #[allow(clippy::cast_possible_truncation)] // The module is single precision.
        let bytes: Vec<u8> = reals
            .iter()
            .flat_map(|&v| (v as f32).to_le_bytes())
            .collect();
        if !bytes.is_empty() {
            self.queue.write_buffer(&self.params, 0, &bytes);
        }
    }

    /// Runs `pipeline` on `points`, a chunk a dispatch, reading back
    /// `stride` floats a point.
    fn run(
        &self,
        pipeline: &::wgpu::ComputePipeline,
        points: &[DVec3],
        stride: usize,
    ) -> Result<Vec<f32>> {
        let mut out = Vec::with_capacity(points.len() * stride);
        for chunk in points.chunks(CHUNK) {
            out.extend(self.dispatch(pipeline, chunk, stride)?);
        }
        Ok(out)
    }

    fn dispatch(
        &self,
        pipeline: &::wgpu::ComputePipeline,
        points: &[DVec3],
        stride: usize,
    ) -> Result<Vec<f32>> {
        let device = &self.device;
        #[allow(clippy::cast_possible_truncation)] // The module is single precision.
        let flat: Vec<u8> = points
            .iter()
            .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .flat_map(f32::to_le_bytes)
            .collect();
        let out_bytes = 4 * stride * points.len();
        let commands = checked(device, "the point evaluation", || {
            let input = buffer(
                device,
                "points",
                flat.len(),
                ::wgpu::BufferUsages::STORAGE | ::wgpu::BufferUsages::COPY_DST,
            );
            self.queue.write_buffer(&input, 0, &flat);
            let output = buffer(
                device,
                "values",
                out_bytes,
                ::wgpu::BufferUsages::STORAGE | ::wgpu::BufferUsages::COPY_SRC,
            );
            let staging = buffer(device, "values readback", out_bytes, read_back());
            let group = device.create_bind_group(&::wgpu::BindGroupDescriptor {
                label: Some("fractal-sdf points"),
                layout: &self.layout,
                entries: &[
                    ::wgpu::BindGroupEntry {
                        binding: WGSL_PARAMS.1,
                        resource: self.params.as_entire_binding(),
                    },
                    ::wgpu::BindGroupEntry {
                        binding: POINTS,
                        resource: input.as_entire_binding(),
                    },
                    ::wgpu::BindGroupEntry {
                        binding: OUTPUTS,
                        resource: output.as_entire_binding(),
                    },
                ],
            });
            let mut encoder =
                device.create_command_encoder(&::wgpu::CommandEncoderDescriptor::default());
            {
                let mut pass =
                    encoder.begin_compute_pass(&::wgpu::ComputePassDescriptor::default());
                pass.set_pipeline(pipeline);
                pass.set_bind_group(WGSL_PARAMS.0, &group, &[]);
                let groups = u32::try_from(points.len().div_ceil(64)).expect("a chunk is small");
                pass.dispatch_workgroups(groups, 1, 1);
            }
            encoder.copy_buffer_to_buffer(&output, 0, &staging, 0, out_bytes as u64);
            (encoder.finish(), staging)
        })?;
        let (commands, staging) = commands;
        checked(device, "the point evaluation", || {
            self.queue.submit([commands]);
        })?;
        let bytes = read(device, &staging)?;
        if bytes.len() != out_bytes {
            return Err(wgpu_error("the point evaluation", "a short read"));
        }
        Ok(bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect())
    }
}

/// The two entry points, after the scene's module: a point's `DE`, and
/// its `DE_shade` colour (three floats, and one of padding).
const ENTRY_POINTS: &str = "
@group(0) @binding(1) var<storage, read> points: array<f32>;
@group(0) @binding(2) var<storage, read_write> outputs: array<f32>;

fn point_at(i: u32) -> real3 {
    return real3(points[3u * i], points[3u * i + 1u], points[3u * i + 2u]);
}

@compute @workgroup_size(64)
fn point_distances(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= arrayLength(&outputs)) {
        return;
    }
    outputs[i] = DE(point_at(i));
}

@compute @workgroup_size(64)
fn point_colors(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (4u * i >= arrayLength(&outputs)) {
        return;
    }
    var color = real3(0.0);
    var trap = real2(0.0);
    let d = DE_shade(point_at(i), &color, &trap);
    outputs[4u * i] = color.x;
    outputs[4u * i + 1u] = color.y;
    outputs[4u * i + 2u] = color.z;
    outputs[4u * i + 3u] = d;
}
";
