//! A minimal kernel-source generator standing in for code generation
//! until it lands: the header described in [`crate::render`] plus `DE` and
//! `DE_shade` for spheres, boxes, planes, translation, colour and (smooth)
//! CSG — enough for the renderer's tests. Other nodes are refused.

use std::fmt::Write;

use glam::DVec3;

use super::program::ProgramSource;
use crate::error::{Error, Result};
use crate::ir::{Ir, NodeId, Scalar};
use crate::quality::{Effects, Precision, Quality};
use crate::scene::{CsgOp, Kind, Scene};

/// The marcher and shading, appended after the scene's functions.
pub(crate) const MARCH_CL: &str = include_str!("../../kernels/march.cl");

/// The complete program for `scene` with these settings.
pub(crate) fn emit(scene: &Scene, quality: &Quality, effects: &Effects) -> Result<ProgramSource> {
    let geometry = scene.geometry.as_ref().ok_or(Error::EmptyScene)?;
    let ir = Ir::lower(geometry)?;
    let mut body = Body {
        ir: &ir,
        code: String::new(),
        next: 0,
    };
    let (d, c) = body.node(ir.root(), "p")?;
    let mut source = header(quality, effects);
    let code = body.code;
    writeln!(
        source,
        "real scene_eval(real3 p, __global const real* params, real3* color) {{\n\
         {code}    *color = {c};\n    return {d};\n}}\n\n\
         real DE_shade(real3 p, __global const real* params, real3* color, real* trap) {{\n\
         \x20   *trap = R(1.0);\n    return scene_eval(p, params, color);\n}}\n\n\
         real DE(real3 p, __global const real* params) {{\n\
         \x20   real3 color;\n    return scene_eval(p, params, &color);\n}}\n"
    )
    .expect("write to String");
    source.push_str(MARCH_CL);
    Ok(ProgramSource {
        source,
        precision: quality.precision,
    })
}

/// The header: precision, quality knobs and the effects that are on.
pub(crate) fn header(quality: &Quality, effects: &Effects) -> String {
    let mut h = String::from("#pragma OPENCL FP_CONTRACT OFF\n");
    match quality.precision {
        Precision::F32 => h.push_str(
            "typedef float real;\ntypedef float2 real2;\ntypedef float3 real3;\n\
             typedef float4 real4;\n#define R(x) x##f\n",
        ),
        Precision::F64 => h.push_str(
            "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\ntypedef double real;\n\
             typedef double2 real2;\ntypedef double3 real3;\ntypedef double4 real4;\n\
             #define R(x) x\n",
        ),
    }
    let mut def = |name: &str, value: String| {
        writeln!(h, "#define {name} {value}").expect("write to String");
    };
    def("REAL_TINY", lit(1e-30));
    def("MAX_STEPS", quality.max_steps.to_string());
    def("MAX_DISTANCE", lit(quality.max_distance));
    def("HIT_EPSILON", lit(quality.hit_epsilon));
    def("NORMAL_EPSILON", lit(quality.normal_epsilon));
    def("OVER_RELAXATION", lit(quality.over_relaxation));
    def("SUPERSAMPLING", quality.supersampling.to_string());
    def("GAMMA", lit(effects.gamma));
    def("SKY_TOP", rgb(effects.sky_top));
    def("SKY_BOTTOM", rgb(effects.sky_bottom));
    def("DEFAULT_COLOR", rgb(DVec3::from(crate::cpu::DEFAULT_COLOR)));
    if effects.ambient_occlusion && quality.ao_samples > 0 {
        def("ENABLE_AO", "1".into());
        def("AO_SAMPLES", quality.ao_samples.to_string());
        def("AO_STEP", lit(quality.ao_step));
    }
    if effects.shadows && quality.shadow_steps > 0 {
        def("ENABLE_SHADOWS", "1".into());
        def("SHADOW_STEPS", quality.shadow_steps.to_string());
    }
    if let Some(glow) = effects.glow {
        def("ENABLE_GLOW", "1".into());
        def("GLOW_COLOR", rgb(glow.color));
        def("GLOW_STRENGTH", lit(glow.strength));
    }
    if effects.fog_density > 0.0 {
        def("ENABLE_FOG", "1".into());
        def("FOG_DENSITY", lit(effects.fog_density));
    }
    h.push('\n');
    h
}

/// A literal of type `real`.
fn lit(v: f64) -> String {
    format!("R({v:?})")
}

fn rgb(c: DVec3) -> String {
    format!("(real3)({}, {}, {})", lit(c.x), lit(c.y), lit(c.z))
}

struct Body<'a> {
    ir: &'a Ir,
    code: String,
    next: usize,
}

impl Body<'_> {
    fn scalar(s: Scalar) -> String {
        match s {
            Scalar::Baked(v) => lit(v),
            Scalar::Dynamic(slot) => format!("params[{slot}]"),
        }
    }

    fn vector(v: [Scalar; 3]) -> String {
        let [x, y, z] = v.map(Self::scalar);
        format!("(real3)({x}, {y}, {z})")
    }

    fn fresh(&mut self) -> usize {
        self.next += 1;
        self.next
    }

    fn line(&mut self, text: &str) {
        self.code.push_str("    ");
        self.code.push_str(text);
        self.code.push('\n');
    }

    /// Emits the node at point expression `p`; returns its distance and
    /// colour variables.
    fn node(&mut self, id: NodeId, p: &str) -> Result<(String, String)> {
        let n = self.fresh();
        let (d, c) = (format!("d{n}"), format!("c{n}"));
        let leaf = |me: &mut Self, expr: String| {
            me.line(&format!("real {d} = {expr};"));
            me.line(&format!("real3 {c} = DEFAULT_COLOR;"));
        };
        match self.ir.node(id) {
            Kind::Sphere { radius } => {
                leaf(self, format!("length({p}) - {}", Self::scalar(*radius)))
            }
            Kind::Cuboid { half_extents } => {
                let b = Self::vector(*half_extents);
                self.line(&format!("real3 q{n} = fabs({p}) - {b};"));
                leaf(
                    self,
                    format!(
                        "length(fmax(q{n}, (real3)(R(0.0)))) \
                         + fmin(fmax(q{n}.x, fmax(q{n}.y, q{n}.z)), R(0.0))"
                    ),
                );
            }
            Kind::Plane { normal, offset } => {
                let v = Self::vector(*normal);
                self.line(&format!("real3 n{n} = {v};"));
                leaf(
                    self,
                    format!(
                        "dot({p}, n{n} / fmax(length(n{n}), REAL_TINY)) + {}",
                        Self::scalar(*offset)
                    ),
                );
            }
            Kind::Translate { offset, child } => {
                let q = format!("p{n}");
                self.line(&format!("real3 {q} = {p} - {};", Self::vector(*offset)));
                return self.node(*child, &q);
            }
            Kind::Color { color, child } => {
                let (cd, _) = self.node(*child, p)?;
                self.line(&format!("real {d} = {cd};"));
                self.line(&format!("real3 {c} = {};", Self::vector(*color)));
            }
            Kind::Csg {
                op,
                smoothing,
                a,
                b,
            } => {
                let (da, ca) = self.node(*a, p)?;
                let (db, cb) = self.node(*b, p)?;
                let (sa, sb) = match op {
                    CsgOp::Union => ("", ""),
                    CsgOp::Subtract => ("-", ""),
                    CsgOp::Intersect => ("-", "-"),
                };
                self.line(&format!("real x{n} = {sa}{da};"));
                self.line(&format!("real y{n} = {sb}{db};"));
                let k = smoothing.map_or_else(|| lit(0.0), Self::scalar);
                self.line(&format!("real k{n} = {k};"));
                self.line(&format!(
                    "real h{n} = k{n} > R(0.0) ? fmax(k{n} - fabs(x{n} - y{n}), R(0.0)) / k{n} : R(0.0);"
                ));
                self.line(&format!("real m{n} = h{n} * h{n} * R(0.5);"));
                self.line(&format!(
                    "real s{n} = fmin(x{n}, y{n}) - m{n} * k{n} * R(0.5);"
                ));
                let sign = if *op == CsgOp::Union { "" } else { "-" };
                self.line(&format!("real {d} = {sign}s{n};"));
                self.line(&format!(
                    "real3 {c} = x{n} < y{n} ? mix({ca}, {cb}, m{n}) : mix({cb}, {ca}, m{n});"
                ));
            }
            other => {
                return Err(Error::OpenCl(format!(
                    "the stand-in kernel generator cannot emit `{}` yet",
                    other.name()
                )));
            }
        }
        Ok((d, c))
    }
}
