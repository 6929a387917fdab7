//! Path-traced global illumination: the white furnace (no light created or
//! lost), units that agree with direct lighting, convergence at the rate of
//! an unbiased estimator against an independent reference, the noise
//! estimate of the stopping rule against the true error, and environment
//! lights against closed forms and a brute-force integral.

use crate::gpu;

use std::f64::consts::FRAC_PI_2;

use fractal_sdf::codegen::{self, Options};
use fractal_sdf::file::SceneFile;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::{GlobalIllumination, display};
use fractal_sdf::render::{Frame, Renderer, StopRule};
use fractal_sdf::scene::{Environment, EnvironmentMap};

const W: u32 = 48;
const H: u32 = 32;

fn gi(bounces: u32) -> Effects {
    Effects::default().global_illumination(GlobalIllumination::new(bounces))
}

/// The mean of `passes` progressive passes, with the linear colour.
fn passes(renderer: &mut Renderer, passes: u32) -> Frame {
    let mut frame = renderer.render_progressive_layers(W, H).unwrap();
    for _ in 1..passes {
        frame = renderer.render_progressive_layers(W, H).unwrap();
    }
    frame
}

fn linear(frame: &Frame) -> &[[f32; 4]] {
    &frame.layers.as_ref().unwrap().linear
}

/// The linear colour of the pixels wholly covered by the surface.
fn covered(frame: &Frame) -> Vec<[f32; 3]> {
    linear(frame)
        .iter()
        .filter(|c| c[3] >= 1.0)
        .map(|c| [c[0], c[1], c[2]])
        .collect()
}

/// The white furnace: `node` under a sky of radiance 1 everywhere, lit by
/// nothing else, rendered with `passes` passes of paths of up to
/// `bounces` bounces.
fn furnace(node: Node, bounces: u32, count: u32) -> Frame {
    let white = DVec3::ONE;
    let scene = Scene::new(node)
        .with_camera(Camera::look_at(dvec3(0.0, 0.3, 3.0), DVec3::ZERO))
        .with_lights([]);
    let effects = gi(bounces)
        .sky_top(white)
        .sky_bottom(white)
        .ambient_occlusion(false)
        .shadows(false)
        .gamma(1.0);
    let options = gpu::options(gpu::plain(Quality::preview()), effects);
    let mut renderer = Renderer::with_options(&scene, &options).unwrap();
    passes(&mut renderer, count)
}

/// The shipped furnace: its sphere of albedo 1 is the sky's radiance, 1,
/// and at albedo 0.5 it is 0.5, within 1% at every pixel it covers.
#[test]
fn the_white_furnace_sphere_vanishes() {
    let Some(_) = gpu::device() else { return };
    let file = SceneFile::load(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/furnace.ron")).unwrap();
    let options = gpu::options(gpu::plain(file.quality.unwrap()), file.effects);
    let mut renderer = Renderer::with_options(&file.scene, &options).unwrap();
    for albedo in [1.0, 0.5] {
        for axis in ["x", "y", "z"] {
            renderer
                .set_param(&format!("albedo.{axis}"), albedo)
                .unwrap();
        }
        let frame = passes(&mut renderer, 4);
        let inside = covered(&frame);
        assert!(
            inside.len() > 300,
            "the sphere covers {} pixels",
            inside.len()
        );
        #[allow(clippy::cast_possible_truncation)]
        let want = albedo as f32;
        for c in &inside {
            for v in c {
                assert!((v - want).abs() <= 0.01 * want, "albedo {albedo}: {c:?}");
            }
        }
        // The sky around it is the same 1.
        for c in linear(&frame).iter().filter(|c| c[3] == 0.0) {
            assert!((c[0] - 1.0).abs() < 1e-5, "{c:?}");
        }
    }
}

/// A white block carved by three tunnels and a narrow slot, whose faces
/// see each other: light reaches the back of its cavities only through
/// paths of many bounces.
fn carved() -> Node {
    let tunnel = || cylinder(0.22, 1.0);
    cuboid(dvec3(0.6, 0.6, 0.6))
        .subtract(tunnel())
        .subtract(tunnel().rotate(DVec3::X, FRAC_PI_2))
        .subtract(tunnel().rotate(DVec3::Z, FRAC_PI_2))
        .subtract(cuboid(dvec3(0.04, 0.7, 0.5)).translate(dvec3(0.35, 0.0, 0.0)))
        .rotate(DVec3::Y, 0.5)
        .rotate(DVec3::X, 0.4)
        .color(DVec3::ONE)
        .material(Material::lambert())
}

/// The mean of the wholly covered pixels' channels.
fn mean(pixels: &[[f32; 3]]) -> f64 {
    #[allow(clippy::cast_precision_loss)]
    let n = (3 * pixels.len()) as f64;
    pixels.iter().flatten().map(|&v| f64::from(v)).sum::<f64>() / n
}

/// A concave white block keeps light between its faces: only paths of
/// many bounces, ended by Russian roulette without bias, bring its
/// cavities up to the sky's radiance. Its mean is 1 within 1%; cut at 2
/// bounces, it loses light (so the check can fail).
#[test]
fn the_white_furnace_holds_for_light_between_faces() {
    let Some(_) = gpu::device() else { return };
    let every = covered(&furnace(carved(), 64, 64));
    assert!(every.len() > 300, "the block covers {} pixels", every.len());
    let kept = mean(&every);
    assert!((kept - 1.0).abs() < 0.01, "mean {kept}");
    let cut = mean(&covered(&furnace(carved(), 2, 64)));
    assert!(cut < 0.98, "two bounces keep {cut}");
}

/// The specular lobe is normalised: a white, fully specular sphere in the
/// furnace loses the part of its lobe below the horizon and creates none.
#[test]
fn a_specular_lobe_creates_no_light() {
    let Some(_) = gpu::device() else { return };
    for shininess in [1.0, 20.0] {
        let shiny = sphere(0.8)
            .color(DVec3::ONE)
            .material(Material::blinn_phong(1.0, shininess));
        let kept = mean(&covered(&furnace(shiny, 16, 64)));
        assert!(kept <= 1.01, "shininess {shininess}: mean {kept}");
        assert!(kept > 0.6, "shininess {shininess}: mean {kept}");
    }
}

/// A light's radiance means the same in both modes: a Lambertian sphere
/// under one sun and a black sky, with nothing for light to bounce off,
/// is the same colour path traced as lit directly.
#[test]
fn global_illumination_agrees_with_direct_light_where_nothing_bounces() {
    let Some(_) = gpu::device() else { return };
    let ball = sphere(0.8)
        .color(dvec3(0.9, 0.6, 0.3))
        .material(Material::lambert());
    let scene = Scene::new(ball)
        .with_camera(Camera::look_at(dvec3(0.0, 0.3, 3.0), DVec3::ZERO))
        .with_lights([gpu::sun(0.0).intensity(1.5)]);
    let black = Effects::default()
        .sky_top(DVec3::ZERO)
        .sky_bottom(DVec3::ZERO)
        .ambient_occlusion(false);
    let quality = gpu::plain(Quality::preview());
    let render = |effects: Effects| {
        let mut r = Renderer::with_options(&scene, &gpu::options(quality, effects)).unwrap();
        r.render_layers(W, H).unwrap()
    };
    let direct = render(black);
    let traced = render(black.global_illumination(GlobalIllumination::new(4)));
    let mut lit = 0;
    for (a, b) in linear(&direct).iter().zip(linear(&traced)) {
        if a[3] < 1.0 {
            continue;
        }
        lit += usize::from(a[0] > 0.1);
        for c in 0..3 {
            assert!((a[c] - b[c]).abs() < 2e-3, "direct {a:?}, traced {b:?}");
        }
    }
    assert!(lit > 50, "{lit} lit pixels");
}

/// A floor, a ball and a box under a sun and the default sky: light
/// bounces between them.
fn bouncing() -> Scene {
    let ball = sphere(0.5).translate(dvec3(0.0, 0.5, 0.0));
    let block = round_box(dvec3(0.3, 0.3, 0.3), 0.05)
        .color(dvec3(0.9, 0.3, 0.2))
        .translate(dvec3(0.9, 0.35, 0.2));
    Scene::new(
        plane(DVec3::Y, 0.0)
            .color(dvec3(0.7, 0.7, 0.7))
            .union(ball)
            .union(block),
    )
    .with_camera(Camera::look_at(dvec3(0.0, 1.5, 3.0), dvec3(0.2, 0.4, 0.0)))
    .with_lights([Light::directional(dvec3(0.5, 0.8, 0.3))])
}

fn rms(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| f64::from(p[c] - q[c]).powi(2)))
        .sum();
    #[allow(clippy::cast_precision_loss)]
    let n = (3 * a.len()) as f64;
    (sum / n).sqrt()
}

/// Passes 1 to 64 converge on the mean of passes 65 to 1024 (a reference
/// that shares no sample with them) with an error that falls as
/// `passes^-0.5`, the rate of an unbiased Monte Carlo estimate, and the
/// 16-pass image's mean error is within the noise it predicts: no bias.
#[test]
fn global_illumination_converges_without_bias() {
    let Some(_) = gpu::device() else { return };
    let options = gpu::options(gpu::plain(Quality::preview()), gi(16));
    let mut renderer = Renderer::with_options(&bouncing(), &options).unwrap();
    let mut early = Vec::new();
    let mut frame = None;
    for pass in 1..=1024u32 {
        let f = renderer.render_progressive_layers(W, H).unwrap();
        if pass.is_power_of_two() && pass <= 64 {
            early.push(linear(&f).to_vec());
        }
        frame = Some(f);
    }
    let all = linear(frame.as_ref().unwrap());
    let first64 = early.last().unwrap();
    // The mean of passes 65..=1024.
    let reference: Vec<[f32; 4]> = all
        .iter()
        .zip(first64)
        .map(|(a, f)| std::array::from_fn(|c| (1024.0 * a[c] - 64.0 * f[c]) / 960.0))
        .collect();
    let errors: Vec<f64> = early.iter().map(|e| rms(e, &reference)).collect();
    // The least-squares slope of log error against log passes.
    #[allow(clippy::cast_precision_loss)]
    let points: Vec<(f64, f64)> = errors
        .iter()
        .enumerate()
        .map(|(k, e)| ((k as f64) * 2f64.ln(), e.ln()))
        .collect();
    #[allow(clippy::cast_precision_loss)]
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(x, y), p| (x + p.0 / n, y + p.1 / n));
    let slope = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / points.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    eprintln!("RMSE by passes 1, 2, 4, .., 64: {errors:.4?}; slope {slope:.3}");
    assert!(
        (slope + 0.5).abs() <= 0.1,
        "slope {slope}, errors {errors:?}"
    );
    // No bias: the mean signed error of the 16-pass image over its
    // independent pixels is within 4 of its standard errors.
    let sixteen = &early[4];
    let diffs: Vec<f64> = sixteen
        .iter()
        .zip(&reference)
        .flat_map(|(p, q)| (0..3).map(move |c| f64::from(p[c] - q[c])))
        .collect();
    #[allow(clippy::cast_precision_loss)]
    let count = diffs.len() as f64;
    let mean = diffs.iter().sum::<f64>() / count;
    let spread = (diffs.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / count).sqrt();
    assert!(
        mean.abs() <= 4.0 * spread / count.sqrt(),
        "mean error {mean} against a standard error of {}",
        spread / count.sqrt()
    );
}

/// The stopping rule's noise, estimated from the passes alone, is the true
/// error of the image against an independent long reference, within a
/// factor of 1.5; and it stops once the noise is reached.
#[test]
fn the_stopping_rule_estimates_the_true_noise() {
    let Some(_) = gpu::device() else { return };
    let options = gpu::options(gpu::plain(Quality::preview()), gi(16));
    let mut renderer = Renderer::with_options(&bouncing(), &options).unwrap();
    let rule = StopRule::new(0.02, 512);
    let done = renderer.render_converged(W, H, &rule).unwrap();
    assert!(
        done.reached(&rule),
        "noise {} after {}",
        done.noise,
        done.passes
    );
    assert!(
        done.passes >= 4 && done.passes < 512,
        "{} passes",
        done.passes
    );
    // The reference: passes done.passes + 1 ..= 1024 of the same sequence.
    let n = done.passes;
    let mut all = None;
    for _ in 0..1024 - n {
        all = Some(renderer.render_progressive_layers(W, H).unwrap());
    }
    let all = all.unwrap();
    let effects = Effects::default();
    let (nf, rest) = (n as f32, (1024 - n) as f32);
    let truth: f64 = {
        let shown: Vec<[f32; 3]> = linear(&done.frame)
            .iter()
            .map(|c| display([c[0], c[1], c[2]], &effects))
            .collect();
        let reference: Vec<[f32; 3]> = linear(&all)
            .iter()
            .zip(linear(&done.frame))
            .map(|(a, d)| {
                let m: [f32; 3] = std::array::from_fn(|c| (1024.0 * a[c] - nf * d[c]) / rest);
                display(m, &effects)
            })
            .collect();
        let sum: f64 = shown
            .iter()
            .zip(&reference)
            .flat_map(|(p, q)| (0..3).map(move |c| f64::from(p[c] - q[c]).powi(2)))
            .sum();
        #[allow(clippy::cast_precision_loss)]
        let count = (3 * shown.len()) as f64;
        (sum / count).sqrt()
    };
    let ratio = done.noise / truth;
    eprintln!(
        "{} passes: estimated noise {:.4}, true {truth:.4}",
        done.passes, done.noise
    );
    assert!(
        (1.0 / 1.5..=1.5).contains(&ratio),
        "estimate {} vs {truth}",
        done.noise
    );
    // Nonsense rules are refused.
    for bad in [
        StopRule::new(0.0, 16),
        StopRule::new(f64::NAN, 16),
        StopRule::new(0.01, 1),
    ] {
        assert!(matches!(
            renderer.render_converged(W, H, &bad),
            Err(Error::Quality { .. })
        ));
    }
}

/// A path needs a normal at every bounce, which an inside shape has only
/// on screen: the program is refused, naming the shape.
#[test]
fn global_illumination_refuses_inside_shapes() {
    let shape = gpu::inside_ball();
    let scene = Scene::new(shape.node::<f64>([]).union(plane(DVec3::Y, -1.0)));
    let compiled = scene.compile().unwrap();
    let options = Options::default().effects(gi(8));
    let err = codegen::emit(&compiled, &options).unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, Error::InsideShape { .. }), "{text}");
    assert!(
        text.contains("`ball`") && text.contains("global illumination"),
        "{text}"
    );
    codegen::emit(&compiled, &Options::default()).unwrap();
}

/// A sky of radiance 1 above the horizon and none below, `rows` texels
/// high (even: the horizon falls between two rows).
fn half_sky(rows: u32) -> EnvironmentMap {
    let texels = (0..rows)
        .flat_map(|y| std::iter::repeat_n(if y < rows / 2 { [1.0f32; 3] } else { [0.0; 3] }, 64))
        .collect();
    EnvironmentMap::new(64, rows, texels).unwrap()
}

/// Linear colours of the pixels wholly covered, and whose four neighbours
/// are, with the normal through their centres.
fn interior(frame: &Frame) -> Vec<([f32; 3], DVec3)> {
    let l = linear(frame);
    let w = W as usize;
    (0..l.len())
        .filter(|&i| {
            let (x, y) = (i % w, i / w);
            x > 0
                && y > 0
                && x + 1 < w
                && y + 1 < H as usize
                && [i, i - 1, i + 1, i - w, i + w]
                    .iter()
                    .all(|&j| l[j][3] >= 1.0)
        })
        .map(|i| {
            let n = frame.normal[i];
            (
                [l[i][0], l[i][1], l[i][2]],
                dvec3(f64::from(n[0]), f64::from(n[1]), f64::from(n[2])),
            )
        })
        .collect()
}

/// A white sphere under a sky of radiance `r` over the upper half and
/// black below sends back `r (1 + n.y) / 2` along normal `n` (the share
/// of its cosine-weighted hemisphere above the horizon): a closed form
/// the path tracer and its importance sampling of the environment must
/// meet, turned and scaled, without bias (mean error within 1%) and with
/// little noise (2,048 samples a pixel: 5% at most, rms).
#[test]
fn an_environment_lights_a_sphere_as_the_closed_form_says() {
    let Some(_) = gpu::device() else { return };
    let env = Environment::new(half_sky(32))
        .rotation_degrees(40.0)
        .intensity(2.0);
    let scene = Scene::new(sphere(0.8).color(DVec3::ONE).material(Material::lambert()))
        .with_camera(Camera::look_at(dvec3(0.0, 0.3, 3.0), DVec3::ZERO))
        .with_lights([])
        .with_environment(env);
    let options = gpu::options(gpu::plain(Quality::preview()), gi(4).gamma(1.0));
    let mut renderer = Renderer::with_options(&scene, &options).unwrap();
    let frame = passes(&mut renderer, 2048);
    let pixels = interior(&frame);
    assert!(pixels.len() > 200, "{} pixels", pixels.len());
    let (mut bias, mut square) = (0.0, 0.0);
    for (c, n) in &pixels {
        let want = 2.0 * (1.0 + n.y) / 2.0;
        let error = (f64::from(c[1]) - want) / want.max(0.2);
        bias += error;
        square += error * error;
    }
    #[allow(clippy::cast_precision_loss)]
    let count = pixels.len() as f64;
    let (bias, rms) = (bias / count, (square / count).sqrt());
    eprintln!("half sky: mean relative error {bias:.4}, rms {rms:.4}");
    assert!(bias.abs() < 0.01, "mean relative error {bias}");
    assert!(rms < 0.05, "rms relative error {rms}");
}

/// A sun as bright as the rest of the sky put together, in a single texel:
/// the lights' sampling finds it by importance, so the sphere it lights
/// is as quiet as under a smooth sky. While lighting read the texels
/// bilinearly (the sun's light spilling into texels drawn as rarely as
/// the sky around) the error measured 0.57.
#[test]
fn a_small_bright_sun_is_found_by_importance_sampling() {
    let Some(_) = gpu::device() else { return };
    let mut texels = vec![[0.2f32; 3]; 64 * 32];
    texels[8 * 64 + 20] = [2000.0; 3];
    let env = Environment::new(EnvironmentMap::new(64, 32, texels).unwrap());
    let scene = Scene::new(sphere(0.8).color(DVec3::ONE).material(Material::lambert()))
        .with_camera(Camera::look_at(dvec3(0.0, 0.3, 3.0), DVec3::ZERO))
        .with_lights([])
        .with_environment(env.clone());
    let options = gpu::options(gpu::plain(Quality::preview()), gi(4).gamma(1.0));
    let mut renderer = Renderer::with_options(&scene, &options).unwrap();
    let frame = passes(&mut renderer, 256);
    // The oracle: the texels' radiance, as constant patches, against the
    // normal's cosine, summed over a fine grid of directions.
    let map = &env.map;
    let (mw, mh) = (map.width() as usize, map.height() as usize);
    let texel = |d: DVec3| {
        let u = 0.5 + d.x.atan2(-d.z) / std::f64::consts::TAU;
        let v = d.y.clamp(-1.0, 1.0).acos() / std::f64::consts::PI;
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let (x, y) = (
            ((u * 64.0) as usize).min(mw - 1),
            ((v * 32.0) as usize).min(mh - 1),
        );
        f64::from(map.texels()[y * mw + x][0])
    };
    let (mut square, mut count) = (0.0, 0.0);
    for (c, n) in interior(&frame) {
        let k = 256;
        let mut sum = 0.0;
        for a in 0..k {
            for b in 0..2 * k {
                #[allow(clippy::cast_precision_loss)]
                let (theta, phi) = (
                    (f64::from(a) + 0.5) / f64::from(k) * std::f64::consts::PI,
                    (f64::from(b) + 0.5) / f64::from(2 * k) * std::f64::consts::TAU,
                );
                let d = dvec3(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                let cos = d.dot(n);
                if cos > 0.0 {
                    let solid = theta.sin() * (std::f64::consts::PI / f64::from(k)).powi(2);
                    sum += texel(d) * cos * solid;
                }
            }
        }
        let want = sum / std::f64::consts::PI;
        square += ((f64::from(c[0]) - want) / want).powi(2);
        count += 1.0;
    }
    let rms = (square / count).sqrt();
    eprintln!("sun: rms relative error {rms:.4} over {count} pixels");
    assert!(rms < 0.06, "rms relative error {rms}");
}

/// Without global illumination an environment is the background along
/// each ray, and its irradiance over pi (the sky gradient's share of it)
/// the ambient light; a new intensity is a buffer, not a program.
#[test]
fn direct_light_shows_the_environment_and_takes_its_ambient_light() {
    let Some(_) = gpu::device() else { return };
    let env = Environment::new(EnvironmentMap::new(8, 4, vec![[0.6, 0.4, 0.2]; 32]).unwrap());
    let scene = Scene::new(sphere(0.8).color(DVec3::ONE).material(Material::lambert()))
        .with_camera(Camera::look_at(dvec3(0.0, 0.3, 3.0), DVec3::ZERO))
        .with_lights([])
        .with_environment(env.clone());
    let effects = Effects::default().ambient_occlusion(false).shadows(false);
    let options = gpu::options(gpu::plain(Quality::preview()), effects);
    let mut renderer = Renderer::with_options(&scene, &options).unwrap();
    let check = |frame: &Frame, scale: f32| {
        for c in linear(frame) {
            // A sky of one radiance everywhere: the background is that
            // radiance, and a white face half of it (the ambient share)
            // whichever way it faces.
            let want = if c[3] == 0.0 {
                1.0
            } else if c[3] >= 1.0 {
                0.5
            } else {
                continue;
            };
            for (v, r) in c[..3].iter().zip([0.6, 0.4, 0.2]) {
                assert!((v - want * r * scale).abs() < 0.01 * scale, "{c:?}");
            }
        }
    };
    check(&renderer.render_layers(W, H).unwrap(), 1.0);
    let builds = renderer.builds();
    renderer.set_environment(Some(env.intensity(2.0))).unwrap();
    check(&renderer.render_layers(W, H).unwrap(), 2.0);
    assert_eq!(
        renderer.builds(),
        builds,
        "a new intensity rebuilt the program"
    );
    // Removing it is a new program, back on the blue-grey sky gradient
    // (the environment was orange).
    renderer.set_environment(None).unwrap();
    let plain = renderer.render_layers(W, H).unwrap();
    assert!(!renderer.source().source.contains("march_environment"));
    let background = linear(&plain).iter().filter(|c| c[3] == 0.0);
    assert!(background.clone().count() > 100);
    assert!(
        background.clone().all(|c| c[2] > c[0]),
        "{:?}",
        background.collect::<Vec<_>>()
    );
}

/// A ball of light lights a floor as a point light of its intensity at its
/// centre would, wherever the whole ball is above the floor's horizon:
/// `I cos(theta) / d^2` at distance `d` and angle `theta` (the closed form
/// of a spherical source's irradiance), within 1% on average; and its
/// shadow is soft where a point light's is hard.
#[test]
fn a_sphere_light_lights_as_its_closed_form_says() {
    let Some(_) = gpu::device() else { return };
    let centre = dvec3(0.3, 1.2, -0.2);
    let floor = plane(DVec3::Y, 0.0)
        .color(DVec3::ONE)
        .material(Material::lambert());
    let scene = Scene::new(floor)
        .with_camera(Camera::look_at(dvec3(0.0, 2.5, 3.0), dvec3(0.0, 0.0, 0.0)))
        .with_lights([Light::sphere(centre, 0.4).intensity(2.0)]);
    let black = Effects::default()
        .sky_top(DVec3::ZERO)
        .sky_bottom(DVec3::ZERO)
        .gamma(1.0);
    let options = gpu::options(
        gpu::plain(Quality::preview()),
        black.global_illumination(GlobalIllumination::new(1)),
    );
    let mut renderer = Renderer::with_options(&scene, &options).unwrap();
    let frame = passes(&mut renderer, 256);
    let layers = frame.layers.as_ref().unwrap();
    let (mut bias, mut count) = (0.0, 0.0);
    for (i, c) in layers.linear.iter().enumerate() {
        if c[3] < 1.0 {
            continue;
        }
        let p = glam::Vec3::from(layers.position[i]).as_dvec3();
        let delta = centre - p;
        let want = 2.0 * delta.normalize().y / delta.length_squared();
        bias += (f64::from(c[0]) - want) / want;
        count += 1.0;
    }
    let bias = bias / count;
    eprintln!("sphere light: mean relative error {bias:.4} over {count} pixels");
    assert!(
        count > 500.0 && bias.abs() < 0.01,
        "mean relative error {bias}"
    );
    // A ball between the light and the floor: the pixels in part shadow
    // (between a tenth and nine tenths of the light they would have).
    let penumbra = |light: Light| {
        let blocker = sphere(0.15).translate(dvec3(0.3, 0.7, -0.2));
        let scene = scene.clone().add(blocker).with_lights([light]);
        let mut renderer = Renderer::with_options(&scene, &options).unwrap();
        let frame = passes(&mut renderer, 64);
        let layers = frame.layers.as_ref().unwrap();
        layers
            .linear
            .iter()
            .zip(&layers.position)
            .filter(|(c, p)| {
                let delta = centre - glam::Vec3::from(**p).as_dvec3();
                let open = 2.0 * delta.normalize().y / delta.length_squared();
                let share = f64::from(c[0]) / open;
                c[3] >= 1.0 && p[1] < 0.05 && share > 0.1 && share < 0.9
            })
            .count()
    };
    let (soft, hard) = (
        penumbra(Light::sphere(centre, 0.4).intensity(2.0)),
        penumbra(Light::point(centre).intensity(2.0)),
    );
    eprintln!("pixels in part shadow: {soft} under the ball of light, {hard} under the point");
    assert!(soft > 3 * hard.max(5), "{soft} against {hard}");
}

/// A ball that gives off light: the camera sees its colour times its
/// emission without global illumination (no sky, no lights), and under
/// it the ball lights a white floor as a sphere of that radiance does,
/// `L (R / d)² cos θ` (its irradiance `π L sin²α cos θ` over π), found by
/// the paths' bounces alone.
#[test]
fn an_emissive_ball_lights_the_floor_as_its_closed_form_says() {
    let Some(_) = gpu::device() else { return };
    let (centre, radius, emission) = (dvec3(0.2, 1.1, -0.3), 0.5, 3.0);
    let color = dvec3(1.0, 0.8, 0.6);
    let floor = plane(DVec3::Y, 0.0)
        .color(DVec3::ONE)
        .material(Material::lambert());
    let ball = sphere(radius)
        .translate(centre)
        .color(color)
        .material(Material::emissive(emission));
    let eye = dvec3(0.0, 2.5, 3.0);
    let scene = Scene::new(floor.clone().union(ball))
        .with_camera(Camera::look_at(eye, dvec3(0.0, 0.3, 0.0)))
        .with_lights([]);
    let black = Effects::default()
        .sky_top(DVec3::ZERO)
        .sky_bottom(DVec3::ZERO)
        .ambient_occlusion(false)
        .gamma(1.0);
    let on_ball = |p: [f32; 3]| glam::Vec3::from(p).as_dvec3().distance(centre) < radius + 0.05;

    let direct = gpu::options(gpu::plain(Quality::preview()), black);
    let frame = Renderer::with_options(&scene, &direct)
        .unwrap()
        .render_layers(W, H)
        .unwrap();
    let layers = frame.layers.as_ref().unwrap();
    let mut seen = 0;
    for (c, p) in layers.linear.iter().zip(&layers.position) {
        if c[3] >= 1.0 && on_ball(*p) {
            let want = color * emission;
            let got = dvec3(c[0].into(), c[1].into(), c[2].into());
            assert!(
                (got - want).abs().max_element() < 1e-3,
                "{got} against {want} at {p:?}"
            );
            seen += 1;
        } else if c[3] >= 1.0 {
            assert!(
                c[0].abs() < 1e-6,
                "the floor is dark without global illumination"
            );
        }
    }
    assert!(seen > 20, "the ball covers {seen} pixels");

    // Rays leave a surface a few hit thresholds off it: a fine threshold
    // keeps that from bringing the floor measurably nearer the ball.
    let options = gpu::options(
        gpu::plain(Quality::preview().detail(0.01).hit_epsilon(0.01)),
        black.global_illumination(GlobalIllumination::new(1)),
    );
    let mut renderer = Renderer::with_options(&scene, &options).unwrap();
    // The closed form at the floor's points near the ball (the hit
    // threshold lifts them), for a pixel wholly on the floor whose rays
    // (jittered in the pixel by the passes) none come near the ball: the
    // factor of the ball's radiance the floor reflects there.
    let floor_share = |c: [f32; 4], p: [f32; 3]| {
        let q = glam::Vec3::from(p).as_dvec3();
        let delta = centre - q;
        let along = (q - eye).normalize();
        let passing = (centre - eye).reject_from_normalized(along).length();
        let near = c[3] >= 1.0 && passing >= radius + 0.4 && q.y <= 0.3 && delta.length() <= 2.5;
        near.then(|| radius * radius / delta.length_squared() * delta.normalize().y)
    };
    let frame = passes(&mut renderer, 1024);
    let layers = frame.layers.as_ref().unwrap();
    let (mut got, mut wanted, mut count) = (0.0, 0.0, 0.0);
    for (c, p) in layers.linear.iter().zip(&layers.position) {
        let Some(share) = floor_share(*c, *p) else {
            continue;
        };
        for (channel, tint) in [(0, color.x), (2, color.z)] {
            got += f64::from(c[channel]);
            wanted += emission * tint * share;
            count += 1.0;
        }
    }
    let bias = got / wanted - 1.0;
    eprintln!("emissive ball: relative error of the mean {bias:.4} over {count} pixel channels");
    // Sixteen passes: the emitter is sampled at every bounce (its bounding
    // sphere's cone), against the same ball repeated every 1,000 units (no
    // bound, so only the bounces find it): the floor's noise.
    let noise = |scene: &Scene| {
        let mut renderer = Renderer::with_options(scene, &options).unwrap();
        let frame = passes(&mut renderer, 16);
        let layers = frame.layers.as_ref().unwrap();
        let (mut squares, mut n) = (0.0, 0.0);
        for (c, p) in layers.linear.iter().zip(&layers.position) {
            let Some(share) = floor_share(*c, *p) else {
                continue;
            };
            let want = emission * color.x * share;
            squares += ((f64::from(c[0]) - want) / want).powi(2);
            n += 1.0;
        }
        (squares / n).sqrt()
    };
    let sampled = noise(&scene);
    let unbounded = sphere(radius)
        .repeat(dvec3(1000.0, 1000.0, 1000.0))
        .translate(centre)
        .color(color)
        .material(Material::emissive(emission));
    let mut alone = scene.clone();
    alone.geometry = Some(floor.union(unbounded));
    let found = noise(&alone);
    eprintln!(
        "emissive ball: relative RMS error of a floor pixel at 16 passes {sampled:.4} \
         sampled, {found:.4} found by bounces alone"
    );
    assert!(
        sampled < 0.1 && sampled < 0.5 * found,
        "{sampled} against {found}"
    );
    assert!(
        count > 500.0 && bias.abs() < 0.015,
        "relative error of the mean {bias}"
    );
}

/// A ball of light needs a radius above 0, finite; a rectangle two sides
/// at right angles, neither zero.
#[test]
fn area_lights_without_an_area_are_refused() {
    let refused = |light: Light, says: &str| {
        let scene = Scene::new(sphere(1.0)).with_lights([light]);
        let err = scene.compile().unwrap_err().to_string();
        assert!(err.contains("light[0]") && err.contains(says), "{err}");
    };
    for radius in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        refused(Light::sphere(DVec3::Y * 3.0, radius), "radius");
    }
    refused(Light::rect(DVec3::Y, DVec3::ZERO, DVec3::X), "`u`");
    refused(
        Light::rect(DVec3::Y, DVec3::X, dvec3(1.0, 0.0, 1.0)),
        "right angles",
    );
    let fine = Scene::new(sphere(1.0)).with_lights([Light::rect(DVec3::Y, DVec3::X, DVec3::Z)]);
    fine.compile().unwrap();
}

/// A rectangle of light facing down lights a floor as Lambert's formula
/// for a polygon says, `E = (L / 2) Σ θᵢ (n · Γᵢ)` over its edges (each
/// seen at angle `θᵢ`, in the plane of unit normal `Γᵢ` through the
/// point), with `L = π I / area`: within 1% on average; nothing lights
/// the floor from the rectangle's back.
#[test]
fn a_rectangle_light_lights_as_lamberts_formula_says() {
    let Some(_) = gpu::device() else { return };
    let (centre, u, v) = (
        dvec3(0.3, 1.0, -0.2),
        dvec3(0.5, 0.0, 0.0),
        dvec3(0.0, 0.0, 0.3),
    );
    let floor = plane(DVec3::Y, 0.0)
        .color(DVec3::ONE)
        .material(Material::lambert());
    let black = Effects::default()
        .sky_top(DVec3::ZERO)
        .sky_bottom(DVec3::ZERO)
        .gamma(1.0)
        .global_illumination(GlobalIllumination::new(1));
    let options = gpu::options(gpu::plain(Quality::preview()), black);
    let render = |light: Light| {
        let scene = Scene::new(floor.clone())
            .with_camera(Camera::look_at(dvec3(0.0, 2.5, 3.0), dvec3(0.0, 0.0, 0.0)))
            .with_lights([light]);
        let mut renderer = Renderer::with_options(&scene, &options).unwrap();
        passes(&mut renderer, 256)
    };
    let frame = render(Light::rect(centre, u, v).intensity(2.0));
    let layers = frame.layers.as_ref().unwrap();
    let corners = [
        centre - u - v,
        centre + u - v,
        centre + u + v,
        centre - u + v,
    ];
    let area = 4.0 * u.cross(v).length();
    let (mut bias, mut count) = (0.0, 0.0);
    for (c, p) in layers.linear.iter().zip(&layers.position) {
        if c[3] < 1.0 {
            continue;
        }
        let p = glam::Vec3::from(*p).as_dvec3();
        let r: Vec<DVec3> = corners.iter().map(|q| (*q - p).normalize()).collect();
        let sum: f64 = (0..4)
            .map(|i| {
                let (a, b) = (r[i], r[(i + 1) % 4]);
                a.dot(b).clamp(-1.0, 1.0).acos() * DVec3::Y.dot(a.cross(b).normalize())
            })
            .sum();
        let want = 2.0 / (2.0 * area) * sum.abs();
        bias += (f64::from(c[0]) - want) / want;
        count += 1.0;
    }
    let bias = bias / count;
    eprintln!("rectangle light: mean relative error {bias:.4} over {count} pixels");
    assert!(
        count > 500.0 && bias.abs() < 0.01,
        "mean relative error {bias}"
    );
    // Turned over, it shines up, away from the floor.
    let back = render(Light::rect(centre, v, u).intensity(2.0));
    let lit = back
        .layers
        .as_ref()
        .unwrap()
        .linear
        .iter()
        .filter(|c| c[0] > 0.0)
        .count();
    assert_eq!(lit, 0, "{lit} pixels lit from behind");
}

/// An environment image of radiance 1 everywhere and a sky gradient of 1
/// are the same light: the block that keeps light between its faces is
/// lit alike by both, with paths cut after one bounce as after sixteen,
/// within 0.25% (measured: 0.9678 and 0.9686 after one, 0.9961 and 0.9972
/// after sixteen). The environment's light is shared between the lights'
/// sampling and the bounces, so the last surface's bounce must be traced
/// too: when it was not, the environment lost most of what the last
/// surface receives from it, and the sky all of it (0.9526 and 0.9560).
#[test]
fn an_environment_and_the_sky_of_the_same_light_agree_at_every_cut() {
    let Some(_) = gpu::device() else { return };
    let uniform = Environment::new(EnvironmentMap::new(8, 4, vec![[1.0; 3]; 32]).unwrap());
    for bounces in [1, 16] {
        let sky = mean(&covered(&furnace(carved(), bounces, 64)));
        let white = Effects::default()
            .global_illumination(GlobalIllumination::new(bounces))
            .ambient_occlusion(false)
            .shadows(false)
            .gamma(1.0);
        let scene = Scene::new(carved())
            .with_camera(Camera::look_at(dvec3(0.0, 0.3, 3.0), DVec3::ZERO))
            .with_lights([])
            .with_environment(uniform.clone());
        let options = gpu::options(gpu::plain(Quality::preview()), white);
        let mut renderer = Renderer::with_options(&scene, &options).unwrap();
        let env = mean(&covered(&passes(&mut renderer, 64)));
        eprintln!("{bounces} bounces: sky {sky:.4}, environment {env:.4}");
        assert!(
            (env - sky).abs() < 0.0025,
            "{bounces} bounces: sky {sky}, environment {env}"
        );
    }
}
