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
        let n = input.count;
        let max = ctx.device.limits().max_compute_workgroups_per_dimension;
        if n.div_ceil(WG_LINEAR) > max {
            return Err(RenderError::Param(format!(
                "{n} VPLs need more workgroups than the adapter's {max}"
            )));
        }
        let frame = frame_constants(input, params, subsets.max(1), warm);
        let b = Buffers::new(ctx, pool, input, &frame);
        rec.enc.clear_buffer(&b.out.order, 0, None);
        rec.enc.clear_buffer(&b.out.state, 0, None);
        let g = self.groups(&ctx.device, input, &b);
        let span = rec.begin("VAL clustering");
        {
            let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("val clustering"),
                timestamp_writes: span.compute(),
            });
            if n > 0 {
                self.dispatch(&mut pass, &g, &frame, params, (warm, input.cpu.is_none()));
            }
        }
        rec.end();
        Ok(b.out)
    }

    /// The clustering's dispatches: the VPLs' scale where the CPU did not give it, the seeds
    /// (cold, or the emptied VALs of a warm start with the paper's seeds), the k-means
    /// iterations, the VALs' sums and the VPLs sorted by (VAL, subset).
    fn dispatch(
        &self,
        pass: &mut wgpu::ComputePass,
        g: &Groups,
        frame: &ValFrame,
        params: &ValParams,
        (warm, scale_here): (bool, bool),
    ) {
        let (n, m) = (frame.vpl_count, frame.val_count);
        let (gv, gm) = (n.div_ceil(WG_LINEAR), m.div_ceil(WG_LINEAR));
        let mut run = |p: &wgpu::ComputePipeline, bg: &wgpu::BindGroup, groups: u32| {
            pass.set_pipeline(p);
            pass.set_bind_group(0, bg, &[]);
            pass.dispatch_workgroups(groups, 1, 1);
        };
        if scale_here {
            run(&self.scale, &g.scale, 1);
        }
        // Cold: every centre from its seed; warm with the paper's seeds: the VALs that held no
        // VPL last frame.
        let reseed = warm && params.seeding == ValSeeding::HaltonFlux;
        if !warm || reseed {
            if params.seeding == ValSeeding::HaltonFlux {
                run(&self.cumulate, &g.cumulate, 1);
            }
            run(&self.init, &g.init, gm);
        }
        // The iterations stop on the GPU once the assignment repeats itself (the later
        // dispatches return at once): no read-back, no wait.
        for _ in 0..params.iterations {
            run(&self.assign, &g.assign, gv);
            run(&self.converge, &g.converge, 1);
            run(&self.update, &g.update, m);
        }
        run(&self.assign, &g.assign, gv);
        run(&self.finish, &g.finish, m);
        let gb = (m * frame.subsets).div_ceil(WG_LINEAR);
        run(&self.bucket_counts, &g.counts, gb);
        run(&self.offsets, &g.offsets, 1);
        run(&self.scatter, &g.scatter, gb);
    }

    /// The bind groups of the clustering's passes over `b`.
    fn groups(&self, d: &wgpu::Device, input: &ValInput, b: &Buffers) -> Groups {
        let bind = |pipeline: &wgpu::ComputePipeline, with: &[(u32, &wgpu::Buffer)]| {
            let resources = with
                .iter()
                .map(|&(binding, b)| (binding, b.as_entire_binding()))
                .collect();
            bind_group(d, &pipeline.get_bind_group_layout(0), "vals", resources)
        };
        let (frame, vpls, centres) = ((0, &b.frame), (1, input.buffer), (2, &b.centres));
        let (mapping, vals, order) = ((3, &b.out.mapping), (4, &b.out.vals), (5, &b.out.order));
        let (inv_scale, state, cdf) = ((6, &b.inv_scale), (7, &b.out.state), (8, &b.cdf));
        Groups {
            scale: bind(&self.scale, &[frame, vpls, inv_scale]),
            cumulate: bind(&self.cumulate, &[frame, vpls, cdf]),
            init: bind(&self.init, &[frame, vpls, centres, vals, cdf]),
            assign: bind(
                &self.assign,
                &[frame, vpls, centres, mapping, inv_scale, state],
            ),
            converge: bind(&self.converge, &[state]),
            update: bind(&self.update, &[frame, vpls, centres, mapping, state]),
            finish: bind(&self.finish, &[frame, vpls, centres, mapping, vals, state]),
            counts: bind(&self.bucket_counts, &[frame, mapping, order]),
            offsets: bind(&self.offsets, &[frame, order]),
            scatter: bind(&self.scatter, &[frame, mapping, order]),
        }
    }
}

/// The clustering's constants for `input` into `params.count` VALs with `subsets` subsets.
fn frame_constants(input: &ValInput, params: &ValParams, subsets: u32, warm: bool) -> ValFrame {
    ValFrame {
        vpl_count: input.count,
        val_count: params.count,
        subsets,
        seeding: u32::from(params.seeding == ValSeeding::HaltonFlux),
        w_x: params.w_x,
        w_alpha: params.w_alpha,
        w_f: params.w_f,
        splat: params.splat_or_zero(),
        reseed: u32::from(warm && params.seeding == ValSeeding::HaltonFlux),
        ..bytemuck::Zeroable::zeroed()
    }
}

/// The clustering's buffers: what it leaves ([`ValBuffers`]) and its own.
struct Buffers {
    out: ValBuffers,
    /// The constants (0).
    frame: wgpu::Buffer,
    /// The centres (2).
    centres: wgpu::Buffer,
    /// 1 / D, the VPLs' scale (6).
    inv_scale: wgpu::Buffer,
    /// The VPLs' importance CDF for the paper's seeds (8).
    cdf: wgpu::Buffer,
}

impl Buffers {
    fn new(ctx: &GpuContext, pool: &mut Pool, input: &ValInput, frame: &ValFrame) -> Buffers {
        let d = &ctx.device;
        let (n, m) = (u64::from(frame.vpl_count), u64::from(frame.val_count));
        let uniform = wgpu::BufferUsages::UNIFORM;
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let inv: [f32; 1] = [input.cpu.map_or(1.0, |v| 1.0 / scale_of(v))];
        let buckets = m * u64::from(frame.subsets);
        let cleared = rw | wgpu::BufferUsages::COPY_DST;
        Buffers {
            frame: pool.upload(ctx, "val frame", bytemuck::bytes_of(frame), uniform),
            inv_scale: pool.upload(ctx, "val inv scale", bytemuck::cast_slice(&inv), rw),
            centres: pool.buffer(d, "val centres", m * 48, rw),
            cdf: pool.buffer(d, "vpl importance cdf", n.max(1) * 4, rw),
            out: ValBuffers {
                mapping: pool.buffer(d, "vpl → val", n * 4, rw),
                vals: pool.buffer(d, "vals", m * size_of::<Val>() as u64, rw),
                order: pool.buffer(d, "vpls by val", (buckets + 1 + n) * 4, cleared),
                state: pool.buffer(d, "val convergence", 16, cleared),
            },
        }
    }
}

/// The bind groups of the clustering's passes.
struct Groups {
    scale: wgpu::BindGroup,
    cumulate: wgpu::BindGroup,
    init: wgpu::BindGroup,
    assign: wgpu::BindGroup,
    converge: wgpu::BindGroup,
    update: wgpu::BindGroup,
    finish: wgpu::BindGroup,
    counts: wgpu::BindGroup,
    offsets: wgpu::BindGroup,
    scatter: wgpu::BindGroup,
}
