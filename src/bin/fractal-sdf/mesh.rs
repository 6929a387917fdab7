//! `fractal-sdf mesh` and `fractal-sdf volume`: a scene's surface as a
//! mesh file, its signed distances as a volume.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use fractal_sdf::mesh::{self, Aabb, GridOptions, MeshFormat, Progress, Sampler, Stage};
use fractal_sdf::prelude::*;
use fractal_sdf::render::DeviceSelector;
use indicatif::{ProgressBar, ProgressStyle};

use super::{Outcome, load_scene, parse_sets, usage};
use fractal_sdf::ir::CompiledScene;
use fractal_sdf::quality::Precision;

/// What `mesh` and `volume` take: the scene and the grid.
#[derive(Args)]
pub struct GridArgs {
    #[command(flatten)]
    scene: super::SceneSource,
    /// Cells along the box's longest side (1..=4096).
    #[arg(long, default_value_t = 256)]
    resolution: u32,
    /// The box to sample, `MINX,MINY,MINZ,MAXX,MAXY,MAXZ` (default: the
    /// scene's bound, tightened to its surface; required for scenes with a
    /// plane or an unlimited repetition).
    #[arg(long, value_name = "BOX", allow_hyphen_values = true)]
    bounds: Option<String>,
    /// Compute distances on the CPU reference instead of an OpenCL device.
    #[arg(long, conflicts_with_all = ["device", "backend"])]
    cpu: bool,
    /// The device backend that computes distances: opencl (default), or
    /// wgpu (the scene's WGSL through wgpu, in single precision).
    #[arg(long, value_enum, conflicts_with = "device")]
    backend: Option<super::Backend>,
    /// A substring of the OpenCL device's name (default: automatic).
    #[arg(long)]
    device: Option<String>,
    /// Compute in double precision.
    #[arg(long)]
    f64: bool,
    /// Set a dynamic parameter: NAME=VALUE (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
}

#[derive(Args)]
pub struct MeshArgs {
    #[command(flatten)]
    grid: GridArgs,
    /// The mesh file to write: `.stl` (binary), `.ply` (binary, with
    /// normals and colours) or `.obj` (with normals and colours).
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Keep Surface Nets' averaged vertices instead of fitting them to the
    /// surface's tangent planes (cheaper; rounds edges and corners).
    #[arg(long)]
    smooth: bool,
}

#[derive(Args)]
pub struct VolumeArgs {
    #[command(flatten)]
    grid: GridArgs,
    /// The NRRD file of signed distances to write (raw little-endian f32,
    /// negative inside), clamped to ±3 sample spacings around the surface:
    /// far from it a fractal's estimate is no distance and an inside-only
    /// shape gives only a sign.
    #[arg(short, long, value_name = "FILE", required_unless_present = "slices")]
    output: Option<PathBuf>,
    /// A directory for one PNG per z slice: white inside, black outside.
    #[arg(long, value_name = "DIR")]
    slices: Option<PathBuf>,
}

fn parse_box(text: &str) -> Outcome<Aabb> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| usage(format!("--bounds `{text}`: expected six numbers")))?;
    match values[..] {
        [x0, y0, z0, x1, y1, z1] => Ok(Aabb::new(dvec3(x0, y0, z0), dvec3(x1, y1, z1))),
        _ => Err(usage(format!(
            "--bounds `{text}`: expected six numbers MINX,MINY,MINZ,MAXX,MAXY,MAXZ, got {}",
            values.len()
        ))),
    }
}

impl GridArgs {
    fn settle(&self) -> Outcome<(CompiledScene, GridOptions, String)> {
        let file = load_scene(&self.scene)?;
        let scene = file.scene.compile()?;
        let sampler = if self.cpu {
            Sampler::Cpu
        } else if self.backend == Some(super::Backend::Wgpu) {
            if self.f64 {
                return Err(usage(
                    "--f64 needs the OpenCL backend or --cpu: WGSL has single precision only",
                ));
            }
            Sampler::Wgpu
        } else {
            Sampler::Device(
                self.device
                    .as_deref()
                    .map_or_else(DeviceSelector::auto, DeviceSelector::device),
            )
        };
        let on = match &sampler {
            Sampler::Cpu => "the CPU".to_string(),
            Sampler::Device(selector) => selector.resolve()?.label(),
            Sampler::Wgpu => "the wgpu adapter".to_string(),
            other => format!("{other:?}"),
        };
        let mut options = GridOptions::default()
            .resolution(self.resolution)
            .sampler(sampler)
            .precision(if self.f64 {
                Precision::F64
            } else {
                Precision::F32
            });
        if let Some(text) = &self.bounds {
            options = options.bounds(parse_box(text)?);
        }
        for (name, value) in parse_sets(&self.set)? {
            options = options.param(name, value);
        }
        Ok((scene, options, on))
    }
}

/// A bar that follows the extraction's stages.
fn bar() -> (ProgressBar, impl FnMut(Progress)) {
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{msg:>10} [{bar:40}] {pos}/{len} {elapsed}")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    let handle = bar.clone();
    let update = move |p: Progress| {
        handle.set_message(match p.stage {
            Stage::Bounds => "bounds",
            Stage::Culling => "culling",
            Stage::Sampling => "sampling",
            Stage::Sharpening => "fitting",
            Stage::Shading => "colouring",
            _ => "meshing",
        });
        handle.set_length(p.total);
        handle.set_position(p.done);
    };
    (bar, update)
}

pub fn mesh(args: &MeshArgs) -> Outcome {
    MeshFormat::from_path(&args.output)?;
    let (scene, options, on) = args.grid.settle()?;
    let options = options.sharp(!args.smooth);
    let start = Instant::now();
    let (bar, mut update) = bar();
    let mesh = mesh::extract_with_progress(&scene, &options, &mut update);
    bar.finish_and_clear();
    let mesh = mesh?;
    mesh.write(&args.output)?;
    let topology = mesh.topology();
    let duplicates = mesh.duplicate_positions();
    let shape = if topology.is_closed_manifold() && duplicates == 0 {
        "closed 2-manifold, every vertex at its own position".to_string()
    } else {
        format!(
            "{} boundary, {} non-manifold, {} misoriented of {} edges, {duplicates} vertices at \
             a shared position",
            topology.boundary_edges,
            topology.non_manifold_edges,
            topology.misoriented_edges,
            topology.edges
        )
    };
    let [x, y, z] = mesh.stats.cells;
    println!(
        "{}: {} triangles, {} vertices, {shape}; {x}x{y}x{z} cells of {:.3e}, {} of {} blocks sampled, {:.2} s on {on}",
        args.output.display(),
        mesh.triangles.len(),
        mesh.positions.len(),
        mesh.voxel_size,
        mesh.stats.blocks_sampled,
        mesh.stats.blocks,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

pub fn volume(args: &VolumeArgs) -> Outcome {
    let (scene, options, on) = args.grid.settle()?;
    let start = Instant::now();
    let (bar, mut update) = bar();
    let volume = mesh::sample_volume_with_progress(&scene, &options, &mut update);
    bar.finish_and_clear();
    let volume = volume?;
    let [x, y, z] = volume.dims;
    let inside = volume.distances.iter().filter(|d| **d < 0.0).count();
    if let Some(path) = &args.output {
        volume.write_nrrd(path)?;
        println!("{}: {x}x{y}x{z} signed distances", path.display());
    }
    if let Some(dir) = &args.slices {
        let files = volume.write_slices(dir)?;
        println!("{}: {} slices of {x}x{y}", dir.display(), files.len());
    }
    println!(
        "  spacing {:.3e} from {}, {inside} samples inside, {:.2} s on {on}",
        volume.spacing,
        volume.origin,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
