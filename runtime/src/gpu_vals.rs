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
        }
    }
}

/// The VALs and the mapping C on the GPU.
pub(super) struct Buffers {
    pub vals: wgpu::Buffer,
    pub mapping: wgpu::Buffer,
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
        }
        drop(pass);
        Ok(Buffers { vals, mapping })
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
