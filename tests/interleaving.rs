//! Interleaved sampling over the VPL list's order (`visgate_runtime::vpl_order`): each of the
//! b² subsets holds every direction of every light, so that a pixel's 8 × 8 block lights what
//! every VPL lights.

use visgate_runtime::camera::View;
use visgate_runtime::cpu::gates::GateLevel;
use visgate_runtime::gpu::InterleaveParams;
use visgate_runtime::gpu::{GatesParams, GpuContext, GpuMode, GpuParams, GpuRenderer};
use visgate_runtime::metrics::indirect_errors;
use visgate_runtime::vpl::{PathParams, Vpl, path_vpls};
use visgate_scenes::Builtin;

// Shared by the gate tests; this one uses its fixture only.
#[allow(dead_code)]
#[path = "support/gates.rs"]
mod gate_support;

/// The pillared hall baked at 128 and its side room (lit through its door by the hall's two
/// lights): a GPU, the level, 1,024 light paths of `seed`, the room's view at `size` and a
/// renderer of the scene.
struct SideRoom {
    ctx: GpuContext,
    gates: GateLevel,
    vpls: Vec<Vpl>,
    view: View,
    gpu: GpuRenderer,
}

fn side_room(seed: u64, size: [u32; 2]) -> SideRoom {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let (scene, gates, tracer, _, _) = gate_support::fixture(Builtin::PillaredHall, 128, 1);
    let paths = PathParams {
        paths: 1024,
        bounces: 1,
        seed,
    };
    let vpls = path_vpls(&tracer, &scene.lights, &paths).expect("vpls");
    let view = View::new(&scene.cameras[1], size).expect("view");
    let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    SideRoom {
        ctx,
        gates,
        vpls,
        view,
        gpu,
    }
}

#[test]
fn an_interleaved_side_room_is_lit_where_every_vpl_lights_it() {
    let SideRoom {
        ctx,
        gates,
        vpls,
        view,
        mut gpu,
    } = side_room(0, [320, 180]);
    gpu.set_level(&ctx, &gates).expect("level");
    let mut render = |mode| {
        gpu.render(&ctx, &view, &vpls, &GpuParams::with_mode(mode))
            .expect("render")
            .0
    };
    let with_block = |block, fill| {
        GpuMode::Gates(GatesParams {
            interleave: InterleaveParams {
                block,
                fill,
                ..InterleaveParams::default()
            },
            ..GatesParams::default()
        })
    };
    let direct = render(GpuMode::DirectOnly);
    let every = render(with_block(1, false));
    let interleaved = render(with_block(8, false));
    // The blur filled from the next blocks: a pipeline of its own (blur.wgsl's BLUR_FILL).
    let filled = render(with_block(8, true));
    for (name, image) in [("8×8", &interleaved), ("8×8, filled", &filled)] {
        let e = indirect_errors(image, &every, &direct).expect("same size");
        eprintln!(
            "{name} against every VPL at every pixel: energy {:.3}, black where lit {:.2} % of \
             {} pixels",
            e.energy_ratio,
            100.0 * e.black_where_lit,
            e.lit_pixels
        );
        assert!(e.lit_pixels > 10_000, "{} lit pixels", e.lit_pixels);
        // In the light paths' order each subset held a band of 1/64 of the directions: 3.1 %
        // of the lit pixels were black.
        assert!(e.black_where_lit < 0.01, "{name}: {e:?}");
        assert!((e.energy_ratio - 1.0).abs() < 0.1, "{name}: {e:?}");
    }
    // The fill acts where a tap does not agree (along the walls' edges, the door), nowhere
    // else.
    let changed = (interleaved.pixels.iter().zip(&filled.pixels))
        .filter(|(a, b)| a != b)
        .count();
    eprintln!(
        "the fill changed {changed} of {} pixels",
        filled.pixels.len()
    );
    assert!(changed > 100, "the fill changed {changed} pixels");
    assert!(
        changed < filled.pixels.len() / 2,
        "the fill changed {changed} pixels"
    );
}

/// The side room's door jamb, a strip a few pixels wide lit by a few VPLs through the door:
/// with the triangles and the tent, starved pixels walking at T = 32 leave it black (its
/// pixels have about 40 agreeing taps in their block, so they do not walk, and the VPLs that
/// light it fall in the other subsets); the accurate setting's three quarters of the block
/// (48 of 8 × 8) walks them, and so does the balanced setting's walk of the pixels whose
/// agreeing taps found no light; against every VPL at every pixel with the triangles
/// (measured: black where lit 1.19 % at T = 32, 0.00 % at 48, 0.00 % balanced; energy 0.993,
/// 1.000 and 1.015; 40 s on lavapipe).
#[test]
fn the_accurate_and_balanced_settings_light_the_side_rooms_door_jamb() {
    let SideRoom {
        ctx,
        gates,
        vpls,
        view,
        mut gpu,
    } = side_room(2, [320, 240]);
    let accurate = GatesParams::default().accurate();
    assert_eq!(accurate.interleave.starved_taps, 48);
    let mut render = |mode: GpuMode| {
        gpu.level_for_mode(&ctx, &gates, &mode).expect("level");
        gpu.render(&ctx, &view, &vpls, &GpuParams::with_mode(mode))
            .expect("render")
            .0
    };
    let direct = render(GpuMode::DirectOnly);
    let mut every = accurate;
    every.interleave.block = 1;
    every.interleave.starved_taps = 0;
    let every = render(GpuMode::Gates(every));
    let mut t32 = accurate;
    t32.interleave.starved_taps = 32;
    let balanced = GatesParams::default().balanced();
    assert!(balanced.interleave.starved_dark && balanced.interleave.starved_taps == 0);
    let runs = [
        ("T = 32", t32),
        ("accurate, T = 48", accurate),
        ("balanced, dark pixels", balanced),
    ];
    let [t32, t48, dark] = runs.map(|(name, g)| {
        let e = indirect_errors(&render(GpuMode::Gates(g)), &every, &direct).expect("same size");
        eprintln!(
            "side room, 1,024 paths seed 2, triangles + tent, {name}: energy {:.3}, black where \
             lit {:.2} % of {} pixels",
            e.energy_ratio,
            100.0 * e.black_where_lit,
            e.lit_pixels
        );
        e
    });
    assert!(t48.lit_pixels > 10_000, "{t48:?}");
    assert!(t48.black_where_lit < 0.005, "{t48:?}");
    assert!((t48.energy_ratio - 1.0).abs() < 0.05, "{t48:?}");
    assert!(t32.black_where_lit > 0.01, "the jamb at T = 32: {t32:?}");
    assert!(dark.black_where_lit < 0.005, "{dark:?}");
    assert!((dark.energy_ratio - 1.0).abs() < 0.05, "{dark:?}");
}
