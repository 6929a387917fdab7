//! No silently wrong image from numbers: a value the chosen precision
//! cannot hold is a typed error naming it, degenerate vectors normalise
//! robustly, the CPU reference stays finite for every accepted value, and
//! the quality knobs stay above what the precision can resolve.

use crate::gpu;

use fractal_sdf::codegen;
use fractal_sdf::cpu::{self, Evaluator};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Glow;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{DeviceSelector, Frame, PointEvaluator, RenderOptions, Renderer};
use fractal_sdf::scene::Param;
use fractal_sdf::scene::ellipsoid;
use fractal_sdf::scene::param3;
use glam::EulerRot;

const SAFELY: &str = "cannot be represented safely in";

/// Draft quality in `precision`, no effects: the cheapest image.
fn options(precision: Precision) -> RenderOptions {
    gpu::options(
        gpu::plain(Quality::draft()).precision(precision),
        Effects::none(),
    )
}

/// Renders `scene` (with dynamic values `sets`) at 16x12, or the error.
fn render(
    scene: &Scene,
    options: &RenderOptions,
    sets: &[(&str, f64)],
) -> Result<(Renderer, Frame)> {
    let mut renderer = Renderer::with_options(scene, options)?;
    for (name, value) in sets {
        renderer.set_param(name, *value)?;
    }
    let frame = renderer.render_with_aovs(16, 12)?;
    Ok((renderer, frame))
}

/// The share of pixels whose device hit flag matches `cpu::march` on the
/// same rays, and the number of CPU hits.
fn agreement(renderer: &Renderer, frame: &Frame, sets: &[(&str, f64)]) -> (f64, usize) {
    let (w, h) = (frame.width(), frame.height());
    let view = renderer.viewport(w, h).unwrap();
    let settings = view.march_settings(&renderer.options().quality);
    let mut eval = Evaluator::from_compiled(renderer.scene());
    for (name, value) in sets {
        eval.set_param(name, *value).unwrap();
    }
    let (mut same, mut hits) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let reference = cpu::march(&eval, ray, &settings);
            hits += usize::from(reference.hit);
            same += usize::from(reference.hit == frame.hit[frame.index(x, y)]);
        }
    }
    (same as f64 / f64::from(w * h), hits)
}

/// Either a typed error that says the value cannot be held in F32 (not a
/// build failure), or an image that draws what the CPU reference draws.
fn refused_or_drawn(what: &str, scene: &Scene, options: &RenderOptions, sets: &[(&str, f64)]) {
    match render(scene, options, sets) {
        Err(e) => {
            assert!(
                !matches!(e, Error::Build { .. }),
                "{what}: the kernel failed to build: {}",
                e.to_string().lines().next().unwrap_or("")
            );
            assert!(
                e.to_string().contains(SAFELY),
                "{what}: refused, but not for its precision: {e}"
            );
        }
        Ok((renderer, frame)) => {
            let (same, hits) = agreement(&renderer, &frame, sets);
            assert!(hits > 0, "{what}: the CPU reference draws nothing");
            assert!(
                same >= 0.95,
                "{what}: the image agrees with the CPU reference on {same:.2} of the hit mask"
            );
        }
    }
}

fn camera() -> Camera {
    Camera::look_at(dvec3(0.0, 1.0, 4.0), DVec3::ZERO)
}

#[test]
fn values_beyond_f32_are_refused_before_the_build() {
    let Some(_) = gpu::device() else { return };
    let big = 1e39;
    let scene = |node: Node| Scene::new(node).with_camera(camera());
    let f32_options = options(Precision::F32);
    for (what, scene) in [
        ("baked radius", scene(sphere(big))),
        ("dynamic default", scene(sphere(param("r", big)))),
        (
            "translation",
            scene(sphere(1.0).translate(dvec3(0.0, big, 0.0))),
        ),
    ] {
        let err = Renderer::with_options(&scene, &f32_options).unwrap_err();
        assert!(!matches!(err, Error::Build { .. }), "{what}: a build error");
        let text = err.to_string();
        assert!(
            text.contains(SAFELY) && text.contains("F32"),
            "{what}: {text}"
        );
    }
    let plain = scene(sphere(1.0));
    let quality = f32_options
        .clone()
        .quality(gpu::plain(Quality::draft()).max_distance(big));
    let fog = f32_options
        .clone()
        .effects(Effects::none().fog_density(big));
    let glow = f32_options.effects(Effects::none().glow(Glow::new(dvec3(1.0, 1.0, 1.0), big)));
    for (what, options) in [("max_distance", quality), ("fog", fog), ("glow", glow)] {
        let err = Renderer::with_options(&plain, &options).unwrap_err();
        let text = err.to_string();
        assert!(
            !matches!(err, Error::Build { .. }) && text.contains(SAFELY),
            "{what}: {}",
            text.lines().next().unwrap_or("")
        );
    }
    // The point evaluator holds its program to the same limits.
    let big_sphere = Scene::new(sphere(big)).compile().unwrap();
    let err = PointEvaluator::from_compiled(&big_sphere, Precision::F32, &DeviceSelector::auto())
        .unwrap_err();
    assert!(err.to_string().contains(SAFELY), "{err}");
    let dynamic = Scene::new(sphere(param("r", 1.0))).compile().unwrap();
    let mut points =
        PointEvaluator::from_compiled(&dynamic, Precision::F32, &DeviceSelector::auto()).unwrap();
    let err = points.set_param("r", big).unwrap_err();
    assert!(err.to_string().contains(SAFELY), "{err}");
    // The sphere's distance at its centre, `length(0) - 1`, is exact in any
    // precision (measured 0 in F32); 1e-6 is about 8 f32 ulps of 1.
    assert!((points.eval(&[DVec3::ZERO]).unwrap()[0].distance + 1.0).abs() < 1e-6);
    // The same values are fine where they fit.
    let mut renderer = Renderer::with_options(&plain, &options(Precision::F64)).unwrap();
    renderer
        .set_quality(
            gpu::plain(Quality::draft())
                .precision(Precision::F64)
                .max_distance(big),
        )
        .unwrap();
}

#[test]
fn values_that_overflow_inside_an_f32_kernel_are_refused_or_drawn() {
    let Some(_) = gpu::device() else { return };
    let f32_options = options(Precision::F32);
    let scene = |node: Node| Scene::new(node).with_camera(camera());
    let box_ = || cuboid(dvec3(0.6, 0.3, 0.4));
    type Case<'a> = (&'a str, Scene, Vec<(&'a str, f64)>);
    let cases: Vec<Case> = vec![
        (
            "dynamic rotation angle 1e300",
            scene(box_().rotate(dvec3(0.0, 1.0, 0.0), param("angle", 0.5))),
            vec![("angle", 1e300)],
        ),
        (
            "smoothing k 1e300",
            scene(sphere(0.5).smooth_union(box_(), 1e300)),
            vec![],
        ),
        (
            "repeat period 1e-40",
            scene(sphere(0.5).repeat(dvec3(1e-40, 0.0, 0.0))),
            vec![],
        ),
        (
            "capsule end 1e30",
            scene(capsule(dvec3(0.0, 0.0, 0.0), dvec3(0.0, 1e30, 0.0), 0.3)),
            vec![],
        ),
        (
            "dynamic capsule end 1e30",
            scene(capsule(
                dvec3(0.0, 0.0, 0.0),
                param3("end", dvec3(0.0, 1.0, 0.0)),
                0.3,
            )),
            vec![("end.y", 1e30)],
        ),
        (
            "orthographic height 1e300",
            scene(sphere(1.0)).with_camera(camera().orthographic(1e300)),
            vec![],
        ),
    ];
    for (what, scene, sets) in cases {
        refused_or_drawn(what, &scene, &f32_options, &sets);
    }
}

#[test]
fn a_huge_up_vector_gives_the_image_of_a_unit_one() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let unit = scene
        .clone()
        .with_camera(scene.camera.up(dvec3(0.0, 1.0, 0.0)));
    let huge = scene
        .clone()
        .with_camera(scene.camera.up(dvec3(0.0, 1e300, 0.0)));
    let tiny = scene
        .clone()
        .with_camera(scene.camera.up(dvec3(0.0, 1e-300, 0.0)));
    let options = options(Precision::F32);
    let (_, expected) = render(&unit, &options, &[]).unwrap();
    for (what, scene) in [("1e300", huge), ("1e-300", tiny)] {
        let (_, frame) = render(&scene, &options, &[]).unwrap_or_else(|e| panic!("{what}: {e}"));
        assert!(
            frame.image == expected.image,
            "up of length {what}: a different image"
        );
    }
}

#[test]
fn a_light_direction_of_any_length_lights_the_scene() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor();
    let direction = dvec3(0.5, 1.0, 0.6);
    let lit = |scale: f64| {
        scene
            .clone()
            .with_lights([Light::directional(direction * scale)])
    };
    let options = options(Precision::F32);
    let (_, expected) = render(&lit(1.0), &options, &[]).unwrap();
    for scale in [1e200, 1e-200] {
        let (_, frame) =
            render(&lit(scale), &options, &[]).unwrap_or_else(|e| panic!("{scale}: {e}"));
        assert!(
            frame.image == expected.image,
            "direction scaled by {scale}: a different image"
        );
    }
}

#[test]
fn plane_normals_of_any_length_draw_the_plane_in_f32() {
    let Some(_) = gpu::device() else { return };
    let normal = dvec3(0.3, 1.0, 0.2);
    let floor = |scale: f64| {
        Scene::new(plane(normal * scale, 0.5).union(sphere(0.5))).with_camera(camera())
    };
    let options = options(Precision::F32);
    let (_, expected) = render(&floor(1.0), &options, &[]).unwrap();
    for scale in [1e-31, 1e-40, 1e155, 1e200] {
        let (_, frame) =
            render(&floor(scale), &options, &[]).unwrap_or_else(|e| panic!("{scale}: {e}"));
        let same = frame
            .hit
            .iter()
            .zip(&expected.hit)
            .filter(|(a, b)| a == b)
            .count();
        assert!(
            same as f64 >= 0.99 * expected.hit.len() as f64,
            "normal scaled by {scale}: {same} of {} hit flags agree",
            expected.hit.len()
        );
    }
    // A dynamic normal that F32 cannot normalise is refused, or drawn.
    let dynamic =
        Scene::new(plane(param3("n", normal), 0.5).union(sphere(0.5))).with_camera(camera());
    for scale in [1e-31, 1e30] {
        let sets = [
            ("n.x", normal.x * scale),
            ("n.y", normal.y * scale),
            ("n.z", normal.z * scale),
        ];
        refused_or_drawn(
            &format!("dynamic normal x {scale}"),
            &dynamic,
            &options,
            &sets,
        );
    }
}

#[test]
fn the_cpu_reference_is_finite_for_every_accepted_value() {
    let points = [
        DVec3::ZERO,
        dvec3(0.5, 0.25, -0.1),
        dvec3(3.0, -2.0, 1.0),
        dvec3(1e3, 1e3, 1e3),
        dvec3(-1e6, 0.0, 1e6),
    ];
    for (what, node) in [
        ("ellipsoid 1e-300", ellipsoid(dvec3(1e-300, 1.0, 1.0))),
        (
            "ellipsoid 1e-300 everywhere",
            ellipsoid(dvec3(1e-300, 1e-300, 1e-300)),
        ),
        (
            "ellipsoid 1e-200 and 1e200",
            ellipsoid(dvec3(1e-200, 1e200, 1.0)),
        ),
        (
            "ellipsoid 1e-150 and 1e150",
            ellipsoid(dvec3(1e-150, 1e150, 1.0)),
        ),
        ("ellipsoid 1e-150", ellipsoid(dvec3(1e-150, 1e-150, 1e-150))),
        (
            "ellipsoid 1e-18 and 1e18",
            ellipsoid(dvec3(1e-18, 1e18, 1.0)),
        ),
        ("ellipsoid 1e-18", ellipsoid(dvec3(1e-18, 1.0, 1.0))),
        ("twist 1e18", cuboid(dvec3(0.5, 0.5, 0.5)).twist(1e18)),
        ("scale 1e-300", sphere(1.0).scale(1e-300)),
        ("scale 1e300", sphere(1.0).scale(1e300)),
        ("sphere 1e300", sphere(1e300)),
        ("twist 1e300", cuboid(dvec3(0.5, 0.5, 0.5)).twist(1e300)),
        ("smooth 1e300", sphere(0.5).smooth_union(sphere(0.3), 1e300)),
    ] {
        let Ok(compiled) = Scene::new(node).compile() else {
            continue;
        };
        let eval = Evaluator::from_compiled(&compiled);
        // The f32 reference, for what an F32 program accepts.
        let f32_program = codegen::Options::default().quality(gpu::plain(Quality::draft()));
        let in_f32 = codegen::emit(&compiled, &f32_program).is_ok();
        for p in points {
            let s = eval.sample::<f64>(p.into());
            assert!(
                s.distance.is_finite() && s.trap.is_finite(),
                "{what}: distance {} at {p}",
                s.distance
            );
            if in_f32 {
                let s = eval.sample::<f32>(p.as_vec3().into());
                assert!(
                    s.distance.is_finite() && s.trap.is_finite(),
                    "{what}: f32 distance {} at {p}",
                    s.distance
                );
            }
        }
    }
}

#[test]
fn knobs_below_the_resolution_of_the_precision_are_refused() {
    for precision in [Precision::F32, Precision::F64] {
        let q = gpu::plain(Quality::draft()).precision(precision);
        for (what, bad) in [
            ("detail", q.detail(1e-300)),
            ("hit_epsilon", q.hit_epsilon(1e-300)),
            ("normal_epsilon", q.normal_epsilon(1e-300)),
            ("max_distance", q.max_distance(1e-300)),
            ("max_distance", q.max_distance(1e300)),
            ("detail", q.detail(1e300)),
            ("normal_epsilon", q.normal_epsilon(1e300)),
        ] {
            let err = bad.validate().expect_err(what);
            assert!(err.to_string().contains(what), "{what}: {err}");
        }
        q.validate().unwrap();
    }
    // The F32 floor is coarser than the F64 one.
    let fine = Quality::reference().hit_epsilon(1e-9);
    fine.validate().unwrap();
    assert!(fine.precision(Precision::F32).validate().is_err());
    for (what, bad) in [
        ("ao_distance", Effects::default().ao_distance(1e-300)),
        ("fog_density", Effects::default().fog_density(1e300)),
        ("gamma", Effects::default().gamma(1e-300)),
    ] {
        let err = bad.validate().expect_err(what);
        assert!(err.to_string().contains(what), "{what}: {err}");
    }
}

#[test]
fn degenerate_rotations_are_refused_and_huge_axes_normalise() {
    let shape = || cuboid(dvec3(0.5, 0.3, 0.2));
    for (what, node) in [
        (
            "zero quaternion",
            shape().rotate_quat(DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0)),
        ),
        (
            "NaN quaternion",
            shape().rotate_quat(DQuat::from_xyzw(f64::NAN, 0.0, 0.0, 1.0)),
        ),
        (
            "infinite quaternion",
            shape().rotate_quat(DQuat::from_xyzw(f64::INFINITY, 0.0, 0.0, 1.0)),
        ),
        (
            "NaN Euler angle",
            shape().rotate_euler(EulerRot::XYZ, f64::NAN, 0.0, 0.0),
        ),
        ("zero axis", shape().rotate(DVec3::ZERO, 1.0)),
    ] {
        let err = Scene::new(node).compile().expect_err(what);
        assert!(err.to_string().contains("axis"), "{what}: {err}");
    }
    // Length 1e200 and 1e-200: the rotation of the unit axis. Normalising
    // puts the scaled axis (and below, the scaled quaternion) within an ulp
    // or two of the unit one, and both sides are then the same f64
    // operations on values below 2: measured 0 at all 5 points; the
    // tolerances are about 20 ulps of 2.
    let unit = Evaluator::new(&shape().rotate(dvec3(1.0, 2.0, 2.0), 0.7)).unwrap();
    for scale in [1e200, 1e-200] {
        let eval = Evaluator::new(&shape().rotate(dvec3(1.0, 2.0, 2.0) * scale, 0.7)).unwrap();
        for p in [dvec3(0.3, 0.4, 0.5), dvec3(-1.0, 0.2, 0.7)] {
            assert!(
                (eval.distance(p) - unit.distance(p)).abs() < 1e-14,
                "{scale}"
            );
        }
    }
    // A huge quaternion is the rotation of its unit.
    let q = DQuat::from_axis_angle(dvec3(0.0, 0.6, 0.8), 0.9);
    let unit = Evaluator::new(&shape().rotate_quat(q)).unwrap();
    let huge = Evaluator::new(&shape().rotate_quat(DQuat::from_vec4(glam::DVec4::from(q) * 1e300)))
        .unwrap();
    let p = dvec3(0.3, -0.4, 0.5);
    assert!((huge.distance(p) - unit.distance(p)).abs() < 1e-14);
}

#[test]
fn a_renderer_checks_its_inputs_against_its_precision_as_they_change() {
    let Some(_) = gpu::device() else { return };
    let scene = Scene::new(sphere(param("r", 1.0)).translate(param3("at", DVec3::ZERO)))
        .with_camera(camera());
    let mut renderer = Renderer::with_options(&scene, &options(Precision::F64)).unwrap();
    // Fine in F64...
    renderer.set_param("at.x", 1e30).unwrap();
    // ...but not in the F32 program a quality change asks for.
    let err = renderer
        .set_quality(gpu::plain(Quality::draft()).precision(Precision::F32))
        .unwrap_err();
    assert!(
        matches!(&err, Error::Precision { node, param, precision: "F32", .. }
            if node == "translate" && param == "offset.x"),
        "{err}"
    );
    renderer.set_param("at.x", 0.0).unwrap();
    renderer
        .set_quality(gpu::plain(Quality::draft()).precision(Precision::F32))
        .unwrap();
    // Now in F32: dynamic values, cameras and lights beyond it are refused
    // and leave the renderer as it was.
    let err = renderer.set_param("r", 1e30).unwrap_err();
    assert!(err.to_string().contains(SAFELY), "{err}");
    assert_eq!(renderer.param("r"), Some(1.0));
    let err = renderer
        .set_camera(camera().orthographic(1e30))
        .unwrap_err();
    assert!(
        matches!(&err, Error::Precision { node, .. } if node == "camera"),
        "{err}"
    );
    let err = renderer
        .set_lights([Light::point(dvec3(0.0, 1e30, 0.0))])
        .unwrap_err();
    assert!(
        matches!(&err, Error::Precision { node, .. } if node == "light[0]"),
        "{err}"
    );
    assert_eq!(renderer.lights().len(), 2);
    renderer.render(8, 6).unwrap();
}

#[test]
fn angles_of_any_size_turn_the_same_on_the_cpu_and_the_device() {
    let Some(_) = gpu::device() else { return };
    let spin = |angle: Param| {
        Scene::new(cuboid(dvec3(0.6, 0.3, 0.4)).rotate(dvec3(0.0, 1.0, 0.0), angle))
            .with_camera(camera())
    };
    let options = options(Precision::F32);
    for angle in [1e10, -1e300, 1e300] {
        // Baked and dynamic turn by the same reduced angle.
        let (_, baked) = render(&spin(Param::Value(angle)), &options, &[]).unwrap();
        let (renderer, dynamic) =
            render(&spin(param("a", 0.0)), &options, &[("a", angle)]).unwrap();
        assert!(
            baked.hit == dynamic.hit,
            "angle {angle}: baked and dynamic differ"
        );
        let (same, hits) = agreement(&renderer, &dynamic, &[("a", angle)]);
        assert!(hits > 0 && same >= 0.95, "angle {angle}: {same}");
    }
}
