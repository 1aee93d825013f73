//! The report's tables, plot and panels against render and diff; mixed pixels; an animated scene's stability table; bad requests.

use super::*;

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
    // A render kept by another build of visgate is made again (its key names the build).
    let kept = out.join("renders").join("main").join("none-16.json");
    let text = std::fs::read_to_string(&kept).expect("kept render");
    assert!(text.contains("|visgate "), "{text}");
    std::fs::write(&kept, text.replace("|visgate ", "|an older visgate ")).expect("write");
    let rebuilt = stdout(&visgate(&args));
    assert!(rebuilt.contains("1 renders made, 7 read back"), "{rebuilt}");
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
