//! Imperfect shadow maps (ism_maps.wgsl) and the two modes that light through them
//! (ism_gather.wgsl): `per-vpl-ism` (Ritschel et al. 2008: a map per VPL) and `val-ism`
//! (Weinzierl-Heigl: a map per virtual area light, the point-to-disk form factor, PCSS).
//!
//! The maps are compute passes, not point draws: wgpu draws points one pixel wide, and a splat
//! of a radius set per point is a loop of `atomicMax` over its texels (the nearest distance
//! wins, as a depth test would), each texel taking the distance where its ray meets the
//! point's surfel (a disk in its triangle's plane). The maps are one storage buffer, map k at
//! k·s² words; the pull-push pyramid a second one. The points are drawn each frame: point i
//! from the scene's triangles by a hash of i (a few ALU a point), so moved meshes move their
//! points; a frame keeps them (position, normal) up to 2²² points and beyond that the splat
//! draws them again, so no point pool grows with the emitters.

use super::gbuffer::GBufferOutput;
use super::interleave_blur::InterleaveBlur;
pub use super::ism_params::{DiskLight, ISM_MAP_SIZE, IsmParams, ValIsmParams, VplIsmParams};
use super::shade::{frame_pass, frame_target};
use super::vals::{ValClustering, ValInput};
use crate::RenderError;
use crate::gpu::context::{Pool, bind_group, compute_pipelines, slice};
use crate::gpu::layout::{IsmFrame, IsmLevel, UNIFORM_STRIDE, strided};
use crate::gpu::shaders::{self, ShaderSources, WG_LINEAR};
use crate::gpu::timing::Recorder;
use crate::gpu::{Frame, GpuContext};

/// The ISM pipelines.
pub struct Isms {
    emit: wgpu::ComputePipeline,
    sample: wgpu::ComputePipeline,
    splat: wgpu::ComputePipeline,
    pull: wgpu::ComputePipeline,
    push: wgpu::ComputePipeline,
    gather_vpl: wgpu::ComputePipeline,
    gather_val: wgpu::ComputePipeline,
}

/// The maps of a frame.
pub struct IsmOutput {
    /// The constants ([`IsmFrame`]).
    pub frame: wgpu::Buffer,
    /// Each emitter's centre and axis.
    pub emitters: wgpu::Buffer,
    /// The maps (map k at k·s² words, a texel !bits of the distance, 0 nothing).
    pub atlas: wgpu::Buffer,
    /// Their side. [Units: texels]
    pub map_size: u32,
}

/// What the maps are made for.
pub enum Emitters<'a> {
    /// The frame's VPLs.
    Vpls,
    /// These VALs.
    Vals(&'a wgpu::Buffer, u32),
}

/// Points a frame may keep (32 bytes each: position, normal; and within the adapter's
/// largest storage binding): beyond, they are drawn again in the splat pass.
const MAX_KEPT_POINTS: u64 = 1 << 22;

/// Workgroups for `n` threads as (x, y) within the adapter's 65,535 per dimension.
fn groups(n: u64) -> (u32, u32) {
    let g = n.div_ceil(WG_LINEAR as u64);
    (g.min(65_535) as u32, g.div_ceil(65_535) as u32)
}

/// A compute pass in its own timed span `name`.
fn timed_pass(rec: &mut Recorder, name: &'static str, f: impl FnOnce(&mut wgpu::ComputePass)) {
    let span = rec.begin(name);
    {
        let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(name),
            timestamp_writes: span.compute(),
        });
        f(&mut pass);
    }
    rec.end();
}

/// One dispatch of `n` threads.
fn dispatch(
    pass: &mut wgpu::ComputePass,
    pl: &wgpu::ComputePipeline,
    bg: &wgpu::BindGroup,
    n: u64,
) {
    let (x, y) = groups(n);
    pass.set_pipeline(pl);
    pass.set_bind_group(0, bg, &[]);
    pass.dispatch_workgroups(x, y, 1);
}

/// The maps' constants: `kind` (0 VPLs, 1 VALs), `count` maps of side `s`, `points` in all;
/// `gather`: the gather's interleaving block, PCSS samples (none: hard) and disk parts.
fn frame_constants(
    f: &Frame,
    p: &IsmParams,
    (kind, count, s): (u32, u32, u32),
    points: u32,
    (block, pcss, disk_parts): (u32, Option<super::lc_params::PcssParams>, u32),
) -> IsmFrame {
    let geo = &f.scene.geometry;
    IsmFrame {
        emitters: count,
        map_size: s,
        points,
        triangles: geo.triangle_count,
        kind,
        seed: p.seed,
        block,
        subsets: block * block,
        // A point stands for the scene's area over the points of a map, as a disk; its splat
        // √coverage times wider.
        point_radius: (p.coverage * geo.area_m2 / (p.points_per_map as f32 * std::f32::consts::PI))
            .sqrt(),
        max_splat: p.max_splat,
        centre_offset: f.scene.near_m,
        g_max: f.params.g_max,
        bias: p.bias,
        normal_offset: p.normal_offset,
        blocker_samples: pcss.map_or(0, |p| p.blocker_samples),
        filter_samples: pcss.map_or(0, |p| p.filter_samples),
        disk_parts,
        ..bytemuck::Zeroable::zeroed()
    }
}

/// The pull-push of `count` maps of side `s` over `levels` levels: one pull a level up, one
/// push a level down, and the pyramid's size in words (levels 1… of every map).
fn pull_push_steps(s: u32, levels: u32, count: u32) -> (Vec<IsmLevel>, u64) {
    let mut offsets = vec![0u64; levels as usize + 2];
    for l in 1..=levels as usize {
        offsets[l + 1] = offsets[l] + count as u64 * ((s >> l) as u64).pow(2);
    }
    let at = |l: u32| offsets[l as usize] as u32;
    let mut steps: Vec<IsmLevel> = (1..=levels)
        .map(|l| IsmLevel {
            level: l,
            side: s >> l,
            offset: at(l),
            other: at(l - 1),
        })
        .collect();
    steps.extend((0..levels).rev().map(|l| IsmLevel {
        level: l,
        side: s >> l,
        offset: at(l),
        other: at(l + 1),
    }));
    (steps, offsets[levels as usize + 1])
}

impl Isms {
    /// Builds the pipelines.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<Isms, RenderError> {
        let maps = shaders::module(d, s, "ism_maps.wgsl")?;
        let [emit, sample, splat, pull, push] =
            compute_pipelines(d, &maps, ["emit", "sample", "splat", "pull", "push"]);
        let gather = shaders::module(d, s, "ism_gather.wgsl")?;
        let [gather_vpl, gather_val] = compute_pipelines(d, &gather, ["cs_vpl", "cs_val"]);
        Ok(Isms {
            emit,
            sample,
            splat,
            pull,
            push,
            gather_vpl,
            gather_val,
        })
    }

    /// Records the maps of `emitters` with `p`; `gather`: the gather's interleaving block and
    /// PCSS samples (none: hard lookups) and the parts of a VAL's disk, kept in the same
    /// constants.
    pub fn record_maps(
        &self,
        f: &Frame,
        p: &IsmParams,
        emitters: Emitters,
        gather: (u32, Option<super::lc_params::PcssParams>, u32),
        pool: &mut Pool,
        rec: &mut Recorder,
    ) -> Result<IsmOutput, RenderError> {
        p.check()?;
        let d = &f.ctx.device;
        let (kind, count, vals) = match emitters {
            Emitters::Vpls => (0, f.vpl_count, None),
            Emitters::Vals(b, m) => (1, m, Some(b)),
        };
        let limit = (d.limits().max_storage_buffer_binding_size).min(d.limits().max_buffer_size);
        let s = p.side_for(count, limit)?;
        let points = count as u64 * p.points_per_map as u64;
        if points > u32::MAX as u64 {
            return Err(RenderError::Param(format!(
                "{count} maps × {} points is more than 2³² points: use fewer points per map",
                p.points_per_map
            )));
        }
        let constants = frame_constants(f, p, (kind, count, s), points as u32, gather);
        let levels = p.pull_push.min(s.trailing_zeros());
        let (steps, words) = pull_push_steps(s, levels, count);
        let keep = points <= MAX_KEPT_POINTS.min(limit / 32);
        let b = MapBuffers::new(f, pool, &constants, (words, keep), vals);
        let g = self.map_groups(f, pool, &b, (&steps, levels));
        rec.enc.clear_buffer(&b.atlas, 0, None);
        timed_pass(rec, "ISM points", |pass| {
            if count > 0 {
                dispatch(pass, &self.emit, &g.emit, count as u64);
                if keep {
                    dispatch(pass, &self.sample, &g.sample, points);
                }
            }
        });
        timed_pass(rec, "ISM atlas", |pass| {
            if count > 0 {
                dispatch(pass, &self.splat, &g.splat, points);
            }
        });
        timed_pass(rec, "pull-push", |pass| {
            for (k, step) in steps.iter().enumerate().filter(|_| count > 0) {
                let (pl, bg) = match k < levels as usize {
                    true => (&self.pull, &g.pull),
                    false => (&self.push, &g.push),
                };
                pass.set_bind_group(1, &g.levels[k], &[]);
                dispatch(pass, pl, bg, count as u64 * (step.side as u64).pow(2));
            }
        });
        Ok(IsmOutput {
            frame: b.frame,
            emitters: b.emitters,
            atlas: b.atlas,
            map_size: s,
        })
    }

    /// The maps' passes' bind groups over `b`, and one a pull-push step (`levels` pulls, then
    /// the pushes).
    fn map_groups(
        &self,
        f: &Frame,
        pool: &mut Pool,
        b: &MapBuffers,
        (steps, levels): (&[IsmLevel], u32),
    ) -> MapGroups {
        let d = &f.ctx.device;
        let geo = &f.scene.geometry;
        let all: [&wgpu::Buffer; 9] = [
            &b.frame,
            &f.vpls,
            &b.vals,
            &b.emitters,
            &geo.triangles,
            &geo.area_cdf,
            &b.kept,
            &b.atlas,
            &b.pyramid,
        ];
        let bind = |pl: &wgpu::ComputePipeline, which: &[u32]| {
            let r = which
                .iter()
                .map(|&i| (i, all[i as usize].as_entire_binding()))
                .collect();
            bind_group(d, &pl.get_bind_group_layout(0), "ism", r)
        };
        let uniform = wgpu::BufferUsages::UNIFORM;
        let level_buf = pool.upload(f.ctx, "ism levels", &strided(steps), uniform);
        let size = size_of::<IsmLevel>() as u64;
        let levels = (0..steps.len())
            .map(|k| {
                let pl = if k < levels as usize {
                    &self.pull
                } else {
                    &self.push
                };
                let off = (k * UNIFORM_STRIDE) as u64;
                bind_group(
                    d,
                    &pl.get_bind_group_layout(1),
                    "ism level",
                    vec![(0, slice(&level_buf, off, size))],
                )
            })
            .collect();
        MapGroups {
            emit: bind(&self.emit, &[0, 1, 2, 3]),
            sample: bind(&self.sample, &[0, 4, 5, 6]),
            splat: bind(&self.splat, &[0, 3, 4, 5, 6, 7]),
            pull: bind(&self.pull, &[0, 7, 8]),
            push: bind(&self.push, &[0, 7, 8]),
            levels,
        }
    }

    /// Records the gather through `maps` into an indirect target and the blur composing it
    /// onto `out`: `vals` for val-ism, none for per-vpl-ism.
    #[allow(clippy::too_many_arguments)]
    fn record_gather(
        &self,
        f: &Frame,
        maps: &IsmOutput,
        vals: Option<&wgpu::Buffer>,
        interleave: &super::interleave_blur::InterleaveParams,
        blur: &InterleaveBlur,
        pool: &mut Pool,
        rec: &mut Recorder,
        (g, out): (&GBufferOutput, &wgpu::Texture),
    ) {
        let d = &f.ctx.device;
        let indirect = frame_target(f, pool, "indirect irradiance");
        let indirect_view = indirect.create_view(&Default::default());
        let tex = wgpu::BindingResource::TextureView;
        let (pipeline, emitters) = match vals {
            Some(v) => (&self.gather_val, (2, v)),
            None => (&self.gather_vpl, (1, &f.vpls)),
        };
        let bg = bind_group(
            d,
            &pipeline.get_bind_group_layout(0),
            "ism gather",
            vec![
                (0, maps.frame.as_entire_binding()),
                (emitters.0, emitters.1.as_entire_binding()),
                (3, maps.emitters.as_entire_binding()),
                (4, maps.atlas.as_entire_binding()),
                (5, tex(&g.views[0])),
                (6, tex(&g.views[1])),
                (7, tex(&indirect_view)),
            ],
        );
        let span = rec.begin("indirect lighting");
        frame_pass(
            &mut rec.enc,
            "ism gather",
            pipeline,
            &[&bg],
            span.compute(),
            f.view.size,
        );
        rec.end();
        let uniform = InterleaveBlur::uniform(f, interleave, pool, false);
        blur.record(
            f,
            interleave,
            pool,
            rec,
            (g, &uniform, &indirect, out),
            (None, None),
        );
    }

    /// Mode per-vpl-ism onto `out`.
    pub fn record_vpls(
        &self,
        f: &Frame,
        p: &VplIsmParams,
        blur: &InterleaveBlur,
        pool: &mut Pool,
        rec: &mut Recorder,
        io: (&GBufferOutput, &wgpu::Texture),
    ) -> Result<(), RenderError> {
        p.check()?;
        if f.vpl_count == 0 {
            return Ok(());
        }
        let gather = (p.interleave.block, None, 1);
        let maps = self.record_maps(f, &p.ism, Emitters::Vpls, gather, pool, rec)?;
        self.record_gather(f, &maps, None, &p.interleave, blur, pool, rec, io);
        Ok(())
    }

    /// Mode val-ism onto `out`: the clustering, the VALs' maps, the gather. Returns the
    /// clustering's convergence words (none without VPLs).
    #[allow(clippy::too_many_arguments)]
    pub fn record_vals(
        &self,
        f: &Frame,
        p: &ValIsmParams,
        clustering: &ValClustering,
        blur: &InterleaveBlur,
        warm: bool,
        pool: &mut Pool,
        rec: &mut Recorder,
        io: (&GBufferOutput, &wgpu::Texture),
    ) -> Result<Option<wgpu::Buffer>, RenderError> {
        p.check()?;
        if f.vpl_count == 0 {
            return Ok(None);
        }
        let input = ValInput {
            buffer: &f.vpls,
            count: f.vpl_count,
            cpu: f.vpls_cpu,
        };
        let b = clustering.record(f.ctx, &input, &p.vals, 1, warm, pool, rec)?;
        let m = p.vals.count;
        let samples = match p.hard_lookups {
            true => None,
            false => Some(p.pcss),
        };
        let gather = (p.interleave.block, samples, p.disk.parts());
        let maps = self.record_maps(f, &p.ism, Emitters::Vals(&b.vals, m), gather, pool, rec)?;
        self.record_gather(f, &maps, Some(&b.vals), &p.interleave, blur, pool, rec, io);
        Ok(Some(b.state))
    }
}

/// Reads every map back as distances (m; `f32::INFINITY` where nothing was seen): map k's
/// texel (x, y) at k·s² + y·s + x. For tests and inspection.
pub fn read_maps(ctx: &GpuContext, maps: &IsmOutput) -> Result<Vec<f32>, RenderError> {
    let words: Vec<u32> =
        bytemuck::cast_slice(&crate::gpu::context::read_buffer(ctx, &maps.atlas)?).to_vec();
    Ok(words
        .iter()
        .map(|&w| match w {
            0 => f32::INFINITY,
            w => f32::from_bits(!w),
        })
        .collect())
}

/// The maps' buffers for one frame.
struct MapBuffers {
    /// The constants (0).
    frame: wgpu::Buffer,
    /// The VALs (2; a stand-in for per-VPL maps).
    vals: wgpu::Buffer,
    /// Each map's emitter (3).
    emitters: wgpu::Buffer,
    /// The points kept between sampling and splatting, where they fit (6).
    kept: wgpu::Buffer,
    /// The maps (7).
    atlas: wgpu::Buffer,
    /// The pull-push pyramid (8).
    pyramid: wgpu::Buffer,
}

impl MapBuffers {
    /// The buffers for `c` (its maps' count and side), a pyramid of `words`, the points kept
    /// where `keep`, and `vals` (none: per-VPL maps).
    fn new(
        f: &Frame,
        pool: &mut Pool,
        c: &IsmFrame,
        (words, keep): (u64, bool),
        vals: Option<&wgpu::Buffer>,
    ) -> MapBuffers {
        let d = &f.ctx.device;
        let rw = wgpu::BufferUsages::STORAGE;
        let uniform = wgpu::BufferUsages::UNIFORM;
        let (count, side) = (u64::from(c.emitters.max(1)), u64::from(c.map_size));
        let points = u64::from(c.points);
        let copies = wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC;
        MapBuffers {
            frame: pool.upload(f.ctx, "ism frame", bytemuck::bytes_of(c), uniform),
            emitters: pool.buffer(d, "ism emitters", count * 32, rw),
            atlas: pool.buffer(d, "ism atlas", count * side * side * 4, rw | copies),
            pyramid: pool.buffer(d, "ism pyramid", words * 4, rw),
            kept: pool.buffer(d, "ism points", if keep { points * 32 } else { 32 }, rw),
            vals: match vals {
                Some(v) => v.clone(),
                None => pool.buffer(d, "ism no vals", 64, rw),
            },
        }
    }
}

/// The maps' passes' bind groups.
struct MapGroups {
    emit: wgpu::BindGroup,
    sample: wgpu::BindGroup,
    splat: wgpu::BindGroup,
    pull: wgpu::BindGroup,
    push: wgpu::BindGroup,
    /// A pull-push step's constants each (group 1).
    levels: Vec<wgpu::BindGroup>,
}
