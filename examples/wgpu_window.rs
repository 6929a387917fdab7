//! A scene in a window of a wgpu application: the application owns the
//! device, the queue and the window's surface; [`WgpuRenderer`] renders
//! each frame into a texture of that device ([`render_to_texture`]), and a
//! small render pass draws the texture onto the surface. No pixel passes
//! through the CPU. The Mandelbulb's power moves with time, 8 + 2 sin(t/2)
//! from 8 at the first frame, a parameter written to a buffer each frame.
//!
//! `cargo run --release --features viewer,wgpu --example wgpu_window
//! [-- SCENE] [--frames N] [--screenshot FILE]`: a gallery scene (the
//! Mandelbulb by default), until the window closes or after N frames;
//! `--screenshot` writes the window's first frame, read back from its
//! surface, as a PNG. Runs under Xvfb with Mesa's lavapipe.
//!
//! [`render_to_texture`]: WgpuRenderer::render_to_texture

use std::error::Error;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use fractal_sdf::prelude::*;
use fractal_sdf::render::wgpu;
use fractal_sdf::render::{RenderOptions, WGPU_TEXTURE_FORMAT, WgpuRenderer};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

/// Draws the rendered texture over the whole surface: one triangle that
/// covers it, sampling texel for texel.
const BLIT: &str = "
@group(0) @binding(0) var frame: texture_2d<f32>;

@vertex
fn vertex(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fragment(@builtin(position) at: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(frame, vec2<i32>(at.xy), 0);
}
";

struct Args {
    scene: String,
    frames: Option<u32>,
    screenshot: Option<PathBuf>,
}

fn parse() -> Result<Args, Box<dyn Error>> {
    let mut args = Args {
        scene: "mandelbulb".into(),
        frames: None,
        screenshot: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "--frames" => args.frames = Some(it.next().ok_or("--frames needs N")?.parse()?),
            "--screenshot" => {
                args.screenshot = Some(it.next().ok_or("--screenshot needs a file")?.into());
            }
            name => args.scene = name.to_string(),
        }
    }
    Ok(args)
}

/// The window, its surface and the renderer drawing into it.
struct Shown {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    renderer: WgpuRenderer,
    /// The texture the renderer draws into, and the blit's binding of it.
    frame: Option<(wgpu::Texture, wgpu::BindGroup)>,
    blit: wgpu::RenderPipeline,
    dynamic_power: bool,
}

impl Shown {
    fn new(event_loop: &ActiveEventLoop, args: &Args) -> Result<Self, Box<dyn Error>> {
        let window = Arc::new(
            event_loop.create_window(
                Window::default_attributes()
                    .with_title("fractal-sdf on wgpu")
                    .with_inner_size(PhysicalSize::new(320, 240)),
            )?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        let surface = instance.create_surface(window.clone())?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            compatible_surface: Some(&surface),
            ..wgpu::RequestAdapterOptions::default()
        }))?;
        let (device, queue) =
            pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default()))?;
        let caps = surface.get_capabilities(&adapter);
        // The renderer's texture holds display-encoded 8-bit colours
        // already: the surface takes them as they are (an sRGB surface
        // would encode them again, through a view without the encoding).
        let format = [
            wgpu::TextureFormat::Bgra8Unorm,
            wgpu::TextureFormat::Rgba8Unorm,
        ]
        .into_iter()
        .find(|f| caps.formats.contains(f))
        .or_else(|| caps.formats.first().copied())
        .ok_or("the surface offers no format")?;
        let view_format = format.remove_srgb_suffix();
        let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        if args.screenshot.is_some() {
            if !caps.usages.contains(wgpu::TextureUsages::COPY_SRC) {
                return Err("this surface cannot be read back for --screenshot".into());
            }
            usage |= wgpu::TextureUsages::COPY_SRC;
        }
        let size = window.inner_size();
        let side = device.limits().max_texture_dimension_2d;
        let config = wgpu::SurfaceConfiguration {
            usage,
            format,
            width: size.width.clamp(1, side),
            height: size.height.clamp(1, side),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: if view_format == format {
                Vec::new()
            } else {
                vec![view_format]
            },
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&device, &config);

        let mut scene = fractal_sdf::gallery::file(&args.scene)
            .ok_or_else(|| format!("no gallery scene `{}`", args.scene))?;
        let dynamic_power = args.scene == "mandelbulb";
        if dynamic_power {
            scene.scene.geometry = Some(
                mandelbulb(fractal_sdf::scene::param("power", 8.0)).color(dvec3(0.85, 0.65, 0.45)),
            );
        }
        let mut options = RenderOptions::default();
        options.quality = Quality::preview().resolution_scale(1);
        options.effects = scene.effects;
        let renderer = WgpuRenderer::with_device(
            scene.scene.compile()?,
            &options,
            device.clone(),
            queue.clone(),
        )?;

        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("blit"),
            source: wgpu::ShaderSource::Wgsl(BLIT.into()),
        });
        let blit = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("blit"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vertex"),
                compilation_options: wgpu::PipelineCompilationOptions::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fragment"),
                compilation_options: wgpu::PipelineCompilationOptions::default(),
                targets: &[Some(view_format.into())],
            }),
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            multiview_mask: None,
            cache: None,
        });
        Ok(Shown {
            window,
            surface,
            device,
            queue,
            config,
            renderer,
            frame: None,
            blit,
            dynamic_power,
        })
    }

    /// Follows the window's size; a minimised window (no pixels) is left
    /// as it was, and nothing is drawn until it has some again.
    fn resize(&mut self, size: PhysicalSize<u32>) {
        if size.width == 0 || size.height == 0 {
            return;
        }
        let side = self.device.limits().max_texture_dimension_2d;
        self.config.width = size.width.min(side);
        self.config.height = size.height.min(side);
        self.surface.configure(&self.device, &self.config);
        self.frame = None;
    }

    /// Renders a frame at `seconds` into the texture, draws it onto the
    /// surface and presents it; with `screenshot`, writes the surface's
    /// pixels there first.
    fn draw(&mut self, seconds: f64, screenshot: Option<&PathBuf>) -> Result<(), Box<dyn Error>> {
        let (width, height) = (self.config.width, self.config.height);
        if self.frame.is_none() {
            let texture = self.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("fractal"),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: WGPU_TEXTURE_FORMAT,
                usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            });
            let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
            let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("blit"),
                layout: &self.blit.get_bind_group_layout(0),
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                }],
            });
            self.frame = Some((texture, group));
        }
        let (texture, group) = self.frame.as_ref().expect("made above");
        if self.dynamic_power {
            self.renderer
                .set_param("power", 8.0 + 2.0 * (0.5 * seconds).sin())?;
        }
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        self.renderer.render_to_texture(&view, width, height)?;

        let output = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            // Resized or lost under it: configured again, drawn next time.
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                return Ok(());
            }
            // Not shown now: drawn next time.
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(());
            }
            other => return Err(format!("no surface texture: {other:?}").into()),
        };
        let target = output.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(self.config.format.remove_srgb_suffix()),
            ..wgpu::TextureViewDescriptor::default()
        });
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("blit"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.blit);
            pass.set_bind_group(0, group, &[]);
            pass.draw(0..3, 0..1);
        }
        let row = (4 * width).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let staging = screenshot.map(|_| {
            let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("screenshot"),
                size: u64::from(row * height),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            encoder.copy_texture_to_buffer(
                output.texture.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer: &staging,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(row),
                        rows_per_image: Some(height),
                    },
                },
                output.texture.size(),
            );
            staging
        });
        self.queue.submit([encoder.finish()]);
        if let (Some(path), Some(staging)) = (screenshot, staging) {
            staging.slice(..).map_async(wgpu::MapMode::Read, |r| {
                r.expect("the screenshot maps");
            });
            self.device.poll(wgpu::PollType::wait_indefinitely())?;
            let bytes = staging.slice(..).get_mapped_range()?.to_vec();
            let bgra = match self.config.format.remove_srgb_suffix() {
                wgpu::TextureFormat::Bgra8Unorm => true,
                wgpu::TextureFormat::Rgba8Unorm => false,
                other => {
                    return Err(format!("--screenshot reads 8-bit surfaces, not {other:?}").into());
                }
            };
            let mut rgba = Vec::with_capacity(4 * (width * height) as usize);
            for line in bytes.chunks_exact(row as usize) {
                for p in line[..4 * width as usize].chunks_exact(4) {
                    let (r, b) = if bgra { (p[2], p[0]) } else { (p[0], p[2]) };
                    rgba.extend_from_slice(&[r, p[1], b, 255]);
                }
            }
            let image = fractal_sdf::image::RgbaImage::from_raw(width, height, rgba)
                .expect("four bytes a pixel");
            image.save(path)?;
            println!("screenshot -> {}", path.display());
        }
        self.queue.present(output);
        Ok(())
    }
}

struct App {
    args: Args,
    shown: Option<Shown>,
    /// When the first frame was drawn: the animation's time 0.
    started: Option<Instant>,
    frames: u32,
    failed: Option<Box<dyn Error>>,
}

impl App {
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: Box<dyn Error>) {
        self.failed = Some(e);
        event_loop.exit();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.shown.is_some() {
            return;
        }
        match Shown::new(event_loop, &self.args) {
            Ok(shown) => {
                println!(
                    "showing {} on {} ({:?})",
                    self.args.scene,
                    shown.renderer.adapter().name,
                    shown.renderer.adapter().backend
                );
                shown.window.request_redraw();
                self.shown = Some(shown);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(shown) = self.shown.as_mut() else {
            return;
        };
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => shown.resize(size),
            WindowEvent::RedrawRequested => {
                let size = shown.window.inner_size();
                if size.width == 0 || size.height == 0 {
                    // Minimised: nothing to draw until it has pixels again.
                    return;
                }
                let first = self.frames == 0;
                let screenshot = self.args.screenshot.as_ref().filter(|_| first);
                let started = *self.started.get_or_insert_with(Instant::now);
                let seconds = started.elapsed().as_secs_f64();
                if let Err(e) = shown.draw(seconds, screenshot) {
                    return self.fail(event_loop, e);
                }
                self.frames += 1;
                if self.args.frames.is_some_and(|n| self.frames >= n) {
                    println!("{} frames", self.frames);
                    event_loop.exit();
                } else {
                    shown.window.request_redraw();
                }
            }
            _ => {}
        }
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = parse()?;
    let event_loop = EventLoop::new()?;
    let mut app = App {
        args,
        shown: None,
        started: None,
        frames: 0,
        failed: None,
    };
    event_loop.run_app(&mut app)?;
    match app.failed {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
