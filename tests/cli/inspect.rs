//! The subcommands' help, the built-in scenes, inspect and export, bare meshes' units and up axis, clear errors.

use super::*;

#[test]
fn help_lists_the_subcommands_that_exist() {
    let o = visgate(&["--help"]);
    assert!(o.status.success());
    let out = stdout(&o);
    for sub in ["inspect", "scenes", "builtin:NAME"] {
        assert!(out.contains(sub), "--help does not mention {sub}:\n{out}");
    }
    let o = visgate(&["no-such-command"]);
    assert!(!o.status.success());
}

#[test]
fn scenes_lists_every_builtin() {
    let o = visgate(&["scenes"]);
    assert!(o.status.success());
    for name in [
        "empty-box",
        "two-rooms",
        "ring-corridor",
        "l-corridor",
        "four-rooms",
        "cornell-box",
    ] {
        assert!(stdout(&o).contains(name), "{name} missing");
    }
}

#[test]
fn inspect_a_builtin_as_text_and_json() {
    let o = visgate(&["inspect", "builtin:two-rooms"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.contains("triangles") && out.contains("bounds") && out.contains("closed      yes"),
        "{out}"
    );
    // How high its rooms stand, which tells a user whether the units are right.
    assert!(
        out.contains("rooms       3.00 m floor to ceiling (the median of"),
        "{out}"
    );
    // Its objects by name, the most triangles first: what a scene TOML's leave_out takes.
    let o = visgate(&["inspect", "builtin:ajar-door"]);
    let out = stdout(&o);
    assert!(
        out.contains("objects     5: 'wood' 72, 'wall' 14, 'floor' 2, 'ceiling' 2, 'red' 2"),
        "{out}"
    );
    // Each light a line: the four rooms' lamp and spot, where they are and how bright.
    let o = visgate(&["inspect", "builtin:four-rooms"]);
    let out = stdout(&o);
    assert!(
        out.contains("point at (2.000, 2.700, 2.000) m, (8.000, 8.000, 8.000) W/sr")
            && out.contains("beam 30.0°, cutoff 40.0°"),
        "{out}"
    );
    let o = visgate(&["inspect", "builtin:lamp-hall"]);
    assert!(stdout(&o).contains("… and 43 more"), "{}", stdout(&o));
    let o = visgate(&["inspect", "--json", "builtin:four-rooms"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("valid JSON");
    assert_eq!(v["kind"], "scene");
    assert_eq!(v["point_lights"], 1);
    assert_eq!(v["spot_lights"], 1);
    assert_eq!(v["closed"], true);
    assert!(v["triangles"].as_u64().expect("count") > 0);
    let rooms = v["rooms_m"].as_f64().expect("rooms measured");
    assert!((rooms - 3.0).abs() < 1e-3, "{rooms}");
    assert!(v["room_columns"].as_u64().expect("columns") > 1000);
    // A ground alone holds no room.
    let dir = tempfile::tempdir().expect("tempdir");
    let ground = dir.path().join("ground.obj");
    std::fs::write(
        &ground,
        "v 0 0 0\nv 40 0 0\nv 40 0 40\nv 0 0 40\nf 1 3 2\nf 1 4 3\n",
    )
    .expect("write");
    let o = visgate(&["inspect", ground.to_str().expect("utf8")]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("rooms       none measured"),
        "{}",
        stdout(&o)
    );
}

#[test]
fn export_then_inspect_the_files_and_a_bare_mesh() {
    let (dir, out) = exported("cornell-box");
    let o = visgate(&[
        "inspect",
        "--json",
        out.join("cornell-box.toml").to_str().expect("utf8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(v["triangles"], 36);
    assert_eq!(v["point_lights"], 1);
    // The OBJ on its own: one static mesh, no lights.
    let o = visgate(&[
        "inspect",
        "--json",
        out.join("CornellBox-Original.obj").to_str().expect("utf8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(v["triangles"], 36);
    assert_eq!(v["point_lights"], 0);
    assert_eq!(v["static_triangles"], 36);
    // Rendering it: it gets a light under its glowing ceiling lamp and a camera in the open
    // space inside the box (not in its blocks), and says so; the image is lit.
    let png = dir.path().join("bare.exr");
    let o = visgate(&[
        "render",
        out.join("CornellBox-Original.obj").to_str().expect("utf8"),
        "--mode",
        "none",
        "--size",
        "32x24",
        "--vpls",
        "64",
        "-o",
        png.to_str().expect("utf8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("no light and no camera") && stdout(&o).contains("[[light]]"),
        "{}",
        stdout(&o)
    );
    // Its ceiling lamp is a glowing material: the light goes there.
    assert!(
        stdout(&o).contains("at its glowing surfaces (material 'light'"),
        "{}",
        stdout(&o)
    );
    let img = image::open(&png).expect("exr").to_rgb32f();
    let mean = img.pixels().map(|p| p.0.iter().sum::<f32>()).sum::<f32>() / (3.0 * 768.0);
    // Lit: 0.032 with the light under the lamp (over 0.05 with it at the camera before).
    assert!(mean > 0.01, "mean radiance {mean}");
    // Compare too: the same light and camera, one row against the reference.
    let cmp = dir.path().join("cmp");
    let o = visgate(&[
        "compare",
        out.join("CornellBox-Original.obj").to_str().expect("utf8"),
        "--modes",
        "none",
        "--vpls",
        "64",
        "--size",
        "32x24",
        "--spp",
        "1",
        "--out",
        cmp.to_str().expect("utf8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("no light and no camera"),
        "{}",
        stdout(&o)
    );
    let report = std::fs::read_to_string(cmp.join("report.md")).expect("report");
    assert!(report.contains("## Camera inside"), "{report}");
}

/// The JSON summary's size of the scene's box, metres.
fn size_of(v: &serde_json::Value) -> [f64; 3] {
    let at = |k: &str, a: usize| v[k][a].as_f64().expect("bounds");
    [0, 1, 2].map(|a| at("bounds_max_m", a) - at("bounds_min_m", a))
}

#[test]
fn a_bare_obj_modelled_z_up_in_millimetres_is_read_as_its_flags_say() {
    let (_dir, out) = exported("two-rooms");
    // The two rooms (8.6 × 3.4 × 4.4 m outside, Y up) as a Z-up exporter in millimetres
    // writes them.
    let obj = std::fs::read_to_string(out.join("two-rooms.obj")).expect("obj");
    let zup: String = obj
        .lines()
        .map(|l| match l.strip_prefix("v ") {
            Some(v) => {
                let c: Vec<f64> = v
                    .split_whitespace()
                    .map(|x| x.parse().expect("f64"))
                    .collect();
                format!("v {} {} {}\n", 1e3 * c[0], -1e3 * c[2], 1e3 * c[1])
            }
            None => format!("{l}\n"),
        })
        .collect();
    let mesh = out.join("zup.obj");
    std::fs::write(&mesh, zup).expect("write");
    let mesh = mesh.to_str().expect("utf8");
    let inspect = |extra: &[&str]| {
        let o = visgate(&[&["inspect", "--json", mesh][..], extra].concat());
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_slice::<serde_json::Value>(&o.stdout).expect("json")
    };
    // Unsaid: read Z up (floors face z, the level is low along z) and, 8,600 units long, in
    // millimetres: its extent alone would read centimetres (86 m), its rooms' height there
    // (30 m floor to ceiling) is none a room has; both said in its warnings.
    let v = inspect(&[]);
    let size = size_of(&v);
    assert!(
        (size[0] - 8.6).abs() < 1e-4 && (size[1] - 3.4).abs() < 1e-4,
        "{size:?}"
    );
    let warnings = v["warnings"].to_string();
    assert!(
        warnings.contains("read Z up")
            && warnings.contains("read in millimetres")
            && warnings.contains("--metres-per-unit"),
        "{warnings}"
    );
    // Said: millimetres, Y up as written (the rooms then lie on their side), no warning.
    let v = inspect(&["--metres-per-unit", "0.001", "--up", "y"]);
    let size = size_of(&v);
    assert!(
        (size[1] - 4.4).abs() < 1e-6 && (size[2] - 3.4).abs() < 1e-6,
        "{size:?}"
    );
    assert_eq!(v["warnings"].as_array().map(Vec::len), Some(0), "{v}");
    // The flags read a bare mesh only, and a unit must be a length.
    let o = visgate(&["inspect", "builtin:two-rooms", "--up", "z"]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("read a bare mesh file"),
        "{}",
        stderr(&o)
    );
    let o = visgate(&["inspect", mesh, "--metres-per-unit", "0"]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("must be a number > 0"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn inspect_a_baked_file_and_refuse_a_broken_one() {
    use visgate_formats::vgate::*;
    let dir = tempfile::tempdir().expect("tempdir");
    let grid = GridMeta {
        origin_m: [0.0; 3],
        voxel_size_m: 0.5,
        dims: [2, 2, 2],
    };
    let level = BakedLevel {
        info: BakeInfo {
            params: BakeParams::default(),
            geometry_hash: visgate_formats::GeometryHash([1; 16]),
            grid,
            sight_grid: grid,
            tool_version: "test".into(),
        },
        topology: Topology {
            skeleton: Skeleton {
                nodes: vec![SkeletonNode {
                    voxel: [0, 0, 0],
                    position_m: [0.25; 3],
                    radius_m: 0.5,
                }],
                edges: vec![],
            },
            segmented: SegmentedSkeleton {
                nodes: vec![SegNode {
                    skeleton_node: 0,
                    kind: SegNodeKind::Topology,
                }],
                edges: vec![],
            },
            node_cluster: vec![0],
            clusters: vec![Cluster {
                seed: 0,
                bounds_min_m: [0.0; 3],
                bounds_max_m: [1.0; 3],
            }],
            gates: vec![],
            portals: vec![],
        },
        voxel_cluster: VoxelValues::pack(&[0; 8]),
        open: VoxelBits::from_fn(8, |_| true),
    };
    let path = dir.path().join("l.vgate");
    level.write(&path).expect("write");
    let o = visgate(&["inspect", path.to_str().expect("utf8")]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("2 x 2 x 2 voxels"), "{}", stdout(&o));
    let o = visgate(&["inspect", "--json", path.to_str().expect("utf8")]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(v["clusters"], 1);
    assert_eq!(v["gates"], 0);
    // Corrupt it: a clear error, exit code 1, no panic.
    let mut bytes = std::fs::read(&path).expect("read");
    let last = bytes.len() - 1;
    bytes[last] ^= 0x55;
    std::fs::write(&path, &bytes).expect("write");
    let o = visgate(&["inspect", path.to_str().expect("utf8")]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("corrupt") && stderr(&o).contains("l.vgate"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn bad_arguments_give_clear_errors() {
    let o = visgate(&["inspect", "missing.toml"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("missing.toml") && stderr(&o).contains("no such file"),
        "{}",
        stderr(&o)
    );
    let o = visgate(&["inspect", "builtin:nope"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("two-rooms"),
        "the error lists the built-ins: {}",
        stderr(&o)
    );
    let o = visgate(&["scenes", "export", "nope", "out"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(!Path::new("out").exists());
    let dir = tempfile::tempdir().expect("tempdir");
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[[mesh]]\npath = \"x.obj\"\nstatik = true\n").expect("write");
    let o = visgate(&["inspect", bad.to_str().expect("utf8")]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("statik") && stderr(&o).contains("bad.toml"),
        "{}",
        stderr(&o)
    );
    assert!(!stderr(&o).contains("panicked"));
}
