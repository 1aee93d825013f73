//! visgate bake: its report, debug exports, leaks, warnings and refusals.

use super::*;

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
    // Into a pipe or a log file, without the terminal's colour codes (they were written as
    // `\x1b[33m WARN\x1b[0m` whatever stderr was).
    assert!(!stderr(&o).contains('\x1b'), "{:?}", stderr(&o));
}

#[test]
fn a_triangle_far_from_the_level_is_left_out_of_a_bare_mesh_and_named_in_a_scene_file() {
    // The leaky room's mesh (8 m long) with one triangle 500 m away, as an exporter leaves a
    // helper behind. Read bare, it is left out, said so, and the bake is the room's alone; kept
    // (--keep-far) or named in a scene TOML, the grid spans it, so the bake says where it is
    // and by how much it grew the voxels. The room alone says nothing of it.
    let dir = tempfile::tempdir().expect("tempdir");
    let toml = leaky_room(dir.path());
    let mesh = dir.path().join("room.obj");
    let out = dir.path().join("l.vgate");
    let (m, o) = (mesh.to_str().expect("utf-8"), out.to_str().expect("utf-8"));
    let bake = ["bake", m, "--resolution", "32", "-o", o];
    let clean = visgate(&bake);
    assert!(clean.status.success(), "{}", stderr(&clean));
    assert!(
        !stderr(&clean).contains("far from the rest"),
        "{}",
        stderr(&clean)
    );
    let mut obj = std::fs::read_to_string(&mesh).expect("obj");
    obj += "v 500 0 0\nv 501 0 0\nv 500 1 0\nf -3 -2 -1\n";
    std::fs::write(&mesh, obj).expect("obj");
    let left_out = support::visgate_warn(&bake);
    assert!(left_out.status.success(), "{}", stderr(&left_out));
    let said = "1 of its 21 triangles lies far from the rest, the farthest corner at (501.00, \
                0.00, 0.00) in the file, 493.0 m from the rest's bounds: left out of the level. \
                With them it would be 501.0 m long where the rest is 8.00 m";
    assert!(stderr(&left_out).contains(said), "{}", stderr(&left_out));
    // The same grid and partition as the room's alone.
    let summary = |o: &std::process::Output| -> Vec<String> {
        (stdout(o).lines())
            .filter(|l| l.starts_with("grid ") || l.starts_with("clusters "))
            .map(String::from)
            .collect()
    };
    assert_eq!(summary(&left_out), summary(&clean));
    let said = "1 of the level's 21 static triangles lies far from the rest, the farthest corner \
                at (501.00, 0.00, 0.00) m, 493 m from the rest's bounds. The grid spans them, a \
                501.0 m level where the rest is 8.00 m long, so its voxels are 63× as large";
    let keep = visgate(&["bake", m, "--keep-far", "--resolution", "32", "-o", o]);
    assert!(keep.status.success(), "{}", stderr(&keep));
    assert!(stderr(&keep).contains(said), "{}", stderr(&keep));
    let t = toml.to_str().expect("utf-8");
    // (The leaky room's TOML says it is closed: its window leaks.)
    let described = visgate(&["bake", t, "--allow-leaks", "--resolution", "32", "-o", o]);
    assert!(described.status.success(), "{}", stderr(&described));
    assert!(stderr(&described).contains(said), "{}", stderr(&described));
}

#[test]
fn a_flat_mesh_is_refused_as_no_level() {
    // One ground triangle, as a bare file: its grid is a voxel thick, and the bake said that it
    // was too coarse and to bake at --resolution 768 (a quad on its side: every voxel solid,
    // and a voxel of 1 mm). A plane encloses no space at any resolution; it says so.
    let dir = tempfile::tempdir().expect("tempdir");
    for (name, obj) in [
        ("ground.obj", "v 0 0 0\nv 10 0 0\nv 0 0 10\nf 1 2 3\n"),
        (
            "wall.obj",
            "v 0 0 0\nv 4 0 0\nv 4 3 0\nv 0 3 0\nf 1 2 3 4\n",
        ),
    ] {
        let mesh = dir.path().join(name);
        std::fs::write(&mesh, obj).expect("obj");
        let out = dir.path().join("l.vgate");
        let (m, o) = (mesh.to_str().expect("utf-8"), out.to_str().expect("utf-8"));
        let r = visgate(&["bake", m, "-o", o]);
        assert!(!r.status.success(), "{name}: {}", stdout(&r));
        let err = stderr(&r);
        assert!(
            err.contains("the level is flat") && err.contains("encloses no space"),
            "{name}: {err}"
        );
        assert!(
            !err.contains("--resolution 7") && !out.exists(),
            "{name}: {err}"
        );
    }
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
    // An output's folder is made where it is not there; one that cannot be made (a file
    // stands at its name) is refused before the bake, not after it.
    let made = dir.path().join("new-folder").join("x.vgate");
    let made = made.to_str().expect("utf-8");
    let o = visgate(&[
        "bake",
        "builtin:two-rooms",
        "-o",
        made,
        "--resolution",
        "32",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(Path::new(made).is_file());
    let lost = support::under_a_file(dir.path(), "x.vgate");
    let lost = lost.as_str();
    for (flag, args) in [
        ("-o", vec!["-o", lost]),
        ("--report", vec!["-o", out, "--report", lost]),
    ] {
        let o = visgate(&[&["bake", "builtin:two-rooms"], &args[..]].concat());
        assert!(!o.status.success());
        let want = format!("{flag} {lost}: cannot make its folder");
        assert!(stderr(&o).contains(&want), "{}", stderr(&o));
        assert!(!stdout(&o).contains("bake of"), "it baked: {}", stdout(&o));
    }
    // A level that cannot be read says so once, the file's name with it.
    let missing = dir.path().join("missing.vgate");
    let missing = missing.to_str().expect("utf-8");
    let o = visgate(&["inspect", missing]);
    assert!(!o.status.success());
    let image = dir.path().join("x.png");
    let image = image.to_str().expect("utf-8");
    let o = visgate(&[
        "render",
        "builtin:two-rooms",
        "--mode",
        "gates",
        "--level",
        missing,
        "--out",
        image,
    ]);
    let err = stderr(&o);
    assert!(
        err.contains(&format!("cannot read the level {missing}: ")),
        "{err}"
    );
    assert_eq!(err.matches("os error").count(), 1, "{err}");
    assert_eq!(err.matches(missing).count(), 1, "{err}");
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
