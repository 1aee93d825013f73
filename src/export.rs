//! `visgate export`: a scene for another renderer.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use visgate_formats::mitsuba::{MitsubaOptions, write};

pub const EXPORT_HELP: &str = "\
Mitsuba 3 renders the exported scene as visgate's CPU reference converges to it (direct light
and one bounce, box filter, horizontal field of view, two-sided Lambertian, the same albedos and
textures, point and spot lights in W/sr): an independent ground truth for `visgate compare
--ground-truth`. bench/mitsuba.sh sets Mitsuba up in a virtual environment and renders it.

Examples:
  visgate export mitsuba builtin:cornell-box cornell-mi --size 256x256 --spp 4096
  bench/mitsuba.sh cornell-mi/scene.xml cornell-mi/out";

#[derive(Debug, Subcommand)]
pub enum ExportAction {
    /// Mitsuba 3: DIR/scene.xml (a sensor per camera, in order), DIR/meshes/*.obj,
    /// DIR/textures/*.exr.
    Mitsuba(MitsubaArgs),
}

#[derive(Debug, Args)]
pub struct MitsubaArgs {
    /// The scene: a .toml, .obj, .gltf/.glb file or builtin:NAME.
    pub scene: String,
    /// Output folder (created if missing).
    pub dir: PathBuf,
    /// Film size, WIDTHxHEIGHT (as `visgate render --size`).
    #[arg(long, default_value = "512x512")]
    pub size: String,
    /// Samples per pixel.
    #[arg(long, default_value_t = 1024)]
    pub spp: u32,
    /// Path depth: 3 is direct light and one bounce (visgate's VPLs of --bounces 1), 2 direct
    /// light alone.
    #[arg(long, default_value_t = 3)]
    pub max_depth: u32,
    /// Time the scene's dynamic meshes and lights are posed at, seconds.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub time: f64,
}

pub fn run(action: ExportAction) -> Result<()> {
    let ExportAction::Mitsuba(args) = action;
    if args.spp == 0 || args.max_depth < 2 {
        bail!("--spp must be ≥ 1 and --max-depth ≥ 2 (2: direct light, 3: one bounce)");
    }
    let scene = crate::load_scene(&args.scene, true)?;
    if scene.cameras.is_empty() {
        tracing::warn!(
            "{}: no camera; the scene file has no sensor to render",
            args.scene
        );
    }
    let opts = MitsubaOptions {
        size: crate::render::parse_size(&args.size)?,
        spp: args.spp,
        max_depth: args.max_depth,
    };
    let files = write(&scene.at(args.time), &args.dir, &opts)
        .with_context(|| format!("cannot write the Mitsuba scene into {}", args.dir.display()))?;
    println!(
        "wrote {} ({} shapes, {} textures; sensors in order: {})",
        files.xml.display(),
        files.shapes,
        files.textures,
        files.sensors.join(", ")
    );
    Ok(())
}
