//! The renderer lives across frames: every method of the registry renders a second frame with
//! the same settings without making a GPU resource, the same image as the first; a new size
//! makes new ones; RSM VPLs kept on the GPU give the image their read-back copy gives; and the
//! job (what `visgate render` runs) gives the image a direct renderer call gives.

use visgate_formats::vgate::{BakeParams, Resolution};
use visgate_preprocess::bake::{BakeOptions, bake};
use visgate_runtime::camera::View;
use visgate_runtime::cpu::gates::GateLevel;
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::gpu::{
    GpuContext, GpuMode, GpuParams, GpuRenderer, METHODS, MethodSettings, RsmParams, VplInput,
    method,
};
use visgate_runtime::job::{FrameStats, RenderJob, Renderer, VplSource};
use visgate_runtime::vpl::{PathParams, path_vpls};
use visgate_scenes::Builtin;

fn context() -> GpuContext {
    GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"))
}

fn four_rooms() -> (visgate_formats::Scene, GateLevel) {
    let scene = Builtin::FourRooms.scene().expect("scene");
    let params = BakeParams {
        resolution: Resolution::LongestAxisVoxels(64),
        ..BakeParams::default()
    };
    let level = bake(&scene, &params, &BakeOptions::default(), &|_| {})
        .expect("bake")
        .level;
    let gates = GateLevel::new(level, &scene).expect("level");
    (scene, gates)
}

fn mode_of(name: &str, s: &MethodSettings) -> GpuMode {
    (method(name).expect("registered").make)(s)
}

/// Small settings so that every method runs quickly on a software adapter.
fn small_settings() -> MethodSettings {
    let mut s = MethodSettings::default();
    s.per_vpl.map_size = 32;
    s.per_vpl.batch = 16;
    s.vals.map_size = 32;
    s.vals.vals.count = 8;
    s
}

#[test]
fn a_second_frame_with_the_same_settings_makes_no_gpu_resource_in_every_method() {
    let ctx = context();
    let (scene, gates) = four_rooms();
    let tracer = Tracer::new(&scene);
    let vpls = path_vpls(
        &tracer,
        &scene.lights,
        &PathParams {
            paths: 48,
            bounces: 1,
            seed: 3,
        },
    )
    .expect("vpls");
    let cam = scene.cameras.first().expect("camera");
    let (view, bigger) = (
        View::new(cam, [32, 24]).expect("view"),
        View::new(cam, [40, 30]).expect("view"),
    );
    let settings = small_settings();
    for m in METHODS {
        let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
        gpu.set_level(&ctx, &gates).expect("level");
        let mut params = GpuParams::with_mode((m.make)(&settings));
        params.shadows.size = 64;
        let (first, _) = gpu.render(&ctx, &view, &vpls, &params).expect("first");
        let made = gpu.resources_created();
        assert!(made > 0, "{}: the first frame makes its resources", m.name);
        let (second, times) = gpu.render(&ctx, &view, &vpls, &params).expect("second");
        assert_eq!(
            gpu.resources_created(),
            made,
            "{}: a second frame made resources",
            m.name
        );
        assert_eq!(first.pixels, second.pixels, "{}: frames differ", m.name);
        assert!(!times.passes.is_empty(), "{}", m.name);
        gpu.render(&ctx, &bigger, &vpls, &params).expect("bigger");
        assert!(
            gpu.resources_created() > made,
            "{}: a new size makes new targets",
            m.name
        );
    }
}

#[test]
fn rsm_vpls_kept_on_the_gpu_light_as_their_read_back_copy() {
    let ctx = context();
    let scene = Builtin::CornellBox.scene().expect("scene");
    let view = View::new(scene.cameras.first().expect("camera"), [32, 32]).expect("view");
    let settings = small_settings();
    let rsm = RsmParams {
        count: 200,
        rsm_size: 64,
        seed: 2,
    };
    for mode in [
        GpuMode::None,
        mode_of("val-hard", &settings),
        mode_of("val-cssm", &settings),
    ] {
        let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
        let mut params = GpuParams::with_mode(mode);
        params.shadows.size = 64;
        let read = gpu
            .rsm_vpls(&ctx, rsm.count, rsm.rsm_size, rsm.seed)
            .expect("read back");
        assert_eq!(read.len(), 200);
        let (given, _) = gpu
            .render_frame(&ctx, &view, VplInput::Given(&read), &params)
            .expect("given");
        let (kept, t) = gpu
            .render_frame(&ctx, &view, VplInput::Rsm(rsm), &params)
            .expect("kept");
        assert!(t.passes.iter().any(|p| p.name == "RSM VPLs"));
        let diff = given
            .pixels
            .iter()
            .zip(&kept.pixels)
            .map(|(a, b)| (*a - *b).abs().max_element())
            .fold(0.0f32, f32::max);
        // The VAL modes' 1/D comes from the GPU's own reduction with kept VPLs (float
        // rounding of a length); everything else is the same arithmetic.
        assert!(
            diff <= 1e-4 * given.mean().max_element().max(1e-6),
            "{mode:?}: {diff}"
        );
        assert!(given.mean().x > 0.0);
    }
}

#[test]
fn a_render_job_gives_the_image_of_a_direct_renderer_call() {
    let ctx = context();
    let scene = Builtin::CornellBox.scene().expect("scene");
    let cam = scene.cameras.first().expect("camera").clone();
    let job = RenderJob {
        renderer: Renderer::Gpu(GpuMode::None),
        vpls: 64,
        size: [24, 24],
        ..RenderJob::default()
    };
    let mut frames = Vec::new();
    job.run(&scene, &cam, None, &mut |_| {}, &|_, _| {}, &mut |f| {
        frames.push(f);
        Ok(())
    })
    .expect("job");
    assert_eq!(frames.len(), 1);
    assert!(matches!(frames[0].stats, FrameStats::Gpu(_)));
    let tracer = Tracer::new(&scene);
    let vpls = path_vpls(
        &tracer,
        &scene.lights,
        &PathParams {
            paths: 64,
            bounces: 1,
            seed: 1,
        },
    )
    .expect("vpls");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let view = View::new(&cam, [24, 24]).expect("view");
    // The job's clamp follows the scene's size: 1 / (0.025 · diagonal)².
    let (lo, hi) = scene.bounds().expect("bounds");
    let g_max = (0.025 * (hi - lo).length()).powi(-2);
    assert_eq!(job.for_scene(&scene).expect("job").params.g_max, g_max);
    let params = GpuParams {
        g_max,
        ..GpuParams::default()
    };
    let (img, _) = gpu.render(&ctx, &view, &vpls, &params).expect("render");
    assert_eq!(frames[0].image.pixels, img.pixels);
    // The limits are the library's: a gate mode without a level, RSM with 2 bounces.
    let gates = RenderJob {
        renderer: Renderer::Gpu(mode_of("gates", &MethodSettings::default())),
        ..job.clone()
    };
    assert!(
        gates
            .check(false)
            .expect_err("refused")
            .to_string()
            .contains("--level")
    );
    let rsm = RenderJob {
        vpl_source: VplSource::Rsm,
        bounces: 2,
        ..job
    };
    assert!(
        rsm.check(false)
            .expect_err("refused")
            .to_string()
            .contains("one bounce")
    );
}
