//! A level whose faces are all wound the other way (winding.rs) bakes as the level does: the
//! same kept space, clusters and voxel grid, with its faces said to be turned.

use visgate_formats::Scene;
use visgate_formats::vgate::{BakeParams, Resolution};
use visgate_preprocess::bake::{BakeOptions, Baked, bake};
use visgate_scenes::Builtin;

fn bake_at(scene: &Scene, res: u32) -> Baked {
    let p = BakeParams {
        resolution: Resolution::LongestAxisVoxels(res),
        ..BakeParams::default()
    };
    bake(scene, &p, &BakeOptions::default(), &|_| {}).expect("bake")
}

/// `scene` with every triangle wound the other way.
fn turned(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    for m in &mut s.meshes {
        m.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    }
    s
}

/// Whether the bake read the faces turned.
fn faces_turned(b: &Baked) -> bool {
    b.report.empty_space["faces_turned"] == true
}

#[test]
fn a_level_wound_inside_out_bakes_as_the_level_with_and_without_lights() {
    for (b, res) in [
        (Builtin::LCorridor, 64),
        (Builtin::PillaredHall, 96),
        (Builtin::AjarDoor, 64),
        (Builtin::FourRooms, 64),
    ] {
        let lit = b.scene().expect("built-in");
        // As a bare mesh file reads: no light, no camera, not declared closed.
        let mut bare = lit.clone();
        bare.lights.clear();
        bare.cameras.clear();
        bare.closed = false;
        for (what, scene) in [("lit", lit), ("bare", bare)] {
            let (written, flipped) = (bake_at(&scene, res), bake_at(&turned(&scene), res));
            let kept = |b: &Baked| -> Vec<bool> {
                let c = b.report.empty_space["components"].as_array().expect("list");
                c.iter().map(|c| c["kept"] == true).collect()
            };
            eprintln!(
                "{} {what}: {} / {} clusters, turned {} / {}",
                b.name(),
                written.level.topology.clusters.len(),
                flipped.level.topology.clusters.len(),
                faces_turned(&written),
                faces_turned(&flipped)
            );
            assert!(!faces_turned(&written), "{} {what}", b.name());
            assert!(faces_turned(&flipped), "{} {what}", b.name());
            assert_eq!(kept(&written), kept(&flipped), "{} {what}", b.name());
            assert_eq!(
                written.level.voxel_cluster,
                flipped.level.voxel_cluster,
                "{} {what}",
                b.name()
            );
        }
    }
}
