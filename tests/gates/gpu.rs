//! The GPU's gates at extreme scales and sizes, its pass report, and the interleaved gather's starved pixels and blur.

use super::*;

#[test]
fn gpu_gates_stay_stable_at_the_extremes() {
    use visgate_runtime::gpu::{GatesParams, GpuContext, GpuMode, GpuParams, GpuRenderer};
    use visgate_runtime::vpl::{PathParams, Vpl, path_vpls};
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let (scene, gates, tracer, vpls, view) = fixture(Builtin::FourRooms, 128);
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    gpu.set_level(&ctx, &gates).expect("level");
    let params = GpuParams::with_mode;
    let gates_mode = || GpuMode::Gates(portal_gates());
    // No VPLs: direct light alone, empty lists.
    let (none, t) = gpu
        .render(&ctx, &view, &[], &params(gates_mode()))
        .expect("0 VPLs");
    let (direct, _) = gpu
        .render(&ctx, &view, &[], &params(GpuMode::DirectOnly))
        .expect("direct");
    assert_eq!(none.pixels, direct.pixels);
    assert_eq!(t.lists.expect("lists").entries, 0);
    // 65,536 VPLs on a small image: finite, and more light than direct alone.
    let many = path_vpls(
        &tracer,
        &scene.lights,
        &PathParams {
            paths: 65536,
            bounces: 1,
            seed: 2,
        },
    )
    .expect("vpls");
    let small =
        visgate_runtime::camera::View::new(scene.cameras.first().expect("camera"), [16, 12])
            .expect("view");
    let (img, t) = gpu
        .render(&ctx, &small, &many, &params(gates_mode()))
        .expect("65536 VPLs");
    assert!(img.pixels.iter().all(|p| p.is_finite()));
    let (d, _) = gpu
        .render(&ctx, &small, &[], &params(GpuMode::DirectOnly))
        .expect("direct");
    assert!(
        img.mean().x > d.mean().x * 1.01,
        "{} vs {}",
        img.mean(),
        d.mean()
    );
    eprintln!("65536 VPLs: {:?}", t.lists);
    // A pool too small: an error naming the setting, never an image with light cut.
    let e = gpu
        .render(
            &ctx,
            &view,
            &vpls,
            &params(GpuMode::Gates(GatesParams {
                light_entries: Some(1000),
                ..disk_lists()
            })),
        )
        .expect_err("overflow");
    assert!(e.to_string().contains("--light-entries"), "{e}");
    // All VPLs in one cluster (the camera's): agrees with the twin; lists carry no gates there.
    let home = gates
        .cluster_at(view.eye, Vec3::ZERO)
        .expect("camera cluster");
    let one: Vec<Vpl> = vpls
        .iter()
        .filter(|v| gates.cluster_at(Vec3::from(v.position), Vec3::from(v.normal)) == Some(home))
        .copied()
        .collect();
    assert!(one.len() > 20, "{} VPLs in the camera's cluster", one.len());
    let (_, rel) = gpu_vs_twin(&mut gpu, &ctx, &scene, &tracer, &gates, &one, &view);
    assert!(rel < 0.02, "one cluster: {rel}");
    let (_, lists) = gpu
        .light_lists(&ctx, &view, &one, &disk_lists())
        .expect("lists");
    for (c, l) in lists.clusters.iter().zip(&lists.lists) {
        if c.cluster == Some(home) {
            assert_eq!(l.len(), one.len());
            assert!(l.iter().all(|e| e.gates.is_empty()));
        }
    }
    // VPLs at a gate's centre and in its plane: finite, and as the twin.
    let (c, n, r) = gates.gate(0);
    let t = n.any_orthonormal_vector();
    let flux = Vec3::ONE;
    let on_gate = [
        Vpl::new(c, n, flux),
        Vpl::new(c, -n, flux),
        Vpl::new(c + t * (0.5 * r), n.cross(t), flux),
    ];
    let (_, rel) = gpu_vs_twin(&mut gpu, &ctx, &scene, &tracer, &gates, &on_gate, &view);
    assert!(rel < 0.05, "VPLs on a gate: {rel}");
    // A gate of radius zero passes no light, as on the CPU.
    let (scene0, level0) = baked(Builtin::FourRooms, 128);
    let mut level0 = level0;
    level0.topology.gates[0].radius_m = 0.0;
    let gates0 = GateLevel::new(level0, &scene0).expect("level");
    let mut gpu0 = GpuRenderer::new(&ctx, &scene0).expect("upload");
    gpu0.set_level(&ctx, &gates0).expect("level");
    let (_, rel) = gpu_vs_twin(&mut gpu0, &ctx, &scene0, &tracer, &gates0, &vpls, &view);
    assert!(rel < 0.02, "gate of radius 0: {rel}");
    // A camera inside a wall: finite, and as the twin.
    let dir = (view.forward).normalize();
    let hit = tracer.trace(view.eye, dir).expect("a wall ahead");
    let mut cam = scene.cameras[0].clone();
    cam.eye = hit.position + dir * 0.02;
    cam.target = cam.eye + dir;
    let inside = visgate_runtime::camera::View::new(&cam, [64, 48]).expect("view");
    let (img, rel) = gpu_vs_twin(&mut gpu, &ctx, &scene, &tracer, &gates, &vpls, &inside);
    eprintln!("camera in a wall: mean {}, rel. MSE {rel}", img.mean());
    assert!(rel < 0.05, "camera in a wall: {rel}");
}

#[test]
fn gpu_gates_give_the_same_image_at_scales_1e_3_to_1e4() {
    use visgate_runtime::gpu::{GatesParams, GpuContext, GpuMode, GpuParams, GpuRenderer};
    use visgate_runtime::metrics::errors;
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let shapes = [GateShape::Portal, GateShape::Disk, GateShape::Voxels];
    // Each scale baked once; its image with each gate shape.
    let mut images: [Vec<_>; 3] = Default::default();
    for s in [1e-3f32, 1.0, 1e4] {
        let (scene, cam) = common::scaled_four_rooms(s);
        let gates = GateLevel::new(gate_support::bake_at(&scene, 96).level, &scene).expect("level");
        let tracer = Tracer::new(&scene);
        let vpls = light_paths(&tracer, &scene);
        let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
        gpu.set_level(&ctx, &gates).expect("level");
        let view = visgate_runtime::camera::View::new(&cam, [64, 48]).expect("view");
        for (shape, out) in shapes.iter().zip(&mut images) {
            let gates_mode = GatesParams {
                gates: GateParams {
                    shape: *shape,
                    ..GateParams::default()
                },
                ..GatesParams::default()
            };
            let params = GpuParams {
                g_max: 10.0 / (s * s),
                ..GpuParams::with_mode(GpuMode::Gates(gates_mode))
            };
            let (img, t) = gpu.render(&ctx, &view, &vpls, &params).expect("render");
            eprintln!(
                "scale {s} {shape:?}: {} clusters, {} gates, {:?}, mean {}",
                gates.cluster_count(),
                gates.gate_count(),
                t.lists,
                img.mean()
            );
            out.push(img);
        }
    }
    for (shape, images) in shapes.iter().zip(&images) {
        for img in [&images[0], &images[2]] {
            let e = errors(img, &images[1]).expect("same size");
            assert!(e.rel_mse < 1e-3, "{shape:?}: {e:?}");
        }
    }
}

#[test]
fn the_pass_report_counts_pixels_and_vpls_outside_every_cluster() {
    use visgate_runtime::gpu::{GpuContext, GpuMode, GpuParams, GpuRenderer};
    use visgate_runtime::vpl::Vpl;
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let (scene, gates, _tracer, mut vpls, inside) = fixture(Builtin::FourRooms, 128);
    // A camera outside the building sees its outer walls, which face no cluster's space.
    let (lo, hi) = scene.bounds().expect("bounds");
    let outside_cam = visgate_formats::Camera {
        name: "outside".into(),
        eye: lo - (hi - lo) * 0.5 + Vec3::Y * (hi - lo).y,
        target: (lo + hi) * 0.5,
        up: Vec3::Y,
        fov_x_rad: 60f32.to_radians(),
    };
    let view = visgate_runtime::camera::View::new(&outside_cam, inside.size).expect("view");
    // Five VPLs far outside the baked grid: no cluster, their light unoccluded.
    vpls.extend((0..5).map(|k| Vpl::new(Vec3::new(1e3 + k as f32, 1e3, 0.0), Vec3::Y, Vec3::ONE)));
    let want_vpls = vpls
        .iter()
        .filter(|v| {
            gates
                .cluster_at(Vec3::from(v.position), Vec3::from(v.normal))
                .is_none()
        })
        .count();
    assert!(want_vpls >= 5);
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    gpu.set_level(&ctx, &gates).expect("level");
    let params = GpuParams::with_mode(GpuMode::Gates(portal_gates()));
    let (_, t) = gpu.render(&ctx, &view, &vpls, &params).expect("render");
    let lists = t.lists.expect("lists");
    assert_eq!(lists.vpls_outside as usize, want_vpls);
    let (pixels, _) = gpu
        .light_lists(&ctx, &view, &vpls, &portal_gates())
        .expect("lists");
    let outside = pixels
        .iter()
        .flatten()
        .filter(|p| p.cluster.is_none())
        .count();
    assert_eq!(lists.pixels_outside as usize, outside);
    assert!(outside > 100, "{outside} pixels outside every cluster");
    eprintln!("outside: {outside} pixels, {want_vpls} VPLs");
}

#[test]
fn interleaved_gates_keep_the_light_of_every_vpl_gather() {
    use visgate_runtime::gpu::InterleaveParams;
    use visgate_runtime::gpu::{GatesParams, GpuMode, GpuParams, GpuRenderer};
    use visgate_runtime::metrics::errors;
    let (ctx, mut gpu, vpls, view) = four_rooms_on_the_gpu([128, 96]);
    let render = |gpu: &mut GpuRenderer, mode| {
        gpu.render(&ctx, &view, &vpls, &GpuParams::with_mode(mode))
            .expect("render")
    };
    let (direct, _) = render(&mut gpu, GpuMode::DirectOnly);
    let (full, _) = render(&mut gpu, GpuMode::Gates(every_vpl_at_every_pixel()));
    let indirect = |img: &visgate_runtime::hdr::HdrImage| (img.mean() - direct.mean()).x;
    for block in [2, 4, 8] {
        let params = GatesParams {
            interleave: InterleaveParams {
                block,
                ..InterleaveParams::default()
            },
            ..GatesParams::default()
        };
        let (img, t) = render(&mut gpu, GpuMode::Gates(params));
        // Each pixel gathered its subset alone (a pass of its own), then the blur.
        let names: Vec<&str> = t.passes.iter().map(|p| p.name).collect();
        assert!(
            names.contains(&"indirect lighting") && names.contains(&"blur + compose"),
            "{names:?}"
        );
        let ratio = indirect(&img) / indirect(&full);
        let e = errors(&img, &full).expect("same size");
        eprintln!(
            "block {block}: indirect energy {ratio:.3} of every VPL's, rel. MSE {:.2e}",
            e.rel_mse
        );
        assert!(
            (ratio - 1.0).abs() < 0.05,
            "block {block}: energy ratio {ratio}"
        );
        assert!(e.rel_mse < 0.05, "block {block}: rel. MSE {}", e.rel_mse);
        assert!(e.rel_mse > 0.0, "block {block}: the image did not change");
    }
}

#[test]
fn starved_pixels_walk_the_subsets_their_block_lacks_and_count_every_vpl_once() {
    use visgate_runtime::gpu::InterleaveParams;
    use visgate_runtime::gpu::{GatesParams, GpuMode, GpuParams, GpuRenderer, WalkRoulette};
    use visgate_runtime::metrics::errors;
    let (ctx, mut gpu, vpls, view) = four_rooms_on_the_gpu([96, 72]);
    let render = |gpu: &mut GpuRenderer, mode| {
        gpu.render(&ctx, &view, &vpls, &GpuParams::with_mode(mode))
            .expect("render")
    };
    for shape in [GateShape::Voxels, GateShape::Portal] {
        let with = |block: u32, blur_distance: f32, starved_taps: u32| {
            // Every VPL walked (no roulette at 256 VPLs a pixel): the sums are exact.
            let mut p = GatesParams {
                interleave: InterleaveParams {
                    block,
                    blur_distance,
                    starved_taps,
                    min_vpls: 0,
                    ..InterleaveParams::default()
                },
                walk_roulette: WalkRoulette::Share(0.0),
                ..GatesParams::default()
            };
            p.gates.shape = shape;
            GpuMode::Gates(p)
        };
        let (full, _) = render(&mut gpu, with(1, 0.1, 0));
        for block in [4, 8] {
            // No tap but the pixel itself agrees (blur distance 0): every pixel is starved and
            // walks the other b² − 1 subsets itself, so the image is every VPL's gather.
            let (img, t) = render(&mut gpu, with(block, 0.0, block * block));
            let names: Vec<&str> = t.passes.iter().map(|p| p.name).collect();
            assert!(
                names.contains(&"indirect lighting: starved pixels"),
                "{names:?}"
            );
            // A (pixel, subset) pair for each of the b² − 1 other taps of every lit pixel's
            // block, in a list that grew from four pairs a pixel to hold them all.
            let st = t.starved.expect("starved pixels' stats");
            let lit = img.pixels.iter().filter(|p| p.max_element() > 0.0).count() as u32;
            assert!(st.pixels > 0 && st.pixels <= 96 * 72 && st.pixels + 96 * 72 / 10 >= lit);
            assert_eq!(
                st.pairs,
                u64::from(st.pixels) * u64::from(block * block - 1)
            );
            assert!(u64::from(st.capacity) >= st.pairs && st.capacity > 4 * 96 * 72);
            let e = errors(&img, &full).expect("same size");
            eprintln!(
                "{shape:?} block {block}: rel. MSE {:.2e} to every VPL's, {} starved pixels, \
                 {} pairs (list of {})",
                e.rel_mse, st.pixels, st.pairs, st.capacity
            );
            assert!(e.rel_mse < 1e-8, "{shape:?} block {block}: {}", e.rel_mse);
            // Without it the same blur leaves each pixel its own subset, × b².
            let (alone, t) = render(&mut gpu, with(block, 0.0, 0));
            assert!(!t.passes.iter().any(|p| p.name.contains("starved")));
            let e = errors(&alone, &full).expect("same size");
            assert!(e.rel_mse > 1e-3, "{shape:?} block {block}: {}", e.rel_mse);
        }
    }
}

#[test]
fn the_blur_filled_from_the_next_blocks_is_nearer_every_vpls_gather_and_leaves_agreeing_taps() {
    use visgate_runtime::gpu::InterleaveParams;
    use visgate_runtime::gpu::{GatesParams, GpuMode, GpuParams};
    use visgate_runtime::metrics::errors;
    let (ctx, mut gpu, vpls, view) = four_rooms_on_the_gpu([96, 72]);
    let mut render = |block: u32, fill: bool, (blur_distance, blur_normal): (f32, f32)| {
        let p = GatesParams {
            interleave: InterleaveParams {
                block,
                blur_distance,
                blur_normal,
                fill,
                ..InterleaveParams::default()
            },
            ..GatesParams::default()
        };
        let params = GpuParams::with_mode(GpuMode::Gates(p));
        gpu.render(&ctx, &view, &vpls, &params).expect("render").0
    };
    let laine = (0.1, 0.8);
    let full = render(1, false, laine);
    for block in [4, 8] {
        // Along the rooms' edges and the doorways a block holds taps that do not agree; their
        // subsets' copies a block away that do bring the average nearer every VPL's (less at
        // 8 × 8, whose subsets each hold all directions of the lights: 1.95e-2 → 1.85e-2).
        let bound = if block == 4 { 0.9 } else { 0.97 };
        let plain = errors(&render(block, false, laine), &full).expect("size");
        let filled = errors(&render(block, true, laine), &full).expect("size");
        eprintln!(
            "block {block}: rel. MSE to every VPL's {:.3e} -> {:.3e} filled",
            plain.rel_mse, filled.rel_mse
        );
        assert!(
            filled.rel_mse < bound * plain.rel_mse,
            "block {block}: {} vs {}",
            filled.rel_mse,
            plain.rel_mse
        );
        // Where every tap agrees nothing is filled: the same image, bit for bit.
        let all = (1e9, -1.0);
        assert_eq!(
            render(block, true, all),
            render(block, false, all),
            "block {block}"
        );
    }
}
