//! Knighty's pseudo-Kleinian fractal: the estimate's sign held to the
//! membership test ([`testing::pseudo_kleinian_inside`], written from the
//! definition with no code of the estimator), and its size to the
//! distance to the points that test finds inside.
//!
//! Knighty's estimate is not a proven bound, so it carries a measured
//! safety factor ([`sdf::PSEUDO_KLEINIAN_SAFETY`]):
//! `pseudo_kleinian_worst_ratio_is_measured` measures the largest ratio of
//! the raw estimate to the distance and checks that the factor covers 1.25
//! times it; the property tests check the estimate as drawn for random
//! settings.

use fractal_sdf::cpu;
use fractal_sdf::cpu::sdf;
use fractal_sdf::prelude::*;
use fractal_sdf::scene::{Kind, PseudoKleinian};
use fractal_sdf::testing::{self, check_never_overestimates, pseudo_kleinian_inside};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::TestRunner;

use super::julia::SplitMix;
use super::ratio::worst_ratio;

/// The settings the guide's table measures: the published preset at
/// three iteration counts, Knighty's slider defaults, and others.
fn cases() -> Vec<(&'static str, PseudoKleinian)> {
    let preset = PseudoKleinian::new;
    vec![
        ("the preset, 4 iterations", preset().iterations(4)),
        ("the preset, 8 iterations", preset()),
        ("the preset, 14 iterations", preset().iterations(14)),
        ("fold size (1, 1, 1)", preset().fold_size([1.0, 1.0, 1.0])),
        (
            "fold size (0.7, 0.7, 0.7), inversion 0.5",
            preset().fold_size([0.7, 0.7, 0.7]).inversion(0.5),
        ),
        (
            "offset (0.1, −0.05, 0.2)",
            preset().offset([0.1, -0.05, 0.2]),
        ),
        ("thickness 0.1", preset().thickness(0.1)),
        (
            "fold size (0.8, 1.1, 0.6), inversion 1.6",
            preset().fold_size([0.8, 1.1, 0.6]).inversion(1.6),
        ),
    ]
}

/// How many random settings the measurement draws.
const RANDOM: usize = 200;

/// The raw estimate at `p`: the drawn one over the factor.
fn raw_estimate(eval: &cpu::Evaluator, p: DVec3) -> f64 {
    eval.distance(p) / sdf::PSEUDO_KLEINIAN_SAFETY
}

/// The measured table in the guide's fractals chapter: the largest ratio
/// of the raw estimate to the distance to the nearest point the membership
/// test finds inside, near the surface (within 0.02 of it, in the ball of
/// radius 2) and farther out (within 0.3), and the median near it. The
/// safety factor must cover 1.25 times the largest.
#[test]
fn pseudo_kleinian_worst_ratio_is_measured() {
    let (mut overall, mut total) = (0.0f64, 0);
    println!(
        "| pseudo-Kleinian | points | with a point inside found | largest ratio | out to 0.3 | median |"
    );
    println!("|---|---:|---:|---:|---:|---:|");
    for (i, (name, k)) in cases().iter().enumerate() {
        let eval = cpu::Evaluator::new(&k.clone().into()).unwrap();
        let measure = |shell: f64, seed: u64| {
            worst_ratio(
                |p| raw_estimate(&eval, p),
                |p| pseudo_kleinian_inside(p, k),
                (2.0, shell),
                (400, 3000),
                &[1.2, 4.0, 16.0],
                seed,
            )
        };
        let near = measure(0.02, 1 + i as u64);
        let far = measure(0.3, 1001 + i as u64);
        println!(
            "| {name} | {} | {} | {:.3} | {:.3} | {:.3} |",
            near.tested, near.witnessed, near.ratio, far.ratio, near.median
        );
        assert!(
            near.witnessed >= 30,
            "{name}: only {} witnessed",
            near.witnessed
        );
        total += near.witnessed + far.witnessed;
        overall = overall.max(near.ratio).max(far.ratio);
    }
    assert!(
        total >= 2000,
        "only {total} points had a point inside within reach"
    );
    // And random settings, drawn the same way every run.
    let mut runner = TestRunner::deterministic();
    let strategy = testing::pseudo_kleinian_node();
    let mut ratios = Vec::new();
    for seed in 0..RANDOM as u64 {
        let k = kleinian_of(&strategy.new_tree(&mut runner).unwrap().current());
        let eval = cpu::Evaluator::new(&k.clone().into()).unwrap();
        let ratio = [0.02, 0.3]
            .into_iter()
            .map(|shell| {
                worst_ratio(
                    |p| raw_estimate(&eval, p),
                    |p| pseudo_kleinian_inside(p, &k),
                    (2.0, shell),
                    (48, 2000),
                    &[1.2, 4.0, 16.0],
                    seed,
                )
            })
            .filter(|w| w.witnessed >= 8)
            .map(|w| w.ratio)
            .fold(None, |m: Option<f64>, r| Some(m.map_or(r, |m| m.max(r))));
        ratios.extend(ratio);
    }
    ratios.sort_by(f64::total_cmp);
    let largest = ratios.last().copied().unwrap_or(0.0);
    let median = ratios.get(ratios.len() / 2).copied().unwrap_or(0.0);
    println!("| random settings | measured | largest ratio | median of each one's largest |");
    println!("|---|---:|---:|---:|");
    println!(
        "| {RANDOM} drawn | {} | {largest:.3} | {median:.3} |",
        ratios.len()
    );
    assert!(
        ratios.len() >= RANDOM / 2,
        "only {} random settings measured",
        ratios.len()
    );
    overall = overall.max(largest);
    println!(
        "largest ratio {overall:.3}; safety factor {}",
        sdf::PSEUDO_KLEINIAN_SAFETY
    );
    assert!(
        1.25 * overall * sdf::PSEUDO_KLEINIAN_SAFETY <= 1.0,
        "the safety factor {} does not cover 1.25 times the measured ratio {overall}",
        sdf::PSEUDO_KLEINIAN_SAFETY
    );
}

/// The pseudo-Kleinian a strategy's node holds.
fn kleinian_of(node: &Node) -> PseudoKleinian {
    match node.kind() {
        Kind::PseudoKleinian(k) => k.clone(),
        other => panic!("not a pseudo-Kleinian: {}", other.name()),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The estimate is negative exactly inside the set the membership
    /// test finds, for random settings and points, except within rounding
    /// of the surface.
    #[test]
    fn the_sign_is_the_membership_tests(node in testing::pseudo_kleinian_node(), seed in any::<u64>()) {
        let k = kleinian_of(&node);
        let eval = cpu::Evaluator::new(&node)?;
        let mut rng = SplitMix(seed);
        for _ in 0..64 {
            let p = rng.in_ball(3.0);
            let d = eval.distance(p);
            let inside = pseudo_kleinian_inside(p, &k);
            prop_assert!(
                inside == (d < 0.0) || d.abs() < 1e-9,
                "{p}: estimate {d}, inside {inside}, {k:?}"
            );
        }
    }

    /// The estimate as drawn never overestimates the distance to the
    /// points the membership test finds inside, near the surface, for
    /// random settings.
    #[test]
    fn pseudo_kleinian_never_overestimates(node in testing::pseudo_kleinian_node(), seed in any::<u64>()) {
        let k = kleinian_of(&node);
        let eval = cpu::Evaluator::new(&node)?;
        let inside = |p| pseudo_kleinian_inside(p, &k);
        let points: Vec<_> = testing::near_surface_points(inside, 2.0, 0.05, 32, seed)
            .into_iter()
            .filter(|&p| eval.distance(p) > 1e-9)
            .collect();
        if points.len() >= 4 {
            check_never_overestimates(&eval, inside, &points, 32)?;
        }
    }
}
