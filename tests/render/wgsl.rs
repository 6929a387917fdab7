//! The march in WGSL (`march_ray` of a module `codegen::emit_wgsl` writes
//! for rendering) against the OpenCL renderer's: every gallery scene the
//! WGSL backend draws, marched on a Vulkan device through wgpu (Mesa's
//! lavapipe where there is no GPU) along the renderer's own rays, hits
//! the same pixels.

use crate::gpu;
use crate::wgpu_device::{device, run};

use fractal_sdf::codegen::{self, Options, Target, WGSL_PARAMS};
use fractal_sdf::prelude::*;
use fractal_sdf::render::Renderer;

const WIDTH: u32 = 96;
const HEIGHT: u32 = 72;

/// The shader: each invocation marches one ray (origin and direction from
/// `rays`) and writes its hit flag, distance along the ray and
/// evaluations.
fn shader(module: &str, footprint: (f64, f64), count: usize) -> String {
    let (group, binding) = WGSL_PARAMS;
    assert_eq!((group, binding), (0, 0), "the harness binds inputs from 0");
    #[allow(clippy::cast_possible_truncation)]
    let (base, per_unit) = (footprint.0 as f32, footprint.1 as f32);
    format!(
        "{module}\n\
         @group(0) @binding(1) var<storage, read> rays: array<f32>;\n\
         @group(0) @binding(2) var<storage, read_write> outputs: array<f32>;\n\
         @compute @workgroup_size(64)\n\
         fn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
         \x20   let i = id.x;\n\
         \x20   if (i >= {count}u || arrayLength(&params) == 0u) {{ return; }}\n\
         \x20   let ro = real3(rays[6u * i], rays[6u * i + 1u], rays[6u * i + 2u]);\n\
         \x20   let rd = real3(rays[6u * i + 3u], rays[6u * i + 4u], rays[6u * i + 5u]);\n\
         \x20   let m = march_ray(ro, rd, 0.0, real2({base:?}, {per_unit:?}), 1.0);\n\
         \x20   outputs[3u * i] = select(0.0, 1.0, m.hit);\n\
         \x20   outputs[3u * i + 1u] = m.t;\n\
         \x20   outputs[3u * i + 2u] = real(m.steps);\n\
         }}\n"
    )
}

/// At 96×72 production, with the effects that march more rays off, the
/// WGSL march hits the pixels the OpenCL renderer's march hits: at most
/// 0.1% of each scene's pixels differ (measured: none of the 21 scenes'
/// 145,152 pixels; at 640×480 about 25 of 6.45 million, in `materials`
/// and `bulb_variants`, see the performance chapter), and at least 20
/// scenes are compared.
#[test]
fn the_wgsl_march_hits_the_pixels_the_opencl_renderer_hits() {
    if gpu::device().is_none() {
        return;
    }
    let Some(wgpu) = device() else { return };
    let mut compared = 0;
    let mut differing = Vec::new();
    let mut total = 0;
    for (name, scene) in fractal_sdf::gallery::all() {
        let compiled = scene.compile().expect("gallery scenes compile");
        if compiled.ir().has_inside_shapes() {
            continue;
        }
        let quality = Quality::production();
        let mut renderer = Renderer::new(&scene, quality).expect("the scene renders");
        let mut effects = renderer.options().effects;
        effects.ambient_occlusion = false;
        effects.shadows = false;
        effects.glow = None;
        effects.fog_density = 0.0;
        renderer.set_effects(effects).expect("effects off");
        let frame = renderer
            .render_with_aovs(WIDTH, HEIGHT)
            .expect("the frame renders");
        let module = codegen::emit_wgsl(
            &compiled,
            &Options::default().quality(quality).target(Target::Render),
        )
        .expect("the scene prints");
        let view = renderer.viewport(WIDTH, HEIGHT).expect("a viewport");
        let settings = view.march_settings(&quality);
        let mut rays = Vec::new();
        for y in 0..HEIGHT {
            for x in 0..WIDTH {
                let ray = view.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let origin = ray.origin - module.origin;
                #[allow(clippy::cast_possible_truncation)]
                rays.extend(
                    origin
                        .to_array()
                        .into_iter()
                        .chain(ray.direction.to_array())
                        .map(|v| v as f32),
                );
            }
        }
        #[allow(clippy::cast_possible_truncation)]
        let params: Vec<f32> = module
            .param_buffer(compiled.default_values().as_slice())
            .iter()
            .map(|&v| v as f32)
            .chain([0.0])
            .collect();
        let count = (WIDTH * HEIGHT) as usize;
        let footprint = (settings.footprint_base, settings.footprint_per_unit);
        let got = run(
            &wgpu,
            &shader(&module.source, footprint, count),
            &[&params, &rays],
            3 * count,
            count,
        );
        let differ = frame
            .hit
            .iter()
            .zip(got.chunks_exact(3))
            .filter(|(opencl, w)| **opencl != (w[0] == 1.0))
            .count();
        assert!(
            got.chunks_exact(3).any(|w| w[0] == 1.0),
            "{name}: the WGSL march hits nothing"
        );
        total += differ;
        if differ * 1000 > count {
            differing.push(format!("{name}: {differ} of {count} pixels"));
        }
        compared += 1;
    }
    println!("{compared} scenes, {total} pixels' hit flags differ");
    assert!(
        differing.is_empty(),
        "hit flags differ:\n{}",
        differing.join("\n")
    );
    assert!(compared >= 20, "only {compared} scenes compared");
}
