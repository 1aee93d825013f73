//! What the command-line tests share: the binary run as a user runs it, and scenes written to
//! a scratch folder.

#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `visgate ARGS` with errors-only logging.
pub fn visgate(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_visgate"))
        .args(args)
        .env("RUST_LOG", "error")
        .output()
        .expect("runs visgate")
}

/// `visgate ARGS` with warnings shown, as a user sees them.
pub fn visgate_warn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_visgate"))
        .args(args)
        .env("RUST_LOG", "warn")
        .output()
        .expect("runs visgate")
}

/// A path `name` in a folder that cannot be made, for outputs that must be refused before
/// the work: a file stands at the folder's name in `dir`.
pub fn under_a_file(dir: &Path, name: &str) -> String {
    std::fs::write(dir.join("a-file"), "x").expect("write a-file");
    let path = dir.join("a-file").join(name);
    path.to_str().expect("utf-8").to_string()
}

/// The number after the word `label` on the bake report's summary line (`clusters 44  gates
/// 70  portals 1263 …`).
pub fn summary_count(report: &str, label: &str) -> f64 {
    let line = report
        .lines()
        .find(|l| l.starts_with("clusters "))
        .unwrap_or_else(|| panic!("no summary line in\n{report}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    words
        .windows(2)
        .find(|w| w[0] == label)
        .and_then(|w| w[1].parse().ok())
        .unwrap_or_else(|| panic!("no number after {label:?}: {line}"))
}

/// `visgate compare SCENE --level LEVEL --modes gates,none --vpls 256 --size SIZE --spp 1`
/// into `out`, as the tests of levels unlike the built-ins run it: a lookup of each (camera,
/// mode) row's indirect energy ratio and black-where-lit share.
pub fn gates_and_none(
    scene: &Path,
    level: &Path,
    size: &str,
    out: &Path,
) -> impl Fn(&str, &str) -> (f64, f64) + use<> {
    let path = |p: &Path| p.to_str().expect("utf8").to_string();
    let (scene, level, out_s) = (path(scene), path(level), path(out));
    let o = visgate(&[
        "compare",
        &scene,
        "--level",
        &level,
        "--modes",
        "gates,none",
        "--vpls",
        "256",
        "--size",
        size,
        "--spp",
        "1",
        "--out",
        &out_s,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json = std::fs::read_to_string(out.join("report.json")).expect("report.json");
    let report: serde_json::Value = serde_json::from_str(&json).expect("json");
    let rows = report["rows"].as_array().expect("rows").clone();
    move |camera: &str, mode: &str| {
        let row = rows
            .iter()
            .find(|r| r["camera"] == camera && r["mode"] == mode)
            .unwrap_or_else(|| panic!("no row {camera} {mode} in {json}"));
        let energy = row["energy_ratio"].as_f64().expect("energy");
        (energy, row["black_where_lit"].as_f64().expect("black"))
    }
}

/// Its standard output.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Its standard error.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A floor and a box sliding across it, lit by a light on an orbit: a dynamic scene.
pub fn dynamic_scene(dir: &Path) -> PathBuf {
    let w = |n: &str, t: &str| std::fs::write(dir.join(n), t).expect("write");
    w(
        "floor.obj",
        "v -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\nf 1 4 3 2\n",
    );
    w(
        "box.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
         f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n",
    );
    w(
        "scene.toml",
        r#"
[[mesh]]
path = "floor.obj"

[[mesh]]
path = "box.obj"
static = false
animate = [{ t = 0, translate = [-2, 0, -0.5] }, { t = 2, translate = [1, 0, -0.5] }]

[[light]]
type = "point"
position = [0, 3, 0]
intensity = [10, 10, 10]
orbit = { centre = [0, 3, 0], radius = 1, period_s = 4 }

[[camera]]
name = "main"
eye = [0, 4, 6]
target = [0, 0, 0]
fov_deg = 60
"#,
    );
    dir.join("scene.toml")
}
