//! `--volumes`: the enclosed volume of meshes of shapes whose exact volume
//! is known, against resolution: the relative error and its rate of
//! convergence, with fitted vertices and with Surface Nets' averages.

use fractal_sdf::mesh::{self, GridOptions, Sampler};
use fractal_sdf::prelude::*;

/// A shape and its exact volume.
type Known = (String, Node, f64);

fn shapes() -> Vec<Known> {
    use std::f64::consts::PI;
    let mut out: Vec<Known> = vec![
        ("sphere r = 1".into(), sphere(1.0), 4.0 / 3.0 * PI),
        (
            "box 1 × 1.4 × 1.8".into(),
            cuboid(dvec3(0.5, 0.7, 0.9)),
            2.52,
        ),
        (
            "torus 1, 0.3".into(),
            torus(1.0, 0.3),
            2.0 * PI * PI * 1.0 * 0.3 * 0.3,
        ),
        (
            "cylinder r = 0.6, h = 1.6".into(),
            cylinder(0.6, 0.8),
            PI * 0.36 * 1.6,
        ),
        (
            "capsule r = 0.4, segment 1".into(),
            capsule(dvec3(0.0, -0.5, 0.0), dvec3(0.0, 0.5, 0.0), 0.4),
            PI * 0.16 * (4.0 / 3.0 * 0.4 + 1.0),
        ),
    ];
    // The sponge fills [-1, 1]³: each level keeps 20 of 27 cubes.
    for level in 1..=4 {
        let exact = 8.0 * (20.0f64 / 27.0).powi(level);
        out.push((format!("Menger level {level}"), menger(level as u32), exact));
    }
    out
}

/// Prints the table for `resolutions` (CPU sampling, so the numbers do
/// not depend on a device).
pub fn table(resolutions: &[u32]) -> Result<()> {
    println!("## Volume against the exact volume (CPU sampling)\n");
    println!(
        "| shape | resolution | voxel | volume error, fitted | rate | volume error, averaged | rate |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, node, exact) in shapes() {
        let scene = Scene::new(node).compile()?;
        let mut previous: Option<([f64; 2], f64)> = None;
        for &resolution in resolutions {
            let options = GridOptions::default()
                .resolution(resolution)
                .sampler(Sampler::Cpu);
            let mut errors = [0.0; 2];
            let mut voxel = 0.0;
            for (i, sharp) in [true, false].into_iter().enumerate() {
                let mesh = mesh::extract(&scene, &options.clone().sharp(sharp))?;
                errors[i] = (mesh.volume() - exact) / exact;
                voxel = mesh.voxel_size;
            }
            // The order p in |error| ∝ voxel^p, from the previous row.
            let rate = |i: usize| match previous {
                Some((p, h)) => format!(
                    "{:.2}",
                    (p[i].abs() / errors[i].abs()).ln() / (h / voxel).ln()
                ),
                None => String::new(),
            };
            println!(
                "| {name} | {resolution} | {voxel:.4} | {:+.3}% | {} | {:+.3}% | {} |",
                100.0 * errors[0],
                rate(0),
                100.0 * errors[1],
                rate(1),
            );
            previous = Some((errors, voxel));
        }
    }
    Ok(())
}
