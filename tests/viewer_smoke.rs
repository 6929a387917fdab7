//! The viewer example in a real window on a virtual X server (Xvfb): a
//! scripted key press (`--keys h`: shadows off) and a real one (`xdotool
//! key 1`: draft quality) each change what it shows, and its screenshots
//! are not blank.
//!
//! Needs the example binary, built by `cargo build --profile test
//! --all-features --example viewer` (as `make test` does first), and
//! `Xvfb` and `xdotool` (`make setup` installs them). Without them the tests print a note and
//! pass, except under `CI=true`, where they fail.
#![cfg(feature = "viewer")]

mod gpu;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::thread::sleep;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use fractal_sdf::image::{self, RgbaImage};
use fractal_sdf::quality::Preset;
use fractal_sdf::view::{Action, Key, KeyScript};

/// How long to wait for a window, a file or an exit before failing.
const PATIENCE: Duration = Duration::from_secs(120);

fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true" || v == "1")
}

const BUILD: &str = "cargo build --profile test --all-features --example viewer";

/// The newest modification time of the file `path` or of the files under
/// it.
fn newest(path: &Path) -> SystemTime {
    if path.is_file() {
        return path
            .metadata()
            .and_then(|m| m.modified())
            .unwrap_or(UNIX_EPOCH);
    }
    std::fs::read_dir(path)
        .into_iter()
        .flatten()
        .flatten()
        .map(|entry| {
            let path = entry.path();
            if path.is_dir() {
                newest(&path)
            } else {
                entry
                    .metadata()
                    .and_then(|m| m.modified())
                    .unwrap_or(UNIX_EPOCH)
            }
        })
        .max()
        .unwrap_or(UNIX_EPOCH)
}

/// The viewer example next to this test binary (`target/PROFILE/examples`),
/// built after the last change to what it is built from: the library, the
/// kernels, the example and the examples' shared code (not the other
/// examples, whose changes cargo rightly does not rebuild it for).
fn viewer_binary() -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    let profile_dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("tests run from target/PROFILE/deps");
    let path = profile_dir.join("examples/viewer");
    let built = std::fs::metadata(&path).and_then(|m| m.modified());
    let built = built.unwrap_or_else(|_| panic!("{} is missing: run `{BUILD}`", path.display()));
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let sources = ["src", "kernels", "examples/viewer.rs", "examples/common"]
        .map(|d| newest(&root.join(d)))
        .into_iter()
        .max()
        .unwrap_or(UNIX_EPOCH);
    assert!(
        built >= sources,
        "{} is older than the sources: run `{BUILD}`",
        path.display()
    );
    path
}

/// Whether `tool` runs; if not, a note (or, in CI, a failure).
fn have(tool: &str) -> bool {
    let found = Command::new("which")
        .arg(tool)
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    assert!(found || !in_ci(), "CI=true requires `{tool}` (make setup)");
    if !found {
        eprintln!("note: skipping the viewer smoke test: `{tool}` is not installed");
    }
    found
}

/// A virtual X server on a free display, stopped when dropped.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    /// Starts a server; tests running at once pass different `slot`s.
    fn start(slot: u32) -> Xvfb {
        let first = 100 + (std::process::id() % 100) * 4 + slot * 2;
        for n in (first..first + 50).filter(|n| !Path::new(&format!("/tmp/.X{n}-lock")).exists()) {
            let display = format!(":{n}");
            let socket = format!("/tmp/.X11-unix/X{n}");
            // No lock file, so a socket left here belongs to a server that
            // is gone: remove it, or it would pass for this server's.
            let _ = std::fs::remove_file(&socket);
            let mut child = Command::new("Xvfb")
                .args([&display, "-screen", "0", "320x240x24", "-nolisten", "tcp"])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("Xvfb starts");
            let start = Instant::now();
            while start.elapsed() < Duration::from_secs(20) {
                let exited = child.try_wait().ok().flatten().is_some();
                if exited {
                    break; // that display was taken: try the next
                }
                if Path::new(&socket).exists() {
                    // Make sure the socket is this server's, not a rival's.
                    sleep(Duration::from_millis(300));
                    if child.try_wait().ok().flatten().is_none() {
                        return Xvfb { child, display };
                    }
                    break;
                }
                sleep(Duration::from_millis(50));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
        panic!("could not start Xvfb on any display from :{first}");
    }

    fn command(&self, program: impl AsRef<std::ffi::OsStr>) -> Command {
        let mut c = Command::new(program);
        c.env("DISPLAY", &self.display)
            .env_remove("WAYLAND_DISPLAY");
        c
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fractal-sdf-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Waits until `done` holds, or fails with `what`.
fn wait_for(what: &str, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(start.elapsed() < PATIENCE, "timed out waiting for {what}");
        sleep(Duration::from_millis(100));
    }
}

/// The standard deviation of the luminance: 0 for a blank image.
fn contrast(image: &RgbaImage) -> f64 {
    let lum: Vec<f64> = image
        .pixels()
        .map(|p| 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]))
        .collect();
    #[allow(clippy::cast_precision_loss)]
    let n = lum.len() as f64;
    let mean = lum.iter().sum::<f64>() / n;
    (lum.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / n).sqrt()
}

fn differing_pixels(a: &RgbaImage, b: &RgbaImage) -> usize {
    assert_eq!(a.dimensions(), b.dimensions());
    a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count()
}

fn assert_shows_the_scene(image: &RgbaImage, what: &str) {
    assert_eq!(image.dimensions(), (96, 72), "{what}");
    let c = contrast(image);
    assert!(c > 10.0, "{what} looks blank (luminance deviation {c:.1})");
}

const SCENE: [&str; 5] = ["csg", "--size", "96x72", "--quality", "preview"];

#[test]
fn scripted_keys_change_the_headless_screenshot() {
    if gpu::device().is_none() || !have("Xvfb") {
        return;
    }
    let x = Xvfb::start(0);
    let dir = scratch("viewer-keys");
    let shot = |name: &str, keys: Option<&str>| {
        let file = dir.join(name);
        let mut c = x.command(viewer_binary());
        c.args(SCENE)
            .args(["--frames", "3", "--screenshot"])
            .arg(&file);
        if let Some(k) = keys {
            c.args(["--keys", k]);
        }
        let out = c.output().expect("the viewer runs");
        assert!(
            out.status.success(),
            "viewer failed: {}\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        image::open(&file).expect("a screenshot").to_rgba8()
    };
    let plain = shot("plain.png", None);
    // `h` switches the shadows off before frame 1.
    assert_eq!(Action::for_key(Key::H), Some(Action::ToggleShadows));
    let script = KeyScript::new([(1, Key::H)]).unwrap().to_string();
    let unshadowed = shot("unshadowed.png", Some(&script));
    let again = shot("again.png", None);
    gpu::save("viewer_plain", &plain);
    gpu::save("viewer_unshadowed", &unshadowed);
    assert_shows_the_scene(&plain, "the plain screenshot");
    assert_shows_the_scene(&unshadowed, "the screenshot without shadows");
    assert_eq!(plain, again, "the same settings give the same screenshot");
    let changed = differing_pixels(&plain, &unshadowed);
    assert!(changed > 96 * 72 / 20, "`h` changed only {changed} pixels");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn real_key_presses_reach_the_window() {
    if gpu::device().is_none() || !have("Xvfb") || !have("xdotool") {
        return;
    }
    let x = Xvfb::start(1);
    let dir = scratch("viewer-xdotool");
    let mut viewer = x
        .command(viewer_binary())
        .args(SCENE)
        .arg("--shots")
        .arg(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the viewer starts");
    let xdotool = |args: &[&str]| {
        x.command("xdotool")
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .output()
            .expect("xdotool runs")
    };
    let mut window = String::new();
    wait_for("the viewer's window", || {
        if let Some(status) = viewer.try_wait().unwrap() {
            let mut said = String::new();
            if let Some(mut err) = viewer.stderr.take() {
                let _ = std::io::Read::read_to_string(&mut err, &mut said);
            }
            panic!("the viewer exited early ({status}): {said}");
        }
        let found = xdotool(&["search", "--name", "^csg "]);
        window = String::from_utf8_lossy(&found.stdout)
            .lines()
            .next()
            .unwrap_or_default()
            .to_string();
        !window.is_empty()
    });
    let key = |name: &str| {
        let focus = xdotool(&["windowfocus", "--sync", &window]);
        assert!(focus.status.success(), "xdotool windowfocus failed");
        assert!(
            xdotool(&["key", name]).status.success(),
            "xdotool key {name}"
        );
    };
    let shot = |i: u32| dir.join(format!("screenshot_{i:03}.png"));
    // xdotool takes X key names: F12, 1 and Escape are the library's
    // `Key::F12`, `Key::Digit1` and `Key::Escape`.
    assert_eq!(Action::for_key(Key::F12), Some(Action::Screenshot));
    assert_eq!(
        Action::for_key(Key::Digit1),
        Some(Action::Quality(Preset::Draft))
    );
    assert_eq!(Action::for_key(Key::Escape), Some(Action::Quit));
    key("F12");
    wait_for("the first screenshot", || shot(0).is_file());
    key("1"); // draft quality: no ambient occlusion, no shadows
    key("F12");
    wait_for("the second screenshot", || shot(1).is_file());
    key("Escape");
    let mut status = None;
    wait_for("the viewer to quit on Escape", || {
        status = viewer.try_wait().unwrap();
        status.is_some()
    });
    assert!(status.unwrap().success(), "viewer exit status {status:?}");

    let before = image::open(shot(0)).unwrap().to_rgba8();
    let after = image::open(shot(1)).unwrap().to_rgba8();
    gpu::save("viewer_key_before", &before);
    gpu::save("viewer_key_after", &after);
    assert_shows_the_scene(&before, "the screenshot before `1`");
    assert_shows_the_scene(&after, "the screenshot after `1`");
    let changed = differing_pixels(&before, &after);
    assert!(changed > 96 * 72 / 20, "`1` changed only {changed} pixels");
    std::fs::remove_dir_all(dir).unwrap();
}
