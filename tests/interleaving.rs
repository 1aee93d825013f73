//! Interleaved sampling over the VPL list's order (`visgate_runtime::vpl_order`): each of the
//! b² subsets holds every direction of every light, so that a pixel's 8 × 8 block lights what
//! every VPL lights.

use visgate_runtime::camera::View;
use visgate_runtime::gpu::InterleaveParams;
use visgate_runtime::gpu::{GatesParams, GpuContext, GpuMode, GpuParams, GpuRenderer};
use visgate_runtime::metrics::indirect_errors;
use visgate_runtime::vpl::{PathParams, path_vpls};
use visgate_scenes::Builtin;

// Shared by the gate tests; this one uses its fixture only.
#[allow(dead_code)]
#[path = "support/gates.rs"]
mod gate_support;

#[test]
fn an_interleaved_side_room_is_lit_where_every_vpl_lights_it() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let (scene, gates, tracer, _, _) = gate_support::fixture(Builtin::PillaredHall, 128, 1);
    let paths = PathParams {
        paths: 1024,
        bounces: 1,
        seed: 0,
    };
    let vpls = path_vpls(&tracer, &scene.lights, &paths).expect("vpls");
    // The side room, lit through its door by the hall's two lights.
    let view = View::new(&scene.cameras[1], [320, 180]).expect("view");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    gpu.set_level(&ctx, &gates).expect("level");
    let mut render = |mode| {
        gpu.render(&ctx, &view, &vpls, &GpuParams::with_mode(mode))
            .expect("render")
            .0
    };
    let with_block = |block| {
        GpuMode::Gates(GatesParams {
            interleave: InterleaveParams {
                block,
                ..InterleaveParams::default()
            },
            ..GatesParams::default()
        })
    };
    let direct = render(GpuMode::DirectOnly);
    let every = render(with_block(1));
    let interleaved = render(with_block(8));
    let e = indirect_errors(&interleaved, &every, &direct).expect("same size");
    eprintln!(
        "8×8 against every VPL at every pixel: energy {:.3}, black where lit {:.2} % of {} \
         pixels",
        e.energy_ratio,
        100.0 * e.black_where_lit,
        e.lit_pixels
    );
    assert!(e.lit_pixels > 10_000, "{} lit pixels", e.lit_pixels);
    // In the light paths' order each subset held a band of 1/64 of the directions: 3.1 % of
    // the lit pixels were black.
    assert!(e.black_where_lit < 0.01, "{e:?}");
    assert!((e.energy_ratio - 1.0).abs() < 0.1, "{e:?}");
}
