//! VPLs from reflective shadow maps (rsm_vpls.wgsl; Dong et al. §6): each light's RSM (a
//! G-buffer from the light, `rsm_size`² per layer: 6 cube faces per point light, 1 per spot)
//! fetched at `count` Halton points in all, shared between the lights by power, rotated by
//! `seed`. The same lights give the same VPLs (no flicker). The VPLs are written straight into
//! the frame's VPL buffer: they stay on the GPU unless a caller asks for them
//! ([`crate::gpu::GpuRenderer::rsm_vpls`]).

use glam::Mat4;
use visgate_formats::Light as SceneLight;

use super::gbuffer::{Depth, FORMATS, GBuffer};
use super::shadow_maps::light_views;
use crate::RenderError;
use crate::gpu::context::{Pool, array_view, bind_group, compute_pipelines, layer_view, slice};
use crate::gpu::layout::{Globals, Light, RsmSample, ShadowView, UNIFORM_STRIDE, Vpl, strided};
use crate::gpu::shaders::ShaderSources;
use crate::gpu::shaders::{self, WG_LINEAR};
use crate::gpu::timing::Recorder;
use crate::gpu::{GpuContext, SceneGpu};

/// VPLs from the lights' RSMs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RsmParams {
    /// VPLs in all. [Limit: ≤ 2^24]
    pub count: u32,
    /// RSM side per layer. [Units: texels] [Limit: 16..=4096]
    pub rsm_size: u32,
    /// Rotation of the Halton points.
    pub seed: u64,
}

impl RsmParams {
    /// Checks the limits.
    pub fn check(&self) -> Result<(), RenderError> {
        if !(16..=4096).contains(&self.rsm_size) {
            return Err(RenderError::Param(format!(
                "RSM size {} must be 16..=4096",
                self.rsm_size
            )));
        }
        if self.count > 1 << 24 {
            return Err(RenderError::Param(format!(
                "{} RSM VPLs: at most {} are supported",
                self.count,
                1 << 24
            )));
        }
        Ok(())
    }
}

/// The RSM → VPL compute pipeline.
pub struct RsmVpls {
    pipeline: wgpu::ComputePipeline,
}

/// The Halton samples of the lights' RSM layers: (layer, texel) and power of each, in
/// [`crate::vpl_order`]'s order.
fn samples(
    lights: &[SceneLight],
    (gpu_lights, views): (&[Light], &[ShadowView]),
    p: &RsmParams,
) -> Vec<RsmSample> {
    let share = crate::vpl::share_by_power(lights, p.count);
    let s = p.rsm_size;
    let mut by_light = Vec::with_capacity(lights.len());
    for (li, l) in lights.iter().enumerate() {
        let m = share[li];
        let mut out = Vec::with_capacity(m as usize);
        let first = gpu_lights[li].layers[0];
        let shift = crate::vpl::seed_shift(p.seed ^ li as u64, 0);
        // Point lights and wide spots: six cube faces; other spots: their one frustum.
        let cube = gpu_lights[li].layers[1] == 6;
        for k in 0..m as u64 {
            let u = crate::vpl::halton2(k, 2, 3, shift);
            let (layer, x, y, half) = match *l {
                SceneLight::Spot { cutoff_rad, .. } if !cube => {
                    let t = cutoff_rad.tan();
                    (first, (u.x * 2.0 - 1.0) * t, (u.y * 2.0 - 1.0) * t, t)
                }
                _ => {
                    let f = ((u.x * 6.0) as u32).min(5);
                    (
                        first + f,
                        (u.x * 6.0 - f as f32) * 2.0 - 1.0,
                        u.y * 2.0 - 1.0,
                        1.0,
                    )
                }
            };
            let faces = if cube { 6.0 } else { 1.0 };
            // Direction through (x, y) on the layer's image plane at distance 1.
            let view = &views[layer as usize];
            // The layer's matrix takes points relative to the light.
            let inv = Mat4::from_cols_array_2d(&view.view_proj).inverse();
            let w = inv * glam::Vec4::new(x / half, y / half, 0.5, 1.0);
            let dir = (w.truncate() / w.w).normalize_or_zero();
            let solid = faces * 4.0 * half * half / m as f32 / (1.0 + x * x + y * y).powf(1.5);
            let power = crate::lights::intensity_towards(l, dir) * solid;
            let tx = (((x / half) * 0.5 + 0.5) * s as f32).clamp(0.0, s as f32 - 1.0) as u32;
            let ty = ((0.5 - (y / half) * 0.5) * s as f32).clamp(0.0, s as f32 - 1.0) as u32;
            out.push(vec![RsmSample {
                texel: [layer, tx, ty, 0],
                power: power.extend(0.0).to_array(),
            }]);
        }
        by_light.push(out);
    }
    crate::vpl_order::interleaving_order(by_light)
}

impl RsmVpls {
    /// Builds the pipeline.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<RsmVpls, RenderError> {
        let module = shaders::module(d, s, "rsm_vpls.wgsl")?;
        let [pipeline] = compute_pipelines(d, &module, ["main"]);
        Ok(RsmVpls { pipeline })
    }

    /// Records the RSMs and the VPL pass into `vpls` (grown to fit, kept in `pool`); returns
    /// the VPL buffer and the count (`p.count`, or 0 without lights or power).
    pub fn record(
        &self,
        ctx: &GpuContext,
        gbuffer: &GBuffer,
        scene: &SceneGpu,
        p: &RsmParams,
        pool: &mut Pool,
        rec: &mut Recorder,
    ) -> Result<(wgpu::Buffer, u32), RenderError> {
        p.check()?;
        let d = &ctx.device;
        let (gpu_lights, views) = light_views(scene);
        let samples = if views.is_empty() {
            Vec::new()
        } else {
            samples(&scene.lights, (&gpu_lights, &views), p)
        };
        let n = samples.len() as u32;
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let vpls = pool.buffer(d, "vpls", n as u64 * size_of::<Vpl>() as u64, usage);
        if n == 0 {
            return Ok((vpls, 0));
        }
        let layers = views.len() as u32;
        if layers > d.limits().max_texture_array_layers {
            return Err(RenderError::Param(format!(
                "{layers} RSM layers exceed the adapter's {}",
                d.limits().max_texture_array_layers
            )));
        }
        let groups = n.div_ceil(WG_LINEAR);
        let max = d.limits().max_compute_workgroups_per_dimension;
        if groups > max {
            return Err(RenderError::Param(format!(
                "{n} RSM VPLs need {groups} workgroups, more than the adapter's {max}"
            )));
        }
        let s = p.rsm_size;
        let rt = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let labels = ["rsm position", "rsm normal", "rsm albedo"];
        let maps = [0, 1, 2].map(|k| pool.texture(d, labels[k], [s, s, layers], 1, FORMATS[k], rt));
        let depth = pool.texture(
            d,
            "rsm depth",
            [s, s, 1],
            1,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let depth_view = depth.create_view(&Default::default());
        let globals: Vec<Globals> = views
            .iter()
            .map(|v| Globals {
                view_proj: v.world_view_proj().to_cols_array_2d(),
                eye: v.light,
                ..bytemuck::Zeroable::zeroed()
            })
            .collect();
        let uniform = wgpu::BufferUsages::UNIFORM;
        let globals_buf = pool.upload(ctx, "rsm globals", &strided(&globals), uniform);
        let sample_buf = pool.upload(
            ctx,
            "rsm samples",
            bytemuck::cast_slice(&samples),
            wgpu::BufferUsages::STORAGE,
        );
        let span = rec.begin("RSM VPLs");
        for i in 0..views.len() {
            let g = slice(
                &globals_buf,
                (i * UNIFORM_STRIDE) as u64,
                size_of::<Globals>() as u64,
            );
            let bg = gbuffer.bind_group(d, scene, g, &scene.no_grid);
            let targets = maps.each_ref().map(|t| layer_view(t, i as u32));
            gbuffer.draw(
                Depth::Standard,
                &mut rec.enc,
                scene,
                &targets,
                &depth_view,
                &bg,
                span.render(i == 0, false),
            );
        }
        let arrays = maps.each_ref().map(array_view);
        let bg = bind_group(
            d,
            &self.pipeline.get_bind_group_layout(0),
            "rsm vpls",
            vec![
                (
                    0,
                    slice(&sample_buf, 0, size_of_val(samples.as_slice()) as u64),
                ),
                (1, vpls.as_entire_binding()),
                (2, wgpu::BindingResource::TextureView(&arrays[0])),
                (3, wgpu::BindingResource::TextureView(&arrays[1])),
                (4, wgpu::BindingResource::TextureView(&arrays[2])),
            ],
        );
        {
            let writes = span.compute().map(|w| wgpu::ComputePassTimestampWrites {
                beginning_of_pass_write_index: None,
                ..w
            });
            let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("rsm vpls"),
                timestamp_writes: writes,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        rec.end();
        Ok((vpls, n))
    }
}
