//! `visgate compare`: every method against the CPU reference, one report.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use visgate_formats::vgate::{BakeParams, Resolution};
use visgate_formats::{BakedLevel, Scene};
use visgate_runtime::compare::{
    CompareMode, CompareReport, CompareSpec, ErrorMetric, Step, report, run,
};
use visgate_runtime::cpu::gates::GateLevel;
use visgate_runtime::hdr::HdrImage;

use crate::compare_modes::{lightcluster_modes, modes, variant_modes};
use crate::settings::{LightArgs, MethodArgs};

pub const COMPARE_HELP: &str = "\
Modes (--modes, comma-separated, or all): every GPU method of `visgate render --mode`
(none, per-vpl-shadow-maps, gates, gates-per-pixel, val-hard, val-cssm, direct-only) and
gates-voxels, gates-triangles, gates-portal and gates-disk (mode gates walking the level's open
voxels past the closed ones' planes, walking them along the true segment with the closed voxels' triangles
(--closed-voxel-triangles), walking its portals, or with the paper's disks, whatever
--gate-shape says; gates takes --gate-shape, voxels by default), gates-filled (gates as set,
its blur filled from the next blocks: --blur-fill), gates-starved (gates as set, its
starved pixels walking what their blur block lacks: --starved-taps, or 3/4 of the block's
pixels where that is 0), gates-roulette (gates as set, its walks by Russian roulette:
--walk-roulette, or 0.05 where that is 0 or auto), gates-fast (gates as set, in the fast
setting: --fast, the walk on the closed voxels' planes with the box blur), gates-balanced
(gates as set, in the balanced setting: --balanced, the default, so gates itself unless
--fast or --accurate) and gates-accurate (gates as set, in the accurate setting:
--accurate). `all`: every one but direct-only, gates-accurate and gates-balanced, gates once a
shape, gates-fast where gates are not fast, gates-filled and gates-starved where gates
interleave without them, and gates-roulette where gates walk (voxels, portals) without it; the gate modes only with a level
(given, or baked here). A mode that would render another's very frame (gates-roulette where
gates' auto roulette takes the same share: 8,192 VPLs or more, 2,048 or more in the
balanced and accurate settings) takes that mode's row instead.

Every mode renders at every --vpls count from every camera, beside the CPU reference with the
very same VPLs (a shadow ray per VPL and pixel sample; --spp samples). OUT/report.md and
OUT/report.html hold a table per camera (pass times, MSE, relative MSE, FLIP, indirect energy
ratio, black-where-lit share, speed-up over per-VPL shadow maps), the Pareto plot (frame time
against --metric, log-log) and a panel per render (reference | method | FLIP map | where the
method is black and the reference lit, in red); OUT/report.json holds every figure. With
--spp above 1, black where lit leaves out the pixels whose reference samples and centre see
several surfaces or albedos tenfold apart (silhouettes, creases, sharp texels: the reference
averages them, a method shades one point a pixel), dark yellow in the panels and white in
OUT/renders/CAMERA/mixed.png; the share over every pixel follows in brackets. Renders
are kept in OUT/renders: run the same command again after a stop and it resumes, redoing only
what changed.

A level: --level LEVEL.vgate, or --bake-resolution N to bake one here; with neither, a gate
mode makes the level be baked here at 128 voxels (and is left out, with a warning, if the
scene does not bake).

Examples:
  visgate compare builtin:ajar-door --vpls 256,1024 --size 320x240 --out cmp
  visgate compare scenes/shared/crytek-sponza.toml --bake-resolution 128 --modes none,gates,val-hard --out sponza
  visgate compare builtin:four-rooms --budget-ms 50 --max-error 0.05 --metric flip --out fr
  visgate compare builtin:cornell-box --modes val-cssm,val-hard --val-counts 2,8,30,64 --vpls 1024 --out m
  visgate compare builtin:four-rooms --modes direct-only,none,gates --gate-shape disk --gate-hops 1 \
      --variant \"gates-2hops=gates --gate-hops 2\" --variant \"portals=gates --gate-shape portal\" --out g
  visgate compare scenes/shared/cornell-box-turning-spot.toml --modes val-cssm --stability-frames 60 \
      --variant \"val-cssm-warm=val-cssm --val-warm-start\" --vpls 1024 --out coherence

Variants (--variant LABEL=MODE FLAGS…): a mode again with other settings, as a row (and a
curve) of its own — the run's flags with the variant's after them. The stability table of an
animated scene counts the live VALs of the VAL modes over the frames (restart against warm
start).";

/// `--metric`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MetricArg {
    /// MSE of the indirect light alone: each image with its own direct light replaced by the
    /// reference's (the direct light's shadow-map vs shadow-ray differences left out).
    IndirectMse,
    /// Mean squared error of the whole image (the papers' measure).
    Mse,
    /// Relative MSE (scale-free; weighs dark pixels as much as bright ones, so light leaking
    /// into dark rooms counts heavily).
    RelMse,
    /// Mean LDR-FLIP (perceptual).
    Flip,
}

#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The scene: a .toml, .obj, .gltf/.glb file or builtin:NAME.
    pub scene: String,
    /// Output folder: the report, the plot, the panels and every render (kept for resuming).
    #[arg(long, short)]
    pub out: PathBuf,
    /// The baked level for the gate modes.
    #[arg(long, conflicts_with = "bake_resolution")]
    pub level: Option<PathBuf>,
    /// Bake the level here at this many voxels on the longest axis.
    #[arg(long)]
    pub bake_resolution: Option<u32>,
    /// Modes to compare, comma-separated (see below), or all.
    #[arg(long, value_delimiter = ',', default_value = "all")]
    pub modes: Vec<String>,
    /// Light paths per render (or RSM VPLs), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "256,1024,4096")]
    pub vpls: Vec<u32>,
    /// VAL counts M, comma-separated: each VAL mode is compared at each (as `val-hard-m16`, …;
    /// the paper's Fig. 10). Default: --vals alone.
    #[arg(long, value_delimiter = ',')]
    pub val_counts: Vec<u32>,
    /// LightCluster's minimum distances, metres, comma-separated: each mode is compared with
    /// its lights' own shadow maps and once with LightCluster at each (as `direct-only-lc0.5`,
    /// …: its trade curve; the other --lc-* flags apply). Compare with --metric mse: the
    /// indirect-only error takes each image's direct light out.
    #[arg(long, value_delimiter = ',')]
    pub lc_min_distances: Vec<f32>,
    /// A mode with other settings, as a row of its own: `LABEL=MODE FLAGS…` (quoted), the
    /// run's own settings with FLAGS on top — `--variant "gates-2hops=gates --gate-shape disk
    /// --gate-hops 2"`, `--variant "val-cssm-warm=val-cssm --val-warm-start"`. Repeat it for
    /// several; a flag the run gave too is replaced by the variant's.
    #[arg(long = "variant", value_name = "LABEL=MODE FLAGS")]
    pub variants: Vec<String>,
    /// Cameras by name, comma-separated, or all.
    #[arg(long, value_delimiter = ',', default_value = "all")]
    pub cameras: Vec<String>,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "320x240")]
    pub size: String,
    /// An independent image per camera (a path tracer's EXR, same size), in camera order: each
    /// method's and the reference's error against it.
    #[arg(long)]
    pub ground_truth: Vec<PathBuf>,
    /// Frame-time budget, ms: the report names the most accurate setting within it.
    #[arg(long)]
    pub budget_ms: Option<f64>,
    /// Error bound (in --metric): the report names the fastest setting within it.
    #[arg(long)]
    pub max_error: Option<f64>,
    /// The error of the plot and the answers.
    #[arg(long, value_enum, default_value_t = MetricArg::IndirectMse)]
    pub metric: MetricArg,
    /// Frames of the temporal-stability sequence of an animated scene (0: none).
    #[arg(long, default_value_t = 8)]
    pub stability_frames: u32,
    /// Exposure of the PNGs and of FLIP, in stops.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub exposure: f32,
    /// GPU frames rendered and dropped before each timed one.
    #[arg(long, default_value_t = 1)]
    pub warmup: u32,
    /// Time the scene is posed at (the first frame of a sequence), seconds.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub time: f64,
    #[command(flatten)]
    pub light: LightArgs,
    #[command(flatten)]
    pub method: MethodArgs,
}

/// The level for the gate modes: --level read, or baked at the asked resolution, or baked at
/// 128 when a gate mode wants one (left out if the scene does not bake); and its key.
fn level(
    args: &CompareArgs,
    scene: &Scene,
    modes: &mut Vec<CompareMode>,
) -> Result<Option<(GateLevel, String)>> {
    if !modes.iter().any(|m| m.mode.gates().is_some()) {
        return Ok(None);
    }
    let baked = match (&args.level, args.bake_resolution) {
        (Some(p), _) => read_level(p)?,
        (None, n) => {
            let voxels = n.unwrap_or(128);
            println!("baking the level at {voxels} voxels on the longest axis");
            crate::bake_warnings::warn_of_strays(scene);
            let params = BakeParams {
                resolution: Resolution::LongestAxisVoxels(voxels),
                ..BakeParams::default()
            };
            let opts = visgate_preprocess::bake::BakeOptions::default();
            match visgate_preprocess::bake::bake(scene, &params, &opts, &|_| {}) {
                Ok(b) => {
                    for w in crate::bake_warnings::warnings(&b.report) {
                        eprintln!("warning: the bake at {voxels}: {w}");
                    }
                    b.level
                }
                Err(e) if n.is_none() => {
                    eprintln!(
                        "warning: the scene does not bake ({e}); the gate modes are left out"
                    );
                    modes.retain(|m| m.mode.gates().is_none());
                    return Ok(None);
                }
                Err(e) => return Err(e).context("cannot bake the level"),
            }
        }
    };
    let key = format!("{:?}", baked.info);
    Ok(Some((GateLevel::new(baked, scene)?, key)))
}

/// The baked level at `p`.
fn read_level(p: &std::path::Path) -> Result<BakedLevel> {
    BakedLevel::read(p).with_context(|| format!("cannot read the level {}", p.display()))
}

pub fn run_compare(args: CompareArgs) -> Result<()> {
    let mut scene = crate::load_scene(&args.scene, true)?;
    // A bare mesh gets a light and a camera where `visgate render` puts them.
    crate::bare::light_if_bare(&mut scene, &args.scene);
    let cameras = compare_cameras(&scene, &args)?;
    let command_line: Vec<String> = std::env::args().collect();
    let mut modes = compare_rows(&args, &command_line)?;
    let level = level(&args, &scene, &mut modes)?;
    let ground_truth = args
        .ground_truth
        .iter()
        .map(|p| HdrImage::read(p).with_context(|| format!("cannot read {}", p.display())))
        .collect::<Result<_>>()?;
    let mut base = args.light.job(&args.method);
    base.size = crate::render::parse_size(&args.size)?;
    base.time = args.time;
    base.warmup = args.warmup;
    let spec = CompareSpec {
        scene: args.scene.clone(),
        level_key: level.as_ref().map_or(String::new(), |l| l.1.clone()),
        modes,
        vpls: args.vpls.clone(),
        cameras,
        base,
        metric: match args.metric {
            MetricArg::IndirectMse => ErrorMetric::IndirectMse,
            MetricArg::RelMse => ErrorMetric::RelMse,
            MetricArg::Mse => ErrorMetric::Mse,
            MetricArg::Flip => ErrorMetric::Flip,
        },
        budget_ms: args.budget_ms,
        max_error: args.max_error,
        ground_truth,
        stability_frames: args.stability_frames,
        exposure: args.exposure,
        command: std::iter::once("visgate".to_string())
            .chain(command_line.iter().skip(1).map(|a| shell_word(a)))
            .collect::<Vec<_>>()
            .join(" "),
    };
    spec.check(level.is_some())?;
    std::fs::create_dir_all(args.out.join("panels"))
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let report = run_with_progress(&spec, &scene, level.as_ref().map(|l| &l.0), &args.out)?;
    report::write(&report, &args.out)?;
    print_report(&report, &spec, &args);
    Ok(())
}

/// The cameras `--cameras` names (`all`: the scene's), or the scene's first where it names
/// none the scene has.
fn compare_cameras(scene: &Scene, args: &CompareArgs) -> Result<Vec<visgate_formats::Camera>> {
    let cameras = if args.cameras.iter().any(|c| c == "all") {
        scene.cameras.clone()
    } else {
        args.cameras
            .iter()
            .map(|c| crate::camera_of(scene, &args.scene, Some(c)))
            .collect::<Result<_>>()?
    };
    if cameras.is_empty() {
        crate::camera_of(scene, &args.scene, None)?;
    }
    Ok(cameras)
}

/// The rows: `--modes`, the VAL counts', LightCluster's distances and the `--variant`s, each
/// label once.
fn compare_rows(args: &CompareArgs, command_line: &[String]) -> Result<Vec<CompareMode>> {
    let mut modes = modes(&args.modes, &args.method, &args.val_counts)?;
    modes = lightcluster_modes(modes, &args.method, &args.lc_min_distances)?;
    modes.extend(variant_modes(&args.variants, command_line)?);
    if let Some(twice) =
        (modes.iter().enumerate()).find(|(i, m)| modes[..*i].iter().any(|o| o.label == m.label))
    {
        bail!(
            "two rows are labelled {}: give each --variant a label of its own",
            twice.1.label
        );
    }
    Ok(modes)
}

/// `run` with a progress bar of the renders, the one under way and its rows.
fn run_with_progress(
    spec: &CompareSpec,
    scene: &Scene,
    level: Option<&GateLevel>,
    out: &std::path::Path,
) -> Result<CompareReport> {
    let bar = ProgressBar::new(1).with_style(
        ProgressStyle::with_template("compare {bar:30} {pos}/{len} renders {elapsed}<{eta} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let what = std::sync::Mutex::new(String::new());
    let progress = |s: Step| match s {
        Step::Render {
            index,
            total,
            what: w,
        } => {
            bar.set_length(total as u64);
            bar.set_position(index as u64);
            w.clone_into(&mut what.lock().unwrap_or_else(|e| e.into_inner()));
            bar.set_message(w.to_string());
        }
        Step::Rows(d, t) => {
            let w = what.lock().unwrap_or_else(|e| e.into_inner()).clone();
            bar.set_message(format!("{w} (rows {d}/{t})"));
        }
    };
    let report = run(spec, scene, level, out, &progress)?;
    bar.finish_and_clear();
    Ok(report)
}

/// What the terminal shows of a report: renders made and failed, the references' warnings,
/// the answers, the Pareto front and where the report is.
fn print_report(report: &CompareReport, spec: &CompareSpec, args: &CompareArgs) {
    println!(
        "{}: {} renders made, {} read back; {} failed",
        args.scene,
        report.resumed[1],
        report.resumed[0],
        report.failures.len()
    );
    for f in &report.failures {
        println!(
            "  failed: {} at {} VPLs, camera {}: {}",
            f.mode, f.vpls, f.camera, f.error
        );
    }
    for r in &report.references {
        if let Some(w) = &r.warning {
            eprintln!("warning: camera {} at {} VPLs: {w}", r.camera, r.vpls);
        }
    }
    for a in &report.answers {
        println!("{}: {}", a.kind, a.text);
    }
    println!("on the front ({}), fastest first:", spec.metric.name());
    let mut front: Vec<_> = report.points.iter().filter(|p| p.pareto).collect();
    front.sort_by(|a, b| a.ms.total_cmp(&b.ms));
    for p in front {
        println!(
            "  {:<22} {:>6} VPLs {:>10.2} ms  {:.3e}",
            p.mode, p.vpls, p.ms, p.error
        );
    }
    println!("wrote {}", args.out.join("report.md").display());
}

/// `arg` as a POSIX shell reads it back: as it is when it holds only characters no shell
/// treats specially, else in single quotes (a quote in it closed, escaped and reopened), so
/// that the report's command runs again as given (a `--variant "LABEL=MODE FLAGS"`).
fn shell_word(arg: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "-_./:=,@%+".contains(c);
    if !arg.is_empty() && arg.chars().all(plain) {
        arg.to_string()
    } else {
        format!("'{}'", arg.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reports_command_quotes_what_a_shell_would_split() {
        assert_eq!(shell_word("--vpls"), "--vpls");
        assert_eq!(shell_word("scenes/a-b_c.toml"), "scenes/a-b_c.toml");
        assert_eq!(
            shell_word("st64=gates --starved-taps 64"),
            "'st64=gates --starved-taps 64'"
        );
        assert_eq!(shell_word("it's"), r"'it'\''s'");
        assert_eq!(shell_word(""), "''");
    }
}
