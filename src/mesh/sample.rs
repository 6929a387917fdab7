//! Where distances come from: an OpenCL device running the generated `DE`
//! (only distances travel back), or the CPU reference on every core.

use glam::DVec3;

use crate::cpu::Evaluator;
use crate::error::{Error, Result};
use crate::ir::CompiledScene;
use crate::quality::Precision;
#[cfg(feature = "opencl")]
use crate::render::{DeviceSelector, PointEvaluator};

/// Where a mesh's or a volume's distances are computed.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Sampler {
    /// The generated `DE` on an OpenCL device (the default with the
    /// `opencl` feature, on the automatically chosen device).
    #[cfg(feature = "opencl")]
    Device(DeviceSelector),
    /// The CPU reference evaluator, on every core (the default without
    /// `opencl`).
    Cpu,
    /// The scene's WGSL `DE` through wgpu, in single precision
    /// ([`WgpuPointEvaluator`](crate::render::WgpuPointEvaluator), feature
    /// `wgpu`).
    #[cfg(feature = "wgpu")]
    Wgpu,
}

impl Default for Sampler {
    fn default() -> Self {
        #[cfg(feature = "opencl")]
        return Sampler::Device(DeviceSelector::auto());
        #[cfg(not(feature = "opencl"))]
        return Sampler::Cpu;
    }
}

/// A built sampler.
pub(crate) enum Sampling {
    Cpu {
        eval: Box<Evaluator>,
        precision: Precision,
    },
    #[cfg(feature = "opencl")]
    Device(Box<PointEvaluator>),
    #[cfg(feature = "wgpu")]
    Wgpu(Box<crate::render::WgpuPointEvaluator>),
}

impl Sampling {
    pub fn new(scene: &CompiledScene, sampler: &Sampler, precision: Precision) -> Result<Self> {
        Ok(match sampler {
            Sampler::Cpu => Sampling::Cpu {
                eval: Box::new(Evaluator::from_compiled(scene)),
                precision,
            },
            #[cfg(feature = "opencl")]
            Sampler::Device(selector) => Sampling::Device(Box::new(PointEvaluator::from_compiled(
                scene, precision, selector,
            )?)),
            #[cfg(feature = "wgpu")]
            Sampler::Wgpu => {
                if precision == Precision::F64 {
                    return Err(Error::Unsupported {
                        backend: "wgpu",
                        what: "sample in double precision (F64), which WGSL does not have".into(),
                        instead: "sample in single precision, or on an OpenCL device or the CPU"
                            .into(),
                    });
                }
                Sampling::Wgpu(Box::new(crate::render::WgpuPointEvaluator::from_compiled(
                    scene,
                )?))
            }
        })
    }

    /// Sets a dynamic parameter.
    pub fn set_param(&mut self, name: &str, value: f64) -> Result<()> {
        match self {
            Sampling::Cpu { eval, precision } => {
                eval.set_param(name, value)?;
                eval.values().check_within(precision.limits())
            }
            #[cfg(feature = "opencl")]
            Sampling::Device(device) => device.set_param(name, value),
            #[cfg(feature = "wgpu")]
            Sampling::Wgpu(points) => points.set_param(name, value),
        }
    }

    /// The distance at every point.
    pub fn distances(&self, points: &[DVec3]) -> Result<Vec<f64>> {
        match self {
            Sampling::Cpu { eval, precision } => on_cores(eval, points.len(), |i| {
                distance(eval, *precision, points[i])
            }),
            #[cfg(feature = "opencl")]
            Sampling::Device(device) => device.distances(points),
            #[cfg(feature = "wgpu")]
            Sampling::Wgpu(device) => device.distances(points),
        }
    }

    /// The colour (linear RGB) `DE_shade` gives at every point.
    pub fn colors(&self, points: &[DVec3]) -> Result<Vec<DVec3>> {
        match self {
            Sampling::Cpu { eval, .. } => on_cores(eval, points.len(), |i| {
                eval.sample::<f64>(points[i].into()).color.into()
            }),
            #[cfg(feature = "opencl")]
            Sampling::Device(device) => {
                Ok(device.eval(points)?.into_iter().map(|s| s.color).collect())
            }
            #[cfg(feature = "wgpu")]
            Sampling::Wgpu(device) => device.colors(points),
        }
    }

    /// `DE` at every sample of cubic blocks of `side³` samples of the grid
    /// at `origin` with `spacing`, block after block, `x` fastest (as
    /// [`PointEvaluator::eval_grid`]).
    pub fn blocks(
        &self,
        origin: DVec3,
        spacing: f64,
        side: u32,
        blocks: &[[i32; 3]],
    ) -> Result<Vec<f32>> {
        let per = (side as usize).pow(3);
        let at = |i: usize| {
            let b = blocks[i / per];
            let s = u32::try_from(i % per).expect("a block is small");
            let at = [s % side, (s / side) % side, s / (side * side)];
            origin
                + spacing
                    * DVec3::new(
                        f64::from(b[0]) + f64::from(at[0]),
                        f64::from(b[1]) + f64::from(at[1]),
                        f64::from(b[2]) + f64::from(at[2]),
                    )
        };
        match self {
            Sampling::Cpu { eval, precision } => on_cores(eval, per * blocks.len(), |i| {
                #[allow(clippy::cast_possible_truncation)] // Grids hold f32.
                let d = distance(eval, *precision, at(i)) as f32;
                d
            }),
            #[cfg(feature = "wgpu")]
            Sampling::Wgpu(device) => {
                let points: Vec<DVec3> = (0..per * blocks.len()).map(at).collect();
                #[allow(clippy::cast_possible_truncation)] // Grids hold f32.
                let out = device
                    .distances(&points)?
                    .into_iter()
                    .map(|d| d as f32)
                    .collect();
                Ok(out)
            }
            #[cfg(feature = "opencl")]
            Sampling::Device(device) => {
                #[allow(clippy::cast_possible_truncation)] // Grids hold f32.
                let out = device
                    .eval_grid(origin, spacing, side, blocks)?
                    .into_iter()
                    .map(|d| d as f32)
                    .collect();
                Ok(out)
            }
        }
    }
}

fn distance(eval: &Evaluator, precision: Precision, p: DVec3) -> f64 {
    match precision {
        Precision::F32 => f64::from(eval.distance_f32(p.as_vec3())),
        Precision::F64 => eval.distance(p),
    }
}

/// `f(i)` for every `i < len`, split over the machine's cores. The only
/// code of a user's that `f` runs is a custom shape's CPU function (of
/// `eval`'s scene): where one panics, the error says so with its message
/// instead of the threads' panic hiding it.
fn on_cores<T: Send + Default + Clone>(
    eval: &Evaluator,
    len: usize,
    f: impl Fn(usize) -> T + Sync,
) -> Result<Vec<T>> {
    let mut out = vec![T::default(); len];
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    let per = len.div_ceil(cores).max(1024);
    let panics: Vec<String> = std::thread::scope(|s| {
        let threads: Vec<_> = out
            .chunks_mut(per)
            .enumerate()
            .map(|(k, part)| {
                let f = &f;
                s.spawn(move || {
                    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        for (j, v) in part.iter_mut().enumerate() {
                            *v = f(k * per + j);
                        }
                    }))
                    .err()
                    .map(|payload| panic_message(payload.as_ref()))
                })
            })
            .collect();
        threads
            .into_iter()
            .filter_map(|t| t.join().ok().flatten())
            .collect()
    });
    match panics.into_iter().next() {
        None => Ok(out),
        Some(message) => {
            let names: Vec<&str> = eval
                .ir()
                .nodes()
                .iter()
                .filter_map(|n| match n {
                    crate::scene::Kind::Custom { shape, .. } => Some(shape.name()),
                    _ => None,
                })
                .collect();
            Err(Error::CustomShape {
                name: if names.is_empty() {
                    "?".into()
                } else {
                    names.join("`, `")
                },
                reason: format!("its CPU function panicked while sampling: {message}"),
            })
        }
    }
}

/// The text a panic carries, where it is a string.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".into())
}
