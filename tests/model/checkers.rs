//! The toolkit's checkers themselves: they report what they tested, fail
//! when that is too little, and catch estimators that are wrong in the
//! ways a vacuous check would let through.
use fractal_sdf::prelude::*;
use fractal_sdf::testing::{
    Check, MIN_BALL_FRACTION, check_exact, check_lipschitz, check_never_overestimates,
    menger_inside, near_surface_points,
};

fn unit_ball(p: DVec3) -> bool {
    p.length() <= 1.0
}

#[test]
fn an_estimator_that_says_inside_everywhere_fails() {
    let points = near_surface_points(unit_ball, 2.0, 0.5, 64, 3);
    let err = check_never_overestimates(&|_: DVec3| -1.0, unit_ball, &points, 16).unwrap_err();
    assert_eq!(err.check, Check::Sign, "{err}");
    // Every point outside the ball is a wrong sign.
    let outside = points.iter().filter(|&&p| !unit_ball(p)).count();
    assert_eq!(err.violations, outside, "{err}");
    assert!(err.to_string().contains("wrong sign"), "{err}");
}

#[test]
fn points_that_are_all_inside_test_no_ball_and_fail() {
    let inside: Vec<DVec3> = near_surface_points(unit_ball, 2.0, 0.5, 64, 4)
        .into_iter()
        .filter(|&p| unit_ball(p))
        .collect();
    assert!(!inside.is_empty());
    let err = check_never_overestimates(&sphere(1.0), unit_ball, &inside, 8).unwrap_err();
    assert_eq!(err.check, Check::TooFewTested, "{err}");
    assert_eq!(err.measured, 0.0);
    assert!(err.to_string().contains("too few inputs tested"), "{err}");
}

#[test]
fn checkers_report_what_they_tested() {
    let points = near_surface_points(unit_ball, 2.0, 0.5, 200, 5);
    assert_eq!(points.len(), 200);
    let tested = check_never_overestimates(&sphere(1.0), unit_ball, &points, 8).unwrap();
    let outside = points.iter().filter(|&&p| p.length() > 1.0).count();
    assert_eq!(tested.inputs, 200);
    assert_eq!(tested.balls, outside);
    assert_eq!(tested.signs, 200 - outside);
    // The sampler puts points on both sides in about equal numbers.
    assert!((60..=140).contains(&outside), "{outside} of 200 outside");
    #[allow(clippy::cast_precision_loss)]
    let share = tested.balls as f64 / 200.0;
    assert!(share >= MIN_BALL_FRACTION);

    let pairs: Vec<_> = points.windows(2).map(|w| (w[0], w[1])).collect();
    let tested = check_lipschitz(&sphere(1.0), 1.0, &pairs).unwrap();
    assert_eq!((tested.inputs, tested.balls), (199, 199));
    let tested = check_exact(&sphere(1.0), |p| p.length() - 1.0, &points, 1e-12).unwrap();
    assert_eq!(tested.inputs, 200);
}

#[test]
fn empty_inputs_fail_every_checker() {
    for err in [
        check_lipschitz(&sphere(1.0), 1.0, &[]).unwrap_err(),
        check_exact(&sphere(1.0), |p| p.length() - 1.0, &[], 1e-12).unwrap_err(),
        check_never_overestimates(&sphere(1.0), unit_ball, &[], 8).unwrap_err(),
    ] {
        assert_eq!(err.check, Check::TooFewTested, "{err}");
    }
}

#[test]
fn near_surface_points_lie_near_the_surface() {
    for band in [1e-3, 0.1, 0.5] {
        let points = near_surface_points(unit_ball, 2.0, band, 300, 6);
        assert_eq!(points.len(), 300);
        for p in &points {
            // Within the band of the sphere, up to the bisection's last step.
            assert!(
                (p.length() - 1.0).abs() <= band * (1.0 + 1e-9),
                "{p} band {band}"
            );
        }
        // Log-uniform offsets: a third of them below a hundredth of the band.
        let close = points
            .iter()
            .filter(|p| (p.length() - 1.0).abs() < band / 100.0)
            .count();
        assert!(
            (50..=150).contains(&close),
            "{close} of 300 within band/100"
        );
    }
    // Deterministic per seed, and different seeds give different points.
    let a = near_surface_points(|p| menger_inside(p, 2), 1.8, 0.1, 50, 7);
    assert_eq!(
        a,
        near_surface_points(|p| menger_inside(p, 2), 1.8, 0.1, 50, 7)
    );
    assert_ne!(
        a,
        near_surface_points(|p| menger_inside(p, 2), 1.8, 0.1, 50, 8)
    );
    // A set that fills none of the ball gives no points, not a loop.
    assert!(near_surface_points(|_| false, 1.0, 0.1, 10, 1).is_empty());
}

#[test]
fn a_failure_counts_what_was_checked_and_what_broke() {
    // Twice the sphere's distance overestimates at every point outside.
    let points = near_surface_points(unit_ball, 2.0, 0.5, 64, 9);
    let outside = points.iter().filter(|&&p| !unit_ball(p)).count();
    let err =
        check_never_overestimates(&|p: DVec3| 2.0 * (p.length() - 1.0), unit_ball, &points, 16)
            .unwrap_err();
    assert_eq!((err.violations, err.checked), (outside, outside), "{err}");
    assert!(
        err.to_string()
            .contains(&format!("{outside} of {outside} balls fail")),
        "{err}"
    );
}

#[test]
fn spicy_points_cover_both_ends_of_each_axis() {
    let points = fractal_sdf::testing::spicy_points();
    let on_an_axis = |p: &&DVec3| p.to_array().iter().filter(|&&c| c != 0.0).count() == 1;
    for p in points.iter().filter(on_an_axis) {
        assert!(points.contains(&-*p), "{p} without {}", -*p);
    }
    assert!(points.contains(&DVec3::new(-1e6, 0.0, 0.0)));
}

#[test]
fn unit_vectors_are_uniform_on_the_sphere() {
    use proptest::strategy::{Strategy, ValueTree};
    use proptest::test_runner::{Config, TestRng, TestRunner};
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        TestRng::deterministic_rng(Config::default().rng_algorithm),
    );
    let strategy = fractal_sdf::testing::unit_vector();
    let n = 4000;
    let (mut mean, mut abs_z) = (DVec3::ZERO, 0.0);
    for _ in 0..n {
        let u = strategy.new_tree(&mut runner).unwrap().current();
        assert!((u.length() - 1.0).abs() < 1e-12);
        mean += u;
        abs_z += u.z.abs();
    }
    #[allow(clippy::cast_precision_loss)]
    let (mean, abs_z) = (mean / n as f64, abs_z / n as f64);
    // Uniform on the sphere: mean 0 and E|z| = 1/2 (z is uniform in
    // [-1, 1]); 4,000 samples put each within about 0.02 (three standard
    // errors).
    assert!(mean.length() < 0.05, "mean {mean}");
    assert!((abs_z - 0.5).abs() < 0.02, "E|z| = {abs_z}");
}
