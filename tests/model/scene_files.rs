//! Scene files: every gallery scene survives a round trip (the same value,
//! and the same image on the device), the shipped `scenes/*.ron` are the
//! gallery as written today, and every kind of bad file is an error that
//! names the line and column of what is wrong.
//!
//! `UPDATE_SCENES=1 cargo test --features proptest --test model scene_files` rewrites `scenes/`.

use crate::gpu;

use std::path::{Path, PathBuf};

use fractal_sdf::file::MAX_NESTING;
use fractal_sdf::file::SceneFile;
use fractal_sdf::gallery;
use fractal_sdf::prelude::*;
use fractal_sdf::scene::{CustomShape, Environment, EnvironmentMap, Rule};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

#[test]
fn every_gallery_scene_round_trips_to_an_equal_value() {
    for name in gallery::names() {
        let file = gallery::file(name).unwrap();
        let text = file.to_text().unwrap();
        // Beside the crate's scene files: `gi` names its sky as `sky.hdr`.
        let back = SceneFile::parse_in(&text, scenes_dir())
            .unwrap_or_else(|e| panic!("{name}: {e}\n{text}"));
        assert_eq!(back, file, "{name}:\n{text}");
        // Writing is stable: the text of what was read is the same text.
        assert_eq!(back.to_text().unwrap(), text, "{name}");
    }
}

#[test]
fn the_shipped_scene_files_are_the_gallery() {
    let update = std::env::var_os("UPDATE_SCENES").is_some();
    for name in gallery::names() {
        let path = scenes_dir().join(format!("{name}.ron"));
        let expected = gallery::file(name).unwrap();
        if update {
            expected.save(&path).unwrap();
        }
        let loaded = SceneFile::load(&path).unwrap_or_else(|e| {
            panic!("{e} (run `UPDATE_SCENES=1 cargo test --features proptest --test model scene_files`)")
        });
        assert_eq!(loaded, expected, "{} is out of date", path.display());
    }
}

/// A file's scene read back renders the identical image: same source, same
/// buffers, same pixels.
#[test]
fn a_round_trip_renders_the_identical_image() {
    let Some(_device) = gpu::device() else {
        return;
    };
    for name in gallery::names() {
        let file = gallery::file(name).unwrap();
        let back = SceneFile::parse_in(&file.to_text().unwrap(), scenes_dir()).unwrap();
        let render = |f: &SceneFile| {
            let options = fractal_sdf::render::RenderOptions::default()
                .quality(Quality::draft())
                .effects(f.effects);
            fractal_sdf::render::Renderer::with_options(&f.scene, &options)
                .and_then(|mut r| r.render(40, 30))
                .unwrap_or_else(|e| panic!("{name}: {e}"))
        };
        let (a, b) = (render(&file), render(&back));
        assert!(
            a.pixels().any(|p| p.0 != a.get_pixel(0, 0).0),
            "{name} is blank"
        );
        assert_eq!(a.as_raw(), b.as_raw(), "{name}: the images differ");
    }
}

/// Parses `text` and returns the error's (line, column, message).
fn error_at(text: &str) -> (usize, usize, String) {
    match SceneFile::parse(text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e @ Error::SceneFile { .. }) => {
            let Error::SceneFile { line, column, .. } = e else {
                unreachable!()
            };
            (line, column, e.to_string())
        }
        Err(other) => panic!("not a scene-file error: {other}"),
    }
}

/// The (line, column) where `needle` starts in `text`.
fn position_of(text: &str, needle: &str) -> (usize, usize) {
    let at = text.find(needle).expect("the needle is in the text");
    let line = text[..at].matches('\n').count() + 1;
    let column = text[..at].rsplit('\n').next().unwrap().chars().count() + 1;
    (line, column)
}

#[test]
fn a_bad_value_is_located_at_its_node_with_its_path() {
    let text = "(
    version: 1,
    geometry: Union([
        Sphere(radius: 1),
        Translate(
            offset: (1, 0, 0),
            child: Torus(major_radius: 0.5, minor_radius: -0.1),
        ),
    ]),
)";
    let (line, column, message) = error_at(text);
    assert_eq!((line, column), position_of(text, "Torus"), "{message}");
    assert!(
        message.contains("union/b:translate/torus: parameter `minor_radius` must be >= 0"),
        "{message}"
    );
    assert!(message.starts_with("<scene>:7:20: "), "{message}");
}

#[test]
fn more_errors_are_located_where_they_are() {
    // The operand of a one-operand union.
    let text = "(version: 1, geometry: Union([\n    Sphere(radius: -1),\n]))";
    let (line, column, message) = error_at(text);
    assert_eq!((line, column), (2, 5), "{message}");
    // A version, after comments.
    let text = "// one\n// two\n(\n    version: 7,\n    geometry: Sphere(radius: 1),\n)";
    let (line, column, message) = error_at(text);
    assert_eq!((line, column), (4, 5), "{message}");
    // A value that F64 holds and the file's F32 quality does not.
    let text = "(\n    version: 1,\n    geometry: Union([\n        Sphere(radius: 1),\n        Sphere(radius: 1e30),\n    ]),\n    quality: (preset: Production),\n)";
    let (line, column, message) = error_at(text);
    assert_eq!((line, column), (5, 9), "{message}");
    assert!(message.contains("F32"), "{message}");
    // In F64, or with no quality of its own (held to F64's limits), it reads.
    SceneFile::parse(&text.replace("Production", "Reference")).unwrap();
    SceneFile::parse(&text.replace("    quality: (preset: Production),\n", "")).unwrap();
    // A motion that takes a parameter out of its range, at the motion.
    let text = "(\n    version: 1,\n    geometry: Sphere(radius: param(\"r\", 0.5)),\n    motions: [\n        Oscillate(name: \"r\", center: 0.1, amplitude: 1, period: 1),\n    ],\n)";
    let (line, column, message) = error_at(text);
    assert_eq!((line, column), (5, 9), "{message}");
    assert!(message.contains("must be >= 0, got -0.9"), "{message}");
}

/// A custom shape: a ball of radius `radius`.
fn blob() -> CustomShape {
    CustomShape::new(
        "blob",
        &[("radius", Rule::Positive)],
        |p, a| p.length() - a[0],
        "return length(p) - radius;",
    )
    .unwrap()
}

#[test]
fn a_custom_shape_error_is_located_at_its_node() {
    let blob = blob();
    let text = "(\n    version: 1,\n    geometry: Union([\n        Sphere(radius: 1),\n        Custom(name: \"blob\", args: []),\n    ]),\n)";
    let e = SceneFile::parse_with(text, std::slice::from_ref(&blob)).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("<scene>:5:9: custom shape `blob`"),
        "{e}"
    );
}

#[test]
fn invalid_settings_are_not_written() {
    let mut file = SceneFile::new(Scene::new(sphere(1.0)));
    file.quality = Some(Quality::draft());
    file.quality.as_mut().unwrap().detail = f64::NAN;
    assert!(file.to_text().is_err());
}

#[test]
fn each_operand_of_a_long_union_is_located() {
    let mut text = String::from("(version: 1, geometry: Union([\n");
    for i in 0..40 {
        let radius = if i == 27 { "NaN" } else { "0.1" };
        text.push_str(&format!(
            "    Translate(offset: ({i}, 0, 0), child: Sphere(radius: {radius})),\n"
        ));
    }
    text.push_str("]))\n");
    let (line, column, message) = error_at(&text);
    assert_eq!(
        (line, column),
        position_of(&text, "Sphere(radius: NaN"),
        "{message}"
    );
    assert!(message.contains("must be finite"), "{message}");
}

#[test]
fn settings_errors_are_located_at_the_setting() {
    let cases = [
        (
            "camera: (position: (0, 0, 3), target: (0, 0, 3))",
            "(position",
            "target equals position",
        ),
        (
            "lights: [(source: Directional(direction: (0, 1, 0))), (source: Point(position: (0, 1, 0)), intensity: -2)]",
            "(source: Point",
            "light[1]",
        ),
        (
            "quality: (preset: Draft, max_steps: 0)",
            "(preset",
            "max_steps",
        ),
        ("effects: (gamma: -1)", "(gamma", "gamma"),
        (
            "path: [(time: 0, position: (0, 0, 3), target: (0, 0, 0)), (time: 0, position: (1, 0, 3), target: (0, 0, 0))]",
            "[(time",
            "camera path",
        ),
        (
            "motions: [Oscillate(name: \"powr\", center: 8, amplitude: 1, period: 2)]",
            "Oscillate",
            "no dynamic parameter named `powr`",
        ),
    ];
    for (setting, needle, says) in cases {
        let text = format!(
            "(\n    version: 1,\n    geometry: Sphere(radius: param(\"power\", 1)),\n    {setting},\n)"
        );
        let (line, column, message) = error_at(&text);
        assert_eq!((line, column), position_of(&text, needle), "{message}");
        assert!(message.contains(says), "{setting}: {message}");
    }
}

#[test]
fn syntax_and_vocabulary_errors_say_what_and_where() {
    let cases = [
        (
            "(version: 1, geometry: Sphere(radius: 1)",
            "1:40: Expected comma",
        ),
        (
            "(version: 1, geometry: Sphere(radius: 1), camra: ())",
            "camra",
        ),
        ("(version: 1, geometry: Spher(radius: 1))", "Spher"),
        (
            "(version: 1, geometry: Sphere(radius: 1, height: 2))",
            "height",
        ),
        ("(version: 1, geometry: Sphere(radius: \"big\"))", "big"),
        ("(version: 1, geometry: Sphere())", "radius"),
        ("(version: 1, geometry: Union([]))", "at least one operand"),
        (
            "(version: 1, geometry: Custom(name: \"gyroid\", args: [0.1]))",
            "gyroid",
        ),
        ("(geometry: Sphere(radius: 1))", "version"),
        (
            "(version: 2, geometry: Sphere(radius: 1))",
            "format version 2",
        ),
        (
            "(version: 1, geometry: Mandelbulb(power: 8, iterations: 0))",
            "iterations",
        ),
    ];
    for (text, says) in cases {
        let (line, column, message) = error_at(text);
        assert!((line, column) >= (1, 1), "{message}");
        assert!(message.contains(says), "{text}: {message}");
    }
    // The file is named in errors from `load`.
    let dir = std::env::temp_dir().join(format!("fractal-sdf-scene-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.ron");
    std::fs::write(&path, "(version: 1,\ngeometry: Sphere(radius: -1))").unwrap();
    let message = SceneFile::load(&path).unwrap_err().to_string();
    assert!(
        message.starts_with(&format!("{}:2:11: sphere", path.display())),
        "{message}"
    );
}

#[test]
fn nesting_is_bounded_when_writing_and_reading() {
    // Deeper than a file may be: refused with a typed error, no overflow.
    let mut node = sphere(0.5);
    for _ in 0..(MAX_NESTING + 10) {
        node = node.translate(dvec3(0.01, 0.0, 0.0));
    }
    let err = SceneFile::new(Scene::new(node)).to_text().unwrap_err();
    assert!(err.to_string().contains("nested"), "{err}");

    let deep = |levels: usize| {
        let mut text = String::from("(version: 1, geometry: ");
        for _ in 0..levels {
            text.push_str("Translate(offset: 0, child: ");
        }
        text.push_str("Sphere(radius: 1)");
        text.push_str(&")".repeat(levels));
        text.push(')');
        text
    };
    // At the limit it reads (on a test thread's small stack), beyond it is
    // an error, and far beyond (where recursion would overflow) also.
    let file = SceneFile::parse(&deep(MAX_NESTING - 1)).unwrap();
    assert_eq!(file.scene.geometry.unwrap().size_and_depth().1, MAX_NESTING);
    for levels in [MAX_NESTING + 1, 100_000] {
        let (_, _, message) = error_at(&deep(levels));
        assert!(message.contains("nested more than 64 deep"), "{message}");
    }
}

#[test]
fn a_hundred_thousand_operands_read_and_write() {
    let mut text = String::from("(version: 1, geometry: Union([\n");
    for i in 0..100_000 {
        text.push_str(&format!(
            "Translate(offset: ({}, 0, {}), child: Sphere(radius: 0.1)),\n",
            i % 100,
            i / 100
        ));
    }
    text.push_str("]))");
    let file = SceneFile::parse(&text).unwrap();
    assert_eq!(
        file.scene.geometry.as_ref().unwrap().size_and_depth().0,
        3 * 100_000 - 1
    );
    assert_eq!(SceneFile::parse(&file.to_text().unwrap()).unwrap(), file);
}

#[test]
fn custom_shapes_are_named_by_the_caller() {
    let blob = blob();
    let scene = Scene::new(blob.node([param("r", 0.7)]).translate(dvec3(0.0, 1.0, 0.0)));
    let text = SceneFile::new(scene.clone()).to_text().unwrap();
    assert!(
        text.contains("Custom(name: \"blob\", args: [param(\"r\", 0.7)])"),
        "{text}"
    );
    let back = SceneFile::parse_with(&text, std::slice::from_ref(&blob)).unwrap();
    assert_eq!(back.scene, scene);
    let message = SceneFile::parse(&text).unwrap_err().to_string();
    assert!(
        message.contains("no custom shape named `blob`"),
        "{message}"
    );
}

#[test]
fn shorthand_forms_read_as_their_long_forms() {
    let short = "(version: 1, geometry: Union([
        Cuboid(half_extents: 0.5),
        Mandelbulb(power: 8),
        Translate(offset: param3(\"at\", (1, 2, 3)), child: Sphere(radius: param(name: \"r\", default: 2))),
    ]), quality: (preset: Draft, supersampling: 3))";
    let file = SceneFile::parse(short).unwrap();
    let expected = cuboid(dvec3(0.5, 0.5, 0.5)).union(mandelbulb(8.0)).union(
        sphere(param("r", 2.0)).translate(fractal_sdf::scene::param3("at", dvec3(1.0, 2.0, 3.0))),
    );
    assert_eq!(file.scene.geometry, Some(expected));
    assert_eq!(file.quality, Some(Quality::draft().supersampling(3)));
    assert_eq!(file.scene.camera, Camera::default());
    assert_eq!(file.scene.lights, Scene::empty().lights);
    assert_eq!(file.effects, Effects::default());
}

/// The Mandelbulb variants' operations read with their defaults: the
/// power-2 bulb's square negates `z` unless told not to.
#[test]
fn the_bulb_variants_read_with_their_defaults() {
    use fractal_sdf::scene::{Hybrid, HybridOp};
    let text = "(version: 1, geometry: Union([
        Hybrid(stages: [(ops: [BulbSquare(), AddPoint])]),
        Hybrid(stages: [(ops: [BulbSquare(negate_z: false), QuaternionSquare, AddPoint])]),
    ]))";
    let file = SceneFile::parse(text).unwrap();
    let expected = Node::from(Hybrid::power2_mandelbulb()).union(Node::from(Hybrid::new().stage(
        1,
        [
            HybridOp::BulbSquare { negate_z: false },
            HybridOp::QuaternionSquare,
            HybridOp::AddPoint,
        ],
    )));
    assert_eq!(file.scene.geometry, Some(expected));
}

/// Orbit traps read in every form: each trap, each named palette, a
/// gradient, the range's defaults; a palette the parser does not know is
/// an error that names the word.
#[test]
fn orbit_traps_read_in_every_form() {
    use fractal_sdf::scene::{OrbitColoring, Palette, Trap};
    let names = [
        "Fire", "Ocean", "Viridis", "Magma", "Copper", "Rainbow", "Grey",
    ];
    for name in names {
        let text = format!(
            "(version: 1, geometry: OrbitTrap(trap: Point(centre: (0, 0, 1)), palette: {name}, \
             child: Menger(iterations: 2)))"
        );
        let file = SceneFile::parse(&text).unwrap();
        let palette = Palette::named(&name.to_lowercase()).unwrap();
        let expected = menger(2).orbit_trap(Trap::point(dvec3(0.0, 0.0, 1.0)), palette);
        assert_eq!(file.scene.geometry, Some(expected));
        // And it is written back by its name.
        assert!(
            file.to_text()
                .unwrap()
                .contains(&format!("palette: {name}"))
        );
    }
    let text = "(version: 1, geometry: OrbitTrap(
        trap: Line(point: (0, 0, 0), direction: param3(\"dir\", (0, 1, 0))),
        palette: Gradient([(0, (0, 0, 0.1)), (0.5, (1, 0.2, 0)), (1, (1, 1, 1))]),
        near: 0.1, far: param(\"far\", 2),
        child: Mandelbulb(power: 8)))";
    let file = SceneFile::parse(text).unwrap();
    let expected = mandelbulb(8.0).orbit_coloring(
        OrbitColoring::new(
            Trap::line(DVec3::ZERO, fractal_sdf::scene::param3("dir", DVec3::Y)),
            Palette::gradient([
                (0.0, [0.0, 0.0, 0.1]),
                (0.5, [1.0, 0.2, 0.0]),
                (1.0, [1.0, 1.0, 1.0]),
            ]),
        )
        .range(0.1, param("far", 2.0)),
    );
    assert_eq!(file.scene.geometry, Some(expected));
    let again = SceneFile::parse(&file.to_text().unwrap()).unwrap();
    assert_eq!(again.scene.geometry, file.scene.geometry);

    let plaid = "(version: 1, geometry: OrbitTrap(trap: Point(centre: 0), palette: Plaid, \
                 child: Menger(iterations: 2)))";
    let err = SceneFile::parse(plaid).unwrap_err().to_string();
    assert!(err.contains("Plaid"), "{err}");
    // A trap on a shape that is not a fractal is refused where it is.
    let on_sphere = "(version: 1, geometry: OrbitTrap(trap: Point(centre: 0), palette: Fire, \
                     child: Sphere(radius: 1)))";
    let err = SceneFile::parse(on_sphere).unwrap_err().to_string();
    assert!(err.contains("its child is a sphere"), "{err}");
}

/// The README's complete scene file reads, with every part it shows.
#[test]
fn the_readme_example_file_reads() {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let start = readme.find("```ron\n").expect("a RON block in the README") + 7;
    let end = start + readme[start..].find("```").unwrap();
    let file = SceneFile::parse(&readme[start..end]).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(file.scene.lights.len(), 2);
    assert_eq!(file.quality, Some(Quality::production().supersampling(2)));
    assert!(file.effects.glow.is_some());
    assert_eq!(file.motions.len(), 1);
    assert!(file.scene.compile().unwrap().params().slots().len() == 1);
}

mod properties {
    use fractal_sdf::file::SceneFile;
    use fractal_sdf::prelude::*;
    use fractal_sdf::testing::scene_node;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(128))]

        /// Every node kind, dynamic or baked, any nesting the strategy
        /// makes: written and read back, the same scene.
        #[test]
        fn random_scenes_round_trip(node in scene_node(4)) {
            let file = SceneFile::new(Scene::new(node));
            let text = file.to_text().unwrap();
            let back = SceneFile::parse(&text);
            prop_assert!(back.is_ok(), "{}\n{text}", back.unwrap_err());
            prop_assert_eq!(back.unwrap(), file);
        }

        /// A file cut, or with a character changed, inserted or removed,
        /// reads or is an error located inside the text: never a panic.
        #[test]
        fn mangled_files_are_errors_inside_the_text(
            name in prop::sample::select(fractal_sdf::gallery::names()),
            at in any::<prop::sample::Index>(),
            edit in 0..4u8,
            c in prop::char::range(' ', '~'),
        ) {
            let text = fractal_sdf::gallery::file(name).unwrap().to_text().unwrap();
            let mut chars: Vec<char> = text.chars().collect();
            let i = at.index(chars.len());
            match edit {
                0 => chars.truncate(i),
                1 => chars[i] = c,
                2 => chars.insert(i, c),
                _ => {
                    chars.remove(i);
                }
            }
            let mangled: String = chars.into_iter().collect();
            if let Err(e) = SceneFile::parse(&mangled) {
                let Error::SceneFile { line, column, .. } = e else {
                    panic!("not a scene-file error: {e}");
                };
                let lines = mangled.lines().count().max(1);
                prop_assert!(line >= 1 && line <= lines + 1, "line {line} of {lines}: {e}");
                prop_assert!(column >= 1, "{e}");
            }
        }
    }
}

#[test]
fn a_motion_period_must_be_a_positive_finite_number() {
    for period in ["NaN", "inf", "0", "-2", "-0.0"] {
        for motion in [
            format!("Oscillate(name: \"power\", center: 8, amplitude: 1, period: {period})"),
            format!("Orbit(name: \"at\", center: (0, 0, 0), radius: 1, period: {period})"),
        ] {
            let text = format!(
                "(version: 1, geometry: Translate(offset: param3(\"at\", (0, 0, 0)), \
                 child: Sphere(radius: param(\"power\", 1))),\n motions: [{motion}])"
            );
            let err = SceneFile::parse(&text).unwrap_err();
            let message = err.to_string();
            assert!(
                message.contains("`period` must be a finite number of seconds > 0, got"),
                "{text}: {message}"
            );
            assert!(message.starts_with("<scene>:2:"), "{message}");
            let Error::SceneFile { cause, .. } = &err else {
                panic!("{err:?}")
            };
            assert!(
                matches!(
                    cause.as_deref(),
                    Some(Error::Motion {
                        field: "period",
                        ..
                    })
                ),
                "{err:?}"
            );
        }
    }
}

#[test]
fn a_byte_order_mark_is_not_part_of_the_text() {
    let file = SceneFile::parse("\u{feff}(version: 1, geometry: Sphere(radius: 1))").unwrap();
    assert_eq!(file.scene.geometry, Some(sphere(1.0)));
    // Columns are counted as an editor shows them, without the mark.
    let err = SceneFile::parse("\u{feff}(version: 1, geometry: Sphere(radius: -1))")
        .unwrap_err()
        .to_string();
    assert!(err.starts_with("<scene>:1:24: sphere"), "{err}");
}

#[test]
fn a_camera_too_far_away_is_named_as_such() {
    // Beside a target one unit away, a camera at 1e39 cannot tell the
    // view's direction: its position is what is wrong.
    for (position, target, says) in [
        (
            "(1e39, 0, 0)",
            "(1e39, 0, 1)",
            "position (1e39, 0, 0) is too large",
        ),
        (
            "(0, 0, 1e200)",
            "(1, 0, 1e200)",
            "`position.z` = 1e200 cannot be",
        ),
    ] {
        let text = format!(
            "(version: 1, geometry: Sphere(radius: 1), camera: (position: {position}, target: {target}))"
        );
        let err = SceneFile::parse(&text).unwrap_err().to_string();
        assert!(!err.contains("target equals position"), "{position}: {err}");
        assert!(err.contains(says), "{position}: {err}");
    }
    let text = "(version: 1, geometry: Sphere(radius: 1), camera: (position: (0, 0, 2), target: (0, 0, 2)))";
    let err = SceneFile::parse(text).unwrap_err().to_string();
    assert!(err.contains("target equals position"), "{err}");
}

#[test]
fn messages_name_the_words_written_not_internal_types() {
    let node = |geometry: &str| {
        let text = format!("(version: 1, geometry: {geometry})");
        SceneFile::parse(&text).unwrap_err().to_string()
    };
    for (geometry, says) in [
        (
            "Material(material: Glass(ior: 1.5, colour: 1), child: Sphere(radius: 1))",
            "`Glass(..)` is not a material",
        ),
        (
            "Material(material: (roughness: 0.2, colour: 1), child: Sphere(radius: 1))",
            "colour",
        ),
        (
            "Mandelbulb(power: 8, iterations: 4.5)",
            "`iterations` must be a whole number",
        ),
        (
            "Menger(iterations: -3)",
            "`iterations` must be a whole number",
        ),
        (
            "RepeatLimited(period: 1, limit: (1, 2.5, 1), child: Sphere(radius: 0.2))",
            "`limit` must be whole numbers",
        ),
    ] {
        let message = node(geometry);
        assert!(message.contains(says), "{geometry}: {message}");
        assert!(!message.contains("Repr"), "{geometry}: {message}");
    }
}

#[test]
fn a_cut_plane_is_a_node_of_its_own() {
    let text = "(version: 1, geometry: CutPlane(normal: (1, 0, 0), offset: param(\"cut\", 0),\n\
                child: Sphere(radius: 1)))";
    let file = SceneFile::parse(text).unwrap();
    let expected = sphere(1.0).cut_plane(dvec3(1.0, 0.0, 0.0), param("cut", 0.0));
    assert_eq!(file.scene.geometry, Some(expected.clone()));
    // Written back as a cut plane, and read back equal.
    let written = SceneFile::new(Scene::new(expected.clone()))
        .to_text()
        .unwrap();
    assert!(written.contains("CutPlane("), "{written}");
    assert_eq!(
        SceneFile::parse(&written).unwrap().scene.geometry,
        Some(expected)
    );
    // The older spelling, a cut by a plane node, still reads.
    let older = "(version: 1, geometry: Cut(a: Sphere(radius: 1), b: Plane(normal: (1, 0, 0), \
                 offset: param(\"cut\", 0))))";
    assert_eq!(SceneFile::parse(older).unwrap(), file);
    // A zero normal is blamed on the cut plane as written.
    let err = SceneFile::parse(
        "(version: 1,\n geometry: CutPlane(normal: 0, offset: 0, child: Sphere(radius: 1)))",
    )
    .unwrap_err()
    .to_string();
    assert!(err.starts_with("<scene>:2:12:"), "{err}");
    assert!(err.contains("`normal`"), "{err}");
}

/// Every scene file the crate ships, gallery or not, loads and compiles.
#[test]
fn every_shipped_scene_file_loads() {
    let mut count = 0;
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "ron") {
            continue;
        }
        let file = SceneFile::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        file.scene
            .compile()
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        file.effects
            .validate()
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        count += 1;
    }
    assert!(count > gallery::names().len(), "{count} scene files");
}

/// The guide's benchmark scenes load and compile: the one-formula scenes
/// of its cost table (`benches/formulas`) and the Mandelbox drawn from its
/// estimate and by brute force (`benches/brute`).
#[test]
fn the_benchmark_scenes_load() {
    for (folder, least) in [("benches/formulas", 13), ("benches/brute", 3)] {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(folder);
        let mut count = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let file = SceneFile::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            file.scene
                .compile()
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            count += 1;
        }
        assert!(count >= least, "{count} scenes in {}", dir.display());
    }
}

/// Keyframed tracks in a file: a parameter's keys and a path's optional
/// camera fields read back as written; a track that takes a parameter out
/// of its range between its keys (a spline's overshoot), keys out of
/// order, and a camera field on some keyframes only are each refused where
/// they are written.
#[test]
fn keyframed_tracks_read_back_and_bad_ones_are_located() {
    use fractal_sdf::animation::{Interpolation, Motion};
    let file = |motion: &str, path: &str| {
        format!(
            "(\n    version: 1,\n    geometry: Sphere(radius: param(\"r\", 0.5)),\n    \
             motions: [\n        {motion},\n    ],\n    path: [\n{path}\n    ],\n)"
        )
    };
    let keys = "Keys(name: \"r\", keys: [(time: 0, value: 0.5, interpolation: EaseInOut), \
                (time: 2, value: 1), (time: 3, value: 0.8, interpolation: Step)])";
    let path = "        (time: 0, position: (0, 0, 4), target: (0, 0, 0), fov_y_degrees: 40, \
                roll_degrees: 0),\n        (time: 2, position: (0, 1, 3), target: (0, 0, 0), \
                interpolation: Linear, fov_y_degrees: 30, roll_degrees: 10),";
    let read = SceneFile::parse(&file(keys, path)).unwrap();
    let Motion::Keys {
        keys: read_keys, ..
    } = &read.motions[0]
    else {
        panic!("{:?}", read.motions)
    };
    assert_eq!(read_keys.len(), 3);
    assert_eq!(read_keys[0].interpolation, Interpolation::EaseInOut);
    assert_eq!(read_keys[1].interpolation, Interpolation::CatmullRom);
    assert_eq!(read.motions[0].values(1.0)[0].1, 0.75);
    let path_read = read.path.as_ref().unwrap();
    assert_eq!(path_read.keyframes()[1].roll_degrees, Some(10.0));
    assert_eq!(SceneFile::parse(&read.to_text().unwrap()).unwrap(), read);

    // Through 0.5, 0.05 and 0.5 on a spline: below 0 between the keys.
    let dips = "Keys(name: \"r\", keys: [(time: 0, value: 0.5), (time: 1, value: 0.05), \
                (time: 1.1, value: 0.5)])";
    let (line, column, message) = error_at(&file(dips, path));
    assert_eq!((line, column), (5, 9), "{message}");
    assert!(message.contains("must be >= 0"), "{message}");
    let backwards = "Keys(name: \"r\", keys: [(time: 1, value: 0.5), (time: 0, value: 1)])";
    let (line, _, message) = error_at(&file(backwards, path));
    assert_eq!(line, 5, "{message}");
    assert!(message.contains("later than the key before"), "{message}");
    let partly = path.replace(", fov_y_degrees: 30", "");
    let err = SceneFile::parse(&file(keys, &partly))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("`fov_y_degrees` must be on every keyframe or on none"),
        "{err}"
    );
}

/// The crate's `scenes/sky.hdr` is the sky `EnvironmentMap::sky` makes for
/// the gallery, to the precision of the file's shared exponents (1%);
/// `UPDATE_SCENES=1` writes it again.
#[test]
fn the_shipped_sky_is_the_gallery_sky() {
    let (w, h) = gallery::SKY_SIZE;
    let made = EnvironmentMap::sky(w, h, gallery::SKY_SUN).unwrap();
    let path = scenes_dir().join("sky.hdr");
    if std::env::var_os("UPDATE_SCENES").is_some() {
        made.save_hdr(&path).unwrap();
    }
    let shipped = EnvironmentMap::load(&path).unwrap();
    assert_eq!((shipped.width(), shipped.height()), (w, h));
    for (a, b) in made.texels().iter().zip(shipped.texels()) {
        for c in 0..3 {
            let scale = a.iter().fold(0.0f32, |m, v| m.max(*v));
            assert!((a[c] - b[c]).abs() <= 0.01 * scale, "{a:?} vs {b:?}");
        }
    }
    // The sun is where the gallery says, a thousand times the sky.
    let sun = gallery::sky().radiance(gallery::SKY_SUN);
    let beside = gallery::sky().radiance(DVec3::Y);
    assert!(sun.x > 300.0 && beside.x < 0.5, "{sun} {beside}");
}

/// An environment's image is found beside the file that names it; a
/// missing one, or a bad intensity, is an error at the `environment`
/// field; an image made in memory has no name to write.
#[test]
fn an_environment_is_read_beside_its_file_and_errors_are_located() {
    let dir = std::env::temp_dir().join(format!("fractal-sdf-env-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("maps")).unwrap();
    let map = EnvironmentMap::new(4, 2, vec![[0.5, 1.0, 2.0]; 8]).unwrap();
    map.save_hdr(dir.join("maps/small.hdr")).unwrap();
    let text = |image: &str, intensity: &str| {
        format!(
            "(version: 1, geometry: Sphere(radius: 1.0),\n environment: (image: \"{image}\", \
             rotation_degrees: 30.0, intensity: {intensity}))"
        )
    };
    let path = dir.join("scene.ron");
    std::fs::write(&path, text("maps/small.hdr", "2.0")).unwrap();
    let file = SceneFile::load(&path).unwrap();
    let env = file.scene.environment.as_ref().unwrap();
    assert_eq!(env.source.as_deref(), Some(Path::new("maps/small.hdr")));
    assert_eq!((env.rotation_degrees, env.intensity), (30.0, 2.0));
    assert_eq!(env.map.texels()[0], [0.5, 1.0, 2.0]);
    // Written back, it names the image as the file did.
    assert!(
        file.to_text()
            .unwrap()
            .contains("image: \"maps/small.hdr\"")
    );
    for (text, says) in [
        (
            text("maps/none.hdr", "1.0"),
            "cannot read the environment image",
        ),
        (text("maps/small.hdr", "-1.0"), "intensity -1"),
        (text("scene.ron", "1.0"), "`.hdr` or an OpenEXR `.exr`"),
    ] {
        std::fs::write(&path, &text).unwrap();
        let err = SceneFile::load(&path).unwrap_err().to_string();
        assert!(err.contains(":2:") && err.contains(says), "{err}");
    }
    let made = Scene::new(sphere(1.0)).with_environment(Environment::new(map));
    let err = SceneFile::from(made).to_text().unwrap_err().to_string();
    assert!(err.contains("EnvironmentMap::save_hdr"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A glow node in a file: read as `Node::glow` builds it, written back
/// the same, and its bad values located.
#[test]
fn glow_nodes_read_back_and_bad_ones_are_located() {
    let text = "(version: 1, geometry: Glow(color: (1, 0.5, 0.2), strength: param(\"g\", 1.5), \
                child: Sphere(radius: 1)))";
    let file = SceneFile::parse(text).unwrap();
    let built = sphere(1.0).glow(dvec3(1.0, 0.5, 0.2), param("g", 1.5));
    assert_eq!(file.scene.geometry, Some(built));
    let again = SceneFile::parse(&file.to_text().unwrap()).unwrap();
    assert_eq!(again, file);
    let err = SceneFile::parse(
        "(version: 1, geometry: Glow(color: (1, 0.5, 0.2), strength: -1, child: Sphere(radius: 1)))",
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("strength"), "{err}");
}
