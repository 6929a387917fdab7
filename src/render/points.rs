//! Evaluating a scene's generated `DE` and `DE_shade` at arbitrary points,
//! or `DE` over blocks of a regular grid, on an OpenCL device: how the
//! OpenCL twins of the formulas are checked against the CPU reference, and
//! how meshes and volumes are sampled.

use glam::DVec3;
use ocl::{Kernel, Queue};

use super::buffer::RealBuffer;
use super::device::{self, DeviceInfo, DeviceSelector, Selected, opencl};
use super::program;
use crate::codegen::interface::{
    EVAL_DISTANCES, EVAL_GRID, EVAL_OUT_STRIDE, EVAL_POINTS, EvalArg, GridArg,
};
use crate::codegen::{self, Options, Target};
use crate::error::{Error, Result};
use crate::ir::{CompiledScene, Ir, ParamValues};
use crate::quality::{Precision, Quality};
use crate::scene::Node;

/// What the device computed at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct PointSample {
    /// `DE(p)`.
    pub distance: f64,
    /// The distance `DE_shade(p)` returned (must equal `distance`).
    pub shade_distance: f64,
    /// The colour `DE_shade` returned.
    pub color: DVec3,
    /// The orbit trap `DE_shade` returned, that tints the colour.
    pub trap: f64,
    /// The orbit trap the shading layers show
    /// ([`cpu::Sample::orbit`](crate::cpu::Sample::orbit)).
    pub orbit: f64,
}

/// Runs a scene's generated distance functions on an OpenCL device.
///
/// ```no_run
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::cpu;
/// use fractal_sdf::quality::Precision;
/// use fractal_sdf::render::{DeviceSelector, PointEvaluator};
///
/// let node = mandelbulb(8.0);
/// let mut device = PointEvaluator::new(&node, Precision::F32, &DeviceSelector::auto())?;
/// let cpu = cpu::Evaluator::new(&node)?;
/// let p = dvec3(0.3, 1.2, -0.4);
/// let on_device = device.eval(&[p])?[0].distance;
/// assert!((on_device - f64::from(cpu.distance_f32(p.as_vec3()))).abs() < 1e-4);
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
#[derive(Debug)]
pub struct PointEvaluator {
    selected: Selected,
    queue: Queue,
    program: ocl::Program,
    source: codegen::KernelSource,
    precision: Precision,
    values: ParamValues,
}

impl PointEvaluator {
    /// Lowers `geometry`, then generates and builds its evaluation
    /// program in `precision` on the selected device.
    ///
    /// # Errors
    /// Validation errors, [`Error::NoPlatform`](crate::Error::NoPlatform),
    /// [`Error::Fp64Unsupported`](crate::Error::Fp64Unsupported),
    /// [`Error::Build`](crate::Error::Build),
    /// [`Error::CustomShapeBuild`](crate::Error::CustomShapeBuild).
    pub fn new(geometry: &Node, precision: Precision, selector: &DeviceSelector) -> Result<Self> {
        Self::from_ir(&Ir::lower(geometry)?, precision, selector)
    }

    /// The evaluation program for a compiled scene's geometry (nothing is
    /// lowered again).
    ///
    /// # Errors
    /// As [`PointEvaluator::new`], less validation;
    /// [`Error::Precision`](crate::Error::Precision) for a baked value or a
    /// dynamic default that `precision` cannot compute with.
    pub fn from_compiled(
        scene: &CompiledScene,
        precision: Precision,
        selector: &DeviceSelector,
    ) -> Result<Self> {
        Self::from_ir(scene.ir(), precision, selector)
    }

    fn from_ir(ir: &Ir, precision: Precision, selector: &DeviceSelector) -> Result<Self> {
        let options = Options {
            quality: Quality {
                precision,
                ..Quality::default()
            },
            target: Target::Evaluate,
            ..Options::default()
        };
        let source = codegen::emit_ir(ir, &options)?;
        let values = ir.default_values();
        values.check_within(precision.limits())?;
        let selected = device::select(selector)?;
        let context = program::context(&selected)?;
        let queue = Queue::new(&context, selected.device, None).map_err(opencl)?;
        let (program, _, _) = program::build(&selected, &context, &source)?;
        Ok(PointEvaluator {
            selected,
            queue,
            program,
            source,
            precision,
            values,
        })
    }

    /// The generated program it runs.
    #[must_use]
    pub fn source(&self) -> &codegen::KernelSource {
        &self.source
    }

    /// The device it runs on.
    #[must_use]
    pub fn device(&self) -> &DeviceInfo {
        &self.selected.info
    }

    /// Sets a dynamic parameter for later evaluations.
    ///
    /// # Errors
    /// See [`ParamValues::set_within`]: the parameter's rules, and the
    /// limits of the program's precision.
    pub fn set_param(&mut self, name: &str, value: f64) -> Result<()> {
        self.values.set_within(name, value, self.precision.limits())
    }

    /// Evaluates every point (rounded to the program's precision).
    ///
    /// # Errors
    /// [`Error::OpenCl`](crate::Error::OpenCl) if a buffer or the launch
    /// fails.
    pub fn eval(&self, points: &[DVec3]) -> Result<Vec<PointSample>> {
        let out = self.launch(points, "eval_points", &EVAL_POINTS, EVAL_OUT_STRIDE)?;
        Ok(out
            .chunks_exact(EVAL_OUT_STRIDE)
            .map(|c| PointSample {
                distance: c[0],
                shade_distance: c[1],
                trap: c[2],
                orbit: c[3],
                color: DVec3::new(c[4], c[5], c[6]),
            })
            .collect())
    }

    /// `DE` at every point, and nothing else: half the work of
    /// [`PointEvaluator::eval`], which also runs `DE_shade`.
    ///
    /// # Errors
    /// As [`PointEvaluator::eval`].
    pub fn distances(&self, points: &[DVec3]) -> Result<Vec<f64>> {
        self.launch(points, "eval_distances", &EVAL_DISTANCES, 1)
    }

    /// Runs the point kernel `name` (whose arguments are `list`) on
    /// `points`, reading back `stride` reals per point.
    fn launch(
        &self,
        points: &[DVec3],
        name: &str,
        list: &[(EvalArg, &str)],
        stride: usize,
    ) -> Result<Vec<f64>> {
        if points.is_empty() {
            return Ok(Vec::new());
        }
        let packed: Vec<f64> = points.iter().flat_map(|p| [p.x, p.y, p.z, 0.0]).collect();
        let q = &self.queue;
        let input = RealBuffer::new(q, self.precision, &packed)?;
        let params = RealBuffer::new(
            q,
            self.precision,
            &self.source.param_buffer(self.values.as_slice()),
        )?;
        let output = RealBuffer::output(q, self.precision, points.len() * stride)?;
        let count = u32::try_from(points.len()).map_err(|_| too_many(points.len() as u64))?;
        let mut builder = Kernel::builder();
        builder
            .program(&self.program)
            .name(name)
            .queue(q.clone())
            .global_work_size(points.len());
        for (arg, _) in list {
            match arg {
                EvalArg::Points => input.push_arg(&mut builder),
                EvalArg::Params => params.push_arg(&mut builder),
                EvalArg::Out => output.push_arg(&mut builder),
                EvalArg::Count => {
                    builder.arg(count);
                }
            }
        }
        let kernel = builder.build().map_err(opencl)?;
        // SAFETY: the kernel reads `count` points and writes `stride` reals
        // per point, exactly the sizes of the buffers bound above.
        unsafe { kernel.enq().map_err(opencl)? };
        output.read()
    }

    /// `DE` at every sample of cubic blocks of a regular grid whose sample
    /// `(i, j, k)` lies at `origin + spacing · (i, j, k)`: `side³` samples
    /// per block, starting at the block's grid indices, in the order `x`
    /// fastest, then `y`, then `z`; block after block. Only distances
    /// travel back, so this is the fast way to sample a volume.
    ///
    /// # Errors
    /// [`Error::OpenCl`](crate::Error::OpenCl) if a buffer or the launch
    /// fails; [`Error::Invalid`](crate::Error::Invalid) if the samples
    /// number more than `u32::MAX`.
    pub fn eval_grid(
        &self,
        origin: DVec3,
        spacing: f64,
        side: u32,
        blocks: &[[i32; 3]],
    ) -> Result<Vec<f64>> {
        let per = u64::from(side).pow(3);
        let total = per * blocks.len() as u64;
        if total == 0 {
            return Ok(Vec::new());
        }
        let count = u32::try_from(total).map_err(|_| too_many(total))?;
        let q = &self.queue;
        let packed: Vec<ocl::prm::Int4> = blocks
            .iter()
            .map(|b| ocl::prm::Int4::new(b[0], b[1], b[2], 0))
            .collect();
        let block_buffer = ocl::Buffer::<ocl::prm::Int4>::builder()
            .queue(q.clone())
            .len(packed.len())
            .copy_host_slice(&packed)
            .build()
            .map_err(opencl)?;
        let grid = RealBuffer::new(q, self.precision, &[origin.x, origin.y, origin.z, spacing])?;
        let params = RealBuffer::new(
            q,
            self.precision,
            &self.source.param_buffer(self.values.as_slice()),
        )?;
        let output = RealBuffer::output(q, self.precision, count as usize)?;
        let mut builder = Kernel::builder();
        builder
            .program(&self.program)
            .name("eval_grid")
            .queue(q.clone())
            .global_work_size(count as usize);
        for (arg, _) in EVAL_GRID {
            match arg {
                GridArg::Blocks => {
                    builder.arg(&block_buffer);
                }
                GridArg::Grid => grid.push_arg(&mut builder),
                GridArg::Side => {
                    builder.arg(side);
                }
                GridArg::Params => params.push_arg(&mut builder),
                GridArg::Out => output.push_arg(&mut builder),
                GridArg::Count => {
                    builder.arg(count);
                }
            }
        }
        let kernel = builder.build().map_err(opencl)?;
        // SAFETY: the kernel reads one int4 per block (`count / side³`
        // blocks) and four reals of `grid`, and writes `count` reals: the
        // sizes of the buffers bound above.
        unsafe { kernel.enq().map_err(opencl)? };
        output.read()
    }
}

/// The error for a launch of more than `u32::MAX` points or samples.
fn too_many(count: u64) -> Error {
    Error::Invalid {
        what: "point count",
        reason: format!(
            "{count} points in one call; at most {} (split them into several calls)",
            u32::MAX
        ),
    }
}
