//! Interactive viewing, without a window: everything between a window's
//! events and its pixels, so that a viewer's window code stays small and
//! what it does is tested here.
//!
//! A window toolkit translates its key events into [`Key`]s and its mouse
//! motion into pixel deltas. Each turn of a viewer's loop then
//!
//! 1. feeds held keys to [`Movement::set`], pressed keys to
//!    [`Action::for_key`] (or [`KeyBindings::action`], with keys rebound)
//!    and [`ViewSettings::apply`] (a changed setting means a new program),
//!    and mouse motion to [`FlyCamera::look`];
//! 2. advances the [`FlyCamera`] and hands its camera to the renderer;
//! 3. renders at the size that [`ResolutionScaler`] and [`reduced_size`]
//!    choose — reduced while the view changes, full once it stops — and
//!    reports the frame's time back to the scaler;
//! 4. fills the window with the image: [`blit_scaled`].
//!
//! [`KeyScript`] schedules key presses by frame, for unattended runs.
//! [`FrameTiming`] (what a frame cost, from the renderer) and
//! [`FrameStats`] measure frames in benchmarks too. `examples/viewer/`
//! connects all of it to a `winit` window.
//!
//! ```
//! use std::time::Duration;
//! use fractal_sdf::prelude::*;
//! use fractal_sdf::image::RgbaImage;
//! use fractal_sdf::view::{
//!     Action, FlyCamera, Key, Movement, ResolutionScaler, ViewSettings, blit_scaled, reduced_size,
//! };
//!
//! let start = Camera::look_at(dvec3(0.0, 0.0, 5.0), DVec3::ZERO);
//! let mut fly = FlyCamera::from_camera(&start);
//! let mut held = Movement::default();
//! let mut settings = ViewSettings::default();
//! let mut scaler = ResolutionScaler::new(Duration::from_millis(50), 8);
//!
//! // The window reports `w` pressed (and held), then `g` pressed.
//! for key in [Key::W, Key::G] {
//!     if !held.set(key, true) {
//!         if let Some(action) = Action::for_key(key) {
//!             // `true`: render with the new `settings.effects()` from now on.
//!             assert!(settings.apply(action));
//!         }
//!     }
//! }
//! assert_eq!(Action::for_key(Key::G), Some(Action::ToggleGlow));
//! assert!(settings.effects().glow.is_some());
//!
//! // Half a second at 2 units per second, towards the target.
//! fly.speed = 2.0;
//! let moved = fly.advance(held, 0.5);
//! let camera = fly.camera(&start);
//! assert!((camera.position.z - 4.0).abs() < 1e-9);
//!
//! // While moving, render a 640x480 view at a reduced size...
//! let divisor = scaler.next(moved).expect("the view changed");
//! let (w, h) = reduced_size(640, 480, divisor);
//! assert_eq!((w, h), (320, 240));
//! let image = RgbaImage::new(w, h); // `renderer.render(w, h)?` with `camera`
//! scaler.record(divisor, Duration::from_millis(40));
//! // ...and scale it up to fill the window.
//! let mut pixels = vec![0u32; 640 * 480];
//! blit_scaled(&image, 640, 480, &mut pixels);
//! ```

mod bindings;
mod blit;
mod control;
mod key;
mod script;
mod settings;
mod timing;

pub use bindings::{Action, KeyBindings};
pub use blit::blit_scaled;
pub use control::{FlyCamera, Movement};
pub use key::Key;
pub use script::KeyScript;
pub use settings::ViewSettings;
pub use timing::{FrameStats, FrameTiming, ResolutionScaler, fps, reduced_size};
