//! Per-VPL paraboloid shadow maps, the brute-force baseline (vpl_shadow.wgsl, gather_batch.wgsl):
//! the VPLs in batches of `batch`; per batch a paraboloid distance map per VPL (one render pass
//! per layer, the VPL read from the VPL buffer by instance) and a gather of the batch's light
//! through them, added onto the image (ping-pong: 32-bit float targets are not blendable
//! everywhere). Memory stays bounded by the batch; each batch is submitted when recorded.

use super::gbuffer::GBufferOutput;
use super::shade::{frame_pass, frame_target};
use super::shadow_maps::DistancePass;
use crate::RenderError;
use crate::gpu::context::{
    Pool, array_view, bind_group, compute_pipelines, layer_view, render_pipeline, slice,
};
use crate::gpu::geometry::positions;
use crate::gpu::layout::{Batch, MapParams, UNIFORM_STRIDE, strided};
use crate::gpu::shaders::ShaderSources;
use crate::gpu::timing::Recorder;
use crate::gpu::{Frame, shaders};

/// Parameters of mode `per-vpl-shadow-maps`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerVplParams {
    /// Paraboloid map side per VPL. [Units: texels] [Limit: 16..=2048]
    pub map_size: u32,
    /// VPL maps rendered and gathered per batch (bounds their memory). [Limit: 1..=2048]
    pub batch: u32,
}

impl Default for PerVplParams {
    fn default() -> Self {
        PerVplParams {
            map_size: 128,
            batch: 128,
        }
    }
}

impl PerVplParams {
    /// Checks the limits.
    pub fn check(&self) -> Result<(), RenderError> {
        if !(16..=2048).contains(&self.map_size) || !(1..=2048).contains(&self.batch) {
            return Err(RenderError::Param(format!(
                "VPL map size {} must be 16..=2048 and VPL batch {} 1..=2048",
                self.map_size, self.batch
            )));
        }
        Ok(())
    }
}

/// The paraboloid map pipelines (per VPL, per VAL) and the batch gather.
pub struct ParaboloidMaps {
    /// A VPL's map: vertex entry `vs`.
    pub vpl: wgpu::RenderPipeline,
    /// A VAL's map: vertex entry `vs_val`.
    pub val: wgpu::RenderPipeline,
    gather: wgpu::ComputePipeline,
}

impl ParaboloidMaps {
    /// Builds the pipelines.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<ParaboloidMaps, RenderError> {
        let maps = shaders::module(d, s, "vpl_shadow.wgsl")?;
        let r32 = [wgpu::TextureFormat::R32Float];
        let gather = shaders::module(d, s, "gather_batch.wgsl")?;
        let [gather] = compute_pipelines(d, &gather, ["cs"]);
        Ok(ParaboloidMaps {
            vpl: render_pipeline(
                d,
                "vpl maps",
                &maps,
                ("vs", "fs"),
                &[Some(positions(12))],
                &r32,
                Some(wgpu::CompareFunction::Less),
            ),
            val: render_pipeline(
                d,
                "val maps",
                &maps,
                ("vs_val", "fs"),
                &[Some(positions(12))],
                &r32,
                Some(wgpu::CompareFunction::Less),
            ),
            gather,
        })
    }

    /// Records every batch's maps and gather onto `out`.
    pub fn record(
        &self,
        f: &Frame,
        p: &PerVplParams,
        pool: &mut Pool,
        rec: &mut Recorder,
        (g, out): (&GBufferOutput, &wgpu::Texture),
    ) {
        let n = f.vpl_count as usize;
        if n == 0 {
            return;
        }
        let most = f.ctx.device.limits().max_texture_array_layers;
        let batch = p.batch.min(most).max(1) as usize;
        let batches: Vec<Batch> = (0..n.div_ceil(batch))
            .map(|b| Batch {
                first: (b * batch) as u32,
                count: batch.min(n - b * batch) as u32,
                map_size: p.map_size,
                g_max: f.params.g_max,
                normal_offset: f.params.shadows.normal_offset,
                bias: f.params.shadows.bias,
                ..bytemuck::Zeroable::zeroed()
            })
            .collect();
        let other = frame_target(f, pool, "hdr (ping-pong)");
        let t = self.targets(f, pool, (p.map_size, batch as u32), &batches, [out, &other]);
        let mut current = 0;
        for (bi, b) in batches.iter().enumerate() {
            let span = rec.begin("VPL paraboloid maps");
            for k in 0..b.count {
                DistancePass {
                    color: &t.layers[k as usize],
                    depth: &t.depth,
                    pipeline: &self.vpl,
                    bind_group: &t.map_group,
                    vertices: &f.scene.geometry.vpl_vertices,
                    count: f.scene.geometry.vpl_vertex_count,
                    instances: b.first + k..b.first + k + 1,
                }
                .record(&mut rec.enc, span.render(k == 0, k + 1 == b.count));
            }
            rec.end();
            self.record_gather(f, rec, (&t, g), bi, current);
            current = 1 - current;
            // Each batch goes to the GPU as soon as it is recorded (no wait): with a thousand
            // render passes in one command buffer the GPU would idle while they are recorded
            // (H100: 1,024 VPLs at 512², 239 → 178 ms a frame).
            rec.submit();
        }
        if current == 1 {
            rec.enc
                .copy_texture_to_texture(other.as_image_copy(), out.as_image_copy(), out.size());
        }
    }

    /// The maps (`m`² texels, `batch` layers), their depth, the batches' constants and the
    /// ping-pong pair's views for one frame.
    fn targets(
        &self,
        f: &Frame,
        pool: &mut Pool,
        (m, batch): (u32, u32),
        batches: &[Batch],
        pair: [&wgpu::Texture; 2],
    ) -> Targets {
        let d = &f.ctx.device;
        let maps = pool.texture(
            d,
            "vpl paraboloid maps",
            [m, m, batch],
            1,
            wgpu::TextureFormat::R32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let depth = pool.texture(
            d,
            "vpl map depth",
            [m, m, 1],
            1,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let uniform = wgpu::BufferUsages::UNIFORM;
        let map_params = MapParams {
            far: f.scene.far_m,
            ..bytemuck::Zeroable::zeroed()
        };
        let params_buf = pool.upload(
            f.ctx,
            "map params",
            bytemuck::bytes_of(&map_params),
            uniform,
        );
        let batch_buf = pool.upload(f.ctx, "batches", &strided(batches), uniform);
        Targets {
            pair: pair.map(|t| t.create_view(&Default::default())),
            layers: (0..batch).map(|l| layer_view(&maps, l)).collect(),
            maps: array_view(&maps),
            depth: depth.create_view(&Default::default()),
            map_group: bind_group(
                d,
                &self.vpl.get_bind_group_layout(0),
                "vpl maps",
                vec![
                    (0, params_buf.as_entire_binding()),
                    (1, f.vpls.as_entire_binding()),
                ],
            ),
            batches: batch_buf,
        }
    }

    /// Records batch `bi`'s gather through its maps, from the pair's `current` target into
    /// the other.
    fn record_gather(
        &self,
        f: &Frame,
        rec: &mut Recorder,
        (t, g): (&Targets, &GBufferOutput),
        bi: usize,
        current: usize,
    ) {
        let tex = wgpu::BindingResource::TextureView;
        let size = size_of::<Batch>() as u64;
        let bg = bind_group(
            &f.ctx.device,
            &self.gather.get_bind_group_layout(0),
            "gather batch",
            vec![
                (0, slice(&t.batches, (bi * UNIFORM_STRIDE) as u64, size)),
                (1, f.vpls.as_entire_binding()),
                (2, tex(&t.maps)),
                (3, tex(&g.views[0])),
                (4, tex(&g.views[1])),
                (5, tex(&g.views[2])),
                (6, tex(&t.pair[current])),
                (7, tex(&t.pair[1 - current])),
            ],
        );
        let span = rec.begin("VPL gather");
        frame_pass(
            &mut rec.enc,
            "gather batch",
            &self.gather,
            &[&bg],
            span.compute(),
            f.view.size,
        );
        rec.end();
    }

    /// Records a paraboloid distance map per VAL of `vals` (`m` of them, `s`² each; one render
    /// pass per layer: wgpu has no layered rendering without multiview), each VAL's centre
    /// moved off its surface by the near plane's hair; returns the maps.
    pub fn record_vals(
        &self,
        f: &Frame,
        vals: &wgpu::Buffer,
        (m, s): (u32, u32),
        pool: &mut Pool,
        rec: &mut Recorder,
    ) -> wgpu::Texture {
        let d = &f.ctx.device;
        let maps = pool.texture(
            d,
            "val maps",
            [s, s, m],
            1,
            wgpu::TextureFormat::R32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let depth = pool.texture(
            d,
            "val map depth",
            [s, s, 1],
            1,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let map_params = MapParams {
            far: f.scene.far_m,
            centre_offset: f.scene.near_m,
            ..bytemuck::Zeroable::zeroed()
        };
        let uniform = wgpu::BufferUsages::UNIFORM;
        let params_buf = pool.upload(
            f.ctx,
            "val map params",
            bytemuck::bytes_of(&map_params),
            uniform,
        );
        let map_bg = bind_group(
            d,
            &self.val.get_bind_group_layout(0),
            "val maps",
            vec![
                (0, params_buf.as_entire_binding()),
                (2, vals.as_entire_binding()),
            ],
        );
        let depth_view = depth.create_view(&Default::default());
        let span = rec.begin("VAL paraboloid maps");
        for k in 0..m {
            DistancePass {
                color: &layer_view(&maps, k),
                depth: &depth_view,
                pipeline: &self.val,
                bind_group: &map_bg,
                vertices: &f.scene.geometry.vpl_vertices,
                count: f.scene.geometry.vpl_vertex_count,
                instances: k..k + 1,
            }
            .record(&mut rec.enc, span.render(k == 0, k + 1 == m));
        }
        rec.end();
        maps
    }
}

/// A frame's per-VPL maps and what their passes read.
struct Targets {
    /// The ping-pong pair's views (the output first).
    pair: [wgpu::TextureView; 2],
    /// A map layer's view each.
    layers: Vec<wgpu::TextureView>,
    /// The maps as an array.
    maps: wgpu::TextureView,
    /// The maps' depth buffer.
    depth: wgpu::TextureView,
    /// The maps' pass's bind group.
    map_group: wgpu::BindGroup,
    /// The batches' constants, strided.
    batches: wgpu::Buffer,
}
