//! The `fractal-sdf` command: every subcommand run as a user runs it, and
//! its errors and exit codes.

mod gpu;
/// The Vulkan device of the crate's own WGSL tests: whether wgpu has an
/// adapter here (a failure where the run requires one).
#[path = "../src/codegen/wgsl_tests/device.rs"]
#[allow(dead_code)] // `run`, the distance tests' shader runner
mod wgpu_device;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use fractal_sdf::output::verify_png;
use fractal_sdf::sequence::frame_name;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fractal-sdf-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs the command with a settings file of `settings` (every default
/// when empty), so the user's own settings never apply.
fn run(dir: &Path, settings: &str, args: &[&str]) -> Output {
    let config = dir.join("config.toml");
    std::fs::write(&config, settings).unwrap();
    Command::new(env!("CARGO_BIN_EXE_fractal-sdf"))
        .args(args)
        .env("FRACTAL_SDF_CONFIG", &config)
        .output()
        .expect("the command runs")
}

fn text(out: &Output) -> String {
    format!(
        "status {:?}\nstdout:\n{}\nstderr:\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

fn scene_path(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(format!("{name}.ron"))
        .display()
        .to_string()
}

#[test]
fn render_writes_the_image_of_a_scene_file() {
    if gpu::device().is_none() {
        return;
    }
    let dir = scratch("render");
    let png = dir.join("csg.png");
    let out = run(
        &dir,
        "",
        &[
            "render",
            &scene_path("csg"),
            "-o",
            png.to_str().unwrap(),
            "--size",
            "64x48",
            "--preset",
            "draft",
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    verify_png(&png, (64, 48)).unwrap();
    let image = image::open(&png).unwrap().to_rgba8();
    assert!(image.pixels().any(|p| p != image.get_pixel(0, 0)), "blank");

    // The settings file's size applies where no flag is given, and `--set`
    // moves a dynamic parameter: a different image.
    let moved = dir.join("moved.png");
    let out = run(
        &dir,
        "size = \"40x30\"\npreset = \"draft\"\n",
        &[
            "render",
            "benchmark",
            "-o",
            moved.to_str().unwrap(),
            "--set",
            "orbit.y=1.0",
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    verify_png(&moved, (40, 30)).unwrap();
    let still = dir.join("still.png");
    let out = run(
        &dir,
        "size = \"40x30\"\npreset = \"draft\"\n",
        &["render", "benchmark", "-o", still.to_str().unwrap()],
    );
    assert!(out.status.success(), "{}", text(&out));
    assert_ne!(
        std::fs::read(&moved).unwrap(),
        std::fs::read(&still).unwrap()
    );
}

#[test]
fn render_takes_passes_a_lens_and_stereo() {
    if gpu::device().is_none() {
        return;
    }
    let dir = scratch("optics");
    let render = |name: &str, extra: &[&str]| {
        let png = dir.join(name);
        let mut args = vec!["render", "csg", "-o", png.to_str().unwrap()];
        args.extend(["--size", "40x30", "--preset", "preview"]);
        args.extend(extra);
        let out = run(&dir, "", &args);
        assert!(out.status.success(), "{extra:?}: {}", text(&out));
        png
    };
    let plain = render("plain.png", &[]);
    let passes = render("passes.png", &["--passes", "4"]);
    let two = render("two.png", &["--passes", "2"]);
    let lens = render(
        "lens.png",
        &["--aperture", "0.2", "--focus", "1", "--passes", "2"],
    );
    let bytes = |p: &Path| std::fs::read(p).unwrap();
    assert_ne!(
        bytes(&plain),
        bytes(&passes),
        "four passes smooth the edges"
    );
    assert_ne!(bytes(&two), bytes(&lens), "a lens blurs");
    verify_png(&lens, (40, 30)).unwrap();
    let pair = render(
        "pair.png",
        &["--stereo", "side-by-side", "--eye-separation", "0.2"],
    );
    verify_png(&pair, (80, 30)).unwrap();
    let over = render(
        "over.png",
        &["--stereo", "over-under", "--convergence", "3"],
    );
    verify_png(&over, (40, 60)).unwrap();
    let anaglyph = render("anaglyph.png", &["--stereo", "anaglyph"]);
    verify_png(&anaglyph, (40, 30)).unwrap();
    // Adaptive: every pixel the plain frame's or four passes', and some
    // of each.
    let adaptive = render("adaptive.png", &["--adaptive", "4"]);
    let read = |p: &Path| image::open(p).unwrap().to_rgba8();
    let (plain, passes, adaptive) = (read(&plain), read(&passes), read(&adaptive));
    let (mut kept, mut refined) = (0, 0);
    for ((a, p), q) in adaptive.pixels().zip(plain.pixels()).zip(passes.pixels()) {
        assert!(a == p || a == q, "{a:?} is neither {p:?} nor {q:?}");
        kept += usize::from(a == p && p != q);
        refined += usize::from(a == q && p != q);
    }
    assert!(kept > 0 && refined > 0, "{kept} kept, {refined} refined");
    // Bounces: the gallery's mirror and glass show the sky without any.
    let bounce = |n: &str| {
        let png = dir.join(format!("bounces-{n}.png"));
        let args = ["render", "materials", "-o", png.to_str().unwrap()];
        let out = run(
            &dir,
            "",
            &[&args[..], &["--size", "40x30", "--bounces", n]].concat(),
        );
        assert!(out.status.success(), "--bounces {n}: {}", text(&out));
        read(&png)
    };
    assert_ne!(bounce("0"), bounce("2"), "bounces show reflections");
    // Bad values: a clear error and no image.
    let o = dir.join("x.png");
    let o = o.to_str().unwrap();
    let cases: [(&[&str], i32, &str); 6] = [
        (&["--bounces", "9"], 1, "bounces"),
        (
            &["--stereo", "crossed"],
            2,
            "--stereo `crossed`: expected one of anaglyph",
        ),
        (
            &["--aperture=-1"],
            1,
            "aperture must be finite and >= 0, got -1",
        ),
        (&["--passes", "0"], 2, "--passes"),
        (
            &["--adaptive", "4", "--passes", "2"],
            2,
            "cannot be used with",
        ),
        (
            &["--stereo", "anaglyph", "--eye-separation=-1"],
            1,
            "eye separation",
        ),
    ];
    for (extra, code, says) in cases {
        let mut args = vec!["render", "csg", "-o", o, "--size", "8x8"];
        args.extend(extra);
        let out = run(&dir, "", &args);
        assert_eq!(out.status.code(), Some(code), "{extra:?}: {}", text(&out));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(says), "{extra:?}: {stderr}");
    }
    assert!(!Path::new(o).exists());
}

#[test]
fn sequence_shards_resume_and_verify() {
    if gpu::device().is_none() {
        return;
    }
    let dir = scratch("sequence");
    let frames = dir.join("frames");
    let f = frames.to_str().unwrap();
    let common = [
        "sequence",
        "csg",
        "--fps",
        "4",
        "--seconds",
        "1",
        "--size",
        "32x24",
        "--preset",
        "draft",
        "--out",
        f,
        "--no-video",
    ];
    let with = |extra: &[&str]| {
        let mut args = common.to_vec();
        args.extend_from_slice(extra);
        run(&dir, "", &args)
    };
    let out = with(&["--shard", "1/2"]);
    assert!(out.status.success(), "{}", text(&out));
    let on_disk = |i: u32| frames.join(frame_name(i)).exists();
    assert_eq!(
        (0..4).map(on_disk).collect::<Vec<_>>(),
        [false, true, false, true]
    );

    // The share verifies on its own.
    let out = with(&["--shard", "1/2", "--verify"]);
    assert!(out.status.success(), "{}", text(&out));
    // Half the frames: verify fails, listing the missing ones.
    let out = with(&["--verify"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("frame 0:") && stderr.contains("frame 2:"),
        "{stderr}"
    );

    // The other share renders only what is missing; then all verify.
    let before = std::fs::metadata(frames.join(frame_name(1)))
        .unwrap()
        .modified()
        .unwrap();
    let out = with(&[]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("2 of 4 on disk already"));
    let after = std::fs::metadata(frames.join(frame_name(1)))
        .unwrap()
        .modified()
        .unwrap();
    assert_eq!(before, after, "a whole frame was rendered again");
    let out = with(&["--verify"]);
    assert!(out.status.success(), "{}", text(&out));
}

/// `sequence --format exr --aov ...`: OpenEXR frames whose layers an
/// independent reader lists, verified whole, a frame cut short rendered
/// again on resume, and no video made of linear frames.
#[test]
fn sequence_writes_openexr_frames_with_layers() {
    if gpu::device().is_none() || gpu::oiiotool().is_none() {
        return;
    }
    let dir = scratch("sequence-exr");
    let frames = dir.join("frames");
    let args = [
        "sequence",
        "csg",
        "--fps",
        "4",
        "--seconds",
        "0.75",
        "--size",
        "24x16",
        "--preset",
        "draft",
        "--format",
        "exr",
        "--aov",
        "depth,object",
        "--out",
        frames.to_str().unwrap(),
    ];
    let out = run(&dir, "", &args);
    assert!(out.status.success(), "{}", text(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("no video of OpenEXR frames"));
    let frame = |i: u32| frames.join(format!("frame_{i:05}.exr"));
    for i in 0..3 {
        let (channels, pixels) = gpu::read_exr(&frame(i));
        assert_eq!(
            channels,
            ["R", "G", "B", "A", "depth.Z", "object.Y"],
            "frame {i}"
        );
        assert_eq!(pixels.len(), 24 * 16);
        // The csg scene's shapes: every hit is one of them.
        assert!(pixels.iter().any(|p| p[5] >= 1.0), "frame {i} has hits");
    }
    let verify = |extra: &[&str]| {
        let mut all = args.to_vec();
        all.extend_from_slice(extra);
        run(&dir, "", &all)
    };
    assert!(verify(&["--verify"]).status.success());
    // A frame cut short fails verification and is rendered again.
    let bytes = std::fs::read(frame(1)).unwrap();
    std::fs::write(frame(1), &bytes[..bytes.len() / 2]).unwrap();
    let out = verify(&["--verify"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    assert!(String::from_utf8_lossy(&out.stderr).contains("frame 1:"));
    let out = verify(&[]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("2 of 3 on disk already"));
    assert!(verify(&["--verify"]).status.success());
    // An unknown format is refused before anything renders.
    let mut bad = args.to_vec();
    bad[11] = "gif";
    let out = run(&dir, "", &bad);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--format"));
}

#[test]
fn emit_prints_only_what_the_scene_uses() {
    let dir = scratch("emit");
    let out = run(&dir, "", &["emit", "mandelbulb"]);
    assert!(out.status.success(), "{}", text(&out));
    let source = String::from_utf8_lossy(&out.stdout);
    assert!(source.contains("DE("), "{source}");
    assert!(source.contains("mandelbulb"), "no Mandelbulb");
    assert!(
        !source.contains("real menger("),
        "a Menger sponge in a Mandelbulb scene"
    );
    let out = run(&dir, "", &["emit", "mandelbulb", "--preset", "reference"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("typedef double real;"));

    // The settings' preset (reference: F64) applies to a file without a
    // quality of its own, not to one with (the gallery's: F32), and
    // `--preset` to both.
    let bare = dir.join("bare.ron");
    std::fs::write(&bare, "(version: 1, geometry: Sphere(radius: 1))").unwrap();
    let bare = bare.to_str().unwrap();
    let f64_source = |args: &[&str]| {
        let out = run(&dir, "preset = \"reference\"", args);
        assert!(out.status.success(), "{}", text(&out));
        String::from_utf8_lossy(&out.stdout).contains("typedef double real;")
    };
    assert!(f64_source(&["emit", bare]));
    assert!(!f64_source(&["emit", "mandelbulb"]));
    assert!(!f64_source(&["emit", bare, "--preset", "draft"]));
}

#[test]
fn emit_writes_a_scenes_functions_in_wgsl_and_refuses_double_precision() {
    let dir = scratch("emit-wgsl");
    let out = run(&dir, "", &["emit", "mandelbulb", "--language", "wgsl"]);
    assert!(out.status.success(), "{}", text(&out));
    let source = String::from_utf8_lossy(&out.stdout);
    assert!(source.contains("fn DE(p0: real3) -> real {"), "{source}");
    assert!(!source.contains("__kernel"), "a kernel in the WGSL module");
    let module = naga::front::wgsl::parse_str(&source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    // The reference preset computes in double precision, which WGSL
    // does not have: a typed error, exit code 1, nothing on stdout.
    let out = run(
        &dir,
        "",
        &[
            "emit",
            "mandelbulb",
            "--language",
            "wgsl",
            "--preset",
            "reference",
        ],
    );
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    assert!(out.stdout.is_empty());
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(
        message.contains("WGSL backend cannot") && message.contains("OpenCL"),
        "{message}"
    );
}

/// `render --backend wgpu` writes the image on the Vulkan adapter (Mesa's
/// lavapipe where there is no GPU), the picture the OpenCL backend draws,
/// path-traced scenes included; a double-precision preset and options
/// only the OpenCL backend has are errors that say so, exit code 1 or 2,
/// and no image.
#[test]
fn render_on_the_wgpu_backend_writes_the_opencl_picture() {
    if gpu::device().is_none() || wgpu_device::device().is_none() {
        return;
    }
    let dir = scratch("render-wgpu");
    let base = ["render", "mandelbulb", "--size", "48x36"];
    let with = |extra: &[&str], output: &str| {
        let output = dir.join(output);
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", output.to_str().unwrap()]);
        run(&dir, "", &args)
    };
    // The preview preset renders one pixel in 3 × 3 and scales the image
    // up, on either backend.
    let out = with(&["--backend", "wgpu", "--preset", "preview"], "wgpu.png");
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("(wgpu)"),
        "{}",
        text(&out)
    );
    let out = with(&["--preset", "preview"], "opencl.png");
    assert!(out.status.success(), "{}", text(&out));
    // The settings file chooses the backend where the command line does
    // not.
    let chosen = dir.join("chosen.png");
    let out = run(
        &dir,
        "backend = \"wgpu\"\n",
        &[
            "render",
            "csg",
            "--size",
            "32x24",
            "-o",
            chosen.to_str().unwrap(),
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("(wgpu)"),
        "{}",
        text(&out)
    );
    // And `bench` times either.
    let out = run(
        &dir,
        "",
        &[
            "bench",
            "csg",
            "--size",
            "32x24",
            "--preset",
            "draft",
            "--frames",
            "2",
            "--backend",
            "wgpu",
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(
        report.contains("(wgpu)") && report.contains("ms/frame median of 2"),
        "{report}"
    );
    let wgpu = image::open(dir.join("wgpu.png")).unwrap().to_rgba8();
    let opencl = image::open(dir.join("opencl.png")).unwrap().to_rgba8();
    let db = fractal_sdf::metrics::psnr(&wgpu, &opencl);
    assert!(db >= 40.0, "{db:.1} dB between the backends");

    for (extra, output, code, says) in [
        (
            &["--preset", "reference"][..],
            "f64.png",
            1,
            "double precision",
        ),
        (&["--aov", "depth"][..], "layers.png", 2, "--aov"),
    ] {
        let out = with(&[&["--backend", "wgpu"][..], extra].concat(), output);
        assert_eq!(out.status.code(), Some(code), "{}", text(&out));
        let message = String::from_utf8_lossy(&out.stderr);
        assert!(
            message.contains(says) && message.contains("OpenCL"),
            "{message}"
        );
        assert!(!dir.join(output).exists());
    }
    // A path-traced scene.
    let path_traced = dir.join("gi.png");
    let out = run(
        &dir,
        "",
        &[
            "render",
            "gi",
            "--size",
            "16x12",
            "--backend",
            "wgpu",
            "-o",
            path_traced.to_str().unwrap(),
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    let drawn = image::open(&path_traced).unwrap().to_rgba8();
    assert_eq!(drawn.dimensions(), (16, 12));
    // A stereo pair, side by side: both eyes, as OpenCL lays them out.
    let out = with(
        &["--backend", "wgpu", "--stereo", "side-by-side"],
        "pair_wgpu.png",
    );
    assert!(out.status.success(), "{}", text(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("96x36"));
    let out = with(&["--stereo", "side-by-side"], "pair_opencl.png");
    assert!(out.status.success(), "{}", text(&out));
    let pair = |name: &str| image::open(dir.join(name)).unwrap().to_rgba8();
    let db = fractal_sdf::metrics::psnr(&pair("pair_wgpu.png"), &pair("pair_opencl.png"));
    assert!(db >= 40.0, "{db:.1} dB between the stereo pairs");
}

/// `sequence --backend wgpu` renders the frames on the wgpu backend, with
/// motion blur, as the OpenCL backend renders them; layered frames are a
/// usage error naming the OpenCL backend.
#[test]
fn sequence_on_the_wgpu_backend_is_the_opencl_sequence() {
    if gpu::device().is_none() || wgpu_device::device().is_none() {
        return;
    }
    let dir = scratch("sequence-wgpu");
    let frames = |backend: &str, out: &str, extra: &[&str]| {
        let out_dir = dir.join(out);
        let mut args = vec![
            "sequence",
            "mandelbulb",
            "--size",
            "48x36",
            "--preset",
            "preview",
            "--fps",
            "3",
            "--seconds",
            "1",
            "--motion-blur",
            "3",
            "--no-video",
            "--backend",
            backend,
            "--out",
            out_dir.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        run(&dir, "", &args)
    };
    let out = frames("wgpu", "wgpu", &[]);
    assert!(out.status.success(), "{}", text(&out));
    let out = frames("opencl", "opencl", &[]);
    assert!(out.status.success(), "{}", text(&out));
    for i in 0..3 {
        let frame = |backend: &str| {
            image::open(dir.join(backend).join(format!("frame_{i:05}.png")))
                .unwrap()
                .to_rgba8()
        };
        let db = fractal_sdf::metrics::psnr(&frame("wgpu"), &frame("opencl"));
        assert!(db >= 40.0, "frame {i}: {db:.1} dB between the backends");
    }
    let out = frames("wgpu", "exr", &["--format", "exr"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--backend opencl"));
    assert!(!dir.join("exr").join("frame_00000.exr").exists());
}

#[test]
fn devices_and_bench_report_the_device() {
    let Some(device) = gpu::device() else {
        return;
    };
    let dir = scratch("devices");
    let out = run(&dir, "", &["devices"]);
    assert!(out.status.success(), "{}", text(&out));
    let listing = String::from_utf8_lossy(&out.stdout);
    assert!(listing.contains(&device.name), "{listing}");
    assert!(listing.contains("fp64: "), "{listing}");
    if wgpu_device::device().is_some() {
        // The wgpu backend's adapters too.
        assert!(listing.contains("wgpu: "), "{listing}");
    }

    let out = run(
        &dir,
        "",
        &[
            "bench",
            "sierpinski",
            "--size",
            "32x24",
            "--preset",
            "draft",
            "--frames",
            "2",
            "--stages",
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(report.contains("ms/frame median of 2"), "{report}");
    assert!(
        report.contains("distance evaluations per pixel"),
        "{report}"
    );
    // The rate is the frame's evaluations over its median time (within
    // the rounding of the printed numbers).
    let before = |marker: &str| -> f64 {
        let head = &report[..report.find(marker).expect(marker)];
        let word = head.split_whitespace().last().expect("a number");
        word.parse()
            .unwrap_or_else(|_| panic!("{word} before {marker}"))
    };
    let (ms, per_pixel) = (before("ms/frame"), before("distance evaluations per pixel"));
    let rate = before("million evaluations a second");
    // Each printed number is rounded to a tenth.
    let pixels = 32.0 * 24.0 / 1e3;
    let low = (per_pixel - 0.05) * pixels / (ms + 0.05) - 0.05;
    let high = (per_pixel + 0.05) * pixels / (ms - 0.05).max(0.01) + 0.05;
    assert!(
        (low..=high).contains(&rate),
        "{rate} outside {low}..{high}: {report}"
    );
    // The operations a second are the rate times the operations an
    // evaluation, and their share of the measured peak what it says.
    let (ops, gflops) = (before("operations an evaluation"), before("GFLOP/s, "));
    assert!(ops > 10.0, "{report}");
    let expected = rate * ops / 1e3;
    assert!(
        (gflops - expected).abs() <= 0.005 + 0.06 * ops / 1e3 + 0.001 * expected,
        "{gflops} GFLOP/s against {rate} million evaluations of {ops}: {report}"
    );
    let share = before("% of the");
    let peak = before("GFLOP/s this device reaches");
    assert!(peak > 0.0, "{report}");
    assert!(
        (share - 100.0 * gflops / peak).abs() <= 0.05 + 100.0 * 0.005 / peak + 0.01 * share,
        "{share}% of {peak}: {report}"
    );
    // The stages: the march alone first, its time and evaluations.
    assert!(report.contains("march, normals and shading"), "{report}");
}

#[test]
fn config_shows_the_settings_in_effect() {
    let dir = scratch("config");
    let out = run(
        &dir,
        "preset = \"reference\"\n[viewer]\nmouse_sensitivity = 0.002\n",
        &["config"],
    );
    assert!(out.status.success(), "{}", text(&out));
    let shown = String::from_utf8_lossy(&out.stdout);
    assert!(shown.contains("config.toml"), "{shown}");
    assert!(shown.contains("preset = \"reference\""), "{shown}");
    assert!(shown.contains("mouse_sensitivity = 0.002"), "{shown}");
}

#[test]
fn bad_input_is_a_clear_error_and_a_nonzero_exit() {
    let dir = scratch("errors");
    let bad = dir.join("bad.ron");
    std::fs::write(&bad, "(version: 1,\n  geometry: Sphere(radius: -2))").unwrap();
    let png = dir.join("x.png");
    let o = png.to_str().unwrap();
    let jpg = dir.join("x.jpg");
    let j = jpg.to_str().unwrap();
    let exr = dir.join("x.exr");
    let e = exr.to_str().unwrap();
    let cases: [(&[&str], &str, i32, &str); 16] = [
        (
            &["render", "csg", "-o", o, "--aov", "depth,nrml"],
            "",
            2,
            "`nrml` is not an output; the outputs are depth, normal",
        ),
        (
            &["render", "csg", "-o", o, "--tonemap", "aces"],
            "",
            2,
            "--tonemap `aces`: expected one of clip, reinhard, filmic",
        ),
        (
            &["render", "csg", "-o", j, "--bits", "16"],
            "",
            2,
            "holds 8 bits per channel",
        ),
        (
            &["render", "csg", "-o", e, "--bits", "16"],
            "",
            2,
            "holds 32-bit floats",
        ),
        (
            &["render", "csg", "-o", e, "--stereo", "anaglyph"],
            "",
            2,
            "--stereo writes an 8-bit composite",
        ),
        (
            &["render", "csg", "-o", o, "--exposure", "40"],
            "",
            1,
            "exposure",
        ),
        (
            &["render", bad.to_str().unwrap(), "-o", o],
            "",
            1,
            "bad.ron:2:13: sphere",
        ),
        (
            &["render", "nosuch", "-o", o],
            "",
            2,
            "neither a scene file nor a gallery scene",
        ),
        (
            &["render", "csg", "-o", o, "--size", "0x5"],
            "",
            2,
            "not a size",
        ),
        (
            &["render", "csg", "-o", o, "--preset", "ultra"],
            "",
            2,
            "unknown preset",
        ),
        (
            &["render", "csg", "-o", o, "--set", "radius"],
            "",
            2,
            "expected NAME=VALUE",
        ),
        (
            &["render", "benchmark", "-o", o, "--set", "orbit=1"],
            "",
            1,
            "no dynamic parameter named `orbit`; it has `orbit.x`, `orbit.y`, `orbit.z`",
        ),
        (
            &["render", "csg", "-o", o],
            "presett = 1",
            1,
            "config.toml:1:1",
        ),
        (&["config"], "presett = 1", 1, "config.toml:1:1"),
        (
            &["render", "csg", "-o", o, "--devices", "pthread,,"],
            "",
            2,
            "an empty device name",
        ),
        (
            &["sequence", "fractal_mix", "--out", o, "--set", "power=4"],
            "",
            2,
            "motions set `power`",
        ),
    ];
    for (args, settings, code, says) in cases {
        let out = run(&dir, settings, args);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {}", text(&out));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
    assert!(!png.exists(), "an image was written despite the errors");
    assert!(
        !jpg.exists() && !exr.exists(),
        "an image was written despite the errors"
    );
    // A bad settings file does not stop `devices`, which does not read it.
    if gpu::device().is_some() {
        let out = run(&dir, "presett = 1", &["devices"]);
        assert!(out.status.success(), "{}", text(&out));
    }
}

/// `mesh --backend wgpu` samples the scene's WGSL `DE` through wgpu: a
/// closed mesh with the triangles the OpenCL device's has, within the
/// roundings of single precision; `--f64` with it is a usage error.
#[test]
fn mesh_on_the_wgpu_backend_is_the_opencl_mesh() {
    if gpu::device().is_none() || wgpu_device::device().is_none() {
        return;
    }
    let dir = scratch("mesh-wgpu");
    let mesh = |name: &str, extra: &[&str]| {
        let file = dir.join(name);
        let mut args = vec![
            "mesh",
            "julia",
            "--resolution",
            "32",
            "-o",
            file.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        (run(&dir, "", &args), file)
    };
    let (out, wgpu) = mesh("wgpu.stl", &["--backend", "wgpu"]);
    assert!(out.status.success(), "{}", text(&out));
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        said.contains("closed 2-manifold") && said.contains("wgpu"),
        "{said}"
    );
    let (out, opencl) = mesh("opencl.stl", &[]);
    assert!(out.status.success(), "{}", text(&out));
    let faces = |path: &Path| {
        let mut file = std::fs::File::open(path).unwrap();
        stl_io::read_stl(&mut file).unwrap().faces.len()
    };
    let (a, b) = (faces(&wgpu), faces(&opencl));
    assert!(a.abs_diff(b) * 200 <= b, "{a} against {b} triangles");
    let (out, _) = mesh("f64.stl", &["--backend", "wgpu", "--f64"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(String::from_utf8_lossy(&out.stderr).contains("single precision"));
}

#[test]
fn mesh_and_volume_write_files_and_refuse_bad_grids() {
    if gpu::device().is_none() {
        return;
    }
    let dir = scratch("mesh");
    let stl = dir.join("julia.stl");
    let out = run(
        &dir,
        "",
        &[
            "mesh",
            "julia",
            "-o",
            stl.to_str().unwrap(),
            "--resolution",
            "32",
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(said.contains("triangles") && said.contains("32x"), "{said}");
    assert!(
        said.contains("closed 2-manifold, every vertex at its own position"),
        "{said}"
    );
    let mut file = std::fs::File::open(&stl).unwrap();
    let mesh = stl_io::read_stl(&mut file).unwrap();
    assert!(mesh.faces.len() > 1000, "{} faces", mesh.faces.len());

    // A floor has no bound: the error names the box of the rest, and that
    // box works.
    let ply = dir.join("menger.ply");
    let ply_arg = ply.to_str().unwrap();
    let out = run(
        &dir,
        "",
        &["mesh", "menger", "-o", ply_arg, "--resolution", "24"],
    );
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(
        said.contains("no bound") && said.contains("-1.732"),
        "{said}"
    );
    let bounds = "--bounds=-1.8,-0.99,-1.8,1.8,1.8,1.8";
    let out = run(
        &dir,
        "",
        &[
            "mesh",
            "menger",
            "-o",
            ply_arg,
            "--resolution",
            "24",
            bounds,
            "--cpu",
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        std::fs::read(&ply)
            .unwrap()
            .starts_with(b"ply\nformat binary_little_endian")
    );

    let nrrd = dir.join("bulb.nrrd");
    let slices = dir.join("slices");
    let out = run(
        &dir,
        "",
        &[
            "volume",
            "mandelbulb",
            "-o",
            nrrd.to_str().unwrap(),
            "--slices",
            slices.to_str().unwrap(),
            "--resolution",
            "20",
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    let written = std::fs::read(&nrrd).unwrap();
    assert!(written.starts_with(b"NRRD0004\n"));
    assert!(String::from_utf8_lossy(&written[..200]).contains("\n# clamped to +-"));
    assert_eq!(std::fs::read_dir(&slices).unwrap().count(), 21);
    // The help names the band the values are clamped to.
    let out = run(&dir, "", &["volume", "--help"]);
    let band = format!(
        "clamped to ±{} sample spacings",
        fractal_sdf::mesh::BAND_VOXELS
    );
    assert!(text(&out).contains(&band), "{}", text(&out));

    for (args, code, says) in [
        (
            vec!["mesh", "julia", "-o", "x.gltf"],
            1,
            ".stl, .ply or .obj",
        ),
        (
            vec!["mesh", "julia", "-o", "x.stl", "--resolution", "0"],
            1,
            "grid resolution",
        ),
        (
            vec!["mesh", "julia", "-o", "x.stl", "--bounds", "1,2,3"],
            2,
            "six numbers",
        ),
        (
            vec!["mesh", "julia", "-o", "x.stl", "--bounds=0,0,0,-1,1,1"],
            1,
            "min < max",
        ),
        (vec!["volume", "julia"], 2, "--output"),
    ] {
        let out = run(&dir, "", &args);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {}", text(&out));
        assert!(
            String::from_utf8_lossy(&out.stderr).contains(says),
            "{args:?}: {}",
            text(&out)
        );
    }
}

/// Regression: `-o x.jpg` wrote PNG bytes into a `.jpg` file. The format
/// follows the extension, and an extension no format has is refused
/// before anything renders.
#[test]
fn the_image_format_follows_the_output_extension() {
    let dir = scratch("formats");
    let xyz = dir.join("out.xyz");
    let out = run(
        &dir,
        "",
        &[
            "render",
            "mandelbulb",
            "-o",
            xyz.to_str().unwrap(),
            "--size",
            "8x6",
        ],
    );
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(".xyz") && stderr.contains(".png, .jpg, .jpeg, .tif, .tiff, .exr"),
        "{stderr}"
    );
    assert!(!xyz.exists());
    if gpu::device().is_none() {
        return;
    }
    for (name, magic) in [
        ("out.jpg", &[0xff, 0xd8, 0xff][..]),
        ("out.PNG", b"\x89PNG"),
        ("out.tif", b"II*\0"),
        ("out.exr", &[0x76, 0x2f, 0x31, 0x01][..]),
    ] {
        let path = dir.join(name);
        let out = run(
            &dir,
            "",
            &[
                "render",
                "primitives",
                "--preset",
                "draft",
                "--size",
                "16x12",
                "-o",
                path.to_str().unwrap(),
            ],
        );
        assert!(out.status.success(), "{}", text(&out));
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..magic.len()], magic, "{name}");
    }
}

/// Regression: a scene with a lens rendered in one pass was grainy with no
/// hint of the passes its blur needs.
#[test]
fn a_lens_rendered_in_one_pass_says_how_many_passes_it_needs() {
    if gpu::device().is_none() {
        return;
    }
    let dir = scratch("lens-note");
    let png = dir.join("lens.png");
    let png = png.to_str().unwrap();
    let lens = [
        "render",
        "primitives",
        "--aperture",
        "0.05",
        "--preset",
        "draft",
        "--size",
        "16x12",
        "-o",
        png,
    ];
    let out = run(&dir, "", &lens);
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--passes 16"),
        "{}",
        text(&out)
    );
    let out = run(&dir, "", &[&lens[..], &["--passes", "2"]].concat());
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        !String::from_utf8_lossy(&out.stderr).contains("--passes"),
        "{}",
        text(&out)
    );
}

/// A scene file with a text formula renders; `--set` moves its dynamic
/// parameter; `--formula` renders and meshes a shape with no scene file
/// and no `--bounds`; a formula's mistake is located.
#[test]
fn text_formulas_render_from_files_and_the_command_line() {
    if gpu::device().is_none() {
        return;
    }
    let dir = scratch("formula");
    let render = |name: &str, extra: &[&str]| {
        let png = dir.join(name);
        let mut args = vec![
            "render",
            "-o",
            png.to_str().unwrap(),
            "--size",
            "64x48",
            "--preset",
            "draft",
        ];
        args.extend_from_slice(extra);
        let out = run(&dir, "", &args);
        assert!(out.status.success(), "{}", text(&out));
        verify_png(&png, (64, 48)).unwrap();
        image::open(&png).unwrap().to_rgba8()
    };
    let scene = scene_path("custom_formula");
    let calm = render("calm.png", &[&scene]);
    assert!(calm.pixels().any(|p| p != calm.get_pixel(0, 0)), "blank");
    let rippled = render("rippled.png", &[&scene, "--set", "ripple=0.2"]);
    assert_ne!(calm, rippled, "--set ripple changed nothing");

    let cube = render(
        "cube.png",
        &[
            "--formula",
            "let q = abs(p) - vec3(0.5, 0.5, 0.5); max(q.x, max(q.y, q.z))",
        ],
    );
    assert_ne!(
        cube.get_pixel(32, 24),
        cube.get_pixel(1, 1),
        "the cube is not drawn"
    );

    let stl = dir.join("ball.stl");
    let out = run(
        &dir,
        "",
        &[
            "mesh",
            "--formula",
            "length(p) - 1",
            "-o",
            stl.to_str().unwrap(),
            "--resolution",
            "32",
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    assert!(text(&out).contains("closed 2-manifold"), "{}", text(&out));

    let out = run(
        &dir,
        "",
        &["render", "--formula", "length(p) -", "-o", "x.png"],
    );
    assert!(!out.status.success());
    assert!(
        text(&out).contains("line 1, column 12: expected a number"),
        "{}",
        text(&out)
    );
}

#[test]
fn nodes_lists_every_node_as_text_and_json() {
    let dir = scratch("nodes");
    let out = run(&dir, "", &["nodes"]);
    assert!(out.status.success(), "{}", text(&out));
    let listing = String::from_utf8_lossy(&out.stdout);
    for line in [
        "  Sphere: radius (>= 0)",
        "  Ellipsoid [bound]:",
        "  Kifs: fold (Tetrahedral,",
    ] {
        assert!(listing.contains(line), "no `{line}` in:\n{listing}");
    }
    let json = run(&dir, "", &["nodes", "--json"]);
    assert!(json.status.success(), "{}", text(&json));
    let json = String::from_utf8_lossy(&json.stdout);
    // One object per node the library lists, each with its fields.
    let nodes = fractal_sdf::file::node_kinds();
    assert!(json.trim_start().starts_with('[') && json.trim_end().ends_with(']'));
    assert_eq!(json.matches("\"name\":").count(), nodes.len(), "{json}");
    assert_eq!(json.matches("\"fields\":").count(), nodes.len());
    let exact = json.matches("\"exact\": true").count();
    assert_eq!(
        exact,
        nodes.iter().filter(|n| n.exact == Some(true)).count()
    );
    assert!(exact >= 14, "{exact} exact primitives");
    assert!(
        json.contains(
            "\"name\": \"CutSphere\",\n    \"category\": \"primitive\",\n    \"exact\": true"
        ),
        "{json}"
    );
    assert!(json.contains("\"exact\": null"));
}

#[test]
fn a_reader_that_stops_early_ends_the_command_quietly() {
    // `fractal-sdf emit mandelbulb | head -1`: the pipe closes before the
    // kernel's source is written.
    for args in [
        &["emit", "mandelbulb"][..],
        &["nodes"],
        &["nodes", "--json"],
    ] {
        let dir = scratch("pipe");
        std::fs::write(dir.join("config.toml"), "").unwrap();
        let mut child = Command::new(env!("CARGO_BIN_EXE_fractal-sdf"))
            .args(args)
            .env("FRACTAL_SDF_CONFIG", dir.join("config.toml"))
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        assert!(out.status.success(), "{args:?}: {}", text(&out));
        assert!(out.stderr.is_empty(), "{args:?}: {}", text(&out));
    }
}

/// `--aov`, `--bits 16`, `--exposure`, `--tonemap` and `--camera-json`:
/// an OpenEXR file whose layers an independent reader lists, a 16-bit PNG
/// with an output PNG beside it, and cameras for one frame and for a whole
/// sequence.
#[test]
fn render_writes_layers_deep_images_and_cameras() {
    if gpu::device().is_none() || gpu::oiiotool().is_none() {
        return;
    }
    let dir = scratch("layers");
    let exr = dir.join("bulb.exr");
    let camera = dir.join("bulb.json");
    let small = ["--preset", "draft", "--size", "24x16"];
    let mut args = vec![
        "render",
        "mandelbulb",
        "-o",
        exr.to_str().unwrap(),
        "--aov",
        "depth,normal,albedo",
        "--exposure",
        "-0.5",
        "--tonemap",
        "filmic",
        "--camera-json",
        camera.to_str().unwrap(),
    ];
    args.extend(small);
    let out = run(&dir, "", &args);
    assert!(out.status.success(), "{}", text(&out));
    let (channels, pixels) = gpu::read_exr(&exr);
    for name in [
        "R", "G", "B", "A", "depth.Z", "normal.X", "normal.Z", "albedo.G",
    ] {
        assert!(channels.iter().any(|c| c == name), "{name} in {channels:?}");
    }
    assert_eq!(channels.len(), 11);
    assert_eq!(pixels.len(), 24 * 16);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&camera).unwrap()).unwrap();
    assert_eq!(json["format"], "fractal-sdf camera");
    assert_eq!(
        (json["width"].as_u64(), json["height"].as_u64()),
        (Some(24), Some(16))
    );

    let png = dir.join("deep.png");
    let mut args = vec![
        "render",
        "mandelbulb",
        "-o",
        png.to_str().unwrap(),
        "--bits",
        "16",
        "--aov",
        "depth",
    ];
    args.extend(small);
    let out = run(&dir, "", &args);
    assert!(out.status.success(), "{}", text(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("deep.depth.png"));
    let deep = image::open(&png).unwrap();
    assert!(matches!(deep, image::DynamicImage::ImageRgba16(_)));
    let depth = image::open(dir.join("deep.depth.png")).unwrap();
    assert!(matches!(depth, image::DynamicImage::ImageLuma16(_)));

    // A sequence's cameras: every frame's, whichever frames render.
    let cameras = dir.join("cameras.json");
    let frames = dir.join("frames");
    let out = run(
        &dir,
        "",
        &[
            "sequence",
            "csg",
            "--fps",
            "4",
            "--seconds",
            "1",
            "--frames",
            "0..1",
            "--size",
            "16x12",
            "--preset",
            "draft",
            "--out",
            frames.to_str().unwrap(),
            "--no-video",
            "--camera-json",
            cameras.to_str().unwrap(),
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    let all: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(&cameras).unwrap()).unwrap();
    assert_eq!(all.len(), 4);
    for (i, c) in all.iter().enumerate() {
        assert_eq!(c["frame"].as_u64(), Some(i as u64));
        assert_eq!(c["time"].as_f64(), Some(i as f64 / 4.0));
    }
    // An orbit: the camera moves from frame to frame.
    assert_ne!(all[0]["position"], all[1]["position"]);
}

/// `--gi`, `--environment`, `--noise` and `--srgb`: a path-traced render
/// lit by the crate's sky that stops at its noise and says so, the furnace
/// vanishing from the command line, the sRGB curve changing the image, and
/// a missing environment image named in a clear error.
#[test]
fn render_path_traces_under_an_environment_until_quiet() {
    if gpu::device().is_none() {
        return;
    }
    let dir = scratch("gi");
    let sky = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/sky.hdr")
        .display()
        .to_string();
    let lit = dir.join("lit.png");
    let small = ["--preset", "draft", "--size", "32x24"];
    let mut args = vec![
        "render",
        "csg",
        "-o",
        lit.to_str().unwrap(),
        "--gi",
        "4",
        "--environment",
        &sky,
        "--noise",
        "0.05",
        "--passes",
        "64",
    ];
    args.extend(small);
    let out = run(&dir, "", &args);
    assert!(out.status.success(), "{}", text(&out));
    assert!(text(&out).contains("noise 0.0"), "{}", text(&out));
    assert!(lit.exists());

    let furnace = dir.join("furnace.png");
    let furnace_file = scene_path("furnace");
    let out = run(
        &dir,
        "",
        &[
            "render",
            &furnace_file,
            "-o",
            furnace.to_str().unwrap(),
            "--size",
            "24x16",
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    let image = image::open(&furnace).unwrap().to_rgba8();
    assert!(
        image.pixels().all(|p| p.0 == [255, 255, 255, 255]),
        "the furnace shows"
    );

    let shade = |name: &str, extra: &[&str]| {
        let path = dir.join(name);
        let mut args = vec!["render", "csg", "-o", path.to_str().unwrap()];
        args.extend(small);
        args.extend(extra);
        let out = run(&dir, "", &args);
        assert!(out.status.success(), "{}", text(&out));
        image::open(&path).unwrap().to_rgba8()
    };
    assert_ne!(shade("gamma.png", &[]), shade("srgb.png", &["--srgb"]));

    let out = run(
        &dir,
        "",
        &[
            "render",
            "csg",
            "-o",
            "x.png",
            "--environment",
            "nowhere.hdr",
        ],
    );
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    assert!(
        text(&out).contains("nowhere.hdr: cannot read the environment image"),
        "{}",
        text(&out)
    );
}
