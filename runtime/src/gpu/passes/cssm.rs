//! Convolution soft shadow maps (cssm.wgsl; Annen et al., Dong et al. §4.1): from the VALs'
//! paraboloid distance maps, each VAL's depth range, the Fourier basis images of the normalised
//! depth in one mip-mapped RGBA16F array, and its mips (one dispatch per level, every layer).
//! [`crate::cpu::cssm`] holds the expansion's CPU side.

use crate::RenderError;
use crate::gpu::GpuContext;
use crate::gpu::context::{Pool, array_view, bind_group, compute_pipelines, slice};
use crate::gpu::layout::{CssmFrame, UNIFORM_STRIDE, strided};
use crate::gpu::shaders::ShaderSources;
use crate::gpu::shaders::{self, WG_CSSM};
use crate::gpu::timing::Recorder;

/// Parameters of the CSSM (mode `val-cssm`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CssmParams {
    /// Fourier terms K. [Limit: 1..=16]
    pub terms: u32,
    /// Sharpening of the reconstruction ([`crate::cpu::cssm::visibility`]). [Limit: 1..=8]
    pub sharpness: f32,
    /// Normal offset of CSSM lookups (slope-scaled up to 2×): larger avoids self-shadowing
    /// under wide kernels, smaller keeps contact shadows. [Units: texels] [Limit: 0..=64]
    pub normal_offset: f32,
}

impl Default for CssmParams {
    fn default() -> Self {
        CssmParams {
            terms: crate::cpu::cssm::DEFAULT_TERMS,
            sharpness: crate::cpu::cssm::DEFAULT_SHARPNESS,
            normal_offset: 3.0,
        }
    }
}

impl CssmParams {
    /// Checks the limits (the basis layers against the adapter's at render time).
    pub fn check(&self) -> Result<(), RenderError> {
        let (sharp, off) = (self.sharpness, self.normal_offset);
        if !(1..=16).contains(&self.terms) {
            return Err(RenderError::Param(format!(
                "CSSM terms {} must be 1..=16",
                self.terms
            )));
        }
        if !(1.0..=8.0).contains(&sharp) || !(0.0..=64.0).contains(&off) {
            return Err(RenderError::Param(format!(
                "CSSM sharpening {sharp} must be 1..=8 and normal offset {off} 0..=64 texels"
            )));
        }
        Ok(())
    }
}

/// The CSSM pipelines.
pub struct Cssm {
    ranges: wgpu::ComputePipeline,
    basis: wgpu::ComputePipeline,
    downsample: wgpu::ComputePipeline,
}

/// A VAL set's CSSM basis on the GPU.
pub struct CssmBasis {
    /// All groups of all VALs, every mip level.
    pub view: wgpu::TextureView,
    /// Each VAL's depth range (m).
    pub ranges: wgpu::Buffer,
}

impl Cssm {
    /// Builds the pipelines.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<Cssm, RenderError> {
        let module = shaders::module(d, s, "cssm.wgsl")?;
        let [ranges, basis, downsample] =
            compute_pipelines(d, &module, ["ranges_of", "basis", "downsample"]);
        Ok(Cssm {
            ranges,
            basis,
            downsample,
        })
    }

    /// Records the basis of the VALs' distance `maps` (`m` layers of `size`²).
    pub fn record(
        &self,
        ctx: &GpuContext,
        p: &CssmParams,
        (maps, m, size): (&wgpu::Texture, u32, u32),
        pool: &mut Pool,
        rec: &mut Recorder,
    ) -> Result<CssmBasis, RenderError> {
        p.check()?;
        let d = &ctx.device;
        let terms = p.terms;
        let groups = terms.div_ceil(2);
        let layers = (2 * groups + 1) * m;
        if layers > d.limits().max_texture_array_layers {
            return Err(RenderError::Param(format!(
                "CSSM terms {terms}: its {layers} basis layers ({} per VAL) exceed the adapter's \
                 {}: use fewer terms or VALs",
                2 * groups + 1,
                d.limits().max_texture_array_layers
            )));
        }
        let levels = size.ilog2() + 1;
        let basis = pool.texture(
            d,
            "cssm basis",
            [size, size, layers],
            levels,
            wgpu::TextureFormat::Rgba16Float,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let level_view = |l: u32| {
            basis.create_view(&wgpu::TextureViewDescriptor {
                label: Some("cssm level"),
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                base_mip_level: l,
                mip_level_count: Some(1),
                ..Default::default()
            })
        };
        let ranges = pool.buffer(
            d,
            "val depth ranges",
            m as u64 * 4,
            wgpu::BufferUsages::STORAGE,
        );
        let uniforms = pool.upload(
            ctx,
            "cssm frames",
            &strided(&frames(m, terms, size)),
            wgpu::BufferUsages::UNIFORM,
        );
        let frame = |l: u32| {
            slice(
                &uniforms,
                l as u64 * UNIFORM_STRIDE as u64,
                size_of::<CssmFrame>() as u64,
            )
        };
        let maps_view = array_view(maps);
        let bind = |pl: &wgpu::ComputePipeline, r: Vec<(u32, wgpu::BindingResource)>| {
            bind_group(d, &pl.get_bind_group_layout(0), "cssm", r)
        };
        let tex = wgpu::BindingResource::TextureView;
        let views: Vec<wgpu::TextureView> = (0..levels).map(level_view).collect();
        let ranges_bg = bind(
            &self.ranges,
            vec![
                (0, frame(0)),
                (1, tex(&maps_view)),
                (2, ranges.as_entire_binding()),
            ],
        );
        let basis_bg = bind(
            &self.basis,
            vec![
                (0, frame(0)),
                (1, tex(&maps_view)),
                (2, ranges.as_entire_binding()),
                (3, tex(&views[0])),
            ],
        );
        let down_bgs: Vec<wgpu::BindGroup> = (1..levels)
            .map(|l| {
                let l = l as usize;
                bind(
                    &self.downsample,
                    vec![
                        (0, frame(l as u32)),
                        (3, tex(&views[l])),
                        (4, tex(&views[l - 1])),
                    ],
                )
            })
            .collect();
        let span = rec.begin("CSSM basis + mips");
        {
            let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cssm basis"),
                timestamp_writes: span.compute(),
            });
            pass.set_pipeline(&self.ranges);
            pass.set_bind_group(0, &ranges_bg, &[]);
            pass.dispatch_workgroups(m, 1, 1);
            pass.set_pipeline(&self.basis);
            pass.set_bind_group(0, &basis_bg, &[]);
            pass.dispatch_workgroups(size.div_ceil(WG_CSSM), size.div_ceil(WG_CSSM), m);
            pass.set_pipeline(&self.downsample);
            for (l, bg) in (1..levels).zip(&down_bgs) {
                let s = (size >> l).max(1);
                pass.set_bind_group(0, bg, &[]);
                pass.dispatch_workgroups(s.div_ceil(WG_CSSM), s.div_ceil(WG_CSSM), layers);
            }
        }
        rec.end();
        Ok(CssmBasis {
            view: array_view(&basis),
            ranges,
        })
    }
}

/// The constants of each mip level's pass, level 0 first.
fn frames(m: u32, terms: u32, size: u32) -> Vec<CssmFrame> {
    (0..size.ilog2() + 1)
        .map(|l| CssmFrame {
            val_count: m,
            terms,
            groups: terms.div_ceil(2),
            map_size: size,
            level_size: (size >> l).max(1),
            ..bytemuck::Zeroable::zeroed()
        })
        .collect()
}

/// The CSSM basis sampler (trilinear, clamped), kept with the scene.
pub fn sampler(d: &wgpu::Device) -> wgpu::Sampler {
    d.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("cssm basis"),
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    })
}
