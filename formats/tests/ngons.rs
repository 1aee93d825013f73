//! An OBJ's concave polygons are ear-clipped, not fanned: Blender's OBJ export keeps n-gons,
//! and a wall with a doorway cut from the floor is one concave polygon, which tobj's fan from
//! its first corner closed (two rooms joined by such a doorway: the far room black).

use std::fmt::Write as _;

use glam::Vec3;
use visgate_formats::{ImportOptions, Scene};

/// The wall at x = 4 of a 4 m room, 3 m high: its outline round a doorway 1 m wide and 2.1 m
/// high, cut from the floor at z 1.5–2.5, as (z, y).
const WALL: [(f32, f32); 8] = [
    (0.0, 0.0),
    (1.5, 0.0),
    (1.5, 2.1),
    (2.5, 2.1),
    (2.5, 0.0),
    (4.0, 0.0),
    (4.0, 3.0),
    (0.0, 3.0),
];

/// Whether the segment a-b passes through triangle t (Möller-Trumbore, strictly inside).
fn crosses(t: [Vec3; 3], a: Vec3, b: Vec3) -> bool {
    let (e1, e2, d) = (t[1] - t[0], t[2] - t[0], b - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-9 {
        return false;
    }
    let s = a - t[0];
    let (u, q) = (s.dot(p) / det, s.cross(e1));
    let (v, h) = (d.dot(q) / det, e2.dot(q) / det);
    u > 0.0 && v > 0.0 && u + v < 1.0 && h > 0.0 && h < 1.0
}

#[test]
fn a_wall_written_as_one_concave_polygon_keeps_its_doorway_open() {
    // The wall's two faces, one facing each room (the second written the other way round).
    let mut obj = String::new();
    for face in ["f 1 2 3 4 5 6 7 8", "f 16 15 14 13 12 11 10 9"] {
        for (z, y) in WALL {
            writeln!(obj, "v 4 {y} {z}").expect("write");
        }
        writeln!(obj, "{face}").expect("write");
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("wall.obj");
    std::fs::write(&path, obj).expect("obj");
    let scene = Scene::load(&path, &ImportOptions::default()).expect("load");
    assert_eq!(scene.report.concave_polygons, 2);
    let tris: Vec<[Vec3; 3]> = scene.static_triangles().collect();
    assert_eq!(tris.len(), 12);
    // Through the doorway: no triangle; through the wall beside it and above it: one a face.
    let through = |y: f32, z: f32| {
        let (a, b) = (Vec3::new(3.0, y, z), Vec3::new(5.0, y, z));
        tris.iter().filter(|&&t| crosses(t, a, b)).count()
    };
    for (y, z) in [(1.0, 2.0), (0.1, 1.6), (2.0, 2.4), (1.0, 1.9)] {
        assert_eq!(through(y, z), 0, "the doorway at y {y}, z {z}");
    }
    for (y, z) in [(1.0, 0.5), (2.5, 2.0), (1.0, 3.5), (2.9, 0.1)] {
        assert_eq!(through(y, z), 2, "the wall at y {y}, z {z}");
    }
    // Each face's triangles cover the wall less the doorway (12 − 2.1 m²), facing the way the
    // polygon was written: the first −x, the second +x.
    for (half, facing) in [(&tris[..6], -1.0), (&tris[6..], 1.0)] {
        let area: f32 = (half.iter())
            .map(|t| {
                let n = (t[1] - t[0]).cross(t[2] - t[0]);
                assert!(n.x * facing > 0.0, "{t:?}");
                0.5 * n.length()
            })
            .sum();
        assert!((area - 9.9).abs() < 1e-4, "{area}");
    }
}
