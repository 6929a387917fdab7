//! Camera paths pass through every keyframe, stay smooth between them and
//! survive a round trip through their text format.

use fractal_sdf::animation::{CameraPath, Keyframe};
use fractal_sdf::prelude::*;
use proptest::prelude::*;

/// How far a sample at a keyframe's time may be from the keyframe. At
/// `t = t_i` the spline's pyramid of lerps returns `p_i` up to a few
/// roundings of coordinates below 10 (and of the reflected end points,
/// below 30): measured worst 2.7e-15 over 1,145 keyframes in 256 cases
/// (PROPTEST_RNG_SEED=20261201; four other seeds 2.6e-15 at most). The
/// tolerance is about 40 times that.
const AT_A_KEYFRAME: f64 = 1e-13;

fn keyframes() -> impl Strategy<Value = Vec<Keyframe>> {
    let v =
        || (-10.0..10.0f64, -10.0..10.0f64, -10.0..10.0f64).prop_map(|(x, y, z)| dvec3(x, y, z));
    prop::collection::vec((0.1..3.0f64, v(), v()), 2..8).prop_map(|items| {
        let mut time = 0.0;
        items
            .into_iter()
            .map(|(dt, p, t)| {
                time += dt;
                Keyframe::new(time, p, t)
            })
            .collect()
    })
}

proptest! {
    #[test]
    fn interpolation_passes_through_every_keyframe(keys in keyframes()) {
        let path = CameraPath::new(keys.clone()).unwrap();
        for k in &keys {
            let (p, t) = path.sample(k.time);
            prop_assert!((p - DVec3::from(k.position)).length() < AT_A_KEYFRAME, "{p} vs {:?}", k.position);
            prop_assert!((t - DVec3::from(k.target)).length() < AT_A_KEYFRAME);
        }
    }

    #[test]
    fn interpolation_is_continuous(keys in keyframes()) {
        // A short segment between distant keyframes is legitimately fast, so
        // no fixed bound on one step says "continuous". What does: the
        // largest step between samples shrinks in proportion to the sampling
        // interval, while a jump keeps its size however finely it is sampled.
        let path = CameraPath::new(keys.clone()).unwrap();
        let largest_step = |n: u32| {
            let mut last = path.sample(path.start()).0;
            let mut largest = 0.0f64;
            for i in 1..=n {
                let t = path.start() + path.duration() * f64::from(i) / f64::from(n);
                let p = path.sample(t).0;
                largest = largest.max((p - last).length());
                last = p;
            }
            largest
        };
        let (coarse, fine) = (largest_step(2_000), largest_step(20_000));
        prop_assert!(fine <= coarse / 4.0, "largest step {fine} at 10x the samples, {coarse} before");
        // Each keyframe joins two segments, the place an indexing slip would
        // show: both sides agree there. Not a rounding tolerance: samples
        // `2h` apart in time differ by about `2h` times the path's speed,
        // which a 0.1 s segment between keyframes 20 units apart makes
        // hundreds of units a second. Measured worst 4.8e-6 (that case,
        // kept in the regressions file) over 630 joins in 256 cases
        // (PROPTEST_RNG_SEED=20261201; 2.4e-6 at most in the random cases
        // of five seeds); the bound is about 2 times that, while an
        // indexing slip moves a sample by a segment's length (units).
        for k in &keys[1..keys.len() - 1] {
            let h = 1e-9 * k.time;
            let (before, after) = (path.sample(k.time - h).0, path.sample(k.time + h).0);
            prop_assert!((before - after).length() < 1e-5, "{before} | {after} at {}", k.time);
        }
    }

    #[test]
    fn toml_round_trip(keys in keyframes()) {
        let path = CameraPath::new(keys).unwrap();
        prop_assert_eq!(CameraPath::from_toml(&path.to_toml().unwrap()).unwrap(), path);
    }
}

#[test]
fn bad_paths_are_rejected() {
    let k = |t: f64| Keyframe::new(t, DVec3::ZERO, DVec3::X);
    assert!(matches!(
        CameraPath::new(vec![k(0.0)]),
        Err(Error::Animation { .. })
    ));
    assert!(matches!(
        CameraPath::new(vec![k(1.0), k(1.0)]),
        Err(Error::Animation { .. })
    ));
    assert!(matches!(
        CameraPath::new(vec![k(0.0), k(f64::NAN)]),
        Err(Error::Animation { .. })
    ));
    assert!(matches!(
        CameraPath::from_toml("keyframe = 3"),
        Err(Error::Animation { .. })
    ));
}

#[test]
fn times_outside_the_path_clamp_to_its_ends() {
    let path = CameraPath::new(vec![
        Keyframe::new(1.0, dvec3(0.0, 0.0, 0.0), DVec3::Z),
        Keyframe::new(2.0, dvec3(1.0, 0.0, 0.0), DVec3::Z),
    ])
    .unwrap();
    assert_eq!(path.sample(-5.0).0, DVec3::ZERO);
    assert_eq!(path.sample(9.0).0, DVec3::X);
    // Two keyframes: a straight line at constant speed. Every value in
    // the spline's lerps here is a small dyadic fraction, so the sample is
    // exact (measured 0); the tolerance admits a few roundings of 0.25.
    assert!((path.sample(1.25).0 - dvec3(0.25, 0.0, 0.0)).length() < 1e-15);
}
