//! `visgate bake`: a scene → a baked `.vgate` level, with progress bars, a timing tree, a
//! JSON report and debug exports.

use std::path::PathBuf;
use std::sync::Mutex;

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use visgate_formats::vgate::{
    AlphaRule, BakeParams, CurvatureTo, GatePlacement, MaxBall, Resolution,
};
use visgate_preprocess::bake::{BakeOptions, Baked, Progress, bake};

use crate::bake_warnings::{warn_of_strays, warnings};

/// Options of `visgate bake`.
#[derive(Args)]
pub struct BakeArgs {
    /// The scene to bake: a .toml description, a bare .obj/.gltf/.glb, or builtin:NAME.
    pub scene: String,
    /// Where to write the baked level (conventionally LEVEL.vgate).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Voxels on the longest axis of the static bounds (8..=2048). On 2 cores Crytek Sponza
    /// bakes in about 1.7 s at 256, 2.7 s and 0.33 GB at 512, 10 s and 1.9 GB at 1024.
    #[arg(long, default_value_t = 128, conflicts_with = "voxel_size")]
    pub resolution: u32,
    /// Voxel edge length in metres, instead of --resolution.
    #[arg(long)]
    pub voxel_size: Option<f32>,
    /// Cluster growth tolerance α as a fraction of the cluster's largest max ball (paper: 0.2).
    #[arg(long, default_value_t = 0.2)]
    pub alpha: f32,
    /// Thinning persistence in steps (voxel layers); default grows with the grid: 2 + ceil(n/64).
    #[arg(long)]
    pub persistence: Option<u32>,
    /// Where gates sit on a segmented edge that joins two clusters.
    #[arg(long, value_enum, default_value_t = Gates::Narrowest)]
    pub gates: Gates,
    /// What a skeleton node's max-ball radius measures (default: solid-centre; see README).
    #[arg(long, value_enum)]
    pub max_ball: Option<MaxBallArg>,
    /// What the cluster growth's α compares a neighbour's radius with (default: popped-node;
    /// see README).
    #[arg(long, value_enum)]
    pub alpha_rule: Option<AlphaRuleArg>,
    /// What a skeleton line node's curvature measures the distance to (default: line, the paper's).
    #[arg(long, value_enum)]
    pub curvature_to: Option<CurvatureArg>,
    /// Edge of a portal's coverage-mask cell, voxels (0.25–8): finer follows the openings'
    /// shapes more closely, coarser makes smaller files.
    #[arg(long, default_value_t = 1.0)]
    pub portal_cell: f32,
    /// Narrowest gap that shapes the partition: the radius of the largest ball it holds, metres
    /// (0–10; 0 = every gap, the paper's). Skeleton loops through narrower cracks are opened
    /// and thinner branches pruned, so cluster counts stay put as the resolution grows; light
    /// still passes there. Default: 0.1 m (gaps under 20 cm), or 1/256 of the level's longest
    /// extent if smaller.
    #[arg(long)]
    pub min_gap: Option<f32>,
    /// Voxel edge of the grid the skeleton, clusters and gates are made on, metres (0–10; 0 =
    /// the level's grid): a finer --resolution then refines only the voxels' clusters and the
    /// portals, so the partition is the same at 256, 512 or 1024 and the bake much faster.
    /// Default: the finest of 1/128, 1/256, 1/512, … of the level's longest extent that reaches
    /// 0.125 m, so one size at 128, 256, 512 and 1024 voxels (elsewhere the least whole multiple
    /// of the level's voxel that reaches it), or 1/128 of the level's longest extent if that is
    /// smaller (a small level keeps its doors: the ajar door
    /// at 256 then agrees with shadow rays on 91–98 % of pairs, 79–98 % partitioned on its own
    /// grid). A coarser --resolution is partitioned on a whole fraction of its voxel, each voxel
    /// taking the cluster most of its share has (at most 25 cm voxels: Dabrovic Sponza at 128 on
    /// its 256 grid, 160 clusters as at 256 and 512, where its own 27 cm voxels made 17; 0 bakes
    /// it on its own grid, 3–8× faster: Crytek Sponza 0.7 s against 2.2 s on two cores).
    #[arg(long)]
    pub partition_voxel: Option<f32>,
    /// Voxel edge of the open-voxel grid that `--gate-shape voxels` walks, metres (0 or more; 0 =
    /// the level's grid; a bit a voxel, voxelized thin: a voxel is closed when a triangle
    /// crosses its centre segments): openings narrow by up to half a voxel at each edge, and a
    /// segment passing within a voxel of a surface is blocked, so a finer grid lets more of the
    /// light through. Default: the level's voxel, or 1/512 of the level's longest extent if
    /// smaller, and on a level over 20 m long finer, down to 4 cm while the grid holds at most
    /// 2^28 voxels (32 MiB of bits, 64 MiB on the GPU): Crytek and Dabrovic Sponza 4 cm, the
    /// Quake level 12.8 cm (on 2 cores 0.1–0.4 s, 9–19 MB of the file).
    #[arg(long)]
    pub sight_voxel: Option<f32>,
    /// Smallest room, metres: a cluster whose largest ball (radius, 0–10) is smaller is merged
    /// into the neighbour across its widest gate (a roof slab, a crack, a niche where nobody
    /// stands). Default 0: none merged (the paper's). 0.3 halves Dabrovic Sponza's clusters at
    /// 256 and 512 (its roof slab), but merges thin rooms of a coarse bake too.
    #[arg(long)]
    pub min_cluster_ball: Option<f32>,
    /// Empty components with no camera or light and fewer voxels than this are dropped.
    #[arg(long, default_value_t = 64)]
    pub min_component_voxels: u64,
    /// Bake a scene declared closed even if its empty space reaches its bounds.
    #[arg(long)]
    pub allow_leaks: bool,
    /// Worker threads (default: all cores). The result does not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Refuse grids whose bake would need more memory than this, GiB.
    #[arg(long, default_value_t = 16.0)]
    pub memory_limit_gib: f64,
    /// Write the bake report (params, per-stage times and counts, peak memory) as JSON.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Write debug exports (PLY for Blender/MeshLab, solid.npy, skeleton.npy) into this folder.
    #[arg(long)]
    pub debug_dir: Option<PathBuf>,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Gate placement rule.
#[derive(Clone, Copy, ValueEnum)]
pub enum Gates {
    /// At the narrowest point of the skeleton line between the two nodes (the doorway).
    Narrowest,
    /// At the middle of the segmented edge, as in the paper (IV.C).
    Midpoint,
}

/// `--max-ball`.
#[derive(Clone, Copy, ValueEnum)]
pub enum MaxBallArg {
    /// The ball contained in the empty space: to the nearest solid voxel's surface (the paper's).
    Contained,
    /// To the nearest solid voxel's centre: up to half a voxel larger.
    SolidCentre,
}

/// `--alpha-rule`.
#[derive(Clone, Copy, ValueEnum)]
pub enum AlphaRuleArg {
    /// |r(neighbour) − r(popped node)| ≤ α · the cluster's largest radius.
    PoppedNode,
    /// |r(neighbour) − the cluster's largest radius| ≤ α · that radius.
    ClusterMax,
}

/// `--curvature-to`.
#[derive(Clone, Copy, ValueEnum)]
pub enum CurvatureArg {
    /// The straight line through the line's ends (the paper's).
    Line,
    /// The segment between the line's ends.
    Segment,
}

pub const AFTER_HELP: &str = "\
Stages: load static meshes → voxelize → empty space → distance → thin → skeleton graph →
segment → clusters → gates → flatten. A timing tree and a summary are printed at the end.

What is kept: the empty space around each camera and light (without any, as for a bare mesh,
the space the most triangles face: the level's inside), and any other the geometry faces more
than it turns its back to (not a thick wall's inside) of --min-component-voxels or more; with
cameras or lights, each triangle's sides counted from the first voxel off it that is not
solid, so the space around and over the rooms, which sees their walls' backs, is dropped. A
scene declared `closed = true` stops where its space reaches the bounds and names the opening
(--allow-leaks bakes on); a bare mesh's inside that reaches them is baked, the opening named
in a warning (and in leak.ply with --debug-dir).

Warnings, each with what to do: most of the space dropped as a wall's inside; a camera sealed
off from every light (a doorway the voxels close); a grid too coarse for the level (its widest
space under 6 voxels across), with the --resolution to use instead.

Examples:
  visgate bake builtin:two-rooms -o two-rooms.vgate
  visgate bake ../shared/scenes/crytek_sponza/sponza.glb -o sponza.vgate --resolution 256 \\
      --report sponza.json --debug-dir sponza-debug
  visgate inspect sponza.vgate";

pub fn run(args: BakeArgs) -> Result<()> {
    let (params, options) = params_of(&args)?;
    crate::writable(&args.output, "-o")?;
    if let Some(report) = &args.report {
        crate::writable(report, "--report")?;
    }
    let scene = crate::load_scene(&args.scene, false)?;
    // The importer has logged the scene's warnings (degenerate triangles dropped, …) once.
    warn_of_strays(&scene);
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = args.threads {
        pool = pool.num_threads(t);
    }
    let pool = pool.build().context("cannot start the worker threads")?;
    let bars = Bars {
        bar: Mutex::new(None),
        quiet: args.quiet,
    };
    let progress = |p: Progress| bars.show(p);
    let baked = pool.install(|| bake(&scene, &params, &options, &progress));
    // A leak stops the bake; its paths still go where the user asked for debug files.
    if let (Err(visgate_preprocess::BakeError::Leak { openings, .. }), Some(dir)) =
        (&baked, &args.debug_dir)
    {
        write_leak_ply(dir, openings)?;
    }
    let baked = baked.with_context(|| format!("cannot bake {}", args.scene))?;
    baked
        .level
        .write(&args.output)
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    print_outcome(&args, &baked)
}

/// The bake's parameters and options from the flags (the limits a flag alone can break
/// checked here; the rest by the bake).
fn params_of(args: &BakeArgs) -> Result<(BakeParams, BakeOptions)> {
    let resolution = match args.voxel_size {
        Some(v) => Resolution::VoxelSizeM(v),
        None => Resolution::LongestAxisVoxels(args.resolution),
    };
    if !(args.memory_limit_gib.is_finite() && args.memory_limit_gib > 0.0) {
        bail!(
            "--memory-limit-gib {} must be a number > 0",
            args.memory_limit_gib
        );
    }
    if args.threads == Some(0) {
        bail!("--threads 0: give at least 1 thread, or leave it out to use all cores");
    }
    let defaults = BakeParams::default();
    let params = BakeParams {
        resolution,
        alpha: args.alpha,
        persistence: args.persistence,
        min_component_voxels: args.min_component_voxels,
        min_gap_m: args.min_gap,
        partition_voxel_m: args.partition_voxel,
        sight_voxel_m: args.sight_voxel,
        min_cluster_ball_m: args.min_cluster_ball,
        gate_placement: match args.gates {
            Gates::Narrowest => GatePlacement::Narrowest,
            Gates::Midpoint => GatePlacement::Midpoint,
        },
        max_ball: args.max_ball.map_or(defaults.max_ball, |m| match m {
            MaxBallArg::Contained => MaxBall::Contained,
            MaxBallArg::SolidCentre => MaxBall::SolidCentre,
        }),
        alpha_rule: args.alpha_rule.map_or(defaults.alpha_rule, |r| match r {
            AlphaRuleArg::PoppedNode => AlphaRule::PoppedNode,
            AlphaRuleArg::ClusterMax => AlphaRule::ClusterMax,
        }),
        curvature_to: args
            .curvature_to
            .map_or(defaults.curvature_to, |c| match c {
                CurvatureArg::Line => CurvatureTo::Line,
                CurvatureArg::Segment => CurvatureTo::Segment,
            }),
        allow_leaks: args.allow_leaks,
        portal_cell_voxels: args.portal_cell,
    };
    let options = BakeOptions {
        memory_limit_bytes: (args.memory_limit_gib * (1u64 << 30) as f64) as u64,
        keep_solid_grid: args.debug_dir.is_some(),
    };
    Ok((params, options))
}

/// The bake's progress on the terminal: a bar for a stage that counts its work, else a
/// spinner; nothing with --quiet.
struct Bars {
    bar: Mutex<Option<ProgressBar>>,
    quiet: bool,
}

impl Bars {
    /// Shows `p`.
    fn show(&self, p: Progress) {
        if self.quiet {
            return;
        }
        let Ok(mut slot) = self.bar.lock() else {
            return;
        };
        match p {
            Progress::Start { stage, total } => {
                let b = if total > 0 {
                    ProgressBar::new(total).with_style(
                        ProgressStyle::with_template(
                            "{msg:>16} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}",
                        )
                        .unwrap_or_else(|_| ProgressStyle::default_bar())
                        .progress_chars("=> "),
                    )
                } else {
                    ProgressBar::new_spinner()
                };
                b.set_message(stage);
                *slot = Some(b);
            }
            Progress::Advance(done) => {
                if let Some(b) = slot.as_ref() {
                    b.set_position(done);
                }
            }
            Progress::Finish => {
                if let Some(b) = slot.take() {
                    b.finish_and_clear();
                }
            }
        }
    }
}

/// Prints the bake's report, its leaks and warnings, and writes the JSON report and the
/// debug files where asked.
fn print_outcome(args: &BakeArgs, baked: &Baked) -> Result<()> {
    print!("{}", baked.report.text());
    for l in baked.report.empty_space["leaks"]
        .as_array()
        .into_iter()
        .flatten()
    {
        eprintln!("warning: the closed scene leaks (baked anyway, --allow-leaks): {l}");
    }
    for o in &baked.openings {
        eprintln!("warning: leak: {}", o.describe());
    }
    if let (Some(dir), false) = (&args.debug_dir, baked.openings.is_empty()) {
        write_leak_ply(dir, &baked.openings)?;
    }
    for w in warnings(&baked.report) {
        eprintln!("warning: {w}");
    }
    println!("wrote {}", args.output.display());
    if let Some(path) = &args.report {
        let json = serde_json::to_string_pretty(&baked.report)?;
        std::fs::write(path, json).with_context(|| format!("cannot write {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    if let Some(dir) = &args.debug_dir {
        let files = visgate_preprocess::debug::write_all(dir, &baked.level, &baked.grids)
            .with_context(|| format!("cannot write debug exports into {}", dir.display()))?;
        println!("wrote {} debug files into {}", files.len(), dir.display());
    }
    Ok(())
}

/// Writes the leaks' paths into `dir` as leak.ply.
fn write_leak_ply(
    dir: &std::path::Path,
    openings: &[visgate_preprocess::leak::LeakPath],
) -> Result<()> {
    let path = dir.join("leak.ply");
    let write = || -> std::io::Result<()> {
        std::fs::create_dir_all(dir)?;
        let mut w = std::io::BufWriter::new(std::fs::File::create(&path)?);
        visgate_preprocess::leak::write_ply(&mut w, openings)?;
        std::io::Write::flush(&mut w)
    };
    write().with_context(|| format!("cannot write {}", path.display()))?;
    eprintln!("wrote {} (the paths to the outside)", path.display());
    Ok(())
}
