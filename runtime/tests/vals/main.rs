//! Virtual area lights: the GPU k-means against its CPU twin, and the edge cases.

use glam::Vec3;
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::cpu::val::centres_of;
use visgate_runtime::cpu::val::{Clustering, NO_VAL, ValParams, cluster};
use visgate_runtime::gpu::{CssmParams, GpuContext, GpuMode, GpuRenderer, ValModeParams};
use visgate_runtime::vpl::{PathParams, Vpl, path_vpls};
use visgate_scenes::Builtin;

fn hard() -> GpuMode {
    GpuMode::ValHard(ValModeParams::new())
}

fn cssm() -> GpuMode {
    GpuMode::ValCssm(ValModeParams::new(), CssmParams::default())
}

fn context() -> GpuContext {
    GpuContext::new()
        .unwrap_or_else(|e| panic!("GPU tests need an adapter (CI installs lavapipe): {e}"))
}

fn assert_sane(c: &Clustering, n: usize, m: u32) {
    assert_eq!(c.vals.len(), m as usize);
    assert_eq!(c.mapping.len(), n);
    assert!(c.mapping.iter().all(|&k| k < m || k == NO_VAL));
    let counted: u32 = c.vals.iter().map(|v| v.vpl_count()).sum();
    let live = c.mapping.iter().filter(|&&k| k != NO_VAL).count();
    assert_eq!(counted as usize, live);
    for v in &c.vals {
        let all = v
            .position
            .iter()
            .chain(&v.normal)
            .chain(&v.flux)
            .chain(&v.rect);
        assert!(all.clone().all(|x| x.is_finite()), "{v:?}");
        assert!(v.normal[3] >= 0.0, "area {v:?}");
    }
}

#[path = "../common/mod.rs"]
mod common;

/// GPU image of `scene` from `cam` with `vpls` in `mode`, 64×48, every VPL at every pixel.
fn gpu_image(
    ctx: &GpuContext,
    scene: &visgate_formats::Scene,
    cam: &visgate_formats::Camera,
    vpls: &[Vpl],
    mode: visgate_runtime::gpu::GpuMode,
    vals: u32,
) -> visgate_runtime::hdr::HdrImage {
    gpu_image_with(ctx, scene, cam, vpls, mode, vals, 1, [64, 48])
}

/// As [`gpu_image`] with interleaving blocks of side `interleave` at `size`.
#[allow(clippy::too_many_arguments)]
fn gpu_image_with(
    ctx: &GpuContext,
    scene: &visgate_formats::Scene,
    cam: &visgate_formats::Camera,
    vpls: &[Vpl],
    mode: visgate_runtime::gpu::GpuMode,
    vals: u32,
    interleave: u32,
    size: [u32; 2],
) -> visgate_runtime::hdr::HdrImage {
    use visgate_runtime::gpu::{GpuParams, InterleaveParams};
    let mut gpu = GpuRenderer::new(ctx, scene).expect("upload");
    let v = ValModeParams {
        vals: ValParams {
            count: vals,
            ..ValParams::default()
        },
        interleave: InterleaveParams {
            block: interleave,
            ..InterleaveParams::default()
        },
        ..ValModeParams::new()
    };
    let mode = match mode {
        GpuMode::ValHard(_) => GpuMode::ValHard(v),
        GpuMode::ValCssm(_, c) => GpuMode::ValCssm(v, c),
        other => other,
    };
    let view = visgate_runtime::camera::View::new(cam, size).expect("view");
    gpu.render(ctx, &view, vpls, &GpuParams::with_mode(mode))
        .expect("render")
        .0
}

/// A horizontal square of half-side `r` at height `y`.
fn square(r: f32, y: f32) -> [Vec3; 4] {
    [
        Vec3::new(-r, y, -r),
        Vec3::new(r, y, -r),
        Vec3::new(r, y, r),
        Vec3::new(-r, y, r),
    ]
}

mod kmeans;
mod shadows;
