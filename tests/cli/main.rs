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

mod bake;
mod inspect;
mod render;
