//! `fractal-sdf`: render scene files and gallery scenes from the command
//! line. `fractal-sdf --help` lists the subcommands; each has its own
//! `--help`.

mod mesh;
mod nodes;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use clap::{Args, Parser, Subcommand};
use fractal_sdf::animation::CameraPath;
use fractal_sdf::codegen::{self, Options};
use fractal_sdf::expr::CALL_FLOPS;
use fractal_sdf::file::SceneFile;
use fractal_sdf::gallery;
use fractal_sdf::output::{
    Aov, Bits, CameraExport, FrameOutput, image_extension, save_frame, save_image, verify_image,
};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::{Encoding, GlobalIllumination, Preset, ToneMap};
use fractal_sdf::render::{
    DeviceKind, DeviceSelector, EdgeThresholds, RenderOptions, Renderer, StopRule, WgpuRenderer,
    devices, render_stereo, wgpu_adapters,
};
use fractal_sdf::scene::{CustomShape, Environment, Stereo, StereoLayout};
use fractal_sdf::sequence::{Encoded, MotionBlur, RenderedFrame, Sequence, parse_range};
use fractal_sdf::settings::{self, CONFIG_ENV, Settings, parse_preset, parse_size};
use indicatif::{ProgressBar, ProgressStyle};

/// Render signed-distance scenes and 3D fractals with OpenCL.
///
/// SCENE is a scene file (`.ron`, see the crate's `scenes/` folder) or the
/// name of a gallery scene (`fractal-sdf render mandelbulb -o bulb.png`).
/// Settings (default preset, size and device) come from the settings
/// file (`fractal-sdf config` shows where it is); flags override it.
#[derive(Parser)]
#[command(name = "fractal-sdf", version, propagate_version = true)]
struct Cli {
    /// The settings file to read instead of the default one.
    #[arg(long, global = true, value_name = "FILE")]
    config: Option<PathBuf>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render one image to a PNG, JPEG, TIFF or OpenEXR file (by the output's extension).
    Render(RenderArgs),
    /// Render a camera path to numbered frames (PNG, TIFF, JPEG or OpenEXR; resumable), then a video.
    Sequence(SequenceArgs),
    /// Print the generated OpenCL C of a scene, or its functions in WGSL.
    Emit(EmitArgs),
    /// List the OpenCL platforms and devices.
    Devices,
    /// Time frames of a scene: milliseconds and distance evaluations per pixel.
    Bench(BenchArgs),
    /// Show the settings file's path and the settings in effect.
    Config,
    /// Compare two images of the same size: PSNR, SSIM and differing pixels.
    Compare(CompareArgs),
    /// Extract a watertight mesh of a scene's surface: STL, PLY or OBJ.
    Mesh(mesh::MeshArgs),
    /// Sample a scene's signed distances on a grid: an NRRD volume, PNG slices.
    Volume(mesh::VolumeArgs),
    /// List every node a scene file can hold: its fields, kind, and whether
    /// its distance is exact.
    Nodes(nodes::NodesArgs),
}

#[derive(Args)]
struct CompareArgs {
    /// The first image (PNG).
    a: PathBuf,
    /// The second image (PNG).
    b: PathBuf,
}

/// Where the scene comes from: a file or gallery name, or a text formula.
#[derive(Args)]
pub(crate) struct SceneSource {
    /// A scene file (`.ron`) or a gallery scene name.
    #[arg(required_unless_present = "formula")]
    scene: Option<String>,
    /// The scene as one shape written as a text formula, instead of SCENE:
    /// the distance at the point `p` (`'length(p) - 1'`; the language is
    /// in the crate's `expr::Formula` docs), under the default camera.
    #[arg(long, value_name = "TEXT", conflicts_with = "scene")]
    formula: Option<String>,
}

impl SceneSource {
    /// The scene's name in messages.
    fn label(&self) -> &str {
        self.scene.as_deref().unwrap_or("formula")
    }
}

/// What every rendering subcommand takes.
#[derive(Args)]
struct SceneArgs {
    #[command(flatten)]
    scene: SceneSource,
    /// Quality preset: draft, preview, production or reference (default:
    /// the scene file's quality, else the settings file's preset, else
    /// production).
    #[arg(long)]
    preset: Option<String>,
    /// Image size, WIDTHxHEIGHT (default: the settings file's, else 640x480).
    #[arg(long)]
    size: Option<String>,
    /// Set a dynamic parameter: NAME=VALUE (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
    /// An environment light: an equirectangular HDR image (.hdr or .exr)
    /// around the scene, its background and ambient light, which lights it
    /// exactly with --gi (in place of the scene file's).
    #[arg(long, value_name = "FILE")]
    environment: Option<PathBuf>,
    /// A substring of the OpenCL device's name (default: the settings
    /// file's, else automatic).
    #[arg(long)]
    device: Option<String>,
    /// Split every frame across devices: `all` (every GPU, or every device
    /// where there is none), or device name substrings separated by commas
    /// (a name twice uses that device twice).
    #[arg(long, value_name = "all|NAME,...", conflicts_with = "device")]
    devices: Option<String>,
    /// The longest a frame may take, in seconds: past it the command stops
    /// with an error instead of waiting (a launch still running at twice
    /// the time is abandoned).
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    deadline: Option<Duration>,
}

/// A positive, finite number of seconds.
fn parse_seconds(text: &str) -> std::result::Result<Duration, String> {
    let seconds: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number of seconds"))?;
    Duration::try_from_secs_f64(seconds)
        .ok()
        .filter(|d| !d.is_zero())
        .ok_or_else(|| format!("`{text}`: expected a positive number of seconds"))
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// The image to write: `.png`, `.jpg`/`.jpeg`, `.tif`/`.tiff`, or
    /// `.exr` for OpenEXR with the linear colour and a layer per --aov
    /// (the extension chooses the format; any other is refused before
    /// rendering).
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Outputs to write besides the colour, comma-separated: depth,
    /// normal, position, albedo, ao, shadow, trap, evaluations, coverage,
    /// object, material (ids: 1 for the file's first shape or material,
    /// in the order the file writes them; 0 on a miss). Layers of
    /// an `.exr` file; otherwise a 16-bit PNG each beside the image
    /// (`out.png` gets `out.depth.png`, ...).
    #[arg(long, value_name = "LIST", value_delimiter = ',', conflicts_with_all = ["stereo", "adaptive"])]
    aov: Vec<String>,
    /// Bits per channel of a `.png` or `.tif` image: 8, or 16 (the linear
    /// colour through the tone curve on the host, without 8-bit rounding).
    #[arg(long, value_name = "N", default_value = "8", value_parser = ["8", "16"],
          conflicts_with_all = ["stereo", "adaptive"])]
    bits: String,
    /// Exposure in stops: linear colours are scaled by 2^STOPS before the
    /// tone curve (default: the scene file's, else 0).
    #[arg(long, value_name = "STOPS", allow_hyphen_values = true)]
    exposure: Option<f64>,
    /// The tone curve that maps exposed colours into the image: clip,
    /// reinhard or filmic (default: the scene file's, else clip).
    #[arg(long, value_name = "CURVE")]
    tonemap: Option<String>,
    /// Encode the image by the exact sRGB curve instead of the gamma.
    #[arg(long)]
    srgb: bool,
    /// Also writes the camera as JSON (position, orientation, field of
    /// view, sensor and aspect; see the guide's chapter on outputs for
    /// lining it up in a 3D package).
    #[arg(long, value_name = "FILE")]
    camera_json: Option<PathBuf>,
    /// Progressive passes: the image is the mean of N passes of the
    /// preset's samples, each at new points in the pixel and on the lens
    /// (default 1; a camera with a lens needs about 16 for a smooth blur,
    /// and the command says so when it renders one with a single pass).
    #[arg(long, value_name = "N",
          value_parser = clap::value_parser!(u32).range(1..=4096))]
    passes: Option<u32>,
    /// Progressive passes until the image's estimated noise (the root mean
    /// square error of its displayed colour, in [0, 1]: 0.004 is about one
    /// 8-bit step) is at most NOISE, with at most --passes passes (default
    /// 1024). The noise is estimated from the passes themselves, after 2,
    /// 4, 8, ... of them.
    #[arg(long, value_name = "NOISE", conflicts_with_all = ["stereo", "adaptive"])]
    noise: Option<f64>,
    /// Path-traced global illumination: light bounces between surfaces and
    /// arrives from the whole sky, up to BOUNCES bounces a path (default
    /// 16). Grainy in one pass: add --passes or --noise.
    #[arg(long, value_name = "BOUNCES", num_args = 0..=1, default_missing_value = "16")]
    gi: Option<u32>,
    /// Adaptive supersampling: N passes at the pixels that differ from a
    /// neighbour (edges, creases, shadow borders), one elsewhere.
    #[arg(long, value_name = "N", conflicts_with_all = ["passes", "stereo"],
          value_parser = clap::value_parser!(u32).range(1..=4096))]
    adaptive: Option<u32>,
    /// The lens's radius in scene units, for depth of field (0: a pinhole).
    #[arg(long, value_name = "RADIUS")]
    aperture: Option<f64>,
    /// The distance in focus (default: the scene camera's, else its target's).
    #[arg(long, value_name = "DISTANCE")]
    focus: Option<f64>,
    /// A stereo pair: anaglyph, side-by-side or over-under (each eye at
    /// --size).
    #[arg(long, value_name = "LAYOUT", conflicts_with = "passes")]
    stereo: Option<String>,
    /// The distance between the eyes (default: a thirtieth of the
    /// convergence distance).
    #[arg(long, value_name = "DISTANCE", requires = "stereo")]
    eye_separation: Option<f64>,
    /// Where the eyes' images coincide (default: the distance in focus).
    #[arg(long, value_name = "DISTANCE", requires = "stereo")]
    convergence: Option<f64>,
    /// How many times a path may bounce off mirrors or pass through glass
    /// (0 to 8; default: the quality's).
    #[arg(long, value_name = "N")]
    bounces: Option<u32>,
    /// The brute-force step through shapes given by an inside test, in
    /// pixel footprints (default: the quality's).
    #[arg(long, value_name = "FOOTPRINTS")]
    brute_step: Option<f64>,
    /// The backend that renders: opencl, or wgpu (WGSL on Vulkan, in
    /// single precision; the 8-bit image, with --passes, --gi and
    /// --stereo: no --aov, --bits 16, .exr, --noise, --adaptive, --device
    /// or --devices, nor custom shapes written in OpenCL C, which need
    /// opencl). Default: the settings file's, else opencl.
    #[arg(long, value_enum)]
    backend: Option<Backend>,
}

/// The backends `render`, `sequence` and `bench` render with, and `mesh` and
/// `volume` sample with.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Backend {
    Opencl,
    Wgpu,
}

impl Backend {
    /// The backend asked for, else the settings file's, else OpenCL.
    fn chosen(asked: Option<Backend>, settings: &Settings) -> Backend {
        asked.unwrap_or(match settings.backend {
            Some(settings::Backend::Wgpu) => Backend::Wgpu,
            _ => Backend::Opencl,
        })
    }
}

impl RenderArgs {
    /// The stereo view asked for, if any.
    fn stereo(&self) -> Outcome<Option<Stereo>> {
        let Some(name) = &self.stereo else {
            return Ok(None);
        };
        let layout = StereoLayout::from_name(name).ok_or_else(|| {
            let names: Vec<&str> = StereoLayout::ALL.iter().map(|l| l.name()).collect();
            usage(format!(
                "--stereo `{name}`: expected one of {}",
                names.join(", ")
            ))
        })?;
        let mut stereo = Stereo::new(layout);
        stereo.eye_separation = self.eye_separation;
        stereo.convergence = self.convergence;
        Ok(Some(stereo))
    }
}

#[derive(Args)]
struct SequenceArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Frames per second.
    #[arg(long, default_value_t = 24.0)]
    fps: f64,
    /// The frames' directory (frame_00000.png, ...).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// The frames' format: png, tif, jpg, or exr (OpenEXR with the linear
    /// colour and a layer per --aov; no video is made of them).
    #[arg(long, value_name = "EXT", default_value = "png")]
    format: String,
    /// Outputs to write with every frame, as `render --aov` writes them:
    /// layers of an .exr frame, else a 16-bit PNG each beside it.
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    aov: Vec<String>,
    /// A camera path file in TOML (default: the scene file's path, else one
    /// orbit around the camera's target).
    #[arg(long, value_name = "FILE")]
    path: Option<PathBuf>,
    /// The orbit's length in seconds, where there is no camera path.
    #[arg(long, default_value_t = 4.0)]
    seconds: f64,
    /// Only these frames: a..b, a..=b, a.., ..b or n.
    #[arg(long, value_name = "RANGE")]
    frames: Option<String>,
    /// Only this share of the frames, I/N: those whose index is I modulo
    /// N (for job arrays; see deploy/slurm).
    #[arg(long, value_name = "I/N")]
    shard: Option<String>,
    /// Render nothing: check that every frame of the range is a whole PNG
    /// of the size, and exit 1 listing those that are not.
    #[arg(long)]
    verify: bool,
    /// Do not encode a video once every frame exists.
    #[arg(long)]
    no_video: bool,
    /// The video to encode with ffmpeg (default: DIR.mp4).
    #[arg(long, value_name = "FILE")]
    video: Option<PathBuf>,
    /// Also writes every frame's camera, the whole sequence's, as one
    /// JSON array (each entry as `render --camera-json` writes one, with
    /// its frame and time).
    #[arg(long, value_name = "FILE")]
    camera_json: Option<PathBuf>,
    /// Motion blur: each frame the mean of N moments spread over the time
    /// its shutter is open (1 to 256; 1 is none).
    #[arg(long, value_name = "N", default_value_t = 1)]
    motion_blur: u32,
    /// The fraction of a frame's duration the shutter is open, from the
    /// frame's time on (0.5: a 180° shutter).
    #[arg(
        long,
        value_name = "FRACTION",
        default_value_t = 0.5,
        requires = "motion_blur"
    )]
    shutter: f64,
    /// The backend that renders: opencl, or wgpu (8-bit frames: no --aov
    /// or exr). Default: the settings file's, else opencl.
    #[arg(long, value_enum)]
    backend: Option<Backend>,
}

#[derive(Args)]
struct EmitArgs {
    #[command(flatten)]
    scene: SceneSource,
    /// Quality preset, which decides precision and loop bounds.
    #[arg(long)]
    preset: Option<String>,
    /// The language: the whole OpenCL C program, or the scene's functions
    /// in WGSL (`DE`, `DE_shade`), to call from a shader of your own
    /// (single precision only).
    #[arg(long, value_enum, default_value_t = Language::Opencl)]
    language: Language,
}

/// The languages `emit` writes.
#[derive(Clone, Copy, clap::ValueEnum)]
enum Language {
    Opencl,
    Wgsl,
}

#[derive(Args)]
struct BenchArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Frames to time after one warm-up frame.
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..))]
    frames: u32,
    /// Also time the frame stage by stage: the march with normals and
    /// shading alone, then with each of ambient occlusion, shadows, glow
    /// and lit fog that the scene and preset have added one after the
    /// other (each a program of its own).
    #[arg(long)]
    stages: bool,
    /// The backend to time: opencl or wgpu (default: the settings file's,
    /// else opencl). The operation count and the share of the device's
    /// peak are measured on OpenCL devices alone.
    #[arg(long, value_enum)]
    backend: Option<Backend>,
}

/// A failure and the exit code it gets: 2 for a command line that cannot
/// be used, 1 for everything else.
struct Failure {
    code: u8,
    message: String,
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        Failure {
            code: 1,
            message: e.to_string(),
        }
    }
}

fn usage(message: impl Into<String>) -> Failure {
    Failure {
        code: 2,
        message: message.into(),
    }
}

type Outcome<T = ()> = std::result::Result<T, Failure>;

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprintln!("fractal-sdf: {}", f.message);
            ExitCode::from(f.code)
        }
    }
}

fn run(cli: Cli) -> Outcome {
    // Read only by the subcommands that use it: `devices` runs whatever the
    // file holds, and `config` reports what is wrong with it.
    let settings = || match &cli.config {
        Some(path) => Settings::load_from(path),
        None => Settings::load(),
    };
    match &cli.command {
        Command::Render(args) => render(args, &settings()?),
        Command::Sequence(args) => sequence(args, &settings()?),
        Command::Emit(args) => emit(args, &settings()?),
        Command::Devices => list_devices(),
        Command::Bench(args) => bench(args, &settings()?),
        Command::Config => show_config(cli.config.as_deref(), settings()),
        Command::Compare(args) => compare(args),
        Command::Mesh(args) => mesh::mesh(args),
        Command::Volume(args) => mesh::volume(args),
        Command::Nodes(args) => nodes::nodes(args),
    }
}

/// A scene file's path, a gallery name's file, or a formula's shape.
fn load_scene(source: &SceneSource) -> Outcome<SceneFile> {
    if let Some(text) = &source.formula {
        let shape = CustomShape::parse("formula", &[], text)?;
        let no_args: [f64; 0] = [];
        return Ok(SceneFile::new(Scene::new(shape.node(no_args))));
    }
    let scene = source.scene.as_deref().unwrap_or_default();
    let path = Path::new(scene);
    if path.is_file() || scene.ends_with(".ron") || scene.contains(std::path::MAIN_SEPARATOR) {
        return Ok(SceneFile::load(path)?);
    }
    gallery::file(scene).ok_or_else(|| {
        usage(format!(
            "`{scene}` is neither a scene file nor a gallery scene (one of: {})",
            gallery::names().join(", ")
        ))
    })
}

/// `--set NAME=VALUE` flags.
fn parse_sets(flags: &[String]) -> Outcome<Vec<(String, f64)>> {
    flags
        .iter()
        .map(|pair| {
            let (name, value) = pair
                .split_once('=')
                .ok_or_else(|| usage(format!("--set `{pair}`: expected NAME=VALUE")))?;
            let value: f64 = value
                .trim()
                .parse()
                .map_err(|_| usage(format!("--set `{pair}`: `{value}` is not a number")))?;
            Ok((name.trim().to_string(), value))
        })
        .collect()
}

/// Everything a rendering subcommand needs, settled from the flags, the
/// settings file and the scene file.
struct Job {
    file: SceneFile,
    devices: Option<Vec<DeviceSelector>>,
    size: (u32, u32),
    options: RenderOptions,
    sets: Vec<(String, f64)>,
}

impl Job {
    fn new(args: &SceneArgs, settings: &Settings) -> Outcome<Job> {
        let mut file = load_scene(&args.scene)?;
        if let Some(image) = &args.environment {
            file.scene.environment = Some(Environment::load(image)?);
        }
        let preset = match &args.preset {
            Some(name) => Some(parse_preset(name).map_err(|e| usage(e.to_string()))?),
            None => None,
        };
        let size = match &args.size {
            Some(text) => parse_size(text).map_err(|e| usage(e.to_string()))?,
            None => settings.size.unwrap_or((640, 480)),
        };
        let device = args.device.clone().or_else(|| settings.device.clone());
        let sets = parse_sets(&args.set)?;
        // Checked before a device is opened: a misspelt name is reported,
        // with the names the scene has, on any machine.
        let mut values = file.scene.compile()?.default_values();
        for (name, value) in &sets {
            values.set(name, *value)?;
        }
        let devices = match args.devices.as_deref() {
            None => None,
            Some("all") => Some(every_device()?),
            Some(list) => Some(
                list.split(',')
                    .map(|name| match name.trim() {
                        "" => Err(usage(format!("--devices `{list}`: an empty device name"))),
                        name => Ok(DeviceSelector::device(name)),
                    })
                    .collect::<Outcome<_>>()?,
            ),
        };
        let options = RenderOptions::default()
            .quality(quality(preset, &file, settings))
            .effects(file.effects)
            .device(device.map_or_else(DeviceSelector::auto, DeviceSelector::device))
            .deadline(args.deadline);
        Ok(Job {
            file,
            devices,
            size,
            options,
            sets,
        })
    }

    fn renderer(&self) -> Outcome<Renderer> {
        let mut renderer = match &self.devices {
            Some(devices) => Renderer::with_devices(&self.file.scene, &self.options, devices)?,
            None => Renderer::with_options(&self.file.scene, &self.options)?,
        };
        for (name, value) in &self.sets {
            renderer.set_param(name, *value)?;
        }
        Ok(renderer)
    }

    /// The wgpu backend's renderer of the job's scene, with its `--set`
    /// values: `--device`, `--devices` and `--deadline` are usage errors.
    fn wgpu_renderer(&self, scene: &SceneArgs) -> Outcome<WgpuRenderer> {
        if self.devices.is_some() || scene.device.is_some() || scene.deadline.is_some() {
            return Err(usage(
                "--device, --devices and --deadline are the OpenCL backend's (--backend \
                 opencl): the wgpu backend runs on the adapter wgpu chooses, a frame in one \
                 dispatch",
            ));
        }
        let mut renderer = WgpuRenderer::from_compiled(self.file.scene.compile()?, &self.options)?;
        for (name, value) in &self.sets {
            renderer.set_param(name, *value)?;
        }
        Ok(renderer)
    }

    fn preset_name(&self) -> String {
        Preset::ALL
            .into_iter()
            .find(|p| p.quality() == self.options.quality)
            .map_or_else(|| "custom".into(), |p| p.name().into())
    }
}

fn spinner(message: String) -> ProgressBar {
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("a valid template"),
    );
    bar.set_message(message);
    bar.enable_steady_tick(Duration::from_millis(120));
    bar
}

/// The outputs `--aov` names, empty names skipped.
fn parse_aovs(names: &[String]) -> Outcome<Vec<Aov>> {
    names
        .iter()
        .filter(|name| !name.trim().is_empty())
        .map(|name| Aov::from_name(name).map_err(|e| usage(format!("--aov: {e}"))))
        .collect()
}

fn render(args: &RenderArgs, settings: &Settings) -> Outcome {
    image_extension(&args.output).map_err(|e| usage(e.to_string()))?;
    let stereo = args.stereo()?;
    let aovs = parse_aovs(&args.aov)?;
    let mut job = Job::new(&args.scene, settings)?;
    let camera = &mut job.file.scene.camera;
    if let Some(aperture) = args.aperture {
        camera.aperture = aperture;
    }
    if let Some(focus) = args.focus {
        camera.focus_distance = Some(focus);
    }
    if let Some(bounces) = args.bounces {
        job.options.quality.bounces = bounces;
    }
    if let Some(step) = args.brute_step {
        job.options.quality.brute_step = step;
    }
    if let Some(stops) = args.exposure {
        job.options.effects.exposure = stops;
    }
    if args.srgb {
        job.options.effects.encoding = Encoding::Srgb;
    }
    if let Some(bounces) = args.gi {
        job.options.effects.global_illumination = Some(GlobalIllumination::new(bounces));
    }
    if let Some(name) = &args.tonemap {
        job.options.effects.tone_map = ToneMap::from_name(name).ok_or_else(|| {
            let names: Vec<&str> = ToneMap::ALL.iter().map(|t| t.name()).collect();
            usage(format!(
                "--tonemap `{name}`: expected one of {}",
                names.join(", ")
            ))
        })?;
    }
    let bits = if args.bits == "16" {
        Bits::Sixteen
    } else {
        Bits::Eight
    };
    let output = FrameOutput::new(job.options.effects).aovs(aovs).bits(bits);
    output
        .check(&args.output)
        .map_err(|e| usage(e.to_string()))?;
    let layered = output.needs_layers(&args.output)?;
    if layered && stereo.is_some() {
        return Err(usage(format!(
            "--stereo writes an 8-bit composite, which {} cannot hold: write a .png, .jpg or .tif",
            args.output.display()
        )));
    }
    if args.camera_json.is_some() && stereo.is_some() {
        return Err(usage(
            "--camera-json writes one camera, and --stereo renders two eyes: export each \
             eye's view with its own render",
        ));
    }
    if layered && args.adaptive.is_some() {
        return Err(usage(format!(
            "--adaptive refines the 8-bit image alone, which {} cannot hold: use --passes",
            args.output.display()
        )));
    }
    if Backend::chosen(args.backend, settings) == Backend::Wgpu {
        return render_wgpu(args, &job, stereo.as_ref());
    }
    let stop = args
        .noise
        .map(|noise| StopRule::new(noise, args.passes.unwrap_or(NOISE_PASSES)));
    let mut passes = args.passes.unwrap_or(1);
    let plain = stereo.is_none() && args.adaptive.is_none();
    let aperture = job.file.scene.camera.aperture;
    if plain && stop.is_none() && passes == 1 && aperture > 0.0 {
        eprintln!(
            "note: the camera has a lens (aperture {aperture}), whose blur one pass leaves \
             grainy: --passes {LENS_PASSES} renders a smooth one in {LENS_PASSES} times the time"
        );
    }
    let (width, height) = job.size;
    let start = Instant::now();
    let bar = spinner(format!("rendering {width}x{height}"));
    let mut renderer = job.renderer()?;
    let mut refined = None;
    let dimensions;
    let written = if layered || output.needs_aovs() || stop.is_some() {
        let frame = if let Some(stop) = &stop {
            let done = renderer.render_converged(width, height, stop);
            bar.finish_and_clear();
            let done = done?;
            passes = done.passes;
            refined = Some(if done.reached(stop) {
                format!("noise {:.4} after {} passes", done.noise, done.passes)
            } else {
                format!(
                    "noise {:.4} after {} passes, above --noise {}: more --passes would lower it",
                    done.noise, done.passes, stop.noise
                )
            });
            done.frame
        } else {
            let mut frame = renderer.render_progressive_layers(width, height);
            for _ in 1..passes {
                frame = renderer.render_progressive_layers(width, height);
            }
            bar.finish_and_clear();
            frame?
        };
        let mut frame = frame;
        if output.needs_ids() {
            renderer.identify(&mut frame)?;
        }
        dimensions = (frame.width(), frame.height());
        save_frame(&frame, &args.output, &output)?
    } else {
        let image = match (stereo, args.adaptive) {
            (Some(stereo), _) => renderer.render_stereo(width, height, &stereo),
            (None, Some(passes)) => renderer
                .render_adaptive(width, height, passes, &EdgeThresholds::default())
                .map(|frame| {
                    refined = Some(format!(
                        "{:.1}% of the pixels refined by {passes} passes",
                        100.0 * frame.refined_fraction()
                    ));
                    frame.image
                }),
            (None, None) if passes > 1 => progressive(&mut renderer, width, height, passes),
            (None, None) => renderer.render(width, height),
        };
        bar.finish_and_clear();
        let image = image?;
        dimensions = image.dimensions();
        save_image(&image, &args.output)?;
        vec![args.output.clone()]
    };
    if let Some(path) = &args.camera_json {
        CameraExport::new(renderer.camera(), job.size)?.save(path)?;
    }
    if let Some(refined) = refined {
        println!("{refined}");
    }
    let passes = if passes > 1 && plain {
        format!(", {passes} passes")
    } else {
        String::new()
    };
    let (width, height) = dimensions;
    let others: Vec<String> = written[1..]
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    let others = if others.is_empty() {
        String::new()
    } else {
        format!(" (and {})", others.join(", "))
    };
    println!(
        "{}: {width}x{height}, {} quality{passes}, {:.2} s on {}{others}",
        args.output.display(),
        job.preset_name(),
        start.elapsed().as_secs_f64(),
        on_devices(&renderer)
    );
    Ok(())
}

/// `render --backend wgpu`: the image, in one frame or `--passes`
/// progressive passes, or a stereo pair, on the adapter wgpu chooses.
fn render_wgpu(args: &RenderArgs, job: &Job, stereo: Option<&Stereo>) -> Outcome {
    let opencl_only = [
        ("--aov", !args.aov.is_empty()),
        ("--bits 16", args.bits == "16"),
        ("--noise", args.noise.is_some()),
        ("--adaptive", args.adaptive.is_some()),
        ("--devices", job.devices.is_some()),
        ("--device", args.scene.device.is_some()),
        ("--deadline", args.scene.deadline.is_some()),
    ];
    if let Some((option, _)) = opencl_only.iter().find(|(_, asked)| *asked) {
        return Err(usage(format!(
            "{option} needs the OpenCL backend (--backend opencl): the wgpu backend renders \
             the image alone, each pass in one dispatch"
        )));
    }
    if image_extension(&args.output).ok().flatten().as_deref() == Some("exr") {
        return Err(usage(
            "the wgpu backend writes 8-bit images: write a .png, .jpg or .tif, or render the \
             .exr with the OpenCL backend (--backend opencl)",
        ));
    }
    let passes = args.passes.unwrap_or(1);
    let aperture = job.file.scene.camera.aperture;
    if stereo.is_none() && passes == 1 && aperture > 0.0 {
        eprintln!(
            "note: the camera has a lens (aperture {aperture}), whose blur one pass leaves \
             grainy: --passes {LENS_PASSES} renders a smooth one in {LENS_PASSES} times the time"
        );
    }
    let (width, height) = job.size;
    let start = Instant::now();
    let mut renderer = job.wgpu_renderer(&args.scene)?;
    let bar = spinner(format!("rendering {width}x{height} on wgpu"));
    let rendered = (|| {
        if let Some(stereo) = stereo {
            return render_stereo(&mut renderer, width, height, stereo);
        }
        let mut image = renderer.render_progressive(width, height)?;
        for _ in 1..passes {
            image = renderer.render_progressive(width, height)?;
        }
        Ok(image)
    })();
    bar.finish_and_clear();
    let image = rendered?;
    let adapter = &renderer.adapter().name;
    save_image(&image, &args.output)?;
    if let Some(path) = &args.camera_json {
        CameraExport::new(&job.file.scene.camera, job.size)?.save(path)?;
    }
    let passes = if passes > 1 && stereo.is_none() {
        format!(", {passes} passes")
    } else {
        String::new()
    };
    let (width, height) = image.dimensions();
    println!(
        "{}: {width}x{height}, {} quality{passes}, {:.2} s on {adapter} (wgpu)",
        args.output.display(),
        job.preset_name(),
        start.elapsed().as_secs_f64(),
    );
    Ok(())
}

/// The most progressive passes of `render --noise` without `--passes`.
const NOISE_PASSES: u32 = 1024;

/// The progressive passes the command suggests for a render through a
/// lens: enough for the gallery's lens scene at its own quality to show a
/// smooth blur.
const LENS_PASSES: u32 = 16;

/// The mean of `passes` progressive passes (fewer past the renderer's
/// sample limit, where the image has converged).
fn progressive(
    renderer: &mut Renderer,
    width: u32,
    height: u32,
    passes: u32,
) -> fractal_sdf::Result<image::RgbaImage> {
    let mut image = renderer.render_progressive(width, height)?;
    for _ in 1..passes {
        image = renderer.render_progressive(width, height)?;
    }
    Ok(image)
}

/// The quality to render with: `--preset`, else the scene file's own, else
/// the settings file's preset, else production.
fn quality(flag: Option<Preset>, file: &SceneFile, settings: &Settings) -> Quality {
    match (flag, file.quality, settings.preset) {
        (Some(preset), _, _) => preset.quality(),
        (None, Some(quality), _) => quality,
        (None, None, Some(preset)) => preset.quality(),
        (None, None, None) => Quality::production(),
    }
}

/// Every GPU of the machine, by its place in the list (identical GPUs are
/// each used once); every device where there is no GPU.
fn every_device() -> Outcome<Vec<DeviceSelector>> {
    let all = devices()?;
    let gpus: Vec<usize> = (0..all.len())
        .filter(|&i| all[i].kind == DeviceKind::Gpu)
        .collect();
    let chosen = if gpus.is_empty() {
        (0..all.len()).collect()
    } else {
        gpus
    };
    Ok(chosen.into_iter().map(DeviceSelector::at).collect())
}

/// The renderer's devices, for reports.
fn on_devices(renderer: &Renderer) -> String {
    let labels: Vec<String> = renderer.devices().iter().map(|d| d.label()).collect();
    labels.join(" + ")
}

/// `I/N` with `I < N`.
fn parse_shard(text: &str) -> Outcome<(u32, u32)> {
    text.split_once('/')
        .and_then(|(i, n)| Some((i.trim().parse().ok()?, n.trim().parse().ok()?)))
        .filter(|&(i, n): &(u32, u32)| n > 0 && i < n)
        .ok_or_else(|| usage(format!("--shard `{text}`: expected I/N with 0 <= I < N")))
}

fn read_path(file: &Path) -> Outcome<CameraPath> {
    let text = std::fs::read_to_string(file)
        .map_err(|source| Error::io(file, "cannot read the camera path", source))?;
    Ok(CameraPath::from_toml(&text)?)
}

/// One turn around the camera's target at its distance and height.
fn orbit(scene: &Scene, seconds: f64) -> Outcome<CameraPath> {
    let c = &scene.camera;
    let offset = c.position - c.target;
    let radius = offset.with_y(0.0).length().max(1e-3);
    Ok(CameraPath::orbit(c.target, radius, offset.y, seconds, 16)?)
}

fn sequence(args: &SequenceArgs, settings: &Settings) -> Outcome {
    let job = Job::new(&args.scene, settings)?;
    let path = match (&args.path, &job.file.path) {
        (Some(file), _) => read_path(file)?,
        (None, Some(path)) => path.clone(),
        (None, None) => orbit(&job.file.scene, args.seconds)?,
    };
    for (name, _) in &job.sets {
        let driven = job
            .file
            .motions
            .iter()
            .any(|m| m.values(0.0).iter().any(|(slot, _)| slot == name));
        if driven {
            return Err(usage(format!(
                "--set {name}: the scene's motions set `{name}` on every frame"
            )));
        }
    }
    let aovs = parse_aovs(&args.aov)?;
    let wgpu = Backend::chosen(args.backend, settings) == Backend::Wgpu;
    let layered = !aovs.is_empty() || args.format.eq_ignore_ascii_case("exr");
    let seq = Sequence::for_duration(&args.out, args.fps, path.duration())?
        .motion_blur(MotionBlur::new(args.motion_blur, args.shutter))?
        .format(&args.format)
        .map_err(|e| usage(format!("--format: {e}")))?
        .outputs(FrameOutput::new(job.options.effects).aovs(aovs));
    let range = match &args.frames {
        Some(text) => parse_range(text, seq.frames())?,
        None => 0..seq.frames(),
    };
    let shard = args.shard.as_deref().map(parse_shard).transpose()?;
    let mine = |i: &u32| shard.is_none_or(|(k, n)| i % n == k);
    if let Some(file) = &args.camera_json {
        let cameras = seq.camera_exports(&path, &job.file.scene.camera, job.size)?;
        CameraExport::save_all(&cameras, file)?;
    }

    if args.verify {
        let bad: Vec<String> = range
            .clone()
            .filter(mine)
            .filter_map(|i| {
                verify_image(seq.frame_path(i), job.size)
                    .err()
                    .map(|e| format!("  frame {i}: {e}"))
            })
            .collect();
        if bad.is_empty() {
            println!(
                "frames {}..{}{} in {}: all {} present and whole",
                range.start,
                range.end,
                shard.map_or_else(String::new, |(k, n)| format!(" (share {k}/{n})")),
                args.out.display(),
                range.clone().filter(mine).count()
            );
            return Ok(());
        }
        return Err(Failure {
            code: 1,
            message: format!(
                "{} of frames {}..{} are missing or broken:\n{}",
                bad.len(),
                range.start,
                range.end,
                bad.join("\n")
            ),
        });
    }

    if wgpu && layered {
        return Err(usage(
            "--aov and exr frames need the OpenCL backend (--backend opencl): the wgpu backend \
             writes 8-bit png, tif or jpg frames",
        ));
    }
    let todo: Vec<u32> = seq
        .remaining(range.clone(), job.size)
        .into_iter()
        .filter(mine)
        .collect();
    let share = range.clone().filter(mine).count();
    println!(
        "{}: frames {}..{} of {}{} at {} fps, {}x{}, {} quality -> {}/ ({} of {} on disk already)",
        args.scene.scene.label(),
        range.start,
        range.end,
        seq.frames(),
        shard.map_or_else(String::new, |(k, n)| format!(" (share {k}/{n})")),
        args.fps,
        job.size.0,
        job.size.1,
        job.preset_name(),
        args.out.display(),
        share - todo.len(),
        share,
    );
    if !todo.is_empty() {
        let bar = ProgressBar::new(todo.len() as u64);
        bar.set_style(
            ProgressStyle::with_template(
                "{bar:40} {pos}/{len} frames  {elapsed_precise} elapsed, ETA {eta}  {msg}",
            )
            .expect("a valid template"),
        );
        let on_frame = |frame: &RenderedFrame| {
            if let Some(t) = frame.timing {
                bar.set_message(format!("{:.0} ms/frame", t.total.as_secs_f64() * 1e3));
            }
            bar.inc(1);
        };
        let (motions, size) = (&job.file.motions, job.size);
        if wgpu {
            let mut renderer = job.wgpu_renderer(&args.scene)?;
            seq.render_images(&mut renderer, &path, motions, &todo, size, on_frame)?;
        } else {
            let mut renderer = job.renderer()?;
            seq.render(&mut renderer, &path, motions, &todo, size, on_frame)?;
        }
        bar.finish();
    }
    if seq.extension() == "exr" {
        if !args.no_video {
            println!("no video of OpenEXR frames: their colour is linear, before the tone curve");
        }
    } else if !args.no_video && seq.remaining(0..seq.frames(), job.size).is_empty() {
        let video = match (&args.video, args.out.file_name()) {
            (Some(video), _) => video.clone(),
            (None, Some(_)) => args.out.with_extension("mp4"),
            (None, None) => args.out.join("sequence.mp4"),
        };
        encode(&seq, &video);
    }
    Ok(())
}

fn encode(seq: &Sequence, video: &Path) {
    match seq.encode(video) {
        Encoded::Written => println!("video -> {}", video.display()),
        other => println!("{other}"),
    }
}

fn emit(args: &EmitArgs, settings: &Settings) -> Outcome {
    let file = load_scene(&args.scene)?;
    let preset = match &args.preset {
        Some(name) => Some(parse_preset(name).map_err(|e| usage(e.to_string()))?),
        None => None,
    };
    let options = Options::default()
        .quality(quality(preset, &file, settings))
        .effects(file.effects);
    let compiled = file.scene.compile()?;
    let kernel = match args.language {
        Language::Opencl => codegen::emit(&compiled, &options)?,
        Language::Wgsl => codegen::emit_wgsl(&compiled, &options)?,
    };
    write_out(&kernel.source)
}

/// Writes `text` to standard output. A reader that stops early
/// (`fractal-sdf emit mandelbulb | head`) ends the command quietly, as it
/// does other Unix tools, rather than with a panic.
fn write_out(text: &str) -> Outcome {
    use std::io::{ErrorKind, Write};
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != ErrorKind::BrokenPipe => Err(Failure {
            code: 1,
            message: format!("cannot write to standard output: {e}"),
        }),
        _ => Ok(()),
    }
}

fn list_devices() -> Outcome {
    // The wgpu backend's adapters (`render --backend wgpu`), whether or
    // not OpenCL has a platform here.
    let adapters = wgpu_adapters();
    if adapters.is_empty() {
        println!("wgpu: no adapter (on Linux, Mesa's lavapipe is mesa-vulkan-drivers)");
    }
    for a in &adapters {
        println!(
            "wgpu: {} ({:?}, {:?}, driver {} {})",
            a.name, a.backend, a.device_type, a.driver, a.driver_info
        );
    }
    let all = match devices() {
        Ok(all) => all,
        Err(e) if !adapters.is_empty() => {
            println!("OpenCL: {e}");
            return Ok(());
        }
        Err(e) => return Err(e.into()),
    };
    for (i, d) in all.iter().enumerate() {
        println!(
            "{i}: {} / {} ({:?}, {} compute units, {} MiB, fp64: {}, {})",
            d.platform,
            d.name,
            d.kind,
            d.compute_units,
            d.global_memory >> 20,
            if d.fp64 { "yes" } else { "no" },
            d.opencl_version
        );
    }
    println!(
        "automatic choice: {}",
        DeviceSelector::auto().resolve()?.label()
    );
    Ok(())
}

/// A timed frame: its median time, the fastest and slowest, and its
/// evaluations per pixel, all and in the primary march.
struct Timed {
    times: Vec<f64>,
    evaluations: f64,
    primary: f64,
}

impl Timed {
    fn median(&self) -> f64 {
        self.times
            .get(self.times.len() / 2)
            .copied()
            .unwrap_or(f64::NAN)
    }
}

/// Counts one frame's evaluations, then times `frames` more.
/// A renderer of either backend, as `bench` times it.
trait Timing {
    /// Renders a frame and returns each pixel's evaluations: all, and the
    /// primary march's.
    fn costs(&mut self, width: u32, height: u32) -> fractal_sdf::Result<(Vec<u32>, Vec<u32>)>;
    /// Renders a frame.
    fn frame(&mut self, width: u32, height: u32) -> fractal_sdf::Result<()>;
    /// The options it renders with.
    fn options(&self) -> &RenderOptions;
    /// Sets the effects.
    fn set_effects(&mut self, effects: Effects) -> fractal_sdf::Result<()>;
}

impl Timing for Renderer {
    fn costs(&mut self, width: u32, height: u32) -> fractal_sdf::Result<(Vec<u32>, Vec<u32>)> {
        let frame = self.render_with_aovs(width, height)?;
        Ok((frame.evaluations, frame.steps))
    }
    fn frame(&mut self, width: u32, height: u32) -> fractal_sdf::Result<()> {
        self.render(width, height).map(drop)
    }
    fn options(&self) -> &RenderOptions {
        Renderer::options(self)
    }
    fn set_effects(&mut self, effects: Effects) -> fractal_sdf::Result<()> {
        Renderer::set_effects(self, effects)
    }
}

impl Timing for WgpuRenderer {
    fn costs(&mut self, width: u32, height: u32) -> fractal_sdf::Result<(Vec<u32>, Vec<u32>)> {
        let frame = self.render_frame(width, height)?;
        Ok((frame.evaluations, frame.steps))
    }
    fn frame(&mut self, width: u32, height: u32) -> fractal_sdf::Result<()> {
        self.render(width, height).map(drop)
    }
    fn options(&self) -> &RenderOptions {
        WgpuRenderer::options(self)
    }
    fn set_effects(&mut self, effects: Effects) -> fractal_sdf::Result<()> {
        WgpuRenderer::set_effects(self, effects)
    }
}

fn time_frames(
    renderer: &mut impl Timing,
    size: (u32, u32),
    frames: u32,
) -> Result<Timed, Failure> {
    let (width, height) = size;
    let (evaluations, steps) = renderer.costs(width, height)?;
    let pixels = f64::from(width) * f64::from(height);
    let evaluations: f64 = evaluations.iter().map(|&e| f64::from(e)).sum();
    let primary: f64 = steps.iter().map(|&e| f64::from(e)).sum();
    let mut times = Vec::new();
    let bar = ProgressBar::new(u64::from(frames));
    for _ in 0..frames {
        let start = Instant::now();
        renderer.frame(width, height)?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
        bar.inc(1);
    }
    bar.finish_and_clear();
    times.sort_by(f64::total_cmp);
    Ok(Timed {
        times,
        evaluations: evaluations / pixels,
        primary: primary / pixels,
    })
}

/// One pixel in this many, each way, has its primary march's evaluations
/// counted for the cost of an evaluation.
const COUNTED_EVERY: u32 = 8;

/// Prints a timed frame's line: its median time and spread, its
/// evaluations per pixel and a second. Returns the evaluations a second,
/// in millions.
fn report(timed: &Timed, (width, height): (u32, u32)) -> f64 {
    let median = timed.median();
    let (low, high) = (
        timed.times.first().copied().unwrap_or(f64::NAN),
        timed.times.last().copied().unwrap_or(f64::NAN),
    );
    let pixels = f64::from(width) * f64::from(height);
    let rate = timed.evaluations * pixels / median / 1e3;
    println!(
        "  {:.1} ms/frame median of {} (min {low:.1}, max {high:.1}); {:.1} distance evaluations per pixel ({:.1} in the primary march); {rate:.1} million evaluations a second",
        median,
        timed.times.len(),
        timed.evaluations,
        timed.primary,
    );
    rate
}

fn bench(args: &BenchArgs, settings: &Settings) -> Outcome {
    let job = Job::new(&args.scene, settings)?;
    let (width, height) = job.size;
    if Backend::chosen(args.backend, settings) == Backend::Wgpu {
        let mut renderer = job.wgpu_renderer(&args.scene)?;
        let timed = time_frames(&mut renderer, job.size, args.frames)?;
        println!(
            "{}: {width}x{height}, {} quality on {} (wgpu)",
            args.scene.scene.label(),
            job.preset_name(),
            renderer.adapter().name
        );
        report(&timed, job.size);
        if args.stages {
            bench_stages(&mut renderer, job.size, args.frames)?;
        }
        return Ok(());
    }
    let mut renderer = job.renderer()?;
    let timed = time_frames(&mut renderer, job.size, args.frames)?;
    println!(
        "{}: {width}x{height}, {} quality on {}",
        args.scene.scene.label(),
        job.preset_name(),
        on_devices(&renderer)
    );
    let rate = report(&timed, job.size);
    let cost = renderer.evaluation_cost(width, height, COUNTED_EVERY)?;
    let peak = renderer.peak_flops()?;
    let flops = rate * 1e6 * cost.flops();
    println!(
        "  {:.0} operations an evaluation ({:.0} arithmetic and {:.1} calls at {CALL_FLOPS} each, counted by the CPU reference along the primary rays of one pixel in {COUNTED_EVERY}x{COUNTED_EVERY}): {:.2} GFLOP/s, {:.1}% of the {:.1} GFLOP/s this device reaches on fused multiply-adds",
        cost.flops(),
        cost.arithmetic(),
        cost.calls(),
        flops / 1e9,
        100.0 * flops / peak,
        peak / 1e9,
    );
    if args.stages {
        bench_stages(&mut renderer, job.size, args.frames)?;
    }
    Ok(())
}

/// Times the frame with the march, normals and shading alone, then with
/// each effect the scene has added in turn: what each stage costs.
fn bench_stages(renderer: &mut impl Timing, size: (u32, u32), frames: u32) -> Outcome {
    let full = renderer.options().effects;
    let quality = renderer.options().quality;
    let mut effects = full;
    effects.ambient_occlusion = false;
    effects.shadows = false;
    effects.glow = None;
    effects.volumetric = None;
    let mut stages = vec![("march, normals and shading", effects)];
    // An effect the quality leaves no samples or steps does nothing.
    if full.ambient_occlusion && quality.ao_samples > 0 {
        effects.ambient_occlusion = true;
        stages.push(("+ ambient occlusion", effects));
    }
    if full.shadows && quality.shadow_steps > 0 {
        effects.shadows = true;
        stages.push(("+ shadows", effects));
    }
    if full.glow.is_some() {
        effects.glow = full.glow;
        stages.push(("+ glow", effects));
    }
    if full.volumetric.is_some() && full.fog_density > 0.0 {
        effects.volumetric = full.volumetric;
        stages.push(("+ lit fog", effects));
    }
    println!("  stage                          ms/frame  added  evaluations/pixel  added");
    let mut before: Option<Timed> = None;
    for (name, effects) in stages {
        renderer.set_effects(effects)?;
        let timed = time_frames(renderer, size, frames)?;
        let (ms, evaluations) = (timed.median(), timed.evaluations);
        let (added_ms, added_evaluations) = before.as_ref().map_or((ms, evaluations), |b| {
            (ms - b.median(), evaluations - b.evaluations)
        });
        println!(
            "  {name:<30} {ms:>8.1} {added_ms:>6.1} {evaluations:>18.1} {added_evaluations:>6.1}"
        );
        before = Some(timed);
    }
    renderer.set_effects(full)?;
    Ok(())
}

fn compare(args: &CompareArgs) -> Outcome {
    let open = |path: &Path| {
        image::open(path)
            .map(|i| i.to_rgba8())
            .map_err(|e| Failure {
                code: 1,
                message: format!("{}: {e}", path.display()),
            })
    };
    let (a, b) = (open(&args.a)?, open(&args.b)?);
    if a.dimensions() != b.dimensions() {
        return Err(usage(format!(
            "the images differ in size: {}x{} and {}x{}",
            a.width(),
            a.height(),
            b.width(),
            b.height()
        )));
    }
    let differing = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
    println!(
        "PSNR {:.2} dB, SSIM {:.5}, {differing} of {} pixels differ",
        fractal_sdf::metrics::psnr(&a, &b),
        fractal_sdf::metrics::ssim(&a, &b),
        a.width() * a.height()
    );
    Ok(())
}

fn show_config(given: Option<&Path>, settings: fractal_sdf::Result<Settings>) -> Outcome {
    let path = given.map(Path::to_path_buf).or_else(Settings::path);
    match &path {
        Some(p) if p.exists() => println!("# settings file: {}", p.display()),
        Some(p) => println!("# settings file: {} (absent: every default)", p.display()),
        None => println!("# no configuration directory; set {CONFIG_ENV} to name a file"),
    }
    print!("{}", settings?.to_toml()?);
    Ok(())
}
