//! The kaleidoscopic IFS: its ball (the claim its estimate rests on)
//! checked with the membership test alone, and its estimate held to the
//! distance to the points the membership test
//! ([`testing::kifs_inside`]) finds inside.
//!
//! The estimate is a proven bound (see [`kifs_radius`]), so it carries no
//! safety factor: `kifs_worst_ratio_is_measured` measures the largest ratio
//! of estimate to distance for every fold, with and without turns, and it
//! must not pass 1.

use fractal_sdf::cpu;
use fractal_sdf::math::kifs_radius;
use fractal_sdf::prelude::*;
use fractal_sdf::scene::{Kifs, KifsFold};
use fractal_sdf::testing::{self, check_never_overestimates, kifs_inside};
use proptest::prelude::*;

use super::julia::SplitMix;
use super::ratio::worst_ratio;

/// The radius of the ball the library says holds the set.
fn radius(k: &Kifs) -> f64 {
    let offset = k.offset.clone().map(|x| x.default_value());
    kifs_radius(offset, k.fold == KifsFold::Menger)
}

/// Settings drawn for these tests: any fold, a scale in `[1.1, 4]`, an
/// offset in `[-1.5, 1.5]^3` (its length at least 0.2), and each turn one
/// time in three.
fn settings() -> impl Strategy<Value = Kifs> {
    let fold = prop_oneof![
        Just(KifsFold::Tetrahedral),
        Just(KifsFold::Octahedral),
        Just(KifsFold::Icosahedral),
        Just(KifsFold::Menger),
    ];
    let angle = || -std::f64::consts::PI..=std::f64::consts::PI;
    let turn = move || prop::option::weighted(0.3, [angle(), angle(), angle()]);
    let offset = testing::point(1.5).prop_filter("an offset away from 0", |o| o.length() > 0.2);
    (fold, 1.1..=4.0f64, offset, turn(), turn()).prop_map(|(fold, s, o, before, after)| {
        let mut k = Kifs::new(fold).scale(s).offset(o.to_array());
        if let Some(a) = before {
            k = k.rotate_before(a);
        }
        if let Some(a) = after {
            k = k.rotate_after(a);
        }
        k
    })
}

/// The drawn set as a function of the point.
fn member(k: &Kifs) -> impl Fn(DVec3) -> bool + '_ {
    move |p| kifs_inside(p, k)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A point outside the stated ball is outside the drawn set at every
    /// iteration count, for the membership test and the estimate, and a
    /// point inside after `n + 1` steps is inside after `n`: the sets only
    /// shrink.
    #[test]
    fn the_ball_holds_every_drawn_set(
        k in settings(),
        direction in testing::unit_vector(),
        beyond in 1.0001..=2.0f64,
        start in testing::point(1.0),
    ) {
        let r = radius(&k);
        let outside = direction * beyond * r;
        for n in 0..=12 {
            let k = k.clone().iterations(n);
            prop_assert!(!kifs_inside(outside, &k), "{outside} at {n}");
            let d = cpu::Evaluator::new(&k.into())?.distance(outside);
            prop_assert!(d > 0.0, "{outside} at {n}: estimate {d}");
        }
        let p = start * r;
        for n in 0..12 {
            if kifs_inside(p, &k.clone().iterations(n + 1)) {
                prop_assert!(kifs_inside(p, &k.clone().iterations(n)), "{p} at {n}");
            }
        }
    }

    /// The estimate never overestimates the distance to the points the
    /// membership test finds inside, near the surface and through the
    /// ball, and its sign is the membership test's.
    #[test]
    fn kifs_never_overestimates(k in settings(), iterations in 0u32..=10, seed in any::<u64>()) {
        let k = k.iterations(iterations);
        let r = radius(&k);
        let eval = cpu::Evaluator::new(&k.clone().into())?;
        let inside = member(&k);
        let mut points = testing::near_surface_points(&inside, 1.5 * r, 0.1 * r, 48, seed);
        let mut rng = SplitMix(seed);
        points.extend((0..16).map(|_| rng.in_ball(1.5 * r)));
        for &p in &points {
            let d = eval.distance(p);
            if d.abs() > 1e-9 * r {
                prop_assert_eq!(d < 0.0, inside(p), "{} at {}", d, p);
            }
        }
        let outside: Vec<_> = points.into_iter().filter(|&p| eval.distance(p) > 0.0).collect();
        if !outside.is_empty() {
            check_never_overestimates(&eval, &inside, &outside, 32)?;
        }
    }
}

/// The measured table in the guide's fractals chapter: the largest ratio
/// of the estimate to the distance for each fold's classic settings at 4
/// and 8 iterations, and turned. The bound is proven, so none may pass 1
/// (beyond rounding).
#[test]
fn kifs_worst_ratio_is_measured() {
    let folds = [
        ("tetrahedral", KifsFold::Tetrahedral),
        ("octahedral", KifsFold::Octahedral),
        ("icosahedral", KifsFold::Icosahedral),
        ("Menger", KifsFold::Menger),
    ];
    let mut cases = Vec::new();
    for (name, fold) in folds {
        for n in [4, 8] {
            cases.push((
                format!("{name}, classic, {n} iterations"),
                Kifs::new(fold).iterations(n),
            ));
        }
        cases.push((
            format!("{name}, turned (0.1, 0.05, 0) and (0, 0, 0.1), 5 iterations"),
            Kifs::new(fold)
                .rotate_before([0.1, 0.05, 0.0])
                .rotate_after([0.0, 0.0, 0.1])
                .iterations(5),
        ));
    }
    let (mut overall, mut total) = (0.0f64, 0);
    println!("| KIFS | points | with a point inside found | largest ratio |");
    println!("|---|---:|---:|---:|");
    for (i, (name, k)) in cases.iter().enumerate() {
        let r = radius(k);
        let eval = cpu::Evaluator::new(&k.clone().into()).unwrap();
        let w = worst_ratio(
            |p| eval.distance(p),
            member(k),
            (1.5 * r, 0.05 * r),
            (200, 2000),
            &[1.2, 4.0],
            1 + i as u64,
        );
        println!(
            "| {name} | {} | {} | {:.4} |",
            w.tested, w.witnessed, w.ratio
        );
        total += w.witnessed;
        overall = overall.max(w.ratio);
    }
    println!("largest ratio {overall:.6}");
    assert!(
        total >= 800,
        "only {total} points had a point inside within reach"
    );
    assert!(
        overall <= 1.0 + 1e-9,
        "the estimate overestimates: ratio {overall}"
    );
}

/// The guide's table of how turns shrink the classic sets: the share of
/// 20,000 random points of the ball inside after 5 iterations, turned by
/// `(t, t/2, 0)` before the fold and `(0, 0, t)` after it. Where the
/// membership test finds nothing, the estimate must be positive at every
/// point tried (an empty set is drawn as nothing); the classic octahedral
/// and icosahedral sets must be gone by `t = 0.5`.
#[test]
fn turns_can_empty_the_set() {
    let turns = [0.0, 0.05, 0.1, 0.2, 0.3, 0.5];
    let folds = [
        ("tetrahedral", KifsFold::Tetrahedral),
        ("octahedral", KifsFold::Octahedral),
        ("icosahedral", KifsFold::Icosahedral),
        ("Menger", KifsFold::Menger),
    ];
    let mut rng = SplitMix(7);
    println!("| fold | t = 0 | 0.05 | 0.1 | 0.2 | 0.3 | 0.5 |");
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for (name, fold) in folds {
        let mut row = format!("| {name} |");
        for t in turns {
            let k = Kifs::new(fold)
                .rotate_before([t, 0.5 * t, 0.0])
                .rotate_after([0.0, 0.0, t])
                .iterations(5);
            let r = radius(&k);
            let eval = cpu::Evaluator::new(&k.clone().into()).unwrap();
            let points: Vec<_> = (0..20_000).map(|_| rng.in_ball(r)).collect();
            let hits = points.iter().filter(|&&p| kifs_inside(p, &k)).count();
            if hits == 0 {
                assert!(
                    points.iter().all(|&p| eval.distance(p) > 0.0),
                    "{name} at {t}: the estimate draws an empty set"
                );
            }
            if t == 0.5 && matches!(fold, KifsFold::Octahedral | KifsFold::Icosahedral) {
                assert_eq!(hits, 0, "{name} at {t}");
            }
            #[allow(clippy::cast_precision_loss)]
            let share = 100.0 * hits as f64 / 20_000.0;
            row.push_str(&format!(" {share:.2}% |"));
        }
        println!("{row}");
    }
}
