//! The large scenes in `../shared/scenes/` (or `$VISGATE_SHARED_SCENES`). Skipped, with the
//! reason printed, where they are absent.

use std::path::PathBuf;
use std::time::Instant;

use visgate_formats::{ImportOptions, Scene};

fn shared_scenes() -> Option<PathBuf> {
    let dir = std::env::var_os("VISGATE_SHARED_SCENES")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/scenes"));
    if dir.is_dir() {
        Some(dir)
    } else {
        println!(
            "SKIPPED: {} is absent; set VISGATE_SHARED_SCENES to the folder of shared scenes",
            dir.display()
        );
        None
    }
}

fn load(path: &std::path::Path) -> Scene {
    let start = Instant::now();
    let scene = Scene::load(path, &ImportOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    println!(
        "{}: {} triangles read, {} degenerate dropped, {} materials, {} textures ({} failed), {:.3} s",
        path.display(),
        scene.report.triangles_read,
        scene.report.degenerate_dropped,
        scene.materials.len(),
        scene.textures.len(),
        scene.report.textures_failed,
        start.elapsed().as_secs_f64()
    );
    scene
}

/// The repository's scene file `scenes/shared/NAME.toml` for a shared level.
fn scene_file(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/shared/{name}.toml"))
}

/// Each triangle as its corners quantised to `q` units, rotated so the smallest corner comes
/// first (winding kept), sorted.
fn canonical_triangles(scene: &Scene, q: f32) -> Vec<[[i64; 3]; 3]> {
    let mut v: Vec<[[i64; 3]; 3]> = scene
        .static_triangles()
        .map(|t| {
            let t = t.map(|p| p.to_array().map(|c| (c / q).round() as i64));
            let k = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        })
        .collect();
    v.sort_unstable();
    v
}

#[test]
fn every_shared_scene_loads() {
    let Some(dir) = shared_scenes() else { return };
    let expect = [
        ("cornell_box/CornellBox-Original.obj", 36, 0),
        ("cornell_box/CornellBox-Original.gltf", 36, 0),
        ("crytek_sponza/sponza.obj", 262_267, 232),
        ("crytek_sponza/sponza.glb", 262_267, 232),
        ("dabrovic_sponza/sponza.obj", 66_454, 1),
        ("dabrovic_sponza/sponza.gltf", 66_454, 1),
        ("librequake_e2m3/e2m3.obj", 24_610, 2_748),
    ];
    for (file, read, degenerate) in expect {
        let scene = load(&dir.join(file));
        assert_eq!(scene.report.triangles_read, read, "{file}");
        assert_eq!(scene.report.degenerate_dropped, degenerate, "{file}");
        assert_eq!(scene.triangle_count(), read - degenerate, "{file}");
        assert_eq!(scene.report.textures_failed, 0, "{file}");
        // Their polygons are convex, fanned as before: e2m3's brush faces, whose rounded corners
        // turn back by up to 1.7e-4, are not taken for concave (visgate_formats::polygons).
        assert_eq!(scene.report.concave_polygons, 0, "{file}");
        // Nothing in them is taken for a sky box, a sky dome or a stray helper.
        assert_eq!(
            visgate_formats::stray::stray_geometry(&scene),
            None,
            "{file}"
        );
        if degenerate > 0 {
            assert!(
                scene
                    .report
                    .warnings
                    .iter()
                    .any(|w| w.contains(&format!("{degenerate} degenerate")))
            );
        }
    }
    // The textured scenes have their textures.
    let dab = load(&dir.join("dabrovic_sponza/sponza.obj"));
    assert!(dab.materials.iter().filter(|m| m.texture.is_some()).count() >= 18);
    let quake = load(&dir.join("librequake_e2m3/e2m3.obj"));
    assert!(quake.materials.iter().any(|m| m.name.starts_with("sky_")));
}

#[test]
fn crytek_sponza_obj_and_glb_give_the_same_triangles() {
    let Some(dir) = shared_scenes() else { return };
    let obj = load(&dir.join("crytek_sponza/sponza.obj"));
    let glb = load(&dir.join("crytek_sponza/sponza.glb"));
    assert_eq!(obj.triangle_count(), 262_035);
    assert_eq!(glb.triangle_count(), 262_035);
    let (a, b) = (
        canonical_triangles(&obj, 1e-3),
        canonical_triangles(&glb, 1e-3),
    );
    let differing = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    assert_eq!(
        differing, 0,
        "{differing} triangles differ between the OBJ and the GLB"
    );
    assert_eq!(obj.bounds(), glb.bounds());
}

#[test]
fn dabrovic_sponzas_80_arcade_lights_cluster_into_fewer_as_the_minimum_distance_grows() {
    use visgate_runtime::camera::View;
    use visgate_runtime::cpu::lightcluster::{CULLED, LightClusterParams, cluster_lights};
    if shared_scenes().is_none() {
        return;
    }
    let scene = load(&scene_file("dabrovic-sponza-80-lights"));
    assert_eq!(scene.lights.len(), 80);
    let (lo, hi) = scene.static_bounds().expect("bounds");
    let diagonal = (hi - lo).length();
    for camera in &scene.cameras {
        let view = View::new(camera, [1920, 1080]).expect("view");
        let mut counts = Vec::new();
        for d in [0.0, 0.25, 0.5, 1.0, 2.0, 4.0, 1e3] {
            let params = LightClusterParams {
                min_distance_m: d,
                max_clusters: 256,
                ..LightClusterParams::default()
            };
            let c = cluster_lights(&scene.lights, &view, diagonal, &params).expect("clusters");
            let live = c.light_cluster.iter().filter(|&&k| k != CULLED).count();
            if d == 0.0 {
                assert_eq!(
                    c.centres.len(),
                    live,
                    "no minimum distance: a cluster a light"
                );
            }
            counts.push((d, c.centres.len(), c.culled));
        }
        println!(
            "{}: (min distance m, clusters, culled) {counts:?}",
            camera.name
        );
        assert!(counts.windows(2).all(|w| w[0].1 >= w[1].1), "{counts:?}");
        assert_eq!(counts.last().map(|c| c.1), Some(1));
    }
}

#[test]
fn levels_wound_inside_out_bake_as_written() {
    use visgate_formats::vgate::{BakeParams, Resolution};
    use visgate_preprocess::bake::{BakeOptions, Baked, bake};
    let Some(dir) = shared_scenes() else { return };
    // On the level's own grid: the winding is read there (a finer partition grid would only
    // make this test slower).
    let params = BakeParams {
        resolution: Resolution::LongestAxisVoxels(128),
        partition_voxel_m: Some(0.0),
        ..BakeParams::default()
    };
    let bake_it = |s: &Scene| bake(s, &params, &BakeOptions::default(), &|_| {}).expect("bake");
    let said = |b: &Baked| b.report.empty_space["faces_turned"] == true;
    // The bare OBJs, as `visgate bake FILE` reads them (no camera, no light): e2m3's void
    // wraps its rooms; Crytek Sponza's rooms are open to the sky. And their scene files, whose
    // cameras and lights are in the rooms.
    for file in [
        dir.join("librequake_e2m3/e2m3.obj"),
        dir.join("crytek_sponza/sponza.obj"),
        scene_file("librequake-e2m3"),
        scene_file("crytek-sponza"),
    ] {
        let file = file.display().to_string();
        let written = load(std::path::Path::new(&file));
        let mut turned = written.clone();
        for m in &mut turned.meshes {
            m.triangles.iter_mut().for_each(|t| t.swap(1, 2));
        }
        let (w, t) = (bake_it(&written), bake_it(&turned));
        println!(
            "{file} at 128: {} / {} clusters, faces turned {} / {}",
            w.level.topology.clusters.len(),
            t.level.topology.clusters.len(),
            said(&w),
            said(&t)
        );
        // Read as written, e2m3's void was kept and its rooms dropped.
        assert!(!said(&w) && said(&t), "{file}");
        assert!(w.level.voxel_cluster == t.level.voxel_cluster, "{file}");
    }
}

#[test]
fn dabrovic_sponza_at_128_is_partitioned_as_at_256() {
    use visgate_formats::vgate::{BakeParams, NONE, Resolution};
    use visgate_preprocess::bake::{BakeOptions, bake};
    if shared_scenes().is_none() {
        return;
    }
    let scene = load(&scene_file("dabrovic-sponza-80-lights"));
    let at = |res: u32, partition_voxel_m: Option<f32>| {
        let params = BakeParams {
            resolution: Resolution::LongestAxisVoxels(res),
            partition_voxel_m,
            ..BakeParams::default()
        };
        bake(&scene, &params, &BakeOptions::default(), &|_| {}).expect("bake")
    };
    let (coarse, fine) = (at(128, None), at(256, None));
    let (c, f) = (&coarse.level, &fine.level);
    // Its 27 cm voxels close the upper arcades: on its own grid the 128 bake partitions
    // another level (17 clusters against 160).
    let own = at(128, Some(0.0)).level.topology.clusters.len();
    let n = [c, f].map(|l| l.topology.clusters.len());
    println!(
        "Dabrovic Sponza clusters: 128 {} (own grid {own}), 256 {}",
        n[0], n[1]
    );
    assert_eq!(
        c.info.params.partition_voxel_m,
        Some(f.info.grid.voxel_size_m)
    );
    assert!(n[0] <= 2 * n[1] && n[1] <= 2 * n[0], "{n:?}");
    assert!(
        2 * own < n[1],
        "the own grid's partition is no longer another level: {own}"
    );
    // Every kept empty voxel of the coarse grid has a cluster.
    let e = &coarse.grids.empty;
    let given = (0..e.len()).filter(|&i| e[i] && c.voxel_cluster.get(i).is_some_and(|k| k != NONE));
    assert_eq!(given.count(), e.iter().filter(|&&x| x).count());
}

/// Crytek Sponza's gallery, 8 × 8 interleaved, against every VPL at every pixel with the walk
/// along the true segment (its visibility the shadow rays' on 99.9 % of pairs; README, *The
/// voxel walk*): with the triangles in the closed voxels and the tent blur it is lit where that
/// is, where the default walk (planes in closed voxels, the box) leaves its fluted columns'
/// and curtains' light out.
#[test]
fn crytek_sponzas_gallery_with_the_triangles_and_the_tent_is_lit_where_every_vpl_lights_it() {
    use visgate_formats::vgate::{BakeParams, Resolution};
    use visgate_preprocess::bake::{BakeOptions, bake};
    use visgate_runtime::camera::View;
    use visgate_runtime::cpu::gates::{GateLevel, GateParams};
    use visgate_runtime::cpu::tracer::Tracer;
    use visgate_runtime::gpu::{
        GatesParams, GpuContext, GpuMode, GpuParams, GpuRenderer, InterleaveParams,
    };
    use visgate_runtime::metrics::indirect_errors;
    use visgate_runtime::vpl::{PathParams, path_vpls};
    if shared_scenes().is_none() {
        return;
    }
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let scene = load(&scene_file("crytek-sponza"));
    // Its sight grid is 4 cm whatever the level's resolution.
    let params = BakeParams {
        resolution: Resolution::LongestAxisVoxels(128),
        ..BakeParams::default()
    };
    let baked = bake(&scene, &params, &BakeOptions::default(), &|_| {}).expect("bake");
    let gates = GateLevel::new(baked.level, &scene).expect("level");
    let tracer = Tracer::new(&scene);
    let paths = PathParams {
        paths: 1024,
        bounces: 1,
        seed: 1,
    };
    let vpls = path_vpls(&tracer, &scene.lights, &paths).expect("vpls");
    let camera = scene.cameras.iter().position(|c| c.name == "gallery");
    let view = View::new(&scene.cameras[camera.expect("gallery")], [320, 240]).expect("view");
    let mode = |block, triangles, tent| {
        GpuMode::Gates(GatesParams {
            gates: GateParams {
                triangles,
                ..GateParams::default()
            },
            interleave: InterleaveParams {
                block,
                tent,
                ..InterleaveParams::default()
            },
            ..GatesParams::default()
        })
    };
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let mut render = |m: GpuMode| {
        gpu.level_for_mode(&ctx, &gates, &m).expect("level");
        gpu.render(&ctx, &view, &vpls, &GpuParams::with_mode(m))
            .expect("render")
            .0
    };
    let direct = render(GpuMode::DirectOnly);
    let every = render(mode(1, true, false));
    let [default, accurate] = [
        ("default walk and box", mode(8, false, false)),
        ("triangles + tent", mode(8, true, true)),
    ]
    .map(|(name, m)| {
        let e = indirect_errors(&render(m), &every, &direct).expect("same size");
        println!(
            "gallery 320×240, 1,024 paths, {name}: energy {:.3}, black where lit {:.2} % of {} \
             lit pixels",
            e.energy_ratio,
            100.0 * e.black_where_lit,
            e.lit_pixels
        );
        e
    });
    assert!(accurate.lit_pixels > 5_000, "{accurate:?}");
    assert!(accurate.black_where_lit < 0.01, "{accurate:?}");
    assert!((accurate.energy_ratio - 1.0).abs() < 0.05, "{accurate:?}");
    // What the triangles and the tent are for: the default leaves more of it out.
    assert!(
        default.black_where_lit > accurate.black_where_lit,
        "{default:?}"
    );
    assert!(default.energy_ratio < accurate.energy_ratio, "{default:?}");
}
