//! Renders each fractal as ASCII art with the CPU reference: no OpenCL
//! needed. `cargo run --release --example ascii [mandelbulb|menger|julia|sierpinski|all]`

use fractal_sdf::cpu::{Evaluator, MarchSettings, Ray, march};
use fractal_sdf::prelude::*;

fn render(name: &str, geometry: &Node, camera: Camera) -> Result<()> {
    let eval = Evaluator::new(geometry)?;
    let (right, up, forward) = camera.basis()?;
    let (w, h) = (72usize, 32usize);
    let tan = (45f64.to_radians() * 0.5).tan();
    let shades = b" .:-=+*#%@";
    let settings = MarchSettings::default()
        .max_steps(200)
        .max_distance(20.0)
        .footprint_base(1e-3);
    let light = dvec3(0.6, 0.8, 0.4).normalize();
    println!("{name}:");
    for j in 0..h {
        let mut line = String::with_capacity(w);
        for i in 0..w {
            // Terminal cells are about twice as tall as wide.
            let x = (2.0 * (i as f64 + 0.5) / w as f64 - 1.0) * tan * (w as f64 / h as f64) * 0.5;
            let y = (1.0 - 2.0 * (j as f64 + 0.5) / h as f64) * tan;
            let direction = (forward + right * x + up * y).normalize();
            let hit = march(&eval, Ray::new(camera.position, direction), &settings);
            let c = if hit.hit {
                let p = camera.position + direction * hit.depth;
                let lambert = eval.normal(p, 1e-4).dot(light).max(0.0);
                shades[1 + ((0.15 + 0.85 * lambert) * 8.99) as usize]
            } else {
                b' '
            };
            line.push(c as char);
        }
        println!("{line}");
    }
    Ok(())
}

fn main() -> Result<()> {
    let which = std::env::args().nth(1).unwrap_or_else(|| "all".into());
    let cam = Camera::look_at(dvec3(2.0, 1.6, 2.4), dvec3(0.0, 0.0, 0.0));
    let scenes: [(&str, Node); 4] = [
        (
            "mandelbulb",
            mandelbulb(8.0).rotate(DVec3::X, -std::f64::consts::FRAC_PI_2),
        ),
        ("menger", menger(3)),
        ("julia", julia([-0.2, 0.6, 0.2, 0.2])),
        ("sierpinski", sierpinski(5)),
    ];
    for (name, node) in &scenes {
        if which == "all" || which == *name {
            render(name, node, cam)?;
        }
    }
    Ok(())
}
