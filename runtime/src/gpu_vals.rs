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
    /// x VPLs, y VALs, z interleaving subsets B.
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
    bucket_counts: wgpu::ComputePipeline,
    offsets: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
}

impl Pipelines {
    pub(super) fn new(d: &wgpu::Device, source: &str) -> Pipelines {
        let [
            init,
            assign,
            update,
            finish,
            bucket_counts,
            offsets,
            scatter,
        ] = super::compute_pipelines(
            d,
            "vals.wgsl",
            source,
            [
                "init",
                "assign",
                "update",
                "finish",
                "bucket_counts",
                "offsets",
                "scatter",
            ],
        );
        Pipelines {
            init,
            assign,
            update,
            finish,
            bucket_counts,
            offsets,
            scatter,
        }
    }
}

/// The VALs and the mapping C on the GPU.
pub(super) struct Buffers {
    pub vals: wgpu::Buffer,
    pub mapping: wgpu::Buffer,
    /// M·B + 1 offsets, then the VPL indices sorted by VAL and interleaving subset.
    pub order: wgpu::Buffer,
}

impl GpuRenderer {
    /// Clusters `vpls` (already in `vpl_buf`) into VALs on the GPU, recording into `enc`.
    /// The normalising length D comes from the VPLs on the CPU (they pass through it).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn val_passes(
        &self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        vpls: &[Vpl],
        vpl_buf: &wgpu::Buffer,
        params: &ValParams,
        subsets: u32,
        timestamps: Option<wgpu::ComputePassTimestampWrites>,
    ) -> Result<Buffers, RenderError> {
        params.check()?;
        let d = &ctx.device;
        let (n, m) = (vpls.len() as u32, params.count);
        let subsets = subsets.max(1);
        let max = d.limits().max_compute_workgroups_per_dimension;
        if n.div_ceil(64) > max {
            return Err(RenderError::Param(format!(
                "{n} VPLs need more workgroups than the adapter's {max}"
            )));
        }
        let frame = ValFrame {
            counts: [n, m, subsets, 0],
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
        // Last frame's centres (warm start), or the restart from the VPLs.
        let last = params
            .warm_start
            .then(|| self.val_centres.lock().ok()?.take())
            .flatten()
            .filter(|(count, _)| *count == m);
        let restart = last.is_none();
        let centres = match last {
            Some((_, b)) => b,
            None => buf("val centres", m as u64 * 32),
        };
        let mapping = buf("vpl → val", n as u64 * 4);
        let vals = buf("vals", m as u64 * std::mem::size_of::<Val>() as u64);
        let buckets = m as u64 * subsets as u64;
        let order = buf("vpls by val", (buckets + 1 + n as u64) * 4);
        let p = &self.val_pipelines;
        let bind = |pipeline: &wgpu::ComputePipeline, with: &[(u32, &wgpu::Buffer)]| {
            let resources = with
                .iter()
                .map(|&(binding, b)| (binding, b.as_entire_binding()))
                .collect();
            super::bind_group(d, &pipeline.get_bind_group_layout(0), "vals", resources)
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
        let counts_bg = bind(&p.bucket_counts, &[base[0], (3, &mapping), (5, &order)]);
        let offsets_bg = bind(&p.offsets, &[base[0], (5, &order)]);
        let scatter_bg = bind(&p.scatter, &[base[0], (3, &mapping), (5, &order)]);
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("val clustering"),
            timestamp_writes: timestamps,
        });
        if n > 0 {
            let (gv, gm) = (n.div_ceil(64), m.div_ceil(64));
            if restart {
                pass.set_pipeline(&p.init);
                pass.set_bind_group(0, &init_bg, &[]);
                pass.dispatch_workgroups(gm, 1, 1);
            }
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
            let gb = (buckets as u32).div_ceil(64);
            pass.set_pipeline(&p.bucket_counts);
            pass.set_bind_group(0, &counts_bg, &[]);
            pass.dispatch_workgroups(gb, 1, 1);
            pass.set_pipeline(&p.offsets);
            pass.set_bind_group(0, &offsets_bg, &[]);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&p.scatter);
            pass.set_bind_group(0, &scatter_bg, &[]);
            pass.dispatch_workgroups(gb, 1, 1);
        }
        drop(pass);
        if let Ok(mut keep) = self.val_centres.lock() {
            *keep = Some((m, centres.clone()));
        }
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
        let b = self.val_passes(ctx, &mut enc, vpls, &vpl_buf, params, 1, None)?;
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
    /// x VPLs, y VALs, z map size (texels), w Fourier terms K.
    pub counts: [u32; 4],
    /// x g_max (1/m²), y normal offset (texels), z bias (texels), w VAL centre offset (m).
    pub params: [f32; 4],
    /// x receiver offset (normalised depth), y sharpening s, z normal offset (texels).
    pub cssm: [f32; 4],
    /// x interleaving block side b (1: none), y subsets b².
    pub interleave: [u32; 4],
    /// x blur distance threshold (m), y blur normal threshold (cosine).
    pub blur: [f32; 4],
}

/// Constants of the CSSM passes, shared with WGSL (`CssmFrame` in cssm.wgsl).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct CssmFrame {
    /// x VALs, y terms K, z groups ⌈K/2⌉, w map size.
    pub counts: [u32; 4],
    /// x size of the mip level being written.
    pub level: [u32; 4],
}

/// The CSSM pipelines and the two VAL gathers.
pub(super) struct CssmPipelines {
    ranges: wgpu::ComputePipeline,
    basis: wgpu::ComputePipeline,
    downsample: wgpu::ComputePipeline,
    gather_hard: wgpu::RenderPipeline,
    gather_cssm: wgpu::RenderPipeline,
    compose: wgpu::RenderPipeline,
}

impl CssmPipelines {
    pub(super) fn new(d: &wgpu::Device, cssm: &str, gather: &str) -> CssmPipelines {
        let module = |label: &str, src: &str| {
            d.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(src.into()),
            })
        };
        let gm = module("val_gather.wgsl", gather);
        let [ranges, basis, downsample] =
            super::compute_pipelines(d, "cssm.wgsl", cssm, ["ranges_of", "basis", "downsample"]);
        let fullscreen = |entry: &str| {
            d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(entry),
                layout: None,
                vertex: wgpu::VertexState {
                    module: &gm,
                    entry_point: Some("vs"),
                    buffers: &[],
                    compilation_options: Default::default(),
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &gm,
                    entry_point: Some(entry),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: wgpu::TextureFormat::Rgba32Float,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                    compilation_options: Default::default(),
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        CssmPipelines {
            ranges,
            basis,
            downsample,
            gather_hard: fullscreen("fs_hard"),
            gather_cssm: fullscreen("fs_cssm"),
            compose: fullscreen("fs_compose"),
        }
    }
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
        let sharp = params.cssm_sharpness;
        let (blur_d, blur_n) = (params.blur_distance, params.blur_normal);
        if !(1..=16).contains(&params.interleave) {
            return Err(RenderError::Param(format!(
                "interleaving block {} must be 1..=16 pixels (1: every VPL at every pixel)",
                params.interleave
            )));
        }
        if !(blur_d >= 0.0 && blur_d.is_finite() && (-1.0..=1.0).contains(&blur_n)) {
            return Err(RenderError::Param(format!(
                "blur distance {blur_d} must be >= 0 (a fraction of the scene's size) and blur \
                 normal threshold {blur_n} a cosine in -1..=1"
            )));
        }
        let off = params.cssm_normal_offset;
        if !(1.0..=8.0).contains(&sharp) || !(0.0..=64.0).contains(&off) {
            return Err(RenderError::Param(format!(
                "CSSM sharpening {sharp} must be 1..=8 and normal offset {off} 0..=64 texels"
            )));
        }
        if !(16..=4096).contains(&s) {
            return Err(RenderError::Param(format!(
                "VAL map size {s} must be 16..=4096 texels"
            )));
        }
        let layers = d.limits().max_texture_array_layers;
        if m > layers {
            return Err(RenderError::Param(format!(
                "{m} VALs need {m} map layers, more than the adapter's {layers}: use fewer VALs"
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
        let block = params.interleave;
        let b = self.val_passes(
            ctx,
            &mut enc,
            vpls,
            vpl_buf,
            &params.vals,
            block * block,
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

        // 2b. val-cssm: depth ranges, the Fourier basis and its mips.
        let soft = params.mode == super::GpuMode::ValCssm;
        let terms = params.cssm_terms;
        let cssm = if soft {
            let t0 = Instant::now();
            let c = self.cssm_basis(ctx, &maps, m, s, terms, timer)?;
            times.cssm = t0.elapsed().as_secs_f64();
            Some(c)
        } else {
            None
        };

        // 3. The gather into an indirect target, then the compose (blur over the interleaving
        // block, × albedo, onto `out` through a copy: ping-pong).
        let t0 = Instant::now();
        let target = |label: &str| {
            super::texture(
                d,
                label,
                [out.width(), out.height(), 1],
                wgpu::TextureFormat::Rgba32Float,
                wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::COPY_SRC
                    | wgpu::TextureUsages::TEXTURE_BINDING,
            )
        };
        let indirect = target("indirect irradiance");
        let other = target("hdr (ping-pong)");
        let uniform = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("val gather"),
            contents: bytemuck::bytes_of(&ValGather {
                counts: [vpls.len() as u32, m, s, terms],
                params: [
                    params.g_max,
                    params.shadow_normal_offset,
                    params.shadow_bias,
                    offset,
                ],
                cssm: [
                    crate::cssm::receiver_offset(terms, params.cssm_sharpness),
                    params.cssm_sharpness,
                    params.cssm_normal_offset,
                    0.0,
                ],
                interleave: [block, block * block, 0, 0],
                blur: [blur_d * self.far_m / 4.0, blur_n, 0.0, 0.0],
            }),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let maps_view = maps.create_view(&wgpu::TextureViewDescriptor {
            label: Some("val maps"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let out_view = out.create_view(&Default::default());
        let indirect_view = indirect.create_view(&Default::default());
        let tex = wgpu::BindingResource::TextureView;
        let bind = |pipeline: &wgpu::RenderPipeline, entries: Vec<(u32, wgpu::BindingResource)>| {
            super::bind_group(d, &pipeline.get_bind_group_layout(0), "val gather", entries)
        };
        let mut entries: Vec<(u32, wgpu::BindingResource)> = vec![
            (0, uniform.as_entire_binding()),
            (1, vpl_buf.as_entire_binding()),
            (3, tex(&gviews[0])),
            (4, tex(&gviews[1])),
            (7, b.order.as_entire_binding()),
            (8, b.vals.as_entire_binding()),
        ];
        let pipeline = match &cssm {
            Some(c) => {
                entries.push((9, tex(&c.view)));
                entries.push((10, wgpu::BindingResource::Sampler(&c.sampler)));
                entries.push((11, c.ranges.as_entire_binding()));
                &self.cssm_pipelines.gather_cssm
            }
            None => {
                entries.push((2, tex(&maps_view)));
                &self.cssm_pipelines.gather_hard
            }
        };
        let bg = bind(pipeline, entries);
        let span = timer.span(Stage::VplGather);
        super::fullscreen_pass(
            ctx,
            "val gather",
            &indirect_view,
            pipeline,
            &bg,
            timer.writes(span, true, true),
        );
        times.vpl_gather = t0.elapsed().as_secs_f64();
        let t0 = Instant::now();
        let compose = &self.cssm_pipelines.compose;
        let bg = bind(
            compose,
            vec![
                (0, uniform.as_entire_binding()),
                (3, tex(&gviews[0])),
                (4, tex(&gviews[1])),
                (5, tex(&gviews[2])),
                (6, tex(&out_view)),
                (12, tex(&indirect_view)),
            ],
        );
        let span = timer.span(Stage::Blur);
        super::fullscreen_pass(
            ctx,
            "val compose",
            &other.create_view(&Default::default()),
            compose,
            &bg,
            timer.writes(span, true, true),
        );
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("ping-pong copy"),
        });
        enc.copy_texture_to_texture(other.as_image_copy(), out.as_image_copy(), out.size());
        ctx.queue.submit([enc.finish()]);
        ctx.wait();
        times.blur = t0.elapsed().as_secs_f64();
        Ok(())
    }
}

/// A VAL set's CSSM basis on the GPU.
pub(super) struct CssmBasis {
    /// All groups of all VALs, every mip level.
    pub view: wgpu::TextureView,
    /// Trilinear, clamped.
    pub sampler: wgpu::Sampler,
    /// Each VAL's depth range (m).
    pub ranges: wgpu::Buffer,
}

impl GpuRenderer {
    /// The CSSM basis of the VALs' distance `maps` (`m` layers of `size`²) with `terms` Fourier
    /// terms: depth ranges, the basis images, their mips (one dispatch per level, every layer).
    fn cssm_basis(
        &self,
        ctx: &GpuContext,
        maps: &wgpu::Texture,
        m: u32,
        size: u32,
        terms: u32,
        timer: &mut super::Timer,
    ) -> Result<CssmBasis, RenderError> {
        let d = &ctx.device;
        let groups = terms.div_ceil(2);
        let layers = (2 * groups + 1) * m;
        if !(1..=16).contains(&terms) || layers > d.limits().max_texture_array_layers {
            return Err(RenderError::Param(format!(
                "CSSM terms {terms} must be 1..=16, and its {layers} basis layers ({} per VAL) at \
                 most the adapter's {}: use fewer terms or VALs",
                2 * groups + 1,
                d.limits().max_texture_array_layers
            )));
        }
        let levels = size.ilog2() + 1;
        let basis = d.create_texture(&wgpu::TextureDescriptor {
            label: Some("cssm basis"),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: layers,
            },
            mip_level_count: levels,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let level_view = |l: u32| {
            basis.create_view(&wgpu::TextureViewDescriptor {
                label: Some("cssm level"),
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                base_mip_level: l,
                mip_level_count: Some(1),
                ..Default::default()
            })
        };
        let ranges = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("val depth ranges"),
            size: (m as u64 * 4).max(16),
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let uniform = |level: u32| {
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("cssm frame"),
                contents: bytemuck::bytes_of(&CssmFrame {
                    counts: [m, terms, groups, size],
                    level: [level, 0, 0, 0],
                }),
                usage: wgpu::BufferUsages::UNIFORM,
            })
        };
        let p = &self.cssm_pipelines;
        let maps_view = maps.create_view(&wgpu::TextureViewDescriptor {
            label: Some("val maps"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let bind = |pipeline: &wgpu::ComputePipeline,
                    entries: Vec<(u32, wgpu::BindingResource)>| {
            super::bind_group(d, &pipeline.get_bind_group_layout(0), "cssm", entries)
        };
        let tex = wgpu::BindingResource::TextureView;
        let u0 = uniform(size);
        let level0 = level_view(0);
        let ranges_bg = bind(
            &p.ranges,
            vec![
                (0, u0.as_entire_binding()),
                (1, tex(&maps_view)),
                (2, ranges.as_entire_binding()),
            ],
        );
        let basis_bg = bind(
            &p.basis,
            vec![
                (0, u0.as_entire_binding()),
                (1, tex(&maps_view)),
                (2, ranges.as_entire_binding()),
                (3, tex(&level0)),
            ],
        );
        let views: Vec<wgpu::TextureView> = (0..levels).map(level_view).collect();
        let uniforms: Vec<wgpu::Buffer> =
            (1..levels).map(|l| uniform((size >> l).max(1))).collect();
        let down_bgs: Vec<wgpu::BindGroup> = (1..levels as usize)
            .map(|l| {
                bind(
                    &p.downsample,
                    vec![
                        (0, uniforms[l - 1].as_entire_binding()),
                        (3, tex(&views[l])),
                        (4, tex(&views[l - 1])),
                    ],
                )
            })
            .collect();
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("cssm"),
        });
        {
            let span = timer.span(super::Stage::Cssm);
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cssm basis"),
                timestamp_writes: timer.compute_writes(span),
            });
            pass.set_pipeline(&p.ranges);
            pass.set_bind_group(0, &ranges_bg, &[]);
            pass.dispatch_workgroups(m, 1, 1);
            pass.set_pipeline(&p.basis);
            pass.set_bind_group(0, &basis_bg, &[]);
            pass.dispatch_workgroups(size.div_ceil(8), size.div_ceil(8), m);
            pass.set_pipeline(&p.downsample);
            for (l, bg) in (1..levels).zip(&down_bgs) {
                let s = (size >> l).max(1);
                pass.set_bind_group(0, bg, &[]);
                pass.dispatch_workgroups(s.div_ceil(8), s.div_ceil(8), layers);
            }
        }
        ctx.queue.submit([enc.finish()]);
        ctx.wait();
        let sampler = d.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("cssm basis"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        Ok(CssmBasis {
            view: basis.create_view(&wgpu::TextureViewDescriptor {
                label: Some("cssm basis"),
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            }),
            sampler,
            ranges,
        })
    }
}
