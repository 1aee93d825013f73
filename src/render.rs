//! `visgate render` and `visgate diff`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use visgate_formats::ImportOptions;
use visgate_runtime::camera::View;
use visgate_runtime::clustered::ClusterParams;
use visgate_runtime::gates::{GateLevel, GateParams};
use visgate_runtime::gpu::{GpuContext, GpuMode, GpuParams, GpuRenderer, PassTimes};
use visgate_runtime::hdr::{HdrImage, false_colour};
use visgate_runtime::metrics::{errors, flip};
use visgate_runtime::reference::{IndirectVisibility, ReferenceParams, render_with};
use visgate_runtime::tracer::Tracer;
use visgate_runtime::val::ValParams;
use visgate_runtime::vpl::{GatherParams, PathParams, path_vpls};

pub const RENDER_HELP: &str = "\
Modes:
  reference    CPU: direct light with shadow rays + every VPL with a shadow ray per pixel
               sample (exact visibility)
  none         GPU: direct light with shadow maps (PCF) + every VPL lighting every point (no
               indirect shadows: the baseline that gates and virtual area lights improve on)
  per-vpl-shadow-maps
               GPU: one paraboloid shadow map per VPL, rendered and gathered in batches of
               --vpl-batch (the brute-force baseline that gates and virtual area lights beat)
  gates        GPU: a VPL lights a point of another visibility cluster only through a chain
               of at most --gate-hops gate disks (× --gate-oversize) of the baked --level, by
               clustered shading (the paper's Table I passes: geometry pass, unique clusters
               of --tile-px tiles × --depth-slices slices × visibility cluster, light
               assignment into a pool of --light-entries, indirect lighting); GPU: ≤ 2 hops;
               --cpu: the CPU twin, per point
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
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum VplSource {
    /// Light paths traced on the CPU (any number of bounces).
    Paths,
    /// Reflective shadow maps of the lights, sampled at Halton points on the GPU (one bounce).
    Rsm,
}

/// Indirect-light visibility.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Mode {
    /// Exact: a shadow ray per VPL and sample.
    Reference,
    /// No visibility on indirect light.
    None,
    /// One paraboloid shadow map per VPL (GPU, in batches).
    PerVplShadowMaps,
    /// Visibility through the gates of a baked level by clustered shading (needs --level).
    Gates,
    /// The gate test brute force, every pixel against every VPL (GPU; needs --level).
    GatesPerPixel,
    /// Every VPL through one hard shadow map of its virtual area light (GPU).
    ValHard,
    /// Every VPL through the convolution soft shadow map of its virtual area light (GPU).
    ValCssm,
    /// Direct light only.
    DirectOnly,
}

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// The scene: a .toml, .obj, .gltf/.glb file or builtin:NAME.
    pub scene: String,
    /// Camera by name (default: the scene's first camera).
    #[arg(long)]
    pub camera: Option<String>,
    /// Visibility of indirect light.
    #[arg(long, value_enum, default_value_t = Mode::Reference)]
    pub mode: Mode,
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
    /// Upper bound of the VPL geometry term cos·cos/d², 1/m² (against spikes near VPLs).
    #[arg(long, default_value_t = 10.0)]
    pub g_max: f32,
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
    /// Gate disks are this many times their baked radius (--mode gates).
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
    /// Capacity of the light-list pool (--mode gates), entries of 8 bytes; a frame that needs
    /// more stops with the count it needs.
    #[arg(long, default_value_t = 1 << 23)]
    pub light_entries: u32,
    /// Virtual area lights (--mode val-hard): the VPLs are clustered into this many.
    #[arg(long, default_value_t = 30)]
    pub vals: u32,
    /// k-means iterations of the VAL clustering.
    #[arg(long, default_value_t = 8)]
    pub val_iterations: u32,
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
    /// VAL modes: interleaved sampling in blocks of this side (each pixel lights itself with
    /// one of side² VPL subsets, then a geometry-aware blur over the block); 1: every VPL
    /// at every pixel.
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

pub fn run(args: RenderArgs) -> Result<()> {
    let size = parse_size(&args.size)?;
    if !matches!(
        args.out.extension().and_then(|e| e.to_str()),
        Some("exr" | "png")
    ) {
        bail!(
            "--out {}: write .exr (linear radiance) or .png (sRGB)",
            args.out.display()
        );
    }
    if args.frames == 0 {
        bail!("--frames 0: render at least 1 frame");
    }
    if !(args.fps.is_finite() && args.fps > 0.0) {
        bail!("--fps {}: give a number of frames per second > 0", args.fps);
    }
    if !args.time.is_finite() {
        bail!("--time {}: give a finite time in seconds", args.time);
    }
    if args.threads == Some(0) {
        bail!("--threads 0: give at least 1 thread, or leave it out to use all cores");
    }
    let gated = matches!(args.mode, Mode::Gates | Mode::GatesPerPixel);
    if gated && args.level.is_none() {
        bail!(
            "--mode {} needs --level LEVEL.vgate (bake one with `visgate bake SCENE -o LEVEL.vgate`)",
            if args.mode == Mode::Gates {
                "gates"
            } else {
                "gates-per-pixel"
            }
        );
    }
    if args.mode == Mode::GatesPerPixel && args.cpu {
        bail!("--mode gates-per-pixel runs on the GPU; the CPU twin is --mode gates --cpu");
    }
    if matches!(args.mode, Mode::ValHard | Mode::ValCssm) && args.cpu {
        bail!("the VAL modes run on the GPU; their reference is --mode reference");
    }
    let oversize_ok = args.gate_oversize > 0.0 && args.gate_oversize.is_finite();
    if !oversize_ok || !(1..=16).contains(&args.gate_hops) {
        bail!(
            "--gate-oversize {} must be > 0 and --gate-hops {} 1..=16",
            args.gate_oversize,
            args.gate_hops
        );
    }
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
    let camera = match &args.camera {
        Some(name) => scene.camera(name).cloned().with_context(|| {
            let names: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
            format!(
                "{}: no camera '{name}'; its cameras are: {}",
                args.scene,
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )
        })?,
        None => scene.cameras.first().cloned().with_context(|| {
            format!(
                "{}: the scene has no camera; add a [[camera]] to its TOML (see README)",
                args.scene
            )
        })?,
    };
    if scene.lights.is_empty() {
        tracing::warn!(
            "{}: the scene has no lights; the image is black",
            args.scene
        );
    }
    let view = View::new(&camera, size)?;
    let rest = &scene;
    pool.install(|| -> Result<()> {
        if args.vpl_source == VplSource::Rsm && args.bounces != 1 {
            bail!(
                "--vpl-source rsm gives one bounce; use --vpl-source paths for --bounces {}",
                args.bounces
            );
        }
        let on_gpu = args.mode != Mode::Reference && !args.cpu;
        let t = Instant::now();
        let first = rest.at(args.time);
        let gpu_ctx = if on_gpu || args.vpl_source == VplSource::Rsm {
            Some(GpuContext::new()?)
        } else {
            None
        };
        let mut gpu = match &gpu_ctx {
            Some(ctx) => Some(GpuRenderer::new(ctx, &first)?),
            None => None,
        };
        let gate_level = match (&args.level, gated) {
            (Some(path), true) => {
                let level = visgate_formats::BakedLevel::read(path)
                    .with_context(|| format!("cannot read the level {}", path.display()))?;
                Some(GateLevel::new(level, rest)?)
            }
            _ => None,
        };
        if let (Some(ctx), Some(gpu), Some(level)) = (&gpu_ctx, &mut gpu, &gate_level) {
            gpu.set_level(ctx, level)?;
        }
        let setup_s = t.elapsed().as_secs_f64();
        for frame in 0..args.frames {
            let time = args.time + frame as f64 / args.fps;
            let scene = if frame == 0 { first.clone() } else { rest.at(time) };
            let out = frame_path(&args.out, frame, args.frames);
            if args.frames > 1 {
                println!("frame {} of {} at t = {time:.3} s", frame + 1, args.frames);
            }
            let t = Instant::now();
            let tracer = Tracer::new(&scene);
            let bvh_s = t.elapsed().as_secs_f64();
            let t = Instant::now();
            if let (Some(ctx), Some(g), true) = (&gpu_ctx, &mut gpu, frame > 0) {
                g.set_scene(ctx, &scene);
            }
            let vpls = match (args.mode, args.vpl_source, &gpu_ctx, &gpu) {
                (Mode::DirectOnly, _, _, _) => Vec::new(),
                (_, VplSource::Rsm, Some(ctx), Some(g)) => {
                    g.rsm_vpls(ctx, args.vpls, args.rsm_size, args.seed)?
                }
                _ => path_vpls(
                    &tracer,
                    &scene.lights,
                    &PathParams {
                        paths: args.vpls,
                        bounces: args.bounces,
                        seed: args.seed,
                    },
                )?,
            };
            let vpl_s = t.elapsed().as_secs_f64();
            if let (true, Some(ctx), Some(gpu)) = (on_gpu, &gpu_ctx, &mut gpu) {
                let (img, times) = gpu.render(
                    ctx,
                    &view,
                    &vpls,
                    &GpuParams {
                        mode: match args.mode {
                            Mode::None => GpuMode::None,
                            Mode::PerVplShadowMaps => GpuMode::PerVplShadowMaps,
                            Mode::Gates => GpuMode::Gates,
                            Mode::GatesPerPixel => GpuMode::GatesPerPixel,
                            Mode::ValHard => GpuMode::ValHard,
                            Mode::ValCssm => GpuMode::ValCssm,
                            _ => GpuMode::DirectOnly,
                        },
                        clusters: ClusterParams {
                            tile_px: args.tile_px,
                            depth_slices: args.depth_slices,
                        },
                        light_entries: args.light_entries,
                        vals: ValParams {
                            count: args.vals,
                            iterations: args.val_iterations,
                            ..ValParams::default()
                        },
                        val_map_size: args.val_map_size,
                        cssm_terms: args.cssm_terms,
                        cssm_normal_offset: args.cssm_normal_offset,
                        interleave: args.interleave,
                        blur_distance: args.blur_distance,
                        blur_normal: args.blur_normal,
                        gates: GateParams {
                            oversize: args.gate_oversize,
                            max_hops: args.gate_hops,
                        },
                        vpl_map_size: args.vpl_map_size,
                        vpl_batch: args.vpl_batch,
                        g_max: args.g_max,
                        shadow_size: args.shadow_size,
                        ..GpuParams::default()
                    },
                )?;
                img.write(&out, args.exposure)?;
                println!(
                    "{} {:?} {}x{} on {} ({:?}): {} VPLs ({:?}, {} asked, {} bounce(s))",
                    scene.name,
                    args.mode,
                    size[0],
                    size[1],
                    ctx.adapter_info.name,
                    ctx.adapter_info.backend,
                    vpls.len(),
                    args.vpl_source,
                    args.vpls,
                    args.bounces
                );
                println!(
                    "times: load {load_s:.3} s, adapter + upload + level {setup_s:.3} s, BVH {bvh_s:.3} s, \
                     geometry + VPLs {vpl_s:.3} s"
                );
                print_passes(&times, args.mode);
                let m = img.mean();
                println!("mean radiance {:.5} {:.5} {:.5}", m.x, m.y, m.z);
                println!("wrote {}", out.display());
                continue;
            }
            let params = ReferenceParams {
                samples_per_pixel: args.spp,
                direct: true,
                indirect: args.mode != Mode::DirectOnly,
                indirect_visibility: matches!(args.mode, Mode::Reference | Mode::PerVplShadowMaps),
                gather: GatherParams { g_max: args.g_max },
            };
            let bar = ProgressBar::new(size[1] as u64).with_style(
                ProgressStyle::with_template("render {bar:40} {pos}/{len} rows {elapsed}<{eta}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            let vis = match &gate_level {
                Some(g) => IndirectVisibility::Gates(
                    g,
                    GateParams {
                        oversize: args.gate_oversize,
                        max_hops: args.gate_hops,
                    },
                ),
                None if params.indirect_visibility => IndirectVisibility::Exact,
                None => IndirectVisibility::Unoccluded,
            };
            let (img, stats) = render_with(
                &tracer,
                &scene.lights,
                &vpls,
                &view,
                &params,
                vis,
                &|done, _| bar.set_position(done as u64),
            )?;
            bar.finish_and_clear();
            img.write(&out, args.exposure)?;
            println!(
                "{} {:?} {}x{} spp {}: {} triangles, {} VPLs ({:?}, {} asked, {} bounce(s))",
                scene.name,
                args.mode,
                size[0],
                size[1],
                args.spp,
                tracer.triangle_count(),
                vpls.len(),
                args.vpl_source,
                args.vpls,
                args.bounces
            );
            println!(
                "times (CPU): load {load_s:.3} s, BVH {bvh_s:.3} s, VPLs {vpl_s:.3} s, render {:.3} s",
                stats.seconds
            );
            if stats.shadow_rays > 0 {
                println!(
                    "shadow rays {} ({:.2} M/s), camera rays {}",
                    stats.shadow_rays,
                    stats.shadow_rays as f64 / stats.seconds.max(1e-9) / 1e6,
                    stats.camera_rays
                );
            }
            let m = img.mean();
            println!("mean radiance {:.5} {:.5} {:.5}", m.x, m.y, m.z);
            println!("wrote {}", out.display());
        }
        Ok(())
    })
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

/// Prints the passes that ran (named as the paper's Table I in mode gates), each with its CPU
/// wall time and, where the adapter has timestamp queries, its GPU time.
fn print_passes(t: &PassTimes, mode: Mode) {
    let g = t.gpu.unwrap_or_default();
    let shading = match mode {
        Mode::Gates | Mode::GatesPerPixel | Mode::None => "shading: direct + indirect lighting",
        _ => "shading: direct lighting",
    };
    let mut rows = vec![
        ("shadow maps", t.shadows, g.shadows),
        ("geometry pass (G-buffer)", t.gbuffer, g.gbuffer),
    ];
    if mode == Mode::Gates {
        rows.push(("unique clusters", t.unique_clusters, g.unique_clusters));
        rows.push(("light assignment", t.light_assignment, g.light_assignment));
    }
    rows.push((shading, t.shade, g.shade));
    if mode == Mode::PerVplShadowMaps {
        rows.push(("VPL paraboloid maps", t.vpl_maps, g.vpl_maps));
        rows.push(("VPL gather", t.vpl_gather, g.vpl_gather));
    }
    if matches!(mode, Mode::ValHard | Mode::ValCssm) {
        rows.push(("VAL clustering", t.val_clustering, g.val_clustering));
        rows.push(("VAL paraboloid maps", t.vpl_maps, g.vpl_maps));
        if mode == Mode::ValCssm {
            rows.push(("CSSM basis + mips", t.cssm, g.cssm));
        }
        rows.push(("indirect lighting", t.vpl_gather, g.vpl_gather));
        rows.push(("blur + compose", t.blur, g.blur));
    }
    println!("pass                               CPU wall (ms)   GPU (ms)");
    for (name, cpu, gpu) in rows {
        match t.gpu {
            Some(_) => println!("  {name:<33}{:>12.2}{:>11.2}", cpu * 1e3, gpu * 1e3),
            None => println!("  {name:<33}{:>12.2}          -", cpu * 1e3),
        }
    }
    println!("  {:<33}{:>12.2}", "readback", t.readback * 1e3);
    if t.gpu.is_none() {
        println!("(the adapter has no timestamp queries: no GPU times)");
    }
    if let Some(l) = t.lists {
        println!(
            "light lists: {} geometry clusters, {} entries ({:.1} per cluster), pool {} \
             entries ({:.1} % used)",
            l.geometry_clusters,
            l.entries,
            l.entries as f64 / l.geometry_clusters.max(1) as f64,
            l.capacity,
            l.entries as f64 / l.capacity.max(1) as f64 * 100.0
        );
    }
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
