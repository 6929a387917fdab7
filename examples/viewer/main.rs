//! An interactive window on a gallery scene or a scene file.
//!
//! `cargo run --release --features viewer --example viewer -- fractal_mix`
//! `cargo run --release --features viewer --example viewer -- my_scene.ron`
//!
//! A scene file (`.ron`, see `fractal_sdf::file::SceneFile`) brings its
//! quality, effects and motions, and is reloaded whenever it changes on
//! disk (polled: its modification time and size): a good file replaces the
//! scene (keeping the program when only parameter defaults or the lights
//! changed, and the view's camera unless the file's changed), a bad one is
//! reported on stderr and in the title while the last good scene stays.
//! The user's settings file (`fractal_sdf::settings`) sets the defaults and
//! the key bindings; command-line options override it.
//!
//! The camera, keys, settings and resolution choice live in the library
//! (`fractal_sdf::view`); this file only connects them to a `winit` window
//! and a `softbuffer` surface. Run with `--help` for every option.

mod backend;
#[path = "../common/mod.rs"]
mod common;
mod config;

use backend::*;
use config::*;

use std::num::NonZeroU32;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::time::{Duration, Instant, SystemTime};

use fractal_sdf::animation::Motion;
use fractal_sdf::codegen;
use fractal_sdf::file::SceneFile;
use fractal_sdf::ir::CompiledScene;
use fractal_sdf::ir::ParamLayout;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Preset;
use fractal_sdf::render::{DeviceSelector, RenderOptions, Renderer};
use fractal_sdf::scene::{Stereo, StereoLayout};
use fractal_sdf::settings::Settings;
use fractal_sdf::view::{
    Action, FlyCamera, Key, KeyBindings, KeyScript, Movement, ResolutionScaler, ViewSettings,
    blit_scaled, reduced_size,
};
use fractal_sdf::{gallery, output};
use image::RgbaImage;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

/// The progressive passes a still view is refined by (see
/// `Renderer::render_progressive`).
const REFINE_PASSES: u32 = 64;

/// How often a scene file's modification time and size are checked.
const POLL: Duration = Duration::from_millis(250);

/// The longest error message the title shows.
const TITLE_ERROR_CHARS: usize = 120;

/// What tells a file's versions apart without reading it.
type Stamp = (SystemTime, u64);

/// The window and its pixel surface, created once the event loop runs.
struct Surface {
    window: Rc<Window>,
    pixels: softbuffer::Surface<Rc<Window>, Rc<Window>>,
}

struct Viewer {
    args: Args,
    /// The window size asked for.
    size: (u32, u32),
    bindings: KeyBindings,
    script: KeyScript,
    /// The scene's name in the title: the gallery name or the file name.
    name: String,
    scene: Scene,
    motions: Vec<Motion>,
    /// The scene file, when the scene comes from one.
    watched: Option<Watched>,
    renderer: Backend,
    fly: FlyCamera,
    keys: Movement,
    settings: ViewSettings,
    scaler: ResolutionScaler,
    surface: Option<Surface>,
    /// The last rendered image, kept to re-present and to save.
    image: Option<RgbaImage>,
    /// Whether `image` is full size.
    image_sharp: bool,
    /// The size of `image`, for the title.
    image_size: (u32, u32),
    last_tick: Instant,
    /// The last tick found nothing to do, and the loop slept.
    idle: bool,
    anim_time: f64,
    animating: bool,
    /// Something other than time changed since the last frame.
    changed: bool,
    dragging: bool,
    cursor: Option<(f64, f64)>,
    frame: u64,
    /// The frame whose scripted keys were pressed last.
    scripted: Option<u64>,
    smoothed_ms: f64,
    screenshot_wanted: bool,
    result: Result<()>,
}

impl Viewer {
    fn new(config: Config) -> Result<Self> {
        let Config {
            args,
            size,
            settings_preset,
            device,
            backend,
            sensitivity,
            bindings,
            script,
        } = config;
        let mut settings = ViewSettings::default();
        let (name, scene, motions, watched) = if is_scene_file(&args.scene) {
            let path = PathBuf::from(&args.scene);
            // The stamp first: a change while the file is read is seen.
            let stamp = stamp(&path);
            let file = SceneFile::load(&path)?;
            match file.quality {
                Some(quality) => settings.take_quality(quality),
                None => {
                    if let Some(preset) = settings_preset {
                        settings.apply(Action::Quality(preset));
                    }
                }
            }
            settings.take_effects(file.effects);
            let name = path
                .file_name()
                .map_or_else(|| args.scene.clone(), |n| n.to_string_lossy().into_owned());
            let watched = Watched {
                path,
                stamp,
                next_check: Instant::now() + POLL,
                good: file.clone(),
                error: None,
            };
            (name, file.scene, file.motions, Some(watched))
        } else {
            let scene = common::gallery_scene(&args.scene)?;
            if let Some(preset) = settings_preset {
                settings.apply(Action::Quality(preset));
            }
            (
                args.scene.clone(),
                scene,
                gallery::motions(&args.scene),
                None,
            )
        };
        // The command line over the scene file and the settings.
        if let Some(preset) = args.preset {
            settings.apply(Action::Quality(preset));
        }
        settings.ambient_occlusion &= !args.no_ao;
        settings.shadows &= !args.no_shadows;
        settings.glow |= args.glow;
        let renderer = Backend::new(
            backend,
            scene.compile()?,
            &RenderOptions::default()
                .quality(settings.quality())
                .effects(settings.effects())
                .device(device),
        )?;
        println!(
            "{name}: {} on {} (build {:.0} ms)",
            settings.summary(),
            renderer.label(),
            renderer.build_time().as_secs_f64() * 1e3
        );
        let mut fly = FlyCamera::from_camera(&scene.camera);
        fly.sensitivity = sensitivity;
        if let Some(speed) = args.speed {
            fly.speed = speed;
        }
        Ok(Viewer {
            scaler: ResolutionScaler::new(args.target, args.max_divisor),
            animating: !motions.is_empty(),
            args,
            size,
            bindings,
            script,
            name,
            scene,
            motions,
            watched,
            renderer,
            fly,
            keys: Movement::default(),
            settings,
            surface: None,
            image: None,
            image_sharp: false,
            image_size: size,
            last_tick: Instant::now(),
            idle: false,
            anim_time: 0.0,
            changed: true,
            dragging: false,
            cursor: None,
            frame: 0,
            scripted: None,
            smoothed_ms: 0.0,
            screenshot_wanted: false,
            result: Ok(()),
        })
    }

    fn headless(&self) -> bool {
        self.args.frames.is_some()
    }

    /// The fly camera at `camera`, keeping the mouse sensitivity (and the
    /// speed given on the command line).
    fn fly_from(&self, camera: &Camera) -> FlyCamera {
        let mut fly = FlyCamera::from_camera(camera);
        fly.sensitivity = self.fly.sensitivity;
        if let Some(speed) = self.args.speed {
            fly.speed = speed;
        }
        fly
    }

    /// Applies a key's action.
    fn act(&mut self, action: Action, event_loop: &ActiveEventLoop) -> Result<()> {
        match action {
            Action::ToggleAnimation => {
                self.animating ^= true;
                self.changed = true;
            }
            Action::ResetCamera => {
                let mut fly = FlyCamera::from_camera(&self.scene.camera);
                fly.speed = self.fly.speed;
                fly.sensitivity = self.fly.sensitivity;
                self.fly = fly;
                self.changed = true;
            }
            Action::Screenshot => self.screenshot_wanted = true,
            Action::Quit => event_loop.exit(),
            _ => {
                if self.settings.apply(action) {
                    let t = Instant::now();
                    let (quality, effects) = (self.settings.quality(), self.settings.effects());
                    let cached = self.renderer.set_options(quality, effects)?;
                    println!(
                        "{} ({} in {:.0} ms)",
                        self.settings.summary(),
                        if cached {
                            "cached program"
                        } else {
                            "new program"
                        },
                        t.elapsed().as_secs_f64() * 1e3
                    );
                    self.changed = true;
                }
            }
        }
        Ok(())
    }

    /// Checks the scene file, at most every [`POLL`], and reloads it when
    /// its modification time or size changed. A file that fails to load
    /// is reported and the last good scene stays; the next change retries
    /// (so a half-written file is reported, then read again once it is
    /// complete).
    fn check_file(&mut self) {
        let Some(watched) = self.watched.as_mut() else {
            return;
        };
        let now = Instant::now();
        if now < watched.next_check {
            return;
        }
        watched.next_check = now + POLL;
        let stamp = stamp(&watched.path);
        if stamp == watched.stamp {
            return;
        }
        watched.stamp = stamp;
        let t = Instant::now();
        let outcome = self.reload();
        let watched = self.watched.as_mut().expect("checked above");
        match outcome {
            Ok(how) => {
                watched.error = None;
                println!(
                    "reloaded {}: {} ({how} in {:.0} ms)",
                    watched.path.display(),
                    self.settings.summary(),
                    t.elapsed().as_secs_f64() * 1e3
                );
            }
            Err(e) => {
                eprintln!("error: {e}");
                watched.error = Some(title_error(&e));
            }
        }
        self.set_title();
    }

    /// Reads the scene file again and shows it; returns how the program
    /// was obtained. On an error nothing the viewer shows has changed.
    fn reload(&mut self) -> Result<&'static str> {
        let watched = self.watched.as_ref().expect("a scene file");
        let file = SceneFile::load(&watched.path)?;
        let old = &watched.good;
        // What the file changes replaces what the user chose; the rest
        // (keys pressed, the camera flown) stays.
        let mut settings = self.settings;
        if file.quality != old.quality
            && let Some(quality) = file.quality
        {
            settings.take_quality(quality);
        }
        if file.effects != old.effects {
            settings.take_effects(file.effects);
        }
        let fly = if file.scene.camera == old.scene.camera {
            self.fly
        } else {
            self.fly_from(&file.scene.camera)
        };
        let compiled = file.scene.compile()?;
        let (quality, effects) = (settings.quality(), settings.effects());
        let same_program = self.renderer.runs(&compiled, quality, effects)?;
        let mut fresh = None;
        let how = if same_program && update_in_place(&mut self.renderer, &compiled).is_ok() {
            "same program"
        } else {
            let options = self
                .renderer
                .options()
                .clone()
                .quality(quality)
                .effects(effects);
            let r = fresh.insert(self.renderer.another(compiled, &options)?);
            if r.cached() {
                "cached program"
            } else {
                "new program"
            }
        };
        let renderer = fresh.as_mut().unwrap_or(&mut self.renderer);
        // Options that leave the program as it is take it from the cache.
        renderer.set_options(quality, effects)?;
        renderer.set_camera(fly.camera(&file.scene.camera))?;
        for motion in &file.motions {
            for (name, value) in motion.values(self.anim_time) {
                renderer.set_param(&name, value)?;
            }
        }
        if let Some(r) = fresh {
            self.renderer = r;
            self.scaler.invalidate();
        }
        self.settings = settings;
        self.fly = fly;
        if self.motions.is_empty() && !file.motions.is_empty() {
            self.animating = true;
        }
        self.motions.clone_from(&file.motions);
        self.scene = file.scene.clone();
        self.watched.as_mut().expect("a scene file").good = file;
        self.changed = true;
        Ok(how)
    }

    /// One turn of the game loop, after the window's input was delivered:
    /// update the scene, render, present.
    fn tick(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let now = Instant::now();
        // Unattended runs advance a fixed 1/30 s per frame, so they are
        // repeatable; interactive ones follow the clock.
        let dt = if self.headless() {
            1.0 / 30.0
        } else if self.idle {
            0.0 // waking up: no time has passed for the scene
        } else {
            (now - self.last_tick).as_secs_f64().min(0.25)
        };
        self.last_tick = now;
        if !self.headless() {
            self.check_file();
        }
        // Scripted keys for the coming frame, once even if a tick draws
        // nothing.
        if self.scripted != Some(self.frame) {
            self.scripted = Some(self.frame);
            let script: Vec<Action> = self
                .script
                .keys_at(self.frame)
                .filter_map(|k| self.bindings.action(k))
                .collect();
            for action in script {
                self.act(action, event_loop)?;
            }
        }

        // Update: camera and animated parameters.
        let moved = self.fly.advance(self.keys, dt);
        if self.animating {
            self.anim_time += dt;
            for motion in &self.motions {
                for (name, value) in motion.values(self.anim_time) {
                    self.renderer.set_param(&name, value)?;
                }
            }
        }
        let changing = moved || self.changed || (self.animating && !self.motions.is_empty());
        self.changed = false;
        // A camera set again restarts the progressive passes: only a new
        // one is handed over.
        let camera = self.fly.camera(&self.scene.camera);
        if self.renderer.camera() != &camera {
            self.renderer.set_camera(camera)?;
        }

        // Render at the chosen resolution (always full size unattended),
        // then, while the view stays still, refine it pass by pass.
        let divisor = if self.headless() {
            Some(1)
        } else {
            self.scaler.next(changing).or(self.refining().then_some(1))
        };
        let (width, height) = self.window_size();
        if let Some(d) = divisor {
            let (w, h) = reduced_size(width, height, d);
            let image = self.draw(w, h, d == 1)?;
            let took = self.renderer.last_frame_time();
            self.scaler.record(d, took);
            self.smoothed_ms = if self.frame == 0 {
                took.as_secs_f64() * 1e3
            } else {
                0.8 * self.smoothed_ms + 0.2 * took.as_secs_f64() * 1e3
            };
            self.image = Some(image);
            self.image_sharp = d == 1;
            self.image_size = (w, h);
            self.frame += 1;
            self.present()?;
            self.set_title();
        }

        if self.screenshot_wanted {
            self.screenshot_wanted = false;
            let path = next_free(&self.args.shots);
            self.save_sharp(&path)?;
            println!("screenshot -> {}", path.display());
        }
        if let Some(n) = self.args.frames
            && self.frame >= n
        {
            if let Some(path) = self.args.screenshot.clone() {
                self.save_sharp(&path)?;
                println!("{n} frames -> {}", path.display());
            }
            event_loop.exit();
        }
        let busy = self.headless()
            || changing
            || self.keys.is_moving()
            || divisor.is_some()
            || self.refining();
        self.idle = !busy;
        event_loop.set_control_flow(match &self.watched {
            _ if busy => ControlFlow::Poll,
            // Wake up to look at the scene file.
            Some(watched) => ControlFlow::WaitUntil(watched.next_check),
            None => ControlFlow::Wait,
        });
        Ok(())
    }

    /// Whether the still view has more progressive passes to add: the
    /// full-size image is up, in one eye, short of [`REFINE_PASSES`].
    fn refining(&self) -> bool {
        let supersampling = self.renderer.options().quality.supersampling.max(1);
        let most = (Renderer::MAX_PROGRESSIVE_SAMPLES / supersampling.pow(2)).max(1);
        !self.headless()
            && self.image_sharp
            && self.settings.stereo.is_none()
            && self.renderer.progressive_passes() < REFINE_PASSES.min(most)
    }

    /// Renders a `w` × `h` view: both eyes laid out in it with stereo on,
    /// else the next progressive pass of a full-size (`sharp`) view in an
    /// interactive window, else a frame of its own.
    fn draw(&mut self, w: u32, h: u32, sharp: bool) -> Result<RgbaImage> {
        match self.settings.stereo {
            Some(layout) => {
                let (ew, eh) = match layout {
                    StereoLayout::Anaglyph => (w, h),
                    StereoLayout::SideBySide => ((w / 2).max(1), h),
                    _ => (w, (h / 2).max(1)),
                };
                self.renderer.render_stereo(ew, eh, &Stereo::new(layout))
            }
            None if sharp && !self.headless() => self.renderer.render_progressive(w, h),
            None => self.renderer.render(w, h),
        }
    }

    /// Saves the current view at full size (rendering it if the last frame
    /// was reduced) and, in a window, with every progressive pass.
    fn save_sharp(&mut self, path: &Path) -> Result<()> {
        let (w, h) = self.window_size();
        if !self.image_sharp || self.image.is_none() {
            self.image = Some(self.draw(w, h, true)?);
            self.image_sharp = true;
            self.image_size = (w, h);
            self.present()?;
        }
        // The view refined to the end, whenever the key came.
        while self.refining() {
            self.image = Some(self.draw(w, h, true)?);
        }
        self.present()?;
        output::save_png(self.image.as_ref().expect("rendered above"), path)
    }

    fn window_size(&self) -> (u32, u32) {
        self.surface
            .as_ref()
            .map(|s| s.window.inner_size())
            .filter(|s| s.width > 0 && s.height > 0)
            .map_or(self.size, |s| (s.width, s.height))
    }

    fn present(&mut self) -> Result<()> {
        let (width, height) = self.window_size();
        let (Some(surface), Some(image)) = (self.surface.as_mut(), self.image.as_ref()) else {
            return Ok(());
        };
        let (Some(w), Some(h)) = (NonZeroU32::new(width), NonZeroU32::new(height)) else {
            return Ok(());
        };
        surface.pixels.resize(w, h).map_err(display_error)?;
        let mut buffer = surface.pixels.buffer_mut().map_err(display_error)?;
        blit_scaled(image, width, height, &mut buffer);
        buffer.present().map_err(display_error)
    }

    /// The title: the scene, the scene file's error if it has one, and the
    /// last frame's cost, size and settings.
    fn set_title(&self) {
        let Some(s) = &self.surface else { return };
        let error = self
            .watched
            .as_ref()
            .and_then(|w| w.error.as_ref())
            .map(|e| format!(" | ERROR {e}"))
            .unwrap_or_default();
        let (w, h) = self.image_size;
        s.window.set_title(&format!(
            "{}{error} | {:.1} ms/frame | {w}x{h} | {}{} | speed {:.2}",
            self.name,
            self.smoothed_ms,
            self.settings.summary(),
            if self.animating || self.motions.is_empty() {
                ""
            } else {
                ", paused"
            },
            self.fly.speed
        ));
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: Error) {
        self.result = Err(e);
        event_loop.exit();
    }
}

/// Gives `renderer` the parameter defaults and lights of `compiled`, whose
/// program is the renderer's; on an error the parameters are put back.
fn update_in_place(renderer: &mut Backend, compiled: &CompiledScene) -> Result<()> {
    let slots = compiled.params().slots();
    let before: Vec<(&str, f64)> = slots
        .iter()
        .filter_map(|s| Some((s.name.as_str(), renderer.param(&s.name)?)))
        .collect();
    let result = slots
        .iter()
        .try_for_each(|s| renderer.set_param(&s.name, s.default))
        .and_then(|()| renderer.set_lights(compiled.lights()));
    if result.is_err() {
        for (name, value) in before {
            let _ = renderer.set_param(name, value);
        }
    }
    result
}

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.surface.is_some() {
            return;
        }
        let (w, h) = self.size;
        let attributes = Window::default_attributes()
            .with_title(format!("{} | fractal-sdf", self.name))
            .with_inner_size(PhysicalSize::new(w, h));
        let made = event_loop
            .create_window(attributes)
            .map_err(display_error)
            .and_then(|window| {
                let window = Rc::new(window);
                let context = softbuffer::Context::new(window.clone()).map_err(display_error)?;
                let pixels =
                    softbuffer::Surface::new(&context, window.clone()).map_err(display_error)?;
                Ok(Surface { window, pixels })
            });
        match made {
            Ok(surface) => self.surface = Some(surface),
            Err(e) => self.fail(event_loop, e),
        }
        self.last_tick = Instant::now();
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(_) => {
                self.scaler.invalidate();
                self.changed = true;
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.present() {
                    self.fail(event_loop, e);
                }
            }
            WindowEvent::KeyboardInput { event, .. } => {
                let PhysicalKey::Code(code) = event.physical_key else {
                    return;
                };
                let Some(key) = key_of(code) else { return };
                let pressed = event.state == ElementState::Pressed;
                if self.keys.set(key, pressed) || !pressed || event.repeat {
                    return;
                }
                if let Some(action) = self.bindings.action(key)
                    && let Err(e) = self.act(action, event_loop)
                {
                    self.fail(event_loop, e);
                }
            }
            WindowEvent::MouseInput {
                button: MouseButton::Left,
                state,
                ..
            } => self.dragging = state == ElementState::Pressed,
            WindowEvent::CursorMoved { position, .. } => {
                let now = (position.x, position.y);
                if let (true, Some(last)) = (self.dragging, self.cursor) {
                    self.fly.look(now.0 - last.0, now.1 - last.1);
                    self.changed = true;
                }
                self.cursor = Some(now);
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => f64::from(y),
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                self.fly.change_speed(steps);
                self.changed = true;
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self.surface.is_none() || self.result.is_err() {
            return;
        }
        if let Err(e) = self.tick(event_loop) {
            self.fail(event_loop, e);
        }
    }
}

/// The library's key for a physical key, if it has one.
fn key_of(code: KeyCode) -> Option<Key> {
    Some(match code {
        KeyCode::KeyA => Key::A,
        KeyCode::KeyB => Key::B,
        KeyCode::KeyC => Key::C,
        KeyCode::KeyD => Key::D,
        KeyCode::KeyE => Key::E,
        KeyCode::KeyF => Key::F,
        KeyCode::KeyG => Key::G,
        KeyCode::KeyH => Key::H,
        KeyCode::KeyI => Key::I,
        KeyCode::KeyJ => Key::J,
        KeyCode::KeyK => Key::K,
        KeyCode::KeyL => Key::L,
        KeyCode::KeyM => Key::M,
        KeyCode::KeyN => Key::N,
        KeyCode::KeyO => Key::O,
        KeyCode::KeyP => Key::P,
        KeyCode::KeyQ => Key::Q,
        KeyCode::KeyR => Key::R,
        KeyCode::KeyS => Key::S,
        KeyCode::KeyT => Key::T,
        KeyCode::KeyU => Key::U,
        KeyCode::KeyV => Key::V,
        KeyCode::KeyW => Key::W,
        KeyCode::KeyX => Key::X,
        KeyCode::KeyY => Key::Y,
        KeyCode::KeyZ => Key::Z,
        KeyCode::Digit0 => Key::Digit0,
        KeyCode::Digit1 => Key::Digit1,
        KeyCode::Digit2 => Key::Digit2,
        KeyCode::Digit3 => Key::Digit3,
        KeyCode::Digit4 => Key::Digit4,
        KeyCode::Digit5 => Key::Digit5,
        KeyCode::Digit6 => Key::Digit6,
        KeyCode::Digit7 => Key::Digit7,
        KeyCode::Digit8 => Key::Digit8,
        KeyCode::Digit9 => Key::Digit9,
        KeyCode::F1 => Key::F1,
        KeyCode::F2 => Key::F2,
        KeyCode::F3 => Key::F3,
        KeyCode::F4 => Key::F4,
        KeyCode::F5 => Key::F5,
        KeyCode::F6 => Key::F6,
        KeyCode::F7 => Key::F7,
        KeyCode::F8 => Key::F8,
        KeyCode::F9 => Key::F9,
        KeyCode::F10 => Key::F10,
        KeyCode::F11 => Key::F11,
        KeyCode::F12 => Key::F12,
        KeyCode::ArrowUp => Key::ArrowUp,
        KeyCode::ArrowDown => Key::ArrowDown,
        KeyCode::ArrowLeft => Key::ArrowLeft,
        KeyCode::ArrowRight => Key::ArrowRight,
        KeyCode::Space => Key::Space,
        KeyCode::Enter => Key::Enter,
        KeyCode::Escape => Key::Escape,
        KeyCode::Tab => Key::Tab,
        KeyCode::Backspace => Key::Backspace,
        _ => return None,
    })
}

/// `DIR/screenshot_NNN.png` with the first number not yet taken.
fn next_free(dir: &Path) -> PathBuf {
    (0..)
        .map(|i| dir.join(format!("screenshot_{i:03}.png")))
        .find(|p| !p.exists())
        .expect("a free name")
}

fn display_error(e: impl std::fmt::Display) -> Error {
    Error::Invalid {
        what: "display",
        reason: format!(
            "cannot open or draw the window: {e} (with no display, run under `xvfb-run -a`)"
        ),
    }
}

fn main() -> std::process::ExitCode {
    common::run(|| {
        let Some(args) = parse_args()? else {
            return Ok(());
        };
        let config = Config::new(args, Settings::load()?)?;
        // The scene first: its errors come before the display's.
        let mut viewer = Viewer::new(config)?;
        let event_loop = EventLoop::new().map_err(display_error)?;
        event_loop.set_control_flow(ControlFlow::Poll);
        event_loop.run_app(&mut viewer).map_err(display_error)?;
        viewer.result
    })
}
