//! Clustered shading with gates on the GPU (`clusters.wgsl`): between the G-buffer (which holds
//! each pixel's visibility cluster) and the shading pass, the *unique clusters* pass finds the
//! geometry clusters in view (screen tiles × exponential depth slices × visibility cluster)
//! with their boxes, and the *light assignment* pass gives each one its list of (VPL, gate
//! chain) entries in one pool. [`crate::clustered`] is the CPU twin; the tests hold the two
//! equal ([`GpuRenderer::light_lists`]).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

use super::{GpuContext, GpuParams, GpuRenderer, PassTimes, Stage, Timer};
use crate::RenderError;
use crate::camera::View;
use crate::clustered::{Clustered, GeometryCluster, LightEntry, PixelSurface};
use crate::vpl::Vpl;

/// Per-frame constants of the clustered passes, shared with WGSL (`Frame` in clusters.wgsl).
/// 64 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct ClusterFrame {
    /// xyz eye (m).
    pub eye: [f32; 4],
    /// xyz unit view axis.
    pub forward: [f32; 4],
    /// x width, y height (px), z tile side (px), w depth slices.
    pub size: [u32; 4],
    /// x tiles across, y tiles down, z VPLs, w light-entry capacity.
    pub counts: [u32; 4],
}

/// A geometry cluster and its light list, shared with WGSL (`GeometryCluster` in
/// clusters.wgsl, `ClusterLists` in shade.wgsl). 64 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuGeometryCluster {
    /// x tile x, y tile y, z depth slice, w visibility cluster (`u32::MAX`: outside every one).
    pub key: [u32; 4],
    /// xyz box minimum (m).
    pub lo: [f32; 4],
    /// xyz box maximum (m).
    pub hi: [f32; 4],
    /// x first entry, y entries, z entries needed (> y only when the pool overflowed).
    pub list: [u32; 4],
}

/// How full the light lists came out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LightListStats {
    /// Geometry clusters in view.
    pub geometry_clusters: u32,
    /// Entries over all lists (needed, even when they did not fit).
    pub entries: u64,
    /// The pool's capacity ([`GpuParams::light_entries`]).
    pub capacity: u32,
}

/// Entry encoding: the chain's gates as (g0 + 1) | (g1 + 1) << 16, so at most this many gates.
pub const MAX_GATES: usize = 0xfffe;
/// Keys hold a visibility cluster in 23 bits, the all-ones value meaning "none".
pub const MAX_CLUSTERS: usize = 0x7f_fffe;

/// The compute pipelines of clusters.wgsl.
pub(super) struct Pipelines {
    depths: wgpu::ComputePipeline,
    tile_count: wgpu::ComputePipeline,
    scan_tiles: wgpu::ComputePipeline,
    tile_clusters: wgpu::ComputePipeline,
    vpl_clusters: wgpu::ComputePipeline,
    assign: wgpu::ComputePipeline,
}

impl Pipelines {
    pub(super) fn new(d: &wgpu::Device, source: &str) -> Pipelines {
        let [
            depths,
            tile_count,
            scan_tiles,
            tile_clusters,
            vpl_clusters,
            assign,
        ] = super::compute_pipelines(
            d,
            "clusters.wgsl",
            source,
            [
                "depths",
                "tile_count",
                "scan_tiles",
                "tile_clusters",
                "vpl_clusters",
                "assign",
            ],
        );
        Pipelines {
            depths,
            tile_count,
            scan_tiles,
            tile_clusters,
            vpl_clusters,
            assign,
        }
    }
}

/// The buffers the clustered passes fill; the shading pass reads `pixel_cluster`, `clusters`
/// and `entries`.
pub(super) struct Buffers {
    pub pixel_depth: wgpu::Buffer,
    pub pixel_cluster: wgpu::Buffer,
    pub clusters: wgpu::Buffer,
    pub counter: wgpu::Buffer,
    pub entries: wgpu::Buffer,
    pub capacity: u32,
}

fn bind_group(
    d: &wgpu::Device,
    pipeline: &wgpu::ComputePipeline,
    resources: Vec<(u32, wgpu::BindingResource)>,
) -> wgpu::BindGroup {
    super::bind_group(d, &pipeline.get_bind_group_layout(0), "clusters", resources)
}

impl GpuRenderer {
    /// The unique-clusters and light-assignment passes for `view` over the G-buffer positions
    /// `g_position` (w = visibility cluster), with `vpls` in `vpl_buf` and the level's grid
    /// uniform `grid_buf`. Each pass is submitted and waited for; their times go into `times`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn cluster_passes(
        &self,
        ctx: &GpuContext,
        view: &View,
        vpls: &[Vpl],
        vpl_buf: &wgpu::Buffer,
        grid_buf: &wgpu::Buffer,
        g_position: &wgpu::TextureView,
        params: &GpuParams,
        timer: &mut Timer,
        times: &mut PassTimes,
    ) -> Result<Buffers, RenderError> {
        let d = &ctx.device;
        let level = self.level.as_ref().ok_or_else(|| {
            RenderError::Param("mode gates needs a baked level (GpuRenderer::set_level)".into())
        })?;
        let cp = params.clusters;
        if !(1..=16).contains(&cp.tile_px) || !(1..=256).contains(&cp.depth_slices) {
            return Err(RenderError::Param(format!(
                "tile side {} px must be 1..=16 on the GPU (one 256-thread workgroup per tile) \
                 and depth slices {} 1..=256",
                cp.tile_px, cp.depth_slices
            )));
        }
        let [w, h] = view.size;
        let tiles = [w.div_ceil(cp.tile_px), h.div_ceil(cp.tile_px)];
        let n_tiles = tiles[0] as u64 * tiles[1] as u64;
        let pixels = w as u64 * h as u64;
        let limits = d.limits();
        let max_binding = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        let capacity = params.light_entries;
        let sizes = [
            ("geometry clusters", pixels * 64, "a smaller image"),
            (
                "light entries",
                capacity as u64 * 8,
                "a smaller --light-entries (GpuParams::light_entries)",
            ),
        ];
        for (what, bytes, fix) in sizes {
            if bytes > max_binding {
                return Err(RenderError::Param(format!(
                    "the {what} need {bytes} bytes, more than the adapter's storage binding limit \
                     {max_binding}: use {fix}"
                )));
            }
        }
        if capacity == 0 {
            return Err(RenderError::Param(
                "the light-entry pool (--light-entries) must hold at least 1 entry".into(),
            ));
        }
        let vpl_groups = (vpls.len() as u32).div_ceil(64);
        if vpl_groups > limits.max_compute_workgroups_per_dimension {
            return Err(RenderError::Param(format!(
                "{} VPLs need {vpl_groups} workgroups, more than the adapter's {}",
                vpls.len(),
                limits.max_compute_workgroups_per_dimension
            )));
        }
        let frame = ClusterFrame {
            eye: view.eye.extend(0.0).to_array(),
            forward: view.forward.extend(0.0).to_array(),
            size: [w, h, cp.tile_px, cp.depth_slices],
            counts: [tiles[0], tiles[1], vpls.len() as u32, capacity],
        };
        let frame_buf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("cluster frame"),
            contents: bytemuck::bytes_of(&frame),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let zeroed = |label: &str, bytes: u64, usage| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage,
                mapped_at_creation: false,
            })
        };
        let pixel_depth = zeroed("pixel depth", pixels * 4, rw);
        let depth_range = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("depth range"),
            contents: bytemuck::cast_slice(&[u32::MAX, 0u32]),
            usage: rw,
        });
        let tile_buf = zeroed("tile clusters", (n_tiles + 1) * 4, rw);
        let pixel_cluster = zeroed("pixel cluster", pixels * 4, rw);
        let clusters = zeroed("geometry clusters", pixels * 64, rw);
        let counter = zeroed("light list counter", 16, rw);
        let vpl_cluster = zeroed("vpl cluster", vpls.len() as u64 * 4, rw);
        let entries = zeroed("light entries", capacity as u64 * 8, rw);
        let dispatch = zeroed(
            "assignment dispatch",
            12,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
        );
        fn res(b: &wgpu::Buffer) -> wgpu::BindingResource<'_> {
            b.as_entire_binding()
        }
        let p = &self.cluster_pipelines;
        let tex = wgpu::BindingResource::TextureView(g_position);
        let depths_bg = bind_group(
            d,
            &p.depths,
            vec![
                (0, res(&frame_buf)),
                (1, tex.clone()),
                (2, res(&pixel_depth)),
                (3, res(&depth_range)),
            ],
        );
        let count_bg = bind_group(
            d,
            &p.tile_count,
            vec![
                (0, res(&frame_buf)),
                (1, tex.clone()),
                (2, res(&pixel_depth)),
                (3, res(&depth_range)),
                (4, res(&tile_buf)),
            ],
        );
        let scan_bg = bind_group(
            d,
            &p.scan_tiles,
            vec![
                (0, res(&frame_buf)),
                (4, res(&tile_buf)),
                (7, res(&counter)),
                (15, res(&dispatch)),
            ],
        );
        let clusters_bg = bind_group(
            d,
            &p.tile_clusters,
            vec![
                (0, res(&frame_buf)),
                (1, tex),
                (2, res(&pixel_depth)),
                (3, res(&depth_range)),
                (4, res(&tile_buf)),
                (5, res(&pixel_cluster)),
                (6, res(&clusters)),
            ],
        );
        let vpl_bg = bind_group(
            d,
            &p.vpl_clusters,
            vec![
                (0, res(&frame_buf)),
                (8, res(grid_buf)),
                (9, res(&level.voxel_words)),
                (12, res(vpl_buf)),
                (13, res(&vpl_cluster)),
            ],
        );
        let assign_bg = bind_group(
            d,
            &p.assign,
            vec![
                (0, res(&frame_buf)),
                (6, res(&clusters)),
                (7, res(&counter)),
                (8, res(grid_buf)),
                (10, res(&level.gates)),
                (11, res(&level.cluster_gates)),
                (12, res(vpl_buf)),
                (13, res(&vpl_cluster)),
                (14, res(&entries)),
            ],
        );

        // Unique clusters.
        let t0 = std::time::Instant::now();
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("unique clusters"),
        });
        {
            let span = timer.span(Stage::UniqueClusters);
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("unique clusters"),
                timestamp_writes: timer.compute_writes(span),
            });
            pass.set_pipeline(&p.depths);
            pass.set_bind_group(0, &depths_bg, &[]);
            pass.dispatch_workgroups(w.div_ceil(16), h.div_ceil(16), 1);
            pass.set_pipeline(&p.tile_count);
            pass.set_bind_group(0, &count_bg, &[]);
            pass.dispatch_workgroups(tiles[0], tiles[1], 1);
            pass.set_pipeline(&p.scan_tiles);
            pass.set_bind_group(0, &scan_bg, &[]);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&p.tile_clusters);
            pass.set_bind_group(0, &clusters_bg, &[]);
            pass.dispatch_workgroups(tiles[0], tiles[1], 1);
        }
        ctx.queue.submit([enc.finish()]);
        ctx.wait();
        times.unique_clusters = t0.elapsed().as_secs_f64();

        // Light assignment.
        let t0 = std::time::Instant::now();
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("light assignment"),
        });
        {
            let span = timer.span(Stage::LightAssignment);
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("light assignment"),
                timestamp_writes: timer.compute_writes(span),
            });
            if vpl_groups > 0 {
                pass.set_pipeline(&p.vpl_clusters);
                pass.set_bind_group(0, &vpl_bg, &[]);
                pass.dispatch_workgroups(vpl_groups, 1, 1);
            }
            pass.set_pipeline(&p.assign);
            pass.set_bind_group(0, &assign_bg, &[]);
            pass.dispatch_workgroups_indirect(&dispatch, 0);
        }
        ctx.queue.submit([enc.finish()]);
        ctx.wait();
        times.light_assignment = t0.elapsed().as_secs_f64();
        Ok(Buffers {
            pixel_depth,
            pixel_cluster,
            clusters,
            counter,
            entries,
            capacity,
        })
    }

    /// How full the lists of `b` came out; an error naming the setting to raise when some did
    /// not fit (their light is never cut silently).
    pub(super) fn list_stats(
        &self,
        ctx: &GpuContext,
        b: &Buffers,
    ) -> Result<LightListStats, RenderError> {
        let c: Vec<u32> = bytemuck::cast_slice(&super::read_buffer(ctx, &b.counter)?).to_vec();
        let stats = LightListStats {
            geometry_clusters: c[2],
            entries: c[0] as u64,
            capacity: b.capacity,
        };
        if c[1] > 0 {
            return Err(RenderError::Param(format!(
                "the light lists of {} geometry clusters need {} entries, more than the pool's {} \
                 ({} lists did not fit): raise --light-entries (GpuParams::light_entries) to at \
                 least {}, or use fewer VPLs",
                stats.geometry_clusters, stats.entries, b.capacity, c[1], stats.entries
            )));
        }
        Ok(stats)
    }

    /// Runs the G-buffer, unique-clusters and light-assignment passes of mode
    /// [`super::GpuMode::Gates`] for `view` and reads back what they built, as the CPU twin
    /// [`crate::clustered::assign`] gives it: each pixel's surface (the G-buffer's position,
    /// normal, visibility cluster, and the GPU's view depth), the geometry clusters with their
    /// boxes, and each cluster's light list. For tests and inspection; slow (reads all back).
    pub fn light_lists(
        &self,
        ctx: &GpuContext,
        view: &View,
        vpls: &[Vpl],
        params: &GpuParams,
    ) -> Result<(Vec<Option<PixelSurface>>, Clustered), RenderError> {
        let mut p = *params;
        p.mode = super::GpuMode::Gates;
        let mut times = PassTimes::default();
        let mut timer = Timer::new(ctx, 0);
        let frame = self.frame_inputs(ctx, view, vpls, &p)?;
        let (targets, views) = self.geometry_pass(ctx, view, &frame, &mut timer, &mut times);
        let b = self.cluster_passes(
            ctx,
            view,
            vpls,
            &frame.vpls,
            &frame.grid,
            &views[0],
            &p,
            &mut timer,
            &mut times,
        )?;
        let stats = self.list_stats(ctx, &b)?;
        let pos = super::read_texture(ctx, &targets[0])?;
        let nrm = super::read_texture(ctx, &targets[1])?;
        let depth: Vec<f32> =
            bytemuck::cast_slice(&super::read_buffer(ctx, &b.pixel_depth)?)[..pos.len()].to_vec();
        let pixels: Vec<Option<PixelSurface>> = pos
            .iter()
            .zip(&nrm)
            .zip(&depth)
            .map(|((p, n), &d)| {
                (p[3] != 0.0).then(|| PixelSurface {
                    position: Vec3::new(p[0], p[1], p[2]),
                    normal: Vec3::new(n[0], n[1], n[2]),
                    depth: d,
                    cluster: ((p[3] - 1.0) as u32).checked_sub(1),
                })
            })
            .collect();
        let pixel_cluster: Vec<u32> =
            bytemuck::cast_slice(&super::read_buffer(ctx, &b.pixel_cluster)?)[..pos.len()].to_vec();
        let n = stats.geometry_clusters as usize;
        let records: Vec<GpuGeometryCluster> =
            bytemuck::cast_slice(&super::read_buffer(ctx, &b.clusters)?)[..n].to_vec();
        let pool: Vec<[u32; 2]> = bytemuck::cast_slice(&super::read_buffer(ctx, &b.entries)?)
            [..stats.entries as usize]
            .to_vec();
        let clusters = records
            .iter()
            .map(|r| GeometryCluster {
                tile: [r.key[0], r.key[1], r.key[2]],
                cluster: (r.key[3] != u32::MAX).then_some(r.key[3]),
                bounds: [Vec3::from_slice(&r.lo[..3]), Vec3::from_slice(&r.hi[..3])],
            })
            .collect();
        let lists = records
            .iter()
            .map(|r| {
                pool[r.list[0] as usize..(r.list[0] + r.list[1]) as usize]
                    .iter()
                    .map(|&[vpl, g]| LightEntry {
                        vpl,
                        gates: [g & 0xffff, g >> 16]
                            .into_iter()
                            .filter(|&x| x != 0)
                            .map(|x| x - 1)
                            .collect(),
                    })
                    .collect()
            })
            .collect();
        Ok((
            pixels,
            Clustered {
                pixel_cluster,
                clusters,
                lists,
            },
        ))
    }
}
