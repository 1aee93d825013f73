//! `visgate render` and `visgate diff`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};

use crate::settings::{LightArgs, MethodArgs};
use visgate_runtime::cpu::gates::GateLevel;
use visgate_runtime::gpu::{METHODS, method};
use visgate_runtime::hdr::{HdrImage, false_colour};
use visgate_runtime::job::{FrameStats, JobFrame, RenderJob, Renderer, pass_table};
use visgate_runtime::metrics::{errors, flip, indirect_map, rebase_direct};
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
  per-vpl-ism  GPU: an imperfect shadow map per VPL (Ritschel et al.): the scene as
               --ism-points random points a map, splatted as surfels into one atlas of
               --ism-map-size² paraboloid maps, holes filled by --ism-pull-push levels; one
               hard lookup per VPL (the cheap twin of per-vpl-shadow-maps)
  gates        GPU: a VPL lights a point along the baked --level's open voxels
               (--gate-shape voxels, the default; in the balanced setting, the default,
               blocked only where the true segment hits a triangle in a closed voxel,
               near-exact, with a tent blur and the dark pixels walking what their block
               lacks; --fast passes a closed voxel on its one or two planes with the box
               blur, 1.2-2.5x faster on lavapipe and darker where columns or curtains
               graze the light's paths; --accurate walks more pixels), or only through
               its portals when the point lies in another visibility cluster
               (--gate-shape portal: the segment walks from cluster to cluster through the
               openings, at most --max-walk of them), or through a chain of at most --gate-hops gate disks
               (× --gate-oversize; --gate-shape disk, the paper's), by clustered shading
               (the paper's Table I passes: geometry pass, unique clusters of --tile-px
               tiles × --depth-slices slices × visibility cluster, light assignment into a
               pool of --light-entries, indirect lighting); GPU: ≤ 2 hops;
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
  val-ism      GPU: virtual area lights with imperfect shadow maps and PCSS
               (Weinzierl-Heigl): the VPLs clustered into --ism-vals VALs (Halton seeds warped
               by flux, position/normal/flux metric, point splats, iterated frame to frame),
               each VAL a disk lighting through the point-to-disk form factor
               (--ism-val-disk), its visibility PCSS on its ISM (--pcss-*, or
               --ism-hard-lookups) over a --ism-interleave split G-buffer and the blur
  vpl-clusters GPU: the VPLs clustered as LightCluster clusters lights (--lc-min-distance,
               --lc-distance-scale, --lc-max-clusters; beyond its paper): a cube shadow map
               per cluster (--lc-map-size), every VPL shadowed by its cluster's PCSS soft
               shadow (--pcss-*), interleaved and blurred as the VAL modes (--interleave;
               1: every VPL at every pixel; at most 16,384 VPLs)
  direct-only  GPU: direct light alone
Direct light (GPU, every mode): --direct per-light shadows each light with its own cube or spot
maps (exact hard shadows); --direct lightcluster clusters the lights in view each frame
(LightCluster: --lc-min-distance metres between cluster centres at the eye, growing by
--lc-distance-scale per metre of distance, at most --lc-max-clusters; lights whose range misses
the view are culled), renders one cube map per cluster and a PCSS soft shadow per cluster, its
disk's radius its lights' extent (--lc-disk). The pass report names each pass and counts the
clusters.
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
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "512x512")]
    pub size: String,
    /// Exposure of the PNG, in stops.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub exposure: f32,
    /// Output image: .exr (linear) or .png (sRGB).
    #[arg(long, short)]
    pub out: PathBuf,
    /// Run none/direct-only on the CPU twin instead of the GPU.
    #[arg(long)]
    pub cpu: bool,
    /// The baked level (.vgate) for --mode gates; it must come from this scene's geometry.
    #[arg(long)]
    pub level: Option<PathBuf>,
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
    /// GPU frames rendered and dropped before the one kept, so that its pass times are of a
    /// warm device (pipelines compiled, light-list pools grown).
    #[arg(long, default_value_t = 0)]
    pub warmup: u32,
    #[command(flatten)]
    pub light: LightArgs,
    #[command(flatten)]
    pub method: MethodArgs,
}

pub fn parse_size(s: &str) -> Result<[u32; 2]> {
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
    /// The job the flags describe.
    fn job(&self) -> Result<RenderJob> {
        let renderer = match method(&self.mode) {
            None => Renderer::Reference,
            Some(m) if self.cpu => Renderer::CpuTwin((m.make)(&self.method.settings())),
            Some(m) => Renderer::Gpu((m.make)(&self.method.settings())),
        };
        Ok(RenderJob {
            renderer,
            vpls: self.vpls,
            size: parse_size(&self.size)?,
            time: self.time,
            frames: self.frames,
            fps: self.fps,
            warmup: self.warmup,
            ..self.light.job(&self.method)
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
    crate::writable(&args.out, "--out")?;
    job.check(args.level.is_some())?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("cannot start the thread pool")?;
    let t = Instant::now();
    let mut scene = crate::load_scene(&args.scene, true)?;
    let load_s = t.elapsed().as_secs_f64();
    let baked = match &args.level {
        Some(path) => Some(
            visgate_formats::BakedLevel::read(path)
                .with_context(|| format!("cannot read the level {}", path.display()))?,
        ),
        None => None,
    };
    crate::bare::light_if_bare(&mut scene, &args.scene);
    let camera = crate::camera_of(&scene, &args.scene, args.camera.as_deref())?;
    if scene.lights.is_empty() {
        tracing::warn!(
            "{}: the scene has no lights; the image is black",
            args.scene
        );
    }
    let level = match (baked, job.mode().and_then(|m| m.gates())) {
        (Some(level), Some(_)) => Some(GateLevel::new(level, &scene)?),
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
    // The method the frames run (the job's, or the walk that took its place: JobSetup::mode).
    let ran = std::sync::Mutex::new(job.mode());
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
                *ran.lock().unwrap_or_else(|e| e.into_inner()) = s.mode;
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
                let ran = *ran.lock().unwrap_or_else(|e| e.into_inner());
                let described = ran.map(|m| m.describe_for(f.vpl_count as u32));
                let described = described.unwrap_or_default();
                print_frame(&args, (&scene.name, &described), &f, load_s, &setup);
                println!("wrote {}", out.display());
                Ok(())
            },
        )
    })?;
    Ok(())
}

/// Prints what a frame was (the scene's name and the method's settings in words) and took.
fn print_frame(
    args: &RenderArgs,
    (scene, described): (&str, &str),
    f: &JobFrame,
    load_s: f64,
    setup: &str,
) {
    let [bvh_s, vpl_s] = f.prep_s;
    let mode = if described.is_empty() {
        args.mode.to_string()
    } else {
        format!("{} ({described})", args.mode)
    };
    println!(
        "{scene} {mode} {}{}: {} VPLs ({:?}, {} asked, {} bounce(s))",
        args.size,
        match f.stats {
            FrameStats::Gpu(_) => " (GPU)".to_string(),
            FrameStats::Cpu(_) if args.cpu => format!(" spp {} (CPU twin)", args.light.spp),
            FrameStats::Cpu(_) => format!(" spp {} (CPU)", args.light.spp),
        },
        f.vpl_count,
        args.light.vpl_source,
        args.vpls,
        args.light.bounces
    );
    if args.vpls > 0 && f.vpl_count == 0 && args.mode != "direct-only" {
        let what =
            visgate_runtime::vpl::no_light_paths(args.vpls, "the image has no indirect light");
        eprintln!("warning: {what}");
    }
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
    if m.max_element() <= 0.0 {
        eprintln!(
            "warning: the image is black: no light reaches what the camera sees (a light inside \
             closed geometry such as a lamp's shade, a light or camera outside the level, or a \
             camera facing away from every lit surface). `visgate bake` names lights inside \
             closed geometry"
        );
    }
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
    /// The reference's direct light alone (.exr): also print the indirect energy ratio and the
    /// share of pixels black where the reference's indirect light is. It must come from the
    /// reference's own renderer: `render --mode direct-only --cpu` (rays) for `render`'s
    /// reference, `renders/CAMERA/direct-cpu.exr` (the CPU twin's shadow maps) for `visgate
    /// compare`'s. Another's shadow edges stay in the indirect light: on a level lit mostly
    /// directly the energy ratio reads far from 1 (LibreQuake e2m3's hall at 4,096 VPLs: 0.05
    /// instead of 1.00).
    #[arg(long)]
    pub direct: Option<PathBuf>,
    /// The image's own direct light (.exr, e.g. `render --mode direct-only`), taken out of it
    /// instead of --direct's (GPU shadow maps and CPU rays differ a little at shadow edges).
    #[arg(long, requires = "direct")]
    pub image_direct: Option<PathBuf>,
    /// Write where the image is black where the reference is lit indirectly, as a PNG: red
    /// there, grey where the reference's indirect light counts, dark grey where it does not.
    #[arg(long, requires = "direct")]
    pub black_map: Option<PathBuf>,
    /// The pixels to leave out of black where lit, white in a PNG of the images' size: `visgate
    /// compare`'s `renders/CAMERA/mixed.png` (those whose reference samples see several
    /// surfaces or albedos), so that the figure is compare's; the share over every pixel is
    /// printed too.
    #[arg(long, requires = "direct")]
    pub mixed: Option<PathBuf>,
}

/// Refuses an image `diff` would misread: it measures linear radiance, which an .exr holds (a
/// .png holds sRGB-encoded 8-bit values, which it would take for radiance; another file is no
/// image at all).
fn linear_exr(what: &str, path: Option<&PathBuf>) -> Result<()> {
    match path {
        Some(p) if p.extension().and_then(|e| e.to_str()) != Some("exr") => bail!(
            "{what} {}: diff reads linear .exr images (render one with --out NAME.exr)",
            p.display()
        ),
        _ => Ok(()),
    }
}

pub fn diff(args: DiffArgs) -> Result<()> {
    let named = [
        ("IMAGE", Some(&args.image)),
        ("REFERENCE", Some(&args.reference)),
    ];
    let flags = [
        ("--direct", args.direct.as_ref()),
        ("--image-direct", args.image_direct.as_ref()),
    ];
    for (what, path) in named.into_iter().chain(flags) {
        linear_exr(what, path)?;
    }
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
    if let Some(d) = &args.direct {
        let direct = HdrImage::read(d)?;
        let own = match &args.image_direct {
            Some(p) => rebase_direct(&a, &HdrImage::read(p)?, &direct)?,
            None => a.clone(),
        };
        let mut map = indirect_map(&own, &r, &direct)?;
        if let Some(p) = &args.mixed {
            let mask = image::open(p)
                .with_context(|| format!("cannot read the mixed pixels {}", p.display()))?
                .to_luma8();
            if mask.dimensions() != (a.width, a.height) {
                bail!(
                    "{} is {}x{}, the images {}x{}",
                    p.display(),
                    mask.width(),
                    mask.height(),
                    a.width,
                    a.height
                );
            }
            map = map.leave_out_mixed(mask.pixels().map(|q| q.0[0] > 127).collect())?;
        }
        let i = map.errors();
        if let Some(out) = &args.black_map {
            map.to_image(a.width, a.height)
                .save(out)
                .with_context(|| format!("cannot write {}", out.display()))?;
            println!("wrote {}", out.display());
        }
        if args.image_direct.is_some() {
            println!(
                "indirect MSE     {:.6e}  (its direct light replaced by the reference's)",
                errors(&own, &r)?.mse
            );
        }
        println!(
            "indirect energy  {:.6}  (mean indirect light over the reference's)",
            i.energy_ratio
        );
        match &args.mixed {
            Some(p) => println!(
                "black where lit  {:.6} %  (of the {} pixels the reference lights indirectly, \
                 those white in {} left out; {:.6} % over every pixel)",
                i.black_where_lit * 100.0,
                i.lit_pixels,
                p.display(),
                i.black_where_lit_all * 100.0
            ),
            None => println!(
                "black where lit  {:.6} %  (of the {} pixels the reference lights indirectly, \
                 every pixel counted: compare leaves out those whose reference samples see \
                 several surfaces or albedos, --mixed)",
                i.black_where_lit * 100.0,
                i.lit_pixels
            ),
        }
    }
    if let Some(out) = &args.out {
        false_colour(&map, a.width, a.height, 1.0)
            .save(out)
            .with_context(|| format!("cannot write {}", out.display()))?;
        println!("wrote {}", out.display());
    }
    Ok(())
}
