//! The VAL modes after the direct light (val_gather.wgsl; Dong et al. §4): a paraboloid distance
//! map per VAL (one render pass per layer: wgpu has no layered rendering without multiview),
//! for `val-cssm` its convolution basis ([`super::cssm`]), then every VPL gathered through its
//! VAL's visibility — hard (`cs_hard`) or soft (`cs_cssm`) — into an indirect target, each pixel
//! with its interleaving subset, and the blur composing it ([`super::interleave_blur`]).

use super::cssm::{Cssm, CssmParams};
use super::gbuffer::GBufferOutput;
use super::interleave_blur::{InterleaveBlur, InterleaveParams};
use super::per_vpl_maps::ParaboloidMaps;
use super::shade::{frame_pass, frame_target};
use super::vals::{ValClustering, ValInput};
use crate::RenderError;
use crate::cpu::val::ValParams;
use crate::gpu::context::{Pool, array_view, bind_group, compute_pipelines};
use crate::gpu::layout::ValGather;
use crate::gpu::shaders::ShaderSources;
use crate::gpu::timing::Recorder;
use crate::gpu::{Frame, shaders};

/// Parameters of modes `val-hard` and `val-cssm`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ValModeParams {
    /// The clustering of VPLs into VALs.
    pub vals: ValParams,
    /// Paraboloid map side per VAL. [Units: texels] [Limit: 16..=4096]
    pub map_size: u32,
    /// Interleaved sampling and the blur.
    pub interleave: InterleaveParams,
}

impl ValModeParams {
    /// The defaults: 30 VALs, 256² maps, 8 × 8 interleaving.
    pub fn new() -> ValModeParams {
        ValModeParams {
            vals: ValParams::default(),
            map_size: 256,
            interleave: InterleaveParams::default(),
        }
    }

    /// Checks the limits (the VAL count against the adapter's layers at render time).
    pub fn check(&self) -> Result<(), RenderError> {
        self.vals.check()?;
        self.interleave.check()?;
        if !(16..=4096).contains(&self.map_size) {
            return Err(RenderError::Param(format!(
                "VAL map size {} must be 16..=4096 texels",
                self.map_size
            )));
        }
        Ok(())
    }
}

/// The VAL gathers (hard and CSSM).
pub struct ValGathers {
    hard: wgpu::ComputePipeline,
    cssm: wgpu::ComputePipeline,
    sampler: wgpu::Sampler,
}

/// The pipelines a VAL frame uses besides the gathers.
pub struct ValPasses<'a> {
    /// The clustering.
    pub clustering: &'a ValClustering,
    /// The VAL maps.
    pub maps: &'a ParaboloidMaps,
    /// The CSSM basis.
    pub cssm: &'a Cssm,
    /// The blur.
    pub blur: &'a InterleaveBlur,
}

impl ValGathers {
    /// Builds the pipelines.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<ValGathers, RenderError> {
        let m = shaders::module(d, s, "val_gather.wgsl")?;
        let [hard, cssm] = compute_pipelines(d, &m, ["cs_hard", "cs_cssm"]);
        Ok(ValGathers {
            hard,
            cssm,
            sampler: super::cssm::sampler(d),
        })
    }

    /// Records a VAL frame onto `out`: with `cssm` the soft mode. `warm`: start the
    /// clustering from last frame's centres. Returns the clustering's convergence words (none
    /// without VPLs).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        f: &Frame,
        p: &ValModeParams,
        cssm: Option<&CssmParams>,
        warm: bool,
        passes: &ValPasses,
        pool: &mut Pool,
        rec: &mut Recorder,
        (g, out): (&GBufferOutput, &wgpu::Texture),
    ) -> Result<Option<wgpu::Buffer>, RenderError> {
        p.check()?;
        let d = &f.ctx.device;
        let (m, s) = (p.vals.count, p.map_size);
        let layers = d.limits().max_texture_array_layers;
        if m > layers {
            return Err(RenderError::Param(format!(
                "{m} VALs need {m} map layers, more than the adapter's {layers}: use fewer VALs"
            )));
        }
        if f.vpl_count == 0 {
            return Ok(None);
        }
        let block = p.interleave.block;
        let input = ValInput {
            buffer: &f.vpls,
            count: f.vpl_count,
            cpu: f.vpls_cpu,
        };
        let b = passes
            .clustering
            .record(f.ctx, &input, &p.vals, block * block, warm, pool, rec)?;
        // The VAL's centre, a mean of VPLs, may sit on (or just inside) a surface: move it off
        // by a hair, relative to the scene.
        let offset = f.scene.near_m;
        let maps = passes.maps.record_vals(f, &b.vals, (m, s), pool, rec);
        let basis = match cssm {
            Some(c) => Some(passes.cssm.record(f.ctx, c, (&maps, m, s), pool, rec)?),
            None => None,
        };
        let c = cssm.copied().unwrap_or_default();
        let il = &p.interleave;
        let constants = ValGather {
            vpl_count: f.vpl_count,
            val_count: m,
            map_size: s,
            terms: c.terms,
            g_max: f.params.g_max,
            normal_offset: f.params.shadows.normal_offset,
            bias: f.params.shadows.bias,
            centre_offset: offset,
            receiver_offset: crate::cpu::cssm::receiver_offset(c.terms, c.sharpness),
            sharpness: c.sharpness,
            cssm_normal_offset: c.normal_offset,
            block,
            subsets: il.subsets(),
            blur_distance: il.blur_distance_m(f),
            blur_normal: il.blur_normal,
            blur_fill: u32::from(il.fill),
            blur_tent: u32::from(il.tent),
            ..bytemuck::Zeroable::zeroed()
        };
        let uniform_buf = pool.upload(
            f.ctx,
            "val gather",
            bytemuck::bytes_of(&constants),
            wgpu::BufferUsages::UNIFORM,
        );
        let indirect = frame_target(f, pool, "indirect irradiance");
        let indirect_view = indirect.create_view(&Default::default());
        let maps_view = array_view(&maps);
        let tex = wgpu::BindingResource::TextureView;
        let mut entries: Vec<(u32, wgpu::BindingResource)> = vec![
            (0, uniform_buf.as_entire_binding()),
            (1, f.vpls.as_entire_binding()),
            (3, tex(&g.views[0])),
            (4, tex(&g.views[1])),
            (7, b.order.as_entire_binding()),
            (8, b.vals.as_entire_binding()),
            (12, tex(&indirect_view)),
        ];
        let pipeline = match &basis {
            Some(basis) => {
                entries.push((9, tex(&basis.view)));
                entries.push((10, wgpu::BindingResource::Sampler(&self.sampler)));
                entries.push((11, basis.ranges.as_entire_binding()));
                &self.cssm
            }
            None => {
                entries.push((2, tex(&maps_view)));
                &self.hard
            }
        };
        let bg = bind_group(d, &pipeline.get_bind_group_layout(0), "val gather", entries);
        let span = rec.begin("indirect lighting");
        frame_pass(
            &mut rec.enc,
            "val gather",
            pipeline,
            &[&bg],
            span.compute(),
            f.view.size,
        );
        rec.end();
        passes.blur.record(
            f,
            il,
            pool,
            rec,
            (g, &uniform_buf, &indirect, out),
            (None, None),
        );
        Ok(Some(b.state))
    }
}
