//! The wgpu renderer against the CPU reference with the same VPLs and the same visibility
//! choice, on whatever adapter wgpu finds (lavapipe in CI). A missing adapter fails the test.

use std::f32::consts::PI;

use glam::Vec3;
use visgate_runtime::camera::View;
use visgate_runtime::cpu::reference::{ReferenceParams, render_reference};
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::gpu::{
    GpuContext, GpuMode, GpuParams, GpuRenderer, PerVplParams, ShadowParams,
};
use visgate_runtime::metrics::{errors, flip};
use visgate_runtime::vpl::{GatherParams, PathParams, path_vpls};
use visgate_scenes::Builtin;

#[path = "../common/mod.rs"]
mod common;
use common::{closed_box, floor, quads, scaled_four_rooms};

fn per_vpl() -> GpuMode {
    GpuMode::PerVplShadowMaps(PerVplParams::default())
}

fn context() -> GpuContext {
    match GpuContext::new() {
        Ok(c) => c,
        Err(e) => panic!("GPU tests need an adapter (CI installs lavapipe): {e}"),
    }
}

/// CPU (spp 1, pixel centres) and GPU images of a built-in scene's first camera.
fn both(
    b: Builtin,
    size: [u32; 2],
    paths: u32,
    mode: GpuMode,
) -> (
    visgate_runtime::hdr::HdrImage,
    visgate_runtime::hdr::HdrImage,
) {
    let ctx = context();
    let scene = b.scene().expect("scene");
    let tracer = Tracer::new(&scene);
    let vpls = path_vpls(
        &tracer,
        &scene.lights,
        &PathParams {
            paths,
            bounces: 1,
            seed: 2,
        },
    )
    .expect("vpls");
    let view = View::new(scene.cameras.first().expect("camera"), size).expect("view");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let (img, _) = gpu
        .render(
            &ctx,
            &view,
            &vpls,
            &GpuParams {
                mode,
                ..GpuParams::default()
            },
        )
        .expect("render");
    let (cpu, _) = render_reference(
        &tracer,
        &scene.lights,
        &vpls,
        &view,
        &ReferenceParams {
            samples_per_pixel: 1,
            indirect: mode != GpuMode::DirectOnly,
            indirect_visibility: matches!(mode, GpuMode::PerVplShadowMaps(_)),
            gather: GatherParams::default(),
            ..ReferenceParams::default()
        },
        &|_, _| {},
    )
    .expect("reference");
    (img, cpu)
}

/// A 100 m floor of albedo `rho` with `lights`, for the GPU known answers.
fn floor_scene(rho: f32, lights: Vec<visgate_formats::Light>) -> visgate_formats::Scene {
    quads(&[floor(50.0)], rho, lights)
}

/// Direct light alone of `view`: the GPU's `direct-only` frame and the CPU reference's.
fn direct_on_gpu_and_cpu(
    ctx: &GpuContext,
    scene: &visgate_formats::Scene,
    view: &View,
) -> (
    visgate_runtime::hdr::HdrImage,
    visgate_runtime::hdr::HdrImage,
) {
    let mut gpu = GpuRenderer::new(ctx, scene).expect("upload");
    let (img, _) = gpu
        .render(ctx, view, &[], &GpuParams::with_mode(GpuMode::DirectOnly))
        .expect("render");
    let params = ReferenceParams {
        samples_per_pixel: 1,
        indirect: false,
        ..ReferenceParams::default()
    };
    let tracer = Tracer::new(scene);
    let (cpu, _) = render_reference(&tracer, &scene.lights, &[], view, &params, &|_, _| {})
        .expect("reference");
    (img, cpu)
}

mod agree;
mod lights;
