//! The recorded bytes of three bakes, a bake refined from a coarser partition grid, and the smallest clusters merged.

use super::*;

/// FNV-1a, 64 bits.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The bytes of these bakes, recorded: a change to the bake that should not change its output
/// (a stage moved to a file of its own, a faster flood) must leave them as they are. A change
/// that means to change the output updates them, saying why in its commit.
#[test]
fn the_bake_writes_the_recorded_bytes() {
    // The third goes through the partition grid (its 64 grid) and the refinement.
    let got: Vec<(&str, u64, usize)> = [
        (Builtin::AjarDoor, params(64)),
        (Builtin::PillaredHall, params(64)),
        (Builtin::PillaredHall, pillared_hall_refined()),
    ]
    .into_iter()
    .map(|(b, p)| {
        let scene = b.scene().expect("scene");
        let bytes = bake_scene(&scene, &p)
            .expect("bake")
            .level
            .to_bytes()
            .expect("encode");
        (b.name(), fnv1a(&bytes), bytes.len())
    })
    .collect();
    let want = [
        RECORDED_AJAR_DOOR,
        RECORDED_PILLARED_HALL,
        RECORDED_PILLARED_HALL_REFINED,
    ];
    assert_eq!(got, want, "got {got:#x?}");
}

/// The pillared hall at 128 voxels partitioned on its 64-voxel grid.
fn pillared_hall_refined() -> BakeParams {
    let scene = Builtin::PillaredHall.scene().expect("scene");
    let (lo, hi) = scene.static_bounds().expect("bounds");
    // As the bake sizes a grid of 64 voxels on the longest axis.
    let voxel = ((hi.as_dvec3() - lo.as_dvec3()).max_element() / 64.0) as f32;
    BakeParams {
        partition_voxel_m: Some(voxel),
        ..params(128)
    }
}

#[test]
fn a_bake_finer_than_its_partition_grid_keeps_that_grid_s_clusters_and_gates() {
    let scene = Builtin::PillaredHall.scene().expect("scene");
    let own = BakeParams {
        partition_voxel_m: Some(0.0),
        ..params(64)
    };
    let coarse = bake_scene(&scene, &own).expect("bake");
    let fine = bake_scene(&scene, &pillared_hall_refined()).expect("bake");
    let (c, f) = (&coarse.level, &fine.level);
    assert_eq!(
        coarse.level.info.grid.voxel_size_m,
        fine.level.info.params.partition_voxel_m.expect("stored"),
        "the partition grid is the 64 grid"
    );
    assert_eq!(f.info.grid.dims[0], 2 * c.info.grid.dims[0] - 2);
    // The same gates (the two grids' origins differ in the last bits of a float).
    assert_eq!(f.topology.gates.len(), c.topology.gates.len());
    for (a, b) in f.topology.gates.iter().zip(&c.topology.gates) {
        assert_eq!(
            (a.clusters, a.seg_edge, a.normal),
            (b.clusters, b.seg_edge, b.normal)
        );
        let d = Vec3::from(a.centre_m).distance(Vec3::from(b.centre_m));
        assert!(
            d < 1e-4 && (a.radius_m - b.radius_m).abs() < 1e-4,
            "{a:?} {b:?}"
        );
    }
    assert_eq!(f.topology.segmented, c.topology.segmented);
    assert_eq!(f.topology.node_cluster, c.topology.node_cluster);
    assert_eq!(f.topology.clusters.len(), c.topology.clusters.len());
    // Every kept empty voxel of the fine grid has a cluster; every interface face a portal.
    let refine = fine
        .report
        .stages
        .iter()
        .find(|s| s.name == "refine")
        .expect("a refine stage");
    assert_eq!(refine.counts["unreached"], 0, "{:?}", refine.counts);
    assert!(refine.counts["flooded"].as_u64().expect("count") > 0);
    let g = &f.info.grid;
    for (i, &e) in fine.grids.empty.iter().enumerate() {
        if e {
            assert!(
                f.voxel_cluster.get(i).is_some_and(|k| k != NONE),
                "voxel {i}"
            );
        }
    }
    assert_eq!(fine.report.summary.uncovered_interface_faces, 0);
    // Each gate's two clusters touch on the fine grid: a portal joins them.
    for gate in &f.topology.gates {
        let [a, b] = gate.clusters;
        let pair = [a.min(b), a.max(b)];
        assert!(
            f.topology.portals.iter().any(|p| p.clusters == pair),
            "{gate:?}"
        );
    }
    // The skeleton's voxels are the fine grid's.
    for n in &f.topology.skeleton.nodes {
        assert!((0..3).all(|a| n.voxel[a] < g.dims[a]));
    }
    // Without the partition grid the same bake partitions its own grid.
    let own = bake_scene(
        &scene,
        &BakeParams {
            partition_voxel_m: Some(0.0),
            ..params(128)
        },
    )
    .expect("bake");
    assert!(own.report.stages.iter().all(|s| s.name != "refine"));
}

/// Each cluster's largest max ball. [Units: m]
fn widest_balls(level: &BakedLevel) -> Vec<f32> {
    let t = &level.topology;
    let mut widest = vec![0f32; t.clusters.len()];
    for (s, &c) in t.node_cluster.iter().enumerate() {
        let node = t.segmented.nodes[s].skeleton_node as usize;
        widest[c as usize] = widest[c as usize].max(t.skeleton.nodes[node].radius_m);
    }
    widest
}

#[test]
fn clusters_smaller_than_the_smallest_ball_merge_and_the_portals_still_cover_every_face() {
    let scene = Builtin::PillaredHall.scene().expect("scene");
    let plain = bake_scene(&scene, &params(64)).expect("bake");
    // The size: just above the smallest cluster's widest ball.
    let widest = widest_balls(&plain.level);
    let size = widest.iter().copied().fold(f32::MAX, f32::min) + 1e-3;
    let merged = bake_scene(
        &scene,
        &BakeParams {
            min_cluster_ball_m: Some(size),
            ..params(64)
        },
    )
    .expect("bake");
    let gates = |b: &Baked| -> serde_json::Value {
        let s = b.report.stages.iter().find(|s| s.name == "gates");
        s.expect("gates stage").counts["small_merged"].clone()
    };
    assert_eq!(gates(&plain), 0);
    let n = gates(&merged).as_u64().expect("count");
    assert!(n > 0, "{widest:?}");
    let (p, m) = (&plain.report.summary, &merged.report.summary);
    assert_eq!(m.clusters + n, p.clusters);
    assert_eq!(m.uncovered_interface_faces, 0);
    // Every cluster left holds a ball of that size.
    let widest = widest_balls(&merged.level);
    assert!(widest.iter().all(|&r| r >= size), "{widest:?} {size}");
}
