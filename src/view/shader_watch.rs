//! `visgate view --shader-dir DIR`: shader hot reload for the people who work on the methods.
//! The folder's copies of the WGSL files (flat, or as `passes/` and `shaders/` like the
//! repository's `runtime/src/gpu`) replace the built-in ones; when one changes, every pipeline
//! is rebuilt from them. A compile error shows in the panel with its file and line, and the
//! last good pipelines keep drawing.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

use anyhow::{Result, bail};
use visgate_runtime::RenderError;
use visgate_runtime::gpu::{GpuContext, GpuRenderer, ShaderSources};

/// How often the folder is looked at.
pub const POLL: Duration = Duration::from_millis(400);

/// The watched folder.
pub struct ShaderWatch {
    dir: PathBuf,
    /// Each shader file's modification time in the folder (`None`: not there).
    stamps: Vec<Option<SystemTime>>,
    checked: Instant,
    /// The last reload's error (the last good shaders draw).
    pub error: Option<String>,
    /// Files read from the folder by the last good reload.
    pub files: usize,
    /// Good reloads so far.
    pub reloads: u32,
}

/// Each shader file's modification time in `dir`.
fn stamps(dir: &Path) -> Vec<Option<SystemTime>> {
    ShaderSources::names()
        .map(|n| {
            ShaderSources::path_in(dir, n)
                .and_then(|p| std::fs::metadata(p).ok())
                .and_then(|m| m.modified().ok())
        })
        .collect()
}

impl ShaderWatch {
    /// Watches `dir` and builds `gpu`'s pipelines from it (a compile error is kept and shown,
    /// the built-in shaders drawing); refuses a path that is not a folder of visgate's shaders.
    pub fn start(dir: &Path, ctx: &GpuContext, gpu: &mut GpuRenderer) -> Result<ShaderWatch> {
        if !dir.is_dir() {
            bail!("--shader-dir {}: not a folder", dir.display());
        }
        let sources = ShaderSources::read_dir(dir)?;
        let mut w = ShaderWatch {
            dir: dir.to_path_buf(),
            stamps: stamps(dir),
            checked: Instant::now(),
            error: None,
            files: 0,
            reloads: 0,
        };
        w.apply(Ok(sources), ctx, gpu);
        Ok(w)
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Whether a shader file in the folder changed (or came or went) since the last look;
    /// looks at most every [`POLL`].
    pub fn changed(&mut self) -> bool {
        if self.checked.elapsed() < POLL {
            return false;
        }
        self.checked = Instant::now();
        let now = stamps(&self.dir);
        let changed = now != self.stamps;
        self.stamps = now;
        changed
    }

    /// Reads the folder and rebuilds `gpu`'s pipelines from it; prints and keeps the outcome.
    /// Whether the new shaders draw.
    pub fn reload(&mut self, ctx: &GpuContext, gpu: &mut GpuRenderer) -> bool {
        self.apply(ShaderSources::read_dir(&self.dir), ctx, gpu)
    }

    /// Rebuilds `gpu`'s pipelines from `sources` (as read); prints and keeps the outcome.
    fn apply(
        &mut self,
        sources: Result<ShaderSources, RenderError>,
        ctx: &GpuContext,
        gpu: &mut GpuRenderer,
    ) -> bool {
        let result =
            sources.and_then(|s| gpu.reload_shaders(ctx, &s).map(|()| s.overridden().count()));
        match result {
            Ok(files) => {
                self.reloads += 1;
                self.files = files;
                self.error = None;
                println!(
                    "shaders: {files} file(s) from {} compiled",
                    self.dir.display()
                );
                true
            }
            Err(e) => {
                eprintln!("shader error (the last good shaders draw on): {e}");
                self.error = Some(e.to_string());
                false
            }
        }
    }
}
