//! Hostile numbers through the public API: every parameter of every node
//! kind (driven by the node vocabulary through `testing::parameter_sites`),
//! baked, as a dynamic default and set dynamically, and every camera,
//! light, quality and effects value, each replaced by NaN, ±infinity, ±0,
//! ±1e300, 1e-300, `f32::MAX`, `f32::MIN_POSITIVE` and 1e30; and
//! degenerate vectors (zero, tiny, huge, NaN) wherever a direction is
//! given.
//!
//! Every case ends in one of two ways, and no case panics:
//! - a typed error whose message names the node (or `camera`, `light[0]`,
//!   `quality`, `effects`) and the parameter;
//! - an accepted value: the CPU reference is finite (distance, colour,
//!   trap) in `f64`, and in `f32` where an `F32` program accepts the value;
//!   code generation succeeds for `F64` and, where accepted, `F32`; and for
//!   a sample of the accepted cases a rendered 8 × 6 draft image agrees with
//!   the CPU reference's march on the hit mask.
//!
//! The test prints a summary (cases, errors, accepted, rendered).

use crate::gpu;

use std::panic::{AssertUnwindSafe, catch_unwind};

use fractal_sdf::codegen::{self, Options};
use fractal_sdf::cpu::{self, Evaluator};
use fractal_sdf::math::F32_LIMITS;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Glow;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{RenderOptions, Renderer};
use fractal_sdf::scene::Axis;
use fractal_sdf::scene::Mandelbulb;
use fractal_sdf::scene::Menger;
use fractal_sdf::scene::Param;
use fractal_sdf::scene::QuaternionJulia;
use fractal_sdf::scene::Sierpinski;
use fractal_sdf::scene::capped_cone;
use fractal_sdf::scene::ellipsoid;
use fractal_sdf::scene::octahedron;
use fractal_sdf::scene::{CustomShape, Rule};
use fractal_sdf::testing::{parameter_sites, substitute};
use glam::Vec3;

/// The hostile values.
const VALUES: [f64; 11] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -0.0,
    1e300,
    -1e300,
    1e-300,
    f32::MAX as f64,
    f32::MIN_POSITIVE as f64,
    1e30,
];

/// How a value reaches a parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Mode {
    Baked,
    DynamicDefault,
    DynamicSet,
}

/// Points where the CPU reference is evaluated.
fn points() -> Vec<DVec3> {
    vec![
        DVec3::ZERO,
        dvec3(0.3, 0.2, 0.1),
        dvec3(1.0, 1.0, 1.0),
        dvec3(-2.0, 0.5, 3.0),
        dvec3(0.0, 4.0, 0.0),
        dvec3(10.0, -10.0, 10.0),
        dvec3(1e3, 0.0, -1e3),
        camera().position,
    ]
}

fn camera() -> Camera {
    Camera::look_at(dvec3(0.0, 1.0, 4.0), DVec3::ZERO)
}

fn child() -> Node {
    cuboid(dvec3(0.4, 0.3, 0.3))
}

/// One node of every kind, each with a child where it takes one.
fn kinds() -> Vec<Node> {
    let shell = CustomShape::new(
        "shell",
        &[("radius", Rule::NonNegative), ("offset", Rule::Finite)],
        |p, a| (p.length() - a[0]).abs() - 0.05 + 0.0 * a[1],
        "return fabs(length(p) - radius) - R(0.05) + R(0.0) * offset;",
    )
    .unwrap();
    vec![
        sphere(0.5),
        cuboid(dvec3(0.5, 0.4, 0.3)),
        round_box(dvec3(0.5, 0.4, 0.3), 0.1),
        torus(0.6, 0.2),
        cylinder(0.4, 0.5),
        capsule(dvec3(-0.4, 0.0, 0.0), dvec3(0.4, 0.2, 0.0), 0.2),
        plane(dvec3(0.0, 1.0, 0.0), 0.5),
        octahedron(0.6),
        capped_cone(0.5, 0.4, 0.2),
        ellipsoid(dvec3(0.6, 0.4, 0.3)),
        Mandelbulb::new(8.0).iterations(6).bailout(2.0).into(),
        Menger::new(3).scale(3.0).into(),
        QuaternionJulia::new([
            Param::from(-0.2),
            Param::from(0.6),
            Param::from(0.2),
            Param::from(0.0),
        ])
        .iterations(8)
        .into(),
        Sierpinski::new(4).scale(2.0).into(),
        child().translate(dvec3(0.1, 0.2, 0.0)),
        child().rotate(dvec3(0.0, 1.0, 0.0), 0.5),
        child().scale(1.5),
        child().mirror(Axis::X),
        child().round(0.05),
        child().onion(0.05),
        child().elongate(dvec3(0.1, 0.2, 0.0)),
        child().repeat(dvec3(2.0, 0.0, 0.0)),
        child().repeat_limited(dvec3(2.0, 0.0, 0.0), [1, 0, 0]),
        child().twist(0.5),
        child().bend(0.3),
        child().smooth_union(sphere(0.4), 0.1),
        child().smooth_subtract(sphere(0.4), 0.1),
        child().smooth_intersect(sphere(0.4), 0.1),
        shell.node([0.5, 0.0]),
        child().color(dvec3(0.9, 0.5, 0.1)),
    ]
}

/// The name a node's errors give it.
fn label(node: &Node) -> String {
    match node.kind() {
        fractal_sdf::scene::Kind::Custom { shape, .. } => shape.name().to_string(),
        kind => kind.name().to_string(),
    }
}

/// What the suite saw.
#[derive(Default)]
struct Tally {
    cases: usize,
    errors: usize,
    accepted: usize,
    f32_refused: usize,
    rendered: usize,
    failures: Vec<String>,
    /// Accepted cases kept for rendering: (what, scene, dynamic value).
    to_render: Vec<(String, Scene, Option<f64>, Precision)>,
}

impl Tally {
    fn fail(&mut self, what: &str, why: impl std::fmt::Display) {
        self.failures.push(format!("{what}: {why}"));
    }

    /// An error must be typed and readable: it names the node and one of
    /// its parameters.
    fn refused(&mut self, what: &str, e: &Error, node: &str, params: &[&str]) {
        self.errors += 1;
        let text = e.to_string();
        if matches!(e, Error::Build { .. } | Error::OpenCl(_)) {
            self.fail(
                what,
                format!("an executor error, not a validation one: {text}"),
            );
        } else if !text.contains(node) {
            self.fail(what, format!("the message does not name `{node}`: {text}"));
        } else if !params.iter().any(|p| text.contains(p)) {
            self.fail(
                what,
                format!("the message names none of {params:?}: {text}"),
            );
        }
    }
}

/// The CPU reference's sample at every point is finite, in `T`.
fn finite_reference(eval: &Evaluator, f32_too: bool) -> Result<(), String> {
    for p in points() {
        let s = eval.sample::<f64>(p.into());
        let color = DVec3::from(s.color);
        if !(s.distance.is_finite() && s.trap.is_finite() && color.is_finite()) {
            return Err(format!(
                "f64 reference at {p}: distance {}, trap {}, colour {color}",
                s.distance, s.trap
            ));
        }
        if f32_too {
            let s = eval.sample::<f32>(p.as_vec3().into());
            let color = Vec3::from(s.color);
            if !(s.distance.is_finite() && s.trap.is_finite() && color.is_finite()) {
                return Err(format!(
                    "f32 reference at {p}: distance {}, trap {}, colour {color}",
                    s.distance, s.trap
                ));
            }
        }
    }
    Ok(())
}

fn program(precision: Precision) -> Options {
    Options::default().quality(gpu::plain(Quality::draft()).precision(precision))
}

/// One node parameter case: compile, set, check the reference and the
/// programs; keep accepted cases for rendering.
fn node_case(t: &mut Tally, what: &str, node: &Node, site: usize, value: f64, mode: Mode) {
    let sites = parameter_sites(node.kind());
    let names: Vec<&str> = sites
        .iter()
        .map(|s| s.name.split('.').next().unwrap_or(""))
        .collect();
    let label = label(node);
    let param = match mode {
        Mode::Baked => Param::Value(value),
        Mode::DynamicDefault => param("h", value),
        Mode::DynamicSet => param("h", sites[site].value),
    };
    let scene = Scene::new(substitute(node, site, param)).with_camera(camera());
    t.cases += 1;
    let compiled = match scene.compile() {
        Ok(c) => c,
        Err(e) => return t.refused(what, &e, &label, &names),
    };
    let mut eval = Evaluator::from_compiled(&compiled);
    let mut values = compiled.default_values();
    if mode == Mode::DynamicSet
        && let Err(e) = eval.set_param("h", value)
    {
        return t.refused(what, &e, &label, &names);
    }
    t.accepted += 1;
    // F32: what an F32 program and its uploads accept.
    let in_f32 = codegen::emit(&compiled, &program(Precision::F32)).and_then(|_| match mode {
        Mode::DynamicSet => values.set_within("h", value, &F32_LIMITS),
        _ => values.check_within(&F32_LIMITS),
    });
    if let Err(e) = &in_f32 {
        t.f32_refused += 1;
        let text = e.to_string();
        if !(text.contains("F32") && text.contains(&label)) {
            t.fail(what, format!("F32 refusal does not say why: {text}"));
        }
    }
    if let Err(e) = codegen::emit(&compiled, &program(Precision::F64)) {
        t.fail(
            what,
            format!("accepted, but F64 code generation fails: {e}"),
        );
    }
    if let Err(why) = finite_reference(&eval, in_f32.is_ok()) {
        t.fail(what, why);
    }
    let precision = if in_f32.is_ok() {
        Precision::F32
    } else {
        Precision::F64
    };
    let set = (mode == Mode::DynamicSet).then_some(value);
    t.to_render.push((what.to_string(), scene, set, precision));
}

/// Renders an 8 × 6 draft and compares its hit mask with `cpu::march`.
fn render_case(
    what: &str,
    scene: &Scene,
    set: Option<f64>,
    options: &RenderOptions,
) -> Result<(), String> {
    let mut renderer = Renderer::with_options(scene, options).map_err(|e| e.to_string())?;
    if let Some(v) = set {
        renderer.set_param("h", v).map_err(|e| e.to_string())?;
    }
    let frame = renderer.render_with_aovs(8, 6).map_err(|e| e.to_string())?;
    let view = renderer.viewport(8, 6).map_err(|e| e.to_string())?;
    let settings = view.march_settings(&renderer.options().quality);
    let mut eval = Evaluator::from_compiled(renderer.scene());
    if let Some(v) = set {
        eval.set_param("h", v).map_err(|e| e.to_string())?;
    }
    let mut same = 0;
    for y in 0..6 {
        for x in 0..8 {
            let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let reference = cpu::march(&eval, ray, &settings);
            if !reference.depth.is_finite() && !reference.depth.is_infinite() {
                return Err(format!("{what}: the CPU march gave a NaN depth"));
            }
            same += usize::from(reference.hit == frame.hit[frame.index(x, y)]);
        }
    }
    // The F32 kernel and the f64 reference may part on a silhouette pixel.
    if same < 44 {
        return Err(format!(
            "{same} of 48 hit flags agree with the CPU reference"
        ));
    }
    Ok(())
}

/// Runs `f`, turning a panic into a failure.
fn guarded(t: &mut Tally, what: &str, f: impl FnOnce(&mut Tally)) {
    let outcome = catch_unwind(AssertUnwindSafe(|| f(t)));
    if let Err(panic) = outcome {
        let message = panic
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| panic.downcast_ref::<&str>().map(|s| (*s).to_string()))
            .unwrap_or_default();
        t.fail(what, format!("panicked: {message}"));
    }
}

/// Runs every node case; returns how many distinct kinds were covered.
fn node_cases(t: &mut Tally) -> usize {
    let mut kinds_seen = Vec::new();
    for node in kinds() {
        let kind = std::mem::discriminant(node.kind());
        if !kinds_seen.contains(&kind) {
            kinds_seen.push(kind);
        }
        let sites = parameter_sites(node.kind());
        for (i, site) in sites.iter().enumerate() {
            for value in VALUES {
                for mode in [Mode::Baked, Mode::DynamicDefault, Mode::DynamicSet] {
                    let what = format!("{} {} = {value:e} {mode:?}", label(&node), site.name);
                    guarded(t, &what, |t| node_case(t, &what, &node, i, value, mode));
                }
            }
        }
    }
    kinds_seen.len()
}

/// The degenerate vectors: zero, tiny, huge and NaN versions of `v`.
fn degenerate(v: DVec3) -> [(&'static str, DVec3); 4] {
    [
        ("zero", DVec3::ZERO),
        ("tiny", v * 1e-300),
        ("huge", v * 1e300),
        ("NaN", dvec3(f64::NAN, v.y, v.z)),
    ]
}

fn vector_cases(t: &mut Tally) {
    let v = dvec3(0.3, 1.0, 0.2);
    let p = dvec3(0.4, -0.3, 0.5);
    let unit = v.normalize();
    // Both sides are the same f64 operations on an axis (or quaternion)
    // that normalising puts within an ulp or two of the unit one, at a
    // distance below 1: measured 0 over the 6 accepted cases. The
    // tolerance is about 45 ulps of 1.
    let same_as = |a: &Node, b: &Node| {
        let (a, b) = (Evaluator::new(a).unwrap(), Evaluator::new(b).unwrap());
        (a.distance(p) - b.distance(p)).abs() <= 1e-14
    };
    for (name, d) in degenerate(v) {
        // A rotation axis and a quaternion.
        let what = format!("rotate axis {name}");
        guarded(t, &what, |t| {
            t.cases += 1;
            let node = child().rotate(d, 0.7);
            match Scene::new(node.clone()).compile() {
                Err(e) => t.refused(&what, &e, "rotate", &["axis"]),
                Ok(_) if name == "zero" || name == "NaN" => t.fail(&what, "accepted"),
                Ok(_) => {
                    t.accepted += 1;
                    if !same_as(&node, &child().rotate(unit, 0.7)) {
                        t.fail(&what, "not the rotation about the unit axis");
                    }
                }
            }
        });
        let what = format!("rotate_quat {name}");
        guarded(t, &what, |t| {
            t.cases += 1;
            let q = DQuat::from_axis_angle(unit, 0.7);
            let scaled = match name {
                "zero" => DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0),
                "tiny" => DQuat::from_vec4(glam::DVec4::from(q) * 1e-300),
                "huge" => DQuat::from_vec4(glam::DVec4::from(q) * 1e300),
                _ => DQuat::from_xyzw(f64::NAN, 0.0, 0.0, 1.0),
            };
            let node = child().rotate_quat(scaled);
            match Scene::new(node.clone()).compile() {
                Err(e) => t.refused(&what, &e, "rotate", &["axis"]),
                Ok(_) if name == "zero" || name == "NaN" => t.fail(&what, "accepted"),
                Ok(_) => {
                    t.accepted += 1;
                    if !same_as(&node, &child().rotate_quat(q)) {
                        t.fail(&what, "not the rotation of the unit quaternion");
                    }
                }
            }
        });
        // A baked plane normal: normalised in f64, so any length draws the
        // plane, in F32 too.
        let what = format!("plane normal {name}");
        guarded(t, &what, |t| {
            t.cases += 1;
            let node = plane(d, 0.5);
            match Scene::new(node.clone()).compile() {
                Err(e) => t.refused(&what, &e, "plane", &["normal"]),
                Ok(_) if name == "zero" || name == "NaN" => t.fail(&what, "accepted"),
                Ok(compiled) => {
                    t.accepted += 1;
                    if !same_as(&node, &plane(unit, 0.5)) {
                        t.fail(&what, "not the plane of the unit normal");
                    }
                    if let Err(e) = codegen::emit(&compiled, &program(Precision::F32)) {
                        t.fail(&what, format!("refused in F32: {e}"));
                    }
                    let scene = Scene::new(node.union(sphere(0.5))).with_camera(camera());
                    t.to_render
                        .push((what.clone(), scene, None, Precision::F32));
                }
            }
        });
        // A camera's up and a light's direction: any length gives the
        // same image.
        let what = format!("camera up {name}");
        guarded(t, &what, |t| {
            t.cases += 1;
            let scene = Scene::new(sphere(0.5)).with_camera(camera().up(d));
            match scene.compile() {
                Err(e) => t.refused(&what, &e, "camera", &["up", "finite"]),
                Ok(_) if name == "zero" || name == "NaN" => t.fail(&what, "accepted"),
                Ok(_) => {
                    t.accepted += 1;
                    let basis = scene.camera.basis().unwrap();
                    let expected = camera().up(v).basis().unwrap();
                    if (basis.0 - expected.0).length() > 1e-12 {
                        t.fail(&what, "a different camera basis");
                    }
                    t.to_render
                        .push((what.clone(), scene, None, Precision::F32));
                }
            }
        });
        let what = format!("light direction {name}");
        guarded(t, &what, |t| {
            t.cases += 1;
            let scene = Scene::new(sphere(0.5))
                .with_camera(camera())
                .with_lights([Light::directional(d)]);
            match scene.compile() {
                Err(e) => t.refused(&what, &e, "light[0]", &["direction"]),
                Ok(_) if name == "zero" || name == "NaN" => t.fail(&what, "accepted"),
                Ok(_) => {
                    t.accepted += 1;
                    t.to_render
                        .push((what.clone(), scene, None, Precision::F32));
                }
            }
        });
        // A camera whose target is `d` away.
        let what = format!("camera view {name}");
        guarded(t, &what, |t| {
            t.cases += 1;
            let c = Camera::look_at(dvec3(0.0, 0.0, 4.0), dvec3(0.0, 0.0, 4.0) - d);
            match Scene::new(sphere(0.5)).with_camera(c).compile() {
                Err(e) => t.refused(&what, &e, "camera", &["target", "finite"]),
                Ok(_) if name != "huge" => t.fail(&what, "accepted"),
                Ok(_) => t.accepted += 1,
            }
        });
    }
}

/// An accepted camera or light: an F32 renderer takes it, or refuses it
/// by name (then it is rendered in F64).
fn accepted_frame_input(t: &mut Tally, what: &str, scene: Scene, node: &str, params: &[&str]) {
    t.accepted += 1;
    let mut precision = Precision::F32;
    if gpu::device().is_some() {
        let options = gpu::options(gpu::plain(Quality::draft()), Effects::none());
        if let Err(e) = Renderer::with_options(&scene, &options) {
            t.f32_refused += 1;
            let text = e.to_string();
            if !(text.contains("F32")
                && text.contains(node)
                && params.iter().any(|p| text.contains(p)))
            {
                t.fail(what, format!("F32 refusal does not say why: {text}"));
            }
            precision = Precision::F64;
        }
    }
    t.to_render.push((what.to_string(), scene, None, precision));
}

/// Every camera, light, quality and effects value, each substituted.
fn setting_cases(t: &mut Tally) {
    let base =
        Scene::new(sphere(0.5).union(plane(dvec3(0.0, 1.0, 0.0), 0.5))).with_camera(camera());
    type CameraEdit = fn(&mut Camera, f64);
    let cameras: [(&str, CameraEdit); 11] = [
        ("position.x", |c, v| c.position.x = v),
        ("position.y", |c, v| c.position.y = v),
        ("position.z", |c, v| c.position.z = v),
        ("target.x", |c, v| c.target.x = v),
        ("target.y", |c, v| c.target.y = v),
        ("target.z", |c, v| c.target.z = v),
        ("up.x", |c, v| c.up.x = v),
        ("up.y", |c, v| c.up.y = v),
        ("up.z", |c, v| c.up.z = v),
        ("field of view", |c, v| *c = c.fov(v)),
        ("orthographic height", |c, v| *c = c.orthographic(v)),
    ];
    type LightEdit = fn(f64) -> Light;
    let lights: [(&str, LightEdit); 8] = [
        ("direction", |v| Light::directional(dvec3(v, 1.0, 0.5))),
        ("position", |v| Light::point(dvec3(1.0, v, 2.0))),
        ("color", |v| {
            Light::directional(dvec3(0.5, 1.0, 0.5)).color(dvec3(v, 1.0, 1.0))
        }),
        ("intensity", |v| {
            Light::directional(dvec3(0.5, 1.0, 0.5)).intensity(v)
        }),
        ("softness", |v| {
            Light::directional(dvec3(0.5, 1.0, 0.5)).softness(v)
        }),
        ("color", |v| {
            Light::point(dvec3(1.0, 2.0, 2.0)).color(dvec3(1.0, v, 1.0))
        }),
        ("intensity", |v| {
            Light::point(dvec3(1.0, 2.0, 2.0)).intensity(v)
        }),
        ("softness", |v| {
            Light::point(dvec3(1.0, 2.0, 2.0)).softness(v)
        }),
    ];
    type QualityEdit = fn(Quality, f64) -> Quality;
    let qualities: [(&str, QualityEdit); 5] = [
        ("detail", |q, v| {
            q.detail(v).hit_epsilon(v.abs().min(q.hit_epsilon))
        }),
        ("hit_epsilon", Quality::hit_epsilon),
        ("max_distance", Quality::max_distance),
        ("normal_epsilon", Quality::normal_epsilon),
        ("over_relaxation", Quality::over_relaxation),
    ];
    type EffectsEdit = fn(Effects, f64) -> Effects;
    let effects: [(&str, EffectsEdit); 8] = [
        ("ao_distance", Effects::ao_distance),
        ("exposure", Effects::exposure),
        ("fog_density", Effects::fog_density),
        ("gamma", Effects::gamma),
        ("glow", |e, v| e.glow(Glow::new(dvec3(0.5, 0.7, 1.0), v))),
        ("glow", |e, v| e.glow(Glow::new(dvec3(v, 0.7, 1.0), 0.5))),
        ("sky_top", |e, v| e.sky_top(dvec3(0.3, v, 0.5))),
        ("sky_bottom", |e, v| e.sky_bottom(dvec3(v, 0.1, 0.1))),
    ];
    for value in VALUES {
        for (name, edit) in cameras {
            let what = format!("camera {name} = {value:e}");
            let base = base.clone();
            guarded(t, &what, |t| {
                t.cases += 1;
                let mut c = camera();
                edit(&mut c, value);
                let scene = base.with_camera(c);
                let first = name.split('.').next().unwrap_or(name);
                let params = [first, "finite", "target equals position", "up is"];
                match scene.compile() {
                    Err(e) => t.refused(&what, &e, "camera", &params),
                    Ok(_) => {
                        let params = [first, "field of view", "distance", "height"];
                        accepted_frame_input(t, &what, scene, "camera", &params);
                    }
                }
            });
        }
        for (name, light) in lights {
            let what = format!("light {name} = {value:e}");
            let base = base.clone();
            guarded(t, &what, |t| {
                t.cases += 1;
                let scene = base.with_lights([light(value)]);
                match scene.compile() {
                    Err(e) => t.refused(&what, &e, "light[0]", &[name]),
                    Ok(_) => accepted_frame_input(t, &what, scene, "light[0]", &[name]),
                }
            });
        }
        for precision in [Precision::F32, Precision::F64] {
            for (name, edit) in qualities {
                let what = format!("quality {name} = {value:e} {precision:?}");
                guarded(t, &what, |t| {
                    t.cases += 1;
                    let q = edit(gpu::plain(Quality::draft()).precision(precision), value);
                    match q.validate() {
                        Err(e) => t.refused(&what, &e, name, &[name]),
                        Ok(()) => {
                            t.accepted += 1;
                            let options = Options::default().quality(q);
                            if let Err(e) = codegen::emit(&base.compile().unwrap(), &options) {
                                t.fail(&what, format!("valid, but code generation fails: {e}"));
                            }
                        }
                    }
                });
            }
            for (name, edit) in effects {
                let what = format!("effects {name} = {value:e} {precision:?}");
                guarded(t, &what, |t| {
                    t.cases += 1;
                    let e = edit(Effects::default(), value);
                    match e.validate_for(precision) {
                        Err(err) => t.refused(&what, &err, name, &[name]),
                        Ok(()) => {
                            t.accepted += 1;
                            let options = Options::default()
                                .quality(gpu::plain(Quality::preview()).precision(precision))
                                .effects(e);
                            if let Err(err) = codegen::emit(&base.compile().unwrap(), &options) {
                                t.fail(&what, format!("valid, but code generation fails: {err}"));
                            }
                        }
                    }
                });
            }
        }
    }
}

#[test]
fn hostile_values_are_refused_by_name_or_computed_finitely() {
    let mut t = Tally::default();
    let kinds = node_cases(&mut t);
    vector_cases(&mut t);
    setting_cases(&mut t);

    // Render a sample of the accepted cases: an even spread of those with
    // a degenerate vector or a camera or light value (every third), and of
    // the node parameters (every 23rd).
    if gpu::device().is_some() {
        let mut picked = Vec::new();
        let (mut settings, mut parameters) = (0, 0);
        for case in std::mem::take(&mut t.to_render) {
            let setting = ["plane normal", "camera", "light"]
                .iter()
                .any(|s| case.0.starts_with(s));
            let count = if setting {
                &mut settings
            } else {
                &mut parameters
            };
            if *count % if setting { 3 } else { 23 } == 0 {
                picked.push(case);
            }
            *count += 1;
        }
        for (what, scene, set, precision) in picked {
            let options = gpu::options(
                gpu::plain(Quality::draft()).precision(precision),
                Effects::none(),
            );
            let outcome = catch_unwind(AssertUnwindSafe(|| {
                render_case(&what, &scene, set, &options)
            }));
            t.rendered += 1;
            match outcome {
                Ok(Ok(())) => {}
                Ok(Err(why)) => t.fail(&format!("{what} rendered in {precision:?}"), why),
                Err(_) => t.fail(&what, "panicked while rendering"),
            }
        }
    }

    println!(
        "hostile inputs: {} cases over all {kinds} node kinds and the camera, lights, quality \
         and effects; {} refused with a typed error, {} accepted ({} of them refused for \
         F32 only); {} accepted cases rendered and compared with the CPU reference; {} failures",
        t.cases,
        t.errors,
        t.accepted,
        t.f32_refused,
        t.rendered,
        t.failures.len()
    );
    assert!(
        t.failures.is_empty(),
        "{} of {} hostile cases failed:\n{}",
        t.failures.len(),
        t.cases,
        t.failures.join("\n")
    );
}

mod hostile_classes;

/// The classes of bad input found by trying the library from outside, as
/// generated cases (see `hostile_classes`): each a typed error or a
/// result checked to be right, with a table per class.
#[test]
fn the_classes_found_from_outside_end_in_a_typed_error_or_a_checked_result() {
    hostile_classes::run(gpu::device().is_some());
}
