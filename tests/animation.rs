//! Camera paths pass through every keyframe, stay smooth between them and
//! survive a round trip through their text format.

use fractal_sdf::animation::{CameraPath, Keyframe};
use fractal_sdf::prelude::*;
use proptest::prelude::*;

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
            prop_assert!((p - DVec3::from(k.position)).length() < 1e-9, "{p} vs {:?}", k.position);
            prop_assert!((t - DVec3::from(k.target)).length() < 1e-9);
        }
    }

    #[test]
    fn interpolation_is_continuous(keys in keyframes()) {
        let path = CameraPath::new(keys).unwrap();
        let n = 2000;
        let mut last = path.sample(path.start()).0;
        let mut largest = 0.0f64;
        for i in 1..=n {
            let t = path.start() + path.duration() * f64::from(i) / f64::from(n);
            let p = path.sample(t).0;
            largest = largest.max((p - last).length());
            last = p;
        }
        // Keyframes are at most 20 * sqrt(3) apart; a continuous curve moves
        // only a small fraction of that per 1/2000 of the path.
        prop_assert!(largest < 1.0, "jump of {largest}");
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
    // Two keyframes: a straight line at constant speed.
    assert!((path.sample(1.25).0 - dvec3(0.25, 0.0, 0.0)).length() < 1e-12);
}
