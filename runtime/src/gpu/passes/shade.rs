//! Deferred shading (shade.wgsl): direct light from every light with its shadow maps (PCF), plus
//! what the mode's [`ShadeIndirect`] says of the VPLs (all of them unoccluded, through the
//! gates per pixel or by the clustered light lists, or none), into the frame's HDR target.

use super::clustered_gates::ListBuffers;
use super::gbuffer::GBufferOutput;
use super::light_cluster::LcOutput;
use super::shadow_maps::ShadowOutput;
use crate::RenderError;
use crate::cpu::gates::GateShape;
use crate::gpu::context::{
    Pool, array_view, bind_group, compute_pipeline_with, compute_pipelines, slice,
};
use crate::gpu::layout::{UNIFORM_STRIDE, strided};
use crate::gpu::shaders::ShaderSources;
use crate::gpu::timing::Recorder;
use crate::gpu::{Frame, shaders};

/// The HDR target's format.
pub const HDR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// The shading pipelines: direct + the mode's indirect, and interleaved gates' indirect alone.
pub struct Shade {
    pipeline: wgpu::ComputePipeline,
    /// The interleaved gates' indirect pass (compute), a pipeline per gate shape (shade.wgsl's
    /// `GATE_SHAPE`, by [`crate::cpu::gates::GateShape::shader_id`]; the voxel walk's without
    /// the closed voxels' planes) and one each for the voxel walk with their triangles
    /// (`SIGHT_TRIANGLES`) and with their planes (`SIGHT_PLANES`), each made when first used.
    gates_indirect: [std::sync::OnceLock<wgpu::ComputePipeline>; 5],
    /// The starved pixels' walks (`cs_starved_walks`), likewise.
    gates_starved: [std::sync::OnceLock<wgpu::ComputePipeline>; 5],
    /// The near field's walks (`cs_near_field`), marks (`cs_near_marks`) and sums composed
    /// (`cs_near_compose`), likewise.
    gates_near: [std::sync::OnceLock<wgpu::ComputePipeline>; 5],
    near_marks: [std::sync::OnceLock<wgpu::ComputePipeline>; 5],
    near_compose: [std::sync::OnceLock<wgpu::ComputePipeline>; 5],
    /// The starved pixels' other passes (starved.rs).
    pub(super) starved: super::starved::StarvedPipelines,
    module: wgpu::ShaderModule,
    vpl_clusters_indirect: wgpu::ComputePipeline,
}

/// A compute pass of `pipeline` over the frame's pixels, 8 × 8 a workgroup (the `cs_*` entry
/// points of the passes that shade the frame: compute, not fullscreen draws, because the same
/// loop ran 30× slower as a fragment shader on an NVIDIA H200 — examples/fragment_vs_compute.rs
/// — and as fast on lavapipe), one dispatch per bind group of `groups`, in order.
pub fn frame_pass(
    enc: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    groups: &[&wgpu::BindGroup],
    timestamps: Option<wgpu::ComputePassTimestampWrites>,
    [w, h]: [u32; 2],
) {
    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(label),
        timestamp_writes: timestamps,
    });
    pass.set_pipeline(pipeline);
    for group in groups {
        pass.set_bind_group(0, *group, &[]);
        pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
    }
}

/// A full-frame RGBA32F image `label` of the frame's size (kept in `pool`), written by a
/// compute pass, read, copied and read back.
pub fn frame_target(f: &Frame, pool: &mut Pool, label: &'static str) -> wgpu::Texture {
    let [w, h] = f.view.size;
    pool.texture(
        &f.ctx.device,
        label,
        [w, h, 1],
        1,
        HDR,
        wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::TEXTURE_BINDING,
    )
}

/// The two targets of a gather in `dispatches` dispatches, each writing one and reading the
/// other as the sum so far (named `names`, kept in `pool`); with one dispatch a 1 × 1 texel
/// stands in for the second, which it binds but does not read.
pub(super) fn ping_pong_targets(
    f: &Frame,
    pool: &mut Pool,
    names: [&'static str; 2],
    dispatches: u32,
) -> [wgpu::Texture; 2] {
    let second = match dispatches {
        1 => pool.texture(
            &f.ctx.device,
            "no earlier dispatches",
            [1, 1, 1],
            1,
            HDR,
            wgpu::TextureUsages::TEXTURE_BINDING,
        ),
        _ => frame_target(f, pool, names[1]),
    };
    [frame_target(f, pool, names[0]), second]
}

/// What shading reads: the lights (and their maps), the G-buffer, mode gates' gather inputs,
/// LightCluster's visibility.
pub type Inputs<'a> = (
    &'a ShadowOutput,
    &'a GBufferOutput,
    Gathers<'a>,
    Option<&'a LcOutput>,
    Option<&'a LcOutput>,
);

/// What mode gates' gather reads beside the level: the light lists (disks; portals' VPL
/// clusters) or each VPL's end of the voxel walk (voxels).
#[derive(Clone, Copy, Default)]
pub struct Gathers<'a> {
    /// The clustered passes' lists.
    pub lists: Option<&'a ListBuffers>,
    /// [`super::sight_ends`]'s output.
    pub vpl_ends: Option<&'a wgpu::Buffer>,
}

/// The bindings of shade.wgsl's `cs_gates_indirect` (an automatic layout holds only what an
/// entry point uses) but its batch index (24) and its output (25).
const GATES_INDIRECT_BINDINGS: [u32; 16] =
    [0, 2, 5, 6, 7, 8, 10, 12, 13, 14, 15, 16, 21, 22, 23, 31];
/// The bindings of shade.wgsl's `cs_near_field` but its batch (24), marks (34) and sums (35):
/// `cs_gates_indirect`'s but the gate disks, the light lists and the batches' sum.
const NEAR_BINDINGS: [u32; 11] = [0, 2, 5, 6, 7, 8, 15, 16, 22, 23, 31];
/// The bindings of shade.wgsl's `cs_shade` but its output (25): all but the batches' sum, the
/// batch index, the VPLs' clusters and walk ends, the portals and the sight grid (portals and
/// voxels walk apart, in `cs_gates_indirect`; `cs_shade` gathers the disks, per pixel or by
/// the lists).
const SHADE_BINDINGS: [u32; 19] = [
    0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 17, 18, 19, 20,
];
/// The bindings of shade.wgsl's `cs_vpl_clusters_indirect` but its output (25).
const VPL_CLUSTERS_INDIRECT_BINDINGS: [u32; 6] = [0, 2, 5, 6, 19, 20];

impl Shade {
    /// Builds the pipelines.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<Shade, RenderError> {
        let module = shaders::module(d, s, "shade.wgsl")?;
        let [pipeline, vpl_clusters_indirect] =
            compute_pipelines(d, &module, ["cs_shade", "cs_vpl_clusters_indirect"]);
        Ok(Shade {
            pipeline,
            gates_indirect: Default::default(),
            gates_starved: Default::default(),
            gates_near: Default::default(),
            near_marks: Default::default(),
            near_compose: Default::default(),
            starved: super::starved::StarvedPipelines::new(d, s)?,
            module,
            vpl_clusters_indirect,
        })
    }

    /// Gather `gather`'s pipeline for gate shape `shape`, the voxel walk with the closed
    /// voxels' triangles where frame `f`'s mode asks for them, made when first asked for.
    pub(super) fn gates_pipeline(
        &self,
        f: &Frame,
        gather: GatesGather,
        shape: GateShape,
    ) -> &wgpu::ComputePipeline {
        let shape = shape.shader_id();
        let voxels = f
            .params
            .mode
            .gates()
            .filter(|_| shape == GateShape::Voxels.shader_id());
        let triangles = voxels.is_some_and(|g| g.triangles);
        let planes = voxels.is_some_and(|g| g.planes && !g.triangles);
        let k = match (triangles, planes) {
            (true, _) => 3,
            (false, true) => 4,
            (false, false) => shape as usize,
        };
        let (cache, entry) = match gather {
            GatesGather::Indirect => (&self.gates_indirect, "cs_gates_indirect"),
            GatesGather::Starved => (&self.gates_starved, "cs_starved_walks"),
            GatesGather::Near => (&self.gates_near, "cs_near_field"),
            GatesGather::NearMarks => (&self.near_marks, "cs_near_marks"),
            GatesGather::NearCompose => (&self.near_compose, "cs_near_compose"),
        };
        let d = &f.ctx.device;
        cache[k].get_or_init(|| {
            compute_pipeline_with(
                d,
                entry,
                &self.module,
                entry,
                &[
                    ("GATE_SHAPE", f64::from(shape)),
                    ("SIGHT_TRIANGLES", f64::from(u8::from(triangles))),
                    ("SIGHT_PLANES", f64::from(u8::from(planes))),
                ],
            )
        })
    }

    /// Records the shading pass; returns the frame's HDR image so far.
    pub fn record(
        &self,
        f: &Frame,
        pool: &mut Pool,
        rec: &mut Recorder,
        inputs: Inputs,
        name: &'static str,
    ) -> wgpu::Texture {
        let out = frame_target(f, pool, "hdr");
        let pipeline = (&self.pipeline, Some(&SHADE_BINDINGS[..]));
        self.draw(f, rec, inputs, pipeline, (&out, name));
        out
    }

    /// Records an interleaved mode's indirect irradiance (each pixel its subset's, × B) into a
    /// target of its own, for the blur to compose: clustered gates' with gate shape `gates`
    /// (portals also without interleaving, B = 1, and in batches of VPLs on a software
    /// rasterizer), or with `gates` `None` the VPL clusters'.
    pub fn record_indirect(
        &self,
        f: &Frame,
        pool: &mut Pool,
        rec: &mut Recorder,
        inputs: Inputs,
        gates: Option<GateShape>,
    ) -> wgpu::Texture {
        let name = "indirect lighting";
        let Some(shape) = gates else {
            let out = frame_target(f, pool, "indirect irradiance");
            let pipeline = (
                &self.vpl_clusters_indirect,
                Some(&VPL_CLUSTERS_INDIRECT_BINDINGS[..]),
            );
            self.draw(f, rec, inputs, pipeline, (&out, name));
            return out;
        };
        let walks = f.params.mode.walks_per_pixel(f.vpl_count);
        let batched = Batched {
            pipeline: self.gates_pipeline(f, GatesGather::Indirect, shape),
            batches: batch_count(f, walks),
            used: &GATES_INDIRECT_BINDINGS,
            names: ["indirect irradiance", "indirect irradiance (batches)"],
            span: "indirect lighting",
            extra: None,
        };
        self.walk_batches(f, pool, rec, inputs, batched)
    }

    /// Records the near field of interleaved walks with gate shape `shape`
    /// (`globals.near_scale` > 0): each tile's VPLs within its pixels' radius marked, each
    /// pixel's light from the VPLs within its radius walked there and summed (on a software
    /// rasterizer in rounds of `f.near_run` marked VPLs a tile: the first over every tile, the
    /// later ones indirect, over the tiles that the round before left unfinished), then added
    /// onto `hdr` (the image so far) into a target of its own, which it returns.
    pub fn record_near(
        &self,
        f: &Frame,
        pool: &mut Pool,
        rec: &mut Recorder,
        inputs: Inputs,
        (shape, hdr): (GateShape, &wgpu::Texture),
    ) -> wgpu::Texture {
        let n = f.vpl_count;
        let [w, h] = f.view.size;
        let tiles = [w.div_ceil(8), h.div_ceil(8)];
        let d = &f.ctx.device;
        let storage = wgpu::BufferUsages::STORAGE;
        let marks_bytes = near_marks_bytes(f.view.size, n);
        let marks = pool.buffer(d, "near VPLs' marks", marks_bytes, storage);
        let sums_bytes = u64::from(w) * u64::from(h) * 16;
        let sums = pool.buffer(
            d,
            "near VPLs' light",
            sums_bytes,
            storage | wgpu::BufferUsages::COPY_DST,
        );
        rec.enc.clear_buffer(&sums, 0, None);
        let (run, rounds) = match f.near_run {
            0 => (u32::MAX, 1),
            r => (r, n.div_ceil(r).max(1)),
        };
        let lists = near_lists(f, pool, rec, tiles[0] * tiles[1]);
        let index_buf = pool.upload(
            f.ctx,
            "near round indices",
            &strided(&[[0, run, 0, 0], [1, run, 0, 0]]),
            wgpu::BufferUsages::UNIFORM,
        );
        let views = Views::new(f, inputs);
        let before = hdr.create_view(&Default::default());
        let out = frame_target(f, pool, "hdr (near VPLs)");
        let target = out.create_view(&Default::default());
        let group = |gather, used: &[u32], extra: Vec<(u32, wgpu::BindingResource)>| {
            let pipeline = self.gates_pipeline(f, gather, shape);
            let earlier = used.contains(&21).then_some(&before);
            let mut resources = views.resources(f, inputs, earlier, Some(used));
            resources.extend(extra);
            let layout = pipeline.get_bind_group_layout(0);
            (pipeline, bind_group(d, &layout, "near VPLs", resources))
        };
        let marks_at = (34, marks.as_entire_binding());
        let sums_at = || (35, sums.as_entire_binding());
        let (mark, marking) = group(GatesGather::NearMarks, &[0, 2, 5], vec![marks_at.clone()]);
        // The first round's group, then a later round r's (r mod 3): its list, the next, the
        // one after.
        let walking: Vec<wgpu::BindGroup> = [(0, 0), (1, 0), (1, 1), (1, 2)]
            .into_iter()
            .map(|(later, r)| {
                let index = (24, slice(&index_buf, later * UNIFORM_STRIDE as u64, 16));
                let mut extra = vec![index, marks_at.clone(), sums_at()];
                for (k, binding) in [36, 37, 38].into_iter().enumerate() {
                    extra.push((binding, lists[(r + k) % 3].as_entire_binding()));
                }
                group(GatesGather::Near, &NEAR_BINDINGS, extra).1
            })
            .collect();
        let walk = self.gates_pipeline(f, GatesGather::Near, shape);
        let out_at = (25, wgpu::BindingResource::TextureView(&target));
        let (compose, composing) = group(
            GatesGather::NearCompose,
            &[5, 7, 21],
            vec![out_at, sums_at()],
        );
        let name = "indirect lighting: near VPLs";
        let span = rec.begin(name);
        {
            let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(name),
                timestamp_writes: span.compute(),
            });
            pass.set_pipeline(mark);
            pass.set_bind_group(0, &marking, &[]);
            pass.dispatch_workgroups(tiles[0], tiles[1], 1);
            pass.set_pipeline(walk);
            pass.set_bind_group(0, &walking[0], &[]);
            pass.dispatch_workgroups(tiles[0], tiles[1], 1);
            for r in 1..rounds as usize {
                pass.set_bind_group(0, &walking[1 + r % 3], &[]);
                pass.dispatch_workgroups_indirect(&lists[r % 3], 0);
            }
            pass.set_pipeline(compose);
            pass.set_bind_group(0, &composing, &[]);
            pass.dispatch_workgroups(tiles[0], tiles[1], 1);
        }
        rec.end();
        out
    }

    /// A pass of shade.wgsl with `pipeline` (and the bindings it uses but its output, all if
    /// `None`) into `out`, timed as `name`.
    fn draw(
        &self,
        f: &Frame,
        rec: &mut Recorder,
        inputs: Inputs,
        (pipeline, used): (&wgpu::ComputePipeline, Option<&[u32]>),
        (out, name): (&wgpu::Texture, &'static str),
    ) {
        let views = Views::new(f, inputs);
        let target = out.create_view(&Default::default());
        let mut resources = views.resources(f, inputs, None, used);
        resources.push((25, wgpu::BindingResource::TextureView(&target)));
        let layout = pipeline.get_bind_group_layout(0);
        let group = bind_group(&f.ctx.device, &layout, name, resources);
        let span = rec.begin(name);
        frame_pass(
            &mut rec.enc,
            name,
            pipeline,
            &[&group],
            span.compute(),
            f.view.size,
        );
        rec.end();
    }

    /// A gates gather in batches: `b.batches` dispatches of `b.pipeline` in one compute pass,
    /// timed as one span; dispatch `i` walks batch `i`, writes target `i % 2` and reads the
    /// other as the batches' sum so far (one batch: a texel stands in for it). Returns the last
    /// target.
    fn walk_batches(
        &self,
        f: &Frame,
        pool: &mut Pool,
        rec: &mut Recorder,
        inputs: Inputs,
        b: Batched,
    ) -> wgpu::Texture {
        let Batched {
            pipeline,
            batches,
            used,
            names,
            span,
            extra,
        } = b;
        let d = &f.ctx.device;
        let targets = ping_pong_targets(f, pool, names, batches);
        let targets_view = targets
            .each_ref()
            .map(|t| t.create_view(&Default::default()));
        let indices: Vec<[u32; 4]> = (0..batches).map(|i| [i, 0, 0, 0]).collect();
        let index_buf = pool.upload(
            f.ctx,
            "walk batch indices",
            &strided(&indices),
            wgpu::BufferUsages::UNIFORM,
        );
        let views = Views::new(f, inputs);
        let layout = pipeline.get_bind_group_layout(0);
        let groups: Vec<wgpu::BindGroup> = (0..batches as usize)
            .map(|i| {
                let (out, earlier) = (&targets_view[i % 2], &targets_view[(i + 1) % 2]);
                let mut resources = views.resources(f, inputs, Some(earlier), Some(used));
                resources.push((24, slice(&index_buf, (i * UNIFORM_STRIDE) as u64, 16)));
                resources.push((25, wgpu::BindingResource::TextureView(out)));
                resources.extend(extra.map(|u| (26, u.as_entire_binding())));
                bind_group(d, &layout, span, resources)
            })
            .collect();
        let groups: Vec<&wgpu::BindGroup> = groups.iter().collect();
        let timed = rec.begin(span);
        let size = f.view.size;
        frame_pass(&mut rec.enc, span, pipeline, &groups, timed.compute(), size);
        rec.end();
        targets[(batches as usize - 1) % 2].clone()
    }
}

/// The gates' two gathers (shade.wgsl's entry points).
#[derive(Debug, Clone, Copy)]
pub(super) enum GatesGather {
    /// `cs_gates_indirect`: each pixel its subset's VPLs (or every VPL).
    Indirect,
    /// `cs_starved_walks`: the starved pixels' walks of what their block lacks.
    Starved,
    /// `cs_near_field`: each pixel's walks of the VPLs near it.
    Near,
    /// `cs_near_marks`: each tile's near VPLs marked.
    NearMarks,
    /// `cs_near_compose`: the near light added onto the image.
    NearCompose,
}

/// The bytes of the near field's marks for a frame of `size` pixels and `vpls` VPLs: a bit a
/// VPL for each 8 × 8 tile, in words.
pub fn near_marks_bytes([w, h]: [u32; 2], vpls: u32) -> u64 {
    let tiles = u64::from(w.div_ceil(8)) * u64::from(h.div_ceil(8));
    tiles * u64::from(vpls.div_ceil(32)) * 4
}

/// The near field's three lists of tiles (shade.wgsl's `near_in`, `near_out`, `near_spare`,
/// rotated a round) for a frame of `tiles` tiles, each emptied in the frame's commands: its
/// control slot alone, an indirect dispatch of one workgroup.
fn near_lists(f: &Frame, pool: &mut Pool, rec: &mut Recorder, tiles: u32) -> [wgpu::Buffer; 3] {
    const NAMES: [&str; 3] = [
        "near rounds' list 0",
        "near rounds' list 1",
        "near rounds' list 2",
    ];
    let head: [u32; 4] = [1, 1, 1, 1];
    let empty = pool.upload(
        f.ctx,
        "near rounds' empty list",
        bytemuck::cast_slice(&head),
        wgpu::BufferUsages::COPY_SRC,
    );
    let bytes = (4 + 2 * (u64::from(tiles) + 1)) * 4;
    let usage =
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST;
    NAMES.map(|name| {
        let list = pool.buffer(&f.ctx.device, name, bytes, usage);
        rec.enc.copy_buffer_to_buffer(&empty, 0, &list, 0, 16);
        list
    })
}

/// The dispatches a gather of up to `walks` walks a pixel takes: batches of `f.walk_batch`
/// walks on a software rasterizer (its loop limit), one elsewhere.
pub(super) fn batch_count(f: &Frame, walks: u32) -> u32 {
    match f.walk_batch {
        0 => 1,
        batch => walks.div_ceil(batch).max(1),
    }
}

/// A gates gather in batches ([`Shade::walk_batches`]).
struct Batched<'a> {
    /// Its entry point's pipeline.
    pipeline: &'a wgpu::ComputePipeline,
    /// Dispatches, a batch of walks each.
    batches: u32,
    /// The bindings the entry point uses but 24, 25 and `extra`'s.
    used: &'a [u32],
    /// Its two targets' names in the pool (the result, the batches' sum).
    names: [&'static str; 2],
    /// The pass's name in the timings.
    span: &'static str,
    /// A uniform at binding 26, for the entry points that read one.
    extra: Option<&'a wgpu::Buffer>,
}

/// The texture views shade.wgsl's passes read beside the G-buffer's.
pub(super) struct Views {
    maps: wgpu::TextureView,
    vis: wgpu::TextureView,
    vpl_vis: wgpu::TextureView,
}

impl Views {
    pub(super) fn new(f: &Frame, (shadows, _, _, lc, vpl_lc): Inputs) -> Views {
        let no_vis = array_view(&f.scene.no_visibility);
        Views {
            maps: array_view(&shadows.maps),
            vis: lc.map_or_else(|| no_vis.clone(), |o| array_view(&o.visibility)),
            vpl_vis: vpl_lc.map_or(no_vis, |o| array_view(&o.visibility)),
        }
    }

    /// shade.wgsl's group 0 but bindings 24 and 25 (`used` alone where given), with `earlier`
    /// as the batches' sum (binding 21, left out when `None`).
    pub(super) fn resources<'a>(
        &'a self,
        f: &'a Frame,
        (shadows, g, gathers, lc, vpl_lc): Inputs<'a>,
        earlier: Option<&'a wgpu::TextureView>,
        used: Option<&[u32]>,
    ) -> Vec<(u32, wgpu::BindingResource<'a>)> {
        let level = f.scene.level.as_ref();
        let lists = gathers.lists;
        let none = &f.scene.no_level;
        let buffers: [(u32, &wgpu::Buffer); 18] = [
            (0, &f.globals),
            (1, &shadows.lights),
            (2, &f.vpls),
            (3, &shadows.matrices),
            (8, &f.grid),
            (9, level.map_or(none, |l| &l.voxel_words)),
            (10, level.map_or(none, |l| &l.gates)),
            (11, level.map_or(none, |l| &l.cluster_gates)),
            (12, lists.map_or(none, |b| &b.pixel_cluster)),
            (13, lists.map_or(none, |b| &b.clusters)),
            (14, lists.map_or(none, |b| &b.entries)),
            (15, level.map_or(none, |l| &l.portal_words)),
            (16, lists.map_or(none, |b| &b.vpl_cluster)),
            (18, lc.map_or(none, |o| &o.clusters.light_cluster)),
            (20, vpl_lc.map_or(none, |o| &o.clusters.light_cluster)),
            (22, level.map_or(none, |l| &l.sight_words)),
            (23, gathers.vpl_ends.unwrap_or(none)),
            (31, level.map_or(none, |l| &l.sight_extra)),
        ];
        let textures = [
            (4, &self.maps),
            (5, &g.views[0]),
            (6, &g.views[1]),
            (7, &g.views[2]),
            (17, &self.vis),
            (19, &self.vpl_vis),
        ];
        buffers
            .iter()
            .map(|&(k, b)| (k, b.as_entire_binding()))
            .chain(
                textures
                    .into_iter()
                    .chain(earlier.map(|v| (21, v)))
                    .map(|(k, v)| (k, wgpu::BindingResource::TextureView(v))),
            )
            .filter(|(k, _)| used.is_none_or(|u| u.contains(k)))
            .collect()
    }
}
