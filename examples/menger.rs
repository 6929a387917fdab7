//! Renders the gallery's `menger` scene to `out/menger.png`.
//!
//! `cargo run --release --example menger [-- --size 1280x960]`

mod common;

fn main() -> std::process::ExitCode {
    common::run(|| {
        let scene = fractal_sdf::gallery::menger_sponge();
        let size = common::size_arg((800, 600));
        common::render_to_png("menger", &scene, &common::gallery_options(), size)
    })
}
