//! The sight grid's open voxels, and a bare mesh's inside kept and its openings said.

use super::*;

#[test]
fn the_sight_grid_is_the_thin_voxelization_s_open_voxels_never_coarser_than_the_level() {
    use visgate_preprocess::separating;
    use visgate_preprocess::voxelize::voxelize;
    let scene = Builtin::AjarDoor.scene().expect("scene");
    let triangles: Vec<[Vec3; 3]> = scene.static_triangles().collect();
    // (resolution, sight voxel asked for, the sight grid's voxels on the longest axis): by
    // default at most 1/512 of the level (8 m: 1.5625 cm), a level as fine keeps its own grid,
    // 0 and a coarser sight voxel take the level's, a finer one is taken as given.
    for (res, asked, longest) in [
        (64, None, 512),
        (600, None, 600),
        (64, Some(0.0), 64),
        (64, Some(1.0), 64),
        (64, Some(0.0625), 128),
    ] {
        let p = BakeParams {
            sight_voxel_m: asked,
            ..params(res)
        };
        let level = bake_scene(&scene, &p).expect("bake").level;
        let (g, s) = (level.info.grid, level.info.sight_grid);
        assert_eq!(
            s.dims.iter().max().copied(),
            Some(longest + 2),
            "{res} {asked:?}"
        );
        assert_eq!(level.info.params.sight_voxel_m, Some(s.voxel_size_m));
        assert!(s.voxel_size_m <= g.voxel_size_m, "{res} {asked:?}");
        // Over the same bounds: the grids' far corners agree within a voxel.
        let far = |m: &GridMeta| {
            Vec3::from(m.origin_m) + m.voxel_size_m * Vec3::from(m.dims.map(|d| d as f32))
        };
        assert!(
            (far(&s) - far(&g)).abs().max_element() <= g.voxel_size_m,
            "{res} {asked:?}"
        );
        // Voxelized thin: every voxel the conservative voxelization leaves open is open, and
        // more besides (a plane closes one voxel a column, not two or three).
        assert_eq!(level.open, separating::open_voxels(s, &triangles));
        let solid = voxelize(s, &triangles).solid;
        assert_eq!(level.open.len(), solid.len() as u64);
        assert!(
            (0..solid.len()).all(|i| level.open.get(i) || solid[i]),
            "{res} {asked:?}"
        );
        let conservative = solid.iter().filter(|s| !**s).count() as u64;
        assert!(
            level.open.count_ones() > conservative,
            "{res} {asked:?}: {} open, {conservative} conservatively",
            level.open.count_ones()
        );
    }
    for v in [-0.1, f32::INFINITY, f32::NAN] {
        let p = BakeParams {
            sight_voxel_m: Some(v),
            ..params(32)
        };
        assert!(
            matches!(bake_scene(&scene, &p), Err(BakeError::Param(_))),
            "{v}"
        );
    }
}

/// `model` as a bare mesh: no camera, no light, not declared closed.
fn bare(name: &str, model: ImportedModel) -> Scene {
    let mut desc = SceneDesc::for_mesh_file(Path::new(&format!("{name}.obj")));
    desc.closed = false;
    desc.cameras.clear();
    desc.lights.clear();
    Scene::assemble(&desc, vec![model], Path::new(name)).expect("assemble")
}

/// Adds to `model` a slab 5 cm thick standing on the ground outside the room of
/// [`room_with_windows`] (x 6.5 … 6.55 m, 2.5 m off the window: no narrower place on the way
/// out than the window), its two faces split into `n` × `n` quads each and
/// facing into it, as a Quake brush thinner than a voxel does: the void beside it sees their
/// backs, many of them.
fn add_inward_slab(model: &mut ImportedModel, n: u32) {
    let m = &mut model.meshes[0];
    for (x, sign) in [(6.5f32, 1.0f32), (6.55, -1.0)] {
        for i in 0..n {
            for j in 0..n {
                let (y0, y1) = (
                    0.5 + 2.0 * i as f32 / n as f32,
                    0.5 + 2.0 * (i + 1) as f32 / n as f32,
                );
                let (z0, z1) = (
                    0.5 + 3.0 * j as f32 / n as f32,
                    0.5 + 3.0 * (j + 1) as f32 / n as f32,
                );
                let b = m.positions.len() as u32;
                // Wound so that the normal is +x at x = 6.5 and -x at 6.55: into the slab.
                let (yb, zb) = if sign > 0.0 { (y1, z0) } else { (y0, z1) };
                m.positions.extend([
                    Vec3::new(x, y0, z0),
                    Vec3::new(x, yb, zb),
                    Vec3::new(x, y1, z1),
                    Vec3::new(x, y0 + y1 - yb, z0 + z1 - zb),
                ]);
                m.triangles.extend([[b, b + 1, b + 2], [b, b + 2, b + 3]]);
            }
        }
    }
    let k = m.positions.len();
    m.normals.resize(k, Vec3::X);
    m.uvs.resize(k, Vec2::ZERO);
}

#[test]
fn a_bare_mesh_keeps_the_level_s_inside_and_says_where_it_leaks() {
    let room = Vec3::new(2.0, 1.5, 2.0);
    // Without the window: the room is kept as the level's inside, and nothing leaks.
    let sealed = bake_scene(&bare("sealed", room_with_windows(0)), &params(64)).expect("bake");
    assert!(sealed.openings.is_empty());
    assert!(cluster_at(&sealed.level, room).is_some());
    let reasons = sealed.report.empty_space["components"].to_string();
    assert!(reasons.contains("the level's inside"), "{reasons}");
    // With the window onto the ground outside and a slab out there whose many faces turn their
    // backs to the void: the room and the void are one component that the facing vote alone
    // would drop (more backs than fronts), as a bare Quake level's interior was dropped.
    let mut model = room_with_windows(1);
    add_inward_slab(&mut model, 12);
    let scene = bare("window", model);
    for res in [64, 96, 128] {
        let b = bake_scene(&scene, &params(res)).unwrap_or_else(|e| panic!("at {res}: {e}"));
        assert!(
            cluster_at(&b.level, room).is_some(),
            "at {res}: the room dropped"
        );
        let comps = b.report.empty_space["components"]
            .as_array()
            .expect("components");
        let inside = comps
            .iter()
            .find(|c| {
                c["reason"]
                    .as_str()
                    .is_some_and(|r| r.contains("the level's inside"))
            })
            .unwrap_or_else(|| panic!("at {res}: no inside in {comps:?}"));
        let faced = &inside["faced_by"];
        assert!(
            faced[1].as_u64() > faced[0].as_u64(),
            "at {res}: the vote would keep it anyway: {faced}"
        );
        assert_eq!(b.openings.len(), 1, "at {res}: {:?}", b.openings);
        let o = &b.openings[0];
        assert_eq!(o.from, visgate_preprocess::empty::INSIDE);
        assert_at_the_window(o, res);
        let from = Vec3::from(o.from_m);
        assert!(
            from.cmpge(Vec3::ZERO).all() && from.cmple(Vec3::new(4.0, 3.0, 4.0)).all(),
            "at {res}: the inside's point {from} is not in the room"
        );
        eprintln!("at {res}: {}", o.describe());
    }
    // A block standing on a ground, its faces outward: the air around it is the inside, open
    // all round (no voxel of it enclosed) — openings, not leaks.
    let v = Vec3::new;
    let mut pos = vec![v(0., 0., 0.), v(0., 0., 8.), v(8., 0., 8.), v(8., 0., 0.)];
    let mut tris = vec![[0, 1, 2], [0, 2, 3]];
    let (lo, hi) = (v(3., 0., 3.), v(5., 3., 5.));
    for axis in 0..3 {
        for side in [0.0f32, 1.0] {
            // The face's corners, wound so that its normal points out of the block.
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |a: f32, b: f32| {
                let mut p = [0.0f32; 3];
                p[axis] = lo[axis] + side * (hi[axis] - lo[axis]);
                p[u] = lo[u] + a * (hi[u] - lo[u]);
                p[w] = lo[w] + b * (hi[w] - lo[w]);
                Vec3::from(p)
            };
            let n = pos.len() as u32;
            let quad = [
                corner(0., 0.),
                corner(1., 0.),
                corner(1., 1.),
                corner(0., 1.),
            ];
            pos.extend(if side > 0.5 {
                quad
            } else {
                [quad[0], quad[3], quad[2], quad[1]]
            });
            tris.extend([[n, n + 1, n + 2], [n, n + 2, n + 3]]);
        }
    }
    let b = bake_scene(&bare("block", raw("block", pos, tris)), &params(64)).expect("bake");
    let comps = b.report.empty_space["components"].to_string();
    assert!(comps.contains("the level's inside"), "{comps}");
    assert!(b.openings.is_empty(), "{:?}", b.openings);
}

#[test]
fn a_bare_mesh_s_inside_is_searched_for_openings_only_where_asked() {
    use visgate_preprocess::empty::{EmptySpaceParams, empty_space};
    use visgate_preprocess::voxelize::{grid_for, voxelize};
    let model = room_with_windows(1);
    let m = &model.meshes[0];
    let triangles: Vec<[Vec3; 3]> = m
        .triangles
        .iter()
        .map(|t| t.map(|i| m.positions[i as usize]))
        .collect();
    let bounds = (Vec3::ZERO, Vec3::new(8.0, 3.0, 4.0));
    let meta = grid_for(bounds, Resolution::LongestAxisVoxels(64), u64::MAX).expect("grid");
    let solid = voxelize(meta, &triangles).solid;
    let run = |locate_inside_leaks: bool| {
        let params = EmptySpaceParams {
            min_component_voxels: 64,
            closed: false,
            allow_leaks: false,
            locate_inside_leaks,
        };
        empty_space(&meta, &solid, &triangles, &[], &params).expect("empty space")
    };
    // Asked: the inside's point and the window. Not asked (a partition grid looks, or the grid
    // is too large): the inside still reaches the bounds, and nothing is searched.
    let (asked, not) = (run(true), run(false));
    assert!(asked.inside_at_bounds && asked.inside.is_some() && asked.openings.len() == 1);
    assert!(not.inside_at_bounds && not.inside.is_none() && not.openings.is_empty());
    assert_eq!(asked.empty, not.empty);
}
