//! LightCluster for the direct light (`--direct lightcluster`; the paper in
//! `../shared/papers/lightcluster-pcss.txt`): the lights culled by range and clustered on the
//! GPU each frame exactly as [`crate::cpu::lightcluster`] does (light_cluster.wgsl), a cube
//! shadow map per cluster as six tiles of one depth atlas (a depth-only draw per tile, indirect:
//! a tile whose cluster was not made draws nothing), and each cluster's PCSS visibility written once into a screen-sized layer (lc_shadows.wgsl),
//! which the shading pass reads for every light of the cluster. The per-light shadow maps are
//! not drawn.

use glam::Vec3;

use crate::RenderError;
use crate::camera::View;
use crate::cpu::lightcluster::light_range_scale;
use crate::gpu::context::{Pool, array_view, bind_group, compute_pipelines};
use crate::gpu::geometry::{VERTEX_STRIDE, positions};
use crate::gpu::layout::LcFrame;
use crate::gpu::passes::gbuffer::GBufferOutput;
use crate::gpu::shaders::{self, ShaderSources, WG_LINEAR};
use crate::gpu::timing::Recorder;
use crate::gpu::{Frame, SceneGpu};

pub use super::lc_params::{DirectLight, LcDisk, LightClusterGpuParams, PcssParams};

/// Most clusters a frame can have (the centre pass keeps them in workgroup memory).
pub const MAX_LC_CLUSTERS: u32 = 256;
/// Most lights (or VPLs) LightCluster takes: its ranking walks every pair, a light's thread
/// every light (a software rasterizer ends a shader's loops after 65,535 steps).
pub const MAX_LC_LIGHTS: u32 = 16_384;

/// The pipelines.
pub struct LightCluster {
    cull: wgpu::ComputePipeline,
    rank: wgpu::ComputePipeline,
    vpl_lights: wgpu::ComputePipeline,
    centres: wgpu::ComputePipeline,
    assign: wgpu::ComputePipeline,
    atlas: wgpu::RenderPipeline,
    pcss: wgpu::ComputePipeline,
}

/// What the clustering leaves on the GPU.
pub struct LcClusters {
    /// The frame's constants.
    pub frame: wgpu::Buffer,
    /// Each light's cluster (`NONE` where culled).
    pub light_cluster: wgpu::Buffer,
    /// Each cluster's centre and radius.
    pub clusters: wgpu::Buffer,
    /// Each cluster's centre light.
    pub centres: wgpu::Buffer,
    /// Each cluster's reach (f32 bits).
    pub reach: wgpu::Buffer,
    /// Each cluster's extent (f32 bits).
    pub extent: wgpu::Buffer,
    /// The PCSS pass's dispatch args, clusters and culled lights (at [`ARGS_COUNTS`]), then
    /// from byte 32 each atlas tile's draw args (u32 each).
    pub args: wgpu::Buffer,
}

/// What the shading pass reads.
pub struct LcOutput {
    /// The clusters.
    pub clusters: LcClusters,
    /// Each cluster's visibility: layer k / 4, channel k % 4.
    pub visibility: wgpu::Texture,
}

/// Where in `args` the clusters' and the culled lights' counts are (u32 words).
pub const ARGS_COUNTS: u64 = 3;
/// Where in `args` the atlas tiles' draw args start. [Units: bytes]
const ARGS_DRAWS: u64 = 32;

/// The frame constants of the clustering for `view`.
pub fn lc_frame(
    scene: &SceneGpu,
    view: &View,
    p: &LightClusterGpuParams,
    (normal_offset, bias): (f32, f32),
) -> LcFrame {
    let half_x = 0.5 * view.fov_x_rad;
    let half_y = view.tan_half().y.atan();
    let (per_row, _) = p.atlas_tiles();
    let v4 = |v: Vec3| v.extend(0.0).to_array();
    LcFrame {
        eye: v4(view.eye),
        right: v4(view.right),
        up: v4(view.up),
        forward: v4(view.forward),
        half_fov: [half_x.cos(), half_x.sin(), half_y.cos(), half_y.sin()],
        light_count: scene.lights.len() as u32,
        max_clusters: p.clustering.max_clusters,
        map_size: p.map_size,
        tiles_per_row: per_row,
        min_distance_m: p.clustering.min_distance_m,
        distance_scale: p.clustering.distance_scale,
        range_scale: light_range_scale(&scene.lights, scene.diagonal_m, p.clustering.cutoff),
        near_m: scene.near_m,
        far_m: scene.light_far_m(),
        normal_offset,
        bias,
        blocker_samples: p.pcss.blocker_samples,
        filter_samples: p.pcss.filter_samples,
        width: view.size[0],
        height: view.size[1],
        vertex_count: scene.geometry.vertex_count,
        disk_extent: u32::from(p.disk == LcDisk::Extent),
        hemisphere: 0,
        _pad1: 0,
        _pad2: 0,
    }
}

/// What LightCluster clusters: the scene's lights (`--direct lightcluster`) or the frame's
/// VPLs (mode vpl-clusters). Each keeps its own resources, so both can run in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LcKind {
    /// The lights.
    Direct = 0,
    /// The VPLs.
    Vpls = 1,
}

/// The pool labels of one kind's resources, `prefix` before each: frame, light cluster,
/// clusters, centres, reach, extent, args, key, order, atlas, visibility, tiles, VPL lights.
macro_rules! lc_labels {
    ($prefix:literal) => {
        [
            concat!($prefix, "lc frame"),
            concat!($prefix, "lc light cluster"),
            concat!($prefix, "lc clusters"),
            concat!($prefix, "lc centres"),
            concat!($prefix, "lc reach"),
            concat!($prefix, "lc extent"),
            concat!($prefix, "lc args"),
            concat!($prefix, "lc light key"),
            concat!($prefix, "lc order"),
            concat!($prefix, "lc atlas"),
            concat!($prefix, "lc visibility"),
            concat!($prefix, "lc tiles"),
            concat!($prefix, "lc lights"),
        ]
    };
}

/// Each kind's labels (by [`LcKind`]).
const LABELS: [[&str; 13]; 2] = [lc_labels!(""), lc_labels!("vpl ")];

/// The atlas pipeline: positions and a per-instance tile index in, reversed depth out (test
/// "greater", cleared to 0), no fragment stage.
fn depth_only_pipeline(d: &wgpu::Device, module: &wgpu::ShaderModule) -> wgpu::RenderPipeline {
    let tile = wgpu::VertexBufferLayout {
        array_stride: 4,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &[wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Uint32,
            offset: 0,
            shader_location: 1,
        }],
    };
    d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("lightcluster atlas"),
        layout: None,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_atlas"),
            buffers: &[Some(positions(VERTEX_STRIDE)), Some(tile)],
            compilation_options: Default::default(),
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Greater),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: None,
        multiview_mask: None,
        cache: None,
    })
}

impl LightCluster {
    /// Builds the pipelines.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<LightCluster, RenderError> {
        let module = shaders::module(d, s, "light_cluster.wgsl")?;
        let [cull, rank, centres, assign, vpl_lights] = compute_pipelines(
            d,
            &module,
            ["cull", "rank", "centres_pass", "assign", "vpl_lights"],
        );
        let shadows = shaders::module(d, s, "lc_shadows.wgsl")?;
        let atlas = depth_only_pipeline(d, &shadows);
        let [pcss] = compute_pipelines(d, &shadows, ["pcss_pass"]);
        Ok(LightCluster {
            cull,
            rank,
            vpl_lights,
            centres,
            assign,
            atlas,
            pcss,
        })
    }

    /// Records the culling and the clustering of the emitters in `lights` for `frame`
    /// (uploaded in `frame_buf`, [`upload_frame`]).
    pub fn record_clustering(
        &self,
        ctx: &crate::gpu::GpuContext,
        (frame, frame_buf, kind): (&LcFrame, &wgpu::Buffer, LcKind),
        lights: &wgpu::Buffer,
        pool: &mut Pool,
        rec: &mut Recorder,
    ) -> Result<LcClusters, RenderError> {
        let n = frame.light_count;
        if n > MAX_LC_LIGHTS {
            let (what, instead) = match kind {
                LcKind::Direct => ("lights; the scene has", "--direct per-light"),
                LcKind::Vpls => ("VPLs; the frame has", "fewer VPLs"),
            };
            return Err(RenderError::Param(format!(
                "LightCluster takes at most {MAX_LC_LIGHTS} {what} {n} (use {instead})"
            )));
        }
        let l = &LABELS[kind as usize];
        let d = &ctx.device;
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let words = |k: u32| 4 * u64::from(k.max(1));
        let m = frame.max_clusters;
        let out = LcClusters {
            frame: frame_buf.clone(),
            light_cluster: pool.buffer(d, l[1], words(n), rw),
            clusters: pool.buffer(d, l[2], 4 * words(m), rw),
            centres: pool.buffer(d, l[3], words(m), rw),
            reach: pool.buffer(d, l[4], words(m), rw),
            extent: pool.buffer(d, l[5], words(m), rw),
            args: pool.buffer(
                d,
                l[6],
                ARGS_DRAWS + 16 * 6 * u64::from(m),
                rw | wgpu::BufferUsages::INDIRECT,
            ),
        };
        let key = pool.buffer(d, l[7], words(n), rw);
        let order = pool.buffer(d, l[8], words(n), rw);
        let all: [(u32, &wgpu::Buffer); 10] = [
            (0, &out.frame),
            (1, lights),
            (2, &key),
            (3, &out.light_cluster),
            (4, &order),
            (5, &out.clusters),
            (6, &out.centres),
            (7, &out.reach),
            (8, &out.args),
            (9, &out.extent),
        ];
        let group = |pipeline: &wgpu::ComputePipeline, used: &[u32]| {
            let resources = all
                .iter()
                .filter(|(k, _)| used.contains(k))
                .map(|&(k, b)| (k, b.as_entire_binding()))
                .collect();
            bind_group(d, &pipeline.get_bind_group_layout(0), "lc", resources)
        };
        let steps = [
            (
                &self.cull,
                group(&self.cull, &[0, 1, 2, 3]),
                n.div_ceil(WG_LINEAR),
            ),
            (
                &self.rank,
                group(&self.rank, &[0, 2, 4]),
                n.div_ceil(WG_LINEAR),
            ),
            (
                &self.centres,
                group(&self.centres, &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9]),
                1,
            ),
            (
                &self.assign,
                group(&self.assign, &[0, 1, 2, 3, 5, 6, 7, 8, 9]),
                n.div_ceil(WG_LINEAR),
            ),
        ];
        for (i, (pipeline, bg, groups)) in steps.iter().enumerate() {
            let span = rec.begin(span_names(kind)[usize::from(i > 0)]);
            {
                let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("lightcluster clustering"),
                    timestamp_writes: span.compute(),
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, bg, &[]);
                pass.dispatch_workgroups((*groups).max(1), 1, 1);
            }
            rec.end();
        }
        Ok(out)
    }

    /// Records the cube faces of every cluster into `atlas`: a depth-only draw per tile, in its
    /// viewport, drawn where the clustering made its cluster (indirect: 0 instances else).
    fn record_atlas(
        &self,
        f: &Frame,
        (p, kind): (&LightClusterGpuParams, LcKind),
        clusters: &LcClusters,
        atlas: &wgpu::TextureView,
        pool: &mut Pool,
        rec: &mut Recorder,
    ) {
        let d = &f.ctx.device;
        let tiles = 6 * p.clustering.max_clusters;
        let index: Vec<u32> = (0..tiles).collect();
        let l = &LABELS[kind as usize];
        let index_buf = pool.upload(
            f.ctx,
            l[11],
            bytemuck::cast_slice(&index),
            wgpu::BufferUsages::VERTEX,
        );
        let bg = bind_group(
            d,
            &self.atlas.get_bind_group_layout(0),
            l[9],
            vec![
                (0, clusters.frame.as_entire_binding()),
                (1, clusters.clusters.as_entire_binding()),
            ],
        );
        let (per_row, _) = p.atlas_tiles();
        let side = p.map_size;
        let span = rec.begin(span_names(kind)[2]);
        let mut pass = rec.enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("lightcluster atlas"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: atlas,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: span.render(true, true),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.atlas);
        pass.set_bind_group(0, &bg, &[]);
        pass.set_vertex_buffer(0, f.scene.geometry.vertices.slice(..));
        for t in 0..tiles {
            let (x, y) = ((t % per_row) * side, (t / per_row) * side);
            pass.set_viewport(x as f32, y as f32, side as f32, side as f32, 0.0, 1.0);
            pass.set_scissor_rect(x, y, side, side);
            let at = u64::from(t) * 4;
            pass.set_vertex_buffer(1, index_buf.slice(at..at + 4));
            pass.draw_indirect(&clusters.args, ARGS_DRAWS + 16 * u64::from(t));
        }
        drop(pass);
        rec.end();
    }

    /// Records the whole method for frame `f`'s lights: clustering, the cluster shadow atlas
    /// and the PCSS visibility of every cluster at every pixel of `g`.
    pub fn record(
        &self,
        f: &Frame,
        p: &LightClusterGpuParams,
        lights: &wgpu::Buffer,
        g: &GBufferOutput,
        pool: &mut Pool,
        rec: &mut Recorder,
    ) -> Result<LcOutput, RenderError> {
        let shadows = &f.params.shadows;
        let frame = lc_frame(f.scene, f.view, p, (shadows.normal_offset, shadows.bias));
        let frame_buf = upload_frame(f.ctx, pool, &frame, LcKind::Direct);
        let input = (p, &frame, &frame_buf, LcKind::Direct);
        self.record_with(f, input, lights, g, pool, rec)
    }

    /// The same for frame `f`'s VPLs (mode vpl-clusters): each a point light of intensity
    /// Φ/π lighting its normal's hemisphere, none culled by range (a VPL out of view lights
    /// what is in view).
    pub fn record_vpls(
        &self,
        f: &Frame,
        p: &LightClusterGpuParams,
        g: &GBufferOutput,
        pool: &mut Pool,
        rec: &mut Recorder,
    ) -> Result<LcOutput, RenderError> {
        let shadows = &f.params.shadows;
        let mut frame = lc_frame(f.scene, f.view, p, (shadows.normal_offset, shadows.bias));
        frame.light_count = f.vpl_count;
        frame.range_scale = 1e30;
        frame.hemisphere = 1;
        let l = &LABELS[LcKind::Vpls as usize];
        let d = &f.ctx.device;
        let uniform = upload_frame(f.ctx, pool, &frame, LcKind::Vpls);
        let lights = pool.buffer(
            d,
            l[12],
            64 * u64::from(f.vpl_count.max(1)),
            wgpu::BufferUsages::STORAGE,
        );
        let bg = bind_group(
            d,
            &self.vpl_lights.get_bind_group_layout(0),
            l[12],
            vec![
                (0, uniform.as_entire_binding()),
                (10, f.vpls.as_entire_binding()),
                (11, lights.as_entire_binding()),
            ],
        );
        {
            let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("VPLs as lights"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.vpl_lights);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(f.vpl_count.div_ceil(WG_LINEAR).max(1), 1, 1);
        }
        let input = (p, &frame, &uniform, LcKind::Vpls);
        self.record_with(f, input, &lights, g, pool, rec)
    }

    /// [`LightCluster::record`] with `frame` (uploaded in `frame_buf`) for the emitters in
    /// `lights`.
    fn record_with(
        &self,
        f: &Frame,
        (p, frame, frame_buf, kind): (&LightClusterGpuParams, &LcFrame, &wgpu::Buffer, LcKind),
        lights: &wgpu::Buffer,
        g: &GBufferOutput,
        pool: &mut Pool,
        rec: &mut Recorder,
    ) -> Result<LcOutput, RenderError> {
        p.check()?;
        let d = &f.ctx.device;
        let (per_row, rows) = p.atlas_tiles();
        let side = p.map_size;
        let max_dim = d.limits().max_texture_dimension_2d;
        if per_row * side > max_dim || rows * side > max_dim {
            return Err(RenderError::Param(format!(
                "LightCluster's shadow atlas ({} × {} texels: {} clusters × 6 faces of {side}²) \
                 exceeds the adapter's {max_dim}: lower the cube face size or the most clusters",
                per_row * side,
                rows * side,
                p.clustering.max_clusters
            )));
        }
        let input = (frame, frame_buf, kind);
        let clusters = self.record_clustering(f.ctx, input, lights, pool, rec)?;
        let l = &LABELS[kind as usize];
        let atlas = pool.texture(
            d,
            l[9],
            [per_row * side, rows * side, 1],
            1,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let atlas_view = atlas.create_view(&Default::default());
        let [w, h] = f.view.size;
        let layers = p.clustering.max_clusters.div_ceil(4);
        let visibility = pool.texture(
            d,
            l[10],
            [w, h, layers],
            1,
            wgpu::TextureFormat::Rgba8Unorm,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        self.record_atlas(f, (p, kind), &clusters, &atlas_view, pool, rec);
        let span = rec.begin(span_names(kind)[3]);
        let vis_view = array_view(&visibility);
        let bg = bind_group(
            d,
            &self.pcss.get_bind_group_layout(0),
            l[10],
            vec![
                (0, clusters.frame.as_entire_binding()),
                (1, clusters.clusters.as_entire_binding()),
                (2, clusters.reach.as_entire_binding()),
                (3, clusters.args.as_entire_binding()),
                (4, wgpu::BindingResource::TextureView(&atlas_view)),
                (5, wgpu::BindingResource::TextureView(&g.views[0])),
                (6, wgpu::BindingResource::TextureView(&g.views[1])),
                (7, wgpu::BindingResource::TextureView(&vis_view)),
                (8, clusters.extent.as_entire_binding()),
                (9, lights.as_entire_binding()),
                (10, clusters.centres.as_entire_binding()),
            ],
        );
        {
            let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("lightcluster pcss"),
                timestamp_writes: span.compute(),
            });
            pass.set_pipeline(&self.pcss);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups_indirect(&clusters.args, 0);
        }
        rec.end();
        Ok(LcOutput {
            clusters,
            visibility,
        })
    }
}

/// `frame` uploaded as `kind`'s uniform (one upload a frame: every pass of the kind binds it).
pub fn upload_frame(
    ctx: &crate::gpu::GpuContext,
    pool: &mut Pool,
    frame: &LcFrame,
    kind: LcKind,
) -> wgpu::Buffer {
    let label = LABELS[kind as usize][0];
    pool.upload(
        ctx,
        label,
        bytemuck::bytes_of(frame),
        wgpu::BufferUsages::UNIFORM,
    )
}

/// LightCluster's counts from its args (read back): clusters made, emitters culled, of
/// `emitters`.
pub fn counts_of(args: &[u32], emitters: u32) -> crate::gpu::LcCounts {
    let at = ARGS_COUNTS as usize;
    crate::gpu::LcCounts {
        clusters: args[at],
        culled: args[at + 1],
        lights: emitters,
    }
}

/// The pass names of each kind: culling, clustering, shadow maps, visibility (the paper's).
fn span_names(kind: LcKind) -> [&'static str; 4] {
    match kind {
        LcKind::Direct => [
            "light culling",
            "light clustering",
            "cluster shadow maps",
            "PCSS visibility",
        ],
        LcKind::Vpls => [
            "VPL culling",
            "VPL clustering",
            "VPL cluster shadow maps",
            "VPL PCSS visibility",
        ],
    }
}
