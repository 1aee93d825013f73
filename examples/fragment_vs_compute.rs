//! The same per-pixel loop — the no-visibility gather of `--mode none`: every VPL's
//! geometry term summed at a pixel — run as a full-screen fragment shader and as a compute
//! shader, GPU time of each from timestamp queries. Whether the indirect passes, written as
//! fragment shaders, lose time to being fragment shaders on a GPU.
//!
//! `cargo run --release --example fragment_vs_compute -- [SIZE] [VPLS]` (default 512, 4096)

use visgate_runtime::gpu::GpuContext;
use wgpu::util::DeviceExt;

const SHADER: &str = r#"
struct Vpl { position: vec4<f32>, normal: vec4<f32>, flux: vec4<f32> };
@group(0) @binding(0) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(1) var<uniform> size: vec4<u32>;
@group(0) @binding(2) var out_tex: texture_storage_2d<rgba16float, write>;

fn gather(px: vec2<f32>) -> vec3<f32> {
    let uv = px / vec2<f32>(size.xy);
    let p = vec3<f32>(uv.x * 10.0, 0.0, uv.y * 10.0);
    let n = vec3<f32>(0.0, 1.0, 0.0);
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < size.z; i++) {
        let v = vpls[i];
        let d = v.position.xyz - p;
        let d2 = max(dot(d, d), 1e-4);
        let w = d * inverseSqrt(d2);
        let g = min(max(dot(n, w), 0.0) * max(-dot(v.normal.xyz, w), 0.0) / d2, 0.1);
        sum += v.flux.xyz * g;
    }
    return sum;
}

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(gather(frag.xy), 1.0);
}

@compute @workgroup_size(8, 8)
fn cs(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    textureStore(out_tex, id.xy, vec4<f32>(gather(vec2<f32>(id.xy) + 0.5), 1.0));
}
"#;

fn main() -> anyhow::Result<()> {
    let args: Vec<u32> = std::env::args()
        .skip(1)
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let (side, count) = (
        args.first().copied().unwrap_or(512),
        args.get(1).copied().unwrap_or(4096),
    );
    let ctx = GpuContext::new()?;
    // The device's own timestamps (GpuContext leaves lavapipe's out of its frames: they are
    // wrong for compute passes, as this shows).
    if !ctx
        .device
        .features()
        .contains(wgpu::Features::TIMESTAMP_QUERY)
    {
        anyhow::bail!("{}: no timestamp queries", ctx.adapter_info.name);
    }
    let bench = Bench::new(&ctx, side, count);
    println!(
        "{} ({:?}), {side}x{side}, {count} VPLs a pixel",
        ctx.adapter_info.name, ctx.adapter_info.backend
    );
    for rep in 0..4 {
        let fragment_wall = bench.fragment(&ctx);
        let compute_wall = bench.compute(&ctx);
        let [fragment, compute] = bench.gpu_ms(&ctx)?;
        println!(
            "rep {rep}: GPU fragment {fragment:.3} ms, compute {compute:.3} ms; wall (submit + \
             wait) fragment {fragment_wall:.1} ms, compute {compute_wall:.1} ms",
        );
    }
    // Both wrote the same image (else a timing means nothing).
    let mean = |t: &wgpu::Texture| -> anyhow::Result<f64> {
        let px = visgate_runtime::gpu::context::read_texture(&ctx, t)?;
        Ok(px.iter().map(|p| f64::from(p[0])).sum::<f64>() / px.len() as f64)
    };
    let (f, c) = (mean(&bench.colour_tex)?, mean(&bench.storage_tex)?);
    println!("mean red: fragment {f:.6}, compute {c:.6}");
    anyhow::ensure!(
        (f - c).abs() <= 1e-3 * f.abs().max(1e-9),
        "the passes disagree"
    );
    Ok(())
}

/// `count` VPLs above a 10 m floor, facing down: position, normal and flux, 4 floats each.
fn vpl_data(count: u32) -> Vec<f32> {
    (0..count)
        .flat_map(|i| {
            let t = i as f32 * 0.618;
            let pos = [
                t.sin() * 5.0 + 5.0,
                3.0 + t.cos(),
                (t * 1.7).cos() * 5.0 + 5.0,
                1.0,
            ];
            [pos, [0.0, -1.0, 0.0, 0.0], [0.01, 0.01, 0.01, 0.0]]
        })
        .flatten()
        .collect()
}

/// The two passes over a `side`² target, their bind groups and the timestamp queries.
struct Bench {
    side: u32,
    fragment: wgpu::RenderPipeline,
    compute: wgpu::ComputePipeline,
    fragment_group: wgpu::BindGroup,
    compute_group: wgpu::BindGroup,
    colour_tex: wgpu::Texture,
    storage_tex: wgpu::Texture,
    colour: wgpu::TextureView,
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
}

impl Bench {
    /// The passes for `count` VPLs on a `side`² target.
    fn new(ctx: &GpuContext, side: u32, count: u32) -> Bench {
        let d = &ctx.device;
        let vpl_buf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("vpls"),
            contents: bytemuck::cast_slice(&vpl_data(count)),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let size_buf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("size"),
            contents: bytemuck::cast_slice(&[side, side, count, 0]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let target = |usage| {
            d.create_texture(&wgpu::TextureDescriptor {
                label: Some("target"),
                size: wgpu::Extent3d {
                    width: side,
                    height: side,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba16Float,
                usage,
                view_formats: &[],
            })
        };
        let copy = wgpu::TextureUsages::COPY_SRC;
        let colour_tex = target(wgpu::TextureUsages::RENDER_ATTACHMENT | copy);
        let storage_tex = target(wgpu::TextureUsages::STORAGE_BINDING | copy);
        let storage = storage_tex.create_view(&Default::default());
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("fragment_vs_compute"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let fmt = [wgpu::TextureFormat::Rgba16Float];
        let fragment = visgate_runtime::gpu::context::render_pipeline(
            d,
            "fs",
            &module,
            ("vs", "fs"),
            &[],
            &fmt,
            None,
        );
        let [compute] = visgate_runtime::gpu::context::compute_pipelines(d, &module, ["cs"]);
        let buffers = |layout: &wgpu::BindGroupLayout, with_storage: bool| {
            let mut entries = vec![
                (0, vpl_buf.as_entire_binding()),
                (1, size_buf.as_entire_binding()),
            ];
            if with_storage {
                entries.push((2, wgpu::BindingResource::TextureView(&storage)));
            }
            visgate_runtime::gpu::context::bind_group(d, layout, "fvc", entries)
        };
        let fragment_group = buffers(&fragment.get_bind_group_layout(0), false);
        let compute_group = buffers(&compute.get_bind_group_layout(0), true);
        let buffer = |label, usage| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 32,
                usage,
                mapped_at_creation: false,
            })
        };
        Bench {
            side,
            colour: colour_tex.create_view(&Default::default()),
            fragment,
            compute,
            fragment_group,
            compute_group,
            colour_tex,
            storage_tex,
            queries: d.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("fvc"),
                ty: wgpu::QueryType::Timestamp,
                count: 4,
            }),
            resolve: buffer(
                "resolve",
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            ),
            read: buffer(
                "read",
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            ),
        }
    }

    /// Runs the fragment pass (timestamps 0 and 1); its wall time, submit and wait, in ms.
    fn fragment(&self, ctx: &GpuContext) -> f64 {
        let wall = std::time::Instant::now();
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("fs"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &self.colour,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: Some(wgpu::RenderPassTimestampWrites {
                    query_set: &self.queries,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                }),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.fragment);
            pass.set_bind_group(0, &self.fragment_group, &[]);
            pass.draw(0..3, 0..1);
        }
        ctx.queue.submit([enc.finish()]);
        ctx.wait();
        wall.elapsed().as_secs_f64() * 1e3
    }

    /// Runs the compute pass (timestamps 2 and 3); its wall time, submit and wait, in ms.
    fn compute(&self, ctx: &GpuContext) -> f64 {
        let wall = std::time::Instant::now();
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cs"),
                timestamp_writes: Some(wgpu::ComputePassTimestampWrites {
                    query_set: &self.queries,
                    beginning_of_pass_write_index: Some(2),
                    end_of_pass_write_index: Some(3),
                }),
            });
            pass.set_pipeline(&self.compute);
            pass.set_bind_group(0, &self.compute_group, &[]);
            let groups = self.side.div_ceil(8);
            pass.dispatch_workgroups(groups, groups, 1);
        }
        ctx.queue.submit([enc.finish()]);
        ctx.wait();
        wall.elapsed().as_secs_f64() * 1e3
    }

    /// The GPU ms of the last fragment and compute passes, from their timestamps.
    fn gpu_ms(&self, ctx: &GpuContext) -> anyhow::Result<[f64; 2]> {
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        enc.resolve_query_set(&self.queries, 0..4, &self.resolve, 0);
        enc.copy_buffer_to_buffer(&self.resolve, 0, &self.read, 0, 32);
        ctx.queue.submit([enc.finish()]);
        let bytes = visgate_runtime::gpu::context::map_read(ctx, &self.read)?;
        let t: &[u64] = bytemuck::cast_slice(&bytes);
        let period = f64::from(ctx.queue.get_timestamp_period());
        Ok([0, 2].map(|a| (t[a + 1] - t[a]) as f64 * period * 1e-6))
    }
}
