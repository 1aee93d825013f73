//! Virtual area lights on the GPU (`vals.wgsl`): k-means of the VPLs into VALs, restarted
//! each frame from the same assignment, then each VAL's count, flux and rectangle. The CPU
//! twin is [`crate::val`].

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

use super::{GpuContext, GpuRenderer};
use crate::RenderError;
use crate::val::{Clustering, Val, ValParams, scale_of};
use crate::vpl::Vpl;

/// Per-frame constants of the clustering, shared with WGSL (`ValFrame` in vals.wgsl).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct ValFrame {
    /// x VPLs, y VALs.
    pub counts: [u32; 4],
    /// x w_x, y w_α, z 1 / D.
    pub weights: [f32; 4],
}

/// The clustering pipelines.
pub(super) struct Pipelines {
    init: wgpu::ComputePipeline,
    assign: wgpu::ComputePipeline,
    update: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    offsets: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
}

impl Pipelines {
    pub(super) fn new(d: &wgpu::Device, source: &str) -> Pipelines {
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("vals.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipe = |entry: &str| {
            d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: None,
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        Pipelines {
            init: pipe("init"),
            assign: pipe("assign"),
            update: pipe("update"),
            finish: pipe("finish"),
            offsets: pipe("offsets"),
            scatter: pipe("scatter"),
        }
    }
}

/// The VALs and the mapping C on the GPU.
pub(super) struct Buffers {
    pub vals: wgpu::Buffer,
    pub mapping: wgpu::Buffer,
    /// M + 1 offsets, then the VPL indices sorted by VAL.
    pub order: wgpu::Buffer,
}

impl GpuRenderer {
    /// Clusters `vpls` (already in `vpl_buf`) into VALs on the GPU, recording into `enc`.
    /// The normalising length D comes from the VPLs on the CPU (they pass through it).
    pub(super) fn val_passes(
        &self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        vpls: &[Vpl],
        vpl_buf: &wgpu::Buffer,
        params: &ValParams,
        timestamps: Option<wgpu::ComputePassTimestampWrites>,
    ) -> Result<Buffers, RenderError> {
        params.check()?;
        let d = &ctx.device;
        let (n, m) = (vpls.len() as u32, params.count);
        let max = d.limits().max_compute_workgroups_per_dimension;
        if n.div_ceil(64) > max {
            return Err(RenderError::Param(format!(
                "{n} VPLs need more workgroups than the adapter's {max}"
            )));
        }
        let frame = ValFrame {
            counts: [n, m, 0, 0],
            weights: [params.w_x, params.w_alpha, 1.0 / scale_of(vpls), 0.0],
        };
        let frame_buf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("val frame"),
            contents: bytemuck::bytes_of(&frame),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let buf = |label: &str, bytes: u64| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage: rw,
                mapped_at_creation: false,
            })
        };
        let centres = buf("val centres", m as u64 * 32);
        let mapping = buf("vpl → val", n as u64 * 4);
        let vals = buf("vals", m as u64 * std::mem::size_of::<Val>() as u64);
        let order = buf("vpls by val", (m as u64 + 1 + n as u64) * 4);
        let p = &self.val_pipelines;
        let bind = |pipeline: &wgpu::ComputePipeline, with: &[(u32, &wgpu::Buffer)]| {
            let entries: Vec<wgpu::BindGroupEntry> = with
                .iter()
                .map(|&(binding, b)| wgpu::BindGroupEntry {
                    binding,
                    resource: b.as_entire_binding(),
                })
                .collect();
            d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("vals"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            })
        };
        let base = [(0, &frame_buf), (1, vpl_buf), (2, &centres)];
        let init_bg = bind(&p.init, &base);
        let with_map = [base[0], base[1], base[2], (3, &mapping)];
        let assign_bg = bind(&p.assign, &with_map);
        let update_bg = bind(&p.update, &with_map);
        let finish_bg = bind(
            &p.finish,
            &[base[0], base[1], base[2], (3, &mapping), (4, &vals)],
        );
        let offsets_bg = bind(&p.offsets, &[base[0], (4, &vals), (5, &order)]);
        let scatter_bg = bind(&p.scatter, &[base[0], (3, &mapping), (5, &order)]);
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("val clustering"),
            timestamp_writes: timestamps,
        });
        if n > 0 {
            let (gv, gm) = (n.div_ceil(64), m.div_ceil(64));
            pass.set_pipeline(&p.init);
            pass.set_bind_group(0, &init_bg, &[]);
            pass.dispatch_workgroups(gm, 1, 1);
            for _ in 0..params.iterations {
                pass.set_pipeline(&p.assign);
                pass.set_bind_group(0, &assign_bg, &[]);
                pass.dispatch_workgroups(gv, 1, 1);
                pass.set_pipeline(&p.update);
                pass.set_bind_group(0, &update_bg, &[]);
                pass.dispatch_workgroups(gm, 1, 1);
            }
            pass.set_pipeline(&p.assign);
            pass.set_bind_group(0, &assign_bg, &[]);
            pass.dispatch_workgroups(gv, 1, 1);
            pass.set_pipeline(&p.finish);
            pass.set_bind_group(0, &finish_bg, &[]);
            pass.dispatch_workgroups(gm, 1, 1);
            pass.set_pipeline(&p.offsets);
            pass.set_bind_group(0, &offsets_bg, &[]);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&p.scatter);
            pass.set_bind_group(0, &scatter_bg, &[]);
            pass.dispatch_workgroups(gm, 1, 1);
        }
        drop(pass);
        Ok(Buffers {
            vals,
            mapping,
            order,
        })
    }

    /// Clusters `vpls` into VALs on the GPU and reads them back (for tests and inspection).
    pub fn cluster_vals(
        &self,
        ctx: &GpuContext,
        vpls: &[Vpl],
        params: &ValParams,
    ) -> Result<Clustering, RenderError> {
        let d = &ctx.device;
        let vpl_buf = super::storage(d, "vpls", bytemuck::cast_slice(vpls));
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("vals"),
        });
        let b = self.val_passes(ctx, &mut enc, vpls, &vpl_buf, params, None)?;
        ctx.queue.submit([enc.finish()]);
        let m = params.count as usize;
        let vals: Vec<Val> = if vpls.is_empty() {
            vec![Zeroable::zeroed(); m]
        } else {
            bytemuck::cast_slice(&super::read_buffer(ctx, &b.vals)?)[..m].to_vec()
        };
        let mapping: Vec<u32> =
            bytemuck::cast_slice(&super::read_buffer(ctx, &b.mapping)?)[..vpls.len()].to_vec();
        Ok(Clustering {
            vals,
            mapping,
            scale_m: scale_of(vpls),
        })
    }
}

/// The centres of a clustering (to start the next frame from, or to compare).
pub fn centres_of(c: &Clustering) -> Vec<(Vec3, Vec3)> {
    c.vals
        .iter()
        .map(|v| (v.centre(), v.unit_normal()))
        .collect()
}

/// Constants of the VAL maps' vertex stage, shared with WGSL (`ValMaps` in vpl_shadow.wgsl).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct ValMaps {
    /// x far distance (m), y VAL centre offset along its normal (m).
    pub params: [f32; 4],
}

/// Constants of the VAL gather, shared with WGSL (`ValGather` in val_gather.wgsl).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct ValGather {
    /// x VPLs, y VALs, z map size (texels).
    pub counts: [u32; 4],
    /// x g_max (1/m²), y normal offset (texels), z bias (texels), w VAL centre offset (m).
    pub params: [f32; 4],
}

impl GpuRenderer {
    /// The VAL modes after the direct light: cluster `vpls` into VALs, render a paraboloid
    /// distance map per VAL (one pass per layer: wgpu has no layered rendering without
    /// multiview), then gather every VPL through its VAL's map, added onto `out`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn val_frame(
        &self,
        ctx: &GpuContext,
        params: &super::GpuParams,
        vpls: &[Vpl],
        vpl_buf: &wgpu::Buffer,
        gviews: &[wgpu::TextureView; 3],
        out: &wgpu::Texture,
        times: &mut super::PassTimes,
        timer: &mut super::Timer,
    ) -> Result<(), RenderError> {
        use super::Stage;
        use std::time::Instant;
        let d = &ctx.device;
        let (m, s) = (params.vals.count, params.val_map_size);
        if !(16..=4096).contains(&s) || m > d.limits().max_texture_array_layers {
            return Err(RenderError::Param(format!(
                "VAL map size {s} must be 16..=4096 and VALs {m} at most the adapter's {} layers",
                d.limits().max_texture_array_layers
            )));
        }
        // The VAL's centre, a mean of VPLs, may sit on (or just inside) a surface: move it off
        // by a hair, relative to the scene.
        let offset = self.near_m;
        // 1. Clustering.
        let t0 = Instant::now();
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("val clustering"),
        });
        let span = timer.span(Stage::ValClustering);
        let b = self.val_passes(
            ctx,
            &mut enc,
            vpls,
            vpl_buf,
            &params.vals,
            timer.compute_writes(span),
        )?;
        ctx.queue.submit([enc.finish()]);
        ctx.wait();
        times.val_clustering = t0.elapsed().as_secs_f64();

        // 2. A paraboloid distance map per VAL.
        let t0 = Instant::now();
        let maps = super::texture(
            d,
            "val maps",
            [s, s, m],
            wgpu::TextureFormat::R32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let depth = super::texture(
            d,
            "val map depth",
            [s, s, 1],
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let depth_view = depth.create_view(&Default::default());
        let maps_uniform = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("val maps"),
            contents: bytemuck::bytes_of(&ValMaps {
                params: [self.far_m, offset, 0.0, 0.0],
            }),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("val maps"),
            layout: &self.val_shadow.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: maps_uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: b.vals.as_entire_binding(),
                },
            ],
        });
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("val maps"),
        });
        let span = timer.span(Stage::VplMaps);
        for k in 0..m {
            let layer = maps.create_view(&wgpu::TextureViewDescriptor {
                label: Some("val map layer"),
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: k,
                array_layer_count: Some(1),
                ..Default::default()
            });
            super::distance_pass(
                &mut enc,
                "val map",
                &layer,
                &depth_view,
                &self.val_shadow,
                &bg,
                &self.vpl_vertices,
                self.vpl_vertex_count,
                k..k + 1,
                timer.writes(span, k == 0, k + 1 == m),
            );
        }
        ctx.queue.submit([enc.finish()]);
        ctx.wait();
        times.vpl_maps = t0.elapsed().as_secs_f64();

        // 3. The gather, read from `out` and written to a copy (ping-pong), copied back.
        let t0 = Instant::now();
        let other = super::texture(
            d,
            "hdr (ping-pong)",
            [out.width(), out.height(), 1],
            wgpu::TextureFormat::Rgba32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let uniform = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("val gather"),
            contents: bytemuck::bytes_of(&ValGather {
                counts: [vpls.len() as u32, m, s, 0],
                params: [
                    params.g_max,
                    params.shadow_normal_offset,
                    params.shadow_bias,
                    offset,
                ],
            }),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let maps_view = maps.create_view(&wgpu::TextureViewDescriptor {
            label: Some("val maps"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let out_view = out.create_view(&Default::default());
        let tex = wgpu::BindingResource::TextureView;
        let entries = [
            (0, uniform.as_entire_binding()),
            (1, vpl_buf.as_entire_binding()),
            (2, tex(&maps_view)),
            (3, tex(&gviews[0])),
            (4, tex(&gviews[1])),
            (5, tex(&gviews[2])),
            (6, tex(&out_view)),
            (7, b.order.as_entire_binding()),
            (8, b.vals.as_entire_binding()),
        ]
        .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource });
        let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("val gather"),
            layout: &self.val_gather.get_bind_group_layout(0),
            entries: &entries,
        });
        let span = timer.span(Stage::VplGather);
        super::fullscreen_pass(
            ctx,
            "val gather",
            &other.create_view(&Default::default()),
            &self.val_gather,
            &bg,
            timer.writes(span, true, true),
        );
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("ping-pong copy"),
        });
        enc.copy_texture_to_texture(other.as_image_copy(), out.as_image_copy(), out.size());
        ctx.queue.submit([enc.finish()]);
        ctx.wait();
        times.vpl_gather = t0.elapsed().as_secs_f64();
        Ok(())
    }
}
