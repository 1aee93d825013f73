//! The viewer's window: the runtime's one frame call (`GpuRenderer::render_kept`, as
//! `visgate render` makes it) on the window's own device, the frame tone-mapped on the GPU and
//! drawn from its texture in the central panel (egui's `register_native_texture`; read back
//! only for the reference, the indirect layer and screenshots), the method and its settings in
//! a side panel applied on the next frame, a fly camera, live pass times.

use std::collections::VecDeque;
use std::path::PathBuf;

use eframe::egui;
use eframe::egui_wgpu::{self, wgpu};
use glam::Vec3;
use visgate_formats::Scene;
use visgate_runtime::camera::View;
use visgate_runtime::cpu::gates::GateLevel;
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::gpu::{
    DirectLight, GpuContext, GpuMode, GpuParams, GpuRenderer, MethodSettings, PassTimes, RsmParams,
    VplInput, method,
};
use visgate_runtime::hdr::HdrImage;
use visgate_runtime::job::RenderJob;
use visgate_runtime::vpl::{PathParams, Vpl, path_vpls};

mod kept;
mod scripted;
mod shown;
mod side;
#[cfg(test)]
mod snapshots;
mod tools;

use super::bench::Bench;
use super::camera::FlyCamera;
use super::compare::Compare;
use super::layers::{self, Layers};
use super::path::Recorder;
use super::shader_watch::ShaderWatch;
use super::state::SavedView;

/// What the viewer starts with.
pub struct Start {
    /// The scene (its animation included; the viewer poses it).
    pub scene: Scene,
    /// The time to pose it at first. [Units: s]
    pub time: f64,
    /// Its baked level, if given.
    pub level: Option<GateLevel>,
    /// The first method's name.
    pub mode: &'static str,
    /// Light paths (or RSM VPLs); `None`: 1024 on a GPU, 64 on a software adapter.
    pub vpls: Option<u32>,
    /// VPLs from the lights' RSMs on the GPU instead of light paths.
    pub rsm: bool,
    /// The render size; `None`: the panel's size.
    pub size: Option<[u32; 2]>,
    /// The geometry-term clamp for this scene. [Units: 1/m²]
    pub g_max: f32,
    /// The scene camera to start from (else the whole level, framed).
    pub camera: Option<usize>,
    /// Write the last frame here after `frames` frames, then close.
    pub screenshot: Option<(PathBuf, u32)>,
    /// Write the whole window (panels and layers) here as PNG with the screenshot.
    pub window_shot: Option<PathBuf>,
    /// The debug layers on at the start.
    pub layers: Layers,
    /// Render the reference of the first view (and wait for it before the screenshot).
    pub compare: bool,
    /// Play a benchmark path of this many frames, write its CSV here, then close.
    pub benchmark: Option<(u32, PathBuf)>,
    /// The benchmark's path (else the scene's cameras).
    pub benchmark_path: Option<Vec<visgate_formats::Camera>>,
    /// Where a recorded camera path is saved.
    pub record_path: PathBuf,
    /// The state of the last run to take the camera, exposure and settings from.
    pub restore: Option<SavedView>,
    /// Save the state when the window closes.
    pub persist: bool,
    /// Read the shaders from this folder and reload them when they change.
    pub shader_dir: Option<PathBuf>,
}

/// The viewer's state.
pub struct ViewerApp {
    start: Start,
    /// Light paths (or RSM VPLs).
    vpl_count: u32,
    ctx: GpuContext,
    gpu: GpuRenderer,
    /// The window's device and egui's renderer (the frame's texture is registered there).
    window: egui_wgpu::RenderState,
    /// The frame's texture as egui knows it.
    native: Option<egui::TextureId>,
    tracer: Tracer,
    /// Light-path VPLs and the path count they were made for.
    vpls: Option<(u32, Vec<Vpl>)>,
    camera: FlyCamera,
    settings: MethodSettings,
    /// The direct lights' shadows (per light, or LightCluster).
    direct: DirectLight,
    /// Render at this fraction of the panel while the camera moves.
    moving_scale: f32,
    exposure: f32,
    /// The indirect layer's image, uploaded from the CPU.
    texture: Option<egui::TextureHandle>,
    /// Frames rendered, exposure and whether the indirect layer showed when it was drawn.
    texture_key: Option<(u32, f32, bool)>,
    /// The last frame's pass times, and its HDR image where it was read back (see
    /// [`ViewerApp::needs_hdr`]).
    last: Option<(Option<HdrImage>, PassTimes)>,
    error: Option<String>,
    /// What the viewer changed of the user's settings, and why (the walk on the closed voxels'
    /// planes where their triangle lists do not fit the adapter).
    notice: Option<String>,
    /// Recent frame times. [Units: ms]
    history: VecDeque<f32>,
    frames: u32,
    /// The view of the last frame (the layers are drawn with it).
    last_view: Option<View>,
    /// The gates' block as the last frame ran it, where its VPLs shrank it (panel::block_note).
    block_note: Option<String>,
    layers: Layers,
    /// The cluster layer and the view it was made for.
    cluster_tex: Option<(View, layers::PixelLayer, egui::TextureHandle)>,
    /// The level's portal outlines, made once (the level does not change).
    portal_lines: Vec<layers::Line>,
    compare: Compare,
    compare_started: bool,
    /// What the last frame was rendered with: a frame with nothing changed is not rendered again.
    last_key: String,
    bench: Option<Bench>,
    /// The scene at `time`.
    posed: Scene,
    /// The scene's time. [Units: s]
    time: f64,
    /// Whether time runs.
    playing: bool,
    /// Where the frame was drawn last.
    image_rect: Option<egui::Rect>,
    /// The point a middle drag orbits about.
    pivot: Option<Vec3>,
    /// The last frame's indirect light alone, when that layer is on.
    indirect: Option<HdrImage>,
    /// The state last saved, and when.
    last_saved: Option<(SavedView, std::time::Instant)>,
    /// `--shader-dir`: the watched folder of shaders.
    shaders: Option<ShaderWatch>,
    /// The VAL layer's disks and what they were clustered for.
    val_disks: Option<(String, Vec<layers::ValDisk>)>,
    /// The camera path being recorded, and what the last recording did.
    recorder: Option<Recorder>,
    record_note: Option<String>,
}

impl ViewerApp {
    /// The viewer of `start`, rendering on `window`'s device (made with
    /// `GpuContext::device_descriptor`: see `super::wgpu_options`).
    pub fn new(start: Start, window: egui_wgpu::RenderState) -> anyhow::Result<ViewerApp> {
        let ctx = GpuContext::from_device(
            window.adapter.get_info(),
            window.device.clone(),
            window.queue.clone(),
        );
        let software = ctx.adapter_info.device_type == wgpu::DeviceType::Cpu;
        let vpl_count = start.vpls.unwrap_or(if software { 64 } else { 1024 });
        // On a software adapter the gates keep their block at few VPLs too: its cost grows
        // with the VPLs a pixel walks (64 VPLs would run in 2 × 2 blocks).
        let mut settings = crate::view::panel::start_settings();
        if software {
            settings = settings.with_min_vpls(0);
            println!(
                "{}: a software adapter; {vpl_count} VPLs, 8 × 8 interleaving blocks whatever \
                 their count, and a quarter of the resolution while moving keep it walkable",
                ctx.adapter_info.name
            );
        }
        let posed = start.scene.at(start.time);
        let mut gpu = GpuRenderer::new(&ctx, &posed)?;
        if let Some(l) = &start.level {
            gpu.set_level(&ctx, l)?;
        }
        let shaders = match &start.shader_dir {
            Some(dir) => Some(ShaderWatch::start(dir, &ctx, &mut gpu)?),
            None => None,
        };
        let (lo, hi) = start.scene.bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
        let speed = FlyCamera::speed_for(lo, hi);
        let camera = match start.camera.and_then(|i| start.scene.cameras.get(i)) {
            Some(c) => FlyCamera::from_camera(c, speed),
            None => FlyCamera::framing(lo, hi),
        };
        let mut app = ViewerApp {
            tracer: Tracer::new(&posed),
            posed,
            time: start.time,
            playing: false,
            image_rect: None,
            pivot: None,
            indirect: None,
            last_saved: None,
            shaders,
            recorder: None,
            record_note: None,
            val_disks: None,
            ctx,
            gpu,
            window,
            native: None,
            vpls: None,
            camera,
            settings,
            direct: DirectLight::PerLight,
            moving_scale: if software { 0.25 } else { 0.5 },
            vpl_count,
            exposure: 0.0,
            texture: None,
            texture_key: None,
            last: None,
            error: None,
            notice: None,
            history: VecDeque::new(),
            frames: 0,
            last_view: None,
            block_note: None,
            layers: start.layers,
            cluster_tex: None,
            portal_lines: start
                .level
                .as_ref()
                .map_or_else(Vec::new, layers::portal_lines),
            compare: Compare::new(),
            compare_started: false,
            last_key: String::new(),
            bench: start
                .benchmark
                .clone()
                .map(|(n, out)| Bench::new(&start.scene, n, out, start.benchmark_path.clone())),
            start,
        };
        if let Some(saved) = app.start.restore.take() {
            println!(
                "restored the last run's view of {} ({})",
                app.start.scene.name, saved.mode
            );
            app.restore(&saved);
        }
        Ok(app)
    }

    /// Renders one frame at `size`; an error keeps the last good frame.
    fn render(&mut self, size: [u32; 2]) {
        let Some(m) = method(self.start.mode) else {
            return;
        };
        let mode = (m.make)(&self.settings);
        let mut params = GpuParams {
            mode,
            g_max: self.start.g_max,
            direct: self.direct,
            ..GpuParams::default()
        };
        let direct_only = mode == GpuMode::DirectOnly;
        if !self.start.rsm
            && !direct_only
            && self.vpls.as_ref().map(|v| v.0) != Some(self.vpl_count)
        {
            match path_vpls(&self.tracer, &self.posed.lights, &self.path_params()) {
                Ok(v) => self.vpls = Some((self.vpl_count, v)),
                Err(e) => {
                    self.error = Some(e.to_string());
                    return;
                }
            }
        }
        let input = match (self.start.rsm, direct_only, &self.vpls) {
            (_, true, _) => VplInput::Given(&[]),
            (true, false, _) => VplInput::Rsm(self.rsm_params()),
            (false, false, Some((_, v))) => VplInput::Given(v),
            (false, false, None) => VplInput::Given(&[]),
        };
        let count = match &input {
            VplInput::Given(v) => v.len() as u32,
            VplInput::Rsm(p) => p.count,
        };
        let read_hdr = self.needs_hdr();
        let key = format!(
            "{params:?} {:?} {size:?} {} {} {} {} {read_hdr}",
            self.camera.camera(),
            self.layers.indirect,
            self.time,
            self.vpl_count,
            self.start.rsm
        );
        let forced =
            self.start.screenshot.is_some() || self.bench.is_some() || self.error.is_some();
        if key == self.last_key && !forced {
            return;
        }
        self.last_key = key;
        let view = match View::new(&self.camera.camera(), size) {
            Ok(v) => v,
            Err(e) => {
                self.error = Some(e.to_string());
                return;
            }
        };
        // The closed voxels' triangles go up when the walk first needs them (the box ticked,
        // or a kept view that had it).
        // Where they do not fit the adapter, the walk on the planes instead, the box unticked.
        if let Some(l) = &self.start.level {
            match (self.gpu).level_for_mode_or_planes(&self.ctx, l, &mut params.mode) {
                Ok(None) => {}
                Ok(Some(note)) => {
                    self.settings.gates.gates.triangles = false;
                    self.settings.gates.gates.planes = true;
                    self.notice = Some(note);
                }
                Err(e) => {
                    self.error = Some(e.to_string());
                    return;
                }
            }
        }
        match (self.gpu).render_kept(&self.ctx, &view, input, &params, read_hdr) {
            Ok((img, times)) => {
                self.last_view = Some(view);
                self.block_note = crate::view::panel::block_note(&params.mode, count);
                self.history.push_back((times.frame_s * 1e3) as f32);
                if self.history.len() > 120 {
                    self.history.pop_front();
                }
                self.indirect = match (&img, self.layers.indirect && !direct_only) {
                    (Some(img), true) => self.indirect_of(&view, img),
                    _ => None,
                };
                self.last = Some((img, times));
                self.error = None;
                self.frames += 1;
                if self.layers.vals {
                    self.update_val_layer(&mode);
                }
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// The surface point under the pointer (else the level's centre).
    fn pick(&self, image: &egui::Response) -> Option<Vec3> {
        let view = self.last_view?;
        let rect = self.image_rect?;
        let pos = image.interact_pointer_pos()?;
        let p = glam::Vec2::new(
            (pos.x - rect.left()) / rect.width() * view.size[0] as f32,
            (pos.y - rect.top()) / rect.height() * view.size[1] as f32,
        );
        let hit = self.tracer.trace(view.eye, view.ray_dir(p));
        let (lo, hi) = self.posed.bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
        Some(hit.map_or((lo + hi) * 0.5, |s| s.position))
    }

    /// Moves the camera from the keyboard and the mouse; true if it moved.
    fn steer(&mut self, ui: &egui::Ui, image: &egui::Response) -> bool {
        let mut moved = false;
        if !ui.ctx().egui_wants_keyboard_input() {
            let (local, dt) = ui.input(|i| {
                let axis = |p: egui::Key, n: egui::Key| {
                    i.key_down(p) as i32 as f32 - i.key_down(n) as i32 as f32
                };
                let local = Vec3::new(
                    axis(egui::Key::D, egui::Key::A),
                    axis(egui::Key::E, egui::Key::Q),
                    axis(egui::Key::W, egui::Key::S),
                );
                (local, i.stable_dt.min(0.1))
            });
            if local != Vec3::ZERO {
                self.camera.fly(local, dt);
                moved = true;
            }
            if ui.input(|i| i.key_pressed(egui::Key::F)) {
                let (lo, hi) = self.start.scene.bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
                self.camera = FlyCamera::framing(lo, hi);
                moved = true;
            }
        }
        // Middle drag orbits about the surface under the pointer where the drag began.
        if image.drag_started_by(egui::PointerButton::Middle) {
            self.pivot = self.pick(image);
        }
        if image.dragged_by(egui::PointerButton::Middle)
            && let Some(p) = self.pivot
        {
            let d = image.drag_delta();
            self.camera.orbit(p, d.x, d.y, 0.006);
            moved = true;
        }
        if image.dragged_by(egui::PointerButton::Secondary) {
            let d = image.drag_delta();
            self.camera.look(d.x, d.y, 0.004);
            moved = true;
        }
        if image.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.camera.speed *= (scroll * 0.01).exp();
            }
        }
        moved
    }

    /// Poses the scene at `t` seconds: geometry and lights on the GPU, the CPU tracer, and
    /// the light paths (made again on the next frame).
    fn set_time(&mut self, t: f64) {
        self.time = t;
        self.posed = self.start.scene.at(t);
        self.gpu.set_scene(&self.ctx, &self.posed);
        self.tracer = Tracer::new(&self.posed);
        self.vpls = None;
    }

    /// The indirect light alone: `img` less a direct-only frame of `view`.
    fn indirect_of(&mut self, view: &View, img: &HdrImage) -> Option<HdrImage> {
        let params = GpuParams {
            mode: GpuMode::DirectOnly,
            g_max: self.start.g_max,
            direct: self.direct,
            ..GpuParams::default()
        };
        let (direct, _) = self
            .gpu
            .render_frame(&self.ctx, view, VplInput::Given(&[]), &params)
            .map_err(|e| self.error = Some(e.to_string()))
            .ok()?;
        let mut out = img.clone();
        for (o, d) in out.pixels.iter_mut().zip(&direct.pixels) {
            *o = (*o - *d).max(Vec3::ZERO);
        }
        Some(out)
    }

    /// The light paths `visgate render` makes by default, `vpl_count` of them.
    fn path_params(&self) -> PathParams {
        let job = RenderJob::default();
        PathParams {
            paths: self.vpl_count,
            bounces: job.bounces,
            seed: job.seed,
        }
    }

    /// The RSM VPLs `visgate render --vpl-source rsm` makes by default, `vpl_count` of them.
    fn rsm_params(&self) -> RsmParams {
        let job = RenderJob::default();
        RsmParams {
            count: self.vpl_count,
            rsm_size: job.rsm_size,
            seed: job.seed,
        }
    }

    /// Starts the reference of the last frame's view, with its VPLs.
    fn start_reference(&mut self) {
        let Some(view) = &self.last_view else {
            return;
        };
        let vpls = match (self.start.rsm, &self.vpls) {
            (true, _) => {
                let r = self.rsm_params();
                match self.gpu.rsm_vpls(&self.ctx, r.count, r.rsm_size, r.seed) {
                    Ok(v) => v,
                    Err(e) => {
                        self.error = Some(e.to_string());
                        return;
                    }
                }
            }
            (false, Some((_, v))) => v.clone(),
            (false, None) => Vec::new(),
        };
        self.compare
            .start(&self.posed, view, &vpls, self.start.g_max);
    }
}

impl eframe::App for ViewerApp {
    fn on_exit(&mut self) {
        self.keep_state(true);
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.draw(ui);
    }
}

impl ViewerApp {
    /// One frame of the window: the side panel, the image (rendered again if anything
    /// changed), the scripted runs' steps.
    pub fn draw(&mut self, ui: &mut egui::Ui) {
        egui::Panel::left("settings")
            .default_size(280.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.side_panel(ui));
            });
        egui::CentralPanel::default().show(ui, |ui| {
            let response = self.show_image(ui);
            let moved = self.steer(ui, &response);
            let full = response.rect.size();
            let size = self.start.size.unwrap_or_else(|| {
                let s = if moved { self.moving_scale } else { 1.0 };
                let ppp = ui.ctx().pixels_per_point();
                [
                    ((full.x * ppp * s) as u32).max(8),
                    ((full.y * ppp * s) as u32).max(8),
                ]
            });
            if self.playing {
                let dt = ui.input(|i| i.stable_dt.min(0.1)) as f64;
                self.set_time(self.time + dt);
                ui.ctx().request_repaint();
            }
            if let Some(b) = &self.bench {
                self.camera = FlyCamera::from_camera(&b.camera(b.done), self.camera.speed);
            }
            self.watch_shaders(ui.ctx());
            if let Some(r) = &mut self.recorder {
                r.push(self.camera.camera(), std::time::Instant::now());
                ui.ctx().request_repaint_after(Recorder::STEP);
            }
            let before = self.frames;
            self.render(size);
            if self.frames > before {
                // Shown on the next pass (the image was laid out before this frame was made).
                ui.ctx().request_repaint();
            }
            self.bench_step(ui.ctx(), before);
            self.compare.poll(self.last_view.as_ref());
            if self.start.compare && !self.compare_started && self.last_view.is_some() {
                self.compare_started = true;
                self.start_reference();
            }
            if moved {
                ui.ctx().request_repaint();
            }
        });
        self.screenshot_done(ui.ctx());
        self.keep_state(false);
        if self.start.screenshot.is_some() {
            ui.ctx().request_repaint();
        }
    }
}
