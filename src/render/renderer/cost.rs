//! What a frame's distance evaluations cost, and how fast this device can
//! go: the numbers `fractal-sdf bench` sets beside its evaluations a
//! second to say how far a scene is from the machine's limit.

use std::time::Instant;

use glam::DVec3;
use ocl::{Kernel, Program};

use super::Renderer;
use crate::cpu::{self, Evaluator};
use crate::error::Result;
use crate::expr::{Counted, Num, Operations, counting};
use crate::math::V3;
use crate::quality::Precision;
use crate::render::buffer::RealBuffer;
use crate::render::device::opencl;

/// The operations of a scene's distance evaluations, counted by the CPU
/// reference ([`Counted`]) at the points the primary march of a sample
/// of pixels visits ([`Renderer::evaluation_cost`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct EvaluationCost {
    /// The evaluations counted.
    pub evaluations: u64,
    /// Their operations, all together.
    pub operations: Operations,
}

impl EvaluationCost {
    /// Floating-point operations an evaluation, on average
    /// ([`Operations::flops`]).
    #[must_use]
    pub fn flops(&self) -> f64 {
        self.operations.flops() as f64 / self.evaluations.max(1) as f64
    }

    /// Arithmetic operations an evaluation, on average.
    #[must_use]
    pub fn arithmetic(&self) -> f64 {
        self.operations.arithmetic as f64 / self.evaluations.max(1) as f64
    }

    /// Calls (`sin`, `exp`, `pow`…) an evaluation, on average.
    #[must_use]
    pub fn calls(&self) -> f64 {
        self.operations.calls as f64 / self.evaluations.max(1) as f64
    }
}

/// The multiply-adds each work item of the peak kernel does: eight chains
/// of sixteen lanes, `PEAK_STEPS` steps.
const PEAK_CHAINS: usize = 8;
const PEAK_LANES: usize = 16;
const PEAK_STEPS: i32 = 4096;

/// A kernel of nothing but independent fused multiply-adds, in `real`.
fn peak_source(precision: Precision) -> String {
    let real = match precision {
        Precision::F32 => "float",
        Precision::F64 => "double",
    };
    // Every lane starts apart and every lane reaches the output, so no
    // compiler can merge lanes or drop one as dead.
    let lanes = (0..PEAK_LANES)
        .map(|l| format!("({real}){l}"))
        .collect::<Vec<_>>()
        .join(", ");
    let chains = (0..PEAK_CHAINS)
        .map(|c| {
            format!(
                "    {real}16 a{c} = x + ({real}16)({lanes}) * ({real}){};\n",
                c + 1
            )
        })
        .collect::<String>();
    let steps = (0..PEAK_CHAINS)
        .map(|c| format!("        a{c} = fma(a{c}, m, k);\n"))
        .collect::<String>();
    let sum = (0..PEAK_CHAINS)
        .map(|c| format!("a{c}"))
        .collect::<Vec<_>>()
        .join(" + ");
    let pragma = if precision == Precision::F64 {
        "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n"
    } else {
        ""
    };
    format!(
        "{pragma}__kernel void peak(__global {real} *out, int steps) {{\n\
         \x20   {real} x = ({real})get_global_id(0) * ({real})1e-9;\n\
         {chains}\
         \x20   const {real}16 m = ({real}16)(0.9999), k = ({real}16)(1e-4);\n\
         \x20   for (int i = 0; i < steps; i++) {{\n\
         {steps}\
         \x20   }}\n\
         \x20   {real}16 s = {sum};\n\
         \x20   {real}8 h = s.lo + s.hi;\n\
         \x20   {real}4 q = h.lo + h.hi;\n\
         \x20   out[get_global_id(0)] = q.x + q.y + q.z + q.w;\n\
         }}\n"
    )
}

impl Renderer {
    /// Counts the operations of this scene's distance evaluations with the
    /// CPU reference at the current values: at every point where the
    /// primary march of one pixel in `every` × `every` of a `width` ×
    /// `height` image evaluates (as [`cpu::march`] marches it, on the host's
    /// threads), the distance alone, as the kernels' `DE` computes it. The
    /// kernels compute the same formulas; their compiler may share or fuse
    /// some operations, a custom shape's own code is not counted, and the
    /// CPU reference walks a hierarchy over any union of 32 bounded
    /// operands where the kernels walk one only over alike operands, so
    /// this estimates their work.
    ///
    /// # Errors
    /// As [`Renderer::viewport`].
    pub fn evaluation_cost(&self, width: u32, height: u32, every: u32) -> Result<EvaluationCost> {
        let viewport = self.viewport(width, height)?;
        let settings = viewport.march_settings(&self.options.quality);
        let eval = Evaluator::from_compiled(&self.scene)
            .with_values(self.values.clone())
            .distances_only();
        let every = every.max(1);
        let rows: Vec<u32> = (0..height).step_by(every as usize).collect();
        let threads = std::thread::available_parallelism().map_or(1, usize::from);
        let chunk = rows.len().div_ceil(threads).max(1);
        let parts = std::thread::scope(|scope| {
            let handles: Vec<_> = rows
                .chunks(chunk)
                .map(|rows| {
                    let (eval, viewport, settings) = (&eval, &viewport, &settings);
                    scope.spawn(move || {
                        let mut points: Vec<DVec3> = Vec::new();
                        for &y in rows {
                            for x in (0..width).step_by(every as usize) {
                                let ray = viewport.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
                                cpu::march_visiting(eval, ray, settings, &mut |p| points.push(p));
                            }
                        }
                        let ((), ops) = counting(|| {
                            for p in &points {
                                let _ = eval.sample::<Counted>(V3::from_array(
                                    p.to_array().map(Counted::of),
                                ));
                            }
                        });
                        (points.len() as u64, ops)
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("counting does not panic"))
                .collect::<Vec<_>>()
        });
        Ok(parts.into_iter().fold(
            EvaluationCost {
                evaluations: 0,
                operations: Operations::default(),
            },
            |acc, (n, ops)| EvaluationCost {
                evaluations: acc.evaluations + n,
                operations: acc.operations + ops,
            },
        ))
    }

    /// The floating-point operations a second this renderer's device does
    /// in its precision on a kernel of nothing but independent fused
    /// multiply-adds (each two operations): the most its distance
    /// evaluations could reach, measured. The best of three launches.
    ///
    /// # Errors
    /// [`Error::OpenCl`](crate::Error::OpenCl) where the kernel does not
    /// build or run.
    pub fn peak_flops(&self) -> Result<f64> {
        let precision = self.source.precision;
        let program = Program::builder()
            .src(peak_source(precision))
            .devices(self.selected.device)
            .build(&self.context)
            .map_err(opencl)?;
        let items = 64 * self.selected.info.compute_units.max(1) as usize * 64;
        // The buffer's element type is the kernel argument's.
        let out = RealBuffer::output(&self.queue, precision, items)?;
        let mut builder = Kernel::builder();
        builder
            .program(&program)
            .name("peak")
            .queue(self.queue.clone())
            .global_work_size(items);
        out.push_arg(&mut builder);
        builder.arg(PEAK_STEPS);
        let kernel = builder.build().map_err(opencl)?;
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let start = Instant::now();
            // SAFETY: the kernel writes one value per work item into a
            // buffer of one value per work item.
            unsafe { kernel.enq() }.map_err(opencl)?;
            self.queue.finish().map_err(opencl)?;
            best = best.min(start.elapsed().as_secs_f64());
        }
        let flops = items as f64 * PEAK_STEPS as f64 * (PEAK_CHAINS * PEAK_LANES * 2) as f64;
        Ok(flops / best)
    }
}
