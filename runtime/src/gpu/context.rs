//! The device, small wgpu helpers, and the [`Pool`] that keeps a renderer's resources across
//! frames.

use std::collections::HashMap;

use wgpu::util::DeviceExt;

use crate::RenderError;

/// A device and queue (both are handles: cloning shares them).
#[derive(Clone)]
pub struct GpuContext {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// What the adapter says it is.
    pub adapter_info: wgpu::AdapterInfo,
    /// Nanoseconds per timestamp tick, where the adapter has timestamp queries.
    pub timestamp_period: Option<f32>,
}

impl GpuContext {
    /// The backends a window or a renderer opens first: those `WGPU_BACKEND` names, else the
    /// primary ones (Vulkan, Metal, DX12) — not OpenGL, whose EGL, initialised next to lavapipe
    /// in one process, crashed one run in twenty at exit.
    pub fn primary_backends() -> wgpu::Backends {
        wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY)
    }

    /// Opens the first adapter of [`GpuContext::primary_backends`], and only when they have
    /// none (and `WGPU_BACKEND` is unset), OpenGL's where it is built in. An error that says
    /// what to install when there is no adapter at all.
    pub fn new() -> Result<GpuContext, RenderError> {
        let mut tries = vec![GpuContext::primary_backends()];
        if wgpu::Backends::from_env().is_none() {
            tries.push(wgpu::Backends::SECONDARY);
        }
        let mut refusal = String::new();
        for backends in tries {
            let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
            desc.backends = backends;
            let instance = wgpu::Instance::new(desc);
            match pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter: false,
                compatible_surface: None,
                apply_limit_buckets: false,
            })) {
                Ok(adapter) => return GpuContext::open(&adapter),
                Err(e) => refusal = e.to_string(),
            }
        }
        Err(RenderError::NoAdapter(format!(
            "{refusal}. Install a Vulkan driver (on Debian/Ubuntu without a GPU: apt-get install \
             mesa-vulkan-drivers for the software driver, lavapipe), or Metal/DX12 on macOS/Windows"
        )))
    }

    /// A device on `adapter`, asked for with [`GpuContext::device_descriptor`].
    fn open(adapter: &wgpu::Adapter) -> Result<GpuContext, RenderError> {
        let info = adapter.get_info();
        let (device, queue) =
            pollster::block_on(adapter.request_device(&GpuContext::device_descriptor(adapter)))
                .map_err(|e| RenderError::NoAdapter(format!("cannot open {}: {e}", info.name)))?;
        Ok(GpuContext::from_device(info, device, queue))
    }

    /// What visgate asks of a device on `adapter`: the downlevel limits raised to the
    /// adapter's where a method needs more (texture layers and size, storage bindings and
    /// buffer size), timestamp queries where there are. A window that opens its own device
    /// (eframe) asks with this too, so that the viewer renders on the window's device.
    pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
        let mut have = adapter.limits();
        // An adapter's binding as a smaller one has it (an integrated GPU, WebGPU's 128 MiB),
        // to see how a level fares there: `VISGATE_MAX_BINDING_BYTES`.
        if let Some(bytes) = binding_cap() {
            have.max_storage_buffer_binding_size = have.max_storage_buffer_binding_size.min(bytes);
        }
        let limits = wgpu::Limits {
            max_texture_array_layers: have.max_texture_array_layers,
            // LightCluster's shadow atlas (6 faces a cluster in one texture).
            max_texture_dimension_2d: have.max_texture_dimension_2d,
            max_storage_buffer_binding_size: have.max_storage_buffer_binding_size,
            // The imperfect shadow maps' atlas (a map per VPL in one buffer).
            max_buffer_size: have.max_buffer_size,
            max_storage_buffers_per_shader_stage: have.max_storage_buffers_per_shader_stage.min(16),
            ..wgpu::Limits::downlevel_defaults()
        };
        wgpu::DeviceDescriptor {
            label: Some("visgate device"),
            required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
            required_limits: limits,
            ..Default::default()
        }
    }

    /// The context of a device already open (a window's), made with
    /// [`GpuContext::device_descriptor`].
    pub fn from_device(
        adapter_info: wgpu::AdapterInfo,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> GpuContext {
        // lavapipe writes a compute pass's closing timestamp without waiting for its
        // dispatches (a 300 ms pass read 0.04 ms: examples/fragment_vs_compute.rs): on a CPU
        // adapter each span is timed by waiting for it instead.
        let timestamp_period = (device.features().contains(wgpu::Features::TIMESTAMP_QUERY)
            && adapter_info.device_type != wgpu::DeviceType::Cpu)
            .then(|| queue.get_timestamp_period());
        GpuContext {
            device,
            queue,
            adapter_info,
            timestamp_period,
        }
    }

    /// Waits until the GPU is idle.
    pub fn wait(&self) {
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
    }
}

/// `VISGATE_MAX_BINDING_BYTES`: the storage binding visgate asks of any adapter, at most (a
/// number of bytes, at least 1 MiB); `None` where it is unset or not such a number.
fn binding_cap() -> Option<u64> {
    let text = std::env::var("VISGATE_MAX_BINDING_BYTES").ok()?;
    let bytes = text.trim().parse::<u64>().ok().filter(|&b| b >= 1 << 20);
    if bytes.is_none() {
        tracing::warn!(
            "VISGATE_MAX_BINDING_BYTES={text} is not a number of bytes ≥ 1048576: ignored"
        );
    }
    bytes
}

/// Runs `f` with the device's validation and out-of-memory errors captured: a GPU error comes
/// back as a [`RenderError::Gpu`] naming it, never as a panic (wgpu's default for errors no
/// scope catches).
pub fn scoped<T>(
    ctx: &GpuContext,
    f: impl FnOnce() -> Result<T, RenderError>,
) -> Result<T, RenderError> {
    let oom = ctx.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
    let result = f();
    let invalid = pollster::block_on(validation.pop());
    let out_of_memory = pollster::block_on(oom.pop());
    match (invalid, out_of_memory) {
        (Some(e), _) => Err(RenderError::Gpu(format!("the GPU refused the frame: {e}"))),
        (None, Some(e)) => Err(RenderError::Gpu(format!(
            "out of GPU memory ({e}): use a smaller image, fewer VPLs or smaller maps"
        ))),
        (None, None) => result,
    }
}

/// The compute pipelines of shader module `module`'s entry points `entries`, in order (auto
/// layouts).
pub fn compute_pipelines<const N: usize>(
    d: &wgpu::Device,
    module: &wgpu::ShaderModule,
    entries: [&str; N],
) -> [wgpu::ComputePipeline; N] {
    entries.map(|entry| compute_pipeline_with(d, entry, module, entry, &[]))
}

/// The compute pipeline (auto layout) of `module`'s entry point `entry` with the shader's
/// pipeline-overridable `constants` set (WGSL `override`s, by name).
pub fn compute_pipeline_with(
    d: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    entry: &str,
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: None,
        module,
        entry_point: Some(entry),
        compilation_options: wgpu::PipelineCompilationOptions {
            constants,
            ..Default::default()
        },
        cache: None,
    })
}

/// A render pipeline (auto layout) of `module`'s `vertex` and `fragment` entries with one
/// colour target per format, a Depth32Float test with `depth` where given (`Less` for standard
/// depth, `Greater` for the camera's reversed depth), and vertex buffers.
pub fn render_pipeline(
    d: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    entries: (&str, &str),
    buffers: &[Option<wgpu::VertexBufferLayout>],
    targets: &[wgpu::TextureFormat],
    depth: Option<wgpu::CompareFunction>,
) -> wgpu::RenderPipeline {
    let raster = Raster::default();
    render_pipeline_with(d, label, module, entries, buffers, targets, depth, &raster)
}

/// How a [`render_pipeline_with`] rasterizes: its layout (`None`: derived from the shader), the
/// faces it culls and its depth bias.
#[derive(Default)]
pub struct Raster<'a> {
    /// An explicit layout, so that one bind group serves several pipelines.
    pub layout: Option<&'a wgpu::PipelineLayout>,
    /// The faces not drawn.
    pub cull: Option<wgpu::Face>,
    /// Added to each fragment's depth before its test.
    pub bias: wgpu::DepthBiasState,
}

/// [`render_pipeline`] rasterized as `raster` says.
#[allow(clippy::too_many_arguments)]
pub fn render_pipeline_with(
    d: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    (vertex, fragment): (&str, &str),
    buffers: &[Option<wgpu::VertexBufferLayout>],
    targets: &[wgpu::TextureFormat],
    depth: Option<wgpu::CompareFunction>,
    raster: &Raster,
) -> wgpu::RenderPipeline {
    let targets: Vec<Option<wgpu::ColorTargetState>> = targets
        .iter()
        .map(|&format| {
            Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        })
        .collect();
    d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: raster.layout,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(vertex),
            buffers,
            compilation_options: Default::default(),
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: raster.cull,
            ..Default::default()
        },
        depth_stencil: depth.map(|compare| wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(compare),
            stencil: Default::default(),
            bias: raster.bias,
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment),
            targets: &targets,
            compilation_options: Default::default(),
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A bind group for group 0 of a pipeline's layout from (binding, resource) pairs.
pub fn bind_group(
    d: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    label: &str,
    resources: Vec<(u32, wgpu::BindingResource)>,
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = resources
        .into_iter()
        .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
        .collect();
    d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// The binding of `size` bytes of `buffer` from `offset` (a strided uniform's element).
pub fn slice(buffer: &wgpu::Buffer, offset: u64, size: u64) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer,
        offset,
        size: std::num::NonZeroU64::new(size),
    })
}

/// A view of one layer of a 2D array texture.
pub fn layer_view(t: &wgpu::Texture, layer: u32) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor {
        label: Some("layer"),
        dimension: Some(wgpu::TextureViewDimension::D2),
        base_array_layer: layer,
        array_layer_count: Some(1),
        ..Default::default()
    })
}

/// A view of a whole 2D array texture.
pub fn array_view(t: &wgpu::Texture) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor {
        label: Some("array"),
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    })
}

/// A buffer holding `bytes` now (for data that lives as long as the scene).
pub fn init_buffer(
    d: &wgpu::Device,
    label: &str,
    bytes: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    let mut v = bytes.to_vec();
    if v.len() < 64 {
        v.resize(64, 0);
    }
    d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: &v,
        usage,
    })
}

/// What a kept texture was made with; another request under the same label with another key
/// replaces it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct TextureKey {
    size: [u32; 3],
    mips: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
}

/// A renderer's frame resources, kept by label across frames: a request for a label with the
/// same size, format and usage returns the texture or buffer made before; a request with
/// another size replaces it. [`Pool::created`] counts what was ever made, so a test can check
/// that a frame with the same settings makes nothing.
#[derive(Default)]
pub struct Pool {
    textures: HashMap<&'static str, (TextureKey, wgpu::Texture)>,
    buffers: HashMap<&'static str, wgpu::Buffer>,
    /// The frame's timestamp queries ([`Pool::query_set`]).
    pub(super) queries: Option<wgpu::QuerySet>,
    created: u64,
}

impl Pool {
    /// Textures, buffers and query sets made so far.
    pub fn created(&self) -> u64 {
        self.created
    }

    /// Counts a resource made outside the pool's own methods.
    pub(super) fn note_created(&mut self) {
        self.created += 1;
    }

    /// The 2D (array) texture `label` of `size` = [width, height, layers] and `mips` levels.
    pub fn texture(
        &mut self,
        d: &wgpu::Device,
        label: &'static str,
        size: [u32; 3],
        mips: u32,
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> wgpu::Texture {
        let key = TextureKey {
            size,
            mips,
            format,
            usage,
        };
        if let Some((k, t)) = self.textures.get(label)
            && *k == key
        {
            return t.clone();
        }
        self.created += 1;
        let t = d.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: size[0],
                height: size[1],
                depth_or_array_layers: size[2],
            },
            mip_level_count: mips,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        });
        self.textures.insert(label, (key, t.clone()));
        t
    }

    /// The buffer `label` of `bytes` (at least 64) with `usage`.
    pub fn buffer(
        &mut self,
        d: &wgpu::Device,
        label: &'static str,
        bytes: u64,
        usage: wgpu::BufferUsages,
    ) -> wgpu::Buffer {
        let size = bytes.max(64).next_multiple_of(4);
        if let Some(b) = self.buffers.get(label)
            && b.size() == size
            && b.usage() == usage
        {
            return b.clone();
        }
        self.created += 1;
        let b = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage,
            mapped_at_creation: false,
        });
        self.buffers.insert(label, b.clone());
        b
    }

    /// The buffer `label` holding `bytes`, written through the queue (it is in place before
    /// the next submission).
    pub fn upload(
        &mut self,
        ctx: &super::GpuContext,
        label: &'static str,
        bytes: &[u8],
        usage: wgpu::BufferUsages,
    ) -> wgpu::Buffer {
        let b = self.buffer(
            &ctx.device,
            label,
            bytes.len() as u64,
            usage | wgpu::BufferUsages::COPY_DST,
        );
        if !bytes.is_empty() {
            ctx.queue.write_buffer(&b, 0, bytes);
        }
        b
    }
}

/// Copies `buf` (made with COPY_SRC) back to the CPU, waiting for the GPU (tests and
/// inspection; a frame reads back through its recorder instead).
pub fn read_buffer(ctx: &GpuContext, buf: &wgpu::Buffer) -> Result<Vec<u8>, RenderError> {
    let d = &ctx.device;
    let read = d.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: buf.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("readback"),
    });
    enc.copy_buffer_to_buffer(buf, 0, &read, 0, buf.size());
    ctx.queue.submit([enc.finish()]);
    map_read(ctx, &read)
}

/// Maps `read` (MAP_READ, its copies submitted), waits, and returns its bytes.
pub fn map_read(ctx: &GpuContext, read: &wgpu::Buffer) -> Result<Vec<u8>, RenderError> {
    let slice = read.slice(..);
    slice.map_async(wgpu::MapMode::Read, |_| {});
    ctx.wait();
    let bytes = slice
        .get_mapped_range()
        .map_err(|e| RenderError::Gpu(format!("cannot read a buffer back: {e}")))?
        .to_vec();
    read.unmap();
    Ok(bytes)
}

/// Bytes per row of a texture copy of `width` texels of `texel` bytes (256-aligned).
pub fn row_bytes(width: u32, texel: u64) -> u64 {
    (width as u64 * texel).div_ceil(256) * 256
}

/// Records a copy of 2D texture `tex` into `read` (rows of [`row_bytes`]).
pub fn copy_texture(enc: &mut wgpu::CommandEncoder, tex: &wgpu::Texture, read: &wgpu::Buffer) {
    let texel = texel_bytes(tex.format());
    enc.copy_texture_to_buffer(
        tex.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: read,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row_bytes(tex.width(), texel) as u32),
                rows_per_image: Some(tex.height()),
            },
        },
        wgpu::Extent3d {
            width: tex.width(),
            height: tex.height(),
            depth_or_array_layers: 1,
        },
    );
}

/// The texels of a 4-channel image (Rgba32Float, or Rgba16Float widened) of `w` × `h` from the
/// bytes of [`copy_texture`].
pub fn texels(bytes: &[u8], w: u32, h: u32, half: bool) -> Vec<[f32; 4]> {
    let texel = if half { 8u64 } else { 16 };
    let row = row_bytes(w, texel);
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h as u64 {
        let r = &bytes[(y * row) as usize..][..(w as u64 * texel) as usize];
        if half {
            let v: &[u16] = bytemuck::cast_slice(r);
            out.extend(
                v.chunks_exact(4)
                    .map(|c| [0, 1, 2, 3].map(|k| half::f16::from_bits(c[k]).to_f32())),
            );
        } else {
            let v: &[f32] = bytemuck::cast_slice(r);
            out.extend(v.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]));
        }
    }
    out
}

/// The bytes of a texel of the 4-channel formats the frames copy back.
pub fn texel_bytes(format: wgpu::TextureFormat) -> u64 {
    match format {
        wgpu::TextureFormat::Rgba16Float => 8,
        wgpu::TextureFormat::Rgba8Unorm => 4,
        _ => 16,
    }
}

/// The bytes of a 2D texture of 4 channels copied back to the CPU (rows of [`row_bytes`]),
/// waiting (tests, inspection, screenshots).
pub fn read_texture_bytes(ctx: &GpuContext, tex: &wgpu::Texture) -> Result<Vec<u8>, RenderError> {
    let read = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("texture readback"),
        size: row_bytes(tex.width(), texel_bytes(tex.format())) * tex.height() as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("texture readback"),
        });
    copy_texture(&mut enc, tex, &read);
    ctx.queue.submit([enc.finish()]);
    map_read(ctx, &read)
}

/// Copies a 2D texture of 4 channels (Rgba32Float or Rgba16Float) back to the CPU, waiting.
pub fn read_texture(ctx: &GpuContext, tex: &wgpu::Texture) -> Result<Vec<[f32; 4]>, RenderError> {
    let half = tex.format() == wgpu::TextureFormat::Rgba16Float;
    let bytes = read_texture_bytes(ctx, tex)?;
    Ok(texels(&bytes, tex.width(), tex.height(), half))
}
