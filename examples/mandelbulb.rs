//! Renders the gallery's `mandelbulb` scene to `out/mandelbulb.png`.
//!
//! `cargo run --release --example mandelbulb [-- --size 1280x960]`

mod common;

fn main() -> std::process::ExitCode {
    common::run(|| {
        let scene = fractal_sdf::gallery::mandelbulb();
        let size = common::size_arg((800, 600));
        common::render_to_png("mandelbulb", &scene, &common::gallery_options(), size)
    })
}
