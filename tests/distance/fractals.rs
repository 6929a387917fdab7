//! The fractal distance estimators: finite everywhere (f64 and f32), never
//! overestimating the distance to the set that independent membership tests
//! describe, invariant under the symmetries of their sets, and the two
//! Mandelbulb forms (trig-free integer and trigonometric) in agreement.
//!
//! Measured, not hidden: relative to "does not escape within the same N
//! iterations", the Mandelbulb and Julia estimators overestimate in a thin
//! band around their surface (the escape set also holds points where
//! `1 < |z_N| <= bailout`, where the estimate is already positive). The
//! band is below 0.046 (in estimate units) for powers 3 to 16 with 8 to 32
//! iterations and bailout 2 or 4; the tests below allow a band of
//! [`SURFACE_BAND`]. Outside that regime it is wider: power 2 with
//! bailout 2 (whose set touches the bailout sphere) up to 1.17, and 4
//! iterations up to 0.82 (power 3). Far from the Mandelbulb the raw
//! escape-time estimate (`0.5 r ln r` beyond the bailout radius) grows
//! faster than the distance; beyond 1.5 times the radius of its proven
//! bounding ball the estimator returns the distance to that ball instead
//! (`mandelbulb_far_field_never_overestimates`).
//!
//! Quaternion Julia sets are held to the distance to the points that stay
//! within the bailout for 64 more iterations than the estimator takes, for
//! any valid constant (`julia_never_overestimates_for_any_constant`); only
//! at points that do not escape within its own iterations is a band
//! allowed (measured: about 0.06 with 4 iterations, 0.016 with 8, 0.009
//! with 12, 0.001 with 16). `julia_worst_ratio_is_measured` prints the
//! worst ratios; the estimator's docs (`cpu::sdf::julia`) say why the
//! constants outside the Mandelbrot set needed a proven bound.

use super::julia::{SplitMix, quaternion};
use crate::common::fixtures::{self, JULIA_C};
use approx::relative_eq;
use fractal_sdf::cpu;
use fractal_sdf::cpu::sdf;
use fractal_sdf::prelude::*;
use fractal_sdf::scene::Kind;
use fractal_sdf::scene::Mandelbulb;
use fractal_sdf::scene::Param;
use fractal_sdf::scene::QuaternionJulia;
use fractal_sdf::testing::{
    self, check_never_overestimates, fractal_node, julia_inside, mandelbulb_inside, menger_inside,
    point, sierpinski_inside, unit_vector,
};
use proptest::prelude::*;

/// Mandelbulb and Julia estimates are checked only where they are at least
/// this far from their surface (see the module docs for the measured band).
pub(super) const SURFACE_BAND: f64 = 0.06;

/// How many of the 256 points drawn near the Mandelbulb's surface must lie
/// outside [`SURFACE_BAND`] for its property test to count: half the
/// fewest measured (8 to 35, median 19, over 1,030 cases with four seeds).
const NEAR_MINIMUM: usize = 4;

/// The escape radius of an escape-time fractal node.
fn bailout(node: &Node) -> Option<f64> {
    match node.kind() {
        Kind::Mandelbulb(m) => Some(m.bailout.default_value()),
        Kind::Julia(j) => Some(j.bailout.default_value()),
        _ => None,
    }
}

/// The origin, points on the axes from tiny to huge, and points on, just
/// inside and just outside the bailout sphere.
fn spicy_points(bailout: Option<f64>, directions: &[DVec3]) -> Vec<DVec3> {
    let mut points = vec![DVec3::ZERO];
    for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
        for t in [1e-300, 1e-9, 0.5, 1.0, 2.0, 4.0, 1e3, 1e6] {
            points.push(axis * t);
            points.push(axis * -t);
        }
    }
    if let Some(b) = bailout {
        for &u in directions {
            for s in [1.0 - 1e-12, 1.0, 1.0 + 1e-12] {
                points.push(u * b * s);
            }
        }
    }
    points
}

fn assert_finite(eval: &cpu::Evaluator, node: &Node, points: &[DVec3]) {
    for &p in points {
        let s = eval.sample::<f64>(p.into());
        assert!(
            s.distance.is_finite() && (0.0..=1.0).contains(&s.trap),
            "{node:?} at {p}: distance {}, trap {}",
            s.distance,
            s.trap
        );
        let s = eval.sample::<f32>(p.as_vec3().into());
        assert!(
            s.distance.is_finite() && (0.0..=1.0).contains(&s.trap),
            "{node:?} at {p} in f32: distance {}, trap {}",
            s.distance,
            s.trap
        );
    }
}

proptest! {
    /// Any valid settings, anywhere in a large box, on the axes and on the
    /// bailout sphere: finite distances and traps in [0, 1], in both
    /// precisions.
    #[test]
    fn estimates_are_finite_everywhere(
        node in fractal_node(),
        near in prop::collection::vec(point(3.0), 8),
        far in prop::collection::vec(point(1e6), 8),
        directions in prop::collection::vec(unit_vector(), 4),
    ) {
        let eval = cpu::Evaluator::new(&node)?;
        let mut points = spicy_points(bailout(&node), &directions);
        points.extend(near);
        points.extend(far);
        assert_finite(&eval, &node, &points);
    }

    #[test]
    fn menger_never_overestimates(
        iterations in 0u32..=6,
        points in prop::collection::vec(point(1.6), 16),
    ) {
        check_never_overestimates(&menger(iterations), |p| menger_inside(p, iterations), &points, 16)?;
    }

    #[test]
    fn sierpinski_never_overestimates(
        iterations in 0u32..=8,
        points in prop::collection::vec(point(1.6), 16),
    ) {
        check_never_overestimates(
            &sierpinski(iterations),
            |p| sierpinski_inside(p, iterations),
            &points,
            16,
        )?;
    }

    /// Integer and non-integer powers, baked (integer powers take the
    /// trig-free form) or dynamic (always trigonometric), at points drawn
    /// within 1 of the surface by the membership test alone (most of them
    /// close to it) and points spread through `[-3, 3]^3`. Like the Julia
    /// sets, the estimate is held to the points that stay within the
    /// bailout for 64 more iterations than it takes, where it is at least
    /// [`SURFACE_BAND`]. At least [`NEAR_MINIMUM`] of the near points must
    /// be tested.
    #[test]
    fn mandelbulb_never_overestimates_near_the_surface(
        power in prop_oneof![(3u32..=16).prop_map(f64::from), 3.0..16.0f64],
        dynamic in any::<bool>(),
        iterations in 8u32..=32,
        bailout in prop_oneof![Just(2.0), Just(4.0)],
        seed in any::<u64>(),
        far in prop::collection::vec(point(3.0), 16),
    ) {
        let p = if dynamic { param("power", power) } else { Param::from(power) };
        let node: Node = Mandelbulb::new(p).iterations(iterations).bailout(bailout).into();
        let eval = cpu::Evaluator::new(&node)?;
        let escapes = |p| !mandelbulb_inside(p, power, iterations, bailout);
        let near = testing::near_surface_points(|p| !escapes(p), 1.6, 1.0, 256, seed);
        let near: Vec<_> = near
            .into_iter()
            .filter(|&p| eval.distance(p) >= SURFACE_BAND)
            .collect();
        prop_assert!(near.len() >= NEAR_MINIMUM, "only {} near points tested", near.len());
        let points: Vec<_> = near
            .into_iter()
            .chain(far.into_iter().filter(|&p| eval.distance(p) >= SURFACE_BAND))
            .collect();
        let inside = |p| mandelbulb_inside(p, power, iterations + 64, bailout);
        let tested = check_never_overestimates(&eval, inside, &points, 16)?;
        prop_assert_eq!(tested.balls, points.len());
    }

    /// The 48 symmetries of the cube (axis permutations and sign flips)
    /// leave the sponge's estimate unchanged, for any scale: exactly once
    /// folding has put the point in canonical order (iterations >= 1), up
    /// to rounding for the plain cube, whose bound sums the squares in the
    /// permuted order (an ulp or two; measured 0 over 2,400 images of
    /// points with PROPTEST_RNG_SEED=20261201, and in three other seeds).
    #[test]
    fn menger_is_invariant_under_the_cube_symmetries(
        node in testing::menger_node(),
        p in point(1.6),
    ) {
        let eval = cpu::Evaluator::new(&node)?;
        let d = eval.distance(p);
        for perm in PERMUTATIONS {
            for signs in 0..8u32 {
                let flip = |i: u32| if signs & (1 << i) == 0 { 1.0 } else { -1.0 };
                let q = dvec3(p[perm[0]] * flip(0), p[perm[1]] * flip(1), p[perm[2]] * flip(2));
                let dq = eval.distance(q);
                if node.kind().iterations() == Some(0) {
                    prop_assert!(relative_eq!(dq, d, epsilon = 1e-15, max_relative = 1e-15));
                } else {
                    prop_assert_eq!(dq, d, "{:?} at {} and {}", node, p, q);
                }
            }
        }
    }

    /// The 24 symmetries of the tetrahedron (axis permutations with an even
    /// number of sign flips) leave the estimate unchanged up to rounding,
    /// for any scale: the folds see the coordinates' sums in another order.
    /// Measured worst 3.7e-16 (absolute or relative, whichever is smaller)
    /// over 6,192 images of points (PROPTEST_RNG_SEED=20261201; 4.6e-16 in
    /// three other seeds); the tolerance is about 20 times that.
    #[test]
    fn sierpinski_is_invariant_under_the_tetrahedron_symmetries(
        node in testing::sierpinski_node(),
        p in point(1.6),
    ) {
        let eval = cpu::Evaluator::new(&node)?;
        let d = eval.distance(p);
        for perm in PERMUTATIONS {
            for flip in [[1.0, 1.0, 1.0], [-1.0, -1.0, 1.0], [-1.0, 1.0, -1.0], [1.0, -1.0, -1.0]] {
                let q = dvec3(p[perm[0]] * flip[0], p[perm[1]] * flip[1], p[perm[2]] * flip[2]);
                let dq = eval.distance(q);
                prop_assert!(
                    relative_eq!(dq, d, epsilon = 1e-14, max_relative = 1e-14),
                    "{:?}: {} at {}, {} at {}", node, d, p, dq, q
                );
            }
        }
    }

    /// Away from the surface the two forms of the integer-power map agree.
    /// The distances: measured worst 2.2e-12 relative over 3,897 points
    /// with |DE| >= 0.05 (PROPTEST_RNG_SEED=20261201; no worse over 46,803
    /// points in 12 seeds, and 1.5e-11 in an earlier run); the tolerance
    /// is about 70 times the largest. The orbit traps, taken before the
    /// orbit grows: measured worst 5.3e-15 (1.2e-14 in 12 seeds); the
    /// tolerance is about 80 times the largest.
    #[test]
    fn trig_free_and_trigonometric_mandelbulbs_agree_away_from_the_surface(
        power in 2u32..=16,
        iterations in 1u32..=16,
        points in prop::collection::vec(point(2.0), 16),
    ) {
        for p in points {
            let fast = sdf::mandelbulb::<f64>(p.into(), f64::from(power), iterations, 2.0, Some(power));
            let trig = sdf::mandelbulb::<f64>(p.into(), f64::from(power), iterations, 2.0, None);
            if fast.distance.abs().min(trig.distance.abs()) >= 0.05 {
                prop_assert!(
                    relative_eq!(fast.distance, trig.distance, max_relative = 1e-9),
                    "power {} at {}: {} vs {}", power, p, fast.distance, trig.distance
                );
                prop_assert!(relative_eq!(fast.trap, trig.trap, max_relative = 1e-12));
            }
        }
    }
}

const PERMUTATIONS: [[usize; 3]; 6] = [
    [0, 1, 2],
    [0, 2, 1],
    [1, 0, 2],
    [1, 2, 0],
    [2, 0, 1],
    [2, 1, 0],
];

/// Every integer power 2..=16 with every iteration count 1..=64, and
/// non-integer powers, in both forms and precisions: finite at the spicy
/// points.
#[test]
fn mandelbulb_power_and_iteration_grid_stays_finite() {
    let directions = [DVec3::ONE.normalize(), dvec3(0.3, -0.8, 0.52).normalize()];
    let points = spicy_points(Some(2.0), &directions);
    let powers = (2..=16).map(f64::from).chain([2.5, 3.7, 7.5, 12.25, 15.9]);
    for power in powers {
        for iterations in 1..=64 {
            for node in [
                Mandelbulb::new(power).iterations(iterations).into(),
                Mandelbulb::new(param("power", power))
                    .iterations(iterations)
                    .into(),
            ] {
                let eval = cpu::Evaluator::new(&node).unwrap();
                assert_finite(&eval, &node, &points);
            }
        }
    }
}

/// The fixtures along random rays: the membership tests and the estimates
/// agree on which side of the surface each point is, away from the band.
#[test]
fn fixtures_agree_with_membership_on_the_sign() {
    type Membership = Box<dyn Fn(DVec3) -> bool>;
    let cases: [(Node, Membership); 5] = [
        (
            fixtures::mandelbulb_scene(),
            Box::new(|p| mandelbulb_inside(p, 8.0, 12, 2.0)),
        ),
        (
            fixtures::mandelbulb_trig_scene(),
            Box::new(|p| mandelbulb_inside(p, 8.0, 12, 2.0)),
        ),
        (
            fixtures::julia_scene(),
            Box::new(|p| julia_inside(p, JULIA_C, 0.0, 12, 4.0)),
        ),
        (fixtures::menger_scene(), Box::new(|p| menger_inside(p, 4))),
        (
            fixtures::sierpinski_scene(),
            Box::new(|p| sierpinski_inside(p, 6)),
        ),
    ];
    for (node, inside) in cases {
        let eval = cpu::Evaluator::new(&node).unwrap();
        let (mut agree, mut checked) = (0, 0);
        for i in 0..4000 {
            let t = f64::from(i);
            let p = dvec3(
                (t * 0.618_034).fract(),
                (t * 0.754_877).fract(),
                (t * 0.569_840).fract(),
            ) * 3.0
                - DVec3::splat(1.5);
            let d = eval.distance(p);
            if d.abs() < SURFACE_BAND {
                continue;
            }
            checked += 1;
            if (d < 0.0) == inside(p) {
                agree += 1;
            }
        }
        assert_eq!(agree, checked, "{node:?}");
    }
}

/// Points spread evenly through `[-1, 1]^3` (the R3 low-discrepancy
/// sequence).
fn cube_points(n: u32) -> impl Iterator<Item = DVec3> {
    let g = 1.220_744_084_605_759_5_f64; // x^4 = x + 1
    let a = dvec3(1.0 / g, 1.0 / (g * g), 1.0 / (g * g * g));
    (0..n).map(move |i| {
        let v = DVec3::splat(0.5) + a * f64::from(i);
        (v - v.floor()) * 2.0 - DVec3::ONE
    })
}

/// The oracles themselves: the sponge keeps 20 of 27 subcubes per level
/// and the gasket 4 half-size tetrahedra (half the volume), so their
/// volume fractions of `[-1, 1]^3` are `(20/27)^n` and `(1/3) (1/2)^n`.
/// Counted over 200,000 evenly spread points (deterministic), the
/// fractions are within 5.9e-4 (sponge) and 7.6e-4 (gasket) of those,
/// relatively, at levels 0 to 3; the tolerance of 1% is about 13 times
/// the larger. A subcube too many or too few moves the sponge's fraction
/// by 5% at level 1.
#[test]
fn membership_oracles_have_the_right_volumes() {
    const N: u32 = 200_000;
    for level in 0..=3 {
        let count = |inside: &dyn Fn(DVec3) -> bool| {
            f64::from(u32::try_from(cube_points(N).filter(|&p| inside(p)).count()).unwrap())
                / f64::from(N)
        };
        let sponge = count(&|p| menger_inside(p, level));
        let expected = (20.0f64 / 27.0).powi(i32::try_from(level).unwrap());
        assert!(
            relative_eq!(sponge, expected, max_relative = 0.01),
            "level {level}: {sponge}"
        );
        let gasket = count(&|p| sierpinski_inside(p, level));
        let expected = 0.5f64.powi(i32::try_from(level).unwrap()) / 3.0;
        assert!(
            relative_eq!(gasket, expected, max_relative = 0.01),
            "level {level}: {gasket}"
        );
    }
}

/// On the z axis the power-2 triplex map is the real map `t -> t^2 + c`,
/// whose bounded orbits are `c` in `[-2, 1/4]`; on the real axis a Julia
/// set of real `c` follows the same map.
#[test]
fn escape_oracles_reduce_to_the_real_quadratic_map() {
    for (c, inside) in [
        (-2.1, false),
        (-1.9, true),
        (0.0, true),
        (0.2, true),
        (0.3, false),
    ] {
        assert_eq!(
            mandelbulb_inside(dvec3(0.0, 0.0, c), 2.0, 256, 2.0),
            inside,
            "{c}"
        );
    }
    // For c = -1 the real Julia set spans [-phi, phi] (phi the golden ratio).
    let c = [-1.0, 0.0, 0.0, 0.0];
    for (x, inside) in [(0.0, true), (1.6, true), (1.63, false), (-1.63, false)] {
        assert_eq!(
            julia_inside(dvec3(x, 0.0, 0.0), c, 0.0, 256, 4.0),
            inside,
            "{x}"
        );
    }
}

/// Evenly spread unit vectors (an additive recurrence).
fn directions(n: u32) -> impl Iterator<Item = DVec3> {
    (0..n).filter_map(|i| {
        let t = f64::from(i);
        let v = dvec3(
            (t * 0.618_034).fract(),
            (t * 0.754_877).fract(),
            (t * 0.569_840).fract(),
        );
        (v * 2.0 - DVec3::ONE).try_normalize()
    })
}

/// Far from the Mandelbulb the raw escape-time estimate is `0.5 r ln r`
/// (beyond the bailout radius), which grows faster than the distance. It
/// used to be returned as is: along +z (power 8, bailout 2), where
/// (0, 0, 0.66) is in the set so the distance is at most `r - 0.66`, it
/// gave 11.5 at r = 10 (a ray from there missed the bulb) and 6.9e6 at
/// r = 1e6, and it first overestimated at r = 4.0 (power 3) to 4.8
/// (power 16). Now, beyond 1.5 times the radius `2^(1/(n-1))` of the
/// proven bounding ball, the estimator returns the distance to that ball.
#[test]
fn mandelbulb_far_field_never_overestimates() {
    let inside = |p| mandelbulb_inside(p, 8.0, 12, 2.0);
    assert!(inside(dvec3(0.0, 0.0, 0.66)));
    let eval = cpu::Evaluator::new(&fixtures::mandelbulb_scene()).unwrap();
    let shell = |r: f64| -> Vec<DVec3> { directions(400).map(|u| u * r).collect() };
    for r in [1.5, 2.0, 3.0, 4.5, 5.0, 7.0, 10.0, 100.0, 1e6] {
        if let Err(e) = check_never_overestimates(&eval, inside, &shell(r), 8) {
            panic!("at r = {r}: {e}");
        }
    }
    for r in [5.0, 7.0, 10.0, 1e6] {
        let along_z = eval.distance(dvec3(0.0, 0.0, r));
        assert!(along_z <= r - 0.66, "at r = {r}: {along_z}");
    }
    // The bound is the ball's exact distance, so rays from far away lose
    // nothing: one step from r = 1e6 lands on the ball.
    // The radius is the same expression (measured 0; the tolerance is a few
    // ulps of 1.1), and the distance at r = 1e6 one subtraction from it
    // (measured 0; the tolerance is about 8 ulps of 1e6).
    let ball = fractal_sdf::math::mandelbulb_radius(8.0);
    assert!((ball - 2f64.powf(1.0 / 7.0)).abs() < 1e-15);
    let far = eval.distance(dvec3(0.0, 0.0, 1e6));
    assert!((far - (1e6 - ball)).abs() < 1e-9, "{far}");
    // A ray from r = 10 towards the origin reaches the surface where a ray
    // from r = 3 does (it used to jump past the bulb).
    let settings = cpu::MarchSettings::default().footprint_base(1e-6);
    let ray = |z: f64| cpu::Ray::new(dvec3(0.1, 0.05, z), dvec3(0.0, 0.0, -1.0));
    let (from_far, from_near) = (
        cpu::march(&eval, ray(10.0), &settings),
        cpu::march(&eval, ray(3.0), &settings),
    );
    assert!(from_far.hit && from_near.hit);
    // The two marches step through different points and end 2.5e-5 apart
    // (measured; 42 and 32 steps, 25 footprints). The tolerance is 4
    // times that; a ray that stepped past the bulb would be off by about
    // the bulb's size.
    assert!(
        ((from_far.depth - 7.0) - from_near.depth).abs() < 1e-4,
        "{from_far:?} vs {from_near:?}"
    );
}

/// The bounding ball's lemma, checked: from just outside the ball every
/// orbit grows at each step (so it never stays bounded and the estimate is
/// positive there), for powers 2 to 64; the estimate is positive on the
/// ball for bailouts 1 to 1e6 from one iteration up; far away the distance
/// is the ball's.
#[test]
fn mandelbulb_bounding_ball_holds_the_set() {
    for power in [2.0, 3.0, 7.5, 16.0, 64.0] {
        let ball = fractal_sdf::math::mandelbulb_radius(power);
        for u in directions(200) {
            let p = u * (ball * (1.0 + 1e-9));
            // Every |z_k| (k = 1..=8) exceeds |z_0| = |p|.
            assert!(!mandelbulb_inside(p, power, 8, p.length()), "n={power} {p}");
        }
        for bailout in [1.0, 2.0, 1e6] {
            for iterations in [1, 4, 12, 64] {
                let node: Node = Mandelbulb::new(power)
                    .iterations(iterations)
                    .bailout(bailout)
                    .into();
                let eval = cpu::Evaluator::new(&node).unwrap();
                for u in directions(50) {
                    let near = eval.distance(u * (ball * (1.0 + 1e-9)));
                    assert!(near > 0.0, "n={power} B={bailout} N={iterations}: {near}");
                    let far = eval.distance(u * (ball * 3.0));
                    // A few roundings of 3 ball and 2 ball: measured worst
                    // 1.3e-15 relative over these 3,000 points; the
                    // tolerance is about 15 times that.
                    assert!((far - 2.0 * ball).abs() <= 2e-14 * ball, "{far}");
                }
            }
        }
    }
}

/// Regression: for a constant outside the Mandelbrot set the estimate was
/// no bound: at a point 0.15 from a point that stays within the bailout for
/// 12 iterations it was 0.80 (a factor of 5.3). The critical orbit leaves
/// the unit ball at step 2, so the estimate there is now held to the
/// proven bound.
#[test]
fn regression_julia_dust_was_overestimated() {
    let c = [0.254_840_07, -0.486_528_93, -0.464_104_19, 0.095_615_69];
    let w = 0.351_884_94;
    assert!(
        !julia_inside(DVec3::ZERO, c, 0.0, 64, 2.0),
        "c is outside the locus"
    );
    let node: Node = QuaternionJulia::new(c.map(Param::from)).slice_w(w).into();
    let eval = cpu::Evaluator::new(&node).unwrap();
    let p = dvec3(-0.404_369_25, -0.046_999_9, -0.310_841_13);
    let q = dvec3(-0.287_190_44, 0.011_694_66, -0.383_685_69);
    assert!(julia_inside(q, c, w, 12, 4.0));
    let d = eval.distance(p);
    assert!(d <= p.distance(q), "{d} > {}", p.distance(q));
    let inside = |x| julia_inside(x, c, w, 12 + 64, 4.0);
    let shell: Vec<DVec3> = directions(200).map(|u| p + u * 0.01).collect();
    check_never_overestimates(&eval, inside, &shell, 32).unwrap();
}

/// For c = (-1.0954, 0, 0, 0), in the period-2 bulb, interior orbits
/// settle on a 2-cycle with one point outside the unit ball, and near the
/// critical point the derivative vanishes: the escape-time estimate was
/// positive across the interior at odd N (14% of the interior points above
/// 0.06 at N = 12, 63% at N = 19, up to 2358) and 4.6e13 at the origin.
/// The critical orbit leaves the unit ball at once, so now a point is only
/// positive where its orbit proves escape. The fixture's constant, whose
/// critical orbit stays within 0.8 for 14 steps, keeps its estimate (a
/// large depth at the origin).
#[test]
fn julia_interior_is_not_outside_when_the_critical_orbit_leaves_the_unit_ball() {
    let c = [-1.0954, 0.0, 0.0, 0.0];
    for iterations in [12, 13, 19] {
        let node: Node = QuaternionJulia::new(c.map(Param::from))
            .iterations(iterations)
            .into();
        let eval = cpu::Evaluator::new(&node).unwrap();
        let inside = |p| julia_inside(p, c, 0.0, iterations + 64, 4.0);
        let (mut interior, mut largest) = (0, f64::NEG_INFINITY);
        for p in cube_points(20_000).map(|p| p * 1.5) {
            if inside(p) {
                interior += 1;
                largest = largest.max(eval.distance(p));
            }
        }
        assert!(interior > 300, "{interior}");
        assert!(largest <= 0.0, "N = {iterations}: {largest}");
    }
    let fixture = cpu::Evaluator::new(&fixtures::julia_scene()).unwrap();
    assert!(fixture.distance(DVec3::ZERO) < -1e13);
}

/// Far from the set the escape-time estimate grows like `0.5 r ln r`,
/// faster than the distance: for the fixture it was 11.5 at (10, 0, 0),
/// whose distance to the set is at most 9.43, and 6.9e6 at 1e6 (a factor
/// of 6.9), and a ray from 10 units stepped past the set. Beyond 1.5 times
/// the radius of the ball that holds the set it is now 0.9 times the
/// distance to that ball.
#[test]
fn julia_far_field_never_overestimates() {
    let eval = cpu::Evaluator::new(&fixtures::julia_scene()).unwrap();
    let inside = |p| julia_inside(p, JULIA_C, 0.0, 12 + 64, 4.0);
    let shell = |r: f64| -> Vec<DVec3> { directions(400).map(|u| u * r).collect() };
    for r in [1.0, 1.5, 2.0, 2.2, 2.5, 3.0, 4.5, 7.0, 10.0, 100.0, 1e6] {
        // Balls around the points outside; the estimate's sign follows its
        // own 12 iterations, so a point it calls inside is held to that set
        // (the 76-iteration set is smaller).
        let (outside, negative): (Vec<DVec3>, Vec<DVec3>) =
            shell(r).into_iter().partition(|&p| eval.distance(p) > 0.0);
        for p in negative {
            assert!(julia_inside(p, JULIA_C, 0.0, 12, 4.0), "at r = {r}: {p}");
        }
        match check_never_overestimates(&eval, inside, &outside, 8) {
            Ok(tested) => assert!(tested.balls >= 200, "at r = {r}: {tested:?}"),
            Err(e) => panic!("at r = {r}: {e}"),
        }
    }
    // The farthest point inside along +x: (r, 0, 0) is at most r - tip from
    // the set.
    let tip = (0..=1200)
        .map(|i| f64::from(i) * 1e-3)
        .filter(|&x| inside(dvec3(x, 0.0, 0.0)))
        .fold(0.0, f64::max);
    assert!(tip > 0.5, "{tip}");
    let ball = fractal_sdf::math::julia_radius(JULIA_C);
    for r in [5.0, 10.0, 1e6] {
        let d = eval.distance(dvec3(r, 0.0, 0.0));
        assert!(d <= r - tip, "at r = {r}: {d}");
        // The estimator's own f64 operations on an axis point, where |p|
        // is r exactly: measured 0 at all three; the tolerance is a few
        // ulps of r.
        assert!((d - 0.9 * (r - ball)).abs() <= 1e-15 * r, "at r = {r}: {d}");
    }
    // A ray from 10 units reaches the surface where a ray from 2 does (it
    // used to step past the set).
    let settings = cpu::MarchSettings::default().footprint_base(1e-6);
    let ray = |z: f64| cpu::Ray::new(dvec3(0.1, 0.05, z), dvec3(0.0, 0.0, -1.0));
    let (from_far, from_near) = (
        cpu::march(&eval, ray(10.0), &settings),
        cpu::march(&eval, ray(2.0), &settings),
    );
    assert!(from_far.hit && from_near.hit, "{from_far:?} {from_near:?}");
    // Measured 1.2e-8 apart (33 steps each); the tolerance is about 80
    // times that, one footprint. A ray that stepped past the set would be
    // off by about the set's size.
    assert!(
        ((from_far.depth - 8.0) - from_near.depth).abs() < 1e-6,
        "{from_far:?} vs {from_near:?}"
    );
}

/// The critical orbit of a quaternion constant is the complex orbit of
/// `c' = c.x + i |(c.y, c.z, c.w)|` (it stays in the plane of 1 and c's
/// vector part), and the set is symmetric under the rotations that fix
/// that plane, but not under turning the vector part elsewhere: unless `c`
/// is real, the set is not a solid of revolution of the complex Julia set
/// of `c'`, only its slice by that plane is that set. So the set contains
/// its critical point 0 exactly when `c'` is in the Mandelbrot set, which
/// is what the estimator checks.
#[test]
fn julia_constant_reduces_to_a_complex_constant() {
    let mut rng = SplitMix(7);
    for c in [
        JULIA_C,
        [-1.0954, 0.0, 0.0, 0.0],
        [0.2548, -0.4865, -0.4641, 0.0956],
    ] {
        let q = quaternion(c);
        let b = dvec3(c[1], c[2], c[3]).length();
        let (mut z, mut x, mut y) = (DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0), 0.0, 0.0);
        for _ in 0..12 {
            z = z * z + q;
            (x, y) = (x * x - y * y + c[0], 2.0 * x * y + b);
            let complex: f64 = f64::hypot(x, y);
            // The same orbit in quaternion and in complex arithmetic, whose
            // rounding 12 squarings amplify: measured worst 1.9e-14
            // relative over these 36 steps; the tolerance is about 50
            // times that.
            assert!((z.length() - complex).abs() <= 1e-12 * complex.max(1.0));
        }
    }
    // Rotations about the axis of c's vector part commute with c.
    let c = JULIA_C;
    let axis = dvec3(c[1], c[2], c[3]).normalize();
    let member = |z: DQuat| julia_inside(dvec3(z.w, z.x, z.y), c, z.z, 24, 4.0);
    let (mut same, mut moved_differs) = (true, 0);
    for _ in 0..2000 {
        let z = DQuat::from_xyzw(
            rng.range(-1.2, 1.2),
            rng.range(-1.2, 1.2),
            rng.range(-1.2, 1.2),
            rng.range(-1.2, 1.2),
        );
        let about_c = DQuat::from_axis_angle(axis, rng.range(0.0, 6.0));
        same &= member(z) == member(about_c * z * about_c.inverse());
        let elsewhere = DQuat::from_axis_angle(axis.any_orthonormal_vector(), 1.0);
        if member(z) != member(elsewhere * z * elsewhere.inverse()) {
            moved_differs += 1;
        }
    }
    assert!(same);
    assert!(moved_differs > 20, "{moved_differs}");
}

/// Regression: once the running derivative hit its cap, `|z|` kept growing
/// and the quaternion Julia estimate with it: for a connected set with
/// bailout 1e6 and 36 iterations it was 0.0079 at a point 3.1e-5 from a
/// point that stays bounded.
#[test]
fn regression_capped_derivative_inflated_the_julia_estimate() {
    let c = [-0.709_718_896_099_059_4, 0.0, 0.0, 0.0];
    let w = 0.559_420_406_547_514_2;
    let node: Node = QuaternionJulia::new(c.map(Param::from))
        .iterations(36)
        .bailout(1e6)
        .slice_w(w)
        .into();
    let eval = cpu::Evaluator::new(&node).unwrap();
    let p = dvec3(
        -0.099_946_343_172_445,
        -0.099_024_431_594_264_16,
        0.532_062_851_996_509_5,
    );
    let q = dvec3(
        -0.099_977_335_015_233_94,
        -0.099_024_046_480_323_74,
        0.532_060_782_760_815_6,
    );
    assert!(julia_inside(q, c, w, 36 + 64, 1e6));
    let d = eval.distance(p);
    assert!(d <= p.distance(q), "{d} > {}", p.distance(q));
}

/// Regression: r^power overflowed for valid settings (power 55 with
/// bailout 1e6 in f64, power 18 with bailout 365242 in f32), giving an
/// infinite distance.
#[test]
fn regression_mandelbulb_power_overflowed_to_infinity() {
    let cases = [
        (55.0, 1e6, dvec3(322.5, -932.6, -600.1)),
        (18.0, 365_242.0, dvec3(0.43, 1.21, -1.44)),
        (64.0, 1e6, dvec3(0.5, 0.2, -0.1)),
        (64.0, 2.0, dvec3(1.0, 0.3, 0.7)),
    ];
    for (power, bailout, p) in cases {
        let node: Node = Mandelbulb::new(power)
            .iterations(256)
            .bailout(bailout)
            .into();
        let eval = cpu::Evaluator::new(&node).unwrap();
        assert_finite(&eval, &node, &[p]);
    }
}

/// Regression: once the running derivative hit its cap while r^power kept
/// growing, the estimate exploded (3.2e64 at a point 1.93 from the
/// origin, which is in the set).
#[test]
fn regression_capped_derivative_inflated_the_mandelbulb_estimate() {
    let node: Node = Mandelbulb::new(18.0)
        .iterations(256)
        .bailout(365_242.0)
        .into();
    let eval = cpu::Evaluator::new(&node).unwrap();
    let p = dvec3(0.43, 1.21, -1.44);
    assert!(mandelbulb_inside(DVec3::ZERO, 18.0, 256, 365_242.0));
    assert!(eval.distance(p) <= p.length(), "{}", eval.distance(p));
}
