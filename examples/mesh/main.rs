//! Meshes and volumes, measured: time, triangles and evaluations for each
//! gallery fractal at several resolutions; device against CPU sampling
//! throughput; and accuracy against exact shapes (the distance of vertices
//! to the surface, and the Hausdorff distance to a sphere, a box and a
//! torus) against resolution. Writes `out/menger.stl` and `out/mandelbulb.ply`.
//! With `--volumes`, only the enclosed volume of shapes whose exact volume
//! is known (sphere, box, torus, cylinder, capsule, Menger sponge levels 1
//! to 4) against resolution, with its rate of convergence.
//!
//! `cargo run --release --example mesh [-- --resolutions 128,256,512]`
//! `cargo run --release --example mesh -- --volumes [--resolutions 32,64,128,256]`

mod hausdorff;
mod volumes;

use std::time::Instant;

use fractal_sdf::mesh::{self, Aabb, GridOptions, Sampler};
use fractal_sdf::prelude::*;
use fractal_sdf::render::DeviceSelector;

fn main() -> Result<()> {
    let mut args = pico_args::Arguments::from_env();
    let volume_table = args.contains("--volumes");
    let resolutions: Option<Vec<u32>> = args
        .opt_value_from_fn("--resolutions", |s: &str| {
            s.split(',')
                .map(str::parse)
                .collect::<std::result::Result<Vec<u32>, _>>()
        })
        .expect("--resolutions takes numbers separated by commas");
    if volume_table {
        return volumes::table(&resolutions.unwrap_or_else(|| vec![32, 64, 128, 256]));
    }
    let resolutions = resolutions.unwrap_or_else(|| vec![128, 256, 512]);
    let device = Sampler::Device(DeviceSelector::auto());
    std::fs::create_dir_all("out").ok();

    println!("## Fractals: time, size and evaluations (device sampling, sharp vertices)\n");
    println!(
        "| fractal | resolution | cells | blocks sampled | triangles | closed | non-manifold edges | evaluations | time |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let fractals: [(&str, Node, Option<Aabb>); 4] = [
        (
            "mandelbulb",
            gallery_geometry(&fractal_sdf::gallery::mandelbulb()),
            None,
        ),
        ("menger", menger(4), None),
        (
            "julia",
            gallery_geometry(&fractal_sdf::gallery::quaternion_julia()),
            None,
        ),
        ("sierpinski", sierpinski(7), None),
    ];
    for (name, node, bounds) in &fractals {
        let scene = Scene::new(node.clone()).compile()?;
        for &resolution in &resolutions {
            let mut options = GridOptions::default()
                .resolution(resolution)
                .sampler(device.clone());
            if let Some(b) = bounds {
                options = options.bounds(*b);
            }
            let start = Instant::now();
            let mesh = mesh::extract(&scene, &options)?;
            let seconds = start.elapsed().as_secs_f64();
            let t = mesh.topology();
            let [x, y, z] = mesh.stats.cells;
            println!(
                "| {name} | {resolution} | {x}×{y}×{z} | {} of {} | {} | {} | {} | {:.1} M | {seconds:.2} s |",
                mesh.stats.blocks_sampled,
                mesh.stats.blocks,
                mesh.triangles.len(),
                if t.boundary_edges == 0 && t.misoriented_edges == 0 {
                    "yes"
                } else {
                    "no"
                },
                t.non_manifold_edges,
                mesh.stats.evaluations as f64 / 1e6,
            );
            if resolution == resolutions[resolutions.len() / 2] {
                match *name {
                    "menger" => mesh.write("out/menger.stl")?,
                    "mandelbulb" => mesh.write("out/mandelbulb.ply")?,
                    _ => {}
                }
            }
        }
    }

    println!("\n## Sampling throughput (a dense 256³ volume of each fractal)\n");
    println!("| fractal | device | CPU reference |");
    println!("|---|---|---|");
    for (name, node, _) in &fractals {
        let scene = Scene::new(node.clone()).compile()?;
        let mut rates = Vec::new();
        for sampler in [device.clone(), Sampler::Cpu] {
            let options = GridOptions::default().resolution(255).sampler(sampler);
            // The first volume builds the device's program; time the second.
            mesh::sample_volume(&scene, &options.clone().resolution(15))?;
            let start = Instant::now();
            let volume = mesh::sample_volume(&scene, &options)?;
            let rate = volume.distances.len() as f64 / start.elapsed().as_secs_f64();
            rates.push(format!("{:.1} M points/s", rate / 1e6));
        }
        println!("| {name} | {} | {} |", rates[0], rates[1]);
    }

    println!(
        "\n## Accuracy against exact shapes (voxel units; sharp vertices, then Surface Nets' averages)\n"
    );
    println!(
        "| shape | resolution | max \\|d\\| at vertices | mean \\|d\\| | Hausdorff | Hausdorff, averaged vertices | volume error |"
    );
    println!("|---|---|---|---|---|---|---|");
    let shapes: [Exact; 3] = [
        (
            "sphere r = 1",
            sphere(1.0),
            |p| p.length() - 1.0,
            4.0 / 3.0 * std::f64::consts::PI,
        ),
        (
            "box 1 × 1.4 × 1.8",
            cuboid(dvec3(0.5, 0.7, 0.9)),
            box_distance,
            2.52,
        ),
        (
            "torus 1, 0.3",
            torus(1.0, 0.3),
            |p| (p.x.hypot(p.z) - 1.0).hypot(p.y) - 0.3,
            2.0 * std::f64::consts::PI.powi(2) * 1.0 * 0.09,
        ),
    ];
    for (name, node, exact, volume) in shapes {
        let scene = Scene::new(node).compile()?;
        for resolution in [32, 64, 128, 256] {
            let options = GridOptions::default()
                .resolution(resolution)
                .sampler(device.clone());
            let sharp = mesh::extract(&scene, &options)?;
            let averaged = mesh::extract(&scene, &options.sharp(false))?;
            let h = sharp.voxel_size;
            let d: Vec<f64> = sharp
                .positions
                .iter()
                .map(|p| exact(p.as_dvec3()).abs() / h)
                .collect();
            let max = d.iter().copied().fold(0.0, f64::max);
            let mean = d.iter().sum::<f64>() / d.len() as f64;
            println!(
                "| {name} | {resolution} | {max:.4} | {mean:.5} | {:.3} | {:.3} | {:+.3}% |",
                hausdorff::distance(&sharp, exact, h) / h,
                hausdorff::distance(&averaged, exact, h) / h,
                100.0 * (sharp.volume() - volume) / volume,
            );
        }
    }
    Ok(())
}

/// A shape, its exact distance function and its volume.
type Exact = (&'static str, Node, fn(DVec3) -> f64, f64);

/// A gallery scene's geometry.
fn gallery_geometry(scene: &Scene) -> Node {
    scene
        .geometry
        .clone()
        .expect("gallery scenes have geometry")
}

fn box_distance(p: DVec3) -> f64 {
    let q = p.abs() - dvec3(0.5, 0.7, 0.9);
    q.max(DVec3::ZERO).length() + q.max_element().min(0.0)
}
