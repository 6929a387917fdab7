//! Path-traced global illumination, measured and pictured:
//!
//! - the white furnace (`scenes/furnace.ron`) at albedo 1 and 0.5, side by
//!   side, to `out/furnace.png`;
//! - the noise of a small scene against its passes, beside a reference of
//!   4,096 passes that shares no sample with them, as a table and a
//!   log-log plot (`out/gi_convergence.svg`), with its slope;
//! - the cost of a pass of each kind of light at 640×480 on the gallery's
//!   `gi` scene (direct, path traced under the sky gradient, path traced
//!   under the environment), with distance evaluations per pixel;
//! - the `gi` scene itself, until its estimated noise is 0.01 or after
//!   `--passes` passes (default 16), to `out/gi.png`.
//!
//! `cargo run --release --example global_illumination [-- --size 320x240 --passes 16]`

mod common;

use std::fmt::Write as _;
use std::time::Instant;

use fractal_sdf::file::SceneFile;
use fractal_sdf::image::{RgbaImage, imageops};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::GlobalIllumination;
use fractal_sdf::render::{Frame, RenderOptions, Renderer, StopRule};

fn main() -> std::process::ExitCode {
    common::run(|| {
        furnace()?;
        convergence()?;
        costs()?;
        let size = common::size_arg((320, 240));
        picture(size, passes_arg(16))
    })
}

/// `--passes N` on the command line, or `default`.
fn passes_arg(default: u32) -> u32 {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == "--passes")
        .and_then(|i| args.get(i + 1)?.parse().ok())
        .unwrap_or(default)
}

fn furnace() -> Result<()> {
    let file = SceneFile::load(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/furnace.ron"))?;
    let options = RenderOptions::default()
        .quality(file.quality.unwrap_or_else(Quality::preview))
        .effects(file.effects);
    let mut renderer = Renderer::with_options(&file.scene, &options)?;
    let (w, h) = (240, 180);
    let mut sheet = RgbaImage::new(2 * w, h);
    println!("White furnace (scenes/furnace.ron), 64 passes:");
    for (i, albedo) in [1.0, 0.5].into_iter().enumerate() {
        for axis in ["x", "y", "z"] {
            renderer.set_param(&format!("albedo.{axis}"), albedo)?;
        }
        let frame = passes(&mut renderer, w, h, 64)?;
        let (mean, worst) = covered_stats(&frame, albedo);
        println!(
            "  albedo {albedo}: the sphere's mean radiance {mean:.5}, the farthest pixel \
             {worst:.5} from {albedo}"
        );
        #[allow(clippy::cast_possible_truncation)]
        imageops::replace(&mut sheet, &frame.image, i64::from(w) * i as i64, 0);
    }
    fractal_sdf::output::save_png(&sheet, "out/furnace.png")?;
    println!("  -> out/furnace.png");
    Ok(())
}

/// The mean of `count` passes at `w` × `h`, with the linear colour.
fn passes(renderer: &mut Renderer, w: u32, h: u32, count: u32) -> Result<Frame> {
    renderer.restart_progressive();
    let mut frame = renderer.render_progressive_layers(w, h)?;
    for _ in 1..count {
        frame = renderer.render_progressive_layers(w, h)?;
    }
    Ok(frame)
}

/// The mean linear radiance of the wholly covered pixels, and the largest
/// distance of one of them from `want`.
fn covered_stats(frame: &Frame, want: f64) -> (f64, f64) {
    let layers = frame.layers.as_ref().expect("layers were asked for");
    let (mut sum, mut count, mut worst) = (0.0, 0.0, 0.0f64);
    for c in layers.linear.iter().filter(|c| c[3] >= 1.0) {
        for v in &c[..3] {
            sum += f64::from(*v);
            count += 1.0;
            worst = worst.max((f64::from(*v) - want).abs());
        }
    }
    (sum / count, worst)
}

/// A floor, a ball and a box under a sun and the default sky.
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

fn convergence() -> Result<()> {
    let (w, h) = (64, 48);
    let effects = Effects::default().global_illumination(GlobalIllumination::default());
    let options = RenderOptions::default()
        .quality(Quality::preview().supersampling(1))
        .effects(effects);
    let mut renderer = Renderer::with_options(&bouncing(), &options)?;
    let checks: Vec<u32> = (0..=8).map(|k| 1 << k).collect();
    let last = 4096;
    let mut early = Vec::new();
    let mut frame = None;
    let start = Instant::now();
    for pass in 1..=last {
        let f = renderer.render_progressive_layers(w, h)?;
        if checks.contains(&pass) {
            early.push(f.layers.as_ref().expect("layers").linear.clone());
        }
        frame = Some(f);
    }
    let per_pass = start.elapsed().as_secs_f64() * 1e3 / f64::from(last);
    let all = &frame.expect("passes ran").layers.expect("layers").linear;
    // The reference: passes 257 to 4096, none of them in the images.
    let first = early.last().expect("checks");
    let (n, m) = (f64::from(last), f64::from(*checks.last().expect("checks")));
    #[allow(clippy::cast_possible_truncation)]
    let reference: Vec<[f32; 3]> = all
        .iter()
        .zip(first)
        .map(|(a, f)| {
            std::array::from_fn(|c| ((n * f64::from(a[c]) - m * f64::from(f[c])) / (n - m)) as f32)
        })
        .collect();
    let errors: Vec<f64> = early
        .iter()
        .map(|image| {
            let sum: f64 = image
                .iter()
                .zip(&reference)
                .flat_map(|(p, q)| (0..3).map(move |c| f64::from(p[c] - q[c]).powi(2)))
                .sum();
            #[allow(clippy::cast_precision_loss)]
            let count = (3 * image.len()) as f64;
            (sum / count).sqrt()
        })
        .collect();
    let points: Vec<(f64, f64)> = checks
        .iter()
        .zip(&errors)
        .map(|(&p, &e)| (f64::from(p).ln(), e.ln()))
        .collect();
    let slope = fit(&points).0;
    println!(
        "\nConvergence at {w}x{h} (linear RMSE against passes 257-4096; {per_pass:.1} ms a pass):"
    );
    println!("| passes | RMSE |\n|---:|---:|");
    for (p, e) in checks.iter().zip(&errors) {
        println!("| {p} | {e:.4} |");
    }
    println!("slope of log RMSE against log passes: {slope:.3} (an unbiased estimate: -0.5)");
    std::fs::create_dir_all("out").map_err(|e| Error::io("out", "cannot create", e))?;
    std::fs::write("out/gi_convergence.svg", plot(&points, slope))
        .map_err(|e| Error::io("out/gi_convergence.svg", "cannot write", e))?;
    println!("  -> out/gi_convergence.svg");
    Ok(())
}

/// The least-squares line through `points`: slope and intercept.
fn fit(points: &[(f64, f64)]) -> (f64, f64) {
    #[allow(clippy::cast_precision_loss)]
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(x, y), p| (x + p.0 / n, y + p.1 / n));
    let slope = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / points.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    (slope, my - slope * mx)
}

/// A log-log plot of the errors (natural logarithms in `points`), their
/// fitted line and a line of slope -1/2 through the first point.
fn plot(points: &[(f64, f64)], slope: f64) -> String {
    let (w, h, pad) = (480.0, 320.0, 56.0);
    let (x0, x1) = (points[0].0, points[points.len() - 1].0);
    let lo = points.iter().map(|p| p.1).fold(f64::MAX, f64::min) - 0.3;
    let hi = points.iter().map(|p| p.1).fold(f64::MIN, f64::max) + 0.3;
    let sx = |x: f64| pad + (x - x0) / (x1 - x0) * (w - 2.0 * pad);
    let sy = |y: f64| h - pad - (y - lo) / (hi - lo) * (h - 2.0 * pad);
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
         font-family=\"sans-serif\" font-size=\"12\">"
    );
    let _ = writeln!(svg, "<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>");
    let (left, right, top, bottom) = (pad, w - pad, pad, h - pad);
    let _ = writeln!(
        svg,
        "<path d=\"M{left} {top} V{bottom} H{right}\" stroke=\"black\" fill=\"none\"/>"
    );
    for &(x, _) in points {
        let _ = writeln!(
            svg,
            "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{:.0}</text>",
            sx(x),
            bottom + 16.0,
            x.exp()
        );
    }
    let mut y = (lo.exp() * 1000.0).log10().ceil();
    while 10f64.powf(y) / 1000.0 <= hi.exp() {
        let v = 10f64.powf(y) / 1000.0;
        let _ = writeln!(
            svg,
            "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{v}</text>",
            left - 6.0,
            sy(v.ln()) + 4.0
        );
        y += 1.0;
    }
    let _ = writeln!(
        svg,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">passes</text>",
        w / 2.0,
        h - 12.0
    );
    let _ = writeln!(
        svg,
        "<text x=\"14\" y=\"{:.1}\" transform=\"rotate(-90 14 {:.1})\" \
         text-anchor=\"middle\">RMSE (linear)</text>",
        h / 2.0,
        h / 2.0
    );
    let (fit_slope, intercept) = fit(points);
    let line = |s: f64, c: f64, style: &str| {
        format!(
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" {style}/>",
            sx(x0),
            sy(c + s * x0),
            sx(x1),
            sy(c + s * x1)
        )
    };
    let half = points[0].1 + 0.5 * points[0].0;
    let _ = writeln!(
        svg,
        "{}",
        line(-0.5, half, "stroke=\"#999\" stroke-dasharray=\"6 4\"")
    );
    let _ = writeln!(svg, "{}", line(fit_slope, intercept, "stroke=\"#c33\""));
    for &(x, y) in points {
        let _ = writeln!(
            svg,
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\" fill=\"#36c\"/>",
            sx(x),
            sy(y)
        );
    }
    let _ = writeln!(
        svg,
        "<text x=\"{:.1}\" y=\"{:.1}\" fill=\"#c33\">fitted slope {slope:.3}</text>",
        right - 150.0,
        top + 4.0
    );
    let _ = writeln!(
        svg,
        "<text x=\"{:.1}\" y=\"{:.1}\" fill=\"#777\">slope -0.5</text>",
        right - 150.0,
        top + 20.0
    );
    svg.push_str("</svg>\n");
    svg
}

/// One frame's milliseconds and distance evaluations per pixel, after a
/// frame to warm up.
fn cost(renderer: &mut Renderer, w: u32, h: u32) -> Result<(f64, f64)> {
    renderer.render(w, h)?;
    let start = Instant::now();
    let frame = renderer.render_with_aovs(w, h)?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    let evals: u64 = frame.evaluations.iter().map(|&e| u64::from(e)).sum();
    #[allow(clippy::cast_precision_loss)]
    Ok((ms, evals as f64 / frame.evaluations.len() as f64))
}

fn costs() -> Result<()> {
    let (w, h) = (640, 480);
    let file = fractal_sdf::gallery::file("gi").expect("a gallery scene");
    let quality = file.quality.unwrap_or_else(Quality::production);
    let gi = Effects::default().global_illumination(GlobalIllumination::default());
    let direct = Effects::default();
    let sky = file.scene.clone().with_environment(None);
    println!(
        "\nCost of a pass of the gallery's gi scene at {w}x{h} ({}x{} samples a pixel):",
        quality.supersampling, quality.supersampling
    );
    println!("| light | ms a pass | evaluations a pixel |\n|---|---:|---:|");
    for (what, scene, effects) in [
        ("direct, environment", &file.scene, direct),
        ("path traced, sky gradient", &sky, gi),
        ("path traced, environment", &file.scene, gi),
    ] {
        let options = RenderOptions::default().quality(quality).effects(effects);
        let mut renderer = Renderer::with_options(scene, &options)?;
        let (ms, evals) = cost(&mut renderer, w, h)?;
        println!("| {what} | {ms:.0} | {evals:.0} |");
    }
    Ok(())
}

fn picture((w, h): (u32, u32), most: u32) -> Result<()> {
    let file = fractal_sdf::gallery::file("gi").expect("a gallery scene");
    let options = RenderOptions::default()
        .quality(file.quality.unwrap_or_else(Quality::production))
        .effects(file.effects);
    let mut renderer = Renderer::with_options(&file.scene, &options)?;
    let start = Instant::now();
    let done = renderer.render_converged(w, h, &StopRule::new(0.01, most.max(2)))?;
    fractal_sdf::output::save_png(&done.frame.image, "out/gi.png")?;
    println!(
        "\ngi {w}x{h}: {} passes, estimated noise {:.4}, {:.1} s -> out/gi.png",
        done.passes,
        done.noise,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
