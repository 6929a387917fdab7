//! Meshes and volumes: closed, accurate surfaces on the device and the
//! CPU; sharp box edges; files that independent readers read back; voxel
//! grids whose signs are the CPU reference's; clear errors for bad grids.

mod gpu;
/// The Vulkan device of the crate's own WGSL tests: whether wgpu has an
/// adapter (a failure where the run requires one).
#[cfg(feature = "wgpu")]
#[path = "../src/codegen/wgsl_tests/device.rs"]
#[allow(dead_code)] // `run`, the distance tests' shader runner
mod wgpu_device;

use std::f64::consts::PI;
use std::path::PathBuf;

use fractal_sdf::cpu;
use fractal_sdf::ir::CompiledScene;
use fractal_sdf::mesh::{self, Aabb, GridOptions, Mesh, Sampler, Volume};
use fractal_sdf::prelude::*;
use fractal_sdf::quality::Precision;
use fractal_sdf::render::DeviceSelector;
use fractal_sdf::scene::InsideShape;

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("mesh")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn compiled(node: Node) -> CompiledScene {
    Scene::new(node).compile().unwrap()
}

/// The device sampler, or `None` where no OpenCL platform is installed
/// and none is required (the skip is recorded).
fn device() -> Option<Sampler> {
    gpu::device().map(|_| Sampler::Device(DeviceSelector::auto()))
}

/// The largest `|f(vertex)|` in voxels.
fn worst(mesh: &Mesh, f: impl Fn(DVec3) -> f64) -> f64 {
    mesh.positions
        .iter()
        .map(|p| f(p.as_dvec3()).abs() / mesh.voxel_size)
        .fold(0.0, f64::max)
}

#[test]
fn a_sphere_at_128_is_closed_on_the_surface_and_holds_its_volume() {
    let Some(sampler) = device() else { return };
    let scene = compiled(sphere(1.0));
    let mesh = mesh::extract(&scene, &GridOptions::default().sampler(sampler)).unwrap();
    assert_eq!(mesh.stats.cells, [128, 128, 128]);
    let topology = mesh.topology();
    assert!(topology.is_closed_manifold(), "{topology:?}");
    assert!(
        mesh.triangles.len() > 100_000,
        "{} triangles",
        mesh.triangles.len()
    );
    let off = worst(&mesh, |p| p.length() - 1.0);
    assert!(off < 0.5, "a vertex lies {off} voxels off the sphere");
    let exact = 4.0 / 3.0 * PI;
    let error = (mesh.volume() - exact).abs() / exact;
    assert!(
        error < 0.01,
        "volume {} is {error:.4} off {exact}",
        mesh.volume()
    );
    // Normals point out, along the radius.
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        assert!(n.dot(p.normalize()) > 0.99, "normal {n} at {p}");
    }
    // The octree samples only blocks near the surface.
    assert!(
        mesh.stats.blocks_sampled < mesh.stats.blocks,
        "{:?}",
        mesh.stats
    );
}

#[test]
fn a_box_keeps_its_edges_and_corners() {
    let half = dvec3(0.5, 0.7, 0.9);
    let scene = compiled(cuboid(half));
    for sharp in [true, false] {
        let options = GridOptions::default()
            .resolution(48)
            .sampler(Sampler::Cpu)
            .sharp(sharp);
        let mesh = mesh::extract(&scene, &options).unwrap();
        assert!(mesh.topology().is_closed_manifold());
        let box_distance = |p: DVec3| {
            let q = p.abs() - half;
            q.max(DVec3::ZERO).length() + q.max_element().min(0.0)
        };
        let off = worst(&mesh, box_distance);
        let nearest_corner = [-1.0, 1.0]
            .into_iter()
            .flat_map(|x| [-1.0, 1.0].map(|y| (x, y)))
            .flat_map(|(x, y)| [-1.0, 1.0].map(|z| dvec3(x, y, z) * half))
            .map(|c| {
                mesh.positions
                    .iter()
                    .map(|p| (p.as_dvec3() - c).length() / mesh.voxel_size)
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max);
        if sharp {
            // The fit puts vertices on the faces, the edges and the corners.
            assert!(off < 0.1, "a vertex lies {off} voxels off the box");
            assert!(
                nearest_corner < 0.25,
                "a corner is {nearest_corner} voxels from any vertex"
            );
        } else {
            // Surface Nets' averages cut corners: what the fit is for.
            assert!(off > 0.2 && nearest_corner > 0.3, "{off} {nearest_corner}");
        }
    }
}

/// `Sampler::Wgpu`: the scene's WGSL `DE` through wgpu samples the mesh
/// the CPU reference samples (in single precision both), its vertex
/// colours from the WGSL `DE_shade`, and refuses double precision.
#[cfg(feature = "wgpu")]
#[test]
fn the_wgpu_backend_and_the_cpu_give_the_same_mesh() {
    if wgpu_device::device().is_none() {
        return;
    }
    let node = sphere(0.6)
        .color(dvec3(0.9, 0.2, 0.1))
        .smooth_union(
            cuboid(dvec3(0.4, 0.3, 0.5))
                .color(dvec3(0.1, 0.3, 0.9))
                .translate(dvec3(0.5, 0.0, 0.0)),
            0.1,
        )
        .union(mandelbulb(8.0).scale(0.4).translate(dvec3(-0.7, 0.2, 0.0)));
    let scene = compiled(node);
    let options = GridOptions::default().resolution(64);
    let on_wgpu = mesh::extract(&scene, &options.clone().sampler(Sampler::Wgpu)).unwrap();
    let on_cpu = mesh::extract(&scene, &options.clone().sampler(Sampler::Cpu)).unwrap();
    let near = |a: f64, b: f64, tolerance: f64| (a - b).abs() <= tolerance * b.abs();
    #[allow(clippy::cast_precision_loss)]
    let count = |m: &Mesh| m.triangles.len() as f64;
    assert!(
        near(count(&on_wgpu), count(&on_cpu), 5e-3),
        "{} vs {}",
        count(&on_wgpu),
        count(&on_cpu)
    );
    assert!(near(on_wgpu.volume(), on_cpu.volume(), 1e-3));
    assert!(near(on_wgpu.area(), on_cpu.area(), 2e-3));
    assert!(on_wgpu.topology().is_closed_manifold());
    // The colours: red at the ball's top, blue on the box's far face.
    let colour_at = |m: &Mesh, at: DVec3| {
        let i = m
            .positions
            .iter()
            .enumerate()
            .min_by(|a, b| {
                let d = |p: &glam::Vec3| (p.as_dvec3() - at).length();
                d(a.1).total_cmp(&d(b.1))
            })
            .unwrap()
            .0;
        m.colors[i]
    };
    for mesh in [&on_wgpu, &on_cpu] {
        let red = colour_at(mesh, dvec3(0.0, 0.7, 0.0));
        let blue = colour_at(mesh, dvec3(1.0, 0.0, 0.0));
        assert!(u16::from(red[0]) > u16::from(red[2]) + 100, "{red:?}");
        assert!(u16::from(blue[2]) > u16::from(blue[0]) + 100, "{blue:?}");
    }
    let refused = mesh::extract(
        &scene,
        &options.sampler(Sampler::Wgpu).precision(Precision::F64),
    );
    assert!(
        matches!(&refused, Err(fractal_sdf::Error::Unsupported { what, .. }) if what.contains("double")),
        "{refused:?}"
    );
}

#[test]
fn the_device_and_the_cpu_give_the_same_mesh() {
    let Some(sampler) = device() else { return };
    let node = sphere(0.6)
        .smooth_union(
            cuboid(dvec3(0.4, 0.3, 0.5)).translate(dvec3(0.5, 0.0, 0.0)),
            0.1,
        )
        .union(torus(0.5, 0.15).translate(dvec3(-0.6, 0.2, 0.0)));
    let scene = compiled(node);
    let options = GridOptions::default().resolution(64);
    let on_device = mesh::extract(&scene, &options.clone().sampler(sampler)).unwrap();
    let on_cpu = mesh::extract(&scene, &options.sampler(Sampler::Cpu)).unwrap();
    // Both round to f32, in different orders: a sample within rounding
    // of the surface may take the other sign, and nothing more.
    let near = |a: f64, b: f64, tolerance: f64| (a - b).abs() <= tolerance * b.abs();
    #[allow(clippy::cast_precision_loss)]
    let count = |m: &Mesh| m.triangles.len() as f64;
    assert!(
        near(count(&on_device), count(&on_cpu), 2e-3),
        "{} vs {}",
        count(&on_device),
        count(&on_cpu)
    );
    assert!(near(on_device.volume(), on_cpu.volume(), 1e-4));
    assert!(near(on_device.area(), on_cpu.area(), 1e-3));
    assert!(on_device.topology().is_closed_manifold());
    assert!(on_cpu.topology().is_closed_manifold());
}

#[test]
fn fractals_mesh_closed_and_coloured() {
    let Some(sampler) = device() else { return };
    for node in [menger(3).color(dvec3(0.9, 0.3, 0.1)), mandelbulb(8.0)] {
        let scene = compiled(node);
        let options = GridOptions::default()
            .resolution(48)
            .sampler(sampler.clone());
        let mesh = mesh::extract(&scene, &options).unwrap();
        let topology = mesh.topology();
        assert!(topology.is_closed_manifold(), "{topology:?}");
        assert_eq!(mesh.duplicate_positions(), 0);
        assert!(mesh.volume() > 0.0);
        assert_eq!(mesh.colors.len(), mesh.positions.len());
        let eval = cpu::Evaluator::from_compiled(&scene);
        let expected = eval
            .sample::<f64>(mesh.positions[0].as_dvec3().into())
            .color;
        let expected = DVec3::from(expected)
            .to_array()
            .map(|c| (c.powf(1.0 / 2.2) * 255.0).round());
        let got = mesh.colors[0].map(f64::from);
        for (g, e) in got.iter().zip(expected) {
            assert!(
                (g - e).abs() <= 1.0,
                "colour {got:?}, expected {expected:?}"
            );
        }
    }
}

/// An orbit trap's palette reaches the mesh: each vertex takes the colour
/// the CPU reference paints there, and the colours vary over the surface.
#[test]
fn orbit_trap_colours_reach_the_vertices() {
    use fractal_sdf::scene::{OrbitColoring, Palette, Trap};
    let Some(sampler) = device() else { return };
    let node = mandelbulb(8.0).orbit_coloring(
        OrbitColoring::new(Trap::plane([0.0, 0.0, 1.0], 0.0), Palette::viridis()).range(0.0, 0.8),
    );
    let scene = compiled(node);
    let options = GridOptions::default().resolution(48).sampler(sampler);
    let mesh = mesh::extract(&scene, &options).unwrap();
    assert_eq!(mesh.colors.len(), mesh.positions.len());
    let eval = cpu::Evaluator::from_compiled(&scene);
    // The device samples in single precision, the reference in double.
    // Vertices lie on the surface, where orbits are longest and rounding
    // grows most: measured, 20 of 11,618 vertices are more than 1 level
    // of 255 off (most by 2 or 3), 6 by more than 4, where an iterate
    // lies within rounding of the bailout and one side counts it.
    let (mut off, mut far_off) = (0, 0);
    for (p, got) in mesh.positions.iter().zip(&mesh.colors) {
        let expected = DVec3::from(eval.sample::<f64>(p.as_dvec3().into()).color)
            .to_array()
            .map(|c| (c.powf(1.0 / 2.2) * 255.0).round());
        let worst = got
            .iter()
            .zip(expected)
            .map(|(&g, e)| (f64::from(g) - e).abs())
            .fold(0.0, f64::max);
        off += usize::from(worst > 1.0);
        far_off += usize::from(worst > 4.0);
    }
    let n = mesh.positions.len();
    assert!(
        off * 200 <= n,
        "{off} of {n} vertices more than 1 level off"
    );
    assert!(
        far_off * 1000 <= n,
        "{far_off} of {n} vertices more than 4 levels off"
    );
    let distinct: std::collections::HashSet<[u8; 3]> = mesh.colors.iter().copied().collect();
    assert!(distinct.len() > 200, "{} distinct colours", distinct.len());
}

#[test]
fn a_box_that_cuts_the_scene_closes_the_mesh() {
    // A floor has no bound: the box is required, and the cut is capped.
    let scene = compiled(plane(DVec3::Y, 0.0).union(sphere(0.5).translate(dvec3(0.0, 0.5, 0.0))));
    let err = mesh::extract(&scene, &GridOptions::default().sampler(Sampler::Cpu)).unwrap_err();
    assert!(err.to_string().contains("no bound"), "{err}");
    let bounds = Aabb::new(dvec3(-1.0, -0.5, -1.0), dvec3(1.0, 1.5, 1.0));
    let options = GridOptions::default()
        .bounds(bounds)
        .resolution(32)
        .sampler(Sampler::Cpu);
    let mesh = mesh::extract(&scene, &options).unwrap();
    assert!(
        mesh.topology().is_closed_manifold(),
        "{:?}",
        mesh.topology()
    );
    // The cap under the slab faces down: its vertices keep the closed
    // field's normal, not the floor's.
    let h = mesh.voxel_size as f32;
    let mut capped = 0;
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        if p.y < -0.5 + 1.5 * h && p.x.abs() < 0.8 && p.z.abs() < 0.8 {
            assert!(n.y < -0.9, "normal {n} at {p} on the cap");
            capped += 1;
        }
    }
    assert!(capped > 100, "{capped} cap vertices");
    // A slab of 2 × 0.5 × 2 under the floor, less a voxel at the cut, and
    // most of the sphere above it.
    let slab = 2.0 * 0.5 * 2.0;
    assert!(
        mesh.volume() > 0.8 * slab && mesh.volume() < slab + 0.6,
        "{}",
        mesh.volume()
    );
}

#[test]
fn bad_grids_say_what_is_wrong() {
    let scene = compiled(sphere(1.0));
    let cpu = GridOptions::default().sampler(Sampler::Cpu);
    let cases = [
        (cpu.clone().resolution(0), "grid resolution"),
        (cpu.clone().resolution(1 << 20), "1..=4096"),
        (
            cpu.clone().bounds(Aabb::new(DVec3::ONE, DVec3::ZERO)),
            "min < max",
        ),
        (
            cpu.clone()
                .bounds(Aabb::new(DVec3::ZERO, dvec3(1.0, f64::NAN, 1.0))),
            "finite",
        ),
        (
            cpu.clone()
                .bounds(Aabb::new(DVec3::splat(-1e308), DVec3::splat(1e308))),
            "finite",
        ),
        // Regression: a box 1e-300 wide collapsed to one point's samples.
        (
            cpu.clone()
                .bounds(Aabb::new(DVec3::ZERO, DVec3::splat(1e-300))),
            "narrowest axis",
        ),
        (
            cpu.clone()
                .bounds(Aabb::new(dvec3(1e6, 0.0, 0.0), dvec3(1e6 + 1e-3, 1.0, 1.0))),
            "narrowest axis",
        ),
    ];
    for (options, says) in cases {
        let err = mesh::extract(&scene, &options).unwrap_err();
        assert!(matches!(err, Error::Invalid { .. }), "{err:?}");
        assert!(err.to_string().contains(says), "{err} should say {says}");
        let err = mesh::sample_volume(&scene, &options).unwrap_err();
        assert!(err.to_string().contains(says), "{err} should say {says}");
    }
    let mesh = mesh::extract(&scene, &cpu.clone().resolution(8)).unwrap();
    let err = mesh.write(scratch("bad").join("out.gltf")).unwrap_err();
    assert!(err.to_string().contains(".stl, .ply or .obj"), "{err}");
    let err = mesh::sample_volume(&scene, &cpu.resolution(4096)).unwrap_err();
    assert!(err.to_string().contains("lower the resolution"), "{err}");
}

#[test]
fn stl_ply_and_obj_read_back_with_independent_readers() {
    let scene = compiled(
        sphere(0.5)
            .color(dvec3(0.2, 0.6, 1.0))
            .union(cuboid(dvec3(0.3, 0.3, 0.3)).translate(dvec3(0.6, 0.0, 0.0))),
    );
    let options = GridOptions::default().resolution(24).sampler(Sampler::Cpu);
    let mesh = mesh::extract(&scene, &options).unwrap();
    let dir = scratch("files");

    // STL: a triangle soup; the reader welds equal corners again.
    mesh.write(dir.join("mesh.stl")).unwrap();
    let mut file = std::fs::File::open(dir.join("mesh.stl")).unwrap();
    let stl = stl_io::read_stl(&mut file).unwrap();
    assert_eq!(stl.faces.len(), mesh.triangles.len());
    assert_eq!(stl.vertices.len(), mesh.positions.len());
    for (face, t) in stl.faces.iter().zip(&mesh.triangles) {
        for (i, v) in face.vertices.iter().zip(t) {
            let read = stl.vertices[*i];
            let p = mesh.positions[*v as usize];
            assert_eq!([read[0], read[1], read[2]], p.to_array());
        }
    }

    // PLY: positions, normals and colours.
    mesh.write(dir.join("mesh.ply")).unwrap();
    let mut file = std::fs::File::open(dir.join("mesh.ply")).unwrap();
    let parser = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new();
    let ply = parser.read_ply(&mut file).unwrap();
    let vertices = &ply.payload["vertex"];
    let faces = &ply.payload["face"];
    assert_eq!(vertices.len(), mesh.positions.len());
    assert_eq!(faces.len(), mesh.triangles.len());
    use ply_rs_bw::ply::Property;
    let float = |e: &ply_rs_bw::ply::DefaultElement, k: &str| match e[k] {
        Property::Float(v) => v,
        ref other => panic!("{k} is {other:?}"),
    };
    let byte = |e: &ply_rs_bw::ply::DefaultElement, k: &str| match e[k] {
        Property::UChar(v) => v,
        ref other => panic!("{k} is {other:?}"),
    };
    for (i, v) in vertices.iter().enumerate() {
        assert_eq!(
            [float(v, "x"), float(v, "y"), float(v, "z")],
            mesh.positions[i].to_array()
        );
        assert_eq!(
            [float(v, "nx"), float(v, "ny"), float(v, "nz")],
            mesh.normals[i].to_array()
        );
        assert_eq!(
            [byte(v, "red"), byte(v, "green"), byte(v, "blue")],
            mesh.colors[i]
        );
    }
    for (f, t) in faces.iter().zip(&mesh.triangles) {
        match &f["vertex_indices"] {
            Property::ListInt(list) => {
                assert_eq!(list, &t.map(|i| i32::try_from(i).unwrap()).to_vec());
            }
            other => panic!("vertex_indices is {other:?}"),
        }
    }
    // The blue sphere's colour reached its vertices.
    assert!(mesh.colors.iter().any(|c| c[2] > 200 && c[0] < 150));

    // OBJ: positions, colours and normals, indices from 1.
    mesh.write(dir.join("mesh.obj")).unwrap();
    // The reader numbers vertices in the order faces first use them.
    let (models, _) = tobj::load_obj(dir.join("mesh.obj"), &tobj::LoadOptions::default()).unwrap();
    let obj = &models[0].mesh;
    assert_eq!(obj.positions.len(), 3 * mesh.positions.len());
    assert_eq!(obj.indices.len(), 3 * mesh.triangles.len());
    assert_eq!(obj.vertex_color.len(), 3 * mesh.positions.len());
    let at = |list: &[f32], i: u32| [0, 1, 2].map(|k| list[3 * i as usize + k]);
    for (read, t) in obj.indices.chunks(3).zip(&mesh.triangles) {
        for (r, v) in read.iter().zip(t) {
            assert_eq!(
                at(&obj.positions, *r),
                mesh.positions[*v as usize].to_array()
            );
            let color = at(&obj.vertex_color, *r).map(|c| (c * 255.0).round());
            assert_eq!(color, mesh.colors[*v as usize].map(f32::from));
        }
    }
    // Without normals, OBJ faces name positions only.
    let mut bare = mesh.clone();
    bare.normals.clear();
    bare.write(dir.join("bare.obj")).unwrap();
    let (models, _) = tobj::load_obj(dir.join("bare.obj"), &tobj::LoadOptions::default()).unwrap();
    assert_eq!(models[0].mesh.indices.len(), 3 * mesh.triangles.len());
    assert!(models[0].mesh.normals.is_empty());
    std::fs::remove_file(dir.join("bare.obj")).unwrap();
    // No temporary file is left beside them.
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 3, "{names:?}");
}

/// Reads an NRRD file as `write_nrrd` writes it: the header's fields, then
/// raw little-endian `f32`.
fn read_nrrd(path: &std::path::Path) -> (Vec<u32>, Vec<f32>) {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    assert!(header.starts_with("NRRD0004\n"));
    assert!(header.contains("type: float\n") && header.contains("encoding: raw\n"));
    assert!(header.contains("endian: little\n"));
    let sizes: Vec<u32> = header
        .lines()
        .find_map(|l| l.strip_prefix("sizes: "))
        .unwrap()
        .split(' ')
        .map(|s| s.parse().unwrap())
        .collect();
    let values = bytes[end..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    (sizes, values)
}

#[test]
fn a_volume_has_the_cpu_references_signs_and_reads_back() {
    let Some(device) = gpu::device() else { return };
    if !gpu::fp64(&device) {
        return;
    }
    let node = mandelbulb(8.0).union(sphere(0.3).translate(dvec3(1.2, 0.0, 0.0)));
    let scene = compiled(node);
    let options = GridOptions::default()
        .resolution(40)
        .precision(Precision::F64)
        .sampler(Sampler::Device(DeviceSelector::auto()));
    let volume: Volume = mesh::sample_volume(&scene, &options).unwrap();
    let eval = cpu::Evaluator::from_compiled(&scene);
    let [nx, ny, nz] = volume.dims;
    assert!(nx > 40 && ny > 20 && nz > 20, "{:?}", volume.dims);
    let mut inside = 0;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let d = eval.distance(volume.point([i, j, k]));
                let got = volume.distance([i, j, k]);
                assert_eq!(got < 0.0, d < 0.0, "sign at ({i}, {j}, {k}): {got} vs {d}");
                inside += usize::from(d < 0.0);
            }
        }
    }
    assert!(inside > 1000, "only {inside} samples inside");

    let dir = scratch("volume");
    volume.write_nrrd(dir.join("bulb.nrrd")).unwrap();
    let (sizes, values) = read_nrrd(&dir.join("bulb.nrrd"));
    assert_eq!(sizes, volume.dims.to_vec());
    assert_eq!(values, volume.distances);

    let slices = volume.write_slices(dir.join("slices")).unwrap();
    assert_eq!(slices.len(), nz as usize);
    let middle = image::open(&slices[nz as usize / 2]).unwrap().to_luma8();
    assert_eq!(middle.dimensions(), (nx, ny));
    for (i, j, pixel) in middle.enumerate_pixels() {
        let inside = volume.distance([i, j, nz / 2]) < 0.0;
        assert_eq!(pixel.0[0], if inside { 255 } else { 0 });
    }
}

#[test]
fn the_distance_kernels_agree_with_the_point_kernel() {
    use fractal_sdf::render::PointEvaluator;
    if gpu::device().is_none() {
        return;
    }
    let scene =
        compiled(mandelbulb(8.0).smooth_union(sphere(0.4).translate(dvec3(1.0, 0.2, 0.0)), 0.1));
    let device =
        PointEvaluator::from_compiled(&scene, Precision::F32, &DeviceSelector::auto()).unwrap();
    let (origin, spacing, side) = (dvec3(-1.3, -1.1, -1.2), 0.07, 5);
    let blocks = [[0, 0, 0], [5, 0, 0], [3, 7, 11], [-2, 4, 1]];
    let grid = device.eval_grid(origin, spacing, side, &blocks).unwrap();
    let mut points = Vec::new();
    for b in blocks {
        for z in 0..side {
            for y in 0..side {
                for x in 0..side {
                    let at = [x, y, z].map(|c| i32::try_from(c).unwrap());
                    let index = DVec3::from_array([0, 1, 2].map(|a| f64::from(b[a] + at[a])));
                    points.push(origin + spacing * index);
                }
            }
        }
    }
    assert_eq!(grid.len(), points.len());
    let full = device.eval(&points).unwrap();
    let distances = device.distances(&points).unwrap();
    let eval = cpu::Evaluator::from_compiled(&scene);
    for (i, p) in points.iter().enumerate() {
        assert_eq!(distances[i], full[i].distance, "at {p}");
        // The grid kernel computes the point itself, rounding differently.
        let cpu = f64::from(eval.distance_f32(p.as_vec3()));
        assert!(
            (grid[i] - cpu).abs() < 1e-4,
            "at {p}: grid {} vs CPU {cpu}",
            grid[i]
        );
    }
}

#[test]
fn an_inside_only_shape_meshes_within_its_own_bound() {
    // Its value is a sign (±1e15), not a distance: nothing may be culled
    // by distance, and the box is its whole bound.
    let scene = compiled(InsideShape::mandelbulb().node([8.0, 10.0]));
    let options = GridOptions::default().resolution(32).sampler(Sampler::Cpu);
    let mesh = mesh::extract(&scene, &options).unwrap();
    assert!(mesh.triangles.len() > 1000, "{}", mesh.triangles.len());
    assert_eq!(mesh.stats.blocks_sampled, mesh.stats.blocks);
    let topology = mesh.topology();
    assert_eq!(topology.boundary_edges, 0, "{topology:?}");
    assert_eq!(topology.misoriented_edges, 0, "{topology:?}");
    // The set lies in the ball of radius 1.104 that the estimate's
    // Mandelbulb fills; every vertex lies between samples of the grid.
    let reach = 1.104 + 1.8 * mesh.voxel_size;
    for p in &mesh.positions {
        assert!(f64::from(p.length()) < reach, "vertex at {p}");
    }
    assert!(mesh.volume() > 1.0 && mesh.volume() < 4.0 / 3.0 * PI * 1.104f64.powi(3));
}

/// What a mesh file read back says about its surface, counted with no
/// code of the crate's: edges not shared by exactly two triangles, edges
/// two triangles traverse the same way, and vertices at a position an
/// earlier vertex holds.
#[derive(Debug, PartialEq, Eq)]
struct FileCounts {
    triangles: usize,
    /// Edges of one triangle or of more than two.
    not_two: usize,
    misoriented: usize,
    duplicate_positions: usize,
}

impl FileCounts {
    fn of(positions: &[[f32; 3]], faces: &[[usize; 3]]) -> Self {
        use std::collections::{HashMap, HashSet};
        let mut edges: HashMap<(usize, usize), (usize, i64)> = HashMap::new();
        for f in faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                let e = edges.entry((a.min(b), a.max(b))).or_default();
                e.0 += 1;
                e.1 += if a < b { 1 } else { -1 };
            }
        }
        let mut seen = HashSet::new();
        let duplicate_positions = positions
            .iter()
            .filter(|p| !seen.insert(p.map(|c| (c + 0.0).to_bits())))
            .count();
        FileCounts {
            triangles: faces.len(),
            not_two: edges.values().filter(|e| e.0 != 2).count(),
            misoriented: edges.values().filter(|e| e.0 == 2 && e.1 != 0).count(),
            duplicate_positions,
        }
    }

    /// A closed, consistently oriented 2-manifold with no two vertices at
    /// one position.
    fn is_clean(&self) -> bool {
        self.triangles > 0
            && self.not_two == 0
            && self.misoriented == 0
            && self.duplicate_positions == 0
    }
}

/// Counts a binary PLY file as `ply-rs-bw` reads it (indices as written).
fn ply_counts(path: &std::path::Path) -> FileCounts {
    use ply_rs_bw::ply::Property;
    let mut file = std::fs::File::open(path).unwrap();
    let parser = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new();
    let ply = parser.read_ply(&mut file).unwrap();
    let float = |e: &ply_rs_bw::ply::DefaultElement, k: &str| match e[k] {
        Property::Float(v) => v,
        ref other => panic!("{k} is {other:?}"),
    };
    let positions: Vec<[f32; 3]> = ply.payload["vertex"]
        .iter()
        .map(|v| [float(v, "x"), float(v, "y"), float(v, "z")])
        .collect();
    let faces: Vec<[usize; 3]> = ply.payload["face"]
        .iter()
        .map(|f| match &f["vertex_indices"] {
            Property::ListInt(l) => [0, 1, 2].map(|k| usize::try_from(l[k]).unwrap()),
            other => panic!("vertex_indices is {other:?}"),
        })
        .collect();
    FileCounts::of(&positions, &faces)
}

/// Counts a binary STL file as `stl_io` reads it: corners at equal
/// positions are one vertex, as slicers and `trimesh` weld them.
fn stl_counts(path: &std::path::Path) -> FileCounts {
    let mut file = std::fs::File::open(path).unwrap();
    let stl = stl_io::read_stl(&mut file).unwrap();
    let positions: Vec<[f32; 3]> = stl.vertices.iter().map(|v| [v[0], v[1], v[2]]).collect();
    let faces: Vec<[usize; 3]> = stl.faces.iter().map(|f| f.vertices).collect();
    FileCounts::of(&positions, &faces)
}

/// Writes `mesh` as PLY and STL into `dir` and counts both files.
fn file_counts(mesh: &Mesh, dir: &std::path::Path, name: &str) -> (FileCounts, FileCounts) {
    let ply = dir.join(format!("{name}.ply"));
    let stl = dir.join(format!("{name}.stl"));
    mesh.write(&ply).unwrap();
    mesh.write(&stl).unwrap();
    let counts = (ply_counts(&ply), stl_counts(&stl));
    std::fs::remove_file(ply).unwrap();
    std::fs::remove_file(stl).unwrap();
    counts
}

#[test]
fn every_gallery_scene_meshes_closed_manifold_as_files_read_back() {
    let dir = scratch("gallery");
    let mut meshed = Vec::new();
    let mut failures = Vec::new();
    for (name, scene) in fractal_sdf::gallery::all() {
        let scene = scene.compile().unwrap();
        let ir = scene.ir();
        let mut options = GridOptions::default().resolution(48).sampler(Sampler::Cpu);
        // A scene with a floor is cut by a box, which caps it.
        if ir.bounds()[ir.root().index()].is_none() {
            options = options.bounds(Aabb::cube(DVec3::ZERO, 2.5));
        }
        let mesh = mesh::extract(&scene, &options).unwrap();
        let (ply, stl) = file_counts(&mesh, &dir, name);
        assert_eq!(ply.triangles, mesh.triangles.len());
        if !ply.is_clean() || !stl.is_clean() {
            failures.push(format!("{name}: PLY {ply:?}, STL {stl:?}"));
        }
        // The crate's own counts say the same.
        assert_eq!(
            mesh.duplicate_positions(),
            ply.duplicate_positions,
            "{name}"
        );
        assert_eq!(
            mesh.topology().is_closed_manifold(),
            ply.not_two == 0 && ply.misoriented == 0,
            "{name}"
        );
        meshed.push(name);
    }
    assert!(failures.is_empty(), "{failures:#?}");
    assert_eq!(meshed, fractal_sdf::gallery::names());
}

#[test]
fn a_rotated_menger_sponge_at_128_cells_is_a_closed_manifold_as_files_read_back() {
    // Rotated off the grid's axes: where the user's checker found 5,756
    // non-manifold edges.
    let scene = compiled(menger(4).rotate(dvec3(1.0, 2.0, 3.0), 0.7));
    let options = GridOptions::default().resolution(128).sampler(Sampler::Cpu);
    let mesh = mesh::extract(&scene, &options).unwrap();
    let (ply, stl) = file_counts(&mesh, &scratch("rotated"), "sponge");
    assert!(ply.is_clean(), "PLY {ply:?}");
    assert!(stl.is_clean(), "STL {stl:?}");
    assert!(mesh.triangles.len() > 500_000, "{}", mesh.triangles.len());
}

#[test]
fn a_volumes_values_lie_in_its_band_with_the_scenes_signs() {
    // An inside-only shape gives ±1e15 (a sign), a fractal's estimate
    // inside is no distance, a sphere's is exact.
    let dir = scratch("band");
    let shapes = [
        ("escape", InsideShape::mandelbulb().node([8.0, 10.0])),
        ("estimate", mandelbulb(8.0)),
        ("sphere", sphere(1.0)),
    ];
    for (name, node) in shapes {
        let scene = compiled(node);
        let options = GridOptions::default()
            .bounds(Aabb::cube(DVec3::ZERO, 1.3))
            .resolution(32)
            .precision(Precision::F64)
            .sampler(Sampler::Cpu);
        let volume = mesh::sample_volume(&scene, &options).unwrap();
        let band = volume.band();
        assert!(
            (f64::from(band) - mesh::BAND_VOXELS * volume.spacing).abs() < 1e-6,
            "{name}: band {band}"
        );
        let eval = cpu::Evaluator::from_compiled(&scene);
        let [nx, ny, nz] = volume.dims;
        let (mut inside, mut clamped_inside) = (0, 0);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let d = eval.distance(volume.point([i, j, k]));
                    let got = volume.distance([i, j, k]);
                    assert!(got.abs() <= band, "{name}: {got} at ({i}, {j}, {k})");
                    assert_eq!(got < 0.0, d < 0.0, "{name}: sign {got} vs {d}");
                    if d.abs() < f64::from(band) {
                        assert!((f64::from(got) - d).abs() < 1e-6, "{name}: {got} vs {d}");
                    }
                    inside += usize::from(d < 0.0);
                    clamped_inside += usize::from(got == -band);
                }
            }
        }
        assert!(inside > 1000, "{name}: {inside} samples inside");
        // The estimate stays small inside the Mandelbulb; the others
        // reach the band.
        assert!(
            name == "estimate" || clamped_inside > 0,
            "{name}: nothing deep inside"
        );
        let path = dir.join(format!("{name}.nrrd"));
        volume.write_nrrd(&path).unwrap();
        let (_, values) = read_nrrd(&path);
        assert!(values.iter().all(|v| v.abs() <= band), "{name}");
    }
}

/// The relative error of a mesh's enclosed volume against `exact`.
fn volume_error(node: &Node, exact: f64, resolution: u32) -> f64 {
    let scene = compiled(node.clone());
    let options = GridOptions::default()
        .resolution(resolution)
        .sampler(Sampler::Cpu);
    let mesh = mesh::extract(&scene, &options).unwrap();
    (mesh.volume() - exact) / exact
}

#[test]
fn the_volume_error_shrinks_with_resolution() {
    let cases = [
        ("sphere", sphere(1.0), 4.0 / 3.0 * PI, [16, 32, 64]),
        (
            "Menger level 2",
            menger(2),
            8.0 * (20.0f64 / 27.0).powi(2),
            [32, 64, 128],
        ),
    ];
    for (name, node, exact, resolutions) in cases {
        let errors = resolutions.map(|r| volume_error(&node, exact, r).abs());
        assert!(
            errors[0] > errors[1] && errors[1] > errors[2],
            "{name}: {errors:?} at {resolutions:?}"
        );
    }
    // Where the user's sponge lost 4.9% of its volume (crossings
    // interpolated linearly, off the surface near edges): within 0.5%.
    let exact = 8.0 * (20.0f64 / 27.0).powi(4);
    let error = volume_error(&menger(4), exact, 128);
    assert!(
        error.abs() < 0.005,
        "Menger level 4 at 128 cells: {error:+.4}"
    );
}
