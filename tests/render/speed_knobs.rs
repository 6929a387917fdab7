//! The knobs that trade accuracy for speed beyond the march's own:
//! rendering fewer pixels (`resolution_scale`) and relaxed math
//! (`fast_math`).

use crate::gpu;

use fractal_sdf::gallery;
use fractal_sdf::metrics::psnr;
use fractal_sdf::prelude::*;
use fractal_sdf::render::{Frame, Renderer};

fn render(scene: &Scene, quality: Quality, (w, h): (u32, u32)) -> (Frame, Renderer) {
    let mut renderer =
        Renderer::with_options(scene, &gpu::options(quality, Effects::default())).unwrap();
    let frame = renderer.render_with_aovs(w, h).unwrap();
    (frame, renderer)
}

fn evaluations(frame: &Frame) -> u64 {
    frame.evaluations.iter().map(|&e| u64::from(e)).sum()
}

#[test]
fn a_resolution_scale_renders_fewer_pixels_of_the_same_image() {
    let Some(_) = gpu::device() else { return };
    let scene = gallery::by_name("csg").unwrap();
    // Sizes that the scale divides and sizes it does not.
    for size in [(96, 72), (97, 71)] {
        let full_quality = gpu::plain(Quality::preview());
        let (full, _) = render(&scene, full_quality, size);
        let (half, mut renderer) = render(&scene, full_quality.resolution_scale(2), size);
        gpu::save(&format!("scale2_{}x{}", size.0, size.1), &half.image);
        assert_eq!(half.image.dimensions(), size);
        assert_eq!(half.depth.len(), (size.0 * size.1) as usize);
        // About a quarter of the cost: one pixel in four is rendered.
        let ratio = evaluations(&half) as f64 / evaluations(&full) as f64;
        assert!((0.15..0.4).contains(&ratio), "{size:?}: {ratio}");
        // The same picture, softer: measured 23.9 and 24.3 dB on PoCL at
        // these small sizes (each rendered pixel spans more of the scene).
        let db = psnr(&full.image, &half.image);
        eprintln!("{size:?}: {db:.1} dB, cost ratio {ratio:.3}");
        assert!(db > 20.0, "{size:?}: {db} dB");
        // A plain render scales the same way as the frame's image.
        let image = renderer.render(size.0, size.1).unwrap();
        assert_eq!(image, half.image, "{size:?}");
        // Hit masks agree but for silhouettes: the nearest rendered pixel.
        let differ = full
            .hit
            .iter()
            .zip(&half.hit)
            .filter(|(a, b)| a != b)
            .count();
        assert!(
            differ * 10 < full.hit.len(),
            "{size:?}: {differ} hits differ"
        );
    }
}

/// Switching back from a resolution scale renders every pixel again: the
/// same image as a renderer that never scaled.
#[test]
fn a_scale_of_one_is_the_full_image() {
    let Some(_) = gpu::device() else { return };
    let scene = gallery::by_name("menger").unwrap();
    let full = gpu::plain(Quality::preview());
    let (a, _) = render(&scene, full, (64, 48));
    let (b, mut renderer) = render(&scene, full.resolution_scale(4), (64, 48));
    assert!(a.image != b.image);
    renderer.set_quality(full).unwrap();
    let c = renderer.render(64, 48).unwrap();
    assert!(a.image == c, "switching back to every pixel");
}

#[test]
fn fast_math_is_close_and_off_is_exact() {
    let Some(_) = gpu::device() else { return };
    let scene = gallery::by_name("mandelbulb").unwrap();
    let exact_quality = gpu::plain(Quality::preview());
    let (exact, r) = render(&scene, exact_quality, (80, 60));
    assert!(r.source().source.contains("#pragma OPENCL FP_CONTRACT OFF"));
    let (fast, r) = render(&scene, exact_quality.fast_math(true), (80, 60));
    assert!(!r.source().source.contains("FP_CONTRACT OFF"));
    assert!(r.source().fast_math);
    gpu::save("fast_math", &fast.image);
    // Measured on PoCL: 89.7 dB here, 66 dB at 320 × 240 production.
    let db = psnr(&exact.image, &fast.image);
    eprintln!("fast math: {db:.1} dB");
    assert!(db > 35.0, "{db} dB");
    assert!(fast.image.pixels().any(|p| p.0[0] > 100), "lit");
}
