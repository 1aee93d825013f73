//! The viewer's window: the runtime's one frame call (`GpuRenderer::render_frame`, as
//! `visgate render` makes it) drawn in the central panel, the method and its settings in a side
//! panel applied on the next frame, a fly camera, live pass times.

use std::collections::VecDeque;
use std::path::PathBuf;

use eframe::egui;
use glam::Vec3;
use visgate_formats::Scene;
use visgate_runtime::camera::View;
use visgate_runtime::cpu::gates::GateLevel;
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::gpu::{
    GpuContext, GpuMode, GpuParams, GpuRenderer, METHODS, MethodSettings, PassTimes, RsmParams,
    VplInput, method,
};
use visgate_runtime::hdr::HdrImage;
use visgate_runtime::vpl::{PathParams, Vpl, path_vpls};

use super::camera::FlyCamera;

/// What the viewer starts with.
pub struct Start {
    /// The scene, posed at time 0.
    pub scene: Scene,
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
}

/// The viewer's state.
pub struct ViewerApp {
    start: Start,
    /// Light paths (or RSM VPLs).
    vpl_count: u32,
    ctx: GpuContext,
    gpu: GpuRenderer,
    tracer: Tracer,
    /// Light-path VPLs and the path count they were made for.
    vpls: Option<(u32, Vec<Vpl>)>,
    camera: FlyCamera,
    settings: MethodSettings,
    /// Render at this fraction of the panel while the camera moves.
    moving_scale: f32,
    exposure: f32,
    texture: Option<egui::TextureHandle>,
    last: Option<(HdrImage, PassTimes)>,
    error: Option<String>,
    /// Recent frame times. [Units: ms]
    history: VecDeque<f32>,
    frames: u32,
}

impl ViewerApp {
    /// The viewer of `start`, on its own device.
    pub fn new(start: Start) -> anyhow::Result<ViewerApp> {
        let ctx = GpuContext::new()?;
        let software = ctx.adapter_info.device_type == eframe::wgpu::DeviceType::Cpu;
        let vpl_count = start.vpls.unwrap_or(if software { 64 } else { 1024 });
        if software {
            println!(
                "{}: a software adapter; {vpl_count} VPLs and a quarter of the resolution while \
                 moving keep it walkable",
                ctx.adapter_info.name
            );
        }
        let mut gpu = GpuRenderer::new(&ctx, &start.scene)?;
        if let Some(l) = &start.level {
            gpu.set_level(&ctx, l)?;
        }
        let (lo, hi) = start.scene.bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
        let speed = FlyCamera::speed_for(lo, hi);
        let camera = match start.camera.and_then(|i| start.scene.cameras.get(i)) {
            Some(c) => FlyCamera::from_camera(c, speed),
            None => FlyCamera::framing(lo, hi),
        };
        Ok(ViewerApp {
            tracer: Tracer::new(&start.scene),
            ctx,
            gpu,
            vpls: None,
            camera,
            settings: MethodSettings::default(),
            moving_scale: if software { 0.25 } else { 0.5 },
            vpl_count,
            exposure: 0.0,
            texture: None,
            last: None,
            error: None,
            history: VecDeque::new(),
            frames: 0,
            start,
        })
    }

    /// Renders one frame at `size`; an error keeps the last good frame.
    fn render(&mut self, size: [u32; 2]) {
        let Some(m) = method(self.start.mode) else {
            return;
        };
        let mode = (m.make)(&self.settings);
        let params = GpuParams {
            mode,
            g_max: self.start.g_max,
            ..GpuParams::default()
        };
        let direct_only = mode == GpuMode::DirectOnly;
        if !self.start.rsm
            && !direct_only
            && self.vpls.as_ref().map(|v| v.0) != Some(self.vpl_count)
        {
            let paths = PathParams {
                paths: self.vpl_count,
                bounces: 1,
                seed: 1,
            };
            match path_vpls(&self.tracer, &self.start.scene.lights, &paths) {
                Ok(v) => self.vpls = Some((self.vpl_count, v)),
                Err(e) => {
                    self.error = Some(e.to_string());
                    return;
                }
            }
        }
        let input = match (self.start.rsm, direct_only, &self.vpls) {
            (_, true, _) => VplInput::Given(&[]),
            (true, false, _) => VplInput::Rsm(RsmParams {
                count: self.vpl_count,
                rsm_size: 256,
                seed: 1,
            }),
            (false, false, Some((_, v))) => VplInput::Given(v),
            (false, false, None) => VplInput::Given(&[]),
        };
        let result = View::new(&self.camera.camera(), size)
            .and_then(|view| self.gpu.render_frame(&self.ctx, &view, input, &params));
        match result {
            Ok((img, times)) => {
                self.history.push_back((times.frame_s * 1e3) as f32);
                if self.history.len() > 120 {
                    self.history.pop_front();
                }
                self.last = Some((img, times));
                self.error = None;
                self.frames += 1;
            }
            Err(e) => self.error = Some(e.to_string()),
        }
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

    /// The side panel: method, its settings, the camera, the frame's passes.
    fn side_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("visgate");
        ui.label(&self.start.scene.name);
        egui::ComboBox::from_label("method")
            .selected_text(self.start.mode)
            .show_ui(ui, |ui| {
                for m in METHODS {
                    let ok = !m.needs_level || self.start.level.is_some();
                    ui.add_enabled_ui(ok, |ui| {
                        ui.selectable_value(&mut self.start.mode, m.name, m.name)
                            .on_hover_text(m.summary)
                    });
                }
            });
        super::panel::method_settings(ui, self.start.mode, &mut self.settings);
        ui.add(
            egui::Slider::new(&mut self.vpl_count, 1..=16384)
                .logarithmic(true)
                .text("VPLs (paths)"),
        );
        ui.checkbox(&mut self.start.rsm, "VPLs from the lights' RSMs");
        ui.add(egui::Slider::new(&mut self.exposure, -8.0..=8.0).text("exposure (stops)"));
        ui.add(egui::Slider::new(&mut self.moving_scale, 0.125..=1.0).text("resolution moving"));
        ui.separator();
        super::panel::camera_controls(ui, &mut self.camera, &self.start.scene);
        ui.separator();
        if let Some(e) = &self.error {
            ui.colored_label(
                egui::Color32::LIGHT_RED,
                format!("kept the last frame: {e}"),
            );
        }
        if let Some((img, times)) = &self.last {
            super::panel::pass_times(ui, img, times, &self.history);
        }
    }

    /// Shows the last frame, fitted into the panel.
    fn show_image(&mut self, ui: &mut egui::Ui) -> egui::Response {
        let avail = ui.available_size();
        if let Some((img, _)) = &self.last {
            let rgb = img.to_srgb8(self.exposure);
            let colour =
                egui::ColorImage::from_rgb([img.width as usize, img.height as usize], rgb.as_raw());
            match &mut self.texture {
                Some(t) => t.set(colour, egui::TextureOptions::LINEAR),
                None => {
                    self.texture = Some(ui.ctx().load_texture(
                        "frame",
                        colour,
                        egui::TextureOptions::LINEAR,
                    ))
                }
            }
        }
        let (rect, response) = ui.allocate_exact_size(avail, egui::Sense::click_and_drag());
        if let (Some(t), Some((img, _))) = (&self.texture, &self.last) {
            let aspect = img.width as f32 / img.height.max(1) as f32;
            let mut size = rect.size();
            if size.x / size.y.max(1.0) > aspect {
                size.x = size.y * aspect;
            } else {
                size.y = size.x / aspect;
            }
            let fitted = egui::Rect::from_center_size(rect.center(), size);
            let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
            ui.painter().image(t.id(), fitted, uv, egui::Color32::WHITE);
        }
        response
    }

    /// Writes the screenshot and closes the window once its frames are rendered.
    fn screenshot_done(&mut self, ctx: &egui::Context) {
        let Some((path, frames)) = &self.start.screenshot else {
            return;
        };
        if self.frames < *frames {
            return;
        }
        let outcome = match &self.last {
            Some((img, _)) => img.write(path, self.exposure).map_err(|e| e.to_string()),
            None => Err(self
                .error
                .clone()
                .unwrap_or_else(|| "no frame rendered".into())),
        };
        match outcome {
            Ok(()) => {
                if let Some((img, times)) = &self.last {
                    println!("last frame, {} x {}:", img.width, img.height);
                    print!("{}", visgate_runtime::job::pass_table(times));
                }
                println!("wrote {} after {} frames", path.display(), self.frames)
            }
            Err(e) => eprintln!("error: screenshot {}: {e}", path.display()),
        }
        self.start.screenshot = None;
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
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
            self.render(size);
            if moved {
                ui.ctx().request_repaint();
            }
        });
        self.screenshot_done(ui.ctx());
        if self.start.screenshot.is_some() {
            ui.ctx().request_repaint();
        }
    }
}
