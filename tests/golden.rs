//! Golden renders: every gallery scene at 96×64 compared with the committed
//! reference images in `tests/golden/` (PSNR ≥ 40 dB). After an intended
//! change to shading or a scene, regenerate them with `make golden`
//! (`UPDATE_GOLDEN=1 cargo test --test golden`) and look at the new images.

mod gpu;

use std::path::PathBuf;

use fractal_sdf::metrics::psnr;
use fractal_sdf::prelude::*;
use fractal_sdf::render::Renderer;

const SIZE: (u32, u32) = (96, 64);
const MIN_PSNR: f64 = 40.0;

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("{name}.png"))
}

#[test]
fn gallery_renders_match_the_golden_images() {
    if gpu::device().is_none() {
        return;
    }
    let update = std::env::var_os("UPDATE_GOLDEN").is_some();
    let mut report = Vec::new();
    let mut failures = Vec::new();
    for (name, scene) in fractal_sdf::gallery::all() {
        let mut renderer = Renderer::new(&scene, Quality::preview()).unwrap();
        let image = renderer.render(SIZE.0, SIZE.1).unwrap();
        if update {
            fractal_sdf::output::save_png(&image, path(name)).unwrap();
            continue;
        }
        let golden = image::open(path(name))
            .unwrap_or_else(|e| panic!("{name}: {e} (run `make golden`)"))
            .to_rgba8();
        let db = psnr(&image, &golden);
        report.push(format!("{name}: {db:.1} dB"));
        if db < MIN_PSNR {
            gpu::save(&format!("golden_{name}_actual"), &image);
            failures.push(format!("{name}: PSNR {db:.1} dB < {MIN_PSNR} dB"));
        }
    }
    eprintln!("{}", report.join("\n"));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn golden_images_are_not_blank() {
    // Guards the references themselves: each has a lit subject, not a flat
    // background or a black frame.
    for (name, _) in fractal_sdf::gallery::all() {
        let Ok(golden) = image::open(path(name)) else {
            continue;
        };
        let img = golden.to_rgba8();
        let luma: Vec<f64> = img
            .pixels()
            .map(|p| 0.299 * f64::from(p[0]) + 0.587 * f64::from(p[1]) + 0.114 * f64::from(p[2]))
            .collect();
        #[allow(clippy::cast_precision_loss)]
        let mean = luma.iter().sum::<f64>() / luma.len() as f64;
        let (lo, hi) = luma
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), &l| (lo.min(l), hi.max(l)));
        assert!(mean > 30.0, "{name}: too dark (mean luma {mean:.0})");
        assert!(hi - lo > 60.0, "{name}: no contrast ({lo:.0}..{hi:.0})");
    }
}
