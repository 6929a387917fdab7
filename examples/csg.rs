//! Renders the gallery's `csg` scene to `out/csg.png`.
//!
//! `cargo run --release --example csg [-- --size 1280x960]`

mod common;

fn main() -> std::process::ExitCode {
    common::run(|| {
        let scene = fractal_sdf::gallery::csg();
        let size = common::size_arg((800, 600));
        common::render_to_png("csg", &scene, &common::gallery_options(), size)
    })
}
