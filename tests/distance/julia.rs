//! Quaternion Julia sets for any constant: the estimate never exceeds the
//! distance to the points found inside, whether or not the constant is in
//! the Mandelbrot set, measured over random cases
//! (`julia_worst_ratio_is_measured`).

use crate::common::fixtures::JULIA_C;
use fractal_sdf::cpu;
use fractal_sdf::cpu::sdf;
use fractal_sdf::prelude::*;
use fractal_sdf::scene::Param;
use fractal_sdf::scene::QuaternionJulia;
use fractal_sdf::testing::{check_never_overestimates, julia_inside, unit_vector};
use proptest::prelude::*;

use super::fractals::SURFACE_BAND;

proptest! {
    // Cheap cases (under 3 ms each), and most constants give sparse dust:
    // many of them.
    #![proptest_config(ProptestConfig::with_cases(1024))]

    /// Any valid constant (connected sets and dust, up to the corners of
    /// `[-4, 4]^4`), any slice, bailouts from 1 to 1e6 and 8 to 256
    /// iterations, `c` baked or set at run time, with points near bounded
    /// points, near the critical point and its preimages and near tips: the
    /// estimate never exceeds the distance to the points that stay within
    /// the bailout for 64 more iterations than it takes. Points that stay
    /// within it for the estimator's own iterations are held to this only
    /// where the estimate is at least [`SURFACE_BAND`].
    #[test]
    fn julia_never_overestimates_for_any_constant(case in julia_case()) {
        let eval = case.evaluator();
        let points = case.checked_points(&eval);
        check_never_overestimates(&eval, |q| case.inside(q), &points, 16)?;
    }
}

/// One quaternion Julia set for the properties below: the constant, slice,
/// iterations and bailout, whether `c` is a dynamic parameter (set at run
/// time, after the evaluator is built), and where the test points are put.
#[derive(Debug, Clone)]
struct JuliaCase {
    c: [f64; 4],
    slice_w: f64,
    iterations: u32,
    bailout: f64,
    dynamic: bool,
    focus: Focus,
    seed: u64,
}

/// Where a [`JuliaCase`] looks, besides points near bounded points and the
/// slice's origin: near a preimage of the critical point 0 (the slice is
/// moved through it), or outward from the repelling fixed point (a tip of
/// the set; the slice is moved through it).
#[derive(Debug, Clone, Copy)]
enum Focus {
    Anywhere,
    CriticalPreimage(u32),
    Tip,
}

/// The names of the dynamic components of `c`.
const C_NAMES: [&str; 4] = ["c.x", "c.y", "c.z", "c.w"];

impl JuliaCase {
    /// The slice and, for a focused case, the point of interest in it.
    fn focus_point(&self) -> Option<(f64, DVec3)> {
        let c = quaternion(self.c);
        let q = match self.focus {
            Focus::Anywhere => return None,
            Focus::CriticalPreimage(depth) => {
                // 0 = z^2 + c at each step back: z = ±sqrt(z' - c).
                let mut z = DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0);
                for i in 0..depth {
                    let root = quaternion_sqrt(z - c);
                    z = if (self.seed >> i) & 1 == 0 {
                        root
                    } else {
                        -root
                    };
                }
                z
            }
            // beta = (1 + sqrt(1 - 4c)) / 2 solves beta^2 + c = beta.
            Focus::Tip => {
                let one = DQuat::from_xyzw(0.0, 0.0, 0.0, 1.0);
                (one + quaternion_sqrt(one - c * 4.0)) * 0.5
            }
        };
        Some((q.z, dvec3(q.w, q.x, q.y)))
    }

    fn slice(&self) -> f64 {
        self.focus_point().map_or(self.slice_w, |(w, _)| w)
    }

    /// The node, with `c` baked or dynamic; a dynamic `c` starts at the
    /// gallery's constant and is changed to `self.c` afterwards.
    fn evaluator(&self) -> cpu::Evaluator {
        let c: [Param; 4] = if self.dynamic {
            std::array::from_fn(|i| param(C_NAMES[i], JULIA_C[i]))
        } else {
            self.c.map(Param::from)
        };
        let node: Node = QuaternionJulia::new(c)
            .iterations(self.iterations)
            .bailout(self.bailout)
            .slice_w(self.slice())
            .into();
        let mut eval = cpu::Evaluator::new(&node).expect("valid Julia settings");
        if self.dynamic {
            for (name, v) in C_NAMES.into_iter().zip(self.c) {
                eval.set_param(name, v).expect("a dynamic component");
            }
        }
        eval
    }

    /// Whether `p` stays within the bailout for the estimator's iterations
    /// and 64 more: the set the estimate is checked against.
    fn inside(&self, p: DVec3) -> bool {
        julia_inside(p, self.c, self.slice(), self.iterations + 64, self.bailout)
    }

    /// Whether `p` escapes within the estimator's own iterations.
    fn escapes(&self, p: DVec3) -> bool {
        !julia_inside(p, self.c, self.slice(), self.iterations, self.bailout)
    }

    /// Points near the set: around up to 8 bounded points found in the
    /// ball that holds it, around the slice's origin (the critical point 0
    /// for slice 0) and the focus point, plus points spread through 1.6
    /// times that ball.
    fn points(&self) -> Vec<DVec3> {
        let mut rng = SplitMix(self.seed);
        let radius = fractal_sdf::math::julia_radius(self.c).min(self.bailout);
        let mut points = Vec::new();
        let mut bounded = Vec::new();
        for _ in 0..1500 {
            let q = rng.in_ball(radius);
            if self.inside(q) {
                bounded.push(q);
                if bounded.len() == 8 {
                    break;
                }
            }
        }
        let mut centres = bounded;
        centres.push(DVec3::ZERO);
        if let Some((_, f)) = self.focus_point() {
            centres.push(f);
            // Straight outward from the focus (from a tip, along the axis).
            for k in 0..8 {
                let t = 10f64.powf(-3.0 + 0.5 * f64::from(k)) * radius;
                points.push(f + f.normalize_or_zero() * t);
            }
        }
        for centre in centres {
            for _ in 0..8 {
                let r = 10f64.powf(rng.range(-3.0, 0.0));
                points.push(centre + rng.direction() * r);
            }
        }
        for _ in 0..24 {
            points.push(rng.in_ball(1.6 * radius));
        }
        points
    }

    /// The points the estimate is held to: those that escape within its
    /// iterations (any positive estimate), and others whose estimate is at
    /// least the surface band (a point that stays within the bailout for
    /// `N` iterations but not for more may get a small positive estimate).
    fn checked_points(&self, eval: &cpu::Evaluator) -> Vec<DVec3> {
        self.points()
            .into_iter()
            .filter(|&p| {
                let d = eval.distance(p);
                d >= SURFACE_BAND || (d > 0.0 && self.escapes(p))
            })
            .collect()
    }
}

/// `c` as a glam quaternion (`c.x` is the real part, glam's `w`).
pub(super) fn quaternion(c: [f64; 4]) -> DQuat {
    DQuat::from_xyzw(c[1], c[2], c[3], c[0])
}

/// A square root of the quaternion `q`, in the plane of 1 and `q`'s vector
/// part.
fn quaternion_sqrt(q: DQuat) -> DQuat {
    let v = dvec3(q.x, q.y, q.z);
    let r = q.length();
    let real = ((r + q.w) / 2.0).max(0.0).sqrt();
    let imaginary = v.try_normalize().unwrap_or(DVec3::X) * ((r - q.w) / 2.0).max(0.0).sqrt();
    DQuat::from_xyzw(imaginary.x, imaginary.y, imaginary.z, real)
}

/// SplitMix64: the points of a case follow from its seed.
pub(super) struct SplitMix(pub(super) u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn unit(&mut self) -> f64 {
        #[allow(clippy::cast_precision_loss)]
        let u = (self.next() >> 11) as f64;
        u / (1u64 << 53) as f64
    }

    pub(super) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    fn direction(&mut self) -> DVec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let rho = (1.0 - z * z).max(0.0).sqrt();
        dvec3(rho * phi.cos(), rho * phi.sin(), z)
    }

    pub(super) fn in_ball(&mut self, radius: f64) -> DVec3 {
        self.direction() * radius * self.unit().cbrt()
    }
}

/// Constants: near the Mandelbrot set's own (`c' = a + i b` in a box
/// around it, its vector part real, in the (1, i) plane or turned
/// anywhere), anywhere in the valid `[-4, 4]^4`, and the corners and axes
/// of that range.
fn julia_constant() -> impl Strategy<Value = [f64; 4]> {
    let near_locus = (-2.2..0.6f64, 0.0..1.3f64, unit_vector(), 0..3u8).prop_map(
        |(a, b, u, plane)| match plane {
            0 => [a, 0.0, 0.0, 0.0],
            1 => [a, b, 0.0, 0.0],
            _ => [a, b * u.x, b * u.y, b * u.z],
        },
    );
    let extreme = prop::sample::select(vec![-4.0, -2.0, 0.0, 0.25, 4.0]);
    prop_oneof![
        6 => near_locus,
        2 => [-4.0..=4.0f64, -4.0..=4.0f64, -4.0..=4.0f64, -4.0..=4.0f64],
        1 => [extreme.clone(), extreme.clone(), extreme.clone(), extreme],
        1 => Just(JULIA_C),
    ]
}

fn julia_case() -> impl Strategy<Value = JuliaCase> {
    let bailout = prop_oneof![
        Just(1.0),
        Just(2.0),
        Just(4.0),
        Just(1e6),
        (0.0..6.0f64).prop_map(|e| 10f64.powf(e)),
    ];
    let iterations = prop_oneof![3 => 8u32..=16, 2 => 17u32..=64, 1 => 65u32..=256];
    let focus = prop_oneof![
        2 => Just(Focus::Anywhere),
        1 => (0u32..=5).prop_map(Focus::CriticalPreimage),
        1 => Just(Focus::Tip),
    ];
    (
        julia_constant(),
        prop_oneof![Just(0.0), -0.6..0.6f64, -2.0..2.0f64],
        iterations,
        bailout,
        any::<bool>(),
        focus,
        any::<u64>(),
    )
        .prop_map(
            |(c, slice_w, iterations, bailout, dynamic, focus, seed)| JuliaCase {
                c,
                slice_w,
                iterations,
                bailout,
                dynamic,
                focus,
                seed,
            },
        )
}

/// For each of the case's checked points at which a point inside was
/// found within twice the estimate `d`: the ratio of `d` to the distance to
/// the nearest, the point, that inside point, and whether the point
/// escapes within the estimator's iterations. Candidates are the point
/// itself, 88 points straight towards the surface (64 evenly spaced up to
/// `2 d`, 24 at `d / 2^k`) and 48 within `2 d`.
fn julia_ratios(case: &JuliaCase) -> Vec<(f64, DVec3, DVec3, bool)> {
    let eval = case.evaluator();
    let mut rng = SplitMix(case.seed ^ 0x5eed);
    let mut ratios = Vec::new();
    for p in case.checked_points(&eval) {
        let d = eval.distance(p);
        let descent = -eval.normal(p, 1e-6 * d.max(1e-6));
        let along = (1..=64)
            .map(|i| d * f64::from(i) / 32.0)
            .chain((1..=24).map(|k| d * 0.5f64.powi(k)))
            .map(|t| p + descent * t);
        let inner: Vec<DVec3> = (0..48)
            .map(|_| p + rng.direction() * 2.0 * d * rng.unit().cbrt())
            .collect();
        let nearest = std::iter::once(p)
            .chain(along)
            .chain(inner)
            .filter(|&q| case.inside(q))
            .min_by(|a, b| a.distance(p).total_cmp(&b.distance(p)));
        if let Some(q) = nearest {
            ratios.push((d / p.distance(q), p, q, case.escapes(p)));
        }
    }
    ratios
}

/// The measurement behind the Julia property and the `QuaternionJulia`
/// docs: over `JULIA_CASES` (default 2000) cases from the property's
/// strategy, the worst ratio of the estimate to the distance to the
/// nearest point found inside, by whether `c` is in the Mandelbrot set
/// (its critical orbit stays within 2 for 1000 steps), whether the point
/// escapes within the estimator's iterations, and whether the bailout is
/// at most 16; and over the points within 1.5 ball radii of the cases
/// whose constant keeps the escape-time estimate there (bailout at least
/// 2.5 ball radii, critical orbit within 0.9 for the iterations and 2
/// more). It also asserts that no ratio found exceeds 1. `make test` runs
/// 200 cases; for the guide's figures run
/// `JULIA_CASES=3000 cargo test --release --features proptest --test distance -- --nocapture julia_worst_ratio`.
#[test]
fn julia_worst_ratio_is_measured() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    use std::collections::BTreeMap;
    let cases: usize = std::env::var("JULIA_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(200);
    let mut runner = TestRunner::deterministic();
    let strategy = julia_case();
    let mut worst: BTreeMap<String, (f64, JuliaCase, DVec3, DVec3)> = BTreeMap::new();
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    for _ in 0..cases {
        let case = strategy.new_tree(&mut runner).unwrap().current();
        let connected = julia_inside(DVec3::ZERO, case.c, 0.0, 1000, 2.0);
        let escape_time = case.bailout >= 2.5 * fractal_sdf::math::julia_radius(case.c)
            && !sdf::julia_critical_leaves(case.c, case.iterations + 2, 0.81);
        let set = if connected { "connected" } else { "dust" };
        let bailout = if case.bailout <= 16.0 {
            "bailout <= 16"
        } else {
            "bailout > 16"
        };
        let mut groups = vec![format!("{set}, {bailout}")];
        if escape_time {
            groups.push("escape-time estimate".into());
        }
        for group in &groups {
            *counts.entry(group.clone()).or_default() += 1;
        }
        let radius = fractal_sdf::math::julia_radius(case.c).min(case.bailout);
        for (ratio, p, q, escapes) in julia_ratios(&case) {
            let which = if escapes { "escaping" } else { "band" };
            let near = p.extend(case.slice()).length() <= 1.5 * radius;
            for group in &groups {
                if group == "escape-time estimate" && !near {
                    continue;
                }
                let key = format!("{group}, {which} points");
                if worst.get(&key).is_none_or(|w| ratio > w.0) {
                    worst.insert(key, (ratio, case.clone(), p, q));
                }
            }
        }
    }
    for (group, n) in &counts {
        for which in ["escaping", "band"] {
            let key = format!("{group}, {which} points");
            match worst.get(&key) {
                Some((ratio, case, p, q)) => eprintln!(
                    "{key} ({n} cases): worst ratio {ratio:.6} at p = {p} (inside: {q}) for {case:?}"
                ),
                None => eprintln!("{key} ({n} cases): no inside point within twice the estimate"),
            }
        }
    }
    // The estimate never exceeds the distance to a point found inside
    // (rounding aside: the bound is exact at the tips of real constants).
    for (key, (ratio, case, p, _)) in &worst {
        assert!(
            *ratio <= 1.0 + 1e-9,
            "{key}: ratio {ratio} at {p} for {case:?}"
        );
    }
}
