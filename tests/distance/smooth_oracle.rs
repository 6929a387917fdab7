//! The smooth booleans against closed forms that share no code with the
//! implementation: the two half-spaces `x <= 0` and `y <= 0` have the
//! distances `a = x` and `b = y` exactly, so at any point the polynomial
//! smooth union of radius `k` must equal
//! `min(a, b) - max(k - |a - b|, 0)^2 / (4k)` (Quilez's published form),
//! the smooth intersection `max(a, b) + max(k - |a - b|, 0)^2 / (4k)`, and
//! the smooth subtraction the intersection with `-b`. Its known limits
//! follow: exactly `k / 4` below the hard union where `a = b`, exactly the
//! hard union where `|a - b| >= k`, so the blended surface crosses the
//! diagonal `x = y` at `k / 4`. The colour is the two children's mean where
//! `a = b` and the nearer child's where `|a - b| >= k`.
//!
//! Checked on the CPU reference (both precisions) and on the device, so a
//! change to the blend made in both twins alike is caught here, not only by
//! the golden images.
use crate::gpu;

use fractal_sdf::cpu;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{DeviceSelector, PointEvaluator};

const RED: DVec3 = DVec3::new(1.0, 0.0, 0.0);
const BLUE: DVec3 = DVec3::new(0.0, 0.0, 1.0);
const RADII: [f64; 4] = [0.05, 0.3, 1.0, 2.5];

/// The half-spaces `x <= 0` (red) and `y <= 0` (blue).
fn halves() -> (Node, Node) {
    (
        plane(DVec3::X, 0.0).color(RED),
        plane(DVec3::Y, 0.0).color(BLUE),
    )
}

#[derive(Clone, Copy, Debug)]
enum Op {
    Union,
    Intersect,
    Subtract,
}

impl Op {
    fn node(self, k: f64) -> Node {
        let (a, b) = halves();
        match self {
            Op::Union => a.smooth_union(b, k),
            Op::Intersect => a.smooth_intersect(b, k),
            Op::Subtract => a.smooth_subtract(b, k),
        }
    }

    /// The closed form at `p`: the published polynomial blend, written
    /// from the definition rather than from the code.
    fn expected(self, p: DVec3, k: f64) -> f64 {
        let (a, b) = match self {
            Op::Subtract => (p.x, -p.y),
            _ => (p.x, p.y),
        };
        let lift = (k - (a - b).abs()).max(0.0).powi(2) / (4.0 * k);
        match self {
            Op::Union => a.min(b) - lift,
            Op::Intersect | Op::Subtract => a.max(b) + lift,
        }
    }
}

/// Points on the diagonal (`a = b`), inside the blend (`|a - b| = k / 2`)
/// and outside it (`|a - b| = k` and `2k`), on both sides of the corner.
fn points(k: f64) -> Vec<DVec3> {
    let mut points = Vec::new();
    for t in [-1.5, -0.2, 0.0, 0.01, 0.4, 3.0] {
        for gap in [0.0, 0.5 * k, -0.5 * k, k, -k, 2.0 * k] {
            points.push(dvec3(t + gap, t, 0.7));
        }
    }
    points
}

/// Relative to `max(1, |value|)`. Measured worst errors against the closed
/// forms, CPU and PoCL together: 1.2e-16 in f64 and 5.4e-8 in f32 (the
/// points themselves rounded to f32); the tolerances are about 100 and 20
/// times those.
fn tolerance(precision: Precision) -> f64 {
    match precision {
        Precision::F64 => 1e-14,
        _ => 1e-6,
    }
}

fn assert_close(what: &str, got: f64, want: f64, tolerance: f64) {
    let error = (got - want).abs() / want.abs().max(1.0);
    assert!(
        error <= tolerance,
        "{what}: got {got}, closed form {want} (error {error:e})"
    );
}

#[test]
fn smooth_booleans_match_the_closed_forms_on_the_cpu() {
    for op in [Op::Union, Op::Intersect, Op::Subtract] {
        for k in RADII {
            let eval = cpu::Evaluator::new(&op.node(k)).unwrap();
            for p in points(k) {
                let want = op.expected(p, k);
                let what = format!("{op:?} k = {k} at {p}");
                let d64 = eval.sample::<f64>(p.into()).distance;
                assert_close(&what, d64, want, tolerance(Precision::F64));
                let d32 = eval.sample::<f32>(p.as_vec3().into()).distance;
                assert_close(&what, f64::from(d32), want, tolerance(Precision::F32));
            }
        }
    }
}

#[test]
fn smooth_union_limits_hold() {
    for k in RADII {
        let eval = cpu::Evaluator::new(&Op::Union.node(k)).unwrap();
        // A quarter of k below the hard union on the diagonal, where the
        // colours mix evenly.
        for t in [-1.0, 0.0, 0.5, 2.0] {
            let s = eval.sample::<f64>(dvec3(t, t, 0.0).into());
            assert_close("diagonal", s.distance, t - k / 4.0, 1e-14);
            let color = DVec3::from(s.color);
            assert!(
                color.abs_diff_eq(0.5 * (RED + BLUE), 1e-12),
                "k = {k}: {color} on the diagonal"
            );
        }
        // The hard union, and the nearer child's colour, from |a - b| = k on.
        for gap in [k, 1.5 * k, 10.0 * k] {
            let p = dvec3(0.3, 0.3 + gap, 0.0);
            let s = eval.sample::<f64>(p.into());
            assert_close("outside the blend", s.distance, 0.3, 1e-14);
            let color = DVec3::from(s.color);
            assert!(color.abs_diff_eq(RED, 1e-12), "k = {k}: {color} at {p}");
        }
        // The blended surface crosses the diagonal at x = y = k / 4: found by
        // bisection on the sign alone.
        let (mut lo, mut hi) = (0.0, 10.0);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if eval.distance(dvec3(mid, mid, 0.0)) <= 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        assert_close("crossing", lo, k / 4.0, 1e-14);
    }
    // k = 0 is the hard union exactly.
    let eval = cpu::Evaluator::new(&Op::Union.node(0.0)).unwrap();
    for p in points(0.3) {
        assert_eq!(eval.distance(p), p.x.min(p.y), "at {p}");
    }
}

#[test]
fn smooth_booleans_match_the_closed_forms_on_the_device() {
    let Some(device) = gpu::device() else {
        return;
    };
    let mut precisions = vec![Precision::F32];
    if gpu::fp64(&device) {
        precisions.push(Precision::F64);
    }
    for precision in precisions {
        for op in [Op::Union, Op::Intersect, Op::Subtract] {
            for k in RADII {
                let twin =
                    PointEvaluator::new(&op.node(k), precision, &DeviceSelector::auto()).unwrap();
                let points = points(k);
                let got = twin.eval(&points).unwrap();
                for (p, s) in points.iter().zip(&got) {
                    let what = format!("{op:?} k = {k} at {p} ({precision:?}, device)");
                    assert_close(&what, s.distance, op.expected(*p, k), tolerance(precision));
                }
            }
        }
    }
}
