//! The viewer example in a real window on a virtual X server (Xvfb): a
//! scripted key press (`--keys h`: shadows off) and a real one (`xdotool
//! key 1`: draft quality) each change what it shows, and its screenshots
//! are not blank. A scene file it shows is reloaded when it changes, a bad
//! one is reported (stderr and the title) while the last good scene stays,
//! and a settings file's size, preset and key bindings are honoured.
//!
//! The wgpu window example (`examples/wgpu_window.rs`) likewise shows its
//! first frame.
//!
//! Needs the example binaries, built by `cargo build --profile test
//! --all-features --example viewer --example wgpu_window` (as `make test`
//! does first), and
//! `Xvfb` and `xdotool` (`make setup` installs them). Without them the tests print a note and
//! pass, except under `CI=true`, where they fail.
#![cfg(feature = "viewer")]

mod gpu;
/// Whether wgpu has an adapter here (a failure where the run requires one).
#[cfg(feature = "wgpu")]
#[path = "../src/codegen/wgsl_tests/device.rs"]
#[allow(dead_code)] // `run`, the distance tests' shader runner
mod wgpu_device;

use std::ffi::OsStr;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::sleep;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use fractal_sdf::image::{self, RgbaImage};
use fractal_sdf::quality::Preset;
use fractal_sdf::settings::CONFIG_ENV;
use fractal_sdf::view::{Action, Key, KeyBindings, KeyScript};

/// How long to wait for a window, a file or an exit before failing.
const PATIENCE: Duration = Duration::from_secs(120);

fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true" || v == "1")
}

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

/// The example `name` next to this test binary (`target/PROFILE/examples`),
/// built after the last change to `sources` (the library, the kernels,
/// the example and what it shares with others; not the other examples,
/// whose changes cargo rightly does not rebuild it for).
fn example_binary(name: &str, sources: &[&str]) -> PathBuf {
    let build = format!("cargo build --profile test --all-features --example {name}");
    let exe = std::env::current_exe().expect("the test binary's path");
    let profile_dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("tests run from target/PROFILE/deps");
    let path = profile_dir.join("examples").join(name);
    let built = std::fs::metadata(&path).and_then(|m| m.modified());
    let built = built.unwrap_or_else(|_| panic!("{} is missing: run `{build}`", path.display()));
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let sources = sources
        .iter()
        .map(|d| newest(&root.join(d)))
        .max()
        .unwrap_or(UNIX_EPOCH);
    assert!(
        built >= sources,
        "{} is older than the sources: run `{build}`",
        path.display()
    );
    path
}

/// The viewer example, built after the last change to what it is built
/// from.
fn viewer_binary() -> PathBuf {
    example_binary(
        "viewer",
        &["src", "kernels", "examples/viewer", "examples/common"],
    )
}

/// The wgpu window example, built after the last change to the library,
/// the kernels or the example.
#[cfg(feature = "wgpu")]
fn wgpu_window_binary() -> PathBuf {
    example_binary(
        "wgpu_window",
        &["src", "kernels", "examples/wgpu_window.rs"],
    )
}

/// The wgpu window example on the virtual X server: its first frame, read
/// back from the window's surface, is the picture the wgpu renderer draws
/// of the same scene into an image (the texture drawn onto the surface
/// texel for texel), and it is not blank.
#[cfg(feature = "wgpu")]
#[test]
fn the_wgpu_window_shows_the_rendered_frame() {
    if wgpu_device::device().is_none() || !have("Xvfb") {
        return;
    }
    let x = Xvfb::start();
    let dir = scratch("wgpu-window");
    let file = dir.join("first.png");
    let out = x
        .command(wgpu_window_binary())
        .args(["--frames", "3", "--screenshot"])
        .arg(&file)
        .output()
        .expect("the example runs");
    assert!(
        out.status.success(),
        "wgpu_window failed: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let shown = image::open(&file).expect("a screenshot").to_rgba8();
    gpu::save("wgpu_window_first", &shown);
    assert_eq!(shown.dimensions(), (320, 240));
    let c = contrast(&shown);
    assert!(
        c > 10.0,
        "the window looks blank (luminance deviation {c:.1})"
    );

    // The example's scene, rendered into an image.
    use fractal_sdf::prelude::*;
    let mut file = fractal_sdf::gallery::file("mandelbulb").unwrap();
    file.scene.geometry =
        Some(mandelbulb(fractal_sdf::scene::param("power", 8.0)).color(dvec3(0.85, 0.65, 0.45)));
    let mut options = fractal_sdf::render::RenderOptions::default();
    options.quality = Quality::preview().resolution_scale(1);
    options.effects = file.effects;
    let mut renderer =
        fractal_sdf::render::WgpuRenderer::from_compiled(file.scene.compile().unwrap(), &options)
            .unwrap();
    let drawn = renderer.render(320, 240).unwrap();
    let db = fractal_sdf::metrics::psnr(&shown, &drawn);
    eprintln!("the window's first frame against the image: {db:.1} dB");
    assert!(db >= 50.0, "the window shows another picture ({db:.1} dB)");
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
    /// Starts a server on the first free display from one chosen by the
    /// process id, and waits until it accepts connections (`-displayfd`
    /// reports the display then). A server refuses a display another one
    /// holds before touching its socket; servers left to pick a display
    /// themselves would probe, and disturb, the displays in use. This
    /// process starts one at a time.
    fn start() -> Xvfb {
        static STARTING: Mutex<()> = Mutex::new(());
        let _one_at_a_time = STARTING.lock().unwrap_or_else(PoisonError::into_inner);
        let first = 100 + (std::process::id() % 100) * 4;
        for n in first..first + 100 {
            let mut child = Command::new("Xvfb")
                .arg(format!(":{n}"))
                .args(["-displayfd", "1", "-screen", "0", "320x240x24"])
                // -noreset: a server resets when its last client leaves,
                // and a client connecting meanwhile (the viewer, while
                // xdotool looks for its window) is refused.
                .args(["-nolisten", "tcp", "-noreset"])
                .stdout(Stdio::piped())
                .stderr(Stdio::null())
                .spawn()
                .expect("Xvfb starts");
            let stdout = child.stdout.take().expect("piped");
            let (tx, rx) = std::sync::mpsc::channel();
            std::thread::spawn(move || {
                let mut stdout = BufReader::new(stdout);
                let mut line = String::new();
                let _ = stdout.read_line(&mut line);
                let _ = tx.send(line);
                // Keep reading: a closed pipe would kill the server with
                // SIGPIPE should it write again.
                let _ = std::io::copy(&mut stdout, &mut std::io::sink());
            });
            // The display, once the server is ready; nothing if it gave up
            // (the display is taken).
            let ready = rx.recv_timeout(Duration::from_secs(30)).unwrap_or_default();
            if ready.trim() == n.to_string() {
                return Xvfb {
                    child,
                    display: format!(":{n}"),
                };
            }
            let _ = child.kill();
            let _ = child.wait();
        }
        panic!("could not start Xvfb on any display from :{first}");
    }

    /// `program` on this display, with no settings file (the user's own
    /// must not change what the viewer does).
    fn command(&self, program: impl AsRef<OsStr>) -> Command {
        let mut c = Command::new(program);
        c.env("DISPLAY", &self.display)
            .env_remove("WAYLAND_DISPLAY")
            .env(CONFIG_ENV, no_settings());
        c
    }

    fn xdotool(&self, args: &[&str]) -> Output {
        self.command("xdotool")
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .output()
            .expect("xdotool runs")
    }
}

impl Drop for Xvfb {
    /// Stops the server with SIGTERM, so that it removes its lock file and
    /// socket (SIGKILL would leave them behind).
    fn drop(&mut self) {
        let _ = Command::new("kill")
            .args(["-TERM", &self.child.id().to_string()])
            .status();
        let start = Instant::now();
        while self.child.try_wait().ok().flatten().is_none() {
            if start.elapsed() > Duration::from_secs(5) {
                let _ = self.child.kill();
                break;
            }
            sleep(Duration::from_millis(20));
        }
        let _ = self.child.wait();
    }
}

/// A settings file that does not exist: every default.
fn no_settings() -> PathBuf {
    std::env::temp_dir().join(format!(
        "fractal-sdf-no-settings-{}/config.toml",
        std::process::id()
    ))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fractal-sdf-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
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

/// Everything a pipe says, collected by a thread as it comes.
fn collect(pipe: impl Read + Send + 'static) -> Arc<Mutex<String>> {
    let text = Arc::new(Mutex::new(String::new()));
    let sink = Arc::clone(&text);
    std::thread::spawn(move || {
        for line in BufReader::new(pipe).lines() {
            let Ok(line) = line else { break };
            let mut sink = sink.lock().unwrap();
            sink.push_str(&line);
            sink.push('\n');
        }
    });
    text
}

/// The viewer in a window, with what it prints on stdout and stderr;
/// killed when dropped.
struct Running<'x> {
    x: &'x Xvfb,
    child: Child,
    stdout: Arc<Mutex<String>>,
    stderr: Arc<Mutex<String>>,
    window: String,
}

impl<'x> Running<'x> {
    /// Starts the viewer with `args` (and `env`), and waits for its window,
    /// whose title begins with `title`.
    fn start(x: &'x Xvfb, args: &[&OsStr], env: &[(&str, &OsStr)], title: &str) -> Self {
        let mut command = x.command(viewer_binary());
        command
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        for (name, value) in env {
            command.env(name, value);
        }
        let mut child = command.spawn().expect("the viewer starts");
        let stdout = collect(child.stdout.take().expect("piped"));
        let stderr = collect(child.stderr.take().expect("piped"));
        let mut running = Running {
            x,
            child,
            stdout,
            stderr,
            window: String::new(),
        };
        let pattern = format!("^{} ", title.replace('.', "\\."));
        let mut window = String::new();
        running.wait_for("the viewer's window", |r| {
            let found = r.x.xdotool(&["search", "--name", &pattern]);
            window = String::from_utf8_lossy(&found.stdout)
                .lines()
                .next()
                .unwrap_or_default()
                .to_string();
            !window.is_empty()
        });
        running.window = window;
        running
    }

    fn stdout(&self) -> String {
        self.stdout.lock().unwrap().clone()
    }

    fn stderr(&self) -> String {
        self.stderr.lock().unwrap().clone()
    }

    /// Waits until `done` holds, failing at once if the viewer exits.
    fn wait_for(&mut self, what: &str, mut done: impl FnMut(&Self) -> bool) {
        let start = Instant::now();
        while !done(self) {
            if let Some(status) = self.child.try_wait().unwrap() {
                sleep(Duration::from_millis(200)); // the pipes' last words
                panic!(
                    "the viewer on {} exited ({status}) while waiting for {what}:\n{}\n{}",
                    self.x.display,
                    self.stdout(),
                    self.stderr()
                );
            }
            assert!(
                start.elapsed() < PATIENCE,
                "timed out waiting for {what}:\n{}\n{}",
                self.stdout(),
                self.stderr()
            );
            sleep(Duration::from_millis(50));
        }
    }

    /// Presses `name` (an X key name) in the focused window.
    fn key(&self, name: &str) {
        let focus = self.x.xdotool(&["windowfocus", "--sync", &self.window]);
        assert!(focus.status.success(), "xdotool windowfocus failed");
        assert!(
            self.x.xdotool(&["key", name]).status.success(),
            "xdotool key {name}"
        );
    }

    /// The window's title.
    fn title(&self) -> String {
        let out = self.x.xdotool(&["getwindowname", &self.window]);
        String::from_utf8_lossy(&out.stdout).trim().to_string()
    }

    /// Presses `key` (the screenshot key) and reads the screenshot saved
    /// as `DIR/screenshot_NNN.png` number `n`.
    fn screenshot(&mut self, key: &str, dir: &Path, n: u32) -> RgbaImage {
        let path = dir.join(format!("screenshot_{n:03}.png"));
        self.key(key);
        let said = format!("screenshot -> {}", path.display());
        self.wait_for(&format!("screenshot {n}"), |r| r.stdout().contains(&said));
        image::open(&path).expect("a screenshot").to_rgba8()
    }

    /// Presses `key` and waits for the viewer to exit.
    fn quit_with(&mut self, key: &str) -> ExitStatus {
        self.key(key);
        let start = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                return status;
            }
            assert!(
                start.elapsed() < PATIENCE,
                "the viewer did not quit on {key}"
            );
            sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Running<'_> {
    fn drop(&mut self) {
        if self.child.try_wait().ok().flatten().is_none() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

fn differing_pixels(a: &RgbaImage, b: &RgbaImage) -> usize {
    assert_eq!(a.dimensions(), b.dimensions());
    a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count()
}

fn assert_shows_the_scene(image: &RgbaImage, what: &str) {
    assert_shows_the_scene_by(image, what, 10.0);
}

/// `image` deviates by more than `least` levels of luminance. A blank
/// image deviates by the sky's gradient alone, a few levels.
fn assert_shows_the_scene_by(image: &RgbaImage, what: &str, least: f64) {
    assert_eq!(image.dimensions(), (96, 72), "{what}");
    let c = contrast(image);
    assert!(c > least, "{what} looks blank (luminance deviation {c:.1})");
}

const SCENE: [&str; 5] = ["csg", "--size", "96x72", "--quality", "preview"];

#[test]
fn scripted_keys_change_the_headless_screenshot() {
    if gpu::device().is_none() || !have("Xvfb") {
        return;
    }
    let x = Xvfb::start();
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
    // `v` twice: side-by-side stereo, two 48 × 72 eyes that see the scene
    // from a little apart.
    assert_eq!(Action::for_key(Key::V), Some(Action::CycleStereo));
    let script = KeyScript::new([(1, Key::V), (1, Key::V)])
        .unwrap()
        .to_string();
    let pair = shot("pair.png", Some(&script));
    gpu::save("viewer_side_by_side", &pair);
    assert_shows_the_scene(&pair, "the side-by-side screenshot");
    let half = |x| image::imageops::crop_imm(&pair, x, 0, 48, 72).to_image();
    let (left, right) = (half(0), half(48));
    let apart = differing_pixels(&left, &right);
    assert!(
        apart > 48 * 72 / 50 && contrast(&left) > 10.0 && contrast(&right) > 10.0,
        "two eyes, each showing the scene from its side: {apart} pixels differ"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--backend wgpu`: the viewer draws with the wgpu backend the picture it
/// draws with OpenCL, and its keys work there too (`v` twice: a
/// side-by-side stereo pair).
#[test]
fn the_viewer_draws_on_the_wgpu_backend() {
    if gpu::device().is_none() || wgpu_device::device().is_none() || !have("Xvfb") {
        return;
    }
    let x = Xvfb::start();
    let dir = scratch("viewer-wgpu");
    let shot = |name: &str, extra: &[&str]| {
        let file = dir.join(name);
        let out = x
            .command(viewer_binary())
            .args(SCENE)
            .args(["--frames", "3", "--screenshot"])
            .arg(&file)
            .args(extra)
            .output()
            .expect("the viewer runs");
        assert!(
            out.status.success(),
            "viewer failed: {}\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        (
            image::open(&file).expect("a screenshot").to_rgba8(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
        )
    };
    let (opencl, _) = shot("opencl.png", &["--backend", "opencl"]);
    let (drawn, said) = shot("wgpu.png", &["--backend", "wgpu"]);
    assert!(said.contains("(wgpu)"), "{said}");
    gpu::save("viewer_wgpu", &drawn);
    assert_shows_the_scene(&drawn, "the wgpu screenshot");
    let db = fractal_sdf::metrics::psnr(&opencl, &drawn);
    assert!(db >= 60.0, "{db:.1} dB between the backends' screenshots");
    let script = KeyScript::new([(1, Key::V), (1, Key::V)])
        .unwrap()
        .to_string();
    let (pair, _) = shot("pair.png", &["--backend", "wgpu", "--keys", &script]);
    let half = |x| image::imageops::crop_imm(&pair, x, 0, 48, 72).to_image();
    let apart = differing_pixels(&half(0), &half(48));
    assert!(
        apart > 48 * 72 / 50 && contrast(&half(0)) > 10.0,
        "two eyes on wgpu: {apart} pixels differ"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn real_key_presses_reach_the_window() {
    if gpu::device().is_none() || !have("Xvfb") || !have("xdotool") {
        return;
    }
    let x = Xvfb::start();
    let dir = scratch("viewer-xdotool");
    let mut args: Vec<&OsStr> = SCENE.iter().map(OsStr::new).collect();
    args.extend([OsStr::new("--shots"), dir.as_os_str()]);
    let mut viewer = Running::start(&x, &args, &[], "csg");
    // xdotool takes X key names: F12, 1 and Escape are the library's
    // `Key::F12`, `Key::Digit1` and `Key::Escape`.
    assert_eq!(Action::for_key(Key::F12), Some(Action::Screenshot));
    assert_eq!(
        Action::for_key(Key::Digit1),
        Some(Action::Quality(Preset::Draft))
    );
    assert_eq!(Action::for_key(Key::Escape), Some(Action::Quit));
    let before = viewer.screenshot("F12", &dir, 0);
    viewer.key("1"); // draft quality: no ambient occlusion, no shadows
    let after = viewer.screenshot("F12", &dir, 1);
    let status = viewer.quit_with("Escape");
    assert!(status.success(), "viewer exit status {status:?}");

    gpu::save("viewer_key_before", &before);
    gpu::save("viewer_key_after", &after);
    assert_shows_the_scene(&before, "the screenshot before `1`");
    assert_shows_the_scene(&after, "the screenshot after `1`");
    let changed = differing_pixels(&before, &after);
    assert!(changed > 96 * 72 / 20, "`1` changed only {changed} pixels");
    std::fs::remove_dir_all(dir).unwrap();
}

/// The camera of the scene files.
const CAMERA: &str = "(position: (0, 0.8, 4), target: (0, -0.2, 0))";

/// A scene file: `geometry` on one line (the file's third), seen from
/// `camera`, at draft quality.
fn scene_text_from(geometry: &str, camera: &str) -> String {
    format!(
        "(
    version: 1,
    geometry: {geometry},
    camera: {camera},
    quality: (preset: Draft),
)
"
    )
}

/// A scene file: `geometry` seen from [`CAMERA`].
fn scene_text(geometry: &str) -> String {
    scene_text_from(geometry, CAMERA)
}

/// A sphere of dynamic radius `radius` (orange) on a grey floor.
fn sphere_geometry(radius: f64) -> String {
    format!(
        "Union([Color(color: (0.95, 0.45, 0.2), child: Sphere(radius: param(\"radius\", {radius}))), \
         Color(color: (0.55, 0.55, 0.6), child: Plane(normal: (0, 1, 0), offset: 1))])"
    )
}

/// The sphere of [`sphere_geometry`] seen from [`CAMERA`].
fn sphere_scene(radius: f64) -> String {
    scene_text(&sphere_geometry(radius))
}

/// How many times the viewer has reloaded its scene file.
fn reloads(viewer: &Running) -> usize {
    viewer.stdout().matches("reloaded ").count()
}

/// Replaces the file at `path` with `text` at once (written beside it,
/// then renamed), as editors that save safely do.
fn replace(path: &Path, text: &str) {
    let temporary = path.with_extension("ron.tmp");
    std::fs::write(&temporary, text).unwrap();
    std::fs::rename(&temporary, path).unwrap();
}

#[test]
fn an_edited_scene_file_is_reloaded_and_a_bad_one_reported() {
    if gpu::device().is_none() || !have("Xvfb") || !have("xdotool") {
        return;
    }
    let x = Xvfb::start();
    let dir = scratch("viewer-reload");
    let file = dir.join("scene.ron");
    std::fs::write(&file, sphere_scene(1.0)).unwrap();
    let args = [
        file.as_os_str(),
        OsStr::new("--size"),
        OsStr::new("96x72"),
        OsStr::new("--shots"),
        dir.as_os_str(),
    ];
    let mut viewer = Running::start(&x, &args, &[], "scene.ron");
    let mut shots = 0..;
    // The smallest view here, a sphere seen from afar with its edges
    // smoothed by the window's progressive passes, deviates by 9.
    let mut shot = |viewer: &mut Running, name: &str| {
        let image = viewer.screenshot("F12", &dir, shots.next().unwrap());
        gpu::save(&format!("viewer_reload_{name}"), &image);
        assert_shows_the_scene_by(&image, name, 6.0);
        image
    };
    let big = shot(&mut viewer, "big_sphere");
    viewer.wait_for("the file's quality in the title", |r| {
        r.title().contains("| draft, ")
    });

    // A new default of a dynamic parameter: the same program.
    replace(&file, &sphere_scene(0.6));
    viewer.wait_for("the first reload", |r| reloads(r) == 1);
    assert!(
        viewer.stdout().contains("(same program in"),
        "{}",
        viewer.stdout()
    );
    let small = shot(&mut viewer, "small_sphere");
    let changed = differing_pixels(&big, &small);
    assert!(
        changed > 96 * 72 / 20,
        "the radius changed {changed} pixels"
    );

    // Another camera: the view moves to it, with the same program.
    let aside = "(position: (2.5, 2, 2.5), target: (0, -0.2, 0))";
    replace(&file, &scene_text_from(&sphere_geometry(0.6), aside));
    viewer.wait_for("the second reload", |r| reloads(r) == 2);
    assert_eq!(viewer.stdout().matches("(same program in").count(), 2);
    let moved = shot(&mut viewer, "camera_moved");
    let changed = differing_pixels(&small, &moved);
    assert!(
        changed > 96 * 72 / 20,
        "the camera changed {changed} pixels"
    );

    // Another shape: another program.
    replace(
        &file,
        &scene_text(
            "Union([Color(color: (0.2, 0.5, 0.95), child: Cuboid(half_extents: (0.7, 0.7, 0.7))), \
             Color(color: (0.55, 0.55, 0.6), child: Plane(normal: (0, 1, 0), offset: 1))])",
        ),
    );
    viewer.wait_for("the third reload", |r| reloads(r) == 3);
    assert!(
        viewer.stdout().contains("(new program in"),
        "{}",
        viewer.stdout()
    );
    let cube = shot(&mut viewer, "cube");
    let changed = differing_pixels(&moved, &cube);
    assert!(changed > 96 * 72 / 10, "the cube changed {changed} pixels");

    // A syntax error, then a value that does not validate, each on line
    // 3: reported with the file, line and column; the cube stays.
    for (n, (geometry, says)) in [
        ("Sphere(radius 1)", ""),
        (
            "Sphere(radius: -1)",
            "sphere: parameter `radius` must be >= 0",
        ),
    ]
    .into_iter()
    .enumerate()
    {
        replace(&file, &scene_text(geometry));
        let place = format!("{}:3:", file.display());
        viewer.wait_for(&format!("error {n} on stderr"), |r| {
            r.stderr().matches(&place).count() == n + 1
        });
        let said = viewer.stderr();
        let error = said.lines().rfind(|l| l.contains(&place)).unwrap();
        assert!(error.starts_with(&format!("error: {place}")), "{error}");
        assert!(error.contains(says), "{error}");
        viewer.wait_for(&format!("error {n} in the title"), |r| {
            let title = r.title();
            title.starts_with("scene.ron | ERROR scene.ron:3:") && title.contains(says)
        });
        let still = shot(&mut viewer, &format!("still_cube_{n}"));
        let changed = differing_pixels(&cube, &still);
        assert!(
            changed <= 96 * 72 / 100,
            "a bad file changed {changed} pixels"
        );
    }
    assert_eq!(reloads(&viewer), 3, "bad files are not reloads");

    // A good file again: the error is gone and the sphere is back.
    replace(&file, &sphere_scene(1.0));
    viewer.wait_for("the recovery", |r| reloads(r) == 4);
    viewer.wait_for("the title without the error", |r| {
        let title = r.title();
        title.starts_with("scene.ron | ") && !title.contains("ERROR")
    });
    let again = shot(&mut viewer, "recovered");
    let changed = differing_pixels(&big, &again);
    assert!(
        changed <= 96 * 72 / 100,
        "the sphere came back changed in {changed} pixels"
    );
    let status = viewer.quit_with("Escape");
    assert!(status.success(), "viewer exit status {status:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn the_settings_file_sets_the_size_preset_and_keys() {
    if gpu::device().is_none() || !have("Xvfb") || !have("xdotool") {
        return;
    }
    let x = Xvfb::start();
    let dir = scratch("viewer-settings");
    let settings = dir.join("config.toml");
    std::fs::write(
        &settings,
        "size = \"96x72\"\npreset = \"draft\"\n\n[viewer.keys]\nquit = \"x\"\nscreenshot = \"p\"\n",
    )
    .unwrap();
    let keys = KeyBindings::from_names([("quit", "x"), ("screenshot", "p")]).unwrap();
    assert_eq!(keys.action(Key::Escape), None);
    let args = [OsStr::new("csg"), OsStr::new("--shots"), dir.as_os_str()];
    let env = [(CONFIG_ENV, settings.as_os_str())];
    let mut viewer = Running::start(&x, &args, &env, "csg");
    // Escape quits no more; `p` saves a screenshot, twice (the second
    // comes after Escape has surely been handled).
    viewer.key("Escape");
    let first = viewer.screenshot("p", &dir, 0);
    let second = viewer.screenshot("p", &dir, 1);
    assert_shows_the_scene(&first, "the screenshot at the settings' size");
    assert_eq!(first, second);
    viewer.wait_for("the settings' preset in the title", |r| {
        r.title().contains("| draft, ")
    });
    let status = viewer.quit_with("x");
    assert!(status.success(), "viewer exit status {status:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_key_bindings_are_refused_with_the_reason() {
    if gpu::device().is_none() {
        return;
    }
    let dir = scratch("viewer-bad-settings");
    let settings = dir.join("config.toml");
    // `q` moves the camera down.
    std::fs::write(&settings, "[viewer.keys]\nquit = \"q\"\n").unwrap();
    let out = Command::new(viewer_binary())
        .args(["csg", "--frames", "1"])
        .env(CONFIG_ENV, &settings)
        .output()
        .expect("the viewer runs");
    let said = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{said}");
    assert!(said.contains(&settings.display().to_string()), "{said}");
    assert!(said.contains("`quit`: `q` moves the camera"), "{said}");
    std::fs::remove_dir_all(dir).unwrap();
}
