//! The OpenCL twin of a node against its CPU reference.

use glam::DVec3;

use super::check::{Check, Failure, Tally};
use crate::cpu::Evaluator;
use crate::quality::Precision;
use crate::render::{DeviceSelector, PointEvaluator};
use crate::scene::Node;

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
/// Good tolerances: `1e-4` for F32 and `1e-10` for F64.
///
/// # Errors
/// [`Check::Valid`] if the node does not validate or the program cannot be
/// built or run (the detail says why); otherwise the point with the largest
/// relative error.
///
/// ```no_run
/// use fractal_sdf::prelude::*;
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
) -> Result<(), Failure> {
    let invalid = |detail: String| Failure {
        detail,
        ..Failure::new(Check::Valid, vec![], vec![], 0.0, 0.0)
    };
    let cpu = Evaluator::new(node).map_err(|e| invalid(e.to_string()))?;
    let twin = PointEvaluator::new(node, precision, device).map_err(|e| invalid(e.to_string()))?;
    let got = twin.eval(points).map_err(|e| invalid(e.to_string()))?;
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
        let mut compare = |what: &str, device: f64, cpu: f64| {
            let error = (device - cpu).abs() / cpu.abs().max(1.0);
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
            None => tally.pass(),
        }
    }
    tally.finish()
}
