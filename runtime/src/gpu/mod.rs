//! The wgpu renderer. A [`GpuRenderer`] is made once for a scene (and a baked level), keeps its
//! pipelines and — in a [`context::Pool`] — every texture and buffer a frame needs, and renders
//! frames: per-frame inputs (view, VPLs or their RSM source, [`GpuParams`]) go in, an HDR image
//! and the [`PassTimes`] come out. A second frame with the same sizes and settings makes no GPU
//! resource; a frame is recorded into one command encoder and, where the adapter has timestamp
//! queries, submitted once (per-VPL maps: once per batch, as recorded) and waited for once, at
//! its readback. GPU errors of a frame come back as [`RenderError`], not as panics.
//!
//! A frame, as [`record_passes`] lists it:
//!
//! 1. VPLs: uploaded, or made from the lights' RSMs on the GPU ([`passes::rsm_vpls`]), where
//!    they stay;
//! 2. the lights' shadow maps ([`passes::shadow_maps`]), unless LightCluster shadows them;
//! 3. the G-buffer ([`passes::gbuffer`]); with `--direct lightcluster`, LightCluster's light
//!    culling, clustering, cluster shadow maps and PCSS visibility ([`passes::light_cluster`]),
//!    and in mode `vpl-clusters` the same over the VPLs;
//! 4. mode `gates`: unique clusters and light assignment ([`passes::clustered_gates`]), or with
//!    the voxel walk each VPL's walk end ([`passes::sight_ends`]);
//! 5. shading: direct light, and the indirect light of modes `none` and the gate modes
//!    ([`passes::shade`]);
//! 6. mode `per-vpl-shadow-maps`: maps and gather per batch ([`passes::per_vpl_maps`]); the VAL
//!    modes: clustering, maps, CSSM basis, gather, blur ([`passes::vals`], [`passes::cssm`],
//!    [`passes::val_gather`], [`passes::interleave_blur`]); the ISM modes: (val-ism) the
//!    clustering, ISM points, atlas, pull-push, gather, blur ([`passes::ism`]);
//! 7. readback of the HDR image, unless a window asked for the frame on the GPU only: then
//!    [`GpuRenderer::display`] tone-maps it into a texture a window shows as it is
//!    ([`passes::display`]).
//!
//! The methods and their parameters are in [`methods`] (the registry [`METHODS`]); a frame's
//! run — its checks, its passes recorded, its readback — in `run.rs` and `record.rs`; what a
//! renderer reads back besides a frame (for tests and inspection) in `inspect.rs`; every
//! struct shared with WGSL in [`layout`]; the WGSL include step and injected constants in
//! [`shaders`].

pub mod context;
pub mod geometry;
mod inspect;
pub mod layout;
pub mod methods;
pub mod passes;
mod record;
mod run;
mod scene_gpu;
pub use scene_gpu::SceneGpu;
pub mod shaders;
pub mod timing;

use glam::Vec3;
use visgate_formats::{Light as SceneLight, Scene};

use crate::RenderError;
use crate::camera::View;
use crate::cpu::gates::{GateLevel, GateShape};
use crate::hdr::HdrImage;
use crate::vpl::Vpl;
use context::{Pool, init_buffer};
use geometry::{Geometry, albedo_array};
use layout::{Globals, Grid};
use passes::clustered_gates::{ClusteredGates, LevelBuffers};
use passes::cssm::Cssm;
use passes::display::Display;
use passes::gbuffer::GBuffer;
use passes::interleave_blur::InterleaveBlur;
use passes::ism::Isms;
use passes::light_cluster::LightCluster;
use passes::per_vpl_maps::ParaboloidMaps;
use passes::rsm_vpls::RsmVpls;
use passes::shade::Shade;
use passes::shadow_maps::ShadowMaps;
use passes::sight_ends::SightEnds;
use passes::unshadowed::Unshadowed;
use passes::val_gather::ValGathers;
use passes::vals::ValClustering;
use shaders::ShadeIndirect;
pub use shaders::ShaderSources;
use timing::Recorder;

pub use context::GpuContext;
pub use geometry::{MAX_TEXTURE_SIZE, VPL_SHADOW_MAX_EDGE};
pub use methods::{
    CssmParams, DirectLight, DiskLight, GatesParams, GpuMode, GpuParams, InterleaveParams,
    IsmParams, LcDisk, LightClusterGpuParams, METHODS, MethodInfo, MethodSettings, PcssParams,
    PerVplParams, ShadowParams, ValIsmParams, ValModeParams, VplIsmParams, method,
};
pub use passes::clustered_gates::{
    AUTO_ROULETTE_BLOCK, AUTO_ROULETTE_RATIO_VPLS, AUTO_ROULETTE_SHARE, AUTO_ROULETTE_VPLS,
    MAX_CLUSTERS, MAX_GATES, WalkRoulette,
};
pub use passes::display::{DISPLAY_FORMAT, read_display};
pub use passes::gates_params::{NEAR_FIELD_MAX, RATIO_STRIDE, RATIO_STRIDE_MAX};
pub use passes::interleave_blur::MIN_VPLS_PER_PIXEL;
pub use passes::light_cluster::{MAX_LC_CLUSTERS, MAX_LC_LIGHTS};
pub use passes::rsm_vpls::RsmParams;
pub use passes::unshadowed::RATIO_RUN;
pub use timing::{LcCounts, LightListStats, PassTime, PassTimes, ValIterations};

/// Where a frame's VPLs come from.
#[derive(Debug, Clone, Copy)]
pub enum VplInput<'a> {
    /// These, uploaded.
    Given(&'a [Vpl]),
    /// The lights' RSMs, on the GPU (they stay there).
    Rsm(RsmParams),
}

/// What every pass of a frame reads.
pub struct Frame<'a> {
    /// The device.
    pub ctx: &'a GpuContext,
    /// The scene.
    pub scene: &'a SceneGpu,
    /// The camera.
    pub view: &'a View,
    /// The settings.
    pub params: &'a GpuParams,
    /// [`Globals`].
    pub globals: wgpu::Buffer,
    /// [`Grid`].
    pub grid: wgpu::Buffer,
    /// The VPLs.
    pub vpls: wgpu::Buffer,
    /// How many.
    pub vpl_count: u32,
    /// The same VPLs on the CPU, where the caller gave them.
    pub vpls_cpu: Option<&'a [Vpl]>,
    /// VPLs of a pixel's subset mode gates walks a draw ([`methods::walk_batch`]; also
    /// [`Globals::walk_batch`], which the shader reads).
    pub walk_batch: u32,
    /// The near field's radius per metre of distance from the eye ([`Globals::near_scale`]; 0:
    /// none).
    pub near_scale: f32,
    /// Whether the interleaved walks' blur takes the ratio estimator ([`Globals::ratio`];
    /// [`GpuMode::ratio_for`] of the frame's VPLs).
    pub ratio: bool,
    /// The ratio estimator's grid stride ([`Globals::ratio_stride`]; 1 without it).
    pub ratio_stride: u32,
    /// Marked VPLs a tile of the near field walks a round ([`methods::near_run`]; 0: all in
    /// one).
    pub near_run: u32,
    /// The starved pixels' list of (pixel, subset) pairs: its capacity.
    pub starved_pairs: u32,
}

/// Every pass's pipelines.
pub struct Pipelines {
    shadow_maps: ShadowMaps,
    gbuffer: GBuffer,
    shade: Shade,
    rsm: RsmVpls,
    maps: ParaboloidMaps,
    clustered: ClusteredGates,
    vals: ValClustering,
    cssm: Cssm,
    val_gather: ValGathers,
    blur: InterleaveBlur,
    light_cluster: LightCluster,
    isms: Isms,
    display: Display,
    sight_ends: SightEnds,
    unshadowed: Unshadowed,
}

impl Pipelines {
    fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<Pipelines, RenderError> {
        Ok(Pipelines {
            shadow_maps: ShadowMaps::new(d, s)?,
            gbuffer: GBuffer::new(d, s)?,
            shade: Shade::new(d, s)?,
            rsm: RsmVpls::new(d, s)?,
            maps: ParaboloidMaps::new(d, s)?,
            clustered: ClusteredGates::new(d, s)?,
            vals: ValClustering::new(d, s)?,
            cssm: Cssm::new(d, s)?,
            val_gather: ValGathers::new(d, s)?,
            blur: InterleaveBlur::new(d, s)?,
            light_cluster: LightCluster::new(d, s)?,
            isms: Isms::new(d, s)?,
            display: Display::new(d, s)?,
            sight_ends: SightEnds::new(d, s)?,
            unshadowed: Unshadowed::new(d, s)?,
        })
    }
}

/// The scene on the GPU, the pipelines, and the resources kept across frames.
pub struct GpuRenderer {
    scene: SceneGpu,
    pipelines: Pipelines,
    pool: Pool,
    /// VALs clustered last frame (their centres are in the pool): a warm start's condition.
    val_warm: Option<u32>,
    /// The light-list pool's capacity when it grows on its own (mode gates).
    light_entries: u32,
    /// The starved pixels' pairs' list's capacity once a frame outgrew its first (0: none
    /// yet, [`passes::starved::FIRST_PAIRS_PER_PIXEL`] a pixel).
    starved_pairs: u32,
    /// The last frame's HDR target (in the pool: the next frame of its size overwrites it).
    last_hdr: Option<wgpu::Texture>,
}

impl GpuRenderer {
    /// Uploads every mesh of `scene` (albedo per vertex from its material, textures as layers
    /// of one sRGB array, resized to the largest texture's size up to [`MAX_TEXTURE_SIZE`]) and
    /// builds the pipelines.
    pub fn new(ctx: &GpuContext, scene: &Scene) -> Result<GpuRenderer, RenderError> {
        let d = &ctx.device;
        let geometry = Geometry::upload(d, scene);
        let size = geometry.size;
        let (albedo_maps, albedo_sampler) = albedo_array(ctx, scene);
        let no_grid = Grid {
            voxel_size: 1.0,
            value_bytes: 4,
            oversize: 1.0,
            max_hops: 1,
            ..bytemuck::Zeroable::zeroed()
        };
        Ok(GpuRenderer {
            scene: SceneGpu {
                geometry,
                lights: scene.lights.clone(),
                near_m: size * 1e-4,
                far_m: size * 4.0,
                bounds: scene.bounds().unwrap_or((Vec3::ZERO, Vec3::ZERO)),
                diagonal_m: size,
                albedo_maps,
                albedo_sampler,
                level: None,
                no_level: init_buffer(d, "no level", &[], wgpu::BufferUsages::STORAGE),
                no_visibility: d.create_texture(&wgpu::TextureDescriptor {
                    label: Some("no lightcluster visibility"),
                    size: wgpu::Extent3d {
                        width: 1,
                        height: 1,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: wgpu::TextureFormat::Rgba8Unorm,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                }),
                no_grid: init_buffer(
                    d,
                    "no grid",
                    bytemuck::bytes_of(&no_grid),
                    wgpu::BufferUsages::UNIFORM,
                ),
            },
            pipelines: Pipelines::new(d, &ShaderSources::builtin())?,
            pool: Pool::default(),
            val_warm: None,
            light_entries: passes::clustered_gates::AUTO_LIGHT_ENTRIES,
            starved_pairs: 0,
            last_hdr: None,
        })
    }

    /// Rebuilds every pipeline from `sources` (shader hot reload): they are validated first
    /// (naga, as the GPU's compiler; the error names the file and line) and built under an
    /// error scope, and only when all of them build do they replace the current ones — on an
    /// error the last good pipelines keep drawing.
    pub fn reload_shaders(
        &mut self,
        ctx: &GpuContext,
        sources: &ShaderSources,
    ) -> Result<(), RenderError> {
        sources.validate()?;
        let pipelines = context::scoped(ctx, || Pipelines::new(&ctx.device, sources))?;
        self.pipelines = pipelines;
        self.val_warm = None;
        Ok(())
    }

    /// Replaces the geometry and the lights with those of `scene` posed at another time (the
    /// same meshes and materials; dynamic meshes moved, see `Scene::at`). Pipelines, textures,
    /// the level, the kept frame resources and the near/far planes (from the first scene's
    /// size) stay.
    pub fn set_scene(&mut self, ctx: &GpuContext, scene: &Scene) {
        self.scene.geometry = Geometry::upload(&ctx.device, scene);
        self.scene.lights = scene.lights.clone();
    }

    /// Replaces the lights (they move freely: shadow maps and RSMs are made per frame).
    pub fn set_lights(&mut self, lights: &[SceneLight]) {
        self.scene.lights = lights.to_vec();
    }

    /// Uploads a baked level's gate tables for the gate modes; the voxel→cluster grid keeps
    /// the smallest integer type that holds the level's clusters. The closed voxels' planes,
    /// which the default voxel walk reads, are fitted now if they were not
    /// ([`GateLevel::fit_planes`]); their triangle lists go up if they are listed
    /// ([`GateLevel::list_triangles`]), which the voxel walk with the triangles needs — where
    /// they overflow the adapter's storage binding, the planes alone, or neither (a mode that
    /// needs them then says so: [`GpuRenderer::level_for_mode`]).
    pub fn set_level(&mut self, ctx: &GpuContext, level: &GateLevel) -> Result<(), RenderError> {
        level.fit_planes();
        let tries = [[true; 2], [false, true], [false; 2]];
        self.scene.level = Some(upload_level(ctx, level, &tries)?);
        Ok(())
    }

    /// Whether the uploaded level carries the closed voxels' triangle lists (the voxel walk
    /// with the triangles needs them; [`GpuRenderer::set_level`]).
    pub fn level_has_triangles(&self) -> bool {
        self.scene.level.as_ref().is_some_and(|l| l.triangles)
    }

    /// Whether the uploaded level carries the closed voxels' planes (the default voxel walk
    /// needs them; [`GpuRenderer::set_level`]).
    pub fn level_has_planes(&self) -> bool {
        self.scene.level.as_ref().is_some_and(|l| l.planes)
    }

    /// Makes the uploaded level serve `mode`: uploads `level` if none is up, and again with the
    /// closed voxels' triangle lists (listed now) when `mode` walks with them and they are not
    /// up yet, or with their planes (fitted now) likewise — the first frame of that mode pays
    /// for them, a level never walked with them does not. An upload keeps what was up with
    /// what `mode` needs where both fit the adapter's storage binding, else it takes what
    /// `mode` needs alone: on an adapter whose binding the lists overflow (each part of the
    /// walk's tables is a binding of its own: `VoxelSight::words`), only the mode that walks
    /// them fails.
    pub fn level_for_mode(
        &mut self,
        ctx: &GpuContext,
        level: &GateLevel,
        mode: &GpuMode,
    ) -> Result<(), RenderError> {
        let voxels = mode.gates().filter(|g| g.shape == GateShape::Voxels);
        let need = [
            voxels.is_some_and(|g| g.triangles),
            voxels.is_some_and(|g| g.planes && !g.triangles),
        ];
        let has = [self.level_has_triangles(), self.level_has_planes()];
        if self.scene.level.is_some() && (0..2).all(|k| !need[k] || has[k]) {
            return Ok(());
        }
        if need[0] {
            level.list_triangles();
        }
        if need[1] {
            level.fit_planes();
        }
        let want = [need[0] || has[0], need[1] || has[1]];
        self.scene.level = Some(upload_level(ctx, level, &[want, need])?);
        Ok(())
    }

    /// [`GpuRenderer::level_for_mode`], and where `mode` walks the closed voxels' triangles
    /// and their lists do not go up (over the adapter's storage binding: a level of millions of
    /// triangles on a 4 cm sight grid, on an adapter that allows 128 MiB a binding), the walk
    /// on their planes instead (the fast setting's walk; the rest of `mode` kept): `mode`
    /// changed so, and a note of why and what would keep the triangles. A mode that needs
    /// neither, or a level whose planes do not go up either, fails as before.
    pub fn level_for_mode_or_planes(
        &mut self,
        ctx: &GpuContext,
        level: &GateLevel,
        mode: &mut GpuMode,
    ) -> Result<Option<String>, RenderError> {
        let err = match self.level_for_mode(ctx, level, mode) {
            Ok(()) => return Ok(None),
            Err(e) => e,
        };
        let GpuMode::Gates(p) = mode else {
            return Err(err);
        };
        if !(p.gates.shape == GateShape::Voxels && p.gates.triangles) {
            return Err(err);
        }
        let mut planes = *p;
        planes.gates.triangles = false;
        planes.gates.planes = true;
        let planes = GpuMode::Gates(planes);
        if self.level_for_mode(ctx, level, &planes).is_err() {
            return Err(err);
        }
        *mode = planes;
        Ok(Some(format!(
            "{err}. This render walks on the closed voxels' planes instead (the fast setting's \
             walk; the rest of the setting kept)"
        )))
    }

    /// GPU textures, buffers and query sets the renderer's frames have made so far (a frame
    /// with the same sizes and settings as the last makes none).
    pub fn resources_created(&self) -> u64 {
        self.pool.created()
    }

    /// Renders `view` with `vpls` and returns the linear HDR image and the pass times.
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        view: &View,
        vpls: &[Vpl],
        params: &GpuParams,
    ) -> Result<(HdrImage, PassTimes), RenderError> {
        self.render_frame(ctx, view, VplInput::Given(vpls), params)
    }

    /// The frame's VPL buffer and count.
    fn frame_vpls(
        &mut self,
        ctx: &GpuContext,
        vpls: &VplInput,
        rec: &mut Recorder,
    ) -> Result<(wgpu::Buffer, u32), RenderError> {
        match vpls {
            VplInput::Given(v) => {
                let bytes = std::mem::size_of_val(*v) as u64;
                let limit = ctx.device.limits().max_storage_buffer_binding_size;
                if bytes > limit {
                    return Err(RenderError::Param(format!(
                        "{} VPLs need {bytes} bytes, more than the adapter's storage binding \
                         limit {limit}",
                        v.len()
                    )));
                }
                let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
                let buf = self
                    .pool
                    .upload(ctx, "vpls", bytemuck::cast_slice(v), usage);
                Ok((buf, v.len() as u32))
            }
            VplInput::Rsm(p) => self.pipelines.rsm.record(
                ctx,
                &self.pipelines.gbuffer,
                &self.scene,
                p,
                &mut self.pool,
                rec,
            ),
        }
    }

    /// The frame's constants, uploaded.
    fn frame<'a>(
        &'a mut self,
        ctx: &'a GpuContext,
        view: &'a View,
        params: &'a GpuParams,
        (vpls, vpl_count, vpls_cpu): (wgpu::Buffer, u32, Option<&'a [Vpl]>),
    ) -> (Frame<'a>, &'a Pipelines, &'a mut Pool) {
        let scene = &self.scene;
        let shade_mode = match params.mode {
            GpuMode::None => ShadeIndirect::All,
            GpuMode::GatesPerPixel(_) => ShadeIndirect::GatesPerPixel,
            GpuMode::Gates(_) => ShadeIndirect::GatesClustered,
            GpuMode::VplClusters(..) => ShadeIndirect::VplClusters,
            _ => ShadeIndirect::DirectOnly,
        };
        let walk_batch = methods::walk_batch(
            &ctx.adapter_info.name,
            &params.mode,
            scene.level.as_ref().map(|l| l.sight_steps),
            vpl_count,
        );
        let (walk_roulette, walk_seed, near_scale) = match params.mode {
            GpuMode::Gates(gp) => (
                gp.roulette_share(vpl_count),
                gp.walk_seed,
                gp.near_scale(view, vpl_count),
            ),
            _ => (0.0, 0, 0.0),
        };
        // Off where its marks (a bit a VPL for each 8 × 8 tile) would not fit a storage binding
        // (7680 × 4320 at 8,128 VPLs): the gathers must leave out only what the pass walks.
        let marks = passes::shade::near_marks_bytes(view.size, vpl_count);
        let fits = marks <= ctx.device.limits().max_storage_buffer_binding_size;
        let near_scale = if fits { near_scale } else { 0.0 };
        let ratio = params.mode.ratio_for(vpl_count);
        // Its grid: every pixel without it, or where its list would not fit a binding.
        let limit = ctx.device.limits().max_storage_buffer_binding_size;
        let stride = params.mode.ratio_stride();
        let ratio_stride = if ratio {
            passes::unshadowed::stride_that_fits(stride, view.size, limit)
        } else {
            1
        };
        let globals = Globals {
            view_proj: view.view_proj(scene.near_m).to_cols_array_2d(),
            eye: view.eye.extend(1.0).to_array(),
            g_max: params.g_max,
            shadow_normal_offset: params.shadows.normal_offset,
            shadow_bias: params.shadows.bias,
            interleave_block: match params.mode {
                GpuMode::Gates(gp) => gp.interleave.block,
                GpuMode::VplClusters(_, il) => il.block,
                _ => 1,
            },
            vpl_count,
            light_count: scene.lights.len() as u32,
            shade_mode: shade_mode as u32,
            shadow_size: params.shadows.size,
            direct_mode: params.direct.shader_id(),
            walk_batch,
            walk_roulette,
            walk_seed,
            near_scale,
            ratio: u32::from(ratio),
            ratio_stride,
            _pad2: 0,
        };
        let level = scene.level.as_ref();
        let gates = params.mode.gates().unwrap_or_default();
        let grid = Grid {
            origin: level.map_or([0.0; 3], |l| [l.origin[0], l.origin[1], l.origin[2]]),
            voxel_size: level.map_or(1.0, |l| l.origin[3]),
            dims: level.map_or([0; 3], |l| [l.dims[0], l.dims[1], l.dims[2]]),
            value_bytes: level.map_or(4, |l| l.dims[3]),
            oversize: gates.oversize,
            max_hops: gates.max_hops,
            shape: gates.shape.shader_id(),
            max_walk: gates.max_walk,
            triangles: u32::from(gates.triangles),
            planes: u32::from(gates.planes),
            _pad1: 0,
            _pad2: 0,
        };
        let uniform = wgpu::BufferUsages::UNIFORM;
        let pool = &mut self.pool;
        let frame = Frame {
            ctx,
            scene,
            view,
            params,
            globals: pool.upload(ctx, "globals", bytemuck::bytes_of(&globals), uniform),
            grid: pool.upload(ctx, "grid", bytemuck::bytes_of(&grid), uniform),
            vpls,
            vpl_count,
            vpls_cpu,
            walk_batch,
            near_scale,
            ratio,
            ratio_stride,
            near_run: methods::near_run(
                &ctx.adapter_info.name,
                &params.mode,
                scene.level.as_ref().map(|l| l.sight_voxel_m),
                near_scale * farthest(view.eye, scene.bounds),
                vpl_count,
            ),
            starved_pairs: self
                .starved_pairs
                .max(passes::starved::first_capacity(ctx, view.size)),
        };
        (frame, &self.pipelines, pool)
    }

    /// Renders `view` with VPLs from `vpls` and returns the linear HDR image and the pass
    /// times. The same call serves tests, the CLI and the viewer. A GPU error (validation,
    /// out of memory) is returned, not raised.
    pub fn render_frame(
        &mut self,
        ctx: &GpuContext,
        view: &View,
        vpls: VplInput,
        params: &GpuParams,
    ) -> Result<(HdrImage, PassTimes), RenderError> {
        let (img, times) = self.render_kept(ctx, view, vpls, params, true)?;
        let img = img.ok_or_else(|| RenderError::Gpu("the frame was not read back".into()))?;
        Ok((img, times))
    }

    /// [`GpuRenderer::render_frame`] with the frame kept on the GPU for
    /// [`GpuRenderer::display`]; the HDR image is read back only if `read_hdr` (a window that
    /// shows the frame from its texture needs no readback).
    pub fn render_kept(
        &mut self,
        ctx: &GpuContext,
        view: &View,
        vpls: VplInput,
        params: &GpuParams,
        read_hdr: bool,
    ) -> Result<(Option<HdrImage>, PassTimes), RenderError> {
        let run = |r: &mut Self, p: &GpuParams| {
            context::scoped(ctx, || r.frame_unscoped(ctx, view, vpls, p, read_hdr))
        };
        // Pools that grow: the frame again with the capacity it needed (a quarter more, for
        // the next frames' changes), up to the adapter's limit: the disks' light lists when
        // their size is not set, the starved pixels' pairs.
        let auto_lists = match params.mode {
            GpuMode::Gates(g) if g.light_entries.is_none() && g.gates.shape == GateShape::Disk => {
                Some(g)
            }
            _ => None,
        };
        let max = (ctx.device.limits().max_storage_buffer_binding_size / 8).min(u32::MAX as u64);
        let max_pairs = passes::starved::max_capacity(ctx);
        for _ in 0..3 {
            let mut p = *params;
            if let Some(g) = auto_lists {
                p.mode = GpuMode::Gates(GatesParams {
                    light_entries: Some(self.light_entries),
                    ..g
                });
            }
            match run(self, &p) {
                Err(RenderError::LightListsFull { needed, .. })
                    if auto_lists.is_some() && needed <= max =>
                {
                    self.light_entries = (needed + needed / 4).min(max) as u32;
                }
                Err(RenderError::LightListsFull { needed, .. }) if auto_lists.is_some() => {
                    return Err(RenderError::Param(format!(
                        "the light lists need {needed} entries ({} bytes), more than the \
                         adapter's storage binding limit allows ({max} entries): use fewer VPLs, \
                         a smaller image or larger tiles (--tile-px)",
                        needed * 8
                    )));
                }
                // `needed` counts every pair reserved, so it is over the capacity that failed.
                Err(RenderError::StarvedPairsFull { needed, .. }) if needed <= max_pairs => {
                    self.starved_pairs = (needed + needed / 4).min(max_pairs) as u32;
                }
                r => return r,
            }
        }
        Err(RenderError::Gpu(
            "the light lists or the starved pixels' pairs kept outgrowing their pools".into(),
        ))
    }

    /// The last frame's linear HDR image, tone-mapped at `exposure_stops` and sRGB-encoded
    /// into a texture of [`DISPLAY_FORMAT`] (the same bytes as `HdrImage::to_srgb8`), without
    /// reading anything back; submitted, not waited for. The texture is made again only when
    /// the frame's size changes. An error before the first frame.
    pub fn display(
        &mut self,
        ctx: &GpuContext,
        exposure_stops: f32,
    ) -> Result<wgpu::Texture, RenderError> {
        let hdr = (self.last_hdr.clone())
            .ok_or_else(|| RenderError::Param("no frame rendered to display yet".into()))?;
        let display = &self.pipelines.display;
        context::scoped(ctx, || {
            display.run(ctx, &mut self.pool, &hdr, exposure_stops)
        })
    }
}

/// Uploads `level` with the first of `tries` (closed voxels' triangle lists and planes,
/// `[lists, planes]`) that fits the adapter's bindings; the last one's error where none does.
fn upload_level(
    ctx: &GpuContext,
    level: &GateLevel,
    tries: &[[bool; 2]],
) -> Result<LevelBuffers, RenderError> {
    let mut result = Err(RenderError::Param("no upload tried".into()));
    for &[lists, planes] in tries {
        result = LevelBuffers::upload(ctx, level, lists, planes);
        if result.is_ok() {
            break;
        }
    }
    result
}

/// The distance from `eye` to the farthest corner of box `(lo, hi)`. [Units: m]
fn farthest(eye: glam::Vec3, (lo, hi): (glam::Vec3, glam::Vec3)) -> f32 {
    (eye - lo).abs().max((eye - hi).abs()).length()
}
