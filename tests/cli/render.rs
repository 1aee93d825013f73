//! visgate render and diff: images, gates with a baked level, the VAL modes, dynamic scenes.

use super::*;

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
    // An image whose folder cannot be made (a file stands at its name) is refused before
    // the render, not after it.
    let lost = support::under_a_file(dir.path(), "x.png");
    let lost = lost.as_str();
    let o = visgate(&[
        "render",
        "builtin:cornell-box",
        "--size",
        "8x8",
        "--out",
        lost,
    ]);
    assert!(!o.status.success());
    let want = format!("--out {lost}: cannot make its folder");
    assert!(stderr(&o).contains(&want), "{}", stderr(&o));
    assert!(
        !stdout(&o).contains("mean radiance"),
        "it rendered: {}",
        stdout(&o)
    );
    let o = visgate(&["diff", "missing-a.exr", "missing-b.exr"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("missing-a.exr"), "{}", stderr(&o));
    // A PNG holds sRGB-encoded values, a level no image: diff measures radiance in .exr files.
    for (args, want) in [
        (
            ["image.png", "ref.exr"],
            "IMAGE image.png: diff reads linear .exr images",
        ),
        (
            ["image.exr", "level.vgate"],
            "REFERENCE level.vgate: diff reads",
        ),
    ] {
        let o = visgate(&[&["diff"], &args[..]].concat());
        assert!(!o.status.success());
        assert!(stderr(&o).contains(want), "{}", stderr(&o));
    }
}

/// The two rooms baked at 64 in a scratch folder: the folder, the level's path and an image's.
fn two_rooms_level() -> (tempfile::TempDir, String, String) {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = |n: &str| dir.path().join(n).to_str().expect("utf-8").to_string();
    let (level, out) = (p("two.vgate"), p("g.exr"));
    let o = two_rooms_at_64(&level, &["-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    (dir, level, out)
}

/// `visgate` with `args`, which must succeed (its stderr shown where it does not).
fn succeeded(args: &[&str]) -> std::process::Output {
    let o = visgate(args);
    assert!(o.status.success(), "{}", stderr(&o));
    o
}

/// The small renders' settings: 64 VPLs, 16×12, one sample a pixel.
/// Small and fast; 64 VPLs in the 8 × 8 blocks the tests name (by default 2 × 2: see
/// `render_gates_names_its_setting_and_each_flag_that_adds_to_the_fast_one`).
const SMALL: [&str; 8] = [
    "--vpls",
    "64",
    "--size",
    "16x12",
    "--spp",
    "1",
    "--interleave-min-vpls",
    "0",
];

/// `visgate render builtin:two-rooms --mode gates` at [`SMALL`] with `level`, to `out`.
fn gates_render<'a>(level: &'a str, out: &'a str) -> Vec<&'a str> {
    let mut a = vec!["render", "builtin:two-rooms", "--mode", "gates"];
    a.extend(SMALL);
    a.extend(["--level", level, "--out", out]);
    a
}

#[test]
fn render_gates_names_its_setting_and_each_flag_that_adds_to_the_fast_one() {
    let (_dir, level, out) = two_rooms_level();
    let mut a = gates_render(&level, &out);
    // The default: the voxel walk (no clusters or lists, each VPL's end) in the balanced
    // setting, named in the frame's first line, with the dark pixels' pass, the near field's
    // and the ratio estimator's unshadowed light.
    let o = visgate(&a);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("VPL walk ends"), "{}", stdout(&o));
    let balanced = "gates (voxel walk + triangles, 8×8 interleaved, tent blur, dark pixels walk \
                    the rest, near field 4 blocks, ratio estimator (grid 3 px)) 16x12";
    assert!(stdout(&o).contains(balanced), "{}", stdout(&o));
    assert!(
        stdout(&o)
            .contains("ratio estimator: unshadowed light summed at 30 grid pixels (every 3 px)"),
        "{}",
        stdout(&o)
    );
    assert!(stdout(&o).contains("starved pixels"), "{}", stdout(&o));
    assert!(stdout(&o).contains("near VPLs"), "{}", stdout(&o));
    assert!(stdout(&o).contains("unshadowed"), "{}", stdout(&o));
    assert!(!stdout(&o).contains("unique clusters"), "{}", stdout(&o));
    // By default the 64 VPLs run in 2 × 2 blocks, 16 a pixel, named so.
    let mut shrunk = a.clone();
    let at = shrunk.iter().position(|x| *x == "--interleave-min-vpls");
    shrunk[at.expect("in SMALL") + 1] = "12";
    let out = stdout(&succeeded(&shrunk));
    let named = "(voxel walk + triangles, 2×2 interleaved (8×8 for 64 VPLs: 1.0 a pixel), tent";
    assert!(out.contains(named), "{out}");
    // Without the ratio estimator: named so, and its pass not run; with both flags, refused.
    let no_ratio = [&a[..], &["--no-ratio"]].concat();
    let out = stdout(&succeeded(&no_ratio));
    assert!(out.contains("near field 4 blocks) 16x12"), "{out}");
    assert!(!out.contains("unshadowed"), "{out}");
    let both = visgate(&[&no_ratio[..], &["--ratio"]].concat());
    assert!(!both.status.success(), "--ratio with --no-ratio is refused");
    let grid = visgate(&[&no_ratio[..], &["--ratio-stride", "3"]].concat());
    assert!(
        !grid.status.success(),
        "--ratio-stride with --no-ratio is refused"
    );
    // Its grid: every pixel's own at stride 1 (named without a grid), a wider one named, one
    // past the limit refused with it.
    let out = stdout(&succeeded(&[&a[..], &["--ratio-stride", "1"]].concat()));
    assert!(out.contains("ratio estimator) 16x12"), "{out}");
    assert!(
        out.contains("summed at 192 grid pixels (every 1 px) and 0 between"),
        "{out}"
    );
    let out = stdout(&succeeded(&[&a[..], &["--ratio-stride", "8"]].concat()));
    assert!(out.contains("ratio estimator (grid 8 px)) 16x12"), "{out}");
    let wide = visgate(&[&a[..], &["--ratio-stride", "9"]].concat());
    assert!(!wide.status.success(), "stride 9 is refused");
    assert!(stderr(&wide).contains("0..=8 pixels"), "{}", stderr(&wide));
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
    assert!(!stdout(&o).contains("near VPLs"), "{}", stdout(&o));
    assert!(!stdout(&o).contains("unshadowed"), "{}", stdout(&o));
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
}

#[test]
fn render_gates_takes_the_roulette_and_every_gate_shape_and_refuses_a_missing_or_stale_level() {
    let (_dir, level, out) = two_rooms_level();
    let mut a = gates_render(&level, &out);
    a.push("--fast");
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
    // In the balanced setting, whose blur takes the ratio estimator, from 32 VPLs a pixel
    // (2,048 in 8 × 8 blocks), the near field and the estimator kept beside it.
    let mut balanced = gates_render(&level, &out);
    balanced[vpls] = "2048";
    let ob = visgate(&balanced);
    assert!(ob.status.success(), "{}", stderr(&ob));
    let named = "near field 4 blocks, ratio estimator (grid 3 px), roulette under 0.05 (auto))";
    assert!(stdout(&ob).contains(named), "{}", stdout(&ob));
    assert!(stdout(&ob).contains("ratio estimator: unshadowed light summed"));
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

/// The line in which a render says where it put a bare mesh's light and camera.
fn placement(o: &std::process::Output) -> String {
    let out = stdout(o);
    let line = out.lines().find(|l| l.contains("camera 'inside' at"));
    line.unwrap_or_else(|| panic!("no placement in {out}"))
        .to_string()
}

#[test]
fn a_bare_mesh_is_looked_at_from_one_place_with_a_level_or_without() {
    // The ajar door's rooms as a bare OBJ: no light, no camera. A reference rendered without
    // a level and a gate render with one must show the same view (they differed: the level's
    // skeleton placed them, or without it a lattice of probes).
    let (dir, out) = exported("ajar-door");
    let obj = out.join("ajar-door.obj");
    let (obj, level) = (obj.to_str().expect("utf8"), dir.path().join("a.vgate"));
    let level = level.to_str().expect("utf8");
    let o = visgate(&["bake", obj, "-o", level, "--resolution", "64", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let render = |mode: &str, with_level: bool| {
        let png = dir.path().join(format!("{mode}-{with_level}.exr"));
        let mut a = vec![
            "render", obj, "--mode", mode, "--size", "16x12", "--vpls", "64",
        ];
        a.extend(["--spp", "1", "--out", png.to_str().expect("utf8")]);
        if with_level {
            a.extend(["--level", level]);
        }
        let o = visgate(&a);
        assert!(o.status.success(), "{}", stderr(&o));
        (placement(&o), std::fs::read(&png).expect("image"))
    };
    let (without, none_without) = render("none", false);
    let (with, none_with) = render("none", true);
    assert_eq!(without, with);
    assert!(without.contains("largest empty ball"), "{without}");
    // The same camera and light: the same image where the level is not used.
    assert_eq!(none_without, none_with);
    assert_eq!(render("gates", true).0, without);
}

#[test]
fn where_the_triangle_lists_overflow_the_binding_render_walks_the_planes_and_compare_says_why() {
    // VISGATE_MAX_BINDING_BYTES: an adapter whose storage binding holds the two rooms' open
    // voxels (7.0 MB) and planes but not their triangle lists (11.5 MB), as lavapipe's 128 MiB
    // held none of a 4.2 M-triangle level's 337 MB.
    let (dir, level, out) = two_rooms_level();
    let capped = |args: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_visgate"))
            .args(args)
            .env("RUST_LOG", "warn")
            .env("VISGATE_MAX_BINDING_BYTES", "9000000")
            .output()
            .expect("runs visgate");
        assert!(o.status.success(), "{}", stderr(&o));
        o
    };
    let o = capped(&gates_render(&level, &out));
    let (said, report) = (stderr(&o), stdout(&o));
    assert!(
        said.contains("the closed voxels' triangle lists")
            && said.contains("more than the adapter's storage binding limit 9000000")
            && said.contains("walks on the closed voxels' planes instead"),
        "{said}"
    );
    assert!(
        report.contains("gates (voxel walk, 8×8") && !report.contains("+ triangles"),
        "{report}"
    );
    // Uncapped, the default walks the triangles, and says nothing of it.
    let o = succeeded(&gates_render(&level, &out));
    assert!(
        stdout(&o).contains("gates (voxel walk + triangles"),
        "{}",
        stdout(&o)
    );
    assert!(!stderr(&o).contains("planes instead"), "{}", stderr(&o));
    // `compare` measures the method it names: the default fails with the reason, the fast
    // setting (the planes' walk) renders.
    let cmp = dir.path().join("cmp");
    let cmp = cmp.to_str().expect("utf-8");
    let mut compare = vec![
        "compare",
        "builtin:two-rooms",
        "--modes",
        "gates,gates-fast",
    ];
    compare.extend(SMALL);
    compare.extend(["--level", &level, "--out", cmp]);
    capped(&compare);
    let text = std::fs::read_to_string(std::path::Path::new(cmp).join("report.json"));
    let report: serde_json::Value = serde_json::from_str(&text.expect("report")).expect("json");
    let failures = report["failures"].as_array().expect("failures");
    assert!(
        !failures.is_empty()
            && failures.iter().all(|f| f["mode"] == "gates"
                && f["error"]
                    .as_str()
                    .is_some_and(|e| e.contains("gates-fast's walk"))),
        "{failures:?}"
    );
    let rows = report["rows"].as_array().expect("rows");
    assert!(rows.iter().any(|r| r["mode"] == "gates-fast"), "{rows:?}");
    assert!(!rows.iter().any(|r| r["mode"] == "gates"), "{rows:?}");
}
