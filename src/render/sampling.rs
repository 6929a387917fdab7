//! Where each sample of a pixel lies, in the pixel and on the lens: the
//! CPU twin of `march_sample_point` in `kernels/optics.cl`, so a test can
//! trace the rays the kernel traces.

use glam::DVec2;

/// Sample `j` of a pixel: its position in the pixel and on the lens.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SamplePoint {
    /// The position in the pixel, each coordinate in `[0, 1)`; add the
    /// pixel's corner to get an image position for
    /// [`Viewport::lens_ray`](super::Viewport::lens_ray).
    pub offset: DVec2,
    /// The point of the unit disc where the ray leaves the lens.
    pub lens: DVec2,
}

/// Sample `j` of rendered pixel `(x, y)` of an image `width` pixels wide,
/// with `supersampling` × `supersampling` samples per pass: sample
/// `j = pass · N² + s`. With supersampling, sample `s` is jittered in cell
/// `s` of an N × N grid over the pixel; without, sample 0 is the pixel's
/// centre and later ones follow the R2 sequence (Roberts 2018) rotated by a
/// per-pixel offset. The lens follows the Halton sequence in bases 2 and 3,
/// with an offset of its own, mapped to the disc by Shirley and Chiu's
/// concentric map: a different kind of sequence from the pixel's, so no
/// point in the pixel is tied to one on the lens.
///
/// ```
/// use fractal_sdf::render::sample_point;
/// let first = sample_point(64, 3, 5, 0, 1);
/// assert_eq!(first.offset.to_array(), [0.5, 0.5]);
/// assert!(first.lens.length() <= 1.0);
/// ```
#[must_use]
pub fn sample_point(width: u32, x: u32, y: u32, j: u32, supersampling: u32) -> SamplePoint {
    let pixel = y.wrapping_mul(width).wrapping_add(x);
    let n = supersampling.max(1);
    let offset = if n > 1 {
        let s = j % (n * n);
        DVec2::new(
            (f64::from(s % n) + jitter(pixel, j, 0)) / f64::from(n),
            (f64::from(s / n) + jitter(pixel, j, 1)) / f64::from(n),
        )
    } else if j == 0 {
        DVec2::splat(0.5)
    } else {
        pixel_point(pixel, j)
    };
    SamplePoint {
        offset,
        lens: disc(lens_point(pixel, j)),
    }
}

/// Where the brute-force steps of sample `j` of rendered pixel `(x, y)` of
/// an image `width` pixels wide start, in `[0, 1)` of a step: the kernel's
/// `march_brute_phase`, the phase
/// [`cpu::Brute`](crate::cpu::Brute) takes to march exactly the kernel's
/// lattice. A per-pixel offset, advanced by the golden ratio's fraction
/// from one sample to the next. (In `F32` kernels the phase of a large `j`
/// is rounded; sample 0's is exact in both precisions.)
///
/// ```
/// use fractal_sdf::render::brute_phase;
/// let phase = brute_phase(64, 3, 5, 0);
/// assert!((0.0..1.0).contains(&phase));
/// assert_ne!(phase, brute_phase(64, 3, 5, 1));
/// ```
#[must_use]
pub fn brute_phase(width: u32, x: u32, y: u32, j: u32) -> f64 {
    let pixel = y.wrapping_mul(width).wrapping_add(x);
    let u = jitter(pixel, 0, 2) + 0.618_033_988_749_894_8 * f64::from(j);
    u - u.floor()
}

/// The kernel's `march_hash`.
fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// The kernel's `march_jitter`: a number in `[0, 1)` with 24 bits.
fn jitter(x: u32, y: u32, sample: u32) -> f64 {
    f64::from(hash(x ^ hash(y ^ hash(sample))) >> 8) * 2f64.powi(-24)
}

/// The kernel's `march_pixel_point`: point `j` of the R2 sequence, its
/// steps as 32-bit fractions, rotated by the pixel's offset.
fn pixel_point(pixel: u32, j: u32) -> DVec2 {
    const STEPS: [u32; 2] = [0xc13f_a9a9, 0x91e1_0da6];
    let at = |k: usize| {
        let step = f64::from(STEPS[k].wrapping_mul(j) >> 8) * 2f64.powi(-24);
        let q = jitter(pixel, 0, k as u32) + step;
        q - q.floor()
    };
    DVec2::new(at(0), at(1))
}

/// The kernel's `march_radical_inverse`: `j`'s digits in base `b`
/// mirrored about the point.
fn radical_inverse(mut j: u32, b: u32) -> f64 {
    let step = 1.0 / f64::from(b);
    let (mut scale, mut r) = (step, 0.0);
    while j > 0 {
        r += scale * f64::from(j % b);
        scale *= step;
        j /= b;
    }
    r
}

/// The kernel's `march_lens_point`: point `j` of the Halton sequence in
/// bases 2 and 3, rotated by the pixel's offset.
fn lens_point(pixel: u32, j: u32) -> DVec2 {
    let q = DVec2::new(jitter(pixel, 0, 2), jitter(pixel, 0, 3))
        + DVec2::new(radical_inverse(j, 2), radical_inverse(j, 3));
    q - q.floor()
}

/// The kernel's `march_disc`: the unit square onto the unit disc.
fn disc(q: DVec2) -> DVec2 {
    let (a, b) = (2.0 * q.x - 1.0, 2.0 * q.y - 1.0);
    if a == 0.0 && b == 0.0 {
        return DVec2::ZERO;
    }
    let quarter = std::f64::consts::FRAC_PI_4;
    if a.abs() > b.abs() {
        a * DVec2::new((quarter * b / a).cos(), (quarter * b / a).sin())
    } else {
        b * DVec2::new((quarter * a / b).sin(), (quarter * a / b).cos())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn supersampled_points_fill_their_cells() {
        for j in 0..32 {
            let p = sample_point(100, 7, 9, j, 4);
            let s = j % 16;
            let cell = DVec2::new(f64::from(s % 4), f64::from(s / 4)) / 4.0;
            let inside = p.offset - cell;
            assert!(
                inside.min_element() >= 0.0 && inside.max_element() < 0.25,
                "{j}: {p:?}"
            );
        }
    }

    #[test]
    fn lens_points_cover_the_disc_evenly() {
        // 4096 points: each quarter of the disc, and the inner disc of half
        // the radius (a quarter of the area), gets close to a quarter.
        let points: Vec<DVec2> = (0..4096)
            .map(|j| sample_point(64, 3, 2, j, 1).lens)
            .collect();
        assert!(points.iter().all(|p| p.length() <= 1.0 + 1e-12));
        let share = |f: &dyn Fn(&DVec2) -> bool| {
            points.iter().filter(|p| f(p)).count() as f64 / points.len() as f64
        };
        for quadrant in [
            share(&|p| p.x > 0.0 && p.y > 0.0),
            share(&|p| p.x < 0.0 && p.y > 0.0),
            share(&|p| p.x < 0.0 && p.y < 0.0),
            share(&|p| p.x > 0.0 && p.y < 0.0),
            share(&|p| p.length() < 0.5),
        ] {
            assert!((quadrant - 0.25).abs() < 0.01, "{quadrant}");
        }
    }

    #[test]
    fn lens_points_are_not_tied_to_pixel_points() {
        // The samples in one quarter of the pixel land on every quarter of
        // the lens alike: a lens point drawn from the pixel point (the
        // pixel's sequence shifted, say) would crowd one of them.
        let mut quarters = [0u32; 4];
        for j in 1..4097 {
            let p = sample_point(64, 3, 2, j, 1);
            if p.offset.x < 0.5 && p.offset.y < 0.5 {
                quarters[usize::from(p.lens.x > 0.0) + 2 * usize::from(p.lens.y > 0.0)] += 1;
            }
        }
        let total: u32 = quarters.iter().sum();
        assert!(total > 900, "{total}");
        for q in quarters {
            let share = f64::from(q) / f64::from(total);
            assert!((share - 0.25).abs() < 0.03, "{quarters:?}");
        }
    }

    #[test]
    fn pixel_points_after_the_first_spread_over_the_pixel() {
        let points: Vec<DVec2> = (1..1025)
            .map(|j| sample_point(64, 3, 2, j, 1).offset)
            .collect();
        let mean = points.iter().copied().sum::<DVec2>() / points.len() as f64;
        assert!((mean - DVec2::splat(0.5)).length() < 0.01, "{mean}");
        // Every cell of an 8 × 8 grid gets 16 ± 4 of them: the R2
        // sequence is far more even than independent random points.
        let mut cells = [0u32; 64];
        for p in &points {
            cells[(p.y * 8.0) as usize * 8 + (p.x * 8.0) as usize] += 1;
        }
        assert!(cells.iter().all(|&c| (12..=20).contains(&c)), "{cells:?}");
    }
}
