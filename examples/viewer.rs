//! An interactive window on any gallery scene.
//!
//! `cargo run --release --features viewer --example viewer -- fractal_mix`
//!
//! The camera, keys, settings and resolution choice live in the library
//! (`fractal_sdf::view`); this file only connects them to a `winit` window
//! and a `softbuffer` surface. Run with `--help` for every option.

mod common;

use std::num::NonZeroU32;
use std::path::PathBuf;
use std::rc::Rc;
use std::time::{Duration, Instant};

use fractal_sdf::animation::Motion;
use fractal_sdf::prelude::*;
use fractal_sdf::render::{RenderOptions, Renderer};
use fractal_sdf::view::{
    Action, FlyCamera, Key, KeyScript, Movement, ResolutionScaler, ViewSettings, blit_scaled,
    reduced_size,
};
use fractal_sdf::{gallery, output};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

const HELP: &str = "\
fractal-sdf viewer: fly through a gallery scene.

USAGE: viewer [SCENE] [OPTIONS]

SCENE is a gallery scene name (default mandelbulb); --list prints them.

OPTIONS:
  --size WxH           window size in pixels (default 640x480)
  --quality NAME       draft, preview (default), production or reference
  --no-ao              start with ambient occlusion off
  --no-shadows         start with shadows off
  --glow               start with glow on
  --sensitivity F      mouse sensitivity in radians per pixel (default 0.004)
  --speed F            movement speed in units per second (default: a third of
                       the distance to the scene camera's target)
  --target-ms F        frame time aimed at while moving (default 50)
  --max-divisor N      most the resolution is divided by while moving (default 8)
  --shots DIR          where F12 saves screenshots (default out)
  --frames N           render N full-size frames (animation at 30 fps), then exit
  --screenshot FILE    with --frames: save the last frame here
  --keys LIST          scripted key presses, KEY or KEY@FRAME, comma-separated,
                       e.g. \"g,3\" (g before frame 1, 3 before frame 2) or \"g@5\"
  --list               list the scenes and exit
  -h, --help           this text

CONTROLS:
  W/S A/D E/Q (or arrows)  move forward/back, left/right, up/down
  drag with left button    look around
  scroll wheel             change movement speed
";

struct Args {
    scene: String,
    size: (u32, u32),
    settings: ViewSettings,
    sensitivity: f64,
    speed: Option<f64>,
    target: Duration,
    max_divisor: u32,
    shots: PathBuf,
    frames: Option<u64>,
    screenshot: Option<PathBuf>,
    keys: KeyScript,
}

fn parse_args() -> Result<Option<Args>> {
    let mut a = pico_args::Arguments::from_env();
    if a.contains(["-h", "--help"]) {
        print!("{HELP}");
        println!("KEYS:");
        for action in Action::ALL {
            println!("  {:<24} {}", action.key(), action.description());
        }
        return Ok(None);
    }
    if a.contains("--list") {
        println!("{}", gallery::names().join("\n"));
        return Ok(None);
    }
    let u = common::usage;
    let mut settings = ViewSettings::default();
    if let Some(q) = a.opt_value_from_str::<_, String>("--quality").map_err(u)? {
        settings.preset = common::parse_preset(&q)?;
    }
    settings.ambient_occlusion = !a.contains("--no-ao");
    settings.shadows = !a.contains("--no-shadows");
    settings.glow = a.contains("--glow");
    let size = match a.opt_value_from_str::<_, String>("--size").map_err(u)? {
        Some(s) => common::parse_size(&s)?,
        None => (640, 480),
    };
    let keys = match a.opt_value_from_str::<_, String>("--keys").map_err(u)? {
        Some(s) => KeyScript::parse(&s)?,
        None => KeyScript::default(),
    };
    let args = Args {
        size,
        settings,
        sensitivity: a
            .opt_value_from_str("--sensitivity")
            .map_err(u)?
            .unwrap_or(FlyCamera::DEFAULT_SENSITIVITY),
        speed: a.opt_value_from_str("--speed").map_err(u)?,
        target: Duration::from_secs_f64(
            a.opt_value_from_str::<_, f64>("--target-ms")
                .map_err(u)?
                .unwrap_or(50.0)
                .max(1.0)
                / 1e3,
        ),
        max_divisor: a
            .opt_value_from_str("--max-divisor")
            .map_err(u)?
            .unwrap_or(8),
        shots: a
            .opt_value_from_str("--shots")
            .map_err(u)?
            .unwrap_or_else(|| "out".into()),
        frames: a.opt_value_from_str("--frames").map_err(u)?,
        screenshot: a.opt_value_from_str("--screenshot").map_err(u)?,
        keys,
        scene: a
            .opt_free_from_str()
            .map_err(u)?
            .unwrap_or_else(|| "mandelbulb".into()),
    };
    let rest = a.finish();
    if !rest.is_empty() {
        return Err(common::usage(format!("unexpected arguments {rest:?}")));
    }
    if let (Some(last), Some(n)) = (args.keys.last_frame(), args.frames)
        && last >= n
    {
        return Err(common::usage(format!(
            "--keys presses a key before frame {last}, but --frames renders frames 0..{n}"
        )));
    }
    if args.screenshot.is_some() && args.frames.is_none() {
        return Err(common::usage("--screenshot needs --frames"));
    }
    Ok(Some(args))
}

/// The window and its pixel surface, created once the event loop runs.
struct Surface {
    window: Rc<Window>,
    pixels: softbuffer::Surface<Rc<Window>, Rc<Window>>,
}

struct Viewer {
    args: Args,
    scene: Scene,
    motions: Vec<Motion>,
    renderer: Renderer,
    fly: FlyCamera,
    keys: Movement,
    settings: ViewSettings,
    scaler: ResolutionScaler,
    surface: Option<Surface>,
    /// The last rendered image, kept to re-present and to save.
    image: Option<RgbaImage>,
    /// Whether `image` is full size.
    image_sharp: bool,
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
    fn new(args: Args) -> Result<Self> {
        let scene = common::gallery_scene(&args.scene)?;
        let motions = gallery::motions(&args.scene);
        let settings = args.settings;
        let renderer = Renderer::with_options(
            &scene,
            &RenderOptions {
                quality: settings.quality(),
                effects: settings.effects(),
                ..RenderOptions::default()
            },
        )?;
        println!(
            "{}: {} on {} (build {:.0} ms)",
            args.scene,
            settings.summary(),
            renderer.device().label(),
            renderer.build_info().build_time.as_secs_f64() * 1e3
        );
        let mut fly = FlyCamera::from_camera(&scene.camera);
        fly.sensitivity = args.sensitivity;
        if let Some(speed) = args.speed {
            fly.speed = speed;
        }
        Ok(Viewer {
            scaler: ResolutionScaler::new(args.target, args.max_divisor),
            animating: !motions.is_empty(),
            args,
            scene,
            motions,
            renderer,
            fly,
            keys: Movement::default(),
            settings,
            surface: None,
            image: None,
            image_sharp: false,
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

    /// Applies a key's action.
    fn act(&mut self, action: Action, event_loop: &ActiveEventLoop) -> Result<()> {
        match action {
            Action::ToggleAnimation => {
                self.animating ^= true;
                self.changed = true;
            }
            Action::ResetCamera => {
                let speed = self.fly.speed;
                self.fly = FlyCamera {
                    speed,
                    sensitivity: self.fly.sensitivity,
                    ..FlyCamera::from_camera(&self.scene.camera)
                };
                self.changed = true;
            }
            Action::Screenshot => self.screenshot_wanted = true,
            Action::Quit => event_loop.exit(),
            _ => {
                if self.settings.apply(action) {
                    let t = Instant::now();
                    let (quality, effects) = (self.settings.quality(), self.settings.effects());
                    if self.renderer.options().quality != quality {
                        self.renderer.set_quality(quality)?;
                    }
                    if self.renderer.options().effects != effects {
                        self.renderer.set_effects(effects)?;
                    }
                    println!(
                        "{} ({} in {:.0} ms)",
                        self.settings.summary(),
                        if self.renderer.build_info().cached {
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
        // Scripted keys for the coming frame, once even if a tick draws
        // nothing.
        if self.scripted != Some(self.frame) {
            self.scripted = Some(self.frame);
            let script: Vec<Key> = self.args.keys.keys_at(self.frame).collect();
            for action in script.into_iter().filter_map(Action::for_key) {
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
        self.renderer
            .set_camera(self.fly.camera(&self.scene.camera))?;

        // Render at the chosen resolution (always full size unattended).
        let divisor = if self.headless() {
            Some(1)
        } else {
            self.scaler.next(changing)
        };
        let (width, height) = self.window_size();
        if let Some(d) = divisor {
            let (w, h) = reduced_size(width, height, d);
            let image = self.renderer.render(w, h)?;
            let took = self
                .renderer
                .last_timing()
                .map_or(Duration::ZERO, |t| t.total);
            self.scaler.record(d, took);
            self.smoothed_ms = if self.frame == 0 {
                took.as_secs_f64() * 1e3
            } else {
                0.8 * self.smoothed_ms + 0.2 * took.as_secs_f64() * 1e3
            };
            self.image = Some(image);
            self.image_sharp = d == 1;
            self.frame += 1;
            self.present()?;
            self.set_title(w, h);
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
        let busy = self.headless() || changing || self.keys.is_moving() || divisor.is_some();
        self.idle = !busy;
        event_loop.set_control_flow(if busy {
            ControlFlow::Poll
        } else {
            ControlFlow::Wait
        });
        Ok(())
    }

    /// Saves the current view at full size (rendering it if the last frame
    /// was reduced).
    fn save_sharp(&mut self, path: &std::path::Path) -> Result<()> {
        if !self.image_sharp || self.image.is_none() {
            let (w, h) = self.window_size();
            self.image = Some(self.renderer.render(w, h)?);
            self.image_sharp = true;
            self.present()?;
        }
        output::save_png(self.image.as_ref().expect("rendered above"), path)
    }

    fn window_size(&self) -> (u32, u32) {
        self.surface
            .as_ref()
            .map(|s| s.window.inner_size())
            .filter(|s| s.width > 0 && s.height > 0)
            .map_or(self.args.size, |s| (s.width, s.height))
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

    fn set_title(&self, w: u32, h: u32) {
        if let Some(s) = &self.surface {
            s.window.set_title(&format!(
                "{} | {:.1} ms/frame | {w}x{h} | {}{} | speed {:.2}",
                self.args.scene,
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
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: Error) {
        self.result = Err(e);
        event_loop.exit();
    }
}

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.surface.is_some() {
            return;
        }
        let (w, h) = self.args.size;
        let attributes = Window::default_attributes()
            .with_title(format!("{} | fractal-sdf", self.args.scene))
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
                if let Some(action) = Action::for_key(key)
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
fn next_free(dir: &std::path::Path) -> PathBuf {
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
        let event_loop = EventLoop::new().map_err(display_error)?;
        let mut viewer = Viewer::new(args)?;
        event_loop.set_control_flow(ControlFlow::Poll);
        event_loop.run_app(&mut viewer).map_err(display_error)?;
        viewer.result
    })
}
