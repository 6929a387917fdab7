//! A render stops between tiles: when its token is cancelled, from any
//! thread, or when its deadline passes; the renderer stays usable.

use crate::gpu;

use std::time::{Duration, Instant};

use fractal_sdf::prelude::*;
use fractal_sdf::render::{CancelToken, RenderOptions, Renderer};
use fractal_sdf::scene::{CustomShape, Rule};

/// A sphere whose OpenCL distance burns `work` sine evaluations first: a
/// slow (not endless) custom body.
fn slow_sphere(work: u32) -> Scene {
    let shape = CustomShape::new(
        "slow_sphere",
        &[("radius", Rule::NonNegative)],
        |p, a| p.length() - a[0],
        &format!(
            "real acc = R(0.0);
             for (int i = 0; i < {work}; ++i) {{ acc += sin(acc + p.x); }}
             return length(p) - radius + R(0.0) * acc;"
        ),
    )
    .unwrap();
    Scene::new(shape.node([0.8])).with_camera(Camera::look_at(dvec3(0.0, 0.0, 3.0), DVec3::ZERO))
}

fn options(token: Option<CancelToken>, deadline: Option<Duration>) -> RenderOptions {
    gpu::options(gpu::plain(Quality::draft()), Effects::none())
        .tile_size(4)
        .cancel(token)
        .deadline(deadline)
}

#[test]
fn a_cancelled_token_stops_before_the_first_tile_until_reset() {
    let Some(_) = gpu::device() else { return };
    let token = CancelToken::new();
    let mut renderer =
        Renderer::with_options(&slow_sphere(1), &options(Some(token.clone()), None)).unwrap();
    token.cancel();
    let err = renderer.render(16, 12).unwrap_err();
    assert!(
        matches!(
            err,
            Error::Cancelled {
                tiles: 0,
                total: 12
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("cancelled"), "{err}");
    token.reset();
    let image = renderer.render(16, 12).unwrap();
    assert_eq!(image.dimensions(), (16, 12));
}

#[test]
fn a_passed_deadline_stops_the_frame() {
    let Some(_) = gpu::device() else { return };
    let mut renderer =
        Renderer::with_options(&slow_sphere(1), &options(None, Some(Duration::ZERO))).unwrap();
    let err = renderer.render_with_aovs(16, 12).unwrap_err();
    assert!(matches!(err, Error::Deadline { tiles: 0, .. }), "{err}");
    assert!(renderer.last_timing().is_none());
}

#[test]
fn a_slow_custom_body_is_stopped_between_tiles() {
    let Some(_) = gpu::device() else { return };
    // About 0.1 s a tile on a two-core CPU device; 48 tiles.
    let scene = slow_sphere(5_000);
    let (w, h) = (32, 24);

    // From another thread.
    let token = CancelToken::new();
    let mut renderer = Renderer::with_options(&scene, &options(Some(token.clone()), None)).unwrap();
    let canceller = {
        let token = token.clone();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(150));
            token.cancel();
        })
    };
    let start = Instant::now();
    let outcome = renderer.render(w, h);
    let took = start.elapsed();
    canceller.join().unwrap();
    match outcome {
        Err(Error::Cancelled { tiles, total }) => {
            assert_eq!(total, 48);
            assert!(tiles < total, "{tiles} of {total}");
            eprintln!("cancelled after {tiles} of {total} tiles, in {took:?}");
        }
        Ok(_) => eprintln!("note: the device rendered all 48 tiles in {took:?}, before the cancel"),
        Err(other) => panic!("{other}"),
    }

    // By a deadline.
    let deadline = Duration::from_millis(100);
    let mut renderer = Renderer::with_options(&scene, &options(None, Some(deadline))).unwrap();
    let start = Instant::now();
    match renderer.render(w, h) {
        Err(Error::Deadline {
            deadline: d,
            tiles,
            total,
        }) => {
            assert_eq!(d, deadline);
            assert!(tiles >= 1 && tiles < total, "{tiles} of {total}");
            eprintln!(
                "stopped after {tiles} of {total} tiles, in {:?}",
                start.elapsed()
            );
        }
        Ok(_) => eprintln!("note: the device rendered all tiles within {deadline:?}"),
        Err(other) => panic!("{other}"),
    }
    // The renderer is still usable (and the shape is drawn).
    renderer
        .set_param("nothing", 0.0)
        .expect_err("no such parameter");
    let mut quick = Renderer::with_options(&slow_sphere(1), &options(None, None)).unwrap();
    let frame = quick.render_with_aovs(w, h).unwrap();
    assert!(frame.hit.iter().any(|&h| h));
}

/// Set in the child process of
/// [`a_launch_that_never_ends_is_abandoned_at_the_watchdog`], which runs
/// the endless body where its stuck launch cannot hold up other tests.
const ENDLESS_CHILD: &str = "FRACTAL_SDF_ENDLESS_CHILD";

/// Regression: a custom body that never ends hung the render, with no
/// way out. Under a deadline, a watchdog abandons a launch still running
/// at twice the deadline: the frame fails with the deadline's error, the
/// renderer refuses further frames, and dropping it does not wait. The
/// device keeps running the endless launch until the process ends, so
/// this test runs it in a child process of its own.
#[test]
fn a_launch_that_never_ends_is_abandoned_at_the_watchdog() {
    let Some(_) = gpu::device() else { return };
    if std::env::var(ENDLESS_CHILD).is_ok() {
        let shape = CustomShape::new(
            "endless",
            &[],
            |p, _| p.length() - 1.0,
            "volatile int spin = 1;
             while (spin) {}
             return length(p) - R(1.0);",
        )
        .unwrap();
        let scene = Scene::new(shape.node::<f64>([]))
            .with_camera(Camera::look_at(dvec3(0.0, 0.0, 3.0), DVec3::ZERO));
        let deadline = Duration::from_millis(500);
        let mut renderer = Renderer::with_options(&scene, &options(None, Some(deadline))).unwrap();
        let start = Instant::now();
        let err = renderer.render(16, 12).unwrap_err();
        assert!(matches!(err, Error::Deadline { .. }), "{err}");
        assert!(
            start.elapsed() < Duration::from_secs(10),
            "{:?}",
            start.elapsed()
        );
        let again = renderer.render(16, 12).unwrap_err().to_string();
        assert!(again.contains("abandoned"), "{again}");
        drop(renderer);
        println!("endless launch abandoned after {:?}", start.elapsed());
        return;
    }
    // The test's name in its suite: its module path without the crate.
    let module = module_path!().split_once("::").map_or("", |(_, m)| m);
    let name = format!("{module}::a_launch_that_never_ends_is_abandoned_at_the_watchdog");
    let mut child = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["--exact", name.as_str(), "--nocapture", "--test-threads=1"])
        .env(ENDLESS_CHILD, "1")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > Duration::from_secs(120) {
            child.kill().unwrap();
            panic!("the child hung: the watchdog did not abandon the launch");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let out = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        status.success()
            && stdout.contains("1 passed")
            && stdout.contains("endless launch abandoned"),
        "{status:?}\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
