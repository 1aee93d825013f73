//! `visgate view` as a person runs it: in a window on a virtual X display (Xvfb, which CI
//! installs; a machine without it fails here rather than skipping), its screenshot equals
//! `visgate render`'s image of the same view; without a display it says what to do instead.

mod support;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::Duration;

use support::dynamic_scene;
use visgate_runtime::hdr::HdrImage;
use visgate_runtime::metrics::errors;

fn visgate(args: &[&str], display: Option<&str>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_visgate"));
    c.args(args).env("RUST_LOG", "error");
    match display {
        Some(d) => c.env("DISPLAY", d),
        None => c.env_remove("DISPLAY"),
    };
    c.env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("runs visgate")
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// An Xvfb server on a free display, stopped when dropped.
struct Xvfb(Child, String);

impl Xvfb {
    fn start() -> Xvfb {
        // A server that exits or hangs before it is ready is stopped and another started.
        for _ in 0..5 {
            if let Some(x) = Xvfb::try_start() {
                return x;
            }
        }
        panic!("Xvfb did not start 5 times");
    }

    /// Xvfb on a display it picks itself (`-displayfd`: the first free one, its lock taken
    /// atomically, so the tests' servers started at once do not collide), once it says it
    /// accepts connections; `None` if it exited or said nothing in 60 s (a loaded 2-core
    /// machine starting several servers at once can take a while; on a fresh machine one
    /// was seen never to make its socket's file when the display was guessed from the lock
    /// files).
    fn try_start() -> Option<Xvfb> {
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "1280x800x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| panic!("the viewer test needs Xvfb (apt-get install xvfb): {e}"));
        let out = child.stdout.take().expect("a piped stdout");
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut line = String::new();
            let _ = std::io::BufRead::read_line(&mut std::io::BufReader::new(out), &mut line);
            let _ = tx.send(line);
        });
        let said = rx.recv_timeout(Duration::from_secs(60)).ok();
        match said
            .as_deref()
            .map(str::trim)
            .and_then(|n| n.parse::<u32>().ok())
        {
            Some(n) => Some(Xvfb(child, format!(":{n}"))),
            None => {
                let _ = child.kill();
                let _ = child.wait();
                None
            }
        }
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn read(p: &Path) -> HdrImage {
    HdrImage::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn the_viewers_screenshot_is_visgate_renders_image_of_the_same_view() {
    let x = Xvfb::start();
    let dir = tempfile::tempdir().expect("tempdir");
    let dynamic = dynamic_scene(dir.path());
    let dynamic = dynamic.to_str().expect("utf-8");
    for (scene, time) in [("builtin:cornell-box", "0"), (dynamic, "1.5")] {
        let shot = dir.path().join("shot.exr");
        let want = dir.path().join("render.exr");
        let (shot_s, want_s) = (shot.to_str().expect("utf-8"), want.to_str().expect("utf-8"));
        let common = ["--vpls", "64", "--time", time];
        let mut view = vec![
            "view",
            scene,
            "--render-size",
            "64x48",
            "--screenshot",
            shot_s,
        ];
        view.extend(common);
        let o = visgate(&view, Some(&x.1));
        assert!(o.status.success(), "{}", text(&o));
        assert!(text(&o).contains("after 3 frames"), "{}", text(&o));
        let mut render = vec![
            "render", scene, "--mode", "none", "--size", "64x48", "--out", want_s,
        ];
        render.extend(common);
        let o = visgate(&render, None);
        assert!(o.status.success(), "{}", text(&o));
        let (img, reference) = (read(&shot), read(&want));
        assert!(
            img.mean().x > 1e-4,
            "{scene}: a blank screenshot: {}",
            img.mean()
        );
        let e = errors(&img, &reference).expect("same size");
        // The same call with the same VPLs, clamp, shadow maps and pose: equal to rounding.
        assert!(e.rel_mse < 1e-9, "{scene} at {time} s: {e:?}");
    }
    // The PNG is what the window shows: the frame tone-mapped on the GPU into the texture egui
    // draws (no readback of the HDR image), equal to `visgate render`'s PNG to one level.
    let (shown, png) = (dir.path().join("shown.png"), dir.path().join("render.png"));
    let o = visgate(
        &[
            "view",
            "builtin:cornell-box",
            "--render-size",
            "64x48",
            "--vpls",
            "64",
            "--screenshot",
            shown.to_str().expect("utf-8"),
        ],
        Some(&x.1),
    );
    assert!(o.status.success(), "{}", text(&o));
    let o = visgate(
        &[
            "render",
            "builtin:cornell-box",
            "--mode",
            "none",
            "--size",
            "64x48",
            "--vpls",
            "64",
            "--out",
            png.to_str().expect("utf-8"),
        ],
        None,
    );
    assert!(o.status.success(), "{}", text(&o));
    let load = |p: &Path| image::open(p).expect("png").to_rgb8();
    let (a, b) = (load(&shown), load(&png));
    assert_eq!(a.dimensions(), b.dimensions());
    let diffs: Vec<u8> = (a.pixels().zip(b.pixels()))
        .map(|(p, q)| (0..3).map(|k| p[k].abs_diff(q[k])).max().unwrap_or(0))
        .collect();
    let worst = diffs.iter().copied().max().unwrap_or(0);
    let differ = diffs.iter().filter(|d| **d > 0).count();
    assert!(
        worst <= 1 && differ * 100 <= diffs.len(),
        "{worst}, {differ} pixels"
    );
    assert!(a.pixels().any(|p| p[0] > 20), "a blank window image");
    // Another time poses the box and the light elsewhere: another image.
    let other = dir.path().join("other.exr");
    let o = visgate(
        &[
            "view",
            dynamic,
            "--render-size",
            "64x48",
            "--vpls",
            "64",
            "--time",
            "0.2",
            "--screenshot",
            other.to_str().expect("utf-8"),
        ],
        Some(&x.1),
    );
    assert!(o.status.success(), "{}", text(&o));
    let e = errors(&read(&other), &read(&dir.path().join("shot.exr"))).expect("same size");
    assert!(e.rel_mse > 1e-4, "the pose did not change the image: {e:?}");
}

#[test]
fn without_a_display_the_viewer_says_what_to_do_or_renders_headless() {
    let o = visgate(&["view", "builtin:cornell-box"], None);
    assert!(!o.status.success());
    for want in ["no display", "visgate render", "Xvfb", "--or-render"] {
        assert!(text(&o).contains(want), "missing '{want}': {}", text(&o));
    }
    // A scene that is not there is the error, not the display.
    let o = visgate(&["view", "builtin:no-such-scene"], None);
    assert!(!o.status.success());
    assert!(text(&o).contains("no-such-scene"), "{}", text(&o));
    assert!(!text(&o).contains("no display"), "{}", text(&o));
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("headless.png");
    let o = visgate(
        &[
            "view",
            "builtin:cornell-box",
            "--render-size",
            "32x24",
            "--vpls",
            "16",
            "--or-render",
            out.to_str().expect("utf-8"),
        ],
        None,
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("headless"), "{}", text(&o));
    assert!(text(&o).contains("16 asked"), "{}", text(&o));
    assert!(std::fs::metadata(&out).expect("written").len() > 100);
    // Without --vpls, `visgate render`'s 1,024 light paths.
    let o = visgate(
        &[
            "view",
            "builtin:cornell-box",
            "--render-size",
            "32x24",
            "--or-render",
            out.to_str().expect("utf-8"),
        ],
        None,
    );
    assert!(text(&o).contains("1024 asked"), "{}", text(&o));
    // Bad arguments are refused before any window.
    let o = visgate(&["view", "builtin:cornell-box", "--mode", "gates"], None);
    assert!(text(&o).contains("--level"), "{}", text(&o));
    let o = visgate(&["view", "builtin:cornell-box", "--mode", "nope"], None);
    assert!(text(&o).contains("give one of"), "{}", text(&o));
    let lost = support::under_a_file(dir.path(), "x.png");
    let lost = lost.as_str();
    let o = visgate(&["view", "builtin:cornell-box", "--or-render", lost], None);
    assert!(!o.status.success());
    assert!(!text(&o).contains("headless"), "{}", text(&o));
    let want = format!("--or-render {lost}: cannot make its folder");
    assert!(text(&o).contains(&want), "{}", text(&o));
}

#[test]
fn the_viewer_draws_its_layers_and_the_reference_beside_the_method() {
    let x = Xvfb::start();
    let dir = tempfile::tempdir().expect("tempdir");
    let p = |n: &str| dir.path().join(n).to_str().expect("utf-8").to_string();
    let o = visgate(
        &[
            "bake",
            "builtin:four-rooms",
            "-o",
            &p("rooms.vgate"),
            "--resolution",
            "64",
            "-q",
        ],
        None,
    );
    assert!(o.status.success(), "{}", text(&o));
    let o = visgate(
        &[
            "view",
            "builtin:four-rooms",
            "--level",
            &p("rooms.vgate"),
            "--render-size",
            "48x32",
            "--vpls",
            "16",
            "--layers",
            "clusters,gates,skeleton,vpls,indirect",
            "--compare",
            "--screenshot",
            &p("frame.png"),
            "--window-shot",
            &p("window.png"),
            "--frames",
            "2",
        ],
        Some(&x.1),
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("the window"), "{}", text(&o));
    // The window holds the panel, the frame and its layers: many distinct colours.
    let window = image::open(p("window.png")).expect("window shot").to_rgb8();
    assert_eq!(window.dimensions(), (1280, 760));
    let seen: std::collections::BTreeSet<[u8; 3]> = window.pixels().map(|px| px.0).collect();
    assert!(seen.len() > 50, "{} colours: a blank window?", seen.len());
    let o = visgate(
        &["view", "builtin:four-rooms", "--layers", "gates"],
        Some(&x.1),
    );
    assert!(text(&o).contains("--level"), "{}", text(&o));
}

#[test]
fn a_benchmark_walks_its_path_and_writes_every_frames_passes() {
    let x = Xvfb::start();
    let dir = tempfile::tempdir().expect("tempdir");
    let csv = dir.path().join("times.csv");
    let o = visgate(
        &[
            "view",
            "builtin:cornell-box",
            "--mode",
            "val-cssm",
            "--render-size",
            "40x30",
            "--vpls",
            "32",
            "--benchmark",
            "4",
            "--benchmark-out",
            csv.to_str().expect("utf-8"),
        ],
        Some(&x.1),
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("benchmark: 4 frames"), "{}", text(&o));
    let rows = std::fs::read_to_string(&csv).expect("csv");
    assert!(
        rows.starts_with("frame,pass,gpu_ms,cpu_wall_ms\n"),
        "{rows}"
    );
    let frames: Vec<&str> = rows.lines().filter(|l| l.contains(",frame,")).collect();
    assert_eq!(frames.len(), 4, "{rows}");
    assert!(rows.contains("3,frame,"), "{rows}");
    assert!(rows.lines().any(|l| l.contains("VAL")), "{rows}");
}

#[test]
fn the_method_and_the_view_come_back_in_the_next_run_but_not_in_scripted_ones() {
    let x = Xvfb::start();
    let config = tempfile::tempdir().expect("tempdir");
    // An interactive run (no --screenshot) stopped from outside after 10 s: the state is saved
    // with the first frame and whenever it changes, not only at a clean exit.
    let run = |extra: &[&str]| {
        let mut c = Command::new("timeout");
        c.args([
            "10",
            env!("CARGO_BIN_EXE_visgate"),
            "view",
            "builtin:cornell-box",
        ])
        .args(["--render-size", "32x24", "--vpls", "8"])
        .args(extra)
        .env("DISPLAY", &x.1)
        .env("XDG_CONFIG_HOME", config.path())
        .env("RUST_LOG", "error");
        c.output().expect("runs")
    };
    let state = config.path().join("visgate").join("viewer.json");
    let o = run(&["--mode", "val-hard"]);
    let saved = std::fs::read_to_string(&state).unwrap_or_else(|e| panic!("{e}: {}", text(&o)));
    assert!(saved.contains("\"val-hard\""), "{saved}");
    let o = run(&[]);
    assert!(
        text(&o).contains("restored the last run's view of cornell-box (val-hard)"),
        "{}",
        text(&o)
    );
    // --fresh neither reads nor writes it.
    let o = run(&["--fresh", "--mode", "none"]);
    assert!(!text(&o).contains("restored"), "{}", text(&o));
    assert!(
        std::fs::read_to_string(&state)
            .expect("state")
            .contains("\"val-hard\"")
    );
}

#[test]
fn shaders_from_a_folder_draw_and_a_broken_one_is_named_while_the_last_good_draws() {
    let x = Xvfb::start();
    let dir = tempfile::tempdir().expect("tempdir");
    let shaders = dir.path().join("gpu");
    std::fs::create_dir_all(shaders.join("passes")).expect("mkdir");
    let shade = include_str!("../runtime/src/gpu/passes/shade.wgsl");
    let end = "    return vec4<f32>(radiance, 1.0);";
    assert_eq!(shade.matches(end).count(), 1, "the shading pass's return");
    let file = shaders.join("passes/shade.wgsl");
    let want = dir.path().join("render.exr");
    let o = visgate(
        &[
            "render",
            "builtin:cornell-box",
            "--mode",
            "direct-only",
            "--size",
            "64x48",
            "--out",
            want.to_str().expect("utf-8"),
        ],
        None,
    );
    assert!(o.status.success(), "{}", text(&o));
    let shot = dir.path().join("shot.exr");
    let view = |display: &str| {
        visgate(
            &[
                "view",
                "builtin:cornell-box",
                "--mode",
                "direct-only",
                "--render-size",
                "64x48",
                "--frames",
                "2",
                "--shader-dir",
                shaders.to_str().expect("utf-8"),
                "--screenshot",
                shot.to_str().expect("utf-8"),
            ],
            Some(display),
        )
    };
    // The shading pass halved: the viewer draws with it.
    std::fs::write(
        &file,
        shade.replace(end, "    return vec4<f32>(radiance * 0.5, 1.0);"),
    )
    .expect("write");
    let o = view(&x.1);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("1 file(s) from"), "{}", text(&o));
    let (img, reference) = (read(&shot), read(&want));
    let ratio = img.mean().x / reference.mean().x;
    assert!((ratio - 0.5).abs() < 1e-4, "{ratio}");
    // Broken on line 40: named, and the built-in shaders (the last good) draw.
    let mut lines: Vec<&str> = shade.lines().collect();
    lines[39] = "this is not WGSL";
    std::fs::write(&file, lines.join("\n")).expect("write");
    let o = view(&x.1);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("shader error") && text(&o).contains("shade.wgsl:40:"),
        "{}",
        text(&o)
    );
    let e = errors(&read(&shot), &reference).expect("same size");
    assert!(e.rel_mse < 1e-9, "{e:?}");
    // Not a folder of shaders: refused before a window opens.
    let o = visgate(
        &[
            "view",
            "builtin:cornell-box",
            "--shader-dir",
            dir.path().to_str().expect("utf-8"),
        ],
        Some(&x.1),
    );
    assert!(
        !o.status.success() && text(&o).contains("holds none of visgate's shaders"),
        "{}",
        text(&o)
    );
}

#[test]
fn a_recorded_camera_path_is_what_the_benchmark_plays() {
    let x = Xvfb::start();
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = visgate_scenes::Builtin::CornellBox.scene().expect("scene");
    let c = &scene.cameras[0];
    let key = |eye: glam::Vec3| {
        serde_json::json!({ "eye": eye.to_array(), "target": c.target.to_array(),
            "fov_deg": c.fov_x_rad.to_degrees() })
    };
    // Two frames: from a step back to the scene's camera, which the last frame shows.
    let path = dir.path().join("path.json");
    let file = serde_json::json!({ "scene": "cornell-box",
        "cameras": [key(c.eye + (c.eye - c.target) * 0.5), key(c.eye)] });
    std::fs::write(&path, file.to_string()).expect("write");
    let (csv, shot, want) = (
        dir.path().join("t.csv"),
        dir.path().join("shot.exr"),
        dir.path().join("want.exr"),
    );
    let p = |f: &PathBuf| f.to_str().expect("utf-8").to_string();
    let o = visgate(
        &[
            "view",
            "builtin:cornell-box",
            "--mode",
            "direct-only",
            "--render-size",
            "48x36",
            "--benchmark",
            "2",
            "--benchmark-out",
            &p(&csv),
            "--benchmark-path",
            &p(&path),
            "--screenshot",
            &p(&shot),
            "--frames",
            "2",
        ],
        Some(&x.1),
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("benchmark: 2 frames"), "{}", text(&o));
    let o = visgate(
        &[
            "render",
            "builtin:cornell-box",
            "--mode",
            "direct-only",
            "--size",
            "48x36",
            "--out",
            &p(&want),
        ],
        None,
    );
    assert!(o.status.success(), "{}", text(&o));
    let e = errors(&read(&shot), &read(&want)).expect("same size");
    assert!(e.rel_mse < 1e-6, "{e:?}");
    // A path that is not one: refused before a window opens.
    std::fs::write(&path, r#"{"cameras": []}"#).expect("write");
    let o = visgate(
        &[
            "view",
            "builtin:cornell-box",
            "--benchmark",
            "2",
            "--benchmark-out",
            &p(&csv),
            "--benchmark-path",
            &p(&path),
        ],
        Some(&x.1),
    );
    assert!(
        !o.status.success() && text(&o).contains("two at least"),
        "{}",
        text(&o)
    );
}
