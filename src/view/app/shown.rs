//! What the central panel shows: the frame tone-mapped on the GPU and handed to egui as a
//! native texture (no readback), or the indirect layer's image from the CPU; the split view
//! and the layers over it.

use eframe::egui;
use eframe::egui_wgpu::wgpu;

use visgate_runtime::camera::View;

use super::ViewerApp;
use crate::view::layers;

impl ViewerApp {
    /// Whether the next frame must come back to the CPU: for the reference's figures and
    /// split view, the indirect layer (a frame less its direct light) and a screenshot; a frame
    /// only looked at stays on the GPU.
    pub(super) fn needs_hdr(&self) -> bool {
        self.start.screenshot.is_some()
            || self.start.compare
            || self.compare.is_active()
            || self.layers.indirect
    }

    /// The texture of what the panel shows (drawn again when the frame, the exposure or the
    /// image shown changed, not on every repaint: a pointer move repaints too): the frame
    /// tone-mapped on the GPU, or the indirect layer's image from the CPU.
    fn shown_texture(&mut self, ui: &egui::Ui) -> Option<egui::TextureId> {
        let key = (self.frames, self.exposure, self.indirect.is_some());
        if self.last.is_some() && self.texture_key != Some(key) {
            self.texture_key = Some(key);
            match &self.indirect {
                Some(img) => {
                    let rgb = img.to_srgb8(self.exposure);
                    let size = [img.width as usize, img.height as usize];
                    let colour = egui::ColorImage::from_rgb(size, rgb.as_raw());
                    match &mut self.texture {
                        Some(t) => t.set(colour, egui::TextureOptions::LINEAR),
                        None => {
                            let o = egui::TextureOptions::LINEAR;
                            self.texture = Some(ui.ctx().load_texture("indirect", colour, o));
                        }
                    }
                }
                None => match self.gpu.display(&self.ctx, self.exposure) {
                    Ok(tex) => self.register(&tex),
                    Err(e) => self.error = Some(e.to_string()),
                },
            }
        }
        match &self.indirect {
            Some(_) => self.texture.as_ref().map(|t| t.id()),
            None => self.native,
        }
    }

    /// Hands the frame's display texture to egui's renderer (a new texture when the size
    /// changed; the same id throughout).
    fn register(&mut self, tex: &wgpu::Texture) {
        let view = tex.create_view(&Default::default());
        let device = &self.window.device;
        let filter = wgpu::FilterMode::Linear;
        let mut r = self.window.renderer.write();
        match self.native {
            Some(id) => r.update_egui_texture_from_wgpu_texture(device, &view, filter, id),
            None => self.native = Some(r.register_native_texture(device, &view, filter)),
        }
    }

    /// Shows the last frame, fitted into the panel.
    pub(super) fn show_image(&mut self, ui: &mut egui::Ui) -> egui::Response {
        let avail = ui.available_size();
        let shown = self.shown_texture(ui);
        let (rect, response) = ui.allocate_exact_size(avail, egui::Sense::click_and_drag());
        if let (Some(t), Some(view)) = (shown, self.last_view) {
            let aspect = view.size[0] as f32 / view.size[1].max(1) as f32;
            let mut size = rect.size();
            if size.x / size.y.max(1.0) > aspect {
                size.x = size.y * aspect;
            } else {
                size.y = size.x / aspect;
            }
            let fitted = egui::Rect::from_center_size(rect.center(), size);
            self.image_rect = Some(fitted);
            let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
            ui.painter().image(t, fitted, uv, egui::Color32::WHITE);
            if let Some((Some(img), _)) = &self.last {
                self.compare.draw(ui, fitted, img, self.exposure, &response);
            }
            self.draw_layers(ui, fitted, &response);
        }
        response
    }

    /// The debug layers over the frame at `rect`, and what lies under the pointer.
    fn draw_layers(&mut self, ui: &egui::Ui, rect: egui::Rect, response: &egui::Response) {
        let Some(view) = self.last_view else {
            return;
        };
        let level = self.start.level.as_ref();
        if let (Some(which), Some(l)) = (self.layers.pixel_layer(), level) {
            // At most 320 pixels wide: a CPU ray per pixel.
            let k = (view.size[0] as f32 / 320.0).max(1.0);
            let small = [
                ((view.size[0] as f32 / k) as u32).max(1),
                ((view.size[1] as f32 / k) as u32).max(1),
            ];
            let fresh = self.cluster_tex.as_ref().is_some_and(|(v, w, _)| {
                v.eye == view.eye && v.forward == view.forward && v.size == small && *w == which
            });
            let cam = visgate_formats::Camera {
                name: "frame".into(),
                eye: view.eye,
                target: view.eye + view.forward,
                up: view.up,
                fov_x_rad: view.fov_x_rad,
            };
            if !fresh && let Ok(sv) = View::new(&cam, small) {
                let img = match which {
                    layers::PixelLayer::Clusters => {
                        layers::cluster_image(&sv, &layers::pixel_clusters(&sv, &self.tracer, l))
                    }
                    _ => {
                        let vpls = self.vpls.as_ref().map_or(&[][..], |v| &v.1[..]);
                        let g = &self.settings.gates;
                        // The GPU's tiles, at this view's scale.
                        let tile = ((g.clusters.tile_px as f32 / k).round() as u32).max(1);
                        layers::clustered_image(&sv, &self.tracer, l, vpls, &g.gates, tile, which)
                    }
                };
                let tex = ui
                    .ctx()
                    .load_texture("pixel layer", img, egui::TextureOptions::NEAREST);
                self.cluster_tex = Some((sv, which, tex));
            }
            if let Some((_, _, t)) = &self.cluster_tex {
                let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
                let tint = egui::Color32::from_white_alpha(150);
                ui.painter().image(t.id(), rect, uv, tint);
            }
        }
        let vpls = self.vpls.as_ref().map_or(&[][..], |v| &v.1[..]);
        let painter = ui.painter().with_clip_rect(rect);
        let vals = self.val_disks.as_ref().map_or(&[][..], |v| &v.1[..]);
        let lines = (level, vpls, &self.portal_lines[..], vals);
        layers::draw_lines(&painter, rect, &view, self.layers, lines);
        if let Some(pos) = response.hover_pos().filter(|p| rect.contains(*p)) {
            let p = glam::Vec2::new(
                (pos.x - rect.left()) / rect.width() * view.size[0] as f32,
                (pos.y - rect.top()) / rect.height() * view.size[1] as f32,
            );
            let gates = self.settings.gates.gates;
            let text = layers::probe(&view, p, &self.tracer, level, vpls, &gates);
            // On a dark band: white on a lit wall or a bright floor could not be read. Not
            // clipped to the frame: a long line runs on past a narrow one.
            let window = ui.painter();
            let galley =
                window.layout_no_wrap(text, egui::FontId::monospace(12.0), egui::Color32::WHITE);
            let at = rect.left_bottom() + egui::vec2(4.0, -4.0 - galley.size().y);
            let band = egui::Rect::from_min_size(at, galley.size()).expand(2.0);
            window.rect_filled(band, 2.0, egui::Color32::from_black_alpha(170));
            window.galley(at, galley, egui::Color32::WHITE);
        }
    }
}
