//! The hybrid fractal's estimate ([`Hybrid`]): its operations run in
//! order on the orbit's point and the running derivative.

use super::{
    Estimate, TrapShape, TrapSlot, box_fold, kifs_fold, sphere_fold_factor, triplex_direction, turn,
};
use crate::expr::Step;
use crate::ir::Scalar;
use crate::math::{Num, V3, integer_power, v3};
use crate::scene::{Hybrid, HybridOp};

/// The estimate of a hybrid with no power step ([`HybridOp::is_power`]) is
/// multiplied by this safety factor: a running-derivative estimate of an
/// arbitrary sequence of steps is not a proven bound. The largest ratio of
/// estimate to distance measured against brute-force membership, over the
/// classic hybrids and 400 random ones, near their surfaces and out to 1.5
/// bailouts from them, is 1.20 (`tests/distance/hybrid.rs`, and the
/// table in the [fractals chapter](crate::guide::fractals#hybrids) of the
/// guide); the factor covers 1.25 times that.
pub const HYBRID_SAFETY: f64 = 0.65;

/// The factor of the estimate of a hybrid that raises to a power
/// ([`HybridOp::is_power`]). With each power's largest stretch in the
/// running derivative, the largest ratio measured over the classic forms
/// (the Mandelbulb, the power-2 bulbs, the quaternion Mandelbrot set, the
/// burning bulb, Julia bulbs, boxes and bulbs alternated) is 1.07 and over
/// 400 random hybrids 1.27, with the estimate held to the powers' reach
/// ([`HYBRID_POWER_REACH`]), both far from the surface, where the
/// logarithmic form grows faster than the distance (near it, at most
/// 0.61); the factor covers 1.97 times that. It is measured, not proven:
/// a finer survey (`examples/hybrid_survey`, 10,000 points near each of
/// 300 random hybrids) finds none that it does not cover, and two at a
/// factor of 0.6 (see the [guide](crate::guide::fractals#hybrids)).
pub const HYBRID_POWER_SAFETY: f64 = 0.4;

/// The estimate of a hybrid with a power step is at most the smallest
/// `HYBRID_POWER_REACH · r / (n · dr)` over the orbit's power steps, with
/// `r` the radius entering a step of power `n` and `dr` the running
/// derivative there: a move of `p` by `d` moves the point entering the step
/// by about `d · dr` (to first order). Along the radius, `z^n` stretches a
/// move `δ` by `((r + δ)^n − r^n) / δ`, which is `((1 + x)^n − 1) / (n x)`
/// times its derivative `n r^(n − 1)` with `x = δ / r`: at most `e − 1`
/// times while `δ ≤ r / n`, but growing like `exp(n x)` beyond. Where an
/// orbit passes close to the origin before a power, the derivative taken
/// there sees nothing of how fast the map bends around it, and the
/// estimate could claim a ball that reaches the set (by 4.0, 1.6, 2.67
/// and 8.0 times in four of the first 300 hybrids of
/// `examples/hybrid_survey`). The multiplier is measured: at 16 the first
/// two of those overestimate again, at 12 none of the first 100 hybrids
/// does, and at 8 none of 300; the power-8 Mandelbulb written as a hybrid
/// then takes 4.5% more evaluations a pixel (at 4, 32% more; at 1, three
/// times as many). An escaping orbit that meets the origin exactly has a
/// reach of 0, so around such a point (isolated, where it exists) the
/// estimate falls to 0 although the set is not there: a ray passing
/// within the hit threshold of it stops on nothing, a speck of at most a
/// pixel.
pub const HYBRID_POWER_REACH: f64 = 8.0;

/// Beyond this many times the bailout the estimate is the distance to the
/// bailout's ball alone, a proven bound: there the escape-time estimate,
/// which grows faster than the distance, would overestimate it (as the
/// Mandelbulb's does beyond
/// [`MANDELBULB_FAR_FIELD`](super::MANDELBULB_FAR_FIELD) radii).
pub const HYBRID_FAR_FIELD: f64 = 1.5;

/// An orbit is followed until it passes this many times the bailout (or
/// its iterations end): the estimate is then taken far from the ball's
/// edge, where it measures the distance to the set rather than to the
/// points that leave the ball at one step or the next.
pub const HYBRID_FOLLOW: f64 = 16.0;

/// The integer form of each operation's power, in the order the stages
/// list their operations (`None` for every other operation and for a
/// power that is dynamic or not an integer): where a power is a baked
/// integer, [`hybrid_estimate`] raises to it with no trigonometry.
#[must_use]
pub(crate) fn hybrid_integer_powers(h: &Hybrid<Scalar>) -> Vec<Option<u32>> {
    h.stages
        .iter()
        .flat_map(|s| &s.ops)
        .map(|op| match op {
            HybridOp::Power { power } => power.baked().and_then(integer_power),
            _ => None,
        })
        .collect()
}

/// [`hybrid_estimate`] with an integer iteration count.
#[must_use]
pub fn hybrid<T: Num>(
    p: V3<T>,
    iterations: u32,
    h: &Hybrid<T>,
    integer_powers: &[Option<u32>],
) -> Estimate<T> {
    hybrid_estimate(p, T::of(f64::from(iterations)), h, integer_powers, None)
}

/// One operation, ready to run: `(z, dr, p) → (z', dr')`.
type Op<'a, T> = Box<dyn Fn(V3<T>, T, V3<T>) -> (V3<T>, T) + 'a>;

/// A power step's reach at the point `z` entering it ([`power_reach`]).
type Reach<'a, T> = Box<dyn Fn(V3<T>) -> T + 'a>;

/// One operation of a stage, ready to run, with its reach if it raises
/// to a power.
struct Prepared<'a, T> {
    run: Op<'a, T>,
    reach: Option<Reach<'a, T>>,
}

/// The operation `op` with its constants (turns' sines and cosines, unit
/// normals, squared radii) computed once, outside the loop.
fn prepare<'a, T: Num + 'a>(op: &HybridOp<T>, integer: Option<u32>) -> Op<'a, T> {
    match *op {
        HybridOp::BoxFold { limit } => {
            Box::new(move |z: V3<T>, dr, _| (z.map(|v| box_fold(v, limit)), dr))
        }
        HybridOp::SurfFold { limit_x, limit_y } => Box::new(move |z: V3<T>, dr, _| {
            (v3(box_fold(z.x, limit_x), box_fold(z.y, limit_y), z.z), dr)
        }),
        HybridOp::SphereFold {
            min_radius,
            fixed_radius,
        } => {
            let fixed2 = fixed_radius * fixed_radius;
            let min2 = (min_radius * min_radius).min(fixed2);
            Box::new(move |z: V3<T>, dr: T, _| {
                let k = sphere_fold_factor(z.dot(z), min2, fixed2);
                (z * k, dr * k)
            })
        }
        HybridOp::Scale { factor, center } => {
            let c = v3(center[0], center[1], center[2]);
            let stretch = factor.abs();
            Box::new(move |z: V3<T>, dr: T, _| ((z - c) * factor + c, dr * stretch))
        }
        HybridOp::Rotate { angles } => {
            let turn = turn(v3(angles[0], angles[1], angles[2]));
            Box::new(move |z, dr, _| (turn(z), dr))
        }
        HybridOp::AbsFold => Box::new(|z: V3<T>, dr, _| (z.abs(), dr)),
        HybridOp::PlaneFold { normal, offset } => {
            let n = v3(normal[0], normal[1], normal[2]);
            let n = n * (T::one() / n.length().max(T::tiny()));
            Box::new(move |z: V3<T>, dr, _| {
                let below = (z.dot(n) - offset).min(T::zero());
                (z - n * (T::of(2.0) * below), dr)
            })
        }
        HybridOp::Fold(fold) => Box::new(move |z, dr, _| (kifs_fold(fold, z), dr)),
        HybridOp::Power { power } => Box::new(move |z: V3<T>, dr: T, _| {
            let r = z.length();
            // r^(power - 1), capped so that no product overflows.
            let r_pow = match integer {
                Some(n) => super::pow_int(r, n - 1),
                None => r.powf(power - T::one()),
            }
            .min(T::magnitude_cap());
            let direction = triplex_direction(z, r, power, integer);
            // The map stretches by `power · r^(power − 1)` along the radius
            // and the polar angle, and by that times `sin(power θ) / sin θ`
            // along the azimuth (up to `power` times more, near the poles):
            // the running derivative takes the largest.
            let stretch = power * r_pow * azimuthal_stretch(z, r, direction, power);
            // The new radius, capped so that its square stays finite.
            let radius = (r_pow * r).min(T::magnitude_cap());
            (direction * radius, stretch * dr)
        }),
        HybridOp::BulbSquare { negate_z } => Box::new(move |z: V3<T>, dr: T, _| {
            let r = z.length();
            let rho = z.x.hypot(z.y);
            let inv_r = T::one() / r.max(T::tiny());
            // The latitude's cosine and sine, doubled.
            let (cos_lat, sin_lat) = (rho * inv_r, z.z * inv_r);
            let cos2 = cos_lat * cos_lat - sin_lat * sin_lat;
            let sin2 = T::of(2.0) * sin_lat * cos_lat;
            // The azimuth's, doubled; on the z axis the azimuth is 0.
            let off_axis = rho.gt(T::tiny());
            let (c, s) = (
                T::select(off_axis, z.x / rho, T::one()),
                T::select(off_axis, z.y / rho, T::zero()),
            );
            let sign = T::of(if negate_z { -1.0 } else { 1.0 });
            let direction = v3(
                cos2 * (c * c - s * s),
                cos2 * (T::of(2.0) * c * s),
                sign * sin2,
            );
            let r = r.min(T::magnitude_cap());
            let stretch = T::of(2.0) * r * azimuthal_stretch(z, r, direction, T::derivative_cap());
            (direction * (r * r).min(T::magnitude_cap()), stretch * dr)
        }),
        HybridOp::QuaternionSquare => Box::new(|z: V3<T>, dr: T, _| {
            let two_x = T::of(2.0) * z.x;
            let square = v3(z.x * z.x - z.y * z.y - z.z * z.z, two_x * z.y, two_x * z.z);
            // |q²| = |q|²: held where its square would not be finite.
            let r2 = z.dot(z);
            let hold = (T::magnitude_cap() / r2.max(T::tiny())).min(T::one());
            (square * hold, T::of(2.0) * r2.sqrt() * dr)
        }),
        HybridOp::AddPoint => Box::new(|z, dr: T, p| (z + p, dr + T::one())),
        HybridOp::AddConstant { c } => {
            let c = v3(c[0], c[1], c[2]);
            Box::new(move |z, dr, _| (z + c, dr))
        }
    }
}

/// How far the point entering a step may move before the step's map bends
/// past what its derivative at the point describes, for the steps that
/// raise to a power: [`HYBRID_POWER_REACH`] `· r / n` for a power `n` at
/// radius `r` (`None` for the other steps, whose maps are piecewise
/// isometries and scalings, bent only where they fold).
fn power_reach<'a, T: Num + 'a>(op: &HybridOp<T>) -> Option<Reach<'a, T>> {
    let power = match *op {
        HybridOp::Power { power } => power.abs().max(T::one()),
        HybridOp::BulbSquare { .. } | HybridOp::QuaternionSquare => T::of(2.0),
        _ => return None,
    };
    let reach = T::of(HYBRID_POWER_REACH) / power;
    Some(Box::new(move |z: V3<T>| z.length() * reach))
}

/// How much more than along the radius a power step's map stretches along
/// the azimuth, at the point `z` of radius `r` that it sends in
/// `direction`: the ratio of the circles of latitude the two lie on (at
/// least 1, and at most `cap`).
fn azimuthal_stretch<T: Num>(z: V3<T>, r: T, direction: V3<T>, cap: T) -> T {
    (direction.x.hypot(direction.y) * r / z.x.hypot(z.y).max(T::tiny()))
        .min(cap)
        .max(T::one())
}

/// The hybrid fractal's distance estimate (see [`Hybrid`]).
///
/// The drawn set is the points within the ball of radius `h.bailout`
/// whose orbit is within it at the end of each of `iterations`
/// iterations, and which no operation takes past [`HYBRID_FOLLOW`] times
/// the bailout. Each iteration runs every operation in turn; the orbit is
/// followed until it passes [`HYBRID_FOLLOW`] times the bailout (the rest
/// of that iteration leaves it there, and the loop ends). With `r` the
/// orbit's last radius and `dr` its running derivative, the estimate is
/// `0.5 · r · ln(r / bailout) / dr` where an iteration raises to a power
/// (and at most the power steps' reach, [`HYBRID_POWER_REACH`])
/// and `(r − bailout) / dr` otherwise, times the hybrid's
/// [`safety`](Hybrid::safety) ([`HYBRID_POWER_SAFETY`] or
/// [`HYBRID_SAFETY`] where it has none), and at least the distance to the
/// ball; an orbit that
/// left the ball is outside whatever it does next, so the sign is the
/// membership's. `integer_powers` lists the baked integer power of each
/// operation in the order the stages list them (`None` for the rest, or an
/// empty list: every power in the trigonometric form). The trap is the
/// orbit's smallest radius, at most 1.
#[must_use]
pub fn hybrid_estimate<T: Num>(
    p: V3<T>,
    iterations: T,
    h: &Hybrid<T>,
    integer_powers: &[Option<u32>],
    trap: Option<&TrapShape<T>>,
) -> Estimate<T> {
    let slot = TrapSlot::new(trap);
    let bailout = h.bailout;
    let bailout2 = bailout * bailout;
    let mut integer = integer_powers.iter().copied();
    let stages: Vec<(Vec<Prepared<'_, T>>, u32)> = h
        .stages
        .iter()
        .map(|stage| {
            let ops = stage
                .ops
                .iter()
                .map(|op| Prepared {
                    run: prepare(op, integer.next().flatten()),
                    reach: power_reach(op),
                })
                .collect();
            (ops, stage.repeat)
        })
        .collect();
    let r0 = p.length();
    let outer = r0 - bailout;
    let follow = bailout * T::of(HYBRID_FOLLOW);
    let follow2 = follow * follow;
    // A point outside the ball is outside the set; its orbit is still
    // followed, for an estimate of the distance to the set rather than to
    // the ball.
    let escaped = T::select(outer.gt(T::zero()), T::one(), T::zero());
    // Far from the ball its distance alone: no orbit to follow.
    let far_field = r0.gt(bailout * T::of(HYBRID_FAR_FIELD));
    let iterations = T::select(far_field, T::zero(), iterations);
    // With a power, the state carries the smallest reach of its steps
    // ([`HYBRID_POWER_REACH`]); without one there is none to carry.
    let powered = h.has_power();
    let mut start = vec![p.x, p.y, p.z, T::one(), slot.start(p.dot(p), p), escaped];
    if powered {
        start.push(T::magnitude_cap());
    }
    let end = T::iterate_dyn(iterations, start, &mut |_, state| {
        let (mut z, mut dr, mut escaped) = (v3(state[0], state[1], state[2]), state[3], state[5]);
        let mut reach = state.get(6).copied();
        // 1 once an operation has taken the orbit past `follow`: the
        // rest of the iteration leaves it there, and the loop ends.
        let mut far = T::zero();
        for (ops, repeat) in &stages {
            for _ in 0..*repeat {
                for op in ops {
                    let (next, next_dr) = (op.run)(z, dr, p);
                    let stay = far.lt(T::of(0.5));
                    if let (Some(power_reach), Some(reach)) = (&op.reach, reach.as_mut()) {
                        // A move of `p` by `d` moves `z` by about `d · dr`.
                        let within = power_reach(z) / dr.max(T::tiny());
                        *reach = T::select(stay, reach.min(within), *reach);
                    }
                    z = V3::select(stay, next, z);
                    dr = T::select(stay, next_dr.min(T::derivative_cap()), dr);
                    far = T::select(z.dot(z).gt(follow2), T::one(), far);
                }
            }
        }
        // The bailout is checked where each iteration ends.
        let out = far.gt(T::of(0.5)) | z.dot(z).gt(bailout2);
        escaped = T::select(out, T::one(), escaped);
        let trap = slot.shape_within(slot.own(state[4], || z.dot(z)), z, !out);
        let mut next = vec![z.x, z.y, z.z, dr, trap, escaped];
        next.extend(reach);
        Step {
            stop_before: None,
            next,
            stop_after: Some(far.gt(T::of(0.5))),
        }
    });
    let (x, y, z, dr, trap, escaped) = (end[0], end[1], end[2], end[3], end[4], end[5]);
    let r = v3(x, y, z).length();
    // A power of 0 leaves no derivative: guarded, and the estimate held to
    // magnitudes whose squares are finite.
    let dr = dr.max(T::tiny());
    let estimate = match end.get(6) {
        Some(&reach) => (T::of(0.5) * r * (r.max(T::tiny()) / bailout).ln() / dr)
            .clamp(-T::magnitude_cap(), T::magnitude_cap())
            .min(reach),
        None => ((r - bailout) / dr).clamp(-T::magnitude_cap(), T::magnitude_cap()),
    };
    // An orbit that left the ball and came back is still outside.
    let estimate = T::select(escaped.gt(T::of(0.5)), estimate.max(T::tiny()), estimate);
    let factor = h.safety.unwrap_or_else(|| {
        T::of(if powered {
            HYBRID_POWER_SAFETY
        } else {
            HYBRID_SAFETY
        })
    });
    Estimate {
        distance: T::select(far_field, outer, (factor * estimate).max(outer)),
        trap: slot.end(trap, |t| t.sqrt().min(T::one())),
    }
}
