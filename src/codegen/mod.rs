//! Compiles a scene to OpenCL C.
//!
//! The program is, in a fixed order: a header (precision typedefs, the
//! quality constants, the kernel interface (the argument lists and buffer
//! layouts the renderer packs, `src/codegen/interface.rs`) and one
//! `#define` per effect that is on), the helper functions the scene uses
//! and nothing else (each printed from its formula's expression IR, see
//! [`crate::expr`]), the
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
//! let scene = Scene::new(sphere(param("radius", 1.0))).compile()?;
//! let kernel = codegen::emit(&scene, &Options::default())?;
//! assert!(kernel.source.contains("sd_sphere(p0, params[0] /* radius */)"));
//! assert!(!kernel.source.contains("mandelbulb"));
//! # Ok::<(), fractal_sdf::Error>(())
//! ```

mod formulas;
mod helpers;
pub(crate) mod interface;
pub(crate) mod names;
mod scene;
mod tables;
mod wgsl;
#[cfg(test)]
mod wgsl_tests;
mod writer;

pub use scene::{MIN_HIERARCHY, MIN_INSTANCES};
pub use tables::InstanceTables;
pub use wgsl::{WGSL_PARAMS, emit_wgsl, emit_wgsl_ir};
pub use writer::literal;

use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;

use crate::error::{Error, Result};
use crate::expr::{OpenCl, Unprintable};
use crate::ir::{Bound, CompiledScene, Ir, Scalar, union_chain};
use crate::math::{DEFAULT_COLOR, DERIVATIVE_CAP, MAGNITUDE_CAP, REAL_TINY};
use crate::quality::{Effects, Precision, Quality, ScreenNormals};
use crate::scene::{BRUTE_MAX_STEPS, DEFAULT_MATERIAL, INSIDE_HUGE, Kind, MATERIAL_SPECS};

/// What the generated program is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[non_exhaustive]
pub enum Target {
    /// The ray-marching renderer (`kernels/march.cl`, `shade.cl`,
    /// `optics.cl`, `paths.cl` and `render.cl`).
    #[default]
    Render,
    /// A kernel `eval_points` that writes `DE` (and colour/trap) for a
    /// buffer of points: used to check the OpenCL twins against the CPU.
    Evaluate,
}

/// Everything that shapes the generated source besides the scene.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct Options {
    /// March and sample settings, precision.
    pub quality: Quality,
    /// Which lighting effects are compiled in.
    pub effects: Effects,
    /// Which kernel to append.
    pub target: Target,
    /// Whether the scene has an environment light
    /// ([`Scene::environment`](crate::scene::Scene::environment)): the
    /// program then reads it (`ENABLE_ENVIRONMENT`) for the background, the
    /// sky that rays and paths meet, and the ambient light. Its image,
    /// rotation and intensity are a buffer: changing them never rebuilds
    /// the program.
    pub environment: bool,
}

impl Options {
    /// The one check of the quality and the effects on their way to a
    /// program: every path to the kernel (the renderer, the mesher, the
    /// command) passes through code generation, and code generation checks
    /// them here, before it writes anything.
    fn validate(&self) -> Result<()> {
        self.quality.validate()?;
        self.effects.validate_for(self.quality.precision)
    }
}

setters!(Options {
    /// Sets [`Options::quality`].
    quality: Quality,
    /// Sets [`Options::effects`].
    effects: Effects,
    /// Sets [`Options::target`].
    target: Target,
    /// Sets [`Options::environment`].
    environment: bool,
});

/// A lighting effect that can be compiled into the marcher. Each names an
/// `#ifdef ENABLE_*` block of the render kernel (`kernels/*.cl`); code generation keeps
/// the blocks of the effects that are on and removes the others entirely.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Effect {
    /// Ambient occlusion (`ENABLE_AO`).
    AmbientOcclusion,
    /// Shadow rays towards each light (`ENABLE_SHADOWS`).
    Shadows,
    /// Glow around near misses (`ENABLE_GLOW`).
    Glow,
    /// Distance fog (`ENABLE_FOG`).
    Fog,
    /// Path-traced global illumination in place of direct lighting
    /// (`ENABLE_GI`, with `GI_BOUNCES`).
    GlobalIllumination,
}

impl Effect {
    /// Every effect, in the order their switches appear in the header.
    pub const ALL: [Effect; 5] = [
        Effect::AmbientOcclusion,
        Effect::Shadows,
        Effect::Glow,
        Effect::Fog,
        Effect::GlobalIllumination,
    ];

    /// The preprocessor switch naming the effect's blocks.
    #[must_use]
    pub fn switch(self) -> &'static str {
        match self {
            Effect::AmbientOcclusion => "ENABLE_AO",
            Effect::Shadows => "ENABLE_SHADOWS",
            Effect::Glow => "ENABLE_GLOW",
            Effect::Fog => "ENABLE_FOG",
            Effect::GlobalIllumination => "ENABLE_GI",
        }
    }

    /// The effects `options` compile in: those that are on and cost
    /// something (an occlusion or shadow sample count of 0, a glow
    /// strength or fog density of 0, leaves the effect out).
    #[must_use]
    pub fn enabled(options: &Options) -> Vec<Effect> {
        let (q, e) = (&options.quality, &options.effects);
        Effect::ALL
            .into_iter()
            .filter(|effect| match effect {
                Effect::AmbientOcclusion => e.ambient_occlusion && q.ao_samples > 0,
                Effect::Shadows => e.shadows && q.shadow_steps > 0,
                Effect::Glow => e.glow.is_some_and(|g| g.strength > 0.0),
                Effect::Fog => e.fog_density > 0.0,
                Effect::GlobalIllumination => e.global_illumination.is_some(),
            })
            .collect()
    }
}

/// A generated program and what the executor needs to run it: the one
/// type for a program's source, generated or hand-written.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct KernelSource {
    /// The complete source: an OpenCL C program, or a WGSL module of the
    /// scene's functions ([`emit_wgsl`]).
    pub source: String,
    /// The language of [`source`](Self::source).
    pub language: Language,
    /// The precision the source was generated for; `F64` requires a device
    /// with `cl_khr_fp64`.
    pub precision: Precision,
    /// A stable 64-bit hash (FNV-1a) of `source`; equal sources have equal
    /// hashes, and changing a dynamic value never changes either.
    pub hash: u64,
    /// Whether the program is built with relaxed, fast math
    /// ([`Quality::fast_math`]; an OpenCL build option, which a WGSL module
    /// leaves to the application that builds it).
    pub fast_math: bool,
    /// The side of the coarse pass's tiles, in rendered pixels: the
    /// program has a `cone_starts` kernel when it is not 0
    /// ([`Quality::cone_tile`]), which a program that marches inside shapes
    /// by brute force never has.
    pub cone_tile: u32,
    /// Whether the program marches inside shapes by brute force
    /// ([`Quality::brute_step`]): its `render_tile` then shades from the
    /// depths a `brute_depths` kernel leaves, which runs first.
    pub brute: bool,
    /// Where the program's `DE` has its origin in the scene: the scene's
    /// outermost baked translation for [`Target::Render`] (see
    /// [`Ir::local_frame`]), zero otherwise. The renderer moves the camera
    /// and the lights by it, in `f64`, before they reach the device.
    pub origin: DVec3,
    /// Where the target kernel (the render files `kernels/march.cl` to
    /// `render.cl`, or `kernels/eval.cl`,
    /// after effect selection) starts in `source`: its end for a WGSL
    /// module, which holds no kernel.
    pub kernel_start: usize,
    /// Where each custom shape's function lies in `source`, in order, so
    /// that a compiler message about a line of the program can be told as
    /// a line of the shape's body (empty for a WGSL module, whose custom
    /// shapes are formulas, printed as the built-in ones are).
    pub custom_regions: Vec<CustomRegion>,
    /// Values the program reads from its parameter buffer after the
    /// dynamic parameters (whose values fill the first slots): the values
    /// of instanced union operands, one row per instance (see
    /// [`MIN_INSTANCES`]; an entry that copies a dynamic value holds its
    /// default), and the nodes of the hierarchies over them (see
    /// [`MIN_HIERARCHY`]). The parameter buffer a host passes is
    /// [`param_buffer`](Self::param_buffer). Like dynamic values, they
    /// never change the source or its hash.
    pub constants: Vec<f64>,
    /// Which entries of [`constants`](Self::constants) copy a dynamic
    /// value, and the hierarchies over instances fitted again when one
    /// changes: [`param_buffer`](Self::param_buffer) applies them.
    pub tables: InstanceTables,
}

/// The language of a generated program.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Language {
    /// OpenCL C: the whole program, kernels included ([`emit`]).
    #[default]
    OpenCl,
    /// WGSL: the scene's functions, for a shader to call ([`emit_wgsl`]).
    Wgsl,
}

/// Where a custom shape's OpenCL function lies in a generated program: its
/// signature on line `first_line - 1`, the body as given on lines
/// `first_line .. first_line + lines`, and the closing brace after them.
/// Lines are counted from 1, as compilers count them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CustomRegion {
    /// The shape's name.
    pub shape: String,
    /// The program line holding the first line of the body.
    pub first_line: usize,
    /// How many lines the body has.
    pub lines: usize,
}

impl CustomRegion {
    /// The line of the shape's definition that program line `line` is:
    /// 0 for the signature, `1..=lines` for the body's lines (the first
    /// line of the string the shape was given is 1), `lines + 1` for the
    /// closing brace; `None` outside the definition.
    #[must_use]
    pub fn body_line(&self, line: usize) -> Option<usize> {
        (line + 1 >= self.first_line && line <= self.first_line + self.lines)
            .then(|| line + 1 - self.first_line)
    }
}

impl KernelSource {
    /// The contents of the program's parameter buffer for the dynamic
    /// values `values` (one per slot): the values, then
    /// [`constants`](Self::constants).
    #[must_use]
    pub fn param_buffer(&self, values: &[f64]) -> Vec<f64> {
        let mut buffer = Vec::with_capacity(values.len() + self.constants.len());
        buffer.extend_from_slice(values);
        buffer.extend_from_slice(&self.constants);
        if !self.tables.is_baked() {
            self.tables.fill(&mut buffer[values.len()..], values);
        }
        buffer
    }

    /// The scene's part of the program: header, helpers, `DE` and
    /// `DE_shade`.
    #[must_use]
    pub fn scene_part(&self) -> &str {
        &self.source[..self.kernel_start]
    }

    /// The target kernel, as appended after the scene's part.
    #[must_use]
    pub fn kernel_part(&self) -> &str {
        &self.source[self.kernel_start..]
    }

    /// The custom shape whose definition holds program line `line`
    /// (counted from 1), and which line of the definition it is (see
    /// [`CustomRegion::body_line`]).
    #[must_use]
    pub fn custom_line(&self, line: usize) -> Option<(&CustomRegion, usize)> {
        self.custom_regions
            .iter()
            .find_map(|r| r.body_line(line).map(|l| (r, l)))
    }

    /// The hash [`KernelSource::hash`] holds for a program of text
    /// `source`.
    #[must_use]
    pub fn hash_of(source: &str) -> u64 {
        fnv1a(source.as_bytes())
    }

    /// Line `line` of the program (counted from 1), if there is one.
    #[must_use]
    pub fn line(&self, line: usize) -> Option<&str> {
        self.source.lines().nth(line.checked_sub(1)?)
    }
}

static EMISSIONS: AtomicU64 = AtomicU64::new(0);

/// How many programs code generation has written in this process.
/// Changing a renderer's camera, lights or dynamic parameters writes none.
#[must_use]
pub fn emissions() -> u64 {
    EMISSIONS.load(Ordering::Relaxed)
}

/// Generates the OpenCL C program for a compiled scene.
///
/// # Errors
/// A validation error of the quality or effects.
pub fn emit(scene: &CompiledScene, options: &Options) -> Result<KernelSource> {
    emit_ir(scene.ir(), options)
}

/// Generates the program for lowered geometry alone (the camera and lights
/// never shape the source).
///
/// Every value written as a literal is first checked against the limits of
/// the program's precision ([`Precision::limits`]): a baked scene value,
/// quality knob or effect setting that precision cannot compute with is an
/// [`Error::Precision`] naming it, never a
/// program that fails to build or draws nothing.
///
/// # Errors
/// A validation error of the quality or effects;
/// [`Error::Precision`] for a baked value beyond
/// the precision's limits, with its node's path;
/// [`Error::InsideShape`] for global illumination over a scene with an
/// inside shape, which has no normal away from the screen to bounce from.
pub fn emit_ir(ir: &Ir, options: &Options) -> Result<KernelSource> {
    options.validate()?;
    let precision = options.quality.precision;
    ir.check_limits(precision.limits())?;

    // The scene functions first, to learn which helpers they call.
    // Rendering works in the scene's local frame (see `Ir::local_frame`);
    // evaluation takes points where the user gives them.
    let frame = match options.target {
        Target::Render => ir.local_frame(),
        Target::Evaluate => None,
    };
    let origin = frame.map_or(DVec3::ZERO, |(offset, _)| offset);
    let mut body = writer::Writer::new(precision);
    body.name_slots(ir.params().iter().map(|s| s.name.as_str()));
    let mut emitter = scene::SceneEmitter::new(
        ir,
        frame.map(|(_, node)| node),
        &mut body,
        options.quality.fractal_iterations,
    );
    let materials = shades_materials(ir, options);
    emitter.emit(materials);
    let count = ir.glows().len();
    if options.target == Target::Render && count > 0 && ir.has_inside_shapes() {
        return Err(glows_with_inside_shapes());
    }
    if options.target == Target::Render && count > MAX_GLOW_NODES {
        return Err(too_many_glows(count));
    }
    let glows = if options.target == Target::Render {
        emitter.emit_glows()
    } else {
        0
    };
    if options.target == Target::Render && options.effects.global_illumination.is_some() {
        ir.check_paths()?;
    }
    // Inside shapes are marched by brute force within their region.
    let features = Features {
        materials,
        inside: ir.has_inside_shapes(),
        brute: match options.target {
            Target::Render => ir.brute_region().map(|b| Bound {
                centre: b.centre - origin,
                ..b
            }),
            Target::Evaluate => None,
        },
        glow: glow_bound(ir, options, origin),
        origin,
        node_glow: (glows > 0).then(|| (glows, node_glow(ir))),
        emitters: emitters(ir, options, origin),
    };
    let customs: Vec<_> = emitter.customs.values().cloned().collect();
    let constants = std::mem::take(&mut emitter.constants);
    let tables = std::mem::take(&mut emitter.tables);

    let mut w = writer::Writer::new(precision);
    header(&mut w, options, &features);
    write_helpers(&mut w, &mut emitter)?;
    let mut custom_regions = Vec::with_capacity(customs.len());
    for shape in &customs {
        names::check_custom(shape)?;
    }
    for shape in &customs {
        w.line(format!("/* ---- custom shape {} ---- */", shape.name()));
        let definition = shape.opencl_definition();
        // The signature takes one line, the closing brace another.
        custom_regions.push(CustomRegion {
            shape: shape.name().to_string(),
            first_line: w.lines() + 2,
            lines: definition.matches('\n').count() - 2,
        });
        w.raw(&definition);
        if let Some(wrapper) = shape.opencl_wrapper() {
            w.raw(&wrapper);
        }
        w.line("");
    }
    w.line("/* ---- scene ---- */");
    unwritable(&body, precision)?;
    w.raw(&body.finish());
    let mut kernel = finish(
        w,
        options,
        origin,
        scene_bound(ir, options, origin),
        &features,
    )?;
    kernel.custom_regions = custom_regions;
    kernel.constants = constants;
    kernel.tables = tables;
    Ok(kernel)
}

/// Whether the program shades materials (`DE_material`): only a renderer
/// does, and only for a scene that sets one.
fn shades_materials(ir: &Ir, options: &Options) -> bool {
    options.target == Target::Render
        && ir
            .nodes()
            .iter()
            .any(|n| matches!(n, Kind::Material { .. }))
}

/// Writes the helpers the scene functions `emitter` wrote call, in the
/// writer's language: each helper, and after it its trapped form where an
/// orbit trap colours the fractal; then the specialised Mandelbulb powers
/// and the hybrids.
fn write_helpers(w: &mut writer::Writer, emitter: &mut scene::SceneEmitter<'_>) -> Result<()> {
    let to = w.printer();
    let used = std::mem::take(&mut emitter.used);
    let trapped = std::mem::take(&mut emitter.trapped);
    let powers: Vec<u32> = emitter.powers.iter().copied().collect();
    let mut hybrids: Vec<_> = std::mem::take(&mut emitter.hybrids).into_values().collect();
    hybrids.sort_by(|a, b| a.0.cmp(&b.0));
    let mut section = |name: &str, source: Result<String, Unprintable>| -> Result<()> {
        w.line(format!("/* ---- {name} ---- */"));
        w.raw(&source.map_err(|e| Error::Invalid {
            what: "formula",
            reason: e.to_string(),
        })?);
        w.line("");
        Ok(())
    };
    for helper in helpers::Helper::ALL
        .into_iter()
        .filter(|h| used.contains(h))
    {
        section(helper.name(), helper.source(to))?;
        if trapped.contains(helper.name())
            && let Some(source) = helper.fractal_source(to, true)
        {
            section(&formulas::fractal_name(helper.name(), true), source)?;
        }
    }
    for n in powers {
        let name = formulas::power_helper_name(n);
        section(&name, formulas::mandelbulb_power(to, n, false))?;
        if trapped.contains(&name) {
            section(
                &formulas::fractal_name(&name, true),
                formulas::mandelbulb_power(to, n, true),
            )?;
        }
    }
    for (name, shape, integer_powers) in &hybrids {
        section(
            name,
            formulas::hybrid(to, name, shape, integer_powers, false),
        )?;
        if trapped.contains(name) {
            section(
                &formulas::fractal_name(name, true),
                formulas::hybrid(to, name, shape, integer_powers, true),
            )?;
        }
    }
    Ok(())
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
    options.validate()?;
    let mut w = writer::Writer::new(options.quality.precision);
    header(&mut w, options, &Features::default());
    w.line("/* ---- scene (hand-written) ---- */");
    w.raw(scene_functions);
    finish(w, options, DVec3::ZERO, None, &Features::default())
}

/// The error for a value `w` could not write as a literal of `precision`
/// (one that validation let through), if there is one.
fn unwritable(w: &writer::Writer, precision: Precision) -> Result<()> {
    match w.unwritable() {
        None => Ok(()),
        Some(value) => {
            let limits = precision.limits();
            Err(Error::Precision {
                node: "scene".into(),
                param: "a value of the generated program".into(),
                value,
                precision: limits.precision,
                limit: limits.max,
            })
        }
    }
}

/// The switch of the march's stop at the scene's bounding sphere.
const SCENE_BOUND: &str = "ENABLE_SCENE_BOUND";

/// The switch of the coarse pass ([`Quality::cone_tile`]).
const CONE: &str = "ENABLE_CONE";

/// The switch of materials and the secondary rays they send
/// ([`Quality::bounces`]): on for scenes that set a material.
const MATERIALS: &str = "ENABLE_MATERIALS";

/// The switch of brute-force marching ([`Quality::brute_step`]): on for
/// rendering scenes with an inside shape.
const BRUTE: &str = "ENABLE_BRUTE";

/// The switch of direct lighting: ambient occlusion standing in for the
/// sky and each light's shading at the first hit (on unless global
/// illumination is).
const DIRECT: &str = "ENABLE_DIRECT";

/// The switch of the sky seen along a ray's direction (`march_sky`): on
/// for programs that send rays past the first hit (materials, global
/// illumination).
const SKY_RAYS: &str = "ENABLE_SKY_RAYS";

/// The switch of the environment light ([`Options::environment`]).
const ENVIRONMENT: &str = "ENABLE_ENVIRONMENT";

/// The switch of a background that is the sky along each ray rather than
/// a gradient down the image (global illumination, an environment).
const SKY_BACKGROUND: &str = "ENABLE_SKY_BACKGROUND";

/// The switch of the march's glow test against the sphere around the
/// shapes that glow ([`glow_bound`]).
const GLOW_BOUND: &str = "ENABLE_GLOW_BOUND";

/// The switch of the fog's light ([`crate::quality::Volumetric`]).
const FOG_LIGHT: &str = "ENABLE_FOG_LIGHT";

/// Whether `options` render fog as a lit medium.
fn fog_light(options: &Options) -> bool {
    options.target == Target::Render
        && options.effects.volumetric.is_some()
        && Effect::enabled(options).contains(&Effect::Fog)
}

/// The most glow nodes ([`crate::scene::Node::glow`]) a rendered scene
/// may have: each halo is traced on its own, at every step near a surface.
pub const MAX_GLOW_NODES: usize = 16;

/// The switch of the sampling of emissive shapes under global
/// illumination ([`emitters`]).
const EMITTERS: &str = "ENABLE_EMITTERS";

/// The most emissive shapes a path-traced program samples: more are still
/// lit by, and light, the paths that meet them.
const MAX_EMITTERS: usize = 16;

/// For a path-traced rendering program, the bounding spheres (in the
/// program's frame, about `origin`) of the material nodes that give off
/// light (an emission above 0, or a dynamic one) and have a bound the
/// precision can hold: next-event estimation draws a direction in each
/// one's cone at every bounce. Emitters beyond [`MAX_EMITTERS`], or
/// without a bound, are found by the paths' bounces alone (their light is
/// exact all the same, only noisier).
fn emitters(ir: &Ir, options: &Options, origin: DVec3) -> Vec<Bound> {
    if options.target != Target::Render || options.effects.global_illumination.is_none() {
        return Vec::new();
    }
    let bounds = ir.bounds();
    ir.materials()
        .into_iter()
        .filter(|&id| match ir.node(id) {
            Kind::Material { material, .. } => material.emission != Scalar::Baked(0.0),
            _ => false,
        })
        .filter_map(|id| bounds[id.index()])
        .map(|b| Bound {
            centre: b.centre - origin,
            ..b
        })
        .filter(|b| b.fits(options.quality.precision.limits()))
        .take(MAX_EMITTERS)
        .collect()
}

/// A rendered scene with both glow nodes and inside shapes.
fn glows_with_inside_shapes() -> Error {
    Error::Invalid {
        what: "scene",
        reason: "glow nodes need the distance to their shapes along each ray, which a scene \
                 with inside shapes (marched by brute force) does not have: use the scene's \
                 glow (Effects::glow) instead"
            .into(),
    }
}

/// A rendered scene with `count` glow nodes, above [`MAX_GLOW_NODES`].
fn too_many_glows(count: usize) -> Error {
    Error::Invalid {
        what: "scene",
        reason: format!(
            "{count} glow nodes, more than the {MAX_GLOW_NODES} a scene may have (each halo is \
             traced on its own): give their union one glow instead"
        ),
    }
}

/// The switch of glow nodes' halos ([`crate::scene::Node::glow`]).
const NODE_GLOW: &str = "ENABLE_NODE_GLOW";

/// The brightest the glow nodes' halos can add up to: the sum of each
/// one's brightest channel, with the values the program is built with (a
/// dynamic colour or strength at its default). The march stops early only where no halo that bright can
/// still change a pixel: a dynamic glow raised above it later may lose
/// the faint end of its halo beyond the scene's bounding sphere.
fn node_glow(ir: &Ir) -> f64 {
    let values = ir.default_values();
    let value = |s: Scalar| match s {
        Scalar::Baked(v) => v,
        Scalar::Dynamic(slot) => values.as_slice()[slot as usize],
    };
    ir.nodes()
        .iter()
        .filter_map(|n| match n {
            Kind::Glow {
                color, strength, ..
            } => Some(color.map(value).into_iter().fold(0.0, f64::max) * value(*strength)),
            _ => None,
        })
        .sum()
}

/// What a scene asks of its program beyond the quality and effects.
#[derive(Debug, Clone, Default)]
pub(crate) struct Features {
    /// The bounding spheres of the shapes that give off light, in the
    /// program's frame, for a path-traced program to sample ([`emitters`]).
    pub(crate) emitters: Vec<Bound>,
    /// Where the program's `DE` has its origin in the scene
    /// ([`KernelSource::origin`]).
    pub(crate) origin: DVec3,
    /// The glow nodes' halos: how many (each with its `DE_glow` function),
    /// and the brightest channel of the brightest as the program is built
    /// ([`node_glow`]); `None` without glow nodes.
    pub(crate) node_glow: Option<(usize, f64)>,
    /// It sets a material (rendering only).
    pub(crate) materials: bool,
    /// It holds an inside shape, whose value is `±INSIDE_HUGE`.
    pub(crate) inside: bool,
    /// Where its rays step by brute force, in the program's frame
    /// (rendering a scene with inside shapes only).
    pub(crate) brute: Option<Bound>,
    /// The sphere around the shapes that glow, in the program's frame:
    /// for a glowing scene without a bound of its own, the bounded
    /// operands of its root's union (see [`glow_bound`]).
    pub(crate) glow: Option<Bound>,
}

/// The target kernel for `options`, with the blocks of the effects that are
/// off removed (and the stop at the scene's bounding sphere, which only
/// programs for a bounded scene keep): what every program for these
/// options ends with.
#[must_use]
pub fn target_kernel(options: &Options) -> String {
    kernel_with(options, false, &Features::default())
}

/// The render program's kernel source: its five files, in order (see the
/// header of `kernels/march.cl`).
pub(crate) const RENDER_KERNEL: &str = concat!(
    include_str!("../../kernels/march.cl"),
    include_str!("../../kernels/shade.cl"),
    include_str!("../../kernels/optics.cl"),
    include_str!("../../kernels/paths.cl"),
    include_str!("../../kernels/render.cl"),
);

fn kernel_with(options: &Options, bounded: bool, features: &Features) -> String {
    let kernel = match options.target {
        Target::Render => RENDER_KERNEL,
        Target::Evaluate => include_str!("../../kernels/eval.cl"),
    };
    let effects = Effect::enabled(options);
    let gi = effects.contains(&Effect::GlobalIllumination);
    let mut on: Vec<&str> = effects.into_iter().map(Effect::switch).collect();
    let environment = options.environment && options.target == Target::Render;
    if !gi {
        on.push(DIRECT);
    }
    if gi || environment || features.materials {
        on.push(SKY_RAYS);
    }
    if gi || environment {
        on.push(SKY_BACKGROUND);
    }
    if environment {
        on.push(ENVIRONMENT);
    }
    if bounded {
        on.push(SCENE_BOUND);
    }
    if cone_tile(options, features) > 0 {
        on.push(CONE);
    }
    if features.materials {
        on.push(MATERIALS);
    }
    if features.brute.is_some() {
        on.push(BRUTE);
    }
    if features.glow.is_some() {
        on.push(GLOW_BOUND);
    }
    if fog_light(options) {
        on.push(FOG_LIGHT);
    }
    if features.node_glow.is_some() {
        on.push(NODE_GLOW);
        if !on.contains(&Effect::Glow.switch()) {
            on.push(Effect::Glow.switch());
        }
    }
    if !features.emitters.is_empty() {
        on.push(EMITTERS);
    }
    select_blocks(kernel, &on)
}

/// The coarse pass's tile side: none for evaluation, nor where inside
/// shapes (which a cone cannot see) are marched by brute force.
fn cone_tile(options: &Options, features: &Features) -> u32 {
    if options.target == Target::Render && features.brute.is_none() {
        options.quality.cone_tile
    } else {
        0
    }
}

/// The sphere a rendering program's rays stop at, in the program's frame:
/// the bound of the whole scene ([`Ir::bounds`]), where it has one the
/// precision can compute.
fn scene_bound(ir: &Ir, options: &Options, origin: DVec3) -> Option<Bound> {
    if options.target != Target::Render {
        return None;
    }
    let bound = ir.bounds()[ir.root().index()]?;
    let local = Bound {
        centre: bound.centre - origin,
        ..bound
    };
    local
        .fits(options.quality.precision.limits())
        .then_some(local)
}

/// The sphere around the shapes whose near misses glow, in the program's
/// frame, for a rendering program with glow whose scene has no bound: its
/// root is a union of unbounded operands (a floor plane, an infinite
/// repetition) and bounded ones, and only the bounded ones glow. A ray
/// grazing an infinite plane comes arbitrarily near it at the horizon
/// without any shape there to glow; the march measures a near miss as at
/// least the distance to this sphere, which the glowing shapes' distance
/// never falls below (`ENABLE_GLOW_BOUND` in `march.cl`).
fn glow_bound(ir: &Ir, options: &Options, origin: DVec3) -> Option<Bound> {
    let glowing = Effect::enabled(options).contains(&Effect::Glow);
    if options.target != Target::Render || !glowing {
        return None;
    }
    let bounds = ir.bounds();
    if bounds[ir.root().index()].is_some() {
        return None;
    }
    let chain = union_chain(ir, ir.root(), &bounds)?;
    let bound = chain
        .operands
        .iter()
        .filter_map(|o| bounds[o.index()])
        .reduce(Bound::around)?;
    let local = Bound {
        centre: bound.centre - origin,
        ..bound
    };
    local
        .fits(options.quality.precision.limits())
        .then_some(local)
}

/// Defines `NAME_CENTRE` and `NAME_RADIUS`, the sphere of `bound`, under a
/// comment saying what it is.
fn define_sphere(w: &mut writer::Writer, what: &str, name: &str, bound: &Bound) {
    w.line(format!("/* {what} */"));
    let c = bound.centre;
    w.line(format!(
        "#define {name}_CENTRE (real3)({}, {}, {})",
        w.float(c.x),
        w.float(c.y),
        w.float(c.z)
    ));
    w.line(format!("#define {name}_RADIUS {}", w.float(bound.radius)));
}

/// Appends the target kernel (with the scene's bounding sphere, if it has
/// one) and hashes the program.
fn finish(
    mut w: writer::Writer,
    options: &Options,
    origin: DVec3,
    bound: Option<Bound>,
    features: &Features,
) -> Result<KernelSource> {
    EMISSIONS.fetch_add(1, Ordering::Relaxed);
    if let Some(b) = features.brute {
        let what = "The sphere inside shapes lie in: marched by brute force.";
        define_sphere(&mut w, what, "BRUTE", &b);
    }
    if let Some(b) = bound {
        define_sphere(
            &mut w,
            "The sphere around the scene (src/ir/bounds.rs).",
            "SCENE_BOUND",
            &b,
        );
        w.line(format!("#define SCENE_BOUND_SLOPE {}", w.float(b.slope)));
    }
    if let Some(b) = features.glow {
        let what = "The sphere around the shapes that glow (the scene has no bound).";
        define_sphere(&mut w, what, "GLOW_BOUND", &b);
        w.line(format!("#define GLOW_BOUND_SLOPE {}", w.float(b.slope)));
    }
    if options.target == Target::Render {
        // The display transform the render kernel ends each pixel with.
        let display =
            formulas::display(&OpenCl, options.effects.tone_map, options.effects.encoding)
                .map_err(|e| Error::Invalid {
                    what: "formula",
                    reason: e.to_string(),
                })?;
        w.line("/* ---- display ---- */");
        w.raw(&display);
        w.line("");
    }
    w.line(format!(
        "/* ---- kernel: {} ---- */",
        match options.target {
            Target::Render => "march.cl, shade.cl, optics.cl, paths.cl, render.cl",
            Target::Evaluate => "eval.cl",
        }
    ));
    let kernel_start = w.len();
    w.raw(&kernel_with(options, bound.is_some(), features));
    unwritable(&w, options.quality.precision)?;
    let source = w.finish();
    Ok(KernelSource {
        hash: fnv1a(source.as_bytes()),
        source,
        language: Language::OpenCl,
        precision: options.quality.precision,
        fast_math: options.quality.fast_math,
        cone_tile: cone_tile(options, features),
        brute: features.brute.is_some(),
        origin,
        kernel_start,
        custom_regions: Vec::new(),
        constants: Vec::new(),
        tables: InstanceTables::default(),
    })
}

fn header(w: &mut writer::Writer, options: &Options, features: &Features) {
    let materials = features.materials;
    let q = &options.quality;
    let e = &options.effects;
    w.line("/* Generated by fractal-sdf. */");
    if q.fast_math {
        // Built with -cl-unsafe-math-optimizations (`fast_math`).
        w.line("/* fast math: relaxed, contracted arithmetic */");
    } else {
        w.line("#pragma OPENCL FP_CONTRACT OFF");
    }
    match q.precision {
        Precision::F32 => {
            w.line("typedef float real;");
            w.line("typedef float2 real2;");
            w.line("typedef float3 real3;");
            w.line("typedef float4 real4;");
            if materials {
                w.line("typedef float16 real16;");
            }
            w.line("#define R(x) x##f");
        }
        Precision::F64 => {
            w.line("#pragma OPENCL EXTENSION cl_khr_fp64 : enable");
            w.line("typedef double real;");
            w.line("typedef double2 real2;");
            w.line("typedef double3 real3;");
            w.line("typedef double4 real4;");
            if materials {
                w.line("typedef double16 real16;");
            }
            w.line("#define R(x) x");
        }
    }
    let f = |v: f64| w.float(v);
    let rgb = |c: glam::DVec3| format!("(real3)({}, {}, {})", f(c.x), f(c.y), f(c.z));
    let mut defines = vec![
        ("REAL_TINY", f(REAL_TINY)),
        ("DERIVATIVE_CAP", f(DERIVATIVE_CAP)),
        ("MAGNITUDE_CAP", f(MAGNITUDE_CAP)),
        ("DEFAULT_COLOR", rgb(DEFAULT_COLOR.into())),
        ("MAX_STEPS", q.max_steps.to_string()),
        ("MAX_DISTANCE", f(q.max_distance)),
        ("DETAIL", f(q.detail)),
        ("HIT_EPSILON", f(q.hit_epsilon)),
        ("NORMAL_EPSILON", f(q.normal_epsilon)),
        ("OVER_RELAXATION", f(q.over_relaxation)),
        ("SUPERSAMPLING", q.supersampling.to_string()),
        ("GAMMA", f(e.gamma)),
        ("EXPOSURE_SCALE", f(e.exposure_scale())),
        ("SKY_TOP", rgb(e.sky_top)),
        ("SKY_BOTTOM", rgb(e.sky_bottom)),
    ];
    let on = Effect::enabled(options);
    if on.contains(&Effect::AmbientOcclusion) {
        defines.push(("AO_SAMPLES", q.ao_samples.to_string()));
        defines.push(("AO_DISTANCE", f(e.ao_distance)));
    }
    if on.contains(&Effect::Shadows) {
        defines.push(("SHADOW_STEPS", q.shadow_steps.to_string()));
    }
    if let Some(glow) = e.glow.filter(|_| on.contains(&Effect::Glow)) {
        defines.push(("GLOW_COLOR", rgb(glow.color)));
        defines.push(("GLOW_STRENGTH", f(glow.strength)));
    } else if features.node_glow.is_some() {
        // Glow nodes glow, and nothing else does.
        defines.push(("GLOW_COLOR", rgb(DVec3::ZERO)));
        defines.push(("GLOW_STRENGTH", f(0.0)));
    }
    if let Some((count, brightest)) = features.node_glow {
        defines.push(("GLOW_NODES", count.to_string()));
        defines.push(("NODE_GLOW_BRIGHTEST", f(brightest)));
    }
    if on.contains(&Effect::Fog) {
        defines.push(("FOG_DENSITY", f(e.fog_density)));
    }
    if let Some(fog) = e.volumetric.filter(|_| fog_light(options)) {
        defines.push(("FOG_FALLOFF", f(fog.falloff)));
        // Heights in the program's frame.
        defines.push(("FOG_HEIGHT", f(fog.height - features.origin.y)));
        defines.push(("FOG_SAMPLES", fog.samples.to_string()));
        defines.push(("FOG_ANISOTROPY", f(fog.anisotropy)));
    }
    if let Some(gi) = e.global_illumination {
        defines.push(("GI_BOUNCES", gi.max_bounces.to_string()));
    }
    if cone_tile(options, features) > 0 {
        defines.push(("CONE_TILE", q.cone_tile.to_string()));
    }
    if features.inside {
        defines.push(("INSIDE_HUGE", f(INSIDE_HUGE)));
    }
    if features.brute.is_some() {
        defines.push(("BRUTE_STEP", f(q.brute_step)));
        defines.push(("BRUTE_MAX_STEPS", BRUTE_MAX_STEPS.to_string()));
        let method = match q.screen_normals {
            ScreenNormals::Differences => 0,
            ScreenNormals::LeastSquares => 1,
        };
        defines.push(("SCREEN_NORMALS", method.to_string()));
    }
    if materials {
        defines.push(("DEFAULT_MATERIAL", w.material(DEFAULT_MATERIAL.map(f))));
        defines.push(("BOUNCES", q.bounces.to_string()));
    }
    for (name, value) in defines {
        w.line(format!("#define {name} {value}"));
    }
    if materials {
        // A material is a `real16` of its values in `MATERIAL_SPECS` order:
        // the kernel reads each by name (`material.MATERIAL_IOR`).
        for (i, spec) in MATERIAL_SPECS.iter().enumerate() {
            w.line(format!(
                "#define MATERIAL_{} s{i}",
                spec.name.to_uppercase()
            ));
        }
    }
    for effect in &on {
        w.line(format!("#define {}", effect.switch()));
    }
    if features.node_glow.is_some() {
        if !on.contains(&Effect::Glow) {
            w.line(format!("#define {}", Effect::Glow.switch()));
        }
        w.line(format!("#define {NODE_GLOW}"));
    }
    if materials {
        w.line(format!("#define {MATERIALS}"));
    }
    if features.brute.is_some() {
        w.line(format!("#define {BRUTE}"));
    }
    if !features.emitters.is_empty() {
        w.line("/* The bounding spheres of the shapes that give off light. */");
        w.line(format!("#define EMITTERS {}", features.emitters.len()));
        let spheres: Vec<String> = features
            .emitters
            .iter()
            .map(|b| {
                let c = b.centre;
                format!(
                    "(real4)({}, {}, {}, {})",
                    w.float(c.x),
                    w.float(c.y),
                    w.float(c.z),
                    w.float(b.radius)
                )
            })
            .collect();
        w.line(format!(
            "__constant real4 EMITTER_BOUNDS[EMITTERS] = {{{}}};",
            spheres.join(", ")
        ));
    }
    w.line("/* The kernel interface (src/codegen/interface.rs). */");
    w.raw(&interface::defines(options.target));
    w.line("");
}

/// Resolves the kernels' `#ifdef ENABLE_*` / `#endif` blocks (the kernels
/// have no `#else`): keeps the lines of the switches that are on and drops
/// the rest, so a disabled effect leaves no code at all. Other directives
/// pass through.
fn select_blocks(kernel: &str, on: &[&str]) -> String {
    // One entry per open feature block: whether the text around it was
    // being kept.
    let mut outer: Vec<bool> = Vec::new();
    let mut keep = true;
    let mut out = String::with_capacity(kernel.len());
    for line in kernel.lines() {
        let directive = line.trim_start();
        if let Some(name) = directive.strip_prefix("#ifdef ENABLE_") {
            let name = format!("ENABLE_{}", name.trim());
            outer.push(keep);
            keep = keep && on.contains(&name.as_str());
        } else if directive.starts_with("#endif") && !outer.is_empty() {
            keep = outer.pop().expect("checked non-empty");
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
