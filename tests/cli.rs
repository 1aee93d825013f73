//! The `visgate` command line, run as a user runs it.

mod support;

use std::path::Path;

use support::{stderr, stdout, visgate};

/// `visgate bake builtin:two-rooms -o OUT --resolution 64` and `extra`.
fn two_rooms_at_64(out: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["bake", "builtin:two-rooms", "-o", out, "--resolution", "64"];
    args.extend(extra);
    visgate(&args)
}

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
}

#[test]
fn export_then_inspect_the_files_and_a_bare_mesh() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("cb");
    let o = visgate(&[
        "scenes",
        "export",
        "cornell-box",
        out.to_str().expect("utf8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
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
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("tr");
    let o = visgate(&["scenes", "export", "two-rooms", out.to_str().expect("utf8")]);
    assert!(o.status.success(), "{}", stderr(&o));
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
    // Unsaid: read Z up (floors face z, the level is low along z) and, 8,000 units long, in
    // centimetres; both said in its warnings.
    let v = inspect(&[]);
    let size = size_of(&v);
    assert!(
        (size[0] - 86.0).abs() < 1e-3 && (size[1] - 34.0).abs() < 1e-3,
        "{size:?}"
    );
    let warnings = v["warnings"].to_string();
    assert!(
        warnings.contains("read Z up") && warnings.contains("--metres-per-unit"),
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

#[test]
fn bake_writes_the_level_report_and_debug_exports() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("two.vgate");
    let report = dir.path().join("bake.json");
    let debug = dir.path().join("debug");
    // On its own grid, so that the skeleton's nodes are the exported grid's voxels.
    let o = two_rooms_at_64(
        out.to_str().expect("utf-8"),
        &[
            "--partition-voxel",
            "0",
            "--threads",
            "2",
            "--report",
            report.to_str().expect("utf-8"),
            "--debug-dir",
            debug.to_str().expect("utf-8"),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    for want in [
        "voxelize",
        "thin",
        "skeleton nodes",
        "clusters 2",
        "gates 1",
        "(preserved)",
    ] {
        assert!(text.contains(want), "missing '{want}' in:\n{text}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("json");
    // The doorway's own cluster is a sliver in a thin wall, merged into a room: one gate.
    assert_eq!(json["summary"]["gates"], 1);
    assert!(json["stages"].as_array().expect("stages").len() >= 10);
    for f in [
        "solid.npy",
        "skeleton.npy",
        "solid_surface.ply",
        "skeleton.ply",
        "segmented.ply",
        "clusters.ply",
        "gates.ply",
    ] {
        let bytes = std::fs::read(debug.join(f)).expect(f);
        assert!(bytes.len() > 64, "{f} is empty");
    }
    // The .npy files have the grid's shape and 0/1 values.
    let npy = std::fs::read(debug.join("skeleton.npy")).expect("npy");
    assert_eq!(&npy[..6], b"\x93NUMPY");
    let hlen = u16::from_le_bytes([npy[8], npy[9]]) as usize;
    let header = String::from_utf8_lossy(&npy[10..10 + hlen]);
    let dims = &json["grid"]["dims"];
    let shape = format!("({}, {}, {})", dims[0], dims[1], dims[2]);
    assert!(header.contains(&shape), "{header} vs {shape}");
    let body = &npy[10 + hlen..];
    assert!(body.iter().all(|&b| b <= 1));
    assert_eq!(
        body.iter().filter(|&&b| b == 1).count() as u64,
        json["summary"]["skeleton_nodes"].as_u64().expect("n")
    );
    // inspect reads it back.
    let o = visgate(&["inspect", out.to_str().expect("utf-8")]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("gates       1"), "{}", stdout(&o));
}

/// A closed room (4 × 3 × 4 m, zero-thickness walls) with a 0.6 m window in its +x wall
/// centred at (4, 1.5, 2), a ground outside, and a lamp inside, as an OBJ and a scene file.
fn leaky_room(dir: &std::path::Path) -> std::path::PathBuf {
    let mut obj = String::new();
    let mut quad = |p: [[f32; 3]; 4]| {
        for v in p {
            obj += &format!("v {} {} {}\n", v[0], v[1], v[2]);
        }
        obj += "f -4 -3 -2 -1\n";
    };
    quad([[0., 0., 0.], [0., 0., 4.], [4., 0., 4.], [4., 0., 0.]]);
    quad([[0., 3., 0.], [4., 3., 0.], [4., 3., 4.], [0., 3., 4.]]);
    quad([[0., 0., 0.], [0., 3., 0.], [0., 3., 4.], [0., 0., 4.]]);
    quad([[0., 0., 0.], [4., 0., 0.], [4., 3., 0.], [0., 3., 0.]]);
    quad([[0., 0., 4.], [0., 3., 4.], [4., 3., 4.], [4., 0., 4.]]);
    quad([[4., 0., 0.], [4., 0., 4.], [8., 0., 4.], [8., 0., 0.]]);
    for (y0, y1, z0, z1) in [
        (0., 1.2, 0., 4.),
        (1.8, 3., 0., 4.),
        (1.2, 1.8, 0., 1.7),
        (1.2, 1.8, 2.3, 4.),
    ] {
        quad([[4., y0, z0], [4., y0, z1], [4., y1, z1], [4., y1, z0]]);
    }
    std::fs::write(dir.join("room.obj"), obj).expect("obj");
    let toml = "name = \"leaky\"\nclosed = true\n[[mesh]]\npath = \"room.obj\"\n\
                [[light]]\ntype = \"point\"\nposition = [2.0, 1.5, 2.0]\nintensity = [5, 5, 5]\n";
    let path = dir.join("leaky.toml");
    std::fs::write(&path, toml).expect("toml");
    path
}

#[test]
fn bake_says_each_import_warning_once() {
    // The leaky room's mesh with a zero-area triangle added: the importer drops it and says
    // so; the bake used to say it a second time.
    let dir = tempfile::tempdir().expect("tempdir");
    leaky_room(dir.path());
    let mesh = dir.path().join("room.obj");
    let mut obj = std::fs::read_to_string(&mesh).expect("obj");
    obj += "v 1 1 1\nv 2 2 2\nv 3 3 3\nf -3 -2 -1\n";
    std::fs::write(&mesh, obj).expect("obj");
    let out = dir.path().join("l.vgate");
    // Warnings shown, as a user sees them (the other tests run with RUST_LOG=error).
    let (mesh, out) = (mesh.to_str().expect("utf-8"), out.to_str().expect("utf-8"));
    let o = support::visgate_warn(&["bake", mesh, "--resolution", "16", "-o", out]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        stderr(&o).matches("degenerate").count(),
        1,
        "{}",
        stderr(&o)
    );
}

/// `visgate bake SCENE -o DIR/l.vgate --resolution 64 --debug-dir DIR/debug --report
/// DIR/bake.json`, and those two paths.
fn bake_at_64_with_debug(
    scene: &std::path::Path,
    dir: &std::path::Path,
) -> (Vec<String>, std::path::PathBuf, std::path::PathBuf) {
    let (debug, report) = (dir.join("debug"), dir.join("bake.json"));
    let path = |p: &std::path::Path| p.to_str().expect("utf-8").to_string();
    let args = [
        "bake".to_string(),
        path(scene),
        "-o".into(),
        path(&dir.join("l.vgate")),
        "--resolution".into(),
        "64".into(),
        "--debug-dir".into(),
        path(&debug),
        "--report".into(),
        path(&report),
    ];
    (args.to_vec(), debug, report)
}

#[test]
fn a_leak_is_printed_where_it_is_and_written_as_a_path() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = leaky_room(dir.path());
    let (args, debug, report) = bake_at_64_with_debug(&scene, dir.path());
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = visgate(&args);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("point light 0")
            && err.contains("reaches the outside through an opening near (4."),
        "{err}"
    );
    assert!(
        err.contains("--allow-leaks") && !err.contains("panicked"),
        "{err}"
    );
    let ply = std::fs::read_to_string(debug.join("leak.ply")).expect("leak.ply");
    assert!(
        ply.starts_with("ply") && ply.contains("element edge"),
        "{ply}"
    );
    // Baked anyway: a warning with the place, and the openings in the report.
    let mut anyway = args.clone();
    anyway.push("--allow-leaks");
    let o = visgate(&anyway);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("warning: leak: point light 0"),
        "{}",
        stderr(&o)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("json");
    let openings = json["empty_space"]["openings"]
        .as_array()
        .expect("openings");
    assert_eq!(openings.len(), 1, "{openings:?}");
    assert!(openings[0]["path_m"].as_array().expect("path").len() > 5);
}

#[test]
fn a_bare_mesh_is_baked_around_its_inside_and_told_where_that_leaks() {
    // The leaky room's mesh alone: no camera, no light, not declared closed.
    let dir = tempfile::tempdir().expect("tempdir");
    leaky_room(dir.path());
    let (args, debug, report) = bake_at_64_with_debug(&dir.path().join("room.obj"), dir.path());
    let o = visgate(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("warning: leak: the level's inside at (")
            && err.contains("reaches the outside through an opening near (4."),
        "{err}"
    );
    assert!(
        err.contains("the most triangles face") && err.contains("`closed = true`"),
        "{err}"
    );
    assert!(debug.join("leak.ply").exists());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("json");
    let inside = json["empty_space"]["inside_m"]
        .as_array()
        .expect("inside_m");
    let x = inside[0].as_f64().expect("x");
    assert!(
        (0.0..4.0).contains(&x),
        "the inside's point {inside:?} is not in the room"
    );
}

#[test]
fn bake_takes_the_papers_readings_and_records_them_in_the_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("ring.vgate");
    let out = out.to_str().expect("utf-8");
    let bake = |extra: &[&str]| {
        let mut a = vec![
            "bake",
            "builtin:ring-corridor",
            "-o",
            out,
            "--resolution",
            "64",
            "-q",
        ];
        a.extend(extra);
        let o = visgate(&a);
        assert!(o.status.success(), "{}", stderr(&o));
        stdout(&o)
    };
    let text = bake(&[]);
    assert!(
        text.contains("max ball SolidCentre, curvature to Line") && text.contains("PoppedNode"),
        "{text}"
    );
    let text = bake(&[
        "--max-ball",
        "contained",
        "--alpha-rule",
        "cluster-max",
        "--curvature-to",
        "segment",
    ]);
    assert!(text.contains("against ClusterMax"), "{text}");
    let o = visgate(&["inspect", out]);
    let info = stdout(&o);
    for want in [
        "max_ball: Contained",
        "alpha_rule: ClusterMax",
        "curvature_to: Segment",
    ] {
        assert!(info.contains(want), "missing '{want}' in {info}");
    }
    let o = visgate(&[
        "bake",
        "builtin:two-rooms",
        "-o",
        out,
        "--max-ball",
        "centre",
    ]);
    assert!(stderr(&o).contains("solid-centre"), "{}", stderr(&o));
}

#[test]
fn a_clean_bake_writes_nothing_on_stderr() {
    // Warnings and errors go to stderr; a built-in level with nothing to warn of leaves it
    // empty (a stage's leftover timing print once went there on every bake).
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("x.vgate");
    let o = two_rooms_at_64(out.to_str().expect("utf-8"), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stderr(&o), "", "stderr of a clean bake");
}

#[test]
fn a_bake_too_coarse_for_its_level_says_so_and_what_resolution_to_use() {
    // `ajar-door` at 16 voxels: 0.5 m voxels close the door, the cameras' room is sealed off
    // from the light's; partitioned on its own grid, two clusters and no gate. At 32 the rooms
    // are wide enough, the door still closed; at 64 it is open: nothing to say.
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("x.vgate");
    let out = out.to_str().expect("utf-8");
    let bake_with = |res: &str, more: &[&str]| {
        let mut args = vec!["bake", "builtin:ajar-door", "-o", out, "--resolution", res];
        args.extend(more);
        visgate(&args)
    };
    let bake = |res: &str| bake_with(res, &[]);
    let sealed = "warning: camera 'main' and camera 'door' are in a part of the empty space that \
                  no light is in";
    // By default a bake this coarse is partitioned on the level's 128 grid: its clusters
    // follow the rooms (6), only the closed door is said.
    let o = bake("16");
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains(sealed) && err.contains("--resolution 32 or more"),
        "{err}"
    );
    assert!(!err.contains("too coarse"), "{err}");
    assert!(stdout(&o).contains("clusters 6 "), "{}", stdout(&o));
    let o = bake_with("16", &["--partition-voxel", "0"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains(sealed) && err.contains("--resolution 32 or more"),
        "{err}"
    );
    assert!(
        err.contains("warning: the grid is too coarse for this level: its widest empty space is 4.0 voxels across")
            && err.contains("the 2 cluster(s)")
            && err.contains("--resolution 48 or more"),
        "{err}"
    );
    let o = bake("32");
    let err = stderr(&o);
    assert!(
        err.contains("no light is in") && err.contains("--resolution 64 or more"),
        "{err}"
    );
    assert!(!err.contains("too coarse"), "{err}");
    let o = bake("64");
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stderr(&o), "", "stderr of a bake fine enough");
}

#[test]
fn a_refined_bake_says_where_its_partition_was_made() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("x.vgate");
    let out = out.to_str().expect("utf-8");
    // Two rooms at 64 voxels of 0.134 m, partitioned on 0.27 m voxels.
    let o = two_rooms_at_64(out, &["--partition-voxel", "0.27"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    for want in ["refine", "partition: made on a 0.270 m grid", "clusters 2"] {
        assert!(text.contains(want), "missing '{want}' in:\n{text}");
    }
    let info = stdout(&visgate(&["inspect", out]));
    assert!(
        info.contains("made on a 0.27 m grid, refined onto this one"),
        "{info}"
    );
    // On its own grid it says so.
    let o = two_rooms_at_64(out, &["--partition-voxel", "0"]);
    assert!(stdout(&o).contains("partition: made on the level's grid"));
    let info = stdout(&visgate(&["inspect", out]));
    assert!(info.contains("made on this grid"), "{info}");
    // By default a bake this coarse (its voxels twice 1/128 of the level) is partitioned on
    // its 128 grid, and says so.
    let o = two_rooms_at_64(out, &[]);
    let text = stdout(&o);
    let want = "partition: made on a finer 0.0672 m grid (its topology below), each 0.134 m \
                voxel given the cluster most of its share of it has";
    assert!(text.contains(want), "{text}");
    let info = stdout(&visgate(&["inspect", out]));
    assert!(
        info.contains("made on a finer 0.0671875 m grid, each voxel here its share's cluster"),
        "{info}"
    );
}

#[test]
fn a_bake_says_its_sight_grid_and_inspect_how_the_file_stores_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("x.vgate");
    let out = out.to_str().expect("utf-8");
    let report = dir.path().join("r.json");
    let report = report.to_str().expect("utf-8");
    // Two rooms, 8.6 m long: the sight grid at 1/512 of it, 515 voxels with the border.
    let o = two_rooms_at_64(out, &["--report", report]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Each stage's CPU time, where the OS tells it (Linux).
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report).expect("report")).expect("JSON");
    let stages = r["stages"].as_array().expect("stages");
    assert!(stages.len() > 8, "{r}");
    for st in stages {
        let cpu = st["cpu_seconds"].as_f64();
        if cfg!(target_os = "linux") {
            assert!(cpu.is_some_and(|c| c >= 0.0), "{st}");
        }
    }
    let text = stdout(&o);
    let want = "sight grid 515 x 205 x 264, ";
    assert!(
        text.contains(want) && text.contains("voxel 0.0168 m (the voxel walk's: --sight-voxel)"),
        "missing the sight grid in:\n{text}"
    );
    let info = stdout(&visgate(&["inspect", out]));
    assert!(
        info.contains("format v7") && info.contains("bit each), stored runs in "),
        "{info}"
    );
}

#[test]
fn bake_refuses_bad_arguments_clearly() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("x.vgate");
    let out = out.to_str().expect("utf-8");
    let o = visgate(&["bake", "builtin:two-rooms", "-o", out, "--alpha", "3"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("alpha"), "{}", stderr(&o));
    let o = visgate(&["bake", "builtin:two-rooms", "-o", out, "--resolution", "4"]);
    assert!(stderr(&o).contains("8..=2048"), "{}", stderr(&o));
    let o = visgate(&[
        "bake",
        "builtin:two-rooms",
        "-o",
        out,
        "--resolution",
        "2000",
        "--memory-limit-gib",
        "0.5",
    ]);
    assert!(stderr(&o).contains("GiB"), "{}", stderr(&o));
    let o = visgate(&["bake", "nope.toml", "-o", out]);
    assert!(stderr(&o).contains("no such file"), "{}", stderr(&o));
    // The sizes that shape the partition name their limits.
    for (flag, value, says) in [
        ("--min-gap", "-0.1", "minimum gap -0.1 m must be in 0..=10"),
        (
            "--partition-voxel",
            "NaN",
            "partition voxel NaN m must be in 0..=10",
        ),
        (
            "--min-cluster-ball",
            "11",
            "smallest cluster ball 11 m must be in 0..=10",
        ),
        (
            "--sight-voxel",
            "-1",
            "sight voxel -1 m must be a finite number >= 0 (0 walks the level's own grid)",
        ),
    ] {
        let arg = format!("{flag}={value}");
        let o = visgate(&["bake", "builtin:two-rooms", "-o", out, &arg]);
        assert!(!o.status.success());
        assert!(stderr(&o).contains(says), "{flag}: {}", stderr(&o));
    }
}

#[test]
fn render_writes_exr_and_png_and_diff_compares_them() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = |n: &str| dir.path().join(n).to_str().expect("utf-8").to_string();
    for (mode, out) in [
        ("reference", "ref.exr"),
        ("none", "none.exr"),
        ("direct-only", "direct.png"),
    ] {
        let o = visgate(&[
            "render",
            "builtin:cornell-box",
            "--mode",
            mode,
            "--vpls",
            "64",
            "--size",
            "24x16",
            "--spp",
            "1",
            "--out",
            &p(out),
        ]);
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        assert!(stdout(&o).contains("wrote"), "{}", stdout(&o));
    }
    // The CPU twin of none agrees with the GPU's none.
    let o = visgate(&[
        "render",
        "builtin:cornell-box",
        "--mode",
        "none",
        "--cpu",
        "--vpls",
        "64",
        "--size",
        "24x16",
        "--spp",
        "1",
        "--out",
        &p("none-cpu.exr"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = visgate(&["diff", &p("none.exr"), &p("none-cpu.exr")]);
    assert!(o.status.success(), "{}", stderr(&o));
    // RSM VPLs (GPU) in the GPU's none and in the CPU reference.
    for mode in ["none", "reference"] {
        let o = visgate(&[
            "render",
            "builtin:cornell-box",
            "--mode",
            mode,
            "--vpl-source",
            "rsm",
            "--vpls",
            "64",
            "--size",
            "24x16",
            "--spp",
            "1",
            "--out",
            &p("rsm.exr"),
        ]);
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        assert!(stdout(&o).contains("Rsm"), "{}", stdout(&o));
    }
    let o = visgate(&[
        "render",
        "builtin:cornell-box",
        "--vpl-source",
        "rsm",
        "--bounces",
        "2",
        "--out",
        &p("x.exr"),
    ]);
    assert!(stderr(&o).contains("one bounce"), "{}", stderr(&o));
    let o = visgate(&["diff", &p("none.exr"), &p("ref.exr"), "-o", &p("d.png")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    for want in ["MSE", "rel. MSE", "FLIP mean", "wrote"] {
        assert!(text.contains(want), "missing {want}: {text}");
    }
    assert!(std::path::Path::new(&p("d.png")).exists());
    // The same image against itself: zero error.
    let o = visgate(&["diff", &p("ref.exr"), &p("ref.exr")]);
    assert!(stdout(&o).contains("MSE        0.0"), "{}", stdout(&o));
    // Direct light alone has no indirect light: black wherever the reference is lit
    // indirectly, every such pixel red in the black map, the rest grey.
    let o = visgate(&[
        "render",
        "builtin:cornell-box",
        "--mode",
        "direct-only",
        "--cpu",
        "--size",
        "24x16",
        "--spp",
        "1",
        "--out",
        &p("direct.exr"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (image, reference, direct) = (p("direct.exr"), p("ref.exr"), p("direct.exr"));
    let map = p("black.png");
    let args = [
        "diff",
        &image,
        &reference,
        "--direct",
        &direct,
        "--black-map",
        &map,
    ];
    let o = visgate(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("black where lit  100.0"),
        "{}",
        stdout(&o)
    );
    let png = image::open(&map).expect("the black map").to_rgb8();
    assert_eq!(png.dimensions(), (24, 16));
    let red = png.pixels().filter(|p| p.0 == [255, 0, 0]).count();
    assert!(red > 24 * 16 / 2, "{red} red pixels");
    assert!(
        png.pixels()
            .all(|p| [[255, 0, 0], [32, 32, 32]].contains(&p.0))
    );
    // It needs the direct light to know what is indirect.
    let o = visgate(&["diff", &image, &reference, "--black-map", &map]);
    assert!(stderr(&o).contains("--direct"), "{}", stderr(&o));
}

#[test]
fn render_and_diff_refuse_bad_arguments_clearly() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("x.exr");
    let out = out.to_str().expect("utf-8");
    for (args, want) in [
        (vec!["--size", "0x10"], "1..=16384"),
        (vec!["--size", "abc"], "WIDTHxHEIGHT"),
        (vec!["--camera", "nope"], "no camera 'nope'"),
        (vec!["--bounces", "0"], "bounces"),
        (vec!["--spp", "0"], "samples per pixel"),
        (vec!["--g-max", "0"], "clamp"),
        (vec!["--clamp-distance", "0"], "fraction of the diagonal"),
        (
            vec!["--clamp-distance", "0.1", "--g-max", "3"],
            "cannot be used with",
        ),
    ] {
        let mut a = vec!["render", "builtin:cornell-box", "--out", out];
        if !args.contains(&"--size") {
            a.extend(["--size", "8x8"]);
        }
        a.extend(args.iter().copied());
        let o = visgate(&a);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(stderr(&o).contains(want), "{args:?}: {}", stderr(&o));
    }
    let o = visgate(&["render", "builtin:cornell-box", "--out", "x.jpg"]);
    assert!(stderr(&o).contains(".exr"), "{}", stderr(&o));
    let o = visgate(&["diff", "missing-a.exr", "missing-b.exr"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("missing-a.exr"), "{}", stderr(&o));
}

#[test]
fn render_gates_uses_a_baked_level_and_refuses_a_missing_or_stale_one() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = |n: &str| dir.path().join(n).to_str().expect("utf-8").to_string();
    let o = two_rooms_at_64(&p("two.vgate"), &["-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let base = [
        "render", "--mode", "gates", "--vpls", "64", "--size", "16x12", "--spp", "1",
    ];
    let mut a: Vec<&str> = base.to_vec();
    a.insert(1, "builtin:two-rooms");
    let out = p("g.exr");
    let level = p("two.vgate");
    a.extend(["--level", &level, "--out", &out]);
    // The default: the voxel walk (no clusters or lists, each VPL's end) in the balanced
    // setting, named in the frame's first line, with the dark pixels' pass.
    let o = visgate(&a);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("VPL walk ends"), "{}", stdout(&o));
    let balanced = "gates (voxel walk + triangles, 8×8 interleaved, tent blur, dark pixels walk \
                    the rest) 16x12";
    assert!(stdout(&o).contains(balanced), "{}", stdout(&o));
    assert!(stdout(&o).contains("starved pixels"), "{}", stdout(&o));
    assert!(!stdout(&o).contains("unique clusters"), "{}", stdout(&o));
    // The fast setting: the walk on the closed voxels' planes, the box blur, no second pass;
    // the rest below adds to it.
    a.push("--fast");
    let o = visgate(&a);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("gates (voxel walk, 8×8 interleaved) 16x12"),
        "{}",
        stdout(&o)
    );
    assert!(!stdout(&o).contains("starved pixels"), "{}", stdout(&o));
    // With the triangles in the closed voxels, named too, and the same room as bright (the
    // two rooms' walls are thick, so the walk sees what it saw).
    // The "mean radiance R G B" line's values.
    let radiance = |o: &std::process::Output| -> Vec<f32> {
        let out = stdout(o);
        let line = out.lines().find(|l| l.starts_with("mean radiance"));
        let values = line.expect("mean radiance").split_whitespace().skip(2);
        values.map(|x| x.parse().expect("a number")).collect()
    };
    let mut t = a.clone();
    t.push("--closed-voxel-triangles");
    let ot = visgate(&t);
    assert!(ot.status.success(), "{}", stderr(&ot));
    assert!(
        stdout(&ot).contains("gates (voxel walk + triangles, 8×8 interleaved) 16x12"),
        "{}",
        stdout(&ot)
    );
    let (plain, with) = (radiance(&o), radiance(&ot));
    assert_eq!(plain.len(), 3);
    for (x, y) in plain.iter().zip(&with) {
        assert!((x - y).abs() <= 0.02 * x.max(1e-3), "{plain:?} / {with:?}");
    }
    // The blur filled from the next blocks and the starved pixels' walks, named.
    let mut f = a.clone();
    f.extend(["--blur-fill", "--starved-taps", "40"]);
    let of = visgate(&f);
    assert!(of.status.success(), "{}", stderr(&of));
    let named = "gates (voxel walk, 8×8 interleaved, blur filled, under 40 agreeing walk the rest)";
    assert!(stdout(&of).contains(named), "{}", stdout(&of));
    assert!(stdout(&of).contains("starved pixels"), "{}", stdout(&of));
    // How many pixels were starved and the pairs they walked, counted.
    assert!(
        stdout(&of).contains("(pixel, subset) pairs (list of"),
        "{}",
        stdout(&of)
    );
    // An image too large for the pairs' pixel numbers is refused before anything is made.
    let mut big = f.clone();
    let size = big.iter().position(|x| *x == "--size").expect("size");
    big[size + 1] = "4097x4097";
    let ob = visgate(&big);
    assert!(!ob.status.success());
    assert!(
        stderr(&ob).contains("at most 16777216 pixels"),
        "{}",
        stderr(&ob)
    );
    // The roulette on the walks: on by default at 128 VPLs a pixel (8,192 in 8 × 8 blocks),
    // named as it acts; --walk-roulette 0 turns it off.
    let mut r = a.clone();
    let vpls = r.iter().position(|x| *x == "64").expect("vpls");
    r[vpls] = "8192";
    let or = visgate(&r);
    assert!(or.status.success(), "{}", stderr(&or));
    let named = "gates (voxel walk, 8×8 interleaved, roulette under 0.05 (auto)) 16x12";
    assert!(stdout(&or).contains(named), "{}", stdout(&or));
    r.extend(["--walk-roulette", "0"]);
    let or = visgate(&r);
    assert!(or.status.success(), "{}", stderr(&or));
    let named = "gates (voxel walk, 8×8 interleaved) 16x12";
    assert!(stdout(&or).contains(named), "{}", stdout(&or));
    a.extend(["--gate-shape", "portal"]);
    let o = visgate(&a);
    assert!(o.status.success(), "{}", stderr(&o));
    // Portals: the passes are named as the paper's Table I, with the lists' fill.
    for pass in [
        "geometry pass",
        "unique clusters",
        "light assignment",
        "indirect lighting",
        "light lists:",
    ] {
        assert!(stdout(&o).contains(pass), "{pass}: {}", stdout(&o));
    }
    // A pool too small (disks keep lists; portals none): the error names the setting and
    // what it needs.
    let mut small = a.clone();
    *small.last_mut().expect("shape") = "disk";
    small.extend(["--light-entries", "10"]);
    let o = visgate(&small);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("raise --light-entries"),
        "{}",
        stderr(&o)
    );
    let mut brute = a.clone();
    brute[3] = "gates-per-pixel";
    let o = visgate(&brute);
    assert!(o.status.success(), "{}", stderr(&o));
    brute.push("--cpu");
    let o = visgate(&brute);
    assert!(stderr(&o).contains("--mode gates --cpu"), "{}", stderr(&o));
    // The voxel walk: no clusters or lists, each VPL's end, on the GPU and its CPU twin.
    let mut voxels = a.clone();
    *voxels.last_mut().expect("shape") = "voxels";
    let o = visgate(&voxels);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("VPL walk ends"), "{}", stdout(&o));
    assert!(!stdout(&o).contains("unique clusters"), "{}", stdout(&o));
    voxels.push("--cpu");
    let o = visgate(&voxels);
    assert!(o.status.success(), "{}", stderr(&o));
    a.push("--cpu");
    let o = visgate(&a);
    assert!(o.status.success(), "{}", stderr(&o));
    // No level: a clear message.
    let o = visgate(&[
        "render",
        "builtin:two-rooms",
        "--mode",
        "gates",
        "--out",
        &out,
    ]);
    assert!(stderr(&o).contains("--level"), "{}", stderr(&o));
    // A level from other geometry: re-bake.
    let o = visgate(&[
        "render",
        "builtin:four-rooms",
        "--mode",
        "gates",
        "--level",
        &level,
        "--out",
        &out,
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("re-bake"), "{}", stderr(&o));
}

#[test]
fn render_val_modes_print_their_passes_and_refuse_bad_settings() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("v.exr");
    let out = out.to_str().expect("utf-8");
    let base = [
        "render",
        "builtin:cornell-box",
        "--vpls",
        "128",
        "--size",
        "32x24",
        "--vals",
        "8",
        "--out",
        out,
    ];
    for (mode, passes) in [
        (
            "val-cssm",
            &[
                "VAL clustering",
                "VAL paraboloid maps",
                "CSSM basis",
                "blur + compose",
            ][..],
        ),
        ("val-hard", &["VAL clustering", "indirect lighting"][..]),
    ] {
        // Both VPL sources feed the VAL modes.
        let mut rsm = base.to_vec();
        rsm.extend(["--mode", mode, "--vpl-source", "rsm"]);
        let o = visgate(&rsm);
        assert!(o.status.success(), "{mode} rsm: {}", stderr(&o));
        assert!(stdout(&o).contains("Rsm"), "{}", stdout(&o));
        let mut a = base.to_vec();
        a.extend(["--mode", mode]);
        let o = visgate(&a);
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        for p in passes {
            assert!(stdout(&o).contains(p), "{mode} {p}: {}", stdout(&o));
        }
        for (flag, value, says) in [
            ("--vals", "0", "VALs 0"),
            ("--interleave", "0", "interleaving block 0"),
            ("--starved-taps", "65", "starved taps 65"),
            ("--cssm-terms", "0", "terms 0"),
        ] {
            if flag == "--cssm-terms" && mode == "val-hard" {
                continue;
            }
            let mut bad = a.clone();
            if let Some(i) = bad.iter().position(|x| *x == flag) {
                bad[i + 1] = value;
            } else {
                bad.extend([flag, value]);
            }
            let o = visgate(&bad);
            assert!(!o.status.success(), "{mode} {flag} {value}");
            assert!(stderr(&o).contains(says), "{mode} {flag}: {}", stderr(&o));
        }
        let mut cpu = a.clone();
        cpu.push("--cpu");
        let o = visgate(&cpu);
        assert!(stderr(&o).contains("--mode reference"), "{}", stderr(&o));
    }
}

#[test]
fn render_frames_of_a_dynamic_scene_pose_meshes_and_lights() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = |n: &str| dir.path().join(n);
    // A floor and a small box that slides across it, lit by a light on an orbit.
    let scene = support::dynamic_scene(dir.path());
    let out = p("shot.png");
    for mode in ["val-hard", "none", "reference"] {
        let o = visgate(&[
            "render",
            scene.to_str().expect("utf-8"),
            "--mode",
            mode,
            "--frames",
            "3",
            "--fps",
            "1",
            "--size",
            "32x24",
            "--spp",
            "1",
            "--vpls",
            "64",
            "--out",
            out.to_str().expect("utf-8"),
        ]);
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        assert!(
            stdout(&o).contains("frame 3 of 3 at t = 2.000 s"),
            "{}",
            stdout(&o)
        );
        let frames: Vec<Vec<u8>> = (0..3)
            .map(|f| std::fs::read(p(&format!("shot-{f:04}.png"))).expect("frame written"))
            .collect();
        assert!(
            frames[0] != frames[1] && frames[1] != frames[2],
            "{mode}: frames differ"
        );
    }
    let o = visgate(&[
        "render",
        scene.to_str().expect("utf-8"),
        "--frames",
        "0",
        "--out",
        "x.png",
    ]);
    assert!(stderr(&o).contains("--frames 0"), "{}", stderr(&o));
}

#[test]
fn a_reader_that_goes_away_ends_visgate_quietly() {
    use std::io::Read;
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_visgate"))
        .args(["inspect", "builtin:four-rooms"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    // Close the pipe before visgate writes (it builds the scene first): its prints fail.
    drop(child.stdout.take());
    let status = child.wait().expect("wait");
    let mut err = String::new();
    child
        .stderr
        .take()
        .expect("stderr")
        .read_to_string(&mut err)
        .expect("read");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(status.code(), Some(141), "{err}");
}
