//! The OpenCL twin of a node against its CPU reference.

use glam::DVec3;

use super::check::{Check, Failure, GeneratedProgram, Tally, Tested};
use crate::codegen::KernelSource;
use crate::cpu::Evaluator;
use crate::error::Error;
use crate::quality::Precision;
use crate::render::{DeviceSelector, PointEvaluator};
use crate::scene::{InsideShape, Node};

/// Deterministic pseudo-random points in the cube `[-extent, extent]^3`
/// (xorshift64 from `seed`), for checks that must not vary between runs.
#[must_use]
pub fn random_points(count: usize, extent: f64, seed: u64) -> Vec<DVec3> {
    let mut s = seed.max(1);
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        #[allow(clippy::cast_precision_loss)]
        let unit = (s >> 11) as f64 / (1u64 << 53) as f64;
        (2.0 * unit - 1.0) * extent
    };
    (0..count)
        .map(|_| DVec3::new(next(), next(), next()))
        .collect()
}

/// Points where formulas tend to break: the origin, points on the axes and
/// diagonals from `1e-7` to `1e6` away (through the fractals' bailout
/// radii 2 and 4).
#[must_use]
pub fn spicy_points() -> Vec<DVec3> {
    let dirs = [
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        -DVec3::X,
        -DVec3::Y,
        -DVec3::Z,
        DVec3::ONE.normalize(),
        DVec3::new(-1.0, 1.0, -1.0).normalize(),
    ];
    let mut points = vec![DVec3::ZERO];
    for d in dirs {
        for r in [1e-7, 1e-3, 0.5, 1.0, 2.0, 4.0, 1e3, 1e6] {
            points.push(d * r);
        }
    }
    points
}

/// Checks that `node`'s generated OpenCL code, run on the selected device
/// in `precision`, agrees with the CPU reference (evaluated in the same
/// precision) at every point: `|device - cpu| <= tolerance * max(1, |cpu|)`
/// for the distance and for each colour channel, `DE` and `DE_shade`
/// return the same distance, and every value is finite.
///
/// Tolerances: on PoCL (a CPU device) the crate's own conformance suite
/// measures at worst `3.6e-6` in F32 and `7.8e-16` in F64 over every node
/// kind and gallery scene, and holds them to `2e-5` and `1e-14`; GPUs'
/// single-precision built-ins are less exact, so `1e-4` and `1e-10` are
/// safer starting points there. [`Tested::worst`] says how much of the
/// tolerance a passing run used.
///
/// # Errors
/// [`Check::Valid`] if the node does not validate; [`Check::Build`] if the
/// generated program does not build (the detail has the compiler's
/// message, for a custom shape the line of its body); [`Check::Device`] if
/// there is no device to run it on or running it fails; otherwise the
/// point with the largest relative error. Every failure after code
/// generation keeps the generated program ([`Failure::program`]) and says
/// where it saved it.
///
/// ```no_run
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::quality::Precision;
/// use fractal_sdf::render::DeviceSelector;
/// use fractal_sdf::testing::{check_device_matches_cpu, random_points};
///
/// let points = random_points(1000, 2.0, 7);
/// check_device_matches_cpu(&torus(1.0, 0.25), &DeviceSelector::auto(), Precision::F32, &points, 1e-4)?;
/// # Ok::<(), fractal_sdf::testing::Failure>(())
/// ```
pub fn check_device_matches_cpu(
    node: &Node,
    device: &DeviceSelector,
    precision: Precision,
    points: &[DVec3],
    tolerance: f64,
) -> Result<Tested, Failure> {
    let cpu = Evaluator::new(node).map_err(|e| Failure {
        detail: e.to_string(),
        ..Failure::new(Check::Valid, vec![], vec![], 0.0, 0.0)
    })?;
    let twin = PointEvaluator::new(node, precision, device).map_err(not_run)?;
    let keep = |failure: Failure| keep_source(failure, twin.source());
    let got = twin.eval(points).map_err(|e| keep(not_run(e)))?;
    let mut tally = Tally::new();
    for (&p, g) in points.iter().zip(&got) {
        let (distance, color) = match precision {
            Precision::F32 => {
                let s = cpu.sample::<f32>(p.as_vec3().into());
                (f64::from(s.distance), glam::Vec3::from(s.color).as_dvec3())
            }
            Precision::F64 => {
                let s = cpu.sample::<f64>(p.into());
                (s.distance, DVec3::from(s.color))
            }
        };
        let finite = g.distance.is_finite() && g.trap.is_finite() && g.color.is_finite();
        if !finite || !distance.is_finite() {
            let value = if finite { distance } else { g.distance };
            tally.fail(Failure {
                detail: "the distance".into(),
                ..Failure::new(Check::Finite, vec![p], vec![value], value, 0.0)
            });
            continue;
        }
        let mut worst: Option<Failure> = None;
        let mut largest: f64 = 0.0;
        let mut compare = |what: &str, device: f64, cpu: f64| {
            let error = (device - cpu).abs() / cpu.abs().max(1.0);
            largest = largest.max(error);
            if error > tolerance && worst.as_ref().is_none_or(|w| error > w.measured) {
                worst = Some(Failure {
                    detail: what.into(),
                    ..Failure::new(
                        Check::DeviceMatchesCpu,
                        vec![p],
                        vec![device, cpu],
                        error,
                        tolerance,
                    )
                });
            }
        };
        compare("DE", g.distance, distance);
        compare("DE_shade's distance", g.shade_distance, g.distance);
        for (i, channel) in ["red", "green", "blue"].into_iter().enumerate() {
            compare(channel, g.color[i], color[i]);
        }
        match worst {
            Some(f) => tally.fail(f),
            None => tally.pass(largest / tolerance),
        }
    }
    tally.finish().map_err(keep)
}

/// Checks an inside shape's OpenCL test against its CPU test at `points`,
/// with parameter values `args`: whether each point is in the set. Near the
/// set's surface an `F32` test may decide a point differently from the
/// CPU's `f64` one (an orbit that escapes at the last iteration), so a
/// fraction `allowed` of the points may disagree; 0 demands agreement
/// everywhere.
///
/// Returns the points tested and, as `worst`, the fraction that disagreed
/// over `allowed`.
///
/// # Errors
/// [`Check::Valid`], [`Check::Build`] or [`Check::Device`] as
/// [`check_device_matches_cpu`]; [`Check::InsideMatchesDevice`] with the
/// first disagreeing point when more than `allowed` of them disagree.
///
/// ```no_run
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::quality::Precision;
/// use fractal_sdf::scene::InsideShape;
/// use fractal_sdf::render::DeviceSelector;
/// use fractal_sdf::testing::{check_inside_matches_device, random_points};
///
/// let points = random_points(2000, 2.0, 3);
/// let bulb = InsideShape::mandelbulb();
/// check_inside_matches_device(&bulb, &[8.0, 8.0], &DeviceSelector::auto(), Precision::F64, &points, 0.0)?;
/// # Ok::<(), fractal_sdf::testing::Failure>(())
/// ```
pub fn check_inside_matches_device(
    shape: &InsideShape,
    args: &[f64],
    device: &DeviceSelector,
    precision: Precision,
    points: &[DVec3],
    allowed: f64,
) -> Result<Tested, Failure> {
    let node = shape.node(args.iter().copied());
    Evaluator::new(&node).map_err(|e| Failure {
        detail: e.to_string(),
        ..Failure::new(Check::Valid, vec![], vec![], 0.0, 0.0)
    })?;
    let twin = PointEvaluator::new(&node, precision, device).map_err(not_run)?;
    let got = twin
        .eval(points)
        .map_err(|e| keep_source(not_run(e), twin.source()))?;
    let mut first: Option<(DVec3, bool, bool)> = None;
    let mut violations = 0;
    for (&p, g) in points.iter().zip(&got) {
        let device_in = g.distance < 0.0;
        let cpu_in = shape.contains(p, args);
        if device_in != cpu_in {
            violations += 1;
            first.get_or_insert((p, device_in, cpu_in));
        }
    }
    #[allow(clippy::cast_precision_loss)]
    let fraction = violations as f64 / points.len().max(1) as f64;
    match first {
        Some((p, device_in, cpu_in)) if fraction > allowed => {
            let failure = Failure {
                violations,
                checked: points.len(),
                ..Failure::new(
                    Check::InsideMatchesDevice,
                    vec![p],
                    vec![f64::from(u8::from(device_in)), f64::from(u8::from(cpu_in))],
                    fraction,
                    allowed,
                )
            };
            Err(keep_source(failure, twin.source()))
        }
        _ if points.is_empty() => Err(Failure {
            detail: "points".into(),
            violations: 1,
            ..Failure::new(Check::TooFewTested, vec![], vec![], 0.0, 1.0)
        }),
        _ => Ok(Tested {
            inputs: points.len(),
            balls: points.len(),
            signs: 0,
            worst: if allowed > 0.0 {
                fraction / allowed
            } else {
                0.0
            },
        }),
    }
}

/// The failure for a device check that could not run: the program did not
/// build ([`Check::Build`], with the program), or the device could not be
/// found or run it ([`Check::Device`]).
fn not_run(error: Error) -> Failure {
    let source = error.kernel_source().map(str::to_string);
    let check = if source.is_some() {
        Check::Build
    } else {
        Check::Device
    };
    let failure = Failure {
        detail: error.to_string(),
        ..Failure::new(check, vec![], vec![], 0.0, 0.0)
    };
    match source {
        Some(source) => {
            let hash = KernelSource::hash_of(&source);
            with_source(failure, source, hash)
        }
        None => failure,
    }
}

/// `failure` with the program the check ran.
fn keep_source(failure: Failure, source: &KernelSource) -> Failure {
    with_source(failure, source.source.clone(), source.hash)
}

/// `failure` with `source`, saved to a file named after its hash in the
/// temporary directory (overwritten by the next failure of the same
/// program, which has the same text).
fn with_source(failure: Failure, source: String, hash: u64) -> Failure {
    let path = std::env::temp_dir().join(format!("fractal-sdf-{hash:016x}.cl"));
    let path = std::fs::write(&path, &source).is_ok().then_some(path);
    Failure {
        program: Some(Box::new(GeneratedProgram { source, path })),
        ..failure
    }
}
