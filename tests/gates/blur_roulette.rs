//! The tent blur, the walks' roulette, the light-list pool and walks of many VPLs on the GPU.

use super::*;

#[test]
fn the_tent_blur_keeps_the_light_of_every_vpl_and_is_nearer_every_vpls_gather_than_the_box() {
    use visgate_runtime::gpu::InterleaveParams;
    use visgate_runtime::gpu::{GatesParams, GpuMode, GpuParams};
    use visgate_runtime::metrics::errors;
    let (ctx, mut gpu, vpls, view) = four_rooms_on_the_gpu([96, 72]);
    let mut render = |mode: GpuMode| {
        gpu.render(&ctx, &view, &vpls, &GpuParams::with_mode(mode))
            .expect("render")
            .0
    };
    let gates = |block: u32, tent: bool| {
        GpuMode::Gates(GatesParams {
            interleave: InterleaveParams {
                block,
                tent,
                ..InterleaveParams::default()
            },
            ..GatesParams::default()
        })
    };
    let direct = render(GpuMode::DirectOnly).mean().x;
    let full = render(gates(1, false));
    for block in [4, 8] {
        let boxed = render(gates(block, false));
        let tent = render(gates(block, true));
        let (b, t) = (
            errors(&boxed, &full).expect("size"),
            errors(&tent, &full).expect("size"),
        );
        let energy = (tent.mean().x - direct) / (full.mean().x - direct);
        eprintln!(
            "block {block}: rel. MSE to every VPL's, box {:.3e}, tent {:.3e}; tent's indirect \
             energy {energy:.3}",
            b.rel_mse, t.rel_mse
        );
        // Every subset weighs the same under the tent (b² in all): the light of every VPL.
        assert!((energy - 1.0).abs() < 0.05, "block {block}: {energy}");
        assert!(t.rel_mse < b.rel_mse, "block {block}: {t:?} vs {b:?}");
        assert!(tent != boxed, "block {block}: the tent changed nothing");
    }
}

/// The tent in two passes (rows, then a column of rows) against the one pass of (2b − 1)²
/// taps: the same light where every tap agrees with every pixel (a blur whose thresholds take
/// every surface), and near it with the blur's own thresholds, where a tap can agree with its
/// row's pixel and not with the pixel.
#[test]
fn the_tent_in_two_passes_is_the_one_pass_tent_where_every_tap_agrees() {
    use visgate_runtime::gpu::{GatesParams, GpuMode, GpuParams, InterleaveParams};
    use visgate_runtime::metrics::errors;
    let (ctx, mut gpu, vpls, view) = four_rooms_on_the_gpu([96, 72]);
    let mut render = |blur_distance: f32, blur_normal: f32, tent_rows: bool| {
        let interleave = InterleaveParams {
            tent: true,
            tent_rows,
            blur_distance,
            blur_normal,
            ..InterleaveParams::default()
        };
        let mode = GpuMode::Gates(GatesParams {
            interleave,
            ..GatesParams::default()
        });
        let (image, times) = gpu
            .render(&ctx, &view, &vpls, &GpuParams::with_mode(mode))
            .expect("render");
        let rows_pass = times.passes.iter().any(|p| p.name == "tent rows");
        assert_eq!(rows_pass, tent_rows, "the rows' pass ran as asked");
        image
    };
    for (distance, normal, bound) in [(100.0, -1.0, 1e-10), (0.1, 0.8, 2e-4)] {
        let two = render(distance, normal, true);
        let one = render(distance, normal, false);
        let e = errors(&two, &one).expect("size").rel_mse;
        eprintln!("blur thresholds {distance}, {normal}: rel. MSE of two passes to one {e:.3e}");
        assert!(e < bound, "thresholds {distance}, {normal}: {e}");
    }
}

/// Gates (the default voxel walk) interleaved as `interleave`, the walks' roulette at share
/// `walk_roulette` with seed `walk_seed`.
fn with_roulette(
    interleave: visgate_runtime::gpu::InterleaveParams,
    walk_roulette: f32,
    walk_seed: u32,
) -> visgate_runtime::gpu::GpuParams {
    use visgate_runtime::gpu::{GatesParams, GpuMode, GpuParams, WalkRoulette};
    let p = GatesParams {
        interleave,
        walk_roulette: WalkRoulette::Share(walk_roulette),
        walk_seed,
        ..GatesParams::default()
    };
    GpuParams::with_mode(GpuMode::Gates(p))
}

/// The relative MSE to `full` of seed 0's render (`render(seed)`) and of `seeds` seeds'
/// mean, and the mean's energy over `full`'s: a roulette's noise and its bias.
fn over_seeds(
    full: &visgate_runtime::hdr::HdrImage,
    seeds: u32,
    mut render: impl FnMut(u32) -> visgate_runtime::hdr::HdrImage,
) -> (f64, f64, f64) {
    use visgate_runtime::metrics::errors;
    let one = render(0);
    let mut mean = one.clone();
    for seed in 1..seeds {
        for (m, p) in mean.pixels.iter_mut().zip(&render(seed).pixels) {
            *m += *p;
        }
    }
    for m in &mut mean.pixels {
        *m /= seeds as f32;
    }
    let sum = |img: &visgate_runtime::hdr::HdrImage| -> f64 {
        img.pixels.iter().map(|p| f64::from(p.element_sum())).sum()
    };
    (
        errors(&one, full).expect("size").rel_mse,
        errors(&mean, full).expect("size").rel_mse,
        sum(&mean) / sum(full),
    )
}

#[test]
fn the_walks_roulette_gives_every_walks_light_on_average_over_its_seeds() {
    use visgate_runtime::gpu::InterleaveParams;
    let (ctx, mut gpu, vpls, view) = four_rooms_on_the_gpu([96, 72]);
    // Every VPL at every pixel (no blur to hide a bias): the roulette's noise is all there is.
    let mut render = |walk_roulette: f32, walk_seed: u32| {
        let interleave = InterleaveParams {
            block: 1,
            ..InterleaveParams::default()
        };
        let params = with_roulette(interleave, walk_roulette, walk_seed);
        gpu.render(&ctx, &view, &vpls, &params).expect("render").0
    };
    let full = render(0.0, 0);
    let seeds = 16;
    let (e_one, e_mean, energy) = over_seeds(&full, seeds, |seed| render(0.2, seed));
    eprintln!(
        "roulette 0.2: rel. MSE to every walk's {:.3e} (one seed), {:.3e} ({seeds} seeds' mean); \
         energy {energy:.4}",
        e_one, e_mean
    );
    // It skips walks (noise) and weights the walked up (no bias): the mean of 16 seeds is
    // nearer by about 16×, and keeps the light.
    assert!(e_one > 1e-6, "{}", e_one);
    assert!(e_mean < 0.25 * e_one, "{} vs {}", e_mean, e_one);
    assert!((energy - 1.0).abs() < 0.01, "{energy}");
    // Off, the seed changes nothing.
    assert_eq!(render(0.0, 7).pixels, full.pixels);
}

#[test]
fn the_starved_pixels_walks_take_the_roulette_and_keep_every_walks_light_on_average() {
    use visgate_runtime::gpu::InterleaveParams;
    use visgate_runtime::metrics::errors;
    let (ctx, mut gpu, vpls, view) = four_rooms_on_the_gpu([96, 72]);
    // Blocks of 4 × 4 where no tap but the pixel itself agrees: every pixel starved, its 15
    // other subsets walked by the starved pass, so that its roulette is most of the noise.
    let mut render_in = |starved_taps: u32, walk_roulette: f32, walk_seed: u32| {
        let interleave = InterleaveParams {
            block: 4,
            blur_distance: 0.0,
            starved_taps,
            ..InterleaveParams::default()
        };
        let params = with_roulette(interleave, walk_roulette, walk_seed);
        gpu.render(&ctx, &view, &vpls, &params).expect("render").0
    };
    // Not starved, each pixel its own subset × 16 (no blur): one subset's roulette noise,
    // × 16² in variance. Starved, 16 subsets' noise, each × 1: about a sixteenth of that
    // (without the roulette in the starved pass, one subset's: a 256th).
    let own = errors(&render_in(0, 0.2, 0), &render_in(0, 0.0, 0))
        .expect("size")
        .rel_mse;
    let mut render = |walk_roulette: f32, walk_seed: u32| render_in(16, walk_roulette, walk_seed);
    let full = render(0.0, 0);
    let seeds = 16;
    let (e_one, e_mean, energy) = over_seeds(&full, seeds, |seed| render(0.2, seed));
    eprintln!(
        "starved walks, roulette 0.2: rel. MSE to every walk's {:.3e} (one seed), {:.3e} \
         ({seeds} seeds' mean); energy {energy:.4}; one subset's × 16 {own:.3e}",
        e_one, e_mean
    );
    assert!(e_one > own / 50.0, "{} vs {own}", e_one);
    // The walked weighted up (no bias): 16 seeds' mean is nearer by about 16× and keeps the
    // light.
    assert!(e_one > 1e-6, "{}", e_one);
    assert!(e_mean < 0.25 * e_one, "{} vs {}", e_mean, e_one);
    assert!((energy - 1.0).abs() < 0.01, "{energy}");
}

#[test]
fn the_light_list_pool_grows_to_what_a_frame_needs() {
    // Disks keep lists; portals keep none (their pool stays at one entry).
    use visgate_runtime::gpu::{GatesParams, GpuContext, GpuMode, GpuParams, GpuRenderer};
    use visgate_runtime::vpl::{PathParams, path_vpls};
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let (scene, gates, tracer, _, _) = fixture(Builtin::FourRooms, 96);
    let view = visgate_runtime::camera::View::new(&scene.cameras[0], [96, 72]).expect("view");
    let paths = PathParams {
        paths: 32768,
        bounces: 1,
        seed: 3,
    };
    let vpls = path_vpls(&tracer, &scene.lights, &paths).expect("vpls");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    gpu.set_level(&ctx, &gates).expect("level");
    let (grown, t) = gpu
        .render(
            &ctx,
            &view,
            &vpls,
            &GpuParams::with_mode(GpuMode::Gates(disk_lists())),
        )
        .expect("the pool grows");
    let lists = t.lists.expect("lists");
    eprintln!("{} entries in a pool of {}", lists.entries, lists.capacity);
    let start = visgate_runtime::gpu::passes::clustered_gates::AUTO_LIGHT_ENTRIES;
    assert!(
        lists.entries > u64::from(start),
        "{} entries: the test needs more",
        lists.entries
    );
    assert!(u64::from(lists.capacity) >= lists.entries);
    // The same image as a pool of fixed size that holds them; one too small still fails.
    let fixed = |n: u64| {
        GpuParams::with_mode(GpuMode::Gates(GatesParams {
            light_entries: Some(n as u32),
            ..disk_lists()
        }))
    };
    let (img, _) = gpu
        .render(&ctx, &view, &vpls, &fixed(lists.entries))
        .expect("fixed");
    assert_eq!(img.pixels, grown.pixels);
    let e = gpu
        .render(&ctx, &view, &vpls, &fixed(lists.entries - 1))
        .expect_err("too small");
    assert!(e.to_string().contains("--light-entries"), "{e}");
    // Portals: no lists at all, however many VPLs.
    let (_, t) = gpu
        .render(
            &ctx,
            &view,
            &vpls,
            &GpuParams::with_mode(GpuMode::Gates(portal_gates())),
        )
        .expect("portals");
    let l = t.lists.expect("stats");
    assert_eq!((l.entries, l.capacity), (0, 1));
}

#[test]
fn gpu_walks_keep_their_light_however_many_vpls_a_pixel_walks() {
    // llvmpipe ends a shader invocation's loops after 65,535 iterations in all: a pixel that
    // walked 2,048 VPLs' portals in one pass lost a third of their light on ajar-door's `door`
    // camera (then it warned). Mode gates walks them in batches there, portals and voxels; the
    // GPU keeps the CPU twin's light.
    use visgate_runtime::gpu::{GpuContext, GpuMode, GpuParams, GpuRenderer};
    use visgate_runtime::vpl::{PathParams, path_vpls};
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let (scene, baked) = gate_support::baked(Builtin::AjarDoor, 128);
    let gates = GateLevel::new(baked.level, &scene).expect("level");
    let tracer = Tracer::new(&scene);
    let paths = PathParams {
        paths: 2048,
        bounces: 1,
        seed: 4,
    };
    let vpls = path_vpls(&tracer, &scene.lights, &paths).expect("vpls");
    let view = visgate_runtime::camera::View::new(&scene.cameras[1], [24, 16]).expect("view");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    gpu.set_level(&ctx, &gates).expect("level");
    let (direct, _) = gpu
        .render(
            &ctx,
            &view,
            &vpls,
            &GpuParams::with_mode(GpuMode::DirectOnly),
        )
        .expect("direct");
    let indirect = |img: &visgate_runtime::hdr::HdrImage| -> f64 {
        img.pixels
            .iter()
            .zip(&direct.pixels)
            .map(|(p, d)| f64::from((*p - *d).element_sum()))
            .sum()
    };
    for shape in [GateShape::Portal, GateShape::Voxels] {
        let gp = GateParams {
            shape,
            ..GateParams::default()
        };
        let cpu = cpu_twin(&tracer, &scene.lights, &vpls, &view, (&gates, gp));
        let mut p = every_vpl_at_every_pixel();
        p.gates = gp;
        let mode = GpuMode::Gates(p);
        let (img, _) = gpu
            .render(&ctx, &view, &vpls, &GpuParams::with_mode(mode))
            .expect("gpu");
        let ratio = indirect(&img) / indirect(&cpu);
        eprintln!(
            "{shape:?}, {} VPLs a pixel: GPU / CPU indirect {ratio:.4}",
            vpls.len()
        );
        assert!((ratio - 1.0).abs() < 0.01, "{shape:?}: {ratio}");
    }
}
