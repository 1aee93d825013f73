//! A bare mesh states no units: it is read in metres unless that would make a level longer
//! than any indoor level, then in centimetres or millimetres, with a warning (and in metres
//! with a note where that makes it longer than most, or smaller than any room); a scene
//! TOML's `metres_per_unit` chooses.

use std::path::{Path, PathBuf};

use visgate_formats::{ImportOptions, Scene, bare_mesh_units};

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
