//! The CPU twin's gate test against ray-cast visibility, and the GPU's gates and light lists against the twin.

use super::*;

#[test]
fn two_rooms_a_vpl_in_a_lights_b_only_through_the_doorway_gates() {
    let (scene, level) = baked(Builtin::TwoRooms, 96);
    let ka = Builtin::TwoRooms.known_answers();
    let (a_room, b_room) = (&ka.rooms[0], &ka.rooms[1]);
    let tracer = Tracer::new(&scene);
    let gates = GateLevel::new(level.clone(), &scene).expect("level");
    // VPLs on room A's floor, points on room B's floor and walls seen from a grid.
    let lerp = |lo: [f32; 3], hi: [f32; 3], t: Vec3| {
        Vec3::from(lo) + (Vec3::from(hi) - Vec3::from(lo)) * t
    };
    let mut lit = 0;
    let mut tested = 0;
    let mut exact_lit = 0;
    let (mut portal_lit, mut portal_wrong) = (0, 0);
    let params = GateParams {
        shape: GateShape::Disk,
        ..GateParams::default()
    };
    let portals = GateParams {
        shape: GateShape::Portal,
        ..GateParams::default()
    };
    // Where a segment crosses the doorway wall (x 4.0–4.2 m), its least distance from the
    // doorway's frame (z 1.5–2.5, y 0–2.1), metres.
    let outside_doorway = |a: Vec3, b: Vec3| {
        [4.0, 4.1, 4.2]
            .map(|x| {
                let q = a.lerp(b, (x - a.x) / (b.x - a.x));
                (1.5 - q.z).max(q.z - 2.5).max(q.y - 2.1).max(-q.y).abs()
            })
            .into_iter()
            .fold(f32::MAX, f32::min)
    };
    for i in 1..6 {
        for k in 1..6 {
            let t = Vec3::new(i as f32 / 6.0, 0.0, k as f32 / 6.0);
            let vpl = lerp(a_room.min_m, a_room.max_m, t) + Vec3::Y * 0.01;
            let ca = gates.cluster_at(vpl, Vec3::Y).expect("VPL cluster");
            for u in 1..8 {
                for w in 1..8 {
                    let s = Vec3::new(u as f32 / 8.0, 0.3, w as f32 / 8.0);
                    let p = lerp(b_room.min_m, b_room.max_m, s);
                    let cb = gates.cluster_at(p, Vec3::Y).expect("point cluster");
                    assert_ne!(ca, cb, "rooms A and B share a cluster");
                    tested += 1;
                    let end = |position, cluster| End {
                        position,
                        normal: Vec3::Y,
                        cluster: Some(cluster),
                    };
                    let (from, to) = (end(vpl, ca), end(p, cb));
                    let through = gates.visible(&from, &to, &params);
                    let seen = !tracer.occluded(vpl, p);
                    exact_lit += seen as u32;
                    if through {
                        lit += 1;
                        // Light through a gate disk (no wider than the doorway) is really seen.
                        assert!(seen, "gate lets light through a wall: {vpl} → {p}");
                    }
                    // Portals: the walk's answer is the ray's but for segments that graze the
                    // doorway's frame (crossing within a voxel of its edge, 0.0854 m).
                    if gates.visible(&from, &to, &portals) {
                        portal_lit += 1;
                    }
                    if gates.visible(&from, &to, &portals) != seen {
                        portal_wrong += 1;
                        assert!(
                            outside_doorway(vpl, p).abs() < 0.0854,
                            "portal walk {} but ray {seen}: {vpl} → {p}",
                            !seen
                        );
                    }
                }
            }
        }
    }
    eprintln!(
        "two rooms: {lit} of {tested} VPL–point pairs lit through gates, {exact_lit} seen exactly; \
         {} clusters, {} gates",
        gates.cluster_count(),
        gates.gate_count()
    );
    eprintln!("portals: {portal_lit} lit, {portal_wrong} disagree with the ray (all at the frame)");
    assert!(lit > 0 && lit <= exact_lit);
    assert!(
        portal_lit > lit && portal_wrong * 20 <= exact_lit,
        "{portal_lit} {portal_wrong}"
    );
    // Without the gates, room A lights nothing in room B.
    let mut closed = level.clone();
    closed.topology.gates.clear();
    let closed = GateLevel::new(closed, &scene).expect("level");
    let vpl = Vec3::from(a_room.min_m).lerp(Vec3::from(a_room.max_m), 0.5)
        * Vec3::new(1.0, 0.0, 1.0)
        + Vec3::Y * 0.01;
    let ca = closed.cluster_at(vpl, Vec3::Y).expect("cluster");
    let p = Vec3::from(b_room.min_m).lerp(Vec3::from(b_room.max_m), 0.5);
    let cb = closed.cluster_at(p, Vec3::Y).expect("cluster");
    let end = |position, cluster| End {
        position,
        normal: Vec3::Y,
        cluster: Some(cluster),
    };
    assert!(!closed.visible(&end(vpl, ca), &end(p, cb), &params));
}

#[test]
fn a_level_baked_from_other_geometry_is_refused_with_a_re_bake_message() {
    let (mut scene, level) = baked(Builtin::TwoRooms, 48);
    scene.meshes[0].positions[0] += Vec3::X * 0.01;
    let e = GateLevel::new(level, &scene).err().expect("refused");
    assert!(e.to_string().contains("re-bake"), "{e}");
}

#[test]
fn gate_tests_are_stable_at_the_extremes() {
    use visgate_runtime::cpu::gates::segment_crosses_disk;
    let (c, n) = (Vec3::ZERO, Vec3::X);
    // A VPL in the plane of a gate: the segment never crosses the plane.
    assert!(!segment_crosses_disk(
        Vec3::new(0.0, 0.1, 0.0),
        Vec3::new(0.0, 0.2, 0.3),
        c,
        n,
        1.0
    ));
    // At the gate's centre: it crosses at t = 0.
    assert!(segment_crosses_disk(c, Vec3::new(1.0, 0.1, 0.0), c, n, 0.5));
    // A gate of radius zero lets only the exact centre through.
    assert!(!segment_crosses_disk(
        Vec3::new(-1.0, 0.1, 0.0),
        Vec3::new(1.0, 0.1, 0.0),
        c,
        n,
        0.0
    ));
    assert!(segment_crosses_disk(
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        c,
        n,
        0.0
    ));
    // Degenerate segments and NaN radii: no crossing, no panic.
    assert!(!segment_crosses_disk(c, c, c, n, 1.0));
    assert!(!segment_crosses_disk(Vec3::NEG_X, Vec3::X, c, n, f32::NAN));
}

#[test]
fn gpu_gates_agree_with_the_cpu_twin() {
    use visgate_runtime::gpu::{GatesParams, GpuContext, GpuMode, GpuParams, GpuRenderer};
    use visgate_runtime::metrics::errors;
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    for (b, res) in [(Builtin::FourRooms, 128), (Builtin::TwoRooms, 96)] {
        let (scene, gates, tracer, vpls, view) = fixture(b, res);
        let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
        assert!(
            gpu.render(
                &ctx,
                &view,
                &vpls,
                &GpuParams::with_mode(GpuMode::Gates(GatesParams::default()))
            )
            .is_err(),
            "gates without a level must be refused"
        );
        gpu.set_level(&ctx, &gates).expect("level upload");
        // A level loads without its closed voxels' triangle lists; the walk with them is
        // refused until they are listed and uploaded.
        let with_triangles = GpuMode::GatesPerPixel(GateParams {
            shape: GateShape::Voxels,
            triangles: true,
            ..GateParams::default()
        });
        assert!(!gates.sight().triangles_listed() && !gpu.level_has_triangles());
        let refused = gpu.render(&ctx, &view, &vpls, &GpuParams::with_mode(with_triangles));
        assert!(
            refused.is_err_and(|e| e.to_string().contains("list_triangles")),
            "the triangle walk without lists must be refused"
        );
        gpu.level_for_mode(&ctx, &gates, &with_triangles)
            .expect("level upload");
        assert!(gates.sight().triangles_listed() && gpu.level_has_triangles());
        // Another render of a run (its own renderer) that walks without them uploads none,
        // though they are listed now: where they overflow the adapter's storage binding, only
        // the walk with them fails (`visgate compare` with a variant of
        // `--closed-voxel-triangles`). `set_level`, the viewer's, carries what is listed.
        let plain = GpuMode::GatesPerPixel(GateParams {
            shape: GateShape::Voxels,
            ..GateParams::default()
        });
        let mut other = GpuRenderer::new(&ctx, &scene).expect("upload");
        other
            .level_for_mode(&ctx, &gates, &plain)
            .expect("level upload");
        assert!(!other.level_has_triangles());
        other
            .level_for_mode(&ctx, &gates, &with_triangles)
            .expect("level upload");
        assert!(other.level_has_triangles());
        other.set_level(&ctx, &gates).expect("level upload");
        assert!(other.level_has_triangles());
        for (clustered, hops, shape, triangles) in [
            (true, 1, GateShape::Disk, false),
            (true, 2, GateShape::Disk, false),
            (false, 1, GateShape::Disk, false),
            (false, 2, GateShape::Disk, false),
            (true, 2, GateShape::Portal, false),
            (false, 2, GateShape::Portal, false),
            (true, 2, GateShape::Voxels, false),
            (false, 2, GateShape::Voxels, false),
            (true, 2, GateShape::Voxels, true),
            (false, 2, GateShape::Voxels, true),
        ] {
            let gp = GateParams {
                oversize: 1.5,
                max_hops: hops,
                shape,
                triangles,
                ..GateParams::default()
            };
            let mode = if clustered {
                GpuMode::Gates(GatesParams {
                    gates: gp,
                    ..every_vpl_at_every_pixel()
                })
            } else {
                GpuMode::GatesPerPixel(gp)
            };
            let (img, _) = gpu
                .render(&ctx, &view, &vpls, &GpuParams::with_mode(mode))
                .expect("render");
            let cpu = cpu_twin(&tracer, &scene.lights, &vpls, &view, (&gates, gp));
            let e = errors(&img, &cpu).expect("same size");
            eprintln!(
                "{} {} {shape:?} {hops} hop(s), triangles {triangles}: {e:?}",
                b.name(),
                mode.name()
            );
            assert!(
                e.rel_mse < 0.02,
                "{} {} {hops}: {e:?}",
                b.name(),
                mode.name()
            );
            assert!(
                (e.image_mean / e.reference_mean - 1.0).abs() < 0.01,
                "{e:?}"
            );
        }
    }
}

#[test]
fn clustered_light_lists_give_exactly_the_per_point_gate_test() {
    use glam::Vec2;
    use visgate_runtime::cpu::clustered::{ClusterParams, PixelSurface, assign, entry_reaches};
    // The thin walls, ajar door and table of the ajar door, the columns and loops of the
    // pillared hall: the portal cull must keep every pair a walk lights there too.
    for (b, res) in [
        (Builtin::FourRooms, 128),
        (Builtin::TwoRooms, 96),
        (Builtin::AjarDoor, 128),
        (Builtin::PillaredHall, 128),
    ] {
        let (_scene, gates, tracer, vpls, view) = fixture(b, res);
        let pixels: Vec<Option<PixelSurface>> = (0..48u32)
            .flat_map(|y| (0..64u32).map(move |x| (x, y)))
            .map(|(x, y)| {
                let dir = view.ray_dir(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
                tracer.trace(view.eye, dir).map(|s| PixelSurface {
                    position: s.position,
                    normal: s.normal,
                    depth: (s.position - view.eye).dot(view.forward),
                    cluster: gates.cluster_at(s.position, s.normal),
                })
            })
            .collect();
        for gp in [
            GateParams {
                oversize: 1.0,
                max_hops: 1,
                shape: GateShape::Disk,
                ..GateParams::default()
            },
            GateParams {
                oversize: 1.5,
                max_hops: 2,
                shape: GateShape::Disk,
                ..GateParams::default()
            },
            GateParams {
                shape: GateShape::Portal,
                ..GateParams::default()
            },
            GateParams {
                shape: GateShape::Voxels,
                ..GateParams::default()
            },
        ] {
            let c = assign(
                &pixels,
                64,
                &vpls,
                &gates,
                &gp,
                (&ClusterParams::default(), 1),
            );
            let vpl_cluster: Vec<_> = vpls
                .iter()
                .map(|v| gates.cluster_at(Vec3::from(v.position), Vec3::from(v.normal)))
                .collect();
            let mut lit_pairs = 0u64;
            for (i, p) in pixels.iter().enumerate() {
                let Some(p) = p else { continue };
                let list = &c.lists[c.pixel_cluster[i] as usize];
                for (j, v) in vpls.iter().enumerate() {
                    // Walks' lists drop the VPLs a point lies behind (they cannot light it).
                    let behind =
                        (p.position - Vec3::from(v.position)).dot(Vec3::from(v.normal)) < 0.0;
                    if gp.shape != GateShape::Disk && behind {
                        continue;
                    }
                    let vpl = End::of_vpl(v, vpl_cluster[j]);
                    let point = End {
                        position: p.position,
                        normal: p.normal,
                        cluster: p.cluster,
                    };
                    let want = gates.visible(&vpl, &point, &gp);
                    let got = list
                        .iter()
                        .filter(|e| e.vpl == j as u32)
                        .any(|e| entry_reaches(e, v, &point, &gates, &gp));
                    assert_eq!(got, want, "{} pixel {i} VPL {j} {gp:?}", b.name());
                    lit_pairs += got as u64;
                }
            }
            let covered = pixels.iter().flatten().count() as u64 * vpls.len() as u64;
            eprintln!(
                "{} {gp:?}: {} geometry clusters, {} list entries ({:.1} per cluster) for {} \
                 pixel-VPL pairs, {} lit",
                b.name(),
                c.clusters.len(),
                c.entries(),
                c.entries() as f64 / c.clusters.len() as f64,
                covered,
                lit_pairs
            );
            // Every pixel of a geometry cluster shares one visibility cluster.
            for (i, p) in pixels.iter().enumerate() {
                if let Some(p) = p {
                    assert_eq!(c.clusters[c.pixel_cluster[i] as usize].cluster, p.cluster);
                }
            }
        }
    }
}

#[test]
fn gpu_light_lists_equal_the_cpu_twin() {
    use visgate_runtime::cpu::clustered::{
        CONE_SLACK, ClusterParams, LightEntry, assign, cone_margin,
    };
    use visgate_runtime::gpu::{GatesParams, GpuContext, GpuRenderer};
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    for (b, res) in [(Builtin::FourRooms, 128), (Builtin::TwoRooms, 96)] {
        let (scene, gates, _tracer, vpls, view) = fixture(b, res);
        let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
        gpu.set_level(&ctx, &gates).expect("level upload");
        for (gp, cp) in [
            (
                GateParams {
                    oversize: 1.0,
                    max_hops: 1,
                    shape: GateShape::Disk,
                    ..GateParams::default()
                },
                ClusterParams::default(),
            ),
            (
                GateParams {
                    oversize: 1.5,
                    max_hops: 2,
                    shape: GateShape::Disk,
                    ..GateParams::default()
                },
                ClusterParams {
                    tile_px: 8,
                    depth_slices: 7,
                },
            ),
        ] {
            let params = GatesParams {
                gates: gp,
                clusters: cp,
                ..GatesParams::default()
            };
            let (pixels, got) = gpu.light_lists(&ctx, &view, &vpls, &params).expect("lists");
            // The G-buffer's visibility cluster follows the CPU rule (through the normal side;
            // the normal is stored in half precision, so allow a few pixels on voxel borders).
            let surfaces: Vec<_> = pixels.iter().flatten().collect();
            let differ = surfaces
                .iter()
                .filter(|p| p.cluster != gates.cluster_at(p.position, p.normal))
                .count();
            assert!(
                surfaces.len() > 1000,
                "{} pixels see a surface",
                surfaces.len()
            );
            assert!(
                differ * 200 <= surfaces.len(),
                "{differ} of {} pixels",
                surfaces.len()
            );
            // The CPU twin on the same G-buffer gives the same clusters, boxes and lists.
            let subsets = params.interleave.subsets();
            let want = assign(&pixels, view.size[0], &vpls, &gates, &gp, (&cp, subsets));
            assert_eq!(got.pixel_cluster, want.pixel_cluster, "{}", b.name());
            assert_eq!(got.clusters.len(), want.clusters.len());
            for (g, w) in got.clusters.iter().zip(&want.clusters) {
                assert_eq!((g.tile, g.cluster), (w.tile, w.cluster));
                assert_eq!(g.bounds, w.bounds, "{} cluster {:?}", b.name(), g.tile);
            }
            // Equal lists, but for entries whose cone test lies within float rounding of its
            // edge (the GPU's asin / acos differ from the CPU's in the last bits), each in the
            // order of the interleaving subsets (VPL mod B, VPL).
            let mut borderline = 0;
            for (k, (g, w)) in got.lists.iter().zip(&want.lists).enumerate() {
                let key = |e: &LightEntry| (e.vpl % subsets, e.vpl);
                assert!(
                    g.is_sorted_by_key(key) && w.is_sorted_by_key(key),
                    "list {k} order"
                );
                let (s, r) = got.clusters[k].sphere();
                let odd = g
                    .iter()
                    .filter(|e| !w.contains(e))
                    .chain(w.iter().filter(|e| !g.contains(e)));
                for e in odd {
                    let (c, _, radius) = gates.gate(e.gates[0]);
                    let a = Vec3::from(vpls[e.vpl as usize].position);
                    let margin = cone_margin(a, c, radius * gp.oversize, s, r);
                    assert!(
                        (margin - CONE_SLACK).abs() < 1e-4,
                        "{} {gp:?} {cp:?} cluster {k}: {e:?} differs, cone margin {margin} rad",
                        b.name()
                    );
                    borderline += 1;
                }
            }
            // Every pixel of a geometry cluster shares one visibility cluster.
            for (i, p) in pixels.iter().enumerate() {
                if let Some(p) = p {
                    assert_eq!(
                        got.clusters[got.pixel_cluster[i] as usize].cluster,
                        p.cluster
                    );
                }
            }
            eprintln!(
                "{} {gp:?} {cp:?}: {} geometry clusters, {} entries ({borderline} on a cone's \
                 edge differ), {differ} pixels of {} differ from the CPU cluster rule",
                b.name(),
                got.clusters.len(),
                got.entries(),
                surfaces.len()
            );
            assert!(
                borderline * 1000 <= got.entries(),
                "{borderline} entries differ"
            );
        }
    }
}

#[test]
fn gates_per_pixel_keeps_every_vpls_light_at_thousands_a_pixel() {
    // Every VPL at every pixel through the voxels and the portals, 4,096 of them: walked in
    // the shading pass, all in one loop, llvmpipe ended the loop early (its 65,535 iterations
    // an invocation) and the ajar door's main camera kept 0.67 of its CPU twin's radiance
    // here; run as mode gates in 1 × 1 blocks, its walks batched, it keeps the twin's.
    use visgate_runtime::gpu::{GpuContext, GpuMode, GpuParams, GpuRenderer};
    use visgate_runtime::metrics::errors;
    use visgate_runtime::vpl::{PathParams, path_vpls};
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let (scene, gates, tracer, _, _) = fixture(Builtin::AjarDoor, 64);
    let paths = PathParams {
        paths: 4096,
        bounces: 1,
        seed: 4,
    };
    let vpls = path_vpls(&tracer, &scene.lights, &paths).expect("vpls");
    let main = scene
        .cameras
        .iter()
        .find(|c| c.name == "main")
        .expect("camera main");
    let view = visgate_runtime::camera::View::new(main, [16, 12]).expect("view");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    gpu.set_level(&ctx, &gates).expect("level upload");
    for shape in [GateShape::Voxels, GateShape::Portal] {
        let gp = GateParams {
            shape,
            ..GateParams::default()
        };
        let mode = GpuMode::GatesPerPixel(gp);
        let (img, _) = gpu
            .render(&ctx, &view, &vpls, &GpuParams::with_mode(mode))
            .expect("render");
        let cpu = cpu_twin(&tracer, &scene.lights, &vpls, &view, (&gates, gp));
        let e = errors(&img, &cpu).expect("same size");
        let ratio = e.image_mean / e.reference_mean;
        assert!((ratio - 1.0).abs() < 0.01, "{shape:?}: {ratio} ({e:?})");
    }
}
