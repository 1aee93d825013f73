//! Interleaved sampling over the VPL list's order (`visgate_runtime::vpl_order`): each of the
//! b² subsets holds every direction of every light, so that a pixel's 8 × 8 block lights what
//! every VPL lights.

use visgate_formats::Scene;
use visgate_runtime::camera::View;
use visgate_runtime::cpu::gates::GateLevel;
use visgate_runtime::gpu::InterleaveParams;
use visgate_runtime::gpu::{GatesParams, GpuContext, GpuMode, GpuParams, GpuRenderer};
use visgate_runtime::hdr::HdrImage;
use visgate_runtime::metrics::{errors, indirect_errors};
use visgate_runtime::vpl::{PathParams, Vpl, path_vpls};
use visgate_scenes::Builtin;

// Shared by the gate tests; this one uses its fixture only.
#[allow(dead_code)]
#[path = "support/gates.rs"]
mod gate_support;

/// A built-in baked, lit and seen: a GPU, the level, the VPLs of its lights' paths, a view and
/// a renderer of the scene.
struct LitView {
    ctx: GpuContext,
    gates: GateLevel,
    vpls: Vec<Vpl>,
    view: View,
    gpu: GpuRenderer,
}

impl LitView {
    /// A frame of `mode` (its level made for it).
    fn render(&mut self, mode: GpuMode) -> HdrImage {
        let (ctx, gpu) = (&self.ctx, &mut self.gpu);
        gpu.level_for_mode(ctx, &self.gates, &mode).expect("level");
        let params = GpuParams::with_mode(mode);
        gpu.render(ctx, &self.view, &self.vpls, &params)
            .expect("render")
            .0
    }
}

/// Built-in `b` baked at `res` voxels, `paths` one-bounce light paths of `seed`, its camera
/// `camera` at `size`; and the scene.
fn lit_view(
    b: Builtin,
    res: u32,
    camera: usize,
    (paths, seed): (u32, u64),
    size: [u32; 2],
) -> (LitView, Scene) {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let (scene, gates, tracer, _, _) = gate_support::fixture(b, res, camera);
    let paths = PathParams {
        paths,
        bounces: 1,
        seed,
    };
    let vpls = path_vpls(&tracer, &scene.lights, &paths).expect("vpls");
    let view = View::new(&scene.cameras[camera], size).expect("view");
    let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let lit = LitView {
        ctx,
        gates,
        vpls,
        view,
        gpu,
    };
    (lit, scene)
}

/// The pillared hall baked at 128 and its side room (lit through its door by the hall's two
/// lights), 1,024 light paths of `seed`, the room's view at `size`.
fn side_room(seed: u64, size: [u32; 2]) -> LitView {
    lit_view(Builtin::PillaredHall, 128, 1, (1024, seed), size).0
}

#[test]
fn an_interleaved_side_room_is_lit_where_every_vpl_lights_it() {
    let LitView {
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
    let mut room = side_room(2, [320, 240]);
    let accurate = GatesParams::default().accurate();
    assert_eq!(accurate.interleave.starved_taps, 48);
    let mut render = |mode: GpuMode| room.render(mode);
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

/// The near field (`GatesParams::near_field`): in the pillared hall's main view, lit by its two
/// lights, most of the interleaving's error lies in the far end's creases beside the point
/// light, spots that single VPLs light; walking the VPLs within the balanced setting's 4
/// blocks' width at each pixel itself takes most of it away, against every VPL at every pixel
/// (1,024 paths, 320 × 240; measured 5.07e-4 without, 4.60e-5 with), and the ratio estimator
/// (the balanced setting's too) most of what is left (2.35e-6 with its unshadowed light on the
/// setting's 3 px grid; 1.84e-6 summed at every pixel, 4.8e-6 on the grid before the pixels
/// where its light spreads summed their own).
#[test]
fn the_near_field_takes_the_creases_error_out_of_the_interleaving() {
    let (mut lit, _) = lit_view(Builtin::PillaredHall, 128, 0, (1024, 0), [320, 240]);
    let balanced = GatesParams::default().balanced();
    assert_eq!(
        balanced.near_field, 4.0,
        "the balanced setting's near field"
    );
    assert!(balanced.ratio, "and its ratio estimator");
    let mut every = balanced;
    every.interleave.block = 1;
    let every = lit.render(GpuMode::Gates(every));
    let direct = lit.render(GpuMode::DirectOnly);
    let mut near = balanced;
    near.ratio = false;
    let mut plain = near;
    plain.near_field = 0.0;
    let images = [plain, near, balanced].map(|g| lit.render(GpuMode::Gates(g)));
    let [e_plain, e_near, e_ratio] = images
        .each_ref()
        .map(|i| errors(i, &every).expect("same size"));
    let [i_plain, i_near, i_ratio] = images
        .each_ref()
        .map(|i| indirect_errors(i, &every, &direct).expect("same size"));
    eprintln!(
        "pillared hall, main: indirect MSE against every VPL at every pixel {:.3e} without the \
         near field, {:.3e} with 4 blocks, {:.3e} with the ratio estimator too; energy {:.3} / \
         {:.3} / {:.3}",
        e_plain.mse,
        e_near.mse,
        e_ratio.mse,
        i_plain.energy_ratio,
        i_near.energy_ratio,
        i_ratio.energy_ratio
    );
    assert!(
        e_near.mse < 0.25 * e_plain.mse,
        "{e_near:?} against {e_plain:?}"
    );
    assert!((i_near.energy_ratio - 1.0).abs() < 0.05, "{i_near:?}");
    // What the near field leaves, the interleaving's error from the VPLs beyond it, the ratio
    // estimator takes most of.
    assert!(
        e_ratio.mse < 0.1 * e_near.mse,
        "{e_ratio:?} against {e_near:?}"
    );
    assert!((i_ratio.energy_ratio - 1.0).abs() < 0.05, "{i_ratio:?}");
}

/// With a near field wider than the level at every pixel (8 blocks on an 8 × 6 image of the
/// Cornell box: its whole share reaches over 4 times each point's distance from the eye),
/// every VPL is near: the interleaved gathers take none and each pixel walks them all itself,
/// which is the render with every VPL at every pixel. On lavapipe every tile marks every VPL
/// and walks them in rounds of 2 (the loop limit; `methods::near_run`): 114 rounds, all but
/// the first over the tiles that the round before left (relative MSE 0.24 with them left out).
#[test]
fn a_near_field_that_holds_every_vpl_is_every_vpl_at_every_pixel() {
    let (mut lit, scene) = lit_view(Builtin::CornellBox, 64, 0, (256, 1), [8, 6]);
    let mut near = GatesParams::default().balanced();
    near.near_field = 8.0;
    let (view, vpls) = (lit.view, lit.vpls.len() as u32);
    let scale = near.near_scale(&view, vpls);
    let (lo, hi) = scene.bounds().expect("bounds");
    let nearest = (lo - view.eye)
        .max(view.eye - hi)
        .max(glam::Vec3::ZERO)
        .length();
    assert!(
        scale / 2.0 * nearest.max(0.5) > (hi - lo).length(),
        "the near field {scale} m a metre, the box {:?} from the eye {nearest} m",
        hi - lo
    );
    let mut every = near;
    every.interleave.block = 1;
    let every = lit.render(GpuMode::Gates(every));
    let near = lit.render(GpuMode::Gates(near));
    let e = errors(&near, &every).expect("same size");
    eprintln!("near field of every VPL against every VPL at every pixel: {e:?}");
    assert!(e.reference_mean > 0.0, "{e:?}");
    assert!(e.rel_mse < 1e-8, "{e:?}");
}

/// The ratio estimator's known answer (`GatesParams::ratio`): in one closed room (one cluster,
/// the portal walk) every VPL lights every point it faces, so the taps' walks find all of
/// their subsets' light visible and the blur's share is 1: each pixel gets its own unshadowed
/// far light, summed over every VPL, and the near field its near light, which together are
/// the render with every VPL at every pixel (measured: relative MSE 7e-14) — where the
/// interleaving's average, without the ratio, is off by what the subsets' light changes
/// across a block (7.8e-4). With the voxel walk 2e-7: a few pixels along the ceiling, whose
/// walks to VPLs beside them the closed voxels block at some pixels of a block and not at
/// others. On the unshadowed light's 3 px grid (`GatesParams::ratio_stride`, the balanced
/// setting's) the pixels between the grid's take it bilinearly: 5.8e-7. With the walks'
/// roulette on (S = 0.05, the balanced setting's auto share from 2,048 VPLs): the share is of
/// the light of the VPLs walked, each weighed as its light, so still 1 (measured 7.4e-14;
/// against the subset's whole unshadowed light, as before, 7.9e-7).
#[test]
fn the_ratio_estimator_in_a_room_that_sees_itself_is_every_vpl_at_every_pixel() {
    use visgate_runtime::gpu::WalkRoulette;
    let (mut lit, _) = lit_view(Builtin::EmptyBox, 32, 0, (1024, 1), [160, 120]);
    let mut balanced = GatesParams::default().balanced();
    balanced.gates.shape = visgate_runtime::cpu::gates::GateShape::Portal;
    balanced.walk_roulette = WalkRoulette::Share(0.05);
    let mut every = balanced;
    every.interleave.block = 1;
    every.walk_roulette = WalkRoulette::Share(0.0);
    let every = lit.render(GpuMode::Gates(every));
    let mut ratio = balanced;
    balanced.ratio = false;
    ratio.ratio = true;
    ratio.ratio_stride = 1;
    let mut grid = ratio;
    grid.ratio_stride = 3;
    let [plain, ratio, grid] = [balanced, ratio, grid].map(|g| lit.render(GpuMode::Gates(g)));
    let [e_plain, e_ratio, e_grid] =
        [&plain, &ratio, &grid].map(|i| errors(i, &every).expect("same size"));
    eprintln!(
        "empty box against every VPL at every pixel: relative MSE {:.3e} averaged, {:.3e} with \
         the ratio estimator, {:.3e} on its 3 px grid",
        e_plain.rel_mse, e_ratio.rel_mse, e_grid.rel_mse
    );
    assert!(e_ratio.reference_mean > 0.0, "{e_ratio:?}");
    assert!(e_ratio.rel_mse < 1e-10, "{e_ratio:?}");
    assert!(e_plain.rel_mse > 100.0 * e_ratio.rel_mse, "{e_plain:?}");
    // On a grid the pixels between take the light bilinearly, which it is not quite: a small
    // error, far below the average's.
    assert!(e_grid.rel_mse < 0.05 * e_plain.rel_mse, "{e_grid:?}");
}

/// The unshadowed light sums its VPLs in runs of `RATIO_RUN` a dispatch (lavapipe's loop
/// limit), each adding to the runs' before: past one run (20,000 light paths, the walks'
/// roulette off so that the ratio stays on) the empty box's known answer holds as it does
/// within one — every VPL at every pixel (measured: relative MSE 1.2e-12; 9.6e-3 with the
/// shader's run set to half the renderer's, the last VPLs left out) — and on the balanced
/// setting's grid, within its bilinear error.
#[test]
fn the_ratio_estimators_unshadowed_light_holds_every_run_of_vpls() {
    use visgate_runtime::gpu::{RATIO_RUN, WalkRoulette};
    let (mut lit, _) = lit_view(Builtin::EmptyBox, 32, 0, (20_000, 1), [16, 12]);
    assert!(lit.vpls.len() as u32 > RATIO_RUN, "{} VPLs", lit.vpls.len());
    let mut ratio = GatesParams::default().balanced();
    ratio.gates.shape = visgate_runtime::cpu::gates::GateShape::Portal;
    ratio.walk_roulette = WalkRoulette::Share(0.0);
    // No near field: at 16 × 12 pixels its radius would hold the whole box.
    ratio.near_field = 0.0;
    ratio.ratio_stride = 1;
    assert!(ratio.ratio_for(lit.vpls.len() as u32));
    let mut every = ratio;
    every.interleave.block = 1;
    let every = lit.render(GpuMode::Gates(every));
    let mut grid = ratio;
    grid.ratio_stride = 3;
    let [ratio, grid] = [ratio, grid].map(|g| lit.render(GpuMode::Gates(g)));
    let [e, e_grid] = [&ratio, &grid].map(|i| errors(i, &every).expect("same size"));
    eprintln!(
        "{} VPLs, ratio against every VPL at every pixel: {e:?}; on a 3 px grid {e_grid:?}",
        lit.vpls.len()
    );
    assert!(e.reference_mean > 0.0, "{e:?}");
    assert!(e.rel_mse < 1e-10, "{e:?}");
    // On a 3 px grid the grid's pixels and those beside the box's creases sum both runs too:
    // 4.6e-4 before the list's spread test, 8.0e-5 with it (16 × 12 pixels, a grid of 6 × 5:
    // the bilinear light's error); 1.2e-2 with the shader's run set to half the renderer's
    // (measured while the shader held a copy of it; now injected from the renderer's).
    assert!(e_grid.rel_mse < 2e-3, "{e_grid:?}");
}

/// A lamp outside a window to the void: 1,024 light paths leave 189 VPLs in the sun window's
/// rooms, 3 a pixel in 8 × 8 blocks. The block shrinks to 2 × 2 (47 a pixel; 3 × 3 is no
/// power of two), and the room beyond the door comes nearer every VPL at every pixel:
/// measured at 160 × 120 (the balanced setting, baked at 96), the relative MSE 0.628 → 0.053
/// and black where lit 17.3 → 9.0 % of 399 lit pixels.
#[test]
fn few_vpls_shrink_the_interleaving_block_and_light_the_room_beyond_the_door() {
    let (mut lit, _) = lit_view(Builtin::SunWindow, 96, 1, (1024, 1), [160, 120]);
    let n = lit.vpls.len() as u32;
    assert!((100..400).contains(&n), "{n} VPLs");
    let gates = |block, min_vpls| {
        let mut p = GatesParams::default().balanced();
        p.interleave = InterleaveParams {
            block,
            min_vpls,
            ..p.interleave
        };
        GpuMode::Gates(p)
    };
    let shrunk = gates(8, 12);
    assert_eq!(
        shrunk.interleave_for(n).interleave().map(|i| i.block),
        Some(2)
    );
    let direct = lit.render(GpuMode::DirectOnly);
    let every = lit.render(gates(1, 12));
    let (eight, two) = (lit.render(gates(8, 0)), lit.render(shrunk));
    let (fixed, small) = (
        errors(&eight, &every).expect("same size"),
        errors(&two, &every).expect("same size"),
    );
    let (fixed_i, small_i) = (
        indirect_errors(&eight, &every, &direct).expect("same size"),
        indirect_errors(&two, &every, &direct).expect("same size"),
    );
    eprintln!(
        "{n} VPLs against every VPL at every pixel: 8 × 8 rel. MSE {:.3e}, energy {:.3}, black \
         {:.1} % of {}; shrunk to 2 × 2 {:.3e}, {:.3}, {:.1} %",
        fixed.rel_mse,
        fixed_i.energy_ratio,
        100.0 * fixed_i.black_where_lit,
        fixed_i.lit_pixels,
        small.rel_mse,
        small_i.energy_ratio,
        100.0 * small_i.black_where_lit
    );
    assert!(fixed_i.lit_pixels > 200, "{fixed_i:?}");
    assert!(small.rel_mse < 0.6 * fixed.rel_mse, "{small:?} / {fixed:?}");
    // A few hundred lit pixels: a line of them moves the share by a point, so the black
    // share is held to no worse (by 2 points) and the MSE carries the gain.
    assert!(
        small_i.black_where_lit < fixed_i.black_where_lit + 0.02,
        "{small_i:?} / {fixed_i:?}"
    );
    assert!((small_i.energy_ratio - 1.0).abs() < 0.1, "{small_i:?}");
}
