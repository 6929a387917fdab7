//! A Vulkan device through wgpu, and a compute shader run on it.

/// A Vulkan device through wgpu; `None` where there is none, which under
/// `make test` or CI is a failure.
pub(super) fn device() -> Option<(wgpu::Device, wgpu::Queue)> {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let found =
        pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
            .ok()
            .and_then(|adapter| {
                pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default())).ok()
            });
    let required = std::env::var("FRACTAL_SDF_REQUIRE_DEVICE").is_ok_and(|v| v == "1")
        || std::env::var("CI").is_ok_and(|v| v == "true" || v == "1");
    assert!(
        found.is_some() || !required,
        "no Vulkan adapter for wgpu: install Mesa's lavapipe (scripts/setup.sh installs \
         mesa-vulkan-drivers)"
    );
    found
}

/// Runs `source`'s `main` over `points` invocations with `inputs` (bound
/// in order from binding 0 of group 0), giving `outputs` numbers (bound
/// after them).
pub(super) fn run(
    (device, queue): &(wgpu::Device, wgpu::Queue),
    source: &str,
    inputs: &[&[f32]],
    outputs: usize,
    points: usize,
) -> Vec<f32> {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: None,
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: wgpu::PipelineCompilationOptions::default(),
        cache: None,
    });
    let buffer = |size: usize, usage| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: size as u64,
            usage,
            mapped_at_creation: false,
        })
    };
    let inputs: Vec<wgpu::Buffer> = inputs
        .iter()
        .map(|values| {
            let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
            let input = buffer(
                bytes.len(),
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            );
            queue.write_buffer(&input, 0, &bytes);
            input
        })
        .collect();
    let size = outputs * 4;
    let output = buffer(
        size,
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    );
    let staging = buffer(
        size,
        wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
    );
    let entries: Vec<wgpu::BindGroupEntry<'_>> = inputs
        .iter()
        .chain([&output])
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: u32::try_from(i).expect("a few bindings"),
            resource: b.as_entire_binding(),
        })
        .collect();
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(u32::try_from(points.div_ceil(64)).unwrap(), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &staging, 0, size as u64);
    queue.submit([encoder.finish()]);
    staging
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.unwrap());
    device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    let view = staging
        .slice(..)
        .get_mapped_range()
        .expect("the mapped output");
    view.chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}
