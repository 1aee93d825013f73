//! `visgate compare`: the report holds every table, the plot and the panels; its figures are
//! those `visgate render` + `visgate diff` give on the same settings; a second run resumes.

mod support;

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

fn visgate(args: &[&str]) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_visgate"))
        .args(args)
        .env("RUST_LOG", "error")
        .output()
        .expect("runs visgate");
    assert!(
        o.status.success(),
        "visgate {args:?} failed:\n{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The number after `label` on its line of `text`.
fn figure(text: &str, label: &str) -> f64 {
    let line = text
        .lines()
        .find(|l| l.starts_with(label))
        .unwrap_or_else(|| panic!("no '{label}' in:\n{text}"));
    line[label.len()..]
        .split_whitespace()
        .next()
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no number in '{line}'"))
}

/// Equal to the digits `diff` prints: six significant digits, FLIP five decimals.
fn close(a: f64, b: f64, what: &str) {
    let printed = if what == "FLIP" { 6e-6 } else { 1e-12 };
    assert!(
        (a - b).abs() <= 1e-5 * a.abs().max(b.abs()) + printed,
        "{what}: compare {a} vs render + diff {b}"
    );
}

const SETTINGS: [&str; 6] = ["--size", "48x36", "--spp", "1", "--camera", "main"];

#[test]
fn the_report_holds_every_table_plot_and_panel_with_the_figures_of_render_and_diff() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("cmp");
    let out_s = out.to_str().expect("utf-8");
    let args = [
        "compare",
        "builtin:two-rooms",
        "--modes",
        "none,val-hard",
        "--vpls",
        "16,64",
        "--size",
        "48x36",
        "--spp",
        "1",
        "--cameras",
        "main",
        "--budget-ms",
        "100000",
        "--out",
        out_s,
    ];
    let first = stdout(&visgate(&args));
    assert!(first.contains("8 renders made, 0 read back"), "{first}");
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("json"))
            .expect("parses");
    let rows = json["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 4, "2 modes × 2 VPL counts × 1 camera");
    assert_eq!(json["references"][0]["mixed_share"].as_f64(), Some(0.0));
    assert!(json["references"][0]["mixed_map"].is_null());
    let md = std::fs::read_to_string(out.join("report.md")).expect("md");
    let html = std::fs::read_to_string(out.join("report.html")).expect("html");
    assert!(md.contains("## Camera main") && md.contains("| mode | settings | VPLs |"));
    assert!(md.contains("![Pareto plot](pareto.png)") && html.contains("src=\"pareto.png\""));
    assert!(md.contains("**Answer (budget)**"), "{md}");
    let plot = image::open(out.join("pareto.png")).expect("plot").to_rgb8();
    assert_eq!(plot.dimensions(), (960, 640));
    let ink = plot.pixels().filter(|p| p.0 != [255, 255, 255]).count();
    assert!(ink > 10_000, "the plot is blank: {ink} pixels drawn");
    for r in rows {
        let panel = r["panel"].as_str().expect("panel");
        assert!(
            md.contains(panel) && html.contains(panel),
            "{panel} not in the report"
        );
        let p = image::open(out.join(panel)).expect("panel jpeg").to_rgb8();
        // Reference | method | FLIP | black where lit, 6 pixels apart.
        assert_eq!(p.dimensions(), (4 * 48 + 18, 36 + 44));
        // The black map's tile holds only its three greys and red (JPEG: near them).
        let tile = image::imageops::crop_imm(&p, 3 * 54, 44, 48, 36).to_image();
        let known = |c: [u8; 3]| {
            [[32, 32, 32], [150, 150, 150], [255, 0, 0]]
                .iter()
                .any(|k| (0..3).all(|i| c[i].abs_diff(k[i]) < 40))
        };
        let off = tile.pixels().filter(|px| !known(px.0)).count();
        assert!(
            off < 48 * 36 / 10,
            "{off} pixels of the black map are no class's colour"
        );
        let cells = [
            "mode",
            "total_ms",
            "mse",
            "indirect_mse",
            "rel_mse",
            "flip",
            "energy_ratio",
        ];
        assert!(cells.iter().all(|c| !r[c].is_null()), "{r}");
        // One sample a pixel: no pixel is mixed, the two black-where-lit shares agree.
        assert_eq!(r["black_where_lit"], r["black_where_lit_all"], "{r}");
        assert_eq!(
            md.matches(&format!("| {} |", r["mode"].as_str().expect("mode")))
                .count(),
            2
        );
    }
    // The same settings through render + diff give the same figures.
    let p = |n: &str| dir.path().join(n).to_str().expect("utf-8").to_string();
    let render = |mode: &str, vpls: &str, out: &str, cpu: bool| {
        let mut a = vec![
            "render",
            "builtin:two-rooms",
            "--mode",
            mode,
            "--vpls",
            vpls,
            "--out",
            out,
        ];
        a.extend(SETTINGS);
        if cpu {
            a.push("--cpu");
        }
        visgate(&a);
    };
    render("val-hard", "64", &p("m.exr"), false);
    render("reference", "64", &p("r.exr"), false);
    render("direct-only", "64", &p("d.exr"), true);
    render("direct-only", "64", &p("dg.exr"), false);
    let diff = stdout(&visgate(&[
        "diff",
        &p("m.exr"),
        &p("r.exr"),
        "--direct",
        &p("d.exr"),
        "--image-direct",
        &p("dg.exr"),
    ]));
    let row = rows
        .iter()
        .find(|r| r["mode"] == "val-hard" && r["vpls"] == 64)
        .expect("val-hard at 64");
    let f = |k: &str| row[k].as_f64().expect("number");
    close(f("mse"), figure(&diff, "MSE"), "MSE");
    close(f("rel_mse"), figure(&diff, "rel. MSE"), "rel. MSE");
    close(
        f("indirect_mse"),
        figure(&diff, "indirect MSE"),
        "indirect MSE",
    );
    close(f("flip"), figure(&diff, "FLIP mean"), "FLIP");
    close(
        f("energy_ratio"),
        figure(&diff, "indirect energy"),
        "energy",
    );
    close(
        f("black_where_lit") * 100.0,
        figure(&diff, "black where lit"),
        "black where lit",
    );
    // Stopped or not, a second run reads every render back.
    let again = stdout(&visgate(&args));
    assert!(again.contains("0 renders made, 8 read back"), "{again}");
    // A changed setting redoes only the renders it touches (the VAL count: val-hard).
    let mut more = args.to_vec();
    more.extend(["--vals", "8"]);
    let changed = stdout(&visgate(&more));
    assert!(changed.contains("2 renders made, 6 read back"), "{changed}");
}

#[test]
fn with_several_samples_a_pixel_the_mixed_pixels_are_left_out_of_black_where_lit() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("cmp");
    let args = [
        "compare",
        "builtin:two-rooms",
        "--modes",
        "none,val-hard",
        "--vpls",
        "16",
        "--size",
        "48x36",
        "--spp",
        "4",
        "--cameras",
        "main",
        "--out",
        out.to_str().expect("utf-8"),
    ];
    visgate(&args);
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("json"))
            .expect("parses");
    // The room's corners and the door's edges: a few percent of the pixels.
    let share = json["references"][0]["mixed_share"]
        .as_f64()
        .expect("share");
    assert!(share > 0.01 && share < 0.3, "{share}");
    // Those pixels white in a map of their own, named in the report.
    let map = json["references"][0]["mixed_map"].as_str().expect("map");
    let white = image::open(out.join(map)).expect("map png").to_luma8();
    let n = white.pixels().filter(|p| p.0[0] == 255).count();
    assert_eq!(n, (share * 48.0 * 36.0).round() as usize);
    let md = std::fs::read_to_string(out.join("report.md")).expect("md");
    assert!(
        md.contains("of its pixels mixed, seeing several surfaces"),
        "{md}"
    );
    assert!(md.contains(map), "{md}");
    for r in json["rows"].as_array().expect("rows") {
        let (b, all) = (
            r["black_where_lit"].as_f64().expect("share"),
            r["black_where_lit_all"].as_f64().expect("share"),
        );
        assert!(
            (0.0..=1.0).contains(&b) && (0.0..=1.0).contains(&all),
            "{r}"
        );
        // `diff` on the same renders with the map gives both figures.
        let at = |f: &str| {
            let p = out.join("renders").join("main").join(f);
            p.to_str().expect("utf-8").to_string()
        };
        let image = format!("{}-16.exr", r["mode"].as_str().expect("mode"));
        let printed = stdout(&visgate(&[
            "diff",
            &at(&image),
            &at("reference-16.exr"),
            "--direct",
            &at("direct-cpu.exr"),
            "--image-direct",
            &at("direct-gpu.exr"),
            "--mixed",
            &at("mixed.png"),
        ]));
        close(
            b * 100.0,
            figure(&printed, "black where lit"),
            "black where lit",
        );
        let every = printed
            .split("left out; ")
            .nth(1)
            .expect("every pixel's share");
        close(all * 100.0, figure(every, ""), "over every pixel");
    }
}

#[test]
fn an_animated_scene_gets_a_stability_table_and_bad_requests_are_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = support::dynamic_scene(dir.path());
    let out = dir.path().join("cmp");
    let s = |p: &Path| p.to_str().expect("utf-8").to_string();
    let (scene, out) = (s(&scene), s(&out));
    let base = [
        "compare", &scene, "--vpls", "32", "--size", "32x24", "--spp", "1",
    ];
    let mut args = base.to_vec();
    args.extend([
        "--modes",
        "none,val-hard",
        "--variant",
        "val-hard-warm=val-hard --val-warm-start",
        "--stability-frames",
        "3",
        "--out",
        &out,
    ]);
    visgate(&args);
    let json: Value = serde_json::from_str(
        &std::fs::read_to_string(Path::new(&out).join("report.json")).expect("json"),
    )
    .expect("parses");
    let st = json["stability"].as_array().expect("stability");
    assert_eq!(st.len(), 3, "{st:?}");
    // The VAL rows count their live VALs over the sequence (of the 30 asked for).
    for r in st {
        let live = &r["live_vals"];
        match r["mode"].as_str() {
            Some("none") => assert!(live.is_null(), "{r}"),
            _ => {
                let (mean, min) = (live["mean"].as_f64(), live["min"].as_u64());
                assert_eq!(live["count"], 30, "{r}");
                assert!(
                    min.is_some_and(|m| m >= 1) && mean.is_some_and(|m| m <= 30.0),
                    "{r}"
                );
                assert!(mean >= min.map(|m| m as f64), "{r}");
            }
        }
    }
    for r in st {
        let (c, rc) = (r["change"].as_f64(), r["reference_change"].as_f64());
        assert!(
            c.is_some_and(|c| c > 0.0) && rc.is_some_and(|c| c > 0.0),
            "{r}"
        );
        assert_eq!(r["frames"], 3);
    }
    let md = std::fs::read_to_string(Path::new(&out).join("report.md")).expect("md");
    assert!(md.contains("## Temporal stability") && md.contains("live VALs"));
    // The warm start is the variant's setting only.
    let rows = json["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 3, "{rows:?}");
    let settings = |mode: &str| {
        let r = rows.iter().find(|r| r["mode"] == mode).expect("row");
        r["settings"].as_str().expect("settings").to_string()
    };
    assert!(settings("val-hard-warm").contains("warm start"));
    assert!(!settings("val-hard").contains("warm start"));
    // Bad requests say what to give.
    for (extra, says) in [
        (vec!["--modes", "nope"], "gates-disk"),
        (vec!["--vpls", "0"], "--vpls"),
        (vec!["--cameras", "nowhere"], "no camera 'nowhere'"),
        (
            vec!["--modes", "gates", "--level", "/no/such.vgate"],
            "cannot read the level",
        ),
    ] {
        let mut a = base.to_vec();
        a.extend(extra);
        a.extend(["--out", &out]);
        let o = Command::new(env!("CARGO_BIN_EXE_visgate"))
            .args(&a)
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(says), "{a:?}: {err}");
    }
}

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
    // At 16,384 VPLs gates' auto roulette is gates-roulette's share: one frame, two rows; at
    // 64 it is off, and gates-roulette renders its own.
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
        "64,16384",
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
    let (g, r) = (row("gates", 16384), row("gates-roulette", 16384));
    let settings = r["settings"].as_str().expect("settings");
    assert!(settings.contains("the frame of gates"), "{settings}");
    assert_eq!(g["indirect_mse"], r["indirect_mse"]);
    assert_eq!(g["image"], r["image"]);
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
