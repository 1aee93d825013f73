//! `visgate render` and `visgate diff`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use visgate_formats::ImportOptions;
use visgate_runtime::cpu::clustered::ClusterParams;
use visgate_runtime::cpu::gates::{GateLevel, GateParams, GateShape};
use visgate_runtime::cpu::val::ValParams;
use visgate_runtime::gpu::{
    CssmParams, GatesParams, GpuMode, GpuParams, InterleaveParams, METHODS, MethodSettings,
    PerVplParams, ShadowParams, ValModeParams, method,
};
use visgate_runtime::hdr::{HdrImage, false_colour};
use visgate_runtime::job::{
    FrameStats, JobFrame, RenderJob, Renderer, VplSource as JobVpls, pass_table,
};
use visgate_runtime::metrics::{errors, flip};
use visgate_runtime::vpl::GeometryClamp;

pub const RENDER_HELP: &str = "\
Modes:
  reference    CPU: direct light with shadow rays + every VPL with a shadow ray per pixel
               sample (exact visibility)
  none         GPU: direct light with shadow maps (PCF) + every VPL lighting every point (no
               indirect shadows: the baseline that gates and virtual area lights improve on)
  per-vpl-shadow-maps
               GPU: one paraboloid shadow map per VPL, rendered and gathered in batches of
               --vpl-batch (the brute-force baseline that gates and virtual area lights beat)
  gates        GPU: a VPL lights a point of another visibility cluster only through the
               baked --level's portals (--gate-shape portal, the default: the segment walks
               from cluster to cluster through the openings, at most --max-walk of them) or
               a chain of at most --gate-hops gate disks (× --gate-oversize; --gate-shape
               disk, the paper's), by
               clustered shading (the paper's Table I passes: geometry pass, unique clusters
               of --tile-px tiles × --depth-slices slices × visibility cluster, light
               assignment into a pool of --light-entries, indirect lighting); GPU: ≤ 2 hops;
               --cpu: the CPU twin, per point. Pixels and VPLs outside every visibility
               cluster are not occluded (the pass report counts them)
  gates-per-pixel
               GPU: the same gate test, brute force (every pixel tests every VPL)
  val-hard     GPU: the VPLs clustered into --vals virtual area lights (k-means by position
               and normal, --val-iterations, restarted each frame); every VPL lights every
               pixel through one hard paraboloid shadow map (--val-map-size) of its VAL (the
               banding baseline of Dong et al.; no bake needed)
  val-cssm     GPU: as val-hard with convolution soft shadow maps per VAL (Dong et al.):
               --cssm-terms Fourier terms of the depth, mip-mapped, filtered over the
               penumbra each VAL's size and the average blocker depth give
  direct-only  GPU: direct light alone
With --cpu, none and direct-only run on the CPU twin (shadow rays for direct light), and
per-vpl-shadow-maps is the reference (exact shadow rays).

VPLs come from light paths traced from the scene's lights on the CPU (--vpl-source paths:
--bounces generations, a VPL at every hit) or from the lights' reflective shadow maps sampled at
Halton points on the GPU (--vpl-source rsm: one bounce), deterministic for a --seed. Output: .exr is linear radiance (W/(m²·sr), for `visgate diff`),
.png is sRGB at --exposure stops.

Dynamic scenes: a scene file's dynamic meshes and lights may move (keyframes or orbits, see
the README); --time poses the scene, --frames/--fps render a sequence. The VAL modes and the
per-VPL maps follow every change without a bake; the gate modes keep the baked static topology
(dynamic meshes are lit, and shadow direct light, but do not block indirect light there).

Examples:
  visgate render builtin:cornell-box --mode reference --vpls 4096 --out cornell.exr
  visgate render builtin:four-rooms --mode none --size 320x240 --out none.png
  visgate render builtin:four-rooms --mode none --cpu --out none-cpu.exr
  visgate bake builtin:four-rooms -o four-rooms.vgate
  visgate render builtin:four-rooms --mode gates --level four-rooms.vgate --out gates.png
  visgate diff none.exr cornell.exr --out diff.png";

/// Where VPLs come from.
/// `--gate-shape`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum GateShapeArg {
    /// The baked portals (the true openings between clusters), walked along each segment.
    Portal,
    /// The paper's disks, through chains of at most --gate-hops of them.
    Disk,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum VplSource {
    /// Light paths traced on the CPU (any number of bounces).
    Paths,
    /// Reflective shadow maps of the lights, sampled at Halton points on the GPU (one bounce).
    Rsm,
}

/// `--mode`'s values: `reference` and every GPU method of the runtime's registry.
fn mode_names() -> Vec<&'static str> {
    std::iter::once("reference")
        .chain(METHODS.iter().map(|m| m.name))
        .collect()
}

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// The scene: a .toml, .obj, .gltf/.glb file or builtin:NAME.
    pub scene: String,
    /// Camera by name (default: the scene's first camera).
    #[arg(long)]
    pub camera: Option<String>,
    /// Visibility of indirect light (see the list below).
    #[arg(long, default_value = "reference", value_parser = clap::builder::PossibleValuesParser::new(mode_names()))]
    pub mode: String,
    /// Light paths traced from the lights (VPLs: one per path and bounce that hits).
    #[arg(long, default_value_t = 1024)]
    pub vpls: u32,
    /// Where the VPLs come from.
    #[arg(long, value_enum, default_value_t = VplSource::Paths)]
    pub vpl_source: VplSource,
    /// RSM size per layer (cube face or spot), texels, for --vpl-source rsm.
    #[arg(long, default_value_t = 256)]
    pub rsm_size: u32,
    /// VPL generations per path (1: one-bounce indirect light).
    #[arg(long, default_value_t = 1)]
    pub bounces: u32,
    /// Seed of the VPLs' low-discrepancy sequence.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "512x512")]
    pub size: String,
    /// Pixel samples (jittered).
    #[arg(long, default_value_t = 4)]
    pub spp: u32,
    /// Upper bound of the VPL geometry term cos·cos/d², 1/m² (against spikes near VPLs);
    /// absolute, so the image changes with the scene's scale. Default: from --clamp-distance.
    #[arg(long, conflicts_with = "clamp_distance")]
    pub g_max: Option<f32>,
    /// The geometry-term clamp starts at this fraction of the scene's bounding diagonal
    /// (g_max = 1 / (F·diagonal)²): the same image, up to scale, at any scale of the level.
    #[arg(long, default_value_t = 0.025)]
    pub clamp_distance: f32,
    /// Exposure of the PNG, in stops.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub exposure: f32,
    /// Output image: .exr (linear) or .png (sRGB).
    #[arg(long, short)]
    pub out: PathBuf,
    /// Run none/direct-only on the CPU twin instead of the GPU.
    #[arg(long)]
    pub cpu: bool,
    /// Shadow map size per layer (GPU), texels.
    #[arg(long, default_value_t = 1024)]
    pub shadow_size: u32,
    /// The baked level (.vgate) for --mode gates; it must come from this scene's geometry.
    #[arg(long)]
    pub level: Option<PathBuf>,
    /// What a gate is (--mode gates): the baked portals, walked, or the paper's disks.
    #[arg(long, value_enum, default_value_t = GateShapeArg::Portal)]
    pub gate_shape: GateShapeArg,
    /// Portals one walk may pass before it is given up and counted as occluded (--gate-shape
    /// portal), 1..=1024.
    #[arg(long, default_value_t = 64)]
    pub max_walk: u32,
    /// Gate disks are this many times their baked radius (--gate-shape disk).
    #[arg(long, default_value_t = 1.0)]
    pub gate_oversize: f32,
    /// Gates a VPL's light may pass in a chain (--mode gates; the paper: 1).
    #[arg(long, default_value_t = 2)]
    pub gate_hops: u32,
    /// Screen tile side of geometry clusters (--mode gates), pixels, 1..=16 on the GPU.
    #[arg(long, default_value_t = 16)]
    pub tile_px: u32,
    /// Exponential depth slices of geometry clusters (--mode gates), 1..=256.
    #[arg(long, default_value_t = 24)]
    pub depth_slices: u32,
    /// Capacity of the light-list pool (--mode gates with --gate-shape disk; portals keep no
    /// lists: a pixel walks every VPL of its subset), entries of 8 bytes: a frame that needs
    /// more stops with the count it needs. Unset, the pool grows to what a frame needs, up to
    /// the adapter's storage binding limit.
    #[arg(long)]
    pub light_entries: Option<u32>,
    /// Virtual area lights (--mode val-hard): the VPLs are clustered into this many.
    #[arg(long, default_value_t = 30)]
    pub vals: u32,
    /// Most k-means iterations of the VAL clustering (it stops earlier where the assignment
    /// repeats itself; the pass report says whether it converged).
    #[arg(long, default_value_t = 8)]
    pub val_iterations: u32,
    /// Weight of the position term of the VAL clustering distance (the paper: 0.7).
    #[arg(long, default_value_t = 0.7, allow_hyphen_values = true)]
    pub val_w_x: f32,
    /// Weight of the normal-angle term of the VAL clustering distance (the paper: 0.3).
    #[arg(long, default_value_t = 0.3, allow_hyphen_values = true)]
    pub val_w_alpha: f32,
    /// Paraboloid shadow map size per VAL, texels.
    #[arg(long, default_value_t = 256)]
    pub val_map_size: u32,
    /// Fourier terms of the convolution soft shadow maps (--mode val-cssm), 1..=16.
    #[arg(long, default_value_t = 4)]
    pub cssm_terms: u32,
    /// Normal offset of CSSM lookups, texels (slope-scaled up to 2×): larger avoids
    /// self-shadowing under wide filter kernels, smaller keeps contact shadows.
    #[arg(long, default_value_t = 3.0)]
    pub cssm_normal_offset: f32,
    /// VAL modes and gates: interleaved sampling in blocks of this side (each pixel lights
    /// itself with one of side² VPL subsets, then a geometry-aware blur over the block); 1:
    /// every VPL at every pixel (the CPU twins, --cpu, always gather every VPL).
    #[arg(long, default_value_t = 8)]
    pub interleave: u32,
    /// Blur: leave out neighbours farther than this fraction of the scene's size.
    #[arg(long, default_value_t = 0.1)]
    pub blur_distance: f32,
    /// Blur: leave out neighbours whose normals' cosine is below this.
    #[arg(long, default_value_t = 0.8, allow_hyphen_values = true)]
    pub blur_normal: f32,
    /// Per-VPL paraboloid map size (GPU), texels.
    #[arg(long, default_value_t = 128)]
    pub vpl_map_size: u32,
    /// Per-VPL maps rendered and gathered per batch (bounds their memory).
    #[arg(long, default_value_t = 128)]
    pub vpl_batch: u32,
    /// Time of the (first) frame, seconds: dynamic meshes and lights of the scene file are
    /// posed there (their keyframes or orbits).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub time: f64,
    /// Frames to render from --time on, --fps apart; with more than one, OUT gets a frame
    /// number (shot.png → shot-0000.png, shot-0001.png, …).
    #[arg(long, default_value_t = 1)]
    pub frames: u32,
    /// Frames per second of a sequence.
    #[arg(long, default_value_t = 30.0)]
    pub fps: f64,
    /// Rayon threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
}

fn parse_size(s: &str) -> Result<[u32; 2]> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .with_context(|| format!("--size {s}: write WIDTHxHEIGHT, e.g. 512x512"))?;
    let w: u32 = w
        .trim()
        .parse()
        .with_context(|| format!("--size {s}: width is not a number"))?;
    let h: u32 = h
        .trim()
        .parse()
        .with_context(|| format!("--size {s}: height is not a number"))?;
    Ok([w, h])
}

impl RenderArgs {
    /// Interleaving and blur from the flags (VAL modes and gates alike).
    fn interleave_params(&self) -> InterleaveParams {
        InterleaveParams {
            block: self.interleave,
            blur_distance: self.blur_distance,
            blur_normal: self.blur_normal,
        }
    }

    /// Every method's settings from the flags.
    fn settings(&self) -> MethodSettings {
        MethodSettings {
            per_vpl: PerVplParams {
                map_size: self.vpl_map_size,
                batch: self.vpl_batch,
            },
            gates: GatesParams {
                gates: GateParams {
                    oversize: self.gate_oversize,
                    max_hops: self.gate_hops,
                    shape: match self.gate_shape {
                        GateShapeArg::Portal => GateShape::Portal,
                        GateShapeArg::Disk => GateShape::Disk,
                    },
                    max_walk: self.max_walk,
                },
                clusters: ClusterParams {
                    tile_px: self.tile_px,
                    depth_slices: self.depth_slices,
                },
                light_entries: self.light_entries,
                interleave: self.interleave_params(),
            },
            vals: ValModeParams {
                vals: ValParams {
                    count: self.vals,
                    iterations: self.val_iterations,
                    w_x: self.val_w_x,
                    w_alpha: self.val_w_alpha,
                    ..ValParams::default()
                },
                map_size: self.val_map_size,
                interleave: self.interleave_params(),
            },
            cssm: CssmParams {
                terms: self.cssm_terms,
                normal_offset: self.cssm_normal_offset,
                ..CssmParams::default()
            },
        }
    }

    /// The job the flags describe.
    fn job(&self) -> Result<RenderJob> {
        let renderer = match method(&self.mode) {
            None => Renderer::Reference,
            Some(m) if self.cpu => Renderer::CpuTwin((m.make)(&self.settings())),
            Some(m) => Renderer::Gpu((m.make)(&self.settings())),
        };
        Ok(RenderJob {
            renderer,
            params: GpuParams {
                mode: GpuMode::None,
                g_max: GpuParams::default().g_max,
                shadows: ShadowParams {
                    size: self.shadow_size,
                    ..ShadowParams::default()
                },
            },
            clamp: match self.g_max {
                Some(g) => GeometryClamp::PerSquareMetre(g),
                None => GeometryClamp::DiagonalFraction(self.clamp_distance),
            },
            vpls: self.vpls,
            vpl_source: match self.vpl_source {
                VplSource::Paths => JobVpls::Paths,
                VplSource::Rsm => JobVpls::Rsm,
            },
            rsm_size: self.rsm_size,
            bounces: self.bounces,
            seed: self.seed,
            size: parse_size(&self.size)?,
            spp: self.spp,
            time: self.time,
            frames: self.frames,
            fps: self.fps,
        })
    }
}

pub fn run(args: RenderArgs) -> Result<()> {
    let job = args.job()?;
    if !matches!(
        args.out.extension().and_then(|e| e.to_str()),
        Some("exr" | "png")
    ) {
        bail!(
            "--out {}: write .exr (linear radiance) or .png (sRGB)",
            args.out.display()
        );
    }
    if args.threads == Some(0) {
        bail!("--threads 0: give at least 1 thread, or leave it out to use all cores");
    }
    job.check(args.level.is_some())?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("cannot start the thread pool")?;
    let t = Instant::now();
    let scene = crate::load_scene(
        &args.scene,
        &ImportOptions {
            load_textures: true,
        },
    )?;
    let load_s = t.elapsed().as_secs_f64();
    let camera = crate::camera_of(&scene, &args.scene, args.camera.as_deref())?;
    if scene.lights.is_empty() {
        tracing::warn!(
            "{}: the scene has no lights; the image is black",
            args.scene
        );
    }
    let level = match (&args.level, job.mode().and_then(|m| m.gates())) {
        (Some(path), Some(_)) => {
            let level = visgate_formats::BakedLevel::read(path)
                .with_context(|| format!("cannot read the level {}", path.display()))?;
            Some(GateLevel::new(level, &scene)?)
        }
        _ => None,
    };
    let g_max = job.for_scene(&scene)?.params.g_max;
    match job.clamp {
        GeometryClamp::PerSquareMetre(_) => println!("geometry-term clamp g_max {g_max:.4} 1/m²"),
        GeometryClamp::DiagonalFraction(f) => println!(
            "geometry-term clamp g_max {g_max:.4} 1/m² (from {f} of the scene's diagonal: it acts \
             within {:.4} m of a VPL)",
            g_max.powf(-0.5)
        ),
    }
    let bar = ProgressBar::new(job.size[1] as u64).with_style(
        ProgressStyle::with_template("render {bar:40} {pos}/{len} rows {elapsed}<{eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let setup = std::sync::Mutex::new(String::new());
    pool.install(|| {
        job.run(
            &scene,
            &camera,
            level.as_ref(),
            &mut |s| {
                *setup.lock().unwrap_or_else(|e| e.into_inner()) = match &s.adapter {
                    Some(a) => format!("on {a}, adapter + upload + level {:.3} s", s.seconds),
                    None => String::new(),
                };
            },
            &|done, _| bar.set_position(done as u64),
            &mut |f| {
                bar.finish_and_clear();
                let out = frame_path(&args.out, f.index, job.frames);
                if job.frames > 1 {
                    println!(
                        "frame {} of {} at t = {:.3} s",
                        f.index + 1,
                        job.frames,
                        f.time
                    );
                }
                f.image.write(&out, args.exposure)?;
                let setup = setup.lock().unwrap_or_else(|e| e.into_inner()).clone();
                print_frame(&args, &scene.name, &f, load_s, &setup);
                println!("wrote {}", out.display());
                Ok(())
            },
        )
    })?;
    Ok(())
}

/// Prints what a frame was and took.
fn print_frame(args: &RenderArgs, scene: &str, f: &JobFrame, load_s: f64, setup: &str) {
    let [bvh_s, vpl_s] = f.prep_s;
    println!(
        "{scene} {} {}{}: {} VPLs ({:?}, {} asked, {} bounce(s))",
        args.mode,
        args.size,
        match f.stats {
            FrameStats::Gpu(_) => " (GPU)".to_string(),
            FrameStats::Cpu(_) if args.cpu => format!(" spp {} (CPU twin)", args.spp),
            FrameStats::Cpu(_) => format!(" spp {} (CPU)", args.spp),
        },
        f.vpl_count,
        args.vpl_source,
        args.vpls,
        args.bounces
    );
    println!("times: load {load_s:.3} s, BVH {bvh_s:.3} s, VPLs {vpl_s:.3} s {setup}");
    match &f.stats {
        FrameStats::Gpu(t) => print!("{}", pass_table(t)),
        FrameStats::Cpu(stats) => {
            println!("render (CPU) {:.3} s", stats.seconds);
            if stats.shadow_rays > 0 {
                println!(
                    "shadow rays {} ({:.2} M/s), camera rays {}",
                    stats.shadow_rays,
                    stats.shadow_rays as f64 / stats.seconds.max(1e-9) / 1e6,
                    stats.camera_rays
                );
            }
        }
    }
    let m = f.image.mean();
    println!("mean radiance {:.5} {:.5} {:.5}", m.x, m.y, m.z);
}

/// The output of frame `frame` of `frames`: OUT itself for one frame, else OUT's stem with a
/// four-digit frame number (`shot.png` → `shot-0000.png`, `shot-0001.png`, …).
fn frame_path(out: &std::path::Path, frame: u32, frames: u32) -> PathBuf {
    if frames <= 1 {
        return out.to_path_buf();
    }
    let stem = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = out
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    out.with_file_name(format!("{stem}-{frame:04}.{ext}"))
}

#[derive(Debug, Args)]
pub struct DiffArgs {
    /// The image to judge (.exr).
    pub image: PathBuf,
    /// The reference (.exr).
    pub reference: PathBuf,
    /// Write the FLIP error map, false-coloured (black 0 … white 1), as a PNG.
    #[arg(long, short)]
    pub out: Option<PathBuf>,
    /// Exposure both are tone mapped at for FLIP, in stops.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub exposure: f32,
}

pub fn diff(args: DiffArgs) -> Result<()> {
    let a = HdrImage::read(&args.image)?;
    let r = HdrImage::read(&args.reference)?;
    let e = errors(&a, &r)?;
    let (f, map) = flip(&a, &r, args.exposure)?;
    println!("image      {}", args.image.display());
    println!("reference  {}", args.reference.display());
    println!("MSE        {:.6e}", e.mse);
    println!("rel. MSE   {:.6e}", e.rel_mse);
    println!(
        "FLIP mean  {f:.5}  (LDR-FLIP at exposure {})",
        args.exposure
    );
    println!(
        "mean       {:.6e} vs {:.6e} ({:+.2} %)",
        e.image_mean,
        e.reference_mean,
        100.0 * (e.image_mean / e.reference_mean.max(f64::MIN_POSITIVE) - 1.0)
    );
    if let Some(out) = &args.out {
        false_colour(&map, a.width, a.height, 1.0)
            .save(out)
            .with_context(|| format!("cannot write {}", out.display()))?;
        println!("wrote {}", out.display());
    }
    Ok(())
}
