//! Renders the gallery's `julia` scene to `out/julia.png`.
//!
//! `cargo run --release --example julia [-- --size 1280x960]`

mod common;

fn main() -> std::process::ExitCode {
    common::run(|| {
        let scene = fractal_sdf::gallery::quaternion_julia();
        let size = common::size_arg((800, 600));
        common::render_to_png("julia", &scene, &common::gallery_options(), size)
    })
}
