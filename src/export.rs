//! `visgate export`: a scene for another renderer.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use visgate_formats::mitsuba::{MitsubaOptions, write};

pub const EXPORT_HELP: &str = "\
glTF writes the scene as visgate sees it — +Y up, metres, its meshes, albedos, point and spot
lights (KHR_lights_punctual, W/sr as candela: x 683) and cameras — one file with its buffer
beside it, to open in Blender or another engine. Given bare to any visgate command it reads
back as the same scene (textures are not written). OUT.glb writes it as one binary file.

Mitsuba 3 renders the exported scene as visgate's CPU reference converges to it (direct light
and one bounce, box filter, horizontal field of view, two-sided Lambertian, the same albedos and
textures, point and spot lights in W/sr): an independent ground truth for `visgate compare
--ground-truth`. bench/mitsuba.sh sets Mitsuba up in a virtual environment and renders it.

Examples:
  visgate export gltf builtin:ajar-door ajar-door.gltf
  visgate export mitsuba builtin:cornell-box cornell-mi --size 256x256 --spp 4096
  bench/mitsuba.sh cornell-mi/scene.xml cornell-mi/out";

#[derive(Debug, Subcommand)]
pub enum ExportAction {
    /// Mitsuba 3: DIR/scene.xml (a sensor per camera, in order), DIR/meshes/*.obj,
    /// DIR/textures/*.exr.
    Mitsuba(MitsubaArgs),
    /// glTF 2.0: OUT.gltf and OUT.bin beside it, or one OUT.glb — meshes, albedos, lights,
    /// cameras.
    Gltf(GltfArgs),
}

#[derive(Debug, Args)]
pub struct GltfArgs {
    /// The scene: a .toml, .obj, .gltf/.glb file or builtin:NAME.
    pub scene: String,
    /// The file to write: .gltf (its buffer beside it, with the extension .bin) or .glb.
    pub out: PathBuf,
    /// Time the scene's dynamic meshes and lights are posed at, seconds.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub time: f64,
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
    match action {
        ExportAction::Mitsuba(args) => mitsuba(args),
        ExportAction::Gltf(args) => gltf(args),
    }
}

fn gltf(args: GltfArgs) -> Result<()> {
    let glb = match args.out.extension().and_then(|e| e.to_str()) {
        Some("gltf") => false,
        Some("glb") => true,
        _ => bail!(
            "{}: the output must end in .gltf (its buffer written beside it as .bin) or .glb \
             (one file)",
            args.out.display()
        ),
    };
    let scene = crate::load_scene(&args.scene, false)?.at(args.time);
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let write = |path: &std::path::Path, bytes: &[u8]| {
        std::fs::write(path, bytes).with_context(|| format!("cannot write {}", path.display()))
    };
    let wrote = if glb {
        write(&args.out, &visgate_formats::gltf_export::to_glb(&scene))?;
        args.out.display().to_string()
    } else {
        let bin = args.out.with_extension("bin");
        let bin_name = bin
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let (json, bytes) = visgate_formats::gltf_export::to_gltf(&scene, Some(&bin_name));
        write(&bin, &bytes)?;
        write(&args.out, json.as_bytes())?;
        format!("{} and {}", args.out.display(), bin.display())
    };
    println!(
        "wrote {wrote} ({} meshes, {} materials, {} lights, {} cameras{})",
        scene.meshes.len(),
        scene.materials.len(),
        scene.lights.len(),
        scene.cameras.len(),
        if scene.textures.is_empty() {
            ""
        } else {
            "; textures not written"
        }
    );
    Ok(())
}

fn mitsuba(args: MitsubaArgs) -> Result<()> {
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
