//! Renders every gallery scene to `out/NAME.png`.
//!
//! `cargo run --release --example gallery [-- --size 640x480]`

mod common;

fn main() -> std::process::ExitCode {
    common::run(|| {
        let size = common::size_arg((640, 480));
        let options = common::gallery_options();
        for (name, scene) in fractal_sdf::gallery::all() {
            common::render_to_png(name, &scene, &options, size)?;
        }
        Ok(())
    })
}
