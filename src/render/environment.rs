//! The environment light's buffer (the layout of
//! [`interface::environment`](crate::codegen::interface::environment)): the
//! image, the distributions its directions are drawn from in proportion to
//! their light, and its irradiance at a few normals.

use crate::codegen::interface::environment as layout;
use crate::scene::{Environment, EnvironmentMap, environment_direction};

/// The irradiance map's size: enough for light that varies as slowly as a
/// cosine lobe's integral does.
const IRRADIANCE: (u32, u32) = (32, 16);

/// The grid of directions the irradiance is integrated over: the image is
/// averaged down to it, or a smaller image's texels repeated.
const INTEGRATED: (u32, u32) = (64, 32);

/// The buffer `render_tile` reads `environment` from; the header alone,
/// zeros, without one.
pub(crate) fn pack(environment: Option<&Environment>) -> Vec<f32> {
    let Some(env) = environment else {
        return vec![0.0; layout::TEXELS];
    };
    let map = &*env.map;
    let (w, h) = (map.width() as usize, map.height() as usize);
    let mut out = Vec::with_capacity(layout::len(
        w,
        h,
        (IRRADIANCE.0 as usize, IRRADIANCE.1 as usize),
    ));
    let (sin, cos) = env.rotation_degrees.to_radians().sin_cos();
    let (rows, total) = distributions(map);
    #[allow(clippy::cast_possible_truncation)] // the kernel reads floats
    let header = [
        map.width() as f32,
        map.height() as f32,
        cos as f32,
        sin as f32,
        env.intensity as f32,
        total as f32,
        IRRADIANCE.0 as f32,
        IRRADIANCE.1 as f32,
    ];
    out.extend_from_slice(&header);
    out.extend(map.texels().iter().flatten());
    out.extend(rows);
    out.extend(irradiance(map).into_iter().flatten());
    debug_assert_eq!(out.len(), out.capacity());
    out
}

/// A texel's luminance.
fn luminance(t: [f32; 3]) -> f64 {
    0.2126 * f64::from(t[0]) + 0.7152 * f64::from(t[1]) + 0.0722 * f64::from(t[2])
}

/// The weight each texel is drawn with: its luminance times the sine of
/// its row's polar angle (the solid angle it spans).
fn weights(map: &EnvironmentMap) -> Vec<f64> {
    let (w, h) = (map.width() as usize, map.height() as usize);
    map.texels()
        .iter()
        .enumerate()
        .map(|(i, &t)| luminance(t) * row_sine(i / w, h))
        .collect()
}

/// The sine of the polar angle at the centre of row `y` of `h`.
fn row_sine(y: usize, h: usize) -> f64 {
    #[allow(clippy::cast_precision_loss)]
    ((y as f64 + 0.5) / h as f64 * std::f64::consts::PI).sin()
}

/// The marginal distribution of rows (`h + 1` cumulative sums) followed by
/// each row's conditional distribution of texels (`w + 1` each), and the
/// sum of the weights.
fn distributions(map: &EnvironmentMap) -> (Vec<f32>, f64) {
    let (w, h) = (map.width() as usize, map.height() as usize);
    let weights = weights(map);
    let row_sums: Vec<f64> = weights.chunks_exact(w).map(|r| r.iter().sum()).collect();
    let total: f64 = row_sums.iter().sum();
    let mut out = Vec::with_capacity((h + 1) + h * (w + 1));
    push_cumulative(&mut out, &row_sums);
    for row in weights.chunks_exact(w) {
        push_cumulative(&mut out, row);
    }
    (out, total)
}

/// The cumulative sums of `weights` over their total, from 0 to exactly 1
/// (evenly spread where the total is 0).
fn push_cumulative(out: &mut Vec<f32>, weights: &[f64]) {
    let total: f64 = weights.iter().sum();
    let mut sum = 0.0;
    out.push(0.0);
    #[allow(clippy::cast_possible_truncation, clippy::cast_precision_loss)]
    for (i, &w) in weights.iter().enumerate() {
        sum += w;
        let at = if i + 1 == weights.len() {
            1.0
        } else if total > 0.0 {
            sum / total
        } else {
            (i + 1) as f64 / weights.len() as f64
        };
        out.push(at as f32);
    }
}

/// The map's irradiance over π at the centre of each texel of an
/// [`IRRADIANCE`]-sized map (in the image's own frame): the radiance a
/// white Lambertian face turned that way sends back under it.
fn irradiance(map: &EnvironmentMap) -> Vec<[f32; 3]> {
    let small = shrink(map, INTEGRATED);
    let (sw, sh) = (small.width() as usize, small.height() as usize);
    let step = |n: usize| 1.0 / f64::from(u32::try_from(n).unwrap_or(u32::MAX));
    // Each small texel's direction and solid angle.
    let texels: Vec<(glam::DVec3, f64, [f32; 3])> = (0..sh)
        .flat_map(|y| (0..sw).map(move |x| (x, y)))
        .map(|(x, y)| {
            #[allow(clippy::cast_precision_loss)]
            let (u, v) = ((x as f64 + 0.5) * step(sw), (y as f64 + 0.5) * step(sh));
            let solid = std::f64::consts::TAU
                * std::f64::consts::PI
                * step(sw)
                * step(sh)
                * row_sine(y, sh);
            (
                environment_direction(u, v),
                solid,
                small.texels()[y * sw + x],
            )
        })
        .collect();
    let (iw, ih) = (IRRADIANCE.0 as usize, IRRADIANCE.1 as usize);
    (0..ih)
        .flat_map(|y| (0..iw).map(move |x| (x, y)))
        .map(|(x, y)| {
            #[allow(clippy::cast_precision_loss)]
            let n = environment_direction((x as f64 + 0.5) * step(iw), (y as f64 + 0.5) * step(ih));
            let mut sum = [0.0f64; 3];
            for &(d, solid, t) in &texels {
                let cos = n.dot(d);
                if cos > 0.0 {
                    for c in 0..3 {
                        sum[c] += f64::from(t[c]) * cos * solid;
                    }
                }
            }
            #[allow(clippy::cast_possible_truncation)]
            sum.map(|s| (s / std::f64::consts::PI) as f32)
        })
        .collect()
}

/// `map` on a grid of `size`: each cell the mean of the texels it covers,
/// or the one texel it lies in.
fn shrink(map: &EnvironmentMap, size: (u32, u32)) -> EnvironmentMap {
    let (w, h) = (map.width(), map.height());
    let (sw, sh) = size;
    let span = |i: u32, n: u32, small: u32| {
        let lo = (u64::from(i) * u64::from(n) / u64::from(small)) as usize;
        let hi = (u64::from(i + 1) * u64::from(n) / u64::from(small)) as usize;
        lo..hi.max(lo + 1)
    };
    let mut texels = Vec::with_capacity((sw * sh) as usize);
    for y in 0..sh {
        for x in 0..sw {
            let mut sum = [0.0f64; 3];
            let mut count = 0.0;
            for yy in span(y, h, sh) {
                for xx in span(x, w, sw) {
                    let t = map.texels()[yy * w as usize + xx];
                    for c in 0..3 {
                        sum[c] += f64::from(t[c]);
                    }
                    count += 1.0;
                }
            }
            #[allow(clippy::cast_possible_truncation)]
            texels.push(sum.map(|s| (s / count) as f32));
        }
    }
    EnvironmentMap::new(sw, sh, texels).expect("an average of valid texels")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_uniform_sky_is_drawn_in_proportion_to_solid_angle_and_lights_a_face_with_itself() {
        let map = EnvironmentMap::new(16, 8, vec![[2.0, 2.0, 2.0]; 128]).unwrap();
        let env = Environment::new(map);
        let buffer = pack(Some(&env));
        assert_eq!(buffer.len(), layout::len(16, 8, (32, 16)));
        let rows = &buffer[layout::TEXELS + 3 * 128..][..9];
        assert_eq!((rows[0], rows[8]), (0.0, 1.0));
        // The rows' shares follow the sine of their polar angles.
        let expected: f64 = (0..8).map(|y| row_sine(y, 8)).sum();
        for y in 0..8 {
            let share = f64::from(rows[y + 1] - rows[y]);
            assert!((share - row_sine(y, 8) / expected).abs() < 1e-6);
        }
        // Under radiance 2 everywhere a white face sends back 2, facing
        // any way (the integration's error is a few tenths of a percent).
        let irr = &buffer[layout::len(16, 8, (0, 0))..];
        for v in irr {
            assert!((v - 2.0).abs() < 0.02, "{v}");
        }
        assert_eq!(pack(None), vec![0.0; layout::TEXELS]);
    }
}
