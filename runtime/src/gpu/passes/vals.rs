//! Virtual area lights on the GPU (vals.wgsl; Dong et al. §5–6): k-means of the VPLs into
//! VALs, restarted each frame from the same assignment (or warm-started from last frame's
//! centres, kept in the renderer's pool), then each VAL's count, flux and rectangle, and the
//! VPLs sorted by (VAL, interleaving subset). [`crate::cpu::val`] is the CPU twin.

use crate::RenderError;
use crate::cpu::val::{ValParams, ValSeeding, scale_of};
use crate::gpu::GpuContext;
use crate::gpu::context::{Pool, bind_group, compute_pipelines};
use crate::gpu::layout::{Val, ValFrame, Vpl};
use crate::gpu::shaders::ShaderSources;
use crate::gpu::shaders::{self, WG_LINEAR};
use crate::gpu::timing::Recorder;

/// The clustering pipelines.
pub struct ValClustering {
    scale: wgpu::ComputePipeline,
    cumulate: wgpu::ComputePipeline,
    init: wgpu::ComputePipeline,
    assign: wgpu::ComputePipeline,
    converge: wgpu::ComputePipeline,
    update: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    bucket_counts: wgpu::ComputePipeline,
    offsets: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
}

/// The VALs and the mapping C on the GPU.
pub struct ValBuffers {
    /// The VALs.
    pub vals: wgpu::Buffer,
    /// Each VPL's VAL.
    pub mapping: wgpu::Buffer,
    /// M·B + 1 offsets, then the VPL indices sorted by VAL and interleaving subset.
    pub order: wgpu::Buffer,
    /// Convergence: changes in the last assignment, done, updates run (u32 each).
    pub state: wgpu::Buffer,
}

/// The VPLs to cluster: on the GPU (`buffer`, `count`), and on the CPU where the caller has
/// them (then 1 / D is computed there, exactly as the CPU twin does).
pub struct ValInput<'a> {
    /// The VPL buffer.
    pub buffer: &'a wgpu::Buffer,
    /// VPLs in it.
    pub count: u32,
    /// The same VPLs on the CPU, where known.
    pub cpu: Option<&'a [Vpl]>,
}

impl ValClustering {
    /// Builds the pipelines.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<ValClustering, RenderError> {
        let module = shaders::module(d, s, "vals.wgsl")?;
        let [
            scale,
            cumulate,
            init,
            assign,
            converge,
            update,
            finish,
            bucket_counts,
            offsets,
            scatter,
        ] = compute_pipelines(
            d,
            &module,
            [
                "scale",
                "cumulate",
                "init",
                "assign",
                "converge",
                "update",
                "finish",
                "bucket_counts",
                "offsets",
                "scatter",
            ],
        );
        Ok(ValClustering {
            scale,
            cumulate,
            init,
            assign,
            converge,
            update,
            finish,
            bucket_counts,
            offsets,
            scatter,
        })
    }

    /// Records the clustering of `input` into `params.count` VALs with `subsets` interleaving
    /// subsets. `warm`: last frame's centres (of the same count) are in the pool's buffer.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &GpuContext,
        input: &ValInput,
        params: &ValParams,
        subsets: u32,
        warm: bool,
        pool: &mut Pool,
        rec: &mut Recorder,
    ) -> Result<ValBuffers, RenderError> {
        params.check()?;
        let d = &ctx.device;
        let (n, m) = (input.count, params.count);
        let subsets = subsets.max(1);
        let max = d.limits().max_compute_workgroups_per_dimension;
        if n.div_ceil(WG_LINEAR) > max {
            return Err(RenderError::Param(format!(
                "{n} VPLs need more workgroups than the adapter's {max}"
            )));
        }
        let frame = ValFrame {
            vpl_count: n,
            val_count: m,
            subsets,
            seeding: u32::from(params.seeding == ValSeeding::HaltonFlux),
            w_x: params.w_x,
            w_alpha: params.w_alpha,
            w_f: params.w_f,
            splat: params.splat_or_zero(),
            reseed: u32::from(warm && params.seeding == ValSeeding::HaltonFlux),
            ..bytemuck::Zeroable::zeroed()
        };
        let uniform = wgpu::BufferUsages::UNIFORM;
        let frame_buf = pool.upload(ctx, "val frame", bytemuck::bytes_of(&frame), uniform);
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let inv: [f32; 1] = [input.cpu.map_or(1.0, |v| 1.0 / scale_of(v))];
        let inv_scale = pool.upload(ctx, "val inv scale", bytemuck::cast_slice(&inv), rw);
        let centres = pool.buffer(d, "val centres", m as u64 * 48, rw);
        let cdf = pool.buffer(d, "vpl importance cdf", n.max(1) as u64 * 4, rw);
        let mapping = pool.buffer(d, "vpl → val", n as u64 * 4, rw);
        let vals = pool.buffer(d, "vals", m as u64 * size_of::<Val>() as u64, rw);
        let buckets = m as u64 * subsets as u64;
        let order = pool.buffer(
            d,
            "vpls by val",
            (buckets + 1 + n as u64) * 4,
            rw | wgpu::BufferUsages::COPY_DST,
        );
        let state = pool.buffer(d, "val convergence", 16, rw | wgpu::BufferUsages::COPY_DST);
        rec.enc.clear_buffer(&order, 0, None);
        rec.enc.clear_buffer(&state, 0, None);
        let bind = |pipeline: &wgpu::ComputePipeline, with: &[(u32, &wgpu::Buffer)]| {
            let resources = with
                .iter()
                .map(|&(binding, b)| (binding, b.as_entire_binding()))
                .collect();
            bind_group(d, &pipeline.get_bind_group_layout(0), "vals", resources)
        };
        let base = [(0, &frame_buf), (1, input.buffer), (2, &centres)];
        let scale_bg = bind(&self.scale, &[base[0], base[1], (6, &inv_scale)]);
        let cumulate_bg = bind(&self.cumulate, &[base[0], base[1], (8, &cdf)]);
        let init_bg = bind(
            &self.init,
            &[base[0], base[1], base[2], (4, &vals), (8, &cdf)],
        );
        let assign_bg = bind(
            &self.assign,
            &[
                base[0],
                base[1],
                base[2],
                (3, &mapping),
                (6, &inv_scale),
                (7, &state),
            ],
        );
        let converge_bg = bind(&self.converge, &[(7, &state)]);
        let update_bg = bind(
            &self.update,
            &[base[0], base[1], base[2], (3, &mapping), (7, &state)],
        );
        let finish_bg = bind(
            &self.finish,
            &[
                base[0],
                base[1],
                base[2],
                (3, &mapping),
                (4, &vals),
                (7, &state),
            ],
        );
        let counts_bg = bind(&self.bucket_counts, &[base[0], (3, &mapping), (5, &order)]);
        let offsets_bg = bind(&self.offsets, &[base[0], (5, &order)]);
        let scatter_bg = bind(&self.scatter, &[base[0], (3, &mapping), (5, &order)]);
        let span = rec.begin("VAL clustering");
        {
            let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("val clustering"),
                timestamp_writes: span.compute(),
            });
            if n > 0 {
                let (gv, gm) = (n.div_ceil(WG_LINEAR), m.div_ceil(WG_LINEAR));
                let mut run = |p: &wgpu::ComputePipeline, bg: &wgpu::BindGroup, groups: u32| {
                    pass.set_pipeline(p);
                    pass.set_bind_group(0, bg, &[]);
                    pass.dispatch_workgroups(groups, 1, 1);
                };
                if input.cpu.is_none() {
                    run(&self.scale, &scale_bg, 1);
                }
                // Cold: every centre from its seed; warm with the paper's seeds: the VALs
                // that held no VPL last frame.
                let reseed = warm && params.seeding == ValSeeding::HaltonFlux;
                if !warm || reseed {
                    if params.seeding == ValSeeding::HaltonFlux {
                        run(&self.cumulate, &cumulate_bg, 1);
                    }
                    run(&self.init, &init_bg, gm);
                }
                // The iterations stop on the GPU once the assignment repeats itself (the
                // later dispatches return at once): no read-back, no wait.
                for _ in 0..params.iterations {
                    run(&self.assign, &assign_bg, gv);
                    run(&self.converge, &converge_bg, 1);
                    run(&self.update, &update_bg, m);
                }
                run(&self.assign, &assign_bg, gv);
                run(&self.finish, &finish_bg, m);
                let gb = (buckets as u32).div_ceil(WG_LINEAR);
                run(&self.bucket_counts, &counts_bg, gb);
                run(&self.offsets, &offsets_bg, 1);
                run(&self.scatter, &scatter_bg, gb);
            }
        }
        rec.end();
        Ok(ValBuffers {
            vals,
            mapping,
            order,
            state,
        })
    }
}
