//! The viewer's tools for the people who work on the methods: shader hot reload
//! (`--shader-dir`) and recording a camera path for the benchmark.

use eframe::egui;

use super::ViewerApp;
use crate::view::path::Recorder;

impl ViewerApp {
    /// `--shader-dir`: rebuilds the pipelines when a shader file changed (the next frame is
    /// rendered again), and looks again soon.
    pub(super) fn watch_shaders(&mut self, ctx: &egui::Context) {
        let Some(w) = &mut self.shaders else {
            return;
        };
        if w.changed() && w.reload(&self.ctx, &mut self.gpu) {
            self.last_key.clear();
        }
        ctx.request_repaint_after(crate::view::shader_watch::POLL);
    }

    /// Records the camera's path and saves it for `--benchmark-path`.
    pub(super) fn record_controls(&mut self, ui: &mut egui::Ui) {
        let file = self.start.record_path.clone();
        match &self.recorder {
            None => {
                if ui.button("record camera path").clicked() {
                    self.recorder = Some(Recorder::default());
                }
            }
            Some(r) => {
                let n = r.cameras.len();
                if ui
                    .button(format!("stop recording and save ({n} cameras)"))
                    .clicked()
                {
                    let scene = &self.start.scene.name;
                    self.record_note =
                        Some(match crate::view::path::write(&file, scene, &r.cameras) {
                            Ok(()) if n >= 2 => format!(
                                "saved {n} cameras to {}: replay with --benchmark 300 \
                             --benchmark-path {0} --benchmark-out times.csv",
                                file.display()
                            ),
                            Ok(()) => format!(
                                "saved {n} camera(s) to {}: move while recording, a path needs two",
                                file.display()
                            ),
                            Err(e) => format!("not saved: {e:#}"),
                        });
                    println!("{}", self.record_note.as_deref().unwrap_or_default());
                    self.recorder = None;
                }
            }
        }
        if let Some(note) = &self.record_note {
            ui.label(note);
        }
    }
}
