//! One camera of a comparison: its direct light, its references at each VPL count and each
//! method's row (errors, panel), with the pixels that black where lit leaves out.

use std::path::{Path, PathBuf};

use visgate_formats::Camera;

use super::{CompareMode, CompareReport, Failure, Kept, ReferenceRow, Row, Store, file_name, plot};
use crate::RenderError;
use crate::gpu::{DirectLight, GpuMode};
use crate::hdr::HdrImage;
use crate::job::{RenderJob, Renderer};
use crate::metrics::{errors, flip, indirect_map, rebase_direct};

/// The direct light of one camera, on the CPU (the reference's) and on the GPU (the
/// method's).
struct Direct<'a> {
    cpu: &'a HdrImage,
    gpu: &'a HdrImage,
}

/// Renders one camera's references and methods into `report`; `mixed`: the pixels whose
/// reference samples see several surfaces (empty: none).
pub(super) fn camera_rows(
    store: &mut Store,
    report: &mut CompareReport,
    camera: &Camera,
    ground_truth: Option<&HdrImage>,
    mixed: &[bool],
) -> Result<(), RenderError> {
    let spec = store.spec;
    let job = |renderer, vpls| RenderJob {
        renderer,
        vpls,
        frames: 1,
        ..spec.base.clone()
    };
    let one = |v: Vec<HdrImage>| v.into_iter().next().unwrap_or_else(|| HdrImage::new(1, 1));
    let mut direct =
        |name: &str, renderer| (store.render(camera, name, &job(renderer, 0))).map(|r| one(r.0));
    let direct_cpu = direct("direct-cpu", Renderer::CpuTwin(GpuMode::DirectOnly))?;
    let direct_gpu = direct("direct-gpu", Renderer::Gpu(GpuMode::DirectOnly))?;
    let mixed_map = mixed_map(store, camera, mixed, [direct_cpu.width, direct_cpu.height])?;
    // A method with other direct shadows than the run's: its own direct light, to take out of
    // its image (once a camera, whatever the VPL count).
    let mut own_direct = Vec::new();
    for m in &spec.modes {
        own_direct.push(match m.own_direct(&spec.base) {
            true => {
                let mut dj = job(Renderer::Gpu(GpuMode::DirectOnly), 0);
                dj.params.direct = m.direct;
                let label = format!("direct-gpu-{}", file_name(&m.label));
                Some(one(store.render(camera, &label, &dj)?.0))
            }
            false => None,
        });
    }
    for &vpls in &spec.vpls {
        let (images, kept, rel) = store.render(
            camera,
            &format!("reference-{vpls}"),
            &job(Renderer::Reference, vpls),
        )?;
        let reference = one(images);
        reference.write_png(&store.dir.join(rel.with_extension("png")), spec.exposure)?;
        let gt = ground_truth.map(|g| errors(&reference, g)).transpose()?;
        report.references.push(ReferenceRow {
            camera: camera.name.clone(),
            vpls,
            vpl_count: kept.vpl_count,
            seconds: kept.total_ms / 1e3,
            shadow_rays: kept.shadow_rays,
            ground_truth_rel_mse: gt.map(|e| e.rel_mse),
            mixed_share: mixed.iter().filter(|&&m| m).count() as f64 / mixed.len().max(1) as f64,
            mixed_map: mixed_map.clone(),
            image: path_string(&rel.with_extension("png")),
            warning: super::report::reference_warning(vpls, kept.vpl_count, &reference),
        });
        for (k, (m, own)) in spec.modes.iter().zip(&own_direct).enumerate() {
            if let Some(row) = same_frame(&report.rows, &spec.modes[..k], m, &camera.name, vpls) {
                report.rows.push(row);
                continue;
            }
            let name = format!("{}-{vpls}", file_name(&m.label));
            let mode_job = m.job(&job(Renderer::Gpu(m.mode), vpls));
            let direct = Direct {
                cpu: &direct_cpu,
                gpu: own.as_ref().unwrap_or(&direct_gpu),
            };
            match store.render(camera, &name, &mode_job) {
                Ok((images, kept, rel)) => {
                    let row = measure(
                        store,
                        camera,
                        m,
                        vpls,
                        (&one(images), kept, rel),
                        (&reference, mixed),
                        &direct,
                        ground_truth,
                    )?;
                    report.rows.push(row);
                }
                Err(e) => report.failures.push(Failure {
                    camera: camera.name.clone(),
                    mode: m.label.clone(),
                    vpls,
                    error: e.to_string(),
                }),
            }
        }
    }
    Ok(())
}

/// Writes `camera`'s mixed pixels (white; `size` pixels) as `renders/CAMERA/mixed.png`, and
/// returns its path relative to the report; none where no pixel was judged.
fn mixed_map(
    store: &Store,
    camera: &Camera,
    mixed: &[bool],
    [w, h]: [u32; 2],
) -> Result<Option<String>, RenderError> {
    if mixed.len() != (w * h) as usize {
        return Ok(None);
    }
    let rel = Path::new("renders")
        .join(file_name(&camera.name))
        .join("mixed.png");
    let path = store.dir.join(&rel);
    image::GrayImage::from_fn(w, h, |x, y| {
        image::Luma([255 * u8::from(mixed[(y * w + x) as usize])])
    })
    .save(&path)
    .map_err(|e| RenderError::io(&path, e))?;
    Ok(Some(path_string(&rel)))
}

/// The row of `m` where an earlier mode of the run (`before`) rendered the same frame for
/// `camera` at `vpls` (its settings resolved for the VPLs that frame made: `gates` with the
/// auto roulette on and `gates-roulette`): that mode's row under `m`'s label, its settings
/// naming the frame it shares, instead of a second render of it.
fn same_frame(
    rows: &[Row],
    before: &[CompareMode],
    m: &CompareMode,
    camera: &str,
    vpls: u32,
) -> Option<Row> {
    before.iter().find_map(|b| {
        let row = rows
            .iter()
            .find(|r| r.camera == camera && r.vpls == vpls && r.mode == b.label)?;
        let n = row.vpl_count as u32;
        let same = b.direct == m.direct && b.mode.resolved_for(n) == m.mode.resolved_for(n);
        same.then(|| Row {
            mode: m.label.clone(),
            settings: format!("{} — the frame of {}", m.describe_for(n), b.label),
            ..row.clone()
        })
    })
}

/// The method's settings in words, with its clusters: the VPLs' as the render counted them,
/// the lights' from LightCluster's CPU twin (the GPU's equal, tested).
fn settings_of(
    store: &Store,
    camera: &Camera,
    m: &CompareMode,
    kept: &Kept,
) -> Result<String, RenderError> {
    let mut s = m.describe_for(kept.vpl_count as u32);
    if let Some(n) = kept.vpl_clusters {
        s += &format!(" → {n} clusters");
    }
    if let DirectLight::LightCluster(p) = &m.direct {
        let scene = store.scene;
        let view = crate::camera::View::new(camera, store.spec.base.size)?;
        let c = crate::cpu::lightcluster::cluster_lights(
            &scene.lights,
            &view,
            scene.diagonal_m(),
            &p.clustering,
        )?;
        s += &format!(
            " → {} clusters of {} lights",
            c.centres.len(),
            scene.lights.len() as u32 - c.culled
        );
    }
    Ok(s)
}

/// A method's row: its errors against the reference, its PNG and its panel.
#[allow(clippy::too_many_arguments)]
fn measure(
    store: &Store,
    camera: &Camera,
    m: &CompareMode,
    vpls: u32,
    (image, kept, rel): (&HdrImage, Kept, PathBuf),
    (reference, mixed): (&HdrImage, &[bool]),
    direct: &Direct,
    ground_truth: Option<&HdrImage>,
) -> Result<Row, RenderError> {
    let exposure = store.spec.exposure;
    // Direct light alone is measured against the reference's direct light alone (shadow
    // rays): every error, the energy and black-where-lit are then the direct light's.
    let direct_only = m.mode == GpuMode::DirectOnly;
    let reference = if direct_only { direct.cpu } else { reference };
    let e = errors(image, reference)?;
    let (f, flip_map) = flip(image, reference, exposure)?;
    let (map, indirect_mse) = if direct_only {
        let black = HdrImage::new(image.width, image.height);
        (indirect_map(image, reference, &black)?, e.mse)
    } else {
        let rebased = rebase_direct(image, direct.gpu, direct.cpu)?;
        let map = indirect_map(&rebased, reference, direct.cpu)?;
        (map, errors(&rebased, reference)?.mse)
    };
    let map = map.leave_out_mixed(mixed.to_vec())?;
    let i = map.errors();
    let png = rel.with_extension("png");
    image.write_png(&store.dir.join(&png), exposure)?;
    let panel = Path::new("panels").join(format!(
        "{}-{}-{vpls}.jpg",
        file_name(&camera.name),
        file_name(&m.label)
    ));
    let title = format!("{} · {} · {vpls} VPLs", camera.name, m.label);
    let black_map = map.to_image(image.width, image.height);
    let picture = plot::panel(reference, image, (&flip_map, &black_map), exposure, &title)?;
    plot::write_jpeg(&picture, &store.dir.join(&panel))?;
    Ok(Row {
        camera: camera.name.clone(),
        mode: m.label.clone(),
        settings: settings_of(store, camera, m, &kept)?,
        vpls,
        vpl_count: kept.vpl_count,
        passes: kept.passes,
        total_ms: kept.total_ms,
        gpu_timed: kept.gpu_timed,
        mse: e.mse,
        indirect_mse,
        rel_mse: e.rel_mse,
        flip: f as f64,
        energy_ratio: i.energy_ratio,
        black_where_lit: i.black_where_lit,
        black_where_lit_all: i.black_where_lit_all,
        lit_pixels: i.lit_pixels,
        pixels: (image.width * image.height) as u64,
        speedup: None,
        ground_truth_rel_mse: ground_truth
            .map(|g| errors(image, g))
            .transpose()?
            .map(|e| e.rel_mse),
        pareto: false,
        answers: Vec::new(),
        image: path_string(&png),
        panel: path_string(&panel),
    })
}

/// A relative path with `/` separators, for Markdown and HTML.
fn path_string(p: &Path) -> String {
    p.components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}
