//! `visgate view`: walk through a level in a window (eframe, wgpu renderer only) and switch the
//! visibility method live. The frame is `GpuRenderer::render_frame`, the call `visgate render`
//! makes, with the same VPLs and clamp, so both give the same image of the same view.

mod app;
mod bench;
mod camera;
mod compare;
mod layers;
mod panel;
mod path;
mod shader_watch;
mod state;

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::{Args, Parser};
use visgate_runtime::cpu::gates::GateLevel;
use visgate_runtime::gpu::{GpuContext, MethodInfo, method};

use state::SavedView;
use visgate_runtime::job::RenderJob;

/// Options of `visgate view`.
#[derive(Args)]
pub struct ViewArgs {
    /// The scene: a .toml description, a bare .obj/.gltf/.glb, or builtin:NAME.
    pub scene: String,
    /// A baked level of the scene (`visgate bake`), for the gate methods.
    #[arg(long)]
    pub level: Option<PathBuf>,
    /// The method to start with (any of `visgate render --mode`, but `reference`); default
    /// `gates` with a level, else `none`.
    #[arg(long)]
    pub mode: Option<String>,
    /// Light paths (VPLs), changeable in the window (default: 1024 on a GPU, 64 on a software
    /// adapter, where 1024 take seconds a frame).
    #[arg(long)]
    pub vpls: Option<u32>,
    /// Take the VPLs from the lights' reflective shadow maps on the GPU.
    #[arg(long)]
    pub rsm: bool,
    /// The scene camera to start from (default: the first; `--camera level` frames the level).
    #[arg(long)]
    pub camera: Option<String>,
    /// Render at this size, WIDTHxHEIGHT, shown fitted into the window (default: the window's).
    #[arg(long)]
    pub render_size: Option<String>,
    /// The scene's time to start at, seconds (animated meshes and lights; play in the window).
    #[arg(long, default_value_t = 0.0)]
    pub time: f64,
    /// Write the last frame (.png sRGB, .exr linear) after --frames frames, then close.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Frames to render before --screenshot is written.
    #[arg(long, default_value_t = 3)]
    pub frames: u32,
    /// Also write the whole window (panels and debug layers) as PNG with --screenshot.
    #[arg(long, requires = "screenshot")]
    pub window_shot: Option<PathBuf>,
    /// Debug layers on at the start, comma separated: clusters (visibility), geometry
    /// (geometry clusters), lists (light-list length) — one of these shows at a time —, gates,
    /// skeleton, vpls, vals (the VALs of a VAL mode as disks of their area), indirect (the
    /// frame less its direct light).
    #[arg(long, value_delimiter = ',')]
    pub layers: Vec<String>,
    /// Render the exact CPU reference of the first view and show it beside the method (the
    /// screenshot waits for it).
    #[arg(long)]
    pub compare: bool,
    /// Play a camera path of this many frames through the scene's cameras (or a turn about
    /// the level), write every frame's pass times to --benchmark-out, then close.
    #[arg(long, requires = "benchmark_out")]
    pub benchmark: Option<u32>,
    /// The benchmark's CSV: frame,pass,gpu_ms,cpu_wall_ms.
    #[arg(long)]
    pub benchmark_out: Option<PathBuf>,
    /// Play this camera path (JSON, as the panel's "record camera path" saves it) instead of
    /// the scene's cameras.
    #[arg(long, requires = "benchmark")]
    pub benchmark_path: Option<PathBuf>,
    /// Where the panel's "record camera path" saves the path.
    #[arg(long, default_value = "camera-path.json")]
    pub record_path: PathBuf,
    /// Start from the defaults and the flags alone: neither read nor write the state kept
    /// across runs (scripted runs, --screenshot and --benchmark, never do).
    #[arg(long)]
    pub fresh: bool,
    /// Read the WGSL shaders from this folder (flat, or with passes/ and shaders/ as in the
    /// repository's runtime/src/gpu; files it lacks stay built in) and rebuild the pipelines
    /// whenever one changes: a compile error shows in the panel with its file and line, and
    /// the last good shaders keep drawing.
    #[arg(long)]
    pub shader_dir: Option<PathBuf>,
    /// With no display, render this image headless instead (`visgate render` with the same
    /// scene, level, method, VPLs — 1024 unless given — and --render-size) rather than fail.
    #[arg(long)]
    pub or_render: Option<PathBuf>,
}

pub const VIEW_HELP: &str = "\
In the window: WASD + QE fly (metres per second, scroll to change), right drag looks around,
middle drag orbits about the surface under the pointer, F frames the whole level; the scene's cameras are buttons; the method and its settings apply on
the next frame; a setting the GPU refuses shows its error and keeps the last frame.

Without a display (no DISPLAY or WAYLAND_DISPLAY), use `visgate render`, run under Xvfb
(`Xvfb :99 & DISPLAY=:99 visgate view …`), or give --or-render OUT.png.

Examples:
  visgate bake builtin:four-rooms -o four-rooms.vgate
  visgate view builtin:four-rooms --level four-rooms.vgate
  visgate view builtin:cornell-box --mode val-cssm --rsm --vpls 4096
  visgate view builtin:cornell-box --render-size 320x240 --screenshot shot.png --frames 3
  visgate view builtin:four-rooms --level four-rooms.vgate --shader-dir runtime/src/gpu
  visgate view builtin:four-rooms --benchmark 300 --benchmark-out times.csv
      --benchmark-path camera-path.json   (a path the panel's \"record camera path\" saved)";

/// `--render-size` or `--size` as `[w, h]`.
fn parse_size(s: &str) -> Result<[u32; 2]> {
    let (w, h) = s
        .split_once('x')
        .with_context(|| format!("size '{s}': give WIDTHxHEIGHT, e.g. 640x360"))?;
    let (w, h): (u32, u32) = (w.trim().parse()?, h.trim().parse()?);
    if !(8..=16384).contains(&w) || !(8..=16384).contains(&h) {
        bail!("size {w}x{h}: each side must be 8..=16384 pixels");
    }
    Ok([w, h])
}

/// Whether a window can open here.
fn has_display() -> bool {
    if cfg!(any(target_os = "windows", target_os = "macos")) {
        return true;
    }
    ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

/// `visgate render` with the viewer's scene, level, method and VPLs, headless.
fn render_instead(args: &ViewArgs, mode: &str, out: &std::path::Path) -> Result<()> {
    #[derive(Parser)]
    struct Render {
        #[command(flatten)]
        args: crate::render::RenderArgs,
    }
    let mut argv: Vec<String> = ["render", &args.scene, "--mode", mode, "--vpls"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    // `visgate render`'s 1,024 light paths unless asked (256 left 8×8 squares of interleaving
    // noise at the four rooms' corners; 1,024 take 0.6 s more on lavapipe at 512²).
    argv.push(args.vpls.unwrap_or(1024).to_string());
    argv.extend(["--out".into(), out.display().to_string()]);
    if let Some(l) = &args.level {
        argv.extend(["--level".into(), l.display().to_string()]);
    }
    if args.rsm {
        argv.extend(["--vpl-source".into(), "rsm".into()]);
    }
    if let Some(s) = &args.render_size {
        argv.extend(["--size".into(), s.clone()]);
    }
    if let Some(c) = &args.camera {
        argv.extend(["--camera".into(), c.clone()]);
    }
    argv.extend(["--time".into(), args.time.to_string()]);
    crate::render::run(Render::try_parse_from(argv)?.args)
}

/// The method to start with: `--mode`, else the saved one, else `gates` with a level.
fn start_mode(args: &ViewArgs, saved: Option<&SavedView>) -> Result<&'static MethodInfo> {
    let saved = saved
        .and_then(|s| method(&s.mode))
        .filter(|m| !m.needs_level || args.level.is_some());
    let mode = match (&args.mode, saved, &args.level) {
        (Some(m), _, _) => m.as_str(),
        (None, Some(m), _) => m.name,
        (None, None, Some(_)) => "gates",
        (None, None, None) => "none",
    };
    let Some(info) = method(mode) else {
        bail!(
            "--mode {mode}: give one of {}",
            visgate_runtime::gpu::METHODS.map(|m| m.name).join(", ")
        );
    };
    if info.needs_level && args.level.is_none() {
        bail!("--mode {mode} needs --level LEVEL.vgate (bake one with `visgate bake`)");
    }
    Ok(info)
}

pub fn run(args: ViewArgs) -> Result<()> {
    let size = args.render_size.as_deref().map(parse_size).transpose()?;
    let benchmark_path = args.benchmark_path.as_deref().map(path::read).transpose()?;
    if args.benchmark == Some(0) {
        bail!("--benchmark 0: give the number of frames of the path");
    }
    if args.frames == 0 {
        bail!("--frames 0: render at least 1 frame before the screenshot");
    }
    for (flag, out) in [
        ("--or-render", &args.or_render),
        ("--screenshot", &args.screenshot),
    ] {
        if let Some(out) = out {
            crate::writable(out, flag)?;
        }
    }
    if !has_display() {
        let mode = start_mode(&args, None)?.name;
        if let Some(out) = &args.or_render {
            println!("no display: rendering {} headless instead", out.display());
            return render_instead(&args, mode, out);
        }
        // A scene that cannot load says so first: the advice below would only lead to it.
        crate::load_scene(&args.scene, false)?;
        bail!(
            "no display to open a window on (DISPLAY and WAYLAND_DISPLAY are unset): use \
             `visgate render {} --out image.png`, run the viewer under Xvfb (`Xvfb :99 & \
             DISPLAY=:99 visgate view …`), or give --or-render image.png",
            args.scene
        );
    }
    let mut scene = crate::load_scene(&args.scene, true)?;
    let persist = !args.fresh && args.screenshot.is_none() && args.benchmark.is_none();
    let saved = persist.then(|| state::load(&scene.name)).flatten();
    let info = start_mode(&args, saved.as_ref())?;
    let level = match &args.level {
        Some(path) => {
            let l = visgate_formats::BakedLevel::read(path)
                .with_context(|| format!("cannot read the level {}", path.display()))?;
            Some(GateLevel::new(l, &scene)?)
        }
        None => None,
    };
    crate::bare::light_if_bare(&mut scene, &args.scene);
    let camera = start_camera(&args, &scene)?;
    let layers = start_layers(&args, saved.as_ref())?;
    let g_max = RenderJob::default().for_scene(&scene)?.params.g_max;
    let start = app::Start {
        level,
        mode: info.name,
        vpls: args.vpls.or(saved.as_ref().map(|s| s.vpls)),
        rsm: args.rsm || saved.as_ref().is_some_and(|s| s.rsm),
        size,
        g_max,
        camera,
        screenshot: args.screenshot.clone().map(|p| (p, args.frames)),
        window_shot: args.window_shot.clone(),
        layers,
        compare: args.compare,
        time: args.time,
        benchmark: args.benchmark.zip(args.benchmark_out.clone()),
        benchmark_path,
        record_path: args.record_path.clone(),
        // The saved camera only when no --camera was asked for.
        restore: saved.filter(|_| args.camera.is_none()),
        persist,
        shader_dir: args.shader_dir.clone(),
        scene,
    };
    if !args.time.is_finite() {
        bail!("--time {}: give a finite time in seconds", args.time);
    }
    open_window(start)
}

/// The camera the viewer opens on: --camera's (`level`: none, the level framed), else the
/// scene's first.
fn start_camera(args: &ViewArgs, scene: &visgate_formats::Scene) -> Result<Option<usize>> {
    Ok(match args.camera.as_deref() {
        Some("level") => None,
        Some(name) => Some(
            scene
                .cameras
                .iter()
                .position(|c| c.name == name)
                .with_context(|| format!("--camera {name}: the scene has no such camera"))?,
        ),
        None => (!scene.cameras.is_empty()).then_some(0),
    })
}

/// The debug layers the viewer opens with: --layers, else the saved view's; a level's layers
/// only with --level.
fn start_layers(args: &ViewArgs, saved: Option<&SavedView>) -> Result<layers::Layers> {
    let mut layers = layers::Layers::default();
    if let (true, Some(s)) = (args.layers.is_empty(), saved) {
        let [clusters, gates, skeleton, vpls, indirect, geometry, lists] = s.layers;
        let lv = args.level.is_some();
        layers = layers::Layers {
            clusters: clusters && lv,
            gates: gates && lv,
            skeleton: skeleton && lv,
            vpls,
            indirect,
            geometry: geometry && lv,
            lists: lists && lv,
            vals: s.vals_layer,
        };
    }
    for l in &args.layers {
        match l.as_str() {
            "clusters" => layers.clusters = true,
            "gates" => layers.gates = true,
            "skeleton" => layers.skeleton = true,
            "vpls" => layers.vpls = true,
            "indirect" => layers.indirect = true,
            "geometry" => layers.geometry = true,
            "lists" => layers.lists = true,
            "vals" => layers.vals = true,
            _ => bail!(
                "--layers {l}: give clusters, geometry, lists, gates, skeleton, vpls, vals or \
                 indirect"
            ),
        }
    }
    let needs_level = layers.clusters || layers.geometry || layers.lists;
    if (needs_level || layers.gates || layers.skeleton) && args.level.is_none() {
        bail!(
            "--layers clusters, geometry, lists, gates and skeleton draw a baked level: give --level"
        );
    }
    Ok(layers)
}

/// Opens the window on `start` and runs it until it closes.
fn open_window(start: app::Start) -> Result<()> {
    let options = eframe::NativeOptions {
        viewport: eframe::egui::ViewportBuilder::default()
            .with_inner_size([1280.0, 760.0])
            .with_title("visgate"),
        renderer: eframe::Renderer::Wgpu,
        wgpu_options: wgpu_options(),
        ..Default::default()
    };
    eframe::run_native(
        "visgate",
        options,
        Box::new(move |cc| {
            let window = (cc.wgpu_render_state.clone())
                .ok_or("the window has no wgpu device (eframe's wgpu renderer is required)")?;
            Ok(Box::new(app::ViewerApp::new(start, window)?))
        }),
    )
    .map_err(|e| anyhow::anyhow!("the window failed: {e}"))
}

/// The window's wgpu set-up: the backends `WGPU_BACKEND` names, else Vulkan, Metal and DX12;
/// the device asked for as `visgate render` asks (`GpuContext::device_descriptor`: the
/// methods' limits, timestamp queries), so that the viewer renders on the window's device and
/// shows the frame from its texture.
pub fn wgpu_setup() -> eframe::egui_wgpu::WgpuSetupCreateNew {
    let mut setup = eframe::egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    setup.instance_descriptor.backends = GpuContext::primary_backends();
    setup.device_descriptor = std::sync::Arc::new(GpuContext::device_descriptor);
    setup
}

/// eframe's wgpu configuration with [`wgpu_setup`].
fn wgpu_options() -> eframe::egui_wgpu::WgpuConfiguration {
    eframe::egui_wgpu::WgpuConfiguration {
        wgpu_setup: eframe::egui_wgpu::WgpuSetup::CreateNew(wgpu_setup()),
        ..Default::default()
    }
}
