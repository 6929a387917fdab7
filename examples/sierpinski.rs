//! Renders the gallery's `sierpinski` scene to `out/sierpinski.png`.
//!
//! `cargo run --release --example sierpinski [-- --size 1280x960]`

mod common;

fn main() -> std::process::ExitCode {
    common::run(|| {
        let scene = fractal_sdf::gallery::sierpinski_tetrahedron();
        let size = common::size_arg((800, 600));
        common::render_to_png("sierpinski", &scene, &common::gallery_options(), size)
    })
}
