//! The `visgate` command line, run as a user runs it.

#[path = "../support/mod.rs"]
mod support;

use std::path::Path;

use support::{stderr, stdout, visgate};

/// `visgate bake builtin:two-rooms -o OUT --resolution 64` and `extra`.
fn two_rooms_at_64(out: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["bake", "builtin:two-rooms", "-o", out, "--resolution", "64"];
    args.extend(extra);
    visgate(&args)
}

/// `visgate scenes export NAME` into a scratch folder: the folder (kept while it lives) and
/// the exported files' folder in it.
fn exported(name: &str) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join(name);
    let o = visgate(&["scenes", "export", name, out.to_str().expect("utf8")]);
    assert!(o.status.success(), "{}", stderr(&o));
    (dir, out)
}

mod bake;
mod inspect;
mod render;
