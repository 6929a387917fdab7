//! Points where a distance estimate is most at risk: near the surface.

use glam::DVec3;

/// Bisection steps between an inside and an outside point: the boundary
/// point is then known to `2^-48` of the segment.
const BISECTIONS: u32 = 48;

/// Draws `count` points within `band` of the boundary of the set that
/// `inside` describes, found within the ball of radius `radius` around the
/// origin, using nothing but `inside`: so the points owe nothing to the
/// estimator they will test.
///
/// Each point comes from a pair of uniform points in the ball on either
/// side of the boundary: bisection finds a boundary point between them,
/// and the sample lies in a random direction from it at a distance drawn
/// log-uniformly between `band / 1000` and `band`. About half the points
/// land outside the set, where [`check_never_overestimates`] tests a small
/// ball, and half inside, where it checks the sign.
///
/// Deterministic for a given `seed`. Returns fewer than `count` points
/// when the set fills all or none of the ball (after `64 * count` pairs
/// with no boundary between them): the checkers' minimums then fail
/// rather than pass with nothing tested.
///
/// [`check_never_overestimates`]: super::check_never_overestimates
///
/// ```
/// use fractal_sdf::testing::{menger_inside, near_surface_points};
/// let points = near_surface_points(|p| menger_inside(p, 3), 1.8, 0.1, 100, 1);
/// assert_eq!(points.len(), 100);
/// // Every point is within 0.1 of a boundary point inside the ball.
/// assert!(points.iter().all(|p| p.length() <= 1.8 + 0.1));
/// ```
#[must_use]
pub fn near_surface_points(
    inside: impl Fn(DVec3) -> bool,
    radius: f64,
    band: f64,
    count: usize,
    seed: u64,
) -> Vec<DVec3> {
    let mut rng = Xorshift(seed.max(1));
    let mut points = Vec::with_capacity(count);
    let mut attempts = 0usize;
    while points.len() < count && attempts < count.saturating_mul(64) {
        attempts += 1;
        let (a, b) = (rng.in_ball(radius), rng.in_ball(radius));
        let (inside_a, inside_b) = (inside(a), inside(b));
        if inside_a == inside_b {
            continue;
        }
        // Bisect, keeping `lo` on a's side and `hi` on b's.
        let (mut lo, mut hi) = (a, b);
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if inside(mid) == inside_a {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let offset = band * 10f64.powf(-3.0 * rng.unit());
        points.push(0.5 * (lo + hi) + rng.direction() * offset);
    }
    points
}

/// xorshift64: small, fast and deterministic.
struct Xorshift(u64);

impl Xorshift {
    /// Uniform in `[0, 1)`.
    #[allow(clippy::cast_precision_loss)]
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform on the unit sphere.
    fn direction(&mut self) -> DVec3 {
        let z = 2.0 * self.unit() - 1.0;
        let phi = std::f64::consts::TAU * self.unit();
        let rho = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(rho * phi.cos(), rho * phi.sin(), z)
    }

    /// Uniform in the ball of radius `r` around the origin.
    fn in_ball(&mut self, r: f64) -> DVec3 {
        self.direction() * (r * self.unit().cbrt())
    }
}
