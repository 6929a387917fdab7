//! Materials: the shading models against their CPU reference
//! (`cpu::shade`) at the rendered pixels' own hit points and normals, and
//! the secondary rays of mirrors and glass against rays traced
//! analytically on the CPU.

use crate::gpu;

use fractal_sdf::cpu::{Evaluator, shade};
use fractal_sdf::prelude::*;
use fractal_sdf::render::{Frame, Renderer, Viewport};
use fractal_sdf::scene::Kind;
use image::RgbaImage;

const W: u32 = 64;
const H: u32 = 48;

/// The kernels' output encoding of a linear colour (gamma, 8 bits).
fn encode(c: DVec3, gamma: f64) -> [f64; 3] {
    c.to_array()
        .map(|v| (v.clamp(0.0, 1.0).powf(1.0 / gamma) * 255.0).round())
}

fn frame(scene: &Scene, quality: Quality) -> (Frame, Viewport) {
    let mut r = Renderer::with_options(scene, &gpu::options(quality, Effects::none())).unwrap();
    let frame = r.render_with_aovs(W, H).unwrap();
    let view = Viewport::new(&scene.camera, W, H, quality.precision).unwrap();
    (frame, view)
}

/// Pixels whose centre ray and its four neighbours hit: their colour is
/// the surface's alone, not an edge's.
fn interior(frame: &Frame) -> Vec<(u32, u32)> {
    let hit = |x: i64, y: i64| {
        (0..i64::from(W)).contains(&x)
            && (0..i64::from(H)).contains(&y)
            && frame.hit[frame.index(x as u32, y as u32)]
    };
    (0..H)
        .flat_map(|y| (0..W).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let (x, y) = (i64::from(x), i64::from(y));
            [(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .all(|(dx, dy)| hit(x + dx, y + dy))
        })
        .collect()
}

/// A lit ball, and behind it a light that shows through thin parts.
fn lit(node: Node) -> Scene {
    Scene::new(node)
        .with_camera(Camera::look_at(dvec3(0.6, 0.4, 2.2), DVec3::ZERO).fov(40.0))
        .with_lights([
            Light::directional(dvec3(0.5, 0.6, 1.0)).color(dvec3(1.0, 0.9, 0.8)),
            Light::directional(dvec3(-0.3, 0.2, -1.0)).intensity(0.8),
        ])
}

#[test]
fn each_shading_model_matches_its_cpu_reference() {
    let Some(_) = gpu::device() else { return };
    let ball = |m: Material| sphere(0.5).color(dvec3(0.8, 0.5, 0.3)).material(m);
    let models = [
        ("lambert", ball(Material::lambert())),
        ("oren-nayar", ball(Material::oren_nayar(0.7))),
        ("blinn-phong", ball(Material::blinn_phong(0.8, 40.0))),
        ("subsurface", ball(Material::subsurface(0.9, 1.2))),
        // A smooth seam blends two materials as it blends colours.
        (
            "blend",
            sphere(0.35)
                .material(Material::oren_nayar(1.0))
                .translate(dvec3(-0.25, 0.0, 0.0))
                .smooth_union(
                    sphere(0.35)
                        .color(dvec3(0.3, 0.5, 0.9))
                        .material(Material::blinn_phong(1.0, 12.0))
                        .translate(dvec3(0.25, 0.0, 0.0)),
                    0.3,
                ),
        ),
    ];
    let quality = gpu::quick();
    let effects = Effects::none();
    let sky = shade::Sky::new(effects.sky_top, effects.sky_bottom);
    let mut images = Vec::new();
    for (name, node) in models {
        let scene = lit(node.clone());
        let (frame, view) = frame(&scene, quality);
        let eval = Evaluator::new(&node).unwrap();
        let pixels = interior(&frame);
        assert!(pixels.len() > 300, "{name}: {} pixels", pixels.len());
        let mut worst = 0.0f64;
        for &(x, y) in &pixels {
            let i = frame.index(x, y);
            let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let p = ray.origin + ray.direction * f64::from(frame.depth[i]);
            let n = DVec3::from(frame.normal[i].map(f64::from));
            let expected = encode(
                shade::shade(&eval, p, n, ray.direction, &scene.lights, sky),
                effects.gamma,
            );
            let got = frame.image.get_pixel(x, y).0;
            for c in 0..3 {
                worst = worst.max((f64::from(got[c]) - expected[c]).abs());
            }
        }
        eprintln!(
            "{name}: {} pixels, at most {worst} levels off",
            pixels.len()
        );
        assert!(worst <= 2.0, "{name}: off its reference by {worst} levels");
        images.push((name, frame.image));
    }
    // Each model changes the image: a kernel that ignored a material
    // would match Lambert's reference, not its own.
    for (name, image) in &images[1..4] {
        assert!(
            differing(image, &images[0].1) > 100,
            "{name} looks like Lambert"
        );
    }
}

fn differing(a: &RgbaImage, b: &RgbaImage) -> usize {
    a.pixels()
        .zip(b.pixels())
        .filter(|(p, q)| p.0.iter().zip(q.0).any(|(u, v)| u.abs_diff(v) > 2))
        .count()
}

#[test]
fn the_default_material_is_the_image_without_materials() {
    let Some(_) = gpu::device() else { return };
    let scene = gpu::sphere_box_floor().with_lights([gpu::sun(0.05)]);
    let mut with = scene.clone();
    with.geometry = scene
        .geometry
        .clone()
        .map(|g| g.material(Material::default()));
    let quality = gpu::quick().supersampling(2);
    let options = gpu::options(quality, Effects::default());
    let plain = Renderer::with_options(&scene, &options)
        .unwrap()
        .render(W, H)
        .unwrap();
    let mut materials = Renderer::with_options(&with, &options).unwrap();
    assert!(materials.source().source.contains("DE_material"));
    assert_eq!(materials.render(W, H).unwrap(), plain);
}

/// A mirror ball at the origin, seen from +z, and behind the camera a red
/// wall whose face at z = 5.5 spans y in [0, 10]: only reflections can
/// show it.
fn mirror_scene(bounces: u32) -> (Scene, Quality) {
    let wall = cuboid(dvec3(10.0, 5.0, 0.5))
        .color(dvec3(1.0, 0.0, 0.0))
        .translate(dvec3(0.0, 5.0, 6.0));
    let scene = Scene::new(sphere(1.0).material(Material::mirror()).union(wall))
        .with_camera(Camera::look_at(dvec3(0.0, 0.0, 4.0), DVec3::ZERO).fov(36.0))
        .with_lights([]);
    (scene, gpu::quick().bounces(bounces))
}

/// Where the reflection of the centre ray of each pixel that hits the
/// unit ball at the origin goes: `Some(true)` to the red wall, `Some(false)`
/// elsewhere, `None` for a ray that misses the ball.
fn mirror_prediction(view: &Viewport, x: u32, y: u32) -> Option<(bool, DVec3)> {
    let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
    let b = ray.origin.dot(ray.direction);
    let disc = b * b - (ray.origin.length_squared() - 1.0);
    if disc < 0.0 {
        return None;
    }
    let p = ray.origin + ray.direction * (-b - disc.sqrt());
    let r = ray.direction - 2.0 * ray.direction.dot(p) * p;
    let red = r.z > 0.0 && {
        let q = p + r * ((5.5 - p.z) / r.z);
        (0.0..=10.0).contains(&q.y) && q.x.abs() <= 10.0
    };
    Some((red, r))
}

#[test]
fn a_mirror_shows_what_its_reflected_rays_must_hit() {
    let Some(_) = gpu::device() else { return };
    let (scene, quality) = mirror_scene(1);
    let (frame, view) = frame(&scene, quality);
    let (mut agree, mut total, mut red) = (0, 0, 0);
    for y in 0..H {
        for x in 0..W {
            let Some((expected, _)) = mirror_prediction(&view, x, y) else {
                continue;
            };
            // The wall is pure red: it alone has no green.
            let shown = frame.image.get_pixel(x, y).0[1] == 0;
            total += 1;
            red += usize::from(expected);
            agree += usize::from(shown == expected);
        }
    }
    assert!(
        red > 100 && total - red > 100,
        "{red} of {total} see the wall"
    );
    let share = agree as f64 / total as f64;
    eprintln!("mirror: {agree} of {total} pixels as predicted, {red} see the wall");
    assert!(share > 0.97, "{agree} of {total} pixels as predicted");
}

#[test]
fn a_path_past_its_bounces_takes_the_sky() {
    let Some(_) = gpu::device() else { return };
    let (scene, quality) = mirror_scene(0);
    let (frame, view) = frame(&scene, quality);
    let effects = Effects::none();
    let mut checked = 0;
    for &(x, y) in &interior(&frame) {
        // The reflection about the pixel's own normal.
        let rd = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5).direction;
        let n = DVec3::from(frame.normal[frame.index(x, y)].map(f64::from));
        let r = rd - 2.0 * rd.dot(n) * n;
        let sky = effects
            .sky_bottom
            .lerp(effects.sky_top, (0.5 + 0.5 * r.y).clamp(0.0, 1.0));
        let expected = encode(sky, effects.gamma);
        let got = frame.image.get_pixel(x, y).0;
        for c in 0..3 {
            assert!(
                (f64::from(got[c]) - expected[c]).abs() <= 1.0,
                "({x}, {y}): {got:?} against the sky {expected:?}"
            );
        }
        checked += 1;
    }
    assert!(checked > 300, "{checked} pixels");
}

/// A glass ball of index `ior` in front of a wall, red left of x = 0 and
/// blue right of it, at z = -3.
fn glass_scene(ior: f64) -> Scene {
    let half = |x: f64, rgb: DVec3| {
        cuboid(dvec3(5.0, 5.0, 0.5))
            .color(rgb)
            .translate(dvec3(x, 0.0, -3.5))
    };
    let wall = half(-5.0, dvec3(1.0, 0.0, 0.0)).union(half(5.0, dvec3(0.0, 0.0, 1.0)));
    Scene::new(
        sphere(1.0)
            .material(Material::glass(ior))
            .translate(dvec3(0.3, 0.0, 0.0))
            .union(wall),
    )
    .with_camera(Camera::look_at(dvec3(0.0, 0.0, 4.0), DVec3::ZERO).fov(36.0))
    .with_lights([])
}

/// Which half of the wall the centre ray of pixel (x, y) reaches through
/// the ball of index `ior` at (0.3, 0, 0), traced on the CPU: `Some(true)`
/// for red; `None` where it misses the ball, reflects inside, or passes
/// too near the wall's seam to tell.
fn through_glass(view: &Viewport, x: u32, y: u32, ior: f64) -> Option<bool> {
    let centre = dvec3(0.3, 0.0, 0.0);
    let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
    let o = ray.origin - centre;
    let b = o.dot(ray.direction);
    let disc = b * b - (o.length_squared() - 1.0);
    if disc < 0.0 {
        return None;
    }
    let p = o + ray.direction * (-b - disc.sqrt());
    let inside = shade::refract(ray.direction, p, 1.0 / ior)?.normalize();
    let q = p + inside * (-2.0 * p.dot(inside));
    let out = shade::refract(inside, -q, ior)?.normalize();
    if out.z >= 0.0 {
        return None;
    }
    let hit = q + centre + out * ((-3.0 - q.z) / out.z);
    (hit.x.abs() > 0.05).then_some(hit.x < 0.0)
}

#[test]
fn glass_bends_rays_as_snell_says() {
    let Some(_) = gpu::device() else { return };
    let quality = gpu::quick().bounces(3);
    for ior in [1.0, 1.5] {
        let (frame, view) = frame(&glass_scene(ior), quality);
        let (mut agree, mut total, mut moved) = (0, 0, 0);
        for y in 0..H {
            for x in 0..W {
                let Some(red) = through_glass(&view, x, y, ior) else {
                    continue;
                };
                let [r, _, b, _] = frame.image.get_pixel(x, y).0;
                total += 1;
                agree += usize::from((r > b) == red);
                // Where the bent ray lands on the other half from the
                // straight one.
                moved += usize::from(through_glass(&view, x, y, 1.0) != Some(red));
            }
        }
        let share = agree as f64 / total as f64;
        eprintln!("glass {ior}: {agree} of {total} as predicted, {moved} moved");
        assert!(total > 400, "ior {ior}: {total} pixels");
        assert!(share > 0.95, "ior {ior}: {agree} of {total} as predicted");
        if ior > 1.0 {
            assert!(moved > 100, "the ball bends {moved} pixels' rays");
        }
    }
}

#[test]
fn glass_of_index_one_is_invisible() {
    let Some(_) = gpu::device() else { return };
    let quality = gpu::quick().bounces(2);
    let (glass, _) = frame(&glass_scene(1.0), quality);
    let mut without = glass_scene(1.0);
    let Some(Kind::Csg { b: wall, .. }) = without.geometry.map(|g| g.kind().clone()) else {
        unreachable!("a union")
    };
    without.geometry = Some(wall);
    let (bare, _) = frame(&without, quality);
    let off = glass
        .image
        .pixels()
        .zip(bare.image.pixels())
        .filter(|(p, q)| p.0.iter().zip(q.0).any(|(u, v)| u.abs_diff(v) > 3))
        .count();
    // Only pixels at the wall's seam, seen through the ball's rim, may
    // differ: the rays are moved off the surface by a pixel or so.
    eprintln!("glass of index 1: {off} pixels differ");
    assert!(off < 10, "{off} pixels differ");
}

#[test]
fn materials_are_checked_like_every_value() {
    let bad = sphere(1.0).material(Material::mirror().reflectivity(1.5));
    let error = Scene::new(bad).compile().unwrap_err().to_string();
    assert!(error.contains("reflectivity"), "{error}");
    let dark = sphere(1.0).material(Material::glass(0.0));
    let error = Scene::new(dark).compile().unwrap_err().to_string();
    assert!(error.contains("ior"), "{error}");
    let error = Quality::production().bounces(9).validate().unwrap_err();
    assert!(error.to_string().contains("bounces"), "{error}");
}
