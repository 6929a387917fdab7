//! The gallery's Mandelbulb marched twice at 640×480: by the OpenCL
//! renderer with ambient occlusion, shadows and glow off (the march,
//! normals and shading), and by a WGSL compute shader through wgpu whose
//! distance estimate is the same formula printed by [`expr::Wgsl`] (the
//! march, a four-tap normal and a plain diffuse light). On a machine
//! without a GPU these are PoCL and Mesa's lavapipe: two compilers of
//! the same kind of work for the same CPU cores. Prints each one's frame
//! time, evaluations per pixel and evaluations a second, and how many
//! pixels' hit flags differ; writes `out/wgsl_march.png`.
//!
//! It is also how to use a fractal-sdf formula in a wgpu application of
//! your own: trace it, print it with [`expr::Wgsl`] after
//! [`Wgsl::PRELUDE`], and call it from your shader.
//!
//! `cargo run --release --example wgsl_march` (needs a Vulkan adapter:
//! `scripts/setup.sh` installs lavapipe).

use std::error::Error;
use std::time::Instant;

use fractal_sdf::cpu::sdf;
use fractal_sdf::expr::{self, Num, Printer, Shape, Signature, Var, Wgsl, trace, v3};
use fractal_sdf::math::{escape_radius, mandelbulb_radius};
use fractal_sdf::metrics::mask_mismatch;
use fractal_sdf::prelude::*;
use fractal_sdf::render::Renderer;

const WIDTH: u32 = 640;
const HEIGHT: u32 = 480;

fn main() -> Result<(), Box<dyn Error>> {
    let scene = fractal_sdf::gallery::mandelbulb();
    let quality = Quality::production();
    let mut renderer = Renderer::new(&scene, quality)?;
    let mut effects = renderer.options().effects;
    effects.ambient_occlusion = false;
    effects.shadows = false;
    effects.glow = None;
    renderer.set_effects(effects)?;
    let frame = renderer.render_with_aovs(WIDTH, HEIGHT)?;
    let pixels = f64::from(WIDTH * HEIGHT);
    let opencl_evaluations = frame.evaluations.iter().map(|&e| f64::from(e)).sum::<f64>();
    let opencl_ms = median_ms(|| {
        renderer.render(WIDTH, HEIGHT).map(|_| ())?;
        Ok(())
    })?;

    // The same rays and hit threshold as the OpenCL kernel's.
    let viewport = renderer.viewport(WIDTH, HEIGHT)?;
    let settings = viewport.march_settings(&quality);
    let origin = viewport.ray(0.5, 0.5).origin;
    let mut directions = Vec::with_capacity((WIDTH * HEIGHT * 3) as usize);
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let d = viewport
                .ray(f64::from(x) + 0.5, f64::from(y) + 0.5)
                .direction;
            directions.extend(d.to_array().map(|v| v as f32));
        }
    }
    let shader = shader(&distance_estimate()?, origin, &settings);
    let gpu = Gpu::new()?;
    let march = gpu.prepare(&shader, &directions);
    march.run(&gpu);
    let wgsl_ms = median_ms(|| {
        march.run(&gpu);
        Ok(())
    })?;
    let (colours, evaluations) = march.read(&gpu);
    let wgsl_evaluations = evaluations
        .iter()
        .map(|&e| f64::from(e & 0xffff))
        .sum::<f64>();
    let hits: Vec<bool> = evaluations.iter().map(|&e| e >> 16 != 0).collect();
    let image = fractal_sdf::image::RgbaImage::from_fn(WIDTH, HEIGHT, |x, y| {
        fractal_sdf::image::Rgba(colours[(y * WIDTH + x) as usize].to_le_bytes())
    });
    std::fs::create_dir_all("out")?;
    fractal_sdf::output::save_png(&image, "out/wgsl_march.png")?;

    println!("Mandelbulb, 640×480, the march, normals and shading:");
    println!("| backend | frame | evaluations / pixel | million evaluations / s |");
    println!("|---|---:|---:|---:|");
    for (name, ms, evaluations) in [
        (
            format!("OpenCL ({})", renderer.device().name),
            opencl_ms,
            opencl_evaluations,
        ),
        (format!("WGSL ({})", gpu.adapter), wgsl_ms, wgsl_evaluations),
    ] {
        println!(
            "| {name} | {ms:.1} ms | {:.1} | {:.1} |",
            evaluations / pixels,
            evaluations / ms / 1e3
        );
    }
    println!(
        "hit flags that differ: {:.3}% of the pixels; out/wgsl_march.png",
        100.0 * mask_mismatch(&frame.hit, &hits)
    );
    Ok(())
}

/// The gallery Mandelbulb's estimate (power 8, 10 iterations, bailout 2,
/// turned a quarter about x) as a WGSL function `de(p: real3) -> real`.
fn distance_estimate() -> Result<String, expr::Unprintable> {
    let power = 8.0;
    let program = trace(3, |a| {
        // The child of a rotation by −π/2 about x sees (x, −z, y).
        let q = v3(a[0], -a[2], a[1]);
        let e = sdf::mandelbulb_estimate(
            q,
            Var::of(power),
            Var::of(10.0),
            Var::of(escape_radius(power, 2.0)),
            Var::of(mandelbulb_radius(power)),
            Some(8),
            None,
        );
        vec![e.distance]
    });
    Wgsl.function(
        &Signature::new("de", &[("p", Shape::Vec3)], Shape::Scalar),
        &program,
    )
}

/// The compute shader: one invocation a pixel marches its ray as the
/// OpenCL kernel's plain march does (steps of the distance to the drawn
/// surface, no shorter than `hit_epsilon` footprints), then shades a hit
/// with a tetrahedral normal and the scene's key light. Writes the
/// pixel's colour, and its evaluations (low 16 bits) and hit (bit 16).
fn shader(de: &str, origin: DVec3, s: &fractal_sdf::cpu::MarchSettings) -> String {
    let f = |v: f64| format!("{:?}", v as f32);
    let ball = mandelbulb_radius(8.0);
    format!(
        "{prelude}
{de}
const ORIGIN = vec3<f32>({ox}, {oy}, {oz});
@group(0) @binding(0) var<storage, read> directions: array<f32>;
@group(0) @binding(1) var<storage, read_write> colours: array<u32>;
@group(0) @binding(2) var<storage, read_write> counts: array<u32>;

fn footprint(t: f32) -> f32 {{
    return {base} + {per_unit} * t;
}}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    if (id.x >= {width}u || id.y >= {height}u) {{
        return;
    }}
    let i = id.y * {width}u + id.x;
    let rd = vec3<f32>(directions[3u * i], directions[3u * i + 1u], directions[3u * i + 2u]);
    var t = 0.0;
    var evaluations = 0u;
    var hit = false;
    for (var step = 0; step < {max_steps}; step++) {{
        let p = ORIGIN + rd * t;
        let d = de(p);
        evaluations++;
        let surface = {detail} * footprint(t);
        if (d < surface) {{
            hit = true;
            break;
        }}
        t += max(d - surface, {hit_epsilon} * footprint(t));
        // Past the ball that holds the set and leaving it: a miss.
        if (t > {max_distance} || (dot(p, p) > {far} && dot(p, rd) > 0.0)) {{
            break;
        }}
    }}
    let sky = mix(vec3<f32>(0.85, 0.9, 1.0), vec3<f32>(0.35, 0.5, 0.8), f32(id.y) / {height}.0);
    var colour = sky;
    if (hit) {{
        let p = ORIGIN + rd * t;
        let h = footprint(t);
        let k = vec2<f32>(1.0, -1.0);
        let n = normalize(k.xyy * de(p + k.xyy * h) + k.yyx * de(p + k.yyx * h)
            + k.yxy * de(p + k.yxy * h) + k.xxx * de(p + k.xxx * h));
        evaluations += 4u;
        let light = normalize(vec3<f32>(0.5, 0.8, 0.35));
        let lit = 0.15 + 0.85 * max(dot(n, light), 0.0);
        colour = vec3<f32>(0.9, 0.6, 0.35) * lit;
    }}
    let c = vec3<u32>(clamp(pow(colour, vec3<f32>(1.0 / 2.2)), vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0 + 0.5);
    colours[i] = c.x | (c.y << 8u) | (c.z << 16u) | (255u << 24u);
    counts[i] = min(evaluations, 65535u) | (select(0u, 1u, hit) << 16u);
}}
",
        prelude = Wgsl::PRELUDE,
        ox = f(origin.x),
        oy = f(origin.y),
        oz = f(origin.z),
        base = f(s.footprint_base),
        per_unit = f(s.footprint_per_unit),
        width = WIDTH,
        height = HEIGHT,
        max_steps = s.max_steps,
        detail = f(s.detail),
        hit_epsilon = f(s.hit_epsilon),
        max_distance = f(s.max_distance),
        far = f(4.0 * ball * ball),
    )
}

/// The median of three timed runs of `f`, in milliseconds.
fn median_ms(mut f: impl FnMut() -> Result<(), Box<dyn Error>>) -> Result<f64, Box<dyn Error>> {
    let mut times = Vec::new();
    for _ in 0..3 {
        let start = Instant::now();
        f()?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    Ok(times[1])
}

/// A wgpu device and queue, and the adapter's name.
struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    adapter: String,
}

impl Gpu {
    fn new() -> Result<Self, Box<dyn Error>> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter =
            pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))?;
        let (device, queue) =
            pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default()))?;
        Ok(Gpu {
            device,
            queue,
            adapter: adapter.get_info().name,
        })
    }

    fn buffer(&self, bytes: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: bytes,
            usage,
            mapped_at_creation: false,
        })
    }

    /// The pipeline and buffers of `shader` over the rays' `directions`.
    fn prepare(&self, shader: &str, directions: &[f32]) -> March {
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("wgsl_march"),
                source: wgpu::ShaderSource::Wgsl(shader.into()),
            });
        let pipeline = self
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: None,
                layout: None,
                module: &module,
                entry_point: Some("main"),
                compilation_options: wgpu::PipelineCompilationOptions::default(),
                cache: None,
            });
        use wgpu::BufferUsages as U;
        let bytes: Vec<u8> = directions.iter().flat_map(|v| v.to_le_bytes()).collect();
        let rays = self.buffer(bytes.len() as u64, U::STORAGE | U::COPY_DST);
        self.queue.write_buffer(&rays, 0, &bytes);
        let size = u64::from(WIDTH * HEIGHT) * 4;
        let colours = self.buffer(size, U::STORAGE | U::COPY_SRC);
        let counts = self.buffer(size, U::STORAGE | U::COPY_SRC);
        let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: rays.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: colours.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: counts.as_entire_binding(),
                },
            ],
        });
        March {
            pipeline,
            group,
            colours,
            counts,
        }
    }
}

/// A prepared frame: run it, then read its colours and counts back.
struct March {
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    colours: wgpu::Buffer,
    counts: wgpu::Buffer,
}

impl March {
    /// Marches every pixel and waits for the device.
    fn run(&self, gpu: &Gpu) {
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.group, &[]);
            pass.dispatch_workgroups(WIDTH.div_ceil(8), HEIGHT.div_ceil(8), 1);
        }
        gpu.queue.submit([encoder.finish()]);
        gpu.device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("the device finishes");
    }

    /// The last frame's packed colours and counts.
    fn read(&self, gpu: &Gpu) -> (Vec<u32>, Vec<u32>) {
        let read = |buffer: &wgpu::Buffer| {
            let staging = gpu.buffer(
                buffer.size(),
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            );
            let mut encoder = gpu
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, buffer.size());
            gpu.queue.submit([encoder.finish()]);
            staging
                .slice(..)
                .map_async(wgpu::MapMode::Read, |r| r.expect("mapped"));
            gpu.device
                .poll(wgpu::PollType::wait_indefinitely())
                .expect("the device finishes");
            let view = staging.slice(..).get_mapped_range().expect("mapped");
            view.chunks_exact(4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect::<Vec<u32>>()
        };
        (read(&self.colours), read(&self.counts))
    }
}
