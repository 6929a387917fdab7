//! Inside shapes: sets given only by a membership test, marched by brute
//! force (see `fractal_sdf::scene::InsideShape`).

use fractal_sdf::cpu::{self, Brute, Ray};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;
use fractal_sdf::quality::ScreenNormals;
use fractal_sdf::render::{DeviceSelector, Frame, RenderOptions, Renderer};
use fractal_sdf::scene::Axis;
use fractal_sdf::scene::InsideBounds;
use fractal_sdf::scene::InsideShape;
use fractal_sdf::scene::param3;
use fractal_sdf::scene::{INSIDE_HUGE, Rule};
use fractal_sdf::testing::{
    check_inside_agrees_with_de, check_inside_matches_device, random_points,
};

const RADIUS: f64 = 1.0;

/// A ball known only by `|p| < r`.
fn ball() -> InsideShape {
    ball_shape("ball", 1.5, "return length(p) < r;")
}

/// A shape called `name` whose CPU test is `|p| < r`, with its OpenCL
/// body and bounds of `bounds` about the origin.
fn ball_shape(name: &str, bounds: f64, opencl: &str) -> InsideShape {
    InsideShape::new(
        name,
        &[("r", Rule::Positive)],
        InsideBounds::sphere(DVec3::ZERO, bounds),
        |p, a| p.length() < a[0],
        opencl,
    )
    .unwrap()
}

fn camera() -> Camera {
    Camera::look_at(dvec3(0.0, 0.4, 3.2), DVec3::ZERO).fov(40.0)
}

fn options(quality: Quality) -> RenderOptions {
    let mut options = RenderOptions::default().quality(quality);
    options.effects.shadows = false;
    options
}

fn frame(
    scene: &Scene,
    quality: Quality,
    (w, h): (u32, u32),
) -> (Frame, fractal_sdf::render::Viewport) {
    let mut renderer = Renderer::with_options(scene, &options(quality)).unwrap();
    let frame = renderer.render_with_aovs(w, h).unwrap();
    (frame, renderer.viewport(w, h).unwrap())
}

/// Where the ray first meets the sphere of `radius` about `centre`.
fn sphere_hit(ray: Ray, centre: DVec3, radius: f64) -> Option<f64> {
    let oc = ray.origin - centre;
    let b = oc.dot(ray.direction);
    let disc = b * b - (oc.length_squared() - radius * radius);
    (disc >= 0.0).then(|| -b - disc.sqrt()).filter(|t| *t > 0.0)
}

/// The chord a ray cuts through the sphere.
fn chord(ray: Ray, centre: DVec3, radius: f64) -> f64 {
    let oc = ray.origin - centre;
    let b = oc.dot(ray.direction);
    let disc = b * b - (oc.length_squared() - radius * radius);
    2.0 * disc.max(0.0).sqrt()
}

fn angle_degrees(a: DVec3, b: DVec3) -> f64 {
    a.normalize()
        .dot(b.normalize())
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

#[test]
fn brute_force_hits_lie_within_a_step_of_the_surface() {
    let scene = Scene::new(ball().node([RADIUS])).with_camera(camera());
    let step = 2.0;
    let quality = Quality::production().brute_step(step);
    let (frame, view) = frame(&scene, quality, (96, 72));
    let settings = view.march_settings(&quality);
    let (mut hits, mut worst, mut grazing_misses) = (0, 0.0f64, 0);
    for y in 0..frame.height() {
        for x in 0..frame.width() {
            let i = frame.index(x, y);
            let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let footprint = settings.footprint(f64::from(frame.depth[i]));
            match (frame.hit[i], sphere_hit(ray, DVec3::ZERO, RADIUS)) {
                (true, Some(t)) => {
                    hits += 1;
                    let error = (f64::from(frame.depth[i]) - t).abs() / footprint;
                    worst = worst.max(error);
                }
                (true, None) => panic!("pixel ({x}, {y}) hits outside the ball"),
                (false, Some(_)) => {
                    // Only a ray whose chord is shorter than a step may pass.
                    let h = step * settings.footprint(3.2);
                    assert!(
                        chord(ray, DVec3::ZERO, RADIUS) < 2.0 * h,
                        "pixel ({x}, {y}) misses the ball across a chord of {}",
                        chord(ray, DVec3::ZERO, RADIUS)
                    );
                    grazing_misses += 1;
                }
                (false, None) => {}
            }
        }
    }
    eprintln!(
        "ball, brute step {step}: {hits} hits, depth error at most {worst:.4} footprints, \
         {grazing_misses} grazing rays missed"
    );
    assert!(hits > 1500, "{hits} hits");
    assert!(
        worst <= step,
        "a hit is {worst} footprints off, more than a step"
    );
}

#[test]
fn bisection_locates_the_crossing_to_hit_epsilon() {
    let node = ball().node([RADIUS]);
    let eval = cpu::Evaluator::new(&node).unwrap();
    for hit_epsilon in [0.05, 0.001] {
        let settings = cpu::MarchSettings::default()
            .footprint_base(0.0)
            .footprint_per_unit(0.004)
            .detail(0.5)
            .hit_epsilon(hit_epsilon)
            .max_steps(512);
        let mut worst = 0.0f64;
        let mut rays = 0;
        for k in 0..200 {
            let phase = f64::from(k) / 200.0;
            let target = dvec3(
                0.3 * (f64::from(k) * 0.37).sin(),
                0.3 * (f64::from(k) * 0.71).cos(),
                0.0,
            );
            let origin = dvec3(0.0, 0.4, 3.2);
            let ray = Ray::new(origin, (target - origin).normalize());
            let brute = Brute::of(&eval, 4.0, phase).expect("a scene with an inside shape");
            let hit = cpu::march_brute(&eval, ray, &settings, &brute);
            let t = sphere_hit(ray, DVec3::ZERO, RADIUS).unwrap();
            assert!(hit.hit, "ray {k} misses");
            let error = (hit.depth - t).abs() / settings.footprint(t);
            worst = worst.max(error);
            rays += 1;
        }
        eprintln!("bisection, hit_epsilon {hit_epsilon}: {rays} rays, worst {worst:.5} footprints");
        assert!(
            worst <= hit_epsilon * 1.01,
            "located to {worst} footprints, not {hit_epsilon}"
        );
    }
}

#[test]
fn the_device_marches_as_the_cpu_twin_does() {
    // Sample 0 of each pixel, in F64: the CPU twin takes the kernel's
    // phase and marches the same lattice, so every step and every
    // evaluation of the bisection agree.
    let scene = Scene::new(ball().node([RADIUS])).with_camera(camera());
    let quality = Quality::production().precision(Precision::F64);
    let (w, h) = (64, 48);
    let (frame, view) = frame(&scene, quality, (w, h));
    let settings = view.march_settings(&quality);
    let eval = cpu::Evaluator::new(&ball().node([RADIUS])).unwrap();
    let (mut compared, mut worst) = (0, 0.0f64);
    for y in 0..h {
        for x in 0..w {
            let i = frame.index(x, y);
            let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let phase = fractal_sdf::render::brute_phase(w, x, y, 0);
            let brute = Brute::of(&eval, quality.brute_step, phase).unwrap();
            let cpu = cpu::march_brute(&eval, ray, &settings, &brute);
            assert_eq!(frame.hit[i], cpu.hit, "pixel ({x}, {y})");
            if cpu.hit {
                assert_eq!(frame.steps[i], cpu.steps, "pixel ({x}, {y}): evaluations");
                let gap = (f64::from(frame.depth[i]) - cpu.depth).abs();
                worst = worst.max(gap);
                assert!(
                    gap <= 1e-6 * cpu.depth,
                    "pixel ({x}, {y}): depths {} and {}",
                    frame.depth[i],
                    cpu.depth
                );
                compared += 1;
            }
        }
    }
    eprintln!(
        "device and CPU twin: {compared} hits with equal evaluations, depths within {worst:e}"
    );
    assert!(compared > 400, "{compared} hits compared");
}

#[test]
fn screen_space_normals_of_a_sphere_are_close_to_its_own() {
    let scene = Scene::new(ball().node([RADIUS])).with_camera(camera());
    for (method, mean_limit, typical_limit) in [
        (ScreenNormals::Differences, 1.0, 0.75),
        (ScreenNormals::LeastSquares, 1.0, 0.75),
    ] {
        let quality = Quality::production().screen_normals(method);
        let (frame, view) = frame(&scene, quality, (96, 72));
        let mut angles = Vec::new();
        for y in 0..frame.height() {
            for x in 0..frame.width() {
                let i = frame.index(x, y);
                let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
                // Away from the silhouette, where every neighbour is on the ball.
                if !frame.hit[i] || chord(ray, DVec3::ZERO, RADIUS) < 0.6 {
                    continue;
                }
                let p = ray.origin + ray.direction * f64::from(frame.depth[i]);
                let n = DVec3::from(frame.normal[i].map(f64::from));
                angles.push(angle_degrees(n, p));
            }
        }
        angles.sort_by(f64::total_cmp);
        let mean = angles.iter().sum::<f64>() / angles.len() as f64;
        let median = angles[angles.len() / 2];
        let p95 = angles[angles.len() * 95 / 100];
        eprintln!(
            "{method:?}: {} pixels, mean {mean:.2}°, median {median:.2}°, 95th percentile {p95:.2}°",
            angles.len()
        );
        assert!(angles.len() > 1000);
        assert!(mean < mean_limit, "{method:?}: mean angle {mean}°");
        assert!(median < typical_limit, "{method:?}: median angle {median}°");
    }
}

#[test]
fn a_mixed_scene_draws_both_kinds() {
    let left = dvec3(-0.7, 0.0, 0.0);
    let right = dvec3(0.7, 0.0, 0.0);
    let inside = ball()
        .node([0.5])
        .translate(left)
        .color(dvec3(0.9, 0.2, 0.1));
    let estimated = sphere(0.5).translate(right).color(dvec3(0.1, 0.3, 0.9));
    let alone = Scene::new(estimated.clone()).with_camera(camera());
    let scene = Scene::new(inside.union(estimated)).with_camera(camera());
    let quality = Quality::production();
    let (plain, _) = frame(&alone, quality, (96, 72));
    let (frame, view) = frame(&scene, quality, (96, 72));
    let (mut on_inside, mut on_estimated) = (0, 0);
    for y in 0..frame.height() {
        for x in 0..frame.width() {
            let i = frame.index(x, y);
            let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            if !frame.hit[i] {
                continue;
            }
            let p = ray.origin + ray.direction * f64::from(frame.depth[i]);
            let n = DVec3::from(frame.normal[i].map(f64::from));
            let pixel = frame.image.get_pixel(x, y).0;
            if (p - left).length() < 0.55 {
                on_inside += 1;
                assert!(
                    pixel[0] > pixel[2],
                    "pixel ({x}, {y}) on the red ball: {pixel:?}"
                );
            } else {
                assert!((p - right).length() < 0.55, "pixel ({x}, {y}) hits {p}");
                on_estimated += 1;
                assert!(
                    pixel[2] > pixel[0],
                    "pixel ({x}, {y}) on the blue sphere: {pixel:?}"
                );
                // The estimate's own normal, as in a scene without inside
                // shapes (at a hit the brute-force lattice moves by up to
                // hit_epsilon footprints).
                if chord(ray, right, 0.5) > 0.2 {
                    assert!(plain.hit[i], "pixel ({x}, {y})");
                    let m = DVec3::from(plain.normal[i].map(f64::from));
                    let angle = angle_degrees(n, m);
                    assert!(angle < 0.5, "pixel ({x}, {y}): normals {n} and {m}");
                }
            }
        }
    }
    eprintln!("mixed: {on_inside} pixels on the inside ball, {on_estimated} on the sphere");
    assert!(on_inside > 300 && on_estimated > 300);
    // The same scene on the CPU: the inside shape's value composes by sign.
    let eval = cpu::Evaluator::new(scene.geometry.as_ref().unwrap()).unwrap();
    assert_eq!(eval.distance(left), -INSIDE_HUGE);
    assert!((eval.distance(right) + 0.5).abs() < 1e-12);
    assert!((eval.distance(DVec3::ZERO) - 0.2).abs() < 1e-12);
}

#[test]
fn bad_bounds_and_combinations_are_refused_clearly() {
    let test = |p: DVec3, _: &[f64]| p.length() < 1.0;
    for (bounds, says) in [
        (
            InsideBounds::sphere(DVec3::ZERO, 0.0),
            "radius must be positive",
        ),
        (
            InsideBounds::sphere(DVec3::ZERO, f64::NAN),
            "radius must be positive",
        ),
        (
            InsideBounds::sphere(dvec3(f64::INFINITY, 0.0, 0.0), 1.0),
            "centre",
        ),
        (
            InsideBounds::cuboid(DVec3::ZERO, dvec3(1.0, -1.0, 1.0)),
            "half extents",
        ),
        // Regression: bounds of 1e300 passed, then panicked in code
        // generation ("non-finite literal").
        (InsideBounds::sphere(DVec3::ZERO, 1e300), "reach 1e300"),
        (
            InsideBounds::cuboid(dvec3(0.0, 2e12, 0.0), DVec3::ONE),
            "from the origin",
        ),
    ] {
        let err = InsideShape::new("blob", &[], bounds, test, "return 1;").unwrap_err();
        let text = err.to_string();
        assert!(matches!(err, Error::CustomShape { .. }), "{text}");
        assert!(text.contains(says), "{text}");
    }
    let shape = ball();
    let set = || shape.node([1.0]);
    for (node, says) in [
        (set().smooth_union(sphere(1.0), 0.1), "smooth union"),
        (
            sphere(1.0).smooth_subtract(set(), 0.1),
            "smooth subtraction",
        ),
        (set().round(0.1), "rounding"),
        (set().onion(0.1), "onion"),
        (set().repeat(dvec3(3.0, 3.0, 3.0)), "without bound"),
        (set().twist(0.5), "twist or a bend"),
        (set().bend(0.5), "twist or a bend"),
        (
            set().translate(param3("at", dvec3(1.0, 0.0, 0.0))),
            "without bound",
        ),
        (
            set().union(sphere(1.0).material(Material::mirror())),
            "materials",
        ),
    ] {
        let err = Scene::new(node).compile().unwrap_err();
        let text = err.to_string();
        assert!(matches!(err, Error::InsideShape { .. }), "{text}");
        assert!(text.contains("inside shape `ball`"), "{text}");
        assert!(text.contains(says), "{text}");
    }
    // What is allowed: hard booleans, transforms, mirrors, limited
    // repetition, colours.
    let allowed = set()
        .subtract(sphere(0.5))
        .intersect(cuboid(dvec3(2.0, 2.0, 2.0)))
        .union(sphere(0.3).subtract(set().scale(0.2)))
        .mirror(Axis::X)
        .repeat_limited(dvec3(3.0, 3.0, 3.0), [1, 0, 0])
        .rotate(DVec3::Y, 0.3)
        .color(dvec3(0.5, 0.5, 0.5));
    Scene::new(allowed).compile().unwrap();
}

#[test]
fn inside_tests_match_on_the_device() {
    let device = DeviceSelector::auto();
    let points = random_points(4000, 2.2, 11);
    for (shape, args) in [
        (InsideShape::mandelbulb(), [8.0, 10.0]),
        (InsideShape::mandelbox(), [-1.5, 12.0]),
    ] {
        let name = shape.shape().name().to_string();
        let exact =
            check_inside_matches_device(&shape, &args, &device, Precision::F64, &points, 0.0)
                .unwrap_or_else(|f| panic!("{name} in F64: {f}"));
        let rounded =
            check_inside_matches_device(&shape, &args, &device, Precision::F32, &points, 0.01)
                .unwrap_or_else(|f| panic!("{name} in F32: {f}"));
        eprintln!(
            "{name}: {} points agree in F64; in F32 {:.4} of the allowed 1% disagree",
            exact.inputs, rounded.worst
        );
    }
    // A twin that tests another set is caught.
    let wrong = ball_shape("wrong_ball", 1.5, "return length(p) < r * R(0.9);");
    let err = check_inside_matches_device(&wrong, &[1.0], &device, Precision::F32, &points, 0.001)
        .unwrap_err();
    assert!(
        err.to_string().contains("membership test disagrees"),
        "{err}"
    );
}

#[test]
fn the_estimate_and_the_test_of_the_mandelbulb_agree() {
    use fractal_sdf::scene::Mandelbulb;
    let de = Node::from(Mandelbulb::new(8.0).iterations(10));
    let bulb = InsideShape::mandelbulb();
    let points = random_points(20000, 1.3, 5);
    let margin = 0.025;
    let tested =
        check_inside_agrees_with_de(&de, |p| bulb.contains(p, &[8.0, 10.0]), &points, margin)
            .unwrap_or_else(|f| panic!("{f}"));
    eprintln!(
        "Mandelbulb: {} of {} points beyond {margin} agree; within it, disagreement up to {:.3} of the margin",
        tested.inputs,
        points.len(),
        tested.worst
    );
    assert!(tested.inputs > 15000);
    // The checker catches a set that is not the estimate's.
    let err = check_inside_agrees_with_de(&de, |p| bulb.contains(p, &[7.0, 10.0]), &points, margin)
        .unwrap_err();
    assert!(err.to_string().contains("disagree"), "{err}");
}

/// The mean brightness of the floor pixels within `radius` of `centre`
/// (in the floor's plane) that the camera sees, from the depth AOVs.
fn floor_brightness(
    frame: &Frame,
    view: &fractal_sdf::render::Viewport,
    centre: DVec3,
    radius: f64,
) -> (f64, usize) {
    let (mut sum, mut n) = (0.0, 0);
    for y in 0..frame.height() {
        for x in 0..frame.width() {
            let i = frame.index(x, y);
            if !frame.hit[i] {
                continue;
            }
            let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let p = ray.origin + ray.direction * f64::from(frame.depth[i]);
            let on_floor = (p.y + RADIUS).abs() < 0.05 && p.length() > RADIUS + 0.02;
            if on_floor && dvec3(p.x - centre.x, 0.0, p.z - centre.z).length() < radius {
                let px = frame.image.get_pixel(x, y).0;
                sum += f64::from(px[0]) + f64::from(px[1]) + f64::from(px[2]);
                n += 1;
            }
        }
    }
    (sum / (3.0 * n.max(1) as f64), n)
}

#[test]
fn inside_shapes_cast_shadows_and_occlude() {
    // A ball resting on a floor, lit from straight above.
    let scene = Scene::new(ball().node([RADIUS]).union(plane(DVec3::Y, RADIUS)))
        .with_camera(Camera::look_at(dvec3(0.0, 1.5, 4.0), dvec3(0.0, -0.6, 0.0)).fov(45.0))
        .with_lights(vec![Light::directional(DVec3::Y)]);
    let render = |shadows: bool, occlusion: bool| {
        let mut options = options(Quality::production());
        options.effects.shadows = shadows;
        options.effects.ambient_occlusion = occlusion;
        // Occlusion dims the sky's light: seen alone, without the sun.
        let scene = if occlusion {
            scene.clone().with_lights(vec![])
        } else {
            scene.clone()
        };
        let mut renderer = Renderer::with_options(&scene, &options).unwrap();
        let frame = renderer.render_with_aovs(96, 72).unwrap();
        (frame, renderer.viewport(96, 72).unwrap())
    };
    let (lit, view) = render(false, false);
    let (shadowed, _) = render(true, false);
    let (occluded, _) = render(false, true);
    let (open_sky, _) = {
        let mut options = options(Quality::production());
        options.effects.ambient_occlusion = false;
        let mut renderer =
            Renderer::with_options(&scene.clone().with_lights(vec![]), &options).unwrap();
        (renderer.render_with_aovs(96, 72).unwrap(), ())
    };
    // Under the ball, within 0.8 of its foot; the open floor beyond 1.6.
    let under = |f: &Frame| floor_brightness(f, &view, DVec3::ZERO, 0.8);
    let open = |f: &Frame| {
        let (a, _) = floor_brightness(f, &view, dvec3(2.2, 0.0, 0.8), 0.4);
        a
    };
    let ((bright, n), (dark, _)) = (under(&lit), under(&shadowed));
    let ((sky, _), (dim, _)) = (under(&open_sky), under(&occluded));
    eprintln!(
        "floor under the ball ({n} pixels): {bright:.1} unshadowed, {dark:.1} shadowed; in the \
         sky's light alone {sky:.1}, {dim:.1} with occlusion; open floor {:.1} and {:.1} \
         (shadows), {:.1} and {:.1} (occlusion)",
        open(&lit),
        open(&shadowed),
        open(&open_sky),
        open(&occluded)
    );
    assert!(n > 50, "{n} floor pixels under the ball");
    assert!(
        dark < 0.6 * bright,
        "the ball's shadow: {dark} against {bright}"
    );
    assert!(
        dim < 0.9 * sky,
        "occlusion next to the ball: {dim} against {sky}"
    );
    assert!(
        (open(&shadowed) - open(&lit)).abs() < 2.0,
        "no shadow on the open floor"
    );
    // The ball's top faces the light: a set's rough surface does not
    // shadow itself.
    let top = |f: &Frame| {
        let (mut sum, mut n) = (0.0, 0);
        for y in 0..f.height() {
            for x in 0..f.width() {
                let i = f.index(x, y);
                let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let p = ray.origin + ray.direction * f64::from(f.depth[i]);
                if f.hit[i] && p.y > 0.6 && p.length() < RADIUS + 0.05 {
                    sum += f64::from(f.image.get_pixel(x, y).0[0]);
                    n += 1;
                }
            }
        }
        (sum / f64::from(n.max(1)), n)
    };
    let ((top_lit, n), (top_shadowed, _)) = (top(&lit), top(&shadowed));
    eprintln!("the ball's top ({n} pixels): {top_lit:.1} unshadowed, {top_shadowed:.1} shadowed");
    assert!(n > 100, "{n} pixels on the ball's top");
    assert!(
        (top_lit - top_shadowed).abs() < 3.0,
        "the ball shadows its own top: {top_shadowed} against {top_lit}"
    );
    assert!(
        open(&occluded) > 0.95 * open(&open_sky),
        "the open floor is open"
    );
}

/// The mean of the red channel over hit pixels.
fn mean_lit(frame: &Frame) -> f64 {
    let (mut sum, mut n) = (0.0, 0);
    for (i, hit) in frame.hit.iter().enumerate() {
        if *hit {
            let (x, y) = (i as u32 % frame.width(), i as u32 / frame.width());
            sum += f64::from(frame.image.get_pixel(x, y).0[0]);
            n += 1;
        }
    }
    sum / f64::from(n.max(1))
}

#[test]
fn a_rough_set_is_not_shadowed_by_its_own_dust() {
    // The escape-time Mandelbulb is rough at the scale of a step: without
    // care, the first shadow samples land in the dust beside each hit.
    let scene = fractal_sdf::gallery::mandelbulb_escape();
    let render = |shadows: bool| {
        let mut options = options(Quality::production());
        options.effects.shadows = shadows;
        options.effects.ambient_occlusion = false;
        let mut renderer = Renderer::with_options(&scene, &options).unwrap();
        renderer.render_with_aovs(96, 72).unwrap()
    };
    let (open, shadowed) = (mean_lit(&render(false)), mean_lit(&render(true)));
    eprintln!("Mandelbulb's set: mean red {open:.1} unshadowed, {shadowed:.1} shadowed");
    // Measured: 0.97 of the unshadowed mean; 0.93 when the first shadow
    // samples count the dust.
    assert!(
        shadowed > 0.95 * open,
        "shadows darken the set from {open} to {shadowed}"
    );
    assert!(shadowed < open, "the set shadows itself somewhere");
}

#[test]
fn occlusion_sees_what_the_screen_shows() {
    // A box known only by its test, on a floor: the floor in front of the
    // wall is occluded by the wall beside it, which samples along the
    // floor's normal (straight up) never meet, but the neighbouring
    // pixels show.
    let cube = InsideShape::new(
        "cube",
        &[],
        InsideBounds::cuboid(DVec3::ZERO, DVec3::splat(0.6)),
        |p, _| p.abs().max_element() < 0.5,
        "return all(isless(fabs(p), (real3)(R(0.5))));",
    )
    .unwrap();
    let scene = Scene::new(cube.node(Vec::<f64>::new()).union(plane(DVec3::Y, 0.5)))
        .with_camera(Camera::look_at(dvec3(0.0, 0.9, 2.6), dvec3(0.0, -0.3, 0.0)).fov(40.0))
        .with_lights(vec![]);
    let render = |occlusion: bool| {
        let mut options = options(Quality::production());
        options.effects.ambient_occlusion = occlusion;
        let mut renderer = Renderer::with_options(&scene, &options).unwrap();
        let frame = renderer.render_with_aovs(96, 72).unwrap();
        (frame, renderer.viewport(96, 72).unwrap())
    };
    let ((open, view), (occluded, _)) = (render(false), render(true));
    let strip = |f: &Frame, near: f64, far: f64| {
        let (mut sum, mut n) = (0.0, 0);
        for y in 0..f.height() {
            for x in 0..f.width() {
                let i = f.index(x, y);
                let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let p = ray.origin + ray.direction * f64::from(f.depth[i]);
                let floor = f.hit[i] && (p.y + 0.5).abs() < 0.05;
                if floor && p.x.abs() < 0.3 && p.z > 0.5 + near && p.z < 0.5 + far {
                    sum += f64::from(f.image.get_pixel(x, y).0[0]);
                    n += 1;
                }
            }
        }
        (sum / f64::from(n.max(1)), n)
    };
    let ((before, n), (after, _)) = (strip(&open, 0.02, 0.12), strip(&occluded, 0.02, 0.12));
    let ((far_before, m), (far_after, _)) = (strip(&open, 0.5, 0.7), strip(&occluded, 0.5, 0.7));
    eprintln!(
        "floor in front of the wall ({n} pixels): {before:.1} open, {after:.1} occluded; farther \
         out {far_before:.1} and {far_after:.1}"
    );
    assert!(n > 20, "{n} floor pixels in front of the wall");
    assert!(
        after < before - 4.0,
        "the wall occludes the floor: {after} against {before}"
    );
    assert!(m > 20, "{m} floor pixels farther out");
    assert!(far_after > far_before - 2.0, "the open floor stays open");
}

#[test]
fn bounds_clip_the_set_on_both_twins() {
    let clipped = ball_shape("clipped_ball", 0.6, "return length(p) < r;");
    assert!(clipped.contains(dvec3(0.5, 0.0, 0.0), &[1.0]));
    assert!(!clipped.contains(dvec3(0.8, 0.0, 0.0), &[1.0]));
    let points = random_points(2000, 1.2, 17);
    check_inside_matches_device(
        &clipped,
        &[1.0],
        &DeviceSelector::auto(),
        Precision::F64,
        &points,
        0.0,
    )
    .unwrap_or_else(|f| panic!("{f}"));
}

/// Regression: a membership test that panics while a mesh is sampled on
/// the CPU surfaced as the threads' panic, without its message; it is an
/// error naming the shape and saying what the test said.
#[test]
fn a_panicking_membership_test_is_an_error_with_its_message() {
    let shape = InsideShape::new(
        "touchy",
        &[],
        InsideBounds::sphere(DVec3::ZERO, 1.0),
        |p, _| {
            assert!(p.x < 0.5, "touchy cannot look right of 0.5");
            p.length() < 0.8
        },
        "return length(p) < R(0.8);",
    )
    .unwrap();
    let scene = Scene::new(shape.node::<f64>([])).compile().unwrap();
    let options = fractal_sdf::mesh::GridOptions::default()
        .resolution(16)
        .sampler(fractal_sdf::mesh::Sampler::Cpu);
    let err = fractal_sdf::mesh::extract(&scene, &options).unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, Error::CustomShape { .. }), "{text}");
    assert!(
        text.contains("touchy") && text.contains("right of 0.5"),
        "{text}"
    );
}
