//! The Mitsuba export, VAL counts, LightCluster sweeps, variants, and a mode that renders another's frame.

use super::*;

#[test]
fn the_mitsuba_export_spells_out_visgates_conventions() {
    let dir = tempfile::tempdir().expect("tempdir");
    let w = |n: &str, t: &[u8]| std::fs::write(dir.path().join(n), t).expect("write");
    // A textured quad (2 × 2 texels), a spot light and a camera.
    w(
        "quad.obj",
        b"mtllib quad.mtl\nv 0 0 0\nv 2 0 0\nv 2 0 2\nv 0 0 2\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
          usemtl tiles\nf 1/1 4/4 3/3 2/2\n",
    );
    w(
        "quad.mtl",
        b"newmtl tiles\nKd 0.5 0.5 0.5\nmap_Kd tiles.png\n",
    );
    let mut tex = image::RgbaImage::new(2, 2);
    tex.put_pixel(0, 0, image::Rgba([255, 128, 0, 255]));
    tex.save(dir.path().join("tiles.png")).expect("png");
    w(
        "scene.toml",
        br#"
[[mesh]]
path = "quad.obj"

[[light]]
type = "spot"
position = [1, 2, 1]
target = [1, 0, 1]
cutoff_deg = 40
beam_deg = 30
intensity = [5, 5, 5]

[[camera]]
name = "top"
eye = [1, 3, 3]
target = [1, 0, 1]
fov_deg = 60
"#,
    );
    let out = dir.path().join("mi");
    let s = |p: &Path| p.to_str().expect("utf-8").to_string();
    let printed = stdout(&visgate(&[
        "export",
        "mitsuba",
        &s(&dir.path().join("scene.toml")),
        &s(&out),
        "--size",
        "64x48",
        "--spp",
        "16",
    ]));
    assert!(
        printed.contains("1 shapes, 1 textures; sensors in order: top"),
        "{printed}"
    );
    let xml = std::fs::read_to_string(out.join("scene.xml")).expect("xml");
    for want in [
        "<integer name=\"max_depth\" value=\"3\"/>",
        "<integer name=\"rr_depth\" value=\"4\"/>",
        "<string name=\"fov_axis\" value=\"x\"/>",
        "<float name=\"fov\" value=\"60",
        "<rfilter type=\"box\"/>",
        "<integer name=\"width\" value=\"64\"/>",
        "<integer name=\"sample_count\" value=\"16\"/>",
        "<bsdf type=\"twosided\" id=\"mat0\">",
        "<string name=\"filter_type\" value=\"nearest\"/>",
        "<emitter type=\"spot\">",
        "<float name=\"cutoff_angle\" value=\"40",
        "<float name=\"beam_width\" value=\"30",
        "<rgb name=\"intensity\" value=\"5, 5, 5\"/>",
    ] {
        assert!(xml.contains(want), "no {want} in:\n{xml}");
    }
    // The texture is the albedo × the sRGB-decoded texels, linear.
    let t = image::open(out.join("textures/mat0.exr"))
        .expect("exr")
        .to_rgb32f();
    let p = t.get_pixel(0, 0).0;
    let want = [0.5, 0.5 * 0.2158605, 0.0];
    assert!(
        p.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-4),
        "{p:?}"
    );
    // One OBJ: the quad's two triangles, a normal and texture coordinates (in OBJ's convention)
    // with every vertex.
    let obj = std::fs::read_to_string(out.join("meshes/0-0.obj")).expect("obj");
    let count = |p: &str| obj.lines().filter(|l| l.starts_with(p)).count();
    assert_eq!(count("f "), 2, "{obj}");
    assert!(count("v ") >= 4 && count("vn ") == count("v ") && count("vt ") == count("v "));
    assert!(
        obj.contains("vt 0 0\n") && obj.contains("vt 1 1\n"),
        "{obj}"
    );
    // Bad requests say what to give.
    let o = Command::new(env!("CARGO_BIN_EXE_visgate"))
        .args([
            "export",
            "mitsuba",
            "builtin:cornell-box",
            &s(&out),
            "--max-depth",
            "1",
        ])
        .output()
        .expect("runs");
    assert!(
        !o.status.success() && String::from_utf8_lossy(&o.stderr).contains("--max-depth"),
        "{o:?}"
    );
}

#[test]
fn val_counts_compare_each_val_mode_at_each_count() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("vals");
    let out_s = out.to_str().expect("utf-8");
    visgate(&[
        "compare",
        "builtin:cornell-box",
        "--modes",
        "none,val-hard",
        "--val-counts",
        "2,30",
        "--vpls",
        "256",
        "--size",
        "40x30",
        "--spp",
        "1",
        "--out",
        out_s,
    ]);
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("json"))
            .expect("parses");
    let rows = report["rows"].as_array().expect("rows");
    let row = |mode: &str| {
        rows.iter()
            .find(|r| r["mode"] == mode)
            .unwrap_or_else(|| panic!("no row {mode}: {rows:?}"))
    };
    assert_eq!(rows.len(), 3, "none, val-hard at M = 2 and 30");
    let (m2, m30) = (row("val-hard-m2"), row("val-hard-m30"));
    assert!(
        m2["settings"]
            .as_str()
            .expect("settings")
            .starts_with("2 VALs")
    );
    assert!(
        m30["settings"]
            .as_str()
            .expect("settings")
            .starts_with("30 VALs")
    );
    // Two VALs for a whole room cast coarser shadows: a larger error.
    let e = |r: &Value| r["indirect_mse"].as_f64().expect("error");
    assert!(e(m2) > e(m30), "M = 2 {} vs M = 30 {}", e(m2), e(m30));
    // The mode without VALs is not split by --val-counts.
    assert!(rows.iter().filter(|r| r["mode"] == "none").count() == 1);
    // A count out of range is refused with the limit.
    let o = Command::new(env!("CARGO_BIN_EXE_visgate"))
        .args([
            "compare",
            "builtin:cornell-box",
            "--modes",
            "val-hard",
            "--val-counts",
            "0",
            "--out",
            out_s,
        ])
        .output()
        .expect("runs");
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--val-counts 0"));
}

#[test]
fn lightcluster_sweeps_beside_each_modes_own_shadow_maps() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("lc");
    let args = [
        "compare",
        "builtin:lamp-hall",
        "--modes",
        "direct-only",
        "--vpls",
        "1",
        "--lc-min-distances",
        "0,2",
        "--metric",
        "mse",
        "--size",
        "48x32",
        "--spp",
        "1",
        "--cameras",
        "main",
        "--out",
        out.to_str().expect("utf-8"),
    ];
    let o = visgate(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("json"))
            .expect("parses");
    let rows = json["rows"].as_array().expect("rows");
    let labels: Vec<&str> = rows.iter().filter_map(|r| r["mode"].as_str()).collect();
    assert_eq!(
        labels,
        ["direct-only", "direct-only-lc0", "direct-only-lc2"],
        "{json}"
    );
    for r in &rows[1..] {
        let settings = r["settings"].as_str().expect("settings");
        assert!(settings.contains("clusters of 51 lights"), "{settings}");
        // Direct light alone is measured against the reference's direct light: per light and
        // every lamp its own cluster keep it.
        let energy = r["energy_ratio"].as_f64().expect("energy");
        assert!(energy > 0.5 && energy < 1.1, "{settings}: {energy}");
    }
    let own = rows[0]["energy_ratio"].as_f64().expect("energy");
    assert!((own - 1.0).abs() < 0.02, "per light: {own}");
}

#[test]
fn variants_are_rows_of_a_mode_with_the_runs_settings_and_their_own_flags() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("variants");
    let out_s = out.to_str().expect("utf-8");
    let base = [
        "compare",
        "builtin:two-rooms",
        "--bake-resolution",
        "32",
        "--vpls",
        "64",
        "--size",
        "40x30",
        "--spp",
        "1",
        "--gate-shape",
        "disk",
        "--gate-hops",
        "1",
        "--out",
        out_s,
    ];
    let mut a = base.to_vec();
    a.extend([
        "--modes",
        "gates",
        "--variant",
        "gates-2hops=gates --gate-hops 2",
        "--variant",
        "gates-wide=gates --gate-hops 2 --gate-oversize 2",
    ]);
    visgate(&a);
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("json"))
            .expect("parses");
    let rows = report["rows"].as_array().expect("rows");
    let settings = |mode: &str| {
        let r = rows.iter().find(|r| r["mode"] == mode);
        let r = r.unwrap_or_else(|| panic!("no row {mode}: {rows:?}"));
        r["settings"].as_str().expect("settings").to_string()
    };
    // The run's own --gate-hops 1 for the mode, the variants' flags replacing it in theirs,
    // and the run's --gate-shape disk kept in both.
    let (one, two, wide) = (
        settings("gates"),
        settings("gates-2hops"),
        settings("gates-wide"),
    );
    assert!(one.contains("disks ×1, 1 hop(s)"), "{one}");
    assert!(two.contains("disks ×1, 2 hop(s)"), "{two}");
    assert!(wide.contains("disks ×2, 2 hop(s)"), "{wide}");
    // The report's command runs again as given: each variant one word for a shell.
    let command = report["command"].as_str().expect("command");
    assert!(
        command.contains(" --variant 'gates-2hops=gates --gate-hops 2' --variant"),
        "{command}"
    );
    // Badly written variants are refused, saying how to write one.
    for (variant, says) in [
        ("gates --gate-hops 2", "LABEL=MODE"),
        ("x=", "no mode"),
        ("x=nope", "gates-disk"),
        ("x=gates --gate-hops banana", "--variant x"),
        ("gates=gates --gate-hops 2", "two rows are labelled gates"),
    ] {
        let mut b = base.to_vec();
        b.extend(["--modes", "gates", "--variant", variant]);
        let o = Command::new(env!("CARGO_BIN_EXE_visgate"))
            .args(&b)
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && err.contains(says),
            "{variant}: {err}"
        );
    }
}

#[test]
fn a_mode_that_renders_another_s_frame_takes_its_row_instead_of_a_second_render() {
    // At 16,384 VPLs gates' auto roulette is gates-roulette's share: one frame, two rows; so
    // at 2,048, where the balanced setting's blur takes the ratio estimator (the near field
    // and the estimator kept beside the roulette, in both); at 64 it is off, and
    // gates-roulette renders its own.
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("same");
    visgate(&[
        "compare",
        "builtin:two-rooms",
        "--bake-resolution",
        "32",
        "--modes",
        "gates,gates-roulette",
        "--vpls",
        "64,2048,16384",
        "--size",
        "24x18",
        "--spp",
        "1",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("json"))
            .expect("parses");
    let rows = report["rows"].as_array().expect("rows");
    let row = |mode: &str, vpls: u64| {
        rows.iter()
            .find(|r| r["camera"] == "main" && r["mode"] == mode && r["vpls"] == vpls)
            .unwrap_or_else(|| panic!("no row {mode} at {vpls}: {rows:?}"))
    };
    for vpls in [2048, 16384] {
        let (g, r) = (row("gates", vpls), row("gates-roulette", vpls));
        let settings = r["settings"].as_str().expect("settings");
        assert!(
            settings.contains("the frame of gates"),
            "{vpls}: {settings}"
        );
        assert_eq!(g["indirect_mse"], r["indirect_mse"]);
        assert_eq!(g["image"], r["image"]);
    }
    let settings = row("gates", 2048)["settings"].as_str().expect("settings");
    assert!(
        settings.contains("ratio estimator (grid 3 px), roulette under 0.05 (auto)"),
        "{settings}"
    );
    let (g, r) = (row("gates", 64), row("gates-roulette", 64));
    assert!(
        !r["settings"]
            .as_str()
            .expect("settings")
            .contains("the frame of")
    );
    assert_ne!(g["image"], r["image"]);
    // No image of its own for the shared frame.
    let renders = out.join("renders").join("main");
    let files: Vec<String> = std::fs::read_dir(&renders)
        .expect("renders of camera main")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        files.iter().any(|f| f.contains("gates-roulette-64"))
            && !files.iter().any(|f| f.contains("gates-roulette-16384")),
        "{files:?}"
    );
}
