//! Each VPL's end of the voxel walk, once a frame (sight_ends.wgsl): mode gates with voxels
//! then walks every pixel's VPLs from these ([`crate::cpu::sight::VoxelSight::end`] is the CPU
//! twin). Finding a VPL's end again at every pixel cost a quarter of the indirect pass on
//! lavapipe (four rooms, 320 × 240, 1,024 VPLs: 333 ms, 88 of them the ends).

use crate::RenderError;
use crate::gpu::Frame;
use crate::gpu::context::{Pool, bind_group, compute_pipeline_with};
use crate::gpu::shaders::{self, ShaderSources, WG_LINEAR};
use crate::gpu::timing::Recorder;

/// The pass's pipelines: the ends without the closed voxels' planes, and with them.
pub struct SightEnds {
    pipelines: [wgpu::ComputePipeline; 2],
}

impl SightEnds {
    /// Builds the pipelines.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<SightEnds, RenderError> {
        let module = shaders::module(d, s, "sight_ends.wgsl")?;
        let with = |planes: u8| {
            let constants = [("SIGHT_END_PLANES", f64::from(planes))];
            compute_pipeline_with(d, "vpl sight ends", &module, "main", &constants)
        };
        Ok(SightEnds {
            pipelines: [with(0), with(1)],
        })
    }

    /// Records the pass over the frame's VPLs and `sight_words` (the level's open voxels), the
    /// ends off the closed voxels' planes where the frame's walk passes them (which
    /// `sight_extra` then carries): the buffer of their ends, a `vec4<f32>` each (kept in `pool`).
    pub fn record(
        &self,
        f: &Frame,
        (sight_words, sight_extra): (&wgpu::Buffer, &wgpu::Buffer),
        pool: &mut Pool,
        rec: &mut Recorder,
    ) -> Result<wgpu::Buffer, RenderError> {
        let d = &f.ctx.device;
        let groups = f.vpl_count.div_ceil(WG_LINEAR);
        let max = d.limits().max_compute_workgroups_per_dimension;
        if groups > max {
            return Err(RenderError::Param(format!(
                "{} VPLs need {groups} workgroups, more than the adapter's {max}",
                f.vpl_count
            )));
        }
        let planes = f
            .params
            .mode
            .gates()
            .is_some_and(|g| g.planes && !g.triangles);
        let pipeline = &self.pipelines[usize::from(planes)];
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let ends = pool.buffer(d, "vpl sight ends", u64::from(f.vpl_count) * 16, usage);
        let bg = bind_group(
            d,
            &pipeline.get_bind_group_layout(0),
            "vpl sight ends",
            vec![
                (0, f.vpls.as_entire_binding()),
                (1, sight_words.as_entire_binding()),
                (2, ends.as_entire_binding()),
                (3, sight_extra.as_entire_binding()),
            ],
        );
        let span = rec.begin("VPL walk ends");
        {
            let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("vpl sight ends"),
                timestamp_writes: span.compute(),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bg, &[]);
            if groups > 0 {
                pass.dispatch_workgroups(groups, 1, 1);
            }
        }
        rec.end();
        Ok(ends)
    }
}
