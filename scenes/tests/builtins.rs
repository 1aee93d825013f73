//! The built-in scenes: complete, closed where they say so, and the same in memory and on disk.

use glam::{DVec3, Vec3};
use visgate_formats::{ImportOptions, Light, Scene};
use visgate_scenes::{Builtin, Opening};

fn inside(p: Vec3, boxes: &[Opening]) -> bool {
    boxes
        .iter()
        .any(|b| (0..3).all(|a| p[a] > b.min_m[a] && p[a] < b.max_m[a]))
}

#[test]
fn every_builtin_loads_with_a_camera_and_a_light_inside_its_empty_space() {
    for b in Builtin::ALL {
        let scene = b.scene().unwrap_or_else(|e| panic!("{}: {e}", b.name()));
        assert!(scene.triangle_count() > 0, "{}", b.name());
        assert_eq!(scene.report.degenerate_dropped, 0, "{}", b.name());
        // Nothing in them is taken for a sky box or a stray helper (the bake would warn).
        assert_eq!(
            visgate_formats::stray::stray_geometry(&scene),
            None,
            "{}",
            b.name()
        );
        assert!(
            !scene.lights.is_empty() && !scene.cameras.is_empty(),
            "{}",
            b.name()
        );
        let boxes = b.empty_boxes_m();
        // An open scene may be lit from outside, through a window (sun-window).
        for l in scene.lights.iter().filter(|_| b != Builtin::SunWindow) {
            let (Light::Point { position, .. } | Light::Spot { position, .. }) = *l;
            assert!(
                inside(position, &boxes),
                "{}: light at {position} is not in the level",
                b.name()
            );
        }
        // An open scene (the Cornell box) may be looked into from outside.
        for c in scene.cameras.iter().filter(|_| scene.closed) {
            assert!(
                inside(c.eye, &boxes),
                "{}: camera '{}' at {} is not in the level",
                b.name(),
                c.name,
                c.eye
            );
        }
        assert!(Builtin::from_name(b.name()) == Some(b));
        assert!(Builtin::from_name(&format!("builtin:{}", b.name().replace('-', "_"))) == Some(b));
    }
    assert_eq!(Builtin::from_name("no-such-scene"), None);
}

/// A closed surface has zero vector area: Σ area·normal over its triangles vanishes.
fn vector_area(scene: &Scene) -> DVec3 {
    scene
        .static_triangles()
        .map(|[a, b, c]| 0.5 * (b - a).as_dvec3().cross((c - a).as_dvec3()))
        .sum()
}

#[test]
fn generated_levels_are_closed_surfaces_with_the_stated_floor_area() {
    for b in Builtin::ALL {
        // Single-sided walls: neither closed nor two-faced (by design).
        if matches!(
            b,
            Builtin::CornellBox | Builtin::AjarDoor | Builtin::SunWindow | Builtin::Stairwell
        ) {
            continue;
        }
        let scene = b.scene().expect("loads");
        let va = vector_area(&scene);
        assert!(
            // f32 rounding over hundreds of m²; a missing face would leave at least one
            // 0.1 m cell, 0.01 m².
            va.length() < 1e-4,
            "{}: vector area {va} (the surface is not closed)",
            b.name()
        );
        // Floor faces: upward triangles at y = 0 cover exactly the rooms' and doorways' floors.
        let floor: f64 = scene
            .static_triangles()
            .filter(|t| t.iter().all(|p| p.y == 0.0))
            .map(|[a, b, c]| 0.5 * (b - a).as_dvec3().cross((c - a).as_dvec3()).y)
            .sum();
        let expected: f64 = b
            .empty_boxes_m()
            .iter()
            .map(|o| f64::from(o.max_m[0] - o.min_m[0]) * f64::from(o.max_m[2] - o.min_m[2]))
            .sum();
        assert!(
            (floor - expected).abs() < 1e-3,
            "{}: floor area {floor} m², expected {expected}",
            b.name()
        );
    }
}

#[test]
fn the_cornell_box_is_mcguires_with_its_open_front() {
    let scene = Builtin::CornellBox.scene().expect("loads");
    assert_eq!(scene.triangle_count(), 36);
    assert!(!scene.closed);
    let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
    for n in [
        "leftWall",
        "rightWall",
        "floor",
        "light",
        "tallBox",
        "shortBox",
    ] {
        assert!(names.contains(&n), "{names:?}");
    }
    let red = scene
        .materials
        .iter()
        .find(|m| m.name == "leftWall")
        .expect("red wall");
    assert_eq!(red.albedo, Vec3::new(0.63, 0.065, 0.05));
}

#[test]
fn known_answers_are_consistent() {
    for b in Builtin::ALL {
        let k = b.known_answers();
        assert!(
            k.clusters[0] <= k.clusters[1] && k.gates[0] <= k.gates[1],
            "{}",
            b.name()
        );
        assert!(k.clusters[0] >= 1 && k.components == 1, "{}", b.name());
        // A level whose skeleton has a loop needs at least 3 clusters and as many gates.
        if k.cycles > 0 {
            assert!(k.clusters[0] >= 3 && k.gates[0] >= 3, "{}", b.name());
        }
        // n clusters in one component are joined by at least n − 1 gates.
        assert!(k.gates[1] + 1 >= k.clusters[0], "{}", b.name());
        for d in &k.doorways {
            assert!(
                (d.width_m() - 1.0).abs() < 1e-5,
                "{}: doorway {d:?}",
                b.name()
            );
        }
    }
    assert_eq!(Builtin::EmptyBox.known_answers().clusters, [1, 1]);
    assert_eq!(Builtin::EmptyBox.known_answers().gates, [0, 0]);
    assert_eq!(Builtin::RingCorridor.known_answers().cycles, 1);
    assert_eq!(Builtin::FourRooms.known_answers().cycles, 1);
}

#[test]
fn exported_scenes_load_from_disk_with_the_same_static_geometry() {
    let dir = tempfile::tempdir().expect("tempdir");
    for b in Builtin::ALL {
        let sub = dir.path().join(b.name());
        let toml = b.export(&sub).expect("exports");
        assert!(sub.join(format!("{}.expected.toml", b.name())).is_file());
        let from_disk = Scene::load(&toml, &ImportOptions::default())
            .unwrap_or_else(|e| panic!("{}: {e}", b.name()));
        let in_memory = b.scene().expect("loads");
        assert_eq!(
            from_disk.triangle_count(),
            in_memory.triangle_count(),
            "{}",
            b.name()
        );
        assert_eq!(
            from_disk.static_geometry_hash(),
            in_memory.static_geometry_hash(),
            "{}: exported geometry differs",
            b.name()
        );
        assert_eq!(from_disk.lights, in_memory.lights, "{}", b.name());
        assert_eq!(from_disk.cameras, in_memory.cameras, "{}", b.name());
        assert_eq!(from_disk.closed, in_memory.closed);
        let albedos = |s: &Scene| {
            s.materials
                .iter()
                .map(|m| (m.name.clone(), m.albedo.to_array()))
                .collect::<Vec<_>>()
        };
        let mut a = albedos(&from_disk);
        let mut m = albedos(&in_memory);
        a.sort_by(|x, y| x.0.cmp(&y.0));
        m.sort_by(|x, y| x.0.cmp(&y.0));
        a.dedup();
        m.dedup();
        assert_eq!(a, m, "{}", b.name());
    }
}

#[test]
fn the_ajar_door_level_has_zero_thickness_walls_and_a_door_twenty_degrees_open() {
    let scene = Builtin::AjarDoor.scene().expect("loads");
    // The dividing wall: quads in the plane x = 4 facing room A (−x), none facing +x.
    let divider: Vec<_> = scene
        .static_triangles()
        .filter(|t| t.iter().all(|p| (p.x - 4.0).abs() < 1e-6))
        .map(|[a, b, c]| (b - a).cross(c - a))
        .collect();
    assert!(!divider.is_empty());
    assert!(
        divider.iter().all(|n| n.x < 0.0),
        "one-sided, facing room A"
    );
    // The door: wood triangles whose normals are the panel's, turned 20° about +Y.
    let wood = scene
        .materials
        .iter()
        .position(|m| m.name == "wood")
        .expect("wood") as u32;
    let door_normal = scene
        .meshes
        .iter()
        .flat_map(|m| {
            m.triangles
                .iter()
                .zip(&m.material)
                .map(move |(t, &k)| (m, t, k))
        })
        .filter(|(_, _, k)| *k == wood)
        .map(|(m, t, _)| {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            ((b - a).cross(c - a).normalize(), (a + b + c) / 3.0)
        })
        .find(|(n, p)| p.x > 4.0 && n.y.abs() < 1e-3 && n.x > 0.5)
        .expect("the door's face towards room B")
        .0;
    let angle = door_normal.z.atan2(door_normal.x).to_degrees().abs();
    assert!((angle - 20.0).abs() < 0.01, "{angle}°");
}

#[test]
fn the_sun_window_is_lit_from_outside_through_its_window() {
    let b = Builtin::SunWindow;
    let scene = b.scene().expect("loads");
    assert!(!scene.closed);
    let [Light::Point { position, .. }] = scene.lights[..] else {
        panic!("one point light: {:?}", scene.lights);
    };
    // Outside the rooms, beyond the window's wall, above the window's sill.
    assert!(!inside(position, &b.empty_boxes_m()), "{position}");
    let [x0, x1, y0, _] = visgate_scenes::quads::SUN_WINDOW;
    assert!(position.z > 4.0 && (x0..=x1).contains(&position.x) && position.y > y0);
    // The window is open: a ray from the light to room B's floor through it meets nothing
    // in the wall's plane (no triangle of the z = 4 m wall covers the window's middle).
    let mid = Vec3::new(0.5 * (x0 + x1), 1.6, 4.0);
    let covered = scene.static_triangles().any(|[a, b2, c]| {
        let z = |p: Vec3| (p.z - 4.0).abs() < 1e-6;
        let (lo, hi) = (a.min(b2).min(c), a.max(b2).max(c));
        z(a) && z(b2) && z(c) && (lo.x..=hi.x).contains(&mid.x) && (lo.y..=hi.y).contains(&mid.y)
    });
    assert!(!covered);
}
