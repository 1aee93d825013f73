//! One frame's run: its settings checked against the renderer's level, its passes recorded
//! (record.rs) and submitted, and what it reads back — the image where asked, and the light
//! lists', starved pixels', VAL clustering's and LightCluster's counts — mapped into its
//! [`PassTimes`].

use std::time::Instant;

use glam::Vec3;

use super::context::{self, Pool, map_read, row_bytes, texels};
use super::record::{self, Recorded};
use super::timing::Recorder;
use super::{
    GpuContext, GpuMode, GpuParams, GpuRenderer, LcCounts, PassTimes, ValIterations, VplInput,
    passes,
};
use crate::RenderError;
use crate::camera::View;
use crate::cpu::gates::GateShape;
use crate::hdr::HdrImage;

/// The buffers a frame's counts are copied into for reading back, where it has them.
struct Readbacks {
    lists: Option<wgpu::Buffer>,
    val_state: Option<wgpu::Buffer>,
    lc: Option<wgpu::Buffer>,
    vpl_lc: Option<wgpu::Buffer>,
    starved: Option<wgpu::Buffer>,
    ratio: Option<wgpu::Buffer>,
}

impl GpuRenderer {
    /// [`GpuRenderer::render_kept`] without the error scope.
    pub(super) fn frame_unscoped(
        &mut self,
        ctx: &GpuContext,
        view: &View,
        vpls: VplInput,
        params: &GpuParams,
        read_hdr: bool,
    ) -> Result<(Option<HdrImage>, PassTimes), RenderError> {
        let t0 = Instant::now();
        self.check_frame(view, params)?;
        let mut rec = Recorder::new(ctx, &mut self.pool);
        let (vpl_buf, count) = self.frame_vpls(ctx, &vpls, &mut rec)?;
        // The interleaving block for the frame's VPLs (InterleaveParams::for_vpls).
        let params = &GpuParams {
            mode: params.mode.as_run().interleave_for(count),
            ..*params
        };
        let vals = params.mode.vals();
        let val_count = vals.map(|v| v.count);
        let warm = vals.is_some_and(|p| p.warm_start && self.val_warm == Some(p.count));
        let cpu = match vpls {
            VplInput::Given(v) => Some(v),
            VplInput::Rsm(_) => None,
        };
        let [w, h] = view.size;
        let (frame, pipelines, pool) = self.frame(ctx, view, params, (vpl_buf, count, cpu));
        let out = record::record_passes(pipelines, &frame, pool, &mut rec, warm)?;
        let read = read_hdr.then(|| {
            let read = pool.buffer(
                &ctx.device,
                "hdr readback",
                row_bytes(w, 16) * h as u64,
                wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            );
            context::copy_texture(&mut rec.enc, &out.hdr, &read);
            read
        });
        let readbacks = copy_counts(ctx, pool, &mut rec, &out);
        let mut times = rec.finish(pool)?;
        let t1 = Instant::now();
        self.read_counts(ctx, &out, &readbacks, params, count, &mut times)?;
        let img = match &read {
            Some(read) => {
                let px = texels(&map_read(ctx, read)?, w, h, false);
                let mut img = HdrImage::new(w, h);
                for (o, p) in img.pixels.iter_mut().zip(&px) {
                    *o = Vec3::new(p[0], p[1], p[2]);
                }
                Some(img)
            }
            None => None,
        };
        self.last_hdr = Some(out.hdr.clone());
        if val_count.is_some() && count > 0 {
            self.val_warm = val_count;
        }
        times.readback_s += t1.elapsed().as_secs_f64();
        times.frame_s = t0.elapsed().as_secs_f64();
        Ok((img, times))
    }

    /// Refuses a frame whose settings are out of their limits, or whose gates need what the
    /// renderer's level does not hold on the GPU (a level; the closed voxels' triangle lists or
    /// planes).
    fn check_frame(&self, view: &View, params: &GpuParams) -> Result<(), RenderError> {
        params.check()?;
        if let GpuMode::Gates(g) = params.mode
            && g.interleave.walks_starved()
        {
            passes::starved::check_size(view.size)?;
        }
        if params.mode.gates().is_some() && self.scene.level.is_none() {
            return Err(RenderError::Param(format!(
                "mode {} needs a baked level (GpuRenderer::set_level, --level)",
                params.mode.name()
            )));
        }
        if let (Some(g), Some(l)) = (params.mode.gates(), &self.scene.level)
            && g.shape == GateShape::Voxels
            && g.triangles
            && !l.triangles
        {
            return Err(RenderError::Param(
                "the voxel walk with the closed voxels' triangles needs their lists on the GPU: \
                 GateLevel::list_triangles before GpuRenderer::set_level"
                    .into(),
            ));
        }
        if let (Some(g), Some(l)) = (params.mode.gates(), &self.scene.level)
            && g.shape == GateShape::Voxels
            && g.planes
            && !g.triangles
            && !l.planes
        {
            return Err(RenderError::Param(
                "the voxel walk with the closed voxels' planes needs them on the GPU: \
                 GpuRenderer::level_for_mode uploads them (and says where they overflow the \
                 adapter's storage binding; --no-closed-voxel-planes walks without them)"
                    .into(),
            ));
        }
        Ok(())
    }

    /// Maps the frame's counts (copied by [`copy_counts`]) into `times`: the light lists',
    /// the starved pixels', the VAL clustering's iterations, LightCluster's clusters of the
    /// lights and of the `count` VPLs.
    fn read_counts(
        &self,
        ctx: &GpuContext,
        out: &Recorded,
        r: &Readbacks,
        params: &GpuParams,
        count: u32,
        times: &mut PassTimes,
    ) -> Result<(), RenderError> {
        let words = |b: &wgpu::Buffer| -> Result<Vec<u32>, RenderError> {
            Ok(bytemuck::cast_slice(&map_read(ctx, b)?).to_vec())
        };
        if let (Some(l), Some(b)) = (&out.lists, &r.lists) {
            times.lists = Some(l.stats(&words(b)?)?);
        }
        if let (Some(s), Some(b)) = (&out.starved, &r.starved) {
            times.starved = Some(passes::starved::stats(&words(b)?, s.capacity)?);
        }
        if let (Some(u), Some(b)) = (&out.unshadowed, &r.ratio) {
            let own = words(b)?[0];
            times.ratio = Some(passes::unshadowed::RatioStats { own, ..u.stats });
        }
        if let (Some(b), Some(v)) = (&r.val_state, params.mode.vals()) {
            let c = words(b)?;
            times.vals = Some(ValIterations {
                iterations: c[2],
                max: v.iterations,
                converged: c[1] != 0,
                live: c[3],
                count: v.count,
            });
        }
        let counts = |b: &wgpu::Buffer, emitters: u32| -> Result<LcCounts, RenderError> {
            Ok(passes::light_cluster::counts_of(&words(b)?, emitters))
        };
        if let Some(b) = &r.lc {
            times.direct_clusters = Some(counts(b, self.scene.lights.len() as u32)?);
        }
        if let Some(b) = &r.vpl_lc {
            times.vpl_clusters = Some(counts(b, count)?);
        }
        Ok(())
    }
}

/// Copies the counts the frame `out` has into buffers it can map: the light lists' counter,
/// the VAL clustering's convergence words, LightCluster's arguments (lights and VPLs), the
/// starved pixels' count.
fn copy_counts(ctx: &GpuContext, pool: &mut Pool, rec: &mut Recorder, out: &Recorded) -> Readbacks {
    let mut read_back = |label, src: &wgpu::Buffer, bytes| {
        let r = pool.buffer(
            &ctx.device,
            label,
            bytes,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        );
        rec.enc.copy_buffer_to_buffer(src, 0, &r, 0, bytes);
        r
    };
    Readbacks {
        lists: (out.lists.as_ref())
            .map(|l| read_back("light list counter readback", &l.counter, 32)),
        val_state: (out.val_state.as_ref()).map(|s| read_back("val convergence readback", s, 16)),
        lc: (out.lc_args.as_ref()).map(|a| read_back("lc args readback", a, 64)),
        vpl_lc: (out.vpl_lc_args.as_ref()).map(|a| read_back("vpl lc args readback", a, 64)),
        starved: (out.starved.as_ref()).map(|s| read_back("starved count readback", &s.count, 16)),
        ratio: (out.unshadowed.as_ref()).map(|u| read_back("ratio own count readback", &u.list, 4)),
    }
}
