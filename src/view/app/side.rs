//! The viewer's side panel: the method and its settings, the direct shadows, the VPLs, the
//! debug layers, the reference beside the method, the camera, the animation's time and the
//! frame's passes.

use eframe::egui;
use visgate_runtime::gpu::METHODS;

use super::ViewerApp;

impl ViewerApp {
    /// The side panel: method, its settings, the camera, the frame's passes.
    pub(super) fn side_panel(&mut self, ui: &mut egui::Ui) {
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
        crate::view::panel::method_settings(ui, self.start.mode, &mut self.settings);
        if let Some(n) = &self.block_note {
            ui.label(n);
        }
        // What the viewer changed of these settings, under them, where it is seen.
        if let Some(n) = &self.notice {
            ui.colored_label(egui::Color32::YELLOW, n);
        }
        crate::view::panel::direct_settings(ui, &mut self.direct);
        ui.add(
            egui::Slider::new(&mut self.vpl_count, 1..=16384)
                .logarithmic(true)
                .text("VPLs (paths)"),
        );
        ui.checkbox(&mut self.start.rsm, "VPLs from the lights' RSMs");
        ui.add(egui::Slider::new(&mut self.exposure, -8.0..=8.0).text("exposure (stops)"));
        ui.add(egui::Slider::new(&mut self.moving_scale, 0.125..=1.0).text("resolution moving"));
        ui.separator();
        let has_level = self.start.level.is_some();
        let l = &mut self.layers;
        // The layers a baked level draws, then those any frame has.
        ui.add_enabled_ui(has_level, |ui| {
            for (on, label) in [
                (&mut l.clusters, "visibility cluster of each pixel"),
                (&mut l.geometry, "geometry cluster of each pixel"),
                (&mut l.lists, "light-list length (blue short, red long)"),
                (&mut l.gates, "gates"),
                (&mut l.skeleton, "skeleton (blue narrow, red wide)"),
            ] {
                ui.checkbox(on, label);
            }
        });
        for (on, label) in [
            (&mut l.vpls, "VPLs (colour: flux)"),
            (&mut l.vals, "VALs (VAL modes: disks of their area)"),
            (&mut l.indirect, "indirect light alone"),
        ] {
            ui.checkbox(on, label);
        }
        ui.separator();
        let image = self.last.as_ref().and_then(|(img, _)| img.as_ref());
        if self.compare.panel(ui, image) {
            self.start_reference();
        }
        ui.separator();
        crate::view::panel::camera_controls(ui, &mut self.camera, &self.start.scene);
        self.record_controls(ui);
        if self.start.scene.is_animated() {
            ui.separator();
            ui.horizontal(|ui| {
                ui.checkbox(&mut self.playing, "play");
                let mut t = self.time;
                if ui
                    .add(egui::Slider::new(&mut t, 0.0..=30.0).text("time (s)"))
                    .changed()
                {
                    self.set_time(t);
                }
            });
        }
        ui.separator();
        if let Some(w) = &self.shaders {
            crate::view::panel::shader_status(ui, w);
        }
        if let Some(e) = &self.error {
            ui.colored_label(
                egui::Color32::LIGHT_RED,
                format!("kept the last frame: {e}"),
            );
        }
        if let (Some((_, times)), Some(view)) = (&self.last, &self.last_view) {
            crate::view::panel::pass_times(ui, view.size, times, &self.history);
        }
    }
}
