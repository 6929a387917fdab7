//! The classes of bad input found by trying the library from outside, each
//! as generated cases: warp rates, inside shapes' bounds, brute-force
//! steps, sampled boxes, output file names, stereo sizes, panicking
//! membership tests and custom bodies that would leave their function.
//!
//! Every case ends as a typed error, or as a result checked to be right
//! (a finite estimate that never overestimates, a program that builds, a
//! closed mesh, a file in the format its name asks for, a picture of the
//! size asked for); anything else, a panic included, is a failure. The
//! test prints a table with one row per class.

use std::panic::{AssertUnwindSafe, catch_unwind};

use fractal_sdf::codegen::{self, Options};
use fractal_sdf::cpu;
use fractal_sdf::mesh::{self, Aabb, GridOptions, Sampler};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;
use fractal_sdf::scene::{CustomShape, InsideBounds, InsideShape, Stereo, StereoLayout};

/// How one case ended.
enum End {
    /// A typed error: the variant's name, checked by the class.
    Refused,
    /// A result the class checked.
    Correct,
}

/// One class's counts.
#[derive(Default)]
struct Row {
    cases: usize,
    refused: usize,
    correct: usize,
    failures: Vec<String>,
}

impl Row {
    /// Runs one case, turning a panic into a failure.
    fn case(&mut self, what: &str, f: impl FnOnce() -> Result<End, String>) {
        self.cases += 1;
        match catch_unwind(AssertUnwindSafe(f)) {
            Ok(Ok(End::Refused)) => self.refused += 1,
            Ok(Ok(End::Correct)) => self.correct += 1,
            Ok(Err(why)) => self.failures.push(format!("{what}: {why}")),
            Err(_) => self.failures.push(format!("{what}: panicked")),
        }
    }
}

/// `n` values spread over many magnitudes, both signs, and the
/// non-finite ones.
fn sweep(n: usize) -> Vec<f64> {
    let mut out = vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, -0.0];
    #[allow(clippy::cast_precision_loss, clippy::cast_possible_wrap)]
    for i in 0..n.saturating_sub(out.len()) {
        let exponent = -24.0 + 48.0 * i as f64 / n as f64;
        let sign = if i % 3 == 0 { -1.0 } else { 1.0 };
        out.push(sign * 10f64.powf(exponent) * (1.0 + 0.37 * (i % 5) as f64));
    }
    out
}

fn program(precision: Precision) -> Options {
    Options::default().quality(Quality::draft().precision(precision))
}

/// A typed error whose text mentions `says`.
fn refused(err: &Error, says: &str) -> Result<End, String> {
    let text = err.to_string();
    if text.contains(says) {
        Ok(End::Refused)
    } else {
        Err(format!("the error does not say `{says}`: {text}"))
    }
}

fn warp_rates(row: &mut Row) {
    for rate in sweep(40) {
        for (name, node) in [
            ("twist", sphere(0.5).twist(rate)),
            ("bend", sphere(0.5).bend(rate)),
        ] {
            row.case(&format!("{name} rate {rate:e}"), || {
                let compiled = match Scene::new(node).compile() {
                    Err(e) => return refused(&e, "rate"),
                    Ok(c) => c,
                };
                // A sphere on the warp's axis is left as it is: its
                // distance is known exactly.
                let eval = cpu::Evaluator::from_compiled(&compiled);
                for p in [
                    dvec3(3.0, 0.5, 0.2),
                    dvec3(0.1, 0.2, 0.3),
                    dvec3(-40.0, 9.0, 2.0),
                ] {
                    let (d, exact) = (eval.distance(p), p.length() - 0.5);
                    // A bound: at most the distance outside, at least it
                    // (and of the same sign) inside; far away, close to it.
                    let bound = if exact > 0.0 {
                        d <= exact + 1e-9
                    } else {
                        d >= exact - 1e-9 && d <= 0.0
                    };
                    let far_enough = exact < 2.0 || d >= 0.9 * exact;
                    if !d.is_finite() || !bound || !far_enough {
                        return Err(format!("at {p}: {d} against {exact}"));
                    }
                }
                codegen::emit(&compiled, &program(Precision::F32)).map_err(|e| e.to_string())?;
                Ok(End::Correct)
            });
        }
    }
}

fn inside_bounds(row: &mut Row) {
    for v in sweep(40) {
        for (name, bounds) in [
            ("radius", InsideBounds::sphere(DVec3::ZERO, v)),
            ("centre", InsideBounds::sphere(dvec3(v, 0.0, 0.0), 1.0)),
            (
                "half extent",
                InsideBounds::cuboid(DVec3::ZERO, dvec3(1.0, v, 1.0)),
            ),
        ] {
            row.case(&format!("inside bounds {name} {v:e}"), || {
                let shape = match InsideShape::new(
                    "blob",
                    &[],
                    bounds,
                    |p, _| p.length() < 1.0,
                    "return length(p) < R(1.0);",
                ) {
                    Err(e) => return refused(&e, "blob"),
                    Ok(s) => s,
                };
                let compiled = Scene::new(shape.node::<f64>([]))
                    .compile()
                    .map_err(|e| e.to_string())?;
                for precision in [Precision::F32, Precision::F64] {
                    if let Err(e) = codegen::emit(&compiled, &program(precision)) {
                        return refused(&e, "cannot be represented");
                    }
                }
                Ok(End::Correct)
            });
        }
    }
}

fn brute_steps(row: &mut Row) {
    for step in sweep(30) {
        row.case(
            &format!("brute_step {step:e}"),
            || match Quality::production().brute_step(step).validate() {
                Err(e) => refused(&e, "brute_step"),
                Ok(()) if (0.125..=64.0).contains(&step) => Ok(End::Correct),
                Ok(()) => Err("accepted a step the march cannot use".into()),
            },
        );
    }
}

fn mesh_boxes(row: &mut Row) {
    let scene = Scene::new(sphere(1.0)).compile().unwrap();
    for side in sweep(30) {
        row.case(&format!("mesh box side {side:e}"), || {
            let bounds = Aabb::new(DVec3::splat(-1.2), DVec3::splat(-1.2) + side);
            let options = GridOptions::default()
                .resolution(12)
                .sampler(Sampler::Cpu)
                .bounds(bounds);
            match mesh::extract(&scene, &options) {
                Err(e) => refused(&e, "grid bounds"),
                Ok(m) if m.topology().is_closed_manifold() => Ok(End::Correct),
                Ok(_) => Err("a mesh that is not closed".into()),
            }
        });
    }
}

fn output_names(row: &mut Row) {
    let dir = std::env::temp_dir().join(format!("fractal-sdf-hostile-{}", std::process::id()));
    let image = fractal_sdf::image::RgbaImage::new(3, 2);
    let png: &[u8] = b"\x89PNG";
    let jpeg: &[u8] = &[0xff, 0xd8, 0xff];
    let tiff: &[u8] = b"II*\0";
    for (name, magic) in [
        ("a.png", Some(png)),
        ("a.PNG", Some(png)),
        ("a.jpg", Some(jpeg)),
        ("a.JPEG", Some(jpeg)),
        ("a.jpeg", Some(jpeg)),
        ("a", Some(png)),
        ("a.tar.png", Some(png)),
        ("a.xyz", None),
        ("a.tif", Some(tiff)),
        ("a.TIFF", Some(tiff)),
        ("a.gif", None),
        ("a.png.bak", None),
        ("a.", None),
        ("a.jpg ", None),
        (".jpg", Some(png)),
        ("a.pn", None),
        ("a.webp", None),
        ("a.bmp", None),
        ("a.j\u{e9}pg", None),
        ("a.svg", None),
    ] {
        row.case(&format!("output `{name}`"), || {
            let path = dir.join(name);
            match (fractal_sdf::output::save_image(&image, &path), magic) {
                (Err(e), None) => refused(&e, ".png, .jpg, .jpeg, .tif, .tiff, .exr"),
                (Ok(()), Some(magic)) => {
                    let bytes = std::fs::read(&path).map_err(|e| e.to_string())?;
                    if bytes.starts_with(magic) {
                        Ok(End::Correct)
                    } else {
                        Err("the file is not in the format its name asks for".into())
                    }
                }
                (Ok(()), None) => Err("written in a format its name does not ask for".into()),
                (Err(e), Some(_)) => Err(format!("refused: {e}")),
            }
        });
    }
    // An OpenEXR file holds linear colour, which an 8-bit image has not:
    // refused by name, towards the call that writes one.
    row.case("output `a.exr`", || {
        let path = dir.join("a.exr");
        match fractal_sdf::output::save_image(&image, &path) {
            Err(e) if path.exists() => Err(format!("refused ({e}) but written")),
            Err(e) => refused(&e, "save_frame"),
            Ok(()) => Err("an 8-bit image written as OpenEXR".into()),
        }
    });
    let _ = std::fs::remove_dir_all(dir);
}

fn stereo_sizes(row: &mut Row) {
    let scene = Scene::new(sphere(1.0));
    let options = super::gpu::options(Quality::draft(), Effects::none());
    let Ok(mut renderer) = fractal_sdf::render::Renderer::with_options(&scene, &options) else {
        row.failures.push("no renderer".into());
        return;
    };
    let side = fractal_sdf::render::MAX_IMAGE_SIDE;
    for layout in StereoLayout::ALL {
        for width in [0, 1, 3, side / 2, side / 2 + 1, side, side + 1, u32::MAX] {
            let stereo = Stereo::new(layout);
            row.case(
                &format!("{} eyes {width}x1", layout.name()),
                || match renderer.render_stereo(width, 1, &stereo) {
                    Err(e @ Error::Resolution { .. }) => refused(&e, "resolution"),
                    Err(e) => Err(e.to_string()),
                    Ok(image) if image.dimensions() == layout.size(width, 1) => Ok(End::Correct),
                    Ok(image) => Err(format!("a picture of {:?}", image.dimensions())),
                },
            );
        }
    }
}

fn panicking_tests(row: &mut Row) {
    for (i, threshold) in [-2.0, -0.5, 0.0, 0.3, 0.9, 2.0].into_iter().enumerate() {
        row.case(
            &format!("membership test panicking right of x = {threshold}"),
            || {
                let shape = InsideShape::new(
                    &format!("touchy{i}"),
                    &[],
                    InsideBounds::sphere(DVec3::ZERO, 1.0),
                    move |p, _| {
                        assert!(p.x < threshold, "cannot look right of {threshold}");
                        p.length() < 0.8
                    },
                    "return length(p) < R(0.8);",
                )
                .map_err(|e| e.to_string())?;
                let compiled = Scene::new(shape.node::<f64>([]))
                    .compile()
                    .map_err(|e| e.to_string())?;
                let options = GridOptions::default().resolution(10).sampler(Sampler::Cpu);
                match mesh::extract(&compiled, &options) {
                    Err(e) => refused(&e, "cannot look right of"),
                    Ok(m) if m.topology().is_closed_manifold() => Ok(End::Correct),
                    Ok(_) => Err("a mesh that is not closed".into()),
                }
            },
        );
    }
}

fn custom_bodies(row: &mut Row) {
    let bodies = [
        "return length(p) - r;",
        "return length(p) - r;\0",
        "return 1.0; } real DE(real3 p, __global const real* params) { return 0.0;",
        "#define DE(p, params) 0\nreturn length(p) - r;",
        "#undef R\nreturn length(p) - r;",
        "return length(p) - r; }",
        "{ return length(p) - r;",
        "return length(p) - r; /* \u{7} */",
        "\u{1b}[31mreturn length(p) - r;",
        "return length(p) - r;\r\n",
        "",
        "   ",
        "return (length(p) - r);",
        "real q = r; return length(p) - q;",
        "#define DE_shade 1\nreturn 1.0;",
        "// }\nreturn length(p) - r;",
    ];
    for body in bodies {
        row.case(&format!("custom body {body:?}"), || {
            let shape = match CustomShape::new(
                "bodied",
                &[("r", fractal_sdf::scene::Rule::Positive)],
                |p, a| p.length() - a[0],
                body,
            ) {
                Err(e) => return refused(&e, "bodied"),
                Ok(s) => s,
            };
            let compiled = Scene::new(shape.node([1.0]))
                .compile()
                .map_err(|e| e.to_string())?;
            match codegen::emit(&compiled, &program(Precision::F32)) {
                Err(e) => refused(&e, "bodied"),
                Ok(kernel) if !kernel.source.contains('\0') => Ok(End::Correct),
                Ok(_) => Err("a NUL reached the program".into()),
            }
        });
    }
}

/// A class of cases: adds its cases to a row.
type Class = fn(&mut Row);

/// Runs every class and prints the table; fails on any case that ended
/// neither as a typed error nor as a checked result.
pub fn run(with_device: bool) {
    let mut rows: Vec<(&str, Row)> = Vec::new();
    let classes: [(&str, Class); 6] = [
        ("twist and bend rates", warp_rates),
        ("inside shapes' bounds", inside_bounds),
        ("brute-force steps", brute_steps),
        ("sampled boxes", mesh_boxes),
        ("output file names", output_names),
        ("panicking membership tests", panicking_tests),
    ];
    for (name, class) in classes {
        let mut row = Row::default();
        class(&mut row);
        rows.push((name, row));
    }
    let mut row = Row::default();
    custom_bodies(&mut row);
    rows.push(("custom bodies", row));
    if with_device {
        let mut row = Row::default();
        stereo_sizes(&mut row);
        rows.push(("stereo sizes", row));
    }
    println!(
        "{:<28} {:>6} {:>12} {:>14}",
        "class", "cases", "typed error", "correct result"
    );
    let mut total = 0;
    let mut failures = Vec::new();
    for (name, row) in &rows {
        println!(
            "{name:<28} {:>6} {:>12} {:>14}",
            row.cases, row.refused, row.correct
        );
        total += row.cases;
        failures.extend(row.failures.iter().cloned());
    }
    println!("{total} cases, {} ended otherwise", failures.len());
    assert!(total >= 200, "only {total} cases");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
