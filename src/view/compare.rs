//! Compare in the viewer: the exact CPU reference of the current view (the same VPLs and clamp)
//! rendered on a background thread, then shown beside the method with a draggable divider, or
//! as a false-colour error map, with the error figures. A camera that moves makes it stale: its
//! result is dropped and the next one starts from the new view.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{Receiver, channel};

use eframe::egui;
use visgate_formats::Scene;
use visgate_runtime::camera::View;
use visgate_runtime::cpu::reference::{IndirectVisibility, ReferenceParams, render_cancellable};
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::hdr::{HdrImage, false_colour};
use visgate_runtime::metrics::{ImageErrors, IndirectErrors, errors, indirect_errors};
use visgate_runtime::vpl::{GatherParams, Vpl};

/// The reference and the direct light alone, of one view.
type Pair = Result<(HdrImage, HdrImage), String>;

/// A reference being rendered: its view, the result to come, rows done, the flag that stops it.
type Running = (View, Receiver<Pair>, Arc<AtomicU32>, Arc<AtomicBool>);

/// A reference being rendered or done.
pub struct Compare {
    running: Option<Running>,
    done: Option<(View, HdrImage, HdrImage)>,
    /// Where the divider is, as a fraction of the image's width (method left, reference right).
    pub split: f32,
    /// Show the error map instead of the reference.
    pub error_map: bool,
    texture: Option<(bool, egui::TextureHandle)>,
    error: Option<String>,
}

impl Compare {
    pub fn new() -> Compare {
        Compare {
            running: None,
            done: None,
            split: 0.5,
            error_map: false,
            texture: None,
            error: None,
        }
    }

    /// Stops the reference being rendered, if any (its thread ends at its next row).
    fn cancel(&mut self) {
        if let Some((.., stop)) = self.running.take() {
            stop.store(true, Ordering::Relaxed);
        }
    }

    /// Whether a reference is shown.
    pub fn is_done(&self) -> bool {
        self.done.is_some()
    }

    /// Whether a reference is being rendered or shown (the frames must come back to the CPU).
    pub fn is_active(&self) -> bool {
        self.running.is_some() || self.done.is_some()
    }

    /// Starts the reference of `view` with `vpls` on a thread.
    pub fn start(&mut self, scene: &Scene, view: &View, vpls: &[Vpl], g_max: f32) {
        self.cancel();
        let (tx, rx) = channel();
        let rows = Arc::new(AtomicU32::new(0));
        let cancel = Arc::new(AtomicBool::new(false));
        let cancel_t = cancel.clone();
        let (scene, view_t, vpls, rows_t) = (scene.clone(), *view, vpls.to_vec(), rows.clone());
        std::thread::spawn(move || {
            let tracer = Tracer::new(&scene);
            let params = ReferenceParams {
                samples_per_pixel: 1,
                gather: GatherParams { g_max },
                ..ReferenceParams::default()
            };
            let progress = |done: u32, _| rows_t.store(done, Ordering::Relaxed);
            let run = |p: ReferenceParams| {
                render_cancellable(
                    &tracer,
                    &scene.lights,
                    &vpls,
                    &view_t,
                    &p,
                    IndirectVisibility::Exact,
                    &progress,
                    &cancel_t,
                )
                .map(|r| r.0)
                .map_err(|e| e.to_string())
            };
            let direct = ReferenceParams {
                indirect: false,
                ..params
            };
            let _ = tx.send(run(params).and_then(|r| Ok((r, run(direct)?))));
        });
        self.running = Some((*view, rx, rows, cancel));
        self.done = None;
        self.texture = None;
        self.error = None;
    }

    /// Takes a finished reference; drops one whose view is no longer `view`.
    pub fn poll(&mut self, view: Option<&View>) {
        if let Some((v, rx, _, _)) = &self.running
            && let Ok(r) = rx.try_recv()
        {
            match r {
                Ok((reference, direct)) => self.done = Some((*v, reference, direct)),
                Err(e) => self.error = Some(e),
            }
            self.running = None;
        }
        let stale = |v: &View| view != Some(v);
        if self.done.as_ref().is_some_and(|(v, _, _)| stale(v)) {
            self.done = None;
            self.texture = None;
        }
        if self.running.as_ref().is_some_and(|(v, ..)| stale(v)) {
            self.cancel();
        }
    }

    /// The panel section: start, progress, the figures of `image` against the reference.
    pub fn panel(&mut self, ui: &mut egui::Ui, image: Option<&HdrImage>) -> bool {
        let mut start = false;
        ui.label("Reference (exact CPU, the same VPLs)");
        match (&self.running, &self.done) {
            (Some((v, _, rows, _)), _) => {
                let f = rows.load(Ordering::Relaxed) as f32 / v.size[1].max(1) as f32;
                ui.add(egui::ProgressBar::new(f).text("rendering; moving cancels it"));
                ui.ctx().request_repaint();
            }
            (None, Some((_, reference, direct))) => {
                if let Some(img) = image
                    && let (Ok(e), Ok(i)) = (
                        errors(img, reference),
                        indirect_errors(img, reference, direct),
                    )
                {
                    figures(ui, &e, &i);
                }
                ui.add(egui::Slider::new(&mut self.split, 0.0..=1.0).text("divider"));
                ui.checkbox(&mut self.error_map, "error map (|method − reference|)");
            }
            (None, None) => start = ui.button("render the reference of this view").clicked(),
        }
        if let Some(e) = &self.error {
            ui.colored_label(egui::Color32::LIGHT_RED, e);
        }
        start
    }

    /// Draws the reference (or the error map) right of the divider over `rect`; a drag with
    /// the left button moves the divider.
    pub fn draw(
        &mut self,
        ui: &egui::Ui,
        rect: egui::Rect,
        image: &HdrImage,
        exposure: f32,
        response: &egui::Response,
    ) {
        let Some((_, reference, _)) = &self.done else {
            return;
        };
        if response.dragged_by(egui::PointerButton::Primary)
            && let Some(p) = response.interact_pointer_pos()
        {
            self.split = ((p.x - rect.left()) / rect.width()).clamp(0.0, 1.0);
        }
        if self
            .texture
            .as_ref()
            .is_none_or(|(m, _)| *m != self.error_map)
        {
            let rgb = match self.error_map {
                false => reference.to_srgb8(exposure),
                true => {
                    let map = visgate_runtime::metrics::abs_error_map(image, reference)
                        .unwrap_or_default();
                    let max = reference.mean().max_element().max(1e-12);
                    false_colour(&map, image.width, image.height, max)
                }
            };
            let c = egui::ColorImage::from_rgb(
                [rgb.width() as usize, rgb.height() as usize],
                rgb.as_raw(),
            );
            let t = ui
                .ctx()
                .load_texture("reference", c, egui::TextureOptions::LINEAR);
            self.texture = Some((self.error_map, t));
        }
        if let Some((_, t)) = &self.texture {
            let x = rect.left() + self.split * rect.width();
            let right = egui::Rect::from_min_max(egui::pos2(x, rect.top()), rect.right_bottom());
            let uv = egui::Rect::from_min_max(egui::pos2(self.split, 0.0), egui::pos2(1.0, 1.0));
            ui.painter().image(t.id(), right, uv, egui::Color32::WHITE);
            let stroke = egui::Stroke::new(2.0, egui::Color32::WHITE);
            ui.painter().line_segment(
                [egui::pos2(x, rect.top()), egui::pos2(x, rect.bottom())],
                stroke,
            );
        }
    }
}

/// The error figures of a method against the reference.
fn figures(ui: &mut egui::Ui, e: &ImageErrors, i: &IndirectErrors) {
    egui::Grid::new("errors").show(ui, |ui| {
        for (name, value) in [
            ("MSE", format!("{:.3e}", e.mse)),
            ("relative MSE", format!("{:.3e}", e.rel_mse)),
            ("indirect energy", format!("{:.3}", i.energy_ratio)),
            (
                "black where lit",
                format!("{:.1} %", i.black_where_lit * 100.0),
            ),
        ] {
            ui.label(name);
            ui.label(value);
            ui.end_row();
        }
    });
}
