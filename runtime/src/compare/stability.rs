//! Temporal stability of an animated scene: each method renders a sequence of frames at the
//! smallest VPL count, as the reference does; a method flickers where its indirect light
//! changes from frame to frame more than the reference's does.

use serde::Serialize;
use visgate_formats::Scene;

use super::{CompareSpec, Store};
use crate::RenderError;
use crate::gpu::GpuMode;
use crate::hdr::HdrImage;
use crate::job::{RenderJob, Renderer};

/// One method's frame-to-frame change from one camera.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StabilityRow {
    /// The camera.
    pub camera: String,
    /// The method's label.
    pub mode: String,
    /// Light paths asked.
    pub vpls: u32,
    /// Frames of the sequence.
    pub frames: u32,
    /// Mean absolute change of the indirect light between consecutive frames. [Units: radiance]
    pub change: f64,
    /// The reference's own. [Units: radiance]
    pub reference_change: f64,
    /// `change / reference_change` (1: as steady as the reference; above: flicker).
    pub ratio: f64,
    /// Mean absolute difference of the method's change and the reference's, over the
    /// reference's mean indirect light: the change that is the method's alone.
    pub excess: f64,
    /// The VAL modes: VALs holding VPLs, mean and fewest over the frames, of the VALs asked
    /// for (a warm-started clustering loses VALs as the light moves).
    pub live_vals: Option<LiveVals>,
}

/// Live VALs over a sequence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LiveVals {
    /// Mean over the frames.
    pub mean: f64,
    /// Fewest in a frame.
    pub min: u32,
    /// In the last frame.
    pub last: u32,
    /// VALs asked for (M).
    pub count: u32,
}

/// The live-VAL figures of a render's frames, where it is a VAL mode.
fn live_vals(live: &[u32], count: Option<u32>) -> Option<LiveVals> {
    let (count, last) = (count?, *live.last()?);
    Some(LiveVals {
        mean: live.iter().map(|&v| v as f64).sum::<f64>() / live.len() as f64,
        min: live.iter().copied().min().unwrap_or(0),
        last,
        count,
    })
}

/// Whether `spec` asks for sequences of `scene`.
fn wanted(spec: &CompareSpec, scene: &Scene) -> bool {
    spec.stability_frames >= 2 && scene.is_animated()
}

/// Renders the sequences take (for the progress total).
pub(super) fn renders(spec: &CompareSpec, scene: &Scene) -> u32 {
    match wanted(spec, scene) {
        true => spec.cameras.len() as u32 * (3 + spec.modes.len() as u32),
        false => 0,
    }
}

/// The indirect light of each frame: `images` less `direct`.
fn indirect(images: &[HdrImage], direct: &[HdrImage]) -> Vec<Vec<f64>> {
    images
        .iter()
        .zip(direct)
        .map(|(i, d)| {
            i.pixels
                .iter()
                .zip(&d.pixels)
                .map(|(p, q)| ((*p - *q).max(glam::Vec3::ZERO).element_sum() / 3.0) as f64)
                .collect()
        })
        .collect()
}

/// Frame-to-frame differences of a sequence.
fn deltas(seq: &[Vec<f64>]) -> Vec<Vec<f64>> {
    seq.windows(2)
        .map(|w| w[1].iter().zip(&w[0]).map(|(a, b)| a - b).collect())
        .collect()
}

/// Mean of `|v|` over every frame and pixel.
fn mean_abs(v: &[Vec<f64>]) -> f64 {
    let n: usize = v.iter().map(Vec::len).sum();
    v.iter().flatten().map(|x| x.abs()).sum::<f64>() / n.max(1) as f64
}

/// Renders and measures the sequences (none for a still scene).
pub(super) fn measure(store: &mut Store) -> Result<Vec<StabilityRow>, RenderError> {
    let spec = store.spec;
    if !wanted(spec, store.scene) {
        return Ok(Vec::new());
    }
    let vpls = spec.vpls[0];
    let frames = spec.stability_frames;
    let job = |renderer, vpls| RenderJob {
        renderer,
        vpls,
        frames,
        ..spec.base.clone()
    };
    let mut rows = Vec::new();
    for camera in &spec.cameras {
        let mut seq =
            |name: &str, j: RenderJob| store.render(camera, &format!("sequence-{name}"), &j);
        let cpu_direct = seq("direct-cpu", job(Renderer::CpuTwin(GpuMode::DirectOnly), 0))?.0;
        let gpu_direct = seq("direct-gpu", job(Renderer::Gpu(GpuMode::DirectOnly), 0))?.0;
        let reference = seq(&format!("reference-{vpls}"), job(Renderer::Reference, vpls))?.0;
        let ref_ind = indirect(&reference, &cpu_direct);
        let ref_delta = deltas(&ref_ind);
        let reference_change = mean_abs(&ref_delta);
        let ref_mean = mean_abs(&ref_ind);
        for m in &spec.modes {
            let name = format!("{}-{vpls}", super::file_name(&m.label));
            let Ok((images, kept, _)) = seq(&name, job(Renderer::Gpu(m.mode), vpls)) else {
                continue;
            };
            let d = deltas(&indirect(&images, &gpu_direct));
            let change = mean_abs(&d);
            let diff: Vec<Vec<f64>> = d
                .iter()
                .zip(&ref_delta)
                .map(|(a, b)| a.iter().zip(b).map(|(x, y)| x - y).collect())
                .collect();
            rows.push(StabilityRow {
                camera: camera.name.clone(),
                mode: m.label.clone(),
                vpls,
                frames,
                change,
                reference_change,
                ratio: change / reference_change.max(f64::MIN_POSITIVE),
                excess: mean_abs(&diff) / ref_mean.max(f64::MIN_POSITIVE),
                live_vals: live_vals(&kept.live_vals, kept.val_count),
            });
        }
    }
    Ok(rows)
}
