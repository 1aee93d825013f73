//! A bare mesh's few triangles far from the rest — a sky box, a helper object left in the
//! export — are left out of it, with a warning, before its units are chosen: a house in a sky
//! box 2,000 units wide read as a 20 m level in centimetres, the house 8 cm long.
//! `--keep-far` (BareMesh::keep_far) and a scene TOML keep every triangle.

use std::fmt::Write as _;
use std::path::Path;

use visgate_formats::{BareMesh, ImportOptions, Scene};

/// What surrounds the house of [`write_house_in_sky`].
#[derive(Clone, Copy, PartialEq)]
enum Sky {
    /// A sky box 2,000 units wide: 12 triangles facing in.
    Box,
    /// A sky dome 2,000 units wide, the object `Sky`: a UV sphere of 24 × 12 segments, 528
    /// triangles facing in (41 % of the house's, where the few far triangles may be 1 %).
    Dome,
}

/// An 8 × 5 m house 2.7 m high in metres (its floor a grid of 1,280 triangles, its ceiling
/// and walls single quads), inside a `sky`.
fn write_house_in_sky(dir: &Path, sky: Sky) -> String {
    let mut obj = String::new();
    let mut quad = |c: [[f64; 3]; 4]| {
        for [x, y, z] in c {
            writeln!(obj, "v {x} {y} {z}").expect("write");
        }
        obj += "f -4 -3 -2 -1\n";
    };
    let (l, w, h) = (8.0, 5.0, 2.7);
    let (nx, nz) = (32, 20);
    for i in 0..nx {
        for k in 0..nz {
            let (x0, x1) = (l * i as f64 / nx as f64, l * (i + 1) as f64 / nx as f64);
            let (z0, z1) = (w * k as f64 / nz as f64, w * (k + 1) as f64 / nz as f64);
            quad([[x0, 0.0, z0], [x0, 0.0, z1], [x1, 0.0, z1], [x1, 0.0, z0]]);
        }
    }
    quad([[0.0, h, 0.0], [l, h, 0.0], [l, h, w], [0.0, h, w]]);
    quad([[0.0, 0.0, 0.0], [l, 0.0, 0.0], [l, h, 0.0], [0.0, h, 0.0]]);
    quad([[0.0, 0.0, w], [0.0, h, w], [l, h, w], [l, 0.0, w]]);
    quad([[0.0, 0.0, 0.0], [0.0, h, 0.0], [0.0, h, w], [0.0, 0.0, w]]);
    quad([[l, 0.0, 0.0], [l, 0.0, w], [l, h, w], [l, h, 0.0]]);
    let (a, b) = (-1000.0, 1000.0);
    if sky == Sky::Box {
        quad([[a, a, a], [b, a, a], [b, a, b], [a, a, b]]);
        quad([[a, b, a], [a, b, b], [b, b, b], [b, b, a]]);
        quad([[a, a, a], [a, b, a], [b, b, a], [b, a, a]]);
        quad([[a, a, b], [b, a, b], [b, b, b], [a, b, b]]);
        quad([[a, a, a], [a, a, b], [a, b, b], [a, b, a]]);
        quad([[b, a, a], [b, b, a], [b, b, b], [b, a, b]]);
    } else {
        write_dome(&mut obj, b, 24);
    }
    std::fs::write(dir.join("house.obj"), obj).expect("obj");
    std::fs::write(
        dir.join("house.toml"),
        "[[mesh]]\npath = \"house.obj\"\n[[light]]\ntype = \"point\"\n\
         position = [4.0, 2.0, 2.5]\nintensity = [5, 5, 5]\n",
    )
    .expect("toml");
    "house.obj".into()
}

/// A UV sphere of `n` × `n / 2` segments and `radius` round the origin, facing in, as the
/// OBJ object `Sky` (its vertices after the file's others: faces index from the end).
fn write_dome(obj: &mut String, radius: f64, n: usize) {
    obj.push_str("o Sky\n");
    for j in 0..=n / 2 {
        for i in 0..n {
            let th = std::f64::consts::PI * j as f64 / (n / 2) as f64;
            let ph = std::f64::consts::TAU * i as f64 / n as f64;
            let (x, y, z) = (th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin());
            writeln!(obj, "v {} {} {}", radius * x, radius * y, radius * z).expect("write");
        }
    }
    let count = (n / 2 + 1) * n;
    let at = |j: usize, i: usize| j * n + i % n;
    for j in 0..n / 2 {
        for i in 0..n {
            let [a, b, c, d] = [at(j, i), at(j, i + 1), at(j + 1, i + 1), at(j + 1, i)]
                .map(|v| v as i64 - count as i64);
            if j > 0 {
                writeln!(obj, "f {a} {c} {b}").expect("write");
            }
            if j + 1 < n / 2 {
                writeln!(obj, "f {a} {d} {c}").expect("write");
            }
        }
    }
}

/// Options that keep a bare mesh's far triangles (`--keep-far`).
fn keep_far() -> ImportOptions {
    ImportOptions {
        bare: BareMesh {
            keep_far: true,
            ..BareMesh::default()
        },
        ..ImportOptions::default()
    }
}

/// Asserts that `scene` is the house alone, in metres: 1,280 + 10 triangles, 8 m long.
fn assert_the_house_alone(scene: &Scene) {
    assert_eq!(scene.static_triangles().count(), 1290);
    let longest = longest_m(scene);
    assert!((longest - 8.0).abs() < 1e-4, "{longest}");
}

fn longest_m(scene: &Scene) -> f32 {
    let (lo, hi) = scene.bounds().expect("bounds");
    (hi - lo).max_element()
}

#[test]
fn a_sky_box_round_a_bare_house_is_left_out_before_its_units_are_chosen() {
    let dir = tempfile::tempdir().expect("tempdir");
    let house = dir.path().join(write_house_in_sky(dir.path(), Sky::Box));
    let scene = Scene::load(&house, &ImportOptions::default()).expect("load");
    assert_the_house_alone(&scene);
    let w = scene.report.warnings.join("\n");
    assert!(
        w.contains("12 of its 1302 triangles lie far from the rest")
            && w.contains("left out of the level")
            && w.contains("With them it would be 2000.0 m long where the rest is 8.00 m")
            && w.contains("--keep-far")
            && !w.contains("centimetres"),
        "{w}"
    );
    // Kept: the sky box chooses centimetres (a 20 m level, the house 8 cm long), as before.
    let keep = keep_far();
    let kept = Scene::load(&house, &keep).expect("load");
    assert_eq!(kept.static_triangles().count(), 1302);
    assert!(
        (longest_m(&kept) - 20.0).abs() < 1e-3,
        "{}",
        longest_m(&kept)
    );
    assert!(
        kept.report
            .warnings
            .join("\n")
            .contains("read in centimetres")
    );
    // A scene TOML keeps every triangle (the bake warns of them), and refuses --keep-far.
    let toml = dir.path().join("house.toml");
    let described = Scene::load(&toml, &ImportOptions::default()).expect("load");
    assert_eq!(described.static_triangles().count(), 1302);
    let refused = Scene::load(&toml, &keep).expect_err("a TOML keeps every triangle");
    assert!(refused.to_string().contains("--keep-far"), "{refused}");
}

#[test]
fn a_sky_dome_round_a_bare_house_is_left_out_whole() {
    let dir = tempfile::tempdir().expect("tempdir");
    let house = dir.path().join(write_house_in_sky(dir.path(), Sky::Dome));
    let scene = Scene::load(&house, &ImportOptions::default()).expect("load");
    assert_the_house_alone(&scene);
    let w = scene.report.warnings.join("\n");
    assert!(
        w.contains(
            "528 of its 1818 triangles lie far from the rest (the whole of 'Sky', round it)"
        ) && w.contains("left out of the level")
            && !w.contains("centimetres"),
        "{w}"
    );
    // Kept, the dome chooses centimetres, and the bake warns of it as a whole.
    let kept = Scene::load(&house, &keep_far()).expect("load");
    assert_eq!(kept.static_triangles().count(), 1818);
    assert!(
        kept.report
            .warnings
            .join("\n")
            .contains("read in centimetres")
    );
    let stray = visgate_formats::stray::stray_geometry(&kept).expect("the dome");
    assert_eq!(
        (stray.triangles, &stray.objects[..]),
        (528, &["Sky".to_string()][..])
    );
    // A scene TOML keeps it, unless it leaves the object out by name; a name that is no
    // object of the file is refused with the file's objects.
    let toml = |leave_out: &str| {
        let path = dir.path().join("leave-out.toml");
        let text = format!("[[mesh]]\npath = \"house.obj\"\nleave_out = [{leave_out}]\n");
        std::fs::write(&path, text).expect("toml");
        Scene::load(&path, &ImportOptions::default())
    };
    let described = toml("").expect("load");
    assert_eq!(described.static_triangles().count(), 1818);
    let left = toml("\"Sky\"").expect("load");
    assert_eq!(left.static_triangles().count(), 1290);
    assert_eq!(visgate_formats::stray::stray_geometry(&left), None);
    let e = toml("\"Skye\"").expect_err("no such object").to_string();
    assert!(
        e.contains("leave_out names 'Skye', which is no object of the file") && e.contains("'Sky'"),
        "{e}"
    );
}

#[test]
fn a_room_round_a_statue_of_many_triangles_keeps_its_walls() {
    // An 8 × 3 × 8 m room of 12 triangles round a 1 m statue of 1,600 (a "bunny in a box"): the
    // far-triangle rule takes the room for the strays round the statue (8× the statue's size),
    // under the 16× a bare mesh's strays must shorten it by to be left out. The bake warns.
    let dir = tempfile::tempdir().expect("tempdir");
    let mut obj = String::new();
    let mut quad = |c: [[f64; 3]; 4]| {
        for [x, y, z] in c {
            writeln!(obj, "v {x} {y} {z}").expect("write");
        }
        obj += "f -4 -3 -2 -1\n";
    };
    let (s, h) = (8.0, 3.0);
    quad([[0.0, 0.0, 0.0], [0.0, 0.0, s], [s, 0.0, s], [s, 0.0, 0.0]]);
    quad([[0.0, h, 0.0], [s, h, 0.0], [s, h, s], [0.0, h, s]]);
    quad([[0.0, 0.0, 0.0], [s, 0.0, 0.0], [s, h, 0.0], [0.0, h, 0.0]]);
    quad([[0.0, 0.0, s], [0.0, h, s], [s, h, s], [s, 0.0, s]]);
    quad([[0.0, 0.0, 0.0], [0.0, h, 0.0], [0.0, h, s], [0.0, 0.0, s]]);
    quad([[s, 0.0, 0.0], [s, 0.0, s], [s, h, s], [s, h, 0.0]]);
    // The statue: a 1 m column of 800 thin slabs' tops (1,600 triangles) at the room's middle.
    for i in 0..800 {
        let y = 1.0 + i as f64 / 800.0;
        quad([[3.5, y, 3.5], [3.5, y, 4.5], [4.5, y, 4.5], [4.5, y, 3.5]]);
    }
    let path = dir.path().join("statue.obj");
    std::fs::write(&path, obj).expect("obj");
    let scene = Scene::load(&path, &ImportOptions::default()).expect("load");
    let stray = visgate_formats::stray::stray_geometry(&scene).expect("the room taken for strays");
    assert_eq!((stray.triangles, stray.total), (12, 1612));
    assert_eq!(scene.static_triangles().count(), 1612);
    assert!(
        (longest_m(&scene) - 8.0).abs() < 1e-4,
        "{}",
        longest_m(&scene)
    );
    let w = scene.report.warnings.join("\n");
    assert!(!w.contains("left out"), "{w}");
}
