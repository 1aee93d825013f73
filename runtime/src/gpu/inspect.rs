//! What a [`GpuRenderer`] can read back besides a frame, for the tests, the viewer's layers and
//! inspection: the RSM VPLs, the VAL clustering, the imperfect shadow maps, LightCluster's
//! clusters and the clustered gates' light lists — each as its CPU twin gives it.

use glam::Vec3;

use super::context::read_buffer;
use super::timing::Recorder;
use super::{
    GatesParams, GpuContext, GpuMode, GpuParams, GpuRenderer, IsmParams, LightClusterGpuParams,
    RsmParams, VplInput, VplIsmParams, passes,
};
use crate::RenderError;
use crate::camera::View;
use crate::cpu::clustered::{Clustered, PixelSurface};
use crate::cpu::lightcluster::LightClusters;
use crate::cpu::val::{Clustering, ValParams, scale_of};
use crate::vpl::Vpl;
use passes::vals::ValInput;

impl GpuRenderer {
    /// VPLs from the lights' reflective shadow maps ([`RsmParams`]), read back to the CPU (so
    /// that the reference can use the very same). A frame with [`VplInput::Rsm`] makes the
    /// same VPLs and keeps them on the GPU.
    pub fn rsm_vpls(
        &mut self,
        ctx: &GpuContext,
        n: u32,
        rsm_size: u32,
        seed: u64,
    ) -> Result<Vec<Vpl>, RenderError> {
        let p = RsmParams {
            count: n,
            rsm_size,
            seed,
        };
        let mut rec = Recorder::new(ctx, &mut self.pool);
        let (buf, count) = self.frame_vpls(ctx, &VplInput::Rsm(p), &mut rec)?;
        rec.finish(&mut self.pool)?;
        if count == 0 {
            return Ok(Vec::new());
        }
        let bytes = read_buffer(ctx, &buf)?;
        Ok(bytemuck::cast_slice::<u8, Vpl>(&bytes)[..count as usize].to_vec())
    }

    /// Clusters `vpls` into VALs on the GPU and reads them back (for tests and inspection).
    pub fn cluster_vals(
        &mut self,
        ctx: &GpuContext,
        vpls: &[Vpl],
        params: &ValParams,
    ) -> Result<Clustering, RenderError> {
        let mut rec = Recorder::new(ctx, &mut self.pool);
        let (buf, count) = self.frame_vpls(ctx, &VplInput::Given(vpls), &mut rec)?;
        let input = ValInput {
            buffer: &buf,
            count,
            cpu: Some(vpls),
        };
        let b =
            self.pipelines
                .vals
                .record(ctx, &input, params, 1, false, &mut self.pool, &mut rec)?;
        rec.finish(&mut self.pool)?;
        let m = params.count as usize;
        let vals = if vpls.is_empty() {
            vec![bytemuck::Zeroable::zeroed(); m]
        } else {
            bytemuck::cast_slice(&read_buffer(ctx, &b.vals)?)[..m].to_vec()
        };
        let mapping: Vec<u32> =
            bytemuck::cast_slice(&read_buffer(ctx, &b.mapping)?)[..vpls.len()].to_vec();
        let state: Vec<u32> = bytemuck::cast_slice(&read_buffer(ctx, &b.state)?).to_vec();
        Ok(Clustering {
            vals,
            mapping,
            scale_m: scale_of(vpls),
            iterations: state[2],
            converged: vpls.is_empty() || state[1] != 0,
        })
    }

    /// Builds the imperfect shadow maps of `vpls` with `params` (as mode per-vpl-ism does) and
    /// reads them back: (distances, map side), map k's texel (x, y) at k·s² + y·s + x, in
    /// metres, `f32::INFINITY` where nothing was seen. For tests and inspection.
    pub fn ism_maps(
        &mut self,
        ctx: &GpuContext,
        vpls: &[Vpl],
        params: &IsmParams,
    ) -> Result<(Vec<f32>, u32), RenderError> {
        let gpu_params = GpuParams::with_mode(GpuMode::PerVplIsm(VplIsmParams {
            ism: *params,
            ..VplIsmParams::default()
        }));
        gpu_params.check()?;
        let camera = visgate_formats::Camera {
            name: "ism".into(),
            eye: Vec3::Z,
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_x_rad: 1.0,
        };
        let view = View::new(&camera, [1, 1])?;
        let mut rec = Recorder::new(ctx, &mut self.pool);
        let v = self.frame_vpls(ctx, &VplInput::Given(vpls), &mut rec)?;
        let (frame, p, pool) = self.frame(ctx, &view, &gpu_params, (v.0, v.1, Some(vpls)));
        let emitters = passes::ism::Emitters::Vpls;
        let maps = p
            .isms
            .record_maps(&frame, params, emitters, (1, None, 1), pool, &mut rec)?;
        rec.finish(pool)?;
        Ok((passes::ism::read_maps(ctx, &maps)?, maps.map_size))
    }

    /// Runs LightCluster's culling and clustering of the scene's lights for `view` on the GPU
    /// and reads back what they made, as the CPU twin
    /// [`crate::cpu::lightcluster::cluster_lights`] gives it (for tests and inspection).
    pub fn cluster_direct_lights(
        &mut self,
        ctx: &GpuContext,
        view: &View,
        params: &LightClusterGpuParams,
    ) -> Result<LightClusters, RenderError> {
        params.check()?;
        let (lights, _) = passes::shadow_maps::light_views(&self.scene);
        let lights_buf = self.pool.upload(
            ctx,
            "lights",
            bytemuck::cast_slice(&lights),
            wgpu::BufferUsages::STORAGE,
        );
        let frame = passes::light_cluster::lc_frame(&self.scene, view, params, (0.0, 0.0));
        let kind = passes::light_cluster::LcKind::Direct;
        let frame_buf = passes::light_cluster::upload_frame(ctx, &mut self.pool, &frame, kind);
        let mut rec = Recorder::new(ctx, &mut self.pool);
        let c = self.pipelines.light_cluster.record_clustering(
            ctx,
            (&frame, &frame_buf, kind),
            &lights_buf,
            &mut self.pool,
            &mut rec,
        )?;
        rec.finish(&mut self.pool)?;
        let words = |b: &wgpu::Buffer| -> Result<Vec<u32>, RenderError> {
            Ok(bytemuck::cast_slice(&read_buffer(ctx, b)?).to_vec())
        };
        let n = self.scene.lights.len();
        let counts = passes::light_cluster::counts_of(&words(&c.args)?, n as u32);
        let count = counts.clusters as usize;
        let clusters: Vec<f32> = bytemuck::cast_slice(&read_buffer(ctx, &c.clusters)?).to_vec();
        let extent: Vec<f32> = bytemuck::cast_slice(&read_buffer(ctx, &c.extent)?).to_vec();
        Ok(LightClusters {
            centres: words(&c.centres)?[..count].to_vec(),
            radius_m: (0..count).map(|k| clusters[4 * k + 3]).collect(),
            extent_m: extent[..count].to_vec(),
            light_cluster: words(&c.light_cluster)?[..n].to_vec(),
            culled: counts.culled,
        })
    }

    /// Runs the G-buffer, unique-clusters and light-assignment passes of mode gates for `view`
    /// and reads back what they built, as the CPU twin [`crate::cpu::clustered::assign`] gives
    /// it: each pixel's surface (the G-buffer's position, normal, visibility cluster, and the
    /// GPU's view depth), the geometry clusters with their boxes, and each cluster's light
    /// list (empty with portals, which keep none). For tests and inspection; slow (reads all
    /// back).
    pub fn light_lists(
        &mut self,
        ctx: &GpuContext,
        view: &View,
        vpls: &[Vpl],
        gates: &GatesParams,
    ) -> Result<(Vec<Option<PixelSurface>>, Clustered), RenderError> {
        let params = GpuParams::with_mode(GpuMode::Gates(*gates));
        params.check()?;
        let mut rec = Recorder::new(ctx, &mut self.pool);
        let v = self.frame_vpls(ctx, &VplInput::Given(vpls), &mut rec)?;
        let n = v.1;
        let (frame, p, pool) = self.frame(ctx, view, &params, (v.0, n, Some(vpls)));
        let g = p.gbuffer.record(&frame, pool, &mut rec);
        let b = p
            .clustered
            .record(&frame, gates, pool, &mut rec, &g.views[0])?;
        rec.finish(pool)?;
        b.read_back(ctx, &g)
    }
}
