//! The largest ratio of a distance estimate to the distance to the points
//! a membership test finds inside: how the estimates that carry a
//! measured safety factor (the Mandelbox, the hybrids) and those with a
//! proof (the KIFS) are measured.

use fractal_sdf::prelude::*;
use fractal_sdf::testing;

use super::julia::SplitMix;

/// What [`worst_ratio`] found.
pub(super) struct Worst {
    /// The largest ratio of estimate to distance.
    pub(super) ratio: f64,
    /// Points with a positive estimate.
    pub(super) tested: usize,
    /// Of those, the ones with a point inside found (a ratio measured).
    pub(super) witnessed: usize,
    /// The median ratio of those: how far below the distance the
    /// estimate typically is (the marching speed it costs).
    pub(super) median: f64,
}

/// The largest ratio of `estimate` to the distance to the nearest point
/// found inside, over `count` points within `shell` of the surface of the
/// set `inside` in the ball of radius `reach`. For each point with a
/// positive estimate `e`, `candidates` random points are tested, in turn
/// within each of `spread` times `e` (`1.2 e`, where an overestimate would
/// be, then farther for the ratios well below 1); the
/// nearest one inside is moved by bisection to where the segment from the
/// point first enters the set. A point found inside is at least as far as
/// the nearest one, so this is the largest ratio found, a lower bound of
/// the true largest: thin parts the samples miss can hide more.
pub(super) fn worst_ratio(
    estimate: impl Fn(DVec3) -> f64,
    inside: impl Fn(DVec3) -> bool,
    (reach, shell): (f64, f64),
    (count, candidates): (usize, usize),
    spread: &[f64],
    seed: u64,
) -> Worst {
    let mut rng = SplitMix(seed);
    let mut worst = Worst {
        ratio: 0.0,
        tested: 0,
        witnessed: 0,
        median: 0.0,
    };
    let mut ratios = Vec::new();
    for p in testing::near_surface_points(&inside, reach, shell, count, seed) {
        let e = estimate(p);
        if e <= 0.0 {
            continue;
        }
        worst.tested += 1;
        let witness = (0..candidates)
            .map(|i| p + rng.in_ball(spread[i % spread.len()] * e))
            .filter(|&q| inside(q))
            .min_by(|a, b| a.distance(p).total_cmp(&b.distance(p)));
        if let Some(q) = witness {
            let (mut out, mut inn) = (0.0, 1.0);
            for _ in 0..48 {
                let mid = 0.5 * (out + inn);
                if inside(p.lerp(q, mid)) {
                    inn = mid;
                } else {
                    out = mid;
                }
            }
            ratios.push(e / (inn * q.distance(p)));
        }
    }
    ratios.sort_by(f64::total_cmp);
    worst.witnessed = ratios.len();
    worst.ratio = ratios.last().copied().unwrap_or(0.0);
    worst.median = ratios.get(ratios.len() / 2).copied().unwrap_or(0.0);
    worst
}
