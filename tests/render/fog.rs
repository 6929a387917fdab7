//! Fog as a lit medium (`quality::Volumetric`) against closed forms and
//! integrals the tests compute themselves: light scattered under a
//! directional light, transmittance through a fog thinning with height
//! (integrated numerically along each ray), and the shafts a ball's shadow
//! cuts (the ray's stretch inside the shadow found by intersecting it with
//! the shadow's cylinder).

use crate::gpu;

use fractal_sdf::prelude::*;
use fractal_sdf::quality::Volumetric;
use fractal_sdf::render::{Frame, Renderer};

/// Odd, so that a pixel's centre lies on the camera's axis.
const W: u32 = 41;
const H: u32 = 31;

const SKY: DVec3 = DVec3::new(0.2, 0.3, 0.4);

fn effects(density: f64, fog: Volumetric) -> Effects {
    Effects::none()
        .fog_density(density)
        .volumetric(fog)
        .sky_top(SKY)
        .sky_bottom(SKY)
        .gamma(1.0)
}

/// The mean of `count` progressive passes, with the shading layers.
fn render(scene: &Scene, effects: Effects, count: u32) -> Frame {
    let options = gpu::options(gpu::plain(Quality::preview()), effects);
    let mut renderer = Renderer::with_options(scene, &options).unwrap();
    let mut frame = renderer.render_progressive_layers(W, H).unwrap();
    for _ in 1..count {
        frame = renderer.render_progressive_layers(W, H).unwrap();
    }
    frame
}

/// Henyey and Greenstein's phase function times π, for `g` and the cosine
/// between the light's direction of travel and the ray towards the camera.
fn phase_pi(g: f64, cos: f64) -> f64 {
    (1.0 - g * g) / (4.0 * (1.0 + g * g - 2.0 * g * cos).powf(1.5))
}

fn rgb(c: [f32; 4]) -> DVec3 {
    dvec3(c[0].into(), c[1].into(), c[2].into())
}

/// A uniform fog under a directional light of radiance `L`, nothing in
/// the way: a ray that leaves the scene gathers `π p(θ) L` whatever the
/// fog's density (the integral of `σ e^(−σ s)` is 1), on top of the sky.
#[test]
fn a_uniform_fog_scatters_a_lights_closed_form() {
    let Some(_) = gpu::device() else { return };
    let camera = Camera::look_at(dvec3(0.0, 0.0, 5.0), DVec3::ZERO);
    let to_light = dvec3(0.3, 0.5, -0.8).normalize();
    // A ball far behind, out of every ray's way.
    let scene = Scene::new(sphere(0.5).translate(dvec3(0.0, 0.0, 50.0)))
        .with_camera(camera)
        .with_lights([Light::directional(to_light).intensity(2.0)]);
    let dirs = gpu::pixel_rays(&camera, (W, H));
    for (density, g) in [(1.0, 0.0), (0.05, 0.0), (0.3, 0.6), (0.3, -0.4)] {
        let frame = render(
            &scene,
            effects(density, Volumetric::default().anisotropy(g)),
            1,
        );
        let linear = &frame.layers.as_ref().unwrap().linear;
        let mut worst: f64 = 0.0;
        for (c, rd) in linear.iter().zip(&dirs) {
            let want = SKY + DVec3::splat(2.0 * phase_pi(g, to_light.dot(*rd)));
            worst = worst.max(((rgb(*c) - want) / want).abs().max_element());
        }
        eprintln!("density {density}, g {g}: worst relative error {worst:.2e}");
        assert!(worst < 2e-3, "density {density}, g {g}: {worst}");
    }
}

/// The fog's optical depth from `ro` along `rd` to `t`, by the midpoint
/// rule over the density `σ e^(−b (y − h))`.
fn depth(ro: DVec3, rd: DVec3, t: f64, (sigma, b, h): (f64, f64, f64)) -> f64 {
    let n = 20_000;
    let ds = t / f64::from(n);
    (0..n)
        .map(|i| {
            let y = ro.y + rd.y * (f64::from(i) + 0.5) * ds;
            sigma * (-b * (y - h)).exp() * ds
        })
        .sum()
}

/// Fog thinning with height in front of a wall, under a directional light
/// (no shadows): every pixel is the sky's share `1 − T` of the fog, the
/// wall's colour without fog times `T`, and the light the fog scatters,
/// `(1 − T) π p(θ) L`, with `T` the transmittance along the ray integrated
/// numerically (to the wall, or far up for the rays that miss it). Seen
/// from within the fog, and from high above a steep ground fog (whose
/// density at the camera is `e^-108` of its density at its height).
#[test]
fn a_fog_thinning_with_height_matches_its_integral() {
    let Some(_) = gpu::device() else { return };
    let to_light = dvec3(-0.4, 0.6, 0.7).normalize();
    let wall = plane(dvec3(0.0, 0.0, 1.0), 1.0).intersect(plane(DVec3::Y, -1.2));
    let g = 0.3;
    for (eye, target, sigma, falloff, height) in [
        (dvec3(0.0, 0.5, 4.0), dvec3(0.0, 1.5, 0.0), 0.5, 1.2, 0.3),
        (dvec3(0.0, 9.3, 6.0), dvec3(0.0, 0.5, -1.0), 2.0, 12.0, 0.3),
    ] {
        let camera = Camera::look_at(eye, target);
        let scene = Scene::new(wall.clone().color(dvec3(0.7, 0.5, 0.3)))
            .with_camera(camera)
            .with_lights([Light::directional(to_light).intensity(1.5)]);
        let fog = Volumetric::height(falloff, height).anisotropy(g);
        let clear = render(&scene, effects(0.0, fog), 1);
        let foggy = render(&scene, effects(sigma, fog), 1);
        let clear = clear.layers.as_ref().unwrap();
        let layers = foggy.layers.as_ref().unwrap();
        let (mut worst, mut misses, mut hits): (f64, u32, u32) = (0.0, 0, 0);
        let mut darkest: f64 = 1.0;
        for (i, rd) in gpu::pixel_rays(&camera, (W, H)).into_iter().enumerate() {
            let hit = layers.linear[i][3] >= 1.0;
            let far = if hit {
                (DVec3::from(layers.position[i].map(f64::from)) - eye).length()
            } else {
                // Far enough that the rest of the fog is negligible.
                (12.0 / rd.y.max(1e-3)).min(400.0)
            };
            let t = (-depth(eye, rd, far, (sigma, falloff, height))).exp();
            darkest = darkest.min(t);
            let surface = if hit { rgb(clear.linear[i]) } else { SKY };
            let want = SKY * (1.0 - t)
                + surface * t
                + DVec3::splat((1.0 - t) * 1.5 * phase_pi(g, to_light.dot(rd)));
            worst = worst.max((rgb(layers.linear[i]) - want).abs().max_element());
            if hit {
                hits += 1;
            } else {
                misses += 1;
            }
        }
        eprintln!(
            "height fog seen from {eye}: worst error {worst:.2e} over {hits} hits and {misses} \
             misses (least transmittance {darkest:.3})"
        );
        assert!(hits > 200, "{hits} hits");
        assert!(worst < 3e-3, "worst error {worst}");
    }
}

/// A ball above a uniform fog under a light straight above: each ray that
/// crosses the ball's shadow (a vertical cylinder below it) loses the
/// light of the fog in it, `π p L (e^(−σ s₀) − e^(−σ s₁))` for the
/// stretch `[s₀, s₁]` inside the cylinder; a ray that misses it keeps all
/// of it. The rays' samples are jittered, so this holds for the mean of
/// passes.
#[test]
fn shadows_cut_shafts_in_the_fog() {
    let Some(_) = gpu::device() else { return };
    let eye = dvec3(0.0, 0.0, 5.0);
    let camera = Camera::look_at(eye, dvec3(0.0, 0.0, 0.0));
    let (centre, radius, sigma) = (dvec3(0.0, 3.0, -1.0), 1.0, 0.3);
    let scene = Scene::new(sphere(radius).translate(centre))
        .with_camera(camera)
        .with_lights([Light::directional(DVec3::Y)]);
    let fog = effects(sigma, Volumetric::default().samples(16)).shadows(true);
    let frame = render(&scene, fog, 64);
    let linear = &frame.layers.as_ref().unwrap().linear;
    let open = 0.25;
    let (mut error, mut count, mut shaded) = (0.0, 0, 0);
    for (i, rd) in gpu::pixel_rays(&camera, (W, H)).into_iter().enumerate() {
        if linear[i][3] > 0.0 {
            continue;
        }
        // The ray's stretch within the cylinder x² + (z − c.z)² < r².
        let (ox, oz) = (eye.x - centre.x, eye.z - centre.z);
        let a = rd.x * rd.x + rd.z * rd.z;
        let b = ox * rd.x + oz * rd.z;
        let c = ox * ox + oz * oz - radius * radius;
        let disc = b * b - a * c;
        let lost = if disc > 0.0 {
            let (s0, s1) = ((-b - disc.sqrt()) / a, (-b + disc.sqrt()) / a);
            // Only where the stretch lies well below the ball.
            if (eye + rd * s0).y.max((eye + rd * s1).y) > centre.y - radius {
                continue;
            }
            shaded += 1;
            (-sigma * s0.max(0.0)).exp() - (-sigma * s1.max(0.0)).exp()
        } else {
            0.0
        };
        let want = SKY.x + open * (1.0 - lost);
        error += f64::from(linear[i][0]) - want;
        count += 1;
        let got = f64::from(linear[i][0]);
        assert!((got - want).abs() < 0.02, "pixel {i}: {got} against {want}");
    }
    let bias = error / f64::from(count);
    eprintln!(
        "fog shafts: mean error {bias:.2e} over {count} pixels, {shaded} crossing the shadow"
    );
    assert!(shaded > 100 && count > 600, "{shaded} of {count}");
    assert!(bias.abs() < 2e-3, "mean error {bias}");
}

/// Bad fog settings are refused by name.
#[test]
fn bad_fog_settings_are_refused() {
    for (fog, setting) in [
        (Volumetric::height(-1.0, 0.0), "volumetric.falloff"),
        (Volumetric::height(f64::NAN, 0.0), "volumetric.falloff"),
        (Volumetric::height(1.0, f64::INFINITY), "volumetric.height"),
        (Volumetric::default().samples(0), "volumetric.samples"),
        (Volumetric::default().samples(65), "volumetric.samples"),
        (
            Volumetric::default().anisotropy(1.0),
            "volumetric.anisotropy",
        ),
    ] {
        let err = Effects::default()
            .fog_density(0.1)
            .volumetric(fog)
            .validate()
            .unwrap_err();
        assert!(
            matches!(err, Error::Effects { setting: s, .. } if s == setting),
            "{setting}: {err}"
        );
    }
}
