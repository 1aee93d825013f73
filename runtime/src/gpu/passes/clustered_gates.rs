//! Clustered shading with gates (clusters.wgsl; section V of the visibility-gates paper): between
//! the G-buffer (which holds each pixel's visibility cluster) and the shading pass, the *unique
//! clusters* pass finds the geometry clusters in view (screen tiles × exponential depth slices ×
//! visibility cluster) with their boxes, and the *light assignment* pass gives each one its
//! list of (VPL, gate chain) entries in one pool. [`crate::cpu::clustered`] is the CPU twin;
//! the tests hold the two equal ([`crate::gpu::GpuRenderer::light_lists`]).

use crate::RenderError;
use glam::Vec3;

pub use super::gates_params::{AUTO_LIGHT_ENTRIES, GatesParams, check_gates};
use super::gbuffer::GBufferOutput;
pub use super::roulette::{
    AUTO_ROULETTE_BLOCK, AUTO_ROULETTE_RATIO_VPLS, AUTO_ROULETTE_SHARE, AUTO_ROULETTE_VPLS,
    WalkRoulette,
};
use crate::cpu::clustered::{
    Clustered, GeometryCluster as CpuGeometryCluster, LightEntry, PixelSurface,
};
use crate::cpu::gates::{GateLevel, GateShape};
use crate::cpu::sight_triangles::{SightExtra, sight_too_large};
use crate::gpu::context::{
    Pool, bind_group, compute_pipelines, init_buffer, read_buffer, read_texture,
};
use crate::gpu::layout::{ClusterFrame, GeometryCluster};
use crate::gpu::shaders::ShaderSources;
use crate::gpu::shaders::{self, CLUSTER_BITS, WG_LINEAR, WG_TILE};
use crate::gpu::timing::{LightListStats, Recorder};
use crate::gpu::{Frame, GpuContext};

/// Entry encoding: the chain's gates as (g0 + 1) | (g1 + 1) << 16, so at most this many gates.
pub const MAX_GATES: usize = 0xfffe;
/// Keys hold a visibility cluster in [`CLUSTER_BITS`] bits, the all-ones value meaning "none".
pub const MAX_CLUSTERS: usize = (1 << CLUSTER_BITS) - 2;

/// A level's gate tables on the GPU.
pub struct LevelBuffers {
    /// Grid origin (xyz, m) and voxel size (w, m).
    pub origin: [f32; 4],
    /// Grid dims (xyz) and bytes per value (w).
    pub dims: [u32; 4],
    /// The voxel→cluster grid in words.
    pub voxel_words: wgpu::Buffer,
    /// The gate disks.
    pub gates: wgpu::Buffer,
    /// Each cluster's gates: offsets, then indices.
    pub cluster_gates: wgpu::Buffer,
    /// The portals, packed (`GateLevel::portal_words`).
    pub portal_words: wgpu::Buffer,
    /// The open voxels, packed (`VoxelSight::words`' base).
    pub sight_words: wgpu::Buffer,
    /// The closed voxels' triangle lists and planes (`VoxelSight::words`' extra).
    pub sight_extra: wgpu::Buffer,
    /// The most steps a voxel walk takes (`VoxelSight::most_steps`).
    pub sight_steps: u32,
    /// The sight grid's voxel edge. [Units: m]
    pub sight_voxel_m: f32,
    /// Whether `sight_extra` holds the closed voxels' triangle lists.
    pub triangles: bool,
    /// Whether `sight_extra` holds the closed voxels' planes.
    pub planes: bool,
}

impl LevelBuffers {
    /// The frame's level, which mode gates needs.
    pub fn of<'a>(f: &Frame<'a>) -> Result<&'a LevelBuffers, RenderError> {
        f.scene.level.as_ref().ok_or_else(|| {
            RenderError::Param("mode gates needs a baked level (GpuRenderer::set_level)".into())
        })
    }

    /// Uploads `level`'s tables, with the closed voxels' triangle lists where `lists` asks for
    /// them and they are listed, and their planes where `planes` asks for them and they are
    /// fitted; the voxel grid keeps the smallest integer type that holds the level's clusters.
    pub fn upload(
        ctx: &GpuContext,
        level: &GateLevel,
        lists: bool,
        planes: bool,
    ) -> Result<LevelBuffers, RenderError> {
        let lists = lists && level.sight().triangles_listed();
        let planes = planes && level.sight().planes_fitted();
        let t = level.tables(lists, planes);
        let d = &ctx.device;
        if t.gates.len() > MAX_GATES || level.cluster_count() > MAX_CLUSTERS {
            return Err(RenderError::Param(format!(
                "the level has {} gates and {} clusters; the GPU's light lists hold at most {} \
                 gates and {} clusters: bake at a lower resolution",
                t.gates.len(),
                level.cluster_count(),
                MAX_GATES,
                MAX_CLUSTERS
            )));
        }
        let limit = d.limits().max_storage_buffer_binding_size;
        let bytes = |words: &[u32]| (words.len() * 4) as u64;
        if bytes(&t.voxel_words) > limit {
            return Err(RenderError::Param(format!(
                "the voxel→cluster grid needs {} bytes, more than the adapter's storage binding \
                 limit {limit}: bake at a lower resolution",
                bytes(&t.voxel_words)
            )));
        }
        let extra = match (lists, planes) {
            (true, _) => Some(SightExtra::Lists),
            (false, true) => Some(SightExtra::Planes),
            (false, false) => None,
        };
        let sight = &t.sight_words;
        let extra_bytes = extra.map(|x| (x, bytes(&sight.extra)));
        if let Some(why) = sight_too_large(
            bytes(&sight.base),
            extra_bytes,
            level.sight().voxel_m(),
            limit,
        ) {
            return Err(RenderError::Param(why));
        }
        let storage = wgpu::BufferUsages::STORAGE;
        Ok(LevelBuffers {
            origin: t.origin,
            dims: t.dims,
            voxel_words: init_buffer(
                d,
                "voxel clusters",
                bytemuck::cast_slice(&t.voxel_words),
                storage,
            ),
            gates: init_buffer(d, "gates", bytemuck::cast_slice(&t.gates), storage),
            cluster_gates: init_buffer(
                d,
                "cluster gates",
                bytemuck::cast_slice(&t.cluster_gates),
                storage,
            ),
            portal_words: init_buffer(d, "portals", bytemuck::cast_slice(&t.portal_words), storage),
            sight_words: init_buffer(
                d,
                "open voxels",
                bytemuck::cast_slice(&t.sight_words.base),
                storage,
            ),
            sight_extra: init_buffer(
                d,
                "closed voxels' triangles and planes",
                bytemuck::cast_slice(&t.sight_words.extra),
                storage,
            ),
            sight_steps: t.sight_steps,
            sight_voxel_m: level.sight().voxel_m(),
            triangles: lists,
            planes,
        })
    }
}

/// The compute pipelines of clusters.wgsl.
pub struct ClusteredGates {
    depths: wgpu::ComputePipeline,
    tile_count: wgpu::ComputePipeline,
    scan_tiles: wgpu::ComputePipeline,
    tile_clusters: wgpu::ComputePipeline,
    vpl_clusters: wgpu::ComputePipeline,
    assign: wgpu::ComputePipeline,
}

/// The buffers the clustered passes fill; the shading pass reads `pixel_cluster`, `clusters`
/// and `entries`.
pub struct ListBuffers {
    /// View depth per pixel.
    pub pixel_depth: wgpu::Buffer,
    /// Geometry cluster per pixel.
    pub pixel_cluster: wgpu::Buffer,
    /// The geometry clusters and their lists.
    pub clusters: wgpu::Buffer,
    /// Entries used (or needed), lists that did not fit, geometry clusters.
    pub counter: wgpu::Buffer,
    /// The pool of entries.
    pub entries: wgpu::Buffer,
    /// The pool's capacity.
    pub capacity: u32,
    /// Each VPL's visibility cluster (`u32::MAX`: none).
    pub vpl_cluster: wgpu::Buffer,
}

impl ListBuffers {
    /// How full the lists came out from the counter's words; an error naming the setting to
    /// raise when some did not fit (their light is never cut silently).
    pub fn stats(&self, c: &[u32]) -> Result<LightListStats, RenderError> {
        let stats = LightListStats {
            geometry_clusters: c[2],
            entries: c[0] as u64,
            capacity: self.capacity,
            pixels_outside: c[3],
            vpls_outside: c[4],
        };
        if c[1] > 0 {
            return Err(RenderError::LightListsFull {
                needed: stats.entries,
                capacity: self.capacity,
                lists: c[1],
                clusters: stats.geometry_clusters,
            });
        }
        Ok(stats)
    }
}

impl ClusteredGates {
    /// Builds the pipelines.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<ClusteredGates, RenderError> {
        let module = shaders::module(d, s, "clusters.wgsl")?;
        let [
            depths,
            tile_count,
            scan_tiles,
            tile_clusters,
            vpl_clusters,
            assign,
        ] = compute_pipelines(
            d,
            &module,
            [
                "depths",
                "tile_count",
                "scan_tiles",
                "tile_clusters",
                "vpl_clusters",
                "assign",
            ],
        );
        Ok(ClusteredGates {
            depths,
            tile_count,
            scan_tiles,
            tile_clusters,
            vpl_clusters,
            assign,
        })
    }

    /// The frame's list buffers (kept in `pool`), after checking their sizes.
    fn buffers(f: &Frame, p: &GatesParams, pool: &mut Pool) -> Result<ListBuffers, RenderError> {
        let d = &f.ctx.device;
        let [w, h] = f.view.size;
        let pixels = w as u64 * h as u64;
        let limits = d.limits();
        let max_binding = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        // Walks keep no lists: a pixel walks every VPL of its subset (clusters.wgsl).
        let capacity = match p.gates.shape {
            GateShape::Portal | GateShape::Voxels => 1,
            GateShape::Disk => p.light_entries.unwrap_or(AUTO_LIGHT_ENTRIES),
        };
        let sizes = [
            ("geometry clusters", pixels * 64, "a smaller image"),
            (
                "light entries",
                capacity as u64 * 8,
                "a smaller --light-entries (GatesParams::light_entries)",
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
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        Ok(ListBuffers {
            pixel_depth: pool.buffer(d, "pixel depth", pixels * 4, rw),
            pixel_cluster: pool.buffer(d, "pixel cluster", pixels * 4, rw),
            clusters: pool.buffer(d, "geometry clusters", pixels * 64, rw),
            counter: pool.buffer(
                d,
                "light list counter",
                16,
                rw | wgpu::BufferUsages::COPY_DST,
            ),
            entries: pool.buffer(d, "light entries", capacity as u64 * 8, rw),
            capacity,
            vpl_cluster: pool.buffer(d, "vpl cluster", f.vpl_count as u64 * 4, rw),
        })
    }

    /// Records the unique-clusters and light-assignment passes over the G-buffer positions
    /// `g_position` (w = visibility cluster).
    pub fn record(
        &self,
        f: &Frame,
        p: &GatesParams,
        pool: &mut Pool,
        rec: &mut Recorder,
        g_position: &wgpu::TextureView,
    ) -> Result<ListBuffers, RenderError> {
        let d = &f.ctx.device;
        let level = LevelBuffers::of(f)?;
        let cp = p.clusters;
        let [w, h] = f.view.size;
        let tiles = [w.div_ceil(cp.tile_px), h.div_ceil(cp.tile_px)];
        let vpl_groups = f.vpl_count.div_ceil(WG_LINEAR);
        let max = d.limits().max_compute_workgroups_per_dimension;
        if vpl_groups > max {
            return Err(RenderError::Param(format!(
                "{} VPLs need {vpl_groups} workgroups, more than the adapter's {max}",
                f.vpl_count
            )));
        }
        let b = Self::buffers(f, p, pool)?;
        let s = Scratch::new(f, p, &b, tiles, pool);
        rec.enc.clear_buffer(&b.counter, 0, None);
        let [depths_bg, count_bg, scan_bg, clusters_bg, vpl_bg, assign_bg] =
            self.bind_groups(f, level, &b, &s, g_position);
        let span = rec.begin("unique clusters");
        {
            let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("unique clusters"),
                timestamp_writes: span.compute(),
            });
            pass.set_pipeline(&self.depths);
            pass.set_bind_group(0, &depths_bg, &[]);
            pass.dispatch_workgroups(w.div_ceil(WG_TILE), h.div_ceil(WG_TILE), 1);
            pass.set_pipeline(&self.tile_count);
            pass.set_bind_group(0, &count_bg, &[]);
            pass.dispatch_workgroups(tiles[0], tiles[1], 1);
            pass.set_pipeline(&self.scan_tiles);
            pass.set_bind_group(0, &scan_bg, &[]);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&self.tile_clusters);
            pass.set_bind_group(0, &clusters_bg, &[]);
            pass.dispatch_workgroups(tiles[0], tiles[1], 1);
        }
        rec.end();
        let span = rec.begin("light assignment");
        {
            let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("light assignment"),
                timestamp_writes: span.compute(),
            });
            if vpl_groups > 0 {
                pass.set_pipeline(&self.vpl_clusters);
                pass.set_bind_group(0, &vpl_bg, &[]);
                pass.dispatch_workgroups(vpl_groups, 1, 1);
            }
            // Portals keep no lists (the shading pass walks each pixel's VPL subset).
            if p.gates.shape == GateShape::Disk {
                pass.set_pipeline(&self.assign);
                pass.set_bind_group(0, &assign_bg, &[]);
                pass.dispatch_workgroups_indirect(&s.dispatch, 0);
            }
        }
        rec.end();
        Ok(b)
    }
}

/// The clustered passes' own buffers of a frame.
struct Scratch {
    frame: wgpu::Buffer,
    depth_range: wgpu::Buffer,
    tile_buf: wgpu::Buffer,
    dispatch: wgpu::Buffer,
}

impl Scratch {
    fn new(
        f: &Frame,
        p: &GatesParams,
        b: &ListBuffers,
        tiles: [u32; 2],
        pool: &mut Pool,
    ) -> Scratch {
        let d = &f.ctx.device;
        let cp = p.clusters;
        let [w, h] = f.view.size;
        let frame = ClusterFrame {
            eye: f.view.eye.to_array(),
            subsets: p.interleave.subsets(),
            forward: f.view.forward.to_array(),
            width: w,
            height: h,
            tile_px: cp.tile_px,
            depth_slices: cp.depth_slices,
            tiles_x: tiles[0],
            tiles_y: tiles[1],
            vpl_count: f.vpl_count,
            capacity: b.capacity,
            ..bytemuck::Zeroable::zeroed()
        };
        let uniform = wgpu::BufferUsages::UNIFORM;
        let frame_buf = pool.upload(f.ctx, "cluster frame", bytemuck::bytes_of(&frame), uniform);
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let range: [u32; 2] = [u32::MAX, 0];
        let depth_range = pool.upload(f.ctx, "depth range", bytemuck::cast_slice(&range), rw);
        let n_tiles = tiles[0] as u64 * tiles[1] as u64;
        let tile_buf = pool.buffer(d, "tile clusters", (n_tiles + 1) * 4, rw);
        let dispatch = pool.buffer(
            d,
            "assignment dispatch",
            12,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
        );
        Scratch {
            frame: frame_buf,
            depth_range,
            tile_buf,
            dispatch,
        }
    }
}

impl ClusteredGates {
    /// The bind groups of depths, tile_count, scan_tiles, tile_clusters, vpl_clusters, assign.
    fn bind_groups(
        &self,
        f: &Frame,
        level: &LevelBuffers,
        b: &ListBuffers,
        s: &Scratch,
        g_position: &wgpu::TextureView,
    ) -> [wgpu::BindGroup; 6] {
        let d = &f.ctx.device;
        fn res(b: &wgpu::Buffer) -> wgpu::BindingResource<'_> {
            b.as_entire_binding()
        }
        let tex = || wgpu::BindingResource::TextureView(g_position);
        let bind = |pl: &wgpu::ComputePipeline, r: Vec<(u32, wgpu::BindingResource)>| {
            bind_group(d, &pl.get_bind_group_layout(0), "clusters", r)
        };
        let frame0 = || (0, res(&s.frame));
        let depths_bg = bind(
            &self.depths,
            vec![
                frame0(),
                (1, tex()),
                (2, res(&b.pixel_depth)),
                (3, res(&s.depth_range)),
                (7, res(&b.counter)),
            ],
        );
        let count_bg = bind(
            &self.tile_count,
            vec![
                frame0(),
                (1, tex()),
                (2, res(&b.pixel_depth)),
                (3, res(&s.depth_range)),
                (4, res(&s.tile_buf)),
            ],
        );
        let scan_bg = bind(
            &self.scan_tiles,
            vec![
                frame0(),
                (4, res(&s.tile_buf)),
                (7, res(&b.counter)),
                (15, res(&s.dispatch)),
            ],
        );
        let clusters_bg = bind(
            &self.tile_clusters,
            vec![
                frame0(),
                (1, tex()),
                (2, res(&b.pixel_depth)),
                (3, res(&s.depth_range)),
                (4, res(&s.tile_buf)),
                (5, res(&b.pixel_cluster)),
                (6, res(&b.clusters)),
            ],
        );
        let vpl_bg = bind(
            &self.vpl_clusters,
            vec![
                frame0(),
                (7, res(&b.counter)),
                (8, res(&f.grid)),
                (9, res(&level.voxel_words)),
                (12, res(&f.vpls)),
                (13, res(&b.vpl_cluster)),
            ],
        );
        let assign_bg = bind(
            &self.assign,
            vec![
                frame0(),
                (6, res(&b.clusters)),
                (7, res(&b.counter)),
                (8, res(&f.grid)),
                (10, res(&level.gates)),
                (11, res(&level.cluster_gates)),
                (12, res(&f.vpls)),
                (13, res(&b.vpl_cluster)),
                (14, res(&b.entries)),
            ],
        );
        [depths_bg, count_bg, scan_bg, clusters_bg, vpl_bg, assign_bg]
    }
}

impl ListBuffers {
    /// Reads back a frame's G-buffer surfaces and these lists, as the CPU twin gives them (for
    /// [`crate::gpu::GpuRenderer::light_lists`]; waits for the GPU).
    pub fn read_back(
        &self,
        ctx: &GpuContext,
        g: &GBufferOutput,
    ) -> Result<(Vec<Option<PixelSurface>>, Clustered), RenderError> {
        let b = self;
        let c: Vec<u32> = bytemuck::cast_slice(&read_buffer(ctx, &b.counter)?).to_vec();
        let stats = b.stats(&c)?;
        let pos = read_texture(ctx, &g.textures[0])?;
        let nrm = read_texture(ctx, &g.textures[1])?;
        let depth: Vec<f32> =
            bytemuck::cast_slice(&read_buffer(ctx, &b.pixel_depth)?)[..pos.len()].to_vec();
        let pixels = pos
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
            bytemuck::cast_slice(&read_buffer(ctx, &b.pixel_cluster)?)[..pos.len()].to_vec();
        let n = stats.geometry_clusters as usize;
        let records: Vec<GeometryCluster> =
            bytemuck::cast_slice(&read_buffer(ctx, &b.clusters)?)[..n].to_vec();
        let pool: Vec<[u32; 2]> =
            bytemuck::cast_slice(&read_buffer(ctx, &b.entries)?)[..stats.entries as usize].to_vec();
        let clusters = records
            .iter()
            .map(|r| CpuGeometryCluster {
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
                        walk_from: None,
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
