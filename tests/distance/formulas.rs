//! Formulas written once: random programs agree between the CPU and the
//! printed OpenCL, intervals hold every value over their box, and a custom
//! shape from one generic function (or one text formula) renders, meshes
//! without bounds and passes the testing toolkit's checks.

use crate::gpu;

use fractal_sdf::cpu;
use fractal_sdf::expr::V3;
use fractal_sdf::expr::{
    Counted, Distance, Formula, Interval, Num, Printer, Program, Shape, Signature, Wgsl, counting,
};
use fractal_sdf::mesh::{GridOptions, Sampler, extract};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{DeviceSelector, PointEvaluator};
use fractal_sdf::scene::Param;
use fractal_sdf::scene::{CustomShape, Rule};
use fractal_sdf::testing::{check_lipschitz, check_never_overestimates, random_points};
use proptest::prelude::*;

/// A random scalar expression of `p` and the parameter `a`, as formula
/// text: every operation of the language, with branches and comparisons.
fn scalar(vars: &'static [&'static str]) -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        prop::sample::select(vars),
        (-4.0..4.0f64)
            .prop_map(|v| format!("{v:.3}"))
            .boxed()
            .prop_map(|s| {
                // Leaked once per case: a handful of short strings.
                &*Box::leak(s.into_boxed_str())
            }),
    ]
    .prop_map(str::to_string);
    leaf.prop_recursive(5, 48, 3, |e| {
        prop_oneof![
            (
                e.clone(),
                e.clone(),
                prop::sample::select(&["+", "-", "*"][..])
            )
                .prop_map(|(a, b, op)| format!("({a} {op} {b})")),
            (e.clone(), e.clone()).prop_map(|(a, b)| format!("({a} / (abs({b}) + 0.5))")),
            (
                prop::sample::select(&["abs", "sin", "cos", "floor", "round", "fract"][..]),
                e.clone()
            )
                .prop_map(|(f, a)| format!("{f}({a})")),
            e.clone().prop_map(|a| format!("sqrt(abs({a}))")),
            e.clone().prop_map(|a| format!("log(abs({a}) + 0.25)")),
            e.clone().prop_map(|a| format!("exp(clamp({a}, -4, 4))")),
            e.clone().prop_map(|a| format!("acos(clamp({a}, -1, 1))")),
            (e.clone(), e.clone())
                .prop_map(|(a, b)| format!("pow(abs({a}) + 0.25, clamp({b}, -2, 2))")),
            (
                prop::sample::select(&["min", "max", "atan2", "hypot"][..]),
                e.clone(),
                e.clone()
            )
                .prop_map(|(f, a, b)| format!("{f}({a}, {b})")),
            (e.clone(), e.clone(), e.clone())
                .prop_map(|(a, b, c)| format!("length(vec3({a}, {b}, {c}))")),
            (
                e.clone(),
                e.clone(),
                e.clone(),
                e.clone(),
                prop::sample::select(&["<", "<=", ">", ">="][..])
            )
                .prop_map(|(a, b, c, d, op)| format!("if {a} {op} {b} {{ {c} }} else {{ {d} }}")),
            (e.clone(), e.clone(), e.clone())
                .prop_map(|(a, b, t)| format!("mix({a}, {b}, clamp({t}, 0, 1))")),
        ]
    })
}

/// A random formula: a value, possibly built by a bounded loop with an
/// early exit and an `if` statement, kept finite by a final clamp.
fn formula() -> impl Strategy<Value = String> {
    const OUTER: &[&str] = &["p.x", "p.y", "p.z", "a"];
    const INNER: &[&str] = &["p.x", "p.y", "p.z", "a", "s", "i"];
    (
        scalar(OUTER),
        scalar(INNER),
        scalar(INNER),
        1..5i64,
        -2.0..6.0f64,
        any::<bool>(),
    )
        .prop_map(|(start, step, cond, n, stop, branch)| {
            let body = if branch {
                format!("if {cond} > 0 {{ s = {step}; }} else {{ s = s * 0.5; }}")
            } else {
                format!("s = {step};")
            };
            format!(
                "let s = {start};\nfor i in 0..{n} {{\n    {body}\n    break if abs(s) > {stop:.2};\n}}\nclamp(s, -1e6, 1e6)"
            )
        })
}

fn run(program: &Program, p: DVec3, a: f64) -> f64 {
    program.run(&[p.x, p.y, p.z, a])[0]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// The printed OpenCL of a random program computes what the CPU does
    /// (F64, 256 points each).
    #[test]
    fn random_programs_agree_on_cpu_and_device(text in formula(), a in -2.0..2.0f64) {
        let Some(_device) = gpu::device() else {
            return Ok(());
        };
        let shape = CustomShape::parse("random", &[("a", Rule::Finite)], &text)
            .unwrap_or_else(|e| panic!("{e}\n{text}"));
        let program = shape.program().unwrap().clone();
        let node = shape.node([param("a", a)]);
        let device = PointEvaluator::new(&node, Precision::F64, &DeviceSelector::auto())
            .unwrap_or_else(|e| panic!("{e}\n{text}"));
        let points = random_points(256, 3.0, 7);
        let got = device.distances(&points).unwrap();
        let mut worst = 0.0f64;
        for (p, g) in points.iter().zip(&got) {
            let c = run(&program, *p, a);
            let error = (g - c).abs() / c.abs().max(1.0);
            worst = worst.max(error);
            prop_assert!(
                error <= 1e-9,
                "at {p}: device {g}, CPU {c}\n{text}\n{}",
                shape.opencl_body()
            );
        }
    }

    /// A random program printed as WGSL parses and validates as a WebGPU
    /// implementation reads it (naga), beside the prelude it calls into.
    #[test]
    fn random_programs_print_as_valid_wgsl(text in formula()) {
        let f = Formula::parse(&text, &["a"]).unwrap_or_else(|e| panic!("{e}\n{text}"));
        let signature = Signature::new(
            "random",
            &[("p", Shape::Vec3), ("a", Shape::Scalar)],
            Shape::Scalar,
        );
        let function = Wgsl.function(&signature, &f.program()).unwrap();
        let source = format!("{}\n{function}", Wgsl::PRELUDE);
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{}\n{text}", e.emit_to_string(&source)));
        let valid = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        )
        .validate(&module);
        prop_assert!(valid.is_ok(), "{}\n{text}", valid.unwrap_err().emit_to_string(&source));
    }

    /// The range a random program takes over a box holds its value at
    /// every point in the box.
    #[test]
    fn intervals_hold_every_value_in_their_box(
        text in formula(),
        a in -2.0..2.0f64,
        centre in (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64),
        half in 0.0..1.5f64,
    ) {
        let f = Formula::parse(&text, &["a"]).unwrap_or_else(|e| panic!("{e}\n{text}"));
        let program = f.program();
        let c = DVec3::new(centre.0, centre.1, centre.2);
        let boxed = |i: usize| Interval::new(c[i] - half, c[i] + half);
        let range = program.run(&[boxed(0), boxed(1), boxed(2), Interval::point(a)])[0];
        for p in random_points(64, 1.0, 3) {
            let q = c + p * half;
            let v = run(&program, q, a);
            prop_assert!(
                v.is_nan() || range.contains(v),
                "{v} at {q} is outside {range:?} over the box {c} ± {half}\n{text}"
            );
        }
    }
}

/// A torus knot-free "twisted ring", written once: a torus whose tube
/// radius breathes with the angle around its axis.
struct Ring;

impl Distance for Ring {
    fn distance<N: Num>(&self, p: V3<N>, a: &[N]) -> N {
        let (major, minor, wave) = (a[0], a[1], a[2]);
        let angle = p.z.atan2(p.x);
        let tube = minor + wave * (N::of(3.0) * angle).sin();
        let q = p.x.hypot(p.z) - major;
        // The tube radius changes by at most 3 wave per radian, so by at
        // most 3 wave / (major - minor - wave) per unit length: divide by
        // 1 + that to keep a bound.
        let slope = N::one() + N::of(3.0) * wave / (major - minor - wave);
        (q.hypot(p.y) - tube) / slope
    }
}

fn ring() -> CustomShape {
    CustomShape::formula(
        "ring",
        &[
            ("major", Rule::Positive),
            ("minor", Rule::Positive),
            ("wave", Rule::NonNegative),
        ],
        Ring,
    )
    .unwrap()
}

/// An independent inside test of the ring: the point's distance from the
/// circle of radius `major`, against the tube radius at its angle.
fn ring_inside(p: DVec3) -> bool {
    let (major, minor, wave) = (1.0, 0.3, 0.08);
    let tube = minor + wave * (3.0 * p.z.atan2(p.x)).sin();
    let rho = (p.x * p.x + p.z * p.z).sqrt();
    ((rho - major).powi(2) + p.y * p.y).sqrt() <= tube
}

#[test]
fn a_shape_written_once_passes_the_toolkit_checks() {
    let node = ring().node([1.0, 0.3, 0.08]);
    let points = random_points(400, 1.8, 11);
    check_never_overestimates(&node, ring_inside, &points, 32).unwrap();
    let pairs: Vec<(DVec3, DVec3)> = points
        .iter()
        .zip(random_points(400, 0.05, 12))
        .map(|(p, d)| (*p, *p + d))
        .collect();
    check_lipschitz(&node, 1.0, &pairs).unwrap();
}

#[test]
fn a_shape_written_once_meshes_without_bounds() {
    let scene = ring().node([1.0, 0.3, 0.08]);
    let compiled = Scene::new(scene).compile().unwrap();
    let options = GridOptions::default()
        .resolution(64)
        .sampler(Sampler::Cpu)
        .precision(Precision::F64);
    let mesh = extract(&compiled, &options).unwrap();
    assert!(mesh.topology().is_closed_manifold());
    // The tube's volume, 2 pi^2 R r^2 on average over the wave (the
    // wave's mean square adds pi^2 R wave^2).
    let expected = 2.0 * std::f64::consts::PI.powi(2) * (0.3f64.powi(2) + 0.08f64.powi(2) / 2.0);
    let volume = mesh.volume();
    assert!(
        (volume - expected).abs() < 0.05 * expected,
        "volume {volume}, expected {expected}"
    );
}

#[test]
fn a_shape_written_once_renders_on_the_device() {
    let Some(_device) = gpu::device() else {
        return;
    };
    let scene = Scene::new(ring().node([Param::from(1.0), Param::from(0.3), param("wave", 0.08)]))
        .add(gpu::floor());
    let options = gpu::options(gpu::quick(), Effects::default());
    let mut renderer = fractal_sdf::render::Renderer::with_options(&scene, &options).unwrap();
    let image = renderer.render(96, 72).unwrap();
    gpu::save("formula_ring", &image);
    let centre = image.get_pixel(48, 36).0;
    let corner = image.get_pixel(2, 2).0;
    assert_ne!(centre, corner, "the ring is not drawn");
    // The CPU reference agrees with the device at the shape's points.
    let points = random_points(500, 1.6, 5);
    fractal_sdf::testing::check_device_matches_cpu(
        &ring().node([1.0, 0.3, 0.08]),
        &DeviceSelector::auto(),
        Precision::F32,
        &points,
        1e-5,
    )
    .unwrap();
}

#[test]
fn a_text_formula_in_a_scene_file_has_bounds_and_reads_back() {
    let file = fractal_sdf::file::SceneFile::load(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/custom_formula.ron"),
    )
    .unwrap();
    let text = file.to_text().unwrap();
    assert!(text.contains("formulas:"), "{text}");
    let back = fractal_sdf::file::SceneFile::parse(&text).unwrap();
    assert_eq!(
        back.scene.geometry.as_ref().map(|g| format!("{g:?}")),
        file.scene.geometry.as_ref().map(|g| format!("{g:?}"))
    );
    // With the ripple baked, the shape has a bound from its formula.
    let shape = CustomShape::parse(
        "ball",
        &[("r", Rule::Positive)],
        "length(p - vec3(2, 0, 0)) - r",
    )
    .unwrap();
    let [lo, hi] = shape.surface_box(&[0.5]).unwrap();
    assert!(
        lo.x <= 1.5 && hi.x >= 2.5 && lo.x > 1.4 && hi.x < 2.6,
        "{lo} {hi}"
    );
}

#[test]
fn formula_errors_name_line_column_and_what_was_expected() {
    let err = |text: &str| CustomShape::parse("f", &[("r", Rule::Positive)], text).unwrap_err();
    match err("let a = 1;\nlength(p) - * r") {
        fractal_sdf::Error::Formula {
            line,
            column,
            message,
            ..
        } => {
            assert_eq!((line, column), (2, 13));
            assert!(
                message.contains("expected a number, a name, a call or `(`"),
                "{message}"
            );
        }
        e => panic!("{e}"),
    }
    match err("length(p) - radius") {
        fractal_sdf::Error::Formula {
            line,
            column,
            message,
            ..
        } => {
            assert_eq!((line, column), (1, 13));
            assert!(
                message.contains("unknown variable `radius`") && message.contains("p, r"),
                "{message}"
            );
        }
        e => panic!("{e}"),
    }
    // In a scene file, the error also names the file's line.
    let file = "(version: 1, formulas: [(name: \"f\", distance: \"length(p) - q\")], geometry: Custom(name: \"f\", args: []))";
    let e = fractal_sdf::file::SceneFile::parse(file)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("unknown variable `q`") && e.contains("line 1, column 13"),
        "{e}"
    );
}

#[test]
fn a_formula_never_reaches_the_source_as_text() {
    // Text that would be code in a body: it is only ever a parse error.
    for text in [
        "1; } real DE(real3 p) { return 0",
        "/* */ 1",
        "#define x 1\n1",
        "length(p) - 1;",
    ] {
        assert!(CustomShape::parse("f", &[], text).is_err(), "{text}");
    }
    let shape = CustomShape::parse("f", &[], "length(p) - 1 // a comment } {").unwrap();
    assert!(
        !shape.opencl_body().contains("comment"),
        "{}",
        shape.opencl_body()
    );
}

/// The longest formulas, as deep as their length allows, end in a value or
/// a located error on a test thread's small stack: nesting and chains are
/// never followed by recursion as deep as the text.
#[test]
fn the_deepest_formulas_are_refused_or_evaluated_without_overflowing() {
    let parse = |text: &str| CustomShape::parse("deep", &[("r", Rule::Positive)], text);
    let nested = format!("{}length(p) - r{}", "(".repeat(7000), ")".repeat(7000));
    let err = parse(&nested).unwrap_err().to_string();
    assert!(err.contains("nested"), "{err}");
    let negated = format!("{}(length(p) - r)", "-".repeat(12000));
    let err = parse(&negated).unwrap_err().to_string();
    assert!(err.contains("nested"), "{err}");
    let chain = format!("length(p) - r{}", " + 0".repeat(3000));
    let err = parse(&chain).unwrap_err().to_string();
    assert!(err.contains("operations deep"), "{err}");
    // As deep as allowed: it evaluates, on the CPU and as bounds.
    let chain = format!(
        "length(p) - r{}",
        " + 0".repeat(fractal_sdf::expr::MAX_DEPTH - 3)
    );
    let shape = parse(&chain).unwrap();
    let d = shape.distance(DVec3::new(2.0, 0.0, 0.0), &[0.5]);
    assert!((d - 1.5).abs() < 1e-12, "{d}");
    assert!(shape.surface_box(&[0.5]).is_some());
}

/// The CPU reference's whole scene runs on a number that counts its
/// operations: a sphere is the hand count of `|p| − r` (three products,
/// two sums, a square root, a difference), a translation three
/// differences more; its values are `f64`'s; pruning saves operations,
/// and a fractal costs less far away, where it returns early, than on its
/// surface.
#[test]
fn operations_are_counted_on_the_whole_scene() {
    let count = |eval: &cpu::Evaluator, p: DVec3| {
        let (sample, ops) =
            counting(|| eval.sample::<Counted>(V3::from_array(p.to_array().map(Counted::of))));
        assert_eq!(sample.distance.value(), eval.distance(p), "at {p}");
        ops
    };
    let p = dvec3(0.3, -1.2, 2.0);
    let ball = cpu::Evaluator::new(&sphere(1.0)).unwrap();
    assert_eq!((count(&ball, p).arithmetic, count(&ball, p).calls), (7, 0));
    let moved = cpu::Evaluator::new(&sphere(1.0).translate(dvec3(1.0, 2.0, 3.0))).unwrap();
    assert_eq!(count(&moved, p).arithmetic, 10);

    let pair = sphere(0.5)
        .translate(dvec3(-3.0, 0.0, 0.0))
        .union(sphere(0.5).translate(dvec3(3.0, 0.0, 0.0)));
    let pruned = cpu::Evaluator::new(&pair).unwrap();
    let unpruned = pruned.clone().with_pruning(false);
    let near_one = dvec3(-3.0, 0.6, 0.0);
    assert!(count(&pruned, near_one).flops() < count(&unpruned, near_one).flops());

    let bulb = cpu::Evaluator::new(&mandelbulb(8.0)).unwrap();
    let (far, surface) = (
        count(&bulb, dvec3(0.0, 0.0, 5.0)),
        count(&bulb, dvec3(0.0, 0.0, 1.0)),
    );
    assert!(
        far.flops() * 4 < surface.flops(),
        "far {far:?}, surface {surface:?}"
    );
    assert!(surface.calls > 0);
}
