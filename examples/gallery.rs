//! Renders every gallery scene to `out/NAME.png`.
//!
//! `cargo run --release --example gallery [-- --size 640x480]`

mod common;

fn main() -> std::process::ExitCode {
    common::run(|| {
        let size = common::size_arg((640, 480));
        for (name, scene) in fractal_sdf::gallery::all() {
            let mut options = common::gallery_options();
            if let Some(file) = fractal_sdf::gallery::file(name) {
                // Scenes with inside shapes take their scene file's coarser
                // brute-force step: the 2×2 samples average its noise.
                if let Some(quality) = file.quality {
                    options.quality.brute_step = quality.brute_step;
                }
                // And every scene its file's light: `gi` is path traced.
                options.effects = file.effects;
            }
            common::render_to_png(name, &scene, &options, size)?;
        }
        Ok(())
    })
}
