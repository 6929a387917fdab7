//! Each lighting effect does what it is for, where it should.

use crate::gpu;

use fractal_sdf::cpu::{self, Evaluator, MarchSettings, Ray};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Glow;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{Frame, Renderer};

const W: u32 = 96;
const H: u32 = 64;

fn render(scene: &Scene, quality: Quality, effects: Effects) -> Frame {
    let mut r = Renderer::with_options(scene, &gpu::options(quality, effects)).unwrap();
    r.render_with_aovs(W, H).unwrap()
}

fn luma(frame: &Frame, i: usize) -> f64 {
    let (x, y) = (i as u32 % W, i as u32 / W);
    gpu::luminance(&frame.image, x, y, 0)
}

/// Pixels showing the open floor (normal straight up).
fn floor_pixels(frame: &Frame) -> Vec<usize> {
    (0..frame.hit.len())
        .filter(|&i| frame.hit[i] && frame.normal[i][1] > 0.999)
        .collect()
}

#[test]
fn ambient_occlusion_darkens_the_crease_where_a_box_meets_the_floor() {
    let Some(_) = gpu::device() else { return };
    // Ambient light only, so occlusion is the only thing that varies.
    let scene = gpu::sphere_box_floor().with_lights([]);
    // Occlusion reaching 0.5 from the surface: the crease spans a few
    // pixels.
    let with = Effects::default().shadows(false).ao_distance(0.5);
    let without = Effects::none();
    let quality = gpu::quick();
    let on = render(&scene, quality, with);
    let off = render(&scene, quality, without);
    gpu::save("effects_ao_on", &on.image);
    let view = Renderer::with_options(&scene, &gpu::options(gpu::quick(), without))
        .unwrap()
        .viewport(W, H)
        .unwrap();
    // On the floor 0.03 in front of the box's front face, and out in the open.
    let (cx, cy) = gpu::project(&view, dvec3(0.6, 0.0, 0.48));
    let (ox, oy) = gpu::project(&view, dvec3(0.0, 0.0, 1.0));
    for (x, y) in [(cx, cy), (ox, oy)] {
        let i = on.index(x, y);
        assert!(
            on.hit[i] && on.normal[i][1] > 0.99,
            "({x}, {y}) is not open floor"
        );
    }
    let crease = |f: &Frame| gpu::luminance(&f.image, cx, cy, 0);
    let open = |f: &Frame| gpu::luminance(&f.image, ox, oy, 0);
    let ratio_on = crease(&on) / open(&on);
    let ratio_off = crease(&off) / open(&off);
    eprintln!("crease/open luminance: {ratio_on:.3} with AO, {ratio_off:.3} without");
    // Lit by the sky alone, the two floor pixels are the same colour
    // (measured: a ratio of exactly 1, luma 111.5 both); one 8-bit level
    // is 0.9% of that, and 0.02 admits two.
    assert!(
        (ratio_off - 1.0).abs() < 0.02,
        "without AO the floor is even: {ratio_off}"
    );
    // Measured 0.708: the crease is 29% darker.
    assert!(ratio_on < 0.8, "AO darkens the crease: {ratio_on}");
    // The open floor is unoccluded: measured the same luma with and
    // without AO; 2.0 admits two 8-bit levels.
    assert!((open(&on) - open(&off)).abs() < 2.0);
}

/// Which floor pixels the CPU reference sees in shadow from `light_dir`:
/// (clearly shadowed, clearly lit). A pixel is clear-cut when the shadow
/// rays from its floor point, its four neighbours' floor points and a point
/// 0.1 above it all agree: the kernel's shading point and the start of its
/// shadow ray lie up to about a pixel from the exact floor point.
fn classify_shadows(scene: &Scene, frame: &Frame, light_dir: DVec3) -> (Vec<usize>, Vec<usize>) {
    let eval = Evaluator::new(scene.geometry.as_ref().unwrap()).unwrap();
    let view = Renderer::with_options(scene, &gpu::options(gpu::quick(), Effects::none()))
        .unwrap()
        .viewport(W, H)
        .unwrap();
    let settings = MarchSettings::default()
        .max_steps(512)
        .max_distance(50.0)
        .footprint_base(1e-4);
    // Where the ray through image position (x, y) meets the floor y = 0.
    let floor_point = |x: f64, y: f64| {
        let ray = view.ray(x, y);
        ray.origin - ray.direction * (ray.origin.y / ray.direction.y)
    };
    let blocked = |p: DVec3| {
        let ray = Ray::new(p + dvec3(0.0, 1e-3, 0.0), light_dir);
        cpu::march(&eval, ray, &settings).hit
    };
    let (mut dark, mut lit) = (Vec::new(), Vec::new());
    for i in floor_pixels(frame) {
        let (x, y) = (f64::from(i as u32 % W) + 0.5, f64::from(i as u32 / W) + 0.5);
        let around = [(0.0, 0.0), (1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)];
        let raised = floor_point(x, y) + dvec3(0.0, 0.1, 0.0);
        let count = around
            .iter()
            .map(|(dx, dy)| floor_point(x + dx, y + dy))
            .chain([raised])
            .filter(|&p| blocked(p))
            .count();
        match count {
            0 => lit.push(i),
            6 => dark.push(i),
            _ => {}
        }
    }
    (dark, lit)
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0.0), |(s, n), x| (s + x, n + 1.0));
    s / n
}

#[test]
fn a_shadowed_floor_point_is_darker_than_a_lit_one() {
    let Some(_) = gpu::device() else { return };
    let sun = gpu::sun(0.0);
    let scene = gpu::sphere_box_floor().with_lights([sun]);
    let effects = Effects::default().ambient_occlusion(false);
    let frame = render(&scene, gpu::quick(), effects);
    gpu::save("effects_hard_shadow", &frame.image);
    let (dark, lit) = classify_shadows(&scene, &frame, gpu::direction_of(&sun).unwrap());
    // Measured: 349 clearly shadowed and 3,921 clearly lit pixels; the
    // shadowed ones up to luma 111.5 and the lit ones from 182.6, a gap
    // of 71 levels against the 20 required.
    assert!(
        dark.len() > 30 && lit.len() > 300,
        "{} dark, {} lit",
        dark.len(),
        lit.len()
    );
    let brightest_dark = dark.iter().map(|&i| luma(&frame, i)).fold(0.0, f64::max);
    let darkest_lit = lit.iter().map(|&i| luma(&frame, i)).fold(255.0, f64::min);
    eprintln!(
        "{} shadowed pixels up to {brightest_dark:.1}, {} lit from {darkest_lit:.1}",
        dark.len(),
        lit.len()
    );
    assert!(
        brightest_dark + 20.0 < darkest_lit,
        "shadowed up to {brightest_dark}, lit from {darkest_lit}"
    );
    // Without shadows the same pixels are lit: their mean lumas measured
    // 0.23 apart; the tolerance is about 13 times that.
    let unshadowed = render(&scene, gpu::quick(), Effects::none());
    let d = mean(dark.iter().map(|&i| luma(&unshadowed, i)));
    let l = mean(lit.iter().map(|&i| luma(&unshadowed, i)));
    assert!((d - l).abs() < 3.0, "no shadows: {d} vs {l}");
}

/// Linear green channel of pixel `i`.
fn linear(frame: &Frame, i: usize) -> f64 {
    let (x, y) = (i as u32 % W, i as u32 / W);
    (f64::from(frame.image.get_pixel(x, y).0[1]) / 255.0).powf(2.2)
}

/// Per floor pixel, the fraction of the light that reaches it: the shadowed
/// render's light above ambient over the unshadowed render's.
fn visibility(scene: &Scene, quality: Quality) -> (Vec<f64>, Frame) {
    let effects = Effects::default().ambient_occlusion(false);
    let shadowed = render(scene, quality, effects);
    let unshadowed = render(scene, quality, Effects::none());
    let ambient = render(&scene.clone().with_lights([]), quality, Effects::none());
    let v = floor_pixels(&unshadowed)
        .into_iter()
        .filter(|&i| shadowed.hit[i] && shadowed.normal[i][1] > 0.999)
        .map(|i| {
            let base = linear(&ambient, i);
            (linear(&shadowed, i) - base) / (linear(&unshadowed, i) - base)
        })
        .collect();
    (v, shadowed)
}

#[test]
fn a_soft_shadow_has_a_penumbra_and_a_hard_one_has_none() {
    let Some(_) = gpu::device() else { return };
    let base = gpu::sphere_box_floor();
    let (hard, _) = visibility(&base.clone().with_lights([gpu::sun(0.0)]), gpu::quick());
    let (soft, image) = visibility(&base.with_lights([gpu::sun(0.3)]), gpu::quick());
    gpu::save("effects_soft_shadow", &image.image);
    // Measured over 4,484 floor pixels: 0 partly lit in the hard render
    // (22 allowed) and 422 in the soft one (106 required); umbrae of 424
    // and 499 pixels (30 and 10 required).
    let partial = |v: &[f64]| v.iter().filter(|&&x| x > 0.15 && x < 0.85).count();
    let umbra = |v: &[f64]| v.iter().filter(|&&x| x < 0.05).count();
    assert!(umbra(&hard) > 30, "the hard render has a shadow");
    assert!(umbra(&soft) > 10, "the soft render has an umbra");
    let (in_hard, in_soft) = (partial(&hard), partial(&soft));
    eprintln!(
        "partly lit floor pixels: {in_hard} hard, {in_soft} soft; umbra {} hard, {} soft",
        umbra(&hard),
        umbra(&soft)
    );
    assert!(
        in_hard <= hard.len() / 200,
        "hard shadow edge: {in_hard} of {}",
        hard.len()
    );
    let shadowed = umbra(&hard);
    assert!(
        in_soft >= shadowed / 4 && in_soft > 10 * in_hard.max(1),
        "soft penumbra: {in_soft} (hard: {in_hard}, hard shadow: {shadowed} of {})",
        soft.len()
    );
}

/// Regression: the improved soft-shadow estimate assumed each distance is
/// less than twice the previous one. Under a light straight overhead a
/// flat floor's distance doubles exactly at every shadow step, and the
/// whole open floor went black.
#[test]
fn soft_shadows_from_straight_above_light_an_open_floor() {
    let Some(_) = gpu::device() else { return };
    let overhead = Light::directional(dvec3(0.0, 1.0, 0.0)).softness(0.05);
    let scene = gpu::sphere_box_floor().with_lights([overhead]);
    let effects = Effects::default().ambient_occlusion(false);
    let shadowed = render(&scene, gpu::quick(), effects);
    let unshadowed = render(&scene, gpu::quick(), Effects::none());
    let view = Renderer::with_options(&scene, &gpu::options(gpu::quick(), effects))
        .unwrap()
        .viewport(W, H)
        .unwrap();
    let (x, y) = gpu::project(&view, dvec3(0.0, 0.0, 1.2));
    let (a, b) = (
        gpu::luminance(&shadowed.image, x, y, 1),
        gpu::luminance(&unshadowed.image, x, y, 1),
    );
    eprintln!("open floor: {a:.1} with shadows, {b:.1} without");
    // Measured the same luma (251.2); 2.0 admits two 8-bit levels.
    assert!(
        (a - b).abs() < 2.0,
        "open floor under an overhead light: {a} vs {b}"
    );
}

#[test]
fn glow_brightens_missed_rays_near_the_surface_only() {
    let Some(_) = gpu::device() else { return };
    let scene = Scene::new(sphere(0.5))
        .with_camera(Camera::look_at(dvec3(0.0, 0.0, 4.0), DVec3::ZERO).fov(40.0));
    let glow = Effects::none().glow(Some(Glow::new(dvec3(1.0, 0.6, 0.2), 1.0)));
    let on = render(&scene, gpu::quick(), glow);
    let off = render(&scene, gpu::quick(), Effects::none());
    gpu::save("effects_glow", &on.image);
    // Surfaces are unchanged; a missed pixel beside the silhouette glows; a
    // far corner does not.
    let mut near_gain = Vec::new();
    for y in 0..H {
        for x in 1..W - 1 {
            let i = on.index(x, y);
            if on.hit[i] {
                assert_eq!(on.image.get_pixel(x, y), off.image.get_pixel(x, y));
            } else if on.hit[i - 1] || on.hit[i + 1] {
                near_gain.push(luma(&on, i) - luma(&off, i));
            }
        }
    }
    assert!(!near_gain.is_empty());
    // Measured: at least 81 levels of glow beside the silhouette, at most
    // 0.7 in a corner.
    let weakest = near_gain.iter().copied().fold(255.0, f64::min);
    eprintln!("weakest glow beside the silhouette: {weakest:.1}");
    assert!(weakest > 40.0, "glow beside the silhouette: {weakest}");
    for (x, y) in [(0, 0), (W - 1, 0), (0, H - 1), (W - 1, H - 1)] {
        let gain = gpu::luminance(&on.image, x, y, 0) - gpu::luminance(&off.image, x, y, 0);
        eprintln!("corner ({x}, {y}) glow: {gain:.1}");
        assert!(gain < 8.0, "corner ({x}, {y}) glows by {gain}");
    }
}

#[test]
fn fog_fades_distant_surfaces_into_the_background() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor().with_lights([gpu::sun(0.0)]);
    let fog = Effects::none().fog_density(0.3);
    let on = render(&scene, gpu::quick(), fog);
    let off = render(&scene, gpu::quick(), Effects::none());
    // The farthest floor pixel is closer to the background colour with fog.
    let far = floor_pixels(&off)
        .into_iter()
        .max_by(|&a, &b| off.depth[a].total_cmp(&off.depth[b]))
        .unwrap();
    let (x, y) = (far as u32 % W, far as u32 / W);
    // The background gradient's value at this row.
    let sky = Effects::default().sky_top.lerp(
        Effects::default().sky_bottom,
        (f64::from(y) + 0.5) / f64::from(H),
    );
    let g = |c: f64| 255.0 * c.powf(1.0 / 2.2);
    let target = 0.2126 * g(sky.x) + 0.7152 * g(sky.y) + 0.0722 * g(sky.z);
    let d_on = (luma(&on, far) - target).abs();
    let d_off = (luma(&off, far) - target).abs();
    eprintln!("distance from the background: {d_on:.1} with fog, {d_off:.1} without");
    // Measured 0.2 levels from the background with fog, 66.3 without.
    assert!(d_on < 0.5 * d_off, "fog at ({x}, {y}): {d_on} vs {d_off}");
}

/// `unit` with its geometry and camera scaled by `s`, lit by the sky alone
/// so that occlusion is all that varies: for `s` below 1 the same view
/// magnified `1 / s` times.
fn shrunk(unit: &Scene, s: f64) -> Scene {
    let mut camera = unit.camera;
    camera.position = unit.camera.position * s;
    camera.target = unit.camera.target * s;
    Scene::new(unit.geometry.clone().unwrap().scale(s))
        .with_camera(camera)
        .with_lights([])
}

/// Mean luma (0–255) of the pixels that show a surface.
fn surface_brightness(frame: &Frame) -> f64 {
    mean(
        (0..frame.hit.len())
            .filter(|&i| frame.hit[i])
            .map(|i| luma(frame, i)),
    )
}

/// Occlusion reaches a fraction of the view where that is shorter than
/// `ao_distance`, so magnifying a view does not darken it: a scene shrunk
/// by 1e3 (F32) and by 1e6 (F64), seen from as much closer, is about as
/// bright as at its own scale.
///
/// Two scenes: a Menger sponge repeated through all of space, seen from
/// inside (structure on every side, as in a deep zoom into a fractal),
/// where the reach is a fraction of the view at every scale, so the
/// images agree closely (measured: 0.3% apart); and the gallery's
/// Sierpinski tetrahedron on its floor, where the unit scene keeps
/// `ao_distance` and the shrunk one reaches a fraction of the view, a
/// little further (measured: 3.6% darker). With a reach of `ao_distance`
/// scene units at every scale the shrunk sponge was black (mean luma 2 and
/// 0 against 56) and the shrunk tetrahedron 25% darker. The tolerances
/// are about 11 times the sponge's 0.18% (measured, in F32 and F64 alike)
/// and 1.6 times the tetrahedron's 3.6%, a real difference that a reach of
/// `ao_distance` would make 25%. At unit scale the sponge fills the view
/// at luma 58.4 and the tetrahedron 94% of it at 88.2 (half the view and
/// 30 required).
#[test]
fn occlusion_does_not_darken_a_magnified_view() {
    let Some(device) = gpu::device() else { return };
    let sponge = Scene::new(menger(3).repeat(dvec3(2.0, 2.0, 2.0)))
        .with_camera(Camera::look_at(dvec3(0.0, 0.1, 0.6), dvec3(0.9, -0.3, -0.5)).fov(45.0));
    let scenes = [
        ("sponge", sponge, 0.02),
        (
            "sierpinski",
            fractal_sdf::gallery::sierpinski_tetrahedron(),
            0.06,
        ),
    ];
    let effects = Effects::default().shadows(false);
    let mut cases = vec![(1e-3, Precision::F32)];
    if gpu::fp64(&device) {
        cases.push((1e-6, Precision::F64));
    }
    for (name, scene, tolerance) in scenes {
        let frame = |s: f64, precision: Precision| {
            let quality = gpu::quick()
                .precision(precision)
                .max_distance(gpu::quick().max_distance * s);
            render(&shrunk(&scene, s), quality, effects)
        };
        let unit = frame(1.0, Precision::F32);
        gpu::save(&format!("effects_ao_{name}"), &unit.image);
        let bright = surface_brightness(&unit);
        assert!(unit.coverage() > 0.5 && bright > 30.0, "{name}: {bright}");
        for &(s, precision) in &cases {
            let small = frame(s, precision);
            gpu::save(&format!("effects_ao_{name}_{s:e}"), &small.image);
            let b = surface_brightness(&small);
            eprintln!(
                "{name}: surface luma {bright:.1} at unit scale, {b:.1} shrunk by {s:e} in {precision:?}"
            );
            assert_eq!(unit.hit, small.hit, "{name} shrunk by {s:e}");
            assert!(
                (b / bright - 1.0).abs() <= tolerance,
                "{name} shrunk by {s:e} in {precision:?}: {b:.1} against {bright:.1}"
            );
        }
    }
}

/// A camera inside a solid shades the nearest point of the surface, seen
/// from no distance: there is no view to scale occlusion to, and it keeps
/// `ao_distance`. (Scaled to the view, it reached only into the
/// Mandelbulb's interior, and the image was black.)
#[test]
fn occlusion_seen_from_inside_a_solid_keeps_its_reach() {
    let Some(_) = gpu::device() else { return };
    let bulb = fractal_sdf::gallery::mandelbulb().geometry.unwrap();
    let camera = Camera::look_at(dvec3(0.41, 0.29, 0.56), dvec3(0.0, -0.12, 0.0)).fov(40.0);
    let scene = Scene::new(bulb).with_camera(camera).with_lights([]);
    let effects = Effects::default().shadows(false);
    let on = render(&scene, gpu::quick(), effects);
    let off = render(&scene, gpu::quick(), Effects::none());
    assert!(on.depth.iter().all(|&d| d == 0.0), "the camera is inside");
    let (with, without) = (surface_brightness(&on), surface_brightness(&off));
    eprintln!("inside the bulb: surface luma {with:.1} with occlusion, {without:.1} without");
    // Measured 28.9 against 86.9 (0.33); the black image was 0.
    assert!(with > 0.2 * without, "{with} against {without}");
}

/// Regression: a glowing scene with a floor glowed along the horizon,
/// where rays graze the infinite plane without any shape near them.
#[test]
fn glow_comes_from_the_shapes_not_from_a_floor_at_the_horizon() {
    let Some(_) = gpu::device() else { return };
    // Looking level over the floor: the horizon crosses the image.
    let scene = Scene::new(gpu::floor().union(sphere(0.5).translate(dvec3(0.0, 0.5, 0.0))))
        .with_camera(Camera::look_at(dvec3(0.0, 0.6, 4.0), dvec3(0.0, 0.6, 0.0)).fov(50.0));
    let glow = Effects::none().glow(Some(Glow::new(dvec3(1.0, 0.6, 0.2), 1.0)));
    let on = render(&scene, gpu::quick(), glow);
    let off = render(&scene, gpu::quick(), Effects::none());
    gpu::save("effects_glow_floor", &on.image);
    // Missed pixels just above the horizon, in the outer fifths of the
    // image (far from the sphere): no glow there.
    let mut worst: f64 = 0.0;
    for x in (0..W / 5).chain(4 * W / 5..W) {
        let horizon = (0..H).rev().find(|&y| !on.hit[on.index(x, y)]);
        let Some(y) = horizon else { continue };
        let gain = luma(&on, on.index(x, y)) - luma(&off, off.index(x, y));
        worst = worst.max(gain);
    }
    eprintln!("largest glow at the horizon far from the sphere: {worst:.1}");
    assert!(worst < 4.0, "the floor's horizon glows by {worst}");
    // The sphere still glows: a missed pixel beside its top.
    let mut beside = 0.0_f64;
    for y in 0..H {
        for x in 1..W - 1 {
            let i = on.index(x, y);
            if !on.hit[i] && (on.hit[i - 1] || on.hit[i + 1]) && on.normal[i][1] >= 0.0 {
                beside = beside.max(luma(&on, i) - luma(&off, i));
            }
        }
    }
    assert!(beside > 40.0, "glow beside the sphere: {beside}");
}

/// Regression: one twist anywhere in a scene darkened every lit surface
/// (soft shadow rays met its estimate, which far from its axis shrank
/// with the twist's stretch) and slowed the frame. A twisted sphere on
/// the twist's axis is the same sphere: the image must be the plain
/// sphere's, within its own penumbra's difference.
#[test]
fn a_twist_darkens_nothing_far_from_its_shape() {
    let Some(_) = gpu::device() else { return };
    let scene = |ball: Node| {
        Scene::new(
            gpu::floor()
                .union(ball.translate(dvec3(-0.6, 0.5, 0.0)))
                .union(cuboid(dvec3(0.35, 0.35, 0.35)).translate(dvec3(0.6, 0.35, 0.1))),
        )
        .with_camera(Camera::look_at(dvec3(0.0, 1.4, 3.2), dvec3(0.0, 0.35, 0.0)).fov(40.0))
        .with_lights([gpu::sun(0.1)])
    };
    let effects = Effects::default().ambient_occlusion(false);
    let twisted = render(&scene(sphere(0.5).twist(2.5)), gpu::quick(), effects);
    let plain = render(&scene(sphere(0.5)), gpu::quick(), effects);
    gpu::save("effects_twist", &twisted.image);
    // The open floor in the image's right half, beyond the twisted
    // sphere's own penumbra (which its underestimate near the shape may
    // darken a little).
    let floor: Vec<usize> = floor_pixels(&plain)
        .into_iter()
        .filter(|&i| i as u32 % W > W / 2)
        .collect();
    let mean = |f: &Frame| floor.iter().map(|&i| luma(f, i)).sum::<f64>() / floor.len() as f64;
    let (a, b) = (mean(&twisted), mean(&plain));
    eprintln!("open floor: {a:.1} with the twist, {b:.1} without");
    assert!(
        (a - b).abs() < 2.0,
        "the twist darkens the floor: {a} vs {b}"
    );
    let evals = |f: &Frame| f.evaluations.iter().map(|&e| f64::from(e)).sum::<f64>();
    let ratio = evals(&twisted) / evals(&plain);
    eprintln!("evaluations with the twist / without: {ratio:.2}");
    assert!(ratio < 1.3, "the twist costs {ratio} times the evaluations");
}

/// Regression: a Mandelbulb with occlusion had pure black specks in lit
/// areas, where every occlusion sample landed inside dust finer than the
/// normal's step.
#[test]
fn occlusion_leaves_no_pure_black_pixel_on_a_fractal() {
    let Some(_) = gpu::device() else { return };
    let file = fractal_sdf::gallery::file("mandelbulb").unwrap();
    let options = gpu::options(Quality::preview(), file.effects);
    let mut r = Renderer::with_options(&file.scene, &options).unwrap();
    // Measured on the build before the fix: 135 black pixels at this size.
    let image = r.render(640, 480).unwrap();
    gpu::save("effects_mandelbulb_ao", &image);
    let black = image.pixels().filter(|p| p.0[..3] == [0, 0, 0]).count();
    assert_eq!(black, 0, "{black} pure black pixels");
}

/// Glow nodes: a glowing ball beside a plain one. A ray that misses both
/// takes the glowing ball's colour times its strength times
/// `exp(−24 θ)`, θ the smallest `d / (t + d)` of the ball's exact
/// distance along the ray (found here by sampling the ray densely; the
/// march's own samples are its steps, so its halo may fall short, never
/// over), and nothing of the plain ball however near it passes; a glow
/// node at the root is the scene-wide glow of the same colour and
/// strength.
#[test]
fn glow_nodes_give_each_shape_its_own_halo() {
    let Some(_) = gpu::device() else { return };
    let eye = dvec3(0.0, 0.3, 4.0);
    let camera = Camera::look_at(eye, DVec3::ZERO);
    let (centre, radius) = (dvec3(-0.7, 0.0, 0.0), 0.4);
    let (color, strength) = (dvec3(1.0, 0.4, 0.1), 1.2);
    // The glowing ball is placed by a scale above its glow, and the path
    // to it passes a subtraction: its halo is its own shape's as placed.
    let glowing = sphere(radius / 2.0)
        .translate(centre / 2.0)
        .glow(color, strength)
        .scale(2.0);
    let far_box = cuboid(dvec3(0.1, 0.1, 0.1)).translate(dvec3(0.0, 0.0, -40.0));
    let scene = Scene::new(
        glowing
            .union(sphere(0.4).translate(dvec3(0.7, 0.0, 0.0)))
            .subtract(far_box),
    )
    .with_camera(camera);
    let black = Effects::none()
        .sky_top(DVec3::ZERO)
        .sky_bottom(DVec3::ZERO)
        .gamma(1.0);
    let quality = gpu::plain(Quality::production());
    let mut r = Renderer::with_options(&scene, &gpu::options(quality, black)).unwrap();
    let frame = r.render_layers(W, H).unwrap();
    let linear = &frame.layers.as_ref().unwrap().linear;
    let (mut got, mut want, mut misses) = (0.0, 0.0, 0);
    for (i, rd) in gpu::pixel_rays(&camera, (W, H)).into_iter().enumerate() {
        if frame.hit[i] {
            continue;
        }
        let angle = (0..40_000)
            .map(|k| {
                let t = f64::from(k) * 2e-4 * 20.0;
                let d = ((eye + rd * t).distance(centre) - radius).max(0.0);
                d / (t + d)
            })
            .fold(1.0, f64::min);
        let halo = color * strength * (-24.0 * angle).exp();
        let c = linear[i];
        for (channel, w) in [(0, halo.x), (1, halo.y)] {
            got += f64::from(c[channel]);
            want += w;
        }
        // Blue is 0.1 of red: the plain ball adds nothing of its own.
        assert!(
            (f64::from(c[2]) - halo.z).abs() < 0.01 + 0.05 * halo.z,
            "pixel {i}: blue {} against {}",
            c[2],
            halo.z
        );
        misses += 1;
    }
    let error = got / want - 1.0;
    eprintln!(
        "glow node: halo {got:.2} against {want:.2} ({error:+.4}) over {misses} missed pixels"
    );
    assert!(misses > 2000, "{misses}");
    // The march sees the distance at its steps only, so the smallest angle
    // it finds is at least the exact one: the halo is never brighter.
    assert!(error < 1e-3 && error > -0.04, "relative error {error}");

    // At the root, a glow node is the scene's glow.
    let ball = sphere(0.5);
    let node = Scene::new(ball.clone().glow(color, strength)).with_camera(camera);
    let global = Scene::new(ball).with_camera(camera);
    let layered = |scene: &Scene, effects: Effects| {
        let mut r = Renderer::with_options(scene, &gpu::options(quality, effects)).unwrap();
        r.render_layers(W, H).unwrap()
    };
    let a = layered(&node, black);
    let b = layered(&global, black.glow(Glow::new(color, strength)));
    let (la, lb) = (
        &a.layers.as_ref().unwrap().linear,
        &b.layers.as_ref().unwrap().linear,
    );
    let worst = la
        .iter()
        .zip(lb)
        .map(|(x, y)| (0..3).map(|c| (x[c] - y[c]).abs()).fold(0.0f32, f32::max))
        .fold(0.0f32, f32::max);
    eprintln!("glow node at the root against the scene's glow: largest difference {worst:.2e}");
    // A node's halo is looked for only where it could reach half an 8-bit
    // step: the scene's glow keeps fainter ends.
    assert!(worst <= 0.5 / 255.0, "{worst}");
}

/// More glow nodes than a scene may have are refused, saying what to do,
/// and so are glow nodes beside an inside shape (which has no distance
/// for a halo).
#[test]
fn too_many_glow_nodes_are_refused() {
    let shape = gpu::inside_ball();
    let scene = Scene::new(
        shape
            .node::<f64>([])
            .union(sphere(0.2).glow(DVec3::ONE, 1.0)),
    );
    let err = fractal_sdf::codegen::emit(
        &scene.compile().unwrap(),
        &fractal_sdf::codegen::Options::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("inside shapes") && err.contains("Effects::glow"),
        "{err}"
    );

    let many = (0..17)
        .map(|i| {
            sphere(0.1)
                .translate(dvec3(f64::from(i), 0.0, 0.0))
                .glow(DVec3::ONE, 1.0)
        })
        .reduce(Node::union)
        .unwrap();
    let compiled = Scene::new(many).compile().unwrap();
    let err = fractal_sdf::codegen::emit(&compiled, &fractal_sdf::codegen::Options::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("17 glow nodes") && err.contains("union"),
        "{err}"
    );
}

/// Regression: the improved soft-shadow estimate takes the point where the
/// distance spheres of two shadow samples cross as the ray's nearest
/// approach. Where a distance nearly doubles from one sample to the next
/// (the ray heading almost straight away from the nearest surface) that
/// point lies behind the earlier sample, off the stretch between them,
/// and its tiny side distance darkened single floor pixels in rings around
/// a shape. A soft shadow is smooth: no floor pixel's light is below all
/// eight of its neighbours' by a tenth.
#[test]
fn a_soft_shadow_has_no_isolated_dark_pixels() {
    let Some(_) = gpu::device() else { return };
    let (w, h) = (320, 240);
    let scene = fractal_sdf::gallery::hybrid();
    let effects = Effects::default().ambient_occlusion(false);
    let mut renderer =
        Renderer::with_options(&scene, &gpu::options(gpu::quick(), effects)).unwrap();
    let frame = renderer.render_layers(w, h).unwrap();
    let shadow = &frame.layers.as_ref().expect("layers").shadow;
    let floor = |i: usize| frame.hit[i] && frame.normal[i][1] > 0.999;
    let (mut floor_pixels, mut isolated) = (0, Vec::new());
    for y in 1..h as usize - 1 {
        for x in 1..w as usize - 1 {
            let i = y * w as usize + x;
            let around: Vec<usize> = [
                (-1, -1),
                (0, -1),
                (1, -1),
                (-1, 0),
                (1, 0),
                (-1, 1),
                (0, 1),
                (1, 1),
            ]
            .iter()
            .map(|&(dx, dy)| ((y as i64 + dy) as usize) * w as usize + (x as i64 + dx) as usize)
            .collect();
            if !floor(i) || !around.iter().all(|&j| floor(j)) {
                continue;
            }
            floor_pixels += 1;
            let least = around
                .iter()
                .map(|&j| shadow[j])
                .fold(f32::INFINITY, f32::min);
            if shadow[i] < least - 0.1 {
                isolated.push((x, y, shadow[i], least));
            }
        }
    }
    eprintln!(
        "{} isolated dark pixels of {floor_pixels} floor pixels",
        isolated.len()
    );
    assert!(floor_pixels > 10_000, "{floor_pixels} floor pixels");
    assert!(
        isolated.is_empty(),
        "isolated dark pixels (x, y, light, least around): {isolated:?}"
    );
}
