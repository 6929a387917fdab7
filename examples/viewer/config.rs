//! The viewer's command line, its settings, and the scene file it watches.

use super::*;

pub(super) const HELP: &str = "\
fractal-sdf viewer: fly through a gallery scene or a scene file.

USAGE: viewer [SCENE] [OPTIONS]

SCENE is a gallery scene name (default mandelbulb; --list prints them) or a
scene file: a path that contains `/`, ends in `.ron` or names a file. A
scene file brings its quality, effects and motions, and is reloaded when its
modification time or size changes (checked 4 times a second): the camera,
quality and effects a new version changes replace the view's, the rest
stays. A bad version is reported on stderr and in the title (ERROR) while
the last good scene stays on screen.

SETTINGS: $FRACTAL_SDF_CONFIG or fractal-sdf/config.toml in the user's
configuration directory: `preset`, `size`, `device`, `backend`, and under [viewer]
`mouse_sensitivity` and [viewer.keys] (action name = key name, e.g.
`toggle_glow = \"l\"`; names below). Options given here override them; a
scene file's own quality overrides `preset`.

OPTIONS:
  --size WxH           window size in pixels (default 640x480)
  --quality NAME       draft, preview (default), production or reference
  --no-ao              start with ambient occlusion off
  --no-shadows         start with shadows off
  --glow               start with glow on
  --device NAME        the first OpenCL device whose name contains NAME
  --backend NAME       opencl (default) or wgpu (built with --features wgpu)
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

A still view is refined by 64 progressive passes (64 samples per pixel
times the preset's supersampling):
edges smooth out, and a camera with a lens (a scene file's `aperture`)
shows its depth of field.
";

/// The command line; `None` where it leaves the setting to the settings
/// file or the scene.
pub(super) struct Args {
    pub(super) scene: String,
    pub(super) size: Option<(u32, u32)>,
    pub(super) preset: Option<Preset>,
    pub(super) no_ao: bool,
    pub(super) no_shadows: bool,
    pub(super) glow: bool,
    pub(super) device: Option<String>,
    pub(super) backend: Option<BackendKind>,
    pub(super) sensitivity: Option<f64>,
    pub(super) speed: Option<f64>,
    pub(super) target: Duration,
    pub(super) max_divisor: u32,
    pub(super) shots: PathBuf,
    pub(super) frames: Option<u64>,
    pub(super) screenshot: Option<PathBuf>,
    pub(super) keys: Option<String>,
}

pub(super) fn parse_args() -> Result<Option<Args>> {
    let mut a = pico_args::Arguments::from_env();
    if a.contains(["-h", "--help"]) {
        print!("{HELP}");
        println!("\nKEYS (default key, action name for [viewer.keys]):");
        for action in Action::ALL {
            println!(
                "  {:<8} {:<26} {}",
                action.key(),
                action.name(),
                action.description()
            );
        }
        return Ok(None);
    }
    if a.contains("--list") {
        println!("{}", gallery::names().join("\n"));
        return Ok(None);
    }
    let u = common::usage;
    let preset = match a.opt_value_from_str::<_, String>("--quality").map_err(u)? {
        Some(q) => Some(common::parse_preset(&q)?),
        None => None,
    };
    let size = match a.opt_value_from_str::<_, String>("--size").map_err(u)? {
        Some(s) => Some(common::parse_size(&s)?),
        None => None,
    };
    let args = Args {
        size,
        preset,
        no_ao: a.contains("--no-ao"),
        no_shadows: a.contains("--no-shadows"),
        glow: a.contains("--glow"),
        device: a.opt_value_from_str("--device").map_err(u)?,
        backend: match a.opt_value_from_str::<_, String>("--backend").map_err(u)? {
            Some(name) => Some(BackendKind::from_name(&name)?),
            None => None,
        },
        sensitivity: a.opt_value_from_str("--sensitivity").map_err(u)?,
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
        keys: a.opt_value_from_str("--keys").map_err(u)?,
        scene: a
            .opt_free_from_str()
            .map_err(u)?
            .unwrap_or_else(|| "mandelbulb".into()),
    };
    let rest = a.finish();
    if !rest.is_empty() {
        return Err(common::usage(format!("unexpected arguments {rest:?}")));
    }
    if args.screenshot.is_some() && args.frames.is_none() {
        return Err(common::usage("--screenshot needs --frames"));
    }
    if let Some(s) = args.sensitivity
        && !s.is_finite()
    {
        return Err(common::usage(format!("--sensitivity {s} is not a number")));
    }
    Ok(Some(args))
}

/// Everything that decides how the viewer runs: the command line over the
/// settings file over the defaults.
pub(super) struct Config {
    pub(super) args: Args,
    pub(super) size: (u32, u32),
    /// The settings file's preset, for gallery scenes and scene files
    /// without a quality.
    pub(super) settings_preset: Option<Preset>,
    pub(super) device: DeviceSelector,
    pub(super) backend: BackendKind,
    pub(super) sensitivity: f64,
    pub(super) bindings: KeyBindings,
    pub(super) script: KeyScript,
}

impl Config {
    pub(super) fn new(args: Args, settings: Settings) -> Result<Self> {
        let in_settings = |e: Error| Error::Invalid {
            what: "settings file",
            reason: format!(
                "{}: {e}",
                Settings::path().map_or_else(String::new, |p| p.display().to_string())
            ),
        };
        let bindings = KeyBindings::from_names(&settings.viewer.keys).map_err(in_settings)?;
        let sensitivity = match (args.sensitivity, settings.viewer.mouse_sensitivity) {
            (Some(s), _) => s,
            (None, Some(s)) if s.is_finite() => s,
            (None, Some(s)) => {
                return Err(in_settings(Error::Invalid {
                    what: "mouse_sensitivity",
                    reason: format!("{s} is not a number"),
                }));
            }
            (None, None) => FlyCamera::DEFAULT_SENSITIVITY,
        };
        let script = match &args.keys {
            Some(text) => KeyScript::parse_with(text, &bindings)?,
            None => KeyScript::default(),
        };
        if let (Some(last), Some(n)) = (script.last_frame(), args.frames)
            && last >= n
        {
            return Err(common::usage(format!(
                "--keys presses a key before frame {last}, but --frames renders frames 0..{n}"
            )));
        }
        let device = match args.device.as_ref().or(settings.device.as_ref()) {
            Some(name) => DeviceSelector::device(name.clone()),
            None => DeviceSelector::auto(),
        };
        let backend = args.backend.unwrap_or(match settings.backend {
            Some(fractal_sdf::settings::Backend::Wgpu) => BackendKind::Wgpu,
            _ => BackendKind::OpenCl,
        });
        if backend == BackendKind::Wgpu && args.device.is_some() {
            return Err(common::usage(
                "--device chooses an OpenCL device: the wgpu backend runs on the adapter wgpu \
                 chooses (WGPU_ADAPTER_NAME steers it)",
            ));
        }
        Ok(Config {
            backend,
            settings_preset: settings.preset,
            size: args.size.or(settings.size).unwrap_or((640, 480)),
            args,
            device,
            sensitivity,
            bindings,
            script,
        })
    }
}

/// Whether the SCENE argument names a scene file rather than a gallery
/// scene.
pub(super) fn is_scene_file(scene: &str) -> bool {
    scene.contains('/')
        || scene.contains(std::path::MAIN_SEPARATOR)
        || scene.ends_with(".ron")
        || Path::new(scene).is_file()
}

/// The modification time and size of the file at `path`, if it has one.
pub(super) fn stamp(path: &Path) -> Option<Stamp> {
    let meta = std::fs::metadata(path).ok()?;
    Some((meta.modified().ok()?, meta.len()))
}

/// A scene file the viewer shows and watches for changes.
pub(super) struct Watched {
    pub(super) path: PathBuf,
    /// The file's stamp when it was last read.
    pub(super) stamp: Option<Stamp>,
    pub(super) next_check: Instant,
    /// The last file that loaded and rendered.
    pub(super) good: SceneFile,
    /// The error of the last read, if it failed: for the title.
    pub(super) error: Option<String>,
}

/// The layouts give the same parameters the same slots and rules (their
/// defaults may differ).
pub(super) fn same_slots(a: &ParamLayout, b: &ParamLayout) -> bool {
    a.constraints() == b.constraints()
        && a.slots().len() == b.slots().len()
        && a.slots()
            .iter()
            .zip(b.slots())
            .all(|(x, y)| x.name == y.name && x.rule == y.rule && x.used_at == y.used_at)
}

/// An error for the title: short, and a scene file's with its file name
/// instead of its path.
pub(super) fn title_error(e: &Error) -> String {
    let text = match e {
        Error::SceneFile {
            file,
            line,
            column,
            reason,
            ..
        } => format!(
            "{}:{line}:{column}: {reason}",
            file.file_name().map_or_else(
                || file.display().to_string(),
                |n| n.to_string_lossy().into_owned()
            )
        ),
        other => other.to_string(),
    };
    let text = text.split_whitespace().collect::<Vec<_>>().join(" ");
    if text.chars().count() > TITLE_ERROR_CHARS {
        let cut: String = text.chars().take(TITLE_ERROR_CHARS - 3).collect();
        format!("{cut}...")
    } else {
        text
    }
}
