//! Deep zoom: one point of a Mandelbulb's surface seen at magnifications
//! 1 to 1e14 (the camera moves towards it along a fixed ray, one decade a
//! step), in F32 and F64, to measure where each precision breaks down.
//!
//! Two measures per magnification:
//!
//! - F32 against F64 (PSNR): where F32 departs from F64;
//! - each precision against itself with the whole scene moved by a fixed
//!   offset (bulb, camera and target together; the lights are
//!   directional). The moved bulb is joined by a speck far outside the
//!   view, so the offset stays inside the geometry: a scene whose root is
//!   the translation would be rendered in the translation's frame, the
//!   offset removed on the host in `f64` (see `Ir::local_frame`), and both
//!   copies would be the same program with the same inputs. In exact
//!   arithmetic the two images are identical, so
//!   their difference is rounding alone: where it grows past 30 dB PSNR
//!   the precision no longer carries the view. For F32 it breaks where F32
//!   departs from F64, which validates the measure; for F64 it is the only
//!   measure there is (no wider precision to compare with).
//!
//! A precision can also fail the same way in both copies: once no
//! gradient can be resolved every pixel gets the same colour. So the
//! contrast of each image (the standard deviation of its luma, 0 to 255)
//! is reported too, and an image below [`FLAT`] counts as broken.
//!
//! Then it traces shadow rays from the target point towards the key light,
//! starting 1e-2 to 1e-12 along it, to show at which scales the point is
//! in the shadow of the bulb's own structure.
//!
//! These renders leave ambient occlusion out, so they measure the geometry
//! and the lights alone. A fifth render per magnification, in F64, has
//! occlusion on: its reach follows the view (see `Effects::ao_distance`),
//! so it should darken the creases about as much at every magnification.
//! Its mean luma is reported against the same render without occlusion.
//!
//! Prints markdown tables and writes a contact sheet to
//! `out/deep_zoom.png` (rows: F32, F32 moved, F64, F64 moved, F64 with
//! occlusion).
//!
//! `cargo run --release --example deep_zoom [-- --size 160x120] [--decades 14]`

mod common;

use fractal_sdf::cpu::{self, Evaluator, MarchSettings, Ray};
use fractal_sdf::metrics::psnr;
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::{RenderOptions, Renderer};
use fractal_sdf::scene::Mandelbulb;
use image::RgbaImage;

/// Iterations of the bulb: each resolves detail about 8 times finer, so
/// 16 keep structure in view down to about 1e-14.
const ITERATIONS: u32 = 16;
/// Decades of magnification by default: 1 to 1e14, far enough to see F64
/// break.
const DECADES: i32 = 14;
/// Where the unmagnified camera is, and what it looks at.
const CAMERA: DVec3 = DVec3::new(2.05, 1.45, 2.8);
const TARGET: DVec3 = DVec3::new(0.0, -0.12, 0.0);
/// The offset of the moved copy (not a power of two in any coordinate, so
/// every coordinate is rounded differently).
const SHIFT: DVec3 = DVec3::new(0.375, -0.3, 0.2);
/// PSNR below which two renders count as different.
const BREAK_DB: f64 = 30.0;
/// Luma standard deviation below which an image counts as flat.
const FLAT: f64 = 2.0;

fn bulb() -> Node {
    Node::from(Mandelbulb::new(8.0).iterations(ITERATIONS)).color(dvec3(0.9, 0.6, 0.35))
}

/// The first point where the ray from `CAMERA` towards `TARGET` meets the
/// bulb's surface (the estimate's zero), to about 1e-16.
fn surface_point() -> Result<(DVec3, DVec3)> {
    let eval = Evaluator::new(&bulb())?;
    let direction = (TARGET - CAMERA).normalize();
    let ray = Ray::new(CAMERA, direction);
    let settings = MarchSettings::default()
        .max_steps(100_000)
        .footprint_base(1e-12);
    let hit = cpu::march(&eval, ray, &settings);
    assert!(hit.hit, "the view ray misses the bulb");
    // Step on in small steps until inside, then bisect the crossing.
    let at = |t: f64| eval.distance(CAMERA + direction * t);
    let (mut outside, mut inside) = (hit.depth, hit.depth);
    while at(inside) > 0.0 {
        outside = inside;
        inside += 1e-9;
    }
    for _ in 0..200 {
        let mid = 0.5 * (outside + inside);
        if mid == outside || mid == inside {
            break;
        }
        if at(mid) > 0.0 {
            outside = mid;
        } else {
            inside = mid;
        }
    }
    Ok((CAMERA + direction * outside, direction))
}

/// The scene at magnification `10^decade`, moved by `shift`.
fn view(point: DVec3, direction: DVec3, decade: i32, shift: DVec3) -> Scene {
    let distance = (point - CAMERA).length() * 10f64.powi(-decade);
    let camera = Camera::look_at(point - direction * distance + shift, point + shift).fov(40.0);
    let speck = sphere(1e-3).translate(dvec3(0.0, 1e3, 0.0));
    Scene::new(bulb().translate(shift).union(speck))
        .with_camera(camera)
        .with_lights([
            Light::directional(KEY_LIGHT).softness(0.06),
            Light::directional(dvec3(-0.6, 0.35, -0.4))
                .color(dvec3(0.6, 0.7, 1.0))
                .intensity(0.3),
        ])
}

/// The key light's direction (the view's first light).
const KEY_LIGHT: DVec3 = DVec3::new(0.5, 0.8, 0.35);

/// Where a ray from `point` towards the key light, starting `offset` along
/// it, first meets the bulb (CPU, F64), if it does: whether the target
/// point is in the shadow of the bulb's structure at that scale.
fn key_light_blocked(point: DVec3, offset: f64) -> Result<Option<f64>> {
    let eval = Evaluator::new(&bulb())?;
    let direction = KEY_LIGHT.normalize();
    let settings = MarchSettings::default()
        .max_steps(100_000)
        .max_distance(10.0)
        .footprint_base(1e-3 * offset);
    let ray = Ray::new(point + direction * offset, direction);
    let hit = cpu::march(&eval, ray, &settings);
    Ok(hit.hit.then_some(hit.depth))
}

fn render(
    scene: &Scene,
    precision: Precision,
    occlusion: bool,
    size: (u32, u32),
) -> Result<RgbaImage> {
    let options = RenderOptions::default()
        .quality(Quality::production().precision(precision).max_steps(1024))
        .effects(Effects::default().ambient_occlusion(occlusion));
    Renderer::with_options(scene, &options)?.render(size.0, size.1)
}

/// An image's luma (0 to 255), pixel by pixel.
fn luma(image: &RgbaImage) -> Vec<f64> {
    image
        .pixels()
        .map(|p| 0.299 * f64::from(p[0]) + 0.587 * f64::from(p[1]) + 0.114 * f64::from(p[2]))
        .collect()
}

/// The mean of an image's luma (0 to 255).
fn brightness(image: &RgbaImage) -> f64 {
    let luma = luma(image);
    #[allow(clippy::cast_precision_loss)]
    let n = luma.len() as f64;
    luma.iter().sum::<f64>() / n
}

/// The standard deviation of an image's luma (0 to 255).
fn contrast(image: &RgbaImage) -> f64 {
    let luma = luma(image);
    #[allow(clippy::cast_precision_loss)]
    let n = luma.len() as f64;
    let mean = luma.iter().sum::<f64>() / n;
    (luma.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / n).sqrt()
}

/// The first magnification (as a decade) where a precision breaks: its
/// PSNR against the comparison is below [`BREAK_DB`] or its image is flat.
/// (Further in, a broken precision can agree with itself again: both
/// renders are a flat colour once the camera itself cannot be placed.)
fn breaks_at(psnrs: &[f64], contrasts: &[f64]) -> Option<usize> {
    (0..psnrs.len()).find(|&i| psnrs[i] < BREAK_DB || contrasts[i] < FLAT)
}

fn label(decade: Option<usize>, last: usize) -> String {
    decade.map_or(format!("none up to 1e{last}"), |d| format!("1e{d}"))
}

fn main() -> std::process::ExitCode {
    common::run(|| {
        let size = common::size_arg((160, 120));
        let decades = common::measure::value("--decades")
            .and_then(|d| d.parse().ok())
            .unwrap_or(DECADES);
        let (point, direction) = surface_point()?;
        let device = fractal_sdf::render::devices()?
            .first()
            .map(|d| d.name.clone())
            .unwrap_or_default();
        eprintln!("surface point {point:.17} on {device}");
        let mut rows = Vec::new();
        let mut brightnesses = Vec::new();
        let mut tiles = Vec::new();
        for decade in 0..=decades {
            let here = view(point, direction, decade, DVec3::ZERO);
            let moved = view(point, direction, decade, SHIFT);
            let f32_here = render(&here, Precision::F32, false, size)?;
            let f32_moved = render(&moved, Precision::F32, false, size)?;
            let f64_here = render(&here, Precision::F64, false, size)?;
            let f64_moved = render(&moved, Precision::F64, false, size)?;
            let f64_occluded = render(&here, Precision::F64, true, size)?;
            let row = [
                psnr(&f32_here, &f64_here),
                psnr(&f32_here, &f32_moved),
                psnr(&f64_here, &f64_moved),
                contrast(&f32_here),
                contrast(&f64_here),
            ];
            eprintln!(
                "1e{decade:<2}  F32 vs F64 {:6.1} dB  F32 moved {:6.1} dB  F64 moved {:6.1} dB  contrast {:5.1} {:5.1}",
                row[0], row[1], row[2], row[3], row[4]
            );
            let lit = [brightness(&f64_here), brightness(&f64_occluded)];
            eprintln!(
                "      F64 mean luma {:5.1} without occlusion, {:5.1} with",
                lit[0], lit[1]
            );
            rows.push(row);
            brightnesses.push(lit);
            tiles.push([f32_here, f32_moved, f64_here, f64_moved, f64_occluded]);
        }
        let column = |i: usize| rows.iter().map(|r| r[i]).collect::<Vec<_>>();
        let db = |v: f64| {
            if v.is_finite() {
                format!("{v:.1}")
            } else {
                "∞".into()
            }
        };
        println!(
            "Measured by `cargo run --release --example deep_zoom` at {}x{} on {device}: PSNR in dB (below {BREAK_DB} dB in bold) and luma standard deviation (below {FLAT}, a flat image, in bold).\n",
            size.0, size.1
        );
        println!(
            "| magnification | F32 vs F64 | F32 vs F32 moved | F64 vs F64 moved | F32 contrast | F64 contrast |"
        );
        println!("|---|---:|---:|---:|---:|---:|");
        for (decade, row) in rows.iter().enumerate() {
            let bold = |text: String, broken: bool| {
                if broken { format!("**{text}**") } else { text }
            };
            let mut cells: Vec<String> = row[..3]
                .iter()
                .map(|&v| bold(db(v), v < BREAK_DB))
                .collect();
            cells.extend(row[3..].iter().map(|&c| bold(format!("{c:.1}"), c < FLAT)));
            println!("| 1e{decade} | {} |", cells.join(" | "));
        }
        let last = rows.len() - 1;
        println!(
            "\nFirst magnification where a precision breaks: F32 against F64 {}; F32 against F32 moved {}; F64 against F64 moved {}.",
            label(breaks_at(&column(0), &column(3)), last),
            label(breaks_at(&column(1), &column(3)), last),
            label(breaks_at(&column(2), &column(4)), last)
        );
        println!(
            "\nAmbient occlusion in F64 at each magnification: mean luma (0 to 255) without and with it, and their ratio.\n"
        );
        println!("| magnification | without occlusion | with occlusion | ratio |");
        println!("|---|---:|---:|---:|");
        for (decade, [off, on]) in brightnesses.iter().enumerate() {
            println!("| 1e{decade} | {off:.1} | {on:.1} | {:.2} |", on / off);
        }
        println!(
            "\nShadow rays from the target point towards the key light, starting that far along it:\n"
        );
        for exponent in [2, 4, 6, 8, 9, 10, 11, 12] {
            let offset = 10f64.powi(-exponent);
            match key_light_blocked(point, offset)? {
                Some(at) => println!("- from 1e-{exponent}: blocked {at:.2e} further on"),
                None => println!("- from 1e-{exponent}: visible"),
            }
        }
        let sheet = common::sheet::contact_sheet(&tiles, size);
        fractal_sdf::output::save_png(&sheet, "out/deep_zoom.png")?;
        eprintln!("wrote out/deep_zoom.png");
        Ok(())
    })
}
