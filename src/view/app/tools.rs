//! The viewer's tools for the people who work on the methods: shader hot reload
//! (`--shader-dir`), recording a camera path for the benchmark, and the VAL layer's
//! clustering.

use eframe::egui;
use visgate_runtime::gpu::GpuMode;

use super::ViewerApp;
use crate::view::layers;
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

    /// The VAL layer: the VALs of `mode` (a VAL mode; none otherwise) clustered from this
    /// frame's VPLs on the GPU, again only when the VPLs or the clustering changed.
    pub(super) fn update_val_layer(&mut self, mode: &GpuMode) {
        let Some(params) = mode.vals() else {
            self.val_disks = None;
            return;
        };
        let key = format!(
            "{params:?} {} {} {}",
            self.vpl_count, self.start.rsm, self.time
        );
        if self.val_disks.as_ref().is_some_and(|(k, _)| *k == key) {
            return;
        }
        let vpls = match (self.start.rsm, &self.vpls) {
            (true, _) => {
                let r = self.rsm_params();
                self.gpu.rsm_vpls(&self.ctx, r.count, r.rsm_size, r.seed)
            }
            (false, Some((_, v))) => Ok(v.clone()),
            (false, None) => Ok(Vec::new()),
        };
        // The renderer's clustering buffers hold this clustering afterwards: the next frame's
        // warm start begins from it (the same VPLs, clustered cold), not from its own last.
        match vpls.and_then(|v| self.gpu.cluster_vals(&self.ctx, &v, &params)) {
            Ok(c) => self.val_disks = Some((key, layers::val_disks(&c.vals))),
            Err(e) => self.error = Some(format!("VAL layer: {e}")),
        }
    }
}
