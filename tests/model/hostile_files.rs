//! Hostile input through the public API — files, memory and messages: a
//! killed write, a truncated frame, links, full and unwritable targets,
//! zero, huge and odd sizes, overflowing frame and keyframe counts and
//! script numbers. Each gives a typed, readable error or correct output;
//! none crashes, hangs or writes something wrong silently.

use crate::gpu;

use std::fs::{self, File};
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

use fractal_sdf::animation::{CameraPath, Keyframe};
use fractal_sdf::file::SceneFile;
use fractal_sdf::image::{self, Rgba, RgbaImage};
use fractal_sdf::output::{STALE_TEMPORARY_AGE, save_png, verify_png};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Glow;
use fractal_sdf::sequence::{Sequence, parse_range};
use fractal_sdf::view::{FrameStats, KeyScript};

fn scratch(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("fractal-sdf-hostile-{name}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn picture(width: u32, height: u32) -> RgbaImage {
    RgbaImage::from_fn(width, height, |x, y| {
        Rgba([(x * 7) as u8, (y * 13) as u8, (x ^ y) as u8, 255])
    })
}

/// `err` is an [`Error::Io`] naming exactly `target`, whose message says
/// `what`; returns the message.
fn io_error_naming(err: &Error, target: &Path, what: &str) -> String {
    let text = err.to_string();
    match err {
        Error::Io { path, .. } => assert_eq!(path, target, "{text}"),
        other => panic!("expected Error::Io for {}, got {other:?}", target.display()),
    }
    assert!(
        text.starts_with(&format!("{}: ", target.display())),
        "{text}"
    );
    assert!(text.contains(what), "{what:?} not in {text}");
    text
}

/// A process id that no process has.
fn dead_pid() -> u32 {
    (4_000_000..u32::MAX)
        .find(|pid| !Path::new(&format!("/proc/{pid}")).exists())
        .unwrap()
}

// ---------------------------------------------------------------- files

#[test]
fn a_killed_writes_temporary_files_are_removed_by_the_next_write() {
    let dir = scratch("stale");
    let target = dir.join("img.png");
    let temp = |pid: u32, n: u32| dir.join(format!(".img.png.{pid}-{n}.png.tmp"));
    let has_proc = Path::new("/proc/self").exists();
    // Left by a writer that was killed: its process is gone.
    let dead = temp(dead_pid(), 0);
    fs::write(&dead, vec![0u8; 4096]).unwrap();
    // A live process (init) writing: kept...
    let live = temp(1, 3);
    fs::write(&live, b"in flight").unwrap();
    // ...unless nobody wrote to it for the stale age.
    let abandoned = temp(1, 4);
    fs::write(&abandoned, b"old").unwrap();
    File::options()
        .write(true)
        .open(&abandoned)
        .unwrap()
        .set_modified(SystemTime::now() - STALE_TEMPORARY_AGE - Duration::from_secs(1))
        .unwrap();
    // This process's id, but not written by it: an earlier process that
    // had the same id (as in a container, where ids repeat).
    let reused = temp(std::process::id(), 999_999_999);
    fs::write(&reused, b"x").unwrap();
    // Another image's stale temporary file, and files that only look alike.
    let other = dir.join(format!(".other.png.{}-1.png.tmp", dead_pid()));
    fs::write(&other, b"x").unwrap();
    for keep in ["notes.png.tmp", ".img.png.12x-1.png.tmp", ".img.png"] {
        fs::write(dir.join(keep), b"mine").unwrap();
    }
    save_png(&picture(9, 7), &target).unwrap();
    assert_eq!(image::open(&target).unwrap().to_rgba8(), picture(9, 7));
    let left = names(&dir);
    assert!(!abandoned.exists() && !reused.exists(), "{left:?}");
    assert!(live.exists(), "a live writer's file is kept: {left:?}");
    if has_proc {
        assert_eq!(
            left,
            [
                ".img.png",
                ".img.png.1-3.png.tmp",
                ".img.png.12x-1.png.tmp",
                "img.png",
                "notes.png.tmp"
            ]
        );
    }
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_truncated_frame_is_not_done_and_is_rendered_again() {
    let dir = scratch("resume");
    let size = (24, 16);
    let seq = Sequence::new(&dir, 4.0, 6).unwrap();
    for i in 0..6 {
        save_png(&picture(size.0, size.1), seq.frame_path(i)).unwrap();
    }
    assert!(seq.remaining(0..6, size).is_empty());
    // 1: killed copy; 2: empty; 3: other size; 4: not a PNG; 5: a directory.
    let whole = fs::read(seq.frame_path(1)).unwrap();
    fs::write(seq.frame_path(1), &whole[..whole.len() / 2]).unwrap();
    fs::write(seq.frame_path(2), b"").unwrap();
    save_png(&picture(16, 24), seq.frame_path(3)).unwrap();
    fs::write(seq.frame_path(4), vec![b'x'; whole.len()]).unwrap();
    fs::remove_file(seq.frame_path(5)).unwrap();
    fs::create_dir(seq.frame_path(5)).unwrap();
    assert_eq!(seq.remaining(0..6, size), [1, 2, 3, 4, 5]);
    assert_eq!(seq.remaining(0..6, (16, 24)), [0, 1, 2, 4, 5]);
    for (i, what) in [
        (1, "truncated"),
        (2, "truncated: 0 bytes"),
        (3, "the image is 16x24, expected 24x16"),
        (4, "no PNG signature"),
        (5, "not a regular file"),
    ] {
        let err = verify_png(seq.frame_path(i), size).unwrap_err().to_string();
        assert!(err.contains(what), "{i}: {err}");
        assert!(err.contains(&*seq.frame_path(i).to_string_lossy()), "{err}");
    }
    fs::remove_dir(seq.frame_path(5)).unwrap();
    if gpu::device().is_some() {
        use fractal_sdf::render::Renderer;
        let mut renderer = Renderer::new(&Scene::new(sphere(1.0)), Quality::draft()).unwrap();
        let path = CameraPath::orbit(DVec3::ZERO, 4.0, 1.0, 1.5, 8).unwrap();
        let todo = seq.remaining(0..6, size);
        seq.render(&mut renderer, &path, &[], &todo, size, |_| {})
            .unwrap();
        assert!(seq.remaining(0..6, size).is_empty());
        // Indices outside the sequence are refused before anything runs.
        let err = seq
            .render(&mut renderer, &path, &[], &[0, 6], size, |_| {
                panic!("nothing is rendered")
            })
            .unwrap_err();
        assert!(
            err.to_string()
                .contains("frame 6 is not in the sequence (frames 0..6)"),
            "{err}"
        );
    }
    fs::remove_dir_all(dir).unwrap();
}

#[cfg(unix)]
#[test]
fn links_are_written_through_and_stay_links() {
    use std::os::unix::fs::symlink;
    let dir = scratch("links");
    let is_link = |p: &Path| fs::symlink_metadata(p).unwrap().file_type().is_symlink();
    let image = picture(5, 3);
    // Relative, absolute, a chain, into another directory, dangling.
    fs::create_dir(dir.join("real")).unwrap();
    fs::write(dir.join("real/a.png"), b"old").unwrap();
    symlink("real/a.png", dir.join("rel.png")).unwrap();
    symlink(dir.join("real/a.png"), dir.join("abs.png")).unwrap();
    symlink("rel.png", dir.join("chain.png")).unwrap();
    symlink("real/new/b.png", dir.join("dangling.png")).unwrap();
    for link in ["rel.png", "abs.png", "chain.png", "dangling.png"] {
        let link = dir.join(link);
        fs::write(dir.join("real/a.png"), b"old").unwrap();
        save_png(&image, &link).unwrap();
        assert!(is_link(&link), "{} was replaced", link.display());
        assert_eq!(image::open(&link).unwrap().to_rgba8(), image);
    }
    assert!(is_link(dir.join("rel.png").as_path()) && is_link(&dir.join("chain.png")));
    assert_eq!(
        image::open(dir.join("real/new/b.png")).unwrap().to_rgba8(),
        image
    );
    assert_eq!(names(&dir.join("real")), ["a.png", "new"]);
    // A loop is an error naming the link.
    symlink("loop_b.png", dir.join("loop_a.png")).unwrap();
    symlink("loop_a.png", dir.join("loop_b.png")).unwrap();
    let target = dir.join("loop_a.png");
    let err = save_png(&image, &target).unwrap_err();
    io_error_naming(&err, &target, "cannot follow the symbolic link");
    assert!(is_link(&target));
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_full_device_is_an_error_naming_it_and_stays_a_device() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        eprintln!("note: no /dev/full");
        return;
    }
    let err = save_png(&picture(64, 64), full).unwrap_err();
    let text = io_error_naming(&err, full, "cannot write the image");
    assert!(text.contains("No space left on device"), "{text}");
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        assert!(fs::metadata(full).unwrap().file_type().is_char_device());
    }
}

#[test]
fn unwritable_targets_are_errors_naming_the_target() {
    let dir = scratch("unwritable");
    // A file where a directory is needed.
    fs::write(dir.join("file"), b"x").unwrap();
    let target = dir.join("file/sub/img.png");
    let err = save_png(&picture(2, 2), &target).unwrap_err();
    io_error_naming(&err, &target, "cannot create the directory");
    // A directory where the image goes: refused, untouched.
    fs::create_dir_all(dir.join("taken.png/inner")).unwrap();
    let target = dir.join("taken.png");
    let err = save_png(&picture(2, 2), &target).unwrap_err();
    io_error_naming(&err, &target, "cannot replace a directory with the image");
    assert!(dir.join("taken.png/inner").is_dir());
    // A file system that takes no new files.
    if Path::new("/proc/self").exists() {
        let target = Path::new("/proc/fractal-sdf-hostile.png");
        let err = save_png(&picture(2, 2), target).unwrap_err();
        let text = io_error_naming(&err, target, "cannot create the temporary file");
        assert!(!target.exists(), "{text}");
    }
    // A directory without write permission (root may write anyway).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let locked = dir.join("locked");
        fs::create_dir(&locked).unwrap();
        fs::set_permissions(&locked, fs::Permissions::from_mode(0o555)).unwrap();
        let root = File::create(locked.join("probe")).is_ok();
        let _ = fs::remove_file(locked.join("probe"));
        let target = locked.join("img.png");
        let result = save_png(&picture(2, 2), &target);
        fs::set_permissions(&locked, fs::Permissions::from_mode(0o755)).unwrap();
        if root {
            result.unwrap();
        } else {
            let err = result.unwrap_err();
            io_error_naming(&err, &target, "Permission denied");
        }
    }
    // No temporary file is left anywhere.
    let left = names(&dir);
    assert!(left.iter().all(|n| !n.ends_with(".tmp")), "{left:?}");
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn zero_huge_and_odd_sizes() {
    let dir = scratch("sizes");
    for (w, h) in [(0, 0), (0, 7), (7, 0)] {
        let target = dir.join(format!("{w}x{h}.png"));
        let err = save_png(&RgbaImage::new(w, h), &target).unwrap_err();
        assert!(
            matches!(err, Error::Resolution { width, height, .. } if (width, height) == (w, h)),
            "{err}"
        );
        assert!(
            err.to_string().contains(&*target.to_string_lossy()),
            "{err}"
        );
        assert!(!target.exists());
    }
    for (w, h) in [(1, 1), (1, 1000), (1000, 1), (257, 3), (3, 257), (4099, 2)] {
        let target = dir.join(format!("{w}x{h}.png"));
        let image = picture(w, h);
        save_png(&image, &target).unwrap();
        verify_png(&target, (w, h)).unwrap();
        assert_eq!(image::open(&target).unwrap().to_rgba8(), image);
    }
    // Paths that name no file.
    for target in ["", "nowhere-fractal-sdf/.."] {
        let err = save_png(&picture(2, 2), target).unwrap_err();
        io_error_naming(&err, Path::new(target), "the path names no file");
    }
    // A name that is only dots and spaces, a long name.
    for name in [" .png", "..png", &format!("{}.png", "n".repeat(200))] {
        let target = dir.join(name);
        save_png(&picture(2, 2), &target).unwrap();
        verify_png(&target, (2, 2)).unwrap();
    }
    assert!(names(&dir).iter().all(|n| !n.ends_with(".tmp")));
    fs::remove_dir_all(dir).unwrap();
}

// --------------------------------------------------------------- memory

#[test]
fn counts_that_cannot_be_held_are_typed_errors() {
    // An orbit of u32::MAX segments would need 240 GB of keyframes.
    let err = CameraPath::orbit(DVec3::ZERO, 3.0, 1.0, 10.0, u32::MAX).unwrap_err();
    assert!(matches!(err, Error::Animation { .. }), "{err}");
    assert!(
        err.to_string()
            .contains("at most 1048575 segments, got 4294967295"),
        "{err}"
    );
    // Four-segment orbits and the largest allowed both work.
    for segments in [0, 1, 4] {
        let path = CameraPath::orbit(DVec3::ZERO, 3.0, 1.0, 10.0, segments).unwrap();
        assert_eq!(path.keyframes().len(), 5);
    }
    // Frame counts: u32::MAX frames would be a 16 GiB frame list.
    for frames in [Sequence::MAX_FRAMES + 1, u32::MAX] {
        let err = Sequence::new("out/seq", 24.0, frames).unwrap_err();
        assert!(matches!(err, Error::Invalid { .. }), "{err}");
    }
    for (fps, seconds) in [
        (1e9, 1e9),
        (f64::MAX, f64::MAX),
        (24.0, 1e300),
        (1e300, 1.0),
    ] {
        let err = Sequence::for_duration("out/seq", fps, seconds).unwrap_err();
        assert!(err.to_string().contains("too many"), "{err}");
        assert!(err.to_string().len() < 160, "{err}");
    }
    let seq = Sequence::new(std::env::temp_dir().join("fractal-sdf-none"), 24.0, 10).unwrap();
    assert_eq!(seq.remaining(0..u32::MAX, (8, 8)).len(), 10);
    assert_eq!(parse_range("..", seq.frames()).unwrap(), 0..10);
    assert!(parse_range("0..4294967295", seq.frames()).is_err());
    assert!(parse_range("..=4294967295", seq.frames()).is_err());
    assert!(parse_range("99999999999999999999", seq.frames()).is_err());
    // A path of more keyframes than allowed, from TOML.
    let keys = CameraPath::MAX_KEYFRAMES + 1;
    #[allow(clippy::cast_precision_loss)]
    let many: Vec<Keyframe> = (0..keys)
        .map(|i| Keyframe::new(i as f64, DVec3::ZERO, DVec3::X))
        .collect();
    assert!(matches!(
        CameraPath::new(many),
        Err(Error::Animation { .. })
    ));
    // Frame statistics saturate instead of overflowing.
    let mut stats = FrameStats::new();
    for _ in 0..3 {
        stats.push(Duration::MAX);
    }
    assert_eq!(stats.total(), Duration::MAX);
    assert_eq!(stats.count(), 3);
}

#[test]
fn script_numbers_never_wrap() {
    let last = u64::MAX;
    let err = KeyScript::parse("g@18446744073709551615,h").unwrap_err();
    assert!(matches!(err, Error::Invalid { .. }), "{err}");
    assert!(
        err.to_string().contains("after frame 18446744073709551615"),
        "{err}"
    );
    assert_eq!(
        KeyScript::parse("g@18446744073709551615")
            .unwrap()
            .last_frame(),
        Some(last)
    );
    for text in [
        "g@18446744073709551616",
        "g@340282366920938463463374607431768211456",
        "g@-1",
        "g@+-1",
        "g@0x10",
        "g@1.5",
        "g@",
    ] {
        let err = KeyScript::parse(text).unwrap_err();
        assert!(matches!(err, Error::Invalid { .. }), "{text}: {err}");
        assert!(err.to_string().contains("whole number"), "{text}: {err}");
    }
    // Many keys: one frame apart, in order.
    let text = vec!["g"; 10_000].join(",");
    assert_eq!(KeyScript::parse(&text).unwrap().last_frame(), Some(10_000));
}

// ------------------------------------------------------------- messages

#[test]
fn numbers_in_messages_are_readable() {
    let errors = [
        Scene::new(torus(1.0, -1e300)).validate().unwrap_err(),
        Scene::new(sphere(-1e-300)).validate().unwrap_err(),
        Scene::new(sphere(f64::NEG_INFINITY))
            .validate()
            .unwrap_err(),
        Effects::default()
            .fog_density(-1e300)
            .validate()
            .unwrap_err(),
        Effects::default().gamma(-5e-324).validate().unwrap_err(),
        CameraPath::orbit(DVec3::ZERO, 1.0, 1.0, -1e300, 8).unwrap_err(),
        Sequence::for_duration("d", 24.0, -1e300).unwrap_err(),
        Sequence::new("d", -1e-320, 3).unwrap_err(),
        Scene::new(sphere(1.0))
            .with_camera(Camera::look_at(dvec3(0.0, 0.0, 5.0), DVec3::ZERO).fov(1e300))
            .validate()
            .unwrap_err(),
        Scene::new(sphere(1.0))
            .with_camera(Camera::look_at(dvec3(0.0, 0.0, 5.0), DVec3::ZERO).orthographic(-1e300))
            .validate()
            .unwrap_err(),
    ];
    for err in &errors {
        let text = err.to_string();
        assert!(text.len() < 120, "{text}");
        assert!(
            ["e300", "e-300", "5e-324", "-inf", "e-320", "-1e300"]
                .iter()
                .any(|n| text.contains(n)),
            "{text}"
        );
    }
}

#[test]
fn nan_colours_are_reported_as_nan() {
    let nan = f64::NAN;
    for color in [
        dvec3(nan, 0.0, 0.0),
        dvec3(1.0, nan, 0.0),
        dvec3(0.0, 0.0, nan),
    ] {
        let glow = Effects::default().glow(Glow::new(color, 1.0));
        let sky = Effects::default().sky_top(color);
        let light =
            Scene::new(sphere(1.0)).with_lights([Light::directional(DVec3::Y).color(color)]);
        for err in [
            glow.validate().unwrap_err(),
            sky.validate().unwrap_err(),
            light.validate().unwrap_err(),
        ] {
            let text = err.to_string();
            assert!(text.ends_with("got NaN"), "{text}");
        }
    }
    // A negative component is reported as itself, not hidden by another.
    let err = Effects::default()
        .glow(Glow::new(dvec3(1.0, -2.0, nan), 1.0))
        .validate()
        .unwrap_err();
    assert!(err.to_string().ends_with("got -2"), "{err}");
}

#[test]
fn sequence_errors_blame_the_right_argument() {
    let text = |fps: f64, seconds: f64| {
        Sequence::for_duration("d", fps, seconds)
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        text(f64::NAN, 1.0),
        "invalid frame sequence: the frame rate must be a finite number > 0, got NaN"
    );
    assert_eq!(
        text(24.0, f64::NAN),
        "invalid frame sequence: the duration must be a finite number > 0, got NaN s"
    );
    assert!(text(-1.0, -1.0).contains("frame rate"));
    assert!(text(f64::INFINITY, 1.0).contains("frame rate"));
    assert!(text(24.0, f64::INFINITY).contains("duration"));
    assert!(text(24.0, 0.0).contains("duration"));
}

// ---------------------------------------------------------- scene files

/// Every field of every node, each given a value `@`.
const NODE_FIELDS: &[(&str, &str)] = &[
    ("Sphere(radius: @)", "radius"),
    ("Cuboid(half_extents: @)", "half_extents"),
    ("RoundBox(half_extents: 1, radius: @)", "radius"),
    ("Torus(major_radius: @, minor_radius: 0.2)", "major_radius"),
    ("Torus(major_radius: 1, minor_radius: @)", "minor_radius"),
    ("Cylinder(radius: @, half_height: 1)", "radius"),
    ("Cylinder(radius: 1, half_height: @)", "half_height"),
    ("Capsule(a: @, b: (0, 1, 0), radius: 0.2)", "a"),
    ("Capsule(a: 0, b: (0, 1, 0), radius: @)", "radius"),
    ("Plane(normal: @, offset: 0)", "normal"),
    ("Plane(normal: (0, 1, 0), offset: @)", "offset"),
    ("Octahedron(size: @)", "size"),
    ("OctahedronBound(size: @)", "size"),
    (
        "CappedCone(half_height: @, bottom_radius: 1, top_radius: 0.5)",
        "half_height",
    ),
    (
        "CappedCone(half_height: 1, bottom_radius: @, top_radius: 0.5)",
        "bottom_radius",
    ),
    (
        "CappedCone(half_height: 1, bottom_radius: 1, top_radius: @)",
        "top_radius",
    ),
    ("HexPrism(radius: @, half_height: 1)", "radius"),
    ("HexPrism(radius: 1, half_height: @)", "half_height"),
    (
        "RoundCone(half_height: @, bottom_radius: 1, top_radius: 0.5)",
        "half_height",
    ),
    (
        "RoundCone(half_height: 1, bottom_radius: @, top_radius: 0.5)",
        "bottom_radius",
    ),
    (
        "RoundCone(half_height: 1, bottom_radius: 1, top_radius: @)",
        "top_radius",
    ),
    (
        "Link(half_length: @, major_radius: 0.5, minor_radius: 0.1)",
        "half_length",
    ),
    (
        "Link(half_length: 1, major_radius: @, minor_radius: 0.1)",
        "major_radius",
    ),
    (
        "Link(half_length: 1, major_radius: 0.5, minor_radius: @)",
        "minor_radius",
    ),
    ("CutSphere(radius: @, height: 0.2)", "radius"),
    ("CutSphere(radius: 1, height: @)", "height"),
    ("SolidAngle(angle: @, radius: 1)", "angle"),
    ("SolidAngle(angle: 0.5, radius: @)", "radius"),
    (
        "CappedTorus(angle: @, major_radius: 1, minor_radius: 0.2)",
        "angle",
    ),
    (
        "CappedTorus(angle: 1, major_radius: @, minor_radius: 0.2)",
        "major_radius",
    ),
    (
        "CappedTorus(angle: 1, major_radius: 1, minor_radius: @)",
        "minor_radius",
    ),
    (
        "Triangle(a: @, b: (1, 0, 0), c: (0, 1, 0), thickness: 0.1)",
        "a",
    ),
    (
        "Triangle(a: 0, b: (1, 0, 0), c: (0, 1, 0), thickness: @)",
        "thickness",
    ),
    (
        "Quad(a: 0, b: (1, 0, 0), c: @, d: (0, 1, 0), thickness: 0.1)",
        "c",
    ),
    (
        "Quad(a: 0, b: (1, 0, 0), c: (1, 1, 0), d: (0, 1, 0), thickness: @)",
        "thickness",
    ),
    ("BoxFrame(half_extents: @, thickness: 0)", "half_extents"),
    ("BoxFrame(half_extents: 1, thickness: @)", "thickness"),
    ("Pyramid(half_base: @, height: 1)", "half_base"),
    ("Pyramid(half_base: 0.5, height: @)", "height"),
    (
        "Rhombus(half_x: @, half_z: 0.5, half_height: 0.1, radius: 0.05)",
        "half_x",
    ),
    (
        "Rhombus(half_x: 0.5, half_z: 0.5, half_height: 0.1, radius: @)",
        "radius",
    ),
    ("TriPrism(radius: @, half_height: 1)", "radius"),
    ("TriPrism(radius: 1, half_height: @)", "half_height"),
    (
        "RoundedCylinder(radius: @, half_height: 1, rounding: 0.1)",
        "radius",
    ),
    (
        "RoundedCylinder(radius: 1, half_height: 1, rounding: @)",
        "rounding",
    ),
    ("Cone(radius: @, height: 1)", "radius"),
    ("Cone(radius: 1, height: @)", "height"),
    ("InfiniteCylinder(radius: @)", "radius"),
    ("InfiniteCone(angle: @)", "angle"),
    (
        "CutHollowSphere(radius: @, height: 0.2, thickness: 0.1)",
        "radius",
    ),
    (
        "CutHollowSphere(radius: 1, height: @, thickness: 0.1)",
        "height",
    ),
    (
        "CutHollowSphere(radius: 1, height: 0.2, thickness: @)",
        "thickness",
    ),
    (
        "DeathStar(radius: @, carve_radius: 0.5, carve_distance: 0.8)",
        "radius",
    ),
    (
        "DeathStar(radius: 1, carve_radius: @, carve_distance: 0.8)",
        "carve_radius",
    ),
    (
        "DeathStar(radius: 1, carve_radius: 0.5, carve_distance: @)",
        "carve_distance",
    ),
    ("CylinderBetween(a: @, b: (0, 1, 0), radius: 0.2)", "a"),
    ("CylinderBetween(a: 0, b: (0, 1, 0), radius: @)", "radius"),
    ("ConeBetween(a: 0, b: @, radius_a: 0.5, radius_b: 0.2)", "b"),
    (
        "ConeBetween(a: 0, b: (0, 1, 0), radius_a: @, radius_b: 0.2)",
        "radius_a",
    ),
    (
        "ConeBetween(a: 0, b: (0, 1, 0), radius_a: 0.5, radius_b: @)",
        "radius_b",
    ),
    (
        "RoundConeBetween(a: @, b: (0, 1, 0), radius_a: 0.5, radius_b: 0.2)",
        "a",
    ),
    (
        "RoundConeBetween(a: 0, b: (0, 1, 0), radius_a: @, radius_b: 0.2)",
        "radius_a",
    ),
    (
        "RoundConeBetween(a: 0, b: (0, 1, 0), radius_a: 0.5, radius_b: @)",
        "radius_b",
    ),
    (
        "Extrude(profile: Circle(radius: @), half_height: 1)",
        "radius",
    ),
    (
        "Extrude(profile: Rect(half_extents: (@, 1)), half_height: 1)",
        "half_extents",
    ),
    (
        "Extrude(profile: RoundRect(half_extents: (1, 1), radius: @), half_height: 1)",
        "radius",
    ),
    (
        "Extrude(profile: Segment(a: (@, 0), b: (1, 0), radius: 0.2), half_height: 1)",
        "profile.a",
    ),
    (
        "Extrude(profile: Segment(a: (0, 0), b: (1, 0), radius: @), half_height: 1)",
        "radius",
    ),
    (
        "Extrude(profile: Polygon(vertices: [(0, 0), (1, @), (0, 1)]), half_height: 1)",
        "vertices",
    ),
    (
        "Revolve(profile: Vesica(half_length: @, half_width: 0.2))",
        "half_length",
    ),
    (
        "Revolve(profile: Vesica(half_length: 1, half_width: @))",
        "half_width",
    ),
    (
        "Extrude(profile: Ellipse(radii: (1, @)), half_height: 1)",
        "radii",
    ),
    (
        "Extrude(profile: Circle(radius: 1), half_height: @)",
        "half_height",
    ),
    ("Revolve(profile: Circle(radius: 0.2), offset: @)", "offset"),
    ("Ellipsoid(radii: @)", "radii"),
    ("Mandelbulb(power: @)", "power"),
    ("Mandelbulb(power: 8, iterations: @)", "iterations"),
    ("Mandelbulb(power: 8, bailout: @)", "bailout"),
    ("Menger(iterations: @)", "iterations"),
    ("Menger(iterations: 3, scale: @)", "scale"),
    ("Julia(c: (@, 0, 0, 0))", "c"),
    ("Julia(c: (0, 0, 0, 0), iterations: @)", "iterations"),
    ("Julia(c: (0, 0, 0, 0), bailout: @)", "bailout"),
    ("Julia(c: (0, 0, 0, 0), slice_w: @)", "slice_w"),
    ("Sierpinski(iterations: @)", "iterations"),
    ("Sierpinski(iterations: 3, scale: @)", "scale"),
    ("Mandelbox(scale: @)", "scale"),
    ("Mandelbox(scale: 2, min_radius: @)", "min_radius"),
    ("Mandelbox(scale: 2, fixed_radius: @)", "fixed_radius"),
    ("Mandelbox(scale: 2, fold_limit: @)", "fold_limit"),
    ("Mandelbox(scale: 2, iterations: @)", "iterations"),
    ("Mandelbox(scale: 2, julia: Some((@, 0, 0)))", "julia"),
    ("PseudoKleinian(fold_size: (1, @, 1))", "fold_size"),
    ("PseudoKleinian(inversion: @)", "inversion"),
    ("PseudoKleinian(offset: (0, 0, @))", "offset"),
    ("PseudoKleinian(thickness: @)", "thickness"),
    ("PseudoKleinian(iterations: @)", "iterations"),
    ("Kifs(fold: Octahedral, scale: @)", "scale"),
    ("Kifs(fold: Tetrahedral, offset: (1, @, 1))", "offset"),
    ("Kifs(fold: Icosahedral, iterations: @)", "iterations"),
    (
        "Kifs(fold: Menger, rotate_before: (@, 0, 0))",
        "rotate_before",
    ),
    (
        "Kifs(fold: Menger, rotate_after: (0, 0, @))",
        "rotate_after",
    ),
    ("Hybrid(stages: [(ops: [BoxFold(limit: @)])])", "limit"),
    (
        "Hybrid(stages: [(repeat: 2, ops: [AddPoint, Power(power: @)])])",
        "power",
    ),
    (
        "Hybrid(stages: [(ops: [Scale(factor: @, center: (0, 0, 0))])])",
        "factor",
    ),
    (
        "Hybrid(stages: [(ops: [Rotate(angles: (0, @, 0))])])",
        "angles",
    ),
    ("Hybrid(stages: [], bailout: @)", "bailout"),
    ("Hybrid(stages: [], safety: Some(@))", "safety"),
    ("Hybrid(stages: [], iterations: @)", "iterations"),
    ("Translate(offset: @, child: Sphere(radius: 1))", "offset"),
    (
        "Rotate(axis: (0, 1, 0), angle: @, child: Sphere(radius: 1))",
        "angle",
    ),
    (
        "Rotate(axis: (@, 0, 0), angle: 1, child: Sphere(radius: 1))",
        "axis",
    ),
    ("Scale(factor: @, child: Sphere(radius: 1))", "factor"),
    ("Round(radius: @, child: Sphere(radius: 1))", "radius"),
    ("Onion(thickness: @, child: Sphere(radius: 1))", "thickness"),
    ("Elongate(extents: @, child: Sphere(radius: 1))", "extents"),
    ("Repeat(period: @, child: Sphere(radius: 0.2))", "period"),
    (
        "RepeatLimited(period: @, limit: (1, 1, 1), child: Sphere(radius: 0.2))",
        "period",
    ),
    (
        "RepeatLimited(period: 1, limit: (@, 1, 1), child: Sphere(radius: 0.2))",
        "limit",
    ),
    ("Twist(rate: @, child: Sphere(radius: 1))", "rate"),
    ("Bend(rate: @, child: Sphere(radius: 1))", "rate"),
    ("Color(color: @, child: Sphere(radius: 1))", "color"),
    (
        "Material(material: (roughness: @), child: Sphere(radius: 1))",
        "roughness",
    ),
    (
        "Material(material: (ior: @), child: Sphere(radius: 1))",
        "ior",
    ),
    (
        "Material(material: (transparency: @), child: Sphere(radius: 1))",
        "transparency",
    ),
    (
        "OrbitTrap(trap: Sphere(centre: @, radius: 1), palette: Fire, child: Menger(iterations: 2))",
        "centre",
    ),
    (
        "OrbitTrap(trap: Sphere(centre: 0, radius: @), palette: Fire, child: Menger(iterations: 2))",
        "radius",
    ),
    (
        "OrbitTrap(trap: Plane(normal: (@, 0, 0), offset: 0), palette: Fire, child: Menger(iterations: 2))",
        "normal",
    ),
    (
        "OrbitTrap(trap: Line(point: 0, direction: @), palette: Fire, child: Menger(iterations: 2))",
        "direction",
    ),
    (
        "OrbitTrap(trap: Iterations, palette: Fire, near: @, child: Menger(iterations: 2))",
        "near",
    ),
    (
        "OrbitTrap(trap: Iterations, palette: Fire, far: @, child: Menger(iterations: 2))",
        "far",
    ),
    (
        "OrbitTrap(trap: Iterations, palette: Gradient([(@, (1, 1, 1))]), child: Menger(iterations: 2))",
        "palette",
    ),
    (
        "OrbitTrap(trap: Iterations, palette: Gradient([(0, (1, @, 1))]), child: Menger(iterations: 2))",
        "palette",
    ),
    (
        "CutPlane(normal: @, offset: 0, child: Sphere(radius: 1))",
        "normal",
    ),
    (
        "CutPlane(normal: (1, 0, 0), offset: @, child: Sphere(radius: 1))",
        "offset",
    ),
    (
        "SmoothUnion(k: @, a: Sphere(radius: 1), b: Sphere(radius: 1))",
        "k",
    ),
    (
        "SmoothSubtract(k: @, a: Sphere(radius: 1), b: Sphere(radius: 1))",
        "k",
    ),
    (
        "SmoothIntersect(k: @, a: Sphere(radius: 1), b: Sphere(radius: 1))",
        "k",
    ),
    (
        "SmoothCut(k: @, a: Sphere(radius: 1), b: Sphere(radius: 1))",
        "k",
    ),
    (
        "Custom(name: \"mandelbox_escape\", args: [@, 12])",
        "mandelbox_escape",
    ),
];

/// Hostile values as a file writes them.
const FILE_VALUES: &[&str] = &[
    "4.5",
    "-1",
    "-3.5",
    "NaN",
    "inf",
    "-inf",
    "1e39",
    "1e400",
    "-0.0",
    "4294967296",
    "0",
];

/// `text` parses to a scene or gives a typed scene-file error naming
/// `word`; never a panic.
fn file_case(text: &str, word: &str) -> Result<(), String> {
    let outcome = std::panic::catch_unwind(|| SceneFile::parse(text));
    match outcome {
        Err(_) => Err(format!("{text}: panicked")),
        Ok(Ok(_)) => Ok(()),
        Ok(Err(err @ Error::SceneFile { .. })) => {
            let message = err.to_string();
            if message.contains(word) && !message.contains("Repr") {
                Ok(())
            } else {
                Err(format!(
                    "{text}: the message does not name `{word}`: {message}"
                ))
            }
        }
        Ok(Err(other)) => Err(format!("{text}: not a scene-file error: {other:?}")),
    }
}

#[test]
fn every_node_field_given_a_hostile_value_is_refused_by_name_or_read() {
    let mut failures = Vec::new();
    let mut cases = 0;
    for (node, field) in NODE_FIELDS {
        for value in FILE_VALUES {
            for bom in ["", "\u{feff}"] {
                cases += 1;
                let text = format!(
                    "{bom}(version: 1,\n geometry: {})",
                    node.replace('@', value)
                );
                if let Err(why) = file_case(&text, field) {
                    failures.push(why);
                }
            }
        }
    }
    // Counts among the quality settings, the camera's angle, motions.
    let settings: &[(&str, &str)] = &[
        ("quality: (preset: Draft, max_steps: @)", "max_steps"),
        (
            "quality: (preset: Draft, supersampling: @)",
            "supersampling",
        ),
        ("quality: (preset: Draft, bounces: @)", "bounces"),
        ("quality: (preset: Draft, detail: @)", "detail"),
        (
            "camera: (projection: Perspective(fov_y_degrees: @))",
            "field of view",
        ),
        ("camera: (position: (0, 0, @))", "position"),
        ("effects: (gamma: @)", "gamma"),
        ("effects: (fog_density: @)", "fog_density"),
        ("effects: (exposure: @)", "exposure"),
        (
            "motions: [Oscillate(name: \"r\", center: 1, amplitude: 0.1, period: @)]",
            "period",
        ),
        (
            "motions: [Oscillate(name: \"r\", center: @, amplitude: 0.1, period: 1)]",
            "r",
        ),
    ];
    for (setting, word) in settings {
        for value in FILE_VALUES {
            cases += 1;
            let text = format!(
                "(version: 1, geometry: Sphere(radius: param(\"r\", 1)),\n {})",
                setting.replace('@', value)
            );
            if let Err(why) = file_case(&text, word) {
                failures.push(why);
            }
        }
    }
    // Wrong material spellings name what was written.
    for (material, word) in [
        ("Glass(ior: 1.5)", "Glass"),
        ("Mirror()", "Mirror"),
        ("(colour: 1)", "colour"),
        ("Material(ior: 1.5, tint: 2)", "tint"),
    ] {
        cases += 1;
        let text = format!(
            "(version: 1, geometry: Material(material: {material}, child: Sphere(radius: 1)))"
        );
        if let Err(why) = file_case(&text, word) {
            failures.push(why);
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {cases} hostile scene-file cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
