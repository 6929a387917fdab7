//! Knighty's pseudo-Kleinian fractal's estimate ([`PseudoKleinian`]).

use super::{Estimate, TrapShape, TrapSlot, box_fold};
use crate::expr::Step;
use crate::math::{Num, V3, v3};
use crate::scene::PseudoKleinian;

/// The pseudo-Kleinian estimate is multiplied by this safety factor:
/// Knighty's estimate is not a proven bound. The largest ratio of estimate
/// to distance measured against brute-force membership
/// ([`testing::pseudo_kleinian_inside`](crate::testing::pseudo_kleinian_inside)),
/// over the published preset and random settings, near the surface and out
/// from it, is in the [fractals chapter](crate::guide::fractals#the-pseudo-kleinian)
/// of the guide; the factor covers 1.25 times it.
pub const PSEUDO_KLEINIAN_SAFETY: f64 = 0.4;

/// [`pseudo_kleinian_estimate`] with an integer iteration count.
#[must_use]
pub fn pseudo_kleinian<T: Num>(p: V3<T>, iterations: u32, k: &PseudoKleinian<T>) -> Estimate<T> {
    pseudo_kleinian_estimate(p, T::of(f64::from(iterations)), k, None)
}

/// Knighty's pseudo-Kleinian estimate (see [`PseudoKleinian`]): the
/// orbit's end `z` after `iterations` steps of box fold, inversion and
/// offset, and the running derivative `dr` (the product of the
/// inversions' stretches), give `(ρ·|z_z| − t) / √(|z|² + t) / dr` with
/// `ρ = √(z_x² + z_y²)` and `t` the thickness, times
/// [`PSEUDO_KLEINIAN_SAFETY`]. Negative exactly inside the set (but for
/// the points a fold brings within 1e-6 of the origin, inverted as if that
/// far: see [`PseudoKleinian`]). The trap
/// is the orbit's smallest radius over the inversion sphere's, at most 1.
#[must_use]
pub fn pseudo_kleinian_estimate<T: Num>(
    p: V3<T>,
    iterations: T,
    k: &PseudoKleinian<T>,
    trap: Option<&TrapShape<T>>,
) -> Estimate<T> {
    let slot = TrapSlot::new(trap);
    let [bx, by, bz] = k.fold_size;
    let c = v3(k.offset[0], k.offset[1], k.offset[2]);
    let inversion = k.inversion;
    // The smallest squared radius an inversion divides by: its image is
    // then at most `inversion / √floor` from the origin, whose square
    // stays finite in single precision.
    let floor = T::of(1e-12);
    let start = [p.x, p.y, p.z, T::one(), slot.start(p.dot(p), p)];
    let [x, y, z, dr, trap] = T::iterate(iterations, start, |_, [x, y, z, dr, trap]| {
        let z = v3(box_fold(x, bx), box_fold(y, by), box_fold(z, bz));
        let stretch = (inversion / z.dot(z).max(floor)).max(T::one());
        let z = z * stretch + c;
        Step {
            stop_before: None,
            next: [
                z.x,
                z.y,
                z.z,
                (dr * stretch).min(T::derivative_cap()),
                slot.shape(slot.own(trap, || z.dot(z)), z),
            ],
            stop_after: None,
        }
    });
    let z = v3(x, y, z);
    let t = k.thickness;
    let shape = (z.x.hypot(z.y) * z.z.abs() - t) / (z.dot(z) + t).sqrt();
    Estimate {
        distance: T::of(PSEUDO_KLEINIAN_SAFETY) * shape / dr,
        trap: slot.end(trap, |r2| (r2 / inversion).sqrt().min(T::one())),
    }
}
