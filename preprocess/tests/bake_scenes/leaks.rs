//! Walls thin or on the bounds that do not leak, leaks found at their openings, and clear errors on bad input.

use super::*;

/// A sealed box of zero-thickness walls, `size` metres, its corner at the origin: its walls
/// are its bounds.
fn sealed_box(size: Vec3) -> ImportedModel {
    let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * size;
    let pos = vec![
        c(0., 0., 0.),
        c(1., 0., 0.),
        c(1., 1., 0.),
        c(0., 1., 0.),
        c(0., 0., 1.),
        c(1., 0., 1.),
        c(1., 1., 1.),
        c(0., 1., 1.),
    ];
    let quads = [
        [0, 1, 2, 3],
        [4, 7, 6, 5],
        [0, 4, 5, 1],
        [3, 2, 6, 7],
        [0, 3, 7, 4],
        [1, 5, 6, 2],
    ];
    let tris = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    raw("cube", pos, tris)
}

#[test]
fn walls_thinner_than_a_voxel_do_not_leak() {
    // A closed 2 m cube of zero-thickness walls.
    let s = custom(
        "thin-walls",
        sealed_box(Vec3::splat(2.0)),
        true,
        [1.0, 1.0, 1.0],
        1.0,
    );
    for res in [8, 16, 33, 64] {
        let b = bake_scene(&s, &params(res)).expect("a sealed cube does not leak");
        assert_eq!(
            (b.report.summary.components, b.report.summary.clusters),
            (1, 1),
            "at {res}"
        );
    }
}

#[test]
fn a_scene_file_drops_the_space_around_its_rooms_and_keeps_a_room_cut_off_from_its_camera() {
    // Two sealed 4 × 3 × 4 m rooms of single-sided walls facing in, 2 m apart; the camera in
    // the first. The second room is faced by its walls; the space around both sees only
    // their backs.
    let mut model = sealed_box(Vec3::new(4.0, 3.0, 4.0));
    let second = sealed_box(Vec3::new(4.0, 3.0, 4.0)).meshes.remove(0);
    let mesh = &mut model.meshes[0];
    let base = mesh.positions.len() as u32;
    let moved = second
        .positions
        .iter()
        .map(|p| *p + Vec3::new(6.0, 0.0, 0.0));
    mesh.positions.extend(moved);
    let tris = second.triangles.iter().map(|t| t.map(|i| i + base));
    mesh.triangles.extend(tris);
    mesh.normals.resize(mesh.positions.len(), Vec3::Y);
    mesh.uvs.resize(mesh.positions.len(), Vec2::ZERO);
    let s = custom("two-boxes", model, false, [2.0, 1.5, 2.0], 1.0);
    for res in [48, 96] {
        let b = bake_scene(&s, &params(res)).expect("bake");
        let comps = b.report.empty_space["components"]
            .as_array()
            .expect("components")
            .clone();
        let large: Vec<_> = comps
            .iter()
            .filter(|c| c["voxels"].as_u64() > Some(500))
            .collect();
        assert_eq!(large.len(), 3, "at {res}: {comps:?}");
        let inside = |c: &serde_json::Value, x: f64| {
            let (lo, hi) = (&c["bounds_min_m"], &c["bounds_max_m"]);
            lo[0].as_f64() > Some(x - 0.5) && hi[0].as_f64() < Some(x + 4.5)
        };
        let reason = |c: &serde_json::Value| c["reason"].as_str().unwrap_or("").to_string();
        for c in large {
            match (inside(c, 0.0), inside(c, 6.0)) {
                (true, false) => assert!(reason(c).starts_with("holds camera"), "{c}"),
                (false, true) => {
                    assert_eq!(c["kept"], true, "the second room, at {res}: {c}");
                    assert!(reason(c).starts_with("faced by its walls"), "{c}");
                }
                _ => {
                    assert_eq!(c["kept"], false, "the space around, at {res}: {c}");
                    assert!(
                        reason(c).starts_with(visgate_preprocess::empty::UNSEEN),
                        "{c}"
                    );
                }
            }
        }
    }
}

#[test]
fn walls_on_the_bounds_never_leak_at_any_resolution_or_scale() {
    // Rounding used to put such a wall in the solid border ring alone, so that the room
    // touched the ring: "leaks on the +x side" at some resolutions (the ajar door at 100).
    // A box for the coarse grids (8 voxels leave it 2 × 2 inside), a long one for the fine.
    let (small, long) = (
        sealed_box(Vec3::new(4.0, 2.0, 2.0)),
        sealed_box(Vec3::new(8.0, 1.0, 1.0)),
    );
    for mpu in [1e-3, 1.0, 1e4] {
        for res in [
            8, 9, 13, 16, 31, 33, 64, 100, 127, 128, 200, 255, 256, 257, 511, 512,
        ] {
            let (model, eye) = if res < 100 {
                (small.clone(), [2.0, 1.0, 1.0])
            } else {
                (long.clone(), [4.0, 0.5, 0.5])
            };
            let s = custom("on-bounds", model, true, eye, mpu);
            let b = bake_scene(&s, &params(res))
                .unwrap_or_else(|e| panic!("{mpu} m/unit at {res}: {e}"));
            assert_eq!(b.report.summary.components, 1, "{mpu} m/unit at {res}");
        }
    }
    let door = Builtin::AjarDoor.scene().expect("scene");
    for res in [64, 100, 256] {
        bake_scene(&door, &params(res)).unwrap_or_else(|e| panic!("ajar door at {res}: {e}"));
    }
}

#[test]
fn a_leak_is_found_at_its_opening_and_a_sealed_room_does_not_leak() {
    let scene = |n| custom("window", room_with_windows(n), true, [2.0, 1.5, 2.0], 1.0);
    let (leaky, sealed) = (scene(1), scene(0));
    for res in [64, 96, 128] {
        bake_scene(&sealed, &params(res)).unwrap_or_else(|e| panic!("sealed at {res}: {e}"));
        let e = bake_scene(&leaky, &params(res)).expect_err("the window leaks");
        let msg = e.to_string();
        let BakeError::Leak { openings, .. } = e else {
            panic!("{msg}");
        };
        assert_eq!(openings.len(), 1, "at {res}: {msg}");
        let o = &openings[0];
        assert_at_the_window(o, res);
        assert!(
            (0.18..=0.9).contains(&o.width_m),
            "at {res}: {} m wide",
            o.width_m
        );
        assert_eq!(o.from, "camera 'main'");
        assert!(
            msg.contains("reaches the outside through an opening near"),
            "{msg}"
        );
        eprintln!("at {res}: {}", o.describe());
    }
    // Two windows: two openings.
    let e = bake_scene(&scene(2), &params(96)).expect_err("two windows leak");
    let BakeError::Leak { openings, .. } = e else {
        panic!("not a leak");
    };
    let at = |c: Vec3| {
        openings
            .iter()
            .filter(|o| (Vec3::from(o.opening_m) - c).length() < 0.3)
            .count()
    };
    let places: Vec<_> = openings.iter().map(|o| o.opening_m).collect();
    assert_eq!(openings.len(), 2, "{places:?}");
    assert_eq!(at(Vec3::new(4.0, 1.5, 2.0)), 1, "{places:?}");
    assert_eq!(at(Vec3::new(2.0, 1.5, 0.0)), 1, "{places:?}");
}

#[test]
fn no_empty_space_no_triangles_and_too_much_memory_are_clear_errors() {
    // Planes closer than a voxel fill the grid.
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    for i in 0..=20u32 {
        let z = i as f32 * 0.05;
        pos.extend([
            Vec3::new(0., 0., z),
            Vec3::new(1., 0., z),
            Vec3::new(1., 1., z),
            Vec3::new(0., 1., z),
        ]);
        tris.extend([[4 * i, 4 * i + 1, 4 * i + 2], [4 * i, 4 * i + 2, 4 * i + 3]]);
    }
    let s = custom(
        "solid",
        raw("planes", pos, tris),
        false,
        [0.5, 0.5, 0.5],
        1.0,
    );
    let e = bake_scene(&s, &params(8)).expect_err("no empty space");
    assert!(matches!(e, BakeError::NoEmptySpace(_)), "{e}");
    assert!(e.to_string().contains("--resolution"), "{e}");

    // The ajar door on a 400 m ground: at 128 voxels on its longest axis (3.1 m) its rooms
    // are one voxel high. The error says so and what voxel size would do, with its cost.
    let mut s = Builtin::AjarDoor.scene().expect("scene");
    let mut ground = s.meshes[0].clone();
    ground.positions = [
        (-200.0, -200.0),
        (200.0, -200.0),
        (200.0, 200.0),
        (-200.0, 200.0),
    ]
    .map(|(x, z)| Vec3::new(x, -0.01, z))
    .to_vec();
    ground.normals = vec![Vec3::Y; 4];
    ground.uvs = vec![Vec2::ZERO; 4];
    ground.triangles = vec![[0, 2, 1], [0, 3, 2]];
    ground.material = vec![0; 2];
    s.meshes.push(ground);
    let e = bake_scene(&s, &params(128)).expect_err("no empty space");
    let text = e.to_string();
    assert!(
        text.contains("400.0 x 3.1 x 400.0 m") && text.contains("--voxel-size 0.130 puts 24"),
        "{text}"
    );

    let mut s = Builtin::EmptyBox.scene().expect("scene");
    s.meshes.iter_mut().for_each(|m| m.is_static = false);
    let e = bake_scene(&s, &params(32)).expect_err("no static triangles");
    assert!(matches!(e, BakeError::NoGeometry), "{e}");

    let s = Builtin::EmptyBox.scene().expect("scene");
    let opts = BakeOptions {
        memory_limit_bytes: 1 << 30,
        ..BakeOptions::default()
    };
    let e = bake(&s, &params(2048), &opts, &|_| {}).expect_err("too large");
    match &e {
        BakeError::TooLarge { bytes, .. } => {
            assert!(*bytes > (1u64 << 30) as f64);
            assert!(*bytes >= 2048.0 * 1500.0 * 2048.0 * BAKE_BYTES_PER_VOXEL as f64);
        }
        other => panic!("expected TooLarge, got {other}"),
    }
    assert!(e.to_string().contains("GiB"), "{e}");

    // A fine sight grid is a bit a voxel: checked on its own, it bakes where a level grid of
    // its voxels would not (the room's 4.4 m bounds at 1 cm: 443 x 343 x 443 voxels, 34 MB at
    // half a byte, 1.5 GiB at a bake's 24 bytes) and is refused past the limit with its own flag.
    let fine = |m: f32| BakeParams {
        sight_voxel_m: Some(m),
        ..params(16)
    };
    let opts = BakeOptions {
        memory_limit_bytes: 64 << 20,
        ..BakeOptions::default()
    };
    let baked = bake(&s, &fine(0.01), &opts, &|_| {}).expect("a 1 cm sight grid fits");
    assert_eq!(baked.level.info.sight_grid.dims, [443, 343, 443]);
    let e = bake(&s, &fine(0.004), &opts, &|_| {}).expect_err("too large");
    assert!(matches!(e, BakeError::SightTooLarge { .. }), "{e}");
    assert!(e.to_string().contains("raise --sight-voxel"), "{e}");
}

#[test]
fn a_leaking_closed_scene_names_where_and_bakes_with_allow_leaks() {
    // A room with one wall missing, declared closed.
    let mut model = Builtin::EmptyBox.model().expect("model");
    for m in &mut model.meshes {
        let keep: Vec<[u32; 3]> = m
            .triangles
            .iter()
            .copied()
            .filter(|t| !t.iter().all(|&i| m.positions[i as usize].x > 3.95))
            .collect();
        m.triangles = keep;
    }
    let s = custom("leaky", model, true, [2.0, 1.5, 2.0], 1.0);
    let e = bake_scene(&s, &params(48)).expect_err("leak");
    let msg = e.to_string();
    assert!(
        matches!(e, BakeError::Leak { .. }) && msg.contains("+x"),
        "{msg}"
    );
    let mut p = params(48);
    p.allow_leaks = true;
    let b = bake_scene(&s, &p).expect("bake anyway");
    assert!(
        !b.report.empty_space["leaks"]
            .as_array()
            .expect("leaks")
            .is_empty()
    );
}

#[test]
fn bad_parameters_are_refused() {
    let s = Builtin::EmptyBox.scene().expect("scene");
    for alpha in [-0.1, 1.5, f32::NAN] {
        let mut p = params(32);
        p.alpha = alpha;
        assert!(
            matches!(bake_scene(&s, &p), Err(BakeError::Param(_))),
            "alpha {alpha}"
        );
    }
    for res in [0, 7, 4096] {
        assert!(
            matches!(bake_scene(&s, &params(res)), Err(BakeError::Param(_))),
            "res {res}"
        );
    }
}
