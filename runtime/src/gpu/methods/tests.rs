use super::*;

#[test]
fn the_default_roulette_is_on_where_an_interleaved_pixel_walks_many_vpls() {
    use super::super::passes::clustered_gates::AUTO_ROULETTE_SHARE as AUTO;
    let mut p = GatesParams::default();
    assert_eq!(p.walk_roulette, WalkRoulette::Auto);
    assert_eq!(p.interleave.block, 8);
    assert_eq!(p.roulette_share(4_096), 0.0, "64 VPLs a pixel");
    assert_eq!(p.roulette_share(8_192), AUTO);
    assert_eq!(p.roulette_share(16_384), AUTO);
    assert_eq!(p.roulette_share(8_128), 0.0, "127 VPLs a pixel");
    // Reports name it as it acts.
    let described = |p, vpls| GpuMode::Gates(p).describe_for(vpls);
    assert_eq!(
        described(p, 8_192),
        "voxel walk, 8×8 interleaved, roulette under 0.05 (auto)"
    );
    assert_eq!(described(p, 4_096), "voxel walk, 8×8 interleaved");
    assert!(GpuMode::Gates(p).describe().ends_with("roulette auto"));
    // With the ratio estimator (the balanced setting) from 32 VPLs a pixel, its near field
    // and ratio kept until 128.
    let balanced = GatesParams::default().balanced();
    assert_eq!(balanced.roulette_share(2_048), AUTO);
    assert_eq!(balanced.roulette_share(1_984), 0.0, "31 VPLs a pixel");
    assert!(!described(balanced, 1_024).contains("roulette"));
    let named = described(balanced, 4_096);
    assert!(
        named.ends_with("ratio estimator (grid 3 px), roulette under 0.05 (auto)"),
        "{named}"
    );
    assert!(described(balanced, 8_192).ends_with("roulette under 0.05 (auto)"));
    assert!(!described(balanced, 8_192).contains("ratio"));
    p.interleave.block = 16;
    assert_eq!(p.roulette_share(32_768), AUTO);
    // 4 × 4 blocks blur too few subsets to hide it; no blur, none at all.
    for block in [1, 4] {
        p.interleave.block = block;
        assert_eq!(p.roulette_share(16_384), 0.0, "{block}");
        assert!(!described(p, 16_384).contains("roulette"), "{block}");
    }
    p.walk_roulette = WalkRoulette::Share(0.1);
    assert_eq!(p.roulette_share(16), 0.1);
    p.walk_roulette = WalkRoulette::Share(0.0);
    p.interleave.block = 8;
    assert_eq!(p.roulette_share(16_384), 0.0, "off when asked");
}

/// A 320 × 240 view with a horizontal field of 1.2 rad.
fn view_320x240() -> crate::camera::View {
    let camera = visgate_formats::scene::Camera {
        name: "c".into(),
        eye: glam::Vec3::ZERO,
        target: glam::Vec3::NEG_Z,
        up: glam::Vec3::Y,
        fov_x_rad: 1.2,
    };
    crate::camera::View::new(&camera, [320, 240]).expect("view")
}

#[test]
fn the_roulette_keeps_the_near_field_and_the_ratio_until_a_subset_holds_128_vpls() {
    let view = view_320x240();
    let mut p = GatesParams::default().balanced();
    p.walk_roulette = WalkRoulette::Share(0.05);
    for vpls in [1_024, 4_096, 8_128] {
        assert!(!p.thinned(vpls), "{vpls}");
        assert!(
            p.near_scale(&view, vpls) > 0.0 && p.ratio_for(vpls),
            "{vpls}"
        );
        let resolved = GpuMode::Gates(p).resolved_for(vpls);
        assert!(
            matches!(resolved, GpuMode::Gates(r) if r.ratio && r.near_field == 4.0),
            "{vpls}"
        );
        let named = GpuMode::Gates(p).describe_for(vpls);
        assert!(
            named.contains("near field 4 blocks, ratio estimator"),
            "{named}"
        );
        assert!(named.ends_with("roulette under 0.05"), "{named}");
    }
    // 128 a subset: both off, as the resolved mode says.
    assert!(p.thinned(8_192));
    assert!(p.near_scale(&view, 8_192) == 0.0 && !p.ratio_for(8_192));
    let resolved = GpuMode::Gates(p).resolved_for(8_192);
    assert!(matches!(resolved, GpuMode::Gates(r) if !r.ratio && r.near_field == 0.0));
    // Without the roulette, never thinned.
    p.walk_roulette = WalkRoulette::Share(0.0);
    assert!(!p.thinned(16_384) && p.ratio_for(16_384));
    // In 4 × 4 blocks a subset holds 128 from 2,048 VPLs.
    p.walk_roulette = WalkRoulette::Share(0.05);
    p.interleave.block = 4;
    assert!(!p.thinned(2_032) && p.thinned(2_048));
}

#[test]
fn the_near_field_is_on_in_the_balanced_setting_where_the_walks_are_not_thinned() {
    let view = view_320x240();
    let balanced = GatesParams::default().balanced();
    assert_eq!(balanced.near_field, 4.0);
    assert_eq!(GatesParams::default().near_field, 0.0, "the fast setting");
    // 4 blocks of 8 pixels, each 2 tan(fov_x / 2) / 320 of the distance.
    let pixel = 2.0 * (view.fov_x_rad / 2.0).tan() / 320.0;
    let scale = balanced.near_scale(&view, 1_024);
    assert!((scale - 32.0 * pixel).abs() < 1e-6, "{scale}");
    assert_eq!(
        balanced.near_scale(&view, 8_128),
        scale,
        "127 VPLs a subset"
    );
    assert_eq!(balanced.near_scale(&view, 8_192), 0.0, "the roulette on");
    let described = |p, vpls| GpuMode::Gates(p).describe_for(vpls);
    assert!(described(balanced, 1_024).contains("near field 4 blocks"));
    assert!(!described(balanced, 16_384).contains("near field"));
    // The ratio estimator likewise: in the balanced setting, off where the roulette is on.
    assert!(described(balanced, 1_024).contains("ratio estimator"));
    assert!(!described(balanced, 16_384).contains("ratio estimator"));
    assert!(balanced.ratio_for(8_128) && !balanced.ratio_for(8_192));
    assert!(
        GatesParams::default()
            .balanced()
            .accurate()
            .ratio_for(1_024)
    );
    assert!(
        !GatesParams::default().fast().ratio_for(1_024),
        "the fast setting"
    );
    let mut disks = balanced;
    disks.gates.shape = GateShape::Disk;
    assert!(!disks.ratio_for(1_024), "the paper's disks walk nothing");
    let mut p = balanced;
    p.walk_roulette = WalkRoulette::Share(0.0);
    assert_eq!(p.near_scale(&view, 16_384), scale, "the roulette off");
    assert_eq!(p.near_scale(&view, 40_000), 0.0, "over the marks' words");
    p.interleave.block = 1;
    assert_eq!(p.near_scale(&view, 1_024), 0.0, "not interleaved");
    let mut p = balanced;
    p.gates.shape = GateShape::Disk;
    assert_eq!(
        p.near_scale(&view, 1_024),
        0.0,
        "the paper's disks walk nothing"
    );
    assert_eq!(GatesParams::default().fast().near_scale(&view, 1_024), 0.0);
    p = balanced;
    p.near_field = 9.0;
    assert!(p.check().is_err());
    // The ratio estimator's grid: the settings', named; 0 and 1 every pixel; 8 the widest.
    assert_eq!(balanced.ratio_stride, crate::gpu::RATIO_STRIDE);
    assert!(described(balanced, 1_024).contains("ratio estimator (grid 3 px)"));
    p = balanced;
    for (n, grid) in [(0, 1), (1, 1), (8, 8)] {
        p.ratio_stride = n;
        assert!(p.check().is_ok(), "stride {n}");
        assert_eq!(p.ratio_grid(), grid);
    }
    assert!(described(p, 1_024).contains("ratio estimator (grid 8 px)"));
    p.ratio_stride = 1;
    assert!(!described(p, 1_024).contains("grid"));
    p.ratio_stride = 9;
    assert!(p.check().is_err());
}

/// The ratio estimator's grid holds the pixels 0, s, 2s, … and the last of each axis.
#[test]
fn the_ratio_grid_ends_on_the_last_pixel() {
    use crate::gpu::passes::unshadowed::ratio_grid_size;
    assert_eq!(ratio_grid_size([16, 12], 2), [9, 7]);
    assert_eq!(ratio_grid_size([16, 12], 1), [16, 12]);
    assert_eq!(ratio_grid_size([16, 12], 0), [16, 12]);
    // 320: 0, 3, …, 318 and 319.
    assert_eq!(ratio_grid_size([320, 1], 3), [108, 1]);
    assert_eq!(ratio_grid_size([1, 7], 8), [1, 2]);
}

/// Where the list of the pixels that sum their own would not fit a storage binding, the grid
/// falls back to every pixel (no list): 8192 × 4096 against lavapipe's 128 MiB.
#[test]
fn the_ratio_grid_falls_back_to_every_pixel_where_its_list_would_not_fit() {
    use crate::gpu::passes::unshadowed::{own_list_bytes, stride_that_fits};
    let mib128 = 128 << 20;
    assert_eq!(own_list_bytes([16, 12]), 193 * 4);
    assert_eq!(stride_that_fits(3, [3840, 2160], mib128), 3);
    assert_eq!(stride_that_fits(3, [7680, 4320], mib128), 3);
    assert_eq!(stride_that_fits(3, [8192, 4096], mib128), 1);
}

/// Gates with the portal walk.
fn portals() -> GatesParams {
    let mut p = GatesParams::default();
    p.gates.shape = GateShape::Portal;
    p
}

#[test]
fn portals_walk_in_batches_on_a_software_rasterizer_alone() {
    let portals = portals();
    let llvmpipe = "llvmpipe (LLVM 19.1.7, 256 bits)";
    let gates = GpuMode::Gates(portals);
    assert_eq!(
        walk_batch(llvmpipe, &gates, Some(1251), 1024),
        SOFTWARE_WALK_BATCH
    );
    assert_eq!(
        walk_batch("NVIDIA H100 80GB HBM3", &gates, Some(1251), 1024),
        0
    );
    let mut disks = portals;
    disks.gates.shape = GateShape::Disk;
    assert_eq!(walk_batch(llvmpipe, &GpuMode::Gates(disks), None, 1024), 0);
    assert_eq!(
        walk_batch(llvmpipe, &GpuMode::GatesPerPixel(portals.gates), None, 1024),
        0
    );
    // Voxel walks: as many as fit the loop limit at the sight grid's longest walk, at
    // least one (tests/gates/blur_roulette.rs loses light with a thousand times as many).
    let mut voxels = portals;
    voxels.gates.shape = GateShape::Voxels;
    let voxels = GpuMode::Gates(voxels);
    assert_eq!(walk_batch(llvmpipe, &voxels, Some(1251), 1024), 52);
    assert_eq!(walk_batch(llvmpipe, &voxels, Some(99), 1024), 652);
    // With the triangles, a walk may read 512 list entries too.
    let mut triangles = portals;
    triangles.gates.shape = GateShape::Voxels;
    triangles.gates.triangles = true;
    let triangles = GpuMode::Gates(triangles);
    assert_eq!(walk_batch(llvmpipe, &triangles, Some(1251), 1024), 37);
    assert_eq!(walk_batch(llvmpipe, &triangles, Some(99), 1024), 106);
    assert_eq!(walk_batch(llvmpipe, &voxels, Some(200_000), 1024), 1);
    assert_eq!(
        walk_batch(llvmpipe, &voxels, None, 1024),
        SOFTWARE_WALK_BATCH
    );
    // The roulette's sum over a pixel's subset (16,384 VPLs in 8 × 8: 256) first.
    let GpuMode::Gates(mut roulette) = voxels else {
        unreachable!()
    };
    roulette.walk_roulette = WalkRoulette::Share(0.05);
    let roulette = GpuMode::Gates(roulette);
    assert_eq!(walk_batch(llvmpipe, &roulette, Some(1251), 1024), 52);
    assert_eq!(
        walk_batch(llvmpipe, &roulette, Some(99), 16_384),
        (65_279 - 256) / 100
    );
    // The default roulette, on at 256 VPLs a pixel, sums them too.
    assert_eq!(
        walk_batch(llvmpipe, &voxels, Some(99), 16_384),
        (65_279 - 256) / 100
    );
    for steps in [3, 100, 1251, 4000] {
        for (mode, lists) in [(&voxels, 0), (&triangles, TRIANGLE_TESTS_PER_WALK)] {
            let batch = walk_batch(llvmpipe, mode, Some(steps), 1024);
            assert!(
                batch * (steps + 1 + lists) + 256 <= 65_535,
                "{steps}: {batch}"
            );
        }
    }
    assert_eq!(
        walk_batch("NVIDIA H100 80GB HBM3", &voxels, Some(1251), 1024),
        0
    );
}

#[test]
fn portal_walks_a_pixel_follow_the_shape_and_the_interleaving() {
    use crate::cpu::gates::GateShape;
    assert_eq!(GatesParams::default().gates.shape, GateShape::Voxels);
    let portals = portals();
    assert_eq!(portals.interleave.subsets(), 64);
    assert_eq!(GpuMode::Gates(portals).walks_per_pixel(4096), 64);
    assert_eq!(GpuMode::Gates(portals).walks_per_pixel(4097), 65);
    assert_eq!(
        GpuMode::GatesPerPixel(portals.gates).walks_per_pixel(4096),
        4096
    );
    let mut disks = portals;
    disks.gates.shape = GateShape::Disk;
    assert_eq!(GpuMode::Gates(disks).walks_per_pixel(4096), 0);
    assert_eq!(GpuMode::GatesPerPixel(disks.gates).walks_per_pixel(4096), 0);
    assert_eq!(GpuMode::None.walks_per_pixel(4096), 0);
}

#[test]
fn every_registered_method_makes_its_own_mode() {
    let s = MethodSettings::default();
    for m in METHODS {
        let mode = (m.make)(&s);
        assert_eq!(mode.name(), m.name);
        assert_eq!(mode.gates().is_some(), m.needs_level, "{}", m.name);
        assert!(mode.check().is_ok(), "{}", m.name);
    }
}

#[test]
fn the_block_shrinks_where_the_vpls_are_too_few_for_it() {
    let il = InterleaveParams {
        starved_taps: 48,
        ..InterleaveParams::default()
    };
    assert_eq!(il.min_vpls, 12);
    // 8 × 8 from 768 VPLs (12 a pixel); below, the largest power of two that leaves 12.
    let blocks = [
        (16_384, 8),
        (928, 8),
        (768, 8),
        (767, 4),
        (192, 4),
        (189, 2),
        (48, 2),
    ];
    for (vpls, block) in blocks.into_iter().chain([(47, 1)]) {
        assert_eq!(il.for_vpls(vpls).block, block, "{vpls}");
    }
    assert_eq!((il.for_vpls(11).block, il.for_vpls(0).block), (1, 8));
    // The starved taps in proportion (48 of 64: 12 of 16), at most the block's pixels.
    let four = il.for_vpls(200);
    assert_eq!((four.block, four.starved_taps), (4, 12));
    let all = InterleaveParams {
        starved_taps: 64,
        ..il
    };
    assert_eq!(all.for_vpls(20).starved_taps, 1);
    // Off, or a block given smaller: as given.
    let fixed = InterleaveParams { min_vpls: 0, ..il };
    assert_eq!(fixed.for_vpls(64), fixed);
    let small = InterleaveParams { block: 2, ..il };
    assert_eq!(small.for_vpls(189), small);
    // A block given that is no power of two shrinks to one.
    let six = InterleaveParams { block: 6, ..il };
    assert_eq!(six.for_vpls(300).block, 4);
    assert!(
        InterleaveParams {
            min_vpls: 4_097,
            ..il
        }
        .check()
        .is_err()
    );
    // The gates run it, and a report names it with the block asked for.
    let gates = GpuMode::Gates(GatesParams::default());
    let ran = gates.interleave_for(189).interleave().expect("interleaved");
    assert_eq!(ran.block, 2);
    let named = gates.describe_for(189);
    assert!(
        named.contains("2×2 interleaved (8×8 for 189 VPLs: 3.0 a pixel)"),
        "{named}"
    );
    assert!(!gates.describe_for(1_024).contains("for 1024 VPLs"));
    // Where the rule keeps the block, the frame is the fixed block's (compare renders it once).
    let fixed_gates = GpuMode::Gates(GatesParams {
        interleave: fixed,
        ..GatesParams::default()
    });
    let default_gates = GpuMode::Gates(GatesParams {
        interleave: il,
        ..GatesParams::default()
    });
    assert_eq!(
        fixed_gates.resolved_for(1_024),
        default_gates.resolved_for(1_024)
    );
    assert_ne!(
        fixed_gates.resolved_for(189),
        default_gates.resolved_for(189)
    );
    // The VAL modes keep theirs.
    let val = GpuMode::ValHard(Default::default());
    assert_eq!(val.interleave_for(189), val);
    let one = GpuMode::Gates(GatesParams::default()).describe_for(11);
    assert!(
        one.contains("every VPL per pixel (8×8 for 11 VPLs: 0.2 a pixel)"),
        "{one}"
    );
    assert_eq!(GpuMode::None.interleave_for(10), GpuMode::None);
}
