//! Gallery scenes marched twice at 640×480: by the OpenCL renderer with
//! ambient occlusion, shadows, glow and fog off (the march, normals and
//! shading), and by a WGSL compute shader through wgpu that calls the
//! scene's functions as [`codegen::emit_wgsl`] writes them (its
//! `march_ray`, the OpenCL kernel's march; a four-tap normal; the
//! surface's colour under the key light). On a
//! machine without a GPU these are PoCL and Mesa's lavapipe: two
//! compilers of the same kind of work for the same CPU cores. Prints each
//! one's frame time (median of three), evaluations per pixel and
//! evaluations a second, and the share of pixels whose hit flags differ;
//! writes `out/wgsl_<scene>.png`.
//!
//! It is also how to draw a fractal-sdf scene in a wgpu application of
//! your own: emit its module, bind its parameter buffer at
//! [`codegen::WGSL_PARAMS`], and call `DE` or `DE_shade` from your shader.
//!
//! `cargo run --release --example wgsl_march [SCENE...]` (every gallery
//! scene the WGSL backend draws by default; needs a Vulkan adapter:
//! `scripts/setup.sh` installs lavapipe).

use std::error::Error;
use std::time::Instant;

use fractal_sdf::codegen::{self, KernelSource, Options, Target, WGSL_PARAMS};
use fractal_sdf::cpu::MarchSettings;
use fractal_sdf::metrics::mask_mismatch;
use fractal_sdf::prelude::*;
use fractal_sdf::render::Renderer;

const WIDTH: u32 = 640;
const HEIGHT: u32 = 480;

fn main() -> Result<(), Box<dyn Error>> {
    let asked: Vec<String> = std::env::args().skip(1).collect();
    let gpu = Gpu::new()?;
    std::fs::create_dir_all("out")?;
    println!("640×480 production, the march, normals and shading:");
    println!(
        "| scene | OpenCL ({}) | evaluations / pixel | M evaluations / s | WGSL ({}) | \
         evaluations / pixel | M evaluations / s | hit flags that differ |",
        Renderer::new(&fractal_sdf::gallery::mandelbulb(), Quality::draft())?
            .device()
            .name,
        gpu.adapter
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for (name, scene) in fractal_sdf::gallery::all() {
        if !asked.is_empty() && !asked.iter().any(|a| a == name) {
            continue;
        }
        let compiled = scene.compile()?;
        if compiled.ir().has_inside_shapes() {
            // Marched by brute force, its normals from the neighbours'
            // depths: the render kernels' work, not this plain shader's
            // (examples/backends.rs renders it on both).
            continue;
        }
        let row = compare(name, &scene, &compiled, &gpu)?;
        println!("{row}");
    }
    Ok(())
}

/// One scene on both backends: its table row.
fn compare(
    name: &str,
    scene: &Scene,
    compiled: &fractal_sdf::ir::CompiledScene,
    gpu: &Gpu,
) -> Result<String, Box<dyn Error>> {
    let quality = Quality::production();
    let mut renderer = Renderer::new(scene, quality)?;
    let mut effects = renderer.options().effects;
    effects.ambient_occlusion = false;
    effects.shadows = false;
    effects.glow = None;
    effects.fog_density = 0.0;
    renderer.set_effects(effects)?;
    let frame = renderer.render_with_aovs(WIDTH, HEIGHT)?;
    let pixels = f64::from(WIDTH * HEIGHT);
    let opencl_evaluations = frame.evaluations.iter().map(|&e| f64::from(e)).sum::<f64>();
    let opencl_ms = median_ms(|| {
        renderer.render(WIDTH, HEIGHT).map(|_| ())?;
        Ok(())
    })?;

    // The same rays and hit threshold as the OpenCL kernel's, in the
    // module's frame.
    let module = codegen::emit_wgsl(compiled, &Options::default().target(Target::Render))?;
    let viewport = renderer.viewport(WIDTH, HEIGHT)?;
    let settings = viewport.march_settings(&quality);
    let origin = viewport.ray(0.5, 0.5).origin - module.origin;
    let mut directions = Vec::with_capacity((WIDTH * HEIGHT * 3) as usize);
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let d = viewport
                .ray(f64::from(x) + 0.5, f64::from(y) + 0.5)
                .direction;
            directions.extend(d.to_array().map(|v| v as f32));
        }
    }
    let shader = shader(&module, origin, &settings);
    let params: Vec<f32> = module
        .param_buffer(compiled.default_values().as_slice())
        .iter()
        .map(|&v| v as f32)
        // A binding is never empty.
        .chain([0.0])
        .collect();
    let march = gpu.prepare(&shader, &params, &directions);
    march.run(gpu);
    let wgsl_ms = median_ms(|| {
        march.run(gpu);
        Ok(())
    })?;
    let (colours, evaluations) = march.read(gpu);
    let wgsl_evaluations = evaluations
        .iter()
        .map(|&e| f64::from(e & 0xffff))
        .sum::<f64>();
    let hits: Vec<bool> = evaluations.iter().map(|&e| e >> 16 != 0).collect();
    let image = fractal_sdf::image::RgbaImage::from_fn(WIDTH, HEIGHT, |x, y| {
        fractal_sdf::image::Rgba(colours[(y * WIDTH + x) as usize].to_le_bytes())
    });
    fractal_sdf::output::save_png(&image, format!("out/wgsl_{name}.png"))?;
    Ok(format!(
        "| {name} | {opencl_ms:.1} ms | {:.1} | {:.1} | {wgsl_ms:.1} ms | {:.1} | {:.1} | {:.3}% |",
        opencl_evaluations / pixels,
        opencl_evaluations / opencl_ms / 1e3,
        wgsl_evaluations / pixels,
        wgsl_evaluations / wgsl_ms / 1e3,
        100.0 * mask_mismatch(&frame.hit, &hits)
    ))
}

/// The compute shader: the scene's module, then one invocation a pixel
/// that marches its ray with the module's `march_ray` (the OpenCL
/// kernel's march: over-relaxed steps, the hit located, the stop past the
/// scene's bounding sphere), then shades a hit: `DE_shade`'s colour under
/// the key light, with a tetrahedral normal. Writes the pixel's colour,
/// and its evaluations (low 16 bits) and hit (bit 16).
fn shader(module: &KernelSource, origin: DVec3, s: &MarchSettings) -> String {
    let f = |v: f64| format!("{:?}", v as f32);
    let (group, binding) = WGSL_PARAMS;
    format!(
        "{module}
const ORIGIN = vec3<f32>({ox}, {oy}, {oz});
const FOOTPRINT = vec2<f32>({base}, {per_unit});
@group({group}) @binding({rays}) var<storage, read> directions: array<f32>;
@group({group}) @binding({colours_at}) var<storage, read_write> colours: array<u32>;
@group({group}) @binding({counts_at}) var<storage, read_write> counts: array<u32>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    if (id.x >= {width}u || id.y >= {height}u || arrayLength(&params) == 0u) {{
        return;
    }}
    let i = id.y * {width}u + id.x;
    let rd = vec3<f32>(directions[3u * i], directions[3u * i + 1u], directions[3u * i + 2u]);
    let m = march_ray(ORIGIN, rd, 0.0, FOOTPRINT, 1.0);
    var evaluations = u32(m.steps);
    let sky = mix(vec3<f32>(0.85, 0.9, 1.0), vec3<f32>(0.35, 0.5, 0.8), f32(id.y) / {height}.0);
    var colour = sky;
    if (m.hit) {{
        let p = ORIGIN + rd * m.t;
        let h = march_footprint(FOOTPRINT, m.t);
        let k = vec2<f32>(1.0, -1.0);
        let n = normalize(k.xyy * DE(p + k.xyy * h) + k.yyx * DE(p + k.yyx * h)
            + k.yxy * DE(p + k.yxy * h) + k.xxx * DE(p + k.xxx * h));
        var surface = vec3<f32>(0.0);
        var trap = vec2<f32>(0.0);
        _ = DE_shade(p, &surface, &trap);
        evaluations += 5u;
        let light = normalize(vec3<f32>(0.5, 0.8, 0.35));
        let lit = 0.15 + 0.85 * max(dot(n, light), 0.0);
        colour = surface * lit;
    }}
    let c = vec3<u32>(clamp(pow(colour, vec3<f32>(1.0 / 2.2)), vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0 + 0.5);
    colours[i] = c.x | (c.y << 8u) | (c.z << 16u) | (255u << 24u);
    counts[i] = min(evaluations, 65535u) | (select(0u, 1u, m.hit) << 16u);
}}
",
        module = module.source,
        ox = f(origin.x),
        oy = f(origin.y),
        oz = f(origin.z),
        rays = binding + 1,
        colours_at = binding + 2,
        counts_at = binding + 3,
        base = f(s.footprint_base),
        per_unit = f(s.footprint_per_unit),
        width = WIDTH,
        height = HEIGHT,
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

    /// The pipeline and buffers of `shader` over the parameter buffer
    /// `params` and the rays' `directions`.
    fn prepare(&self, shader: &str, params: &[f32], directions: &[f32]) -> March {
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
        let upload = |values: &[f32]| {
            let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
            let buffer = self.buffer(bytes.len() as u64, U::STORAGE | U::COPY_DST);
            self.queue.write_buffer(&buffer, 0, &bytes);
            buffer
        };
        let (params, rays) = (upload(params), upload(directions));
        let size = u64::from(WIDTH * HEIGHT) * 4;
        let colours = self.buffer(size, U::STORAGE | U::COPY_SRC);
        let counts = self.buffer(size, U::STORAGE | U::COPY_SRC);
        let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(WGSL_PARAMS.0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: WGSL_PARAMS.1,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: WGSL_PARAMS.1 + 1,
                    resource: rays.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: WGSL_PARAMS.1 + 2,
                    resource: colours.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: WGSL_PARAMS.1 + 3,
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
            pass.set_bind_group(WGSL_PARAMS.0, &self.group, &[]);
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
