//! User-defined shapes: a Rust distance function (the CPU reference) and
//! its OpenCL C twin, usable in scenes like any built-in node.
//!
//! ```
//! use fractal_sdf::prelude::*;
//! use fractal_sdf::cpu;
//! use fractal_sdf::scene::{CustomShape, Rule};
//!
//! // A gyroid shell, |sin x cos y + sin y cos z + sin z cos x| / 1.5 - t, a
//! // bound because the gradient of the trigonometric sum is at most 1.5.
//! let gyroid = CustomShape::new(
//!     "gyroid",
//!     &[("thickness", Rule::NonNegative)],
//!     |p, a| {
//!         let g = p.x.sin() * p.y.cos() + p.y.sin() * p.z.cos() + p.z.sin() * p.x.cos();
//!         g.abs() / 1.5 - a[0]
//!     },
//!     "real g = sin(p.x) * cos(p.y) + sin(p.y) * cos(p.z) + sin(p.z) * cos(p.x);
//!      return fabs(g) / R(1.5) - thickness;",
//! )?;
//! let node = gyroid.node([0.1]).intersect(sphere(2.0));
//! let eval = cpu::Evaluator::new(&node)?;
//! assert!(eval.distance(dvec3(0.0, 0.0, 0.0)) < 0.0);
//! # Ok::<(), fractal_sdf::Error>(())
//! ```

use std::any::TypeId;
use std::fmt;
use std::sync::Arc;

use glam::DVec3;

use super::names;
use super::rule::Rule;
use crate::error::{Error, Result, fmt_value};
use crate::expr::{Distance, Formula, OpenCl, Printer, Program, Shape, Signature, trace};
use crate::math::{V3, v3};

/// The Rust distance function of a custom shape: the point and the
/// parameter values in declaration order.
pub type CpuDistance = dyn Fn(DVec3, &[f64]) -> f64 + Send + Sync;

/// The Rust membership test of an inside shape (see
/// [`InsideShape`](super::InsideShape)): the point and the parameter values
/// in declaration order.
pub type CpuInside = dyn Fn(DVec3, &[f64]) -> bool + Send + Sync;

/// The magnitude of an inside shape's value: `-INSIDE_HUGE` in the set,
/// `INSIDE_HUGE` out of it. Larger than any distance a scene measures, so
/// unions, intersections and subtractions of it with distance estimates
/// keep the membership of the result in its sign, and a march never
/// mistakes it for a distance to step by (see
/// [`InsideShape`](super::InsideShape)); small enough that its square (soft
/// shadows square distances), even scaled a thousandfold, stays finite in
/// `f32`.
pub const INSIDE_HUGE: f64 = 1e15;

/// How far from the origin an inside shape's bounds may reach: a thousandth
/// of [`INSIDE_HUGE`], so that the sign-only value stays larger than any
/// distance measured around the shape, and well within what `F32` kernels
/// compute with.
pub const MAX_INSIDE_REACH: f64 = 1e12;

/// What a custom shape's functions compute.
enum Form {
    /// A distance estimate.
    Distance(Box<CpuDistance>),
    /// A membership test, clipped to bounds.
    Inside {
        test: Box<CpuInside>,
        bounds: InsideBounds,
    },
}

/// The region an inside shape's set lies in, stated by its author: the
/// set is clipped to it, code generation marches by brute force only
/// within it, and it is the shape's bound for pruning.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum InsideBounds {
    /// A ball.
    Sphere {
        /// The ball's centre.
        centre: DVec3,
        /// Its radius, positive.
        radius: f64,
    },
    /// An axis-aligned box.
    Cuboid {
        /// The box's centre.
        centre: DVec3,
        /// Its half extents along x, y and z, each positive.
        half_extents: DVec3,
    },
}

impl InsideBounds {
    /// The ball of `radius` around `centre`.
    #[must_use]
    pub fn sphere(centre: DVec3, radius: f64) -> Self {
        InsideBounds::Sphere { centre, radius }
    }

    /// The axis-aligned box around `centre` with `half_extents`.
    #[must_use]
    pub fn cuboid(centre: DVec3, half_extents: DVec3) -> Self {
        InsideBounds::Cuboid {
            centre,
            half_extents,
        }
    }

    /// Whether `p` lies in the region (its boundary included).
    #[must_use]
    pub fn contains(&self, p: DVec3) -> bool {
        match *self {
            InsideBounds::Sphere { centre, radius } => (p - centre).length() <= radius,
            InsideBounds::Cuboid {
                centre,
                half_extents,
            } => ((p - centre).abs() - half_extents).max_element() <= 0.0,
        }
    }

    /// The smallest ball around the region: its centre and radius.
    #[must_use]
    pub fn ball(&self) -> (DVec3, f64) {
        match *self {
            InsideBounds::Sphere { centre, radius } => (centre, radius),
            InsideBounds::Cuboid {
                centre,
                half_extents,
            } => (centre, half_extents.length()),
        }
    }

    /// Why the region cannot bound a shape, or `None`: every value finite,
    /// the radius and half extents positive, and the region within
    /// [`MAX_INSIDE_REACH`] of the origin.
    fn problem(&self) -> Option<String> {
        let shape = self.shape_problem();
        if shape.is_some() {
            return shape;
        }
        let (centre, radius) = self.ball();
        let reach = centre.length() + radius;
        (reach > MAX_INSIDE_REACH).then(|| {
            format!(
                "the bounds reach {} from the origin, past {}: an inside shape's value \
                 outside its set is {}, which must exceed every distance in its scene",
                fmt_value(reach),
                fmt_value(MAX_INSIDE_REACH),
                fmt_value(INSIDE_HUGE)
            )
        })
    }

    /// Why the region's own values cannot bound a shape, or `None`.
    fn shape_problem(&self) -> Option<String> {
        let finite = |v: DVec3| v.is_finite();
        match *self {
            InsideBounds::Sphere { centre, radius } => {
                if !finite(centre) {
                    Some(format!(
                        "the bounding sphere's centre {centre} is not finite"
                    ))
                } else if !(radius.is_finite() && radius > 0.0) {
                    Some(format!(
                        "the bounding sphere's radius must be positive and finite, got {radius}"
                    ))
                } else {
                    None
                }
            }
            InsideBounds::Cuboid {
                centre,
                half_extents,
            } => {
                if !finite(centre) {
                    Some(format!("the bounding box's centre {centre} is not finite"))
                } else if !(finite(half_extents) && half_extents.min_element() > 0.0) {
                    Some(format!(
                        "the bounding box's half extents must be positive and finite, got \
                         {half_extents}"
                    ))
                } else {
                    None
                }
            }
        }
    }

    /// A WGSL expression, true where `p` lies outside the region.
    fn wgsl_outside(&self) -> String {
        let lit = |v: f64| format!("{:?}", v as f32);
        let vec = |v: DVec3| format!("real3({}, {}, {})", lit(v.x), lit(v.y), lit(v.z));
        match *self {
            InsideBounds::Sphere { centre, radius } => {
                format!("length(p - {}) > {}", vec(centre), lit(radius))
            }
            InsideBounds::Cuboid {
                centre,
                half_extents,
            } => format!(
                "any(abs(p - {}) - {} > real3(0.0))",
                vec(centre),
                vec(half_extents)
            ),
        }
    }

    /// An OpenCL C expression, true where `p` lies outside the region.
    fn opencl_outside(&self) -> String {
        let lit = |v: f64| format!("R({v:?})");
        let vec = |v: DVec3| format!("(real3)({}, {}, {})", lit(v.x), lit(v.y), lit(v.z));
        match *self {
            InsideBounds::Sphere { centre, radius } => {
                format!("length(p - {}) > {}", vec(centre), lit(radius))
            }
            InsideBounds::Cuboid {
                centre,
                half_extents,
            } => {
                let q = format!("fabs(p - {}) - {}", vec(centre), vec(half_extents));
                format!("any(isgreater({q}, (real3)(R(0.0))))")
            }
        }
    }
}

/// A user-defined shape. Cheap to clone (shared).
///
/// The OpenCL body is the body of a function
/// `real custom_NAME(real3 p, real PARAM1, real PARAM2, ...)` that returns
/// the distance; it may use `real`, `real2`, `real3`, `R(x)` for literals and
/// every OpenCL built-in. It is compiled in only when a scene uses the
/// shape. The CPU function runs in `f64` (also when the CPU reference
/// evaluates in `f32`).
///
/// # Names
///
/// The name and the parameter names become OpenCL identifiers, so they
/// must be ASCII identifiers (`[A-Za-z_][A-Za-z0-9_]*`, at most 48
/// characters). A parameter may not be called `p` (the point) nor take a
/// name that OpenCL C or the generated program already gives a meaning to:
///
/// - OpenCL C keywords, qualifiers and type names, vector types included
///   (`kernel`, `float3`, `real`, `real3`), and built-in functions (`sin`,
///   `length`, `clamp`, `half_sqrt`, and the families `convert_*`,
///   `as_TYPE`, `vload*`, `native_*`, `atomic_*`, ...);
/// - names reserved for the compiler: starting with `__`, or with `_` and
///   a capital;
/// - names in capitals (no lower-case letter), which macros use: the
///   generated header's (`DETAIL`, `GAMMA`, `R`, `MAX_STEPS`,
///   `CAMERA_ORIGIN`, ...) and OpenCL's (`M_PI`, `FLT_MAX`);
/// - `params` (the generated functions' buffer of dynamic parameter
///   values) and the prefixes of generated names: `custom_`, `inside_`, `sd_`,
///   `march_`, `cl_`, and the specialised Mandelbulbs `mandelbulb_pN`;
/// - every other name the generated program defines or calls (its
///   typedefs, helper functions such as `menger`, `DE` and `DE_shade`),
///   read from the program's own header, helper library and kernels.
///
/// The shape's function, `custom_NAME`, may not be a name the generated
/// program already defines or calls. Write parameter names in lower case
/// (`radius`, `half_length`) and none of these rules gets in the way. A
/// refused name is an [`Error::CustomShape`] saying which rule it breaks.
///
/// # Bodies
///
/// The body is emitted inside the shape's function, so it is refused
/// ([`Error::CustomShape`]) before anything is compiled if it could not
/// stay there or would change the program around it: [`CustomShape::new`]
/// refuses a NUL byte or another control character (tabs and line ends
/// are fine), a `}` that closes the function early (what follows would
/// stand at file scope, where it could define `DE` or `DE_shade` again)
/// or braces left open; code generation refuses a `#define` or `#undef`
/// of a name the generated program uses.
///
/// # Build errors
///
/// The body is code you write and is emitted as given. If the OpenCL
/// compiler rejects it, rendering fails with
/// [`Error::CustomShapeBuild`], which names the shape and quotes the line
/// of the body (counted from 1, the first line of the string you gave) the
/// compiler complained about.
///
/// # One definition per name
///
/// A scene may use a shape many times, but one name stands for one
/// definition, because the program holds one `custom_NAME`. Two handles
/// are the same shape when one is a clone of the other, or when they have
/// the same name, parameters (names and rules) and OpenCL body and their
/// CPU functions are of the same type *that holds no data*: a function
/// item or a closure that captures nothing, whose type fixes what it
/// computes. A closure that captures values, a function pointer or a boxed
/// closure may compute something else in each handle, so such shapes are
/// the same only as clones of one handle: define the shape once and clone
/// it. Lowering refuses two different shapes of one name in a scene
/// ([`Error::CustomShape`]).
#[derive(Clone)]
pub struct CustomShape(Arc<Inner>);

struct Inner {
    name: String,
    params: Vec<(String, Rule)>,
    cpu: Form,
    /// The CPU function's type, when it holds no data (so the type alone
    /// says what it computes); `None` otherwise.
    cpu_type: Option<TypeId>,
    opencl: String,
    /// The traced formula of a shape written once ([`CustomShape::formula`]
    /// or [`CustomShape::parse`]); `opencl` is then its printed function.
    program: Option<Arc<Program>>,
    /// The text of a shape defined by [`CustomShape::parse`].
    text: Option<String>,
    /// A built-in inside shape's test in WGSL: the body of
    /// `fn inside_NAME(p: real3, PARAM: real, ...) -> bool`.
    wgsl: Option<&'static str>,
}

impl CustomShape {
    /// Defines a shape called `name` with parameters `(name, rule)`, a CPU
    /// distance function and its OpenCL C body.
    ///
    /// # Errors
    /// [`Error::CustomShape`] if a name is not a valid identifier or is
    /// reserved (see [Names](CustomShape#names)), a parameter name repeats
    /// or is `p`, or the body is empty or cannot be emitted as given (see
    /// [Bodies](CustomShape#bodies)).
    pub fn new<F>(name: &str, params: &[(&str, Rule)], cpu: F, opencl_body: &str) -> Result<Self>
    where
        F: Fn(DVec3, &[f64]) -> f64 + Send + Sync + 'static,
    {
        let cpu_type = (std::mem::size_of::<F>() == 0).then(TypeId::of::<F>);
        Self::define(
            name,
            params,
            Form::Distance(Box::new(cpu)),
            cpu_type,
            opencl_body,
        )
    }

    /// Defines a shape from one formula, written once: the CPU reference
    /// runs it in `f64`, code generation traces it into the expression IR
    /// and prints its OpenCL function, and its bounds come from interval
    /// arithmetic over it (so meshing needs no `--bounds` where the
    /// formula bounds its shape). Its parameters are the `(name, rule)`s,
    /// in the order `params` gets their values.
    ///
    /// ```
    /// use fractal_sdf::expr::{Distance, Num};
    /// use fractal_sdf::expr::V3;
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::cpu;
    /// use fractal_sdf::scene::{CustomShape, Rule};
    ///
    /// /// A box with rounded edges: half extents `b`, rounding `r`.
    /// struct Rounded;
    ///
    /// impl Distance for Rounded {
    ///     fn distance<N: Num>(&self, p: V3<N>, a: &[N]) -> N {
    ///         let q = p.abs() - V3::splat(a[0] - a[1]);
    ///         q.max_s(N::zero()).length() + q.max_element().min(N::zero()) - a[1]
    ///     }
    /// }
    ///
    /// let shape = CustomShape::formula("rounded", &[("b", Rule::Positive), ("r", Rule::NonNegative)], Rounded)?;
    /// let eval = cpu::Evaluator::new(&shape.node([1.0, 0.25]))?;
    /// assert!((eval.distance(dvec3(2.0, 0.0, 0.0)) - 1.0).abs() < 1e-12);
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::CustomShape`] for a name or parameter as in
    /// [`CustomShape::new`].
    pub fn formula<F: Distance>(name: &str, params: &[(&str, Rule)], formula: F) -> Result<Self> {
        let program = trace_formula(&formula, params.len());
        let cpu_type = (std::mem::size_of::<F>() == 0).then(TypeId::of::<F>);
        let cpu = move |p: DVec3, a: &[f64]| formula.distance(V3::from(p), a);
        Self::define_program(name, params, program, Box::new(cpu), cpu_type)
    }

    /// Defines a shape from a text formula (see [`Formula`] for the
    /// language): the formula is parsed, checked and traced once, and
    /// works as [`CustomShape::formula`] does. Scene files and the
    /// command line's `--formula` define shapes this way.
    ///
    /// ```
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::cpu;
    /// use fractal_sdf::scene::{CustomShape, Rule};
    ///
    /// let shape = CustomShape::parse("ball", &[("r", Rule::Positive)], "length(p) - r")?;
    /// let eval = cpu::Evaluator::new(&shape.node([1.0]))?;
    /// assert_eq!(eval.distance(dvec3(3.0, 0.0, 0.0)), 2.0);
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::Formula`] with the line and column of a syntax error, an
    /// unknown name or a wrong type; [`Error::CustomShape`] for a name or
    /// parameter as in [`CustomShape::new`].
    pub fn parse(name: &str, params: &[(&str, Rule)], text: &str) -> Result<Self> {
        let names: Vec<&str> = params.iter().map(|(n, _)| *n).collect();
        let formula = Formula::parse(text, &names).map_err(|e| Error::Formula {
            name: name.chars().take(48).collect(),
            line: e.line,
            column: e.column,
            message: e.message,
        })?;
        let program = formula.program();
        let run = program.clone();
        // The traced program runs faster than the parsed text.
        let cpu = move |p: DVec3, a: &[f64]| {
            let mut inputs = vec![p.x, p.y, p.z];
            inputs.extend_from_slice(a);
            run.run(&inputs).first().copied().unwrap_or(f64::NAN)
        };
        let mut shape = Self::define_program(name, params, program, Box::new(cpu), None)?;
        if let Some(inner) = Arc::get_mut(&mut shape.0) {
            inner.text = Some(text.to_string());
        }
        Ok(shape)
    }

    /// The text of a shape defined by [`CustomShape::parse`] (how a scene
    /// file writes it back); `None` for other shapes.
    #[must_use]
    pub fn formula_text(&self) -> Option<&str> {
        self.0.text.as_deref()
    }

    fn define_program(
        name: &str,
        params: &[(&str, Rule)],
        program: Program,
        cpu: Box<CpuDistance>,
        cpu_type: Option<TypeId>,
    ) -> Result<Self> {
        check_names(name, params)?;
        let opencl = print_definition(name, params.iter().map(|(n, _)| *n), &OpenCl, &program)?;
        Ok(CustomShape(Arc::new(Inner {
            name: name.into(),
            params: params.iter().map(|(n, r)| ((*n).to_string(), *r)).collect(),
            cpu: Form::Distance(cpu),
            cpu_type,
            opencl,
            program: Some(Arc::new(program)),
            text: None,
            wgsl: None,
        })))
    }

    /// The function `custom_NAME(p, params…)` of a shape defined by a
    /// program, printed by `to` (the OpenCL text is kept at definition).
    pub(crate) fn definition(&self, to: &dyn Printer, program: &Program) -> Result<String> {
        print_definition(
            &self.0.name,
            self.0.params.iter().map(|(n, _)| n.as_str()),
            to,
            program,
        )
    }

    /// Defines an inside shape: see [`InsideShape::new`](super::InsideShape::new).
    pub(super) fn new_inside<F>(
        name: &str,
        params: &[(&str, Rule)],
        bounds: InsideBounds,
        test: F,
        opencl_body: &str,
    ) -> Result<Self>
    where
        F: Fn(DVec3, &[f64]) -> bool + Send + Sync + 'static,
    {
        if let Some(why) = bounds.problem() {
            return Err(Error::CustomShape {
                name: name.chars().take(48).collect(),
                reason: why,
            });
        }
        let cpu_type = (std::mem::size_of::<F>() == 0).then(TypeId::of::<F>);
        let form = Form::Inside {
            test: Box::new(test),
            bounds,
        };
        Self::define(name, params, form, cpu_type, opencl_body)
    }

    fn define(
        name: &str,
        params: &[(&str, Rule)],
        cpu: Form,
        cpu_type: Option<TypeId>,
        opencl_body: &str,
    ) -> Result<Self> {
        let bad = |reason: String| Error::CustomShape {
            name: name.chars().take(48).collect(),
            reason,
        };
        check_names(name, params)?;
        if opencl_body.trim().is_empty() {
            return Err(bad("the OpenCL body is empty".into()));
        }
        if let Some(why) = body_problem(opencl_body) {
            return Err(bad(why));
        }
        Ok(CustomShape(Arc::new(Inner {
            name: name.into(),
            params: params.iter().map(|(n, r)| ((*n).to_string(), *r)).collect(),
            cpu,
            cpu_type,
            opencl: opencl_body.into(),
            program: None,
            text: None,
            wgsl: None,
        })))
    }

    /// The shape's name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.0.name
    }

    /// The OpenCL body as given, or for a shape written once
    /// ([`CustomShape::formula`], [`CustomShape::parse`]) its printed
    /// function.
    #[must_use]
    pub fn opencl_body(&self) -> &str {
        &self.0.opencl
    }

    /// The traced formula of a shape written once; `None` for a shape
    /// with an OpenCL body of its own.
    #[must_use]
    pub fn program(&self) -> Option<&Program> {
        self.0.program.as_deref()
    }

    /// A box holding the surface of a shape written once with these
    /// parameter values, from interval arithmetic over its formula (see
    /// [`crate::expr::surface_box`]); `None` where the formula does not
    /// bound its shape, or for other shapes.
    #[must_use]
    pub fn surface_box(&self, args: &[f64]) -> Option<[DVec3; 2]> {
        crate::expr::surface_box(self.program()?, args)
    }

    /// The parameters' names and rules, in order.
    pub fn params(&self) -> impl Iterator<Item = (&str, Rule)> {
        self.0.params.iter().map(|(n, r)| (n.as_str(), *r))
    }

    /// Number of parameters.
    #[must_use]
    pub fn arity(&self) -> usize {
        self.0.params.len()
    }

    /// Evaluates the CPU distance function. For an inside shape, the
    /// value scenes compose: `-INSIDE_HUGE` where `p` is in the set (within
    /// the bounds), `INSIDE_HUGE` elsewhere.
    #[must_use]
    pub fn distance(&self, p: DVec3, args: &[f64]) -> f64 {
        match &self.0.cpu {
            Form::Distance(f) => f(p, args),
            Form::Inside { test, bounds } => {
                if bounds.contains(p) && test(p, args) {
                    -INSIDE_HUGE
                } else {
                    INSIDE_HUGE
                }
            }
        }
    }

    /// The bounds of an inside shape (see
    /// [`InsideShape`](super::InsideShape)); `None` for a shape with a
    /// distance estimate.
    #[must_use]
    pub fn inside_bounds(&self) -> Option<InsideBounds> {
        match &self.0.cpu {
            Form::Distance(_) => None,
            Form::Inside { bounds, .. } => Some(*bounds),
        }
    }

    /// The OpenCL function name, `custom_NAME`: the shape's value as scenes
    /// compose it (the distance, or an inside shape's `±INSIDE_HUGE`).
    #[must_use]
    pub fn function_name(&self) -> String {
        format!("custom_{}", self.0.name)
    }

    /// The OpenCL function an inside shape's body defines, `inside_NAME`,
    /// or `None` for a shape with a distance estimate.
    #[must_use]
    pub fn test_name(&self) -> Option<String> {
        self.inside_bounds()
            .map(|_| format!("inside_{}", self.0.name))
    }

    /// The OpenCL C function definition of the body: `custom_NAME`
    /// returning a distance, or an inside shape's `inside_NAME` returning
    /// nonzero in the set. The signature takes one line, the closing brace
    /// another.
    #[must_use]
    pub fn opencl_definition(&self) -> String {
        if self.0.program.is_some() {
            return self.0.opencl.clone();
        }
        let (ty, name) = match self.test_name() {
            Some(test) => ("int", test),
            None => ("real", self.function_name()),
        };
        format!(
            "{ty} {name}(real3 p{}) {{\n{}\n}}\n",
            self.signature_params(),
            self.0.opencl.trim_end()
        )
    }

    /// For an inside shape, the definition of `custom_NAME`, the value
    /// scenes compose: `INSIDE_HUGE` outside the bounds (where the test is
    /// not run) or the set, `-INSIDE_HUGE` in it. `None` for a shape with a
    /// distance estimate.
    #[must_use]
    pub fn opencl_wrapper(&self) -> Option<String> {
        let bounds = self.inside_bounds()?;
        let test = self.test_name()?;
        let args = self.params_as(|n| format!(", {n}"));
        Some(format!(
            "real {}(real3 p{}) {{\n    if ({}) {{\n        return INSIDE_HUGE;\n    }}\n    \
             return {test}(p{args}) ? -INSIDE_HUGE : INSIDE_HUGE;\n}}\n",
            self.function_name(),
            self.signature_params(),
            bounds.opencl_outside(),
        ))
    }

    /// A built-in inside shape with its test in WGSL too (`body`, the body
    /// of `fn inside_NAME(p: real3, PARAM: real, ...) -> bool`): the WGSL
    /// backend draws it.
    pub(super) fn with_wgsl_test(mut self, body: &'static str) -> Self {
        Arc::get_mut(&mut self.0)
            .expect("a shape just defined is not shared")
            .wgsl = Some(body);
        self
    }

    /// For an inside shape with a WGSL test, the WGSL definitions of
    /// `inside_NAME` and of `custom_NAME`, the value scenes compose
    /// (`INSIDE_HUGE` outside the bounds or the set, `-INSIDE_HUGE` in
    /// it), as [`opencl_wrapper`](Self::opencl_wrapper) in OpenCL C.
    /// `None` for other shapes.
    pub(crate) fn wgsl_inside_definition(&self) -> Option<String> {
        let bounds = self.inside_bounds()?;
        let body = self.0.wgsl?;
        let test = self.test_name()?;
        let params = self.params_as(|n| format!(", {n}: real"));
        let args = self.params_as(|n| format!(", {n}"));
        Some(format!(
            "fn {test}(p: real3{params}) -> bool {{\n{}\n}}\n\
             fn {}(p: real3{params}) -> real {{\n    if ({}) {{\n        return INSIDE_HUGE;\n    \
             }}\n    return select(INSIDE_HUGE, -INSIDE_HUGE, {test}(p{args}));\n}}\n",
            body.trim_end(),
            self.function_name(),
            bounds.wgsl_outside(),
        ))
    }

    fn signature_params(&self) -> String {
        self.params_as(|n| format!(", real {n}"))
    }

    /// Each parameter's name written by `item`, one after another.
    fn params_as(&self, item: impl Fn(&str) -> String) -> String {
        self.0.params.iter().map(|(n, _)| item(n)).collect()
    }

    /// What tells `other` apart from this shape, or `None` if the two are
    /// the same shape (see [One definition per
    /// name](CustomShape#one-definition-per-name)).
    #[must_use]
    pub fn difference(&self, other: &Self) -> Option<&'static str> {
        let (a, b) = (&self.0, &other.0);
        if Arc::ptr_eq(a, b) {
            None
        } else if a.name != b.name {
            Some("the names differ")
        } else if a.params != b.params {
            Some("the parameters (names or rules) differ")
        } else if let (Some(x), Some(y)) = (&a.program, &b.program) {
            // A formula written once is its program: the CPU runs it too.
            (x != y).then_some("the formulas differ")
        } else if a.opencl != b.opencl {
            Some("the OpenCL bodies differ")
        } else if a.wgsl != b.wgsl {
            Some("the WGSL bodies differ")
        } else if self.inside_bounds() != other.inside_bounds() {
            Some("the bounds (or whether it is an inside test) differ")
        } else if a.cpu_type.is_none() || b.cpu_type.is_none() {
            Some(
                "a CPU function holds data (a closure that captures values, a function pointer \
                 or a boxed closure), so only clones of one handle are known to agree: define \
                 the shape once and clone it",
            )
        } else if a.cpu_type != b.cpu_type {
            Some("the CPU functions differ")
        } else {
            None
        }
    }
}

/// Two handles are equal when they are the same shape: see [One definition
/// per name](CustomShape#one-definition-per-name).
impl PartialEq for CustomShape {
    fn eq(&self, other: &Self) -> bool {
        self.difference(other).is_none()
    }
}

impl fmt::Debug for CustomShape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("CustomShape")
            .field("name", &self.0.name)
            .field("params", &self.0.params)
            .finish_non_exhaustive()
    }
}

/// Traces `formula` with inputs `p.x, p.y, p.z` and `params` parameters.
fn trace_formula<F: Distance>(formula: &F, params: usize) -> Program {
    let n = u32::try_from(params + 3).unwrap_or(u32::MAX);
    trace(n, |a| vec![formula.distance(v3(a[0], a[1], a[2]), &a[3..])])
}

/// Checks a shape's name and its parameters' names.
fn check_names(name: &str, params: &[(&str, Rule)]) -> Result<()> {
    let bad = |reason: String| Error::CustomShape {
        name: name.chars().take(48).collect(),
        reason,
    };
    check_identifier(name).map_err(|r| bad(format!("name {r}")))?;
    let mut seen: Vec<&str> = Vec::new();
    for (param, _) in params {
        check_identifier(param).map_err(|r| bad(format!("parameter `{param}` {r}")))?;
        if *param == "p" {
            return Err(bad("parameter `p` shadows the point `p`".into()));
        }
        if let Some(why) = names::reserved(param) {
            return Err(bad(format!("parameter `{param}` {why}")));
        }
        if seen.contains(param) {
            return Err(bad(format!("parameter name `{param}` is used twice")));
        }
        seen.push(param);
    }
    Ok(())
}

/// Why a custom shape's OpenCL body cannot stay inside the shape's
/// function, or `None`: a NUL or other control character (which the
/// compiler would stop at or misread), or braces that close the function
/// early or leave it open (code after an early close would stand at file
/// scope, where it could define `DE` or any generated name again). Lines
/// are counted from 1, the body's first line. Code generation refuses
/// `#define`s of generated names as well.
fn body_problem(body: &str) -> Option<String> {
    let line_of = |offset: usize| body[..offset].matches('\n').count() + 1;
    if let Some((at, c)) = body
        .char_indices()
        .find(|&(_, c)| c.is_control() && !matches!(c, '\t' | '\n' | '\r'))
    {
        let what = if c == '\0' {
            "a NUL byte".to_string()
        } else {
            format!("the control character U+{:04X}", u32::from(c))
        };
        return Some(format!(
            "the OpenCL body contains {what} (line {} of the body)",
            line_of(at)
        ));
    }
    let code = super::names::strip_comments(body);
    let mut depth = 0usize;
    let mut quote = None;
    let mut escaped = false;
    for (at, c) in code.char_indices() {
        if let Some(q) = quote {
            if escaped {
                escaped = false;
            } else if c == '\\' {
                escaped = true;
            } else if c == q {
                quote = None;
            }
            continue;
        }
        match c {
            '"' | '\'' => quote = Some(c),
            '{' => depth += 1,
            '}' if depth == 0 => {
                return Some(format!(
                    "the OpenCL body closes a brace it did not open (line {} of the body): \
                     what follows would stand outside the shape's function",
                    line_of(at)
                ));
            }
            '}' => depth -= 1,
            _ => {}
        }
    }
    if depth > 0 {
        return Some(format!(
            "the OpenCL body leaves {depth} brace(s) open: the shape's function would not end"
        ));
    }
    None
}

fn check_identifier(s: &str) -> std::result::Result<(), String> {
    let mut chars = s.chars();
    let first_ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    if !first_ok || !chars.all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(format!(
            "`{s}` is not an identifier ([A-Za-z_][A-Za-z0-9_]*)"
        ));
    }
    if s.len() > 48 {
        return Err(format!("`{s}` is longer than 48 characters"));
    }
    Ok(())
}

/// The function `custom_NAME(p, params…)` computing `program`, printed by
/// `to`.
fn print_definition<'n>(
    name: &str,
    params: impl Iterator<Item = &'n str>,
    to: &dyn Printer,
    program: &Program,
) -> Result<String> {
    let function = format!("custom_{name}");
    let mut signature_params = vec![("p", Shape::Vec3)];
    signature_params.extend(params.map(|n| (n, Shape::Scalar)));
    let signature = Signature {
        name: &function,
        params: &signature_params,
        result: Shape::Scalar,
    };
    to.function(&signature, program)
        .map_err(|e| Error::CustomShape {
            name: name.into(),
            reason: e.to_string(),
        })
}
