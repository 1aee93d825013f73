//! `visgate compare`: the speed/accuracy trade-off of every method on one level. Every mode is
//! rendered at every VPL count from every camera through the same [`RenderJob`] that `visgate
//! render` runs, beside the exact CPU reference with the very same VPLs; each is measured (pass
//! times, MSE, relative MSE, FLIP, indirect energy ratio, black-where-lit share, speed-up over
//! per-VPL shadow maps), the non-dominated settings are found ([`pareto`]), and the report is
//! written as Markdown, HTML and JSON with a Pareto plot and image panels ([`report`],
//! [`plot`]).
//!
//! Every render is kept in the output folder (`renders/CAMERA/NAME.exr` and its `.json` with
//! the settings' key and the pass times), so that a run that was stopped resumes where it was:
//! a render whose key matches is read back, not redone.

mod camera;
pub mod pareto;
pub mod plot;
pub mod report;
mod stability;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use visgate_formats::{Camera, Scene};

use crate::RenderError;
use crate::cpu::gates::GateLevel;
use crate::gpu::{DirectLight, GpuMode};
use crate::hdr::HdrImage;
use crate::job::{FrameStats, JobFrame, RenderJob, Renderer};

pub use stability::{LiveVals, StabilityRow};

/// The error the plot, `--budget-ms` and `--max-error` go by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum ErrorMetric {
    /// MSE of the indirect light alone: the image with its own direct light replaced by the
    /// reference's (GPU shadow maps and CPU shadow rays differ at shadow edges by the same
    /// amount for every method; this leaves that out). [Units: radiance²]
    IndirectMse,
    /// Mean squared error of the whole image. [Units: radiance²]
    Mse,
    /// Relative MSE (scale-free; see [`crate::metrics::ImageErrors::rel_mse`]).
    RelMse,
    /// Mean LDR-FLIP (perceptual, 0 … 1).
    Flip,
}

impl ErrorMetric {
    /// Its name in reports.
    pub fn name(&self) -> &'static str {
        match self {
            ErrorMetric::IndirectMse => "indirect MSE",
            ErrorMetric::Mse => "MSE",
            ErrorMetric::RelMse => "relative MSE",
            ErrorMetric::Flip => "FLIP",
        }
    }

    /// A row's value of it.
    pub fn of(&self, row: &Row) -> f64 {
        match self {
            ErrorMetric::IndirectMse => row.indirect_mse,
            ErrorMetric::Mse => row.mse,
            ErrorMetric::RelMse => row.rel_mse,
            ErrorMetric::Flip => row.flip,
        }
    }
}

/// One method with its settings, under the label reports give it.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareMode {
    /// Its name in tables and files (`gates`, `gates-disk`, …). Unique in a run.
    pub label: String,
    /// The method and its parameters.
    pub mode: GpuMode,
    /// The direct lights' shadows (per light, or LightCluster at some setting).
    pub direct: DirectLight,
}

impl CompareMode {
    /// The method's settings in words for a frame of `vpls` VPLs ([`GpuMode::describe_for`]),
    /// LightCluster's included.
    pub fn describe_for(&self, vpls: u32) -> String {
        let mode = self.mode.describe_for(vpls);
        let DirectLight::LightCluster(p) = &self.direct else {
            return mode;
        };
        let lc = format!("LightCluster {}", p.describe());
        if mode.is_empty() {
            lc
        } else {
            format!("{mode}; {lc}")
        }
    }

    /// Whether its image's direct light is not `base`'s: its direct shadows differ, and it has
    /// indirect light to measure apart.
    fn own_direct(&self, base: &RenderJob) -> bool {
        self.direct != base.params.direct && self.mode != GpuMode::DirectOnly
    }

    /// `job` rendering this method.
    fn job(&self, job: &RenderJob) -> RenderJob {
        let mut j = job.clone();
        j.renderer = Renderer::Gpu(self.mode);
        j.params.direct = self.direct;
        j
    }
}

/// What to compare.
#[derive(Debug, Clone)]
pub struct CompareSpec {
    /// The scene as the user named it.
    pub scene: String,
    /// What identifies the baked level (a gate render is redone when it changes).
    pub level_key: String,
    /// The methods.
    pub modes: Vec<CompareMode>,
    /// Light paths (or RSM VPLs) per render, ascending. [Limit: ≥ 1 each]
    pub vpls: Vec<u32>,
    /// The views.
    pub cameras: Vec<Camera>,
    /// Size, samples, seed, VPL source, clamp, shadows and warm-up frames of every render (its
    /// renderer and VPL count are set per render).
    pub base: RenderJob,
    /// The error of the plot and the answers.
    pub metric: ErrorMetric,
    /// Most frame time allowed: the most accurate setting within it is the answer. [Units: ms]
    pub budget_ms: Option<f64>,
    /// Most error allowed: the fastest setting within it is the answer.
    pub max_error: Option<f64>,
    /// Independent images (a path tracer's), one per camera in order, or none.
    pub ground_truth: Vec<HdrImage>,
    /// Frames of the temporal-stability sequence of an animated scene (0 or 1: none).
    pub stability_frames: u32,
    /// Exposure of the PNGs and of FLIP. [Units: stops]
    pub exposure: f32,
    /// The command line that made the report, written into it.
    pub command: String,
}

/// A pass's time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PassMs {
    /// The pass.
    pub name: String,
    /// Its time (GPU timestamps, or CPU wall time where the adapter has none). [Units: ms]
    pub ms: f64,
}

/// One method at one VPL count from one camera.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    /// The camera.
    pub camera: String,
    /// The method's label.
    pub mode: String,
    /// Its settings in words.
    pub settings: String,
    /// Light paths asked.
    pub vpls: u32,
    /// VPLs made.
    pub vpl_count: usize,
    /// Pass times in frame order.
    pub passes: Vec<PassMs>,
    /// The frame. [Units: ms]
    pub total_ms: f64,
    /// Whether the times are GPU timestamps (else CPU wall time per pass).
    pub gpu_timed: bool,
    /// MSE against the reference.
    pub mse: f64,
    /// MSE of the indirect light alone ([`ErrorMetric::IndirectMse`]).
    pub indirect_mse: f64,
    /// Relative MSE against the reference.
    pub rel_mse: f64,
    /// Mean LDR-FLIP against the reference.
    pub flip: f64,
    /// Mean indirect light over the reference's.
    pub energy_ratio: f64,
    /// Share of the reference's lit pixels that are black in indirect light, the pixels whose
    /// reference samples see several surfaces left out.
    pub black_where_lit: f64,
    /// The same share over every pixel, the mixed ones too.
    pub black_where_lit_all: f64,
    /// The lit pixels (mixed ones left out) [`Row::black_where_lit`] is a share of.
    pub lit_pixels: u64,
    /// The image's pixels.
    pub pixels: u64,
    /// Per-VPL shadow maps' frame time over this one's (same camera and VPLs).
    pub speedup: Option<f64>,
    /// Relative MSE against the camera's ground truth.
    pub ground_truth_rel_mse: Option<f64>,
    /// Whether no other setting is both faster and more accurate (over the cameras).
    pub pareto: bool,
    /// The answers this row is (`budget`, `max-error`).
    pub answers: Vec<String>,
    /// The image, relative to the report.
    pub image: String,
    /// Reference | method | error map, relative to the report.
    pub panel: String,
}

/// The CPU reference of one camera at one VPL count.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReferenceRow {
    /// The camera.
    pub camera: String,
    /// Light paths asked.
    pub vpls: u32,
    /// VPLs made.
    pub vpl_count: usize,
    /// Render time. [Units: s]
    pub seconds: f64,
    /// Shadow rays cast.
    pub shadow_rays: u64,
    /// Relative MSE against the camera's ground truth: the VPL approximation's own error.
    pub ground_truth_rel_mse: Option<f64>,
    /// Share of the pixels whose samples see several surfaces (left out of black-where-lit).
    pub mixed_share: f64,
    /// Those pixels, white, relative to the report (none with one sample a pixel).
    pub mixed_map: Option<String>,
    /// The image, relative to the report.
    pub image: String,
    /// Why the comparison proves nothing, where it does not: no light path met the geometry,
    /// or the reference is black.
    pub warning: Option<String>,
}

/// A render that failed (the run goes on).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Failure {
    /// The camera.
    pub camera: String,
    /// The method's label.
    pub mode: String,
    /// Light paths asked.
    pub vpls: u32,
    /// Why.
    pub error: String,
}

/// Everything `compare` measured.
#[derive(Debug, Clone, Serialize)]
pub struct CompareReport {
    /// The scene as named.
    pub scene: String,
    /// The command line.
    pub command: String,
    /// The GPU adapter.
    pub adapter: String,
    /// Image size. [Units: px]
    pub size: [u32; 2],
    /// CPU pixel samples.
    pub spp: u32,
    /// The error the plot and answers go by.
    pub metric: ErrorMetric,
    /// The cameras, in order.
    pub cameras: Vec<String>,
    /// Every method × VPL count × camera that rendered.
    pub rows: Vec<Row>,
    /// The references.
    pub references: Vec<ReferenceRow>,
    /// Those that failed.
    pub failures: Vec<Failure>,
    /// Means over the cameras per method and VPL count: the plot's points.
    pub points: Vec<pareto::Point>,
    /// The answers to `--budget-ms` and `--max-error`.
    pub answers: Vec<pareto::Answer>,
    /// Frame-to-frame change of animated scenes.
    pub stability: Vec<StabilityRow>,
    /// Renders read back from an earlier run, and made in this one.
    pub resumed: [u32; 2],
}

/// How far a run is.
#[derive(Debug, Clone, Copy)]
pub enum Step<'a> {
    /// Render `index` of `total` begins (`what` says which).
    Render {
        /// 0-based.
        index: u32,
        /// Renders in the run.
        total: u32,
        /// "CAMERA: MODE at N VPLs".
        what: &'a str,
    },
    /// Rows done of a CPU render.
    Rows(u32, u32),
}

/// A render as kept in the folder: what identifies it and what it took.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Kept {
    key: String,
    /// The GPU adapter that made it (empty for a CPU render).
    #[serde(default)]
    adapter: String,
    vpl_count: usize,
    passes: Vec<PassMs>,
    total_ms: f64,
    gpu_timed: bool,
    shadow_rays: u64,
    frames: u32,
    /// Mode vpl-clusters: the VPLs' clusters of the first frame.
    #[serde(default)]
    vpl_clusters: Option<u32>,
    /// The VAL modes: the VALs holding VPLs in each frame, and the VALs asked for.
    #[serde(default)]
    live_vals: Vec<u32>,
    #[serde(default)]
    val_count: Option<u32>,
}

/// Where renders go and what was reused.
struct Store<'a> {
    dir: &'a Path,
    spec: &'a CompareSpec,
    scene: &'a Scene,
    level: Option<&'a GateLevel>,
    done: u32,
    total: u32,
    resumed: [u32; 2],
    /// The adapter of the GPU renders (made or read back).
    adapter: String,
    progress: &'a (dyn Fn(Step) + Sync),
}

impl Store<'_> {
    /// The frames of `job` from `camera`, kept as `renders/CAMERA/NAME(-i).exr`: read back when
    /// kept with the same key, else rendered and kept.
    fn render(
        &mut self,
        camera: &Camera,
        name: &str,
        job: &RenderJob,
    ) -> Result<(Vec<HdrImage>, Kept, PathBuf), RenderError> {
        let rel = Path::new("renders")
            .join(file_name(&camera.name))
            .join(name);
        let path = self.dir.join(&rel);
        let key = format!(
            "{}|{camera:?}|{job:?}|{}|{}",
            self.spec.scene,
            self.spec.level_key,
            build_id()
        );
        let exr = |i: u32| match job.frames {
            1 => path.with_extension("exr"),
            _ => path.with_file_name(format!("{name}-{i:03}.exr")),
        };
        let what = format!("{}: {name}", camera.name);
        (self.progress)(Step::Render {
            index: self.done,
            total: self.total,
            what: &what,
        });
        self.done += 1;
        if let Some(kept) = read_kept(&path.with_extension("json"), &key) {
            let images: Result<Vec<_>, _> =
                (0..kept.frames).map(|i| HdrImage::read(&exr(i))).collect();
            if let Ok(images) = images {
                self.resumed[0] += 1;
                self.note_adapter(&kept.adapter);
                return Ok((images, kept, rel.with_extension("exr")));
            }
        }
        std::fs::create_dir_all(path.parent().unwrap_or(self.dir))
            .map_err(|e| RenderError::io(&path, e))?;
        let mut frames: Vec<JobFrame> = Vec::new();
        let mut adapter = String::new();
        let progress = |d: u32, t: u32| (self.progress)(Step::Rows(d, t));
        // A variant measures its own method: where its walk's tables did not fit the adapter
        // and `run` took another walk (JobSetup::mode), it fails with the reason instead.
        let swapped = std::cell::Cell::new(false);
        job.run(
            self.scene,
            camera,
            self.level,
            &mut |s| {
                adapter = s.adapter.clone().unwrap_or_default();
                swapped.set(s.mode != job.mode());
            },
            &progress,
            &mut |f| {
                if swapped.get() {
                    return Err(RenderError::Param(
                        "the closed voxels' triangle lists do not fit this adapter's storage \
                         binding (`visgate render` says by how much, and walks on their planes \
                         instead: the variant gates-fast's walk)"
                            .into(),
                    ));
                }
                frames.push(f);
                Ok(())
            },
        )?;
        let kept = kept_of(&frames, key, adapter)?;
        self.note_adapter(&kept.adapter);
        for (i, f) in frames.iter().enumerate() {
            f.image.write_exr(&exr(i as u32))?;
        }
        let json = path.with_extension("json");
        let text = serde_json::to_string_pretty(&kept).map_err(|e| RenderError::io(&json, e))?;
        std::fs::write(&json, text).map_err(|e| RenderError::io(&json, e))?;
        self.resumed[1] += 1;
        let images = frames.into_iter().map(|f| f.image).collect();
        Ok((images, kept, rel.with_extension("exr")))
    }

    /// Records the adapter of a GPU render (the first one named stands for the report).
    fn note_adapter(&mut self, adapter: &str) {
        if self.adapter.is_empty() {
            adapter.clone_into(&mut self.adapter);
        }
    }
}

/// The program that renders: its version and its executable's size and modification time,
/// so that a kept render is read back only by the build that made it (a rebuilt visgate may
/// render a mode otherwise: `gates-per-pixel` kept 0.41 of the light on lavapipe before it
/// walked in batches, and a second run would have read that back).
fn build_id() -> &'static str {
    static ID: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    ID.get_or_init(|| {
        let exe = std::env::current_exe().and_then(std::fs::metadata);
        let stamp = exe.map_or(String::from("?"), |m| {
            let modified = m
                .modified()
                .ok()
                .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok());
            format!(
                "{} bytes, {}",
                m.len(),
                modified.map_or(0, |d| d.as_nanos())
            )
        });
        format!("visgate {} ({stamp})", env!("CARGO_PKG_VERSION"))
    })
}

/// A kept render's record at `path`, if it has `key`.
fn read_kept(path: &Path, key: &str) -> Option<Kept> {
    let text = std::fs::read_to_string(path).ok()?;
    let kept: Kept = serde_json::from_str(&text).ok()?;
    (kept.key == key).then_some(kept)
}

/// The record of `frames` (times of the first frame).
fn kept_of(frames: &[JobFrame], key: String, adapter: String) -> Result<Kept, RenderError> {
    let first = frames
        .first()
        .ok_or_else(|| RenderError::Param("a render gave no frame".into()))?;
    let (passes, total_ms, gpu_timed, shadow_rays) = match &first.stats {
        FrameStats::Gpu(t) => {
            let gpu_timed = t.passes.iter().any(|p| p.gpu_s.is_some());
            let passes = t
                .by_name()
                .into_iter()
                .map(|(name, gpu, cpu)| PassMs {
                    name: name.to_string(),
                    ms: gpu.or(cpu).unwrap_or(0.0) * 1e3,
                })
                .collect();
            let total = t.gpu_total().unwrap_or(t.frame_s) * 1e3;
            (passes, total, gpu_timed, 0)
        }
        FrameStats::Cpu(s) => (Vec::new(), s.seconds * 1e3, false, s.shadow_rays),
    };
    let vpl_clusters = match &first.stats {
        FrameStats::Gpu(t) => t.vpl_clusters.map(|c| c.clusters),
        FrameStats::Cpu(_) => None,
    };
    let vals = |f: &JobFrame| match &f.stats {
        FrameStats::Gpu(t) => t.vals,
        FrameStats::Cpu(_) => None,
    };
    Ok(Kept {
        key,
        adapter,
        vpl_clusters,
        live_vals: frames
            .iter()
            .filter_map(|f| vals(f).map(|v| v.live))
            .collect(),
        val_count: vals(first).map(|v| v.count),
        vpl_count: first.vpl_count,
        passes,
        total_ms,
        gpu_timed,
        shadow_rays,
        frames: frames.len() as u32,
    })
}

/// A name safe in a file path (letters, digits, `-`, `_`; the rest become `_`).
pub fn file_name(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            'a'..='z' | 'A'..='Z' | '0'..='9' | '-' | '_' => c,
            _ => '_',
        })
        .collect()
}

impl CompareSpec {
    /// Checks the settings before anything is rendered.
    pub fn check(&self, has_level: bool) -> Result<(), RenderError> {
        let param = |s: String| Err(RenderError::Param(s));
        if self.modes.is_empty() {
            return param("no mode to compare: give --modes".into());
        }
        if self.vpls.is_empty() || self.vpls.contains(&0) {
            return param("--vpls: give one or more counts ≥ 1, e.g. 256,1024,4096".into());
        }
        if self.cameras.is_empty() {
            return param("no camera: the scene has none, or --cameras named none of them".into());
        }
        if !self.ground_truth.is_empty() && self.ground_truth.len() != self.cameras.len() {
            return param(format!(
                "{} ground-truth images for {} cameras: give one per camera, in order",
                self.ground_truth.len(),
                self.cameras.len()
            ));
        }
        let [w, h] = self.base.size;
        for gt in &self.ground_truth {
            if (gt.width, gt.height) != (w, h) {
                return param(format!(
                    "a ground-truth image is {}x{}, the renders {w}x{h}: give --size {}x{}",
                    gt.width, gt.height, gt.width, gt.height
                ));
            }
        }
        for m in &self.modes {
            m.job(&self.base).check(has_level)?;
        }
        Ok(())
    }
}

/// Renders and measures everything `spec` asks on `scene` (with `level` for the gate modes),
/// keeping every render in `dir`, and returns the report (not yet written: see
/// [`report::write`]).
pub fn run(
    spec: &CompareSpec,
    scene: &Scene,
    level: Option<&GateLevel>,
    dir: &Path,
    progress: &(dyn Fn(Step) + Sync),
) -> Result<CompareReport, RenderError> {
    spec.check(level.is_some())?;
    // Direct light on the CPU and GPU and that of each method shadowed otherwise than the run,
    // then per VPL count the reference and each method.
    let own_direct = spec
        .modes
        .iter()
        .filter(|m| m.own_direct(&spec.base))
        .count() as u32;
    let per_camera = 2 + own_direct + spec.vpls.len() as u32 * (1 + spec.modes.len() as u32);
    let mut store = Store {
        dir,
        spec,
        scene,
        level,
        done: 0,
        total: per_camera * spec.cameras.len() as u32 + stability::renders(spec, scene),
        resumed: [0, 0],
        adapter: String::new(),
        progress,
    };
    let mut report = CompareReport {
        scene: spec.scene.clone(),
        command: spec.command.clone(),
        adapter: String::new(),
        size: spec.base.size,
        spp: spec.base.spp,
        metric: spec.metric,
        cameras: spec.cameras.iter().map(|c| c.name.clone()).collect(),
        rows: Vec::new(),
        references: Vec::new(),
        failures: Vec::new(),
        points: Vec::new(),
        answers: Vec::new(),
        stability: Vec::new(),
        resumed: [0, 0],
    };
    // With several samples a pixel, the pixels whose samples see several surfaces are left out
    // of black-where-lit (the primary rays alone, on the scene posed as the renders pose it: a
    // second for a 262 k-triangle level's BVH).
    let tracer =
        (spec.base.spp > 1).then(|| crate::cpu::tracer::Tracer::new(&scene.at(spec.base.time)));
    for (ci, camera) in spec.cameras.iter().enumerate() {
        let mixed = match &tracer {
            Some(t) => {
                let view = crate::camera::View::new(camera, spec.base.size)?;
                crate::cpu::reference::mixed_pixels(t, &view, spec.base.spp)
            }
            None => Vec::new(),
        };
        camera::camera_rows(
            &mut store,
            &mut report,
            camera,
            spec.ground_truth.get(ci),
            &mixed,
        )?;
    }
    report.stability = stability::measure(&mut store)?;
    report.resumed = store.resumed;
    report.adapter = if store.adapter.is_empty() {
        "an adapter not recorded (renders read back from an older run)".into()
    } else {
        store.adapter
    };
    pareto::mark(&mut report, spec);
    Ok(report)
}
