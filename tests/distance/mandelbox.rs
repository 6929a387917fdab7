//! The Mandelbox: its extent and escape threshold (the two claims its
//! distance estimate rests on) checked by following orbits with no use of
//! the library, and its estimate held to the distance to the points the
//! membership test ([`testing::mandelbox_inside`]) finds inside.
//!
//! The estimate is not a proven bound, so it carries a measured safety
//! factor ([`sdf::MANDELBOX_SAFETY`]). `mandelbox_worst_ratio_is_measured`
//! measures the largest ratio of the raw estimate to the distance over a
//! sweep of scales, iteration counts, radii and Julia constants and checks
//! that the factor covers it; the property test checks the estimate as
//! drawn (factor applied) for random settings.

use fractal_sdf::cpu;
use fractal_sdf::cpu::sdf;
use fractal_sdf::math::mandelbox_extent;
use fractal_sdf::prelude::*;
use fractal_sdf::scene::Mandelbox;
use fractal_sdf::testing::{self, check_never_overestimates, mandelbox_inside};
use proptest::prelude::*;

use super::julia::SplitMix;
use super::ratio::worst_ratio;

/// The half side of the cube the library says holds the set.
fn half_side(m: &Mandelbox) -> f64 {
    let julia = m
        .julia
        .as_ref()
        .map(|c| c.clone().map(|x| x.default_value()));
    mandelbox_extent(m.scale.default_value(), m.fold_limit.default_value(), julia).0
}

/// One step of the map, written out: box fold, sphere fold, scale, add.
fn step(z: DVec3, c: DVec3, s: f64, min: f64, fixed: f64, l: f64) -> DVec3 {
    let z = z.clamp(DVec3::splat(-l), DVec3::splat(l)) * 2.0 - z;
    let r2 = z.length_squared();
    let k = if r2 < min * min {
        (fixed / min).powi(2)
    } else if r2 < fixed * fixed {
        fixed * fixed / r2
    } else {
        1.0
    };
    s * k * z + c
}

/// Whether the orbit of `p` passes `1e9` within 4,000 steps.
fn escapes(p: DVec3, julia: Option<DVec3>, s: f64, min: f64, fixed: f64, l: f64) -> bool {
    let c = julia.unwrap_or(p);
    let mut z = p;
    (0..4000).any(|_| {
        z = step(z, c, s, min, fixed, l);
        z.abs().max_element() > 1e9
    })
}

/// Settings drawn for the extent tests: either sign of scale with
/// magnitude in `[1.1, 4]`, any radii and fold limit in range, and a Julia
/// constant half the time.
fn settings() -> impl Strategy<Value = (f64, f64, f64, f64, Option<DVec3>)> {
    let scale = (1.1..=4.0f64, any::<bool>()).prop_map(|(s, neg)| if neg { -s } else { s });
    let julia = prop::option::of(testing::point(1.5));
    (scale, 0.1..=1.0f64, 0.5..=1.5f64, 0.5..=1.5f64, julia)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A point with a coordinate beyond the stated half side escapes: the
    /// cube holds the whole set, for every setting.
    #[test]
    fn the_cube_holds_the_set(
        (s, min, fixed, l, julia) in settings(),
        which in 0usize..3,
        beyond in 1.0001..=1.5f64,
        rest in testing::point(1.0),
        sign in any::<bool>(),
    ) {
        let mut m = Mandelbox::new(s).min_radius(min).fixed_radius(fixed).fold_limit(l);
        if let Some(c) = julia {
            m = m.julia([c.x, c.y, c.z]);
        }
        let h = half_side(&m);
        let mut p = rest.clamp(DVec3::splat(-1.0), DVec3::ONE) * h;
        p[which] = if sign { beyond * h } else { -beyond * h };
        prop_assert!(escapes(p, julia, s, min.min(fixed), fixed, l), "{p} stays, half side {h}");
    }

    /// An orbit whose largest coordinate passes the escape threshold keeps
    /// growing at every later step: the drawn set (within the threshold
    /// after n steps) only shrinks as n grows. Each case follows the orbit
    /// of a point of the cube from its start, and from a point past the
    /// threshold (any coordinate of the orbit's point, any constant of
    /// the cube).
    #[test]
    fn past_the_threshold_orbits_only_grow(
        (s, min, fixed, l, julia) in settings(),
        start in testing::point(1.0),
        past_start in testing::point(1.0),
        which in 0usize..3,
        beyond in 1.0001..=3.0f64,
    ) {
        let (h, threshold) = mandelbox_extent(s, l, julia.map(|c| c.to_array()));
        let p = start.clamp(DVec3::splat(-1.0), DVec3::ONE) * h;
        let c = julia.unwrap_or(p);
        let mut past = past_start.clamp(DVec3::splat(-1.0), DVec3::ONE) * threshold;
        past[which] = beyond * threshold * past_start[which].signum();
        let mut crossed = 0;
        for mut z in [p, past] {
            for _ in 0..200 {
                let next = step(z, c, s, min.min(fixed), fixed, l);
                let (a, b) = (z.abs().max_element(), next.abs().max_element());
                if a > threshold {
                    crossed += 1;
                    prop_assert!(b > a, "{a} -> {b} past the threshold {threshold}");
                }
                if b > 1e12 {
                    break;
                }
                z = next;
            }
        }
        prop_assert!(crossed > 0, "no orbit passed the threshold");
    }

    /// The estimate as drawn never overestimates the distance to the
    /// points the membership test finds inside, near the surface and
    /// through the cube, for random settings.
    #[test]
    fn mandelbox_never_overestimates(
        (s, min, fixed, l, julia) in settings(),
        iterations in 2u32..=20,
        seed in any::<u64>(),
    ) {
        let mut m = Mandelbox::new(s)
            .min_radius(min)
            .fixed_radius(fixed)
            .fold_limit(l)
            .iterations(iterations);
        if let Some(c) = julia {
            m = m.julia([c.x, c.y, c.z]);
        }
        let h = half_side(&m);
        let node: Node = m.clone().into();
        let eval = cpu::Evaluator::new(&node)?;
        let inside = |p| mandelbox_inside(p, &m);
        let mut points = testing::near_surface_points(inside, 1.8 * h, 0.1 * h, 48, seed);
        let mut rng = SplitMix(seed);
        points.extend((0..16).map(|_| rng.in_ball(1.8 * h)));
        let points: Vec<_> = points.into_iter().filter(|&p| eval.distance(p) > 0.0).collect();
        if !points.is_empty() {
            check_never_overestimates(&eval, inside, &points, 32)?;
        }
    }
}

/// The raw estimate of `m` at `p`: the drawn one over
/// [`sdf::MANDELBOX_SAFETY`], where it is not the distance to the cube
/// (exact, and then the raw estimate is below it).
fn raw_estimate(eval: &cpu::Evaluator, h: f64, p: DVec3) -> f64 {
    let drawn = eval.distance(p);
    let q = p.abs() - DVec3::splat(h);
    let cube = q.max(DVec3::ZERO).length() + q.max_element().min(0.0);
    if drawn > cube {
        drawn / sdf::MANDELBOX_SAFETY
    } else {
        drawn
    }
}

/// The measured table in the guide's fractals chapter: the largest ratio
/// of the raw estimate to the distance, for the classic and extreme scales
/// at 8 and 16 iterations, other radii and fold limits, and Julia mode. The
/// safety factor must cover every one of them.
#[test]
fn mandelbox_worst_ratio_is_measured() {
    let mut cases = Vec::new();
    for s in [-3.0, -2.0, -1.5, -1.2, 1.5, 2.0, 2.5, 3.0] {
        for n in [8, 16] {
            cases.push((
                format!("scale {s}, {n} iterations"),
                Mandelbox::new(s).iterations(n),
            ));
        }
    }
    cases.push((
        "scale 2, radii 0.25 and 1.2, fold limit 0.8".into(),
        Mandelbox::new(2.0)
            .min_radius(0.25)
            .fixed_radius(1.2)
            .fold_limit(0.8),
    ));
    cases.push((
        "scale -1.5, radii 0.7 and 0.9, fold limit 1.3".into(),
        Mandelbox::new(-1.5)
            .min_radius(0.7)
            .fixed_radius(0.9)
            .fold_limit(1.3),
    ));
    cases.push((
        "scale -1.5, Julia (0.3, -0.2, 0.5)".into(),
        Mandelbox::new(-1.5).julia([0.3, -0.2, 0.5]),
    ));
    cases.push((
        "scale 2, Julia (1, 0.5, 0.2)".into(),
        Mandelbox::new(2.0).julia([1.0, 0.5, 0.2]),
    ));
    let (mut overall, mut total) = (0.0f64, 0);
    println!("| Mandelbox | points | with a point inside found | largest ratio |");
    println!("|---|---:|---:|---:|");
    for (i, (name, m)) in cases.iter().enumerate() {
        let h = half_side(m);
        let eval = cpu::Evaluator::new(&m.clone().into()).unwrap();
        let w = worst_ratio(
            |p| raw_estimate(&eval, h, p),
            |p| mandelbox_inside(p, m),
            (1.8 * h, 0.05 * h),
            (400, 4000),
            &[1.2, 4.0],
            1 + i as u64,
        );
        let ratio = if w.witnessed > 0 {
            format!("{:.3}", w.ratio)
        } else {
            "—".into()
        };
        println!("| {name} | {} | {} | {ratio} |", w.tested, w.witnessed);
        total += w.witnessed;
        overall = overall.max(w.ratio);
    }
    assert!(
        total >= 2500,
        "only {total} points had a point inside within reach"
    );
    println!(
        "largest ratio {overall:.3}; safety factor {}",
        sdf::MANDELBOX_SAFETY
    );
    assert!(
        overall * sdf::MANDELBOX_SAFETY <= 1.0,
        "the safety factor {} does not cover the measured ratio {overall}",
        sdf::MANDELBOX_SAFETY
    );
}
