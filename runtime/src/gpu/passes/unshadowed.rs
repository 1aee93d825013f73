//! The ratio estimator's unshadowed far light (unshadowed.wgsl; [`GatesParams::ratio`]): each
//! pixel's unshadowed light from every VPL beyond its near field, summed at the pixels of a
//! grid every [`GatesParams::ratio_stride`] pixels and at those between whose grid pixels do
//! not lie on their surface, for the blur to take at every pixel (`blur.wgsl`'s compose).
//!
//! [`GatesParams::ratio`]: super::gates_params::GatesParams::ratio
//! [`GatesParams::ratio_stride`]: super::gates_params::GatesParams::ratio_stride

use super::gbuffer::GBufferOutput;
use super::shade::ping_pong_targets;
use crate::RenderError;
use crate::gpu::Frame;
use crate::gpu::context::{Pool, bind_group, compute_pipelines, slice};
use crate::gpu::layout::{UNIFORM_STRIDE, strided};
use crate::gpu::shaders::{self, ShaderSources};
use crate::gpu::timing::Recorder;

/// VPLs a dispatch of unshadowed.wgsl sums (injected as its RATIO_RUN): a software
/// rasterizer ends a shader invocation's loops after 65,535 iterations.
pub const RATIO_RUN: u32 = 16_384;

/// The ratio estimator's grid for a frame of `size` pixels with stride `stride`: the pixels
/// 0, s, 2s, … and the last of each axis (ratio.wgsl's `ratio_grid_size`).
pub fn ratio_grid_size(size: [u32; 2], stride: u32) -> [u32; 2] {
    let s = stride.max(1);
    size.map(|n| n.saturating_sub(1).div_ceil(s) + 1)
}

/// The bytes of the list of the pixels that sum their own light for a frame of `size` pixels:
/// a word each and the count.
pub fn own_list_bytes([w, h]: [u32; 2]) -> u64 {
    (1 + u64::from(w) * u64::from(h)) * 4
}

/// The grid stride a frame of `size` pixels takes: `stride`, or every pixel (1, no list) where
/// the list of the pixels that sum their own would not fit a storage binding of `limit` bytes
/// (from 8192 × 4096 on lavapipe's 128 MiB): the blur must find every listed pixel's light.
pub fn stride_that_fits(stride: u32, size: [u32; 2], limit: u64) -> u32 {
    if own_list_bytes(size) <= limit {
        stride
    } else {
        1
    }
}

/// Where a frame's unshadowed far light was summed (`PassTimes::ratio`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RatioStats {
    /// The grid's stride. [Units: px]
    pub stride: u32,
    /// Its grid pixels.
    pub grid: u32,
    /// The pixels between them that summed their own.
    pub own: u32,
    /// The frame's pixels.
    pub pixels: u32,
}

/// What [`Unshadowed::record`] leaves: the light, and what says where it was summed.
pub struct UnshadowedOutput {
    /// The unshadowed far light, a texel a pixel.
    pub image: wgpu::Texture,
    /// The list of the pixels that summed their own (word 0: their count).
    pub list: wgpu::Buffer,
    /// The stats but the own pixels' count, which the list holds.
    pub stats: RatioStats,
}

/// The pass's pipelines.
pub struct Unshadowed {
    own_list: wgpu::ComputePipeline,
    grid: wgpu::ComputePipeline,
    own: wgpu::ComputePipeline,
}

impl Unshadowed {
    /// Builds the pipelines.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<Unshadowed, RenderError> {
        let module = shaders::module(d, s, "unshadowed.wgsl")?;
        let [own_list, grid, own] =
            compute_pipelines(d, &module, ["cs_own_list", "cs_far_grid", "cs_far_own"]);
        Ok(Unshadowed {
            own_list,
            grid,
            own,
        })
    }

    /// Records the unshadowed far light of frame `f` over G-buffer `g`: in runs of
    /// [`RATIO_RUN`] VPLs the grid's pixels', then the pixels that sum their own listed, then
    /// in runs theirs; each run into one of two targets, reading the other, so that both end
    /// in the same. Returns it with the list (a texel a pixel; the pixels between the grid's
    /// that take theirs from it are not written).
    pub fn record(
        &self,
        f: &Frame,
        pool: &mut Pool,
        rec: &mut Recorder,
        g: &GBufferOutput,
    ) -> UnshadowedOutput {
        let d = &f.ctx.device;
        let [w, h] = f.view.size;
        let runs = f.vpl_count.div_ceil(RATIO_RUN).max(1);
        let names = ["unshadowed far light", "unshadowed far light (runs)"];
        let [first, second] = ping_pong_targets(f, pool, names, runs);
        let views = [&first, &second].map(|t| t.create_view(&Default::default()));
        let (list, args) = own_list(f, pool, rec);
        let runs_buf = pool.upload(
            f.ctx,
            "unshadowed runs",
            &strided(&(0..runs).map(|i| [i, 0, 0, 0]).collect::<Vec<_>>()),
            wgpu::BufferUsages::UNIFORM,
        );
        let g_views = [
            (2, wgpu::BindingResource::TextureView(&g.views[0])),
            (3, wgpu::BindingResource::TextureView(&g.views[1])),
        ];
        // The runs' bindings (cs_far_grid's; cs_far_own's with the list).
        let run = |i: usize| {
            let mut r = vec![
                (0, f.globals.as_entire_binding()),
                (1, f.vpls.as_entire_binding()),
                (4, wgpu::BindingResource::TextureView(&views[(i + 1) % 2])),
                (5, wgpu::BindingResource::TextureView(&views[i % 2])),
                (6, slice(&runs_buf, (i * UNIFORM_STRIDE) as u64, 16)),
            ];
            r.extend(g_views.iter().cloned());
            r
        };
        let layout = |p: &wgpu::ComputePipeline| p.get_bind_group_layout(0);
        let last = &views[(runs as usize - 1) % 2];
        let mut listing = vec![
            (0, f.globals.as_entire_binding()),
            (7, list.as_entire_binding()),
            (8, args.as_entire_binding()),
            (9, wgpu::BindingResource::TextureView(&g.views[2])),
            (10, wgpu::BindingResource::TextureView(last)),
        ];
        listing.extend(g_views.iter().cloned());
        let lister = bind_group(d, &layout(&self.own_list), "unshadowed list", listing);
        let grids: Vec<_> = (0..runs as usize)
            .map(|i| bind_group(d, &layout(&self.grid), "unshadowed grid", run(i)))
            .collect();
        let owns: Vec<_> = (0..runs as usize)
            .map(|i| {
                let mut r = run(i);
                r.push((7, list.as_entire_binding()));
                bind_group(d, &layout(&self.own), "unshadowed own", r)
            })
            .collect();
        let grid = ratio_grid_size(f.view.size, f.ratio_stride);
        let span = rec.begin("indirect lighting: unshadowed");
        {
            let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("unshadowed far light"),
                timestamp_writes: span.compute(),
            });
            for group in &grids {
                pass.set_pipeline(&self.grid);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(grid[0].div_ceil(8), grid[1].div_ceil(8), 1);
            }
            if f.ratio_stride > 1 {
                pass.set_pipeline(&self.own_list);
                pass.set_bind_group(0, &lister, &[]);
                pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
                pass.set_pipeline(&self.own);
                for group in &owns {
                    pass.set_bind_group(0, group, &[]);
                    pass.dispatch_workgroups_indirect(&args, 0);
                }
            }
        }
        rec.end();
        let image = if runs % 2 == 1 { first } else { second };
        let stats = RatioStats {
            stride: f.ratio_stride,
            grid: grid[0] * grid[1],
            own: 0,
            pixels: w * h,
        };
        UnshadowedOutput { image, list, stats }
    }
}

/// The list of the pixels that sum their own light (word 0 their count, then each one's
/// index) and its indirect dispatch's workgroups (0, 1, 1), both emptied in the frame's
/// commands.
fn own_list(f: &Frame, pool: &mut Pool, rec: &mut Recorder) -> (wgpu::Buffer, wgpu::Buffer) {
    let d = &f.ctx.device;
    let head: [u32; 4] = [0, 1, 1, 0];
    let empty = pool.upload(
        f.ctx,
        "unshadowed empty list",
        bytemuck::cast_slice(&head),
        wgpu::BufferUsages::COPY_SRC,
    );
    let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
    // At stride 1 no pixel is listed: the count alone.
    let bytes = match f.ratio_stride {
        1 => 4,
        _ => own_list_bytes(f.view.size),
    };
    let list = pool.buffer(
        d,
        "unshadowed own pixels",
        bytes,
        storage | wgpu::BufferUsages::COPY_SRC,
    );
    let args = pool.buffer(
        d,
        "unshadowed own dispatch",
        16,
        storage | wgpu::BufferUsages::INDIRECT,
    );
    rec.enc.copy_buffer_to_buffer(&empty, 0, &list, 0, 4);
    rec.enc.copy_buffer_to_buffer(&empty, 0, &args, 0, 16);
    (list, args)
}
