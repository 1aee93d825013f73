//! The viewer's scripted runs: the benchmark's frames, the screenshots, closing after them.

use eframe::egui;

use super::ViewerApp;

impl ViewerApp {
    /// Records a benchmark frame (if one was rendered since `before`); writes the CSV and
    /// closes after the last.
    pub(super) fn bench_step(&mut self, ctx: &egui::Context, before: u32) {
        let Some(b) = &mut self.bench else {
            return;
        };
        if self.frames > before
            && let Some((_, t)) = &self.last
        {
            b.record(t);
        }
        if b.done >= b.frames {
            match b.finish() {
                Ok(s) => println!("{s}"),
                Err(e) => eprintln!("error: benchmark: {e}"),
            }
            self.bench = None;
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        } else if let Some(e) = &self.error {
            eprintln!("error: benchmark frame {}: {e}", b.done);
            self.bench = None;
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
        ctx.request_repaint();
    }

    /// Writes the frame to `path`: EXR the linear image, PNG what the window shows (the
    /// display texture read back; the indirect layer's image when that layer is on).
    fn write_screenshot(&mut self, path: &std::path::Path) -> Result<(), String> {
        let png = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if png && self.indirect.is_none() {
            let e = |e: visgate_runtime::RenderError| e.to_string();
            let tex = self.gpu.display(&self.ctx, self.exposure).map_err(e)?;
            let shown = visgate_runtime::gpu::read_display(&self.ctx, &tex).map_err(e)?;
            return (shown.save(path)).map_err(|err| format!("{}: {err}", path.display()));
        }
        let img = match (&self.indirect, &self.last) {
            (Some(indirect), _) if png => indirect,
            (_, Some((Some(img), _))) => img,
            _ => return Err("the frame was not read back".into()),
        };
        img.write(path, self.exposure).map_err(|e| e.to_string())
    }

    /// Writes the screenshot and closes the window once its frames are rendered.
    pub(super) fn screenshot_done(&mut self, ctx: &egui::Context) {
        let Some((path, frames)) = self.start.screenshot.clone() else {
            return;
        };
        if self.frames < frames || (self.start.compare && !self.compare.is_done()) {
            return;
        }
        let outcome = match &self.last {
            Some(_) => self.write_screenshot(&path),
            None => Err(self
                .error
                .clone()
                .unwrap_or_else(|| "no frame rendered".into())),
        };
        match outcome {
            Ok(()) => {
                if let Some((Some(img), times)) = &self.last {
                    println!("last frame, {} x {}:", img.width, img.height);
                    print!("{}", visgate_runtime::job::pass_table(times));
                }
                println!("wrote {} after {} frames", path.display(), self.frames)
            }
            Err(e) => eprintln!("error: screenshot {}: {e}", path.display()),
        }
        self.start.screenshot = None;
        let Some(path) = self.start.window_shot.take() else {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            return;
        };
        // The window as drawn, then close.
        let c = ctx.clone();
        ctx.request_screenshot(move |img| {
            let rgba: Vec<u8> = img
                .pixels
                .iter()
                .flat_map(|p| p.to_srgba_unmultiplied())
                .collect();
            let [w, h] = img.size;
            match image::save_buffer(&path, &rgba, w as u32, h as u32, image::ColorType::Rgba8) {
                Ok(()) => println!("wrote {} ({w} x {h}, the window)", path.display()),
                Err(e) => eprintln!("error: window shot {}: {e}", path.display()),
            }
            c.send_viewport_cmd(egui::ViewportCommand::Close);
            c.request_repaint();
        });
        ctx.request_repaint();
    }
}
