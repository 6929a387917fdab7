//! The gallery's `keyframes` scene at six moments of its four seconds:
//! every track (the camera's position, field of view and roll, the
//! Mandelbulb's `power`, the cut's offset) set from its keyframes, each
//! frame written to `out/keyframes/t_SECONDS.png` and all six side by side
//! to `out/keyframes.png`.
//!
//! `cargo run --release --example keyframes [-- --size 320x240]`

mod common;

use fractal_sdf::image::{RgbaImage, imageops};
use fractal_sdf::render::Renderer;

fn main() -> std::process::ExitCode {
    common::run(|| {
        let (w, h) = common::size_arg((320, 240));
        let file = fractal_sdf::gallery::file("keyframes").expect("a gallery scene");
        let path = file.path.clone().expect("the scene's camera path");
        let mut options = common::gallery_options();
        options.quality = options.quality.supersampling(1);
        let mut renderer = Renderer::with_options(&file.scene, &options)?;
        let base = file.scene.camera;
        let mut sheet = RgbaImage::new(3 * w, 2 * h);
        for (i, time) in [0.0, 0.8, 1.6, 2.4, 3.2, 4.0].into_iter().enumerate() {
            renderer.set_camera(path.camera_at(path.start() + time, &base))?;
            for motion in &file.motions {
                for (name, value) in motion.values(time) {
                    renderer.set_param(&name, value)?;
                }
            }
            let image = renderer.render(w, h)?;
            let target = format!("out/keyframes/t_{time:.1}.png");
            fractal_sdf::output::save_png(&image, &target)?;
            println!("{target}");
            #[allow(clippy::cast_possible_truncation)]
            let (x, y) = ((i % 3) as u32 * w, (i / 3) as u32 * h);
            imageops::replace(&mut sheet, &image, i64::from(x), i64::from(y));
        }
        fractal_sdf::output::save_png(&sheet, "out/keyframes.png")?;
        println!("out/keyframes.png");
        Ok(())
    })
}
