//! A bare mesh states no units: it is read in metres unless that would make a level longer
//! than any indoor level, then in centimetres or millimetres, with a warning (and in metres
//! with a note where that makes it longer than most, or smaller than any room) — unless its
//! rooms' height, floor to ceiling, is implausible in that unit and typical in another
//! (millimetres; centimetres for a small level; inches), with a warning saying both; a scene
//! TOML's `metres_per_unit` chooses.

use std::path::{Path, PathBuf};

use visgate_formats::{
    ImportOptions, ROOM_UNITS, Scene, bare_mesh_units, bare_mesh_units_with_rooms,
};

/// An OBJ of two triangles spanning `length` units along x (1 unit in y and z).
fn write_obj(dir: &Path, name: &str, length: f64) -> PathBuf {
    let p = dir.join(name);
    let text = format!("v 0 0 0\nv {length} 0 0\nv {length} 1 0\nv 0 1 1\nf 1 2 3\nf 1 3 4\n");
    std::fs::write(&p, text).expect("write");
    p
}

fn longest_m(scene: &Scene) -> f64 {
    let (lo, hi) = scene.bounds().expect("bounds");
    (hi - lo).max_element() as f64
}

#[test]
fn the_units_rule_reads_metres_up_to_a_kilometre_then_centimetres_then_millimetres() {
    assert_eq!(bare_mesh_units(2.0), 1.0);
    assert_eq!(bare_mesh_units(1000.0), 1.0);
    assert_eq!(bare_mesh_units(3721.0), 0.01);
    assert_eq!(bare_mesh_units(100_000.0), 0.01);
    assert_eq!(bare_mesh_units(200_000.0), 0.001);
}

#[test]
fn a_bare_mesh_in_centimetres_is_read_as_such_and_says_so() {
    let dir = tempfile::tempdir().expect("tempdir");
    let options = ImportOptions::default();
    // 37 m modelled in centimetres, as Crytek Sponza is.
    let cm = Scene::load(&write_obj(dir.path(), "cm.obj", 3700.0), &options).expect("load");
    assert!((longest_m(&cm) - 37.0).abs() < 1e-3, "{}", longest_m(&cm));
    let w = cm.report.warnings.join("\n");
    assert!(w.contains("cm.obj") && w.contains("centimetres"), "{w}");
    assert!(w.contains("metres_per_unit"), "{w}");
    // Millimetres read in centimetres (a 9 m apartment as 90 m): the note says what they make.
    assert!(
        w.contains("in millimetres it would be a 3.7 m level"),
        "{w}"
    );
    // 200 m in millimetres: centimetres would still make 2 km.
    let mm = Scene::load(&write_obj(dir.path(), "mm.obj", 2.0e5), &options).expect("load");
    assert!((longest_m(&mm) - 200.0).abs() < 1e-2, "{}", longest_m(&mm));
    assert!(mm.report.warnings.join("\n").contains("millimetres"));
    // A level of plausible size in metres is left alone, silently (of its units: its two
    // triangles face z more than y, which the up axis's note says).
    let m = Scene::load(&write_obj(dir.path(), "m.obj", 120.0), &options).expect("load");
    assert!((longest_m(&m) - 120.0).abs() < 1e-3);
    let units = |w: &String| w.contains("units");
    assert!(
        !m.report.warnings.iter().any(units),
        "{:?}",
        m.report.warnings
    );
    // 800 units, read in metres (under a kilometre), but longer than most indoor levels: a
    // note says what centimetres would make it.
    let long = Scene::load(&write_obj(dir.path(), "long.obj", 800.0), &options).expect("load");
    assert!((longest_m(&long) - 800.0).abs() < 1e-3);
    let w = long.report.warnings.join("\n");
    assert!(
        w.contains("long.obj")
            && w.contains("makes a 800 m level")
            && w.contains("a 8.0 m level")
            && w.contains("inches (20.3 m)"),
        "{w}"
    );
    assert!(w.contains("--metres-per-unit 0.01"), "{w}");
    // 0.08 units, read in metres: smaller than any room (a level scaled down on export); a
    // note says what × 100 and × 10 would make it.
    let tiny = dir.path().join("small.obj");
    let text = "v 0 0 0\nv 0.08 0 0\nv 0.08 0.03 0\nv 0 0.03 0.04\nf 1 2 3\nf 1 3 4\n";
    std::fs::write(&tiny, text).expect("write");
    let small = Scene::load(&tiny, &options).expect("load");
    let w = small.report.warnings.join("\n");
    assert!(
        w.contains("small.obj")
            && w.contains("makes a 0.080 m level")
            && w.contains("× 100: a 8.0 m level"),
        "{w}"
    );
    // A scene TOML's units are the user's: never guessed.
    let toml = dir.path().join("s.toml");
    std::fs::write(
        &toml,
        "metres_per_unit = 1.0\n[[mesh]]\npath = \"cm.obj\"\n",
    )
    .expect("toml");
    let stated = Scene::load(&toml, &options).expect("load");
    assert!((longest_m(&stated) - 3700.0).abs() < 1e-2);
    assert!(stated.report.warnings.is_empty());
}

/// An OBJ of a room `long` × `wide` units, `high` units floor to ceiling, Z up (as a modeller
/// in millimetres or centimetres writes it): a floor, a ceiling and four walls, single quads.
fn write_room(dir: &Path, name: &str, long: f64, wide: f64, high: f64) -> PathBuf {
    let p = dir.join(name);
    let corners = [
        (0.0, 0.0, 0.0),
        (long, 0.0, 0.0),
        (long, wide, 0.0),
        (0.0, wide, 0.0),
        (0.0, 0.0, high),
        (long, 0.0, high),
        (long, wide, high),
        (0.0, wide, high),
    ];
    let mut text: String = corners
        .iter()
        .map(|(x, y, z)| format!("v {x} {y} {z}\n"))
        .collect();
    for f in [
        "1 2 3 4", "8 7 6 5", "1 5 6 2", "2 6 7 3", "3 7 8 4", "4 8 5 1",
    ] {
        text += &format!("f {f}\n");
    }
    std::fs::write(&p, text).expect("write");
    p
}

#[test]
fn the_rooms_height_reads_millimetres_and_small_levels_in_centimetres_where_the_extent_cannot() {
    assert_eq!(bare_mesh_units_with_rooms(9000.0, Some(2700.0)), 0.001);
    assert_eq!(bare_mesh_units_with_rooms(800.0, Some(270.0)), 0.01);
    // The Cornell box (1.99 units high in metres) modelled in centimetres.
    assert_eq!(bare_mesh_units_with_rooms(199.0, Some(199.0)), 0.01);
    // Rooms plausible in the extent's unit, or in no unit typical, or not measured: the extent's.
    assert_eq!(bare_mesh_units_with_rooms(3721.0, Some(1457.5)), 0.01);
    assert_eq!(bare_mesh_units_with_rooms(60.0, Some(15.4)), 1.0);
    assert_eq!(bare_mesh_units_with_rooms(3721.0, Some(10_000.0)), 0.01);
    assert_eq!(bare_mesh_units_with_rooms(9000.0, None), 0.01);
    // Inches where centimetres leave the rooms under 1.9 m and inches make them a room's: an
    // 8 ft ceiling in a 40 ft house and in a 150 ft hall (centimetres by its extent); a room of
    // 200 units is 2.0 m in centimetres, tried first, and 5.1 m in inches.
    assert_eq!(ROOM_UNITS, [0.01, 0.0254, 0.001]);
    assert_eq!(bare_mesh_units_with_rooms(480.0, Some(96.0)), 0.0254);
    assert_eq!(bare_mesh_units_with_rooms(1800.0, Some(96.0)), 0.0254);
    assert_eq!(bare_mesh_units_with_rooms(800.0, Some(200.0)), 0.01);
    // A level in metres with low rooms (1.2 m crawl spaces) is no level in smaller units.
    assert_eq!(bare_mesh_units_with_rooms(40.0, Some(1.2)), 1.0);
    let dir = tempfile::tempdir().expect("tempdir");
    // A room `long` × `wide` × `high` units read bare: its longest side in metres and its
    // warnings.
    let read = |name: &str, long: f64, wide: f64, high: f64| {
        let path = write_room(dir.path(), name, long, wide, high);
        let scene = Scene::load(&path, &ImportOptions::default()).expect("load");
        (longest_m(&scene), scene.report.warnings.join("\n"))
    };
    // A 9 m room in millimetres, 2.7 m high: its extent alone read it as 90 m.
    let (mm, w) = read("mm.obj", 9000.0, 6000.0, 2700.0);
    assert!((mm - 9.0).abs() < 1e-3, "{mm}");
    assert!(
        w.contains("mm.obj")
            && w.contains("its rooms stand 2700 units floor to ceiling")
            && w.contains("in centimetres would make them 27.0 m high")
            && w.contains("read in millimetres (rooms 2.70 m high, the level 9.0 m long)")
            && w.contains("--metres-per-unit"),
        "{w}"
    );
    // An 8 m room in centimetres: its extent alone read it as 800 m.
    let (cm, w) = read("cm.obj", 800.0, 500.0, 270.0);
    assert!((cm - 8.0).abs() < 1e-4, "{cm}");
    assert!(
        w.contains("in metres would make them 270.0 m high") && w.contains("read in centimetres"),
        "{w}"
    );
    // The same room in metres is left alone, and so is a 37 m hall in centimetres 14.6 m high.
    let (m, w) = read("m.obj", 8.0, 5.0, 2.7);
    assert!((m - 8.0).abs() < 1e-4);
    assert!(!w.contains("units"), "{w}");
    let (hall, _) = read("hall.obj", 3700.0, 2000.0, 1460.0);
    assert!((hall - 37.0).abs() < 1e-3);
    // A house in inches (3ds Max, SketchUp), 40 × 30 ft, 8 ft floor to ceiling: 96 units,
    // 96 m in metres and 0.96 m in centimetres; read in inches, the warning saying so.
    let (inches, w) = read("in.obj", 480.0, 360.0, 96.0);
    assert!((inches - 12.192).abs() < 1e-3, "{inches}");
    assert!(
        w.contains("in metres would make them 96.0 m high")
            && w.contains("read in inches (rooms 2.44 m high, the level 12.2 m long)"),
        "{w}"
    );
    // A 150 ft hall in inches (1,800 units: centimetres by its extent, whose rooms of 0.96 m
    // are no room's height either).
    let (hall_in, w) = read("hall-in.obj", 1800.0, 600.0, 96.0);
    assert!((hall_in - 45.72).abs() < 1e-2, "{hall_in}");
    assert!(
        w.contains("in centimetres would make them 0.96 m high") && w.contains("read in inches"),
        "{w}"
    );
    // The user's units are never guessed.
    let said = ImportOptions {
        bare: visgate_formats::BareMesh {
            metres_per_unit: Some(0.01),
            ..Default::default()
        },
        ..ImportOptions::default()
    };
    let stated = Scene::load(&dir.path().join("mm.obj"), &said).expect("load");
    assert!((longest_m(&stated) - 90.0).abs() < 1e-2);
}
