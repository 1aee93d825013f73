//! What `visgate render` does, as one library call that the CLI, the viewer and `compare`
//! share: a [`RenderJob`] (method, VPLs, image size, frames) run on a scene renders each frame
//! on the GPU, on a CPU twin, or as the exact CPU reference, and hands each [`JobFrame`] to the
//! caller. Every limit is checked here, once.

use std::time::Instant;

use visgate_formats::{Camera, Scene};

use crate::RenderError;
use crate::camera::View;
use crate::cpu::gates::{GateLevel, GateParams};
use crate::cpu::reference::{IndirectVisibility, ReferenceParams, ReferenceStats, render_with};
use crate::cpu::tracer::Tracer;
use crate::gpu::{GpuContext, GpuMode, GpuParams, GpuRenderer, PassTimes, RsmParams, VplInput};
use crate::hdr::HdrImage;
use crate::vpl::{GatherParams, GeometryClamp, PathParams, Vpl, path_vpls};

/// Where the VPLs come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VplSource {
    /// Light paths traced from the lights on the CPU (any number of bounces).
    Paths,
    /// The lights' reflective shadow maps, sampled at Halton points on the GPU (one bounce).
    Rsm,
}

/// Which renderer makes the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Renderer {
    /// The exact CPU reference: a shadow ray per VPL and pixel sample.
    Reference,
    /// A GPU method.
    Gpu(GpuMode),
    /// The CPU twin of a GPU method: `none` and `direct-only` with shadow rays for direct
    /// light, `gates` per point (any number of hops), `per-vpl-shadow-maps` as the reference.
    CpuTwin(GpuMode),
}

/// A render: what to draw and how.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderJob {
    /// The renderer and method.
    pub renderer: Renderer,
    /// GPU settings: the method inside is `renderer`'s, and `g_max` is replaced by `clamp`'s
    /// value for the scene; the shadows serve every renderer.
    pub params: GpuParams,
    /// The geometry-term clamp of every renderer (by default relative to the scene's size).
    pub clamp: GeometryClamp,
    /// Light paths (VPL source paths) or VPLs (RSM). [Limit: ≤ 2^24]
    pub vpls: u32,
    /// Where the VPLs come from.
    pub vpl_source: VplSource,
    /// RSM side per layer. [Units: texels] [Limit: 16..=4096]
    pub rsm_size: u32,
    /// VPL generations per light path. [Limit: 1..=64]
    pub bounces: u32,
    /// Seed of the VPLs' low-discrepancy sequence.
    pub seed: u64,
    /// Image size. [Units: px] [Limit: 1..=16384 each]
    pub size: [u32; 2],
    /// CPU pixel samples. [Limit: 1..=4096]
    pub spp: u32,
    /// Time of the first frame. [Units: s]
    pub time: f64,
    /// Frames, `1 / fps` apart. [Limit: ≥ 1]
    pub frames: u32,
    /// Frames per second of a sequence. [Limit: > 0]
    pub fps: f64,
    /// GPU frames rendered and dropped before each frame that is kept, so that its pass times
    /// are of a warm device (pipelines compiled, buffers grown). [Limit: ≤ 16]
    pub warmup: u32,
}

impl Default for RenderJob {
    fn default() -> Self {
        RenderJob {
            renderer: Renderer::Reference,
            params: GpuParams::default(),
            clamp: GeometryClamp::default(),
            vpls: 1024,
            vpl_source: VplSource::Paths,
            rsm_size: 256,
            bounces: 1,
            seed: 1,
            size: [512, 512],
            spp: 4,
            time: 0.0,
            frames: 1,
            fps: 30.0,
            warmup: 0,
        }
    }
}

/// What a frame took and counted.
#[derive(Debug, Clone, PartialEq)]
pub enum FrameStats {
    /// A GPU frame's passes.
    Gpu(PassTimes),
    /// A CPU frame's rays and time.
    Cpu(ReferenceStats),
}

/// One rendered frame.
#[derive(Debug, Clone)]
pub struct JobFrame {
    /// Its index in the sequence.
    pub index: u32,
    /// Its time. [Units: s]
    pub time: f64,
    /// The linear HDR image.
    pub image: HdrImage,
    /// VPLs it used.
    pub vpl_count: usize,
    /// Times of the BVH build and the VPLs (CPU wall; RSM VPLs: part of the GPU frame). [Units: s]
    pub prep_s: [f64; 2],
    /// What it took.
    pub stats: FrameStats,
}

/// The GPU adapter a job runs on, where it uses one.
#[derive(Debug, Clone)]
pub struct JobSetup {
    /// The adapter's name and backend.
    pub adapter: Option<String>,
    /// Opening it, uploading the scene and the level. [Units: s]
    pub seconds: f64,
    /// The method the frames run: the job's, but where its walk's tables did not fit the
    /// adapter and another walk took their place ([`GpuRenderer::level_for_mode_or_planes`]).
    pub mode: Option<GpuMode>,
}

impl RenderJob {
    /// The GPU method, if the job has one (the CPU twin's included).
    pub fn mode(&self) -> Option<GpuMode> {
        match self.renderer {
            Renderer::Reference => None,
            Renderer::Gpu(m) | Renderer::CpuTwin(m) => Some(m),
        }
    }

    /// Checks every setting; `has_level`: a baked level is given.
    pub fn check(&self, has_level: bool) -> Result<(), RenderError> {
        let [w, h] = self.size;
        if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
            return Err(RenderError::Param(format!(
                "image size {w}x{h}: each side must be 1..=16384 pixels"
            )));
        }
        if self.frames == 0 {
            return Err(RenderError::Param(
                "--frames 0: render at least 1 frame".into(),
            ));
        }
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(RenderError::Param(format!(
                "--fps {}: give a number of frames per second > 0",
                self.fps
            )));
        }
        if self.warmup > 16 {
            return Err(RenderError::Param(format!(
                "--warmup {}: at most 16 frames",
                self.warmup
            )));
        }
        if !self.time.is_finite() {
            return Err(RenderError::Param(format!(
                "--time {}: give a finite time in seconds",
                self.time
            )));
        }
        if self.vpl_source == VplSource::Rsm && self.bounces != 1 {
            return Err(RenderError::Param(format!(
                "--vpl-source rsm gives one bounce; use --vpl-source paths for --bounces {}",
                self.bounces
            )));
        }
        if self.vpl_source == VplSource::Rsm {
            RsmParams {
                count: self.vpls,
                rsm_size: self.rsm_size,
                seed: self.seed,
            }
            .check()?;
        }
        let mode = self.mode();
        if let Some(m) = mode
            && m.gates().is_some()
            && !has_level
        {
            return Err(RenderError::Param(format!(
                "--mode {} needs --level LEVEL.vgate (bake one with `visgate bake SCENE -o \
                 LEVEL.vgate`)",
                m.name()
            )));
        }
        self.clamp.g_max(1.0)?;
        match self.renderer {
            Renderer::Gpu(_) => self.params.check(),
            Renderer::Reference => Ok(()),
            Renderer::CpuTwin(m) => match m {
                GpuMode::None | GpuMode::DirectOnly | GpuMode::PerVplShadowMaps(_) => Ok(()),
                GpuMode::Gates(g) => check_cpu_gates(&g.gates),
                GpuMode::GatesPerPixel(_) => Err(RenderError::Param(
                    "--mode gates-per-pixel runs on the GPU; the CPU twin is --mode gates --cpu"
                        .into(),
                )),
                GpuMode::ValHard(_)
                | GpuMode::ValCssm(..)
                | GpuMode::VplClusters(..)
                | GpuMode::PerVplIsm(_)
                | GpuMode::ValIsm(_) => Err(RenderError::Param(format!(
                    "--mode {} runs on the GPU; its reference is --mode reference",
                    m.name()
                ))),
            },
        }
    }

    /// Renders every frame of `scene` (posed at each frame's time) from `camera` and hands
    /// each to `on_frame`; `setup` is told the adapter first. `progress(rows_done, rows)`
    /// follows CPU renders.
    pub fn run(
        &self,
        scene: &Scene,
        camera: &Camera,
        level: Option<&GateLevel>,
        setup: &mut dyn FnMut(&JobSetup),
        progress: &(dyn Fn(u32, u32) + Sync),
        on_frame: &mut dyn FnMut(JobFrame) -> Result<(), RenderError>,
    ) -> Result<(), RenderError> {
        self.check(level.is_some())?;
        let mut job = self.for_scene(scene)?;
        let view = View::new(camera, job.size)?;
        let on_gpu = matches!(job.renderer, Renderer::Gpu(_));
        let t = Instant::now();
        let first = scene.at(job.time);
        let ctx = if on_gpu || job.vpl_source == VplSource::Rsm {
            Some(GpuContext::new()?)
        } else {
            None
        };
        let mut gpu = match &ctx {
            Some(ctx) => Some(GpuRenderer::new(ctx, &first)?),
            None => None,
        };
        if let (Some(ctx), Some(g), Some(l), Renderer::Gpu(mode)) =
            (&ctx, &mut gpu, level, &mut job.renderer)
            && let Some(note) = g.level_for_mode_or_planes(ctx, l, mode)?
        {
            tracing::warn!("{note}");
        }
        setup(&JobSetup {
            adapter: ctx
                .as_ref()
                .map(|c| format!("{} ({:?})", c.adapter_info.name, c.adapter_info.backend)),
            seconds: t.elapsed().as_secs_f64(),
            mode: job.mode(),
        });
        for index in 0..job.frames {
            let time = job.time + index as f64 / job.fps;
            let posed = if index == 0 {
                first.clone()
            } else {
                scene.at(time)
            };
            if let (Some(ctx), Some(g), true) = (&ctx, &mut gpu, index > 0) {
                g.set_scene(ctx, &posed);
            }
            let frame = match (&ctx, &mut gpu) {
                (Some(ctx), Some(g)) => job.frame_gpu(ctx, g, &posed, &view, level)?,
                _ => job.frame_cpu(&posed, &view, level, &[], progress)?,
            };
            on_frame(JobFrame {
                index,
                time,
                ..frame
            })?;
        }
        Ok(())
    }

    /// The job with `params.g_max` resolved from `clamp` for `scene` (its bounding diagonal).
    pub fn for_scene(&self, scene: &Scene) -> Result<RenderJob, RenderError> {
        let diagonal = scene.bounds().map_or(0.0, |(lo, hi)| (hi - lo).length());
        let mut job = self.clone();
        job.params.g_max = self.clamp.g_max(diagonal)?;
        Ok(job)
    }

    /// Light-path VPLs of `scene` (none for direct light only).
    fn path_vpls(&self, tracer: &Tracer, scene: &Scene) -> Result<Vec<Vpl>, RenderError> {
        if self.mode() == Some(GpuMode::DirectOnly) {
            return Ok(Vec::new());
        }
        path_vpls(
            tracer,
            &scene.lights,
            &PathParams {
                paths: self.vpls,
                bounces: self.bounces,
                seed: self.seed,
            },
        )
    }

    /// A frame with a GPU context: the GPU method, or the CPU renderer with RSM VPLs.
    fn frame_gpu(
        &self,
        ctx: &GpuContext,
        gpu: &mut GpuRenderer,
        scene: &Scene,
        view: &View,
        level: Option<&GateLevel>,
    ) -> Result<JobFrame, RenderError> {
        let rsm = RsmParams {
            count: self.vpls,
            rsm_size: self.rsm_size,
            seed: self.seed,
        };
        let direct_only = self.mode() == Some(GpuMode::DirectOnly);
        let Renderer::Gpu(mode) = self.renderer else {
            // CPU renderer, RSM VPLs: read them back so that the CPU uses the very same.
            let t = Instant::now();
            let vpls = if direct_only {
                Vec::new()
            } else {
                gpu.rsm_vpls(ctx, rsm.count, rsm.rsm_size, rsm.seed)?
            };
            let vpl_s = t.elapsed().as_secs_f64();
            let mut f = self.frame_cpu(scene, view, level, &vpls, &|_, _| {})?;
            f.prep_s[1] = vpl_s;
            return Ok(f);
        };
        let params = GpuParams {
            mode,
            ..self.params
        };
        let t = Instant::now();
        let (tracer, bvh_s) = match self.vpl_source {
            VplSource::Paths if !direct_only => (Some(Tracer::new(scene)), t.elapsed()),
            _ => (None, t.elapsed()),
        };
        let t = Instant::now();
        let vpls = match &tracer {
            Some(tr) => self.path_vpls(tr, scene)?,
            None => Vec::new(),
        };
        let vpl_s = t.elapsed().as_secs_f64();
        // The BVH only traced the VPLs: freed before the frame, whose buffers a software
        // adapter holds in host memory beside it (Crytek Sponza subdivided to 4.2 M triangles:
        // its BVH 0.8 GB of a 4.97 GB peak).
        drop(tracer);
        let input = match (self.vpl_source, direct_only) {
            (VplSource::Rsm, false) => VplInput::Rsm(rsm),
            _ => VplInput::Given(&vpls),
        };
        for _ in 0..self.warmup {
            gpu.render_frame(ctx, view, input, &params)?;
        }
        let (image, times) = gpu.render_frame(ctx, view, input, &params)?;
        let vpl_count = match input {
            VplInput::Given(v) => v.len(),
            VplInput::Rsm(_) => rsm.count as usize,
        };
        Ok(JobFrame {
            index: 0,
            time: 0.0,
            image,
            vpl_count,
            prep_s: [bvh_s.as_secs_f64(), vpl_s],
            stats: FrameStats::Gpu(times),
        })
    }

    /// A CPU frame: the reference or a CPU twin, with `given` VPLs (RSM) or light paths.
    fn frame_cpu(
        &self,
        scene: &Scene,
        view: &View,
        level: Option<&GateLevel>,
        given: &[Vpl],
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<JobFrame, RenderError> {
        let t = Instant::now();
        let tracer = Tracer::new(scene);
        let bvh_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let vpls = match self.vpl_source {
            VplSource::Rsm => given.to_vec(),
            VplSource::Paths => self.path_vpls(&tracer, scene)?,
        };
        let vpl_s = t.elapsed().as_secs_f64();
        let mode = self.mode();
        let exact = matches!(mode, None | Some(GpuMode::PerVplShadowMaps(_)));
        let params = ReferenceParams {
            samples_per_pixel: self.spp,
            direct: true,
            indirect: mode != Some(GpuMode::DirectOnly),
            indirect_visibility: exact,
            gather: GatherParams {
                g_max: self.params.g_max,
            },
        };
        let vis = match (mode.and_then(|m| m.gates()), level) {
            (Some(g), Some(l)) => IndirectVisibility::Gates(l, g),
            _ if exact => IndirectVisibility::Exact,
            _ => IndirectVisibility::Unoccluded,
        };
        let (image, stats) =
            render_with(&tracer, &scene.lights, &vpls, view, &params, vis, progress)?;
        Ok(JobFrame {
            index: 0,
            time: 0.0,
            image,
            vpl_count: vpls.len(),
            prep_s: [bvh_s, vpl_s],
            stats: FrameStats::Cpu(stats),
        })
    }
}

/// Checks gate parameters for the CPU twin (any number of hops up to 16).
pub fn check_cpu_gates(g: &GateParams) -> Result<(), RenderError> {
    let o = g.oversize;
    if !(o > 0.0 && o.is_finite() && (1..=16).contains(&g.max_hops)) {
        return Err(RenderError::Param(format!(
            "gate oversize {o} must be > 0 and hops {} 1..=16 on the CPU twin",
            g.max_hops
        )));
    }
    crate::gpu::passes::gates_params::check_walk_limit(g)
}

/// The pass table of a GPU frame: a row per pass that ran (GPU time from timestamp queries,
/// or CPU wall time where the adapter has none), the readback, the frame, the light lists.
pub fn pass_table(t: &PassTimes) -> String {
    let mut s = String::from("pass                               GPU (ms)   CPU wall (ms)\n");
    let ms = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{:.2}", v * 1e3));
    for (name, gpu, cpu) in t.by_name() {
        s += &format!("  {name:<33}{:>8}{:>16}\n", ms(gpu), ms(cpu));
    }
    s += &format!(
        "  {:<33}{:>8}{:>16.2}\n",
        "readback (wait)",
        "-",
        t.readback_s * 1e3
    );
    s += &format!(
        "  {:<33}{:>8}{:>16.2}\n",
        "frame",
        ms(t.gpu_total()),
        t.frame_s * 1e3
    );
    if let Some(v) = t.vals {
        s += &match v.converged {
            true => format!(
                "VAL clustering: {} of {} VALs hold VPLs, converged after {} of at most {} \
                 iterations\n",
                v.live, v.count, v.iterations, v.max
            ),
            false => format!(
                "VAL clustering: {} of {} VALs hold VPLs, not converged in {} iterations (raise \
                 --val-iterations)\n",
                v.live, v.count, v.max
            ),
        };
    }
    let clustered = [
        (
            "LightCluster",
            "lights",
            "culled by range",
            t.direct_clusters,
        ),
        (
            "VPL clusters",
            "VPLs",
            "of no flux left out",
            t.vpl_clusters,
        ),
    ];
    for (what, items, dropped, counts) in clustered {
        if let Some(c) = counts {
            s += &format!(
                "{what}: {} {items} in {} clusters (cube shadow maps), {} {dropped}\n",
                c.lights - c.culled,
                c.clusters,
                c.culled
            );
        }
    }
    if t.passes.iter().all(|p| p.gpu_s.is_none()) {
        s += "(no timestamp queries used on this adapter — none, or a CPU one's, which are \
              wrong for compute passes: each pass was submitted and waited for alone, for its CPU \
              wall time)\n";
    }
    if let Some(st) = t.starved {
        s += &format!(
            "starved pixels: {} walked the subsets of their block's other taps themselves, {} \
             (pixel, subset) pairs (list of {}, {:.1} % used)\n",
            st.pixels,
            st.pairs,
            st.capacity,
            st.pairs as f64 / f64::from(st.capacity.max(1)) * 100.0
        );
    }
    if let Some(r) = t.ratio {
        s += &format!(
            "ratio estimator: unshadowed light summed at {} grid pixels (every {} px) and {} \
             between them ({:.1} % of {} pixels) off their grid pixels' surface, the rest \
             bilinear\n",
            r.grid,
            r.stride,
            r.own,
            f64::from(r.own) / f64::from(r.pixels.max(1)) * 100.0,
            r.pixels
        );
    }
    if let Some(l) = t.lists {
        s += &format!(
            "light lists: {} geometry clusters, {} entries ({:.1} per cluster), pool {} entries \
             ({:.1} % used)\n",
            l.geometry_clusters,
            l.entries,
            l.entries as f64 / l.geometry_clusters.max(1) as f64,
            l.capacity,
            l.entries as f64 / l.capacity.max(1) as f64 * 100.0
        );
        s += &format!(
            "outside every visibility cluster (light unoccluded there): {} pixels, {} VPLs\n",
            l.pixels_outside, l.vpls_outside
        );
    }
    s
}
