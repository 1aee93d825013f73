//! Gate visibility on baked built-in levels (the CPU twin of the `gates` mode, per point),
//! against the exact ray-cast visibility.

use glam::Vec3;
use visgate_runtime::cpu::gates::{End, GateLevel, GateParams, GateShape};
use visgate_runtime::cpu::tracer::Tracer;
use visgate_scenes::Builtin;

#[path = "../support/gates.rs"]
mod gate_support;

use gate_support::light_paths;

fn baked(b: Builtin, res: u32) -> (visgate_formats::Scene, visgate_formats::BakedLevel) {
    let (scene, baked) = gate_support::baked(b, res);
    (scene, baked.level)
}

/// A built-in scene baked at `res`, its gate level, tracer, 256 path VPLs and its first
/// camera's 64×48 view.
fn fixture(
    b: Builtin,
    res: u32,
) -> (
    visgate_formats::Scene,
    GateLevel,
    Tracer,
    Vec<visgate_runtime::vpl::Vpl>,
    visgate_runtime::camera::View,
) {
    gate_support::fixture(b, res, 0)
}

/// The four rooms baked at 128 on the GPU with their level, the fixture's VPLs and a view of
/// its first camera at `size` (the interleaving tests' set-up).
fn four_rooms_on_the_gpu(
    size: [u32; 2],
) -> (
    visgate_runtime::gpu::GpuContext,
    visgate_runtime::gpu::GpuRenderer,
    Vec<visgate_runtime::vpl::Vpl>,
    visgate_runtime::camera::View,
) {
    use visgate_runtime::gpu::{GpuContext, GpuRenderer};
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let (scene, gates, _, vpls, _) = fixture(Builtin::FourRooms, 128);
    let view = visgate_runtime::camera::View::new(&scene.cameras[0], size).expect("view");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    gpu.set_level(&ctx, &gates).expect("level");
    (ctx, gpu, vpls, view)
}

// The runtime tests' scene builders; this file uses the scaled four rooms.
#[path = "../../runtime/tests/common/mod.rs"]
mod common;

/// Clustered gates with the paper's disks, the shape that keeps light lists (portals walk each
/// pixel's VPL subset without lists).
fn disk_lists() -> visgate_runtime::gpu::GatesParams {
    use visgate_runtime::gpu::GatesParams;
    let mut p = GatesParams::default();
    p.gates.shape = GateShape::Disk;
    p
}

/// Clustered gates without interleaving (what the CPU twin computes).
fn every_vpl_at_every_pixel() -> visgate_runtime::gpu::GatesParams {
    use visgate_runtime::gpu::{GatesParams, InterleaveParams};
    GatesParams {
        interleave: InterleaveParams {
            block: 1,
            ..InterleaveParams::default()
        },
        ..GatesParams::default()
    }
}

/// GPU gates (clustered) and the CPU twin on `vpls`, relative MSE of the GPU image.
fn gpu_vs_twin(
    gpu: &mut visgate_runtime::gpu::GpuRenderer,
    ctx: &visgate_runtime::gpu::GpuContext,
    scene: &visgate_formats::Scene,
    tracer: &Tracer,
    gates: &GateLevel,
    vpls: &[visgate_runtime::vpl::Vpl],
    view: &visgate_runtime::camera::View,
) -> (visgate_runtime::hdr::HdrImage, f64) {
    use visgate_runtime::gpu::{GpuMode, GpuParams};
    use visgate_runtime::metrics::errors;
    let (img, _) = gpu
        .render(
            ctx,
            view,
            vpls,
            &GpuParams::with_mode(GpuMode::Gates(every_vpl_at_every_pixel())),
        )
        .expect("gpu");
    assert!(img.pixels.iter().all(|p| p.is_finite()), "finite");
    let cpu = cpu_twin(
        tracer,
        &scene.lights,
        vpls,
        view,
        (gates, GateParams::default()),
    );
    let e = errors(&img, &cpu).expect("same size");
    (img, e.rel_mse)
}

/// The CPU twin of mode `gates` (one sample at each pixel's centre) with `gates` and `params`.
fn cpu_twin(
    tracer: &Tracer,
    lights: &[visgate_formats::Light],
    vpls: &[visgate_runtime::vpl::Vpl],
    view: &visgate_runtime::camera::View,
    (gates, params): (&GateLevel, GateParams),
) -> visgate_runtime::hdr::HdrImage {
    use visgate_runtime::cpu::reference::{IndirectVisibility, ReferenceParams, render_with};
    let reference = ReferenceParams {
        samples_per_pixel: 1,
        ..ReferenceParams::default()
    };
    let visibility = IndirectVisibility::Gates(gates, params);
    render_with(
        tracer,
        lights,
        vpls,
        view,
        &reference,
        visibility,
        &|_, _| {},
    )
    .expect("cpu")
    .0
}

/// Mode gates' settings with the portal walk.
fn portal_gates() -> visgate_runtime::gpu::GatesParams {
    let mut p = visgate_runtime::gpu::GatesParams::default();
    p.gates.shape = GateShape::Portal;
    p
}

mod blur_roulette;
mod gpu;
mod small_binding;
mod twin;
