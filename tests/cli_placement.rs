//! Scenes that rendered black with nothing said: lights and cameras written in metres while the
//! level is modelled in centimetres (every method matched the black reference to the digit),
//! a lamp inside a closed shade (which the bake took for a doorway closed by the voxels), and a
//! camera behind a sealed level's wall (dropped by the bake with nothing said).
//! The command line says so now, with the fix.

mod support;

use std::path::{Path, PathBuf};

use support::{stderr, visgate_warn};

/// A closed 4 × 3 × 4 m room modelled in centimetres 1 km along x from the origin, with a
/// lamp and a camera at its middle written as `light` and `eye` (in the file's units).
fn room_in_centimetres(dir: &Path, light: [f64; 3], eye: [f64; 3]) -> PathBuf {
    let c = |x: f64, y: f64, z: f64| [100_000.0 + 400.0 * x, 300.0 * y, 400.0 * z];
    let corners: Vec<[f64; 3]> = (0..8)
        .map(|i| c((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64))
        .collect();
    let mut obj: String = corners
        .iter()
        .map(|p| format!("v {} {} {}\n", p[0], p[1], p[2]))
        .collect();
    // Its six faces (corner index bits: x, y, z; 1-based).
    obj += "f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\nf 5 6 8 7\n";
    std::fs::write(dir.join("room.obj"), obj).expect("obj");
    let toml = format!(
        "name = \"room-cm\"\nmetres_per_unit = 0.01\n[[mesh]]\npath = \"room.obj\"\n\
         [[light]]\ntype = \"point\"\nposition = {light:?}\nintensity = [5, 5, 5]\n\
         [[camera]]\nname = \"middle\"\neye = {eye:?}\ntarget = [100200.0, 150.0, 0.0]\n\
         fov_deg = 70\n"
    );
    let path = dir.join("room.toml");
    std::fs::write(&path, toml).expect("toml");
    path
}

#[test]
fn lights_and_cameras_written_in_the_wrong_units_are_named_with_the_fix() {
    let dir = tempfile::tempdir().expect("tempdir");
    // Written in metres: a hundredth of the way to the origin, 1 km from the room.
    let scene = room_in_centimetres(dir.path(), [1002.0, 1.0, 2.0], [1002.0, 1.5, 3.0]);
    let scene = scene.to_str().expect("utf-8");
    let o = visgate_warn(&["inspect", scene]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("point light 0 at (10.02, 0.01, 0.02) m stands")
            && err.contains("if (1002, 1, 2) are metres, write (100200, 100, 200)")
            && err.contains("camera 'middle' at"),
        "{err}"
    );
    // The render: no light path meets the room.
    let out = dir.path().join("x.png");
    let args = ["render", scene, "--mode", "none", "--cpu", "--vpls", "64"];
    let o = visgate_warn(
        &[
            &args[..],
            &["--size", "16x12", "-o", out.to_str().expect("utf-8")],
        ]
        .concat(),
    );
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("no light path from the scene's lights met the geometry (0 VPLs of 64"),
        "{err}"
    );
    // Written in centimetres: nothing to say, and the lamp lights the room.
    let scene = room_in_centimetres(
        dir.path(),
        [100_200.0, 150.0, 200.0],
        [100_200.0, 150.0, 300.0],
    );
    let scene = scene.to_str().expect("utf-8");
    let o = visgate_warn(
        &[
            &args[..1],
            &[scene],
            &args[2..],
            &["--size", "16x12", "-o", out.to_str().expect("utf-8")],
        ]
        .concat(),
    );
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        !err.contains("outside the level") && !err.contains("no light path"),
        "{err}"
    );
}

#[test]
fn a_lamp_inside_a_closed_shade_is_named_by_the_bake_and_its_render_says_black() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let o = visgate_warn(&["scenes", "export", "ajar-door", d.to_str().expect("utf-8")]);
    assert!(o.status.success(), "{}", stderr(&o));
    // A closed 20 cm box around the lamp at (6.6, 2.5, 3.3).
    let mut obj = std::fs::read_to_string(d.join("ajar-door.obj")).expect("obj");
    obj += "o shade\n";
    for i in 0..8 {
        let s = |b: usize| if i >> b & 1 == 1 { 0.1 } else { -0.1 };
        obj += &format!("v {} {} {}\n", 6.6 + s(0), 2.5 + s(1), 3.3 + s(2));
    }
    obj += "f -8 -6 -5 -7\nf -4 -3 -1 -2\nf -8 -7 -3 -4\nf -6 -2 -1 -5\nf -8 -4 -2 -6\nf -7 -5 -1 -3\n";
    std::fs::write(d.join("ajar-door.obj"), obj).expect("obj");
    let scene = d.join("ajar-door.toml");
    let scene = scene.to_str().expect("utf-8");
    let level = d.join("l.vgate");
    let level = level.to_str().expect("utf-8");
    // At 128 (voxels of 6.25 cm) the shade holds empty voxels; at 64 it is solid through.
    let o = visgate_warn(&["bake", scene, "--resolution", "128", "-o", level]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("point light 0 is inside closed geometry"),
        "{err}"
    );
    // Not taken for a doorway the voxels close.
    assert!(!err.contains("bake at --resolution"), "{err}");
    let out = d.join("x.png");
    let o = visgate_warn(&[
        "render",
        scene,
        "--camera",
        "light-room",
        "--mode",
        "reference",
        "--vpls",
        "64",
        "--size",
        "16x12",
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("the image is black"), "{err}");
}

#[test]
fn a_camera_behind_a_sealed_level_s_wall_is_named_by_the_bake() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let o = visgate_warn(&["scenes", "export", "ajar-door", d.to_str().expect("utf-8")]);
    assert!(o.status.success(), "{}", stderr(&o));
    // 30 cm behind the wall at z = 0, beyond the grid: the bake dropped it with nothing said.
    let scene = d.join("ajar-door.toml");
    let mut toml = std::fs::read_to_string(&scene).expect("toml");
    toml += "\n[[camera]]\nname = \"behind\"\neye = [4.0, 1.5, -0.3]\n\
             target = [4.0, 1.5, 2.0]\nfov_deg = 70.0\n";
    std::fs::write(&scene, toml).expect("toml");
    let level = d.join("l.vgate");
    let args = ["bake", scene.to_str().expect("utf-8"), "--resolution", "64"];
    let o = visgate_warn(&[&args[..], &["-o", level.to_str().expect("utf-8")]].concat());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("camera 'behind' is outside the level: beyond the grid")
            && err.contains("Move it inside (the rooms span (0.12, 0.12, 0.12) .. (7.88, 2.88"),
        "{err}"
    );
    // The level's own cameras and light: not named.
    assert!(
        !err.contains("camera 'main' is") && !err.contains("light 0 is"),
        "{err}"
    );
}
