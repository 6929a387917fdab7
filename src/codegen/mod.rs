//! Compiles a scene to OpenCL C.
//!
//! The program is, in a fixed order: a header (precision typedefs, the
//! quality constants and one `#define` per effect that is on), the helper
//! functions from `kernels/sdf/` that the scene uses and nothing else, the
//! scene's `DE()` and `DE_shade()`, and the target's kernel (the marcher, or
//! a point evaluator for tests).
//!
//! Dynamic parameters are reads of a parameter buffer, so changing their
//! values never changes the source; baked values are literals.
//!
//! ```
//! use fractal_sdf::prelude::*;
//! use fractal_sdf::codegen::{self, Options};
//!
//! let scene = Scene::new(sphere(param("radius", 1.0)));
//! let kernel = codegen::emit(&scene, &Options::default())?;
//! assert!(kernel.source.contains("sd_sphere(p0, params[0])"));
//! assert!(!kernel.source.contains("mandelbulb"));
//! # Ok::<(), fractal_sdf::Error>(())
//! ```

mod helpers;
mod power;
mod scene;
mod writer;

pub use writer::literal;

use glam::DVec3;

use crate::error::{Error, Result};
use crate::ir::{Ir, ParamSlot};
use crate::quality::{Effects, Precision, Quality};
use crate::scene::Scene;

/// What the generated program is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Target {
    /// The ray-marching renderer (`kernels/march.cl`).
    #[default]
    Render,
    /// A kernel `eval_points` that writes `DE` (and colour/trap) for a
    /// buffer of points: used to check the OpenCL twins against the CPU.
    Evaluate,
}

/// Everything that shapes the generated source besides the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// March and sample settings, precision.
    pub quality: Quality,
    /// Which lighting effects are compiled in.
    pub effects: Effects,
    /// Which kernel to append.
    pub target: Target,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            quality: Quality::default(),
            effects: Effects::default(),
            target: Target::Render,
        }
    }
}

/// A generated program and what the executor needs to run it.
#[derive(Debug, Clone, PartialEq)]
pub struct KernelSource {
    /// The complete OpenCL C source.
    pub source: String,
    /// The parameter buffer's layout, slot by slot.
    pub params: Vec<ParamSlot>,
    /// The precision the source was generated for.
    pub precision: Precision,
    /// A stable 64-bit hash (FNV-1a) of `source`; equal sources have equal
    /// hashes, and changing a dynamic value never changes either.
    pub hash: u64,
    /// Where the program's `DE` has its origin in the scene: the scene's
    /// outermost baked translation for [`Target::Render`] (see
    /// [`Ir::local_frame`]), zero otherwise.
    pub origin: DVec3,
}

/// Generates the OpenCL C program for `scene`.
///
/// # Errors
/// Any validation error of the scene, quality or effects.
pub fn emit(scene: &Scene, options: &Options) -> Result<KernelSource> {
    scene.validate()?;
    let geometry = scene.geometry.as_ref().ok_or(Error::EmptyScene)?;
    emit_ir(&Ir::lower(geometry)?, options)
}

/// Generates the program for already lowered geometry.
///
/// # Errors
/// A validation error of the quality or effects.
pub fn emit_ir(ir: &Ir, options: &Options) -> Result<KernelSource> {
    options.quality.validate()?;
    options.effects.validate()?;
    let precision = options.quality.precision;

    // The scene functions first, to learn which helpers they call.
    // Rendering works in the scene's local frame (see `Ir::local_frame`);
    // evaluation takes points where the user gives them.
    let frame = match options.target {
        Target::Render => ir.local_frame(),
        Target::Evaluate => None,
    };
    let origin = frame.map_or(DVec3::ZERO, |(offset, _)| offset);
    let mut body = writer::Writer::new(precision);
    let mut emitter = scene::SceneEmitter::new(
        ir,
        frame.map(|(_, node)| node),
        &mut body,
        options.quality.fractal_iterations,
    );
    emitter.emit();
    let used: Vec<&'static str> = emitter.used.iter().copied().collect();
    let customs: Vec<_> = emitter.customs.values().cloned().collect();
    let powers: Vec<u32> = emitter.powers.iter().copied().collect();

    let mut w = writer::Writer::new(precision);
    header(&mut w, options);
    for helper in helpers::closure(&used) {
        w.line(format!("/* ---- {} ---- */", helper.name));
        w.raw(helper.source);
        w.line("");
    }
    for n in powers {
        w.line(format!("/* ---- {} ---- */", power::helper_name(n)));
        w.raw(&power::mandelbulb_helper(n));
        w.line("");
    }
    for shape in &customs {
        w.line(format!("/* ---- custom shape {} ---- */", shape.name()));
        w.raw(&shape.opencl_definition());
        w.line("");
    }
    w.line("/* ---- scene ---- */");
    w.raw(&body.finish());
    Ok(finish(w, options, ir.params().to_vec(), origin))
}

/// A complete program around hand-written scene functions: the header for
/// `options`, then `scene_functions` (which must define `DE` and
/// `DE_shade` with the signatures of the generated ones, using only the
/// header's types and constants), then the target kernel. For experiments
/// and for measuring generated code against hand-written code.
///
/// # Errors
/// A validation error of the quality or effects.
pub fn emit_handwritten(scene_functions: &str, options: &Options) -> Result<KernelSource> {
    options.quality.validate()?;
    options.effects.validate()?;
    let mut w = writer::Writer::new(options.quality.precision);
    header(&mut w, options);
    w.line("/* ---- scene (hand-written) ---- */");
    w.raw(scene_functions);
    Ok(finish(w, options, Vec::new(), DVec3::ZERO))
}

/// Appends the target kernel and hashes the program.
fn finish(
    mut w: writer::Writer,
    options: &Options,
    params: Vec<ParamSlot>,
    origin: DVec3,
) -> KernelSource {
    let kernel = match options.target {
        Target::Render => include_str!("../../kernels/march.cl"),
        Target::Evaluate => include_str!("../../kernels/eval.cl"),
    };
    w.raw(&select_features(kernel, &features(options)));
    let source = w.finish();
    KernelSource {
        hash: fnv1a(source.as_bytes()),
        source,
        params,
        precision: options.quality.precision,
        origin,
    }
}

fn header(w: &mut writer::Writer, options: &Options) {
    let q = &options.quality;
    let e = &options.effects;
    w.line("/* Generated by fractal-sdf. */");
    w.line("#pragma OPENCL FP_CONTRACT OFF");
    match q.precision {
        Precision::F32 => {
            w.line("typedef float real;");
            w.line("typedef float2 real2;");
            w.line("typedef float3 real3;");
            w.line("typedef float4 real4;");
            w.line("#define R(x) x##f");
        }
        Precision::F64 => {
            w.line("#pragma OPENCL EXTENSION cl_khr_fp64 : enable");
            w.line("typedef double real;");
            w.line("typedef double2 real2;");
            w.line("typedef double3 real3;");
            w.line("typedef double4 real4;");
            w.line("#define R(x) x");
        }
    }
    let f = |v: f64| w.float(v);
    let rgb = |c: glam::DVec3| format!("(real3)({}, {}, {})", f(c.x), f(c.y), f(c.z));
    let mut defines = vec![
        ("REAL_TINY", f(1e-30)),
        ("DERIVATIVE_CAP", f(1e30)),
        ("MAGNITUDE_CAP", f(1e18)),
        ("DEFAULT_COLOR", rgb(crate::cpu::DEFAULT_COLOR.into())),
        ("MAX_STEPS", q.max_steps.to_string()),
        ("MAX_DISTANCE", f(q.max_distance)),
        ("DETAIL", f(q.detail)),
        ("HIT_EPSILON", f(q.hit_epsilon)),
        ("NORMAL_EPSILON", f(q.normal_epsilon)),
        ("OVER_RELAXATION", f(q.over_relaxation)),
        ("SUPERSAMPLING", q.supersampling.to_string()),
        ("GAMMA", f(e.gamma)),
        ("SKY_TOP", rgb(e.sky_top)),
        ("SKY_BOTTOM", rgb(e.sky_bottom)),
    ];
    let on = features(options);
    if on.contains(&"ENABLE_AO") {
        defines.push(("AO_SAMPLES", q.ao_samples.to_string()));
        defines.push(("AO_DISTANCE", f(e.ao_distance)));
    }
    if on.contains(&"ENABLE_SHADOWS") {
        defines.push(("SHADOW_STEPS", q.shadow_steps.to_string()));
    }
    if let Some(glow) = e.glow.filter(|_| on.contains(&"ENABLE_GLOW")) {
        defines.push(("GLOW_COLOR", rgb(glow.color)));
        defines.push(("GLOW_STRENGTH", f(glow.strength)));
    }
    if on.contains(&"ENABLE_FOG") {
        defines.push(("FOG_DENSITY", f(e.fog_density)));
    }
    for (name, value) in defines {
        w.line(format!("#define {name} {value}"));
    }
    w.line("");
}

/// The effect switches that are on. Each names an `#ifdef` block of the
/// kernels; blocks that are off are removed from the source entirely.
fn features(options: &Options) -> Vec<&'static str> {
    let (q, e) = (&options.quality, &options.effects);
    let mut on = Vec::new();
    if e.ambient_occlusion && q.ao_samples > 0 {
        on.push("ENABLE_AO");
    }
    if e.shadows && q.shadow_steps > 0 {
        on.push("ENABLE_SHADOWS");
    }
    if e.glow.is_some_and(|g| g.strength > 0.0) {
        on.push("ENABLE_GLOW");
    }
    if e.fog_density > 0.0 {
        on.push("ENABLE_FOG");
    }
    on
}

/// Resolves the kernels' `#ifdef ENABLE_*` / `#else` / `#endif` blocks:
/// keeps the lines of features that are on and drops the rest, so a
/// disabled effect leaves no code at all. Other directives pass through.
fn select_features(kernel: &str, on: &[&str]) -> String {
    // One entry per open feature block: (is it being kept, was the
    // enclosing text being kept).
    let mut stack: Vec<(bool, bool)> = Vec::new();
    let mut keep = true;
    let mut out = String::with_capacity(kernel.len());
    for line in kernel.lines() {
        let directive = line.trim_start();
        if let Some(name) = directive.strip_prefix("#ifdef ENABLE_") {
            let name = format!("ENABLE_{}", name.trim());
            stack.push((on.contains(&name.as_str()), keep));
            keep = keep && on.contains(&name.as_str());
        } else if directive.starts_with("#else") && !stack.is_empty() {
            let (taken, outer) = stack.last_mut().expect("checked non-empty");
            *taken = !*taken;
            keep = *outer && *taken;
        } else if directive.starts_with("#endif") && !stack.is_empty() {
            let (_, outer) = stack.pop().expect("checked non-empty");
            keep = outer;
        } else if keep {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// 64-bit FNV-1a: small, stable across platforms and Rust versions.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}
