//! `visgate`: the one command-line tool — bake levels, render and compare images, inspect
//! scenes, meshes and baked levels, and list or export the built-in scenes.

mod bake;
mod bake_warnings;
mod bare;
mod compare;
mod compare_modes;
mod export;
mod inspect;
mod render;
mod settings;
mod view;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use visgate_formats::desc::UpAxis;
use visgate_formats::{BareMesh, ImportOptions, Scene};
use visgate_scenes::Builtin;

const AFTER_HELP: &str = "\
A SCENE argument is any of:
  level.toml          a scene description (meshes, lights, cameras; see README)
  mesh.obj|.gltf|.glb a bare mesh file, taken as one static mesh with no lights
  builtin:NAME        a built-in scene (list them with `visgate scenes`)

Examples:
  visgate bake builtin:two-rooms -o two-rooms.vgate
  visgate render builtin:cornell-box --out cornell.png
  visgate view builtin:two-rooms --level two-rooms.vgate
  visgate inspect builtin:four-rooms
  visgate inspect --json ../shared/scenes/crytek_sponza/sponza.glb
  visgate scenes export two-rooms out/two-rooms

Logs go to stderr; set RUST_LOG=debug for more.";

#[derive(Parser)]
#[command(
    name = "visgate",
    version,
    about = "Bake level topology into visibility clusters and gates; render one-bounce GI from virtual point lights.",
    after_help = AFTER_HELP
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// For a bare mesh file (a SCENE that is an OBJ, glTF or GLB, no scene TOML): metres per
    /// unit of the file (0.01 centimetres, 0.0254 inches, 0.001 millimetres). Default: metres,
    /// or centimetres (then millimetres) where metres would make the level longer than 1 km;
    /// then centimetres, inches or millimetres (the first that does) where that unit makes its
    /// rooms 1.9-6 m floor to ceiling and the first makes them no room's height (outside 1.9-20
    /// m). A warning says which.
    #[arg(long, global = true, value_name = "M", allow_negative_numbers = true)]
    metres_per_unit: Option<f64>,
    /// For a bare mesh file: the axis that points up. Default: y for glTF (its convention);
    /// for OBJ, z where more of its area faces ±z than ±y (floors, ceilings) and it is lower
    /// along z, else y. The bake, the renders and the viewer must read a mesh the same way.
    #[arg(long, global = true, value_enum)]
    up: Option<UpArg>,
    /// For a bare mesh file: keep the triangles that lie far from the rest. By default, where
    /// leaving them out shortens the level more than 16×, a few (at most 1 %) far triangles —
    /// a sky box, a helper object left in the export, a vertex in the wrong place — or whole
    /// objects round the rest from far away with no more triangles than it — a sky dome — are
    /// left out, with a warning: they would choose the units and size the bake's voxels. A
    /// scene TOML keeps every triangle (the bake then warns of them, from 4×).
    #[arg(long, global = true)]
    keep_far: bool,
}

/// An up axis on the command line.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum UpArg {
    /// +Y up (glTF, most OBJ exporters).
    Y,
    /// +Z up (Blender's scenes, Quake, 3ds Max, Unreal): read with (x, y, z) → (x, z, −y).
    Z,
}

/// The bare-mesh reading the command line asked for, set once before the command runs.
static BARE_MESH: std::sync::OnceLock<BareMesh> = std::sync::OnceLock::new();

/// The command line's `--metres-per-unit` and `--up`, checked.
fn bare_mesh_of(cli: &Cli) -> Result<BareMesh> {
    if let Some(m) = cli.metres_per_unit
        && !(m.is_finite() && m > 0.0)
    {
        anyhow::bail!("--metres-per-unit {m} must be a number > 0 (0.01 for centimetres)");
    }
    Ok(BareMesh {
        metres_per_unit: cli.metres_per_unit,
        up: cli.up.map(|u| match u {
            UpArg::Y => UpAxis::Y,
            UpArg::Z => UpAxis::Z,
        }),
        keep_far: cli.keep_far,
    })
}

#[derive(Subcommand)]
enum Command {
    /// Bake a scene's topology (skeleton, visibility clusters, gates) into a .vgate level.
    #[command(after_help = bake::AFTER_HELP)]
    Bake(bake::BakeArgs),
    /// Render an image of a scene (CPU: exact reference, no indirect visibility, or direct only).
    #[command(after_help = render::RENDER_HELP)]
    Render(render::RenderArgs),
    /// Walk through a scene in a window, switching the visibility method live.
    #[command(after_help = view::VIEW_HELP)]
    View(view::ViewArgs),
    /// Every method against the CPU reference on one level: times, errors, a Pareto plot, a
    /// report (Markdown, HTML, JSON) and the answer to a time budget or an error bound.
    #[command(after_help = compare::COMPARE_HELP)]
    Compare(compare::CompareArgs),
    /// Write a scene for another renderer or tool: Mitsuba 3 (an independent ground truth) or
    /// glTF (Blender, engines; reads back bare as the same scene).
    #[command(after_help = export::EXPORT_HELP)]
    Export {
        #[command(subcommand)]
        action: export::ExportAction,
    },
    /// Compare an image with a reference: MSE, relative MSE, FLIP, and an error map.
    Diff(render::DiffArgs),
    /// Print a summary of a scene, a mesh file or a baked .vgate level.
    Inspect {
        /// A scene (TOML, OBJ, glTF/GLB, builtin:NAME) or a baked .vgate file.
        file: String,
        /// Print the summary as JSON, for scripts.
        #[arg(long)]
        json: bool,
        /// Skip decoding textures (faster on large scenes).
        #[arg(long)]
        no_textures: bool,
    },
    /// List the built-in scenes, or export one as OBJ + TOML.
    Scenes {
        #[command(subcommand)]
        action: Option<ScenesAction>,
    },
}

#[derive(Subcommand)]
enum ScenesAction {
    /// List the built-in scenes (the default).
    List,
    /// Write a built-in scene as NAME.toml + its OBJ/MTL + NAME.expected.toml into DIR.
    Export {
        /// The scene's name (see `visgate scenes`).
        name: String,
        /// Output directory (created if missing).
        dir: PathBuf,
    },
}

/// `visgate compare`'s arguments from `argv` (a whole command line), a flag given again
/// replacing the earlier one: `compare --variant` reads its run's settings this way, with the
/// variant's flags after them.
fn compare_args_from(argv: impl IntoIterator<Item = String>) -> Result<compare::CompareArgs> {
    use clap::{CommandFactory, FromArgMatches};
    let matches = Cli::command()
        .args_override_self(true)
        .try_get_matches_from(argv)
        .map_err(|e| anyhow::anyhow!("{}", e.render().to_string().trim()))?;
    match Cli::from_arg_matches(&matches)?.command {
        Command::Compare(args) => Ok(args),
        _ => anyhow::bail!("not a compare command line"),
    }
}

fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn")),
        )
        .with_writer(std::io::stderr)
        // Colour codes only on a terminal: not in a pipe or a log file.
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .with_target(false)
        .init();
    quiet_on_closed_stdout();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    // Set once, here: a second set could only come from a second parse of the same line.
    let _ = BARE_MESH.set(bare_mesh_of(&cli)?);
    match cli.command {
        Command::Bake(args) => bake::run(args),
        Command::Render(args) => render::run(args),
        Command::Compare(args) => compare::run_compare(args),
        Command::Export { action } => export::run(action),
        Command::View(args) => view::run(args),
        Command::Diff(args) => render::diff(args),
        Command::Inspect {
            file,
            json,
            no_textures,
        } => inspect::run(&file, json, no_textures),
        Command::Scenes { action } => match action.unwrap_or(ScenesAction::List) {
            ScenesAction::List => {
                println!("Built-in scenes (use as builtin:NAME wherever a scene is taken):");
                for b in Builtin::ALL {
                    println!("  {:<14} {}", b.name(), b.description());
                }
                Ok(())
            }
            ScenesAction::Export { name, dir } => {
                let b = builtin_or_err(&name)?;
                let path = b.export(&dir).with_context(|| {
                    format!("cannot export '{}' into {}", b.name(), dir.display())
                })?;
                println!("wrote {}", path.display());
                Ok(())
            }
        },
    }
}

fn builtin_or_err(name: &str) -> Result<Builtin> {
    Ok(visgate_scenes::builtin(name)?)
}

/// Loads a SCENE argument: `builtin:NAME`, a scene TOML, or a bare OBJ/glTF/GLB file.
/// `load_textures`: decode the diffuse textures (the bake needs none). A bare mesh is read with
/// the command line's `--metres-per-unit` and `--up`.
pub fn load_scene(arg: &str, load_textures: bool) -> Result<Scene> {
    let options = ImportOptions {
        load_textures,
        bare: BARE_MESH.get().copied().unwrap_or_default(),
    };
    Ok(visgate_scenes::load(arg, &options)?)
}

/// Makes ready an output file before a command works: its folder made where it is not there
/// (as `visgate export` and `scenes export` make theirs), and a file made and removed there, so
/// that a place it cannot write is refused first (a bake at 1024 voxels or a reference render
/// takes minutes, and a folder that was not there failed only then). The probe is
/// `PATH.partial`, the file the level is written through.
pub fn writable(path: &Path, flag: &str) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir).with_context(|| {
        format!(
            "{flag} {}: cannot make its folder {}",
            path.display(),
            dir.display()
        )
    })?;
    let mut probe = path.as_os_str().to_owned();
    probe.push(".partial");
    std::fs::File::create(&probe)
        .with_context(|| format!("{flag} {}: cannot write there", path.display()))?;
    std::fs::remove_file(&probe).ok();
    Ok(())
}

/// The camera named `name` of `scene` (loaded from `arg`), or its first.
pub fn camera_of(scene: &Scene, arg: &str, name: Option<&str>) -> Result<visgate_formats::Camera> {
    match name {
        Some(name) => scene.camera(name).cloned().with_context(|| {
            let names: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
            format!(
                "{arg}: no camera '{name}'; its cameras are: {}",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )
        }),
        None => scene.cameras.first().cloned().with_context(|| {
            if scene.is_bare_mesh() {
                format!(
                    "{arg}: a bare mesh carries no camera (nor lights); write a scene TOML \
                     beside it that names it ([[mesh]] path = \"…\") and adds a [[camera]] and \
                     a [[light]] (see README, Scenes), or walk it in the viewer's window"
                )
            } else {
                format!("{arg}: the scene has no camera; add a [[camera]] to its TOML (see README)")
            }
        }),
    }
}

/// `visgate … | head` closes stdout early; Rust's print then panics. Exit quietly instead, as
/// command-line tools do when their reader goes away (status 141 = 128 + SIGPIPE).
fn quiet_on_closed_stdout() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.contains("failed printing to stdout") {
            std::process::exit(141);
        }
        default(info)
    }));
}
