//! Where a formula's surface can be: a box found by interval arithmetic.
//!
//! A distance formula is at most 0 only on and inside its surface. Run on
//! intervals over a box, it gives a range that holds every value in the
//! box; where that range is above 0, the box holds none of the shape. So
//! the shape lies within `[-r, r]^3` once the six half-spaces beyond it
//! (each a box with infinite sides) are proven empty, and the boxes of a
//! subdivision of that cube that are not proven empty hold it all.

use glam::DVec3;

use super::interval::Interval;
use super::program::Program;

/// The half-sizes tried for the outer cube: powers of 2 from 2^-20 to 2^40.
const SIZES: std::ops::RangeInclusive<i32> = -20..=40;

/// How many times a box is halved along each axis when tightening.
const LEVELS: u32 = 4;

/// The most tightening passes.
const PASSES: usize = 3;

/// A box `[min, max]` holding every point where `program` (inputs `p.x,
/// p.y, p.z`, then `params`) can be at most 0, or `None` if intervals
/// cannot prove any box holds them (an unbounded shape, or one whose
/// formula the arithmetic cannot bound, such as a division by a range
/// holding 0).
#[must_use]
pub fn surface_box(program: &Program, params: &[f64]) -> Option<[DVec3; 2]> {
    let params: Vec<Interval> = params.iter().map(|v| Interval::point(*v)).collect();
    let empty = |lo: DVec3, hi: DVec3| -> bool {
        let mut inputs = vec![
            Interval::new(lo.x, hi.x),
            Interval::new(lo.y, hi.y),
            Interval::new(lo.z, hi.z),
        ];
        inputs.extend_from_slice(&params);
        program.run(&inputs).first().is_some_and(|d| d.lo > 0.0)
    };
    let inf = f64::INFINITY;
    let size = SIZES.map(|k| 2f64.powi(k)).find(|&r| {
        (0..3).all(|axis| {
            let (mut lo, mut hi) = (DVec3::splat(-inf), DVec3::splat(inf));
            lo[axis] = r;
            let beyond = empty(lo, hi);
            lo[axis] = -inf;
            hi[axis] = -r;
            beyond && empty(lo, hi)
        })
    })?;
    // Tighten: the boxes of a subdivision that may hold the shape, then
    // of a subdivision of the box they span, while that shrinks it.
    let mut found = [DVec3::splat(-size), DVec3::splat(size)];
    for _ in 0..PASSES {
        let tighter = tighten(&empty, found)?;
        if tighter == found {
            break;
        }
        found = tighter;
    }
    Some(found)
}

/// The box spanned by the cells of `LEVELS` halvings of `[lo, hi]` that
/// `empty` does not rule out, or `None` if it rules out them all.
fn tighten(empty: &impl Fn(DVec3, DVec3) -> bool, [lo, hi]: [DVec3; 2]) -> Option<[DVec3; 2]> {
    let mut found: Option<[DVec3; 2]> = None;
    let mut stack = vec![(lo, hi, 0)];
    while let Some((lo, hi, level)) = stack.pop() {
        if empty(lo, hi) {
            continue;
        }
        if level == LEVELS {
            found = Some(match found {
                None => [lo, hi],
                Some([a, b]) => [a.min(lo), b.max(hi)],
            });
            continue;
        }
        let mid = 0.5 * (lo + hi);
        for corner in 0..8 {
            let pick = |bit: usize, i: usize| {
                if corner >> bit & 1 == 0 {
                    (lo[i], mid[i])
                } else {
                    (mid[i], hi[i])
                }
            };
            let (x, y, z) = (pick(0, 0), pick(1, 1), pick(2, 2));
            stack.push((
                DVec3::new(x.0, y.0, z.0),
                DVec3::new(x.1, y.1, z.1),
                level + 1,
            ));
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::{Num, trace};

    #[test]
    fn a_ball_is_boxed_tightly() {
        let ball = trace(4, |a| {
            let q = [a[0] - a[3], a[1], a[2]];
            vec![Num::length3(q[0], q[1], q[2]) - Num::of(0.5)]
        });
        let [lo, hi] = surface_box(&ball, &[1.0]).unwrap();
        assert!(lo.x <= 0.5 && hi.x >= 1.5 && lo.y <= -0.5 && hi.y >= 0.5);
        // Three passes of 2^4 cells per axis: within 1/16 of a unit.
        assert!(lo.x > 0.4 && hi.x < 1.6 && hi.y < 0.6, "{lo} {hi}");
    }

    #[test]
    fn a_half_space_has_no_box() {
        let plane = trace(3, |a| vec![a[1]]);
        assert_eq!(surface_box(&plane, &[]), None);
    }
}
