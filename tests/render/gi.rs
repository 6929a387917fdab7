//! Path-traced global illumination: the white furnace (no light created or
//! lost), units that agree with direct lighting, convergence at the rate of
//! an unbiased estimator against an independent reference, and the noise
//! estimate of the stopping rule against the true error.

use crate::gpu;

use std::f64::consts::FRAC_PI_2;

use fractal_sdf::codegen::{self, Options};
use fractal_sdf::file::SceneFile;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::{GlobalIllumination, display};
use fractal_sdf::render::{Frame, Renderer, StopRule};
use fractal_sdf::scene::{InsideBounds, InsideShape};

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
    let shape = InsideShape::new(
        "ball",
        &[],
        InsideBounds::sphere(DVec3::ZERO, 1.5),
        |p, _| p.length() < 1.0,
        "return length(p) < 1.0f;",
    )
    .unwrap();
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
