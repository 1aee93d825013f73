//! The same topology at scales from millimetres to ten kilometres a unit, and resolutions 8 and 512.

use super::*;

#[test]
fn scale_from_millimetres_to_ten_kilometres_per_unit_gives_the_same_topology() {
    // On the level's own grid at every scale; at the default partition voxel (a small level's
    // 1/128 of its length, a large one's 12.5 cm or 1/256 of it: sizes in metres, by design)
    // at the scales where the level stays small (under 16 m).
    let own = BakeParams {
        partition_voxel_m: Some(0.0),
        ..params(96)
    };
    let model = Builtin::TwoRooms.model().expect("model");
    let eye = [0.5, 1.6, 2.0];
    for (p, scales) in [
        (&own, &[1e-3, 1e-1, 10.0, 1e4][..]),
        (&params(96), &[1e-3, 1e-1]),
    ] {
        let base = bake_scene(&custom("s1", model.clone(), true, eye, 1.0), p).expect("bake");
        same_topology_at_scales(&base, &model, p, scales);
    }
}

fn same_topology_at_scales(base: &Baked, model: &ImportedModel, p: &BakeParams, scales: &[f64]) {
    for &mpu in scales {
        let s = custom("s", model.clone(), true, [0.5, 1.6, 2.0], mpu);
        let b = bake_scene(&s, p).expect("bake");
        // Solid voxels outside the walls may round differently; the empty space may not.
        let (mut x, mut y) = (b.report.summary.clone(), base.report.summary.clone());
        x.solid_voxels = 0;
        y.solid_voxels = 0;
        assert_eq!(x, y, "metres per unit {mpu}");
        for (g, h) in b
            .level
            .topology
            .gates
            .iter()
            .zip(&base.level.topology.gates)
        {
            let d = (Vec3::from(g.centre_m) / mpu as f32 - Vec3::from(h.centre_m)).length();
            assert!(d < 1e-3, "gate moved by {d} m at {mpu} m/unit");
            assert!((g.radius_m / mpu as f32 - h.radius_m).abs() < 1e-3);
        }
    }
}

#[test]
fn resolutions_8_and_512_bake_or_say_why_not() {
    // At 8 voxels the doorway closes: a clear error or a coarse bake, never a panic.
    let two = Builtin::TwoRooms.scene().expect("scene");
    match bake_scene(&two, &params(8)) {
        Ok(b) => assert!(b.report.summary.skeleton_nodes > 0),
        Err(e) => assert!(matches!(e, BakeError::NoEmptySpace(_)), "{e}"),
    }
    // A 10 m corridor at 512 on its long axis.
    let corridor = BoxLevel {
        cell_m: 0.1,
        wall_cells: 2,
        empty: vec![cbox(0, 100, 0, 10, 0, 10)],
    };
    let s = custom("corridor", model_of(&corridor), true, [1.0, 0.5, 0.5], 1.0);
    let b = bake_scene(&s, &params(512)).expect("bake at 512");
    assert_eq!(b.level.info.grid.dims.iter().max(), Some(&514));
    assert_eq!(
        (b.report.summary.components, b.report.summary.cycles),
        (1, 0)
    );
    assert!(b.report.summary.clusters >= 1);
}
